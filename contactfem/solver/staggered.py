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

    system = System(bodies, [contact], loads, fixed)     # the contacts as they are
    stepper = Staggered(Newmark(system, ...))            # or Staggered(Static(system))
    u1, v1, a1, result = stepper.step(t, u, v, a, dt)    # result.iterations = all linear solves
    for rec in march(stepper, ...): ...                  # works like any stepper

A phase is a value frozen from the full evaluation that starts it (contact/tangents.py,
``freeze``) and handed to every evaluation of the phase: the contacts are not wrapped.
"""

from dataclasses import dataclass, field

import numpy as np

from ..contact.tangents import freeze
from .newton import RTOL, NewtonError, force_scale, newton


@dataclass
class StaggeredResult:
    """Like NewtonResult; ``residuals`` are the full residual norms at the start and after
    each cycle, ``iterations`` all linear solves, ``phase_iterations`` the solves of each
    phase in order (normal, friction, normal, ...)."""

    u: np.ndarray
    residuals: list = field(default_factory=list)
    iterations: int = 0
    G: np.ndarray | None = None
    evaluation: object = None
    evaluations: int = 0
    cycles: int = 0
    phase_iterations: list = field(default_factory=list)
    residual_ratio: float = 0.0  # (max |G_f| - atol)+ / F of the full residual it converged at (as newton's)


def staggered(
    fun, u0, free, atol=1e-12, rtol=RTOL, maxit=25, max_cycles=60, label="", instrument=None, **newton_options
):
    """The staggered iteration (module docstring) on fun(u, phases) -> the (effective)
    Evaluation of a System, ``phases`` one per contact (None: the full contacts).

    Converged when the full residual passes ``newton``'s test in force units: max |G_f| <=
    atol + rtol F, F the force scale of the full evaluation (newton.force_scale); each phase is
    solved by ``newton`` to that same absolute tolerance (its other options: ``newton_options``).
    Raises NewtonError after ``max_cycles`` cycles or if a phase fails.
    """
    free = np.asarray(free)
    where = f" ({label})" if label else ""
    u = np.array(u0, dtype=float)
    ev = fun(u, None)
    calls = 1
    history = [float(np.linalg.norm(ev.G[free]))]  # ||G_f|| of every cycle, for reports

    def tolerance(ev):  # newton's test: the full residual's force scale
        return atol + rtol * force_scale(ev, free)

    def converged(ev):
        return float(np.max(np.abs(ev.G[free]), initial=0.0)) <= tolerance(ev)

    def ratio(ev):  # what the test accepted above atol, against the force scale (NewtonResult.residual_ratio)
        F = force_scale(ev, free)
        return max(float(np.max(np.abs(ev.G[free]), initial=0.0)) - atol, 0.0) / F if F > 0 else 0.0

    solves, per_phase = 0, []
    for cycle in range(1, max_cycles + 1):
        if converged(ev):
            return StaggeredResult(
                u=u,
                residuals=history,
                iterations=solves,
                G=ev.G,
                evaluation=ev,
                evaluations=calls,
                cycles=cycle - 1,
                phase_iterations=per_phase,
                residual_ratio=ratio(ev),
            )
        for kind in ("normal", "friction"):
            if kind == "friction":  # freeze from the full state at the end of the normal phase
                ev, calls = fun(u, None), calls + 1
            phases, tol = [freeze(state, kind) for state in ev.contacts], tolerance(ev)
            try:
                res = newton(
                    lambda w: fun(w, phases),
                    u,
                    free,
                    atol=tol,
                    rtol=0.0,
                    maxit=maxit,
                    label=f"{kind} phase{where}",
                    instrument=instrument,
                    **newton_options,
                )
            except NewtonError as err:
                raise NewtonError(
                    f"staggered: {kind} phase of cycle {cycle} failed{where}: {err}",
                    history,
                    label,
                    calls + err.evaluations,
                ) from err
            u, solves, calls = res.u, solves + res.iterations, calls + res.evaluations
            per_phase.append(res.iterations)
        ev, calls = fun(u, None), calls + 1
        r = float(np.linalg.norm(ev.G[free]))
        if not np.isfinite(r):
            raise NewtonError(f"staggered: residual is NaN/inf after cycle {cycle}{where}", history, label, calls)
        history.append(r)
    if converged(ev):
        return StaggeredResult(
            u=u,
            residuals=history,
            iterations=solves,
            G=ev.G,
            evaluation=ev,
            evaluations=calls,
            cycles=max_cycles,
            phase_iterations=per_phase,
            residual_ratio=ratio(ev),
        )
    raise NewtonError(
        f"staggered: no convergence in {max_cycles} cycles{where}; full residuals "
        f"{', '.join(f'{x:.3e}' for x in history[-5:])} (last 5)",
        history,
        label,
        calls,
    )


class Staggered:
    """Wraps a Newmark or Static stepper: the same step equation (Newmark: eq 29 with
    a+ = (u+ - u_pred) / (beta dt^2); Static: G = 0), solved by ``staggered`` instead of
    ``newton``. Use with ``march`` like any stepper; the atol, rtol, maxit of the
    wrapped stepper apply to every phase."""

    def __init__(self, stepper, max_cycles=60):
        self.stepper, self.max_cycles = stepper, max_cycles
        self.system, self.dynamic, self.error_model = stepper.system, stepper.dynamic, stepper.error_model
        if self.dynamic and not hasattr(stepper, "beta"):
            raise ValueError("parameter stepper must be a Newmark or Static stepper (an implicit one)")

    def step(self, t, u, v, a, dt, label="", *, state):
        st, s = self.stepper, self.system
        t1 = t + dt
        opts = dict(st.newton_options, instrument=s.instrument)
        if not self.dynamic:
            res = staggered(
                lambda w, ph: s.evaluate(w, t1, dt, u, phases=ph, state=state),
                s.apply_dirichlet(u, t1),
                s.free_dofs,
                max_cycles=self.max_cycles,
                label=label,
                **opts,
            )
            zero = np.zeros(s.ndof)
            return res.u, zero, zero.copy(), res
        beta, delta = st.beta, st.delta
        c = 1.0 / (beta * dt**2)
        u_pred = u + dt * v + dt**2 * (0.5 - beta) * a

        def effective(u1, phases):  # as Newmark.step
            ev = s.evaluate(u1, t1, dt, u, mass_coefficient=c, phases=phases, state=state)
            return ev._replace(G=ev.G + s.mass_times(c * (u1 - u_pred)))

        guess = s.apply_dirichlet(u_pred + beta * dt**2 * a, t1)
        res = staggered(effective, guess, s.free_dofs, max_cycles=self.max_cycles, label=label, **opts)
        a1 = c * (res.u - u_pred)
        v1 = v + dt * ((1 - delta) * a + delta * a1)
        return res.u, v1, a1, res
