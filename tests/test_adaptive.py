"""A tolerance the user can ask for (a dynamic scene's ``accuracy``): the local error estimate
of a step (solver/estimate.py: local_error) against the exact motion of an oscillator, the rule
(solver/schedule.py: error_step, AtTolerance) and its fixed point, and the scenes' adaptive runs."""

import math
import warnings

import numpy as np
import pytest

from contactfem.scenes import get_scene, run_scene
from contactfem.solver.estimate import MIDPOINT, Slope, StepError, local_error, newmark_error_model
from contactfem.solver.schedule import AtTolerance, error_step


class _Oscillator:
    """Newmark (delta, beta) on m u'' + k u = 0 (m = 2, one dof), solved in closed form."""

    def __init__(self, delta, beta, k=3.0, m=2.0):
        self.delta, self.beta, self.k, self.m = delta, beta, k, m
        self.model, self.mass = newmark_error_model(delta, beta), np.array([m])

    def step(self, u, v, a, dt):
        u_pred = u + dt * v + dt**2 * (0.5 - self.beta) * a
        u1 = u_pred / (1.0 + self.beta * dt**2 * self.k / self.m)
        a1 = -self.k / self.m * u1
        v1 = v + dt * ((1.0 - self.delta) * a + self.delta * a1)
        return u1, v1, a1

    def estimate(self, a, a1, dt, before=None):
        return local_error(self.model, self.mass, a, a1, dt, before)


def _velocity_error(osc, dt, u=np.array([1.0]), v=np.array([0.5])):
    """The estimate of one step from (u, v) and the step's true velocity error."""
    w = math.sqrt(osc.k / osc.m)
    a = -osc.k / osc.m * u
    _, v1, a1 = osc.step(u, v, a, dt)
    exact = -u * w * math.sin(w * dt) + v * math.cos(w * dt)
    return osc.estimate(a, a1, dt)[0], float(abs(v1 - exact)[0])


@pytest.mark.parametrize("dt", [1e-2, 1e-3])
def test_estimate_is_the_first_order_error_of_newmark_delta_07(dt):
    est, err = _velocity_error(_Oscillator(0.7, 0.4), dt)
    assert est == pytest.approx(err, rel=20 * dt)  # the leading term, to O(dt)


@pytest.mark.parametrize("dt", [1e-1, 1e-2, 1e-3])
def test_estimate_bounds_the_trapezoidal_rule_error(dt):
    est, err = _velocity_error(_Oscillator(0.5, 0.25), dt)
    assert err <= est and est < 10 * err / dt  # a bound, one order of dt above the error


@pytest.mark.parametrize("dt", [1e-1, 1e-2, 1e-3])
@pytest.mark.parametrize("ratio", [1.0, 0.5, 2.0])
def test_second_difference_is_the_trapezoidal_rule_error(dt, ratio):
    """After a step of dt (its Slope handed on in the SystemState), the trapezoidal rule's estimate
    of a step of ratio dt is dt^3 |a''| / 12 from the second difference: the step's true velocity
    error, to O(dt), for equal and unequal steps."""
    osc = _Oscillator(0.5, 0.25)
    w = math.sqrt(osc.k / osc.m)
    exact = lambda t: (math.cos(w * t) + 0.5 / w * math.sin(w * t), -w * math.sin(w * t) + 0.5 * math.cos(w * t))
    u0, v0 = np.array([1.0]), np.array([0.5])
    a0 = -osc.k / osc.m * u0
    u1, v1, a1 = osc.step(u0, v0, a0, dt)
    before = Slope((a1 - a0) / dt, dt)
    u1, v1 = (np.array([x]) for x in exact(dt))  # the step from the exact state
    h = ratio * dt
    a1 = -osc.k / osc.m * u1
    _, v2, a2 = osc.step(u1, v1, a1, h)
    assert osc.estimate(a1, a2, h, before)[0] == pytest.approx(abs(v2[0] - exact(dt + h)[1]), rel=dt)


