"""2D mortar contact (contact/mortar.py, segmentation.py, mortar_contact.py).

Tangents: the assembled tangent against central differences of the residual, relative
error < 1e-6, for stick, slip both ways and frictionless, on a rigid line, a rigid
polyline and a deformable master, with a slave segment spanning two master segments and
with a slave segment partly beyond the end of the master. Invariants: the segmentation's
projections against node-to-segment's (eqs 17-19, 27), the quadrature against an
independent one, partition of unity of D and M, the weighted gap of a uniform gap, the
contact patch test at the kernel level (uniform tractions give the consistent nodal
loads on both meshes, at any gap), linear momentum, frame indifference of the slip.
"""

import dataclasses

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error

from contactfem.contact import BodySurface, RigidArc, RigidLine, RigidPolyline, segment_variations
from contactfem.contact.mortar import (
    NormalLawError,
    Pairs,
    contact_forces,
    mortar_integrals,
    mortar_matrices,
    nodal_gap,
    weighted_slip,
)
from contactfem.contact.mortar_contact import MortarContact
from contactfem.contact.segmentation import candidate_pairs, pair_geometry
from contactfem.laws import OPEN, SLIP, STICK, ArchardWear, Coulomb, ParabolicSlip, PowerLaw

# Central differences with h = 1e-6 on coordinates of size 1 and gaps of size 0.05: the
# truncation error (h^2 times third derivatives of size 1-100) and the round-off
# (1e-16 |R| / h) are both below 1e-8 relative, two decades under the tolerance; no
# kink (stick/slip switch, overlap end crossing a node, contact opening) lies within h.
H = 1e-6
TOL = 1e-6
DT = 0.1

# slave: four nodes right to left (outward normal -y); master: left to right (normal +y).
# The slave segment 0.62 -> 0.35 spans the master node at 0.45 (two master segments).
X_SLAVE = np.array([(0.9, 0.0), (0.62, 0.01), (0.35, -0.005), (0.1, 0.0)])
X_MASTER = np.array([(-0.2, -0.02), (0.2, 0.01), (0.45, -0.01), (0.7, 0.0), (1.2, -0.015)])
# a master ending at x = 0.75: the slave segment 0.9 -> 0.62 lies partly beyond it
X_MASTER_SHORT = np.array([(-0.2, -0.02), (0.2, 0.01), (0.45, -0.01), (0.75, 0.0)])


def make_contact(master_kind, normal=PowerLaw(c_N=50.0), friction=None, short=False, kinematics="finite"):
    slave = PointCloud(X_SLAVE, "slave")
    Xm = X_MASTER_SHORT if short else X_MASTER
    if master_kind == "deformable":
        body = PointCloud(Xm, "master", dof_offset=slave.ndof)
        master, ndof = BodySurface(body, np.arange(len(Xm))), slave.ndof + body.ndof
    elif master_kind == "polyline":
        master, ndof = RigidPolyline(Xm), slave.ndof
    else:
        master, ndof = RigidLine(point=(0.3, -0.01), normal=(0.05, 1.0)), slave.ndof
    return MortarContact(
        slave, np.arange(len(X_SLAVE)), master, normal=normal, friction=friction, kinematics=kinematics
    ), ndof


def pressed(ndof, rng, depth=0.05):
    """The slave pushed into the master by about `depth`, everything slightly perturbed."""
    u = 0.005 * rng.standard_normal(ndof)
    u[1:8:2] -= depth
    return u


def tangent(contact, u, h, dt=DT):
    st = contact.evaluate(u, 0.0, dt, history=h)
    K = np.zeros((len(u), len(u)))
    np.add.at(K, (st.rows, st.cols), st.vals)
    return st, K


def check_tangent(contact, u, h, dt=DT):
    st, K = tangent(contact, u, h, dt)
    Kfd = fd_jacobian(lambda v: contact.evaluate(v, 0.0, dt, history=h).R, u, h=H)
    assert np.linalg.norm(K) > 0, "nothing in contact: the test is vacuous"
    err = rel_error(K, Kfd)
    print(f"tangent relative error {err:.1e}")
    assert err < TOL, f"tangent mismatch {err:.2e}"
    return st


