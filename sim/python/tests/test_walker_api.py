"""The package's surface: every public name documented, the extension's stubs complete."""

from __future__ import annotations

import ast
import inspect
import pathlib

import walker
from walker import _walker

STUB = pathlib.Path(walker.__file__).with_name("_walker.pyi")


def test_every_public_name_has_a_docstring():
    for name in walker.__all__:
        obj = getattr(walker, name)
        if inspect.isclass(obj) or callable(obj):
            assert inspect.getdoc(obj), f"walker.{name} has no docstring"
        if inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (callable(member) or isinstance(member, property)):
                    assert inspect.getdoc(member), f"walker.{name}.{attr} has no docstring"


def test_the_stub_lists_every_name_of_the_extension():
    tree = ast.parse(STUB.read_text())
    stubbed = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            stubbed.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            stubbed.add(node.target.id)
    public = {n for n in dir(_walker) if not n.startswith("_")}
    assert public == stubbed
    assert (pathlib.Path(walker.__file__).with_name("py.typed")).is_file()
