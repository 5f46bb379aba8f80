"""How accurate a run is: the indicators every result carries in its ``accuracy`` section.

Each indicator is a dict: ``value``, ``threshold``, ``source`` (where the threshold comes
from), ``what`` (what the value measures) and ``ok`` (value within the threshold). A run
warns once per indicator past its threshold, with ``AccuracyWarning`` (one class, which a
notebook can filter: ``warnings.simplefilter("ignore", contactfem.AccuracyWarning)``); the
command line prints those warnings and ``--strict`` makes them exit code 1.

The indicators that apply to a run (``collect``), from its records and the model's sizes:

    equilibrium     the largest converged residual over the step's force scale (solver/newton.py: plus
                    atol / 1e-6, so that a residual within Newton's absolute floor atol is within 1e-6)
    penetration     the largest penetration over the local element size, and over the body's size
    facets          a ring's elements against its radius: the angle one element spans (few: no ring)
    energy_gain     the energy balance's error: a gain (the integrator adds energy), friction's dissipation
                    and the loads' work counted as the balance counts them (time_integration.energy_error);
                    a loss is what the damping of Newmark's delta > 1/2 takes, and what it does to the
                    headline quantities is the time step's part of their error bands (problem/uncertainty.py)
    impact_steps    the steps that resolve the longest contact episode (from touch-down to lift-off)
    penalty_steps   dt against the penalty's period, dt sqrt(k / m) at the stiffest touching node, in
                    every dynamic step in contact (an impact, a resting or a rolling contact)
    separated       an impact scene (the model's ``rebound``): the body has left the obstacle by the run's
                    end, so the rebound it reports is a rebound (0), not a velocity read mid-impact (1)
    missed          an impact scene: the body never touched the obstacle (1), so the rebound it reports is
                    the velocity it started with (a step refined without more steps ends the run earlier)
    error_budget    a run at a tolerance (``accuracy``): its own estimate of its time-stepping error over
                    the error the tolerance allows (the sum of its steps' local error estimates over the sum
                    of their shares, solver/schedule.py); past 2 the tolerance is not assured

and, from the scene's headline quantities (problem/uncertainty.py): the error against each closed form a
quantity declares (``references``, NAME: held to the run's tolerance), and with error bars each quantity's
relative band against the same tolerance (NAME_band; no value where no band could be estimated).
"""

import math
import os
import sys
import warnings

import numpy as np

from .time_integration import integrator_of


class AccuracyWarning(UserWarning):
    """A run's accuracy indicator is past its threshold (contactfem.problem.accuracy)."""


def indicator(value, threshold, what, source, upper=True):
    """One indicator: ok when value <= threshold (``upper``) or value >= threshold."""
    value, threshold = float(value), float(threshold)
    ok = value <= threshold if upper else value >= threshold
    return dict(
        value=value,
        threshold=threshold,
        ok=bool(ok),
        what=what,
        source=source,
        bound="at most" if upper else "at least",
    )


EQUILIBRIUM = 1e-6  # solver.newton.ROUNDOFF_RTOL: what Newton accepts when round-off stops it
PENETRATION_ELEMENT = 0.1  # ANSYS's default penetration tolerance (FTOLN): 0.1 of the underlying element
PENETRATION_BODY = 0.01  # 1 % of the body's size: the contact changes the body's geometry visibly
ENERGY_GAIN = 0.01  # a gain of 1 % is no Newton tolerance's share (1e-6 at most)
# The run's tolerance (--tolerance; a relative error): the band a headline quantity may have before the run
# warns (problem/uncertainty.py), and what the time resolution (_time_resolution) is held to: an impact
# resolved to it errs by it.
TOLERANCE = 0.05
FACETS_SOURCE = (
    "geometry: a ring of straight elements each spanning theta lies inside its circle by the sagitta "
    "1 - cos(theta / 2) of its radius at an element's middle; the largest theta whose sagitta is within the run's "
    "tolerance"
)
ERROR_BUDGET = 2.0  # a step is kept with up to twice its share of the error (solver/schedule.py)
REFERENCE_SOURCE = (
    "the run's tolerance (--tolerance TOL, tolerance= in Python; 5 % by default): the closed form is the "
    "quantity's true value, so its error is held to the tolerance its band is"
)


