"""Energy-consistent contact in time (contact/conserving.py, solver/conserving.py).

* the step force's tangent against finite differences: rigid line, arc, polyline and a
  deformable master; frictionless, stick, slip; in contact throughout, closing, opening;
* its work over the step is the change of the interface energy plus the dissipation, and
  the dissipation is >= 0;
* the impact that gains energy under the trapezoidal rule (test_extremes.py, kept there as
  the documented failure of Newmark + an unresolved penalty) conserves it;
* bar_impact: |energy error| < 1e-4 for contact beginning at 5 phases within a step and
  for c_N over 4 decades;
* sloping impact: frictionless, the energy after rebound within 1e-3 of the energy before;
  frictional, the energy never increases and the dissipation equals the loss within 1 %.
"""

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error
from test_contact_tangent import make_master
from test_extremes import throw

from contactfem import AccuracyWarning
from contactfem.contact import BodySurface, NodeToSegment
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.scenes import run_scene
from contactfem.scenes.bar_impact import bar_exact
from contactfem.solver.conserving import EnergyConsistent

FRICTIONS = {
    "none": None,
    "stick": Coulomb(30.0, 10.0),
    "slip": Coulomb(30.0, 0.05),
    "parabolic": ParabolicSlip(30.0, 0.02, 0.03, 0.5),
}
# slave y at the start and the end of the step (gap of a node on the line y = 0)
PHASES = {
    "contact": (-0.02, -0.05),
    "closing": (0.02, -0.04),
    "opening": (-0.03, 0.01),
    "opening_far": (-0.03, 1.5),
}  # a node leaving by more than a unit length in one step


def pair(master, friction, phase, rng):
    """Two slave nodes (and a master body for 'body'); the state committed at u0 after a
    tangential move so that t_T_bar != 0; returns (iface, u0, u1)."""
    y0, y1 = PHASES[phase]
    bodies = []
    if master == "body":
        mb = PointCloud(np.stack([np.linspace(-0.5, 1.5, 4), np.zeros(4)], axis=1), "master")
        bodies.append(mb)
        m = BodySurface(mb, np.arange(4))
    else:
        m = make_master(master)
    off = sum(b.ndof for b in bodies)
    sb = PointCloud([[0.3, 0.0], [0.6, 0.0]], "slave", dof_offset=off)
    n = off + sb.ndof
    iface = NodeToSegment(
        sb,
        [0, 1],
        m,
        normal=PowerLaw(80.0),
        friction=friction,
        weights=np.array([0.7, 1.2]),
        integration="energy_consistent",
    )
    u_prev = np.zeros(n)
    u_prev[off + 1 :: 2] = y0
    u0 = u_prev.copy()
    u0[off::2] += 0.01 if phase != "closing" else 0.0  # a stick load before the step
    u1 = u0.copy()
    u1[off::2] += np.array([0.04, -0.03])
    u1[off + 1 :: 2] = y1 + 0.003 * rng.standard_normal(2)
    if master == "body":
        u1[:off] = 0.003 * rng.standard_normal(off)
    h = iface.start(u_prev)
    h = iface.commit(iface.evaluate(u_prev, history=h))
    h = iface.commit(iface.evaluate(u0, history=h))
    return iface, u0, u1, h


def force(iface, u0, u1, h):
    """The step force (residual and tangent, dense) of the step u0 -> u1 from the history h."""
    G, rows, cols, vals = iface.evaluate(u1, u0=u0, history=h).scatter(len(u1))
    Kg = np.zeros((len(u1), len(u1)))
    np.add.at(Kg, (rows, cols), vals)
    return G, Kg


@pytest.mark.parametrize("master", ["line", "arc_outside", "tilted_polyline", "body"])
@pytest.mark.parametrize("fric", list(FRICTIONS))
@pytest.mark.parametrize("phase", list(PHASES))
def test_step_force_tangent(rng, master, fric, phase):
    iface, u0, u1, h = pair(master, FRICTIONS[fric], phase, rng)
    G, K = force(iface, u0, u1, h)
    assert np.linalg.norm(K) > 0, "no force: the test is vacuous"
    Kfd = fd_jacobian(lambda w: force(iface, u0, w, h)[0], u1, h=1e-7)
    assert rel_error(K, Kfd) < 1e-6, rel_error(K, Kfd)


