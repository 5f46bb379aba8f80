"""The contact parameters a scene shares: how the contact is discretised (node-to-segment,
the paper's, or mortar: contact/mortar_contact.py) and how its conditions are enforced
(penalty, the paper's; augmented Lagrangian: contact/augmented.py, solver/uzawa.py; Lagrange
multipliers solved by a semi-smooth Newton method: contact/lagrange.py), the Uzawa
tolerance, the contact they build (``interface``) and the results every scene reports about
them (uzawa_iterations, newton_per_outer, gap_violation)."""

import numpy as np

from ..contact import NodeToSegment
from ..contact.augmented import AugmentedNodeToSegment
from ..contact.lagrange import LagrangeMortar, LagrangeNodeToSegment
from ..contact.mortar_contact import MortarContact
from ..solver.newton import ROUNDOFF_RTOL as RTOL
from ..solver.uzawa import Uzawa
from .scene import Param

ENFORCEMENTS = ("penalty", "augmented", "lagrange")
DISCRETIZATIONS = ("node_to_segment", "mortar")

ENFORCEMENT_PARAMS = (
    Param(
        "contact_discretization",
        "node_to_segment",
        choices=DISCRETIZATIONS,
        doc="node_to_segment: the paper's (each slave node against a master segment, eqs 17-50); mortar: "
        "segment-to-segment mortar contact (the tractions a field on the slave surface, integrated "
        "against both meshes: passes the contact patch test), in the reference configuration for "
        "material = linear, in the current one otherwise",
    ),
    Param(
        "enforcement",
        "penalty",
        choices=ENFORCEMENTS,
        doc="penalty: the paper's penalty method (the result depends on c_N); augmented: Lagrange "
        "multipliers updated in an outer Uzawa loop until the contact conditions hold to uzawa_tol "
        "(c_N, c_T become numerical parameters; a power law with m != 1 stays a constitutive law; "
        "node_to_segment only); lagrange: the tractions are unknowns beside the displacements and the "
        "contact conditions equations, solved together by a semi-smooth Newton method (no penalty, no "
        "outer loop; c_N, c_T only steer the iterates; the penalty law m = 1 with Coulomb or the eq 10 "
        "laws)",
    ),
    Param(
        "uzawa_tol",
        1e-9,
        "",
        0.0,
        1e-2,
        low_open=True,
        doc="augmented: stop when the largest multiplier change / c (the penetration at an active node, "
        "the stick creep at a sticking one), divided by the scene's length, is <= uzawa_tol",
        when=(("enforcement", ("augmented",)),),
    ),
    Param(
        "uzawa_max_updates",
        200,
        "",
        0,
        100000,
        doc="augmented: multiplier updates allowed per step",
        when=(("enforcement", ("augmented",)),),
    ),
)


def check(params):
    """Combinations that do not exist, before any run: one ValueError naming the parameters."""
    if params.get("contact_discretization") != "mortar":
        return
    if params.get("enforcement") == "augmented":
        raise ValueError(
            "parameter enforcement = augmented is offered with contact_discretization = node_to_segment "
            "only: use penalty or lagrange with mortar"
        )
    if params.get("tangent", "consistent") != "consistent":  # (contact_integration: the scene's check)
        raise ValueError(
            f"parameter tangent = {params['tangent']} is offered with contact_discretization = "
            "node_to_segment only: mortar takes tangent = consistent"
        )


def outward(body, nodes):
    """The chain of nodes ordered so that n = e3 x t points out of the body (what mortar
    contact needs): reversed if its normals point, on the whole, towards the body's centroid."""
    X = body.X[nodes]
    t = np.diff(X, axis=0)
    n = np.stack([-t[:, 1], t[:, 0]], axis=1)
    out = np.einsum("ij,ij->", n, 0.5 * (X[1:] + X[:-1]) - body.X.mean(axis=0))
    return np.asarray(nodes) if out > 0 else np.asarray(nodes)[::-1]


def interface(
    params,
    slave,
    nodes,
    master,
    *,
    normal,
    friction=None,
    weights=1.0,
    offset=0.0,
    name="contact",
    material="linear",
    tangent="consistent",
    integration="standard",
):
    """The contact the parameters ask for (contact_discretization x enforcement): NodeToSegment,
    AugmentedNodeToSegment or LagrangeNodeToSegment with these weights, or MortarContact or
    LagrangeMortar on the chain ``nodes`` (put in its outward order; its own weights; small
    kinematics for a linear material, finite otherwise)."""
    enforcement = params.get("enforcement", "penalty")
    if params.get("contact_discretization", "node_to_segment") == "node_to_segment":
        cls = {"penalty": NodeToSegment, "augmented": AugmentedNodeToSegment, "lagrange": LagrangeNodeToSegment}
        return cls[enforcement](
            slave,
            nodes,
            master,
            normal=normal,
            friction=friction,
            weights=weights,
            offset=offset,
            name=name,
            tangent=tangent,
            integration=integration,
        )
    assert enforcement != "augmented" and tangent == "consistent" and integration == "standard", (
        "a mortar contact with node-to-segment options (enforcement.check refuses them)"
    )
    cls = LagrangeMortar if enforcement == "lagrange" else MortarContact
    return cls(
        slave,
        outward(slave, nodes),
        master,
        normal=normal,
        friction=friction,
        offset=offset,
        name=name,
        kinematics="small" if material == "linear" else "finite",
    )


