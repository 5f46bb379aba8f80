"""check_law: verify a student's interface law the way the test suite verifies ours.

    >>> from contactfem import check_law
    >>> print(check_law(MyFriction(c_T=30.0, mu=0.3)))
    >>> print(check_law(MyFriction(c_T=30.0, mu=0.3), p_max=500.0, dt=0.01))   # a scene's range

A friction law is checked first as a function (the protocol of
contactfem.laws.protocol; finite values and Y >= 0 over the whole range of pressures,
slips and slip rates; every derivative against finite differences, each wrong one
named), then through the return mapping (eqs 40-48) over a grid of pressures,
accumulated slips, states and slip increments in both directions; a normal law through
its traction, its derivative and its energy. The report says, in words, what holds and
what does not, and which derivatives the law supplied and which were computed.

``preflight`` is what ``contactfem run`` (and ``run_scene``) checks of a law object
before solving, over the range the scene declares (Scene.law_range): a value no law may
return, or a block the friction cannot hold, refuses the run (LawError); a derivative
that disagrees with finite differences is a warning."""

from dataclasses import dataclass, field

import numpy as np

from .normal import PowerLaw
from .protocol import FrictionLaw, LawError, LawValueError, NormalLawView, explain_call_error
from .return_map import SLIP, STICK, return_map


@dataclass
class LawReport:
    """What check_law found: ``checks``, a list of (ok, sentence); ``ok`` if all hold.
    ``errors``: the failed checks a run would stop on (the protocol, values no law may
    return); ``warnings``: the other failed checks (derivatives, the return mapping)."""

    law: object
    checks: list = field(default_factory=list)  # (ok, sentence)
    fatal: set = field(default_factory=set)  # indices of checks a run would stop on

    @property
    def ok(self):
        return all(ok for ok, _ in self.checks)

    @property
    def errors(self):
        return [s for i, (ok, s) in enumerate(self.checks) if not ok and i in self.fatal]

    @property
    def warnings(self):
        return [s for i, (ok, s) in enumerate(self.checks) if not ok and i not in self.fatal]

    def add(self, ok, good, bad, fatal=False):
        if fatal:
            self.fatal.add(len(self.checks))
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
    checks = [
        ("dY/dp", Y_p, p, lambda x: L.slip_bound(x, q, v, z)[0]),
        ("dY/dq", Y_q, q, lambda x: L.slip_bound(p, x, v, z)[0]),
    ]
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
        noise = 100 * np.finfo(float).eps * (np.abs(fun(x)) + np.max(np.abs(Y))) / h  # round-off of the differences
        err = np.maximum(np.abs(an - fd) - noise, 0.0) / (np.abs(fd) + np.abs(an) + 1e-300)
        err = np.where(ok_pts, err, 0.0)
        i = int(np.argmax(err))
        if err[i] >= rtol:
            how = "computed by complex step" if name in L.computed else "returned by the law"
            hint = (
                (
                    " -- the complex step needs slip_bound to be complex-analytic: np.abs, np.sign, np.maximum,"
                    " comparisons and np.where on the argument break it (use np.sqrt(x * x) for |x|, or return"
                    " the derivative yourself)"
                )
                if name in L.computed
                else ""
            )
            rep.add(
                False,
                "",
                f"{name} does not match finite differences: worst relative error {err[i]:.2e} at "
                f"{_where(where, i)} ({how}: {an[i]:.6g}, finite differences: {fd[i]:.6g}){hint}",
            )
        else:
            good.append(name)
            worst_all = max(worst_all, float(err[i]))
    if good:
        verb = "agrees" if len(good) == 1 else "agree"
        rep.add(
            True,
            f"{', '.join(good)} {verb} with finite differences (worst relative error beyond round-off {worst_all:.1e})",
            "",
        )


def _grid(p_max, q_max, v_max, rate, n_p=31):
    """The values sweep: p = 0 and n_p pressures over 9 decades up to p_max, each with
    accumulated slips 0 ... q_max and (for a rate law) slip rates 0 ... v_max."""
    p = np.concatenate([[0.0], np.geomspace(1e-8 * p_max, p_max, n_p)])
    q = np.array([0.0, 1e-3, 0.1, 1.0]) * q_max
    v = np.array([0.0, 1e-3, 0.03, 1.0]) * v_max if rate else np.zeros(1)
    P, Q, V = (a.ravel() for a in np.meshgrid(p, q, v, indexing="ij"))
    return P, Q, V


