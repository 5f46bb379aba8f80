"""The checks of lecture 02: kinematics and the tangent."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "02_kinematics_linearisation"


def _circle(circle_gap):
    x_s = np.array([[2.0, 0.5], [1.0, 3.0], [1.4, 1.0], [-0.5, 0.2]])
    c, R = np.array([1.0, 1.0]), 1.5
    out = call(circle_gap, "circle_gap", x_s, c, R)
    g_N, n = parts(out, 2, "circle_gap", "g_N and n")
    d = x_s - c
    r = np.linalg.norm(d, axis=1)
    return x_s, c, R, np.asarray(g_N, dtype=float), np.asarray(n, dtype=float), r - R, d / r[:, None]


def circle_gap_value(circle_gap):
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    at = {"x_s": [f"({x:g}, {y:g})" for x, y in x_s]}
    if g_N.shape == g_ref.shape and np.allclose(g_N, -g_ref):
        raise AssertionError(
            "your g_N has the wrong sign: a slave outside the disc has an open gap g_N > 0, "
            "one inside has penetrated, g_N < 0"
        )
    compare("g_N (centre (1, 1), R = 1.5)", g_N, g_ref, at, rule="g_N = |x_s - centre| - R")


def circle_gap_normal(circle_gap):
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    if n.shape != n_ref.shape:
        raise AssertionError(f"n should have shape {n_ref.shape} (one unit vector per slave node), got {n.shape}")
    norm = np.linalg.norm(n, axis=1)
    if not np.allclose(norm, 1.0, rtol=1e-8):
        i = int(np.argmax(np.abs(norm - 1.0)))
        raise AssertionError(
            f"your n at x_s = ({x_s[i, 0]:g}, {x_s[i, 1]:g}) has length {norm[i]:.4g}: "
            "divide by |x_s - centre| to make it a unit vector"
        )
    dots = np.einsum("ij,ij->i", n, n_ref)
    if np.all(dots < -0.999999):
        raise AssertionError(
            "your n points into the disc: the outward normal n = (x_s - centre)/|x_s - centre| "
            "points from the centre to the slave"
        )
    i = int(np.argmin(dots))
    if dots[i] < 1 - 1e-8:
        raise AssertionError(
            f"your n at x_s = ({x_s[i, 0]:g}, {x_s[i, 1]:g}) is ({n[i, 0]:.4g}, {n[i, 1]:.4g}), "
            f"expected ({n_ref[i, 0]:.4g}, {n_ref[i, 1]:.4g}), the direction from the centre to the slave"
        )


def circle_gap_variation(circle_gap):
    """The gap's derivative with respect to the slave's position is the normal (delta g_N = n . delta x_s)."""
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    h = 1e-6
    for k, name in ((0, "x"), (1, "y")):
        e = np.zeros(2)
        e[k] = h
        gp = np.asarray(parts(call(circle_gap, "circle_gap", x_s + e, c, R), 2, "circle_gap", "g_N and n")[0], float)
        gm = np.asarray(parts(call(circle_gap, "circle_gap", x_s - e, c, R), 2, "circle_gap", "g_N and n")[0], float)
        fd = (gp - gm) / (2 * h)
        if not np.allclose(fd, n[:, k], atol=1e-6):
            i = int(np.argmax(np.abs(fd - n[:, k])))
            raise AssertionError(
                f"d g_N / d x_s,{name} by finite differences is {fd[i]:.6g} at x_s = "
                f"({x_s[i, 0]:g}, {x_s[i, 1]:g}) but your n_{name} is {n[i, k]:.6g}: the "
                "variation of the gap is n . delta x_s, so g_N and n must belong together"
            )


def _segment_case():
    x_s, x_1, x_2 = np.array([0.35, 0.02]), np.array([0.0, 0.0]), np.array([1.0, 0.2])
    return x_s, x_1, x_2, 50.0


def _K_parts(x_s, x_1, x_2, c_N):
    from ....contact.kinematics import outer, segment_geometry, segment_vectors

    l, t, n, g_N, alpha = segment_geometry(x_s[None], x_1[None], x_2[None])
    N_s, N_0, T_s, T_0 = segment_vectors(t, n, alpha)
    t_N = c_N * min(g_N[0], 0.0)
    mat = c_N * outer(N_s, N_s)[0]
    geo = -t_N * ((outer(N_0, T_s) + outer(T_s, N_0))[0] / l[0] + g_N[0] / l[0] ** 2 * outer(N_0, N_0)[0])
    return mat, geo


def _residual_fd(x_s, x_1, x_2, c_N):
    from ....contact.kinematics import segment_geometry, segment_vectors

    def R(X):
        l, t, n, g_N, alpha = segment_geometry(X[None, 0:2], X[None, 2:4], X[None, 4:6])
        N_s = segment_vectors(t, n, alpha)[0]
        return c_N * np.minimum(g_N, 0.0)[0] * N_s[0]

    X0 = np.concatenate([x_s, x_1, x_2])
    h = 1e-7
    return np.stack([(R(X0 + h * e) - R(X0 - h * e)) / (2 * h) for e in np.eye(6)], axis=1)


def _K_student(normal_tangent):
    x_s, x_1, x_2, c_N = _segment_case()
    K = np.asarray(call(normal_tangent, "normal_tangent", x_s, x_1, x_2, c_N), dtype=float)
    if K.shape != (6, 6):
        raise AssertionError(
            f"normal_tangent should return the 6x6 matrix K_N (rows and columns s_x, s_y, 1_x, "
            f"1_y, 2_x, 2_y), it returned shape {K.shape}"
        )
    if not np.all(np.isfinite(K)):
        raise AssertionError("your K_N has entries that are not finite numbers")
    return K, (x_s, x_1, x_2, c_N)


LABELS6 = ["s_x", "s_y", "1_x", "1_y", "2_x", "2_y"]


def normal_tangent_fd(normal_tangent):
    K, case = _K_student(normal_tangent)
    fd = _residual_fd(*case)
    scale = np.abs(fd).max()
    if np.abs(K - fd).max() <= 1e-6 * scale:
        return
    mat, geo = _K_parts(*case)
    if np.abs(K - mat).max() <= 1e-6 * scale:
        raise AssertionError(
            "your K_N is c_N N_s N_s^T alone: the geometric part "
            "-t_N [(N_0 T_s^T + T_s N_0^T)/l + (g_N/l^2) N_0 N_0^T] of eq (33) is missing "
            "(it comes from the variation of N_s)"
        )
    if np.abs(K - (mat - geo)).max() <= 1e-6 * scale:
        raise AssertionError(
            "the geometric part of your K_N has the wrong sign: eq (33) has -t_N [...] with t_N < 0 in contact"
        )
    if np.abs(K - geo).max() <= 1e-6 * scale:
        raise AssertionError(
            "your K_N is the geometric part alone: the material part dt_N/dg_N N_s N_s^T "
            "(= c_N N_s N_s^T for the penalty law) is missing"
        )
    i, j = np.unravel_index(np.argmax(np.abs(K - fd)), K.shape)
    raise AssertionError(
        f"your K_N differs from the finite-difference Jacobian of R = t_N N_s: entry "
        f"({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, finite differences give {fd[i, j]:.6g}"
    )


def normal_tangent_material(normal_tangent):
    K, case = _K_student(normal_tangent)
    mat, geo = _K_parts(*case)
    x_s, x_1, x_2, c_N = case
    from ....contact.kinematics import segment_geometry, segment_vectors

    l, t, n, g_N, alpha = segment_geometry(x_s[None], x_1[None], x_2[None])
    N_s = segment_vectors(t, n, alpha)[0][0]
    got, want = N_s @ K @ N_s, N_s @ (mat + geo) @ N_s
    if not math.isclose(got, want, rel_tol=1e-6):
        raise AssertionError(
            f"N_s^T K_N N_s is {got:.6g}, expected {want:.6g} (off by a factor {got / want:.4g}): "
            "check the term dt_N/dg_N N_s N_s^T (dt_N/dg_N = c_N for the penalty law in contact)"
        )


def normal_tangent_symmetric(normal_tangent):
    K, _ = _K_student(normal_tangent)
    asym = np.abs(K - K.T).max()
    if asym > 1e-10 * max(np.abs(K).max(), 1e-300):
        i, j = np.unravel_index(np.argmax(np.abs(K - K.T)), K.shape)
        raise AssertionError(
            f"your K_N is not symmetric: entry ({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, "
            f"({LABELS6[j]}, {LABELS6[i]}) is {K[j, i]:.6g}; eq (33) is symmetric "
            "(N_0 T_s^T + T_s N_0^T, not N_0 T_s^T alone)"
        )


EXERCISES = [
    exercise(
        "ex02_circle_gap",
        LECTURE,
        "easy",
        True,
        "the gap and normal of a circular rigid master",
        (circle_gap_value, 2),
        (circle_gap_normal, 2),
        (circle_gap_variation, 1),
    ),
    exercise(
        "ex02_normal_tangent",
        LECTURE,
        "hard",
        True,
        "the normal block K_N of the tangent (eq 33), checked against finite differences",
        (normal_tangent_fd, 3),
        (normal_tangent_material, 1),
        (normal_tangent_symmetric, 1),
    ),
]


LIBRARY = {
    "ex02_circle_gap": (
        "contactfem.contact.masters:RigidArc",
        "contactfem.contact.kinematics:arc_variations",
        "contactfem.contact.reference:arc_pair",
    ),
    "ex02_normal_tangent": (
        "contactfem.contact.element:normal_element",
        "contactfem.contact.element:contact_element",
        "contactfem.contact.reference:segment_element",
    ),
}
