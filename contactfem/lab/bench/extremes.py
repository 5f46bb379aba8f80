"""Bench study: the extremes grid. Every scene at the ends of its numerical ranges, where they
apply: the penalty from 1e-4 to 1e18 times the scene's, the step from 1e-3 to 10 times, friction
mu = 0 and 2, the coarsest and a fine mesh, every enforcement, contact discretisation and time
integration. Each run ends in one of:

    within     no indicator past its threshold, every headline quantity within 5 % of its reference
    flagged    at least one accuracy indicator past its threshold (the run warns; --strict: exit 1)
    refused    a ValueError of one line before any work (a setting the scene does not take)
    stopped    a one-line error during the run (Newton did not converge, a law returned nonsense)
    wrong      none of the above: exit 0, no warning, a headline quantity more than 5 % off

and ``wrong`` must stay empty. A crash (another exception or a message of several lines) and a
run past its time limit are counted apart; they must stay empty too.

The reference of a run is its closed form where the scene has one for the headline (Hertz's a,
p0; the patch's uniform pressure), else the same physical problem with the numerical settings
refined: the step REFINE times the scene's (a run finer still is checked against that converged
answer; the cork's dt sets its gas ramp, so its pop's dt_fine and travel_max are refined instead),
the penalty max(the run's, the scene's) (the scene's is argued stiff enough; a stiffer one is
nearer the constraint), the mesh the finer of the run's and the preset's, the scene's default
enforcement, discretisation and integrator; the static block uses Lagrange multipliers (no
penalty error at all) and keeps its nx (its free ends are counted in elements). A headline
quantity near zero is compared with a scale of the scene (its initial speed) instead of itself.
A run and its reference share what makes the smallest step affordable (Spec.tiny).

The grid is no Cartesian product: each axis is walked from the fast preset, one at a time, and the
penalty and the step are crossed where they interact (the dynamic scenes); the run's end time is
shortened where the headline quantity is decided early (argued at each scene). The finest mesh is
the finest this bench affords, not the range's end (Hertz n_el = 2000 is four million quads).
``quick`` is the slice the test suite runs (seconds).
"""

import signal
import threading
import time
import warnings
from dataclasses import dataclass, field

from ...scenes import get_scene, run_scene
from ...problem.accuracy import AccuracyWarning

TOL = 0.05  # a headline quantity more than 5 % off its reference is wrong
REFINE = 0.25  # the reference's step, times the scene's (the presets are first order at worst:
# the reference's own error is a quarter of the preset's, which is below 5 %)
TIME_LIMIT = 240.0  # seconds one run may take before it counts as past its time limit
C_N = (1e-4, 1e-2, 1.0, 1e2, 1e4, 1e9, 1e18)  # penalty factors on the static scenes
C_N_DYN = (1e-4, 1e-2, 1.0, 1e4, 1e18)  # and on the dynamic ones, crossed with DT
DT = (1.0, 10.0)  # step factors crossed with the penalty
DT_ALONE = 0.1  # a step factor at the scene's penalty only, beside Spec.tiny
NUMERICAL = {
    "c_N",
    "c_N_factor",
    "dt",
    "dt_fine",
    "courant",
    "n_steps",
    "t_end",
    "enforcement",
    "contact_discretization",
    "contact_integration",
    "integrator",
    "passes",
    "n_el",
    "nx",
    "ny",
    "nx_lower",
    "nx_upper",
    "n_r",
    "n_z",
    "uzawa_tol",
    "travel_max",
}


@dataclass(frozen=True)
class Spec:
    """How a scene enters the grid."""

    headlines: tuple  # result keys compared with the reference
    base: dict = field(default_factory=dict)  # overrides every run shares (a shortened end)
    scale: dict = field(default_factory=dict)  # headline -> the absolute scale of a near-zero one
    c_N: str = "c_N"  # the penalty's parameter
    dt: str = None  # the step's parameter (None: static)
    steps: float = None  # end time kept by n_steps = steps / dt (the scenes counted in steps)
    mesh: tuple = ()  # (coarsest overrides, finest overrides)
    mu: tuple = ()  # the overrides of mu = 0 and mu = 2
    methods: tuple = ()  # enforcement / discretisation / integration overrides
    exact: dict = None  # headline -> the result key of its closed form
    reference: dict = field(default_factory=dict)  # what the reference adds (the block: lagrange)
    c_N_factors: tuple = None  # the penalty factors, where not C_N / C_N_DYN (the cork: cost)
    physical: tuple = ()  # numerical elsewhere, part of the problem here (the block's nx)
    tiny: tuple = (1e-3, {})  # the smallest step factor and what makes it affordable (shared by its reference)
    ref_mesh: dict = field(default_factory=dict)  # the reference's mesh at least this fine (else the preset's)