MOTION = {"stick": 0.001, "slip+": 0.05, "slip-": -0.05}


MASTERS = [("line", False), ("polyline", False), ("polyline", True), ("deformable", False), ("deformable", True)]


@pytest.mark.parametrize("master_kind, short", MASTERS, ids=[k + ("-end" if e else "") for k, e in MASTERS])
@pytest.mark.parametrize("regime", ["frictionless", "stick", "slip+", "slip-"])
def test_tangent_matches_finite_differences(rng, master_kind, regime, short):
    friction = None if regime == "frictionless" else Coulomb(c_T=30.0, mu=0.3)
    contact, ndof = make_contact(master_kind, friction=friction, short=short)
    u = pressed(ndof, rng)
    h = contact.start(u)
    u[0:8:2] += 0.002  # a converged sticking step: t_T_bar != 0
    h = contact.commit(contact.evaluate(u, 0.0, DT, history=h))
    u[0:8:2] += MOTION.get(regime, 0.02)  # slide the slave along x
    st = check_tangent(contact, u, h)
    closed = st.g_N < 0
    assert closed.sum() >= 3
    if regime != "frictionless":
        assert np.all(st.state[closed] == (STICK if regime == "stick" else SLIP)), st.state
    if master_kind != "line":  # (a line is one master segment)
        assert np.any(np.bincount(st.integrals.pairs.slave) >= 2), "no slave segment spans two master segments"
    if short:  # the first slave segment lies partly beyond the master end
        half_segment = 0.5 * np.linalg.norm(X_SLAVE[1] - X_SLAVE[0])
        assert 0.0 < st.weights[0] < 0.6 * half_segment


@pytest.mark.parametrize(
    "normal, friction",
    [
        (PowerLaw(c_N=80.0, m=2.5), ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5)),
        (PowerLaw(c_N=50.0), ArchardWear(c_T=30.0, mu=0.3, k_w=0.2)),  # internal variables, worn surface
    ],
    ids=["power2.5-parabolic", "wear"],
)
def test_tangent_other_laws(rng, normal, friction):
    contact, ndof = make_contact("deformable", normal=normal, friction=friction)
    u_bar = pressed(ndof, rng)
    h = contact.start(u_bar)
    u = u_bar.copy()
    u[0:8:2] += 0.05
    h = contact.commit(contact.evaluate(u, 0.0, DT, history=h))  # one slipping step: wear, t_T_bar, q_bar
    u[0:8:2] += 0.03
    st = check_tangent(contact, u, h)
    assert np.any(st.state == SLIP)


def test_segmentation_is_node_to_segment_projection(rng):
    """xi_c, g_c (xi_d, g_d) of a master end projected onto a slave segment, and their
    gradients, equal node-to-segment's alpha and g_N (eqs 17, 19, 27) with the master end
    as the point."""
    xa, xb, xc, xd = (rng.standard_normal((6, 2)) for _ in range(4))
    geo = pair_geometry(xa, xb, xc, xd)
    for end, x, point_dofs in (("c", xc, [4, 5]), ("d", xd, [6, 7])):
        ref = segment_variations(x, xa, xb)  # its dofs: (point, x_a, x_b)
        order = point_dofs + [0, 1, 2, 3]
        g, xi = geo["g_" + end], geo["xi_" + end]
        assert np.allclose(g.val, ref["g_N"], rtol=1e-13, atol=1e-14)
        assert np.allclose(xi.val, ref["alpha"], rtol=1e-13, atol=1e-14)
        assert np.allclose(g.grad[:, order], ref["dg_N"], rtol=1e-12, atol=1e-13)
        assert np.allclose(xi.grad[:, order], ref["dalpha"], rtol=1e-12, atol=1e-13)
        other = [6, 7] if end == "c" else [4, 5]
        assert np.all(g.grad[:, other] == 0.0) and np.all(xi.grad[:, other] == 0.0)


