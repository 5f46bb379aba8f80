"""A scene's parameter: its name, default, unit, allowed range or choices, what it means, and
when it applies; ``parse`` converts text and checks the range (one clear line naming the
parameter and its range).

One rule for a value, whichever way it comes (the command line's text, a sweep's grid, a scene
file, Python's run_scene): it is accepted when it denotes exactly one value of the parameter's
type, as a number or as the text of one. An integer parameter takes 12, 12.0, "12" and "1.2e1"
(the same integer) and refuses 12.5; a boolean is not a number (True is not 1).

A range that depends on other parameters (the block's free end nodes and its number of
elements, a cork's tip between the neck's radius and its own) is part of the parameter too
(``limit``): ``Scene.resolve`` checks it once every value is known. The Param is the one place
a scene's parameter is checked; the constructors the scene calls only assert what they need."""

import difflib
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..laws.validation import require


@dataclass(frozen=True)
class Limit:
    """A range from other parameters: ``bounds(values) -> (low, high)`` (None: no bound beyond
    the parameter's own), the parameters it reads (``of``) and how ``show`` states it (``text``,
    e.g. "[1, (nx - 1) // 2]")."""

    of: tuple
    bounds: Callable[[dict], tuple]
    text: str


@dataclass(frozen=True)
class Param:
    name: str
    default: Any
    unit: str = ""
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple | None = None
    doc: str = ""
    when: tuple = ()  # ((other_param, (values...)), ...): the parameter is used only then
    limit: Limit | None = None  # a range from other parameters (checked by Scene.resolve)

    def applies(self, values):
        """Whether the resolved `values` use this parameter (see `when`)."""
        return all(values.get(k) in vals for k, vals in self.when)

    def when_text(self):
        return " and ".join(f"{k}={'|'.join(map(str, vals))}" for k, vals in self.when)

    def range_text(self, values=None):
        """The allowed range, e.g. "(0, inf)"; with a ``limit``: its text, or, given the other
        parameters' ``values``, the range they leave, e.g. "[1, 12] for nx = 25"."""
        if self.choices is not None:
            return "one of " + "|".join(map(str, self.choices))
        if isinstance(self.default, bool):
            return "true|false"
        if self.limit is not None and values is None:
            return self.limit.text
        low, high = self.bounds(values)
        lo = "-inf" if low is None else f"{low:g}"
        hi = "inf" if high is None else f"{high:g}"
        text = (
            ("(" if self.low_open or low is None else "[")
            + f"{lo}, {hi}"
            + (")" if self.high_open or high is None else "]")
        )
        if self.limit is not None:
            text += " for " + ", ".join(f"{k} = {values[k]:g}" for k in self.limit.of)
        return text

    def bounds(self, values=None):
        """(low, high): the parameter's own, narrowed by its ``limit`` at the other ``values``."""
        low, high = self.low, self.high
        if self.limit is not None and values is not None:
            lo, hi = self.limit.bounds(values)
            low = lo if low is None else (low if lo is None else max(low, lo))
            high = hi if high is None else (high if hi is None else min(high, hi))
        return low, high

    def check_limit(self, values):
        """ValueError (one line, naming the parameter and the range the others leave) unless
        ``values[name]`` is within its limit; nothing without one."""
        if self.limit is None:
            return
        v = values[self.name]
        low, high = self.bounds(values)
        if (low is not None and (v <= low if self.low_open else v < low)) or (
            high is not None and (v >= high if self.high_open else v > high)
        ):
            raise ValueError(f"parameter {self.name} = {v:g} is out of range: allowed {self.range_text(values)}")

    def parse(self, value):
        """Convert (from text if need be) and validate; ValueError names the parameter and range."""
        if self.choices is not None:
            v = str(value)
            if v not in map(str, self.choices):
                raise ValueError(f"parameter {self.name} = {value!r} is not allowed: {self.range_text()}")
            return type(self.choices[0])(v) if not isinstance(self.choices[0], str) else v
        if isinstance(self.default, bool):
            if isinstance(value, bool):
                return value
            s = str(value).lower()
            if s in ("true", "1", "yes"):
                return True
            if s in ("false", "0", "no"):
                return False
            raise ValueError(f"parameter {self.name} = {value!r} is not allowed: true|false")
        if isinstance(value, (bool, np.bool_)):
            raise ValueError(f"parameter {self.name} must be a number in {self.range_text()}, got {value!r}")
        number = self._integer(value) if isinstance(self.default, int) else value
        try:
            v = require(self.name, number, self.low, self.high, self.low_open, self.high_open)
        except ValueError:
            if self.limit is None:
                raise
            raise ValueError(
                f"parameter {self.name} = {value!r} is out of range: allowed {self.range_text()}"
            ) from None
        return number if isinstance(self.default, int) else v

    def _integer(self, value):
        """The integer ``value`` denotes (an int, an integral float, or the text of either)."""
        bad = ValueError(f"parameter {self.name} must be an integer in {self.range_text()}, got {value!r}")
        if isinstance(value, numbers.Integral):
            return int(value)
        if isinstance(value, str):
            text = value.strip()
            try:
                return int(text)
            except ValueError:
                pass
        try:
            f = float(value)
        except (TypeError, ValueError):
            raise bad from None
        if not f.is_integer():
            raise bad
        return int(f)


def parse_all(params, values):
    """{name: value} with every value parsed by its Param, then checked against the range the
    other values leave it (its Limit, where it applies)."""
    known = {p.name: p for p in params}
    values = {k: known[k].parse(v) for k, v in values.items()}
    for p in params:
        if p.applies(values):
            p.check_limit(values)
    return values


def check_overrides(overrides):
    """``overrides`` as a dict (None: no overrides); TypeError naming it unless it is a mapping of
    parameter names to values (e.g. {"nx": 12})."""
    if overrides is None:
        return {}
    if not isinstance(overrides, Mapping):
        raise TypeError(
            f"parameter overrides must be a dict of parameter name -> value (e.g. {{'nx': 12}}), got "
            f"{type(overrides).__name__} {overrides!r}"[:200]
        )
    bad = [k for k in overrides if not isinstance(k, str)]
    if bad:
        raise TypeError(f"parameter overrides: the names must be strings, got {bad[0]!r}")
    return dict(overrides)


def did_you_mean(name, known):
    """' (did you mean NAME?)' for the known name closest to a mistyped one, case aside (difflib's ratio at
    least 0.6: c_n is c_N, not c_T), else ''."""
    by_lower = {}
    for k in known:
        by_lower.setdefault(str(k).lower(), str(k))
    close = difflib.get_close_matches(str(name).lower(), list(by_lower), n=1)
    return f" (did you mean {by_lower[close[0]]!r}?)" if close else ""
