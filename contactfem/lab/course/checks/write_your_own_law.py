"""The checks of lecture 10: your own law."""

import numpy as np

from .answers import call, compare, defined, parts
from .exercise import exercise

LECTURE = "10_write_your_own_law"


def _hardening(LinearHardening):
    defined(LinearHardening, "LinearHardening", "class")
    try:
        law = LinearHardening(c_T=30.0, mu_0=0.3, h=0.5)
    except Exception as err:
        raise AssertionError(f"LinearHardening(c_T=30.0, mu_0=0.3, h=0.5) raised {type(err).__name__}: {err}") from None
    p = np.array([0.5, 1.0, 2.0, 0.5, 1.0, 2.0])
    q = np.array([0.0, 0.0, 0.0, 0.2, 0.4, 0.8])
    out = call(law.slip_bound, "LinearHardening(c_T=30.0, mu_0=0.3, h=0.5).slip_bound", p, q)
    Y, Y_p, Y_q = parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")
    return law, p, q, Y, Y_p, Y_q


def hardening_bound(LinearHardening):
    law, p, q, Y, Y_p, Y_q = _hardening(LinearHardening)
    compare("Y (mu_0 = 0.3, h = 0.5)", Y, (0.3 + 0.5 * q) * p, {"p": p, "q": q})


def hardening_derivatives(LinearHardening):
    law, p, q, Y, Y_p, Y_q = _hardening(LinearHardening)
    compare("dY/dp", Y_p, 0.3 + 0.5 * q + 0 * p, {"p": p, "q": q})
    compare("dY/dq", Y_q, 0.5 * p, {"p": p, "q": q})


def hardening_check_law(LinearHardening):
    from ....laws.check import check_law

    law = _hardening(LinearHardening)[0]
    report = check_law(law)
    if not report.ok:
        raise AssertionError(
            "check_law(LinearHardening(c_T=30.0, mu_0=0.3, h=0.5)) fails: "
            + [s for ok, s in report.checks if not ok][0]
        )


def _cubic(QuadraticNormal):
    defined(QuadraticNormal, "QuadraticNormal", "class")
    try:
        law = QuadraticNormal(c_N=200.0)
    except Exception as err:
        raise AssertionError(f"QuadraticNormal(c_N=200.0) raised {type(err).__name__}: {err}") from None
    return law


def quadratic_traction(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    g = np.array([0.05, 0.0, -0.01, -0.1, -0.3])
    out = call(law.traction, "QuadraticNormal(c_N=200.0).traction", g)
    t_N, dt_N = parts(out, 2, "traction", "t_N and dt_N/dg_N")
    compare("t_N (c_N = 200)", t_N, np.where(g < 0, -200.0 * g**2, 0.0), {"g_N": g})
    compare("dt_N/dg_N (c_N = 200)", dt_N, np.where(g < 0, -400.0 * g, 0.0), {"g_N": g})


def quadratic_energy(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    if not callable(getattr(law, "energy", None)):
        raise AssertionError("QuadraticNormal needs a method energy(self, g_N): the stored energy of the interface")
    g = np.array([0.05, 0.0, -0.01, -0.1, -0.3])
    E = np.asarray(call(law.energy, "QuadraticNormal(c_N=200.0).energy", g), dtype=float)
    compare("energy for an open gap", E[:2], np.zeros(2), {"g_N": g[:2]})
    if np.any(E[2:] < 0):
        raise AssertionError("your energy is negative in contact: the interface stores energy, >= 0")


def quadratic_energy_gradient(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    g = np.array([-0.01, -0.1, -0.3])
    h = 1e-6
    E = lambda x: np.asarray(call(law.energy, "QuadraticNormal(c_N=200.0).energy", x), dtype=float)
    fd = (E(g + h) - E(g - h)) / (2 * h)
    t_N = -200.0 * g**2
    compare(
        "d energy / d g_N (finite differences of your energy)",
        fd,
        t_N,
        {"g_N": g},
        rtol=1e-5,
        rule="the energy's derivative is the traction t_N",
    )


EXERCISES = [
    exercise(
        "ex10_linear_hardening",
        LECTURE,
        "easy",
        True,
        "a slip-hardening friction law with its derivatives, passing check_law",
        (hardening_bound, 2),
        (hardening_derivatives, 2),
        (hardening_check_law, 1),
    ),
    exercise(
        "ex10_quadratic_normal",
        LECTURE,
        "medium",
        True,
        "a normal law with its stored energy, the energy checked against the traction",
        (quadratic_traction, 2),
        (quadratic_energy, 1),
        (quadratic_energy_gradient, 2),
    ),
]


LIBRARY = {
    "ex10_linear_hardening": ("contactfem.laws.friction:SlipHardening",),
    "ex10_quadratic_normal": ("contactfem.laws.normal:PowerLaw",),
}
