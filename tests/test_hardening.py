"""The command line's contract under bad input, failed solves and Ctrl-C; saved runs that
are not runs. Exit 2: one line naming the cause, found before any solve; exit 1: the
cause in one line and the residual history; exit 130: one line, no output written."""

import json
import os
import re
import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

import contactfem.lab.sweep  # noqa: F401  (imported before any test patches scenes.run_scene: it binds the real one)
from contactfem import cli, scenes
from contactfem.cli import main, plain_table
from contactfem.io import Outputs, load_run, save_run


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "contactfem", *args], capture_output=True, text=True, cwd=cwd)


@pytest.fixture
def no_solve(monkeypatch):
    """Make any scene run an error: what is checked must be checked before the solve."""

    def refuse(*a, **k):
        raise AssertionError("a scene was run although the input was knowable beforehand")

    monkeypatch.setattr(scenes, "run_scene", refuse)


BAD_BEFORE_THE_RUN = [
    (["run", "block", "--json", "/proc/nonexistent/dir/x.json"], "cannot write in /proc"),
    (["run", "block", "--json", "{tmp}"], "--json"),
    (["run", "block", "--save", "/proc/x.npz"], "cannot write in /proc"),
    (["run", "rolling_ring", "--gif", "{tmp}/y.png"], "must end in .gif or .mp4"),
    (["run", "block", "--save", "{tmp}/y.txt"], "must end in .json or .npz"),
    (["run", "block", "--gif", "{tmp}/b.gif"], "records no outlines"),
    (["run", "block", "--json", "{tmp}/a.json", "--save", "{tmp}/a.json"], "the same file as --json"),
    (["run", "block", "--set", "mu=0.3"], "parameter mu does not apply to block with law=conical"),
    (["run", "block", "--set", "law=coulomb", "--set", "n=0.3"], "parameter n does not apply"),
    (["run", "sloping_impact", "--set", "N0=2"], "does not apply to sloping_impact with variant=frictionless"),
    (["run", "funnel", "--set", "c_T=2"], "does not apply to funnel with variant=frictionless"),
    (["run", "rolling_ring", "--set", "n_radial=3"], "used only with kind=continuum"),
    (["run", "block", "--set", "law=coulomb", "--set", "mu=0.3", "--set", "mu=0.4"], "--set mu is given twice"),
    (["run", "block", "--set", "law=coulomb", "--set", "mu=0.1"], "no static equilibrium"),
    (["run", "block", "--set", "law=parabolic", "--set", "alpha=0.01", "--set", "beta=0.01"], "no static equilibrium"),
    (["run", "hertz", "--set", "n_el=2000"], "add --force"),
    (["run", "hertz", "--set", "n_el=3"], "allowed [4, 2000]"),
    (["run", "hertz", "--set", "P=1e6"], "a/R < 0.5"),
    (["run", "hertz", "--set", "n_el=128", "--linear-algebra", "dense"], "add --force"),  # K alone 8.9 GB
    (["run", "hertz", "--set", "n_el=256", "--linear-algebra", "banded"], "add --force"),  # its band 3.4 GB
    (["sweep", "hertz", "--set", "n_el=512", "--out", "{tmp}/s.csv"], "add --force"),
    (["sweep", "hertz", "--set", "n_el=300,310", "--jobs", "2", "--out", "{tmp}/s.csv"], "2 runs at once"),
    (["run", "rolling_ring", "--set", "dt=1e-9"], "steps"),
    (["run", "block", "--preset", "nonsense"], "nonsense"),
    (["run"], "required: scene"),
    (["figures", "--only", "nomatch"], "matches no figure"),
    (["run", "sloping_impact", "--set", "variant=viscoplastic", "--set", "kind=continuum"], "needs kind = 'beam'"),
]


@pytest.mark.parametrize("args,needle", BAD_BEFORE_THE_RUN)
def test_bad_input_is_one_line_before_any_solve(args, needle, tmp_path, capsys, no_solve):
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], err
    assert list(tmp_path.iterdir()) == []  # nothing written, no probe left


def test_bad_input_from_a_real_process_has_no_traceback():
    out = run_cli("run", "block", "--json", "/proc/nonexistent/dir/x.json")
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1 and "Traceback" not in out.stderr


def test_resource_guard_names_the_estimate(capsys, no_solve):
    assert main(["run", "hertz", "--set", "n_el=2000"]) == 2
    err = capsys.readouterr().err
    assert "4,000,000 elements" in err and "GB" in err and "limit" in err


