"""Results do not depend on the order of the contact nodes or on the mesh numbering
(issue 6): the same frictional impact computed with permuted slave lists, permuted node
and element numbers, on a rigid and on a deformable master, gives the same motion."""

import numpy as np
import pytest
from skfem import MeshQuad

from contactfem.bodies.continuum import Continuum
from contactfem.contact import BodySurface, NodeToSegment, RigidLine, tributary_lengths
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.solver import Dirichlet, Newmark, System, integrate

TOL = 1e-8  # relative; the runs differ only by rounding (summation and pivoting order)


def block(x0, y0, nx, ny, perm_rng=None, name="block"):
    """A 1 x 0.5 block of nx x ny quads; with perm_rng its nodes and elements are renumbered
    at random. Returns (body, old_of_new): body node i is node old_of_new[i] of the plain mesh."""
    mesh = MeshQuad.init_tensor(np.linspace(x0, x0 + 1.0, nx + 1), np.linspace(y0, y0 + 0.5, ny + 1))
    p, t = mesh.p, mesh.t
    old_of_new = np.arange(p.shape[1])
    if perm_rng is not None:
        old_of_new = perm_rng.permutation(p.shape[1])
        new_of_old = np.argsort(old_of_new)
        p, t = p[:, old_of_new], new_of_old[t][:, perm_rng.permutation(t.shape[1])]
    return Continuum(MeshQuad(p, t), 100.0, 0.3, 1.0, kind="plane_strain", material="neohooke", name=name), old_of_new


def bottom_chain(body, y):
    nodes = np.flatnonzero(np.abs(body.X[:, 1] - y) < 1e-9)
    return nodes[np.argsort(body.X[nodes, 0])]


def run(rng=None, shuffle_slaves=False, deformable=False):
    """Frictional oblique impact of the upper block; final displacements of all bodies
    returned per node of the plain (unpermuted) numbering, shape (nn, 2) each."""
    upper, old_up = block(0.2, 0.0, 4, 2, rng, "upper")
    bodies, fixed = [upper], []
    if deformable:
        lower, old_lo = block(0.0, -0.5, 5, 1, rng, "lower")
        bodies.append(lower)
        top = bottom_chain(lower, 0.0)  # left to right: n = e3 x t = +y
        master = BodySurface(lower, top)
        base = np.flatnonzero(np.abs(lower.X[:, 1] + 0.5) < 1e-9)
        fixed.append(Dirichlet(lower, lower.xdofs[base].ravel(), 0.0))
        friction = ParabolicSlip(1e3, 0.1, 0.2, 0.8)
    else:
        master = RigidLine((0.0, 0.0), (0.0, 1.0))
        friction = Coulomb(1e3, 0.3)
    slaves = bottom_chain(upper, 0.0)
    w = tributary_lengths(upper.X[slaves])
    if shuffle_slaves:
        k = np.random.default_rng(7).permutation(len(slaves))
        slaves, w = slaves[k], w[k]
    contact = NodeToSegment(upper, slaves, master, normal=PowerLaw(1e3), friction=friction, weights=w)
    system = System(bodies, [contact], fixed=fixed)
    u0, v0 = np.zeros(system.ndof), np.zeros(system.ndof)
    v0[upper.xdofs[:, 0]], v0[upper.xdofs[:, 1]] = 1.0, -1.0
    hist = integrate(Newmark(system, 0.7, 0.4, atol=1e-11, rtol=1e-12, maxit=25), 0.0, u0, v0, n_steps=25, dt=0.01)
    out = []
    for b, old in zip(bodies, (old_up, old_lo) if deformable else (old_up,)):
        U = np.empty((b.X.shape[0], 2))
        U[old] = hist.u[system.global_dofs(b, b.xdofs)]
        out.append(U)
    return out, hist


@pytest.mark.slow
@pytest.mark.parametrize("deformable", [False, True], ids=["rigid_plane", "deformable_master"])
def test_order_and_numbering_do_not_matter(deformable):
    ref, h0 = run(deformable=deformable)
    assert h0.dissipation[-1] > 0  # friction was at work
    for kw in (
        dict(shuffle_slaves=True),
        dict(rng=np.random.default_rng(3)),
        dict(rng=np.random.default_rng(4), shuffle_slaves=True),
    ):
        res, h = run(deformable=deformable, **kw)
        for U, U0 in zip(res, ref):
            assert np.max(np.abs(U - U0)) <= TOL * np.max(np.abs(U0)), kw
        assert h.dissipation[-1] == pytest.approx(h0.dissipation[-1], rel=TOL)
        assert np.array_equal(h.iterations, h0.iterations)
