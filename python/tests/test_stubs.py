"""The type stubs (cellsph/_cellsph.pyi) name exactly what the compiled module has, and every public
function, class and method has a docstring."""
import ast
import os

import cellsph
from cellsph import _cellsph


def stub_tree():
    path = os.path.join(os.path.dirname(cellsph.__file__), "_cellsph.pyi")
    return ast.parse(open(path).read())


def public(names):
    return {n for n in names if not n.startswith("_")}


def test_stub_names_match_the_module():
    tree = stub_tree()
    top = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    assert top == public(dir(_cellsph))
    for cls in (n for n in tree.body if isinstance(n, ast.ClassDef)):
        members = {n.name for n in cls.body if isinstance(n, ast.FunctionDef)} - {"__init__"}
        runtime = public(dir(getattr(_cellsph, cls.name))) - public(dir(RuntimeError if cls.name ==
                                                                             "SimulationError" else object))
        assert members == runtime, cls.name


def test_docstrings():
    for name in cellsph.__all__:
        obj = getattr(cellsph, name)
        assert obj.__doc__ and obj.__doc__.strip(), name
        if isinstance(obj, type) and name != "SimulationError":
            for member in public(vars(obj)):
                assert getattr(obj, member).__doc__, f"{name}.{member}"
