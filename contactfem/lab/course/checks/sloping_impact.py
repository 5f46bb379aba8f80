"""The checks of lecture 06: the sloping impact."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "06_sloping_impact"


def _rebound_case(k_last=6, n=12):
    """A centre-of-mass history: flying in at (2, -2), in contact for records 3..k_last, then
    leaving at (1.2, 1.7) and slowly drifting (a vibrating ring's centre is not exactly constant)."""
    v = np.zeros((n, 2))
    v[:3] = (2.0, -2.0)
    v[3 : k_last + 1] = np.linspace([1.8, -1.0], [1.3, 1.5], k_last - 2)
    v[k_last + 1 :] = (1.2, 1.7) + 0.01 * np.arange(n - k_last - 1)[:, None]
    contact = np.zeros(n, bool)
    contact[3 : k_last + 1] = True
    return v, contact


def _rebound_call(rebound, v, contact):
    return call(rebound, "rebound", v, contact)


def rebound_velocity(rebound):
    v, contact = _rebound_case()
    out = parts(_rebound_call(rebound, v, contact), 3, "rebound", "v_x, v_y and the angle")
    got = np.array([float(np.asarray(x)) for x in out[:2]])
    if np.allclose(got, v[-1]):
        raise AssertionError(
            "your rebound velocity is the last record's: take the first record after the last "
            "one in contact (the ring has just left the plane)"
        )
    compare(
        "rebound velocity (v_x, v_y)",
        got,
        v[7],
        {"component": ["v_x", "v_y"]},
        rule="the centre's velocity at the first record after the last record in contact",
    )


def rebound_angle(rebound):
    v, contact = _rebound_case()
    out = parts(_rebound_call(rebound, v, contact), 3, "rebound", "v_x, v_y and the angle")
    angle = float(np.asarray(out[2]))
    vx, vy = v[7]
    want = float(np.degrees(np.arctan2(abs(vx), abs(vy))))
    if math.isclose(angle, 90.0 - want, rel_tol=1e-6):
        raise AssertionError(
            f"your angle {angle:.4g} deg is measured from the plane; Table 2's angle of reflection "
            f"is measured from the normal: atan(|v_x| / |v_y|) = {want:.4g} deg"
        )
    if math.isclose(angle, np.radians(want), rel_tol=1e-6):
        raise AssertionError(f"your angle {angle:.4g} is in radians: give degrees (np.degrees)")
    compare(
        "angle of reflection (deg)",
        angle,
        want,
        {"v": f"({vx:g}, {vy:g})"},
        rule="atan(|v_x| / |v_y|), from the normal, in degrees",
    )


def rebound_none(rebound):
    v, contact = _rebound_case()
    contact[-1] = True
    out = call(rebound, "rebound", v, contact)
    if not (isinstance(out, tuple) and len(out) == 3 and all(x is None for x in out)):
        raise AssertionError(
            "when the ring is still in contact at the last record it has not rebounded: "
            f"return (None, None, None); yours returned {out!r:.80}"
        )


def _energy_cases():
    g = np.array([-0.02, -0.1, 0.05, -0.3, 0.0, -0.05])
    t_T = np.array([0.3, -1.2, 0.0, 2.0, 0.0, -0.4])
    w = np.array([1.0, 0.5, 1.0, 2.0, 1.0, 1.5])
    return g, t_T, w


def _interface(interface_energy, g, t_T, w, c_N, m, c_T):
    out = call(interface_energy, "interface_energy", g, t_T, w, c_N, m, c_T)
    try:
        return float(np.asarray(out, dtype=float))
    except (TypeError, ValueError):
        raise AssertionError(
            f"interface_energy should return one number (the sum over the nodes), got {out!r:.80}"
        ) from None


def _energy_ref(g, t_T, w, c_N, m, c_T):
    from ....laws import PowerLaw

    W = PowerLaw(c_N=c_N, m=m).energy(g)
    return float(np.sum(w * (W + (t_T**2 / (2 * c_T) if c_T else 0.0))))


def energy_normal(interface_energy):
    g, t_T, w = _energy_cases()
    for m in (1.0, 1.5):
        got = _interface(interface_energy, g, 0 * t_T, w, 50.0, m, 30.0)
        want = _energy_ref(g, 0 * t_T, w, 50.0, m, 30.0)
        if math.isclose(got, (m + 1) * want, rel_tol=1e-8):
            raise AssertionError(
                f"your normal energy is (m + 1) times too large (m = {m:g}): the potential of "
                "t_N = -c_N (-g_N)^m is c_N (-g_N)^(m+1) / (m + 1)"
            )
        if math.isclose(got, float(np.sum(_power_energy(g, 50.0, m))), rel_tol=1e-8) and not np.allclose(w, 1):
            raise AssertionError("your energy leaves out the weights: each node's energy counts with its weight w")
        compare(
            f"interface energy without friction (c_N = 50, m = {m:g})",
            got,
            want,
            {"g_N": "-0.02 ... -0.3"},
            rule="sum_i w_i c_N (-g_N,i)^(m+1) / (m + 1) over the nodes in contact (g_N < 0)",
        )


def _power_energy(g, c_N, m):
    """The potential of eq (4) per node, without weights."""
    return np.where(g < 0, c_N * np.abs(np.minimum(g, 0)) ** (m + 1) / (m + 1), 0.0)


def energy_open(interface_energy):
    g = np.array([0.05, 0.2, 0.0])
    got = _interface(interface_energy, g, np.zeros(3), np.ones(3), 50.0, 1.0, 30.0)
    compare(
        "interface energy of open nodes",
        got,
        0.0,
        {"g_N": "0.05, 0.2, 0"},
        rule="an open node (g_N >= 0) stores no energy: use np.where(g_N < 0, ..., 0)",
    )


def energy_friction(interface_energy):
    g, t_T, w = _energy_cases()
    got = _interface(interface_energy, g, t_T, w, 50.0, 1.0, 30.0)
    want = _energy_ref(g, t_T, w, 50.0, 1.0, 30.0)
    normal = _energy_ref(g, 0 * t_T, w, 50.0, 1.0, 30.0)
    if math.isclose(got, normal, rel_tol=1e-8):
        raise AssertionError(
            "your energy leaves out the stick springs: a node in stick stores t_T^2 / (2 c_T) (eq 5: t_T = c_T g_T^e)"
        )
    compare(
        "interface energy with friction (c_T = 30)",
        got,
        want,
        {"t_T": "0.3 ... -0.4"},
        rule="add sum_i w_i t_T,i^2 / (2 c_T), the energy of the stick springs",
    )


EXERCISES = [
    exercise(
        "ex06_rebound",
        LECTURE,
        "easy",
        False,
        "the rebound velocity and the angle of reflection of Table 2 from a centre-of-mass history",
        (rebound_velocity, 2),
        (rebound_angle, 2),
        (rebound_none, 1),
    ),
    exercise(
        "ex06_interface_energy",
        LECTURE,
        "medium",
        True,
        "the energy stored in the interface (penalty potential and stick springs), the energy check's term",
        (energy_normal, 2),
        (energy_open, 1),
        (energy_friction, 2),
    ),
]
