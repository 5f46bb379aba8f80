"""2D segment-to-segment mortar contact with penalty enforcement: the kernel
(beyond the paper, whose contact is node-to-segment; the interface laws and the return
map are the paper's, Secs 2 and 4.2.3).

Pure functions over numpy arrays, vectorised over segment pairs. Positions are the
current ones, x = X + u: a slave chain xs (ns, 2) and a master chain xm (nm, 2), both
ordered so that n = e3 x t points out of their body (contact/segmentation.py). The
kernel's unknowns are the interface dofs: slave node i -> (2i, 2i + 1), master node
k -> (2 ns + 2k, 2 ns + 2k + 1); the caller maps them to global dofs (and drops a rigid
master's).

Multipliers: standard Lagrange multipliers, Phi_j = N_j, the slave's own linear shape
functions (as in the penalty mortar methods of Puso & Laursen, CMAME 193, 2004, and
Yang, Laursen & Meng, IJNME 62, 2005). Dual multipliers (Wohlmuth, SIAM J Numer Anal
38, 2000; Popp, Gee & Wall, IJNME 79, 2009: Phi_1 = 2 - 3 xi, Phi_2 = 3 xi - 1 on
[0, 1]) would make D diagonal, but they change sign: the weighted gap of a node can be
negative while the whole surface is open, and on a partly covered segment (the edge of
the contact zone, a master end) the weights int Phi_j vanish or turn negative unless the
basis is modified there. With N_j the weights are positive and the nodal gap below is a
true average of the pointwise gap.

Mortar integrals. Each pair p (slave segment e = a-b, master segment c-d) is integrated
over its overlap [xi_lo, xi_hi] (segmentation.py) with dGamma = l dxi:

    D^p_jk = int N_j N_k dGamma             (j, k = a, b)      slave-slave
    M^p_jl = int N_j N_l(eta) dGamma        (l = c, d)         slave-master
    w^p_j  = int N_j dGamma = sum_k D^p_jk                      nodal weight

Every integrand is a polynomial of degree <= 2 in xi (eta(xi) is affine), so the two
Gauss points per overlap integrate them exactly. Summed over the pairs of node j:
D_jk, M_jl and w_j (the covered length of node j).

Weighted gap (the form of Popp, Gee & Wall 2009, with our segment normal n_e):

    g~_j = int N_j g dGamma = sum_p n_e . ( M^p_jl x_l - D^p_jk x_k )

(an identity: x_m(eta) - x_s(xi) = g n_e on each pair).

Weighted slip increment (frame-indifferent; Gitterle, Popp, Gee & Wall, IJNME 84, 2010):
theirs is, up to its sign, t_j . [ (D_jk - D_bar_jk) x_k - (M_jl - M_bar_jl) x_l ] with
D_bar, M_bar the integrals of the last converged configuration, x the current positions
and t_j a nodal tangent. Taken per
converged pair p with its slave tangent t_e, the part with the current D, M vanishes
identically (t_e . (x_s - x_m) = 0 on a pair), which leaves

    g~_T,j = sum over converged pairs p of j:  t_e . ( D_bar^p_jk x_k - M_bar^p_jl x_l ),

the weighted tangential distance, now, of each slave point from the master material
point it faced at the end of the last step; positive when the slave moves along its own
tangent t relative to the master. A rigid motion of both bodies leaves it unchanged
(only differences of current positions and the current t_e enter).

Penalty (c_N, c_T keep their meaning of tractions per unit gap, per unit length):

    g_N,j       = g~_j / w_j - o_j              average gap of node j (o_j: a surface offset)
    t_N,j       = normal law at g_N,j           (eq 4: t_N = -c_N <-g_N> for m = 1)
    Delta g_T,j = g~_T,j / w_bar_j              (w_bar_j: node j's converged weight)
    t_T,j       = return map at (t_N,j, Delta g_T,j)       (eqs 40-48, laws/return_map.py)

Residual: the virtual work of the traction field t_N,h n + t_T,h t (t_N,h = sum_j N_j
t_N,j) on the relative virtual displacement (as Popp, Gee & Wall 2009 write it):

    R = sum_j t_N,j f_N,j + t_T,j f_T,j,
    f_N,j = d/dx [ n_e . (M^p_jl x_l - D^p_jk x_k) ] with D, M, n_e held:   -D_jk n_e (slave), +M_jl n_e (master)
    f_T,j = d/dx [ t_e . (D^p_jk x_k - M^p_jl x_l) ] with D, M, t_e held:   +D_jk t_e (slave), -M_jl t_e (master)

summed over the current pairs of j. On a flat interface a uniform traction gives the
consistent nodal loads on both meshes whatever the gap: the contact patch test holds,
also with the penalty's gap (node-to-segment fails it). Tangent (contact_forces): the moduli times the linearised
gap and slip,
plus the tractions times Delta f (Delta D, Delta M, Delta n_e, Delta t_e, including the
moving overlap ends), all exact through the jets of contact/variations.py.

Exact here: the segmentation and all mortar integrals for straight segments; the
tangent (to round-off, checked by central differences). Modelling choices: the slave
segment normal (strips of width about |g| theta missed or doubled at slave kinks,
segmentation.py); the nodal average gap and the penalty; the slip measured against the
converged integrals and divided by the converged weight (exact for a rigid relative
slide; a node that faced no master at the end of the last step starts with zero slip).
Everything above lives in the current configuration (finite deformation): next to a
geometrically linear bulk the contact lengths, hence the tractions, differ from the
small-strain ones by the strain along the surface.

Small kinematics (``linearised``, ``linear_slip``): the geometrically linear form for a
small-strain bulk. The segmentation, D, M, n_e and t_e are computed once, in the
reference configuration X, and held; the weighted gap and slip are then linear in the
positions x = X + u,

    g~_j   = sum_p n_e . (M^p_jl x_l - D^p_jk x_k)  = F_N,j . x       (dg~ = F_N, dw = 0)
    g~_T,j = sum_p t_e . (D^p_jk x_k - M^p_jl x_l)  = F_T,j . (x - x_bar)

(F_T,j . X = 0: on a reference pair x_m(eta) - x_s(xi) is along n_e), and the residual
R = sum_j t_N,j F_N,j + t_T,j F_T,j has no geometric part (Delta f = 0). This is the
contact of the small-strain theory (Hertz's, the patch test's): tractions act on the
reference surfaces, like the bulk's dead loads.
"""

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from .. import lazy
from ..laws.friction import Frictionless
from ..laws.protocol import as_friction_law
from ..laws.return_map import return_map
from .element import to_coo
from .segmentation import gap_at, overlap, pair_geometry

