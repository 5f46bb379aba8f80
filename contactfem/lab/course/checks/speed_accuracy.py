"""The checks of lecture 09: speed against accuracy."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "09_speed_accuracy"


def observed_order_exact(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    for p, C in ((2.0, 3.0), (1.0, 0.5)):
        got = call(observed_order, "observed_order", h, C * h**p)
        compare(f"observed order of e = {C:g} h^{p:g}", got, p, {"h": "0.1 ... 0.0125"}, rtol=1e-8)


def observed_order_least_squares(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125, 0.00625])
    e = 2.0 * h**1.5 * np.array([1.0, 1.3, 0.8, 1.1, 0.95])
    want = np.polyfit(np.log(h), np.log(e), 1)[0]
    got = call(observed_order, "observed_order", h, e)
    two = [
        np.log(e[-1] / e[0]) / np.log(h[-1] / h[0]),
        np.log(e[1] / e[0]) / np.log(h[1] / h[0]),
        np.log(e[-1] / e[-2]) / np.log(h[-1] / h[-2]),
    ]
    if any(math.isclose(float(got), t, rel_tol=1e-8) for t in two):
        raise AssertionError(
            f"your order {float(got):.4g} comes from two points only; fit a line through all "
            f"points of (log h, log e) by least squares (np.polyfit): {want:.4g}"
        )
    compare("observed order of noisy errors", got, want, {"h": "0.1 ... 0.00625"}, rtol=1e-8)


def observed_order_signed(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    e = -4.0 * h**2
    got = call(observed_order, "observed_order", h, e)
    if not np.isfinite(float(got)):
        raise AssertionError(
            "your order is not finite for negative errors e = -4 h^2: an error can be negative "
            "(too low); its size is |e|"
        )
    compare("observed order of e = -4 h^2", got, 2.0, {"h": "0.1 ... 0.0125"}, rtol=1e-8)


def convergence_order_linear(convergence_order):
    r = 0.5 ** np.arange(1, 8) * 3.0
    compare(
        "convergence order of r_k = 3 (1/2)^k",
        call(convergence_order, "convergence_order", r),
        1.0,
        {"r": "3/2, 3/4, ..."},
        rtol=1e-8,
    )


def convergence_order_quadratic(convergence_order):
    r = [0.5]
    for _ in range(4):
        r.append(r[-1] ** 2)
    got = call(convergence_order, "convergence_order", np.array(r))
    if math.isclose(float(got), 0.5, rel_tol=1e-8):
        raise AssertionError(
            "your order for r_(k+1) = r_k^2 is 0.5, the inverse of 2: the order is "
            "log(r_k+1 / r_k) / log(r_k / r_k-1) with the newest ratio on top"
        )
    compare("convergence order of r_(k+1) = r_k^2", got, 2.0, {"r": "0.5, 0.25, 0.0625, ..."}, rtol=1e-8)


def convergence_order_last(convergence_order):
    r = np.array([1.0, 0.5, 0.25, 0.125, 0.125**2, 0.125**4])
    got = call(convergence_order, "convergence_order", r)
    compare(
        "convergence order from the last three residuals of 1, 0.5, 0.25, 0.125, 0.125^2, 0.125^4",
        got,
        2.0,
        {"r": "..."},
        rtol=1e-8,
    )


# settings for a tolerance: the frictionless sloping impact, run to t = 4 (the rebound is over by 2.4)
TOLERANCE_END = 4.0
# steps: a tolerance's settings may cost this much at most (the largest steps that resolve the contact at the
# penalty the tolerance needs, dt sqrt(c_N / m) <= 0.16 (penalty_steps), take 890 and 2860)
TOLERANCE_BUDGET = {0.05: 1000, 0.01: 3000}
# 10 times the paper's penalty at a step that resolves it (dt sqrt(c_N / m) = 0.11)
TOLERANCE_REFERENCE = dict(c_N=500.0, dt=0.001)
_TOLERANCE_RUNS = {}


def tolerance_run(c_N, dt):
    """The frictionless sloping impact (fast preset) with c_N and dt to t = 4, warnings kept out (the
    check reads the accuracy section); run once per setting in this process."""
    import warnings

    from ....scenes import run_scene

    key = (float(c_N), float(dt))
    if key not in _TOLERANCE_RUNS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _TOLERANCE_RUNS[key] = run_scene(
                "sloping_impact",
                "fast",
                dict(c_N=key[0], dt=key[1], n_steps=max(1, round(TOLERANCE_END / key[1]))),
                error_bars=False,  # the exercise is about the indicators, not the bands (exercise 9.4)
            )
    return _TOLERANCE_RUNS[key]


def _tolerance_settings(settings_for, tol):
    out = call(settings_for, "settings_for", tol)
    if not isinstance(out, dict) or not {"dt", "c_N"} <= set(out):
        raise AssertionError(
            f"settings_for({tol:g}) should return a dict with the keys 'dt' and 'c_N', got {out!r:.80}"
        )
    try:
        dt, c_N = float(out["dt"]), float(out["c_N"])
    except (TypeError, ValueError):
        raise AssertionError(f"settings_for({tol:g}) should give numbers for dt and c_N, got {out!r:.80}") from None
    if not (math.isfinite(dt) and math.isfinite(c_N) and dt > 0 and c_N > 0):
        raise AssertionError(f"settings_for({tol:g}) gave dt = {dt:g}, c_N = {c_N:g}: both must be positive numbers")
    return dt, c_N, max(1, round(TOLERANCE_END / dt))


def _tolerance_checked(settings_for, tol):
    """The run of the student's settings at tol, within the budget (a run past it is not made)."""
    dt, c_N, steps = _tolerance_settings(settings_for, tol)
    budget = TOLERANCE_BUDGET[tol]
    if steps > budget:
        raise AssertionError(
            f"at tol = {tol:g} your dt = {dt:g} takes {steps} steps to t = {TOLERANCE_END:g}; the "
            f"budget is {budget} (dt >= {TOLERANCE_END / budget:g}): a step far smaller than the "
            "tolerance needs is work wasted; the run was not made"
        )
    try:
        return dt, c_N, tolerance_run(c_N, dt)
    except (ValueError, RuntimeError) as err:
        raise AssertionError(f"at tol = {tol:g} the run with dt = {dt:g}, c_N = {c_N:g} stopped: {err}") from None


