"""scripts/bench_python.py keeps working (a small set: the figures of docs/python.md come from 10^6 points)."""
import os
import subprocess
import sys

from conftest import BUILD


def test_bench_python_runs_on_a_small_set(repo_root):
    out = subprocess.run([sys.executable, os.path.join(repo_root, "scripts", "bench_python.py"), "--n", "20000",
                          "--repeat", "1", "--build", BUILD], check=True, capture_output=True, text=True).stdout
    for line in ("cellsph ", "cli ", "scipy-ball ", "scipy-sdm ", "scipy-pairs ", "cellsph / cli search time: ",
                 "fastest SciPy path: "):
        assert line in out, out