def facets_threshold(tolerance):
    """The largest angle one element of a ring may span (FACETS_SOURCE): 2 acos(1 - tolerance)."""
    return float(2.0 * np.arccos(1.0 - min(tolerance, 1.0)))


def references(quantities, params, results, tolerance):
    """The indicators of the closed forms a scene's quantities declare (Quantity.exact: a result's name or
    a number): |value - closed form| / the closed form (or the quantity's scale where that is larger: a
    quantity near zero), against the tolerance. A quantity without a value or a closed form in this run (a
    law without one) has none."""
    out = {}
    for q in quantities:
        exact = results.get(q.exact) if isinstance(q.exact, str) else q.exact
        value = results.get(q.name)
        if exact is None or value is None or isinstance(value, bool):
            continue
        ref = q.reference(params, exact)
        what = f"|{q.name} - its closed form| / " + ("the closed form" if ref == abs(exact) else f"{ref:g}")
        out[q.name] = indicator(abs(value - exact) / ref, tolerance, what, REFERENCE_SOURCE)
    return out


def hertz_half_width(x, f):
    """Hertz's half-width from the moments of the nodal contact forces f at the reference x >= 0:
    for p = p0 sqrt(1 - x^2/a^2), int p x^2 dx / int p dx = a^2 / 4 over [0, a], so a = 2 sqrt(sum f x^2 /
    sum f). The forces carry the load as the discretisation transfers it (node-to-segment's nodal
    forces, mortar's w t_N), so no profile is fitted through the edge of the zone."""
    f = np.maximum(np.asarray(f, float), 0.0)
    return float(2.0 * np.sqrt(np.sum(f * np.asarray(x) ** 2) / np.sum(f)))


def collect(model, params, records, results, tolerance=TOLERANCE):
    """The generic indicators of a run (module docstring), as a dict name -> indicator; ``tolerance``:
    the relative error the run's error bars are held to (the time resolution's and the facets' thresholds
    follow it)."""
    out = {}
    steps = [r for r in records if r.result is not None]
    ratios = [r.result.residual_ratio for r in steps]  # every stepper's result has it (newton, uzawa, staggered)
    if ratios:
        out["equilibrium"] = indicator(
            max(ratios),
            EQUILIBRIUM,
            "largest converged residual / the step's force scale (plus atol / 1e-6: a residual within Newton's "
            "absolute floor atol is within the threshold)",
            "Newton's round-off tolerance (solver.newton.ROUNDOFF_RTOL); its own is 1e-8",
        )
    sizes = model.sizes
    deepest = _deepest(records[1:] or records)  # (a scene's initial guess may overlap on purpose: hertz)
    if deepest is not None and sizes.get("element"):
        out["penetration"] = indicator(
            deepest / sizes["element"],
            PENETRATION_ELEMENT,
            f"largest penetration / local element size ({sizes['element']:.3g})",
            "ANSYS's default penetration tolerance: 0.1 of the underlying element",
        )
    if deepest is not None and sizes.get("body"):
        out["penetration_body"] = indicator(
            deepest / sizes["body"],
            PENETRATION_BODY,
            f"largest penetration / the body's size ({sizes['body']:.3g})",
            "chosen: 1 % of the body changes its geometry visibly",
        )
    if sizes.get("radius") and sizes.get("element"):
        out["facets"] = indicator(
            sizes["element"] / sizes["radius"],
            facets_threshold(tolerance),
            "the angle one element of the ring spans [rad] (its length over the radius)",
            FACETS_SOURCE,
        )
    err = results.get("energy_error")
    if isinstance(err, float):
        out["energy_gain"] = indicator(
            max(err, 0.0),
            ENERGY_GAIN,
            "energy gained over the run / initial energy (dissipation and the loads' work counted)",
            "a gain above 1 % is the integrator's, not Newton's (1e-6 at most)",
        )
    if model.rebound and steps:
        out["separated"] = indicator(
            float(_touching(records[-1])),
            0.0,
            "in contact at the run's end (1: the impact is not over, the rebound it reports is read mid-impact)",
            "the scene's rebound quantities are read after the body has left the obstacle",
        )
        out["missed"] = indicator(
            0.0 if any(_touching(r) for r in records) else 1.0,
            0.0,
            "no contact in the whole run (1: the body never reached the obstacle; the rebound it reports is the "
            "velocity it started with)",
            "the scene's rebound quantities are those of an impact",
        )
    shares = [(r.error.local, r.error.share) for r in steps if r.error is not None and r.error.share is not None]
    if shares:  # a run at a tolerance
        out["error_budget"] = indicator(
            sum(e for e, _ in shares) / sum(s for _, s in shares),
            ERROR_BUDGET,
            "the run's own estimate of its time-stepping error / the error its tolerance allows (its steps' local "
            f"error estimates over their shares, summed; {100 * at_floor(steps):.0f} % of the run's time in steps kept "
            "at the floor dt TOL with more than twice their share)",
            "a step is kept with up to twice its share; "
            "beyond: steps at the floor dt TOL where the estimate asked for smaller ones, and the tolerance is not "
            "assured",
        )
    out.update(_time_resolution(model, records, tolerance))
    return out


