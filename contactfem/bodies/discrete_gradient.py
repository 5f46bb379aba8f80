"""Discrete gradients of a body's stored energy W for energy-consistent time stepping
(solver/conserving.py): the internal force F of a step u_0 -> u_1, conjugate to the step's
increment dq, with

    F . dq = W(u_1) - W(u_0)      exactly (not to the order of the time step),

and, like the exact internal force, no resultant (and for the beam no moment), so that the
midpoint rule built on it keeps the momentum.

The increment dq is d = u_1 - u_0 except on the angles of a beam (``rotation_dofs``), whose
increment Delta theta enters as phi = 2 tan(Delta theta / 2) (``cayley``): the rotation by
Delta theta is the Cayley transform of phi J, (I - phi/2 J)^-1 (I + phi/2 J), which is what
the midpoint rule x_1 - x_0 = phi J (x_0 + x_1) / 2 turns a vector by. A rigid rotation
of the midpoint rule then turns the positions and the angles alike, W does not change in it,
and a discrete gradient can be orthogonal to it (Simo, Tarnow & Doblare, IJNME 38, 1995,
for rods; beam.py).

``algorithmic_stress``: a continuum's stress of the step, Gonzalez's discrete gradient in
the Green strain at every quadrature point (Simo & Tarnow, ZAMP 43, 1992): no resultant
and no moment.

``gonzalez``: any hyperelastic body, from its W and R = dW/du alone (Gonzalez, J Nonlinear
Sci 6, 1996): F = R(u_mid) + c w, with w the increment without its rigid translations, so
that F has no resultant; it may have a moment (the correction's, of the order of the energy
mismatch it removes). The linear continuum (c = 0: R(u_mid)) and a body of one's own.
"""

import numpy as np

from .. import lazy
from .materials import _eye

sp = lazy.module("scipy.sparse")


def cayley(d, rotations):
    """The increment dq of the step (module docstring): d with phi = 2 tan(Delta theta / 2) in
    place of the angle increments Delta theta at ``rotations``; D = d dq / d d (1 + phi^2 / 4
    there, 1 elsewhere); and chord = Delta theta / phi with its derivative d chord / d Delta theta,
    the factor that turns a force conjugate to Delta theta into one conjugate to phi. Below
    |Delta theta| = 1e-2, chord and its derivative are their series (the next term < 1e-17 there;
    the closed forms cancel). A step must turn a node by less than pi: FloatingPointError
    naming the dof otherwise (Newton reports it; the time loop cuts the step)."""
    dq, D = np.array(d, dtype=float), np.ones(len(d))
    chord = np.ones(len(d))
    x = dq[rotations]
    if np.any(~(np.abs(x) < np.pi)):
        i = int(np.argmax(~(np.abs(x) < np.pi)))
        raise FloatingPointError(
            f"an angle turns by {x[i]:.3g} rad in one step at dof {int(rotations[i])}: the "
            "Cayley update allows less than pi (a smaller dt)"
        )
    h = 0.5 * x
    phi = 2.0 * np.tan(h)
    dq[rotations] = phi
    D[rotations] = 1.0 + 0.25 * phi * phi
    small = np.abs(x) < 1e-2
    hs = np.where(small, 1.0, h)
    chord[rotations] = np.where(small, 1.0 - x * x / 12.0 - x**4 / 720.0 - x**6 / 30240.0, hs / np.tan(hs))
    dchord = np.where(small, -x / 6.0 - x**3 / 180.0 - x**5 / 5040.0, 0.5 / np.tan(hs) - 0.5 * hs / np.sin(hs) ** 2)
    return dq, D, chord, dchord


