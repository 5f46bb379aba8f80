"""Fall of an elastic ring into a rigid funnel (paper Sec. 5.4, Figs 12, 13).

The ring of Sec. 5.3 (R = 10, square section 1 x 1, E = 100, nu = 0, rho = 0.01) falls
with v0 = 4 into a rigid funnel. By symmetry only half of the ring is modelled: the arc
x <= 0 with 30 linear beam elements (make_ring(half=True)); on the symmetry plane x = 0
the two end nodes keep u_x = 0 and theta = 0. Newmark delta = 0.7, beta = 0.4 (as in
Sec. 5.3), dt = 0.1. Interface: eq (4) with m = 1, c_N = 10; friction eq (10) with
c_T = 5, n = 0.75, alpha = 0.3, beta = 0.1 (nodal stiffnesses, weights = 1).

Paper: frictionless -- large elastic deformation and rebound; frictional -- the ring
sticks in the funnel, with a smaller deformation.

Choices the paper does not state:
    * the funnel: a V with its vertex at the origin on the symmetry axis; by symmetry one
      straight wall (RigidPolyline from the top down to the vertex, so that its normal
      e3 x t points into the funnel). Its angle from the vertical, phi = 20 degrees, is
      chosen (scan lost the figure's angle): a rigid ring wedged between two walls with no
      gravity stays put only if the friction carries the walls' outward push,
      |t_T| / |t_N| = tan(phi) <= mu_eff = alpha |t_N|^(n - 1) + beta (eq 10). For the
      light contact pressures here mu_eff is about 0.5-0.7: phi = 20 deg (tan = 0.36)
      sticks with a clear margin, phi = 25 deg is marginal (the centre creeps up at about
      1 % of v0), phi = 30 deg leaves at about 0.2 v0.
    * no gravity (the paper gives none for Secs 5.3-5.4), so "falls" is the initial
      velocity only; the ring starts with its outer surface `gap0` = 0.2 above the wall.

`stuck` (the scene's verdict on Fig 13 vs Fig 12): over the last quarter of the run the
ring is in contact at every step AND its centre moves on average by less than
2 % of v0, |y_c(end) - y_c(start of window)| / T_window < 0.02 v0 (the ring keeps
vibrating in place, so the mean, not the instantaneous, velocity is tested).
"""

import numpy as np

from ..bodies.ring import make_ring
from ..contact import NodeToSegment, RigidPolyline
from ..laws import ParabolicSlip, PowerLaw
from ..solver import Dirichlet, History, Steps, System
from ..problem import time_integration
from ..problem.scene import Model, Param, Quantity, Scene, Stage
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

VARIANTS = ("frictionless", "frictional")


def funnel_wall(phi_deg, length):
    """The left wall of the V funnel, vertex at the origin, at phi from the vertical:
    points from the top (-L sin phi, L cos phi) down to (0, 0), so that n = e3 x t
    (left of the direction of travel) points into the funnel (towards +x, up)."""
    phi = np.radians(phi_deg)
    return np.array([[-length * np.sin(phi), length * np.cos(phi)], [0.0, 0.0]])


def build(params, *, normal=None, friction=None, system_options=None):
    """Half ring, funnel wall, contact, symmetry conditions and the march; returns a dict.
    ``normal`` / ``friction``: law objects instead of the ones the parameters build
    (a friction law given makes the run frictional)."""
    R, h = params["R"], params["thickness"]
    phi = np.radians(params["phi_deg"])
    yc0 = (R + h / 2) / np.sin(phi) + params["gap0"]  # wall distance of the centre = R + h/2 + gap
    ring = make_ring(
        kind=params["kind"],
        R=R,
        thickness=h,
        width=params["width"],
        n_el=params["n_el"],
        E=params["E"],
        nu=params["nu"],
        rho=params["rho"],
        center=(0.0, yc0),
        half=True,
        name="half ring",
        mass_matrix=params["mass_matrix"],
    )
    wall = RigidPolyline(funnel_wall(params["phi_deg"], params["wall_length"]))
    if friction is None and params["variant"] == "frictional":
        friction = ParabolicSlip(params["c_T"], params["alpha"], params["beta"], params["n"])
    contact = NodeToSegment(
        ring.body,
        ring.contact_nodes,
        wall,
        normal=normal or PowerLaw(params["c_N"], params["m"]),
        friction=friction,
        weights=1.0,
        offset=ring.offset,
        name="funnel",
        integration=time_integration.contact_integration(params),
    )
    symmetry = Dirichlet(ring.body, ring.symmetry_dofs(), 0.0)
    system = System([ring.body], [contact], fixed=[symmetry], **(system_options or {}))
    stepper = time_integration.make_stepper(params, system, atol=1e-10, maxit=30)
    stage = Stage(
        stepper,
        Steps(params["dt"], n_steps=params["n_steps"], max_cuts=6),
        np.zeros(ring.body.ndof),
        ring.initial_velocity((0.0, -params["v0"])),
        name="funnel",
    )
    return Model(
        systems=(system,),
        stage=stage,
        sizes=dict(element=np.pi * R / params["n_el"], body=2.0 * R, radius=R),
        parts=dict(ring=ring, wall=wall, contact=contact),
    )
    # the accuracy indicators' lengths (n_el on the half ring):
    # a beam element's size is its length (the thickness is its section's)


