"""Normal interface laws (paper Sec. 2.1).

Sign convention (NOTES.md): the gap g_N >= 0 is open, g_N < 0 is penetration
("approach"). The signed normal traction t_N is the work conjugate of g_N: it is
negative in contact and zero when open. A normal law gives, vectorised over
contact nodes,

    t_N(g_N)   and   dt_N/dg_N,

the only two things the contact element needs (eqs 28 and 33).
"""

from dataclasses import dataclass

import numpy as np

from .validation import require


@dataclass(frozen=True)
class PowerLaw:
    """Eq (4): |t_N| = c_N |g_N|^m for g_N < 0.  m = 1 is the penalty method (Remark 2.1);
    m = 2 .. 3.3 describes rough metal surfaces (Kragelski)."""

    c_N: float
    m: float = 1.0

    def __post_init__(self):
        require("c_N", self.c_N, 0.0, low_open=True)
        require("m", self.m, 1.0)

    def traction(self, g_N):
        """Return (t_N, dt_N/dg_N); t_N = -c_N (-g_N)^m in contact, 0 when open."""
        g_N = np.asarray(g_N, dtype=float)
        closed = g_N < 0.0
        a = np.where(closed, -g_N, 0.0)  # approach, >= 0
        if self.m == 1.0:  # the penalty: a**1 = a and a**0 = 1, the same numbers without powers
            return -self.c_N * a, np.where(closed, self.c_N * 1.0, 0.0)
        t_N = -self.c_N * a**self.m
        dt_N = np.where(closed, self.c_N * self.m * a ** (self.m - 1.0), 0.0)
        return t_N, dt_N

    def energy(self, g_N):
        """Stored interface energy c_N (-g_N)^(m+1) / (m+1) (its derivative is t_N)."""
        a = np.where(np.asarray(g_N) < 0.0, -np.asarray(g_N), 0.0)
        return self.c_N * a ** (self.m + 1.0) / (self.m + 1.0)


@dataclass(frozen=True)
class ExponentialLaw:
    """The exponential law for high pressures (paper Sec. 2.1.2, ref [12]):
    |t_N| = a exp(b |g_N|).  As printed it jumps to a at first touch; we use the
    shifted form |t_N| = a (exp(b |g_N|) - 1), which vanishes at g_N = 0 and has the
    same growth (our choice, so that contact starts without a jump)."""

    a: float
    b: float

    def __post_init__(self):
        require("a", self.a, 0.0, low_open=True)
        require("b", self.b, 0.0, low_open=True)

    def traction(self, g_N):
        g_N = np.asarray(g_N, dtype=float)
        ap = np.where(g_N < 0.0, -g_N, 0.0)
        e = np.exp(np.minimum(self.b * ap, 700.0))  # no overflow to inf
        t_N = -self.a * (e - 1.0)
        dt_N = np.where(g_N < 0.0, self.a * self.b * e, 0.0)
        return t_N, dt_N

    def energy(self, g_N):
        ap = np.where(np.asarray(g_N) < 0.0, -np.asarray(g_N), 0.0)
        return self.a * ((np.exp(np.minimum(self.b * ap, 700.0)) - 1.0) / self.b - ap)
