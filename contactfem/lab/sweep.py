"""Parameter sweeps: the cartesian product of parameter values, each run a scene, run in
worker processes on the local cores (``lab.batch``) or on a Dask cluster when a scheduler
address is given. Results land in one table, written as each point ends.

    contactfem sweep hertz --set n_el=8,16,32 --set penalty=per_length,per_node --jobs 2 --out hertz.csv
    contactfem sweep rolling_ring --friction my_law.py:Saturating --set law.mu0=0.1,0.2,0.3

A law's fields are swept like parameters (``law.NAME``, ``friction.NAME``, ``normal.NAME``);
each run builds its laws from the same specification as ``contactfem run`` (law file,
module path or shipped law), so a sweep point equals that run. Every point is validated
(parameters, laws, the laws' check over the scene's range) before any run starts.

Each row says how accurate its run is: ``accuracy.flags`` (the indicators past their
thresholds, by name), ``accuracy.NAME`` (each indicator's value), the error bars of the
headline quantities where the run carries them (its ``uncertainty`` section: ``band.NAME``,
``relative_band.NAME``, ... for each field of a quantity's entry), and ``warnings`` (the run's
accuracy warnings, in short). A flagged point is one warning (``AccuracyWarning``) naming the
point, as it ends.

Every run is a task of a worker process, also with one job: a worker that dies (killed by
the out-of-memory killer, or ended by a law calling ``os._exit``) is replaced and its point
run once more, then recorded as failed with the reason ("worker died: signal 9", "worker
exited with code 7"); the other points go on. The workers ignore Ctrl-C: the sweep's own
process stops them. On a Dask cluster, the scheduler runs the task of a lost worker again
and gives up on a point whose runs keep killing their workers (KilledWorker: a failed row).

The table on disk (``Table``) is rewritten after every point (a temporary in the same
folder, renamed onto it), so it is always a complete table of the points done. Each row
says which code made it (``code_version``: contactfem's version and a digest of the sources
a run uses, the library's and the law files'); ``resume`` skips the points whose row has
no error and was made by the same scene, preset, laws and code.
"""

import asyncio
import csv
import hashlib
import inspect
import itertools
import json
import os
import secrets
import socket
import warnings
from contextlib import closing
from pathlib import Path

from .. import __version__, lazy
from ..io.outputs import hold_interrupts, make_parents
from ..problem.accuracy import AccuracyWarning
from ..problem.resources import LIMITS, check_resources, describe
from ..scenes import check_laws, get_scene, is_scene_file, run_scene
from .lawfile import laws_from_options, load_class, split_sets

batch = lazy.module("contactfem.lab.batch")  # its worker pool, loaded when a sweep runs


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
    overrides, law_sets = split_sets(point)
    if friction is None and normal is None and not any(law_sets.values()):
        return overrides, {}
    sc = get_scene(scene)
    classes = {k: load_class(s, f"--{k}") for k, s in (("friction", friction), ("normal", normal)) if s}
    check_laws(sc, classes, overrides)
    params = sc.resolve(preset, overrides)
    from_scene = {k: {n: params[n] for n in sc.law_params.get(k, ()) if n in params} for k in classes}
    return overrides, laws_from_options(friction, normal, law_sets, from_scene, notes)


def _one(scene, preset, point, friction=None, normal=None, error_bars=None, tolerance=None):
    """One run, reduced to its scalar results (lists and dicts are left out of the table; so
    are results that repeat a swept parameter, which has its column param.NAME), its accuracy
    (accuracy_columns) and its accuracy warnings (``warnings``: their first clauses, joined by
    "; "); the run's other warnings (numpy's, libraries') are dropped, as `contactfem run` drops them.
    ``error_bars``, ``tolerance``: as for run_scene."""
    try:
        overrides, laws = build_laws(scene, preset, point, friction, normal)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = run_scene(scene, preset, overrides, check=False, error_bars=error_bars, tolerance=tolerance, **laws)
        row = {k: v for k, v in res.items() if not isinstance(v, (list, dict)) and k not in point}
        row.update(accuracy_columns(res))
        said = [str(w.message).split(" (")[0] for w in caught if issubclass(w.category, AccuracyWarning)]
        row["warnings"] = "; ".join(dict.fromkeys(s.removeprefix("accuracy: ") for s in said))
        row["error"] = ""
    except Exception as exc:  # a failed point is a row of the table, not the end of the sweep
        row = {"error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"}
    row.update({f"param.{k}": v for k, v in point.items()})
    return row


