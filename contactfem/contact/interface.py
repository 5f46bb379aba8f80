"""A contact interface: slave nodes of one body against a master, with their friction
history (paper Sec. 4.3, step 4: per slave node, check the gap -> normal force -> trial
friction -> slip check -> stick or return map -> tangents).

    contact = NodeToSegment(body, nodes, RigidLine(), normal=PowerLaw(c_N), friction=Coulomb(c_T, mu))
    history = contact.start(u0)                 # the history at the initial state (a value)
    state = contact.evaluate(u, t, dt, history=history)   # a ContactState (contact/state.py)
    R_c, rows, cols, vals = state.scatter(len(u))
    history = contact.commit(state)             # the history after a converged state

A contact holds its configuration only (body, nodes, master, laws, weights): ``evaluate`` is
a pure function of u and the ``history`` it is given (a ContactHistory value), and ``commit``
returns the next history without keeping it. The System carries the histories from step to
step in its SystemState (solver/system.py).

The closing step: a node open at the start of a step (committed gap g_bar > 0) that is in
contact at its end touched the master at the fraction theta = g_bar / (g_bar - g_N) of the
step (the gap interpolated linearly). Its stick spring starts there: the slip increment is
the travel after touching, Delta g_T = r (s - s_bar) with r = 1 - theta = -g_N / (g_bar - g_N),
not the whole travel of the step (which would load the spring with the tangential motion
made while still open). ``NodeToSegment(..., closing_step=False)`` drops the rule, to study
what it changes (the cork's exit time, lecture 08).

Strategies the contact is built with (not wrappers): ``tangent`` (contact/tangents.py: the
consistent tangent of eqs 33, 39, 49-50, or the symmetric and frozen variants the paper
compares) and ``integration`` (``standard``: the forces at the end of the step;
``energy_consistent``: the discrete-gradient force of the step, contact/conserving.py).
"""

import copy
from functools import lru_cache

import numpy as np

from ..laws.protocol import as_friction_law
from ..laws.return_map import OPEN, STICK, return_map
from .conserving import conserving_force
from .element import contact_element, normal_element, pattern, to_coo
from .placement import start_of
from .state import ContactHistory, ContactState
from .tangents import TANGENTS

INTEGRATIONS = ("standard", "energy_consistent")


@lru_cache(maxsize=16)
def ones(n):
    """n ones, made once per n and read-only (the closing-step factor r of nodes that did not close)."""
    a = np.ones(n)
    a.flags.writeable = False
    return a


