"""The ```python blocks of docs/python.md and README.md run as written (each file's blocks in order, in one
namespace, in a scratch folder), so the tour stays true."""
import os
import re

import pytest


def python_blocks(path):
    with open(path) as f:
        return re.findall(r"^```python\n(.*?)^```", f.read(), flags=re.S | re.M)


@pytest.mark.parametrize("doc", ["docs/python.md", "README.md"])
def test_python_blocks_run(repo_root, tmp_path, monkeypatch, doc):
    blocks = python_blocks(os.path.join(repo_root, doc))
    assert blocks, f"{doc} has no python block"
    monkeypatch.chdir(tmp_path)
    os.symlink(os.path.join(repo_root, "scenes"), tmp_path / "scenes")
    namespace = {"__name__": "__docs__"}
    for k, code in enumerate(blocks):
        exec(compile(code, f"{doc} python block {k + 1}", "exec"), namespace)