def integrate_reference(xs, xm, s, m, n_gauss=12):
    """D, M, g~ of one pair by a 12-point Gauss rule, computed independently of the kernel:
    the overlap by intersecting the rays along the slave normal with the master line."""
    xa, xb, xc, xd = xs[s], xs[s + 1], xm[m], xm[m + 1]
    l = np.linalg.norm(xb - xa)
    t = (xb - xa) / l
    n = np.array([-t[1], t[0]])
    tm = xd - xc

    def hit(xi):  # x_a + xi (x_b - x_a) + g n on c + eta tm
        A = np.column_stack([n, -tm])
        g, eta = np.linalg.solve(A, xc - (xa + xi * (xb - xa)))
        return g, eta

    ends = sorted([np.dot(xc - xa, t) / l, np.dot(xd - xa, t) / l])
    lo, hi = max(0.0, ends[0]), min(1.0, ends[1])
    z, wz = np.polynomial.legendre.leggauss(n_gauss)
    D, M, g = np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2)
    for zq, wq in zip(z, wz):
        xi = lo + (hi - lo) * (zq + 1) / 2
        dG = l * (hi - lo) / 2 * wq
        gq, eta = hit(xi)
        Ns, Nm = np.array([1 - xi, xi]), np.array([1 - eta, eta])
        D += np.outer(Ns, Ns) * dG
        M += np.outer(Ns, Nm) * dG
        g += Ns * gq * dG
    return D, M, g


def test_two_gauss_points_are_exact(rng):
    xs = X_SLAVE + 0.01 * rng.standard_normal(X_SLAVE.shape) - [0, 0.03]
    xm = X_MASTER + 0.01 * rng.standard_normal(X_MASTER.shape)
    s, m = candidate_pairs(xs, xm)
    mi = mortar_integrals(xs, xm, Pairs.of(s, m, len(xs)))
    assert len(s) >= 5
    for p in range(len(s)):
        D, M, g = integrate_reference(xs, xm, s[p], m[p])
        assert np.allclose(mi.D[p], D, rtol=1e-13, atol=1e-15)
        assert np.allclose(mi.M[p], M, rtol=1e-13, atol=1e-15)
    # the nodal weighted gap, summed over the pairs of each node
    g_ref = np.zeros(len(xs))
    for p in range(len(s)):
        g_ref[[s[p], s[p] + 1]] += integrate_reference(xs, xm, s[p], m[p])[2]
    assert np.allclose(mi.g, g_ref, rtol=1e-13, atol=1e-15)


def flat_chains(g0=0.0, angle=0.2):
    """Non-matching straight chains on a line tilted by `angle`, the slave at distance g0
    (along the normal) from the master and covering an inner part of it."""
    R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    s_x = np.array([0.95, 0.71, 0.5, 0.33, 0.12])  # slave, right to left
    m_x = np.array([-0.1, 0.2, 0.45, 0.6, 0.83, 1.1])  # master, left to right
    xs = np.column_stack([s_x, np.full_like(s_x, g0)]) @ R.T
    xm = np.column_stack([m_x, np.zeros_like(m_x)]) @ R.T
    return xs, xm, s_x, m_x


def hat_integrals(nodes_x, a, b):
    """int_a^b N_k(x) dx of the hat functions on the (sorted) 1D mesh nodes_x: the
    consistent nodal load of a unit traction on [a, b]."""
    order = np.argsort(nodes_x)
    x = nodes_x[order]
    f = np.zeros(len(x))
    for i in range(len(x) - 1):
        lo, hi = max(a, x[i]), min(b, x[i + 1])
        if hi > lo:
            L = x[i + 1] - x[i]
            f[i] += ((x[i + 1] - lo) ** 2 - (x[i + 1] - hi) ** 2) / (2 * L)
            f[i + 1] += ((hi - x[i]) ** 2 - (lo - x[i]) ** 2) / (2 * L)
    out = np.empty_like(f)
    out[order] = f
    return out


def flat_integrals(g0=0.0):
    xs, xm, s_x, m_x = flat_chains(g0)
    s, m = candidate_pairs(xs, xm)
    return mortar_integrals(xs, xm, Pairs.of(s, m, len(xs))), xs, xm, s_x, m_x


