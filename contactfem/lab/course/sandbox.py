"""The process a submitted notebook runs in, apart from the grader.

    python -c "from contactfem.lab.course.sandbox import serve; serve(FD_IN, FD_OUT)"

The grader (:mod:`contactfem.lab.course.grade`) starts this process, sends it the notebook's
code cells one by one, then asks it for the student's answers and calls them with the checks'
arguments. Requests come pickled from the grader (trusted); replies go back as JSON, arrays as
``.npy`` bytes read without pickle: nothing the submission does here (patching modules,
builtins, numpy or the checks) can run code in the grader or change a reference it computes.
An object that is not plain data (a function, a class, an instance) stays here and is sent as
a handle the grader calls through this process.

While a call of an exercise that asks for an implementation runs, the library's own
implementation of that part is replaced by a tripwire: the reply says the answer used it.
"""

import base64
import importlib
import inspect
import io
import json
import os
import pickle
import re
import signal
import sys
import traceback
from multiprocessing.connection import Connection

import numpy as np

MAX_REPLY = 60 * 2**20
OTTER_LINE = re.compile(
    r"^\s*(import otter\b.*|grader\s*=\s*otter\.Notebook\(.*\)|grader\.check(_all)?\(.*\)|"
    r"grader\.export\(.*\))?\s*(#.*)?$"
)
MAGIC = re.compile(r"^(\s*)([%!].*)$", re.M)


class CallTimeout(BaseException):
    """A call of the student's code ran past its time limit (BaseException: an answer's
    `except Exception` does not swallow it)."""


