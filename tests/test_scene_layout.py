"""Scenes are parameters + build + measure, and no scene imports another scene (what ring
scenes share lives once, in scenes/rings.py, not in one of them)."""

import ast
from pathlib import Path

import pytest

SCENES = Path(__file__).resolve().parents[1] / "contactfem" / "scenes"
MODULES = sorted(p for p in SCENES.glob("*.py") if p.name != "__init__.py")


def is_scene(path):
    """A scene module defines SCENE at its top level."""
    tree = ast.parse(path.read_text())
    return any(
        isinstance(n, ast.Assign) and any(getattr(t, "id", None) == "SCENE" for t in n.targets) for n in tree.body
    )


@pytest.mark.parametrize("path", [p for p in MODULES if is_scene(p)], ids=lambda p: p.name)
def test_no_scene_imports_another(path):
    scenes = {p.stem for p in MODULES if is_scene(p)}
    imported = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                imported.add(node.module.split(".")[0])
            else:
                imported |= {a.name for a in node.names}
    assert not (imported & scenes) - {path.stem}, f"{path.name} imports the scenes {sorted(imported & scenes)}"


def test_the_check_sees_the_scenes():
    assert {"block", "cork", "funnel", "hertz", "rolling_ring", "sloping_impact"} <= {
        p.stem for p in MODULES if is_scene(p)
    }


def test_no_python_line_passes_120_characters():
    """The formatter (ruff format, line length 120: pyproject.toml) breaks code, not long strings and comments:
    those are wrapped by hand, and this holds them to the same length."""
    repo = SCENES.parents[1]
    files = [p for folder in ("contactfem", "tests", "lectures") for p in (repo / folder).rglob("*.py")]
    long = [
        f"{p.relative_to(repo)}:{i}"
        for p in files
        if ".venv" not in p.parts
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if len(line) > 120
    ]
    assert len(files) > 100 and long == []
