"""Bench study: do the error bands hold? Every scene over the ranges of its discretisations (step, mesh,
penalty, enforcement, integrator, both presets, and the physics that move them: penalty, friction),
each run with its error bars as a user gets them (problem/uncertainty.py, tolerance 5 %), against the
true error of each headline quantity.

The true error is measured against a converged reference of the same physical problem: the closed form
where the scene has one (Hertz's a and p0, the continuous bar's contact duration and rebound, the
patch test's uniform pressure), else a ladder refined in every discretisation that moves the quantity
at once (the step halved and the elements doubled, level after level, with the trapezoidal rule) until
two successive levels agree to REF_AGREE (0.1 %); the finest level is the reference and the ladder is
recorded (where the ladder ends before every quantity agrees, the quantities whose last two levels agree
are judged by them and the others are not judged). Runs that differ only in their discretisation (step, mesh,
integrator, penalty where it
regularises a constraint, enforcement) share their reference. Errors are relative to the quantity's
reference value, or to the scale below which it counts as near zero (the Quantity's own), never
inflated otherwise.

Each run ends in one of:

    covered      every headline quantity's true error lies within its band (+ the reference's own change)
    uncovered    a quantity's band does not hold its true error
    no band      a quantity got no band (the run warns, naming it)
    closed form  the scene's headline is its error against a closed form, which the run knows (the patch)
    refused      a ValueError of one line before any work
    stopped      a one-line error during the run
    crashed      anything else (must stay empty), or past the time limit

and it is *silent-wrong* when it exits without an error and without any AccuracyWarning while a
quantity's true error passes TOL (5 %): that count must be 0. Band efficiency: the median of band /
true error over the covered quantities (1 is a band that holds exactly; large is a loose band).

The study keeps its runs in a checkpoint ($CONTACTFEM_CACHE/coverage, keyed by the runs' parameters and a
digest of the sources they use), so that a study stopped midway goes on where it was; ``quick`` is the
slice the test suite runs."""

import hashlib
import json
import math
import os
import signal
import threading
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from ...problem.accuracy import AccuracyWarning
from ...problem.uncertainty import NOISE, line
from ...scenes import get_scene, run_scene
from ... import environment

TOL = 0.05  # the tolerance every run of the study has (the default): a true error past it is wrong
REF_AGREE = 1e-3  # two successive levels of a reference ladder agree to this (relative)
TIME_LIMIT = 1800.0  # seconds a run with its error bars may take
TRAPEZOIDAL = {"delta": 0.5, "beta_newmark": 0.25}


@dataclass(frozen=True)
class Physics:
    """A physical problem of a scene: the parameters that make it (``over``), and how its reference is
    refined (``refine(k)``: the overrides of level k; None: the scene's closed forms), from level 0 up to
    ``levels`` levels at most."""

    scene: str
    over: dict = field(default_factory=dict)
    refine: object = None
    levels: int = 6
    exact_error: object = None  # (params, values) -> the closed form's own relative error (an approximation's)


def _ring_refine(dt0, n0, t_end=None):
    """A ring scene's reference ladder: the step halved and the elements doubled each level, the
    trapezoidal rule; ``t_end``: the n_steps that reach it (the scenes counted in steps)."""

    def refine(k):
        dt = dt0 / 2**k
        out = dict(TRAPEZOIDAL, dt=dt, n_el=n0 * 2**k)
        if t_end is not None:
            out["n_steps"] = math.ceil(t_end / dt - 1e-9)
        return out

    return refine


def _block_refine(k):
    return {"ny": 8 * 2**k}


def _cork_refine(k):
    return dict(TRAPEZOIDAL, dt_fine=1e-5 / 2**k, travel_max=0.5 / 2**k, n_r=6 * 2**k, n_z=19 * 2**k, n_press=20 * 2**k)


