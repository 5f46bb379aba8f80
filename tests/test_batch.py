"""The batch executor: every task ends with an outcome, whatever its worker does, and a
stopped batch leaves no process behind."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from contextlib import closing
from pathlib import Path

import pytest

from contactfem.lab.batch import Outcome, run_batch


def gone(pid, within=5.0):
    """True once no process `pid` exists (or only a zombie: reaped by nobody yet)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < within:
        try:
            with open(f"/proc/{pid}/stat") as fh:
                if fh.read().rsplit(")", 1)[1].split()[0] == "Z":
                    return True
        except FileNotFoundError:
            return True
        except OSError:
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                return True
        time.sleep(0.05)
    return False


def square(x):
    return x * x


def act(how, arg=None):
    """What a task does: answer, raise, end its process, kill it, sleep, allocate."""
    if how == "pid":
        return os.getpid()
    if how == "raise":
        raise ValueError(f"bad  value\n{arg}")
    if how == "exit":
        os._exit(arg)
    if how == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    if how == "sleep":
        time.sleep(arg)
        return os.getpid()
    if how == "allocate":
        return len(bytearray(arg))
    if how == "once":  # dies on its first attempt only (a marker file says it tried)
        marker = Path(arg)
        if not marker.exists():
            marker.write_text("tried")
            os.kill(os.getpid(), signal.SIGKILL)
        return "second time"
    if how == "unpicklable":
        return lambda: None
    raise AssertionError(how)


def by_key(outcomes):
    return {o.key: o for o in outcomes}


def test_values_come_back_by_key_from_several_workers():
    out = list(run_batch(square, [(i, (i,)) for i in range(7)], jobs=3))
    assert sorted(o.key for o in out) == list(range(7))
    assert all(o.ok and o.value == o.key**2 and o.reason is None and o.attempts == 1 for o in out)
    assert all(isinstance(o, Outcome) for o in out)


@pytest.mark.slow
def test_outcomes_come_in_completion_order():
    out = list(run_batch(act, [("slow", ("sleep", 1.0)), ("fast", ("sleep", 0.0))], jobs=2))
    assert [o.key for o in out] == ["fast", "slow"]
    assert out[0].value != out[1].value  # two workers


def test_an_exception_is_reported_once_and_not_run_again():
    out = by_key(run_batch(act, [("bad", ("raise", "x")), ("good", ("pid",))], jobs=1))
    assert out["bad"] == Outcome("bad", False, None, "error: ValueError: bad value x", 1)
    assert out["good"].ok and out["good"].value != os.getpid()  # in a worker, not here


def test_a_task_that_ends_its_worker_is_retried_then_reported_and_the_others_complete():
    tasks = [("exit", ("exit", 7)), ("kill", ("kill",))] + [(i, ("pid",)) for i in range(4)]
    out = by_key(run_batch(act, tasks, jobs=2))
    assert out["exit"] == Outcome("exit", False, None, "worker exited with code 7", 2)
    assert out["kill"] == Outcome("kill", False, None, "worker died: signal 9", 2)
    assert all(out[i].ok and out[i].attempts == 1 for i in range(4))
    out = by_key(run_batch(act, [("kill", ("kill",))], retries=0))
    assert out["kill"].attempts == 1 and out["kill"].reason == "worker died: signal 9"
    out = by_key(run_batch(act, [("kill", ("kill",))], retries=3))
    assert out["kill"].attempts == 4


def test_a_task_whose_worker_died_once_succeeds_on_a_fresh_worker(tmp_path):
    out = list(run_batch(act, [("once", ("once", str(tmp_path / "m")))], jobs=1))
    assert out == [Outcome("once", True, "second time", None, 2)]


@pytest.mark.slow
def test_a_task_over_its_time_limit_is_stopped_and_not_retried():
    t0 = time.monotonic()
    out = by_key(run_batch(act, [("hang", ("sleep", 60)), ("quick", ("sleep", 0.1))], jobs=2, timeout=1.5))
    assert time.monotonic() - t0 < 20
    assert out["hang"] == Outcome("hang", False, None, "time limit 1.5 s", 1)
    assert out["quick"].ok


