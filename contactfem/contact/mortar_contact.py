"""Mortar contact of a slave surface on a master, with its history (beyond the paper:
segment-to-segment instead of the paper's node-to-segment; the kernel is
contact/mortar.py, the segmentation contact/segmentation.py).

The protocol (tentative, as the solver's contact protocol is being settled):

    h = contact.start(u, t)                the history of the initial state (a value)
    state = contact.evaluate(u, t, dt, history=h)   pure: a frozen MortarState
    h = contact.commit(state)              the history after it (the contact keeps nothing)

A converged step is evaluated once; what is recorded reads that state, and commit takes
the history it carries (no re-evaluation).
"""

from dataclasses import dataclass

import numpy as np

from .masters import BodySurface, RigidLine, RigidPolyline
from .placement import start_of
from .mortar import (
    Pairs,
    contact_forces,
    linear_slip,
    linearised,
    mortar_integrals,
    nodal_gap,
    penalty_tractions,
    slip_increment,
    weighted_slip,
)
from .segmentation import candidate_pairs
from ..laws.protocol import as_friction_law
from ..laws.return_map import SLIP, STATE_NAMES


KINEMATICS = ("finite", "small")


@dataclass(frozen=True)
class MortarHistory:
    """What a step starts from, per slave node: the tangential traction t_T, the
    accumulated slip q and the friction law's internal variables z (n, k) at the end of
    the last converged step; the converged pairs with their mortar integrals D, M
    (np, 2, 2) (the reference of the slip: the master points each slave point faced),
    the converged nodal weights w and interface positions x (small kinematics: the pairs,
    D, M and w of the reference configuration, and x the reference of the slip)."""

    t_T: np.ndarray
    q: np.ndarray
    z: np.ndarray
    pairs: Pairs
    D: np.ndarray
    M: np.ndarray
    w: np.ndarray
    x: np.ndarray | None = None  # the interface positions (slave, master) of the converged state


@dataclass(frozen=True)
class MortarState:
    """One evaluation at (u, t), per slave node (in the order of ``nodes``):

    X, x (ns, 2) reference and current positions, g_N average gap (+inf where no master faces the node), t_N, t_T
    nodal tractions (per unit length), dt_N = dt_N/dg_N, and the return map's c_T_s, c_N_s
    (eq 48), lam (slip of the step), q (accumulated slip), z (the law's variables),
    state (OPEN 0, STICK 1, SLIP 2; laws/return_map),
    weights w (the covered length of each node, int N_j), dg_T the slip increment of
    the step; the global residual R (len(u)) and tangent triplets (rows, cols, vals)
    (repeated indices add up); the history that commit() takes; the mortar integrals
    (pairs, D, M, ...: contact/mortar.py) for inspection.

    energy: sum_j w_j (W_N(g_N,j) + t_T,j^2 / (2 c_T)), the normal law's potential and
    the stick spring, as node-to-segment reports it (the mortar forces are the virtual
    work of the tractions, not this energy's exact gradient); dissipation: the slip work
    of the step, sum_j w_bar_j (t_T_bar,j + t_T,j)/2 lambda_j sign(t_T,j) (trapezoidal,
    lambda the return map's slip, per unit length of the converged weight w_bar)."""

    t: float
    dt: float
    nodes: np.ndarray
    X: np.ndarray
    x: np.ndarray
    g_N: np.ndarray
    t_N: np.ndarray
    dt_N: np.ndarray
    t_T: np.ndarray
    c_T_s: np.ndarray
    c_N_s: np.ndarray
    lam: np.ndarray
    q: np.ndarray
    z: np.ndarray
    state: np.ndarray
    weights: np.ndarray
    dg_T: np.ndarray
    R: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    vals: np.ndarray
    history: MortarHistory
    integrals: object
    energy: float
    dissipation: float

    @property
    def n_pairs(self):
        return len(self.integrals.pairs)

    # -- what the solver reads (the names of contact/state.py's ContactState) -------------
    def scatter(self, ndof):
        """The global contact residual (ndof,) and the tangent's COO triplets."""
        if ndof != len(self.R):
            raise ValueError(f"scatter: the state was evaluated with {len(self.R)} dofs, asked for {ndof}")
        return self.R, self.rows, self.cols, self.vals

    @property
    def next_history(self):
        """The history a commit of this state keeps."""
        return self.history

    @property
    def slip(self):
        """OPEN/STICK/SLIP per slave node (= state; the name ContactState uses)."""
        return self.state

    @property
    def n_active(self):
        """Slave nodes in contact."""
        return int(np.count_nonzero(self.t_N < 0.0))

    @property
    def n_slip(self):
        """Slave nodes slipping in this step."""
        return int(np.count_nonzero(self.state == SLIP))

    def report(self):
        """Per slave node: reference and current position, average gap, tractions, nodal
        force measures f = w t (the weights are the covered lengths), state names."""
        return dict(
            X=self.X,
            x=self.x,
            g_N=self.g_N,
            t_N=self.t_N,
            t_T=self.t_T,
            f_N=self.weights * self.t_N,
            f_T=self.weights * self.t_T,
            state=STATE_NAMES[self.state],
            weights=self.weights,
        )


