"""The generated markdown tables a reader sees in figures/ hold what the code computes today.

Each table is made again here, from paper-preset runs (the figures' own functions and their
cache, ``plots.cached_run``: the runs are shared with test_cork, test_summary and the other
tests of this session), and compared with the committed file cell by cell:

    figures/summary.md                    every row (the front page's block of it: tests/test_readme.py)
    figures/table1_block_newton_residuals.md   the whole file
    figures/table2_sloping_impact.md      the whole file
    figures/table_cork_sensitivity.md     the row the quick profile runs ("as chosen", both pressures);
                                          the other rows are the slow study (`contactfem figures`)
    figures/cork_exit_time.md             the whole file from its committed JSON, and the JSON's
                                          quick-profile cases against runs (test_cork runs them)

A number agrees when it is printed the same, a number printed with its spread ("29.7 ± 0.1":
rounding moves it past its digits, plots.rounding.held) within twice that spread (plots.data.MARGIN);
a number below ROUNDOFF in both (a residual or an
equilibrium error at the round-off of loads of order 1e2-1e3, e.g. 3e-12) is not a result of
the run but of its rounding, and agrees when both are below it. A failure names the file, the
row and the column, both values, and the command that regenerates the file.
"""

import json
import re
from pathlib import Path

import pytest

from contactfem.plots.data import MARGIN

REPO = Path(__file__).resolve().parents[1]
FIGURES = REPO / "figures"
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
# round-off: the tables' smallest results are residual norms and equilibrium errors of 1e-12 to
# 1e-11 where the loads are 1e2-1e3 (1e-14 of them); Newton's own tolerance there is 1e-10 of the
# first residual (1.7e-8). Below 1e-9 a number is the rounding of the run, not its result.
ROUNDOFF = 1e-9

SUMMARY = "`contactfem figures --only summary --preset paper` (fills the front page's blocks too)"
HOW = {
    "summary.md": SUMMARY,
    "table1_block_newton_residuals.md": "`contactfem figures --only table1 --preset paper`",
    "table2_sloping_impact.md": "`contactfem figures --only table2 --preset paper`",
    "table_cork_sensitivity.md": "`contactfem figures --only table_cork_sensitivity --preset paper`",
    "cork_exit_time.md": "`CONTACTFEM_SLOW=1 contactfem figures --only cork_exit_time --preset paper`",
}


# a number printed with its spread, "29.7 ± 0.1" (plots.rounding.held: rounding moves it past its
# printed digits)
HELD = re.compile(rf"({NUMBER.pattern}) ± ({NUMBER.pattern})")


def _skeleton(text):
    """The text with every number replaced by '#' (a number with its spread by '#±'), the numbers
    and the (number, spread) pairs."""
    held = [(float(m.group(1)), float(m.group(2))) for m in HELD.finditer(text)]
    text = HELD.sub("#±", text)
    return NUMBER.sub("#", text), [m.group(0) for m in NUMBER.finditer(text)], held


def cell_difference(written, fresh):
    """None if the two cells agree (module docstring), else a short reason."""
    if written == fresh:
        return None
    (sw, nw, hw), (sf, nf, hf) = _skeleton(written), _skeleton(fresh)
    if sw != sf or len(nw) != len(nf):
        return "the text differs"
    for a, b in zip(nw, nf):
        if a != b and not (abs(float(a)) < ROUNDOFF and abs(float(b)) < ROUNDOFF):
            return f"{a} in the file, {b} from the run"
    for (a, wa), (b, wb) in zip(hw, hf):  # within twice the spread, as plots.data.differences holds it
        if abs(a - b) > MARGIN * max(wa, wb) * (1 + 1e-9):
            return f"{a:g} ± {wa:g} in the file, {b:g} ± {wb:g} from the run"
    return None


def _cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def assert_same_text(name, written, fresh):
    """Compare two versions of a generated file line by line; table lines cell by cell, each
    difference named by the row's first cell and the column's header."""
    w, f = written.rstrip("\n").splitlines(), fresh.rstrip("\n").splitlines()
    problems, header = [], None
    if len(w) != len(f):
        problems.append(f"{len(w)} lines in the file, {len(f)} from the run")
    for i, (a, b) in enumerate(zip(w, f), 1):
        if a.startswith("|") and b.startswith("|"):
            ca, cb = _cells(a), _cells(b)
            if set("".join(ca)) <= set("-:"):  # the separator line
                continue
            if header is None:
                header = ca
            if len(ca) != len(cb):
                problems.append(f"line {i}: {len(ca)} cells in the file, {len(cb)} from the run")
                continue
            for j, (x, y) in enumerate(zip(ca, cb)):
                why = cell_difference(x, y)
                if why:
                    column = header[j] if header and j < len(header) else f"column {j + 1}"
                    problems.append(f"row {ca[0]!r}, column {column!r}: {why}\n    file: {x}\n    run:  {y}")
        else:
            header = None if not a.startswith("|") else header
            why = cell_difference(a, b)
            if why:
                problems.append(f"line {i}: {why}\n    file: {a}\n    run:  {b}")
    assert not problems, (
        f"figures/{name} is not what the code computes today ({len(problems)} difference(s)); "
        f"regenerate it with {HOW[name]}:\n" + "\n".join(problems)
    )