sparse = lazy.module("scipy.sparse")

if TYPE_CHECKING:  # the fields' type, for the type checker; scipy is loaded on first use
    from scipy.sparse import csr_matrix

FRICTIONLESS = as_friction_law(Frictionless())

# two-point Gauss rule on [0, 1]: exact for polynomials of degree <= 3
GAUSS_POINTS = (0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0))
GAUSS_WEIGHTS = (0.5, 0.5)


@dataclass(frozen=True)
class Pairs:
    """Slave segment / master segment pairs: segment indices, the two slave nodes of each
    pair (np, 2) and the pair's eight interface dofs (x_a, x_b, x_c, x_d) (np, 8)."""

    slave: np.ndarray
    master: np.ndarray
    nodes: np.ndarray
    dofs: np.ndarray

    @staticmethod
    def of(slave_segments, master_segments, ns):
        """The pairs of slave segments (i, i+1) and master segments (k, k+1) in a chain of ns slave nodes."""
        s = np.asarray(slave_segments, dtype=int)
        m = np.asarray(master_segments, dtype=int)
        nodes = np.stack([s, s + 1], axis=1)
        both = np.concatenate([nodes, np.stack([m, m + 1], axis=1) + ns], axis=1)  # interface nodes a, b, c, d
        dofs = np.stack([2 * both, 2 * both + 1], axis=2).reshape(len(s), 8)
        return Pairs(s, m, nodes, dofs)

    def __len__(self):
        return len(self.slave)

    def positions(self, xs, xm):
        """x_a, x_b, x_c, x_d of every pair."""
        return xs[self.slave], xs[self.slave + 1], xm[self.master], xm[self.master + 1]


@dataclass(frozen=True)
class MortarIntegrals:
    """The mortar quantities of the current pairs.

    Per node (ns,):  w (weights), g (weighted gaps g~), and their gradients dw, dg as
                     sparse (ns, n) matrices over the n interface dofs.
    Per pair:        D, M (np, 2, 2) (rows: local slave node a, b; columns a, b resp. c, d);
                     f_N, f_T (np, 2, 8): the virtual-work vectors of local node a, b over
                     the pair's dofs, and df_N, df_T (np, 2, 8, 8) their linearisations."""

    pairs: Pairs
    w: np.ndarray
    g: np.ndarray
    dw: "csr_matrix"
    dg: "csr_matrix"
    D: np.ndarray
    M: np.ndarray
    f_N: np.ndarray
    df_N: np.ndarray
    f_T: np.ndarray
    df_T: np.ndarray


