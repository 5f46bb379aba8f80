"""Error bars (problem/uncertainty.py): the estimator on sequences whose error is known (a power law in h:
Richardson's estimate exact, the band at least the true error), the convergence classes, the ladder's
choice of levels (coarser first, finer where a level fails or the order is out of range), and the bands of
real runs: the section every run carries, what the command line prints, the warnings and --strict."""

import json
import math
import os
import subprocess
import sys
import warnings

import pytest

from contactfem import AccuracyWarning, run_scene
from contactfem.cli import main
from contactfem.problem.uncertainty import (
    FS0,
    FS1,
    Quantity,
    bands,
    check_tolerance,
    classify,
    error_bars_default,
    estimate,
    factor_of_safety,
    line,
    mesh,
    observed_order,
    penalty,
    time_step,
)

ON = dict(os.environ, CONTACTFEM_ERROR_BARS="on")  # the suite runs without them (conftest.py)


def power_law(f_exact, C, p):
    return lambda h: f_exact + C * h**p


@pytest.mark.parametrize("p", [0.7, 1.0, 2.0, 3.1])
@pytest.mark.parametrize("ratios", [(2.0, 2.0), (2.0, 1.5), (1.3, 2.7)])
def test_observed_order_and_richardson_are_exact_on_a_power_law(p, ratios):
    f = power_law(1.5, -0.3, p)
    h1 = 0.01
    h2 = h1 * ratios[0]
    h3 = h2 * ratios[1]
    assert observed_order(f(h2) - f(h1), f(h3) - f(h2), *ratios) == pytest.approx(p, rel=1e-9)
    est = estimate([(h1, f(h1)), (h2, f(h2)), (h3, f(h3))], p_th=p)
    assert est["cls"] == "monotone" and est["richardson"] == pytest.approx(1.5, rel=1e-12)
    assert est["band"] >= abs(f(h1) - 1.5)  # P = 1: the band is FS1 = 1.6 times the exact error
    assert est["band"] == pytest.approx(FS1 * abs(f(h1) - 1.5), rel=1e-8)


def test_factor_of_safety_is_xing_and_sterns():
    assert factor_of_safety(0.0) == FS0 and factor_of_safety(1.0) == FS1
    assert factor_of_safety(0.5) == pytest.approx(0.5 * (FS0 + FS1))
    assert factor_of_safety(2.0) == pytest.approx(2 * FS1 + FS0)  # grows past the asymptotic range
    # continuous at P = 1, and never below FS1 in the range the statistics cover
    assert factor_of_safety(1 - 1e-9) == pytest.approx(factor_of_safety(1 + 1e-9))
    assert min(factor_of_safety(P / 100) for P in range(1, 201)) >= FS1 - 1e-12


def test_oscillatory_levels_take_finer_ones_then_give_no_band():
    """A coarsest level outside the asymptotic range can swing back (the block with one element through its
    height): the finer triplet is taken; where it oscillates too, no band (an envelope would not hold a drift
    under the oscillation)."""
    table = {0.4: 1.0117, 0.2: 0.9899, 0.1: 1.0145, 0.05: 1.0327, 0.025: 1.0423}
    run, _ = _fake(lambda h: table[round(h, 6)])
    section, _ = bands(run, PARAMS, {"q": 1.0145}, [Q], [DT])
    entry = section["quantities"]["q"]
    assert entry["convergence"] == "monotone" and entry["band"] >= 1.0476 - 1.0145
    wobble = {0.4: 1.05, 0.2: 0.97, 0.1: 1.0, 0.05: 0.98, 0.025: 1.01}
    run, _ = _fake(lambda h: wobble[round(h, 6)])
    section, indicators = bands(run, PARAMS, {"q": 1.0}, [Q], [DT])
    assert section["quantities"]["q"]["convergence"] == "oscillatory"
    assert section["quantities"]["q"]["band"] is None and not indicators["q_band"]["ok"]


def test_a_quantity_its_scene_never_measures_warns_instead_of_losing_its_band():
    """A headline quantity whose name the scene's measure does not return (a misspelled name in a scene file):
    no band, and an indicator that says so, naming it; no level is run for it."""
    run, _ = _fake(lambda h: 1.0 + h)
    section, indicators = bands(run, PARAMS, {"q": 1.1}, [Q, Quantity("vx")], [DT])
    assert "vx" not in section["quantities"] and not indicators["vx_band"]["ok"]
    assert "returns no value named vx" in indicators["vx_band"]["what"]
    assert indicators["q_band"]["ok"] is not None


