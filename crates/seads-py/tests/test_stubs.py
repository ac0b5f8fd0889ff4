"""The type stubs name everything the extension module exports, and everything has a docstring."""

import ast
import pathlib

import pytest

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


@pytest.mark.without_gymnasium
def test_mypy_stubtest_finds_the_stubs_equal_to_the_module():
    """mypy's stubtest compares every stubbed signature, default and property with the compiled
    module's own (a pyo3 class is built by ``__new__``, not ``__init__``)."""
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "seads._seads"],
        capture_output=True, text=True, check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_extension_is_built_for_the_stable_abi():
    """One abi3 wheel serves every CPython from 3.9 on: the compiled module is named for the
    stable ABI, not for this interpreter."""
    assert pathlib.Path(_seads.__file__).name == "_seads.abi3.so"
