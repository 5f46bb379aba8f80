"""The grading of a class: a mock class of lecture 01 graded by one command, where every
submission gets the score intended for it, whatever it does to the grader.

Each submission is a small notebook made here (the lecture's two exercises and its written
question), not the whole lecture: grading runs the notebook's cells in a process of its own,
so a notebook of a few cells is graded in about a second.
"""

import csv
import os
import time

import pytest

pytestmark = pytest.mark.slow  # end-to-end: command lines and processes (the fast tier leaves them out)

nbformat = pytest.importorskip("nbformat")

LECTURE = "01_interface_laws"
HEAD = "import numpy as np\nfrom dataclasses import dataclass"
PL = """def power_law(g_N, c_N, m):
    g_N = np.asarray(g_N, dtype=float)
    approach = np.where(g_N < 0.0, -g_N, 0.0)
    return -c_N * approach ** m, np.where(g_N < 0.0, c_N * m * approach ** (m - 1.0), 0.0)"""
TR = """@dataclass(frozen=True)
class Tresca:
    c_T: float
    tau_y: float

    def slip_bound(self, p, q):
        Y = np.full(np.broadcast(p, q).shape, float(self.tau_y))
        return Y, np.zeros_like(Y), np.zeros_like(Y)"""
PL_STUB = "def power_law(g_N, c_N, m):\n    ..."
TR_STUB = "@dataclass(frozen=True)\nclass Tresca:\n    c_T: float\n    tau_y: float\n\n    def slip_bound(self, p, q):\n        ..."
PL_SIGN = PL.replace("return -c_N", "return c_N")  # t_N of the wrong sign
PL_NO_M = PL.replace("c_N * m * approach", "c_N * approach")  # dt_N without the factor m
PL_C100 = PL.replace("c_N", "100.0").replace("100.0, m", "c_N, m")  # c_N ignored: right only at c_N = 100
TR_COULOMB = TR.replace(
    "Y = np.full(np.broadcast(p, q).shape, float(self.tau_y))",
    "Y = self.tau_y * np.asarray(p, dtype=float) + 0.0 * np.asarray(q)",
)
PL_ONE = PL.replace(
    "return -c_N * approach ** m, np.where(g_N < 0.0, c_N * m * approach ** (m - 1.0), 0.0)",
    "return -c_N * approach ** m",
)
PL_RAISES = "def power_law(g_N, c_N, m):\n    return 1 / 0"
PL_FOREVER = "import time\n\ndef power_law(g_N, c_N, m):\n    while True:\n        time.sleep(0.01)"
PL_LIBRARY = """from contactfem.laws.normal import PowerLaw

def power_law(g_N, c_N, m):
    return PowerLaw(c_N, m).traction(g_N)"""
PL_LIBRARY_HIDDEN = """import importlib

def power_law(g_N, c_N, m):
    law = getattr(importlib.import_module("contactfem.laws." + "normal"), "Power" + "Law")
    return law(c_N, m).traction(g_N)"""
PATCH_CHECKS = """import contactfem.lab.course.checks as checks
for name in dir(checks):
    if not name.startswith("__"):
        setattr(checks, name, lambda *a, **k: None)"""
PATCH_NUMPY = """np.allclose = lambda *a, **k: True
np.all = lambda *a, **k: True
np.testing.assert_allclose = lambda *a, **k: None"""
PATCH_BUILTINS = """import builtins
builtins.isinstance = lambda *a: True
builtins.AssertionError = type("Nothing", (Exception,), {})"""
PL_ZEROS = "def power_law(g_N, c_N, m):\n    return np.zeros_like(g_N), np.zeros_like(g_N)"

