"""RigidComposite (contact/masters.py): a smooth rigid master of lines and arcs. Here a
fillet touched from inside (floor, counter-clockwise quarter circle, wall), the mirror
case of the cork's neck (wall, clockwise mouth, top; tests/test_cork.py). The arc
coordinate runs on across the joints, the normal is continuous, the first and second
variations of g_N and s match finite differences on every piece, and a prescribed motion
moves the master without changing s."""

import numpy as np
import pytest

from contactfem.contact import NodeToSegment
from contactfem.contact.masters import RigidComposite
from contactfem.laws import Coulomb, PowerLaw

from conftest import PointCloud, assert_locate_matches_fd


def fillet(offset=(0.0, 0.0)):
    return RigidComposite(
        [
            ("line", (-5.0, 0.0), (0.0, 0.0)),
            ("arc", (0.0, 1.0), 1.0, -np.pi / 2, 0.0),
            ("line", (1.0, 1.0), (1.0, 5.0)),
        ],
        offset=offset,
    )


def test_joints_are_continuous_and_s_runs_on():
    m = fillet()
    e = 1e-9
    x = np.array([[-e, 0.1], [e, 0.1], [0.9, 1.0 - e], [0.9, 1.0 + e]])
    k = m.locate(x, np.zeros(len(x)), None)
    assert list(k["seg"]) == [0, 1, 1, 2]
    assert np.allclose(k["n"][0], k["n"][1], atol=1e-6) and np.allclose(k["n"][2], k["n"][3], atol=1e-6)
    assert k["s"][1] - k["s"][0] == pytest.approx(0.0, abs=1e-6)
    assert k["s"][3] - k["s"][2] == pytest.approx(0.0, abs=1e-6)
    assert k["s"][3] == pytest.approx(5.0 + np.pi / 2, abs=1e-6)  # floor + quarter circle
    assert np.allclose(k["n"], np.stack([-k["t"][:, 1], k["t"][:, 0]], axis=1))  # n = e3 x t (eq 18)
    assert k["g_N"][0] == pytest.approx(0.1) and k["g_N"][3] == pytest.approx(0.1)
    assert np.allclose(k["n"][0], [0, 1]) and np.allclose(k["n"][3], [-1, 0])  # into the fillet
    inside = m.locate(np.array([[-6.0, 0.5], [0.5, 6.0], [0.5, 0.5]]), np.zeros(3), None)["inside"]
    assert list(inside) == [False, False, True]  # beyond either end


@pytest.mark.parametrize("x", [[-2.0, 0.2], [0.3, 0.4], [0.7, 0.8], [0.8, 3.0]])
def test_variations_match_finite_differences(x):
    assert_locate_matches_fd(fillet(offset=(0.2, -0.1)), np.array(x) + np.array([0.2, -0.1]))


def test_motion_keeps_s_and_moves_the_gap():
    m = RigidComposite(
        [
            ("line", (-5.0, 0.0), (0.0, 0.0)),
            ("arc", (0.0, 1.0), 1.0, -np.pi / 2, 0.0),
            ("line", (1.0, 1.0), (1.0, 5.0)),
        ],
        motion=lambda t: (0.0, 0.1 * t),
    )
    x = np.array([[0.5, 0.3], [0.9, 2.0]])
    k0 = m.locate(x, np.zeros(2), None, t=0.0)
    k1 = m.locate(x + [0.0, 0.1], np.zeros(2), None, t=1.0)
    assert np.allclose(k0["s"], k1["s"]) and np.allclose(k0["g_N"], k1["g_N"])
    assert np.allclose(m.locate(x, np.zeros(2), None)["g_N"], k0["g_N"])  # no time: no motion


def test_a_node_sliding_round_the_fillet_keeps_its_friction_history():
    """One slave pressed into the floor, moved round the corner onto the wall: the slip
    increment s - s_bar is the path length, whatever piece the node is on."""
    body = PointCloud(np.array([[-0.5, -0.01]]), "slave")
    contact = NodeToSegment(body, [0], fillet(), normal=PowerLaw(c_N=100.0), friction=Coulomb(c_T=10.0, mu=0.3))
    u = np.zeros(2)
    h = contact.start(u)
    s0 = h.s_bar.copy()
    th = np.linspace(-np.pi / 2, 0.0, 7)
    for a in th:  # along the arc, just inside the glass
        x = np.array([0.0, 1.0]) + 1.01 * np.array([np.cos(a), np.sin(a)])
        h = contact.commit(contact.evaluate(x - body.X[0], history=h))
    assert h.s_bar[0] - s0[0] == pytest.approx(0.5 + np.pi / 2, rel=1e-9)


def test_bad_pieces_are_refused():
    with pytest.raises(ValueError, match="line|arc"):
        RigidComposite([("spline", (0, 0), (1, 0))])
    with pytest.raises(ValueError, match="zero length"):
        RigidComposite([("line", (0, 0), (0, 0))])
    with pytest.raises(ValueError, match="R > 0"):
        RigidComposite([("arc", (0, 0), 0.0, 0.0, 1.0)])
