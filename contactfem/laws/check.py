"""check_law: verify a student's interface law the way the test suite verifies ours.

    >>> from contactfem import check_law
    >>> print(check_law(MyFriction(c_T=30.0, mu=0.3)))

A friction law is checked first as a function (the protocol of
contactfem.laws.protocol, finite values, every derivative against finite differences,
each wrong one named), then through the return mapping (eqs 40-48) over a grid of
pressures, accumulated slips, states and slip increments in both directions; a normal
law through its traction and derivative. The report says, in words, what holds and
what does not, and which derivatives the law supplied and which were computed."""

from dataclasses import dataclass, field

import numpy as np

from .return_map import SLIP, STICK, return_map
from .normal import PowerLaw
from .protocol import FrictionLaw, LawError, explain_call_error


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


def _fd_nonneg(fun, x, h):
    """d fun / dx by central differences, one-sided (second order) where x - h would
    leave x >= 0 (the arguments p, q, v, lambda and most states are non-negative);
    also whether the point straddles a kink (forward and backward slopes disagree)."""
    f0 = fun(x)
    one_sided = (x >= 0.0) & (x - h < 0.0)
    xm = np.where(one_sided, x, x - h)
    fp, fm = fun(x + h), fun(xm)
    f2 = fun(x + 2 * h)
    central = (fp - fm) / np.where(one_sided, h, 2 * h)
    forward2 = (-3 * f0 + 4 * fp - f2) / (2 * h)
    d = np.where(one_sided, forward2, central)
    fwd, bwd = (fp - f0) / h, np.where(one_sided, (f2 - fp) / h, (f0 - fm) / h)
    noise = 100 * np.finfo(float).eps * (np.abs(f0) + np.abs(fp)) / h
    kink = np.abs(fwd - bwd) > 1e-3 * (np.abs(fwd) + np.abs(bwd)) + noise
    return d, kink


def _where(points, i):
    return ", ".join(f"{k} = {v[i]:.3g}" for k, v in points.items())


def _check_derivatives(rep, L, p, q, v, z, lam, dt, rtol):
    """Each derivative of Y (and of the state evolution) against finite differences;
    one sentence per wrong derivative, naming it."""
    Y, Y_p, Y_q, Y_v, Y_z = L.slip_bound(p, q, v, z)
    where = {"p": p, "q": q, "v": v} if L.rate else {"p": p, "q": q}
    checks = [("dY/dp", Y_p, p, lambda x: L.slip_bound(x, q, v, z)[0]),
              ("dY/dq", Y_q, q, lambda x: L.slip_bound(p, x, v, z)[0])]
    if L.arity >= 3:
        checks.append(("dY/dv", Y_v, v, lambda x: L.slip_bound(p, q, x, z)[0]))
    if L.arity >= 4:
        for c in range(L.n_state):
            def f(x, c=c):
                zz = z.copy()
                zz[:, c] = x
                return L.slip_bound(p, q, v, zz)[0]
            checks.append((f"dY/dz[{c}]" if L.n_state > 1 else "dY/dz", Y_z[:, c], z[:, c], f))
    if L.n_state and hasattr(L.law, "evolve"):
        zb = z
        _, z_p, z_lam = L.evolve(zb, p, lam, dt)
        for c in range(L.n_state):
            sfx = f"[{c}]" if L.n_state > 1 else ""
            checks.append((f"dz{sfx}/dp", z_p[:, c], p, lambda x, c=c: L.evolve(zb, x, lam, dt)[0][:, c]))
            checks.append((f"dz{sfx}/dlam", z_lam[:, c], lam, lambda x, c=c: L.evolve(zb, p, x, dt)[0][:, c]))
    good, worst_all = [], 0.0
    for name, an, x, fun in checks:
        xs = np.max(np.abs(x), initial=0.0)
        h = 1e-6 * np.maximum(np.abs(x), 1e-2 * xs if xs > 0 else 1.0)
        fd, kink = _fd_nonneg(fun, x, h)
        ok_pts = ~kink & np.isfinite(fd)
        noise = 100 * np.finfo(float).eps * (np.abs(fun(x)) + np.max(np.abs(Y))) / h    # round-off of the differences
        err = np.maximum(np.abs(an - fd) - noise, 0.0) / (np.abs(fd) + np.abs(an) + 1e-300)
        err = np.where(ok_pts, err, 0.0)
        i = int(np.argmax(err))
        if err[i] >= rtol:
            how = "computed by complex step" if name in L.computed else "returned by the law"
            rep.add(False, "", f"{name} does not match finite differences: worst relative error {err[i]:.2e} at "
                               f"{_where(where, i)} ({how}: {an[i]:.6g}, finite differences: {fd[i]:.6g})")
        else:
            good.append(name)
            worst_all = max(worst_all, float(err[i]))
    if good:
        verb = "agrees" if len(good) == 1 else "agree"
        rep.add(True, f"{', '.join(good)} {verb} with finite differences (worst relative error beyond round-off {worst_all:.1e})", "")