# (name, cells, the scores intended for (ex01_power_law, ex01_tresca), a note the row must hold)
CLASS = [
    ("full1", [HEAD, PL, TR], (5, 5), ""),
    ("full2", [HEAD, TR, PL], (5, 5), ""),
    ("partial_pl", [HEAD, PL, TR_STUB], (5, 0), "`...`"),
    ("partial_tr", [HEAD, PL_STUB, TR], (0, 5), "`...`"),
    ("blank", [HEAD, PL_STUB, TR_STUB], (0, 0), "`...`"),
    ("empty", [], (0, 0), "is not defined"),
    ("sign", [HEAD, PL_SIGN, TR], (3, 5), "the sign is wrong"),
    ("no_m", [HEAD, PL_NO_M, TR], (3, 5), "off by a factor 0.4"),
    ("coulomb", [HEAD, PL, TR_COULOMB], (5, 2), "grows with the pressure"),
    ("c_N_ignored", [HEAD, PL_C100, TR], (1, 5), "c_N = 37"),  # passes the public checks only
    ("one_value", [HEAD, PL_ONE, TR], (0, 5), "should return 2 values"),
    ("raises", [HEAD, PL_RAISES, TR], (0, 5), "raised ZeroDivisionError"),
    (
        "patch_checks",
        [HEAD, PATCH_CHECKS, "def power_law(g_N, c_N, m):\n    return None", TR_STUB],
        (0, 0),
        "returned None",
    ),
    ("patch_numpy", [HEAD, PATCH_NUMPY, PL_ZEROS, TR_STUB], (1, 0), "expected"),
    ("patch_builtins", [HEAD, PATCH_BUILTINS, PL_ZEROS, TR_STUB], (1, 0), "expected"),
    ("library", [HEAD, PL_LIBRARY, TR], (0, 5), "the library's own contactfem.laws.normal.PowerLaw"),
    ("library_hidden", [HEAD, PL_LIBRARY_HIDDEN, TR], (0, 5), "the library's own contactfem.laws.normal.PowerLaw"),
    ("endless_cell", [HEAD, PL, "import time\nwhile True:\n    time.sleep(1)", TR], (0, 0), "time limit"),
    ("endless_answer", [HEAD, PL_FOREVER, TR], (0, 5), "did not return within"),
    ("sys_exit", [HEAD, PL, TR, "import sys\nsys.exit(3)"], (5, 5), "SystemExit: 3"),
    ("os_exit", [HEAD, PL, "import os\nos._exit(7)", TR], (0, 0), "exited with code 7"),
    ("import_error", ["import no_such_package\n" + HEAD, PL, TR], (0, 0), "ModuleNotFoundError"),
    ("segfault", ["import ctypes\nctypes.string_at(0)", HEAD, PL, TR], (0, 0), "died (signal 11)"),
    ("flood", [HEAD, PL, 'print("x" * 100_000_000)', TR], (5, 5), "printed 95 MB"),
    ("memory", [HEAD, PL, "hog = bytearray(3 * 2**30)", TR], (5, 5), "MemoryError"),
    ("late", [HEAD, PL, TR], (5, 5), "late by 2 h 00 min"),
    (
        "magic",
        [
            HEAD,
            "%matplotlib inline\n" + PL,
            "import otter\ngrader = otter.Notebook('x.ipynb')",
            TR,
            'grader.check("ex01_power_law")',
        ],
        (5, 5),
        "",
    ),
    ("tr_only_fields", [HEAD, PL, TR.replace("float(self.tau_y)", "0.2")], (5, 3), "tau_y = 1.3"),
    (
        "kills_the_grader",
        [HEAD, PL, TR, "import os, signal\nos.kill(os.getppid(), signal.SIGKILL)"],
        (0, 0),
        "worker died: signal 9",
    ),  # it can stop its grading, not score
    ("full3", [HEAD, PL, TR], (5, 5), ""),
    (
        "compares_with_library",
        [
            HEAD,
            PL + "\n\nfrom contactfem.laws import PowerLaw\n"
            "print(PowerLaw(100.0, 2.5).traction(-0.1), power_law(-0.1, 100.0, 2.5))",
            TR,
        ],
        (5, 5),
        "",
    ),
    ("full4", [HEAD, PL, TR], (5, 5), ""),
]
CORRUPT = "corrupt"
MISSING = "absent"
STRAY = "stray"