# the paper's 20 time units: a refined ring without damping can touch the plane again after its first
# contact (64 elements: contact from 0 to 2.4 and again from 3 to 5.6), so no shorter run is safe
SLOPING = _ring_refine(0.025, 16, t_end=20.0)
SLOPING_LEVELS = 5  # to 256 elements at dt = 0.0016: a level past it costs an hour on two shared cores
RING_LEVELS = 5  # the rolling ring to 1920 elements, the funnel's half ring to 480: likewise
PHYSICS = {
    "sloping frictionless": Physics("sloping_impact", {}, SLOPING, SLOPING_LEVELS),
    "sloping frictional": Physics("sloping_impact", {"variant": "frictional"}, SLOPING, SLOPING_LEVELS),
    "rolling mu 0.15": Physics("rolling_ring", {}, _ring_refine(0.005, 120), RING_LEVELS),
    "rolling mu 0.3": Physics("rolling_ring", {"mu": 0.3}, _ring_refine(0.005, 120), RING_LEVELS),
    "funnel frictionless": Physics("funnel", {}, _ring_refine(0.05, 30, 15.0), RING_LEVELS),
    "funnel frictional": Physics("funnel", {"variant": "frictional"}, _ring_refine(0.05, 30, 15.0), RING_LEVELS),
    "funnel c_N 20": Physics("funnel", {"c_N": 20.0}, _ring_refine(0.05, 30, 15.0), RING_LEVELS),
    "block conical": Physics("block", {}, _block_refine),
    "block parabolic": Physics("block", {"law": "parabolic"}, _block_refine),
    "block coulomb": Physics("block", {"law": "coulomb", "mu": 0.3}, _block_refine),
    "block c_N 1e4": Physics("block", {"c_N": 1e4}, _block_refine),
    "block lagrange": Physics("block", {"enforcement": "lagrange"}, _block_refine),
    "block nx 10": Physics("block", {"nx": 10}, _block_refine),
    "cork": Physics("cork", {}, _cork_refine, levels=2),
    # Hertz's solution replaces the circle by a parabola near the contact and the disc by a half-space: both
    # neglect terms of relative size (a / R)^2 (the parabola's first neglected term alone is (a / R)^2 / 4)
    "hertz": Physics("hertz", exact_error=lambda p, v: (v["a"]["exact"] / p["R"]) ** 2),
    "bar": Physics("bar_impact"),
    "patch": Physics("patch"),
}


def _sweep(physics, axis, values, extra=None, preset="fast"):
    """Cases of one physics along one axis: (physics, preset, overrides, label)."""
    return [(physics, preset, dict(extra or {}, **{axis: v}), f"{axis}={v:g}") for v in values]


def _steps(physics, dts, t_end, extra=None, preset="fast", label=""):
    """Cases at the steps dts of a scene counted in steps (n_steps kept at t_end / dt)."""
    return [
        (physics, preset, dict(extra or {}, dt=dt, n_steps=math.ceil(t_end / dt - 1e-9)), f"dt={dt:g}{label}")
        for dt in dts
    ]


