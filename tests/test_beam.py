"""Tests of the geometrically exact plane beam (contactfem/bodies/beam.py)."""

import numpy as np
import pytest
from scipy.sparse.linalg import spsolve

from contactfem.bodies.beam import Beam, BeamGravity, ring


def straight(L, n_el):
    return np.column_stack([np.linspace(0, L, n_el + 1), np.zeros(n_el + 1)])


def fd_tangent(beam, u, h=1e-6, dt=None):
    """Central finite differences of internal(u)[0]."""
    cols = []
    for e in np.eye(beam.ndof):
        cols.append((beam.internal(u + h * e, dt)[0] - beam.internal(u - h * e, dt)[0]) / (2 * h))
    return np.array(cols).T


def newton(beam, P, free, u, tol=1e-10, maxit=30):
    """Tiny local Newton loop: solve R(u) = P on the free dofs."""
    for _ in range(maxit):
        R, K = beam.internal(u)
        r = (R - P)[free]
        if np.linalg.norm(r) <= tol * max(1.0, np.linalg.norm(P)):
            return u
        u = u.copy()
        u[free] -= spsolve(K[free][:, free].tocsc(), r)
    raise AssertionError("Newton did not converge")


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("plastic", [None, dict(N0=20.0, Q0=10.0, M0=5.0, eta=0.1)])
@pytest.mark.parametrize("integration", [1, 2])
def test_tangent_matches_finite_differences(closed, plastic, integration):
    rng = np.random.default_rng(1)
    X = ring(2.0, 7) if closed else np.column_stack([np.linspace(0, 3, 6), 0.2 * np.linspace(0, 3, 6) ** 2])
    beam = Beam(X, closed, E=100.0, A=1.0, I=0.1, rho=1.0, plastic=plastic, integration=integration)
    u = 0.1 * rng.standard_normal(beam.ndof)
    u[2::3] = 1.5 * rng.standard_normal(X.shape[0])  # large rotations
    dt = 0.1 if plastic else None
    if plastic:
        ep = 0.005 * rng.standard_normal(beam.start(u).shape)
        S = beam.resultants(u, dt=dt, state=ep)[0]
        yielding = np.abs(S) > beam.S0
        assert yielding.any() and not yielding.all()  # both branches are exercised
    R, K = beam.internal(u, dt)
    Kfd = fd_tangent(beam, u, dt=dt)
    assert np.abs(K.toarray() - Kfd).max() <= 1e-6 * np.abs(Kfd).max()
    if not plastic:  # R is the gradient of the strain energy
        h = 1e-6
        g = [(beam.strain_energy(u + h * e) - beam.strain_energy(u - h * e)) / (2 * h) for e in np.eye(beam.ndof)]
        assert np.allclose(g, R, atol=1e-6 * np.abs(R).max())


def test_cantilever_rolls_into_a_circle():
    """End moment M = 2 pi EI / L bends the cantilever into a full circle of radius L / (2 pi)."""
    L, EI = 10.0, 2.0
    errors = []
    for n_el in (8, 16, 32):
        beam = Beam(straight(L, n_el), False, E=EI / 0.01, A=1.0, I=0.01, rho=0.0)
        free = np.arange(3, beam.ndof)  # clamp node 0
        u, P = np.zeros(beam.ndof), np.zeros(beam.ndof)
        for lam in np.linspace(0, 1, 9)[1:]:  # 8 load steps
            P[-1] = lam * 2 * np.pi * EI / L
            u = newton(beam, P, free, u)
        x = beam.positions(u)
        assert np.linalg.norm(x[-1] - x[0]) < 1e-8 * L  # the tip returns to the clamp
        assert abs(u[-1] - 2 * np.pi) < 1e-8  # after a full turn
        radius = np.linalg.norm(x - x[:-1].mean(axis=0), axis=1)
        assert np.ptp(radius) < 1e-8 * L  # the nodes lie on one circle
        errors.append(abs(radius.mean() - L / (2 * np.pi)))
    assert errors[0] < 0.03 * L / (2 * np.pi)
    assert errors[1] < errors[0] / 3.5 and errors[2] < errors[1] / 3.5  # O(h^2) convergence


