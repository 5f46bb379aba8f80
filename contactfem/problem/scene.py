"""What a scene is: named parameters with units and ranges, presets, and three steps,

    model = scene.build(params, normal=..., friction=..., system_options=...)   # a Model: Systems, Stages
    records = simulate(model, params, progress)   # the time loop (solver.march) over the model's Stages
    results = scene.measure(model, params, records)   # a JSON-able dict from the records

that ``run`` puts together (one function for every scene: it also reports the size of the
system, how it was solved and how often it was evaluated). A scene of several stages (the cork:
press fit, then pop) marches them in turn: its records carry the stage that made them
(``record.stage``), and a stage may start from the last record of the one before it.

A scene module defines ``SCENE = Scene(...)``; the registry in ``contactfem.scenes`` finds
it. Parameter names follow the paper's symbols (c_N, c_T, m, n, alpha, beta, mu, E, nu, dt,
delta, beta_newmark, ...)."""

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .. import solver
from ..clock import imports_timed
from ..laws import check as law_check
from ..solver.march import evaluations
from .accuracy import collect, references, stepping, warn
from .model import Model, Stage  # noqa: F401  (scene modules take them here)
from .params import Limit, Param  # noqa: F401  (scene modules take Param, Limit here)
from .params import check_overrides, did_you_mean, parse_all
from .resources import check_resources, describe  # noqa: F401  (the command line takes them from here)
from .resources import estimate as estimate_resources
from .time_integration import at_tolerance_values
from .uncertainty import TOLERANCE, Discretisation, Quantity  # noqa: F401  (scene modules take them here)
from .uncertainty import bands, run_level

# what a run reports of itself, how it went rather than what it computed (set by run and
# scenes.run_scene; io.compare_runs leaves them out): a scene's measure may not return them
RUN_KEYS = (
    "wall_time_s",
    "import_time_s",
    "linear_algebra",
    "ordering",
    "unknowns",
    "band_kl",
    "band_ku",
    "residual_evaluations",
    "contact_evaluations",
    "scene",
    "preset",
    "parameters",
    "accuracy",
    "stepping",
)

PENALTIES = ("per_length", "per_node")
PENALTY_DOC = (
    "unit of c_N and c_T: per_length = tractions per unit gap and per unit length of the contact "
    "boundary (nodal weights = tributary lengths; per unit area of an axisymmetric surface), "
    "per_node = nodal stiffnesses (weights 1)"
)


def simulate(model, params=None, progress=None):
    """The records of the model's stages in turn (``model.stages``), each stage's initial state and
    every step, as one list (``record.stage``: which stage made it); a stage given as a function is
    built from the last record of the stage before it, and its ``until`` may end it early. A
    NewtonError that ends the run carries the records so far (``error.records``)."""
    records = []
    try:
        for i, stage in enumerate(model.stages):
            st = stage if isinstance(stage, Stage) else stage(records[-1])
            marched = solver.march(
                st.stepper, st.schedule, st.t0, st.u0, st.v0, a0=st.a0, label=st.label, state=st.state, stage=i
            )
            if st.until is not None:
                marched = st.until(marched)
            for rec in solver.watch(marched, progress, st.t0, st.schedule.t_end, st.name or model.name):
                records.append(rec)
    except solver.NewtonError as err:
        err.records = records
        raise
    return records


