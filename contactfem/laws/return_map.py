"""Return mapping of the frictional interface law (paper Sec. 4.2.3, eqs 40-48).

Plane case: the tangential traction t_T is a scalar along the master tangent.
Everything is vectorised over contact nodes. Beyond the paper's laws Y(p, q), the
return map integrates laws that depend on the slip rate and on internal variables of
their own (the protocol of ``contactfem.laws.protocol``).
"""

from dataclasses import dataclass

import numpy as np

from ..laws.protocol import as_shape, as_friction_law

OPEN, STICK, SLIP = 0, 1, 2
STATE_NAMES = np.array(["open", "stick", "slip"])


class ReturnMapError(FloatingPointError):
    """The local Newton iteration for the slip multiplier did not converge."""


@dataclass
class FrictionState:
    """Result of the return mapping at each contact node."""

    t_T: np.ndarray  # tangential traction (eq 43)
    c_T_s: np.ndarray  # dt_T / dg_T  (eq 48; c_T when sticking)
    c_N_s: np.ndarray  # dt_T / dg_N  (eq 48; 0 when sticking)
    state: np.ndarray  # OPEN, STICK or SLIP
    lam: np.ndarray  # slip increment lambda >= 0 (eq 45)
    q: np.ndarray  # accumulated slip after the step
    z: np.ndarray | None = None  # the law's internal variables after the step (n, k)
    v: np.ndarray | None = None  # slip rate lambda / dt of the step

    @property
    def dissipation(self):
        """Frictional dissipation per unit area in the step, t_T dg_T^s = lambda |t_T| >= 0."""
        return self.lam * np.abs(self.t_T)


