"""What a master and a contact are: the interfaces the solver relies on, written down.

The solver never asks what an object can do (no ``hasattr``): a master and a contact have
exactly these members. ``typing.Protocol`` classes: any object with these members is one
(no inheritance needed), and ``isinstance(x, Contact)`` checks the members are there.
"""

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Master(Protocol):
    """A master surface (contact/masters.py): rigid (a line, polyline, arc, composite) or a
    deformable body's boundary (BodySurface)."""

    rigid: bool
    straight: bool  # second variations of g_N and s zero everywhere (a rigid line or polyline)

    def locate(
        self, x_s: np.ndarray, s_bar: np.ndarray, u: np.ndarray, t=None, ref=None, offsets: dict | None = None
    ) -> dict:
        """The kinematics of each slave with its closest master segment (masters.py): g_N, s,
        dg_N, ds, d2g_N, d2s, master_dofs, inside, seg (and s_next)."""

    def reference(self, u: np.ndarray, offsets: dict | None = None) -> object:
        """What the master remembers of a converged state (a metric), None if nothing."""


@runtime_checkable
class Contact(Protocol):
    """A contact interface (contact/interface.py: NodeToSegment and its augmented form; the
    mortar and Lagrange contacts).

    A contact holds its configuration only. ``start`` gives the history of the initial state,
    ``evaluate`` is pure: a state (contact/state.py) from u and the ``history`` it is given;
    ``commit`` returns the history after a converged state. The System carries the histories
    in its SystemState (solver/system.py); nothing changes a contact.

    ``unknowns``: how many unknowns of its own the contact carries (the Lagrange multipliers
    of contact/lagrange.py; 0 for penalty contacts). The System places them after the
    bodies' dofs and keeps where, with where each body's dofs start (``offsets``, by identity:
    contact/placement.py), handed to ``start`` and ``evaluate``; the contact's states then
    give their rows of the residual and the tangent like any other."""

    name: str
    integration: str  # "standard" | "energy_consistent"
    unknowns: int  # unknowns of its own (0: only the bodies' dofs)

    def start(self, u: np.ndarray, t: float = 0.0, *, offsets: dict | None = None) -> object:
        """The history at the initial state u (a value)."""

    def evaluate(
        self,
        u: np.ndarray,
        t: float = 0.0,
        dt: float | None = None,
        u0: np.ndarray | None = None,
        phase: object = None,
        *,
        history: object,
        offsets: dict | None = None,
    ) -> object:
        """The contact's state at the trial u of the step (t - dt, t] that starts from u0, with
        the committed ``history``."""

    def commit(self, state: object) -> object:
        """The history after the converged ``state``."""


@runtime_checkable
class NodeToSegmentContact(Contact, Protocol):
    """What a node-to-segment contact's states (contact/state.py: ContactState) read of the
    contact that made them, besides the Contact protocol: where the slaves are, the weights
    and stick stiffness of its energies, and the functions of its laws."""

    slave: object  # the slave body (contactfem.bodies.interfaces.Body)
    nodes: np.ndarray  # (nc,) slave node numbers
    master: Master
    weights: np.ndarray  # (nc,) per-slave weights of the tractions
    c_T: float  # stick stiffness of the friction law (0: frictionless)

    def pattern(self, dofs: np.ndarray) -> tuple:
        """(rows, cols) of the element tangents at the pairs' dofs (m, k)."""

    def gap_offset(self, z: np.ndarray) -> np.ndarray:
        """How far the friction law's internal variables z have moved the surface, (nc,)."""

    def normal_energy(self, g_N: np.ndarray) -> np.ndarray:
        """The normal law's potential at g_N (0 for a law without one)."""