def _states(L, p, q_max, dt, rng):
    """States a run reaches: the initial state, and the initial state advanced by slips up to q_max."""
    n = len(p)
    z = L.initial_state(n)
    if L.n_state:
        z1 = L.evolve(z, p, rng.uniform(0.0, 1.0, n) * q_max, dt)[0]
        z = np.where((np.arange(n) % 3 == 0)[:, None], z, z1)
    return z


def _values(rep, L, p_max, q_max, v_max, dt):
    """Finite values and Y >= 0 everywhere in the range (the guards of the protocol,
    also for a shipped law); False if a check failed."""
    P, Q, V = _grid(p_max, q_max, v_max, L.rate)
    try:
        Z = _states(L, P, q_max, dt, np.random.default_rng(1))
        out = L.slip_bound(P, Q, V, Z)
        L._guard_slip_bound([P, Q, V, Z], out)  # (a shipped law's adapter does not guard)
    except LawError as err:
        rep.add(False, "", str(err), fatal=True)
        return False
    rng = f"p in [0, {p_max:.3g}], q in [0, {q_max:.3g}]" + (f", v in [0, {v_max:.3g}]" if L.rate else "")
    rep.add(True, f"slip bound Y and its derivatives are finite and Y >= 0 for {rng}", "", fatal=True)
    return True


def check_friction_law(law, normal=None, scale=1.0, rtol=1e-5, dt=1.0, p_max=None, q_max=None, v_max=None):
    """check_law for a friction law (see check_law for the keywords)."""
    with np.errstate(all="ignore"):  # the report says what is wrong; no numpy warnings
        return _check_friction_law(law, normal, scale, rtol, dt, p_max, q_max, v_max)