def test_the_first_step_hands_on_no_slope():
    """The first step starts from the initial acceleration, which a scene may set by hand: it hands
    on its size but no slope, and the step after it takes the first-difference bound as well."""
    osc = _Oscillator(0.5, 0.25)
    u0, v0 = np.array([1.0]), np.array([0.5])
    a0 = -osc.k / osc.m * u0
    u1, v1, a1 = osc.step(u0, v0, a0, 0.01)
    _, first = osc.estimate(a0, a1, 0.01)
    assert first.value is None and first.dt == 0.01
    u2, v2, a2 = osc.step(u1, v1, a1, 0.01)
    e, second = osc.estimate(a1, a2, 0.01, first)
    assert e == pytest.approx(0.01 / 12 * abs(a2 - a1)[0]) and second.value is not None


def test_the_midpoint_rule_errs_as_the_trapezoidal_rule():
    assert MIDPOINT == newmark_error_model(0.5, 0.25) and (MIDPOINT.order, MIDPOINT.c) == (2, pytest.approx(1 / 12))


def test_a_step_past_twice_its_share_is_rejected_down_to_the_floor():
    """AtTolerance's share of a step of dt is tol speed dt / duration; a step above the floor (dt_max
    tol) past twice it is retried halved, one at the floor is kept."""
    at = AtTolerance(1e-2, 2.0, 4.0, 0.1, 4.0, newmark_error_model(0.7, 0.4))
    share = at.share(0.05)
    assert share == pytest.approx(1e-2 * 2.0 * 0.05 / 4.0) and at.floor == pytest.approx(1e-3)
    assert at.rejects(StepError(2.01 * share, share), 0.05) and not at.rejects(StepError(1.99 * share, share), 0.05)
    assert not at.rejects(StepError(100 * share, share), at.floor)  # at the floor: kept


def test_error_step_fixed_point_first_step_and_cap():
    rec = type("R", (), {})()
    rec.k, rec.dt = 5, 0.01
    tol, speed, duration = 1e-3, 2.0, 4.0
    rec.error = StepError(tol * speed * rec.dt / duration)
    assert error_step(rec, tol, speed, duration, 1e-5, 1.0) == pytest.approx(rec.dt)  # on target: kept
    rec.error = StepError(4.0 * rec.error.local)
    assert error_step(rec, tol, speed, duration, 1e-5, 1.0) == pytest.approx(rec.dt / 4)
    assert error_step(rec, tol, speed, duration, 1e-5, 1.0, power=0.5) == pytest.approx(rec.dt / 2)
    rec.error = StepError(1e6 * rec.error.local)
    assert error_step(rec, tol, speed, duration, 1e-5, 1.0) == 1e-5  # never below the first step
    rec.error = StepError(0.0)
    assert error_step(rec, tol, speed, duration, 1e-5, 0.02) == 0.02  # nothing to resolve: dt_max
    rec.k = 0
    assert error_step(rec, tol, speed, duration, 1e-5, 0.02) == 1e-5  # no estimate yet


@pytest.mark.parametrize("scene", ["sloping_impact", "rolling_ring", "bar_impact", "cork"])
def test_accuracy_is_a_parameter_off_by_default(scene):
    s = get_scene(scene)
    assert s.resolve("fast")["accuracy"] == 0.0
    assert s.resolve("fast", {"accuracy": "1e-3"})["accuracy"] == 1e-3
    for bad in (-1e-3, 0.5, 1e-4, 1e-300, float("nan")):  # below 1e-3: steps below round-off
        with pytest.raises(ValueError, match=r"parameter accuracy = .* allowed 0 \(fixed steps\) or \[0.001, 0.1\]"):
            s.resolve("fast", {"accuracy": bad})
    with pytest.raises(ValueError, match=r"parameter accuracy must be a number: 0 \(fixed steps\) or \[0.001, 0.1\]"):
        s.resolve("fast", {"accuracy": "tight"})


