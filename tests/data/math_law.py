import math
from dataclasses import dataclass


@dataclass(frozen=True)
class MathTanh:
    c_T: float = 30.0
    mu: float = 0.3

    def slip_bound(self, p, q):
        th = math.tanh(p)
        return self.mu * th, self.mu * (1 - th**2), 0.0
