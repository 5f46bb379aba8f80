"""A fuzz campaign on the command line's contract, with hypothesis.

Cases: random parameter sets of every scene (in range, at the ends of the range, out of
range, of the wrong type), malformed command lines, corrupt and foreign saved runs, random
interface laws, and random law files (friction and normal laws as a student writes them,
valid and broken: NaN, inf, negative slip bounds, tensile tractions, c_T <= 0, wrong
derivatives, wrong shapes and counts, math instead of numpy, exceptions) run in the scenes.
The property of every command-line case:

    exit 0 with finite JSON (and every requested output written), or
    exit 2 with exactly one line on stderr (the cause), or
    exit 1 with one line of cause and, after a Newton failure, one line of residual history;
    never a traceback, never a warning, never NaN in an output, never a partial file.

Saved runs: load_run returns the run or raises one ValueError of one line (never another
exception, never advice to allow pickles). Laws: a constructor accepts its parameters or
raises ValueError naming one; the return mapping of an accepted law is finite. Law files:
besides the contract above, no run exits 0 after its law returned a value no law may
return (the law file records every value it returned: NaN or inf, Y < 0, t_N > 0 in
contact) or with a stick stiffness c_T that is not finite and > 0.

Profiles: the quick one runs in CI (about two minutes); `pytest --fuzz long` runs the long
one (>= 500 cases, every scene, >= 300 law files). The summary line with the counts is
printed either way.
"""

import io
import json
import math
import os
import signal
import warnings
from collections import Counter
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, assume, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from conftest import OPTIONS  # noqa: E402
from contactfem.cli import main  # noqa: E402
from contactfem.io import load_run, save_run  # noqa: E402
from contactfem.scenes import all_scenes  # noqa: E402
from contactfem.problem.resources import LIMITS  # noqa: E402

LONG = OPTIONS["fuzz"] == "long"
EXAMPLES = (
    dict(params=330, cli=120, files=120, laws=80, lawfiles=320)
    if LONG
    else dict(params=30, cli=40, files=60, laws=40, lawfiles=40)
)
BUDGET = 1500 if LONG else 300  # cost of a run: steps x (unknowns / 100); dearer cases are skipped
TIMEOUT = 180 if LONG else 90  # seconds: a case running longer is a violation (a hang)
SCENES = (
    sorted(all_scenes())
    if LONG
    else ["bar_impact", "block", "hertz", "patch", "rolling_ring", "sloping_impact", "funnel"]
)
# shorter runs of the dynamic scenes (the fuzzed values override these)
CHEAP = {
    "rolling_ring": {"t_end": 0.2},
    "sloping_impact": {"n_steps": 20},
    "funnel": {"n_steps": 20},
    "cork": {"t_end": 4e-4},
    "bar_impact": {"t_end": 0.5},
}
SIZE_CAP = {"n_steps": 40, "n_press": 12, "n_ramp": 10, "maxit": 60, "max_cuts": 8}  # other ints: low + 24

COUNTS = Counter()
VIOLATIONS = []
SETTINGS = dict(
    deadline=None, database=None, derandomize=not LONG, print_blob=True, suppress_health_check=list(HealthCheck)
)


class CaseTimeout(BaseException):
    pass


def _alarm(signum, frame):
    raise CaseTimeout


def violation(kind, argv, why):
    VIOLATIONS.append((kind, argv, why))
    COUNTS["violations"] += 1
    raise AssertionError(f"{kind} case {argv}: {why}")


def non_finite_json(text):
    """Parse JSON refusing NaN/Infinity; True if the text holds any."""

    def refuse(const):
        raise ValueError(const)

    try:
        json.loads(text, parse_constant=refuse)
    except ValueError:
        return True
    return False


def non_finite(obj):
    if isinstance(obj, dict):
        return any(non_finite(v) for v in obj.values())
    if isinstance(obj, (list, tuple)):
        return any(non_finite(v) for v in obj)
    if isinstance(obj, np.ndarray):
        return obj.dtype.kind in "fc" and not np.all(np.isfinite(obj))
    if isinstance(obj, float):
        return not math.isfinite(obj)
    return False


