"""A law from a Python file, for the command line:

    contactfem run SCENE --friction my_law.py:Saturating --set law.mu0=0.6
    contactfem run SCENE --normal my_normal.py:Hyperbolic --set law.c_N=20

The file is a module defining the law class (a frozen dataclass, as the shipped laws).
Its fields are set like scene parameters: ``law.NAME=VALUE`` (or ``friction.NAME`` /
``normal.NAME`` when both laws have a field of that name); a field not set takes the
scene parameter of the same name (c_T, mu, c_N, m, ...), else the dataclass default.
Values are converted to the field's type and validated by the law itself
(``__post_init__``), so a bad value gives the same one-line error as a scene parameter.

Any error in the file (syntax, import, a name that does not exist, a law that fails on
arrays, returns the wrong number of values, ...) is one ValueError line naming the
file, the line and the cause. ``describe`` gives the JSON record of a law: class, file
and fields.
"""

import dataclasses
import importlib.util
import itertools
import sys
import traceback
from pathlib import Path

import numpy as np

from ..laws.protocol import FrictionLaw, LawError, describe  # noqa: F401 (describe: public here too)

KINDS = ("friction", "normal")
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
    """The class named by 'FILE.py:CLASS' (ValueError with one line naming file, line, cause)."""
    if not isinstance(spec, str) or ":" not in spec:
        raise ValueError(f"{option} expects FILE.py:CLASS, got {spec!r}")
    file, _, name = spec.rpartition(":")
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
    sys.modules[mod_name] = module                     # dataclasses look the module up
    try:
        mspec.loader.exec_module(module)
    except Exception as err:                          # noqa: BLE001 (anything in the user's file)
        sys.modules.pop(mod_name, None)
        raise ValueError(f"{_where(path, err)}: {_cause(err)}") from None
    cls = getattr(module, name, None)
    if cls is None or not isinstance(cls, type):
        found = sorted(k for k, v in vars(module).items() if isinstance(v, type) and v.__module__ == mod_name)
        raise ValueError(f"law file {path.name} has no class {name}" + (f" (it defines: {', '.join(found)})" if found else ""))
    cls._contactfem_file = str(file)
    return cls


def _convert(value, field):
    """A --set text to the field's type (float unless the annotation says otherwise)."""
    if not isinstance(value, str):
        return value
    t = field.type if isinstance(field.type, type) else {"int": int, "bool": bool, "str": str}.get(str(field.type), float)
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
        return int(value) if t is int else float(value)
    except ValueError:
        raise ValueError(f"law parameter {field.name} must be a number, got {value!r}") from None


def make_law(cls, values=None, scene_params=None, option="--friction"):
    """cls(**fields): the fields from ``values`` (text or numbers), else the scene parameter
    of the same name, else the dataclass default. Validated by the law's own checks."""
    values = dict(values or {})
    path = Path(getattr(cls, "_contactfem_file", "")).resolve() if getattr(cls, "_contactfem_file", None) else None
    if not dataclasses.is_dataclass(cls):
        raise ValueError(f"{option}: {cls.__name__} is not a dataclass: write the law as @dataclass(frozen=True) "
                         "so that its parameters can be set with --set law.NAME=VALUE")
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise ValueError(f"unknown law parameter law.{unknown[0]} for {cls.__name__}: known are {', '.join(fields) or '(none)'}")
    kwargs = {}
    for name, f in fields.items():
        if name in values:
            kwargs[name] = _convert(values[name], f)
        elif scene_params and name in scene_params:
            kwargs[name] = scene_params[name]
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ValueError(f"law parameter {name} of {cls.__name__} has no default and the scene has no parameter "
                             f"{name}: give --set law.{name}=VALUE")
    try:
        law = cls(**kwargs)
    except ValueError as err:
        raise ValueError(f"{cls.__name__}: {err}") from None
    except Exception as err:                          # noqa: BLE001
        where = _where(path, err) if path else cls.__name__
        raise ValueError(f"{where}: {_cause(err)}") from None
    probe(law, path, option)
    return law


def probe(law, path=None, option="--friction"):
    """Call the law once with a few values per node, so that a law failing on arrays or
    returning the wrong number of values is reported now, naming the file and line."""
    p = np.array([0.5, 1.0, 2.0])
    try:
        if option == "--normal":
            if not hasattr(law, "traction"):
                raise LawError(f"{type(law).__name__} has no method traction(g_N): a normal law needs one")
            out = law.traction(-0.01 * p)
            if not (isinstance(out, (tuple, list)) and len(out) == 2):
                raise LawError(f"{type(law).__name__}.traction(g_N) must return the two values (t_N, dt_N/dg_N)")
        else:
            L = FrictionLaw(law)
            z = L.evolve(L.initial_state(3), p, 0.1 * p, 1.0)[0]
            L.slip_bound(p, 0.1 * p, 0.1 * p, z)
    except Exception as err:                          # noqa: BLE001
        where = _where(path, err) if path else type(law).__name__
        cause = str(err) if isinstance(err, LawError) else _cause(err)
        if isinstance(err, LawError) and path is not None:
            # the LawError was raised by the protocol; find the law's own line, if any
            ctx = err.__context__
            if ctx is not None:
                where = _where(path, ctx)
        raise ValueError(f"{where}: {cause}") from None


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


def laws_from_options(friction=None, normal=None, law_sets=None, scene_params=None):
    """The friction and normal law objects named by --friction / --normal FILE:CLASS, with
    their fields from law_sets (split_sets' second value). Returns {kind: law} for the
    laws given."""
    law_sets = law_sets or {"law": {}, "friction": {}, "normal": {}}
    specs = {"friction": friction, "normal": normal}
    classes = {k: load_class(s, f"--{k}") for k, s in specs.items() if s}
    fields = {k: {f.name for f in dataclasses.fields(c)} if dataclasses.is_dataclass(c) else set()
              for k, c in classes.items()}
    values = {k: dict(law_sets.get(k, {})) for k in KINDS}
    for k in KINDS:
        if values[k] and k not in classes:
            raise ValueError(f"--set {k}.{next(iter(values[k]))} needs --{k} FILE:CLASS")
    for name, value in law_sets.get("law", {}).items():
        owners = [k for k in classes if name in fields[k]]
        if not classes:
            raise ValueError(f"--set law.{name} needs --friction FILE:CLASS or --normal FILE:CLASS")
        if len(owners) > 1:
            raise ValueError(f"--set law.{name}: both laws have a parameter {name}: write friction.{name} or normal.{name}")
        values[owners[0] if owners else next(iter(classes))][name] = value
    return {k: make_law(c, values[k], scene_params, f"--{k}") for k, c in classes.items()}
