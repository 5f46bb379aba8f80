"""A contact interface: slave nodes of one body against a master, with their
friction history (paper Sec. 4.3, step 4: per slave node, check the gap -> normal
force -> trial friction -> slip check -> stick or return map -> tangents).

History (s_bar, t_T_bar, q_bar and the friction law's internal variables z_bar) is
committed only on a converged step (commit).

The closing step: a node open at the start of a step (committed gap g_bar > 0) that is in
contact at its end touched the master at the fraction theta = g_bar / (g_bar - g_N) of the
step (the gap interpolated linearly). Its stick spring starts there: the slip increment is
the travel after touching, Delta g_T = r (s - s_bar) with r = 1 - theta = -g_N / (g_bar - g_N),
not the whole travel of the step (which would load the spring with the tangential motion
made while still open). ``NodeToSegment.closing_step = False`` (per interface) drops the
rule, to study what it changes (the cork's exit time, lecture 08)."""

import numpy as np

from .element import contact_element, to_coo
from ..laws.friction import Frictionless
from ..laws.protocol import as_friction_law
from ..laws.return_map import STATE_NAMES, return_map

FRICTIONLESS = as_friction_law(Frictionless())


def tributary_lengths(X):
    """Half the length of the two neighbouring edges of each node of an ordered chain X (n, 2)."""
    L = np.linalg.norm(np.diff(np.asarray(X, dtype=float), axis=0), axis=1)
    w = np.zeros(len(X))
    w[:-1] += L / 2
    w[1:] += L / 2
    return w