def _check_friction_law(law, normal, scale, rtol, dt, p_max, q_max, v_max):
    rep = LawReport(law)
    try:
        L = FrictionLaw(law)
    except LawError as err:
        rep.add(False, "", str(err), fatal=True)
        return rep
    L.trusted = False  # check a shipped law like any other
    rep.add(True, f"stick stiffness c_T = {L.c_T:g} > 0", "", fatal=True)
    p_max = 1e4 * scale if p_max is None else float(p_max)
    q_max = 10.0 * scale if q_max is None else float(q_max)
    v_max = 10.0 * scale / dt if v_max is None else float(v_max)
    if not _values(rep, L, p_max, q_max, v_max, dt):
        return rep
    normal = normal or PowerLaw(c_N=10.0 * scale, m=1.0)

    # derivatives and return mapping: 40 points spread over the range (5 pressures x 8)
    p = np.repeat(np.geomspace(1e-6, 1.0, 5) * p_max, 8)
    n = len(p)
    t_N = -p
    try:  # a normal stiffness dt_N/dg_N for the modulus dt_T/dg_N (any positive one serves)
        dt_N = np.abs(NormalLawView(normal).traction(-p / (10.0 * scale))[1])
    except LawError:
        dt_N = np.zeros(n)
    dt_N = np.where(np.isfinite(dt_N) & (dt_N > 0), dt_N, 10.0 * scale)
    q_bar = np.tile(np.array([0.0, 0.0, 0.01, 0.01, 0.1, 0.1, 0.03, 0.03]) * q_max, 5)
    t_bar = np.tile(np.array([0.0, 0.5, -0.5, 0.2, 0.0, -0.1, 0.4, 0.0]), 5)
    rng = np.random.default_rng(1)
    v = np.tile(np.array([0.0, 1e-4, 1e-3, 0.01, 0.1, 0.003, 0.03, 0.3]), 5) * v_max
    lam = v * dt
    try:
        z_bar = _states(L, p, 0.05 * q_max, dt, rng)
        z = L.evolve(z_bar, p, lam, dt)[0]
        L.slip_bound(p, q_bar, v, z)
    except LawError as err:
        rep.add(False, "", str(err), fatal=True)
        return rep
    if L.supplied or L.computed:
        sup = ", ".join(sorted(L.supplied)) or "none"
        comp = ", ".join(sorted(L.computed)) or "none"
        rep.add(True, f"derivatives supplied by the law: {sup}; computed by complex step: {comp}", "")
    try:
        _check_derivatives(rep, L, p, q_bar, v, z, lam, dt, rtol)
    except LawError as err:
        rep.add(False, "", str(err), fatal=True)
        return rep
    if not rep.ok:
        return rep

    c_T = L.c_T
    z0 = L.evolve(z_bar, p, 0.0 * p, dt)[0]
    Y0 = L.slip_bound(p, q_bar, 0.0 * p, z0)[0]
    t_bar = t_bar * Y0  # start inside the slip surface
    worst_f, worst_tan, min_diss, states = 0.0, 0.0, np.inf, set()

    def rm(t_N, dt_N, dg):
        return return_map(L, t_N, dt_N, dg, t_bar, q_bar, z_bar=z_bar, dt=dt)

    try:
        # the slip increment that reaches Y0, at most the range's slip (a soft c_T would ask for more)
        size = np.minimum((Y0 + 1e-3 * Y0.max() + 1e-300) / c_T, q_max / 3.0)
        for dg in np.array([1e-4, -1e-4, 0.05, -0.05, 0.5, -0.5, 3.0, -3.0])[:, None] * size:
            fr = rm(t_N, dt_N, dg)
            states |= set(np.unique(fr.state).tolist())
            Y = L.slip_bound(p, fr.q, fr.v, fr.z)[0]
            f = np.abs(fr.t_T) - Y
            scale_f = np.maximum(1.0, Y)  # the return map's tolerance: 1e-12 max(1, |t_tr|)
            slip = fr.state == SLIP
            stick = fr.state == STICK
            if np.any(slip):
                worst_f = max(worst_f, np.max(np.abs(f[slip]) / scale_f[slip]))
                t_tr = t_bar + c_T * dg
                moving = slip & (np.abs(fr.t_T) > 1e-12 * scale_f)
                if not np.all(np.sign(fr.t_T[moving]) == np.sign(t_tr[moving])):
                    rep.add(False, "", "slip traction points against the trial traction")
            if np.any(stick):
                worst_f = max(worst_f, np.max(np.maximum(f[stick], 0.0) / scale_f[stick]))
            min_diss = min(min_diss, float(np.min(fr.dissipation)))
            # tangents by central differences in the slip increment and in the gap
            h_g = 1e-7 * (np.abs(dg) + (np.abs(t_bar) + Y0) / c_T)  # round-off: relative to t_T, not dg
            d_T_fd = _fd(lambda x: rm(t_N, dt_N, x).t_T, dg, h_g)
            h_p = 1e-7 * p
            d_N_fd = _fd(lambda x: rm(-x, dt_N, dg).t_T, p, h_p) * -dt_N  # dt_T/dg_N = dt_T/dp dp/dg_N
            # skip points where the finite difference straddles the stick/slip kink
            same = np.ones(n, bool)
            for a, b in ((dg + h_g, p), (dg - h_g, p), (dg, p + h_p), (dg, p - h_p)):
                same &= rm(-b, dt_N, a).state == fr.state
            for an, fd in ((fr.c_T_s, d_T_fd), (fr.c_N_s, d_N_fd)):
                rel = np.abs(an - fd) / (np.abs(fd) + np.abs(an) + 1e-3 * c_T)
                worst_tan = max(worst_tan, float(np.max(np.where(same, rel, 0.0))))
    except LawValueError as err:  # a value no law may return, within the range
        rep.add(False, "", str(err), fatal=True)
        return rep
    except (LawError, FloatingPointError, ValueError) as err:
        rep.add(False, "", f"the return mapping fails with this law: {err}")
        return rep
    rep.add(
        worst_f < 1e-8,
        f"the return mapping lands on the slip surface when slipping and stays inside when sticking (worst |f|/Y = "
        f"{worst_f:.1e})",
        f"the return mapping misses the slip surface: worst |f|/Y = {worst_f:.2e} (should be < 1e-8)",
    )
    rep.add(
        min_diss >= -1e-12,
        "dissipation lambda |t_T| >= 0 in every slip step",
        f"negative dissipation {min_diss:.3e}: the slip works against the traction",
    )
    rep.add(
        worst_tan < rtol,
        f"the moduli dt_T/dg_T and dt_T/dg_N match finite differences (worst relative error {worst_tan:.1e})",
        f"the moduli do not match finite differences: worst relative error {worst_tan:.2e} (needs < {rtol:g})",
    )
    rep.add(
        {STICK, SLIP} <= states,
        "both stick and slip were exercised",
        "the test grid never produced both stick and slip: is the slip bound sensible?",
    )
    return rep


