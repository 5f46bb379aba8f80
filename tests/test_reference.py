"""The vectorised contact equals contact/reference.py, the paper's formulas written one pair at
a time: masters' locate (g_N, s and their first and second variations), segment_variations,
PowerLaw, return_map (t_T, c_T^s, c_N^s, lambda, state) and contact_element (R and K), to
1e-12 relative, over random states of every master, both laws (Coulomb, ParabolicSlip with
n = 1 and n < 1), stick and slip of both signs, with and without the closing step. The
reference's own tangent is checked against finite differences of its residual.

"Relative" is in the norm of each compared quantity of one pair: |vectorised - reference|
<= 1e-12 |reference|, about 4500 machine epsilons. Both sides sum the same terms in other
orders, so they agree to a few ulps of the largest term; the states keep g_N, s and t_T away
from zero, so no compared quantity is a cancellation of terms more than ~100 times larger
(the worst, the gap of a slave 1 % of a segment deep, differed by 2e-14 relative when
this was written). Each stage is fed the reference's inputs (see the first test).
"""

import math

import numpy as np
import pytest
from conftest import PointCloud
from fd import rel_error

from contactfem.contact import reference as ref
from contactfem.contact.element import contact_element
from contactfem.contact.kinematics import segment_variations
from contactfem.contact.masters import BodySurface, RigidArc, RigidComposite, RigidLine, RigidPolyline
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.laws.return_map import OPEN, SLIP, STICK, return_map

TOL = 1e-12
NC = 12  # states per case: 6 masters x 3 laws x 2 (closing or not), 432 states
REGIMES = ("stick", "slip+", "slip-")


def close(a, b, what):
    err, size = np.linalg.norm(np.asarray(a) - np.asarray(b)), np.linalg.norm(b)
    assert err <= TOL * size, f"{what}: |vectorised - reference| = {err:.3e}, |reference| = {size:.3e}"


def make_law(name, rng):
    """The vectorised law and its parameters (c_T, alpha, beta, n) for reference.return_map."""
    c_T = rng.uniform(50.0, 500.0)
    if name == "coulomb":
        mu = rng.uniform(0.1, 0.6)
        return Coulomb(c_T, mu), (c_T, mu, 0.0, 1.0)  # eq (11): n = 1, alpha + beta = mu
    a, b = rng.uniform(0.05, 0.4), rng.uniform(0.05, 0.4)
    n = 1.0 if name == "parabolic n=1" else rng.uniform(0.4, 0.9)
    return ParabolicSlip(c_T, a, b, n), (c_T, a, b, n)


# -- masters: each builder returns (master, x_s (NC, 2), u, seg, s0, pairs); pairs[i](dx, s_bar)
# gives the reference kinematics of state i (its pair dofs moved by dx: 6 for a deformable
# master; a rigid one reads the first 2) and its element; s0: an s_bar for a first look (the arc unwraps
# theta near s_bar / R). Slaves lie at 20-80 % of a segment or piece, 1-8 % of its length deep.


def _unit(phi):
    return np.array([math.cos(phi), math.sin(phi)])


def _segment_pairs(x_s, P, Pbar, j, rigid):
    def pair(i):
        a, b, lb = P[j[i]], P[j[i] + 1], np.linalg.norm(Pbar[j[i] + 1] - Pbar[j[i]])
        Sb = np.sum(np.linalg.norm(np.diff(Pbar[: j[i] + 1], axis=0), axis=1))

        def kin(dx, s_bar):
            if rigid:
                k = ref.rigid_segment(x_s[i] + dx[:2], a, b, S=Sb)
            else:
                k = ref.pair_variations(x_s[i] + dx[:2], a + dx[2:4], b + dx[4:], l_bar=lb, S_bar=Sb)
            return k, lambda w, t_N, dt_N, fr, ddg_T=None: ref.segment_element(k, w, t_N, dt_N, fr, ddg_T, rigid)

        return kin

    return [pair(i) for i in range(len(x_s))]


def _on_chain(rng, P, nc):
    j = rng.integers(0, len(P) - 1, nc)
    a, b = P[j], P[j + 1]
    n = np.stack([a[:, 1] - b[:, 1], b[:, 0] - a[:, 0]], axis=1)  # e3 x (b - a), length l
    x_s = a + rng.uniform(0.2, 0.8, (nc, 1)) * (b - a) - rng.uniform(0.01, 0.08, (nc, 1)) * n
    return x_s, j


