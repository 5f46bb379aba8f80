"""A scene's parameter: its name, default, unit, allowed range or choices, what it means, and
when it applies; ``parse`` converts text and checks the range (one clear line naming the
parameter and its range).

One rule for a value, whichever way it comes (the command line's text, a sweep's grid, a scene
file, Python's run_scene): it is accepted when it denotes exactly one value of the parameter's
type, as a number or as the text of one. An integer parameter takes 12, 12.0, "12" and "1.2e1"
(the same integer) and refuses 12.5; a boolean is not a number (True is not 1)."""

import numbers

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..laws.validation import require


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
    when: tuple = ()      # ((other_param, (values...)), ...): the parameter is used only then

    def applies(self, values):
        """Whether the resolved `values` use this parameter (see `when`)."""
        return all(values.get(k) in vals for k, vals in self.when)

    def when_text(self):
        return " and ".join(f"{k}={'|'.join(map(str, vals))}" for k, vals in self.when)

    def range_text(self):
        if self.choices is not None:
            return "one of " + "|".join(map(str, self.choices))
        if isinstance(self.default, bool):
            return "true|false"
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return ("(" if self.low_open or self.low is None else "[") + f"{lo}, {hi}" + (")" if self.high_open or self.high is None else "]")

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
        if isinstance(self.default, int):
            iv = self._integer(value)
            require(self.name, iv, self.low, self.high, self.low_open, self.high_open)
            return iv
        return require(self.name, value, self.low, self.high, self.low_open, self.high_open)

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


def check_overrides(overrides):
    """``overrides`` as a dict (None: no overrides); TypeError naming it unless it is a mapping of
    parameter names to values (e.g. {"nx": 12})."""
    from collections.abc import Mapping

    if overrides is None:
        return {}
    if not isinstance(overrides, Mapping):
        raise TypeError(f"parameter overrides must be a dict of parameter name -> value (e.g. {{'nx': 12}}), got "
                        f"{type(overrides).__name__} {overrides!r}"[:200])
    bad = [k for k in overrides if not isinstance(k, str)]
    if bad:
        raise TypeError(f"parameter overrides: the names must be strings, got {bad[0]!r}")
    return dict(overrides)
