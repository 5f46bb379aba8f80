"""Time stepping (paper Sec. 4.1 and the algorithm of Sec. 4.3).

Three steppers share one interface (solver/interfaces.py), ``step(t, u, v, a, dt, label="")
-> (u+, v+, a+, NewtonResult)``: one step of size dt from the converged (t, u, v, a). A step
commits nothing; the time loop (march.py) commits the converged evaluation, which the
NewtonResult carries (``result.evaluation``), and records it.

* Newmark: implicit, full Newton on the effective system (paper Sec. 4.1, 4.3).
* Static: quasi-static (no inertia), for load stepping and pressing-in phases.
* CentralDifference: explicit (Newmark with beta = 0, delta = 1/2), no Newton.

Newmark (the paper's delta is the usual gamma), with the predictor
    u_pred = u + dt v + dt^2 (1/2 - beta) a
the update of the step is
    a+ = (u+ - u_pred) / (beta dt^2),    v+ = v + dt ((1 - delta) a + delta a+),
and u+ solves eq 29 at t+ = t + dt,
    G(u+) = M a+ + R(u+) + R_c(u+) - P(u+, t+) = 0,
by Newton with the effective tangent M / (beta dt^2) + K + K_c (M the lumped, diagonal mass,
or the consistent one where a body asks for it: System.mass).
Unconditionally stable (linear analysis) for delta >= 1/2 and
beta >= (delta + 1/2)^2 / 4; delta = 1/2, beta = 1/4 (average acceleration)
conserves energy; the paper's delta = 0.7, beta = 0.4 damps high frequencies.

The unknowns a contact owns (Lagrange multipliers, system.py) are not motions: Newton
starts them from their last converged values and they get no velocity or acceleration
(``system.contact_dofs``; none in a penalty model, where nothing of this changes).
"""

import warnings

import numpy as np

from ..laws.validation import require
from .estimate import newmark_error_model
from .march import acceleration
from .newton import NewtonError, NewtonResult, newton

# Newmark's parameters (a scene's delta and beta_newmark take these ranges): delta >= 1/2, or every
# step amplifies (no stable step size); beta = 0 is explicit (CentralDifference); beta <= 1/2.
DELTA_RANGE = dict(low=0.5, high=1.0)
BETA_RANGE = dict(low=0.0, high=0.5, low_open=True)
EPS = float(np.finfo(float).eps)
SIZE_CHECKED = "a step's size comes from its Schedule, which checks it (schedule.check_dt)"


def initial_acceleration(system, t, u, dt=None, state=None):
    """a0 from M a0 = P(u0, t0) - R(u0) - R_c(u0) (eq 29 at t0), with the SystemState ``state``
    (default: ``system.start(u, t)``). Prescribed dofs get 0 (their acceleration is not known
    from the data)."""
    state = system.start(u, t) if state is None else state
    return acceleration(system, system.evaluate(u, t, dt, state=state).G)


def inertia_roundoff(m, c, d, d_pred):
    """The round-off of a stepper's inertia c M (d - d_pred) (Evaluation.roundoff; solver/newton.py): eps
    times its largest operand, c m (|d| + |d_pred|) at the heaviest-loaded dof (m the lumped mass)."""
    return EPS * float(np.max(c * m * (np.abs(d) + np.abs(d_pred)), initial=0.0))


def increment(system, u, d, t1):
    """A step's first increment d over u with the prescribed values at t1 written in (their dofs:
    the prescribed value - u) and the contact's own unknowns (multipliers) kept as they were (0)."""
    d = np.array(d, dtype=float)
    fixed = system.fixed_dofs
    d[fixed] = system.apply_dirichlet(u, t1)[fixed] - u[fixed]
    d[system.contact_dofs] = 0.0
    return d


