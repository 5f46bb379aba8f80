"""The hidden checks of the course's exercises: instructor material, not part of the installed
package and not in the student notebooks.

`contactfem course grade` reads this file (from the folder given by --autograders, else from
the checkout's lectures/) and runs it in its own process, never in the submission's. A part of
an exercise scores its points when its public check (contactfem.lab.course.checks) and every
hidden check listed for it in HIDDEN pass: the hidden ones ask the same question at other
parameters and points, so an answer fitted to the public checks' values does not pass them.

HIDDEN maps the name of a public part to its hidden checks; each takes the same student
answers (by name) as the part it belongs to, and raises AssertionError with a hint.
"""

import numpy as np

from contactfem.lab.course.checks import _tresca, call, compare, parts


# -- lecture 01 ---------------------------------------------------------------------------------

def _power(power_law, g, c_N, m):
    return parts(call(power_law, "power_law", g, c_N, m), 2, "power_law", "t_N and dt_N/dg_N")


def power_law_open_far(power_law):
    g = np.array([1e-9, 3.0, 250.0])
    t_N, dt_N = _power(power_law, g, 37.0, 1.5)
    compare("t_N for an open gap", t_N, np.zeros(3), {"g_N": g}, rule="t_N = 0 where g_N >= 0")
    compare("dt_N/dg_N for an open gap", dt_N, np.zeros(3), {"g_N": g})


def power_law_traction_other(power_law):
    g = np.array([-0.003, -0.07, -0.9])
    for c_N, m in ((37.0, 1.5), (2.0e4, 3.0)):
        t_N, _ = _power(power_law, g, c_N, m)
        compare(f"t_N (c_N = {c_N:g}, m = {m:g})", t_N, -c_N * (-g) ** m, {"g_N": g},
                rule="t_N = -c_N (-g_N)^m in contact")


def power_law_derivative_other(power_law):
    g = np.array([-0.003, -0.07, -0.9])
    for c_N, m in ((37.0, 1.5), (2.0e4, 3.0)):
        _, dt_N = _power(power_law, g, c_N, m)
        compare(f"dt_N/dg_N (c_N = {c_N:g}, m = {m:g})", dt_N, c_N * m * (-g) ** (m - 1.0), {"g_N": g},
                rule="dt_N/dg_N = c_N m (-g_N)^(m-1) in contact")


def _tresca_other(Tresca):
    law = _tresca(Tresca, c_T=7.0, tau_y=1.3)
    p = np.array([0.01, 2.0, 900.0, 0.01, 2.0, 900.0])
    q = np.array([0.0, 0.0, 0.0, 5.0, 5.0, 5.0])
    out = call(law.slip_bound, "Tresca(c_T=7.0, tau_y=1.3).slip_bound", p, q)
    return p, q, parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def tresca_bound_other(Tresca):
    p, q, (Y, _, _) = _tresca_other(Tresca)
    compare("slip bound Y (tau_y = 1.3)", Y, np.full(p.shape, 1.3), {"p": p, "q": q}, rule="Y = tau_y")


def tresca_derivatives_other(Tresca):
    p, q, (_, Y_p, Y_q) = _tresca_other(Tresca)
    compare("dY/dp (tau_y = 1.3)", Y_p, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on p")
    compare("dY/dq (tau_y = 1.3)", Y_q, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on q")


def tresca_fields_other(Tresca):
    law = _tresca(Tresca, c_T=7.0, tau_y=1.3)
    if getattr(law, "c_T", None) != 7.0 or getattr(law, "tau_y", None) != 1.3:
        raise AssertionError("Tresca(c_T=7.0, tau_y=1.3) should keep the fields it is given")


# -- lecture 02 ---------------------------------------------------------------------------------

def circle_gap_value_other(circle_gap):
    x_s = np.array([[-2.0, 1.4], [-1.0, 0.5], [-2.3, 0.1], [0.5, -3.0]])
    c, R = np.array([-2.0, 0.5]), 0.7
    g_N, n = parts(call(circle_gap, "circle_gap", x_s, c, R), 2, "circle_gap", "g_N and n")
    d = x_s - c
    r = np.linalg.norm(d, axis=1)
    at = {"x_s": [f"({x:g}, {y:g})" for x, y in x_s]}
    compare("g_N (centre (-2, 0.5), R = 0.7)", g_N, r - R, at, rule="g_N = |x_s - centre| - R")
    compare("n (centre (-2, 0.5), R = 0.7)", np.asarray(n, float), d / r[:, None],
            {"x_s": np.repeat(np.array(at["x_s"])[:, None], 2, axis=1)}, rule="n = (x_s - centre)/|x_s - centre|")


# -- lecture 12 ---------------------------------------------------------------------------------

def _cn_other(C_N):
    from contactfem.contact.complementarity import normal_complementarity

    t_N = np.array([-7.0, -0.1, 0.0, -0.4, -2.5])
    g_N = np.array([-0.2, 0.05, 1.0, -0.001, 0.4])
    C, dt, dg = (np.asarray(x, float) for x in parts(call(C_N, "C_N", t_N, g_N, 3.0), 3, "C_N",
                                                    "C_N, dC_N/dt_N and dC_N/dg_N"))
    return C, dt, dg, normal_complementarity(t_N, g_N, 3.0), {"t_N": t_N, "g_N": g_N}


def cn_values_other(C_N):
    C, _, _, want, at = _cn_other(C_N)
    compare("C_N (c_N = 3)", C, want[0], at, rule="C_N = p - max(0, p - c_N g_N) with p = -t_N")


def cn_derivatives_other(C_N):
    _, dt, dg, want, at = _cn_other(C_N)
    compare("dC_N/dt_N (c_N = 3)", dt, want[1], at)
    compare("dC_N/dg_N (c_N = 3)", dg, want[2], at)


HIDDEN = {
    "power_law_open": [power_law_open_far],
    "power_law_traction": [power_law_traction_other],
    "power_law_derivative": [power_law_derivative_other],
    "tresca_fields": [tresca_fields_other],
    "tresca_bound": [tresca_bound_other],
    "tresca_derivatives": [tresca_derivatives_other],
    "circle_gap_value": [circle_gap_value_other],
    "cn_values": [cn_values_other],
    "cn_derivatives": [cn_derivatives_other],
}
