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
    straight: bool          # second variations of g_N and s zero everywhere (a rigid line or polyline)

    def locate(self, x_s: np.ndarray, s_bar: np.ndarray, u: np.ndarray, t=None, ref=None) -> dict:
        """The kinematics of each slave with its closest master segment (masters.py): g_N, s,
        dg_N, ds, d2g_N, d2s, master_dofs, inside, seg (and s_next)."""

    def reference(self, u: np.ndarray) -> object:
        """What the master remembers of a converged state (a metric), None if nothing."""


@runtime_checkable
class Contact(Protocol):
    """A contact interface (contact/interface.py: NodeToSegment and its augmented form).

    ``evaluate`` is pure: a state (contact/state.py) from u and the committed history;
    ``commit`` keeps a converged state's history; nothing else changes a contact.

    ``unknowns``: how many unknowns of its own the contact carries (the Lagrange multipliers
    of contact/lagrange.py; 0 for penalty contacts). The System places them after the
    bodies' dofs and tells the contact where (``dof_offset``); the contact's states then
    give their rows of the residual and the tangent like any other."""

    name: str
    history: object
    integration: str            # "standard" | "energy_consistent"
    unknowns: int               # unknowns of its own (0: only the bodies' dofs)

    def start(self, u: np.ndarray, t: float = 0.0) -> None:
        """The history at the initial state u."""

    def evaluate(self, u: np.ndarray, t: float = 0.0, dt=None, u0=None, phase=None):
        """The ContactState at the trial u of the step (t - dt, t] that starts from u0."""

    def commit(self, state) -> None:
        """Keep the converged state's history."""