def cases():
    """The study's runs: (physics, preset, overrides, label)."""
    out = []
    # sloping impact: both presets are the paper's (Newmark 0.7 / 0.4, dt = 0.1, 16 elements)
    for ph in ("sloping frictionless", "sloping frictional"):
        out += [(ph, "paper", {}, "paper preset"), (ph, "fast", {}, "fast preset")]
        out += _steps(ph, (0.2, 0.05, 0.025), 20.0)
        out += _steps(ph, (0.1, 0.05, 0.025, 0.0125), 20.0, TRAPEZOIDAL, label=", trapezoidal")
        out += _steps(ph, (0.1, 0.025), 20.0, {"contact_integration": "energy_consistent"}, label=", energy-consistent")
        out += [(ph, "fast", {"n_el": n}, f"n_el={n}") for n in (8, 32, 64)]
        out += [(ph, "fast", {"accuracy": a}, f"accuracy={a:g}") for a in (0.03, 0.01)]
        out += [(ph, "fast", {"mass_matrix": "consistent"}, "consistent mass")]
    # rolling ring: fast (120 elements, dt = 0.02) and paper (120, 0.01)
    ph = "rolling mu 0.15"
    out += [(ph, "fast", {}, "fast preset"), (ph, "paper", {}, "paper preset")]
    out += _sweep(ph, "dt", (0.04, 0.005)) + _sweep(ph, "n_el", (40, 60, 240))
    out += [(ph, "fast", TRAPEZOIDAL, "trapezoidal"), (ph, "fast", {"contact_integration": "energy_consistent"}, "EC")]
    out += [(ph, "fast", {"accuracy": 0.01}, "accuracy=0.01")]
    ph = "rolling mu 0.3"
    out += [(ph, "fast", {}, "fast preset"), (ph, "paper", {}, "paper preset")]
    out += _sweep(ph, "dt", (0.04, 0.005)) + _sweep(ph, "n_el", (60,)) + [(ph, "fast", TRAPEZOIDAL, "trapezoidal")]
    # funnel: fast = paper (30 elements of the half ring, dt = 0.1)
    for ph in ("funnel frictionless", "funnel frictional"):
        out += [(ph, "fast", {}, "preset")] + _sweep(ph, "dt", (0.2, 0.05, 0.025))
        out += _sweep(ph, "n_el", (15, 60))
        out += [
            (ph, "fast", TRAPEZOIDAL, "trapezoidal"),
            (ph, "fast", {"contact_integration": "energy_consistent"}, "EC"),
        ]
    out += [("funnel c_N 20", "fast", {}, "c_N=20")] + _sweep("funnel c_N 20", "dt", (0.05,))
    # block: static, nx the problem's own; the mesh through the height
    for ph in ("block conical", "block parabolic", "block coulomb", "block c_N 1e4", "block nx 10"):
        out += [(ph, "fast", {}, "preset")] + _sweep(ph, "ny", (2, 4, 16))
    out += [("block conical", "fast", {"contact_discretization": "mortar"}, "mortar")]
    out += [("block lagrange", "fast", {}, "lagrange")] + _sweep("block lagrange", "ny", (4, 16))
    out += [("block lagrange", "fast", {"enforcement": "augmented"}, "augmented")]
    out += _sweep("block lagrange", "ny", (2,)) + _sweep("block nx 10", "ny", (32,))
    # hertz: closed form; mesh, penalty, grading, enforcement, discretisation
    out += [("hertz", "fast", {}, "fast preset"), ("hertz", "paper", {}, "paper preset")]
    out += _sweep("hertz", "n_el", (8, 16, 48))
    out += _sweep("hertz", "c_N", (1e6, 1e7, 1e8, 1e10))
    out += _sweep("hertz", "grading", (0.0, 2.0)) + _sweep("hertz", "grading", (0.0,), {"n_el": 16})
    out += _sweep("hertz", "n_el", (24,)) + _sweep("hertz", "c_N", (1e7,), {"n_el": 16})
    out += [("hertz", "fast", {"penalty": "per_node", "c_N": 1e8}, "per node")]
    out += [("hertz", "fast", {"enforcement": e}, e) for e in ("augmented", "lagrange")]
    out += [("hertz", "fast", {"contact_discretization": "mortar"}, "mortar")]
    out += [("hertz", "fast", {"contact_discretization": "mortar", "n_el": 64}, "mortar, n_el=64")]
    out += [("hertz", "fast", {"penalty": "per_node", "c_N": c}, f"per node, c_N={c:g}") for c in (1e6, 1e7)]
    out += [("hertz", "fast", {"n_el": n, "grading": 2.0}, f"n_el={n}, grading=2") for n in (8, 16)]
    # bar: closed form; step, mesh, penalty, integrators, enforcement
    out += [("bar", "fast", {}, "fast preset"), ("bar", "paper", {}, "paper preset")]
    out += _sweep("bar", "courant", (0.25, 0.5, 2.0, 4.0))
    out += _sweep("bar", "n_el", (10, 20, 80, 200))
    out += _sweep("bar", "c_N_factor", (0.1, 0.3, 3.0, 10.0, 100.0))
    out += _sweep("bar", "c_N_factor", (0.3, 3.0), {"n_el": 100}) + _sweep("bar", "courant", (0.5, 2.0), {"n_el": 20})
    out += _sweep("bar", "courant", (0.5, 2.0), {"n_el": 100}) + _sweep(
        "bar", "n_el", (10, 20, 80), {"c_N_factor": 3.0}
    )
    out += [
        ("bar", "fast", {"delta": 0.7, "beta_newmark": 0.4, "n_el": n}, f"Newmark 0.7, n_el={n}") for n in (20, 100)
    ]
    out += [
        ("bar", "fast", {"integrator": "central_difference", "courant": c}, f"central differences {c:g}")
        for c in (0.5, 0.9)
    ]
    out += [("bar", "fast", {"contact_integration": "energy_consistent"}, "EC")]
    out += [("bar", "fast", {"delta": 0.7, "beta_newmark": 0.4}, "Newmark 0.7")]
    out += [("bar", "fast", {"enforcement": e}, e) for e in ("augmented", "lagrange")]
    out += [("bar", "fast", {"contact_discretization": "mortar"}, "mortar")]
    out += [("bar", "fast", {"accuracy": a}, f"accuracy={a:g}") for a in (0.01, 0.003)]
    # patch: closed form, no band (its headline is its error)
    out += [("patch", "fast", {}, "fast preset"), ("patch", "paper", {}, "paper preset")]
    out += [("patch", "fast", {"nx_lower": a, "nx_upper": b}, f"{a}|{b}") for a, b in ((11, 5), (17, 3), (2, 3))]
    out += [
        ("patch", "fast", o, t)
        for o, t in (
            ({"passes": 2}, "two passes"),
            ({"contact_discretization": "mortar"}, "mortar"),
            ({"enforcement": "lagrange"}, "lagrange"),
            ({"mu": 0.3, "E_upper": 500.0}, "friction"),
        )
    ]
    # the cork: its preset, and its step varied (the fine step and the travel limit)
    out += [("cork", "fast", {}, "fast preset"), ("cork", "paper", {}, "paper preset")]
    out += [("cork", "fast", {"dt_fine": 2e-5 * f, "travel_max": 1.0 * f}, f"step x {f:g}") for f in (0.5, 2.0)]
    # the cheap scenes first: a study stopped midway has judged the most runs
    order = ("block", "hertz", "bar_impact", "patch", "sloping_impact", "funnel", "rolling_ring", "cork")
    return sorted(out, key=lambda c: order.index(PHYSICS[c[0]].scene))


