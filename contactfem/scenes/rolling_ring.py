"""A steel ring slides, then rolls, on a rigid plane (paper Sec. 5.2, Fig 9).

Data (paper): mean radius R = 50 cm, cross-section A = 10 cm^2 (rectangular), E = 2.1e4
kN/cm^2, v0 = 300 cm/s along the plane, gravity, 120 elements, Coulomb friction mu = 0.15
(eq 11), normal law eq (4) with m = 1, Newmark delta = 0.7, beta = 0.4, dt = 0.01 s.
Units: cm, s, kN (mass unit kN s^2/cm = 1e5 kg).

Choices (the scan lost or does not give them):
    * density: the scan reads "7.85e-? kN s^2/cm^4". Steel is 7850 kg/m^3 and
      1 kN s^2/cm^4 = 1e11 kg/m^3, so rho = 7.85e-8 kN s^2/cm^4 (ring mass 24.7 kg,
      weight W = 0.242 kN). The rigid-ring answer does not depend on the mass.
    * section: A = 10 cm^2 as thickness h = 1 cm (radial) x width b = 10 cm (depth), a
      THIN ring, as the paper's closed form assumes (I = m R^2); a 10 cm thick wall would
      roll on radius 55 cm and move x* by ~9 %.
    * c_N = 10 kN/cm, c_T = 1 kN/cm, NODAL stiffnesses (force per unit gap of one node,
      weights = 1): static penetration W / c_N ~ 0.02 cm (2 % of the wall), stick
      displacement mu W / c_T ~ 0.04 cm. The scan reads "c_N = 10' kN/cm and c_T = lo*
      kN/cm"; by the rule lecture 04 uses ('*' stands for a superscript 2 elsewhere in the
      scan) c_T would read 10^2 kN/cm. We do not use that reading: measured, c_T = 100
      moves the rolling point by < 0.1 % and the final speed by 0.4 % (paper preset;
      1.5 % on the fast one), slightly towards the rigid ring, but Newton switches between
      stick and slip at the nodes that touch down: hundreds of step cutbacks and about
      seven times the time (lecture 05 runs both).
    * start: outer surface touching the plane (lowest point at y = 0) without penetration
      and without sag; the ring settles by W / c_N ~ 0.02 cm plus its elastic sag (~0.1 cm)
      and the Newmark damping (delta = 0.7) takes out the small bounce within a few steps.
    * gravity g = 981 cm/s^2; t_end = 2 s (the paper's second bracketed position,
      x = 376 cm, is the exact centre position at t = 2 s).
    * Newton atol = 1e-7 kN for the beam (its residual's round-off floor is ~1e-8 kN), 1e-6 kN for the continuum
      (its floor after step cuts to dt ~ 3e-7: ~2e-6 kN).

Closed form (rigid ring, contact lever arm a, radius of gyration k; thin hoop a = k = R):
    sliding:  v(t) = v0 - mu g t,  omega(t) = -mu g a t / k^2   (clockwise for v0 > 0)
    rolling starts when the contact point stops, v = -omega a:
              t* = v0 / (mu g (1 + a^2/k^2)),  x* = v0 t* - mu g t*^2 / 2,
              v* = v0 - mu g t*  (= v0 / 2 for the hoop),  then x = x* + v* (t - t*).
Hoop, v0 = 300, mu = 0.15, g = 981: t* = 1.019 s, x* = 229.4 cm, v* = 150 cm/s.

Measured from the simulation (all centre-of-mass quantities of RingModel):
    slip velocity  s(t) = v_x + omega a, a = ring.rolling_radius (beam: R, the contact
                   measures the slip of the centreline node; continuum: R + h/2)
    t_roll         the sliding phase has s(t) linear in t (constant friction force): a
                   least-squares line through the samples with 0.1 v0 < s < 0.9 v0 is
                   extended to s = 0 (robust against the contact bumps of a polygonal
                   ring); `rolled` is False, and t_roll, x_roll are None, if s never falls
                   below 0.02 v0 in the run
    x_roll         centre x at t_roll (linear interpolation)
    v_final, omega_final   means over the rolling phase t > t_roll + 0.1 s
    x_end, v_end   at t_end, compared with the exact x(t_end) (paper: 376 exact, 382 computed)
"""

