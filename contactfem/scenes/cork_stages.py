"""The two stages of the champagne cork (scene ``cork``, paper Sec. 5.5): the press fit
and the pop, and what the scene measures of them.

Stage 1 (press fit, ``Static``): the neck starts at r = 12 mm (touching the cork)
and is moved radially inwards to r = 10 mm in ``n_press`` increments (prescribed
rigid-obstacle motion of the neck, its ``motion``), friction active; the axial position is
held at one axis node (at 2/3 of the shaft, ``z_hold``). That hold is released
when stage 2 starts: its reaction (``hold_reaction_N``, 2.5 N in the paper preset,
~20 N in the coarse fast one, against ~250 N of friction) is the small imbalance
the first dynamic step absorbs. (A static release step
without the hold, where friction alone carries the cork, is singular whenever all
nodes slip and its Newton iteration chatters between stick and slip.)

Stage 2 (pop, ``Newmark`` delta = 0.7, beta = 0.4; the trapezoidal rule at a tolerance): a follower pressure p on the
cork's bottom face, raised by p_step per step of dt for n_ramp steps, then Boyle's
law evaluated ONCE PER STEP from the last converged state (explicit coupling, as
the paper; the gas pressure load's state, GasPressure.update at each commit): p = p0 V0 / V, V0 = pi R_neck^2 * gas_column, V = V0 + (volume swept
by the bottom face since the start of stage 2), i.e. V0 + pi R^2 * (its axial
displacement). When the bottom corner of the cork reaches the mouth (z = 24 mm)
the gas escapes: p = 0 from then on (ambient; no gas jet is modelled).
Adaptive step (what drives it; with ``accuracy`` > 0 the local error estimate instead,
solver/schedule.py, under the same travel limit): dt_fine while the cork bottom is within
``exit_zone`` of the mouth and for ``t_after`` after the gas release (the paper's
5e-6 s), otherwise dt, but never more than ``travel_max`` of axial travel per step
(so a contact node does not jump over the 2 mm mouth in one step); a step whose Newton
fails is halved (up to ``max_cuts`` times, each counted in ``newton_failures``),
then the NewtonError is raised with its residual history.

What the scene measures of both stages (the exit, the breakaway) is in cork_measure.py.
"""

from dataclasses import replace

import numpy as np

from ..solver import Adaptive, Dirichlet, Newmark, Static, System
from ..solver.march import march, watch
from ..solver.schedule import at_tolerance
from .cork_measure import R_TIP_FITTED, centre_of_mass_velocity, contact_forces, static_breakaway
from .time_integration import newmark_of


def _newton_options(P):
    return dict(atol=P["atol"], rtol=P["rtol"], maxit=P["maxit"])


def _hold(cork, axis, P):
    """The axis node the press fit holds axially (nearest to z = z_hold L_neck)."""
    return axis[np.argmin(np.abs(cork.X[axis, 1] - P["z_hold"] * P["L_neck"]))]


def stage_systems(parts, P, system_options=None, contacts=None):
    """The Systems of both stages, from the cork's parts (cork.build): the press fit's
    (the axis held radially, the hold node axially) and the pop's (the gas on the bottom
    face, the neck at rest at r = R_neck). ``contacts``: (the press fit's, the pop's) contacts
    instead of ``parts["contacts"]`` in both (the pop's own moved to the neck at rest)."""
    cork, axis, neck, options = parts["cork"], parts["axis"], parts["neck"], system_options or {}
    fit_contacts, pop_contacts = contacts if contacts is not None else (parts["contacts"], parts["contacts"])
    hold = _hold(cork, axis, P)
    fixed = [Dirichlet(cork, cork.xdofs[axis, 0], 0.0), Dirichlet(cork, [cork.xdofs[hold, 1]], 0.0)]
    fit = System([cork], fit_contacts, [], fixed, **options)
    rest = neck.without_motion()  # the press fit is done: the neck stays at r = R_neck
    moved = [c.with_master(rest) if c.master is neck else c for c in pop_contacts]
    pop = System([cork], moved, [parts["gas"]], [Dirichlet(cork, cork.xdofs[axis, 0], 0.0)], **options)
    return fit, pop