def line(rng, nc):
    n = _unit(rng.uniform(-math.pi, math.pi))
    t, point = np.array([n[1], -n[0]]), rng.normal(size=2)  # e3 x t = n
    f = rng.choice([-1, 1], nc) * rng.uniform(0.3, 2.0, nc)  # s = f, away from 0
    x_s = point + f[:, None] * t - rng.uniform(0.01, 0.08, (nc, 1)) * n
    P = np.array([point, point + t])
    return RigidLine(point, n), x_s, None, np.full(nc, -1), np.zeros(nc), _segment_pairs(x_s, P, P, [0] * nc, True)


def polyline(rng, nc):
    P = np.stack([np.arange(5.0), 0.3 * rng.standard_normal(5)], axis=1)
    x_s, j = _on_chain(rng, P, nc)
    return RigidPolyline(P), x_s, None, j, np.zeros(nc), _segment_pairs(x_s, P, P, j, True)


def body(rng, nc):
    X = np.stack([np.arange(5.0), 0.1 * rng.standard_normal(5)], axis=1)
    surface = BodySurface(PointCloud(X, "master"), np.arange(5))
    u_bar = 0.05 * rng.standard_normal(10)
    surface.ref = surface.reference(u_bar)  # converged metric: l_bar != l
    u = u_bar + 0.05 * rng.standard_normal(10)
    P, Pbar = X + u.reshape(-1, 2), X + u_bar.reshape(-1, 2)
    x_s, j = _on_chain(rng, P, nc)
    return surface, x_s, u, j, np.zeros(nc), _segment_pairs(x_s, P, Pbar, j, False)


def _arc_pair(x, c, R, sigma, **kw):
    def kin(dx, s_bar):
        k = (
            ref.arc_pair(x + dx[:2], c, R, sigma, **kw)
            if "theta_ref" in kw
            else ref.arc_pair(x + dx[:2], c, R, sigma, theta_ref=s_bar / R)
        )  # RigidArc: theta near s_bar / R
        return k, lambda w, t_N, dt_N, fr, ddg_T=None: ref.obstacle_element(k, w, t_N, dt_N, fr, ddg_T)

    return kin


def arc(inside):
    def build(rng, nc):
        c, R = rng.normal(size=2), rng.uniform(0.5, 3.0)
        th = rng.choice([-1, 1], nc) * rng.uniform(0.3, 2.8, nc)  # s = R theta away from 0
        sigma = -1.0 if inside else 1.0
        x_s = c + (R + sigma * rng.uniform(-0.08, -0.01, nc) * R)[:, None] * np.stack([np.cos(th), np.sin(th)], 1)
        return (
            RigidArc(c, R, inside=inside),
            x_s,
            None,
            np.full(nc, -1),
            R * th,
            [_arc_pair(x_s[i], c, R, sigma) for i in range(nc)],
        )

    return build


def composite(rng, nc):
    """A wall, a rounded edge seen from outside (clockwise), a wall, a fillet seen from inside
    (counter-clockwise), moved by an offset; the states spread over the four pieces."""
    off = rng.normal(size=2)
    pieces = [
        ("line", (-2.0, 0.0), (0.0, 0.0)),
        ("arc", (0.0, -1.0), 1.0, math.pi / 2, 0.0),
        ("line", (1.0, -1.0), (1.0, -3.0)),
        ("arc", (2.0, -3.0), 1.0, math.pi, 1.5 * math.pi),
    ]
    S = [0.0, 2.0, 2.0 + math.pi / 2, 4.0 + math.pi / 2]
    own = np.arange(nc) % 4
    x_s, pairs = np.zeros((nc, 2)), []
    for i, p in enumerate(own):
        f, depth = rng.uniform(0.2, 0.8), rng.uniform(0.01, 0.08)
        if pieces[p][0] == "line":
            A, B = np.array(pieces[p][1]) + off, np.array(pieces[p][2]) + off
            t = (B - A) / np.linalg.norm(B - A)
            x_s[i] = A + f * (B - A) - depth * np.array([-t[1], t[0]])
            pairs.append(_composite_line(x_s[i], A, B, S[p]))
        else:
            _, cc, R, th0, th1 = pieces[p]
            cw = th1 < th0
            sigma, c = (1.0 if cw else -1.0), np.array(cc) + off
            th = th0 + f * (th1 - th0)
            x_s[i] = c + (R - sigma * depth) * _unit(th)
            pairs.append(
                _arc_pair(
                    x_s[i], c, R, sigma, theta_ref=0.5 * (th0 + th1), theta_0=th0, direction=-1.0 if cw else 1.0, S=S[p]
                )
            )
    return RigidComposite(pieces, offset=off), x_s, None, own, np.zeros(nc), pairs