def test_the_comparison_finds_a_changed_number_and_ignores_roundoff():
    assert cell_difference("exit 2.86 ms at 28.8 m/s", "exit 2.86 ms at 28.8 m/s") is None
    assert cell_difference("equilibrium to 3e-12 (800 down)", "equilibrium to 6e-12 (800 down)") is None
    assert cell_difference("exit 2.86 ms", "exit 2.71 ms") == "2.86 in the file, 2.71 from the run"
    assert cell_difference("x = 149.2 cm", "x = 149.3 cm") == "149.2 in the file, 149.3 from the run"
    assert cell_difference("3e-12 (800 down)", "3e-12 (801 down)") is not None
    assert cell_difference("stays in", "28.8") == "the text differs"
    assert cell_difference("v = 29.7 ± 0.1 m/s", "v = 29.5 ± 0.1 m/s") is None
    moved = cell_difference("v = 29.7 ± 0.1 m/s", "v = 29.4 ± 0.1 m/s")
    assert moved == "29.7 ± 0.1 in the file, 29.4 ± 0.1 from the run"
    assert cell_difference("v = 29.7 ± 0.1 m/s", "v = 29.7 m/s") == "the text differs"
    with pytest.raises(AssertionError, match=r"row 'Table 2', column 'ours': 1.46 in the file, 1.45 from the run"):
        assert_same_text(
            "summary.md",
            "| paper | ours |\n|---|---|\n| Table 2 | (2.00, 1.46) |\n",
            "| paper | ours |\n|---|---|\n| Table 2 | (2.00, 1.45) |\n",
        )


@pytest.mark.slow
def test_summary_md_is_what_the_paper_preset_runs_give():
    """Every row of figures/summary.md (and so of the front page's block of it) from paper-preset runs.
    The cork's row is the slowest part: its paper run and the two refined exit cases are
    shared with test_cork (plots.cached_run, plots.cork.cached_exit_case)."""
    from contactfem.plots import summary as S

    written = "\n".join(S.table_lines((FIGURES / "summary.md").read_text()))
    assert_same_text("summary.md", written, "\n".join(S.summary_table("paper")))


def test_table1_md_is_what_the_block_runs_give():
    from contactfem.plots.block import residual_histories, table1_markdown

    assert_same_text(
        "table1_block_newton_residuals.md",
        (FIGURES / "table1_block_newton_residuals.md").read_text(),
        table1_markdown(residual_histories("paper")),
    )


@pytest.mark.slow
def test_table2_md_is_what_the_ring_runs_give():
    from contactfem.plots.sloping_impact import table2_markdown

    assert_same_text(
        "table2_sloping_impact.md", (FIGURES / "table2_sloping_impact.md").read_text(), table2_markdown("paper")
    )


@pytest.mark.slow
def test_cork_sensitivity_md_as_chosen_row_is_the_run():
    """The quick profile of the sensitivity table: its "as chosen" row (the paper run at
    p0 = 0.8 MPa, shared, and one more run at 0.9 MPa). The other rows change one
    reconstructed datum each (eight more runs, minutes): `contactfem figures` makes them."""
    from contactfem.plots import cork as F

    written = (FIGURES / "table_cork_sensitivity.md").read_text()
    assert "Preset: paper." in written
    rows = F.sensitivity_rows("paper", cases=F.SENSITIVITY[:1], jobs=1)
    fresh = F.sensitivity_markdown(rows, "paper").splitlines()
    table = [ln for ln in written.splitlines() if ln.startswith("|")]
    assert_same_text("table_cork_sensitivity.md", "\n".join(table[:3]), "\n".join(fresh[:3]))
    assert [_cells(ln)[0] for ln in table[2:]] == [label for label, _ in F.SENSITIVITY]


@pytest.mark.slow
def test_cork_exit_time_md_is_its_json_and_the_quick_cases_are_the_runs():
    """figures/cork_exit_time.md is written from figures/cork_exit_time.json (the full study,
    CONTACTFEM_SLOW=1, 38 runs): the file equals the markdown made from the JSON. The quick
    profile's cases (seven runs, which test_cork's exit-time tests run in this session) are run
    again and must print as the JSON's rows do."""
    from contactfem.plots import cork as F

    d = json.loads((FIGURES / "cork_exit_time.json").read_text())
    assert d["slow"] and len(d["cases"]) == len(F.EXIT_CASES_SLOW)
    assert (FIGURES / "cork_exit_time.md").read_text() == F.exit_time_markdown(d), (
        "figures/cork_exit_time.md and figures/cork_exit_time.json disagree: regenerate both with "
        + HOW["cork_exit_time.md"]
    )
    quick = F.exit_time_data(F.EXIT_CASES_QUICK)
    fresh = dict(
        d,
        cases=[
            next(
                r
                for r in d["cases"]
                if (r["group"], r["label"], r["closing_step_press_fit"], r["closing_step_pop"]) == key
            )
            for key in [
                (r["group"], r["label"], r["closing_step_press_fit"], r["closing_step_pop"]) for r in quick["cases"]
            ]
        ],
    )
    written = [ln for ln in F.exit_time_markdown(fresh).splitlines() if ln.startswith("|")]
    ran = [ln for ln in F.exit_time_markdown(dict(d, cases=quick["cases"])).splitlines() if ln.startswith("|")]
    assert_same_text("cork_exit_time.md", "\n".join(written), "\n".join(ran))
