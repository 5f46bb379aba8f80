"""The checks of lecture 12: beyond node-to-segment."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "12_beyond_node_to_segment"


def _cn_cases():
    t_N = np.array([-2.0, -0.5, 0.0, 0.0, -1.0, -3.0])
    g_N = np.array([-0.01, 0.3, 0.2, -0.02, 0.02, 0.0])
    return t_N, g_N, 10.0


def _cn(C_N, t_N, g_N, c_N):
    out = call(C_N, "C_N", t_N, g_N, c_N)
    return [np.asarray(x, dtype=float) for x in parts(out, 3, "C_N", "C_N, dC_N/dt_N and dC_N/dg_N")]


def cn_values(C_N):
    from ....contact.complementarity import normal_complementarity

    t_N, g_N, c_N = _cn_cases()
    C, _, _ = _cn(C_N, t_N, g_N, c_N)
    want = normal_complementarity(t_N, g_N, c_N)[0]
    at = {"t_N": t_N, "g_N": g_N}
    if C.shape == want.shape and np.allclose(C, -want):
        raise AssertionError("your C_N has the wrong sign: with p = -t_N, xi = p - c_N g_N and C_N = p - max(0, xi)")
    compare("C_N (c_N = 10)", C, want, at, rule="C_N = p - max(0, p - c_N g_N) with p = -t_N")


def cn_derivatives(C_N):
    from ....contact.complementarity import normal_complementarity

    t_N, g_N, c_N = _cn_cases()
    _, dt, dg = _cn(C_N, t_N, g_N, c_N)
    _, w_dt, w_dg, _ = normal_complementarity(t_N, g_N, c_N)
    at = {"t_N": t_N, "g_N": g_N}
    compare("dC_N/dt_N", dt, w_dt, at, rule="closed (xi >= 0): C_N = c_N g_N, so 0; open: C_N = p = -t_N, so -1")
    compare("dC_N/dg_N", dg, w_dg, at, rule="closed: c_N; open: 0")


def cn_tie(C_N):
    t_N, g_N, c_N = np.array([0.0]), np.array([0.0]), 10.0
    C, dt, dg = _cn(C_N, t_N, g_N, c_N)
    if not (np.allclose(dt, 0.0) and np.allclose(dg, c_N)):
        raise AssertionError(
            "at xi = 0 (touching, no pressure) your node is open; the tie goes to contact "
            "(xi >= 0 is closed), so that a body resting on its support is held in the first "
            "iteration: dC_N/dt_N = 0, dC_N/dg_N = c_N there"
        )


def _ct_cases():
    t_T = np.array([0.1, 0.5, -0.4, 0.2, 0.0, 0.3])
    dg = np.array([0.0, 0.02, -0.05, 0.01, 0.0, 0.1])
    xi = np.array([-1.0, 2.0, 2.0, 1.0, 0.5, 3.0])
    return t_T, dg, xi, 10.0, 0.3


def _ct(C_T, t_T, dg, xi, c_T, mu):
    out = call(C_T, "C_T", t_T, dg, xi, c_T, mu)
    return [np.asarray(x, dtype=float) for x in parts(out, 4, "C_T", "C_T, dC_T/dt_T, dC_T/d(dg_T), dC_T/dxi")]


def _ct_ref(t_T, dg, xi, c_T, mu):
    from ....contact.complementarity import friction_complementarity
    from ....laws import Coulomb

    return friction_complementarity(Coulomb(c_T=c_T, mu=mu), t_T, dg, xi, c_T)


def ct_open(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    sel = xi < 0
    at = {"t_T": t_T[sel], "xi": xi[sel]}
    compare("C_T of an open node", got[0][sel], want[0][sel], at, rule="open (xi < 0): C_T = t_T, no traction")
    compare("dC_T/dt_T of an open node", got[1][sel], want[1][sel], at)


def ct_stick_slip(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    sel = xi >= 0
    at = {"t_T": t_T[sel], "dg_T": dg[sel], "xi": xi[sel]}
    compare(
        "C_T (Coulomb mu = 0.3, c_T = 10)",
        got[0][sel],
        want[0][sel],
        at,
        rule="tau = t_T + c_T dg_T; stick (|tau| <= mu xi): -c_T dg_T; slip: t_T - sign(tau) mu xi",
    )


def ct_derivatives(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    at = {"t_T": t_T, "dg_T": dg, "xi": xi}
    for k, name, rule in (
        (1, "dC_T/dt_T", "stick 0; slip and open 1"),
        (2, "dC_T/d(dg_T)", "stick -c_T; else 0"),
        (3, "dC_T/dxi", "slip -sign(tau) mu (Y = mu xi); else 0"),
    ):
        compare(name, got[k], want[k], at, rule=rule)


SSN_CASES = ((100.0, 10.0, 0.05, 1000.0), (100.0, 10.0, 0.05, 1.0), (10.0, 5.0, 0.1, 1e4))


def _ssn(semismooth_1dof, k, P, g0, c_N):
    out = call(semismooth_1dof, "semismooth_1dof", k, P, g0, c_N, 1e-10)
    u, p, n = parts(out, 3, "semismooth_1dof", "u, p and the number of iterations")
    try:
        return float(u), float(p), int(n)
    except (TypeError, ValueError):
        raise AssertionError(f"semismooth_1dof should return (u, p, iterations): numbers, got {out!r:.80}") from None


def ssn_contact(semismooth_1dof):
    for k, P, g0, c_N in SSN_CASES:
        u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
        at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
        pen = (P + c_N * g0) / (k + c_N)
        if math.isclose(u, pen, rel_tol=1e-9) and not math.isclose(pen, g0, rel_tol=1e-9):
            raise AssertionError(
                f"at k = {k:g}, P = {P:g}, g0 = {g0:g}, c_N = {c_N:g} your u = {u:.6g} is the penalty "
                "answer: here c_N only steers the iterates; the solution has g = g0 - u = 0 exactly"
            )
        compare("u (the node at the wall)", u, g0, at, rule="in contact the gap closes exactly: u = g0")
        compare("p (the contact pressure)", p, P - k * g0, at, rule="equilibrium k u = P - p with u = g0")


def ssn_open(semismooth_1dof):
    k, P, g0, c_N = 100.0, 2.0, 0.05, 1000.0  # P / k = 0.02 < g0: never touches
    u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
    at = {"k": k, "P": P, "g0": g0}
    compare("u when the wall is not reached", u, P / k, at, rule="open: p = 0 and k u = P")
    compare("p when the wall is not reached", p, 0.0, at)


def ssn_iterations(semismooth_1dof):
    for k, P, g0, c_N in SSN_CASES:
        _, _, n = _ssn(semismooth_1dof, k, P, g0, c_N)
        if n > 3:
            raise AssertionError(
                f"at k = {k:g}, c_N = {c_N:g} your method took {n} iterations; from u = p = 0 the "
                "semi-smooth Newton method finds the set (contact) in one step and is then exact "
                "(the equations are linear once the set is right): 2 iterations, at most 3. Do you "
                "update the set from the new iterate and solve the full Newton system?"
            )
        if n < 1:
            raise AssertionError("your method reports 0 iterations: count the Newton updates you made")


EXERCISES = [
    exercise(
        "ex12_normal_complementarity",
        LECTURE,
        "easy",
        True,
        "the complementarity function of the normal contact condition and its Newton derivative",
        (cn_values, 2),
        (cn_derivatives, 2),
        (cn_tie, 1),
    ),
    exercise(
        "ex12_friction_complementarity",
        LECTURE,
        "hard",
        True,
        "the Coulomb complementarity function: open, stick and slip sets and their derivatives",
        (ct_open, 1),
        (ct_stick_slip, 2),
        (ct_derivatives, 2),
    ),
    exercise(
        "ex12_semismooth_1dof",
        LECTURE,
        "medium",
        True,
        "a semi-smooth Newton method on a one-degree-of-freedom contact",
        (ssn_contact, 2),
        (ssn_open, 1),
        (ssn_iterations, 2),
    ),
]


LIBRARY = {
    "ex12_normal_complementarity": ("contactfem.contact.complementarity:normal_complementarity",),
    "ex12_friction_complementarity": ("contactfem.contact.complementarity:friction_complementarity",),
}
