"""Every figure carries its data: NAME.json beside NAME.png (plots.data), and the committed
data is what the code computes today."""

import json

import numpy as np
import pytest

from contactfem.plots import data as D


def test_save_figure_writes_the_png_and_its_numbers(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 2])
    paths = D.save_figure(
        fig, tmp_path / "fig99_test.png", dict(v_final=np.float64(149.3), t=np.arange(3.0)), dict(mu=0.3)
    )
    assert paths == [str(tmp_path / "fig99_test.png"), str(tmp_path / "fig99_test.json")]
    d = json.loads((tmp_path / "fig99_test.json").read_text())
    assert d == dict(
        figure="fig99_test", code_version=D.code_version(), parameters=dict(mu=0.3), v_final=149.3, t=[0.0, 1.0, 2.0]
    )
    assert (tmp_path / "fig99_test.png").stat().st_size > 0
    with pytest.raises(ValueError, match="reserved key"):
        D.save_figure(None, tmp_path / "x.png", dict(parameters=1), {})


def test_code_version_is_the_version_and_a_hash_of_the_sources():
    from contactfem import __version__

    v = D.code_version()
    assert v.startswith(__version__ + "+src.") and len(D.source_hash()) == 10
    assert v == D.code_version()


def test_differences_find_a_changed_number_and_ignore_roundoff_and_version():
    a = dict(
        figure="f",
        code_version="0.1.0+src.aaaa",
        parameters=dict(mu=0.3),
        v_final=149.3,
        residuals=[171.88, 3.2, 3e-12],
        slip=[150.0, 1e-12],
        n_slip=2,
        label="sticks",
        x=None,
    )
    same = json.loads(json.dumps(a))
    same.update(
        code_version="0.1.0+src.bbbb", residuals=[171.88, 3.2, 6e-12], slip=[150.0, 1e-7], v_final=149.3 * (1 + 1e-10)
    )
    assert D.differences(a, same) == []
    assert D.differences(a, dict(a, v_final=149.2)) == ["v_final: 149.3 in the file, 149.2 from the run"]
    assert D.differences(a, dict(a, parameters=dict(mu=0.31))) == ["parameters.mu: 0.3 in the file, 0.31 from the run"]
    assert D.differences(a, dict(a, n_slip=3)) == ["n_slip: 2 in the file, 3 from the run"]
    assert D.differences(a, dict(a, residuals=[171.88, 3.2])) == ["residuals: 3 entries in the file, 2 from the run"]
    assert D.differences(a, dict(a, label="rebounds")) == ["label: 'sticks' in the file, 'rebounds' from the run"]
    assert D.differences(a, dict(a, slip=[150.0, 1e-4])) == ["slip[1]: 1e-12 in the file, 0.0001 from the run"]
    extra = dict(a, new=1)
    del extra["x"]
    assert D.differences(a, extra) == ["x: in the file, not from the run", "new: not in the file, from the run"]
    assert D.differences(a, dict(a, v_final=149.3 * (1 + 1e-7))) != []