def test_a_forced_solver_counts_its_own_matrices():
    """The estimate adds what a forced solver holds: a dense K and its LU copy (16 bytes an
    entry), a band of about 3 sqrt(n) each side (72 bytes per n^1.5); auto and sparse keep
    the sparse model (the System chooses dense or banded only where they are small)."""
    from contactfem.problem.resources import BAND_BYTES, DENSE_BYTES, estimate

    size = {"elements": 16384, "unknowns": 33282, "steps": 1}
    auto = estimate(size)["memory_bytes"]
    assert estimate(size, "sparse")["memory_bytes"] == auto
    assert estimate(size, "dense")["memory_bytes"] == pytest.approx(auto + DENSE_BYTES * 33282**2, rel=1e-9)
    assert estimate(size, "banded")["memory_bytes"] == pytest.approx(
        auto + BAND_BYTES * 33282**1.5, rel=1e-9
    )  # whole bytes


def test_large_meshes_announce_themselves(monkeypatch, capsys):
    """Above 1e5 elements a line says what is being built (here the run itself is skipped)."""
    monkeypatch.setattr(scenes, "run_scene", lambda *a, **k: {"scene": "hertz", "n_quads": 160000})
    assert main(["run", "hertz", "--set", "n_el=400"]) == 0
    err = capsys.readouterr().err
    assert "building the mesh" in err and "160,000 elements" in err


@pytest.mark.slow
def test_a_non_finite_residual_is_one_line_of_cause_and_the_history():
    out = run_cli("run", "block", "--set", "c_N=1e300")
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 1 and len(lines) == 2, out.stderr
    assert "non-finite residual at iteration 0" in lines[0] and lines[1].startswith("residual history:")
    assert "Warning" not in out.stderr and "Traceback" not in out.stderr