def run_case(kind, argv, folder, outputs=()):
    """Run the command line in-process in `folder` and check the contract."""
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(folder)
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(TIMEOUT)
    raised = None
    try:
        with warnings.catch_warnings(record=True) as caught, redirect_stdout(out), redirect_stderr(err):
            warnings.simplefilter("always")
            try:
                rc = main(argv)
            except SystemExit as exc:  # --help: argparse prints and exits 0
                rc = exc.code
            except CaseTimeout:
                rc, raised = "timeout", f"still running after {TIMEOUT} s"
            except BaseException as exc:  # would be a traceback
                rc, raised = "traceback", f"{type(exc).__name__}: {exc}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
        os.chdir(cwd)
    COUNTS[f"exit {rc}"] += 1
    COUNTS["cases"] += 1
    COUNTS[kind] += 1
    if raised:
        violation(kind, argv, raised)
    if caught:
        violation(kind, argv, f"warning on stderr: {caught[0].category.__name__}: {caught[0].message}")
    lines = err.getvalue().strip().splitlines()
    names = [f.name for f in Path(folder).iterdir()]
    if any(".part" in n or ".probe" in n for n in names):
        violation(kind, argv, f"partial file left: {names}")
    if "Traceback" in err.getvalue():
        violation(kind, argv, "traceback on stderr")
    present = [o for o in outputs if (Path(folder) / o).exists()]
    if rc == 0:
        if len(present) != len(outputs):
            violation(kind, argv, f"exit 0 but outputs missing: {sorted(set(outputs) - set(present))}")
        for o in outputs:
            p = Path(folder) / o
            if o.endswith(".json") and non_finite_json(p.read_text()):
                violation(kind, argv, f"NaN or inf in {o}")
            if o.endswith((".json", ".npz")) and non_finite(load_run(p)):
                violation(kind, argv, f"NaN or inf in {o} (reloaded)")
        if any(not ln.startswith(("contactfem: warning:", "contactfem: note:")) for ln in lines if "\r" not in ln):
            violation(kind, argv, f"exit 0 with stray stderr: {lines}")
        return rc
    if rc not in (1, 2):
        violation(kind, argv, f"exit code {rc}: {lines}")
    if rc == 1:  # a run that started may have said what it found in the laws beforehand
        while len(lines) > 1 and lines[0].startswith(("contactfem: warning:", "contactfem: note:")):
            lines = lines[1:]
    if present:
        violation(kind, argv, f"exit {rc} but outputs written: {present}")
    if rc == 2 and not (len(lines) == 1 and lines[0].startswith("contactfem: error: ")):
        violation(kind, argv, f"exit 2 needs one line 'contactfem: error: ...', got {lines}")
    if rc == 1 and lines and lines[0].startswith(("contactfem: law failed: ", "contactfem: sweep: ")):
        if len(lines) != 1:
            violation(kind, argv, f"exit 1 of a law or a sweep needs one line, got {lines}")
    elif rc == 1:
        ok = (
            1 <= len(lines) <= 2
            and lines[0].startswith("contactfem: solver failed: ")
            and all(ln.startswith("residual history: ") for ln in lines[1:])
        )
        newton = "Newton" in lines[0] if lines else False
        if not ok or (newton and len(lines) != 2):
            violation(kind, argv, f"exit 1 needs the cause and the residual history, got {lines}")
    return rc


# ---- parameter sets ---------------------------------------------------------------------


def _in_range_float(p):
    lo, hi = p.low, p.high
    vals = [p.default, p.default * 0.5 if p.default else 0.5, p.default * 2 if p.default else 2.0]
    if lo is not None and not p.low_open:
        vals.append(lo)
    if hi is not None and not p.high_open:
        vals.append(hi)
    if lo is None:
        vals += [-1e300, -1.0]
    elif p.low_open:
        vals += [lo + 1e-300 if lo == 0 else lo + abs(lo) * 1e-12, lo + 1e-9]
    if hi is None:
        vals += [1e300, 1e12]
    elif p.high_open:
        vals.append(hi - abs(hi) * 1e-12 if hi else -1e-300)
    strategies = [st.sampled_from(vals)]
    a = lo if lo is not None else -1e6
    b = hi if hi is not None else 1e6
    strategies.append(st.floats(a, b, exclude_min=p.low_open, exclude_max=p.high_open, allow_nan=False))
    return st.one_of(strategies)


def _out_of_range_float(p):
    vals = ["nan", "inf", "-inf", "1e999", "abc", "", "0x10", "1,5"]
    if p.low is not None:
        vals += [p.low - 1.0, p.low - 1e-9 * (1 + abs(p.low))] + ([p.low] if p.low_open else [])
    if p.high is not None:
        vals += [p.high + 1.0] + ([p.high] if p.high_open else [])
    return st.sampled_from(vals)


