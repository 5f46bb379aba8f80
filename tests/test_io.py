"""Results tooling (contactfem.io): saved runs reload identically, ParaView series are
valid VTU + PVD, animations have one frame per snapshot, the progress bar reaches 100 %."""

import io
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from contactfem.io import (
    ProgressBar,
    Recorder,
    animate_outlines,
    chain,
    export_continuum,
    export_polyline,
    load_run,
    save_run,
)

RESULTS = {
    "wall_time_s": 1.5,
    "newton_iterations_total": np.int64(12),
    "name": "ring",
    "converged": True,
    "t": np.linspace(0.0, 1.0, 5),
    "state": np.array(["open", "stick", "slip"]),
    "nested": {"u": np.arange(6.0).reshape(3, 2), "ids": np.array([3, 1, 2]), "none": None},
    "residuals": [[1.0, 1e-3, 1e-9], [2.0, 1e-11]],
}


def check_same(a, b):
    assert set(a) == set(b)
    for k in a:
        if isinstance(a[k], dict):
            check_same(a[k], b[k])
        elif isinstance(a[k], np.ndarray):
            assert isinstance(b[k], np.ndarray) and b[k].dtype == a[k].dtype and b[k].shape == a[k].shape, k
            assert np.array_equal(a[k], b[k]), k
        elif isinstance(a[k], list):  # rectangular lists of numbers come back as arrays
            assert len(a[k]) == len(b[k]) and all(np.array_equal(x, y) for x, y in zip(a[k], b[k])), k
        else:
            assert a[k] == b[k], k


@pytest.mark.parametrize("suffix", [".json", ".npz"])
def test_save_load_roundtrip(tmp_path, suffix):
    path = save_run(RESULTS, tmp_path / "new_folder" / f"run{suffix}")
    check_same(RESULTS, load_run(path))


def test_nan_needs_npz(tmp_path):
    bad = {"x": np.array([1.0, np.nan])}
    with pytest.raises(ValueError, match="results.x contains NaN"):
        save_run(bad, tmp_path / "run.json")
    assert np.isnan(load_run(save_run(bad, tmp_path / "run.npz"))["x"][1])
    with pytest.raises(ValueError, match="path must end in .json or .npz"):
        save_run(RESULTS, tmp_path / "run.txt")


def test_load_cli_json(tmp_path):
    """The CLI writes arrays as plain lists: they come back as arrays; ragged lists stay lists."""
    p = tmp_path / "cli.json"
    p.write_text(
        json.dumps({"scene": "block", "t_N": [[-1.0, -2.0], [0.0, -3.0]], "residuals": [[1.0, 0.1], [1.0]], "ok": True})
    )
    r = load_run(p)
    assert isinstance(r["t_N"], np.ndarray) and r["t_N"].shape == (2, 2)
    assert isinstance(r["residuals"], list) and r["ok"] is True


def test_recorder():
    rec = Recorder(every=2)
    for k in range(5):
        rec(0.1 * k, np.full(3, k), np.zeros(3), None)
    assert np.allclose(rec.t, [0.0, 0.2, 0.4]) and rec.u.shape == (3, 3) and rec.u[2, 0] == 4
    with pytest.raises(ValueError, match="every"):
        Recorder(every=0)


def test_export_polyline(tmp_path):
    pytest.importorskip("meshio")
    import meshio

    th = np.linspace(0, 2 * np.pi, 9)[:-1]
    frames = [np.column_stack([np.cos(th) + 0.1 * k, np.sin(th)]) for k in range(4)]
    files = export_polyline(
        frames,
        np.arange(4) * 0.5,
        tmp_path / "ring.pvd",
        closed=True,
        point_data={"speed": [np.full(8, k) for k in range(4)]},
    )
    assert len(files) == 5 and files[-1].endswith(".pvd")
    ds = ET.parse(files[-1]).getroot().findall("./Collection/DataSet")
    assert [float(d.get("timestep")) for d in ds] == [0.0, 0.5, 1.0, 1.5]
    m = meshio.read(files[2])
    assert np.allclose(m.points[:, :2], frames[2]) and len(m.cells_dict["line"]) == 8
    assert np.allclose(m.point_data["speed"], 2)


def test_export_continuum(tmp_path):
    pytest.importorskip("meshio")
    import meshio
    from skfem import MeshQuad

    from contactfem.bodies.continuum import Continuum

    body = Continuum(MeshQuad.init_tensor(np.linspace(0, 2, 3), np.linspace(0, 1, 2)), E=100.0, nu=0.3, rho=1.0)
    u = np.zeros(body.ndof)
    u[body.xdofs[:, 0]] = 0.01 * body.X[:, 0]  # uniaxial stretch eps_xx = 0.01
    files = export_continuum(body, [0.0, 1.0], [0 * u, u], tmp_path / "block.pvd")
    m = meshio.read(files[1])
    assert np.allclose(m.points[:, 0], 1.01 * body.X[:, 0])
    lam, mu = body.lam, body.mu
    assert np.allclose(m.cell_data["sxx"][0], (lam + 2 * mu) * 0.01)
    with pytest.raises(ValueError, match="one time per snapshot"):
        export_continuum(body, [0.0], [u, u], tmp_path / "bad.pvd")


