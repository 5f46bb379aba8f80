"""The grading of submitted notebooks: one row a student, whatever the submission does.

    contactfem course grade FOLDER --out scores.csv [--roster R.csv] [--deadline T] [--jobs N]

Each notebook is graded in a worker of :func:`contactfem.lab.batch.run_batch`, in two
processes that share nothing:

* the **submission's process** (:mod:`.sandbox`) runs the notebook's code cells, with a
  memory limit, its output discarded (counted), and answers the grader's calls of the
  student's functions, each under the per-check time limit;
* the **grader's process** (the worker) holds the checks: the public ones of
  :mod:`.checks` and the hidden ones of the instructor's material (``hidden_checks.py``:
  not part of the installed package, not in the student notebooks). The references the
  checks compare with are computed here, where the submission has never run. What comes
  back from the submission is plain data (numbers, arrays read without pickle) or a handle
  to call: patching modules, builtins, numpy or the checks in the notebook changes nothing
  the grader computes.

A part of an exercise scores its points when its public check and its hidden checks pass.
An exercise that asks for part of the method (``implements``) is graded with the library's
implementation of that part (checks.LIBRARY) out of reach: the answer's definition is read
for it, and during the calls it is replaced by a tripwire in the submission's process; an
answer that uses it scores zero for the part, with a hint that says so.

What a submission can still do, running as the grader's user: end its own process (its row
says how), kill the worker that grades it (the row says "worker died"), read files. What it
cannot do is change a reference, a check or a score.

Written answers (checks.MANUAL) are collected into one review file per lecture
(``REVIEW/LECTURE.html``: one section per student, code and answer side by side); the
instructor's scores, entered in ``REVIEW/LECTURE-scores.csv``, are read back into the CSV on
the next run. Every student gets a feedback file (``FEEDBACK/ID-LECTURE.md``).
"""

import ast
import csv
import datetime as dt
import html
import io
import json
import os
import pickle
import re
import secrets
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .hidden import FOLDER, hidden_folder, load_hidden, read_hidden, rng_for

REPO = Path(__file__).resolve().parents[3]
MANUAL_MARK = re.compile(r"<!--\s*manual:\s*(\w+)\s*-->")

# The limits, and why these defaults. A notebook's cells run its lecture in the fast preset and
# its checks run the student's functions: graded two at a time on a shared 2-core machine, the
# solutions of the twelve lectures took 19 s (02) to 271 s (08, the cork); 900 s leaves more
# than three times the slowest. A call of the student's code in a check takes milliseconds
# (closed forms, small arrays): 20 s is an endless loop; the checks that run a scene give their
# calls 60-120 s, which this limit does not lower. Memory: a lecture's fast runs need a few
# hundred MB; 4 GB stops a runaway allocation before it takes the machine.
NOTEBOOK_TIMEOUT = 900.0
CHECK_TIMEOUT = 20.0
MEMORY_LIMIT = 4 * 2**30
MAX_REPLY = 64 * 2**20  # bytes of one answer of the submission (an array of some 6 million numbers)
GRACE = 5.0  # how long past a check's limit the submission's process may take to answer


@dataclass(frozen=True)
class Limits:
    notebook: float = NOTEBOOK_TIMEOUT  # seconds for a whole notebook: its cells and its checks
    check: float = CHECK_TIMEOUT  # seconds for one call of the student's code
    memory: int | None = MEMORY_LIMIT  # bytes of address space of the submission's process


class Stopped(Exception):
    """The submission's process is gone (killed at a time limit, exited, crashed)."""


class LibraryCall(Exception):
    pass


# -- the submission's process, seen from the grader -------------------------------------------


class Remote:
    """An object of the submission's process (its function, class or instance): calling it or
    reading an attribute asks that process; what comes back is data or another Remote."""

    remote = True

    def __init__(self, box, meta):
        self.__dict__.update(_box=box, _id=meta["id"], _meta=meta)

    def __call__(self, *args, **kwargs):
        return self._box.call(self._id, args, kwargs)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return self._box.getattr(self._id, name)

    def __setattr__(self, name, value):
        raise AttributeError("the grader does not change the submission's objects")

    @property
    def __signature__(self):
        import inspect

        params = self._meta.get("params")
        if params is None:
            return None
        return inspect.Signature(
            [
                inspect.Parameter(n, inspect._ParameterKind(k), default=None if d else inspect.Parameter.empty)
                for n, k, d in params
            ]
        )

    def __repr__(self):
        return self._meta.get("name") or self._meta.get("type") or "object"


