"""Mortar contact and the semi-smooth Newton method in the scenes (problem/enforcement.py):
what they must show, computed by the runs.

* the contact patch test (non-matching meshes at the fast and paper presets and two other
  mesh ratios, frictionless and Coulomb): mortar passes it to 1e-10 with the penalty and with
  Lagrange multipliers; node-to-segment does not, with either;
* Hertz on an elastic foundation with a non-matching mesh: mortar's p0 within 0.5 % and no
  node-to-node oscillation of the pressures; node-to-segment's oscillation beside it;
* the semi-smooth Newton method on the paper-preset block: few iterations, zero penetration,
  no dependence on c_N or c_T, quadratic convergence, the augmented Lagrangian's tractions;
* bar_impact and the refusals of combinations that do not exist.
"""

import numpy as np
import pytest

from contactfem.scenes import run_scene

# -- the patch test ----------------------------------------------------------------------------

MESHES = [
    ("fast", {}),
    ("paper", {}),
    ("fast", {"nx_lower": 3, "nx_upper": 11}),
    ("fast", {"nx_lower": 11, "nx_upper": 5}),
]
MESH_IDS = ["fast-4|7", "paper-8|13", "3|11", "11|5"]


@pytest.mark.parametrize("preset, mesh", MESHES, ids=MESH_IDS)
@pytest.mark.parametrize("mu", [0.0, 0.3], ids=["frictionless", "coulomb"])
@pytest.mark.parametrize("enforcement", ["penalty", "lagrange"])
def test_mortar_passes_the_patch_test(preset, mesh, mu, enforcement):
    r = run_scene("patch", preset, dict(mesh, mu=mu, contact_discretization="mortar", enforcement=enforcement))
    # The exact answer is homogeneous; with every interface node closed at the first iterate the
    # problem is linear, so one Newton solve lands on it to round-off (1e-11 or less measured):
    # 1e-10 is the bar asked of the method, a decade above what round-off leaves.
    print(
        f"{preset} {mesh} mu={mu} {enforcement}: pressure {r['pressure_deviation_max']:.1e}, "
        f"sigma_yy {r['stress_deviation_max']:.1e}, gap violation {r['gap_violation']:.1e}"
    )
    assert r["pressure_deviation_max"] < 1e-10
    assert r["stress_deviation_max"] < 1e-10
    assert r["load_carried"] == pytest.approx(r["load_applied"], rel=1e-10)
    if enforcement == "penalty":
        # the penalty's own error is the uniform penetration p / c_N, not a traction error
        assert r["gap_violation"] == pytest.approx(10.0 / 1e6 / 0.5, rel=1e-9)
    else:
        assert r["gap_violation"] < 1e-14


@pytest.mark.parametrize("preset, mesh", MESHES, ids=MESH_IDS)
@pytest.mark.parametrize("enforcement", ["penalty", "lagrange"])
def test_node_to_segment_fails_it_whatever_the_enforcement(preset, mesh, enforcement):
    """One-pass node-to-segment: the slave's tractions reach the master through the
    projections, not as the master's consistent load: errors of 0.6-5 % (2.6 % fast, 5.2 %
    paper), the same with exact multipliers (the error is the load transfer, not c_N)."""
    r = run_scene("patch", preset, dict(mesh, contact_discretization="node_to_segment", enforcement=enforcement))
    print(
        f"{preset} {mesh} {enforcement}: pressure {r['pressure_deviation_max']:.1e}, "
        f"sigma_yy {r['stress_deviation_max']:.1e}"
    )
    assert r["pressure_deviation_max"] > 1e-3 and r["stress_deviation_max"] > 1e-3


# -- Hertz on non-matching meshes ------------------------------------------------------------


@pytest.fixture(scope="module")
def hertz_elastic():
    return {
        (d, e): run_scene("hertz", "paper", dict(foundation="elastic", contact_discretization=d, enforcement=e))
        for d in ("node_to_segment", "mortar")
        for e in ("penalty", "lagrange")
    }


