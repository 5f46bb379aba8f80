"""External loads on a ``Continuum`` body.

Each load has ``assemble(u_global, t, state, offsets) -> (P, rows, cols, vals)``: the
external force vector P (ndof_global,) and dP/du as COO triplets in global numbering
(empty for dead loads). The body's dofs start where the System's ``offsets`` place it
(contact/placement.py; at 0 without a System). A load holds its configuration only; what it
remembers from step to step (the gas pressure's value) is its state, a value the System
carries (``start(u, t, offsets)``, ``commit(u, t, state, offsets)``; None for the loads
without one).
``total_force(u_global, t)`` sums the nodal forces: the resultant (Fx, Fy).

Axisymmetric bodies integrate over the full ring (2 pi r), plane bodies over
the thickness, exactly as in ``Continuum``.
"""

from dataclasses import dataclass, replace

import numpy as np
from skfem import FacetBasis, LinearForm, asm

from ..contact.placement import start_of
from .continuum import _weight, oriented_facets

_EMPTY = (np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0))


def _value(f, t):
    """A constant, or a callable evaluated at time t, as a float array."""
    return np.asarray(f(t) if callable(f) else f, dtype=float)


@LinearForm
def _unit_load(v, w):
    """int N_i e_comp . v dV (or dS): nodal forces of a unit load in direction comp."""
    return v[w.comp] * _weight(w)


@LinearForm
def _unit_pressure(v, w):
    """-int n . v dS: nodal forces of a unit dead pressure (n = reference outward normal)."""
    return -np.einsum("i...,i...->...", w.n, v) * _weight(w)


class _Load:
    """Shared plumbing: local (body) vector -> global vector and triplets."""

    def __init__(self, body):
        self.body = body

    def _local(self, u, t, state=None):
        raise NotImplementedError

    def start(self, u_global, t=0.0, offsets=None):
        """The load's state at the initial state: None (no history)."""
        return None

    def commit(self, u_global, t, state=None, offsets=None):
        """The load's state after the converged state u at time t: unchanged (no history)."""
        return state

    def assemble(self, u_global, t, state=None, offsets=None):
        off, n = start_of(self.body, offsets), self.body.ndof
        P_local, rows, cols, vals = self._local(np.asarray(u_global)[off : off + n], t, state)
        P = np.zeros(len(u_global))
        P[off : off + n] = P_local
        return P, rows + off, cols + off, vals

    def total_force(self, u_global, t, state=None, offsets=None):
        """Resultant (sum of the nodal forces) in x and y."""
        P = self.assemble(u_global, t, state, offsets)[0]
        dofs = self.body.xdofs + start_of(self.body, offsets)
        return np.array([P[dofs[:, 0]].sum(), P[dofs[:, 1]].sum()])


class BodyForce(_Load):
    """Dead load b = (bx, by) per unit reference volume (e.g. (0, -g rho)),
    or a callable t -> (bx, by). P = int N^T b dV."""

    def __init__(self, body, b):
        super().__init__(body)
        self.b = b
        params = dict(axi=body.axi, thickness=body.thickness)
        self._unit = [asm(_unit_load, body.basis, comp=c, **params) for c in (0, 1)]

    def _local(self, u, t, state=None):
        b = _value(self.b, t)
        return b[0] * self._unit[0] + b[1] * self._unit[1], *_EMPTY


class Traction(_Load):
    """Dead traction (tx, ty) per unit reference length on a named boundary,
    or a callable t -> (tx, ty). P = int_boundary N^T t dS."""

    def __init__(self, body, boundary_name, traction):
        super().__init__(body)
        self.traction = traction
        fb = FacetBasis(body.mesh, body.element, facets=body.boundary_facets(boundary_name))
        params = dict(axi=body.axi, thickness=body.thickness)
        self._unit = [asm(_unit_load, fb, comp=c, **params) for c in (0, 1)]

    def _local(self, u, t, state=None):
        tr = _value(self.traction, t)
        return tr[0] * self._unit[0] + tr[1] * self._unit[1], *_EMPTY


