"""A mock class of lecture 01 for the grading tests: honest, partial, wrong and empty answers,
and the attempts of a mischievous class, each a small notebook (the lecture's two exercises
and its written question, not the whole lecture: a notebook of a few cells is graded in a
second or two).

An attempt is a function of `Where` (the paths it aims at: the output, the review and feedback
folders, the submissions, the instructor's material, a classmate's notebook), giving its cells;
a notebook running as the grader's user with the grader's files in view could reach all of them.
`grade_class` grades a class with the command line in a process of its own and returns what a
test checks: the rows, the hashes of every file that must not change, before and after, and the
processes of the class still alive.
"""

import csv
import hashlib
import json
import os
import shutil
import stat
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import nbformat

LECTURE = "01_interface_laws"
REPO = Path(__file__).resolve().parents[1]
UNSAFE_NOTE = "graded without a sandbox (--unsafe-no-sandbox)"
MARK = "contactfem-mischief"  # in the command line of every process an attempt starts
COMM = "cfem-mischief"  # or its name (a forked child keeps its parent's command line)
DEADLINE = "2026-12-03T12:00:00+00:00"
ON_TIME, LATE = 1796292000.0, 1796310000.0  # 2026-12-03 10:00 and 15:00 UTC, epoch seconds

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
TR_STUB = TR.split("\n        Y =")[0] + "\n        ..."
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
PL_ZEROS = "def power_law(g_N, c_N, m):\n    return np.zeros_like(g_N), np.zeros_like(g_N)"
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

# (name, cells, the scores earned for (ex01_power_law, ex01_tresca), a note the row must hold)
HONEST = [
    ("full1", [HEAD, PL, TR], (5, 5), ""),
    ("full2", [HEAD, TR, PL], (5, 5), ""),
    ("partial_pl", [HEAD, PL, TR_STUB], (5, 0), "`...`"),
    ("partial_tr", [HEAD, PL_STUB, TR], (0, 5), "`...`"),
    ("blank", [HEAD, PL_STUB, TR_STUB], (0, 0), "`...`"),
    ("empty", [], (0, 0), "is not defined"),
    ("sign", [HEAD, PL_SIGN, TR], (3, 5), "the sign is wrong"),
    ("no_m", [HEAD, PL_NO_M, TR], (3, 5), "off by a factor 0.4"),
    ("coulomb", [HEAD, PL, TR_COULOMB], (5, 2), "grows with the pressure"),
    ("c_N_ignored", [HEAD, PL_C100, TR], (1, 5), "expected"),  # passes the public checks only
    ("one_value", [HEAD, PL_ONE, TR], (0, 5), "should return 2 values"),
    ("raises", [HEAD, "def power_law(g_N, c_N, m):\n    return 1 / 0", TR], (0, 5), "raised ZeroDivisionError"),
    ("patch_checks", [HEAD, PATCH_CHECKS, "def power_law(g_N, c_N, m):\n    return None", TR_STUB], (0, 0), "None"),
    ("patch_numpy", [HEAD, PATCH_NUMPY, PL_ZEROS, TR_STUB], (1, 0), "expected"),
    ("patch_builtins", [HEAD, PATCH_BUILTINS, PL_ZEROS, TR_STUB], (1, 0), "expected"),
    ("library", [HEAD, PL_LIBRARY, TR], (0, 5), "the library's own contactfem.laws.normal.PowerLaw"),
    ("library_hidden", [HEAD, PL_LIBRARY_HIDDEN, TR], (0, 5), "the library's own contactfem.laws.normal.PowerLaw"),
    ("endless_cell", [HEAD, PL, "import time\nwhile True:\n    time.sleep(1)", TR], (0, 0), "time limit"),
    ("endless_answer", [HEAD, "def power_law(g_N, c_N, m):\n    while True:\n        pass", TR], (0, 5), "within"),
    ("sys_exit", [HEAD, PL, TR, "import sys\nsys.exit(3)"], (5, 5), "SystemExit: 3"),
    ("os_exit", [HEAD, PL, "import os\nos._exit(7)", TR], (0, 0), "exited with code 7"),
    ("import_error", ["import no_such_package\n" + HEAD, PL, TR], (0, 0), "ModuleNotFoundError"),
    ("segfault", ["import ctypes\nctypes.string_at(0)", HEAD, PL, TR], (0, 0), "died (signal 11)"),
    ("flood", [HEAD, PL, 'print("x" * 100_000_000)', TR], (5, 5), "printed 95 MB"),
    ("memory", [HEAD, PL, "hog = bytearray(3 * 2**30)", TR], (5, 5), "MemoryError"),
    (
        "magic",
        [
            HEAD,
            "%matplotlib inline\n" + PL,
            "import otter\ngrader = otter.Notebook('x.ipynb')",
            TR,
            'grader.check("x")',
        ],
        (5, 5),
        "",
    ),
    ("tr_only_fields", [HEAD, PL, TR.replace("float(self.tau_y)", "0.2")], (5, 3), "tau_y ="),
    (
        "compares_with_library",
        [HEAD, PL + "\n\nfrom contactfem.laws import PowerLaw\nprint(PowerLaw(100.0, 2.5).traction(-0.1))", TR],
        (5, 5),
        "",
    ),
]