@dataclass(frozen=True)
class WeightedSlip:
    """The weighted slip increment g~_T (ns,) and its gradient (ns, n), from the converged pairs."""

    pairs: Pairs
    g_T: np.ndarray
    dg_T: "csr_matrix"


def _nodal(jets, pairs, ns, n):
    """Sum each pair's two jets (local slave nodes a, b) into the slave nodes: values
    (ns,) and gradients, a sparse (ns, n) matrix."""
    val = sum(np.bincount(pairs.nodes[:, i], jets[i].val, minlength=ns) for i in range(2))
    rows = np.concatenate([np.repeat(pairs.nodes[:, i], 8) for i in range(2)])
    cols = np.concatenate([pairs.dofs.ravel()] * 2)
    vals = np.concatenate([jets[i].grad.ravel() for i in range(2)])
    return val, sparse.csr_matrix((vals, (rows, cols)), shape=(ns, n))


def pair_integrals(geo, lo, hi):
    """D_ik, M_ik and g~_i of each pair as jets (i: local slave node a, b; k: a, b for D,
    c, d for M), by two-point Gauss quadrature on the overlap [lo, hi]: exact, since the
    integrands have degree <= 2 in xi (N_s and N_m(eta(xi)) are linear, g(xi) is linear)."""
    D = [[0.0, 0.0], [0.0, 0.0]]
    M = [[0.0, 0.0], [0.0, 0.0]]
    g = [0.0, 0.0]
    for zeta, omega in zip(GAUSS_POINTS, GAUSS_WEIGHTS):
        xi = lo + (hi - lo) * zeta  # the Gauss point on the overlap
        dGamma = geo["l"] * (hi - lo) * omega  # l dxi
        g_xi, eta = gap_at(geo, xi)
        N_s = (1.0 - xi, xi)  # slave shape functions = Phi_j
        N_m = (1.0 - eta, eta)  # master shape functions at eta(xi)
        for i in range(2):
            g[i] = N_s[i] * g_xi * dGamma + g[i]
            for k in range(2):
                D[i][k] = N_s[i] * N_s[k] * dGamma + D[i][k]
                M[i][k] = N_s[i] * N_m[k] * dGamma + M[i][k]
    return D, M, g


def virtual_work_vectors(D, M, ex, ey):
    """For each local slave node i of a pair, the vector over its dofs (x_a, x_b, x_c, x_d)

        d/dx [ e . (D_ik x_k - M_il x_l) ]  with D, M, e held  =  (D_ia e, D_ib e, -M_ic e, -M_id e)

    (e = t_e gives f_T, e = n_e gives -f_N): values (np, 2, 8) and their linearisations
    (np, 2, 8, 8), which carry Delta D, Delta M and Delta e."""
    values, grads = [], []
    for i in range(2):
        parts = [
            D[i][0] * ex,
            D[i][0] * ey,
            D[i][1] * ex,
            D[i][1] * ey,
            -M[i][0] * ex,
            -M[i][0] * ey,
            -M[i][1] * ex,
            -M[i][1] * ey,
        ]
        values.append(np.stack([f.val for f in parts], axis=1))
        grads.append(np.stack([f.grad for f in parts], axis=1))
    return np.stack(values, axis=1), np.stack(grads, axis=1)


def _values(A):
    """A 2 x 2 list of jets -> their values (np, 2, 2)."""
    return np.stack([np.stack([A[i][k].val for k in range(2)], axis=1) for i in range(2)], axis=1)


def mortar_integrals(xs, xm, pairs, unbounded=False):
    """The mortar quantities of the pairs (module docstring): segmentation, integrals,
    nodal weights and weighted gaps, virtual-work vectors and their linearisations."""
    ns, n = len(xs), 2 * (len(xs) + len(xm))
    geo = pair_geometry(*pairs.positions(xs, xm))
    lo, hi = overlap(geo["xi_c"], geo["xi_d"], unbounded)
    D, M, g = pair_integrals(geo, lo, hi)
    w = [D[i][0] + D[i][1] for i in range(2)]  # int N_i = int N_i (N_a + N_b)
    minus_f_N, minus_df_N = virtual_work_vectors(D, M, geo["nx"], geo["ny"])
    f_T, df_T = virtual_work_vectors(D, M, geo["tx"], geo["ty"])
    w_val, dw = _nodal(w, pairs, ns, n)
    g_val, dg = _nodal(g, pairs, ns, n)
    return MortarIntegrals(pairs, w_val, g_val, dw, dg, _values(D), _values(M), -minus_f_N, -minus_df_N, f_T, df_T)


