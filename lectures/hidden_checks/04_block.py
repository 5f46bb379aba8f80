"""The hidden checks of lecture 04: a Coulomb law and a number of load steps drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw
from contactfem.lab.course.checks.block import _load_steps, _load_steps_ref


def margin_other(slip_margin, rng):
    from contactfem.laws import Coulomb

    mu = draw(rng, 0.1, 0.9)
    law = Coulomb(c_T=draw(rng, 10.0, 1e4, log=True), mu=mu)
    t_N = -draw(rng, 0.1, 20.0, 4)
    t_T = draw(rng, -1.5, 1.5, 4) * mu * -t_N
    got = np.asarray(call(slip_margin, "slip_margin", t_N, t_T, law), dtype=float)
    compare(f"f = |t_T| - mu |t_N| (Coulomb, mu = {mu:g})", got, np.abs(t_T) + mu * t_N, {"t_N": t_N, "t_T": t_T})


def load_steps_other(load_steps, rng):
    n = int(rng.integers(2, 4))
    t, its, slip = _load_steps(load_steps, n)
    want = _load_steps_ref(n)
    if t.size != n:
        raise AssertionError(f"load_steps(stepper, {n}) should give one entry per load step, {n}, got {t.size}")
    compare(
        f"the load in {n} steps: (t, solves, slipping nodes)",
        np.r_[t, its, slip],
        np.r_[want[0], want[1], want[2]],
        {"entry": [f"{what}{k}" for what in ("t", "solves", "slip") for k in range(1, n + 1)]},
        rule="Steps(1 / n, n_steps=n), rec.iterations, the SLIP states of each record",
    )


HIDDEN = {
    "margin_coulomb": [margin_other],
    "load_steps_times": [load_steps_other],
    "load_steps_slipping": [load_steps_other],
}
