"""Sloping impact of a ring on a rigid plane (paper Sec. 5.3, Figs 10, 11, Table 2).

A ring (mean radius R = 10, square section 1 x 1, E = 100, nu = 0, rho = 0.01, 16 linear
finite-deformation beam elements) flies at 45 degrees onto a rigid plane with
v = (2, -2) and rebounds. Newmark delta = 0.7, beta = 0.4, dt = 0.1, 200 steps.
Interface: eq (4) with m = 1, c_N = 50; friction eq (10) with c_T = 30, n = 0.8,
alpha = 0.2, beta = 0.3. c_N and c_T are NODAL stiffnesses (force per unit gap of one
node, weights = 1), as the ring data are given.

Variants (``variant``):
    frictionless   no tangential traction: v_x is kept, the ring does not spin
    frictional     parabolic slip surface, eq (10): the ring loses v_x and spins
    viscoplastic   frictional + Perzyna viscoplastic resultants (N0 = 1, Q0 = 0.5,
                   M0 = 0.25, paper) with the relaxation time eta (scan gives none, chosen)

Choices the paper does not state:
    * no gravity (the paper gives none; the centre then flies straight after rebound, so
      the rebound velocity is the centre-of-mass velocity at the end of the run);
    * the ring starts with its outer surface `gap0` = 0.05 above the plane, a node at the
      bottom (node angles 2 pi k / n_el, node 12 of 16 at 270 degrees);
    * contact at the outer surface: the centreline nodes are the slaves with offset h/2
      (NodeToSegment offset); the force acts at the centreline node (no moment from the
      offset: for h/R = 0.1 a small difference in the friction torque).

Rebound measures (Table 2): the centre-of-mass velocity (v_x, v_y) once the ring has
left the plane and the angle of reflection from the normal, atan(|v_x| / |v_y|);
the spin after rebound is the angular velocity about the centre of mass
(RingModel.angular_velocity, L / I_c).
"""

import numpy as np

from ..bodies.ring import make_ring
from ..contact import NodeToSegment, RigidLine, tributary_lengths
from ..contact.tangents import TANGENTS
from ..laws import ParabolicSlip, PowerLaw
from ..solver import History, System
from ..problem import time_integration
from ..problem.scene import PENALTIES, PENALTY_DOC, Model, Param, Quantity, Scene, Stage
from ..problem.uncertainty import mesh, time_step
from .rings import (
    MASS_MATRIX_PARAM,
    RING_FLOOR,
    RING_PARAMS,
    penalty_pressure,
    ring_history,
    ring_size,
    snapshot_indices,
)

VARIANTS = ("frictionless", "frictional", "viscoplastic")

# Paper, Table 2: rebound velocity components and angle of reflection (from the normal)
PAPER_TABLE2 = {
    "frictionless": dict(vx=2.0, vy=1.7, angle_deg=50.0),
    "frictional": dict(vx=1.2, vy=1.7, angle_deg=35.0),
}


def rebound_angle(vx, vy):
    """Angle of reflection from the plane's normal (Table 2): atan(|v_x| / |v_y|) in degrees."""
    return float(np.degrees(np.arctan2(abs(vx), abs(vy))))


def check(params):
    if params["variant"] == "viscoplastic" and params["kind"] != "beam":
        raise ValueError("parameter variant = 'viscoplastic' needs kind = 'beam' (the continuum ring is elastic)")


def integration_points(params):
    """Points per beam element: the parameter, or for 'auto' 2 (elastic ring, fitted to Table 2), 1 (viscoplastic)."""
    if params["integration"] != "auto":
        return int(params["integration"])
    return 1 if params["variant"] == "viscoplastic" else 2


def newton_atol(params, ndof):
    """Newton's absolute tolerance: 1e-10, or ten times the round-off of the ring's residual where that is
    larger, eps (E A / L0) R sqrt(ndof) (n_el = 700 stalls at 1.1e-10, as estimated; to n_el ~ 140: 1e-10)."""
    L0 = 2.0 * np.pi * params["R"] / params["n_el"]
    EA = params["E"] * params["thickness"] * params["width"]
    return max(1e-10, 10.0 * np.finfo(float).eps * EA / L0 * params["R"] * np.sqrt(ndof))


