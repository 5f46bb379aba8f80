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

Mistakes in a law raise ``LawError`` with one sentence naming the mistake.
"""

import inspect
import warnings

import numpy as np

try:                                           # numpy >= 1.25
    from numpy.exceptions import ComplexWarning
except ImportError:                            # pragma: no cover
    from numpy import ComplexWarning

H_CS = 1e-30                                   # complex step
ARG_NAMES = ("p", "q", "v", "z")


class LawError(ValueError):
    """A law that does not follow the protocol (one sentence naming the mistake)."""


def explain_call_error(what, err):
    """One sentence for an exception raised inside a law's method called with arrays."""
    msg = str(err)
    if isinstance(err, TypeError) and any(k in msg for k in ("length-1", "size-1", "0-dimensional", "convert")):
        return (f"{what} fails on arrays ({msg}): it is called with one value per contact node, so use numpy "
                "functions (np.tanh, not math.tanh) and np.where instead of if/else on the values")
    if isinstance(err, ValueError) and "truth value" in msg:
        return (f"{what} uses if/else on its arguments ({msg}): it is called with one value per contact node, "
                "so use np.where(condition, a, b)")
    return f"{what} raised {type(err).__name__}: {msg}"


def _name(law):
    return type(law).__name__


def slip_bound_arity(law):
    """2, 3 or 4: how many of (p, q, v, z) the law's slip_bound takes."""
    fun = getattr(law, "slip_bound", None)
    if fun is None or not callable(fun):
        raise LawError(f"{_name(law)} has no method slip_bound(p, q): a friction law needs one "
                       "(and a stick stiffness c_T)")
    try:
        sig = inspect.signature(fun)
    except (TypeError, ValueError):
        return 2
    pos = [p for p in sig.parameters.values() if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if any(p.kind == p.VAR_POSITIONAL for p in sig.parameters.values()):
        return 4
    if len(pos) < 2:
        raise LawError(f"{_name(law)}.slip_bound takes {len(pos)} argument(s); it must take (p, q), "
                       "(p, q, v) for a rate-dependent law or (p, q, v, z) for a law with internal variables")
    return min(len(pos), 4)


def _as_array(value, shape, what):
    if type(value) is np.ndarray and value.shape == shape and value.dtype == np.float64:
        return value                           # the common case, nothing to check (a return map calls this often)
    try:
        a = np.asarray(value)
    except Exception as err:                   # noqa: BLE001 (anything a law returns)
        raise LawError(f"{what} is not an array of numbers ({err})") from None
    if a.dtype == object or not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
        raise LawError(f"{what} is not an array of numbers (got {type(value).__name__})")
    try:
        return np.broadcast_to(a, shape)
    except ValueError:
        raise LawError(f"{what} has shape {a.shape}, expected {shape} (one value per contact node)") from None


def as_shape(a, shape):
    """a as a float array of the given shape (broadcast; no copy when it already is one)."""
    if type(a) is np.ndarray and a.shape == shape and a.dtype == np.float64:
        return a
    return np.broadcast_to(np.asarray(a, dtype=float), shape)


class FrictionLaw:
    """A friction law read through the protocol (module docstring): Y and all its
    derivatives, the state evolution and its derivatives, whatever the law supplies.

    ``supplied`` and ``computed`` (sets of names such as "dY/dp", "dz/dlam") say which
    derivatives the law returned and which were computed by complex step."""

    def __init__(self, law):
        self.law = law
        self.name = _name(law)
        if not hasattr(law, "c_T"):
            raise LawError(f"{self.name} has no stick stiffness c_T (eq 5): add a field c_T: float > 0")
        try:
            self.c_T = float(law.c_T)
        except (TypeError, ValueError):
            raise LawError(f"{self.name}.c_T = {law.c_T!r} is not a number") from None
        self.arity = slip_bound_arity(law)
        k = getattr(law, "n_state", 0)
        if int(k) != k or k < 0:
            raise LawError(f"{self.name}.n_state = {k!r} must be an integer >= 0 (internal variables per node)")
        self.n_state = int(k)
        self.rate = self.arity >= 3
        self.stateful = self.n_state > 0
        self.supplied, self.computed = set(), set()

    @property
    def needs_dt(self):
        return self.rate or self.stateful

    # -- internal variables -------------------------------------------------
    def initial_state(self, n):
        if not self.n_state:
            return np.zeros((n, 0))
        if hasattr(self.law, "initial_state"):
            z = self.law.initial_state(n)
            z = np.array(_as_array(z, (n, self.n_state), f"{self.name}.initial_state({n})"), dtype=float)
        else:
            z = np.zeros((n, self.n_state))
        return z

    def gap_offset(self, z):
        n = len(z)
        if not self.n_state or not hasattr(self.law, "gap_offset"):
            return np.zeros(n)
        g = _as_array(self.law.gap_offset(z), (n,), f"{self.name}.gap_offset(z)")
        return np.array(g, dtype=float)

    # -- the slip bound -----------------------------------------------------
    def _call(self, args, what):
        try:
            return self.law.slip_bound(*args[:self.arity])
        except (LawError, ComplexWarning):
            raise
        except Exception as err:               # noqa: BLE001 (a student's law may raise anything)
            raise LawError(explain_call_error(f"{self.name}.slip_bound", err)) from None

    def _split(self, out, n):
        """(Y, [derivatives or None]) from what slip_bound returned."""
        expect = 1 + self.arity
        if isinstance(out, (tuple, list)):
            if len(out) != expect:
                names = ", ".join(["Y"] + [f"dY/d{a}" for a in ARG_NAMES[:self.arity]])
                raise LawError(f"{self.name}.slip_bound({', '.join(ARG_NAMES[:self.arity])}) returned {len(out)} "
                               f"values: it must return Y alone or the {expect} values ({names})")
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
                raise LawError(
                    f"{self.name}.slip_bound leaves out dY/d{ARG_NAMES[j]}, which is then computed by complex step, "
                    "but the law casts its arguments to float (e.g. np.asarray(p, dtype=float)): write np.asarray(p) "
                    "or return the derivative") from None
            except LawError as err:
                raise LawError(f"{err} (while computing dY/d{ARG_NAMES[j]} by complex step: return it yourself)") from None
        Y, _ = self._split(out, n)
        return np.imag(np.broadcast_to(np.asarray(Y), (n,))) / H_CS

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
        Y, ders = self._split(self._call(args, ""), n)
        if np.iscomplexobj(Y):
            Y = np.real(Y)
        Y = np.array(_as_array(Y, (n,), f"{self.name}.slip_bound: Y"), dtype=float)
        res = []
        for j in range(4):
            name = f"dY/d{ARG_NAMES[j]}"
            if j >= self.arity:
                res.append(np.zeros((n, k)) if j == 3 else np.zeros(n))
                continue
            d = ders[j]
            if d is not None:
                shape = (n, k) if j == 3 else (n,)
                res.append(np.array(_as_array(d, shape, f"{self.name}.slip_bound: {name}"), dtype=float))
                self.supplied.add(name)
            elif j == 3:
                res.append(np.stack([self._complex_step(args, 3, n, c) for c in range(k)], axis=1)
                           if k else np.zeros((n, 0)))
                self.computed.add(name)
            else:
                res.append(self._complex_step(args, j, n))
                self.computed.add(name)
        return (Y, *res)

    # -- the state evolution -------------------------------------------------
    def _evolve_call(self, z_bar, p, lam, dt):
        try:
            return self.law.evolve(z_bar, p, lam, dt)
        except ComplexWarning:
            raise
        except Exception as err:               # noqa: BLE001
            raise LawError(explain_call_error(f"{self.name}.evolve(z_bar, p, lam, dt)", err)) from None

    def evolve(self, z_bar, p, lam, dt):
        """z (n, k) after the step and dz/dp, dz/dlam (n, k)."""
        n, k = len(p), self.n_state
        zero = np.zeros((n, k))
        if not k or not hasattr(self.law, "evolve"):
            return np.array(np.broadcast_to(z_bar, (n, k)), dtype=float), zero, zero.copy()
        out = self._evolve_call(z_bar, p, lam, dt)
        if isinstance(out, (tuple, list)):
            if len(out) != 3:
                raise LawError(f"{self.name}.evolve returned {len(out)} values: it must return z alone or "
                               "(z, dz/dp, dz/dlam)")
            z, dz_p, dz_lam = out
        else:
            z, dz_p, dz_lam = out, None, None
        z = np.array(_as_array(np.real(z) if np.iscomplexobj(z) else z, (n, k), f"{self.name}.evolve: z"), dtype=float)
        res = []
        for name, d, x in (("dz/dp", dz_p, 1), ("dz/dlam", dz_lam, 2)):
            if d is not None:
                res.append(np.array(_as_array(d, (n, k), f"{self.name}.evolve: {name}"), dtype=float))
                self.supplied.add(name)
                continue
            a = [z_bar, np.asarray(p, dtype=float), np.asarray(lam, dtype=float), dt]
            a[x] = a[x] + 1j * H_CS
            with warnings.catch_warnings():
                warnings.simplefilter("error", ComplexWarning)
                try:
                    o = self._evolve_call(*a)
                except ComplexWarning:
                    raise LawError(f"{self.name}.evolve leaves out {name}, which is then computed by complex step, "
                                   "but it casts its arguments to float: return the derivative") from None
            zc = o[0] if isinstance(o, (tuple, list)) else o
            res.append(np.imag(np.broadcast_to(np.asarray(zc), (n, k))) / H_CS)
            self.computed.add(name)
        return z, res[0], res[1]


def as_friction_law(law):
    """A FrictionLaw view of law (law itself if it already is one)."""
    return law if isinstance(law, FrictionLaw) else FrictionLaw(law)


def describe(law):
    """JSON record of a law: class, file (None for a shipped law, else the law file it came from) and fields."""
    import dataclasses

    cls = type(law)
    fields = ({f.name: getattr(law, f.name) for f in dataclasses.fields(law)} if dataclasses.is_dataclass(law) else {})
    return {"class": cls.__name__, "file": getattr(cls, "_contactfem_file", None), "fields": fields}
