"""What a scene is: named parameters with units and ranges, presets, and three steps,

    model = scene.build(params, normal=..., friction=..., system_options=...)   # bodies, contacts, System
    records = simulate(model, params, progress)   # the time loop (solver.march) over the model's Stage
    results = scene.measure(model, params, records)   # a JSON-able dict from the records

that ``run`` puts together (one function for every scene: it also reports the size of the
system, how it was solved and how often it was evaluated). A scene with more than one stage
(the cork: press fit, then pop) gives its own ``simulate``.

A scene module defines ``SCENE = Scene(...)``; the registry in ``contactfem.scenes`` finds
it. Parameter names follow the paper's symbols (c_N, c_T, m, n, alpha, beta, mu, E, nu, dt,
delta, beta_newmark, ...)."""

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..laws.validation import require

PENALTIES = ("per_length", "per_node")
PENALTY_DOC = ("unit of c_N and c_T: per_length = tractions per unit gap and per unit length of the contact "
               "boundary (nodal weights = tributary lengths; per unit area of an axisymmetric surface), "
               "per_node = nodal stiffnesses (weights 1)")


@dataclass
class Stage:
    """One march of a scene (solver.march): the stepper, the schedule, the initial state,
    and how the progress bar and error messages name it."""
    stepper: object
    schedule: object
    u0: np.ndarray
    v0: np.ndarray = None
    t0: float = 0.0
    a0: np.ndarray = None
    name: str = ""
    label: Callable | None = None


def simulate(model, params=None, progress=None):
    """The records of the model's stage (``model["stage"]``): the initial state and every step."""
    from ..solver.march import march, watch

    st = model["stage"]
    records = march(st.stepper, st.schedule, st.t0, st.u0, st.v0, a0=st.a0, label=st.label)
    return list(watch(records, progress, st.t0, st.schedule.t_end, st.name or model.get("name", "")))


