"""The course as a course: a student version and an instructor version of the lectures,
and the grading of submitted notebooks, on top of otter-grader.

    contactfem course build [--instructor] [--out DIR]
    contactfem course grade FOLDER --out scores.csv [--autograders DIR] [--jobs N]

One source: each lecture in ``lectures/`` holds its exercises in otter-grader's
assignment format (raw cells ``# BEGIN QUESTION`` / ``name: exNN_...``, ``# BEGIN
SOLUTION`` ... ``# END QUESTION``, solution lines between ``# BEGIN SOLUTION`` and
``# END SOLUTION`` comments). The checks of each exercise live in
:mod:`contactfem.lab.course.checks` (parts with points and hints); :func:`build`
writes them into the notebook as otter's test cells and runs ``otter assign``:

* the **student** version (``build/course/student``): solutions replaced by ``...``,
  a check cell ``grader.check("exNN_...")`` after each answer (the checks travel in
  the notebook's metadata, so a student checks without any other file);
* the **instructor** version (``build/course/instructor``): the solutions, the same
  check cells, and in ``autograder/`` otter's grading configuration of each lecture
  (``NN_topic.zip``).

:func:`grade` runs otter's local grader (``otter run``: no server, no Docker) on every
submitted notebook of a folder and writes one CSV row per submission: the points of
each exercise, the total, the points possible and the hints of what failed.
"""

import contextlib
import csv
import io
import logging
import os
import re
import shutil
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]
QUESTION = re.compile(r"^\s*#\s*BEGIN\s+QUESTION\s*$", re.I)
END_QUESTION = re.compile(r"^\s*#\s*END\s+QUESTION\s*$", re.I)


def lecture_sources(repo=None):
    """The lecture notebooks of the checkout, in course order."""
    folder = Path(repo or REPO) / "lectures"
    if not folder.is_dir():
        raise ValueError(f"contactfem course needs a checkout of the repository: no lectures/ in {folder.parent}")
    return sorted(folder.glob("[0-9][0-9]_*.ipynb"))


def _first_line(cell):
    return cell.source.split("\n", 1)[0] if cell.source else ""


def questions(nb):
    """[(name, index of its BEGIN QUESTION cell)] of an otter-format notebook."""
    import yaml

    out = []
    for i, c in enumerate(nb.cells):
        if c.cell_type == "raw" and QUESTION.match(_first_line(c)):
            cfg = yaml.safe_load(c.source.split("\n", 1)[1]) or {}
            out.append((cfg.get("name"), i))
    return out


BEGIN_SOLUTION = re.compile(r"^\s*#\s*BEGIN\s+SOLUTION\s*$", re.I)
END_SOLUTION = re.compile(r"^\s*#\s*END\s+SOLUTION\s*$", re.I)


def solution_cells(nb):
    """{exercise: [source of each code cell of its solution]} of an otter-format notebook
    (the cells between the raw cells BEGIN SOLUTION and END SOLUTION of each question)."""
    import yaml

    out, current, inside = {}, None, False
    for c in nb.cells:
        first = _first_line(c)
        if c.cell_type == "raw" and QUESTION.match(first):
            current = (yaml.safe_load(c.source.split("\n", 1)[1]) or {}).get("name")
        elif c.cell_type == "raw" and BEGIN_SOLUTION.match(first):
            inside = True
        elif c.cell_type == "raw" and END_SOLUTION.match(first):
            inside = False
        elif c.cell_type == "raw" and END_QUESTION.match(first):
            current = None
        elif inside and current and c.cell_type == "code":
            out.setdefault(current, []).append(c.source)
    return out


def solution_lines(nb, min_length=8):
    """The lines of the solutions (between the # BEGIN SOLUTION and # END SOLUTION comments)
    that appear nowhere else in the lecture: what a student version must not contain."""
    cells = solution_cells(nb)
    lines = set()
    for sources in cells.values():
        for code in sources:
            inside = False
            for ln in code.splitlines():
                if BEGIN_SOLUTION.match(ln) or END_SOLUTION.match(ln):
                    inside = bool(BEGIN_SOLUTION.match(ln))
                    continue
                if inside and len(ln.strip()) >= min_length:
                    lines.add(ln.strip())
    solution_sources = {code for sources in cells.values() for code in sources}
    rest = "\n".join(c.source for c in nb.cells if c.source not in solution_sources)
    return sorted(ln for ln in lines if ln not in rest)


