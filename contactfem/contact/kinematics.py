"""Node-to-segment kinematics (paper Sec. 3.2 and 4.2), vectorised over contact pairs.

A contact pair is a slave node s and a master segment 1-2 with current positions
x_s, x_1, x_2. The element unknowns are v_c = (v_s, v_1, v_2) (eq 24), six dofs,
ordered (s_x, s_y, 1_x, 1_y, 2_x, 2_y). All functions return arrays with a leading
axis over pairs; 6-vectors are (nc, 6), 6x6 matrices are (nc, 6, 6).
"""

from functools import lru_cache

import numpy as np


def e3_cross(t):
    """n = e_3 x t: the vector t turned by +90 degrees (eq 18)."""
    return np.stack([-t[..., 1], t[..., 0]], axis=-1)


def segment_geometry(x_s, x_1, x_2):
    """Eqs (17)-(19): length l, unit tangent t, normal n = e3 x t, gap g_N and
    natural coordinate alpha of the slave's projection.

    Raises ValueError for a degenerate (zero-length) segment."""
    a = x_2 - x_1
    l = np.linalg.norm(a, axis=-1)  # eq (18)
    if np.any(~(l > 1e-14 * (1.0 + np.abs(x_1).max(initial=0.0)))):
        raise ValueError("master segment has zero length (degenerate segment): its two nodes coincide")
    t = a / l[:, None]
    n = e3_cross(t)
    d = x_s - x_1
    g_N = np.einsum("ij,ij->i", d, n)  # eq (17)
    alpha = np.einsum("ij,ij->i", d, t) / l  # eq (19)
    return l, t, n, g_N, alpha


def segment_vectors(t, n, alpha):
    """Eqs (25)-(26): N_s, N_0, T_s, T_0 as (nc, 6) arrays."""
    z = np.zeros_like(n)
    N_s = np.concatenate([n, -(1 - alpha)[:, None] * n, -alpha[:, None] * n], axis=1)
    T_s = np.concatenate([t, -(1 - alpha)[:, None] * t, -alpha[:, None] * t], axis=1)
    N_0 = np.concatenate([z, -n, n], axis=1)
    T_0 = np.concatenate([z, -t, t], axis=1)
    return N_s, N_0, T_s, T_0


def outer(a, b):
    return a[:, :, None] * b[:, None, :]


def segment_variations(x_s, x_1, x_2):
    """First and second variations of g_N and alpha with respect to v_c.

    Eq (27):     delta g_N = N_s . delta v_c
                 delta alpha = (1/l) (T_s + (g_N/l) N_0) . delta v_c
    Eqs (31)-(32): Delta delta g_N = -dv^T [ (N_0 T_s^T + T_s N_0^T)/l + (g_N/l^2) N_0 N_0^T ] Dv
    Eqs (37)-(38): Delta delta alpha = dv^T (B / l^2) Dv,
                 B = (N_s N_0^T + N_0 N_s^T) - (T_s T_0^T + T_0 T_s^T) - 2 (g_N/l)(N_0 T_0^T + T_0 N_0^T)

    Returns dict with l, t, n, g_N, alpha, dg_N, d2g_N, dalpha, d2alpha.
    """
    l, t, n, g_N, alpha = segment_geometry(x_s, x_1, x_2)
    N_s, N_0, T_s, T_0 = segment_vectors(t, n, alpha)
    r = (g_N / l)[:, None]
    dg_N = N_s
    d2g_N = -((outer(N_0, T_s) + outer(T_s, N_0)) / l[:, None, None] + (g_N / l**2)[:, None, None] * outer(N_0, N_0))
    dalpha = (T_s + r * N_0) / l[:, None]
    B = (
        (outer(N_s, N_0) + outer(N_0, N_s))
        - (outer(T_s, T_0) + outer(T_0, T_s))
        - 2.0 * r[:, :, None] * (outer(N_0, T_0) + outer(T_0, N_0))
    )
    d2alpha = B / (l**2)[:, None, None]
    return dict(l=l, t=t, n=n, g_N=g_N, alpha=alpha, dg_N=dg_N, d2g_N=d2g_N, dalpha=dalpha, d2alpha=d2alpha)


