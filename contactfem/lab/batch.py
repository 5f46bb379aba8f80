"""A batch of tasks in worker processes that may die, hang or be told to stop.

    from contactfem.lab.batch import run_batch

    for o in run_batch(simulate, [(name, (name, size)) for name, size in cases], jobs=2, timeout=600):
        print(o.key, o.value if o.ok else o.reason)

Each task ``(key, args)`` runs as ``fn(*args)`` in a worker process; its ``Outcome`` comes
back as soon as it ends (completion order). A worker is a process of its own (forked where
the platform can, else spawned) that runs one task at a time, sent and answered over its own
pipe: the batch's process waits on the pipes and on the workers' sentinels together, so it
knows at once when a worker dies and which task it held.

- A worker that dies (killed by a signal: the out-of-memory killer's SIGKILL; or ended by its
  task: ``os._exit(7)``) is replaced by a fresh one that runs its task again, up to
  ``retries`` times; then the task is reported: "worker died: signal 9", "worker exited with
  code 7".
- A task that raises is reported at once, not run again: "error: ValueError: <message>".
- A task over ``timeout`` seconds has its worker killed and is reported: "time limit 600 s".
- ``memory_limit`` (bytes) caps each worker's address space (RLIMIT_AS, where the platform
  has it): a task that allocates more fails with MemoryError instead of taking the machine.
- Workers ignore Ctrl-C: the batch's process stops them. Closing the generator, or a
  KeyboardInterrupt or SystemExit (a SIGTERM handler's) in the batch's process, kills every
  worker at once together with the processes it started (each worker leads a process group
  of its own); a worker whose batch process is gone (killed) ends itself within a second.

Used by `contactfem sweep` and by the course's grading.
"""

import atexit
import multiprocessing
import multiprocessing.util  # noqa: F401  (its exit handler, which joins child processes, runs after ours)
import os
import signal
import threading
import time
from collections import deque
from dataclasses import dataclass
from functools import partial
from multiprocessing.connection import wait

_POLL_S = 1.0  # the longest the batch waits without looking at every worker


@dataclass(frozen=True)
class Outcome:
    """How one task ended: ``value`` is ``fn(*args)``'s return value when ``ok``, else None
    and ``reason`` says why; ``attempts`` counts the workers it ran on."""

    key: object
    ok: bool
    value: object
    reason: str | None
    attempts: int


