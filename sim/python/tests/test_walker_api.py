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


def test_a_scenes_repr_builds_the_same_scene(tmp_path):
    import pathlib
    import shutil

    scene = walker.Scene.load("compass").with_params(slope=0.05, leg_mass_kg=6.0)
    shown = repr(scene)
    assert shown.startswith('Scene.load("compass").with_params(') and "slope_rad=0.05" in shown
    again = eval(shown, {"Scene": walker.Scene})
    assert again.values == scene.values
    assert repr(walker.Scene.load("compass")) == 'Scene.load("compass")'
    # a scene file keeps its path
    root = pathlib.Path(__file__).resolve().parents[3]
    files = sorted((root / "sim" / "scenes").glob("*.toml"))
    if files:
        copy = tmp_path / files[0].name
        shutil.copy(files[0], copy)
        try:
            loaded = walker.Scene.load(copy)
        except walker.SceneError:
            return  # a scene that extends another by name is not loadable alone
        assert repr(loaded) == f"Scene.load({str(copy)!r})".replace("'", '"')
