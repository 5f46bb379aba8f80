"""The friction-law protocol, read the same way by the return mapping and the checker.

A friction law is an object with a stick stiffness ``c_T`` (eq 5) and a slip bound.
The paper's laws (eqs 10, 11) depend on the pressure p = |t_N| and the accumulated
slip q; a law may also depend on the slip rate v and on internal variables z of its
own. The signature of ``slip_bound`` says which:

    slip_bound(p, q)          -> Y  or  (Y, dY/dp, dY/dq)
    slip_bound(p, q, v)       -> Y  or  (Y, dY/dp, dY/dq, dY/dv)
    slip_bound(p, q, v, z)    -> Y  or  (Y, dY/dp, dY/dq, dY/dv, dY/dz)

all vectorised over contact nodes (p, q, v of shape (n,), z of shape (n, k)).

* v = lambda / dt >= 0 is the slip rate of the step: lambda, the slip part of the
  tangential increment found by the return map, over the time step; v = 0 while sticking.
* z are the law's internal variables, ``n_state = k`` of them per contact node,
  starting from ``initial_state(n)`` (default zeros) and advanced over a step by

      evolve(z_bar, p, lam, dt) -> z  or  (z, dz/dp, dz/dlam)

  (default: z stays z_bar). The contact commits z with the step, only on convergence.
* ``gap_offset(z) -> (n,)`` (optional) moves the surface: the amount by which it has
  receded (wear), added to the gap g_N. The contact uses the committed z.

A law may leave out any derivative (return Y alone, or None in its place): it is then
computed by complex-step differentiation, d f/dx = Im f(x + i h) / h with h = 1e-30,
exact to round-off (no subtraction), provided the law is written with numpy functions
that accept complex numbers (np.exp, np.tanh, np.log1p, ...; not np.abs, and without
casting its arguments to float). ``FrictionLaw`` records which derivatives were
supplied and which computed, for ``check_law`` to say.

The contact reads every law through an adapter, ``as_friction_law(law)`` or
``as_normal_law(law)``, and each adapter checks what the law returns where it returns
(guarded evaluation): non-finite values, a negative slip bound Y, a tensile normal
traction (t_N > 0 in contact), a wrong shape. When it is made, the adapter checks the
stick stiffness (c_T finite and > 0) and the law's fields (every number finite).
``check_values = False`` on an adapter leaves the values unchecked (only the protocol).
The adapters are ``FrictionLaw`` and ``NormalLawView`` (the protocols they read are
written down in laws/interfaces.py).

    LawError       the law does not follow the protocol (no c_T, c_T <= 0, a slip_bound
                   with the wrong arguments, ...), found when the adapter is made: bad
                   input, before any solve (the command line's exit code 2).
    LawValueError  (a LawError) a call into the law returned a value no law may return,
                   or raised: one line naming the law, the method, the value and the
                   point (p, q, v) or g_N. Raised during a run, it ends the run (exit
                   code 1): it is not a FloatingPointError, so Newton's iteration does
                   not take it for a failed iterate and the time loop does not cut the
                   step back (a smaller step does not cure a law's NaN).

The shipped laws (contactfem.laws.friction, .normal, .rate_state) validate their fields
when built and are exact by construction: their adapters call them directly, without
the checks (the small iteration pays nothing for them).
"""

import dataclasses
import inspect
import math
import warnings

import numpy as np

from .friction import Coulomb, Frictionless, ParabolicSlip, SlipHardening
from .normal import ExponentialLaw, PowerLaw
from .rate_state import ArchardWear, DieterichRuina, Stribeck

try:  # numpy >= 1.25
    from numpy.exceptions import ComplexWarning
except ImportError:  # pragma: no cover
    from numpy import ComplexWarning  # type: ignore[attr-defined,no-redef]

