"""The automatic checks of the course's exercises: one entry of EXERCISES per exercise,
each a few parts with points; a part passes or raises AssertionError with a hint a
student can act on ("your dt_N/dg_N is off by a factor 2.5 at g_N = -0.1").

A part is a function of the student's names (the answer the exercise asks for, looked up
in the notebook by name). It calls the student's code through `call` (an exception, a
missing answer, `...` or an endless loop becomes one sentence), then compares with the
library's own implementation or a closed form through `compare`, which names the point
and the kind of error: a wrong sign, a constant factor, a constant offset.

`contactfem course build` writes every part into the notebook as a test of the grading
tool (otter-grader), with its points; `grader.check("NAME")` in the student's notebook
runs them, and `contactfem course grade` runs them on the submissions.
"""

import math
import signal
import threading
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

# -- the helpers every check uses ---------------------------------------------------------

STILL_DOTS = "its body is still `...`: write it in the answer cell of the exercise"


class Timeout(Exception):
    pass


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


def _args_text(args, kwargs):
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


TIME_LIMIT = 20.0  # seconds a call of the student's code may take (the grader sets its own)
CALL_LIMIT = [None]  # the limit of the call under way (a call in the submission's process reads it)


def call(fun, name, *args, timeout=None, **kwargs):
    """fun(*args, **kwargs), the student's function `name`: its value, or AssertionError
    with one sentence saying what went wrong. A function of the submission's process (the
    grader's) keeps its time limit there."""
    defined(fun, name)
    if not callable(fun):
        raise AssertionError(f"`{name}` should be a function, but it is {type(fun).__name__}: {fun!r:.60}")
    timeout = TIME_LIMIT if timeout is None else timeout
    where = f"{name}({_args_text(args, kwargs)})"
    local = not getattr(type(fun), "remote", False)
    timeout = CALL_LIMIT[0] = timeout if local else max(timeout, TIME_LIMIT)
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


def _fd(fun, x, h):
    return (fun(x + h) - fun(x - h)) / (2 * h)


@dataclass(frozen=True)
class Part:
    """One graded part of an exercise: `check(**answers)` raises AssertionError with a hint."""

    name: str
    points: float
    check: object
    answers: tuple  # the names of the student's answers it reads


@dataclass(frozen=True)
class Exercise:
    name: str
    lecture: str
    difficulty: str  # easy, medium, hard
    implements: bool  # asks the student to implement part of the method
    parts: tuple
    what: str  # one line for the course plan

    @property
    def points(self):
        return sum(p.points for p in self.parts)


def run(name, env):
    """Run the parts of exercise `name` on the names in `env` (a notebook's globals):
    [(part, points scored, message)]. For the instructor and the tests; the grading goes
    through otter."""
    out = []
    for part in EXERCISES[name].parts:
        try:
            part.check(**{a: env.get(a) for a in part.answers})
            out.append((part.name, part.points, "passed"))
        except AssertionError as err:
            out.append((part.name, 0.0, str(err)))
    return out


# -- lecture 01: the interface laws ---------------------------------------------------------


def _power_law_call(power_law, g_N, c_N, m):
    out = call(power_law, "power_law", g_N, c_N, m)
    return parts(out, 2, "power_law", "t_N and dt_N/dg_N")


def power_law_open(power_law):
    g = np.array([0.01, 0.2, 0.0])
    t_N, dt_N = _power_law_call(power_law, g, 100.0, 2.5)
    compare("t_N for an open gap", t_N, np.zeros(3), {"g_N": g}, rule="no contact, no traction: t_N = 0 where g_N >= 0")
    compare("dt_N/dg_N for an open gap", dt_N, np.zeros(3), {"g_N": g})


def power_law_traction(power_law):
    g = np.array([-0.01, -0.1, -0.5, -0.01, -0.1, -0.5])
    m = np.array([1.0, 1.0, 1.0, 2.5, 2.5, 2.5])
    for mm in (1.0, 2.5):
        sel = m == mm
        t_N, _ = _power_law_call(power_law, g[sel], 100.0, mm)
        compare(f"t_N (c_N = 100, m = {mm:g})", t_N, -100.0 * (-g[sel]) ** mm, {"g_N": g[sel]})


def power_law_derivative(power_law):
    g = np.array([-0.01, -0.1, -0.5])
    for mm in (1.0, 2.5):
        _, dt_N = _power_law_call(power_law, g, 100.0, mm)
        compare(f"dt_N/dg_N (c_N = 100, m = {mm:g})", dt_N, 100.0 * mm * (-g) ** (mm - 1.0), {"g_N": g})


def _tresca(Tresca, **kw):
    defined(Tresca, "Tresca", "class")
    try:
        return Tresca(**kw)
    except Exception as err:
        raise AssertionError(f"Tresca({_args_text((), kw)}) raised {type(err).__name__}: {err}") from None


def tresca_fields(Tresca):
    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    if getattr(law, "c_T", None) != 30.0 or getattr(law, "tau_y", None) != 0.2:
        raise AssertionError(
            "Tresca(c_T=30.0, tau_y=0.2) should keep its fields c_T and tau_y "
            "(a dataclass with the fields c_T: float and tau_y: float)"
        )
    if not callable(getattr(law, "slip_bound", None)):
        raise AssertionError("a Tresca law needs a method slip_bound(self, p, q)")
    out = call(law.slip_bound, "Tresca(c_T=30.0, tau_y=0.2).slip_bound", np.array([1.0]), np.array([0.0]))
    parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def _tresca_bound(Tresca):
    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    p = np.array([0.5, 1.0, 4.0, 0.5, 1.0, 4.0])
    q = np.array([0.0, 0.0, 0.0, 0.3, 0.3, 0.3])
    out = call(law.slip_bound, "Tresca(c_T=30.0, tau_y=0.2).slip_bound", p, q)
    return p, q, parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def tresca_bound(Tresca):
    p, q, (Y, _, _) = _tresca_bound(Tresca)
    Yb = np.broadcast_to(np.asarray(Y, dtype=float), p.shape) if np.ndim(Y) <= 1 else np.asarray(Y)
    if np.all(np.isfinite(Yb)) and np.allclose(Yb / p, Yb[0] / p[0]) and not np.allclose(Yb, Yb[0]):
        raise AssertionError(
            f"your Y grows with the pressure (Y/p = {Yb[0] / p[0]:.4g} at every p): that is "
            "Coulomb's law; Tresca's bound is the constant shear strength tau_y, whatever p"
        )
    compare("slip bound Y (tau_y = 0.2)", Y, np.full(p.shape, 0.2), {"p": p, "q": q})


