"""Hertz: an elastic cylinder pressed on a rigid plane (plane strain), a verification
scene with a closed form (not one of the paper's examples).

A cylinder of radius R carries a line load P (force per unit thickness). Hertz's
solution for a cylinder on a rigid half-space (Johnson, Contact Mechanics, eqs 4.43, 4.45
with E* = E / (1 - nu^2) for one elastic body):

    a  = sqrt(4 P R (1 - nu^2) / (pi E))          contact half-width
    p0 = 2 P / (pi a)                             peak pressure
    p(x) = p0 sqrt(1 - x^2 / a^2)                 pressure profile

Model: by symmetry the quarter disk x >= 0, y <= 0 (centre at the origin, contact point
B = (0, -R)); u_x = 0 on x = 0; a uniform pressure q = P / (2 R) on the flat cut y = 0
carries the half load P / 2. The mesh is a transfinite (Coons) map of a square onto the
quarter disk, graded with a sinh stretching towards the contact point (bodies/meshes.py, quarter_disk).
Contact: the nodes of the arc near B against RigidLine y = -R, penalty law eq (4) with m = 1:

    penalty = per_length:  c_N is a traction per unit gap (stress/length); nodal forces
                           f_i = w_i c_N g_i with w_i the tributary lengths (the block's units)
    penalty = per_node:    c_N is a nodal stiffness (force/length per unit thickness; the
                           rings' units): f_i = c_N g_i, whatever the mesh

With `per_node` the effective interface stiffness per unit length, c_N / w_i, grows as the
mesh is refined and varies along a graded mesh: the answer depends on the mesh.

The pressure at each contact node is p_i = -f_i / w_i (for both penalty kinds). Reported: p0 (largest
nodal pressure, at x = 0) and a, p0 from a least-squares fit of p^2 = p0^2 (1 - x^2/a^2) (linear in x^2)
over the nodes in contact (mortar: a from the moments of its nodal forces), at their positions in the
REFERENCE configuration: Hertz's theory is a small-strain theory, its a and p(x) live on the undeformed
surface (the deformed positions are shifted outwards by the lateral expansion, about nu a / R of a: -0.8 %
on a if they were used). The errors against the closed form fall under refinement (tests/test_hertz.py).
Two Newton iterations: the overlap a^2 / 2R guesses the active set.

An elastic foundation (``foundation = elastic``) instead of the rigid plane: the quarter
block [0, R] x [-2R, -R] (u_x = 0 on x = 0, u_y = 0 below) of modulus E_foundation, its
elements ``foundation_ratio`` times the cylinder's contact elements (non-matching meshes),
1/E* = (1 - nu^2)/E + (1 - nu^2)/E_foundation (Johnson eq 4.43, two half-planes; R = 30 a
changes it far less than the mesh does). The foundation's top is the master (BodySurface);
node-to-segment's slave on the symmetry line, exactly at the master's end, is left out (its
tributary length goes to its neighbour). On these meshes node-to-segment's pressures
oscillate about Hertz's profile from node to node, mortar's do not (``oscillation``,
``max_jump``).
"""

import numpy as np

from .. import lazy
from ..bodies.meshes import graded_block_mesh, grading_for, quarter_disk
from ..contact import BodySurface, RigidLine, tributary_lengths
from ..laws import PowerLaw
from ..problem import enforcement
from ..problem.accuracy import hertz_half_width
from ..problem.scene import PENALTIES, PENALTY_DOC, Model, Param, Quantity, Scene, Stage
from ..problem.uncertainty import mesh, penalty
from ..solver import Dirichlet, History, Static, Steps, System

continuum = lazy.module("contactfem.bodies.continuum")  # loads scikit-fem: not when the scenes are listed
body_loads = lazy.module("contactfem.bodies.loads")  # loads scikit-fem


def hertz_exact(P, R, E, nu, E2=np.inf, nu2=0.0):
    """Hertz line contact of an elastic cylinder on a rigid plane (or, with E2, nu2, on an
    elastic half-plane: 1/E* = (1 - nu^2)/E + (1 - nu2^2)/E2): (a, p0)."""
    E_star = 1.0 / ((1.0 - nu**2) / E + (1.0 - nu2**2) / E2)
    a = np.sqrt(4.0 * P * R / (np.pi * E_star))
    return a, 2.0 * P / (np.pi * a)


