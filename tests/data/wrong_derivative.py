"""Coulomb's law with its derivative dY/dp off by 10 %: it runs, Newton converges more
slowly, and the check before the run names the derivative."""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WrongSlope:
    c_T: float = 1e4
    mu: float = 0.4

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        return self.mu * p, 1.1 * self.mu + 0 * p, 0 * p
