"""Augmented-Lagrangian contact: the penalty interface of the paper with Lagrange
multipliers updated in an outer (Uzawa) loop, so that the converged solution meets the
contact conditions to a tolerance whatever the penalty (Simo & Laursen 1992, "An
augmented Lagrangian treatment of contact problems involving friction", Computers &
Structures 42, 97-116).

Per slave node two multipliers, both tractions (per unit length or per node, like the
interface's laws): lam_N <= 0 for the normal and lam_T for the tangential traction. They
are held FIXED during a Newton solve and updated after it (solver/uzawa.py).

Normal (penalty law eq 4 with m = 1, c_N the penalty):

    t_N = min(0, lam_N + c_N g_N) = t_N^law(g_N + lam_N / c_N),   dt_N/dg_N = c_N where active,

i.e. the penalty law evaluated at the gap shifted by lam_N / c_N. The update
lam_N <- t_N converges to g_N = 0 where lam_N < 0: no penetration, whatever c_N.

Friction (the stick law eq 5 becomes the penalty of exact stick): the elastic predictor of
the return mapping starts from lam_T instead of the converged traction (eqs 40-44),

    t_T^tr = lam_T + c_T (s - s_bar),   t_T = return_map(t_T^tr, Y(|t_N|)),   lam_T <- t_T.

At the fixed point a sticking node has s = s_bar (no elastic micro-slip) and carries
t_T = lam_T, |lam_T| <= Y; a slipping one carries t_T = Y sign(t_T^tr) and slips by
|s - s_bar| (the return map's lambda). The tangent is the penalty interface's (eqs 33,
39, 49-50) at the shifted state: the multipliers do not depend on u.

Laws other than the penalty: a power law with m != 1 (or the exponential law) is a
constitutive law of a rough interface, its approach g_N < 0 is physical (the asperities
flatten), not an error to remove. Such a normal law is used AS IS (no normal multiplier,
lam_N stays 0) while the friction is still augmented: only the stick spring c_T is
treated as a penalty. ``gap_violation`` counts the augmented normal interfaces only.

Step history: at the start of a step lam_T is the converged t_T (warm start: the first
outer iteration is exactly the penalty step); lam_N carries over from the last step. The
multipliers are part of the history (AugmentedHistory), a value: ``update_multipliers``
returns the history with the new ones, and the contact keeps nothing.
"""

from dataclasses import dataclass, replace

import numpy as np

from ..laws.normal import PowerLaw
from .interface import NodeToSegment
from .state import ContactHistory

ENFORCEMENTS = ("penalty", "augmented")


def augments_normal(law):
    """True when the normal law is the penalty method (eq 4 with m = 1), whose c_N is a
    numerical parameter the multiplier removes; False for constitutive laws."""
    return isinstance(law, PowerLaw) and law.m == 1.0


@dataclass(frozen=True)
class AugmentedHistory(ContactHistory):
    """A ContactHistory with the multipliers the next solve holds fixed: lam_N (normal, 0 when
    the normal law is not augmented) and lam_T (tangential), per slave node."""

    lam_N: np.ndarray | None = None
    lam_T: np.ndarray | None = None


class AugmentedNodeToSegment(NodeToSegment):
    """NodeToSegment (same arguments) with normal and tangential multipliers (module
    docstring) in its history (AugmentedHistory), held fixed during a Newton solve:
    ``update_multipliers(state)`` is the Uzawa update from a converged inner state; everything
    else is used by the solver exactly like the penalty interface."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.augment_normal = augments_normal(self.normal)

    def start(self, u, t=0.0, *, offsets=None):
        """The penalty interface's initial history with zero multipliers."""
        h = super().start(u, t, offsets=offsets)
        nc = len(self.nodes)
        return AugmentedHistory(**vars(h), lam_N=np.zeros(nc), lam_T=np.zeros(nc))

    def kinematics(self, u, t, h, offsets=None):
        """As NodeToSegment.kinematics, with the penalty law evaluated at the shifted gap
        g_N + lam_N / c_N (eq 4, m = 1; module docstring)."""
        e = super().kinematics(u, t, h, offsets)
        if not self.augment_normal:
            return e
        g_eff = e["g_N"] + h.lam_N / self.normal.c_N
        active = e["inside"] & (g_eff < 0.0)
        t_N, dt_N = self.normal.traction(np.where(active, g_eff, 1.0))
        return dict(e, active=active, t_N=t_N, dt_N=dt_N, g_eff=g_eff)

    def predictor(self, h):
        """The return mapping (eqs 40-44) starts from the multiplier lam_T (module docstring)."""
        return h.lam_T

    def violation(self, state):
        """What the next update would change at a converged inner state, in length units:
        max |t - lam| / c over the slave nodes, normal (= the penetration of an active node)
        and tangential (= the stick creep |s - s_bar| of a sticking node); and the largest
        penetration (augmented normal only; 0 otherwise)."""
        on, h = state.active, state.history
        dN = pen = 0.0
        if self.augment_normal:
            t_N = np.where(on, state.t_N, 0.0)
            dN = float(np.max(np.abs(t_N - h.lam_N), initial=0.0)) / self.normal.c_N
            pen = float(np.max(np.where(state.inside, -state.g_N, 0.0), initial=0.0))
        dT = 0.0
        if self.friction is not None:
            t_T = np.where(on, state.t_T, 0.0)
            dT = float(np.max(np.abs(t_T - h.lam_T), initial=0.0)) / self.c_T
        return dict(change=max(dN, dT, 0.0), normal=dN, tangential=dT, penetration=max(pen, 0.0))

    def update_multipliers(self, state):
        """The history of the state with the Uzawa update lam <- t at a converged inner state
        (module docstring): the next outer iteration of the same step is evaluated with it."""
        on, h = state.active, state.history
        lam_N = np.where(on, state.t_N, 0.0) if self.augment_normal else h.lam_N
        lam_T = np.where(on, state.t_T, 0.0) if self.friction is not None else h.lam_T
        return replace(h, lam_N=lam_N, lam_T=lam_T)

    def commit(self, state):
        """The penalty interface's next history (t_T_bar = t_T, accumulated slip, projection)
        with lam_T = t_T_bar, so the next step starts from the converged traction, and
        lam_N = t_N (warm start of the next step)."""
        h = state.next_history
        lam_N = np.where(state.active, state.t_N, 0.0) if self.augment_normal else state.history.lam_N
        return AugmentedHistory(**vars(h), lam_N=lam_N, lam_T=h.t_T_bar.copy())


def make_interface(enforcement, *args, **kwargs):
    """A NodeToSegment (enforcement = 'penalty') or an AugmentedNodeToSegment
    ('augmented') with the same arguments."""
    if enforcement == "penalty":
        return NodeToSegment(*args, **kwargs)
    if enforcement == "augmented":
        return AugmentedNodeToSegment(*args, **kwargs)
    raise ValueError(f"parameter enforcement = {enforcement!r} is not allowed: one of {'|'.join(ENFORCEMENTS)}")
