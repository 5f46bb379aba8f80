"""Friction and normal laws that lie, as a student might write them by mistake, and one
honest law with fields of its own (m, delta) that the scenes also have as parameters.
Used by tests/test_law_guards.py through the command line and through run_scene."""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class NaNEverywhere:
    c_T: float = 10.0
    mu: float = 0.3

    def slip_bound(self, p, q):
        return np.nan * np.asarray(p)


@dataclass(frozen=True)
class NaNAbove:
    """Coulomb, but NaN above the pressure p_bad (a forgotten branch)."""

    c_T: float = 10.0
    mu: float = 0.3
    p_bad: float = 50.0

    def slip_bound(self, p, q):
        p = np.asarray(p)
        return np.where(p > self.p_bad, np.nan, self.mu * p)


@dataclass(frozen=True)
class NegativeAbove:
    """Coulomb, but Y = -mu p above p_bad (a sign error in one branch)."""

    c_T: float = 10.0
    mu: float = 0.3
    p_bad: float = 0.0

    def slip_bound(self, p, q):
        p = np.asarray(p)
        return np.where(p > self.p_bad, -self.mu * p, self.mu * p)


@dataclass(frozen=True)
class NaNWindow:
    """NaN for pressures strictly between lo and hi only: a law the quick probe of the law
    file (p = 0.5, 1, 2) does not catch, so that --no-check lets the run meet it."""

    c_T: float = 10.0
    mu: float = 0.3
    lo: float = 0.01
    hi: float = 0.45

    def slip_bound(self, p, q):
        p = np.asarray(p)
        return np.where((p > self.lo) & (p < self.hi), np.nan, self.mu * p)


@dataclass(frozen=True)
class OwnFields:
    """A slip bound hardening with the slip, Y = mu p (1 + delta q)^m: its fields m and
    delta share their names with the scenes' normal-law exponent and Newmark parameter,
    and keep their own defaults."""

    c_T: float = 10.0
    mu: float = 0.2
    m: float = 0.5
    delta: float = 0.0

    def slip_bound(self, p, q):
        return self.mu * np.asarray(p) * (1.0 + self.delta * np.asarray(q)) ** self.m


@dataclass(frozen=True)
class Tensile:
    """A normal law with the sign of t_N wrong beyond the depth d (it pulls)."""

    c_N: float = 10.0
    d: float = 0.05

    def traction(self, g_N):
        g = np.asarray(g_N, dtype=float)
        t = np.where(g < -self.d, -self.c_N * g, np.minimum(self.c_N * g, 0.0))
        return t, np.where(g < 0, self.c_N, 0.0)