SCENES = {
    # static, closed form: a and p0 against Hertz's, whatever the run's settings
    "hertz": Spec(
        ("a", "p0"),
        mesh=({"n_el": 4}, {"n_el": 128}),
        exact={"a": "a_exact", "p0": "p0_exact"},
        methods=(
            {"contact_discretization": "mortar"},
            {"enforcement": "augmented"},
            {"enforcement": "lagrange"},
            {"enforcement": "lagrange", "contact_discretization": "mortar"},
            {"enforcement": "lagrange", "c_N": 1e5},
            {"enforcement": "lagrange", "c_N": 1e27},
            {"enforcement": "augmented", "contact_discretization": "mortar"},
        ),
    ),
    # static: the largest displacement against the same block solved with Lagrange multipliers and 16
    # elements through its height; nx is the problem's own (the free ends are free_end_nodes of nx)
    "block": Spec(
        ("max_displacement",),
        mesh=({"nx": 3, "ny": 1}, {"nx": 3, "ny": 1, "free_end_nodes": 1}, {"nx": 100, "ny": 32}),
        mu=({"law": "coulomb", "mu": 0.0}, {"law": "coulomb", "mu": 2.0}),
        methods=(
            {"contact_discretization": "mortar"},
            {"enforcement": "augmented"},
            {"enforcement": "lagrange"},
            {"law": "coulomb", "enforcement": "lagrange"},
        ),
        reference={"enforcement": "lagrange"},
        physical=("nx",),
        ref_mesh={"ny": 16},
    ),
    # static, closed form: the uniform pressure on both blocks (pressure_deviation_max is the error)
    "patch": Spec(
        ("pressure",),
        mesh=(
            {"nx_lower": 1, "nx_upper": 1, "ny": 1},
            {"nx_lower": 11, "nx_upper": 5},
            {"nx_lower": 17, "nx_upper": 3},
            {"nx_lower": 64, "nx_upper": 117, "ny": 16},
        ),
        mu=({"mu": 2.0},),
        methods=(
            {"passes": 2},
            {"contact_discretization": "mortar"},
            {"enforcement": "augmented"},
            {"enforcement": "lagrange"},
            {"enforcement": "lagrange", "contact_discretization": "mortar"},
            {"enforcement": "lagrange", "c_N": 1e10},
            {"enforcement": "lagrange", "c_N": 1e24},
            {"contact_discretization": "mortar", "nx_lower": 17, "nx_upper": 3},
        ),
    ),
    # the rebound is over by t = 2.4 (the paper's step: contact from 0.1 to 2.4): end at 4; dt / 1000 ends at 3
    "sloping_impact": Spec(
        ("rebound_vx", "rebound_vy"),
        scale={"rebound_vx": 2.83, "rebound_vy": 2.83},
        tiny=(1e-3, {"n_steps": 30000}),
        dt="dt",
        steps=4.0,
        mesh=({"n_el": 3}, {"n_el": 400}),
        mu=({"variant": "frictional", "alpha": 0.0, "beta": 0.0}, {"variant": "frictional", "alpha": 0.0, "beta": 2.0}),
        methods=(
            {"contact_integration": "energy_consistent"},
            {"contact_integration": "energy_consistent", "c_N": 5e5},
            {"variant": "frictional"},
            {"variant": "viscoplastic"},
            {"kind": "continuum"},
        ),
    ),
    # rolling starts near t = 1.02 s (mu = 0.15) and v_final is read after it: 1.5 s of the 2
    # dt / 1000: mu = 2 rolls from t = 0.076 s, so 0.2 s of it (10,000 steps) decides v_final
    "rolling_ring": Spec(
        ("v_final", "x_end"),
        base={"t_end": 1.5},
        scale={"v_final": 300.0},
        dt="dt",
        tiny=(1e-3, {"mu": 2.0, "t_end": 0.2}),
        mesh=({"n_el": 8}, {"n_el": 480}),
        mu=({"mu": 1e-9}, {"mu": 2.0}),
        methods=({"contact_integration": "energy_consistent"}, {"kind": "continuum"}),
    ),
    # one impact: contact lasts 2L/c, the run ends at 1.5 of it (the preset)
    # courant / 1000 on 4 elements (12,000 steps; 40 elements would take 120,000)
    "bar_impact": Spec(
        ("duration", "rebound_velocity"),
        c_N="c_N_factor",
        dt="courant",
        tiny=(1e-3, {"n_el": 4}),
        mesh=({"n_el": 2}, {"n_el": 400}),
        methods=(
            {"integrator": "central_difference", "courant": 0.5},
            {"contact_integration": "energy_consistent"},
            {"contact_discretization": "mortar"},
            {"enforcement": "augmented"},
            {"enforcement": "lagrange"},
            {"enforcement": "lagrange", "c_N_factor": 1e-4},
            {"enforcement": "lagrange", "c_N_factor": 1e18},
        ),
    ),
    # the lowest point is reached at t = 4.4 and the ring has left the wall by 7: end at 8
    # dt / 100 (8,000 steps): dt / 1000 would take 80,000
    "funnel": Spec(
        ("y_c_min", "v_c_final"),
        scale={"v_c_final": 4.0},
        dt="dt",
        steps=8.0,
        tiny=(1e-2, {}),
        mesh=({"n_el": 2}, {"n_el": 240}),
        mu=({"variant": "frictional", "alpha": 0.0, "beta": 0.0}, {"variant": "frictional", "alpha": 0.0, "beta": 2.0}),
        methods=({"contact_integration": "energy_consistent"}, {"variant": "frictional"}),
    ),
    # 8 s a run at the fast preset: the penalty's ends, friction's and the coarse mesh only; the reference
    # refines the pop's dt_fine and travel_max
    "cork": Spec(
        ("exit_velocity_m_s", "exit_time_ms"),
        mu=({"mu": 0.0}, {"mu": 2.0}),
        mesh=({"n_r": 1, "n_z": 3},),
        c_N_factors=(1e-4, 1e4),
    ),
}


