"""Contact with Lagrange multipliers and the semi-smooth Newton method
(contact/complementarity.py, contact/lagrange.py).

* the complementarity functions vanish exactly where the contact conditions hold
  (Signorini and Coulomb), and not elsewhere;
* the Jacobian of node-to-segment and mortar contact with multipliers (the bodies' rows
  and the multipliers' rows, over displacements and multipliers) against central
  differences, relative error < 1e-6, in every set: open, stick, slip both ways, and
  frictionless; rigid line, rigid polyline and a deformable master; mortar in both
  kinematics;
* bad input: laws the method cannot take, a contact outside a System.
"""

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error

from contactfem.contact import BodySurface, RigidLine, RigidPolyline
from contactfem.contact.complementarity import friction_complementarity, normal_complementarity
from contactfem.contact.lagrange import LagrangeMortar, LagrangeNodeToSegment
from contactfem.laws import OPEN, SLIP, STICK, Coulomb, ParabolicSlip, PowerLaw, SlipHardening

C_N, C_T, DT = 50.0, 30.0, 0.1
# Central differences with h = 1e-6: the residual is piecewise smooth with second derivatives
# of size 1-100 (the segment and mortar geometry; Y'' of the parabolic law at p >= 0.5), so the
# truncation error is below 1e-9 relative and the round-off 1e-16 |R| / h below 1e-9; every node
# is kept at least 0.2 (in traction) away from a switch of its set, far beyond what h moves it.
H = 1e-6
TOL = 1e-6

FRICTIONS = {
    "frictionless": None,
    "coulomb": Coulomb(c_T=C_T, mu=0.3),
    "parabolic": ParabolicSlip(c_T=C_T, alpha=0.2, beta=0.3, n=0.5),
}


# -- the complementarity functions ------------------------------------------------------


def test_normal_function_vanishes_exactly_on_the_signorini_conditions():
    g = np.array([0.0, 0.0, 0.1, 0.1, -0.1, 0.0])
    t_N = np.array([-2.0, 0.0, 0.0, -2.0, 0.0, 1.0])  # p = -t_N
    C, *_ = normal_complementarity(t_N, g, c_N=7.0)
    holds = (g >= 0) & (-t_N >= 0) & (t_N * g == 0)
    assert np.array_equal(C == 0.0, holds), (C, holds)


@pytest.mark.parametrize("c_N, c_T", [(1.0, 1.0), (1e5, 1e-3), (1e-3, 1e6)])
def test_friction_function_vanishes_exactly_on_coulombs_conditions(c_N, c_T):
    law, p = Coulomb(c_T=1.0, mu=0.5), 2.0  # Y = 1 at a closed node with g_N = 0
    xi = np.full(7, p)  # ... whatever c_N: xi = p - c_N * 0
    t_T = np.array([0.3, -0.7, 1.0, -1.0, 1.0, 0.3, 1.2])
    dg_T = np.array([0.0, 0.0, 0.2, -0.1, -0.1, 0.1, 0.0])
    C, _, _, _, state = friction_complementarity(law, t_T, dg_T, xi, c_T)
    # stick |t| < Y and no slip; slip |t| = Y and slip along t; violated: slip while |t| < Y,
    # slip against t, |t| > Y
    expected = [True, True, True, True, False, False, False]
    assert list(C == 0.0) == expected, C
    assert list(state[:4]) == [STICK, STICK, SLIP, SLIP]
    # an open node (xi < 0) carries nothing: C_T = t_T
    C, *_ = friction_complementarity(law, t_T, dg_T, np.full(7, -1.0), c_T)
    assert np.array_equal(C, t_T)


# -- the Jacobian against finite differences ---------------------------------------------

X_SLAVE = np.array([(0.85, 0.0), (0.62, 0.01), (0.38, -0.005), (0.15, 0.0)])  # right to left: n = -y
X_MASTER = np.array([(-0.2, -0.02), (0.2, 0.01), (0.45, -0.01), (0.7, 0.0), (1.2, -0.015)])


def make(kind, master_kind, friction, kinematics="finite"):
    """A contact of four slave nodes with multipliers, and the number of body dofs."""
    slave = PointCloud(X_SLAVE, "slave")
    if master_kind == "line":
        master, nb = RigidLine((0.0, 0.0), (0.02, 1.0)), slave.ndof
    elif master_kind == "polyline":
        master, nb = RigidPolyline(X_MASTER), slave.ndof
    else:
        body = PointCloud(X_MASTER, "master", dof_offset=slave.ndof)
        master, nb = BodySurface(body, np.arange(len(X_MASTER))), slave.ndof + body.ndof
    if kind == "node_to_segment":
        c = LagrangeNodeToSegment(
            slave, np.arange(4), master, normal=PowerLaw(c_N=C_N), friction=friction, weights=[0.2, 0.25, 0.22, 0.18]
        )
    else:
        c = LagrangeMortar(
            slave, np.arange(4), master, normal=PowerLaw(c_N=C_N), friction=friction, kinematics=kinematics
        )
    c.dof_offset = nb  # as a System places it
    return c, nb


def gaps_and_slips(contact, u, h):
    st = contact.evaluate(u, 0.0, DT, history=h)
    dg_T = st.dg_T if hasattr(st, "integrals") else st.s - h.s_bar
    return st.g_N, dg_T