def _value(p):
    if p.choices is not None:
        return st.one_of(st.sampled_from([str(c) for c in p.choices]), st.sampled_from(["", "magic", "Linear", "1.0"]))
    if isinstance(p.default, bool):
        return st.sampled_from(["true", "false", "maybe"])
    if isinstance(p.default, int):
        hi = min(p.high if p.high is not None else 10**9, SIZE_CAP.get(p.name, (p.low or 0) + 24))
        good = st.integers(int(p.low if p.low is not None else -5), int(hi))
        bad = st.sampled_from(
            ["2.5", "abc", "", "1e3", str(10**12), str((p.low or 0) - 1)]
            + ([str(p.high + 1)] if p.high is not None else [])
        )
        return st.one_of(good.map(str), good.map(str), bad)
    return st.one_of(_in_range_float(p).map(repr), _in_range_float(p).map(repr), _out_of_range_float(p).map(str))


@st.composite
def param_cases(draw):
    name = draw(st.sampled_from(SCENES))
    sc = all_scenes()[name]
    preset = draw(st.sampled_from(["fast", "fast", "paper"]))
    chosen = draw(st.lists(st.sampled_from([p.name for p in sc.params]), min_size=1, max_size=3, unique=True))
    sets = dict(CHEAP.get(name, {}))
    sets.update({k: draw(_value(sc.param(k))) for k in chosen})
    outputs = ["run.json"]
    extra = draw(st.sampled_from(["", "", "run.npz", "save.json"] + (["run.gif"] if LONG and sc.outlines else [])))
    if extra:
        outputs.append(extra)
    return name, preset, sets, outputs


def _cost(name, preset, sets):
    """None if the command line refuses the case before running (cheap), else its cost."""
    sc = all_scenes()[name]
    try:
        params = sc.resolve(preset, sets)
    except ValueError:
        return None
    est = sc.estimate(params)
    if any(est.get(k, 0) > lim for k, lim in LIMITS.items()):
        return None
    return est["steps"] * max(1.0, est["unknowns"] / 100)


@pytest.mark.slow
@settings(max_examples=EXAMPLES["params"], **SETTINGS)
@given(case=param_cases())
def test_fuzz_parameters(case, tmp_path_factory):
    name, preset, sets, outputs = case
    cost = _cost(name, preset, sets)
    assume(cost is None or cost <= BUDGET)
    folder = tmp_path_factory.mktemp("p")
    argv = ["run", name, "--preset", preset]
    for k, v in sets.items():
        argv += ["--set", f"{k}={v}"]
    flags = {".json": "--json", ".npz": "--save", ".gif": "--gif"}
    for o in outputs:
        argv += ["--save" if o.startswith("save") else flags[Path(o).suffix], o]
    run_case("params", argv, folder, outputs)


# ---- malformed command lines ------------------------------------------------------------

TOKENS = [
    "run",
    "show",
    "list",
    "sweep",
    "equations",
    "block",
    "patch",
    "nosuch",
    "--set",
    "--preset",
    "fast",
    "paper",
    "nonsense",
    "--json",
    "--save",
    "--gif",
    "--jobs",
    "--out",
    "--force",
    "--markdown",
    "--help",
    "mu=0.3",
    "law=coulomb",
    "mu==1",
    "=3",
    "c_N=1e999",
    "nx=-1",
    "nx=3.5",
    "x.json",
    "x.npz",
    "x.gif",
    "x.txt",
    "/proc/x.json",
    "/nonexistent/x.json",
    ".",
    "",
    " ",
    "é",
    "--set=mu=1",
    "--jobs=0",
    "--jobs=abc",
    "-x",
    "--",
    "p_y=nan",
    "maxit=1",
    "maxit=1,40",
    "law=coulomb,parabolic",
    "out.csv",
    "out.json",
]


@st.composite
def command_lines(draw):
    kind = draw(st.sampled_from(["tokens", "run", "sweep", "figures"]))
    tail = draw(st.lists(st.sampled_from(TOKENS), max_size=6))
    if kind == "run":
        return ["run", draw(st.sampled_from(["block", "patch", "nosuch", ""]))] + tail
    if kind == "sweep":
        return ["sweep", "block"] + tail
    if kind == "figures":  # only texts that match no figure (figure names are lower case)
        return ["figures", "--only", draw(st.text(alphabet="QZ!%", min_size=1, max_size=4))]
    return tail


