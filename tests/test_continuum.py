"""Continuum bodies and their loads: Jacobians, patch tests, closed forms."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import MeshQuad, MeshTri

from contactfem.bodies.continuum import Continuum, InvertedElementError
from contactfem.bodies.loads import BodyForce, Pressure, Traction

E, NU = 100.0, 0.3
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))
MU = E / (2 * (1 + NU))

COMBOS = [
    ("plane_strain", "linear"),
    ("plane_strain", "svk"),
    ("plane_strain", "neohooke"),
    ("plane_stress", "linear"),
    ("axisymmetric", "linear"),
    ("axisymmetric", "svk"),
    ("axisymmetric", "neohooke"),
]


def block(r0=1.0, r1=2.0, h=1.0, nx=4, ny=3, tri=False):
    """Rectangle [r0, r1] x [0, h] with boundaries inner/outer/bottom/top."""
    Mesh = MeshTri if tri else MeshQuad
    m = Mesh.init_tensor(np.linspace(r0, r1, nx + 1), np.linspace(0.0, h, ny + 1))
    tol = 1e-9
    return m.with_boundaries(
        {
            "inner": lambda x: x[0] < r0 + tol,
            "outer": lambda x: x[0] > r1 - tol,
            "bottom": lambda x: x[1] < tol,
            "top": lambda x: x[1] > h - tol,
        }
    )


def dof_field(body, fx, fy):
    """Displacement vector from nodal functions u_x = fx(X, Y), u_y = fy(X, Y)."""
    u = np.zeros(body.ndof)
    X, Y = body.X.T
    u[body.xdofs[:, 0]], u[body.xdofs[:, 1]] = fx(X, Y), fy(X, Y)
    return u


def fd_jacobian_error(f, jac, u, seed=0, h=1e-6):
    """Relative error of jac @ du against a central difference of f along a random du."""
    du = np.random.default_rng(seed).standard_normal(len(u))
    fd = (f(u + h * du) - f(u - h * du)) / (2 * h)
    return np.linalg.norm(fd - jac @ du) / np.linalg.norm(fd)


# -- tangents ----------------------------------------------------------------


@pytest.mark.parametrize("tri", [False, True])
@pytest.mark.parametrize("kind,material", COMBOS)
def test_tangent_matches_finite_differences(kind, material, tri):
    body = Continuum(block(tri=tri), E, NU, 1.0, kind=kind, material=material)
    u = 0.05 * np.random.default_rng(1).standard_normal(body.ndof)
    R, K = body.internal(u)
    assert fd_jacobian_error(lambda v: body.internal(v)[0], K, u) < 1e-6
    # R is the gradient of the strain energy
    grad = np.array([R])
    assert fd_jacobian_error(lambda v: np.array([body.strain_energy(v)]), grad, u) < 1e-6


@pytest.mark.parametrize("tri", [False, True])
@pytest.mark.parametrize("kind", ["plane_strain", "plane_stress", "axisymmetric"])
def test_linear_strain_energy_is_the_integral_of_W(kind, tri):
    """The linear body's energy u.K u / 2 is int W dV of materials.linear_elastic at the
    quadrature points (2 pi r for axisymmetric), to rounding: a sum of ~100 positive terms
    rounds at ~1e-15, so 1e-12 leaves a factor 1000."""
    from skfem import Functional, asm

    from contactfem.bodies.materials import linear_elastic

    body = Continuum(block(tri=tri), E, NU, 1.0, kind=kind)
    u = 0.05 * np.random.default_rng(2).standard_normal(body.ndof)
    uq = body.basis.interpolate(u)
    F = np.zeros((3, 3) + uq.shape[1:])
    F[:2, :2] = uq.grad
    if kind == "axisymmetric":
        F[2, 2] = uq[0] / body.basis.global_coordinates()[0]
    F += np.eye(3)[:, :, None, None]
    W = linear_elastic(F, body.lam, body.mu)[0]
    weight = (lambda w: 2 * np.pi * w.x[0]) if kind == "axisymmetric" else (lambda w: body.thickness)
    integral = asm(Functional(lambda w: w.W * weight(w)), body.basis, W=W)
    assert body.strain_energy(u) == pytest.approx(integral, rel=1e-12, abs=0)


@pytest.mark.parametrize("tri", [False, True])
@pytest.mark.parametrize("kind", ["plane_strain", "plane_stress", "axisymmetric"])
def test_linear_stiffness_is_the_general_tangent_form_with_C(kind, tri):
    """The linear material's K (its own form: lam tr eps tr eps + 2 mu eps : eps) equals the
    general tangent form grad v : A : grad du with A = C of materials.linear_elastic, entry by
    entry, to rounding (sums of a few terms of size ~E: 1e-13 E leaves a factor ~100)."""
    from skfem import asm

    from contactfem.bodies.continuum import _tangent_form
    from contactfem.bodies.materials import linear_elastic

    body = Continuum(block(tri=tri), E, NU, 1.0, kind=kind)
    F = np.broadcast_to(np.eye(3)[:, :, None, None], (3, 3) + body.basis.dx.shape)
    A = linear_elastic(F, body.lam, body.mu)[2]
    general = asm(_tangent_form, body.basis, A=A, axi=body.axi, thickness=body.thickness)
    K = body.internal(np.zeros(body.ndof))[1]
    assert abs(K - general).max() < 1e-13 * E


# -- patch tests -------------------------------------------------------------


@pytest.mark.parametrize("material", ["linear", "svk", "neohooke"])
def test_uniform_stretch_gives_uniform_stress(material):
    body = Continuum(block(tri=True), E, NU, 1.0, material=material)
    u = dof_field(body, lambda X, Y: 0.1 * X, lambda X, Y: -0.05 * Y)
    sigma = body.cauchy_stress(u)
    assert np.allclose(sigma, sigma[0], atol=1e-10 * E)
    R, _ = body.internal(u)
    boundary = np.unique(body.mesh.facets[:, body.mesh.boundary_facets()])
    interior = np.setdiff1d(np.arange(len(body.X)), boundary)
    assert np.allclose(R[body.xdofs[interior]], 0.0, atol=1e-10 * E)
    if material == "linear":
        eps = np.diag([0.1, -0.05, 0.0])
        assert np.allclose(sigma[0], LAM * np.trace(eps) * np.eye(3) + 2 * MU * eps)


@pytest.mark.parametrize("material", ["svk", "neohooke"])
def test_rigid_rotation_is_stress_free(material):
    body = Continuum(block(), E, NU, 1.0, material=material)
    u = dof_field(body, lambda X, Y: -Y - X, lambda X, Y: X - Y)  # 90 deg: x = -Y, y = X
    R, _ = body.internal(u)
    assert np.abs(R).max() < 1e-10 * E
    assert abs(body.strain_energy(u)) < 1e-10 * E


@pytest.mark.parametrize("kind", ["plane_strain", "axisymmetric"])
def test_linear_agrees_with_svk_at_tiny_strain(kind):
    lin = Continuum(block(), E, NU, 1.0, kind=kind, material="linear")
    svk = Continuum(block(), E, NU, 1.0, kind=kind, material="svk")
    u = 1e-7 * np.random.default_rng(2).standard_normal(lin.ndof)
    R_lin, R_svk = lin.internal(u)[0], svk.internal(u)[0]
    assert np.linalg.norm(R_svk - R_lin) < 1e-5 * np.linalg.norm(R_lin)


# -- axisymmetric closed forms -----------------------------------------------


def test_uniform_radial_expansion():
    body = Continuum(block(tri=True), E, NU, 1.0, kind="axisymmetric")
    eps = 1e-3
    sigma = body.cauchy_stress(dof_field(body, lambda r, z: eps * r, lambda r, z: 0 * z))
    expected = np.diag([2 * (LAM + MU) * eps, 2 * LAM * eps, 2 * (LAM + MU) * eps])
    assert np.allclose(sigma, expected)  # [rr, zz, hoop]


@pytest.mark.parametrize("follower", [False, True])
def test_thick_cylinder_under_internal_pressure_vs_lame(follower):
    """Linear solve, so the follower load is taken at u = 0 (where it equals the dead one)."""
    a, b, p = 1.0, 2.0, 1.0
    body = Continuum(block(a, b, 0.2, nx=8, ny=1), E, NU, 0.0, kind="axisymmetric")
    load = Pressure(body, "inner", p, follower=follower)
    P = load.assemble(np.zeros(body.ndof), 0.0)[0]
    _, K = body.internal(np.zeros(body.ndof))
    free = body.xdofs[:, 0]  # u_z = 0 everywhere: plane strain in z
    u = np.zeros(body.ndof)
    u[free] = spsolve(K[free][:, free].tocsc(), P[free])
    # Lame, u = A r + B / r, sigma_rr = 2 (lam + mu) A - 2 mu B / r^2, sigma_rr(a) = -p, sigma_rr(b) = 0
    A, B = np.linalg.solve([[2 * (LAM + MU), -2 * MU / a**2], [2 * (LAM + MU), -2 * MU / b**2]], [-p, 0.0])
    r = body.X[:, 0]
    assert np.allclose(u[body.xdofs[:, 0]], A * r + B / r, rtol=0.01)


# -- mass --------------------------------------------------------------------


@pytest.mark.parametrize("kind,volume", [("plane_strain", 3.0 * 1.0), ("axisymmetric", np.pi * 3.0)])
def test_lumped_mass_sums_to_rho_volume(kind, volume):
    rho = 7.0
    body = Continuum(block(tri=True), E, NU, rho, kind=kind, thickness=3.0)
    m = body.mass()
    assert m.shape == (body.ndof,) and np.all(m > 0)
    assert np.isclose(m[body.xdofs[:, 0]].sum(), rho * volume)
    assert np.isclose(m[body.xdofs[:, 1]].sum(), rho * volume)


# -- loads -------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["plane_strain", "axisymmetric"])
def test_follower_pressure_tangent(kind):
    body = Continuum(block(), E, NU, 1.0, kind=kind)
    body.dof_offset = 3  # placed inside a larger system
    u = np.zeros(body.ndof + 5)
    u[3 : 3 + body.ndof] = 0.1 * np.random.default_rng(3).standard_normal(body.ndof)
    for name in ["inner", "top"]:
        load = Pressure(body, name, lambda t: 2.0 * t, follower=True)
        P, rows, cols, vals = load.assemble(u, 1.5)
        K = sp.coo_matrix((vals, (rows, cols)), shape=(len(u), len(u)))
        assert fd_jacobian_error(lambda v: load.assemble(v, 1.5)[0], K, u) < 1e-6


def test_load_resultants():
    body = Continuum(block(r0=0.0, r1=2.0, h=1.0), E, NU, 1.0, thickness=0.5)
    u0 = np.zeros(body.ndof)
    assert np.allclose(Traction(body, "top", (1.0, -3.0)).total_force(u0, 0.0), [1.0, -3.0])  # * 2 * 0.5
    assert np.allclose(BodyForce(body, lambda t: (0.0, -t)).total_force(u0, 4.0), [0.0, -4.0])
    for follower in [False, True]:
        # pressure 2 on the top edge (length 2, thickness 0.5) pushes down with 2
        assert np.allclose(Pressure(body, "top", 2.0, follower).total_force(u0, 0.0), [0.0, -2.0])
    # axisymmetric: dead traction on the top annulus r in [1, 2]: t * pi (2^2 - 1^2)
    axi = Continuum(block(), E, NU, 1.0, kind="axisymmetric")
    assert np.allclose(Traction(axi, "top", (0.0, 1.0)).total_force(np.zeros(axi.ndof), 0.0), [0.0, 3 * np.pi])


def test_boundary_nodes_are_ordered_with_body_on_the_right():
    body = Continuum(block(), E, NU, 1.0)
    X = body.X[body.boundary_nodes("bottom")]
    assert np.all(X[:, 1] == 0.0) and np.all(np.diff(X[:, 0]) < 0)  # walk -x: body (y > 0) on the right


# -- errors ------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs,word",
    [
        (dict(E=-1.0), "E"),
        (dict(nu=0.5), "nu"),
        (dict(nu=-1.0), "nu"),
        (dict(rho=-1.0), "rho"),
        (dict(kind="3d"), "kind"),
        (dict(material="steel"), "material"),
        (dict(kind="plane_stress", material="svk"), "material"),
        (dict(thickness=0.0), "thickness"),
    ],
)
def test_bad_input_raises(kwargs, word):
    args = dict(mesh=block(), E=E, nu=NU, rho=1.0) | kwargs
    with pytest.raises(ValueError, match=word):
        Continuum(**args)


def test_unknown_boundary_raises():
    with pytest.raises(ValueError, match="boundary"):
        Continuum(block(), E, NU, 1.0).boundary_nodes("nowhere")


@pytest.mark.parametrize("material", ["svk", "neohooke"])
def test_inverted_element_raises(material):
    body = Continuum(block(), E, NU, 1.0, material=material)
    u = dof_field(body, lambda X, Y: -2.0 * X, lambda X, Y: 0 * Y)  # x = -X: mirrored
    with pytest.raises(InvertedElementError, match="element volume non-positive"):
        body.internal(u)


@pytest.mark.parametrize("tri", [False, True])
def test_corner_jacobian_ratios(tri):
    """det J of the deformed over the reference element at its corners: det F for a homogeneous
    deformation (any element shape), 1 for a rigid rotation; <= 0 where an element is folded,
    which a small-strain (linear) body reports instead of raising."""
    body = Continuum(block(tri=tri), E, NU, 1.0)  # linear: no error raised
    F = np.array([[1.3, 0.2], [-0.1, 0.7]])
    u = dof_field(body, lambda X, Y: (F[0, 0] - 1) * X + F[0, 1] * Y, lambda X, Y: F[1, 0] * X + (F[1, 1] - 1) * Y)
    assert np.allclose(body.corner_jacobian_ratios(u), np.linalg.det(F), rtol=1e-12)
    c, s = np.cos(1.1), np.sin(1.1)
    u = dof_field(body, lambda X, Y: c * X - s * Y - X, lambda X, Y: s * X + c * Y - Y)
    assert np.allclose(body.corner_jacobian_ratios(u), 1.0, rtol=1e-12)
    assert body.inverted_elements(u).size == 0
    u = dof_field(body, lambda X, Y: -2.0 * X, lambda X, Y: 0 * Y)  # x = -X: every element mirrored
    assert np.array_equal(body.inverted_elements(u), np.arange(body.mesh.t.shape[1]))
    # one node pushed through its element's opposite side folds the elements around it
    u = np.zeros(body.ndof)
    k = int(np.argmin(np.linalg.norm(body.X - [1.5, 2.0 / 3.0], axis=1)))  # an interior node
    u[body.xdofs[k, 1]] = -0.9
    bad = body.inverted_elements(u)
    assert 0 < bad.size and all(k in body.mesh.t[:, e] for e in bad)