H_CS = 1e-30  # complex step
ARG_NAMES = ("p", "q", "v", "z")
# the shipped law classes themselves: their adapters skip the guards (module docstring); a class
# is trusted by what it is, never by the name of the module that defines it
SHIPPED_LAWS = frozenset(
    {
        PowerLaw,
        ExponentialLaw,
        ParabolicSlip,
        Coulomb,
        SlipHardening,
        Frictionless,
        Stribeck,
        DieterichRuina,
        ArchardWear,
    }
)


class LawError(ValueError):
    """A law that does not follow the protocol (one sentence naming the mistake)."""


class LawValueError(LawError):
    """A call into a law returned a value no law may return (non-finite, Y < 0, t_N > 0 in
    contact, wrong shape) or raised: one line naming the law, the method, the value and
    the point. Not a FloatingPointError: a run ends on it, without step cutbacks."""


def explain_call_error(what, err):
    """One sentence for an exception raised inside a law's method called with arrays."""
    msg = str(err)
    if isinstance(err, TypeError) and any(k in msg for k in ("length-1", "size-1", "0-dimensional", "convert")):
        return (
            f"{what} fails on arrays ({msg}): it is called with one value per contact node, so use numpy "
            "functions (np.tanh, not math.tanh) and np.where instead of if/else on the values"
        )
    if isinstance(err, ValueError) and "truth value" in msg:
        return (
            f"{what} uses if/else on its arguments ({msg}): it is called with one value per contact node, "
            "so use np.where(condition, a, b)"
        )
    return f"{what} raised {type(err).__name__}: {' '.join(msg.split())}"


def _name(law):
    return type(law).__name__


def is_shipped(law):
    """Whether law is one of contactfem's own laws (its class exactly one of SHIPPED_LAWS: a
    subclass, or a class of the same name from elsewhere, is the user's)."""
    return type(law) in SHIPPED_LAWS


def _num(x):
    """A value for a message: 6 significant digits, nan/inf as such."""
    try:
        x = complex(x)
    except (TypeError, ValueError):
        return repr(x)
    if x.imag:
        return f"{x.real:.6g}{x.imag:+.6g}j"
    return f"{x.real:.6g}"


def _real(value, what, where=lambda i: ""):
    """``value`` (a law's output at real arguments) as real numbers: a zero imaginary part is
    dropped, a nonzero one is a LawValueError (one line: the value and, via ``where(i)``, the point)."""
    if not np.iscomplexobj(value):
        return value
    a = np.asarray(value)
    bad = np.imag(a) != 0
    if np.any(bad):
        i = np.unravel_index(int(np.argmax(bad)), a.shape) if a.ndim else ()
        at = where(i[0] if len(i) == 1 else 0)
        raise LawValueError(
            f"{what} is complex, {_num(a[i])}{' at ' + at if at else ''}: a law returns real numbers "
            "at real arguments (a square root or a fractional power of a negative number? "
            "clip it with np.maximum(x, 0) first)"
        )
    return np.real(a)


def check_fields(law):
    """LawError unless every number among a dataclass law's fields is finite (checked when
    an adapter is made: a NaN field would only come back as NaN values during the run)."""
    if not dataclasses.is_dataclass(law):
        return
    for f in dataclasses.fields(law):
        v = getattr(law, f.name, None)
        if isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_)) and not math.isfinite(v):
            raise LawError(f"{_name(law)}.{f.name} = {v}: a law's field must be a finite number")