QUICK = [
    ("bar", "fast", {"n_el": 10}, "n_el=10"),
    ("hertz", "fast", {"n_el": 8}, "n_el=8"),
    ("patch", "fast", {}, "fast preset"),
    ("block conical", "fast", {"ny": 4}, "ny=4"),
]


# -- running, with a checkpoint ---------------------------------------------------------------------


PHYSICS_SOURCES = (
    "clock.py",
    "laws",
    "contact",
    "bodies",
    "solver",
    "scenes",
    "problem/time_integration.py",
    "problem/enforcement.py",
    "problem/model.py",
    "problem/params.py",
)


def _digest(physics_only=False):
    """A digest of the library's sources that runs compute with (not the command line, the plots, the files
    or the lab), for the checkpoint's keys; ``physics_only``:
    of the sources a run's values come from (PHYSICS_SOURCES; not its indicators, bands, plots or files)."""
    import contactfem

    root = Path(contactfem.__file__).parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        rel = f.relative_to(root)
        if rel.parts[0] in ("lab", "plots", "io", "cli.py", "equations.py", "__main__.py"):  # (not what runs compute)
            continue
        if physics_only and not any(str(rel) == p or str(rel).startswith(p + "/") for p in PHYSICS_SOURCES):
            continue
        h.update(str(rel).encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:16]


class Checkpoint:
    """The study's runs kept on disk as they end (one JSON file per run, keyed by what it ran and the
    code's digest), so that a study stopped midway goes on where it was. ``path`` None: none kept."""

    def __init__(self, path):
        self.path = None if path is None else Path(path)

    def _file(self, key):
        return self.path / (hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:24] + ".json")

    def get(self, key, compute):
        if self.path is None:
            return compute()
        f = self._file(key)
        if f.exists():
            return json.loads(f.read_text())
        value = compute()
        self.path.mkdir(parents=True, exist_ok=True)
        tmp = f.with_suffix(".tmp")
        tmp.write_text(json.dumps(value))
        tmp.replace(f)
        return value


def default_checkpoint():
    root = Path(environment.read("CONTACTFEM_CACHE") or Path.home() / ".cache" / "contactfem")
    return root / "coverage"


class _Late(Exception):
    pass


def _limited(fn, seconds):
    if seconds is None or threading.current_thread() is not threading.main_thread() or not hasattr(signal, "SIGALRM"):
        return fn()

    def stop(signum, frame):
        raise _Late()

    old = signal.signal(signal.SIGALRM, stop)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return fn()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _values(scene, r):
    """The headline quantities' values, their closed forms and what they are relative to."""
    sc = get_scene(scene)
    out = {}
    for q in sc.quantities:
        v = r.get(q.name)
        exact = r.get(q.exact) if isinstance(q.exact, str) else q.exact
        out[q.name] = dict(value=v if isinstance(v, (int, float)) and not isinstance(v, bool) else None, exact=exact)
    return out