def build(params, *, normal=None, friction=None, system_options=None):
    """The ring (make_ring), the plane y = 0, the contact and the march; returns a dict. ``normal`` /
    ``friction``: law objects instead of the parameters' (a friction law given makes any variant frictional)."""
    h = params["thickness"]
    plastic = None
    if params["variant"] == "viscoplastic":
        assert params["kind"] == "beam", "variant = viscoplastic with a continuum ring (the scene's check)"
        plastic = dict(N0=params["N0"], Q0=params["Q0"], M0=params["M0"], eta=params["eta"])
    R = params["R"]
    center = (0.0, R + h / 2 + params["gap0"])
    beam = (
        dict(integration=integration_points(params), rotary_inertia=params["rotary_inertia"])
        if params["kind"] == "beam"
        else {}
    )
    ring = make_ring(
        kind=params["kind"],
        R=R,
        thickness=h,
        width=params["width"],
        n_el=params["n_el"],
        E=params["E"],
        nu=params["nu"],
        rho=params["rho"],
        center=center,
        plastic=plastic,
        name="ring",
        mass_matrix=params["mass_matrix"],
        **beam,
    )
    if friction is None and params["variant"] != "frictionless":
        friction = ParabolicSlip(params["c_T"], params["alpha"], params["beta"], params["n"])
    plane = RigidLine((0.0, 0.0), (0.0, 1.0))
    if params["penalty"] == "per_node":
        weights = 1.0
    else:  # c_N, c_T per unit length of the outer surface: nodal weights = tributary lengths
        w = tributary_lengths(ring.outline(np.zeros(ring.body.ndof)))  # closed polyline: node 0 twice
        weights = np.concatenate([[w[0] + w[-1]], w[1:-1]])
    offset = ring.offset if params["contact_at"] == "outer" else 0.0
    contact = NodeToSegment(
        ring.body,
        ring.contact_nodes,
        plane,
        normal=normal or PowerLaw(params["c_N"], params["m"]),
        friction=friction,
        weights=weights,
        offset=offset,
        name="plane",
        tangent=params["tangent"],
        integration=time_integration.contact_integration(params),
    )
    system = System([ring.body], [contact], **(system_options or {}))
    stepper = time_integration.make_stepper(params, system, atol=newton_atol(params, ring.body.ndof), maxit=30)
    v0 = (params["vx0"], params["vy0"])  # accuracy: the rebound velocities' errors, relative to |v0|
    stepper, schedule = time_integration.plan(
        params, stepper, dt=params["dt"], n_steps=params["n_steps"], speed=float(np.hypot(*v0)), max_cuts=6
    )
    stage = Stage(stepper, schedule, np.zeros(ring.body.ndof), ring.initial_velocity(v0), name="sloping_impact")
    return Model(
        systems=(system,),
        stage=stage,
        sizes=dict(
            element=2.0 * np.pi * params["R"] / params["n_el"],
            body=2.0 * params["R"],  # (elements' length)
            radius=params["R"],
        ),
        rebound=True,  # the accuracy's `separated`: the rebound is read after the impact
        parts=dict(ring=ring, contact=contact, plane=plane),
    )


