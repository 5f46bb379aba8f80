"""Disturbing a run the way rounding could, to measure what its results hold.

Two runs of one model on one machine agree bit for bit; on another machine (another BLAS
kernel) or with another factorisation the last bits differ, and where a result sits on a knife's
edge (a step that just converges, a contact that just breaks away) those bits decide it. Under a
condition every System built and every march started takes it:

    linear_algebra   $CONTACTFEM_LINEAR_ALGEBRA: the factorisation every System uses where it would
                     choose its own ("auto"): dense, banded or sparse (solver/assembly.py)
    perturbation     $CONTACTFEM_PERTURB: every march starts from a perturbed state: each free
                     unknown of u0 moved by perturbation x the bodies' extent and v0 scaled by
                     1 + perturbation, each with its own factor in [-1, 1] (seeded: the same
                     condition gives the same run)

The condition is carried by the environment, so that the worker processes a study starts (joblib)
take it too; ``with rounding(...)`` sets it for a block of code. ``contactfem figures
--linear-algebra KIND --perturb EPS`` draws the figures under one; ``contactfem figures
--rounding`` measures every figure's spread under several (plots/rounding.py).
"""

import os
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from .. import environment
from .assembly import KINDS

ENV = dict(linear_algebra="CONTACTFEM_LINEAR_ALGEBRA", perturbation="CONTACTFEM_PERTURB")
LARGEST = 1e-6  # a larger perturbation is a change of the problem, not of its rounding


@dataclass(frozen=True)
class Condition:
    linear_algebra: str | None = None
    perturbation: float = 0.0

    def tag(self):
        """A short name of the condition ("" for none): a folder name for what runs under it keep."""
        parts = [f"la-{self.linear_algebra}"] if self.linear_algebra else []
        parts += [f"perturb-{self.perturbation:g}"] if self.perturbation else []
        return "_".join(parts)


def checked(linear_algebra=None, perturbation=0.0):
    """The Condition of these values; a bad one is a ValueError naming it and its range."""
    if linear_algebra not in (None, "", *KINDS):
        raise ValueError(f"parameter linear_algebra = {linear_algebra!r} is not allowed: one of {'|'.join(KINDS)}")
    try:
        eps = float(perturbation or 0.0)
    except ValueError:
        raise ValueError(f"parameter perturbation = {perturbation!r} is not a number: allowed [0, {LARGEST:g}]")
    if not 0.0 <= eps <= LARGEST:
        raise ValueError(f"parameter perturbation = {eps:g} is out of range: allowed [0, {LARGEST:g}]")
    return Condition(linear_algebra if linear_algebra not in (None, "", "auto") else None, eps)


def current():
    """The rounding condition in force (from the environment; Condition(): none)."""
    return checked(environment.read(ENV["linear_algebra"]), environment.read(ENV["perturbation"]))


@contextmanager
def rounding(linear_algebra=None, perturbation=0.0):
    """Runs inside take the condition (module docstring), and so do processes started inside."""
    condition = checked(linear_algebra, perturbation)
    values = dict(linear_algebra=condition.linear_algebra or "", perturbation=f"{condition.perturbation!r}")
    before = {k: os.environ.get(v) for k, v in ENV.items()}
    os.environ.update({ENV[k]: v for k, v in values.items()})
    try:
        yield condition
    finally:
        for k, v in before.items():
            if v is None:
                os.environ.pop(ENV[k], None)
            else:
                os.environ[ENV[k]] = v


def perturbed(system, u, v):
    """(u, v) of a march's initial state under the current condition (the same arrays without one)."""
    eps = current().perturbation
    if not eps:
        return u, v
    rng = np.random.default_rng(12345)
    extent = max(float(np.ptp(np.asarray(b.X), axis=0).max()) for b in system.bodies)
    u = np.array(u, dtype=float)
    u[system.free_dofs] += eps * extent * rng.uniform(-1.0, 1.0, system.free_dofs.size)
    v = np.array(v, dtype=float) * (1.0 + eps * rng.uniform(-1.0, 1.0, len(v)))
    return u, v
