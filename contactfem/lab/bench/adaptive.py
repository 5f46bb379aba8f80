"""Study 10, a tolerance against fixed steps: for each dynamic scene, the cost of a run (Newton
iterations, residual evaluations, wall time) against the error it achieves in its headline
quantities, for two ladders of fixed steps (the scene's preset integrator, and the trapezoidal
rule a run at a tolerance integrates with) and for the adaptive mode (``accuracy``) at several
tolerances.

The reference of a scene is its run refined in time: fixed steps h_ref with the integrator the
study names (``reference_with``: the trapezoidal rule, or the preset's), Richardson's
extrapolation 2 q(h_ref) - q(2 h_ref) where that run is first order in dt (the paper's damped
Newmark, delta = 0.7; the cork's gas, coupled explicitly, whatever the integrator), q(h_ref)
where it is second order (the trapezoidal rule). Its own uncertainty (``reference_change``): the
change of the headline quantities from q(2 h_ref) (second order), or from the extrapolation one
step coarser (first order). The error of a run is the largest relative error of its headline
quantities against the reference. Cost: residual evaluations count every Newton iteration, those
of rejected and halved steps too (``newton_iterations`` counts the accepted steps' only).

``quick``: the bar impact alone (seconds); the full study: the four scenes (tens of minutes:
the cork's reference and the rolling ring's runs at a tolerance take the longest).

A fixed step matches an error only if it and every finer step of its ladder are within it
(``matching_fixed``; an error below the reference's own change is matched at that change); each run at a tolerance
also gets the largest fixed step that stays within
the tolerance itself (``tolerance_match``): a run that lands far inside its tolerance has paid for
accuracy it did not ask for, and the study says how much."""

import warnings

from ...problem import time_integration
from ...scenes import run_scene
from .common import timed

# the trapezoidal rule as a scene's parameters (the integrator of a run at a tolerance)
TRAPEZOIDAL = {"delta": time_integration.TRAPEZOIDAL["delta"], "beta_newmark": time_integration.TRAPEZOIDAL["beta"]}

