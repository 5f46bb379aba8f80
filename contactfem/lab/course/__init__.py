"""The course as a course: a student version and an instructor version of the lectures,
and the grading of submitted notebooks, on top of otter-grader.

    contactfem course build [--instructor] [--out DIR]
    contactfem course grade FOLDER --out scores.csv [--autograders DIR] [--jobs N]

One source: each lecture in ``lectures/`` holds its exercises in otter-grader's
assignment format (raw cells ``# BEGIN QUESTION`` / ``name: exNN_...``, ``# BEGIN
SOLUTION`` ... ``# END QUESTION``, solution lines between ``# BEGIN SOLUTION`` and
``# END SOLUTION`` comments). The checks of each exercise live in
:mod:`contactfem.lab.course.checks`, one module per lecture (parts with points and hints);
:func:`build`
writes them into the notebook as otter's test cells and runs ``otter assign``:

* the **student** version (``build/course/student``): solutions replaced by ``...``,
  a check cell ``grader.check("exNN_...")`` after each answer (the checks travel in
  the notebook's metadata, so a student checks without any other file);
* the **instructor** version (``build/course/instructor``): the solutions, the same
  check cells, and in ``autograder/`` otter's grading configuration of each lecture
  (``NN_topic.zip``).

:func:`grade` (:mod:`contactfem.lab.course.grade`) grades every submitted notebook of a
folder, each in a sandbox of its own (:mod:`.sandbox`) with the students' edition of the library
(:mod:`.edition`), the checks outside it, and writes one CSV row per submission: the points of
each exercise, the total, the points possible and the hints.
"""

import contextlib
import io
import logging
import re
import shutil
import sys
import tempfile
from pathlib import Path

from .lectures import REPO, lecture_sources  # noqa: F401  (lecture_sources: the package's name for it)

QUESTION = re.compile(r"^\s*#\s*BEGIN\s+QUESTION\s*$", re.I)
END_QUESTION = re.compile(r"^\s*#\s*END\s+QUESTION\s*$", re.I)


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
    src = (
        f'""" # BEGIN TEST CONFIG\npoints: {part.points}\n""" # END TEST CONFIG\n'
        f"def test_{part.name}({args}):\n"
        f"    from {part.check.__module__} import {part.name}\n"
        f"    {part.name}({args})"
    )
    return nbformat.v4.new_code_cell(src)


def assignment(nb, name):
    """The otter master notebook of one lecture: an assignment configuration first, and the
    test cells of every exercise (from checks.EXERCISES) before its END QUESTION."""
    import nbformat

    from .checks import EXERCISES

    nb = nbformat.from_dict(nbformat.from_dict(nb))  # a copy
    config = nbformat.v4.new_raw_cell(
        "# ASSIGNMENT CONFIG\n"
        f"name: {name}\n"
        "init_cell: true\ncheck_all_cell: false\nexport_cell: false\nrun_tests: false\n"
        "tests:\n  files: false\n  ok_format: false\n"
        "generate:\n  pdf: false\n"
    )
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
    for c in nb.cells:  # otter adds ids where the format wants them
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
    if not force:  # a notebook changed since the last build: refused before work
        for out in outs.values():
            changed = handout.changed_since_built(out, [s.name for s in sources])
            if changed:
                raise ValueError(handout.refusal(out, changed))
    if work is not None:
        Path(work).mkdir(parents=True, exist_ok=True)
    written = {v: [] for v in outs}
    with tempfile.TemporaryDirectory(prefix="contactfem-course-", dir=work) as tmp:
        plan = {v: {} for v in outs}  # version: {name in out: file made here}
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
        examples = sorted((Path(repo or REPO) / "lectures" / "examples").glob("*.*"))
        for version in plan:  # the files the lectures read (a scene file, its mesh)
            plan[version].update({f"examples/{f.name}": f for f in examples if f.is_file()})
        hidden = Path(repo or REPO) / "lectures" / "hidden_checks"
        if "instructor" in plan:  # the hidden checks: instructor material only
            plan["instructor"].update({f"autograder/hidden_checks/{f.name}": f for f in sorted(hidden.glob("*.py"))})
        if "student" in plan:
            notebooks = [p for n, p in plan["student"].items() if n.endswith(".ipynb")]
            extras = [(n, p) for n, p in plan["student"].items() if n.startswith("examples/")]
            plan["student"][handout.STUDENT_ZIP] = handout.student_zip(
                notebooks, Path(tmp) / handout.STUDENT_ZIP, extras
            )
        guarded = {v: {n: p for n, p in files.items() if not n.startswith("autograder/")} for v, files in plan.items()}
        found = {v: handout.conflicts(outs[v], guarded[v]) for v in outs}
        if not force:
            for v, names in found.items():
                if names:
                    raise ValueError(handout.refusal(outs[v], names))
        with hold_interrupts():  # all notebooks of the build, or none of them
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


# -- grading: contactfem.lab.course.grade -------------------------------------------------------

from .grade import GradingInterrupted, grade, lecture_of  # noqa: E402,F401
from .sandbox import Limits, NoSandbox  # noqa: E402,F401