@pytest.mark.parametrize("master", ["line", "arc_outside", "body"])
@pytest.mark.parametrize("fric", list(FRICTIONS))
@pytest.mark.parametrize("phase", list(PHASES))
def test_step_work_is_energy_change_plus_dissipation(rng, master, fric, phase):
    iface, u0, u1, h = pair(master, FRICTIONS[fric], phase, rng)
    G, _ = force(iface, u0, u1, h)
    W0 = iface.evaluate(u0, history=h).energy  # interface energy at the committed state
    W1 = iface.evaluate(u1, history=h).energy  # at the end (not committed: t_T from the return map)
    D = iface.evaluate(u1, u0=u0, history=h).dissipation  # of the step
    assert D >= -1e-14
    assert G @ (u1 - u0) == pytest.approx(W1 - W0 + D, rel=1e-10, abs=1e-14)


def test_unresolved_penalty_conserves_energy():
    """The impact of test_extremes.test_unresolved_penalty_gains_energy (omega_p dt = 141:
    the trapezoidal rule ends with ~4 E0) with the energy-consistent stepper."""
    from contactfem.solver import integrate
    from test_extremes import quad

    body = quad()
    contact = NodeToSegment(
        body, np.arange(4), make_master("line"), normal=PowerLaw(1e8), weights=0.5, integration="energy_consistent"
    )
    from contactfem.solver import System

    system = System([body], [contact])
    u0, v0 = np.zeros(system.ndof), np.zeros(system.ndof)
    v0[body.xdofs[:, 0]], v0[body.xdofs[:, 1]] = 0.5, -1.0
    hist = integrate(EnergyConsistent(system, atol=1e-9, rtol=1e-9, maxit=40), 0.0, u0, v0, n_steps=30, dt=0.01)
    E = hist.kinetic + hist.strain + hist.contact
    assert np.count_nonzero(hist.contact > 0) + np.count_nonzero(np.diff(np.sign(hist.v[body.xdofs[:, 1]]))) > 0
    assert np.max(np.abs(E - E[0])) <= 1e-6 * E[0]
    # the same throw with Newmark 1/2, 1/4 gains energy (the documented failure)
    hist_n, _ = throw(normal=PowerLaw(1e8), delta=0.5, beta=0.25)
    E_n = hist_n.kinetic + hist_n.strain + hist_n.contact
    assert np.max(E_n) > 1.5 * E_n[0]


# -- bar impact: 5 phases of first contact within a step, c_N over 4 decades ------------


def bar(phase=0.5, c_N_factor=1.0):
    p = dict(n_el=20, courant=1.0, c_N_factor=c_N_factor, contact_integration="energy_consistent")
    ex = bar_exact(100.0, 2.1e5, 7.85e-9, 1000.0)  # the scene's defaults
    dt = p["courant"] * (100.0 / p["n_el"]) / ex["c"]
    p["gap"] = phase * 1000.0 * dt  # contact begins at this phase of step 1
    return run_scene("bar_impact", "fast", p)


@pytest.mark.parametrize("phase", [0.0, 0.2, 0.4, 0.6, 0.8])
def test_bar_impact_energy_any_phase(phase):
    r = bar(phase=phase)
    assert abs(r["energy_error_max"]) < 1e-4, r["energy_error_max"]
    assert abs(r["error_rebound"]) < 0.05  # it did rebound


@pytest.mark.slow
@pytest.mark.parametrize("c_N_factor", [0.1, 1.0, 10.0, 100.0, 1000.0])
def test_bar_impact_energy_any_penalty(c_N_factor):
    r = bar(phase=0.3, c_N_factor=c_N_factor)
    assert abs(r["energy_error_max"]) < 1e-4, r["energy_error_max"]

    def standard():
        return run_scene("bar_impact", "fast", dict(n_el=20, c_N_factor=c_N_factor, gap=r["parameters"]["gap"]))

    if c_N_factor >= 100:
        with pytest.warns(AccuracyWarning, match="energy_gain"):  # and says so
            assert standard()["energy_error"] > 1e-2  # Newmark 1/2, 1/4 gains energy here


# -- sloping impact ---------------------------------------------------------------------


