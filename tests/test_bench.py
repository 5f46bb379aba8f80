"""`contactfem bench` and the staggered algorithm (issue 6).

The staggered (normal-then-friction) algorithm of Sec. 2.2 converges to the consistent
Newton's solution with more linear solves; each of its phases has the exact tangent of
its own residual (FD check); the quick bench writes valid JSON and markdown and shows the
consistent tangent needing fewer solves than the alternatives where they converge.
No timing is asserted (times depend on the machine)."""

import json

import numpy as np
import pytest
from fd import fd_jacobian, rel_error

from contactfem.cli import main
from contactfem.contact import NodeToSegment, RigidLine
from contactfem.laws import Coulomb, ParabolicSlip, PowerLaw
from contactfem.scenes import block, get_scene
from contactfem.contact.tangents import freeze
from contactfem.solver import NewtonError, Static
from contactfem.solver.newton import force_scale
from contactfem.solver.staggered import Staggered
from contactfem.lab.bench import observed_order, write_markdown

from conftest import PointCloud


def _block_staggered(params, max_cycles=200):
    b = block.build(params)
    system = b.system
    stepper = Staggered(
        Static(system, atol=params["atol"], rtol=params["rtol"], maxit=params["maxit"]), max_cycles=max_cycles
    )
    u = np.zeros(system.ndof)
    state = system.start(u)
    u1, _, _, res = stepper.step(0.0, u, u, u, 1.0, state=state)
    return state, system, u1, res


@pytest.mark.parametrize("law", ["coulomb", "parabolic"])
def test_staggered_converges_to_the_newton_solution_with_more_solves(law):
    params = get_scene("block").resolve("paper", {"law": law})
    ref = block.solve(params)
    start, system, u, res = _block_staggered(params)
    # same solution: both satisfy the same full residual to 1e-10 relative
    scale = np.max(np.abs(ref["u"]))
    assert np.max(np.abs(u - ref["u"])) < 1e-8 * scale, "staggered and Newton solutions differ"
    # converged by newton's own test in force units: the largest free residual against the force scale
    ev = system.evaluate(u, 1.0, 1.0, state=start)
    free = system.free_dofs
    assert np.max(np.abs(ev.G[free])) <= params["atol"] + params["rtol"] * force_scale(ev, free)
    # more work: consistent Newton 5-6 solves, staggered ~ 3x (linear convergence of the cycles)
    assert res.iterations > ref["result"].iterations, (res.iterations, ref["result"].iterations)
    assert res.cycles >= 3
    assert res.iterations == sum(res.phase_iterations)
    # the cycles converge linearly: the contraction factor stays well below 1 (but for the last
    # cycle, which may only move the residual within its round-off, ~1e-8 here, below the tolerance)
    r = np.asarray(res.residuals)
    assert np.all(r[2:-1] < 0.5 * r[1:-2]), r


def test_staggered_raises_after_max_cycles():
    params = get_scene("block").resolve("paper", {"law": "coulomb"})
    with pytest.raises(NewtonError, match="staggered: no convergence in 2 cycles"):
        _block_staggered(params, max_cycles=2)


def test_frictionless_contact_is_the_same_in_every_phase():
    X = np.stack([np.linspace(0.1, 0.9, 4), np.zeros(4)], axis=1)
    body = PointCloud(X, "slave")
    c = NodeToSegment(body, np.arange(4), RigidLine((0.0, 0.0), (0.0, 1.0)), normal=PowerLaw(50.0, 1.0))
    u = np.zeros(body.ndof)
    u[1::2] = -0.01
    h = c.start(np.zeros(body.ndof))
    state = c.evaluate(u, history=h)
    full = state.scatter(len(u))
    for phase in ("normal", "friction"):
        for a, b in zip(c.evaluate(u, phase=freeze(state, phase), history=h).scatter(len(u)), full):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("phase", ["normal", "friction"])
