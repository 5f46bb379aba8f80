"""Segmentation of 2D mortar contact: which parts of a slave segment face which master
segment, and where (beyond the paper: the paper's contact is node-to-segment).

Slave surface: a chain of straight segments a-b of a deformable body, ordered so that
n = e3 x t (t = (x_b - x_a)/l) points out of the slave body, as the masters of
contact/masters.py are ordered. Master: a chain of straight segments c-d ordered the
same way (its normal points out of the master, towards the slave), of a deformable
body or fixed; a rigid straight line is one master segment through two of its points
that is not clipped at its ends (``unbounded``).

The projection (our choice, argued here): every point of a slave segment looks for the
master along the segment's own normal n. The gap at slave coordinate xi in [0, 1],
x_s(xi) = (1 - xi) x_a + xi x_b, is the distance along n to the master segment's line:

    x_s(xi) + g(xi) n  lies on c-d,    g > 0 open, g < 0 penetration.

Because n is constant on the segment, projecting along n is an affine map: the master
ends land at

    xi_c = (x_c - x_a).t / l,   g_c = (x_c - x_a).n       (and likewise xi_d, g_d),

the node-to-segment projection of eqs (17), (19) with the roles swapped (a master end
projected onto the slave segment), and the master coordinate eta (x_m = (1 - eta) x_c +
eta x_d) and the gap are affine in xi:

    eta(xi) = (xi - xi_c) / (xi_d - xi_c),    g(xi) = (1 - eta) g_c + eta g_d.

Clipping: the part of the slave segment a master segment covers is the interval
[xi_lo, xi_hi] = [max(0, min(xi_c, xi_d)), min(1, max(xi_c, xi_d))] (all of [0, 1] for an
unbounded line). Its ends move with the unknowns through xi_c, xi_d: that is the
linearisation of the segmentation, carried exactly by the jets (contact/variations.py).

Why the segment normal and not the continuous averaged nodal normal of Popp, Gee & Wall
(IJNME 79, 2009): with the segment normal the maps eta(xi) and g(xi) are affine, so every
mortar integrand is a polynomial of degree <= 2 in xi and two Gauss points integrate it
exactly, and the linearisations are those of a handful of closed-form quantities
(above). It is the 2D form of what the mortar segment-to-segment method of Puso &
Laursen (CMAME 193, 2004) does on flat facets: project onto the slave facet's plane along
its normal. The price: the normal jumps at a slave node where the chain kinks by an
angle theta, so a master strip of width about |g| theta beside that node is covered by
both neighbouring segments (slave concave) or by neither (slave convex). The strip
vanishes with the gap (exactly when the slave node sits on the master); on a flat slave
surface there is none. The averaged nodal normal avoids it but makes eta(xi) rational
(quadrature then approximate, projections by local Newton iterations).

A slave segment and a master segment form a pair when they face each other (n . n_m < 0)
and their overlap has positive length; the search is a brute-force test of all
segment pairs (vectorised; fine for the surfaces of teaching meshes). A master chain
must be seen once from the slave surface (no folds facing the same slave part).
"""

import numpy as np

from .kinematics import e3_cross
from .variations import Jet


def segment_frames(x, name="chain"):
    """Length l, unit tangent t and normal n = e3 x t of each segment of the chain x (n, 2).
    Raises ValueError for a segment of zero length (two nodes coincide)."""
    a = np.diff(x, axis=0)
    l = np.linalg.norm(a, axis=1)
    if np.any(~(l > 1e-14 * (1.0 + np.abs(x).max(initial=0.0)))):
        raise ValueError(f"{name} segment {int(np.argmin(l))} has zero length (degenerate): its two nodes coincide")
    t = a / l[:, None]
    return l, t, e3_cross(t)


