"""Sloping impact of a ring on a rigid plane (paper Sec. 5.3, Figs 10-11, Table 2).

The fast preset is the paper's run (16 beam elements, 200 steps of dt = 0.1): it takes
about two seconds. Paper values (Table 2) are stated in the assert messages with the
tolerance. The runs are shared with the figure code through its cache."""

import json
from pathlib import Path

import numpy as np
import pytest

from contactfem.plots import sloping_impact as plots
from contactfem.scenes import run_scene
from contactfem.scenes.sloping_impact import PAPER_TABLE2, SCENE, rebound_angle
from contactfem.lab import reconstruct as rc

R_OUTER = 10.5


@pytest.fixture(scope="module")
def res():
    return {v: plots.result(v, "fast") for v in ("frictionless", "frictional", "viscoplastic")}


def test_json_has_the_required_results(res):
    for r in res.values():
        for key in (
            "rebound_vx",
            "rebound_vy",
            "rebound_angle_deg",
            "rebound_spin",
            "energy_kinetic",
            "energy_strain",
            "energy_contact",
            "energy_dissipation",
            "energy_total",
            "newton_iterations_total",
        ):
            assert key in r, key
        assert r["rebounded"], "the ring leaves the plane within the 200 steps"
        assert r["newton_iterations_total"] > 200
        json.dumps(r)  # JSON-able, no NaN
        assert len(r["energy_total"]) == len(r["t"]) == 201


def test_rebound_angle_definition():
    assert rebound_angle(2.0, 1.7) == pytest.approx(49.64, abs=0.01)  # Table 2: 50 deg
    assert rebound_angle(1.2, -1.7) == pytest.approx(35.22, abs=0.01)  # Table 2: 35 deg


# Table 2 prints the velocities to two digits (1.7, 1.2: +-0.05, 3-4 %). A number is reproduced
# when ours is within 10 %: twice the printing uncertainty, the rest for the paper's own
# time-discretisation error at dt = 0.1, which for ours is of that size (lecture 06: v_y moves
# by 0.1-0.3 from dt = 0.1 to 0.0125). Same criterion as `contactfem reconstruct sloping_impact`.
# The angles are not compared with the paper's here: each is atan(|v_x| / |v_y|) of its row, and
# the beam integration was fitted so that they land near the printed ones.
VELOCITY_TOL = rc.TABLE2_VELOCITY_TOL


@pytest.mark.slow
@pytest.mark.parametrize(
    "over",
    [
        {},
        {"integration": "1"},
        {"mass_matrix": "consistent"},
        {"contact_integration": "energy_consistent"},
        {"kind": "continuum", "n_el": 24},
    ],
)
def test_a_frictionless_plane_keeps_v_x(over):
    """Table 2's frictionless v_x = 2 is no test of a reading: a frictionless plane exerts no
    tangential force, so the momentum along it is kept, whatever the ring, its mass and the
    stepper (both keep linear momentum exactly when the resultant is zero): v_x = 2 to 1e-8."""
    r = run_scene("sloping_impact", "paper", dict(over, variant="frictionless", n_steps=60))
    assert r["rebounded"] and r["rebound_vx"] == pytest.approx(2.0, rel=1e-8)
    assert np.allclose(r["vx_c"], 2.0, rtol=1e-8, atol=0)  # at every step, through the impact


def test_the_studys_preset_reading_is_this_run(res):
    """The inverse study's reading of the preset (figures/table_reconstruct.json, from which the front page's
    Table 2 row is generated) is this run: its velocities and angles to 1e-6 (the study stops at t = 8,
    after the rebound), and how many of Table 2's three scored numbers (rc.TABLE2_SCORED) lie within the
    10 %: counted here from the run, so the row holds whichever way a change moves the model. The
    frictionless v_x is no test of a reading (test_a_frictionless_plane_keeps_v_x)."""
    import json

    committed = json.loads((Path(__file__).parents[1] / "figures" / "table_reconstruct.json").read_text())
    row = committed["sloping_impact"]["preset"]
    for v in ("frictionless", "frictional"):
        r = res[v]
        assert abs(r["rebound_vx"]) == pytest.approx(abs(row[f"{v}_vx"]), abs=1e-6)
        assert abs(r["rebound_vy"]) == pytest.approx(abs(row[f"{v}_vy"]), abs=1e-6)
        assert r["rebound_angle_deg"] == pytest.approx(row[f"{v}_angle"], abs=1e-4)
    within = sum(abs(abs(res[v][f"rebound_{q}"]) / PAPER_TABLE2[v][q] - 1) <= VELOCITY_TOL for v, q in rc.TABLE2_SCORED)
    assert within == row["n_facts"]


def test_friction_slows_and_spins_the_ring(res):
    """Paper: the frictional ring loses tangential speed and spins after rebound. Friction at the
    bottom turns it clockwise (omega < 0 for v_x > 0), towards rolling v_x + omega R_outer = 0."""
    fl, fr = res["frictionless"], res["frictional"]
    assert abs(fl["rebound_spin"]) < 1e-10
    assert fr["rebound_vx"] < 0.7 * fl["rebound_vx"], "paper: 1.2 vs 2"
    assert fr["rebound_spin"] < 0
    slip_speed = fr["rebound_vx"] + fr["rebound_spin"] * R_OUTER
    assert abs(slip_speed) < 0.2 * fr["rebound_vx"], f"nearly rolling off the plane: {slip_speed:.3f}"


