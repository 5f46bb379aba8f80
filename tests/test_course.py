"""The course as a course: every lecture states its objectives, prerequisites and time;
the exercises' checks give full marks to the instructor's solution, zero to the blank
stub (naming what is missing) and less than full, with a hint, to a wrong answer
(tests/course/wrong/, one per exercise); the student version holds no solution text;
`contactfem course grade` turns a folder of submissions into a CSV.

Two levels: the checks called in this process on the solution, the stub and the wrong answer
of every exercise (fast), and the real path, the notebooks built by otter assign (every
lecture) and graded by otter on a folder of submissions: solution, stub and wrong answer of
a sample of lectures, GRADED (each grading executes the whole lecture in the fast preset: all
twelve lectures three times over would take many minutes; pytest --every-case grades them all).

Needs the course extra (otter-grader): skipped without it, except on CI (CI=true),
where a missing package is a failure.
"""

import csv
import os
import re
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from conftest import OPTIONS

ON_CI = os.environ.get("CI", "").lower() in ("true", "1", "yes")
# the lectures graded through otter: an early one (its check cells the command-line test grades
# too), a paper example whose checks run a scene, the newest; --every-case: every lecture
GRADED_SAMPLE = ("01_interface_laws", "07_funnel", "12_beyond_node_to_segment")
REPO = Path(__file__).resolve().parents[1]
WRONG = REPO / "tests" / "course" / "wrong"


def require(module):
    if ON_CI:
        try:
            return __import__(module)
        except ImportError as err:
            pytest.fail(
                f"CI=true but the course dependency {module!r} is missing ({err}): install '.[all]'", pytrace=False
            )
    return pytest.importorskip(module)


def _nbformat():
    return require("nbformat")


def _sources():
    from contactfem.lab.course import lecture_sources

    return lecture_sources()


def _exercises():
    from contactfem.lab.course.checks import EXERCISES

    return EXERCISES


EXERCISE_NAMES = list(_exercises())


def graded_lectures():
    lectures = sorted({e.lecture for e in _exercises().values()})
    return lectures if OPTIONS["every_case"] else [lec for lec in lectures if lec in GRADED_SAMPLE]


GRADED_NAMES = [n for n, e in _exercises().items() if e.lecture in graded_lectures()]


def _solutions():
    from contactfem.lab.course import solution_cells

    nbformat = _nbformat()
    out = {}
    for src in _sources():
        out.update(solution_cells(nbformat.read(src, as_version=4)))
    return out


def _wrong(name):
    text = (WRONG / f"{name}.py").read_text()
    expect = re.search(r"^# expect: (.+)$", text, re.M).group(1).strip()
    return text, expect


# -- the course's shape ---------------------------------------------------------------------


@pytest.mark.slow
def test_every_lecture_opens_with_objectives_prerequisites_and_time():
    nbformat = _nbformat()
    for src in _sources():
        nb = nbformat.read(src, as_version=4)
        head = "\n".join(c.source for c in nb.cells[:3] if c.cell_type == "markdown")
        for what in ("**Learning objectives.**", "**Prerequisites.**", "**Time.**"):
            assert what in head, f"{src.name}: no {what} at the top"
        objectives = re.findall(r"^\d\. \*[a-z ]+\*", head, re.M)  # "1. *compute* ..."
        assert 3 <= len(objectives) <= 5, f"{src.name}: {len(objectives)} learning objectives (3-5, each a verb)"


def test_exercises_per_lecture_and_in_all():
    """At least 2 graded exercises in every lecture, 25 in all, 6 of them implementing part of
    the method; each labelled easy, medium or hard."""
    ex = _exercises()
    per = {}
    for e in ex.values():
        per.setdefault(e.lecture, []).append(e.name)
    for src in _sources():
        assert len(per.get(src.stem, [])) >= 2, f"lecture {src.stem}: {per.get(src.stem)}"
    assert len(ex) >= 25
    assert sum(e.implements for e in ex.values()) >= 6
    assert all(e.difficulty in ("easy", "medium", "hard") for e in ex.values())


