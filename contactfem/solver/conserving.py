"""An energy-consistent time stepper for impacts: the midpoint rule with discrete
gradients (Gonzalez 1996) for the bodies and for the contact (contact/conserving.py,
Armero & Petocz 1998).

    contact = NodeToSegment(..., integration="energy_consistent")
    stepper = EnergyConsistent(System(bodies, [contact], ...))
    for rec in march(stepper, Steps(dt, n_steps=...), t0, u0, v0): ...

One step from (u_0, v_0) solves for u_1. With d = u_1 - u_0 and dq the same increment
with the beams' angle increments Delta theta replaced by phi = 2 tan(Delta theta / 2)
(a rotation's Cayley parameter, bodies/discrete_gradient.py), v_1 = 2 dq / dt - v_0 and

    M (v_1 - v_0) / dt + F_int + X (F_c - P(u_mid, t_mid)) = 0,

    F_int = every body's discrete gradient (body.discrete_gradient): dq . F_int = W(u_1) - W(u_0),
    F_c   = the discrete gradient of the interface potential (contact/conserving.py):
            d . F_c = the change of the interface energy plus the frictional dissipation,
    X     = diag(d / dq): 1 on the positions, Delta theta / phi on an angle (a moment
            conjugate to Delta theta made conjugate to phi).

With dq = dt (v_0 + v_1) / 2 the kinetic energy changes by -dq . (F_int + X (F_c - P)) =
-(W(u_1) - W(u_0)) - d . (F_c - P): the total energy kinetic + strain + interface changes by
the work of the loads minus the dissipation, exactly (to the Newton tolerance) -- whatever
the penalty c_N, the time step, and the phase within a step at which a node touches.

Momentum: the midpoint rule changes the linear momentum by dt times the resultant force,
and the angular momentum about the origin by dt times the moment at the midpoint positions
(the angles' part through phi: the rigid rotation of the midpoint rule turns positions and
angles by the same Cayley rotation). No body's F_int has a resultant, so a body in free
flight keeps its momentum exactly and, on a frictionless plane, its momentum along the
plane. Nor has it a moment (the beam: Beam.discrete_gradient, after Simo, Tarnow & Doblare
1995; a finite-strain continuum: the discrete gradient in the Green strain,
Continuum.discrete_gradient): a ring in free flight keeps its angular momentum exactly. The
small-strain linear material is the exception: its energy changes under a finite rotation,
so R(u_mid) (for it the midpoint rule, the trapezoidal rule of Newmark 1/2, 1/4: only the
contact force differs from it) has a moment.

Newton's tangent is exact: 2 M D / dt^2 (D = d dq / d u_1, 1 + phi^2 / 4 on an angle) plus the
bodies' tangents of their discrete gradients, plus X times the contacts' and loads' tangents
with the derivative of X on the diagonal.
"""

import numpy as np

from .. import lazy
from ..bodies.discrete_gradient import cayley
from .estimate import MIDPOINT
from .newmark import increment, inertia_roundoff
from .newton import newton
from .system import Evaluation

sp = lazy.module("scipy.sparse")


