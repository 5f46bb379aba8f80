"""Geometrically exact plane beam (Reissner 1972 / Simo & Vu-Quoc 1986), the
finite-deformation beam element of the paper's rings (Sec. 5.3, 5.4).

Unknowns per node: (u_x, u_y, theta), numbered node by node: dof 3*i + k.

Kinematics (exact under large rotations; textbook: Simo & Vu-Quoc 1986, Crisfield vol. 2 ch. 17):
    current centreline   x = X + u
    total rotation       phi = theta0 + theta   (theta0: reference tangent angle of the element)
    t(phi) = (cos phi, sin phi),  n(phi) = (-sin phi, cos phi)  (normal to the left of t)
    axial strain         eps = x' . t - 1
    shear strain         gam = x' . n
    curvature change     kap = theta'
    resultants           N = EA eps,  Q = kappa_s G A gam,  M = EI kap
    energy               W = int (N eps + Q gam + M kap) / 2 ds

Discretisation: straight two-node elements (a polygon in the reference state), linear
interpolation in the reference arc length s, ONE-point (midpoint) integration against
shear locking (``integration=2``: two-point Gauss, which locks in shear). The element
kernel is vectorised numpy over all elements; K comes as COO triplets on the constant
element connectivity (``internal_coo``, what the solver's System assembles) or as a CSR
matrix (``internal``).

The 1D mesh in the arc length s is scikit-fem's ``MeshLine`` (``mesh``, made on first
use; its element lengths are the reference chord lengths). A closed ring is an open 1D
mesh of length L whose last node (s = L) is identified with the first; the
identification is the index map ``self.fold`` (mesh node -> beam node). The lumped mass
is the row sums of the P1 mass matrix on that mesh, L0 / 2 to each end of an element,
summed here without scikit-fem (a run of rings then loads no scikit-fem or scipy; the
tests check it against ``asm(mass, basis)``).

Viscoplastic variant (paper Sec. 5.3 gives only the plastic resultants N0, Q0, M0):
a Perzyna overstress model, decoupled per resultant S in (N, Q, M) with elastic
modulus D in (EA, kappa_s GA, EI):
    plastic strain rate   e_p' = <|S| - S0> / (eta D) * sign(S)
eta is a relaxation time (units of time): eta -> 0 is rate-independent perfect
plasticity, eta -> inf is elastic. The scan gives no viscosity; the default
eta = 0.1 equals the paper's time step in Sec. 5.3, so the overstress relaxes
within about one step (nearly rate-independent, but the tangent stays regular).
Backward Euler gives the closed-form return map (see ``return_map``).
"""

import numpy as np

from .. import lazy
from ..contact.placement import start_of
from .interfaces import MASS_MATRICES

sp = lazy.module("scipy.sparse")
skfem = lazy.module("skfem")