def candidate_pairs(xs, xm, unbounded=False, search=np.inf):
    """The (slave segment, master segment) pairs that face each other with an overlap
    of positive length. xs (ns, 2) slave chain, xm (nm, 2) master chain (current positions).
    ``search``: pairs whose gap exceeds it at both ends of the overlap are left out.
    Returns (slave_segment, master_segment), index arrays of equal length."""
    l, t, n = segment_frames(xs, "slave")
    _, _, n_m = segment_frames(xm, "master")
    d_c = xm[None, :-1, :] - xs[:-1, None, :]  # (slave seg, master seg, 2)
    d_d = xm[None, 1:, :] - xs[:-1, None, :]
    xi_c = np.einsum("ekx,ex->ek", d_c, t) / l[:, None]
    xi_d = np.einsum("ekx,ex->ek", d_d, t) / l[:, None]
    g_c = np.einsum("ekx,ex->ek", d_c, n)
    g_d = np.einsum("ekx,ex->ek", d_d, n)
    facing = (n @ n_m.T) < 0.0
    if unbounded:
        lo, hi = np.zeros_like(xi_c), np.ones_like(xi_c)
    else:
        lo = np.maximum(0.0, np.minimum(xi_c, xi_d))
        hi = np.minimum(1.0, np.maximum(xi_c, xi_d))
    keep = facing & (hi > lo)
    if np.isfinite(search):
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = (g_d - g_c) / (xi_d - xi_c)
        g_lo, g_hi = g_c + slope * (lo - xi_c), g_c + slope * (hi - xi_c)
        keep &= np.minimum(g_lo, g_hi) <= search
    return np.nonzero(keep)


def pair_geometry(xa, xb, xc, xd):
    """The master segment c-d seen from the slave segment a-b, as jets over the pair's
    eight unknowns v = (x_a, x_b, x_c, x_d) (each (np, 2)):

        l = |x_b - x_a|,  t = (x_b - x_a)/l,  n = e3 x t               (eq 18 on the slave)
        xi_c = (x_c - x_a).t / l,  g_c = (x_c - x_a).n                   (eqs 19, 17, swapped)
        xi_d = (x_d - x_a).t / l,  g_d = (x_d - x_a).n

    Returns a dict of jets: l, tx, ty, nx, ny, xi_c, g_c, xi_d, g_d, and v: the eight
    coordinates (ax, ay, bx, by, cx, cy, dx, dy) themselves."""
    ax, ay, bx, by, cx, cy, dx, dy = Jet.variables(np.concatenate([xa, xb, xc, xd], axis=1))
    ex, ey = bx - ax, by - ay
    l = (ex * ex + ey * ey).sqrt()
    tx, ty = ex / l, ey / l
    nx, ny = -ty, tx  # n = e3 x t, out of the slave
    xi_c = ((cx - ax) * tx + (cy - ay) * ty) / l
    g_c = (cx - ax) * nx + (cy - ay) * ny
    xi_d = ((dx - ax) * tx + (dy - ay) * ty) / l
    g_d = (dx - ax) * nx + (dy - ay) * ny
    return dict(
        l=l, tx=tx, ty=ty, nx=nx, ny=ny, xi_c=xi_c, g_c=g_c, xi_d=xi_d, g_d=g_d, v=(ax, ay, bx, by, cx, cy, dx, dy)
    )


def overlap(xi_c, xi_d, unbounded=False):
    """The clipping: [xi_lo, xi_hi] = [max(0, min(xi_c, xi_d)), min(1, max(xi_c, xi_d))],
    as jets (an end that is a slave node is a constant; an end that is a projected
    master node moves with it). An unbounded master (a rigid line) covers [0, 1]."""
    if unbounded:
        return xi_c._lift(0.0), xi_c._lift(1.0)
    c_first = xi_c.val < xi_d.val
    first = Jet.where(c_first, xi_c, xi_d)
    last = Jet.where(c_first, xi_d, xi_c)
    return Jet.where(first.val > 0.0, first, 0.0), Jet.where(last.val < 1.0, last, 1.0)


def gap_at(geo, xi):
    """The gap along the slave normal at slave coordinate xi (a jet or a number) and the
    master coordinate facing it: g(xi) = (1 - eta) g_c + eta g_d, eta = (xi - xi_c)/(xi_d - xi_c).
    Returns (g, eta)."""
    eta = (xi - geo["xi_c"]) / (geo["xi_d"] - geo["xi_c"])
    return geo["g_c"] + eta * (geo["g_d"] - geo["g_c"]), eta
