"""The type stubs name everything the extension module exports, and everything has a docstring."""

import ast
import pathlib

import seads
from seads import _seads

STUB = pathlib.Path(seads.__file__).with_name("_seads.pyi")


def test_the_stubs_cover_every_export_and_every_method():
    tree = ast.parse(STUB.read_text())
    stubbed = {node.name: node for node in tree.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    exported = {name for name in dir(_seads) if not name.startswith("_")}
    assert exported <= set(stubbed), f"not in the stubs: {exported - set(stubbed)}"
    for name in exported:
        obj = getattr(_seads, name)
        assert obj.__doc__, f"{name} has no docstring"
        if isinstance(obj, type):
            methods = {m for m in vars(obj) if not m.startswith("_")}
            in_stub = {n.name for n in stubbed[name].body if isinstance(n, ast.FunctionDef)}
            assert methods <= in_stub, f"{name}: not in the stubs: {methods - in_stub}"
            for m in methods:
                assert getattr(obj, m).__doc__, f"{name}.{m} has no docstring"