def attempt(scene, preset, over, error_bars=True, seconds=TIME_LIMIT):
    """One run as a user gets it: dict(outcome=ran|refused|stopped|crashed, values, uncertainty,
    warnings (the AccuracyWarning lines), time_s)."""
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = _limited(lambda: run_scene(scene, preset, over, error_bars=error_bars, tolerance=TOL), seconds)
        except _Late:
            return dict(outcome="crashed", error=f"past {seconds:g} s", time_s=time.perf_counter() - t0)
        except (ValueError, RuntimeError, ArithmeticError) as err:
            text = str(err)
            one = bool(text) and "\n" not in text.strip()
            kind = ("refused" if isinstance(err, ValueError) else "stopped") if one else "crashed"
            return dict(outcome=kind, error=f"{type(err).__name__}: {text}"[:300], time_s=time.perf_counter() - t0)
        except Exception as err:  # noqa: BLE001 (anything else is a crash, counted)
            return dict(outcome="crashed", error=f"{type(err).__name__}: {err}"[:300], time_s=time.perf_counter() - t0)
    lines = [str(w.message) for w in caught if issubclass(w.category, AccuracyWarning)]
    u = r.get("uncertainty") or {}
    separated = (r.get("accuracy") or {}).get("separated", {}).get("ok", True)
    return dict(
        outcome="ran",
        values=_values(scene, r),
        uncertainty=u.get("quantities", {}),
        bars_s=u.get("wall_time_s"),
        bar_runs=u.get("runs"),
        run_s=r["wall_time_s"],
        warnings=lines,
        separated=separated,
        t_separation=r.get("t_separation"),
        t_end=float(r["t"][-1]) if isinstance(r.get("t"), list) and r["t"] else None,
        time_s=time.perf_counter() - t0,
    )


def reference(name, checkpoint, progress=None):
    """The converged reference of a physics (module docstring): dict(values, change, ladder, converged),
    or None for a scene's closed forms."""
    ph = PHYSICS[name]
    if ph.refine is None:
        return None
    sc = get_scene(ph.scene)
    ladder, prev = [], None
    for k in range(ph.levels):
        over = dict(ph.over, **ph.refine(k))
        run = checkpoint.get(
            ["reference", ph.scene, over, _digest(physics_only=True)], lambda: attempt(ph.scene, "paper", over, False)
        )
        level = dict(k=k, overrides=over, outcome=run["outcome"], error=run.get("error"), time_s=run["time_s"])
        if run["outcome"] == "ran" and not run["separated"]:
            level.update(outcome="stopped", error="ends in contact: its rebound would be read mid-impact")
        if run["outcome"] == "ran" and run.get("t_separation") is not None and run["t_separation"] > 0.5 * run["t_end"]:
            level.update(outcome="stopped", error="left the obstacle in the run's second half: it may touch again")
        if level["outcome"] != "ran":
            ladder.append(level)
            break
        values = {q: v["value"] for q, v in run["values"].items()}
        level["values"] = values
        ladder.append(level)
        if progress:
            progress(f"coverage: reference {name} level {k}: {values}")
        if prev is not None:
            params = sc.resolve("paper", over)
            change = {}
            for q in sc.quantities:
                a, b = prev.get(q.name), values.get(q.name)
                if a is None or b is None:
                    change[q.name] = 0.0 if a is None and b is None else math.inf
                else:
                    change[q.name] = abs(b - a) / max(q.reference(params, b), 1e-300)
            level["change"] = change
            if max(change.values(), default=0.0) <= REF_AGREE:
                return dict(values=values, change=change, ladder=ladder, converged=True)
        prev = values
    # not every quantity agreed: those whose last two levels did are judged by them, the others by none
    last = next((lv for lv in reversed(ladder) if "change" in lv), None)
    agreed = [q for q, c in (last or {}).get("change", {}).items() if c <= REF_AGREE]
    if not agreed:
        return dict(values=None, change=None, ladder=ladder, converged=False)
    pick = lambda d: {q: d[q] for q in agreed}
    return dict(values=pick(last["values"]), change=pick(last["change"]), ladder=ladder, converged=False)


