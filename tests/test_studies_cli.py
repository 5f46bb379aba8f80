"""Sweeps, animations, progress and saved runs from the command line."""

import csv
import json

import numpy as np
import pytest

from contactfem.cli import main
from contactfem.io import load_run


def test_sweep_runs_a_grid_in_parallel_into_one_table(tmp_path):
    out = tmp_path / "sweep.csv"
    assert main(["sweep", "block", "--set", "law=coulomb,parabolic", "--set", "c_N=1e5,1e6",
                 "--jobs", "2", "--out", str(out)]) == 0
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 4 and all(r["error"] == "" for r in rows)
    assert {r["param.law"] for r in rows} == {"coulomb", "parabolic"}
    assert all(float(r["newton_iterations_total"]) >= 1 for r in rows)


def test_sweep_validates_every_point_before_running(tmp_path, capsys):
    assert main(["sweep", "block", "--set", "law=coulomb", "--set", "mu=0.3,-1", "--out", str(tmp_path / "s.json")]) == 2
    assert "parameter mu = -1 is out of range" in capsys.readouterr().err


def test_sweep_on_a_cluster_needs_dask(tmp_path, capsys):
    pytest.importorskip("joblib")
    try:
        import dask.distributed  # noqa: F401
        pytest.skip("dask is installed here")
    except ImportError:
        pass
    assert main(["sweep", "block", "--set", "law=coulomb", "--set", "mu=0.3", "--scheduler", "tcp://127.0.0.1:1",
                 "--out", str(tmp_path / "s.csv")]) == 2
    assert "dask" in capsys.readouterr().err


def test_run_animates_saves_and_reloads(tmp_path, capsys):
    gif, saved = tmp_path / "ring.gif", tmp_path / "ring.json"
    assert main(["run", "sloping_impact", "--gif", str(gif), "--save", str(saved), "--progress"]) == 0
    from PIL import Image

    assert Image.open(gif).n_frames >= 5
    assert "100%" in capsys.readouterr().err                 # the progress bar finished
    res = load_run(saved)
    assert res["rebound_angle_deg"] == pytest.approx(json.loads(saved.read_text())["results"]["rebound_angle_deg"])
    assert isinstance(res["outlines"], np.ndarray) and len(res["outlines"]) >= 5     # arrays, not lists


def test_gif_of_a_scene_without_outlines_is_a_clear_error(tmp_path, capsys):
    assert main(["run", "block", "--gif", str(tmp_path / "b.gif")]) == 2
    assert "records no outlines" in capsys.readouterr().err


def test_a_quick_figure_run_never_writes_over_the_paper_figures(monkeypatch):
    """figures/ holds the paper preset's figures (kept with the code); other presets write
    into figures/<preset>/ unless a folder is given."""
    from pathlib import Path

    from contactfem.plots import default_outdir

    monkeypatch.delenv("CONTACTFEM_FIGURES", raising=False)
    monkeypatch.delenv("CONTACTFEM_PRESET", raising=False)
    paper, fast = Path(default_outdir("paper")), Path(default_outdir("fast"))
    assert paper.name == "figures" and fast == paper / "fast"
    assert Path(default_outdir()) == fast                      # the default preset is fast
    monkeypatch.setenv("CONTACTFEM_PRESET", "paper")
    assert Path(default_outdir()) == paper
    monkeypatch.setenv("CONTACTFEM_FIGURES", "/tmp/elsewhere")
    assert default_outdir("paper") == default_outdir("fast") == "/tmp/elsewhere"
