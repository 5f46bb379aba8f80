from dataclasses import dataclass


@dataclass(frozen=True)
class Broken:
    c_T: float = 30.0

    def slip_bound(self, p, q)
        return 0.3 * p
