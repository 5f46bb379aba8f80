"""Lumped and consistent mass (bodies' ``mass(consistent=True)``, ``mass_matrix``; System.mass).

* the matrices: symmetric, row sums = the lumped mass; the beam's equals scikit-fem's P1 mass on
  its arc-length mesh (translations and rotations); a rigid translation's and, for the
  consistent continuum, a rigid rotation's kinetic energy in closed form;
* a free oscillator (one beam element stretched along its axis: linear, the strain x'.t - 1
  is exact) follows the trapezoidal rule's closed form u_n = u_0 cos(n Omega dt),
  tan(Omega dt / 2) = omega dt / 2, with omega^2 = 12 E / (rho L^2) (consistent) or
  4 E / (rho L^2) (lumped);
* Newmark 1/2, 1/4 conserves the energy of a linear body with the consistent mass;
* momentum in free flight with either mass and either stepper;
* the same run dense, banded and sparse; the ring scenes' parameter.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from contactfem.bodies.beam import Beam, ring
from contactfem.bodies.ring import make_ring
from contactfem.solver import Newmark, System, integrate
from contactfem.solver.conserving import EnergyConsistent


def rect_continuum(mass_matrix="consistent", nx=6, ny=3, a=3.0, b=1.5, material="linear", rho=2.0):
    from skfem import MeshQuad

    from contactfem.bodies.continuum import Continuum

    mesh = MeshQuad.init_tensor(np.linspace(0, a, nx + 1), np.linspace(0, b, ny + 1))
    return Continuum(
        mesh, E=100.0, nu=0.3, rho=rho, kind="plane_strain", material=material, thickness=0.5, mass_matrix=mass_matrix
    )


@pytest.mark.parametrize("rotary", [True, False])
def test_beam_consistent_mass_is_the_p1_mass_on_the_arc_length(rotary):
    from skfem import Basis, BilinearForm, ElementLineP1, MeshLine, asm

    b = Beam(ring(2.0, 9), closed=True, E=1.0, A=0.3, I=0.02, rho=1.7, rotary_inertia=rotary)
    M = b.mass(consistent=True)
    assert sp.issparse(M) and abs(M - M.T).max() == 0.0
    assert np.allclose(np.asarray(M.sum(axis=1)).ravel(), b.mass(), rtol=1e-14, atol=0)
    P1 = asm(BilinearForm(lambda u, v, w: u * v), Basis(MeshLine(b.s), ElementLineP1()))
    F = sp.csr_matrix((np.ones(len(b.fold)), (np.arange(len(b.fold)), b.fold)))  # mesh node -> beam node
    scalar = (F.T @ P1 @ F).toarray()  # the closed ring: node L identified with node 0
    for k, m in enumerate((b.A, b.A, b.I if rotary else 0.0)):
        assert np.allclose(M.toarray()[k::3, k::3], b.rho * m * scalar, rtol=1e-13, atol=1e-15)


def test_continuum_consistent_mass_rigid_motions_in_closed_form():
    """vT M v of a rigid translation is m |v|^2 with either mass; of a rigid rotation about the
    centroid, omega^2 rho t a b (a^2 + b^2) / 12 with the consistent mass (bilinear elements
    hold a linear velocity field exactly), which the lumped mass does not give."""
    a, b, rho, t = 3.0, 1.5, 2.0, 0.5
    body = rect_continuum("consistent", a=a, b=b, rho=rho)
    M, m = body.mass(consistent=True), body.mass()
    assert np.allclose(np.asarray(M.sum(axis=1)).ravel(), m, rtol=1e-13, atol=0)
    v = np.zeros(body.ndof)
    v[body.xdofs[:, 0]], v[body.xdofs[:, 1]] = 0.3, -0.4
    mass = rho * t * a * b
    assert v @ (M @ v) == pytest.approx(mass * 0.25, rel=1e-13) and v @ (m * v) == pytest.approx(mass * 0.25, rel=1e-13)
    r = body.X - [a / 2, b / 2]
    w = np.zeros(body.ndof)
    w[body.xdofs[:, 0]], w[body.xdofs[:, 1]] = -r[:, 1], r[:, 0]  # omega = 1
    exact = rho * t * a * b * (a * a + b * b) / 12
    assert w @ (M @ w) == pytest.approx(exact, rel=1e-13)
    assert abs(w @ (m * w) / exact - 1) > 1e-3  # lumping moves mass outwards


@pytest.mark.parametrize("mass_matrix, omega2", [("consistent", 12.0), ("lumped", 4.0)])
def test_free_oscillator_follows_the_trapezoidal_closed_form(mass_matrix, omega2):
    """One beam element, both ends free, stretched by a along its axis and let go: the axial mode
    (1, -1) with omega^2 = omega2 E / (rho L^2). Newmark 1/2, 1/4 advances it by the rotation
    cos(Omega dt) = (1 - (omega dt / 2)^2) / (1 + (omega dt / 2)^2) exactly (a linear problem: the
    axial strain is exact in u), so u_n = u_0 cos(n Omega dt) to round-off, over two periods."""
    E, A, rho, L, a = 50.0, 0.2, 3.0, 2.0, 1e-3
    beam = Beam(np.array([[0.0, 0.0], [L, 0.0]]), closed=False, E=E, A=A, I=0.01, rho=rho, mass_matrix=mass_matrix)
    system = System([beam])
    assert system.mass_matrix == mass_matrix
    omega = np.sqrt(omega2 * E / (rho * L * L))
    dt = 2 * np.pi / omega / 40
    u0 = np.array([-a / 2, 0, 0, a / 2, 0, 0])
    hist = integrate(Newmark(system, 0.5, 0.25, atol=1e-14, rtol=1e-14), 0.0, u0, np.zeros(6), n_steps=80, dt=dt)
    Omega = 2 * np.arctan(omega * dt / 2) / dt
    stretch = np.array([r.u[3] - r.u[0] for r in hist.records])
    assert np.allclose(stretch, a * np.cos(Omega * hist.t), rtol=0, atol=1e-10 * a)
    assert np.allclose([r.u[0] + r.u[3] for r in hist.records], 0.0, atol=1e-14)  # no drift of the centre


def test_newmark_trapezoidal_conserves_the_energy_with_the_consistent_mass():
    """A linear body, free, with a random initial velocity: kinetic (1/2 v.M v, consistent M) plus
    strain energy is an invariant of Newmark 1/2, 1/4 (to Newton's tolerance)."""
    body = rect_continuum("consistent")
    system = System([body])
    v0 = np.random.default_rng(3).normal(size=body.ndof)
    hist = integrate(
        Newmark(system, 0.5, 0.25, atol=1e-13, rtol=1e-13), 0.0, np.zeros(body.ndof), v0, n_steps=30, dt=0.05
    )
    E = hist.kinetic + hist.strain
    assert hist.kinetic[0] == pytest.approx(0.5 * v0 @ (body.mass(consistent=True) @ v0), rel=1e-14)
    assert np.max(np.abs(E - E[0])) <= 1e-10 * E[0]
    assert np.max(hist.strain) > 0.1 * E[0]  # it does vibrate


def test_initial_acceleration_solves_with_the_consistent_mass():
    from contactfem.solver import initial_acceleration

    body = rect_continuum("consistent")
    system = System([body])
    u = 1e-2 * np.random.default_rng(4).normal(size=body.ndof)
    a0 = initial_acceleration(system, 0.0, u)
    R = body.internal(u)[0]
    assert np.allclose(body.mass(consistent=True) @ a0, -R, rtol=0, atol=1e-10 * np.abs(R).max())


@pytest.mark.parametrize("stepper", ["newmark", "energy_consistent"])
@pytest.mark.parametrize("mass_matrix", ["lumped", "consistent"])
def test_free_flight_keeps_the_momentum_with_either_mass(stepper, mass_matrix):
    """A deforming ring in free flight (no force: its internal forces have no resultant): the
    centre-of-mass velocity (the momentum 1^T M v over the mass; M symmetric, so the row sums,
    RingModel.velocity_of_mass) stays constant to 1e-10 of the speed."""
    rg = make_ring("beam", R=10.0, thickness=1.0, n_el=16, E=100.0, rho=0.01, mass_matrix=mass_matrix)
    system = System([rg.body])
    v0 = rg.initial_velocity((2.0, -1.0), omega=0.05)
    v0[rg.body.xdofs[:, 0]] += 0.3 * np.sin(np.arange(16))  # a deformation mode on top
    step = (
        Newmark(system, 0.7, 0.4, atol=1e-12, rtol=1e-12)
        if stepper == "newmark"
        else EnergyConsistent(system, atol=1e-12, rtol=1e-12)
    )
    hist = integrate(step, 0.0, np.zeros(system.ndof), v0, n_steps=30, dt=0.1)
    vc = np.array([rg.velocity_of_mass(r.v) for r in hist.records])
    assert np.max(np.abs(vc - vc[0])) <= 1e-10 * np.hypot(*vc[0])
    assert rg.angular_velocity(np.zeros(system.ndof), rg.initial_velocity((0.0, 0.0), omega=0.05)) == pytest.approx(
        0.05, rel=1e-12
    )  # a rigid spin measured exactly with either mass


def test_energy_consistent_conserves_the_energy_with_the_consistent_mass():
    """The nonlinear beam ring in free flight, deforming: the energy-consistent stepper keeps
    kinetic (consistent M) plus strain energy to Newton's tolerance."""
    rg = make_ring("beam", R=10.0, thickness=1.0, n_el=16, E=100.0, rho=0.01, mass_matrix="consistent")
    system = System([rg.body])
    v0 = rg.initial_velocity((1.0, 0.5))
    v0[rg.body.xdofs[:, 1]] += 0.5 * np.cos(2 * np.arange(16) * 2 * np.pi / 16)
    hist = integrate(
        EnergyConsistent(system, atol=1e-12, rtol=1e-12), 0.0, np.zeros(system.ndof), v0, n_steps=40, dt=0.2
    )
    E = hist.kinetic + hist.strain
    assert np.max(np.abs(E - E[0])) <= 1e-9 * E[0]
    assert np.max(hist.strain) > 1e-3 * E[0]


@pytest.mark.parametrize("variant", ["frictionless", "frictional"])
def test_consistent_mass_run_is_the_same_dense_and_sparse(variant):
    """The sloping impact with the consistent mass (48 unknowns: dense by default) forced onto
    the sparse path: every number agrees to 1e-12 of its largest value, iteration counts
    exactly (as test_speed_paths does for the lumped mass)."""
    from contactfem.scenes import run_scene

    over = dict(variant=variant, mass_matrix="consistent", n_steps=50)
    dense, sparse = (run_scene("sloping_impact", "paper", over, linear_algebra=la) for la in ("auto", "sparse"))
    assert (dense["linear_algebra"], sparse["linear_algebra"]) == ("dense", "sparse")
    same_run(dense, sparse)


# Numbers compared on a scale of their own kind, not against their own size (which is round-off
# where they vanish): energy changes as fractions of the initial energy E0 (differences of nearly
# equal numbers), the spin (0 to round-off without friction) against the ring's rigid spin scale
# |v0| / R = 0.28 (absolutely, to 1e-12 of it).
ABSOLUTE = dict.fromkeys(
    (
        "energy_total_max_rel_increase_per_step",
        "energy_total_max_rel_change_impact",
        "energy_error",
        "energy_error_max",
        "energy_after_rebound_rel",
        "energy_total_final_rel",
    ),
    1e-12,
) | {"rebound_spin": 0.28e-12, "outline_spin": 0.28e-12}


def same_run(a, b):
    from test_speed_paths import DERIVED, numbers_agree

    skip = ("wall_time_s", "linear_algebra", "ordering", "band_kl", "band_ku", "import_time_s") + DERIVED
    numbers_agree(a, b, skip=skip + tuple(ABSOLUTE))
    for k, tol in ABSOLUTE.items():
        if a.get(k) is not None:
            assert np.max(np.abs(np.subtract(a[k], b[k]))) <= tol, k


@pytest.mark.slow
def test_consistent_mass_continuum_is_the_same_banded_and_sparse():
    """A continuum ring (above the dense limit) in a frictional impact with the consistent mass:
    banded and sparse (and dense) give the same run, to 1e-12."""
    from contactfem.scenes import run_scene

    over = dict(kind="continuum", n_el=24, variant="frictional", mass_matrix="consistent", n_steps=40)
    runs = {la: run_scene("sloping_impact", "paper", over, linear_algebra=la) for la in ("banded", "sparse", "dense")}
    assert runs["banded"]["unknowns"] > 100 and runs["banded"]["linear_algebra"] == "banded"
    same_run(runs["banded"], runs["sparse"])
    same_run(runs["banded"], runs["dense"])


def test_ring_scenes_take_the_mass_matrix():
    """Every ring scene has mass_matrix (default lumped, the paper's 'lumping technique'); a
    consistent mass changes the run, not the mass: the total mass and the rigid ring's inertia
    measure the same body."""
    from contactfem.scenes import get_scene, run_scene

    for name in ("sloping_impact", "rolling_ring", "funnel"):
        assert get_scene(name).resolve("paper")["mass_matrix"] == "lumped"
    with pytest.raises(ValueError, match="mass_matrix"):
        get_scene("funnel").resolve("fast", {"mass_matrix": "diagonal"})
    lumped, consistent = (
        run_scene("sloping_impact", "paper", dict(mass_matrix=m, n_steps=40)) for m in ("lumped", "consistent")
    )
    assert consistent["mass"] == pytest.approx(lumped["mass"], rel=1e-14)
    assert consistent["rebound_vy"] != lumped["rebound_vy"]
