"""The bench's enforcement study: the augmented Lagrangian meets a gap violation of 1e-8 at
each of three penalties; the penalty meets it at none of them (its gap falls like 1/c_N)."""

import pytest

from contactfem.lab.bench import STUDIES, write_markdown
from contactfem.lab.bench.enforcement import TARGET, enforcement_markdown, enforcement_study


@pytest.fixture(scope="module")
def study():
    return enforcement_study(quick=True)


@pytest.mark.slow
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


@pytest.mark.slow
def test_in_the_bench_and_its_markdown(study):
    assert STUDIES["enforcement"] is enforcement_study
    md = write_markdown({"machine": {}, "enforcement": study})
    assert "## Enforcement" in md and "\n".join(enforcement_markdown(study)) in md
    assert "nan" not in md.lower()


# -- penalty, Uzawa and the semi-smooth Newton method to a gap violation of 1e-10 ------------


@pytest.fixture(scope="module")
def ssn_study():
    from contactfem.lab.bench.semismooth import semismooth_study

    return semismooth_study(quick=True)


@pytest.mark.slow
def test_semismooth_newton_meets_the_target_in_fewer_solves_than_uzawa(ssn_study):
    from contactfem.lab.bench.semismooth import TARGET

    for scene, s in ssn_study["scenes"].items():
        rows = s["rows"]
        for key in ("uzawa", "semismooth", "semismooth_mortar"):
            assert rows[key]["ok"] and rows[key]["met"], (scene, key, rows[key])
        assert rows["semismooth"]["gap_violation"] < 1e-3 * TARGET  # exact, not a tolerance
        assert rows["semismooth"]["outer"] == 0 and rows["uzawa"]["outer"] >= 1
        assert rows["semismooth"]["solves"] < rows["uzawa"]["solves"], scene
        # Uzawa to 1e-10 gives the same tractions within c_N * length * 1e-10 (relative 1e-8 at most)
        assert rows["uzawa"]["traction_difference"] < 1e-6
        # the penalty is run at the c_N extrapolated to half the target (gap * c_N constant)
        assert rows["penalty"]["c_N"] > 1e3 * s["c_N_default"]


@pytest.mark.slow
def test_semismooth_study_in_the_bench_and_its_markdown(ssn_study):
    from contactfem.lab.bench.semismooth import semismooth_markdown, semismooth_study

    assert STUDIES["semismooth"] is semismooth_study
    md = write_markdown({"machine": {}, "semismooth": ssn_study})
    assert "## Penalty, Uzawa, semi-smooth Newton" in md and "\n".join(semismooth_markdown(ssn_study)) in md
    assert "nan" not in md.lower()