def measure(model, params, records):
    ring = model.parts["ring"]
    hist = History.of(records)
    ep = records[-1].state.bodies[0]  # the ring's plastic strains (the System's one body)
    rec = ring_history(ring, records)
    shots = snapshot_indices(rec["t"], every=params["outline_every"])
    t, x_c, v_c, omega = rec["t"], rec["x_c"], rec["v_c"], rec["omega"][shots]
    n_contact = rec["n_contact"]
    touched = np.flatnonzero(n_contact > 0)
    rebounded = bool(touched.size and touched[-1] < len(t) - 1)
    t_first = float(t[touched[0]]) if touched.size else None
    t_separation = float(t[touched[-1] + 1]) if rebounded else None
    vx, vy = v_c[-1]

    mech = hist.kinetic + hist.strain + hist.contact  # total mechanical energy
    E0 = mech[0]
    window = slice(0, (touched[-1] + 2) if rebounded else len(t))  # over the impact
    out = dict(
        variant=params["variant"],
        rebound_vx=float(vx),
        rebound_vy=float(vy),
        rebound_angle_deg=rebound_angle(vx, vy),
        rebound_spin=ring.angular_velocity(hist.u, hist.v),
        rebounded=rebounded,
        t_first_contact=t_first,
        t_separation=t_separation,
        t=t,
        x_c=x_c[:, 0],
        y_c=x_c[:, 1],
        vx_c=v_c[:, 0],
        vy_c=v_c[:, 1],
        n_contact_nodes=n_contact,
        energy_kinetic=hist.kinetic,
        energy_strain=hist.strain,
        energy_contact=hist.contact,
        energy_dissipation=hist.dissipation,
        energy_total=mech,
        energy_total_max_rel_change_impact=float(np.max(np.abs(mech[window] - E0)) / E0),
        energy_total_max_rel_increase_per_step=float(np.max(np.diff(mech)) / E0),
        energy_total_final_rel=float(mech[-1] / E0),
        energy_error=time_integration.energy_error(hist)[0],
        energy_error_max=time_integration.energy_error(hist)[1],
        energy_after_rebound_rel=float(mech[-1] / E0 - 1.0) if rebounded else None,
        outlines=[ring.outline(records[k].u) for k in shots],
        outline_t=t[shots],
        outline_spin=omega,
        obstacles=[np.array([[x_c[:, 0].min() - 1.5 * params["R"], 0.0], [x_c[:, 0].max() + 1.5 * params["R"], 0.0]])],
        mass=ring.total_mass(),
        # committed plastic strains of the beam (eps_p, gam_p, kap_p): the permanent deformation
        plastic_strain_max=np.max(np.abs(np.zeros((1, 3)) if ep is None else ep), axis=0),
        newton_iterations_total=int(np.sum(hist.iterations)),
        integration_points=integration_points(params),
        # lost in the scan; fitted to Table 2 by `contactfem reconstruct sloping_impact`
        # (the viscoplastic ring's midpoint rule is the paper's separate element, not fitted)
        fitted={"integration": integration_points(params)}
        if params["integration"] == "auto" and params["variant"] != "viscoplastic"
        else {},
        step_cuts_total=int(np.sum(hist.cuts)),
    )
    if params["variant"] in PAPER_TABLE2:
        p = PAPER_TABLE2[params["variant"]]
        out.update(paper_vx=p["vx"], paper_vy=p["vy"], paper_angle_deg=p["angle_deg"])
    return out


def settles(params, results):
    """The ladder's levels end at four times the run's separation (Scene.settles): without gravity the centre
    of mass keeps its velocity in flight (the internal forces have no resultant), so the rebound is read then
    as at the run's end. A finer ring can touch again after it flew for about as long as its first contact
    lasted (measured: 64 elements, trapezoidal rule, leave at 2.4, touch again from 3 to 5.6): four times the
    separation leaves that room. A level still in contact at its end is not taken."""
    t_sep = results.get("t_separation")
    if t_sep is None or not results.get("rebounded"):
        return {}
    n = int(np.ceil(4.0 * t_sep / params["dt"]))
    return {"n_steps": n} if n < params["n_steps"] else {}