class Pressure(_Load):
    """Pressure p (or callable t -> p) on a named boundary, pushing into the body
    (along minus the outward normal).

    follower=False: dead load on the reference geometry (FacetBasis normals).
    follower=True: acts on the current facet. For a straight two-node facet a -> b
    (body on the right, so the outward normal times length is nL = e3 x (x_b - x_a))
    the nodal forces are exact:
        plane         f_a = f_b = -p nL thickness / 2
        axisymmetric  f_a = -p nL 2 pi (2 r_a + r_b) / 6,  f_b = -p nL 2 pi (r_a + 2 r_b) / 6
    (int N_i 2 pi r ds with r linear along the edge, current radii r = x).
    The tangent dP/du follows by the product rule and is returned as COO triplets.
    """

    # d nL / d(u_ax, u_ay, u_bx, u_by), nL = (-(y_b - y_a), x_b - x_a)
    _dnL = np.array([[0.0, 1.0, 0.0, -1.0], [-1.0, 0.0, 1.0, 0.0]])

    def __init__(self, body, boundary_name, p, follower=False):
        super().__init__(body)
        self.p, self.follower = p, bool(follower)
        facets = body.boundary_facets(boundary_name)
        if self.follower:
            ab = oriented_facets(body.mesh, facets)
            self._dofs = body.xdofs[ab].reshape(-1, 4)  # [a_x, a_y, b_x, b_y] per facet
            self._X = body.X[ab].reshape(-1, 4)  # reference (X_a, Y_a, X_b, Y_b)
        else:
            fb = FacetBasis(body.mesh, body.element, facets=facets)
            self._unit = asm(_unit_pressure, fb, axi=body.axi, thickness=body.thickness)

    def _value(self, t, state):
        """The pressure at time t."""
        return float(_value(self.p, t))

    def _local(self, u, t, state=None):
        p = self._value(t, state)
        if not self.follower:
            return p * self._unit, *_EMPTY
        x = self._X + u[self._dofs]  # current (x_a, y_a, x_b, y_b), (nf, 4)
        nL = np.column_stack([-(x[:, 3] - x[:, 1]), x[:, 2] - x[:, 0]])
        if self.body.axi:
            ra, rb = x[:, 0], x[:, 2]
            c = 2.0 * np.pi * np.column_stack([2 * ra + rb, ra + 2 * rb]) / 6.0
            dc = 2.0 * np.pi * np.array([[2, 0, 1, 0], [1, 0, 2, 0]]) / 6.0
        else:
            c = np.full((len(x), 2), 0.5 * self.body.thickness)
            dc = np.zeros((2, 4))
        f = -p * np.concatenate([c[:, 0:1] * nL, c[:, 1:2] * nL], axis=1)  # (nf, 4)
        K = (
            np.concatenate([c[:, i, None, None] * self._dnL + nL[:, :, None] * dc[i] for i in (0, 1)], axis=1) * -p
        )  # (nf, 4, 4)
        P = np.zeros(self.body.ndof)
        np.add.at(P, self._dofs, f)
        rows = np.repeat(self._dofs, 4, axis=1).ravel()
        cols = np.tile(self._dofs, (1, 4)).ravel()
        return P, rows, cols, K.ravel()


def swept_volume(x):
    """Volume of revolution under the profile x = (r_i, z_i), ordered in r
    (Pappus on each straight segment):  int 2 pi r z dr
    = sum 2 pi (r2 - r1) (2 r1 z1 + r1 z2 + r2 z1 + 2 r2 z2) / 6.
    For a flat face at height z and radius r it is pi r^2 z."""
    r, z = x[:, 0], x[:, 1]
    r1, r2, z1, z2 = r[:-1], r[1:], z[:-1], z[1:]
    return float(np.sum(2.0 * np.pi * (r2 - r1) * (2 * r1 * z1 + r1 * z2 + r2 * z1 + 2 * r2 * z2) / 6.0))


@dataclass(frozen=True)
class GasState:
    """What the gas column remembers (GasPressure): the swept volume S0 of the initial state,
    the value (Boyle's) set from the last converged state, whether the gas has escaped and when."""

    S0: float
    value: float = 0.0
    released: bool = False
    released_at: float | None = None


