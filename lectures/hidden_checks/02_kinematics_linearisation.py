"""The hidden checks of lecture 02: another circle, another segment, drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw, parts
from contactfem.lab.course.checks.kinematics_linearisation import LABELS6, _residual_fd


def circle_gap_value_other(circle_gap, rng):
    c, R = draw(rng, -3.0, 3.0, 2), draw(rng, 0.3, 2.0)
    angle, r = rng.uniform(0.0, 2 * np.pi, 4), draw(rng, 0.1, 3.0, 4) * R
    x_s = np.round(c + r[:, None] * np.c_[np.cos(angle), np.sin(angle)], 3)
    g_N, n = parts(call(circle_gap, "circle_gap", x_s, c, R), 2, "circle_gap", "g_N and n")
    d = x_s - c
    dist = np.linalg.norm(d, axis=1)
    at = {"x_s": [f"({x:g}, {y:g})" for x, y in x_s]}
    where = f"centre ({c[0]:g}, {c[1]:g}), R = {R:g}"
    compare(f"g_N ({where})", g_N, dist - R, at, rule="g_N = |x_s - centre| - R")
    compare(
        f"n ({where})",
        np.asarray(n, float),
        d / dist[:, None],
        {"x_s": np.repeat(np.array(at["x_s"])[:, None], 2, axis=1)},
        rule="n = (x_s - centre)/|x_s - centre|",
    )


def normal_tangent_fd_other(normal_tangent, rng):
    """A segment of any direction and length with the slave node penetrating it."""
    x_1, angle, length = draw(rng, -1.0, 1.0, 2), rng.uniform(0.0, 2 * np.pi), draw(rng, 0.5, 2.0)
    t = np.array([np.cos(angle), np.sin(angle)])
    x_2 = np.round(x_1 + length * t, 3)
    normal = np.array([-t[1], t[0]])
    x_s = np.round(x_1 + draw(rng, 0.15, 0.85) * (x_2 - x_1) - draw(rng, 0.01, 0.1) * length * normal, 3)
    c_N = draw(rng, 5.0, 500.0, log=True)
    K = np.asarray(call(normal_tangent, "normal_tangent", x_s, x_1, x_2, c_N), dtype=float)
    fd = _residual_fd(x_s, x_1, x_2, c_N)
    if K.shape != (6, 6):
        raise AssertionError(f"normal_tangent should return a 6x6 matrix, it returned shape {K.shape}")
    if not np.abs(K - fd).max() <= 1e-6 * np.abs(fd).max():
        i, j = np.unravel_index(np.argmax(np.abs(K - fd)), K.shape)
        raise AssertionError(
            f"at x_s = {tuple(x_s)}, x_1 = {tuple(x_1)}, x_2 = {tuple(x_2)}, c_N = {c_N:g} your K_N entry "
            f"({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, finite differences give {fd[i, j]:.6g}"
        )


HIDDEN = {
    "circle_gap_value": [circle_gap_value_other],
    "normal_tangent_fd": [normal_tangent_fd_other],
}
