"""The enforcement parameters a scene shares: penalty (the paper) or augmented Lagrangian
(contact/augmented.py, solver/uzawa.py), the Uzawa tolerance, and the results every scene
reports about it (uzawa_iterations, newton_per_outer, gap_violation)."""

import numpy as np

from ..contact.augmented import ENFORCEMENTS
from ..solver.uzawa import Uzawa
from .base import Param

ENFORCEMENT_PARAMS = (
    Param("enforcement", "penalty", choices=ENFORCEMENTS,
          doc="penalty: the paper's penalty method (the result depends on c_N); augmented: Lagrange "
              "multipliers updated in an outer Uzawa loop until the contact conditions hold to uzawa_tol "
              "(c_N, c_T become numerical parameters; a power law with m != 1 stays a constitutive law)"),
    Param("uzawa_tol", 1e-9, "", 0.0, 1e-2, low_open=True,
          doc="augmented: stop when the largest multiplier change / c (the penetration at an active node, "
              "the stick creep at a sticking one), divided by the scene's length, is <= uzawa_tol",
          when=(("enforcement", ("augmented",)),)),
    Param("uzawa_max_updates", 200, "", 0, 100000, doc="augmented: multiplier updates allowed per step",
          when=(("enforcement", ("augmented",)),)),
)


def wrap(params, stepper, contacts, length):
    """The stepper itself (penalty) or wrapped in the Uzawa loop (augmented)."""
    if params["enforcement"] == "penalty":
        return stepper
    return Uzawa(stepper, contacts, length, tol=params["uzawa_tol"], max_updates=params["uzawa_max_updates"])


def report(params, records, penetration, length, length_name):
    """What a scene reports about its enforcement, from its records: uzawa_iterations (outer
    iterations summed over the steps; 0 for penalty), multiplier_updates, newton_per_outer
    (linear solves of each outer iteration, all steps in order; for penalty the solves of each
    step) and gap_violation = largest penetration / length, the length the scene states
    (``length_name``), with its value after each outer iteration (gap_violation_per_outer).
    For a penalty step the traction error is about c_N times the gap; with the augmented
    method it is about c_N times the last gap violation, so tractions to a relative accuracy eps
    need uzawa_tol ~ eps p / (c_N length) (p a traction scale)."""
    results = [rec.result for rec in records[1:]]
    if params["enforcement"] == "penalty":
        per_outer, outer, updates, gaps = [int(r.iterations) for r in results], 0, 0, []
    else:
        gaps = [float(g) for r in results for g in r.gap_violations]
        per_outer = [int(i) for r in results for i in r.newton_per_outer]
        outer = sum(r.uzawa_iterations for r in results)
        updates = sum(r.updates for r in results)
    return dict(enforcement=params["enforcement"], uzawa_iterations=int(outer), multiplier_updates=int(updates),
                newton_per_outer=per_outer, gap_violation=float(max(penetration, 0.0) / length),
                gap_violation_length=float(length), gap_violation_length_is=length_name,
                gap_violation_per_outer=gaps)


def penetration(state):
    """Largest penetration max(-g_N, 0) over the slave nodes of a contact state."""
    return float(np.max(np.maximum(-state.g_N, 0.0), initial=0.0))
