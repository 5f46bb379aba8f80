"""Tangential interface laws (paper Sec. 2.2).

A friction law is two things (eqs 5 and 10):

* the stick law ``t_T = c_T g_T^e`` (eq 5): a tangential stiffness ``c_T`` for the
  elastic micro-displacement before sliding, and
* the slip bound ``Y(p, q)``: the largest tangential traction the interface
  carries at contact pressure ``p = |t_N|`` after an accumulated slip ``q``, so
  that the slip condition reads ``f = ||t_T|| - Y(p, q) <= 0`` (eqs 10, 11).

``slip_bound(p, q)`` returns ``(Y, dY/dp, dY/dq)`` vectorised over contact nodes.
That is the whole interface: :func:`contactfem.laws.return_map` integrates any
such law (eqs 40-48), and :func:`contactfem.check_law` verifies a new one.
Slip follows the non-associated rule of eq (14): it is tangential only.
"""

from dataclasses import dataclass

import numpy as np

from .validation import require


@dataclass(frozen=True)
class ParabolicSlip:
    """Eq (10): f = -alpha |t_N|^n - beta |t_N| + ||t_T|| <= 0, the parabolic slip
    surface (Fig 4). The friction coefficient Y/p = alpha p^(n-1) + beta falls as the
    pressure rises when n < 1; n = 1 is Coulomb's cone with mu = alpha + beta (eq 11).

    Note for n < 1: dY/dp = alpha n p^(n-1) is unbounded at first touch (p -> 0)."""

    c_T: float
    alpha: float
    beta: float
    n: float = 1.0

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("alpha", self.alpha, 0.0)
        require("beta", self.beta, 0.0)
        require("n", self.n, 0.0, 1.0, low_open=True)

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        on = p > 0.0
        if on.all():  # every node pressed (the return map's call): no masking needed
            return (
                self.alpha * p**self.n + self.beta * p,
                self.alpha * self.n * p ** (self.n - 1.0) + self.beta,
                np.zeros(p.shape),
            )
        pp = np.where(on, p, 1.0)  # avoid 0**(n-1); masked below
        Y = np.where(on, self.alpha * pp**self.n + self.beta * p, 0.0)
        dY_dp = np.where(on, self.alpha * self.n * pp ** (self.n - 1.0) + self.beta, 0.0)
        return Y, dY_dp, np.zeros(p.shape)


@dataclass(frozen=True)
class Coulomb:
    """Eq (11): f = -mu |t_N| + ||t_T|| <= 0 (the n = 1 limit of eq 10, mu = alpha + beta)."""

    c_T: float
    mu: float

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu", self.mu, 0.0)

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        return self.mu * p, np.full(p.shape, float(self.mu)), np.zeros(p.shape)


@dataclass(frozen=True)
class SlipHardening:
    """Coulomb whose coefficient changes linearly with the accumulated slip q
    (paper Sec. 5.5, the cork: mu = mu_0 + h q with h = 0.001):

        Y(p, q) = max(mu_0 + h q, 0) p.

    h > 0 hardens, h < 0 softens (the coefficient is floored at zero). The return
    mapping then needs a local Newton iteration (paper, after eq 44)."""

    c_T: float
    mu: float
    h: float = 0.0

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu", self.mu, 0.0)
        require("h", self.h)

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        coef = self.mu + self.h * np.asarray(q, dtype=float)
        pos = coef > 0.0
        Y = np.where(pos, coef, 0.0) * p
        return Y, np.where(pos, coef, 0.0) + 0.0 * p, np.where(pos, self.h, 0.0) * p


@dataclass(frozen=True)
class Frictionless:
    """No tangential traction at all (c_T = 0, Y = 0)."""

    c_T: float = 0.0

    def slip_bound(self, p, q):
        z = np.zeros_like(np.asarray(p, dtype=float))
        return z, z, z
