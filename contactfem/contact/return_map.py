"""Return mapping of the frictional interface law (paper Sec. 4.2.3, eqs 40-48).

Plane case: the tangential traction t_T is a scalar along the master tangent.
Everything is vectorised over contact nodes.
"""

from dataclasses import dataclass

import numpy as np

OPEN, STICK, SLIP = 0, 1, 2
STATE_NAMES = np.array(["open", "stick", "slip"])


class ReturnMapError(FloatingPointError):
    """The local Newton iteration for the slip multiplier did not converge."""


@dataclass
class FrictionState:
    """Result of the return mapping at each contact node."""

    t_T: np.ndarray    # tangential traction (eq 43)
    c_T_s: np.ndarray  # dt_T / dg_T  (eq 48; c_T when sticking)
    c_N_s: np.ndarray  # dt_T / dg_N  (eq 48; 0 when sticking)
    state: np.ndarray  # OPEN, STICK or SLIP
    lam: np.ndarray    # slip increment lambda >= 0 (eq 45)
    q: np.ndarray      # accumulated slip after the step

    @property
    def dissipation(self):
        """Frictional dissipation per unit area in the step, t_T dg_T^s = lambda |t_T| >= 0."""
        return self.lam * np.abs(self.t_T)


def return_map(law, t_N, dt_N, dg_T, t_T_bar, q_bar, tol=1e-12, maxit=50):
    """Integrate the friction law over one step by elastic predictor / return map.

    law      : friction law (c_T, slip_bound(p, q) -> (Y, dY/dp, dY/dq))
    t_N      : signed normal traction (<= 0 in contact), dt_N = dt_N/dg_N
    dg_T     : tangential slip increment Delta g_T = s - s_bar (eq 20)
    t_T_bar  : converged tangential traction, q_bar: converged accumulated slip

    Eq (42), the elastic predictor:  t_tr = t_T_bar + c_T dg_T.
    Eq (40), the slip check:         f_tr = |t_tr| - Y(p, q_bar), p = |t_N|.
    Eqs (43)-(44), the return:       t_T = t_tr - c_T lam sign(t_tr), with lam from
                                     phi(lam) = |t_tr| - c_T lam - Y(p, q_bar + lam) = 0
                                     (closed form when Y does not depend on q,
                                     otherwise a local Newton iteration).
    Eqs (47)-(48), the consistent moduli, by implicit differentiation of phi = 0:
        c_T^s = dt_T/dg_T = c_T Y_q / (c_T + Y_q),
        c_N^s = dt_T/dg_N = sign(t_tr) Y_p dp/dg_N c_T / (c_T + Y_q),  dp/dg_N = -dt_N.
    """
    t_N, dt_N, dg_T, t_T_bar, q_bar = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (t_N, dt_N, dg_T, t_T_bar, q_bar)))
    p = -t_N
    c_T = float(law.c_T)
    t_tr = t_T_bar + c_T * dg_T                                   # eq (42)
    Y0, _, _ = law.slip_bound(p, q_bar)
    f_tr = np.abs(t_tr) - Y0                                      # eq (40)

    in_contact = p > 0.0
    slip = in_contact & (f_tr > 0.0) & (c_T > 0.0)
    stick = in_contact & ~slip

    t_T = np.where(stick, t_tr, 0.0)
    c_T_s = np.where(stick, c_T, 0.0)
    c_N_s = np.zeros_like(p)
    lam = np.zeros_like(p)
    q = q_bar.copy()

    if slip.any():
        i = np.flatnonzero(slip)
        a_tr, s, pi, qi = np.abs(t_tr[i]), np.sign(t_tr[i]), p[i], q_bar[i]
        lam_i = f_tr[i] / c_T                                     # exact if Y_q = 0
        for _ in range(maxit):                                     # eq (44): local Newton
            Y, Y_p, Y_q = law.slip_bound(pi, qi + lam_i)
            phi = a_tr - c_T * lam_i - Y
            if (np.abs(phi) <= tol * np.maximum(1.0, a_tr)).all():
                break
            dphi = -(c_T + Y_q)
            if (dphi >= 0.0).any():
                raise ReturnMapError("return map: slip softening faster than the stick stiffness c_T (c_T + dY/dq <= 0)")
            lam_i = np.maximum(lam_i - phi / dphi, 0.0)
        else:
            raise ReturnMapError(f"return map: local Newton for lambda did not converge in {maxit} iterations (max |phi| = {np.max(np.abs(phi)):.3e})")
        Y, Y_p, Y_q = law.slip_bound(pi, qi + lam_i)
        D = c_T + Y_q
        t_T[i] = s * (a_tr - c_T * lam_i)                          # eq (43)
        c_T_s[i] = c_T * Y_q / D                                  # eq (48)
        c_N_s[i] = s * Y_p * (-dt_N[i]) * c_T / D                 # eq (48)
        lam[i] = lam_i
        q[i] = qi + lam_i

    state = np.where(slip, SLIP, np.where(stick, STICK, OPEN))
    if not (np.isfinite(t_T).all() and np.isfinite(c_T_s).all() and np.isfinite(c_N_s).all()):
        raise ReturnMapError("return map produced a non-finite traction or modulus")
    return FrictionState(t_T=t_T, c_T_s=c_T_s, c_N_s=c_N_s, state=state, lam=lam, q=q)