class Handle:
    def __init__(self, i):
        self.id = i


def _set_limits(memory):
    """What the submission's process sets up before it starts (POSIX): death with the worker
    (Linux), its memory limit (where the platform allows one), a process group of its own (its
    children end with it; a signal to the worker's group does not reach it)."""

    def limit():
        import ctypes
        import resource

        try:
            ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, 9)  # PR_SET_PDEATHSIG, SIGKILL
        except (OSError, AttributeError):
            pass
        if memory:
            try:
                resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
            except (ValueError, OSError):
                pass
        os.setpgrp()

    return limit


class Box:
    """The submission's process (see :mod:`.sandbox`): started on the first request."""

    def __init__(self, limits, workdir):
        self.limits = limits
        self.deadline = time.monotonic() + limits.notebook
        self.guard = ()
        self.used = set()
        self.dead = None
        self.where = "starting"
        req_r, self._req_w = os.pipe()
        self._rep_r, rep_w = os.pipe()
        env = dict(
            os.environ,
            MPLBACKEND="Agg",
            OPENBLAS_NUM_THREADS="1",
            OMP_NUM_THREADS="1",
            PYTHONPATH=os.pathsep.join(p for p in [str(REPO), os.environ.get("PYTHONPATH", "")] if p),
        )
        code = f"from contactfem.lab.course.sandbox import serve; serve({req_r}, {rep_w})"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code],
            pass_fds=(req_r, rep_w),
            cwd=workdir,
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=_set_limits(limits.memory) if os.name == "posix" else None,
        )
        os.close(req_r)
        os.close(rep_w)
        from multiprocessing.connection import Connection

        self.conn_out = Connection(self._req_w, readable=False)
        self.conn_in = Connection(self._rep_r, writable=False)

    def _kill(self):
        """The submission's process and what it started (its process group)."""
        import signal

        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError, AttributeError):  # AttributeError: not POSIX
            pass
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()

    def close(self):
        self._kill()
        self.conn_out.close()
        self.conn_in.close()

    def _stop(self, reason):
        self._kill()
        self.dead = reason
        raise Stopped(reason)

    def _gone(self):
        try:
            code = self.proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:  # alive, but its connection is broken or garbled
            self._stop(f"the submission broke its connection to the grader {self.where}")
        what = f"died (signal {-code})" if code < 0 else f"exited with code {code}"
        if code == -9 and self.limits.memory:
            what += " (killed: out of memory?)"
        self._stop(f"the submission's process {what} {self.where}")

    def request(self, req, limit=None):
        if self.dead:
            raise Stopped(self.dead)
        left = self.deadline - time.monotonic()
        wait = left if limit is None else min(left, limit + GRACE)
        try:
            self.conn_out.send_bytes(_dumps(req))
            if not self.conn_in.poll(max(wait, 0.0)):
                if time.monotonic() >= self.deadline:
                    self._stop(f"time limit {self.limits.notebook:g} s for the notebook reached {self.where}")
                self._stop(f"the submission did not answer within {limit + GRACE:g} s {self.where}")
            data = self.conn_in.recv_bytes(MAX_REPLY)
            return json.loads(data)
        except (EOFError, OSError, ValueError):
            self._gone()

    def decode(self, v):
        t = v.get("t")
        if t == "none":
            return None
        if t == "ellipsis":
            return Ellipsis
        if t == "py":
            return v["v"]
        if t in ("tuple", "list"):
            return (tuple if t == "tuple" else list)(self.decode(x) for x in v["v"])
        if t == "dict":
            return {k: self.decode(x) for k, x in v["v"].items()}
        if t in ("nd", "np"):
            import base64

            a = np.load(io.BytesIO(base64.b64decode(v["v"])), allow_pickle=False)
            return a if t == "nd" else a[()]
        if t == "ref":
            return Remote(self, v)
        if "exc" in v:
            raise _error(v["exc"], v.get("msg", ""))
        raise Stopped(f"the submission's process answered nonsense {self.where}")

    def cell(self, i, source):
        self.where = f"running cell {i}"
        return self.request(("cell", source))

    def get(self, name):
        self.where = f"reading `{name}`"
        v = self.request(("get", name))
        return None if v.get("t") == "missing" else self.decode(v)

    def getattr(self, i, name):
        from . import checks

        v = self.request(("getattr", i, name), limit=checks.TIME_LIMIT)
        if v.get("t") == "missing":
            raise AttributeError(name)
        return self.decode(v)

    def call(self, i, args, kwargs):
        from . import checks

        limit = checks.CALL_LIMIT[0] or checks.TIME_LIMIT
        self.where = "in a call of the answer"
        reply = self.request(("call", i, _wire(args), _wire(kwargs), limit, tuple(self.guard)), limit=limit)
        self.used.update(reply.get("library", ()))
        if reply.get("timeout"):
            raise checks.Timeout()
        if reply.get("exc") == "LibraryUsed":
            raise LibraryCall("the answer called the library")
        if "exc" in reply:
            raise _error(reply["exc"], reply.get("msg", ""))
        return self.decode(reply["ok"])