def gonzalez(body, u0, u1, modes):
    """The discrete gradient F = R(u_mid) + c w of ``body`` for the step u0 -> u1 (local vectors;
    the body has no rotation dofs: dq = d), with its exact tangent dF/du1, as (F, rows, cols,
    vals) (the tangent dense over the body's dofs where the correction acts):

        w = (I - Pi) d,  Pi = A (A^T A)^-1 A^T  the projector on the constant rigid ``modes`` A,
        c = gap / (w . w),  gap = W(u_1) - W(u_0) - R(u_mid) . d,
        dF/du_1 = K(u_mid) / 2 + w (dc/du_1)^T + c (I - Pi),
        dc/du_1 = (R(u_1) - R(u_mid) - K(u_mid) d / 2 - 2 c w) / (w . w).

    W does not change under the translations A, so R(u_mid) has no resultant, nor has c w. No
    correction for a quadratic W (the midpoint rule is exact: gap = 0 up to the rounding of
    R = K u, a sum of large cancelling terms when the body moves rigidly), nor where the gap
    is at the rounding of W."""
    um = 0.5 * (u0 + u1)
    R, K = body.internal(um)
    d = u1 - u0
    W0, W1 = body.strain_energy(u0), body.strain_energy(u1)
    A = modes
    AtA_inv = np.linalg.inv(A.T @ A)
    w = d - A @ (AtA_inv @ (A.T @ d))  # d without its rigid translation
    gap = W1 - W0 - R @ d
    ww = w @ w
    use = not body.quadratic_energy and ww > 0 and abs(gap) > 1e-13 * (abs(W0) + abs(W1))
    c = gap / ww if use else 0.0
    K = sp.coo_matrix(K)
    rows, cols, vals = [K.row], [K.col], [0.5 * K.data]
    if c != 0.0:
        n = body.ndof
        P = np.eye(n) - A @ AtA_inv @ A.T
        R1 = body.internal(u1)[0]
        dc = (R1 - R - 0.5 * (K @ d) - 2.0 * c * w) / ww
        Z = np.outer(w, dc) + c * P
        rows.append(np.repeat(np.arange(n), n))
        cols.append(np.tile(np.arange(n), n))
        vals.append(Z.ravel())
    return R + c * w, np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def algorithmic_stress(material, F0, F1, lam, mu, W0=None):
    """The first Piola-Kirchhoff stress of a step F0 -> F1 at every quadrature point, (3, 3,
    ...), P = F_mid S_alg, with S_alg Gonzalez's discrete gradient of W in the Green strain E
    (Simo & Tarnow 1992; Gonzalez 2000):

        S_alg = S(E_mid) + [(W(F1) - W(F0) - S(E_mid) : dE) / (dE : dE)] dE,   dE = E1 - E0,

    so that S_alg : dE = W(F1) - W(F0) exactly, and, since dE = sym(F_mid^T (F1 - F0)) exactly,
    P : (F1 - F0) = W(F1) - W(F0). P : grad(omega e3 x x_mid) = S_alg : F_mid^T W F_mid = 0 (S_alg
    symmetric, F_mid^T W F_mid skew): no moment. S(E_mid) from the material at the stretch
    U = sqrt(C_mid) (a function of C alone: the materials are isotropic and frame-indifferent);
    no correction where dE : dE < 1e-9: the energy mismatch is of order (lam + mu) |dE|^3, below
    3e-14 (lam + mu) there, the rounding of W itself (a neo-Hooke W subtracts terms of order
    lam + mu), so that the quotient would be rounding over |dE|^2 (and Newton's residual would
    stall on it). F1 may be complex (the tangent's complex step); W0: W(F0),
    if already known."""
    I = _eye(F0)
    E0 = 0.5 * (np.einsum("ki...,kj...->ij...", F0, F0) - I)
    E1 = 0.5 * (np.einsum("ki...,kj...->ij...", F1, F1) - I)
    C = E0 + E1 + I  # C_mid = 2 E_mid + I
    # U = sqrt(C): the 2x2 in-plane block (B + sqrt(det B) I) / sqrt(tr B + 2 sqrt(det B)), U_33 = sqrt(C_33)
    s = np.sqrt(C[0, 0] * C[1, 1] - C[0, 1] * C[1, 0])
    t = np.sqrt(C[0, 0] + C[1, 1] + 2.0 * s)
    U = np.zeros_like(C)
    U[:2, :2] = (C[:2, :2] + s * I[:2, :2]) / t
    U[2, 2] = np.sqrt(C[2, 2])
    P_mid = material(U, lam, mu, tangent=False)[1]
    Ui = np.zeros_like(U)
    det = U[0, 0] * U[1, 1] - U[0, 1] * U[1, 0]
    Ui[0, 0], Ui[1, 1], Ui[0, 1], Ui[1, 0] = U[1, 1] / det, U[0, 0] / det, -U[0, 1] / det, -U[1, 0] / det
    Ui[2, 2] = 1.0 / U[2, 2]
    S = np.einsum("ik...,kj...->ij...", Ui, P_mid)
    S = 0.5 * (S + S.transpose(1, 0, *range(2, S.ndim)))  # symmetric (to rounding already)
    dE = E1 - E0
    nn = np.einsum("ij...,ij...->...", dE, dE)
    if W0 is None:
        W0 = material(F0, lam, mu, tangent=False)[0]
    gap = material(F1, lam, mu, tangent=False)[0] - W0 - np.einsum("ij...,ij...->...", S, dE)
    use = np.real(nn) > 1e-9
    S = S + np.where(use, gap / np.where(use, nn, 1.0), 0.0) * dE
    return np.einsum("ik...,kj...->ij...", 0.5 * (F0 + F1), S)