@lru_cache(maxsize=16)
def zeros(n, dtype=float):
    """n zeros, made once per n and dtype and read-only."""
    a = np.zeros(n, dtype=dtype)
    a.flags.writeable = False
    return a


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
    tangent:  consistent | symmetric | frozen (contact/tangents.py)
    integration: standard | energy_consistent (module docstring)

    A friction law with a slip rate or internal variables (contactfem.laws.protocol) gets
    the step's dt from ``evaluate`` and keeps its variables z per slave node in the
    history; a law with ``gap_offset(z)`` (wear) moves the surface by the committed z
    (the wear of a step acts from the next step on).
    closing_step: True (default) for the closing step of the module docstring; False: the
              slip increment of a closing node is the whole travel of the step
    """

    unknowns = 0  # no unknowns of its own (contact/interfaces.py)

    def __init__(
        self,
        slave,
        nodes,
        master,
        *,
        normal,
        friction=None,
        weights=1.0,
        offset=0.0,
        name="contact",
        tangent="consistent",
        integration="standard",
        closing_step=True,
    ):
        if tangent not in TANGENTS:
            raise ValueError(f"parameter tangent = {tangent!r} is not allowed: one of {'|'.join(TANGENTS)}")
        if integration not in INTEGRATIONS:
            raise ValueError(f"parameter integration = {integration!r} is not allowed: one of {'|'.join(INTEGRATIONS)}")
        if integration == "energy_consistent" and not hasattr(normal, "energy"):
            raise ValueError(
                f"contact {name!r}: energy-consistent integration needs a normal law with a potential "
                "(an energy method)"
            )
        self.slave, self.master, self.normal, self.friction, self.name = slave, master, normal, friction, name
        self.tangent, self.integration = tangent, integration
        if not isinstance(closing_step, bool):
            raise ValueError(f"parameter closing_step = {closing_step!r} is not allowed: True or False")
        self.closing_step = closing_step
        self.nodes = np.asarray(nodes, dtype=int)
        self.weights = np.broadcast_to(np.asarray(weights, dtype=float), self.nodes.shape).copy()
        if np.any(self.weights <= 0):
            raise ValueError("parameter weights must be positive (tributary lengths or 1)")
        self.offset = float(offset)
        self._law = None if friction is None else as_friction_law(friction)
        self.c_T = 0.0 if self._law is None else self._law.c_T
        self._wear = self._law is not None and self._law.n_state > 0  # gap_offset(z) may move the surface
        self._straight = bool(getattr(master, "straight", False))  # zero second variations (masters.py)
        self._has_energy = hasattr(normal, "energy")
        self._X_s = self.slave.X[self.nodes]  # the slaves' reference positions

    def with_closing_step(self, closing_step):
        """A new contact of the same configuration with the closing step on (True) or off
        (False); this one is left as it is."""
        if not isinstance(closing_step, bool):
            raise ValueError(f"parameter closing_step = {closing_step!r} is not allowed: True or False")
        other = copy.copy(self)
        other.closing_step = closing_step
        return other

    def with_master(self, master):
        """A new contact of the same configuration against another master (e.g. the same
        obstacle at rest after a prescribed motion); this one is left as it is."""
        other = copy.copy(self)
        other.master = master
        other._straight = bool(getattr(master, "straight", False))
        return other

    # -- the history ------------------------------------------------------------------
    def start(self, u, t=0.0, *, offsets=None):
        """The history at the initial state u (a ContactHistory, kept by the caller): the
        projections there are the reference of the first slip increment, no traction, no slip,
        the law's initial variables. ``offsets``: where the bodies' dofs start in u (a System's:
        contact/placement.py)."""
        nc = len(self.nodes)
        ref = self.master.reference(u, offsets)
        k = self.master.locate(self.slave_positions(u, offsets), np.zeros(nc), u, t=t, ref=ref, offsets=offsets)
        z = self._law.initial_state(nc) if self._law is not None else np.zeros((nc, 0))
        g = k["g_N"] - self.offset + self.gap_offset(z)
        return ContactHistory(s_bar=k["s"], g_bar=g, t_T_bar=np.zeros(nc), q_bar=np.zeros(nc), z_bar=z, master=ref)

    def commit(self, state):
        """The history after a converged state (t_T, accumulated slip, law variables, the
        projection and the master's metric): ``state.next_history``; the contact keeps nothing."""
        return state.next_history

    # -- kinematics -------------------------------------------------------------------
    def slave_dofs(self, offsets=None):
        """Global (u_x, u_y) dofs of the slave nodes, (nc, 2), the body placed by ``offsets``."""
        return start_of(self.slave, offsets) + self.slave.xdofs[self.nodes]

    def slave_positions(self, u, offsets=None):
        return self._X_s + u[self.slave_dofs(offsets)]

    def gap_offset(self, z):
        """How far a friction law with internal variables has moved the surface (wear), (nc,)."""
        if not self._wear:
            return np.zeros(len(self.nodes))
        return self._law.gap_offset(z)

    def normal_energy(self, g_N):
        """The normal law's potential at g_N (0 for a law without one)."""
        return self.normal.energy(g_N) if self._has_energy else np.zeros_like(g_N)

    def kinematics(self, u, t, h, offsets=None):
        """Gap, normal traction and variations at u with the history h (step 4a-b of Sec. 4.3),
        before friction: a dict of per-node arrays."""
        x_s = self.slave_positions(u, offsets)
        k = self.master.locate(x_s, h.s_bar, u, t=t, ref=h.master, offsets=offsets)
        g_raw = k["g_N"] - self.offset
        g_N = g_raw + self.gap_offset(h.z_bar) if self._wear else g_raw
        active = k["inside"] & (g_N < 0.0)
        nc = len(g_N)
        touching = active.any()
        if touching:
            t_N, dt_N = self.normal.traction(np.where(active, g_N, 1.0))
        else:  # every node open (a body in flight): a normal
            t_N = dt_N = zeros(nc)  # law's t_N is 0 when open (read-only)
        slave_dofs = self.slave_dofs(offsets)
        dofs = np.concatenate([slave_dofs, k["master_dofs"]], axis=1) if k["master_dofs"].size else slave_dofs
        travel = k["s"] - h.s_bar
        r, dr, dg_T, ddg_T = ones(nc), zeros(nc), travel, k["ds"]  # r = 1: Delta g_T = travel (read-only)
        closing = (active & (h.g_bar > 0.0)).nonzero()[0] if self.closing_step and touching else ()
        if len(closing):  # the closing step (module docstring), at those nodes
            c, gb, g = closing, h.g_bar[closing], g_N[closing]
            r, dr = np.ones(nc), np.zeros(nc)
            r[c] = -g / (gb - g)
            dr[c] = -gb / (gb - g) ** 2
            dg_T = r * travel
            ddg_T = k["ds"].copy()
            ddg_T[c] = r[c, None] * k["ds"][c] + (travel[c] * dr[c])[:, None] * k["dg_N"][c]
        return dict(
            k,
            x_s=x_s,
            g_N=g_N,
            g_raw=g_raw,
            active=active,
            t_N=t_N,
            dt_N=dt_N,
            dg_T=dg_T,
            travel=travel,
            r=r,
            dr=dr,
            ddg_T=ddg_T,
            dofs=dofs,
        )

    # -- friction (eqs 40-48) -----------------------------------------------------------
    def predictor(self, h):
        """The traction the elastic predictor starts from (eq 42): the converged t_T_bar."""
        return h.t_T_bar

    def friction_state(self, k, h, dt, phase=None):
        """t_T, c_T^s, c_N^s and the return map's record at the kinematics k: frictionless,
        the return map of eqs 40-48, or a phase of the staggered algorithm (tangents.Phase)."""
        nc = len(k["g_N"])
        zero = zeros(nc)  # read-only
        if self._law is None:
            slip = np.where(k["t_N"] < 0.0, STICK, OPEN)
            return dict(t_T=zero, c_T_s=zero, c_N_s=zero, slip=slip, lam=zero, q=h.q_bar, z=h.z_bar)
        in_flight = not (k["t_N"] < 0.0).any()  # every node open: the return map's answer,
        if in_flight and phase is None and (dt is not None or not self._law.needs_dt):  # without calling it
            return dict(t_T=zero, c_T_s=zero, c_N_s=zero, slip=zeros(nc, int), lam=zero, q=h.q_bar, z=h.z_bar)
        if phase is not None and phase.kind == "normal":  # stick about the frozen state
            slip = np.where(k["t_N"] < 0.0, STICK, OPEN)
            return dict(
                t_T=phase.t_T + self.c_T * (k["s"] - phase.s),
                c_T_s=np.full(nc, self.c_T),
                c_N_s=zero,
                slip=slip,
                lam=zero,
                q=h.q_bar,
                z=h.z_bar,
                ddg_T=k["ds"],
            )
        if phase is not None:  # friction phase: the pressure frozen
            fr = return_map(self._law, -phase.p, zero, k["dg_T"], self.predictor(h), h.q_bar, z_bar=h.z_bar, dt=dt)
        else:
            fr = return_map(self._law, k["t_N"], k["dt_N"], k["dg_T"], self.predictor(h), h.q_bar, z_bar=h.z_bar, dt=dt)
        return dict(t_T=fr.t_T, c_T_s=fr.c_T_s, c_N_s=fr.c_N_s, slip=fr.state, lam=fr.lam, q=fr.q, z=fr.z)

    # -- one evaluation ------------------------------------------------------------------
    def evaluate(self, u, t=0.0, dt=None, u0=None, phase=None, *, history, offsets=None):
        """The ContactState at the trial displacement u of the step (t - dt, t] that starts
        from u0 (needed by energy-consistent integration), with the committed ``history`` (from
        ``start`` or ``commit``): kinematics, tractions, return mapping, element residuals and
        tangents. ``phase``: a phase of the staggered algorithm (contact/tangents.py), None for
        the contact as it is. ``offsets``: where the bodies' dofs start in u (placement.py)."""
        h = history
        if not isinstance(h, ContactHistory):
            raise ValueError(
                f"contact {self.name!r}: history must be a ContactHistory (from start(u) or "
                f"commit(state)), got {type(h).__name__}"
            )
        k = self.kinematics(u, t, h, offsets)
        fr = self.friction_state(k, h, dt, phase)
        work_T = None
        if self.integration == "energy_consistent" and u0 is not None:
            R, K, on, work_T = conserving_force(self, u0, u, t, h, k, fr, offsets)
            element_dofs = k["dofs"][on]
        else:
            on = k["active"].nonzero()[0]  # the pairs in contact, by index
            element_dofs = k["dofs"][on]
            if on.size:
                R, K = self.element(k, fr, on)
            else:  # none in contact (a body in flight): no element
                m = element_dofs.shape[1]
                R, K = np.zeros((0, m)), np.zeros((0, m, m))
        return ContactState(
            contact=self,
            history=h,
            u=u,
            t=t,
            offsets=offsets,
            x_s=k["x_s"],
            g_N=k["g_N"],
            g_raw=k["g_raw"],
            s=k["s"],
            s_next=k.get("s_next", k["s"]),
            n=k["n"],
            tangent=k["t"],
            seg=k["seg"],
            inside=k["inside"],
            active=k["active"],
            r=k["r"],
            t_N=k["t_N"],
            dt_N=k["dt_N"],
            t_T=fr["t_T"],
            c_T_s=fr["c_T_s"],
            c_N_s=fr["c_N_s"],
            slip=fr["slip"],
            lam=fr["lam"],
            q=fr["q"],
            z=fr["z"],
            R=R,
            K=K,
            element_dofs=element_dofs,
            work_T=work_T,
        )

    def element(self, k, fr, on):
        """The element residuals and tangents (eqs 28, 33, 39, 49-50) of the pairs `on` (a mask
        or their indices), with the tangent strategy the contact was built with (tangents.py).
        A straight rigid master has no second variations (line_variations): they are left out
        (None), the same element without adding zeros."""
        w = self.weights[on]
        d2g_N, d2s = (None, None) if self._straight else (k["d2g_N"][on], k["d2s"][on])
        if self._law is None:
            R, K = normal_element(w, k["t_N"][on], k["dt_N"][on], k["dg_N"][on], d2g_N)
        else:
            ddg_T = fr.get("ddg_T", k["ddg_T"])
            ddg_T = None if ddg_T is k["ds"] else ddg_T[on]  # None: d(Delta g_T) = ds
            c_N_s = fr["c_N_s"][on] if self.tangent != "frozen" else np.zeros(len(w))
            R, K = contact_element(
                w,
                k["t_N"][on],
                k["dt_N"][on],
                fr["t_T"][on],
                fr["c_T_s"][on],
                c_N_s,
                k["dg_N"][on],
                d2g_N,
                k["ds"][on],
                d2s,
                ddg_T,
            )
        if self.tangent == "symmetric":
            K = 0.5 * (K + K.transpose(0, 2, 1))
        return R, K

    def pattern(self, dofs):
        """The rows and cols of the element tangents at the pairs' dofs (m, k) (element.coo_indices,
        read-only): the same arrays as at the last call while the pairs in contact stay the same
        (``pattern``, contact/element.py), so that the System finds their places in K once per
        change of the contact set, not at every evaluation (assembly.py keeps them by identity)."""
        return pattern(dofs)

    # -- conveniences (tests, lectures) -------------------------------------------------
    def assemble(self, u, t=0.0, dt=None, u0=None, *, history, offsets=None):
        """Global contact residual R_c (eq 28) and tangent triplets (eqs 33, 39, 49) at u."""
        return self.evaluate(u, t, dt, u0, history=history, offsets=offsets).scatter(len(u))


def element_triplets(state):
    """COO triplets of a state's element tangents (rows, cols, vals)."""
    return to_coo(state.element_dofs, state.K)
