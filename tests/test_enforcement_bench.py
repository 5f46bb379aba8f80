"""The bench's enforcement study: the augmented Lagrangian meets a gap violation of 1e-8 at
each of three penalties; the penalty meets it at none of them (its gap falls like 1/c_N)."""
import pytest

from contactfem.lab.bench import STUDIES, write_markdown
from contactfem.lab.bench.enforcement import TARGET, enforcement_markdown, enforcement_study


@pytest.fixture(scope="module")
def study():
    return enforcement_study(quick=True)


def test_augmented_meets_the_target_at_every_penalty(study):
    for scene, s in study["scenes"].items():
        assert [r["c_N_factor"] for r in s["rows"]] == [0.01, 1.0, 100.0]
        for r in s["rows"]:
            assert r["augmented"]["ok"] and r["augmented"]["met"], (scene, r)
            assert r["augmented"]["gap_violation"] <= TARGET
            assert r["penalty"]["ok"] and not r["penalty"]["met"]
        # a softer penalty needs more outer iterations
        outer = [r["augmented"]["outer"] for r in s["rows"]]
        assert outer[0] >= outer[1] >= outer[2], (scene, outer)
        # the penalty's gap falls like 1/c_N: two decades per factor 100
        g = [r["penalty"]["gap_violation"] for r in s["rows"]]
        assert g[1] / g[2] == pytest.approx(100.0, rel=0.2) and g[0] > g[1]


def test_in_the_bench_and_its_markdown(study):
    assert STUDIES["enforcement"] is enforcement_study
    md = write_markdown({"machine": {}, "enforcement": study})
    assert "## Enforcement" in md and "\n".join(enforcement_markdown(study)) in md
    assert "nan" not in md.lower()