def _test_cell(part):
    """One otter test cell (exception-based format) that runs one part of the checks."""
    import nbformat

    args = ", ".join(part.answers)
    src = (f'""" # BEGIN TEST CONFIG\npoints: {part.points}\n""" # END TEST CONFIG\n'
           f"def test_{part.name}({args}):\n"
           f"    from contactfem.lab.course.checks import {part.name}\n"
           f"    {part.name}({args})")
    return nbformat.v4.new_code_cell(src)


def assignment(nb, name):
    """The otter master notebook of one lecture: an assignment configuration first, and the
    test cells of every exercise (from checks.EXERCISES) before its END QUESTION."""
    import nbformat

    from .checks import EXERCISES

    nb = nbformat.from_dict(nbformat.from_dict(nb))    # a copy
    config = nbformat.v4.new_raw_cell(
        "# ASSIGNMENT CONFIG\n"
        f"name: {name}\n"
        "init_cell: true\ncheck_all_cell: false\nexport_cell: false\nrun_tests: false\n"
        "tests:\n  files: false\n  ok_format: false\n"
        "generate:\n  pdf: false\n")
    cells, current = [config], None
    for c in nb.cells:
        if c.cell_type == "raw" and QUESTION.match(_first_line(c)):
            current = questions(nbformat.v4.new_notebook(cells=[c]))[0][0]
            if current not in EXERCISES:
                raise ValueError(f"{name}: exercise {current!r} has no checks in contactfem.lab.course.checks")
            if EXERCISES[current].lecture != name:
                raise ValueError(f"{name}: exercise {current!r} belongs to lecture {EXERCISES[current].lecture}")
            c = nbformat.v4.new_raw_cell(c.source.rstrip() + f"\npoints: {EXERCISES[current].points:g}")
        if c.cell_type == "raw" and END_QUESTION.match(_first_line(c)):
            cells.append(nbformat.v4.new_raw_cell("# BEGIN TESTS"))
            cells += [_test_cell(p) for p in EXERCISES[current].parts]
            cells.append(nbformat.v4.new_raw_cell("# END TESTS"))
            current = None
        cells.append(c)
    nb.cells = cells
    for c in nb.cells:          # otter adds ids where the format wants them
        c.pop("id", None)
    nb.nbformat_minor = 4
    return nb


@contextlib.contextmanager
def _quiet():
    """otter prints its progress and logs: keep them off the terminal."""
    buf = io.StringIO()
    level = logging.getLogger("otter").level
    logging.getLogger("otter").setLevel(logging.ERROR)
    try:
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            yield buf
    finally:
        logging.getLogger("otter").setLevel(level)


def _assign(src, work):
    """otter assign on one lecture: (student notebook, instructor notebook, autograder zip)."""
    import nbformat

    from otter.assign import main as otter_assign

    name = src.stem
    master = work / name / f"{name}.ipynb"
    master.parent.mkdir(parents=True)
    nbformat.write(assignment(nbformat.read(src, as_version=4), name), master)
    with _quiet() as log:
        try:
            otter_assign(str(master), str(master.parent / "dist"), no_pdfs=True, no_run_tests=True)
        except Exception as err:
            raise RuntimeError(f"otter assign failed on {src.name}: {err}\n{log.getvalue()[-2000:]}") from err
    dist = master.parent / "dist"
    zips = sorted((dist / "autograder").glob("*.zip"))
    return dist / "student" / f"{name}.ipynb", dist / "autograder" / f"{name}.ipynb", zips[-1]


def default_out(instructor):
    return REPO / "build" / "course" / ("instructor" if instructor else "student")


def check_out_dir(out, option="--out"):
    """A folder that can be written (made, with its parents, if missing; a file is created and
    removed there to be sure); a file there, or a place where nothing can be written, is bad
    input (ValueError naming the option). Makes nothing."""
    from ...io.outputs import check_output_dir

    return check_output_dir(out, option)


def build(out=None, instructor=False, repo=None, only=None, force=False):
    """Write the student version (or the instructor version) of every lecture into `out`;
    returns the notebooks written. Lectures without exercises are copied as they are.
    `only`: lecture names (stems) to build, default all. The student version also goes into
    one zip, OUT/contactfem-course-student.zip. A notebook in `out` that differs from what
    the build would write, and is not unchanged since an earlier build wrote it, is not
    overwritten: ValueError naming it, nothing written; with `force` it is moved to
    OUT/backup-<time>/ first."""
    version = "instructor" if instructor else "student"
    return build_versions({version: out or default_out(instructor)}, repo=repo, only=only, force=force)[version]


