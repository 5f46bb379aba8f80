"""Every indicator threshold is argued from numerics, physics or an outside source, never from the value a
preset happens to reach (a threshold set just above the defaults cannot tell whether the defaults are
accurate). The test reads the ``source`` of every indicator every scene's runs carry (error bands and
closed forms included) and fails on one that cites a preset or its measured value."""

import re
import warnings

import pytest

from contactfem import run_scene

# the phrases by which a source leans on a preset's own value
CITES_A_PRESET = re.compile(
    r"\bpresets?\b|\bthe defaults?\b|stays? below|measured: the|the paper's sloping impact loses|"
    r"at the fast|the extremes grid",
    re.IGNORECASE,
)

# cheap runs of every scene that between them carry every indicator (an impact for the time-resolution
# ones, a run at a tolerance for error_budget, closed forms, error bands)
RUNS = [
    ("block", {}),
    ("hertz", {"n_el": 8}),
    ("patch", {}),
    ("bar_impact", {"n_el": 10}),
    ("bar_impact", {"n_el": 10, "accuracy": 0.05}),
    ("sloping_impact", {"n_steps": 40}),
    ("rolling_ring", {"t_end": 0.3}),
    ("funnel", {"n_steps": 40}),
    ("cork", {"t_end": 2e-4, "n_press": 2}),
]


def _sources():
    found = {}
    for name, over in RUNS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = run_scene(name, "fast", over, error_bars=name in ("block", "hertz"))
        for key, ind in r["accuracy"].items():
            found.setdefault(key, set()).add(ind["source"])
    return found


SOURCES = {}


def sources():
    if not SOURCES:
        SOURCES.update(_sources())
    return SOURCES


EXPECTED = sorted(
    {
        "equilibrium",
        "penetration",
        "penetration_body",
        "facets",
        "energy_gain",
        "separated",
        "impact_steps",
        "penalty_steps",
        "error_budget",
        "duration",
        "rebound_velocity",
        "a",
        "p0",
        "pressure_deviation_max",
        "max_displacement_band",
        "a_band",
        "p0_band",
    }
)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_no_threshold_cites_a_presets_value(name):
    found = sources()
    assert name in found, f"no run carried the indicator {name} (the list of runs no longer reaches it)"
    for source in found[name]:
        assert source.strip(), f"{name}: no source"
        assert not CITES_A_PRESET.search(source), f"{name}: its threshold cites a preset: {source!r}"


def test_the_pattern_catches_the_sources_it_retired():
    for old in (
        "measured: the paper's sloping impact loses 22 % to Newmark's damping",
        "measured: the presets stay below 0.25",
        "the rigid hoop's; the elastic ring differs by 6 % at the fast preset",
        "5 %, the extremes grid's criterion; measured: 40 elements 3.8 %",
        "measured: node-to-segment stays below 0.052 on the presets",
    ):
        assert CITES_A_PRESET.search(old), old
    for argued in (
        "ANSYS's default penetration tolerance: 0.1 of the underlying element",
        "the run's tolerance (--tolerance TOL, tolerance= in Python; 5 % by default)",
    ):
        assert not CITES_A_PRESET.search(argued), argued