import numpy as np

from ..bodies.ring import make_ring
from ..contact import NodeToSegment, RigidLine
from ..laws import Coulomb, PowerLaw
from ..solver import History, System
from ..problem import time_integration
from ..problem.scene import Model, Param, Quantity, Scene, Stage
from ..problem.uncertainty import mesh, time_step
from .rings import (
    RING_FLOOR,
    MASS_MATRIX_PARAM,
    THICKNESS_LIMIT,
    detect_rolling,
    penalty_pressure,
    rigid_ring_exact,
    ring_gyration_radius2,
    ring_history,
    ring_size,
    snapshot_indices,
)  # noqa: F401

# Paper, Fig 9 (bracketed values are the rigid thin-ring solution)
PAPER = dict(x_roll_exact=229.0, x_roll_computed="23x (scan)", x_end_exact=376.0, x_end_computed=382.0, v_final=150.0)


ANIMATION_FRAMES = 120  # frames of the run --gif animation (one every few steps)


def build(params, *, normal=None, friction=None, system_options=None):
    """The ring touching the plane y = 0 (lowest outer point at y = 0), contact, gravity, and
    its march. ``normal`` / ``friction``: law objects instead of the ones the parameters build."""
    R, h = params["R"], params["thickness"]
    args = dict(
        kind=params["kind"],
        R=R,
        thickness=h,
        width=params["width"],
        n_el=params["n_el"],
        E=params["E"],
        nu=params["nu"],
        rho=params["rho"],
        n_radial=params["n_radial"],
        name="ring",
        mass_matrix=params["mass_matrix"],
    )
    probe = make_ring(**args)
    y0 = -probe.outline(np.zeros(probe.body.ndof))[:, 1].min()  # R + h/2 if a node sits at the bottom
    ring = make_ring(center=(0.0, y0), **args)
    plane = RigidLine((0.0, 0.0), (0.0, 1.0))
    contact = NodeToSegment(
        ring.body,
        ring.contact_nodes,
        plane,
        normal=normal or PowerLaw(params["c_N"], params["m"]),
        friction=friction or Coulomb(params["c_T"], params["mu"]),
        weights=1.0,
        offset=ring.offset,
        name="plane",
        integration=time_integration.contact_integration(params),
    )
    system = System([ring.body], [contact], [ring.gravity(params["g"])], **(system_options or {}))
    stepper = time_integration.make_stepper(params, system, atol=1e-7 if params["kind"] == "beam" else 1e-6, maxit=30)
    # accuracy: the errors of v_final (relative to v0) add up over the run
    stepper, schedule = time_integration.plan(
        params, stepper, dt=params["dt"], t_end=params["t_end"], speed=params["v0"], max_cuts=8
    )
    stage = Stage(
        stepper, schedule, np.zeros(ring.body.ndof), ring.initial_velocity((params["v0"], 0.0)), name="rolling_ring"
    )
    # the closed forms hold for Coulomb friction: the scene's, or a Coulomb law given with its own mu
    exact_mu = params["mu"] if friction is None else (friction.mu if isinstance(friction, Coulomb) else None)
    return Model(
        systems=(system,),
        stage=stage,
        sizes=dict(
            element=2.0 * np.pi * params["R"] / params["n_el"],
            body=2.0 * params["R"],  # (their length)
            radius=params["R"],
        ),
        parts=dict(ring=ring, contact=contact, plane=plane, exact_mu=exact_mu),
    )