def accuracy_columns(res):
    """A run's accuracy as columns of its row: ``accuracy.flags``, the names of the indicators past
    their thresholds (space-separated; empty: none), ``accuracy.NAME``, each indicator's value, and,
    where the results carry an ``uncertainty`` section, ``FIELD.NAME`` for every number or text of a
    quantity's entry but its value (which is the quantity's own column) and its parts by discretisation:
    ``band.NAME``, ``relative_band.NAME``, ``observed_order.NAME``, ..."""
    accuracy = {k: v for k, v in (res.get("accuracy") or {}).items() if isinstance(v, dict) and "value" in v}
    cols = {"accuracy.flags": " ".join(k for k, ind in accuracy.items() if not ind.get("ok", True))}
    cols.update({f"accuracy.{k}": ind["value"] for k, ind in accuracy.items()})
    for name, entry in ((res.get("uncertainty") or {}).get("quantities") or {}).items():
        cols.update({f"{field}.{name}": v for field, v in entry.items() if field != "value" and _scalar(v)})
    return cols


def _scalar(v):
    return v is None or isinstance(v, (str, bool, int, float))


def flagged(row):
    """Whether a row's run is flagged: an accuracy indicator past its threshold, or an accuracy
    warning (the error bars'); False for a failed row and for rows of tables without the columns."""
    return not row.get("error") and bool(row.get("accuracy.flags") or row.get("warnings"))


def point_text(point):
    """'c_N=10, nx=12': a point as the summary and the warnings name it."""
    return ", ".join(f"{k}={v}" for k, v in point.items())


def laws_text(friction=None, normal=None):
    """The laws of a sweep as its table's column ``laws`` records them."""
    return " ".join(f"--{k} {v}" for k, v in (("friction", friction), ("normal", normal)) if v)


LIBRARY = ("clock.py", "laws", "contact", "bodies", "solver", "scenes")  # the sources a run uses


def code_version(friction=None, normal=None, scene=None):
    """'0.1.0+1a2b3c4d5e6f': contactfem's version and a digest of the sources a run uses (the
    library below the lab, the files of the laws named by ``friction`` / ``normal``, and the
    scene file where ``scene`` is one)."""
    root = Path(__file__).parents[1]  # the package
    h = hashlib.sha256()
    for rel in LIBRARY:
        files = sorted((root / rel).rglob("*.py")) if (root / rel).is_dir() else [root / rel]
        for f in files:
            h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes())
    for kind, spec in (("friction", friction), ("normal", normal)):
        if spec:
            try:
                h.update(Path(inspect.getfile(load_class(spec, f"--{kind}"))).read_bytes())
            except (TypeError, OSError):
                h.update(spec.encode())
    if is_scene_file(scene):
        h.update(Path(scene).expanduser().read_bytes())
    return f"{__version__}+{h.hexdigest()[:12]}"


