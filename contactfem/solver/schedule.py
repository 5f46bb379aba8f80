"""Schedules: the step sizes of a march (march.py), and what happens when a step fails.

    Steps(dt, n_steps=200)                   fixed steps of dt (or up to t_end)
    Adaptive(rule, t_end, dt=...)            rule(record) -> the size of the next step
    at_tolerance(stepper, tol, speed, ...)   a stepper that estimates its local error and the
                                             rule that keeps it at a tolerance (error_step)

Both halve a step whose Newton fails, up to ``max_cuts`` times and never below
``min_dt`` (``cut``); the march then retries the step with the smaller size. A schedule
answers three questions: the size of the next step after a record (None: the run is
over), the size after a failure, and the time a step ends at.
"""

import math
from dataclasses import replace
from functools import partial

import numpy as np

from .newton import NewtonError


def check_dt(dt, name="dt"):
    """The one check of a step size: a finite number > 0 (ValueError naming it)."""
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"parameter {name} = {dt!r} is out of range: allowed (0, inf)")
    return float(dt)


class _Cuts:
    def __init__(self, max_cuts, min_dt):
        if int(max_cuts) != max_cuts or max_cuts < 0:
            raise ValueError(f"parameter max_cuts = {max_cuts!r} is out of range: allowed integers >= 0")
        self.max_cuts, self.min_dt = int(max_cuts), min_dt

    def cut(self, dt, cuts):
        """The size to retry a failed step of dt with (its cuts-th halving so far), or None."""
        if cuts >= self.max_cuts or (self.min_dt is not None and dt / 2 < self.min_dt * (1 - 1e-9)):
            return None
        return dt / 2


class Steps(_Cuts):
    """Fixed steps of dt from t0: n_steps of them, or as many as reach t_end (the last one
    shortened). After a halved step the rest of the step is covered with the smaller size;
    the next step starts again with dt. Step ends are snapped onto the grid t0 + k dt."""

    def __init__(self, dt, n_steps=None, t_end=None, t0=0.0, max_cuts=0, min_dt=None):
        super().__init__(max_cuts, min_dt)
        self.dt, self.t0 = check_dt(dt), float(t0)
        if (n_steps is None) == (t_end is None):
            raise ValueError("give exactly one of n_steps and t_end")
        if t_end is not None:
            if not t_end > t0:
                raise ValueError(f"parameter t_end = {t_end!r} is out of range: allowed (t0, inf) = ({t0}, inf)")
            self.n_steps = int(np.ceil((t_end - t0) / self.dt - 1e-9))
            self.t_end = float(t_end)
        else:
            if int(n_steps) != n_steps or n_steps < 1:
                raise ValueError(f"parameter n_steps = {n_steps!r} is out of range: allowed integers >= 1")
            self.n_steps = int(n_steps)
            self.t_end = self.t0 + self.n_steps * self.dt

    # times closer than a billionth of a step are the same time: (t - t0) / dt of a grid time
    # t0 + k dt is k only to round-off, ~k 1e-16, which an absolute 1e-12 would not cover from
    # k ~ 1e4 on (slivers of 1e-14 and steps that never end); halved steps are >= dt / 2^20
    SAME = 1e-9

    def _target(self, t):
        """The grid time the step from t heads for: the first t0 + k dt beyond t."""
        k = min(math.floor((t - self.t0) / self.dt + self.SAME) + 1, self.n_steps)
        return min(self.t0 + k * self.dt, self.t_end)

    def next_dt(self, rec):
        if rec.t >= self.t_end - self.SAME * self.dt:
            return None
        target = self._target(rec.t)
        on_grid = rec.k == 0 or abs(rec.t - (target - self.dt)) <= self.SAME * self.dt or rec.t == self.t0
        if not on_grid:  # within a halved step: go on with its size
            return min(rec.dt, target - rec.t)
        return target - rec.t

    def end_time(self, t, dt):
        target = self._target(t)
        return target if target - (t + dt) < self.SAME * self.dt else t + dt

    def cut(self, dt, cuts):
        """As _Cuts.cut, and never below dt / 2^max_cuts of the schedule's dt: the rest of a halved
        step goes on with the smaller size, and its parts, cut again each with a fresh count, would
        otherwise halve without end (a run that crawls at 1e-11 of its step and never finishes)."""
        if dt / 2 < self.dt / 2**self.max_cuts * (1 - 1e-9):
            return None
        return super().cut(dt, cuts)


