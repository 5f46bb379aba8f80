"""Meshes of the scenes' bodies, made with scikit-fem (imported when a mesh is made): a
rectangular block, a quarter disk graded towards its contact point (Hertz) and a graded
foundation block under it, the meridian of a cork with a conical shaft. (The rings'
annulus is in ring.py.)"""

import numpy as np

from .. import lazy

skfem = lazy.module("skfem")


def block_mesh(width, height, nx, ny):
    """MeshQuad of the block [0, width] x [0, height] with boundaries bottom/top/left/right."""
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0.0, width, nx + 1), np.linspace(0.0, height, ny + 1))
    tx, ty = 1e-9 * width, 1e-9 * height
    return mesh.with_boundaries(
        {
            "bottom": lambda x: x[1] < ty,
            "top": lambda x: x[1] > height - ty,
            "left": lambda x: x[0] < tx,
            "right": lambda x: x[0] > width - tx,
        }
    )


def stretching(n, k):
    """n + 1 points in [0, 1], sinh(k s) / sinh(k) for uniform s: fine and almost
    uniform near 0, growing geometrically towards 1 (k -> 0: uniform)."""
    s = np.linspace(0.0, 1.0, n + 1)
    return s if k < 1e-8 else np.sinh(k * s) / np.sinh(k)


def grading_for(xi_zone, frac):
    """The k of `stretching` that maps s = frac onto xi = xi_zone (bisection on the
    monotone function sinh(k frac) / sinh(k))."""
    if xi_zone >= frac:
        return 0.0
    lo, hi = 1e-6, 200.0
    for _ in range(100):
        k = 0.5 * (lo + hi)
        if np.sinh(k * frac) / np.sinh(k) > xi_zone:
            lo = k
        else:
            hi = k
    return 0.5 * (lo + hi)


def quarter_disk(R, n_el, k):
    """MeshQuad of the quarter disk x >= 0, y <= 0, x^2 + y^2 <= R^2 with n_el x n_el quads.

    Transfinite (Coons) interpolation of the unit square (xi, eta):
    eta = 0 -> arc from B = (0, -R) to angle -45 deg, eta = 1 -> flat cut y = 0,
    xi = 0 -> symmetry line x = 0, xi = 1 -> arc from -45 deg to A = (R, 0).
    Both coordinates are stretched with sinh(k s)/sinh(k), so the mesh is finest at B.
    Boundaries: 'symmetry' (x = 0), 'top' (y = 0), 'arc'."""
    xi = stretching(n_el, k)
    XI, ETA = np.meshgrid(xi, xi, indexing="ij")  # (n+1, n+1)

    def arc(theta):
        return R * np.stack([np.cos(theta), np.sin(theta)])

    bottom = arc(-np.pi / 2 + XI * np.pi / 4)
    top = np.stack([XI * R, 0.0 * XI])
    left = np.stack([0.0 * ETA, -R + ETA * R])
    right = arc(-np.pi / 4 + ETA * np.pi / 4)
    P00, P10, P01, P11 = arc(-np.pi / 2), arc(-np.pi / 4), np.zeros(2), arc(0.0)
    corners = (
        ((1 - XI) * (1 - ETA))[None] * P00[:, None, None]
        + (XI * (1 - ETA))[None] * P10[:, None, None]
        + ((1 - XI) * ETA)[None] * P01[:, None, None]
        + (XI * ETA)[None] * P11[:, None, None]
    )
    x = (1 - ETA) * bottom + ETA * top + (1 - XI) * left + XI * right - corners
    p = x.reshape(2, -1)
    idx = np.arange((n_el + 1) ** 2).reshape(n_el + 1, n_el + 1)
    t = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]]).reshape(4, -1)
    # counter-clockwise: (xi, eta) -> (x, y) reverses orientation? check with the signed area
    a, b, d = p[:, t[0]], p[:, t[1]], p[:, t[3]]
    area = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0])
    if np.mean(area) < 0:
        t = t[::-1]
    tol = 1e-9 * R
    return skfem.MeshQuad(p, t).with_boundaries(
        {
            "symmetry": lambda x: np.abs(x[0]) < tol,
            "top": lambda x: np.abs(x[1]) < tol,
            "arc": lambda x: (np.abs(x[0]) > tol) & (np.abs(x[1]) > tol),
        }
    )


def cork_radius(z, R_tip, R_cork, L_taper):
    """Outer radius of the free cork at height z: a conical shaft from R_tip at the
    bottom (z = 0) to R_cork at z = L_taper, then the cylindrical head."""
    return R_tip + (R_cork - R_tip) * np.clip(z / L_taper, 0.0, 1.0)


def cork_mesh(R_tip, R_cork, L_taper, length, n_r, n_z):
    """MeshQuad of the cork's meridian (x = r, y = z): n_r x n_z elements, radius
    ``cork_radius(z)``, with boundaries axis, outer, bottom, top."""
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0.0, 1.0, n_r + 1), np.linspace(0.0, length, n_z + 1))
    tr, tz = 1e-9, 1e-9 * length
    mesh = mesh.with_boundaries(
        {
            "axis": lambda x: x[0] < tr,
            "outer": lambda x: x[0] > 1.0 - tr,
            "bottom": lambda x: x[1] < tz,
            "top": lambda x: x[1] > length - tz,
        }
    )
    p = mesh.p.copy()
    p[0] = p[0] * cork_radius(p[1], R_tip, R_cork, L_taper)
    return skfem.MeshQuad(p, mesh.t, _boundaries=mesh.boundaries)


def graded(h, zone, L, growth=1.25):
    """Coordinates 0, h, 2h, ... over [0, zone], then steps growing by `growth` up to L."""
    x = list(np.arange(0.0, zone + 0.5 * h, h))
    d = h
    while x[-1] < L * (1 - 1e-12):
        d *= growth
        x.append(min(x[-1] + d, L))
    return np.array(x)


def graded_block_mesh(R, h, zone_x, zone_y):
    """MeshQuad of the square [0, R] x [-2R, -R] (an elastic foundation under a cylinder of
    radius R touching it at (0, -R)): elements h wide over [0, zone_x] and h high over the
    top zone_y, growing geometrically beyond (``graded``)."""
    return skfem.MeshQuad.init_tensor(graded(h, zone_x, R), -R - graded(h, zone_y, R)[::-1])
