"""Sweeps under the faults of real machines: a worker killed (the out-of-memory killer's
SIGKILL), a law that ends its process, SIGTERM and Ctrl-C while a point is being run again,
the sweep itself killed and resumed, a Dask worker killed. Each sweep is a subprocess with a
time bound; the points are the block's fast preset (a fraction of a second each)."""

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # end-to-end: command lines and processes (the fast tier leaves them out)

# Coulomb with mu, and two faults: os._exit(7) above the pressure p_exit; and, for the run whose
# mu is `victim`, its process id in the file $FRAGILE_MARK and a pause of $FRAGILE_PAUSE seconds in
# every call of the run (a run slow enough to be killed from outside while it runs; not in the
# probe of the law file, which calls it with three values).
FRAGILE = """
import os
import time
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Fragile:
    c_T: float = 10.0
    mu: float = 0.5
    p_exit: float = 1e300
    victim: float = -1.0

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        if self.mu == self.victim and p.size > 3 and os.environ.get("FRAGILE_MARK"):
            mark = os.environ["FRAGILE_MARK"]
            with open(mark + ".tmp", "w") as fh:
                fh.write(str(os.getpid()))
            os.replace(mark + ".tmp", mark)
            time.sleep(float(os.environ.get("FRAGILE_PAUSE", "0")))
        if np.any(p > self.p_exit):
            os._exit(7)
        return self.mu * p, self.mu + 0 * p, 0 * p
"""

MUS = ["0.5", "0.55", "0.6", "0.65"]


@pytest.fixture
def law(tmp_path):
    path = tmp_path / "fragile.py"
    path.write_text(FRAGILE)
    return f"{path}:Fragile"


def sweep(tmp_path, *args, pause=None, out="s.csv"):
    """The sweep as a subprocess (own session: a signal to it reaches it alone)."""
    env = dict(os.environ, FRAGILE_MARK=str(tmp_path / "mark"))
    if pause is not None:
        env["FRAGILE_PAUSE"] = str(pause)
    return subprocess.Popen(
        [sys.executable, "-m", "contactfem", "sweep", "block", "--no-check", *args, "--out", out],
        cwd=tmp_path,
        env=env,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # a background suite ignores Ctrl-C
    )


def finish(p, within):
    try:
        out, err = p.communicate(timeout=within)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        raise AssertionError(f"the sweep did not end within {within} s")
    return out, err


def victim_pid(tmp_path, other_than=(), within=60):
    """The process id the victim's run wrote, once it is not one of `other_than`."""
    mark = tmp_path / "mark"
    t0 = time.monotonic()
    while time.monotonic() - t0 < within:
        if mark.exists():
            pid = int(mark.read_text())
            if pid not in other_than:
                return pid
        time.sleep(0.01)
    raise AssertionError("the victim's run did not start")


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def wait_for_rows(path, n, within=60):
    t0 = time.monotonic()
    while time.monotonic() - t0 < within:
        if path.exists() and len(rows(path)) >= n:
            return rows(path)
        time.sleep(0.05)
    raise AssertionError(f"the table did not reach {n} rows within {within} s")


def children(pid):
    """Process ids whose parent is pid (from /proc)."""
    found = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(d.name))
    return found