def test_animate_outlines(tmp_path):
    from PIL import Image

    frames = [[np.array([[0, 0], [1, 0.1 * k], [1, 1]]), np.array([[2, 0], [3, k * 0.2]])] for k in range(6)]
    path = animate_outlines(
        frames,
        tmp_path / "a.gif",
        times=np.arange(6.0),
        obstacles=[np.array([[-1, -0.1], [4, -0.1]])],
        closed=[True, False],
        fps=10,
    )
    with Image.open(path) as im:
        assert im.n_frames == 6
    with pytest.raises(ValueError, match="gif or .mp4"):
        animate_outlines(frames, tmp_path / "a.avi")


def test_progress_bar():
    out = io.StringIO()
    seen = []
    bar = ProgressBar(t0=0.0, t_end=2.0, label="ring", stream=out, interval=0.0)
    cb = chain(bar, None, lambda t, u, v, a: seen.append(t))
    for t in np.linspace(0.1, 2.0, 20):
        cb(t, None, None, None)
    bar.close()
    text = out.getvalue()
    assert text.endswith("\n") and "100%" in text.splitlines()[-1].split("\r")[-1] and len(seen) == 20
    steps = io.StringIO()
    with ProgressBar(total=4, stream=steps) as b:
        for _ in range(4):
            b.update()
    assert "step 4/4" in steps.getvalue()
    with pytest.raises(ValueError, match="exactly one of total"):
        ProgressBar()


@pytest.fixture
def clock(monkeypatch):
    """tqdm's clock, faked: a list whose one number is the time; no monitor thread."""
    import tqdm.std

    now = [0.0]
    monkeypatch.setattr(tqdm.std, "time", lambda: now[0])
    monkeypatch.setattr(tqdm.std.tqdm, "monitor_interval", 0)
    return now


def redraws(stream):
    return stream.getvalue().count("\r")


@pytest.mark.parametrize("by", ["time", "steps"])
def test_the_bar_moves_during_a_run(clock, by):
    """A run of 5 s (100 records, 0.05 s apart) redraws its bar about every interval (0.2 s), for a
    bar over [t0, t_end] (whose total is the fraction 1) as for one counting steps: at least 10
    redraws, not the first and the last only."""
    out = io.StringIO()
    bar = ProgressBar(t0=0.0, t_end=1.0, stream=out) if by == "time" else ProgressBar(total=100, stream=out)
    for k in range(1, 101):
        clock[0] += 0.05
        bar(k / 100) if by == "time" else bar.update()
    bar.close()
    assert redraws(out) >= 10
    assert redraws(out) <= 5.0 / 0.2 + 2  # by time: at most one redraw an interval, and the first and the last


def test_the_notebook_bar_moves_too(clock, monkeypatch):
    """In Jupyter the bar is tqdm's widget (tqdm.auto): redrawn as the text bar is."""
    pytest.importorskip("ipywidgets")
    from tqdm.notebook import tqdm as widget

    from contactfem.io import progress

    drawn = []

    class Widget(progress._Fields, widget):
        def display(self, *args, **kwargs):
            drawn.append(self.n)

    monkeypatch.setattr(progress, "_AutoBar", Widget)
    bar = ProgressBar(t0=0.0, t_end=1.0)
    for k in range(1, 101):
        clock[0] += 0.05
        bar(k / 100)
    bar.close()
    assert len(drawn) >= 10 and drawn[-1] == 1.0


def test_compare_runs_walks_every_number():
    """compare_runs: the largest relative difference over the numbers both results hold (an
    array scaled by its largest value), text compared for equality, what describes the run
    (wall time, parameters) left out, entries the first lacks listed."""
    from contactfem.io import compare_runs

    ref = {
        "a": [1.0, 2.0, 4.0],
        "b": {"c": 3.0, "s": ["stick", "slip"]},
        "wall_time_s": 1.0,
        "parameters": {"x": 1},
        "empty": [],
        "none": None,
    }
    same = {
        "a": np.array([1.0, 2.0, 4.0]),
        "b": {"c": 3.0, "s": ["stick", "slip"]},
        "wall_time_s": 9.0,
        "empty": np.zeros((0, 2)),
        "none": None,
    }
    d = compare_runs(same, ref)
    assert d["worst"] == 0.0 and d["compared"] == 4 and d["missing"] == []
    d = compare_runs(dict(same, a=np.array([1.0, 2.0, 4.0 + 4e-6])), ref)
    assert d["worst"] == pytest.approx(1e-6) and d["key"] == "a"
    assert compare_runs(dict(same, a=[1.0, 2.0]), ref)["worst"] == np.inf
    assert compare_runs(dict(same, b={"c": 3.0, "s": ["stick", "open"]}), ref)["key"] == "b.s[1]"
    assert compare_runs({"a": ref["a"]}, ref)["missing"] == ["b", "empty", "none"]
