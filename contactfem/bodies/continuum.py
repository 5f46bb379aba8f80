"""Two-dimensional continuum bodies (plane strain, plane stress, axisymmetric).

One class, ``Continuum``, implements the body interface (see ``__init__.py``)
with scikit-fem: four-node quadrilaterals (``MeshQuad``) or three-node
triangles (``MeshTri``), total Lagrangian formulation.

Every material is written as one pure function ``F -> (W, P, A)`` (materials.py) of the 3x3
deformation gradient at all quadrature points: strain energy density W, first
Piola-Kirchhoff stress P and material tangent A = dP/dF (Holzapfel, Nonlinear
Solid Mechanics, ch. 6; Wriggers, Nonlinear FEM, ch. 3-4). In 2D the third
direction is

    plane strain   F_33 = 1
    plane stress   linear material only, reduced Lame constant (no F_33 needed)
    axisymmetric   x = r, y = z, F_33 = (R + u_r) / R   (hoop stretch)

so that one pair of weak forms serves all cases (principle of virtual work):

    R(u) . v = int  P : grad v  +  P_33 v_r / R   dV
    K        = int  grad v : A : grad du  + (hoop couplings)   dV

with dV = thickness dA (plane) or 2 pi R dA (axisymmetric). The linear material
uses the same forms with F = I + grad u and P = C : eps (small strain).
"""

import numpy as np
from skfem import (
    Basis,
    BilinearForm,
    ElementQuad1,
    ElementTriP1,
    ElementVector,
    Functional,
    LinearForm,
    MeshQuad,
    MeshTri,
    asm,
)

from .discrete_gradient import algorithmic_stress
from .interfaces import MASS_MATRICES
from .materials import MATERIAL_FUNCTIONS, MATERIALS, _eye

KINDS = ("plane_strain", "plane_stress", "axisymmetric")


class InvertedElementError(FloatingPointError):
    """Raised when det F <= 0 at a quadrature point (an element turned inside out)."""


def degenerate_guard(make, mesh):
    """scikit-fem raises a bare Exception for a zero Jacobian determinant: a mesh whose
    elements have no area in floating point (lengths near 1e-300, or 1e300 squared).
    Say so as a FloatingPointError, the error of a computation that cannot go on."""
    try:
        return make()
    except Exception as err:
        if "Jacobian" not in str(err):
            raise
        size = float(np.ptp(mesh.p, axis=1).max()) if mesh.p.size else 0.0
        raise InvertedElementError(
            f"the mesh is degenerate in floating point (zero Jacobian determinant; "
            f"mesh size {size:.3g}): lengths too small or too large"
        ) from None


# ---------------------------------------------------------------------------
# Weak forms. w.axi (bool) and w.thickness are scalars passed to asm.
# ---------------------------------------------------------------------------


def _weight(w):
    """Volume element factor: 2 pi r (axisymmetric) or the thickness (plane)."""
    return 2.0 * np.pi * w.x[0] if w.axi else w.thickness


def _hoop(v, w):
    """Hoop part v_r / r of a (test or trial) displacement; zero in plane problems."""
    return v[0] / w.x[0] if w.axi else 0.0 * v[0]


@LinearForm
def _internal_form(v, w):
    """Virtual work of the stresses: P : grad v + P_33 v_r / r."""
    P = np.asarray(w.P)  # plain array: indexing a DiscreteField copies all of it
    work = np.einsum("ij...,ij...->...", P[:2, :2], v.grad) + P[2, 2] * _hoop(v, w)
    return work * _weight(w)


@BilinearForm
def _tangent_form(u, v, w):
    """Linearised virtual work: grad v : A : grad du (+ hoop couplings)."""
    A = np.asarray(w.A)  # plain array: indexing a DiscreteField copies all of it (8x slower)
    k = np.einsum("ijkl...,ij...,kl...->...", A[:2, :2, :2, :2], v.grad, u.grad)
    if not w.axi:  # plane: no hoop terms
        return k * w.thickness
    hu, hv = _hoop(u, w), _hoop(v, w)
    k = (
        k
        + np.einsum("ij...,ij...->...", A[:2, :2, 2, 2], v.grad) * hu
        + np.einsum("kl...,kl...->...", A[2, 2, :2, :2], u.grad) * hv
        + A[2, 2, 2, 2] * hu * hv
    )
    return k * _weight(w)