def test_each_exercise_is_in_its_lecture_labelled_and_last():
    """Every exercise with checks is a question of its lecture (and back), its prompt says
    its difficulty, and the exercises are the lecture's last section."""
    from contactfem.lab.course import questions

    nbformat = _nbformat()
    ex = _exercises()
    found = {}
    for src in _sources():
        nb = nbformat.read(src, as_version=4)
        qs = questions(nb)
        for name, i in qs:
            found[name] = src.stem
            prompt = next(c.source for c in nb.cells[i + 1 :] if c.cell_type == "markdown")
            assert re.search(rf"\*{ex[name].difficulty.capitalize()}[.;]", prompt), (
                f"{name}: its prompt does not say {ex[name].difficulty}"
            )
            assert ("implement part of the method" in prompt) == ex[name].implements, name
        if qs:
            headings = [
                ln
                for c in nb.cells
                if c.cell_type == "markdown"
                for ln in c.source.splitlines()
                if ln.startswith("## ")
            ]
            assert headings[-1] == "## Exercises", f"{src.name}: the last section is {headings[-1]!r}"
    assert found == {n: e.lecture for n, e in ex.items()}
    assert sorted(p.stem for p in WRONG.glob("*.py")) == sorted(ex)


def test_course_plan_lists_every_exercise_as_graded():
    """The course guide's tables of exercises (plan and checks) say what checks.EXERCISES holds."""
    text = (REPO / "lectures" / "README.md").read_text()
    ex = _exercises()
    rows = {
        m.group(1): [c.strip() for c in m.group(2).split("|")]
        for m in re.finditer(r"^\| `(ex\w+)` \|(.*)\|$", text, re.M)
    }
    assert sorted(rows) == sorted(ex)
    for name, (difficulty, implements, points, what) in rows.items():
        e = ex[name]
        assert (difficulty, implements == "yes", float(points)) == (e.difficulty, e.implements, e.points), name
        shown = [float(x) for x in re.findall(r"\((\d+)\)", what)]
        assert sum(shown) == e.points, f"{name}: the parts' points in the course guide add up to {sum(shown)}"
    plan = dict(re.findall(r"`(ex\w+)` \((\d+)\)", text))
    assert {k: float(v) for k, v in plan.items()} == {n: e.points for n, e in ex.items()}


# -- the checks, in this process --------------------------------------------------------------


def _run(name, code):
    from contactfem.lab.course.checks import run

    env = {"np": np, "dataclass": dataclass}
    exec(compile(code, f"<{name}>", "exec"), env)
    res = run(name, env)
    return sum(r[1] for r in res), next((r[2] for r in res if r[2] != "passed"), "")


@pytest.mark.slow
@pytest.mark.parametrize("name", EXERCISE_NAMES)
def test_checks_solution_stub_and_wrong_answer(name):
    require("otter")
    from otter.assign.solutions import replace_solutions

    full = _exercises()[name].points
    srcs = _solutions()[name]
    assert _run(name, "\n".join(srcs)) == (full, "")
    stub = "\n".join("\n".join(replace_solutions(s.split("\n"), "python")) for s in srcs)
    score, msg = _run(name, stub)
    answer = re.search(r"^(?:def|class) (\w+)", "\n".join(srcs), re.M).group(1)
    assert score == 0 and answer in msg and "`...`" in msg, (score, msg)
    text, expect = _wrong(name)
    score, msg = _run(name, text)
    assert score < full and re.search(expect, msg), (score, msg)


def test_check_stops_an_endless_loop():
    from contactfem.lab.course.checks.answers import call

    def forever(*args):
        while True:
            pass

    with pytest.raises(AssertionError, match="did not return within 0.2 s"):
        call(forever, "forever", 1.0, timeout=0.2)


# -- the real path: otter builds the versions and grades the notebooks ---------------------------


def _answer_cells(nb):
    """{exercise: the answer cell} of a built notebook (the code cell before grader.check)."""
    out = {}
    for i, c in enumerate(nb.cells):
        m = re.search(r'grader\.check\("([^"]+)"\)', c.source) if c.cell_type == "code" else None
        if m:
            out[m.group(1)] = next(cc for cc in reversed(nb.cells[:i]) if cc.cell_type == "code")
    return out


