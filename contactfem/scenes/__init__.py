"""Scenes: each module composes bodies, obstacles, laws and loads into one of the
paper's examples (or a verification problem with a closed form) and declares its
parameters. A module becomes a scene by defining ``SCENE = Scene(...)``.

Listing the scenes imports every scene module, so a scene module takes scikit-fem (and the
continuum bodies built on it) as lazy modules (contactfem/lazy.py), loaded when a model is built:
``contactfem list`` and ``show`` then load neither scikit-fem nor scipy nor matplotlib."""

import importlib
import pkgutil
import warnings
from pathlib import Path

from ..laws.protocol import as_normal_law, describe
from ..problem.files import SceneError, is_scene_file, load_scene_file
from ..problem.params import check_overrides, did_you_mean
from ..problem.scene import Limit, Model, Param, Scene, Stage, jsonable, simulate
from ..problem.uncertainty import (
    TOLERANCE,
    Discretisation,
    Quantity,
    check_tolerance,
    error_bars_default,
    mesh,
    penalty,
    time_step,
)
from ..solver.assembly import KINDS


def all_scenes():
    """name -> Scene, for every module of this package that defines SCENE."""
    found = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        scene = getattr(mod, "SCENE", None)
        if scene is not None:
            found[scene.name] = scene
    return found


def get_scene(name):
    """The Scene called `name`. A scene lives in the module of its name, so only that module
    is imported (the others only when the name is unknown, to list the known ones). A path
    ending in .py is a scene file a user wrote (files.py); a Scene is returned as it is."""
    if isinstance(name, Scene):
        return name
    if is_scene_file(name):
        if not Path(name).expanduser().is_file():
            raise ValueError(
                f"unknown scene {str(name)!r}: no scene file there (a path to a .py file that defines "
                f"SCENE); known are {', '.join(all_scenes())}"
            )
        return load_scene_file(name)
    if isinstance(name, str) and name.isidentifier() and not name.startswith("_"):
        module = f"{__name__}.{name}"
        try:
            scene = getattr(importlib.import_module(module), "SCENE", None)
        except ModuleNotFoundError as err:
            if err.name != module:
                raise
            scene = None
        if scene is not None and scene.name == name:
            return scene
    scenes = all_scenes()
    if name not in scenes:
        raise ValueError(
            f"unknown scene {name!r}{did_you_mean(name, scenes)}: known are {', '.join(scenes) or '(none)'}"
        )
    return scenes[name]


def check_laws(scene, laws, overrides=None):
    """scene.check_laws (law objects or classes of kinds the scene has; no parameter set that
    builds a law they replace), the message naming the scenes a law does apply to."""
    try:
        scene.check_laws(laws, overrides)
    except ValueError as err:
        kind = next((k for k in laws if k not in scene.laws), None)
        if kind is None:
            raise
        others = [n for n, s in all_scenes().items() if kind in s.laws]
        raise ValueError(f"{err}; scenes with a {kind} law: {', '.join(others)}") from None


def run_scene(
    name,
    preset="fast",
    overrides=None,
    progress=None,
    friction=None,
    normal=None,
    linear_algebra=None,
    instrument=None,
    check=True,
    error_bars=None,
    tolerance=None,
):
    """Run a scene and return its JSON-able results with the parameters used, the run's own wall
    time, Newton iteration count and the linear algebra of its Systems (``linear_algebra``:
    dense|banded|sparse, joined by + if they differ; ``ordering``; ``unknowns``, the largest
    System's; ``band_kl``, ``band_ku``: the half-bandwidths of a banded K, else None), and how
    often they were evaluated (``residual_evaluations``, ``contact_evaluations``).
    ``overrides``: {parameter name: value}, a value given as a number or as the text of one (the
    same rule as the command line's --set: an integer parameter takes 12, 12.0 or "12"; see
    problem.params); a TypeError names ``overrides`` or ``progress`` given as anything else.
    ``linear_algebra``: auto|dense|banded|sparse for every System the scene builds (None: auto,
    chosen by size and band width), to compare the solvers on one scene.
    ``progress(t0, t_end, label)``: a progress-callback factory for the scene's time loops
    (e.g. ``contactfem.io.progress_bar``); None shows nothing.
    ``friction`` / ``normal``: law objects replacing the laws the scene's parameters build
    (recorded as ``friction_law`` / ``normal_law``: class, file, fields; the parameters that
    build the replaced law are refused in ``overrides`` and left out of ``parameters``, and
    ``variant`` names the law). ``check``: check the law objects first over the range of
    pressures, slips and gaps the scene meets (Scene.preflight): a LawError (ValueError) for
    a value no law may return, a warning for a derivative that disagrees with finite
    differences. During the run every value a law object returns is checked too
    (contactfem.laws.protocol): a LawValueError ends the run.
    ``instrument``: a solver.instrument.Timings handed to every System (the bench's timings).
    ``error_bars``: the headline quantities with their error bands from coarser runs (the section
    ``uncertainty``; problem/uncertainty.py); None: on, unless $CONTACTFEM_ERROR_BARS is 0 or off.
    ``tolerance``: the relative band (and closed-form error) past which a quantity warns (default 0.05)."""
    scene = get_scene(name)
    overrides = check_overrides(overrides)
    tolerance = TOLERANCE if tolerance is None else check_tolerance(tolerance)
    if error_bars is not None and not isinstance(error_bars, bool):
        raise TypeError(
            f"error_bars = {error_bars!r}: give True, False or None (None: on, unless $CONTACTFEM_ERROR_BARS is off)"
        )
    error_bars = error_bars_default() if error_bars is None else bool(error_bars)
    if progress is not None and not callable(progress):
        raise TypeError(
            f"parameter progress must be None or a callable progress(t0, t_end, label) (e.g. "
            f"contactfem.io.progress_bar), got {type(progress).__name__} {progress!r}"
        )
    laws = {k: v for k, v in (("friction", friction), ("normal", normal)) if v is not None}
    check_laws(scene, laws, overrides)
    params = scene.resolve(preset, overrides)
    if linear_algebra is not None and linear_algebra not in KINDS:
        raise ValueError(f"parameter linear_algebra = {linear_algebra!r} is not allowed: one of {'|'.join(KINDS)}")
    if check:
        for note in scene.preflight(params, laws):
            warnings.warn(note, UserWarning, stacklevel=2)
    if normal is not None:  # every call into it checked (contactfem.laws.protocol)
        normal = as_normal_law(normal)
    results = scene.run(
        params,
        normal=normal,
        friction=friction,
        progress=progress,
        linear_algebra=linear_algebra or "auto",
        instrument=instrument,
        error_bars=error_bars,
        tolerance=tolerance,
    )
    for kind, law in laws.items():
        results[f"{kind}_law"] = describe(law)
    if "friction" in laws and scene.law_choice is not None and "variant" in results:
        results["variant"] = scene.variant_of(params, friction)
    results["scene"] = scene.name
    if is_scene_file(name):
        results["scene_file"] = str(name)
    results["preset"] = preset
    results["parameters"] = {k: v for k, v in params.items() if scene.law_param_kind(k, v) not in laws}
    return jsonable(results)


__all__ = [
    "Discretisation",
    "Limit",
    "Quantity",
    "mesh",
    "penalty",
    "time_step",
    "Model",
    "Param",
    "Scene",
    "SceneError",
    "Stage",
    "all_scenes",
    "is_scene_file",
    "get_scene",
    "run_scene",
    "check_laws",
    "jsonable",
    "simulate",
]