class EnergyConsistent:
    """Energy-consistent implicit stepper (module docstring) of a System whose contacts are
    built with ``integration="energy_consistent"`` and whose bodies are hyperelastic.
    ``newton_options`` go to ``newton``."""

    dynamic = True
    error_model = MIDPOINT  # how its step errs (estimate.py)

    def __init__(self, system, **newton_options):
        self.system, self.newton_options = system, newton_options
        self.rotations = np.concatenate(
            [system.offset(b) + np.asarray(b.rotation_dofs, dtype=int) for b in system.bodies] + [np.zeros(0, int)]
        )
        for c in system.contacts:
            if c.integration != "energy_consistent":
                raise ValueError(
                    f"contact {c.name!r}: energy-consistent time stepping needs contacts built with "
                    "integration='energy_consistent'"
                )
        for b in system.bodies:
            if not b.hyperelastic:
                raise ValueError(
                    f"body {b.name!r}: energy-consistent integration needs hyperelastic bodies "
                    "(use contact_integration=standard for the viscoplastic ring)"
                )

    def _bodies(self, u0, u1):
        """Every body's discrete gradient (its ``discrete_gradient``) placed in the global vector,
        as (G, rows, cols, vals)."""
        s = self.system
        G = np.zeros(s.ndof)
        rows, cols, vals = [], [], []
        for b in s.bodies:
            off = s.offset(b)
            sl = slice(off, off + b.ndof)
            F, r, c, v = b.discrete_gradient(u0[sl], u1[sl])
            G[sl] += F
            rows.append(np.asarray(r, int) + off), cols.append(np.asarray(c, int) + off)
            vals.append(np.asarray(v, float))
        return G, rows, cols, vals

    def step(self, t, u, v, a, dt, label="", *, state):
        assert dt > 0, "a step's size comes from its Schedule, which checks it"
        s = self.system
        t1, tm = t + dt, t + 0.5 * dt
        M = s.mass()  # lumped (a vector) or consistent (a sparse matrix)
        c_mass = 2.0 / dt**2
        m = s.lumped_mass()

        def inertia(D):  # d (c_mass M (dq - dt v)) / d u1 = c_mass M diag(D)
            return sp.diags(c_mass * M * D) if isinstance(M, np.ndarray) else c_mass * (M @ sp.diags(D))

        rot = self.rotations

        def fun(d):  # d = u1 - u, Newton's unknown (newton's base: round-off of d, not of u1)
            u1 = s.apply_dirichlet(u + d, t1)
            dq, D, chord, dchord = cayley(d, rot)
            G, rows, cols, vals = self._bodies(u, u1)
            um = u + 0.5 * d
            states = []
            # the contacts and loads, conjugate to d: on an angle, their moment times chord is
            # conjugate to dq (chord dq = d there); the derivative of chord on the diagonal
            Gc, rows_c, cols_c, vals_c = np.zeros(s.ndof), [], [], []
            for ct, h in zip(s.contacts, state.contacts):
                cs = ct.evaluate(u1, t1, dt, u, history=h, offsets=s.offsets)
                Rc, r, c, vv = cs.scatter(s.ndof)
                states.append(cs)
                Gc += Rc
                (
                    rows_c.append(np.asarray(r, int)),
                    cols_c.append(np.asarray(c, int)),
                    vals_c.append(np.asarray(vv, float)),
                )
            Pm = np.zeros(s.ndof)
            for load, ls in zip(s.loads, state.loads):
                P, r, c, vv = load.assemble(um, tm, ls, offsets=s.offsets)
                Gc -= P
                Pm += P
                rows_c.append(np.asarray(r, int)), cols_c.append(np.asarray(c, int))
                vals_c.append(-0.5 * np.asarray(vv, float))
            G += chord * Gc
            rows += rows_c + [rot]
            cols += cols_c + [rot]
            vals += [vv * chord[r] for r, vv in zip(rows_c, vals_c)] + [dchord * Gc[rot]]
            ma = s.mass_times(c_mass * (dq - dt * v))
            G += ma
            K = sp.coo_matrix(
                (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(s.ndof, s.ndof)
            ).tocsr() + inertia(D)
            return Evaluation(G, K, tuple(states), Pm, state, ma, inertia_roundoff(m, c_mass, dq, dt * v))

        result = newton(
            fun,
            increment(s, u, dt * v + 0.5 * dt**2 * a, t1),
            s.free_dofs,
            instrument=s.instrument,
            label=label or f"t = {t1:.6g}, dt = {dt:.3g}",
            base=u,
            **self.newton_options,
        )
        d = result.u
        u1 = s.apply_dirichlet(u + d, t1)
        result.evaluation = result.evaluation._replace(P=s.external_force(u1, t1, state))  # the loads' work
        v1 = 2.0 * cayley(d, rot)[0] / dt - v
        a1 = (v1 - v) / dt
        return u1, v1, a1, result
