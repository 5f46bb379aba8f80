"""The grading's workings: written scores read back, patched checks, endless notebooks, Ctrl-C,
bad options, the hidden checks, the library's objects handed to an answer. The class graded by
one command, with every attempt of a mischievous class, is tests/test_course_sandbox.py.
"""

import csv
import os
import time

import pytest

pytestmark = pytest.mark.slow  # end-to-end: command lines and processes (the fast tier leaves them out)

nbformat = pytest.importorskip("nbformat")

from grading_class import HEAD, LECTURE, PATCH_CHECKS, PATCH_NUMPY, PL, PL_LIBRARY_HIDDEN  # noqa: E402
from grading_class import PL_STUB, TR, TR_STUB  # noqa: E402
from grading_class import notebook as _notebook  # noqa: E402


def test_written_scores_are_read_back_into_the_csv(tmp_path):
    """The instructor's scores in the review sheet go into the CSV's question column and total."""
    from contactfem.lab.course import grade

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook([HEAD, PL, TR_STUB], subs / "a.ipynb")
    _notebook([HEAD, PL_STUB, TR_STUB], subs / "b.ipynb")
    out = tmp_path / "s.csv"
    rows = grade(subs, out, jobs=2)
    assert [r["ex01_discussion"] for r in rows] == ["", ""] and "written answers to score" in rows[0]["notes"]
    sheet = tmp_path / "s-review" / f"{LECTURE}-scores.csv"
    lines = list(csv.DictReader(open(sheet)))
    lines[0]["score"] = "1.5"
    with open(sheet, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(lines[0]))
        w.writeheader()
        w.writerows(lines)
    rows = grade(subs, out, jobs=2)
    assert (rows[0]["ex01_discussion"], rows[0]["total"], rows[0]["possible"]) == ("1.5", "6.5", "12")
    assert rows[1]["ex01_discussion"] == "" and rows[1]["total"] == "0"
    assert open(sheet).read().count("1.5") == 1  # the instructor's sheet is kept
    digest = __import__("hashlib").sha256((subs / "a.ipynb").read_bytes()).hexdigest()
    assert f"SHA-256 {digest}" in (tmp_path / "s-feedback" / f"a-{LECTURE}.md").read_text()  # what was graded


def test_patching_the_checks_in_the_notebook_scores_nothing(tmp_path):
    """The notebook the issue describes: the checks replaced by do-nothing lambdas, power_law
    returning None and Tresca blank, scores 0 of 10 (it scored 10 of 10 through otter)."""
    from contactfem.lab.course import grade

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook(
        [HEAD, PATCH_CHECKS, PATCH_NUMPY, "def power_law(g_N, c_N, m):\n    return None", TR_STUB], subs / "cheat.ipynb"
    )
    row = grade(subs, tmp_path / "s.csv")[0]
    assert (row["ex01_power_law"], row["ex01_tresca"], row["total"]) == ("0", "0", "0"), row["notes"]


def test_an_answer_that_calls_the_library_scores_zero_with_a_hint(tmp_path):
    from contactfem.lab.course import grade

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook([HEAD, PL_LIBRARY_HIDDEN, TR], subs / "lib.ipynb")
    row = grade(subs, tmp_path / "s.csv")[0]
    assert (row["ex01_power_law"], row["ex01_tresca"]) == ("0", "5"), row["notes"]
    assert "asks you to implement it yourself" in row["notes"]


def test_an_endless_notebook_gets_its_row_and_the_others_are_graded(tmp_path):
    from contactfem.lab.course import Limits, grade

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook([HEAD, "while True:\n    pass", PL, TR], subs / "a_forever.ipynb")
    _notebook([HEAD, PL, TR], subs / "b_good.ipynb")
    t0 = time.perf_counter()
    rows = grade(subs, tmp_path / "s.csv", jobs=2, limits=Limits(notebook=10.0))
    assert time.perf_counter() - t0 < 30
    assert rows[0]["status"] == "stopped" and "time limit 10 s for the notebook" in rows[0]["notes"]
    assert rows[0]["total"] == "0" and rows[1]["total"] == "10"


