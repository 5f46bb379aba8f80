"""Stability at the extremes (issue 6): a unit quad (plane strain, E = 100, rho = 1, all
four nodes slaves) thrown at obstacles with laws and steps at the ends of their ranges.

Every case either converges to finite, physical results or raises the solver's clear
error (NewtonError, or ValueError for a forbidden parameter); none returns NaN, none
loops (Newton's maxit = 25 with at most 3 step halvings bounds the work of each step).
"Physical" here: the tangential traction respects the slip bound, and where the
penalty is resolved by the time step (omega_p dt <= 2, omega_p = sqrt(c_N w / m_node))
the total energy (kinetic + strain + interface) never exceeds the initial energy
(Newmark 0.7/0.4 is dissipative) and the recorded frictional dissipation is not more
than the energy lost (+5 %: the return map records lambda |t_T| at the end of the step,
which over-counts the first slipping step by up to a factor 2, see test_energy.py). Where the penalty is NOT
resolved, implicit Newmark
pumps energy into an impact (see test_unresolved_penalty_gains_energy).
"""

import numpy as np
import pytest
from skfem import MeshQuad

from contactfem.bodies.continuum import Continuum
from contactfem.contact import BodySurface, NodeToSegment, RigidArc, RigidLine, RigidPolyline
from contactfem.laws.return_map import return_map
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.solver import Dirichlet, Newmark, NewtonError, System, integrate

E, RHO, W = 100.0, 1.0, 0.5  # modulus, density, slave weight (half the quad side)
M_NODE = RHO / 4  # lumped mass of a node of the unit quad


def quad(origin=(0.0, 0.0), material="linear", name="quad"):
    mesh = MeshQuad.init_tensor(np.array([0.0, 1.0]) + origin[0], np.array([0.0, 1.0]) + origin[1])
    return Continuum(mesh, E, 0.3, RHO, kind="plane_strain", material=material, name=name)


def throw(
    normal=None,
    friction=None,
    master=None,
    v=(0.5, -1.0),
    dt=0.01,
    n_steps=30,
    origin=(0.0, 0.0),
    material="linear",
    delta=0.7,
    beta=0.4,
    extra_bodies=(),
    fixed=(),
):
    """Throw the unit quad at `master` with velocity v; returns (history, contact)."""
    body = quad(origin, material)
    contact = NodeToSegment(
        body,
        np.arange(4),
        master or RigidLine((0, 0), (0, 1)),
        normal=normal or PowerLaw(1e3),
        friction=friction,
        weights=W,
    )
    system = System([body, *extra_bodies], [contact], fixed=list(fixed))
    u0, v0 = np.zeros(system.ndof), np.zeros(system.ndof)
    v0[body.xdofs[:, 0]], v0[body.xdofs[:, 1]] = v
    stepper = Newmark(system, delta, beta, atol=1e-9, rtol=1e-9, maxit=25)
    return integrate(stepper, 0.0, u0, v0, n_steps=n_steps, dt=dt, cutback=True, max_cuts=3), contact


def outcome(energy_check=True, **kw):
    """'ok' after checking finiteness and physics, or 'error' for a clear solver error."""
    try:
        hist, contact = throw(**kw)
    except (NewtonError, ValueError) as err:
        assert str(err), "errors must say what went wrong"
        return "error"
    total = hist.kinetic + hist.strain + hist.contact
    for name, a in dict(u=hist.u, v=hist.v, a=hist.a, energy=total, D=hist.dissipation).items():
        assert np.all(np.isfinite(a)), f"{name} is not finite"
    state = hist.records[-1].contacts[0]  # the converged end state
    rep = state.report()
    if contact.friction is not None:
        Y = contact.friction.slip_bound(-rep["t_N"], state.q)[0]
        assert np.all(np.abs(rep["t_T"]) <= Y * (1 + 1e-9) + 1e-12), "slip bound violated"
    if energy_check:
        E0, D = total[0], hist.dissipation[-1]
        assert np.max(total) <= E0 * (1 + 1e-6), f"energy grew: E0 = {E0:.4g}, max E = {np.max(total):.4g}"
        assert D <= 1.05 * (E0 - total[-1]) + 1e-9 * E0, (
            f"recorded dissipation {D:.4g} exceeds the energy lost {E0 - total[-1]:.4g} by more than 5 %"
        )
    assert np.all(hist.dissipation >= -1e-14)
    return "ok"


