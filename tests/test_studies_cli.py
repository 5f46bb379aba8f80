"""Sweeps, animations, progress and saved runs from the command line."""

import csv
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from contactfem.cli import main
from contactfem.io import load_run


def test_sweep_runs_a_grid_in_parallel_into_one_table(tmp_path):
    out = tmp_path / "sweep.csv"
    assert (
        main(
            [
                "sweep",
                "block",
                "--set",
                "law=coulomb,parabolic",
                "--set",
                "c_N=1e5,1e6",
                "--jobs",
                "2",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 4 and all(r["error"] == "" for r in rows)
    assert {r["param.law"] for r in rows} == {"coulomb", "parabolic"}
    assert all(float(r["newton_iterations_total"]) >= 1 for r in rows)


def test_sweep_validates_every_point_before_running(tmp_path, capsys):
    assert (
        main(["sweep", "block", "--set", "law=coulomb", "--set", "mu=0.3,-1", "--out", str(tmp_path / "s.json")]) == 2
    )
    assert "parameter mu = -1 is out of range" in capsys.readouterr().err


def test_sweep_on_a_cluster_without_dask_is_one_clear_error(tmp_path, capsys, monkeypatch):
    """Without dask.distributed (made unimportable here, whether installed or not), --scheduler
    is refused in one line naming what to install."""
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    assert (
        main(
            [
                "sweep",
                "block",
                "--set",
                "law=coulomb",
                "--set",
                "mu=0.3",
                "--scheduler",
                "tcp://127.0.0.1:1",
                "--out",
                str(tmp_path / "s.csv"),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "dask[distributed]" in err[0]
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.slow
def test_sweep_on_a_dask_cluster_is_the_local_sweep(tmp_path):
    """With dask installed (the cluster extra, in [all]): the sweep runs on a scheduler (a local
    cluster started here, in-process workers) and its table equals the local sweep's."""
    distributed = pytest.importorskip("dask.distributed")
    grid = ["--set", "law=coulomb", "--set", "mu=0.3,0.4"]
    local, remote = tmp_path / "local.json", tmp_path / "remote.json"
    assert main(["sweep", "block", *grid, "--out", str(local)]) == 0
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster:
        assert main(["sweep", "block", *grid, "--scheduler", cluster.scheduler_address, "--out", str(remote)]) == 0
    a, b = json.loads(local.read_text()), json.loads(remote.read_text())
    drop = ("wall_time_s", "import_time_s")
    assert [{k: v for k, v in r.items() if k not in drop} for r in a] == [
        {k: v for k, v in r.items() if k not in drop} for r in b
    ]


@pytest.mark.slow
def test_run_animates_saves_and_reloads(tmp_path, capsys):
    gif, saved = tmp_path / "ring.gif", tmp_path / "ring.json"
    assert main(["run", "sloping_impact", "--gif", str(gif), "--save", str(saved), "--progress"]) == 0
    from PIL import Image

    assert Image.open(gif).n_frames >= 5
    assert "100%" in capsys.readouterr().err  # the progress bar finished
    res = load_run(saved)
    assert res["rebound_angle_deg"] == pytest.approx(json.loads(saved.read_text())["results"]["rebound_angle_deg"])
    assert isinstance(res["outlines"], np.ndarray) and len(res["outlines"]) >= 5  # arrays, not lists


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
    assert Path(default_outdir()) == fast  # the default preset is fast
    monkeypatch.setenv("CONTACTFEM_PRESET", "paper")
    assert Path(default_outdir()) == paper
    monkeypatch.setenv("CONTACTFEM_FIGURES", "/tmp/elsewhere")
    assert default_outdir("paper") == default_outdir("fast") == "/tmp/elsewhere"


# ---- sweeps of a law's fields, failed runs, Ctrl-C --------------------------------------

LAWS = Path(__file__).parent / "data" / "lying_laws.py"


@pytest.mark.slow
def test_sweep_of_a_law_files_fields_writes_a_row_per_value(tmp_path, capsys):
    out = tmp_path / "s.csv"
    assert (
        main(
            [
                "sweep",
                "rolling_ring",
                "--friction",
                f"{LAWS}:OwnFields",
                "--set",
                "law.mu=0.1,0.2,0.3",
                "--set",
                "t_end=0.2",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 3 and all(r["error"] == "" for r in rows)
    assert [r["param.law.mu"] for r in rows] == ["0.1", "0.2", "0.3"]
    assert len({r["x_end"] for r in rows}) == 3  # three laws, three results
    assert "t_end" not in rows[0] and rows[0]["param.t_end"] == "0.2"  # a swept parameter once, as param.


@pytest.mark.slow
def test_sweep_points_equal_runs_of_the_same_law(tmp_path, capsys):
    out = tmp_path / "s.json"
    assert (
        main(["sweep", "block", "--friction", f"{LAWS}:OwnFields", "--set", "law.mu=0.3,0.4", "--out", str(out)]) == 0
    )
    rows = json.loads(out.read_text())
    from contactfem.lab.lawfile import load_class
    from contactfem.scenes import run_scene

    own = load_class(f"{LAWS}:OwnFields")
    for row, mu in zip(rows, (0.3, 0.4)):
        res = run_scene("block", "fast", friction=own(mu=mu))
        assert (
            row["total_tangential"] == res["total_tangential"]
            and row["newton_iterations_total"] == res["newton_iterations_total"]
        )


def test_sweep_needs_values_and_fails_when_a_run_fails(tmp_path, capsys):
    assert main(["sweep", "block", "--out", str(tmp_path / "s.csv")]) == 2
    assert "sweep needs at least one --set" in capsys.readouterr().err
    out = tmp_path / "f.csv"
    assert main(["sweep", "block", "--set", "maxit=1,40", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["contactfem: sweep: 1 of 2 points failed (the table's error column says why)"]
    rows = list(csv.DictReader(out.open()))  # the table is written all the same
    assert [r["error"] != "" for r in rows] == [True, False]


def test_sweep_refuses_a_law_that_lies_before_any_run(tmp_path, capsys):
    assert (
        main(
            [
                "sweep",
                "block",
                "--friction",
                f"{LAWS}:NaNAbove",
                "--set",
                "law.p_bad=1e6,50",
                "--out",
                str(tmp_path / "s.csv"),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "NaNAbove.slip_bound returned NaN or inf: Y = nan" in err[0]
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.0, 0.3, 1.0, 2.5])
def test_ctrl_c_during_a_parallel_sweep_is_one_line(tmp_path, delay):
    """SIGINT to the sweep's process (and, as a terminal sends it, to its whole process
    group) while the workers start or run: one line, exit 130, no worker traceback; the
    table holds exactly the points the line says were done (none: no table)."""
    ready = tmp_path / "ready"
    env = dict(os.environ, CONTACTFEM_READY_FILE=str(ready))
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "contactfem",
            "sweep",
            "block",
            "--set",
            "c_N=1e5,2e5,3e5,4e5,5e5,6e5",
            "--set",
            "nx=40",
            "--jobs",
            "2",
            "--out",
            "s.csv",
        ],
        cwd=tmp_path,
        env=env,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )  # as from a terminal
    t0 = time.monotonic()
    while p.poll() is None and not ready.exists() and time.monotonic() - t0 < 120:
        time.sleep(0.002)
    time.sleep(delay)
    if p.poll() is None:
        os.killpg(p.pid, signal.SIGINT)  # as Ctrl-C in a terminal: the whole group
    out, err = p.communicate(timeout=300)
    assert "Traceback" not in err, err
    if p.returncode == 0:  # finished before the signal
        return
    assert p.returncode == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("contactfem: interrupted"), err
    if lines[0].endswith("nothing written"):
        assert not (tmp_path / "s.csv").exists()
    else:
        done, failed, left = map(int, re.search(r"\((\d+) done, (\d+) failed, (\d+) left", lines[0]).groups())
        rows = list(csv.DictReader((tmp_path / "s.csv").open()))
        assert len(rows) == done + failed and done + failed + left == 6 and failed == 0


# ---- what each point of a sweep is worth -------------------------------------------------


def merged(monkeypatch):
    """stdout and stderr into one stream, in the order they are written."""
    import io

    stream = io.StringIO()
    monkeypatch.setattr(sys, "stdout", stream)
    monkeypatch.setattr(sys, "stderr", stream)
    return stream


@pytest.mark.parametrize("strict", [False, True])
def test_a_flagged_point_is_one_warning_line_a_flag_in_the_table_and_with_strict_a_failure(
    tmp_path, monkeypatch, strict
):
    """The block at c_N = 10 sinks 235 times a tenth of an element into its foundation (flagged), at
    c_N = 1e6 not: one warning line names the flagged point, before the summary; the table flags it;
    --strict counts it as failed (exit code 1)."""
    out = tmp_path / "s.csv"
    stream = merged(monkeypatch)
    argv = ["sweep", "block", "--set", "c_N=10,1e6", "--out", str(out)] + (["--strict"] if strict else [])
    assert main(argv) == (1 if strict else 0)
    lines = stream.getvalue().splitlines()
    warned = [i for i, x in enumerate(lines) if x.startswith("contactfem: warning:")]
    assert len(warned) == 1 and lines[warned[0]].startswith(
        "contactfem: warning: accuracy: point c_N=10: penetration = "
    )
    summary = next(i for i, x in enumerate(lines) if x.startswith("2 points: "))
    assert warned[0] < summary and "AccuracyWarning" not in stream.getvalue()
    expected = "1 done, 1 failed" if strict else "2 done (1 flagged), 0 failed"
    assert lines[summary].startswith(f"2 points: {expected}, 0 left"), lines[summary]
    rows = {r["param.c_N"]: r for r in csv.DictReader(out.open())}
    assert rows["10"]["accuracy.flags"] == "penetration penetration_body" and rows["10"]["error"] == ""
    assert rows["1e6"]["accuracy.flags"] == "" and float(rows["1e6"]["accuracy.penetration"]) < 0.1
    assert rows["10"]["warnings"].startswith("penetration = ")
    assert re.fullmatch(
        r"contactfem: warning: accuracy: point c_N=10: penetration = [\d.e+]+, at most 0.1 wanted",
        lines[warned[0]].split(";")[0],
    )


def test_the_sweep_warns_once_per_flagged_point_from_python():
    from contactfem import AccuracyWarning
    from contactfem.lab.sweep import sweep

    with pytest.warns(AccuracyWarning) as caught:
        rows = sweep("block", {"c_N": ["10", "20", "1e6"]})
    said = [str(w.message) for w in caught if issubclass(w.category, AccuracyWarning)]
    assert [s.split(":")[1] for s in said] == [" point c_N=10", " point c_N=20"], said
    assert [r["accuracy.flags"] != "" for r in rows] == [True, True, False]


def test_error_bars_become_columns_when_the_runs_carry_them():
    """The uncertainty section of a run (per headline quantity: value, band, relative band, ...) is
    flattened into FIELD.NAME columns beside the accuracy indicators': a run's own section, and one
    written out."""
    from contactfem.lab.sweep import accuracy_columns
    from contactfem.scenes import run_scene

    res = run_scene("sloping_impact", "fast", {"n_steps": 40}, error_bars=True)
    entry = res["uncertainty"]["quantities"]["rebound_vy"]
    cols = accuracy_columns(res)
    assert cols["band.rebound_vy"] == entry["band"] and cols["relative_band.rebound_vy"] == entry["relative_band"]
    assert "value.rebound_vy" not in cols and "parts.rebound_vy" not in cols  # the value is its own column
    assert all(k.startswith("accuracy.") or k.split(".")[1] in res["uncertainty"]["quantities"] for k in cols)
    res = {
        "rebound_vy": 1.46,
        "accuracy": {
            "equilibrium": {"value": 1e-14, "ok": True, "threshold": 1e-6},
            "energy_gain": {"value": 0.4, "ok": False, "threshold": 0.01},
        },
        "uncertainty": {
            "tolerance": 0.05,
            "quantities": {
                "rebound_vy": {
                    "value": 1.46,
                    "band": 0.12,
                    "relative_band": 0.082,
                    "observed_order": 0.98,
                    "levels": 3,
                    "convergence": "monotone",
                    "parts": {"step": {"band": 0.12}},
                },
            },
        },
    }
    assert accuracy_columns(res) == {
        "accuracy.flags": "energy_gain",
        "accuracy.equilibrium": 1e-14,
        "accuracy.energy_gain": 0.4,
        "band.rebound_vy": 0.12,
        "relative_band.rebound_vy": 0.082,
        "observed_order.rebound_vy": 0.98,
        "levels.rebound_vy": 3,
        "convergence.rebound_vy": "monotone",
    }


def test_a_sweep_says_what_the_laws_check_found_before_the_runs(tmp_path, capsys):
    """A law whose dY/dp is off by 10 %: the sweep warns once, as `run` does, before the points run."""
    law = Path(__file__).parent / "data" / "wrong_derivative.py"
    out = tmp_path / "s.csv"
    assert (
        main(["sweep", "block", "--friction", f"{law}:WrongSlope", "--set", "law.mu=0.3,0.4", "--out", str(out)]) == 0
    )
    err = capsys.readouterr().err.splitlines()
    derivative = [x for x in err if "dY/dp does not match finite differences" in x]
    assert len(derivative) == 1 and derivative[0].startswith("contactfem: warning: friction law WrongSlope: ")


def test_run_strict_ends_with_the_line_that_says_why(capsys):
    assert main(["run", "block", "--set", "c_N=10", "--strict"]) == 1
    last = capsys.readouterr().err.strip().splitlines()[-1]
    said = "the run is flagged by 2 accuracy warnings above (penetration, penetration_body): exit code 1"
    assert last == f"contactfem: strict: {said}"


def test_run_strict_names_a_quantity_without_a_band_by_its_name_alone(capsys):
    # the bar's duration has no band in time (its levels oscillate): the last line names the indicator, not
    # the reason its line gives
    assert main(["run", "bar_impact", "--strict", "--error-bars"]) == 1  # (the suite runs without them by default)
    err = capsys.readouterr().err.strip().splitlines()
    assert any(
        line.startswith("contactfem: warning: accuracy: duration_band: no error band of duration") for line in err
    )
    names = re.fullmatch(
        r"contactfem: strict: the run is flagged by \d+ accuracy warnings? above \((.*)\): exit code 1", err[-1]
    )
    assert names and "duration_band" in names.group(1).split(", "), err[-1]
    assert all(re.fullmatch(r"\w+", name) for name in names.group(1).split(", ")), err[-1]


@pytest.mark.slow
def test_a_sweep_in_workers_prints_no_raw_python_warning(tmp_path):
    """The runs' warnings are raised in the worker processes: they come out as the sweep's own line,
    before the summary, never as Python's `file:line: AccuracyWarning` with a source line."""
    proc = subprocess.run(
        [sys.executable, "-m", "contactfem", "sweep", "block", "--set", "c_N=10,20,1e6", "--jobs", "2"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=300,
    )
    lines = proc.stdout.splitlines()
    assert proc.returncode == 0 and "AccuracyWarning" not in proc.stdout and "warnings.warn" not in proc.stdout
    warned = [i for i, x in enumerate(lines) if x.startswith("contactfem: warning: accuracy: point c_N=")]
    summary = next(i for i, x in enumerate(lines) if x.startswith("3 points: 3 done (2 flagged)"))
    assert len(warned) == 2 and max(warned) < summary, proc.stdout
