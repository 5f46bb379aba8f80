"""Every run knows how accurate it is: Newton's force test, the accuracy indicators, and each
run of the accuracy study right to its tolerance, flagged by a named indicator, or refused."""

import subprocess
import sys
import warnings

import numpy as np
import pytest

from contactfem import AccuracyWarning, run_scene
from contactfem.solver.newton import RTOL, newton


def _run(name, overrides, preset="fast"):
    """The run's results and the names of the indicators it warned about."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = run_scene(name, preset, overrides)
    flagged = {str(w.message).split(" = ")[0].split(": ")[1] for w in caught if issubclass(w.category, AccuracyWarning)}
    assert flagged == {k for k, v in r["accuracy"].items() if not v["ok"]}  # one warning per indicator past it
    return r, flagged


def test_newton_ignores_a_huge_first_residual():
    # G(u) = (u - 1) + 1e12 min(u, 0): a first guess in the stiff region has a huge spurious force, which
    # must not loosen the test (a tolerance of 1e-10 ||G_0|| would be 100 here, a hundred times the load)
    k = 1.0

    def fun(u):
        G = np.array([k * (u[0] - 1.0) + 1e12 * min(u[0], 0.0)])
        return G, np.array([[k + (1e12 if u[0] < 0 else 0.0)]])

    res = newton(fun, np.array([-1.0]), [0], atol=0.0)
    assert abs(res.u[0] - 1.0) <= 10 * RTOL
    assert res.residual_ratio <= RTOL


def test_hertz_too_stiff_penalty_is_refused_in_one_line():
    with pytest.raises(ValueError, match=r"^parameter c_N = 1e\+18 is out of range") as err:
        run_scene("hertz", "fast", {"c_N": 1e18})
    assert "\n" not in str(err.value)
    out = subprocess.run(
        [sys.executable, "-m", "contactfem", "run", "hertz", "--set", "c_N=1e18"], capture_output=True, text=True
    )
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("discretization", ["node_to_segment", "mortar"])
def test_lagrange_patch_converges_at_stiff_steering(discretization):
    r, flagged = _run("patch", {"enforcement": "lagrange", "c_N": 1e8, "contact_discretization": discretization})
    assert not flagged
    assert r["pressure_deviation_max"] < 0.03  # the default c_N's answer (c_N only steers)
    assert r["gap_violation"] < 1e-12


def test_lagrange_node_to_segment_range_says_where_it_holds():
    with pytest.raises(ValueError, match="out of range for enforcement = lagrange"):
        run_scene("patch", "fast", {"enforcement": "lagrange", "c_N": 1e11})


def test_block_soft_penalty_is_flagged_by_penetration():
    r, flagged = _run("block", {"c_N": 10})
    assert {"penetration", "penetration_body"} <= flagged
    assert r["accuracy"]["penetration_body"]["value"] > 10


def test_the_same_run_twice_warns_twice_under_the_default_filters():
    """Python's default filter shows a warning once per text and place: a notebook that runs the
    same flagged scene again must hear it again."""
    shown = []
    with warnings.catch_warnings():
        warnings.resetwarnings()
        warnings.simplefilter("default")
        warnings.showwarning = lambda message, category, filename, lineno, *a, **k: shown.append((category, filename))
        for _ in range(2):
            run_scene("block", "fast", {"c_N": 10})
    assert [c for c, _ in shown].count(AccuracyWarning) >= 4  # penetration and penetration_body, twice


def test_a_warning_points_at_the_line_that_asked_for_the_run():
    """From Python, an AccuracyWarning names the caller's file and line (where run_scene was called), not a
    line inside the package."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = sys._getframe().f_lineno + 1
        run_scene("block", "fast", {"c_N": 10})
    mine = [w for w in caught if issubclass(w.category, AccuracyWarning)]
    assert mine and all((w.filename, w.lineno) == (__file__, line) for w in mine), [
        (w.filename, w.lineno) for w in mine
    ]


@pytest.mark.parametrize("over", [{"n_el": 4}, {"n_el": 20}, {"c_N_factor": 0.1}])
def test_bar_impact_off_its_closed_form_is_flagged(over):
    """A coarse bar (or a soft penalty) lengthens the contact by 7.5-25 %: the closed form names it."""
    r, flagged = _run("bar_impact", over)
    assert "duration" in flagged and r["accuracy"]["duration"]["value"] == pytest.approx(abs(r["error_duration"]))
    assert abs(r["duration"] / r["duration_exact"] - 1) > 0.05


def test_sloping_impact_coarse_step_is_flagged():
    r, flagged = _run("sloping_impact", {"dt": 1})
    assert {"impact_steps", "penalty_steps"} <= flagged and r["accuracy"]["impact_steps"]["value"] <= 3


def test_an_impact_whose_body_never_reaches_the_obstacle_says_so():
    """A step refined a thousandfold without more steps ends the sloping impact before the ring reaches the
    plane: the rebound it reports is the velocity it started with, and the run flags it (missed), which the
    preset's run does not."""
    r, flagged = _run("sloping_impact", {"dt": 1e-4})
    assert "missed" in flagged and r["accuracy"]["missed"]["value"] == 1.0
    assert r["rebound_vy"] == r["parameters"]["vy0"] and not r["rebounded"]
    r, flagged = _run("sloping_impact", {})
    assert "missed" not in flagged and r["accuracy"]["missed"]["value"] == 0.0


