"""check_law: verify a student's interface law the way the test suite verifies ours.

    >>> from contactfem import check_law
    >>> print(check_law(MyFriction(c_T=30.0, mu=0.3)))

A friction law is checked through the return mapping (eqs 40-48) over a grid of
pressures, accumulated slips and slip increments in both directions; a normal law
through its traction and derivative. The report says, in words, what holds and
what does not."""

from dataclasses import dataclass, field

import numpy as np

from .return_map import SLIP, STICK, return_map
from .normal import PowerLaw


@dataclass
class LawReport:
    law: object
    checks: list = field(default_factory=list)   # (ok, sentence)

    @property
    def ok(self):
        return all(ok for ok, _ in self.checks)

    def add(self, ok, good, bad):
        self.checks.append((bool(ok), good if ok else bad))

    def __str__(self):
        head = f"check_law({self.law!r}): " + ("all checks pass" if self.ok else "SOME CHECKS FAIL")
        return "\n".join([head] + [("  [ok]   " if ok else "  [FAIL] ") + s for ok, s in self.checks])

    def __bool__(self):
        return self.ok


def _fd(fun, x, h):
    return (fun(x + h) - fun(x - h)) / (2 * h)


def check_friction_law(law, normal=None, scale=1.0, rtol=1e-5):
    """Check a friction law (c_T, slip_bound) through the return mapping."""
    rep = LawReport(law)
    normal = normal or PowerLaw(c_N=10.0 * scale, m=1.0)
    c_T = float(law.c_T)
    rep.add(c_T > 0, f"stick stiffness c_T = {c_T:g} > 0", f"stick stiffness c_T = {c_T!r} must be positive")
    if not c_T > 0:
        return rep

    g_N = -scale * np.repeat(np.array([1e-3, 0.01, 0.1, 0.5, 1.0]), 8)
    q_bar = np.tile(np.array([0.0, 0.0, 0.1, 0.1, 1.0, 1.0, 0.3, 0.3]) * scale, 5)
    t_bar = np.tile(np.array([0.0, 0.5, -0.5, 0.2, 0.0, -0.1, 0.4, 0.0]), 5)
    t_N, dt_N = normal.traction(g_N)
    p = -t_N
    Y0, _, _ = law.slip_bound(p, q_bar)
    rep.add(np.all(np.isfinite(Y0)) and np.all(Y0 >= 0), "slip bound Y(p, q) is finite and >= 0",
            "slip bound Y(p, q) must be finite and non-negative")
    t_bar = t_bar * Y0   # start inside the slip surface
    worst_f, worst_tan, min_diss, states = 0.0, 0.0, np.inf, set()
    for dg in np.array([1e-4, -1e-4, 0.05, -0.05, 0.5, -0.5, 3.0, -3.0]) * (Y0.max() + 1.0) / c_T:
        fr = return_map(law, t_N, dt_N, dg, t_bar, q_bar)
        states |= set(np.unique(fr.state).tolist())
        Y, _, _ = law.slip_bound(p, fr.q)
        f = np.abs(fr.t_T) - Y
        scale_f = np.maximum(1.0, Y)
        slip = fr.state == SLIP
        stick = fr.state == STICK
        if np.any(slip):
            worst_f = max(worst_f, np.max(np.abs(f[slip]) / scale_f[slip]))
            t_tr = t_bar + c_T * dg
            moving = slip & (np.abs(fr.t_T) > 1e-12 * scale_f)
            if not np.all(np.sign(fr.t_T[moving]) == np.sign(t_tr[moving])):
                rep.add(False, "", f"slip traction points against the trial traction (slip increment {dg:+.3g})")
        if np.any(stick):
            worst_f = max(worst_f, np.max(np.maximum(f[stick], 0.0) / scale_f[stick]))
        min_diss = min(min_diss, float(np.min(fr.dissipation)))
        # tangents by central differences in the slip increment and in the gap
        h_g = 1e-7 * (Y0.max() + 1.0) / c_T
        d_T_fd = _fd(lambda x: return_map(law, t_N, dt_N, x, t_bar, q_bar).t_T, dg, h_g)
        h_N = 1e-7 * scale
        d_N_fd = _fd(lambda x: return_map(law, *normal.traction(x), dg, t_bar, q_bar).t_T, g_N, h_N)
        # skip points where the finite difference straddles the stick/slip kink
        same = np.ones(len(g_N), bool)
        for a, b in ((dg + h_g, g_N), (dg - h_g, g_N), (dg, g_N + h_N), (dg, g_N - h_N)):
            same &= return_map(law, *normal.traction(b), a, t_bar, q_bar).state == fr.state
        for an, fd in ((fr.c_T_s, d_T_fd), (fr.c_N_s, d_N_fd)):
            err = np.abs(an - fd) / (np.abs(fd) + np.abs(an) + 1e-3 * c_T)
            worst_tan = max(worst_tan, float(np.max(np.where(same, err, 0.0))))
    rep.add(worst_f < 1e-8, f"the return mapping lands on the slip surface when slipping and stays inside when sticking (worst |f|/Y = {worst_f:.1e})",
            f"the return mapping misses the slip surface: worst |f|/Y = {worst_f:.2e} (should be < 1e-8)")
    rep.add(min_diss >= -1e-12, "dissipation lambda |t_T| >= 0 in every slip step",
            f"negative dissipation {min_diss:.3e}: the slip works against the traction")
    rep.add(worst_tan < rtol, f"the moduli dt_T/dg_T and dt_T/dg_N match finite differences (worst relative error {worst_tan:.1e})",
            f"the moduli do not match finite differences: worst relative error {worst_tan:.2e} (needs < {rtol:g}); "
            "check dY/dp and dY/dq returned by slip_bound")
    rep.add({STICK, SLIP} <= states, "both stick and slip were exercised",
            "the test grid never produced both stick and slip: is the slip bound sensible?")
    return rep


