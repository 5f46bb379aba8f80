"""Parameter checks shared by the laws: one clear line naming the parameter and its range."""

import math


def require(name, value, low=None, high=None, low_open=False, high_open=False):
    """Raise ValueError unless ``low <(=) value <(=) high``; return the value as float."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"parameter {name} must be a number, got {value!r}") from None
    lo_ok = low is None or (v > low if low_open else v >= low)
    hi_ok = high is None or (v < high if high_open else v <= high)
    if not (math.isfinite(v) and lo_ok and hi_ok):
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        rng = ("(" if low_open or low is None else "[") + f"{lo}, {hi}" + (")" if high_open or high is None else "]")
        raise ValueError(f"parameter {name} = {value} is out of range: allowed {rng}")
    return v
