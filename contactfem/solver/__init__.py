"""Solving: the System that composes bodies, contacts and loads, Newton's method
within a step, and Newmark time stepping (paper Sec. 4.1, 4.3).

    system = System(bodies, contacts, loads, fixed=[Dirichlet(body, dofs, value)])
    G, K = system.residual_tangent(u, t)     # G = R + R_c - P (eq 29 without M a); K dense or CSC
    stepper = Newmark(system, dt, delta=0.7, beta=0.4)   # or Static(system), CentralDifference
    hist = integrate(stepper, t0, u0, v0, n_steps=200, cutback=True)
    hist.t, hist.kinetic, hist.strain, hist.contact, hist.dissipation, hist.residuals

``integrate`` is the one time loop of every scene; its keyword hooks cover what they
need: ``dt_rule`` (adaptive steps, with ``growth`` after a cutback and ``min_dt``),
``before_step`` (explicit coupling, e.g. a gas pressure), ``motion`` (a prescribed
obstacle motion), ``stop``, ``before_commit`` and ``recorder`` (what to keep of each
step), ``progress`` (e.g. ``contactfem.io.progress_bar``) and ``label``.

Files: system.py (System, Dirichlet), newton.py (newton, NewtonResult, NewtonError),
newmark.py (Newmark, Static, CentralDifference, integrate, History, Step, initial_acceleration),
staggered.py (the two-step algorithm of Sec. 2.2 on contact.tangents.SplitContact).
A stepper's ``step`` never commits; ``integrate`` commits only converged steps.
"""
from .system import Dirichlet, System
from .newton import NewtonError, NewtonResult, newton
from .newmark import (CentralDifference, History, Newmark, Static, Step, initial_acceleration,
                      integrate)

__all__ = ["Dirichlet", "System", "NewtonError", "NewtonResult", "newton", "Newmark", "Static",
           "CentralDifference", "History", "Step", "integrate", "initial_acceleration"]
