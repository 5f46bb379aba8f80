"""The fast paths change how, not what, is computed: lazy imports (the CLI's start and
`list`/`show` load no heavy library), and the dense and fixed-pattern sparse tangents
(the same results, assembled and factorised differently). No timing is asserted here:
speed is shown by `contactfem bench` (BENCHMARKS.md)."""

import json
import subprocess
import sys

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp

from contactfem.scenes import get_scene, sloping_impact
from contactfem.solver import Newmark, System, integrate
from contactfem.solver.assembly import DENSE_MAX, TangentAssembler, choose_linear_algebra
from contactfem.solver.system import as_array

HEAVY = ("matplotlib", "scipy", "skfem", "joblib")


def heavy_modules_after(code):
    """The heavy libraries loaded by `code`, run in a fresh interpreter."""
    probe = f"{code}\nimport sys, json\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_cli_start_imports_nothing_heavy():
    assert heavy_modules_after("import contactfem.cli; contactfem.cli.build_parser()") == []


@pytest.mark.parametrize("argv", [["list"], ["show", "block"], ["show", "cork"], ["show", "sloping_impact"]])
def test_list_and_show_import_nothing_heavy(argv):
    assert heavy_modules_after(f"from contactfem.cli import main; main({argv!r})") == []


def test_a_scene_is_found_without_importing_the_others():
    code = "from contactfem.scenes import get_scene\nassert get_scene('block').name == 'block'"
    probe = code + "\nimport sys\nprint(sorted(m for m in sys.modules if m.startswith('contactfem.scenes.')))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    loaded = eval(out.stdout.strip().splitlines()[-1])
    assert "contactfem.scenes.block" in loaded
    assert not {"contactfem.scenes.cork", "contactfem.scenes.funnel", "contactfem.scenes.hertz"} & set(loaded)


@pytest.mark.parametrize("name", ["nonsense", "base", "_private", "block.py", "../cli", ""])
def test_an_unknown_scene_name_lists_the_known_ones(name):
    with pytest.raises(ValueError, match="unknown scene.*known are.*block.*sloping_impact"):
        get_scene(name)


@pytest.mark.slow
def test_building_a_scene_loads_what_it_needs():
    """scikit-fem comes in when a scene builds a continuum, not before; a ring of beams
    (its mass summed with numpy) needs none of the heavy libraries."""
    code = "from contactfem.scenes import get_scene, {0}\n{0}.build(get_scene('{0}').resolve('fast'))"
    assert "skfem" in heavy_modules_after(code.format("block"))
    assert heavy_modules_after(code.format("sloping_impact")) == []


@pytest.mark.slow
def test_a_dense_run_from_the_command_line_loads_no_heavy_library(tmp_path):
    """The sloping impact (48 unknowns: a dense K, LAPACK through numpy) from the command
    line, its JSON written: no scipy, scikit-fem, matplotlib or joblib."""
    out = tmp_path / "r.json"
    code = (
        f"from contactfem.cli import main\nassert main(['run', 'sloping_impact', '--set', 'n_steps=5', "
        f"'--json', {str(out)!r}]) == 0"
    )
    assert heavy_modules_after(code) == []
    assert json.loads(out.read_text())["linear_algebra"] == "dense"


# -- dense and sparse tangents -----------------------------------------------------------


def test_size_threshold_chooses_dense_then_sparse():
    assert choose_linear_algebra(DENSE_MAX) == "dense"
    assert choose_linear_algebra(DENSE_MAX + 1) == "sparse"
    assert choose_linear_algebra(10, "sparse") == "sparse"
    assert choose_linear_algebra(10, "banded") == "banded"
    with pytest.raises(ValueError, match="linear_algebra"):
        choose_linear_algebra(10, "cholesky")


