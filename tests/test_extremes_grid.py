"""A small extremes grid: the sloping impact at penalties 1e-4, 1 and 1e4 times the paper's and
at the paper's step and ten times it. Every run is refused in one line, stops with one line,
carries an accuracy warning, or lands within 5 % of a reference refined in time (dt / 8 at
the same penalty): no run exits unflagged and wrong."""
import warnings

import pytest

from contactfem import AccuracyWarning
from contactfem.scenes import run_scene
from contactfem.solver.newton import NewtonError

C_N, DT, T_END = 50.0, 0.1, 20.0
HEADLINES = ("rebound_vx", "rebound_vy")


def _outcome(c_N, dt):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = run_scene("sloping_impact", "fast", {"c_N": c_N, "dt": dt, "n_steps": round(T_END / dt)})
        except (ValueError, NewtonError) as err:
            assert "\n" not in str(err).splitlines()[0]
            return "stopped", None
    flagged = [w for w in caught if issubclass(w.category, AccuracyWarning)]
    return ("flagged" if flagged else "clean"), r


@pytest.mark.slow
@pytest.mark.parametrize("factor", [1e-4, 1.0, 1e4])
def test_no_run_exits_unflagged_and_wrong(factor):
    c_N = C_N * factor
    _, ref = _outcome(c_N, DT / 8)
    counts = {}
    for dt in (DT, 10 * DT):
        kind, r = _outcome(c_N, dt)
        counts[kind] = counts.get(kind, 0) + 1
        if kind == "clean":
            assert ref is not None
            for key in HEADLINES:
                assert r[key] == pytest.approx(ref[key], rel=0.05, abs=1e-9), (c_N, dt, key)
    print(f"c_N = {c_N:g}: {counts}")
