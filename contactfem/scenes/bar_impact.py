"""Bar impact: an elastic bar hits a rigid wall end-on, a verification scene with a
closed form (not one of the paper's examples).

A bar of length L, density rho, Young's modulus E moves at speed v0 towards a rigid
wall. One-dimensional wave theory (Graff, Wave Motion in Elastic Solids, sec. 1.2;
Hughes, The Finite Element Method, sec. 9.3 uses the same test):

    c = sqrt(E / rho)                bar wave speed
    sigma = rho c v0                 contact stress while in contact
    T = 2 L / c                      contact duration (the stress wave runs to the far
                                     end and back)
    v_after = -v0                    rebound at the same speed: no energy lost

Model: a thin strip of n_el x 1 four-node quads, plane stress with nu = 0 (so it is a
1-D bar exactly: no lateral coupling), lumped mass; the two end nodes facing the wall
are slaves on RigidLine x = 0 with a penalty per unit length (eq 4, m = 1; weights =
tributary lengths along the end face), c_N = c_N_factor E / h_x. Newmark (paper Sec. 4.1) with delta = 1/2,
beta = 1/4 by default: the trapezoidal rule, which conserves energy for linear
problems; dt is set by the Courant number c dt / h.

The penalty must not be much stiffer than the bar's elements: with c_N = 1000 E / h_x
the end node chatters (its velocity flips every step) and the trapezoidal rule, which
conserves energy only for a fixed quadratic potential, pumps energy in at every
open/close switch (the energy grew tenfold over one impact in our runs). With
c_N_factor = 1 the penalty behaves like one more element: contact starts smoothly,
and the contact duration is too long by about h_x / c (first order in the mesh size).

Energy, measured (tests/test_bar_impact.py). The trapezoidal rule is exact for the
quadratic potential of a contact that stays closed (or open) over a step; a step in
which the contact closes or opens integrates the kink of the penalty potential
inexactly. With the default gap = 0 contact starts exactly on a step boundary and the
energy error is ~1e-4 (9.5e-5 with 40 elements, 3.2e-5 with 100). A contact that starts
within a step (the general case: gap = v0 dt / 3, v0 dt / 2) loses energy, up to
4.6e-3 with 40 elements and 1.8e-3 with 100 at Courant number 1: first order in dt
(dt = h_x / c here), never a gain. Energy-consistent contact time-stepping would remove
this error; the standard Newmark method of the paper has it.

contact_integration = energy_consistent replaces Newmark by the energy-consistent stepper
(solver/conserving.py): the contact force of a step is the secant of the penalty
potential, so the energy is conserved to the Newton tolerance for any c_N_factor and any
phase at which contact begins within a step (``gap`` = v0 dt times the phase).

``enforcement = lagrange`` (the impenetrability exact, a semi-smooth Newton method;
``contact_discretization = mortar`` gives the same one-segment end face) is the limit of
an infinitely stiff penalty: under the trapezoidal rule the end node chatters and the
energy grows several times over, while the paper's Newmark 0.7/0.4 damps the chatter:
the contact lasts 2 L / c to the step and the energy falls by about what that rule
removes with the penalty (tests/test_beyond_nts.py). Exact constraints in time need an
energy- or velocity-consistent treatment of the impact that these steppers do not have.

Reported beside the exact values: contact duration (from the first to the last step
with a compressive contact force), the peak contact stress and its mean over the
middle 80 % of the contact (the discrete wave front rings: Gibbs oscillations), the
rebound velocity (momentum / mass at the end) and the energy error.
"""

import numpy as np

from .. import lazy
from ..contact import RigidLine, tributary_lengths
from ..laws import PowerLaw
from ..problem import enforcement, time_integration
from ..problem.scene import Model, Param, Quantity, Scene, Stage
from ..problem.uncertainty import mesh, penalty, time_step
from ..solver import CentralDifference, History, System

skfem = lazy.module("skfem")
continuum = lazy.module("contactfem.bodies.continuum")  # loads scikit-fem: not when the scenes are listed


def bar_exact(L, E, rho, v0):
    """1-D wave theory: wave speed c, contact stress rho c v0, duration 2 L / c."""
    c = np.sqrt(E / rho)
    return dict(c=c, stress=rho * c * v0, duration=2.0 * L / c, rebound_velocity=v0)