@pytest.mark.slow
def test_sloping_impact_frictionless_conserves_energy():
    r = run_scene("sloping_impact", "fast", {"contact_integration": "energy_consistent"})
    assert r["rebounded"]
    assert abs(r["energy_after_rebound_rel"]) < 1e-3, r["energy_after_rebound_rel"]
    paper = run_scene("sloping_impact", "fast")  # Newmark 0.7/0.4 loses 16 %
    assert paper["energy_after_rebound_rel"] < -0.05


@pytest.mark.slow
def test_sloping_impact_friction_only_dissipates():
    r = run_scene("sloping_impact", "fast", {"contact_integration": "energy_consistent", "variant": "frictional"})
    E, D = np.array(r["energy_total"]), np.array(r["energy_dissipation"])
    assert np.max(np.diff(E)) <= 1e-8 * E[0], "the energy increased in a step"
    assert np.all(np.diff(D) >= -1e-14)
    lost = E[0] - E[-1]
    assert lost > 0.05 * E[0]
    assert D[-1] == pytest.approx(lost, rel=0.01)


def test_viscoplastic_ring_refuses_energy_consistent():
    with pytest.raises(ValueError, match="contact_integration"):
        run_scene("sloping_impact", "fast", {"contact_integration": "energy_consistent", "variant": "viscoplastic"})


@pytest.mark.slow
@pytest.mark.parametrize("scene, over", [("funnel", {"n_steps": 40}), ("rolling_ring", {"t_end": 0.3})])
def test_other_ring_scenes_balance_energy(scene, over):
    """The funnel (rigid polyline, symmetry supports) and the rolling ring (gravity, Coulomb
    friction): energy + dissipation - work of the loads stays the initial energy."""
    r = run_scene(scene, "fast", dict(over, contact_integration="energy_consistent"))
    assert abs(r["energy_error"]) < 1e-6, r["energy_error"]


# -- momentum ---------------------------------------------------------------------------


def flying_ring(kind="beam", omega=0.3, wobble=0.3, n_steps=200, atol=1e-11):
    """The sloping impact's ring (R = 10, A = 1, E = 100, rho = 0.01, 16 elements) flying
    freely with v = (2, -2), a spin omega and a random velocity field of size `wobble` on top
    (it deforms as it flies); energy-consistent steps of the paper's dt = 0.1. Returns the
    records and a function giving (linear momentum, angular momentum about the centre of mass)."""
    from contactfem.bodies.ring import make_ring
    from contactfem.solver import Steps, System, march

    ring = make_ring(kind=kind, R=10.0, thickness=1.0, width=1.0, n_el=16, E=100.0, nu=0.0, rho=0.01)
    system = System([ring.body])
    v0 = ring.initial_velocity((2.0, -2.0), omega=omega)
    v0 = v0 + wobble * np.random.default_rng(0).standard_normal(len(v0))
    records = list(
        march(
            EnergyConsistent(system, atol=atol, rtol=1e-14, maxit=40),
            Steps(0.1, n_steps=n_steps),
            0.0,
            np.zeros(system.ndof),
            v0,
        )
    )
    M, b = system.mass(), ring.body
    rot = b.rotation_dofs

    def momenta(rec):
        """The linear momentum and the angular momentum about the centre of mass,
        sum m (x - x_c) x (v - v_c) + sum J theta_dot."""
        m = M[b.xdofs[:, 0]]
        x, v = b.X + rec.u[b.xdofs], rec.v[b.xdofs]
        xc, vc = m @ x / m.sum(), m @ v / m.sum()
        r, w = x - xc, v - vc
        L = np.sum(m * (r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0])) + np.sum(M[rot] * rec.v[rot])
        return m @ v, L

    return records, momenta


@pytest.mark.slow
def test_free_flight_keeps_momentum_and_energy():
    """A spinning ring that deforms as it flies: the discrete-gradient correction acts on the
    increment without its translation, so the momentum (the centre of mass's velocity) stays
    constant to 1e-10 of its size (the Newton tolerance's share: atol dt / |p| per step,
    1e-11 * 0.1 / 1.8 over 200 steps ~ 1e-10 at worst), and the energy to 1e-10."""
    records, momenta = flying_ring()
    p0, _ = momenta(records[0])
    E = np.array([r.energy["kinetic"] + r.energy["strain"] for r in records])
    assert np.max(np.abs(E - E[0])) <= 1e-10 * E[0]
    drift = max(np.max(np.abs(momenta(r)[0] - p0)) for r in records) / np.max(np.abs(p0))
    assert drift <= 1e-10, drift


