"""The coverage study (contactfem/lab/bench/coverage.py, `contactfem bench --only coverage`): what it runs,
how it judges a run, its quick slice, and BENCHMARKS.md against the committed bench.json."""

import json
from pathlib import Path

import pytest

from contactfem.lab.bench import coverage as cov
from contactfem.scenes import all_scenes, get_scene

REPO = Path(__file__).resolve().parents[1]


def test_the_study_covers_every_scene_its_presets_the_cork_and_every_method():
    cases = cov.cases()
    scenes = {cov.PHYSICS[name].scene for name, *_ in cases}
    assert scenes == set(all_scenes())
    assert len(cases) >= 150
    assert {preset for _, preset, _, _ in cases} == {"fast", "paper"}
    cork = [over for name, _, over, _ in cases if name == "cork"]
    assert {} in cork and any("dt_fine" in o for o in cork)  # its preset and its step varied
    settings = [over for _, _, over, _ in cases]
    for key, values in (
        ("enforcement", {"augmented", "lagrange"}),
        ("contact_integration", {"energy_consistent"}),
        ("integrator", {"central_difference"}),
        ("contact_discretization", {"mortar"}),
    ):
        assert values <= {o.get(key) for o in settings}, key
    assert any(o.get("delta") == 0.5 for o in settings) and any(o.get("accuracy") for o in settings)


def test_references_refine_step_and_mesh_together():
    """No reference is the preset's mesh: every ladder doubles the elements as it halves the step."""
    for name, ph in cov.PHYSICS.items():
        if ph.refine is None:
            continue
        a, b = ph.refine(0), ph.refine(1)
        meshes = [k for k in ("n_el", "ny", "n_r", "n_z") if k in a]
        assert meshes and all(b[k] == 2 * a[k] for k in meshes), name
        steps = [k for k in ("dt", "dt_fine") if k in a]
        assert all(b[k] == a[k] / 2 for k in steps), name


def test_errors_are_relative_to_the_quantity_unless_it_is_near_zero():
    """No scale inflation: the sloping impact's rebound is judged against itself (1.46, not |v0| = 2.83),
    and only a rebound below a tenth of the impact speed against that tenth."""
    scene = get_scene("sloping_impact")
    params = scene.resolve("fast")
    vy = next(q for q in scene.quantities if q.name == "rebound_vy")
    assert vy.reference(params, 1.46) == 1.46
    assert vy.reference(params, 0.01) == pytest.approx(0.1 * 8**0.5)
    funnel = get_scene("funnel")
    v = next(q for q in funnel.quantities if q.name == "v_c_final")
    assert v.reference(funnel.resolve("fast"), 3.36) == 3.36


class _Ladder:
    """A checkpoint that hands the reference ladder canned levels instead of running them."""

    def __init__(self, levels):
        self.levels = iter(levels)

    def get(self, key, compute):
        values = next(self.levels)
        quantities = {k: dict(value=v, exact=None) for k, v in values.items()}
        return dict(outcome="ran", values=quantities, separated=True, time_s=0.0)


def test_a_reference_judges_only_the_quantities_whose_levels_agree():
    """The funnel's y_c_min settles (last change 2e-4) while its v_c_final still moves (1 %): y_c_min is judged by
    the finest level, v_c_final by nothing; where every quantity agrees the ladder stops there, converged."""
    levels = [{"y_c_min": 18.0 + 0.1 / 2**k, "v_c_final": 3.0 * (1 + 0.01 * (-1) ** k)} for k in range(9)]
    ref = cov.reference("funnel frictionless", _Ladder(levels))
    assert not ref["converged"] and ref["values"] == {"y_c_min": levels[4]["y_c_min"]}
    assert len(ref["ladder"]) == cov.PHYSICS["funnel frictionless"].levels
    settled = [{"y_c_min": 18.0 + 0.1 / 10**k, "v_c_final": 3.0 + 0.1 / 10**k} for k in range(9)]
    ref = cov.reference("funnel frictionless", _Ladder(settled))
    assert ref["converged"] and set(ref["values"]) == {"y_c_min", "v_c_final"} and len(ref["ladder"]) < 5
    moving = [{"y_c_min": 18.0 * (1 + 0.01 * (-1) ** k), "v_c_final": 3.0 * (1 + 0.01 * (-1) ** k)} for k in range(9)]
    assert cov.reference("funnel frictionless", _Ladder(moving))["values"] is None


def _run(values, warnings=(), bands=None, outcome="ran"):
    quantities = {k: dict(value=v, exact=None) for k, v in values.items()}
    return dict(outcome=outcome, values=quantities, uncertainty=bands or {}, warnings=list(warnings))


def test_judge_covered_uncovered_and_silent_wrong():
    ref = dict(values={"max_displacement": 1.0}, change={"max_displacement": 1e-4})
    band = {"max_displacement": dict(band=0.05)}
    inside = cov.judge("block", "fast", {}, _run({"max_displacement": 1.04}, bands=band), ref)
    assert inside["outcome"] == "covered" and not inside["silent_wrong"]
    outside = cov.judge("block", "fast", {}, _run({"max_displacement": 1.08}, bands=band), ref)
    assert outside["outcome"] == "uncovered" and outside["silent_wrong"]  # 8 % off, no warning
    warned = cov.judge("block", "fast", {}, _run({"max_displacement": 1.08}, ["accuracy: x"], band), ref)
    assert warned["outcome"] == "uncovered" and not warned["silent_wrong"]
    none = cov.judge("block", "fast", {}, _run({"max_displacement": 1.08}, ["accuracy: x"], {}), ref)
    assert none["outcome"] == "no band"


@pytest.mark.slow
def test_the_quick_slice_runs_and_holds():
    res = cov.coverage_study(quick=True, checkpoint=False)
    assert res["runs"] == len(cov.QUICK) and res["counts"]["crashed"] == 0
    assert res["silent_wrong"] == 0
    for ref in res["references"].values():
        if ref is not None:
            assert ref["converged"] and ref["ladder"][-1]["change"]


def _bench():
    path = REPO / "bench.json"
    return json.loads(path.read_text()) if path.exists() else {}


def test_benchmarks_state_the_committed_study():
    """BENCHMARKS.md's section is the committed bench.json's, number for number (the front page's block of it:
    tests/test_readme.py); and the committed study shows what the issue asks of it."""
    from contactfem.lab.bench.error_bars import error_bars_markdown

    bench = _bench()
    if "coverage" not in bench:
        pytest.skip("bench.json has no coverage study")
    res = bench["coverage"]
    md = (REPO / "BENCHMARKS.md").read_text()
    assert "\n".join(cov.coverage_markdown(res)) in md
    if "error_bars" in bench:
        assert "\n".join(error_bars_markdown(bench["error_bars"])) in md
    assert res["runs"] >= 150 and not res["quick"]
    assert res["silent_wrong"] == 0
    assert res["coverage"] >= 0.95  # Xing and Stern's reliability target for a band's factor of safety
    assert all(r["scene"] in all_scenes() for r in res["rows"])
    for ref in res["references"].values():
        if ref is not None:
            assert ref["ladder"], "every reference's ladder is recorded"
