"""Rolling ring (paper Sec. 5.2, Fig 9): closed form, rolling detection, the scene
against the rigid thin-ring solution, and convergence under refinement."""

import numpy as np
import pytest

from contactfem.scenes import get_scene, run_scene
from contactfem.scenes.rings import detect_rolling, rigid_ring_exact

V0, MU, G, R = 300.0, 0.15, 981.0, 50.0


def test_closed_form_thin_hoop():
    # paper Sec 5.2 / NOTES.md: t* = v0 / (2 mu g) = 1.019 s, x* = 229.3 cm, v* = v0 / 2
    ex = rigid_ring_exact(V0, MU, G, R)
    assert ex["t_star"] == pytest.approx(V0 / (2 * MU * G)) and ex["t_star"] == pytest.approx(1.019, abs=1e-3)
    assert ex["x_star"] == pytest.approx(229.36, abs=0.01)
    assert ex["v_star"] == pytest.approx(150.0) and ex["omega_star"] == pytest.approx(-3.0)
    # the paper's later bracketed position, 376 cm, is x(2 s)
    assert rigid_ring_exact(V0, MU, G, R, t=[2.0])["x"][0] == pytest.approx(376.45, abs=0.01)


def test_closed_form_is_consistent():
    t = np.linspace(0, 2, 2001)
    ex = rigid_ring_exact(V0, MU, G, 50.5, k2=2500.0, t=t)
    # dx/dt = v; contact point at rest after t*; v and omega continuous
    assert np.allclose(np.gradient(ex["x"], t)[5:-5], ex["v"][5:-5], atol=0.2)
    after = t > ex["t_star"]
    assert np.allclose(ex["v"][after] + ex["omega"][after] * 50.5, 0.0, atol=1e-9)
    # momentum balance in the sliding phase: m dv = -mu m g dt, I domega = -mu m g a dt
    assert ex["v"][100] == pytest.approx(V0 - MU * G * t[100])
    assert ex["omega"][100] == pytest.approx(-MU * G * 50.5 * t[100] / 2500.0)
    with pytest.raises(ValueError, match="mu"):
        rigid_ring_exact(V0, 0.0, G, R)


def test_detect_rolling_on_a_noisy_kink():
    rng = np.random.default_rng(0)
    t = np.arange(0, 2, 0.02)
    slip = np.maximum(V0 - 2 * MU * G * t, 0.0) + rng.normal(0, 2.0, t.size)
    assert detect_rolling(t, slip, V0) == pytest.approx(V0 / (2 * MU * G), abs=0.01)
    assert detect_rolling(t, np.full_like(t, 100.0), V0) is None  # never rolls


@pytest.fixture(scope="module")
def fast():
    return run_scene("rolling_ring", "fast")


def test_fast_preset_against_the_thin_ring(fast):
    r = fast
    for key in ("t_roll", "x_roll", "v_final", "omega_final", "t", "x_c", "vx_c", "omega", "newton_iterations_total"):
        assert key in r
    assert r["rolled"] and r["newton_iterations_total"] > 0
    # paper (Fig 9, brackets): rolling starts at x = 229 cm, exact 229.4; the paper's own
    # computed value reads "23x" in the scan (230-239 cm: 0.3-4.2 % above the exact). Tolerance
    # 3 %, inside that range. Our discretisation error, measured: +0.9 % on the fast preset
    # (40 elements, dt = 0.02), +0.02 % on the paper's 120 elements and dt = 0.01; it falls
    # under refinement (test_refinement_reduces_the_error).
    assert r["x_roll"] == pytest.approx(229.36, rel=0.03), f"x_roll {r['x_roll']:.1f} vs exact 229.4 (3 %)"
    assert r["t_roll"] == pytest.approx(1.019, rel=0.03), f"t_roll {r['t_roll']:.3f} vs exact 1.019 (3 %)"
    # the rolling speed: on the coarse fast preset the 40-gon loses energy rolling over its
    # corners (a discretisation error that more than halves under refinement: test below); the
    # paper's discretisation is held against the exact value in test_paper_preset_rolling_speed
    assert 0 < r["v_final"] < 150.0 and r["omega_final"] < 0  # rolling forward, losing energy
    # sliding phase: the centre decelerates at mu g (Coulomb, eq 11)
    t, vx = np.asarray(r["t"]), np.asarray(r["vx_c"])
    sl = (t > 0.2) & (t < 0.8)
    decel = -np.polyfit(t[sl], vx[sl], 1)[0]
    assert decel == pytest.approx(MU * G, rel=0.03), f"sliding deceleration {decel:.1f} vs mu g = {MU * G:.1f}"
    # the ring stays on the plane (centre within 0.5 cm of R + h/2)
    assert np.all(np.abs(np.asarray(r["y_c"]) - 50.5) < 0.5)


@pytest.mark.slow
def test_paper_preset_rolling_speed():
    """Paper (Fig 9): 300 -> 150 cm/s exact, computed "149", 0.7 % off. At the paper's 120
    elements and dt = 0.01 ours must be as close to the exact value as the paper's own run, up
    to its last printed digit (+-0.5 cm/s): within (1 + 0.5) / 150 = 1.0 %. The angular speed
    of rolling without slip follows, omega = -v / R (within the same 1 %). (The run is the
    figures' and the summary's: plots.cached_run.)"""
    from contactfem.plots import cached_run

    r = cached_run("rolling_ring", "paper")
    assert r["v_final"] == pytest.approx(150.0, rel=0.01), f"v_final {r['v_final']:.2f} vs exact 150 (1 %)"
    assert r["omega_final"] == pytest.approx(-r["v_final"] / r["rolling_radius"], rel=0.01)


@pytest.mark.slow
def test_refinement_reduces_the_error(fast):
    # mesh and step refined together (twice the fast preset's elements, half its step): both errors shrink
    p = get_scene("rolling_ring").resolve("fast", {})
    fine = run_scene("rolling_ring", "fast", {"n_el": 2 * p["n_el"], "dt": p["dt"] / 2})
    assert abs(fine["x_roll_rel_err"]) < abs(fast["x_roll_rel_err"])
    assert abs(fine["v_final_rel_err"]) < 0.5 * abs(fast["v_final_rel_err"]), (
        f"v error {fine['v_final_rel_err']:.4f} (refined) vs {fast['v_final_rel_err']:.4f} (fast)"
    )


@pytest.mark.slow
def test_continuum_ring_rolls_too():
    # a short, coarse continuum run: rolling starts near the rigid-ring point
    r = run_scene("rolling_ring", "fast", {"kind": "continuum", "n_radial": 1, "n_el": 24, "dt": 1 / 30, "t_end": 1.4})
    assert r["rolled"] and r["rolling_radius"] == pytest.approx(50.5)
    assert r["x_roll"] == pytest.approx(r["x_roll_model"], rel=0.03)


def test_bad_parameter():
    with pytest.raises(ValueError, match="mu"):
        get_scene("rolling_ring").resolve("fast", {"mu": -0.1})


@pytest.mark.slow
def test_fig09_draws_from_the_result(fast, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from contactfem.plots import savefig
    from contactfem.plots.rolling_ring import draw_rolling

    path = savefig(draw_rolling(fast, "Fig 9 (test)"), str(tmp_path), "fig09_rolling_ring")
    assert (tmp_path / "fig09_rolling_ring.png").stat().st_size > 10_000, path