def test_accuracy_refused_with_the_explicit_stepper_and_multipliers():
    with pytest.raises(ValueError, match="parameter accuracy .* integrator = newmark"):
        get_scene("bar_impact").resolve("fast", {"accuracy": 1e-2, "integrator": "central_difference"})
    with pytest.raises(ValueError, match="parameter accuracy .* enforcement = penalty only"):
        get_scene("bar_impact").resolve("fast", {"accuracy": 1e-2, "enforcement": "augmented"})


def _bar(over):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_scene("bar_impact", "fast", over)


def test_adaptive_run_reports_its_steps_and_repeats_bit_for_bit():
    a, b = _bar({"accuracy": 1e-2}), _bar({"accuracy": 1e-2})
    assert a["stepping"]["mode"] == "adaptive" and a["stepping"]["accuracy"] == 1e-2
    assert a["stepping"]["steps"] == a["n_steps"] and a["stepping"]["dt_max"] <= a["dt"] * (1 + 1e-12)
    assert a["stepping"]["dt_min"] < a["stepping"]["dt_max"]
    assert np.array_equal(a["time"], b["time"]) and np.array_equal(a["contact_stress"], b["contact_stress"])
    fixed = _bar({})
    assert fixed["stepping"] == dict(
        mode="fixed",
        accuracy=None,
        integrator="newmark delta = 0.5, beta = 0.25 (trapezoidal rule)",
        steps=fixed["n_steps"],
        dt_min=pytest.approx(fixed["dt"]),
        dt_max=pytest.approx(fixed["dt"]),
        at_floor=None,
    )


def test_steps_kept_past_twice_their_share_are_at_the_floor_and_their_time_is_reported():
    """at_floor: the time of the steps the rule kept only because they are at the floor dt TOL. A
    step past twice its share is rejected above the floor, so every such step is at the floor (or
    cut below it by Newton, or the run's shortened last step); and a budget past 2 needs such steps
    (a run whose every step is within twice its share sums to at most twice the allowed error)."""
    from contactfem.scenes import simulate
    from contactfem.problem.accuracy import at_floor

    scene = get_scene("rolling_ring")
    params = scene.resolve("fast", {"accuracy": 1e-2, "t_end": 0.5})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = run_scene("rolling_ring", "fast", {"accuracy": 1e-2, "t_end": 0.5})
    records = simulate(scene.build(params), params)
    steps = records[1:]
    floor = params["dt"] * params["accuracy"]
    over = [s for s in steps if s.error.local > 2.0 * s.error.share]
    assert over and all(s.dt <= floor * (1 + 1e-9) or s is steps[-1] for s in over)
    assert at_floor(steps) == pytest.approx(sum(s.dt for s in over) / sum(s.dt for s in steps), rel=1e-12)
    assert r["stepping"]["at_floor"] == pytest.approx(at_floor(steps), rel=1e-12) and r["stepping"]["at_floor"] > 0.1
    budget = r["accuracy"]["error_budget"]
    assert budget["value"] > 2 and f"{100 * r['stepping']['at_floor']:.0f} % of the run's time" in budget["what"]
    assert any("error_budget" in str(w.message) for w in caught)
    bar = _bar({"accuracy": 1e-3})  # within its budget: no step past twice its share
    assert bar["stepping"]["at_floor"] == 0.0 and bar["accuracy"]["error_budget"]["value"] <= 2


def test_a_run_at_a_tolerance_is_trapezoidal_and_carries_its_slope_as_a_value():
    """At a tolerance the scene integrates with the trapezoidal rule; each record's SystemState
    holds the Slope the next step's estimate needs, so the run resumed from any record goes on
    exactly as it went."""
    from contactfem.scenes import simulate
    from contactfem.solver.march import resume

    scene = get_scene("sloping_impact")
    params = scene.resolve("fast", {"accuracy": 1e-2, "n_steps": 5})
    model = scene.build(params)
    stepper = model.stage.stepper
    assert (stepper.delta, stepper.beta) == (0.5, 0.25) == (params["delta"], params["beta_newmark"])  # as recorded
    records = simulate(model, params)
    k = len(records) // 2
    slope = records[k].state.slope
    assert slope.dt == records[k].dt and np.array_equal(slope.value, (records[k].a - records[k - 1].a) / slope.dt)
    again = list(resume(model.stage.stepper, model.stage.schedule, records[k]))
    assert len(again) == len(records) - k - 1
    for a, b in zip(again, records[k + 1 :]):
        assert a.t == b.t and np.array_equal(a.u, b.u) and a.error == b.error