def test_fixed_pattern_grows_and_sums_like_coo():
    """Values scattered into the kept pattern equal scipy's COO sum, also when a later
    contribution needs entries the pattern does not have yet (the pattern grows)."""
    rng = np.random.default_rng(1)
    n = 30
    asm = TangentAssembler(n, "sparse")
    body_rows, body_cols = rng.integers(0, n, 200), rng.integers(0, n, 200)
    for k in range(4):
        vals = rng.normal(size=200)
        r, c = rng.integers(0, n, 5 + 10 * k), rng.integers(0, n, 5 + 10 * k)
        v = rng.normal(size=r.size)
        diag = rng.normal(size=n)
        K = asm.assemble([(body_rows, body_cols, vals, 0, "body"), (r, c, v, 0, None)], diag)
        ref = sp.coo_matrix((np.r_[vals, v], (np.r_[body_rows, r], np.r_[body_cols, c])), shape=(n, n)).toarray()
        assert K.format == "csc"
        assert np.allclose(K.toarray(), ref + np.diag(diag), rtol=1e-15, atol=1e-14)
        dense = TangentAssembler(n, "dense").assemble([(body_rows, body_cols, vals, 0, "b"), (r, c, v, 0, None)], diag)
        assert np.allclose(dense, ref + np.diag(diag), rtol=1e-15, atol=1e-14)
    assert asm.pattern_builds >= 2  # it grew at least once after the first assembly


def impact(linear_algebra, n_steps=40):
    """The frictional sloping impact (paper data) through the impact, with a chosen tangent kind."""
    p = get_scene("sloping_impact").resolve("paper", {"variant": "frictional"})
    m = sloping_impact.build(p, system_options=dict(linear_algebra=linear_algebra))
    ring, system = m.parts["ring"], m.system
    stepper = Newmark(system, p["delta"], p["beta_newmark"], atol=1e-10, rtol=1e-10, maxit=30)
    hist = integrate(
        stepper,
        0.0,
        np.zeros(system.ndof),
        ring.initial_velocity((p["vx0"], p["vy0"])),
        n_steps=n_steps,
        dt=p["dt"],
        cutback=True,
        max_cuts=6,
    )
    return system, hist


def test_dense_and_sparse_paths_give_the_same_run():
    """48 unknowns: dense by default; forcing the sparse path changes results only at
    roundoff (1e-12 of the largest value of each history)."""
    (s_d, h_d), (s_s, h_s) = impact("auto"), impact("sparse")
    assert (s_d.linear_algebra, s_s.linear_algebra) == ("dense", "sparse")
    assert np.array_equal(h_d.iterations, h_s.iterations)
    for key in ("u", "v", "kinetic", "strain", "contact", "dissipation"):
        a, b = getattr(h_d, key), getattr(h_s, key)
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), key


def test_effective_tangent_is_the_same_matrix_dense_and_sparse():
    s_d, h = impact("dense", n_steps=8)
    s_s = System(s_d.bodies, s_d.contacts, linear_algebra="sparse")
    state = h.records[-1].state
    _, K_d = s_d.residual_tangent(h.u, 0.8, mass_coefficient=250.0, dt=0.1, state=state)
    _, K_s = s_s.residual_tangent(h.u, 0.8, mass_coefficient=250.0, dt=0.1, state=replace(state, loads=()))
    assert isinstance(K_d, np.ndarray) and sp.issparse(K_s)
    assert np.allclose(K_d, as_array(K_s), rtol=1e-15, atol=1e-13 * np.abs(K_d).max())


# -- the bench's split of a Newton iteration -----------------------------------------------


def test_iteration_cost_splits_the_newton_time_of_a_real_run():
    """Each part is non-negative (the overhead, what the Newton time leaves after the timed
    parts, too: the parts are timed inside it), and the solves counted are the run's linear
    solves (times themselves are not asserted)."""
    from contactfem.scenes import run_scene
    from contactfem.lab.bench.speed import PARTS, iteration_split

    over = {"variant": "frictional", "n_steps": 30}
    cost = iteration_split("sloping_impact", "paper", over)
    assert cost["solves"] == run_scene("sloping_impact", "paper", over)["newton_iterations_total"]
    assert (cost["linear_algebra"], cost["ndof"]) == ("dense", 48)
    parts = [cost[f"{p}_s"] for p in PARTS]
    assert min(parts) >= 0.0


