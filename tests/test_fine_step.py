"""The fine end: a smaller step never makes a run fail. A step's inertia is c M times a difference of
displacements (c = 1 / (beta dt^2)); in the total displacement its round-off, c M eps |u|, grows as
1 / dt^2 and passes every force of a step (solver/newton.py). Each dynamic scene, in contact, goes on
with steps 1e-5 of its own: Newton converges in every step, to its own tolerance, without a halving."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from contactfem.problem.accuracy import EQUILIBRIUM
from contactfem.scenes import get_scene
from contactfem.solver import Steps
from contactfem.solver.march import march, resume

DISC_WALL = str(Path(__file__).parents[1] / "lectures" / "examples" / "disc_wall.py")

# every dynamic scene that is one Stage, with each stepper and enforcement an impact takes
CASES = [
    ("sloping_impact", {"variant": "frictional"}),
    ("sloping_impact", {"variant": "frictional", "contact_integration": "energy_consistent"}),
    ("rolling_ring", {}),
    ("funnel", {}),
    ("funnel", {"variant": "frictional"}),
    ("bar_impact", {}),
    ("bar_impact", {"enforcement": "lagrange"}),
    ("bar_impact", {"contact_integration": "energy_consistent"}),
    (DISC_WALL, {}),
]
TINY = 1e-5  # of the scene's own step: dt = 1e-6 on the paper's rings (their dt is 0.1)


def touching(rec):
    return any(np.any(np.asarray(st.t_N) != 0) for st in rec.contacts)


@pytest.mark.parametrize(
    "name,over", CASES, ids=[f"{Path(n).stem}{'-' + '-'.join(map(str, o.values())) if o else ''}" for n, o in CASES]
)
def test_a_tiny_step_goes_on_from_a_record_in_contact(name, over):
    """From the fifth record in contact (a displacement of the run's own size), 100 steps
    of 1e-5 of the scene's step: each converges without a halving, to the tolerance of its own forces.
    (Before the steps iterated on the increment, every case but the sloping impact stopped here: 'no
    convergence', the residual flat at c M eps |u|.)"""
    scene = get_scene(name)
    params = scene.resolve("fast", over)
    stage = scene.build(params).stage
    records = (r for r in march(stage.stepper, stage.schedule, stage.t0, stage.u0, stage.v0) if touching(r))
    start = next(r for k, r in enumerate(records) if k == 4)  # the fifth record in contact
    dt = TINY * start.dt
    records = list(resume(stage.stepper, Steps(dt, n_steps=100, t0=start.t), start))
    assert len(records) == 100 and sum(r.cuts for r in records) == 0
    assert max(r.result.residual_ratio for r in records) <= EQUILIBRIUM  # what the run's equilibrium indicator holds
    assert touching(records[0])  # (exact constraints may chatter off the wall: the trapezoidal rule's)


@pytest.mark.parametrize("over", [{}, {"contact_integration": "energy_consistent"}], ids=["newmark", "energy"])
def test_the_frictional_sloping_impact_touches_down_at_a_tiny_step(over):
    """dt = 1e-6 from the start (the ring 1e-4 above the plane: it touches at step 50): the run passes its
    first touch, where the step's contact force is far below the inertia's round-off in u."""
    from contactfem import run_scene

    r = run_scene("sloping_impact", "fast", dict(over, variant="frictional", dt=1e-6, n_steps=120, gap0=1e-4))
    assert r["t_first_contact"] == pytest.approx(5e-5, rel=0.05)
    assert r["accuracy"]["equilibrium"]["ok"]


@pytest.mark.slow
def test_sloping_impact_at_dt_1e_6_converges_through_its_first_impact(tmp_path):
    """The command line at the paper's start gap: 26,000 steps of 1e-6, first touch at t = 0.025 (step
    25,000), then 1,000 steps in contact."""
    out = tmp_path / "fine.json"
    cmd = [sys.executable, "-m", "contactfem", "run", "sloping_impact", "--set", "dt=1e-6", "--set", "n_steps=26000"]
    proc = subprocess.run([*cmd, "--json", str(out)], capture_output=True, text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr
    r = json.loads(out.read_text())
    assert r["t_first_contact"] == pytest.approx(0.025, rel=1e-3) and r["step_cuts_total"] == 0
    assert r["accuracy"]["equilibrium"]["ok"]


@pytest.mark.slow
def test_the_corks_pop_goes_on_at_a_tiny_step():
    """The cork's pop, in contact from its start (the press fit's state), at dt = 1e-6 s (a hundredth of the
    paper's) and at 1e-9 s: 100 steps each, without a halving, each within its force test."""
    from contactfem import run_scene

    for dt in (1e-6, 1e-9):
        r = run_scene("cork", "fast", dict(dt=dt, dt_fine=dt, t_end=100 * dt, n_press=2))
        assert r["n_steps"] == 100 and r["newton_failures"] == 0 and r["accuracy"]["equilibrium"]["ok"]
        assert min(r["contact_nodes"]) > 0
