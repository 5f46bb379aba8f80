"""The bench's scaling study: Hertz in contactfem and as a plain scikit-fem script, the same
discrete problem (the same p0 to rounding), and its BENCHMARKS.md table printing the study's
JSON. No timing is asserted (times depend on the machine and its load)."""

import re

import pytest

from contactfem.cli import BENCH_STUDIES
from contactfem.lab.bench import STUDIES, write_markdown
from contactfem.lab.bench.scaling import QUICK_SIZES, scaling_markdown, scaling_study


@pytest.fixture(scope="module")
def study():
    return scaling_study(quick=True)


@pytest.mark.slow
def test_the_plain_script_solves_the_same_problem(study):
    """Both solve one linear system (the same active set, found from the same initial guess).
    p0 = c_N (-g), g = Y + u_y + R: the sum alone rounds at eps R / |g| = 2.2e-16 * 10 / 3.7e-6
    = 6e-10 of p0, and two factorisations of K_ff (cond 3.9e5 at n_el = 16, 1.5e6 at 32) may
    differ by cond eps |u| / |g| = 3.3e-10 * 6e-3 / 3.7e-6 = 5e-7 of p0 at most: 1e-6."""
    assert [r["n_el"] for r in study["rows"]] == list(QUICK_SIZES)
    for r in study["rows"]:
        assert r["n_quads"] == r["n_el"] ** 2 and r["unknowns"] == 2 * (r["n_el"] + 1) ** 2
        assert r["p0_difference"] <= 1e-6, r
        assert r["contactfem_solves"] >= 1 and r["plain_solves"] >= 1
        assert r["ratio"] == r["contactfem_s"] / r["plain_s"]


@pytest.mark.slow
def test_the_table_prints_the_json(study):
    assert STUDIES["scaling"] is scaling_study and "scaling" in BENCH_STUDIES
    md = write_markdown({"machine": {}, "scaling": study})
    assert "\n".join(scaling_markdown(study)) in md and "nan" not in md.lower()
    lines = [line for line in md.splitlines() if re.match(r"\| \d+ \|", line)]
    assert len(lines) == len(study["rows"])
    for line, r in zip(lines, study["rows"]):
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert [int(c) for c in cells[:4]] == [r["n_el"], r["n_quads"], r["unknowns"], r["repeats"]]
        for cell, key in ((cells[4], "contactfem_s"), (cells[5], "plain_s")):  # 3 significant digits
            assert float(cell) == pytest.approx(r[key], rel=5e-3)
        assert float(cells[6]) == pytest.approx(r["ratio"], abs=0.005 + 1e-12)  # 2 decimals
        assert cells[7] == f"{r['contactfem_solves']}, {r['plain_solves']}"
        assert cells[8].startswith(r["linear_algebra"])
        assert float(cells[9]) == pytest.approx(r["error_p0"], rel=5e-3)
        assert float(cells[10]) == pytest.approx(r["p0_difference"], rel=0.05, abs=5e-17)
        for cell, key in ((cells[11], "process_contactfem_s"), (cells[12], "process_plain_s")):
            assert float(cell) == pytest.approx(r[key], rel=5e-3)
        assert float(cells[13]) == pytest.approx(r["process_ratio"], abs=0.005 + 1e-12)
    assert f"{study['import_floor_s']:.3g} s" in md


@pytest.mark.slow
def test_whole_processes_are_timed(study):
    """The whole-process columns are times of processes that ran (a failing process raises),
    each above half the import floor both stand on (half: the floor and the processes are single
    samples on a shared machine, where one sample may be a few tens of percent off), and their
    ratio is theirs."""
    for r in study["rows"]:
        assert r["process_contactfem_s"] > study["import_floor_s"] * 0.5 < r["process_plain_s"]
        assert r["process_ratio"] == r["process_contactfem_s"] / r["process_plain_s"]