def test_a_tolerance_the_run_cannot_vouch_for_warns():
    """A run warns exactly when its own error estimate passes twice what its tolerance allows: the
    rolling ring's polygon touches down node after node and the trapezoidal rule keeps the
    vibrations each touch-down excites, so the estimate asks for steps below the floor dt TOL (it
    warns today); the bar, whose one impact the estimate resolves, stays within its budget."""
    from contactfem.problem.accuracy import AccuracyWarning

    for scene, over in (("rolling_ring", {"accuracy": 1e-2, "t_end": 0.6}), ("bar_impact", {"accuracy": 1e-2})):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            budget = run_scene(scene, "fast", over)["accuracy"]["error_budget"]
        warned = any(issubclass(w.category, AccuracyWarning) and "error_budget" in str(w.message) for w in caught)
        assert warned == (budget["value"] > 2.0) == (not budget["ok"]), scene
        assert budget["ok"] or scene == "rolling_ring", (scene, budget["value"])  # the bar's impact: resolved
    assert "error_budget" not in _bar({})["accuracy"]  # fixed steps: no tolerance to keep


# -- the adaptive mode against a reference refined in time (the bench's study 10, in small) ---------


def _largest_fixed_reaching(scene, ladder, error, ref, trapezoidal=False):
    """The first step of the ladder (coarse to fine) whose run is within ``error`` of ``ref``, with its cost
    (a step that may merely dip below: a coarser, cheaper match than the study's matching_fixed, so a
    stricter test of the run's cost)."""
    for h in ladder:
        r = study.scene_run(scene, h, trapezoidal)
        if r["ok"] and study.max_error(r, ref) <= error:
            return h, r
    return None, None


from contactfem.lab.bench import adaptive as study  # noqa: E402


@pytest.fixture(scope="module")
def bar_reference():
    return study.reference("bar_impact")


@pytest.mark.slow
@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_bar_impact_at_a_tolerance(tol, bar_reference):
    """Duration and rebound velocity within tol of the run refined in time (its change from a
    step twice as long is below tol / 10), at no more residual evaluations than the largest fixed
    step that reaches the same error, and within the run's own error budget."""
    assert bar_reference["change"] < 0.1 * tol
    ref = bar_reference["values"]
    run = study.adaptive_run("bar_impact", tol)
    error = study.max_error(run, ref)
    assert error <= tol and run["error_budget"] <= 2.0
    ladder = study.STUDY["bar_impact"]["ladder"] + (2 * bar_reference["h_ref"],)  # (not the reference's run itself)
    h, fixed = _largest_fixed_reaching("bar_impact", ladder, error, ref)
    assert h is not None, f"no fixed step of the ladder reaches {error:.2e}"
    assert run["residual_evaluations"] <= fixed["residual_evaluations"]


def test_the_committed_study_covers_its_scenes():
    """The committed bench.json's adaptive study (the front page's block of it: tests/test_readme.py) ran every
    scene the study names, and each has its line."""
    import json
    from pathlib import Path

    from contactfem.lab.bench.report import adaptive_sentences

    root = Path(__file__).resolve().parents[1]
    ad = json.loads((root / "bench.json").read_text())["adaptive"]
    assert set(ad["scenes"]) == set(study.STUDY) == {"sloping_impact", "rolling_ring", "bar_impact", "cork"}
    assert len(adaptive_sentences(ad)) == len(ad["scenes"])


