"""What a contact knows, as values: its committed history and the state of one evaluation.

    history = contact.start(u0)                # ContactHistory: what the next step starts from
    state = contact.evaluate(u, t, dt, history=history)   # ContactState at a trial u
    R_c, rows, cols, vals = state.scatter(ndof)   # its residual (eq 28) and tangent, assembled
    history = contact.commit(state)            # a converged state: its next_history

A ContactState is evaluated once per Newton iteration; the converged one is what energies,
reports, recordings and the commit read (``energy``, ``dissipation``, ``next_history`` are
computed from it on first use, never by evaluating the contact again).
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..laws.return_map import SLIP, STATE_NAMES


@dataclass(frozen=True)
class ContactHistory:
    """What a node-to-segment contact remembers from the last converged step (per slave node).

    s_bar    arc coordinate of the projection on the master (eq 20: Delta g_T = s - s_bar)
    g_bar    the gap there (the closing step: a node open at the start of a step)
    t_T_bar  tangential traction (the elastic predictor starts from it, eq 42)
    q_bar    accumulated slip (slip hardening: the cork)
    z_bar    the friction law's internal variables, (nc, k)
    master   what the master remembers: a deformable master's converged node positions
             (its metric l_bar of eq 20), None for a rigid one
    """

    s_bar: np.ndarray
    g_bar: np.ndarray
    t_T_bar: np.ndarray
    q_bar: np.ndarray
    z_bar: np.ndarray
    master: object = None


@dataclass(frozen=True, eq=False)
class ContactState:
    """One evaluation of a node-to-segment contact at a trial displacement u (per slave node,
    nc of them, unless said otherwise).

    Kinematics (eqs 17-27): x_s, g_N, s, n, t, seg, inside, active (in contact: the element
    acts), r (closing-step factor, 1 unless the node touched within the step).
    Tractions: t_N, dt_N (normal law, eq 4), and the return map's (eqs 40-48): t_T, c_T_s,
    c_N_s, slip (OPEN/STICK/SLIP), lam (slip increment), q, z (law variables after the step).
    Element (eqs 28, 33, 39, 49-50): R (m, k) and K (m, k, k) at the global dofs ``element_dofs``
    (m, k) of the m pairs that carry a force.
    """

    contact: object  # the contact that made it (laws, weights, master: read only)
    history: ContactHistory  # the history it was evaluated against
    u: np.ndarray  # the trial displacement (never modified afterwards)
    t: float
    x_s: np.ndarray
    g_N: np.ndarray
    g_raw: np.ndarray  # g_N without the friction law's gap offset (wear)
    s: np.ndarray
    s_next: np.ndarray  # s in the metric of this configuration (the next s_bar)
    n: np.ndarray
    tangent: np.ndarray
    seg: np.ndarray
    inside: np.ndarray
    active: np.ndarray
    r: np.ndarray
    t_N: np.ndarray
    dt_N: np.ndarray
    t_T: np.ndarray
    c_T_s: np.ndarray
    c_N_s: np.ndarray
    slip: np.ndarray
    lam: np.ndarray
    q: np.ndarray
    z: np.ndarray
    R: np.ndarray
    K: np.ndarray
    element_dofs: np.ndarray
    work_T: np.ndarray | None = None  # energy-consistent: the friction force's work over the step
    offsets: object = None  # where the bodies' dofs start in u (a System's: placement.py)

    # -- assembly ---------------------------------------------------------------------
    def scatter(self, ndof):
        """The global contact residual R_c (ndof,) and the tangent's COO triplets."""
        dofs = self.element_dofs
        if not dofs.size:  # no pair carries a force
            empty = np.zeros(0, dtype=int)
            return np.zeros(ndof), empty, empty, np.zeros(0)
        R_c = np.bincount(dofs.ravel(), self.R.ravel(), minlength=ndof)
        rows, cols = self.contact.pattern(dofs)
        return R_c, rows, cols, self.K.ravel()

    # -- what the converged state gives (computed on first use) -------------------------
    @cached_property
    def next_history(self):
        """The history a commit of this state keeps: t_T_bar = t_T where in contact, q, z,
        the projection s (in this configuration's metric) and the gap."""
        c = self.contact
        z = self.z
        g = self.g_raw + c.gap_offset(z)
        return ContactHistory(
            s_bar=self.s_next,
            g_bar=g,
            t_T_bar=np.where(self.active, self.t_T, 0.0),
            q_bar=self.q,
            z_bar=z,
            master=c.master.reference(self.u, self.offsets),
        )

    @property
    def weights(self):
        """(nc,) the contact's per-slave weights of the tractions (as a mortar state's own)."""
        return self.contact.weights

    @cached_property
    def energy(self):
        """Energy stored in the interface: the normal law's potential plus the elastic
        tangential (stick) spring t_T^2 / (2 c_T), summed with the weights."""
        c = self.contact
        W = c.normal_energy(np.where(self.active, self.g_N, 1.0))
        if c.c_T > 0.0:
            W = W + self.t_T**2 / (2.0 * c.c_T)
        return float((c.weights * W).sum())

    @cached_property
    def dissipation(self):
        """Frictional dissipation of the step that ends in this state.

        Standard: the trapezoidal work of the traction on the slip, 1/2 (t_T_bar + t_T)
        dg_T^s with dg_T^s = lambda sign(t_T) (eq 45); it balances the trapezoidal energy
        bookkeeping of the time integrator (the return map's lambda |t_T| is the algorithmic
        measure, >= 0). Energy-consistent: the friction force's work minus the change of
        the stick springs' energy (contact/conserving.py)."""
        c = self.contact
        if c.c_T <= 0.0:
            return 0.0
        t_bar = self.history.t_T_bar
        if self.work_T is not None:
            dW = c.weights * (np.where(self.active, self.t_T, 0.0) ** 2 - t_bar**2) / (2.0 * c.c_T)
            return float(self.work_T.sum() - dW.sum())
        return float((c.weights * 0.5 * (t_bar + self.t_T) * self.lam * np.sign(self.t_T)).sum())

    def report(self):
        """Per slave node: reference and current position, gap, tractions, nodal forces, state."""
        c = self.contact
        return dict(
            X=c.slave.X[c.nodes],
            x=self.x_s,
            g_N=self.g_N,
            t_N=self.t_N,
            t_T=self.t_T,
            f_N=c.weights * self.t_N,
            f_T=c.weights * self.t_T,
            n=self.n,
            t=self.tangent,
            state=STATE_NAMES[self.slip],
            seg=self.seg,
            weights=c.weights,
        )

    @property
    def dg_T(self):
        """The slip increment of the step (eq 20, with the closing step's factor r)."""
        return self.r * (self.s - self.history.s_bar)

    @property
    def n_active(self):
        """Slave nodes in contact."""
        return int(np.count_nonzero(self.active))

    @property
    def n_slip(self):
        """Slave nodes slipping in this step (the return map's decision at this state)."""
        return int(np.count_nonzero(self.slip == SLIP))
