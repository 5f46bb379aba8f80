"""The one report writer of the bench: BENCHMARKS.md (markdown tables) and bench.json."""

import json
from pathlib import Path

import numpy as np

from ...problem.accuracy import ERROR_BUDGET
from .adaptive import STUDY
from .common import TARGETS
from .enforcement import enforcement_markdown
from .coverage import coverage_markdown
from .error_bars import error_bars_markdown
from .scaling import scaling_markdown
from .semismooth import semismooth_markdown
from .speed import PARTS, RINGS, SPEED_TARGETS, STARTUP_LAYERS


def _f(x, fmt="{:.3g}"):
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    return fmt.format(x) if isinstance(x, (int, float)) else str(x)


# Measured on this machine during development (same scene, same preset, before and
# after each change; the tables above are from the current code).
OPTIMISATIONS = [
    "### What made it fast (before -> after, each measured when it was introduced, not by this run)",
    "",
    "| change | where | before | after |",
    "|---|---|---|---|",
    "| quadrature-point fields read as plain arrays in the weak forms (indexing a scikit-fem "
    "DiscreteField copies the whole field, once per basis-function pair) | bodies/continuum.py | "
    "tangent assembly, 4096 quads: 1.40 s | 0.17 s |",
    "| isotropic tangent as a broadcast view; plane tangent form without the zero hoop terms; "
    "no mass assembly for rho = 0 | bodies/continuum.py | hertz 64^2 solve: 0.97 s | 0.40 s |",
    "| SuperLU ordering MMD_AT_PLUS_A instead of COLAMD (symmetric sparsity pattern); no fancy "
    "indexing of K when every dof is free | solver/newton.py | rolling ring, paper preset: 7.1 s; "
    "factorisation at 1e5 unknowns: 2.4 s | 5.5 s; 1.4 s |",
    "| all of the above | | hertz 64^2, whole process: 4.0 s; svk block 4096 quads body.internal: 1.49 s "
    "| 1.2 s; 0.45 s |",
    "| lazy imports: a scene module takes scikit-fem and the continuum bodies as lazy modules (lazy.py), "
    "loaded when it builds; the solver loads scipy on a sparse K; xml (and urllib) only when writing ParaView files "
    "| scenes/, bodies/, solver/, io/paraview.py | `contactfem list`: 0.59 s CPU (median of 5, loaded machine) "
    "| 0.20-0.25 s CPU |",
    "| K dense (LAPACK) up to 100 unknowns, a fixed CSC pattern above (values scattered with one bincount); "
    "the Newmark mass term added on the pattern's diagonal; the beam kernel without repeated strains and "
    "einsum temporaries, as COO triplets on its fixed connectivity; contact elements of the active pairs "
    "only, scattered with bincount; the return map skips a body in flight "
    "| solver/assembly.py, solver/system.py, solver/newton.py, bodies/beam.py, contact/interface.py, "
    "laws/return_map.py | one Newton iteration inside the paper runs (CPU, loaded machine; midpoint beam): "
    "sloping impact 2.2-2.6 ms, rolling ring 3.0 ms | 0.69-0.89 ms; 2.1 ms |",
    "| banded LU: the fixed pattern's free block renumbered by reverse Cuthill-McKee once per pattern, "
    "LAPACK's dgbsv when its work per unknown kl (kl + ku) is at most 1.5e4 (rolling ring kl = ku = 8, block 35, "
    "cork 28; Hertz, 258, stays on SuperLU); K a shallow copy of one CSC matrix of the pattern (no scipy "
    "format checks at every assembly) | solver/banded.py, solver/assembly.py, solver/newton.py | one Newton "
    "iteration inside the paper runs (CPU, best of 5 (cork, Hertz: 3), loaded machine): rolling ring 1.17 ms "
    "(solve 0.41, "
    "assembly 0.16), block 1.64 ms (solve 0.92); cork solve 1.32 ms; Hertz assembly 1.64 ms "
    "| 0.69 ms (0.071, 0.092), 0.74 ms (0.21); 0.17 ms; 1.24 ms |",
    "| the fixed pattern built by one stable argsort of its keys and a mask of the first of each run (the "
    "positions of the first assembly from the same sort) instead of numpy's union1d; the band plan only where a "
    "breadth-first bound leaves the band LU possible; the linear continuum's energy u.K u / 2 and its K from C "
    "directly (no quadrature-point fields) | solver/assembly.py, solver/banded.py, bodies/continuum.py | Hertz on "
    "65k quads (CPU, thread of the run, loaded machine): union1d 2.5 s, band plan 0.35-0.45 s, strain energy "
    "0.1-0.4 s a call (two a run); whole process 9.6 s wall, 7.6 s user, against 7.3 s and 4.7 s for the code "
    "before the fixed pattern (one run each) | first assembly 0.16-0.25 s, no plan, a few ms; whole process "
    "against the code before the fixed pattern (median ratio of 8 pairs, load 9 on 2 cores): CPU 0.81, wall 0.84 |",
    "| a run of rings loads no scipy or scikit-fem: contactfem.io loads each name on first use, the beam's "
    "lumped mass summed with numpy | io/__init__.py, bodies/beam.py | `contactfem run sloping_impact --set "
    "n_steps=5`, whole process (median of 10, load 11 on 2 cores): 0.73 s CPU | 0.32 s CPU; the ratio of 10 pairs "
    "(median): CPU 0.46, wall 0.42 |",
    "| the linear material's K from its own form (lam tr eps tr eps + 2 mu eps : eps, no sum over the 16 "
    "entries of C) and kept as CSC (the pattern's order: its first placement sorts presorted keys); above 1e4 free "
    "unknowns SuperLU after METIS's nested-dissection renumbering (pymetis) instead of its own minimum-degree "
    "ordering; below 1e4 free dofs the band plan without the breadth-first bound | bodies/continuum.py, "
    "solver/dissection.py, solver/assembly.py, solver/banded.py | Hertz, run_scene in one process (wall, best of 3, "
    "65k: of 2; loaded machine, 2 interleaved runs): 1k quads 34-45 ms, 16k 0.71-0.77 s, 65k 3.9-4.0 s; 65k, "
    "first run in a fresh process, against the code before the fixed pattern (3 pairs): 8.3-9.3 s "
    "| 27-36 ms, 0.58-0.63 s, 2.8-3.1 s; 3.5-4.1 s |",
    "",
    "Not adopted (measured when the solvers were chosen, not by this run): pypardiso (MKL PARDISO, installs "
    "from PyPI, about 0.8 s of import time and a large download): at 1e5 unknowns 1.0-1.4 s against 1.3-1.4 s "
    "for SuperLU with MMD_AT_PLUS_A, slower at the paper sizes; not a clear win. scikit-umfpack did not install "
    "from PyPI (it needs swig and SuiteSparse to build). The pypardiso column of the cost table is filled "
    "where it is installed.",
    "",
]


