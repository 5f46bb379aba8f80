"""Parameter sweeps: the cartesian product of parameter values, each run a scene,
run in parallel on the local cores (worker processes), or on a Dask cluster when a
scheduler address is given (joblib's dask backend). Results land in one table.

    contactfem sweep hertz --set n_el=8,16,32 --set penalty=per_length,per_node --jobs 2 --out hertz.csv
    contactfem sweep rolling_ring --friction my_law.py:Saturating --set law.mu0=0.1,0.2,0.3

A law's fields are swept like parameters (``law.NAME``, ``friction.NAME``, ``normal.NAME``);
each run builds its laws from the same specification as ``contactfem run`` (law file,
module path or shipped law), so a sweep point equals that run. Every point is validated
(parameters, laws, the laws' check over the scene's range) before any run starts. The
worker processes ignore Ctrl-C: the sweep's own process stops them and says so in one line.
"""

import csv
import itertools
import json
import signal

from ..scenes import check_laws, get_scene, run_scene


def parse_grid(sets):
    """{"n_el": "8,16,32"} -> {"n_el": ["8", "16", "32"]}"""
    grid = {}
    for k, v in sets.items():
        vals = [x.strip() for x in str(v).split(",")]
        if not any(vals):
            raise ValueError(f"--set {k}= needs at least one value")
        if not all(vals):
            raise ValueError(f"--set {k}={v}: an empty value in the list (two commas, or one at an end)")
        grid[k] = vals
    return grid


def build_laws(scene, preset, point, friction=None, normal=None, notes=None):
    """(scene overrides, {kind: law}) of one sweep point, as `contactfem run` builds them."""
    from .lawfile import laws_from_options, load_class, split_sets

    overrides, law_sets = split_sets(point)
    if not (friction or normal or any(law_sets.values())):
        return overrides, {}
    sc = get_scene(scene)
    classes = {k: load_class(s, f"--{k}") for k, s in (("friction", friction), ("normal", normal)) if s}
    check_laws(sc, classes, overrides)
    params = sc.resolve(preset, overrides)
    from_scene = {k: {n: params[n] for n in sc.law_params.get(k, ()) if n in params} for k in classes}
    return overrides, laws_from_options(friction, normal, law_sets, from_scene, notes)


def _one(scene, preset, point, friction=None, normal=None):
    """One run, reduced to its scalar results (lists and dicts are left out of the table; so
    are results that repeat a swept parameter, which has its column param.NAME)."""
    try:
        overrides, laws = build_laws(scene, preset, point, friction, normal)
        res = run_scene(scene, preset, overrides, check=False, **laws)
        row = {k: v for k, v in res.items() if not isinstance(v, (list, dict)) and k not in point}
        row["error"] = ""
    except Exception as exc:   # a failed point is a row of the table, not the end of the sweep
        row = {"error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"}
    row.update({f"param.{k}": v for k, v in point.items()})
    return row


def _call(task):
    return _one(*task)


def _ignore_interrupts():
    """A worker: Ctrl-C is the sweep's to handle; SIGTERM (the sweep stopping it) ends it at once,
    whatever handler the command line gave the process it was forked from."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def sweep(scene, grid, preset="fast", jobs=1, scheduler=None, friction=None, normal=None, check=True,
          force=False):
    """Run `scene` at every point of the grid (parameters and law fields law.NAME, with the
    laws named by ``friction`` / ``normal`` as on the command line); returns a list of row
    dicts. Every point is validated first (ValueError, one line): its parameters, its laws,
    unless ``check`` is False the laws over the range the scene meets, and unless ``force``
    its size against the limits of `contactfem run` (resources.LIMITS), the memory of the runs
    that go at once (``jobs`` of them locally) together."""
    from ..scenes.resources import LIMITS, check_resources, describe

    sc = get_scene(scene)
    points = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]
    largest = None
    for p in points:               # validate every point before starting anything
        overrides, laws = build_laws(scene, preset, p, friction, normal)
        params = sc.resolve(preset, overrides)
        est = check_resources(sc, params, force)
        if est is not None and (largest is None or est["memory_bytes"] > largest["memory_bytes"]):
            largest = est
        if check and laws:
            sc.preflight(params, laws)
    together = 1 if scheduler else min(jobs, len(points))
    if not force and largest is not None and together * largest["memory_bytes"] > LIMITS["memory_bytes"]:
        raise ValueError(f"{sc.name}: {together} runs at once (--jobs {jobs}), the largest needing "
                         f"{describe(largest)}, would need about {together * largest['memory_bytes'] / 1e9:.2g} GB "
                         f"together: above the limit of {LIMITS['memory_bytes'] / 1e9:.2g} GB (lower --jobs, "
                         "or add --force to run it anyway)")
    tasks = [(scene, preset, p, friction, normal) for p in points]
    if scheduler:
        from joblib import Parallel, delayed, parallel_config

        try:
            from dask.distributed import Client
        except ImportError:
            raise ValueError("--scheduler needs dask.distributed: pip install 'dask[distributed]'") from None
        with Client(scheduler), parallel_config(backend="dask"):
            return Parallel()(delayed(_one)(*t) for t in tasks)
    if jobs == 1 or len(tasks) == 1:
        return [_one(*t) for t in tasks]
    return _parallel(tasks, min(jobs, len(tasks)))


def _parallel(tasks, jobs):
    """The tasks on `jobs` worker processes that ignore Ctrl-C from their first moment
    (SIGINT is ignored while they start, a setting a new process keeps), so that an
    interrupt reaches only this process, which stops them: one line, no worker traceback."""
    import multiprocessing

    # fork where there is one: the workers start at once with what is loaded, and its semaphores
    # need no resource tracker (which would warn of them after an interrupt)
    ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        pool = ctx.Pool(jobs, initializer=_ignore_interrupts)
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        result = pool.map_async(_call, tasks, chunksize=1)
        rows = result.get()
        pool.close()
        return rows
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()


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