def foundation(params, h, a):
    """The elastic foundation (module docstring): its body, the master surface on its top
    and its supports."""
    R = params["R"]
    mesh = graded_block_mesh(R, params["foundation_ratio"] * h, 2.5 * a, a)
    body = continuum.Continuum(
        mesh,
        params["E_foundation"],
        params["nu"],
        0.0,
        kind="plane_strain",
        material=params["material"],
        name="foundation",
    )
    top = np.flatnonzero(np.abs(body.X[:, 1] + R) < 1e-9 * R)
    top = top[np.argsort(body.X[top, 0])]  # left to right: n = e3 x t = +y, out of it
    fixed = [
        Dirichlet(body, body.xdofs[np.abs(body.X[:, 0]) < 1e-9 * R, 0], 0.0),
        Dirichlet(body, body.xdofs[np.abs(body.X[:, 1] + 2 * R) < 1e-9 * R, 1], 0.0),
    ]
    return body, BodySurface(body, top), fixed


def fit_hertz(x, p):
    """Least squares of p^2 = p0^2 - (p0/a)^2 x^2 over the nodes with p > 0 (two at least): (a, p0)."""
    on = p > 0.0
    if np.count_nonzero(on) < 2:
        raise ValueError("fewer than two contact nodes carry pressure: refine the mesh (n_el)")
    A = np.column_stack([np.ones(np.count_nonzero(on)), x[on] ** 2])
    c0, c1 = np.linalg.lstsq(A, p[on] ** 2, rcond=None)[0]
    if not (c0 > 0 and c1 < 0):
        raise ValueError("the contact pressure is not Hertz-like (fit of p^2 against x^2 failed)")
    return float(np.sqrt(-c0 / c1)), float(np.sqrt(c0))


def build(params, *, normal=None, friction=None, system_options=None):
    """Body, contact, load, supports and load stepping of the quarter cylinder; returns a dict.
    ``normal`` / ``friction``: law objects instead of the parameters' (frictionless by default)."""
    R, E, nu, P = params["R"], params["E"], params["nu"], params["P"]
    elastic = params.get("foundation", "rigid") == "elastic"
    a_ex, p0_ex = hertz_exact(P, R, E, nu, params["E_foundation"] if elastic else np.inf, nu)
    n = params["n_el"]
    # grade so that about a third of the elements along the arc lie within 1.5 a of B
    xi_zone = min(1.0, 1.5 * a_ex / (R * np.pi / 4))
    k = grading_for(xi_zone, 1.0 / 3.0) * params["grading"]
    mesh = quarter_disk(R, n, k)
    body = continuum.Continuum(mesh, E, nu, 0.0, kind="plane_strain", material=params["material"], name="cylinder")

    arc = body.X[:, 0] ** 2 + body.X[:, 1] ** 2 > (R * (1 - 1e-9)) ** 2
    near = arc & (body.X[:, 0] < min(0.7 * R, 4.0 * a_ex))
    nodes = np.flatnonzero(near)
    nodes = nodes[np.argsort(body.X[nodes, 0])]  # chain from B outwards
    w = tributary_lengths(body.X[nodes])
    bodies, more_fixed, master = [body], [], RigidLine((0.0, -R), (0.0, 1.0))
    if elastic:
        found, master, more_fixed = foundation(params, body.X[nodes[1], 0], a_ex)
        bodies.append(found)
        if params.get("contact_discretization", "node_to_segment") == "node_to_segment":
            w[1] += w[0]  # the slave on the symmetry line is left out
            nodes, w = nodes[1:], w[1:]
    weights = w if params["penalty"] == "per_length" else 1.0
    contact = enforcement.interface(
        params,
        body,
        nodes,
        master,
        normal=normal or PowerLaw(params["c_N"], 1.0),
        friction=friction,
        weights=weights,
        name="plane",
        material=params["material"],
    )
    if contact.nodes[0] != nodes[0]:  # mortar's chain runs the other way
        nodes, w = nodes[::-1], w[::-1]
    sym = np.flatnonzero(np.abs(body.X[:, 0]) < 1e-9 * R)
    fixed = [Dirichlet(body, body.xdofs[sym, 0], 0.0)] + more_fixed
    q = P / (2.0 * R)
    load = body_loads.Pressure(body, "top", lambda t: q * min(t, 1.0))
    system = System(bodies, [contact], [load], fixed, **(system_options or {}))
    # initial guess: the rigid translation that overlaps the plane over |x| < a (a^2 / 2R),
    # so that the first tangent is not singular (the plane is the only vertical support)
    u0 = np.zeros(system.ndof)
    u0[body.xdofs[:, 1]] = -(a_ex**2) / (2.0 * R)
    stepper = enforcement.wrap(
        params,
        Static(system, atol=1e-12 * P, maxit=40),
        [contact],  # (atol: a floor)
        length=a_ex,
    )  # gap_violation: penetration / a
    n = params["n_steps"]
    stage = Stage(stepper, Steps(1.0 / n, n_steps=n, max_cuts=6), u0, name="hertz")
    return Model(
        systems=(system,),
        stage=stage,
        sizes=dict(element=float(np.min(w[w > 0])), body=R),
        parts=dict(body=body, contact=contact, nodes=nodes, w=w, a_exact=a_ex, p0_exact=p0_ex, grading_k=k),
    )


