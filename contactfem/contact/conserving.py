"""Energy-consistent contact forces over a time step (the penalty interface of the paper,
integrated in time so that a frictionless impact conserves energy and friction only
dissipates, whatever the penalty and wherever in the step contact begins).

The method is Armero & Petocz (1998, "Formulation and analysis of conserving algorithms
for frictionless dynamic contact/impact problems", CMAME 158, 269-300): the penalty
stays, and the contact force of the step from u_0 to u_1 is a *discrete gradient* of the
interface potential instead of its derivative at one instant. Why this one: the paper's
interface IS a penalty potential (eq 4 with its energy c_N |g_N|^(m+1) / (m+1)), so a
discrete gradient conserves exactly the energy the toolkit already reports, for every
normal law, with nothing but the penalty's own unknowns (no multipliers, no extra solve).
Laursen & Chawla (1997) conserve energy with Lagrange multipliers and a discrete
persistency condition, Laursen & Love (2002) add a velocity update to it: both need the
contact constraint as a multiplier, which this toolkit keeps for the augmented-Lagrangian
statics (contact/augmented.py); for impacts the discrete gradient of the penalty does the
job with the element the paper already has.

Normal (per slave node, weight w):

    F_N = w phi grad_bar(g_N),   phi = (Phi(g_1) - Phi(g_0)) / (g_1 - g_0)
                                     (t_N(g_mid) when g_1 ~ g_0; Phi the law's potential),

so that F_N . (u_1 - u_0) = w (Phi(g_1) - Phi(g_0)) exactly: a node that touches at any
phase within the step gets the secant of the potential, not the end value t_N(g_1) whose
work overshoots (the energy an unresolved penalty pumps into a trapezoidal step).
grad_bar(g) is Gonzalez's discrete gradient of the gap on the pair's dofs,

    grad_bar(g) = dg(u_mid) + [(g_1 - g_0 - dg(u_mid) . d) / (w . w)] w,   d = u_1 - u_0 (pair dofs),

exact for the flat master (g linear in u: grad_bar = n) and conserving for curved and
deformable ones (grad_bar . d = g_1 - g_0). For a rigid master w = d; for a deformable one
w = P d, d without its common translation of the pair's three nodes, so that the correction
has no resultant and the pair's forces, like dg(u_mid), keep linear momentum (the gap does
not change under that translation).

Friction: the return mapping (eqs 40-44) at the end of the step gives t_T (from the
converged t_T_bar and the slip after touching, Delta s = r (s_1 - s_0), r the closing-step
factor of interface.py). The force is a mean traction tau on that slip,

    F_T = w tau r grad_bar(s),   tau = t_T - (t_T - t_T_bar)^2 / (2 c_T Delta s),

chosen so that its work w tau Delta s is the change of the stick spring's energy
t_T^2 / (2 c_T) plus w |t_T| lambda, the return map's dissipation (>= 0, lambda the slip):
in stick tau = (t_T_bar + t_T) / 2 (the trapezoidal rule), in slip a mean between that and
t_T, also when the traction reverses within the step (where (t_T_bar + t_T) / 2 can make the
dissipation negative). A node that opens during the step (t_T = 0 at the end) carries no
tangential force; its stick spring's energy t_T_bar^2 / (2 c_T) is dissipated (the slip bound
falls to zero with the pressure). So the interface stores, and friction dissipates, but
neither creates energy. A converged state's ``dissipation`` (contact/state.py) is the work
minus the change of stored energy, exactly this dissipation.

The tangents below are the exact derivatives with respect to u_1 (checked against finite
differences in tests/test_conserving.py).
"""

import numpy as np

from .element import to_coo
from .kinematics import outer