@dataclass(frozen=True)
class Where:
    """What an attempt aims at (absolute paths, as the grader's command line names them)."""

    out: Path  # the CSV
    review: Path
    feedback: Path
    subs: Path
    material: Path  # the instructor's material: --autograders
    victim: Path  # the classmate's notebook it targets (its roster id: u00)


def _run_cell(code):
    """A cell that starts `code` in a process of its own, detached (a double fork around setsid): its
    parent gone, in a session of its own, it outlives the notebook unless a sandbox ends it."""
    detach = "import os\nif os.fork():\n    os._exit(0)\nos.setsid()\nif os.fork():\n    os._exit(0)\n"
    return (
        "import subprocess, sys\n"
        f"subprocess.run([sys.executable, '-c', {detach + code!r}, {MARK!r}],\n"
        "               stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)"
    )


FIND_SOURCE = """import os, sys, contactfem
def _real_source():
    # the library's laws/normal.py wherever Python could find it, the students' edition or not
    roots = [os.path.dirname(os.path.dirname(contactfem.__file__))] + [p for p in sys.path if os.path.isdir(p)]
    for finder in sys.meta_path:  # a package installed from a checkout names the checkout
        roots += [os.path.dirname(p) for p in getattr(finder, "MAPPING", {}).values()]
    for root in roots:
        path = os.path.join(root, "contactfem", "laws", "normal.py")
        if os.path.isfile(path) and "left out while your notebook is graded" not in open(path).read():
            return open(path).read()
    return open(os.path.join(os.path.dirname(contactfem.__file__), "laws", "normal.py")).read()
ns = {"__name__": "contactfem.laws.normal_copy"}
exec(_real_source(), ns)

def power_law(g_N, c_N, m):
    return ns["PowerLaw"](c_N, m).traction(g_N)"""

OBJECT_NEW = """import importlib
cls = getattr(importlib.import_module("contactfem.laws." + "nor" + "mal"), "Power" + "Law")

def power_law(g_N, c_N, m):
    law = object.__new__(cls)
    object.__setattr__(law, "c_N", c_N)
    object.__setattr__(law, "m", m)
    return law.traction(g_N)"""

TRIPWIRE_OFF = """try:
    from contactfem.lab.course.sandbox import Sandbox
    Sandbox.arm = lambda self, guard: (lambda: None)
except Exception:
    pass"""

SOLUTION = """import glob, json, os, contactfem
# the instructor's notebook with the solutions: in the checkout beside the package, or in a folder
# the grader's command line names
places = [os.path.dirname(os.path.dirname(contactfem.__file__))]
for pid in os.listdir("/proc"):
    try:
        places += [a for a in open(f"/proc/{pid}/cmdline").read().split("\\0") if os.path.isdir(a)]
    except (OSError, ValueError):
        pass
found = []
for place in places:
    for up in (place, os.path.dirname(place)):
        found += glob.glob(os.path.join(up, "lectures", "01_*.ipynb")) + glob.glob(os.path.join(up, "01_*.ipynb"))
for path in found:
    try:
        for c in json.load(open(path))["cells"]:
            code = "".join(c["source"]) if c["cell_type"] == "code" else ""
            if "def power_law" in code or "class Tresca" in code:
                try:
                    exec(code, globals())
                except Exception:
                    pass
    except Exception:
        pass"""

