"""What `contactfem course build` writes and what it never destroys: a rebuild refuses to
overwrite a notebook that was answered or edited (one line naming it, exit 2, nothing
written) and with --force keeps it in a backup; the student version is also one zip, the
handout, that holds no solution; every output is checked before the work; a Ctrl-C says
what was written. And the course guide's account of the course against the code.

Needs the course extra (otter-grader): skipped without it, except on CI (CI=true).
"""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # end-to-end: command lines and processes (the fast tier leaves them out)

ON_CI = os.environ.get("CI", "").lower() in ("true", "1", "yes")
REPO = Path(__file__).resolve().parents[1]
LEC = "01_interface_laws"


@pytest.fixture(autouse=True)
def _otter():
    if ON_CI:
        import otter  # noqa: F401
    else:
        pytest.importorskip("otter")


def _answer(path, text="def power_law(g):\n    return 42  # my answer\n"):
    """The notebook at `path` with its first answer cell (the one before a check cell) filled in."""
    nb = json.loads(path.read_text())
    cells = nb["cells"]
    i = next(i for i, c in enumerate(cells) if c["cell_type"] == "code" and "grader.check(" in "".join(c["source"]))
    j = max(k for k in range(i) if cells[k]["cell_type"] == "code")
    cells[j]["source"] = text
    path.write_text(json.dumps(nb))


def _main(argv, capsys):
    from contactfem.cli import main

    capsys.readouterr()
    code = main(argv)
    return code, capsys.readouterr().err.strip().splitlines()


def test_a_rebuild_refuses_to_overwrite_an_answered_notebook(tmp_path, capsys):
    """A student's answers in the output folder: the rebuild stops with one line naming the
    notebook (exit 2) and writes nothing; --force moves it to a backup and writes the
    fresh one; an unchanged rebuild goes through."""
    out = tmp_path / "student"
    assert _main(["course", "build", "--out", str(out)], capsys)[0] == 0
    fresh = (out / f"{LEC}.ipynb").read_bytes()
    assert _main(["course", "build", "--out", str(out)], capsys)[0] == 0  # nothing changed: replaced
    _answer(out / f"{LEC}.ipynb")
    answered = (out / f"{LEC}.ipynb").read_bytes()
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    code, err = _main(["course", "build", "--out", str(out)], capsys)
    assert code == 2 and len(err) == 1, err
    assert f"{LEC}.ipynb" in err[0] and "--force" in err[0], err
    assert (out / f"{LEC}.ipynb").read_bytes() == answered
    assert {p.name: p.stat().st_mtime_ns for p in out.iterdir()} == before  # nothing written at all
    code, err = _main(["course", "build", "--out", str(out), "--force"], capsys)
    assert code == 0, err
    backups = list(out.glob(f"backup-*/{LEC}.ipynb"))
    assert len(backups) == 1 and backups[0].read_bytes() == answered
    assert (out / f"{LEC}.ipynb").read_bytes() == fresh
    assert any(str(backups[0].parent) in line for line in err), err


def test_a_folder_of_work_is_not_built_over(tmp_path):
    """--out on a folder that holds a notebook of a lecture's name that the build did not
    write: refused after the notebooks are made and before anything is written. Replaced
    without fuss: a copy that is exactly what the build writes, and a notebook an earlier
    build wrote that nobody changed since (the lecture did)."""
    from contactfem.lab.course import build, handout

    made = build(tmp_path / "made", only=[LEC])[0]
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy2(made, work / made.name)
    _answer(work / made.name)
    answered = (work / made.name).read_bytes()
    with pytest.raises(ValueError, match=rf"^--out {re.escape(str(work))}: {LEC}.ipynb differs from what the build"):
        build(work, only=[LEC])
    assert sorted(p.name for p in work.iterdir()) == [made.name] and (work / made.name).read_bytes() == answered
    same = tmp_path / "same"
    same.mkdir()
    shutil.copy2(made, same / made.name)
    assert build(same, only=[LEC]) == [same / made.name]
    older = tmp_path / "older"  # what an earlier build wrote, untouched: the lecture changed since
    older.mkdir()
    (older / made.name).write_text('{"an": "older build"}')
    handout.write_manifest(older, "student", [made.name])
    assert build(older, only=[LEC]) == [older / made.name]
    assert (older / made.name).read_bytes() == made.read_bytes() and not list(older.glob("backup-*"))


def _no_work(*args, **kwargs):
    raise AssertionError("the work started before the outputs were checked")


@pytest.mark.parametrize(
    "argv, pattern",
    [
        (["course", "build", "--out", "/proc/x"], r"^contactfem: error: --out /proc/x: cannot write in /proc"),
        (["course", "build", "--out", "{file}/sub"], r"--out .*/sub: .* is a file"),
        (
            ["course", "build", "--instructor", "--out", "{student}"],
            r"--out .*: holds the student version of the course; build the instructor version into another folder",
        ),
        (["course", "build", "--out", "{changed}"], rf"--out .*: {LEC}.ipynb differs from what the build would write"),
        (["site", "--out", "/proc/x"], r"^contactfem: error: --out /proc/x: cannot write in /proc"),
        (["site", "--out", "{dir}"], r"--out .*: holds files that are not a site built by contactfem site \(a_file, "),
    ],
)
def test_course_and_site_check_their_outputs_before_any_work(argv, pattern, tmp_path, monkeypatch, capsys):
    """One line, exit code 2, and the work (otter assign, the site's staging) never started."""
    import contactfem.lab.course as course
    import contactfem.lab.site.pages as pages
    from contactfem.lab.course import handout

    (tmp_path / "a_file").write_text("")
    for name in ("student", "changed"):  # folders an earlier build wrote (recorded)
        folder = tmp_path / name
        folder.mkdir()
        (folder / f"{LEC}.ipynb").write_text("{}")
        handout.write_manifest(folder, "student", [f"{LEC}.ipynb"])
    (tmp_path / "changed" / f"{LEC}.ipynb").write_text('{"answered": 1}')
    monkeypatch.setattr(course, "_assign", _no_work)
    monkeypatch.setattr(pages, "stage", _no_work)
    argv = [
        a.format(file=tmp_path / "a_file", dir=tmp_path, student=tmp_path / "student", changed=tmp_path / "changed")
        for a in argv
    ]
    code, err = _main(argv, capsys)
    assert code == 2 and len(err) == 1 and re.search(pattern, err[0]), err


