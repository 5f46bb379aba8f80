"""The scan's unknowns as an inverse problem (contactfem.lab.reconstruct): the block's
reading against Table 1 and Fig 8, the sloping impact's against Table 2.

CI runs the quick profiles; CONTACTFEM_SLOW=1 runs the full searches and checks that the
presets are their best readings."""

import json
import os

import numpy as np
import pytest

from contactfem.cli import main
from contactfem.scenes import get_scene, run_scene
from contactfem.scenes.block import PAPER_TABLE1, build, load_norms
from contactfem.lab import reconstruct as rc

SLOW = os.environ.get("CONTACTFEM_SLOW") == "1"


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("CONTACTFEM_CACHE", str(tmp_path / "cache"))


# ---------------------------------------------------------------------------------------
# block: the first residual, analytically
@pytest.mark.parametrize("over", [{}, {"width": 3.5, "height": 4.0, "nx": 20, "ny": 10},
                                  {"nx": 10, "ny": 20, "p_x_face": "right"}, {"p_y": 60.0, "p_x": 200.0}])
def test_first_residual_formula_is_the_nodal_load_norm(over):
    # the loads are set after resolving: the formula is about load vectors only, and the
    # swapped reading (p_x = 200 along, p_y = 60 down) has no static equilibrium, which
    # the scene refuses before any solve
    p = dict(get_scene("block").resolve("paper", {}), **over)
    b = build(p)
    top, side = load_norms(b["body"], b["loads"])
    assert rc.block_first_residual(p["width"], p["height"], p["nx"], p["ny"], p["p_y"], p["p_x"]) == \
        pytest.approx(np.hypot(top, side), rel=1e-12)


def test_no_uniform_block_reaches_the_printed_first_residual():
    """Table 1 prints 0.1713709e3 (7 digits, +-5e-5 absolute, 3e-7 relative). The closest
    geometry on the study's grid is W = 3.5, H = 4 (20 x 10) at 171.346: 1.4e-4 off, far
    outside the printed digits; every kept geometry is within 1 % and in equilibrium."""
    g = rc.block_geometries()
    assert (g[0]["nx"], g[0]["width"], g[0]["height"]) == (20, 3.5, 4.0)
    assert abs(g[0]["first_residual"] / rc.PAPER_FIRST_RESIDUAL - 1) > 1e-5
    for x in g:
        assert abs(x["first_residual"] / rc.PAPER_FIRST_RESIDUAL - 1) <= 0.01
        assert x["p_x"] * x["height"] < 0.5 * x["p_y"] * x["width"]


def test_residual_distance():
    paper = PAPER_TABLE1["conical"]
    assert rc.residual_distance(paper, paper) == 0.0
    assert rc.residual_distance(None, paper) == float("inf")
    # stopping one iteration earlier than the paper costs log10(3.2 / 1e-3) / 2 in RMS
    d = rc.residual_distance(paper[:2], paper)
    assert d == pytest.approx(np.sqrt(np.log10(paper[2] / 1e-3) ** 2 / 4))


# ---------------------------------------------------------------------------------------
# block: the paper preset against Table 1
@pytest.fixture(scope="module")
def block_paper():
    return {law: run_scene("block", "paper", {"law": law}) for law in ("conical", "parabolic")}


def test_block_paper_first_residual(block_paper):
    """Table 1: 171.3709. No uniform mesh reaches the printed digits (test above), so the
    comparison is to 1 %: the study keeps only readings within 1 %; the preset's is +0.30 %."""
    for r in block_paper.values():
        assert abs(r["newton_residuals"][0] / 171.3709 - 1) <= 0.01, r["newton_residuals"][0]


def test_block_paper_conical_slips_with_few_residuals(block_paper):
    """Table 1, conical: 4 residuals, the last drop (3.2 -> 4e-11) once the stick/slip set is
    settled. Ours: nodes slip; at most 5 residuals; the last reduction quadratic or to round-off
    (e_{k+1} <= 10 e_k^2 or <= 1e-13, e = r / r_0)."""
    r = block_paper["conical"]
    assert r["n_slip"] > 0
    res = np.array(r["newton_residuals"])
    assert len(res) <= 5, res
    e = res / res[0]
    assert e[-1] <= max(10 * e[-2] ** 2, 1e-13), e