def test_partition_of_unity():
    mi, xs, xm, s_x, m_x = flat_integrals()
    D, M = mortar_matrices(mi, len(xm))
    D, M = D.toarray(), M.toarray()
    tributary = hat_integrals(s_x, s_x.min(), s_x.max())
    assert np.allclose(D.sum(axis=1), tributary, rtol=1e-14)  # rows: int N_j
    assert np.allclose(M.sum(axis=1), D.sum(axis=1), rtol=1e-14)  # sum_l N_l = 1 on a covered slave
    assert np.allclose(mi.w, tributary, rtol=1e-14)
    assert np.isclose(mi.w.sum(), s_x.max() - s_x.min(), rtol=1e-14)  # the slave's length
    assert np.allclose(M.sum(axis=0), hat_integrals(m_x, s_x.min(), s_x.max()), rtol=1e-13, atol=1e-15)
    assert np.allclose(D, D.T) and np.all(np.linalg.eigvalsh(D) > 0)


@pytest.mark.parametrize("g0", [0.03, -0.02])
def test_weighted_gap_of_a_uniform_gap(g0):
    mi, *_ = flat_integrals(g0)
    assert np.allclose(mi.g, g0 * mi.w, rtol=1e-13, atol=1e-16)
    g_N, covered, _ = nodal_gap(mi)
    assert covered.all() and np.allclose(g_N, g0, rtol=1e-12)
    # also for partly covered nodes: the slave beyond the end of the master
    xs, xm, _, _ = flat_chains(g0)
    xm = xm[:-2]  # master ends at x = 0.6, inside a slave segment
    s, m = candidate_pairs(xs, xm)
    mi = mortar_integrals(xs, xm, Pairs.of(s, m, len(xs)))
    g_N, covered, _ = nodal_gap(mi)
    assert not covered.all() and 0 < mi.w[1] < 0.12  # node 0.71 covered only on [0.6, 0.71]
    assert np.allclose(g_N[covered], g0, rtol=1e-12)


@pytest.mark.parametrize("g0", [0.0, 0.03, -0.02])
def test_patch_test_consistent_nodal_loads(g0):
    """A uniform pressure p and a uniform tangential traction tau on two flat non-matching
    chains (at any uniform gap g0) give the consistent nodal loads of those tractions on
    both meshes: int N_k p ds along the normal, int N_k tau ds along the tangent
    (node-to-segment gives the slave's tributary forces to the master through the
    projections instead, which is not the master's consistent load)."""
    mi, xs, xm, s_x, m_x = flat_integrals(g0)
    ns, nm = len(xs), len(xm)
    p, tau = 3.0, 0.7
    t_N, t_T = np.full(ns, -p), np.full(ns, tau)
    slip = weighted_slip(xs, xm, mi.pairs, mi.D, mi.M)
    fr = dataclasses.make_dataclass("F", ["t_T", "c_T_s", "c_N_s"])(t_T, np.zeros(ns), np.zeros(ns))
    R, _ = contact_forces(mi, t_N, np.zeros(ns), slip=slip, friction=fr, w_bar=mi.w)
    R = R.reshape(-1, 2)
    t_s = (xs[1] - xs[0]) / np.linalg.norm(xs[1] - xs[0])  # slave tangent (right to left)
    n_s = np.array([-t_s[1], t_s[0]])  # slave normal, towards the master
    f_slave = hat_integrals(s_x, s_x.min(), s_x.max())
    f_master = hat_integrals(m_x, s_x.min(), s_x.max())
    # R = dPi/du: the contact force on a body is -R
    assert np.allclose(-R[:ns], -p * n_s * f_slave[:, None] - tau * t_s * f_slave[:, None], rtol=1e-13, atol=1e-14)
    assert np.allclose(-R[ns:], p * n_s * f_master[:, None] + tau * t_s * f_master[:, None], rtol=1e-13, atol=1e-14)


