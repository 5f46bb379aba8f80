"""What a normal law and a friction law are, written down (the full friction-law protocol,
with slip rates and internal variables, is spelled out in protocol.py).

``typing.Protocol`` classes: any object with these members is one (the shipped laws and a
student's own, usually a frozen dataclass). The contact calls laws only through the adapters
of protocol.py, which read these members and check what they return.
"""

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class NormalLaw(Protocol):
    """t_N(g_N) (Sec. 2.1): signed normal traction, <= 0 in contact, 0 when open."""

    def traction(self, g_N: np.ndarray) -> tuple:
        """(t_N, dt_N/dg_N), vectorised over contact nodes."""


@runtime_checkable
class FrictionLawSpec(Protocol):
    """A friction law (Sec. 2.2): the stick stiffness c_T (eq 5) and the slip bound Y (eq 10)."""

    c_T: float

    def slip_bound(self, p: np.ndarray, q: np.ndarray) -> object:
        """Y(p, q), or (Y, dY/dp, dY/dq); see protocol.py for slip_bound(p, q, v[, z])."""
