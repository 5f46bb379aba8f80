"""The physics core (contactfem/laws, contact, bodies, solver) type-checks clean with the pinned
mypy of the test extra ([tool.mypy] in pyproject.toml): the Protocols of its interfaces.py files
declare every member the code reads of a law, contact, body, load or stepper. And the library
neither forwards attributes (``__getattr__`` on an object; a lazy module of lazy.py aside) nor
replaces Python's builtins."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_the_core_type_checks(tmp_path):
    try:
        import mypy  # noqa: F401
    except ImportError:
        if os.environ.get("CI"):
            raise
        pytest.skip("mypy is not installed (pip install -e '.[test]')")
    run = subprocess.run(
        [sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache")],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
    assert "no issues found" in run.stdout


def offenders(text):
    """(line number, line) of an object's ``__getattr__`` (a module's PEP 562 lazy import is
    not one: it loads a name once) or a use of ``builtins``."""
    return [
        (n, line.strip())
        for n, line in enumerate(text.splitlines(), 1)
        if re.search(r"\bbuiltins\b", line) or re.match(r"\s+def __getattr__\(self", line)
    ]


# The grader's sandbox is the one place that must do both: it gives a notebook a copy of the
# builtins of its own (serve.py: patching them changes nothing of the server beside it), and the
# checks reach the submission's objects through handles that forward to its sandbox (sandbox.py).
SANDBOX = ("contactfem/lab/course/sandbox.py", "contactfem/lab/course/serve.py")
# A lazy module (lazy.py) stands for one module not loaded yet: its __getattr__ loads that module
# through the import system on the first read (so the run's import clock times it) and reads every
# attribute from it; it is declared at a module's top, never handed around as a value.
LAZY = ("contactfem/lazy.py",)


def test_no_attribute_forwarding_and_no_swapped_builtins():
    found = [
        f"{path.relative_to(REPO)}:{n}: {line}"
        for path in sorted((REPO / "contactfem").rglob("*.py"))
        if path.relative_to(REPO).as_posix() not in SANDBOX + LAZY
        for n, line in offenders(path.read_text())
    ]
    assert not found, "\n".join(found)


def test_the_check_finds_a_forwarding_view_and_a_swapped_import():
    view = "class View:\n    def __getattr__(self, name):\n        return getattr(self.law, name)\n"
    swap = "import builtins\nbuiltins.__import__ = mine\n"
    lazy = "def __getattr__(name):\n    return load(name)\n"
    assert [n for n, _ in offenders(view)] == [2] and [n for n, _ in offenders(swap)] == [1, 2]
    assert offenders(lazy) == []
