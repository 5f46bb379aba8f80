"""Master surfaces: where a slave node touches, and how the gap and the arc
coordinate vary with the unknowns.

Every master answers one question for an array of slave positions x_s (nc, 2):
``locate(x_s, s_bar, u, t=None, ref=None, offsets=None)`` returns the contact kinematics of each slave
with its closest master segment (or point of a smooth obstacle) at time t (a moving rigid
obstacle), in the metric of ``ref`` (what ``reference(u)`` gave at the last converged
state: a deformable master's node positions; None for a rigid master); ``offsets``: where
the bodies' dofs start in u (a System's, contact/placement.py; a deformable master's only):

    g_N (nc,), s (nc,)        gap (eq 17) and arc coordinate of the projection
    dg_N, ds (nc, k)          first variations w.r.t. the pair's dofs (eq 27)
    d2g_N, d2s (nc, k, k)     second variations (eqs 31-32, 37-38)
    master_dofs (nc, k - 2)   global dofs of the master nodes (none for rigid masters)
    inside (nc,) bool         the projection falls on the master
    seg (nc,) int             segment index (-1 for smooth obstacles)
    s_next (nc,)              deformable master: s in the metric of the current configuration
                              (the next s_bar once this state is committed); rigid: s

Masters hold no state: what they remember between steps is ``reference(u)``, kept in the
contact's history (contact/state.py).

The first two dofs of each pair are the slave's. The tangential slip increment of
eq (20) is Delta g_T = s - s_bar: s is measured along the master in the metric of
the last converged configuration, s = S_bar[j] + alpha l_bar[j] on segment j
(S_bar: converged arc length up to node j), so a slave that moves on to a
neighbouring segment keeps its friction history.
"""

import copy
from functools import lru_cache

import numpy as np

from .kinematics import arc_variations, e3_cross, line_variations, segment_variations
from .placement import start_of


@lru_cache(maxsize=16)
def rigid_fields(nc):
    """What every rigid master without segments answers for nc slaves: no master dofs
    (nc, 0), every projection inside, segment -1. Made once per nc and read-only (a
    state holds them as values; nothing writes them)."""
    fields = dict(master_dofs=np.zeros((nc, 0), dtype=int), inside=np.ones(nc, bool), seg=np.full(nc, -1))
    for a in fields.values():
        a.flags.writeable = False
    return fields


def _check_points(points, name):
    P = np.asarray(points, dtype=float)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) < 2:
        raise ValueError(f"parameter {name} must be an array of at least 2 points (shape (n, 2)), got shape {P.shape}")
    if np.any(np.linalg.norm(np.diff(P, axis=0), axis=1) <= 0.0):
        raise ValueError(f"parameter {name} has a zero-length (degenerate) segment: two consecutive points coincide")
    return P


def closest_segment(x_s, P):
    """Closest segment of the polyline P (m+1, 2) to each slave: the one at the
    smallest distance (to the clamped projection). Returns (j, inside) where inside
    is False when the projection falls beyond either end of the polyline."""
    a = P[1:] - P[:-1]
    l2 = np.einsum("ij,ij->i", a, a)
    d = x_s[:, None, :] - P[None, :-1, :]
    alpha = np.einsum("kij,ij->ki", d, a) / l2
    ac = np.clip(alpha, 0.0, 1.0)
    dist2 = np.sum((d - ac[..., None] * a) ** 2, axis=2)
    j = np.argmin(dist2, axis=1)
    aj = alpha[np.arange(len(x_s)), j]
    inside = ~(((j == 0) & (aj < 0.0)) | ((j == len(a) - 1) & (aj > 1.0)))
    return j, inside


def _arc_lengths(P):
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])


class RigidLine:
    """A fixed infinite straight line through `point` with unit `normal` pointing
    towards the slave body (the rigid foundation of Secs 5.1-5.3)."""

    rigid = True
    straight = True  # the second variations of g_N and s vanish (line_variations)

    def __init__(self, point=(0.0, 0.0), normal=(0.0, 1.0)):
        nrm = np.asarray(normal, dtype=float)
        if nrm.shape != (2,) or not np.linalg.norm(nrm) > 0:
            raise ValueError(f"parameter normal must be a non-zero 2-vector, got {normal!r}")
        self.point = np.asarray(point, dtype=float)
        self.normal = nrm / np.linalg.norm(nrm)

    def locate(self, x_s, s_bar, u, t=None, ref=None, offsets=None):
        k = line_variations(x_s, self.point, self.normal)
        k.update(rigid_fields(len(x_s)))
        return k

    def reference(self, u, offsets=None):
        return None

    def outline(self, extent=(-1.0, 1.0)):
        t = np.array([self.normal[1], -self.normal[0]])
        return np.array([self.point + extent[0] * t, self.point + extent[1] * t])


