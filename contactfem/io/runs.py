"""Saving and reloading results, so they can be plotted without re-running.

    save_run(results, "ring.json")      # readable JSON; numpy arrays keep dtype and shape
    save_run(results, "ring.npz")       # compact: arrays stored natively, the rest as JSON
    res = load_run("ring.json")         # the same dict back, arrays as numpy arrays

load_run also reads the JSON written by ``contactfem run SCENE --json FILE`` (where
arrays were written as plain lists). Whatever the format, every rectangular list of
numbers comes back as a numpy array (``arrays=False`` keeps such lists as lists); ragged
lists stay lists. A file that is not a saved run (truncated, corrupt, another program's)
raises one ValueError saying so; load_run never unpickles anything.

save_run writes to a temporary file beside the target and renames it into place, so an
interrupted save never leaves a half-written file.

``compare_runs(mine, ref)`` says how far two results of one scene are apart: the largest
relative difference over every number both hold (a lecture's own time loop against the
scene's run, a reloaded run against the one saved).

``save_record(record, path)`` saves one record of a march (contactfem.solver.march) with its
SystemState, and ``load_record(path)`` gives it back, every number bit for bit, to go on from:

    save_record(records[k], "step.npz")
    rest = resume(stepper, schedule, load_record("step.npz"))   # the run from k on, as it went
"""

import dataclasses
import json
import os
import secrets
import zipfile
from pathlib import Path

import numpy as np

from .. import lazy
from ..contact.augmented import AugmentedHistory
from ..contact.mortar import Pairs
from ..contact.mortar_contact import MortarHistory
from ..contact.state import ContactHistory
from ..problem.scene import RUN_KEYS  # what describes how a run went: compare_runs leaves it out
from ..solver.estimate import ErrorModel, Slope, StepError
from ..solver.march import Record
from ..solver.newton import NewtonResult
from ..solver.system import Evaluation, SystemState

body_loads = lazy.module("contactfem.bodies.loads")  # loads scikit-fem

FORMAT = "contactfem-run/1"
_TAG = "__ndarray__"


