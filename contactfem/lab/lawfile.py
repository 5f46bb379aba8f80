"""Laws for the command line, named three ways:

    contactfem run SCENE --friction my_law.py:Saturating --set law.mu0=0.6     # a law file
    contactfem run SCENE --friction stribeck --set law.mu_s=0.5 ...            # a shipped law
    contactfem run SCENE --normal mypackage.laws:Hyperbolic                    # a module path

A law file is a module defining the law class (a frozen dataclass, as the shipped laws).
Its fields are set like scene parameters: ``law.NAME=VALUE`` (or ``friction.NAME`` /
``normal.NAME`` when both laws have a field of that name). A field not set keeps the
law's own default; a field without a default takes the scene's parameter of the same
name where the scene declares it a parameter of that law (c_T, mu, c_N, m, ...; never an
integrator or mesh parameter), and the command line says so in one line. Values are
converted to the field's type and validated by the law itself (``__post_init__``) and by
the protocol (c_T finite and > 0), so a bad value gives the same one-line error as a
scene parameter.

Any error in the file (syntax, import, a name that does not exist, a law that fails on
arrays, returns the wrong number of values or NaN, ...) is one ValueError line naming the
file, the line and the cause. ``describe`` gives the JSON record of a law: class, file
and fields.
"""

import dataclasses
import importlib
import importlib.util
import itertools
import sys
import traceback
from pathlib import Path

import numpy as np

from .. import laws
from ..laws.protocol import FrictionLaw, LawError, NormalLawView, describe  # noqa: F401 (describe: public here too)
from ..problem.params import did_you_mean

KINDS = ("friction", "normal")


def shipped_laws():
    """{kind: {name: class}} of the shipped laws, by the names the command line accepts
    (the class name in lower case, with or without underscores: stribeck, power_law)."""
    out = {"friction": {}, "normal": {}}
    for cls in (
        laws.Coulomb,
        laws.ParabolicSlip,
        laws.SlipHardening,
        laws.Frictionless,
        laws.Stribeck,
        laws.DieterichRuina,
        laws.ArchardWear,
    ):
        out["friction"][_snake(cls.__name__)] = cls
    for cls in (laws.PowerLaw, laws.ExponentialLaw):
        out["normal"][_snake(cls.__name__)] = cls
    return out


def _snake(name):
    return "".join("_" + c.lower() if c.isupper() and i else c.lower() for i, c in enumerate(name))


def _kind_of(cls):
    if callable(getattr(cls, "slip_bound", None)):
        return "friction"
    if callable(getattr(cls, "traction", None)):
        return "normal"
    return None


def _check_kind(cls, option, where):
    """ValueError unless cls is a law of the kind the option asks for (--friction / --normal)."""
    want = option.lstrip("-")
    have = _kind_of(cls)
    if have == want or want not in KINDS:
        return
    if have is None:
        need = "slip_bound(p, q) and a stick stiffness c_T" if want == "friction" else "traction(g_N)"
        raise ValueError(f"{where}: {cls.__name__} is not a {want} law (a {want} law has {need})")
    raise ValueError(
        f"{where}: {cls.__name__} is a {have} law (it has "
        f"{'slip_bound' if have == 'friction' else 'traction'}): give it with --{have}, not {option}"
    )


_counter = itertools.count()


def _where(path, err):
    """'file, line N' of the innermost frame of err's traceback inside path."""
    if isinstance(err, SyntaxError) and err.filename and Path(err.filename).resolve() == path:
        return f"law file {path.name}, line {err.lineno}"
    line = None
    for frame in traceback.extract_tb(err.__traceback__):
        if Path(frame.filename).resolve() == path:
            line = frame.lineno
    return f"law file {path.name}" + (f", line {line}" if line else "")


def _cause(err):
    if isinstance(err, SyntaxError):
        return f"SyntaxError: {err.msg}"
    return f"{type(err).__name__}: {err}"


def load_class(spec, option="--friction"):
    """The law class named by spec (ValueError with one line naming file, line, cause):
    'FILE.py:CLASS' (a law file), 'package.module:CLASS' or 'package.module.CLASS' (an
    importable module), or the name of a shipped law ('stribeck', 'power_law')."""
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"{option} expects FILE.py:CLASS, a module path or a shipped law, got {spec!r}")
    file, colon, name = spec.rpartition(":")
    if colon and (file.endswith(".py") or "/" in file or "\\" in file or Path(file).expanduser().is_file()):
        cls = _from_file(file, name, option)
    elif colon:
        cls = _from_module(file, name, option, spec)
    elif spec.endswith(".py") or "/" in spec:
        raise ValueError(f"{option} expects FILE.py:CLASS, got {spec!r}")
    elif "." in spec:
        mod, _, name = spec.rpartition(".")
        cls = _from_module(mod, name, option, spec)
    else:
        kinds = shipped_laws()
        key = _snake(spec) if not spec.islower() else spec.lower()
        found = {k: v[key] for k, v in kinds.items() if key in v} or {
            k: c for k, v in kinds.items() for n, c in v.items() if n.replace("_", "") == spec.lower().replace("_", "")
        }
        if not found:
            names = "; ".join(f"{k}: {', '.join(v)}" for k, v in kinds.items())
            raise ValueError(
                f"{option} {spec}: not a shipped law ({names}), a law file FILE.py:CLASS or a module "
                "path package.module:CLASS"
            )
        cls = next(iter(found.values()))
    _check_kind(cls, option, f"{option} {spec}")
    return cls


