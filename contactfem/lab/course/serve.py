"""What runs inside a submission's sandbox: the notebook's code, and the answers the grader calls.

The grader (:mod:`.sandbox`) starts ``python -I -c "import contactfem_serve; contactfem_serve.main()"``
in the sandbox (this file is copied into the students' edition under that name), sends it the
notebook's code cells one by one, then asks for the student's answers and calls them with the
checks' arguments. Everything that crosses is plain data in JSON: numbers, strings, lists,
tuples and dicts of them, arrays as ``.npy`` bytes read without pickle, a handle (a number) for
an object that stays here, and two kinds of recipe for the library objects a check hands to an
answer, built here from the students' edition: an object of a class of the library from plain
data (a dataclass from its fields, a schedule from its steps), and a part of a scene's model. Nothing of the checks
is here; nothing from here runs in the grader.

Before the first request, :func:`main` sets the process up: when the grader is root, it takes
an unprivileged user id in a user namespace of its own (so that its limits bind); then its
limits on processes, open files, file size, CPU time and memory.

Needs nothing but Python and numpy: it is not part of the package the notebook sees.
"""

import base64
import ctypes
import importlib
import inspect
import io
import json
import os
import re
import resource
import signal
import sys
from multiprocessing.connection import Connection

import numpy as np

MAX_MESSAGE = 64 * 2**20  # bytes of one message either way (an array of some 6 million numbers)
MAX_DEPTH = 20
OTTER_LINE = re.compile(
    r"^\s*(import otter\b.*|grader\s*=\s*otter\.Notebook\(.*\)|grader\.check(_all)?\(.*\)|"
    r"grader\.export\(.*\))?\s*(#.*)?$"
)
MAGIC = re.compile(r"^(\s*)([%!].*)$", re.M)


# -- plain data, both ways ---------------------------------------------------------------------


def encode(v, other, depth=0):
    """The JSON form of a plain value; `other(v)` gives that of anything else."""
    if depth > MAX_DEPTH:
        return other(v)
    if v is None:
        return {"t": "none"}
    if v is Ellipsis:
        return {"t": "ellipsis"}
    if type(v) in (bool, int, float, str):
        return {"t": "py", "v": v}
    if type(v) in (tuple, list):
        return {"t": type(v).__name__, "v": [encode(x, other, depth + 1) for x in v]}
    if type(v) is dict and all(type(k) is str for k in v):
        return {"t": "dict", "v": {k: encode(x, other, depth + 1) for k, x in v.items()}}
    if type(v) is np.ndarray or isinstance(v, np.generic) and not isinstance(v, np.object_):
        if np.asarray(v).dtype.kind not in "biufc":
            return other(v)
        buf = io.BytesIO()
        np.save(buf, np.asarray(v), allow_pickle=False)
        return {"t": "nd" if type(v) is np.ndarray else "np", "v": base64.b64encode(buf.getvalue()).decode()}
    return other(v)


def decode(d, other, depth=0):
    """The value of a JSON form; `other(d)` decodes the kinds that are not plain data.
    ValueError for anything that is not one of these forms."""
    if type(d) is not dict or depth > MAX_DEPTH:
        raise ValueError("not a value")
    t = d.get("t")
    if t == "none":
        return None
    if t == "ellipsis":
        return Ellipsis
    if t == "py" and type(d.get("v")) in (bool, int, float, str):
        return d["v"]
    if t in ("tuple", "list") and type(d.get("v")) is list:
        return (tuple if t == "tuple" else list)(decode(x, other, depth + 1) for x in d["v"])
    if t == "dict" and type(d.get("v")) is dict:
        return {k: decode(x, other, depth + 1) for k, x in d["v"].items()}
    if t in ("nd", "np") and type(d.get("v")) is str:
        a = np.load(io.BytesIO(base64.b64decode(d["v"], validate=True)), allow_pickle=False)
        if a.dtype.kind not in "biufc":
            raise ValueError(f"an array of {a.dtype}")
        return a if t == "nd" else a[()]
    return other(d)


# -- the notebook and its answers --------------------------------------------------------------


class CallTimeout(BaseException):
    """A call of the student's code ran past its time limit (BaseException: an answer's
    `except Exception` does not swallow it)."""