def radial_deviation(ring, u, center):
    """max_i | |x_i - c| - R | / R over the ring's nodes: how far the ring is from a circle
    about its current centre (0 for a rigid motion)."""
    r = np.linalg.norm(ring.positions(u) - center, axis=1)
    return float(np.max(np.abs(r - ring.R)) / ring.R)


def measure(m, params, records):
    ring = m.parts["ring"]
    hist = History.of(records)
    rec = ring_history(
        ring, records, measures=dict(deformation=lambda u, v: radial_deviation(ring, u, ring.center_of_mass(u)))
    )
    shots = snapshot_indices(rec["t"], every=params["outline_every"])
    t, y_c, v_c = rec["t"], rec["x_c"][:, 1], rec["v_c"][:, 1]  # the mirrored ring: centre on x = 0
    n_contact = np.asarray(rec["n_contact"])
    k0 = len(t) - max(2, len(t) // 4)  # the last quarter of the run
    T_win = t[-1] - t[k0]
    mean_v_window = float((y_c[-1] - y_c[k0]) / T_win)
    in_contact_window = bool(np.all(n_contact[k0:] > 0))
    stuck = in_contact_window and abs(mean_v_window) < 0.02 * params["v0"]
    k_low = int(np.argmin(y_c))
    rep = records[-1].contacts[0].report()  # the interface at the end of the run
    on = rep["state"] != "open"
    contact_final = dict(x=rep["x"][on], t_N=rep["t_N"][on], t_T=rep["t_T"][on], state=rep["state"][on].tolist())
    mech = hist.kinetic + hist.strain + hist.contact
    return dict(
        variant=params["variant"],
        stuck=bool(stuck),
        mean_v_c_last_quarter=mean_v_window,
        in_contact_last_quarter=in_contact_window,
        t=t,
        x_c=np.zeros_like(t),
        y_c=y_c,
        v_c=v_c,
        n_contact_nodes=n_contact,
        n_slip_nodes=np.asarray(rec["n_slip"]),
        deformation=np.asarray(rec["deformation"]),
        max_deformation=float(np.max(rec["deformation"])),
        y_c_min=float(y_c[k_low]),
        t_y_c_min=float(t[k_low]),
        y_c_start=float(y_c[0]),
        v_c_final=float(v_c[-1]),
        y_c_final=float(y_c[-1]),
        slipping_nodes_final=int(rec["n_slip"][-1]),
        contact_nodes_final=int(n_contact[-1]),
        contact_final=contact_final,
        energy_error=time_integration.energy_error(hist)[0],
        energy_kinetic=hist.kinetic,
        energy_strain=hist.strain,
        energy_contact=hist.contact,
        energy_dissipation=hist.dissipation,
        energy_total=mech,
        outlines=np.array([ring.outline(records[k].u, mirror=True) for k in shots]),
        outline_t=t[shots],
        wall=m.parts["wall"].points,
        obstacles=[m.parts["wall"].points, m.parts["wall"].points * [-1.0, 1.0]],  # the wall and its mirror image
        newton_iterations_total=int(np.sum(hist.iterations)),
        step_cuts_total=int(np.sum(hist.cuts)),
    )


def law_range(params):
    """The range the half ring's laws meet (Scene.law_range): pressures up to the one at which
    a single node's penalty spring would hold all the kinetic energy; slips up to the
    distance the ring can travel, slip rates up to twice its initial speed."""
    M = params["rho"] * np.pi * params["R"] * params["thickness"] * params["width"]
    E = 0.5 * M * params["v0"] ** 2
    return dict(
        p=penalty_pressure(E, params["c_N"], params["m"]),
        q=params["v0"] * params["n_steps"] * params["dt"],
        v=2.0 * params["v0"],
        dt=params["dt"],
        g=params["thickness"],
    )


SCENE = Scene(
    name="funnel",
    title="Fall of an elastic ring into a rigid funnel, half ring by symmetry (Sec. 5.4, Figs 12-13)",
    params=(
        Param(
            "variant",
            "frictionless",
            choices=VARIANTS,
            doc="frictionless (Fig 12: rebounds) or frictional eq (10) (Fig 13: sticks)",
        ),
        *RING_PARAMS,  # "the same ring as in Sec. 5.3" (half of it, by symmetry)
        Param("n_el", 30, "", 2, 2000, doc="elements on the half ring (paper: 30 beam elements)"),
        Param("v0", 4.0, "L/T", 0.0, None, low_open=True, doc="initial downward speed (paper)"),
        Param(
            "phi_deg",
            20.0,
            "deg",
            0.0,
            90.0,
            low_open=True,
            high_open=True,
            doc="funnel wall angle from the vertical (chosen: scan lost it; 20 deg sticks with friction "
            "because tan(phi) = 0.36 < mu_eff of eq (10) at the light pressures, and rebounds without)",
        ),
        Param("wall_length", 45.0, "L", 0.0, None, low_open=True, doc="length of the funnel wall (chosen)"),
        Param("gap0", 0.2, "L", 0.0, None, doc="initial clearance of the outer surface from the wall (chosen)"),
        Param("c_N", 10.0, "F/L", 0.0, None, low_open=True, doc="normal penalty, nodal stiffness, eq (4) (paper)"),
        Param("m", 1.0, "", 1.0, None, doc="exponent of the normal law eq (4) (paper)"),
        Param(
            "c_T",
            5.0,
            "F/L",
            0.0,
            None,
            low_open=True,
            doc="tangential stick stiffness, nodal, eq (5) (paper)",
            when=(("variant", ("frictional",)),),
        ),
        Param(
            "n",
            0.75,
            "",
            0.0,
            1.0,
            low_open=True,
            doc="exponent of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional",)),),
        ),
        Param(
            "alpha",
            0.3,
            "F^(1-n)",
            0.0,
            None,
            doc="alpha of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional",)),),
        ),
        Param(
            "beta",
            0.1,
            "",
            0.0,
            None,
            doc="beta of the slip surface eq (10) (paper)",
            when=(("variant", ("frictional",)),),
        ),
        Param("dt", 0.1, "T", 0.0, None, low_open=True, doc="time step (paper)"),
        Param(
            "n_steps",
            150,
            "",
            4,
            100000,
            doc="number of steps (chosen: the scan gives none; 150 covers the impact and 7 s after it)",
        ),
        *time_integration.newmark_params(0.7, 0.4, "chosen as in Sec. 5.3", tolerance=False),
        time_integration.CONTACT_INTEGRATION_PARAM,
        MASS_MATRIX_PARAM,
        Param("outline_every", 5, "", 1, 100000, doc="store the ring outline every this many steps (paper: 5)"),
    ),
    build=build,
    measure=measure,
    presets={"fast": {}, "paper": {}},  # 30 elements, 150 steps: about a second
    reports=("stuck", "y_c_min", "v_c_final", "max_deformation", "newton_iterations_total"),
    size=lambda p: dict(ring_size(p, half=True), steps=p["n_steps"]),
    outlines=True,
    laws=("normal", "friction"),
    law_params={"friction": ("c_T", "n", "alpha", "beta"), "normal": ("c_N", "m")},
    law_choice=("variant", VARIANTS),
    law_range=law_range,
    # the lowest point of the centre, and its final speed (near zero where the ring sticks: against a tenth of
    # the impact speed); the half ring's elements span what a whole ring's twice as many do
    quantities=(
        Quantity("y_c_min", "L", ("step", "mesh")),
        Quantity("v_c_final", "L/T", ("step", "mesh"), scale=lambda p: 0.1 * p["v0"]),
    ),
    discretisations=(time_step("dt", count="n_steps"), mesh("n_el", low=RING_FLOOR // 2)),
)