def run(
    scene,
    params,
    normal=None,
    friction=None,
    progress=None,
    linear_algebra="auto",
    instrument=None,
    error_bars=False,
    tolerance=TOLERANCE,
):
    """Build, simulate and measure a scene with resolved parameters; ``linear_algebra`` and
    ``instrument`` (solver.instrument.Timings) go to every System the scene builds (its
    ``system_options``). The results come with the run's own wall time (``wall_time_s``:
    building, solving and measuring, less the time spent loading modules on first use:
    contactfem.clock), the linear algebra of the Systems it built (``linear_algebra``,
    ``ordering``, ``unknowns``, ``band_kl``, ``band_ku``) and how often they were evaluated
    (``residual_evaluations``: System evaluations, one per residual Newton needs;
    ``contact_evaluations``: contact evaluations, one per contact in each; both counted from the records,
    solver.march.evaluations), an ``accuracy`` section
    (problem/accuracy.py; AccuracyWarning past a threshold) and ``stepping`` where a scene takes ``accuracy``.
    With ``error_bars``, the scene's headline quantities (``scene.quantities``) get their error bands from
    coarser runs (problem/uncertainty.py: the section ``uncertainty``; a band past ``tolerance``, relative,
    warns); each closed form a quantity declares is an accuracy indicator held to ``tolerance`` too."""
    with imports_timed() as imported:  # modules loaded on first use: not the run's time
        t0 = time.perf_counter()
        options = dict(linear_algebra=linear_algebra, instrument=instrument)
        model = scene.build(params, normal=normal, friction=friction, system_options=options)
        if not isinstance(model, Model):
            raise TypeError(
                f"scene {scene.name}, build: returned {type(model).__name__}, not a Model (contactfem.scenes.Model)"
            )
        records = (scene.simulate or simulate)(model, params, progress)
        results = dict(scene.measure(model, params, records))
        wall = time.perf_counter() - t0
    systems = model.systems
    if "accuracy" in params:  # how the run stepped: fixed, or at a tolerance
        results["stepping"] = stepping(params, records)
    accuracy = collect(model, params, records, results, tolerance)
    accuracy.update(results.pop("accuracy", None) or {})  # the scene's own
    accuracy.update(references(scene.quantities, params, results, tolerance))  # the closed forms it declares
    results["wall_time_s"] = wall - imported[0]
    results["linear_algebra"] = "+".join(dict.fromkeys(s.linear_algebra for s in systems)) or None
    results["ordering"] = "+".join(dict.fromkeys(s.ordering for s in systems)) or None
    results["unknowns"] = max((s.ndof for s in systems), default=None)
    widths = [s.band for s in systems if s.band is not None]
    results["band_kl"] = max((kl for kl, _ in widths), default=None)  # banded: the widest band
    results["band_ku"] = max((ku for _, ku in widths), default=None)
    results.update(evaluations(records))
    results.setdefault("newton_iterations_total", int(sum(r.iterations for r in records)))  # if not counted
    del records, model, systems  # (the ladder's runs need the memory)
    if error_bars and scene.quantities:

        def level(p):  # a level's progress (if the run shows its own) names what the level changed
            changed = ", ".join(
                f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in p.items() if v != params.get(k)
            )
            shown = progress and (lambda t0, t_end, label: progress(t0, t_end, f"error bars ({changed}): {label}"))
            return run(scene, p, normal, friction, shown, linear_algebra=linear_algebra, error_bars=False)

        results["uncertainty"], indicators = bands(
            lambda over: run_level(level, scene, params, over),
            params,
            results,
            scene.quantities,
            scene.discretisations,
            tolerance,
            settled=scene.settles(params, results) if scene.settles else None,
        )
        accuracy.update(indicators)
    results["accuracy"] = accuracy
    warn(accuracy, stacklevel=3)
    return results


