"""Materials of the continuum bodies: each one pure function ``F -> (W, P, A)`` of the
3x3 deformation gradient at all quadrature points, shape (3, 3, nel, nqp): strain energy
density W, first Piola-Kirchhoff stress P and material tangent A = dP/dF (None with
``tangent=False``: energy and stress only) (Holzapfel,
Nonlinear Solid Mechanics, ch. 6; Wriggers, Nonlinear FEM, ch. 3-4). Plain numpy: the
forms of continuum.py integrate them with scikit-fem."""

import numpy as np

MATERIALS = ("linear", "svk", "neohooke")


def _eye(F):
    """Identity with the trailing shape of F."""
    return np.einsum("ij,...->ij...", np.eye(3), np.ones(F.shape[2:]))


def _isotropic_tangent(lam, mu, shape):
    """C_ijkl = lam d_ij d_kl + mu (d_ik d_jl + d_il d_jk), broadcast to shape."""
    d = np.eye(3)
    C = lam * np.einsum("ij,kl->ijkl", d, d) + mu * (np.einsum("ik,jl->ijkl", d, d) + np.einsum("il,jk->ijkl", d, d))
    return np.broadcast_to(C.reshape(C.shape + (1,) * len(shape)), C.shape + tuple(shape))  # a view, no copy


def linear_elastic(F, lam, mu, tangent=True):
    """Small strain: eps = sym(F - I), sigma = lam tr(eps) I + 2 mu eps, W = sigma:eps/2."""
    I = _eye(F)
    eps = 0.5 * (F + F.transpose(1, 0, 2, 3)) - I
    tr = np.einsum("ii...->...", eps)
    P = lam * tr * I + 2.0 * mu * eps
    W = 0.5 * np.einsum("ij...,ij...->...", P, eps)
    return W, P, _isotropic_tangent(lam, mu, F.shape[2:]) if tangent else None


def saint_venant_kirchhoff(F, lam, mu, tangent=True):
    """St Venant-Kirchhoff: E = (F^T F - I)/2, S = lam tr(E) I + 2 mu E, P = F S.

    A_iJkL = d_ik S_JL + lam F_iJ F_kL + mu (F F^T)_ik d_JL + mu F_iL F_kJ
    (= d_ik S_JL + F_iI C_IJKL F_kK, Holzapfel eq. 6.186 written out).
    """
    I = _eye(F)
    E = 0.5 * (np.einsum("ki...,kj...->ij...", F, F) - I)
    trE = np.einsum("ii...->...", E)
    S = lam * trE * I + 2.0 * mu * E
    P = np.einsum("ik...,kj...->ij...", F, S)
    W = 0.5 * lam * trE**2 + mu * np.einsum("ij...,ij...->...", E, E)
    if not tangent:
        return W, P, None
    FFt = np.einsum("ik...,jk...->ij...", F, F)
    A = (
        np.einsum("ik,jl...->ijkl...", np.eye(3), S)
        + lam * np.einsum("ij...,kl...->ijkl...", F, F)
        + mu * np.einsum("ik...,jl->ijkl...", FFt, np.eye(3))
        + mu * np.einsum("il...,kj...->ijkl...", F, F)
    )
    return W, P, A


def neo_hooke(F, lam, mu, tangent=True):
    """Compressible neo-Hooke: W = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2.

    P = mu (F - F^-T) + lam ln J F^-T,
    A_iJkL = mu d_ik d_JL + (mu - lam ln J) Fi_Li Fi_Jk + lam Fi_Ji Fi_Lk  (Fi = F^-1).
    """
    Fm = np.moveaxis(F, (0, 1), (-2, -1))  # (..., 3, 3) for numpy.linalg
    J = np.linalg.det(Fm)
    Fi = np.moveaxis(np.linalg.inv(Fm), (-2, -1), (0, 1))
    FiT = Fi.transpose(1, 0, 2, 3)
    lnJ = np.log(J)
    I1 = np.einsum("ij...,ij...->...", F, F)
    W = 0.5 * mu * (I1 - 3.0) - mu * lnJ + 0.5 * lam * lnJ**2
    P = mu * (F - FiT) + lam * lnJ * FiT
    if not tangent:
        return W, P, None
    d = np.eye(3)
    A = (
        mu * np.einsum("ik,jl,...->ijkl...", d, d, np.ones(J.shape))
        + (mu - lam * lnJ) * np.einsum("li...,jk...->ijkl...", Fi, Fi)
        + lam * np.einsum("ji...,lk...->ijkl...", Fi, Fi)
    )
    return W, P, A


MATERIAL_FUNCTIONS = {"linear": linear_elastic, "svk": saint_venant_kirchhoff, "neohooke": neo_hooke}
