"""Interface laws and the return mapping: slip condition, Coulomb limit, dissipation,
bad input, and the student's checker."""

from dataclasses import dataclass

import numpy as np
import pytest

from contactfem import check_law
from contactfem.laws import SLIP, STICK, return_map
from contactfem.contact.kinematics import segment_geometry
from contactfem.laws import Coulomb, ExponentialLaw, ParabolicSlip, PowerLaw, SlipHardening

SHIPPED = [
    Coulomb(c_T=30.0, mu=0.3),
    ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5),
    ParabolicSlip(c_T=1e4, alpha=0.2, beta=0.3, n=0.8),
    SlipHardening(c_T=10.0, mu=0.1, h=0.001),
    SlipHardening(c_T=30.0, mu=0.4, h=-0.3),
    PowerLaw(c_N=1e3),
    PowerLaw(c_N=5.0, m=3.3),
    ExponentialLaw(a=2.0, b=3.0),
]


@pytest.mark.parametrize("law", SHIPPED, ids=repr)
def test_every_shipped_law_passes_the_checker(law):
    report = check_law(law)
    assert report.ok, str(report)


def random_states(rng, n=400):
    g_N = -(10 ** rng.uniform(-6, 0, n))
    t_bar = rng.uniform(-0.3, 0.3, n)
    dg = rng.standard_normal(n) * 10 ** rng.uniform(-8, 0, n)
    q_bar = rng.uniform(0, 2, n)
    return g_N, t_bar, dg, q_bar


@pytest.mark.parametrize("law", SHIPPED[:5], ids=repr)
def test_return_map_lands_on_slip_surface_and_dissipates(rng, law):
    normal = PowerLaw(c_N=10.0)
    g_N, t_bar, dg, q_bar = random_states(rng)
    t_N, dt_N = normal.traction(g_N)
    Yb, _, _ = law.slip_bound(-t_N, q_bar)
    t_bar = t_bar * Yb
    fr = return_map(law, t_N, dt_N, dg, t_bar, q_bar)
    Y, _, _ = law.slip_bound(-t_N, fr.q)
    f = np.abs(fr.t_T) - Y
    slip, stick = fr.state == SLIP, fr.state == STICK
    assert slip.sum() > 20 and stick.sum() > 20
    assert np.max(np.abs(f[slip])) < 1e-10 * max(1.0, Y.max())  # on the surface
    assert np.all(f[stick] <= 1e-12)  # inside when sticking
    assert np.all(fr.dissipation >= 0.0) and np.all(fr.lam[slip] > 0)
    assert np.all(fr.lam[stick] == 0)


def test_parabolic_with_n_1_is_coulomb(rng):
    normal = PowerLaw(c_N=10.0)
    g_N, t_bar, dg, q_bar = random_states(rng)
    t_N, dt_N = normal.traction(g_N)
    a = return_map(ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=1.0), t_N, dt_N, dg, t_bar, q_bar)
    b = return_map(Coulomb(c_T=30.0, mu=0.5), t_N, dt_N, dg, t_bar, q_bar)
    assert np.allclose(a.t_T, b.t_T, rtol=1e-13, atol=1e-15)
    assert np.allclose(a.c_N_s, b.c_N_s) and np.array_equal(a.state, b.state)


def test_parabolic_lowers_friction_coefficient_at_high_pressure():
    law = ParabolicSlip(c_T=1.0, alpha=0.2, beta=0.3, n=0.5)
    p = np.array([0.01, 1.0, 100.0])
    Y, _, _ = law.slip_bound(p, 0 * p)
    assert np.all(np.diff(Y / p) < 0) and np.isclose(Y[1] / p[1], 0.5)


def test_first_touch_with_n_below_one_stays_finite():
    law = ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5)
    normal = PowerLaw(c_N=10.0)
    g_N = -np.array([1e-300, 1e-200, 1e-30, 1e-12])
    fr = return_map(law, *normal.traction(g_N), 1.0, 0.0, 0.0)
    assert np.all(np.isfinite(fr.c_N_s)) and np.all(fr.state == SLIP)


BAD = [
    (lambda: PowerLaw(c_N=-1.0), "c_N"),
    (lambda: PowerLaw(c_N=1.0, m=0.5), "m"),
    (lambda: ParabolicSlip(c_T=1.0, alpha=0.2, beta=0.3, n=0.0), "n"),
    (lambda: ParabolicSlip(c_T=1.0, alpha=0.2, beta=0.3, n=1.5), "n"),
    (lambda: ParabolicSlip(c_T=1.0, alpha=-0.2, beta=0.3), "alpha"),
    (lambda: ParabolicSlip(c_T=1.0, alpha=0.2, beta=-0.3), "beta"),
    (lambda: ParabolicSlip(c_T=-1.0, alpha=0.2, beta=0.3), "c_T"),
    (lambda: Coulomb(c_T=1.0, mu=-0.1), "mu"),
    (lambda: Coulomb(c_T=1.0, mu=float("nan")), "mu"),
    (lambda: ExponentialLaw(a=0.0, b=1.0), "a"),
    (lambda: SlipHardening(c_T=1.0, mu=0.1, h=float("inf")), "h"),
]


@pytest.mark.parametrize("make,name", BAD)
def test_bad_parameters_name_the_parameter_and_range(make, name):
    with pytest.raises(ValueError, match=rf"parameter {name} .*allowed"):
        make()


def test_degenerate_segment_is_refused():
    x = np.array([[0.0, 0.0]])
    with pytest.raises(ValueError, match="zero length"):
        segment_geometry(x, np.array([[1.0, 1.0]]), np.array([[1.0, 1.0]]))


def test_checker_catches_a_wrong_derivative():
    @dataclass(frozen=True)
    class WrongQuadratic:
        """mu grows with pressure, but dY/dp forgets the factor 2."""

        c_T: float = 30.0

        def slip_bound(self, p, q):
            p = np.asarray(p, float)
            return 0.1 * p + 0.01 * p**2, 0.1 + 0.01 * p, 0 * p

    report = check_law(WrongQuadratic())
    assert not report.ok and "finite differences" in str(report)


def test_checker_accepts_a_student_law():
    @dataclass(frozen=True)
    class Tanh:
        """A friction coefficient saturating with pressure."""

        c_T: float = 30.0
        mu: float = 0.4
        p0: float = 1.0

        def slip_bound(self, p, q):
            p = np.asarray(p, float)
            th = np.tanh(p / self.p0)
            return self.mu * self.p0 * th, self.mu * (1 - th**2), 0 * p

    assert check_law(Tanh()).ok