def return_map(law, t_N, dt_N, dg_T, t_T_bar, q_bar, z_bar=None, dt=None, tol=1e-12, maxit=100):
    """Integrate the friction law over one step by elastic predictor / return map.

    law      : friction law (c_T and slip_bound, see contactfem.laws.protocol)
    t_N      : signed normal traction (<= 0 in contact), dt_N = dt_N/dg_N
    dg_T     : tangential slip increment Delta g_T = s - s_bar (eq 20)
    t_T_bar  : converged tangential traction, q_bar: converged accumulated slip
    z_bar    : converged internal variables of the law (n, k); default its initial state
    dt       : time step (needed by laws with a slip rate or internal variables)

    Eq (42), the elastic predictor:  t_tr = t_T_bar + c_T dg_T.
    Eq (40), the slip check:         f_tr = |t_tr| - Y(p, q_bar, 0, z(0)), p = |t_N|.
    Eqs (43)-(44), the return:       t_T = t_tr - c_T lam sign(t_tr), with lam from
                                     phi(lam) = |t_tr| - c_T lam - Y(p, q_bar + lam, lam/dt, z(lam)) = 0,
                                     z(lam) = evolve(z_bar, p, lam, dt) (a local Newton iteration,
                                     safeguarded by bisection on [0, |t_tr|/c_T], where phi
                                     changes sign; closed form when Y is Y(p) alone).
    Eqs (47)-(48), the consistent moduli, by implicit differentiation of phi = 0, with the
    total derivatives Y_lam = Y_q + Y_v/dt + Y_z . dz/dlam and Y_P = Y_p + Y_z . dz/dp:
        c_T^s = dt_T/dg_T = c_T Y_lam / (c_T + Y_lam),
        c_N^s = dt_T/dg_N = sign(t_tr) Y_P dp/dg_N c_T / (c_T + Y_lam),  dp/dg_N = -dt_N.
    (For the paper's Y(p, q): Y_lam = dY/dq, Y_P = dY/dp, eq 48 as printed.)
    """
    L = as_friction_law(law)
    t_N, dt_N, dg_T, t_T_bar, q_bar = _node_arrays(t_N, dt_N, dg_T, t_T_bar, q_bar)
    n = t_N.size
    c_T = L.c_T
    if L.needs_dt:
        if dt is None or not (np.isfinite(dt) and dt > 0):
            raise ValueError(
                f"the friction law {L.name} depends on the slip rate or on internal variables: "
                f"the return map needs the time step dt > 0, got {dt!r}"
            )
    else:
        dt = 1.0 if dt is None else dt
    z_bar = L.initial_state(n) if z_bar is None else as_shape(z_bar, (n, L.n_state))
    # the paper's laws, Y(p, q) (eqs 10, 11): no slip rate and no internal variables, so Y_v = 0
    # and there is no z; their terms are left out below (they would add zeros)
    paper_form = L.arity == 2 and not L.n_state

    # open nodes (p = 0) carry nothing and keep their history: integrate the nodes in contact, c
    t_T, c_T_s, c_N_s, lam = np.zeros((4, n))
    state = np.zeros(n, dtype=int)  # OPEN (= 0)
    q = q_bar  # (copied where a node slips)
    z = np.array(z_bar, dtype=float) if L.n_state else z_bar  # (no variables: nothing to copy)
    c = (t_N < 0.0).nonzero()[0]
    if not c.size:  # every node open (a body in flight): nothing to integrate
        return FrictionState(t_T=t_T, c_T_s=c_T_s, c_N_s=c_N_s, state=state, lam=lam, q=q.copy(), z=z, v=lam.copy())
    p, q_c = -t_N[c], q_bar[c]
    z_c = z_bar[c] if L.n_state else z_bar[: c.size]
    t_tr = t_T_bar[c] + c_T * dg_T[c]  # eq (42)
    if paper_form:
        z0 = z_c
        Y0 = L.slip_bound_pq(p, q_c)[0]
    else:
        zero = np.zeros(c.size)
        z0 = L.evolve(z_c, p, zero, dt)[0] if L.n_state else z_c
        Y0 = L.slip_bound(p, q_c, zero, z0)[0]
    f_tr = np.abs(t_tr) - Y0  # eq (40)
    slips = f_tr > 0.0 if c_T > 0.0 else np.zeros(c.size, dtype=bool)

    t_T[c] = t_tr  # stick: the trial state (the slipping
    c_T_s[c] = c_T  # nodes are written over below)
    state[c] = STICK
    if L.n_state:
        z[c] = z0

    i = slips.nonzero()[0]  # the slipping nodes, by position in c
    if i.size:
        c_i, t_tr_i = c[i], t_tr[i]  # slipping: position in c, node
        a_tr, s, pi, qi, zi = np.abs(t_tr_i), np.sign(t_tr_i), p[i], q_c[i], z_c[i]
        lo, hi = np.zeros(len(i)), a_tr / c_T  # phi(lo) > 0 >= phi(hi) (Y >= 0)
        lam_i = f_tr[i] / c_T  # exact if Y depends on p alone
        converged = tol * np.maximum(1.0, a_tr)

        def local(lam_i):
            if paper_form:
                Y, Y_p, Y_q = L.slip_bound_pq(pi, qi + lam_i)
                return a_tr - c_T * lam_i - Y, (Y_q, Y_p), zi
            if L.n_state:
                zz, z_p, z_lam = L.evolve(zi, pi, lam_i, dt)
                Y, Y_p, Y_q, Y_v, Y_z = L.slip_bound(pi, qi + lam_i, lam_i / dt, zz)
                return (
                    a_tr - c_T * lam_i - Y,
                    (Y_q + Y_v / dt + np.einsum("ij,ij->i", Y_z, z_lam), Y_p + np.einsum("ij,ij->i", Y_z, z_p)),
                    zz,
                )
            Y, Y_p, Y_q, Y_v, _ = L.slip_bound(pi, qi + lam_i, lam_i / dt)
            return a_tr - c_T * lam_i - Y, (Y_q + Y_v / dt, Y_p), zi

        for _ in range(maxit):  # eq (44): local Newton
            phi, (Y_lam, Y_P), zz = local(lam_i)
            if (np.abs(phi) <= converged).all():  # (False where phi is NaN)
                break
            if not np.isfinite(phi).all():
                raise ReturnMapError(
                    f"return map: the slip bound of {L.name} is not finite at p = {pi[~np.isfinite(phi)][:3]}"
                )
            lo = np.where(phi > 0.0, lam_i, lo)
            hi = np.where(phi < 0.0, lam_i, hi)
            dphi = -(c_T + Y_lam)
            with np.errstate(divide="ignore", invalid="ignore"):
                trial = lam_i - phi / dphi
            bad = ~np.isfinite(trial) | (trial < lo) | (trial > hi) | (dphi >= 0.0)
            lam_i = np.where(bad, 0.5 * (lo + hi), trial)  # bisection where Newton leaves the bracket
        else:
            raise ReturnMapError(
                f"return map: local Newton for lambda did not converge in {maxit} iterations (max |phi| = "
                f"{np.max(np.abs(phi)):.3e})"
            )
        D = c_T + Y_lam
        if (D == 0.0).any():
            raise ReturnMapError(
                f"return map: the slip bound of {L.name} softens exactly as fast as the stick stiffness "
                "(c_T + dY/dlambda = 0): the slip is not unique"
            )
        state[c_i] = SLIP
        t_T[c_i] = s * (a_tr - c_T * lam_i)  # eq (43)
        c_T_s[c_i] = c_T * Y_lam / D  # eq (48)
        c_N_s[c_i] = s * Y_P * (-dt_N[c_i]) * c_T / D  # eq (48)
        lam[c_i] = lam_i
        q = q_bar.copy()
        q[c_i] = qi + lam_i
        if L.n_state:
            z[c_i] = zz
    # A law's values are checked where it returns (its adapter); a shipped law returns finite
    # values at finite arguments, and a non-finite argument (a diverging iterate) makes the
    # residual non-finite, which Newton reports: the sums are taken for the other laws only.
    if not L.trusted and not np.isfinite(t_T.sum() + c_T_s.sum() + c_N_s.sum()):  # (non-finite if a term is)
        raise ReturnMapError("return map produced a non-finite traction or modulus")
    return FrictionState(t_T=t_T, c_T_s=c_T_s, c_N_s=c_N_s, state=state, lam=lam, q=q, z=z, v=lam / dt)


def _node_arrays(*arrays):
    """The arguments as float arrays of one shape (n,) (broadcast if need be)."""
    shape = getattr(arrays[0], "shape", None)
    for a in arrays:
        if type(a) is not np.ndarray or a.dtype != np.float64 or a.shape != shape or a.ndim != 1:
            break
    else:
        return arrays
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in arrays))
    return [a.reshape(-1) for a in arrays]