# scene -> preset, the step of the fixed ladders as overrides, the preset's ladder, the trapezoidal
# rule's ladder (None: the preset is the trapezoidal rule), the reference (its integrator, step and
# order), the headline quantities, the adaptive mode's overrides
STUDY = {
    "bar_impact": dict(
        preset="fast",
        fixed=lambda h: {"courant": h},
        ladder=(2.0, 1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125),
        step="courant",
        trapezoidal=None,
        reference_with="preset",
        h_ref=0.0078125,
        order=2,
        keys=("duration", "rebound_velocity"),
        adaptive={},
    ),
    # the rebound is over by t = 3 (the ring leaves at ~2.5): 3 time units, not the paper's 20
    "sloping_impact": dict(
        preset="fast",
        fixed=lambda h: {"dt": h, "n_steps": int(round(3.0 / h))},
        ladder=(0.1, 0.05, 0.025, 0.0125, 0.00625, 0.003125, 0.0015625, 0.00078125, 0.00015625, 0.000078125),
        step="dt",
        trapezoidal=(0.025, 0.0125, 0.00625, 0.003125, 0.0015625, 0.00078125, 0.000390625),
        reference_with="trapezoidal",
        h_ref=0.000390625 / 2,
        order=2,
        keys=("rebound_vx", "rebound_vy"),
        adaptive={"n_steps": 30},
    ),
    # the paper's ring of 120 elements: the fast preset's 40-gon has no converged v_final (its rolling
    # speed is set by the energy each of its coarse touch-downs trades with the ring's vibrations:
    # fixed trapezoidal steps from 5e-3 to 7.8e-5 s scatter by 1.5 %, 146.3 to 148.5 cm/s); the 120-gon's
    # settles (the trapezoidal rule at 7.8e-5 and 3.9e-5 s: 149.874 and 149.905 cm/s, x_roll 229.5252
    # and 229.5259 cm)
    "rolling_ring": dict(
        preset="paper",
        fixed=lambda h: {"dt": h},
        ladder=(0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625, 0.000078125),
        step="dt",
        trapezoidal=(0.01, 0.005, 0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625),
        reference_with="trapezoidal",
        h_ref=0.0000390625,
        order=2,
        keys=("v_final", "x_roll"),
        adaptive={},
    ),
    # the cork's own schedule with dt_fine = h everywhere: from the start (exit_zone 1e3 mm: the whole
    # neck is "near the exit") and after the exit (a travel limit of 1e-9 mm). dt (1e-4 s) stays: it
    # sets the gas's ramp in time (a staircase the steps resolve, as a run at a tolerance does). A
    # ladder that refined dt_fine alone would keep steps of 1e-4 s over the ramp and converge to
    # another limit (its fixed steps turn the staircase into a linear ramp). The gas is coupled
    # explicitly (a step acts with the pressure of the state before it): first order in dt whatever
    # the integrator. Its trapezoidal values settle only below 1e-6 s (exit velocity at 1.25e-6,
    # 6.25e-7, 3.125e-7 and 1.5625e-7 s: 28.0185, 27.9982, 27.9949, 27.9924 m/s; a reference from
    # 6.25e-7 s moves by 1.1e-3 and cannot judge 1e-3)
    "cork": dict(
        preset="fast",
        fixed=lambda h: {"dt_fine": h, "exit_zone": 1e3, "travel_max": 1e-9},
        ladder=(8e-5, 4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6),
        step="dt_fine",
        trapezoidal=(4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6),
        reference_with="trapezoidal",
        h_ref=1.5625e-7,
        order=1,
        keys=("exit_velocity_m_s", "exit_time_ms"),
        adaptive={},
    ),
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
        warnings.simplefilter("ignore")  # a coarse run's indicators warn: its error is measured here
        try:
            r, wall = timed(run_scene, scene, preset, over, error_bars=False)
        except Exception as err:  # recorded, not hidden: a failed point is a result
            return dict(over, ok=False, failure=f"{type(err).__name__}: {str(err).splitlines()[0][:160]}")
    st = r["stepping"]
    budget = r["accuracy"].get("error_budget")  # a run at a tolerance: its own estimate
    return dict(
        over,
        ok=True,
        values={k: r.get(k) for k in keys},
        error_budget=None if budget is None else budget["value"],
        newton_iterations=int(r["newton_iterations_total"]),
        residual_evaluations=int(r["residual_evaluations"]),
        wall_time_s=wall,
        steps=st["steps"],
        dt_min=st["dt_min"],
        dt_max=st["dt_max"],
        mode=st["mode"],
    )


def _over(scene, h, trapezoidal=False):
    s = STUDY[scene]
    return dict(s["fixed"](h), **(TRAPEZOIDAL if trapezoidal else {}))


def scene_run(scene, h, trapezoidal=False):
    """The scene's run with the fixed step h (a point of the study), with its preset's integrator or
    the trapezoidal rule."""
    s = STUDY[scene]
    return _run(scene, s["preset"], _over(scene, h, trapezoidal), s["keys"])


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
    trap = s["reference_with"] == "trapezoidal"
    runs = [scene_run(scene, h, trap) for h in (h_ref, 2 * h_ref) + ((4 * h_ref,) if s["order"] == 1 else ())]
    if not all(r["ok"] for r in runs):
        return dict(ok=False, runs=runs, h_ref=h_ref)
    q = [r["values"] for r in runs]
    if s["order"] == 1:
        ref = {k: 2 * q[0][k] - q[1][k] for k in keys}
        coarser = {k: 2 * q[1][k] - q[2][k] for k in keys}
    else:
        ref, coarser = q[0], q[1]
    change = max(abs(coarser[k] / ref[k] - 1.0) for k in keys)
    return dict(ok=True, values=ref, h_ref=h_ref, change=change, runs=runs, integrator=s["reference_with"])


def scene_study(scene, tolerances=TOLERANCES, ladder=None, h_ref=None):
    """One scene's points: the fixed ladders (with the reference's own runs in the ladder of its
    integrator), the adaptive runs, the reference (module docstring)."""
    s = STUDY[scene]
    keys = s["keys"]
    r = reference(scene, h_ref)
    if not r["ok"]:
        return dict(reference=r, fixed=[], fixed_trapezoidal=[], adaptive=[])
    ref = r["values"]
    own = (1, 2, 4) if s["order"] == 1 else (2,)  # (a second-order reference is its own run: error 0)
    own = {m * r["h_ref"] for m in own}
    trap = s["reference_with"] == "trapezoidal"

    def ladder_points(steps, trapezoidal):
        steps = sorted(set(steps) | (own if trapezoidal == trap else set()), reverse=True)
        return [dict(_errors(scene_run(scene, h, trapezoidal), ref, keys), h=h) for h in steps]

    fixed = ladder_points(ladder or s["ladder"], False)
    fixed_trapezoidal = ladder_points(s["trapezoidal"], True) if s["trapezoidal"] else []
    adaptive = [dict(_errors(adaptive_run(scene, tol), ref, keys), accuracy=tol) for tol in tolerances]
    adaptive = [dict(a, **matches(a, fixed, fixed_trapezoidal, r["change"])) for a in adaptive]
    return dict(
        step=s["step"],
        keys=list(keys),
        preset=s["preset"],
        h_reference=r["h_ref"],
        reference=ref,
        reference_with=s["reference_with"],
        reference_change=r["change"],
        reference_runs=r["runs"],
        order=s["order"],
        fixed=fixed,
        fixed_trapezoidal=fixed_trapezoidal,
        adaptive=adaptive,
    )


def matching_fixed(fixed, error):
    """The largest fixed step of the ladder that reaches ``error`` and stays there: its error and
    that of every finer step of the ladder at most ``error`` (and its cost), or None. (A user who
    picks a fixed step refines until the result settles: a coarse step whose error happens to dip
    below, with finer steps above it, is not one a user could have chosen; the rolling ring's
    fixed errors rise and fall by up to 6e-4 as the step halves.) A failed point (error None) ends
    the search like an error above: no step coarser than it matches."""
    if error is None:
        return None
    match = None
    for f in sorted(fixed, key=lambda f: f["h"]):  # finest first
        if f.get("error") is None or not f["error"] <= error:  # (None or NaN: not within)
            break
        match = f
    if match is None:
        return None
    return dict(
        h=match["h"],
        error=match["error"],
        residual_evaluations=match["residual_evaluations"],
        newton_iterations=match["newton_iterations"],
        wall_time_s=match["wall_time_s"],
    )


def matches(a, fixed, fixed_trapezoidal, reference_change):
    """The matches of a run at a tolerance ``a`` in the two ladders: ``fixed_match`` and
    ``trapezoidal_match`` at its error, or at the reference's own change where its error is below
    it (below that, an error cannot be told from the reference's: the finest step of a ladder
    is the reference's own neighbour); and ``tolerance_match``, the cheaper ladder's largest step
    that stays within the tolerance itself (what a run at that tolerance could have cost; None
    where the reference moves by more than half the tolerance)."""
    error = None if a.get("error") is None else max(a["error"], reference_change)
    at_tol = (
        []
        if reference_change > a["accuracy"] / 2
        else [
            dict(m, integrator=label)
            for label, m in (
                ("preset", matching_fixed(fixed, a["accuracy"])),
                ("trapezoidal", matching_fixed(fixed_trapezoidal, a["accuracy"])),
            )
            if m
        ]
    )
    return dict(
        fixed_match=matching_fixed(fixed, error),
        trapezoidal_match=matching_fixed(fixed_trapezoidal, error),
        tolerance_match=min(at_tol, key=lambda m: m["residual_evaluations"]) if at_tol else None,
    )


def adaptive_study(quick=False):
    """Study 10 (module docstring)."""
    if quick:
        return dict(scenes={"bar_impact": scene_study("bar_impact", (1e-2, 1e-3), (1.0, 0.5, 0.25, 0.125), 0.0625)})
    return dict(scenes={name: scene_study(name) for name in STUDY})
