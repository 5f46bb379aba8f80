"""Study 7, scaling: Hertz from 1k to 65k quads, contactfem against a plain scikit-fem script.

The plain script (``plain_hertz``) solves the discrete problem of the hertz scene at the paper's
data, written as a scikit-fem example would: the scene's graded quarter-disk mesh
(bodies.meshes.quarter_disk), plane-strain linear elasticity assembled with ``skfem.asm``, the
dead pressure on the flat cut, u_x = 0 on the symmetry line, and the contact as a per-length
penalty on the nodal gaps of the scene's arc nodes against the rigid line y = -R (tributary
lengths as weights). It is solved with scipy (``skfem.solve``: ``spsolve``, SuperLU with scipy's
default ordering) by Newton on the active set ("pressure mode": solve with the nodes in contact
penalised, update the set from the gaps, until the set no longer changes), from the scene's
initial guess (the rigid overlap a^2 / 2R). Its p0 is the scene's to rounding (a test checks it).

Both run in this process, one after the other at each size, after a warm-up on a small mesh
(so neither pays an import); the time of each is the best of a few runs (wall, perf_counter),
and the ratio contactfem / plain is what a regression in contactfem's large-mesh path moves.

Whole processes too: ``contactfem run hertz --preset paper --set n_el=N`` against a Python
process that runs the plain script (``python -c "...; plain_hertz(N)"``: it also loads the scene
registry and the mesh generator of contactfem, a few milliseconds), each the best of
PROCESS_REPEATS, and the floor both stand on: ``python -c "import scipy.sparse.linalg, skfem"``.
Both processes load scipy and scikit-fem, so on a small mesh their ratio tends to 1 whatever
the solve costs.
"""

import subprocess
import sys
import time

import numpy as np

from ...scenes import get_scene, run_scene

SIZES = (32, 64, 128, 256)  # n_el: 1024, 4096, 16384, 65536 quads
REPEATS = (5, 3, 2, 2)
QUICK_SIZES, QUICK_REPEATS = (16, 32), (3, 3)
PROCESS_REPEATS, QUICK_PROCESS_REPEATS = 3, 1
IMPORT_FLOOR = "import scipy.sparse.linalg, skfem"
PLAIN_PROCESS = "import sys; from contactfem.lab.bench.scaling import plain_hertz; plain_hertz(int(sys.argv[1]))"


def plain_hertz(n_el, params=None):
    """Hertz in plain scikit-fem + scipy (module docstring). Returns p0, its error against
    Hertz's p0, the active-set iterations (= linear solves) and the unknowns."""
    from scipy.sparse import diags
    from skfem import Basis, ElementQuad1, ElementVector, FacetBasis, LinearForm, asm, condense, solve
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from ...bodies.meshes import grading_for, quarter_disk
    from ...scenes.hertz import hertz_exact

    p = dict(get_scene("hertz").resolve("paper"), **(params or {}), n_el=n_el)
    R, E, nu, P, c_N = p["R"], p["E"], p["nu"], p["P"], p["c_N"]
    a, p0 = hertz_exact(P, R, E, nu)
    k = grading_for(min(1.0, 1.5 * a / (R * np.pi / 4)), 1.0 / 3.0) * p["grading"]
    mesh = quarter_disk(R, n_el, k)
    basis = Basis(mesh, ElementVector(ElementQuad1()))
    K = asm(linear_elasticity(*lame_parameters(E, nu)), basis)  # plane strain

    @LinearForm
    def pressure(v, w):  # q downwards on y = 0
        return -P / (2.0 * R) * v[1]

    f = asm(pressure, FacetBasis(mesh, basis.elem, facets=mesh.boundaries["top"]))
    X = mesh.p
    near = (X[0] ** 2 + X[1] ** 2 > (R * (1 - 1e-9)) ** 2) & (X[0] < min(0.7 * R, 4 * a))
    nodes = np.flatnonzero(near)
    nodes = nodes[np.argsort(X[0, nodes])]
    L = np.linalg.norm(np.diff(X[:, nodes], axis=1), axis=0)
    w = np.r_[L, 0] / 2 + np.r_[0, L] / 2  # tributary lengths
    ydofs = basis.nodal_dofs[1, nodes]
    fixed = basis.nodal_dofs[0, np.flatnonzero(np.abs(X[0]) < 1e-9 * R)]

    u = np.zeros(basis.N)
    u[basis.nodal_dofs[1]] = -(a**2) / (2 * R)  # the scene's initial guess
    active, solves = None, 0
    while True:
        gap = X[1, nodes] + u[ydofs] + R
        now = gap < 0
        if active is not None and np.array_equal(now, active):
            break
        active = now
        kc = np.zeros(basis.N)
        kc[ydofs] = c_N * w * active  # penalty per unit gap
        rhs = f.copy()
        rhs[ydofs] -= c_N * w * active * (X[1, nodes] + R)
        u = solve(*condense(K + diags(kc), rhs, D=fixed))
        solves += 1
        if solves > 50:
            raise RuntimeError("plain Hertz: the active set does not settle in 50 solves")
    pressure_nodes = -c_N * np.minimum(gap, 0.0)
    return dict(
        p0=float(pressure_nodes.max()),
        error_p0=float(pressure_nodes.max() / p0 - 1.0),
        solves=solves,
        unknowns=int(basis.N),
        n_quads=int(mesh.t.shape[1]),
    )