@pytest.mark.slow
def test_mortar_hertz_on_non_matching_meshes(hertz_elastic):
    for e in ("penalty", "lagrange"):
        m, n = hertz_elastic[("mortar", e)], hertz_elastic[("node_to_segment", e)]
        print(
            f"{e}: p0 error mortar {m['error_p0']:+.4f}, node-to-segment {n['error_p0']:+.4f}; oscillation "
            f"{m['oscillation']:.3f} vs {n['oscillation']:.3f}; largest jump {m['max_jump']:.3f} vs {n['max_jump']:.3f}"
        )
        # 0.5 %: the bar asked of mortar. Measured +0.09 % on 64^2 (the closed form is for two
        # half-planes; the foundation block of size R = 30 a and the mesh together stay below 0.1 %).
        assert abs(m["error_p0"]) < 5e-3
        # sum w t_N: mortar's tractions act along the cylinder's segment normals, tilted by theta < a / R
        # from the vertical where they act: the load they carry is sum w t_N cos(theta), within
        # 1 - cos(a / R) = 6e-4 of the sum (3e-4 measured)
        assert m["contact_force"] == pytest.approx(m["half_load"], rel=1e-3)
        # node-to-segment's pressures oscillate by several percent of p0 from node to node about
        # Hertz's profile (9 % measured); mortar's follow it (2 %, at the edge of the zone, where the
        # profile's own curvature between nodes is largest): at least three times smoother
        assert n["oscillation"] > 0.05
        assert m["oscillation"] < n["oscillation"] / 3
    assert hertz_elastic[("mortar", "lagrange")]["gap_violation"] < 1e-12


def test_mortar_on_the_rigid_foundation_misses_hertz_by_a_few_percent():
    """A known limitation: on the rigid foundation mortar's tractions act
    along the cylinder's segment normals, and p0 and the contact half-width miss Hertz by up
    to a few percent (below 10 %), more than node-to-segment's errors there."""
    m = run_scene("hertz", "fast", dict(contact_discretization="mortar"))
    n = run_scene("hertz", "fast", {})
    print(
        f"mortar: p0 {m['error_p0']:+.4f}, a {m['error_a']:+.4f}; node-to-segment: p0 {n['error_p0']:+.4f}, "
        f"a {n['error_a']:+.4f}"
    )
    assert max(abs(m["error_p0"]), abs(m["error_a"])) < 0.1
    assert abs(m["error_a"]) > abs(n["error_a"]) and abs(m["error_p0"]) > abs(n["error_p0"])


def test_mortar_needs_per_length_tractions():
    with pytest.raises(ValueError, match="per_node"):
        run_scene("hertz", "fast", dict(contact_discretization="mortar", penalty="per_node"))


# -- the semi-smooth Newton method on the block ----------------------------------------------

LAWS = {"coulomb": {"law": "coulomb", "mu": 0.3}, "conical": {"law": "conical"}, "parabolic": {"law": "parabolic"}}


@pytest.fixture(scope="module")
def block_ssn():
    return {law: run_scene("block", "paper", dict(over, enforcement="lagrange")) for law, over in LAWS.items()}


@pytest.mark.slow
@pytest.mark.parametrize("law", list(LAWS))
def test_semismooth_newton_on_the_block(block_ssn, law):
    r = block_ssn[law]
    res = r["newton_residuals"]
    print(
        f"{law}: {r['iterations']} iterations, {r['n_slip']} slipping nodes, residuals "
        + " ".join(f"{x:.1e}" for x in res)
    )
    # at most 10 linear solves, or one per slipping node where the slip zone is wider: from the
    # bonded first iterate it grows by about one node an iteration (Coulomb mu = 0.3: 12 nodes, 11)
    assert r["iterations"] <= max(10, r["n_slip"])
    assert r["equilibrium_error"] < 1e-9
    c = r["contact"]
    closed = np.array(c["t_N"]) < 0.0
    assert np.max(np.abs(np.array(c["g_N"])[closed])) < 1e-12 * 3.25  # zero penetration: of the height
    assert r["max_penetration"] < 1e-12 * 3.25
    assert r["max_slip_violation"] < 1e-9 and r["max_slip_surface_distance"] < 1e-9  # Coulomb holds
    # the sets settle, then Newton on a linear system: the last solve lands at round-off
    assert res[-1] < 1e-12 * res[0] and res[-2] > 1e3 * res[-1]


@pytest.mark.slow
@pytest.mark.parametrize("law", ["coulomb", "parabolic"])
def test_semismooth_newton_does_not_depend_on_c_N_or_c_T(block_ssn, law):
    ref = block_ssn[law]
    for over in ({"c_N": 1e3}, {"c_N": 1e7}, {"c_T": 1e2}, {"c_T": 1e6}):
        r = run_scene("block", "paper", dict(LAWS[law], enforcement="lagrange", **over))
        for key in ("t_N", "t_T"):
            a, b = np.array(r["contact"][key]), np.array(ref["contact"][key])
            # equal to round-off (1e-14 measured): the solution of C = 0 is free of c_N, c_T
            assert np.max(np.abs(a - b)) < 1e-10 * np.max(np.abs(b)), (over, key)


