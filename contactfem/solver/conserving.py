"""An energy-consistent time stepper for impacts: the midpoint rule with discrete
gradients (Gonzalez 1996) for the bodies and for the contact (contact/conserving.py,
Armero & Petocz 1998).

    contact = NodeToSegment(..., integration="energy_consistent")
    stepper = EnergyConsistent(System(bodies, [contact], ...))
    for rec in march(stepper, Steps(dt, n_steps=...), t0, u0, v0): ...

One step from (u_0, v_0) solves for u_1, with d = u_1 - u_0 and v_1 = 2 d / dt - v_0,

    M (v_1 - v_0) / dt + F_int + F_c - P(u_mid, t_mid) = 0,

    F_int = R(u_mid) + [(W(u_1) - W(u_0) - R(u_mid) . d) / (w . w)] w,   w = P d   per body,
    F_c   = the discrete gradient of the interface potential (contact/conserving.py),

so that d . F_int = W(u_1) - W(u_0) and d . F_c = the change of the interface energy plus
the frictional dissipation. P removes from the body's increment d its rigid translations
(``body.rigid_modes``), P = I - A (A^T A)^-1 A^T: W does not change under a translation, so
R(u_mid) has no resultant, and neither has the correction c w. Since the midpoint rule
changes the momentum by dt times the resultant force, a body in free flight keeps its
momentum exactly, and on a frictionless rigid plane its momentum along the plane. (The
correction along the whole increment d, as Gonzalez's discrete gradient is usually written,
has a resultant as soon as the body translates while it deforms: the centre of mass drifts.)
Angular momentum: R(u_mid) has no moment at the mid configuration (W does not change under
a rotation), the correction c w does, of the order of the energy mismatch the correction
removes; the midpoint rule alone (c = 0, a linear body) keeps it exactly. Keeping c w off
the rotation too would need the discrete gradient in the strain invariants (Simo & Tarnow
1992), see Beam.rigid_modes. With d = dt (v_0 + v_1) / 2 the kinetic energy changes by
-d . (F_int + F_c - P): the total energy kinetic + strain + interface changes by the work
of the loads minus the dissipation, exactly (to the Newton tolerance) -- whatever the
penalty c_N, the time step, and the phase within a step at which a node touches. For a
linear body the correction term vanishes (R is linear: the midpoint rule is the
trapezoidal rule of Newmark 1/2, 1/4) and only the contact force differs from it.

Newton's tangent is exact: 2 M / dt^2 + K(u_mid) / 2 plus the derivative of the correction
c w per body (dense over the body's dofs, only where c != 0: a linear body has c = 0, W is
quadratic), with the change of the rigid modes with u_mid, plus the exact contact tangent.
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
        self._dA = {}                   # per body: the derivative of its rigid modes (constant)
        for c in system.contacts:
            if c.integration != "energy_consistent":
                raise ValueError(f"contact {c.name!r}: energy-consistent time stepping needs contacts built with "
                                 "integration='energy_consistent'")
        for b in system.bodies:
            if not b.hyperelastic:
                raise ValueError(f"body {b.name!r}: energy-consistent integration needs hyperelastic bodies "
                                 "(use contact_integration=standard for the viscoplastic ring)")

    def _modes(self, b, um):
        """The body's rigid modes A at u_mid (n, k) and their derivative with respect to u_mid:
        A is affine in u (a rotation mode e3 x x), so dA/du is one constant (k, n, n) array,
        computed once per body from the modes at the unit vectors."""
        A = b.rigid_modes(um)
        key = id(b)
        if key not in self._dA:
            base = b.rigid_modes(np.zeros(b.ndof))
            self._dA[key] = np.stack([b.rigid_modes(e) - base for e in np.eye(b.ndof)], axis=2)   # (n, k, n)
        return A, self._dA[key]

    def _bodies(self, u0, u1):
        """Discrete-gradient internal forces of every body, as (G, rows, cols, vals), with their
        exact tangent (dense over the body's dofs where the correction acts):

            F = R(u_mid) + c w,  w = (I - Pi) d,  c = gap / (w . w),
            dF/du_1 = K(u_mid) / 2 + w (dc/du_1)^T + c dw/du_1,
            dw/du_1 = (I - Pi) - [(I - Pi) dA y + A (A^T A)^-1 dA^T w] / 2,

        Pi = A (A^T A)^-1 A^T the projector on the rigid modes A(u_mid), y = (A^T A)^-1 A^T d
        (the derivative of a projector), dc/du_1 = (dgap/du_1 - 2 c w^T dw/du_1) / (w . w),
        dgap/du_1 = R(u_1) - R(u_mid) - K(u_mid) d / 2."""
        import scipy.sparse as sp     # (imported here: listing the scenes loads no scipy)

        s = self.system
        G = np.zeros(s.ndof)
        rows, cols, vals = [], [], []
        um = 0.5 * (u0 + u1)
        for b in s.bodies:
            sl = slice(b.dof_offset, b.dof_offset + b.ndof)
            dofs = np.arange(b.ndof) + b.dof_offset
            R, K = b.internal(um[sl])
            d = (u1 - u0)[sl]
            W0, W1 = b.strain_energy(u0[sl]), b.strain_energy(u1[sl])
            A, dA = self._modes(b, um[sl])
            AtA_inv = np.linalg.inv(A.T @ A)
            y = AtA_inv @ (A.T @ d)
            w = d - A @ y                                        # d without its rigid motion
            gap = W1 - W0 - R @ d
            ww = w @ w
            # no correction for a quadratic energy (the midpoint rule is exact: gap = 0 up to the
            # rounding of R = K u, a sum of large cancelling terms when the body moves rigidly), nor
            # where the gap is at the rounding of W
            use = not b.quadratic_energy and ww > 0 and abs(gap) > 1e-13 * (abs(W0) + abs(W1))
            c = gap / ww if use else 0.0
            G[sl] += R + c * w
            K = sp.coo_matrix(K)
            rows.append(K.row + b.dof_offset)
            cols.append(K.col + b.dof_offset)
            vals.append(0.5 * K.data)
            if c != 0.0:
                n = b.ndof
                Pi = A @ AtA_inv @ A.T
                dAy = np.einsum("ikn,k->in", dA, y)               # (dA y) per direction du_mid
                dAtw = np.einsum("ikn,i->kn", dA, w)              # (dA^T w)
                dw = (np.eye(n) - Pi) - 0.5 * ((np.eye(n) - Pi) @ dAy + A @ AtA_inv @ dAtw)
                R1 = b.internal(u1[sl])[0]
                dc = (R1 - R - 0.5 * (K @ d) - 2.0 * c * (w @ dw)) / ww
                Z = np.outer(w, dc) + c * dw
                rows.append(np.repeat(dofs, n))
                cols.append(np.tile(dofs, n))
                vals.append(Z.ravel())
        return G, rows, cols, vals

    def step(self, t, u, v, a, dt, label=""):
        import scipy.sparse as sp

        _check_dt(dt)
        s = self.system
        t1, tm = t + dt, t + 0.5 * dt
        M = s.mass()                        # lumped (a vector) or consistent (a sparse matrix)
        Msp = sp.diags(M) if isinstance(M, np.ndarray) else M
        c = 2.0 / dt ** 2

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
            G += s.mass_times(c * (u1 - u - dt * v))
            K = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                              shape=(s.ndof, s.ndof)).tocsr() + c * Msp
            return Evaluation(G, K, tuple(states))

        guess = s.apply_dirichlet(u + dt * v + 0.5 * dt ** 2 * a, t1)
        result = newton(fun, guess, s.free_dofs, instrument=s.instrument, label=label or f"t = {t1:.6g}, dt = {dt:.3g}",
                        **self.newton_options)
        u1 = result.u
        result.evaluation = result.evaluation._replace(P=s.external_force(u1, t1))   # the loads' work
        v1 = 2.0 * (u1 - u) / dt - v
        a1 = (v1 - v) / dt
        return u1, v1, a1, result