def _best(fn, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def process_time(args, repeat):
    """Best wall time of `repeat` whole Python processes ``python ARGS`` (output discarded); a
    process that fails raises with its error output."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, *args], capture_output=True, text=True)
        best = min(best, time.perf_counter() - t0)
        if done.returncode != 0:
            raise RuntimeError(f"python {' '.join(args)} failed:\n{done.stderr}")
    return best


def scaling_study(quick=False):
    """Study 7 (module docstring): per size, contactfem's hertz (run_scene, paper data) and
    the plain script, their best wall times and the ratio, in this process and as whole processes."""
    sizes, repeats = (QUICK_SIZES, QUICK_REPEATS) if quick else (SIZES, REPEATS)
    processes = QUICK_PROCESS_REPEATS if quick else PROCESS_REPEATS
    run_scene("hertz", "paper", {"n_el": 4}, error_bars=False)  # imports and first calls, not timed
    plain_hertz(4)
    rows = []
    for n_el, repeat in zip(sizes, repeats):
        ours, t_ours = _best(lambda: run_scene("hertz", "paper", {"n_el": n_el}, error_bars=False), repeat)
        plain, t_plain = _best(lambda: plain_hertz(n_el), repeat)
        p_ours = process_time(
            ["-m", "contactfem", "run", "hertz", "--preset", "paper", "--set", f"n_el={n_el}", "--no-error-bars"],
            processes,
        )
        p_plain = process_time(["-c", PLAIN_PROCESS, str(n_el)], processes)
        rows.append(
            dict(
                n_el=n_el,
                n_quads=ours["n_quads"],
                unknowns=ours["unknowns"],
                repeats=repeat,
                contactfem_s=t_ours,
                plain_s=t_plain,
                ratio=t_ours / t_plain,
                process_contactfem_s=p_ours,
                process_plain_s=p_plain,
                process_ratio=p_ours / p_plain,
                contactfem_solves=ours["newton_iterations_total"],
                plain_solves=plain["solves"],
                linear_algebra=ours["linear_algebra"],
                ordering=ours["ordering"],
                error_p0=ours["error_p0"],
                plain_error_p0=plain["error_p0"],
                p0_difference=abs(ours["p0"] - plain["p0"]) / ours["p0"],
            )
        )
    return dict(
        scene="hertz",
        preset="paper",
        rows=rows,
        process_repeats=processes,
        import_floor_s=process_time(["-c", IMPORT_FLOOR], processes),
    )


def scaling_markdown(res):
    """The BENCHMARKS.md section of the study."""
    quads = [r["n_quads"] for r in res["rows"]]
    L = [
        f"## Scaling: Hertz from {min(quads):,} to {max(quads):,} quads, against a plain scikit-fem script",
        "",
        "The hertz scene at the paper's data on n_el x n_el quads (`run_scene`, as a Python user runs it) and "
        "the same discrete problem written as a plain scikit-fem script (contactfem/lab/bench/scaling.py: "
        "`skfem.asm`, scipy's `spsolve`, Newton on the contact's active set), in the same process, imports "
        "done beforehand; each time is the best of the runs given (wall seconds). ratio = contactfem / plain: "
        "below 1 contactfem is faster. p0 difference: |p0 - p0_plain| / p0 (the same problem: rounding). "
        f"Process: whole Python processes, best of {res['process_repeats']} (wall seconds): "
        "`contactfem run hertz --preset paper --set n_el=N` against a process running the plain script; both "
        "load scipy and scikit-fem, which alone take "
        f'{res["import_floor_s"]:.3g} s (`python -c "{IMPORT_FLOOR}"`), so on small meshes their ratio '
        "tends to 1 whatever the solve costs.",
        "",
        "| n_el | quads | unknowns | runs | contactfem [s] | plain [s] | ratio | linear solves (contactfem, plain) "
        "| K solved by | p0 error | p0 difference | process: contactfem [s] | process: plain [s] | process ratio |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        L.append(
            f"| {r['n_el']} | {r['n_quads']} | {r['unknowns']} | {r['repeats']} | {r['contactfem_s']:.3g} | "
            f"{r['plain_s']:.3g} | {r['ratio']:.2f} | {r['contactfem_solves']}, {r['plain_solves']} | "
            f"{r['linear_algebra']} ({r['ordering']}) | {r['error_p0']:+.2e} | {r['p0_difference']:.1e} | "
            f"{r['process_contactfem_s']:.3g} | {r['process_plain_s']:.3g} | {r['process_ratio']:.2f} |"
        )
    return L + [""]