@pytest.mark.slow
@settings(max_examples=EXAMPLES["cli"], **SETTINGS)
@given(argv=command_lines())
def test_fuzz_command_lines(argv, tmp_path_factory):
    assume("--jobs" not in " ".join(argv) or "sweep" not in argv)  # no worker processes in-process
    run_case("cli", argv, tmp_path_factory.mktemp("c"))


# ---- corrupt and foreign saved runs -----------------------------------------------------

SAVED = {
    "scene": "block",
    "t": np.linspace(0.0, 1.0, 40),
    "u": np.arange(24.0).reshape(8, 3),
    "state": np.array(["stick", "slip"]),
    "nested": {"k": 3, "ok": True, "x": [1.0, 2.0]},
}
json_values = st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=False) | st.text(max_size=5),
    lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=6), c, max_size=4),
    max_leaves=12,
)


@st.composite
def corrupt(draw):
    suffix = draw(st.sampled_from([".json", ".npz"]))
    how = draw(st.sampled_from(["truncate", "flip", "insert", "random", "json", "formatted"]))
    return suffix, how, draw(st.integers(0, 10**6)), draw(st.binary(min_size=1, max_size=16)), draw(json_values)


@pytest.mark.slow
@settings(max_examples=EXAMPLES["files"], **SETTINGS)
@given(case=corrupt())
def test_fuzz_saved_runs(case, tmp_path_factory):
    suffix, how, where, blob, value = case
    folder = tmp_path_factory.mktemp("f")
    path = Path(save_run(SAVED, folder / f"run{suffix}"))
    raw = path.read_bytes()
    k = where % len(raw)
    data = {
        "truncate": raw[:k],
        "flip": raw[:k] + bytes([raw[k] ^ blob[0]]) + raw[k + 1 :],
        "insert": raw[:k] + blob + raw[k:],
        "random": blob,
        "json": json.dumps(value).encode(),
        "formatted": json.dumps({"format": "contactfem-run/1", "results": value}).encode(),
    }[how]
    path.write_bytes(data)
    COUNTS["cases"] += 1
    COUNTS["files"] += 1
    try:
        res = load_run(path)
    except ValueError as err:
        COUNTS["load_run ValueError"] += 1
        msg = str(err)
        if "\n" in msg or "allow_pickle" in msg:
            violation("files", how, f"message: {msg!r}")
        return
    except FileNotFoundError:
        violation("files", how, "FileNotFoundError for an existing file")
    except BaseException as exc:
        violation("files", how, f"{type(exc).__name__}: {exc}")
    COUNTS["load_run ok"] += 1
    if not isinstance(res, dict):
        violation("files", how, f"returned a {type(res).__name__}")


# ---- random interface laws --------------------------------------------------------------

NUMBERS = st.one_of(
    st.floats(0.01, 10.0),
    st.floats(0.01, 10.0),
    st.floats(0.01, 10.0),
    st.sampled_from([0.0, 1.0, 1e-300, 1e300, 0.5]),
    st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=3), st.none()),
)


@settings(max_examples=EXAMPLES["laws"], **SETTINGS)
@given(
    kind=st.sampled_from(["Coulomb", "ParabolicSlip", "SlipHardening", "PowerLaw", "ExponentialLaw"]),
    values=st.lists(NUMBERS, min_size=4, max_size=4),
)
def test_fuzz_laws(kind, values):
    from contactfem import laws
    from contactfem.laws import return_map

    cls = getattr(laws, kind)
    names = {
        "Coulomb": ("c_T", "mu"),
        "ParabolicSlip": ("c_T", "alpha", "beta", "n"),
        "SlipHardening": ("c_T", "mu", "h"),
        "PowerLaw": ("c_N", "m"),
        "ExponentialLaw": ("a", "b"),
    }[kind]
    kw = dict(zip(names, values))
    COUNTS["cases"] += 1
    COUNTS["laws"] += 1
    try:
        law = cls(**kw)
    except ValueError as err:
        COUNTS["law refused"] += 1
        if not any(n in str(err) for n in names):
            violation("laws", kw, f"the error names no parameter: {err}")
        return
    except BaseException as exc:
        violation("laws", kw, f"{type(exc).__name__}: {exc}")
    COUNTS["law accepted"] += 1
    from contactfem import check_law

    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            report = check_law(law)  # a report in words, whatever the values
        except BaseException as exc:
            violation("laws", kw, f"check_law raised {type(exc).__name__}: {exc}")
    if not isinstance(str(report), str):
        violation("laws", kw, "check_law gave no report")
    with np.errstate(all="ignore"):
        if kind in ("PowerLaw", "ExponentialLaw"):
            t_N, dt_N = law.traction(-np.logspace(-6, 0, 7))
            out = [t_N, dt_N]
        else:
            g = np.full(5, 0.01)
            try:
                r = return_map(law, -g * 10.0, np.full(5, 10.0), np.linspace(-0.1, 0.1, 5), np.zeros(5), np.zeros(5))
            except (FloatingPointError, ValueError):
                return  # refused with a reason: allowed
            out = [v for v in vars(r).values() if isinstance(v, np.ndarray) and v.dtype.kind == "f"]
    if any(not np.all(np.isfinite(a)) for a in out):
        # a law at the edge of floating point may overflow: then the solver must say so
        COUNTS["law non-finite map"] += 1


