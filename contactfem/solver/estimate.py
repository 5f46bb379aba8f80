"""The local error of a time step: one estimator for the steps of a run at a tolerance
(schedule.py), its ``error_budget`` indicator and the time resolution's thresholds
(problem/accuracy.py: ErrorModel.half_period_error). The time loop (march.py) estimates every
dynamic step and records it,

    rec.error     StepError(local, share): the step's local error, and what its tolerance allows
    rec.state.slope   Slope: what the next step's estimate needs (the run carries it as a value)

so a run resumed from any record estimates as it went.

A step of Newmark (delta, beta) updates the velocities by dt ((1 - delta) a + delta a+); against
the Taylor series of the exact motion its local error is

    (delta - 1/2) dt^2 a' + (delta / 2 - 1/6) dt^3 a'' + ...,     a' ~ (a+ - a) / dt,

first order in dt where delta > 1/2 (the paper's 0.7): c dt |a+ - a| with c = delta - 1/2. This
term is the method's numerical damping: it takes the energy of the vibrations an impact excites,
and a rebound's or a rolling ring's speed with it. The trapezoidal rule (delta = 1/2, beta = 1/4)
and the energy-consistent midpoint rule are second order: there the first term vanishes and the
error is the second, dt^3 a'' / 12, from the second difference of the accelerations over the last
two steps (hs their sizes, s = (a+ - a) / h their slopes):

    a'' ~ (s - s_prev) / ((h + h_prev) / 2)

(the midpoint rule's is dt^3 a'' / 24: 1/12 bounds both; the explicit central difference updates
the velocities by the trapezoidal rule too). The norm is the kinetic energy's, a mass-weighted root
mean square (sum m_i d_i^2 / sum m_i)^(1/2): the vibrations an impact excites change the contact
forces while the bodies touch, and the headline quantities with them. The first step has no slope
before it: its estimate is the bound c dt |a+ - a| with c = |beta - 1/6| (Zienkiewicz and Xie's,
1/12 for both second-order steppers), and so has the second (the first step's slope starts from an
initial acceleration a scene may set by hand: the cork's pop starts at rest with a0 = 0).

The local errors of the steps add up: their sum bounds the error of the velocities at the run's
end (``time_error``), an error in the units of the velocities, which the scene compares with its
speed. (Stability keeps the errors of earlier steps from growing in an unconditionally stable
integrator; the sum is the bound of error per unit step.)
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ErrorModel:
    """How a time stepper's step errs: as Newmark's (``delta``, ``beta``) (the energy-consistent
    midpoint rule as the trapezoidal rule (1/2, 1/4), which it is for a linear oscillator; the
    explicit central difference as (1/2, 0)). ``order``: 1 (a first-order velocity update, delta >
    1/2: the first-difference bound every step) or 2; ``c``: the constant of the first-difference
    bound c dt |a+ - a| (module docstring)."""

    delta: float
    beta: float

    @property
    def order(self):
        return 1 if abs(self.delta - 0.5) > 1e-12 else 2

    @property
    def c(self):
        return abs(self.delta - 0.5) if self.order == 1 else abs(self.beta - 1.0 / 6.0)

    @property
    def power(self):
        """The power of the error's ratio that gives the next step at a tolerance (schedule.py):
        1 / order, the local error of a step of h being ~ h^(order + 1) and its share ~ h."""
        return 1.0 / self.order

    def half_period_error(self, omega_dt):
        """The relative error of a linear oscillator (frequency w) integrated over half its period,
        pi / (w dt) steps of w dt = ``omega_dt``: an impact on a penalty spring is such a half period.
        From the principal eigenvalues rho exp(+-i W) of the integrator's amplification matrix (Hughes,
        The Finite Element Method, Sec. 9.3): |rho^n exp(i n W) + 1| with n = pi / omega_dt, amplitude
        (numerical damping) and phase (period error) together."""
        O2 = omega_dt * omega_dt
        A = np.empty((3, 3))  # one step on (u, dt v, dt^2 a)
        for j, (u, v, a) in enumerate(np.eye(3)):
            u1 = (u + v + (0.5 - self.beta) * a) / (1.0 + self.beta * O2)
            a1 = -O2 * u1
            A[:, j] = (u1, v + (1.0 - self.delta) * a + self.delta * a1, a1)
        lam = np.linalg.eigvals(A)
        lam = lam[np.argmax(np.abs(lam))] if not np.any(lam.imag) else lam[np.argmax(np.abs(lam.imag))]
        n = np.pi / omega_dt
        return float(abs(abs(lam) ** n * np.exp(1j * n * abs(np.angle(lam))) + 1.0))

    def resolving_omega_dt(self, tol):
        """The largest w dt (below 2: a few steps a period) at which half_period_error is within tol
        (it grows with w dt): 0.44 for the trapezoidal rule at 5 %, 0.16 for the paper's Newmark 0.7,
        0.4 (its damping), 0.61 for the central difference."""
        lo, hi = 0.0, 2.0
        if self.half_period_error(hi) <= tol:
            return hi
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self.half_period_error(mid) <= tol else (lo, mid)
        return lo


def newmark_error_model(delta, beta):
    """Newmark's (delta, beta) (ErrorModel): first order with c = delta - 1/2 where delta > 1/2,
    else second order with c = |beta - 1/6| (Zienkiewicz and Xie)."""
    return ErrorModel(float(delta), float(beta))


MIDPOINT = ErrorModel(0.5, 0.25)  # the energy-consistent midpoint rule: c = 1/12 bounds its dt^3 a'' / 24


@dataclass(frozen=True, eq=False)
class Slope:
    """What a step hands to the next step's estimate (SystemState.slope): the slope of the
    accelerations over it, (a+ - a) / dt (None after a march's first step), its size dt, and
    ``careful``: a flight a run at a tolerance steps again, in the kinetic energy's norm, after its
    optimistic try ended in a contact (march.py), until the next contact."""

    value: np.ndarray | None
    dt: float
    careful: bool = False


@dataclass(frozen=True)
class StepError:
    """A step's local error in the velocities (``local``, kinetic energy's norm, the velocities'
    unit), the error its share of a tolerance allows a step of its size (``share``: None for
    fixed steps) and the ErrorModel of the stepper that took it (``model``)."""

    local: float
    share: float | None = None
    model: ErrorModel | None = None


def norm(mass, d):
    """|d| in the kinetic energy's norm, (sum m_i d_i^2 / sum m_i)^(1/2) (m: the lumped mass)."""
    return float(np.sqrt(np.sum(mass * d * d) / np.sum(mass)))