def line_variations(x_s, point, normal):
    """A fixed straight line through `point` with unit `normal` (a rigid master with
    x_1, x_2 fixed): g_N = (x_s - point).n, arc coordinate s = (x_s - point).t with
    n = e3 x t. Both are linear in x_s, so their second variations vanish (the slave rows
    of eqs 31-32 and 37-38 hold N_0 or T_0, which are zero there).
    `point` and `normal`: one line (2,) or one per slave (nc, 2) (a rigid polyline's segments).

    The first variations are n and t themselves (dg_N is the array n, ds the array t), and
    d2g_N, d2s one array of zeros: read, never written. For one line they are the same at
    every call (``line_frame``: made once per line and number of slaves, read-only)."""
    normal = np.asarray(normal, dtype=float)
    d = x_s - point
    if normal.ndim == 1:  # one line: the same n and t for all
        nt, n, t, z2 = line_frame(float(normal[0]), float(normal[1]), len(d))
        g_N, s = (d @ nt).T  # (x_s - point).n, (x_s - point).t
    else:
        n, t = np.empty_like(d), np.empty_like(d)
        n[:] = normal
        t[:, 0], t[:, 1] = n[:, 1], -n[:, 0]  # e3 x t = n
        g_N, s = np.einsum("ij,ij->i", d, n), np.einsum("ij,ij->i", d, t)
        z2 = np.zeros((len(d), 2, 2))
    return dict(t=t, n=n, g_N=g_N, s=s, dg_N=n, d2g_N=z2, ds=t, d2s=z2)


@lru_cache(maxsize=64)
def line_frame(n_x, n_y, nc):
    """The constants of line_variations for the line of unit normal (n_x, n_y) and nc slaves:
    the matrix nt whose columns are n and t (e3 x t = n), n and t with one row per slave, and
    the zero second variations (nc, 2, 2). Read-only: states hold them as values."""
    nt = np.array([[n_x, n_y], [n_y, -n_x]])
    n, t = np.empty((2, nc, 2))
    n[:], t[:] = nt[:, 0], nt[:, 1]
    frame = (nt, n, t, np.zeros((nc, 2, 2)))
    for a in frame:
        a.flags.writeable = False
    return frame


def arc_variations(x_s, center, R, inside, theta_ref):
    """A fixed circle of radius R: the contact surface of a rigid cylinder (inside=False,
    slave outside) or of a rigid hole (inside=True, slave inside).

    r = |x_s - c|, theta = angle of x_s - c (unwrapped next to theta_ref),
    g_N = sigma (r - R) with sigma = +1 outside, -1 inside; normal n = sigma e_r;
    arc coordinate s = R theta (the projection onto the circle), tangent e_theta.
    grad r = e_r, Hess r = (I - e_r e_r^T)/r; grad theta = e_theta/r,
    Hess theta = -(e_r e_theta^T + e_theta e_r^T)/r^2."""
    d = x_s - center
    r = np.linalg.norm(d, axis=1)
    if np.any(r < 1e-12 * R):
        raise ValueError("slave node at the centre of a rigid arc: the normal is undefined")
    e_r = d / r[:, None]
    e_th = e3_cross(e_r)
    theta = np.arctan2(d[:, 1], d[:, 0])
    theta = theta_ref + np.angle(np.exp(1j * (theta - theta_ref)))  # unwrap near theta_ref
    sigma = -1.0 if inside else 1.0
    I = np.eye(2)[None]
    hess_r = (I - outer(e_r, e_r)) / r[:, None, None]
    hess_th = -(outer(e_r, e_th) + outer(e_th, e_r)) / (r**2)[:, None, None]
    return dict(
        t=e_th,
        n=sigma * e_r,
        g_N=sigma * (r - R),
        s=R * theta,
        theta=theta,
        dg_N=sigma * e_r,
        d2g_N=sigma * hess_r,
        ds=R * e_th / r[:, None],
        d2s=R * hess_th,
    )
