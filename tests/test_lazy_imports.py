"""Imports sit at the top of a module, where a reader sees them: heavy libraries as lazy modules
(contactfem/lazy.py), the rest plainly. An import inside a function says why on its line (a
comment: an optional extra that may be absent, a deliberate import in a sandboxed child...).

NOT_YET: the modules whose imports inside functions are still to be moved, with their count;
a count may only fall (the test fails when it rises, and asks to lower the number when it falls).
"""

import ast
import sys
from pathlib import Path

from contactfem import lazy

PACKAGE = Path(__file__).resolve().parents[1] / "contactfem"

NOT_YET = {
    "lab/bench/coverage.py": 1,
    "lab/bench/scaling.py": 5,
    "lab/course/__init__.py": 11,
    "lab/course/checks/beyond_node_to_segment.py": 4,
    "lab/course/checks/block.py": 6,
    "lab/course/checks/cork.py": 2,
    "lab/course/checks/funnel.py": 1,
    "lab/course/checks/interface_laws.py": 1,
    "lab/course/checks/kinematics_linearisation.py": 3,
    "lab/course/checks/return_mapping.py": 4,
    "lab/course/checks/rolling_ring.py": 1,
    "lab/course/checks/runs.py": 2,
    "lab/course/checks/sloping_impact.py": 1,
    "lab/course/checks/speed_accuracy.py": 3,
    "lab/course/checks/where_1990_stops.py": 2,
    "lab/course/checks/write_your_own_law.py": 1,
    "lab/course/grade.py": 3,
    "lab/course/hidden.py": 1,
    "lab/course/sandbox.py": 9,
    "lab/course/serve.py": 3,
    "plots/summary.py": 4,
}


def hidden_imports(path):
    """(line, text) of every import inside a function of the file with no comment on its line."""
    lines = path.read_text().splitlines()
    found = []
    for func in ast.walk(ast.parse("\n".join(lines), filename=str(path))):
        if not isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for node in ast.walk(func):
            if isinstance(node, (ast.Import, ast.ImportFrom)) and "#" not in lines[node.lineno - 1]:
                found.append((node.lineno, lines[node.lineno - 1].strip()))
    return sorted(set(found))


def test_imports_inside_functions_say_why():
    counts = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        hidden = hidden_imports(path)
        if hidden:
            counts[path.relative_to(PACKAGE).as_posix()] = hidden
    new = {
        f"{name}:{line}: {text}"
        for name, found in counts.items()
        if len(found) > NOT_YET.get(name, 0)
        for line, text in found
    }
    assert not new, (
        "an import inside a function: move it to the module's top (a heavy library as lazy.module(...)), "
        "or say on its line why it must stay:\n" + "\n".join(sorted(new))
    )
    fell = {name: len(counts.get(name, ())) for name, n in NOT_YET.items() if len(counts.get(name, ())) < n}
    assert not fell, f"fewer imports inside functions now: lower NOT_YET (tests/test_lazy_imports.py) to {fell}"


def test_the_walk_finds_a_hidden_import(tmp_path):
    src = tmp_path / "m.py"
    src.write_text("def f():\n    import scipy\n    import dask  # optional extra\n    return scipy, dask\n")
    assert hidden_imports(src) == [(2, "import scipy")]


def test_a_lazy_module_loads_on_first_use_through_the_import_system():
    name = "json.tool"  # a standard module the test process has not loaded yet
    sys.modules.pop(name, None)
    tool = lazy.module(name)
    assert name not in sys.modules
    assert callable(tool.main) and name in sys.modules
