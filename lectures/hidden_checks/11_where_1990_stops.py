"""The hidden checks of lecture 11: a contact and a law drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw
from contactfem.lab.course.checks.where_1990_stops import _uzawa


def uzawa_other(uzawa_1dof, rng):
    k, g0 = draw(rng, 10.0, 100.0), draw(rng, 0.05, 0.5)
    P, c_N = draw(rng, 1.5, 4.0) * k * g0, draw(rng, 5.0, 50.0) * k  # the load closes the gap
    u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, 1e-11)
    at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
    compare(f"u (k = {k:g}, P = {P:g}, g0 = {g0:g})", u, g0, at, rtol=1e-8, atol=1e-9)
    compare(f"lambda (k = {k:g}, P = {P:g}, g0 = {g0:g})", lam, k * g0 - P, at, rtol=1e-6, atol=1e-8)


def secant_other(secant_traction, rng):
    from contactfem.laws import PowerLaw

    law = PowerLaw(c_N=draw(rng, 1.0, 100.0, log=True), m=draw(rng, 1.0, 2.5))
    pairs = ((draw(rng, 0.05, 0.5), -draw(rng, 0.05, 0.5)), tuple(-draw(rng, 0.05, 1.0, 2)))
    for g0, g1 in pairs:
        F = float(np.asarray(call(secant_traction, "secant_traction", law, g0, g1), dtype=float))
        want = float((law.energy(np.array([g1])) - law.energy(np.array([g0])))[0] / (g1 - g0))
        compare(
            f"secant traction (c_N = {law.c_N:g}, m = {law.m:g})",
            F,
            want,
            {"g0": g0, "g1": g1},
            rule="F (g1 - g0) = energy(g1) - energy(g0)",
        )


HIDDEN = {
    "uzawa_multiplier": [uzawa_other],
    "secant_energy": [secant_other],
}