def test_run_json_reports_the_linear_algebra():
    from contactfem.scenes import run_scene

    small = run_scene("sloping_impact", "fast", {"n_steps": 2})
    mid = run_scene("block", "fast", {})
    big = run_scene("hertz", "fast", {})
    assert (small["linear_algebra"], small["unknowns"]) == ("dense", 48)
    assert small["ordering"].startswith("natural")
    assert (mid["linear_algebra"], mid["unknowns"]) == ("banded", 468)
    assert mid["ordering"] == "reverse Cuthill-McKee, LAPACK banded LU (kl=35, ku=35)"
    assert (big["linear_algebra"], big["ordering"]) == ("sparse", "MMD_AT_PLUS_A")


# -- banded tangents (LAPACK's band LU after reverse Cuthill-McKee) -------------------------


def scrambled_band(n, kl, ku, seed):
    """A random non-symmetric band matrix (kl below, ku above the diagonal) with its rows and
    columns numbered at random (the same permutation), as CSC, and the permutation."""
    rng = np.random.default_rng(seed)
    i, j = np.nonzero(np.abs(np.subtract.outer(np.arange(n), np.arange(n)) - (kl - ku) / 2) <= (kl + ku) / 2)
    A = sp.coo_matrix((rng.normal(size=i.size), (i, j)), shape=(n, n)).toarray()
    p = rng.permutation(n)
    return sp.csc_matrix(A[np.ix_(p, p)]), p


@pytest.mark.parametrize("free", [None, "some"])
def test_band_solve_matches_a_dense_solve(free):
    """A banded-after-renumbering matrix, non-symmetric (rows exchanged by pivoting): the
    band LU's solution equals numpy's dense LU to 1e-12, on all dofs and on a free block."""
    from contactfem.solver.banded import BandPlan

    n = 120
    A, _ = scrambled_band(n, 4, 7, seed=3)
    dofs = np.arange(n) if free is None else np.setdiff1d(np.arange(n), [0, 17, 55, 119])
    plan = BandPlan(A.indptr, A.indices, n, None if free is None else dofs)
    assert plan.kl + plan.ku <= 2 * (4 + 7) < n // 4  # RCM finds a band of about the original width
    b = np.random.default_rng(4).normal(size=len(dofs))
    x = plan.solve(A.data, b)
    x_ref = np.linalg.solve(A.toarray()[np.ix_(dofs, dofs)], b)
    assert np.max(np.abs(x - x_ref)) <= 1e-12 * np.max(np.abs(x_ref))


def test_singular_banded_tangent_raises_through_newton():
    """A zero pivot raises as SuperLU does (RuntimeError 'exactly singular'), and newton turns
    it into a NewtonError: never a NaN correction."""
    from contactfem.solver import NewtonError, newton
    from contactfem.solver.newton import solve_free

    n = 120
    A, _ = scrambled_band(n, 3, 3, seed=5)
    A = A.tocoo()
    vals = np.where(A.col == 40, 0.0, A.data)  # column 40 zero: singular
    asm = TangentAssembler(n, "banded")
    K = asm.assemble([(A.row, A.col, vals, 0, None)])
    assert asm.kind == "banded" and K.band_plan.fits(K, None)
    with pytest.raises(RuntimeError, match="exactly singular"):
        solve_free(K, np.ones(n), np.arange(n), True)
    with pytest.raises(NewtonError, match="singular"):
        newton(lambda u: (A.toarray() @ u - 1.0, K), np.zeros(n), np.arange(n))


