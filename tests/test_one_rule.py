"""Each scene parameter is checked in one place, its Param (problem/params.py): every value out
of its range (its own, or the one the other parameters leave: a Limit) is refused once, in one
line naming the parameter and its range, before any work, from Python (run_scene) as from the
command line (exit 2); and every value inside it passes every later rule (the scene's build
and the constructors it calls only assert), so no second rule disagrees with the Param."""

import math
import warnings

import pytest

import contactfem.problem.scene as base
from contactfem.cli import main
from contactfem.scenes import all_scenes, run_scene

SCENES = all_scenes()


def activated(scene, p):
    """The overrides under which the parameter ``p`` applies (its ``when``)."""
    return {k: vals[0] for k, vals in p.when}


def out_of_range(scene, p):
    """(value, the range text the message must name) for every way out of p's range: below and
    above its own bounds, NaN, a non-integer for an integer, an unknown choice, and beyond the
    range its Limit leaves at the preset's other values."""
    if p.choices is not None:
        return [("no_such_choice", p.range_text())]
    if isinstance(p.default, bool):
        return [("maybe", p.range_text())]
    integer = isinstance(p.default, int)
    step = (lambda b: 1) if integer else (lambda b: max(abs(b), 1.0) * 1e-3)
    values = [math.nan] + ([p.default + 0.5] if integer else [])
    if p.low is not None:
        values.append(p.low if p.low_open else p.low - step(p.low))
    if p.high is not None:
        values.append(p.high if p.high_open else p.high + step(p.high))
    cases = [(v, p.range_text()) for v in values]
    if p.limit is not None:
        others = scene.resolve("fast", activated(scene, p))
        low, high = p.bounds(others)
        text = p.range_text(others)
        if low is not None and low != p.low:
            cases.append((low if p.low_open else low - step(low), text))
        if high is not None and high != p.high:
            cases.append((high if p.high_open else high + step(high), text))
    return cases


@pytest.fixture
def no_work(monkeypatch):
    """Any build, simulation or measurement is a failure of the test: refusals come first."""

    def work(*args, **kwargs):
        raise AssertionError("the run started: the value was not refused before any work")

    monkeypatch.setattr(base, "run", work)


def test_every_scene_has_parameters_with_limits_and_ranges():
    """The test below covers the cases it claims: ranges, choices, and Limits (the block's free
    end nodes, the cork's radii, the rings' wall thickness)."""
    limited = {(n, p.name) for n, s in SCENES.items() for p in s.params if p.limit is not None}
    assert {
        ("block", "free_end_nodes"),
        ("cork", "R_tip"),
        ("cork", "R_cork"),
        ("sloping_impact", "thickness"),
        ("rolling_ring", "thickness"),
        ("funnel", "thickness"),
    } <= limited
    assert sum(len(out_of_range(s, p)) for s in SCENES.values() for p in s.params) > 400


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_value_out_of_range_is_refused_once_from_python(name, no_work):
    scene, wrong = SCENES[name], []
    for p in scene.params:
        for value, rng in out_of_range(scene, p):
            overrides = dict(activated(scene, p), **{p.name: value})
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    run_scene(name, "fast", overrides)
                    wrong.append((p.name, value, "accepted"))
                    continue
                except ValueError as err:
                    message = str(err)
            if len(caught) or "\n" in message or f"parameter {p.name} " not in message or rng not in message:
                wrong.append((p.name, value, message, rng, [str(w.message) for w in caught]))
    assert not wrong, wrong


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_value_out_of_range_is_refused_once_on_the_command_line(name, no_work, capsys):
    scene, wrong = SCENES[name], []
    for p in scene.params:
        for value, rng in out_of_range(scene, p):
            sets = [f"{k}={v}" for k, v in dict(activated(scene, p), **{p.name: value}).items()]
            code = main(["run", name, *(a for s in sets for a in ("--set", s))])
            out, err = capsys.readouterr()
            lines = err.strip().splitlines()
            if code != 2 or out or len(lines) != 1 or f"parameter {p.name} " not in lines[0] or rng not in lines[0]:
                wrong.append((p.name, value, code, lines, rng))
    assert not wrong, wrong


def inside(p):
    """The values at the edges of p's own range, just inside, and every choice."""
    if p.choices is not None:
        return list(p.choices)
    if isinstance(p.default, bool):
        return [True, False]
    integer = isinstance(p.default, int)
    values = []
    if p.low is not None:
        values.append(p.low + (1 if integer else (p.default - p.low) * 1e-3) if p.low_open else p.low)
    if p.high is not None:
        values.append(p.high - (1 if integer else (p.high - p.default) * 1e-3) if p.high_open else p.high)
    return values


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SCENES))
def test_what_the_params_accept_the_build_accepts(name):
    """No later rule disagrees: every value its Params (and the scene's cross-parameter check)
    accept at the edges of the ranges builds the model (meshes of more than 30,000 unknowns are
    left out: their size is no rule)."""
    scene, wrong = SCENES[name], []
    for p in scene.params:
        for value in inside(p):
            try:
                params = scene.resolve("fast", dict(activated(scene, p), **{p.name: value}))
            except ValueError as err:  # a combination the scene refuses: in one line, naming a parameter
                if "\n" in str(err) or "parameter" not in str(err) and "no static equilibrium" not in str(err):
                    wrong.append((p.name, value, str(err)))
                continue
            size = scene.estimate(params) or {}
            if size.get("unknowns", 0) > 3e4:
                continue
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    scene.build(params, system_options={})
            except Exception as err:  # noqa: BLE001 (any refusal after the Params is the defect)
                wrong.append((p.name, value, type(err).__name__, str(err)))
    assert not wrong, wrong