def check_friction_law(law, normal=None, scale=1.0, rtol=1e-5, dt=1.0):
    with np.errstate(all="ignore"):       # the report says what is wrong; no numpy warnings
        return _check_friction_law(law, normal, scale, rtol, dt)


def _check_friction_law(law, normal, scale, rtol, dt):
    """Check a friction law: the protocol, the slip bound and every derivative (against
    finite differences), then the return mapping over a grid of pressures, accumulated
    slips, states and slip increments in both directions: on the slip surface, dissipation
    >= 0, the moduli against finite differences. ``dt``: the time step of the return
    mapping (sets the slip rates v = lambda/dt for a rate-dependent law)."""
    rep = LawReport(law)
    try:
        L = FrictionLaw(law)
    except LawError as err:
        rep.add(False, "", str(err))
        return rep
    c_T = L.c_T
    rep.add(c_T > 0 and np.isfinite(c_T), f"stick stiffness c_T = {c_T:g} > 0",
            f"stick stiffness c_T = {c_T!r} must be a positive number")
    if not (c_T > 0 and np.isfinite(c_T)):
        return rep
    normal = normal or PowerLaw(c_N=10.0 * scale, m=1.0)

    g_N = -scale * np.repeat(np.array([1e-3, 0.01, 0.1, 0.5, 1.0]), 8)
    n = len(g_N)
    q_bar = np.tile(np.array([0.0, 0.0, 0.1, 0.1, 1.0, 1.0, 0.3, 0.3]) * scale, 5)
    t_bar = np.tile(np.array([0.0, 0.5, -0.5, 0.2, 0.0, -0.1, 0.4, 0.0]), 5)
    t_N, dt_N = normal.traction(g_N)
    p = -t_N
    rng = np.random.default_rng(1)
    v = np.tile(np.array([0.0, 1e-3, 0.01, 0.1, 1.0, 0.03, 0.3, 3.0]), 5) * scale / dt
    lam = v * dt
    try:
        z_bar = L.initial_state(n)
        if L.n_state:   # states a run reaches: the initial state advanced by a few slips
            z_bar = L.evolve(z_bar, p, rng.uniform(0.0, 0.5, n) * scale, dt)[0]
            z_bar[::3] = L.initial_state(n)[::3]
        z = L.evolve(z_bar, p, lam, dt)[0]
        Y, *ders = L.slip_bound(p, q_bar, v, z)
    except LawError as err:
        rep.add(False, "", str(err))
        return rep
    bad = [name for name, d in zip(["Y", "dY/dp", "dY/dq", "dY/dv", "dY/dz"], [Y] + ders) if not np.all(np.isfinite(d))]
    if bad:
        i = int(np.argmax(~np.all(np.isfinite(np.column_stack([Y] + [d.reshape(n, -1) for d in ders])), axis=1)))
        rep.add(False, "", f"slip_bound returns NaN or inf ({', '.join(bad)}) at p = {p[i]:.3g}, q = {q_bar[i]:.3g}"
                           + (f", v = {v[i]:.3g}" if L.rate else ""))
        return rep
    rep.add(np.all(Y >= 0), "slip bound Y is finite and >= 0", "slip bound Y must be non-negative")
    if L.supplied or L.computed:
        sup = ", ".join(sorted(L.supplied)) or "none"
        comp = ", ".join(sorted(L.computed)) or "none"
        rep.add(True, f"derivatives supplied by the law: {sup}; computed by complex step: {comp}", "")
    _check_derivatives(rep, L, p, q_bar, v, z, lam, dt, rtol)
    if not rep.ok:
        return rep

    z0 = L.evolve(z_bar, p, 0.0 * p, dt)[0]
    Y0 = L.slip_bound(p, q_bar, 0.0 * p, z0)[0]
    t_bar = t_bar * Y0   # start inside the slip surface
    worst_f, worst_tan, min_diss, states = 0.0, 0.0, np.inf, set()

    def rm(t_N, dt_N, dg):
        return return_map(L, t_N, dt_N, dg, t_bar, q_bar, z_bar=z_bar, dt=dt)

    try:
        for dg in np.array([1e-4, -1e-4, 0.05, -0.05, 0.5, -0.5, 3.0, -3.0]) * (Y0.max() + 1.0) / c_T:
            fr = rm(t_N, dt_N, dg)
            states |= set(np.unique(fr.state).tolist())
            Y = L.slip_bound(p, fr.q, fr.v, fr.z)[0]
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
            d_T_fd = _fd(lambda x: rm(t_N, dt_N, x).t_T, dg, h_g)
            h_N = 1e-7 * scale
            d_N_fd = _fd(lambda x: rm(*normal.traction(x), dg).t_T, g_N, h_N)
            # skip points where the finite difference straddles the stick/slip kink
            same = np.ones(len(g_N), bool)
            for a, b in ((dg + h_g, g_N), (dg - h_g, g_N), (dg, g_N + h_N), (dg, g_N - h_N)):
                same &= rm(*normal.traction(b), a).state == fr.state
            for an, fd in ((fr.c_T_s, d_T_fd), (fr.c_N_s, d_N_fd)):
                err = np.abs(an - fd) / (np.abs(fd) + np.abs(an) + 1e-3 * c_T)
                worst_tan = max(worst_tan, float(np.max(np.where(same, err, 0.0))))
    except (LawError, FloatingPointError, ValueError) as err:
        rep.add(False, "", f"the return mapping fails with this law: {err}")
        return rep
    rep.add(worst_f < 1e-8, f"the return mapping lands on the slip surface when slipping and stays inside when sticking (worst |f|/Y = {worst_f:.1e})",
            f"the return mapping misses the slip surface: worst |f|/Y = {worst_f:.2e} (should be < 1e-8)")
    rep.add(min_diss >= -1e-12, "dissipation lambda |t_T| >= 0 in every slip step",
            f"negative dissipation {min_diss:.3e}: the slip works against the traction")
    rep.add(worst_tan < rtol, f"the moduli dt_T/dg_T and dt_T/dg_N match finite differences (worst relative error {worst_tan:.1e})",
            f"the moduli do not match finite differences: worst relative error {worst_tan:.2e} (needs < {rtol:g})")
    rep.add({STICK, SLIP} <= states, "both stick and slip were exercised",
            "the test grid never produced both stick and slip: is the slip bound sensible?")
    return rep


