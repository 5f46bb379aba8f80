"""Contact with Lagrange multipliers as unknowns, solved by a semi-smooth Newton method
(beyond the paper: no penalty, eqs 4-5, and no outer loop as in augmented.py).

Each slave node j carries its normal and tangential traction t_N,j, t_T,j as unknowns
(tractions per unit length, or nodal forces with weights 1, like the penalty laws';
frictionless: t_N,j only). The contact owns them (``unknowns``; the System places them
after the bodies' dofs, at an offset o it keeps: contact/placement.py):

    o + j                   t_N,j     (j = 0 .. nc - 1)
    o + nc + j              t_T,j     (with friction)

and its state writes two kinds of rows of the global G and K:

* the bodies' rows: the virtual work of the multipliers, eq 28 with t_N, t_T the unknowns,
  R_c = sum_j w_j (t_N,j dg_N,j + t_T,j ds_j)   (node-to-segment; mortar: contact/mortar.py),
  whose tangent has the geometric part w (t_N d2g_N + t_T d2s) (eqs 33, 39 without the
  moduli) and the columns of the multipliers, w dg_N and w ds;
* the multipliers' rows: the complementarity functions C_N, C_T (complementarity.py,
  Alart-Curnier) of the node's gap g_N and slip increment Delta g_T = s - s_bar (eq 20),
  times the node's weight w_j (a constant: the tributary length or 1), so that they are
  forces like the other rows and one Newton tolerance serves all of them.

The active, stick and slip sets are those of the complementarity functions at the
iterate: they change inside Newton, no outer loop. When they have settled, Newton is
Newton's method on a smooth system and converges quadratically; the converged gap is
zero to round-off on the active nodes (the normal row there is c_N w g_N = 0) and the
converged tractions do not depend on c_N, c_T.

One evaluation per Newton iteration, as for the penalty contacts: the state carries the
sets, the tractions (= the multipliers), the residual rows and the tangent. The
multipliers are part of the converged u, so the converged state and the next step's
start both have them; the history (t_T_bar, s_bar, ...) is committed from the converged
state as for the penalty contact.

The closing step of the penalty contact (interface.py) is not used: with the gap
enforced exactly a node that closes within the step touches at its end, where the
closing-step factor vanishes with the gap (and with it every stick condition); here a
node's slip is its whole travel s - s_bar of the step.
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import lazy
from ..laws.return_map import SLIP
from .complementarity import check_laws, friction_complementarity, normal_complementarity
from .element import contact_element
from .interface import NodeToSegment
from .mortar import _pair_rows, contact_forces
from .mortar_contact import MortarContact, MortarHistory, MortarState
from .placement import placed, start_of
from .state import ContactState

sparse = lazy.module("scipy.sparse")


def _lagrange_checks(contact):
    check_laws(contact.normal, contact.friction, f"contact {contact.name!r}")
    nc = len(contact.nodes)
    contact.c_N = float(contact.normal.c_N)
    contact.c_T_ncp = float(contact.friction.c_T) if contact.friction is not None else 0.0
    contact.unknowns = (2 if contact.friction is not None else 1) * nc


def multipliers(contact, u, offsets=None):
    """t_N, t_T (nc,) of the contact from the global u, and their global dofs (where the
    System's ``offsets`` place them: placement.py)."""
    if not placed(contact, offsets):
        raise ValueError(
            f"contact {contact.name!r} owns unknowns (Lagrange multipliers): put it in a System, which places them"
        )
    nc = len(contact.nodes)
    dN = start_of(contact, offsets) + np.arange(nc)
    dT = dN + nc if contact.friction is not None else np.zeros(0, int)
    t_T = u[dT] if contact.friction is not None else np.zeros(nc)
    return u[dN].copy(), np.array(t_T, dtype=float), dN, dT


def conditions(contact, t_N, t_T, g_N, dg_T, eligible):
    """The complementarity functions of every node (complementarity.py) at its gap and
    slip increment (eqs 17, 20), and their derivatives, in a dict: C_N, C_T, and dN_t (dC_N/dt_N), dN_g
    (dC_N/dg_N), dT_t
    (dC_T/dt_T), dT_tN (dC_T/dt_N), dT_g (dC_T/dg_N), dT_dg (dC_T/d Delta g_T), slip (set)."""
    C_N, dN_t, dN_g, xi = normal_complementarity(t_N, g_N, contact.c_N, eligible)
    nc = len(t_N)
    zero = np.zeros(nc)
    if contact.friction is None:
        slip = np.where(xi >= 0.0, 1, 0)  # STICK (closed) or OPEN
        return dict(
            C_N=C_N,
            C_T=zero[:0],
            dN_t=dN_t,
            dN_g=dN_g,
            dT_t=zero,
            dT_tN=zero,
            dT_g=zero,
            dT_dg=zero,
            slip=slip,
            closed=xi >= 0.0,
        )
    C_T, dT_t, dT_dg, dT_xi, slip = friction_complementarity(contact.friction, t_T, dg_T, xi, contact.c_T_ncp)
    # xi = -t_N - c_N g_N
    return dict(
        C_N=C_N,
        C_T=C_T,
        dN_t=dN_t,
        dN_g=dN_g,
        dT_t=dT_t,
        dT_tN=-dT_xi,
        dT_g=-contact.c_N * dT_xi,
        dT_dg=dT_dg,
        slip=slip,
        closed=xi >= 0.0,
    )


@dataclass(frozen=True, eq=False)
class LagrangeState(ContactState):
    """A ContactState of LagrangeNodeToSegment: t_N, t_T are the multipliers; ``active``
    the closed set of the complementarity function, ``slip`` OPEN/STICK/SLIP; ``lam`` the
    slip |Delta g_T| of slipping nodes. The complementarity rows: C (the scaled C_N, C_T at
    ``ncp_dofs``) and the triplets ``ncp_coo`` of the multipliers' columns and rows."""

    C: np.ndarray | None = None
    ncp_dofs: np.ndarray | None = None
    ncp_coo: tuple = ()

    def scatter(self, ndof):
        R_c, rows, cols, vals = super().scatter(ndof)
        R_c[self.ncp_dofs] += self.C
        r, c, v = self.ncp_coo
        return R_c, np.concatenate([rows, r]), np.concatenate([cols, c]), np.concatenate([vals, v])

    @cached_property
    def energy(self):
        """None stored: the constraints hold exactly (t_N g_N = 0, no stick spring)."""
        return 0.0


class LagrangeNodeToSegment(NodeToSegment):
    """Node-to-segment contact (same arguments as NodeToSegment) with the tractions as
    unknowns and the contact conditions as complementarity functions (module docstring).

    normal:   PowerLaw(c_N, m = 1): c_N is the normal complementarity parameter
    friction: Coulomb or ParabolicSlip (its c_T the tangential one), or None
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        if self.integration != "standard" or self.tangent != "consistent":
            raise ValueError(
                f"contact {self.name!r}: enforcement = lagrange takes tangent = consistent and "
                f"integration = standard (got {self.tangent}, {self.integration})"
            )
        _lagrange_checks(self)

    def evaluate(self, u, t=0.0, dt=None, u0=None, phase=None, *, history, offsets=None):
        """The LagrangeState at u (displacements and multipliers) with the committed ``history``."""
        h = history
        if phase is not None:
            raise ValueError(f"contact {self.name!r}: enforcement = lagrange has no staggered phases")
        k = self.kinematics(u, t, h, offsets)
        t_N, t_T, dN, dT = multipliers(self, u, offsets)
        on = k["inside"]
        dg_T = k["s"] - h.s_bar  # eq 20, no closing-step factor (module docstring)
        cond = conditions(self, t_N, t_T, k["g_N"], dg_T, on)
        nc, w = len(t_N), self.weights
        # the bodies' rows: eq 28 with the multipliers, its geometric tangent (eqs 33, 39 without moduli)
        zero = np.zeros(np.count_nonzero(on))
        R, K = contact_element(
            w[on], t_N[on], zero, t_T[on], zero, zero, k["dg_N"][on], k["d2g_N"][on], k["ds"][on], k["d2s"][on]
        )
        dofs, j = k["dofs"][on], np.flatnonzero(on)  # the pairs' dofs (m of them each)
        m = dofs.shape[1]
        W = w[on][:, None]
        coo = [
            (dofs.ravel(), np.repeat(dN[j], m), (W * k["dg_N"][on]).ravel()),  # dR/dt_N = w dg_N
            (dN, dN, w * cond["dN_t"]),  # w dC_N/dt_N
            (np.repeat(dN[j], m), dofs.ravel(), (W * cond["dN_g"][on, None] * k["dg_N"][on]).ravel()),
        ]
        C = [w * cond["C_N"]]
        if self.friction is not None:
            dC_du = cond["dT_g"][on, None] * k["dg_N"][on] + cond["dT_dg"][on, None] * k["ds"][on]
            coo += [
                (dofs.ravel(), np.repeat(dT[j], m), (W * k["ds"][on]).ravel()),  # dR/dt_T = w ds
                (dT, dT, w * cond["dT_t"]),
                (dT, dN, w * cond["dT_tN"]),
                (np.repeat(dT[j], m), dofs.ravel(), (W * dC_du).ravel()),
            ]
            C.append(w * cond["C_T"])
        lam = np.where(cond["slip"] == SLIP, np.abs(dg_T), 0.0)
        return LagrangeState(
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
            inside=on,
            active=cond["closed"],
            r=np.ones(nc),
            t_N=t_N,
            dt_N=np.zeros(nc),
            t_T=t_T,
            c_T_s=np.zeros(nc),
            c_N_s=np.zeros(nc),
            slip=cond["slip"],
            lam=lam,
            q=h.q_bar + lam,
            z=h.z_bar,
            R=R,
            K=K,
            element_dofs=dofs,
            C=np.concatenate(C),
            ncp_dofs=np.concatenate([dN, dT]),
            ncp_coo=tuple(np.concatenate(a) for a in zip(*coo)),
        )


class LagrangeMortar(MortarContact):
    """Mortar contact (same arguments as MortarContact) with the nodal tractions of the
    slave as unknowns (standard multipliers, t_N,h = sum_j N_j t_N,j) and the contact
    conditions as complementarity functions of the nodal average gap g_N,j = g~_j / w_j - o_j
    and slip increment Delta g_T,j = g~_T,j / w_bar_j (contact/mortar.py); each row times
    the slave's tributary length of node j (a constant). A node no master faces is open.

    normal:   PowerLaw(c_N, m = 1): c_N is the normal complementarity parameter
    friction: Coulomb or ParabolicSlip (its c_T the tangential one), or None
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        _lagrange_checks(self)
        X = self.slave.X[self.nodes]
        L = np.linalg.norm(np.diff(X, axis=0), axis=1)
        self.row_weights = np.concatenate([[0.0], L / 2]) + np.concatenate([L / 2, [0.0]])

    def evaluate(self, u, t=0.0, dt=None, u0=None, phase=None, *, history, offsets=None):
        """The MortarState at u (displacements and multipliers) with the committed ``history``:
        the virtual work of the multipliers and the complementarity rows (module docstring)."""
        h = self._check(phase, history)
        k = self.kinematics_at(u, h, offsets)
        mi, slip = k["mi"], k["slip"]
        t_N, t_T, dN, dT = multipliers(self, u, offsets)
        cond = conditions(self, t_N, t_T, k["g_N"], k["dg_T"], k["covered"])
        s, ns = self.row_weights, len(t_N)
        g = np.concatenate(
            [self.slave_dofs(offsets).ravel(), self.master_dofs(offsets).ravel()]
        )  # interface -> global (-1: rigid)
        zero = np.zeros(ns)
        # the bodies' rows: R = sum_j t_N,j f_N,j + t_T,j f_T,j and its geometric tangent (no moduli)
        R_i, (r, c, v) = contact_forces(
            mi, t_N, zero, k["offset"], slip, _Tractions(t_T, zero, zero) if slip is not None else None, h.w
        )
        coo = [(g[r], g[c], v)]
        F = [(_pair_rows(mi.f_N, mi.pairs, ns, len(g)), dN)]  # dR/dt_N = F_N^T, dR/dt_T = F_T^T
        # the multipliers' rows: s C with dC/du through dg_N and d Delta g_T = dg~_T / w_bar
        D_u = [sparse.diags(s * cond["dN_g"]) @ k["dg_N"]]
        coo += [(dN, dN, s * cond["dN_t"])]
        C = [s * cond["C_N"]]
        if slip is not None:
            F.append((_pair_rows(mi.f_T, mi.pairs, ns, len(g)), dT))
            inv_w = np.where(h.w > 0.0, 1.0 / np.where(h.w > 0.0, h.w, 1.0), 0.0)
            D_u.append(sparse.diags(s * cond["dT_g"]) @ k["dg_N"] + sparse.diags(s * cond["dT_dg"] * inv_w) @ slip.dg_T)
            coo += [(dT, dT, s * cond["dT_t"]), (dT, dN, s * cond["dT_tN"])]
            C.append(s * cond["C_T"])
        for mat, own in F:
            m = mat.tocoo()
            coo.append((g[m.col], own[m.row], m.data))
        for mat, own in zip(D_u, (dN, dT)):
            m = mat.tocoo()
            coo.append((own[m.row], g[m.col], m.data))
        rows, cols, vals = (np.concatenate(a) for a in zip(*coo))
        keep = (rows >= 0) & (cols >= 0)
        R = np.zeros(len(u))
        np.add.at(R, g[g >= 0], R_i[g >= 0])
        R[np.concatenate([dN, dT])] += np.concatenate(C)
        lam = np.where(cond["slip"] == SLIP, np.abs(k["dg_T"]), 0.0)
        history = MortarHistory(
            t_T=np.where(cond["closed"], t_T, 0.0), q=h.q + lam, z=h.z, pairs=mi.pairs, D=mi.D, M=mi.M, w=mi.w, x=k["x"]
        )
        return MortarState(
            t=t,
            dt=dt,
            nodes=self.nodes,
            X=self.slave.X[self.nodes],
            x=k["xs"],
            g_N=k["g_N"],
            t_N=t_N,
            dt_N=zero,
            t_T=t_T,
            c_T_s=zero,
            c_N_s=zero,
            lam=lam,
            q=h.q + lam,
            z=h.z,
            state=cond["slip"],
            weights=mi.w,
            dg_T=k["dg_T"],
            R=R,
            rows=rows[keep],
            cols=cols[keep],
            vals=vals[keep],
            history=history,
            integrals=mi,
            energy=0.0,
            dissipation=float(np.sum(h.w * 0.5 * (h.t_T + t_T) * lam * np.sign(t_T))),
        )


@dataclass(frozen=True)
class _Tractions:
    t_T: np.ndarray
    c_T_s: np.ndarray
    c_N_s: np.ndarray