def _composite_line(x, A, B, S):
    def kin(dx, s_bar):
        k = ref.rigid_segment(x + dx[:2], A, B, S=S)
        return k, lambda w, t_N, dt_N, fr, ddg_T=None: ref.segment_element(k, w, t_N, dt_N, fr, ddg_T, True)

    return kin


MASTERS = {
    "RigidLine": line,
    "RigidPolyline": polyline,
    "RigidArc outside": arc(False),
    "RigidArc inside": arc(True),
    "RigidComposite": composite,
    "BodySurface": body,
}
LAWS = ("coulomb", "parabolic n=1", "parabolic n<1")


def reference_pair(kin, dx, s_bar, c_N, m, params, t_T_bar, g_bar, w):
    """The reference chain for one pair: kinematics, normal law (eq 4), slip increment (eq 20,
    scaled on a closing step), return map (eqs 40-48), element (eqs 28, 33, 39, 49-50)."""
    k, element = kin(dx, s_bar)
    t_N, dt_N = ref.power_law(k["g_N"], c_N, m)
    Dg_T, ddg_T = ref.closing_step(g_bar, k["g_N"], k["s"], s_bar, k["dg_N"], k["dg_T"])
    fr = ref.return_map(*params, t_N, dt_N, Dg_T, t_T_bar)
    R, K = element(w, t_N, dt_N, fr, ddg_T if g_bar > 0 else None)
    return k, t_N, dt_N, fr, R, K


def case(master_name, law_name, closing):
    """NC random states of one master and law, a third each in stick, slip+ and slip-:
    the slip increment is chosen so that the trial traction t_tr = t_T_bar + c_T Delta g_T
    (eq 42) lies at 5-80 % of the slip bound Y (stick) or at 125-400 % of it (slip, of the
    given sign), at least 20 % of Y from the slip surface f = 0 (eq 40), far beyond round-off.
    closing: every node was open at the start of the step (committed gap g_bar > 0)."""
    rng = np.random.default_rng([list(MASTERS).index(master_name), LAWS.index(law_name), closing])
    master, x_s, u, seg, s0, pairs = MASTERS[master_name](rng, NC)
    law, params = make_law(law_name, rng)
    c_T, a, b, n = params
    c_N, m, w = rng.uniform(50.0, 500.0), rng.uniform(1.0, 2.5), rng.uniform(0.5, 2.0, NC)
    g_bar = rng.uniform(0.005, 0.05, NC) if closing else np.full(NC, -1.0)
    s_bar, t_T_bar, regime = np.zeros(NC), np.zeros(NC), [REGIMES[i % 3] for i in range(NC)]
    for i in range(NC):
        k, _ = pairs[i](np.zeros(6), s0[i])
        p = -ref.power_law(k["g_N"], c_N, m)[0]
        Y = a * p**n + b * p  # eq (10)
        ratio = rng.uniform(0.05, 0.8) if regime[i] == "stick" else rng.uniform(1.25, 4.0)
        sign = {"stick": rng.choice([-1.0, 1.0]), "slip+": 1.0, "slip-": -1.0}[regime[i]]
        t_T_bar[i] = rng.uniform(-0.9, 0.9) * Y
        Dg_T = (sign * ratio * Y - t_T_bar[i]) / c_T  # puts t_tr there (eq 42)
        r = -k["g_N"] / (g_bar[i] - k["g_N"]) if closing else 1.0  # closing: Delta g_T = r (s - s_bar)
        s_bar[i] = k["s"] - Dg_T / r
    return dict(
        master=master,
        x_s=x_s,
        u=u,
        seg=seg,
        pairs=pairs,
        law=law,
        params=params,
        c_N=c_N,
        m=m,
        w=w,
        g_bar=g_bar,
        s_bar=s_bar,
        t_T_bar=t_T_bar,
        regime=regime,
    )


