"""Contact tangents other than the consistent one (paper Sec. 4.2), to compare Newton's
convergence: the residual is always eq (28), only the matrix handed to the solver changes.
A contact is built with its tangent, ``NodeToSegment(..., tangent=...)``:

    consistent  eqs 33, 39, 49-50 (the contact as it is; non-symmetric)
    symmetric   (K_c + K_c^T) / 2
    frozen      K_c without the coupling w c_N^s C of eq (50), C = ds dg_N^T: the slip bound
                is treated as independent of the normal gap in the tangent

and the phases of the staggered (two-step) algorithm of Sec. 2.2 (solver/staggered.py): a
``Phase`` frozen from a full evaluation, handed to ``evaluate(..., phase=...)``:

    normal      the friction state frozen: stick about it, t_T = t_T* + c_T (s - s*)
    friction    the normal pressure p* = |t_N| frozen in the return mapping (c_N^s = 0)
"""

from dataclasses import dataclass

import numpy as np

TANGENTS = ("consistent", "symmetric", "frozen")
PHASES = ("normal", "friction")


@dataclass(frozen=True)
class Phase:
    """A phase of the staggered algorithm with the quantities it freezes (per slave node):
    t_T* and s* (normal phase), p* = |t_N| (friction phase); zero at open nodes."""

    kind: str
    t_T: np.ndarray
    s: np.ndarray
    p: np.ndarray


def freeze(state, kind):
    """The Phase `kind` frozen from a full evaluation (a ContactState)."""
    if kind not in PHASES:
        raise ValueError(f"parameter phase = {kind!r} is not allowed: one of {'|'.join(PHASES)}")
    on = state.active
    return Phase(kind=kind, t_T=np.where(on, state.t_T, 0.0), s=state.s.copy(), p=np.where(on, -state.t_N, 0.0))