def plan(scene, grid, preset="fast", jobs=1, scheduler=None, friction=None, normal=None, check=True, force=False):
    """The points of the grid (dicts NAME -> value), every one validated (ValueError, one line):
    its parameters, its laws, unless ``check`` is False the laws over the range the scene meets,
    and unless ``force`` its size against the limits of `contactfem run` (resources.LIMITS),
    the memory of the runs that go at once (``jobs`` of them locally) together; and the
    warnings of the laws' check (a derivative that disagrees with finite differences), each
    finding once (with the numbers of the first point that shows it)."""
    sc = get_scene(scene)
    points = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]
    largest, notes = None, []
    for p in points:  # validate every point before starting anything
        overrides, laws = build_laws(scene, preset, p, friction, normal)
        params = sc.resolve(preset, overrides)
        est = check_resources(sc, params, force)
        if est is not None and (largest is None or est["memory_bytes"] > largest["memory_bytes"]):
            largest = est
        if check and laws:
            notes += sc.preflight(params, laws)
    together = 1 if scheduler else min(jobs, len(points))
    if not force and largest is not None and together * largest["memory_bytes"] > LIMITS["memory_bytes"]:
        raise ValueError(
            f"{sc.name}: {together} runs at once (--jobs {jobs}), the largest needing "
            f"{describe(largest)}, would need about {together * largest['memory_bytes'] / 1e9:.2g} GB "
            f"together: above the limit of {LIMITS['memory_bytes'] / 1e9:.2g} GB (lower --jobs, "
            "or add --force to run it anyway)"
        )
    found = {}  # each finding once, with the numbers of the first point that shows it
    for note in notes:
        found.setdefault(note.split(": worst")[0], note)
    return points, list(found.values())


def sweep(
    scene,
    grid,
    preset="fast",
    jobs=1,
    scheduler=None,
    friction=None,
    normal=None,
    check=True,
    force=False,
    table=None,
    timeout=None,
    error_bars=None,
    tolerance=None,
):
    """Run `scene` at every point of the grid (parameters and law fields law.NAME, with the
    laws named by ``friction`` / ``normal`` as on the command line); returns the list of row
    dicts, in the grid's order. Every point is validated first (``plan``). ``table``: a Table
    that keeps the rows (on disk if it has a path, written as each point ends, and with
    ``resume`` the rows it already holds); ``timeout``: seconds a local run may take before it
    is stopped and recorded as failed. ``error_bars``, ``tolerance``: every run's, as for run_scene
    (each row's ``uncertainty`` section is a plain dict of the run's results). The laws' check warns
    (UserWarning) before the first run; each flagged point (``flagged``) warns as it ends
    (AccuracyWarning, naming the point)."""
    args = (scene, grid, preset, jobs, scheduler, friction, normal, check, force)
    (points, notes), version = (
        _guarded(_prepare, args, laws_text(friction, normal))
        if friction is not None or normal is not None
        else _prepare(*args)
    )
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    table = Table() if table is None else table
    same = dict(scene=get_scene(scene).name, preset=preset, laws=laws_text(friction, normal), code_version=version)
    todo = table.start(points, same)
    tasks = [(i, (scene, preset, points[i], friction, normal, error_bars, tolerance)) for i in todo]
    runs = _on_dask(scheduler, tasks) if scheduler else _local(tasks, jobs, timeout)
    with closing(runs):  # an exception here (Ctrl-C, SIGTERM) stops the workers at once
        for i, row in runs:
            table.add(i, row)
            if flagged(row):
                said = row["warnings"] or f"past their thresholds: {row['accuracy.flags']}"
                warnings.warn(f"accuracy: point {point_text(points[i])}: {said}", AccuracyWarning, stacklevel=2)
    return table.grid_rows()


def _prepare(scene, grid, preset, jobs, scheduler, friction, normal, check, force):
    return plan(scene, grid, preset, jobs, scheduler, friction, normal, check, force), code_version(
        friction, normal, scene
    )


def _guarded(fn, args, laws):
    """fn(*args) in a worker process (it loads and checks the user's laws): its value, or its
    exception raised here; a worker that dies is one ValueError naming the laws."""
    (outcome,) = batch.run_batch(_capture, [(None, (fn, *args))], retries=0)
    if not outcome.ok:
        raise ValueError(
            f"{laws}: the law's code ended the process that loaded and checked it ({outcome.reason}); "
            "with --no-check its check over the scene's range is skipped"
        )
    ok, value = outcome.value
    if not ok:
        raise value
    return value


