"""Study 5, speed: where the time of a run goes. Start-up of the process and the cost of one
Newton iteration, split into its parts, for every paper scene; the Table 2 refinement
study as `contactfem sweep` runs it (report: report.py).

One Newton iteration is what ``newton()`` does between two linear solves: evaluate the
residual and tangent (bulk: the bodies' internal forces and tangents; contact: every
contact's residual and tangent; assembly: summing them into K, loads included), solve
K du = -G, and the rest (Python overhead: the time stepper's effective residual, norms,
bookkeeping). The parts are measured inside a real run of the scene by an instrument the
Systems are built with (solver/instrument.py: CPU time of the thread that runs them, so that
a loaded machine disturbs them less, and the idle BLAS threads spinning on another core do
not count); their sum over the run is divided by the number of linear solves. Each scene runs in a
fresh interpreter (best of 3 runs), as a user's run does. A converged
step evaluates once more than it solves, so this per-iteration cost includes that share.

Start-up: whole `python` processes (median of 5 runs, wall and CPU time): an empty
interpreter, `contactfem list`, an interpreter that imports scipy.sparse.linalg and
scikit-fem (what any scikit-fem program pays), and `contactfem run block --preset paper`.
The account of the block's start-up: interpreters that import numpy, scipy.sparse and
scikit-fem, one after the other a layer more of what the block loads, beside `contactfem run
block --preset canonical` and a short run of rings (the sloping impact, 5 steps: dense K,
no scipy and no scikit-fem loaded).
Like the libraries (compiled by pip when installed), contactfem is measured with its
bytecode compiled beforehand.
"""

import compileall
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ...scenes import get_scene, run_scene
from ...scenes.sloping_impact import PAPER_TABLE2
from ...solver.instrument import Timings

PARTS = ("bulk", "contact", "assembly", "solve", "overhead")
# what the speed work aims at (whole-process and per-iteration times on 2 cores)
# (the iterations: wall_time_s / newton_iterations_total of a paper run, about ten times the floor
# that iteration_limit measures for the sloping impact)
SPEED_TARGETS = dict(
    list_s=0.25,
    sloping_impact_iteration_s=0.25e-3,
    rolling_ring_iteration_s=0.25e-3,
    table2_s=60.0,
    run_block_over_scipy_skfem=1.3,
    # the block's start-up: its whole process (canonical preset: a run that costs next to nothing) against an
    # interpreter that only imports scikit-fem, which the block's forms need; 1.15: contactfem's own modules, the
    # model and the run add at most 15 % to what scikit-fem costs to import
    run_block_canonical_over_skfem=1.15,
)
# the block's start-up, layer by layer: (key, what the process runs, label)
STARTUP_LAYERS = (
    ("numpy", ["-c", "import numpy"], '`python -c "import numpy"`'),
    ("scipy_sparse", ["-c", "import scipy.sparse"], '`python -c "import scipy.sparse"`'),
    ("skfem", ["-c", "import skfem"], '`python -c "import skfem"`'),
    (
        "run_block_canonical",
        ["-m", "contactfem", "run", "block", "--preset", "canonical", "--no-error-bars"],
        "`contactfem run block --preset canonical`",
    ),
)
RINGS = (
    "run_rings",
    ["-m", "contactfem", "run", "sloping_impact", "--set", "n_steps=5", "--no-error-bars"],
    "`contactfem run sloping_impact --set n_steps=5`",
)