def _dumps(req):
    """A request for the submission's process: pickled; a library object that pickle cannot
    take (a stepper holding lambdas) by dill, which sends functions by value."""
    try:
        return pickle.dumps(req)
    except (pickle.PicklingError, AttributeError, TypeError):
        import dill

        return dill.dumps(req, recurse=True)


def _error(name, msg):
    name = name if re.fullmatch(r"[A-Za-z_]\w{0,60}", name or "") else "Error"
    return type(name, (Exception,), {})(msg)


def _wire(v):
    if isinstance(v, Remote):
        return Handle(v._id)
    if type(v) in (tuple, list):
        return type(v)(_wire(x) for x in v)
    if type(v) is dict:
        return {k: _wire(x) for k, x in v.items()}
    return v


# -- one notebook ------------------------------------------------------------------------------


def read_notebook(path):
    """The notebook's cells [(type, source)]; ValueError if it is not a notebook."""
    try:
        nb = json.loads(Path(path).read_text(errors="replace"))
        cells = nb["cells"]
        return [
            (c.get("cell_type"), "".join(c["source"]) if isinstance(c["source"], list) else c["source"]) for c in cells
        ], nb.get("metadata", {})
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        raise ValueError(f"not a notebook ({type(err).__name__}: {' '.join(str(err).split())[:80]})") from None


def _answer_nodes(tree, names):
    """The definitions of the answers `names` in a parsed cell: def, class, or assignment."""
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and node.name in names:
            yield node
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id in names for t in targets) and node.value is not None:
                yield node.value


def library_named(source, guard, names):
    """The library names of `guard` ("module:Name.attr") that the definitions of the answers
    `names` in this code use (other code of the cell, a comparison with the library, is free)."""
    wanted = {spec.partition(":")[2].split(".")[0]: spec for spec in guard}
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return set()
    found = set()
    for top in _answer_nodes(tree, names):
        for node in ast.walk(top):
            name = node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else None
            if name in wanted:
                found.add(wanted[name])
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                found |= {wanted[a.name.split(".")[-1]] for a in node.names if a.name.split(".")[-1] in wanted}
    return found


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


def library_hint(exercise, used):
    names = ", ".join(sorted(s.replace(":", ".") for s in used))
    return (
        f"your answer uses the library's own {names}: this exercise asks you to implement it yourself "
        "(write the computation; the library's version is what your answer is compared with)"
    )


def grade_notebook(path, lecture, hidden_source, seed, limits):
    """Grade one notebook (the function the batch's workers run): a dict with the parts
    [(exercise, part, points scored, points possible, message)], the cells that failed, what
    it printed, and `stopped` (why the submission's process ended early, or None)."""
    from . import checks

    t0 = time.monotonic()
    cells, _ = read_notebook(path)
    hidden = load_hidden(hidden_source, lecture) if hidden_source else {}
    checks.TIME_LIMIT = limits.check
    checks._MEMO.clear()
    mine = [e for e in checks.EXERCISES.values() if e.lecture == lecture]
    code_cells = [(i, src) for i, (kind, src) in enumerate(cells, 1) if kind == "code"]
    out = {"parts": [], "errors": [], "stopped": None, "printed": 0}
    with tempfile.TemporaryDirectory(prefix="contactfem-submission-") as work:
        box = Box(limits, work)
        try:
            for i, src in code_cells:
                try:
                    r = box.cell(i, src)
                except Stopped:
                    break
                out["printed"] = r.get("printed", 0)
                if not r.get("ok"):
                    out["errors"].append(f"cell {i}: {r.get('error') or r.get('msg')}")
            for e in mine:
                guard = checks.LIBRARY.get(e.name, ()) if e.implements else ()
                names = {a for p in e.parts for a in p.answers}
                named = set().union(*(library_named(src, guard, names) for _, src in code_cells)) if guard else set()
                for p in e.parts:
                    result = _grade_part(box, p, hidden.get(p.name, ()), seed, guard, named)
                    out["parts"].append((e.name, p.name, *result))
        finally:
            box.close()
            out["stopped"] = box.dead
    out["seconds"] = time.monotonic() - t0
    return out