def test_a_failed_newton_prints_its_residuals_once(capsys):
    assert main(["run", "block", "--set", "law=coulomb", "--set", "maxit=1"]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 2 and "no convergence in 1 iterations" in lines[0]
    first = lines[1].split()[2]  # the first residual norm
    assert first not in lines[0]


def test_sweep_counts_its_failures(tmp_path, capsys):
    out = tmp_path / "sw.csv"
    assert main(["sweep", "block", "--set", "law=coulomb", "--set", "maxit=1,40", "--out", str(out)]) == 1
    text = capsys.readouterr().out
    assert "2 points: 1 done, 1 failed, 0 left" in text and "failed: law=coulomb, maxit=1: NewtonError" in text


def test_equations_on_a_terminal_are_plain_text():
    from contactfem.equations import markdown_table

    text = plain_table(markdown_table())
    assert "\\|" not in text and "`" not in text and "|---" not in text
    assert "(28)" in text


def test_show_columns_are_aligned_and_units_given(capsys):
    for name, sc in scenes.all_scenes().items():
        assert main(["show", name]) == 0
        lines = capsys.readouterr().out.splitlines()
        head = lines[1]
        cols = [head.index(c) for c in ("fast (run)", "unit", "allowed")]
        for line in lines[2 : 2 + len(sc.params)]:
            row = line.split("  -- ")[0]
            for c in cols[1:]:
                assert row[c - 2 : c] == "  " and row[c] != " ", (name, line)
        for key in ("E", "dt", "c_N", "R"):
            if key in {p.name for p in sc.params}:
                assert sc.param(key).unit, (name, key)


def test_time_steps_have_the_same_range_everywhere():
    ranges = {
        n: sc.param("dt").range_text() for n, sc in scenes.all_scenes().items() if "dt" in {p.name for p in sc.params}
    }
    assert set(ranges.values()) == {"(0, inf)"}, ranges


# ---- saved runs that are not runs ------------------------------------------------------


def corrupt_files(tmp_path):
    good = {"scene": "x", "t": np.linspace(0, 1, 50), "u": np.arange(12.0).reshape(4, 3), "name": "ring"}
    j, z = save_run(good, tmp_path / "good.json"), save_run(good, tmp_path / "good.npz")
    raw_j, raw_z = open(j, "rb").read(), open(z, "rb").read()
    files = {
        "truncated.json": raw_j[: len(raw_j) // 2],
        "truncated.npz": raw_z[: len(raw_z) // 2],
        "text.npz": b"this is a text file\n",
        "empty.json": b"",
        "list.json": b"[1, 2, 3]",
        "noresults.json": json.dumps({"format": "contactfem-run/1"}).encode(),
        "foreign.json": json.dumps({"hello": "world"}).encode(),
        "otherformat.json": json.dumps({"format": "other/2", "results": {}}).encode(),
        "badarray.json": json.dumps(
            {"format": "contactfem-run/1", "results": {"x": {"__ndarray__": [1, 2], "dtype": "O", "shape": [2]}}}
        ).encode(),
        "badshape.json": json.dumps(
            {"format": "contactfem-run/1", "results": {"x": {"__ndarray__": [1, 2], "dtype": "<f8", "shape": [5]}}}
        ).encode(),
    }
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    np.savez(tmp_path / "pickled.npz", __json__=np.array("{}"), a=np.array([{"x": 1}], dtype=object))
    np.savez(tmp_path / "nojson.npz", a=np.arange(3))
    with zipfile.ZipFile(tmp_path / "missing.npz", "w") as zf:
        zf.writestr("__json__.npy", b"garbage")
    return [tmp_path / n for n in files] + [tmp_path / "pickled.npz", tmp_path / "nojson.npz", tmp_path / "missing.npz"]


def test_load_run_refuses_what_is_not_a_run_in_one_clear_line(tmp_path):
    for path in corrupt_files(tmp_path):
        with pytest.raises(ValueError) as err:
            load_run(path)
        msg = str(err.value)
        assert "\n" not in msg and str(path.name) in msg and "allow_pickle" not in msg, (path.name, msg)


def test_a_saved_cli_run_comes_back_as_arrays(tmp_path):
    for suffix in (".npz", ".json"):
        path = tmp_path / f"run{suffix}"
        assert main(["run", "block", "--save", str(path)]) == 0
        r = load_run(path)
        assert isinstance(r["newton_residuals"], np.ndarray) and isinstance(r["contact"]["t_N"], np.ndarray)
        assert np.allclose(r["contact"]["t_N"] * 2, 2 * np.asarray(r["contact"]["t_N"]))
    with np.load(tmp_path / "run.npz") as z:  # stored natively, not as JSON lists
        assert len(z.files) > 5


def test_outputs_are_renamed_into_place_together(tmp_path):
    out = Outputs()
    out.add("--json", tmp_path / "a.json", (".json",))
    out.add("--save", tmp_path / "a.npz", (".npz",))
    with pytest.raises(RuntimeError):
        with out:
            out.temp("--json").write_text("{}")
            raise RuntimeError("the second output failed")
    assert list(tmp_path.iterdir()) == []  # the first one's temporary is gone too


# ---- Ctrl-C -----------------------------------------------------------------------------


def _sigint_as_in_a_terminal():
    """Run in the child before it starts: Ctrl-C back to its default. A test suite started in
    the background of a shell without job control ignores SIGINT, and a child keeps that."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


RING = ["run", "rolling_ring", "--preset", "paper", "--json", "a.json", "--save", "a.npz", "--gif", "a.gif"]
OUTS = ("a.json", "a.npz", "a.gif")


def _interrupt(folder, delay=None, when_part=False, timeout=300):
    """Start the ring run in `folder`, send SIGINT `delay` seconds after the process reports
    it is ready (it answers Ctrl-C: $CONTACTFEM_READY_FILE exists), or as soon as a temporary
    output file appears, and return (exit code, stderr, files present). Measured from the
    report, not from the start: on a busy machine the interpreter's own start-up (before any
    of contactfem runs, where no program can answer Ctrl-C its way) takes any time at all."""
    ready = folder.parent / f"{folder.name}.ready"
    env = dict(os.environ, CONTACTFEM_READY_FILE=str(ready))
    p = subprocess.Popen(
        [sys.executable, "-m", "contactfem", *RING],
        cwd=folder,
        text=True,
        env=env,
        preexec_fn=_sigint_as_in_a_terminal,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    t0 = time.monotonic()
    while p.poll() is None and not ready.exists() and time.monotonic() - t0 < timeout:
        time.sleep(0.002)
    t0 = time.monotonic()
    while p.poll() is None and time.monotonic() - t0 < timeout:
        if when_part and any(".part" in f.name for f in folder.iterdir()):
            break
        if delay is not None and time.monotonic() - t0 >= delay:
            break
        time.sleep(0.005)
    if p.poll() is None:
        p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=timeout)
    return p.returncode, err, sorted(f.name for f in folder.iterdir())


LIBRARY_TURNS_CTRL_C_INTO_IMPORT_ERROR = """
import os, signal, sys, time
import contactfem.cli as cli

class Parser:
    def parse_args(self, argv):
        return self
    def func(self, args):
        try:                                    # numpy, interrupted inside its import, re-raises as its own error
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except KeyboardInterrupt:
            raise ImportError("numpy._core.multiarray failed to import")

cli.build_parser = Parser
sys.argv = ["contactfem", "run", "x"]
sys.exit(cli.main())
"""


def test_ctrl_c_turned_into_another_error_by_a_library_is_still_the_interrupt():
    """A Ctrl-C landing in numpy's import surfaces as an ImportError; the command line
    recorded the interrupt, so the user sees the interrupt's one line and exit code 130,
    not an internal error."""
    p = subprocess.run(
        [sys.executable, "-c", LIBRARY_TURNS_CTRL_C_INTO_IMPORT_ERROR],
        preexec_fn=_sigint_as_in_a_terminal,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 130, p.stderr
    assert p.stderr.strip() == "contactfem: interrupted before the run started; nothing written", p.stderr


@pytest.fixture(scope="module")
def ring_run(tmp_path_factory):
    """The whole run, uninterrupted: its duration sets the moments to interrupt at."""
    folder = tmp_path_factory.mktemp("whole")
    t0 = time.monotonic()
    out = subprocess.run([sys.executable, "-m", "contactfem", *RING], cwd=folder, capture_output=True, text=True)
    return out, time.monotonic() - t0, folder


@pytest.mark.slow
def test_the_whole_ring_run_writes_all_three(ring_run):
    out, _, folder = ring_run
    assert out.returncode == 0, out.stderr
    assert sorted(f.name for f in folder.iterdir()) == sorted(OUTS)
    from PIL import Image

    gif = Image.open(folder / "a.gif")
    assert gif.n_frames >= 100  # rolling, frame by frame
    res = load_run(folder / "a.npz")
    anim = res["animation"]
    assert len(anim["marks"]) == gif.n_frames and anim["obstacles"][0].shape == (2, 2)  # a spoke, a floor


@pytest.mark.slow
@pytest.mark.parametrize("fraction", [0.15, 0.35, 0.55, 0.75, 0.9, "writing"])
def test_ctrl_c_leaves_none_or_all_of_the_outputs(ring_run, tmp_path, fraction):
    _, whole, _ = ring_run
    if fraction == "writing":
        rc, err, files = _interrupt(tmp_path, when_part=True)
    else:
        rc, err, files = _interrupt(tmp_path, delay=max(1.5, fraction * whole))
    assert files in ([], sorted(OUTS)), files  # none or all, no temporaries
    assert "Traceback" not in err
    if rc == 0:  # finished before the signal
        assert files == sorted(OUTS)
        return
    assert rc == 130, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    if files:
        assert lines[0] == "contactfem: interrupted after the outputs were written"
    else:
        assert lines[0].endswith("; nothing written"), lines[0]
        assert re.match(
            r"contactfem: interrupted (at t = [-\d.e+]+, step \d+ of \d+|while writing the outputs"
            r"|during the run|before the run started); nothing written",
            lines[0],
        ), lines[0]


@pytest.mark.parametrize("delay", [0.0, 0.01, 0.05, 0.1, 0.2, 0.3])
def test_ctrl_c_while_starting_up_is_one_line_too(tmp_path, delay):
    """Importing the package loads nothing heavy, so the command line handles Ctrl-C from
    its first moments (while scipy and scikit-fem load for the run) like any other: from
    the moment it reports ready, an interrupt is one line."""
    rc, err, files = _interrupt(tmp_path, delay=delay)
    assert files == [] and "Traceback" not in err, err
    assert rc == 130 and len(err.strip().splitlines()) == 1, err
    assert err.strip().endswith("; nothing written"), err


def test_sigterm_ends_a_run_with_143_and_leaves_no_outputs(tmp_path):
    """SIGTERM (a kill, a job's time limit) while the ring runs: exit code 143, no traceback,
    none or all of the outputs and no temporaries (the run unwinds as from an exception)."""
    ready = tmp_path.parent / f"{tmp_path.name}.ready"
    env = dict(os.environ, CONTACTFEM_READY_FILE=str(ready))
    p = subprocess.Popen(
        [sys.executable, "-m", "contactfem", *RING],
        cwd=tmp_path,
        text=True,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    t0 = time.monotonic()
    while p.poll() is None and not ready.exists() and time.monotonic() - t0 < 300:
        time.sleep(0.002)
    time.sleep(0.3)
    if p.poll() is None:
        p.terminate()
    out, err = p.communicate(timeout=300)
    assert "Traceback" not in err, err
    if p.returncode == 0:  # finished before the signal
        return
    assert p.returncode == 143, err
    # none or all (a signal after the outputs were renamed into place finds them written), no temporaries
    assert sorted(f.name for f in tmp_path.iterdir()) in ([], sorted(OUTS))