class RigidPolyline:
    """A fixed polyline through `points`, ordered so that n = e3 x t (to the left
    of the direction of travel) points towards the slave body. Node-to-segment
    with x_1, x_2 fixed: only the slave rows of eqs (25)-(38) remain."""

    rigid = True
    straight = True  # the second variations of g_N and s vanish (line_variations)

    def __init__(self, points):
        self.points = _check_points(points, "points")
        self.S = _arc_lengths(self.points)

    def reference(self, u, offsets=None):
        return None

    def locate(self, x_s, s_bar, u, t=None, ref=None, offsets=None):
        """Each slave against the fixed line of its closest segment j (eqs 17-19 with x_1, x_2
        fixed: line_variations), s = S[j] + (x_s - P_j).t_j."""
        P = self.points
        j, inside = closest_segment(x_s, P)
        a = P[j + 1] - P[j]
        t = a / np.linalg.norm(a, axis=1)[:, None]
        k = line_variations(x_s, P[j], e3_cross(t))
        return dict(k, s=self.S[j] + k["s"], master_dofs=np.zeros((len(x_s), 0), dtype=int), inside=inside, seg=j)

    def outline(self):
        return self.points


class RigidArc:
    """A fixed circular arc of radius R about `center`, covering angles
    theta0..theta1 (radians, counter-clockwise). inside=False: a rigid cylinder the
    slave touches from outside; inside=True: a hole or rounded fillet touched from
    within. Exact curvature terms (no polyline facets)."""

    rigid = True
    straight = False

    def __init__(self, center, R, theta0=-np.pi, theta1=np.pi, inside=False):
        if not float(R) > 0:
            raise ValueError(f"parameter R = {R!r} is out of range: allowed (0, inf)")
        if not theta1 > theta0:
            raise ValueError("parameters theta0 < theta1 required for a rigid arc")
        self.center = np.asarray(center, dtype=float)
        self.R, self.theta0, self.theta1, self.inside = float(R), float(theta0), float(theta1), bool(inside)

    def reference(self, u, offsets=None):
        return None

    def locate(self, x_s, s_bar, u, t=None, ref=None, offsets=None):
        theta_ref = np.asarray(s_bar, dtype=float) / self.R
        k = arc_variations(x_s, self.center, self.R, self.inside, theta_ref)
        th = k["theta"]
        # in range if some 2 pi shift of theta lies in [theta0, theta1]
        th0 = self.theta0 + np.mod(th - self.theta0, 2 * np.pi)
        inside = (th0 <= self.theta1) | (self.theta1 - self.theta0 >= 2 * np.pi - 1e-12)
        nc = len(x_s)
        return dict(k, master_dofs=np.zeros((nc, 0), dtype=int), inside=inside, seg=np.full(nc, -1))

    def outline(self, n=64):
        th = np.linspace(self.theta0, self.theta1, n)
        return self.center + self.R * np.stack([np.cos(th), np.sin(th)], axis=1)


