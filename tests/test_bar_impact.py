"""The bar_impact scene against 1-D wave theory: contact lasts 2 L / c, the contact
stress is rho c v0, the bar rebounds at v0, and no energy is lost (delta = 1/2, beta = 1/4)."""
import pytest

from contactfem.scenes import run_scene


@pytest.fixture(scope="module")
def fast():
    return run_scene("bar_impact", "fast")


def test_contact_duration(fast):
    # exact 2 L / c = 38.7 us; fast preset (40 elements): within 5 % (about h / c too long:
    # the penalty layer c_N = E / h acts like one more element)
    assert abs(fast["error_duration"]) < 0.05, (fast["duration"], fast["duration_exact"])


def test_contact_stress(fast):
    # exact rho c v0 = 40.6 MPa; the mean over the middle of the contact within 1 %,
    # the peak (Gibbs ringing of the discrete wave front) within 20 %
    assert abs(fast["error_stress_mean"]) < 0.01, (fast["stress_mean"], fast["stress_exact"])
    assert fast["stress_peak"] < 1.2 * fast["stress_exact"]


def test_rebound_and_energy(fast):
    # exact: rebound at v0, energy conserved. Ours: rebound within 3 % (the rest stays as
    # vibration), total energy within 1e-3
    assert abs(fast["error_rebound"]) < 0.03, fast["rebound_velocity"]
    assert abs(fast["energy_error_max"]) < 1e-3, fast["energy_error_max"]


def test_dissipative_newmark_loses_energy():
    r = run_scene("bar_impact", "fast", {"delta": 0.7, "beta_newmark": 0.4})
    assert -0.5 < r["energy_error"] < -1e-3        # the paper's 0.7/0.4 damps


def test_bad_parameters_raise():
    with pytest.raises(ValueError):
        run_scene("bar_impact", "fast", {"courant": 0})
