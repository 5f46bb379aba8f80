"""Rings for the paper's ring examples (Secs 5.2-5.4): one builder, two bodies.

``make_ring(kind="beam" | "continuum", ...)`` returns a ``RingModel``: the body, the
ordered contact nodes, the contact offset, and the rigid-body measures a ring scene
reports (centre of mass, its velocity, the spin), so that a scene is written once
and a student swaps the cheap beam ring for a continuum ring with one argument.

Geometry: mean (centreline) radius R, radial wall thickness h = ``thickness``,
out-of-plane depth b = ``width``; cross-section A = h b, I = b h^3 / 12. The
contact surface is the OUTER face, at radius R + h/2, for both kinds:

    beam       Beam(ring(R, n_el), closed=True, E, A, I, rho, nu) (beam.py); contact
               nodes are the centreline nodes, offset = h/2 (the node-to-segment
               gap is measured from the node minus h/2 along the master normal).
    continuum  an annulus of four-node quads on a polar tensor grid, n_el around and
               n_radial through the wall, in PLANE STRAIN with the St Venant-Kirchhoff
               material (the rings roll and rotate through large angles: the linear
               material is not objective, and Continuum allows plane stress only for
               the linear material). Plane strain stiffens the wall by 1/(1 - nu^2)
               against a plane-stress ring of the same E (use nu = 0 to remove the
               difference). The body's thickness is the depth b. Contact nodes: the
               outer nodes, offset = 0.

Both kinds list their contact nodes counter-clockwise (CCW). Note for BodySurface
masters: the outward normal of a master is e3 x t, so a ring used as a master needs
the clockwise order, ``contact_nodes[::-1]``.

Half ring (``half=True``, for the funnel's symmetry, Sec. 5.4): the arc x <= x_c
(x_c = center[0]) from the top (angle pi/2) counter-clockwise through the left
(angle pi) to the bottom (angle 3 pi/2), n_el elements on the HALF. The symmetry
plane is x = x_c; ``symmetry_dofs()`` lists the local dofs to fix with a Dirichlet
condition (value 0): u_x and theta of the two end nodes of the beam arc; u_x of all
the nodes on x = x_c of the continuum half annulus. Its mass is half the ring's; the
rigid-body measures refer to the full (mirrored) ring: centre x = x_c, centre
velocity (0, v_y), spin 0.
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import lazy
from .beam import Beam, BeamGravity, ring as ring_nodes

skfem = lazy.module("skfem")
continuum = lazy.module("contactfem.bodies.continuum")  # loads scikit-fem
loads = lazy.module("contactfem.bodies.loads")

KINDS = ("beam", "continuum")


def _positive(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"parameter {name} must be a number, got {value!r}") from None
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"parameter {name} = {value!r} is out of range: allowed (0, inf)")
    return v


def _count(name, value, low):
    if int(value) != value or value < low:
        raise ValueError(f"parameter {name} = {value!r} is out of range: allowed integers >= {low}")
    return int(value)


def _angles(n_el, half):
    """Node angles: full ring 2 pi k / n_el (k < n_el, node 0 at angle 0);
    half ring pi/2 + pi k / n_el (k = 0..n_el), top to bottom through x < x_c."""
    if half:
        return np.pi / 2 + np.pi * np.arange(n_el + 1) / n_el
    return 2 * np.pi * np.arange(n_el) / n_el


def annulus_mesh(R_in, R_out, n_el, n_radial, center=(0.0, 0.0), half=False):
    """MeshQuad of an annulus (or its half x <= x_c) on a polar tensor grid.

    Node (j, i) = radius layer j (0 inner .. n_radial outer), angle i; index
    j * n_ang + i. Quads (j, i), (j+1, i), (j+1, i+1), (j, i+1): counter-clockwise
    in the plane (radial step first, then the angular step). Boundaries "outer",
    "inner" (and "symmetry" for the half annulus).
    """
    a = _angles(n_el, half)
    n_ang = len(a)
    r = np.linspace(R_in, R_out, n_radial + 1)
    c = np.asarray(center, float)
    p = np.vstack([c[0] + np.outer(r, np.cos(a)).ravel(), c[1] + np.outer(r, np.sin(a)).ravel()])
    i = np.arange(n_el)
    j = np.arange(n_radial)
    J, I = np.meshgrid(j, i, indexing="ij")
    J, I = J.ravel(), I.ravel()
    I1 = (I + 1) % n_ang
    t = np.vstack([J * n_ang + I, (J + 1) * n_ang + I, (J + 1) * n_ang + I1, J * n_ang + I1])
    mesh = skfem.MeshQuad(p, t)
    rad = lambda x: np.hypot(x[0] - c[0], x[1] - c[1])  # noqa: E731
    tol = 1e-6 * (R_out - R_in)
    bnd = {"outer": lambda x: rad(x) > R_out - tol, "inner": lambda x: rad(x) < R_in + tol}
    if half:
        bnd["symmetry"] = lambda x: np.abs(x[0] - c[0]) < 1e-9 * R_out
    return mesh.with_boundaries(bnd), n_ang


@dataclass
class RingModel:
    """A ring body with what the ring scenes need (see the module docstring).

    body           Beam or Continuum (the body interface of contactfem.bodies)
    contact_nodes  (nc,) body node indices of the contact surface, counter-clockwise
    offset         contact offset for NodeToSegment: h/2 (beam), 0 (continuum)
    """

    body: object
    kind: str
    R: float
    thickness: float
    width: float
    center: np.ndarray
    half: bool
    contact_nodes: np.ndarray
    offset: float

    # -- geometry ---------------------------------------------------------------
    @property
    def R_outer(self):
        """Radius of the contact (outer) surface, R + h/2."""
        return self.R + 0.5 * self.thickness

    @property
    def rolling_radius(self):
        """Lever arm of the friction force for rolling without slip: the distance from
        the centre to the point whose tangential slip the contact measures.
        beam: R (NodeToSegment measures the slip of the centreline node; the offset h/2
        enters the gap only), continuum: R + h/2 (the outer nodes)."""
        return self.R if self.kind == "beam" else self.R_outer

    def _u(self, u):
        """The body's local part of u (a global vector whose dofs start with the ring's, as in
        the ring scenes, is accepted too; or a stack of them, one a row)."""
        u = np.asarray(u, float)
        return u[..., : self.body.ndof]

    def positions(self, u):
        """Current positions of all nodes (beam: centreline nodes), (nn, 2) (a stack of u:
        (k, nn, 2))."""
        u = self._u(u)
        return self.body.X + u[..., self.body.xdofs]

    def outline(self, u, mirror=False):
        """Outer surface as a polyline (nc + 1, 2), closed for a full ring.

        beam: the centreline nodes offset by h/2 outward along the current cross-section
        normal (as beam.offset_positions; the beam normal points inward on a CCW ring);
        continuum: the outer nodes. Half ring: the open arc top -> bottom; with
        mirror=True the reflection in x = x_c is appended, giving the whole ring.
        """
        u = self._u(u)
        if self.kind == "beam":
            # cross-section normal n(psi0 + theta) with psi0 the exact tangent angle of the
            # reference circle (equal to the beam's bisector on a closed ring, and right at
            # the symmetry-plane ends of the half ring, where the bisector is one-sided)
            d = self.body.X - self.center
            psi = np.arctan2(d[:, 1], d[:, 0]) + np.pi / 2 + u[2::3]
            P = self.positions(u) - 0.5 * self.thickness * np.column_stack([-np.sin(psi), np.cos(psi)])
            P = P[self.contact_nodes]
        else:
            P = self.positions(u)[self.contact_nodes]
        if not self.half:
            return np.vstack([P, P[:1]])
        if not mirror:
            return P
        back = P[::-1].copy()
        back[:, 0] = 2 * self.center[0] - back[:, 0]
        return np.vstack([P, back[1:]])

    # -- masses and rigid-body measures -----------------------------------------------
    def _mass_split(self):
        """Translational mass per node (nn,) and rotary inertia per node (beam theta dofs) of the
        lumped mass, the consistent mass's row sums; computed once (the mass is constant). The
        centre of mass and its velocity are the same sums for either mass (M is symmetric: the
        momentum 1^T M v is the row sums times v)."""
        return self._masses

    @cached_property
    def _masses(self):
        """(m, J) of ``_mass_split``: a pure function of the body, made on first use."""
        M = self.body.mass()
        m = M[self.body.xdofs[:, 0]]
        J = M[2::3] if self.kind == "beam" else np.zeros_like(m)
        return m, J

    def _second_moments(self, r, w, theta_dot=None):
        """sum_ij M_ij (r_i x w_j) and sum_ij M_ij (r_i . r_j) over the nodes, plus the rotary
        terms sum_ij J_ij theta_dot_j and sum_ij J_ij: the angular momentum and the moment of
        inertia with the body's own mass, lumped (diagonal: M_ii = m_i) or consistent.
        r, w (..., nn, 2), theta_dot (..., nn): a stack of k states gives k values of each."""
        b = self.body
        if b.mass_matrix != "consistent":
            m, J = self._mass_split()
            L = np.sum(m * (r[..., 0] * w[..., 1] - r[..., 1] * w[..., 0]), axis=-1)
            Ic = np.sum(m * np.sum(r * r, axis=-1), axis=-1)
            if self.kind == "beam":
                L = L + (np.sum(J * theta_dot, axis=-1) if theta_dot is not None else 0.0)
                Ic = Ic + J.sum()
            return L, Ic
        M = b.mass(consistent=True).tocsr()
        x = b.xdofs[:, 0]
        Mt = M[x][:, x]  # the same block for u_x and u_y

        def Mx(a):  # M_t a over the node axis, a (..., nn)
            return (Mt @ a.T).T

        L = np.sum(r[..., 0] * Mx(w[..., 1]) - r[..., 1] * Mx(w[..., 0]), axis=-1)
        Ic = np.sum(r[..., 0] * Mx(r[..., 0]) + r[..., 1] * Mx(r[..., 1]), axis=-1)
        if self.kind == "beam":
            Mr = M[2::3][:, 2::3]
            L = L + (np.sum((Mr @ theta_dot.T).T, axis=-1) if theta_dot is not None else 0.0)
            Ic = Ic + Mr.sum()
        return L, Ic

    def total_mass(self):
        """Sum of the lumped translational masses (the half ring's is half the ring's)."""
        return float(self._mass_split()[0].sum())

    def center_of_mass(self, u):
        """Mass-weighted mean of the node positions, sum m_i x_i / sum m_i.
        Half ring: of the full mirrored ring, (x_c, mean y). A stack of u (k, ndof): one
        centre a row, (k, 2)."""
        m, _ = self._mass_split()
        c = m @ self.positions(u) / m.sum()
        if self.half:
            c[..., 0] = self.center[0]
        return c

    def velocity_of_mass(self, v):
        """Centre-of-mass velocity sum m_i v_i / sum m_i (half ring: (0, v_y)); of each row of
        a stack of v."""
        v = self._u(v)
        m, _ = self._mass_split()
        w = m @ v[..., self.body.xdofs] / m.sum()
        if self.half:
            w[..., 0] = 0.0
        return w

    def angular_velocity(self, u, v):
        """Spin about the centre of mass, omega = L / I_c (CCW positive), with
        L = sum m_i (r_i x v_i) + sum J_i theta_dot_i and I_c = sum m_i |r_i|^2 + sum J_i
        (r_i, v_i relative to the centre of mass; J_i: the beam's rotary inertia); with a
        consistent mass the double sums over M_ij. Exact for a rigid motion. Half ring: 0 by
        symmetry. Stacks of u and v (k, ndof): an array of k spins."""
        stack = np.ndim(u) == 2
        if self.half:
            return np.zeros(len(u)) if stack else 0.0
        v = self._u(v)
        r = self.positions(u) - self.center_of_mass(u)[..., None, :]
        w = v[..., self.body.xdofs] - self.velocity_of_mass(v)[..., None, :]
        L, Ic = self._second_moments(r, w, v[..., 2::3] if self.kind == "beam" else None)
        return L / Ic if stack else float(L / Ic)

    def moment_of_inertia(self, u=None):
        """I_c about the centre of mass in configuration u (default: the reference one), with
        the body's mass (lumped or consistent) and the beam's rotary inertia."""
        u = np.zeros(self.body.ndof) if u is None else self._u(u)
        r = self.positions(u) - self.center_of_mass(u)
        return float(self._second_moments(r, np.zeros_like(r))[1])

    def initial_velocity(self, v0_vec, omega=0.0):
        """Local velocity vector (ndof,) of the rigid motion v = v0 + omega e3 x (X - c)
        about the reference centre c; beam rotations get theta_dot = omega.
        (For a one-body System the local vector is the global one; otherwise place
        it at the System's offset of the body, ``System.offset(body)``.)"""
        v0_vec = np.asarray(v0_vec, float)
        if v0_vec.shape != (2,) or not np.all(np.isfinite(v0_vec)):
            raise ValueError(f"parameter v0_vec must be a finite 2-vector, got {v0_vec!r}")
        if self.half and omega != 0.0:
            raise ValueError(f"parameter omega = {omega!r} is out of range: a half ring (symmetry) allows only 0")
        if self.half and v0_vec[0] != 0.0:
            raise ValueError(f"parameter v0_vec = {v0_vec!r}: a half ring (symmetry in x) allows only (0, v_y)")
        b = self.body
        d = b.X - self.center
        v = np.zeros(b.ndof)
        v[b.xdofs[:, 0]] = v0_vec[0] - omega * d[:, 1]
        v[b.xdofs[:, 1]] = v0_vec[1] + omega * d[:, 0]
        if self.kind == "beam":
            v[2::3] = omega
        return v

    # -- loads and constraints ---------------------------------------------------------
    def gravity(self, g):
        """Dead weight: BeamGravity (lumped) for the beam, BodyForce (0, -rho g) for the continuum."""
        g = float(g)
        if self.kind == "beam":
            return BeamGravity(self.body, g)
        return loads.BodyForce(self.body, (0.0, -self.body.rho * g))

    def symmetry_dofs(self):
        """Local dofs to fix (value 0) on the symmetry plane x = x_c of a half ring:
        beam: u_x and theta of the two end nodes; continuum: u_x of every node on x = x_c."""
        if not self.half:
            raise ValueError("parameter half must be True to ask for symmetry dofs (the full ring has none)")
        b = self.body
        if self.kind == "beam":
            ends = np.array([0, b.X.shape[0] - 1])
            return np.sort(np.concatenate([3 * ends, 3 * ends + 2]))
        on_plane = np.flatnonzero(np.abs(b.X[:, 0] - self.center[0]) < 1e-9 * self.R_outer)
        return b.xdofs[on_plane, 0]

    def lowest_node(self, u=None):
        """Index (into contact_nodes) of the lowest contact node in configuration u."""
        u = np.zeros(self.body.ndof) if u is None else u
        return int(np.argmin(self.outline(u)[: len(self.contact_nodes), 1]))


def make_ring(
    kind="beam",
    R=1.0,
    thickness=0.1,
    n_el=32,
    E=1.0,
    nu=0.0,
    rho=1.0,
    center=(0.0, 0.0),
    n_radial=2,
    plastic=None,
    width=1.0,
    half=False,
    name="ring",
    material="svk",
    integration=1,
    rotary_inertia=True,
    mass_matrix="lumped",
):
    """Build a beam or continuum ring (see the module docstring); returns a RingModel.

    R          mean radius > 0;  thickness h in (0, 2R): radial wall thickness
    n_el       elements around (full ring >= 3; half ring: on the half, >= 2)
    E, nu, rho Young's modulus > 0, Poisson's ratio (-1, 0.5), density >= 0
    width      out-of-plane depth b > 0, A = h b, I = b h^3 / 12
    n_radial   continuum only: elements through the wall (>= 1)
    plastic    beam only: None or the Perzyna dict of Beam (N0, Q0, M0, eta)
    half       the half ring x <= center_x (symmetry plane x = center_x)
    material   continuum only: "svk" (default) or "neohooke" (plane strain)
    integration, rotary_inertia   beam only: see Beam (1 or 2 points; rho I on the rotations or not)
    mass_matrix "lumped" (default) or "consistent": the mass the solver uses (Beam, Continuum)
    """
    if kind not in KINDS:
        raise ValueError(f"parameter kind = {kind!r} is not allowed: one of {'|'.join(KINDS)}")
    R = _positive("R", R)
    h = _positive("thickness", thickness)
    if not h < 2 * R:
        raise ValueError(f"parameter thickness = {thickness!r} is out of range: allowed (0, 2R) = (0, {2 * R:g})")
    b = _positive("width", width)
    n_el = _count("n_el", n_el, 2 if half else 3)
    center = np.asarray(center, float)
    if center.shape != (2,) or not np.all(np.isfinite(center)):
        raise ValueError(f"parameter center must be a finite 2-vector, got {center!r}")
    if not -1.0 < float(nu) < 0.5:
        raise ValueError(f"parameter nu = {nu!r} is out of range: allowed (-1, 0.5)")
    if not float(rho) >= 0:
        raise ValueError(f"parameter rho = {rho!r} is out of range: allowed [0, inf)")

    if kind == "beam":
        if half:
            a = _angles(n_el, True)
            X = center + R * np.column_stack([np.cos(a), np.sin(a)])
        else:
            X = ring_nodes(R, n_el, center)
        body = Beam(
            X,
            closed=not half,
            E=E,
            A=h * b,
            I=b * h**3 / 12,
            rho=rho,
            nu=nu,
            name=name,
            plastic=plastic,
            integration=integration,
            rotary_inertia=rotary_inertia,
            mass_matrix=mass_matrix,
        )
        return RingModel(body, kind, R, h, b, center, bool(half), np.arange(X.shape[0]), 0.5 * h)

    if plastic is not None:
        raise ValueError("parameter plastic is for kind='beam' only (the continuum ring is elastic)")
    n_radial = _count("n_radial", n_radial, 1)
    if material not in ("svk", "neohooke"):
        raise ValueError(f"parameter material = {material!r} is not allowed: one of svk|neohooke")
    mesh, n_ang = annulus_mesh(R - h / 2, R + h / 2, n_el, n_radial, center, half)
    body = continuum.Continuum(
        mesh,
        E=E,
        nu=nu,
        rho=rho,
        kind="plane_strain",
        material=material,
        name=name,
        thickness=b,
        mass_matrix=mass_matrix,
    )
    outer = n_radial * n_ang + np.arange(n_ang)
    return RingModel(body, kind, R, h, b, center, bool(half), outer, 0.0)