def oscillations(x, p, p_exact, a, p0):
    """How the nodal pressures jump from node to node over the inner contact zone x < 0.8 a
    (where Hertz's profile itself changes by less than 1.3 p0 h / a between nodes h apart):
    ``max_jump`` = max |p_i+1 - p_i| / p0, and ``oscillation`` = the same of p - p_Hertz,
    the node-to-node oscillation about the closed form."""
    o = np.argsort(x)
    x, p, dev = x[o], p[o], (p - p_exact)[o]
    inner = x[1:] < 0.8 * a
    jump = np.abs(np.diff(p))[inner]
    return dict(
        max_jump=float(np.max(jump, initial=0.0) / p0),
        oscillation=float(np.max(np.abs(np.diff(dev))[inner], initial=0.0) / p0),
    )


def check(params):
    """Combinations that do not exist (one ValueError, before any run)."""
    enforcement.check(params)
    E_f = params["E_foundation"] if params.get("foundation", "rigid") == "elastic" else np.inf
    a = hertz_exact(params["P"], params["R"], params["E"], params["nu"], E_f, params["nu"])[0]
    if not a < 0.5 * params["R"]:  # the graded mesh puts 1.5 a on the quarter arc; Hertz's theory a << R
        raise ValueError(
            f"parameter P = {params['P']:g} gives Hertz's a = {a:.4g}, a/R = {a / params['R']:.2g}: "
            "Hertz's small-strain theory needs a/R < 0.5 (a << R): lower P or raise E"
        )
    per_length = params["c_N"] if params["penalty"] == "per_length" else 0.0  # (per_node: c_N / w is above it)
    enforcement.check_roundoff(per_length, 2.0 * params["P"] / (np.pi * a), params["R"], " MPa")  # against p0
    if params["contact_discretization"] == "mortar" and params["penalty"] != "per_length":
        raise ValueError(
            "parameter penalty = per_node does not apply to contact_discretization = mortar (its "
            "tractions are per unit length): use penalty = per_length"
        )


def measure(m, params, records):
    body, w = m.parts["body"], m.parts["w"]
    P = params["P"]
    a_ex = m.parts["a_exact"]
    hist = History.of(records)
    state = records[-1].contacts[0]
    rep = state.report()
    # Hertz's a and p(x) are small-strain quantities: positions in the reference configuration
    # (the deformed x differs by the lateral expansion u_x, about nu a / R of a)
    x = rep["X"][:, 0]
    # pressure at the nodes: the traction per length, or the nodal force over the tributary length
    p = -rep["t_N"] if params["penalty"] == "per_length" else -rep["f_N"] / w
    a_fit, p0_fit = fit_hertz(x, p)
    p0_max = float(p.max())
    a_ex, p0_ex = m.parts["a_exact"], m.parts["p0_exact"]
    in_contact = p > 0
    h_c = float(np.median(np.diff(np.sort(x))[: max(2, np.count_nonzero(in_contact))]))
    c_eff = params["c_N"] if params["penalty"] == "per_length" else params["c_N"] / w[in_contact]
    profile_exact = p0_ex * np.sqrt(np.clip(1 - (x / a_ex) ** 2, 0, None))
    a_mom = hertz_half_width(x, -rep["f_N"])  # mortar's nodal tractions are smeared where the zone ends: its a
    a = a_mom if params["contact_discretization"] == "mortar" else a_fit
    return dict(
        **oscillations(x, p, profile_exact, a_ex, p0_ex),
        a=a,
        p0=p0_max,
        p0_fit=p0_fit,
        a_exact=a_ex,
        p0_exact=m.parts["p0_exact"],
        a_fit=a_fit,
        a_moments=a_mom,
        error_a=(a - a_ex) / a_ex,
        error_a_fit=(a_fit - a_ex) / a_ex,
        error_a_moments=(a_mom - a_ex) / a_ex,
        error_p0=(p0_max - p0_ex) / p0_ex,
        error_p0_fit=(p0_fit - p0_ex) / p0_ex,
        contact_force=float(-rep["f_N"].sum()),
        half_load=P / 2.0,
        n_quads=int(body.mesh.t.shape[1]),
        n_dofs=int(body.ndof),
        n_contact_nodes=int(np.count_nonzero(in_contact)),
        h_contact=h_c,
        penetration_max=float(-rep["g_N"].min()),
        c_N_per_length_min=float(np.min(c_eff)),
        c_N_per_length_max=float(np.max(c_eff)),
        profile_x=x,
        profile_p=p,
        profile_p_exact=profile_exact,
        newton_iterations_total=int(np.sum(hist.iterations)),
        newton_residuals=[list(r) for r in hist.residuals[1:]],
        **enforcement.report(params, records, enforcement.penetration(state), a_ex, "the exact contact half-width a"),
    )


