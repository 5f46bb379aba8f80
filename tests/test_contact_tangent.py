"""Every contact residual has its tangent checked against a finite-difference Jacobian:
open, stick, slip both ways; rigid line, polyline, arc and deformable master; node
switching segments; every shipped law; m != 1, n < 1."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error

from contactfem.contact import BodySurface, NodeToSegment, RigidArc, RigidLine, RigidPolyline, SLIP, STICK, OPEN
from contactfem.laws import (
    ArchardWear,
    Coulomb,
    DieterichRuina,
    ExponentialLaw,
    ParabolicSlip,
    PowerLaw,
    SlipHardening,
    Stribeck,
)

NORMALS = {
    "penalty": PowerLaw(c_N=50.0, m=1.0),
    "power2.5": PowerLaw(c_N=80.0, m=2.5),
    "exp": ExponentialLaw(a=20.0, b=8.0),
}
FRICTIONS = {
    "none": None,
    "coulomb": Coulomb(c_T=30.0, mu=0.3),
    "parabolic": ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5),
    "parabolic08": ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.8),
    "hardening": SlipHardening(c_T=30.0, mu=0.2, h=0.5),
    "softening": SlipHardening(c_T=30.0, mu=0.4, h=-0.3),
    # laws with a slip rate and internal variables (time step DT, states advanced in set_history)
    "stribeck": Stribeck(c_T=30.0, mu_s=0.5, mu_d=0.3, v_s=0.5, mu_v=0.05),
    "rate_state": DieterichRuina(c_T=30.0, mu_0=0.3, a=0.02, b=0.03, d_c=0.05),
    "wear": ArchardWear(c_T=30.0, mu=0.3, k_w=0.2),
}
DT = 0.1


def check_tangent(iface, u, h, tol=1e-6, dt=DT):
    R0, rows, cols, vals = iface.assemble(u, dt=dt, history=h)
    n = len(u)
    K = np.zeros((n, n))
    np.add.at(K, (rows, cols), vals)
    Kfd = fd_jacobian(lambda v: iface.assemble(v, dt=dt, history=h)[0], u)
    assert np.linalg.norm(K) > 0, "nothing in contact: the test is vacuous"
    err = rel_error(K, Kfd)
    assert err < tol, f"tangent mismatch {err:.2e}"
    return K


def slave_cloud(rng, n=4, y=-0.05):
    X = np.stack([np.linspace(0.15, 0.85, n), np.full(n, 0.0)], axis=1)
    body = PointCloud(X, "slave")
    u = np.zeros(body.ndof)
    u[1::2] = y * (0.5 + rng.random(n))  # penetrations of various depth
    u[0::2] = 0.01 * rng.standard_normal(n)
    return body, u


def set_history(iface, u, t_T_bar, dg, master=None):
    """History such that the slip increment is dg: s_bar = s(u) - dg (``master``: the
    master's remembered reference, e.g. a deformable master's earlier positions)."""
    h = iface.start(u)
    if master is not None:
        h = replace(h, master=master)
        h = replace(h, s_bar=iface.evaluate(u, dt=DT, history=h).s)
    n = len(iface.nodes)
    z = h.z_bar
    if iface.friction is not None and iface._law.n_state:  # a state reached by earlier slip (wear: 0.01 deep)
        z = iface._law.evolve(h.z_bar, np.ones(n), np.full(n, 0.05), DT)[0]
    return replace(h, s_bar=h.s_bar - dg, t_T_bar=np.full(n, t_T_bar), z_bar=z)


MASTERS = ["line", "tilted_polyline", "arc_outside", "arc_inside"]


def make_master(kind):
    if kind == "line":
        return RigidLine(point=(0.0, 0.0), normal=(0.0, 1.0))
    if kind == "tilted_polyline":
        return RigidPolyline([[-1.0, 0.05], [0.3, -0.02], [0.6, 0.01], [2.0, -0.03]])
    if kind == "arc_outside":
        return RigidArc(center=(0.5, -5.0), R=5.0)
    if kind == "arc_inside":
        return RigidArc(center=(0.5, 5.0), R=5.0, inside=True)


@pytest.mark.parametrize("master", MASTERS)
@pytest.mark.parametrize("nlaw", list(NORMALS))
@pytest.mark.parametrize("flaw", list(FRICTIONS))
@pytest.mark.parametrize("regime", ["stick", "slip+", "slip-"])
def test_rigid_master_tangent(rng, master, nlaw, flaw, regime):
    body, u = slave_cloud(rng)
    iface = NodeToSegment(
        body,
        np.arange(4),
        make_master(master),
        normal=NORMALS[nlaw],
        friction=FRICTIONS[flaw],
        weights=rng.uniform(0.5, 1.5, 4),
    )
    dg = {"stick": 1e-6, "slip+": 0.5, "slip-": -0.5}[regime]
    h = set_history(iface, u, t_T_bar=0.0, dg=dg)
    e = iface.evaluate(u, dt=DT, history=h)
    assert np.all(e.active)
    if FRICTIONS[flaw] is not None:
        expected = STICK if regime == "stick" else SLIP
        assert np.all(e.slip == expected)
        if regime != "stick":
            assert np.all(np.sign(e.t_T) == np.sign(dg))
    check_tangent(iface, u, h)


@pytest.mark.parametrize("flaw", list(FRICTIONS))
@pytest.mark.parametrize("regime", ["stick", "slip+", "slip-"])
@pytest.mark.parametrize("nlaw", ["penalty", "power2.5"])
def test_deformable_master_tangent(rng, flaw, regime, nlaw):
    Xm = np.stack([np.linspace(-0.2, 1.2, 5), np.zeros(5)], axis=1)
    master_body = PointCloud(Xm, "master", dof_offset=0)
    Xs = np.stack([np.linspace(0.1, 0.9, 3), np.full(3, 0.0)], axis=1)
    slave_body = PointCloud(Xs, "slave", dof_offset=master_body.ndof)
    u = np.zeros(master_body.ndof + slave_body.ndof)
    u[: master_body.ndof] = 0.02 * rng.standard_normal(master_body.ndof)
    u[master_body.ndof + 1 :: 2] = -0.06 - 0.02 * rng.random(3)
    # move the master a little first so that l_bar differs from l
    surface = BodySurface(master_body, np.arange(5))
    iface = NodeToSegment(
        slave_body, np.arange(3), surface, normal=NORMALS[nlaw], friction=FRICTIONS[flaw], weights=0.7
    )
    u_old = u.copy()
    u_old[: master_body.ndof] *= 0.3
    dg = {"stick": 1e-6, "slip+": 0.5, "slip-": -0.5}[regime]
    h = set_history(iface, u, t_T_bar=0.01, dg=dg, master=surface.reference(u_old))
    e = iface.evaluate(u, dt=DT, history=h)
    assert np.all(e.active)
    K = check_tangent(iface, u, h)
    if FRICTIONS[flaw] is not None and regime != "stick":
        assert not np.allclose(K, K.T), "the slip tangent is non-symmetric (eq 50)"


def test_open_node_has_no_force_nor_tangent(rng):
    body, u = slave_cloud(rng, y=+0.05)
    iface = NodeToSegment(body, np.arange(4), RigidLine(), normal=NORMALS["penalty"], friction=FRICTIONS["coulomb"])
    h = iface.start(u)
    R, rows, cols, vals = iface.assemble(u, history=h)
    assert np.all(R == 0) and len(vals) == 0
    assert np.all(iface.evaluate(u, history=h).slip == OPEN)


def test_node_switches_segment_and_keeps_history(rng):
    """A slave sliding along a polyline onto the next segment: the slip increment is
    the arc length travelled, and t_T_bar carries over."""
    P = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.1]]
    master = RigidPolyline(P)
    body = PointCloud([[0.9, 0.0]], "slave")
    iface = NodeToSegment(body, [0], master, normal=NORMALS["penalty"], friction=Coulomb(c_T=100.0, mu=10.0))
    u = np.array([0.0, -0.01])
    h = iface.start(u)
    h = iface.commit(iface.evaluate(u, history=h))
    e0 = iface.evaluate(u, history=h)
    assert e0.seg[0] == 0
    u1 = np.array([0.2, -0.01 + 0.1 * 0.1])  # now above segment 1
    e1 = iface.evaluate(u1, history=h)
    assert e1.seg[0] == 1
    L1 = np.hypot(1.0, 0.1)
    alpha = ((np.array([1.1, e1.x_s[0, 1]]) - [1.0, 0.0]) @ np.array([1.0, 0.1]) / L1) / L1
    assert np.isclose(e1.dg_T[0], 0.1 + alpha * L1)
    check_tangent(iface, u1, h)


def test_deformable_master_node_switch_tangent(rng):
    Xm = np.stack([np.linspace(0.0, 2.0, 3), np.zeros(3)], axis=1)
    mb = PointCloud(Xm, "master")
    sb = PointCloud([[0.95, 0.0]], "slave", dof_offset=mb.ndof)
    surf = BodySurface(mb, [0, 1, 2])
    iface = NodeToSegment(
        sb, [0], surf, normal=NORMALS["penalty"], friction=ParabolicSlip(c_T=40.0, alpha=0.2, beta=0.3, n=0.5)
    )
    u = np.zeros(mb.ndof + 2)
    u[-1] = -0.03
    h = iface.start(u)
    h = iface.commit(iface.evaluate(u, history=h))
    u2 = u.copy()
    u2[-2] = 0.12  # slides past the middle master node
    u2[: mb.ndof] = 0.01 * rng.standard_normal(mb.ndof)
    e = iface.evaluate(u2, history=h)
    assert e.seg[0] == 1 and e.slip[0] == SLIP
    check_tangent(iface, u2, h)


def test_offset_surface_contacts_earlier():
    body = PointCloud([[0.0, 0.4]], "beam")
    iface = NodeToSegment(body, [0], RigidLine(), normal=NORMALS["penalty"], offset=0.5)
    h = iface.start(np.zeros(2))
    e = iface.evaluate(np.zeros(2), history=h)
    assert e.active[0] and np.isclose(e.g_N[0], -0.1)