def _check(name, value, low, low_open=True):
    """Raise ValueError unless value is a finite number > low (>= low if not low_open)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"parameter {name} must be a number, got {value!r}") from None
    ok = np.isfinite(v) and (v > low if low_open else v >= low)
    if not ok:
        bracket = "(" if low_open else "["
        raise ValueError(f"parameter {name} = {value!r} is out of range: allowed {bracket}{low:g}, inf)")
    return v


def ring(R, n_el, center=(0.0, 0.0)):
    """Nodes of a closed ring of radius R with n_el elements, counter-clockwise.

    For a counter-clockwise ring the beam normal n = e3 x t points INTO the ring,
    so the outer surface is ``offset_positions(u, -thickness / 2)``.
    """
    R = _check("R", R, 0.0)
    if int(n_el) != n_el or n_el < 3:
        raise ValueError(f"parameter n_el = {n_el!r} is out of range: allowed integers >= 3")
    a = 2 * np.pi * np.arange(int(n_el)) / n_el
    return np.asarray(center, float) + R * np.column_stack([np.cos(a), np.sin(a)])


def return_map(E, ep, D, S0, eta, dt):
    """Backward-Euler Perzyna return map, per resultant (vectorised).

    Trial S_tr = D (E - ep), overstress f = |S_tr| - S0. Elastic if f <= 0, else
        S = sign(S_tr) (S0 + f eta / (eta + dt)),   dS/dE = D eta / (eta + dt)
    (from S = S_tr - D de_p sign and D de_p = dt/eta (|S| - S0)).
    Returns S, the algorithmic modulus C = dS/dE, and the updated plastic strain.
    """
    S_tr = D * (E - ep)
    if S0 is None:
        return S_tr, D * np.ones_like(E), ep
    f = np.abs(S_tr) - S0
    yielding = f > 0
    r = eta / (eta + dt)
    S = np.where(yielding, np.sign(S_tr) * (S0 + f * r), S_tr)
    C = np.where(yielding, D * r, D)
    return S, C, E - S / D


class Beam:
    """Plane Reissner beam body (see the module docstring for the formulas).

    X        (nn, 2) reference centreline nodes (an open arc, or a ring if closed)
    closed   True: the last node connects back to the first
    E, A, I  Young's modulus, cross-section area, second moment of area (> 0)
    rho      density (>= 0)
    G        shear modulus (default E / (2 (1 + nu)))
    nu       Poisson's ratio, used only for the default G
    kappa_s  shear correction factor (default 5/6, rectangle)
    plastic  None (elastic) or dict(N0=, Q0=, M0=, eta=0.1): Perzyna viscoplasticity;
             then every evaluation needs the step's ``dt`` (internal_coo(u, dt), commit(u, dt)).
    integration     1 (midpoint, default) or 2 (two-point Gauss: stiffer, shear locking)
    rotary_inertia  True (default): rho I on the rotation dofs of the mass; False: 0
    mass_matrix     the mass the System uses: "lumped" (default) or "consistent" (``mass``)
    """

    def __init__(
        self,
        X,
        closed,
        E,
        A,
        I,
        rho,
        G=None,
        nu=0.0,
        kappa_s=5 / 6,
        name="beam",
        plastic=None,
        integration=1,
        rotary_inertia=True,
        mass_matrix="lumped",
    ):
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != 2 or not np.all(np.isfinite(X)):
            raise ValueError(f"parameter X must be a finite (nn, 2) array, got shape {X.shape}")
        nn = X.shape[0]
        nmin = 3 if closed else 2
        if nn < nmin:
            raise ValueError(f"parameter X has {nn} nodes: allowed nn >= {nmin} for closed={closed}")
        self.name, self.X, self.closed = name, X, bool(closed)
        E = _check("E", E, 0.0)
        self.A, self.I = _check("A", A, 0.0), _check("I", I, 0.0)
        self.rho = _check("rho", rho, 0.0, low_open=False)
        kappa_s = _check("kappa_s", kappa_s, 0.0)
        if G is None:
            if not -1.0 < float(nu) <= 0.5:
                raise ValueError(f"parameter nu = {nu!r} is out of range: allowed (-1, 0.5]")
            G = E / (2 * (1 + nu))
        G = _check("G", G, 0.0)
        self.D = np.array([E * self.A, kappa_s * G * self.A, E * self.I])  # EA, kGA, EI

        # connectivity: element e joins nodes a = e and b = e + 1 (closed: n-1 -> 0)
        ne = nn if closed else nn - 1
        a = np.arange(ne)
        self.conn = np.column_stack([a, (a + 1) % nn])
        chord = X[self.conn[:, 1]] - X[self.conn[:, 0]]
        self.L0 = np.hypot(chord[:, 0], chord[:, 1])
        if np.any(self.L0 <= 1e-14 * np.max(np.abs(X)) + 1e-300):
            raise ValueError("parameter X has coincident consecutive nodes: element lengths must be > 0")
        self.theta0 = np.arctan2(chord[:, 1], chord[:, 0])

        # the 1D mesh in the reference arc length s (closed: node nn sits at s = L and is
        # identified with node 0 through `fold`); scikit-fem's MeshLine of it: ``mesh``
        self.s = np.concatenate([[0.0], np.cumsum(self.L0)])
        self.fold = np.arange(ne + 1) % nn
        self._mesh = None

        self.ndof = 3 * nn
        self.xdofs = 3 * np.arange(nn)[:, None] + np.array([0, 1])
        self.edofs = np.column_stack(
            [3 * self.conn[:, 0] + k for k in range(3)] + [3 * self.conn[:, 1] + k for k in range(3)]
        )
        # COO indices of the element matrices, fixed: entry 6 i + j of every element, entry by entry
        self._rows = np.repeat(self.edofs.T, 6, axis=0).ravel()
        self._cols = np.concatenate([self.edofs.T] * 6).ravel()
        self._edofs_T = self.edofs.T.ravel()  # the element dofs, dof by dof
        self.ne = ne
        self._dX = chord  # X_b - X_a per element

        self.S0, self.eta = None, None
        if plastic is not None:
            unknown = set(plastic) - {"N0", "Q0", "M0", "eta"}
            if unknown:
                raise ValueError(f"parameter plastic has unknown keys {sorted(unknown)}: allowed N0, Q0, M0, eta")
            self.S0 = np.array([_check(k, plastic.get(k, d), 0.0) for k, d in (("N0", 1.0), ("Q0", 0.5), ("M0", 0.25))])
            self.eta = _check("eta", plastic.get("eta", 0.1), 0.0)
        if integration not in (1, 2):
            raise ValueError(f"parameter integration = {integration!r} is not allowed: one of 1|2")
        g = 1 / np.sqrt(3.0)
        # (natural coordinate xi in [-1, 1], weight as a fraction of L0)
        self.points = ((0.0, 1.0),) if integration == 1 else ((-g, 0.5), (g, 0.5))
        # plastic strains (eps_p, gam_p, kap_p) per integration point, the beam's internal variables
        # (its state, from ``start`` and ``commit``): rows k ne .. (k+1) ne - 1 belong to point k
        self._ep0 = np.zeros((len(self.points) * ne, 3))
        self._ep0.flags.writeable = False
        self._g = None  # the constants of internal_coo (``_gauss``), made on first use
        self._mass = None  # the lumped mass, made on first use
        self.rotary_inertia = bool(rotary_inertia)
        if mass_matrix not in MASS_MATRICES:
            raise ValueError(
                f"parameter mass_matrix = {mass_matrix!r} is not allowed: one of {'|'.join(MASS_MATRICES)}"
            )
        self.mass_matrix = mass_matrix

    quadratic_energy = False  # the strains are nonlinear in u (finite rotations)

    @property
    def hyperelastic(self):
        """True for the elastic beam (a stored energy, no history); False when viscoplastic."""
        return self.S0 is None

    def _dt(self, dt):
        """The step's dt, needed by the backward-Euler viscoplastic update only."""
        if self.S0 is None:
            return dt
        if dt is None:
            raise RuntimeError("viscoplastic beam: the step's dt is needed (internal_coo(u, dt), commit(u, dt))")
        return _check("dt", dt, 0.0)

    @property
    def rotation_dofs(self):
        """The local dofs of the node angles theta (energy-consistent steps turn them by a
        Cayley rotation, bodies/discrete_gradient.py)."""
        return np.arange(2, self.ndof, 3)

    def discrete_gradient(self, u0, u1):
        """The internal force of an energy-consistent step u0 -> u1, conjugate to the step's
        increment dq (the angles' phi = 2 tan(Delta theta / 2), discrete_gradient.cayley), with
        its tangent dF/du1, as (F, rows, cols, vals); elastic beams only. Per integration point
        (Simo, Tarnow & Doblare 1995, in the plane), with a = x', theta the angle there and
        sigma = D (Gamma_0 + Gamma_1) / 2, M = EI (kappa_0 + kappa_1) / 2 the mean resultants:

            Gamma_1 - Gamma_0 = cos(Dtheta/2) R(-theta_mid) [Da - psi J a_mid],  psi = 2 tan(Dtheta/2)

        exactly (R(+-Dtheta/2) = cos(Dtheta/2) (I +- tan(Dtheta/2) J)); with phi_bar = N_a phi_a +
        N_b phi_b, psi = phi_bar - (phi_b - phi_a) h, h = (phi_bar - psi) / (phi_b - phi_a) (psi =
        phi_bar exactly where the nodes turn alike: then h is its series); kappa_1 - kappa_0 =
        (phi_b - phi_a) k / L0, k = (Dtheta_b - Dtheta_a) / (phi_b - phi_a). So F . dq = sigma . DGamma + M Dkappa
        summed = W(u1) - W(u0) exactly; no
        translation enters, and a rigid rotation of the midpoint rule (Da = phi J a_mid, phi the
        same at every node) is orthogonal to F: no resultant and no moment. The tangent: the
        complex-step derivative of these element forces (exact to rounding)."""
        if self.S0 is not None:
            raise ValueError(f"body {self.name!r}: a discrete gradient needs a stored energy (an elastic beam)")
        g = self._gauss()
        e = g["edofs"]
        q0 = np.asarray(u0, float)[e]
        # the end state and its six complex steps, one per element dof, in one pass: (6, 7, m)
        step = 1e-30
        q = np.repeat(np.asarray(u1, float)[e][:, None, :], 7, axis=1).astype(complex)
        q[np.arange(6), np.arange(1, 7)] += 1j * step
        out = self._step_forces(q0[:, None, :], q, g)
        F = np.bincount(e.ravel(), out[:, 0].real.ravel(), minlength=self.ndof)
        Ke = out[:, 1:].imag / step  # (6, 6, m): d F_i / d q_j
        rows = np.broadcast_to(e[:, None, :], Ke.shape).ravel()
        cols = np.broadcast_to(e[None, :, :], Ke.shape).ravel()
        return F, rows, cols, Ke.ravel()

    def _step_forces(self, q0, q1, g):
        """The element forces (6, ..., m) of ``discrete_gradient`` at every integration point row,
        from the element dofs q0, q1 (6, ..., m) at the step's start and end (q1 may be complex;
        the middle axes broadcast)."""
        Na, Nb, invL = g["Na"], g["Nb"], g["invL"]
        dX = g["dX"].reshape((2,) + (1,) * (q1.ndim - 2) + (-1,))
        a0 = (dX + q0[3:5] - q0[0:2]) * invL  # x' at the start and the end
        a1 = (dX + q1[3:5] - q1[0:2]) * invL
        th0 = g["theta0"] + Na * q0[2] + Nb * q0[5]
        th1 = g["theta0"] + Na * q1[2] + Nb * q1[5]
        D = g["D"][:, 0]

        def gamma(a, th):
            c, s = np.cos(th), np.sin(th)
            return a[0] * c + a[1] * s - 1.0, a[1] * c - a[0] * s

        (e0, y0), (e1, y1) = gamma(a0, th0), gamma(a1, th1)
        N, Q = 0.5 * D[0] * (e0 + e1), 0.5 * D[1] * (y0 + y1)
        dA, dB = q1[2] - q0[2], q1[5] - q0[5]  # the nodes' Delta theta
        M = 0.5 * D[2] * (q0[5] - q0[2] + q1[5] - q1[2]) * invL
        pA, pB = 2.0 * np.tan(0.5 * dA), 2.0 * np.tan(0.5 * dB)  # their phi
        dth = th1 - th0
        tm = 0.5 * (th0 + th1)
        ch = np.cos(0.5 * dth)
        v = np.array([ch * (N * np.cos(tm) - Q * np.sin(tm)), ch * (N * np.sin(tm) + Q * np.cos(tm))])
        am = 0.5 * (a0 + a1)
        m = v[1] * am[0] - v[0] * am[1]  # v . J a_mid
        delta = pB - pA
        pbar = Na * pA + Nb * pB
        small = np.abs(np.real(delta)) < 1e-6
        safe = np.where(small, 1.0, delta)
        # h = (phi_bar - psi) / delta; where the nodes turn alike its first term, from the Taylor
        # expansion of 2 tan(.../2) about phi_bar: phi_bar / (4 + phi_bar^2) N_a N_b delta
        h = np.where(small, pbar / (4.0 + pbar * pbar) * Na * Nb * delta, (pbar - 2.0 * np.tan(0.5 * dth)) / safe)
        k = np.where(small, 1.0 / (1.0 + 0.0625 * (pA + pB) ** 2), (dB - dA) / safe)
        Mk = M * k * invL
        w = g["wL0"]
        return w * np.array(
            [-v[0] * invL, -v[1] * invL, -Na * m - h * m - Mk, v[0] * invL, v[1] * invL, -Nb * m + h * m + Mk]
        )

    # ---- kinematics ----------------------------------------------------------------
    def positions(self, u):
        """Current centreline node positions x = X + u, (nn, 2)."""
        return self.X + np.asarray(u).reshape(-1, 3)[:, :2]

    def strains(self, u, xi=0.0):
        """Strains (eps, gam, kap) per element at the natural coordinate xi (0: midpoint),
        (ne, 3), and t, n of the total angle there."""
        U = np.asarray(u, float).reshape(-1, 3)
        a, b = self.conn.T
        xp = (self._dX + U[b, :2] - U[a, :2]) / self.L0[:, None]  # x'
        phi = self.theta0 + 0.5 * (1 - xi) * U[a, 2] + 0.5 * (1 + xi) * U[b, 2]
        cos, sin = np.cos(phi), np.sin(phi)
        t = np.stack([cos, sin], axis=1)
        n = np.stack([-sin, cos], axis=1)
        E = np.empty((len(phi), 3))
        E[:, 0] = xp[:, 0] * cos + xp[:, 1] * sin - 1.0  # eps = x' . t - 1
        E[:, 1] = -xp[:, 0] * sin + xp[:, 1] * cos  # gam = x' . n
        E[:, 2] = (U[b, 2] - U[a, 2]) / self.L0  # kap = theta'
        return E, t, n

    def resultants(self, u, xi=0.0, k=0, E=None, dt=None, state=None):
        """(N, Q, M) per element at xi (integration point k), (ne, 3), with the algorithmic
        moduli dS/dE and new plastic strains (E: the strains there, if already computed; dt: the
        step, viscoplastic only; state: the committed plastic strains, None for the initial ones)."""
        if E is None:
            E = self.strains(u, xi)[0]
        ne = len(self.L0)
        return return_map(E, self._ep(state)[k * ne : (k + 1) * ne], self.D, self.S0, self.eta, self._dt(dt))

    def _ep(self, state):
        """The committed plastic strains: the state, or the initial (zero) ones for None."""
        return self._ep0 if state is None else state

    # ---- body interface ------------------------------------------------------------
    def internal(self, u, dt=None, state=None):
        """Internal force R = dW/du and consistent tangent K = dR/du (CSR); see internal_coo."""
        R, rows, cols, vals = self.internal_coo(u, dt, state)
        return R, sp.coo_matrix((vals, (rows, cols)), shape=(self.ndof, self.ndof)).tocsr()

    def internal_coo(self, u, dt=None, state=None):
        """Internal force R = dW/du and consistent tangent K = dR/du (virtual work, midpoint rule,
        or two-point Gauss with ``integration=2``), K as COO triplets (rows, cols, vals) on the
        fixed element connectivity (the same index arrays at every call). dt: the step and
        state: the committed plastic strains (viscoplastic only; None: the initial ones).

        Per element and point, with q = (u_a, theta_a, u_b, theta_b) and B = dE/dq (3 x 6):
            r_e = w L0 B^T S,     K_e = w L0 (B^T C B + N d2eps/dq2 + Q d2gam/dq2)
        deps/dphi = gam, dgam/dphi = -(1 + eps), phi = theta0 + N_a theta_a + N_b theta_b.
        With a_t = d(x'.t)/dq, a_n = d(x'.n)/dq (phi fixed) and p = dphi/dq:
            B = [a_t + gam p,  a_n - (1 + eps) p,  dkap/dq],
            d2eps/dq2 = a_n p^T + p a_n^T - (1 + eps) p p^T,
            d2gam/dq2 = -(a_t p^T + p a_t^T) - gam p p^T,
        so the geometric part is w p^T + p w^T - (N (1 + eps) + Q gam) p p^T, w = N a_n - Q a_t.

        Evaluated through the variables the strains depend on, r = (x', theta_a, theta_b)
        (x' = (X_b - X_a + u_b - u_a) / L0: the displacements enter only through it):
            eps = x'.t - 1,  gam = x'.n,  kap = (theta_b - theta_a) / L0,   t = (c, s), n = (-s, c),
        with c, s = cos phi, sin phi. In r (C = diag(C_N, C_Q, C_M), p = (N_a, N_b)):
            B^T S:   x': N t + Q n,     theta: (N gam - Q (1 + eps)) p + M dkap/dtheta
            K_r:     x'x':     C_N t t^T + C_Q n n^T
                     x'theta:  v p^T,  v = (C_N gam - Q) t + (N - C_Q (1 + eps)) n
                     theta theta:  alpha p p^T + C_M / L0^2 [[1, -1], [-1, 1]],
                               alpha = C_N gam^2 + C_Q (1 + eps)^2 - N (1 + eps) - Q gam
        (the geometric terms: d2eps/dx'dphi = n, d2gam/dx'dphi = -t, d2eps/dphi2 = -(1 + eps),
        d2gam/dphi2 = -gam), and K_e = T^T K_r T with dx'/du_a = -1/L0, dx'/du_b = 1/L0: each
        entry of K_e is one entry of K_r times 1, -1/L0 or 1/L0 per side (``_gauss``'s map).

        Every quantity is an array over the rows (row j = k ne + e is point k of element e, the
        rows of the plastic strains ``ep``): the element's 36 entries are made from ten arrays,
        and the points' sums are taken at the end. A vector over the rows is a (2, m) array (t,
        n, x', v: both components in one product), and so are the entries that share a form.
        """
        g = self._gauss()
        E, t, n = self._row_strains(u, g)
        S, C = self._resultants(E, g, dt, state)
        eps, gam = E[0], E[1]
        N, Q, M = S[0], S[1], S[2]
        C_N, C_Q, C_M = C[0], C[1], C[2]
        e1 = 1 + eps  # x'.t
        m = len(eps)
        # residual w L0 B^T S, one row of re per element dof (u_a, theta_a, u_b, theta_b)
        re = np.empty((6, m))
        np.multiply(g["wiL"], N * t + Q * n, out=re[3:5])  # x': N t + Q n (times 1/L0 at b)
        np.negative(re[3:5], out=re[0:2])  # (times -1/L0 at a)
        h = N * gam - Q * e1  # theta: (N gam - Q (1 + eps)) p
        wM = g["wiL"] * M
        re[2], re[5] = g["wNa"] * h - wM, g["wNb"] * h + wM
        # tangent: the ten distinct entries of w L0 K_e (docstring)
        U = np.empty((20, m))  # the ten entries, then their negatives
        tt = np.empty((3, m))  # t t^T: (c c, c s, s s)
        np.multiply(t, t[0], out=tt[0:2])
        np.multiply(t[1], t[1], out=tt[2])
        nn = tt[::-1] * g["flip"]  # n n^T: (s s, -c s, c c)
        np.multiply(g["wiL2"], C_N * tt + C_Q * nn, out=U[0:3])  # x'x' (times 1/L0^2)
        a1, a2 = C_N * gam - Q, N - C_Q * e1
        v = a1 * t + a2 * n  # v = (C_N gam - Q) t + (N - C_Q (1 + eps)) n
        np.multiply(g["wiLN"], v, out=U[3:7].reshape(2, 2, m))  # x' theta_a, x' theta_b (times 1/L0)
        alpha = gam * a1 - e1 * a2  # = C_N gam^2 + C_Q (1 + eps)^2 - N (1 + eps) - Q gam
        np.multiply(g["wNN"], alpha, out=U[7:10])  # theta theta: alpha p p^T
        U[7:10] += g["wiL2pm"] * C_M  #   + C_M / L0^2 [[1, -1], [-1, 1]]
        if len(self.points) > 1:  # two points: sum them per element (rows
            ne = self.ne  # e and ne + e), before K_e is spread out
            re, U = re[:, :ne] + re[:, ne:], U[:, :ne] + U[:, ne:]
        np.negative(U[:10], out=U[10:])
        Ke = U[g["entry"]]  # (36, ne): entry 6 i + j of each element
        R = np.bincount(self._edofs_T, re.ravel(), minlength=self.ndof)
        return R, self._rows, self._cols, Ke.ravel()

    def _row_strains(self, u, g):
        """The strains E = (eps, gam, kap) (3, m) and t = (cos, sin), n = (-sin, cos) of the angle
        phi (each (2, m)) at every row of ``_gauss`` (all integration points of all elements)."""
        q = np.asarray(u, float)[g["edofs"]]  # (6, m): u_a, theta_a, u_b, theta_b per row
        x = (g["dX"] + q[3:5] - q[0:2]) * g["invL2"]  # x', both components at once
        phi = g["theta0"] + g["Na"] * q[2] + g["Nb"] * q[5]
        t = np.empty((2, len(phi)))
        np.cos(phi, out=t[0])
        np.sin(phi, out=t[1])
        n = t[::-1] * g["turn"]  # n = e3 x t = (-sin, cos)
        xt, xn = x * t, x * n
        E = np.empty((3, len(phi)))
        np.add(xt[0], xt[1], out=E[0])  # eps = x' . t - 1
        E[0] -= 1.0
        np.add(xn[0], xn[1], out=E[1])  # gam = x' . n
        np.multiply(q[5] - q[2], g["invL"], out=E[2])  # kap = theta'
        return E, t, n

    def _resultants(self, E, g, dt, state=None):
        """The resultants S = (N, Q, M) (3, m) at the strains E of every row and their moduli
        C = dS/dE: the elastic beam's S = D E and C = D (what ``return_map`` gives without
        plastic strains; D at every row, so that no product broadcasts), else the viscoplastic
        return map from the committed plastic strains ``state``."""
        if self.S0 is None:
            return g["Dm"] * E, g["Dm"]
        return return_map(E, self._ep(state).T, g["D"], g["S0"], self.eta, self._dt(dt))[:2]

    def _gauss(self):
        """Per-row constants of internal_coo (row k ne + e: point k of element e), made once:
        the element dofs (6, m), chords, lengths and angles, the shape functions N_a, N_b at
        the point and their products with the weight w L0 and 1/L0 (stacked as internal_coo
        uses them: wiLN = w L0 / L0 (N_a, N_b), wNN = w L0 (N_a N_a, N_a N_b, N_b N_b), wiL2pm = w L0
        / L0^2 (1, -1, 1)), the signs that turn t t^T into n n^T (flip) and t into n (turn), and
        the map from the ten distinct entries of K_e and their negatives (rows 10-19) to its 36
        (``entry``)."""
        if self._g is None:
            ne, k = len(self.L0), len(self.points)
            xi = np.repeat([x for x, _ in self.points], ne)
            weight = np.repeat([w for _, w in self.points], ne)
            tile = lambda a: np.concatenate([a] * k)  # noqa: E731
            Na, Nb, invL, wL0 = 0.5 * (1 - xi), 0.5 * (1 + xi), tile(1 / self.L0), weight * tile(self.L0)
            # w L0 K_e[i, j] = sign * U[entry] (internal_coo): dofs 0, 1 (u_a), 2 (theta_a), 3, 4 (u_b), 5 (theta_b)
            side = {0: -1.0, 1: -1.0, 3: 1.0, 4: 1.0}  # dx'/du = -1/L0 at a, 1/L0 at b
            xx = {(0, 0): 0, (0, 1): 1, (1, 0): 1, (1, 1): 2}
            entry, sign = np.zeros(36, dtype=int), np.ones(36)
            for i in range(6):
                for j in range(6):
                    if i in side and j in side:
                        entry[6 * i + j], sign[6 * i + j] = xx[(i % 3, j % 3)], side[i] * side[j]
                    elif i in side or j in side:
                        d, th = (i, j) if i in side else (j, i)
                        entry[6 * i + j], sign[6 * i + j] = 3 + d % 3 + (2 if th == 5 else 0), side[d]
                    else:
                        entry[6 * i + j] = {(2, 2): 7, (2, 5): 8, (5, 2): 8, (5, 5): 9}[(i, j)]
            # C order: the rows of the element dofs q = u[edofs] (u_x of node a, ...) and of the
            # chords are contiguous, so every product over a row runs on contiguous memory
            self._g = dict(
                edofs=np.ascontiguousarray(np.concatenate([self.edofs.T] * k, axis=1)),
                dX=np.ascontiguousarray(np.concatenate([self._dX.T] * k, axis=1)),
                invL=invL,
                invL2=np.array([invL, invL]),
                Dm=self.D[:, None] * np.ones((3, len(xi))),
                D2=2 * self.D[:, None],
                theta0=tile(self.theta0),
                Na=Na,
                Nb=Nb,
                wL0=wL0,
                wiL=wL0 * invL,
                wiL2=wL0 * invL * invL,
                wNa=wL0 * Na,
                wNb=wL0 * Nb,
                wiLN=np.array([wL0 * invL * Na, wL0 * invL * Nb])[:, None, :],
                wNN=np.array([wL0 * Na * Na, wL0 * Na * Nb, wL0 * Nb * Nb]),
                wiL2pm=wL0 * invL * invL * np.array([[1.0], [-1.0], [1.0]]),
                flip=np.array([[1.0], [-1.0], [1.0]]),
                turn=np.array([[-1.0], [1.0]]),
                entry=np.where(sign < 0, entry + 10, entry),
                D=self.D[:, None],
                S0=None if self.S0 is None else self.S0[:, None],
            )
        return self._g

    def strain_energy(self, u, dt=None, state=None):
        """Stored (elastic) energy sum_e L0 sum_k S_k^2 / (2 D_k); elastic case: L0 D E^2 / 2
        (viscoplastic: the resultants of a step of dt from the committed plastic strains).
        All integration points in one pass, the rows of internal_coo."""
        g = self._gauss()
        S = self._resultants(self._row_strains(u, g)[0], g, dt, state)[0]
        return float((g["wL0"] * (S * S / g["D2"])).sum())

    def start(self, u):
        """The internal variables at the initial state: no plastic strain (None if elastic)."""
        return None if self.S0 is None else self._ep0

    def commit(self, u, dt=None, state=None):
        """The internal variables after a step of dt converged at u from ``state``: the plastic
        strains (None if elastic). The beam keeps nothing."""
        if self.S0 is None:
            return None
        return np.concatenate(
            [self.resultants(u, xi, k, dt=dt, state=state)[2] for k, (xi, _) in enumerate(self.points)]
        )

    @property
    def mesh(self):
        """scikit-fem's MeshLine in the reference arc length s (made on first use)."""
        if self._mesh is None:
            self._mesh = skfem.MeshLine(self.s)
        return self._mesh

    def _inertias(self):
        """Mass per unit length of each dof kind: rho A on u_x and u_y, rho I on theta (0 without
        rotary inertia)."""
        return self.rho * np.array([self.A, self.A, self.I if self.rotary_inertia else 0.0])

    def mass(self, consistent=False):
        """The lumped mass, (ndof,): rho A per length on u_x, u_y and rho I per length on theta (half
        to each node; 0 on theta without rotary inertia), the row sums of the P1 mass matrix on the
        arc-length mesh (L0/2 per element end).

        ``consistent=True``: that P1 mass matrix itself, a CSR matrix (ndof, ndof): per element and
        dof kind (u_x, u_y, theta; the interpolation is linear in s for all three)
        rho (A or I) L0 / 6 [[2, 1], [1, 2]]; the rotations are not coupled to the translations.
        """
        if consistent:
            a, b = self.conn.T
            rows, cols, vals = [], [], []
            for k, m in enumerate(self._inertias()):
                i, j, e = 3 * a + k, 3 * b + k, m * self.L0 / 6.0
                rows += [i, i, j, j]
                cols += [i, j, i, j]
                vals += [2 * e, e, e, 2 * e]
            return sp.coo_matrix(
                (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(self.ndof, self.ndof)
            ).tocsr()
        if self._mass is None:  # computed once, then reused
            length = np.bincount(self.conn.ravel(), np.repeat(0.5 * self.L0, 2), minlength=self.X.shape[0])
            J = self.I * length if self.rotary_inertia else 0.0 * length
            self._mass = (self.rho * np.column_stack([self.A * length, self.A * length, J])).ravel()
        return self._mass.copy()

    # ---- surface offset (for contact on the outer face of a ring) -------------------
    def _node_angle0(self):
        """Reference tangent angle at the nodes: bisector of the adjacent element angles."""
        nn, th = self.X.shape[0], self.theta0
        if self.closed:
            left, right = th[np.arange(nn) - 1], th
        else:
            left, right = th[np.r_[0, np.arange(nn - 1)]], th[np.r_[np.arange(nn - 1), nn - 2]]
        return left + 0.5 * ((right - left + np.pi) % (2 * np.pi) - np.pi)

    def offset_positions(self, u, h):
        """Node positions offset by h along the current normal n(psi0 + theta), (nn, 2).

        psi0: reference nodal tangent angle (bisector of the neighbouring elements).
        """
        U = np.asarray(u, float).reshape(-1, 3)
        psi = self._node_angle0() + U[:, 2]
        return self.X + U[:, :2] + h * np.column_stack([-np.sin(psi), np.cos(psi)])

    def offset_jacobian(self, u, h):
        """d(offset position)/d(u_x, u_y, theta) per node, (nn, 2, 3): [I | -h t(psi0 + theta)]."""
        U = np.asarray(u, float).reshape(-1, 3)
        psi = self._node_angle0() + U[:, 2]
        J = np.zeros((U.shape[0], 2, 3))
        J[:, 0, 0] = J[:, 1, 1] = 1.0
        J[:, 0, 2], J[:, 1, 2] = -h * np.cos(psi), -h * np.sin(psi)
        return J


class BeamGravity:
    """Dead gravity load on a beam: P = m_lumped * g on the (u_x, u_y) dofs.

    g: a 2-vector (g_x, g_y), or a number meaning (0, -g).
    """

    def __init__(self, beam, g):
        g = np.array([0.0, -float(g)]) if np.ndim(g) == 0 else np.asarray(g, float)
        if g.shape != (2,) or not np.all(np.isfinite(g)):
            raise ValueError(f"parameter g must be a finite number or 2-vector, got {g!r}")
        self.beam, self.g = beam, g
        self._P = (None, None)  # (where, triplets): P made for one place of the beam

    def start(self, u, t=0.0, offsets=None):
        """A dead load has no state."""
        return None

    def commit(self, u, t, state=None, offsets=None):
        """A dead load keeps no history."""
        return state

    def assemble(self, u_global, t, state=None, offsets=None):
        """(P, rows, cols, vals): the dead load and an empty tangent. P is made once for the
        beam's place in the global vector (read-only: a dead load does not change; a pure
        function of the beam and the vector's size)."""
        b = self.beam
        where = (start_of(b, offsets), np.size(u_global))
        if self._P[0] != where:
            P = np.zeros(where[1])
            P[where[0] + b.xdofs] = b.mass()[b.xdofs] * self.g
            empty_i, empty_v = np.zeros(0, dtype=int), np.zeros(0)
            for a in (P, empty_i, empty_v):
                a.flags.writeable = False
            self._P = (where, (P, empty_i, empty_i, empty_v))
        return self._P[1]