def test_banded_tangent_is_the_sparse_matrix():
    """K assembled for the band solve is the same CSC matrix (values, products, toarray);
    every K owns its values (a later assembly does not change an earlier K)."""
    rng = np.random.default_rng(6)
    n = 150
    A, _ = scrambled_band(n, 5, 5, seed=7)
    A = A.tocoo()
    banded, sparse = TangentAssembler(n, "auto"), TangentAssembler(n, "sparse")
    K1 = banded.assemble([(A.row, A.col, A.data, 0, "body")], np.ones(n))
    K2 = banded.assemble([(A.row, A.col, 2 * A.data, 0, "body")])
    assert (banded.kind, sparse.kind) == ("banded", "sparse")
    ref = A.toarray() + np.eye(n)
    assert np.array_equal(K1.toarray(), ref) and np.array_equal(K2.toarray(), 2 * A.toarray())
    assert np.array_equal(K1.toarray(), sparse.assemble([(A.row, A.col, A.data, 0, "body")], np.ones(n)).toarray())
    x = rng.normal(size=n)
    assert np.allclose(K1 @ x, ref @ x, rtol=1e-14, atol=1e-14)
    assert (
        sp.issparse(K1)
        and K1.format == "csc"
        and not hasattr(sparse.assemble([(A.row, A.col, A.data, 0, None)]), "band_plan")
    )
    with pytest.raises(ValueError):  # the shared pattern is not changed in place
        K1.eliminate_zeros()
    assert np.array_equal(K2.toarray(), 2 * A.toarray())
    # the plan is for all dofs: a solve on other free dofs goes to SuperLU, with the same answer
    from contactfem.solver.newton import solve_free

    sub = np.arange(1, n - 1)
    assert not K1.band_plan.fits(K1, sub)
    assert np.allclose(
        solve_free(K1, x[sub], sub, False), np.linalg.solve(ref[np.ix_(sub, sub)], x[sub]), rtol=1e-12, atol=1e-12
    )


# Numbers that are differences of nearly equal numbers (relative errors against the exact
# solution, the cork's margin over its static estimate) or rounding-level by construction
# (the block's equilibrium error): their inputs are compared instead.
DERIVED = (
    "x_roll_rel_err",
    "v_final_rel_err",
    "x_end_rel_err",
    "breakaway_margin_MPa",
    "equilibrium_error",
    "accuracy",
)  # (the indicators: relative errors and ratios, derived like the rel_err)


# Components of one vector are compared against the vector's size: the rolling ring's
# vertical velocity (at most 13 mm/ms while rolling at up to 300) carries the rounding of
# the whole velocity, eps |u| delta / (beta dt) = 2.2e-16 * 600 * 0.7 / 0.004 = 2e-11 (paper
# preset), 2e-12 of its own largest value (the dense LAPACK solve differs from SuperLU as much).
VECTORS = {"vy_c": ("vx_c", "vy_c"), "vx_c": ("vx_c", "vy_c")}


def numbers_agree(
    a,
    b,
    rel=1e-12,
    skip=("wall_time_s", "linear_algebra", "ordering", "band_kl", "band_ku", "import_time_s") + DERIVED,
    path="",
    scale=None,
):
    """Every number of two results (nested dicts and lists) agrees to `rel` of the largest
    value of its entry (or of its vector, VECTORS); integers (iteration counts), flags and
    strings exactly."""
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            if k not in skip:
                size = (
                    max(np.max(np.abs(a[v])) for v in VECTORS[k])
                    if k in VECTORS and all(v in a for v in VECTORS[k])
                    else None
                )
                numbers_agree(a[k], b[k], rel, skip, f"{path}.{k}", size)
        return
    if isinstance(a, (str, bool, type(None), int, np.integer)):
        assert a == b, path
        return
    try:
        x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    except (TypeError, ValueError):  # a list of strings (contact states)
        assert a == b, path
        return
    assert x.shape == y.shape, path
    if x.size:
        assert np.max(np.abs(x - y)) <= rel * max(np.max(np.abs(x)), scale or 0.0, 1e-300), path