@pytest.mark.parametrize("friction", [Coulomb(c_T=30.0, mu=0.3), ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5)])
def test_phase_tangents_match_finite_differences(phase, friction):
    """Each phase's tangent is the exact Jacobian of that phase's residual (frozen data fixed)."""
    rng = np.random.default_rng(3)
    X = np.stack([np.linspace(0.1, 0.9, 5), np.zeros(5)], axis=1)
    body = PointCloud(X, "slave")
    c = NodeToSegment(
        body, np.arange(5), RigidLine((0.0, 0.0), (0.0, 1.0)), normal=PowerLaw(50.0, 1.0), friction=friction
    )
    u0 = np.zeros(body.ndof)
    h = c.start(u0)
    u = u0.copy()
    u[1::2] = -0.05 * (0.5 + rng.random(5))
    u[0::2] = 0.02 * rng.standard_normal(5)  # some nodes slip, some stick
    frozen = freeze(
        c.evaluate(u + 0.003 * rng.standard_normal(len(u)), history=h), phase
    )  # frozen data from another state
    _, rows, cols, vals = c.evaluate(u, phase=frozen, history=h).scatter(len(u))
    K = np.zeros((len(u), len(u)))
    np.add.at(K, (rows, cols), vals)
    Kfd = fd_jacobian(lambda v: c.evaluate(v, phase=frozen, history=h).scatter(len(u))[0], u)
    assert rel_error(K, Kfd) < 1e-6
    if phase == "friction":  # no coupling c_N^s C: the tangent differs from the consistent one
        _, r2, c2, v2 = c.evaluate(u, history=h).scatter(len(u))
        K2 = np.zeros_like(K)
        np.add.at(K2, (r2, c2), v2)
        assert rel_error(K, K2) > 1e-3


def test_a_bad_phase_is_refused():
    params = get_scene("block").resolve("paper")
    b = block.build(params)
    state = b.system.start(np.zeros(b.system.ndof))
    with pytest.raises(ValueError, match="phase"):
        freeze(b.parts["contact"].evaluate(np.zeros(b.system.ndof), history=state.contacts[0]), "tangential")


def test_observed_order_of_a_power_law():
    h = np.array([0.1, 0.05, 0.025])
    assert observed_order(h, 3.0 * h**2) == pytest.approx(2.0)
    assert observed_order(h[:1], h[:1]) is None


@pytest.mark.slow
def test_quick_bench_writes_json_and_markdown(tmp_path):
    """The quick bench (seconds) through the CLI; its tangent study shows the
    paper's claim: the consistent tangent needs the fewest linear solves, the staggered
    algorithm reaches the same solution with more."""
    assert main(["bench", "--quick", "--out", str(tmp_path)]) == 0
    res = json.loads((tmp_path / "bench.json").read_text())
    md = (tmp_path / "BENCHMARKS.md").read_text()
    assert md == write_markdown(res)
    for section in (
        "## The paper's claim",
        "## Work against precision",
        "## Cost of one Newton iteration",
        "## Targets",
        "## Penalty, Uzawa, semi-smooth Newton",
        "## Scaling",
    ):
        assert section in md
    assert "nan" not in md.lower()
    loads = res["speed"]["startup"]["loads"]  # the start-up account's claims, from the run
    assert loads["run_rings"] == [] and "skfem" in loads["run_block_canonical"]
    assert "What the block's process loads" in md and "The run of rings loads none of" in md
    lim = res["speed"]["limit"]  # the account of one iteration against its floor
    assert lim["n"] == 48 and lim["entries"] == 576 and 0 < lim["assembly_s"] < lim["limit_s"]
    assert "### Where the microseconds of one iteration go: sloping impact, frictional (48 unknowns" in md

    tg = res["tangents"]
    for law, rows in tg["block"].items():
        best = rows["consistent"]["iterations"]
        assert rows["consistent"]["converged"]
        for v in ("symmetric", "frozen", "staggered"):
            if rows[v]["converged"]:
                assert rows[v]["iterations"] > best, (law, v, rows[v]["iterations"], best)
                assert rows[v]["max_difference_to_consistent"] < 1e-8
    imp = tg["sloping_impact"]
    assert imp["consistent"]["converged"]
    for v in ("symmetric", "frozen", "staggered"):
        if imp[v]["converged"]:
            assert imp[v]["iterations"] > imp["consistent"]["iterations"]
            # the same motion: rebound velocity to 1e-6
            assert abs(imp[v]["rebound_vx"] - imp["consistent"]["rebound_vx"]) < 1e-6

    c = res["cost"]
    for name, r in c["cases"].items():
        assert r["ndof"] > 0 and r["solve_s"] > 0
    ring = c["cases"]["rolling ring 120 beams"]  # the solve newton() uses: banded for the ring
    assert ring["linear_algebra"] == "banded" and ring["solve_s"] == ring["solve_banded_s"]
    assert all(r["solve_banded_s"] is None for n, r in c["cases"].items() if n.startswith("hertz"))
    wp = res["work_precision"]
    assert all(r["ok"] for r in wp["hertz_mesh"]["rows"])
    assert abs(wp["hertz_mesh"]["rows"][-1]["error_p0"]) < 0.005  # 32^2 quads: p0 within 0.5 %
    assert res["targets"]["hertz"]["p0_within"]


