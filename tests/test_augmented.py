"""Augmented-Lagrangian contact (contact/augmented.py, solver/uzawa.py).

* the tangent of every augmented interface (multipliers fixed) against finite differences:
  open, stick, slip both ways; rigid line, polyline, arc, deformable master; the penalty
  normal law (augmented) and a power law m = 2.5 (kept as a constitutive law);
* Hertz and the block: the largest penetration / the scene's length < 1e-8 after at most
  6 multiplier updates at the scene's c_N, and the results (p0, totals, nodal tractions)
  the same to 1e-6 with c_N 100 times smaller and larger.
"""

from dataclasses import replace

import numpy as np
import pytest
from conftest import PointCloud
from test_contact_tangent import DT, check_tangent, make_master, set_history, slave_cloud

from contactfem.contact import BodySurface, SLIP, STICK
from contactfem.contact.augmented import AugmentedNodeToSegment, make_interface
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.scenes import run_scene
from contactfem.scenes.hertz import hertz_exact
from contactfem.solver import NewtonError

NORMALS = {"penalty": PowerLaw(c_N=50.0), "power2.5": PowerLaw(c_N=80.0, m=2.5)}
FRICTIONS = {
    "none": None,
    "coulomb": Coulomb(c_T=30.0, mu=0.3),
    "parabolic": ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5),
}


def with_multipliers(iface, rng, u, h):
    """The history h with multipliers as after some Uzawa updates: lam_N < 0 (compressive),
    lam_T of either sign inside the slip bound (a tenth of the pressure)."""
    n = len(iface.nodes)
    if iface.augment_normal:
        h = replace(h, lam_N=-rng.uniform(0.5, 1.5, n))
    return replace(h, lam_T=0.1 * np.abs(iface.evaluate(u, dt=DT, history=h).t_N) * rng.choice([-1.0, 1.0], n))


@pytest.mark.parametrize("master", ["line", "tilted_polyline", "arc_outside", "arc_inside"])
@pytest.mark.parametrize("nlaw", list(NORMALS))
@pytest.mark.parametrize("flaw", list(FRICTIONS))
@pytest.mark.parametrize("regime", ["stick", "slip+", "slip-"])
def test_augmented_rigid_master_tangent(rng, master, nlaw, flaw, regime):
    body, u = slave_cloud(rng)
    iface = AugmentedNodeToSegment(
        body,
        np.arange(4),
        make_master(master),
        normal=NORMALS[nlaw],
        friction=FRICTIONS[flaw],
        weights=rng.uniform(0.5, 1.5, 4),
    )
    dg = {"stick": 1e-6, "slip+": 0.5, "slip-": -0.5}[regime]
    h = with_multipliers(iface, rng, u, set_history(iface, u, t_T_bar=0.0, dg=dg))
    e = iface.evaluate(u, dt=DT, history=h)
    assert np.all(e.active)
    if FRICTIONS[flaw] is not None:
        assert np.all(e.slip == (STICK if regime == "stick" else SLIP))
    check_tangent(iface, u, h)


@pytest.mark.parametrize("flaw", list(FRICTIONS))
@pytest.mark.parametrize("regime", ["stick", "slip+", "slip-"])
def test_augmented_deformable_master_tangent(rng, flaw, regime):
    Xm = np.stack([np.linspace(-0.2, 1.2, 5), np.zeros(5)], axis=1)
    mb = PointCloud(Xm, "master")
    sb = PointCloud(np.stack([np.linspace(0.1, 0.9, 3), np.zeros(3)], axis=1), "slave", dof_offset=mb.ndof)
    u = np.zeros(mb.ndof + sb.ndof)
    u[: mb.ndof] = 0.02 * rng.standard_normal(mb.ndof)
    u[mb.ndof + 1 :: 2] = -0.06 - 0.02 * rng.random(3)
    surface = BodySurface(mb, np.arange(5))
    iface = AugmentedNodeToSegment(
        sb, np.arange(3), surface, normal=NORMALS["penalty"], friction=FRICTIONS[flaw], weights=0.7
    )
    u_old = u.copy()
    u_old[: mb.ndof] *= 0.3
    h = set_history(
        iface, u, t_T_bar=0.01, dg={"stick": 1e-6, "slip+": 0.5, "slip-": -0.5}[regime], master=surface.reference(u_old)
    )
    h = with_multipliers(iface, rng, u, h)
    assert np.all(iface.evaluate(u, dt=DT, history=h).active)
    check_tangent(iface, u, h)


