"""Grades that count: a mischievous class of lecture 01 graded by one command. Every attempt of
a class that tries to score without implementing, to read the answers, to harm a classmate, to
poison the checks or to stop the batch is a submission here, beside honest, partial, wrong and
empty ones; every one gets the score it earned, nothing outside the outputs changes, and no
process of the class outlives the command. Each attempt is also graded alone with two honest
classmates (`test_an_attempt_alone`): the grader before the sandbox failed every one of those.
"""

import shutil
import subprocess
import sys

import pytest
from grading_class import EXPLOITS, HONEST, HUGE, UNSAFE_NOTE, grade_class, material_copy, scores

from contactfem.lab.course.review import ANSWER_CHARS

pytestmark = pytest.mark.slow  # end-to-end: the command line in processes, a class graded

OTHERS = [("corrupt", None, None, "not a notebook"), ("absent", None, None, "no submission")]
OTHERS += [("stray", [], (0, 0), "not on the roster"), ("late", HONEST[0][1], (5, 5), "late by 2 h 00 min")]


def _check(graded, expected):
    """Every row as earned, every file as it was, no process alive, the CSV final."""
    assert graded.code == 0, graded.err
    for name, _, earned, note in expected:
        row = graded.rows.get(f"{name}.ipynb") or next(
            r for r in graded.rows.values() if r["name"] == f"Student {name}"
        )
        if earned is not None:
            assert scores(row) == earned and float(row["total"]) == sum(earned), (name, scores(row), row["notes"])
        assert note in row["notes"], (name, row["notes"])
    changed = sorted(k for k in set(graded.before) | set(graded.after) if graded.before.get(k) != graded.after.get(k))
    assert not changed, changed
    assert graded.alive == [], "processes of the class still run"
    assert graded.csv_later == graded.csv_at_return, "the CSV changed after the command returned"


@pytest.fixture(scope="module")
def mischievous(tmp_path_factory):
    root = tmp_path_factory.mktemp("class")
    members = [(n, c) for n, c, _, _ in HONEST + EXPLOITS + OTHERS]
    return grade_class(root, members, material_copy(root))


def test_a_mischievous_class_gets_what_it_earned(mischievous):
    """Honest, partial, wrong, empty and mischievous submissions: every score as earned, every file
    of the checkout, of the instructor's material, of the roster and of every submission as it
    was, no process of the class alive, the CSV final when the command returns; in well under
    10 minutes on 2 cores."""
    print(f"\ngraded {len(mischievous.rows)} rows in {mischievous.seconds:.0f} s")
    _check(mischievous, HONEST + EXPLOITS + OTHERS)
    assert len(mischievous.rows) == len(HONEST + EXPLOITS + OTHERS)
    assert mischievous.rows["utime.ipynb"]["late"] == "yes" and mischievous.rows["full1.ipynb"]["late"] == ""
    assert mischievous.rows["endless_cell.ipynb"]["status"] == "stopped"
    assert mischievous.seconds < 600


def test_the_review_file_is_bounded_per_answer(mischievous):
    """A written answer of 3 MB is shown cut, with how much more there is."""
    shown = mischievous.review.count("stiff ")
    assert 0 < shown < 10_000 < HUGE.count("stiff ")
    assert "more characters not shown" in mischievous.review


@pytest.mark.parametrize("name", [e[0] for e in EXPLOITS])
def test_an_attempt_alone(name, tmp_path):
    """One attempt with two honest classmates (the first, full1, is the one attempts aim at):
    every score as earned, nothing changed, nothing alive, the CSV final."""
    attempt = next(e for e in EXPLOITS if e[0] == name)
    honest = [("full1", HONEST[0][1], (5, 5), ""), ("full2", HONEST[1][1], (5, 5), "")]
    graded = grade_class(tmp_path, [(n, c) for n, c, _, _ in [honest[0], attempt, honest[1]]], material_copy(tmp_path))
    _check(graded, [*honest, attempt])
    if name == "utime":
        assert (graded.rows["utime.ipynb"]["late"], graded.rows["full1.ipynb"]["late"]) == ("yes", "")
    if name == "huge_answer":  # 3 MB of written answer: the review page stays small
        assert len(graded.review) < 10 * ANSWER_CHARS


def _no_user_namespaces():
    """The command line runs in a user namespace where no further one can be made: a machine
    without user namespaces, for the process and its children (None where it cannot be set up)."""
    probe = subprocess.run(
        ["unshare", "--user", "--map-root-user", "sh", "-c", "echo 0 > /proc/sys/user/max_user_namespaces"],
        capture_output=True,
    )
    if probe.returncode != 0:
        return None
    return [
        "unshare",
        "--user",
        "--map-root-user",
        "sh",
        "-c",
        'echo 0 > /proc/sys/user/max_user_namespaces && exec "$@"',
        "-",
    ]


def test_without_a_sandbox_grading_refuses_in_one_line_or_says_so_on_every_row(tmp_path):
    """Where user namespaces cannot be made, `course grade` refuses in one line saying why, before
    any work; with --unsafe-no-sandbox it grades, and every row says so."""
    from grading_class import notebook

    wrap = _no_user_namespaces()
    if wrap is None or shutil.which("unshare") is None:
        pytest.skip("no unshare here to take user namespaces away")
    subs = tmp_path / "subs"
    subs.mkdir()
    notebook(HONEST[0][1], subs / "a.ipynb")
    notebook(HONEST[2][1], subs / "b.ipynb")
    out = tmp_path / "s.csv"
    argv = [sys.executable, "-m", "contactfem.cli", "course", "grade", str(subs), "--out", str(out)]
    refused = subprocess.run(wrap + argv, capture_output=True, text=True, timeout=300)
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1, refused.stderr
    assert "no sandbox here" in refused.stderr and "user namespaces" in refused.stderr
    assert not out.exists() and not (tmp_path / "s-review").exists()
    unsafe = subprocess.run(wrap + argv + ["--unsafe-no-sandbox"], capture_output=True, text=True, timeout=300)
    assert unsafe.returncode == 0, unsafe.stderr
    import csv

    rows = list(csv.DictReader(open(out)))
    assert [r["total"] for r in rows] == ["10", "5"]
    assert all(UNSAFE_NOTE in r["notes"] for r in rows)