def _default(scene, name):
    return get_scene(scene).resolve("fast", {})[name]


def _with_step(spec, scene, over, factor):
    """over with the step `factor` times the scene's (and the end time kept)."""
    out = dict(over)
    if scene == "cork":
        out.update(dt=_default(scene, "dt") * factor, dt_fine=_default(scene, "dt_fine") * factor)
    elif spec.dt:
        out[spec.dt] = _default(scene, spec.dt) * factor
        if spec.steps and "n_steps" not in over:
            out["n_steps"] = max(1, round(spec.steps / out[spec.dt]))
    return out


def grid(quick=False):
    """The runs: a list of (scene, overrides, axis, what the reference shares)."""
    if quick:
        return [(s, o, a, {}) for s, o, a in QUICK]
    return [p if len(p) == 4 else p + ({},) for p in _points()]


def _points():
    points = []
    for scene, spec in SCENES.items():
        base = _with_step(spec, scene, spec.base, 1.0)
        c0 = _default(scene, spec.c_N)
        dynamic = spec.dt is not None or scene == "cork"
        for f in spec.c_N_factors or (C_N_DYN if dynamic else C_N):
            for d in DT if spec.dt else (1.0,):
                points.append(
                    (
                        scene,
                        dict(_with_step(spec, scene, spec.base, d), **{spec.c_N: c0 * f}),
                        f"c_N x {f:g}" + (f", dt x {d:g}" if spec.dt else ""),
                    )
                )
        if spec.dt:
            points.append((scene, _with_step(spec, scene, spec.base, DT_ALONE), f"dt x {DT_ALONE:g}"))
            f, keep = spec.tiny
            points.append(
                (
                    scene,
                    _with_step(spec, scene, dict(spec.base, **keep), f),
                    f"dt x {f:g}" + (f" ({_text(keep)})" if keep else ""),
                    keep,
                )
            )
        for over in spec.mesh:
            points.append((scene, dict(base, **over), "mesh " + _text(over)))
        for over in spec.mu:
            points.append((scene, dict(base, **over), "mu " + _text(over)))
        for over in spec.methods:
            points.append((scene, dict(base, **over), "method " + _text(over)))
            if spec.dt and not any(k in over for k in ("courant", "c_N", "c_N_factor")):
                points.append(
                    (
                        scene,
                        dict(_with_step(spec, scene, spec.base, 10.0), **over),
                        "method " + _text(over) + ", dt x 10",
                    )
                )
    return points


