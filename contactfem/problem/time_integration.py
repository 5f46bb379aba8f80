"""The time-integration parameter the impact scenes share: the paper's Newmark
(``standard``) or the energy-consistent stepper (solver/conserving.py), and the energy
error every such scene reports."""

from dataclasses import dataclass

import numpy as np

from ..solver import Newmark, Steps
from ..solver.schedule import AtTolerance
from ..solver.conserving import EnergyConsistent
from ..solver.newmark import BETA_RANGE, DELTA_RANGE
from .params import Param

CONTACT_INTEGRATIONS = ("standard", "energy_consistent")

CONTACT_INTEGRATION_PARAM = Param(
    "contact_integration",
    "standard",
    choices=CONTACT_INTEGRATIONS,
    doc="standard: Newmark with delta, beta_newmark (the paper; with an unresolved penalty the trapezoidal "
    "rule gains energy at impact); energy_consistent: midpoint rule with discrete gradients of the "
    "bodies' and the interface's energy (Armero-Petocz): a frictionless impact conserves energy whatever "
    "c_N, dt and the phase at which contact begins; friction only dissipates (delta, beta_newmark unused)",
)


def newmark_params(delta, beta, source, tolerance=True):
    """The Params delta and beta_newmark with the scene's defaults and Newmark's own ranges
    (solver.newmark: delta in [0.5, 1], beta in (0, 0.5]); ``source`` says where the defaults
    come from (e.g. "paper"). ``tolerance``: the scene takes ``accuracy`` too, and a run at a tolerance
    integrates with the trapezoidal rule, so a delta or beta_newmark given with it is refused (they
    apply only with accuracy = 0) and its parameters record the rule's (``at_tolerance_values``)."""
    when = (("accuracy", (0.0,)),) if tolerance else ()
    return (
        Param(
            "delta",
            delta,
            "",
            **DELTA_RANGE,
            doc=f"Newmark delta, the usual gamma ({source}: {delta:g}; 0.5 with beta 0.25 conserves energy, "
            "below 0.5 every step amplifies; a run with accuracy > 0 uses 0.5)",
            when=when,
        ),
        Param(
            "beta_newmark",
            beta,
            "",
            **BETA_RANGE,
            doc=f"Newmark beta ({source}: {beta:g}; stable for every step when beta >= (delta + 1/2)^2 / 4; "
            "a run with accuracy > 0 uses 0.25)",
            when=when,
        ),
    )


def at_tolerance_values(values):
    """A run at a tolerance (values['accuracy'] > 0) integrates with the trapezoidal rule: its delta and
    beta_newmark say so (Scene.resolve), so that the parameters a run records are the ones it used."""
    if values.get("accuracy") and "delta" in values:
        return dict(values, delta=TRAPEZOIDAL["delta"], beta_newmark=TRAPEZOIDAL["beta"])
    return values


def contact_integration(params):
    """How the scene's contacts integrate their forces over a step (NodeToSegment's
    ``integration``): standard, or energy_consistent with the energy-consistent stepper."""
    return params.get("contact_integration", "standard")


# a run at a tolerance integrates with the trapezoidal rule: second order, without the numerical
# damping of delta > 1/2, whose error is first order in dt (solver/schedule.py; bench study 10 runs
# both)
TRAPEZOIDAL = dict(delta=0.5, beta=0.25)


def newmark_of(params):
    """(delta, beta) of the scene's Newmark: params' delta and beta_newmark, or the trapezoidal
    rule's (1/2, 1/4) in a run at a tolerance (params['accuracy'] > 0)."""
    if params.get("accuracy"):
        return TRAPEZOIDAL["delta"], TRAPEZOIDAL["beta"]
    return params["delta"], params["beta_newmark"]


def integrator_of(params):
    """What a scene's march integrates with, in words (its results' ``stepping``): the explicit
    stepper, energy_consistent, or Newmark's delta and beta (newmark_of)."""
    if params.get("integrator", "newmark") != "newmark":
        return params["integrator"]
    if contact_integration(params) == "energy_consistent":
        return "energy_consistent"
    delta, beta = newmark_of(params)
    trapezoidal = (delta, beta) == (TRAPEZOIDAL["delta"], TRAPEZOIDAL["beta"])
    return f"newmark delta = {delta:g}, beta = {beta:g}" + (" (trapezoidal rule)" if trapezoidal else "")


