"""The hidden checks of lecture 07: a law and a census length drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import Built, call, compare, draw
from contactfem.lab.course.checks.runs import ScenePart, as_list, counts, memo, scene_model


def escape_other(escape_angle, rng):
    p = draw(rng, 0.01, 30.0, 3, log=True)
    alpha, beta, n = draw(rng, 0.1, 0.8), draw(rng, 0.0, 0.2), draw(rng, 0.4, 0.95)
    got = np.asarray(call(escape_angle, "escape_angle", p, alpha, beta, n), dtype=float)
    compare(
        f"escape angle (deg; alpha = {alpha:g}, beta = {beta:g}, n = {n:g})",
        got,
        np.degrees(np.arctan(alpha * p ** (n - 1.0) + beta)),
        {"p": p},
        rule="tan(phi) = alpha p^(n-1) + beta",
    )


def _census_short(census, steps):
    """The census of the funnel's first steps (its schedule's step, fewer of them)."""
    from contactfem.solver import Steps
    from contactfem.solver.march import march

    funnel = ("funnel", {"variant": "frictional"})

    def student():
        schedule = ScenePart(*funnel, "stage", "schedule").make({})
        stage = [ScenePart(*funnel, "stage", k) for k in ("stepper", "u0", "v0")]
        short = Built(Steps, dt=schedule.dt, n_steps=steps, t0=schedule.t0)
        return call(census, "census", stage[0], short, *stage[1:], timeout=120.0)

    def reference():
        st = scene_model(*funnel)[0].stage
        recs = list(march(st.stepper, Steps(st.schedule.dt, n_steps=steps, t0=st.schedule.t0), st.t0, st.u0, st.v0))
        c = np.array([counts(r) for r in recs], float)
        return np.array([r.t for r in recs]), c[:, 0], c[:, 1]

    got = as_list(memo(("census_short", census, steps), student), 3, "census", "times, contact and slip counts")
    return got, memo(("census_short_ref", steps), reference)


def census_short(census, rng):
    steps = int(rng.integers(8, 17))
    (t, n_c, n_s), (w_t, w_c, w_s) = _census_short(census, steps)
    if t.size != w_t.size:
        raise AssertionError(
            f"on a schedule of {steps} steps your census has {t.size} entries, the run {w_t.size} "
            "records (the initial state included): loop over the schedule you are given"
        )
    at = {"record": np.arange(t.size)}
    compare(f"time of each record ({steps} steps)", t, w_t, at)
    compare(f"nodes in contact ({steps} steps)", n_c, w_c, at)
    compare(f"slipping nodes ({steps} steps)", n_s, w_s, at)


HIDDEN = {
    "escape_values": [escape_other],
    "census_times": [census_short],
    "census_contact": [census_short],
    "census_slip": [census_short],
}
