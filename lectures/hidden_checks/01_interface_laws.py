"""The hidden checks of lecture 01: the laws at parameters drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw, parts
from contactfem.lab.course.checks.interface_laws import _tresca


def _power(power_law, g, c_N, m):
    return parts(call(power_law, "power_law", g, c_N, m), 2, "power_law", "t_N and dt_N/dg_N")


def _law(rng):
    return draw(rng, 1.0, 1e4, log=True), draw(rng, 1.0, 3.0)


def power_law_open_far(power_law, rng):
    g = np.r_[0.0, draw(rng, 1e-6, 100.0, 3, log=True)]
    c_N, m = _law(rng)
    t_N, dt_N = _power(power_law, g, c_N, m)
    compare("t_N for an open gap", t_N, np.zeros(4), {"g_N": g}, rule="t_N = 0 where g_N >= 0")
    compare("dt_N/dg_N for an open gap", dt_N, np.zeros(4), {"g_N": g})


def power_law_traction_other(power_law, rng):
    g = -draw(rng, 1e-3, 1.0, 3, log=True)
    for _ in range(2):
        c_N, m = _law(rng)
        t_N, _ = _power(power_law, g, c_N, m)
        compare(
            f"t_N (c_N = {c_N:g}, m = {m:g})", t_N, -c_N * (-g) ** m, {"g_N": g}, rule="t_N = -c_N (-g_N)^m in contact"
        )


def power_law_derivative_other(power_law, rng):
    g = -draw(rng, 1e-3, 1.0, 3, log=True)
    for _ in range(2):
        c_N, m = _law(rng)
        _, dt_N = _power(power_law, g, c_N, m)
        compare(
            f"dt_N/dg_N (c_N = {c_N:g}, m = {m:g})",
            dt_N,
            c_N * m * (-g) ** (m - 1.0),
            {"g_N": g},
            rule="dt_N/dg_N = c_N m (-g_N)^(m-1) in contact",
        )


def _tresca_other(Tresca, rng):
    c_T, tau_y = draw(rng, 1.0, 100.0), draw(rng, 0.05, 5.0)
    law = _tresca(Tresca, c_T=c_T, tau_y=tau_y)
    p = np.tile(draw(rng, 0.01, 1000.0, 3, log=True), 2)
    q = np.repeat([0.0, draw(rng, 0.1, 5.0)], 3)
    out = call(law.slip_bound, f"Tresca(c_T={c_T:g}, tau_y={tau_y:g}).slip_bound", p, q)
    return tau_y, p, q, parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def tresca_bound_other(Tresca, rng):
    tau_y, p, q, (Y, _, _) = _tresca_other(Tresca, rng)
    compare(f"slip bound Y (tau_y = {tau_y:g})", Y, np.full(p.shape, tau_y), {"p": p, "q": q}, rule="Y = tau_y")


def tresca_derivatives_other(Tresca, rng):
    tau_y, p, q, (_, Y_p, Y_q) = _tresca_other(Tresca, rng)
    compare(f"dY/dp (tau_y = {tau_y:g})", Y_p, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on p")
    compare(f"dY/dq (tau_y = {tau_y:g})", Y_q, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on q")


def tresca_fields_other(Tresca, rng):
    c_T, tau_y = draw(rng, 1.0, 100.0), draw(rng, 0.05, 5.0)
    law = _tresca(Tresca, c_T=c_T, tau_y=tau_y)
    if getattr(law, "c_T", None) != c_T or getattr(law, "tau_y", None) != tau_y:
        raise AssertionError(f"Tresca(c_T={c_T:g}, tau_y={tau_y:g}) should keep the fields it is given")


HIDDEN = {
    "power_law_open": [power_law_open_far],
    "power_law_traction": [power_law_traction_other],
    "power_law_derivative": [power_law_derivative_other],
    "tresca_fields": [tresca_fields_other],
    "tresca_bound": [tresca_bound_other],
    "tresca_derivatives": [tresca_derivatives_other],
}