def test_energy_never_increases_with_friction(res):
    """Newmark 0.7/0.4 and friction only remove energy: kinetic + strain + contact never
    rises from one step to the next (tolerance 1e-6 of the initial energy)."""
    for v in ("frictional", "viscoplastic"):
        E = np.asarray(res[v]["energy_total"])
        assert np.max(np.diff(E)) <= 1e-6 * E[0], f"{v}: total energy increased by {np.max(np.diff(E)):.3e}"
        assert res[v]["energy_dissipation"][-1] > 0


def test_frictionless_average_acceleration_conserves_energy():
    """delta = 1/2, beta = 1/4: kinetic + strain + contact stays within 2 % of its initial
    value over the impact (until the ring has left the plane). With dt = 0.1 the error is
    3.5 % (contact switching within a step, geometric nonlinearity); dt = 0.025 gives 0.6 %."""
    r = run_scene("sloping_impact", "fast", dict(delta=0.5, beta_newmark=0.25, dt=0.025, n_steps=260))
    assert r["rebounded"]
    assert r["energy_total_max_rel_change_impact"] < 0.02, r["energy_total_max_rel_change_impact"]


def test_viscoplastic_ring_bounces_lower_and_deforms_permanently(res):
    """Paper: 'non-uniform deformations and a lower upward movement of the ring'."""
    vp, fr = res["viscoplastic"], res["frictional"]
    assert vp["rebound_vy"] < 0.8 * fr["rebound_vy"]
    assert vp["plastic_strain_max"][2] > 0.01, "permanent curvature"
    assert max(fr["plastic_strain_max"]) == 0.0


def test_bad_input():
    with pytest.raises(ValueError, match="variant"):
        SCENE.resolve("fast", {"variant": "sticky"})
    with pytest.raises(ValueError, match="vy0"):
        SCENE.resolve("fast", {"vy0": 1.0})
    with pytest.raises(ValueError, match="kind"):
        run_scene("sloping_impact", "fast", {"variant": "viscoplastic", "kind": "continuum"})


@pytest.mark.slow
def test_figures_and_table(tmp_path):
    files = plots.fig10(outdir=tmp_path) + plots.table2(outdir=tmp_path)
    assert all((tmp_path / f).exists() for f in files)
    md = (tmp_path / "table2_sloping_impact.md").read_text()
    assert "| frictionless |" in md and "50" in md and "35" in md


@pytest.mark.slow
def test_discretisation_study_kept_with_the_figures_is_the_run():
    """figures/table_sloping_impact_discretisation.{md,json} (lecture 06 reads its conclusions from
    it) are the study's run: the markdown is its JSON's, and its 16-element rows are recomputed
    here to round-off (a few seconds; CONTACTFEM_SLOW=1: every row, about a minute)."""
    import json
    import os
    from pathlib import Path

    from contactfem.plots import sloping_impact as F

    base = Path(__file__).resolve().parents[1] / "figures" / "table_sloping_impact_discretisation"
    kept = json.loads(base.with_suffix(".json").read_text())
    assert base.with_suffix(".md").read_text() == F.discretisation_markdown(kept["rows"])
    assert [r["label"] for r in kept["rows"]] == [label for label, _, _ in F.DISCRETISATION]
    by_label = {r["label"]: r for r in kept["rows"]}
    rows = F.discretisation_rows(kept["preset"], quick=not os.environ.get("CONTACTFEM_SLOW"))
    assert rows
    for row in rows:
        for variant in ("frictionless", "frictional"):
            assert (variant in row) == (variant in by_label[row["label"]]), (row["label"], variant)
            for k, v in row.get(variant, {}).items():
                assert v == pytest.approx(by_label[row["label"]][variant][k], rel=1e-9, abs=1e-12), (
                    row["label"],
                    variant,
                    k,
                )


@pytest.mark.slow
def test_a_fine_ring_runs():
    """n_el = 1000 (the range allows 2000): Newton's tolerance follows the round-off of the
    ring's residual, which grows with n_el (at the fixed 1e-10 Newton stalled just above it
    after the rebound); the rebound agrees with the paper preset's ring refined, within the
    discretisation's change (n_el = 16 -> 1000 moves v_y by less than 10 %)."""
    from contactfem.scenes import get_scene
    from contactfem.scenes.sloping_impact import newton_atol

    assert newton_atol(get_scene("sloping_impact").resolve("paper"), 48) == 1e-10  # the presets keep 1e-10
    fine = run_scene("sloping_impact", "fast", {"n_el": 1000})
    coarse = run_scene("sloping_impact", "fast")
    assert fine["rebounded"] and abs(fine["rebound_vy"] - coarse["rebound_vy"]) < 0.1 * abs(coarse["rebound_vy"])
