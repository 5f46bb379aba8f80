"""What rounding does to a result: the conditions that disturb a run (solver/rounding.py), the
spread a study records beside a figure's numbers and the comparison that holds a fresh run
within it (plots/rounding.py, plots/data.py)."""

import json

import pytest

from contactfem.plots import data as D
from contactfem.plots import describe_newton, diverged_at
from contactfem.plots import rounding as R
from contactfem.solver.rounding import current, rounding


def test_a_condition_reaches_every_system_and_march_and_leaves_no_trace():
    from contactfem.scenes import run_scene

    base = run_scene("block", "paper")
    with rounding(linear_algebra="sparse"):
        sparse = run_scene("block", "paper")
    with rounding(perturbation=1e-13):
        moved = run_scene("block", "paper")
        again = run_scene("block", "paper")
    after = run_scene("block", "paper")
    assert base["linear_algebra"] == "banded" and sparse["linear_algebra"] == "sparse"
    assert after["newton_residuals"] == base["newton_residuals"] and current().tag() == ""
    assert moved["newton_residuals"] == again["newton_residuals"]  # seeded: the same condition, the same run
    # the perturbation moves the initial state, by about 1e-13 of the block's size (4): the first
    # residual, K u0 - P, by c_N 4e-13 = 4e-8 at most, the others within the Newton tolerance
    first = abs(moved["newton_residuals"][0] - base["newton_residuals"][0])
    assert 0 < first < 1e-7 and len(moved["newton_residuals"]) == len(base["newton_residuals"])
    assert moved["newton_residuals"][1] == pytest.approx(base["newton_residuals"][1], rel=1e-8)


def test_a_bad_condition_names_its_parameter():
    with pytest.raises(ValueError, match=r"linear_algebra = 'lu' is not allowed: one of auto\|dense"):
        with rounding(linear_algebra="lu"):
            pass
    with pytest.raises(ValueError, match=r"perturbation = 0.01 is out of range: allowed \[0, 1e-06\]"):
        with rounding(perturbation=0.01):
            pass
    from contactfem.cli import main

    assert main(["figures", "--preset", "paper", "--perturb", "x", "--outdir", "/tmp/none"]) == 2
    assert main(["figures", "--rounding", "--outdir", "/tmp/none"]) == 2  # the fast preset


def test_a_diverging_history_keeps_no_digits_past_the_bound():
    h = [171.9, 8.4, 155.6, 6.0e4, 2.6e4, 1.2e19, 6.4e17]
    assert diverged_at(h) == 5 and diverged_at(h[:5]) is None
    assert describe_newton(h, False) == "diverges (past 1e+15 in 5 solves)"
    # another kernel: the same solves up to the bound, other digits past it (Table 1's symmetrised tangent)
    assert describe_newton(h[:5] + [3.3e18, 8.0e2], False) == describe_newton(h, False)


def figure(**over):
    return dict(dict(figure="f", code_version="0.1.0+src.a", parameters={}, v=29.90, n=839, x=[1.0, 2.0]), **over)


def test_the_spread_of_samples_is_what_moved_past_rtol():
    samples = [
        figure(runs=[dict(v=29.90, exits=True)], t=[0.0, 1.0, 2.0], text="exit 2.64 ms"),
        figure(runs=[dict(v=30.13, exits=True)], t=[0.0, 1.0], text="exit 2.61 ms", n=840),
        figure(runs=[dict(v=29.95, exits=False)], t=[0.0, 1.0, 2.0], text="exit 2.55 ms", x=[1.0, 2.0 + 1e-6]),
        figure(runs=[dict(v=29.90 * (1 + 1e-12), exits=True)], t=[0.0, 1.0, 2.0], text="exit 2.64 ms"),
    ]
    spread = R.spread_of(samples)
    assert spread == {
        "runs[0].v": {"lo": 29.90, "hi": 30.13},
        "runs[0].exits": {"values": [True, False]},
        "t": {"len": [2, 3]},
        "text": {"texts": ["exit 2.55 ms", "exit 2.61 ms", "exit 2.64 ms"]},
        "n": {"lo": 839, "hi": 840},
        "x[]": {"width": pytest.approx(1e-6)},
    }