def _from_module(module, name, option, spec):
    if not name.isidentifier():
        raise ValueError(f"{option} expects FILE.py:CLASS or package.module:CLASS, got class name {name!r}")
    try:
        mod = importlib.import_module(module)
    except (Exception, SystemExit) as err:  # noqa: BLE001 (anything in the user's module, even exit)
        raise ValueError(f"{option} {spec}: cannot import {module} ({_cause(err)})") from None
    cls = getattr(mod, name, None)
    if cls is None or not isinstance(cls, type):
        raise ValueError(f"{option} {spec}: module {module} has no class {name}")
    return cls


def _from_file(file, name, option):
    path = Path(file).expanduser().resolve()
    if not path.is_file():
        raise ValueError(f"{option}: law file {file} not found")
    if not name.isidentifier():
        raise ValueError(f"{option} expects FILE.py:CLASS, got class name {name!r}")
    mod_name = f"contactfem_lawfile_{next(_counter)}_{path.stem}"
    mspec = importlib.util.spec_from_file_location(mod_name, path)
    if mspec is None:
        raise ValueError(f"{option}: law file {file} is not a Python file")
    module = importlib.util.module_from_spec(mspec)
    sys.modules[mod_name] = module  # dataclasses look the module up
    try:
        mspec.loader.exec_module(module)
    except SystemExit as err:  # sys.exit() in the file: bad input, not our exit
        sys.modules.pop(mod_name, None)
        raise ValueError(
            f"{_where(path, err)}: the law file calls sys.exit({err.code!r}) when it is imported; a law "
            "file only defines its law"
        ) from None
    except Exception as err:  # noqa: BLE001 (anything in the user's file)
        sys.modules.pop(mod_name, None)
        raise ValueError(f"{_where(path, err)}: {_cause(err)}") from None
    cls = getattr(module, name, None)
    if cls is None or not isinstance(cls, type):
        found = sorted(
            k
            for k, v in vars(module).items()  # the law classes it holds
            if isinstance(v, type) and (hasattr(v, "traction") or hasattr(v, "slip_bound"))
        )
        raise ValueError(
            f"law file {path.name} has no class {name}" + (f" (it defines: {', '.join(found)})" if found else "")
        )
    cls._contactfem_file = str(file)
    return cls


def _convert(value, field):
    """A --set text to the field's type (float unless the annotation says otherwise)."""
    if not isinstance(value, str):
        return value
    t = (
        field.type
        if isinstance(field.type, type)
        else {"int": int, "bool": bool, "str": str}.get(str(field.type), float)
    )
    if t is bool:
        s = value.lower()
        if s in ("true", "1", "yes"):
            return True
        if s in ("false", "0", "no"):
            return False
        raise ValueError(f"law parameter {field.name} = {value!r} is not allowed: true|false")
    if t is str:
        return value
    try:
        number = float(value)
    except ValueError:
        raise ValueError(f"law parameter {field.name} must be a number, got {value!r}") from None
    if t is not int:
        return number
    if not number.is_integer():  # 12, 12.0 and 1.2e1 are the integer 12 (the rule of problem/params.py)
        raise ValueError(f"law parameter {field.name} must be an integer, got {value!r}")
    return int(number)