# Lagrange's semi-smooth Newton: step halvings of its line search. A steering c_N far above the
# bodies' stiffness makes full steps cycle between two active sets (the patch at c_N = 1e8, 5e4 E/H);
# backtracking on the residual ends the cycle, and near the solution full steps are taken.
LAGRANGE_LINE_SEARCH = 8


def check_roundoff(c_N, traction, length, unit=""):
    """ValueError (one line, before any work) when one round-off of a position (eps * length, the
    size of the coordinates) times the penalty c_N is a traction above ROUNDOFF_SHARE times
    Newton's round-off tolerance (solver.newton.ROUNDOFF_RTOL) of the scene's traction: Newton's
    force test cannot be met, and the answer is round-off (penalty, and Lagrange's steering c_N)."""
    limit = ROUNDOFF_SHARE * RTOL * traction / (np.finfo(float).eps * length)
    if c_N > limit:
        raise ValueError(
            f"parameter c_N = {c_N:g} is out of range for this run: allowed (0, {limit:.2g}] "
            f"(one round-off of a position, eps x {length:g}, times c_N is a traction of "
            f"{c_N * np.finfo(float).eps * length:.2g}{unit}, above Newton's tolerance {RTOL:g} of the "
            f"traction {traction:.3g}{unit})"
        )


def check_steering(params, stiffness, name):
    """ValueError (one line) for Lagrange node-to-segment with a steering c_N above LAGRANGE_STEERING
    times the bodies' stiffness (``name``): there its semi-smooth Newton's active set cycles."""
    limit = LAGRANGE_STEERING * stiffness
    if (
        params["enforcement"] == "lagrange"
        and params["contact_discretization"] == "node_to_segment"
        and params["c_N"] > limit
    ):
        raise ValueError(
            f"parameter c_N = {params['c_N']:g} is out of range for enforcement = lagrange with "
            f"node_to_segment: allowed (0, {limit:.3g}] ({LAGRANGE_STEERING:g} {name}: above it the "
            "semi-smooth Newton's active set cycles; use mortar, or a smaller c_N, which only steers the "
            "iterates)"
        )


# measured on the patch: Lagrange node-to-segment converges (with its line search) up to c_N = 1e10 =
# 5e6 E/H and cycles at 1e11
LAGRANGE_STEERING = 1e6
ROUNDOFF_SHARE = 4.0  # measured: the limit is within a factor 4 above the c_N where Newton stops converging


def wrap(params, stepper, contacts, length):
    """The stepper itself (penalty, lagrange: with a line search) or wrapped in the Uzawa loop (augmented)."""
    if params["enforcement"] == "lagrange" and hasattr(stepper, "newton_options"):
        stepper.newton_options.setdefault("line_search", LAGRANGE_LINE_SEARCH)
    if params["enforcement"] != "augmented":
        return stepper
    return Uzawa(stepper, contacts, length, tol=params["uzawa_tol"], max_updates=params["uzawa_max_updates"])


def report(params, records, penetration, length, length_name):
    """What a scene reports about its enforcement, from its records: uzawa_iterations (outer
    iterations summed over the steps; 0 for penalty), multiplier_updates, newton_per_outer
    (linear solves of each outer iteration, all steps in order; for penalty and lagrange the
    solves of each step) and gap_violation = largest penetration / length, the length the scene states
    (``length_name``), with its value after each outer iteration (gap_violation_per_outer).
    For a penalty step the traction error is about c_N times the gap; with the augmented
    method it is about c_N times the last gap violation, so tractions to a relative accuracy eps
    need uzawa_tol ~ eps p / (c_N length) (p a traction scale)."""
    results = [rec.result for rec in records[1:]]
    if params["enforcement"] != "augmented":
        per_outer, outer, updates, gaps = [int(r.iterations) for r in results], 0, 0, []
    else:
        gaps = [float(g) for r in results for g in r.gap_violations]
        per_outer = [int(i) for r in results for i in r.newton_per_outer]
        outer = sum(r.uzawa_iterations for r in results)
        updates = sum(r.updates for r in results)
    return dict(
        enforcement=params["enforcement"],
        uzawa_iterations=int(outer),
        multiplier_updates=int(updates),
        newton_per_outer=per_outer,
        gap_violation=float(max(penetration, 0.0) / length),
        gap_violation_length=float(length),
        gap_violation_length_is=length_name,
        gap_violation_per_outer=gaps,
    )


def penetration(state):
    """Largest penetration max(-g_N, 0) over the slave nodes of a contact state."""
    return float(np.max(np.maximum(-state.g_N, 0.0), initial=0.0))
