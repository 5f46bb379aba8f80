"""Study 10, a tolerance against fixed steps: for each dynamic scene, the cost of a run (Newton
iterations, residual evaluations, wall time) against the error it achieves in its headline
quantities, for a ladder of fixed steps and for the adaptive mode (``accuracy``) at several
tolerances.

The reference of a scene is its run refined in time: fixed steps h_ref (below the ladder's
finest); where the scene's stepper is first order (Newmark delta = 0.7: the sloping impact,
the rolling ring, the cork) Richardson's extrapolation 2 q(h_ref) - q(2 h_ref), where it is
second order (the bar's trapezoidal rule) q(h_ref). Its own uncertainty
(``reference_change``): the change of the headline quantities from q(2 h_ref) (second
order), or from the extrapolation one step coarser (first order). The error of a run is the
largest relative error of its headline quantities against the reference. Cost: residual
evaluations count every Newton iteration, those of rejected and halved steps too
(``newton_iterations`` counts the accepted steps' only).

``quick``: the bar impact alone (seconds); the full study: the four scenes (tens of minutes:
the references of the ring scenes take the longest)."""

import warnings

from ...scenes import run_scene
from .common import timed

# scene -> preset, the step of the fixed ladder as overrides, the ladder, the reference step and
# the stepper's order in it, the headline quantities, the adaptive mode's overrides
STUDY = {
    "bar_impact": dict(
        preset="fast", fixed=lambda h: {"courant": h}, ladder=(2.0, 1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125), step="courant",
        h_ref=0.015625, order=2, keys=("duration", "rebound_velocity"), adaptive={}),
    # the rebound is over by t = 3 (the ring leaves at ~2.5): 3 time units, not the paper's 20
    "sloping_impact": dict(
        preset="fast", fixed=lambda h: {"dt": h, "n_steps": int(round(3.0 / h))},
        ladder=(0.1, 0.05, 0.025, 0.0125, 0.00625, 0.003125, 0.0015625, 0.00078125), step="dt", h_ref=0.0000390625,
        order=1, keys=("rebound_vx", "rebound_vy"), adaptive={"n_steps": 30}),
    "rolling_ring": dict(
        preset="fast", fixed=lambda h: {"dt": h}, ladder=(0.02, 0.01, 0.005, 0.0025, 0.00125, 0.000625), step="dt",
        h_ref=0.0003125 / 2, order=1, keys=("v_final", "x_roll"), adaptive={}),
    # the cork's own schedule with dt_fine = h everywhere (a travel limit of 1e-9 mm holds every step
    # to dt_fine once the cork moves); dt (1e-4 s) stays: it sets the gas's ramp in time
    "cork": dict(
        preset="fast", fixed=lambda h: {"dt_fine": h, "travel_max": 1e-9}, ladder=(8e-5, 4e-5, 2e-5, 1e-5),
        step="dt_fine", h_ref=2.5e-6, order=1, keys=("exit_velocity_m_s", "exit_time_ms"), adaptive={}),
}
TOLERANCES = (1e-2, 1e-3)


_POINTS = {}


def _run(scene, preset, over, keys):
    """A point (a point already run in this process is reused: the reference's runs are the ladder's)."""
    key = (scene, preset, tuple(sorted(over.items())), tuple(keys))
    if key not in _POINTS:
        _POINTS[key] = _point(scene, preset, over, keys)
    return dict(_POINTS[key])