class Adaptive(_Cuts):
    """Steps of the size ``rule(record)`` gives after each record, up to t_end (the last one
    shortened); ``growth``: a step is at most growth times the last accepted one (growth = 1
    keeps a halved size); ``dt``: the size the initial state is evaluated with (rate-dependent
    bodies and laws) and ``n_steps`` None (the number of steps is not known beforehand)."""

    n_steps = None

    def __init__(self, rule, t_end, dt, t0=0.0, max_cuts=0, min_dt=None, growth=None):
        super().__init__(max_cuts, min_dt)
        self.rule, self.t0, self.t_end, self.dt = rule, float(t0), float(t_end), check_dt(dt)
        if not self.t_end > self.t0:
            raise ValueError(f"parameter t_end = {t_end!r} is out of range: allowed (t0, inf) = ({t0}, inf)")
        if growth is not None and not growth >= 1:
            raise ValueError(f"parameter growth = {growth!r} is out of range: allowed [1, inf)")
        self.growth = growth

    def next_dt(self, rec):
        if rec.t >= self.t_end - 1e-9 * (self.t_end - self.t0):
            return None
        h = check_dt(float(self.rule(rec)), "dt (the schedule's rule)")
        if self.growth is not None and rec.k > 0:
            h = min(h, self.growth * rec.dt)
        return min(h, self.t_end - rec.t)

    def end_time(self, t, dt):
        return t + dt


# -- steps chosen from a local error estimate (a scene's ``accuracy``) ----------------------------
#
# A step of Newmark (delta, beta) updates the velocities by dt ((1 - delta) a + delta a+); against
# the Taylor series of the exact motion its local error is
#
#     (delta - 1/2) dt^2 a' + (delta / 2 - 1/6) dt^3 a'' + ...,     a' ~ (a+ - a) / dt,
#
# first order in dt where delta > 1/2 (the paper's 0.7): c dt |a+ - a| with c = delta - 1/2. This
# term is the method's numerical damping: it takes the energy of the vibrations an impact excites,
# and a rebound's or a rolling ring's speed with it (bench study 10 measures what it costs against
# the trapezoidal rule). A scene at a tolerance therefore integrates with the trapezoidal rule (delta = 1/2, beta = 1/4,
# problem/time_integration.py) or the energy-consistent stepper, both second order. There the first
# term vanishes and the error is the second, dt^3 a'' / 12, from the second difference of the
# accelerations over the last two steps (hs their sizes, s = (a+ - a) / h their slopes):
#
#     a'' ~ (s - s_prev) / ((h + h_prev) / 2)
#
# (the midpoint rule's is dt^3 a'' / 24: 1/12 bounds both). Its norm is the kinetic energy's, a
# mass-weighted root mean square (sum m_i d_i^2 / sum m_i)^(1/2): the vibrations an impact excites
# change the contact forces while the bodies touch, and the headline quantities with them. The
# first step has no slope before it: its estimate is the bound c dt |a+ - a|, c = |beta - 1/6|
# (Zienkiewicz and Xie's, 1/12 for both steppers), and so has the second (the first step's slope
# starts from an initial acceleration a scene may set by hand). A step hands its slope to the
# next one in its SystemState (``stepper``): the run carries it as a value. The local errors of the steps add up;
# holding each at ``tol speed dt / duration`` (its share) keeps their sum over the run within
# tol speed (error per unit step). A step is chosen from the last one's error (error_step) and
# taken; one whose error is past twice its share (the step into an impact or out of it: the rule
# cannot see an event coming) is retried halved, as a step whose Newton fails (StepRejected), down
# to the first step's size.


def error_constant(stepper):
    """c of the first-difference estimate c dt |a+ - a| (the comment above), and the power of the
    error's ratio that gives the next step (1 for a first-order velocity update, 1/2 for a
    second-order one, whose later steps use the second difference). A wrapping stepper (Uzawa's
    outer loop) is looked through."""
    stepper = getattr(stepper, "stepper", stepper)
    if type(stepper).__name__ == "EnergyConsistent":
        return 1.0 / 12.0, 0.5
    delta, beta = getattr(stepper, "delta", None), getattr(stepper, "beta", None)
    if delta is None or beta is None:
        raise ValueError(
            f"accuracy needs an implicit Newmark or the energy-consistent stepper, not {type(stepper).__name__}"
        )
    if abs(delta - 0.5) > 1e-12:
        return abs(delta - 0.5), 1.0
    return abs(beta - 1.0 / 6.0), 0.5