def _grade_part(box, part, hidden, seed, guard, named):
    """(points, possible, message) of one part: its public check and its hidden checks, in this
    process, on the submission's answers."""
    if named:
        return 0.0, part.points, library_hint(part.name, named)
    box.guard, box.used = guard, set()
    msg = "passed"
    try:
        env = {a: box.get(a) for a in part.answers}
        for check in [part.check, *hidden]:
            extra = {} if check is part.check else {"rng": rng_for(seed, part.name, check.__name__)}
            check(**env, **extra)
            if box.used:
                break
    except AssertionError as err:
        msg = " ".join(str(err).split())
    except Stopped as err:
        msg = str(err)
    except LibraryCall:
        pass
    except Exception as err:  # noqa: BLE001  (an answer the check did not foresee: the part fails)
        msg = f"the check could not use your answer: {type(err).__name__}: {' '.join(str(err).split())[:200]}"
    if box.used:
        return 0.0, part.points, library_hint(part.name, box.used)
    return (part.points if msg == "passed" else 0.0), part.points, msg


# -- the batch -----------------------------------------------------------------------------------


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
):
    """Grade every notebook in `folder` and write `out_csv`: one row per submission (and per
    student of the roster), columns id, name, submission, lecture, one per exercise and written
    question, total, possible, status, late, notes. The review files of the written answers go
    to `review`, a feedback file per student to `feedback` (default: next to the CSV, named
    after it). Returns the rows."""
    from ...io.outputs import check_output_path
    from ..batch import run_batch
    from . import checks
    from . import lecture_sources

    folder = Path(folder)
    subs = submissions(folder)
    out_csv = check_output_path(out_csv, "--out", (".csv",))
    if jobs < 1:
        raise ValueError(f"--jobs {jobs}: give a number of parallel gradings >= 1")
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
    from . import check_out_dir

    check_out_dir(review, "--review")
    check_out_dir(feedback, "--feedback")

    rel = {p: p.relative_to(folder).as_posix() for p in subs}
    which = {p: lecture or lecture_of(p, names) for p in subs}
    known = {w for w in which.values() if w}
    if len(known) == 1 and not lecture:  # a class of one lecture: a missing or unreadable notebook is of it
        lecture = known.pop()
        which = {p: w or (lecture if not _readable(p) else None) for p, w in which.items()}
    entries = []  # (student or None, path or None)
    if students:
        by_file = {s.file: s for s in students if s.file}
        for s in students:
            p = folder / s.file if s.file else None
            entries.append((s, p if p is not None and p in rel else None))
        entries += [(None, p) for p in subs if rel[p] not in by_file]
    else:
        entries = [(None, p) for p in subs]

    lectures = sorted({w for w in which.values() if w} | ({lecture} if lecture else set()))
    scores_read = {lec: _read_manual_scores(review / f"{lec}-scores.csv") for lec in lectures}
    sources = read_hidden(hidden_folder(autograders, repo))  # read once, before any submission runs
    seed = secrets.randbits(64) if seed is None else seed
    tasks, results = [], {}
    for _, p in entries:
        if p is not None and which.get(p) and any(e.lecture == which[p] for e in checks.EXERCISES.values()):
            tasks.append((str(p), (str(p), which[p], sources.get(which[p]), seed, limits)))
    n_done, interrupted = 0, False
    batch = run_batch(grade_notebook, tasks, jobs=jobs, timeout=limits.notebook + 60.0, retries=1)
    try:
        for outcome in batch:
            results[outcome.key] = outcome
            n_done += 1
            if progress:
                progress(n_done, len(tasks))
    except KeyboardInterrupt:
        interrupted = True
    finally:
        batch.close()

    columns = [e for e in checks.EXERCISES if checks.EXERCISES[e].lecture in lectures]
    manual = [m for m in checks.MANUAL if checks.MANUAL[m].lecture in lectures]
    rows, details = [], []
    for s, p in entries:
        if interrupted and p is not None and str(p) not in results:
            continue
        row, detail = _row(
            s,
            p,
            rel.get(p, ""),
            which.get(p) if p is not None else (lecture or ""),
            results.get(str(p)),
            columns,
            manual,
            scores_read,
            deadline,
        )
        if students and s is None:
            row["notes"] = " | ".join(x for x in ("not on the roster", row["notes"]) if x)
        rows.append(row)
        details.append(detail)
    fields = (
        ["id", "name", "submission", "lecture"] + columns + manual + ["total", "possible", "status", "late", "notes"]
    )
    _write_csv(out_csv, fields, rows)
    if interrupted:
        raise GradingInterrupted(
            f"interrupted: {n_done} of {len(tasks)} notebooks graded; their rows are in "
            f"{out_csv} (the others are not; no review or feedback files written)"
        )
    try:
        _write_reviews(review, lectures, details, scores_read)
        _write_feedback(feedback, details)
    except KeyboardInterrupt:
        raise GradingInterrupted(
            f"interrupted after every notebook was graded: {out_csv} is complete; the review "
            f"files ({review}) and the feedback files ({feedback}) may be incomplete"
        ) from None
    return rows