@BilinearForm
def _linear_form(u, v, w):
    """The linear material's tangent, eps(v) : C : eps(du) with C isotropic, written out:
    lam tr eps(v) tr eps(du) + 2 mu eps(v) : eps(du) (+ the hoop strains v_r / r). The same
    integrand as _tangent_form with A = C, in a few products of the strain components instead
    of a sum over the 16 entries of A (Hertz on 16k quads: 0.14 s -> 0.04 s an assembly)."""
    gu, gv = u.grad, v.grad
    tr_u, tr_v = gu[0, 0] + gu[1, 1], gv[0, 0] + gv[1, 1]
    eps_eps = gu[0, 0] * gv[0, 0] + gu[1, 1] * gv[1, 1] + 0.5 * (gu[0, 1] + gu[1, 0]) * (gv[0, 1] + gv[1, 0])
    if w.axi:  # the hoop strain in the trace and in eps : eps
        hu, hv = _hoop(u, w), _hoop(v, w)
        tr_u, tr_v, eps_eps = tr_u + hu, tr_v + hv, eps_eps + hu * hv
    return (w.lam * tr_u * tr_v + 2.0 * w.mu * eps_eps) * _weight(w)


@BilinearForm
def _mass_form(u, v, w):
    """Consistent mass int rho u . v dV (Continuum.mass; the lumped mass is its row sums)."""
    return w.rho * np.einsum("i...,i...->...", u, v) * _weight(w)


@Functional
def _energy_form(w):
    """Integral of a quadrature-point field, int W dV."""
    return w.W * _weight(w)


# ---------------------------------------------------------------------------
# Boundary helper
# ---------------------------------------------------------------------------


def boundary_loop(mesh):
    """Node indices of the boundary of a 2D scikit-fem mesh, in order around it (the outer
    loop of a simply connected mesh): to draw a continuum's outline as one polyline."""
    edges = mesh.facets[:, mesh.boundary_facets()].T
    nxt = {}
    for a, b in edges:
        nxt.setdefault(a, []).append(b)
        nxt.setdefault(b, []).append(a)
    start = edges[0, 0]
    loop, prev, cur = [start], None, start
    while True:
        step = [n for n in nxt[cur] if n != prev][0]
        if step == start:
            return np.array(loop)
        loop.append(step)
        prev, cur = cur, step


def oriented_facets(mesh, facets):
    """Boundary facets as node pairs (a, b), shape (nf, 2), oriented so that the
    body lies to the RIGHT of b - a: the outward normal is e3 x (x_b - x_a),
    the master-segment convention of the paper's eq (18)."""
    ab = mesh.facets[:, facets].T.copy()
    centre = mesh.p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1).T
    xa, xb = mesh.p[:, ab[:, 0]].T, mesh.p[:, ab[:, 1]].T
    d = xb - xa
    left = np.column_stack([-d[:, 1], d[:, 0]])
    flip = np.einsum("ij,ij->i", left, centre - xa) > 0.0
    ab[flip] = ab[flip, ::-1]
    return ab


# ---------------------------------------------------------------------------
# The body
# ---------------------------------------------------------------------------


