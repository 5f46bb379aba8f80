"""The champagne cork (paper Sec. 5.5): one fast run shared by the tests, the
neck's kinematics against finite differences, Boyle's law, failures reported."""

import os

import numpy as np
import pytest

from contactfem.bodies.loads import swept_volume
from contactfem.scenes import run_scene
from contactfem.scenes.cork import PAPER, Neck, cork_mesh
from contactfem.solver import NewtonError

PAPER_V = PAPER["exit_velocity_m_s"]          # 28 m/s


@pytest.fixture(scope="module")
def fast():
    return run_scene("cork", "fast")


def test_fast_run_completes_and_the_cork_leaves(fast):
    # InvertedElementError (det F <= 0) would have ended the run as a NewtonError
    assert fast["exited"], "the cork did not leave the bottle in the fast preset"
    assert fast["min_element_area_ratio"] > 0.5, fast["min_element_area_ratio"]
    assert fast["newton_iterations_total"] > 0
    assert fast["newton_failures"] >= len(fast["newton_failure_log"])    # every cutback is logged


def test_penetration_stays_below_two_percent_of_the_radius(fast):
    # stated bound: |g_N| < 2 % of the neck radius, press fit and exit included
    assert fast["max_penetration_ratio"] < 0.02, fast["max_penetration_ratio"]


def test_fast_preset_exit_velocity_is_near_the_paper(fast):
    # paper 28 m/s; the coarse fast mesh (36 elements) within 25 % (paper preset: 15 %, below)
    v = fast["exit_velocity_m_s"]
    assert abs(v - PAPER_V) / PAPER_V < 0.25, f"paper {PAPER_V} m/s, ours {v:.2f} m/s, tolerance 25 %"


def test_press_fit_force_and_breakaway(fast):
    # paper: normal force ~2500 N, sliding at ~250 N, ~0.8 MPa; coarse mesh within 20 %
    assert abs(fast["press_fit_normal_force_N"] - 2500) / 2500 < 0.2, fast["press_fit_normal_force_N"]
    assert abs(fast["breakaway_pressure_static_MPa"] - 0.8) / 0.8 < 0.2, fast["breakaway_pressure_static_MPa"]
    assert fast["breakaway_pressure_MPa"] is not None and fast["breakaway_pressure_MPa"] <= 0.8 + 1e-9


def test_boyle_pressure_is_explicit_in_the_volume(fast):
    # p_k = p0 V0 / V_(k-1) on every Boyle step (pressure from the last converged state)
    P = fast["parameters"]
    t, p, V = (np.asarray(fast[k]) for k in ("time_ms", "pressure_MPa", "gas_volume_mm3"))
    V0 = np.pi * P["R_neck"] ** 2 * P["gas_column"]
    p0 = P["p_step"] * P["n_ramp"]
    t_ramp = P["n_ramp"] * P["dt"] * 1e3
    boyle = np.flatnonzero((t > t_ramp + 1e-9) & (p > 0))
    assert len(boyle) > 5
    assert np.allclose(p[boyle], p0 * V0 / V[boyle - 1], rtol=1e-12)
    # just before the exit: close to 0.8 * 30 / 54 (24 mm of travel)
    assert abs(fast["pressure_before_exit_MPa"] - 0.8 * 30 / 54) < 0.03, fast["pressure_before_exit_MPa"]
    assert p[-1] == 0.0                      # the gas escaped


def test_swept_volume_closed_form():
    r = np.linspace(0.0, 10.0, 7)
    assert swept_volume(np.column_stack([r, np.full(7, 3.0)])) == pytest.approx(np.pi * 100 * 3.0, rel=1e-12)
    # a cone z = r: int 2 pi r^2 dr = 2 pi R^3 / 3
    assert swept_volume(np.column_stack([r, r])) == pytest.approx(2 * np.pi * 1000 / 3, rel=1e-12)


def test_neck_normal_points_into_the_neck_and_is_continuous():
    neck = Neck(10.0, 24.0, 2.0)
    x = np.array([[9.0, 5.0], [10.1, 5.0], [10.0 - 1e-9, 24.0 - 1e-9], [10.0 - 1e-9, 24.0 + 1e-9],
                  [12.0 - 1e-9, 26.0 + 1e-9], [12.0 + 1e-9, 26.0 + 1e-9]])
    k = neck.locate(x, np.zeros(len(x)), None)
    assert k["g_N"][0] > 0 and k["g_N"][1] < 0                 # inside the neck open, in the glass closed
    assert np.allclose(k["n"][0], [-1, 0])                      # towards the cork (the axis)
    assert np.allclose(k["n"][2], k["n"][3], atol=1e-6) and abs(k["s"][2] - k["s"][3]) < 1e-6
    assert np.allclose(k["n"][4], k["n"][5], atol=1e-6) and abs(k["s"][4] - k["s"][5]) < 1e-6
    assert np.allclose(k["n"], np.stack([-k["t"][:, 1], k["t"][:, 0]], axis=1))   # n = e3 x t (eq 18)


@pytest.mark.parametrize("x", [[10.2, 7.0], [10.3, 24.8], [11.4, 25.7], [14.0, 25.9]])
def test_neck_variations_match_finite_differences(x):
    neck = Neck(10.0, 24.0, 2.0, shift=0.3)
    x = np.array([x], dtype=float)
    k = neck.locate(x, np.zeros(1), None)
    h = 1e-6
    for i in range(2):
        e = np.zeros((1, 2))
        e[0, i] = h
        kp, km = neck.locate(x + e, np.zeros(1), None), neck.locate(x - e, np.zeros(1), None)
        assert (kp["g_N"] - km["g_N"])[0] / (2 * h) == pytest.approx(k["dg_N"][0, i], abs=1e-6)
        assert (kp["s"] - km["s"])[0] / (2 * h) == pytest.approx(k["ds"][0, i], abs=1e-6)
        assert np.allclose((kp["dg_N"] - km["dg_N"])[0] / (2 * h), k["d2g_N"][0, i], atol=1e-5)
        assert np.allclose((kp["ds"] - km["ds"])[0] / (2 * h), k["d2s"][0, i], atol=1e-5)


def test_mesh_has_the_papers_element_count():
    mesh = cork_mesh(10.0, 12.0, 24.0, 48.0, 6, 19)
    assert mesh.t.shape[1] == 114
    assert mesh.p[0].max() == pytest.approx(12.0)


def test_newton_failure_is_raised_not_hidden():
    with pytest.raises(NewtonError):
        run_scene("cork", "fast", {"maxit": 1, "max_cuts": 0})


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="R_tip"):
        run_scene("cork", "fast", {"R_tip": 13.0})
    with pytest.raises(ValueError, match="dt"):
        run_scene("cork", "fast", {"dt": -1.0})


@pytest.mark.skipif(not os.environ.get("CONTACTFEM_SLOW"), reason="paper preset (~15-45 s): set CONTACTFEM_SLOW=1")
def test_paper_preset_exit_velocity_within_15_percent():
    r = run_scene("cork", "paper")
    v = r["exit_velocity_m_s"]
    # paper 28 m/s; ours 28.6 m/s when written; tolerance 15 %
    assert abs(v - PAPER_V) / PAPER_V < 0.15, f"paper {PAPER_V} m/s, ours {v:.2f} m/s, tolerance 15 %"
    assert r["max_penetration_ratio"] < 0.02
