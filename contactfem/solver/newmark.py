"""Time stepping (paper Sec. 4.1 and the algorithm of Sec. 4.3).

Three steppers share one interface, ``step(t, u, v, a, dt=None, label="") ->
(u+, v+, a+, NewtonResult)``, which does NOT commit anything; ``integrate`` drives
them, commits history only after convergence and records energies.

* Newmark: implicit, full Newton on the effective system (paper Sec. 4.1, 4.3).
* Static: quasi-static (no inertia), for load stepping and pressing-in phases.
* CentralDifference: explicit (Newmark with beta = 0, delta = 1/2), no Newton.

Newmark (the paper's delta is the usual gamma), with the predictor
    u_pred = u + dt v + dt^2 (1/2 - beta) a
the update of the step is
    a+ = (u+ - u_pred) / (beta dt^2),    v+ = v + dt ((1 - delta) a + delta a+),
and u+ solves eq 29 at t+ = t + dt,
    G(u+) = M a+ + R(u+) + R_c(u+) - P(u+, t+) = 0,
by Newton with the effective tangent M / (beta dt^2) + K + K_c (M lumped, diagonal).
Unconditionally stable (linear analysis) for delta >= 1/2 and
beta >= (delta + 1/2)^2 / 4; delta = 1/2, beta = 1/4 (average acceleration)
conserves energy; the paper's delta = 0.7, beta = 0.4 damps high frequencies.
"""
import warnings
from dataclasses import dataclass, field

import numpy as np

from .newton import NewtonError, NewtonResult, newton


def _check_dt(dt):
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite number > 0, got {dt}")


def _acceleration(system, G):
    """a = -G / M on the free dofs with mass (M a = P - R, a diagonal solve);
    0 on prescribed and massless dofs."""
    M = system.mass()
    a = np.zeros(system.ndof)
    free = system.free_dofs[M[system.free_dofs] > 0]
    a[free] = -G[free] / M[free]
    return a


def initial_acceleration(system, t, u):
    """a0 from M a0 = P(u0, t0) - R(u0) - R_c(u0) (eq 29 at t0, lumped M).
    Prescribed dofs get 0 (their acceleration is not known from the data)."""
    return _acceleration(system, system.residual_tangent(u, t)[0])


class Newmark:
    """Implicit Newmark stepper (paper Sec. 4.1), full Newton within the step.

    ``newton_options`` (atol, rtol, maxit) are passed on to ``newton``.
    """
    dynamic = True

    def __init__(self, system, dt, delta=0.7, beta=0.4, **newton_options):
        _check_dt(dt)
        if not 0 <= delta <= 1:
            raise ValueError(f"delta must be in [0, 1], got {delta}")
        if not 0 < beta <= 0.5:
            raise ValueError(f"beta must be in (0, 0.5], got {beta} "
                             "(beta = 0 is explicit: use CentralDifference)")
        if delta < 0.5 or beta < (delta + 0.5) ** 2 / 4:
            warnings.warn(f"Newmark delta={delta}, beta={beta} is not unconditionally stable "
                          "(needs delta >= 1/2 and beta >= (delta + 1/2)^2 / 4)", stacklevel=2)
        self.system, self.dt, self.delta, self.beta = system, dt, delta, beta
        self.newton_options = newton_options

    def step(self, t, u, v, a, dt=None, label=""):
        dt = self.dt if dt is None else dt
        _check_dt(dt)
        s, beta, delta = self.system, self.beta, self.delta
        s.set_dt(dt)
        t1 = t + dt
        M = s.mass()
        c = 1.0 / (beta * dt ** 2)
        u_pred = u + dt * v + dt ** 2 * (0.5 - beta) * a

        def effective(u1):                    # eq 29 with a+ = c (u1 - u_pred); tangent K + c M
            G, K = s.residual_tangent(u1, t1, mass_coefficient=c)
            return G + M * c * (u1 - u_pred), K

        # initial guess: the acceleration stays a (u + dt v + dt^2 a / 2)
        guess = s.apply_dirichlet(u_pred + beta * dt ** 2 * a, t1)
        result = newton(effective, guess, s.free_dofs,
                        label=label or f"t = {t1:.6g}, dt = {dt:.3g}", **self.newton_options)
        u1 = result.u
        a1 = c * (u1 - u_pred)
        v1 = v + dt * ((1 - delta) * a + delta * a1)
        return u1, v1, a1, result


