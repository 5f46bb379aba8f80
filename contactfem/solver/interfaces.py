"""What a time stepper and a schedule are: the interfaces the time loop (march.py) relies on.

``typing.Protocol`` classes: any object with these members is one.
"""

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Stepper(Protocol):
    """One step of a time integrator (newmark.py, conserving.py, uzawa.py, staggered.py)."""

    system: object  # the System it steps
    dynamic: bool  # inertia (v, a) or quasi-static
    error_model: object  # how its step errs (estimate.ErrorModel), None for a static stepper

    def step(
        self, t: float, u: np.ndarray, v: np.ndarray, a: np.ndarray, dt: float, label: str = "", *, state: object
    ) -> tuple:
        """(u1, v1, a1, result) of the step of size dt from the converged (t, u, v, a) with the
        committed SystemState ``state``; commits nothing; ``result.evaluation`` is the System's
        converged evaluation, ``result.G`` the residual whose prescribed-dof part are the
        reactions. Raises NewtonError."""


@runtime_checkable
class ImplicitStepper(Stepper, Protocol):
    """A stepper whose step equation others solve differently (the staggered algorithm,
    staggered.py, reads Newmark's constants; the Uzawa loop, uzawa.py, its Newton options)."""

    beta: float  # Newmark's beta (and delta): the step equation's constants
    delta: float
    newton_options: dict  # atol, rtol, maxit, ... of its Newton solves


@runtime_checkable
class Schedule(Protocol):
    """The step sizes of a march (schedule.py)."""

    dt: float  # the size the initial state is evaluated with
    t_end: float
    n_steps: object  # int, or None when not known beforehand

    def next_dt(self, record) -> object:
        """The size of the step after this record, or None when the run is over."""

    def cut(self, dt: float, cuts: int) -> object:
        """The size to retry a failed step with, or None."""

    def end_time(self, t: float, dt: float) -> float:
        """The time a step of dt from t ends at."""

    def share(self, dt: float) -> object:
        """The local error a step of dt may have (a run at a tolerance), or None."""

    def rejects(self, error: object, dt: float) -> bool:
        """Whether a converged step of dt with this StepError is retried halved."""
