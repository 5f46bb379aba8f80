"""Friction laws with a slip rate and internal variables (the protocol of
``contactfem.laws.protocol``): beyond the paper's Y(p, q), three classics of tribology.

* ``Stribeck``: the coefficient falls from static to kinetic as the slip rate grows
  (velocity weakening), with an optional viscous rise at high rates.
* ``DieterichRuina``: rate-and-state friction, a direct effect of the rate and a state
  theta (the age of the contacts) that heals at rest and is renewed by slip.
* ``ArchardWear``: Coulomb friction whose sliding wears the surface away (Archard:
  worn depth = k_w x pressure x slip), so the surface recedes and the gap opens.

The slip rate is v = lambda / dt, the slip part of the step's tangential increment over
the time step (zero while sticking); each law supplies its derivatives (the checker
compares them with finite differences).
"""

from dataclasses import dataclass

import numpy as np

from .validation import require


@dataclass(frozen=True)
class Stribeck:
    """Velocity-weakening (Stribeck) friction:

        Y(p, v) = p [ mu_d + (mu_s - mu_d) exp(-(v/v_s)^delta) + mu_v v ].

    At rest (v = 0) the coefficient is the static mu_s; it falls to the kinetic mu_d
    over the Stribeck velocity v_s and, with mu_v > 0, rises again linearly (viscous
    lubrication). delta >= 1 (2: the Gaussian form, dY/dv = 0 at rest, so the slip starts
    without a jump of the modulus). mu_s < mu_d is allowed: velocity strengthening."""

    c_T: float
    mu_s: float
    mu_d: float
    v_s: float
    mu_v: float = 0.0
    delta: float = 2.0

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu_s", self.mu_s, 0.0)
        require("mu_d", self.mu_d, 0.0)
        require("v_s", self.v_s, 0.0, low_open=True)
        require("mu_v", self.mu_v, 0.0)
        require("delta", self.delta, 1.0)

    def coefficient(self, v):
        """mu(v) and dmu/dv."""
        v = np.asarray(v, dtype=float)
        x = v / self.v_s  # >= 0
        e = np.exp(-(x**self.delta))
        d_e = -self.delta * x ** (self.delta - 1.0) * e / self.v_s
        return self.mu_d + (self.mu_s - self.mu_d) * e + self.mu_v * v, (self.mu_s - self.mu_d) * d_e + self.mu_v

    def slip_bound(self, p, q, v):
        p = np.asarray(p, dtype=float)
        mu, dmu = self.coefficient(v)
        return mu * p, mu + 0.0 * p, 0.0 * p, dmu * p


@dataclass(frozen=True)
class DieterichRuina:
    """Rate-and-state friction (Dieterich 1979, Ruina 1983), in the form with cut-off
    velocities that keeps a static threshold (Dieterich 1981, Okubo 1989):

        mu(v, theta) = mu_0 + a ln(1 + v / v_1) + b ln(1 + v_2 theta / d_c),   Y = mu p,

    with the state theta (a time: the age of the contacts) following the aging law
    d theta/dt = 1 - v theta / d_c, integrated by backward Euler over the step,

        theta = (theta_bar + dt) / (1 + lambda / d_c)     (v = lambda / dt).

    At rest theta grows with the time of contact (healing: the static coefficient rises
    with log time); sliding renews it over the slip d_c. In steady sliding
    (theta = d_c / v, v_1 << v << v_2) mu = const + (a - b) ln v: velocity weakening for
    b > a, strengthening for a > b. State: one variable per node, theta, starting at theta_0."""

    c_T: float
    mu_0: float
    a: float
    b: float
    d_c: float
    v_1: float = 1e-6
    v_2: float = 1e3
    theta_0: float = 1.0

    n_state = 1

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu_0", self.mu_0, 0.0)
        require("a", self.a, 0.0)
        require("b", self.b, 0.0)
        require("d_c", self.d_c, 0.0, low_open=True)
        require("v_1", self.v_1, 0.0, low_open=True)
        require("v_2", self.v_2, 0.0, low_open=True)
        require("theta_0", self.theta_0, 0.0)

    def initial_state(self, n):
        return np.full((n, 1), float(self.theta_0))

    def evolve(self, z_bar, p, lam, dt):
        lam = np.asarray(lam, dtype=float)
        th_bar = np.asarray(z_bar, dtype=float)[:, 0]
        den = 1.0 + lam / self.d_c
        th = (th_bar + dt) / den
        return th[:, None], np.zeros_like(th)[:, None], (-th / den / self.d_c)[:, None]

    def slip_bound(self, p, q, v, z):
        p, v = np.asarray(p, dtype=float), np.asarray(v, dtype=float)
        th = np.asarray(z, dtype=float)[:, 0]
        r = self.v_2 * th / self.d_c
        mu = self.mu_0 + self.a * np.log1p(v / self.v_1) + self.b * np.log1p(r)
        dmu_dv = self.a / (self.v_1 + v)
        dmu_dth = self.b * self.v_2 / self.d_c / (1.0 + r)
        return mu * p, mu + 0.0 * p, 0.0 * p, dmu_dv * p, (dmu_dth * p)[:, None]


@dataclass(frozen=True)
class ArchardWear:
    """Coulomb friction (eq 11) with Archard wear: sliding over a slip lambda at pressure
    p wears the surface by the depth k_w p lambda,

        w = w_bar + k_w p lambda,     Y = mu p,

    and the worn surface recedes: the gap grows by w (``gap_offset``). The contact moves
    the surface by the committed wear, so the wear of a step acts from the next step on
    (explicit in the wear, which is small in a step; the friction itself is implicit).
    k_w is the dimensional wear coefficient (Archard's K / hardness), units L^2/F.
    State: the worn depth w, one variable per node, starting at 0."""

    c_T: float
    mu: float
    k_w: float

    n_state = 1

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu", self.mu, 0.0)
        require("k_w", self.k_w, 0.0)

    def evolve(self, z_bar, p, lam, dt):
        p, lam = np.asarray(p, dtype=float), np.asarray(lam, dtype=float)
        w = np.asarray(z_bar, dtype=float)[:, 0] + self.k_w * p * lam
        return w[:, None], (self.k_w * lam)[:, None], (self.k_w * p)[:, None]

    def gap_offset(self, z):
        return np.asarray(z, dtype=float)[:, 0]

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        return self.mu * p, self.mu + 0.0 * p, 0.0 * p