@pytest.mark.slow
def test_frictionless_rebound_keeps_the_velocity_along_the_plane():
    """A frictionless flat plane pushes along its normal only: the rebound v_x = 2 to 1e-8
    (the correction's resultant along the plane is zero, whatever the ring's deformation)."""
    r = run_scene("sloping_impact", "fast", {"contact_integration": "energy_consistent"})
    assert r["rebounded"] and abs(r["rebound_vx"] - 2.0) <= 1e-8, r["rebound_vx"]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["beam", "continuum"])
@pytest.mark.parametrize("wobble", [0.0, 0.3])
def test_free_flight_keeps_the_angular_momentum(kind, wobble):
    """A spinning ring, rigid or deforming as it flies: the bodies' discrete gradients have no
    moment (the beam's angles turn by the midpoint rule's Cayley rotation; the continuum's
    stress is a discrete gradient in the Green strain), so the angular momentum about the
    centre of mass stays constant to 1e-10 of its size. What moves it is Newton's last
    residual: quadratic convergence leaves it far below atol (measured: 4e-13 beam, 3e-14
    continuum)."""
    records, momenta = flying_ring(kind=kind, wobble=wobble, n_steps=200)
    L = np.array([momenta(r)[1] for r in records])
    assert np.max(np.abs(L - L[0])) <= 1e-10 * abs(L[0]), np.max(np.abs(L - L[0])) / abs(L[0])
    E = np.array([r.energy["kinetic"] + r.energy["strain"] for r in records])
    assert np.max(np.abs(E - E[0])) <= 1e-10 * E[0]
    if wobble:
        strain = np.array([r.energy["strain"] for r in records])
        assert np.max(strain) > 1e-3 * records[0].energy["kinetic"]  # it does deform


# -- the beam's discrete gradient and the step's tangent -------------------------------


@pytest.mark.parametrize("integration", [1, 2])
def test_beam_discrete_gradient_is_exact_and_has_no_resultant_or_moment(rng, integration):
    """Beam.discrete_gradient of a step with rotations up to ~0.5 rad: its work on dq is
    W(u1) - W(u0) to rounding, it has no resultant and no moment about the origin at the
    midpoint positions -- also where two neighbours turn alike (the divided differences'
    series) -- and its tangent matches central differences (h = 1e-6: truncation ~1e-12 of
    |K|; checked where no two neighbours turn alike, since a difference step of 1e-6 there
    crosses into the closed form's cancellation)."""
    from contactfem.bodies.discrete_gradient import cayley
    from contactfem.bodies.ring import make_ring

    b = make_ring(kind="beam", R=10.0, thickness=1.0, n_el=8, E=100.0, rho=0.01, integration=integration).body
    u0 = 0.3 * rng.standard_normal(b.ndof)
    u0[2::3] = 0.2 * rng.standard_normal(8)
    u1 = u0 + 0.3 * rng.standard_normal(b.ndof)
    u1[2::3] = u0[2::3] + 0.5 * rng.uniform(-1, 1, 8)
    alike = u1.copy()
    alike[5] = u0[5] + (u1[2] - u0[2])  # nodes 0 and 1 turn alike
    for x in (u1, alike):
        F = b.discrete_gradient(u0, x)[0]
        dq = cayley(x - u0, b.rotation_dofs)[0]
        W0, W1 = b.strain_energy(u0), b.strain_energy(x)
        assert abs(F @ dq - (W1 - W0)) <= 1e-12 * (W0 + W1)
        xm = b.positions(0.5 * (u0 + x))
        scale = np.max(np.abs(F)) * 10.0  # (10: the ring's radius)
        assert abs(F[0::3].sum()) <= 1e-12 * scale and abs(F[1::3].sum()) <= 1e-12 * scale
        assert abs(np.sum(xm[:, 0] * F[1::3] - xm[:, 1] * F[0::3]) + F[2::3].sum()) <= 1e-12 * scale * 10.0
    # the series and the closed form agree across the switch (|phi_b - phi_a| = 1e-6)
    near = [alike.copy(), alike.copy()]
    near[0][5] += 0.9e-6
    near[1][5] += 1.1e-6
    Fa, Fb = (b.discrete_gradient(u0, x)[0] for x in near)
    assert np.max(np.abs(Fa - Fb)) <= 1e-5 * np.max(np.abs(Fa))  # (the step itself moves F by ~1e-6)
    F, rows, cols, vals = b.discrete_gradient(u0, u1)
    K = np.zeros((b.ndof, b.ndof))
    np.add.at(K, (rows, cols), vals)
    J = fd_jacobian(lambda x: b.discrete_gradient(u0, x)[0], u1, h=1e-6)
    assert rel_error(K, J) < 1e-6