def judge(scene, preset, over, run, ref):
    """A run's outcome (module docstring), its true errors and bands per quantity, and whether it is
    silent-wrong."""
    if run["outcome"] != "ran":
        return dict(outcome=run["outcome"], quantities={}, silent_wrong=False)
    sc = get_scene(scene)
    params = sc.resolve(preset, over)
    rows, outcome = {}, "covered"
    for q in sc.quantities:
        v = run["values"].get(q.name, {})
        value = v.get("value")
        if value is None:
            continue
        if ref is None:
            ph = next((ph for ph in PHYSICS.values() if ph.scene == scene and ph.refine is None), None)
            own = ph.exact_error(params, run["values"]) if ph is not None and ph.exact_error else 0.0
            truth, ref_change = v.get("exact"), own
        else:
            truth = (ref.get("values") or {}).get(q.name)
            ref_change = (ref.get("change") or {}).get(q.name, 0.0)
        if truth is None:
            continue
        scale = q.reference(params, truth)
        error = abs(value - truth) / scale
        u = run["uncertainty"].get(q.name)
        band = None if u is None or u.get("band") is None else u["band"] / scale
        row = dict(value=value, reference=truth, error=error, band=band, reference_change=ref_change)
        if not q.controls:
            row["kind"] = "closed form"
        elif band is None:
            row["kind"] = "no band"
        else:
            # (an error within Newton's tolerance, NOISE, is no error: the frictionless v_x is 2 to rounding)
            row["kind"] = "covered" if error <= band + ref_change + NOISE else "uncovered"
        rows[q.name] = row
    kinds = {r["kind"] for r in rows.values()}
    for k in ("uncovered", "no band", "closed form"):
        if k in kinds:
            outcome = k
            break
    if not rows:
        outcome = "no reference"
    wrong = any(r["error"] > TOL for r in rows.values())
    return dict(outcome=outcome, quantities=rows, silent_wrong=bool(wrong and not run["warnings"]))


OUTCOMES = ("covered", "uncovered", "no band", "closed form", "refused", "stopped", "crashed", "no reference")


def coverage_study(quick=False, progress=None, checkpoint=None, seconds=TIME_LIMIT):
    """Run the study (``quick``: the test suite's slice; ``checkpoint``: a folder for the runs, None:
    $CONTACTFEM_CACHE/coverage, False: none); rows, references, counts and the coverage figures."""
    store = Checkpoint(None if checkpoint is False else (checkpoint or default_checkpoint()))
    todo = QUICK if quick else cases()
    refs, rows = {}, []
    digest = _digest()
    for name, preset, over, label in todo:
        ph = PHYSICS[name]
        full = dict(ph.over, **over)
        if name not in refs:
            refs[name] = reference(name, store, progress)
        unjudged = refs[name] is not None and not refs[name]["values"]
        if unjudged and not label.endswith("preset"):  # no truth to judge it by: only the presets are run (README)
            run = dict(outcome="ran", values={}, uncertainty={}, warnings=[], time_s=0.0, skipped=True)
        else:
            run = store.get(
                ["run", ph.scene, preset, full, digest], lambda: attempt(ph.scene, preset, full, True, seconds)
            )
        verdict = judge(ph.scene, preset, full, run, refs[name])
        row = dict(
            scene=ph.scene,
            physics=name,
            lines={k: line(k, e) for k, e in (run.get("uncertainty") or {}).items()},
            values={k: e.get("value") for k, e in (run.get("uncertainty") or {}).items()},
            preset=preset,
            overrides=full,
            label=label,
            outcome=verdict["outcome"],
            silent_wrong=verdict["silent_wrong"],
            quantities=verdict["quantities"],
            warnings=run.get("warnings", []),
            error=run.get("error", ""),
            run_s=run.get("run_s"),
            bars_s=run.get("bars_s"),
            bar_runs=run.get("bar_runs"),
        )
        rows.append(row)
        if progress:
            progress(f"coverage: {name} {preset} {label}: {row['outcome']} {_text(row['quantities'])}")
    return summarise(rows, refs, quick)


