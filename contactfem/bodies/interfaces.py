"""What a body and a load are: the interfaces the solver relies on, written down.

``typing.Protocol`` classes: any object with these members is one (the beam and the
continuum, the loads of loads.py and a student's own); the solver never asks what a body
or load can do (no ``hasattr``). ``u`` is always the body's own (local) displacement vector
for a body, the global one for a load; ``dt`` is the step being taken (only a body with a
rate-dependent law, the viscoplastic beam, needs it).

Bodies and loads hold their configuration only. What they remember from step to step (a
viscoplastic beam's plastic strains, a gas pressure's value) is their ``state``, a value:
``start`` gives the first, ``commit`` returns the next, the System carries it (its
SystemState, solver/system.py) and passes it to every call that needs it.
"""

from typing import Protocol, runtime_checkable

import numpy as np


MASS_MATRICES = ("lumped", "consistent")


@runtime_checkable
class Body(Protocol):
    """A body (see contactfem.bodies): node positions, unknowns, mass, internal forces."""

    name: str
    X: np.ndarray  # (nn, 2) reference positions of the nodes that can touch
    ndof: int
    xdofs: np.ndarray  # (nn, 2) local dof numbers of each node's (u_x, u_y)
    hyperelastic: bool  # a stored energy and no history (energy-consistent stepping needs it)
    quadratic_energy: bool  # W(u) quadratic (a linear body): the midpoint rule is energy-exact for it
    mass_matrix: str  # the mass the System uses: "lumped" or "consistent" (MASS_MATRICES)
    rotation_dofs: np.ndarray  # local dofs that are angles (a beam's theta; none for a continuum)

    def mass(self, consistent: bool = False):
        """The lumped (diagonal) mass, (ndof,); with ``consistent=True`` the consistent mass as a
        scipy sparse matrix (ndof, ndof), whose row sums are the lumped mass (asked for only of a
        body whose ``mass_matrix`` is "consistent")."""

    def start(self, u: np.ndarray) -> object:
        """The internal variables at the initial state u (None for an elastic body)."""

    def internal_coo(self, u: np.ndarray, dt: float | None = None, state: object = None) -> tuple:
        """(R, rows, cols, vals): internal forces R(u) and the tangent dR/du as COO triplets,
        with the committed internal variables ``state``; rows and cols the same objects from
        call to call while the pattern is the same."""

    def internal(self, u: np.ndarray, dt: float | None = None, state: object = None) -> tuple:
        """(R, K) with K a scipy sparse matrix."""

    def strain_energy(self, u: np.ndarray, dt: float | None = None, state: object = None) -> float:
        """The stored energy at u."""

    def commit(self, u: np.ndarray, dt: float | None = None, state: object = None) -> object:
        """The internal variables after a step of dt from ``state`` converged at u."""

    def discrete_gradient(self, u0: np.ndarray, u1: np.ndarray) -> tuple:
        """(F, rows, cols, vals): the internal force of an energy-consistent step u0 -> u1 and its
        tangent dF/du1 as COO triplets; F . dq = W(u1) - W(u0) exactly, dq the increment with the
        angles' 2 tan(Delta theta / 2) (bodies/discrete_gradient.py), and no resultant.
        Hyperelastic bodies only."""


@runtime_checkable
class Load(Protocol):
    """An external load (see bodies/loads.py)."""

    def start(self, u: np.ndarray, t: float = 0.0, offsets: dict | None = None) -> object:
        """The load's state at the initial state (u, t) (None for a load without one);
        ``offsets``: where the bodies' dofs start in u (a System's: contact/placement.py)."""

    def assemble(self, u: np.ndarray, t: float, state: object = None, offsets: dict | None = None) -> tuple:
        """(P, rows, cols, vals): the external forces (global) and dP/du as COO triplets, with
        the load's ``state``."""

    def commit(self, u: np.ndarray, t: float, state: object = None, offsets: dict | None = None) -> object:
        """The load's state after the converged state u at time t (a gas pressure's next value)."""
