"""How a check calls a student's answer and judges what comes back.

A part of an exercise calls the student's code through `call` (an exception, a missing
answer, `...` or an endless loop becomes one sentence), then compares with the library's own
implementation or a closed form through `compare`, which names the point and the kind of
error: a wrong sign, a constant factor, a constant offset.

An answer is a function of the student's notebook: in the student's own Jupyter, the function
itself; while grading, a handle to it in the submission's sandbox (``remote``), which takes
plain data and the library objects a check builds (:class:`Recipe`: rebuilt there from the
students' edition of the library).
"""

import signal
import threading
from contextlib import contextmanager

import numpy as np

STILL_DOTS = "its body is still `...`: write it in the answer cell of the exercise"
TIME_LIMIT = 20.0  # seconds a call of the student's code may take (the grader sets its own)
CALL_LIMIT = [None]  # the limit of the call under way (the grader reads it for a call in the sandbox)


class Timeout(Exception):
    pass


class Recipe:
    """A library object a check hands to an answer, as the plain data that builds it: built
    here (`make`, sharing what it builds with the other arguments of the call in `built`) for
    an answer of this process, sent as data to an answer in a sandbox."""

    def make(self, built):
        raise NotImplementedError

    def data(self):
        raise NotImplementedError


class Built(Recipe):
    """A library object its class makes from plain data, e.g. ``Built(Steps, dt=1e-3, n_steps=12)``."""

    def __init__(self, cls, **fields):
        self.cls, self.fields = cls, fields

    def make(self, built):
        return self.cls(**self.fields)

    def data(self):
        return {"t": "lib", "cls": f"{self.cls.__module__}:{self.cls.__qualname__}", "set": self.fields}

    def __repr__(self):
        return f"{self.cls.__name__}({', '.join(f'{k}={v!r}' for k, v in self.fields.items())})"


@contextmanager
def _time_limit(seconds):
    """Stop the student's code after `seconds` (an endless loop must not stop the grading)."""
    if seconds is None or threading.current_thread() is not threading.main_thread() or not hasattr(signal, "SIGALRM"):
        yield
        return

    def stop(signum, frame):
        raise Timeout()

    old = signal.signal(signal.SIGALRM, stop)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def args_text(args, kwargs):
    def show(a):
        if isinstance(a, np.ndarray):
            return " ".join(np.array2string(a, precision=4, separator=", ", threshold=8).split())
        text = repr(a)
        return type(a).__name__ if " object at 0x" in text else text  # a stepper: its class, not its address

    return ", ".join([show(a) for a in args] + [f"{k}={show(v)}" for k, v in kwargs.items()])


def defined(obj, name, what="function"):
    """The student's answer `name` exists (the answer cell was run)."""
    if obj is None:
        raise AssertionError(f"`{name}` is not defined: write the {what} `{name}` in the answer cell and run it")
    if obj is Ellipsis:
        raise AssertionError(f"`{name}` is still `...`: write it in the answer cell and run it")
    return obj


def _made(v, built):
    """The arguments for an answer of this process: recipes built."""
    if isinstance(v, Recipe):
        return v.make(built)
    if type(v) in (tuple, list):
        return type(v)(_made(x, built) for x in v)
    if type(v) is dict:
        return {k: _made(x, built) for k, x in v.items()}
    return v


def call(fun, name, *args, timeout=None, **kwargs):
    """fun(*args, **kwargs), the student's function `name`: its value, or AssertionError
    with one sentence saying what went wrong. A function of the submission's sandbox keeps
    its time limit there."""
    defined(fun, name)
    if not callable(fun):
        raise AssertionError(f"`{name}` should be a function, but it is {type(fun).__name__}: {fun!r:.60}")
    timeout = TIME_LIMIT if timeout is None else timeout
    where = f"{name}({args_text(args, kwargs)})"
    local = not getattr(type(fun), "remote", False)
    timeout = CALL_LIMIT[0] = timeout if local else max(timeout, TIME_LIMIT)
    if local:
        built = {}
        args, kwargs = _made(args, built), _made(kwargs, built)
    try:
        with np.errstate(all="ignore"), _time_limit(timeout if local else None):
            out = fun(*args, **kwargs)
    except Timeout:
        raise AssertionError(
            f"{where} did not return within {timeout:g} s: an endless loop? (bound every loop, e.g. by max_updates)"
        ) from None
    except Exception as err:
        raise AssertionError(f"{where} raised {type(err).__name__}: {err}") from None
    finally:
        CALL_LIMIT[0] = None
    if out is None:
        raise AssertionError(f"{where} returned None: {STILL_DOTS} (and end it with `return`)")
    if out is Ellipsis or (isinstance(out, tuple) and any(o is Ellipsis for o in out)):
        raise AssertionError(f"{where} returned `...`: {STILL_DOTS}")
    return out