def check(params):
    if params["integrator"] == "central_difference" and params["contact_integration"] == "energy_consistent":
        raise ValueError(
            "parameter contact_integration = 'energy_consistent' is implicit: use it with integrator = newmark"
        )
    enforcement.check(params)
    if params["integrator"] == "central_difference" and params["accuracy"]:
        raise ValueError(
            f"parameter accuracy = {params['accuracy']} needs an implicit stepper (its local error "
            "estimate): use it with integrator = newmark"
        )
    if params["enforcement"] != "penalty" and params["accuracy"]:
        raise ValueError(
            f"parameter accuracy = {params['accuracy']} is offered with enforcement = penalty only "
            "(the multipliers' iterations are not tried at the adaptive mode's small first steps)"
        )
    if params["integrator"] == "central_difference" and params["enforcement"] != "penalty":
        raise ValueError(
            f"parameter enforcement = {params['enforcement']} needs an implicit solve: use it with integrator = newmark"
        )
    if params["contact_integration"] == "energy_consistent" and (
        params["enforcement"] != "penalty" or params["contact_discretization"] != "node_to_segment"
    ):
        raise ValueError(
            "parameter contact_integration = energy_consistent is offered with the penalty node-to-segment contact only"
        )


def build(params, *, normal=None, friction=None, system_options=None):
    """``normal`` / ``friction``: law objects instead of the parameters' (frictionless by default)."""
    L, H = params["L"], params["h"]
    n = params["n_el"]
    mesh = skfem.MeshQuad.init_tensor(np.linspace(0.0, L, n + 1), np.linspace(0.0, H, 2))
    mesh = mesh.translated((params["gap"], 0.0)).with_boundaries({"left": lambda x: x[0] < params["gap"] + 1e-9 * L})
    body = continuum.Continuum(mesh, params["E"], 0.0, params["rho"], kind="plane_stress", name="bar")
    nodes = np.flatnonzero(body.X[:, 0] < params["gap"] + 1e-9 * L)
    nodes = nodes[np.argsort(body.X[nodes, 1])]
    w = tributary_lengths(body.X[nodes])
    c_N = params["c_N_factor"] * params["E"] / (L / n)
    contact = enforcement.interface(
        params,
        body,
        nodes,
        RigidLine((0.0, 0.0), (1.0, 0.0)),
        normal=normal or PowerLaw(c_N, 1.0),
        friction=friction,
        weights=w,
        name="wall",
        integration=time_integration.contact_integration(params),
    )
    system = System([body], [contact], **(system_options or {}))
    v0, ex = params["v0"], bar_exact(L, params["E"], params["rho"], params["v0"])
    dt = params["courant"] * (L / n) / ex["c"]
    t_end = params["t_end"] * ex["duration"] + params["gap"] / v0
    explicit = params["integrator"] == "central_difference"
    if explicit:
        stepper = CentralDifference(system)
    else:
        F_scale = ex["stress"] * H
        stepper = time_integration.make_stepper(params, system, atol=1e-9 * F_scale, maxit=30)
    stepper = enforcement.wrap(params, stepper, [contact], length=L / n)  # gap_violation: penetration / h_x
    v0_vec = np.zeros(system.ndof)
    v0_vec[body.xdofs[:, 0]] = -v0
    # accuracy: the errors of the rebound velocity (speed v0) are made while the bar touches, 2 L / c
    stepper, schedule = time_integration.plan(
        params, stepper, dt=dt, t_end=t_end, speed=v0, duration=ex["duration"], max_cuts=0 if explicit else 4
    )
    stage = Stage(stepper, schedule, np.zeros(system.ndof), v0_vec, name="bar_impact")
    return Model(
        systems=(system,),
        stage=stage,
        sizes=dict(element=L / n, body=L),  # the accuracy indicators' lengths
        rebound=True,  # the accuracy's `separated`: the rebound is read after the impact
        parts=dict(body=body, contact=contact, nodes=nodes, w=w, c_N=c_N, dt=dt),
    )


def measure(m, params, records):
    body = m.parts["body"]
    L, H, v0 = params["L"], params["h"], params["v0"]
    ex = bar_exact(L, params["E"], params["rho"], v0)
    dt = m.parts["dt"]
    hist = History.of(records)
    force = [0.0] + [float(-rec.contacts[0].report()["f_N"].sum()) for rec in records[1:]]
    t, F = hist.t, np.asarray(force)
    stress = F / H
    on = np.flatnonzero(F > 0.0)
    if len(on) == 0:
        raise ValueError("the bar never touched the wall: check gap and t_end")
    t_first, t_last = t[on[0]], t[on[-1]]
    # contact starts between the step before the first loaded step and that step
    # (and likewise at release): take the midpoints
    t_start = 0.5 * (t[max(on[0] - 1, 0)] + t_first)
    t_stop = 0.5 * (t_last + t[min(on[-1] + 1, len(t) - 1)])
    duration = t_stop - t_start
    mid = (t > t_start + 0.1 * duration) & (t < t_stop - 0.1 * duration)
    M = body.mass()
    vx = hist.v[body.xdofs[:, 0]]
    v_after = float(M[body.xdofs[:, 0]] @ vx / M[body.xdofs[:, 0]].sum())
    E_tot = hist.kinetic + hist.strain + hist.contact
    E0 = E_tot[0]
    return dict(
        duration=duration,
        duration_exact=ex["duration"],
        error_duration=(duration - ex["duration"]) / ex["duration"],
        stress_peak=float(stress.max()),
        stress_mean=float(stress[mid].mean()) if np.any(mid) else float(stress.max()),
        stress_exact=ex["stress"],
        error_stress_mean=(float(stress[mid].mean()) - ex["stress"]) / ex["stress"] if np.any(mid) else 0.0,
        rebound_velocity=v_after,
        rebound_velocity_exact=ex["rebound_velocity"],
        error_rebound=(v_after - v0) / v0,
        energy_initial=E0,
        energy_final=float(E_tot[-1]),
        energy_error=float((E_tot[-1] - E0) / E0),
        energy_error_max=float(np.max(np.abs(E_tot - E0)) / E0),
        wave_speed=ex["c"],
        dt=dt,
        c_N=m.parts["c_N"],
        n_steps=int(len(t) - 1),
        time=t,
        contact_stress=stress,
        energy_total=E_tot,
        newton_iterations_total=int(np.sum(hist.iterations)),
        **enforcement.report(
            params,
            records,
            max(enforcement.penetration(rec.contacts[0]) for rec in records),
            L / params["n_el"],
            "the element length h_x (largest penetration of the run)",
        ),
    )