def resolved(c_N, dt):
    return np.sqrt(c_N * W / M_NODE) * dt <= 2.0


def test_penalty_over_14_decades():
    results = {}
    for c in 10.0 ** np.arange(-3, 11):
        results[c] = outcome(normal=PowerLaw(c), friction=Coulomb(c, 0.3), energy_check=resolved(c, 0.01))
    assert all(r in ("ok", "error") for r in results.values())
    assert results[1e3] == "ok" and results[1e-3] == "ok" and results[1e10] == "ok"


@pytest.mark.parametrize("m", [1.0, 1.5, 2.0, 2.5, 3.0, 3.3])
def test_power_law_exponent(m):
    assert outcome(normal=PowerLaw(1e3, m), friction=Coulomb(1e3, 0.3)) == "ok"


@pytest.mark.parametrize("n", [1e-3, 0.1, 0.5, 0.8, 1.0])
def test_parabolic_slip_first_touch_while_sliding(n):
    # first touch with a tangential speed: dY/dp = alpha n p^(n-1) is unbounded at p -> 0
    assert outcome(friction=ParabolicSlip(1e3, 0.2, 0.3, n), v=(2.0, -1.0)) == "ok"


def test_return_map_at_vanishing_pressure():
    law = ParabolicSlip(1e3, 0.2, 0.3, 0.01)
    p = np.array([1e-300, 1e-200, 1e-30, 1e-8, 0.0])
    fr = return_map(law, -p, np.full(5, 1e3), np.full(5, 1.0), np.zeros(5), np.zeros(5))
    assert np.all(np.isfinite(fr.t_T)) and np.all(np.isfinite(fr.c_N_s))
    assert fr.t_T[-1] == 0.0


@pytest.mark.parametrize("mu", [0.0, 0.1, 0.5, 1.0, 2.0])
def test_friction_coefficient(mu):
    assert outcome(friction=Coulomb(1e3, mu), v=(2.0, -1.0)) == "ok"


@pytest.mark.parametrize("dt", [1e-4, 1e-3, 1e-2, 1e-1, 1.0])
def test_time_step_over_four_decades(dt):
    assert outcome(friction=Coulomb(1e3, 0.3), dt=dt, energy_check=resolved(1e3, dt)) == "ok"


def test_grazing():
    # sliding along the plane exactly at zero gap, and with a vanishing approach speed
    assert outcome(friction=Coulomb(1e3, 0.3), v=(1.0, 0.0)) == "ok"
    assert outcome(friction=Coulomb(1e3, 0.3), v=(1.0, -1e-12)) == "ok"
    # passing over the crest of a rigid cylinder with a 0.5 % interference
    arc = RigidArc((0.5, -5.0 + 0.005), 5.0)
    assert (
        outcome(friction=Coulomb(1e3, 0.3), master=arc, origin=(-3.0, 0.0), v=(3.0, 0.0), dt=0.05, n_steps=40) == "ok"
    )


@pytest.mark.parametrize(
    "points, origin",
    [
        ([[-3.0, 0.0], [1.5, 0.0]], (0.0, 0.0)),  # sliding off the end
        ([[-3.0, 1.5], [1.5, 0.0], [4.0, 1.0]], (-2.5, 1.2)),  # into a valley (concave corner)
        ([[-3.0, 0.0], [1.0, 0.5], [4.0, 0.0]], (-2.5, 0.1)),  # over a ridge (convex corner)
    ],
)
def test_segment_ends_and_corners(points, origin):
    assert (
        outcome(
            friction=Coulomb(1e3, 0.3), master=RigidPolyline(points), origin=origin, v=(3.0, -0.5), dt=0.02, n_steps=40
        )
        == "ok"
    )


