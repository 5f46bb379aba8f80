"""The hidden checks of lecture 10: the students' laws at parameters drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, defined, draw, parts


def _made(cls, name, **kw):
    defined(cls, name, "class")
    text = f"{name}({', '.join(f'{k}={v:g}' for k, v in kw.items())})"
    try:
        return cls(**kw), text
    except Exception as err:
        raise AssertionError(f"{text} raised {type(err).__name__}: {err}") from None


def hardening_other(LinearHardening, rng):
    mu_0, h = draw(rng, 0.05, 0.6), draw(rng, 0.1, 5.0)
    law, text = _made(LinearHardening, "LinearHardening", c_T=draw(rng, 1.0, 50.0), mu_0=mu_0, h=h)
    p = np.tile(draw(rng, 0.01, 100.0, 3, log=True), 2)
    q = np.r_[0.0, 0.0, 0.0, draw(rng, 0.01, 3.0, 3)]
    Y, Y_p, Y_q = parts(call(law.slip_bound, f"{text}.slip_bound", p, q), 3, "slip_bound", "Y, dY/dp, dY/dq")
    at = {"p": p, "q": q}
    compare(f"Y (mu_0 = {mu_0:g}, h = {h:g})", Y, (mu_0 + h * q) * p, at, rule="Y = (mu_0 + h q) p")
    compare(f"dY/dp (mu_0 = {mu_0:g}, h = {h:g})", Y_p, mu_0 + h * q + 0 * p, at)
    compare(f"dY/dq (mu_0 = {mu_0:g}, h = {h:g})", Y_q, h * p, at)


def _quadratic(QuadraticNormal, rng):
    c_N = draw(rng, 1.0, 1000.0, log=True)
    law, text = _made(QuadraticNormal, "QuadraticNormal", c_N=c_N)
    return law, text, c_N, np.r_[draw(rng, 0.01, 1.0), -draw(rng, 1e-3, 2.0, 3, log=True)]


def quadratic_other(QuadraticNormal, rng):
    law, text, c_N, g = _quadratic(QuadraticNormal, rng)
    t_N, dt_N = parts(call(law.traction, f"{text}.traction", g), 2, "traction", "t_N, dt_N/dg_N")
    compare(f"t_N (c_N = {c_N:g})", t_N, np.where(g < 0, -c_N * g**2, 0.0), {"g_N": g})
    compare(f"dt_N/dg_N (c_N = {c_N:g})", dt_N, np.where(g < 0, -2 * c_N * g, 0.0), {"g_N": g})


def quadratic_energy_other(QuadraticNormal, rng):
    law, text, c_N, g = _quadratic(QuadraticNormal, rng)
    E = np.asarray(call(law.energy, f"{text}.energy", g), dtype=float)
    compare(
        f"energy (c_N = {c_N:g})",
        E,
        np.where(g < 0, c_N * (-g) ** 3 / 3.0, 0.0),
        {"g_N": g},
        rule="the energy whose derivative is t_N = -c_N g_N^2: c_N (-g_N)^3 / 3",
    )


HIDDEN = {
    "hardening_bound": [hardening_other],
    "hardening_derivatives": [hardening_other],
    "quadratic_traction": [quadratic_other],
    "quadratic_energy": [quadratic_energy_other],
}