@pytest.mark.parametrize("integration", ["standard", "energy_consistent"])
def test_rolling_ring_coarse_step_is_flagged_by_its_closed_forms(integration):
    r, flagged = _run("rolling_ring", {"dt": 0.5, "contact_integration": integration})
    assert flagged & {"v_final", "x_roll", "x_end"}


def test_rolling_ring_sliding_reference():
    r, flagged = _run("rolling_ring", {"mu": 1e-9})
    assert r["v_final_exact"] == pytest.approx(300.0, rel=1e-6)  # the ring slides to the end: v0 - mu g t
    assert abs(r["v_final_rel_err"]) < 1e-6 and flagged == {"penalty_steps"}  # (its contact: dt sqrt(k/m) = 25)


def test_funnel_paper_penalty_is_flagged_by_its_penetration_and_its_step():
    """The paper's funnel (c_N = 10, dt = 0.1): its ring penetrates just past a tenth of an element, and
    its contact oscillates at dt sqrt(k/m) = 3.1 a step; twice the penalty goes less deep."""
    r, flagged = _run("funnel", {})
    assert flagged == {"penetration", "penalty_steps"} and 0.1 < r["accuracy"]["penetration"]["value"] < 0.11
    assert _run("funnel", {"c_N": 20})[1] == {"penalty_steps"}


@pytest.mark.slow
def test_energy_consistent_stiff_penalty_keeps_energy_or_is_flagged():
    r, flagged = _run("sloping_impact", {"contact_integration": "energy_consistent", "c_N": 5e7})
    assert abs(r["energy_error"]) < 1e-8  # the force test resolves it (was 3.3e-6)
    assert "impact_steps" in flagged  # one step for the whole impact


@pytest.mark.slow
def test_cli_strict_exits_1_with_one_line_per_indicator(tmp_path):
    out = subprocess.run(
        [sys.executable, "-m", "contactfem", "run", "block", "--set", "c_N=10", "--strict"],
        capture_output=True,
        text=True,
    )
    lines = [x for x in out.stderr.splitlines() if "accuracy:" in x]
    assert out.returncode == 1 and len(lines) == 2
    out = subprocess.run(
        [sys.executable, "-m", "contactfem", "run", "block", "--set", "c_N=10"], capture_output=True, text=True
    )
    assert out.returncode == 0


@pytest.mark.parametrize("lower, upper, off", [(11, 5, 1.0), (17, 3, 3.78)])
def test_patch_pressure_covers_both_blocks(lower, upper, off):
    r, flagged = _run("patch", {"nx_lower": lower, "nx_upper": upper})
    assert r["pressure_deviation_lower"] == pytest.approx(off, rel=0.01)  # master nodes that get no load
    assert r["pressure_deviation_max"] >= r["pressure_deviation_lower"]
    assert "pressure_deviation_max" in flagged
    mortar, flagged = _run("patch", {"nx_lower": lower, "nx_upper": upper, "contact_discretization": "mortar"})
    assert mortar["pressure_deviation_max"] < 1e-9 and not flagged  # mortar passes on both blocks


def test_hertz_mortar_half_width_from_the_forces_moments():
    m, flagged = _run("hertz", {"contact_discretization": "mortar"})
    n, _ = _run("hertz", {})
    assert abs(m["error_a_fit"]) > 0.04  # the fit through mortar's smeared edge tractions
    assert abs(m["error_a"]) < 0.03 and m["a"] == m["a_moments"] and not flagged
    assert n["a"] == n["a_fit"] and abs(n["error_a_moments"]) < 5e-3  # node-to-segment: both agree with Hertz


@pytest.mark.parametrize("ext", ["json", "npz"])
def test_a_saved_run_carries_its_accuracy(tmp_path, ext):
    from contactfem.io import as_arrays, load_run, save_run

    r, _ = _run("block", {"c_N": 10})
    save_run(as_arrays(r), tmp_path / f"run.{ext}")
    assert load_run(tmp_path / f"run.{ext}")["accuracy"] == r["accuracy"]


def test_the_equilibrium_indicator_is_the_residual_over_the_force_scale():
    """On the block (one step, its last residual 7e-13 at most, below Newton's atol = 1e-12) the value is
    what its label says, the converged residual over the force scale (about 6e-15), not 0; the force
    scale's floor atol / 1e-6 moves it by atol / (1e-6 F), under 1e-7 of it here."""
    from contactfem.scenes import get_scene
    from contactfem.problem.scene import simulate

    scene = get_scene("block")
    params = scene.resolve("fast")
    model = scene.build(params)
    ratios = [r.result.ratios[-1] for r in simulate(model, params)[1:]]  # max |G_f| / F of each converged step
    value = run_scene("block", "fast")["accuracy"]["equilibrium"]["value"]
    assert 0 < value <= max(ratios) and value == pytest.approx(max(ratios), rel=1e-7)