def weighted_slip(xs, xm, pairs_bar, D_bar, M_bar):
    """The weighted slip increment g~_T,j = sum_p t_e . (D_bar^p_jk x_k - M_bar^p_jl x_l)
    over the converged pairs (module docstring), and its gradient."""
    ns, n = len(xs), 2 * (len(xs) + len(xm))
    geo = pair_geometry(*pairs_bar.positions(xs, xm))
    ax, ay, bx, by, cx, cy, dx, dy = geo["v"]
    g_T = []
    for i in range(2):
        rx = D_bar[:, i, 0] * ax + D_bar[:, i, 1] * bx - M_bar[:, i, 0] * cx - M_bar[:, i, 1] * dx
        ry = D_bar[:, i, 0] * ay + D_bar[:, i, 1] * by - M_bar[:, i, 0] * cy - M_bar[:, i, 1] * dy
        g_T.append(geo["tx"] * rx + geo["ty"] * ry)
    val, grad = _nodal(g_T, pairs_bar, ns, n)
    return WeightedSlip(pairs_bar, val, grad)


def mortar_matrices(mi, nm):
    """The assembled mortar matrices D (ns, ns) and M (ns, nm), sparse (for reporting and
    checks; the residual uses the pairs' virtual-work vectors)."""
    p, ns = mi.pairs, len(mi.w)
    rows = np.repeat(p.nodes, 2, axis=1).ravel()  # node of i for (p, i, k)
    D = sparse.csr_matrix((mi.D.ravel(), (rows, np.tile(p.nodes, (1, 2)).ravel())), shape=(ns, ns))
    master_nodes = np.stack([p.master, p.master + 1], axis=1)
    M = sparse.csr_matrix((mi.M.ravel(), (rows, np.tile(master_nodes, (1, 2)).ravel())), shape=(ns, nm))
    return D, M


def nodal_gap(mi, offset=0.0):
    """The average gap of each slave node and its gradient:

        g_N,j  = g~_j / w_j - o_j,       dg_N,j = (dg~_j - (g_N,j + o_j) dw_j) / w_j

    A node no master segment faces (w_j = 0) is open: g_N = +inf, zero gradient.
    Returns (g_N, covered, dg_N) with dg_N sparse (ns, n)."""
    ns = len(mi.w)
    o = np.broadcast_to(np.asarray(offset, dtype=float), (ns,))
    covered = mi.w > 0.0
    w = np.where(covered, mi.w, 1.0)
    g_avg = np.where(covered, mi.g / w, 0.0)
    g_N = np.where(covered, g_avg - o, np.inf)
    dg_N = sparse.diags(np.where(covered, 1.0 / w, 0.0)) @ (mi.dg - sparse.diags(g_avg) @ mi.dw)
    return g_N, covered, dg_N.tocsr()


def slip_increment(slip, w_bar):
    """Delta g_T,j = g~_T,j / w_bar_j: the slip of node j (0 where w_bar_j = 0: the node
    faced no master at the end of the last step). Returns it and 1 / w_bar (0 there)."""
    inv = np.where(w_bar > 0.0, 1.0 / np.where(w_bar > 0.0, w_bar, 1.0), 0.0)
    return slip.g_T * inv, inv


class NormalLawError(ValueError):
    """A normal law returned a non-finite or unphysical traction."""


def penalty_tractions(normal, friction, g_N, dg_T, t_T_bar, q_bar, z_bar=None, dt=None):
    """Nodal tractions of the penalty method: t_N, dt_N/dg_N from the normal law at the
    average gaps (eq 4: t_N = -c_N <-g_N> for the penalty), zero at open nodes; then the
    return map (eqs 40-48) on the nodal slip increments. friction None: frictionless.
    Returns (t_N, dt_N, FrictionState)."""
    closed = g_N < 0.0  # +inf (uncovered) is open
    t_N, dt_N = normal.traction(np.where(closed, g_N, 1.0))
    t_N, dt_N = np.where(closed, t_N, 0.0), np.where(closed, dt_N, 0.0)
    bad = ~np.isfinite(t_N) | ~np.isfinite(dt_N) | (t_N > 0.0)
    if np.any(bad):
        j = int(np.flatnonzero(bad)[0])
        raise NormalLawError(
            f"normal law {type(normal).__name__}.traction returned t_N = {t_N[j]!r}, "
            f"dt_N = {dt_N[j]!r} at slave node {j} (g_N = {g_N[j]!r}): a contact traction "
            "must be finite and <= 0"
        )
    law = FRICTIONLESS if friction is None else as_friction_law(friction)
    slip = np.zeros_like(g_N) if friction is None else dg_T
    fr = return_map(law, t_N, dt_N, slip, t_T_bar, q_bar, z_bar=z_bar, dt=dt)
    return t_N, dt_N, fr