class Static:
    """Quasi-static stepper: solves R(u+) + R_c(u+) = P(u+, t+) (no inertia).

    ``dt`` is the pseudo-time increment of load stepping; v and a are returned as 0.
    """
    dynamic = False

    def __init__(self, system, dt=1.0, **newton_options):
        _check_dt(dt)
        self.system, self.dt, self.newton_options = system, dt, newton_options

    def step(self, t, u, v, a, dt=None, label=""):
        dt = self.dt if dt is None else dt
        _check_dt(dt)
        s, t1 = self.system, t + dt
        s.set_dt(dt)
        result = newton(lambda w: s.residual_tangent(w, t1), s.apply_dirichlet(u, t1),
                        s.free_dofs, label=label or f"t = {t1:.6g}", **self.newton_options)
        zero = np.zeros(s.ndof)
        return result.u, zero, zero.copy(), result


class CentralDifference:
    """Explicit central differences (Newmark beta = 0, delta = 1/2), lumped mass:

        u+ = u + dt v + dt^2 a / 2,   M a+ = P - R(u+) - R_c(u+),   v+ = v + dt (a + a+) / 2.

    Conditionally stable: dt < 2 / omega_max. Prescribed dofs: v+ = (u+ - u) / dt, a+ = 0.
    (The tangent is assembled but unused; fine for the small problems here.)
    """
    dynamic = True

    def __init__(self, system, dt):
        _check_dt(dt)
        if np.any(system.mass()[system.free_dofs] <= 0):
            raise ValueError("CentralDifference needs mass > 0 on every free dof")
        self.system, self.dt = system, dt

    def step(self, t, u, v, a, dt=None, label=""):
        dt = self.dt if dt is None else dt
        _check_dt(dt)
        s, t1 = self.system, t + dt
        s.set_dt(dt)
        u1 = s.apply_dirichlet(u + dt * v + 0.5 * dt ** 2 * a, t1)
        G, _ = s.residual_tangent(u1, t1)
        a1 = _acceleration(s, G)
        v1 = v + 0.5 * dt * (a + a1)
        v1[s.fixed_dofs] = (u1 - u)[s.fixed_dofs] / dt
        if not (np.all(np.isfinite(u1)) and np.all(np.isfinite(a1))):
            raise NewtonError(f"explicit step gave NaN/inf ({label or f't = {t1:.6g}'})", [], label)
        return u1, v1, a1, NewtonResult(u=u1, residuals=[], iterations=0, G=G + s.mass() * a1)


@dataclass
class History:
    """What ``integrate`` records, one entry per accepted (sub)step; entry 0 is the
    initial state. After integrate returns, the numeric fields are numpy arrays."""
    t: list = field(default_factory=list)
    dt: list = field(default_factory=list)
    residuals: list = field(default_factory=list)      # Newton residual norms of each step
    iterations: list = field(default_factory=list)     # linear solves of each step
    cuts: list = field(default_factory=list)           # step halvings before acceptance
    kinetic: list = field(default_factory=list)
    strain: list = field(default_factory=list)
    contact: list = field(default_factory=list)
    dissipation: list = field(default_factory=list)    # cumulative frictional dissipation
    external_work: list = field(default_factory=list)  # cumulative work of loads and supports
    failures: list = field(default_factory=list)       # first line of each failed Newton solve
    u: np.ndarray = None                               # final state
    v: np.ndarray = None
    a: np.ndarray = None
    result: object = None                              # NewtonResult of the last step

    def append(self, t, dt, result, cuts, energies, work):
        self.t.append(t)
        self.dt.append(dt)
        self.residuals.append(list(result.residuals) if result else [])
        self.iterations.append(result.iterations if result else 0)
        self.cuts.append(cuts)
        for key in ("kinetic", "strain", "contact", "dissipation"):
            getattr(self, key).append(energies[key])
        self.external_work.append(work)
        self.result = result

    def finish(self, u, v, a):
        for key in ("t", "dt", "iterations", "cuts", "kinetic", "strain", "contact",
                    "dissipation", "external_work"):
            setattr(self, key, np.asarray(getattr(self, key)))
        self.u, self.v, self.a = u, v, a
        return self