def cork_press_fit(preset):
    from contactfem.scenes import cork

    from dataclasses import replace

    from contactfem.problem.scene import simulate

    params = get_scene("cork").resolve(preset)
    model = cork.build(params)
    records = simulate(replace(model, stages=model.stages[:1]), params)  # the press fit, its first stage
    last, fit = records[-1], cork.fit_summary(model, params, records)
    system = model.systems[0]  # the press fit's (the pop's is the second)
    return dict(
        fit,
        **cork.contact_forces(last.contacts),
        u=last.u,
        linear_algebra=system.linear_algebra,
        ordering=system.ordering,
    )


def scene_run(scene, preset):
    from contactfem.scenes import run_scene

    return run_scene(scene, preset, {})


@pytest.mark.slow
@pytest.mark.parametrize(
    "run, args, kl",
    [
        (scene_run, ("rolling_ring", "fast"), 8),
        (scene_run, ("rolling_ring", "paper"), 8),
        (scene_run, ("block", "paper"), 35),
        (cork_press_fit, ("paper",), 28),
    ],
)
def test_banded_and_sparse_paths_give_the_same_run(run, args, kl, monkeypatch):
    """Solved banded (the choice for these sizes) and forced onto SuperLU (band limit
    zero), every number of the run agrees to 1e-12 of its largest value, iteration counts
    and contact states exactly: the rolling ring (a ring of beams rolling on a rough plane:
    frictional, non-symmetric tangents, 360 unknowns at the paper preset), the block (a
    continuum with Coulomb friction) and the cork's press fit (axisymmetric continuum with
    friction, its axis dofs fixed: the band of the free block).

    The cork's pop at the fast preset is not compared: its breakaway step is a knife's edge
    decided by rounding (SuperLU's COLAMD ordering flips it the same way the band LU does,
    exit velocity 30.13 against 29.90 m/s; at the paper preset all agree)."""
    from contactfem.solver import assembly

    banded = run(*args)
    monkeypatch.setattr(assembly, "BANDED_WORK", -1.0)
    sparse = run(*args)
    assert (banded["linear_algebra"], sparse["linear_algebra"]) == ("banded", "sparse")
    assert banded["ordering"] == f"reverse Cuthill-McKee, LAPACK banded LU (kl={kl}, ku={kl})"
    numbers_agree(banded, sparse)


def test_a_growing_pattern_gets_a_new_band_or_goes_sparse():
    """A contact coupling new dofs grows the pattern: the band is measured again (a chain
    closed into a ring stays banded, its K solved right), and a coupling that makes the band
    too wide for the band LU sends later solves to SuperLU; the System reports both."""
    from contactfem.solver.newton import solve_free

    n = 400
    A, p = scrambled_band(n, 4, 4, seed=8)
    A = A.tocoo()
    body = (A.row, A.col, A.data + 10.0 * (A.row == A.col), 0, "body")
    asm = TangentAssembler(n, "auto")
    K0 = asm.assemble([body])
    kl0 = K0.band_plan.kl
    first, last = np.argsort(p)[[0, -1]]  # the two ends of the chain
    ring = (np.array([first, last]), np.array([last, first]), np.array([0.5, -0.25]), 0, None)
    K1 = asm.assemble([body, ring])
    assert asm.kind == "banded" and asm.pattern_builds == 2 and K1.band_plan is not K0.band_plan
    b = np.random.default_rng(9).normal(size=n)
    for K in (K0, K1):  # an earlier K keeps its own plan
        x = solve_free(K, b, np.arange(n), True)
        assert np.max(np.abs(x - np.linalg.solve(K.toarray(), b))) <= 1e-12 * np.max(np.abs(x))
    spread = np.random.default_rng(10).choice(n, 60, replace=False)  # one contact couples them all
    r, c = np.meshgrid(spread, spread)
    wide = (r.ravel(), c.ravel(), np.full(r.size, 1e-3), 0, None)
    K2 = asm.assemble([body, ring, wide])
    assert asm.kind == "sparse" and not hasattr(K2, "band_plan") and asm.plan.work > 1.5e4 >= K1.band_plan.work
    assert asm.describe()[0] == "banded+sparse" and asm.describe()[1].endswith("+MMD_AT_PLUS_A")
    assert kl0 <= K1.band_plan.kl


