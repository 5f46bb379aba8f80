"""The two-step (staggered) algorithm the paper argues against (Sec. 2.2), for comparison.

Wriggers, Vu Van & Stein (1990), Sec. 2.2: with an associated slip rule at fixed normal
stress, "algorithms ... need a staggered form: first the normal contact stresses have to
be calculated with fixed tangential stresses and then, in a next iteration, the frictional
stresses have to be computed with fixed normal stresses. In many cases the convergence
properties of these algorithms are not satisfactory." The paper instead solves both at
once with the consistent, non-symmetric tangent (eqs 49-50). This module implements the
staggered form on the same System, contacts and residual, so the two can be measured:

    cycle k = 1, 2, ... until the FULL residual (eq 29, live coupling) is converged:
      normal phase:   Newton on G(u) = 0 with the friction state frozen at the start of
                      the phase: t_T = t_T* + c_T (s - s*) (t_T* the tangential traction
                      there, s* the projection; no slip check). The normal traction t_N
                      is live. At the fixed point s = s*, so t_T = t_T*: "fixed tangential
                      stresses". The elastic stick spring c_T (s - s*) keeps the normal
                      problem solvable when friction alone holds a body tangentially (the
                      block of Sec. 5.1 has no support but the foundation); a truly
                      constant t_T would leave its rigid tangential motion undetermined.
      friction phase: Newton on G(u) = 0 with the return mapping (eqs 40-45) evaluated at
                      the normal pressure p* = |t_N| frozen from the end of the normal
                      phase (a Tresca problem, slip bound Y(p*)); so c_N^s = 0 in eq (49)
                      and the non-symmetric coupling C of eq (50) never appears. The
                      normal law itself stays live.

Each phase is a full Newton solve (to the same absolute tolerance as the whole step);
``iterations`` counts every linear solve of every phase, the figure to compare with the
consistent Newton's. A cycle limit raises NewtonError (never returns an unconverged u).

    split = SplitContact(contact)                   # wraps a NodeToSegment
    system = System(bodies, [split], loads, fixed)  # same bodies and loads
    stepper = Staggered(Newmark(system, dt, ...), [split])   # or Staggered(Static(system))
    u1, v1, a1, result = stepper.step(t, u, v, a)   # result.iterations = all linear solves
    hist = integrate(stepper, ...)                  # works like any stepper
"""
from dataclasses import dataclass, field

import numpy as np

from ..contact.tangents import PHASES, SplitContact  # noqa: F401  (SplitContact: public here too)
from .newton import NewtonError, newton

@dataclass
class StaggeredResult:
    """Like NewtonResult; ``residuals`` are the full residual norms at the start and after
    each cycle, ``iterations`` all linear solves, ``phase_iterations`` the solves of each
    phase in order (normal, friction, normal, ...)."""
    u: np.ndarray
    residuals: list = field(default_factory=list)
    iterations: int = 0
    G: np.ndarray = None
    cycles: int = 0
    phase_iterations: list = field(default_factory=list)


def staggered(fun, u0, free, splits, atol=1e-10, rtol=1e-10, maxit=25, max_cycles=60, label=""):
    """The staggered iteration (module docstring) on fun(u) -> (G, K), the (effective)
    residual of a System whose contacts include the SplitContacts ``splits``.

    Converged when the full residual satisfies ||G|| <= atol + rtol ||G_0|| (the test of
    ``newton``); each phase is solved by ``newton`` to that same absolute tolerance.
    Raises NewtonError after ``max_cycles`` cycles or if a phase fails.
    """
    free = np.asarray(free)
    where = f" ({label})" if label else ""

    def full(u):
        for s in splits:
            s.set_phase("full")
        return fun(u)

    u = np.array(u0, dtype=float)
    G, _ = full(u)
    history = [float(np.linalg.norm(G[free]))]
    tol = atol + rtol * history[0]
    solves, per_phase = 0, []
    for cycle in range(1, max_cycles + 1):
        if history[-1] <= tol:
            return StaggeredResult(u=u, residuals=history, iterations=solves, G=G, cycles=cycle - 1,
                                   phase_iterations=per_phase)
        for phase in ("normal", "friction"):
            for s in splits:
                s.freeze(u)
                s.set_phase(phase)
            try:
                res = newton(fun, u, free, atol=tol, rtol=0.0, maxit=maxit, label=f"{phase} phase{where}")
            except NewtonError as err:
                raise NewtonError(f"staggered: {phase} phase of cycle {cycle} failed{where}: {err}",
                                  history, label) from err
            u, solves = res.u, solves + res.iterations
            per_phase.append(res.iterations)
        G, _ = full(u)
        r = float(np.linalg.norm(G[free]))
        if not np.isfinite(r):
            raise NewtonError(f"staggered: residual is NaN/inf after cycle {cycle}{where}", history, label)
        history.append(r)
    if history[-1] <= tol:
        return StaggeredResult(u=u, residuals=history, iterations=solves, G=G, cycles=max_cycles,
                               phase_iterations=per_phase)
    raise NewtonError(f"staggered: no convergence in {max_cycles} cycles{where}; full residuals "
                      f"{', '.join(f'{x:.3e}' for x in history[-5:])} (last 5)", history, label)


class Staggered:
    """Wraps a Newmark or Static stepper: the same step equation (Newmark: eq 29 with
    a+ = (u+ - u_pred) / (beta dt^2); Static: G = 0), solved by ``staggered`` instead of
    ``newton``. Use with ``integrate`` like any stepper; the atol, rtol, maxit of the
    wrapped stepper apply to every phase."""

    def __init__(self, stepper, splits, max_cycles=60):
        self.stepper, self.splits, self.max_cycles = stepper, list(splits), max_cycles
        self.system, self.dt, self.dynamic = stepper.system, stepper.dt, stepper.dynamic
        if self.dynamic and not hasattr(stepper, "beta"):
            raise ValueError("parameter stepper must be a Newmark or Static stepper (an implicit one)")

    def step(self, t, u, v, a, dt=None, label=""):
        st, s = self.stepper, self.system
        dt = st.dt if dt is None else dt
        s.set_dt(dt)
        t1 = t + dt
        opts = dict(st.newton_options)
        if not self.dynamic:
            res = staggered(lambda w: s.residual_tangent(w, t1), s.apply_dirichlet(u, t1), s.free_dofs,
                            self.splits, max_cycles=self.max_cycles, label=label, **opts)
            zero = np.zeros(s.ndof)
            return res.u, zero, zero.copy(), res
        beta, delta, M = st.beta, st.delta, s.mass()
        c = 1.0 / (beta * dt ** 2)
        u_pred = u + dt * v + dt ** 2 * (0.5 - beta) * a

        def effective(u1):                                   # as Newmark.step
            G, K = s.residual_tangent(u1, t1, mass_coefficient=c)
            return G + M * c * (u1 - u_pred), K

        guess = s.apply_dirichlet(u_pred + beta * dt ** 2 * a, t1)
        res = staggered(effective, guess, s.free_dofs, self.splits, max_cycles=self.max_cycles,
                        label=label, **opts)
        a1 = c * (res.u - u_pred)
        v1 = v + dt * ((1 - delta) * a + delta * a1)
        return res.u, v1, a1, res