@pytest.mark.slow
@pytest.mark.parametrize("law", list(LAWS))
def test_semismooth_newton_tractions_are_the_augmented_lagrangians(block_ssn, law):
    """Uzawa to uzawa_tol = 1e-11 (its violation stalls at 7e-12, round-off of the shifted gap): its
    tractions are off by about c_N h tol = 2e-7 (problem/enforcement.py), 1e-9 of the pressure scale
    p_y = 200, a decade below the 1e-8 compared."""
    aug = run_scene("block", "paper", dict(LAWS[law], enforcement="augmented", uzawa_tol=1e-11))
    r = block_ssn[law]
    for key in ("t_N", "t_T"):
        a, b = np.array(aug["contact"][key]), np.array(r["contact"][key])
        assert np.max(np.abs(a - b)) < 1e-8 * 200.0, (key, np.max(np.abs(a - b)))
    assert aug["contact"]["state"] == r["contact"]["state"]


@pytest.mark.slow
@pytest.mark.parametrize("discretization", ["node_to_segment", "mortar"])
def test_quadratic_convergence_at_finite_strain(discretization):
    """The finite-strain block (St Venant-Kirchhoff, plane strain, a quarter of the loads): the
    gap and the slip are nonlinear in u, and once the sets settle Newton's residual squares
    from one iteration to the next: r_k+1 <= C r_k^2 / r_0 (C = 10, the measured C ~ 0.1-1)
    on the last two steps that end above the round-off floor (1e-10 r_0)."""
    r = run_scene(
        "block",
        "paper",
        dict(
            law="conical",
            enforcement="lagrange",
            material="svk",
            plane="strain",
            p_y=50.0,
            p_x=15.0,
            contact_discretization=discretization,
        ),
    )
    res = r["newton_residuals"]
    tail = [(a, b) for a, b in zip(res[:-1], res[1:]) if b > 1e-10 * res[0]][-2:]
    print(discretization, " ".join(f"{x:.1e}" for x in res))
    assert len(tail) >= 1
    for a, b in tail:
        assert b <= 10.0 * a * a / res[0], (a, b)


def test_mortar_semismooth_newton_on_the_block():
    for law, over in LAWS.items():
        r = run_scene("block", "paper", dict(over, enforcement="lagrange", contact_discretization="mortar"))
        assert r["equilibrium_error"] < 1e-9 and r["max_penetration"] < 1e-12 * 3.25
        assert r["max_slip_violation"] < 1e-12 * np.max(np.abs(r["contact"]["t_N"]))


# -- bar impact and refusals -------------------------------------------------------------------


@pytest.mark.slow
def test_bar_impact_takes_both_options():
    """Exact constraints under the paper's Newmark 0.7/0.4: the contact lasts 2 L / c to the step,
    with no penetration, and the energy falls by about what the rule removes with the penalty
    (within a factor 2); under the trapezoidal rule the end node chatters and the energy grows
    several times over (scene docstring)."""
    paper = dict(delta=0.7, beta_newmark=0.4)
    penalty = run_scene("bar_impact", "fast", paper)
    for d in ("node_to_segment", "mortar"):
        r = run_scene("bar_impact", "fast", dict(paper, contact_discretization=d, enforcement="lagrange"))
        assert abs(r["error_duration"]) <= r["dt"] / r["duration_exact"] + 1e-12
        assert r["gap_violation"] < 1e-12
        assert abs(r["error_stress_mean"]) < 0.01
        assert 0.5 < r["energy_error"] / penalty["energy_error"] < 2.0
    trapezoidal = run_scene("bar_impact", "fast", dict(enforcement="lagrange"))
    assert trapezoidal["energy_error"] > 2.0


@pytest.mark.parametrize(
    "scene, over, match",
    [
        ("block", {"contact_discretization": "mortar", "enforcement": "augmented"}, "node_to_segment only"),
        ("bar_impact", {"enforcement": "lagrange", "integrator": "central_difference"}, "implicit"),
        ("bar_impact", {"contact_discretization": "mortar", "contact_integration": "energy_consistent"}, "penalty"),
        ("block", {"enforcement": "lagrange", "m": 2.0}, "PowerLaw"),
        ("patch", {"contact_discretization": "mortar", "passes": 2}, "passes"),
    ],
)
def test_combinations_that_do_not_exist_are_refused(scene, over, match):
    with pytest.raises(ValueError, match=match):
        run_scene(scene, "fast", over)