def summarise(rows, refs, quick=False):
    """The study's counts and figures from its rows (module docstring)."""
    counts = {k: sum(r["outcome"] == k for r in rows) for k in OUTCOMES}
    banded = [r for r in rows if r["outcome"] in ("covered", "uncovered")]
    pairs = [q for r in rows for q in r["quantities"].values() if q["kind"] in ("covered", "uncovered")]
    held = [q for q in pairs if q["kind"] == "covered" and q["error"] > 0]
    ratios = sorted(q["band"] / q["error"] for q in held)
    overhead = sorted((r["run_s"] + r["bars_s"]) / r["run_s"] for r in rows if r.get("bars_s") and r.get("run_s"))
    return dict(
        tol=TOL,
        reference_agreement=REF_AGREE,
        quick=bool(quick),
        runs=len(rows),
        counts=counts,
        runs_with_bands=len(banded),
        coverage=counts["covered"] / len(banded) if banded else None,
        quantities_with_bands=len(pairs),
        quantity_coverage=sum(q["kind"] == "covered" for q in pairs) / len(pairs) if pairs else None,
        silent_wrong=sum(r["silent_wrong"] for r in rows),
        band_efficiency=_median(ratios),
        overhead_median=_median(overhead),
        references={k: None if v is None else dict(v, ladder=v["ladder"]) for k, v in refs.items()},
        rows=rows,
    )


def _median(xs):
    xs = sorted(xs)
    if not xs:
        return None
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


def _text(quantities):
    return ", ".join(
        f"{k} {100 * q['error']:.2g} % / " + ("-" if q["band"] is None else f"{100 * q['band']:.2g} %")
        for k, q in quantities.items()
    )