def gone(pid, within=5.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < within:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            return True
        if state == "Z":
            return True
        time.sleep(0.05)
    return False


def test_a_worker_killed_twice_mid_sweep_is_a_failed_row_and_every_other_point_completes(tmp_path, law):
    p = sweep(
        tmp_path,
        "--friction",
        law,
        "--set",
        f"law.mu={','.join(MUS)}",
        "--set",
        "law.victim=0.55",
        "--jobs",
        "2",
        pause=0.2,
    )
    first = victim_pid(tmp_path)
    os.kill(first, signal.SIGKILL)  # as the out-of-memory killer does
    second = victim_pid(tmp_path, other_than={first})  # the point again, on a fresh worker
    os.kill(second, signal.SIGKILL)
    out, err = finish(p, 60)
    assert p.returncode == 1, err
    table = {r["param.law.mu"]: r for r in rows(tmp_path / "s.csv")}
    assert sorted(table) == sorted(MUS)
    assert table["0.55"]["error"] == "worker died: signal 9"
    assert all(
        table[mu]["error"] == "" and float(table[mu]["newton_iterations_total"]) >= 1 for mu in MUS if mu != "0.55"
    )
    assert "4 points: 3 done, 1 failed, 0 left" in out
    assert "failed: law.mu=0.55" in out and "worker died: signal 9" in out
    assert err.strip().splitlines() == ["contactfem: sweep: 1 of 4 points failed (the table's error column says why)"]


def test_a_law_that_ends_its_process_fails_its_point_only(tmp_path, law):
    """The example of the sweep's last lines, run: the law ends its process (os._exit(7)) above a pressure
    of 800 that only p_y = 300 reaches (the runs' largest pressures: about 620, 710 and 910); the sweep
    prints its summary and the failed point, and exits 1."""
    argv = "sweep block --no-check --friction fragile.py:Fragile --set law.p_exit=800 --set p_y=100,200,300 --jobs 2"
    shown = [
        "3 points: 2 done, 1 failed, 0 left -> sweep.csv",
        "  failed: law.p_exit=800, p_y=300: worker exited with code 7",
    ]
    p = subprocess.run(
        [sys.executable, "-m", "contactfem", *argv.split()], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )
    assert p.returncode == 1, p.stderr
    assert p.stdout.splitlines() == shown
    table = {r["param.p_y"]: r for r in rows(tmp_path / "sweep.csv")}
    assert table["300"]["error"] == "worker exited with code 7"
    assert table["100"]["error"] == table["200"]["error"] == ""
    assert float(table["200"]["total_normal"]) == pytest.approx(-800, rel=1e-6)  # p_y x width


def test_a_law_that_ends_the_process_checking_it_is_one_line(tmp_path, law):
    """Without --no-check the law is checked over the scene's range (in a worker process):
    the sweep stops before the first run, in one line naming the law."""
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "contactfem",
            "sweep",
            "block",
            "--friction",
            law,
            "--set",
            "law.p_exit=800",
            "--set",
            "p_y=100,200,300",
            "--out",
            "s.csv",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr
    assert "--friction" in lines[0] and "ended the process" in lines[0] and "worker exited with code 7" in lines[0]
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.parametrize("sig,code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_sigterm_and_ctrl_c_while_a_dead_workers_point_runs_again(tmp_path, law, sig, code):
    """The victim's worker killed, its point running again (slowly) on a fresh worker, the
    other points done: the signal ends the sweep within seconds with the documented exit
    code, the table of the points done on disk, and no worker left."""
    p = sweep(
        tmp_path,
        "--friction",
        law,
        "--set",
        f"law.mu={','.join(MUS)}",
        "--set",
        "law.victim=0.5",
        "--jobs",
        "2",
        pause=30,
    )
    first = victim_pid(tmp_path)
    os.kill(first, signal.SIGKILL)
    second = victim_pid(tmp_path, other_than={first})
    done = wait_for_rows(tmp_path / "s.csv", 3)
    workers = children(p.pid)
    assert second in workers
    t0 = time.monotonic()
    os.kill(p.pid, sig)  # the sweep's process alone
    out, err = finish(p, 30)
    assert time.monotonic() - t0 < 10
    assert p.returncode == code, err
    assert "Traceback" not in err
    if sig == signal.SIGINT:
        assert err.strip().splitlines() == [
            "contactfem: interrupted during the sweep; s.csv holds the points done (3 done, 0 failed, 1 left: "
            "--resume runs the rest)"
        ]
    table = rows(tmp_path / "s.csv")
    assert table == done and sorted(r["param.law.mu"] for r in table) == MUS[1:]
    assert all(r["error"] == "" for r in table)
    assert all(gone(pid) for pid in workers), workers


def test_resume_after_the_sweep_was_killed_runs_the_missing_points_only(tmp_path, law):
    """SIGKILL to the sweep itself (no handler runs) after two of four points: its workers
    end themselves, the table holds the two points; --resume runs the other two, keeps the
    two rows as they were, and ends with the table an uninterrupted sweep writes."""
    grid = ["--friction", law, "--set", f"law.mu={','.join(MUS)}", "--set", "law.victim=0.6"]
    p = sweep(tmp_path, *grid, pause=30)
    pid = victim_pid(tmp_path)
    before = wait_for_rows(tmp_path / "s.csv", 2)
    os.kill(p.pid, signal.SIGKILL)
    finish(p, 30)
    assert gone(pid, within=5), "a worker outlived its sweep"
    assert [r["param.law.mu"] for r in rows(tmp_path / "s.csv")] == MUS[:2]
    (tmp_path / "mark").unlink()
    p = sweep(tmp_path, *grid, "--resume")
    out, err = finish(p, 60)
    assert p.returncode == 0, err
    assert "4 points: 4 done (2 kept from the table), 0 failed, 0 left" in out
    after = rows(tmp_path / "s.csv")
    assert after[:2] == before  # kept as they were, wall times included
    p = sweep(tmp_path, *grid, out="fresh.csv")
    finish(p, 60)
    fresh = rows(tmp_path / "fresh.csv")
    drop = ("wall_time_s",)
    assert [{k: v for k, v in r.items() if k not in drop} for r in after] == [
        {k: v for k, v in r.items() if k not in drop} for r in fresh
    ]
    assert len({r["code_version"] for r in after}) == 1 and after[0]["code_version"].startswith("0.")


def test_resume_runs_again_the_failed_points_and_those_of_other_code(tmp_path, law):
    grid = ["--friction", law, "--set", "law.mu=0.5,0.55"]
    finish(sweep(tmp_path, *grid), 60)
    table = rows(tmp_path / "s.csv")
    table[0]["error"] = "worker died: signal 9"
    table[1]["code_version"] = "0.0.1+000000000000"
    with open(tmp_path / "s.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(table[0]))
        w.writeheader()
        w.writerows(table)
    p = sweep(tmp_path, *grid, "--resume")
    out, err = finish(p, 60)
    assert p.returncode == 0 and "2 points: 2 done, 0 failed, 0 left" in out, err
    after = rows(tmp_path / "s.csv")
    assert [r["error"] for r in after] == ["", ""] and after[1]["code_version"] != "0.0.1+000000000000"


def test_an_unreachable_scheduler_is_one_line_at_once(tmp_path):
    pytest.importorskip("dask.distributed")
    t0 = time.monotonic()
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "contactfem",
            "sweep",
            "block",
            "--set",
            "p_y=100,200",
            "--scheduler",
            "tcp://127.0.0.1:1",
            "--out",
            "s.csv",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert time.monotonic() - t0 < 20
    lines = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(lines) == 1, p.stderr
    assert lines[0].startswith("contactfem: error: --scheduler tcp://127.0.0.1:1: ")
    assert not (tmp_path / "s.csv").exists()


@pytest.fixture
def cluster(tmp_path, monkeypatch):
    """Two Dask workers in processes of their own (restarted by their nannies when they die);
    a task whose worker dies twice is given up (KilledWorker)."""
    distributed = pytest.importorskip("dask.distributed")
    import dask

    monkeypatch.setenv("FRAGILE_MARK", str(tmp_path / "mark"))
    monkeypatch.setenv("FRAGILE_PAUSE", "0.2")
    with dask.config.set({"distributed.scheduler.allowed-failures": 1}):
        with distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=50
        ) as c:
            yield c


@pytest.mark.slow
def test_a_dask_worker_killed_mid_sweep_the_sweep_completes(tmp_path, law, cluster):
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "contactfem",
            "sweep",
            "block",
            "--no-check",
            "--friction",
            law,
            "--set",
            f"law.mu={','.join(MUS)}",
            "--set",
            "law.victim=0.55",
            "--scheduler",
            cluster.scheduler_address,
            "--out",
            "s.csv",
        ],
        cwd=tmp_path,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    first = victim_pid(tmp_path, within=120)
    os.kill(first, signal.SIGKILL)  # a real worker process, mid-run
    out, err = finish(p, 180)
    assert p.returncode == 0, err
    table = {r["param.law.mu"]: r for r in rows(tmp_path / "s.csv")}
    assert sorted(table) == sorted(MUS) and all(r["error"] == "" for r in table.values())
    assert int((tmp_path / "mark").read_text()) != first  # the point ran again elsewhere
    assert "4 points: 4 done, 0 failed, 0 left" in out


@pytest.mark.slow
def test_a_point_that_keeps_killing_its_dask_workers_is_a_failed_row(tmp_path, law, cluster):
    p = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "contactfem",
            "sweep",
            "block",
            "--no-check",
            "--friction",
            law,
            "--set",
            "law.p_exit=800",
            "--set",
            "p_y=100,200,300",
            "--scheduler",
            cluster.scheduler_address,
            "--out",
            "s.csv",
        ],
        cwd=tmp_path,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    out, err = finish(p, 180)
    assert p.returncode == 1, err
    table = {r["param.p_y"]: r for r in rows(tmp_path / "s.csv")}
    assert table["300"]["error"].startswith("worker died:") and "KilledWorker" in table["300"]["error"]
    assert table["100"]["error"] == table["200"]["error"] == ""


