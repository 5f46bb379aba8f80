"""The hidden checks of lecture 08: a gas column and a hardening law drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw
from contactfem.lab.course.checks.cork import _hardening_ref, _hardening_return


def gas_other(gas_pressure, rng):
    p0, V0, area, travel = (
        draw(rng, 0.5, 5.0),
        draw(rng, 100.0, 1e4, log=True),
        draw(rng, 10.0, 300.0),
        draw(rng, 5, 30),
    )
    du = np.r_[0.0, draw(rng, 0.0, 0.99, 2) * travel, travel, travel * draw(rng, 1.01, 2.0)]
    got = np.asarray(call(gas_pressure, "gas_pressure", p0, V0, area, du, travel), dtype=float)
    want = np.where(du < travel, p0 * V0 / (V0 + area * du), 0.0)
    compare(f"gas pressure (p0 = {p0:g}, V0 = {V0:g}, area = {area:g}, travel = {travel:g})", got, want, {"du": du})


def hardening_return_other(hardening_return, rng):
    c_T, mu0, h = draw(rng, 2.0, 20.0), draw(rng, 0.1, 0.5), draw(rng, 0.01, 0.5)
    for _ in range(2):
        p, q_bar = draw(rng, 0.5, 4.0), draw(rng, 0.0, 2.0)
        Y = (mu0 + h * q_bar) * p
        t_bar = draw(rng, -0.8, 0.8) * Y
        dg = float(f"{rng.choice([-1.0, 1.0]) * draw(rng, 2.0, 5.0) * Y / c_T:.3g}")  # a slip step
        got = _hardening_return(hardening_return, t_bar, dg, p, q_bar, c_T=c_T, mu0=mu0, h=h)
        want = _hardening_ref(t_bar, dg, p, q_bar, c_T=c_T, mu0=mu0, h=h)
        compare(
            f"(t_T, lambda, q) (c_T = {c_T:g}, mu0 = {mu0:g}, h = {h:g})",
            np.array(got),
            np.array(want),
            {"value": ["t_T", "lambda", "q"]},
        )


HIDDEN = {
    "gas_boyle": [gas_other],
    "gas_release": [gas_other],
    "hardening_slip": [hardening_return_other],
    "hardening_lambda_q": [hardening_return_other],
}