def animation(ring, records, floor):
    """About ANIMATION_FRAMES outlines of at most ~60 points each, for `run --gif`, with a spoke
    from the centre to one point of the ring, so that rolling is told from sliding."""
    every = max(1, int(np.ceil((len(records) - 1) / ANIMATION_FRAMES)))
    u0 = records[0].u
    n_out = len(ring.outline(u0)) - 1
    pick = np.unique(np.r_[np.arange(0, n_out, max(1, n_out // 60)), n_out])
    frames = records[::every]
    outlines = [ring.outline(r.u) for r in frames]
    return dict(
        t=np.array([r.t for r in frames]),
        outlines=np.array([o[pick] for o in outlines]),
        marks=np.array([[np.vstack([ring.center_of_mass(r.u), o[0]])] for r, o in zip(frames, outlines)]),
        obstacles=[floor],
    )


# the rigid ring's closed forms and the errors against them: for Coulomb friction only (else None)
CLOSED_FORM_KEYS = (
    "exact_mu",
    "t_star_exact",
    "x_roll_exact",
    "v_final_exact",
    "omega_final_exact",
    "x_end_exact",
    "x_roll_rel_err",
    "v_final_rel_err",
    "x_end_rel_err",
    "t_star_model",
    "x_roll_model",
    "v_final_model",
    "x_exact",
    "vx_exact",
    "omega_exact",
)


def measure(model, params, records):
    ring = model.parts["ring"]
    v0 = params["v0"]
    nodes = ring.body.xdofs[ring.contact_nodes]  # (u_x, u_y) dofs of the contact nodes
    hist = History.of(records)
    rec = ring_history(ring, records)
    shots = snapshot_indices(rec["t"], interval=params["outline_interval"], tol=1e-6 * params["dt"])

    t, xc, vc, omega = rec["t"], rec["x_c"], rec["v_c"], rec["omega"]
    a = ring.rolling_radius
    slip = vc[:, 0] + omega * a
    t_roll = detect_rolling(t, slip, v0)
    rolled = t_roll is not None
    x_roll = float(np.interp(t_roll, t, xc[:, 0])) if rolled else None
    late = t > (t_roll + 0.1 if rolled else np.inf)
    if np.count_nonzero(late) >= 2:
        v_final, omega_final = float(vc[late, 0].mean()), float(omega[late].mean())
    else:
        late = np.arange(len(t)) == len(t) - 1  # still sliding at the end: the last sample
        v_final, omega_final = float(vc[-1, 0]), float(omega[-1])

    floor = np.array([[xc[:, 0].min() - 1.2 * params["R"], 0.0], [xc[:, 0].max() + 1.2 * params["R"], 0.0]])
    # Coulomb's mu of the closed forms: build's choice; a model composed by hand (a lecture's)
    # with the scene's laws: the parameters' mu
    mu, g = model.parts.get("exact_mu", params.get("mu")), params["g"]
    k2 = ring_gyration_radius2(ring)
    if mu is not None:
        hoop = rigid_ring_exact(v0, mu, g, params["R"], t=t)  # the paper's thin hoop
        # the rigid ring of this model: lever arm a, gyration radius from the lumped masses
        exact = rigid_ring_exact(v0, mu, g, a, k2)
        v_exact = float(np.mean(hoop["v"][late]))
        closed = dict(
            # v_final's reference: the hoop's velocity over the same samples (rolling, sliding to the
            # end when mu is small, or the transition)
            exact_mu=mu,
            t_star_exact=hoop["t_star"],
            x_roll_exact=hoop["x_star"],
            v_final_exact=v_exact,
            omega_final_exact=float(np.mean(hoop["omega"][late])),
            x_end_exact=float(hoop["x"][-1]),
            x_roll_rel_err=(x_roll / hoop["x_star"] - 1.0) if rolled else None,
            v_final_rel_err=v_final / v_exact - 1.0,
            x_end_rel_err=float(xc[-1, 0] / hoop["x"][-1] - 1.0),
            t_star_model=exact["t_star"],
            x_roll_model=exact["x_star"],
            v_final_model=exact["v_star"],
            x_exact=hoop["x"],
            vx_exact=hoop["v"],
            omega_exact=hoop["omega"],
        )
    else:  # a friction law other than Coulomb: no closed form
        closed = dict.fromkeys(CLOSED_FORM_KEYS)
    return dict(
        kind=params["kind"],
        rolled=rolled,
        t_roll=t_roll,
        x_roll=x_roll,
        v_final=v_final,
        omega_final=omega_final,
        x_end=float(xc[-1, 0]),
        v_end=float(vc[-1, 0]),
        omega_end=float(omega[-1]),
        **closed,
        rolling_radius=a,
        gyration_radius2=k2,
        mass=ring.total_mass(),
        ndof=ring.body.ndof,
        paper=PAPER,
        t=t,
        x_c=xc[:, 0],
        y_c=xc[:, 1],
        vx_c=vc[:, 0],
        vy_c=vc[:, 1],
        omega=omega,
        slip_velocity=slip,
        outlines=[ring.outline(records[k].u) for k in shots],
        outline_t=t[shots],
        outline_vc=vc[shots],
        outline_omega=omega[shots],
        outline_node_y=[ring.body.X[ring.contact_nodes, 1] + records[k].u[nodes[:, 1]] for k in shots],
        outline_node_vx=[records[k].v[nodes[:, 0]] for k in shots],
        energy_error=time_integration.energy_error(hist)[0],
        energy_kinetic=hist.kinetic,
        energy_strain=hist.strain,
        energy_dissipation=hist.dissipation,
        animation=animation(ring, records, floor),
        obstacles=[floor],
        newton_iterations_total=int(np.sum(hist.iterations)),
        step_cuts_total=int(np.sum(hist.cuts)),
    )


def law_range(params):
    """The range the ring's laws meet (Scene.law_range): pressures up to the one at which a
    single node's penalty spring would hold all the energy (kinetic, and gravity's over a
    radius), at least ten times the weight; slips up to the distance the ring can travel,
    slip rates up to twice its initial speed."""
    M = params["rho"] * 2.0 * np.pi * params["R"] * params["thickness"] * params["width"]
    E = 0.5 * M * params["v0"] ** 2 + M * params["g"] * params["R"]
    return dict(
        p=max(penalty_pressure(E, params["c_N"], params["m"]), 10.0 * M * params["g"]),
        q=params["v0"] * params["t_end"],
        v=2.0 * params["v0"],
        dt=params["dt"],
        g=params["thickness"],
    )


SCENE = Scene(
    name="rolling_ring",
    title="Steel ring sliding, then rolling, on a rigid plane (Sec. 5.2, Fig 9)",
    params=(
        Param(
            "kind",
            "beam",
            choices=("beam", "continuum"),
            doc="beam: the paper's finite-deformation beam ring; continuum: annulus of quads "
            "(plane strain, St Venant-Kirchhoff, n_radial through the wall)",
        ),
        Param("R", 50.0, "cm", 0.0, None, low_open=True, doc="mean radius (paper)"),
        Param(
            "thickness",
            1.0,
            "cm",
            0.0,
            None,
            low_open=True,
            high_open=True,
            limit=THICKNESS_LIMIT,
            doc="radial wall thickness h (chosen: the paper gives A = 10 cm^2 only; a thin ring, "
            "h = 1 cm x width 10 cm, as the closed form assumes)",
        ),
        Param(
            "width",
            10.0,
            "cm",
            0.0,
            None,
            low_open=True,
            doc="out-of-plane depth b, A = h b (chosen with thickness: A = 10 cm^2, paper)",
        ),
        Param("E", 2.1e4, "kN/cm^2", 0.0, None, low_open=True, doc="Young's modulus, steel (paper)"),
        Param(
            "nu",
            0.3,
            "",
            -1.0,
            0.5,
            low_open=True,
            high_open=True,
            doc="Poisson's ratio (chosen: steel; enters the beam's shear modulus and the continuum)",
        ),
        Param(
            "rho",
            7.85e-8,
            "kN s^2/cm^4",
            0.0,
            None,
            low_open=True,
            doc="density (scan lost the exponent: steel 7850 kg/m^3 = 7.85e-8 kN s^2/cm^4)",
        ),
        Param("n_el", 120, "", 8, 4000, doc="elements around the ring (paper: 120)"),
        Param(
            "n_radial",
            2,
            "",
            1,
            20,
            doc="continuum only: elements through the wall (chosen)",
            when=(("kind", ("continuum",)),),
        ),
        Param("v0", 300.0, "cm/s", 0.0, None, low_open=True, doc="initial velocity along the plane, no spin (paper)"),
        Param("g", 981.0, "cm/s^2", 0.0, None, low_open=True, doc="gravity (paper: 'gravity')"),
        Param("mu", 0.15, "", 0.0, None, low_open=True, doc="Coulomb friction coefficient, eq (11) (paper)"),
        Param(
            "c_N",
            10.0,
            "kN/cm",
            0.0,
            None,
            low_open=True,
            doc="normal penalty, nodal stiffness, eq (4) (chosen: scan lost it; penetration W/c_N ~ 0.02 cm)",
        ),
        Param("m", 1.0, "", 1.0, None, doc="exponent of the normal law eq (4) (paper: 1)"),
        Param(
            "c_T",
            1.0,
            "kN/cm",
            0.0,
            None,
            low_open=True,
            doc="tangential stick stiffness, nodal, eq (5). Chosen: the scan's 'lo*' reads 10^2 by the rule "
            "of lecture 04; 1 (stick slip mu W/c_T ~ 0.04 cm) gives the same motion without the hundreds "
            "of step cutbacks of 100 (lecture 05 compares them)",
        ),
        Param("dt", 0.01, "s", 0.0, None, low_open=True, doc="time step (paper: 0.01)"),
        Param(
            "t_end",
            2.0,
            "s",
            0.0,
            None,
            low_open=True,
            doc="duration (chosen: 2 s, where the paper's exact position is 376 cm)",
        ),
        *time_integration.newmark_params(0.7, 0.4, "paper"),
        time_integration.CONTACT_INTEGRATION_PARAM,
        time_integration.ACCURACY_PARAM,
        MASS_MATRIX_PARAM,
        Param(
            "outline_interval", 0.25, "s", 0.0, None, low_open=True, doc="store the ring outline this often (figures)"
        ),
    ),
    build=build,
    measure=measure,
    # fast: the paper's ring at twice its step. A ring of 40 elements rolls on its corners: its rolling speed
    # is 5.5 % below the hoop's and does not settle as the step is refined (fixed trapezoidal steps from 5e-3 to
    # 7.8e-5 s scatter by 1.5 %), so no band could hold it; 120 elements cost no more (one Newton iteration is
    # Python's, not the band LU's) and roll within 2 % of the hoop
    presets={"fast": {"n_el": 120, "dt": 0.02}, "paper": {"n_el": 120, "dt": 0.01}},
    reports=(
        "t_roll",
        "x_roll",
        "x_roll_exact",
        "v_final",
        "v_final_exact",
        "omega_final",
        "x_end",
        "x_end_exact",
        "newton_iterations_total",
    ),
    size=lambda p: dict(ring_size(p), steps=p["t_end"] / p["dt"]),
    outlines=True,
    laws=("normal", "friction"),
    law_params={"friction": ("c_T", "mu"), "normal": ("c_N", "m")},
    law_range=law_range,
    # against the rigid hoop's closed forms (Coulomb friction; a law without one has none); c_N is the model's
    # interface law (chosen), not a regularisation
    quantities=(
        Quantity("v_final", "cm/s", ("step", "mesh"), exact="v_final_exact"),
        Quantity("x_roll", "cm", ("step", "mesh"), exact="x_roll_exact"),
        Quantity("x_end", "cm", ("step", "mesh"), exact="x_end_exact"),
    ),
    discretisations=(time_step("dt"), mesh("n_el", low=RING_FLOOR)),
)