def make_law(cls, values=None, scene_params=None, option="--friction", notes=None):
    """cls(**fields): the fields from ``values`` (text or numbers), else the law's own default,
    else (a field without a default) the scene parameter of the same name in
    ``scene_params`` (the scene's parameters of this law), noted in ``notes`` (a list: one
    line). Validated by the law's own checks and the protocol, and called once (probe)."""
    values = dict(values or {})
    path = Path(getattr(cls, "_contactfem_file", "")).resolve() if getattr(cls, "_contactfem_file", None) else None
    if not dataclasses.is_dataclass(cls):
        raise ValueError(
            f"{option}: {cls.__name__} is not a dataclass: write the law as @dataclass(frozen=True) "
            "so that its parameters can be set with --set law.NAME=VALUE"
        )
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise ValueError(
            f"unknown law parameter law.{unknown[0]} for {cls.__name__}{did_you_mean(unknown[0], fields)}: known are "
            f"{', '.join(fields) or '(none)'}"
        )
    kwargs, from_scene = {}, []
    for name, f in fields.items():
        if name in values:
            kwargs[name] = _convert(values[name], f)
        elif f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING:
            continue  # the law's own default
        elif scene_params and name in scene_params:
            kwargs[name] = scene_params[name]
            from_scene.append(name)
        else:
            known = f" (the scene's parameters of this law: {', '.join(scene_params)})" if scene_params else ""
            raise ValueError(
                f"law parameter {name} of {cls.__name__} has no default and the scene has no parameter "
                f"{name} for it{known}: give --set law.{name}=VALUE"
            )
    try:
        law = cls(**kwargs)
    except ValueError as err:
        raise ValueError(f"{cls.__name__}: {' '.join(str(err).split())}") from None
    except Exception as err:  # noqa: BLE001
        where = _where(path, err) if path else cls.__name__
        raise ValueError(f"{where}: {_cause(err)}") from None
    probe(law, path, option)
    if from_scene and notes is not None:
        shown = ", ".join(
            f"{k} = {kwargs[k]:g}" if isinstance(kwargs[k], float) else f"{k} = {kwargs[k]}" for k in from_scene
        )
        notes.append(
            f"{option.lstrip('-')} law {cls.__name__}: {shown} from the scene's parameters (fields without "
            "a default; --set law.NAME=VALUE sets them)"
        )
    return law


def probe(law, path=None, option="--friction"):
    """Call the law once with a few values per node (p = 0.5, 1, 2; g_N = -0.005 ... -0.02)
    through the guarded adapter, so that a law failing on arrays, returning the wrong number
    of values or a value no law may return (NaN, Y < 0, t_N > 0), or breaking the protocol
    (no c_T, c_T <= 0, ...) is reported now, naming the file and line. (Its values over the
    range of the scene are checked by the pre-flight, and during the run.)"""
    p = np.array([0.5, 1.0, 2.0])
    try:
        with np.errstate(all="ignore"):
            if option == "--normal":
                NormalLawView(law).traction(-0.01 * p)
            else:
                L = FrictionLaw(law)
                z = L.evolve(L.initial_state(3), p, 0.1 * p, 1.0)[0]
                L.slip_bound(p, 0.1 * p, 0.1 * p, z)
    except Exception as err:  # noqa: BLE001
        where = _where(path, err) if path else type(law).__name__
        cause = str(err) if isinstance(err, LawError) else _cause(err)
        if isinstance(err, LawError) and path is not None:
            # the LawError was raised by the protocol; find the law's own line, if any
            ctx = err.__context__
            if ctx is not None:
                where = _where(path, ctx)
        raise ValueError(f"{where}: {' '.join(cause.split())}") from None


def split_sets(sets):
    """Scene overrides and law fields from a --set dict: 'law.X', 'friction.X', 'normal.X'."""
    scene, laws = {}, {"law": {}, "friction": {}, "normal": {}}
    for key, value in (sets or {}).items():
        head, dot, name = key.partition(".")
        if dot and head in laws:
            laws[head][name] = value
        else:
            scene[key] = value
    return scene, laws


def laws_from_options(friction=None, normal=None, law_sets=None, scene_params=None, notes=None):
    """The friction and normal law objects named by --friction / --normal (load_class), with
    their fields from law_sets (split_sets' second value). ``scene_params``: the scene's
    parameters a field without a default may take, {kind: {name: value}} (or one dict for
    both kinds); ``notes``: a list that gets one line per law that took any. Returns
    {kind: law} for the laws given."""
    law_sets = law_sets or {"law": {}, "friction": {}, "normal": {}}
    specs = {"friction": friction, "normal": normal}
    classes = {k: load_class(s, f"--{k}") for k, s in specs.items() if s is not None}
    fields = {
        k: {f.name for f in dataclasses.fields(c)} if dataclasses.is_dataclass(c) else set() for k, c in classes.items()
    }
    values = {k: dict(law_sets.get(k, {})) for k in KINDS}
    for k in KINDS:
        if values[k] and k not in classes:
            raise ValueError(
                f"--set {k}.{next(iter(values[k]))} needs --{k} (a law file FILE.py:CLASS, a module "
                "path or a shipped law)"
            )
    for name, value in law_sets.get("law", {}).items():
        owners = [k for k in classes if name in fields[k]]
        if not classes:
            raise ValueError(
                f"--set law.{name} needs --friction or --normal (a law file FILE.py:CLASS, a module "
                "path or a shipped law)"
            )
        if len(owners) > 1:
            raise ValueError(
                f"--set law.{name}: both laws have a parameter {name}: write friction.{name} or normal.{name}"
            )
        values[owners[0] if owners else next(iter(classes))][name] = value
    scene_params = scene_params or {}
    per_kind = set(scene_params) <= set(KINDS) and all(isinstance(v, dict) for v in scene_params.values())
    return {
        k: make_law(c, values[k], scene_params.get(k, {}) if per_kind else scene_params, f"--{k}", notes)
        for k, c in classes.items()
    }