class LibraryUsed(BaseException):
    pass


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
    replaces isinstance or AssertionError changes its own names, not those this module runs on."""
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


class Sandbox:
    def __init__(self):
        self.env = {"__name__": "__main__", "grader": _Grader(), "__builtins__": _own_builtins()}
        self.refs = {}
        self.used = set()
        self.sink = Sink()

    # -- replies: plain data, or a handle -------------------------------------------------

    def encode(self, v, depth=0):
        if depth > 20:
            return self.ref(v)
        if v is None:
            return {"t": "none"}
        if v is Ellipsis:
            return {"t": "ellipsis"}
        if type(v) in (bool, int, float, str):
            return {"t": "py", "v": v}
        if type(v) in (tuple, list):
            return {"t": type(v).__name__, "v": [self.encode(x, depth + 1) for x in v]}
        if type(v) is dict and all(type(k) is str for k in v):
            return {"t": "dict", "v": {k: self.encode(x, depth + 1) for k, x in v.items()}}
        if type(v) is np.ndarray and v.dtype != object or isinstance(v, np.generic) and not isinstance(v, np.object_):
            buf = io.BytesIO()
            np.save(buf, np.asarray(v), allow_pickle=False)
            return {"t": "nd" if type(v) is np.ndarray else "np", "v": base64.b64encode(buf.getvalue()).decode()}
        return self.ref(v)

    def ref(self, v):
        i = len(self.refs)
        self.refs[i] = v
        out = {
            "t": "ref",
            "id": i,
            "callable": callable(v),
            "type": type(v).__name__,
            "name": getattr(v, "__name__", None) if isinstance(getattr(v, "__name__", None), str) else None,
        }
        if callable(v):
            try:
                sig = inspect.signature(v)
                out["params"] = [(p.name, int(p.kind), p.default is not p.empty) for p in sig.parameters.values()]
            except (TypeError, ValueError):
                pass
        return out

    def decode(self, v):
        """The grader's arguments: plain values, with handles of this process's objects."""
        if isinstance(v, Handle):
            return self.refs[v.id]
        if type(v) in (tuple, list):
            return type(v)(self.decode(x) for x in v)
        if type(v) is dict:
            return {k: self.decode(x) for k, x in v.items()}
        return v

    # -- requests --------------------------------------------------------------------------

    def cell(self, source):
        lines = [ln for ln in source.splitlines()]
        if lines and all(OTTER_LINE.match(ln) for ln in lines):
            return {"ok": True, "skipped": True, "printed": self.sink.count}
        code = MAGIC.sub(r"\1pass  # \2", source)
        try:
            exec(compile(code, "<cell>", "exec"), self.env)
        except BaseException as err:  # noqa: BLE001  (sys.exit and KeyboardInterrupt are the cell's too)
            msg = " ".join(str(err).split())[:200]
            return {
                "ok": False,
                "error": f"{type(err).__name__}: {msg}" if msg else type(err).__name__,
                "printed": self.sink.count,
            }
        return {"ok": True, "printed": self.sink.count}

    def get(self, name):
        if name not in self.env:
            return {"t": "missing"}
        return self.encode(self.env[name])

    def getattr(self, i, name):
        try:
            return self.encode(getattr(self.refs[i], name))
        except AttributeError:
            return {"t": "missing"}

    def call(self, i, args, kwargs, timeout, guard):
        fun = self.refs[i]
        args, kwargs = self.decode(args), self.decode(kwargs)
        undo = self.arm(guard)

        def stop(signum, frame):
            raise CallTimeout()

        old = signal.signal(signal.SIGALRM, stop)
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            with np.errstate(all="ignore"):
                out = fun(*args, **kwargs)
            reply = {"ok": self.encode(out)}
        except CallTimeout:
            reply = {"timeout": True}
        except LibraryUsed:
            reply = {"exc": "LibraryUsed", "msg": ""}
        except BaseException as err:  # noqa: BLE001
            reply = {"exc": type(err).__name__, "msg": " ".join(str(err).split())[:300]}
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
            undo()
        reply["library"] = sorted(self.used)
        self.used.clear()
        return reply

    def arm(self, guard):
        """Replace each "module:attr.path" of `guard` (and the notebook's names bound to it) by
        a tripwire; returns the function that puts them back."""
        saved = []
        for spec in guard:
            mod, _, path = spec.partition(":")
            try:
                owner = importlib.import_module(mod)
                *head, last = path.split(".")
                for h in head:
                    owner = getattr(owner, h)
                orig = getattr(owner, last)
            except (ImportError, AttributeError):
                continue

            def wire(*a, _spec=spec, **k):
                self.used.add(_spec)
                raise LibraryUsed()

            if isinstance(orig, type):  # a class: its construction is the tripwire
                saved.append((orig, "__init__", orig.__dict__.get("__init__")))
                orig.__init__ = wire
                continue
            saved.append((owner, last, owner.__dict__.get(last, orig)))
            setattr(owner, last, wire)
            for k, v in list(self.env.items()):
                if v is orig:
                    saved.append((self.env, k, v))
                    self.env[k] = wire

        def undo():
            for owner, name, value in reversed(saved):
                if owner is self.env:
                    self.env[name] = value
                elif value is None and name == "__init__":
                    delattr(owner, name)
                else:
                    setattr(owner, name, value)

        return undo


class Handle:
    """An object of the sandbox, named by its number (sent back as a call's argument)."""

    def __init__(self, i):
        self.id = i


def _watch_parent():
    """End this process when the grader that started it is gone (whatever the notebook runs)."""
    import threading
    import time

    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(0)

    threading.Thread(target=watch, daemon=True).start()


def serve(fd_in, fd_out):
    _watch_parent()
    conn_in, conn_out = Connection(fd_in, writable=False), Connection(fd_out, readable=False)
    box = Sandbox()
    sys.stdout = sys.stderr = box.sink
    while True:
        try:
            req = pickle.loads(conn_in.recv_bytes())
        except EOFError:
            return
        kind, *args = req
        try:
            reply = getattr(box, kind)(*args)
        except BaseException as err:  # noqa: BLE001  (a request that cannot be answered is a reply too)
            reply = {
                "exc": type(err).__name__,
                "msg": " ".join(str(err).split())[:300],
                "trace": traceback.format_exc()[-1500:],
            }
        data = json.dumps(reply).encode()
        if len(data) > MAX_REPLY:
            data = json.dumps({"exc": "TooLarge", "msg": f"a reply of {len(data) / 2**20:.0f} MB"}).encode()
        conn_out.send_bytes(data)