def _capture(fn, *args):
    try:
        return True, fn(*args)
    except Exception as exc:  # raised again in the sweep's process
        return False, exc


def _local(tasks, jobs, timeout):
    """(index, row) of each task as it ends, on `jobs` worker processes."""
    if not tasks:
        return
    with closing(batch.run_batch(_one, tasks, jobs=min(jobs, len(tasks)), timeout=timeout)) as outcomes:
        for o in outcomes:
            yield o.key, o.value if o.ok else {"error": o.reason}


def _on_dask(scheduler, tasks):
    """(index, row) of each task as it ends, on the Dask cluster at `scheduler`."""
    try:
        from dask.distributed import as_completed  # optional extra (cluster): may be absent
    except ImportError:
        raise ValueError("--scheduler needs dask.distributed: pip install 'dask[distributed]'") from None
    client = connect(scheduler)
    try:
        futures = {client.submit(_one, *args, pure=False): i for i, args in tasks}
        for fut in as_completed(futures, loop=client.loop):
            if fut.status == "finished":
                yield futures[fut], fut.result()
                continue
            exc = fut.exception() if fut.status == "error" else None
            if exc is None:
                reason = f"error: the Dask task ended {fut.status}"
            elif type(exc).__name__ == "KilledWorker":
                reason = "worker died: every Dask worker that ran it died (KilledWorker)"
            else:
                reason = f"error: {type(exc).__name__}: {' '.join(str(exc).split())}"
            yield futures[fut], {"error": reason}
    finally:
        client.close()


def connect(address, timeout=10):
    """A dask.distributed Client of the scheduler at `address`, or one ValueError naming
    --scheduler and the address, at once if nothing listens there (a TCP address is asked for
    its identity before a Client is made)."""
    from dask.distributed import Client  # optional extra (cluster): the caller said --scheduler
    from distributed.comm import parse_address, parse_host_port  # optional extra (cluster)

    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as err:
        raise ValueError(
            f"--scheduler {address}: not the address of a Dask scheduler, such as tcp://HOST:8786 ({_short(err)})"
        ) from None
    if host is not None:
        try:
            socket.create_connection((host, port), timeout=timeout).close()
            ident = asyncio.run(_identity(address, timeout))
        except OSError as err:
            raise ValueError(
                f"--scheduler {address}: no Dask scheduler answers at {host}:{port} ({err.strerror or _short(err)})"
            ) from None
        except Exception as err:  # noqa: BLE001 (whatever listens there, its answer)
            raise ValueError(
                f"--scheduler {address}: what answers there is not a Dask scheduler "
                f"({type(err).__name__}: {_short(err)[:120]})"
            ) from None
        if not isinstance(ident, dict) or ident.get("type") != "Scheduler":
            raise ValueError(f"--scheduler {address}: what answers there is not a Dask scheduler")
    try:
        return Client(address, timeout=timeout, set_as_default=False)
    except Exception as err:  # noqa: BLE001
        raise ValueError(
            f"--scheduler {address}: no Dask scheduler answers there ({type(err).__name__}: {_short(err)[:120]})"
        ) from None


async def _identity(address, timeout):
    from distributed.comm import connect as open_comm  # optional extra (cluster)

    comm = await open_comm(address, timeout=timeout)
    try:
        await asyncio.wait_for(comm.write({"op": "identity", "reply": True}), timeout)
        return await asyncio.wait_for(comm.read(), timeout)
    finally:
        comm.abort()


def _short(err):
    return " ".join(str(err).split()) or type(err).__name__


