"""The checks of lecture 11: where the 1990 method stops."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "11_where_1990_stops"


def _uzawa_ref(k, P, g0, c_N, tol, max_updates=200):
    lam, n = 0.0, 0
    while True:
        u = (P + c_N * g0 + lam) / (k + c_N)
        if lam + c_N * (g0 - u) >= 0:  # open
            u = P / k
        g = g0 - u
        t = min(0.0, lam + c_N * g)
        if abs(g) <= tol or n >= max_updates:
            return u, t, n
        lam, n = t, n + 1


def _uzawa(uzawa_1dof, k, P, g0, c_N, tol):
    out = call(uzawa_1dof, "uzawa_1dof", k, P, g0, c_N, tol)
    u, lam, n = parts(out, 3, "uzawa_1dof", "u, lambda and the number of updates")
    try:
        return float(u), float(lam), int(n)
    except (TypeError, ValueError):
        raise AssertionError(f"uzawa_1dof should return (u, lambda, updates): numbers, got {out!r:.80}") from None


UZAWA_CASES = ((100.0, 10.0, 0.05, 1000.0, 1e-10), (100.0, 10.0, 0.05, 100.0, 1e-10), (10.0, 5.0, 0.1, 1e4, 1e-12))


def uzawa_gap(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        g = g0 - u
        if abs(g) > 10 * tol:
            pen = _uzawa_ref(k, P, g0, c_N, tol, max_updates=0)[0]
            extra = " (that is the penalty solution: the multiplier never entered)" if math.isclose(u, pen) else ""
            raise AssertionError(
                f"at k = {k:g}, P = {P:g}, g0 = {g0:g}, c_N = {c_N:g}, tol = {tol:g} your final gap "
                f"is {g:.3g}{extra}: update lambda <- min(0, lambda + c_N g) and solve again "
                "until |g| <= tol"
            )


def uzawa_multiplier(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        compare(
            "lambda, the contact traction",
            lam,
            k * g0 - P,
            {"k": k, "P": P, "g0": g0, "c_N": c_N},
            rtol=1e-6,
            atol=1e-8,
        )


def uzawa_updates(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        _, _, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        want = _uzawa_ref(k, P, g0, c_N, tol)[2]
        if abs(n - want) > 1:
            raise AssertionError(
                f"your loop made {n} multiplier updates at k = {k:g}, c_N = {c_N:g}, tol = {tol:g}; "
                f"{want} suffice (each shrinks the gap by k/(k + c_N) = {k / (k + c_N):.3g})"
            )


def _secant(secant_traction, law, g0, g1):
    return float(np.asarray(call(secant_traction, "secant_traction", law, g0, g1), dtype=float))


def secant_energy(secant_traction):
    from ....laws import PowerLaw

    for law in (PowerLaw(c_N=100.0, m=1.0), PowerLaw(c_N=100.0, m=2.5)):
        for g0, g1 in ((0.02, -0.03), (-0.01, -0.05), (-0.04, 0.01), (-0.02, -0.01)):
            F = _secant(secant_traction, law, g0, g1)
            want = float((law.energy(np.array([g1])) - law.energy(np.array([g0])))[0] / (g1 - g0))
            compare(
                f"secant traction of {law!r}",
                F,
                want,
                {"g0": g0, "g1": g1},
                rule="F (g1 - g0) must equal energy(g1) - energy(g0)",
            )


def secant_limit(secant_traction):
    from ....laws import PowerLaw

    law = PowerLaw(c_N=100.0, m=2.5)
    for g in (-0.03, 0.01):
        F = _secant(secant_traction, law, g, g)
        want = float(law.traction(np.array([g]))[0][0])
        if not np.isfinite(F):
            raise AssertionError(
                f"your secant traction is {F} for g0 = g1 = {g:g}: when the gap does not change, "
                "use the limit, the traction t_N(g) itself"
            )
        compare("secant traction for g0 = g1", F, want, {"g": g})


EXERCISES = [
    exercise(
        "ex11_uzawa",
        LECTURE,
        "medium",
        True,
        "Uzawa's multiplier update on a one-degree-of-freedom contact",
        (uzawa_gap, 2),
        (uzawa_multiplier, 2),
        (uzawa_updates, 1),
    ),
    exercise(
        "ex11_secant_traction",
        LECTURE,
        "medium",
        True,
        "the discrete gradient of the penalty energy (an energy check of one step)",
        (secant_energy, 3),
        (secant_limit, 1),
    ),
]


LIBRARY = {
    "ex11_secant_traction": ("contactfem.contact.conserving:secant", "contactfem.contact.conserving:discrete_gradient"),
}
