"""What a scene is: named parameters with units and ranges, presets, and a run
function returning a JSON-able dict of results.

A scene module defines ``SCENE = Scene(...)``; the registry in
``contactfem.scenes`` finds it. Parameter names follow the paper's symbols
(c_N, c_T, m, n, alpha, beta, mu, E, nu, dt, delta, beta_newmark, ...)."""

from dataclasses import dataclass, field
from typing import Any, Callable

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
        if isinstance(self.default, int):
            try:
                iv = int(str(value))
            except ValueError:
                raise ValueError(f"parameter {self.name} must be an integer in {self.range_text()}, got {value!r}") from None
            require(self.name, iv, self.low, self.high, self.low_open, self.high_open)
            return iv
        return require(self.name, value, self.low, self.high, self.low_open, self.high_open)


@dataclass(frozen=True)
class Scene:
    name: str
    title: str
    params: tuple
    run: Callable[[dict], dict]
    presets: dict = field(default_factory=dict)   # preset name -> {param: value}
    reports: tuple = ()                           # names of the main results, for `show`
    notes: str = ""                               # what `show` says after the parameters (data read/fitted)

    def param(self, name):
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def resolve(self, preset="fast", overrides=None):
        """Defaults, then the preset, then the user's overrides; every value validated."""
        if preset not in ("fast", "paper") and preset not in self.presets:
            names = ["fast", "paper", *(k for k in self.presets if k not in ("fast", "paper"))]
            raise ValueError(f"parameter preset = {preset!r} is not allowed: one of {'|'.join(names)}")
        known = {p.name: p for p in self.params}
        values = {p.name: p.default for p in self.params}
        values.update(self.presets.get(preset, {}))
        for k, v in (overrides or {}).items():
            if k not in known:
                raise ValueError(f"unknown parameter {k!r} for scene {self.name}: known are {', '.join(known)}")
            values[k] = v
        return {k: known[k].parse(v) for k, v in values.items()}


def jsonable(obj):
    """numpy arrays and scalars to lists and floats, recursively; NaN is refused."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        if not np.isfinite(f):
            raise FloatingPointError("a result is NaN or infinite; refusing to report it")
        return f
    return obj