@pytest.mark.parametrize(
    "levels, cls",
    [
        ((1.0, 1.1, 1.3), "monotone"),
        ((1.0, 1.1, 0.9), "oscillatory"),
        ((1.0, 1.3, 1.4), "divergent"),  # the coarser difference smaller: no convergence
        ((1.0, 1.1, 1.1), "divergent"),  # two levels equal, the third not: no order
        ((1.0, 1.0 + 1e-12, 1.0 - 1e-12), "converged"),
    ],
)
def test_convergence_classes(levels, cls):
    assert classify(*levels, scale=1.0) == cls


def test_the_band_of_a_middle_level_adds_its_known_difference():
    """With the run the middle level (a finer one was taken), its band is its difference to the finest
    level plus the finest level's band: it holds the run's exact error."""
    f = power_law(2.0, 0.5, 1.0)
    levels = [(0.05, f(0.05)), (0.1, f(0.1)), (0.2, f(0.2))]
    est = estimate(levels, p_th=1.0, user=1)
    assert est["band"] == pytest.approx(abs(f(0.1) - f(0.05)) + FS1 * abs(f(0.05) - 2.0))
    assert est["band"] >= abs(f(0.1) - 2.0)


def _fake(values, counts=None):
    """A ladder's run function from h -> value (None: the level fails); counts the runs."""
    calls = counts if counts is not None else []

    def run(over):
        calls.append(over)
        v = values(over["dt"])
        return RuntimeError("no convergence in 30 iterations") if v is None else {"q": v}

    return run, calls


DT = time_step("dt")
Q = Quantity("q", "m", ("step",))
PARAMS = {"dt": 0.1, "delta": 0.5, "beta_newmark": 0.25}


def test_a_smooth_ladder_takes_two_coarser_runs_and_holds_the_error():
    f = power_law(3.0, 4.0, 2.0)
    run, calls = _fake(f)
    section, indicators = bands(run, PARAMS, {"q": f(0.1)}, [Q], [DT])
    entry = section["quantities"]["q"]
    assert sorted(c["dt"] for c in calls) == pytest.approx([0.2, 0.4])  # coarser only: the run stays the finest
    assert entry["convergence"] == "monotone" and entry["observed_order"] == pytest.approx(2.0)
    assert entry["band"] >= abs(f(0.1) - 3.0) and entry["parts"]["step"]["label"] == "time step"
    assert indicators["q_band"]["ok"] == (entry["relative_band"] <= 0.05)


def test_a_failing_coarser_level_takes_a_finer_one_and_counts_it():
    f = power_law(3.0, 4.0, 1.0)
    run, calls = _fake(lambda h: None if h > 0.3 else f(h))
    section, _ = bands(run, PARAMS, {"q": f(0.1)}, [Q], [DT])
    entry = section["quantities"]["q"]
    assert sorted(c["dt"] for c in calls) == pytest.approx([0.05, 0.2, 0.4])
    assert section["runs"] == 3 and section["failed_runs"] == 1
    assert [lv["factor"] for lv in entry["parts"]["step"]["levels"]] == [0.5, 1.0, 2.0]
    assert entry["band"] >= abs(f(0.1) - 3.0)


def test_an_order_far_above_the_schemes_takes_finer_levels():
    """A plateau between the run and 2 dt hides the error (the paper's sloping impact: 1.462, 1.455, 1.330
    while dt -> 0 gives 1.58): P > 2 means the coarsest level is outside the asymptotic range."""
    table = {0.4: 1.330, 0.2: 1.455, 0.1: 1.462, 0.05: 1.502, 0.025: 1.527}
    run, calls = _fake(lambda h: table[round(h, 6)])
    section, indicators = bands(run, dict(PARAMS, delta=0.7, beta_newmark=0.4), {"q": 1.462}, [Q], [DT])
    entry = section["quantities"]["q"]
    assert min(c["dt"] for c in calls) == pytest.approx(0.025)
    assert entry["band"] >= 1.58 - 1.462 and not indicators["q_band"]["ok"]


