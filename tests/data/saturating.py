"""A student's friction law: the coefficient saturates with pressure,
Y(p) = mu0 p0 tanh(p / p0) (Coulomb mu0 at low pressure, a cap mu0 p0 at high; the
default p0 lies above the pressures of the paper's scenes, so it runs in all of them).

    contactfem run rolling_ring --friction tests/data/saturating.py:Saturating --set law.mu0=0.6

Fields not set take the scene's parameter of the same name (c_T), else the default."""

from dataclasses import dataclass

import numpy as np

from contactfem.laws.validation import require


@dataclass(frozen=True)
class Saturating:
    c_T: float = 30.0
    mu0: float = 0.3
    p0: float = 1000.0

    def __post_init__(self):
        require("c_T", self.c_T, 0.0, low_open=True)
        require("mu0", self.mu0, 0.0)
        require("p0", self.p0, 0.0, low_open=True)

    def slip_bound(self, p, q):
        th = np.tanh(np.asarray(p) / self.p0)
        return self.mu0 * self.p0 * th, self.mu0 * (1 - th**2), 0 * th