CASES = [(mn, ln, cl) for mn in MASTERS for ln in LAWS for cl in (False, True)]
IDS = [f"{mn}-{ln}-{'closing' if cl else 'closed'}" for mn, ln, cl in CASES]


@pytest.mark.parametrize("master_name, law_name, closing", CASES, ids=IDS)
def test_vectorised_contact_equals_the_reference(master_name, law_name, closing):
    """Each vectorised stage against the reference with the same inputs (the reference's):
    locate at the states, then PowerLaw, return_map and contact_element fed with the
    reference's kinematics, tractions and moduli. (Fed with its own upstream values instead,
    a stage would inherit the round-off of Delta g_T = s - s_bar, a difference of two
    numbers larger than itself; each stage is compared where it is well conditioned.)"""
    c = case(master_name, law_name, closing)
    s_bar, t_T_bar, g_bar = c["s_bar"], c["t_T_bar"], c["g_bar"]
    k_v = c["master"].locate(c["x_s"], s_bar, c["u"], ref=getattr(c["master"], "ref", None))
    assert np.array_equal(k_v["seg"], c["seg"]) and np.all(k_v["inside"])
    refs = [
        reference_pair(
            c["pairs"][i], np.zeros(6), s_bar[i], c["c_N"], c["m"], c["params"], t_T_bar[i], g_bar[i], c["w"][i]
        )
        for i in range(NC)
    ]
    k = {key: np.array([r[0][key] for r in refs]) for key in ("g_N", "s", "dg_N", "dg_T", "d2g_N", "d2g_T")}
    t_N, dt_N, fr = np.array([r[1] for r in refs]), np.array([r[2] for r in refs]), [r[3] for r in refs]
    R, K = [r[4] for r in refs], [r[5] for r in refs]
    Dg_T, ddg_T = (
        np.array(x)
        for x in zip(
            *[
                ref.closing_step(g_bar[i], k["g_N"][i], k["s"][i], s_bar[i], k["dg_N"][i], k["dg_T"][i])
                for i in range(NC)
            ]
        )
    )
    t_N_v, dt_N_v = PowerLaw(c["c_N"], c["m"]).traction(k["g_N"])
    fr_v = return_map(c["law"], t_N, dt_N, Dg_T, t_T_bar, np.zeros(NC))
    t_T, c_T_s, c_N_s = (np.array([f[key] for f in fr]) for key in ("t_T", "c_T_s", "c_N_s"))
    R_v, K_v = contact_element(
        c["w"], t_N, dt_N, t_T, c_T_s, c_N_s, k["dg_N"], k["d2g_N"], k["dg_T"], k["d2g_T"], ddg_T if closing else None
    )
    for i in range(NC):
        tag = f"state {i} ({c['regime'][i]})"
        for mine, theirs in (
            ("g_N", "g_N"),
            ("s", "s"),
            ("dg_N", "dg_N"),
            ("ds", "dg_T"),
            ("d2g_N", "d2g_N"),
            ("d2s", "d2g_T"),
        ):
            close(k_v[mine][i], k[theirs][i], f"{tag}: locate {mine}")
        close(t_N_v[i], t_N[i], f"{tag}: t_N")
        close(dt_N_v[i], dt_N[i], f"{tag}: dt_N")
        assert fr_v.state[i] == fr[i]["state"] == (STICK if c["regime"][i] == "stick" else SLIP), tag
        if fr[i]["state"] == SLIP:
            assert np.sign(fr[i]["t_T"]) == (1.0 if c["regime"][i] == "slip+" else -1.0), tag
        for key in ("t_T", "c_T_s", "c_N_s", "lam"):
            close(getattr(fr_v, key)[i], fr[i][key], f"{tag}: return map {key}")
        close(R_v[i], R[i], f"{tag}: element R")
        close(K_v[i], K[i], f"{tag}: element K")


