"""A scene in a file of its own, written by a user: ``contactfem run my_scene.py``.

A scene file is a Python module that defines ``SCENE = Scene(...)`` exactly as the shipped
scenes do (the modules of this package): its parameters (``Param``: unit, range, meaning),
``build(params, *, normal, friction, system_options)`` returning the model (a ``Model`` with
the ``systems`` it built, the time loop's ``stage`` and its own objects in ``parts``), and ``measure(model, params, records)``
returning the results (a dict). Everything a shipped scene gets, it gets: ``run``, ``sweep``
(with ``law.FIELD``), ``show``, ``--friction`` / ``--normal``, ``--json``, ``--save``,
progress, the pre-flight of a law over ``law_range`` where the file declares one. From
Python: ``run_scene("my_scene.py", ...)``.

The file is the user's code, so every call into it is guarded:

* loading it: a syntax error, a failed import, ``sys.exit`` or no ``SCENE`` is one
  ValueError naming the file, the line and the cause (the command line: exit code 2);
* its ``build``, ``measure``, ``check``, ``size`` and ``law_range`` during a run: an error
  is one SceneError naming the file, the function, the line and the cause (exit code 1),
  and a result of the wrong kind (a build that returns no Model, a Model without a
  ``stage`` and no ``simulate`` of its own, results that are not a dict) is named as such.

A solver failure (NewtonError) or a law's bad value (LawValueError) inside the run is the
run's outcome, as in a shipped scene, and passes through unchanged.
"""

import hashlib
import importlib.util
import sys
import traceback
from dataclasses import replace
from pathlib import Path

from .scene import Model, Scene
from .time_integration import ACCURACY_PARAM


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
    from ..laws.protocol import LawValueError
    from ..solver.newton import NewtonError

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
        if model.stage is None and not own_simulate:
            raise SceneError(
                f"scene file {path.name}, build: the Model has no stage (the time loop's Stage) "
                "and the Scene no simulate of its own"
            )
        return model

    return call


def _checked_measure(measure, path):
    def call(model, params, records):
        out = measure(model, params, records)
        if not isinstance(out, dict):
            raise SceneError(f"scene file {path.name}, measure: returned {type(out).__name__}, not a dict of results")
        return out

    return call


def load_scene_file(path):
    """The Scene a scene file defines (``SCENE``), its callables guarded; ValueError in one
    line if the file cannot be loaded or defines no Scene."""
    module = exec_file(path, "scene file")
    path = Path(module.__file__).resolve()
    scene = getattr(module, "SCENE", None)
    if not isinstance(scene, Scene):
        found = "" if scene is None else f" (SCENE is a {type(scene).__name__})"
        raise ValueError(f"scene file {path.name} defines no SCENE = Scene(...){found}: see contactfem.scenes.Scene")
    own = [p for p in scene.params if p.name == "accuracy" and p is not ACCURACY_PARAM]
    if own:  # the framework's name for a run's tolerance (run_scene's accuracy): a file's own would be taken over
        raise ValueError(
            f"scene file {path.name}: the parameter name 'accuracy' is reserved (a run's tolerance for its time "
            "steps, contactfem.problem.time_integration.ACCURACY_PARAM): rename it"
        )
    guarded = {
        role: _guarded(getattr(scene, role), path, role)
        for role in ("check", "size", "law_range", "simulate")
        if getattr(scene, role) is not None
    }
    build = _guarded(_checked_build(scene.build, path, scene.simulate is not None), path, "build")
    measure = _guarded(_checked_measure(scene.measure, path), path, "measure")
    discretisations = tuple(_guarded_discretisation(d, path) for d in scene.discretisations)
    if scene.settles is not None:
        guarded["settles"] = _guarded(scene.settles, path, "settles")
    return replace(scene, build=build, measure=measure, discretisations=discretisations, **guarded)


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
