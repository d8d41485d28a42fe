"""The type stubs (.pyi) shipped in the package cover every public function, class and method of the
compiled module, and nothing it lacks (editors complete exactly what exists)."""

import ast
import pathlib

import pytest

import microcobot

PKG = pathlib.Path(microcobot.__file__).parent
MODULES = ["stickslip", "identify", "dsp", "control", "platform", "haptics", "tweezers", "vision", "cell", "positioner"]


def stub_names(tree):
    out = {}
    for n in tree.body:
        if isinstance(n, ast.FunctionDef):
            out[n.name] = None
        elif isinstance(n, ast.ClassDef):
            out[n.name] = {m.name for m in n.body if isinstance(m, ast.FunctionDef) and not m.name.startswith("_")}
    return out


@pytest.mark.parametrize("name", MODULES)
def test_stub_matches_module(name):
    assert (PKG / "py.typed").exists()
    stub = stub_names(ast.parse((PKG / f"{name}.pyi").read_text()))
    mod = getattr(microcobot, name)
    real = {n for n in dir(mod) if not n.startswith("_")}
    assert set(stub) == real
    for cls, methods in stub.items():
        if methods is None:
            continue
        members = {m for m in dir(getattr(mod, cls)) if not m.startswith("_")}
        assert methods == members, cls
    # Every function and method says what it does beyond pybind11's signature line.
    def documented(obj):
        return len((obj.__doc__ or "").strip().splitlines()) >= 2

    for n in real:
        obj = getattr(mod, n)
        if isinstance(obj, type):
            for k in dir(obj):
                a = getattr(obj, k)
                if not k.startswith("_") and not isinstance(a, property):
                    assert documented(a), f"{name}.{n}.{k}"
        else:
            assert documented(obj), f"{name}.{n}"
