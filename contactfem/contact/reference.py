"""A reference for students: the node-to-segment contact of ONE pair, in the paper's symbols.

One slave node s against one master segment 1-2 (deformable or rigid), or against a smooth
rigid circle, written line by line after Wriggers, Vu Van & Stein (1990), Secs 3.2 and 4.2,
in plain Python and numpy on small vectors (2, 6, 6x6): no arrays over pairs, no broadcasting.
Each line cites the equation it writes. It is for two things: reading the method beside the
paper, and checking the vectorised code (contact/kinematics.py, contact/masters.py,
contact/element.py, laws/return_map.py), which tests/test_reference.py compares with it to
round-off. The solver does not use this module.

Conventions (as in the vectorised code):
- the gap g_N >= 0 is open, g_N < 0 penetration; the signed normal traction t_N <= 0 in
  contact is the work conjugate of g_N; dt_N = dt_N/dg_N >= 0.
- n = e_3 x t: the tangent turned by +90 degrees, to the left of the travel 1 -> 2.
- a pair's six unknowns v_c = (v_s, v_1, v_2), ordered (s_x, s_y, 1_x, 1_y, 2_x, 2_y) (eq 24).
- bar: the last converged state. The arc coordinate of the projection is s = S_bar + alpha l_bar
  (S_bar: converged arc length up to node 1), so the slip increment Delta g_T = s - s_bar is
  (alpha - alpha_bar) l_bar on one segment (eq 20); delta g_T is the variation of s.
- w: the slave's weight (tributary length, or 1 for nodal laws) turning tractions into forces.
"""

import math

import numpy as np

from ..laws.return_map import OPEN, SLIP, STICK


def pair_geometry(x_s, x_1, x_2):
    """Eqs (17)-(19): length l, unit tangent t, normal n, gap g_N and natural coordinate alpha."""
    x_s, x_1, x_2 = (np.asarray(x, dtype=float) for x in (x_s, x_1, x_2))
    l = math.hypot(x_2[0] - x_1[0], x_2[1] - x_1[1])  # eq (18): l = ||x_2 - x_1||
    t = (x_2 - x_1) / l  # eq (18)
    n = np.array([-t[1], t[0]])  # eq (18): n = e_3 x t
    g_N = (x_s - x_1) @ n  # eq (17)
    alpha = (x_s - x_1) @ t / l  # eq (19)
    return l, t, n, g_N, alpha


def pair_vectors(t, n, alpha):
    """Eqs (25)-(26): the 6-vectors N_s, N_0, T_s, T_0 of one pair."""
    zero = np.zeros(2)
    N_s = np.concatenate([n, -(1.0 - alpha) * n, -alpha * n])  # eq (25)
    N_0 = np.concatenate([zero, -n, n])  # eq (25)
    T_s = np.concatenate([t, -(1.0 - alpha) * t, -alpha * t])  # eq (26)
    T_0 = np.concatenate([zero, -t, t])  # eq (26)
    return N_s, N_0, T_s, T_0


def pair_variations(x_s, x_1, x_2, l_bar=None, S_bar=0.0):
    """First and second variations of g_N and g_T for one pair, as 6-vectors and 6x6
    matrices: eq (27) (delta g_N, delta g_T), eqs (31)-(32) (Delta delta g_N), eqs (35)-(36)
    (A) and (37)-(38) (B; Delta delta g_T = l_bar Delta delta alpha). Also the arc coordinate
    s = S_bar + alpha l_bar (eq 20). l_bar = None: the converged length is the current one."""
    l, t, n, g_N, alpha = pair_geometry(x_s, x_1, x_2)
    l_bar = l if l_bar is None else l_bar
    N_s, N_0, T_s, T_0 = pair_vectors(t, n, alpha)
    a = T_s + (g_N / l) * N_0  # the bracket of eq (27)
    dg_N = N_s  # eq (27): delta g_N = N_s . delta v_c
    dg_T = (l_bar / l) * a  # eq (27): delta g_T = (l_bar/l)(T_s + g_N/l N_0) . delta v_c
    d2g_N = -(
        (np.outer(N_0, T_s) + np.outer(T_s, N_0)) / l + (g_N / l**2) * np.outer(N_0, N_0)
    )  # eqs (31)-(32): Delta delta g_N = dv^T d2g_N Dv
    A = np.outer(a, a)  # eq (36); eq (35): Delta g_T delta g_T = dv^T (l_bar/l)^2 A Dv
    B = (
        (np.outer(N_s, N_0) + np.outer(N_0, N_s))
        - (np.outer(T_s, T_0) + np.outer(T_0, T_s))
        - 2.0 * (g_N / l) * (np.outer(N_0, T_0) + np.outer(T_0, N_0))
    )  # eq (38)
    d2g_T = (l_bar / l**2) * B  # eq (37): Delta delta alpha = dv^T (B / l^2) Dv, times l_bar
    return dict(
        l=l,
        l_bar=l_bar,
        t=t,
        n=n,
        g_N=g_N,
        alpha=alpha,
        s=S_bar + alpha * l_bar,
        N_s=N_s,
        N_0=N_0,
        T_s=T_s,
        T_0=T_0,
        A=A,
        B=B,
        dg_N=dg_N,
        dg_T=dg_T,
        d2g_N=d2g_N,
        d2g_T=d2g_T,
    )