@pytest.mark.parametrize("master_name, law_name, closing", CASES, ids=IDS)
def test_reference_tangent_against_finite_differences(master_name, law_name, closing):
    """The reference is right on its own: its K is the Jacobian of its R (the whole chain:
    kinematics, normal law, closing step, return map, element), by central differences
    with h = 1e-6 over the pair's dofs (2 for a rigid master, 6 for a deformable one), in
    the first state of each regime. Truncation (h^2) and round-off (1e-16 / h) errors are
    below 1e-8 relative here; 1e-6 is the bound."""
    c = case(master_name, law_name, closing)
    ndof = 2 if c["master"].rigid else 6
    for i in range(3):

        def residual(dx):
            return reference_pair(
                c["pairs"][i],
                dx,
                c["s_bar"][i],
                c["c_N"],
                c["m"],
                c["params"],
                c["t_T_bar"][i],
                c["g_bar"][i],
                c["w"][i],
            )

        _, _, _, fr, R, K = residual(np.zeros(6))
        h, cols = 1e-6, []
        for j in range(ndof):
            e = np.zeros(6)
            e[j] = h
            (_, _, _, fr_p, R_p, _), (_, _, _, fr_m, R_m, _) = residual(e), residual(-e)
            assert fr_p["state"] == fr_m["state"] == fr["state"]
            cols.append((R_p - R_m) / (2 * h))
        assert rel_error(K, np.array(cols).T) < 1e-6, (i, c["regime"][i])


def test_segment_variations_equal_the_reference():
    """contact/kinematics.segment_variations (l, t, n, g_N, alpha and the variations of g_N and
    alpha) against reference.pair_variations with l_bar = 1, so that delta g_T = delta alpha:
    100 random segments of random length and direction, slaves on either side (|g_N| >= 5 %
    of l) and alpha in [0.1, 1.5] (the formulas do not need the projection on the segment)."""
    rng = np.random.default_rng(19)
    nc = 100
    x_1 = rng.normal(size=(nc, 2))
    x_2 = x_1 + rng.uniform(0.1, 5.0, (nc, 1)) * np.stack([np.cos(phi := rng.uniform(-4, 4, nc)), np.sin(phi)], 1)
    a = x_2 - x_1
    x_s = (
        x_1
        + rng.uniform(0.1, 1.5, (nc, 1)) * a
        + rng.choice([-1, 1], (nc, 1)) * rng.uniform(0.05, 0.5, (nc, 1)) * np.stack([-a[:, 1], a[:, 0]], 1)
    )
    v = segment_variations(x_s, x_1, x_2)
    for i in range(nc):
        r = ref.pair_variations(x_s[i], x_1[i], x_2[i], l_bar=1.0)
        for mine, theirs in (
            ("l", "l"),
            ("t", "t"),
            ("n", "n"),
            ("g_N", "g_N"),
            ("alpha", "alpha"),
            ("dg_N", "dg_N"),
            ("d2g_N", "d2g_N"),
            ("dalpha", "dg_T"),
            ("d2alpha", "d2g_T"),
        ):
            close(v[mine][i], r[theirs], f"segment {i}: {mine}")


@pytest.mark.parametrize("law_name", LAWS)
def test_open_nodes_carry_nothing(law_name):
    """An open node (g_N >= 0): no traction from eq (4), OPEN with zero t_T, moduli and slip
    in both return maps, a zero element."""
    rng = np.random.default_rng(7)
    law, params = make_law(law_name, rng)
    g_N = np.array([0.0, 0.01, 0.3])
    t_N_v, dt_N_v = PowerLaw(100.0, 1.5).traction(g_N)
    fr_v = return_map(law, t_N_v, dt_N_v, np.full(3, 0.2), np.full(3, 0.5), np.zeros(3))
    for i in range(3):
        t_N, dt_N = ref.power_law(g_N[i], 100.0, 1.5)
        assert (t_N, dt_N) == (t_N_v[i], dt_N_v[i]) == (0.0, 0.0)
        fr = ref.return_map(*params, t_N, dt_N, 0.2, 0.5)
        assert fr["state"] == fr_v.state[i] == OPEN
        assert fr["t_T"] == fr["c_T_s"] == fr["c_N_s"] == fr["lam"] == 0.0
        assert fr_v.t_T[i] == fr_v.c_T_s[i] == fr_v.c_N_s[i] == fr_v.lam[i] == 0.0
        v = ref.pair_variations([0.5, g_N[i]], [0.0, 0.0], [1.0, 0.0])
        R, K = ref.segment_element(v, 1.0, t_N, dt_N, fr)
        assert not R.any() and not K.any()
