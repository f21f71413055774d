"""The package's surface: every name exported, documented, and described by the stub."""

import ast
import pathlib

import raylab
import raylab._native as native

STUB = pathlib.Path(raylab.__file__).with_name("_native.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    top = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    methods = {c.name: {m.name for m in c.body if isinstance(m, ast.FunctionDef)} for c in tree.body if isinstance(c, ast.ClassDef)}
    return top, methods


def test_every_export_exists_and_has_a_docstring():
    for name in raylab.__all__:
        obj = getattr(raylab, name)
        if name != "__version__":
            assert obj.__doc__, name
    assert raylab.__version__ == "0.1.0"


def test_the_stub_describes_the_native_module():
    top, methods = stub_names()
    public = {n for n in dir(native) if not n.startswith("_")}
    assert public == top
    for cls in ("Scene", "Structure"):
        real = {n for n in dir(getattr(native, cls)) if not n.startswith("_")}
        assert real == methods[cls] - {"__init__"}, cls