def slip_bound_arity(law):
    """2, 3 or 4: how many of (p, q, v, z) the law's slip_bound takes."""
    fun = getattr(law, "slip_bound", None)
    if fun is None or not callable(fun):
        if callable(getattr(law, "traction", None)):
            raise LawError(
                f"{_name(law)} is a normal law (it has traction(g_N), no slip_bound): give it as the "
                "normal law (--normal, normal=), not as the friction law"
            )
        raise LawError(
            f"{_name(law)} has no method slip_bound(p, q): a friction law needs one (and a stick stiffness c_T)"
        )
    try:
        sig = inspect.signature(fun)
    except (TypeError, ValueError):
        return 2
    pos = [p for p in sig.parameters.values() if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if any(p.kind == p.VAR_POSITIONAL for p in sig.parameters.values()):
        return 4
    if len(pos) < 2:
        raise LawError(
            f"{_name(law)}.slip_bound takes {len(pos)} argument(s); it must take (p, q), "
            "(p, q, v) for a rate-dependent law or (p, q, v, z) for a law with internal variables"
        )
    return min(len(pos), 4)


def _as_array(value, shape, what):
    if type(value) is np.ndarray and value.shape == shape and value.dtype == np.float64:
        return value  # the common case, nothing to check (a return map calls this often)
    try:
        a = np.asarray(value)
    except Exception as err:  # noqa: BLE001 (anything a law returns)
        raise LawValueError(f"{what} is not an array of numbers ({err})") from None
    if a.dtype == object or not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
        raise LawValueError(f"{what} is not an array of numbers (got {type(value).__name__})")
    if a.shape == shape or a.ndim == 0:  # one value per node, or one for all
        return np.broadcast_to(a, shape)
    if len(shape) == 2 and shape[1] == 1 and a.shape == shape[:1]:  # one internal variable, as (n,)
        return a.reshape(shape)
    raise LawValueError(f"{what} has shape {a.shape}, expected {shape} (one value per contact node)")


def as_shape(a, shape):
    """a as a float array of the given shape (broadcast; no copy when it already is one)."""
    if type(a) is np.ndarray and a.shape == shape and a.dtype == np.float64:
        return a
    return np.broadcast_to(np.asarray(a, dtype=float), shape)


def _all_finite(arrays):
    """True if every value of every array is finite (a . a is non-finite if any value is:
    one BLAS call, a third of a microsecond; the exact test only where it overflows)."""
    for a in arrays:
        if a.size:
            f = a.ravel()
            if not math.isfinite(f.dot(f)) and not np.all(np.isfinite(f)):
                return False
    return True


def _rows_finite(*arrays):
    """Per node (first axis): all values finite."""
    ok = None
    for a in arrays:
        f = np.isfinite(a).reshape(len(a), -1).all(axis=1)
        ok = f if ok is None else ok & f
    return ok


class FrictionLaw:
    """A friction law read through the protocol (module docstring): Y and all its
    derivatives, the state evolution and its derivatives, whatever the law supplies;
    every value the law returns is checked (``LawValueError`` naming the law, the method,
    the value and the point), except for the shipped laws (``trusted``).

    ``supplied`` and ``computed`` (sets of names such as "dY/dp", "dz/dlam") say which
    derivatives the law returned and which were computed by complex step."""

    def __init__(self, law):
        self.law = law
        self.name = _name(law)
        self.trusted = is_shipped(law)
        self.arity = slip_bound_arity(law)
        if not hasattr(law, "c_T"):
            raise LawError(f"{self.name} has no stick stiffness c_T (eq 5): add a field c_T: float > 0")
        try:
            self.c_T = float(law.c_T)
        except (TypeError, ValueError):
            raise LawError(
                f"{self.name}.c_T = {law.c_T!r} is not a number: the stick stiffness (eq 5) must be a finite number > 0"
            ) from None
        if not (math.isfinite(self.c_T) and (self.c_T > 0 or (self.trusted and self.c_T == 0))):
            raise LawError(
                f"{self.name}.c_T = {self.c_T:g} is out of range: the stick stiffness (eq 5) must be a "
                "finite number > 0"
            )
        check_fields(law)
        k = getattr(law, "n_state", 0)
        try:
            ok = int(k) == k and k >= 0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise LawError(f"{self.name}.n_state = {k!r} must be an integer >= 0 (internal variables per node)")
        self.n_state = int(k)
        self.rate = self.arity >= 3
        self.stateful = self.n_state > 0
        self.supplied, self.computed = set(), set()
        self.check_values = True  # False: only the protocol (shapes, numbers), not the values
        self._has_evolve = self.n_state > 0 and hasattr(law, "evolve")
        self._has_offset = self.n_state > 0 and hasattr(law, "gap_offset")

    @property
    def needs_dt(self):
        return self.rate or self.stateful

    def _where(self, p=None, q=None, v=None, z=None, i=0, **more):
        """'p = 1.2, q = 0, v = 0.3' at node i (only the arguments the law takes)."""
        parts = []
        for name, a in (("p", p), ("q", q), ("v", v if self.rate else None), ("z", z if self.n_state else None)):
            if a is not None:
                a = np.asarray(a)
                val = a[i] if a.ndim else a
                parts.append(
                    f"{name} = " + (_num(val) if np.ndim(val) == 0 else "[" + ", ".join(_num(x) for x in val) + "]")
                )
        for name, a in more.items():
            a = np.asarray(a)
            parts.append(f"{name} = {_num(a[i] if a.ndim else a)}")
        return ", ".join(parts)

    # -- internal variables -------------------------------------------------
    def initial_state(self, n):
        if not self.n_state:
            return np.zeros((n, 0))
        if hasattr(self.law, "initial_state"):
            z = self._guarded_call("initial_state", lambda: self.law.initial_state(n), f"initial_state({n})")
            z = np.array(_as_array(z, (n, self.n_state), f"{self.name}.initial_state({n})"), dtype=float)
            if not self.trusted and self.check_values and not _all_finite([z]):
                i = int(np.argmin(_rows_finite(z)))
                raise LawValueError(
                    f"{self.name}.initial_state({n}) returned NaN or inf: z = "
                    f"[{', '.join(_num(x) for x in z[i])}] at node {i}"
                )
        else:
            z = np.zeros((n, self.n_state))
        return z

    def gap_offset(self, z):
        n = len(z)
        if not self._has_offset:
            return np.zeros(n)
        g = self._guarded_call("gap_offset", lambda: self.law.gap_offset(z), "gap_offset(z)")
        g = np.array(_as_array(g, (n,), f"{self.name}.gap_offset(z)"), dtype=float)
        if not self.trusted and self.check_values and not _all_finite([g]):
            ok = _rows_finite(np.asarray(z, dtype=float))
            bad = ~np.isfinite(g) & ok
            if np.any(bad):
                i = int(np.argmax(bad))
                raise LawValueError(
                    f"{self.name}.gap_offset returned NaN or inf: {_num(g[i])} at {self._where(z=z, i=i)}"
                )
        return g

    def _guarded_call(self, method, fn, what):
        try:
            return fn()
        except (LawError, ComplexWarning):
            raise
        except (Exception, SystemExit) as err:  # noqa: BLE001 (a student's law may raise anything, even exit)
            raise LawValueError(explain_call_error(f"{self.name}.{what}", err)) from None

    # -- the slip bound -----------------------------------------------------
    def _call(self, args, what):
        try:
            return self.law.slip_bound(*args[: self.arity])
        except (LawError, ComplexWarning):
            raise
        except (Exception, SystemExit) as err:  # noqa: BLE001 (a student's law may raise anything, even exit)
            raise LawValueError(explain_call_error(f"{self.name}.slip_bound", err)) from None

    def _split(self, out, n):
        """(Y, [derivatives or None]) from what slip_bound returned."""
        expect = 1 + self.arity
        if isinstance(out, (tuple, list)):
            if len(out) != expect:
                names = ", ".join(["Y"] + [f"dY/d{a}" for a in ARG_NAMES[: self.arity]])
                raise LawValueError(
                    f"{self.name}.slip_bound({', '.join(ARG_NAMES[: self.arity])}) returned "
                    f"{len(out)} values: it must return Y alone or the {expect} values ({names})"
                )
            return out[0], list(out[1:])
        return out, [None] * self.arity

    def _complex_step(self, args, j, n, comp=None):
        """d Y / d args[j] (component comp of z) by complex step."""
        a = list(args)
        if comp is None:
            a[j] = np.asarray(a[j], dtype=float) + 1j * H_CS
        else:
            zc = np.array(a[j], dtype=complex)
            zc[:, comp] += 1j * H_CS
            a[j] = zc
        with warnings.catch_warnings():
            warnings.simplefilter("error", ComplexWarning)
            try:
                out = self._call(a, "")
            except ComplexWarning:
                raise LawValueError(
                    f"{self.name}.slip_bound leaves out dY/d{ARG_NAMES[j]}, which is then computed by complex step, "
                    "but the law casts its arguments to float (e.g. np.asarray(p, dtype=float)): write np.asarray(p) "
                    "or return the derivative"
                ) from None
            except LawError as err:
                raise LawValueError(
                    f"{err} (while computing dY/d{ARG_NAMES[j]} by complex step: return it yourself)"
                ) from None
        Y, _ = self._split(out, n)
        Y = _as_array(Y, (n,), f"{self.name}.slip_bound: Y")
        return np.imag(Y) / H_CS

    def slip_bound_pq(self, p, q):
        """(Y, dY/dp, dY/dq) of a law of the paper's form Y(p, q) (slip_bound(p, q), no internal
        variables) at float arrays p, q (n,): what the return map calls at every iteration. A
        shipped law is called as it is (exact by construction, module docstring); any other
        law through ``slip_bound`` (its values checked)."""
        if self.trusted:
            return self.law.slip_bound(p, q)
        return self.slip_bound(p, q)[:3]

    def slip_bound(self, p, q, v=None, z=None):
        """Y, dY/dp, dY/dq, dY/dv (n,) and dY/dz (n, k) at the given arguments."""
        p = np.asarray(p, dtype=float)
        n = p.size
        p = p.reshape(n)
        q = as_shape(q, (n,))
        v = np.zeros(n) if v is None else as_shape(v, (n,))
        k = self.n_state
        z = np.zeros((n, k)) if z is None else as_shape(z, (n, k))
        args = [p, q, v, z]
        if self.trusted:  # a shipped law returns Y and every derivative, exact
            out = self.law.slip_bound(*args[: self.arity])
            if self.arity == 4:
                return out
            rest = (np.zeros(n), np.zeros((n, k)))[self.arity - 2 :]
            return (*out, *rest)
        Y, ders = self._split(self._call(args, ""), n)
        at = lambda i: self._where(p, q, v, z, i)  # noqa: E731
        Y = _real(Y, f"{self.name}.slip_bound: Y", at)
        self._one_for_all(Y, args, n)
        Y = np.array(_as_array(Y, (n,), f"{self.name}.slip_bound: Y"), dtype=float)
        if any(d is None for d in ders):  # Y first: the missing derivatives are computed from it
            self._guard_slip_bound(args, (Y,))
        res = []
        for j in range(4):
            name = f"dY/d{ARG_NAMES[j]}"
            if j >= self.arity:
                res.append(np.zeros((n, k)) if j == 3 else np.zeros(n))
                continue
            d = ders[j]
            if d is not None:
                shape = (n, k) if j == 3 else (n,)
                d = _real(d, f"{self.name}.slip_bound: {name}", at)
                res.append(np.array(_as_array(d, shape, f"{self.name}.slip_bound: {name}"), dtype=float))
                self.supplied.add(name)
            elif j == 3:
                res.append(
                    np.stack([self._complex_step(args, 3, n, c) for c in range(k)], axis=1) if k else np.zeros((n, 0))
                )
                self.computed.add(name)
            else:
                res.append(self._complex_step(args, j, n))
                self.computed.add(name)
        out = (Y, *res)
        self._guard_slip_bound(args, out)
        return out

    def _one_for_all(self, Y, args, n):
        """LawValueError if slip_bound returned one number for all n > 1 nodes that depends on
        their values (``mu * np.mean(p)``): Y must be one value per node, each from that node's own
        arguments. One number that does not change with them (a constant Y) is one for every node."""
        if n < 2 or np.ndim(Y) != 0 or np.asarray(Y).dtype.kind not in "biuf":
            return  # (not a number: _as_array says so)
        moved = [np.array(a, dtype=float) for a in args]  # the first node's arguments moved
        moved[0][0] = 2.0 * moved[0][0] + 1.0
        for a in moved[1:]:
            if a.size:
                a[0] = a[0] + 1.0
        try:
            Y2, _ = self._split(self._call(moved, ""), n)
        except LawError:
            return
        Y2 = np.asarray(Y2)
        if Y2.ndim == 0 and Y2.dtype.kind in "biufc" and not np.array_equal(Y2, np.asarray(Y), equal_nan=True):
            names = ", ".join(ARG_NAMES[: self.arity])
            raise LawValueError(
                f"{self.name}.slip_bound returned one number for all {n} contact nodes (shape ()), and it changes "
                f"with the values at one node: it must return one value per node, shape ({n},), each from that "
                f"node's own {names} (e.g. mu * p, not mu * np.mean(p))"
            )

    def _guard_slip_bound(self, args, out):
        """LawValueError at the first node where the law returned NaN/inf or Y < 0 (nodes whose
        arguments are themselves not finite excepted: there the solver has failed, not the law)."""
        Y = out[0]
        out = out[: 1 + self.arity]
        if not self.check_values or not Y.size or (Y.min() >= 0.0 and _all_finite(out)):
            return  # (the minimum is NaN, not >= 0, if a value is NaN)
        p, q, v, z = args
        ok = _rows_finite(p, q, v, z)
        names = ["Y"] + [f"dY/d{a}" for a in ARG_NAMES[: self.arity]]
        for name, a in zip(names, out):
            bad = ~_rows_finite(a) & ok
            if np.any(bad):
                i = int(np.argmax(bad))
                val = a[i] if a.ndim == 1 else "[" + ", ".join(_num(x) for x in a[i]) + "]"
                how = " (computed by complex step)" if name in self.computed else ""
                raise LawValueError(
                    f"{self.name}.slip_bound returned NaN or inf: {name}{how} = "
                    f"{_num(val) if a.ndim == 1 else val} at {self._where(p, q, v, z, i)}"
                )
        bad = (Y < 0.0) & ok
        if np.any(bad):
            i = int(np.argmax(bad))
            raise LawValueError(
                f"{self.name}.slip_bound returned a negative slip bound: Y = {_num(Y[i])} at "
                f"{self._where(p, q, v, z, i)} (Y, the largest tangential traction, must be >= 0)"
            )

    # -- the state evolution -------------------------------------------------
    def _evolve_call(self, z_bar, p, lam, dt):
        try:
            return self.law.evolve(z_bar, p, lam, dt)
        except (LawError, ComplexWarning):
            raise
        except (Exception, SystemExit) as err:  # noqa: BLE001
            raise LawValueError(explain_call_error(f"{self.name}.evolve(z_bar, p, lam, dt)", err)) from None

    def evolve(self, z_bar, p, lam, dt):
        """z (n, k) after the step and dz/dp, dz/dlam (n, k)."""
        n, k = len(p), self.n_state
        zero = np.zeros((n, k))
        if not self._has_evolve:
            return np.array(np.broadcast_to(z_bar, (n, k)), dtype=float), zero, zero.copy()
        if self.trusted:
            return self.law.evolve(z_bar, p, lam, dt)
        out = self._evolve_call(z_bar, p, lam, dt)
        if isinstance(out, (tuple, list)):
            if len(out) != 3:
                raise LawValueError(
                    f"{self.name}.evolve returned {len(out)} values: it must return z alone or (z, dz/dp, dz/dlam)"
                )
            z, dz_p, dz_lam = out
        else:
            z, dz_p, dz_lam = out, None, None
        z = np.array(_as_array(_real(z, f"{self.name}.evolve: z"), (n, k), f"{self.name}.evolve: z"), dtype=float)
        res = []
        for name, d, x in (("dz/dp", dz_p, 1), ("dz/dlam", dz_lam, 2)):
            if d is not None:
                res.append(
                    np.array(
                        _as_array(_real(d, f"{self.name}.evolve: {name}"), (n, k), f"{self.name}.evolve: {name}"),
                        dtype=float,
                    )
                )
                self.supplied.add(name)
                continue
            a = [z_bar, np.asarray(p, dtype=float), np.asarray(lam, dtype=float), dt]
            a[x] = a[x] + 1j * H_CS
            with warnings.catch_warnings():
                warnings.simplefilter("error", ComplexWarning)
                try:
                    o = self._evolve_call(*a)
                except ComplexWarning:
                    raise LawValueError(
                        f"{self.name}.evolve leaves out {name}, which is then computed by complex "
                        "step, but it casts its arguments to float: return the derivative"
                    ) from None
            zc = o[0] if isinstance(o, (tuple, list)) else o
            res.append(np.imag(_as_array(zc, (n, k), f"{self.name}.evolve: z")) / H_CS)
            self.computed.add(name)
        out = (z, res[0], res[1])
        if self.check_values and not _all_finite(out):
            zb = as_shape(z_bar, (n, k))
            p_, lam_ = as_shape(p, (n,)), as_shape(lam, (n,))
            ok = _rows_finite(zb, p_, lam_) & bool(np.isfinite(dt))
            for name, a in zip(("z", "dz/dp", "dz/dlam"), out):
                bad = ~_rows_finite(a) & ok
                if np.any(bad):
                    i = int(np.argmax(bad))
                    how = " (computed by complex step)" if name in self.computed else ""
                    raise LawValueError(
                        f"{self.name}.evolve returned NaN or inf: {name}{how} = "
                        f"[{', '.join(_num(x) for x in a[i])}] at z_bar = "
                        f"[{', '.join(_num(x) for x in zb[i])}], p = {_num(p_[i])}, "
                        f"lam = {_num(lam_[i])}, dt = {_num(dt)}"
                    )
        return out


def as_friction_law(law):
    """A FrictionLaw view of law (law itself if it already is one): the only way the
    contact calls a friction law. LawError if law is no friction law."""
    return law if isinstance(law, FrictionLaw) else FrictionLaw(law)


class NormalLawView:
    """A normal law (laws.interfaces.NormalLaw) read through the protocol: ``traction(g_N) -> (t_N, dt_N/dg_N)`` and,
    if the law has one, ``energy(g_N)``, its potential (dW/dg_N = t_N). ``has_energy``
    says whether it has one; without one the view has no attribute ``energy`` either
    (``hasattr(view, "energy")`` is False, and reading it raises an AttributeError that
    says so). Every value returned is checked (``LawValueError`` naming the law, the
    method, the value and g_N): finite, t_N <= 0 where g_N < 0 (compressive), the shape
    of g_N; the shipped laws are called directly (``trusted``). The law's own fields (c_N,
    m, ...) are read from the law itself, ``view.law``."""

    def __init__(self, law):
        self.law = law
        self.name = _name(law)
        self.trusted = is_shipped(law)
        if not callable(getattr(law, "traction", None)):
            if callable(getattr(law, "slip_bound", None)):
                raise LawError(
                    f"{self.name} is a friction law (it has slip_bound, no traction): give it as the "
                    "friction law (--friction, friction=), not as the normal law"
                )
            raise LawError(
                f"{self.name} has no method traction(g_N): a normal law needs one, returning (t_N, dt_N/dg_N)"
            )
        check_fields(law)
        self.has_energy = callable(getattr(law, "energy", None))
        self.check_values = True  # False: only the protocol (shapes, numbers), not the values

    @property
    def energy(self):
        """The law's potential, ``energy(g_N) -> W`` (checked); an AttributeError that says so for a
        law without one (so ``hasattr(view, "energy")`` is False)."""
        if not self.has_energy:
            raise AttributeError(
                f"{self.name} has no method energy(g_N): this use needs the law's potential W, "
                "dW/dg_N = t_N (e.g. c_N (-g_N)^(m+1) / (m+1) for eq 4)"
            )
        return self._energy

    def _call(self, method, g):
        """The law's own `method`(g): an error it raises becomes one LawValueError naming it."""
        try:
            return getattr(self.law, method)(g)
        except LawError:
            raise
        except (Exception, SystemExit) as err:  # noqa: BLE001
            raise LawValueError(explain_call_error(f"{self.name}.{method}", err)) from None

    def traction(self, g_N):
        """(t_N, dt_N/dg_N), each of the shape of g_N."""
        if self.trusted:
            return self.law.traction(g_N)
        g = np.asarray(g_N, dtype=float)
        out = self._call("traction", g)
        if not (isinstance(out, (tuple, list)) and len(out) == 2):
            got = f"{len(out)} values" if isinstance(out, (tuple, list)) else "one value"
            raise LawValueError(
                f"{self.name}.traction(g_N) returned {got}: it must return the two values (t_N, dt_N/dg_N)"
            )
        at = lambda i: f"g_N = {_num(g.ravel()[i])}" if g.size else ""  # noqa: E731
        t, dt = (
            np.array(
                _as_array(_real(a, f"{self.name}.traction: {w}", at), g.shape, f"{self.name}.traction: {w}"),
                dtype=float,
            )
            for a, w in zip(out, ("t_N", "dt_N/dg_N"))
        )
        if (
            self.check_values
            and t.size
            and not (_all_finite((t, dt)) and (t.max() <= 0.0 or not np.any((t > 0.0) & (g < 0.0))))
        ):
            ok = np.isfinite(g)
            for name, a in (("t_N", t), ("dt_N/dg_N", dt)):
                bad = ~np.isfinite(a) & ok
                if np.any(bad):
                    i = np.unravel_index(int(np.argmax(bad)), a.shape)
                    raise LawValueError(
                        f"{self.name}.traction returned NaN or inf: {name} = {_num(a[i])} at g_N = {_num(g[i])}"
                    )
            bad = (t > 0.0) & (g < 0.0)
            if np.any(bad):
                i = np.unravel_index(int(np.argmax(bad)), t.shape)
                raise LawValueError(
                    f"{self.name}.traction returned a tensile traction: t_N = {_num(t[i])} > 0 at "
                    f"g_N = {_num(g[i])} (in contact, g_N < 0, t_N must be <= 0: compressive)"
                )
        return t, dt

    def _energy(self, g_N):
        """The law's potential W(g_N) (dW/dg_N = t_N), of the shape of g_N (``energy``)."""
        if self.trusted:
            return self.law.energy(g_N)
        g = np.asarray(g_N, dtype=float)
        W = self._call("energy", g)
        W = np.array(_as_array(_real(W, f"{self.name}.energy"), g.shape, f"{self.name}.energy"), dtype=float)
        if self.check_values and not _all_finite((W,)):
            bad = ~np.isfinite(W) & np.isfinite(g)
            if np.any(bad):
                i = np.unravel_index(int(np.argmax(bad)), W.shape)
                raise LawValueError(f"{self.name}.energy returned NaN or inf: W = {_num(W[i])} at g_N = {_num(g[i])}")
        return W


def as_normal_law(law):
    """A NormalLawView of law (law itself if it already is one): the only way the contact
    calls a normal law. LawError if law is no normal law."""
    return law if isinstance(law, NormalLawView) else NormalLawView(law)


def describe(law):
    """JSON record of a law: class, file (None for a shipped law, else the law file it came from) and fields."""
    law = getattr(law, "law", law) if isinstance(law, (FrictionLaw, NormalLawView)) else law
    cls = type(law)
    fields = {f.name: getattr(law, f.name) for f in dataclasses.fields(law)} if dataclasses.is_dataclass(law) else {}
    return {"class": cls.__name__, "file": getattr(cls, "_contactfem_file", None), "fields": fields}