def test_a_table_interrupted_while_it_is_written_keeps_the_last_complete_one(tmp_path, monkeypatch):
    from contactfem.lab import sweep as sw

    table = sw.Table(tmp_path / "t.csv")
    table.start([{"a": "1"}, {"a": "2"}], dict(scene="block", preset="fast", laws="", code_version="v"))
    table.add(0, {"r": 1.0})
    before = (tmp_path / "t.csv").read_text()

    def interrupted(rows, path):
        Path(path).write_text("half a ta")
        raise KeyboardInterrupt

    monkeypatch.setattr(sw, "write_table", interrupted)
    with pytest.raises(KeyboardInterrupt):
        table.add(1, {"r": 2.0})
    assert (tmp_path / "t.csv").read_text() == before and os.listdir(tmp_path) == ["t.csv"]
    assert table.written == (1, 0, 1)


def test_a_run_over_the_time_limit_is_a_failed_row(tmp_path, law):
    p = sweep(
        tmp_path,
        "--friction",
        law,
        "--set",
        "law.mu=0.5,0.55",
        "--set",
        "law.victim=0.5",
        "--jobs",
        "2",
        "--time-limit",
        "8",
        pause=60,
    )
    out, err = finish(p, 60)
    assert p.returncode == 1, err
    table = {r["param.law.mu"]: r for r in rows(tmp_path / "s.csv")}
    assert table["0.5"]["error"] == "time limit 8 s" and table["0.55"]["error"] == ""
    assert "2 points: 1 done, 1 failed, 0 left" in out