def check_normal_law(law, scale=1.0, rtol=1e-6):
    """Check a normal law: no traction when open, compressive and monotone in
    contact, derivative matching finite differences."""
    rep = LawReport(law)
    g_open = scale * np.array([1e-6, 0.1, 1.0])
    t_o, d_o = law.traction(g_open)
    rep.add(np.all(t_o == 0) and np.all(d_o == 0), "no traction and no stiffness while the gap is open (g_N > 0)",
            "the law gives a traction or stiffness for an open gap g_N > 0")
    g = -scale * np.geomspace(1e-4, 1.0, 25)
    t_N, dt_N = law.traction(g)
    rep.add(np.all(np.isfinite(t_N)) and np.all(np.isfinite(dt_N)), "traction and stiffness are finite",
            "traction or stiffness is NaN or infinite")
    rep.add(np.all(t_N < 0), "contact traction is compressive (t_N < 0 for g_N < 0)",
            "the contact traction must be negative (compressive) when g_N < 0")
    rep.add(np.all(dt_N >= 0), "stiffness dt_N/dg_N >= 0 (more penetration, more pressure)",
            "dt_N/dg_N must be non-negative")
    h = 1e-7 * np.abs(g)
    fd = (law.traction(g + h)[0] - law.traction(g - h)[0]) / (2 * h)
    err = float(np.max(np.abs(fd - dt_N) / np.maximum(np.abs(dt_N), 1e-12)))
    rep.add(err < 1e-5, f"dt_N/dg_N matches finite differences (worst relative error {err:.1e})",
            f"dt_N/dg_N does not match finite differences: worst relative error {err:.2e}")
    return rep


def check_law(law, **kw):
    """Check a normal law (has `traction`) or a friction law (has `slip_bound`)."""
    if hasattr(law, "slip_bound"):
        return check_friction_law(law, **kw)
    if hasattr(law, "traction"):
        return check_normal_law(law, **kw)
    raise TypeError("check_law: a law needs traction(g_N) (normal law) or c_T and slip_bound(p, q) (friction law)")
