"""Solving: the System that composes bodies, contacts and loads, Newton's method
within a step, and Newmark time stepping (paper Sec. 4.1, 4.3).

    system = System(bodies, contacts, loads, fixed=[Dirichlet(body, dofs, value)])
    G, K = system.residual_tangent(u, t)     # G = R + R_c - P (eq 29 without M a), K CSR
    stepper = Newmark(system, dt, delta=0.7, beta=0.4)   # or Static(system), CentralDifference
    hist = integrate(stepper, t0, u0, v0, n_steps=200, cutback=True)
    hist.t, hist.kinetic, hist.strain, hist.contact, hist.dissipation, hist.residuals

Files: system.py (System, Dirichlet), newton.py (newton, NewtonResult, NewtonError),
newmark.py (Newmark, Static, CentralDifference, integrate, History, initial_acceleration).
A stepper's ``step`` never commits; ``integrate`` commits only converged steps.
"""
from .system import Dirichlet, System
from .newton import NewtonError, NewtonResult, newton
from .newmark import (CentralDifference, History, Newmark, Static, initial_acceleration,
                      integrate)

__all__ = ["Dirichlet", "System", "NewtonError", "NewtonResult", "newton", "Newmark", "Static",
           "CentralDifference", "History", "integrate", "initial_acceleration"]
