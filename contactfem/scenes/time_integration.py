"""The time-integration parameter the impact scenes share: the paper's Newmark
(``standard``) or the energy-consistent stepper (solver/conserving.py), and the energy
error every such scene reports."""

import numpy as np

from ..solver import Newmark
from ..solver.conserving import EnergyConsistent
from ..solver.newmark import BETA_RANGE, DELTA_RANGE
from .base import Param

CONTACT_INTEGRATIONS = ("standard", "energy_consistent")

CONTACT_INTEGRATION_PARAM = Param(
    "contact_integration", "standard", choices=CONTACT_INTEGRATIONS,
    doc="standard: Newmark with delta, beta_newmark (the paper; with an unresolved penalty the trapezoidal "
        "rule gains energy at impact); energy_consistent: midpoint rule with discrete gradients of the "
        "bodies' and the interface's energy (Armero-Petocz): a frictionless impact conserves energy whatever "
        "c_N, dt and the phase at which contact begins; friction only dissipates (delta, beta_newmark unused)")


def newmark_params(delta, beta, source):
    """The Params delta and beta_newmark with the scene's defaults and Newmark's own ranges
    (solver.newmark: delta in [0.5, 1], beta in (0, 0.5]); ``source`` says where the defaults
    come from (e.g. "paper")."""
    return (Param("delta", delta, "", **DELTA_RANGE,
                  doc=f"Newmark delta, the usual gamma ({source}: {delta:g}; 0.5 with beta 0.25 conserves energy, "
                      "below 0.5 every step amplifies)"),
            Param("beta_newmark", beta, "", **BETA_RANGE,
                  doc=f"Newmark beta ({source}: {beta:g}; stable for every step when beta >= (delta + 1/2)^2 / 4)"))


def contact_integration(params):
    """How the scene's contacts integrate their forces over a step (NodeToSegment's
    ``integration``): standard, or energy_consistent with the energy-consistent stepper."""
    return params.get("contact_integration", "standard")


def make_stepper(params, system, **newton_options):
    """Newmark(delta, beta_newmark) or EnergyConsistent, as params['contact_integration'] says
    (the System's contacts built with ``integration=contact_integration(params)``)."""
    if contact_integration(params) == "energy_consistent":
        return EnergyConsistent(system, **newton_options)
    return Newmark(system, params["delta"], params["beta_newmark"], **newton_options)


def energy_error(hist):
    """Relative change of the total energy, dissipation counted: (E + D - W_ext)(end) / E(0) - 1,
    E = kinetic + strain + interface energy, D the frictional dissipation, W_ext the work of the
    loads and supports. Also its largest magnitude over the run."""
    E = hist.kinetic + hist.strain + hist.contact
    balance = E + hist.dissipation - hist.external_work
    E0 = E[0]
    return float((balance[-1] - E0) / E0), float(np.max(np.abs(balance - E0)) / E0)