def _deepest(records):
    """The deepest penetration max(-g_N) over every contact state of every record, or None."""
    deepest = None
    for r in records:
        for st in r.evaluation.contacts:
            if np.size(st.g_N):
                d = float(np.max(-np.asarray(st.g_N), initial=0.0))
                deepest = d if deepest is None else max(deepest, d)
    return deepest


def _touching(rec):
    return any(np.any(np.asarray(st.t_N) != 0) for st in rec.evaluation.contacts)


def _time_resolution(model, records, tolerance=TOLERANCE):
    """The time resolution of a run's dynamic steps (those with a local error estimate, rec.error):
    impact_steps (closed contact episodes) and penalty_steps (every step in contact: an impact, a
    resting or a rolling contact), held to the run's tolerance (that of its error bars) by the integrator's
    error over half a period of a linear oscillator (one impact on a penalty spring:
    estimate.ErrorModel.half_period_error).

    (No indicator of a fixed-step run reads the steps' local errors: their sum, the run's own bound of
    its velocities' error (estimate.time_error), over its largest speed is 0.78 on the fast sloping
    impact, whose rebound is 7.7 % off the run refined in time, 1.66 on the rolling ring (2.6 % off),
    1.46 on the bar (1.8 % and 3.8 % off its closed forms, mesh included), 0.80 on the funnel and 1.03
    on the cork: held to a tolerance it flags every run, the accurate bar too, so it tells nothing. The
    bands (the time step's ladder) measure what it bounds; a run at a tolerance reports its budget.)"""
    steps = [r for r in records if r.error is not None]
    if not steps:
        return {}
    out = {}
    model_ = steps[-1].error.model  # the stepper's (a run's dynamic steps share one)
    omega = model_.resolving_omega_dt(tolerance)
    newmark = f"Newmark delta = {model_.delta:g}, beta = {model_.beta:g}"
    half = (
        f"{newmark} errs by {100 * tolerance:g} % (the run's tolerance, --tolerance) over half a period of a "
        f"linear oscillator (an impact on a penalty spring) at w dt = {omega:.3g} (its amplification matrix: Hughes, "
        "The Finite Element Method, Sec. 9.3; the energy-consistent midpoint rule as the trapezoidal rule)"
    )
    episodes, start, before = [], None, True  # a contact the run starts in (the cork's press fit) is no impact
    for k, r in enumerate(records):
        touching = _touching(r)
        if touching and not before and r.error is not None:
            start = k  # a touch-down in a dynamic step
        elif not touching and start is not None:
            episodes.append(k - start)  # steps with contact, touch-down to lift-off
            start = None
        before = touching
    if episodes:  # an impact: a closed episode
        out["impact_steps"] = indicator(
            max(episodes),
            math.ceil(math.pi / omega),
            "steps that resolve the longest impact (touch-down to lift-off)",
            f"an impact is half a period of the contact's oscillation, pi / (w dt) steps; {half}",
            upper=False,
        )
    stiff = _penalty_steps(model, steps)
    if stiff is not None:
        out["penalty_steps"] = indicator(
            stiff,
            omega,
            "dt sqrt(k / m) in contact, k the contact stiffness and m the mass at the stiffest touching node",
            half,
        )
    return out


