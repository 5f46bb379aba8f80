"""`contactfem bench`: speed against accuracy, measured.

Four studies, each a function returning a JSON-able dict; ``run_bench`` runs them all
and ``write_markdown`` turns the result into the tables of BENCHMARKS.md.

1. tangents        the paper's central claim (Sec. 4.2): Newton with the consistent
                   non-symmetric tangent (eqs 49-50) against a symmetrised tangent, the
                   tangent without the coupling c_N^s C ("frozen") and the staggered
                   normal-then-friction algorithm of Sec. 2.2 (contactfem.solver.staggered),
                   on the block (Sec. 5.1) and the frictional sloping impact (Sec. 5.3):
                   linear solves and time to the same tolerance; divergence is recorded.
2. work_precision  error against wall time under refinement: hertz (mesh; exact a, p0),
                   rolling ring (dt and mesh; exact rolling point of the rigid ring),
                   Newmark 0.7/0.4 against 0.5/0.25, implicit Newmark against explicit
                   central differences on bar_impact (exact contact duration), beam ring
                   against continuum ring. Observed orders: slope of log(error) against
                   log(h) by least squares.
3. cost            time of one Newton iteration split into bulk assembly (body.internal),
                   contact (contact.assemble), global assembly (COO -> CSR) and linear
                   solve (SuperLU with two orderings, and pypardiso if installed), at the
                   paper sizes and for the block refined to about 1e5 unknowns; contact
                   time against the number of contact nodes (slope ~1: linear).
4. targets         every paper scene at the paper preset (wall time of the solve and of
                   the whole `contactfem run` process), against the targets.

``quick`` shrinks every study (fast presets, fewer points) to about a minute in all.
No timing enters a test: times depend on the machine and its load.
"""

import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from ..scenes import get_scene, jsonable, run_scene

TARGETS = dict(scene_s=10.0, all_s=60.0, hertz_process_s=1.5, hertz_p0_error=0.005, hertz_quads=4000)
PAPER_SCENES = ("block", "rolling_ring", "sloping_impact", "funnel", "cork")