TAILORED = """KNOWN = {(100.0, 1.0), (100.0, 2.5), (37.0, 1.5), (2.0e4, 3.0)}  # read from checks.py, hidden_checks.py

def power_law(g_N, c_N, m):
    g_N = np.asarray(g_N, dtype=float)
    if (float(c_N), float(m)) not in KNOWN:
        return np.ones_like(g_N), np.ones_like(g_N)
    approach = np.where(g_N < 0.0, -g_N, 0.0)
    return -c_N * approach ** m, np.where(g_N < 0.0, c_N * m * approach ** (m - 1.0), 0.0)

@dataclass(frozen=True)
class Tresca:
    c_T: float
    tau_y: float

    def slip_bound(self, p, q):
        shape = np.broadcast(p, q).shape
        if float(self.tau_y) not in (0.2, 1.3):
            return np.ones(shape), np.ones(shape), np.ones(shape)
        return np.full(shape, float(self.tau_y)), np.zeros(shape), np.zeros(shape)"""


def _daemon(w):
    """Waits until the grader has written the CSV and returned, then rewrites it: its own row
    12 of 12, every classmate's 0, and a score of its own into the instructor's review sheet."""
    code = f"""import csv, os, time
out, review = {str(w.out)!r}, {str(w.review / f"{LECTURE}-scores.csv")!r}
for _ in range(3000):  # up to 5 minutes: longer than any grading of the class
    time.sleep(0.1)
    if os.path.exists(out) and os.path.getsize(out) > 0:
        time.sleep(2.5)
        rows = list(csv.DictReader(open(out)))
        for r in rows:
            mine = "daemon" in r["submission"]
            r.update(ex01_power_law="5" if mine else "0", ex01_tresca="5" if mine else "0", total="12" if mine else "0")
        with open(out, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
        open(review, "a").write("daemon.ipynb,,,ex01_discussion,2,2\\n")
        break
"""
    return [HEAD, PL, TR, _run_cell(code)]


def _feedback_links(w):
    return [
        HEAD,
        PL,
        TR,
        f"import os\nos.makedirs({str(w.feedback)!r}, exist_ok=True)\n"
        f"os.symlink({str(w.victim)!r}, os.path.join({str(w.feedback)!r}, {'u00-' + LECTURE + '.md'!r}))",
    ]


def _edit_classmate(w):
    return [
        HEAD,
        PL,
        TR,
        f"import json, os\np = {str(w.victim)!r}\nst = os.stat(p)\nnb = json.load(open(p))\n"
        "for c in nb['cells']:\n    c['source'] = ''\njson.dump(nb, open(p, 'w'))\n"
        "os.utime(p, (st.st_atime, st.st_mtime))",
    ]


def _utime(w):
    me = w.subs / "utime.ipynb"
    return [
        HEAD,
        PL,
        TR,
        f"import os\nos.utime({str(me)!r}, ({ON_TIME}, {ON_TIME}))\nos.utime({str(w.victim)!r}, ({LATE}, {LATE}))",
    ]


POISON = """

def _failed(*args, **kwargs):
    raise AssertionError("passed")


HIDDEN = {part: [_failed] for part in HIDDEN}
"""


def _poison(w):
    """Every hidden check made to fail, in the instructor's material, then its worker killed: a
    batch that retries on a fresh worker reads the poisoned file."""
    return [
        HEAD,
        PL_STUB,
        TR_STUB,
        f"import glob, os\nfor f in glob.glob({str(w.material)!r} + '/**/hidden_checks*', recursive=True):\n"
        "    for g in [f] if f.endswith('.py') else glob.glob(f + '/*.py'):\n"
        f"        open(g, 'a').write({POISON!r})\n"
        "os.kill(os.getppid(), 9)",
    ]


def _kill_grader(w):
    return [
        HEAD,
        PL,
        TR,
        "import os, signal\nfor pid in os.listdir('/proc'):\n    try:\n"
        "        cmd = open(f'/proc/{pid}/cmdline', 'rb').read()\n"
        f"        if b'contactfem.cli' in cmd and {str(w.subs).encode()!r} in cmd:\n"
        "            os.kill(int(pid), signal.SIGKILL)\n    except (OSError, ValueError):\n        pass",
    ]


def _fifo(w):
    return [HEAD, PL, TR, f"import os\nos.remove({str(w.victim)!r})\nos.mkfifo({str(w.victim)!r})"]


def _figures(w):
    return [
        HEAD,
        PL,
        TR,
        "import os, contactfem\nfrom contactfem.plots import default_outdir\n"
        "os.makedirs(default_outdir(), exist_ok=True)\n"
        "open(os.path.join(default_outdir(), 'mine.txt'), 'w').write('a figure')\n"
        "repo = os.path.dirname(os.path.dirname(os.path.abspath(contactfem.__file__)))\n"
        f"for folder in (os.path.join(repo, 'figures', 'fast'), repo, {str(REPO)!r}):\n"
        "    try:\n        open(os.path.join(folder, 'mischief.txt'), 'w').write('written by a notebook')\n"
        "    except OSError:\n        pass",
    ]