class Continuum:
    """A 2D continuum body (see module docstring); implements the body interface.

    Parameters: mesh (MeshQuad or MeshTri, optionally with named boundaries),
    E > 0, -1 < nu < 0.5, rho >= 0, kind in KINDS, material in MATERIALS,
    thickness > 0 (plane problems only), mass_matrix: the mass the System uses,
    "lumped" (row sums, diagonal) or "consistent" (``mass(consistent=True)``).
    """

    def __init__(
        self, mesh, E, nu, rho, kind="plane_strain", material="linear", name="body", thickness=1.0, mass_matrix="lumped"
    ):
        if not E > 0:
            raise ValueError(f"E must be > 0, got {E}")
        if not -1.0 < nu < 0.5:
            raise ValueError(f"nu must satisfy -1 < nu < 0.5, got {nu}")
        if not rho >= 0:
            raise ValueError(f"rho must be >= 0, got {rho}")
        if not thickness > 0:
            raise ValueError(f"thickness must be > 0, got {thickness}")
        if kind not in KINDS:
            raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
        if material not in MATERIALS:
            raise ValueError(f"material must be one of {MATERIALS}, got {material!r}")
        if mass_matrix not in MASS_MATRICES:
            raise ValueError(
                f"parameter mass_matrix = {mass_matrix!r} is not allowed: one of {'|'.join(MASS_MATRICES)}"
            )
        if kind == "plane_stress" and material != "linear":
            raise ValueError(f"material must be 'linear' for kind='plane_stress', got {material!r}")
        if isinstance(mesh, MeshQuad):
            element = ElementVector(ElementQuad1())
        elif isinstance(mesh, MeshTri):
            element = ElementVector(ElementTriP1())
        else:
            raise ValueError(f"mesh must be a MeshQuad or MeshTri, got {type(mesh).__name__}")
        if kind == "axisymmetric" and mesh.p[0].min() < 0:
            raise ValueError("mesh x coordinates (= r) must be >= 0 for kind='axisymmetric'")

        self.mesh, self.name, self.kind, self.material = mesh, name, kind, material
        self.E, self.nu, self.rho = float(E), float(nu), float(rho)
        self.mu = E / (2.0 * (1.0 + nu))
        self.lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        if kind == "plane_stress":  # sigma_33 = 0 eliminated
            self.lam = 2.0 * self.lam * self.mu / (self.lam + 2.0 * self.mu)
        self.axi = kind == "axisymmetric"
        self.thickness = 1.0 if self.axi else float(thickness)

        self.basis = degenerate_guard(lambda: Basis(mesh, element), mesh)
        self.element = element
        self.ndof = self.basis.N
        self.X = mesh.p.T.copy()
        self.xdofs = self.basis.nodal_dofs.T.copy()
        self._K_linear = None
        self.mass_matrix = mass_matrix  # the mass the System uses: lumped (diagonal) or consistent
        self._mass = None
        self._M = None  # the consistent mass matrix (made on first use)
        self._coo = None  # (indptr, indices, rows) of the last tangent's pattern

    # -- kinematics and constitutive update at the quadrature points --------

    def _params(self):
        return dict(axi=self.axi, thickness=self.thickness)

    def _deformation_gradient(self, u, basis):
        """3x3 F = I + grad u at the quadrature points of `basis`, with
        F_33 = 1 + u_r / R (axisymmetric) or 1 (plane)."""
        uq = basis.interpolate(u)
        F = np.zeros((3, 3) + uq.shape[1:])
        F[:2, :2] = uq.grad
        if self.axi:
            F[2, 2] = uq[0] / basis.global_coordinates()[0]
        F += _eye(F)
        return F

    def _constitutive(self, u, basis):
        """(W, P, A) at the quadrature points; raises InvertedElementError if det F <= 0."""
        F = self._deformation_gradient(u, basis)
        if self.material != "linear":
            self._check_volume(F)
        return MATERIAL_FUNCTIONS[self.material](F, self.lam, self.mu)

    def _check_volume(self, F):
        """F, if det F > 0 at every quadrature point; else InvertedElementError naming the elements."""
        J = np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))
        if np.any(J <= 0.0) or not np.all(np.isfinite(J)):
            e = np.unique(np.nonzero(~(J > 0.0))[0])
            raise InvertedElementError(
                f"element volume non-positive (det F <= 0) in body {self.name!r}, elements {e[:10]}"
            )
        return F

    # -- body interface ----------------------------------------------------

    @property
    def hyperelastic(self):
        """The materials here are elastic: a stored energy W(u), no history."""
        return True

    @property
    def quadratic_energy(self):
        """W(u) is quadratic (the linear material): the midpoint rule conserves its energy exactly."""
        return self.material == "linear"

    def internal_coo(self, u, dt=None, state=None):
        """R(u) and K = dR/du as COO triplets (rows, cols, vals): the CSR tangent's entries, its
        index arrays kept (the same objects) while its pattern stays the same (scikit-fem's
        assembly gives the same pattern at every call), so that the System places them once."""
        R, K = self.internal(u)
        last = self._coo
        if last is None or not (
            last[0] is K.indptr or (np.array_equal(last[0], K.indptr) and np.array_equal(last[1], K.indices))
        ):
            last = self._coo = (K.indptr, K.indices, np.repeat(np.arange(K.shape[0]), np.diff(K.indptr)))
        if K.format == "csc":  # columns by columns: (rows, cols) = (indices, the column of each)
            return R, last[1], last[2], K.data
        return R, last[2], last[1], K.data

    def internal(self, u, dt=None, state=None):
        """Internal force R(u) and consistent tangent K = dR/du (scipy sparse: CSC for the linear material,
        CSR else)."""
        u = np.asarray(u, dtype=float)
        if self.material == "linear":
            K = self._linear_stiffness()
            return K @ u, K
        _, P, A = self._constitutive(u, self.basis)
        R = asm(_internal_form, self.basis, P=P, **self._params())
        K = asm(_tangent_form, self.basis, A=A, **self._params()).tocsr()
        return R, K

    def _linear_stiffness(self):
        """The constant K of the linear material (assembled at the first call; _linear_form:
        C isotropic and the same at every point, no fields evaluated)."""
        if self._K_linear is None:
            # CSC: its entries in the order of the System's fixed pattern (column by column), so
            # that placing them there first sorts presorted keys (Hertz on 65k quads: ~0.1 s less)
            self._K_linear = asm(_linear_form, self.basis, lam=self.lam, mu=self.mu, **self._params()).tocsc()
        return self._K_linear

    def strain_energy(self, u, dt=None, state=None):
        """Stored energy int W dV (2 pi r dA for axisymmetric). Linear material: u.K u / 2,
        the same integral on the same quadrature (W = eps:C:eps / 2, K = int grad v:C:grad du),
        without evaluating the fields at the quadrature points (Hertz on 65k quads: 0.1-0.4 s
        a call, against a few milliseconds)."""
        u = np.asarray(u, dtype=float)
        if self.material == "linear":
            return 0.5 * float(u @ (self._linear_stiffness() @ u))
        W, _, _ = self._constitutive(u, self.basis)
        return float(asm(_energy_form, self.basis, W=W, **self._params()))

    def mass(self, consistent=False):
        """The consistent mass int rho N_i N_j dV (scikit-fem's mass form) as a CSR matrix
        (ndof, ndof) with ``consistent=True``; else the lumped mass, its row sums, (ndof,)."""
        if consistent:
            if self._M is None:
                self._M = asm(_mass_form, self.basis, rho=self.rho, **self._params()).tocsr()
            return self._M.copy()
        if self._mass is None and self.rho == 0.0:  # quasi-static body: nothing to integrate
            self._mass = np.zeros(self.ndof)
        if self._mass is None:
            self._mass = np.asarray(self.mass(consistent=True).sum(axis=1)).ravel()
        return self._mass.copy()

    def start(self, u):
        """Elastic: no internal variables (None)."""
        return None

    def commit(self, u, dt=None, state=None):
        """Elastic: no internal variables (None)."""
        return None

    def corner_jacobian_ratios(self, u, offset=0):
        """det J of the element map in the deformed configuration X + u at every corner of
        every element, over its value in the reference configuration, shape (nel, corners).
        A corner's det J is the cross product of its two edges (up to a constant factor that
        the ratio cancels). For the bilinear quadrilateral det J is linear in the reference
        coordinates, so it is positive in the whole element exactly when it is positive at
        the four corners; the linear triangle has one value. An element is inverted (turned
        inside out, or folded) where a ratio is <= 0; a small-strain (linear) run that
        inverts elements is outside the range of its own model."""
        u = np.asarray(u, dtype=float)
        t = self.mesh.t.T  # (nel, corners), one orientation

        def corners(x):
            q = x[t]
            e_next = np.roll(q, -1, axis=1) - q
            e_prev = np.roll(q, 1, axis=1) - q
            return e_next[..., 0] * e_prev[..., 1] - e_next[..., 1] * e_prev[..., 0]

        x = self.X + u[offset + self.xdofs]  # u: the body's vector, or a System's with its offset
        return corners(x) / corners(self.X)

    def inverted_elements(self, u, offset=0):
        """Indices of the elements with a non-positive det J somewhere (corner_jacobian_ratios)."""
        return np.flatnonzero(np.min(self.corner_jacobian_ratios(u, offset), axis=1) <= 0.0)

    rotation_dofs = np.zeros(0, dtype=int)  # no angles among the unknowns

    def discrete_gradient(self, u0, u1):
        """The internal force of an energy-consistent step u0 -> u1 and its tangent dF/du1,
        (F, rows, cols, vals): the virtual work of the algorithmic stress P = F_mid S_alg of
        discrete_gradient.algorithmic_stress at every quadrature point (Gonzalez's discrete
        gradient in the Green strain): F . d = W(u1) - W(u0) exactly, no resultant and no
        moment. The tangent: the complex-step derivative of P with respect to F(u1), A = dP/dF1,
        in the tangent form. The linear material (W quadratic in u, not frame-indifferent):
        R(u_mid), the midpoint rule is exact for it."""
        u0, u1 = np.asarray(u0, dtype=float), np.asarray(u1, dtype=float)
        if self.material == "linear":
            R, K = self.internal(0.5 * (u0 + u1))
            K = K.tocoo()
            return R, K.row, K.col, 0.5 * K.data
        F0 = self._deformation_gradient(u0, self.basis)
        F1 = self._check_volume(self._deformation_gradient(u1, self.basis))
        law = MATERIAL_FUNCTIONS[self.material]
        W0 = law(F0, self.lam, self.mu, tangent=False)[0]
        P = algorithmic_stress(law, F0, F1, self.lam, self.mu, W0)
        step = 1e-30
        A = np.zeros((3, 3) + P.shape)
        for k, l in ((0, 0), (0, 1), (1, 0), (1, 1)) + (((2, 2),) if self.axi else ()):
            F = F1.astype(complex)
            F[k, l] += 1j * step
            A[:, :, k, l] = algorithmic_stress(law, F0, F, self.lam, self.mu, W0).imag / step
        R = asm(_internal_form, self.basis, P=P, **self._params())
        K = asm(_tangent_form, self.basis, A=A, **self._params()).tocoo()
        return R, K.row, K.col, K.data

    def element_areas(self, u):
        """Current (signed) area of every element in the plane (shoelace formula over its
        nodes, counter-clockwise): > 0 for a valid element, <= 0 for an inverted one."""
        x = self.X + np.asarray(u)[self.xdofs]
        q = x[self.mesh.t.T]  # (nel, nodes, 2)
        xs, ys = q[..., 0], q[..., 1]
        return 0.5 * np.sum(xs * np.roll(ys, -1, axis=1) - np.roll(xs, -1, axis=1) * ys, axis=1)

    def volume(self):
        """Reference volume int dV (2 pi r dA axisymmetric, thickness * area plane)."""
        ones = np.ones_like(self.basis.global_coordinates()[0])
        return float(asm(_energy_form, self.basis, W=ones, **self._params()))

    # -- output ------------------------------------------------------------

    def cauchy_stress(self, u):
        """Cauchy stress sigma = P F^T / det F at the ELEMENT CENTRES, shape (nel, 3, 3).

        Component [2, 2] is the hoop stress (axisymmetric), the out-of-plane stress
        (plane strain) or zero (plane stress). Linear material: sigma = C : eps.
        """
        centre = self.element.refdom.p.mean(axis=1)[:, None]
        basis = Basis(self.mesh, self.element, quadrature=(centre, np.array([1.0])))
        u = np.asarray(u, dtype=float)
        _, P, _ = self._constitutive(u, basis)
        if self.material == "linear":
            sigma = P
        else:
            F = self._deformation_gradient(u, basis)
            J = np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))
            sigma = np.einsum("ik...,jk...->ij...", P, F) / J
        if self.kind == "plane_stress":
            sigma = sigma.copy()
            sigma[2, 2] = 0.0
        return np.moveaxis(sigma[..., 0], -1, 0)

    # -- named boundaries --------------------------------------------------

    def boundary_facets(self, name):
        """Facet indices of the named boundary (mesh.with_boundaries)."""
        names = tuple(self.mesh.boundaries or ())
        if name not in names:
            raise ValueError(f"boundary name must be one of {names}, got {name!r}")
        return np.asarray(self.mesh.boundaries[name])

    def boundary_nodes(self, name):
        """Node indices of the named boundary, in order along it, walking with the
        body on the right (outward normal = e3 x tangent, as for a master segment
        in eq 18). A closed boundary starts anywhere and is not repeated."""
        ab = oriented_facets(self.mesh, self.boundary_facets(name))
        nxt = dict(ab)
        if len(nxt) != len(ab):
            raise ValueError(f"boundary {name!r} is not a simple curve")
        starts = set(ab[:, 0]) - set(ab[:, 1])
        node = starts.pop() if starts else ab[0, 0]
        order = [node]
        while node in nxt and len(order) <= len(ab):
            node = nxt[node]
            if node == order[0]:
                break
            order.append(node)
        if len(order) != len(set(ab.ravel())):
            raise ValueError(f"boundary {name!r} must be one connected curve")
        return np.array(order)