def _point(scene, preset, over, keys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")            # a coarse run's indicators warn: its error is measured here
        try:
            r, wall = timed(run_scene, scene, preset, over)
        except Exception as err:                   # recorded, not hidden: a failed point is a result
            return dict(over, ok=False, failure=f"{type(err).__name__}: {str(err).splitlines()[0][:160]}")
    st = r["stepping"]
    return dict(over, ok=True, values={k: r.get(k) for k in keys}, newton_iterations=int(r["newton_iterations_total"]),
                residual_evaluations=int(r["residual_evaluations"]), wall_time_s=wall, steps=st["steps"],
                dt_min=st["dt_min"], dt_max=st["dt_max"], mode=st["mode"])


def scene_run(scene, h):
    """The scene's run with the fixed step h of its ladder (a point of the study)."""
    s = STUDY[scene]
    return _run(scene, s["preset"], s["fixed"](h), s["keys"])


def adaptive_run(scene, tol):
    """The scene's run at the tolerance tol (a point of the study)."""
    s = STUDY[scene]
    return _run(scene, s["preset"], dict(s["adaptive"], accuracy=tol), s["keys"])


def max_error(point, ref):
    """The largest relative error of a point's headline quantities against the reference values."""
    return max(abs(point["values"][k] / ref[k] - 1.0) for k in ref)


def _errors(point, ref, keys):
    if not point["ok"] or any(point["values"][k] is None for k in keys):
        return dict(point, error=None, errors=None)
    errors = {k: abs(point["values"][k] / ref[k] - 1.0) for k in keys}
    return dict(point, errors=errors, error=max(errors.values()))


def reference(scene, h_ref=None):
    """The scene's reference values (module docstring), h_ref, its own change, and the runs."""
    s = STUDY[scene]
    h_ref = h_ref or s["h_ref"]
    keys = s["keys"]
    runs = [_run(scene, s["preset"], s["fixed"](h), keys) for h in (h_ref, 2 * h_ref) +
            ((4 * h_ref,) if s["order"] == 1 else ())]
    if not all(r["ok"] for r in runs):
        return dict(ok=False, runs=runs, h_ref=h_ref)
    q = [r["values"] for r in runs]
    if s["order"] == 1:
        ref = {k: 2 * q[0][k] - q[1][k] for k in keys}
        coarser = {k: 2 * q[1][k] - q[2][k] for k in keys}
    else:
        ref, coarser = q[0], q[1]
    change = max(abs(coarser[k] / ref[k] - 1.0) for k in keys)
    return dict(ok=True, values=ref, h_ref=h_ref, change=change, runs=runs)


def scene_study(scene, tolerances=TOLERANCES, ladder=None, h_ref=None):
    """One scene's points: the fixed ladder (with the reference's own runs), the adaptive runs, the
    reference (module docstring)."""
    s = STUDY[scene]
    ladder = tuple(ladder or s["ladder"])
    keys = s["keys"]
    r = reference(scene, h_ref)
    if not r["ok"]:
        return dict(reference=r, fixed=[], adaptive=[])
    ref = r["values"]
    own = (1, 2, 4) if s["order"] == 1 else (2,)       # (a second-order reference is its own run: error 0)
    steps = sorted(set(ladder) | {m * r["h_ref"] for m in own}, reverse=True)
    fixed = [dict(_errors(_run(scene, s["preset"], s["fixed"](h), keys), ref, keys), h=h) for h in steps]  # ladder + reference runs
    adaptive = [dict(_errors(_run(scene, s["preset"], dict(s["adaptive"], accuracy=tol), keys), ref, keys),
                     accuracy=tol) for tol in tolerances]
    for a in adaptive:
        a["fixed_match"] = matching_fixed(fixed, a["error"])
    return dict(step=s["step"], keys=list(keys), preset=s["preset"], h_reference=r["h_ref"], reference=ref,
                reference_change=r["change"], reference_runs=r["runs"], order=s["order"], fixed=fixed,
                adaptive=adaptive)


def matching_fixed(fixed, error):
    """The largest fixed step of the ladder whose error is at most ``error`` (and its cost), or None."""
    ok = [f for f in fixed if f.get("error") is not None and error is not None and f["error"] <= error]
    if not ok:
        return None
    f = max(ok, key=lambda f: f["h"])
    return dict(h=f["h"], error=f["error"], residual_evaluations=f["residual_evaluations"],
                newton_iterations=f["newton_iterations"], wall_time_s=f["wall_time_s"])


def adaptive_study(quick=False):
    """Study 10 (module docstring)."""
    if quick:
        return dict(scenes={"bar_impact": scene_study("bar_impact", (1e-2, 1e-3), (1.0, 0.5, 0.25, 0.125), 0.0625)})
    return dict(scenes={name: scene_study(name) for name in STUDY})
