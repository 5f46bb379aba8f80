# dY/dq without the pressure.
# expect: dY/dq
@dataclass(frozen=True)
class LinearHardening:
    c_T: float
    mu_0: float
    h: float

    def slip_bound(self, p, q):
        p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
        mu = self.mu_0 + self.h * q
        return mu * p, mu + 0.0 * p, self.h + 0.0 * p