def test_small_tip_load_matches_timoshenko():
    """Stubby cantilever (h / L = 0.2): the shear term is 3 % of the tip deflection."""
    L, E, nu, b, h, P = 1.0, 1000.0, 0.3, 0.5, 0.2, 1e-4
    A, I = b * h, b * h**3 / 12
    beam = Beam(straight(L, 64), False, E=E, A=A, I=I, rho=0.0, nu=nu)
    G = E / (2 * (1 + nu))
    free = np.arange(3, beam.ndof)
    F = np.zeros(beam.ndof)
    F[-2] = P
    u = newton(beam, F, free, np.zeros(beam.ndof))
    exact = P * L**3 / (3 * E * I) + P * L / (5 / 6 * G * A)
    assert u[-2] == pytest.approx(exact, rel=2e-4)


@pytest.mark.parametrize("closed", [False, True])
def test_rigid_body_motion_gives_no_force(closed):
    X = ring(3.0, 12) if closed else np.column_stack([np.linspace(0, 4, 9), np.sin(np.linspace(0, 4, 9))])
    beam = Beam(X, closed, E=100.0, A=1.0, I=0.1, rho=1.0)
    alpha, c, d = 2.3, np.array([1.0, -0.5]), np.array([5.0, 7.0])
    Rot = np.array([[np.cos(alpha), -np.sin(alpha)], [np.sin(alpha), np.cos(alpha)]])
    x = c + (X - c) @ Rot.T + d
    u = np.column_stack([x - X, np.full(len(X), alpha)]).ravel()
    R, _ = beam.internal(u)
    assert np.abs(R).max() < 1e-12 * 100.0
    assert beam.strain_energy(u) < 1e-20


@pytest.mark.parametrize("closed", [False, True])
def test_lumped_mass_and_gravity(closed):
    X = ring(3.0, 10) if closed else straight(4.0, 5)
    rho, A, I = 2.0, 0.5, 0.04
    beam = Beam(X, closed, E=1.0, A=A, I=I, rho=rho)
    L = beam.L0.sum()
    m = beam.mass().reshape(-1, 3)
    assert m[:, 0].sum() == pytest.approx(rho * A * L)
    assert m[:, 1].sum() == pytest.approx(rho * A * L)
    assert m[:, 2].sum() == pytest.approx(rho * I * L)
    assert np.all(Beam(X, closed, E=1.0, A=A, I=I, rho=rho, rotary_inertia=False).mass()[2::3] == 0)
    beam.dof_offset = 4
    P, rows, *_ = BeamGravity(beam, 9.81).assemble(np.zeros(beam.ndof + 6), 0.0)
    assert P[4 + beam.xdofs[:, 1]].sum() == pytest.approx(-9.81 * rho * A * L)
    assert P[:4].sum() == 0 and rows.size == 0


def test_viscoplastic_bar_follows_the_closed_form():
    """Uniaxial stretch past N0: N = N0 + (EA eps - N0) eta/(eta + dt); commit keeps the plastic strain."""
    EA, N0, eta, dt = 100.0, 1.0, 0.1, 0.05
    beam = Beam(straight(1.0, 2), False, E=EA, A=1.0, I=0.1, rho=0.0, plastic=dict(N0=N0, Q0=0.5, M0=0.25, eta=eta))
    u = np.zeros(beam.ndof)
    u[3 * np.arange(3)] = 0.03 * np.linspace(0, 1, 3)  # eps = 0.03
    N = beam.resultants(u, dt=dt)[0][:, 0]
    assert np.allclose(N, N0 + (EA * 0.03 - N0) * eta / (eta + dt))
    ep = beam.commit(u, dt, beam.start(u))
    assert np.allclose(
        beam.resultants(np.zeros(beam.ndof), dt=dt, state=ep)[0][:, 0], -(EA * 0.03 - N)
    )  # residual strain
    assert np.all(beam.resultants(np.zeros(beam.ndof), dt=dt)[0][:, 0] == 0)  # the beam itself kept nothing