def test_the_memory_limit_turns_a_large_allocation_into_an_error():
    pytest.importorskip("resource")
    now = next(int(line.split()[1]) * 1024 for line in open("/proc/self/status") if line.startswith("VmSize"))
    out = by_key(
        run_batch(act, [("big", ("allocate", 4 << 30)), ("small", ("allocate", 1 << 20))], memory_limit=now + (1 << 30))
    )  # the workers start as copies of this one
    assert not out["big"].ok and out["big"].reason.startswith("error: MemoryError")
    assert out["small"].ok and out["small"].value == 1 << 20


def test_the_initializer_runs_in_each_worker_and_its_failure_is_every_tasks_reason():
    out = list(run_batch(os.environ.get, [(i, ("BATCH_TEST",)) for i in range(3)], jobs=2, initializer=_set_env))
    assert [o.value for o in out] == ["set"] * 3 and "BATCH_TEST" not in os.environ
    out = list(run_batch(square, [(1, (1,))], initializer=_fail))
    assert out[0].reason == "error: initializer: RuntimeError: no licence"


def _set_env():
    os.environ["BATCH_TEST"] = "set"


def _fail():
    raise RuntimeError("no licence")


def test_a_value_that_cannot_be_sent_back_is_an_error():
    out = list(run_batch(act, [("f", ("unpicklable",)), ("g", ("pid",))]))
    assert by_key(out)["f"].reason.startswith("error: the value cannot be sent back")
    assert by_key(out)["g"].ok


@pytest.mark.slow
def test_workers_ignore_ctrl_c():
    out = run_batch(act, [("a", ("pid",)), ("b", ("sleep", 1.0))], jobs=1)
    pid = next(out).value
    os.kill(pid, signal.SIGINT)  # the worker now sleeps in task b
    rest = list(out)
    assert rest[0].ok and rest[0].value == pid


def test_bad_arguments_are_refused_when_called():
    for kw in (dict(jobs=0), dict(retries=-1), dict(timeout=0), dict(memory_limit=-5), dict(jobs=1.5)):
        with pytest.raises(ValueError, match="run_batch"):
            run_batch(square, [], **kw)
    assert list(run_batch(square, [])) == []


def test_closing_the_batch_kills_every_worker_and_what_they_started(tmp_path):
    """A task that started a process of its own (a kernel, a solver) and sleeps: closing the
    generator ends the workers and those processes."""
    tasks = [("first", ("pid",))] + [(i, (str(tmp_path / f"{i}.pid"),)) for i in range(2)]
    gen = run_batch(_start_child_and_sleep, tasks, jobs=3)
    with closing(gen):
        next(gen)
        pids = _wait_for_pids(tmp_path, 2)
    assert all(gone(p) for p in pids), pids


def _start_child_and_sleep(path, *_):
    if path == "pid":
        return os.getpid()
    child = subprocess.Popen(["sleep", "60"])
    Path(path + ".tmp").write_text(f"{os.getpid()} {child.pid}")
    os.replace(path + ".tmp", path)
    time.sleep(60)


def _wait_for_pids(folder, n, within=20):
    t0 = time.monotonic()
    while time.monotonic() - t0 < within:
        files = list(Path(folder).glob("*.pid"))
        if len(files) == n:
            return [int(p) for f in files for p in f.read_text().split()]
        time.sleep(0.05)
    raise AssertionError(f"{n} tasks did not start within {within} s")


PARENT = textwrap.dedent("""
    import os, signal, sys, time
    sys.path.insert(0, {tests!r})
    from test_batch import _start_child_and_sleep
    from contactfem.lab.batch import run_batch

    def on_term(signum, frame):
        raise SystemExit(143)

    signal.signal(signal.SIGTERM, on_term)
    try:
        for o in run_batch(_start_child_and_sleep, [(i, ({folder!r} + f"/{{i}}.pid",)) for i in range(2)], jobs=2):
            pass
    except KeyboardInterrupt:
        sys.exit(130)
""")


