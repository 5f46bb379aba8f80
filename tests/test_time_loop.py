"""One time loop: ``contactfem.solver.integrate`` steps every scene. Its hooks (a dt rule
with cutback and growth, a before-step hook, prescribed motion, a stop rule, recorders, a
progress callback) are what the scenes need, so no scene keeps a loop of its own."""
import ast
import io
from pathlib import Path

import numpy as np
import pytest

from contactfem.solver import NewtonError, Static, integrate

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
    assert not loops, f"{path.name}: time loops outside solver.integrate: {loops}"


def test_the_grep_finds_a_private_loop(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("def run(stepper, u):\n    t = 0.0\n    while t < 1.0:\n        t += 0.1\n"
                   "    for k in range(3):\n        u = stepper.step(k, u, u, u)[0]\n    return u\n")
    assert [line for line, _ in private_loops(bad)] == [3, 5]


class Spring:
    """A one-dof System stand-in: G = k u - f(t); Newton fails while `fail` says so."""
    dynamic = False

    def __init__(self, k=2.0, fail=lambda t1, dt: False):
        self.k, self.fail = k, fail
        self.ndof, self.fixed_dofs, self.free_dofs = 1, np.zeros(0, int), np.array([0])
        self.commits = []

    def apply_dirichlet(self, u, t):
        return np.array(u, dtype=float)

    def set_dt(self, dt):
        self.dt = dt

    def residual_tangent(self, u, t):
        import scipy.sparse as sp
        return self.k * u - t, sp.csr_matrix([[self.k]])

    def external_force(self, u, t):
        return np.array([t])

    def energies(self, u, v):
        return dict(kinetic=0.0, strain=0.5 * self.k * float(u @ u), contact=0.0, dissipation=0.0)

    def commit(self, u):
        self.commits.append(float(u[0]))

    def mass(self):
        return np.zeros(1)


class FailingStatic(Static):
    def step(self, t, u, v, a, dt=None, label=""):
        if self.system.fail(t + dt, dt):
            raise NewtonError(f"no convergence ({label})", [1.0], label)
        return super().step(t, u, v, a, dt=dt, label=label)


def test_dt_rule_cutback_growth_and_hooks():
    """A dt rule asks for 0.25; the step ending at 0.5 fails at full size and is halved;
    with growth = 1 the halved size is kept, with growth = 2 it doubles back."""
    for growth, expected in ((1.0, [0.25, 0.125, 0.125, 0.125, 0.125, 0.125, 0.125]),
                             (2.0, [0.25, 0.125, 0.25, 0.25, 0.125])):
        sys = Spring(fail=lambda t1, dt: abs(t1 - 0.5) < 1e-12 and dt > 0.2)
        calls, moves, recs = [], [], []
        hist = integrate(FailingStatic(sys, dt=0.25), 0.0, np.zeros(1), t_end=1.0,
                         dt_rule=lambda t, u, v, a: 0.25, growth=growth, cutback=True, max_cuts=3,
                         before_step=lambda t, u, v, a: calls.append(t), motion=moves.append,
                         recorder=lambda t, u, v, a, step: recs.append((step.k, step.dt, step.cuts)))
        assert np.allclose(hist.dt[1:], expected[:len(hist.dt) - 1]) and hist.t[-1] == pytest.approx(1.0)
        assert len(calls) == len(hist.t) - 1                  # once per accepted step
        assert len(moves) == len(hist.t) - 1 + 1              # once per attempt (one failed)
        assert recs[0] == (0, 0.0, 0) and recs[2][2] == 1     # the halved step is recorded as cut once
        assert hist.failures and "no convergence" in hist.failures[0]
        assert np.allclose(hist.u, 0.5)                       # k u = t at t = 1


def test_stop_min_dt_and_progress():
    sys = Spring()
    hist = integrate(Static(sys, dt=0.1), 0.0, np.zeros(1), t_end=1.0, dt_rule=lambda t, u, v, a: 0.1,
                     stop=lambda t, u, v, a: t >= 0.5 - 1e-12)
    assert hist.t[-1] == pytest.approx(0.5)
    sys = Spring(fail=lambda t1, dt: True)
    with pytest.raises(NewtonError) as err:
        integrate(FailingStatic(sys, dt=0.5), 0.0, np.zeros(1), t_end=1.0, dt_rule=lambda t, u, v, a: 0.5,
                  cutback=True, max_cuts=10, min_dt=0.1)
    assert len(err.value.partial.failures) == 3               # 0.5, 0.25, 0.125; 0.0625 < min_dt
    from contactfem.io import ProgressBar
    out = io.StringIO()
    integrate(Static(Spring(), dt=0.25), 0.0, np.zeros(1), n_steps=4,
              progress=lambda t0, t1, label: ProgressBar(t0=t0, t_end=t1, label=label, stream=out))
    assert "100%" in out.getvalue() and out.getvalue().endswith("\n")


def test_run_cork_progress_shows_a_bar(capsys):
    from contactfem.cli import main
    assert main(["run", "cork", "--progress", "--set", "t_end=0.0004", "--set", "n_press=2"]) == 0
    err = capsys.readouterr().err
    assert "cork: press fit [" in err and "cork: pop [" in err and "100%" in err