def _on_base(origin, v, n_steps=40, dt=0.02, energy_check=True):
    """The quad thrown along the top of a second, supported quad (a deformable master)."""
    base = quad((0.0, -1.0), name="base")
    bottom = np.flatnonzero(base.X[:, 1] < -0.5)
    top = np.flatnonzero(base.X[:, 1] > -0.5)
    top = top[np.argsort(base.X[top, 0])]  # left to right: n = e3 x t = +y
    return outcome(
        friction=Coulomb(1e3, 0.3),
        master=BodySurface(base, top),
        origin=origin,
        v=v,
        extra_bodies=(base,),
        fixed=(Dirichlet(base, base.xdofs[bottom].ravel(), 0.0),),
        n_steps=n_steps,
        dt=dt,
        energy_check=energy_check,
    )


def test_sliding_off_a_deformable_master():
    # both slaves start on the base's top and slide off its right end
    assert _on_base(origin=(0.0, 0.0), v=(2.0, -0.2)) == "ok"


def test_entering_a_master_from_beyond_its_end():
    # the quad's left slave starts beyond the base's left end and sinks while outside it;
    # it is caught penetrated when it enters the master's range (the base's corner went into
    # the quad's side unseen: one pass detects slave nodes only): finite, no error ...
    assert _on_base(origin=(-0.5, 0.0), v=(2.0, -0.2), energy_check=False) == "ok"


@pytest.mark.xfail(
    strict=True,
    reason="known limitation of one-pass node-to-segment: a slave entering "
    "a master from beyond its end already penetrated gets the full penalty force at once "
    "and the energy jumps (ours: +0.2 at dt = 0.02, +0.4 at dt = 0.005, E0 = 2.02)",
)
def test_entering_a_master_from_beyond_its_end_conserves_energy():
    assert _on_base(origin=(-0.5, 0.0), v=(2.0, -0.2)) == "ok"


@pytest.mark.parametrize("speed", [1e1, 1e2, 1e3, 1e6])
@pytest.mark.parametrize("material", ["linear", "neohooke"])
def test_very_high_impact_speed(speed, material):
    # neo-Hooke at 1e6 inverts elements: a clear NewtonError after the cutbacks
    r = outcome(
        friction=Coulomb(1e3, 0.3), v=(speed, -speed), material=material, n_steps=10, energy_check=resolved(1e3, 0.01)
    )
    assert r in ("ok", "error")
    if speed <= 1e3:
        assert r == "ok"


@pytest.mark.xfail(
    strict=True,
    reason="known limitation: implicit Newmark with an unresolved penalty "
    "(omega_p dt >> 1) pumps energy into an impact; the trapezoidal rule carries the "
    "contact acceleration spike into the next step (1 dof: v -> 3 v0 after one bounce); "
    "the energy-consistent stepper conserves it (test_conserving.py)",
)
def test_unresolved_penalty_gains_energy():
    hist, _ = throw(normal=PowerLaw(1e8), delta=0.5, beta=0.25)  # omega_p dt = 141
    total = hist.kinetic + hist.strain + hist.contact
    assert np.max(total) <= total[0] * 1.01  # ours: about 4 x E0


def test_bad_law_parameters_raise():
    for make in (
        lambda: PowerLaw(0.0),
        lambda: PowerLaw(1.0, 0.5),
        lambda: Coulomb(1.0, -0.1),
        lambda: ParabolicSlip(1.0, 0.2, 0.3, 0.0),
        lambda: ParabolicSlip(1.0, 0.2, 0.3, 1.5),
    ):
        with pytest.raises(ValueError):
            make()