def build_versions(outs, repo=None, only=None, force=False, work=None, on_write=None):
    """Both versions in one pass (otter assign runs once per lecture): `outs` maps
    "student" and/or "instructor" to a folder. Returns {version: [notebooks written]}.
    Every folder is checked before any work, and every notebook it would replace after the
    notebooks are made and before any is written (see :mod:`.handout`); the notebooks of
    all versions are then written together, with Ctrl-C held back. `work`: the folder for
    otter's work (default: a temporary folder of the system); `on_write`: called with no
    argument once the writing has begun, with Ctrl-C held back until every file is written
    (the command line's account of what an interrupt leaves)."""
    import nbformat

    from ...io.outputs import hold_interrupts
    from . import handout

    outs = {v: check_out_dir(o) for v, o in outs.items()}
    sources = [s for s in lecture_sources(repo) if only is None or s.stem in only]
    for version, out in outs.items():
        handout.check_version(out, version)
    if not force:                                # a notebook changed since the last build: refused before work
        for out in outs.values():
            changed = handout.changed_since_built(out, [s.name for s in sources])
            if changed:
                raise ValueError(handout.refusal(out, changed))
    if work is not None:
        Path(work).mkdir(parents=True, exist_ok=True)
    written = {v: [] for v in outs}
    with tempfile.TemporaryDirectory(prefix="contactfem-course-", dir=work) as tmp:
        plan = {v: {} for v in outs}             # version: {name in out: file made here}
        for src in sources:
            built = None
            if questions(nbformat.read(src, as_version=4)):
                built = _assign(src, Path(tmp))
            for version in outs:
                if built is None:
                    plan[version][src.name] = src
                elif version == "student":
                    plan[version][src.name] = built[0]
                else:
                    plan[version][src.name] = built[1]
                    plan[version][f"autograder/{src.stem}.zip"] = built[2]
        if "student" in plan:
            notebooks = [p for n, p in plan["student"].items() if n.endswith(".ipynb")]
            plan["student"][handout.STUDENT_ZIP] = handout.student_zip(notebooks, Path(tmp) / handout.STUDENT_ZIP)
        guarded = {v: {n: p for n, p in files.items() if not n.startswith("autograder/")} for v, files in plan.items()}
        found = {v: handout.conflicts(outs[v], guarded[v]) for v in outs}
        if not force:
            for v, names in found.items():
                if names:
                    raise ValueError(handout.refusal(outs[v], names))
        with hold_interrupts():                  # all notebooks of the build, or none of them
            if on_write:
                on_write()
            for version, out in outs.items():
                out.mkdir(parents=True, exist_ok=True)
                if found[version]:
                    kept = handout.back_up(out, found[version])
                    print(f"contactfem: note: {len(found[version])} changed file(s) kept in {kept}", file=sys.stderr)
                for name, made in plan[version].items():
                    (out / name).parent.mkdir(parents=True, exist_ok=True)
                    shutil.copy2(made, out / name)
                    if name.endswith(".ipynb"):
                        written[version].append(out / name)
                handout.write_manifest(out, version, guarded[version])
    return written


# -- grading ------------------------------------------------------------------------------

def submissions(folder):
    """The notebooks of a folder of submissions (subfolders included), sorted."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"course grade: {folder} is not a folder of submitted notebooks")
    found = sorted(p for p in folder.rglob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
    if not found:
        raise ValueError(f"course grade: no notebooks (*.ipynb) in {folder}")
    return found


def lecture_of(path, names):
    """The lecture a submitted notebook answers: otter's assignment name in its metadata,
    else the NN_ prefix of its file name. None if neither names a lecture."""
    import json

    try:
        meta = json.loads(Path(path).read_text()).get("metadata", {})
        name = meta.get("otter", {}).get("assignment_name")
    except (ValueError, OSError, AttributeError):
        name = None
    if name in names:
        return name
    m = re.match(r"(\d\d)_", Path(path).name)
    hits = [n for n in names if m and n.startswith(m.group(1) + "_")]
    return hits[0] if len(hits) == 1 else None


def _grade_one(path, zip_path):
    """otter's local grading of one notebook: ({exercise: points}, {exercise: possible}, notes)."""
    import otter.api

    with _quiet(), _quiet_fds():
        res = otter.api.grade_submission(str(path), str(zip_path), quiet=True)
    scores, possible, notes = {}, {}, []
    for name, r in res.results.items():
        scores[name], possible[name] = float(r.score), float(r.possible)
        failed = [tcr for tcr in r.test_case_results if not tcr.passed]
        if failed:      # the first failing part's hint; the others usually repeat it
            msg = failed[0].message.strip()
            hint = msg.split("AssertionError: ", 1)[1] if "AssertionError: " in msg else msg.splitlines()[-1]
            hint = " ".join(hint.split())
            more = f" (and {len(failed) - 1} more part{'s' if len(failed) > 2 else ''})" if len(failed) > 1 else ""
            notes.append(f"{name}: {hint}{more}")
    return scores, possible, notes