@dataclass(frozen=True)
class Step:
    """What a ``recorder`` learns about a step besides the state: its number k (0: the
    initial state), size dt, Newton result (None at k = 0) and step halvings."""
    k: int
    dt: float
    result: object = None
    cuts: int = 0

    @property
    def iterations(self):
        return self.result.iterations if self.result is not None else 0


def integrate(stepper, t0, u0, v0=None, n_steps=None, t_end=None, callback=None,
              cutback=False, max_cuts=4, *, a0=None, dt_rule=None, min_dt=None, growth=None,
              before_step=None, motion=None, stop=None, before_commit=None, recorder=None, progress=None,
              label=None, name=None):
    """Step from t0 over n_steps steps of stepper.dt, or up to t_end (algorithm of Sec. 4.3).

    Each step: Newton on the stepper's equation; on convergence the System commits
    (history variables, friction state, dissipation) and energies are recorded.
    With ``cutback``, a step whose Newton fails is halved (up to ``max_cuts`` times, and
    never below ``min_dt``) and the remainder of the step is covered with the smaller dt;
    the next step starts again with stepper.dt. ``callback(t, u, v, a)`` is called after
    each accepted step.

    Hooks for scenes with more than a fixed step (all optional, keyword only):

    a0                      initial acceleration (default: from eq 29 at t0, M a0 = -G;
                            0 for a Static stepper)
    dt_rule(t, u, v, a)     the size of the next step (adaptive stepping; needs t_end):
                            the step ends at min(t + dt_rule(...), t_end); a failed step
                            is halved as with cutback
    growth                  with dt_rule: a step may be at most ``growth`` times the last
                            accepted one (growth = 1: a cut step size is kept)
    before_step(t, u, v, a) called once before each step, from the last converged state
                            (explicit coupling, e.g. the gas pressure under the cork)
    motion(t1)              called before each attempt with its end time t1 (prescribed
                            motion of a rigid obstacle)
    stop(t, u, v, a)        ends the run early when it returns True (checked before a step)
    before_commit(t, u, v, a, step)  called with each converged step before the System
                            commits it (what the step did: e.g. which nodes slipped in it)
    recorder(t, u, v, a, step)  called for the initial state and each accepted step with a
                            ``Step`` (k, dt, Newton result, cuts)
    progress(t0, t_end, label)  makes a callback (e.g. ``contactfem.io.ProgressBar``)
                            called after each step and closed (its ``close()``) at the end
    label(k, t1, dt)        the text naming a step in a NewtonError (default: step k, t, dt)
    name                    what the progress bar shows (default: the stepper's class name)

    External work is summed with the trapezoidal rule, 1/2 (F_n + F_n+1) . (u_n+1 - u_n),
    over the loads P and the support reactions (the prescribed-dof part of G).
    Returns a History (``failures`` lists the first line of every failed Newton solve);
    a NewtonError that ends the run carries the History so far as ``error.partial``. A
    KeyboardInterrupt (Ctrl-C) leaves with the time reached and the step in progress as its
    attributes t, step and n_steps (None with an adaptive dt_rule).
    """
    s = stepper.system
    if (n_steps is None) == (t_end is None):
        raise ValueError("give exactly one of n_steps and t_end")
    DT = stepper.dt
    if dt_rule is not None and t_end is None:
        raise ValueError("an adaptive step (dt_rule) needs t_end, not n_steps")
    if t_end is not None:
        if not t_end > t0:
            raise ValueError(f"t_end must be > t0 = {t0}, got {t_end}")
        n_steps = int(np.ceil((t_end - t0) / DT - 1e-9))
    elif int(n_steps) != n_steps or n_steps < 1:
        raise ValueError(f"n_steps must be an integer >= 1, got {n_steps}")
    else:
        n_steps = int(n_steps)
        t_end = t0 + n_steps * DT
    if int(max_cuts) != max_cuts or max_cuts < 0:
        raise ValueError(f"max_cuts must be an integer >= 0, got {max_cuts}")
    if growth is not None and not growth >= 1:
        raise ValueError(f"parameter growth = {growth!r} is out of range: allowed [1, inf)")

    fixed = s.fixed_dofs
    s.set_dt(DT)                    # rate-dependent bodies and laws evaluate the initial state too
    u = s.apply_dirichlet(u0, t0)
    v = np.zeros(s.ndof) if v0 is None else np.array(v0, dtype=float)
    G, _ = s.residual_tangent(u, t0)
    if a0 is not None:
        a = np.array(a0, dtype=float)
    else:
        a = _acceleration(s, G) if stepper.dynamic else np.zeros(s.ndof)
    P, F = s.external_force(u, t0), G[fixed]          # loads and support reactions at t0
    work = 0.0

    bar = progress(t0, t_end, name or type(stepper).__name__) if progress is not None else None
    after = [c for c in (callback, bar) if c is not None]
    hist = History()
    hist.append(t0, 0.0, None, 0, s.energies(u, v), work)
    if recorder is not None:
        recorder(t0, u, v, a, Step(0, 0.0))

    def close():
        if bar is not None and hasattr(bar, "close"):
            bar.close()

    def attempt(t, h, k, cuts):
        """One step of size h from t (None if Newton failed and it may be cut)."""
        if motion is not None:
            motion(t + h)
        name = label(k, t + h, h) if label is not None else f"step {k}, t = {t + h:.6g}, dt = {h:.3g}"
        try:
            return stepper.step(t, u, v, a, dt=h, label=name)
        except NewtonError as err:
            hist.failures.append(str(err).splitlines()[0][:200] if str(err) else "Newton failed")
            if cutback and cuts < max_cuts and (min_dt is None or h / 2 >= min_dt * (1 - 1e-9)):
                return None
            err.partial = hist.finish(u, v, a)
            close()
            raise

    def accept(t, h, k, cuts, step):
        nonlocal u, v, a, P, F, work
        u1, v1, a1, result = step
        if before_commit is not None:
            before_commit(t, u1, v1, a1, Step(k, h, result, cuts))
        s.commit(u1)
        P1, F1 = s.external_force(u1, t), result.G[fixed]
        work += 0.5 * (P + P1) @ (u1 - u) + 0.5 * (F + F1) @ (u1 - u)[fixed]
        u, v, a, P, F = u1, v1, a1, P1, F1
        hist.append(t, h, result, cuts, s.energies(u, v), work)
        for fn in after:
            fn(t, u, v, a)
        if recorder is not None:
            recorder(t, u, v, a, Step(k, h, result, cuts))

    t, k = t0, 0
    try:
        if dt_rule is None:
            for k in range(1, n_steps + 1):
                if stop is not None and stop(t, u, v, a):
                    break
                if before_step is not None:
                    before_step(t, u, v, a)
                t_target = min(t0 + k * DT, t_end)
                h, cuts = t_target - t, 0
                while t < t_target - 1e-12 * DT:
                    h = min(h, t_target - t)
                    step = attempt(t, h, k, cuts)
                    if step is None:
                        h, cuts = h / 2, cuts + 1
                        continue
                    t = t_target if t_target - (t + h) < 1e-12 * DT else t + h
                    accept(t, h, k, cuts, step)
        else:
            k, last = 0, None
            while t < t_end - 1e-9 * (t_end - t0):
                if stop is not None and stop(t, u, v, a):
                    break
                if before_step is not None:
                    before_step(t, u, v, a)
                h = float(dt_rule(t, u, v, a))
                _check_dt(h)
                if growth is not None and last is not None:
                    h = min(h, growth * last)
                h, cuts, k = min(h, t_end - t), 0, k + 1
                while True:
                    step = attempt(t, h, k, cuts)
                    if step is not None:
                        break
                    h, cuts = h / 2, cuts + 1
                t, last = t + h, h
                accept(t, h, k, cuts, step)
    except KeyboardInterrupt as interrupt:     # Ctrl-C: say where (the innermost loop names it)
        if not hasattr(interrupt, "step"):
            interrupt.t, interrupt.step = t, k
            interrupt.n_steps = n_steps if dt_rule is None else None
        close()
        raise
    close()
    return hist.finish(u, v, a)