def press_fit(model, P, progress=None):
    """Stage 1: the neck moves in from r = R_cork to r = R_neck over the pseudo-time t in
    [0, 1] (its ``motion``) in n_press static increments (a failed increment is halved and the
    smaller increment kept), the axial position held at one axis node (released at the start
    of stage 2); the model's first System. Returns the last record and the stage's
    iterations, failures, hold reaction."""
    cork, system = model.parts["cork"], model.systems[0]
    hold = _hold(cork, model.parts["axis"], P)
    ds = 1.0 / P["n_press"]
    schedule = Adaptive(
        lambda rec: ds, t_end=1.0, dt=ds, growth=1.0, max_cuts=P["max_cuts"], min_dt=ds / 2 ** P["max_cuts"]
    )
    records = list(
        watch(
            march(
                Static(system, **_newton_options(P)),
                schedule,
                0.0,
                np.zeros(system.ndof),
                label=lambda k, t1, h: f"press fit {t1:.3f}",
            ),
            progress,
            0.0,
            1.0,
            "cork: press fit",
        )
    )
    last = records[-1]
    # the axial hold's reaction: released at the start of stage 2 (the dynamic run absorbs this
    # small imbalance; it is reported, not hidden)
    return last, dict(
        iterations=int(sum(r.iterations for r in records)),
        failures=int(sum(r.cuts for r in records)),
        hold_reaction=float(last.result.G[cork.xdofs[hold, 1]]),
    )


def choose_dt(P, t, gap_to_mouth, released_at, v_cm):
    """Adaptive step of stage 2 (module docstring): dt_fine near the exit, otherwise dt
    limited to travel_max of axial travel, never below dt_fine."""
    near_exit = 0.0 < gap_to_mouth < P["exit_zone"]
    after_exit = released_at is not None and t - released_at < P["t_after"]
    if near_exit or after_exit:
        return P["dt_fine"]
    dt = P["dt"]
    if abs(v_cm) > 0:
        dt = min(dt, P["travel_max"] / (1e3 * abs(v_cm)))  # v_cm in m/s = 1e3 mm/s
    return max(dt, P["dt_fine"])


def gas_lag_step(P, gas, rec, tol):
    """The step at which the gas's explicit coupling keeps its share of the error at the tolerance
    tol (a run at a tolerance; the integrator's own estimate does not see it): a step acts with the
    pressure of the state before it, p_n for the p_n+1 the step ends with, and so changes the cork's
    velocity by about dt / 2 |p_n+1 - p_n| A / M less than it should (first order in dt). Held at
    tol speed dt / t_end like the integrator's error (schedule.error_step): h = dt (share / error).
    Each of the two errors is held at its share, so together they may reach twice the tolerance;
    the lag is not in the run's error_budget (the integrator's estimate alone)."""
    if rec.k == 0:
        return np.inf
    dp = abs(gas.pressure(rec.t, rec.state.loads[0]) - gas.pressure(rec.t, rec.evaluation.state.loads[0]))
    lag = 0.5 * rec.dt * dp * np.pi * P["R_neck"] ** 2 / cork_mass(P)
    share = tol * speed_scale(P) * rec.dt / P["t_end"]
    return np.inf if lag == 0 else max(rec.dt * share / lag, P["dt"] * tol)


def cork_mass(P):
    """The cork's mass from its outline (shaft over the neck and the mouth, and the head)."""
    return P["rho"] * np.pi * P["R_cork"] ** 2 * (P["L_neck"] + P["r_mouth"] + P["L_head"])


def speed_scale(P):
    """The speed the gas could give the cork over the neck (all its largest pressure's work
    p_0 pi R_neck^2 (L_neck + r_mouth) as kinetic energy), in mm/s: the exit velocity's scale."""
    W = P["p_step"] * P["n_ramp"] * np.pi * P["R_neck"] ** 2 * (P["L_neck"] + P["r_mouth"])
    return float(np.sqrt(2.0 * W / cork_mass(P)))


