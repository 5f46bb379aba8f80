"""The contact conditions as equations: nonlinear complementarity functions of the
normal and the Coulomb conditions, for a semi-smooth Newton method (beyond the paper,
which enforces the conditions by penalty, eqs 4-5, and the return map, eqs 40-48).

Per contact node, with the multipliers as unknowns: the normal traction t_N (<= 0 in
contact, p = -t_N the pressure) and the tangential traction t_T; the gap g_N and the slip
increment of the step Delta g_T (eq 20) come from the kinematics. The conditions

    normal (Signorini):   g_N >= 0,   p >= 0,   p g_N = 0
    friction (Coulomb, eq 11, one step):  |t_T| <= Y(p);  Delta g_T = 0 where |t_T| < Y;
                          Delta g_T = lambda sign(t_T), lambda >= 0, where |t_T| = Y

hold exactly when C_N = 0 and C_T = 0 (Alart & Curnier, CMAME 92, 1991, the projection
form; the primal-dual active set strategy of Hueber & Wohlmuth, CMAME 194, 2005, is this
semi-smooth Newton method read as an active-set update), with

    xi  = p - c_N g_N                                  the normal trial
    C_N = p - max(0, xi)
    tau = t_T + c_T Delta g_T                          the tangential trial
    Y   = Y(max(0, xi))                                the slip bound at the trial pressure
    C_T = t_T - clip(tau, -Y, Y)

c_N > 0 and c_T > 0 are complementarity parameters, not penalties: the solution
(C_N = C_T = 0) does not depend on them, only the path of Newton's iterates does. Read
case by case, each node is in one of three sets, decided anew at every evaluation (so
inside Newton, no outer loop):

    open   (xi < 0):               C_N = p,            C_T = t_T              (no traction)
    stick  (xi >= 0, |tau| <= Y):  C_N = c_N g_N,      C_T = -c_T Delta g_T   (no gap, no slip)
    slip   (xi >= 0, |tau| > Y):   C_N = c_N g_N,      C_T = t_T - sign(tau) Y(xi)

and in each set C is smooth; its derivative there is the Newton (generalised) derivative,

    open:   dC_N = -dt_N,            dC_T = dt_T
    stick:  dC_N = c_N dg_N,         dC_T = -c_T d(Delta g_T)
    slip:   dC_N = c_N dg_N,         dC_T = dt_T - sign(tau) Y'(xi) (-dt_N - c_N dg_N).

The ties go to contact and to stick (xi = 0: a node touching with no pressure is closed;
|tau| = Y sticks), so that a body resting on its support at the start (g_N = 0, no
traction yet) is held in the first iteration instead of floating free.

Y(p) is a slip bound of the pressure alone: Coulomb (Y = mu p) and the parabolic slip
surface of eq 10, Y = alpha p^n + beta p (n = 1: conical), which is Coulomb's condition
with a pressure-dependent coefficient mu(p) = alpha p^(n-1) + beta. Laws with slip
hardening, a slip rate or internal variables have no such complementarity function here.
"""

import numpy as np

from ..laws.friction import Coulomb, ParabolicSlip
from ..laws.normal import PowerLaw
from ..laws.return_map import OPEN, SLIP, STICK

LAGRANGE_FRICTION = (Coulomb, ParabolicSlip)


def check_laws(normal, friction, where):
    """The laws a semi-smooth Newton method can take: the penalty law (eq 4, m = 1), whose
    c_N becomes the complementarity parameter, and a slip bound of the pressure alone
    (module docstring). Anything else: one ValueError naming the law and ``where``."""
    if not (isinstance(normal, PowerLaw) and normal.m == 1.0):
        raise ValueError(
            f"{where}: enforcement = lagrange enforces g_N >= 0 exactly and takes the penalty law "
            f"PowerLaw(m = 1) only (its c_N becomes a complementarity parameter); got {normal!r}"
        )
    if friction is not None and not isinstance(friction, LAGRANGE_FRICTION):
        raise ValueError(
            f"{where}: enforcement = lagrange takes Coulomb or ParabolicSlip friction (a slip bound of "
            f"the pressure alone); got {type(friction).__name__}"
        )


def normal_complementarity(t_N, g_N, c_N, eligible=True):
    """C_N, dC_N/dt_N, dC_N/dg_N and xi (module docstring) per node: the Signorini
    conditions in place of the penalty law of eq 4; ``eligible``: nodes that can touch at
    all (a node no master faces is open whatever its gap)."""
    p = -t_N
    g = np.where(eligible, g_N, 0.0)  # (an uncovered mortar node has g_N = inf)
    xi = np.where(eligible, p - c_N * g, -np.inf)
    closed = xi >= 0.0
    C = np.where(closed, c_N * g, p)
    return C, np.where(closed, 0.0, -1.0), np.where(closed, c_N, 0.0), xi


def friction_complementarity(law, t_T, dg_T, xi, c_T):
    """C_T and its derivatives dC_T/dt_T, dC_T/d(Delta g_T), dC_T/dxi, with the set of
    each node (OPEN, STICK, SLIP), for the slip bound Y of ``law`` (eqs 10, 11; module
    docstring): exact stick and slip in place of the stick law of eq 5 and the return map."""
    closed = xi >= 0.0
    p = np.where(closed, xi, 0.0)
    Y, dY = law.slip_bound(np.where(p > 0.0, p, 1.0), np.zeros_like(p))[:2]
    Y, dY = np.where(p > 0.0, Y, 0.0), np.where(p > 0.0, dY, 0.0)
    tau = t_T + c_T * dg_T
    stick = closed & (np.abs(tau) <= Y)
    slip = closed & ~stick
    sign = np.sign(tau)
    C = np.where(stick, -c_T * dg_T, np.where(slip, t_T - sign * Y, t_T))
    dC_dt = np.where(stick, 0.0, 1.0)
    dC_ddg = np.where(stick, -c_T, 0.0)
    dC_dxi = np.where(slip, -sign * dY, 0.0)
    state = np.where(stick, STICK, np.where(slip, SLIP, OPEN))
    return C, dC_dt, dC_ddg, dC_dxi, state
