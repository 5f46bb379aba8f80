"""The grading of submitted notebooks: one row a student, whatever the submission does.

    contactfem course grade FOLDER --out scores.csv [--roster R.csv] [--deadline T] [--jobs N]

In this order, before any submission runs: the options are checked; the sandbox is tried
(:func:`.sandbox.check_sandbox`: without one, grading refuses, unless ``--unsafe-no-sandbox``);
every submission is copied into a private staging folder (:mod:`.snapshot`: regular files only,
each with its hash and the time it was received, by which lateness is judged); the hidden checks
are read (:mod:`.hidden`) and a seed for their parameters drawn; and the students' edition of
the library is written for each lecture (:mod:`.edition`).

Then each copy is graded in a worker of :func:`contactfem.lab.batch.run_batch`: its code cells
run in its sandbox (:mod:`.sandbox`), and the worker, which holds the checks, calls the
student's answers there, sending arguments and receiving results as plain data. A part of an
exercise scores its points when its public check and its hidden checks pass. The answers are
graded with the students' edition of the library: what an exercise asks for is not in it.

The CSV, the review files and the feedback files are written by the grader alone, each through
a temporary file renamed into place; the CSV is final when :func:`grade` returns, since nothing
a submission started outlives its sandbox.
"""

import csv
import datetime as dt
import json
import re
import secrets
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from ...io.outputs import make_parents, own_dir, write_atomic
from .checks import EXERCISES, LIBRARY, MANUAL, answers, runs
from .edition import PACKAGE, build_edition
from .hidden import FOLDER, hidden_folder, load_hidden, read_hidden, rng_for
from .sandbox import Box, Limits, NoSandbox, Stopped, check_sandbox
from .review import csv_text, read_manual_scores, write_feedback, write_reviews
from .snapshot import MAX_BYTES, take

REPO = PACKAGE.parent

from .lectures import lecture_sources

MANUAL_MARK = re.compile(r"<!--\s*manual:\s*(\w+)\s*-->")
UNSAFE = "graded without a sandbox (--unsafe-no-sandbox)"


# -- one notebook ------------------------------------------------------------------------------


def read_notebook(path):
    """The notebook's cells [(type, source)]; ValueError if it is not a notebook."""
    try:
        nb = json.loads(Path(path).read_text(errors="replace"))
        cells = [
            (c.get("cell_type"), "".join(c["source"]) if isinstance(c["source"], list) else c["source"])
            for c in nb["cells"]
        ]
        if not all(isinstance(kind, str) and isinstance(source, str) for kind, source in cells):
            raise TypeError("a cell that is not text")
        return cells, nb.get("metadata", {})
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        raise ValueError(f"not a notebook ({type(err).__name__}: {' '.join(str(err).split())[:80]})") from None


def manual_answers(cells):
    """{question: (code, written answer)} of the written questions (a markdown cell holding
    ``<!-- manual: NAME -->`` is the prompt; the cells after it, up to the next heading or
    prompt, are the answer)."""
    out, current = {}, None
    for kind, src in cells:
        m = MANUAL_MARK.search(src) if kind == "markdown" else None
        if m:
            current = m.group(1)
            out[current] = ([], [])
            continue
        if current is None:
            continue
        if kind == "raw" or (kind == "markdown" and src.lstrip().startswith("#")) or "grader.check" in src:
            current = None
            continue
        out[current][0 if kind == "code" else 1].append(src.strip())
    return {
        k: ("\n\n".join(c for c in code if c), "\n\n".join(t for t in text if t)) for k, (code, text) in out.items()
    }


