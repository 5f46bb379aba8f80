"""One time loop: ``contactfem.solver.march`` steps every scene, a generator of records.
Its schedules (fixed steps or an adaptive rule, with the halving of failed steps and growth)
are what the scenes need; a scene records and stops by iterating, so no scene keeps a time
loop of its own."""

import ast
import io
import math
import re
from pathlib import Path

import numpy as np
import pytest

from contactfem.solver import Adaptive, NewtonError, Static, Steps, integrate, march

SCENES = Path(__file__).resolve().parents[1] / "contactfem" / "scenes"


def private_loops(path):
    """(line, what) of every loop in the file that is a time loop: a `while` whose test
    reads t (or a time), or any loop whose body calls a stepper's step()."""
    tree = ast.parse(path.read_text())
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, (ast.For, ast.While)):
            continue
        if isinstance(node, ast.While):
            names = {n.id for n in ast.walk(node.test) if isinstance(n, ast.Name)}
            if names & {"t", "time", "s"}:
                found.append((node.lineno, f"while over {sorted(names & {'t', 'time', 's'})}"))
                continue
        for sub in ast.walk(node):
            if isinstance(sub, ast.Call) and isinstance(sub.func, ast.Attribute) and sub.func.attr == "step":
                found.append((node.lineno, "a loop calling .step()"))
                break
    return found


@pytest.mark.parametrize("path", sorted(SCENES.glob("*.py")), ids=lambda p: p.name)
def test_no_scene_keeps_its_own_time_loop(path):
    loops = private_loops(path)
    assert not loops, f"{path.name}: time loops outside solver.march: {loops}"