class MortarContact:
    """Mortar contact (penalty) of the chain ``slave_nodes`` of ``slave_body`` on ``master``.

    slave_nodes: ordered so that n = e3 x t points out of the slave body (as the masters'
                 nodes are ordered, contact/masters.py)
    master:      BodySurface (deformable, its nodes carry unknowns), RigidPolyline, or
                 RigidLine (an unbounded straight line)
    normal:      a normal law (t_N(g_N), eq 4: PowerLaw(c_N) is the penalty with c_N a
                 traction per unit gap, per unit length)
    friction:    a friction law (c_T and slip_bound, eqs 5, 10, 11) or None (frictionless)
    offset:      the slave surface lies ``offset`` beyond the chain along its normal
                 (a positive offset closes the gap; per node or one number)
    search:      pairs farther apart than this are not formed (default: all facing pairs)
    kinematics:  finite (default) or small (contact/mortar.py). ``finite``: segmentation,
                 mortar integrals and normals of the current configuration, with their exact
                 linearisation: the contact of large deformation. ``small``: all of them held
                 at the reference configuration, gap and slip linear in u: the contact that
                 matches a small-strain (``material = linear``) bulk, whose stresses and dead
                 loads live on the reference configuration too. With ``finite`` next to a
                 linear bulk the tractions act on a surface that has stretched while the bulk
                 has not, an inconsistency of the order of the strain along the surface (the
                 patch test with nu = 0.3 deviates by ~4e-4 of p); with ``small`` the patch
                 test holds to round-off. Scenes choose it from their material.
    """

    integration = "standard"  # (no energy-consistent variant)
    unknowns = 0  # penalty: no unknowns of its own (contact/interfaces.py)

    def __init__(
        self,
        slave_body,
        slave_nodes,
        master,
        *,
        normal,
        friction=None,
        offset=0.0,
        search=np.inf,
        kinematics="finite",
        name="mortar",
    ):
        if kinematics not in KINEMATICS:
            raise ValueError(f"parameter kinematics = {kinematics!r} is not allowed: one of {'|'.join(KINEMATICS)}")
        self.kinematics = kinematics
        self.slave, self.master, self.normal, self.friction, self.name = slave_body, master, normal, friction, name
        self.nodes = np.asarray(slave_nodes, dtype=int)
        if self.nodes.ndim != 1 or len(self.nodes) < 2:
            raise ValueError("parameter slave_nodes must list at least 2 nodes of the slave body (a chain)")
        if np.any(np.linalg.norm(np.diff(slave_body.X[self.nodes], axis=0), axis=1) <= 0.0):
            raise ValueError("parameter slave_nodes has a zero-length segment: two consecutive nodes coincide")
        if not isinstance(master, (BodySurface, RigidPolyline, RigidLine)):
            raise ValueError(
                f"parameter master must be a BodySurface, RigidPolyline or RigidLine for mortar "
                f"contact, got {type(master).__name__} (approximate a curved obstacle by a RigidPolyline)"
            )
        if not (np.isfinite(search) or search == np.inf) or not search > 0:
            raise ValueError(f"parameter search = {search!r} is out of range: allowed (0, inf]")
        offset = np.asarray(offset, dtype=float)
        if offset.shape not in ((), self.nodes.shape) or not np.all(np.isfinite(offset)):
            raise ValueError(f"parameter offset must be a finite number or one per slave node, got {offset!r}")
        self.offset = np.broadcast_to(offset, self.nodes.shape).copy()
        self.search = float(search)
        self.unbounded = isinstance(master, RigidLine)
        self._law = None if friction is None else as_friction_law(friction)
        self._reference = None  # small kinematics: the integrals of the reference configuration

    # -- where the interface's unknowns are ----------------------------------------
    def slave_dofs(self, offsets=None):
        """Global (u_x, u_y) dofs of the slave nodes (ns, 2), the body placed by ``offsets``
        (a System's: placement.py)."""
        return start_of(self.slave, offsets) + self.slave.xdofs[self.nodes]

    def master_dofs(self, offsets=None):
        """Global dofs of the master nodes (nm, 2); -1 for a rigid master's fixed points."""
        if isinstance(self.master, BodySurface):
            return self.master.dofs(offsets)
        return np.full((len(self._master_points()), 2), -1)

    def _master_points(self):
        if isinstance(self.master, RigidLine):  # two points of the line, n = e3 x t
            n = self.master.normal
            return np.array([self.master.point, self.master.point + np.array([n[1], -n[0]])])
        return self.master.points

    def positions(self, u, offsets=None):
        """Current slave chain xs (ns, 2) and master chain xm (nm, 2)."""
        xs = self.slave.X[self.nodes] + u[self.slave_dofs(offsets)]
        xm = self.master.positions(u, offsets) if isinstance(self.master, BodySurface) else self._master_points()
        return xs, xm

    # -- the protocol --------------------------------------------------------------
    def start(self, u, t=0.0, *, offsets=None):
        """The history of the state u: no traction, no slip, the pairs of u as the
        reference of the first step's slip (small kinematics: the pairs of the reference
        configuration, computed here once). ``offsets``: where the bodies' dofs start in u."""
        xs, xm = self.positions(u, offsets)
        if self.kinematics == "small":
            zero = np.zeros(len(u))
            self._reference = self._integrals(*self.positions(zero, offsets))
        mi = self._integrals(xs, xm) if self.kinematics == "finite" else self._reference
        ns = len(self.nodes)
        z = self._law.initial_state(ns) if self._law is not None else np.zeros((ns, 0))
        return MortarHistory(
            t_T=np.zeros(ns),
            q=np.zeros(ns),
            z=z,
            pairs=mi.pairs,
            D=mi.D,
            M=mi.M,
            w=mi.w,
            x=np.concatenate([xs.ravel(), xm.ravel()]),
        )

    def kinematics_at(self, u, h, offsets=None):
        """Segmentation, mortar integrals, nodal gaps and slip increments at u with the
        history h: a dict with xs, xm, x (the interface positions), mi (MortarIntegrals),
        offset, g_N, covered, dg_N (sparse, over the interface dofs), slip (WeightedSlip, None
        when frictionless) and dg_T (the nodal slip increments)."""
        xs, xm = self.positions(u, offsets)
        x = np.concatenate([xs.ravel(), xm.ravel()])
        mi = self._integrals(xs, xm) if self.kinematics == "finite" else linearised(self._reference, x)
        offset = self.offset
        if self._law is not None and self._law.n_state:
            offset = offset - self._law.gap_offset(h.z)  # a worn surface: the gap opens
        g_N, covered, dg_N = nodal_gap(mi, offset)
        slip, dg_T = None, np.zeros(len(self.nodes))
        if self.friction is not None:
            slip = weighted_slip(xs, xm, h.pairs, h.D, h.M) if self.kinematics == "finite" else linear_slip(mi, x, h.x)
            dg_T, _ = slip_increment(slip, h.w)
        return dict(xs=xs, xm=xm, x=x, mi=mi, offset=offset, g_N=g_N, covered=covered, dg_N=dg_N, slip=slip, dg_T=dg_T)

    def evaluate(self, u, t=0.0, dt=None, u0=None, phase=None, *, history, offsets=None):
        """Everything at u with the committed ``history``: segmentation, mortar integrals,
        tractions (penalty and return map), residual and tangent. Pure (u0 is not needed:
        the history holds the reference of the slip). ``phase``: the staggered algorithm's
        phases are not offered for mortar contact (None only). ``offsets``: placement.py."""
        h = self._check(phase, history)
        k = self.kinematics_at(u, h, offsets)
        mi, slip, g_N, dg_T = k["mi"], k["slip"], k["g_N"], k["dg_T"]
        t_N, dt_N, fr = penalty_tractions(
            self.normal, self.friction, g_N, dg_T, h.t_T, h.q, z_bar=h.z if self._law is not None else None, dt=dt
        )
        R_i, (r, c, v) = contact_forces(mi, t_N, dt_N, k["offset"], slip, fr if slip is not None else None, h.w)
        R, rows, cols, vals = self._to_global(R_i, r, c, v, len(u), offsets)
        z = fr.z if (self._law is not None and fr.z is not None) else h.z
        history = MortarHistory(t_T=fr.t_T, q=fr.q, z=z, pairs=mi.pairs, D=mi.D, M=mi.M, w=mi.w, x=k["x"])
        return MortarState(
            t=t,
            dt=dt,
            nodes=self.nodes,
            X=self.slave.X[self.nodes],
            x=k["xs"],
            g_N=g_N,
            t_N=t_N,
            dt_N=dt_N,
            t_T=fr.t_T,
            c_T_s=fr.c_T_s,
            c_N_s=fr.c_N_s,
            lam=fr.lam,
            q=fr.q,
            z=z,
            state=fr.state,
            weights=mi.w,
            dg_T=dg_T,
            R=R,
            rows=rows,
            cols=cols,
            vals=vals,
            history=history,
            integrals=mi,
            energy=self._energy(g_N, mi.w, fr.t_T),
            dissipation=float(np.sum(h.w * 0.5 * (h.t_T + fr.t_T) * fr.lam * np.sign(fr.t_T))),
        )

    def _check(self, phase, history):
        """The committed history, after the checks every evaluation makes."""
        if phase is not None:
            raise ValueError(f"{self.name}: mortar contact has no staggered phases (phase={phase!r})")
        if not isinstance(history, MortarHistory):
            raise ValueError(
                f"{self.name}: history must be a MortarHistory (from start(u) or commit(state)), "
                f"got {type(history).__name__}"
            )
        return history

    def commit(self, state):
        """The history after a converged state (the next step's); the contact keeps nothing."""
        return state.history

    # -- helpers -------------------------------------------------------------------
    def _energy(self, g_N, w, t_T):
        closed = g_N < 0.0
        W = np.zeros_like(g_N)
        if hasattr(self.normal, "energy"):
            W = np.where(closed, self.normal.energy(np.where(closed, g_N, 1.0)), 0.0)
        if self.friction is not None and self._law.c_T > 0:
            W = W + t_T**2 / (2.0 * self._law.c_T)
        return float(np.sum(w * W))

    def _integrals(self, xs, xm):
        s, m = candidate_pairs(xs, xm, self.unbounded, self.search)
        return mortar_integrals(xs, xm, Pairs.of(s, m, len(xs)), self.unbounded)

    def _to_global(self, R_i, r, c, v, ndof, offsets=None):
        """Interface dofs (slave nodes, then master nodes) to global dofs; a rigid
        master's rows and columns are dropped."""
        g = np.concatenate([self.slave_dofs(offsets).ravel(), self.master_dofs(offsets).ravel()])
        R = np.zeros(ndof)
        on = g >= 0
        np.add.at(R, g[on], R_i[on])
        rows, cols = g[r], g[c]
        keep = (rows >= 0) & (cols >= 0)
        return R, rows[keep], cols[keep], v[keep]
