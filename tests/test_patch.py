"""The contact patch test: stacked blocks with non-matching meshes under a uniform
pressure; exact answer: the same pressure p all along the interface, sigma_yy = -p."""
import pytest

from contactfem.scenes import run_scene


@pytest.fixture(scope="module")
def results():
    return {n: run_scene("patch", "fast", {"passes": n}) for n in (1, 2)}


def test_load_is_transmitted(results):
    for r in results.values():
        assert r["load_carried"] == pytest.approx(r["load_applied"], rel=1e-6)


def test_one_pass_is_close_but_not_exact(results):
    # one pass, fast preset: interface pressure within 5 % of p (ours 2.6 %), but not exact
    r = results[1]
    assert 1e-3 < r["pressure_deviation_max"] < 0.05, r["pressure_deviation_max"]
    assert r["stress_deviation_max"] < 0.05


def test_two_pass_does_better(results):
    # two passes with halved weights: interface pressure within 1.5 % (ours 0.8 %)
    assert results[2]["pressure_deviation_max"] < 0.015
    assert results[2]["pressure_deviation_max"] < results[1]["pressure_deviation_max"]
    assert results[2]["stress_deviation_max"] < results[1]["stress_deviation_max"]


def test_two_pass_error_falls_with_penalty():
    dev = [run_scene("patch", "fast", {"passes": 2, "c_N": c})["pressure_deviation_max"] for c in (1e5, 1e7)]
    assert dev[1] < 0.2 * dev[0], dev


def test_coincident_nodes_refused():
    with pytest.raises(ValueError, match="nx_upper"):
        run_scene("patch", "fast", {"nx_lower": 2, "nx_upper": 4})