def make_stepper(params, system, **newton_options):
    """Newmark (newmark_of: delta, beta_newmark, or the trapezoidal rule at a tolerance) or
    EnergyConsistent, as params['contact_integration'] says (the System's contacts built with
    ``integration=contact_integration(params)``)."""
    if contact_integration(params) == "energy_consistent":
        return EnergyConsistent(system, **newton_options)
    delta, beta = newmark_of(params)
    return Newmark(system, delta, beta, **newton_options)


def energy_error(hist):
    """Relative change of the total energy, dissipation counted: (E + D - W_ext)(end) / E(0) - 1,
    E = kinetic + strain + interface energy, D the frictional dissipation, W_ext the work of the
    loads and supports. Also its largest magnitude over the run."""
    E = hist.kinetic + hist.strain + hist.contact
    balance = E + hist.dissipation - hist.external_work
    E0 = E[0]
    return float((balance[-1] - E0) / E0), float(np.max(np.abs(balance - E0)) / E0)


# the smallest tolerance a run at a tolerance is offered: measured, at 1e-4 the sloping impact's and
# the rolling ring's steps halve below 1e-9 of dt at their first impact and the run stops (exit 1);
# 1e-3 runs on every scene that takes it (bench study 10)
ACCURACY_MIN = 1e-3


@dataclass(frozen=True)
class Tolerance(Param):
    """A tolerance: 0 (off), or within [ACCURACY_MIN, high]."""

    def range_text(self, values=None):
        return f"0 (fixed steps) or [{ACCURACY_MIN:g}, {self.high:g}]"

    def parse(self, value):
        try:
            v = super().parse(value)
        except ValueError as err:
            if "must be a number" in str(err):  # text or a boolean: no number at all
                raise ValueError(
                    f"parameter {self.name} must be a number: {self.range_text()}, got {value!r}"
                ) from None
            v = None  # a number out of the parameter's own range
        if v is None or 0.0 < v < ACCURACY_MIN:
            raise ValueError(f"parameter {self.name} = {value!r} is out of range: allowed {self.range_text()}")
        return v


ACCURACY_PARAM = Tolerance(
    "accuracy",
    0.0,
    "",
    0.0,
    0.1,
    doc="0: fixed steps of dt (the default); TOL > 0: the steps are chosen from a local error estimate "
    "(solver/schedule.py: each step's error in the velocities held at TOL speed dt / duration) so "
    "that the headline quantities land within about TOL (relative) of the run refined in time; dt is then "
    "the largest step, and Newmark is the trapezoidal rule (delta = 0.5, beta_newmark = 0.25: second order; "
    "the damping of delta > 0.5 is an error of first order in dt); the run's error_budget indicator warns "
    "where its own estimate passes twice what TOL allows. The penalty is not changed: in these scenes it "
    "is the interface law of the model (the paper's eq 4, the bar's one-element stiffness), the reference "
    "is the same model refined in time, and the penetration indicator says how deep it lets the bodies go",
)


def plan(params, stepper, *, dt, speed, max_cuts, t_end=None, n_steps=None, duration=None, t0=0.0):
    """The stepper and the schedule of a dynamic scene's march: fixed steps of dt (``n_steps`` of
    them, or up to t_end) when params['accuracy'] is 0; else steps chosen from the local error
    estimate (schedule.AtTolerance) at the tolerance params['accuracy'], relative to ``speed``
    (the scene's velocity scale) over ``duration`` (the time its errors add up over; default: the
    run's, n_steps dt or t_end - t0), no step longer than dt, the first dt * accuracy; a step past
    twice its share of the error is retried halved."""
    tol = params.get("accuracy") or 0.0
    if not tol:
        return stepper, Steps(dt, n_steps=n_steps, t_end=None if n_steps else t_end, t0=t0, max_cuts=max_cuts)
    end = t0 + n_steps * dt if n_steps else t_end
    duration = duration or end - t0
    return stepper, AtTolerance(tol, speed, duration, dt, end, stepper.error_model, t0=t0, max_cuts=max_cuts)