class Table:
    """A sweep's table: the rows of its points (and, resumed, the rows its file held), on
    disk at ``path`` (.csv or .json) rewritten after every point, in memory if path is None.

    The file always holds a complete table: the rows of the grid's points done so far in the
    grid's order, then the rows of other points the file held before. ``resume``: the rows
    of the file are read first; a point whose row has no error and the same scene, preset,
    laws and code version is not run again; a row of a point that runs again is replaced
    when its new row comes. ``written``: (done, failed, left) as on disk, None until this
    sweep has written the file."""

    def __init__(self, path=None, resume=False):
        self.path = Path(path) if path is not None else None
        self.earlier = read_table(self.path) if resume and self.path is not None and self.path.exists() else []
        self.points = []
        self.rows = {}  # grid index -> row of this sweep (or kept from the file)
        self.stale = {}  # grid index -> the file's row of that point, until its new row comes
        self.others = []  # the file's rows of points outside this grid
        self.kept = 0  # points not run again (resume)
        self.same = {}
        self.written = None

    def start(self, points, same):
        """The indices of the points to run; ``same``: the columns a kept row must match."""
        self.points, self.same = list(points), dict(same)
        index = {_key({f"param.{k}": v for k, v in p.items()}): i for i, p in enumerate(self.points)}
        for row in self.earlier:
            i = index.get(_key(row))
            if i is None:
                self.others.append(row)
            elif (
                i not in self.rows
                and not row.get("error")
                and all(str(row.get(k, "")) == str(v) for k, v in self.same.items())
            ):
                self.rows[i] = row
            else:
                self.stale.setdefault(i, row)
        self.kept = len(self.rows)
        return [i for i in range(len(self.points)) if i not in self.rows]

    def add(self, i, row):
        """The row of point i: its parameters and the sweep's columns added; then written."""
        row = dict(row)
        row.setdefault("error", "")
        row.update({f"param.{k}": v for k, v in self.points[i].items()})
        for k, v in self.same.items():
            row.setdefault(k, v)
        self.rows[i] = row
        self.write()

    def counts(self, strict=False):
        """(done, failed, left) of the grid's points; ``strict``: flagged points count as failed."""
        failed = sum(1 for r in self.rows.values() if r.get("error") or (strict and flagged(r)))
        return len(self.rows) - failed, failed, len(self.points) - len(self.rows)

    def flagged(self):
        """The rows of the grid's points whose runs are flagged (``flagged``), in the grid's order."""
        return [r for r in self.grid_rows() if flagged(r)]

    def grid_rows(self):
        return [self.rows[i] for i in range(len(self.points)) if i in self.rows]

    def all_rows(self):
        mine = [self.rows.get(i, self.stale.get(i)) for i in range(len(self.points))]
        return [r for r in mine if r is not None] + self.others

    def write(self):
        """The table to a temporary beside the file, renamed onto it (Ctrl-C held back
        meanwhile: ``written`` is what the file holds)."""
        if self.path is None:
            return
        make_parents(self.path)  # the folders --out names, made when the table is first written
        temp = self.path.with_name(f".{self.path.stem}.{secrets.token_hex(4)}.part{self.path.suffix}")
        try:
            write_table(self.all_rows(), temp)
            with hold_interrupts():
                os.replace(temp, self.path)
                self.written = self.counts()
        finally:
            temp.unlink(missing_ok=True)


def _key(row):
    """A point's identity: its swept parameters and their values, as text."""
    return frozenset((k, str(v)) for k, v in row.items() if k.startswith("param.") and v not in ("", None))


def read_table(path):
    """The rows of a table written by write_table (ValueError naming --out if it cannot be read)."""
    try:
        if str(path).endswith(".json"):
            rows = json.loads(Path(path).read_text())
            if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
                raise ValueError("not a list of rows")
            return rows
        with open(path, newline="") as fh:
            return list(csv.DictReader(fh))
    except (OSError, ValueError, csv.Error, UnicodeDecodeError) as err:
        raise ValueError(
            f"--out {path}: cannot resume from it, it is not a sweep's table ({' '.join(str(err).split())})"
        ) from None


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