def pop(model, P, u0, progress=None, histories=None):
    """Stage 2: the gas drives the cork out (Newmark; explicit Boyle coupling: the gas pressure
    of the next step from each converged step, the load's state; adaptive dt with cutback).
    Runs to t_end, or t_flight after the exit. ``histories``: the contacts' histories to start
    from (the press fit's last record's, ``record.state.contacts``; None: started at u0).
    The model's second System. Returns the records, the gas pressure that acted in each step,
    the exit time and the gas state at the end (GasState: ``released``, ``released_at``)."""
    cork, gas, system = model.parts["cork"], model.parts["gas"], model.systems[1]
    t_ramp = P["n_ramp"] * P["dt"]
    state = system.start(u0, 0.0)
    if histories is not None:  # the contacts go on from the press fit
        state = replace(state, contacts=tuple(histories))

    delta, beta = newmark_of(P)  # (the trapezoidal rule at a tolerance)
    stepper = Newmark(system, delta=delta, beta=beta, **_newton_options(P))
    tol = P.get("accuracy") or 0.0
    rule, rejections = None, 0
    if tol:  # steps from the local error estimate: the exit velocity's errors (its scale: speed_scale) add up
        stepper, rule, rejections = at_tolerance(stepper, tol, speed_scale(P), P["t_end"], P["dt"])  # over t_end

    def dt_rule(rec):  # rec.state: the gas after the step
        v_cm = centre_of_mass_velocity(cork, rec.v) / 1e3 if rec.k else 0.0
        if rule is not None:  # travel_max still holds, and the gas's lag
            h = min(rule(rec), gas_lag_step(P, gas, rec, tol))
            h = min(h, P["travel_max"] / (1e3 * abs(v_cm))) if v_cm else h
        else:
            h = choose_dt(P, rec.t, P["L_neck"] - gas.edge_z(rec.u), rec.state.loads[0].released_at, v_cm)
        return min(h, t_ramp - rec.t) if rec.t < t_ramp * (1 - 1e-9) else h

    # the press fit is a static state: start at rest with a0 = 0 (M^-1 G would put the hold's
    # reaction on one light axis node as a spurious acceleration spike)
    zero = np.zeros(system.ndof)
    schedule = Adaptive(
        dt_rule, t_end=P["t_end"], dt=P["dt"], max_cuts=P["max_cuts"] + rejections, growth=2.0 if tol else None
    )
    records, pressures, exit_time, touching, acting = [], [], None, None, None
    bar = progress(0.0, P["t_end"], "cork: pop") if progress is not None else None
    try:
        for rec in march(
            stepper,
            schedule,
            0.0,
            u0.copy(),
            zero,
            a0=zero,
            state=state,
            label=lambda k, t1, h: f"cork t = {t1 * 1e3:.5f} ms, dt = {h:.2e}",
        ):
            if bar is not None:
                bar(rec.t, rec.u, rec.v, rec.a)
            records.append(rec)
            pressures.append(gas.pressure(rec.t, acting) if rec.k else 0.0)  # the gas the step was taken with
            n_contact = sum(st.n_active for st in rec.contacts)
            if rec.k and acting.released and n_contact == 0 and (exit_time is None or touching):
                exit_time = rec.t  # the last time the contact opened
            touching = n_contact > 0
            if exit_time is not None and rec.t >= exit_time + P["t_flight"] * (1 - 1e-9):
                if hasattr(bar, "finish"):  # done before t_end: the bar says why
                    bar.finish(
                        f"the cork left at {exit_time * 1e3:.3f} ms; the run stops t_flight = "
                        f"{P['t_flight'] * 1e3:g} ms later"
                    )
                break  # t_flight after the exit: stop
            acting = rec.state.loads[0]  # explicit coupling: the next step's pressure
    finally:
        if hasattr(bar, "close"):
            bar.close()
    return records, np.array(pressures), exit_time, acting


def simulate(model, P, progress=None):
    """Both stages: the press fit (its last record, iterations, failures, hold reaction and
    the contact forces it ends with) and the pop (records, pressures, exit and release)."""
    fit_last, fit = press_fit(model, P, progress)
    fit.update(contact_forces(fit_last.contacts))
    areas = model.parts["cork"].element_areas
    fit["min_area_ratio"] = float(np.min(areas(fit_last.u) / areas(0 * fit_last.u)))
    records, pressures, exit_time, gas = pop(model, P, fit_last.u, progress, fit_last.state.contacts)
    exited = bool(gas.released and records[-1].contacts[0].n_active == 0)
    return dict(
        fit_last=fit_last,
        fit=fit,
        records=records,
        pressures=pressures,
        exited=exited,
        exit_time=exit_time if exited else None,
        released_at=gas.released_at,
    )


def press_fit_only(params):
    """Stage 1 alone (a few seconds): the press-fit force and the static breakaway margin,
    without the pop. For studies of the knife's edge over mu, R_tip and p0."""
    from .cork import build

    model = build(params)
    last, fit = press_fit(model, params)
    fit.update(contact_forces(last.contacts))
    return dict(
        static_breakaway(params, fit["normal"]),
        press_fit_normal_force_N=fit["normal"],
        press_fit_calibrated=bool(params["R_tip"] == R_TIP_FITTED),
    )
