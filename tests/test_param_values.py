"""One rule for a parameter's value, whichever way it comes (command line text, a sweep's grid,
Python's run_scene): accepted when it denotes exactly one value of the parameter's type; the
arguments of run_scene itself checked with a TypeError naming them."""

import numpy as np
import pytest

from contactfem.scenes import get_scene, run_scene

BLOCK = get_scene("block")


@pytest.mark.parametrize("value", [12, 12.0, "12", " 12 ", "12.0", "1.2e1", np.int64(12), np.float64(12.0)])
def test_an_integer_parameter_takes_every_spelling_of_an_integer(value):
    assert BLOCK.resolve("fast", {"nx": value, "ny": 8})["nx"] == 12


@pytest.mark.parametrize("value", [12.5, "12.5", "twelve", True, np.True_, float("nan"), float("inf"), None, [12]])
def test_an_integer_parameter_refuses_anything_else_naming_it(value):
    with pytest.raises(ValueError, match=r"parameter nx must be an? (integer|number) in \[3, 400\]"):
        BLOCK.resolve("fast", {"nx": value})


@pytest.mark.parametrize("value", [True, "abc"])
def test_a_float_parameter_refuses_booleans_and_words(value):
    with pytest.raises(ValueError, match="parameter width must be a number"):
        BLOCK.resolve("fast", {"width": value})


@pytest.mark.parametrize("overrides", [["nx", 5], ("nx", 5), "nx=5", 5])
def test_overrides_must_be_a_mapping(overrides):
    with pytest.raises(TypeError, match="parameter overrides must be a dict of parameter name -> value"):
        run_scene("block", "fast", overrides)


def test_override_names_must_be_text():
    with pytest.raises(TypeError, match="parameter overrides: the names must be strings"):
        run_scene("block", "fast", {5: 12})


@pytest.mark.parametrize("progress", [5, "bar", True])
def test_progress_must_be_callable(progress):
    with pytest.raises(TypeError, match="parameter progress must be None or a callable"):
        run_scene("block", "fast", progress=progress)


def test_the_same_value_gives_the_same_run():
    a, b = (run_scene("block", "canonical", {"nx": v, "ny": 10}) for v in (20, "20.0"))
    assert a["newton_residuals"] == b["newton_residuals"] and a["parameters"]["nx"] == b["parameters"]["nx"] == 20


@pytest.mark.parametrize("value", ["abc", True])
def test_a_tolerance_that_is_no_number_is_called_so(value):
    """Text or a boolean for accuracy is not a number (not a number out of range)."""
    pattern = r"^parameter accuracy must be a number: 0 \(fixed steps\) or \[0.001, 0.1\], got "
    with pytest.raises(ValueError, match=pattern):
        get_scene("rolling_ring").resolve("fast", {"accuracy": value})
    with pytest.raises(ValueError, match=r"^parameter accuracy = 0.5 is out of range: allowed 0 \(fixed steps\)"):
        get_scene("rolling_ring").resolve("fast", {"accuracy": 0.5})