class Sink(io.TextIOBase):
    """sys.stdout and sys.stderr of the submission: counts what is printed, keeps nothing."""

    def __init__(self):
        self.count = 0

    def writable(self):
        return True

    def write(self, s):
        self.count += len(s)
        return len(s)


class _Grader:
    """Stands for otter's `grader` in the notebook: its checks do not run here."""

    def check(self, *args, **kwargs):
        return None

    check_all = export = check


def _own_builtins():
    """A copy of the builtins for the notebook (its `import builtins` too): a notebook that
    replaces isinstance or AssertionError changes its own names, not those this server runs on."""
    import builtins
    import types

    mine = types.ModuleType("builtins")
    mine.__dict__.update(builtins.__dict__)
    real_import = builtins.__import__

    def imp(name, globals=None, locals=None, fromlist=(), level=0):
        if name == "builtins" and level == 0:
            return mine
        return real_import(name, globals, locals, fromlist, level)

    mine.__import__ = imp
    return mine.__dict__


class Notebook:
    """The notebook's namespace, the objects handed to the grader, and what it printed."""

    def __init__(self):
        self.env = {"__name__": "__main__", "grader": _Grader(), "__builtins__": _own_builtins()}
        self.refs = {}
        self.models = {}  # the scenes' models built for recipes: (scene, overrides) -> model
        self.sink = Sink()

    def ref(self, v):
        i = len(self.refs)
        self.refs[i] = v
        name = getattr(v, "__name__", None)
        out = {"t": "ref", "id": i, "type": type(v).__name__, "name": name if isinstance(name, str) else None}
        if callable(v):
            try:
                sig = inspect.signature(v)
                out["params"] = [[p.name, int(p.kind), p.default is not p.empty] for p in sig.parameters.values()]
            except (TypeError, ValueError):
                pass
        return out

    def argument(self, d):
        """A handle to an object of this process, or a library object built from its recipe."""
        t = d.get("t")
        if t == "handle" and type(d.get("id")) is int and d["id"] in self.refs:
            return self.refs[d["id"]]
        if t == "lib":
            module, _, name = str(d.get("cls", "")).partition(":")
            if not module.startswith("contactfem.") or not name.isidentifier():
                raise ValueError(f"not a class of the library: {d.get('cls')!r}")
            cls = getattr(importlib.import_module(module), name)
            fields = decode(d.get("set"), self.argument)
            if not isinstance(cls, type) or type(fields) is not dict:
                raise ValueError(f"not a class of the library: {d.get('cls')!r}")
            return cls(**fields)
        if t == "scene":
            overrides = decode(d.get("set"), self.argument)
            key = (str(d.get("scene")), json.dumps(d.get("set"), sort_keys=True))
            if key not in self.models:
                from contactfem.scenes import get_scene

                scene = get_scene(key[0])
                self.models[key] = scene.build(scene.resolve("fast", overrides))
            obj = self.models[key]
            for step in d.get("path", []):
                obj = obj[step] if isinstance(obj, dict) else getattr(obj, str(step))
            return obj
        raise ValueError(f"not an argument: {t!r}")

    def cell(self, source):
        lines = source.splitlines()
        if lines and all(OTTER_LINE.match(ln) for ln in lines):
            return {"ok": True, "skipped": True, "printed": self.sink.count}
        code = MAGIC.sub(r"\1pass  # \2", source)
        try:
            exec(compile(code, "<cell>", "exec"), self.env)
        except BaseException as err:  # noqa: BLE001  (sys.exit and KeyboardInterrupt are the cell's too)
            msg = " ".join(str(err).split())[:200]
            left_out = isinstance(err, NotImplementedError) and "is left out while your notebook is graded" in msg
            return {
                "ok": False,
                "error": f"{type(err).__name__}: {msg}" if msg else type(err).__name__,
                "left_out": left_out,
                "printed": self.sink.count,
            }
        return {"ok": True, "printed": self.sink.count}

    def get(self, name):
        if name not in self.env:
            return {"t": "missing"}
        return encode(self.env[name], self.ref)

    def getattr(self, i, name):
        try:
            return encode(getattr(self.refs[i], name), self.ref)
        except AttributeError:
            return {"t": "missing"}

    def call(self, i, args, kwargs, timeout):
        fun = self.refs[i]
        args, kwargs = decode(args, self.argument), decode(kwargs, self.argument)

        def stop(signum, frame):
            raise CallTimeout()

        old = signal.signal(signal.SIGALRM, stop)
        signal.setitimer(signal.ITIMER_REAL, float(timeout))
        try:
            with np.errstate(all="ignore"):
                out = fun(*args, **kwargs)
            return {"ok": encode(out, self.ref)}
        except CallTimeout:
            return {"timeout": True}
        except BaseException as err:  # noqa: BLE001
            return {"exc": type(err).__name__, "msg": " ".join(str(err).split())[:300]}
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)