def _notebook(cells, path, written="Penetration against conditioning."):
    nb = nbformat.v4.new_notebook()
    nb.metadata["otter"] = {"assignment_name": LECTURE}
    nb.cells = [nbformat.v4.new_code_cell(c) for c in cells]
    nb.cells += [
        nbformat.v4.new_markdown_cell("<!-- manual: ex01_discussion -->\n**Discuss** c_N."),
        nbformat.v4.new_code_cell("stiffness = [1e2, 1e4]"),
        nbformat.v4.new_markdown_cell(written),
    ]
    nbformat.write(nb, path)


def make_class(root):
    """The submissions folder, the roster and the deadline of the mock class."""
    subs = root / "submissions"
    subs.mkdir()
    for name, cells, _, _ in CLASS:
        _notebook(cells, subs / f"{name}.ipynb", written=f"{name} says: stiff is accurate, soft is well conditioned.")
    (subs / f"{CORRUPT}.ipynb").write_text('{"cells": [ this is not json')
    _notebook([HEAD, PL, TR], subs / f"{STRAY}.ipynb")
    roster = root / "roster.csv"
    with open(roster, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "name", "file", "submitted"])
        for i, (name, *_) in enumerate(CLASS):
            w.writerow(
                [
                    f"u{i:02d}",
                    f"Student {name}",
                    f"{name}.ipynb",
                    "2026-12-03T14:00:00+00:00" if name == "late" else "2026-12-03T10:00:00+00:00",
                ]
            )
        w.writerow(["u90", "Student corrupt", f"{CORRUPT}.ipynb", ""])
        w.writerow(["u91", "Student absent", f"{MISSING}.ipynb", ""])
    return subs, roster, "2026-12-03T12:00:00+00:00"


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    from contactfem.cli import main

    root = tmp_path_factory.mktemp("class")
    subs, roster, deadline = make_class(root)
    out = root / "scores.csv"
    t0 = time.perf_counter()
    code = main(
        [
            "course",
            "grade",
            str(subs),
            "--out",
            str(out),
            "--roster",
            str(roster),
            "--deadline",
            deadline,
            "--jobs",
            "2",
            "--notebook-timeout",
            "20",
            "--check-timeout",
            "1",
            "--memory",
            "2048",
        ]
    )
    seconds = time.perf_counter() - t0
    assert code == 0
    with open(out) as f:
        rows = list(csv.DictReader(f))
    return root, {r["submission"] or r["id"]: r for r in rows}, seconds


def test_a_class_of_thirty_gets_the_scores_intended(graded):
    """Every submission of the mock class gets its intended score and the note that says why;
    the corrupt file, the missing one and the one not on the roster get their rows."""
    root, rows, seconds = graded
    print(f"\ngraded {len(rows)} rows in {seconds:.0f} s")
    assert len(CLASS) >= 30
    for name, _, (pl, tr), note in CLASS:
        r = rows[f"{name}.ipynb"]
        assert (float(r["ex01_power_law"]), float(r["ex01_tresca"])) == (pl, tr), (name, r["notes"])
        assert float(r["total"]) == pl + tr and r["possible"] == "12", name
        assert note in r["notes"], (name, r["notes"])
        assert r["id"] and r["name"] == f"Student {name}"
        assert r["late"] == ("yes" if name == "late" else ""), name
    corrupt = rows[f"{CORRUPT}.ipynb"]
    assert corrupt["status"] == "not graded" and "not a notebook" in corrupt["notes"]
    assert rows["u91"]["status"] == "missing" and "no submission" in rows["u91"]["notes"]
    for r in (corrupt, rows["u91"]):  # the gradebook's columns for every student of the roster
        assert (r["lecture"], r["total"], r["possible"]) == (LECTURE, "0", "12"), r
    assert rows[f"{STRAY}.ipynb"]["id"] == "" and "not on the roster" in rows[f"{STRAY}.ipynb"]["notes"]
    assert rows["endless_cell.ipynb"]["status"] == "stopped"
    assert len(rows) == len(CLASS) + 3
    # bounded: two workers, one notebook stopped at its 20 s limit, an answer at 1 s a call
    assert seconds < 240