def _process(args, repeat=5):
    """Median wall and CPU (user + sys) time of a whole process `args`, over `repeat` runs."""
    walls, cpus = [], []
    for _ in range(repeat):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(args, capture_output=True, text=True)
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise RuntimeError(f"bench: {' '.join(args)} failed: {proc.stderr.strip()[-500:]}")
        cpus.append((r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
    return dict(wall_s=statistics.median(walls), cpu_s=statistics.median(cpus), walls_s=walls)


def compile_bytecode():
    """Compile the package's modules to bytecode (__pycache__), as an installed package has
    them: pip compiles what it installs, and Python caches what it imports, unless
    PYTHONDONTWRITEBYTECODE is set (then an editable install compiles its ~50 modules on
    every start, ~0.08 s). True if the bytecode is there afterwards."""
    package = Path(__file__).resolve().parents[2]
    try:
        return bool(compileall.compile_dir(str(package), quiet=2))
    except OSError:  # a read-only install: compiled by pip
        return False


def startup_study(repeat=5):
    """Start-up of whole processes (module docstring) and the ratios the targets refer to.
    The package's bytecode is compiled first (compile_bytecode), as for the libraries."""
    py = sys.executable
    bytecode = compile_bytecode()
    out = {
        "python": _process([py, "-c", "pass"], repeat),
        "list": _process([py, "-m", "contactfem", "list"], repeat),
        "scipy_skfem": _process([py, "-c", "import scipy.sparse.linalg, skfem"], repeat),
        "run_block": _process([py, "-m", "contactfem", "run", "block", "--preset", "paper", "--no-error-bars"], repeat),
    }
    for key, args, _ in STARTUP_LAYERS + (RINGS,):
        out[key] = _process([py, *args], repeat)
    out["bytecode_compiled"] = bytecode
    out["dont_write_bytecode"] = bool(os.environ.get("PYTHONDONTWRITEBYTECODE"))
    out["list_over_python"] = out["list"]["wall_s"] / out["python"]["wall_s"]
    out["run_block_over_scipy_skfem"] = out["run_block"]["wall_s"] / out["scipy_skfem"]["wall_s"]
    for key in ("skfem", "run_block_canonical", "run_rings"):
        out[f"{key}_over_numpy"] = out[key]["wall_s"] / out["numpy"]["wall_s"]
    out["run_block_canonical_over_skfem"] = out["run_block_canonical"]["wall_s"] / out["skfem"]["wall_s"]
    out["loads"] = {
        "skfem_assembly": _loads("import skfem.assembly"),
        "run_block_canonical": _loads(_cli_run(STARTUP_LAYERS[-1][1][3:])),
        "run_rings": _loads(_cli_run(RINGS[1][3:])),
    }
    return out


HEAVY = ("scipy.sparse", "scipy.sparse.linalg", "scipy.sparse.csgraph", "scipy.linalg", "skfem", "matplotlib")


def _cli_run(args):
    return f"from contactfem.cli import main\nassert main({['run', *args]!r}) == 0"


def _loads(code):
    """Which of HEAVY a fresh interpreter has loaded after running `code`."""
    probe = f"{code}\nimport sys\nprint('loaded:', *(m for m in {HEAVY!r} if m in sys.modules))"
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"bench: {code!r} failed: {proc.stderr.strip()[-500:]}")
    return proc.stdout.strip().splitlines()[-1].split()[1:]


def iteration_split(scene, preset="paper", overrides=None):
    """Run a scene with an instrument (solver/instrument.py) handed to every System it builds;
    per-iteration cost of each part (seconds, CPU of the running thread) and the run's totals
    (run_wall_s, run_cpu_s of the process, run_thread_s of this thread: modules loaded on first
    use included; wall_time_s: the run's own wall time, without them).
    bulk, contact: the System's parts; assembly: loads and summing into K; solve: the linear
    solves; overhead: the rest of newton() and the stepper's effective residual."""
    timings = Timings()
    t0, c0, h0 = time.perf_counter(), time.process_time(), time.thread_time()
    res = run_scene(scene, preset, dict(overrides or {}), instrument=timings, error_bars=False)
    wall, cpu, thread = time.perf_counter() - t0, time.process_time() - c0, time.thread_time() - h0
    sec = timings.seconds
    n = max(timings.solves, 1)
    parts = {k: sec[k] for k in ("bulk", "contact", "assembly", "solve")}
    parts["overhead"] = sec["newton"] - sum(parts.values())
    out = {f"{k}_s": v / n for k, v in parts.items()}
    out.update(
        iteration_s=sec["newton"] / n,
        solves=timings.solves,
        newton_cpu_s=sec["newton"],
        outside_newton_s=sum(timings.outside.values()),
        run_wall_s=wall,
        run_cpu_s=cpu,
        run_thread_s=thread,
        linear_algebra=res.get("linear_algebra"),
        ordering=res.get("ordering"),
        ndof=res.get("unknowns"),
        residual_evaluations=res.get("residual_evaluations"),
        wall_time_s=res.get("wall_time_s"),
        newton_iterations_total=res.get("newton_iterations_total"),
    )
    return out


def iteration_limit(repeat=7, number=200):
    """The floor of one Newton iteration of the sloping impact (frictional, paper preset: 48
    unknowns, a ring of 16 beams) in this Python: its ring's 576 tangent entries and the
    diagonal c M summed into a dense K by one bincount, and K du = -G solved by LAPACK
    (numpy.linalg.solve), the two calls a dense iteration cannot do without; nothing else.
    CPU seconds of the thread per call (best of `repeat` loops of `number` calls), of the
    assembly, the solve and both; and of one small numpy call (numpy_call_s: the product of
    two arrays of 32 entries, the size of the ring's arrays), the unit of the rest."""
    scene = get_scene("sloping_impact")
    params = scene.resolve("paper", {"variant": "frictional"})
    body = scene.build(params).system.bodies[0]
    n = body.ndof
    rng = np.random.default_rng(0)
    u = 1e-3 * rng.standard_normal(n)  # a deformed ring: a regular K, a non-zero G
    G, rows, cols, vals = body.internal_coo(u, params["dt"])
    index = np.concatenate([rows * n + cols, np.arange(n) * (n + 1)])
    values = np.concatenate([vals, body.mass() / (params["beta_newmark"] * params["dt"] ** 2)])

    def assemble():
        return np.bincount(index, values, minlength=n * n).reshape(n, n)

    K = assemble()

    def best(call):
        times = []
        for _ in range(repeat):
            t0 = time.thread_time()
            for _ in range(number):
                call()
            times.append((time.thread_time() - t0) / number)
        return min(times)

    a, b = rng.standard_normal(32), rng.standard_normal(32)
    return dict(
        n=n,
        entries=int(vals.size),
        assembly_s=best(assemble),
        solve_s=best(lambda: np.linalg.solve(K, -G)),
        limit_s=best(lambda: np.linalg.solve(assemble(), -G)),
        numpy_call_s=best(lambda: a * b),
    )


# the paper's scenes at the paper preset (quick: the fast preset)
SCENES = (
    ("block", {}),
    ("rolling_ring", {}),
    ("sloping_impact", {"variant": "frictional"}),
    ("sloping_impact", {"variant": "frictionless"}),
    ("funnel", {"variant": "frictional"}),
    ("cork", {}),
    ("hertz", {}),
)


def table2_study(n_els=(16, 32, 64, 128), jobs=2, refine=8):
    """The Table 2 convergence study as a user runs it: `contactfem sweep sloping_impact` over
    both variants and the element counts, at the paper's dt = 0.1 (200 steps) and at dt / refine
    (200 refine steps, the same 20 s), with `--jobs`. Returns the rows and each sweep's wall time."""
    out = dict(n_el=list(n_els), jobs=jobs, sweeps=[], rows=[])
    with tempfile.TemporaryDirectory() as tmp:
        for dt, n_steps in ((0.1, 200), (0.1 / refine, 200 * refine)):
            table = Path(tmp) / f"table2_dt{n_steps}.csv"
            args = [
                sys.executable,
                "-m",
                "contactfem",
                "sweep",
                "sloping_impact",
                "--preset",
                "paper",
                "--set",
                "variant=frictionless,frictional",
                "--set",
                "n_el=" + ",".join(map(str, n_els)),
                "--set",
                f"dt={dt:g}",
                "--set",
                f"n_steps={n_steps}",
                "--jobs",
                str(jobs),
                "--out",
                str(table),
            ]
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            proc = subprocess.run(args, capture_output=True, text=True)
            wall = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            if proc.returncode != 0:
                raise RuntimeError(f"bench: the Table 2 sweep failed: {proc.stderr.strip()[-500:]}")
            # CPU of the sweep and of its worker processes (user + sys): on a loaded machine the
            # wall time is mostly waiting for a core
            cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
            out["sweeps"].append(dict(command="contactfem " + " ".join(args[3:-2]), wall_s=wall, cpu_s=cpu))
            with open(table, newline="") as fh:
                for row in csv.DictReader(fh):
                    variant = row["param.variant"]
                    num = lambda k: float(row[k]) if row.get(k) not in (None, "") else None  # noqa: E731
                    out["rows"].append(
                        dict(
                            variant=variant,
                            n_el=int(row["param.n_el"]),
                            dt=dt,
                            error=row.get("error") or None,
                            rebound_vx=num("rebound_vx"),
                            rebound_vy=num("rebound_vy"),
                            rebound_angle_deg=num("rebound_angle_deg"),
                            rebound_spin=num("rebound_spin"),
                            newton_iterations_total=num("newton_iterations_total"),
                            paper=PAPER_TABLE2.get(variant),
                        )
                    )
    out["rows"].sort(key=lambda r: (r["variant"], r["dt"] < 0.1, r["n_el"]))
    out["total_wall_s"] = sum(sw["wall_s"] for sw in out["sweeps"])
    out["total_cpu_s"] = sum(sw["cpu_s"] for sw in out["sweeps"])
    return out


def iteration_split_fresh(scene, preset="paper", overrides=None, repeat=3):
    """iteration_split in a fresh interpreter, as a user's run is (a long benchmark process
    holds results that slow Python's garbage collector down), best of `repeat` runs."""
    code = (
        "import json, sys\nfrom contactfem.lab.bench.speed import iteration_split\n"
        "print(json.dumps(iteration_split(*json.loads(sys.argv[1]))))"
    )
    best = None
    for _ in range(repeat):
        proc = subprocess.run(
            [sys.executable, "-c", code, json.dumps([scene, preset, dict(overrides or {})])],
            capture_output=True,
            text=True,
        )
        if proc.returncode != 0:
            raise RuntimeError(f"bench: the iteration split of {scene} failed: {proc.stderr.strip()[-500:]}")
        out = json.loads(proc.stdout.strip().splitlines()[-1])
        if best is None or out["iteration_s"] < best["iteration_s"]:
            best = out
    return best


def speed_study(quick=False):
    """Start-up times, the per-iteration cost of every paper scene (each in a fresh process,
    best of 3) and the Table 2 sweep. Quick: two scenes at the fast preset, one run of each
    process, no sweep."""
    preset = "fast" if quick else "paper"
    scenes = SCENES[:1] + SCENES[2:3] if quick else SCENES
    rows = []
    for scene, over in scenes:
        row = dict(scene=scene, overrides=over, preset=preset)
        row.update(iteration_split_fresh(scene, preset, over, repeat=1 if quick else 3))
        rows.append(row)
    load = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    return dict(
        preset=preset,
        iterations=rows,
        limit=iteration_limit(),
        startup=startup_study(repeat=1 if quick else 5),
        table2=None if quick else table2_study(),
        load_average=load,
    )