def test_interrupted_grading_leaves_the_rows_done_and_says_so(tmp_path, monkeypatch, capsys):
    """Ctrl-C during the batch: the CSV holds the rows graded so far, the message says how many."""
    from contactfem.lab import batch
    from contactfem.lab.course import GradingInterrupted, grade

    subs = tmp_path / "subs"
    subs.mkdir()
    for name in ("a", "b", "c"):
        _notebook([HEAD, PL, TR], subs / f"{name}.ipynb")
    real = batch.run_batch

    def interrupted_after_one(*args, **kwargs):
        gen = real(*args, **kwargs)
        yield next(gen)
        gen.close()
        raise KeyboardInterrupt

    monkeypatch.setattr(batch, "run_batch", interrupted_after_one)
    with pytest.raises(GradingInterrupted, match="1 of 3 notebooks graded; their rows are in"):
        grade(subs, tmp_path / "s.csv", jobs=1)
    rows = list(csv.DictReader(open(tmp_path / "s.csv")))
    assert len(rows) == 1 and rows[0]["total"] == "10"
    from contactfem.cli import main

    (tmp_path / "s.csv").unlink()
    capsys.readouterr()
    assert main(["course", "grade", str(subs), "--out", str(tmp_path / "s.csv")]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1 of 3 notebooks graded" in err and "nothing written" not in err, err
    assert len(list(csv.DictReader(open(tmp_path / "s.csv")))) == 1


def test_grade_refuses_bad_options(tmp_path, capsys):
    from contactfem.cli import main

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook([HEAD], subs / "a.ipynb")
    (tmp_path / "bad_roster.csv").write_text("who,file\n")
    out = str(tmp_path / "s.csv")
    cases = [
        (["--notebook-timeout", "0"], "--notebook-timeout"),
        (["--check-timeout", "-1"], "--check-timeout"),
        (["--memory", "10"], "--memory"),
        (["--roster", str(tmp_path / "none.csv")], "--roster"),
        (["--roster", str(tmp_path / "bad_roster.csv")], "no column id, name"),
        (["--deadline", "tomorrow"], "--deadline"),
        (["--lecture", "99_none"], "--lecture"),
        (["--seed", "-1"], "--seed -1: give an integer from 0"),
    ]
    for extra, what in cases:
        capsys.readouterr()
        assert main(["course", "grade", str(subs), "--out", out] + extra) == 2, extra
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and what in err, err
    assert not os.path.exists(out)


def test_implement_exercises_guard_the_library_or_say_they_build_on_it():
    """An exercise that asks for part of the method has its library counterpart guarded
    (LIBRARY, names that exist) or says in its prompt that it builds on the library (BUILDS_ON)."""
    import importlib
    import re

    from contactfem.lab.course import lecture_sources, questions
    from contactfem.lab.course.checks import BUILDS_ON, EXERCISES, LIBRARY

    assert not set(LIBRARY) & set(BUILDS_ON)
    for name in list(LIBRARY) + list(BUILDS_ON):
        assert EXERCISES[name].implements, name
    for name, specs in LIBRARY.items():
        for spec in specs:
            mod, _, path = spec.partition(":")
            obj = importlib.import_module(mod)
            for part in path.split("."):
                obj = getattr(obj, part)
    for src in lecture_sources():
        nb = nbformat.read(src, as_version=4)
        for name, i in questions(nb):
            prompt = next(c.source for c in nb.cells[i + 1 :] if c.cell_type == "markdown")
            says = bool(re.search(r"builds on the library on purpose", prompt))
            assert says == (name in BUILDS_ON), name


def test_every_written_question_is_in_its_lecture_with_its_points():
    from contactfem.lab.course import lecture_sources
    from contactfem.lab.course.checks import MANUAL
    from contactfem.lab.course.grade import manual_answers

    found = {}
    for src in lecture_sources():
        nb = nbformat.read(src, as_version=4)
        answers = manual_answers([(c.cell_type, c.source) for c in nb.cells])
        for name in answers:
            found[name] = src.stem
            prompt = next(c.source for c in nb.cells if f"manual: {name}" in c.source)
            assert f"({MANUAL[name].points:g} points)" in prompt, name
    assert found == {n: m.lecture for n, m in MANUAL.items()}


def test_hidden_checks_pass_every_solution_and_cover_the_exercises():
    """Every hidden check passes the instructor's solution (run here, in one process) at the
    parameters of three seeds, and the stub fails the hidden checks of every exercise; every
    exercise but one (two long scene runs) has some."""
    import numpy as np

    from contactfem.lab.course import lecture_sources, solution_cells
    from contactfem.lab.course.checks import EXERCISES
    from contactfem.lab.course.hidden import hidden_folder, load_hidden, read_hidden, rng_for

    sources = read_hidden(hidden_folder())
    assert sorted(sources) == sorted({e.lecture for e in EXERCISES.values()})
    hidden = {lec: load_hidden(text, lec) for lec, text in sources.items()}
    for lec, checks in hidden.items():
        assert set(checks) <= {p.name for e in EXERCISES.values() if e.lecture == lec for p in e.parts}, lec
    scenes = {"ex05_incline"}  # two scene runs of 120 s allowed each: public only
    for name, e in EXERCISES.items():
        assert any(p.name in hidden[e.lecture] for p in e.parts) == (name not in scenes), name
    sols = {}
    for src in lecture_sources():
        sols.update(solution_cells(nbformat.read(src, as_version=4)))
    from dataclasses import dataclass

    from otter.assign.solutions import replace_solutions

    for name, e in EXERCISES.items():
        env = {"np": np, "dataclass": dataclass}
        exec(compile("\n".join(sols[name]), f"<{name}>", "exec"), env)
        stub = {"np": np, "dataclass": dataclass}
        exec(
            compile(
                "\n".join("\n".join(replace_solutions(s.split("\n"), "python")) for s in sols[name]),
                f"<{name} stub>",
                "exec",
            ),
            stub,
        )
        failed = 0
        for seed in (1, 2, 3):
            for p in e.parts:
                for check in hidden[e.lecture].get(p.name, ()):
                    check(**{a: env.get(a) for a in p.answers}, rng=rng_for(seed, p.name, check.__name__))
                    try:
                        check(**{a: stub.get(a) for a in p.answers}, rng=rng_for(seed, p.name, check.__name__))
                    except AssertionError:
                        failed += 1
        assert failed or name in scenes, f"{name}: no hidden check fails the stub"


def test_a_bad_score_in_the_review_sheet_stops_before_any_grading(tmp_path, capsys):
    from contactfem.cli import main

    subs = tmp_path / "subs"
    subs.mkdir()
    _notebook([HEAD, PL, TR], subs / "a.ipynb")
    (tmp_path / "s-review").mkdir()
    (tmp_path / "s-review" / f"{LECTURE}-scores.csv").write_text(
        "submission,id,name,question,points,score\na.ipynb,,,ex01_discussion,2,3\n"
    )
    t0 = time.perf_counter()
    assert main(["course", "grade", str(subs), "--out", str(tmp_path / "s.csv")]) == 2
    assert time.perf_counter() - t0 < 10
    err = capsys.readouterr().err
    assert "score 3 of a.ipynb, ex01_discussion is outside 0..2" in err and err.count("\n") == 1
    assert not (tmp_path / "s.csv").exists()


def _sandboxes_of(pid):
    """The submissions' processes started (through its workers) by process `pid` (Linux)."""
    found = []
    for d in os.listdir("/proc"):
        try:
            cmd = open(f"/proc/{d}/cmdline", "rb").read()
            chain, p = [], int(d)
            while p > 1 and len(chain) < 10:
                p = int(open(f"/proc/{p}/stat").read().rsplit(")", 1)[1].split()[1])
                chain.append(p)
        except (OSError, ValueError):
            continue
        if b"contactfem_serve" in cmd and pid in chain[3:]:  # its sandbox's first process, bwrap, a worker
            found.append(int(d))
    return found


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="finds the processes in /proc")
def test_ctrl_c_on_the_command_stops_at_once_and_says_what_was_written(tmp_path):
    """SIGINT to `contactfem course grade` while two endless notebooks run: exit 130 within
    seconds, one line saying none was graded, a CSV of the rows done (none)."""
    import signal
    import subprocess
    import sys

    subs = tmp_path / "subs"
    subs.mkdir()
    for name in ("a", "b"):
        _notebook([HEAD, "while True:\n    pass"], subs / f"{name}.ipynb")
    out = tmp_path / "s.csv"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "contactfem.cli",
            "course",
            "grade",
            str(subs),
            "--out",
            str(out),
            "--jobs",
            "2",
            "--notebook-timeout",
            "300",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # a background suite ignores Ctrl-C
    )
    deadline = time.monotonic() + 120
    while len(_sandboxes_of(proc.pid)) < 2 and time.monotonic() < deadline:  # both notebooks running
        time.sleep(0.2)
    running = _sandboxes_of(proc.pid)
    proc.send_signal(signal.SIGINT)
    t0 = time.perf_counter()
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert time.perf_counter() - t0 < 20, err
    assert "0 of 2 notebooks graded; their rows are in" in err and "nothing written" not in err, err
    assert list(csv.DictReader(open(out))) == []
    assert len(running) == 2
    deadline = time.monotonic() + 10  # the submissions' processes end with their workers
    while any(_alive(pid) for pid in running) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in running)


