"""The checks of lecture 05: the rolling ring."""

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise
from .runs import as_list, memo

LECTURE = "05_rolling_ring"

ROLLING_CASES = (
    (300.0, 0.15, 981.0, 50.0, 2500.0),
    (300.0, 0.15, 981.0, 50.0, 1250.0),
    (200.0, 0.3, 981.0, 55.0, 2700.0),
)


def _rolling(rolling_point):
    out = []
    for v0, mu, g, a, k2 in ROLLING_CASES:
        got = parts(call(rolling_point, "rolling_point", v0, mu, g, a, k2), 3, "rolling_point", "t*, x*, v*")
        try:
            got = [float(np.asarray(x)) for x in got]
        except (TypeError, ValueError):
            raise AssertionError(f"rolling_point should return three numbers (t*, x*, v*), got {got!r:.80}") from None
        out.append(got)
    from ....scenes.rings import rigid_ring_exact

    ref = [rigid_ring_exact(v0, mu, g, a, k2) for v0, mu, g, a, k2 in ROLLING_CASES]
    at = {
        "v0": [c[0] for c in ROLLING_CASES],
        "mu": [c[1] for c in ROLLING_CASES],
        "a": [c[3] for c in ROLLING_CASES],
        "k^2": [c[4] for c in ROLLING_CASES],
    }
    return np.array(out), ref, at


def rolling_time(rolling_point):
    got, ref, at = _rolling(rolling_point)
    want = np.array([r["t_star"] for r in ref])
    no_spin = np.array([c[0] / (c[1] * c[2]) for c in ROLLING_CASES])
    if np.allclose(got[:, 0], no_spin):
        raise AssertionError(
            "your t* = v0 / (mu g) is when the centre would stop; rolling starts earlier, when "
            "the contact point stops: v(t) + omega(t) a = 0 with omega spun up by the friction "
            "torque, t* = v0 / (mu g (1 + a^2/k^2))"
        )
    compare("t* (the start of rolling)", got[:, 0], want, at, rule="t* = v0 / (mu g (1 + a^2/k^2))")


def rolling_position(rolling_point):
    got, ref, at = _rolling(rolling_point)
    compare(
        "x* (the centre when rolling starts)",
        got[:, 1],
        np.array([r["x_star"] for r in ref]),
        at,
        rule="x* = v0 t* - mu g t*^2 / 2 (uniform deceleration mu g while sliding)",
    )


def rolling_speed(rolling_point):
    got, ref, at = _rolling(rolling_point)
    compare(
        "v* (the rolling speed)",
        got[:, 2],
        np.array([r["v_star"] for r in ref]),
        at,
        rule="v* = v0 - mu g t*; for the thin hoop (k = a) v* = v0 / 2",
    )


def _incline(ring_on_incline, theta, mu):
    def run():
        out = call(ring_on_incline, "ring_on_incline", theta, mu, timeout=120.0)
        t, s = as_list(out, 2, "ring_on_incline", "the times and the centre's travel down the slope")
        return t, s

    return memo(("incline", ring_on_incline, theta, mu), run)


def _acceleration(t, s):
    """The centre's acceleration along the slope: s = s0 + v0 t + a t^2 / 2 by least squares."""
    return 2.0 * np.polyfit(t, s, 2)[0]


def incline_start(ring_on_incline):
    t, s = _incline(ring_on_incline, 20.0, 0.5)
    if t.size < 10:
        raise AssertionError(f"ring_on_incline should return one time and one travel per record, got {t.size}")
    if abs(t[0]) > 1e-12 or abs(s[0]) > 1e-9:
        raise AssertionError(
            f"the first record is the initial state: t = 0 and no travel yet; yours has t = {t[0]:.3g}, "
            f"s = {s[0]:.3g} (measure s from the centre's initial position)"
        )
    if s[-1] <= 0:
        raise AssertionError(
            f"your travel at the end is {s[-1]:.3g} <= 0: s is the distance the centre has moved "
            "DOWN the slope, (x_c(t) - x_c(0)) . d with d = (-cos theta, -sin theta) for a plane "
            "rising to the right"
        )


def _incline_verdict(what, a, want, theta, mu, rtol):
    g = 981.0
    th = np.radians(theta)
    others = {
        "a ring sliding without friction, g sin(theta)": g * np.sin(th),
        "a ring sliding with friction, g (sin(theta) - mu cos(theta))": g * (np.sin(th) - mu * np.cos(th)),
        "a hoop rolling without slip, g sin(theta) / 2": g * np.sin(th) / 2,
        "a free fall, g": g,
    }
    if abs(a / want - 1) <= rtol:
        return
    close = [k for k, v in others.items() if v > 0 and abs(a / v - 1) <= rtol]
    hint = f" (that is {close[0]})" if close else ""
    raise AssertionError(
        f"at theta = {theta:g} deg, mu = {mu:g} your ring's acceleration along the slope is "
        f"{a:.4g} cm/s^2{hint}; {what} gives {want:.4g} (within {100 * rtol:g} %): check the "
        "plane's normal (towards the ring), gravity (down, -y), the friction law and its mu"
    )


def incline_rolling(ring_on_incline):
    """tan(20 deg) = 0.36 <= 2 mu = 1: the hoop rolls, a = g sin(theta) / 2. The scene's ring on
    its fast mesh (40 beam elements, dt = 0.02) gives +0.8 % (its polygon rocks over its corners,
    its stick springs settle at the start): 5 % leaves room for another ring of this lecture
    and is far from every other motion (sliding: twice that)."""
    t, s = _incline(ring_on_incline, 20.0, 0.5)
    _incline_verdict("rolling without slip", _acceleration(t, s), 981.0 * np.sin(np.radians(20.0)) / 2, 20.0, 0.5, 0.05)


def incline_sliding(ring_on_incline):
    """tan(30 deg) = 0.58 > 2 mu = 0.3: the ring slides all the way, a = g (sin - mu cos), a
    constant friction force: the fast ring gives +0.5 %, checked to 3 %."""
    th = np.radians(30.0)
    t, s = _incline(ring_on_incline, 30.0, 0.15)
    _incline_verdict(
        "sliding with Coulomb friction", _acceleration(t, s), 981.0 * (np.sin(th) - 0.15 * np.cos(th)), 30.0, 0.15, 0.03
    )


EXERCISES = [
    exercise(
        "ex05_rolling_point",
        LECTURE,
        "easy",
        False,
        "the start of rolling of a rigid ring of any radius of gyration (closed form)",
        (rolling_time, 2),
        (rolling_position, 2),
        (rolling_speed, 1),
    ),
    exercise(
        "ex05_incline",
        LECTURE,
        "hard",
        True,
        "a new scene from parts: the ring on an inclined plane, rolling or sliding",
        (incline_start, 1),
        (incline_rolling, 2),
        (incline_sliding, 2),
    ),
]


BUILDS_ON = {
    "ex05_incline": "the ring, the plane and the stepper are the library's; the answer is the new scene",
}