def test_offset_positions_and_jacobian():
    beam = Beam(ring(2.0, 8), True, E=1.0, A=1.0, I=1.0, rho=1.0)
    u = np.random.default_rng(3).standard_normal(beam.ndof)
    h = -0.25  # outward for a counter-clockwise ring
    x0 = beam.offset_positions(np.zeros(beam.ndof), h)
    assert np.allclose(np.linalg.norm(x0, axis=1), 2.25)
    J = beam.offset_jacobian(u, h)
    for k in range(3):
        e = np.zeros(beam.ndof)
        e[k::3] = 1e-6
        fd = (beam.offset_positions(u + e, h) - beam.offset_positions(u - e, h)) / 2e-6
        assert np.allclose(fd, J[:, :, k], atol=1e-8)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(E=-1.0), "E"),
        (dict(A=0.0), "A"),
        (dict(I=np.nan), "I"),
        (dict(rho=-1.0), "rho"),
        (dict(nu=0.7), "nu"),
        (dict(kappa_s=0.0), "kappa_s"),
        (dict(X=np.zeros((1, 2))), "X"),
        (dict(X=np.zeros((3, 2))), "X"),
        (dict(plastic=dict(N0=-1.0)), "N0"),
        (dict(plastic=dict(eta=0.0)), "eta"),
        (dict(plastic=dict(K0=1.0)), "plastic"),
    ],
)
def test_bad_input_names_the_parameter(kwargs, name):
    args = dict(X=straight(1.0, 4), closed=False, E=1.0, A=1.0, I=1.0, rho=1.0) | kwargs
    with pytest.raises(ValueError, match=name):
        Beam(**args)


def test_two_point_integration_is_exact_for_a_rigid_motion_and_stiffer_in_bending():
    """Two-point Gauss: no force under a rigid rotation; a cantilever tip deflection smaller
    than the midpoint rule's (the two-point element locks in shear)."""
    X = straight(2.0, 4)
    deflection = {}
    for n in (1, 2):
        beam = Beam(X, False, E=100.0, A=1.0, I=0.01, rho=0.0, integration=n)
        c, s_ = np.cos(0.7), np.sin(0.7)
        u = np.zeros(beam.ndof).reshape(-1, 3)
        u[:, 0], u[:, 1], u[:, 2] = c * X[:, 0] - s_ * X[:, 1] - X[:, 0], s_ * X[:, 0] + c * X[:, 1] - X[:, 1], 0.7
        assert np.abs(beam.internal(u.ravel())[0]).max() < 1e-10
        R, K = beam.internal(np.zeros(beam.ndof))
        free = np.arange(3, beam.ndof)
        f = np.zeros(beam.ndof)
        f[-2] = -1e-3
        deflection[n] = -spsolve(K[free][:, free].tocsc(), f[free])[-2]
    assert 0 < deflection[2] < 0.75 * deflection[1], deflection  # 4 elements: 0.54 of the midpoint rule


def test_bad_helper_input():
    with pytest.raises(ValueError, match="n_el"):
        ring(1.0, 2)
    with pytest.raises(ValueError, match="R"):
        ring(-1.0, 8)
    beam = Beam(straight(1.0, 4), False, E=1.0, A=1.0, I=1.0, rho=1.0, plastic={})
    with pytest.raises(ValueError, match="dt"):
        beam.internal(np.zeros(beam.ndof), 0.0)
    with pytest.raises(RuntimeError, match="dt"):
        beam.internal(np.zeros(beam.ndof))


@pytest.mark.parametrize("closed", [False, True])
@pytest.mark.parametrize("rotary_inertia", [False, True])
def test_lumped_mass_is_the_row_sums_of_scikit_fems_p1_mass(closed, rotary_inertia):
    """mass() (L0 / 2 to each element end, summed with numpy) is the row sums of the P1 mass
    matrix scikit-fem assembles on the arc-length mesh (the last node folded onto the first
    in a ring), to the rounding of a sum of two terms: 1e-14."""
    from skfem import Basis, ElementLineP1, asm
    from skfem.models import mass

    X = ring(2.0, 9) if closed else np.column_stack([np.linspace(0, 3, 7) ** 1.3, 0.2 * np.linspace(0, 3, 7) ** 2])
    beam = Beam(X, closed, E=100.0, A=0.5, I=0.1, rho=3.0, rotary_inertia=rotary_inertia)
    rows = np.asarray(asm(mass, Basis(beam.mesh, ElementLineP1())).sum(axis=1)).ravel()
    length = np.bincount(beam.fold, rows, minlength=len(X))
    ref = 3.0 * np.column_stack([0.5 * length, 0.5 * length, 0.1 * length * rotary_inertia]).ravel()
    assert np.allclose(beam.mass(), ref, rtol=1e-14, atol=0)
    assert np.allclose(beam.mesh.p.ravel(), beam.s, rtol=0, atol=0)