def tresca_derivatives(Tresca):
    p, q, (_, Y_p, Y_q) = _tresca_bound(Tresca)
    compare("dY/dp", Y_p, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on p")
    compare("dY/dq", Y_q, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on q")


def tresca_check_law(Tresca):
    from ...laws.check import check_law

    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    report = check_law(law)
    if not report.ok:
        failed = [s for ok, s in report.checks if not ok]
        raise AssertionError("check_law(Tresca(c_T=30.0, tau_y=0.2)) fails: " + failed[0])


# -- lecture 02: kinematics and the tangent --------------------------------------------------


def _circle(circle_gap):
    x_s = np.array([[2.0, 0.5], [1.0, 3.0], [1.4, 1.0], [-0.5, 0.2]])
    c, R = np.array([1.0, 1.0]), 1.5
    out = call(circle_gap, "circle_gap", x_s, c, R)
    g_N, n = parts(out, 2, "circle_gap", "g_N and n")
    d = x_s - c
    r = np.linalg.norm(d, axis=1)
    return x_s, c, R, np.asarray(g_N, dtype=float), np.asarray(n, dtype=float), r - R, d / r[:, None]


def circle_gap_value(circle_gap):
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    at = {"x_s": [f"({x:g}, {y:g})" for x, y in x_s]}
    if g_N.shape == g_ref.shape and np.allclose(g_N, -g_ref):
        raise AssertionError(
            "your g_N has the wrong sign: a slave outside the disc has an open gap g_N > 0, "
            "one inside has penetrated, g_N < 0"
        )
    compare("g_N (centre (1, 1), R = 1.5)", g_N, g_ref, at, rule="g_N = |x_s - centre| - R")


def circle_gap_normal(circle_gap):
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    if n.shape != n_ref.shape:
        raise AssertionError(f"n should have shape {n_ref.shape} (one unit vector per slave node), got {n.shape}")
    norm = np.linalg.norm(n, axis=1)
    if not np.allclose(norm, 1.0, rtol=1e-8):
        i = int(np.argmax(np.abs(norm - 1.0)))
        raise AssertionError(
            f"your n at x_s = ({x_s[i, 0]:g}, {x_s[i, 1]:g}) has length {norm[i]:.4g}: "
            "divide by |x_s - centre| to make it a unit vector"
        )
    dots = np.einsum("ij,ij->i", n, n_ref)
    if np.all(dots < -0.999999):
        raise AssertionError(
            "your n points into the disc: the outward normal n = (x_s - centre)/|x_s - centre| "
            "points from the centre to the slave"
        )
    i = int(np.argmin(dots))
    if dots[i] < 1 - 1e-8:
        raise AssertionError(
            f"your n at x_s = ({x_s[i, 0]:g}, {x_s[i, 1]:g}) is ({n[i, 0]:.4g}, {n[i, 1]:.4g}), "
            f"expected ({n_ref[i, 0]:.4g}, {n_ref[i, 1]:.4g}), the direction from the centre to the slave"
        )


def circle_gap_variation(circle_gap):
    """The gap's derivative with respect to the slave's position is the normal (delta g_N = n . delta x_s)."""
    x_s, c, R, g_N, n, g_ref, n_ref = _circle(circle_gap)
    h = 1e-6
    for k, name in ((0, "x"), (1, "y")):
        e = np.zeros(2)
        e[k] = h
        gp = np.asarray(parts(call(circle_gap, "circle_gap", x_s + e, c, R), 2, "circle_gap", "g_N and n")[0], float)
        gm = np.asarray(parts(call(circle_gap, "circle_gap", x_s - e, c, R), 2, "circle_gap", "g_N and n")[0], float)
        fd = (gp - gm) / (2 * h)
        if not np.allclose(fd, n[:, k], atol=1e-6):
            i = int(np.argmax(np.abs(fd - n[:, k])))
            raise AssertionError(
                f"d g_N / d x_s,{name} by finite differences is {fd[i]:.6g} at x_s = "
                f"({x_s[i, 0]:g}, {x_s[i, 1]:g}) but your n_{name} is {n[i, k]:.6g}: the "
                "variation of the gap is n . delta x_s, so g_N and n must belong together"
            )


def _segment_case():
    x_s, x_1, x_2 = np.array([0.35, 0.02]), np.array([0.0, 0.0]), np.array([1.0, 0.2])
    return x_s, x_1, x_2, 50.0


def _K_parts(x_s, x_1, x_2, c_N):
    from ...contact.kinematics import outer, segment_geometry, segment_vectors

    l, t, n, g_N, alpha = segment_geometry(x_s[None], x_1[None], x_2[None])
    N_s, N_0, T_s, T_0 = segment_vectors(t, n, alpha)
    t_N = c_N * min(g_N[0], 0.0)
    mat = c_N * outer(N_s, N_s)[0]
    geo = -t_N * ((outer(N_0, T_s) + outer(T_s, N_0))[0] / l[0] + g_N[0] / l[0] ** 2 * outer(N_0, N_0)[0])
    return mat, geo


def _residual_fd(x_s, x_1, x_2, c_N):
    from ...contact.kinematics import segment_geometry, segment_vectors

    def R(X):
        l, t, n, g_N, alpha = segment_geometry(X[None, 0:2], X[None, 2:4], X[None, 4:6])
        N_s = segment_vectors(t, n, alpha)[0]
        return c_N * np.minimum(g_N, 0.0)[0] * N_s[0]

    X0 = np.concatenate([x_s, x_1, x_2])
    h = 1e-7
    return np.stack([(R(X0 + h * e) - R(X0 - h * e)) / (2 * h) for e in np.eye(6)], axis=1)


def _K_student(normal_tangent):
    x_s, x_1, x_2, c_N = _segment_case()
    K = np.asarray(call(normal_tangent, "normal_tangent", x_s, x_1, x_2, c_N), dtype=float)
    if K.shape != (6, 6):
        raise AssertionError(
            f"normal_tangent should return the 6x6 matrix K_N (rows and columns s_x, s_y, 1_x, "
            f"1_y, 2_x, 2_y), it returned shape {K.shape}"
        )
    if not np.all(np.isfinite(K)):
        raise AssertionError("your K_N has entries that are not finite numbers")
    return K, (x_s, x_1, x_2, c_N)


LABELS6 = ["s_x", "s_y", "1_x", "1_y", "2_x", "2_y"]


def normal_tangent_fd(normal_tangent):
    K, case = _K_student(normal_tangent)
    fd = _residual_fd(*case)
    scale = np.abs(fd).max()
    if np.abs(K - fd).max() <= 1e-6 * scale:
        return
    mat, geo = _K_parts(*case)
    if np.abs(K - mat).max() <= 1e-6 * scale:
        raise AssertionError(
            "your K_N is c_N N_s N_s^T alone: the geometric part "
            "-t_N [(N_0 T_s^T + T_s N_0^T)/l + (g_N/l^2) N_0 N_0^T] of eq (33) is missing "
            "(it comes from the variation of N_s)"
        )
    if np.abs(K - (mat - geo)).max() <= 1e-6 * scale:
        raise AssertionError(
            "the geometric part of your K_N has the wrong sign: eq (33) has -t_N [...] with t_N < 0 in contact"
        )
    if np.abs(K - geo).max() <= 1e-6 * scale:
        raise AssertionError(
            "your K_N is the geometric part alone: the material part dt_N/dg_N N_s N_s^T "
            "(= c_N N_s N_s^T for the penalty law) is missing"
        )
    i, j = np.unravel_index(np.argmax(np.abs(K - fd)), K.shape)
    raise AssertionError(
        f"your K_N differs from the finite-difference Jacobian of R = t_N N_s: entry "
        f"({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, finite differences give {fd[i, j]:.6g}"
    )


def normal_tangent_material(normal_tangent):
    K, case = _K_student(normal_tangent)
    mat, geo = _K_parts(*case)
    x_s, x_1, x_2, c_N = case
    from ...contact.kinematics import segment_geometry, segment_vectors

    l, t, n, g_N, alpha = segment_geometry(x_s[None], x_1[None], x_2[None])
    N_s = segment_vectors(t, n, alpha)[0][0]
    got, want = N_s @ K @ N_s, N_s @ (mat + geo) @ N_s
    if not math.isclose(got, want, rel_tol=1e-6):
        raise AssertionError(
            f"N_s^T K_N N_s is {got:.6g}, expected {want:.6g} (off by a factor {got / want:.4g}): "
            "check the term dt_N/dg_N N_s N_s^T (dt_N/dg_N = c_N for the penalty law in contact)"
        )


def normal_tangent_symmetric(normal_tangent):
    K, _ = _K_student(normal_tangent)
    asym = np.abs(K - K.T).max()
    if asym > 1e-10 * max(np.abs(K).max(), 1e-300):
        i, j = np.unravel_index(np.argmax(np.abs(K - K.T)), K.shape)
        raise AssertionError(
            f"your K_N is not symmetric: entry ({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, "
            f"({LABELS6[j]}, {LABELS6[i]}) is {K[j, i]:.6g}; eq (33) is symmetric "
            "(N_0 T_s^T + T_s N_0^T, not N_0 T_s^T alone)"
        )


# -- lecture 03: the return mapping -----------------------------------------------------------


def _coulomb_ref(t_bar, dg, p, c_T, mu):
    from ...laws import Coulomb
    from ...laws.return_map import return_map

    fr = return_map(
        Coulomb(c_T=c_T, mu=mu), np.array([-p]), np.array([0.0]), np.array([dg]), np.array([t_bar]), np.array([0.0])
    )
    return float(fr.t_T[0]), float(fr.lam[0])


def _coulomb_student(coulomb_return, t_bar, dg, p, c_T=30.0, mu=0.3):
    out = call(coulomb_return, "coulomb_return", t_bar, dg, p, c_T, mu)
    t_T, lam = parts(out, 2, "coulomb_return", "t_T and lambda")
    try:
        return float(t_T), float(lam)
    except (TypeError, ValueError):
        raise AssertionError(f"coulomb_return should return two numbers (t_T, lambda), got {out!r:.80}") from None


def coulomb_stick(coulomb_return):
    for t_bar, dg, p in ((0.1, 0.002, 1.0), (-0.2, -0.001, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        at = {"t_bar": t_bar, "dg_T": dg, "p": p}
        compare(
            "t_T in stick (c_T = 30, mu = 0.3)",
            t_T,
            want,
            at,
            rule="in stick t_T is the trial traction t_bar + c_T dg_T, eq (42)",
        )
        compare("lambda in stick", lam, 0.0, at)


def coulomb_slip(coulomb_return):
    for t_bar, dg, p in ((0.2, 0.05, 1.0), (0.29, 0.1, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        compare("t_T in slip (c_T = 30, mu = 0.3)", t_T, want, {"t_bar": t_bar, "dg_T": dg, "p": p})


def coulomb_slip_backwards(coulomb_return):
    for t_bar, dg, p in ((0.2, -0.05, 1.0), (-0.1, -0.1, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        at = {"t_bar": t_bar, "dg_T": dg, "p": p}
        if math.isclose(t_T, -want, rel_tol=1e-8):
            raise AssertionError(
                f"your t_T is {t_T:.6g} at t_bar = {t_bar:g}, dg_T = {dg:g}, p = {p:g}, expected "
                f"{want:.6g}: the return goes along sign(t_tr), eq (43), here negative"
            )
        compare("t_T when sliding backwards", t_T, want, at)


def coulomb_lambda(coulomb_return):
    for t_bar, dg, p in ((0.2, 0.05, 1.0), (0.2, -0.05, 1.0), (0.29, 0.1, 2.0)):
        _, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        _, want = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        compare(
            "lambda in slip (c_T = 30)",
            lam,
            want,
            {"t_bar": t_bar, "dg_T": dg, "p": p},
            rule="lambda = (|t_tr| - Y) / c_T >= 0, eq (44)",
        )


def _moduli_cases():
    from ...laws import ParabolicSlip, PowerLaw, SlipHardening

    normal = PowerLaw(c_N=50.0, m=1.5)
    cases = []
    for law, t_bar, dg, g_N in (
        (ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5), 0.3, 0.05, -0.05),
        (SlipHardening(c_T=30.0, mu=0.3, h=2.0), 0.1, 0.08, -0.1),
        (SlipHardening(c_T=30.0, mu=0.3, h=2.0), -0.1, -0.08, -0.1),
        (SlipHardening(c_T=30.0, mu=0.4, h=-3.0), 0.0, 0.1, -0.08),
    ):
        cases.append((law, normal, t_bar, dg, g_N))
    return cases


def _moduli(slip_moduli, case):
    from ...laws.return_map import return_map

    law, normal, t_bar, dg, g_N = case
    t_N, dt_N = normal.traction(np.array([g_N]))
    fr = return_map(law, t_N, dt_N, np.array([dg]), np.array([t_bar]), np.array([0.0]))
    p = -t_N[0]
    t_tr = t_bar + law.c_T * dg
    _, Y_p, Y_q = law.slip_bound(np.array([p]), fr.q)
    args = (t_tr, law.c_T, float(Y_p[0]), float(Y_q[0]), float(dt_N[0]))
    out = call(slip_moduli, "slip_moduli", *args)
    c_T_s, c_N_s = parts(out, 2, "slip_moduli", "c_T^s and c_N^s")
    at = {"t_tr": args[0], "c_T": args[1], "Y_p": args[2], "Y_q": args[3], "dt_N/dg_N": args[4]}
    return float(np.asarray(c_T_s)), float(np.asarray(c_N_s)), float(fr.c_T_s[0]), float(fr.c_N_s[0]), at


def moduli_c_T(slip_moduli):
    for case in _moduli_cases():
        got, _, want, _, at = _moduli(slip_moduli, case)
        compare("c_T^s = dt_T/dg_T", got, want, at)


def moduli_c_N(slip_moduli):
    for case in _moduli_cases():
        _, got, _, want, at = _moduli(slip_moduli, case)
        compare("c_N^s = dt_T/dg_N", got, want, at, rule="dp/dg_N = -dt_N/dg_N")


# -- lecture 09: speed against accuracy -----------------------------------------------------------


def observed_order_exact(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    for p, C in ((2.0, 3.0), (1.0, 0.5)):
        got = call(observed_order, "observed_order", h, C * h**p)
        compare(f"observed order of e = {C:g} h^{p:g}", got, p, {"h": "0.1 ... 0.0125"}, rtol=1e-8)


def observed_order_least_squares(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125, 0.00625])
    e = 2.0 * h**1.5 * np.array([1.0, 1.3, 0.8, 1.1, 0.95])
    want = np.polyfit(np.log(h), np.log(e), 1)[0]
    got = call(observed_order, "observed_order", h, e)
    two = [
        np.log(e[-1] / e[0]) / np.log(h[-1] / h[0]),
        np.log(e[1] / e[0]) / np.log(h[1] / h[0]),
        np.log(e[-1] / e[-2]) / np.log(h[-1] / h[-2]),
    ]
    if any(math.isclose(float(got), t, rel_tol=1e-8) for t in two):
        raise AssertionError(
            f"your order {float(got):.4g} comes from two points only; fit a line through all "
            f"points of (log h, log e) by least squares (np.polyfit): {want:.4g}"
        )
    compare("observed order of noisy errors", got, want, {"h": "0.1 ... 0.00625"}, rtol=1e-8)


def observed_order_signed(observed_order):
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    e = -4.0 * h**2
    got = call(observed_order, "observed_order", h, e)
    if not np.isfinite(float(got)):
        raise AssertionError(
            "your order is not finite for negative errors e = -4 h^2: an error can be negative "
            "(too low); its size is |e|"
        )
    compare("observed order of e = -4 h^2", got, 2.0, {"h": "0.1 ... 0.0125"}, rtol=1e-8)


def convergence_order_linear(convergence_order):
    r = 0.5 ** np.arange(1, 8) * 3.0
    compare(
        "convergence order of r_k = 3 (1/2)^k",
        call(convergence_order, "convergence_order", r),
        1.0,
        {"r": "3/2, 3/4, ..."},
        rtol=1e-8,
    )


def convergence_order_quadratic(convergence_order):
    r = [0.5]
    for _ in range(4):
        r.append(r[-1] ** 2)
    got = call(convergence_order, "convergence_order", np.array(r))
    if math.isclose(float(got), 0.5, rel_tol=1e-8):
        raise AssertionError(
            "your order for r_(k+1) = r_k^2 is 0.5, the inverse of 2: the order is "
            "log(r_k+1 / r_k) / log(r_k / r_k-1) with the newest ratio on top"
        )
    compare("convergence order of r_(k+1) = r_k^2", got, 2.0, {"r": "0.5, 0.25, 0.0625, ..."}, rtol=1e-8)


def convergence_order_last(convergence_order):
    r = np.array([1.0, 0.5, 0.25, 0.125, 0.125**2, 0.125**4])
    got = call(convergence_order, "convergence_order", r)
    compare(
        "convergence order from the last three residuals of 1, 0.5, 0.25, 0.125, 0.125^2, 0.125^4",
        got,
        2.0,
        {"r": "..."},
        rtol=1e-8,
    )


# settings for a tolerance: the frictionless sloping impact, run to t = 4 (the rebound is over by 2.4)
TOLERANCE_END = 4.0
TOLERANCE_BUDGET = {0.05: 100, 0.01: 400}  # steps: a tolerance's settings may cost this much at most
TOLERANCE_REFERENCE = dict(c_N=5000.0, dt=0.004)  # 100 times the paper's penalty, a 25th of its step
_TOLERANCE_RUNS = {}


def tolerance_run(c_N, dt):
    """The frictionless sloping impact (fast preset) with c_N and dt to t = 4, warnings kept out (the
    check reads the accuracy section); run once per setting in this process."""
    import warnings

    from ...scenes import run_scene

    key = (float(c_N), float(dt))
    if key not in _TOLERANCE_RUNS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _TOLERANCE_RUNS[key] = run_scene(
                "sloping_impact",
                "fast",
                dict(c_N=key[0], dt=key[1], n_steps=max(1, round(TOLERANCE_END / key[1]))),
                error_bars=False,  # the exercise is about the indicators, not the bands (exercise 9.4)
            )
    return _TOLERANCE_RUNS[key]


def _tolerance_settings(settings_for, tol):
    out = call(settings_for, "settings_for", tol)
    if not isinstance(out, dict) or not {"dt", "c_N"} <= set(out):
        raise AssertionError(
            f"settings_for({tol:g}) should return a dict with the keys 'dt' and 'c_N', got {out!r:.80}"
        )
    try:
        dt, c_N = float(out["dt"]), float(out["c_N"])
    except (TypeError, ValueError):
        raise AssertionError(f"settings_for({tol:g}) should give numbers for dt and c_N, got {out!r:.80}") from None
    if not (math.isfinite(dt) and math.isfinite(c_N) and dt > 0 and c_N > 0):
        raise AssertionError(f"settings_for({tol:g}) gave dt = {dt:g}, c_N = {c_N:g}: both must be positive numbers")
    return dt, c_N, max(1, round(TOLERANCE_END / dt))


def _tolerance_checked(settings_for, tol):
    """The run of the student's settings at tol, within the budget (a run past it is not made)."""
    dt, c_N, steps = _tolerance_settings(settings_for, tol)
    budget = TOLERANCE_BUDGET[tol]
    if steps > budget:
        raise AssertionError(
            f"at tol = {tol:g} your dt = {dt:g} takes {steps} steps to t = {TOLERANCE_END:g}; the "
            f"budget is {budget} (dt >= {TOLERANCE_END / budget:g}): a step far smaller than the "
            "tolerance needs is work wasted; the run was not made"
        )
    try:
        return dt, c_N, tolerance_run(c_N, dt)
    except (ValueError, RuntimeError) as err:
        raise AssertionError(f"at tol = {tol:g} the run with dt = {dt:g}, c_N = {c_N:g} stopped: {err}") from None


def tolerance_indicators_at(settings_for, tol):
    dt, c_N, r = _tolerance_checked(settings_for, tol)
    past = [
        f"{k} = {v['value']:.3g} ({v['bound']} {v['threshold']:.3g})"
        for k, v in r["accuracy"].items()
        if isinstance(v, dict) and not v["ok"]
    ]
    if past:
        raise AssertionError(
            f"at tol = {tol:g} your settings dt = {dt:g}, c_N = {c_N:g} leave indicators past their "
            f"thresholds: {'; '.join(past)}. Read r['accuracy'][name]['what'] and ['source']: which "
            "setting moves each one?"
        )


def tolerance_error_at(settings_for, tol):
    dt, c_N, r = _tolerance_checked(settings_for, tol)
    ref = tolerance_run(**TOLERANCE_REFERENCE)["rebound_vy"]
    err = abs(r["rebound_vy"] - ref) / abs(ref)
    if not err <= tol:
        raise AssertionError(
            f"at tol = {tol:g} your settings dt = {dt:g}, c_N = {c_N:g} give a rebound v_y = "
            f"{r['rebound_vy']:.4f}, {100 * err:.2g} % off the reference {ref:.4f} (c_N = "
            f"{TOLERANCE_REFERENCE['c_N']:g}, dt = {TOLERANCE_REFERENCE['dt']:g}): more than the "
            "tolerance. Which error is it: the step's (Newmark damps the rebound) or the penalty's?"
        )


def tolerance_budget_at(settings_for, tol):
    _tolerance_checked(settings_for, tol)


def tolerance_indicators(settings_for):
    tolerance_indicators_at(settings_for, 0.05)


def tolerance_error(settings_for):
    tolerance_error_at(settings_for, 0.05)


def tolerance_budget(settings_for):
    tolerance_budget_at(settings_for, 0.05)


# an error band by hand (ex09_band_by_hand): three levels finest first, ratio r, the scheme's order; the
# answer against the library's own estimate (contactfem.problem.uncertainty.estimate)


def _band_case(f_exact, C, p, r, h=0.05):
    return tuple(f_exact + C * (h * r**k) ** p for k in range(3))


def _band(band_from_three, f, r, p_th):
    got = parts(call(band_from_three, "band_from_three", *f, r, p_th), 3, "band_from_three", "p, f_extrapolated, band")
    return [float(x) for x in got]


def _library_band(f, r, p_th, h=0.05):
    from ...problem.uncertainty import estimate

    return estimate([(h * r**k, v) for k, v in enumerate(f)], p_th)


def band_order(band_from_three):
    for f_exact, C, p, r in ((2.0, 0.3, 1.7, 2.0), (-1.0, -4.0, 0.8, 1.5)):
        f = _band_case(f_exact, C, p, r)
        got = _band(band_from_three, f, r, 1.0)[0]
        if math.isclose(got, -p, rel_tol=1e-6):
            raise AssertionError(
                f"your order for f = {f_exact:g} + {C:g} h^{p:g} is {got:.4g}, its negative: p = ln(e32 / e21) / ln r "
                "with e21 = f2 - f1, e32 = f3 - f2 (f1 the finest)"
            )
        compare(
            f"observed order of f = {f_exact:g} + {C:g} h^{p:g}, r = {r:g}",
            got,
            p,
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
        )


def band_richardson(band_from_three):
    for f_exact, C, p, r in ((2.0, 0.3, 1.7, 2.0), (-1.0, -4.0, 0.8, 1.5)):
        f = _band_case(f_exact, C, p, r)
        got = _band(band_from_three, f, r, 1.0)[1]
        if math.isclose(got, 2 * f[0] - f_exact, rel_tol=1e-8):
            raise AssertionError(
                "your extrapolated value is f1 + delta: delta = e21 / (r^p - 1) is f2's lead over f1 scaled down, "
                "and the limit lies on the other side of f1 from f2 (f1 - delta)"
            )
        compare(
            f"Richardson's value of f = {f_exact:g} + {C:g} h^{p:g}",
            got,
            f_exact,
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
        )


def band_factor_of_safety(band_from_three):
    for f, r, p_th in (((1.0, 1.06, 1.14), 2.0, 2.0), ((1.0, 1.01, 1.05), 2.0, 1.0)):  # P < 1, then P > 1
        got = _band(band_from_three, f, r, p_th)[2]
        want = _library_band(f, r, p_th)
        compare(
            f"the band of the levels {f} (r = {r:g}, p_th = {p_th:g}; P = {want['P']:.3g})",
            got,
            want["band"],
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
            rule="FS(P) |delta|, FS = 1.6 P + 2.45 (1 - P) for P <= 1, 1.6 P + 2.45 (P - 1) above",
        )


# -- lecture 10: your own law ------------------------------------------------------------------


def _hardening(LinearHardening):
    defined(LinearHardening, "LinearHardening", "class")
    try:
        law = LinearHardening(c_T=30.0, mu_0=0.3, h=0.5)
    except Exception as err:
        raise AssertionError(f"LinearHardening(c_T=30.0, mu_0=0.3, h=0.5) raised {type(err).__name__}: {err}") from None
    p = np.array([0.5, 1.0, 2.0, 0.5, 1.0, 2.0])
    q = np.array([0.0, 0.0, 0.0, 0.2, 0.4, 0.8])
    out = call(law.slip_bound, "LinearHardening(c_T=30.0, mu_0=0.3, h=0.5).slip_bound", p, q)
    Y, Y_p, Y_q = parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")
    return law, p, q, Y, Y_p, Y_q


def hardening_bound(LinearHardening):
    law, p, q, Y, Y_p, Y_q = _hardening(LinearHardening)
    compare("Y (mu_0 = 0.3, h = 0.5)", Y, (0.3 + 0.5 * q) * p, {"p": p, "q": q})


def hardening_derivatives(LinearHardening):
    law, p, q, Y, Y_p, Y_q = _hardening(LinearHardening)
    compare("dY/dp", Y_p, 0.3 + 0.5 * q + 0 * p, {"p": p, "q": q})
    compare("dY/dq", Y_q, 0.5 * p, {"p": p, "q": q})


def hardening_check_law(LinearHardening):
    from ...laws.check import check_law

    law = _hardening(LinearHardening)[0]
    report = check_law(law)
    if not report.ok:
        raise AssertionError(
            "check_law(LinearHardening(c_T=30.0, mu_0=0.3, h=0.5)) fails: "
            + [s for ok, s in report.checks if not ok][0]
        )


def _cubic(QuadraticNormal):
    defined(QuadraticNormal, "QuadraticNormal", "class")
    try:
        law = QuadraticNormal(c_N=200.0)
    except Exception as err:
        raise AssertionError(f"QuadraticNormal(c_N=200.0) raised {type(err).__name__}: {err}") from None
    return law


def quadratic_traction(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    g = np.array([0.05, 0.0, -0.01, -0.1, -0.3])
    out = call(law.traction, "QuadraticNormal(c_N=200.0).traction", g)
    t_N, dt_N = parts(out, 2, "traction", "t_N and dt_N/dg_N")
    compare("t_N (c_N = 200)", t_N, np.where(g < 0, -200.0 * g**2, 0.0), {"g_N": g})
    compare("dt_N/dg_N (c_N = 200)", dt_N, np.where(g < 0, -400.0 * g, 0.0), {"g_N": g})


def quadratic_energy(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    if not callable(getattr(law, "energy", None)):
        raise AssertionError("QuadraticNormal needs a method energy(self, g_N): the stored energy of the interface")
    g = np.array([0.05, 0.0, -0.01, -0.1, -0.3])
    E = np.asarray(call(law.energy, "QuadraticNormal(c_N=200.0).energy", g), dtype=float)
    compare("energy for an open gap", E[:2], np.zeros(2), {"g_N": g[:2]})
    if np.any(E[2:] < 0):
        raise AssertionError("your energy is negative in contact: the interface stores energy, >= 0")


def quadratic_energy_gradient(QuadraticNormal):
    law = _cubic(QuadraticNormal)
    g = np.array([-0.01, -0.1, -0.3])
    h = 1e-6
    E = lambda x: np.asarray(call(law.energy, "QuadraticNormal(c_N=200.0).energy", x), dtype=float)
    fd = (E(g + h) - E(g - h)) / (2 * h)
    t_N = -200.0 * g**2
    compare(
        "d energy / d g_N (finite differences of your energy)",
        fd,
        t_N,
        {"g_N": g},
        rtol=1e-5,
        rule="the energy's derivative is the traction t_N",
    )


# -- lecture 11: where the 1990 method stops -------------------------------------------------------


def _uzawa_ref(k, P, g0, c_N, tol, max_updates=200):
    lam, n = 0.0, 0
    while True:
        u = (P + c_N * g0 + lam) / (k + c_N)
        if lam + c_N * (g0 - u) >= 0:  # open
            u = P / k
        g = g0 - u
        t = min(0.0, lam + c_N * g)
        if abs(g) <= tol or n >= max_updates:
            return u, t, n
        lam, n = t, n + 1


def _uzawa(uzawa_1dof, k, P, g0, c_N, tol):
    out = call(uzawa_1dof, "uzawa_1dof", k, P, g0, c_N, tol)
    u, lam, n = parts(out, 3, "uzawa_1dof", "u, lambda and the number of updates")
    try:
        return float(u), float(lam), int(n)
    except (TypeError, ValueError):
        raise AssertionError(f"uzawa_1dof should return (u, lambda, updates): numbers, got {out!r:.80}") from None


UZAWA_CASES = ((100.0, 10.0, 0.05, 1000.0, 1e-10), (100.0, 10.0, 0.05, 100.0, 1e-10), (10.0, 5.0, 0.1, 1e4, 1e-12))


def uzawa_gap(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        g = g0 - u
        if abs(g) > 10 * tol:
            pen = _uzawa_ref(k, P, g0, c_N, tol, max_updates=0)[0]
            extra = " (that is the penalty solution: the multiplier never entered)" if math.isclose(u, pen) else ""
            raise AssertionError(
                f"at k = {k:g}, P = {P:g}, g0 = {g0:g}, c_N = {c_N:g}, tol = {tol:g} your final gap "
                f"is {g:.3g}{extra}: update lambda <- min(0, lambda + c_N g) and solve again "
                "until |g| <= tol"
            )


def uzawa_multiplier(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        compare(
            "lambda, the contact traction",
            lam,
            k * g0 - P,
            {"k": k, "P": P, "g0": g0, "c_N": c_N},
            rtol=1e-6,
            atol=1e-8,
        )


def uzawa_updates(uzawa_1dof):
    for k, P, g0, c_N, tol in UZAWA_CASES:
        _, _, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
        want = _uzawa_ref(k, P, g0, c_N, tol)[2]
        if abs(n - want) > 1:
            raise AssertionError(
                f"your loop made {n} multiplier updates at k = {k:g}, c_N = {c_N:g}, tol = {tol:g}; "
                f"{want} suffice (each shrinks the gap by k/(k + c_N) = {k / (k + c_N):.3g})"
            )


def _secant(secant_traction, law, g0, g1):
    return float(np.asarray(call(secant_traction, "secant_traction", law, g0, g1), dtype=float))


def secant_energy(secant_traction):
    from ...laws import PowerLaw

    for law in (PowerLaw(c_N=100.0, m=1.0), PowerLaw(c_N=100.0, m=2.5)):
        for g0, g1 in ((0.02, -0.03), (-0.01, -0.05), (-0.04, 0.01), (-0.02, -0.01)):
            F = _secant(secant_traction, law, g0, g1)
            want = float((law.energy(np.array([g1])) - law.energy(np.array([g0])))[0] / (g1 - g0))
            compare(
                f"secant traction of {law!r}",
                F,
                want,
                {"g0": g0, "g1": g1},
                rule="F (g1 - g0) must equal energy(g1) - energy(g0)",
            )


def secant_limit(secant_traction):
    from ...laws import PowerLaw

    law = PowerLaw(c_N=100.0, m=2.5)
    for g in (-0.03, 0.01):
        F = _secant(secant_traction, law, g, g)
        want = float(law.traction(np.array([g]))[0][0])
        if not np.isfinite(F):
            raise AssertionError(
                f"your secant traction is {F} for g0 = g1 = {g:g}: when the gap does not change, "
                "use the limit, the traction t_N(g) itself"
            )
        compare("secant traction for g0 = g1", F, want, {"g": g})


# -- the answers that run a scene: computed once per answer ----------------------------------------

_MEMO = {}


def memo(key, thunk):
    """thunk() once per key (the student's function and its arguments): the parts of an
    exercise that run a time loop share one run; a failure is remembered as well."""
    if key not in _MEMO:
        try:
            _MEMO[key] = (True, thunk())
        except AssertionError as err:
            _MEMO[key] = (False, err)
    ok, value = _MEMO[key]
    if not ok:
        raise AssertionError(str(value))
    return value


def _scene_model(name, overrides):
    """A fresh model of a scene (its build, fast preset): stepper, schedule, u0, v0 of its stage."""
    from ...scenes import get_scene

    scene = get_scene(name)
    params = scene.resolve("fast", overrides)
    return scene.build(params), params


def _counts(rec):
    """(nodes in contact, nodes slipping) of a record's first converged contact state."""
    from ...laws.return_map import OPEN, SLIP

    st = rec.contacts[0]
    return int(np.count_nonzero(st.slip != OPEN)), int(np.count_nonzero(st.slip == SLIP))


def _as_list(out, n, name, what):
    values = [np.asarray(v, dtype=float).ravel() for v in parts(out, n, name, what)]
    sizes = {v.size for v in values}
    if len(sizes) != 1:
        raise AssertionError(
            f"{name} should return {n} arrays of one length (one entry per step), "
            f"got lengths {[v.size for v in values]}"
        )
    return values


# -- lecture 04: the block ------------------------------------------------------------------------


def _margin_cases():
    from ...laws import Coulomb, ParabolicSlip

    t_N = -np.array([10.0, 40.0, 90.0, 160.0, 250.0, 2.0])
    t_T = np.array([5.0, -14.0, 20.0, -30.0, 80.0, 1.0])
    return t_N, t_T, (ParabolicSlip(c_T=1e4, alpha=0.2, beta=0.3, n=0.5), Coulomb(c_T=1e4, mu=0.3))


def _margin(slip_margin, t_N, t_T, law):
    return np.asarray(call(slip_margin, "slip_margin", t_N, t_T, law), dtype=float)


def margin_parabolic(slip_margin):
    t_N, t_T, (law, _) = _margin_cases()
    want = np.abs(t_T) - law.slip_bound(-t_N, 0 * t_N)[0]
    got = _margin(slip_margin, t_N, t_T, law)
    at = {"t_N": t_N, "t_T": t_T}
    if got.shape == want.shape and np.allclose(got, t_T - law.slip_bound(-t_N, 0 * t_N)[0]):
        raise AssertionError(
            "your f is wrong where t_T < 0: the slip condition bounds the size of the "
            "friction traction, f = |t_T| - Y(|t_N|)"
        )
    compare(
        "f = |t_T| - Y(|t_N|) (parabolic law, n = 0.5)",
        got,
        want,
        at,
        rule="Y(p) = law.slip_bound(p, q)[0] with the pressure p = |t_N| = -t_N and q = 0",
    )


def margin_coulomb(slip_margin):
    t_N, t_T, (_, law) = _margin_cases()
    got = _margin(slip_margin, t_N, t_T, law)
    compare(
        "f = |t_T| - mu |t_N| (Coulomb, mu = 0.3)",
        got,
        np.abs(t_T) + 0.3 * t_N,
        {"t_N": t_N, "t_T": t_T},
        rule="the pressure is |t_N| = -t_N > 0 in contact",
    )


def margin_block(slip_margin):
    """On the block's converged state: f <= 0 everywhere and f = 0 at the slipping nodes."""
    from ...laws.return_map import SLIP

    def run():
        from ...solver.march import march
        from ...scenes.block import friction_law

        model, P = _scene_model("block", {"law": "conical"})
        st = model.stage
        last = list(march(st.stepper, st.schedule, st.t0, st.u0))[-1].contacts[0]
        return last, friction_law(P)

    state, law = memo(("block", "conical"), run)
    f = _margin(slip_margin, state.t_N, state.t_T, law)
    scale = float(np.max(np.abs(state.t_N)))
    slip = state.slip == SLIP
    if f.shape != slip.shape:
        raise AssertionError(f"slip_margin should return one value per node, {slip.size} here, got shape {f.shape}")
    if np.max(f) > 1e-9 * scale:
        i = int(np.argmax(f))
        raise AssertionError(
            f"on the converged block your f is {f[i]:.4g} > 0 at x = {state.x_s[i, 0]:.3g}: "
            "a converged state never violates its slip condition; check |t_N| and the law"
        )
    if np.any(np.abs(f[slip]) > 1e-9 * scale):
        raise AssertionError(
            "on the converged block your f is not 0 at the slipping nodes: a slipping node "
            "sits on its slip surface, |t_T| = Y(|t_N|)"
        )


def _load_steps(load_steps, n):
    def run():
        model, _ = _scene_model("block", {"law": "conical"})
        return call(load_steps, "load_steps", model.parts["stepper"], n, timeout=60.0)

    out = memo(("load_steps", load_steps, n), run)
    return _as_list(out, 3, "load_steps", "the pseudo-times, the linear solves and the slipping nodes of each step")


def _load_steps_ref(n):
    def run():
        from ...solver import Steps
        from ...solver.march import march

        model, _ = _scene_model("block", {"law": "conical"})
        recs = list(march(model.parts["stepper"], Steps(1.0 / n, n_steps=n), 0.0, np.zeros(model.system.ndof)))[1:]
        return (
            np.array([r.t for r in recs]),
            np.array([r.iterations for r in recs], float),
            np.array([_counts(r)[1] for r in recs], float),
            np.array([_counts(r)[0] for r in recs], float),
        )

    return memo(("load_steps_ref", n), run)


def load_steps_times(load_steps):
    t, _, _ = _load_steps(load_steps, 4)
    want = _load_steps_ref(4)[0]
    if t.size == want.size + 1 and t[0] == 0.0:
        raise AssertionError(
            "your lists have 5 entries for 4 load steps: the first record of march is the "
            "initial state (k = 0, t = 0); keep the records with k >= 1"
        )
    if t.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {t.size}")
    compare("pseudo-time of each load step", t, want, {"step": np.arange(1, 5)}, rule="Steps(1 / n, n_steps=n)")


def load_steps_solves(load_steps):
    _, its, _ = _load_steps(load_steps, 4)
    want = _load_steps_ref(4)[1]
    if its.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {its.size}")
    compare(
        "linear solves of each load step", its, want, {"step": np.arange(1, 5)}, rule="rec.iterations of each record"
    )


def load_steps_slipping(load_steps):
    _, _, slip = _load_steps(load_steps, 4)
    _, _, want, contact = _load_steps_ref(4)
    if slip.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {slip.size}")
    if np.allclose(slip, contact) and not np.allclose(slip, want):
        raise AssertionError(
            "your counts are the nodes in contact, not the slipping ones: count the nodes "
            "whose state is SLIP (rec.contacts[0].slip == SLIP, or rec.contacts[0].n_slip)"
        )
    if np.allclose(slip, contact - want) and not np.allclose(slip, want):
        raise AssertionError("your counts are the sticking nodes: count the nodes whose state is SLIP")
    compare(
        "slipping nodes after each load step",
        slip,
        want,
        {"step": np.arange(1, 5)},
        rule="read them from the record's converged state, rec.contacts[0].slip == SLIP",
    )


def load_steps_one(load_steps):
    t, its, slip = _load_steps(load_steps, 1)
    want = _load_steps_ref(1)
    compare(
        "the whole load in one step: (t, solves, slipping nodes)",
        np.r_[t, its, slip],
        np.r_[want[0], want[1], want[2]],
        {"entry": ["t", "solves", "slipping"]},
        rule="n = 1 is the paper's single step",
    )


# -- lecture 05: the rolling ring -------------------------------------------------------------------

ROLLING_CASES = (
    (300.0, 0.15, 981.0, 50.0, 2500.0),
    (300.0, 0.15, 981.0, 50.0, 1250.0),
    (200.0, 0.3, 981.0, 55.0, 2700.0),
)


def _rolling(rolling_point):
    out = []
    for v0, mu, g, a, k2 in ROLLING_CASES:
        got = parts(call(rolling_point, "rolling_point", v0, mu, g, a, k2), 3, "rolling_point", "t*, x*, v*")
        try:
            got = [float(np.asarray(x)) for x in got]
        except (TypeError, ValueError):
            raise AssertionError(f"rolling_point should return three numbers (t*, x*, v*), got {got!r:.80}") from None
        out.append(got)
    from ...scenes.rings import rigid_ring_exact

    ref = [rigid_ring_exact(v0, mu, g, a, k2) for v0, mu, g, a, k2 in ROLLING_CASES]
    at = {
        "v0": [c[0] for c in ROLLING_CASES],
        "mu": [c[1] for c in ROLLING_CASES],
        "a": [c[3] for c in ROLLING_CASES],
        "k^2": [c[4] for c in ROLLING_CASES],
    }
    return np.array(out), ref, at


def rolling_time(rolling_point):
    got, ref, at = _rolling(rolling_point)
    want = np.array([r["t_star"] for r in ref])
    no_spin = np.array([c[0] / (c[1] * c[2]) for c in ROLLING_CASES])
    if np.allclose(got[:, 0], no_spin):
        raise AssertionError(
            "your t* = v0 / (mu g) is when the centre would stop; rolling starts earlier, when "
            "the contact point stops: v(t) + omega(t) a = 0 with omega spun up by the friction "
            "torque, t* = v0 / (mu g (1 + a^2/k^2))"
        )
    compare("t* (the start of rolling)", got[:, 0], want, at, rule="t* = v0 / (mu g (1 + a^2/k^2))")


def rolling_position(rolling_point):
    got, ref, at = _rolling(rolling_point)
    compare(
        "x* (the centre when rolling starts)",
        got[:, 1],
        np.array([r["x_star"] for r in ref]),
        at,
        rule="x* = v0 t* - mu g t*^2 / 2 (uniform deceleration mu g while sliding)",
    )


def rolling_speed(rolling_point):
    got, ref, at = _rolling(rolling_point)
    compare(
        "v* (the rolling speed)",
        got[:, 2],
        np.array([r["v_star"] for r in ref]),
        at,
        rule="v* = v0 - mu g t*; for the thin hoop (k = a) v* = v0 / 2",
    )


def _incline(ring_on_incline, theta, mu):
    def run():
        out = call(ring_on_incline, "ring_on_incline", theta, mu, timeout=120.0)
        t, s = _as_list(out, 2, "ring_on_incline", "the times and the centre's travel down the slope")
        return t, s

    return memo(("incline", ring_on_incline, theta, mu), run)


def _acceleration(t, s):
    """The centre's acceleration along the slope: s = s0 + v0 t + a t^2 / 2 by least squares."""
    return 2.0 * np.polyfit(t, s, 2)[0]


def incline_start(ring_on_incline):
    t, s = _incline(ring_on_incline, 20.0, 0.5)
    if t.size < 10:
        raise AssertionError(f"ring_on_incline should return one time and one travel per record, got {t.size}")
    if abs(t[0]) > 1e-12 or abs(s[0]) > 1e-9:
        raise AssertionError(
            f"the first record is the initial state: t = 0 and no travel yet; yours has t = {t[0]:.3g}, "
            f"s = {s[0]:.3g} (measure s from the centre's initial position)"
        )
    if s[-1] <= 0:
        raise AssertionError(
            f"your travel at the end is {s[-1]:.3g} <= 0: s is the distance the centre has moved "
            "DOWN the slope, (x_c(t) - x_c(0)) . d with d = (-cos theta, -sin theta) for a plane "
            "rising to the right"
        )


def _incline_verdict(what, a, want, theta, mu, rtol):
    g = 981.0
    th = np.radians(theta)
    others = {
        "a ring sliding without friction, g sin(theta)": g * np.sin(th),
        "a ring sliding with friction, g (sin(theta) - mu cos(theta))": g * (np.sin(th) - mu * np.cos(th)),
        "a hoop rolling without slip, g sin(theta) / 2": g * np.sin(th) / 2,
        "a free fall, g": g,
    }
    if abs(a / want - 1) <= rtol:
        return
    close = [k for k, v in others.items() if v > 0 and abs(a / v - 1) <= rtol]
    hint = f" (that is {close[0]})" if close else ""
    raise AssertionError(
        f"at theta = {theta:g} deg, mu = {mu:g} your ring's acceleration along the slope is "
        f"{a:.4g} cm/s^2{hint}; {what} gives {want:.4g} (within {100 * rtol:g} %): check the "
        "plane's normal (towards the ring), gravity (down, -y), the friction law and its mu"
    )


def incline_rolling(ring_on_incline):
    """tan(20 deg) = 0.36 <= 2 mu = 1: the hoop rolls, a = g sin(theta) / 2. The scene's ring on
    its fast mesh (40 beam elements, dt = 0.02) gives +0.8 % (its polygon rocks over its corners,
    its stick springs settle at the start): 5 % leaves room for another ring of this lecture
    and is far from every other motion (sliding: twice that)."""
    t, s = _incline(ring_on_incline, 20.0, 0.5)
    _incline_verdict("rolling without slip", _acceleration(t, s), 981.0 * np.sin(np.radians(20.0)) / 2, 20.0, 0.5, 0.05)


def incline_sliding(ring_on_incline):
    """tan(30 deg) = 0.58 > 2 mu = 0.3: the ring slides all the way, a = g (sin - mu cos), a
    constant friction force: the fast ring gives +0.5 %, checked to 3 %."""
    th = np.radians(30.0)
    t, s = _incline(ring_on_incline, 30.0, 0.15)
    _incline_verdict(
        "sliding with Coulomb friction", _acceleration(t, s), 981.0 * (np.sin(th) - 0.15 * np.cos(th)), 30.0, 0.15, 0.03
    )


# -- lecture 06: the sloping impact -----------------------------------------------------------------


def _rebound_case(k_last=6, n=12):
    """A centre-of-mass history: flying in at (2, -2), in contact for records 3..k_last, then
    leaving at (1.2, 1.7) and slowly drifting (a vibrating ring's centre is not exactly constant)."""
    v = np.zeros((n, 2))
    v[:3] = (2.0, -2.0)
    v[3 : k_last + 1] = np.linspace([1.8, -1.0], [1.3, 1.5], k_last - 2)
    v[k_last + 1 :] = (1.2, 1.7) + 0.01 * np.arange(n - k_last - 1)[:, None]
    contact = np.zeros(n, bool)
    contact[3 : k_last + 1] = True
    return v, contact


def _rebound_call(rebound, v, contact):
    return call(rebound, "rebound", v, contact)


def rebound_velocity(rebound):
    v, contact = _rebound_case()
    out = parts(_rebound_call(rebound, v, contact), 3, "rebound", "v_x, v_y and the angle")
    got = np.array([float(np.asarray(x)) for x in out[:2]])
    if np.allclose(got, v[-1]):
        raise AssertionError(
            "your rebound velocity is the last record's: take the first record after the last "
            "one in contact (the ring has just left the plane)"
        )
    compare(
        "rebound velocity (v_x, v_y)",
        got,
        v[7],
        {"component": ["v_x", "v_y"]},
        rule="the centre's velocity at the first record after the last record in contact",
    )


def rebound_angle(rebound):
    v, contact = _rebound_case()
    out = parts(_rebound_call(rebound, v, contact), 3, "rebound", "v_x, v_y and the angle")
    angle = float(np.asarray(out[2]))
    vx, vy = v[7]
    want = float(np.degrees(np.arctan2(abs(vx), abs(vy))))
    if math.isclose(angle, 90.0 - want, rel_tol=1e-6):
        raise AssertionError(
            f"your angle {angle:.4g} deg is measured from the plane; Table 2's angle of reflection "
            f"is measured from the normal: atan(|v_x| / |v_y|) = {want:.4g} deg"
        )
    if math.isclose(angle, np.radians(want), rel_tol=1e-6):
        raise AssertionError(f"your angle {angle:.4g} is in radians: give degrees (np.degrees)")
    compare(
        "angle of reflection (deg)",
        angle,
        want,
        {"v": f"({vx:g}, {vy:g})"},
        rule="atan(|v_x| / |v_y|), from the normal, in degrees",
    )


def rebound_none(rebound):
    v, contact = _rebound_case()
    contact[-1] = True
    out = call(rebound, "rebound", v, contact)
    if not (isinstance(out, tuple) and len(out) == 3 and all(x is None for x in out)):
        raise AssertionError(
            "when the ring is still in contact at the last record it has not rebounded: "
            f"return (None, None, None); yours returned {out!r:.80}"
        )


def _energy_cases():
    g = np.array([-0.02, -0.1, 0.05, -0.3, 0.0, -0.05])
    t_T = np.array([0.3, -1.2, 0.0, 2.0, 0.0, -0.4])
    w = np.array([1.0, 0.5, 1.0, 2.0, 1.0, 1.5])
    return g, t_T, w


def _interface(interface_energy, g, t_T, w, c_N, m, c_T):
    out = call(interface_energy, "interface_energy", g, t_T, w, c_N, m, c_T)
    try:
        return float(np.asarray(out, dtype=float))
    except (TypeError, ValueError):
        raise AssertionError(
            f"interface_energy should return one number (the sum over the nodes), got {out!r:.80}"
        ) from None


def _energy_ref(g, t_T, w, c_N, m, c_T):
    from ...laws import PowerLaw

    W = PowerLaw(c_N=c_N, m=m).energy(g)
    return float(np.sum(w * (W + (t_T**2 / (2 * c_T) if c_T else 0.0))))


def energy_normal(interface_energy):
    g, t_T, w = _energy_cases()
    for m in (1.0, 1.5):
        got = _interface(interface_energy, g, 0 * t_T, w, 50.0, m, 30.0)
        want = _energy_ref(g, 0 * t_T, w, 50.0, m, 30.0)
        if math.isclose(got, (m + 1) * want, rel_tol=1e-8):
            raise AssertionError(
                f"your normal energy is (m + 1) times too large (m = {m:g}): the potential of "
                "t_N = -c_N (-g_N)^m is c_N (-g_N)^(m+1) / (m + 1)"
            )
        if math.isclose(got, float(np.sum(_power_energy(g, 50.0, m))), rel_tol=1e-8) and not np.allclose(w, 1):
            raise AssertionError("your energy leaves out the weights: each node's energy counts with its weight w")
        compare(
            f"interface energy without friction (c_N = 50, m = {m:g})",
            got,
            want,
            {"g_N": "-0.02 ... -0.3"},
            rule="sum_i w_i c_N (-g_N,i)^(m+1) / (m + 1) over the nodes in contact (g_N < 0)",
        )


def _power_energy(g, c_N, m):
    """The potential of eq (4) per node, without weights."""
    return np.where(g < 0, c_N * np.abs(np.minimum(g, 0)) ** (m + 1) / (m + 1), 0.0)


def energy_open(interface_energy):
    g = np.array([0.05, 0.2, 0.0])
    got = _interface(interface_energy, g, np.zeros(3), np.ones(3), 50.0, 1.0, 30.0)
    compare(
        "interface energy of open nodes",
        got,
        0.0,
        {"g_N": "0.05, 0.2, 0"},
        rule="an open node (g_N >= 0) stores no energy: use np.where(g_N < 0, ..., 0)",
    )


def energy_friction(interface_energy):
    g, t_T, w = _energy_cases()
    got = _interface(interface_energy, g, t_T, w, 50.0, 1.0, 30.0)
    want = _energy_ref(g, t_T, w, 50.0, 1.0, 30.0)
    normal = _energy_ref(g, 0 * t_T, w, 50.0, 1.0, 30.0)
    if math.isclose(got, normal, rel_tol=1e-8):
        raise AssertionError(
            "your energy leaves out the stick springs: a node in stick stores t_T^2 / (2 c_T) (eq 5: t_T = c_T g_T^e)"
        )
    compare(
        "interface energy with friction (c_T = 30)",
        got,
        want,
        {"t_T": "0.3 ... -0.4"},
        rule="add sum_i w_i t_T,i^2 / (2 c_T), the energy of the stick springs",
    )


# -- lecture 07: the funnel ----------------------------------------------------------------------


def _escape(escape_angle, p, alpha=0.3, beta=0.1, n=0.75):
    return np.asarray(call(escape_angle, "escape_angle", p, alpha, beta, n), dtype=float)


def escape_values(escape_angle):
    p = np.array([0.05, 0.1, 0.3, 1.0, 3.0])
    want = np.degrees(np.arctan(0.3 * p**-0.25 + 0.1))
    got = _escape(escape_angle, p)
    if got.shape == want.shape and np.allclose(got, np.radians(want)):
        raise AssertionError("your angles are in radians: give degrees (np.degrees)")
    if got.shape == want.shape and np.allclose(got, np.full(p.shape, np.degrees(np.arctan(0.4)))):
        raise AssertionError(
            "your angle does not depend on the pressure: with eq 10 the coefficient is "
            "mu_eff = Y / p = alpha p^(n-1) + beta, not alpha + beta"
        )
    compare(
        "escape angle (deg; alpha = 0.3, beta = 0.1, n = 0.75)",
        got,
        want,
        {"p": p},
        rule="tan(phi) = mu_eff(p) = alpha p^(n-1) + beta",
    )


def escape_coulomb(escape_angle):
    p = np.array([0.1, 1.0, 10.0])
    got = _escape(escape_angle, p, alpha=0.0, beta=0.3, n=1.0)
    compare(
        "escape angle for Coulomb mu = 0.3 (alpha = 0, n = 1)",
        got,
        np.full(3, np.degrees(np.arctan(0.3))),
        {"p": p},
        rule="tan(phi) = mu whatever the pressure",
    )


def escape_steeper(escape_angle):
    lo, hi = _escape(escape_angle, np.array([0.05])), _escape(escape_angle, np.array([1.0]))
    if not float(np.ravel(lo)[0]) > float(np.ravel(hi)[0]):
        raise AssertionError(
            "with n = 0.75 < 1 the effective coefficient falls as the pressure rises, so a lightly "
            "pressed ring holds at a steeper wall: your angle at p = 0.05 should exceed that at p = 1"
        )


def _census(census):
    def run():
        model, _ = _scene_model("funnel", {"variant": "frictional"})
        st = model.stage
        return call(census, "census", st.stepper, st.schedule, st.u0, st.v0, timeout=120.0)

    out = memo(("census", census), run)
    return _as_list(out, 3, "census", "the times, the nodes in contact and the slipping nodes of each record")


def _census_ref():
    def run():
        from ...solver.march import march

        model, _ = _scene_model("funnel", {"variant": "frictional"})
        st = model.stage
        recs = list(march(st.stepper, st.schedule, st.t0, st.u0, st.v0))
        c = np.array([_counts(r) for r in recs], float)
        return np.array([r.t for r in recs]), c[:, 0], c[:, 1]

    return memo(("census_ref",), run)


def census_times(census):
    t, _, _ = _census(census)
    want = _census_ref()[0]
    if t.size == want.size - 1:
        raise AssertionError(
            f"your census has {t.size} entries, the run {want.size} records: keep the initial state (record 0) too"
        )
    if t.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {t.size}")
    compare("time of each record", t, want, {"record": np.arange(t.size)})


def census_contact(census):
    _, n_c, _ = _census(census)
    _, want, slip = _census_ref()
    if n_c.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {n_c.size}")
    if np.allclose(n_c, slip) and not np.allclose(n_c, want):
        raise AssertionError(
            "your contact counts are the slipping nodes: a node is in contact when its state "
            "is not OPEN (stick or slip)"
        )
    compare(
        "nodes in contact",
        n_c,
        want,
        {"record": np.arange(n_c.size)},
        rule="rec.contacts[0].slip != OPEN, from the record's converged state",
    )


def census_slip(census):
    _, n_c, n_s = _census(census)
    _, contact, want = _census_ref()
    if n_s.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {n_s.size}")
    if np.allclose(n_s, contact - want) and not np.allclose(n_s, want):
        raise AssertionError("your slip counts are the sticking nodes: count the state SLIP")
    compare(
        "slipping nodes",
        n_s,
        want,
        {"record": np.arange(n_s.size)},
        rule="rec.contacts[0].slip == SLIP, from the record's converged state",
    )


# -- lecture 08: the cork -------------------------------------------------------------------------


def _gas(gas_pressure, du, p0=0.8, V0=9424.778, area=314.159, travel=24.0):
    return np.asarray(call(gas_pressure, "gas_pressure", p0, V0, area, du, travel), dtype=float)


def gas_at_rest(gas_pressure):
    got = _gas(gas_pressure, np.array([0.0]))
    compare("pressure before the cork moves", got, np.array([0.8]), {"du": 0.0}, rule="p = p0 at du = 0")


def gas_boyle(gas_pressure):
    du = np.array([1.0, 5.0, 12.0, 23.9])
    got = _gas(gas_pressure, du)
    want = 0.8 * 9424.778 / (9424.778 + 314.159 * du)
    if got.shape == want.shape and np.allclose(got, 0.8 * (9424.778 + 314.159 * du) / 9424.778):
        raise AssertionError(
            "your pressure rises as the cork moves out: the gas expands, V grows and p falls, p = p0 V0 / V (Boyle)"
        )
    compare(
        "gas pressure (Boyle, p0 = 0.8 MPa)",
        got,
        want,
        {"du": du},
        rule="p = p0 V0 / (V0 + area du): the volume grows by the swept area times the travel",
    )


def gas_release(gas_pressure):
    du = np.array([23.0, 24.0, 30.0])
    got = _gas(gas_pressure, du)
    want = np.array([0.8 * 9424.778 / (9424.778 + 314.159 * 23.0), 0.0, 0.0])
    compare(
        "gas pressure at and past the mouth",
        got,
        want,
        {"du": du},
        rule="once the bottom has travelled `travel` (the length in the neck) the gas escapes: p = 0",
    )


def _hardening_return(hardening_return, t_bar, dg, p, q_bar, c_T=10.0, mu0=0.1, h=0.01):
    out = call(hardening_return, "hardening_return", t_bar, dg, p, q_bar, c_T, mu0, h)
    t_T, lam, q = parts(out, 3, "hardening_return", "t_T, lambda and q")
    try:
        return float(t_T), float(lam), float(q)
    except (TypeError, ValueError):
        raise AssertionError(
            f"hardening_return should return three numbers (t_T, lambda, q), got {out!r:.80}"
        ) from None


def _hardening_ref(t_bar, dg, p, q_bar, c_T=10.0, mu0=0.1, h=0.01):
    from ...laws import SlipHardening
    from ...laws.return_map import return_map

    fr = return_map(
        SlipHardening(c_T=c_T, mu=mu0, h=h),
        np.array([-p]),
        np.array([0.0]),
        np.array([dg]),
        np.array([t_bar]),
        np.array([q_bar]),
    )
    return float(fr.t_T[0]), float(fr.lam[0]), float(fr.q[0])


HARDENING_SLIP = ((0.1, 0.05, 2.0, 0.3), (-0.2, -0.08, 3.0, 1.0), (0.15, -0.1, 1.0, 0.0), (0.0, 0.2, 4.0, 5.0))


def hardening_stick(hardening_return):
    for case in ((0.1, 0.005, 2.0, 0.3), (-0.05, 0.002, 3.0, 0.0)):
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        compare("t_T in stick", t_T, want[0], at, rule="in stick t_T = t_bar + c_T dg_T (eq 42)")
        compare("lambda in stick", lam, 0.0, at)
        compare("q in stick", q, case[3], at, rule="no slip, no change of the accumulated slip")


def hardening_slip(hardening_return):
    for case in HARDENING_SLIP:
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        t_tr = case[0] + 10.0 * case[1]
        soft = (abs(t_tr) - (0.1 + 0.01 * case[3]) * case[2]) / 10.0
        if math.isclose(lam, soft, rel_tol=1e-8) and not math.isclose(lam, want[1], rel_tol=1e-8):
            raise AssertionError(
                f"your lambda {lam:.6g} at {', '.join(f'{k} = {v:g}' for k, v in at.items())} is "
                f"the one without hardening in the consistency condition; the bound grows with the "
                f"slip of the step itself: |t_tr| - c_T lambda - (mu0 + h (q_bar + lambda)) p = 0, "
                f"lambda = {want[1]:.6g}"
            )
        compare("t_T in slip", t_T, want[0], at, rule="t_T = sign(t_tr) (mu0 + h q) p on the slip surface")


def hardening_lambda_q(hardening_return):
    for case in HARDENING_SLIP:
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        compare("lambda in slip", lam, want[1], at, rule="lambda = (|t_tr| - (mu0 + h q_bar) p) / (c_T + h p)")
        compare("q after the step", q, want[2], at, rule="q = q_bar + lambda")


# -- lecture 12: beyond node-to-segment -----------------------------------------------------------


def _cn_cases():
    t_N = np.array([-2.0, -0.5, 0.0, 0.0, -1.0, -3.0])
    g_N = np.array([-0.01, 0.3, 0.2, -0.02, 0.02, 0.0])
    return t_N, g_N, 10.0


def _cn(C_N, t_N, g_N, c_N):
    out = call(C_N, "C_N", t_N, g_N, c_N)
    return [np.asarray(x, dtype=float) for x in parts(out, 3, "C_N", "C_N, dC_N/dt_N and dC_N/dg_N")]


def cn_values(C_N):
    from ...contact.complementarity import normal_complementarity

    t_N, g_N, c_N = _cn_cases()
    C, _, _ = _cn(C_N, t_N, g_N, c_N)
    want = normal_complementarity(t_N, g_N, c_N)[0]
    at = {"t_N": t_N, "g_N": g_N}
    if C.shape == want.shape and np.allclose(C, -want):
        raise AssertionError("your C_N has the wrong sign: with p = -t_N, xi = p - c_N g_N and C_N = p - max(0, xi)")
    compare("C_N (c_N = 10)", C, want, at, rule="C_N = p - max(0, p - c_N g_N) with p = -t_N")


def cn_derivatives(C_N):
    from ...contact.complementarity import normal_complementarity

    t_N, g_N, c_N = _cn_cases()
    _, dt, dg = _cn(C_N, t_N, g_N, c_N)
    _, w_dt, w_dg, _ = normal_complementarity(t_N, g_N, c_N)
    at = {"t_N": t_N, "g_N": g_N}
    compare("dC_N/dt_N", dt, w_dt, at, rule="closed (xi >= 0): C_N = c_N g_N, so 0; open: C_N = p = -t_N, so -1")
    compare("dC_N/dg_N", dg, w_dg, at, rule="closed: c_N; open: 0")


def cn_tie(C_N):
    t_N, g_N, c_N = np.array([0.0]), np.array([0.0]), 10.0
    C, dt, dg = _cn(C_N, t_N, g_N, c_N)
    if not (np.allclose(dt, 0.0) and np.allclose(dg, c_N)):
        raise AssertionError(
            "at xi = 0 (touching, no pressure) your node is open; the tie goes to contact "
            "(xi >= 0 is closed), so that a body resting on its support is held in the first "
            "iteration: dC_N/dt_N = 0, dC_N/dg_N = c_N there"
        )


def _ct_cases():
    t_T = np.array([0.1, 0.5, -0.4, 0.2, 0.0, 0.3])
    dg = np.array([0.0, 0.02, -0.05, 0.01, 0.0, 0.1])
    xi = np.array([-1.0, 2.0, 2.0, 1.0, 0.5, 3.0])
    return t_T, dg, xi, 10.0, 0.3


def _ct(C_T, t_T, dg, xi, c_T, mu):
    out = call(C_T, "C_T", t_T, dg, xi, c_T, mu)
    return [np.asarray(x, dtype=float) for x in parts(out, 4, "C_T", "C_T, dC_T/dt_T, dC_T/d(dg_T), dC_T/dxi")]


def _ct_ref(t_T, dg, xi, c_T, mu):
    from ...contact.complementarity import friction_complementarity
    from ...laws import Coulomb

    return friction_complementarity(Coulomb(c_T=c_T, mu=mu), t_T, dg, xi, c_T)


def ct_open(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    sel = xi < 0
    at = {"t_T": t_T[sel], "xi": xi[sel]}
    compare("C_T of an open node", got[0][sel], want[0][sel], at, rule="open (xi < 0): C_T = t_T, no traction")
    compare("dC_T/dt_T of an open node", got[1][sel], want[1][sel], at)


def ct_stick_slip(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    sel = xi >= 0
    at = {"t_T": t_T[sel], "dg_T": dg[sel], "xi": xi[sel]}
    compare(
        "C_T (Coulomb mu = 0.3, c_T = 10)",
        got[0][sel],
        want[0][sel],
        at,
        rule="tau = t_T + c_T dg_T; stick (|tau| <= mu xi): -c_T dg_T; slip: t_T - sign(tau) mu xi",
    )


def ct_derivatives(C_T):
    t_T, dg, xi, c_T, mu = _ct_cases()
    got = _ct(C_T, t_T, dg, xi, c_T, mu)
    want = _ct_ref(t_T, dg, xi, c_T, mu)
    at = {"t_T": t_T, "dg_T": dg, "xi": xi}
    for k, name, rule in (
        (1, "dC_T/dt_T", "stick 0; slip and open 1"),
        (2, "dC_T/d(dg_T)", "stick -c_T; else 0"),
        (3, "dC_T/dxi", "slip -sign(tau) mu (Y = mu xi); else 0"),
    ):
        compare(name, got[k], want[k], at, rule=rule)


SSN_CASES = ((100.0, 10.0, 0.05, 1000.0), (100.0, 10.0, 0.05, 1.0), (10.0, 5.0, 0.1, 1e4))


def _ssn(semismooth_1dof, k, P, g0, c_N):
    out = call(semismooth_1dof, "semismooth_1dof", k, P, g0, c_N, 1e-10)
    u, p, n = parts(out, 3, "semismooth_1dof", "u, p and the number of iterations")
    try:
        return float(u), float(p), int(n)
    except (TypeError, ValueError):
        raise AssertionError(f"semismooth_1dof should return (u, p, iterations): numbers, got {out!r:.80}") from None


def ssn_contact(semismooth_1dof):
    for k, P, g0, c_N in SSN_CASES:
        u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
        at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
        pen = (P + c_N * g0) / (k + c_N)
        if math.isclose(u, pen, rel_tol=1e-9) and not math.isclose(pen, g0, rel_tol=1e-9):
            raise AssertionError(
                f"at k = {k:g}, P = {P:g}, g0 = {g0:g}, c_N = {c_N:g} your u = {u:.6g} is the penalty "
                "answer: here c_N only steers the iterates; the solution has g = g0 - u = 0 exactly"
            )
        compare("u (the node at the wall)", u, g0, at, rule="in contact the gap closes exactly: u = g0")
        compare("p (the contact pressure)", p, P - k * g0, at, rule="equilibrium k u = P - p with u = g0")


def ssn_open(semismooth_1dof):
    k, P, g0, c_N = 100.0, 2.0, 0.05, 1000.0  # P / k = 0.02 < g0: never touches
    u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
    at = {"k": k, "P": P, "g0": g0}
    compare("u when the wall is not reached", u, P / k, at, rule="open: p = 0 and k u = P")
    compare("p when the wall is not reached", p, 0.0, at)


def ssn_iterations(semismooth_1dof):
    for k, P, g0, c_N in SSN_CASES:
        _, _, n = _ssn(semismooth_1dof, k, P, g0, c_N)
        if n > 3:
            raise AssertionError(
                f"at k = {k:g}, c_N = {c_N:g} your method took {n} iterations; from u = p = 0 the "
                "semi-smooth Newton method finds the set (contact) in one step and is then exact "
                "(the equations are linear once the set is right): 2 iterations, at most 3. Do you "
                "update the set from the new iterate and solve the full Newton system?"
            )
        if n < 1:
            raise AssertionError("your method reports 0 iterations: count the Newton updates you made")


# -- the exercises ------------------------------------------------------------------------------


def _ex(name, lecture, difficulty, implements, what, *items):
    ps = tuple(Part(f.__name__, pts, f, tuple(f.__code__.co_varnames[: f.__code__.co_argcount])) for f, pts in items)
    return Exercise(name, lecture, difficulty, implements, ps, what)


EXERCISES = {
    e.name: e
    for e in [
        _ex(
            "ex01_power_law",
            "01_interface_laws",
            "easy",
            True,
            "the normal law of eq (4) and its derivative",
            (power_law_open, 1),
            (power_law_traction, 2),
            (power_law_derivative, 2),
        ),
        _ex(
            "ex01_tresca",
            "01_interface_laws",
            "medium",
            True,
            "a Tresca friction law, passing check_law",
            (tresca_fields, 1),
            (tresca_bound, 2),
            (tresca_derivatives, 1),
            (tresca_check_law, 1),
        ),
        _ex(
            "ex02_circle_gap",
            "02_kinematics_linearisation",
            "easy",
            True,
            "the gap and normal of a circular rigid master",
            (circle_gap_value, 2),
            (circle_gap_normal, 2),
            (circle_gap_variation, 1),
        ),
        _ex(
            "ex02_normal_tangent",
            "02_kinematics_linearisation",
            "hard",
            True,
            "the normal block K_N of the tangent (eq 33), checked against finite differences",
            (normal_tangent_fd, 3),
            (normal_tangent_material, 1),
            (normal_tangent_symmetric, 1),
        ),
        _ex(
            "ex03_coulomb_return",
            "03_return_mapping",
            "medium",
            True,
            "trial state, check and return for one node with Coulomb friction (eqs 40-45)",
            (coulomb_stick, 1),
            (coulomb_slip, 2),
            (coulomb_slip_backwards, 1),
            (coulomb_lambda, 1),
        ),
        _ex(
            "ex03_slip_moduli",
            "03_return_mapping",
            "hard",
            True,
            "the consistent moduli c_T^s, c_N^s (eqs 47-48)",
            (moduli_c_T, 2),
            (moduli_c_N, 3),
        ),
        _ex(
            "ex09_observed_order",
            "09_speed_accuracy",
            "easy",
            False,
            "the observed order of convergence by least squares, applied to the bench",
            (observed_order_exact, 2),
            (observed_order_least_squares, 2),
            (observed_order_signed, 1),
        ),
        _ex(
            "ex09_convergence_order",
            "09_speed_accuracy",
            "medium",
            False,
            "Newton's order from a residual history: consistent tangent against staggered",
            (convergence_order_linear, 1),
            (convergence_order_quadratic, 2),
            (convergence_order_last, 1),
        ),
        _ex(
            "ex09_settings_for_tolerance",
            "09_speed_accuracy",
            "medium",
            False,
            "the step and the penalty of the sloping impact for a tolerance, checked with the run's indicators",
            (tolerance_indicators, 2),
            (tolerance_error, 2),
            (tolerance_budget, 1),
        ),
        _ex(
            "ex09_band_by_hand",
            "09_speed_accuracy",
            "medium",
            False,
            "an error band from three runs: observed order, Richardson's estimate, Xing and Stern's factor of safety",
            (band_order, 2),
            (band_richardson, 2),
            (band_factor_of_safety, 2),
        ),
        _ex(
            "ex10_linear_hardening",
            "10_write_your_own_law",
            "easy",
            True,
            "a slip-hardening friction law with its derivatives, passing check_law",
            (hardening_bound, 2),
            (hardening_derivatives, 2),
            (hardening_check_law, 1),
        ),
        _ex(
            "ex10_quadratic_normal",
            "10_write_your_own_law",
            "medium",
            True,
            "a normal law with its stored energy, the energy checked against the traction",
            (quadratic_traction, 2),
            (quadratic_energy, 1),
            (quadratic_energy_gradient, 2),
        ),
        _ex(
            "ex11_uzawa",
            "11_where_1990_stops",
            "medium",
            True,
            "Uzawa's multiplier update on a one-degree-of-freedom contact",
            (uzawa_gap, 2),
            (uzawa_multiplier, 2),
            (uzawa_updates, 1),
        ),
        _ex(
            "ex11_secant_traction",
            "11_where_1990_stops",
            "medium",
            True,
            "the discrete gradient of the penalty energy (an energy check of one step)",
            (secant_energy, 3),
            (secant_limit, 1),
        ),
        _ex(
            "ex04_slip_margin",
            "04_block",
            "easy",
            True,
            "the slip condition of eq 10 at every contact node, on the converged block",
            (margin_parabolic, 2),
            (margin_coulomb, 1),
            (margin_block, 2),
        ),
        _ex(
            "ex04_load_steps",
            "04_block",
            "medium",
            True,
            "the block's time loop in n load steps, recording the slip from the converged contact states",
            (load_steps_times, 1),
            (load_steps_solves, 1),
            (load_steps_slipping, 2),
            (load_steps_one, 1),
        ),
        _ex(
            "ex05_rolling_point",
            "05_rolling_ring",
            "easy",
            False,
            "the start of rolling of a rigid ring of any radius of gyration (closed form)",
            (rolling_time, 2),
            (rolling_position, 2),
            (rolling_speed, 1),
        ),
        _ex(
            "ex05_incline",
            "05_rolling_ring",
            "hard",
            True,
            "a new scene from parts: the ring on an inclined plane, rolling or sliding",
            (incline_start, 1),
            (incline_rolling, 2),
            (incline_sliding, 2),
        ),
        _ex(
            "ex06_rebound",
            "06_sloping_impact",
            "easy",
            False,
            "the rebound velocity and the angle of reflection of Table 2 from a centre-of-mass history",
            (rebound_velocity, 2),
            (rebound_angle, 2),
            (rebound_none, 1),
        ),
        _ex(
            "ex06_interface_energy",
            "06_sloping_impact",
            "medium",
            True,
            "the energy stored in the interface (penalty potential and stick springs), the energy check's term",
            (energy_normal, 2),
            (energy_open, 1),
            (energy_friction, 2),
        ),
        _ex(
            "ex07_escape_angle",
            "07_funnel",
            "easy",
            False,
            "the steepest funnel wall that holds a wedged ring, from the slip surface of eq 10",
            (escape_values, 2),
            (escape_coulomb, 1),
            (escape_steeper, 1),
        ),
        _ex(
            "ex07_census",
            "07_funnel",
            "medium",
            True,
            "the funnel's time loop, counting the nodes in contact and slipping from the converged states",
            (census_times, 1),
            (census_contact, 2),
            (census_slip, 2),
        ),
        _ex(
            "ex08_gas_pressure",
            "08_cork",
            "easy",
            True,
            "the explicit gas coupling: Boyle's law from the converged travel, and the release at the mouth",
            (gas_at_rest, 1),
            (gas_boyle, 2),
            (gas_release, 1),
        ),
        _ex(
            "ex08_hardening_return",
            "08_cork",
            "medium",
            True,
            "the return map of the slip-hardening Coulomb law (closed form of the local Newton)",
            (hardening_stick, 1),
            (hardening_slip, 2),
            (hardening_lambda_q, 2),
        ),
        _ex(
            "ex12_normal_complementarity",
            "12_beyond_node_to_segment",
            "easy",
            True,
            "the complementarity function of the normal contact condition and its Newton derivative",
            (cn_values, 2),
            (cn_derivatives, 2),
            (cn_tie, 1),
        ),
        _ex(
            "ex12_friction_complementarity",
            "12_beyond_node_to_segment",
            "hard",
            True,
            "the Coulomb complementarity function: open, stick and slip sets and their derivatives",
            (ct_open, 1),
            (ct_stick_slip, 2),
            (ct_derivatives, 2),
        ),
        _ex(
            "ex12_semismooth_1dof",
            "12_beyond_node_to_segment",
            "medium",
            True,
            "a semi-smooth Newton method on a one-degree-of-freedom contact",
            (ssn_contact, 2),
            (ssn_open, 1),
            (ssn_iterations, 2),
        ),
    ]
}


# -- implement, don't import ---------------------------------------------------------------------

# The library's implementation of the part an exercise asks for ("module:Name" or
# "module:Name.method"): out of reach of the answer while it is graded (an answer that uses it
# scores zero for the part). Exercise 11.1 and 12.3 have no counterpart in the library (it
# solves meshes, not one degree of freedom).
LIBRARY = {
    "ex01_power_law": ("contactfem.laws.normal:PowerLaw",),
    "ex01_tresca": ("contactfem.laws.friction:Coulomb", "contactfem.laws.friction:ParabolicSlip"),
    "ex02_circle_gap": ("contactfem.contact.masters:RigidArc", "contactfem.contact.kinematics:arc_variations"),
    "ex02_normal_tangent": ("contactfem.contact.element:normal_element", "contactfem.contact.element:contact_element"),
    "ex03_coulomb_return": ("contactfem.laws.return_map:return_map",),
    "ex03_slip_moduli": ("contactfem.laws.return_map:return_map",),
    "ex08_hardening_return": ("contactfem.laws.return_map:return_map", "contactfem.laws.friction:SlipHardening"),
    "ex10_linear_hardening": ("contactfem.laws.friction:SlipHardening",),
    "ex10_quadratic_normal": ("contactfem.laws.normal:PowerLaw",),
    "ex11_secant_traction": ("contactfem.contact.conserving:secant", "contactfem.contact.conserving:discrete_gradient"),
    "ex12_normal_complementarity": ("contactfem.contact.complementarity:normal_complementarity",),
    "ex12_friction_complementarity": ("contactfem.contact.complementarity:friction_complementarity",),
    "ex08_gas_pressure": ("contactfem.bodies.loads:GasPressure",),
}

# The exercises that ask for part of the method on top of the library's own parts (their
# prompts say so): what the library gives them, and what the student writes.
BUILDS_ON = {
    "ex04_slip_margin": "the law's own slip_bound gives the bound Y; the answer is the margin over the nodes",
    "ex04_load_steps": "the scene's stepper solves each step; the answer is the loop and what it records",
    "ex05_incline": "the ring, the plane and the stepper are the library's; the answer is the new scene",
    "ex07_census": "the scene's stepper solves each step; the answer is the loop and its counts",
}


# -- written answers ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Manual:
    """A written question of a lecture, scored by the instructor: its prompt is a markdown
    cell holding ``<!-- manual: NAME -->``; the cells after it are the answer."""

    name: str
    lecture: str
    points: float
    what: str


MANUAL = {
    m.name: m
    for m in [
        Manual(
            "ex01_discussion",
            "01_interface_laws",
            2,
            "a short discussion: what the penalty law's stiffness c_N trades off (penetration against conditioning)",
        ),
    ]
}