# ---- random law files --------------------------------------------------------------------

LAW_HEAD = """import math
from dataclasses import dataclass

import numpy as np

SEEN = []     # (method, arguments, returned values): every value the law returned, for the test


def _seen(method, args, out):
    if any(np.iscomplexobj(a) for a in args):
        return    # a complex-step call: its real part is not a value of the law (only its derivative is used)
    try:
        vals = [np.real(np.asarray(a, dtype=complex)).copy() for a in out]
        SEEN.append((method, [np.real(np.asarray(a, dtype=complex)).copy() for a in args], vals))
    except Exception:
        SEEN.append((method, None, None))
"""
GOOD_Y = [
    "self.mu * p",
    "self.mu * p * (1.0 + 0.1 * q)",
    "self.mu * self.P * np.tanh(p / self.P)",
    "self.mu * p + 0.0 * q",
    "self.mu * p ** 0.7",
]
GOOD_YV = ["self.mu * p / (1.0 + v)", "p * (self.mu + 0.1 * np.exp(-v))"]
BAD_Y = [
    "np.sqrt(p - self.P)",
    "np.where(p > self.P, np.nan, self.mu * p)",
    "np.where(p > self.P, -self.mu * p, self.mu * p)",
    "-self.mu * p",
    "self.mu * p / (self.P - p)",
    "np.log(p / self.P)",
    "np.exp(p * self.P)",
    "self.mu * p * np.inf",
    "np.where(q > self.P, np.nan, self.mu * p)",
]
BAD_YV = ["np.where(v > self.P, np.nan, self.mu * p)", "self.mu * p * (1.0 - v / self.P)"]
MODES = (
    ["alone"] * 16
    + ["derivs"] * 8
    + [
        "wrong_derivs",
        "nan_deriv",
        "wrong_count",
        "shape",
        "text",
        "cast",
        "math",
        "ifelse",
        "raise_above",
        "no_c_T",
        "syntax",
    ]
)
C_T = ["30.0", "1e4", "1.0"] * 4 + [None] * 3 + ["0.0", "-1.0", "float('nan')", "float('inf')", "1e-300"]
LAW_SETS = [None] * 24 + ["c_T=-1", "c_T=0", "c_T=nan", "c_T=10", "mu=0.5", "mu=-1", "P=1e-3", "P=1e6", "nu=1"]
GOOD_T = ("np.where(g < 0, self.c_N * g, 0.0)", "np.where(g < 0, self.c_N, 0.0)")
BAD_T = [
    ("np.where(g < 0, -self.c_N * g, 0.0)", "np.where(g < 0, -self.c_N, 0.0)"),
    ("np.where(g < -self.D, np.nan, self.c_N * np.minimum(g, 0.0))", "np.where(g < 0, self.c_N, 0.0)"),
    ("np.where(g < 0, -(np.exp(-1e4 * g) - 1.0), 0.0)", "np.where(g < 0, 1e4 * np.exp(-1e4 * g), 0.0)"),
    ("np.where(g < 0, self.c_N * g, 0.0)", "np.where(g < -self.D, np.inf, self.c_N)"),
]
FRICTION_SCENES = ["block", "rolling_ring"] + (["sloping_impact", "funnel", "cork"] if LONG else [])
NORMAL_SCENES = ["patch", "block"] + (["hertz", "bar_impact", "rolling_ring"] if LONG else [])
LAW_CHEAP = dict(CHEAP, rolling_ring={"t_end": 0.1}, cork={"t_end": 2e-4, "n_press": 2})