def run(scene, params, normal=None, friction=None, progress=None, linear_algebra="auto", instrument=None):
    """Build, simulate and measure a scene with resolved parameters; ``linear_algebra`` and
    ``instrument`` (solver.instrument.Timings) go to every System the scene builds (its
    ``system_options``). The results come with the
    run's own wall time (``wall_time_s``: building, solving and measuring, no imports before
    it), the linear algebra of the Systems it built (``linear_algebra``, ``ordering``,
    ``unknowns``, ``band_kl``, ``band_ku``) and how often they were evaluated
    (``residual_evaluations``: System evaluations, one per residual Newton needs;
    ``contact_evaluations``: contact evaluations, one per contact in each)."""
    t0 = time.perf_counter()
    options = dict(linear_algebra=linear_algebra, instrument=instrument)
    model = scene.build(params, normal=normal, friction=friction, system_options=options)
    records = (scene.simulate or simulate)(model, params, progress)
    results = dict(scene.measure(model, params, records))
    systems = model["systems"]
    results["wall_time_s"] = time.perf_counter() - t0
    results["linear_algebra"] = "+".join(dict.fromkeys(s.linear_algebra for s in systems)) or None
    results["ordering"] = "+".join(dict.fromkeys(s.ordering for s in systems)) or None
    results["unknowns"] = max((s.ndof for s in systems), default=None)
    bands = [s.band for s in systems if s.band is not None]
    results["band_kl"] = max((kl for kl, _ in bands), default=None)     # banded: the widest band
    results["band_ku"] = max((ku for _, ku in bands), default=None)
    results["residual_evaluations"] = int(sum(s.evaluations for s in systems))
    contacts = {id(c): c for s in systems for c in s.contacts}
    results["contact_evaluations"] = int(sum(c.evaluations for c in contacts.values()))
    results.setdefault("newton_iterations_total", 0)
    return results


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
    build: Callable                               # (params, *, normal, friction, system_options) -> model dict
    measure: Callable                             # (model, params, records) -> results dict
    simulate: Callable | None = None              # (model, params, progress) -> records; default: the model's stage
    presets: dict = field(default_factory=dict)   # preset name -> {param: value}
    reports: tuple = ()                           # names of the main results, for `show`
    check: Callable[[dict], None] | None = None   # cross-parameter checks (ValueError), before any run
    size: Callable[[dict], dict] | None = None    # {"elements", "unknowns", "steps"} from the parameters
    outlines: bool = False                        # records body outlines (run --gif can animate them)
    notes: str = ""                               # what `show` says after the parameters (data read/fitted)
    # The interface laws (a law object given to run_scene, or --friction / --normal, replaces the scene's own):
    laws: tuple = ()                              # the kinds of law the scene's contact has: "normal", "friction"
    law_params: dict = field(default_factory=dict)   # kind -> the parameters that build the scene's law of that kind
    law_choice: tuple | None = None               # (parameter, values): those values of it choose the friction law
    law_range: Callable[[dict], dict] | None = None  # the range a law meets (LAW_RANGE_KEYS), for the pre-flight

    def run(self, params, normal=None, friction=None, progress=None, linear_algebra="auto", instrument=None):
        """Build, simulate and measure (module function ``run``)."""
        return run(self, params, normal=normal, friction=friction, progress=progress, linear_algebra=linear_algebra,
                   instrument=instrument)

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
        overrides = dict(overrides or {})
        for k, v in overrides.items():
            if k not in known:
                raise ValueError(f"unknown parameter {k!r} for scene {self.name}: known are {', '.join(known)}")
            values[k] = v
        values = {k: known[k].parse(v) for k, v in values.items()}
        for k in overrides:                       # a value the resolved variant would silently ignore
            if not known[k].applies(values):
                now = ", ".join(f"{o}={values[o]}" for o, _ in known[k].when)
                raise ValueError(f"parameter {k} does not apply to {self.name} with {now}: "
                                 f"it is used only with {known[k].when_text()}")
        if self.check is not None:
            self.check(values)
        return values

    def law_param_kind(self, name, value=None):
        """The kind of law ("friction", "normal") the parameter `name` (= value) builds, or None."""
        for kind, names in self.law_params.items():
            if name in names:
                return kind
        if self.law_choice is not None and name == self.law_choice[0] and \
                (value is None or str(value) in map(str, self.law_choice[1])):
            return "friction"
        return None

    def check_laws(self, laws, overrides=None):
        """Before anything runs: ValueError (one line) if a law object (or class) is given for a
        kind the scene's contact does not have, or a parameter is set that builds a law it
        replaces (the hint names the law's own field)."""
        import dataclasses

        for kind, law in laws.items():
            if kind not in self.laws:
                what = "is frictionless" if kind == "friction" else "has no normal law"
                raise ValueError(f"scene {self.name} has no {kind} law (its contact {what}): a {kind} law does "
                                 "not apply to it")
        for k, v in (overrides or {}).items():
            kind = self.law_param_kind(k, v)
            if kind is None or kind not in laws:
                continue
            law = laws[kind]
            cls = law if isinstance(law, type) else type(law)
            name = cls.__name__
            if self.law_choice is not None and k == self.law_choice[0]:
                raise ValueError(f"parameter {k} = {v} chooses the scene's {kind} law, which the {kind} law {name} "
                                 f"replaces: leave {k} out")
            fields = [f.name for f in dataclasses.fields(cls)] if dataclasses.is_dataclass(cls) else []
            fix = (f"set {name}'s own field instead: --set law.{k}={v} (or {name}({k}={v}))" if k in fields else
                   f"{name} has no field {k} (its fields: {', '.join(fields) or 'none'})")
            raise ValueError(f"parameter {k} builds the scene's {kind} law, which the {kind} law {name} replaces: "
                             + fix)

    def variant_of(self, params, friction=None):
        """The variant a run reports: the law_choice parameter's value; with a friction law
        object, that law's class name (after the parameter's value where that value also
        changes something else, such as the ring's material)."""
        if self.law_choice is None:
            return None
        value = params[self.law_choice[0]]
        if friction is None:
            return value
        name = type(friction).__name__
        return name if str(value) in map(str, self.law_choice[1]) else f"{value} with {name}"

    def preflight(self, params, laws):
        """Check law objects over the range the scene meets (``law_range``) before solving:
        returns warning sentences (a derivative that disagrees with finite differences);
        raises LawError (one line) for a value no law may return (NaN, Y < 0, t_N > 0), a
        law that breaks the protocol, or a block its friction cannot hold."""
        from ..laws.check import preflight

        if not laws or self.law_range is None:
            return []
        return preflight(laws.get("friction"), laws.get("normal"), **self.law_range(params))

    def estimate(self, params):
        """Size of the run from the resolved parameters: elements, unknowns, time (or load)
        steps, and the memory it needs in bytes (a model calibrated on the continuum scenes:
        the sparse LU factors and the assembled tangents dominate)."""
        if self.size is None:
            return None
        est = {k: _count(v) for k, v in self.size(params).items()}
        n = max(est.get("unknowns", 0), 1)
        est["memory_bytes"] = int(MEMORY_BASE + MEMORY_PER_UNKNOWN * n * math.log2(max(n, 2))
                                  + MEMORY_PER_STEP * est.get("steps", 0))
        return est


