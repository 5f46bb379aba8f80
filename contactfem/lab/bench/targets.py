"""Study 4, targets: every paper scene at the paper preset (wall time of the solve and of
the whole `contactfem run` process), against the targets."""

import os
import resource
import subprocess
import sys
import tempfile
import time

from ...scenes import all_scenes, run_scene
from .common import PAPER_SCENES, TARGETS
from .speed import compile_bytecode


def _process_time(args):
    """Wall time and CPU time (user + sys) of a whole `python -m contactfem ...` process,
    imports included. On a loaded machine the wall time exceeds the CPU time."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "contactfem", *args], capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"bench: 'contactfem {' '.join(args)}' failed: {proc.stderr.strip()[-500:]}")
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return wall, cpu


def targets_study(quick=False):
    """Study 4 (module docstring). Quick: block and the frictional sloping impact at the
    fast preset, hertz on 32^2 quads, no process times."""
    preset = "fast" if quick else "paper"
    known = all_scenes()
    if not quick:
        compile_bytecode()  # whole processes measured as an installed package runs
    rows = []
    for name in PAPER_SCENES:
        if name not in known:
            continue
        variants = [{}]
        if quick and name not in ("block", "sloping_impact"):
            continue
        if quick and name == "sloping_impact":
            variants = [{"variant": "frictional"}]
        elif name == "sloping_impact":
            variants = [{"variant": v} for v in ("frictionless", "frictional", "viscoplastic")]
        elif name == "funnel":
            variants = [{"variant": v} for v in ("frictionless", "frictional")]
        for over in variants:
            row = dict(scene=name, preset=preset, overrides=over)
            try:
                r = run_scene(name, preset, over, error_bars=False)
                row.update(ok=True, solve_s=r["wall_time_s"], iterations=r["newton_iterations_total"])
            except Exception as err:
                row.update(ok=False, error=f"{type(err).__name__}: {str(err).splitlines()[0][:160]}")
            if not quick:
                sets = [a for k, v in over.items() for a in ("--set", f"{k}={v}")]
                row["process_s"], row["process_cpu_s"] = _process_time(
                    ["run", name, "--preset", preset, *sets, "--no-error-bars"]
                )
            rows.append(row)
    total = sum(r.get("process_s", r.get("solve_s", 0.0)) or 0.0 for r in rows)
    out = dict(
        preset=preset,
        scenes=rows,
        total_s=total,
        each_under_10s=all(
            r.get("ok") and max(r.get("process_s") or 0, r["solve_s"]) < TARGETS["scene_s"] for r in rows
        ),
        all_under_60s=total < TARGETS["all_s"],
    )
    # hertz on about 4,000 quads (64^2 = 4096), whole process
    n = 32 if quick else 64
    if quick:
        r = run_scene("hertz", "paper", {"n_el": n}, error_bars=False)
        process = process_cpu = None
    else:
        with tempfile.TemporaryDirectory() as tmp:  # (the JSON written as a user would)
            out_json = os.path.join(tmp, "hertz.json")
            runs = [
                _process_time(["run", "hertz", "--preset", "paper", "--json", out_json, "--no-error-bars"])
                for _ in range(3)
            ]
        process, process_cpu = min(w for w, _ in runs), min(c for _, c in runs)  # best of 3
        r = run_scene("hertz", "paper", {"n_el": n}, error_bars=False)
    out["hertz"] = dict(
        n_quads=r["n_quads"],
        error_p0=r["error_p0"],
        solve_s=r["wall_time_s"],
        process_s=process,
        process_cpu_s=process_cpu,
        p0_within=abs(r["error_p0"]) < TARGETS["hertz_p0_error"],
        under_1p5s=(process < TARGETS["hertz_process_s"]) if process is not None else None,
    )
    out["process_overhead_s"], out["process_overhead_cpu_s"] = _process_time(["list"])  # imports, registry
    return out
