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


@pytest.fixture(scope="module")
def stiffer(results):
    """The same runs with c_N ten times the preset's."""
    c_N = results[1]["parameters"]["c_N"]
    return {n: run_scene("patch", "fast", {"passes": n, "c_N": 10 * c_N}) for n in (1, 2)}


def test_one_pass_misses_the_patch_test_by_its_load_transfer(results, stiffer):
    """The scene's docstring: one-pass node-to-segment does not pass the patch test, and its error
    comes from the load transfer (eq 28), not from the penalty, so it stalls as c_N grows.
    Not exact: the deviation is far above the round-off the mortar discretisation reaches on the
    same patch (1e-3 against ~1e-12). Stalls: ten times c_N changes it by less than 10 % (a
    penalty error would fall tenfold, by 90 %)."""
    d1, d10 = results[1]["pressure_deviation_max"], stiffer[1]["pressure_deviation_max"]
    assert d1 > 1e-3, d1
    assert abs(d10 / d1 - 1) < 0.1, (d1, d10)


def test_two_passes_leave_a_penalty_error(results, stiffer):
    """Two passes with halved weights: better than one (interface pressure and stress), and the
    error left is mostly the penalty's: ten times c_N at least halves it (a pure penalty error
    would fall tenfold; one pass does not move, above). A better discretisation passes both."""
    assert results[2]["pressure_deviation_max"] < results[1]["pressure_deviation_max"]
    assert results[2]["stress_deviation_max"] < results[1]["stress_deviation_max"]
    d1, d10 = results[2]["pressure_deviation_max"], stiffer[2]["pressure_deviation_max"]
    assert d10 < 0.5 * d1, (d1, d10)


def test_docstring_numbers_are_the_run(results):
    """The deviations the scene's docstring quotes for the fast preset are the run's (to the
    printed digit)."""
    import re

    from contactfem.scenes import patch

    doc = " ".join(patch.__doc__.split())
    m = re.search(
        r"Fast preset \(4 \| 7 elements\): one pass ([0-9.]+) % interface pressure and ([0-9.]+) % "
        r"stress deviation, two passes ([0-9.]+) % and ([0-9.]+) %",
        doc,
    )
    ours = [100 * results[n][k] for n in (1, 2) for k in ("pressure_deviation_max", "stress_deviation_max")]
    assert [float(x) for x in m.groups()] == [round(x, 1) for x in ours], ours


def test_coincident_nodes_refused():
    with pytest.raises(ValueError, match="nx_upper"):
        run_scene("patch", "fast", {"nx_lower": 2, "nx_upper": 4})