def _text(over):
    return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in over.items())


def reference_overrides(scene, over, keep=None):
    """The overrides of the refined reference of a run (module docstring); `keep`: what it shares
    with the run whatever the rules (the smallest step's shortened problem)."""
    spec = SCENES[scene]
    ref = {k: v for k, v in over.items() if k not in NUMERICAL or k in spec.physical}
    ref.update(spec.base)
    ref.update(keep or {})
    ref.update(spec.reference)
    if scene == "cork":  # the pop's fine step and travel refined
        ref.update(dt_fine=_default(scene, "dt_fine") * REFINE, travel_max=_default(scene, "travel_max") * REFINE)
    elif spec.dt:
        step = _default(scene, spec.dt) * REFINE  # a run finer than that is checked against it
        ref[spec.dt] = step
        if spec.steps:  # the run's end time, in the reference's steps
            end = (
                float(over.get(spec.dt, _default(scene, spec.dt))) * over["n_steps"]
                if "n_steps" in over
                else spec.steps
            )
            ref["n_steps"] = max(1, round(end / step))
    if over.get("enforcement", "penalty") == "penalty":
        c0 = _default(scene, spec.c_N)
        ref[spec.c_N] = max(float(over.get(spec.c_N, c0)), c0)
    for k in {"n_el", "nx", "ny", "nx_lower", "nx_upper", "n_r", "n_z"} - set(spec.physical) - set(keep or {}):
        if k in over or k in spec.ref_mesh:
            ref[k] = max(over.get(k, 0), spec.ref_mesh.get(k, 0), _default(scene, k))
    return ref


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


def attempt(scene, over, seconds=TIME_LIMIT):
    """One run: dict(outcome=ran|refused|stopped|crashed|late, result, warnings, error, time_s)."""
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = _limited(lambda: run_scene(scene, "fast", over), seconds)
        except _Late:
            return dict(outcome="late", error=f"past {seconds:g} s", time_s=time.perf_counter() - t0)
        except (ValueError, RuntimeError, ArithmeticError) as err:
            text = str(err)
            one = bool(text) and "\n" not in text.strip()
            kind = ("refused" if isinstance(err, ValueError) else "stopped") if one else "crashed"
            return dict(outcome=kind, error=f"{type(err).__name__}: {text}"[:300], time_s=time.perf_counter() - t0)
        except Exception as err:  # noqa: BLE001 (anything else is a crash, counted)
            return dict(outcome="crashed", error=f"{type(err).__name__}: {err}"[:300], time_s=time.perf_counter() - t0)
    flags = sorted(
        {
            str(w.message).split(" = ")[0].removeprefix("accuracy: ")
            for w in caught
            if issubclass(w.category, AccuracyWarning)
        }
    )
    failing = sorted(k for k, v in (r.get("accuracy") or {}).items() if isinstance(v, dict) and not v.get("ok", True))
    return dict(outcome="ran", result=r, flags=sorted(set(flags) | set(failing)), time_s=time.perf_counter() - t0)


def headline_errors(scene, r, ref):
    """headline -> |error| against the reference (relative, or over the scene's scale)."""
    spec = SCENES[scene]
    if scene == "patch":
        return {"pressure": abs(r["pressure_deviation_max"])}
    out = {}
    for key in spec.headlines:
        got = r.get(key)
        want = r.get(spec.exact[key]) if spec.exact else (ref or {}).get(key)
        if got is None or want is None:
            out[key] = 0.0 if got is None and want is None else float("inf")
            continue
        scale = max(abs(float(want)), spec.scale.get(key, 0.0))
        out[key] = abs(float(got) - float(want)) / scale if scale > 0 else abs(float(got) - float(want))
    return out


def needs_reference(scene):
    return scene not in ("hertz", "patch")