def _pair_rows(vectors, pairs, ns, n):
    """The pairs' per-node vectors (np, 2, 8) summed into a sparse (ns, n) matrix."""
    rows = np.repeat(pairs.nodes, 8, axis=1).ravel()
    cols = np.tile(pairs.dofs, (1, 2)).ravel()
    return sparse.csr_matrix((vectors.ravel(), (rows, cols)), shape=(ns, n))


def contact_forces(mi, t_N, dt_N, offset=0.0, slip=None, friction=None, w_bar=None):
    """The contact residual and its consistent tangent over the interface dofs:

        R = sum_j t_N,j f_N,j + t_T,j f_T,j
        K = sum_j f_N,j (dt_N,j Delta g_N,j) + f_T,j (c_T^s,j Delta g~_T,j / w_bar_j + c_N^s,j Delta g_N,j)
                  + t_N,j Delta f_N,j + t_T,j Delta f_T,j

    (K[r, c] = dR_r/du_c; c_T^s, c_N^s: the return map's moduli, eq 48). ``slip``
    (WeightedSlip), ``friction`` (FrictionState) and ``w_bar`` are left out for
    frictionless contact. Returns R (n,) and COO triplets (rows, cols, vals), whose
    repeated indices add up (as in a COO matrix)."""
    p, ns = mi.pairs, len(mi.w)
    n = mi.dg.shape[1]
    _, _, dg_N = nodal_gap(mi, offset)
    F_N = _pair_rows(mi.f_N, p, ns, n)
    R = F_N.T @ t_N
    K = F_N.T @ sparse.diags(dt_N) @ dg_N
    blocks = sum(t_N[p.nodes[:, i], None, None] * mi.df_N[:, i] for i in range(2))
    if slip is not None:
        _, inv_w_bar = slip_increment(slip, w_bar)
        F_T = _pair_rows(mi.f_T, p, ns, n)
        R = R + F_T.T @ friction.t_T
        K = K + F_T.T @ (sparse.diags(friction.c_T_s * inv_w_bar) @ slip.dg_T + sparse.diags(friction.c_N_s) @ dg_N)
        blocks = blocks + sum(friction.t_T[p.nodes[:, i], None, None] * mi.df_T[:, i] for i in range(2))
    K = K.tocoo()
    rows, cols, vals = to_coo(p.dofs, blocks) if len(p) else (np.zeros(0, int),) * 2 + (np.zeros(0),)
    return np.asarray(R).ravel(), (
        np.concatenate([rows, K.row]),
        np.concatenate([cols, K.col]),
        np.concatenate([vals, K.data]),
    )


def linearised(mi, x):
    """The mortar quantities of small kinematics (module docstring): the integrals ``mi``
    of the reference configuration held, the weighted gap linear in the positions x (n,)
    of the interface dofs, g~ = F_N x with gradient F_N; the weights and the virtual-work
    vectors constant (dw = 0, df_N = df_T = 0)."""
    p, ns = mi.pairs, len(mi.w)
    n = mi.dg.shape[1]
    F_N = _pair_rows(mi.f_N, p, ns, n)
    return replace(
        mi, g=F_N @ x, dg=F_N, dw=sparse.csr_matrix((ns, n)), df_N=np.zeros_like(mi.df_N), df_T=np.zeros_like(mi.df_T)
    )


def linear_slip(mi, x, x_bar):
    """The weighted slip increment of small kinematics, g~_T = F_T (x - x_bar), and its
    gradient F_T (module docstring); x_bar: the interface positions of the last converged step."""
    p, ns = mi.pairs, len(mi.w)
    F_T = _pair_rows(mi.f_T, p, ns, len(x))
    return WeightedSlip(p, F_T @ (x - x_bar), F_T)