@pytest.fixture(scope="module")
def sloping_reference():
    return study.reference("sloping_impact")


@pytest.mark.slow
@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_sloping_impact_at_a_tolerance(tol, sloping_reference):
    """The rebound velocities within tol of the run refined in time (the trapezoidal rule, its
    change from a step twice as long below tol / 10), at no more residual evaluations than the
    largest fixed step of the trapezoidal rule that reaches the same error (the cheaper of the two
    ladders, BENCHMARKS.md), and within the run's own error budget."""
    assert sloping_reference["change"] < 0.1 * tol
    ref = sloping_reference["values"]
    run = study.adaptive_run("sloping_impact", tol)
    error = study.max_error(run, ref)
    assert error <= tol and run["error_budget"] <= 2.0
    ladder = study.STUDY["sloping_impact"]["trapezoidal"]
    h, fixed = _largest_fixed_reaching("sloping_impact", ladder, error, ref, trapezoidal=True)
    assert h is not None, f"no fixed step of the ladder reaches {error:.2e}"
    assert run["residual_evaluations"] <= fixed["residual_evaluations"]


@pytest.mark.slow
def test_the_papers_frictional_impact_at_1e_2_costs_no_more_than_the_fixed_step_within_it():
    """The paper's frictional sloping impact (to t = 20) at accuracy = 1e-2: its rebound within 1e-2 of the
    trapezoidal rule refined (dt / 128; the ring has left by t = 3, and its velocity is constant from there:
    the reference stops there), at no more residual evaluations than the first trapezoidal step of the ladder
    dt / 2^k whose run is within 1e-2 and stays there at the next finer step."""

    def run(over):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return run_scene("sloping_impact", "paper", dict(over, variant="frictional"))

    trap = dict(delta=0.5, beta_newmark=0.25)
    ref = run(dict(trap, dt=0.1 / 128, n_steps=3 * 1280))
    err = lambda r: max(abs(r[k] / ref[k] - 1.0) for k in ("rebound_vx", "rebound_vy"))  # noqa: E731
    adaptive = run({"accuracy": 1e-2})
    assert err(adaptive) <= 1e-2
    ladder = [run(dict(trap, dt=0.1 / 2**k, n_steps=200 * 2**k)) for k in (2, 3, 4, 5)]
    first = next(i for i, r in enumerate(ladder) if err(r) <= 1e-2 and all(err(f) <= 1e-2 for f in ladder[i:]))
    assert adaptive["residual_evaluations"] <= ladder[first]["residual_evaluations"], (first, err(ladder[first]))