def answer(notebook, req):
    """The reply to one request of the grader."""
    op = req.get("op")
    if op == "cell":
        return notebook.cell(str(req["source"]))
    if op == "get":
        return notebook.get(str(req["name"]))
    if op == "getattr":
        return notebook.getattr(int(req["id"]), str(req["name"]))
    if op == "call":
        return notebook.call(int(req["id"]), req["args"], req["kwargs"], req["timeout"])
    raise ValueError(f"unknown request {op!r}")


def serve(conn_in, conn_out):
    notebook = Notebook()
    sys.stdout = sys.stderr = notebook.sink
    while True:
        try:
            req = json.loads(conn_in.recv_bytes(MAX_MESSAGE))
        except EOFError:
            return
        try:
            reply = answer(notebook, req)
        except BaseException as err:  # noqa: BLE001  (a request that cannot be answered is a reply too)
            reply = {"exc": type(err).__name__, "msg": " ".join(str(err).split())[:300]}
        data = json.dumps(reply).encode()
        if len(data) > MAX_MESSAGE:
            data = json.dumps({"exc": "TooLarge", "msg": f"a reply of {len(data) / 2**20:.0f} MB"}).encode()
        conn_out.send_bytes(data)


# -- the process's setup -----------------------------------------------------------------------


def become(uid):
    """From root: the unprivileged `uid`, in a user namespace of its own (the kernel exempts
    root's processes from the process limit, even in a user namespace mapped to root)."""
    libc = ctypes.CDLL(None, use_errno=True)
    os.setgroups([])
    os.setresgid(uid, uid, uid)
    os.setresuid(uid, uid, uid)
    libc.prctl(4, 1, 0, 0, 0)  # PR_SET_DUMPABLE: its own /proc/self files, to write its maps
    if libc.unshare(0x10000000) != 0:  # CLONE_NEWUSER
        raise OSError(ctypes.get_errno(), "no user namespace: " + os.strerror(ctypes.get_errno()))
    for name, text in (("setgroups", "deny"), ("uid_map", f"{uid} {uid} 1"), ("gid_map", f"{uid} {uid} 1")):
        with open(f"/proc/self/{name}", "w") as f:
            f.write(text)


LIMITS = {
    "processes": resource.RLIMIT_NPROC,
    "files": resource.RLIMIT_NOFILE,
    "file_size": resource.RLIMIT_FSIZE,
    "cpu": resource.RLIMIT_CPU,
    "memory": resource.RLIMIT_AS,
}


def main():
    """Set the process up as sys.argv[1] (JSON: uid or null, limits) says, answer "ready" (or
    the reason it cannot start), then serve the grader on stdin and stdout."""
    conn_in, conn_out = Connection(os.dup(0), writable=False), Connection(os.dup(1), readable=False)
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    try:
        setup = json.loads(sys.argv[1])
        if setup.get("uid") is not None:
            become(int(setup["uid"]))
        ctypes.CDLL(None, use_errno=True).prctl(38, 1, 0, 0, 0)  # PR_SET_NO_NEW_PRIVS
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        for name, value in setup.get("limits", {}).items():
            if value is not None:
                resource.setrlimit(LIMITS[name], (int(value), int(value)))
        for folder in (os.environ.get("HOME"), os.environ.get("CONTACTFEM_FIGURES")):
            if folder:
                os.makedirs(folder, exist_ok=True)
    except Exception as err:  # noqa: BLE001  (the grader reads why)
        conn_out.send_bytes(json.dumps({"ready": False, "why": f"{type(err).__name__}: {err}"}).encode())
        return
    conn_out.send_bytes(json.dumps({"ready": True}).encode())
    serve(conn_in, conn_out)