def _ms(x):
    return "-" if x is None else f"{1e3 * x:.3f}"


def startup_account(s):
    """The block's start-up layer by layer (whole processes, the same medians): what it loads that
    it cannot do without, against `import skfem` (the target) and `import numpy`, and a run of rings."""
    if "numpy" not in s:  # a bench.json from before this table
        return []
    T, base = SPEED_TARGETS, s["numpy"]["wall_s"]
    L = [
        "What the block's process loads, layer by layer (each line a whole process, the same medians; "
        "added: its wall time less the line above's):",
        "",
        "| process | wall [s] | CPU [s] | added [s] | x `import numpy` |",
        "|---|---|---|---|---|",
    ]
    prev = s["python"]["wall_s"]
    L.append(f"| `python -c pass` | {prev:.3f} | {s['python']['cpu_s']:.3f} | - | {prev / base:.2f} |")
    for key, _, label in STARTUP_LAYERS:
        w = s[key]["wall_s"]
        L.append(f"| {label} | {w:.3f} | {s[key]['cpu_s']:.3f} | {w - prev:+.3f} | {w / base:.2f} |")
        prev = w
    key, _, label = RINGS
    L.append(f"| {label} | {s[key]['wall_s']:.3f} | {s[key]['cpu_s']:.3f} | - | {s[key]['wall_s'] / base:.2f} |")
    block, skfem, sparse = s["run_block_canonical"]["wall_s"], s["skfem"]["wall_s"], s["scipy_sparse"]["wall_s"]
    loads = s["loads"]
    rings = ", ".join(loads["run_rings"]) or "none of scipy.sparse, scipy.linalg, scikit-fem and matplotlib"
    L += [
        "",
        f"The block (canonical preset, banded K) takes {block / skfem:.2f} x `import skfem` "
        f"(target {T['run_block_canonical_over_skfem']}: {_f(block / skfem <= T['run_block_canonical_over_skfem'])}), "
        f"{s['run_block_canonical_over_numpy']:.2f} x `import numpy`. "
        f"Importing scikit-fem alone takes {s['skfem_over_numpy']:.2f} x: the block's forms need its assembly "
        "(Basis, BilinearForm, asm), and `import skfem.assembly` runs the package's `__init__`, which loads "
        f"{', '.join(loads['skfem_assembly'])} ({skfem - sparse:+.3f} s over scipy.sparse, scikit-fem's own "
        f"modules included; scipy.sparse itself {sparse - base:+.3f} s over numpy). The block's run loads "
        f"{', '.join(loads['run_block_canonical'])}; contactfem's code, the model and the run add "
        f"{block - skfem:+.3f} s to `import skfem`. The run of rings loads {rings}: "
        f"{s['run_rings_over_numpy']:.2f} x `import numpy`.",
        "",
    ]
    return L