def classify(scene, run, ref):
    """The run's outcome (module docstring) and its headline errors."""
    if run["outcome"] != "ran":
        return run["outcome"], {}
    if needs_reference(scene) and (ref is None or ref["outcome"] != "ran"):
        return "no reference", {}
    errors = headline_errors(scene, run["result"], ref["result"] if ref else None)
    off = max(errors.values(), default=0.0) > TOL
    if run["flags"]:
        return ("flagged (off)" if off else "flagged (within)"), errors
    return ("wrong" if off else "within"), errors


OUTCOMES = (
    "within",
    "flagged (off)",
    "flagged (within)",
    "refused",
    "stopped",
    "wrong",
    "crashed",
    "late",
    "no reference",
)


def extremes_study(quick=False, progress=None, seconds=TIME_LIMIT):
    """Run the grid (``quick``: the test suite's slice); rows and counts."""
    refs, rows = {}, []
    for scene, over, axis, keep in grid(quick):
        run = attempt(scene, over, seconds)
        ref = None
        if needs_reference(scene) and run["outcome"] == "ran":
            key = (scene, tuple(sorted(reference_overrides(scene, over, keep).items())))
            if key not in refs:
                refs[key] = attempt(scene, dict(key[1]), seconds)
            ref = refs[key]
        outcome, errors = classify(scene, run, ref)
        row = dict(
            scene=scene,
            axis=axis,
            overrides=over,
            outcome=outcome,
            errors=errors,
            flags=run.get("flags", []),
            error=run.get("error", ""),
            time_s=run["time_s"],
        )
        if ref is not None:
            row["reference"] = dict(
                overrides=dict(key[1]), outcome=ref["outcome"], error=ref.get("error", ""), flags=ref.get("flags", [])
            )
        rows.append(row)
        if progress:
            progress(f"extremes: {scene} {axis}: {outcome} {_errors_text(errors)} {row['error'][:80]}")
    counts = {k: sum(r["outcome"] == k for r in rows) for k in OUTCOMES}
    return dict(
        tol=TOL,
        refine=REFINE,
        quick=bool(quick),
        runs=len(rows),
        reference_runs=len(refs),
        counts=counts,
        rows=rows,
        time_s=sum(r["time_s"] for r in rows) + sum(r["time_s"] for r in refs.values()),
    )


def _errors_text(errors):
    return ", ".join(f"{k} {100 * v:.2g} %" for k, v in errors.items())


# the test suite's slice: a run of each outcome the grid meets, cheap ones (a few seconds each)
QUICK = [
    ("block", {"c_N": 10.0}, "c_N x 1e-4"),
    ("block", {"c_N": 1e23}, "c_N x 1e18"),
    ("block", {"nx": 3, "ny": 1}, "mesh nx=3, ny=1"),
    ("block", {"nx": 3, "ny": 1, "free_end_nodes": 1}, "mesh nx=3, ny=1, free_end_nodes=1"),
    ("sloping_impact", {"n_el": 3, "n_steps": 40}, "mesh n_el=3"),
    ("hertz", {"c_N": 1e27}, "c_N x 1e18"),
    ("hertz", {"n_el": 4}, "mesh n_el=4"),
    ("patch", {"nx_lower": 11, "nx_upper": 5}, "mesh nx_lower=11, nx_upper=5"),
    ("patch", {"enforcement": "augmented", "contact_discretization": "mortar"}, "method augmented, mortar"),
    ("sloping_impact", {"dt": 1.0, "n_steps": 4}, "dt x 10"),
    ("sloping_impact", {"c_N": 5e5, "n_steps": 40}, "c_N x 1e4"),
    ("bar_impact", {"c_N_factor": 1e-4}, "c_N x 1e-4"),
    ("bar_impact", {"courant": 10.0}, "dt x 10"),
    ("rolling_ring", {"mu": 1e-9, "t_end": 1.5}, "mu 1e-9"),
    ("rolling_ring", {"dt": 0.2, "t_end": 1.5}, "dt x 10"),
    ("bar_impact", {"courant": 10.0, "contact_integration": "energy_consistent"}, "method energy_consistent, dt x 10"),
    ("hertz", {"enforcement": "lagrange", "contact_discretization": "mortar"}, "method lagrange, mortar"),
    ("funnel", {"c_N": 1e19, "n_steps": 80}, "c_N x 1e18"),
]