@contextlib.contextmanager
def _quiet_fds():
    """The kernel that otter starts writes its warnings to the process's own stderr: send
    file descriptors 1 and 2 to /dev/null while it runs."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved + [null]:
            os.close(fd)


# A kernel that dies before it answers its first request never ran the submission: with gradings
# in parallel, two kernels starting at once may pick the same free ports (jupyter_client chooses
# them before the kernel binds them), and the loser exits. Such a start is tried again, up to
# KERNEL_START_TRIES times; a kernel that dies while it runs the submission is the submission's.
KERNEL_START_TRIES = 3


def _safe_grade(args):
    path, zip_path = args
    for attempt in range(KERNEL_START_TRIES):
        try:
            return _grade_one(path, zip_path)
        except Exception as err:             # a broken submission is a row with its reason, not a crash
            if "before replying to kernel_info" in str(err) and attempt + 1 < KERNEL_START_TRIES:
                continue
            return None, None, [f"not graded: {type(err).__name__}: {' '.join(str(err).split())[:300]}"]


def grade(folder, out_csv, autograders=None, jobs=1, repo=None):
    """Grade every notebook in `folder` with otter (locally, no Docker) and write `out_csv`:
    one row per submission, one column per exercise, then total, possible and notes (the
    hints of the parts that failed). `autograders`: a folder of NN_topic.zip (the instructor
    build's autograder/); default: built here from the lectures. Returns the rows."""
    from ...io.outputs import check_output_path
    from .checks import EXERCISES

    subs = submissions(folder)
    out_csv = check_output_path(out_csv, "--out", (".csv",))
    if jobs < 1:
        raise ValueError(f"--jobs {jobs}: give a number of parallel gradings >= 1")
    names = [s.stem for s in lecture_sources(repo)]
    if autograders is not None:
        autograders = Path(autograders)
        if not autograders.is_dir() or not list(autograders.glob("*.zip")):
            raise ValueError(f"--autograders {autograders}: no grading configurations (*.zip) there; "
                             "give the autograder/ folder of `contactfem course build --instructor`")
    which = {p: lecture_of(p, names) for p in subs}
    with tempfile.TemporaryDirectory(prefix="contactfem-grade-") as tmp:
        if autograders is None:
            needed = sorted({w for w in which.values() if w})
            build(Path(tmp) / "instructor", instructor=True, repo=repo, only=needed)
            autograders = Path(tmp) / "instructor" / "autograder"
        todo = [(p, autograders / f"{w}.zip") for p, w in which.items() if w and (autograders / f"{w}.zip").exists()]
        if jobs > 1 and len(todo) > 1:
            with ProcessPoolExecutor(max_workers=jobs) as pool:
                done = dict(zip([p for p, _ in todo], pool.map(_safe_grade, todo)))
        else:
            done = {p: _safe_grade((p, z)) for p, z in todo}
    columns = [e for e in EXERCISES if EXERCISES[e].lecture in set(which.values())]
    rows = []
    for p in subs:
        lec = which[p]
        row = {"submission": str(p.relative_to(folder)), "lecture": lec or ""}
        if lec is None:
            scores, possible, notes = {}, {}, ["not graded: not a lecture of this course (no otter assignment "
                                               "name in its metadata, no NN_ prefix)"]
        elif p not in done:
            scores, possible, notes = {}, {}, [f"not graded: lecture {lec} has no exercises"]
        else:
            scores, possible, notes = done[p]
            scores, possible = scores or {}, possible or {}
        for e in columns:
            row[e] = f"{scores[e]:g}" if e in scores else ("0" if EXERCISES[e].lecture == lec else "")
        mine = [e for e in EXERCISES if EXERCISES[e].lecture == lec]
        row["total"] = f"{sum(scores.get(e, 0.0) for e in mine):g}"
        row["possible"] = f"{sum(EXERCISES[e].points for e in mine):g}"
        row["notes"] = " | ".join(notes)
        rows.append(row)
    tmp_csv = out_csv.with_name(f".{out_csv.name}.part")
    with open(tmp_csv, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["submission", "lecture"] + columns + ["total", "possible", "notes"])
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp_csv, out_csv)
    return rows