def check_normal_law(law, scale=1.0, rtol=1e-6, g_max=None):
    """check_law for a normal law (see check_law for the keywords)."""
    rep = LawReport(law)
    g_max = scale if g_max is None else float(g_max)
    with np.errstate(all="ignore"):
        try:
            N = NormalLawView(law)
        except LawError as err:
            rep.add(False, "", str(err), fatal=True)
            return rep
        N.trusted = False  # check a shipped law's values too
        try:
            g_open = g_max * np.array([1e-9, 1e-6, 0.1, 1.0])
            t_o, d_o = N.traction(g_open)
            g = -g_max * np.geomspace(1e-9, 1.0, 37)
            t_N, dt_N = N.traction(g)
        except LawError as err:
            rep.add(False, "", str(err), fatal=True)
            return rep
        rep.add(
            True, f"traction and stiffness are finite, t_N <= 0, for g_N in [{-g_max:.3g}, {g_max:.3g}]", "", fatal=True
        )
        rep.add(
            np.all(t_o == 0) and np.all(d_o == 0),
            "no traction and no stiffness while the gap is open (g_N > 0)",
            "the law gives a traction or stiffness for an open gap g_N > 0",
        )
        rep.add(
            np.all(t_N < 0),
            "contact traction is compressive (t_N < 0 for g_N < 0)",
            "the contact traction must be negative (compressive) when g_N < 0, it is zero somewhere",
        )
        rep.add(
            np.all(dt_N >= 0),
            "stiffness dt_N/dg_N >= 0 (more penetration, more pressure)",
            "dt_N/dg_N must be non-negative",
        )
        gs = g[g < -1e-4 * g_max]
        h = 1e-7 * np.abs(gs)
        try:  # relative errors, with a floor of 1e-9 of the largest value (round-off near g_N = 0)
            ts, ds = N.traction(gs)
            fd = (N.traction(gs + h)[0] - N.traction(gs - h)[0]) / (2 * h)
            rel = np.abs(fd - ds) / (np.abs(ds) + np.abs(fd) + 1e-9 * np.max(np.abs(ds)) + 1e-300)
            i = int(np.argmax(rel))
            rep.add(
                rel[i] < 1e-5,
                f"dt_N/dg_N matches finite differences (worst relative error {rel[i]:.1e})",
                f"dt_N/dg_N does not match finite differences: worst relative error {rel[i]:.2e} at g_N = "
                f"{gs[i]:.3g} (returned {ds[i]:.6g}, finite differences {fd[i]:.6g})",
            )
            if not N.has_energy:
                rep.add(True, "no energy(g_N) (only contact_integration = energy_consistent needs the potential)", "")
            else:
                W0 = N.energy(np.zeros(1))[0]
                hW = 1e-4 * np.abs(gs)  # a wider step: an energy is often a difference of larger terms
                fdW = (N.energy(gs + hW) - N.energy(gs - hW)) / (2 * hW)
                errW = np.abs(fdW - ts) / (np.abs(ts) + np.abs(fdW) + 1e-9 * np.max(np.abs(ts)) + 1e-300)
                j = int(np.argmax(errW))
                rep.add(
                    errW[j] < 1e-5 and W0 == 0.0,
                    f"energy W(0) = 0 and dW/dg_N = t_N (worst relative error {errW[j]:.1e})",
                    f"energy: W(0) = {W0:.3g} must be 0 and dW/dg_N = t_N: worst relative error {errW[j]:.2e} at "
                    f"g_N = {gs[j]:.3g} (t_N {ts[j]:.6g}, finite differences of W {fdW[j]:.6g})",
                )
        except LawError as err:
            rep.add(False, "", str(err), fatal=True)
    return rep


def check_law(law, **kw):
    """Check a normal law (has ``traction``) or a friction law (has ``slip_bound``); returns a
    LawReport (print it: one line per check, what holds and what does not).

    Keywords (all optional):

    ``scale``  the size of the law's arguments, default 1: the default ranges below scale with it.
    ``p_max``  friction: the largest pressure p = |t_N| checked (default 1e4 scale). Set it to
               the largest pressure your run meets (``contactfem run`` uses the scene's range):
               values are checked from 0 over 9 decades up to p_max.
    ``q_max``  friction: the largest accumulated slip q (default 10 scale).
    ``v_max``  friction: the largest slip rate v (default 10 scale / dt); rate laws only.
    ``dt``     friction: the time step of the return mapping (default 1): sets the slip rates
               v = lambda / dt of a rate law and the step of a law with internal variables.
    ``normal`` friction: the normal law whose stiffness dt_N/dg_N enters the modulus dt_T/dg_N
               of the return mapping (default PowerLaw(c_N=10 scale)).
    ``rtol``   the relative tolerance of the derivatives against finite differences (default
               1e-5 for a friction law, 1e-6 for a normal law).
    ``g_max``  normal: the deepest penetration checked, g_N in [-g_max, 0) (default scale).
    """
    if hasattr(law, "slip_bound"):
        return check_friction_law(law, **kw)
    if hasattr(law, "traction"):
        return check_normal_law(law, **kw)
    raise TypeError(
        f"check_law: {type(law).__name__} is not a law: a normal law has traction(g_N), "
        "a friction law c_T and slip_bound(p, q)"
    )


# -- pre-flight: what a run checks of a law object before solving --------------------------