def slave_rows(v):
    """A rigid master: v_1 = v_2 = 0, so only the slave rows (and columns) remain, the first
    two of the ordering (s_x, s_y, 1_x, 1_y, 2_x, 2_y). Its metric does not change: l_bar = l."""
    return v[:2] if v.ndim == 1 else v[:2, :2]


def rigid_segment(x_s, x_1, x_2, S=0.0):
    """A slave against a fixed segment 1-2 (RigidLine, RigidPolyline, a line of RigidComposite):
    eqs (17)-(19), (27), (31)-(32), (37)-(38) with l_bar = l, reduced to the slave's two dofs."""
    v = pair_variations(x_s, x_1, x_2, l_bar=None, S_bar=S)
    return dict(v, **{k: slave_rows(v[k]) for k in ("dg_N", "dg_T", "d2g_N", "d2g_T")})


def arc_pair(x_s, center, R, sigma, theta_ref, theta_0=0.0, direction=1.0, S=0.0):
    """A slave against a fixed circle of radius R about `center` (RigidArc, the arcs of
    RigidComposite): gap, arc coordinate and their first and second derivatives w.r.t. x_s.

    sigma = +1: the slave is outside the circle (a cylinder), -1: inside (a hole, a fillet).
    s = S + direction R (theta - theta_0): the length travelled along the circle from angle
    theta_0, direction = +1 counter-clockwise, -1 clockwise. theta is taken within pi of
    theta_ref (the angle has no jump near the slave). Replaces eqs (17), (20), (27) for a
    curved master; a rigid master has only the slave's dofs."""
    # Polar coordinates about the centre c: d = x_s - c, r = |d|, e_r = d / r,
    # e_theta = e_3 x e_r, theta = atan2(d_y, d_x). Then, for a change dx of x_s:
    #   r^2 = d.d           gives  dr = e_r . dx                           (grad r = e_r)
    #   dx along e_theta turns d by |dx| / r:  dtheta = e_theta . dx / r     (grad theta = e_theta / r)
    #   d(e_r) = e_theta dtheta, d(e_theta) = -e_r dtheta, d(1/r) = -e_r . dx / r^2, so
    #   Hess r     = d(e_r)/dx          = e_theta e_theta^T / r = (I - e_r e_r^T) / r
    #   Hess theta = d(e_theta / r)/dx  = -(e_r e_theta^T + e_theta e_r^T) / r^2      (symmetric)
    # The closest point of the circle is c + R e_r, so g_N = sigma (r - R) (normal sigma e_r),
    # and the projection's arc coordinate is s = S + direction R (theta - theta_0).
    d = np.asarray(x_s, dtype=float) - np.asarray(center, dtype=float)
    r = math.hypot(d[0], d[1])
    e_r = d / r
    e_th = np.array([-e_r[1], e_r[0]])
    theta = theta_ref + math.remainder(math.atan2(d[1], d[0]) - theta_ref, 2.0 * math.pi)
    hess_r = (np.eye(2) - np.outer(e_r, e_r)) / r
    hess_th = -(np.outer(e_r, e_th) + np.outer(e_th, e_r)) / r**2
    return dict(
        g_N=sigma * (r - R),
        dg_N=sigma * e_r,
        d2g_N=sigma * hess_r,
        s=S + direction * R * (theta - theta_0),
        dg_T=direction * R * e_th / r,
        d2g_T=direction * R * hess_th,
        r=r,
        theta=theta,
    )