def test_a_fresh_run_is_held_within_twice_the_recorded_spread():
    spread = {"v": {"lo": 29.90, "hi": 30.13}, "n": {"lo": 839, "hi": 840}, "x[]": {"width": 1e-6}}
    written = figure(rounding=dict(spread=spread), t=[0.0, 1.0], note="exit 2.64 ms")
    spread.update({"t": {"len": [2, 3]}, "note": {"texts": ["exit 2.55 ms", "exit 2.64 ms"]}})
    assert D.differences(written, figure(v=30.36, n=841, x=[1.0, 2.0 - 1.9e-6], t=[0.0], note="exit 2.6 ms")) == []
    problems = D.differences(written, figure(v=30.40, n=842, x=[1.0, 2.0 + 3e-6], t=[], note="sticks"))
    assert problems == [
        "v: 29.9 in the file, 30.4 from the run (rounding moves it 0.23)",
        "n: 839 in the file, 842 from the run (rounding moves it 1)",
        "x[1]: 2.0 in the file, 2.000003 from the run (rounding moves it 1e-06)",
        "t: 0 entries from the run, 2 to 3 under rounding",
        "note: 'exit 2.64 ms' in the file, 'sticks' from the run",
    ]
    # without a rounding section, RTOL as before
    assert D.differences(figure(), figure(v=29.90 * (1 + 1e-7))) != []


def test_the_study_records_the_spread_beside_the_numbers_and_a_redraw_keeps_it(tmp_path, monkeypatch):
    base = figure()
    (tmp_path / "f.json").write_text(D.dumps(base))
    drawn = {}
    for i, c in enumerate(R.CONDITIONS):
        path = tmp_path / f"{i}.json"
        path.write_text(json.dumps(figure(v=29.90 + 0.01 * i)))
        drawn[c] = path
    drawn["perturbation"] = None  # a condition whose run failed is named so
    spread = R.record("f", tmp_path, drawn)
    d = D.load(tmp_path / "f.json")
    assert spread == {"v": {"lo": 29.90, "hi": pytest.approx(29.92)}} and d["rounding"]["spread"] == spread
    assert d["rounding"]["conditions"]["perturbation"].endswith(": failed") and d["v"] == 29.90
    assert R.unmeasured(d) == ["perturbation"] and R.unmeasured(base) == list(R.CONDITIONS)  # the table says so
    assert R.spread("f", "v", tmp_path) == pytest.approx(0.02) and R.spread("f", "n", tmp_path) == 0.0
    D.write_data(tmp_path / "f.json", dict(v=29.91, n=839, x=[1.0, 2.0]), {})
    assert D.load(tmp_path / "f.json")["rounding"] == d["rounding"]


def test_the_figures_command_keeps_the_condition_the_environment_gives(tmp_path, monkeypatch):
    """The study's processes get their condition from the environment: `contactfem figures` without
    --linear-algebra or --perturb draws under it, and an option overrides it."""
    from contactfem import plots
    from contactfem.cli import main

    seen = []
    monkeypatch.setattr(plots, "make_all", lambda *a: seen.append(current()) or [])
    monkeypatch.setenv("CONTACTFEM_LINEAR_ALGEBRA", "sparse")
    monkeypatch.setenv("CONTACTFEM_PERTURB", "1e-13")
    out = ["--preset", "paper", "--only", "fig01", "--outdir", str(tmp_path)]
    assert main(["figures", *out]) in (0, None)
    assert main(["figures", *out, "--linear-algebra", "dense", "--perturb", "0"]) in (0, None)
    assert [(c.linear_algebra, c.perturbation) for c in seen] == [("sparse", 1e-13), ("dense", 0.0)]


@pytest.mark.slow
def test_the_study_draws_each_figure_in_a_process_under_each_condition(tmp_path, monkeypatch):
    """`contactfem figures --preset paper --rounding --only fig01` on a copy of the committed Fig 1 (the
    interface law: no run): one process a condition, the section recorded, the runs kept."""
    from contactfem.cli import main

    monkeypatch.setenv("CONTACTFEM_CACHE", str(tmp_path / "cache"))
    folder = tmp_path / "figures"
    folder.mkdir()
    base = D.load(FIGURES / "fig01_true_contact_area.json")
    base.pop("rounding", None)
    (folder / "fig01_true_contact_area.json").write_text(D.dumps(base))
    assert main(["figures", "--preset", "paper", "--rounding", "--only", "fig01", "--outdir", str(folder)]) == 0
    d = D.load(folder / "fig01_true_contact_area.json")
    assert d["rounding"]["spread"] == {} and list(d["rounding"]["conditions"]) == list(R.CONDITIONS)
    assert {k: v for k, v in d.items() if k != "rounding"} == base
    assert "| figure | number |" in (folder / "rounding.md").read_text()
    seen = []
    assert R.draw("fig01_true_contact_area", "kernel Prescott", base, log=seen.append).exists() and seen == []


