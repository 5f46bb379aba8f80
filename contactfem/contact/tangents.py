"""Contact tangents other than the consistent one (paper Sec. 4.2), to compare Newton's
convergence: the residual is always eq (28), only the matrix handed to the solver changes.

    ContactTangent(contact, "consistent" | "symmetric" | "frozen")
        consistent  eqs 33, 39, 49-50 (the contact as it is; non-symmetric)
        symmetric   (K_c + K_c^T) / 2
        frozen      K_c without the coupling w c_N^s C of eq (50)
    SplitContact(contact)
        the normal / friction phases of the staggered (two-step) algorithm of Sec. 2.2,
        driven by ``contactfem.solver.staggered``.

Both wrap a NodeToSegment and delegate everything else (commit, energy, report) to it.
"""
import numpy as np

from ..laws.return_map import return_map
from .element import to_coo
from .kinematics import outer

TANGENTS = ("consistent", "symmetric", "frozen")


class ContactTangent:
    """A contact with the same residual (eq 28) but a modified tangent, to compare
    Newton's convergence (the point of paper Sec. 4.2):

    symmetric:  (K_c + K_c^T) / 2
    frozen:     K_c - w c_N^s C,  C = ds dg_N^T (eq 50): the slip bound is treated
                as independent of the normal gap in the tangent.
    Everything else is delegated to the wrapped contact."""

    def __init__(self, contact, kind):
        if kind not in TANGENTS:
            raise ValueError(f"parameter tangent = {kind!r} is not allowed: one of {'|'.join(TANGENTS)}")
        self.contact, self.kind = contact, kind

    def __getattr__(self, name):
        return getattr(self.contact, name)

    def assemble(self, u):
        R_c, rows, cols, vals = self.contact.assemble(u)
        if self.kind == "symmetric":
            return R_c, np.concatenate([rows, cols]), np.concatenate([cols, rows]), np.concatenate([vals, vals]) / 2
        if self.kind == "frozen":
            e = self.contact.evaluate(u)
            on = e["active"]
            C = (self.contact.weights * e["friction"].c_N_s)[on, None, None] * outer(e["ds"][on], e["dg_N"][on])
            r, c, v = to_coo(e["dofs"][on], -C)
            return R_c, np.concatenate([rows, r]), np.concatenate([cols, c]), np.concatenate([vals, v])
        return R_c, rows, cols, vals


PHASES = ("full", "normal", "friction")


class SplitContact:
    """A NodeToSegment contact whose residual and tangent can be evaluated in one of
    three phases: ``full`` (the contact as it is: eq 28 with the consistent tangent),
    ``normal`` (friction state frozen, see ``contactfem.solver.staggered``) or ``friction``
    (normal pressure frozen in the return mapping). ``freeze(u)`` stores the frozen
    quantities of both phases from the full evaluation at u. Everything else (commit,
    energy, report, initialize, dissipation) is the wrapped contact's."""

    def __init__(self, contact):
        self.contact = contact
        self.phase = "full"
        self.t_T_star = self.s_star = self.p_star = None

    def __getattr__(self, name):
        return getattr(self.contact, name)

    def set_phase(self, phase):
        if phase not in PHASES:
            raise ValueError(f"parameter phase = {phase!r} is not allowed: one of {'|'.join(PHASES)}")
        self.phase = phase

    def freeze(self, u):
        """Frozen data from the full evaluation at u: t_T* and s* (normal phase), p* = |t_N|
        (friction phase); zero at open nodes."""
        e = self.contact.evaluate(u)
        on = e["active"]
        self.t_T_star = np.where(on, e["friction"].t_T, 0.0)
        self.s_star = e["s"].copy()
        self.p_star = np.where(on, -e["t_N"], 0.0)

    def assemble(self, u):
        c = self.contact
        if self.phase == "full" or c.friction is None:
            return c.assemble(u)
        if self.p_star is None:
            raise ValueError("SplitContact: call freeze(u) before assembling a normal or friction phase")
        e = c.kinematics(u)
        zero = np.zeros_like(e["t_N"])
        if self.phase == "normal":         # stick about the frozen state: t_T = t_T* + c_T (s - s*)
            c_T = float(c.friction.c_T)
            t_T = self.t_T_star + c_T * (e["s"] - self.s_star)
            c_T_s, c_N_s = np.full_like(zero, c_T), zero
            e = dict(e, ddg_T=e["ds"])     # this t_T varies with s alone (no closing-step factor)
        else:                              # eqs 40-45 at the frozen pressure p*: c_N^s = 0
            fr = return_map(c.friction, -self.p_star, zero, e["dg_T"], c.t_T_bar, c.q_bar,
                            z_bar=c.z_bar, dt=c.dt)
            t_T, c_T_s, c_N_s = fr.t_T, fr.c_T_s, fr.c_N_s
        return c.scatter(c.element(e, t_T, c_T_s, c_N_s), len(u))