def power_law(g_N, c_N, m=1.0):
    """Eq (4), |t_N| = c_N |g_N|^m while g_N < 0, signed: t_N = -c_N (-g_N)^m and
    dt_N/dg_N = c_N m (-g_N)^(m-1); both 0 when open (m = 1: the penalty method)."""
    if g_N >= 0.0:
        return 0.0, 0.0
    return -c_N * (-g_N) ** m, c_N * m * (-g_N) ** (m - 1.0)


def return_map(c_T, alpha, beta, n, t_N, dt_N, Dg_T, t_T_bar):
    """Eqs (40)-(48), the paper's plain return map for one node, for the slip surface of
    eq (10), Y = alpha |t_N|^n + beta |t_N| (Coulomb, eq 11: n = 1, alpha + beta = mu), with
    constant alpha, beta (no hardening, no rate): eq (44) in closed form.

    Returns t_T, the consistent moduli c_T_s = dt_T/dg_T and c_N_s = dt_T/dg_N (eqs 47-48;
    c_T and 0 while sticking), the slip multiplier lam, which makes the slip increment
    Delta g_T^s = lam sign(t_T) with Delta g_N^s = 0 (eqs 41, 45), and the state (OPEN,
    STICK, SLIP)."""
    if not t_N < 0.0:  # open: no traction, nothing to integrate
        return dict(t_T=0.0, c_T_s=0.0, c_N_s=0.0, lam=0.0, state=OPEN)
    p = -t_N  # |t_N|
    Y = alpha * p**n + beta * p  # eq (10): f = ||t_T|| - Y
    t_tr = t_T_bar + c_T * Dg_T  # eq (42): elastic predictor (t_T = c_T g_T^e, eq 5)
    f_tr = abs(t_tr) - Y  # eq (40): f(t_N, t_tr)
    if f_tr <= 0.0:  # stick: the trial is the answer, dt_T/dg_T = c_T (eq 39)
        return dict(t_T=t_tr, c_T_s=c_T, c_N_s=0.0, lam=0.0, state=STICK)
    sign = 1.0 if t_tr > 0.0 else -1.0
    lam = (abs(t_tr) - Y) / c_T  # eq (44): f(t_N, t_T) = |t_tr| - c_T lam - Y = 0, for lam
    t_T = t_tr - c_T * lam * sign  # eq (43): t_T = t_tr - c_T lam sign(t_tr) = Y sign(t_tr)
    # eqs (41), (45): the slip Delta g_T^s = lam sign(t_T), Delta g_N^s = 0 (non-associated, eq 14).
    # eqs (46)-(48): t_T = sign(t_tr) Y(|t_N|) on the slip surface; sign(t_tr) is fixed near a slipping
    # state, so t_T does not change with Delta g_T, and changes with g_N through |t_N| = -t_N(g_N):
    c_T_s = 0.0  # eq (47): dt_T/dg_T = c_T dY/dlam / (c_T + dY/dlam), dY/dlam = 0
    dY_dp = alpha * n * p ** (n - 1.0) + beta  # dY/d|t_N| (unbounded at first touch when n < 1)
    c_N_s = sign * dY_dp * (-dt_N)  # eq (48): sign(t_tr) dY/d|t_N| d|t_N|/dg_N (= -dt_N)
    return dict(t_T=t_T, c_T_s=c_T_s, c_N_s=c_N_s, lam=lam, state=SLIP)


def closing_step(g_bar, g_N, s, s_bar, dg_N, dg_T):
    """Not in the paper (the toolkit's choice, see contact/interface.py): a node open at the
    start of the step (g_bar > 0) and in contact at its end touched at the fraction
    theta = g_bar / (g_bar - g_N) of the step; its stick spring starts there, so the slip
    increment of eq (20) is scaled by r = 1 - theta = -g_N / (g_bar - g_N):
        Delta g_T = r (s - s_bar),   its variation  r delta s + (s - s_bar) dr/dg_N delta g_N.
    Returns (Delta g_T, its variation); r = 1 (eq 20 as printed) when the node was closed."""
    if not (g_bar > 0.0 and g_N < 0.0):
        return s - s_bar, dg_T
    r = -g_N / (g_bar - g_N)
    dr = -g_bar / (g_bar - g_N) ** 2  # dr/dg_N
    return r * (s - s_bar), r * dg_T + (s - s_bar) * dr * dg_N