def iteration_account(sp):
    """Where the microseconds of one iteration of the sloping impact (frictional, 48 unknowns) go,
    beside the floor of this Python (speed.iteration_limit): the row of the table above."""
    lim = sp.get("limit")
    rows = [
        r for r in sp["iterations"] if r["scene"] == "sloping_impact" and r["overrides"].get("variant") == "frictional"
    ]
    if not lim or not rows:  # a bench.json from before this account
        return []
    r = rows[0]
    n = r["newton_iterations_total"]
    us = lambda x: f"{1e6 * x:.0f}"  # noqa: E731
    wall = r["wall_time_s"] / n
    rest = wall - r["iteration_s"]
    thread = r.get("run_thread_s")
    cpu = "" if thread is None else f" (CPU {us(thread / n - r['iteration_s'])})"
    cpu_run = "" if thread is None else f" (CPU of the thread {us(thread / n)}, modules loaded on first use included)"
    evals = r["residual_evaluations"] / max(r["solves"], 1)
    L = [
        "",
        f"### Where the microseconds of one iteration go: sloping impact, frictional ({r['ndof']} unknowns, "
        f"{r['preset']} preset)",
        "",
        f"The floor in this Python: the ring's {lim['entries']} tangent entries and its diagonal c M summed into a "
        f"dense {lim['n']} x {lim['n']} K by one bincount ({us(lim['assembly_s'])} us alone) and K du = -G solved by "
        f"LAPACK ({us(lim['solve_s'])} us alone): {us(lim['limit_s'])} us in one loop doing both (CPU, best of 7 "
        "loops of 200 calls each; "
        "speed.iteration_limit). One iteration of the run, part by part (the row above, CPU microseconds of "
        f"the thread over its {r['solves']} linear solves; {evals:.2f} residual evaluations per solve, as a "
        "converged step evaluates once more than it solves):",
        "",
        "| part | us per iteration | what it is |",
        "|---|---|---|",
        f"| bulk | {us(r['bulk_s'])} | the ring's internal forces and tangent (R and the {lim['entries']} entries "
        "of K, bodies/beam.py) |",
        f"| contact | {us(r['contact_s'])} | the contact's kinematics, return map, element and scatter |",
        f"| assembly | {us(r['assembly_s'])} | summing the contributions and c M into K (one bincount) |",
        f"| solve | {us(r['solve_s'])} | LAPACK's LU of K (numpy.linalg.solve) |",
        f"| overhead | {us(r['overhead_s'])} | the rest of newton() and the time stepper's effective residual |",
        f"| Newton | {us(r['iteration_s'])} | the sum: CPU of newton() per solve |",
        f"| the rest of the run | {us(rest)}{cpu} | the run's wall time over its iterations less Newton's: the steps' "
        "commits, energies and records, building the model and measuring (on a loaded machine, waiting for a "
        "core too) |",
        f"| run | {us(wall)}{cpu_run} | wall_time_s / newton_iterations_total ({n} iterations) |",
        "",
        f"Assembly and solve take {us(r['assembly_s'] + r['solve_s'])} us, against the floor's "
        f"{us(lim['limit_s'])} us; the iteration is {wall / lim['limit_s']:.1f} x the floor.",
    ]
    if lim.get("numpy_call_s"):
        other = r["iteration_s"] - r["solve_s"] - lim["assembly_s"]
        L[-1] += (
            f" The rest of Newton's time, {us(other)} us, is Python around the numbers: the time of "
            f"{other / lim['numpy_call_s']:.0f} calls like the product of two arrays of 32 entries "
            f"({1e9 * lim['numpy_call_s']:.0f} ns each, measured like the floor): the beam's kernel over its "
            "integration points, the contact's kinematics and return map over its slave nodes, the element of "
            "the nodes in contact, Newton's loop, each a sequence of numpy calls on arrays of a few dozen "
            "entries."
        )
    return L