class BodySurface:
    """A deformable master: the boundary of another body through its `nodes`,
    ordered so that n = e3 x t points out of the master body (towards the slave).
    All three nodes of each pair carry unknowns: the full 6x6 element of eqs (25)-(50)."""

    rigid = False
    straight = False

    def __init__(self, body, nodes):
        self.body = body
        self.nodes = np.asarray(nodes, dtype=int)
        if self.nodes.ndim != 1 or len(self.nodes) < 2:
            raise ValueError("parameter nodes of a master surface must list at least 2 nodes")
        _check_points(body.X[self.nodes], "master nodes (reference positions)")

    def dofs(self, offsets=None):
        """Global dofs of the master nodes (nm, 2), the body placed by ``offsets`` (placement.py)."""
        return start_of(self.body, offsets) + self.body.xdofs[self.nodes]

    def positions(self, u, offsets=None):
        return self.body.X[self.nodes] + u[self.dofs(offsets)]

    def reference(self, u, offsets=None):
        """The converged node positions x_bar: the metric (l_bar, S_bar) of the next step's s."""
        return self.positions(u, offsets)

    def locate(self, x_s, s_bar, u, t=None, ref=None, offsets=None):
        """Eqs (17)-(19), (27), (31)-(38) with the master nodes moving; s = S_bar[j] + alpha l_bar
        in the metric of ref (the converged positions x_bar; the reference positions if None)."""
        x_bar = self.body.X[self.nodes] if ref is None else ref
        P = self.positions(u, offsets)
        j, inside = closest_segment(x_s, P)
        k = segment_variations(x_s, P[j], P[j + 1])
        l_bar = np.linalg.norm(x_bar[j + 1] - x_bar[j], axis=1)
        S_bar = _arc_lengths(x_bar)
        dofs = self.dofs(offsets)
        return dict(
            g_N=k["g_N"],
            s=S_bar[j] + k["alpha"] * l_bar,
            t=k["t"],
            n=k["n"],
            dg_N=k["dg_N"],
            d2g_N=k["d2g_N"],
            ds=l_bar[:, None] * k["dalpha"],
            d2s=l_bar[:, None, None] * k["d2alpha"],
            master_dofs=np.concatenate([dofs[j], dofs[j + 1]], axis=1),
            inside=inside,
            seg=j,
            s_next=_arc_lengths(P)[j] + k["alpha"] * k["l"],
        )

    def outline(self, u=None, offsets=None):
        return self.body.X[self.nodes] if u is None else self.positions(u, offsets)


def _expand(mask, like):
    """A boolean mask (nc,) broadcast against an array (nc, ...)."""
    return mask.reshape((-1,) + (1,) * (np.ndim(like) - 1))