class GasPressure(Pressure):
    """The pressure of a gas column under the face ``boundary_name`` of an axisymmetric
    body (the champagne under the cork): a follower ``Pressure`` whose value is

        ramp:   p = p_step * ceil(n_ramp t / t_ramp) while t <= t_ramp (by time: n_ramp
                increments of p_step, each held t_ramp / n_ramp)
        Boyle:  p = p0 V0 / V after the ramp (p0 = n_ramp p_step, V0 = area * column,
                V = V0 + the volume swept by the face since ``start``)
        open:   p = 0 once the face's outer edge has reached z_release (the gas escapes).

    Explicit coupling: each converged state (the initial one too) sets the Boyle value and
    the release for the next step (``update``, the load's ``commit``); the pressure is then
    constant over the step (``GasState.value``). ``face_nodes`` are the nodes of that face.
    The state is a GasState value, carried by the System like a contact's history.
    """

    def __init__(self, body, boundary_name, face_nodes, area, column, p_step, n_ramp, t_ramp, z_release):
        super().__init__(body, boundary_name, None, follower=True)
        self.face = np.asarray(face_nodes)
        self.V0 = area * column
        self.p_step, self.n_ramp, self.t_ramp, self.z_release = p_step, n_ramp, t_ramp, z_release
        self.p0 = p_step * n_ramp

    def face_positions(self, u, offsets=None):
        b = self.body
        x = b.X[self.face] + u[start_of(b, offsets) + b.xdofs[self.face]]
        return x[np.argsort(b.X[self.face, 0])]

    def start(self, u, t=0.0, offsets=None):
        """The GasState at the initial state u (where the gas column has its volume V0), with
        the pressure of the first step set from it (``update``)."""
        return self.update(u, t, GasState(S0=swept_volume(self.face_positions(u, offsets))), offsets)

    def commit(self, u, t, state, offsets=None):
        """The GasState after the converged state u at time t: the next step's pressure."""
        return self.update(u, t, state, offsets)

    def volume(self, u, state, offsets=None):
        return self.V0 + swept_volume(self.face_positions(u, offsets)) - state.S0

    def edge_z(self, u, offsets=None):
        """Height of the face's outer edge (the gas escapes when it reaches z_release)."""
        return self.face_positions(u, offsets)[-1, 1]

    def update(self, u, t, state, offsets=None):
        """The GasState with Boyle's pressure for the next step from the converged u (explicit
        coupling; it acts once the ramp is over); t is recorded as ``released_at`` at the release."""
        released, released_at = state.released, state.released_at
        if not released and self.edge_z(u, offsets) >= self.z_release:
            released, released_at = True, t
        value = 0.0 if released else self.p0 * self.V0 / self.volume(u, state, offsets)
        return replace(state, value=value, released=released, released_at=released_at)

    def pressure(self, t, state):
        """The value at time t with the GasState ``state``: the ramp by time, then the value
        set by ``update``."""
        if state.released:
            return 0.0
        if t <= self.t_ramp * (1 + 1e-9):
            return self.p_step * np.ceil(self.n_ramp * t / self.t_ramp - 1e-6)
        return state.value

    def _value(self, t, state):
        return float(self.pressure(t, state))


class OverhangPressure:
    """Dead pressure p on the parts of a straight horizontal chain of surface nodes
    (a body's top, ordered by x) that lie outside [x0, x1]: consistent nodal forces
    int N_i p ds of the linear shape functions over the loaded part of each edge,
    pushing in -y (the patch test's lower block, where it overhangs the upper one)."""

    def __init__(self, body, nodes, p, x0, x1):
        self.body = body
        x = body.X[nodes, 0]
        f = np.zeros(len(nodes))
        for i in range(len(nodes) - 1):
            xa, xb = x[i], x[i + 1]
            L = xb - xa
            for lo, hi in ((xa, min(xb, x0)), (max(xa, x1), xb)):  # loaded sub-intervals
                if hi > lo:
                    # int_lo^hi (xb - s)/L ds and int_lo^hi (s - xa)/L ds
                    f[i] += ((xb - lo) ** 2 - (xb - hi) ** 2) / (2 * L)
                    f[i + 1] += ((hi - xa) ** 2 - (lo - xa) ** 2) / (2 * L)
        self.local = np.zeros(body.ndof)
        self.local[body.xdofs[nodes, 1]] = -p * f * body.thickness

    def start(self, u_global, t=0.0, offsets=None):
        """A dead load has no state."""
        return None

    def commit(self, u_global, t, state=None, offsets=None):
        """A dead load keeps no history."""
        return state

    def assemble(self, u_global, t, state=None, offsets=None):
        P = np.zeros(len(u_global))
        off = start_of(self.body, offsets)
        P[off : off + self.body.ndof] = self.local
        e = np.zeros(0, dtype=int)
        return P, e, e, np.zeros(0)