def _sigint_as_in_a_terminal():
    """Run in the child before it starts: Ctrl-C back to its default. A test suite started in
    the background of a shell without job control ignores SIGINT, and a child keeps that."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.slow
@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGKILL, -9)])
def test_a_stopped_batch_process_leaves_no_worker(tmp_path, sig, code):
    """Ctrl-C and SIGTERM to the batch's process end it at once with every worker and the
    processes they started; killed outright, its workers end themselves."""
    script = PARENT.format(tests=str(Path(__file__).parent), folder=str(tmp_path))
    p = subprocess.Popen(
        [sys.executable, "-c", script],
        env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)),
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_sigint_as_in_a_terminal,
    )
    try:
        pids = _wait_for_pids(tmp_path, 2)
        t0 = time.monotonic()
        p.send_signal(sig)
        _, err = p.communicate(timeout=10)
        assert time.monotonic() - t0 < 5 and p.returncode == code, err
        assert "Traceback" not in err, err
        assert all(gone(pid) for pid in pids), pids
    finally:
        p.kill()
        p.wait()


@pytest.mark.slow
def test_a_task_whose_worker_died_runs_again_on_a_fresh_worker_not_an_idle_one(tmp_path):
    """Two workers; one task kills its worker on its first attempt while the other worker
    is idle: the second attempt runs in a process that ran nothing before."""
    tasks = [("quick", ("pid",)), ("once", ("once", str(tmp_path / "m")))]
    out = list(run_batch(_pid_and, tasks, jobs=2))
    first, again = by_key(out)["quick"], by_key(out)["once"]
    assert again.ok and again.attempts == 2 and again.value[1] == "second time"
    assert again.value[0] != first.value[0]


def _pid_and(how, arg=None):
    if how == "once":
        time.sleep(0.3)  # the other worker is idle by now
    return os.getpid(), act(how, arg)


IMPORT_ONLY = textwrap.dedent("""
    import atexit, multiprocessing.util
    held = []  # the exit hooks registered and not removed since here
    register, unregister = atexit.register, atexit.unregister
    atexit.register = lambda f, *a, **k: (held.append(f), register(f, *a, **k))[1]
    atexit.unregister = lambda f: ([held.remove(g) for g in list(held) if g == f], unregister(f))[1]
    from contactfem.lab.batch import run_batch
    imported = len(held)
    values = sorted(o.value for o in run_batch(abs, [(i, (-i,)) for i in range(3)], jobs=2))
    print(imported, len(held), values)
""")


def test_importing_the_batch_registers_no_exit_hook():
    """The hook that kills a batch's workers at the interpreter's exit is registered where a batch
    starts, and removed where it ends; importing the module registers nothing."""
    out = subprocess.run(
        [sys.executable, "-c", IMPORT_ONLY],
        env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)),
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.strip() == "0 0 [0, 1, 2]", out.stderr


LEFT_OPEN = textwrap.dedent("""
    import sys
    sys.path.insert(0, {tests!r})
    from pathlib import Path
    from test_batch import _start_child_and_sleep, _wait_for_pids
    from contactfem.lab.batch import run_batch

    tasks = [("first", ("pid",))] + [(i, ({folder!r} + f"/{{i}}.pid",)) for i in range(2)]
    batch = run_batch(_start_child_and_sleep, tasks, jobs=3)
    next(batch)  # the first task's answer; the other two workers sleep
    _wait_for_pids(Path({folder!r}), 2)
    sys.exit(0)  # with the batch open
""")


def test_an_interpreter_that_exits_inside_a_batch_leaves_no_worker(tmp_path):
    script = LEFT_OPEN.format(tests=str(Path(__file__).parent), folder=str(tmp_path))
    p = subprocess.run(
        [sys.executable, "-c", script],
        env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)),
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert p.returncode == 0, p.stderr
    pids = _wait_for_pids(tmp_path, 2)
    assert all(gone(pid) for pid in pids), pids
