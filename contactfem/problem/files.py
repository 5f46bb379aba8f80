"""A scene in a file of its own, written by a user: ``contactfem run my_scene.py``.

A scene file is a Python module that defines ``SCENE = Scene(...)`` exactly as the shipped
scenes do (the modules of this package): its parameters (``Param``: unit, range, meaning),
``build(params, *, normal, friction, system_options)`` returning the model (a ``Model`` with
the ``systems`` it built, the time loop's ``stage`` and its own objects in ``parts``), and
``measure(model, params, records)`` returning the results (a dict). Everything a shipped scene
gets, it gets: ``run``, ``sweep`` (with ``law.FIELD``), ``show``, ``--friction`` / ``--normal``,
``--json``, ``--save``, progress, the pre-flight of a law over ``law_range`` (check_law's default
range where the file declares none). From Python: ``run_scene("my_scene.py", ...)``.

The file is the user's code, so every call into it is guarded:

* loading it: a syntax error, a failed import, ``sys.exit`` or no ``SCENE`` is one
  ValueError naming the file, the line and the cause (the command line: exit code 2);
* its declaration, when it is loaded: parameters that are not ``Param`` objects, two of one
  name, a name the run reserves (``tolerance``; ``accuracy`` unless it is the framework's
  ``ACCURACY_PARAM``), defaults out of their own ranges, presets that set no parameter of the
  file: one ValueError naming the file and the key (exit code 2);
* its ``build``, ``measure``, ``check``, ``size`` and ``law_range`` during a run: an error
  is one SceneError naming the file, the function, the line and the cause (exit code 1),
  and so is a value of the wrong kind, named by its key: a build that returns no Model, a
  Model whose ``stage`` is no Stage (and no ``simulate`` of its own), ``systems`` that are
  no Systems, ``sizes`` that are no lengths, a Stage whose initial state does not fit its
  System; results that are not a dict of finite real numbers, text, arrays, lists and dicts
  of them, or that take a name the run sets itself (RESERVED_RESULTS; ``accuracy`` only as
  the scene's own indicators, ``problem.accuracy.indicator``); a size or law range that is
  no dict of numbers.

A solver failure (NewtonError) or a law's bad value (LawValueError) inside the run is the
run's outcome, as in a shipped scene, and passes through unchanged; a run that fails from an
initial configuration whose bodies overlap says so (the contact, how many nodes, how deep).
"""

import hashlib
import importlib.util
import numbers
import sys
import traceback
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..laws.protocol import LawValueError
from ..solver.newton import NewtonError
from ..solver.system import System
from .model import Stage
from .params import Param, parse_all
from .scene import LAW_RANGE_KEYS, RUN_KEYS, Model, Scene, simulate
from .time_integration import ACCURACY_PARAM
from .uncertainty import Discretisation, Quantity

# names of results the run sets itself (RUN_KEYS, and what scenes.run_scene and the error bars add);
# ``accuracy`` is the run's section, where a scene adds its own indicators
RESERVED_RESULTS = tuple(k for k in RUN_KEYS if k != "accuracy") + (
    "scene_file",
    "friction_law",
    "normal_law",
    "uncertainty",
)
# parameter names the run reserves: ``accuracy`` (a run at a tolerance reads it: a file takes it
# as time_integration.ACCURACY_PARAM or not at all) and ``tolerance`` (an option of every run)
RESERVED_PARAMS = ("accuracy", "tolerance")
INDICATOR_KEYS = ("value", "threshold", "ok", "what", "source", "bound")  # problem.accuracy.indicator
SIZES = ("element", "body", "radius")  # Model.sizes: the lengths the accuracy indicators read


class SceneError(RuntimeError):
    """A scene file's own code failed during a run (one line: file, function, line, cause)."""


def is_scene_file(name):
    """Whether `name` names a scene file rather than a shipped scene: a path ending in .py."""
    return isinstance(name, (str, Path)) and str(name).endswith(".py")


def _line_in(path, err):
    """The last line of `path` that err's traceback passed through, or None."""
    if isinstance(err, SyntaxError) and err.filename and Path(err.filename).resolve() == path:
        return err.lineno
    line = None
    for frame in traceback.extract_tb(err.__traceback__):
        if Path(frame.filename).resolve() == path:
            line = frame.lineno
    return line