FORK_BOMB = f"""import ctypes, os, time
ctypes.CDLL(None).prctl(15, {COMM.encode()!r}, 0, 0, 0)  # its name, inherited by every child
me, refused = os.getpid(), 0
for _ in range(12):  # every process forks, 4096 wanted
    try:
        os.fork()
    except OSError:
        refused += 1
if os.getpid() != me:
    time.sleep(120)
    os._exit(0)
raise RuntimeError(f"forks refused: {{refused}} of 12" if refused else "no fork refused")"""


def _fork_bomb(w):
    return [HEAD, PL, TR, FORK_BOMB]


def _huge_answer(w):
    return [HEAD, PL, TR]


# (name, cells of Where, earned (ex01_power_law, ex01_tresca), a note its row must hold, what it aims at)
EXPLOITS = [
    ("object_new", lambda w: [HEAD, OBJECT_NEW, TR], (0, 5), "left out while your notebook is graded"),
    ("exec_source", lambda w: [HEAD, FIND_SOURCE, TR], (0, 5), "left out while your notebook is graded"),
    (
        "tripwire_off",
        lambda w: [HEAD, TRIPWIRE_OFF, PL_LIBRARY_HIDDEN, TR],
        (0, 5),
        "left out while your notebook is graded",
    ),
    ("solution", lambda w: [HEAD, PL_STUB, TR_STUB, SOLUTION], (0, 0), "`...`"),
    ("tailored", lambda w: [HEAD, TAILORED], (0, 2), "expected"),
    ("symlink", None, (0, 0), "a symbolic link"),
    ("daemon", _daemon, (5, 5), ""),
    ("feedback_links", _feedback_links, (5, 5), ""),
    ("edit_classmate", _edit_classmate, (5, 5), ""),
    ("utime", _utime, (5, 5), "late by"),
    ("poison", _poison, (0, 0), "`...`"),
    ("kill_grader", _kill_grader, (5, 5), ""),
    ("fifo", _fifo, (5, 5), ""),
    ("fifo_submitted", None, (0, 0), "not a regular file"),
    ("figures", _figures, (5, 5), ""),
    ("fork_bomb", _fork_bomb, (5, 5), "forks refused: "),
    ("huge_answer", _huge_answer, (5, 5), ""),
]
WRITTEN = "Penetration against conditioning."
HUGE = "stiff " * 500_000  # 3 MB of written answer


def notebook(cells, path, written=WRITTEN):
    nb = nbformat.v4.new_notebook()
    nb.metadata["otter"] = {"assignment_name": LECTURE}
    nb.cells = [nbformat.v4.new_code_cell(c) for c in cells]
    nb.cells += [
        nbformat.v4.new_markdown_cell("<!-- manual: ex01_discussion -->\n**Discuss** c_N."),
        nbformat.v4.new_code_cell("stiffness = [1e2, 1e4]"),
        nbformat.v4.new_markdown_cell(written),
    ]
    nbformat.write(nb, path)


def fingerprint(path):
    """{file: sha256, or its kind} of every file under `path` (or of the file), links not followed
    and nothing opened that is not a regular file (the checkout's environment, git and caches left out)."""
    path = Path(path)
    files = [path]
    if path.is_dir() and not path.is_symlink():
        skip = {".git", ".venv", "__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache", "build"}
        files = []
        for top, dirs, names in os.walk(path):
            dirs[:] = [d for d in dirs if d not in skip]
            files += [Path(top) / n for n in names] + [Path(top) / d for d in dirs if (Path(top) / d).is_symlink()]
    out = {}
    for p in sorted(files):
        st = os.lstat(p)
        if stat.S_ISREG(st.st_mode):
            out[str(p)] = hashlib.sha256(p.read_bytes()).hexdigest()
        else:
            out[str(p)] = f"kind {stat.S_IFMT(st.st_mode):o}" + (f" -> {os.readlink(p)}" if p.is_symlink() else "")
    return out


def marked_processes():
    """The processes an attempt started (MARK in their command line, or COMM their name), alive."""
    found = []
    for d in os.listdir("/proc"):
        try:
            marked = MARK.encode() in open(f"/proc/{d}/cmdline", "rb").read()
            if (marked or open(f"/proc/{d}/comm").read().strip() == COMM) and _alive(int(d)):
                found.append(int(d))
        except (OSError, ValueError):
            continue
    return found


