"""The fast paths change how, not what, is computed: lazy imports (the CLI's start and
`list`/`show` load no heavy library), and the dense and fixed-pattern sparse tangents
(the same results, assembled and factorised differently). No timing is asserted here:
speed is shown by `contactfem bench` (BENCHMARKS.md)."""

import json
import subprocess
import sys

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


def test_building_a_scene_loads_what_it_needs():
    """scikit-fem comes in when a scene builds a body, not before."""
    code = ("from contactfem.scenes import get_scene, sloping_impact\n"
            "sloping_impact.build(get_scene('sloping_impact').resolve('fast'))")
    assert "skfem" in heavy_modules_after(code)


# -- dense and sparse tangents -----------------------------------------------------------

def test_size_threshold_chooses_dense_then_sparse():
    assert choose_linear_algebra(DENSE_MAX) == "dense"
    assert choose_linear_algebra(DENSE_MAX + 1) == "sparse"
    assert choose_linear_algebra(10, "sparse") == "sparse"
    with pytest.raises(ValueError, match="linear_algebra"):
        choose_linear_algebra(10, "banded")


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
    assert asm.pattern_builds >= 2          # it grew at least once after the first assembly


def impact(linear_algebra, n_steps=40):
    """The frictional sloping impact (paper data) through the impact, with a chosen tangent kind."""
    p = get_scene("sloping_impact").resolve("paper", {"variant": "frictional"})
    m = sloping_impact.build(p)
    ring, contact = m["ring"], m["contact"]
    system = System([ring.body], [contact], linear_algebra=linear_algebra)
    u0 = np.zeros(system.ndof)
    contact.initialize(u0)
    system.set_dt(p["dt"])
    stepper = Newmark(system, p["dt"], p["delta"], p["beta_newmark"], atol=1e-10, rtol=1e-10, maxit=30)
    hist = integrate(stepper, 0.0, u0, ring.initial_velocity((p["vx0"], p["vy0"])), n_steps=n_steps,
                     cutback=True, max_cuts=6)
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
    _, K_d = s_d.residual_tangent(h.u, 0.8, mass_coefficient=250.0)
    _, K_s = s_s.residual_tangent(h.u, 0.8, mass_coefficient=250.0)
    assert isinstance(K_d, np.ndarray) and sp.issparse(K_s)
    assert np.allclose(K_d, as_array(K_s), rtol=1e-15, atol=1e-13 * np.abs(K_d).max())


def test_results_match_the_recorded_run_before_the_fast_paths():
    """Rebound of the paper's frictional and frictionless runs (midpoint beam integration),
    recorded with the COO -> CSR assembly and SuperLU of every Newton iteration (before the
    dense and fixed-pattern paths): unchanged to 1e-12."""
    recorded = {   # rebound_vx, rebound_vy, rebound_spin, newton_iterations_total
        "frictional": (0.9830499590681657, 1.3518834128948476, -0.09097208603823569, 457),
        "frictionless": (1.9999999999999762, 1.3125149198268034, -7.529686312116145e-15, 445),
    }
    for variant, (vx, vy, spin, iters) in recorded.items():
        # the recorded runs used one (midpoint) integration point per beam element
        res = sloping_impact.run(get_scene("sloping_impact").resolve("paper", {"variant": variant, "integration": "1"}))
        assert res["newton_iterations_total"] == iters
        for got, want in ((res["rebound_vx"], vx), (res["rebound_vy"], vy), (res["rebound_spin"], spin)):
            assert abs(got - want) <= 1e-12 * max(1.0, abs(want)), variant


# -- the bench's split of a Newton iteration -----------------------------------------------

def test_iteration_cost_splits_the_newton_time_of_a_real_run():
    """The parts add up to the measured Newton time, each part is non-negative, and the
    solves counted are the run's linear solves (times themselves are not asserted)."""
    from contactfem.scenes import run_scene
    from contactfem.studies.bench.speed import PARTS, iteration_split

    over = {"variant": "frictional", "n_steps": 30}
    cost = iteration_split("sloping_impact", "paper", over)
    assert cost["solves"] == run_scene("sloping_impact", "paper", over)["newton_iterations_total"]
    assert (cost["linear_algebra"], cost["ndof"]) == ("dense", 48)
    parts = [cost[f"{p}_s"] for p in PARTS]
    assert min(parts) >= 0.0
    assert sum(parts) == pytest.approx(cost["iteration_s"], rel=1e-9)


def test_run_json_reports_the_linear_algebra():
    from contactfem.scenes import run_scene

    small = run_scene("sloping_impact", "fast", {"n_steps": 2})
    big = run_scene("block", "fast", {})
    assert (small["linear_algebra"], small["unknowns"]) == ("dense", 48)
    assert small["ordering"].startswith("natural")
    assert (big["linear_algebra"], big["ordering"]) == ("sparse", "MMD_AT_PLUS_A")