@dataclass(frozen=True)
class Scene:
    name: str
    title: str
    params: tuple
    build: Callable  # (params, *, normal, friction, system_options) -> Model
    measure: Callable  # (model, params, records) -> results dict
    simulate: Callable | None = None  # (model, params, progress) -> records; default: the model's stages
    presets: dict = field(default_factory=dict)  # preset name -> {param: value}
    reports: tuple = ()  # names of the main results, for `show`
    check: Callable[[dict], None] | None = None  # cross-parameter checks (ValueError), before any run
    size: Callable[[dict], dict] | None = None  # {"elements", "unknowns", "steps"} from the parameters
    outlines: bool = False  # records body outlines (run --gif can animate them)
    notes: str = ""  # what `show` says after the parameters (data read/fitted)
    # The interface laws (a law object given to run_scene, or --friction / --normal, replaces the scene's own):
    laws: tuple = ()  # the kinds of law the scene's contact has: "normal", "friction"
    law_params: dict = field(default_factory=dict)  # kind -> the parameters that build the scene's law of that kind
    law_choice: tuple | None = None  # (parameter, values): those values of it choose the friction law
    law_range: Callable[[dict], dict] | None = None  # the range a law meets (LAW_RANGE_KEYS), for the pre-flight
    # The headline quantities and the discretisations that move them (problem/uncertainty.py): their error
    # bands, and their closed forms as accuracy indicators
    quantities: tuple = ()  # Quantity: name, unit, the discretisations that move it, its closed form
    discretisations: tuple = ()  # Discretisation: how a coarser level's parameters follow from the run's
    settles: Callable[[dict, dict], dict] | None = None  # (params, results) -> overrides that end the ladder's
    # levels once the quantities are decided (a rebound in free flight)

    def run(self, params, **options):
        """Build, simulate and measure, and with ``error_bars`` the error bands (module function ``run``, whose
        keywords ``options`` are; run_scene and the command line ask for the bands by default)."""
        return run(self, params, **options)

    def with_values(self, params, overrides):
        """Resolved ``params`` with ``overrides`` (a coarser level of a ladder), each value checked as
        a user's is (ValueError naming the parameter and its range)."""
        values = parse_all(self.params, dict(params, **overrides))
        if self.check is not None:
            self.check(values)
        return values

    def param(self, name):
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def resolve(self, preset="fast", overrides=None):
        """Defaults, then the preset, then the user's overrides; every value validated."""
        if preset != "fast" and preset not in self.presets:  # fast: the defaults, where no preset says more
            names = ["fast", *(k for k in self.presets if k != "fast")]
            raise ValueError(f"parameter preset = {preset!r} is not allowed for {self.name}: one of {'|'.join(names)}")
        known = {p.name: p for p in self.params}
        values = {p.name: p.default for p in self.params}
        values.update(self.presets.get(preset, {}))
        overrides = check_overrides(overrides)
        for k, v in overrides.items():
            if k not in known:
                head, dot, field = str(k).partition(".")
                if dot and head in ("law", "friction", "normal"):  # the command line's --set law.X, from Python
                    raise ValueError(
                        f"unknown parameter {k!r} for scene {self.name}: from Python a law's fields are "
                        f"set on the law object itself, e.g. friction=Coulomb(c_T, mu) "
                        f"or dataclasses.replace(law, {field}=...)"
                    )
                raise ValueError(
                    f"unknown parameter {k!r} for scene {self.name}{did_you_mean(k, known)}: known are "
                    f"{', '.join(known)}"
                )
            values[k] = v
        values = parse_all(self.params, values)  # each value, then the ranges from other parameters
        for k in overrides:  # a value the resolved variant would silently ignore
            if not known[k].applies(values):
                now = ", ".join(f"{o}={values[o]}" for o, _ in known[k].when)
                raise ValueError(
                    f"parameter {k} does not apply to {self.name} with {now}: "
                    f"it is used only with {known[k].when_text()}"
                )
        if self.check is not None:
            self.check(values)
        return at_tolerance_values(values)

    def law_param_kind(self, name, value=None):
        """The kind of law ("friction", "normal") the parameter `name` (= value) builds, or None."""
        for kind, names in self.law_params.items():
            if name in names:
                return kind
        if (
            self.law_choice is not None
            and name == self.law_choice[0]
            and (value is None or str(value) in map(str, self.law_choice[1]))
        ):
            return "friction"
        return None

    def check_laws(self, laws, overrides=None):
        """Before anything runs: ValueError (one line) if a law object (or class) is given for a
        kind the scene's contact does not have, or a parameter is set that builds a law it
        replaces (the hint names the law's own field)."""
        for kind, law in laws.items():
            if kind not in self.laws:
                what = "is frictionless" if kind == "friction" else "has no normal law"
                raise ValueError(
                    f"scene {self.name} has no {kind} law (its contact {what}): a {kind} law does not apply to it"
                )
        for k, v in (overrides or {}).items():
            kind = self.law_param_kind(k, v)
            if kind is None or kind not in laws:
                continue
            law = laws[kind]
            cls = law if isinstance(law, type) else type(law)
            name = cls.__name__
            if self.law_choice is not None and k == self.law_choice[0]:
                raise ValueError(
                    f"parameter {k} = {v} chooses the scene's {kind} law, which the {kind} law {name} "
                    f"replaces: leave {k} out"
                )
            fields = [f.name for f in dataclasses.fields(cls)] if dataclasses.is_dataclass(cls) else []
            fix = (
                f"set {name}'s own field instead: --set law.{k}={v} (or {name}({k}={v}))"
                if k in fields
                else f"{name} has no field {k} (its fields: {', '.join(fields) or 'none'})"
            )
            raise ValueError(
                f"parameter {k} builds the scene's {kind} law, which the {kind} law {name} replaces: " + fix
            )

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
        """Check law objects over the range the scene meets (``law_range``; a scene without one,
        over check_law's default range, laws.check.DEFAULT_RANGE) before solving: returns warning
        sentences (a derivative that disagrees with finite differences); raises LawError (one
        line) for a value no law may return (NaN, Y < 0, t_N > 0), a law that breaks the
        protocol, or a block its friction cannot hold."""
        if not laws:
            return []
        limits = law_check.DEFAULT_RANGE if self.law_range is None else self.law_range(params)
        return law_check.preflight(laws.get("friction"), laws.get("normal"), **limits)

    def estimate(self, params, linear_algebra="auto"):
        """Size of the run from the resolved parameters (resources.estimate), or None."""
        return None if self.size is None else estimate_resources(self.size(params), linear_algebra)


# What a scene's law_range(params) returns, all maxima of the run (generous bounds from the
# loads and penalties, not the values of one run): p the pressure |t_N| (in the law's unit:
# per length, per area or per node, as the scene's weights), q the accumulated slip, v the slip
# rate, dt the smallest planned time step, g the deepest penetration worth probing a normal
# law at; and, for a static body held by friction alone, hold = dict(T=tangential load,
# N=normal load, L=contact length (sum of the weights), w_min=smallest weight).
LAW_RANGE_KEYS = ("p", "q", "v", "dt", "g", "hold")


def jsonable(obj, where="result"):
    """numpy arrays and scalars to lists and floats, recursively; NaN is refused
    (FloatingPointError naming the result)."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v, f"{k}" if where == "result" else f"{where}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v, where) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "biu" or (obj.dtype.kind == "f" and np.isfinite(obj).all()):
            return obj.tolist()  # numbers, every one finite: Python's ints and floats
        return jsonable(obj.tolist(), where)
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        if not np.isfinite(f):
            raise FloatingPointError(
                f"the run gave a non-finite result ({where} = {f}); refusing to report it "
                "(parameters near the limits of floating point?)"
            )
        return f
    return obj