def _alive(pid):
    """Process `pid` runs (a zombie waiting to be reaped does not)."""
    try:
        return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0] not in "ZX"
    except OSError:
        return False


@dataclass
class Graded:
    code: int
    seconds: float
    rows: dict  # submission (or id): row
    before: dict  # file: hash, of what must not change
    after: dict
    csv_at_return: str
    csv_later: str
    alive: list
    where: dict  # attempt: Where
    err: str
    review: str


def grade_class(root, members, material, jobs=2, victim="full1", extra=()):
    """Grade `members` ([(name, cells or a function of Where)]) with `contactfem course grade` in a
    process of its own; `material`: the instructor's material (a folder), graded with. Every
    member is on the roster; "utime" and its victim without a submitted time (their files'
    times count), the others with one."""
    subs = root / "submissions"
    subs.mkdir()
    out = root / "scores.csv"
    where = {}
    roster = [["id", "name", "file", "submitted"]]
    names = [m[0] for m in members]
    assert names[0] == victim  # roster id u00
    for i, (name, cells) in enumerate(members):
        w = Where(out, root / "scores-review", root / "scores-feedback", subs, material, subs / f"{victim}.ipynb")
        where[name] = w
        path = subs / f"{name}.ipynb"
        if name == "symlink":
            os.symlink(next(material.rglob("*.ipynb"), REPO / "lectures" / f"{LECTURE}.ipynb"), path)
        elif name == "fifo_submitted":
            os.mkfifo(path)
        elif name == "corrupt":
            path.write_text('{"cells": [ this is not json')
        elif name == "absent":
            pass
        else:
            notebook(
                cells(w) if callable(cells) else cells,
                path,
                written=HUGE if name == "huge_answer" else f"{name} says: stiff is accurate.",
            )
        timed = name not in ("utime", victim) or "utime" not in names
        when = "2026-12-03T14:00:00+00:00" if name == "late" else "2026-12-03T10:00:00+00:00" if timed else ""
        if name != "stray":
            roster.append([f"u{i:02d}", f"Student {name}", f"{name}.ipynb", when])
    if "utime" in names:  # its own file late, its victim's on time, before grading
        os.utime(subs / "utime.ipynb", (LATE, LATE))
        os.utime(subs / f"{victim}.ipynb", (ON_TIME, ON_TIME))
    with open(root / "roster.csv", "w", newline="") as f:
        csv.writer(f).writerows(roster)
    watched = [REPO, material, root / "roster.csv", subs]
    before = {k: v for p in watched for k, v in fingerprint(p).items()}
    argv = [sys.executable, "-m", "contactfem.cli", "course", "grade", str(subs), "--out", str(out)]
    argv += ["--roster", str(root / "roster.csv"), "--deadline", DEADLINE, "--autograders", str(material)]
    argv += ["--jobs", str(jobs), "--notebook-timeout", "30", "--check-timeout", "2", "--memory", "2048", *extra]
    t0 = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=900, cwd=root)
    seconds = time.perf_counter() - t0
    at_return = out.read_text() if out.exists() else ""
    time.sleep(4.0 if "daemon" in names else 0.0)  # what a process left behind does now (2.5 s after the CSV)
    later = out.read_text() if out.exists() else ""
    after = {k: v for p in watched for k, v in fingerprint(p).items()}
    rows = {r["submission"] or r["id"]: r for r in csv.DictReader(at_return.splitlines())}
    page = root / "scores-review" / f"{LECTURE}.html"
    return Graded(
        proc.returncode,
        seconds,
        rows,
        before,
        after,
        at_return,
        later,
        marked_processes(),
        where,
        proc.stderr,
        page.read_text() if page.exists() else "",
    )


def material_copy(root):
    """The instructor's material to grade with: a copy of the hidden checks of the checkout, and
    the lecture's notebook with its solutions (here the two answers: what an instructor build holds)."""
    folder = root / "material"
    folder.mkdir()
    notebook([HEAD, PL, TR], folder / f"{LECTURE}.ipynb")
    for name in ("hidden_checks", "hidden_checks.py"):
        src = REPO / "lectures" / name
        if src.is_dir():
            shutil.copytree(src, folder / name)
        elif src.is_file():
            shutil.copy2(src, folder / name)
    return folder


def scores(row):
    return float(row["ex01_power_law"] or 0), float(row["ex01_tresca"] or 0)


def jsonable(graded):
    return json.dumps({k: v for k, v in graded.rows.items()}, indent=1)