def _concave_envelope(x, y, x0):
    """The least concave majorant of the samples (x, y) (x increasing) at x0."""
    hull = []
    for pt in zip(x, y):
        while len(hull) >= 2:
            (x1, y1), (x2, y2) = hull[-2], hull[-1]
            if (x2 - x1) * (pt[1] - y1) - (y2 - y1) * (pt[0] - x1) >= 0:  # hull[-1] below the chord
                hull.pop()
            else:
                break
        hull.append(pt)
    hx, hy = np.array(hull).T
    return float(np.interp(x0, hx, hy))


def hold_capacity(L, T, N, L_c, w_min, q_max, v_max, dt):
    """An upper bound of the tangential force sum w_i Y(p_i) an interface of total weight
    (contact length) L_c can carry when its pressures balance the normal load N,
    sum w_i p_i = N, p_i >= 0, each w_i >= w_min: L_c Yc(N / L_c), with Yc the least concave
    majorant of the largest Y over the slips and rates of the range, on [0, N / w_min]
    (Jensen's inequality). From samples: 4001 pressures, linear and geometric."""
    P = N / w_min
    p = np.unique(np.concatenate([np.linspace(0.0, P, 2001), np.geomspace(1e-9 * P, P, 2000)]))
    q = np.array([0.0, 0.01, 0.1, 1.0]) * q_max
    v = np.array([0.0, 1e-3, 0.03, 1.0]) * v_max if L.rate else np.zeros(1)
    pp, qq, vv = (a.ravel() for a in np.meshgrid(p, q, v, indexing="ij"))
    z = _states(L, pp, q_max, dt, np.random.default_rng(2))
    Y = L.slip_bound(pp, qq, vv, z)[0].reshape(len(p), -1).max(axis=1)
    return L_c * _concave_envelope(p, Y, N / L_c)


# margin of the hold check: the concave majorant is taken from samples (4001 pressures), so a
# law with structure finer than the sampling could hold a little more than the bound says;
# 1 % covers the sampling error of a smooth law (its chords over a spacing of N / w_min / 2000).
HOLD_MARGIN = 0.01


# the range of a scene that declares none (Scene.law_range): check_law's own defaults at scale 1
DEFAULT_RANGE = dict(p=1e4, q=10.0, v=10.0, dt=1.0, g=1.0)


def preflight(friction=None, normal=None, p=1.0, q=1.0, v=1.0, dt=1.0, g=1.0, hold=None):
    """Check law objects over a scene's range (Scene.law_range: the largest pressure p, slip
    q, slip rate v, the time step dt, the deepest penetration g, and for a body held by
    friction alone ``hold`` = dict(T, N, L, w_min)) before a run. Raises LawError (one line)
    for a value no law may return there (NaN or inf, Y < 0, t_N > 0 in contact), a law that
    breaks the protocol, or a hold the friction law cannot carry; returns warnings (one line
    each) for derivatives that disagree with finite differences. A shipped law is checked
    only for the hold (its values are exact by construction)."""
    warnings = []
    with np.errstate(all="ignore"):
        if normal is not None:
            N = NormalLawView(normal)
            if not N.trusted:
                rep = check_normal_law(normal, g_max=g)
                if rep.errors:
                    raise LawError(f"normal law {rep.errors[0]}")
                warnings += [f"normal law {type(normal).__name__}: {s}" for s in rep.warnings]
        if friction is not None:
            L = FrictionLaw(friction)
            if not L.trusted:
                rep = check_friction_law(friction, normal=normal, dt=dt, p_max=p, q_max=q, v_max=v)
                if rep.errors:
                    raise LawError(f"friction law {rep.errors[0]}")
                warnings += [
                    f"friction law {type(friction).__name__}: {s}"
                    for s in rep.warnings
                    if "both stick and slip" not in s
                ]
            if hold is not None:
                try:
                    cap = hold_capacity(L, hold["T"], hold["N"], hold["L"], hold["w_min"], q, v, dt)
                except LawError as err:
                    raise LawError(f"friction law {err}") from None
                if hold["T"] > cap * (1.0 + HOLD_MARGIN):
                    raise LawError(
                        f"no static equilibrium: the tangential load {hold['T']:.4g} exceeds the largest "
                        f"friction force {cap:.4g} the friction law {L.name} can carry under the normal load "
                        f"{hold['N']:.4g}; lower the tangential load or raise the friction"
                    )
    return warnings


__all__ = [
    "LawReport",
    "check_law",
    "check_friction_law",
    "check_normal_law",
    "preflight",
    "DEFAULT_RANGE",
    "hold_capacity",
    "explain_call_error",
]