# -- the printed tables hold under rounding -----------------------------------------------------
# Every printed table made again from the committed figures' data with each number that rounding
# moves at one end of its recorded range, then at the other: what a run under another rounding
# could have written. The tables must say the same (a number printed with its spread within twice
# it, as tests/test_published_tables.py compares them).
REPO = D.Path(__file__).resolve().parents[1]
FIGURES = REPO / "figures"


@pytest.mark.parametrize("side", ["lo", "hi"])
def test_the_readme_table_says_the_same_at_either_end_of_every_spread(side):
    from contactfem.plots import summary as S
    from test_published_tables import assert_same_text

    committed = S.committed(FIGURES)
    written = "\n".join(S.summary_table("paper", committed))
    assert_same_text(
        "summary.md", written, "\n".join(S.summary_table("paper", lambda s: R.extreme(committed(s), side)))
    )


@pytest.mark.parametrize("side", ["lo", "hi"])
def test_the_cork_tables_say_the_same_at_either_end_of_every_spread(side):
    from contactfem.plots import cork as F
    from test_published_tables import assert_same_text

    d = R.extreme(D.load(FIGURES / "cork_exit_time.json"), side)
    assert_same_text("cork_exit_time.md", (FIGURES / "cork_exit_time.md").read_text(), F.exit_time_markdown(d))
    fresh = F.sensitivity_reprinted(R.extreme(D.load(FIGURES / "table_cork_sensitivity.json"), side))
    assert_same_text("table_cork_sensitivity.md", (FIGURES / "table_cork_sensitivity.md").read_text(), fresh)


def test_the_printed_cork_tables_are_what_their_data_and_spreads_print(tmp_path):
    """What the study redraws once it has recorded the spreads (plots.summary.reprint), from a copy of the
    committed data: the committed tables, character for character (no run: the same numbers print the same)."""
    import shutil

    from contactfem.plots import summary as S

    stems = ["cork_exit_time", "table_cork_sensitivity"]
    for stem in stems:
        shutil.copy(FIGURES / f"{stem}.json", tmp_path)
    written = S.reprint(tmp_path, stems)
    assert sorted(D.Path(p).name for p in written if p.endswith(".md")) == sorted(f"{s}.md" for s in stems)
    for stem in stems:
        assert (tmp_path / f"{stem}.md").read_text() == (FIGURES / f"{stem}.md").read_text(), stem


def test_the_table_of_what_rounding_moves_says_how_each_number_is_printed():
    """rounding.md is the figures' rounding sections' table (the front page's block of it: tests/test_readme.py),
    and every number in it says how it is printed."""
    lines = R.table_lines(FIGURES)
    assert (FIGURES / "rounding.md").read_text() == R.markdown(FIGURES)
    unsaid = [ln for ln in lines[2:] if ln.split(" | ")[4] == "-"]
    assert not unsaid, "plots.rounding.PRINTED does not say how these numbers are printed:\n" + "\n".join(unsaid)


@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_table1_prints_our_residuals_to_the_digits_rounding_leaves(sign):
    """Each of our residuals moved by 1e-15 of its history's first, ten times what another kernel moves it
    (Prescott: 1.5e-14 of 172), prints Table 1 the same."""
    from contactfem.plots.block import table1_markdown

    hist = D.load(FIGURES / "table1_block_newton_residuals.json")
    moved = dict(hist)
    for law in ("conical", "parabolic", "coulomb"):
        moved[law] = [r + sign * 1e-15 * hist[law][0] for r in hist[law]]
    assert table1_markdown(moved) == table1_markdown(hist) == (FIGURES / "table1_block_newton_residuals.md").read_text()