def test_command_line_equals_python(tmp_path):
    """`--set accuracy=TOL` on the command line is run_scene(..., {"accuracy": TOL}): the same steps."""
    import json

    from contactfem.cli import main

    out = tmp_path / "run.json"
    assert main(["run", "sloping_impact", "--set", "accuracy=0.01", "--set", "n_steps=10", "--json", str(out)]) == 0
    cli = json.loads(out.read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        py = run_scene("sloping_impact", "fast", {"accuracy": 0.01, "n_steps": 10})
    assert cli["stepping"] == py["stepping"] and cli["stepping"]["mode"] == "adaptive"
    assert cli["t"] == list(py["t"]) and cli["rebound_vy"] == py["rebound_vy"]


def test_matching_fixed_is_the_largest_step_that_stays_within_the_error():
    """A coarse step whose error dips below, with a finer step above it, is not a match."""
    fixed = [
        dict(h=1.0, error=0.02, residual_evaluations=10, newton_iterations=5, wall_time_s=0.1),
        dict(h=0.5, error=0.004, residual_evaluations=20, newton_iterations=10, wall_time_s=0.2),
        dict(h=0.25, error=0.006, residual_evaluations=40, newton_iterations=20, wall_time_s=0.4),
        dict(h=0.125, error=0.001, residual_evaluations=80, newton_iterations=40, wall_time_s=0.8),
    ]
    assert study.matching_fixed(fixed, 0.005)["h"] == 0.125  # 0.5 dips below, 0.25 does not
    assert study.matching_fixed(fixed, 0.007)["h"] == 0.5  # 0.5, 0.25 and 0.125 all within
    assert study.matching_fixed(fixed, 0.002)["residual_evaluations"] == 80
    assert study.matching_fixed(fixed, 1e-4) is None
    assert study.matching_fixed(fixed, float("nan")) is None and study.matching_fixed(fixed, None) is None
    assert study.matching_fixed([], 0.1) is None
    failed = [dict(fixed[0]), dict(fixed[1]), dict(fixed[2], error=None), dict(fixed[3])]
    assert study.matching_fixed(failed, 0.05)["h"] == 0.125  # a failed point ends the search
    nan = [dict(f) for f in fixed[:3]] + [dict(fixed[3], error=float("nan"))]
    assert study.matching_fixed(nan, 0.05) is None  # NaN is not within


def test_matches_below_the_reference_change_and_at_the_tolerance():
    """A run's error below the reference's own change is matched at that change (the finest step of
    a ladder is the reference's neighbour, its error that change); the tolerance's own match is the
    cheaper ladder's, and none where the reference moves by more than half the tolerance."""
    ladder = [
        dict(h=h, error=e, residual_evaluations=n, newton_iterations=n, wall_time_s=0.0)
        for h, e, n in ((0.4, 2e-2, 10), (0.2, 4e-3, 20), (0.1, 1e-3, 40), (0.05, 2e-4, 80))
    ]
    trap = [dict(f, residual_evaluations=f["residual_evaluations"] // 2) for f in ladder[1:]]
    a = dict(accuracy=1e-2, error=1e-5)
    m = study.matches(a, ladder, trap, reference_change=2e-4)
    assert m["fixed_match"]["h"] == 0.05 and m["trapezoidal_match"]["h"] == 0.05
    assert m["tolerance_match"]["integrator"] == "trapezoidal" and m["tolerance_match"]["h"] == 0.2
    assert study.matches(a, ladder, trap, reference_change=1e-5)["fixed_match"] is None
    assert study.matches(a, ladder, trap, reference_change=6e-3)["tolerance_match"] is None
    assert study.matches(dict(a, error=None), ladder, trap, 2e-4)["fixed_match"] is None


def test_a_flight_holds_its_momentum_and_one_that_ends_in_a_contact_is_stepped_again():
    """At a tolerance the sloping ring's approach flight, which ends on the plane, is stepped again from its
    start in the kinetic energy's norm (its Slope careful until the touch); its flight after the rebound ends
    the run and holds only its momentum's error, nil while no force acts (steps up to dt); a run resumed from a
    record of the flight stepped again goes on as it went."""
    from contactfem.scenes import simulate
    from contactfem.solver.march import resume

    scene = get_scene("sloping_impact")
    params = scene.resolve("fast", {"variant": "frictional", "accuracy": 1e-2, "n_steps": 30})
    model = scene.build(params)
    records = simulate(model, params)
    touching = [any(st.n_active for st in r.contacts) for r in records]
    first, last = touching.index(True), len(touching) - 1 - touching[::-1].index(True)
    assert all(r.state.slope.careful for r in records[1:first]) and not records[first].state.slope.careful
    # (the step that lifts off starts in contact: the state's error; the next one's second difference spans
    # the lift-off)
    flight = records[last + 3 :]
    speed = float(np.hypot(params["vx0"], params["vy0"]))
    assert flight and max(r.error.local for r in flight) <= 1e-12 * speed
    assert max(r.dt for r in flight) == pytest.approx(params["dt"])
    assert max(r.error.local for r in records[first:last]) > 1e-6 * speed  # in contact: the state's error
    st = model.stage
    again = list(resume(st.stepper, st.schedule, records[1]))
    assert len(again) == len(records) - 2
    for a, b in zip(again, records[2:]):
        assert a.t == b.t and np.array_equal(a.u, b.u) and a.error == b.error