def _timed(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def observed_order(h, err):
    """Slope p of log(err) = p log(h) + c by least squares (err ~ C h^p); None with
    fewer than two positive errors."""
    h, err = np.asarray(h, float), np.abs(np.asarray(err, float))
    ok = (err > 0) & np.isfinite(err)
    if np.count_nonzero(ok) < 2:
        return None
    return float(np.polyfit(np.log(h[ok]), np.log(err[ok]), 1)[0])


# ---------------------------------------------------------------------------
# 1. Consistent tangent against symmetric, frozen and staggered
# ---------------------------------------------------------------------------

def _block_variant(params, variant):
    """One block solve (whole load in one step) with a tangent variant or the staggered
    algorithm: dict(converged, iterations, time_s, u or error)."""
    from ..scenes import block
    from ..solver import Static, System
    from ..solver.newton import NewtonError
    from ..solver.staggered import SplitContact, Staggered

    t0 = time.perf_counter()
    try:
        if variant == "staggered":
            b = block.build(dict(params, tangent="consistent"))
            split = SplitContact(b["contact"])
            system = System([b["body"]], [split], b["loads"])
            stepper = Staggered(Static(system, 1.0, atol=params["atol"], rtol=params["rtol"],
                                       maxit=params["maxit"]), [split], max_cycles=200)
            u = np.zeros(system.ndof)
            b["contact"].initialize(u)
            u, _, _, res = stepper.step(0.0, u, u, u, label="block, staggered")
            extra = dict(cycles=res.cycles, phase_iterations=res.phase_iterations)
        else:
            s = block.solve(dict(params, tangent=variant))
            u, res, extra = s["u"], s["result"], {}
    except NewtonError as err:
        return dict(converged=False, iterations=None, time_s=time.perf_counter() - t0,
                    error=str(err).splitlines()[0][:200], residuals=list(err.history)[:12])
    return dict(converged=True, iterations=int(res.iterations), time_s=time.perf_counter() - t0,
                residuals=list(res.residuals), u=u, **extra)


def _impact_variant(params, variant):
    """The frictional sloping impact (Sec. 5.3) with a tangent variant or the staggered
    algorithm: total linear solves, step cutbacks, rebound velocity."""
    from ..scenes import sloping_impact
    from ..contact.tangents import ContactTangent
    from ..solver import Newmark, System, integrate
    from ..solver.newton import NewtonError
    from ..solver.staggered import SplitContact, Staggered

    m = sloping_impact.build(params)
    ring, contact = m["ring"], m["contact"]
    if variant == "staggered":
        wrapped = SplitContact(contact)
    elif variant == "consistent":
        wrapped = contact
    else:
        wrapped = ContactTangent(contact, variant)
    system = System([ring.body], [wrapped])
    newmark = Newmark(system, params["dt"], params["delta"], params["beta_newmark"], atol=1e-10, rtol=1e-10,
                      maxit=30)
    stepper = Staggered(newmark, [wrapped], max_cycles=100) if variant == "staggered" else newmark
    u0 = np.zeros(ring.body.ndof)
    contact.initialize(u0)
    system.set_dt(params["dt"])
    t0 = time.perf_counter()
    try:
        hist = integrate(stepper, 0.0, u0, ring.initial_velocity((params["vx0"], params["vy0"])),
                         n_steps=params["n_steps"], cutback=True, max_cuts=6)
    except NewtonError as err:
        part = getattr(err, "partial", None)
        return dict(converged=False, iterations=None, time_s=time.perf_counter() - t0,
                    error=str(err).splitlines()[0][:200],
                    steps_done=int(len(part.t) - 1) if part is not None else None)
    vx, vy = ring.velocity_of_mass(hist.v)
    return dict(converged=True, iterations=int(np.sum(hist.iterations)), time_s=time.perf_counter() - t0,
                step_cuts=int(np.sum(hist.cuts)), rebound_vx=float(vx), rebound_vy=float(vy),
                max_iterations_per_step=int(np.max(hist.iterations)))


VARIANTS = ("consistent", "symmetric", "frozen", "staggered")


def tangent_study(quick=False):
    """Study 1 (module docstring). The block with Coulomb (mu = 0.3) and the parabolic law
    (paper Table 1); the frictional sloping impact (paper data, 200 steps; 60 if quick)."""
    block = get_scene("block")
    out = {"block": {}, "sloping_impact": {}}
    for law in ("coulomb",) if quick else ("coulomb", "parabolic"):
        params = block.resolve("paper", {"law": law})
        rows = {v: _block_variant(params, v) for v in VARIANTS}
        ref = rows["consistent"].get("u")
        for r in rows.values():
            u = r.pop("u", None)
            if ref is not None and u is not None:
                r["max_difference_to_consistent"] = float(np.max(np.abs(u - ref)))
        out["block"][law] = rows
    impact = get_scene("sloping_impact")
    params = impact.resolve("paper", {"variant": "frictional", **({"n_steps": 40} if quick else {})})
    out["sloping_impact"] = {v: _impact_variant(params, v) for v in VARIANTS}
    out["sloping_impact_steps"] = params["n_steps"]
    return out


# ---------------------------------------------------------------------------
# 2. Work-precision
# ---------------------------------------------------------------------------

_POINTS = {}


def _scene_point(scene, preset, over, keys):
    """Run a scene, keep the wall time of the solve, the linear solves and `keys` (a point
    already run in this process is reused)."""
    key = (scene, preset, tuple(sorted(over.items())), keys)
    if key not in _POINTS:
        _POINTS[key] = _scene_point_run(scene, preset, over, keys)
    return dict(_POINTS[key])


def _scene_point_run(scene, preset, over, keys):
    try:
        r = run_scene(scene, preset, over)
    except Exception as err:       # recorded, not hidden: a failed point is a result
        return dict(over, ok=False, error=f"{type(err).__name__}: {str(err).splitlines()[0][:160]}")
    return dict(over, ok=True, time_s=r["wall_time_s"], iterations=r["newton_iterations_total"],
                **{k: r.get(k) for k in keys})


def _bar_run(params, explicit):
    """bar_impact with Newmark (the scene) or explicit central differences (same model)."""
    from ..scenes import bar_impact
    from ..solver import CentralDifference, Newmark, integrate

    m = bar_impact.build(params)
    body, contact, system = m["body"], m["contact"], m["system"]
    L, H, v0 = params["L"], params["h"], params["v0"]
    ex = bar_impact.bar_exact(L, params["E"], params["rho"], v0)
    dt = params["courant"] * (L / params["n_el"]) / ex["c"]
    if explicit:
        stepper = CentralDifference(system, dt)
    else:
        stepper = Newmark(system, dt, delta=params["delta"], beta=params["beta_newmark"],
                          atol=1e-9 * ex["stress"] * H, rtol=1e-12, maxit=30)
    u0, v = np.zeros(body.ndof), np.zeros(body.ndof)
    v[body.xdofs[:, 0]] = -v0
    contact.initialize(u0)
    force = [0.0]
    t0 = time.perf_counter()
    hist = integrate(stepper, 0.0, u0, v, t_end=params["t_end"] * ex["duration"], cutback=not explicit,
                     callback=lambda t, u, vv, a: force.append(float(-contact.report(u)["f_N"].sum())))
    wall = time.perf_counter() - t0
    t, on = hist.t, np.flatnonzero(np.asarray(force) > 0)
    # contact from midway before the first loaded step to midway after the last (as the scene)
    start = 0.5 * (t[max(on[0] - 1, 0)] + t[on[0]])
    stop = 0.5 * (t[on[-1]] + t[min(on[-1] + 1, len(t) - 1)])
    M = body.mass()[body.xdofs[:, 0]]
    v_after = float(M @ hist.v[body.xdofs[:, 0]] / M.sum())
    E = hist.kinetic + hist.strain + hist.contact
    return dict(time_s=wall, steps=int(len(t) - 1), iterations=int(np.sum(hist.iterations)),
                error_duration=float((stop - start) / ex["duration"] - 1.0),
                error_rebound=float(v_after / v0 - 1.0), energy_error=float(E[-1] / E[0] - 1.0))


def work_precision(quick=False):
    """Study 2 (module docstring)."""
    out = {}
    # hertz: mesh refinement (per-length penalty), exact a and p0
    n_hertz = (8, 16, 32) if quick else (8, 16, 32, 64, 96)
    rows = [_scene_point("hertz", "paper", {"n_el": n}, ("error_p0", "error_a", "n_quads", "n_dofs"))
            for n in n_hertz]
    for r in rows:
        r["h"] = 1.0 / r["n_el"]
    ok = [r for r in rows if r["ok"]]
    out["hertz_mesh"] = dict(rows=rows, order_p0=observed_order([r["h"] for r in ok], [r["error_p0"] for r in ok]))

    # rolling ring: dt refinement (beam; Newmark 0.7/0.4 and 0.5/0.25), mesh refinement,
    # beam against continuum. Error: x_roll against the rigid ring of the same lever arm
    # and gyration radius (x_roll_model; the hoop value differs by h^2 / 12 R^2).
    keys = ("x_roll", "x_roll_model", "x_roll_exact", "x_end_rel_err", "step_cuts_total", "rolled")
    base = {"t_end": 1.2} if quick else {}
    n_el = 40 if quick else 120
    dts = (0.04, 0.02) if quick else (0.04, 0.02, 0.01, 0.005)
    newmarks = {"0.7/0.4": {}, "0.5/0.25": {"delta": 0.5, "beta_newmark": 0.25}}
    for name, nm in newmarks.items():
        rows = [_scene_point("rolling_ring", "paper", dict(base, n_el=n_el, dt=dt, **nm), keys)
                for dt in (dts[-1:] if quick and nm else dts)]
        out[f"ring_dt_newmark_{name}"] = _ring_rows(rows, "dt")
    n_els = (20, 40) if quick else (30, 60, 120, 240)
    rows = [_scene_point("rolling_ring", "paper", dict(base, n_el=n, dt=dts[-1] if quick else 0.01), keys)
            for n in n_els]
    for r in rows:
        r["h"] = 1.0 / r["n_el"]
    out["ring_mesh"] = _ring_rows(rows, "h")
    kinds = {}
    for kind in ("beam", "continuum"):
        kinds[kind] = _scene_point("rolling_ring", "paper", dict(base, kind=kind, n_el=n_el if quick else 60,
                                                                dt=dts[-1] if quick else 0.01), keys)
    out["ring_kind"] = _ring_rows(list(kinds.values()), None)

    # implicit Newmark (trapezoidal, courant 1) against explicit central differences
    bar = get_scene("bar_impact")
    n_bar = 40 if quick else 100
    impl = [dict(courant=c, **_bar_run(bar.resolve("paper", {"n_el": n_bar, "courant": c}), False))
            for c in ((1.0,) if quick else (2.0, 1.0, 0.5, 0.25))]
    expl = [dict(courant=c, **_bar_run(bar.resolve("paper", {"n_el": n_bar, "courant": c}), True))
            for c in ((0.5,) if quick else (0.7, 0.5, 0.25))]
    out["bar_implicit_explicit"] = dict(n_el=n_bar, newmark=impl, central_difference=expl)
    return out


def _ring_rows(rows, hkey):
    for r in rows:
        if r["ok"] and r.get("x_roll") is not None:
            r["error_x_roll"] = abs(r["x_roll"] / r["x_roll_model"] - 1.0)
        elif r["ok"]:
            r["error_x_roll"] = None
    ok = [r for r in rows if r["ok"] and r.get("error_x_roll")]
    order = observed_order([r[hkey] for r in ok], [r["error_x_roll"] for r in ok]) if hkey else None
    return dict(rows=rows, order_x_roll=order)


# ---------------------------------------------------------------------------
# 3. Cost structure of one Newton iteration
# ---------------------------------------------------------------------------

def _best_of(fn, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        out, dt = _timed(fn)
        best = min(best, dt)
    return out, best


def iteration_cost(system, u, t=1.0, repeat=3, solvers=True):
    """Wall times (best of `repeat`) of the parts of one Newton iteration at u:
    bulk (every body.internal), contact (every contact.assemble), assembly (the whole
    System.residual_tangent minus those two: loads, COO -> CSR), solve (splu factor +
    solve of the free block with the default COLAMD and with MMD_AT_PLUS_A ordering,
    and pypardiso if installed)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import splu

    out = dict(ndof=int(system.ndof))
    _, out["bulk_s"] = _best_of(lambda: [b.internal(system.local(b, u)) for b in system.bodies], repeat)
    _, out["contact_s"] = _best_of(lambda: [c.assemble(u) for c in system.contacts], repeat)
    (G, K), total = _best_of(lambda: system.residual_tangent(u, t), repeat)
    out["assembly_s"] = max(total - out["bulk_s"] - out["contact_s"], 0.0)
    out["residual_tangent_s"] = total
    free = system.free_dofs
    Kff = sp.csr_matrix(K)[free][:, free].tocsc()
    b = -G[free]
    out["n_contact_nodes"] = int(sum(len(c.nodes) for c in system.contacts))
    if not solvers:
        return out
    for spec in ("COLAMD", "MMD_AT_PLUS_A"):
        _, out[f"solve_splu_{spec}_s"] = _best_of(lambda: splu(Kff, permc_spec=spec).solve(b), repeat)
    try:
        import pypardiso
        A = Kff.tocsr()
        pypardiso.spsolve(A, b)                      # first call: library initialisation
        # spsolve would reuse the factors of the same matrix: factorise explicitly each time
        ps = pypardiso.PyPardisoSolver()
        ps.solve(A, b)
        _, out["solve_pypardiso_s"] = _best_of(lambda: (ps.factorize(A), ps.solve(A, b)), repeat)
    except ImportError:
        out["solve_pypardiso_s"] = None
    out["solve_s"] = out["solve_splu_MMD_AT_PLUS_A_s"]           # what newton() uses
    return out


def _block_system(nx, ny, material="linear", width=None):
    from ..scenes import block

    p = get_scene("block").resolve("paper", {"law": "coulomb", "material": material})
    p = dict(p, nx=nx, ny=ny)                       # past the scene's nx <= 400 for the scaling study
    if width is not None:
        p.update(width=width, height=width * ny / nx)  # square elements
    b = block.build(p)
    u = np.zeros(b["system"].ndof)
    b["contact"].initialize(u)
    # a state with every slave in contact: the block pushed down by 1e-3 (stick)
    u[b["body"].xdofs[:, 1]] = -1e-3
    return b["system"], u


def cost_study(quick=False):
    """Study 3 (module docstring)."""
    from ..scenes import hertz, rolling_ring

    cases = {}
    for material in ("linear", "svk"):
        system, u = _block_system(20, 10, material)
        cases[f"block 20x10 ({material})"] = iteration_cost(system, u)
    hz = get_scene("hertz")
    m = hertz.build(hz.resolve("paper", {"n_el": 32 if quick else 64}))
    u = np.zeros(m["system"].ndof)
    u[m["body"].xdofs[:, 1]] = -m["a_exact"] ** 2 / (2 * 10.0)
    m["contact"].initialize(u)
    cases[f"hertz {m['body'].mesh.t.shape[1]} quads"] = iteration_cost(m["system"], u)
    ring = rolling_ring.build(get_scene("rolling_ring").resolve("paper"))
    u = np.zeros(ring["system"].ndof)
    ring["contact"].initialize(u)
    cases["rolling ring 120 beams"] = iteration_cost(ring["system"], u, t=0.0)
    n_big = 64 if quick else 223                        # 2 (n + 1)^2 = 100352 unknowns
    for material in ("linear",) if quick else ("linear", "svk"):
        system, u = _block_system(n_big, n_big, material)
        system.residual_tangent(u, 1.0)                 # the linear body caches its K
        cases[f"block {n_big}x{n_big} ({material})"] = iteration_cost(system, u, repeat=1 if not quick else 2)

    # contact cost against the number of contact nodes (a one-element-high strip)
    scaling = []
    for nx in ((50, 200, 800) if quick else (50, 200, 800, 1600, 3200)):
        system, u = _block_system(nx, 1, width=4.0)
        c = system.contacts[0]
        _, t_c = _best_of(lambda: c.assemble(u), 5)
        scaling.append(dict(n_contact_nodes=int(len(c.nodes)), contact_s=t_c))
    slope = float(np.polyfit(np.log([r["n_contact_nodes"] for r in scaling[1:]]),
                             np.log([r["contact_s"] for r in scaling[1:]]), 1)[0])
    return dict(cases=cases, contact_scaling=scaling, contact_scaling_slope=slope)


# ---------------------------------------------------------------------------
# 4. Targets: the paper scenes at the paper preset
# ---------------------------------------------------------------------------

def _process_time(args):
    """Wall time and CPU time (user + sys) of a whole `python -m contactfem ...` process,
    imports included. On a loaded machine the wall time exceeds the CPU time."""
    import resource

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
    from ..scenes import all_scenes

    preset = "fast" if quick else "paper"
    known = all_scenes()
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
                r = run_scene(name, preset, over)
                row.update(ok=True, solve_s=r["wall_time_s"], iterations=r["newton_iterations_total"])
            except Exception as err:
                row.update(ok=False, error=f"{type(err).__name__}: {str(err).splitlines()[0][:160]}")
            if not quick:
                sets = [a for k, v in over.items() for a in ("--set", f"{k}={v}")]
                row["process_s"], row["process_cpu_s"] = _process_time(["run", name, "--preset", preset, *sets])
            rows.append(row)
    total = sum(r.get("process_s", r.get("solve_s", 0.0)) or 0.0 for r in rows)
    out = dict(preset=preset, scenes=rows, total_s=total,
               each_under_10s=all(r.get("ok") and max(r.get("process_s") or 0, r["solve_s"]) < TARGETS["scene_s"]
                                  for r in rows),
               all_under_60s=total < TARGETS["all_s"])
    # hertz on about 4,000 quads (64^2 = 4096), whole process
    n = 32 if quick else 64
    if quick:
        r = run_scene("hertz", "paper", {"n_el": n})
        process = process_cpu = None
    else:
        runs = [_process_time(["run", "hertz", "--preset", "paper", "--json", os.devnull]) for _ in range(3)]
        process, process_cpu = min(w for w, _ in runs), min(c for _, c in runs)      # best of 3
        r = run_scene("hertz", "paper", {"n_el": n})
    out["hertz"] = dict(n_quads=r["n_quads"], error_p0=r["error_p0"], solve_s=r["wall_time_s"], process_s=process,
                        process_cpu_s=process_cpu,
                        p0_within=abs(r["error_p0"]) < TARGETS["hertz_p0_error"],
                        under_1p5s=(process < TARGETS["hertz_process_s"]) if process is not None else None)
    out["process_overhead_s"], out["process_overhead_cpu_s"] = _process_time(["list"])  # imports, registry
    return out


# ---------------------------------------------------------------------------
# Driver, JSON and markdown
# ---------------------------------------------------------------------------

STUDIES = {"tangents": tangent_study, "work_precision": work_precision, "cost": cost_study,
           "targets": targets_study}


def machine():
    import scipy

    return dict(python=platform.python_version(), numpy=np.__version__, scipy=scipy.__version__,
                cpus=os.cpu_count(), platform=platform.platform(),
                load_average=list(os.getloadavg()) if hasattr(os, "getloadavg") else None)


def run_bench(quick=False, only=None, progress=print):
    """Run the studies (all, or those named in `only`); returns the JSON-able dict."""
    out = dict(quick=bool(quick), machine=machine(), target_values=TARGETS)
    for name, fn in STUDIES.items():
        if only and name not in only:
            continue
        if progress:
            progress(f"bench: {name} ...")
        res, dt = _timed(fn, quick)
        out[name] = res
        out[f"{name}_bench_s"] = dt
    return jsonable(out)


def _f(x, fmt="{:.3g}"):
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return fmt.format(x) if isinstance(x, (int, float)) else str(x)


# Measured on this machine during development (same scene, same preset, before and
# after each change; the tables above are from the current code).
OPTIMISATIONS = [
    "### Optimisations (before -> after, measured during development)", "",
    "| change | where | before | after |", "|---|---|---|---|",
    "| quadrature-point fields read as plain arrays in the weak forms (indexing a scikit-fem "
    "DiscreteField copies the whole field, once per basis-function pair) | bodies/continuum.py | "
    "tangent assembly, 4096 quads: 1.40 s | 0.17 s |",
    "| isotropic tangent as a broadcast view; plane tangent form without the zero hoop terms; "
    "no mass assembly for rho = 0 | bodies/continuum.py | hertz 64^2 solve: 0.97 s | 0.40 s |",
    "| SuperLU ordering MMD_AT_PLUS_A instead of COLAMD (symmetric sparsity pattern); no fancy "
    "indexing of K when every dof is free | solver/newton.py | rolling ring, paper preset: 7.1 s; "
    "factorisation at 1e5 unknowns: 2.4 s | 5.5 s; 1.4 s |",
    "| all of the above | | hertz 64^2, whole process: 4.0 s; svk block 4096 quads body.internal: 1.49 s "
    "| 1.2 s; 0.45 s |", "",
    "Not adopted: pypardiso (MKL PARDISO, installs from PyPI, about 0.8 s of import time and a large "
    "download): at 1e5 unknowns 1.0-1.4 s against 1.3-1.4 s for SuperLU with MMD_AT_PLUS_A, slower "
    "at the paper sizes; not a clear win. scikit-umfpack does not install from PyPI here (needs swig and "
    "SuiteSparse to build).", ""]


def write_markdown(res):
    """The tables of BENCHMARKS.md from a bench result."""
    L = ["# Benchmarks", "",
         "Written by `contactfem bench" + (" --quick" if res.get("quick") else "") + "` "
         "(contactfem/studies/bench.py); the raw numbers are in bench.json. Times are wall times "
         "on the machine below and move with its load; iteration counts do not.", "",
         "Machine: " + ", ".join(f"{k} {v}" for k, v in res.get("machine", {}).items()), ""]
    if "tangents" in res:
        tg = res["tangents"]
        L += ["## The paper's claim: consistent tangent against symmetric, frozen and staggered", "",
              "Linear solves (all Newton iterations of all phases) and time to the same tolerance "
              "(block: ||G|| <= 1e-12 + 1e-10 ||G_0||, one load step; sloping impact: 1e-10 + 1e-10 "
              "||G_0|| per step, cutbacks allowed). `frozen` drops the coupling c_N^s C of eq 50; "
              "`staggered` is the normal-then-friction algorithm of Sec. 2.2.", "",
              "| problem | variant | converged | linear solves | time [s] | notes |", "|---|---|---|---|---|---|"]
        for law, rows in tg["block"].items():
            for v, r in rows.items():
                note = r.get("error", "")
                if r.get("cycles") is not None:
                    note = f"{r['cycles']} cycles"
                if r.get("max_difference_to_consistent") is not None and v != "consistent":
                    note += f"; max |u - u_consistent| = {r['max_difference_to_consistent']:.1e}"
                L.append(f"| block, {law} | {v} | {_f(r['converged'])} | {_f(r['iterations'])} | "
                         f"{_f(r['time_s'])} | {note.strip('; ')} |")
        for v, r in tg["sloping_impact"].items():
            note = r.get("error", "") if not r["converged"] else (
                f"cuts {r['step_cuts']}, max {r['max_iterations_per_step']} per step, "
                f"rebound ({r['rebound_vx']:.3f}, {r['rebound_vy']:.3f})")
            L.append(f"| sloping impact, frictional, {tg['sloping_impact_steps']} steps | {v} | "
                     f"{_f(r['converged'])} | {_f(r['iterations'])} | {_f(r['time_s'])} | {note} |")
        L.append("")
    if "work_precision" in res:
        wp = res["work_precision"]
        L += ["## Work against precision", "", "### Hertz, mesh refinement (per-length penalty, exact p0)", "",
              "| n_el | quads | error p0 | error a (fit) | time [s] |", "|---|---|---|---|---|"]
        for r in wp["hertz_mesh"]["rows"]:
            if r["ok"]:
                L.append(f"| {r['n_el']} | {r['n_quads']} | {r['error_p0']:+.2e} | {r['error_a']:+.2e} | "
                         f"{_f(r['time_s'])} |")
        L += ["", f"Observed order of |error p0| in h = 1/n_el: {_f(wp['hertz_mesh']['order_p0'])}", ""]
        L += ["### Rolling ring (x_roll against the rigid ring with the model's gyration radius)", "",
              "| study | kind | n_el | dt | delta/beta | error x_roll | linear solves | cutbacks | time [s] |",
              "|---|---|---|---|---|---|---|---|---|"]
        for key, label in (("ring_dt_newmark_0.7/0.4", "dt"), ("ring_dt_newmark_0.5/0.25", "dt"),
                           ("ring_mesh", "mesh"), ("ring_kind", "kind")):
            for r in wp[key]["rows"]:
                nm = f"{r.get('delta', 0.7)}/{r.get('beta_newmark', 0.4)}"
                if not r["ok"]:
                    L.append(f"| {label} | {r.get('kind', 'beam')} | {r['n_el']} | {r['dt']} | {nm} | failed: "
                             f"{r['error'][:60]} | - | - | - |")
                    continue
                L.append(f"| {label} | {r.get('kind', 'beam')} | {r['n_el']} | {r['dt']} | {nm} | "
                         f"{_f(r['error_x_roll'], '{:.2e}')} | {r['iterations']} | {r['step_cuts_total']} | "
                         f"{_f(r['time_s'])} |")
        L += ["", "Observed orders of the x_roll error: " + ", ".join(
            f"{k}: {_f(wp[k]['order_x_roll'])}" for k in ("ring_dt_newmark_0.7/0.4", "ring_dt_newmark_0.5/0.25",
                                                         "ring_mesh")), ""]
        b = wp["bar_implicit_explicit"]
        L += [f"### Bar impact, {b['n_el']} elements: implicit Newmark 0.5/0.25 against explicit central "
              "differences", "", "| integrator | c dt / h | steps | linear solves | error duration | "
              "error rebound | energy error | time [s] |", "|---|---|---|---|---|---|---|---|"]
        for name, rows in (("Newmark", b["newmark"]), ("central differences", b["central_difference"])):
            for r in rows:
                L.append(f"| {name} | {r['courant']} | {r['steps']} | {r['iterations']} | "
                         f"{r['error_duration']:+.2e} | {r['error_rebound']:+.2e} | {r['energy_error']:+.1e} | "
                         f"{_f(r['time_s'])} |")
        L.append("")
    if "cost" in res:
        c = res["cost"]
        L += ["## Cost of one Newton iteration", "",
              "Best of a few repeats. bulk: body.internal (R and K of the bodies); contact: contact.assemble; "
              "assembly: the rest of System.residual_tangent (loads, COO -> CSR); solve: splu factor + solve "
              "of the free block (the ordering newton() uses, MMD_AT_PLUS_A; COLAMD is scipy's default).", "",
              "| case | unknowns | contact nodes | bulk [s] | contact [s] | assembly [s] | solve MMD [s] | "
              "solve COLAMD [s] | pypardiso [s] | contact share |", "|---|---|---|---|---|---|---|---|---|---|"]
        for name, r in c["cases"].items():
            tot = r["bulk_s"] + r["contact_s"] + r["assembly_s"] + r["solve_s"]
            L.append(f"| {name} | {r['ndof']} | {r['n_contact_nodes']} | {_f(r['bulk_s'])} | {_f(r['contact_s'])} | "
                     f"{_f(r['assembly_s'])} | {_f(r['solve_s'])} | {_f(r['solve_splu_COLAMD_s'])} | "
                     f"{_f(r['solve_pypardiso_s'])} | {r['contact_s'] / tot:.1%} |")
        n = np.array([r["n_contact_nodes"] for r in c["contact_scaling"]], float)
        tc = np.array([r["contact_s"] for r in c["contact_scaling"]])
        per_node, fixed = np.polyfit(n, tc, 1)
        L += ["", "Contact time against contact nodes: " + ", ".join(
            f"{int(a)}: {b * 1e3:.2f} ms" for a, b in zip(n, tc))
            + f"; log-log slope {c['contact_scaling_slope']:.2f}. A straight line fits it: "
            f"{fixed * 1e3:.2f} ms fixed (Python overhead) + {per_node * 1e6:.2f} us per contact node, "
            "i.e. linear in the contact nodes (the slope tends to 1 as the fixed part is amortised).", ""]
        L += OPTIMISATIONS
    if "targets" in res:
        t = res["targets"]
        L += [f"## Targets ({t['preset']} preset)", "",
              "solve: the scene's run() in this process; process: wall and CPU (user + sys) time of the whole "
              "`python -m contactfem run` (imports included; an empty `contactfem list` takes "
              f"{_f(t['process_overhead_s'])} s wall, {_f(t.get('process_overhead_cpu_s'))} s CPU here). "
              "The wall time exceeds the CPU time when the machine is loaded.", "",
              "| scene | variant | linear solves | solve [s] | process wall [s] | process CPU [s] | under 10 s |",
              "|---|---|---|---|---|---|---|"]
        for r in t["scenes"]:
            var = ", ".join(f"{k}={v}" for k, v in r["overrides"].items())
            if not r["ok"]:
                L.append(f"| {r['scene']} | {var} | failed: {r['error'][:80]} | - | - | - | no |")
                continue
            worst = max(r["solve_s"], r.get("process_s") or 0.0)
            L.append(f"| {r['scene']} | {var} | {r['iterations']} | {_f(r['solve_s'])} | {_f(r.get('process_s'))} | "
                     f"{_f(r.get('process_cpu_s'))} | {_f(worst < TARGETS['scene_s'])} |")
        h = t["hertz"]
        L += ["", f"All scenes together: {t['total_s']:.1f} s (target 60 s: {_f(t['all_under_60s'])}); "
              f"each under 10 s: {_f(t['each_under_10s'])}.", "",
              f"Hertz on {h['n_quads']} quads: p0 error {h['error_p0']:+.2%} (target 0.5 %: {_f(h['p0_within'])}), "
              f"solve {_f(h['solve_s'])} s, whole process {_f(h['process_s'])} s wall, "
              f"{_f(h.get('process_cpu_s'))} s CPU (best of 3; target 1.5 s wall: {_f(h['under_1p5s'])}).", ""]
    return "\n".join(L) + "\n"


def write_outputs(res, outdir):
    """bench.json and BENCHMARKS.md into outdir; returns the two paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    pj, pm = outdir / "bench.json", outdir / "BENCHMARKS.md"
    pj.write_text(json.dumps(res, indent=1))
    pm.write_text(write_markdown(res))
    return str(pj), str(pm)


def add_bench_parser(sub):
    """`contactfem bench [--quick] [--out DIR] [--only NAME ...]`."""
    bp = sub.add_parser("bench", help="speed against accuracy: tangents, work-precision, cost, targets "
                                      "(writes bench.json and BENCHMARKS.md)")
    bp.add_argument("--quick", action="store_true", help="fast presets and fewer points (about a minute)")
    bp.add_argument("--out", default=".", help="folder for bench.json and BENCHMARKS.md (default: .)")
    bp.add_argument("--only", action="append", choices=list(STUDIES),
                    help="run only this study (repeatable); the other studies of DIR/bench.json are kept")
    bp.set_defaults(func=cmd_bench)
    return bp


def cmd_bench(args):
    res = run_bench(quick=args.quick, only=args.only,
                    progress=lambda m: print(m, file=sys.stderr, flush=True))
    old = Path(args.out) / "bench.json"
    if args.only and old.exists():                  # keep the other studies of an earlier run
        res = dict(json.loads(old.read_text()), **res)
    for path in write_outputs(res, args.out):
        print(path)