def _penalty_steps(model, steps):
    """The largest dt sqrt(k / m) over the steps in contact: k = dt_N w at the stiffest touching node
    of a contact, m its lumped mass; None where no step is in contact. (Besides the solver's Contact protocol it
    reads what every contact of contactfem.contact has: its slave body and nodes, and its states' per-node
    dt_N and weights, as _deepest and _touching read their g_N and t_N.)"""
    system = model.system
    if system is None:
        return None
    m = system.lumped_mass()
    best = None
    for r in steps:
        for st, c in zip(r.evaluation.contacts, system.contacts):  # (every contact's state: per slave node)
            k = np.abs(np.asarray(st.dt_N)) * st.weights
            if not np.size(k):
                continue
            j = int(np.argmax(k))
            if k[j] <= 0:
                continue
            body = c.slave
            dof = system.offset(body) + body.xdofs[c.nodes[j], 1]
            if m[dof] <= 0:
                continue
            f = r.dt * float(np.sqrt(k[j] / m[dof]))
            best = f if best is None else max(best, f)
    return best


def stepping(params, records):
    """How a run stepped (``stepping``): the mode (fixed, or at the tolerance params['accuracy']), the
    integrator, the steps taken, the smallest and the largest step, and at_floor."""
    dynamic = [r for r in records if r.error is not None]  # (a scene's static stage has no estimate)
    dts = [r.dt for r in dynamic]
    tol = params.get("accuracy") or 0.0
    return dict(
        mode="adaptive" if tol else "fixed",
        accuracy=tol or None,
        integrator=integrator_of(params),
        steps=len(dts),
        dt_min=min(dts, default=None),
        dt_max=max(dts, default=None),
        at_floor=at_floor(dynamic) if tol else None,
    )


def at_floor(steps):
    """The fraction of a run's time in steps kept with more than twice their share of the error (above
    the floor dt TOL, schedule.py rejects them: the estimate asked for less); None for fixed steps."""
    shared = [(r.dt, r.error.local > 2.0 * r.error.share) for r in steps if r.error is not None and r.error.share]
    total = sum(dt for dt, _ in shared)
    return (float(sum(dt for dt, over in shared if over) / total) if total > 0 else 0.0) if shared else None


PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep


def _in_package(filename):
    return os.path.abspath(filename).startswith(PACKAGE)


def warn(accuracy, stacklevel=2):
    """One AccuracyWarning per indicator past its threshold (the same run twice warns twice: no
    registry remembers a line), pointing at the first line outside the package from where warnings.warn(stacklevel)
    would (a script's or a notebook cell's call of run_scene); returns the lines. An
    indicator without a value (no error band could be estimated) says what it lacks."""
    lines = [
        f"accuracy: {name}: {ind['what']} ({ind['source']})"
        if ind.get("value") is None
        else f"accuracy: {name} = {ind['value']:.3g}, {ind['bound']} {ind['threshold']:.3g} wanted ({ind['what']}; "
        f"threshold: {ind['source']})"
        for name, ind in accuracy.items()
        if isinstance(ind, dict) and not ind.get("ok", True)
    ]
    frame = sys._getframe(1)
    for _ in range(stacklevel - 2):
        frame = frame.f_back or frame
    while frame.f_back is not None and _in_package(frame.f_code.co_filename):
        frame = frame.f_back  # the line that asked for the run (run_scene's caller), not the package's own
    for line in lines:
        warnings.warn_explicit(
            line,
            AccuracyWarning,
            frame.f_code.co_filename,
            frame.f_lineno,
            module=frame.f_globals.get("__name__"),
            registry=None,
        )
    return lines