def run_batch(fn, tasks, *, jobs=1, timeout=None, retries=1, memory_limit=None, initializer=None):
    """Run fn(*args) for each (key, args) in tasks in worker processes; yield Outcome as each
    task ends (completion order). A task whose worker dies is run again on a fresh worker up to
    `retries` times, then reported with the reason; a task over `timeout` seconds has its worker
    killed and is reported ("time limit N s"), not retried; memory_limit (bytes) is applied
    with resource.setrlimit(RLIMIT_AS) in the worker where the platform allows; initializer()
    runs once in each worker before its first task. Closing the generator, KeyboardInterrupt or
    SystemExit in the parent kill every worker at once (no orphans).

    The arguments are checked when called (ValueError); the work starts with the first
    ``next()``. fn (and initializer) must be picklable where workers are spawned rather than
    forked; args and the values returned are sent through pipes (picklable)."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"run_batch: jobs = {jobs!r} must be an integer >= 1")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise ValueError(f"run_batch: retries = {retries!r} must be an integer >= 0")
    if timeout is not None and not timeout > 0:
        raise ValueError(f"run_batch: timeout = {timeout!r} must be a number of seconds > 0 (or None)")
    if memory_limit is not None and not memory_limit > 0:
        raise ValueError(f"run_batch: memory_limit = {memory_limit!r} must be a number of bytes > 0 (or None)")
    todo = deque((key, tuple(args), 0) for key, args in tasks)  # (key, args, attempts so far)
    return _batch(fn, todo, jobs, timeout, retries, memory_limit, initializer)


def _batch(fn, todo, jobs, timeout, retries, memory_limit, initializer):
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    workers = []
    leftovers = partial(_kill_all, workers)  # what the batch holds if the interpreter exits inside it
    atexit.register(leftovers)  # (multiprocessing's exit handler, which joins them, runs after it)
    finished = False
    try:
        while todo or any(w.task for w in workers):
            for w in workers:  # idle workers first, then new ones
                if w.task is None and w.alive() and todo:
                    w.give(todo.popleft(), todo)
            while todo and len(workers) < jobs:
                _Worker(ctx, fn, initializer, memory_limit, workers).give(todo.popleft(), todo)
            busy = [w for w in workers if w.task is not None]
            wait_s = _POLL_S
            if timeout is not None and busy:
                wait_s = min(wait_s, max(0.0, min(w.started for w in busy) + timeout - time.monotonic()))
            wait([w.conn for w in busy] + [w.proc.sentinel for w in workers], wait_s)
            for w in list(workers):
                answer = w.answer()
                if answer is not None:  # the task ended in the worker
                    key, _, attempts = w.task
                    w.task = None
                    ok, value = answer
                    yield Outcome(key, ok, value if ok else None, None if ok else value, attempts + 1)
                if w.task is not None and timeout is not None and time.monotonic() - w.started >= timeout:
                    key, _, attempts = w.task
                    w.task = None
                    w.stop(workers)
                    yield Outcome(key, False, None, f"time limit {timeout:g} s", attempts + 1)
                    continue
                if w.alive():
                    continue
                w.stop(workers)  # dead: its task (if any) runs again
                if w.task is not None:
                    key, args, attempts = w.task
                    if attempts + 1 <= retries:  # on a fresh worker, not an idle one
                        _Worker(ctx, fn, initializer, memory_limit, workers).give((key, args, attempts + 1), todo)
                    else:
                        yield Outcome(key, False, None, _death(w.proc.exitcode), attempts + 1)
        finished = True
    finally:
        if finished:  # idle workers end on their own
            for w in workers:
                w.close()
        for w in workers:  # everything else at once
            w.kill()
        for w in list(workers):
            w.stop(workers)
        atexit.unregister(leftovers)


def _kill_all(workers):
    for w in list(workers):
        w.kill()


def _death(code):
    if code is not None and code < 0:
        return f"worker died: signal {-code}"
    return f"worker exited with code {code}"


def _describe(exc):
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class _Worker:
    """One worker process, its end of the pipe and the task it holds: (key, args, attempts)."""

    def __init__(self, ctx, fn, initializer, memory_limit, workers):
        self.conn, child_end = ctx.Pipe()
        self.proc = ctx.Process(
            target=_work, args=(child_end, fn, initializer, memory_limit, os.getpid()), name="contactfem-batch-worker"
        )
        self.task = None
        self.started = None
        with _signals_held():  # no Ctrl-C between the fork and the worker's own handlers,
            self.proc.start()  # and the worker is known before one can be raised here
            workers.append(self)
            try:
                os.setpgid(self.proc.pid, self.proc.pid)  # its own group (the worker sets it too)
            except (AttributeError, OSError):
                pass
        child_end.close()

    def give(self, task, todo):
        try:
            self.conn.send(task[1])
        except OSError:  # died before its task: the task waits for another worker
            todo.appendleft(task)
            return
        self.task, self.started = task, time.monotonic()

    def answer(self):
        """(ok, value or reason) if the worker has answered its task, else None."""
        if self.task is None:
            return None
        try:
            if not self.conn.poll():
                return None
            return self.conn.recv()
        except (EOFError, OSError):  # the worker died, with or before its answer
            return None
        except Exception as exc:  # an answer that cannot be unpickled here
            return False, f"error: the value cannot be read back: {_describe(exc)}"

    def alive(self):
        return self.proc.exitcode is None

    def close(self):
        try:
            self.conn.send(None)
        except OSError:
            pass
        self.proc.join(1.0)

    def kill(self):
        """SIGKILL to the worker and to the processes of its group."""
        if self.proc.exitcode is not None:
            return
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (AttributeError, OSError):
            pass
        try:
            self.proc.kill()
        except (AttributeError, OSError, ValueError):
            pass

    def stop(self, workers):
        """Kill (if alive), reap, and forget the worker."""
        self.kill()
        self.proc.join(5.0)
        self.conn.close()
        workers.remove(self)


class _signals_held:
    """SIGINT and SIGTERM blocked in this thread while inside (delivered on leaving)."""

    def __enter__(self):
        self.old = None
        if hasattr(signal, "pthread_sigmask"):
            self.old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})

    def __exit__(self, *exc):
        if self.old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, self.old)


def _work(conn, fn, initializer, memory_limit, parent):
    """A worker's life: its own signal handling and process group, then tasks until told to
    stop (None) or the batch's process is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        os.setpgid(0, 0)
    except (AttributeError, OSError):
        pass
    threading.Thread(target=_end_with, args=(parent,), daemon=True).start()
    if memory_limit is not None:
        _limit_memory(int(memory_limit))
    broken = None
    if initializer is not None:
        try:
            initializer()
        except Exception as exc:  # every task of this worker says so
            broken = f"error: initializer: {_describe(exc)}"
    while True:
        try:
            args = conn.recv()
        except (EOFError, OSError):
            return
        if args is None:
            return
        if broken:
            answer = (False, broken)
        else:
            try:
                answer = (True, fn(*args))
            except Exception as exc:
                answer = (False, f"error: {_describe(exc)}")
        try:
            conn.send(answer)
        except (EOFError, OSError):
            return
        except Exception as exc:  # a value that cannot be pickled
            conn.send((False, f"error: the value cannot be sent back: {_describe(exc)}"))


def _end_with(parent):
    """In a worker: end it (and its group) soon after the batch's process is gone."""
    while os.getppid() == parent:
        time.sleep(0.5)
    try:
        if os.getpgid(0) == os.getpid():
            os.killpg(0, signal.SIGKILL)
    except (AttributeError, OSError):
        pass
    os._exit(1)


def _limit_memory(nbytes):
    try:
        import resource  # POSIX only: absent on Windows, where no limit is set
    except ImportError:
        return
    try:
        _, hard = resource.getrlimit(resource.RLIMIT_AS)
        soft = nbytes if hard == resource.RLIM_INFINITY else min(nbytes, hard)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    except (AttributeError, ValueError, OSError):
        pass