def test_linear_momentum_and_gap_gradient(rng):
    """The contact forces on slave and master sum to zero in any configuration; for
    touching parallel chains the virtual-work vectors are the weighted gap's gradient."""
    contact, ndof = make_contact("deformable", friction=Coulomb(c_T=30.0, mu=0.3))
    u = pressed(ndof, rng)
    h = contact.start(u - 0.01)
    st = contact.evaluate(u, 0.0, DT, history=h)
    assert abs(st.R[0::2].sum()) < 1e-14 * np.abs(st.R).max() * len(u)
    assert abs(st.R[1::2].sum()) < 1e-14 * np.abs(st.R).max() * len(u)
    mi, xs, xm, _, _ = flat_integrals(0.0)
    F = np.zeros((len(xs), 2 * (len(xs) + len(xm))))
    for i in range(2):
        np.add.at(F, (mi.pairs.nodes[:, i, None], mi.pairs.dofs), mi.f_N[:, i])
    assert np.allclose(F, mi.dg.toarray(), atol=1e-14)


def test_slip_is_frame_indifferent_and_exact_for_a_rigid_slide(rng):
    contact, ndof = make_contact("deformable", friction=Coulomb(c_T=30.0, mu=0.3))
    u_bar = pressed(ndof, rng)
    h = contact.start(u_bar)
    X = np.vstack([contact.slave.X, contact.master.body.X])
    x = X + u_bar.reshape(-1, 2)
    th = 0.4
    Q = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    st0 = contact.evaluate(u_bar, 0.0, DT, history=h)
    st = contact.evaluate((x @ Q.T + [0.3, -0.2] - X).ravel(), 0.0, DT, history=h)
    assert np.allclose(st.dg_T, 0.0, atol=1e-15)
    assert np.allclose(st.g_N, st0.g_N, rtol=1e-12)
    # a flat slave slid rigidly by delta along its tangent: every covered node slips delta
    xs, xm, _, _ = flat_chains(-0.01)
    slave, master = PointCloud(xs), PointCloud(xm, dof_offset=2 * len(xs))
    contact = MortarContact(
        slave,
        np.arange(len(xs)),
        BodySurface(master, np.arange(len(xm))),
        normal=PowerLaw(c_N=50.0),
        friction=Coulomb(c_T=30.0, mu=0.3),
    )
    u = np.zeros(2 * (len(xs) + len(xm)))
    h = contact.start(u)
    t_s = (xs[1] - xs[0]) / np.linalg.norm(xs[1] - xs[0])
    u[: 2 * len(xs)] = np.tile(0.004 * t_s, len(xs))
    assert np.allclose(contact.evaluate(u, 0.0, DT, history=h).dg_T, 0.004, rtol=1e-12)


def test_evaluate_is_pure_and_commit_takes_the_state(rng):
    contact, ndof = make_contact("polyline", friction=Coulomb(c_T=30.0, mu=0.3))
    u = pressed(ndof, rng)
    h0 = contact.start(u)
    t_T0 = h0.t_T.copy()
    u[0:8:2] += 0.01
    a, b = contact.evaluate(u, 0.0, DT, history=h0), contact.evaluate(u, 0.0, DT, history=h0)
    assert np.array_equal(h0.t_T, t_T0)
    assert np.array_equal(a.R, b.R) and np.array_equal(a.vals, b.vals)
    h = contact.commit(a)
    assert h is a.history and np.any(a.history.t_T != 0)
    c = contact.evaluate(u, 0.0, DT, history=h)  # nothing moved since the commit: no slip
    assert np.allclose(c.dg_T, 0.0, atol=1e-15) and np.allclose(c.t_T, a.t_T)


