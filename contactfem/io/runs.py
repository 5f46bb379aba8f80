"""Saving and reloading results, so they can be plotted without re-running.

    save_run(results, "ring.json")      # readable JSON; numpy arrays keep dtype and shape
    save_run(results, "ring.npz")       # compact: arrays stored natively, the rest as JSON
    res = load_run("ring.json")         # the same dict back, arrays as numpy arrays

load_run also reads the JSON written by ``contactfem run SCENE --json FILE`` (where
arrays were written as plain lists): there every rectangular list of numbers comes back
as a numpy array (``arrays=False`` keeps lists). Files written by save_run come back
exactly as saved: arrays as arrays, lists as lists.
"""

import json
from pathlib import Path

import numpy as np

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
        if arrays is not None:                     # npz: store natively, reference by key
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
    except ValueError:                             # ragged
        return None
    return a if a.dtype.kind in "biuf" and a.size > 0 else None


def _decode(obj, arrays, to_arrays):
    if isinstance(obj, dict):
        if _TAG in obj:
            ref = obj[_TAG]
            if isinstance(ref, str):
                return arrays[ref]
            return np.array(ref, dtype=np.dtype(obj["dtype"])).reshape(obj["shape"])
        return {k: _decode(v, arrays, to_arrays) for k, v in obj.items()}
    if isinstance(obj, list):
        if to_arrays:
            a = _as_array(obj)
            if a is not None:
                return a
        return [_decode(v, arrays, to_arrays) for v in obj]
    return obj


def save_run(results, path):
    """Write a dict of results to `path` (.json or .npz). Returns the path as a string."""
    path = Path(path)
    if not isinstance(results, dict):
        raise TypeError(f"results must be a dict, got {type(results).__name__}")
    if path.suffix not in (".json", ".npz"):
        raise ValueError(f"parameter path must end in .json or .npz, got {path.name!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix == ".json":
        doc = {"format": FORMAT, "results": _encode(results, "results", None)}
        path.write_text(json.dumps(doc, indent=1, allow_nan=False))
    elif path.suffix == ".npz":
        arrays = {}
        doc = {"format": FORMAT, "results": _encode(results, "results", arrays)}
        np.savez_compressed(path, __json__=np.array(json.dumps(doc, allow_nan=False)), **arrays)
    return str(path)


def load_run(path, arrays=None):
    """Read results written by save_run (or by ``contactfem run --json``). `arrays`: turn
    rectangular lists of numbers into numpy arrays (default: only for files not written
    by save_run)."""
    path = Path(path)
    if path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as z:
            doc = json.loads(str(z["__json__"]))
            stored = {k: z[k] for k in z.files if k != "__json__"}
        return _decode(doc["results"], stored, bool(arrays))
    if path.suffix != ".json":
        raise ValueError(f"parameter path must end in .json or .npz, got {path.name!r}")
    doc = json.loads(path.read_text())
    if isinstance(doc, dict) and doc.get("format") == FORMAT:
        return _decode(doc["results"], {}, bool(arrays))
    return _decode(doc, {}, arrays is None or arrays)


class Recorder:
    """An integrate callback keeping snapshots (t, u, v) every `every` accepted steps:

        rec = Recorder(every=5)
        integrate(stepper, 0.0, u0, v0, n_steps=200, callback=rec)
        rec.t, rec.u            # arrays (n_snap,), (n_snap, ndof)

    Call ``rec(t0, u0, v0)`` once before integrating to keep the initial state too."""

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
