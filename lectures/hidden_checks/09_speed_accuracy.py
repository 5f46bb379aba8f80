"""The hidden checks of lecture 09: errors and residuals drawn from the grader's seed, and the tight tolerance."""

import numpy as np

from contactfem.lab.course.checks.answers import call, compare, draw
from contactfem.lab.course.checks.speed_accuracy import (
    _band,
    _library_band,
    tolerance_budget_at,
    tolerance_error_at,
    tolerance_indicators_at,
)


def observed_order_other(observed_order, rng):
    h = np.sort(draw(rng, 0.01, 0.5, 5, log=True))[::-1]
    order, C = draw(rng, 0.5, 4.0), draw(rng, 0.1, 10.0, log=True)
    e = -C * h**order * draw(rng, 0.8, 1.25, 5)
    want = np.polyfit(np.log(h), np.log(np.abs(e)), 1)[0]
    compare(
        f"observed order of e ~ -{C:g} h^{order:g} (noisy)",
        call(observed_order, "observed_order", h, e),
        want,
        {"h": ", ".join(f"{x:g}" for x in h)},
        rtol=1e-8,
    )


def convergence_order_other(convergence_order, rng):
    q, C = draw(rng, 1.5, 3.0), draw(rng, 0.3, 1.0)
    r = [draw(rng, 0.5, 0.9)]
    for _ in range(4):
        r.append(C * r[-1] ** q)
    r = np.array(r)
    want = np.log(r[-1] / r[-2]) / np.log(r[-2] / r[-3])
    compare(
        f"convergence order of r_(k+1) = {C:g} r_k^{q:g} (last three)",
        call(convergence_order, "convergence_order", r),
        want,
        {"r": f"{r[0]:g}, {r[1]:.4g}, ..."},
        rtol=1e-8,
    )


def tolerance_indicators_tight(settings_for, rng):
    tolerance_indicators_at(settings_for, 0.01)


def tolerance_error_tight(settings_for, rng):
    tolerance_error_at(settings_for, 0.01)


def tolerance_budget_tight(settings_for, rng):
    tolerance_budget_at(settings_for, 0.01)


def _band_cases(rng):
    """Monotone levels drawn from the seed, f = f_exact + C h^p at h, r h, r^2 h, for p_th 1 and 2."""
    for p_th in (1.0, 2.0):
        f_exact, C, p, r = draw(rng, -5.0, 5.0), draw(rng, 0.1, 3.0, log=True), draw(rng, 0.6, 2.4), draw(rng, 1.5, 3.0)
        f = tuple(f_exact + C * (0.05 * r**k) ** p for k in range(3))
        yield f, r, p_th, {"f": ", ".join(f"{x:.6g}" for x in f), "r": f"{r:g}", "p_th": f"{p_th:g}"}


def band_order_other(band_from_three, rng):
    for f, r, p_th, at in _band_cases(rng):
        got = _band(band_from_three, f, r, p_th)[0]
        compare("the observed order", got, _library_band(f, r, p_th)["observed_order"], at, rtol=1e-8)


def band_richardson_other(band_from_three, rng):
    for f, r, p_th, at in _band_cases(rng):
        got = _band(band_from_three, f, r, p_th)[1]
        compare("Richardson's value", got, _library_band(f, r, p_th)["richardson"], at, rtol=1e-8)


def band_factor_of_safety_other(band_from_three, rng):
    for f, r, p_th, at in _band_cases(rng):
        got = _band(band_from_three, f, r, p_th)[2]
        compare("the band", got, _library_band(f, r, p_th)["band"], at, rtol=1e-8)


HIDDEN = {
    "observed_order_least_squares": [observed_order_other],
    "convergence_order_quadratic": [convergence_order_other],
    "tolerance_indicators": [tolerance_indicators_tight],
    "tolerance_error": [tolerance_error_tight],
    "tolerance_budget": [tolerance_budget_tight],
    "band_order": [band_order_other],
    "band_richardson": [band_richardson_other],
    "band_factor_of_safety": [band_factor_of_safety_other],
}