def test_multiplier_opens_and_closes_contact(rng):
    """The active set is that of the shifted gap g_N + lam_N / c_N: a node just above the
    plane carries a pressure when lam_N pulls it in, a penetrating one with no multiplier
    does too, a node above the plane with lam_N = 0 is open (no force, no tangent)."""
    body = PointCloud([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], "slave")
    u = np.array([0.0, 0.01, 0.0, -0.01, 0.0, 0.01])
    iface = AugmentedNodeToSegment(
        body, np.arange(3), make_master("line"), normal=PowerLaw(50.0), friction=Coulomb(30.0, 0.3)
    )
    h = replace(iface.start(u), lam_N=np.array([-1.0, 0.0, 0.0]))
    e = iface.evaluate(u, history=h)
    assert list(e.active) == [True, True, False]
    assert np.isclose(e.t_N[0], -1.0 + 50.0 * 0.01) and np.isclose(e.t_N[1], -0.5)
    R, rows, cols, vals = e.scatter(len(u))
    assert np.all(R[4:] == 0) and not np.any(np.isin(rows, [4, 5]))
    v = iface.violation(e)
    h = iface.update_multipliers(e)
    assert np.isclose(v["penetration"], 0.01)
    assert np.allclose(h.lam_N, [-0.5, -0.5, 0.0])


def test_constitutive_power_law_keeps_its_meaning():
    body = PointCloud([[0.0, 0.0]], "slave")
    iface = AugmentedNodeToSegment(
        body, [0], make_master("line"), normal=PowerLaw(80.0, m=2.5), friction=Coulomb(30.0, 0.3)
    )
    assert not iface.augment_normal
    u = np.array([0.0, -0.1])
    h = iface.start(u)
    e = iface.evaluate(u, history=h)
    v = iface.violation(e)
    h = iface.update_multipliers(e)
    assert v["penetration"] == 0.0 and np.all(h.lam_N == 0.0)
    assert np.isclose(iface.evaluate(u, history=h).t_N[0], -80.0 * 0.1**2.5)


def test_bad_enforcement_raises():
    body = PointCloud([[0.0, 0.0]], "slave")
    with pytest.raises(ValueError, match="enforcement"):
        make_interface("exact", body, [0], make_master("line"), normal=PowerLaw(1.0))
    with pytest.raises(ValueError, match="enforcement"):
        run_scene("hertz", "fast", {"enforcement": "exact"})
    with pytest.raises(ValueError, match="uzawa_tol"):
        run_scene("hertz", "fast", {"enforcement": "augmented", "uzawa_tol": 0.0})


def test_too_few_updates_raise_with_history():
    with pytest.raises(NewtonError, match="uzawa_tol") as err:
        run_scene("block", "fast", {"enforcement": "augmented", "uzawa_max_updates": 2})
    assert len(err.value.history) > 0


# -- Hertz and the block -------------------------------------------------------------


def _tol(c_N, p, L):
    """A gap tolerance that bounds the traction error c_N * gap below 1e-7 p (the last
    multiplier update changes the traction by about c_N times the remaining penetration)."""
    return min(1e-9, 1e-7 * p / (c_N * L))