class StepRejected(NewtonError):
    """A converged step whose local error is past twice its share: the march retries it halved."""


class Estimated:
    """A dynamic stepper whose step results carry ``local_error``, the estimate of the comment
    above, ``error_share``, the error a step of its size may have (None without a share), and
    ``carry``, (the step's slope of the accelerations, its size) for the next step's estimate (the
    march puts it in the SystemState, ``state.stepper``). ``share(dt)``: the error a step of dt
    may have; a step longer than ``floor`` with more than twice that raises StepRejected (None:
    every step kept). Anything else is the wrapped stepper's (``stepper``: its system, whether it
    is dynamic, its Newmark parameters)."""

    def __init__(self, stepper, share=None, floor=0.0):
        self.stepper, self.share, self.floor = stepper, share, floor
        self.c, self.power = error_constant(stepper)
        self.mass = stepper.system.lumped_mass()

    @property
    def system(self):
        return self.stepper.system

    @property
    def dynamic(self):
        return self.stepper.dynamic

    def norm(self, d):
        """|d|: the kinetic energy's norm, (sum m_i d_i^2 / sum m_i)^(1/2)."""
        return float(np.sqrt(np.sum(self.mass * d * d) / np.sum(self.mass)))

    def estimate(self, a, a1, dt, before):
        """The step's local error in the velocities and what it hands to the next step, (its slope
        (a1 - a) / dt, dt); ``before``: what the step before handed on (SystemState.stepper), or
        None at the first step. The first step's slope is not handed on (None): it starts from the
        initial acceleration, which a scene may set by hand (the cork's pop starts at rest with
        a0 = 0), so the second step takes the first-difference bound too."""
        slope = (a1 - a) / dt
        handed = (None if before is None else slope, dt)
        if self.power == 1.0 or before is None or before[0] is None:
            return self.c * dt * self.norm(a1 - a), handed
        s0, h0 = before
        return dt**3 / 12.0 * self.norm((slope - s0) / (0.5 * (dt + h0))), handed

    def step(self, t, u, v, a, dt, label="", *, state):
        u1, v1, a1, result = self.stepper.step(t, u, v, a, dt, label, state=state)
        e, handed = self.estimate(a, a1, dt, getattr(state, "stepper", None))
        if self.share is not None and dt > self.floor * (1 + 1e-9) and e > 2.0 * self.share(dt):
            raise StepRejected(f"local error {e:.3g} is past twice its share {self.share(dt):.3g}", [], label)
        return (
            u1,
            v1,
            a1,
            replace(result, local_error=e, carry=handed, error_share=None if self.share is None else self.share(dt)),
        )


def error_step(rec, tol, speed, duration, dt_first, dt_max, power=1.0):
    """Adaptive's rule for a run at a tolerance: the size of the step after ``rec`` from its
    step's local error e (``rec.result.local_error``, Estimated): the step whose error would be
    tol speed dt / duration, dt (tol speed dt / (duration e))^power, between dt_first and dt_max;
    dt_first for the first step (no estimate yet). (The floor: an acceleration that jumps, as a
    friction force from stick to slip, gives an error that no step makes smaller.)"""
    e = getattr(rec.result, "local_error", None)
    if rec.k == 0 or e is None:
        return dt_first
    if not e > 0:
        return dt_max
    return min(dt_max, max(dt_first, rec.dt * (tol * speed * rec.dt / (duration * e)) ** power))


def at_tolerance(stepper, tol, speed, duration, dt_max):
    """A run at the tolerance tol (relative to ``speed``, its errors adding up over ``duration``,
    no step longer than dt_max): the stepper (Estimated, rejecting a step past twice its share),
    Adaptive's rule (error_step, the first step dt_max tol) and the halvings a step may need
    on top of its Newton's (a rejected step down to the first step's size)."""
    dt_first = dt_max * tol
    share = partial(_share, tol * speed / duration)
    estimated = Estimated(stepper, share=share, floor=dt_first)
    rule = partial(
        error_step, tol=tol, speed=speed, duration=duration, dt_first=dt_first, dt_max=dt_max, power=estimated.power
    )
    return estimated, rule, int(math.ceil(math.log2(1.0 / tol)))


def _share(rate, dt):
    return rate * dt