def momentum_norm(mass, d, positions):
    """|d| in the bodies' momentum: each body's mass-weighted mean of d over its positions (the
    error of its centre of mass's velocity, per direction), in the mass-weighted root mean square
    over the bodies. ``positions``: one (nodes, dim) array of global dofs a body."""
    total, out = 0.0, 0.0
    for x in positions:
        m = mass[x]
        body = float(np.sum(m[:, 0]))
        out += body * float(np.sum((np.sum(m * d[x], axis=0) / body) ** 2))
        total += body
    return float(np.sqrt(out / total))


def error_vector(model, a, a1, dt, before):
    """The step's local error in the velocities, a vector (module docstring; its size: ``norm``),
    and the Slope it hands on. ``model``: the stepper's ErrorModel; ``a``, ``a1``: the step's
    accelerations at its start and end; ``before``: the Slope the step before handed on (None at a
    march's first step). The first step hands on no slope (Slope(None, dt)): it starts from the
    initial acceleration, which a scene may set by hand, so the second step takes the first-
    difference bound too."""
    slope = (a1 - a) / dt
    handed = Slope(None if before is None else slope, dt, False if before is None else before.careful)
    if model.order == 1 or before is None or before.value is None:
        return model.c * dt * (a1 - a), handed
    return dt**3 / 12.0 * (slope - before.value) / (0.5 * (dt + before.dt)), handed


def local_error(model, mass, a, a1, dt, before):
    """The step's local error in the velocities in the kinetic energy's norm (module docstring), and
    the Slope it hands on (error_vector; ``mass``: the lumped mass)."""
    d, handed = error_vector(model, a, a1, dt, before)
    return norm(mass, d), handed


def time_error(records):
    """The time part of a run's error bar from its own records: the sum of its steps' local errors
    (rec.error.local, the velocities' unit), which bounds the error of the velocities at the run's
    end (module docstring); None where no step has an estimate (a static run). A velocity the run
    reports (a rebound, the centre of mass's: a mass-weighted mean, which the kinetic energy's norm
    bounds) errs by at most this. A bound, not an estimate: on the fast presets' fixed steps it is 10
    to 70 times the error a refined run shows (problem/accuracy.py, _time_resolution); a run at a
    tolerance holds it to its tolerance (schedule.AtTolerance)."""
    errors = [r.error.local for r in records if r.error is not None]
    return float(sum(errors)) if errors else None