def _cause(err):
    if isinstance(err, SyntaxError):
        return f"SyntaxError: {err.msg}"
    if isinstance(err, SystemExit):
        return f"it calls sys.exit({err.code!r})"
    return f"{type(err).__name__}: {' '.join(str(err).split())}"


def exec_file(path, what):
    """Execute the Python file `path` as a fresh module (named in sys.modules, as dataclasses
    need) and return it; any error, ``sys.exit`` included, is one ValueError
    '{what} NAME, line N: cause'. A Ctrl-C passes through."""
    path = Path(path).expanduser().resolve()
    if not path.is_file():
        raise ValueError(f"{what} {path} not found")
    stat = path.stat()
    key = hashlib.sha1(f"{path}:{stat.st_mtime_ns}:{stat.st_size}".encode()).hexdigest()[:12]
    mod_name = f"contactfem_{what.replace(' ', '_')}_{key}_{path.stem}"
    if mod_name in sys.modules:  # the same file, unchanged: loaded once a process
        return sys.modules[mod_name]
    spec = importlib.util.spec_from_file_location(mod_name, path)
    if spec is None or spec.loader is None:
        raise ValueError(f"{what} {path.name} is not a Python file")
    module = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = module
    try:
        spec.loader.exec_module(module)
    except (Exception, SystemExit) as err:  # noqa: BLE001 (anything in the user's file)
        sys.modules.pop(mod_name, None)
        line = _line_in(path, err)
        raise ValueError(f"{what} {path.name}" + (f", line {line}" if line else "") + f": {_cause(err)}") from None
    return module