def test_block_paper_parabolic_residuals(block_paper):
    """Table 1, parabolic: 7 residuals. Ours: at most 8, the last two reductions quadratic."""
    res = np.array(block_paper["parabolic"]["newton_residuals"])
    assert len(res) <= 8, res
    e = res / res[0]
    for k in (-3, -2):
        assert e[k + 1] <= max(10 * e[k] ** 2, 1e-13), e


def test_run_block_json_reports_slip_and_fitted_values(tmp_path):
    path = tmp_path / "block.json"
    assert main(["run", "block", "--preset", "paper", "--json", str(path)]) == 0
    r = json.loads(path.read_text())
    assert r["parameters"]["law"] == "conical" and r["n_slip"] > 0
    assert set(r["fitted"]) >= {"width", "height", "c_N"} and "reconstruct block" in r["fitted_to"]


def test_canonical_preset_is_the_earlier_reading():
    p = get_scene("block").resolve("canonical")
    assert (p["width"], p["height"], p["nx"], p["ny"], p["p_x_face"]) == (4.0, 3.5, 20, 10, "right")
    assert run_scene("block", "canonical")["n_slip"] == 0     # why it was replaced: no slip


def test_block_quick_study_ranks_the_paper_preset_first():
    rows, _ = rc.reconstruct_block(quick=True)
    best, paper = rows[0], rc.block_paper_reading()
    assert {k: best[k] for k in rc.BLOCK_KEYS} == {k: paper[k] for k in rc.BLOCK_KEYS}
    f = best["facts"]
    assert f["first_residual_1pct"] and f["conical_4_residuals"] and f["parabolic_7_residuals"]
    assert f["conical_slips"] and f["both_converge"]
    # Fig 8's remark is not reproduced: the highest pressures sit at the far corner, where
    # the nodes stick under both laws (the README says so)
    assert not f["fig8_remark"]
    text = rc.block_table(rows, 5)
    assert text.count("\n") >= 6 and "171.884" in text


@pytest.mark.skipif(not SLOW, reason="full search: CONTACTFEM_SLOW=1")
def test_block_full_study_ranks_the_paper_preset_first():
    rows, geos = rc.reconstruct_block()
    assert len(geos) >= 10 and len(rows) > 400
    paper = rc.block_paper_reading()
    assert {k: rows[0][k] for k in rc.BLOCK_KEYS} == {k: paper[k] for k in rc.BLOCK_KEYS}
    # no block-shaped reading shows Fig 8's remark together with the conical slip of Table 1
    assert not any(r["facts"]["fig8_remark"] and r["facts"]["conical_4_residuals"] for r in rows)


# ---------------------------------------------------------------------------------------
# sloping impact: readings against Table 2
def test_sloping_quick_study():
    rows = rc.reconstruct_sloping_impact(quick=True)
    assert len(rows) == 3
    by = {r["integration"]: r for r in rows if r["rotary_inertia"]}
    # the two-point ring meets more of Table 2 than the midpoint ring: why the preset uses it
    assert by["2"]["n_facts"] > by["1"]["n_facts"] and by["2"]["distance"] < by["1"]["distance"]
    assert not any(all(r["facts"].values()) for r in rows)
    text = rc.sloping_table(rows)
    assert "paper" in text and "53.8" in text


@pytest.mark.skipif(not SLOW, reason="full search: CONTACTFEM_SLOW=1")
def test_sloping_full_study_no_reading_meets_table2():
    """The README's statement: no reading tried reaches all six numbers of Table 2; the best
    with the scan's c_N = 50 is the paper preset's (two-point integration)."""
    rows = rc.reconstruct_sloping_impact()
    assert len(rows) >= 40
    assert not any(all(r["facts"].values()) for r in rows)
    best50 = [r for r in rows if r["c_N"] == 50.0][0]
    assert best50["integration"] == "2" and best50["n_facts"] == 3


def test_cli_reconstruct(capsys, tmp_path):
    path = tmp_path / "r.json"
    assert main(["reconstruct", "sloping_impact", "--quick", "--top", "2", "--json", str(path)]) == 0
    out = capsys.readouterr().out
    assert "rank" in out and "paper" in out
    assert len(json.loads(path.read_text())) == 3
    assert main(["reconstruct", "cork"]) == 2
    assert "block|sloping_impact" in capsys.readouterr().err