def test_bench_cli_names_every_study():
    """`contactfem bench --only NAME` offers exactly the studies run_bench knows."""
    from contactfem.cli import BENCH_STUDIES
    from contactfem.lab.bench import STUDIES

    assert tuple(STUDIES) == BENCH_STUDIES


def test_a_quick_bench_never_replaces_or_mixes_with_a_full_run(tmp_path, monkeypatch, capsys):
    """--quick writes into bench-quick/ by default; a folder holding the other kind of run is
    refused before anything runs (one line naming --out)."""
    import contactfem.lab.bench as bench

    ran = []
    monkeypatch.setattr(
        bench,
        "run_bench",
        lambda quick=False, only=None, progress=None: ran.append(quick) or {"quick": quick, "machine": {}},
    )
    monkeypatch.chdir(tmp_path)
    assert main(["bench", "--quick", "--only", "speed"]) == 0
    assert (tmp_path / "bench-quick" / "bench.json").exists() and not (tmp_path / "bench.json").exists()
    (tmp_path / "bench.json").write_text(json.dumps({"quick": False, "machine": {}, "speed": {}}))
    assert main(["bench", "--quick", "--only", "speed", "--out", "."]) == 2
    assert "--out .: bench.json holds a full bench run" in capsys.readouterr().err
    assert main(["bench", "--only", "speed", "--out", "bench-quick"]) == 2
    (tmp_path / "afile").write_text("")
    assert main(["bench", "--quick", "--out", "afile"]) == 2
    assert "--out afile: is a file" in capsys.readouterr().err
    assert ran == [True]  # nothing ran for the refused ones


def test_the_committed_tangent_and_cost_studies_show_the_papers_claim():
    """The committed bench.json (the front page's blocks of it: tests/test_readme.py): on the block the
    consistent tangent needs the fewest iterations of the tangents that converge and the symmetrised one
    diverges once nodes slip; the banded LU is faster than SuperLU in every banded case of the cost study."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    bench = json.loads((root / "bench.json").read_text())
    blk = bench["tangents"]["block"]
    for law in blk:
        n = {v: blk[law][v]["iterations"] for v in ("consistent", "frozen", "staggered")}
        assert n["consistent"] == min(n.values()), (law, n)
    assert not any(blk[law]["symmetric"]["converged"] for law in blk)
    speedups = [
        r["solve_splu_MMD_AT_PLUS_A_s"] / r["solve_banded_s"]
        for r in bench["cost"]["cases"].values()
        if r.get("solve_banded_s")
    ]
    assert speedups and all(x > 1 for x in speedups), speedups