def _encode(obj, where, arrays):
    """Plain JSON values; numpy arrays become {__ndarray__: key} (npz) or tagged lists (json)."""
    if isinstance(obj, dict):
        return {str(k): _encode(v, f"{where}.{k}", arrays) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_encode(v, f"{where}[{i}]", arrays) for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        if obj.dtype == object:
            return _encode(obj.tolist(), where, arrays)
        if arrays is not None:  # npz: store natively, reference by key
            key = f"a{len(arrays)}"
            arrays[key] = obj
            return {_TAG: key}
        if obj.dtype.kind == "f" and not np.all(np.isfinite(obj)):
            raise ValueError(f"result {where} contains NaN or inf: JSON cannot hold it (save as .npz)")
        return {_TAG: obj.tolist(), "dtype": obj.dtype.str, "shape": list(obj.shape)}
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        raise ValueError(f"result {where} = {obj} is not finite: JSON cannot hold it")
    if obj is None or isinstance(obj, (bool, int, float, str)):
        return obj
    raise TypeError(f"result {where} has type {type(obj).__name__}: save numbers, strings, lists, dicts, arrays")


def _as_array(lst):
    """A rectangular list of numbers as an ndarray, else None."""
    try:
        a = np.array(lst)
    except (ValueError, TypeError, OverflowError):  # ragged, or not numbers
        return None
    return a if a.dtype.kind in "biuf" and a.size > 0 else None


def as_arrays(obj):
    """Every rectangular list of numbers in a nested dict/list as a numpy array (what
    ``contactfem run --save`` stores, so that .npz files hold arrays natively)."""
    if isinstance(obj, dict):
        return {k: as_arrays(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        a = _as_array(obj)
        return a if a is not None else [as_arrays(v) for v in obj]
    return obj


class _Foreign(Exception):
    """Raised inside load_run for a file that is not a saved run; turned into ValueError."""


_DTYPE_KINDS = "biufcU"  # numbers, booleans and text: never Python objects


def _tagged(obj, arrays):
    ref = obj[_TAG]
    if isinstance(ref, str):
        if ref not in arrays:
            raise _Foreign(f"array {ref!r} is missing")
        return arrays[ref]
    try:
        dtype = np.dtype(obj["dtype"])
        if dtype.kind not in _DTYPE_KINDS:
            raise _Foreign(f"an array has dtype {obj['dtype']!r}")
        shape = tuple(int(n) for n in obj["shape"])
        return np.array(ref, dtype=dtype).reshape(shape)
    except (KeyError, TypeError, ValueError, OverflowError) as err:
        raise _Foreign(f"a malformed array ({_one_line(err)})") from None


def _decode(obj, arrays, to_arrays):
    if isinstance(obj, dict):
        if _TAG in obj:
            return _tagged(obj, arrays)
        return {k: _decode(v, arrays, to_arrays) for k, v in obj.items()}
    if isinstance(obj, list):
        if to_arrays:
            a = _as_array(obj)
            if a is not None:
                return a
        return [_decode(v, arrays, to_arrays) for v in obj]
    return obj


def _one_line(err):
    text = " ".join(str(err).split()) or type(err).__name__
    if "pickle" in text.lower():  # numpy's advice to allow pickles is unsafe: never pass it on
        text = "it holds Python objects (pickled data), which load_run does not read"
    return text[:200]


def save_run(results, path):
    """Write a dict of results to `path` (.json or .npz). Returns the path as a string."""
    path = Path(path)
    if not isinstance(results, dict):
        raise TypeError(f"results must be a dict, got {type(results).__name__}")
    if path.suffix not in (".json", ".npz"):
        raise ValueError(f"parameter path must end in .json or .npz, got {path.name!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.{secrets.token_hex(4)}.part{path.suffix}")
    try:
        if path.suffix == ".json":
            doc = {"format": FORMAT, "results": _encode(results, "results", None)}
            tmp.write_text(json.dumps(doc, indent=1, allow_nan=False))
        else:
            arrays = {}
            doc = {"format": FORMAT, "results": _encode(results, "results", arrays)}
            np.savez_compressed(tmp, __json__=np.array(json.dumps(doc, allow_nan=False)), **arrays)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return str(path)


def load_run(path, arrays=True):
    """Read results written by save_run or by ``contactfem run --json/--save``.

    Rectangular lists of numbers come back as numpy arrays (``arrays=False`` keeps them as
    lists). Raises FileNotFoundError for a missing file and ValueError, one line, for any
    file that is not a saved run (truncated, corrupt, written by something else)."""
    path = Path(path)
    if path.suffix not in (".json", ".npz"):
        raise ValueError(f"parameter path must end in .json or .npz, got {path.name!r}")
    if not path.exists():
        raise FileNotFoundError(f"no such file: {path}")
    try:
        return _load(path, bool(arrays))
    except _Foreign as err:
        raise ValueError(f"{path} is not a saved contactfem run: {err}") from None
    except PermissionError:
        raise
    except Exception as err:  # a damaged file fails anywhere inside zipfile, zlib, numpy or json
        raise ValueError(f"{path} is not a readable contactfem run (corrupt or truncated?): {_one_line(err)}") from None


def _load(path, to_arrays):
    if path.suffix == ".npz":
        if not zipfile.is_zipfile(path):
            raise _Foreign("it is not a zip archive, as every .npz file is (truncated, or another kind of file)")
        with np.load(path, allow_pickle=False) as z:
            if "__json__" not in z.files:
                raise _Foreign("the .npz file has no __json__ entry (written by something other than save_run)")
            doc = json.loads(str(z["__json__"]))
            stored = {k: z[k] for k in z.files if k != "__json__"}
        for k, a in stored.items():
            if a.dtype.kind not in _DTYPE_KINDS:
                raise _Foreign(f"array {k!r} has dtype {a.dtype}")
    else:
        doc = json.loads(path.read_text())
        stored = {}
    if not isinstance(doc, dict):
        raise _Foreign(f"the top level is a {type(doc).__name__}, not an object")
    if "format" in doc:
        if doc["format"] != FORMAT:
            raise _Foreign(f"format {doc['format']!r}, expected {FORMAT!r}")
        if not isinstance(doc.get("results"), dict):
            raise _Foreign("it has no results")
        return _decode(doc["results"], stored, to_arrays)
    if path.suffix == ".json" and "scene" in doc:  # written by `contactfem run --json`
        return _decode(doc, stored, to_arrays)
    raise _Foreign("it has neither a 'format' (save_run) nor a 'scene' (contactfem run --json) entry")


class Recorder:
    """Keeps snapshots (t, u, v) of every `every`-th call, e.g. of the records of a march:

    rec = Recorder(every=5)
    for r in march(stepper, Steps(dt, n_steps=200), 0.0, u0, v0):
        rec(r.t, r.u, r.v)
    rec.t, rec.u            # arrays (n_snap,), (n_snap, ndof)
    """

    def __init__(self, every=1):
        if int(every) != every or every < 1:
            raise ValueError(f"parameter every must be an integer >= 1, got {every!r}")
        self.every, self.count = int(every), 0
        self._t, self._u, self._v = [], [], []

    def __call__(self, t, u, v=None, a=None):
        if self.count % self.every == 0:
            self._t.append(float(t))
            self._u.append(np.array(u, dtype=float))
            self._v.append(None if v is None else np.array(v, dtype=float))
        self.count += 1

    @property
    def t(self):
        return np.array(self._t)

    @property
    def u(self):
        return np.array(self._u)

    @property
    def v(self):
        return np.array([np.zeros_like(u) if v is None else v for u, v in zip(self._u, self._v)])

    def as_dict(self):
        """{'t': ..., 'u': ..., 'v': ...}, ready for save_run."""
        return {"t": self.t, "u": self.u, "v": self.v}


def compare_runs(mine, ref, skip=RUN_KEYS):
    """How far two results of a scene are apart: walks every entry of ``ref`` that ``mine``
    also holds (nested dicts and lists included; None and the entries ``skip`` names are
    left out, text must be equal) and returns dict(worst=the largest relative difference, key=where it is,
    compared=how many numbers were compared, missing=entries of ref that mine lacks). An
    entry's difference is max |a - b| / max |b| over the entry (an array is scaled by its
    largest value, a zero reference needs an exact zero); entries of different shape count
    as an infinite difference."""
    worst, where, count, missing = 0.0, None, 0, []

    def walk(a, b, key):
        nonlocal worst, where, count
        if isinstance(b, dict):
            if not isinstance(a, dict):
                return note(np.inf, key)
            for k, v in b.items():
                if k in skip and not key:
                    continue
                if k not in a:
                    missing.append(f"{key}{k}")
                    continue
                walk(a[k], v, f"{key}{k}.")
            return None
        if b is None:
            return None
        if isinstance(b, str):  # text (a node's state): equal or not
            return note(0.0 if a == b else np.inf, key)
        if (
            isinstance(b, (list, tuple))
            and b
            and any(isinstance(x, (dict, list, tuple, str)) or x is None for x in b)
            and not _rectangular(b)
        ):
            if not isinstance(a, (list, tuple)) or len(a) != len(b):
                return note(np.inf, key)
            for i, (x, y) in enumerate(zip(a, b)):
                walk(x, y, f"{key.rstrip('.')}[{i}].")
            return None
        try:
            A, B = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        except (TypeError, ValueError):
            return None
        if A.size == 0 and B.size == 0:  # nothing in either ([] and an empty (0, 2) array)
            return None
        if A.shape != B.shape:
            return note(np.inf, key)
        count += B.size
        scale = float(np.max(np.abs(B)))
        diff = float(np.max(np.abs(A - B)))
        return note(diff / scale if scale > 0 else (0.0 if diff == 0 else np.inf), key)

    def note(d, key):
        nonlocal worst, where
        if d > worst or where is None and d == worst:
            worst, where = d, key.rstrip(".")
        return None

    walk(mine, ref, "")
    return dict(worst=float(worst), key=where, compared=count, missing=missing)


def _rectangular(lst):
    try:
        a = np.asarray(lst, dtype=float)
    except (TypeError, ValueError):
        return False
    return a.dtype.kind == "f"


# -- one record of a march, to resume from -----------------------------------------------------

_STATE = "__state__"


def _state_types():
    """The value types a SystemState may hold, by name (load_record builds only these)."""
    types = (SystemState, ContactHistory, AugmentedHistory, MortarHistory, Pairs, body_loads.GasState, Slope)
    return {t.__name__: t for t in types}


def _state_to_plain(obj, where, types):
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        name = type(obj).__name__
        if types.get(name) is not type(obj):
            raise TypeError(f"record state {where} is a {name}, which save_record cannot save")
        return {
            _STATE: name,
            **{
                f.name: _state_to_plain(getattr(obj, f.name), f"{where}.{f.name}", types)
                for f in dataclasses.fields(obj)
            },
        }
    if isinstance(obj, tuple):
        return {_STATE: "tuple", "items": [_state_to_plain(v, f"{where}[{i}]", types) for i, v in enumerate(obj)]}
    return obj


def _state_from_plain(obj, types):
    if isinstance(obj, dict) and _STATE in obj:
        name = obj[_STATE]
        if name == "tuple":
            return tuple(_state_from_plain(v, types) for v in obj["items"])
        if name not in types:
            raise ValueError(f"a saved record holds a state of type {name!r}, which load_record does not build")
        return types[name](**{k: _state_from_plain(v, types) for k, v in obj.items() if k != _STATE})
    return obj


def save_record(record, path):
    """Write one record of a march (k, t, dt, u, v, a, energies, Newton's residuals, the
    reactions and loads the next step's work needs, its SystemState, its step's local error and
    share, its stage) to `path` (.json or .npz, as save_run). Returns the path as a string."""
    ev, result = record.evaluation, record.result
    G = result.G if result is not None else ev.G  # the prescribed-dof part: the reactions
    doc = dict(
        k=int(record.k),
        t=float(record.t),
        dt=float(record.dt),
        u=record.u,
        v=record.v,
        a=record.a,
        energy={k: float(v) for k, v in record.energy.items()},
        cuts=int(record.cuts),
        failures=list(record.failures),
        G=np.asarray(G),
        P=np.asarray(ev.P) if ev.P is not None else None,
        iterations=int(record.iterations),
        residuals=[float(r) for r in record.residuals],
        state=_state_to_plain(record.state, "state", _state_types()),
        # a run at a tolerance sizes its next step from these (solver/schedule.py)
        local_error=None if record.error is None else record.error.local,
        error_share=None if record.error is None else record.error.share,
        error_model=None if record.error is None else [record.error.model.delta, record.error.model.beta],
        stage=int(record.stage),
    )
    return save_run({"record": doc}, path)


def load_record(path):
    """The record save_record wrote, to resume a march from (contactfem.solver.march.resume):
    its numbers bit for bit, its SystemState, the residual and loads of its evaluation (no
    tangent, no contact states: those of the steps after it are recomputed)."""
    doc = load_run(path, arrays=False)
    if "record" not in doc:
        raise ValueError(f"{path} is a saved run, not a saved record (save_record)")
    r = doc["record"]
    state = _state_from_plain(r["state"], _state_types())
    ev = Evaluation(G=r["G"], K=None, contacts=(), P=r["P"], state=state)
    result = (
        NewtonResult(
            u=r["u"],
            residuals=list(r["residuals"]),
            iterations=int(r["iterations"]),
            G=r["G"],
            evaluation=ev,
        )
        if r["k"] > 0
        else None
    )
    model = r.get("error_model")
    error = (
        None
        if r.get("local_error") is None
        else StepError(r["local_error"], r.get("error_share"), None if model is None else ErrorModel(*model))
    )
    return Record(
        k=int(r["k"]),
        t=float(r["t"]),
        dt=float(r["dt"]),
        u=r["u"],
        v=r["v"],
        a=r["a"],
        evaluation=ev,
        energy=dict(r["energy"]),
        result=result,
        cuts=int(r["cuts"]),
        failures=tuple(r["failures"]),
        state=state,
        error=error,
        stage=int(r.get("stage", 0)),
    )
