"""Schedules: the step sizes of a march (march.py), and what happens when a step fails.

    Steps(dt, n_steps=200)                   fixed steps of dt (or up to t_end)
    Adaptive(rule, t_end, dt=...)            rule(record) -> the size of the next step
    AtTolerance(tol, speed, duration, ...)   steps that keep each step's local error (estimate.py,
                                             rec.error) at its share of a tolerance (error_step)

Each halves a step whose Newton fails, up to ``max_cuts`` times and never below
``min_dt`` (``cut``); the march then retries the step with the smaller size. A schedule
answers three questions: the size of the next step after a record (None: the run is
over), the size after a failure, and the time a step ends at; and two of a converged step's local
error (rec.error): the error its share allows (``share``) and whether it is retried halved
(``rejects``).
"""

import math
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

    def share(self, dt):
        """The error a step of dt may have (AtTolerance); None: no tolerance to keep."""
        return None

    def rejects(self, error, dt):
        """Whether a converged step with this StepError is retried halved (AtTolerance); never here."""
        return False


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
# The march estimates every dynamic step's local error (estimate.py) and records it (rec.error). The
# local errors of the steps add up; holding each at ``tol speed dt / duration`` (its share) keeps their
# sum over the run within tol speed (error per unit step). A step is chosen from the last one's error
# (error_step) and taken; one whose error is past twice its share (the step into an impact or out of
# it: the rule cannot see an event coming) is retried halved, as a step whose Newton fails
# (StepRejected), down to the first step's size. A flight's steps hold the bodies' momentum (march.resume).


class StepRejected(NewtonError):
    """A converged step whose local error is past twice its share: the march retries it halved."""


def error_step(rec, tol, speed, duration, dt_first, dt_max, power=1.0):
    """The rule of a run at a tolerance: the size of the step after ``rec`` from its step's local
    error e (``rec.error.local``, estimate.py): the step whose error would be tol speed dt /
    duration, dt (tol speed dt / (duration e))^power, between dt_first and dt_max; dt_first for the
    first step (no estimate yet). (The floor: an acceleration that jumps, as a friction force from
    stick to slip, gives an error that no step makes smaller.)"""
    if rec.k == 0 or rec.error is None:
        return dt_first
    e = rec.error.local
    if not e > 0:
        return dt_max
    return min(dt_max, max(dt_first, rec.dt * (tol * speed * rec.dt / (duration * e)) ** power))


class AtTolerance(Adaptive):
    """The steps of a run at the tolerance ``tol``, relative to ``speed``, its errors adding up over
    ``duration``, no step longer than ``dt_max``: error_step's rule (the first step dt_max tol, the
    floor), with the power of the stepper's ErrorModel (``model``); each step's share of the error
    (``share``) is tol speed dt / duration, and a step above the floor past twice its share is
    rejected (``rejects``), with the halvings that needs (down to the floor) on top of Newton's
    ``max_cuts``. ``limit(rec)``: a largest step of the scene's own after a record (None: dt_max),
    e.g. the cork's travel per step."""

    def __init__(self, tol, speed, duration, dt_max, t_end, model, t0=0.0, max_cuts=0, limit=None):
        self.tol, self.speed, self.duration, self.dt_max = float(tol), float(speed), float(duration), check_dt(dt_max)
        self.floor, self.limit = self.dt_max * self.tol, limit
        rule = partial(
            error_step,
            tol=self.tol,
            speed=self.speed,
            duration=self.duration,
            dt_first=self.floor,
            dt_max=self.dt_max,
            power=model.power,
        )
        self.error_rule = rule
        rejections = int(math.ceil(math.log2(1.0 / self.tol)))
        super().__init__(self._rule, t_end, dt=self.floor, t0=t0, max_cuts=max_cuts + rejections, growth=2.0)

    def _rule(self, rec):
        h = self.error_rule(rec)
        return h if self.limit is None else min(h, self.limit(rec))

    def share(self, dt):
        return self.tol * self.speed * dt / self.duration

    def rejects(self, error, dt):
        return dt > self.floor * (1 + 1e-9) and error.local > 2.0 * error.share