def _guarded(fn, path, role):
    """fn, with any error of the user's code turned into one SceneError line."""

    def call(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except (NewtonError, LawValueError, FloatingPointError, SceneError):
            raise  # the run's own outcome, as in a shipped scene
        except ValueError as err:
            if role == "check":  # a cross-parameter check: bad input (exit 2)
                raise ValueError(f"scene {path.stem}: {' '.join(str(err).split())}") from None
            raise _error(err, path, role) from None
        except (Exception, SystemExit) as err:  # noqa: BLE001
            raise _error(err, path, role) from None

    return call


def _error(err, path, role):
    line = _line_in(path, err)
    return SceneError(f"scene file {path.name}, {role}" + (f", line {line}" if line else "") + f": {_cause(err)}")


def _checked_build(build, path, own_simulate):
    def call(params, **kwargs):
        model = build(params, **kwargs)
        if not isinstance(model, Model):
            raise SceneError(
                f"scene file {path.name}, build: returned {type(model).__name__}, not a Model: "
                "return Model(systems=(system,), stage=Stage(...), parts=dict(...))"
            )
        bad = _bad_model(model, own_simulate)
        if bad:
            raise SceneError(f"scene file {path.name}, build: {bad}")
        return model

    return call


def _bad_model(model, own_simulate):
    """What is wrong with a file's Model, in words naming the key, or None."""
    for i, system in enumerate(model.systems):
        if not isinstance(system, System):
            return f"Model.systems[{i}] is a {type(system).__name__}, not a System (contactfem.solver.System)"
    if model.stage is None and not own_simulate:
        return "the Model has no stage (the time loop's Stage) and the Scene no simulate of its own"
    if model.stage is not None and not isinstance(model.stage, Stage):
        return (
            f"Model.stage is a {type(model.stage).__name__}, not a Stage: give one march, "
            "Model(..., stage=Stage(stepper, schedule, u0, v0))"
        )
    if not isinstance(model.sizes, dict):
        return f"Model.sizes is a {type(model.sizes).__name__}, not a dict of lengths ({', '.join(SIZES)})"
    for key, value in model.sizes.items():
        if key not in SIZES:
            return f"Model.sizes[{key!r}] is not a size the indicators read: {', '.join(SIZES)}"
        if not _real(value) or not (np.isfinite(value) and value > 0):
            return f"Model.sizes[{key!r}] = {value!r} is not a length > 0"
    if not isinstance(model.parts, dict):
        return f"Model.parts is a {type(model.parts).__name__}, not a dict"
    return None if model.stage is None else _bad_stage(model.stage)


def _bad_stage(stage):
    """What is wrong with a file's Stage, naming the field, or None."""
    system = getattr(stage.stepper, "system", None)
    if not callable(getattr(stage.stepper, "step", None)) or system is None:
        return (
            f"Stage.stepper is a {type(stage.stepper).__name__}, not a time stepper (Newmark(system), Static(system))"
        )
    if not callable(getattr(stage.schedule, "next_dt", None)):
        return f"Stage.schedule is a {type(stage.schedule).__name__}, not a schedule (Steps(dt, n_steps=...))"
    if not _real(stage.t0) or not np.isfinite(stage.t0):
        return f"Stage.t0 = {stage.t0!r} is not a finite time"
    for key in ("u0", "v0", "a0"):
        value = getattr(stage, key)
        if value is None and key != "u0":
            continue
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            return f"Stage.{key} is not an array of numbers"
        if array.shape != (system.ndof,):
            return f"Stage.{key} has the shape {array.shape}, the stepper's System {system.ndof} unknowns"
        if not np.isfinite(array).all():
            return f"Stage.{key} holds NaN or inf"
    return None


def _real(value):
    return isinstance(value, (numbers.Real, np.floating, np.integer)) and not isinstance(value, (bool, np.bool_))


def _bad_value(value, key):
    """What is wrong with one result (``key`` names it), or None: results are finite real numbers,
    booleans, text, None, and arrays, lists, tuples and dicts of them."""
    if value is None or isinstance(value, (str, bool, np.bool_)):
        return None
    if _real(value):
        return None if np.isfinite(value) else f"{key} = {float(value)} is not finite"
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "biu":
            return None
        if value.dtype.kind == "f":
            return None if np.isfinite(value).all() else f"{key} holds NaN or inf"
        if value.dtype.kind in "US":
            return None
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return next((b for i, v in enumerate(value) if (b := _bad_value(v, f"{key}[{i}]"))), None)
    if isinstance(value, dict):
        return next((b for k, v in value.items() if (b := _bad_key(k, key) or _bad_value(v, f"{key}[{k!r}]"))), None)
    kind = "complex" if isinstance(value, (complex, np.complexfloating)) else f"of type {type(value).__name__}"
    return f"{key} is {kind} ({str(value)[:40]}): results are real numbers, text, and lists and dicts of them"


def _bad_key(k, where):
    return None if isinstance(k, str) else f"{where} has a key {k!r} that is not text"


def _bad_results(out):
    """What is wrong with a file's results (a dict), naming the key, or None."""
    for key, value in out.items():
        bad = _bad_key(key, "the results")
        if bad:
            return bad
        if key in RESERVED_RESULTS:
            return f"{key} is a result the run sets itself: rename it (reserved: {', '.join(RESERVED_RESULTS)})"
        if key == "accuracy":
            bad = _bad_indicators(value)
            if bad:
                return bad
            continue
        bad = _bad_value(value, key)
        if bad:
            return bad
    return None


def _bad_indicators(value):
    """The scene's own accuracy indicators: {name: indicator(value, threshold, what, source)}."""
    hint = "accuracy is the run's section, where a scene adds its own indicators: {name: indicator(...)}"
    if not isinstance(value, dict):
        return f"accuracy is a {type(value).__name__}: {hint} (contactfem.problem.accuracy), or rename the result"
    for name, ind in value.items():
        if not isinstance(ind, dict) or set(ind) != set(INDICATOR_KEYS):
            return f"accuracy[{name!r}] is not an indicator: {hint} (contactfem.problem.accuracy)"
        bad = _bad_value(ind["value"], f"accuracy[{name!r}].value") or _bad_value(
            ind["threshold"], f"accuracy[{name!r}].threshold"
        )
        if bad:
            return bad
    return None


def _checked_measure(measure, path):
    def call(model, params, records):
        out = measure(model, params, records)
        if not isinstance(out, dict):
            raise SceneError(f"scene file {path.name}, measure: returned {type(out).__name__}, not a dict of results")
        bad = _bad_results(out)
        if bad:
            raise SceneError(f"scene file {path.name}, measure: {bad}")
        return out

    return call


def _checked_numbers(fn, path, role, keys, positive=()):
    """size and law_range: a dict of finite numbers >= 0 (> 0 under the keys ``positive``) under
    the keys the run reads (law_range's hold: a dict of such numbers too)."""

    def call(params):
        out = fn(params)
        if not isinstance(out, dict):
            raise SceneError(f"scene file {path.name}, {role}: returned {type(out).__name__}, not a dict")
        for key, value in out.items():
            if key not in keys:
                raise SceneError(f"scene file {path.name}, {role}: {key!r} is not one of {', '.join(keys)}")
            values = value.items() if key == "hold" and isinstance(value, dict) else [(key, value)]
            for name, v in values:
                what = "> 0" if name in positive else ">= 0"
                if not _real(v) or not np.isfinite(v) or (v <= 0 if name in positive else v < 0):
                    raise SceneError(f"scene file {path.name}, {role}: {name} = {v!r} is not a finite number {what}")
        return out

    return call


def _named_overlap(fn, path):
    """A scene's simulate ``fn``, with a run that fails after starting from overlapping bodies saying so."""

    def call(model, params, progress):
        try:
            return fn(model, params, progress)
        except NewtonError as err:
            first = (getattr(err, "records", None) or [getattr(err, "record", None)])[0]
            overlap = _overlap(first, model) if first is not None and first.k == 0 else None
            if overlap is not None:
                err.args = (f"{err}; {overlap} (scene file {path.name}, build: place the bodies apart)",)
            raise

    return call


def _overlap(record, model):
    """'the initial configuration overlaps: contact wall, 12 nodes up to 0.31 inside' or None;
    gaps within the round-off of the coordinates (1e3 machine epsilon of the largest) are touching."""
    system = getattr(getattr(model.stage, "stepper", None), "system", None) or model.system
    contacts = getattr(system, "contacts", [])
    extent = max(
        (float(np.max(np.abs(b.X), initial=0.0)) for b in getattr(system, "bodies", ()) if hasattr(b, "X")), default=0.0
    )
    parts = []
    for i, state in enumerate(getattr(record.evaluation, "contacts", ()) or ()):
        g = np.asarray(getattr(state, "g_N", ()), dtype=float)
        inside = g[np.isfinite(g) & (g < -1e3 * np.finfo(float).eps * extent)]
        if inside.size:
            name = getattr(contacts[i], "name", "") if i < len(contacts) else ""
            parts.append(f"contact {name or i}, {inside.size} nodes up to {-inside.min():.3g} inside its master")
    return "the initial configuration overlaps: " + "; ".join(parts) if parts else None


def _check_declaration(scene, path):
    """ValueError (one line, naming the file and the key) for a Scene whose declaration is wrong."""
    where = f"scene file {path.name}, SCENE"
    if not isinstance(scene.params, (tuple, list)):
        raise ValueError(f"{where}: params is a {type(scene.params).__name__}, not a tuple of Param")
    names = []
    for p in scene.params:
        if not isinstance(p, Param):
            raise ValueError(f"{where}: params holds a {type(p).__name__}, not a Param (contactfem.scenes.Param)")
        if not isinstance(p.name, str) or not p.name.isidentifier():
            raise ValueError(f"{where}: parameter name {p.name!r} is not a name (letters, digits and _)")
        if p.name in names:
            raise ValueError(f"{where}: two parameters are named {p.name}: give each parameter one name")
        if p.name in RESERVED_PARAMS and p != ACCURACY_PARAM:
            how = (
                "the run's tolerance: take it as contactfem.problem.time_integration.ACCURACY_PARAM, or rename yours"
                if p.name == "accuracy"
                else "an option of every run: rename yours"
            )
            raise ValueError(f"{where}: parameter {p.name} is a name the run reserves ({how})")
        names.append(p.name)
    for role in ("build", "measure"):
        if not callable(getattr(scene, role)):
            raise ValueError(f"{where}: {role} is a {type(getattr(scene, role)).__name__}, not a function")
    try:
        defaults = parse_all(scene.params, {p.name: p.default for p in scene.params})
    except ValueError as err:
        raise ValueError(f"{where}: a default is not allowed: {' '.join(str(err).split())}") from None
    _check_error_bars(scene, where, dict(defaults, accuracy=0.0), names)
    if not isinstance(scene.presets, dict):
        raise ValueError(f"{where}: presets is a {type(scene.presets).__name__}, not a dict of name -> values")
    for preset, values in scene.presets.items():
        unknown = [k for k in values if k not in names] if isinstance(values, dict) else None
        if unknown is None or unknown:
            what = f"sets {unknown[0]!r}, not a parameter of the file" if unknown else "is not a dict of values"
            raise ValueError(f"{where}: preset {preset} {what} (its parameters: {', '.join(names)})")
    for kind, params in dict(scene.law_params).items():
        unknown = [k for k in params if k not in names]
        if kind not in ("normal", "friction"):
            raise ValueError(f"{where}: law_params has the kind {kind!r}: the kinds of law are normal and friction")
        if unknown:
            raise ValueError(f"{where}: law_params[{kind!r}] names {unknown[0]!r}, not a parameter of the file")


def _check_error_bars(scene, where, defaults, names):
    """The headline quantities and the discretisations of a scene file (its error bars), checked when it is
    loaded: Quantity and Discretisation objects, each quantity controlled by discretisations the file
    declares, each discretisation's coarser level, size and order computed at the defaults (a parameter
    it reads that the file lacks is named)."""
    for what, items, kind in (
        ("quantities", scene.quantities, Quantity),
        ("discretisations", scene.discretisations, Discretisation),
    ):
        if not isinstance(items, (tuple, list)) or not all(isinstance(x, kind) for x in items):
            raise ValueError(f"{where}: {what} is not a tuple of {kind.__name__} (contactfem.scenes.{kind.__name__})")
    known = [d.name for d in scene.discretisations]
    for q in scene.quantities:
        unknown = [c for c in q.controls if c not in known]
        if unknown:
            raise ValueError(
                f"{where}: quantity {q.name} is controlled by {unknown[0]!r}, not a discretisation of the file "
                f"(its discretisations: {', '.join(known) or 'none'}; e.g. time_step(), mesh())"
            )
    for d in scene.discretisations:
        try:
            if d.applies(defaults):
                d.size(defaults), d.order(defaults)
                try:
                    d.coarsen(defaults, 2.0)
                except ValueError:  # no level that coarse at the defaults: the ladder takes another
                    pass
        except KeyError as err:
            raise ValueError(
                f"{where}: discretisation {d.name} reads {err.args[0]!r}, not a parameter of the file "
                f"(its parameters: {', '.join(names)})"
            ) from None
        except Exception as err:  # noqa: BLE001 (the file's own functions: one line naming them)
            raise ValueError(f"{where}: discretisation {d.name} at the defaults: {_cause(err)}") from None


def load_scene_file(path):
    """The Scene a scene file defines (``SCENE``), its callables guarded; ValueError in one
    line if the file cannot be loaded or defines no Scene."""
    module = exec_file(path, "scene file")
    path = Path(module.__file__).resolve()
    scene = getattr(module, "SCENE", None)
    if not isinstance(scene, Scene):
        found = "" if scene is None else f" (SCENE is a {type(scene).__name__})"
        raise ValueError(f"scene file {path.name} defines no SCENE = Scene(...){found}: see contactfem.scenes.Scene")
    _check_declaration(scene, path)
    checked = dict(
        size=scene.size and _checked_numbers(scene.size, path, "size", ("elements", "unknowns", "steps")),
        law_range=scene.law_range
        and _checked_numbers(scene.law_range, path, "law_range", LAW_RANGE_KEYS, positive=("p", "dt", "g")),
        build=_checked_build(scene.build, path, scene.simulate is not None),
        measure=_checked_measure(scene.measure, path),
        check=scene.check,
        simulate=scene.simulate,
        settles=scene.settles,
    )
    guarded = {role: _guarded(fn, path, role) for role, fn in checked.items() if fn is not None}
    discretisations = tuple(_guarded_discretisation(d, path) for d in scene.discretisations)
    return replace(
        scene,
        **guarded,
        discretisations=discretisations,
        simulate=_named_overlap(guarded.get("simulate", simulate), path),
    )


def _guarded_discretisation(d, path):
    """A scene file's Discretisation with its callables guarded; a ValueError of ``coarsen`` passes (no
    level that coarse: the ladder takes another), any other error is one SceneError line."""
    role = f"discretisation {d.name}"

    def coarsen(params, r):
        try:
            return d.coarsen(params, r)
        except ValueError:
            raise
        except (Exception, SystemExit) as err:  # noqa: BLE001
            raise _error(err, path, role + ", coarsen") from None

    calls = {f: _guarded(getattr(d, f), path, f"{role}, {f}") for f in ("size", "order", "applies")}
    return replace(d, coarsen=coarsen, **calls)