def _alive(pid):
    """Process `pid` runs (a zombie waiting to be reaped does not)."""
    try:
        return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0] not in "ZX"
    except OSError:
        return False


def test_the_hidden_checks_are_not_in_the_package():
    """The installed package (contactfem/) holds no hidden check: not a file, not one of their
    functions; the grader finds them in the instructor's material (the checkout's lectures/)."""
    from pathlib import Path

    import contactfem
    from contactfem.lab.course.hidden import hidden_folder, load_hidden, read_hidden

    folder = hidden_folder()
    assert folder is not None and folder.parent.name == "lectures"
    names = {
        f.__name__ for lec, text in read_hidden(folder).items() for fs in load_hidden(text, lec).values() for f in fs
    }
    assert len(names) >= 20
    package = Path(contactfem.__file__).parent
    assert not list(package.rglob("hidden_checks*"))
    for f in package.rglob("*.py"):
        text = f.read_text()
        assert not [n for n in names if f"def {n}(" in text or f" {n}," in text], f


def test_library_objects_reach_the_answer_as_recipes(tmp_path):
    """A check hands an answer library objects (a law, the parts of a scene's model): they are
    rebuilt in the sandbox from plain data, and what comes back is plain data."""
    from contactfem.lab.course.checks.answers import call
    from contactfem.lab.course.checks.runs import ScenePart, scene_model
    from contactfem.lab.course.edition import build_edition
    from contactfem.lab.course.sandbox import Box, Limits
    from contactfem.laws import Coulomb

    edition = build_edition(tmp_path / "edition", {})
    box = Box(Limits(), edition, tmp_path)
    try:
        assert box.cell(1, "def use(law, stepper, u0):\n    return law.mu, type(stepper).__name__, u0.shape")["ok"]
        stage = [ScenePart("block", {"law": "conical"}, "stage", k) for k in ("stepper", "u0")]
        got = call(box.get("use"), "use", Coulomb(c_T=10.0, mu=0.3), *stage)
        model = scene_model("block", {"law": "conical"})[0]
        assert got == (0.3, type(model.stage.stepper).__name__, model.stage.u0.shape)
    finally:
        box.close()