def parts(out, n, name, what):
    """out unpacked into n values (a tuple such as (t_N, dt_N))."""
    if not isinstance(out, (tuple, list)) or len(out) != n:
        got = f"{len(out)} values" if isinstance(out, (tuple, list)) else f"one {type(out).__name__}"
        raise AssertionError(f"{name} should return {n} values ({what}), it returned {got}")
    return out


def _fmt(x):
    return f"{x:.6g}" if isinstance(x, (float, int, np.floating, np.integer)) else str(x)


def compare(what, got, want, at, rtol=1e-6, atol=1e-12, rule=None):
    """AssertionError naming the worst point unless got == want to rtol. `at` is a dict
    {name: array} of the points (one per entry of want), used to say where.
    The hint says whether the error is a sign, a constant factor or a constant offset,
    and ends with `rule`, the formula to compare with, if given."""
    want = np.asarray(want, dtype=float)
    try:
        got = np.broadcast_to(np.asarray(got, dtype=float), want.shape)
    except (ValueError, TypeError):
        shape = np.shape(got) if not isinstance(got, (type(None), type(Ellipsis))) else got
        raise AssertionError(
            f"{what} should be an array of shape {want.shape} (one value per point), got {shape!r:.80}"
        ) from None
    flat_g, flat_w = got.reshape(-1), want.reshape(-1)
    pts = {k: np.broadcast_to(np.asarray(v), want.shape).reshape(-1) for k, v in at.items()}

    def where(i):
        return ", ".join(f"{k} = {_fmt(v[i])}" for k, v in pts.items())

    bad = ~np.isfinite(flat_g)
    if bad.any():
        i = int(np.argmax(bad))
        raise AssertionError(f"your {what} is {flat_g[i]} at {where(i)}: not a finite number")
    err = np.abs(flat_g - flat_w)
    tol = atol + rtol * np.abs(flat_w)
    if np.all(err <= tol):
        return
    i = int(np.argmax(err - tol))
    g, w = flat_g[i], flat_w[i]
    nz = np.abs(flat_w) > atol
    ratio = flat_g[nz] / flat_w[nz] if nz.any() else np.array([])
    diff = flat_g - flat_w
    msg = f"your {what} is {_fmt(g)} at {where(i)}, expected {_fmt(w)}"
    if ratio.size and np.allclose(ratio, -1.0, rtol=1e-6):
        msg += ": the sign is wrong"
    elif ratio.size and np.allclose(ratio, ratio[0], rtol=1e-6) and abs(ratio[0]) > 0:
        msg += f": off by a factor {ratio[0]:.4g} everywhere"
    elif np.allclose(diff, diff[0], rtol=1e-6, atol=atol) and diff.size > 1:
        msg += f": off by {diff[0]:+.4g} everywhere"
    elif abs(w) > atol and g != 0:
        msg += f" (off by a factor {g / w:.4g} there)"
    raise AssertionError(msg + (f"; {rule}" if rule else ""))


def fd(fun, x, h):
    """The central difference of fun at x."""
    return (fun(x + h) - fun(x - h)) / (2 * h)


def draw(rng, lo, hi, size=None, log=False):
    """Parameters of a hidden check from its random generator (seeded by the grader): uniform,
    or log-uniform, in [lo, hi], each to three significant digits (a hint stays readable)."""
    x = np.exp(rng.uniform(np.log(lo), np.log(hi), size)) if log else rng.uniform(lo, hi, size)
    if size is None:
        return float(f"{x:.3g}")
    return np.array([float(f"{v:.3g}") for v in np.ravel(x)]).reshape(np.shape(x))
