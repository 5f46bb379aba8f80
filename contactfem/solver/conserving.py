"""An energy-consistent time stepper for impacts: the midpoint rule with discrete
gradients (Gonzalez 1996) for the bodies and for the contact (contact/conserving.py,
Armero & Petocz 1998).

    contact = NodeToSegment(..., integration="energy_consistent")
    stepper = EnergyConsistent(System(bodies, [contact], ...))
    for rec in march(stepper, Steps(dt, n_steps=...), t0, u0, v0): ...

One step from (u_0, v_0) solves for u_1, with d = u_1 - u_0 and v_1 = 2 d / dt - v_0,

    M (v_1 - v_0) / dt + F_int + F_c - P(u_mid, t_mid) = 0,

    F_int = R(u_mid) + [(W(u_1) - W(u_0) - R(u_mid) . d) / (d . d)] d     per body,
    F_c   = the discrete gradient of the interface potential (contact/conserving.py),

so that d . F_int = W(u_1) - W(u_0) and d . F_c = the change of the interface energy plus
the frictional dissipation. With d = dt (v_0 + v_1) / 2 the kinetic energy changes by
-d . (F_int + F_c - P): the total energy kinetic + strain + interface changes by the work
of the loads minus the dissipation, exactly (to the Newton tolerance) -- whatever the
penalty c_N, the time step, and the phase within a step at which a node touches. For a
linear body the correction term vanishes (R is linear: the midpoint rule is the
trapezoidal rule of Newmark 1/2, 1/4) and only the contact force differs from it.

Newton's tangent: 2 M / dt^2 + K(u_mid) / 2 + c I per body (c the bracket above) plus the
exact contact tangent; the rank-one part d (dc/du_1)^T of the bodies' correction (dense)
is left out, so Newton converges linearly at a rate of order |d| times the third
derivative of W over M / dt^2 (a few iterations more on the nonlinear beam ring; none on
a linear body).
"""
import numpy as np

from .newmark import _check_dt
from .newton import newton
from .system import Evaluation


class EnergyConsistent:
    """Energy-consistent implicit stepper (module docstring) of a System whose contacts are
    built with ``integration="energy_consistent"`` and whose bodies are hyperelastic.
    ``newton_options`` go to ``newton``."""
    dynamic = True

    def __init__(self, system, **newton_options):
        self.system, self.newton_options = system, newton_options
        for c in system.contacts:
            if c.integration != "energy_consistent":
                raise ValueError(f"contact {c.name!r}: energy-consistent time stepping needs contacts built with "
                                 "integration='energy_consistent'")
        for b in system.bodies:
            if not b.hyperelastic:
                raise ValueError(f"body {b.name!r}: energy-consistent integration needs hyperelastic bodies "
                                 "(use contact_integration=standard for the viscoplastic ring)")

    def _bodies(self, u0, u1):
        """Discrete-gradient internal forces of every body, as (G, rows, cols, vals)."""
        import scipy.sparse as sp     # (imported here: listing the scenes loads no scipy)

        s = self.system
        G = np.zeros(s.ndof)
        rows, cols, vals = [], [], []
        um = 0.5 * (u0 + u1)
        for b in s.bodies:
            sl = slice(b.dof_offset, b.dof_offset + b.ndof)
            R, K = b.internal(um[sl])
            d = (u1 - u0)[sl]
            W0, W1 = b.strain_energy(u0[sl]), b.strain_energy(u1[sl])
            gap = W1 - W0 - R @ d
            dd = d @ d
            c = gap / dd if (dd > 0 and abs(gap) > 1e-13 * (abs(W0) + abs(W1))) else 0.0
            G[sl] += R + c * d
            K = sp.coo_matrix(K)
            rows += [K.row + b.dof_offset, np.arange(b.ndof) + b.dof_offset]
            cols += [K.col + b.dof_offset, np.arange(b.ndof) + b.dof_offset]
            vals += [0.5 * K.data, np.full(b.ndof, c)]
        return G, rows, cols, vals

    def step(self, t, u, v, a, dt, label=""):
        _check_dt(dt)
        s = self.system
        t1, tm = t + dt, t + 0.5 * dt
        M = s.mass()
        c = 2.0 / dt ** 2

        import scipy.sparse as sp

        def fun(u1):
            s.evaluations += 1
            G, rows, cols, vals = self._bodies(u, u1)
            um = 0.5 * (u + u1)
            states = []
            for ct in s.contacts:
                state = ct.evaluate(u1, t1, dt, u)
                Rc, r, cc, vv = state.scatter(s.ndof)
                states.append(state)
                G += Rc
                rows.append(np.asarray(r, int)), cols.append(np.asarray(cc, int)), vals.append(np.asarray(vv, float))
            for load in s.loads:
                P, r, cc, vv = load.assemble(um, tm)
                G -= P
                rows.append(np.asarray(r, int)), cols.append(np.asarray(cc, int))
                vals.append(-0.5 * np.asarray(vv, float))
            G += M * c * (u1 - u - dt * v)
            K = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                              shape=(s.ndof, s.ndof)).tocsr() + sp.diags(c * M)
            return Evaluation(G, K, tuple(states))

        guess = s.apply_dirichlet(u + dt * v + 0.5 * dt ** 2 * a, t1)
        result = newton(fun, guess, s.free_dofs, instrument=s.instrument, label=label or f"t = {t1:.6g}, dt = {dt:.3g}",
                        **self.newton_options)
        u1 = result.u
        result.evaluation = result.evaluation._replace(P=s.external_force(u1, t1))   # the loads' work
        v1 = 2.0 * (u1 - u) / dt - v
        a1 = (v1 - v) / dt
        return u1, v1, a1, result
