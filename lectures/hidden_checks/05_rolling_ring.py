"""The hidden checks of lecture 05: a ring drawn from the grader's seed (the incline's scene runs are public only:
two runs of up to 120 s each)."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw, parts


def rolling_other(rolling_point, rng):
    from contactfem.scenes.rings import rigid_ring_exact

    a = draw(rng, 20.0, 80.0)
    case = (draw(rng, 50.0, 400.0), draw(rng, 0.1, 0.5), 981.0, a, draw(rng, 0.3, 1.0) * a**2)
    got = parts(call(rolling_point, "rolling_point", *case), 3, "rolling_point", "t*, x*, v*")
    ref = rigid_ring_exact(*case)
    compare(
        "(t*, x*, v*) at v0 = {:g}, mu = {:g}, a = {:g}, k^2 = {:g}".format(*case[:2], *case[3:]),
        np.array([float(np.asarray(x)) for x in got]),
        np.array([ref["t_star"], ref["x_star"], ref["v_star"]]),
        {"value": ["t*", "x*", "v*"]},
    )


HIDDEN = {
    "rolling_time": [rolling_other],
    "rolling_position": [rolling_other],
    "rolling_speed": [rolling_other],
}