def test_bad_input():
    slave = PointCloud(X_SLAVE)
    with pytest.raises(ValueError, match="parameter master"):
        MortarContact(slave, np.arange(4), RigidArc((0, 0), 1.0), normal=PowerLaw(1.0))
    with pytest.raises(ValueError, match="parameter slave_nodes"):
        MortarContact(slave, [0], RigidLine(), normal=PowerLaw(1.0))
    with pytest.raises(ValueError, match="parameter search"):
        MortarContact(slave, np.arange(4), RigidLine(), normal=PowerLaw(1.0), search=0.0)
    with pytest.raises(ValueError, match="parameter offset"):
        MortarContact(slave, np.arange(4), RigidLine(), normal=PowerLaw(1.0), offset=[0.1, 0.2])
    contact = MortarContact(slave, np.arange(4), RigidLine((0, 0.1)), normal=PowerLaw(1.0))
    with pytest.raises(ValueError, match="history must be a MortarHistory"):
        contact.evaluate(np.zeros(8), history=None)

    class Sticky:
        def traction(self, g):
            return np.abs(g), np.ones_like(g)

    contact = MortarContact(slave, np.arange(4), RigidLine((0, 0.1)), normal=Sticky())
    h = contact.start(np.zeros(8))
    with pytest.raises(NormalLawError, match="normal law Sticky.traction returned t_N"):
        contact.evaluate(np.zeros(8), history=h)


def test_energy_and_dissipation_of_a_sliding_flat_slave():
    """A flat slave at uniform penetration g0 on a rigid line slides along its tangent:
    stored energy L (c_N g0^2 / 2 + t_T^2 / (2 c_T)); once slipping at t_T = mu p, a further
    slide delta dissipates mu p delta L (L: the slave's length)."""
    c_N, c_T, mu, g0 = 50.0, 30.0, 0.3, -0.02
    xs = np.column_stack([np.linspace(1.0, 0.0, 6) ** 1.3, np.full(6, g0)])  # non-uniform, right to left
    L = xs[0, 0] - xs[-1, 0]
    contact = MortarContact(
        PointCloud(xs), np.arange(6), RigidLine(), normal=PowerLaw(c_N=c_N), friction=Coulomb(c_T=c_T, mu=mu)
    )
    u = np.zeros(12)
    h = contact.start(u)
    u[0::2] -= 0.1  # along the slave tangent (-x): positive slip
    st = contact.evaluate(u, 0.0, DT, history=h)
    p = -c_N * g0
    assert np.all(st.state == SLIP) and np.allclose(st.t_T, mu * p, rtol=1e-13)
    assert st.energy == pytest.approx(L * (0.5 * c_N * g0**2 + (mu * p) ** 2 / (2 * c_T)), rel=1e-13)
    h = contact.commit(st)
    u[0::2] -= 0.03
    st = contact.evaluate(u, 0.0, DT, history=h)
    assert st.dissipation == pytest.approx(mu * p * 0.03 * L, rel=1e-12)


def test_search_distance_leaves_far_pairs_out():
    xs, xm, _, _ = flat_chains(0.5)  # the slave 0.5 above the master
    assert len(candidate_pairs(xs, xm)[0]) > 0
    assert len(candidate_pairs(xs, xm, search=0.6)[0]) > 0
    assert len(candidate_pairs(xs, xm, search=0.4)[0]) == 0
    assert len(candidate_pairs(xs[::-1], xm)[0]) == 0  # reversed slave: its normal faces away


# -- small kinematics (the reference configuration held) --------------------------------


@pytest.mark.parametrize(
    "master_kind, short",
    [("line", False), ("deformable", False), ("deformable", True)],
    ids=["line", "deformable", "deformable-end"],
)
@pytest.mark.parametrize("regime", ["frictionless", "stick", "slip+", "slip-"])
def test_small_kinematics_tangent(rng, master_kind, regime, short):
    friction = None if regime == "frictionless" else Coulomb(c_T=30.0, mu=0.3)
    contact, ndof = make_contact(master_kind, friction=friction, short=short, kinematics="small")
    u = pressed(ndof, rng)
    h = contact.start(u)
    u[0:8:2] += 0.002
    h = contact.commit(contact.evaluate(u, 0.0, DT, history=h))
    u[0:8:2] += MOTION.get(regime, 0.02)
    st = check_tangent(contact, u, h)
    if regime != "frictionless":
        closed = st.g_N < 0
        assert np.all(st.state[closed] == (STICK if regime == "stick" else SLIP)), st.state