def speed_section(sp):
    """Study 5 (speed): start-up, the split of one Newton iteration, the Table 2 sweep."""
    T = SPEED_TARGETS
    s = sp["startup"]
    load = sp.get("load_average")
    L = ["## Start-up, and one Newton iteration inside the paper runs", ""]
    if load and load[0] > 1.5:
        L += [
            f"The machine was loaded when this ran (load average {load[0]:.1f} on 2 cores): wall times include "
            "waiting for a core and CPU times are inflated by the other processes sharing the caches; the "
            "targets are for a quiet machine.",
            "",
        ]
    compiled = {
        True: "contactfem's modules compiled to bytecode beforehand, as pip compiles an installed "
        "package and as the libraries are",
        False: "contactfem's bytecode could not be written (a read-only install is compiled by pip)",
        None: "bytecode not checked",
    }[s.get("bytecode_compiled")]
    if s.get("dont_write_bytecode"):
        compiled += (
            "; this machine sets PYTHONDONTWRITEBYTECODE, under which an editable install that was never "
            "compiled compiles its modules at every start (0.05-0.08 s more where this was measured)"
        )
    n_runs = len(s["python"]["walls_s"])
    L += [
        f"Start-up: whole processes, "
        + (f"median of {n_runs} runs" if n_runs > 1 else "one run")
        + " (wall and CPU seconds; "
        f"{compiled}).",
        "",
        "| process | wall [s] | CPU [s] |",
        "|---|---|---|",
    ]
    names = {
        "python": "`python -c pass`",
        "list": "`contactfem list`",
        "scipy_skfem": '`python -c "import scipy.sparse.linalg, skfem"`',
        "run_block": "`contactfem run block --preset paper`",
    }
    for key, label in names.items():
        L.append(f"| {label} | {s[key]['wall_s']:.3f} | {s[key]['cpu_s']:.3f} |")
    L += [
        "",
        f"`contactfem list`: {s['list']['wall_s']:.3f} s, {s['list_over_python']:.1f} x `python -c pass` "
        f"(target {T['list_s']} s: {_f(s['list']['wall_s'] < T['list_s'])}). "
        f"`contactfem run block --preset paper`: {s['run_block_over_scipy_skfem']:.2f} x an interpreter that "
        f"imports scipy.sparse.linalg and scikit-fem (target {T['run_block_over_scipy_skfem']}: "
        f"{_f(s['run_block_over_scipy_skfem'] <= T['run_block_over_scipy_skfem'])}).",
        "",
    ]
    L += startup_account(s)
    L += [
        "One Newton iteration, CPU milliseconds of the thread that runs it: the run's totals inside Newton divided "
        "by its linear solves (the initial state's evaluation, before the first step, is not in them: it also pays "
        "for what a first evaluation loads and builds, scipy's modules and the tangent's pattern), each scene "
        "run in a fresh interpreter, " + ("one run" if sp.get("preset") == "fast" else "best of 3 runs") + " "
        "(contactfem/lab/bench/speed.py). bulk: the bodies' internal forces and tangents; contact: every "
        "contact's residual and tangent; assembly: summing them into K, loads included; solve: factorisation "
        "and solve; overhead: the rest of newton() and the time stepper's effective residual. K: dense "
        "(LAPACK) up to 100 unknowns; above, a fixed pattern, solved banded (reverse Cuthill-McKee, LAPACK's "
        "band LU) where the band is narrow, else sparse (SuperLU). run: wall time of the whole run in that "
        "interpreter (building the model and its lazy imports included).",
        "",
        "| scene | unknowns | K | iteration [ms] | bulk | contact | assembly | solve | overhead | solves | run [s] |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in sp["iterations"]:
        label = r["scene"] + "".join(f", {v}" for v in r["overrides"].values())
        L.append(
            f"| {label} | {r['ndof'] or '-'} | {r['linear_algebra'] or '-'} | {_ms(r['iteration_s'])} | "
            + " | ".join(_ms(r[f"{p}_s"]) for p in PARTS)
            + f" | {r['solves']} | {r['run_wall_s']:.2f} |"
        )
    goals = {
        ("sloping_impact", "frictional"): "sloping_impact_iteration_s",
        ("rolling_ring", None): "rolling_ring_iteration_s",
    }
    for r in sp["iterations"]:
        key = goals.get((r["scene"], r["overrides"].get("variant")))
        if key and r["preset"] == "paper":
            wall = r["wall_time_s"] / r["newton_iterations_total"]
            L.append(
                f"\n{r['scene']}: {_ms(wall)} ms per iteration, the run's own wall time over its Newton "
                f"iterations (wall_time_s / newton_iterations_total; target {1e3 * T[key]:g} ms: "
                f"{_f(wall <= T[key])}); Newton's CPU time {_ms(r['iteration_s'])} ms of it."
            )
    L += iteration_account(sp)
    t2 = sp.get("table2")
    if t2:
        L += [
            "",
            "### Table 2: convergence of the rebound under refinement",
            "",
            "Each line is one run of the two sweeps below (paper data, Newmark 0.7/0.4; the paper prints two "
            "digits). Wall time: "
            + "; ".join(f"`{sw['command']}` {sw['wall_s']:.1f} s" for sw in t2["sweeps"])
            + f"; together {t2['total_wall_s']:.1f} s (target {T['table2_s']:g} s: "
            f"{_f(t2['total_wall_s'] < T['table2_s'])}); CPU time of all processes "
            f"{_f(t2.get('total_cpu_s'))} s, i.e. {_f((t2.get('total_cpu_s') or 0) / max(t2.get('jobs', 2), 1))} s "
            "on the 2 cores if nothing else ran.",
            "",
            "| variant | elements | dt | v_x | v_y | angle [deg] | spin | linear solves | paper v_x, v_y, angle |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for r in t2["rows"]:
            p = r["paper"]
            ref = f"{p['vx']}, {p['vy']}, {p['angle_deg']}" if p else "-"
            if r["error"]:
                L.append(f"| {r['variant']} | {r['n_el']} | {r['dt']:g} | failed: {r['error'][:60]} | | | | | {ref} |")
                continue
            L.append(
                f"| {r['variant']} | {r['n_el']} | {r['dt']:g} | {r['rebound_vx']:.3f} | {r['rebound_vy']:.3f} | "
                f"{r['rebound_angle_deg']:.1f} | {r['rebound_spin']:.4f} | {int(r['newton_iterations_total'])} | "
                f"{ref} |"
            )
    return L + [""]


def write_markdown(res):
    """The tables of BENCHMARKS.md from a bench result."""
    L = [
        "# Benchmarks",
        "",
        "Written by `contactfem bench" + (" --quick" if res.get("quick") else "") + "` "
        "(contactfem/lab/bench/); the raw numbers are in bench.json. Times are wall times, or CPU "
        "times where a table says so, on the machine below; they move with its load, iteration counts "
        "do not.",
        "",
        "Machine: " + ", ".join(f"{k} {v}" for k, v in res.get("machine", {}).items()),
        "",
    ]
    if "tangents" in res:
        tg = res["tangents"]
        L += [
            "## The paper's claim: consistent tangent against symmetric, frozen and staggered",
            "",
            "Linear solves (all Newton iterations of all phases) and time to the same tolerance "
            "(block: ||G|| <= 1e-12 + 1e-10 ||G_0||, one load step; sloping impact: 1e-10 + 1e-10 "
            "||G_0|| per step, cutbacks allowed). `frozen` drops the coupling c_N^s C of eq 50; "
            "`staggered` is the normal-then-friction algorithm of Sec. 2.2.",
            "",
            "| problem | variant | converged | linear solves | time [s] | notes |",
            "|---|---|---|---|---|---|",
        ]
        for law, rows in tg["block"].items():
            for v, r in rows.items():
                note = r.get("error", "")
                if r.get("cycles") is not None:
                    note = f"{r['cycles']} cycles"
                if r.get("max_difference_to_consistent") is not None and v != "consistent":
                    note += f"; max |u - u_consistent| = {r['max_difference_to_consistent']:.1e}"
                L.append(
                    f"| block, {law} | {v} | {_f(r['converged'])} | {_f(r['iterations'])} | "
                    f"{_f(r['time_s'])} | {note.strip('; ')} |"
                )
        for v, r in tg["sloping_impact"].items():
            note = (
                r.get("error", "")
                if not r["converged"]
                else (
                    f"cuts {r['step_cuts']}, max {r['max_iterations_per_step']} per step, "
                    f"rebound ({r['rebound_vx']:.3f}, {r['rebound_vy']:.3f})"
                )
            )
            L.append(
                f"| sloping impact, frictional, {tg['sloping_impact_steps']} steps | {v} | "
                f"{_f(r['converged'])} | {_f(r['iterations'])} | {_f(r['time_s'])} | {note} |"
            )
        L.append("")
    if "work_precision" in res:
        wp = res["work_precision"]
        L += [
            "## Work against precision",
            "",
            "### Hertz, mesh refinement (per-length penalty, exact p0)",
            "",
            "| n_el | quads | error p0 | error a (fit) | time [s] |",
            "|---|---|---|---|---|",
        ]
        for r in wp["hertz_mesh"]["rows"]:
            if r["ok"]:
                L.append(
                    f"| {r['n_el']} | {r['n_quads']} | {r['error_p0']:+.2e} | {r['error_a']:+.2e} | {_f(r['time_s'])} |"
                )
        L += [
            "",
            f"Observed order of |error p0| in h = 1/n_el: {_f(wp['hertz_mesh']['order_p0'])}"
            + " (a least-squares slope through all points: an order of convergence only where the error falls "
            "steadily, not where it levels off at another error's floor or changes sign)" + ".",
            "",
        ]
        L += [
            "### Rolling ring (x_roll against the rigid ring with the model's gyration radius)",
            "",
            "| study | kind | n_el | dt | delta/beta | error x_roll | linear solves | cutbacks | time [s] |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for key, label in (
            ("ring_dt_newmark_0.7/0.4", "dt"),
            ("ring_dt_newmark_0.5/0.25", "dt"),
            ("ring_mesh", "mesh"),
            ("ring_kind", "kind"),
        ):
            for r in wp[key]["rows"]:
                nm = f"{r.get('delta', 0.7)}/{r.get('beta_newmark', 0.4)}"
                if not r["ok"]:
                    L.append(
                        f"| {label} | {r.get('kind', 'beam')} | {r['n_el']} | {r['dt']} | {nm} | failed: "
                        f"{r['error'][:60]} | - | - | - |"
                    )
                    continue
                L.append(
                    f"| {label} | {r.get('kind', 'beam')} | {r['n_el']} | {r['dt']} | {nm} | "
                    f"{_f(r['error_x_roll'], '{:.2e}')} | {r['iterations']} | {r['step_cuts_total']} | "
                    f"{_f(r['time_s'])} |"
                )
        L += [
            "",
            "Observed orders of the x_roll error: "
            + ", ".join(
                f"{k}: {_f(wp[k]['order_x_roll'])}"
                for k in ("ring_dt_newmark_0.7/0.4", "ring_dt_newmark_0.5/0.25", "ring_mesh")
            )
            + " (a least-squares slope through all points: an order of convergence only where the error falls "
            "steadily, not where it levels off at another error's floor or changes sign)" + ".",
            "",
        ]
        b = wp["bar_implicit_explicit"]
        L += [
            f"### Bar impact, {b['n_el']} elements: implicit Newmark 0.5/0.25 against explicit central differences",
            "",
            "| integrator | c dt / h | steps | linear solves | error duration | "
            "error rebound | energy error | time [s] |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for name, rows in (("Newmark", b["newmark"]), ("central differences", b["central_difference"])):
            for r in rows:
                L.append(
                    f"| {name} | {r['courant']} | {r['steps']} | {r['iterations']} | "
                    f"{r['error_duration']:+.2e} | {r['error_rebound']:+.2e} | {r['energy_error']:+.1e} | "
                    f"{_f(r['time_s'])} |"
                )
        L.append("")
    if "cost" in res:
        c = res["cost"]
        L += [
            "## Cost of one Newton iteration, part by part (isolated calls at one state)",
            "",
            "Best of a few repeats. bulk: the bodies' R and K as the System evaluates them (a beam's COO triplets, "
            "a continuum's sparse K); contact: contact.assemble; "
            "assembly: the rest of System.residual_tangent (loads, summing the triplets into K); solve: "
            "factorisation + solve of the free block by LAPACK's band LU where the System solves banded (band), "
            "by SuperLU after the "
            "pattern's nested-dissection renumbering where it has one (ND: from 1e4 free unknowns; METIS's "
            "ordering, made once per pattern like the band plan, not included), else by splu with "
            "the ordering newton() uses (MMD_AT_PLUS_A); SuperLU with each ordering for comparison (COLAMD is "
            "scipy's default).",
            "",
            "| case | unknowns | contact nodes | bulk [s] | contact [s] | assembly [s] | solve [s] | "
            "solve MMD [s] | solve COLAMD [s] | pypardiso [s] | contact share |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for name, r in c["cases"].items():
            tot = r["bulk_s"] + r["contact_s"] + r["assembly_s"] + r["solve_s"]
            band = (
                " (band)"
                if r.get("solve_banded_s") is not None
                else " (ND)"
                if r.get("solve_dissection_s") is not None
                else ""
            )
            L.append(
                f"| {name} | {r['ndof']} | {r['n_contact_nodes']} | {_f(r['bulk_s'])} | {_f(r['contact_s'])} | "
                f"{_f(r['assembly_s']) if r['assembly_s'] > 0 else '~0 (noise)'} | {_f(r['solve_s'])}{band} | "
                f"{_f(r['solve_splu_MMD_AT_PLUS_A_s'])} | "
                f"{_f(r['solve_splu_COLAMD_s'])} | {_f(r['solve_pypardiso_s'])} | {r['contact_s'] / tot:.1%} |"
            )
        n = np.array([r["n_contact_nodes"] for r in c["contact_scaling"]], float)
        tc = np.array([r["contact_s"] for r in c["contact_scaling"]])
        per_node, fixed = np.polyfit(n, tc, 1)
        L += [
            "",
            "Contact time against contact nodes: "
            + ", ".join(f"{int(a)}: {b * 1e3:.2f} ms" for a, b in zip(n, tc))
            + f"; log-log slope {c['contact_scaling_slope']:.2f}. A straight line fits it: "
            f"{fixed * 1e3:.2f} ms fixed (the cost of the calls, whatever the size) + {per_node * 1e6:.2f} us per "
            "contact node, "
            "i.e. linear in the contact nodes (the slope tends to 1 as the fixed part is amortised).",
            "",
        ]
        L += OPTIMISATIONS
    if "targets" in res:
        t = res["targets"]
        L += [
            f"## Targets ({t['preset']} preset)",
            "",
            "solve: the scene's run() in this process; process: wall and CPU (user + sys) time of one whole "
            "`python -m contactfem run` (one run each, imports included: a single sample, see the start-up "
            "section for medians; an empty `contactfem list` takes "
            f"{_f(t['process_overhead_s'])} s wall, {_f(t.get('process_overhead_cpu_s'))} s CPU here). "
            "The wall time exceeds the CPU time when the machine is loaded.",
            "",
            "| scene | variant | linear solves | solve [s] | process wall [s] | process CPU [s] | under 10 s |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in t["scenes"]:
            var = ", ".join(f"{k}={v}" for k, v in r["overrides"].items())
            if not r["ok"]:
                L.append(f"| {r['scene']} | {var} | failed: {r['error'][:80]} | - | - | - | no |")
                continue
            worst = max(r["solve_s"], r.get("process_s") or 0.0)
            L.append(
                f"| {r['scene']} | {var} | {r['iterations']} | {_f(r['solve_s'])} | {_f(r.get('process_s'))} | "
                f"{_f(r.get('process_cpu_s'))} | {_f(worst < TARGETS['scene_s'])} |"
            )
        h = t["hertz"]
        if t["preset"] == "paper":
            L += [
                "",
                f"All scenes together: {t['total_s']:.1f} s (target 60 s: {_f(t['all_under_60s'])}); "
                f"each under 10 s: {_f(t['each_under_10s'])}.",
                "",
                f"Hertz on {h['n_quads']} quads: p0 error {h['error_p0']:+.2%} (target 0.5 %: "
                f"{_f(h['p0_within'])}), solve {_f(h['solve_s'])} s, whole process {_f(h['process_s'])} s wall, "
                f"{_f(h.get('process_cpu_s'))} s CPU (best of 3; target 1.5 s wall: {_f(h['under_1p5s'])}).",
                "",
            ]
        else:  # a quick run: a few scenes, no whole processes
            L += [
                "",
                f"{len(t['scenes'])} scenes at the {t['preset']} preset, {t['total_s']:.1f} s together "
                "(the targets are for the paper preset: `contactfem bench`).",
                "",
                f"Hertz on {h['n_quads']} quads: p0 error {h['error_p0']:+.2%} (target 0.5 % on about 4,000 "
                f"quads: {_f(h['p0_within'])}), solve {_f(h['solve_s'])} s.",
                "",
            ]
    if "enforcement" in res:
        L += enforcement_markdown(res["enforcement"])
    if "speed" in res:
        L += speed_section(res["speed"])
    if "semismooth" in res:
        L += semismooth_markdown(res["semismooth"])
    if "scaling" in res:
        L += scaling_markdown(res["scaling"])
    if "coverage" in res:
        L += coverage_markdown(res["coverage"])
    if "adaptive" in res:
        L += adaptive_markdown(res["adaptive"])
    if "error_bars" in res:
        L += error_bars_markdown(res["error_bars"])
    return "\n".join(L) + "\n"


ADAPTIVE_NOTES = {
    "sloping_impact": "The first 3 time units (the ring leaves the plane at ~2.5), for the fixed and the "
    "adaptive runs alike.",
    "rolling_ring": "The paper's ring of 120 elements: the fast preset's 40 elements have no converged "
    "v_final (its fixed steps do not settle as dt is refined).",
    "cork": "Fixed steps: the scene's schedule with dt_fine = h from the start to the end (exit_zone "
    "1e3 mm, travel_max 1e-9 mm); dt (1e-4 s) stays, as it sets the gas's ramp, a staircase "
    "the steps resolve.",
}


def adaptive_markdown(ad):
    """Study 10: fixed steps against the adaptive mode, per scene (lab/bench/adaptive.py)."""
    L = [
        "## A tolerance against fixed steps (accuracy = TOL)",
        "",
        "Each scene's headline quantities against a reference refined in time (fixed steps h_ref with the "
        "integrator named; Richardson's extrapolation from h_ref and 2 h_ref where that run is first order: "
        "Newmark delta = 0.7, or the cork's explicitly coupled gas); error: the largest relative error of the "
        "headline quantities; cost: residual evaluations (every Newton iteration, those of rejected and halved "
        "steps too). Fixed steps with the scene's preset integrator and with the trapezoidal rule (the one a run "
        "at a tolerance integrates with). `fixed match`: the largest fixed step of each ladder whose error, and "
        "that of every finer step of the ladder, is at most the adaptive run's (a step whose error merely dips "
        "below is not one a user refining until the result settles would pick; an error below the reference's own "
        "change is matched at that change), and its cost; and the largest "
        "fixed step that stays within the tolerance itself (what a run at that tolerance could have cost).",
        "",
    ]
    for name, s in ad["scenes"].items():
        if not s.get("fixed"):
            L += [f"### {name}: the reference failed", ""]
            continue
        ref = ", ".join(f"{k} = {v:.6g}" for k, v in s["reference"].items())
        L += [
            f"### {name} ({s['preset']} preset): {ref}",
            "",
            f"Reference: {s['step']} = {s['h_reference']:g} ({s.get('reference_with', 'preset')}), its own change "
            f"{_f(s['reference_change'])}. " + ADAPTIVE_NOTES.get(name, ""),
            "",
            "| run | error | residual evaluations | Newton iterations | steps | time [s] | fixed match (evaluations) |",
            "|---|---|---|---|---|---|---|",
        ]
        for label, ladder in (("preset", s["fixed"]), ("trapezoidal", s.get("fixed_trapezoidal") or [])):
            for f in ladder:
                L.append(
                    f"| {s['step']} = {f['h']:g}, {label} | {_f(f.get('error'))} | "
                    f"{f.get('residual_evaluations', '-')} | {f.get('newton_iterations', '-')} | "
                    f"{f.get('steps', '-')} | {_f(f.get('wall_time_s'))} | |"
                )
        for a in s["adaptive"]:
            matches = []
            for label, key in (("preset", "fixed_match"), ("trapezoidal", "trapezoidal_match")):
                m = a.get(key)
                if m:
                    matches.append(f"{label} {s['step']} = {m['h']:g} ({m['residual_evaluations']})")
            tm = a.get("tolerance_match")
            if tm:
                matches.append(
                    f"within the tolerance itself: {tm['integrator']} {s['step']} = {tm['h']:g} "
                    f"({tm['residual_evaluations']})"
                )
            L.append(
                f"| accuracy = {a['accuracy']:g} | {_f(a.get('error'))} | {a.get('residual_evaluations', '-')} | "
                f"{a.get('newton_iterations', '-')} | {a.get('steps', '-')} | {_f(a.get('wall_time_s'))} | "
                f"{'; '.join(matches) or 'none of the ladders'} |"
            )
        L.append("")
    return L


def write_outputs(res, outdir):
    """bench.json and BENCHMARKS.md into outdir; returns the two paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    pj, pm = outdir / "bench.json", outdir / "BENCHMARKS.md"
    pj.write_text(json.dumps(res, indent=1))
    pm.write_text(write_markdown(res))
    return str(pj), str(pm)


def _verdict(a, matches, reference_change):
    """Whether a run at a tolerance met it (judged only where the reference is finer than it) and
    cost no more than the cheapest fixed step (of either ladder) that reaches its error."""
    tol = a["accuracy"]
    if reference_change > tol / 2:
        met = f"not judged (the reference itself moves by {reference_change:.1e})"
    else:
        met = "within the tolerance" if a["error"] <= tol else "**above the tolerance**"
    matches = [m for m in matches if m]
    if not matches:
        return met
    cheaper = a["residual_evaluations"] <= min(m["residual_evaluations"] for m in matches)
    return met + (", at no more cost than fixed steps" if cheaper else ", **costlier than fixed steps**")


def _match_text(step, m, integrator):
    if m is None:
        return f"no fixed step of the {integrator} reaches that error"
    return (
        f"the largest fixed step of the {integrator} reaching it and staying there, {step} = {m['h']:g}, needs "
        f"{m['residual_evaluations']}"
    )


def adaptive_sentences(ad):
    """The README's account of study 10 (its block adaptive, lab/readme.py), one line per scene."""
    lines = []
    for name, s in ad["scenes"].items():
        if not s.get("fixed"):
            continue
        parts = []
        for a in s["adaptive"]:
            if a.get("error") is None:
                parts.append(f"accuracy = {a['accuracy']:g} failed ({a.get('failure', 'no headline value')})")
                continue
            against = [_match_text(s["step"], a.get("fixed_match"), "preset")]
            if s.get("fixed_trapezoidal"):
                against.append(_match_text(s["step"], a.get("trapezoidal_match"), "trapezoidal rule"))
            tm = a.get("tolerance_match")
            if tm:
                named = {"preset": "preset", "trapezoidal": "trapezoidal rule"}.get(tm["integrator"], tm["integrator"])
                against.append(
                    f"fixed steps that stay within the tolerance itself: the {named}'s "
                    f"{s['step']} = {tm['h']:g}, {tm['residual_evaluations']}"
                )
            budget = a.get("error_budget")
            own = (
                ""
                if budget is None
                else (
                    f", its own error estimate {budget:.2f} times what the tolerance allows"
                    + (" (it warns: not assured)" if budget > ERROR_BUDGET else "")
                )
            )
            ran = "".join(f", {k} = {a[k]:g}" for k in STUDY.get(name, {}).get("adaptive", {}) if k in a)
            parts.append(
                f"accuracy = {a['accuracy']:g} ({s.get('preset', 'fast')} preset{ran}): error {a['error']:.1e}{own}, "
                f"with {a['residual_evaluations']} "
                f"residual evaluations in {a['steps']} steps of {a['dt_min']:.2g} to {a['dt_max']:.2g} "
                f"({'; '.join(against)}): "
                f"{_verdict(a, (a.get('fixed_match'), a.get('trapezoidal_match')), s['reference_change'])}"
            )
        lines.append(
            f"- {name} ({', '.join(s['keys'])}; the reference, {s.get('reference_with', 'preset')} "
            f"refined in time, changes by {s['reference_change']:.1e}): " + "; ".join(parts) + "."
        )
    return lines