# what the grid found wrong and unflagged, and what was added (measured when each was found, not by this run)
FINDINGS = [
    (
        "bar_impact, c_N x 1e-4",
        "duration 44 %, rebound 200 % off: the run ends in contact and reads its rebound mid-impact",
        "`separated` (an impact scene in contact at its end)",
    ),
    (
        "block, nx = 3, ny = 1",
        "largest displacement 26 % off 16 elements through the height",
        "`mesh_height` (at least 4; measured at nx = 3, 10, 25)",
    ),
    (
        "sloping_impact, n_el = 3",
        "rebound v_y 31 % off the 16-element ring's",
        "`facets` (the angle one element of a ring spans, at most 0.8 rad: 8 elements)",
    ),
    (
        "rolling_ring, c_N x 1e4",
        "x_end 5.9 % off (its closed-form indicator allowed 10 %)",
        "`x_end` against the closed form to 5 % (2.1 % at the preset)",
    ),
    (
        "bar_impact, energy-consistent, courant x 10",
        "rebound 11 % off, its energy exact",
        "`penalty_steps` for the midpoint rule too (its period error is Newmark's)",
    ),
    (
        "funnel, c_N x 1e18",
        "never ended: the parts of a halved step were halved again without end (1e-11 of the step)",
        "a fixed step is halved at most max_cuts times in all: the run stops in one line",
    ),
    (
        "cork, c_N x 1e-4",
        "exit velocity 22 %, exit time 21 % off, no penetration indicator (the cork had no lengths)",
        "the cork's lengths: `penetration` as every scene's",
    ),
]


def extremes_markdown(res):
    """The BENCHMARKS.md section of the study."""
    c = res["counts"]
    judged = res["runs"]
    L = [
        "## Extremes: every run within its reference, flagged, refused or stopped",
        "",
        f"{judged} runs over the numerical ranges of every scene ({res['reference_runs']} refined reference runs "
        f"besides; {res['time_s']:.0f} s in all). A run is *within* when no accuracy indicator is past its "
        f"threshold and every headline quantity is within {100 * res['tol']:g} % of its reference (the closed "
        "form where the scene has one, else the same problem with the step "
        f"{res['refine']:g} times the scene's, the penalty no softer than the scene's, the finer mesh and the "
        "default methods); *flagged* when an indicator is past its threshold (off: a headline more than "
        f"{100 * res['tol']:g} % off as well); *wrong* when neither. The grid and each choice: "
        "contactfem/lab/bench/extremes.py.",
        "",
        "| outcome | runs |",
        "|---|---|",
    ]
    L += [f"| {k} | {c.get(k, 0)} |" for k in OUTCOMES]
    L += [
        "",
        "Each scene's part of the grid (contactfem/lab/bench/extremes.py, SCENES: every run at the fast "
        "preset; the penalty and the step crossed on the dynamic scenes, each other axis alone):",
        "",
        "| scene | headline quantities | reference | coarsest and fine meshes | smallest step |",
        "|---|---|---|---|---|",
    ]
    for scene, spec in SCENES.items():
        ref = (
            "closed form"
            if not needs_reference(scene)
            else "refined run" + (f" ({_text(spec.reference)})" if spec.reference else "")
        )
        tiny = "-" if not spec.dt else f"{spec.tiny[0]:g} x" + (f" ({_text(spec.tiny[1])})" if spec.tiny[1] else "")
        meshes = "; ".join(_text(m) for m in spec.mesh)
        L.append(f"| {scene} | {', '.join(spec.headlines)} | {ref} | {meshes} | {tiny} |")
    L += [
        "",
        "What the grid found wrong and unflagged, and what was added (measured when each was found, not by this run):",
        "",
        "| run | what was wrong | added |",
        "|---|---|---|",
    ]
    L += [f"| {a} | {b} | {c} |" for a, b, c in FINDINGS]
    L += [
        "",
        "| scene | setting | outcome | headline errors | indicators past their thresholds / the error |",
        "|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        what = ", ".join(r["flags"]) if r["flags"] else r["error"][:120].replace("|", "/")
        errors = _errors_text(r["errors"]) or "-"
        L.append(f"| {r['scene']} | {r['axis']} | {r['outcome']} | {errors} | {what or '-'} |")
    return L + [""]
