"""The closing step: a node that touches during a step starts its stick spring where it
touched (the gap interpolated linearly within the step), not with the tangential travel
it made while still open; its tangent (r depends on the gap) against finite differences."""

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error
from test_contact_tangent import check_tangent

from contactfem.contact import BodySurface, NodeToSegment, RigidLine, SLIP, STICK
from contactfem.laws import Coulomb, PowerLaw


def closing_node(dx=0.02, g0=0.01, g1=-0.01, mu=10.0):
    body = PointCloud([[0.0, 0.0]], "slave")
    iface = NodeToSegment(body, [0], RigidLine(), normal=PowerLaw(100.0), friction=Coulomb(50.0, mu))
    u0 = np.array([0.0, g0])
    h = iface.start(u0)
    h = iface.commit(iface.evaluate(u0, history=h))  # open at the start of the step: g_bar = g0 > 0
    return iface, np.array([dx, g1]), h


def test_stick_spring_starts_where_the_node_touched():
    iface, u1, h = closing_node()
    e = iface.evaluate(u1, history=h)
    # the gap goes 0.01 -> -0.01: touch at mid-step, after 0.01 of the 0.02 travel
    assert e.slip[0] == STICK
    assert e.t_T[0] == pytest.approx(50.0 * 0.01, rel=1e-12)


def test_without_the_closing_step_the_whole_travel_loads_the_spring():
    """The switch the cork's exit-time study uses: the rule before the closing step."""
    iface, u1, h = closing_node()
    without = iface.with_closing_step(False)
    e = without.evaluate(u1, history=h)
    assert e.slip[0] == STICK
    assert e.t_T[0] == pytest.approx(50.0 * 0.02, rel=1e-12)
    assert iface.closing_step is True  # the contact it was made from is untouched
    assert iface.evaluate(u1, history=h).t_T[0] == pytest.approx(50.0 * 0.01, rel=1e-12)
    with pytest.raises(ValueError, match="closing_step"):
        NodeToSegment(iface.slave, [0], RigidLine(), normal=PowerLaw(100.0), closing_step=0)


def test_node_in_contact_at_both_ends_keeps_the_whole_travel():
    iface, u1, h = closing_node(g0=-0.005)
    assert iface.evaluate(u1, history=h).t_T[0] == pytest.approx(50.0 * 0.02, rel=1e-12)


@pytest.mark.parametrize("mu", [10.0, 0.01], ids=["stick", "slip"])
def test_closing_tangent_rigid_master(mu):
    iface, u1, h = closing_node(mu=mu)
    assert iface.evaluate(u1, history=h).slip[0] == (STICK if mu > 1 else SLIP)
    check_tangent(iface, u1, h)


@pytest.mark.parametrize("mu", [10.0, 0.01], ids=["stick", "slip"])
def test_closing_tangent_deformable_master(rng, mu):
    mb = PointCloud(np.stack([np.linspace(-0.5, 1.5, 3), np.zeros(3)], axis=1), "master")
    sb = PointCloud([[0.3, 0.02], [0.7, 0.03]], "slave", dof_offset=mb.ndof)
    iface = NodeToSegment(sb, [0, 1], BodySurface(mb, [0, 1, 2]), normal=PowerLaw(100.0), friction=Coulomb(50.0, mu))
    u0 = np.zeros(mb.ndof + sb.ndof)
    h = iface.start(u0)
    h = iface.commit(iface.evaluate(u0, history=h))
    u1 = u0.copy()
    u1[: mb.ndof] = 0.003 * rng.standard_normal(mb.ndof)
    u1[mb.ndof :] = [0.03, -0.04, -0.02, -0.05]
    e = iface.evaluate(u1, history=h)
    assert np.all(e.active) and np.all(e.r < 1.0)
    check_tangent(iface, u1, h)


@pytest.mark.parametrize("phase", ["normal", "friction"])
def test_closing_tangent_staggered_phases(phase):
    """The two phases of the staggered algorithm at a closing node: the normal phase's stick
    about the frozen state varies with s alone, the friction phase's slip with r (s - s_bar)."""
    from contactfem.contact.tangents import freeze

    iface, u1, h = closing_node(mu=0.3)
    frozen = freeze(iface.evaluate(u1, history=h), phase)
    R, rows, cols, vals = iface.evaluate(u1, phase=frozen, history=h).scatter(2)
    K = np.zeros((2, 2))
    np.add.at(K, (rows, cols), vals)
    Kfd = fd_jacobian(lambda v: iface.evaluate(v, phase=frozen, history=h).scatter(2)[0], u1)
    assert np.linalg.norm(K) > 0 and rel_error(K, Kfd) < 1e-6
