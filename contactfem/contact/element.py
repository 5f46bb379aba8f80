"""The contact element: residual (eq 28) and consistent tangent (eqs 33, 39, 49, 50),
vectorised over contact pairs, returned as COO triplets ready to add to a global matrix."""

from functools import lru_cache

import numpy as np

from .kinematics import outer


def contact_element(w, t_N, dt_N, t_T, c_T_s, c_N_s, dg_N, d2g_N, ds, d2s, ddg_T=None):
    """Nodal contact forces and their tangent for each pair.

    w: weight of each slave (tributary length for tractions per unit length, 1 for
    nodal laws). With the variations of the gap and of the arc coordinate s
    (Delta g_T = s - s_bar):

    eq (28)   R_c = w [ t_N dg_N + t_T ds ]
              (for a segment: dg_N = N_s and ds = (l_bar/l)(T_s + (g_N/l) N_0))
    eq (33)   K_N = w [ dt_N/dg_N dg_N dg_N^T + t_N d2g_N ]
    eq (39)   K_T = w [ c_T (ds ds^T) + t_T d2s ]                  (stick; ds ds^T = (l_bar/l)^2 A,
                                                                    d2s = l_bar B / l^2)
    eq (49)   K_T = w [ c_T^s (ds ds^T) + t_T d2s + c_N^s C ]      (slip)
    eq (50)   C = ds dg_N^T                                         (non-symmetric)

    ddg_T: the variation of the slip increment Delta g_T where it is not ds (a node that
    closes during the step: Delta g_T = r (s - s_bar), see NodeToSegment.kinematics); the
    c_T^s term is then c_T^s ds ddg_T^T. Default ds.

    d2g_N, d2s: None where they vanish (a straight rigid master, kinematics.line_variations):
    their terms t_N d2g_N and t_T d2s are left out, which adds nothing but zeros.
    """
    ddg_T = ds if ddg_T is None else ddg_T
    R = w[:, None] * (t_N[:, None] * dg_N + t_T[:, None] * ds)
    # eq (33)'s dt_N dg_N dg_N^T, and the c_T^s and c_N^s terms of eqs (39), (49), (50) in one
    # product: ds (c_T^s ddg_T + c_N^s dg_N)^T
    K = outer(dt_N[:, None] * dg_N, dg_N) + outer(ds, c_T_s[:, None] * ddg_T + c_N_s[:, None] * dg_N)
    if d2g_N is not None:
        K += t_N[:, None, None] * d2g_N
    if d2s is not None:
        K += t_T[:, None, None] * d2s
    K *= w[:, None, None]
    return R, K


def normal_element(w, t_N, dt_N, dg_N, d2g_N):
    """The frictionless element: eq (28) with t_T = 0 and eq (33),

        R_c = w t_N dg_N,    K_N = w [ dt_N/dg_N dg_N dg_N^T + t_N d2g_N ]

    (d2g_N None where it vanishes, as in contact_element)."""
    R = (w * t_N)[:, None] * dg_N
    K = dt_N[:, None, None] * outer(dg_N, dg_N)
    if d2g_N is not None:
        K += t_N[:, None, None] * d2g_N
    K *= w[:, None, None]
    return R, K


def to_coo(dofs, K):
    """COO triplets (rows, cols, vals) of the element matrices K (nc, k, k) placed at
    global dofs (nc, k)."""
    return (*coo_indices(dofs), K.ravel())


def coo_indices(dofs):
    """The rows and cols of to_coo: where the entries of element matrices at global dofs
    (nc, k) go, entry by entry (row-major in each element)."""
    k = dofs.shape[1]
    rows = np.repeat(dofs, k, axis=1).ravel()
    cols = np.concatenate([dofs] * k, axis=1).ravel()  # np.tile(dofs, (1, k)), without its overhead
    return rows, cols


def pattern(dofs):
    """coo_indices(dofs) as read-only arrays, the same objects for the same dofs while they stay
    among the last few asked for: a pure function of the contact set (the pairs' global dofs),
    so the System's assembly finds their places in K once per change of the set (assembly.py
    keeps index arrays by identity). Nothing of a run is kept: equal dofs give equal arrays."""
    dofs = np.asarray(dofs)
    return _pattern(dofs.shape, dofs.dtype.str, dofs.tobytes())


@lru_cache(maxsize=64)
def _pattern(shape, dtype, data):
    rows, cols = coo_indices(np.frombuffer(data, dtype=dtype).reshape(shape))
    rows.flags.writeable = cols.flags.writeable = False
    return rows, cols