class NodeToSegment:
    """Node-to-segment frictional contact of `nodes` of `slave` (a body) on `master`.

    normal:   a normal law (t_N(g_N), e.g. PowerLaw, eq 4)
    friction: a friction law (c_T and slip_bound, eqs 5, 10) or None (frictionless)
    weights:  per-slave weight multiplying the tractions into nodal forces: a
              tributary length when the laws are tractions per unit length
              (the block, Sec. 5.1), 1 when c_N, c_T are nodal stiffnesses (rings, cork)
    offset:   the slave surface lies `offset` beyond the node along the master normal
              (half the thickness of a beam whose centreline nodes are the slaves)

    A friction law with a slip rate or internal variables (contactfem.laws.protocol)
    gets the time step from ``set_dt`` (called by every stepper) and keeps its
    variables z_bar per slave node; a law with ``gap_offset(z)`` (wear) moves the
    surface by the committed z_bar (the wear of a step acts from the next step on).
    """

    closing_step = True     # the closing step of the module docstring; False: the whole travel

    def __init__(self, slave, nodes, master, normal, friction=None, weights=1.0, offset=0.0, name="contact"):
        self.slave, self.master, self.normal, self.friction, self.name = slave, master, normal, friction, name
        self.nodes = np.asarray(nodes, dtype=int)
        self.weights = np.broadcast_to(np.asarray(weights, dtype=float), self.nodes.shape).copy()
        if np.any(self.weights <= 0):
            raise ValueError("parameter weights must be positive (tributary lengths or 1)")
        self.offset = float(offset)
        nc = len(self.nodes)
        self.s_bar = None                   # set at the first evaluation (or initialize)
        self.g_bar = None                   # committed gap (the closing step, module docstring)
        self.t_T_bar = np.zeros(nc)
        self.q_bar = np.zeros(nc)
        self._law = None if friction is None else as_friction_law(friction)
        self.z_bar = self._law.initial_state(nc) if self._law is not None else np.zeros((nc, 0))
        self.dt = None                      # time step, for rate- and state-dependent laws
        self.dissipation = 0.0              # of the last committed step
        self.dissipation_total = 0.0

    def set_dt(self, dt):
        """The step size of the coming step (slip rate = slip increment / dt)."""
        self.dt = float(dt)

    # -- kinematics -------------------------------------------------------------
    def slave_dofs(self):
        """Global (u_x, u_y) dofs of the slave nodes, (nc, 2); kept while the slave body
        stays at the same place in the global vector."""
        offset = self.slave.dof_offset
        if getattr(self, "_dofs_at", None) != offset:
            self._dofs, self._dofs_at = offset + self.slave.xdofs[self.nodes], offset
            self._X_s = self.slave.X[self.nodes]
        return self._dofs

    def slave_positions(self, u):
        dofs = self.slave_dofs()
        return self._X_s + u[dofs]

    def initialize(self, u):
        """Take the projections at u as the reference for the first slip increment."""
        x_s = self.slave_positions(u)
        s0 = np.zeros(len(self.nodes))
        self.s_bar = self.master.locate(x_s, s0, u)["s"]
        self.g_bar = None
        self.g_bar = self.kinematics(u)["g_N"]

    def kinematics(self, u):
        """Gap, normal traction and variations at u (step 4a-b of Sec. 4.3), before friction."""
        if self.s_bar is None:
            self.initialize(u)
        x_s = self.slave_positions(u)
        k = self.master.locate(x_s, self.s_bar, u)
        g_N = k["g_N"] - self.offset
        if self._law is not None and self._law.n_state:
            g_N = g_N + self._law.gap_offset(self.z_bar)    # worn surface: the gap opens
        active = k["inside"] & (g_N < 0.0)
        t_N, dt_N = self.normal.traction(np.where(active, g_N, 1.0))
        dofs = np.concatenate([self.slave_dofs(), k["master_dofs"]], axis=1) if k["master_dofs"].size else self._dofs
        travel = k["s"] - self.s_bar
        r, dr, ddg_T = np.ones_like(g_N), np.zeros_like(g_N), k["ds"]
        if self.closing_step and self.g_bar is not None:    # the closing step (module docstring)
            closing = active & (self.g_bar > 0.0)
            if np.any(closing):
                gb = np.where(closing, self.g_bar, 1.0)
                r = np.where(closing, -g_N / (gb - g_N), 1.0)
                dr = np.where(closing, -gb / (gb - g_N) ** 2, 0.0)
                ddg_T = r[:, None] * k["ds"] + (travel * dr)[:, None] * k["dg_N"]
        return dict(k, x_s=x_s, g_N=g_N, active=active, t_N=t_N, dt_N=dt_N, dg_T=r * travel, travel=travel,
                    r=r, dr=dr, ddg_T=ddg_T, dofs=dofs)

    def evaluate(self, u):
        """Everything at displacement u with the committed history: kinematics,
        tractions, return mapping, element residuals and tangents."""
        e = self.kinematics(u)
        if self.friction is None:
            z = np.zeros_like(e["t_N"])
            fr = return_map(FRICTIONLESS, e["t_N"], e["dt_N"], z, z, self.q_bar)
        else:
            fr = return_map(self._law, e["t_N"], e["dt_N"], e["dg_T"], self.t_T_bar, self.q_bar,
                            z_bar=self.z_bar, dt=self.dt)
        return self.element(e, fr.t_T, fr.c_T_s, fr.c_N_s, friction=fr)

    def element(self, e, t_T, c_T_s, c_N_s, **extra):
        """Add the element residuals and tangents (eqs 28, 33, 39, 49) of the active pairs
        to the kinematics e (an open pair contributes nothing: R and K hold active pairs only)."""
        on = e["active"]
        ddg_T = e.get("ddg_T")
        R, K = contact_element(self.weights[on], e["t_N"][on], e["dt_N"][on], t_T[on], c_T_s[on], c_N_s[on],
                               e["dg_N"][on], e["d2g_N"][on], e["ds"][on], e["d2s"][on],
                               None if ddg_T is None else ddg_T[on])
        return dict(e, R=R, K=K, **extra)

    @staticmethod
    def scatter(e, ndof):
        """Global residual and COO triplets of the active pairs of an evaluation e."""
        dofs = e["dofs"][e["active"]]
        R_c = np.bincount(dofs.ravel(), e["R"].ravel(), minlength=ndof)
        rows, cols, vals = to_coo(dofs, e["K"])
        return R_c, rows, cols, vals

    # -- the contact interface used by the solver -------------------------------
    def assemble(self, u):
        """Global contact residual R_c (eq 28) and tangent triplets (eqs 33, 39, 49)."""
        return self.scatter(self.evaluate(u), len(u))

    def commit(self, u):
        """Accept u as converged: store t_T, accumulated slip and the projection."""
        e = self.evaluate(u)
        fr = e["friction"]
        # energy dissipated in the step: the trapezoidal work of the traction on the slip,
        # 1/2 (t_T_bar + t_T) dg_T^s with dg_T^s = lambda sign(t_T) (eq 45). It balances
        # the trapezoidal energy bookkeeping of the time integrator; the return map's
        # lambda |t_T| (FrictionState.dissipation, >= 0) is the algorithmic measure.
        slip_work = 0.5 * (self.t_T_bar + fr.t_T) * fr.lam * np.sign(fr.t_T)
        self.dissipation = float(np.sum(self.weights * slip_work))
        self.dissipation_total += self.dissipation
        self.t_T_bar = np.where(e["active"], fr.t_T, 0.0)
        self.q_bar = fr.q
        if fr.z is not None and self._law is not None:
            self.z_bar = fr.z
        if hasattr(self.master, "commit"):
            self.master.commit(u)           # new converged metric l_bar of a deformable master
        self.s_bar = self.master.locate(e["x_s"], self.s_bar, u)["s"]
        self.g_bar = self.kinematics(u)["g_N"]

    def energy(self, u):
        """Energy stored in the interface: the normal law's potential plus the elastic
        tangential (stick) spring t_T^2 / (2 c_T)."""
        e = self.evaluate(u)
        g = np.where(e["active"], e["g_N"], 1.0)
        W_N = self.normal.energy(g) if hasattr(self.normal, "energy") else np.zeros_like(g)
        W_T = 0.0
        if self.friction is not None and self.friction.c_T > 0:
            W_T = e["friction"].t_T ** 2 / (2.0 * self.friction.c_T)
        return float(np.sum(self.weights * (W_N + W_T)))

    def report(self, u):
        """Per slave node: reference and current position, gap, tractions, forces, state."""
        e = self.evaluate(u)
        fr = e["friction"]
        return dict(X=self.slave.X[self.nodes], x=e["x_s"], g_N=e["g_N"], t_N=e["t_N"], t_T=fr.t_T,
                    f_N=self.weights * e["t_N"], f_T=self.weights * fr.t_T, n=e["n"], t=e["t"],
                    state=STATE_NAMES[fr.state], seg=e["seg"], weights=self.weights)