@pytest.mark.parametrize(
    "argv,pattern",
    [
        (["--time-limit", "0"], "parameter time-limit = 0 is out of range"),
        (["--time-limit", "5", "--scheduler", "tcp://127.0.0.1:1"], "--time-limit applies to local workers"),
        (["--scheduler", "no scheduler"], "--scheduler no scheduler: "),
    ],
)
def test_bad_limits_and_addresses_are_one_line(tmp_path, capsys, argv, pattern):
    pytest.importorskip("dask.distributed")
    from contactfem.cli import main

    assert main(["sweep", "block", "--set", "p_y=100,200", *argv, "--out", str(tmp_path / "s.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and pattern in err[0], err
    assert not (tmp_path / "s.csv").exists()


def test_a_json_table_resumes_too(tmp_path):
    """The Table alone: a JSON file's rows of the same points and code are kept, a failed row
    and a row of other code are to run again (kept on disk until their new rows come), rows
    of other points stay."""
    import json

    from contactfem.lab.sweep import Table

    same = dict(scene="block", preset="fast", laws="", code_version="v1")
    earlier = [
        dict(same, error="", x=1, **{"param.p_y": "100"}),
        dict(same, error="worker died: signal 9", **{"param.p_y": "200"}),
        dict(same, error="", x=3, **{"param.p_y": "300", "code_version": "v0"}),
        dict(same, error="", x=9, **{"param.p_y": "900"}),
    ]
    path = tmp_path / "t.json"
    path.write_text(json.dumps(earlier))
    table = Table(path, resume=True)
    assert table.start([{"p_y": v} for v in ("100", "200", "300", "400")], same) == [1, 2, 3]
    table.add(3, {"x": 4})
    on_disk = json.loads(path.read_text())
    assert [r["param.p_y"] for r in on_disk] == ["100", "200", "300", "400", "900"]
    assert on_disk[:3] == earlier[:3] and on_disk[4] == earlier[3]
    assert table.counts() == (2, 0, 2) and table.kept == 1


def test_resume_from_a_file_that_is_not_a_table_is_one_line(tmp_path, capsys):
    from contactfem.cli import main

    (tmp_path / "s.json").write_text("{not json")
    assert main(["sweep", "block", "--set", "p_y=100", "--resume", "--out", str(tmp_path / "s.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot resume from it" in err[0] and "--out" in err[0]
    assert (tmp_path / "s.json").read_text() == "{not json"