def law_range(params):
    """The range the ring's laws meet (Scene.law_range): pressures up to the one at which a
    single node's penalty spring would hold all the kinetic energy (per node, or per the
    node's length of the outer surface for penalty = per_length); slips up to the distance
    the ring can travel, slip rates up to three times its speed (sliding plus spin)."""
    R, h = params["R"], params["thickness"]
    M = params["rho"] * 2.0 * np.pi * R * h * params["width"]
    speed = float(np.hypot(params["vx0"], params["vy0"]))
    w = 1.0 if params["penalty"] == "per_node" else 2.0 * np.pi * (R + h / 2) / params["n_el"]
    return dict(
        p=penalty_pressure(0.5 * M * speed**2, params["c_N"], params["m"], w),
        q=speed * params["n_steps"] * params["dt"],
        v=3.0 * speed,
        dt=params["dt"],
        g=h,
    )


SCENE = Scene(
    name="sloping_impact",
    title="Sloping impact of a ring on a rigid plane at 45 degrees (Sec. 5.3, Figs 10-11, Table 2)",
    params=(
        Param(
            "variant",
            "frictionless",
            choices=VARIANTS,
            doc="frictionless (Fig 10), frictional eq (10) (Fig 11a), viscoplastic + frictional (Fig 11b)",
        ),
        *RING_PARAMS,
        Param("n_el", 16, "", 3, 2000, doc="elements around the ring (paper: 16 linear beam elements)"),
        Param("vx0", 2.0, "L/T", doc="initial velocity along the plane (paper)"),
        Param("vy0", -2.0, "L/T", None, 0.0, high_open=True, doc="initial velocity normal to the plane, < 0 (paper)"),
        Param(
            "gap0",
            0.05,
            "L",
            0.0,
            None,
            doc="initial clearance of the outer surface above the plane (chosen: the paper starts 'just above')",
        ),
        Param("c_N", 50.0, "F/L", 0.0, None, low_open=True, doc="normal penalty, eq (4) (paper: 50)"),
        Param(
            "penalty",
            "per_node",
            choices=PENALTIES,
            doc=PENALTY_DOC + " (the scan gives none; per_node chosen: the ring's data are nodal)",
        ),
        Param(
            "contact_at",
            "outer",
            choices=("outer", "axis"),
            doc="where the contact acts (the scan does not say): outer = outer fibre (gap from the "
            "centreline node minus h/2), axis = the beam axis (the centreline nodes themselves)",
        ),
        Param(
            "integration",
            "auto",
            "",
            choices=("auto", "1", "2"),
            doc="beam: points per element, 1 = midpoint (free of shear locking) or 2 = two-point Gauss (locks "
            "in shear: a stiffer ring). The scan only says 'linear beam elements'. auto: 2 for the elastic "
            "ring, FITTED to Table 2 (contactfem reconstruct sloping_impact: every two-point reading comes "
            "closer to its velocities than every one-point reading; none reproduces them within 10 %); "
            "1 for the viscoplastic ring (the paper's separate viscoplastic element)",
        ),
        Param(
            "rotary_inertia",
            True,
            "",
            doc="beam: rho I on the rotation dofs of the lumped mass (the scan does not say)",
        ),
        Param("m", 1.0, "", 1.0, None, doc="exponent of the normal law eq (4) (paper)"),
        Param(
            "c_T",
            30.0,
            "F/L",
            0.0,
            None,
            low_open=True,
            doc="tangential stick stiffness, nodal, eq (5) (paper)",
            when=(("variant", ("frictional", "viscoplastic")),),
        ),
        Param(
            "n",
            0.8,
            "",
            0.0,
            1.0,
            low_open=True,
            doc="exponent of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional", "viscoplastic")),),
        ),
        Param(
            "alpha",
            0.2,
            "F^(1-n)",
            0.0,
            None,
            doc="alpha of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional", "viscoplastic")),),
        ),
        Param(
            "beta",
            0.3,
            "",
            0.0,
            None,
            doc="beta of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional", "viscoplastic")),),
        ),
        Param(
            "N0",
            1.0,
            "F",
            0.0,
            None,
            low_open=True,
            doc="plastic axial force (paper, viscoplastic variant)",
            when=(("variant", ("viscoplastic",)),),
        ),
        Param(
            "Q0",
            0.5,
            "F",
            0.0,
            None,
            low_open=True,
            doc="plastic shear force (paper, viscoplastic variant)",
            when=(("variant", ("viscoplastic",)),),
        ),
        Param(
            "M0",
            0.25,
            "F L",
            0.0,
            None,
            low_open=True,
            doc="plastic moment (paper, viscoplastic variant)",
            when=(("variant", ("viscoplastic",)),),
        ),
        Param(
            "eta",
            0.1,
            "T",
            0.0,
            None,
            low_open=True,
            when=(("variant", ("viscoplastic",)),),
            doc="Perzyna relaxation time (chosen: scan lost it; eta = dt = 0.1 makes the overstress relax "
            "within about one step, nearly rate-independent plasticity with a regular tangent)",
        ),
        Param(
            "tangent",
            "consistent",
            choices=TANGENTS,
            doc="contact tangent given to Newton: consistent (eqs 39, 49-50), symmetric ((K+K^T)/2), frozen "
            "(without the c_N^s C coupling of eq 49); the residual is always eq 28",
        ),
        Param("dt", 0.1, "T", 0.0, None, low_open=True, doc="time step (paper)"),
        Param("n_steps", 200, "", 1, 100000, doc="number of steps (paper: 200)"),
        *time_integration.newmark_params(0.7, 0.4, "paper"),
        time_integration.CONTACT_INTEGRATION_PARAM,
        time_integration.ACCURACY_PARAM,
        MASS_MATRIX_PARAM,
        Param("outline_every", 20, "", 1, 100000, doc="store the ring outline every this many steps (figures)"),
    ),
    build=build,
    measure=measure,
    # 16 elements, 200 steps: the paper's run takes ~2 s. midpoint: the one-point beam of the
    # earlier reading (every elastic ring integrated with the midpoint rule)
    presets={"fast": {}, "paper": {}, "midpoint": {"integration": "1"}},
    notes=(
        "Read from the scan: R, A, E, nu, rho, 16 beam elements, v = (2, -2), Newmark 0.7 / 0.4, lumped mass, "
        "dt = 0.1, 200 steps, m, c_N = 50, c_T = 30, n, alpha, beta, N0, Q0, M0.\n"
        "Chosen (the scan does not say): no gravity, eta; and gap0, penalty per node, contact at the outer "
        "fibre, rotary inertia, which move Table 2's velocities by a few hundredths (contactfem reconstruct "
        "sloping_impact).\n"
        "FITTED to Table 2: integration = 2 points for the elastic ring (closer to Table 2 than 1 point). Of "
        "Table 2's four independent numbers, the frictionless v_x = 2 holds on any frictionless plane; no "
        "reading with the paper's lumped mass and Newmark 0.7 / 0.4 brings the other three (frictionless v_y, "
        "frictional v_x and v_y) within 10 %; the energy-consistent stepper (contact_integration, against the "
        "paper's text) moves v_y most: see the README."
    ),
    reports=("rebound_vx", "rebound_vy", "rebound_angle_deg", "rebound_spin", "newton_iterations_total"),
    check=check,
    size=lambda p: dict(ring_size(p), steps=p["n_steps"]),
    outlines=True,
    laws=("normal", "friction"),
    law_params={"friction": ("c_T", "n", "alpha", "beta"), "normal": ("c_N", "m")},
    law_choice=("variant", ("frictionless", "frictional")),
    law_range=law_range,
    # the rebound velocity, against a tenth of the impact speed where it is smaller (near zero: a rebound that
    # friction stops); c_N is the paper's interface law, not a regularisation
    quantities=tuple(
        Quantity(name, "L/T", ("step", "mesh"), scale=lambda p: 0.1 * float(np.hypot(p["vx0"], p["vy0"])))
        for name in ("rebound_vx", "rebound_vy")
    ),
    discretisations=(time_step("dt", count="n_steps"), mesh("n_el", low=RING_FLOOR)),
    settles=settles,
)