def test_the_class_review_and_feedback_files_are_complete(graded):
    root, rows, _ = graded
    page = (root / "scores-review" / f"{LECTURE}.html").read_text()
    sheet = list(csv.DictReader(open(root / "scores-review" / f"{LECTURE}-scores.csv")))
    for name, *_ in CLASS:
        assert f"{name} says: stiff is accurate" in page, name
        assert sum(1 for r in sheet if r["submission"] == f"{name}.ipynb") == 1
    assert page.count("<section") == len(CLASS) + 2  # the class, the stray and the corrupt one
    assert "stiffness = [1e2, 1e4]" in page
    files = sorted(p.name for p in (root / "scores-feedback").glob("*.md"))
    assert len(files) == len(rows)
    text = (root / "scores-feedback" / f"u{[c[0] for c in CLASS].index('sign'):02d}-{LECTURE}.md").read_text()
    assert (
        "Total: 8 of 12" in text
        and "the sign is wrong" in text
        and "ex01_discussion (written): to be scored, 2 points" in text
    )


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
    rows = grade(subs, tmp_path / "s.csv", jobs=2, limits=Limits(notebook=4.0))
    assert time.perf_counter() - t0 < 30
    assert rows[0]["status"] == "stopped" and "time limit 4 s for the notebook" in rows[0]["notes"]
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


def test_what_a_submission_started_ends_with_its_grading(tmp_path):
    """A notebook that starts a process of its own leaves nothing running after its grading."""
    from contactfem.lab.course import grade

    subs = tmp_path / "subs"
    subs.mkdir()
    pid_file = tmp_path / "pid"
    _notebook(
        [
            HEAD,
            PL,
            TR,
            f"import subprocess\nchild = subprocess.Popen(['sleep', '300'])\n"
            f"open({str(pid_file)!r}, 'w').write(str(child.pid))",
        ],
        subs / "a.ipynb",
    )
    row = grade(subs, tmp_path / "s.csv")[0]
    assert row["total"] == "10", row["notes"]
    pid = int(pid_file.read_text())
    deadline = time.monotonic() + 5
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(pid), f"the submission's child {pid} still runs"


def test_the_answers_own_code_is_read_for_the_library_not_the_rest_of_the_cell():
    from contactfem.lab.course.checks import LIBRARY
    from contactfem.lab.course.grade import library_named

    guard = LIBRARY["ex01_power_law"]
    names = {"power_law"}
    assert library_named(PL_LIBRARY, guard, names) == {"contactfem.laws.normal:PowerLaw"}
    assert library_named("power_law = lambda g, c, m: PowerLaw(c, m).traction(g)", guard, names)
    compare = PL + "\n\nfrom contactfem.laws import PowerLaw\nprint(PowerLaw(100.0, 2.5).traction(-0.1))"
    assert library_named(compare, guard, names) == set()
    assert library_named(PL_LIBRARY_HIDDEN, guard, names) == set()  # the tripwire catches that one


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


def test_a_library_object_holding_lambdas_reaches_the_answer(tmp_path):
    """The checks pass library objects to the answers (a scene's stepper holds lambdas, which
    pickle refuses): they reach the submission's process, and what comes back is data."""
    from contactfem.lab.course.grade import Box, Limits

    class Holder:
        pass

    h = Holder()
    h.f = lambda x: 2.0 * x
    box = Box(Limits(), tmp_path)
    try:
        assert box.cell(1, "def apply(obj, x):\n    return obj.f(x), [x]")["ok"]
        assert box.get("apply")(h, 3.0) == (6.0, [3.0])
    finally:
        box.close()


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
        if b"lab.course.sandbox" in cmd and pid in chain:
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