def grade_notebook(path, lecture, hidden_source, seed, limits, edition, unsafe):
    """Grade one notebook (the function the batch's workers run): a dict with the parts
    [(exercise, part, points scored, points possible, message)], the cells that failed, how many
    cells used what the exercises ask for, what it printed, and `stopped` (why the sandbox ended
    early, or None)."""
    t0 = time.monotonic()
    cells, _ = read_notebook(path)
    hidden = load_hidden(hidden_source, lecture) if hidden_source else {}
    answers.TIME_LIMIT = limits.check
    runs._MEMO.clear()
    mine = [e for e in EXERCISES.values() if e.lecture == lecture]
    out = {"parts": [], "errors": [], "left_out": 0, "stopped": None, "printed": 0}
    with tempfile.TemporaryDirectory(prefix="contactfem-sandbox-") as work:
        try:
            box = Box(limits, edition, work, unsafe=unsafe)
        except NoSandbox as err:
            out["stopped"] = f"the sandbox did not start: {err}"
            out["parts"] = [(e.name, p.name, 0.0, p.points, out["stopped"]) for e in mine for p in e.parts]
            return out
        try:
            for i, (kind, src) in enumerate(cells, 1):
                if kind != "code":
                    continue
                try:
                    r = box.cell(i, src)
                except Stopped:
                    break
                out["printed"] = r.get("printed", 0) if isinstance(r.get("printed"), int) else 0
                if r.get("left_out") is True:
                    out["left_out"] += 1
                elif not r.get("ok"):
                    out["errors"].append(f"cell {i}: {str(r.get('error') or r.get('msg'))[:200]}")
            for e in mine:
                for p in e.parts:
                    out["parts"].append((e.name, p.name, *_grade_part(box, p, hidden.get(p.name, ()), seed)))
        finally:
            box.close()
            out["stopped"] = box.dead
    out["seconds"] = time.monotonic() - t0
    return out


def _grade_part(box, part, hidden, seed):
    """(points, possible, message) of one part: its public check and its hidden checks, in this
    process, on the submission's answers."""
    msg = "passed"
    try:
        env = {a: box.get(a) for a in part.answers}
        part.check(**env)
        for check in hidden:
            check(**env, rng=rng_for(seed, part.name, check.__name__))
    except AssertionError as err:
        msg = " ".join(str(err).split())
    except Stopped as err:
        msg = str(err)
    except Exception as err:  # noqa: BLE001  (an answer the check did not foresee: the part fails)
        msg = f"the check could not use your answer: {type(err).__name__}: {' '.join(str(err).split())[:200]}"
    return (part.points if msg == "passed" else 0.0), part.points, msg


# -- the batch -----------------------------------------------------------------------------------


def lecture_of(path, names):
    """The lecture a submitted notebook answers: otter's assignment name in its metadata,
    else the NN_ prefix of its file name. None if neither names a lecture."""
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


@dataclass(frozen=True)
class Student:
    id: str
    name: str
    file: str
    submitted: str = ""