def grid_pattern(m, dofs=2):
    """The CSC pattern of a bilinear m x m quad mesh, `dofs` per node, numbered row by row."""
    line = sp.csr_matrix(np.abs(np.subtract.outer(np.arange(m + 1), np.arange(m + 1))) <= 1, dtype=float)
    node = sp.kron(line, line)
    return sp.kron(node, np.ones((dofs, dofs))).tocsc()


@pytest.mark.parametrize(
    "A, free",
    [
        (scrambled_band(300, 6, 6, seed=11)[0], None),
        (scrambled_band(300, 6, 6, seed=12)[0], np.arange(0, 300, 3)),
        (grid_pattern(12), None),
        (grid_pattern(12), np.arange(5, 338)),
        (grid_pattern(30), None),
        (grid_pattern(30, 1), np.setdiff1d(np.arange(961), np.arange(0, 961, 31))),
    ],
)
def test_the_band_bound_never_excludes_a_band_the_plan_would_take(A, free):
    """banded.band_too_wide (a breadth-first bound, instead of the plan) says 'too wide' only
    where the plan's band LU work is above the limit, at every limit; it does say so for a
    fine 2-D mesh at the limit the System uses."""
    from contactfem.solver.banded import BANDED_WORK, BandPlan, band_too_wide

    A = sp.csc_matrix((A + A.T) != 0)  # a structurally symmetric pattern
    A.sort_indices()
    n = A.shape[0]
    plan = BandPlan(A.indptr, A.indices, n, free)
    assert plan.kl == plan.ku
    for work in (0.0, 10.0, 100.0, 1e3, 1e4, BANDED_WORK, 1e5):
        if band_too_wide(A.indptr, A.indices, n, free, work):
            assert plan.work > work
    fine = grid_pattern(120)  # 29282 unknowns: no numbering has a band under ~120
    assert band_too_wide(fine.indptr, fine.indices, fine.shape[0], None, BANDED_WORK)


def test_the_band_bound_gives_no_verdict_on_an_unsymmetric_pattern():
    """kl (kl + ku) is not bounded by the band of the symmetrised pattern (an upper triangle
    with one subdiagonal: kl = 1 in its own numbering, whatever its upper width): no verdict,
    where the symmetrised pattern is found too wide."""
    from contactfem.solver.banded import band_too_wide

    n = 400
    A = sp.csc_matrix(np.triu(np.ones((n, n))) + np.eye(n, k=-1))
    S = sp.csc_matrix((A + A.T) != 0)
    assert band_too_wide(S.indptr, S.indices, n, None, 1.0)
    assert not band_too_wide(A.indptr, A.indices, n, None, 1.0)


# -- nested dissection (METIS) for large sparse tangents ---------------------------------