def _readable(path):
    try:
        read_notebook(path)
        return True
    except ValueError:
        return False


def _write_csv(path, fields, rows):
    from ...io.outputs import make_parents

    make_parents(path)  # the folders the output names, made when it is written
    tmp = path.with_name(f".{path.name}.part")
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)


def _row(student, path, rel, lec, outcome, columns, manual, scores_read, deadline):
    from . import checks

    row = {
        "id": student.id if student else "",
        "name": student.name if student else "",
        "submission": rel,
        "lecture": lec or "",
    }
    notes, parts, answers, stop = [], [], {}, None
    mine = [e for e in columns if checks.EXERCISES[e].lecture == lec]
    my_manual = [m for m in manual if checks.MANUAL[m].lecture == lec]
    status = "graded"
    if path is None:
        status = "missing"
        notes.append("no submission" + (f" (the roster names {student.file})" if student and student.file else ""))
    elif not lec:
        try:
            read_notebook(path)
            notes.append(
                "not a lecture of this course (no otter assignment name in its metadata, no NN_ prefix); give --lecture"
            )
        except ValueError as err:
            notes.append(str(err))
        status = "not graded"
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
        if res["printed"] > 2**20:
            notes.append(f"printed {res['printed'] / 2**20:.0f} MB (not kept)")
    if path is not None and lec:  # the written answers, read here: a notebook stopped early has them too
        try:
            answers = manual_answers(read_notebook(path)[0])
        except ValueError:
            pass
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
        got = scores_read.get(lec, {}).get((rel, m))
        if got is None:
            row[m] = ""
            if status == "graded":
                unscored.append(m)
        else:
            row[m] = f"{got:g}"
            total += got
    if unscored:
        notes.append(f"written answers to score: {', '.join(unscored)} (see the review file of {lec})")
    possible = sum(checks.EXERCISES[e].points for e in mine) + sum(checks.MANUAL[m].points for m in my_manual)
    late = ""
    if deadline is not None and path is not None:
        when = (
            parse_time(student.submitted)
            if student and student.submitted
            else dt.datetime.fromtimestamp(path.stat().st_mtime).astimezone()
        )
        late = _late(when, deadline)
        if late:
            notes.append(f"late by {late}")
    row.update(
        total=f"{total:g}", possible=f"{possible:g}", status=status, late="yes" if late else "", notes=" | ".join(notes)
    )
    detail = dict(row=row, parts=parts, answers=answers, manual=my_manual, lecture=lec)
    return row, detail


def _read_manual_scores(path):
    """{(submission, question): score} of the instructor's scores file (blank: not scored)."""
    if not path.is_file():
        return {}
    from . import checks

    out = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            text = (r.get("score") or "").strip()
            if not text:
                continue
            q = r.get("question", "")
            try:
                v = float(text)
            except ValueError:
                raise ValueError(f"{path}: score {text!r} of {r.get('submission')}, {q} is not a number") from None
            top = checks.MANUAL[q].points if q in checks.MANUAL else None
            if top is not None and not 0 <= v <= top:
                raise ValueError(f"{path}: score {v:g} of {r.get('submission')}, {q} is outside 0..{top:g}")
            out[(r.get("submission", ""), q)] = v
    return out