def _with_answers(student, answers, path):
    nbformat = _nbformat()
    nb = nbformat.read(student, as_version=4)
    cells = _answer_cells(nb)
    for name, code in answers.items():
        cells[name].source = code
    nbformat.write(nb, path)


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """Both versions of the lectures that have exercises, and a folder of submissions graded
    by otter: for each graded lecture (graded_lectures) its instructor notebook (the
    solutions), its student notebook (the stubs) and the student notebook with every answer wrong."""
    require("otter")
    from contactfem.lab.course import build_versions, grade

    root = tmp_path_factory.mktemp("course")
    lectures = sorted({e.lecture for e in _exercises().values()})
    build_versions({"student": root / "student", "instructor": root / "instructor"}, only=lectures)
    subs = root / "submissions"
    for lec in graded_lectures():
        folder = subs / lec
        folder.mkdir(parents=True)
        shutil.copy2(root / "instructor" / f"{lec}.ipynb", folder / "solution.ipynb")
        shutil.copy2(root / "student" / f"{lec}.ipynb", folder / "stub.ipynb")
        mine = [n for n, e in _exercises().items() if e.lecture == lec]
        _with_answers(root / "student" / f"{lec}.ipynb", {n: _wrong(n)[0] for n in mine}, folder / "wrong.ipynb")
    rows = grade(subs, root / "scores.csv", autograders=root / "instructor" / "autograder", jobs=2)
    return root, {r["submission"]: r for r in rows}


def _row(graded, lecture, kind):
    return graded[1][f"{lecture}/{kind}.ipynb"]


@pytest.mark.slow
@pytest.mark.parametrize("name", GRADED_NAMES)
def test_graded_solution_stub_and_wrong_answer(course, name):
    e = _exercises()[name]
    sol, stub, wrong = (_row(course, e.lecture, k) for k in ("solution", "stub", "wrong"))
    assert float(sol[name]) == e.points, sol["notes"]
    assert f"{name}:" not in sol["notes"]
    assert float(stub[name]) == 0.0
    answer = re.search(r"^(?:def|class) (\w+)", "\n".join(_solutions()[name]), re.M).group(1)
    note = next(n for n in stub["notes"].split(" | ") if n.startswith(f"{name}:"))
    assert answer in note and "`...`" in note, note
    assert float(wrong[name]) < e.points
    note = next(n for n in wrong["notes"].split(" | ") if n.startswith(f"{name}:"))
    assert re.search(_wrong(name)[1], note), note


@pytest.mark.slow
def test_graded_totals(course):
    from contactfem.lab.course.checks import MANUAL

    ex = _exercises()
    for row in course[1].values():
        mine = [n for n, e in ex.items() if e.lecture == row["lecture"]]
        assert float(row["total"]) == sum(float(row[n]) for n in mine)
        written = [m for m in MANUAL.values() if m.lecture == row["lecture"]]
        assert float(row["possible"]) == sum(ex[n].points for n in mine) + sum(m.points for m in written)


@pytest.mark.slow
def test_student_version_holds_no_solution_text(course):
    """Every line of a solution that appears nowhere else in its lecture is absent from the
    student build (cells and metadata alike), and present in the instructor build."""
    nbformat = _nbformat()
    root = course[0]
    for src in _sources():
        if not (root / "student" / src.name).exists():
            continue
        from contactfem.lab.course import solution_lines

        own = solution_lines(nbformat.read(src, as_version=4))
        assert own, src.name
        student = (root / "student" / src.name).read_text()
        teacher = (root / "instructor" / src.name).read_text()
        import json

        for ln in own:
            assert json.dumps(ln)[1:-1] not in student, f"{src.name}: the student version contains {ln!r}"
            assert json.dumps(ln)[1:-1] in teacher, f"{src.name}: the instructor version lacks {ln!r}"


