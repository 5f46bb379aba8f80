"""Study 3, cost: the time of one Newton iteration split into bulk assembly
(body.internal), contact (contact.assemble), global assembly (summing into K) and linear
solve (SuperLU with two orderings, LAPACK's band LU where the System chose it, and
pypardiso if installed), at the paper sizes and
for the block refined to about 1e5 unknowns; contact time against the number of contact
nodes (slope ~1: linear)."""

import numpy as np

from ... import lazy
from ...scenes import block, get_scene, hertz, rolling_ring
from .common import best_of

sp = lazy.module("scipy.sparse")
linalg = lazy.module("scipy.sparse.linalg")


def iteration_cost(system, u, t=1.0, repeat=3, solvers=True, dt=None, state=None):
    """Wall times (best of `repeat`) of the parts of one Newton iteration at u:
    bulk (every body.internal_coo, as the System calls it), contact (every contact's
    evaluation and scatter), assembly (the whole System.evaluate minus those two: loads,
    summing the triplets into K), solve (splu factor +
    solve of the free block with the default COLAMD and with MMD_AT_PLUS_A ordering, the
    band LU if the System solves banded, SuperLU after its nested-dissection renumbering if
    the System has one (its METIS ordering, made once per pattern, not included), and
    pypardiso if installed); ``solve_s`` is the solver newton() uses (``linear_algebra``)."""
    state = system.start(u, t) if state is None else state  # the SystemState evaluated with
    out = dict(ndof=int(system.ndof))
    # each body as the System evaluates it (a beam's COO triplets, a continuum's sparse K)
    _, out["bulk_s"] = best_of(
        lambda: [b.internal_coo(system.local(b, u), dt, bs) for b, bs in zip(system.bodies, state.bodies)], repeat
    )
    _, out["contact_s"] = best_of(
        lambda: [
            c.evaluate(u, t, dt, history=h, offsets=system.offsets).scatter(system.ndof)
            for c, h in zip(system.contacts, state.contacts)
        ],
        repeat,
    )
    (G, K), total = best_of(lambda: system.residual_tangent(u, t, dt=dt, state=state), repeat)
    out["assembly_s"] = max(total - out["bulk_s"] - out["contact_s"], 0.0)
    out["residual_tangent_s"] = total
    free = system.free_dofs
    Kff = sp.csr_matrix(K)[free][:, free].tocsc()
    b = -G[free]
    out["n_contact_nodes"] = int(sum(len(c.nodes) for c in system.contacts))
    if not solvers:
        return out
    for spec in ("COLAMD", "MMD_AT_PLUS_A"):
        _, out[f"solve_splu_{spec}_s"] = best_of(lambda: linalg.splu(Kff, permc_spec=spec).solve(b), repeat)
    plan = getattr(K, "band_plan", None)
    out["linear_algebra"] = system.linear_algebra
    out["solve_banded_s"] = (
        best_of(lambda: plan.solve(K.data, b), repeat)[1] if plan is not None and plan.fits(K, free) else None
    )
    nd = getattr(K, "dissection_plan", None)  # SuperLU after METIS's renumbering (its plan made once)
    out["solve_dissection_s"] = (
        best_of(lambda: nd.solve(K.data, b), repeat)[1] if nd is not None and nd.fits(K, free) else None
    )
    try:
        import pypardiso  # optional: Intel's PARDISO, measured where it is installed

        A = Kff.tocsr()
        pypardiso.spsolve(A, b)  # first call: library initialisation
        # spsolve would reuse the factors of the same matrix: factorise explicitly each time
        ps = pypardiso.PyPardisoSolver()
        ps.solve(A, b)
        _, out["solve_pypardiso_s"] = best_of(lambda: (ps.factorize(A), ps.solve(A, b)), repeat)
    except ImportError:
        out["solve_pypardiso_s"] = None
    out["solve_s"] = next(
        x
        for x in (
            out["solve_banded_s"],
            out["solve_dissection_s"],  # what newton() uses
            out["solve_splu_MMD_AT_PLUS_A_s"],
        )
        if x is not None
    )
    return out


def _block_system(nx, ny, material="linear", width=None):
    # plane strain: the finite-strain materials have no plane-stress form
    p = get_scene("block").resolve("paper", {"law": "coulomb", "material": material, "plane": "strain"})
    p = dict(p, nx=nx, ny=ny)  # past the scene's nx <= 400 for the scaling study
    if width is not None:
        p.update(width=width, height=width * ny / nx)  # square elements
    b = block.build(p)
    u = np.zeros(b.system.ndof)
    state = b.system.start(u)
    # a state with every slave in contact: the block pushed down by 1e-3 (stick)
    u[b.parts["body"].xdofs[:, 1]] = -1e-3
    return b.system, u, state


def cost_study(quick=False):
    """Study 3 (module docstring)."""
    cases = {}
    for material in ("linear", "svk"):
        system, u, state = _block_system(20, 10, material)
        cases[f"block 20x10 ({material})"] = iteration_cost(system, u, state=state)
    hz = get_scene("hertz")
    m = hertz.build(hz.resolve("paper", {"n_el": 32 if quick else 64}))
    u = np.zeros(m.system.ndof)
    u[m.parts["body"].xdofs[:, 1]] = -(m.parts["a_exact"] ** 2) / (2 * 10.0)
    cases[f"hertz {m.parts['body'].mesh.t.shape[1]} quads"] = iteration_cost(m.system, u)
    ring = rolling_ring.build(get_scene("rolling_ring").resolve("paper"))
    u = np.zeros(ring.system.ndof)
    cases["rolling ring 120 beams"] = iteration_cost(ring.system, u, t=0.0)
    n_big = 64 if quick else 223  # 2 (n + 1)^2 = 100352 unknowns
    for material in ("linear",) if quick else ("linear", "svk"):
        system, u, state = _block_system(n_big, n_big, material)
        system.residual_tangent(u, 1.0, state=state)  # the linear body caches its K
        cases[f"block {n_big}x{n_big} ({material})"] = iteration_cost(
            system, u, repeat=1 if not quick else 2, state=state
        )

    # contact cost against the number of contact nodes (a one-element-high strip)
    scaling = []
    for nx in (50, 200, 800) if quick else (50, 200, 800, 1600, 3200):
        system, u, state = _block_system(nx, 1, width=4.0)
        c = system.contacts[0]
        _, t_c = best_of(
            lambda: c.evaluate(u, 1.0, history=state.contacts[0], offsets=system.offsets).scatter(system.ndof), 5
        )
        scaling.append(dict(n_contact_nodes=int(len(c.nodes)), contact_s=t_c))
    slope = float(
        np.polyfit(
            np.log([r["n_contact_nodes"] for r in scaling[1:]]), np.log([r["contact_s"] for r in scaling[1:]]), 1
        )[0]
    )
    return dict(cases=cases, contact_scaling=scaling, contact_scaling_slope=slope)