SCENE = Scene(
    name="hertz",
    title="Hertz: elastic cylinder on a rigid plane (verification, closed form)",
    params=(
        Param("R", 10.0, "mm", 0.0, None, low_open=True, doc="cylinder radius"),
        Param("E", 2.0e5, "MPa", 0.0, None, low_open=True, doc="Young's modulus"),
        Param("nu", 0.3, "", -1.0, 0.5, low_open=True, high_open=True, doc="Poisson's ratio (plane strain)"),
        Param(
            "P",
            2000.0,
            "N/mm",
            0.0,
            None,
            low_open=True,
            doc="line load per unit thickness (default: a/R = 0.034, small strain)",
        ),
        Param(
            "material",
            "linear",
            "",
            choices=("linear", "svk", "neohooke"),
            doc="linear (small strain, Hertz's setting) or finite strain",
        ),
        Param("n_el", 64, "", 4, 2000, doc="quads per side of the quarter disk (n_el^2 quads; 4: two loaded nodes)"),
        Param(
            "grading",
            1.0,
            "",
            0.0,
            3.0,
            doc="multiplies the sinh stretching that puts a third of the elements within 1.5 a (0: uniform)",
        ),
        Param(
            "penalty",
            "per_length",
            "",
            choices=PENALTIES,
            doc=PENALTY_DOC + " (c_N in MPa/mm per length, N/mm per node)",
        ),
        Param(
            "c_N",
            1.0e9,
            "MPa/mm or N/mm",
            0.0,
            None,
            low_open=True,
            doc="penalty stiffness (eq 4, m = 1); chosen: stiff enough that the penalty error is < 0.1 %",
        ),
        Param("n_steps", 1, "", 1, 1000, doc="load steps (the whole load in one step by default)"),
        Param(
            "foundation",
            "rigid",
            "",
            choices=("rigid", "elastic"),
            doc="rigid plane (Hertz's setting) or an elastic block of E_foundation with a non-matching mesh",
        ),
        Param(
            "E_foundation",
            2.0e5,
            "MPa",
            0.0,
            None,
            low_open=True,
            doc="Young's modulus of the elastic foundation",
            when=(("foundation", ("elastic",)),),
        ),
        Param(
            "foundation_ratio",
            1.37,
            "",
            0.1,
            10.0,
            doc="foundation element size / the cylinder's contact element size (non-matching meshes: not 1)",
            when=(("foundation", ("elastic",)),),
        ),
        *enforcement.ENFORCEMENT_PARAMS,
    ),
    build=build,
    measure=measure,
    check=check,
    presets={"fast": {"n_el": 32}, "paper": {"n_el": 64}},
    reports=("a", "p0", "a_exact", "p0_exact", "error_a", "error_p0"),
    # the elastic foundation adds about as many elements as the cylinder (graded: 1.5 n_el^2 at most)
    size=lambda p: dict(
        elements=p["n_el"] ** 2 * (2.5 if p["foundation"] == "elastic" else 1),
        unknowns=2 * (p["n_el"] + 1) ** 2 * (2.5 if p["foundation"] == "elastic" else 1),
        steps=p["n_steps"],
    ),
    laws=("normal",),
    law_params={"normal": ("c_N",)},
    law_range=lambda params: dict(g=0.1 * params["R"]),  # the normal law probed to a tenth of R deep
    # a and p0 come from the contact pressures, which converge as the element size (a stress), not its square
    quantities=(
        Quantity("a", "mm", ("mesh", "penalty"), exact="a_exact", orders={"mesh": 1.0}),
        Quantity("p0", "MPa", ("mesh", "penalty"), exact="p0_exact", orders={"mesh": 1.0}),
    ),
    discretisations=(mesh("n_el", low=4), penalty("c_N")),
)
