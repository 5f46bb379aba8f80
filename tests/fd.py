"""Finite-difference Jacobians for the tangent checks."""

import numpy as np


def fd_jacobian(residual, u, dofs=None, h=1e-6):
    """Central differences of residual(u) w.r.t. u[dofs] (all dofs by default)."""
    dofs = np.arange(len(u)) if dofs is None else np.asarray(dofs)
    cols = []
    for j in dofs:
        up, um = u.copy(), u.copy()
        up[j] += h
        um[j] -= h
        cols.append((residual(up) - residual(um)) / (2 * h))
    return np.array(cols).T


def rel_error(A, B):
    return np.linalg.norm(A - B) / max(np.linalg.norm(B), 1e-30)