def step_residual(stepper, u, v, dt):
    """The residual function (u1 -> Evaluation) that an EnergyConsistent step from (u, v) hands to
    Newton, and Newton's first guess: taken from the call, which is stopped there."""
    import contactfem.solver.conserving as conserving

    captured = {}

    def capture(fun, guess, free, **options):
        captured["fun"], captured["guess"] = fun, guess
        raise StopIteration

    real = conserving.newton
    conserving.newton = capture
    try:
        with pytest.raises(StopIteration):
            stepper.step(0.0, u, v, np.zeros_like(u), dt, state=stepper.system.start(u))
    finally:
        conserving.newton = real
    return captured["fun"], captured["guess"]


@pytest.mark.parametrize("variant", ["frictionless", "frictional"])
def test_energy_consistent_step_tangent_with_a_contact_on_the_ring(rng, variant):
    """The whole residual of an energy-consistent step of the sloping impact's ring pressed
    into the plane, sliding (its nodes on the outer face; the contact acts on the positions):
    Newton's tangent against central differences."""
    import contactfem.solver.conserving as conserving
    from contactfem.scenes import get_scene, sloping_impact

    p = get_scene("sloping_impact").resolve("fast", {"variant": variant, "contact_integration": "energy_consistent"})
    m = sloping_impact.build(p)
    ring, system = m.parts["ring"], m.system
    stepper = conserving.EnergyConsistent(system)
    u = np.zeros(system.ndof)
    u[ring.body.xdofs[:, 1]] = -(p["gap0"] + 0.02)  # the lowest nodes pressed in
    v = ring.initial_velocity((p["vx0"], p["vy0"]), omega=0.1)
    fun, guess = step_residual(stepper, u, v, p["dt"])
    u1 = guess + 1e-3 * rng.standard_normal(system.ndof)
    u1[ring.body.xdofs[:, 0]] += 0.05  # slip along the plane
    ev = fun(u1)
    assert np.any([np.any(c.active) for c in ev.contacts])
    J = fd_jacobian(lambda x: fun(x).G, u1, h=1e-7)
    assert rel_error(ev.K.toarray(), J) < 1e-6


@pytest.mark.parametrize("material", ["svk", "neohooke"])
@pytest.mark.parametrize("kind", ["plane_strain", "axisymmetric"])
def test_continuum_discrete_gradient_is_exact_and_has_no_resultant_or_moment(rng, material, kind):
    """Continuum.discrete_gradient of a finite step of a distorted quad mesh: its work on d is
    W(u1) - W(u0) to rounding, it has no resultant (plane: x and y; axisymmetric: along the
    axis) and, in the plane, no moment at the midpoint positions; its tangent matches central
    differences."""
    from contactfem.bodies.continuum import Continuum
    from skfem import MeshQuad

    mesh = MeshQuad.init_tensor(np.linspace(1.0, 2.0, 4), np.linspace(0.0, 1.0, 3))
    b = Continuum(mesh, E=100.0, nu=0.3, rho=1.0, kind=kind, material=material)
    u0 = 0.05 * rng.standard_normal(b.ndof)
    u1 = u0 + 0.05 * rng.standard_normal(b.ndof)
    F, rows, cols, vals = b.discrete_gradient(u0, u1)
    W0, W1 = b.strain_energy(u0), b.strain_energy(u1)
    assert abs(F @ (u1 - u0) - (W1 - W0)) <= 1e-12 * (W0 + W1)
    scale = np.max(np.abs(F)) * 2.0  # (2: the mesh's size)
    assert abs(F[b.xdofs[:, 1]].sum()) <= 1e-12 * scale
    if kind == "plane_strain":
        assert abs(F[b.xdofs[:, 0]].sum()) <= 1e-12 * scale
        xm = b.X + 0.5 * (u0 + u1)[b.xdofs]
        assert abs(np.sum(xm[:, 0] * F[b.xdofs[:, 1]] - xm[:, 1] * F[b.xdofs[:, 0]])) <= 1e-12 * scale * 2.0
    K = np.zeros((b.ndof, b.ndof))
    np.add.at(K, (rows, cols), vals)
    J = fd_jacobian(lambda x: b.discrete_gradient(u0, x)[0], u1, h=1e-6)
    assert rel_error(K, J) < 1e-6