def test_supervariables_merge_the_dofs_of_a_node():
    """The two dofs of each node of a quad mesh have the same column in the pattern: one
    supervariable a node; a pattern whose columns all differ keeps one a dof."""
    from contactfem.solver.dissection import supervariables

    A = grid_pattern(7)
    sv, k = supervariables(A.indptr, A.indices, A.shape[0])
    assert k == 64 and np.array_equal(sv, np.arange(128) // 2)
    B = sp.csc_matrix(np.eye(5) + np.eye(5, k=1))
    assert supervariables(B.indptr, B.indices, 5)[1] == 5


@pytest.mark.parametrize("free", [None, "some"])
def test_dissection_solve_matches_superlu(free):
    """A non-symmetric matrix on a 2-D mesh's pattern: SuperLU after METIS's renumbering
    (the plan) solves it as SuperLU with its own ordering does, to 1e-10 relative (both are
    LU with partial pivoting of a matrix of condition ~1e2, in a different order), on all dofs
    and on a free block; the permutation is one."""
    from scipy.sparse.linalg import splu

    from contactfem.solver.dissection import DissectionPlan

    A = grid_pattern(40).tocoo()
    rng = np.random.default_rng(7)
    A = sp.csc_matrix((rng.normal(size=A.nnz) + 20.0 * (A.row == A.col), (A.row, A.col)), shape=A.shape)
    A.sort_indices()
    n = A.shape[0]
    dofs = np.arange(n) if free is None else np.setdiff1d(np.arange(n), np.arange(0, n, 7))
    plan = DissectionPlan(A.indptr, A.indices, n, None if free is None else dofs)
    assert np.array_equal(np.sort(plan.perm), np.arange(len(dofs)))
    b = rng.normal(size=len(dofs))
    x = plan.solve(A.data, b)
    x_ref = splu(A[dofs][:, dofs].tocsc(), permc_spec="MMD_AT_PLUS_A").solve(b)
    assert np.max(np.abs(x - x_ref)) <= 1e-10 * np.max(np.abs(x_ref))


def test_singular_tangent_raises_through_the_dissection_plan():
    """An exactly singular K (a zero column) raises RuntimeError 'exactly singular' from the
    renumbered SuperLU as from the others: Newton turns it into a NewtonError."""
    from contactfem.solver.dissection import DissectionPlan

    A = grid_pattern(10).tocoo()
    vals = np.where(A.col == 33, 0.0, 1.0 + 5.0 * (A.row == A.col))
    A = sp.csc_matrix((vals, (A.row, A.col)), shape=A.shape)
    plan = DissectionPlan(A.indptr, A.indices, A.shape[0])
    with pytest.raises(RuntimeError, match="exactly singular"):
        plan.solve(A.data, np.ones(A.shape[0]))


@pytest.mark.slow
def test_hertz_renumbered_by_nested_dissection_is_the_same_run(monkeypatch):
    """Hertz on 72 x 72 quads (10.4k free unknowns, above DISSECTION_MIN) solves by SuperLU
    after METIS's renumbering, and agrees with SuperLU's own ordering (DISSECTION_MIN raised)
    to 1e-10 of each number's largest value (different elimination orders round differently)."""
    from contactfem.scenes import run_scene
    from contactfem.solver import assembly

    nd = run_scene("hertz", "paper", {"n_el": 72})
    monkeypatch.setattr(assembly, "DISSECTION_MIN", 10**9)
    mmd = run_scene("hertz", "paper", {"n_el": 72})
    assert nd["ordering"] == "nested dissection (METIS), SuperLU" and mmd["ordering"] == "MMD_AT_PLUS_A"
    assert nd["newton_iterations_total"] == mmd["newton_iterations_total"]
    for key in ("p0", "a", "p0_fit", "contact_force", "penetration_max"):
        assert nd[key] == pytest.approx(mmd[key], rel=1e-10, abs=1e-12)


def test_large_pattern_with_int32_indices():
    """Above 46340 unknowns the keys col * n + row pass 2**31: a body's int32 index arrays
    (scipy's) must not overflow them (the cost study's block of 1e5 unknowns)."""
    n = 50000
    rows = np.r_[np.arange(n), 0, n - 1].astype(np.int32)
    cols = np.r_[np.arange(n), n - 1, 0].astype(np.int32)
    vals = np.r_[np.full(n, 2.0), 0.5, -0.5]
    K = TangentAssembler(n, "sparse").assemble([(rows, cols, vals, 0, "body")], np.ones(n))
    ref = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)) + sp.identity(n)
    assert abs(K - ref).max() == 0.0 and K.nnz == n + 2


