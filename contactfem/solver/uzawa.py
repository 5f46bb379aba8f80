"""The Uzawa (outer) loop of augmented-Lagrangian contact (contact/augmented.py).

    stepper = Uzawa(Static(system, ...), contacts, length=a, tol=1e-9)
    u1, v1, a1, result = stepper.step(t, u, v, a, dt, state=state)   # works with march like any stepper

One step: solve the step equation by the wrapped stepper's Newton method (the same
consistent tangent as the penalty method) with the multipliers held fixed; measure what
the multiplier update lam <- t would change, in length units, divided by the scene's
``length`` (the contact half-width of Hertz, the element size of the block);
if that is <= tol, stop; otherwise update the multipliers and solve again.

    outer iteration k:  Newton solve at lam_k  ->  u_k
                        violation_k = max |t(u_k) - lam_k| / c / length
                        stop if violation_k <= tol, else lam_{k+1} = t(u_k)

At an active node the normal part of the violation is the penetration itself, at a
sticking node the tangential part is the stick creep |s - s_bar|. Each update shrinks the
violation by about k / (k + c), k the stiffness of the structure behind the contact: a
stiff penalty converges in few updates (with a worse-conditioned Newton), a soft one in
many (with an easy Newton): the speed/accuracy trade, now between outer and inner
iterations instead of between accuracy and conditioning.

A static step restarts Newton from the last outer iterate; a dynamic step (Newmark) from
its own predictor (its equation depends on the start of the step). The violation and the
update read the contact states of each converged inner solve (its evaluation), so nothing
is evaluated twice. The multipliers are part of the interfaces' histories (a value in the
SystemState, contact/augmented.py): each update gives the next outer iteration a new state
to solve with, and the time loop (march.py) commits the last one, as for any stepper.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ..contact.augmented import AugmentedNodeToSegment
from .newton import NewtonError


@dataclass
class UzawaResult:
    """Like NewtonResult: ``residuals`` and ``iterations`` cover all Newton solves of the
    step. ``uzawa_iterations``: Newton solves (outer iterations); ``updates`` =
    uzawa_iterations - 1 multiplier updates; ``newton_per_outer``: linear solves of each;
    ``violations``: the violation after each; ``gap_violations``: the largest penetration /
    length after each; ``gap_violation``: its last value (the converged state); ``residual_ratio``: the converged Newton
    solve's."""

    u: np.ndarray
    residuals: list = field(default_factory=list)
    iterations: int = 0
    G: np.ndarray | None = None
    evaluation: object = None
    evaluations: int = 0
    uzawa_iterations: int = 0
    updates: int = 0
    newton_per_outer: list = field(default_factory=list)
    violations: list = field(default_factory=list)
    gap_violation: float = 0.0
    gap_violations: list = field(default_factory=list)
    residual_ratio: float = 0.0  # the converged Newton solve's (NewtonResult.residual_ratio)


class Uzawa:
    """Wraps a stepper (Static or Newmark) with the outer loop (module docstring).

    contacts: the AugmentedNodeToSegment interfaces of the system (others are left alone);
    length: the length the violation is divided by (the scene states it);
    tol: stop when the relative violation is <= tol; max_updates: multiplier updates
    allowed per step before a NewtonError (carrying the violation history) is raised.
    """

    def __init__(self, stepper, contacts, length, tol=1e-9, max_updates=50):
        for name, value in (("uzawa_tol", tol), ("length", length)):
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"parameter {name} = {value!r} is out of range: allowed (0, inf)")
        if int(max_updates) != max_updates or max_updates < 0:
            raise ValueError(f"parameter uzawa_max_updates = {max_updates!r} is out of range: allowed integers >= 0")
        self.stepper, self.length, self.tol, self.max_updates = stepper, float(length), float(tol), int(max_updates)
        self.contacts = [c for c in contacts if isinstance(c, AugmentedNodeToSegment)]
        if not self.contacts:
            raise ValueError("Uzawa needs at least one augmented interface (enforcement = 'augmented')")
        self.system, self.dynamic, self.error_model = stepper.system, stepper.dynamic, stepper.error_model

    def step(self, t, u, v, a, dt, label="", *, state):
        start = u
        residuals, per_outer, viols, gaps, calls = [], [], [], [], [0]
        for k in range(self.max_updates + 1):
            try:
                u1, v1, a1, res = self.stepper.step(
                    t, start, v, a, dt, label=f"{label} (outer iteration {k + 1})" if label else "", state=state
                )
            except NewtonError as err:  # the outer iterations' evaluations before it count too
                raise type(err)(str(err), err.history, err.label, calls[0] + err.evaluations) from err
            out = self._outer(k, u1, v1, a1, res, residuals, per_outer, viols, gaps, calls)
            if isinstance(out, tuple):
                return out
            state = out  # the same step again, with the updated multipliers
            if not self.dynamic:
                start = u1  # warm start of the next static solve
        raise NewtonError(
            f"Uzawa: contact violation {viols[-1]:.3e} > uzawa_tol = {self.tol:.1e} after "
            f"{self.max_updates} multiplier updates ({label}); violations "
            f"{', '.join(f'{x:.2e}' for x in viols[-5:])} (last 5)",
            residuals,
            label,
            calls[0],
        )

    def _outer(self, k, u1, v1, a1, res, residuals, per_outer, viols, gaps, calls):
        """Book-keeping of outer iteration k: the step's result if converged, else the SystemState
        with the updated multipliers."""
        residuals += list(res.residuals)
        per_outer.append(res.iterations)
        calls[0] += res.evaluations
        states = dict(zip(self.system.contacts, res.evaluation.contacts))
        checks = [c.violation(states[c]) for c in self.contacts]
        viol = max(c["change"] for c in checks) / self.length
        gap = max(c["penetration"] for c in checks) / self.length
        viols.append(viol)
        gaps.append(gap)
        if viol <= self.tol:
            result = UzawaResult(
                u=u1,
                residuals=residuals,
                iterations=sum(per_outer),
                G=res.G,
                evaluation=res.evaluation,
                evaluations=calls[0],
                uzawa_iterations=k + 1,
                updates=k,
                newton_per_outer=per_outer,
                violations=viols,
                gap_violation=gap,
                gap_violations=list(gaps),
                residual_ratio=res.residual_ratio,
            )
            return u1, v1, a1, result
        ours = set(map(id, self.contacts))
        ev = res.evaluation
        histories = tuple(
            c.update_multipliers(st) if id(c) in ours else h
            for c, st, h in zip(self.system.contacts, ev.contacts, ev.state.contacts)
        )
        return replace(ev.state, contacts=histories)
