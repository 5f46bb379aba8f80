"""The extremes grid in the suite. A small grid: the sloping impact at penalties 1e-4, 1 and 1e4
times the paper's and at the paper's step and ten times it. Every run is refused in one line,
stops with one line, carries an accuracy warning, or lands within 5 % of a reference refined in
time (dt / 8 at the same penalty): no run exits unflagged and wrong.

Then the bench's grid (contactfem/lab/bench/extremes.py, `contactfem bench --only extremes`): its
quick slice, each run the full grid found wrong and unflagged before an indicator was added (the
run is off its reference by more than 5 % and the named indicator flags it), and BENCHMARKS.md
against the committed bench.json."""

import json
import warnings
from pathlib import Path

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


# -- the bench's grid ------------------------------------------------------------------------------

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_the_quick_slice_is_within_flagged_refused_or_stopped():
    """The slice the suite runs (a run of each outcome the full grid meets): none wrong, crashed,
    past its time limit or without its reference; and the grid does tell a run off its reference
    (the flagged runs include some more than 5 % off)."""
    from contactfem.lab.bench.extremes import extremes_study

    res = extremes_study(quick=True, seconds=120)
    c = res["counts"]
    bad = [
        (r["scene"], r["axis"], r["outcome"], r["errors"])
        for r in res["rows"]
        if r["outcome"] in ("wrong", "crashed", "late", "no reference")
    ]
    assert not bad
    assert c["flagged (off)"] >= 5 and c["within"] >= 2 and c["refused"] >= 1 and c["stopped"] >= 1
    assert res["runs"] == sum(c.values())


# each finding of the full grid: the run, its reference, the headline and the indicator that flags it
FINDINGS = [
    # one element through the block's height: the largest displacement 25 % off 16 elements (nx = 3)
    ("block", {"nx": 3, "ny": 1, "free_end_nodes": 1}, "max_displacement", "mesh_height"),
    # a bar on a penalty 1e-4 times the scene's is still in contact at the end: its rebound is read mid-impact
    ("bar_impact", {"c_N_factor": 1e-4}, "rebound_velocity", "separated"),
    # a ring of three elements: the rebound v_y 31 % off the 16-element ring's
    ("sloping_impact", {"n_el": 3, "n_steps": 40}, "rebound_vy", "facets"),
    # a penalty 1e4 times the scene's at the preset's step: x_end 5.9 % off the run at dt / 4
    ("rolling_ring", {"c_N": 1e5, "t_end": 1.5}, "x_end", "x_end"),
    # the energy-consistent midpoint rule at ten times the step: the rebound 11 % off, its energy exact
    ("bar_impact", {"courant": 10.0, "contact_integration": "energy_consistent"}, "rebound_velocity", "penalty_steps"),
]


@pytest.mark.parametrize("scene, over, headline, flag", FINDINGS, ids=[f"{f[0]}-{f[3]}" for f in FINDINGS])
def test_each_finding_is_off_and_flagged_by_its_indicator(scene, over, headline, flag):
    from contactfem.lab.bench.extremes import TOL, attempt, classify, reference_overrides

    run = attempt(scene, over, seconds=None)
    ref = attempt(scene, reference_overrides(scene, over), seconds=None)
    outcome, errors = classify(scene, run, ref)
    assert errors[headline] > TOL, errors  # the indicator is needed: the run is off
    assert flag in run["flags"], run["flags"]
    assert outcome == "flagged (off)"


def test_benchmarks_md_shows_the_committed_extremes_grid():
    """BENCHMARKS.md holds the extremes table of the committed bench.json, and that run of the full
    grid has no run wrong and unflagged (nor crashed, late or without a reference)."""
    from contactfem.lab.bench.extremes import extremes_markdown, grid

    bench = json.loads((REPO / "bench.json").read_text())
    ex = bench["extremes"]
    assert not ex["quick"] and ex["runs"] == len(grid()) == len(ex["rows"])
    assert all(ex["counts"][k] == 0 for k in ("wrong", "crashed", "late", "no reference")), ex["counts"]
    assert "\n".join(extremes_markdown(ex)) in (REPO / "BENCHMARKS.md").read_text()


def test_a_halved_step_is_not_halved_without_end():
    """The funnel at 1e18 times its penalty: each part of a halved step was cut again with a fresh
    count, down to 1e-11 of the step, and the run never ended; now the step stops at dt / 2^max_cuts
    and the run stops in one line."""
    from contactfem.solver.newton import NewtonError
    from contactfem.solver.schedule import Steps

    steps = Steps(0.1, n_steps=10, max_cuts=2)
    assert steps.cut(0.1, 0) == 0.05 and steps.cut(0.05, 0) == 0.025 and steps.cut(0.025, 0) is None
    with pytest.raises(NewtonError) as err:
        run_scene("funnel", "fast", {"c_N": 1e19, "n_steps": 40})
    assert "\n" not in str(err.value) and "dt = 0.00156" in str(err.value)
