"""The layout is the architecture: every module of contactfem belongs to a layer, and no
module imports from a layer above its own (lazy imports inside functions included).

    clock < laws < contact < bodies < solver < problem < scenes < plots, io, equations < lab < cli

``clock`` (a run's wall time without the time spent importing) imports nothing of
contactfem, so the command line can start it first. The physics library is everything
below ``lab``: laws, contact, bodies, solver, problem (the framework scenes are written in), scenes,
and beside them plots (the paper's figures), io (saving runs, ParaView export,
animations, progress bars) and equations (the index of the paper's equations in the
code). ``lab`` is what is built around the library, not part of it: the course
website, the benchmarks that write BENCHMARKS.md, the inverse study of the scan's lost
values, parameter sweeps, and the command line's law files. Only the command line uses
the lab; the library imports nothing of it. The package's ``__init__`` is its public face
and is exempt.
"""

import ast
from pathlib import Path

import pytest
from test_import_cycles import lazy_name

PACKAGE = Path(__file__).resolve().parents[1] / "contactfem"

ORDER = [
    ("clock", "environment", "lazy"),
    ("laws",),
    ("contact",),
    ("bodies",),
    ("solver",),
    ("problem",),
    ("scenes",),
    ("plots", "io", "equations"),
    ("lab",),
    ("cli", "__main__"),
]
LIBRARY = (
    "clock",
    "environment",
    "lazy",
    "laws",
    "contact",
    "bodies",
    "solver",
    "problem",
    "scenes",
    "plots",
    "io",
    "equations",
)
LAYER = {name: level for level, names in enumerate(ORDER) for name in names}


def modules():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def unit(path):
    """The layer unit of a file: its top folder or top-level module name."""
    rel = path.relative_to(PACKAGE)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def imported_units(path, root=PACKAGE):
    """(line, unit) of every contactfem module that the file imports, anywhere in it."""
    rel = path.relative_to(root)
    package = ["contactfem", *rel.parts[:-1]]  # the file's package, for relative imports
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            # `from . import scenes` / `from .. import x`: the names may be modules
            targets = [mod] if node.module else [f"{mod}.{a.name}" for a in node.names]
        elif lazy_name(node):
            targets = [lazy_name(node)]
        else:
            continue
        for name in targets:
            parts = name.split(".")
            if parts[0] == "contactfem" and len(parts) > 1:
                found.append((node.lineno, parts[1]))
    return found


def test_every_module_has_a_layer():
    missing = {unit(p) for p in modules() if unit(p) not in LAYER and unit(p) != "__init__"}
    assert not missing, f"place these in ORDER (tests/test_layers.py): {sorted(missing)}"


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_import_from_a_higher_layer(path):
    own = unit(path)
    if own == "__init__":
        return  # the package's public face
    back = [
        f"{path.relative_to(PACKAGE)}:{line} imports contactfem.{target} "
        f"(layer {LAYER[target]}) from layer {LAYER[own]} ({own})"
        for line, target in imported_units(path)
        if target in LAYER and LAYER[target] > LAYER[own]
    ]
    assert not back, (
        "back edges against clock < laws < contact < bodies < solver < problem < scenes < plots/io/equations < lab "
        "< cli:\n" + "\n".join(back)
    )


def test_the_walk_finds_a_back_edge(tmp_path):
    """The walk itself: a lazy import of a scene inside a solver function is caught, and
    relative imports resolve against the file's package."""
    src = tmp_path / "contactfem" / "solver" / "bad.py"
    src.parent.mkdir(parents=True)
    src.write_text(
        "from .newton import newton\nfrom .. import laws\n\n"
        "def f():\n    from ..scenes import block\n    return block\n"
        'cork = lazy.module("contactfem.plots.cork")\n'
    )
    assert imported_units(src, tmp_path / "contactfem") == [(1, "solver"), (2, "laws"), (5, "scenes"), (7, "plots")]


def test_the_library_imports_nothing_of_the_lab():
    """The physics library stands alone: no module of it imports the lab (site, bench,
    reconstruct, sweep, law files), lazily or not."""
    lab = [
        f"{p.relative_to(PACKAGE)}:{line}"
        for p in modules()
        if unit(p) in LIBRARY
        for line, target in imported_units(p)
        if target == "lab"
    ]
    assert not lab, "the library imports the lab:\n" + "\n".join(lab)