def tolerance_indicators_at(settings_for, tol):
    dt, c_N, r = _tolerance_checked(settings_for, tol)
    past = [
        f"{k} = {v['value']:.3g} ({v['bound']} {v['threshold']:.3g})"
        for k, v in r["accuracy"].items()
        if isinstance(v, dict) and not v["ok"]
    ]
    if past:
        raise AssertionError(
            f"at tol = {tol:g} your settings dt = {dt:g}, c_N = {c_N:g} leave indicators past their "
            f"thresholds: {'; '.join(past)}. Read r['accuracy'][name]['what'] and ['source']: which "
            "setting moves each one?"
        )


def tolerance_error_at(settings_for, tol):
    dt, c_N, r = _tolerance_checked(settings_for, tol)
    ref = tolerance_run(**TOLERANCE_REFERENCE)["rebound_vy"]
    err = abs(r["rebound_vy"] - ref) / abs(ref)
    if not err <= tol:
        raise AssertionError(
            f"at tol = {tol:g} your settings dt = {dt:g}, c_N = {c_N:g} give a rebound v_y = "
            f"{r['rebound_vy']:.4f}, {100 * err:.2g} % off the reference {ref:.4f} (c_N = "
            f"{TOLERANCE_REFERENCE['c_N']:g}, dt = {TOLERANCE_REFERENCE['dt']:g}): more than the "
            "tolerance. Which error is it: the step's (Newmark damps the rebound) or the penalty's?"
        )


def tolerance_budget_at(settings_for, tol):
    _tolerance_checked(settings_for, tol)


def tolerance_indicators(settings_for):
    tolerance_indicators_at(settings_for, 0.05)


def tolerance_error(settings_for):
    tolerance_error_at(settings_for, 0.05)


def tolerance_budget(settings_for):
    tolerance_budget_at(settings_for, 0.05)