def with_sets(contact, u, nb, sets, h):
    """u with multipliers that put node j in sets[j] (open, stick, slip+, slip-), each at
    least 0.2 (in traction) away from a switch."""
    nc = len(contact.nodes)
    g, dg = gaps_and_slips(contact, u, h)
    p = np.where(np.array(sets) == "open", C_N * g - 0.5, C_N * np.maximum(g, 0.0) + 1.0 + np.arange(nc) * 0.3)
    assert np.all(p[np.array(sets) == "open"] >= 0.0), "an open node must have a positive gap here"
    u = u.copy()
    u[nb : nb + nc] = -p
    if contact.friction is not None:
        xi = p - C_N * g
        Y = contact.friction.slip_bound(np.maximum(xi, 0.5), np.zeros(nc))[0]
        tau = np.array([{"open": 0.4, "stick": 0.5, "slip+": 2.0, "slip-": -2.0}[s] for s in sets]) * Y
        t_T = tau - C_T * dg
        t_T[np.array(sets) == "open"] = 0.37
        u[nb + nc : nb + 2 * nc] = t_T
    return u


def check_jacobian(contact, u, h):
    n = len(u)
    R, rows, cols, vals = contact.evaluate(u, 0.0, DT, history=h).scatter(n)
    K = np.zeros((n, n))
    np.add.at(K, (rows, cols), vals)
    Kfd = fd_jacobian(lambda v: contact.evaluate(v, 0.0, DT, history=h).scatter(n)[0], u, h=H)
    err = rel_error(K, Kfd)
    assert err < TOL, f"Jacobian mismatch {err:.2e}"
    return err


# every set: open and stick nodes together, slip in either direction beside stick
SETS = {
    "open-stick": ["open", "stick", "stick", "open"],
    "slip+": ["slip+", "slip+", "stick", "slip+"],
    "slip-": ["slip-", "slip-", "slip-", "stick"],
}
LAWS_SETS = [
    ("frictionless", "open-stick"),
    ("coulomb", "open-stick"),
    ("coulomb", "slip+"),
    ("coulomb", "slip-"),
    ("parabolic", "slip+"),
    ("parabolic", "slip-"),
]
CASES = (
    [("node_to_segment", m, "finite") for m in ("line", "polyline", "deformable")]
    + [("mortar", m, "finite") for m in ("line", "polyline", "deformable")]
    + [("mortar", m, "small") for m in ("line", "deformable")]
)


@pytest.mark.slow
@pytest.mark.parametrize("kind, master, kinematics", CASES, ids=["-".join(c) for c in CASES])
@pytest.mark.parametrize("law, sets", LAWS_SETS, ids=["-".join(c) for c in LAWS_SETS])
def test_jacobian_matches_finite_differences(rng, kind, master, kinematics, law, sets):
    contact, nb = make(kind, master, FRICTIONS[law], kinematics)
    u = np.zeros(nb + contact.unknowns)
    u[:nb] = 0.003 * rng.standard_normal(nb)
    h = contact.start(u)
    u[0:8:2] += 0.02  # the slave slides along x (a slip of the step)
    wanted = SETS[sets]
    u[1:8:2] += np.where(np.array(wanted) == "open", 0.06, -0.02)  # open nodes lifted, the others pressed in
    u = with_sets(contact, u, nb, wanted, h)
    st = contact.evaluate(u, 0.0, DT, history=h)
    expected = {"open": OPEN, "stick": STICK, "slip+": SLIP, "slip-": SLIP}
    got = st.slip
    want = [expected[s] if law != "frictionless" else (OPEN if s == "open" else STICK) for s in wanted]
    assert list(got) == want, (got, want)
    if law != "frictionless" and "slip" in sets:
        sign = 1.0 if sets == "slip+" else -1.0
        on = np.array(wanted) == sets
        assert np.all(np.sign(u[nb + 4 :][on] + C_T * gaps_and_slips(contact, u, h)[1][on]) == sign)
    check_jacobian(contact, u, h)


# -- bad input ------------------------------------------------------------------------------


def test_laws_it_cannot_take_are_refused():
    slave = PointCloud(X_SLAVE)
    with pytest.raises(ValueError, match="PowerLaw"):
        LagrangeNodeToSegment(slave, np.arange(4), RigidLine(), normal=PowerLaw(c_N=1.0, m=2.0))
    with pytest.raises(ValueError, match="Coulomb or ParabolicSlip"):
        LagrangeMortar(
            slave, np.arange(4), RigidLine(), normal=PowerLaw(c_N=1.0), friction=SlipHardening(c_T=1.0, mu=0.2, h=0.5)
        )
    with pytest.raises(ValueError, match="tangent = consistent"):
        LagrangeNodeToSegment(slave, np.arange(4), RigidLine(), normal=PowerLaw(c_N=1.0), tangent="symmetric")


def test_outside_a_system_it_says_so():
    c = LagrangeNodeToSegment(PointCloud(X_SLAVE), np.arange(4), RigidLine(), normal=PowerLaw(c_N=1.0))
    h = c.start(np.zeros(8))
    with pytest.raises(ValueError, match="put it in a System"):
        c.evaluate(np.zeros(12), history=h)