@pytest.mark.slow
def test_grade_a_folder_of_three_from_the_command_line(course, tmp_path, capsys):
    """`contactfem course grade`: a solution, a stub and a mix (one answer right, one wrong)
    of lecture 01 into a CSV with one row per submission and one column per exercise; the
    grading configurations are built from lectures/ by the command itself."""
    from contactfem.cli import main

    lec = "01_interface_laws"
    root = course[0]
    folder = tmp_path / "submissions"
    folder.mkdir()
    shutil.copy2(root / "instructor" / f"{lec}.ipynb", folder / "anna.ipynb")
    shutil.copy2(root / "student" / f"{lec}.ipynb", folder / "ben.ipynb")
    sol = "\n".join(_solutions()["ex01_power_law"])
    _with_answers(
        root / "student" / f"{lec}.ipynb",
        {"ex01_power_law": sol, "ex01_tresca": _wrong("ex01_tresca")[0]},
        folder / "carla.ipynb",
    )
    out = tmp_path / "scores.csv"
    t0 = time.perf_counter()
    assert main(["course", "grade", str(folder), "--out", str(out)]) == 0
    print(f"\ngraded 3 submissions in {time.perf_counter() - t0:.0f} s (wall, otter assign included)")
    with open(out) as f:
        rows = list(csv.DictReader(f))
    assert [r["submission"] for r in rows] == ["anna.ipynb", "ben.ipynb", "carla.ipynb"]
    assert list(rows[0]) == [
        "id",
        "name",
        "submission",
        "lecture",
        "ex01_power_law",
        "ex01_tresca",
        "ex01_discussion",
        "total",
        "possible",
        "status",
        "late",
        "notes",
    ]
    assert [(r["ex01_power_law"], r["ex01_tresca"], r["total"]) for r in rows] == [
        ("5", "5", "10"),
        ("0", "0", "0"),
        ("5", "2", "7"),
    ]
    assert "grows with the pressure" in rows[2]["notes"]


def test_course_command_line_refuses_bad_input(tmp_path, capsys):
    """One line on stderr, exit code 2, before any work."""
    from contactfem.cli import main

    (tmp_path / "empty").mkdir()
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "a.ipynb").write_text("{}")
    (tmp_path / "file").write_text("")
    cases = [
        (["course", "grade", str(tmp_path / "none"), "--out", "x.csv"], "is not a folder"),
        (["course", "grade", str(tmp_path / "empty"), "--out", "x.csv"], "no notebooks"),
        (["course", "grade", str(tmp_path / "subs"), "--out", str(tmp_path / "x.txt")], "must end in .csv"),
        (["course", "grade", str(tmp_path / "subs"), "--out", str(tmp_path / "file" / "x.csv")], "is a file"),
        (["course", "grade", str(tmp_path / "subs"), "--out", str(tmp_path / "x.csv"), "--jobs", "0"], "--jobs"),
        (
            [
                "course",
                "grade",
                str(tmp_path / "subs"),
                "--out",
                str(tmp_path / "x.csv"),
                "--autograders",
                str(tmp_path / "empty"),
            ],
            "no grading configurations",
        ),
        (["course", "build", "--out", str(tmp_path / "file")], "is a file"),
    ]
    for argv, what in cases:
        capsys.readouterr()
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and what in err, err
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.slow
def test_a_broken_submission_is_a_row_not_a_crash(course, tmp_path):
    from contactfem.lab.course import grade

    folder = tmp_path / "subs"
    folder.mkdir()
    (folder / "01_garbage.ipynb").write_text("not a notebook")
    (folder / "notes.ipynb").write_text('{"cells": [], "metadata": {}}')
    rows = grade(folder, tmp_path / "s.csv", autograders=course[0] / "instructor" / "autograder")
    by = {r["submission"]: r for r in rows}
    assert by["01_garbage.ipynb"]["status"] == "not graded" and by["01_garbage.ipynb"]["total"] == "0"
    assert by["01_garbage.ipynb"]["notes"].startswith("not a notebook")
    assert "not a lecture of this course" in by["notes.ipynb"]["notes"]
