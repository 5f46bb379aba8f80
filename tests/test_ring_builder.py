"""make_ring: masses, outline radius, rigid-body measures, the symmetric half ring."""

import numpy as np
import pytest

from contactfem.bodies.ring import make_ring

R, H, B, RHO = 50.0, 1.0, 10.0, 7.85e-8
KW = dict(R=R, thickness=H, width=B, E=2.1e4, nu=0.3, rho=RHO)


def rigid_motion(model, d, phi):
    """Displacement of the rigid motion x = c + d + Rot(phi) (X - c) (beam: theta = phi)."""
    b = model.body
    c = model.center
    Q = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
    x = c + d + (b.X - c) @ Q.T
    u = np.zeros(b.ndof)
    u[b.xdofs] = x - b.X
    if model.kind == "beam":
        u[2::3] = phi
    return u


@pytest.mark.parametrize("n", [8, 40])
def test_beam_mass_is_rho_A_times_perimeter(n):
    ring = make_ring("beam", n_el=n, **KW)
    perimeter = 2 * n * R * np.sin(np.pi / n)  # the polygon's
    assert ring.total_mass() == pytest.approx(RHO * H * B * perimeter, rel=1e-12)
    assert ring.body.I == pytest.approx(B * H**3 / 12)
    # tends to rho A 2 pi R: relative error ~ (pi/n)^2 / 6
    assert ring.total_mass() == pytest.approx(RHO * H * B * 2 * np.pi * R, rel=(np.pi / n) ** 2 / 5)


@pytest.mark.parametrize("n", [8, 40])
def test_continuum_mass_is_rho_times_area(n):
    ring = make_ring("continuum", n_el=n, n_radial=2, **KW)
    Ro, Ri = R + H / 2, R - H / 2
    area = 0.5 * n * np.sin(2 * np.pi / n) * (Ro**2 - Ri**2)  # polygonal annulus
    assert ring.body.volume() == pytest.approx(B * area, rel=1e-12)  # positive: quads are CCW
    assert ring.total_mass() == pytest.approx(RHO * B * area, rel=1e-12)


@pytest.mark.parametrize("kind", ["beam", "continuum"])
def test_outline_radius_and_rigid_measures(kind):
    ring = make_ring(kind, n_el=24, center=(3.0, R + H / 2), **KW)
    d, phi = np.array([7.0, -2.0]), 0.8
    u = rigid_motion(ring, d, phi)
    c = ring.center + d
    P = ring.outline(u)
    assert np.allclose(P[0], P[-1])  # closed polyline
    assert np.allclose(np.hypot(*(P - c).T), R + H / 2, rtol=1e-12)  # outer surface radius
    assert np.allclose(ring.center_of_mass(u), c, atol=1e-9)
    # a rigid motion stores no strain (objectivity of both bodies)
    R_int, _ = ring.body.internal(u)
    assert np.abs(R_int).max() < 1e-8 * ring.body.E * H * B if kind == "continuum" else True
    assert ring.body.strain_energy(u) < 1e-12
    # initial_velocity -> (velocity_of_mass, angular_velocity) round trip
    v = ring.initial_velocity([300.0, -20.0], omega=-5.0)
    assert np.allclose(ring.velocity_of_mass(v), [300.0, -20.0])
    assert ring.angular_velocity(np.zeros(ring.body.ndof), v) == pytest.approx(-5.0)


def test_contact_nodes_are_counter_clockwise_outer_nodes():
    for kind, off in (("beam", H / 2), ("continuum", 0.0)):
        ring = make_ring(kind, n_el=16, **KW)
        X = ring.body.X[ring.contact_nodes]
        a = np.unwrap(np.arctan2(X[:, 1], X[:, 0]))
        assert np.all(np.diff(a) > 0) and len(X) == 16
        assert ring.offset == off
        assert np.allclose(np.hypot(*X.T) + off, R + H / 2)


@pytest.mark.parametrize("kind", ["beam", "continuum"])
def test_half_ring_is_the_symmetric_half(kind):
    full = make_ring(kind, n_el=32, **KW)
    half = make_ring(kind, n_el=16, half=True, **KW)
    assert half.total_mass() == pytest.approx(full.total_mass() / 2, rel=1e-12)
    X = half.body.X
    assert np.all(X[:, 0] <= 1e-9)
    # the mirrored outline covers exactly the full ring's outline points
    P = half.outline(np.zeros(half.body.ndof), mirror=True)
    Q = full.outline(np.zeros(full.body.ndof))[:-1]
    assert len(P) == len(Q) + 1  # top point repeated (closed)
    dist = np.min(np.linalg.norm(P[:, None] - Q[None], axis=2), axis=1)
    assert dist.max() < 1e-9
    # a vertical translation: same centre of mass as the full ring
    u = np.zeros(half.body.ndof)
    u[half.body.xdofs[:, 1]] = -4.0
    assert np.allclose(half.center_of_mass(u), [0.0, -4.0], atol=1e-9)
    # symmetry dofs: u_x (and theta for the beam) on x = 0
    dofs = half.symmetry_dofs()
    if kind == "beam":
        n = X.shape[0]
        assert set(dofs) == {0, 2, 3 * (n - 1), 3 * (n - 1) + 2}
    else:
        nodes = np.flatnonzero(np.abs(X[:, 0]) < 1e-9)
        assert len(nodes) == 2 * 3 and set(dofs) == set(half.body.xdofs[nodes, 0])
    assert half.angular_velocity(u, np.zeros_like(u)) == 0.0


@pytest.mark.parametrize(
    "bad, match",
    [
        (dict(kind="shell"), "kind"),
        (dict(R=-1.0), "R"),
        (dict(thickness=200.0), "thickness"),
        (dict(n_el=2), "n_el"),
        (dict(width=0.0), "width"),
        (dict(nu=0.5), "nu"),
        (dict(kind="continuum", n_radial=0), "n_radial"),
        (dict(kind="continuum", plastic={}), "plastic"),
    ],
)
def test_bad_input(bad, match):
    args = dict(KW, n_el=8)
    args.update(bad)
    with pytest.raises(ValueError, match=match):
        make_ring(**args)
