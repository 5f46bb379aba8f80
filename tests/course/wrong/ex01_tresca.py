# Coulomb written instead of Tresca: the bound grows with the pressure.
# expect: grows with the pressure
from dataclasses import dataclass


@dataclass(frozen=True)
class Tresca:
    c_T: float
    tau_y: float

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        return self.tau_y * p, self.tau_y + 0.0 * p, 0.0 * p
