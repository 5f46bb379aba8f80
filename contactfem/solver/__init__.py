"""Solving: the System that composes bodies, contacts and loads, Newton's method within a
step, the time steppers and the time loop (paper Sec. 4.1, 4.3).

    system = System(bodies, contacts, loads, fixed=[Dirichlet(body, dofs, value)])
    state = system.start(u0, t0)              # SystemState: contact histories, body and load states
    ev = system.evaluate(u, t, dt, state=state)   # G = R + R_c - P (eq 29 without M a), K, contact states
    state = system.commit(ev, u, t, dt)       # the next SystemState, after a converged u
    stepper = Newmark(system, delta=0.7, beta=0.4)   # or Static(system), CentralDifference, EnergyConsistent
    for rec in march(stepper, Steps(dt=0.1, n_steps=200), t0, u0, v0):
        rec.t, rec.u, rec.v, rec.contacts, rec.energy, rec.iterations, rec.state
    hist = integrate(stepper, t0, u0, v0, n_steps=200, dt=0.1)   # the same, collected into arrays

``march`` is the one time loop of every scene (march.py): a generator of records, each the
converged step as a value; the schedule (schedule.py: ``Steps``, ``Adaptive``) sets the step
sizes and the halving of failed steps; a scene stops by leaving the loop.

Files: system.py (System, Dirichlet, Evaluation), newton.py (newton, NewtonResult, NewtonError),
newmark.py (Newmark, Static, CentralDifference), march.py (march, Record, integrate, History),
schedule.py (Steps, Adaptive; AtTolerance: steps chosen from a local error estimate), estimate.py (a step's
local error: the one estimator of the adaptive steps, the indicators and the time part of the bands),
conserving.py (EnergyConsistent), uzawa.py (the augmented
Lagrangian's outer loop), staggered.py (the two-step algorithm of Sec. 2.2), interfaces.py
(what a stepper and a schedule are). A stepper's ``step`` never commits; the time loop commits
only converged steps.
"""

from .system import Dirichlet, Evaluation, System
from .newton import NewtonError, NewtonResult, newton
from .newmark import CentralDifference, Newmark, Static, initial_acceleration
from .march import History, Record, integrate, march, watch
from .schedule import Adaptive, Steps

__all__ = [
    "Dirichlet",
    "Evaluation",
    "System",
    "NewtonError",
    "NewtonResult",
    "newton",
    "Newmark",
    "Static",
    "CentralDifference",
    "History",
    "Record",
    "integrate",
    "march",
    "watch",
    "initial_acceleration",
    "Adaptive",
    "Steps",
]