def _friction_source(draw):
    rate = draw(st.booleans()) and draw(st.booleans())
    good = draw(st.sampled_from([True, True, True, False, False]))
    y = draw(st.sampled_from((GOOD_YV if rate else GOOD_Y) if good else (BAD_YV + BAD_Y if rate else BAD_Y)))
    mode = draw(st.sampled_from(MODES))
    c_T = draw(st.sampled_from(C_T))
    P = draw(st.sampled_from(["1e-3", "0.3", "30.0", "1e3", "1e7"]))
    args = "p, q, v" if rate else "p, q"
    zeros = ", 0.0 * p" * (3 if rate else 2)
    lines = ["", "", "@dataclass(frozen=True)", "class Law:"]
    if mode != "no_c_T":
        lines.append(f"    c_T: float = {c_T}" if c_T is not None else "    c_T: float")
    lines += ["    mu: float = 0.3", f"    P: float = {P}", ""]
    lines.append(f"    def slip_bound(self, {args}){'' if mode == 'syntax' else ':'}")
    if mode == "cast":
        lines.append("        p = np.asarray(p, dtype=float)")
    else:
        lines.append("        p = np.asarray(p)")
    if mode == "ifelse":
        lines.append("        if p > 1.0:\n            return self.mu * p")
    if mode == "raise_above":
        lines.append("        if np.any(np.real(p) > self.P):\n            raise RuntimeError('above P')")
    expr = f"self.mu * math.tanh(p)" if mode == "math" else y
    lines.append(f"        Y = {expr}")
    out = {
        "alone": "Y",
        "derivs": None,
        "wrong_derivs": f"Y, 1.0 + 0.0 * p{zeros[len(', 0.0 * p') :]}",
        "nan_deriv": f"Y, np.nan * p{zeros[len(', 0.0 * p') :]}",
        "wrong_count": "Y, 0.0",
        "shape": "Y[:1] if np.ndim(Y) else Y",
        "text": "'Y'",
    }.get(mode, "Y")
    if out is None:  # the derivatives by complex step, returned as the law's own (right)
        h = "1e-30"
        parts = [
            f"np.imag(self._y(p + 1j * {h}, q{', v' if rate else ''})) / {h}",
            f"np.imag(self._y(p, q + 1j * {h}{', v' if rate else ''})) / {h}",
        ]
        if rate:
            parts.append(f"np.imag(self._y(p, q, v + 1j * {h})) / {h}")
        lines[-1:] = [f"        Y = self._y(p, q{', v' if rate else ''})"]
        out = "Y, " + ", ".join(parts)
        lines += [
            f"        _seen('slip_bound', ({args},), (Y,))",
            f"        return {out}",
            "",
            f"    def _y(self, {args}):",
            f"        return {y}",
        ]
    else:
        lines += [f"        _seen('slip_bound', ({args},), (Y,))", f"        return {out}"]
    return LAW_HEAD + "\n".join(lines) + "\n", good and mode in ("alone", "derivs") and c_T not in (
        "0.0",
        "-1.0",
        "float('nan')",
        "float('inf')",
    )


def _normal_source(draw):
    good = draw(st.sampled_from([True, False]))
    t, dt = GOOD_T if good else draw(st.sampled_from(BAD_T))
    count = draw(st.sampled_from(["two"] * 7 + ["one"]))
    c_N = draw(st.sampled_from(["10.0", "1e5", "1e3"] * 3 + ["-1.0"]))
    D = draw(st.sampled_from(["1e-6", "1e-3", "0.1"]))
    ret = "t, dt" if count == "two" else "t"
    src = LAW_HEAD + "\n".join(
        [
            "",
            "",
            "@dataclass(frozen=True)",
            "class Law:",
            f"    c_N: float = {c_N}",
            f"    D: float = {D}",
            "",
            "    def traction(self, g):",
            "        g = np.asarray(g, dtype=float)",
            f"        t = {t}",
            f"        dt = {dt}",
            "        _seen('traction', (g,), (t, dt))",
            f"        return {ret}",
            "",
        ]
    )
    return src, good and count == "two"


