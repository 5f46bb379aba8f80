"""figures/summary.md (written by `contactfem figures --preset paper`): the table of the paper's
examples, every "ours" cell from a run."""

from pathlib import Path

import pytest

from contactfem.plots import summary as S

REPO = Path(__file__).resolve().parents[1]


def test_summary_has_one_row_per_example():
    written = S.table_lines((REPO / "figures" / "summary.md").read_text())
    assert written[:2] == S.HEAD
    assert len(written) == len(S.HEAD) + len(S.ROWS)
    assert "--preset paper" in (REPO / "figures" / "summary.md").read_text()


def test_ours_is_computed_from_the_figures_data():
    # change the figures' data: the row changes with it (nothing typed)
    data = {
        "fig07_block_conical_stresses": dict(
            n_slip=7, equilibrium_error=3e-13, total_normal=-123.0, total_tangential=45.0
        ),
        "table1_block_newton_residuals": dict(conical=[171.37, 3.2, 4e-12], parabolic=[171.37] + [1.0] * 6),
    }
    row = S.row_table1("paper", data.get)
    assert "conical 3 (7 nodes slip), parabolic 7" in row[3] and "first 171.37" in row[3]
    assert "; 123 down, 45 along" in S.row_block_equilibrium("paper", data.get)[3]


def test_summary_is_the_committed_figures_data():
    """summary.md (and the front page's block of it, tests/test_readme.py) made again from the JSON files beside
    the committed figures: every "ours" cell is a number the figures carry (test_figure_data keeps those
    files equal to fresh runs)."""
    written = S.table_lines((REPO / "figures" / "summary.md").read_text())
    assert written == S.summary_table("paper", S.committed(REPO / "figures")), (
        "figures/summary.md is not what figures/*.json hold: regenerate with `contactfem figures --preset paper`"
    )


def test_describe_newton_reads_the_history():
    from contactfem.plots import describe_newton

    assert describe_newton([10.0, 1.0, 1e-3, 1e-9], True) == "converges in 3 linear solves"
    assert describe_newton([10.0, 9.0, 200.0, 5e3], False).startswith("diverges")
    assert describe_newton([10.0, 5.0, 4.0, 3.0], False).startswith("does not converge in 3 solves")


def test_block_titles_say_what_the_run_found():
    from contactfem.plots.block import slip_words

    base = dict(contact=dict(x=[0.0] * 17), n_stick=17, n_open=0)
    assert slip_words(dict(base, n_slip=0)).startswith("no node reaches the slip bound")
    assert slip_words(dict(base, n_slip=4, n_stick=13)).startswith("4 of 17 nodes slip")


def test_a_headline_number_is_printed_with_the_larger_of_its_band_and_its_rounding_spread():
    base = dict(rolled=True, x_roll=229.43, x_end=375.81, v_final=149.28)
    row = lambda data: S.row_rolling_ring("paper", lambda stem: data)[3]  # noqa: E731
    assert row(base) == "x_roll = 229.4 cm, x(2 s) = 375.8 cm, v = 149.3 cm/s"
    banded = dict(base, uncertainty=dict(v_final=dict(band=0.26), x_end=0.01))
    assert row(banded) == "x_roll = 229.4 cm, x(2 s) = 375.8 cm, v = 149.3 ± 0.3 cm/s"