def test_a_plateau_in_the_finest_triplet_does_not_shrink_its_band():
    """The rolling ring's v_final at its fast preset's step and two halvings (149.33, 149.26, 147.62, finest
    first: P far above Newmark 0.7's order 1): the finer difference, 0.067, is a plateau (the next halvings move
    it by 0.19 and 0.074, to 149.67 at dt / 32, still rising), so the band of the finest level, taken from it
    alone, would be 0.2 and miss; carried down from the coarser difference at the scheme's order it holds."""
    est = estimate([(0.005, 149.328), (0.01, 149.261), (0.02, 147.619)], 1.0)
    assert est["P"] > 2 and est["method"] == "Roache, p = p_th"
    assert est["band"] >= 149.669 - 149.328
    assert est["band"] == pytest.approx(3 * (149.261 - 147.619) / 2)
    second = estimate([(0.005, 1.0), (0.01, 1.0 + 1e-3), (0.02, 1.0 + 1e-3 + 1e-1)], 2.0)  # p_th = 2: e32 / 4
    assert second["P"] > 2 and second["band"] == pytest.approx(3 * (1e-1 / 4) / 3)


def test_levels_that_never_converge_give_no_band_and_a_warning_naming_the_quantity():
    run, calls = _fake(lambda h: 13.0 - 0.2 / h)  # each halving moves it twice as far
    section, indicators = bands(run, PARAMS, {"q": 11.0}, [Q], [DT])
    assert len(calls) == 4 and section["quantities"]["q"]["convergence"] == "divergent"
    assert section["quantities"]["q"]["band"] is None
    ind = indicators["q_band"]
    assert not ind["ok"] and ind["value"] is None and "q" in ind["what"]


def test_coarsening_keeps_the_end_and_the_floors():
    steps = time_step("dt", count="n_steps")
    over = steps.coarsen({"dt": 0.1, "n_steps": 150}, 4.0)
    assert over["n_steps"] == 38 and over["n_steps"] * over["dt"] == pytest.approx(15.0)
    assert steps.coarsen({"dt": 0.1, "n_steps": 150, "accuracy": 0.01}, 2.0) == {"accuracy": 0.02}
    ring = mesh("n_el", low=8)
    assert ring.coarsen({"n_el": 16}, 2.0) == {"n_el": 8}
    with pytest.raises(ValueError, match="no mesh 4 times coarser"):
        ring.coarsen({"n_el": 16}, 4.0)
    soft = penalty("c_N")
    assert soft.coarsen({"c_N": 50.0}, 2.0) == {"c_N": 25.0} and not soft.applies({"enforcement": "lagrange"})


@pytest.mark.parametrize("bad", [0, -0.1, 1.5, "x", True, float("nan")])
def test_a_tolerance_out_of_range_is_refused_in_one_line(bad):
    with pytest.raises(ValueError, match=r"^tolerance") as err:
        check_tolerance(bad)
    assert "\n" not in str(err.value) and "(0, 1]" in str(err.value)


@pytest.mark.parametrize("bad", ["no", 0, 1, "off"])
def test_error_bars_other_than_true_false_or_none_are_refused(bad):
    with pytest.raises(TypeError, match=r"^error_bars = .*: give True, False or None"):
        run_scene("patch", error_bars=bad)


def test_the_environment_switch_takes_on_or_off_and_names_itself_otherwise(monkeypatch):
    for said, on in (("off", False), ("0", False), (" No ", False), ("on", True), ("TRUE", True), ("1", True)):
        monkeypatch.setenv("CONTACTFEM_ERROR_BARS", said)
        assert error_bars_default() is on
    monkeypatch.setenv("CONTACTFEM_ERROR_BARS", "maybe")
    with pytest.raises(ValueError, match=r"^environment variable CONTACTFEM_ERROR_BARS = 'maybe': allowed 0, off"):
        error_bars_default()
    # the command line turns them on where the environment has them off, in one line where both are asked
    monkeypatch.setenv("CONTACTFEM_ERROR_BARS", "off")
    assert main(["run", "patch", "--error-bars", "--no-error-bars"]) == 2


def test_the_line_the_command_line_prints():
    entry = dict(value=1.462382818, unit="", band=0.12, parts={"step": dict(band=0.12, label="time step")})
    assert line("rebound_vy", entry) == "rebound_vy = 1.462 +- 0.12 (time step)"
    two = dict(
        entry, band=0.15, parts={"step": dict(band=0.12, label="time step"), "mesh": dict(band=0.03, label="mesh")}
    )
    assert line("rebound_vy", two) == "rebound_vy = 1.462 +- 0.15 (time step 0.12, mesh 0.03)"