# an error band by hand (ex09_band_by_hand): three levels finest first, ratio r, the scheme's order; the
# answer against the library's own estimate (contactfem.problem.uncertainty.estimate)


def _band_case(f_exact, C, p, r, h=0.05):
    return tuple(f_exact + C * (h * r**k) ** p for k in range(3))


def _band(band_from_three, f, r, p_th):
    got = parts(call(band_from_three, "band_from_three", *f, r, p_th), 3, "band_from_three", "p, f_extrapolated, band")
    return [float(x) for x in got]


def _library_band(f, r, p_th, h=0.05):
    from ....problem.uncertainty import estimate

    return estimate([(h * r**k, v) for k, v in enumerate(f)], p_th)


def band_order(band_from_three):
    for f_exact, C, p, r in ((2.0, 0.3, 1.7, 2.0), (-1.0, -4.0, 0.8, 1.5)):
        f = _band_case(f_exact, C, p, r)
        got = _band(band_from_three, f, r, 1.0)[0]
        if math.isclose(got, -p, rel_tol=1e-6):
            raise AssertionError(
                f"your order for f = {f_exact:g} + {C:g} h^{p:g} is {got:.4g}, its negative: p = ln(e32 / e21) / ln r "
                "with e21 = f2 - f1, e32 = f3 - f2 (f1 the finest)"
            )
        compare(
            f"observed order of f = {f_exact:g} + {C:g} h^{p:g}, r = {r:g}",
            got,
            p,
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
        )


def band_richardson(band_from_three):
    for f_exact, C, p, r in ((2.0, 0.3, 1.7, 2.0), (-1.0, -4.0, 0.8, 1.5)):
        f = _band_case(f_exact, C, p, r)
        got = _band(band_from_three, f, r, 1.0)[1]
        if math.isclose(got, 2 * f[0] - f_exact, rel_tol=1e-8):
            raise AssertionError(
                "your extrapolated value is f1 + delta: delta = e21 / (r^p - 1) is f2's lead over f1 scaled down, "
                "and the limit lies on the other side of f1 from f2 (f1 - delta)"
            )
        compare(
            f"Richardson's value of f = {f_exact:g} + {C:g} h^{p:g}",
            got,
            f_exact,
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
        )


def band_factor_of_safety(band_from_three):
    for f, r, p_th in (((1.0, 1.06, 1.14), 2.0, 2.0), ((1.0, 1.01, 1.05), 2.0, 1.0)):  # P < 1, then P > 1
        got = _band(band_from_three, f, r, p_th)[2]
        want = _library_band(f, r, p_th)
        compare(
            f"the band of the levels {f} (r = {r:g}, p_th = {p_th:g}; P = {want['P']:.3g})",
            got,
            want["band"],
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
            rule="FS(P) |delta|, FS = 1.6 P + 2.45 (1 - P) for P <= 1, 1.6 P + 2.45 (P - 1) above",
        )


EXERCISES = [
    exercise(
        "ex09_observed_order",
        LECTURE,
        "easy",
        False,
        "the observed order of convergence by least squares, applied to the bench",
        (observed_order_exact, 2),
        (observed_order_least_squares, 2),
        (observed_order_signed, 1),
    ),
    exercise(
        "ex09_convergence_order",
        LECTURE,
        "medium",
        False,
        "Newton's order from a residual history: consistent tangent against staggered",
        (convergence_order_linear, 1),
        (convergence_order_quadratic, 2),
        (convergence_order_last, 1),
    ),
    exercise(
        "ex09_settings_for_tolerance",
        LECTURE,
        "medium",
        False,
        "the step and the penalty of the sloping impact for a tolerance, checked with the run's indicators",
        (tolerance_indicators, 2),
        (tolerance_error, 2),
        (tolerance_budget, 1),
    ),
    exercise(
        "ex09_band_by_hand",
        LECTURE,
        "medium",
        False,
        "an error band from three runs: observed order, Richardson's estimate, Xing and Stern's factor of safety",
        (band_order, 2),
        (band_richardson, 2),
        (band_factor_of_safety, 2),
    ),
]
