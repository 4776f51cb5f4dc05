"""pytest set-up: import cellsph from the build folder and find the `cellsph` program beside it.

CELLSPH_BUILD names the build folder (default build/release); scripts/test.sh runs
    /usr/bin/python3 -m pytest python/tests
from the repository root.
"""
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.path.abspath(os.environ.get("CELLSPH_BUILD", os.path.join(ROOT, "build", "release")))
sys.path.insert(0, os.path.join(BUILD, "python"))


@pytest.fixture(scope="session")
def cellsph_binary():
    path = os.path.join(BUILD, "cellsph")
    assert os.path.exists(path), f"{path} missing: build the release first (cmake --build build/release)"
    return path


@pytest.fixture(scope="session")
def repo_root():
    return ROOT