@pytest.mark.parametrize("kind", ["dense", "banded", "sparse"])
def test_a_scene_runs_with_the_linear_algebra_a_user_forces(kind, tmp_path):
    """run_scene(..., linear_algebra=) and `run --linear-algebra` reach every System the scene
    builds; the results stay those of the automatic choice (dense here) to 1e-12."""
    from contactfem.cli import main
    from contactfem.scenes import run_scene

    over = {"variant": "frictional", "n_steps": 40}
    auto = run_scene("sloping_impact", "paper", over)
    forced = run_scene("sloping_impact", "paper", over, linear_algebra=kind)
    assert (auto["linear_algebra"], forced["linear_algebra"]) == ("dense", kind)
    assert forced["newton_iterations_total"] == auto["newton_iterations_total"]
    for key in ("x_c", "y_c", "vx_c", "vy_c", "energy_total"):
        a, b = np.asarray(auto[key]), np.asarray(forced[key])
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), key
    out = tmp_path / "r.json"
    assert (
        main(
            [
                "run",
                "sloping_impact",
                "--preset",
                "paper",
                "--set",
                "variant=frictional",
                "--set",
                "n_steps=40",
                "--linear-algebra",
                kind,
                "--json",
                str(out),
            ]
        )
        == 0
    )
    assert json.loads(out.read_text())["linear_algebra"] == kind


def test_a_wrong_linear_algebra_names_the_allowed_ones():
    from contactfem.scenes import run_scene

    with pytest.raises(ValueError, match="linear_algebra = 'Sparse' is not allowed: one of auto|dense|sparse|banded"):
        run_scene("block", "fast", linear_algebra="Sparse")


@pytest.mark.slow
def test_a_run_reports_the_band_it_solved():
    from contactfem.scenes import run_scene

    ring = run_scene("rolling_ring", "fast")
    assert ring["linear_algebra"] == "banded" and (ring["band_kl"], ring["band_ku"]) == (8, 8)
    assert f"kl={ring['band_kl']}, ku={ring['band_ku']}" in ring["ordering"]
    impact = run_scene("sloping_impact", "fast", {"n_steps": 5})
    assert impact["linear_algebra"] == "dense" and impact["band_kl"] is None and impact["band_ku"] is None


@pytest.mark.parametrize("kind", ["dense", "banded", "sparse"])
def test_a_contact_set_kept_reuses_its_pattern_and_gives_the_same_tangent(kind):
    """While the pairs in contact stay, a contact hands back the same index arrays and the
    System reuses their places in K; the tangent is the one a fresh System assembles, before
    and after the contact set changes."""
    scene = get_scene("rolling_ring")
    params = scene.resolve("fast")

    def system():
        model = scene.build(params, system_options=dict(linear_algebra=kind))
        s = model.system
        return s, s.start(np.zeros(s.ndof))

    s, state = system()
    lowest = np.argmin(s.contacts[0].slave.X[s.contacts[0].nodes, 1])  # the node touching the floor
    dofs = s.contacts[0].slave_dofs()
    u1 = np.zeros(s.ndof)
    u1[dofs[lowest, 1]] = -1e-3  # one node pressed in
    u2 = u1.copy()
    u2[dofs[lowest, 0]] = 2e-4  # the same node, moved along
    u3 = u2.copy()
    u3[dofs[(lowest + 1) % len(dofs), 1]] -= 5.0  # and its neighbour pressed in
    first = s.evaluate(u1, 0.0, params["dt"], u1, mass_coefficient=1.0, state=state)
    runs = []
    for u in (u2, u3):
        ev = s.evaluate(u, 0.0, params["dt"], u1, mass_coefficient=1.0, state=state)
        other, other_state = system()
        fresh = other.evaluate(u, 0.0, params["dt"], u1, mass_coefficient=1.0, state=other_state)
        np.testing.assert_array_equal(ev.G, fresh.G)
        np.testing.assert_allclose(
            as_array(ev.K), as_array(fresh.K), rtol=0, atol=1e-12 * np.abs(as_array(fresh.K)).max()
        )
        runs.append(ev)
    n1, n2, n3 = (e.contacts[0].n_active for e in (first, *runs))
    assert n1 == n2 == 1 and n3 == 2
    r1, r2, r3 = (e.contacts[0].scatter(s.ndof)[1] for e in (first, *runs))
    assert r1 is r2 and r3 is not r2 and not r1.flags.writeable