def _traction(law, g):
    """(t_N, dt_N) of a normal law at gaps g, or LawError with one sentence."""
    try:
        out = law.traction(g)
    except Exception as err:                   # noqa: BLE001 (a student's law may raise anything)
        raise LawError(explain_call_error(f"{type(law).__name__}.traction", err)) from None
    if not (isinstance(out, (tuple, list)) and len(out) == 2):
        got = f"{len(out)} values" if isinstance(out, (tuple, list)) else "one value"
        raise LawError(f"{type(law).__name__}.traction(g_N) returned {got}: it must return the two values "
                       "(t_N, dt_N/dg_N)")
    return tuple(np.array(np.broadcast_to(np.asarray(a, dtype=float), g.shape)) for a in out)


def check_normal_law(law, scale=1.0, rtol=1e-6):
    """Check a normal law: no traction when open, compressive and monotone in
    contact, derivative matching finite differences."""
    rep = LawReport(law)
    with np.errstate(all="ignore"):
        try:
            g_open = scale * np.array([1e-6, 0.1, 1.0])
            t_o, d_o = _traction(law, g_open)
            g = -scale * np.geomspace(1e-4, 1.0, 25)
            t_N, dt_N = _traction(law, g)
            h = 1e-7 * np.abs(g)
            fd = (_traction(law, g + h)[0] - _traction(law, g - h)[0]) / (2 * h)
        except (LawError, ValueError) as err:
            rep.add(False, "", str(err))
            return rep
    rep.add(np.all(t_o == 0) and np.all(d_o == 0), "no traction and no stiffness while the gap is open (g_N > 0)",
            "the law gives a traction or stiffness for an open gap g_N > 0")
    finite = np.all(np.isfinite(t_N)) and np.all(np.isfinite(dt_N))
    rep.add(finite, "traction and stiffness are finite", "traction or stiffness is NaN or infinite")
    if not finite:
        return rep
    rep.add(np.all(t_N < 0), "contact traction is compressive (t_N < 0 for g_N < 0)",
            "the contact traction must be negative (compressive) when g_N < 0")
    rep.add(np.all(dt_N >= 0), "stiffness dt_N/dg_N >= 0 (more penetration, more pressure)",
            "dt_N/dg_N must be non-negative")
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
    raise TypeError(f"check_law: {type(law).__name__} is not a law: a normal law has traction(g_N), "
                    "a friction law c_T and slip_bound(p, q)")