# -- real runs --------------------------------------------------------------------------------------


def _banded(name, over, preset="fast", **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = run_scene(name, preset, over, error_bars=True, **kw)
    return r, [str(w.message) for w in caught if issubclass(w.category, AccuracyWarning)]


def test_a_run_with_error_bars_is_the_run_without_them_and_says_what_its_bands_cost():
    r, _ = _banded("block", {"ny": 4})
    plain = run_scene("block", "fast", {"ny": 4}, error_bars=False)
    assert r["max_displacement"] == plain["max_displacement"] and "uncertainty" not in plain
    u = r["uncertainty"]
    entry = u["quantities"]["max_displacement"]
    assert set(entry) >= {"value", "band", "relative_band", "observed_order", "levels", "convergence", "parts"}
    run_level = next(lv for lv in entry["parts"]["mesh"]["levels"] if lv["factor"] == 1.0)
    assert run_level["value"] == r["max_displacement"] and run_level["overrides"] == {}
    assert u["runs"] >= 2 and u["wall_time_s"] > 0 and json.loads(json.dumps(u)) == u  # plain JSON
    again, _ = _banded("block", {"ny": 4})
    assert again["uncertainty"]["quantities"] == u["quantities"]  # the same run twice: the same bands


def test_a_band_past_the_tolerance_warns_naming_the_quantity_and_a_larger_tolerance_does_not():
    r, lines = _banded("block", {"ny": 8})
    rel = r["uncertainty"]["quantities"]["max_displacement"]["relative_band"]
    assert rel > 0.05 and any(x.startswith("accuracy: max_displacement_band") for x in lines)
    _, quiet = _banded("block", {"ny": 8}, tolerance=min(1.0, 2 * rel))
    assert not any("max_displacement_band" in x for x in quiet)


@pytest.mark.slow
def test_the_command_line_prints_each_band_and_strict_exits_1(tmp_path):
    cmd = [sys.executable, "-m", "contactfem", "run", "block", "--json", str(tmp_path / "b.json")]
    out = subprocess.run(cmd, capture_output=True, text=True, env=ON)
    assert out.returncode == 0, out.stderr
    r = json.loads((tmp_path / "b.json").read_text())
    entry = r["uncertainty"]["quantities"]["max_displacement"]
    assert line("max_displacement", entry) in out.stdout.splitlines()
    assert "accuracy: max_displacement_band" in out.stderr
    assert subprocess.run(cmd + ["--strict"], capture_output=True, env=ON).returncode == 1
    quiet = subprocess.run(cmd + ["--strict", "--tolerance", "0.5"], capture_output=True, text=True, env=ON)
    assert quiet.returncode == 0 and "max_displacement_band" not in quiet.stderr
    off = subprocess.run(cmd + ["--no-error-bars"], capture_output=True, text=True, env=ON)
    assert "uncertainty" not in json.loads((tmp_path / "b.json").read_text()) and " +- " not in off.stdout
    bad = subprocess.run(cmd + ["--tolerance", "2"], capture_output=True, text=True, env=ON)
    assert bad.returncode == 2 and bad.stderr.strip().splitlines() == [
        "contactfem: error: tolerance = 2.0 is out of range: allowed (0, 1]"
    ]


def test_accuracy_with_a_users_delta_or_beta_is_refused_in_one_line_each():
    for name in ("delta", "beta_newmark"):
        with pytest.raises(ValueError, match=rf"^parameter {name} does not apply .* accuracy=0.01") as err:
            run_scene("sloping_impact", "fast", {"accuracy": 0.01, name: 0.5})
        assert "\n" not in str(err.value)


def test_a_run_at_a_tolerance_records_the_integrator_it_used():
    from contactfem.scenes import get_scene

    p = get_scene("sloping_impact").resolve("paper", {"accuracy": 0.01})
    assert (p["delta"], p["beta_newmark"]) == (0.5, 0.25)


def test_a_scene_file_declaring_accuracy_is_refused_at_load_naming_the_file(tmp_path):
    from pathlib import Path

    from contactfem.scenes import get_scene

    example = Path(__file__).resolve().parents[1] / "lectures" / "examples" / "disc_wall.py"
    old = '    Param("dt", 0.01,'
    assert old in example.read_text()
    own = tmp_path / "own_accuracy.py"
    own.write_text(example.read_text().replace(old, '    Param("accuracy", 0.0, "", 0.0, 1.0),\n' + old))
    with pytest.raises(
        ValueError, match=r"^scene file own_accuracy.py, SCENE: parameter accuracy is a name the run reserves"
    ) as e:
        get_scene(str(own))
    assert "\n" not in str(e.value)
    assert get_scene(str(example)).param("dt")  # the example itself loads


def test_a_closed_form_is_an_indicator_held_to_the_tolerance():
    r = run_scene("bar_impact", "fast", {"n_el": 20}, error_bars=False)
    ind = r["accuracy"]["duration"]
    assert ind["value"] == pytest.approx(abs(r["duration"] / r["duration_exact"] - 1)) and ind["threshold"] == 0.05
    loose = run_scene("bar_impact", "fast", {"n_el": 20}, error_bars=False, tolerance=0.2)
    assert loose["accuracy"]["duration"]["threshold"] == 0.2 and loose["accuracy"]["duration"]["ok"]


def test_the_time_step_of_a_run_at_a_tolerance_is_its_tolerance():
    steps = time_step("dt", count="n_steps")
    assert math.isclose(steps.size({"dt": 0.1, "accuracy": 0.02}), 0.02)


# -- the defaults the issue found 5-8 % off, unflagged: each warns with a band that holds its error, or is
# accurate. The references are computed here (the same model refined in time at its own mesh: the time step's
# part of the band must hold the time step's error); the coverage study holds them in step and mesh at once.


def _time_refined(over, dt=0.003125):
    """The sloping impact refined in time at its own mesh (the paper's Newmark: the issue's reference)."""
    return run_scene("sloping_impact", "fast", dict(over, dt=dt, n_steps=round(4.0 / dt)), error_bars=False)


@pytest.mark.slow
@pytest.mark.parametrize("variant, name", [("frictionless", "rebound_vy"), ("frictional", "rebound_vy")])
def test_the_paper_sloping_impact_warns_with_a_time_band_that_holds_its_time_error(variant, name):
    r, lines = _banded("sloping_impact", {"variant": variant})
    ref = _time_refined({"variant": variant})[name]
    entry = r["uncertainty"]["quantities"][name]
    step = entry["parts"]["step"]
    assert step["band"] is not None and step["band"] >= abs(r[name] - ref), (r[name], ref, step)
    assert any(x.startswith(f"accuracy: {name}_band") for x in lines)  # it warns, naming the quantity
    assert entry["parts"]["step"]["label"] == "time step" and "time step" in line(name, entry)


@pytest.mark.slow
def test_the_paper_frictional_rebound_vx_oscillates_in_time_and_warns_without_a_band():
    """The frictional v_x oscillates as the step is refined (1.009, 1.033, 1.027 at dt, 2 dt, 4 dt; 1.012, 0.996
    at dt / 2, dt / 4) while it drifts to 0.96: no ladder within four times the run can bound that, so the run
    says it has no band for it, naming the quantity and the time step."""
    r, lines = _banded("sloping_impact", {"variant": "frictional"})
    entry = r["uncertainty"]["quantities"]["rebound_vx"]
    assert entry["band"] is None and entry["parts"]["step"]["convergence"] == "oscillatory"
    warning = next(x for x in lines if x.startswith("accuracy: rebound_vx_band"))
    assert "no error band of rebound_vx" in warning and "time step" in warning


@pytest.mark.slow
def test_the_rolling_ring_default_is_accurate_and_its_band_holds_the_hoops_error():
    """The fast preset's ring has the paper's 120 elements: v_final within its band of the rigid hoop's and
    within the tolerance (the old 40-gon was 5.8 % off and said nothing)."""
    r, lines = _banded("rolling_ring", {})
    entry = r["uncertainty"]["quantities"]["v_final"]
    assert entry["band"] >= abs(r["v_final"] - r["v_final_exact"])
    assert abs(r["v_final"] / r["v_final_exact"] - 1) < 0.05 and entry["relative_band"] < 0.05
    assert not any(x.startswith("accuracy: v_final") for x in lines)
    coarse = run_scene("rolling_ring", "fast", {"n_el": 40}, error_bars=False)
    assert abs(coarse["v_final"] / coarse["v_final_exact"] - 1) > 0.05 and not coarse["accuracy"]["v_final"]["ok"]