def _write_reviews(review, lectures, details, scores_read):
    """REVIEW/LECTURE.html (one section per student, code and answer side by side) and
    REVIEW/LECTURE-scores.csv for the instructor's scores (kept if it exists: it is theirs)."""
    from . import checks

    review.mkdir(parents=True, exist_ok=True)
    for lec in lectures:
        qs = [m for m in checks.MANUAL.values() if m.lecture == lec]
        if not qs:
            continue
        mine = [d for d in details if d["lecture"] == lec and d["row"]["submission"]]
        parts = [
            f"<!doctype html><meta charset=utf-8><title>Written answers: {html.escape(lec)}</title>",
            "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;width:100%}"
            "td,th{border:1px solid #ccc;vertical-align:top;padding:.5em;width:50%}"
            "pre{white-space:pre-wrap;margin:0}section{margin-bottom:2em}</style>",
            f"<h1>Written answers: {html.escape(lec)}</h1>",
            f"<p>{len(mine)} submissions. Enter the scores in <code>{html.escape(lec)}-scores.csv</code> "
            "(column score) and run <code>contactfem course grade</code> again: they go into the CSV.</p>",
        ]
        for d in mine:
            r = d["row"]
            who = " ".join(x for x in (r["id"], r["name"]) if x) or r["submission"]
            parts.append(
                f'<section id="{html.escape(r["submission"])}"><h2>{html.escape(who)}</h2>'
                f"<p>{html.escape(r['submission'])}</p>"
            )
            for q in qs:
                code, text = d["answers"].get(q.name, ("", ""))
                given = scores_read.get(lec, {}).get((r["submission"], q.name))
                score = f"{given:g}" if given is not None else "not scored"
                parts.append(
                    f"<h3>{html.escape(q.name)} ({q.points:g} points; {score}): {html.escape(q.what)}</h3>"
                    "<table><tr><th>code</th><th>answer</th></tr><tr>"
                    f"<td><pre>{html.escape(code) or '(no code)'}</pre></td>"
                    f"<td><pre>{html.escape(text) or '(no answer)'}</pre></td></tr></table>"
                )
            parts.append("</section>")
        (review / f"{lec}.html").write_text("\n".join(parts))
        sheet = review / f"{lec}-scores.csv"
        if not sheet.exists():
            rows = [
                {
                    "submission": d["row"]["submission"],
                    "id": d["row"]["id"],
                    "name": d["row"]["name"],
                    "question": q.name,
                    "points": f"{q.points:g}",
                    "score": "",
                }
                for d in mine
                for q in qs
            ]
            _write_csv(sheet, ["submission", "id", "name", "question", "points", "score"], rows)


def _write_feedback(feedback, details):
    """FEEDBACK/<id or submission>-<lecture>.md: the student's score per part and the hints."""
    from . import checks

    feedback.mkdir(parents=True, exist_ok=True)
    for d in details:
        r = d["row"]
        stem = r["id"] or Path(r["submission"]).with_suffix("").as_posix().replace("/", "_")
        lines = [
            f"# {d['lecture'] or 'course'}: feedback for {r['name'] or r['id'] or r['submission']}",
            "",
            f"Total: {r['total']} of {r['possible']} ({r['status']}).",
        ]
        if r["late"]:
            lines.append("Submitted late.")
        if r["status"] != "graded" or r["notes"] and not d["parts"]:
            lines += ["", f"Notes: {r['notes']}"]
        for e in [e for e in checks.EXERCISES.values() if e.lecture == d["lecture"]]:
            ps = [p for p in d["parts"] if p[0] == e.name]
            got = sum(p[2] for p in ps)
            lines += ["", f"## {e.name}: {got:g} of {e.points:g}", f"{e.what}", ""]
            if e.name in checks.BUILDS_ON:
                lines[-1:] = [f"(It builds on the library on purpose: {checks.BUILDS_ON[e.name]}.)", ""]
            for _, part, pts, possible, msg in ps:
                lines.append(f"- {part}: {pts:g} of {possible:g}" + ("" if msg == "passed" else f": {msg}"))
        for q in d["manual"]:
            m = checks.MANUAL[q]
            got = f"{r[q]} of {m.points:g}" if r.get(q) else f"to be scored, {m.points:g} points"
            lines += ["", f"## {q} (written): {got}", m.what]
        (feedback / f"{stem}-{d['lecture'] or 'none'}.md").write_text("\n".join(lines) + "\n")