class RigidComposite:
    """A smooth rigid master made of straight lines and circular arcs joined end to end
    (e.g. a bottle neck: wall, rounded mouth, flat top). ``pieces`` in order of travel:

        ("line", start, end)                  n = e3 x t (eq 18), t = (end - start) / length
        ("arc", center, R, theta0, theta1)    from angle theta0 to theta1 (radians); n = e3 x t,
                                              so clockwise (theta1 < theta0) is touched from
                                              outside, counter-clockwise from inside

    Exact curvature on the arcs (``arc_variations``). The arc coordinate s runs on
    continuously from piece to piece (s = S_i + the length travelled on piece i), so a
    node keeps its friction history (Delta g_T = s - s_bar, eq 20) when it passes from
    one piece to the next; with equal tangents at the joints the normal is continuous.
    A node belongs to the first piece whose end it has not passed (its coordinate on the
    piece is below the piece's length), the last piece otherwise; a node exactly at a
    joint belongs to the line piece there. ``motion(t) -> (dx, dy)`` (optional) moves the
    whole master rigidly with time (a prescribed obstacle motion, e.g. a press fit; s is
    unchanged); ``offset`` is a fixed translation.
    """

    rigid = True
    straight = False

    def __init__(self, pieces, offset=(0.0, 0.0), motion=None):
        self.pieces = []
        for p in pieces:
            kind = p[0]
            if kind == "line":
                A, B = np.asarray(p[1], float), np.asarray(p[2], float)
                L = float(np.linalg.norm(B - A))
                if not L > 0:
                    raise ValueError("a line piece of a composite master has zero length")
                self.pieces.append(dict(kind="line", A=A, t=(B - A) / L, length=L))
            elif kind == "arc":
                c, R, th0, th1 = np.asarray(p[1], float), float(p[2]), float(p[3]), float(p[4])
                if not R > 0 or th0 == th1:
                    raise ValueError("an arc piece of a composite master needs R > 0 and theta0 != theta1")
                self.pieces.append(
                    dict(kind="arc", c=c, R=R, th0=th0, th1=th1, length=R * abs(th1 - th0), cw=th1 < th0)
                )
            else:
                raise ValueError(f"piece kind {kind!r} is not allowed: one of line|arc")
        self.S = np.concatenate([[0.0], np.cumsum([p["length"] for p in self.pieces])])
        self.offset = np.asarray(offset, dtype=float)
        self.motion = motion

    def without_motion(self):
        """A new master of the same pieces and offset that stays where its offset puts it (no
        ``motion``); this one is left as it is."""
        other = copy.copy(self)
        other.motion = None
        return other

    def position(self, t=None):
        """The translation of the master at time t: offset + motion(t)."""
        if self.motion is None or t is None:
            return self.offset
        return self.offset + np.asarray(self.motion(t), dtype=float)

    def reference(self, u, offsets=None):
        return None

    def _piece(self, i, x_s, offset):
        """Kinematics of every slave with piece i and its coordinate along it."""
        p, nc = self.pieces[i], len(x_s)
        if p["kind"] == "line":
            t = p["t"]
            k = line_variations(x_s, p["A"] + offset, np.array([-t[1], t[0]]))
            return k, k["s"]
        c = p["c"] + offset
        k = arc_variations(x_s, c, p["R"], not p["cw"], np.full(nc, 0.5 * (p["th0"] + p["th1"])))
        if p["cw"]:  # travelled clockwise: t = -e_theta, s = R (theta0 - theta)
            k = dict(k, t=-k["t"], ds=-k["ds"], d2s=-k["d2s"])
            return k, p["R"] * p["th0"] - k["s"]
        return k, k["s"] - p["R"] * p["th0"]

    def locate(self, x_s, s_bar, u, t=None, ref=None, offsets=None):
        nc, m = len(x_s), len(self.pieces)
        own = np.full(nc, m - 1)
        offset = self.position(t)
        local = []
        for i in range(m):
            k, s_loc = self._piece(i, x_s, offset)
            local.append((k, s_loc))
        for i in reversed(range(m - 1)):  # a joint belongs to the line beside it
            L_i = self.pieces[i]["length"]
            before_end = local[i][1] <= L_i if self.pieces[i]["kind"] == "line" else local[i][1] < L_i
            own = np.where(before_end, i, own)
        out = {}
        for key in ("g_N", "t", "n", "dg_N", "d2g_N", "ds", "d2s"):
            val = local[m - 1][0][key]
            for i in reversed(range(m - 1)):
                val = np.where(_expand(own == i, val), local[i][0][key], val)
            out[key] = val
        s = local[m - 1][1] + self.S[m - 1]
        for i in reversed(range(m - 1)):
            s = np.where(own == i, local[i][1] + self.S[i], s)
        out["s"] = s
        inside = ~(((own == 0) & (local[0][1] < 0.0)) | ((own == m - 1) & (local[-1][1] > self.pieces[-1]["length"])))
        return dict(out, master_dofs=np.zeros((nc, 0), dtype=int), inside=inside, seg=own)

    def outline(self, n=32, t=None):
        """Points along the master (n per arc) at time t, for drawing."""
        offset = self.position(t)
        pts = []
        for p in self.pieces:
            if p["kind"] == "line":
                pts += [p["A"] + offset, p["A"] + p["length"] * p["t"] + offset]
            else:
                th = np.linspace(p["th0"], p["th1"], n)
                pts += list(p["c"] + offset + p["R"] * np.column_stack([np.cos(th), np.sin(th)]))
        pts = np.array(pts)
        scale = max(float(np.max(np.abs(pts))), 1.0)
        keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9 * scale])
        return pts[keep]


def bottle_neck(R_neck, L_neck, r_mouth, z_low=-10.0, shift=0.0, motion=None):
    """The rigid neck of a bottle (the champagne cork, Sec. 5.5) in the meridian plane
    (x = r, y = z): one smooth RigidComposite of three pieces,

        wall   the line r = R_neck for z_low <= z <= L_neck, traversed upwards, so that its
               normal n = e3 x t (eq 18) = -e_r points into the neck, towards the cork;
        mouth  the rounded lip: the circle of radius r_mouth about (R_neck + r_mouth, L_neck),
               angles pi .. pi/2 (clockwise), touched from outside, n = e_r of the circle;
        top    the flat top of the bottle z = L_neck + r_mouth, traversed outwards (n = +e_z).

    The pieces meet with equal tangents (a continuous normal) and the arc coordinate runs on
    from piece to piece, so a node keeps its friction history (eq 20) from the wall to the
    mouth. ``shift``: a fixed radial translation; ``motion(t) -> (dr, dz)``: a prescribed one
    (the press fit moves the neck inwards)."""
    r_top = R_neck + r_mouth + 6.0
    return RigidComposite(
        [
            ("line", (R_neck, z_low), (R_neck, L_neck)),
            ("arc", (R_neck + r_mouth, L_neck), r_mouth, np.pi, np.pi / 2),
            ("line", (R_neck + r_mouth, L_neck + r_mouth), (r_top, L_neck + r_mouth)),
        ],
        offset=(shift, 0.0),
        motion=motion,
    )