class Newmark:
    """Implicit Newmark stepper (paper Sec. 4.1), full Newton within the step.

    ``newton_options`` (atol, rtol, ctol, maxit) are passed on to ``newton``.
    """

    dynamic = True

    def __init__(self, system, delta=0.7, beta=0.4, **newton_options):
        require("delta", delta, **DELTA_RANGE)
        require("beta", beta, **BETA_RANGE)
        if beta < (delta + 0.5) ** 2 / 4:
            warnings.warn(
                f"Newmark delta={delta}, beta={beta} is not unconditionally stable (needs beta >= (delta + 1/2)^2 / 4)",
                stacklevel=2,
            )
        for contact in system.contacts:
            if contact.integration != "standard":
                raise ValueError(
                    f"contact {contact.name!r} is built for {contact.integration} integration: "
                    "step it with EnergyConsistent, not Newmark"
                )
        self.system, self.delta, self.beta = system, delta, beta
        self.newton_options = newton_options
        self.error_model = newmark_error_model(delta, beta)  # how its step errs (estimate.py)

    def step(self, t, u, v, a, dt, label="", *, state):
        assert dt > 0, SIZE_CHECKED
        s, beta, delta = self.system, self.beta, self.delta
        t1 = t + dt
        c = 1.0 / (beta * dt**2)
        cM = c * s.mass()  # the step's constants: c M and the predictor's increment
        lumped = isinstance(cM, np.ndarray)  # a diagonal (ndof,), else a sparse consistent M
        m = s.lumped_mass()
        d_pred = dt * v + dt**2 * (0.5 - beta) * a  # u_pred - u

        # Newton's unknown is the step's increment d = u+ - u (newton's ``base``): a+ = c (d - d_pred) then
        # carries the round-off of d, not of u (solver/newton.py: the inertia's round-off)
        def effective(d):  # eq 29 with a+ = c (d - d_pred); tangent K + c M
            ev = s.evaluate(s.apply_dirichlet(u + d, t1), t1, dt, u, mass_coefficient=c, state=state)
            inertia = cM * (d - d_pred) if lumped else cM @ (d - d_pred)
            return ev._replace(G=ev.G + inertia, inertia=inertia, roundoff=inertia_roundoff(m, c, d, d_pred))

        # initial guess: the acceleration stays a (d = dt v + dt^2 a / 2); multipliers as they were
        result = newton(
            effective,
            increment(s, u, d_pred + beta * dt**2 * a, t1),
            s.free_dofs,
            instrument=s.instrument,
            base=u,
            label=label or f"t = {t1:.6g}, dt = {dt:.3g}",
            **self.newton_options,
        )
        d = result.u
        u1 = s.apply_dirichlet(u + d, t1)
        a1 = c * (d - d_pred)
        v1 = v + dt * ((1 - delta) * a + delta * a1)
        own = s.contact_dofs
        a1[own], v1[own] = 0.0, 0.0
        return u1, v1, a1, result


class Static:
    """Quasi-static stepper: solves R(u+) + R_c(u+) = P(u+, t+) (no inertia).

    ``dt`` of a step is the pseudo-time increment of load stepping; v and a are returned as 0.
    """

    dynamic = False
    error_model = None  # no inertia: no time-stepping error to estimate

    def __init__(self, system, **newton_options):
        self.system, self.newton_options = system, newton_options

    def step(self, t, u, v, a, dt, label="", *, state):
        assert dt > 0, SIZE_CHECKED
        s, t1 = self.system, t + dt
        result = newton(
            lambda w: s.evaluate(w, t1, dt, u, state=state),
            s.apply_dirichlet(u, t1),
            s.free_dofs,
            instrument=s.instrument,
            label=label or f"t = {t1:.6g}",
            start=u,
            **self.newton_options,
        )
        zero = np.zeros(s.ndof)
        return result.u, zero, zero.copy(), result


class CentralDifference:
    """Explicit central differences (Newmark beta = 0, delta = 1/2):

        u+ = u + dt v + dt^2 a / 2,   M a+ = P - R(u+) - R_c(u+),   v+ = v + dt (a + a+) / 2

    (a diagonal solve for a lumped M, a sparse one for a consistent M).

    Conditionally stable: dt < 2 / omega_max. Prescribed dofs: v+ = (u+ - u) / dt, a+ = 0.
    (The tangent is assembled but unused; fine for the small problems here.)
    """

    dynamic = True
    error_model = newmark_error_model(0.5, 0.0)  # its velocities: the trapezoidal rule (estimate.py)

    def __init__(self, system):
        if np.any(system.lumped_mass()[system.free_dofs] <= 0):
            raise ValueError("CentralDifference needs mass > 0 on every free dof")
        self.system = system

    def step(self, t, u, v, a, dt, label="", *, state):
        assert dt > 0, SIZE_CHECKED
        s, t1 = self.system, t + dt
        u1 = s.apply_dirichlet(u + dt * v + 0.5 * dt**2 * a, t1)
        ev = s.evaluate(u1, t1, dt, u, state=state)
        a1 = acceleration(s, ev.G)
        v1 = v + 0.5 * dt * (a + a1)
        v1[s.fixed_dofs] = (u1 - u)[s.fixed_dofs] / dt
        if not (np.all(np.isfinite(u1)) and np.all(np.isfinite(a1))):
            raise NewtonError(f"explicit step gave NaN/inf ({label or f't = {t1:.6g}'})", [], label, 1)
        G = ev.G + s.mass_times(a1)
        return (
            u1,
            v1,
            a1,
            NewtonResult(u=u1, residuals=[], iterations=0, G=G, evaluation=ev._replace(G=G), evaluations=1),
        )