def coverage_markdown(res):
    """The BENCHMARKS.md section of the study."""
    c = res["counts"]
    pct = lambda x: "-" if x is None else f"{100 * x:.1f} %"
    L = [
        "## Do the error bands hold? Coverage",
        "",
        f"{res['runs']} runs over every scene (contactfem/lab/bench/coverage.py), each with its error bars as a user "
        f"gets them (tolerance {100 * res['tol']:g} %), against the true error of each headline quantity: the "
        "closed form where the scene has one, else a reference refined in step and mesh at once (trapezoidal rule) "
        f"until two successive levels agree to {100 * res['reference_agreement']:g} % (each reference's ladder is in "
        "bench.json). A run is *covered* when every quantity's true error lies within its band (plus its "
        "reference's own uncertainty: a ladder's last change; Hertz's closed form, an approximation of the disc, "
        "(a / R)^2); *silent-wrong* when it exits without an error and without any accuracy "
        f"warning while a quantity is more than {100 * res['tol']:g} % off.",
        "",
        "![true error against the band, every quantity of the study](figures/bench_coverage.png)",
        "",
        f"- coverage: **{pct(res['coverage'])}** of the {res['runs_with_bands']} runs with bands "
        f"({pct(res['quantity_coverage'])} of their {res['quantities_with_bands']} quantities)",
        f"- silent-wrong runs: **{res['silent_wrong']}**",
        f"- band efficiency (median band / true error, covered quantities): {_f(res['band_efficiency'])}",
        f"- error bars' cost over these runs (median of (run + error bars) / run): {_f(res['overhead_median'])}",
        "",
        "| outcome | runs |",
        "|---|---|",
    ]
    L += [f"| {k} | {c.get(k, 0)} |" for k in OUTCOMES]
    L += [
        "",
        "References (the finest level of each ladder; its last change between levels):",
        "",
        "| physics | scene | converged | levels | reference values | last change |",
        "|---|---|---|---|---|---|",
    ]
    for name, ref in res["references"].items():
        if ref is None:
            L.append(f"| {name} | {PHYSICS[name].scene} | closed form | - | - | - |")
            continue
        values = ", ".join(f"{k} {v:.6g}" for k, v in (ref["values"] or {}).items() if v is not None) or "-"
        change = ", ".join(f"{k} {v:.1e}" for k, v in (ref["change"] or {}).items()) or "-"
        converged = (
            _f(ref["converged"]) if ref["converged"] or not ref["values"] else "only " + ", ".join(ref["values"])
        )
        L.append(f"| {name} | {PHYSICS[name].scene} | {converged} | {len(ref['ladder'])} | {values} | {change} |")
    L += [
        "",
        "| scene | physics | preset | setting | outcome | true error / band per quantity | warnings or error |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        what = "; ".join(w.split(" (")[0][:70] for w in r["warnings"]) or r["error"][:100]
        L.append(
            f"| {r['scene']} | {r['physics']} | {r['preset']} | {r['label']} | {r['outcome']} | "
            f"{_text(r['quantities']) or '-'} | {what.replace('|', '/') or '-'} |"
        )
    return L + [""]


def _f(x):
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return f"{x:.3g}"


# the runs the README states: the three defaults the issue named, and Table 2 at the paper's data
DEFAULTS = (
    ("sloping frictionless", "fast", "`sloping_impact` (its fast preset is the paper's run)"),
    ("sloping frictional", "fast", "`sloping_impact --set variant=frictional`"),
    ("rolling mu 0.15", "fast", "`rolling_ring` (fast preset: 120 elements at dt = 0.02)"),
)


def _row(res, physics, preset, label=None):
    return next(
        (
            r
            for r in res["rows"]
            if r["physics"] == physics and r["preset"] == preset and (label is None or r["label"] == label)
        ),
        None,
    )


def _quantity_text(row, name, ref=None):
    q = row["quantities"].get(name)
    shown = row.get("lines", {}).get(name, name)
    if q is None:  # no converged reference: what its finest level says, and how far it still moves
        last = (ref or {}).get("ladder", [{}])[-1]
        if name not in last.get("values", {}) or name not in last.get("change", {}):
            return shown + " (no reference to judge it by)"
        o, v = last["overrides"], last["values"][name]
        return (
            f"{shown}: {100 * abs(row['values'][name] / v - 1):.1f} % off the finest level of its reference "
            f"ladder, {v:.4g} ({o.get('n_el')} elements, dt = {o.get('dt'):g}), which still moves by "
            f"{100 * last['change'][name]:.1f} % (not converged to {100 * REF_AGREE:g} %)"
        )
    verdict = {"covered": "the band holds it", "no band": "no band, and the run says so"}.get(
        q["kind"], "**the band does not hold it**"
    )
    return (
        f"{shown}: {100 * q['error']:.1f} % off the reference {q['reference']:.4g} refined in step and mesh ({verdict})"
    )


def readme_lines(res):
    """The README's account of the study (its block coverage, lab/readme.py): coverage, the defaults
    and Table 2 at the paper's data."""
    c = res["counts"]
    pct = lambda x: "-" if x is None else f"{100 * x:.1f} %"
    lines = [
        f"`contactfem bench --only coverage` runs {res['runs']} runs over the eight scenes (the ranges of step, mesh, "
        "penalty, enforcement, integrator, both presets, and the physics that move them), each with its error bars, "
        "against a closed form or a reference refined in step and mesh at once until two successive levels agree "
        f"to {100 * res['reference_agreement']:g} %: the bands hold the true errors of {pct(res['coverage'])} of the "
        f"{res['runs_with_bands']} runs with bands ({pct(res['quantity_coverage'])} of their "
        f"{res['quantities_with_bands']} quantities); {res['silent_wrong']} runs are silent-wrong (more than "
        f"{100 * res['tol']:g} % off without a warning); a band is typically {_f(res['band_efficiency'])} times its "
        f"true error (the median); {c['no band']} runs got no band for a quantity and warned; {c['closed form']} are "
        f"the patch test's, whose headline is its error against the closed form; {c['refused'] + c['stopped']} were "
        f"refused or stopped in one line, {c['no reference']} have no converged reference (BENCHMARKS.md, figure "
        "bench_coverage).",
    ]
    for physics, preset, what in DEFAULTS:
        row = _row(res, physics, preset, "fast preset")
        if row is None:
            continue
        ref = res["references"].get(physics)
        texts = "; ".join(_quantity_text(row, k, ref) for k in row.get("lines") or row["quantities"])
        warned = sorted({w.split(" = ")[0].split(": ")[1].split(":")[0] for w in row["warnings"] if ": " in w})
        lines.append(f"- {what}: {texts}; it warns: {', '.join(warned) or 'no'}.")
    table2 = [(p, _row(res, p, "paper", "paper preset")) for p in ("sloping frictionless", "sloping frictional")]
    if all(r is not None for _, r in table2):
        parts = []
        for physics, row in table2:
            names = ["rebound_vy"] if physics.endswith("frictionless") else ["rebound_vx", "rebound_vy"]
            parts.append(f"{physics.split()[-1]}: " + "; ".join(row.get("lines", {}).get(n, n) for n in names))
        lines.append(
            "Table 2 at the paper's data, each number with the band of its own discretisation: "
            + "; ".join(parts)
            + "."
        )
    return lines