@pytest.fixture(scope="module")
def hertz_runs():
    a, p0 = hertz_exact(2000.0, 10.0, 2.0e5, 0.3)  # the scene's defaults
    out = {}
    for c_N in (1e7, 1e9, 1e11):
        out[c_N] = run_scene("hertz", "fast", {"enforcement": "augmented", "c_N": c_N, "uzawa_tol": _tol(c_N, p0, a)})
    out["default"] = run_scene("hertz", "fast", {"enforcement": "augmented", "uzawa_tol": 1e-8})
    return out


def test_an_augmented_runs_equilibrium_is_its_newton_solves():
    """The equilibrium indicator of a run with the Uzawa loop reads the converged Newton solve of each step (it
    once read 0 for every step: the loop's result had no residual_ratio). Hertz's contact forces (~1e3) leave
    a converged residual of a few ulps of them above newton's atol (1e-12), so its ratio is not 0."""
    from contactfem.problem.accuracy import EQUILIBRIUM

    eq = run_scene("hertz", "fast", {"enforcement": "augmented", "uzawa_tol": 1e-8})["accuracy"]["equilibrium"]
    assert 0.0 < eq["value"] <= EQUILIBRIUM


@pytest.mark.slow
def test_hertz_augmented_reaches_1e8_in_6_updates(hertz_runs):
    r = hertz_runs["default"]
    assert r["c_N_per_length_min"] == 1e9  # the scene's default c_N
    assert r["gap_violation"] < 1e-8 and r["multiplier_updates"] <= 6, (r["gap_violation"], r["multiplier_updates"])
    pen = run_scene("hertz", "fast")
    assert pen["gap_violation"] > 1e-6  # the penalty: a penetration of ~1e-5 a


@pytest.mark.slow
@pytest.mark.parametrize("c_N", [1e7, 1e11])
def test_hertz_augmented_independent_of_penalty(hertz_runs, c_N):
    ref, r = hertz_runs[1e9], hertz_runs[c_N]
    assert r["p0"] == pytest.approx(ref["p0"], rel=1e-6)
    assert r["contact_force"] == pytest.approx(ref["contact_force"], rel=1e-6)
    p, p_ref = np.array(r["profile_p"]), np.array(ref["profile_p"])
    assert np.max(np.abs(p - p_ref)) <= 1e-6 * np.max(p_ref)
    assert r["gap_violation"] < 1e-10


@pytest.mark.parametrize("law", ["conical", "parabolic"])
def test_block_augmented(law):
    # the canonical block (4 x 3.5, 20 x 10: element size 4 / 20) of the augmented-Lagrangian study
    base = {"law": law, "enforcement": "augmented"}
    h, p = 4.0 / 20, 200.0  # element size, traction scale (p_y)
    runs = {c: run_scene("block", "canonical", dict(base, c_N=c, uzawa_tol=_tol(c, p, h))) for c in (1e3, 1e5, 1e7)}
    ref = runs[1e5]
    # at the scene's c_N: penetration / element size < 1e-8 after at most 6 multiplier updates
    gaps = ref["gap_violation_per_outer"]
    first = next(k for k, g in enumerate(gaps) if g < 1e-8)  # outer iteration k follows k updates
    assert first <= 6, gaps
    for c in (1e3, 1e7):
        r = runs[c]
        for key in ("total_normal", "total_tangential"):
            assert r[key] == pytest.approx(ref[key], rel=1e-6)
        for key in ("t_N", "t_T"):
            a, b = np.array(r["contact"][key]), np.array(ref["contact"][key])
            assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(ref["contact"]["t_N"])), (c, key)
        assert r["contact"]["state"] == ref["contact"]["state"]
    # the penalty result moves with c_N
    pen = [run_scene("block", "canonical", {"law": law, "c_N": c})["contact"]["t_N"] for c in (1e3, 1e5)]
    assert np.max(np.abs(np.array(pen[0]) - pen[1])) > 1e-3 * np.max(np.abs(pen[1]))