def test_the_grep_finds_a_private_loop(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text(
        "def run(stepper, u):\n    t = 0.0\n    while t < 1.0:\n        t += 0.1\n"
        "    for k in range(3):\n        u = stepper.step(k, u, u, u)[0]\n    return u\n"
    )
    assert [line for line, _ in private_loops(bad)] == [3, 5]


class Spring:
    """A one-dof System stand-in: G = k u - t; Newton fails while `fail` says so."""

    def __init__(self, k=2.0, fail=lambda t1, dt: False):
        self.k, self.fail = k, fail
        self.ndof, self.fixed_dofs, self.free_dofs = 1, np.zeros(0, int), np.array([0])
        self.commits = []
        self.instrument = None

    def apply_dirichlet(self, u, t):
        return np.array(u, dtype=float)

    def start(self, u, t=0.0):
        from contactfem.solver.system import SystemState

        return SystemState()

    def evaluate(self, u, t, dt=None, u0=None, mass_coefficient=0.0, phases=None, *, state):
        import scipy.sparse as sp

        from contactfem.solver import Evaluation

        return Evaluation(self.k * u - t, sp.csr_matrix([[self.k]]), (), np.array([t]), state)

    def energies(self, u, v, evaluation, dt=None, state=None):
        return dict(kinetic=0.0, strain=0.5 * self.k * float(u @ u), contact=0.0)

    def commit(self, evaluation, u, t, dt=None):
        self.commits.append(float(u[0]))
        return evaluation.state

    def mass(self):
        return np.zeros(1)


class FailingStatic(Static):
    def step(self, t, u, v, a, dt, label="", *, state):
        if self.system.fail(t + dt, dt):
            raise NewtonError(f"no convergence ({label})", [1.0], label)
        return super().step(t, u, v, a, dt, label=label, state=state)


def test_adaptive_rule_cutback_growth():
    """A rule asks for 0.25; the step ending at 0.5 fails at full size and is halved;
    with growth = 1 the halved size is kept, with growth = 2 it doubles back."""
    for growth, expected in (
        (1.0, [0.25, 0.125, 0.125, 0.125, 0.125, 0.125, 0.125]),
        (2.0, [0.25, 0.125, 0.25, 0.25, 0.125]),
    ):
        sys = Spring(fail=lambda t1, dt: abs(t1 - 0.5) < 1e-12 and dt > 0.2)
        schedule = Adaptive(lambda rec: 0.25, t_end=1.0, dt=0.25, growth=growth, max_cuts=3)
        recs = list(march(FailingStatic(sys), schedule, 0.0, np.zeros(1)))
        dts = [r.dt for r in recs[1:]]
        assert np.allclose(dts, expected[: len(dts)]) and recs[-1].t == pytest.approx(1.0)
        assert len(sys.commits) == len(recs) - 1  # committed once per accepted step
        assert (recs[0].k, recs[0].dt, recs[0].cuts) == (0, 0.0, 0) and recs[2].cuts == 1
        assert recs[2].failures and "no convergence" in recs[2].failures[0]
        assert np.allclose(recs[-1].u, 0.5)  # k u = t at t = 1


def test_the_scene_stops_by_leaving_the_loop_and_min_dt_ends_the_cuts():
    recs = []
    for rec in march(Static(Spring()), Adaptive(lambda rec: 0.1, t_end=1.0, dt=0.1), 0.0, np.zeros(1)):
        recs.append(rec)
        if rec.t >= 0.5 - 1e-12:
            break
    assert recs[-1].t == pytest.approx(0.5) and len(recs) == 6
    sys = Spring(fail=lambda t1, dt: True)
    with pytest.raises(NewtonError) as err:
        list(
            march(
                FailingStatic(sys),
                Adaptive(lambda rec: 0.5, t_end=1.0, dt=0.5, max_cuts=10, min_dt=0.1),
                0.0,
                np.zeros(1),
            )
        )
    assert err.value.record.k == 0  # the last record before the failure
    with pytest.raises(NewtonError) as err:
        integrate(FailingStatic(sys), 0.0, np.zeros(1), t_end=1.0, dt=0.5, cutback=True, max_cuts=10, min_dt=0.1)
    assert len(err.value.partial.t) == 1  # 0.5, 0.25, 0.125 failed; 0.0625 < min_dt


def test_progress_bar_follows_the_records():
    from contactfem.io import ProgressBar

    out = io.StringIO()
    integrate(
        Static(Spring()),
        0.0,
        np.zeros(1),
        n_steps=4,
        dt=0.25,
        progress=lambda t0, t1, label: ProgressBar(t0=t0, t_end=t1, label=label, stream=out),
    )
    assert "100%" in out.getvalue() and out.getvalue().endswith("\n")


def test_fixed_steps_snap_to_the_grid_and_cover_a_halved_step():
    """Steps(0.1, n_steps=3) with the step to 0.2 failing at full size: 0.1, then two halves
    of 0.05, then 0.1 again; every grid time is hit exactly."""
    sys = Spring(fail=lambda t1, dt: abs(t1 - 0.2) < 1e-12 and dt > 0.06)
    recs = list(march(FailingStatic(sys), Steps(0.1, n_steps=3, max_cuts=2), 0.0, np.zeros(1)))
    assert np.allclose([r.dt for r in recs[1:]], [0.1, 0.05, 0.05, 0.1])
    assert np.allclose([r.t for r in recs], [0.0, 0.1, 0.15, 0.2, 0.3], rtol=0, atol=1e-15)
    assert recs[3].t == 2 * 0.1 and recs[4].t == 3 * 0.1  # the grid t0 + k dt, exactly
    assert [r.cuts for r in recs] == [0, 0, 1, 0, 0]


@pytest.mark.parametrize("dt, t_end", [(0.01, 200.0), (0.001, 50.0), (1e-5, 1.0), (0.1, 1000.0), (0.3, 10.0)])
def test_fixed_steps_to_t_end_take_exactly_the_steps_that_fit(dt, t_end):
    """Steps(dt, t_end=...) over tens of thousands of steps: ceil(t_end / dt) steps, each dt but
    a shorter last one, ending at t_end; no sliver steps of round-off size (a grid time's
    (t - t0) / dt is its index only to ~k 1e-16), which a Newmark step cannot take."""
    from types import SimpleNamespace

    s = Steps(dt, t_end=t_end)
    rec, sizes = SimpleNamespace(k=0, t=0.0, dt=0.0), []
    while (h := s.next_dt(rec)) is not None and len(sizes) <= s.n_steps:
        t1 = s.end_time(rec.t, h)
        sizes.append(t1 - rec.t)
        rec = SimpleNamespace(k=rec.k + 1, t=t1, dt=t1 - rec.t)
    assert len(sizes) == math.ceil(t_end / dt - 1e-9) and rec.t == t_end
    assert min(sizes[:-1]) >= dt * (1 - 1e-9) and sizes[-1] > 0.5 * dt * 1e-9


@pytest.mark.slow
def test_run_cork_progress_shows_a_bar(capsys):
    from contactfem.cli import main

    assert main(["run", "cork", "--progress", "--set", "t_end=0.0004", "--set", "n_press=2"]) == 0
    err = capsys.readouterr().err
    assert "cork: press fit [" in err and "cork: pop [" in err and "100%" in err


@pytest.mark.slow
def test_a_run_that_ends_before_t_end_finishes_its_bar_and_says_why(capsys, tmp_path):
    """The cork stops t_flight after it has left the bottle, before t_end: its bar ends at 100 %
    with that reason, which names the run's exit time."""
    import json

    from contactfem.cli import main

    assert main(["run", "cork", "--progress", "--json", str(tmp_path / "cork.json")]) == 0
    err = capsys.readouterr().err
    last = [ln for ln in err.replace("\r", "\n").splitlines() if ln.startswith("cork: pop [")][-1]
    exit_ms = json.loads((tmp_path / "cork.json").read_text())["exit_time_ms"]
    assert "100%" in last and f"the cork left at {exit_ms:.3f} ms; the run stops t_flight" in last, last


def test_progress_bar_finish_draws_the_whole_bar_with_the_reason():
    from contactfem.io import ProgressBar

    out = io.StringIO()
    bar = ProgressBar(t0=0.0, t_end=1.0, label="x", stream=out)
    bar(0.25)
    bar.finish("stopped early")
    bar.close()
    assert out.getvalue().rstrip("\n").split("\r")[-1].startswith("x [" + "#" * 30 + "] 100%")
    assert "(stopped early)" in out.getvalue() and out.getvalue().endswith("\n")


# -- how often a run evaluated its System: counted in its results, not on objects -----------------


class CountedSpring(Spring):
    """The Spring, with the test's own count of its evaluations (what the records must add up to)."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.calls = 0

    def evaluate(self, u, t, dt=None, u0=None, mass_coefficient=0.0, phases=None, *, state):
        self.calls += 1
        return super().evaluate(u, t, dt, u0, mass_coefficient, phases, state=state)


class RejectingStatic(Static):
    """Solves every step, then rejects a step longer than 0.2 (as a step past its error share is)."""

    def step(self, t, u, v, a, dt, label="", *, state):
        u1, v1, a1, result = super().step(t, u, v, a, dt, label=label, state=state)
        if dt > 0.2:
            raise NewtonError(f"rejected ({label})", [], label, result.evaluations)
        return u1, v1, a1, result


def test_the_records_count_every_evaluation_of_the_system_the_rejected_tries_too():
    from contactfem.solver.march import evaluations

    sys = CountedSpring()
    recs = list(march(RejectingStatic(sys), Adaptive(lambda rec: 0.25, t_end=1.0, dt=0.25, max_cuts=2), 0.0, [0.0]))
    assert recs[0].evaluations == 1 and recs[1].cuts == 1 and len(recs) > 3
    assert recs[1].evaluations == 2 * recs[1].result.evaluations  # the rejected try cost what the halved one did
    assert evaluations(recs) == dict(residual_evaluations=sys.calls, contact_evaluations=0)


def test_a_failed_newton_says_how_often_it_evaluated():
    from contactfem.solver.newton import newton

    calls = []

    def fun(u):  # a residual Newton cannot bring down: G = 1 + u^2 with K = 2 u + 1
        calls.append(1)
        return np.array([1.0 + u[0] ** 2]), np.array([[2.0 * u[0] + 1.0]])

    with pytest.raises(NewtonError) as info:
        newton(fun, np.zeros(1), [0], maxit=3)
    assert info.value.evaluations == len(calls) == 4


def test_no_object_counts_its_evaluations():
    """Counts travel in results (NewtonResult, Record, a run's results): no System, contact or
    stepper keeps a counter of its own or has one incremented from outside."""
    package = Path(__file__).resolve().parents[1] / "contactfem"
    found = [
        f"{p.relative_to(package)}:{i}: {line.strip()}"
        for p in sorted(package.rglob("*.py"))
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if re.search(r"\.\w*evaluations\s*\+=|\.\w*evaluations\s*=\s*0\b", line)
    ]
    assert not found, found