def segment_element(v, w, t_N, dt_N, fr, ddg_T=None, rigid=False):
    """R_c (eq 28) and K = K_N + K_T (eqs 33, 39, 49-50) of one slave on one segment, in the
    paper's matrices: v from pair_variations, fr from return_map. 6 and 6x6 for a deformable
    master; rigid=True keeps the slave rows (2 and 2x2). K is the linearisation of the
    virtual work t_N delta g_N + t_T delta g_T: eq (30) for the normal part gives eq (33),
    eq (34) for the tangential part while sticking gives eq (39), eq (46) while slipping,
    with Delta t_T = c_T^s Delta g_T + c_N^s Delta g_N (eqs 47-48), gives eq (49).

    ddg_T: the variation of the slip increment when it is not delta g_T (closing_step); the
    c_T term (l_bar/l)^2 A = delta g_T delta g_T^T then reads (l_bar/l) a ddg_T^T."""
    l, l_bar, g_N = v["l"], v["l_bar"], v["g_N"]
    N_s, N_0, T_s, A, B = v["N_s"], v["N_0"], v["T_s"], v["A"], v["B"]
    t_T, c_T_s, c_N_s = fr["t_T"], fr["c_T_s"], fr["c_N_s"]
    a = T_s + (g_N / l) * N_0
    R_c, K = np.zeros(6), np.zeros((6, 6))
    if fr["state"] != OPEN:
        R_c = t_N * N_s + t_T * (l_bar / l) * a  # eq (28)
        K_N = dt_N * np.outer(N_s, N_s) - t_N * (
            (np.outer(N_0, T_s) + np.outer(T_s, N_0)) / l + (g_N / l**2) * np.outer(N_0, N_0)
        )  # eq (33)
        if ddg_T is not None and len(ddg_T) == 2:  # a rigid master's slave rows
            ddg_T = np.concatenate([ddg_T, np.zeros(4)])
        AA = (l_bar / l) ** 2 * A if ddg_T is None else (l_bar / l) * np.outer(a, ddg_T)
        if fr["state"] == STICK:
            c_T = c_T_s  # return_map gives c_T^s = c_T
            K_T = c_T * AA + t_T * (l_bar / l**2) * B  # eq (39)
        else:
            C = (l_bar / l) * np.outer(a, N_s)  # eq (50), non-symmetric
            K_T = c_T_s * AA + t_T * (l_bar / l**2) * B + c_N_s * C  # eq (49)
        K = K_N + K_T
    R_c, K = w * R_c, w * K
    return (slave_rows(R_c), slave_rows(K)) if rigid else (R_c, K)


def obstacle_element(k, w, t_N, dt_N, fr, ddg_T=None):
    """Eqs (28), (33), (39), (49)-(50) for a slave on a smooth rigid obstacle, written with
    the obstacle's variations k (arc_pair) in place of N_s, A, B, C: delta g_N -> N_s,
    delta g_T delta g_T^T -> (l_bar/l)^2 A, Delta delta g_T -> (l_bar/l^2) B,
    delta g_T delta g_N^T -> C."""
    dg_N, d2g_N, dg_T, d2g_T = k["dg_N"], k["d2g_N"], k["dg_T"], k["d2g_T"]
    ddg_T = dg_T if ddg_T is None else ddg_T
    if fr["state"] == OPEN:
        return np.zeros(2), np.zeros((2, 2))
    R_c = t_N * dg_N + fr["t_T"] * dg_T  # eq (28)
    K_N = dt_N * np.outer(dg_N, dg_N) + t_N * d2g_N  # eq (33)
    K_T = fr["c_T_s"] * np.outer(dg_T, ddg_T) + fr["t_T"] * d2g_T  # eq (39)
    if fr["state"] == SLIP:
        K_T = K_T + fr["c_N_s"] * np.outer(dg_T, dg_N)  # eqs (49)-(50)
    return w * R_c, w * (K_N + K_T)