def law_range(params):
    """Normal law only: probed down to a penetration of the bar's height."""
    return dict(g=params["h"])


SCENE = Scene(
    name="bar_impact",
    title="Bar impact on a rigid wall (verification, 1-D wave theory)",
    params=(
        Param("L", 100.0, "mm", 0.0, None, low_open=True, doc="bar length"),
        Param("h", 10.0, "mm", 0.0, None, low_open=True, doc="bar height (one element through it)"),
        Param("E", 2.1e5, "MPa", 0.0, None, low_open=True, doc="Young's modulus (steel)"),
        Param("rho", 7.85e-9, "t/mm^3", 0.0, None, low_open=True, doc="density (steel, N s^2/mm^4)"),
        Param("v0", 1000.0, "mm/s", 0.0, None, low_open=True, doc="impact speed"),
        Param("gap", 0.0, "mm", 0.0, None, doc="initial distance to the wall"),
        Param("n_el", 100, "", 2, 100000, doc="elements along the bar"),
        Param("courant", 1.0, "", 0.0, None, low_open=True, doc="Courant number c dt / h (sets dt)"),
        Param(
            "c_N_factor",
            1.0,
            "",
            0.0,
            None,
            low_open=True,
            doc="penalty per unit length c_N = c_N_factor E / h_x (eq 4, m = 1); chosen: 1, a penalty "
            "as stiff as one element; much stiffer penalties chatter under the trapezoidal rule",
        ),
        Param(
            "integrator",
            "newmark",
            choices=("newmark", "central_difference"),
            doc="implicit Newmark (delta, beta_newmark) or explicit central differences (stable for "
            "courant < 1; no Newton, no cutback)",
        ),
        *time_integration.newmark_params(0.5, 0.25, "chosen, average acceleration"),
        Param("t_end", 1.5, "2L/c", 0.0, None, low_open=True, doc="simulated time in units of 2 L / c"),
        time_integration.CONTACT_INTEGRATION_PARAM,
        time_integration.ACCURACY_PARAM,
        *enforcement.ENFORCEMENT_PARAMS,
    ),
    build=build,
    measure=measure,
    check=check,
    presets={"fast": {"n_el": 40}, "paper": {"n_el": 100}},
    size=lambda p: dict(
        elements=p["n_el"],
        unknowns=4 * (p["n_el"] + 1),
        steps=(2 * p["t_end"] + p["gap"] / p["L"] * (p["E"] / p["rho"]) ** 0.5 / p["v0"]) * p["n_el"] / p["courant"],
    ),
    reports=(
        "duration",
        "duration_exact",
        "stress_mean",
        "stress_peak",
        "stress_exact",
        "rebound_velocity",
        "energy_error",
    ),
    laws=("normal",),
    law_params={"normal": ("c_N_factor",)},
    law_range=law_range,
    # against the continuous bar's closed forms: the contact lasts 2 L / c and the bar leaves at v0. The
    # penalty (a stiffness per element) regularises the rigid wall. The duration is read in whole steps and
    # its wave crosses the elements one by one: first order in the step and in the element size
    quantities=(
        Quantity(
            "duration", "s", ("step", "mesh", "penalty"), exact="duration_exact", orders={"step": 1.0, "mesh": 1.0}
        ),
        Quantity("rebound_velocity", "mm/s", ("step", "mesh", "penalty"), exact="rebound_velocity_exact"),
    ),
    # the mesh's levels keep the step and the penalty (courant and c_N_factor are relative to the element size)
    discretisations=(
        time_step("courant"),
        mesh(
            "n_el",
            extra=lambda p, n: {
                "courant": p["courant"] * n["n_el"] / p["n_el"],
                "c_N_factor": p["c_N_factor"] * p["n_el"] / n["n_el"],
            },
        ),
        penalty("c_N_factor"),
    ),
)