def read_roster(path):
    """The roster: a CSV with the columns id, name, file (the submission's path in the
    folder, may be empty) and, optionally, submitted (an ISO time)."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"--roster {path}: no such file; give a CSV with the columns id, name, file")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = {"id", "name", "file"} - set(reader.fieldnames or ())
        if missing:
            raise ValueError(
                f"--roster {path}: no column {', '.join(sorted(missing))}; give the columns id, name, file"
            )
        rows = [
            Student(r["id"].strip(), r["name"].strip(), (r["file"] or "").strip(), (r.get("submitted") or "").strip())
            for r in reader
        ]
    ids = [s.id for s in rows]
    if "" in ids or len(set(ids)) != len(ids):
        raise ValueError(f"--roster {path}: every student needs an id of their own")
    for s in rows:
        if s.submitted:
            parse_time(s.submitted, f"--roster {path}: submitted of {s.id}")
    return rows


def parse_time(text, what="--deadline"):
    try:
        t = dt.datetime.fromisoformat(text)
    except ValueError:
        raise ValueError(f"{what} {text!r}: give an ISO time, e.g. 2026-12-03T23:59") from None
    return t if t.tzinfo else t.astimezone()


def _late(submitted, deadline):
    late = (submitted - deadline).total_seconds()
    if late <= 0:
        return ""
    h, m = divmod(int(late // 60), 60)
    return f"{h} h {m:02d} min" if h else f"{m} min" if m else f"{int(late)} s"


class GradingInterrupted(KeyboardInterrupt):
    """Ctrl-C during the batch; `message` says what was written."""

    def __init__(self, message):
        super().__init__(message)
        self.message = message


def grade(
    folder,
    out_csv,
    autograders=None,
    jobs=1,
    repo=None,
    roster=None,
    deadline=None,
    lecture=None,
    limits=Limits(),
    review=None,
    feedback=None,
    progress=None,
    seed=None,
    unsafe_no_sandbox=False,
    max_bytes=MAX_BYTES,
):
    """Grade every notebook in `folder` and write `out_csv`: one row per submission (and per
    student of the roster), columns id, name, submission, lecture, one per exercise and written
    question, total, possible, status, late, notes. The review files of the written answers go
    to `review`, a feedback file per student to `feedback` (default: next to the CSV, named
    after it). `seed`: of the hidden checks' parameters (default: drawn afresh). Without a
    sandbox, NoSandbox (a ValueError) before any work, unless `unsafe_no_sandbox`. Returns
    the rows."""
    from ...io.outputs import check_output_dir, check_output_path

    out_csv = check_output_path(out_csv, "--out", (".csv",))
    if jobs < 1:
        raise ValueError(f"--jobs {jobs}: give a number of parallel gradings >= 1")
    if seed is not None and not 0 <= seed < 2**63:
        raise ValueError(f"--seed {seed}: give an integer from 0 to 2**63 - 1")
    for what, v in (("--notebook-timeout", limits.notebook), ("--check-timeout", limits.check)):
        if not v > 0:
            raise ValueError(f"{what} {v}: give a time limit in seconds > 0")
    if limits.memory is not None and limits.memory < 2**28:
        raise ValueError(f"--memory {limits.memory / 2**20:.0f} MB: give at least 256 MB (or 0 for no limit)")
    names = [s.stem for s in lecture_sources(repo)]
    if lecture is not None and lecture not in names:
        raise ValueError(f"--lecture {lecture}: not a lecture of this course ({', '.join(names)})")
    if autograders is not None:
        autograders = Path(autograders)
        if not autograders.is_dir() or not (list(autograders.glob("*.zip")) or (autograders / FOLDER).is_dir()):
            raise ValueError(
                f"--autograders {autograders}: no grading configurations (*.zip, {FOLDER}/) "
                "there; give the autograder/ folder of `contactfem course build --instructor`"
            )
    students = read_roster(roster) if roster else None
    deadline = parse_time(deadline) if isinstance(deadline, str) else deadline
    review = Path(review) if review else out_csv.with_name(out_csv.stem + "-review")
    feedback = Path(feedback) if feedback else out_csv.with_name(out_csv.stem + "-feedback")
    from .snapshot import notebooks

    for path, what in ((review, "--review"), (feedback, "--feedback")):
        check_output_dir(path, what)
        if path.is_symlink():
            raise ValueError(f"{what} {path}: a symbolic link; give a real folder")
    notebooks(folder)  # a folder with notebooks, or ValueError
    sources = read_hidden(hidden_folder(autograders, repo))
    for lec, text in sources.items():  # each file loads (ValueError naming it), before any work
        load_hidden(text, lec)
    scores_read = {}  # the instructor's scores of the written answers, read before any work
    for lec in names:
        sheet = review / f"{lec}-scores.csv"
        scores_read[lec] = read_manual_scores(sheet) if sheet.is_file() else {}
    staging = Path(tempfile.mkdtemp(prefix="contactfem-grade-"))  # the grader's own: mode 0700
    try:
        if not unsafe_no_sandbox:
            try:
                check_sandbox(staging)
            except NoSandbox as err:
                raise NoSandbox(
                    f"course grade: no sandbox here ({err}); every submission runs in bubblewrap, which needs Linux "
                    "with user namespaces (--unsafe-no-sandbox grades without one)"
                ) from None
        received = take(folder, staging / "submissions", max_bytes)  # before any submission runs
        read = {rel: _read(r) for rel, r in received.items()}  # the copies as the grader reads them
        seed = secrets.randbits(63) if seed is None else seed
        entries, which, graded = _entries(received, read, students, names, lecture)
        editions = {
            lec: build_edition(staging / f"edition-{lec}", left_out(lec), Path(repo or REPO) / "lectures" / "examples")
            for lec in sorted(set(graded.values()))
        }
        tasks = [
            (rel, (str(received[rel].copy), lec, sources.get(lec), seed, limits, str(editions[lec]), unsafe_no_sandbox))
            for rel, lec in graded.items()
        ]
        results, interrupted = _run(tasks, jobs, limits, progress)
    finally:
        shutil.rmtree(staging, ignore_errors=True)

    lectures = sorted({w for w in which.values() if w} | ({lecture} if lecture else set()))
    columns = [e for e in EXERCISES if EXERCISES[e].lecture in lectures]
    manual = [m for m in MANUAL if MANUAL[m].lecture in lectures]
    rows, details = [], []
    for s, r in entries:
        if interrupted and r is not None and r.rel in graded and r.rel not in results:
            continue
        lec = which.get(r.rel) if r is not None else (lecture or (lectures[0] if len(lectures) == 1 else ""))
        outcome, written = (results.get(r.rel), read[r.rel]) if r else (None, None)
        row, detail = _row(s, r, written, lec, outcome, columns, manual, scores_read, deadline)
        notes = ["not on the roster"] if students and s is None else []
        notes += [UNSAFE] if unsafe_no_sandbox else []
        row["notes"] = " | ".join(x for x in (*notes, row["notes"]) if x)
        rows.append(row)
        details.append(detail)
    fields = (
        ["id", "name", "submission", "lecture"] + columns + manual + ["total", "possible", "status", "late", "notes"]
    )
    make_parents(out_csv)  # the folders the output names, made when it is written
    write_atomic(out_csv, csv_text(fields, rows))
    if interrupted:
        raise GradingInterrupted(
            f"interrupted: {len(results)} of {len(tasks)} notebooks graded; their rows are in "
            f"{out_csv} (the others are not; no review or feedback files written)"
        )
    try:
        write_reviews(own_dir(review, "--review"), lectures, details, scores_read)
        write_feedback(own_dir(feedback, "--feedback"), details)
    except KeyboardInterrupt:
        raise GradingInterrupted(
            f"interrupted after every notebook was graded: {out_csv} is complete; the review "
            f"files ({review}) and the feedback files ({feedback}) may be incomplete"
        ) from None
    return rows


def left_out(lecture):
    """{"module:Name": exercise} of what the exercises of `lecture` ask for: left out of its edition."""
    return {spec: ex for ex, specs in LIBRARY.items() if EXERCISES[ex].lecture == lecture for spec in specs}


def _entries(received, read, students, names, lecture):
    """([(student or None, Received or None)] in the CSV's order, {path: lecture or None}, {path:
    lecture} of the copies to grade)."""
    which = {rel: lecture or (lecture_of(r.copy, names) if r.copy else None) for rel, r in received.items()}
    known = {w for w in which.values() if w}
    if len(known) == 1 and not lecture:  # a class of one lecture: a refused or unreadable notebook is of it
        only = known.pop()
        which = {rel: w or (only if isinstance(read[rel], str) else None) for rel, w in which.items()}
    if students:
        files = {s.file for s in students if s.file}
        entries = [(s, received.get(s.file) if s.file else None) for s in students]
        entries += [(None, r) for rel, r in received.items() if rel not in files]
    else:
        entries = [(None, r) for r in received.values()]
    lectures_with_checks = {e.lecture for e in EXERCISES.values()}
    graded = {
        r.rel: which[r.rel]
        for _, r in entries
        if r is not None and r.copy is not None and which[r.rel] in lectures_with_checks
    }
    return entries, which, graded


def _run(tasks, jobs, limits, progress):
    """({path: Outcome}, interrupted) of the batch of gradings."""
    from ..batch import run_batch

    results, interrupted = {}, False
    batch = run_batch(grade_notebook, tasks, jobs=jobs, timeout=limits.notebook + 60.0, retries=1)
    try:
        for outcome in batch:
            results[outcome.key] = outcome
            if progress:
                progress(len(results), len(tasks))
    except KeyboardInterrupt:
        interrupted = True
    finally:
        batch.close()
    return results, interrupted


def _read(r):
    """The written answers of a received notebook ({question: (code, answer)}), or why it is not a notebook."""
    if r.copy is None:
        return r.refused
    try:
        return manual_answers(read_notebook(r.copy)[0])
    except ValueError as err:
        return str(err)


def _row(student, received, read, lec, outcome, columns, manual, scores_read, deadline):
    """The CSV row of one student or submission, and what the review and feedback files need. `read`:
    the notebook's written answers, or why it could not be read."""
    row = {
        "id": student.id if student else "",
        "name": student.name if student else "",
        "submission": received.rel if received else "",
        "lecture": lec or "",
    }
    notes, parts, written, stop = [], [], {}, None
    mine = [e for e in columns if EXERCISES[e].lecture == lec]
    my_manual = [m for m in manual if MANUAL[m].lecture == lec]
    status = "graded"
    if received is None:
        status = "missing"
        notes.append("no submission" + (f" (the roster names {student.file})" if student and student.file else ""))
    elif received.copy is None:
        status = "not graded"
        notes.append(f"not graded: {received.refused}")
    elif not lec:
        status = "not graded"
        notes.append(
            read
            if isinstance(read, str)
            else "not a lecture of this course (no otter assignment name in its metadata, no NN_ prefix); "
            "give --lecture"
        )
    elif outcome is None:
        status, _ = "not graded", notes.append(f"lecture {lec} has no exercises")
    elif not outcome.ok:
        status = "not graded"
        reason = outcome.reason or ""
        notes.append(
            reason.replace("error: ValueError: ", "") if "not a notebook" in reason else f"not graded: {reason}"
        )
    else:
        res = outcome.value
        parts = res["parts"]
        if res["stopped"]:
            status, stop = "stopped", res["stopped"]
            notes.append(res["stopped"])
        more = len(res["errors"]) - 3
        notes += res["errors"][:3] + ([f"and {more} more cells failed"] if more > 0 else [])
        if res["left_out"]:
            notes.append(f"{res['left_out']} cells used what this lecture's exercises ask for (left out while grading)")
        if res["printed"] > 2**20:
            notes.append(f"printed {res['printed'] / 2**20:.0f} MB (not kept)")
    if isinstance(read, dict) and lec:  # a notebook stopped early has them too
        written = read
    total = 0.0
    for e in columns:
        if e in mine:
            got = sum(p[2] for p in parts if p[0] == e)
            total += got
            row[e] = f"{got:g}"
            failed = [p for p in parts if p[0] == e and p[4] not in ("passed", stop)]
            if failed:
                more = f" (and {len(failed) - 1} more part{'s' if len(failed) > 2 else ''})" if len(failed) > 1 else ""
                notes.append(f"{e}: {failed[0][4]}{more}")
        else:
            row[e] = ""
    unscored = []
    for m in manual:
        if m not in my_manual:
            row[m] = ""
            continue
        got = scores_read.get(lec, {}).get((row["submission"], m))
        if got is None:
            row[m] = ""
            if status == "graded":
                unscored.append(m)
        else:
            row[m] = f"{got:g}"
            total += got
    if unscored:
        notes.append(f"written answers to score: {', '.join(unscored)} (see the review file of {lec})")
    possible = sum(EXERCISES[e].points for e in mine) + sum(MANUAL[m].points for m in my_manual)
    late = ""
    if deadline is not None and received is not None:  # received: the roster's time, or the snapshot's
        when = (
            parse_time(student.submitted)
            if student and student.submitted
            else dt.datetime.fromtimestamp(received.mtime).astimezone()
        )
        late = _late(when, deadline)
        if late:
            notes.append(f"late by {late}")
    row.update(
        total=f"{total:g}", possible=f"{possible:g}", status=status, late="yes" if late else "", notes=" | ".join(notes)
    )
    got = received if received is not None and received.copy is not None else None
    detail = dict(row=row, parts=parts, answers=written, manual=my_manual, lecture=lec, received=got)
    return row, detail