@st.composite
def law_files(draw):
    kind = draw(st.sampled_from(["friction", "friction", "friction", "normal"]))
    src, good = _friction_source(draw) if kind == "friction" else _normal_source(draw)
    option = kind if draw(st.integers(0, 19)) else ("normal" if kind == "friction" else "friction")
    scene = draw(st.sampled_from(FRICTION_SCENES if option == "friction" else NORMAL_SCENES))
    if not draw(st.integers(0, 24)):
        scene = draw(st.sampled_from(["hertz", "patch"]))  # a scene without that law, now and then
    sets = dict(LAW_CHEAP.get(scene, {}))
    law_set = draw(st.sampled_from(LAW_SETS))
    extra = ["--no-check"] if draw(st.integers(0, 2)) == 0 else []
    return kind, src, good, option, scene, sets, law_set, extra


def _bad_values(module):
    """What the law returned that no law may: [(method, first bad value)]."""
    bad = []
    for method, args, out in getattr(module, "SEEN", []):
        if args is None:
            continue
        try:
            ok_in = np.all([np.isfinite(a) for a in np.broadcast_arrays(*args)], axis=0)
            vals = np.broadcast_arrays(*out, *args)[: len(out)]
        except ValueError:
            continue
        for a in vals:
            if np.any(~np.isfinite(a) & ok_in):
                bad.append((method, "NaN or inf"))
        if method == "slip_bound" and np.any((vals[0] < 0) & ok_in):
            bad.append((method, "Y < 0"))
        if method == "traction" and np.any((vals[0] > 0) & (np.broadcast_to(args[0], vals[0].shape) < 0) & ok_in):
            bad.append((method, "t_N > 0 in contact"))
    return bad


@pytest.mark.slow
@settings(max_examples=EXAMPLES["lawfiles"], **SETTINGS)
@given(case=law_files())
def test_fuzz_law_files(case, tmp_path_factory):
    import sys

    kind, src, good, option, scene, sets, law_set, extra = case
    folder = tmp_path_factory.mktemp("l")
    law = folder / "law.py"
    law.write_text(src)
    argv = ["run", scene, f"--{option}", f"{law}:Law", *extra, "--json", "run.json"]
    for k, v in sets.items():
        argv += ["--set", f"{k}={v}"]
    if law_set:
        argv += ["--set", f"law.{law_set}"]
    before = set(sys.modules)
    rc = run_case("lawfiles", argv, folder, ["run.json"])
    COUNTS[f"law file exit {rc}"] += 1
    modules = [sys.modules[m] for m in set(sys.modules) - before if m.startswith("contactfem_lawfile_")]
    if rc != 0:
        return
    res = json.loads((folder / "run.json").read_text())
    rec = res.get(f"{option}_law", {})
    c_T = rec.get("fields", {}).get("c_T")
    if option == "friction" and not (isinstance(c_T, (int, float)) and math.isfinite(c_T) and c_T > 0):
        violation("lawfiles", argv, f"exit 0 with c_T = {c_T}")
    for m in modules:
        bad = _bad_values(m)
        if bad:
            violation("lawfiles", argv, f"exit 0 although the law returned {bad[0][1]} ({bad[0][0]})")


# ---- the counts ---------------------------------------------------------------------------


def test_fuzz_summary(capsys):
    """Print the counts (run last in this module); the long profile must have run >= 500 cases."""
    line = (
        f"fuzz ({'long' if LONG else 'quick'}): {COUNTS['cases']} cases "
        f"(parameters {COUNTS['params']}, command lines {COUNTS['cli']}, saved files {COUNTS['files']}, "
        f"laws {COUNTS['laws']}, law files {COUNTS['lawfiles']}: exit 0 {COUNTS['law file exit 0']}, "
        f"1 {COUNTS['law file exit 1']}, 2 {COUNTS['law file exit 2']}); exit 0: {COUNTS['exit 0']}, "
        f"exit 1: {COUNTS['exit 1']}, "
        f"exit 2: {COUNTS['exit 2']}; load_run refused {COUNTS['load_run ValueError']}, "
        f"read {COUNTS['load_run ok']}; laws refused {COUNTS['law refused']}, accepted {COUNTS['law accepted']}; "
        f"violations: {len(VIOLATIONS)}"
    )
    with capsys.disabled():
        print("\n" + line)
    assert not VIOLATIONS, VIOLATIONS[:5]
    if LONG:
        assert COUNTS["cases"] >= 500 and COUNTS["lawfiles"] >= 300
