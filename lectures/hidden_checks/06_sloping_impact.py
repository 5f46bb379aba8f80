"""The hidden checks of lecture 06: a history and an interface drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw, parts
from contactfem.lab.course.checks.sloping_impact import _energy_ref, _interface, _rebound_case


def rebound_other(rebound, rng):
    n = int(rng.integers(8, 14))
    k_last = int(rng.integers(4, n - 2))
    v, contact = _rebound_case(k_last=k_last, n=n)
    leave = (draw(rng, -2.0, 2.0), draw(rng, 0.5, 3.0))
    v[k_last + 1 :] = leave
    out = parts(call(rebound, "rebound", v, contact), 3, "rebound", "v_x, v_y and the angle")
    got = np.array([float(np.asarray(x)) for x in out])
    want = np.array([*leave, np.degrees(np.arctan2(abs(leave[0]), abs(leave[1])))])
    compare(f"(v_x, v_y, angle) leaving at {leave}", got, want, {"value": ["v_x", "v_y", "angle"]})


def energy_other(interface_energy, rng):
    g = np.r_[-draw(rng, 0.001, 0.5, 3, log=True), draw(rng, 0.01, 0.5)]
    t_T = np.r_[draw(rng, -3.0, 3.0, 3), 0.0]
    w = draw(rng, 0.2, 3.0, 4)
    c_N, m, c_T = draw(rng, 1.0, 100.0, log=True), draw(rng, 1.0, 2.5), draw(rng, 1.0, 50.0)
    got = _interface(interface_energy, g, t_T, w, c_N, m, c_T)
    compare(
        f"interface energy (c_N = {c_N:g}, m = {m:g}, c_T = {c_T:g})",
        got,
        _energy_ref(g, t_T, w, c_N, m, c_T),
        {"g_N": ", ".join(f"{x:g}" for x in g)},
    )


HIDDEN = {
    "rebound_velocity": [rebound_other],
    "rebound_angle": [rebound_other],
    "energy_friction": [energy_other],
}