def test_the_student_zip_holds_no_solution(tmp_path):
    """The handout of `course build`: every lecture's student notebook and a page for students, and in
    none of its files any `BEGIN SOLUTION` marker or any line of any solution (each found in
    the instructor version, so the search can fail)."""
    import nbformat

    from contactfem.lab.course import build_versions, lecture_sources, solution_lines
    from contactfem.lab.course.handout import STUDENT_GUIDE, STUDENT_ZIP

    outs = {"student": tmp_path / "student", "instructor": tmp_path / "instructor"}
    build_versions(outs)
    with zipfile.ZipFile(outs["student"] / STUDENT_ZIP) as z:
        files = {Path(n).name: z.read(n).decode() for n in z.namelist()}
    sources = lecture_sources()
    examples = sorted(f.name for f in (REPO / "lectures" / "examples").glob("*.*"))
    assert sorted(files) == sorted(
        [STUDENT_GUIDE] + [s.name for s in sources] + examples
    )  # the lectures' example files too
    nbs = {s.name: nbformat.read(s, as_version=4) for s in sources}
    public = {name: _public_text(nb) for name, nb in nbs.items()}  # a lecture may show another's line as text
    searched = 0
    for src in sources:
        teacher = (outs["instructor"] / src.name).read_text()
        for line in solution_lines(nbs[src.name]):
            for form in (line, json.dumps(line)[1:-1]):  # as written, and as a notebook's JSON holds it
                holders = [n for n, text in files.items() if form in text and line not in public.get(n, "")]
                assert not holders, f"{holders} hold {line!r}, a line of the solutions of {src.name}"
            assert json.dumps(line)[1:-1] in teacher
            searched += 1
    assert searched > 100, searched
    for name, text in files.items():
        assert not re.search(r"BEGIN\s+SOLUTION|END\s+SOLUTION", text, re.I), name
    assert files[f"{LEC}.ipynb"] == (outs["student"] / f"{LEC}.ipynb").read_text()
    # the hidden checks are the instructor's material: in its autograder/, nowhere in the student's
    sources = sorted((REPO / "lectures" / "hidden_checks").glob("*.py"))
    for f in sources:
        assert (outs["instructor"] / "autograder" / "hidden_checks" / f.name).read_text() == f.read_text()
    assert not list(outs["student"].rglob("hidden_checks*"))
    hidden = "\n".join(f.read_text() for f in sources)
    defs = [ln.strip() for ln in hidden.splitlines() if ln.startswith("def ")]
    assert defs and not any(d in text for d in defs for text in files.values())


def _public_text(nb):
    """The text of a lecture outside its solution cells (what its student version may show)."""
    from contactfem.lab.course import solution_cells

    hidden = {code for sources in solution_cells(nb).values() for code in sources}
    return "\n".join(c.source for c in nb.cells if c.source not in hidden)


def test_ctrl_c_during_the_course_build_says_nothing_was_written(tmp_path):
    """SIGINT while otter makes the notebooks (its work folder exists): one line that says
    where and that nothing was written, exit 130, the output folder empty, no work left."""
    tmp, out = tmp_path / "tmp", tmp_path / "out"
    tmp.mkdir()
    env = dict(os.environ, TMPDIR=str(tmp), PYTHONPATH=str(REPO))
    p = subprocess.Popen(
        [sys.executable, "-m", "contactfem", "course", "build", "--out", str(out)],
        env=env,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    t0 = time.monotonic()
    while p.poll() is None and not list(tmp.glob("contactfem-course-*/*")) and time.monotonic() - t0 < 120:
        time.sleep(0.01)
    assert p.poll() is None, p.communicate()
    os.killpg(p.pid, signal.SIGINT)  # as Ctrl-C in a terminal: the whole group
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert err.strip() == f"contactfem: interrupted during the course build; nothing written in {out}", err
    assert not out.exists() or list(out.iterdir()) == []
    assert list(tmp.iterdir()) == []


def test_every_lecture_has_exercises():
    """Every lecture ends with graded exercises (the front page counts them from the checks' register:
    tests/test_readme.py)."""
    from contactfem.lab.course import lecture_sources
    from contactfem.lab.course.checks import EXERCISES

    assert {e.lecture for e in EXERCISES.values()} == {s.stem for s in lecture_sources()}
    assert 0 < sum(e.implements for e in EXERCISES.values()) <= len(EXERCISES)


def test_the_course_guide_sends_students_to_the_handout():
    """The course guide names the handout the build writes, tells students to use it and instructors
    the checkout, and says that the repository holds the solutions."""
    from contactfem.lab.course.handout import STUDENT_ZIP

    guide = (REPO / "lectures" / "README.md").read_text()
    assert "**This folder of the repository, `lectures/`, holds the solutions**" in guide
    assert STUDENT_ZIP in guide
    assert re.search(r"[Ii]nstructors work in a checkout", guide)
    assert f"**Hand out** `{STUDENT_ZIP}`, never the checkout" in guide
    assert not re.search(r"instructor and students\)?:? `python -m pip install -e", guide)