def spun_ring_with_moments():
    """A beam ring spinning at omega = 1 with dt = 0.25 (a quarter radian a step) under a dead
    moment 0.005 on one angle and a torsional spring P = 0.005 - 0.003 theta on another (the
    ring's rotary inertia is small: larger moments spin its nodes by more than the Cayley
    update allows in a step): loads on the angles, which the step turns into forces conjugate
    to phi by the factor Delta theta / phi."""
    from test_solver import DeadLoad, SpringLoad

    from contactfem.bodies.ring import make_ring
    from contactfem.solver import System

    ring = make_ring(kind="beam", R=10.0, thickness=1.0, n_el=16, E=100.0, rho=0.01)
    system = System(
        [ring.body], loads=[DeadLoad(ring.body, [5 * 3 + 2], 0.005), SpringLoad(ring.body, 2, 0.005, 0.003)]
    )
    return ring, system, ring.initial_velocity((1.0, 0.0), omega=1.0)


def test_moments_on_the_angles_balance_the_energy():
    """The spun ring under moments (spun_ring_with_moments): kinetic + strain energy change by
    the loads' work, exactly (to the Newton tolerance; both loads are linear in u, so the
    trapezoidal work the records sum is their exact work), 40 steps of a quarter radian."""
    from contactfem.solver import integrate

    ring, system, v0 = spun_ring_with_moments()
    hist = integrate(
        EnergyConsistent(system, atol=1e-11, rtol=1e-14, maxit=40), 0.0, np.zeros(system.ndof), v0, n_steps=40, dt=0.25
    )
    E = hist.kinetic + hist.strain - hist.external_work
    # the loads do work, 1e-3 E0; without the factor the balance misses 7e-6 E0
    assert np.max(np.abs(hist.external_work)) > 1e-4 * E[0]
    assert np.max(np.abs(E - E[0])) <= 1e-10 * E[0], np.max(np.abs(E - E[0])) / E[0]


def test_energy_consistent_step_tangent_with_moments_on_the_angles(rng):
    """Newton's tangent of a step of the spun ring under moments (the factor Delta theta / phi
    on the loads' rows and its derivative on the diagonal) against central differences."""
    import contactfem.solver.conserving as conserving

    ring, system, v = spun_ring_with_moments()
    stepper = conserving.EnergyConsistent(system)
    fun, guess = step_residual(stepper, np.zeros(system.ndof), v, 0.25)
    u1 = guess + 1e-2 * rng.standard_normal(system.ndof)
    J = fd_jacobian(lambda x: fun(x).G, u1, h=1e-7)
    assert rel_error(fun(u1).K.toarray(), J) < 1e-6


def test_a_step_turning_an_angle_by_pi_is_refused():
    """The Cayley update phi = 2 tan(Delta theta / 2) holds for |Delta theta| < pi: beyond, one
    FloatingPointError naming the dof (Newton reports it as a failed iteration)."""
    from contactfem.bodies.discrete_gradient import cayley

    dq, D, chord, dchord = cayley(np.array([0.3, 1.0, 0.2]), np.array([1]))
    assert dq[1] == pytest.approx(2 * np.tan(0.5)) and chord[1] * dq[1] == pytest.approx(1.0)
    with pytest.raises(FloatingPointError, match="dof 1: the Cayley update allows less than pi"):
        cayley(np.array([0.3, 3.5, 0.2]), np.array([1]))
