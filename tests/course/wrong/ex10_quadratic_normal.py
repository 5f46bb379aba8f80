# The energy without the 1/3: its derivative is three times the traction.
# expect: off by a factor 3
@dataclass(frozen=True)
class QuadraticNormal:
    c_N: float

    def traction(self, g_N):
        g_N = np.asarray(g_N, dtype=float)
        approach = np.where(g_N < 0.0, -g_N, 0.0)
        return -self.c_N * approach**2, 2.0 * self.c_N * approach

    def energy(self, g_N):
        g_N = np.asarray(g_N, dtype=float)
        return self.c_N * np.where(g_N < 0.0, -g_N, 0.0) ** 3
