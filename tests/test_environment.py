"""The environment variables contactfem reads are one table (contactfem.environment): every name the
package, the lectures and CI use is declared there, and the package reads them only through it."""

import re
from pathlib import Path

import pytest

from contactfem import environment

REPO = Path(__file__).resolve().parents[1]
NAME = re.compile(r"CONTACTFEM_[A-Z_]+")


def sources():
    yield from (REPO / "contactfem").rglob("*.py")
    yield from (REPO / "lectures").rglob("*.md")
    yield from (REPO / "lectures").rglob("*.py")
    yield REPO / ".ci" / "run"


def test_every_variable_used_is_declared():
    used = {(n, p.relative_to(REPO)) for p in sources() for n in NAME.findall(p.read_text())}
    assert used, "no variable found: the scan is broken"
    assert sorted((n, str(p)) for n, p in used if n not in environment.VARIABLES) == []


def test_the_package_reads_them_through_the_table():
    read = re.compile(r"(environ\.get|environ\[|getenv)\(?\s*[\"']CONTACTFEM_")
    where = [
        f"{p.relative_to(REPO)}:{i}"
        for p in (REPO / "contactfem").rglob("*.py")
        # serve.py runs alone in a submission's sandbox, importing nothing of the package (lab/course/serve.py)
        if p.name not in ("environment.py", "serve.py")
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if read.search(line)
    ]
    assert where == []


def test_an_undeclared_name_is_refused(monkeypatch):
    name = "CONTACTFEM_" + "NOT_DECLARED"
    monkeypatch.setenv(name, "1")
    with pytest.raises(KeyError, match=name):
        environment.read(name)
    monkeypatch.setenv("CONTACTFEM_DEBUG", "1")
    monkeypatch.delenv("CONTACTFEM_BENCH", raising=False)
    assert environment.read("CONTACTFEM_DEBUG") == "1" and environment.read("CONTACTFEM_BENCH", "x") == "x"


def test_the_table_has_a_row_per_variable():
    rows = environment.table().splitlines()[2:]
    assert [r.split("`")[1] for r in rows] == list(environment.VARIABLES)
