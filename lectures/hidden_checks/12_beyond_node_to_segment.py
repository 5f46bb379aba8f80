"""The hidden checks of lecture 12: the complementarity functions and the semi-smooth Newton method at parameters
drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw, parts
from contactfem.lab.course.checks.beyond_node_to_segment import _ct, _ct_ref, _ssn


def _cn_other(C_N, rng):
    from contactfem.contact.complementarity import normal_complementarity

    c_N = draw(rng, 0.5, 50.0, log=True)
    t_N = np.r_[-draw(rng, 0.01, 10.0, 4, log=True), 0.0]
    g_N = np.r_[draw(rng, -0.5, 0.5, 4), -draw(rng, 0.001, 0.1)]
    C, dt, dg = (
        np.asarray(x, float) for x in parts(call(C_N, "C_N", t_N, g_N, c_N), 3, "C_N", "C_N and its derivatives")
    )
    return c_N, C, dt, dg, normal_complementarity(t_N, g_N, c_N), {"t_N": t_N, "g_N": g_N}


def cn_values_other(C_N, rng):
    c_N, C, _, _, want, at = _cn_other(C_N, rng)
    compare(f"C_N (c_N = {c_N:g})", C, want[0], at, rule="C_N = p - max(0, p - c_N g_N) with p = -t_N")


def cn_derivatives_other(C_N, rng):
    c_N, _, dt, dg, want, at = _cn_other(C_N, rng)
    compare(f"dC_N/dt_N (c_N = {c_N:g})", dt, want[1], at)
    compare(f"dC_N/dg_N (c_N = {c_N:g})", dg, want[2], at)


def ct_other(C_T, rng):
    c_T, mu = draw(rng, 1.0, 20.0), draw(rng, 0.1, 0.8)
    xi = np.r_[-draw(rng, 0.1, 2.0), draw(rng, 0.5, 5.0, 4)]
    t_T = draw(rng, -1.5, 1.5, 5) * mu * np.abs(xi)
    dg = draw(rng, -0.3, 0.3, 5)
    got, want = _ct(C_T, t_T, dg, xi, c_T, mu), _ct_ref(t_T, dg, xi, c_T, mu)
    at = {"t_T": t_T, "dg_T": dg, "xi": xi}
    for k, name in enumerate(("C_T", "dC_T/dt_T", "dC_T/d(dg_T)", "dC_T/dxi")):
        compare(f"{name} (Coulomb mu = {mu:g}, c_T = {c_T:g})", got[k], want[k], at)


def ssn_other(semismooth_1dof, rng):
    k, g0 = draw(rng, 10.0, 100.0), draw(rng, 0.05, 0.5)
    P, c_N = draw(rng, 1.5, 4.0) * k * g0, draw(rng, 1.0, 1e4, log=True)  # the load closes the gap
    u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
    at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
    compare(f"u (k = {k:g}, P = {P:g}, g0 = {g0:g})", u, g0, at)
    compare(f"p (k = {k:g}, P = {P:g}, g0 = {g0:g})", p, P - k * g0, at)


HIDDEN = {
    "cn_values": [cn_values_other],
    "cn_derivatives": [cn_derivatives_other],
    "ct_stick_slip": [ct_other],
    "ct_derivatives": [ct_other],
    "ssn_contact": [ssn_other],
}