def translations(k):
    """The projection P = I - T T^T (k x k, T orthonormal) that removes the rigid translations
    of a pair of k dofs, (s_x, s_y, 1_x, 1_y, 2_x, 2_y): a deformable master's pair, whose
    gap and slip a common translation of its three nodes does not change."""
    T = np.zeros((k, 2))
    T[0::2, 0] = T[1::2, 1] = 1.0 / np.sqrt(k // 2)
    return np.eye(k) - T @ T.T


def discrete_gradient(f0, f1, df_m, df_1, d2f_m, d, P=None):
    """Gonzalez's discrete gradient of a scalar f over the step d = u_1 - u_0 (per pair):
    grad_bar = df(u_mid) + c w, w = P d, c = (f_1 - f_0 - df(u_mid) . d) / (w . w), so that
    grad_bar . d = f_1 - f_0 exactly. P (k x k, symmetric, P P = P; None: I) removes the
    directions in which f does not change (the pair's translations, ``translations``): then
    the correction c w has no resultant either, and the pair's forces keep the momentum the
    midpoint rule keeps (df(u_mid) has no resultant when f is translation invariant). Its
    derivative with respect to u_1 (w . w = d . P d, d(w . w)/du_1 = 2 w):
    D grad_bar = d2f(u_mid)/2 + w (df_1 - df_m - d2f_m d / 2)^T / (w.w) + c P - 2 c w w^T / (w.w).
    The correction is left out where w . w is at roundoff level (grad_bar = df(u_mid))."""
    k = d.shape[1]
    P = np.eye(k) if P is None else P
    w = d @ P
    ww = np.einsum("ij,ij->i", w, w)
    G = f1 - f0 - np.einsum("ij,ij->i", df_m, d)
    # the correction only where w . w and G are above rounding (a pair moving rigidly: w ~ 0, G ~ eps)
    noise = np.abs(f0) + np.abs(f1) + np.einsum("ij,ij->i", np.abs(df_m), np.abs(d))
    use = (ww > 1e-24 * (1.0 + np.abs(f0) + np.abs(f1)) ** 2) & (np.abs(G) > 1e-13 * noise)
    safe = np.where(use, ww, 1.0)
    c = np.where(use, G / safe, 0.0)
    dG = df_1 - df_m - 0.5 * np.einsum("ijk,ik->ij", d2f_m, d)
    D = (
        0.5 * d2f_m
        + np.where(use, 1.0 / safe, 0.0)[:, None, None] * outer(w, dG)
        + c[:, None, None] * (P[None] - 2.0 * outer(w, w) / safe[:, None, None])
    )
    return df_m + c[:, None] * w, D


def secant(law, g0, g1):
    """phi = (Phi(g_1) - Phi(g_0)) / (g_1 - g_0) and dphi/dg_1 for a normal law with a
    potential Phi (energy) and derivative t_N (traction); the midpoint values t_N(g_mid),
    dt_N(g_mid) / 2 where g_1 - g_0 is too small for the difference quotient."""
    dg = g1 - g0
    small = np.abs(dg) <= 1e-7 * (np.abs(g0) + np.abs(g1)) + 1e-300
    safe = np.where(small, 1.0, dg)
    P0, P1 = law.energy(g0), law.energy(g1)
    t1, dt1 = law.traction(g1)
    phi = (P1 - P0) / safe
    dphi = (t1 * dg - (P1 - P0)) / safe**2
    tm, dtm = law.traction(0.5 * (g0 + g1))
    return np.where(small, tm, phi), np.where(small, 0.5 * dtm, dphi)


def conserving_force(contact, u0, u1, t, h, e1, fr, offsets=None):
    """Residual and tangent of the energy-consistent contact force of a NodeToSegment over the
    step u0 -> u1 (module docstring), per pair: (R, K, on, work_T), with e1 and fr the
    kinematics and the return map's result at u1 and h the committed history; ``on`` marks the
    pairs that carry a force (in range at the end and penetrating at either end), ``work_T``
    the friction force's work over the step (per node)."""
    um = 0.5 * (u0 + u1)
    e0, em = contact.kinematics(u0, t, h, offsets), contact.kinematics(um, t, h, offsets)
    nc = len(contact.nodes)
    dofs = e1["dofs"]
    d = (u1 - u0)[dofs]
    w = contact.weights
    on = e1["inside"] & ((e0["g_N"] < 0.0) | (e1["g_N"] < 0.0))
    g0 = np.where(on, e0["g_N"], 1.0)
    g1 = np.where(on, e1["g_N"], 1.0)
    phi, dphi = secant(contact.normal, g0, g1)
    P = None if contact.master.rigid else translations(d.shape[1])  # a deformable master: no resultant
    gN, DgN = discrete_gradient(e0["g_N"], e1["g_N"], em["dg_N"], e1["dg_N"], em["d2g_N"], d, P)
    R = (w * phi)[:, None] * gN
    K = w[:, None, None] * (outer(gN, dphi[:, None] * e1["dg_N"]) + phi[:, None, None] * DgN)
    t_bar = h.t_T_bar
    work_T = np.zeros(nc)
    if contact.friction is not None:
        c_T = contact.c_T
        sB, DsB = discrete_gradient(e0["travel"], e1["travel"], em["ds"], e1["ds"], em["d2s"], d, P)
        r = e1["r"]
        act = e1["active"]
        t1 = np.where(act, fr["t_T"], 0.0)
        dS = r * (e1["travel"] - e0["travel"])  # slip increment after touching
        jump = t1 - t_bar
        small = np.abs(dS) <= 1e-12 * (1.0 + np.abs(e1["travel"]))
        ratio = np.where(small, 1.0, jump / (c_T * np.where(small, 1.0, dS)))  # 1 in stick
        tau = np.where(act, t1 - 0.5 * jump * ratio, 0.0)  # = t1 - (t1 - t_bar)^2 / (2 c_T dS)
        dt1 = fr["c_T_s"][:, None] * e1["ddg_T"] + fr["c_N_s"][:, None] * e1["dg_N"]
        dtau = np.where(act[:, None], (1.0 - ratio)[:, None] * dt1 + (0.5 * c_T * ratio**2)[:, None] * e1["ddg_T"], 0.0)
        dr = e1["dr"][:, None] * e1["dg_N"]  # dr/du of the closing-step factor
        R = R + (w * tau * r)[:, None] * sB
        K = K + w[:, None, None] * (
            r[:, None, None] * outer(sB, dtau) + tau[:, None, None] * outer(sB, dr) + (tau * r)[:, None, None] * DsB
        )
        work_T = w * tau * dS
    return R[on], K[on], on, np.where(on, work_T, 0.0)