def test_small_kinematics_is_affine_and_starts_at_the_reference(rng):
    """Gap and slip are affine in u and equal to the finite ones at u = 0; for chains that
    touch in the reference configuration (the geometry's own variations multiply the gap,
    which vanishes there) they are the finite ones to first order; the weights are the
    reference ones whatever u."""
    hist = {}
    g = lambda c, u: c.kinematics_at(u, hist[id(c)])["mi"].g  # noqa: E731 (weighted gaps)
    gT = lambda c, u: c.kinematics_at(u, hist[id(c)])["slip"].g_T  # noqa: E731
    fin, ndof = make_contact("deformable", friction=Coulomb(c_T=30.0, mu=0.3))
    small, _ = make_contact("deformable", friction=Coulomb(c_T=30.0, mu=0.3), kinematics="small")
    zero = np.zeros(ndof)
    hist[id(fin)], hist[id(small)] = fin.start(zero), small.start(zero)
    a, b = 0.01 * rng.standard_normal(ndof), 0.01 * rng.standard_normal(ndof)
    for f in (g, gT):
        assert np.allclose(f(small, a + b) - f(small, b), f(small, a) - f(small, zero), atol=1e-15)
        assert np.allclose(f(small, zero), f(fin, zero), atol=1e-15)
    assert np.array_equal(small.evaluate(0.2 * a, 0.0, DT, history=hist[id(small)]).weights, hist[id(small)].w)
    xs, xm, _, _ = flat_chains(0.0)
    slave, master = PointCloud(xs), PointCloud(xm, dof_offset=2 * len(xs))
    pair = [
        MortarContact(
            slave,
            np.arange(len(xs)),
            BodySurface(master, np.arange(len(xm))),
            normal=PowerLaw(50.0),
            friction=Coulomb(c_T=30.0, mu=0.3),
            kinematics=k,
        )
        for k in ("finite", "small")
    ]
    n = 2 * (len(xs) + len(xm))
    for c in pair:
        hist[id(c)] = c.start(np.zeros(n))
    d = rng.standard_normal(n)
    for eps in (1e-4, 1e-5):  # the difference is second order in eps
        for f in (g, gT):
            diff = np.abs(f(pair[0], eps * d) - f(pair[1], eps * d)).max()
            assert diff < 10 * eps**2, (eps, diff)


def test_small_kinematics_patch_test_at_any_deformation(rng):
    """Flat non-matching chains: uniform tractions give the consistent nodal loads of the
    REFERENCE meshes, whatever the displacement (the finite form gives those of the
    current ones)."""
    xs, xm, s_x, m_x = flat_chains(0.0, angle=0.0)
    slave, master = PointCloud(xs), PointCloud(xm, dof_offset=2 * len(xs))
    contact = MortarContact(
        slave,
        np.arange(len(xs)),
        BodySurface(master, np.arange(len(xm))),
        normal=PowerLaw(c_N=50.0),
        kinematics="small",
    )
    n = 2 * (len(xs) + len(xm))
    h = contact.start(np.zeros(n))
    u = np.zeros(n)
    u[0::2] = 0.1 * np.concatenate([s_x, m_x])  # a stretch of 10 % along x of both chains
    u[1 : 2 * len(xs) : 2] = -0.01  # a uniform penetration of 0.01
    st = contact.evaluate(u, 0.0, DT, history=h)
    p = 50.0 * 0.01
    assert np.allclose(st.t_N, -p, rtol=1e-13)
    R = st.R.reshape(-1, 2)
    assert np.allclose(R[: len(xs), 1], -p * hat_integrals(s_x, s_x.min(), s_x.max()), rtol=1e-13, atol=1e-15)
    assert np.allclose(R[len(xs) :, 1], p * hat_integrals(m_x, s_x.min(), s_x.max()), rtol=1e-13, atol=1e-15)
    assert np.allclose(R[:, 0], 0.0, atol=1e-15)


def test_kinematics_choice_is_checked():
    with pytest.raises(ValueError, match="parameter kinematics"):
        MortarContact(PointCloud(X_SLAVE), np.arange(4), RigidLine(), normal=PowerLaw(1.0), kinematics="large")
