"""The time resolution of a run, held to the tolerance of its error bars: an impact on a penalty spring
is half a period of a linear oscillator, and the integrator's error over it (its amplification matrix)
sets the thresholds of impact_steps and penalty_steps; every dynamic step carries its local error."""

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

from contactfem import AccuracyWarning, run_scene
from contactfem.problem.accuracy import TOLERANCE
from contactfem.scenes import get_scene
from contactfem.solver.estimate import ErrorModel


def _oscillator(model, omega_dt, n):
    """n Newmark steps of u'' + w^2 u = 0 from u = 1, v = 0 (w = 1, dt = omega_dt): u and v / w at the end."""
    d, b, h = model.delta, model.beta, omega_dt
    u, v, a = 1.0, 0.0, -1.0
    for _ in range(n):
        u1 = (u + h * v + h * h * (0.5 - b) * a) / (1.0 + b * h * h)
        a1 = -u1
        v = v + h * ((1.0 - d) * a + d * a1)
        u, a = u1, a1
    return u, v


@pytest.mark.parametrize("delta,beta", [(0.5, 0.25), (0.7, 0.4), (0.6, 0.3025)])
@pytest.mark.parametrize("n", [3, 7, 20, 60])
def test_half_period_error_is_the_integrators_over_half_a_period(delta, beta, n):
    """At w dt = pi / n, n steps are half a period: the exact motion ends at u = -1, and the error the
    amplification matrix gives is the distance the steps themselves end at: to rounding for the
    trapezoidal rule (1e-6: a small difference of two numbers near 1), within (w dt)^2 / 2 where
    delta > 1/2 (the start (1, 0, -1) is off the principal pair's eigenvectors by O(w dt)^2 there:
    measured 0.11 (w dt)^2 from 3 to 60 steps)."""
    model = ErrorModel(delta, beta)
    u, w = _oscillator(model, math.pi / n, n)
    rel = 1e-6 if delta == 0.5 else (math.pi / n) ** 2 / 2
    assert model.half_period_error(math.pi / n) == pytest.approx(math.hypot(u + 1.0, w), rel=rel)


@pytest.mark.parametrize("omega_dt", [0.05, 0.3, 1.0, 1.9])
def test_trapezoidal_half_period_error_is_its_phase_error(omega_dt):
    """The trapezoidal rule keeps the amplitude: its error over half a period is the phase error alone,
    the closed form |exp(i pi W / w dt) + 1| with W = 2 atan(w dt / 2)."""
    phase = math.pi * 2.0 * math.atan(omega_dt / 2.0) / omega_dt
    closed = abs(complex(math.cos(phase), math.sin(phase)) + 1.0)
    assert ErrorModel(0.5, 0.25).half_period_error(omega_dt) == pytest.approx(closed, rel=1e-9)


@pytest.mark.parametrize("delta,beta", [(0.5, 0.25), (0.7, 0.4), (0.5, 0.0)])
def test_the_resolving_step_errs_by_the_tolerance(delta, beta):
    model = ErrorModel(delta, beta)
    omega = model.resolving_omega_dt(TOLERANCE)
    assert model.half_period_error(omega) == pytest.approx(TOLERANCE, rel=1e-6)
    assert model.half_period_error(0.9 * omega) < TOLERANCE < model.half_period_error(1.1 * omega)


def test_the_rolling_ring_is_held_to_its_contact_while_it_rolls():
    """The ring rolls on its floor from the first step to the last (no impact closes): penalty_steps reads
    every step in contact, dt sqrt(k / m) at the stiffest touching node, the linear penalty's k = c_N w."""
    scene = get_scene("rolling_ring")
    params = scene.resolve("fast", {"t_end": 0.2})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = run_scene("rolling_ring", "fast", {"t_end": 0.2})
    acc = r["accuracy"]
    assert "impact_steps" not in acc and not acc["penalty_steps"]["ok"]
    model = scene.build(params)
    contact, m = model.system.contacts[0], model.system.lumped_mass()
    body = contact.slave
    k = params["c_N"] * np.broadcast_to(np.asarray(contact.weights, float), contact.nodes.shape)
    omega = np.sqrt(k / m[model.system.offset(body) + body.xdofs[contact.nodes, 1]])
    assert omega.min() * params["dt"] <= acc["penalty_steps"]["value"] <= omega.max() * params["dt"] * (1 + 1e-12)
    assert acc["penalty_steps"]["threshold"] == pytest.approx(ErrorModel(0.7, 0.4).resolving_omega_dt(TOLERANCE))


@pytest.mark.slow
def test_the_cork_is_held_to_its_steps_and_a_cork_that_stays_in_warns():
    """The pop's contact is held to its steps (penalty_steps; the press fit it starts in is no impact),
    and a cork that has not left by t_end warns, naming it."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = run_scene("cork", "fast", {"mu": 0.105})
    assert not r["exited"] and "impact_steps" not in r["accuracy"]
    assert not r["accuracy"]["exited"]["ok"] and "penalty_steps" in r["accuracy"]
    assert any(issubclass(w.category, AccuracyWarning) and "accuracy: exited = 0" in str(w.message) for w in caught)


@pytest.mark.slow
def test_a_cork_that_stays_in_exits_1_under_strict():
    cmd = [sys.executable, "-m", "contactfem", "run", "cork", "--set", "mu=0.105", "--strict"]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
    assert out.returncode == 1 and "accuracy: exited = 0" in out.stderr


@pytest.mark.slow
def test_the_corks_ramp_is_its_own_whatever_its_step():
    """The gas reaches 0.8 MPa at t_ramp = 0.8 ms (the paper's 8 steps of its 1e-4 s) whatever dt: at ten times
    the paper's step the cork still leaves (its ramp once lasted 8 ms, past t_end, and it stayed in)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = run_scene("cork", "fast", {"dt": 1e-3})
    assert r["exited"] and r["accuracy"]["exited"]["ok"]
    t, p = np.asarray(r["time_ms"]), np.asarray(r["pressure_MPa"])
    assert p[np.searchsorted(t, 0.8 - 1e-9)] == pytest.approx(0.8, rel=1e-12)
