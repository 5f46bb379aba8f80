"""Parameter sweeps: the cartesian product of parameter values, each run a scene,
run in parallel on the local cores through joblib, or on a Dask cluster when a
scheduler address is given (joblib's dask backend). Results land in one table.

    contactfem sweep hertz --set n_el=8,16,32 --set penalty=per_length,per_node --jobs 2 --out hertz.csv
"""

import csv
import itertools
import json

from ..scenes import get_scene, run_scene


def parse_grid(sets):
    """{"n_el": "8,16,32"} -> {"n_el": ["8", "16", "32"]}"""
    grid = {}
    for k, v in sets.items():
        vals = [x.strip() for x in str(v).split(",") if x.strip()]
        if not vals:
            raise ValueError(f"--set {k}= needs at least one value")
        grid[k] = vals
    return grid


def _one(scene, preset, point):
    """One run, reduced to its scalar results (lists and dicts are left out of the table)."""
    try:
        res = run_scene(scene, preset, point)
        row = {k: v for k, v in res.items() if not isinstance(v, (list, dict))}
        row["error"] = ""
    except Exception as exc:   # a failed point is a row of the table, not the end of the sweep
        row = {"error": f"{type(exc).__name__}: {exc}"}
    row.update({f"param.{k}": v for k, v in point.items()})
    return row


def sweep(scene, grid, preset="fast", jobs=1, scheduler=None):
    """Run `scene` at every point of the grid; returns a list of row dicts."""
    sc = get_scene(scene)
    points = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]
    for p in points:               # validate every point before starting anything
        sc.resolve(preset, p)
    from joblib import Parallel, delayed, parallel_config

    tasks = (delayed(_one)(scene, preset, p) for p in points)
    if scheduler:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs dask.distributed: pip install 'dask[distributed]'") from None
        with Client(scheduler), parallel_config(backend="dask"):
            return Parallel()(tasks)
    return Parallel(n_jobs=jobs)(tasks)


def write_table(rows, path):
    """CSV or JSON by the file's extension."""
    if str(path).endswith(".json"):
        with open(path, "w") as fh:
            json.dump(rows, fh, indent=1)
        return
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