# -- the committed figures' data against fresh runs ---------------------------------------------
# Each figure function is called again (paper preset, into a temporary folder) and the NAME.json
# it writes is compared with figures/NAME.json by plots.data.differences: every number to rtol
# 1e-8 (plots.data.RTOL: two decades above what another BLAS or summation order can move in a
# run, four below what a changed parameter or formula moves), keys, lengths, strings and bools
# exactly; the code version is reported, not compared. The session's $CONTACTFEM_CACHE is a fresh
# folder (tests/conftest.py): nothing comes from an earlier run; within the session the figures
# share runs (plots.cached_run) with test_cork, test_published_tables and test_rolling_ring.
#   FAST: in every run of the suite, seconds each on a quiet machine; the slowest is Figs 14-17's
#         paper cork run (shared with test_cork and test_published_tables).
#   SLOW: @pytest.mark.slow, in CI's full run (`python -m pytest -q`; `-m "not slow"` leaves them
#         out): the studies of many runs. Measured on the shared 2-core machine under a load of
#         about 12: fig09b (ten ring runs) 56 s, the discretisation study about 2 min, the cork's
#         sensitivity table (ten cork runs) about 6 min, the knife edge (nine press fits and eight
#         runs) about 5 min, the full exit-time study (38 cork runs) about 25 min.
from pathlib import Path  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
FIGURES = REPO / "figures"
FAST = (
    "bench_adaptive",
    "bench_coverage",
    "bench_cost",
    "bench_speed",
    "bench_tangents",
    "bench_work_precision",
    "fig01_true_contact_area",
    "fig02_force_vs_microdisplacement",
    "fig03_shear_vs_normal",
    "fig04_parabolic_slip_surface",
    "fig06_block_mesh_deformed",
    "fig07_block_conical_stresses",
    "fig08_block_parabolic_stresses",
    "fig08b_block_fig8_readings",
    "table1_block_newton_residuals",
    "fig09_rolling_ring",
    "fig10_sloping_impact_frictionless",
    "fig11a_sloping_impact_frictional",
    "fig11b_sloping_impact_viscoplastic",
    "table2_sloping_impact",
    "fig12_funnel_frictionless",
    "fig13_funnel_frictional",
    "fig14_cork_mesh",
    "fig15_cork_configurations",
    "fig16_cork_pressure",
    "fig17_cork_displacement",
    "verif_bar_impact",
    "verif_hertz_pressure",
    "verif_hertz_refinement",
    "verif_patch",
)
SLOW = (  # the longest first: with the tests spread over processes (CI's second pass), it starts at once
    "cork_exit_time",
    "table_cork_sensitivity",
    "table_reconstruct",
    "cork_knife_edge",
    "table_sloping_impact_discretisation",
    "fig09b_rolling_ring_convergence",
)
# the committed exit-time study is the full one (every case); the others are the default profiles
SLOW_ENV = {"cork_exit_time": "1"}


def registry():
    from contactfem.lab import reconstruct as _reconstruct  # noqa: F401  (registers the inverse study's table)
    from contactfem.lab.bench import figures as _bench  # noqa: F401  (registers the bench figures)
    from contactfem.plots import load_all

    return load_all()


def fresh_data(stem, folder, monkeypatch):
    """Draw figure ``stem`` again (paper preset) into ``folder``; its NAME.json as a dict."""
    if stem in SLOW_ENV:
        monkeypatch.setenv("CONTACTFEM_SLOW", SLOW_ENV[stem])
    else:
        monkeypatch.delenv("CONTACTFEM_SLOW", raising=False)
    monkeypatch.delenv("CONTACTFEM_BENCH", raising=False)
    registry()[stem][1](preset="paper", outdir=str(folder))
    return D.load(Path(folder) / f"{stem}.json")


def assert_same_data(stem, folder, monkeypatch):
    written = D.load(FIGURES / f"{stem}.json")
    fresh = fresh_data(stem, folder, monkeypatch)
    problems = D.differences(written, fresh)
    env = f"CONTACTFEM_SLOW={SLOW_ENV[stem]} " if stem in SLOW_ENV else ""
    assert not problems, (
        f"figures/{stem}.json (code {written['code_version']}) is not what the code computes today (code "
        f"{fresh['code_version']}), {len(problems)} difference(s); regenerate it with "
        f"`{env}contactfem figures --preset paper --only {stem}`:\n  " + "\n  ".join(problems[:20])
    )


def test_every_figure_has_committed_data_and_a_test():
    stems = set(registry()) - {"summary"}  # summary.md: tests/test_summary.py
    assert set(FAST) | set(SLOW) == stems and not set(FAST) & set(SLOW)
    missing = [s for s in sorted(stems) if not (FIGURES / f"{s}.json").exists()]
    assert not missing, f"no committed data for {missing}: `contactfem figures --preset paper`"
    for s in sorted(stems):
        d = D.load(FIGURES / f"{s}.json")
        assert d["figure"] == s and d["code_version"].startswith("0.") and isinstance(d["parameters"], dict)


@pytest.mark.slow
@pytest.mark.parametrize("stem", SLOW)
def test_committed_study_data_is_a_fresh_run(stem, tmp_path, monkeypatch):
    assert_same_data(stem, tmp_path, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("stem", FAST)
def test_committed_figure_data_is_a_fresh_run(stem, tmp_path, monkeypatch):
    assert_same_data(stem, tmp_path, monkeypatch)