# What a scene's law_range(params) returns, all maxima of the run (generous bounds from the
# loads and penalties, not the values of one run): p the pressure |t_N| (in the law's unit:
# per length, per area or per node, as the scene's weights), q the accumulated slip, v the slip
# rate, dt the smallest planned time step, g the deepest penetration worth probing a normal
# law at; and, for a static body held by friction alone, hold = dict(T=tangential load,
# N=normal load, L=contact length (sum of the weights), w_min=smallest weight).
LAW_RANGE_KEYS = ("p", "q", "v", "dt", "g", "hold")


def penalty_pressure(energy, c_N, m=1.0, weight=1.0):
    """The pressure c_N a^m of the penalty law (eq 4) at the penetration a where one node of
    weight `weight` stores all of `energy`: w c_N a^(m+1) / (m+1) = energy. A bound of the
    pressures of a run whose energy is `energy` (a scene's law_range)."""
    a = ((m + 1.0) * energy / (weight * c_N)) ** (1.0 / (m + 1.0))
    return c_N * a ** m


def _count(x):
    """A count from a float estimate: rounded up, overflow (inf, nan) as 1e18."""
    x = float(x)
    return int(math.ceil(x - 1e-9)) if math.isfinite(x) and x < 1e18 else 10 ** 18


# Resource model (Scene.estimate) and the limits that `contactfem run` enforces unless --force.
# Calibrated on hertz (peak resident memory): 45,602 unknowns 312 MB, 181,202 unknowns 1.08 GB,
# i.e. about 310 bytes per unknown and per log2(unknowns) (the LU fill grows like n log n).
MEMORY_BASE = 100e6            # the interpreter with numpy, scipy and scikit-fem loaded
MEMORY_PER_UNKNOWN = 310.0     # bytes per unknown and per log2(unknowns)
MEMORY_PER_STEP = 2.0e3        # bytes per time step (recorded histories)
LIMITS = {"memory_bytes": 2e9, "unknowns": 1e6, "steps": 1e6}


def check_resources(scene, params, force=False):
    """ValueError naming the estimate when a run would exceed LIMITS (unless force);
    returns the estimate (or None for a scene without a size model)."""
    est = scene.estimate(params)
    if est is None or force:
        return est
    over = [k for k, lim in LIMITS.items() if est.get(k, 0) > lim]
    if over:
        raise ValueError(f"{scene.name} would need {describe(est)}: above the limit of "
                         + ", ".join(_fmt(k, LIMITS[k]) for k in over) + " (add --force to run it anyway)")
    return est


def _fmt(key, value):
    if key == "memory_bytes":
        return f"{value / 1e9:.2g} GB" if value >= 1e8 else f"{value / 1e6:.0f} MB"
    return f"{value:,.0f} {key}"


def describe(est):
    """'4,000,000 elements, 8,004,002 unknowns, 1 steps, about 21 GB'"""
    parts = [_fmt(k, est[k]) for k in ("elements", "unknowns", "steps") if k in est]
    return ", ".join(parts) + f", about {_fmt('memory_bytes', est['memory_bytes'])}"


def jsonable(obj, where="result"):
    """numpy arrays and scalars to lists and floats, recursively; NaN is refused
    (FloatingPointError naming the result)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v, f"{k}" if where == "result" else f"{where}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v, where) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist(), where)
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        if not np.isfinite(f):
            raise FloatingPointError(f"the run gave a non-finite result ({where} = {f}); refusing to report it "
                                     "(parameters near the limits of floating point?)")
        return f
    return obj
