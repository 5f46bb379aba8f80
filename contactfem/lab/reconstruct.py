"""The scan's unknowns as an inverse problem: which reading of the paper reproduces
most of what it prints?

    contactfem reconstruct block            # Sec. 5.1, Table 1, Fig 8
    contactfem reconstruct sloping_impact   # Sec. 5.3, Table 2
    (--quick: a small profile for CI; --top N: rows to print; --json FILE)

The scan lost some of the data of the paper's examples (NOTES.md: "scan?"). Each
*reading* is one complete choice of the lost values, among those the scan allows.
Every reading is run and scored against everything the paper prints about the
example; the table of readings is printed, ranked.

Block (Sec. 5.1). Unknown: width W and height H (with 200 elements, nx * ny = 200),
the lateral side carrying the tangential load (pulled or pushed), the contact nodes
kept out at each end (1: the end node; 2: both nodes of the end element), c_N (the
scan reads 'lo*': 10^2 by the rule that '*' is a garbled superscript 2, but any
power of ten is possible), the unit of c_N and c_T (per node or per unit length) and
plane strain or plane stress. Printed: Table 1 (residual norms per Newton iteration,
conical and parabolic) and Fig 8's remark.

  Stage A (analytic, no solve). At u = 0 no contact force acts, so the first residual
  is the norm of the consistent nodal load vector. For a uniform nx x ny mesh,
  pressure p on the top and traction q on one side:
      ||P||^2 = (p W / nx)^2 (nx - 1/2) + (q H / ny)^2 (ny - 1/2)
  (interior nodes carry p W / nx, the two corner nodes half of it; the two loads act
  on different components). It does not depend on the face or the sense of q. W and H
  on a grid of step 0.25 (readings with round dimensions), both assignments of 60 and
  200 to p and q: only readings with ||P|| within 1 % of the printed 171.3709 are kept,
  and only those whose tangential resultant q H is below mu p W (mu = 0.5: else the
  conical block cannot be in equilibrium). No reading on the grid reproduces the
  printed 7 digits: the closest is W = 3.5, H = 4 (20 x 10 elements), 171.346
  (-1.4e-4); on a 0.1 grid none comes within 3e-6 either. The printed first residual
  is out of reach of a uniform mesh with uniform loads: the paper's mesh (Fig 6,
  lost in the scan) or load may differ.
  Stage B: every discrete reading of the kept geometries, plane strain, c_N in
  {1e2, 1e4, 1e6}, conical and parabolic law.
  Stage C: the best readings of B again with c_N in {1e2, ..., 1e6} and plane stress.

Scores (block). A reading *meets* these paper facts: first residual within 1 % of
171.37; conical needs 4 residuals; parabolic needs 7; nodes slip in the conical case
(Table 1's drop 3.2 -> 4e-11 is what the piecewise-linear conical problem does once
the stick/slip set has settled); Fig 8's remark (at the nodes in the top quartile of
the conical normal pressure, the parabolic |t_T| is at least 5 % below the conical
one); both laws converge. Rank: most facts met first, then the distance between the
residual histories, the RMS over iterations of |log10(ours / paper)| with both floored
at 1e-3 (the tails below it are round-off and stopping rule, not the problem).

Sloping impact (Sec. 5.3): see ``sloping_impact_readings``.
"""

import hashlib
import itertools
import json
import os
from pathlib import Path

import numpy as np

PAPER_FIRST_RESIDUAL = 171.3709            # Table 1, 0.1713709e3, 7 printed digits
RESIDUAL_FLOOR = 1e-3


# ---------------------------------------------------------------------------------------
# caching: one JSON file per study, keyed by the reading; invalidated when the code changes
def _code_hash(modules):
    import contactfem

    root = Path(contactfem.__file__).parent
    h = hashlib.sha1()
    for rel in modules:
        for f in sorted((root / rel).rglob("*.py")) if (root / rel).is_dir() else [root / rel]:
            h.update(f.read_bytes())
    return h.hexdigest()[:12]


class Cache:
    """Results of earlier runs of the same code (``$CONTACTFEM_CACHE`` or ~/.cache/contactfem)."""

    def __init__(self, name, modules, enabled=True):
        base = Path(os.environ.get("CONTACTFEM_CACHE", Path.home() / ".cache" / "contactfem"))
        self.path = base / f"reconstruct-{name}-{_code_hash(modules)}.json"
        self.enabled, self.data, self.dirty = enabled, {}, False
        if enabled and self.path.exists():
            try:
                self.data = json.loads(self.path.read_text())
            except (OSError, ValueError):
                self.data = {}

    def get(self, key, compute):
        k = json.dumps(key, sort_keys=True)
        if k not in self.data:
            self.data[k] = compute()
            self.dirty = True
        return self.data[k]

    def save(self):
        if self.enabled and self.dirty:
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self.path.write_text(json.dumps(self.data))
            except OSError:
                pass


# ---------------------------------------------------------------------------------------
# block (Sec. 5.1)
def block_first_residual(width, height, nx, ny, p_normal, p_tangential):
    """Norm of the consistent nodal load vector of the block at u = 0 (see the module
    docstring): pressure p_normal on the top (nx elements), traction p_tangential on a
    lateral side (ny elements)."""
    top = p_normal * width / nx * np.sqrt(nx - 0.5)
    side = p_tangential * height / ny * np.sqrt(ny - 0.5)
    return float(np.hypot(top, side))


MESHES = ((8, 25), (10, 20), (20, 10), (25, 8), (40, 5), (50, 4))   # nx x ny = 200, >= 5 contact nodes


def block_geometries(tol=0.01, step=0.25, size=(0.5, 10.0), meshes=MESHES, mu=0.5, block_aspect=3.0,
                     element_aspect=4.0):
    """Stage A: (nx, ny, W, H, p_y, p_x, first residual) with the first residual within
    ``tol`` of the paper's and an equilibrium possible (p_x H < mu p_y W), sorted by the
    distance to the printed value. A *block* (not a strip: W / H and H / W at most
    ``block_aspect``) meshed with usable elements (side ratio at most ``element_aspect``)."""
    grid = np.round(np.arange(size[0], size[1] + 1e-9, step), 10)
    out = []
    for (nx, ny), (p, q) in itertools.product(meshes, ((200.0, 60.0), (60.0, 200.0))):
        for W, H in itertools.product(grid, grid):
            r0 = block_first_residual(W, H, nx, ny, p, q)
            shape = max(W / H, H / W) <= block_aspect
            elements = max((W / nx) / (H / ny), (H / ny) / (W / nx)) <= element_aspect
            if abs(r0 / PAPER_FIRST_RESIDUAL - 1) <= tol and q * H < mu * p * W and shape and elements:
                out.append(dict(nx=nx, ny=ny, width=float(W), height=float(H), p_y=p, p_x=q, first_residual=r0))
    return sorted(out, key=lambda g: abs(g["first_residual"] / PAPER_FIRST_RESIDUAL - 1))


def residual_distance(ours, paper, floor=RESIDUAL_FLOOR):
    """RMS over iterations of |log10(ours_k / paper_k)|, both floored at ``floor``; a
    history that stopped earlier continues at the floor. None (no convergence) -> inf."""
    if ours is None:
        return float("inf")
    n = max(len(ours), len(paper))
    a = np.log10(np.maximum([*ours, *[floor] * (n - len(ours))], floor))
    b = np.log10(np.maximum([*paper, *[floor] * (n - len(paper))], floor))
    return float(np.sqrt(np.mean((a - b) ** 2)))


def _block_case(params):
    """One solve of the block, reduced to what the score needs."""
    from ..scenes.block import SCENE
    from ..solver.newton import NewtonError

    try:
        r = SCENE.run(params)
    except (NewtonError, FloatingPointError, np.linalg.LinAlgError) as exc:
        return dict(converged=False, error=str(exc).splitlines()[0][:120])
    c = r["contact"]
    return dict(converged=True, residuals=[float(x) for x in r["newton_residuals"]], n_slip=r["n_slip"],
                n_stick=r["n_stick"], n_open=r["n_open"], t_N=np.asarray(c["t_N"]).tolist(),
                t_T=np.asarray(c["t_T"]).tolist())


def fig8_remark(conical, parabolic, drop=0.05):
    """Fig 8's remark at the nodes in the top quartile of the conical normal pressure:
    fraction of them where the parabolic |t_T| is at least ``drop`` below the conical one,
    and the smallest relative reduction there."""
    if not (conical.get("converged") and parabolic.get("converged")):
        return 0.0, float("nan")
    pN = np.abs(conical["t_N"])
    top = pN >= np.quantile(pN, 0.75)
    tc, tp = np.abs(np.asarray(conical["t_T"]))[top], np.abs(np.asarray(parabolic["t_T"]))[top]
    reduction = 1 - tp / np.maximum(tc, 1e-300)
    return float(np.mean(reduction >= drop)), float(np.min(reduction))


def score_block(reading, conical, parabolic):
    """Facts met and the residual distance of one reading (see the module docstring)."""
    from ..scenes.block import PAPER_TABLE1

    r0 = conical["residuals"][0] if conical.get("converged") else reading.get("first_residual")
    n_con = len(conical["residuals"]) if conical.get("converged") else None
    n_par = len(parabolic["residuals"]) if parabolic.get("converged") else None
    frac, red = fig8_remark(conical, parabolic)
    facts = {
        "first_residual_1pct": r0 is not None and abs(r0 / PAPER_FIRST_RESIDUAL - 1) <= 0.01,
        "conical_4_residuals": n_con == len(PAPER_TABLE1["conical"]),
        "parabolic_7_residuals": n_par == len(PAPER_TABLE1["parabolic"]),
        "conical_slips": bool(conical.get("converged") and conical["n_slip"] > 0),
        "fig8_remark": frac == 1.0,
        "both_converge": bool(conical.get("converged") and parabolic.get("converged")),
    }
    d = (residual_distance(conical.get("residuals"), PAPER_TABLE1["conical"])
         + residual_distance(parabolic.get("residuals"), PAPER_TABLE1["parabolic"]))
    return dict(reading, first_residual=r0, n_conical=n_con, n_parabolic=n_par,
                n_slip_conical=conical.get("n_slip"), fig8_fraction=frac, fig8_min_reduction=red,
                residuals_conical=conical.get("residuals"), residuals_parabolic=parabolic.get("residuals"),
                facts=facts, n_facts=int(sum(facts.values())), distance=d)


BLOCK_KEYS = ("nx", "ny", "width", "height", "p_y", "p_x", "p_x_face", "free_end_nodes", "c_N", "penalty", "plane")


def block_reading_params(reading, law):
    """Scene parameters of a reading (everything else: the scene's defaults, the paper's data)."""
    from ..scenes.block import SCENE

    over = {k: reading[k] for k in BLOCK_KEYS}
    # the paper's 10^4 per node or per length; Newton: 20 solves are plenty (the paper's 7)
    over.update(law=law, c_T=1e4, maxit=20)
    return SCENE.resolve("fast", over)


def evaluate_block(reading, cache):
    cases = {}
    for law in ("conical", "parabolic"):
        params = block_reading_params(reading, law)
        cases[law] = cache.get(["block", law, {k: params[k] for k in sorted(params)}],
                               lambda: _block_case(params))
    return score_block(reading, cases["conical"], cases["parabolic"])


def rank(rows):
    return sorted(rows, key=lambda r: (-r["n_facts"], r["distance"]))


def block_paper_reading():
    """The reading of the block scene's defaults (its paper preset), as a study row."""
    from ..scenes.block import SCENE

    p = SCENE.resolve("paper")
    rd = {k: p[k] for k in BLOCK_KEYS}
    rd["first_residual"] = block_first_residual(p["width"], p["height"], p["nx"], p["ny"], p["p_y"], p["p_x"])
    return rd


def reconstruct_block(quick=False, cache=True, progress=None):
    """Stages A-C (module docstring); returns (ranked rows, stage A geometries).
    quick: stage B on the paper preset's geometry and the paper preset's reading itself,
    without stage C (for CI)."""
    cache = Cache("block", ["scenes/block.py", "contact", "laws", "bodies/continuum.py", "bodies/loads.py",
                            "solver", "lab/reconstruct.py"], enabled=cache)
    geos = block_geometries()
    paper = block_paper_reading()
    if quick:
        geos = [g for g in geos if (g["nx"], g["width"], g["height"]) == (paper["nx"], paper["width"], paper["height"])]
    readings = [dict(g, p_x_face=face, free_end_nodes=k, c_N=c_N, penalty=unit, plane="strain")
                for g in geos for face in ("right", "left") for k in (1, 2)
                for c_N in (1e2, 1e4, 1e6) for unit in ("per_node", "per_length")]
    if quick:
        readings.append(paper)
    try:
        rows = evaluate_all(readings, evaluate_block, cache, progress)
        if not quick:                      # stage C around the best of stage B
            seen = {json.dumps({k: r[k] for k in BLOCK_KEYS}, sort_keys=True) for r in rows}
            extra = []
            for best in rank(rows)[:12]:
                for c_N, plane in itertools.product((1e2, 1e3, 1e4, 1e5, 1e6), ("strain", "stress")):
                    rd = {k: best[k] for k in BLOCK_KEYS} | dict(c_N=c_N, plane=plane,
                                                                  first_residual=best["first_residual"])
                    key = json.dumps({k: rd[k] for k in BLOCK_KEYS}, sort_keys=True)
                    if key not in seen:
                        seen.add(key)
                        extra.append(rd)
            rows += evaluate_all(extra, evaluate_block, cache)
    finally:
        cache.save()
    return rank(rows), geos


def evaluate_all(readings, evaluate, cache, progress=None):
    """Score every reading with ``evaluate(reading, cache)``; ``progress(done, total)``."""
    rows = []
    for i, rd in enumerate(readings):
        rows.append(evaluate(rd, cache))
        if progress:
            progress(i + 1, len(readings))
    return rows


def _fmt_res(res):
    return "diverges" if res is None else " ".join(f"{x:.3g}" for x in res)


def block_table(rows, top=25):
    """The ranked readings as a text table."""
    facts = list(rows[0]["facts"]) if rows else []
    head = (f"{'rank':>4} {'mesh':>6} {'W':>5} {'H':>5} {'face':>5} {'free':>4} {'c_N':>6} {'unit':>10} "
            f"{'plane':>6} {'||G0||':>8} {'con':>3} {'par':>3} {'slip':>4} {'fig8':>5} {'facts':>5} {'dist':>6}"
            "  conical residuals | parabolic residuals")
    lines = [head, "-" * len(head)]
    for i, r in enumerate(rows[:top], 1):
        lines.append(
            f"{i:4d} {r['nx']:>2d}x{r['ny']:<3d} {r['width']:5.2f} {r['height']:5.2f} {r['p_x_face']:>5} "
            f"{r['free_end_nodes']:4d} {r['c_N']:6.0e} {r['penalty']:>10} {r['plane']:>6} {r['first_residual']:8.3f} "
            f"{r['n_conical'] or '-':>3} {r['n_parabolic'] or '-':>3} {r['n_slip_conical'] or 0:4d} "
            f"{r['fig8_fraction']:5.2f} {r['n_facts']:3d}/{len(facts)} {r['distance']:6.2f}  "
            f"{_fmt_res(r['residuals_conical'])} | {_fmt_res(r['residuals_parabolic'])}")
    lines.append("facts: " + ", ".join(facts) + "; dist: RMS |log10(ours/paper)| of both residual histories "
                 f"(floored at {RESIDUAL_FLOOR:g})")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------
# sloping impact (Sec. 5.3)
# Table 2 prints v_x, v_y to two digits (1.7, 1.2: +-0.05, i.e. +-3 % to +-4 %) and the angles
# as multiples of 5 deg (50, 35: read off to the nearest 5 deg, +-2.5 deg). A reading *meets* a
# number when it is within 10 % (velocities) or 5 deg (angles): twice the printing uncertainty,
# the remainder for the paper's own time-discretisation error at dt = 0.1, which is of the
# size our refinement study (lecture 06) measures for ours (v_y moves by 0.1-0.3 from
# dt = 0.1 to 0.0125).
TABLE2_VELOCITY_TOL = 0.10
TABLE2_ANGLE_TOL_DEG = 5.0
SLOPING_KEYS = ("integration", "rotary_inertia", "contact_at", "penalty", "c_N", "gap0")
SLOPING_PAPER_READING = dict(integration="2", rotary_inertia=True, contact_at="outer", penalty="per_node",
                             c_N=50.0, gap0=0.05)
# the ring leaves the plane before t = 7 in every reading tried; after that it flies freely (no
# gravity) and its centre-of-mass velocity is constant, so 80 steps (t = 8) give the rebound of
# the paper's 200; a run still in contact at t = 8 is repeated with the paper's 200 steps
SLOPING_STEPS = 80


def _sloping_case(params):
    from ..scenes.sloping_impact import SCENE
    from ..solver.newton import NewtonError

    try:
        r = SCENE.run(params)
    except (NewtonError, FloatingPointError, np.linalg.LinAlgError) as exc:
        return dict(converged=False, error=str(exc).splitlines()[0][:120])
    return dict(converged=True, vx=r["rebound_vx"], vy=r["rebound_vy"], angle=r["rebound_angle_deg"],
                spin=r["rebound_spin"], rebounded=r["rebounded"], t_separation=r["t_separation"],
                steps=params["n_steps"])


def evaluate_sloping(reading, cache):
    from ..scenes.sloping_impact import PAPER_TABLE2, SCENE

    row = dict(reading)
    facts, errs = {}, []
    for variant in ("frictionless", "frictional"):
        over = dict(reading, variant=variant, n_steps=SLOPING_STEPS, outline_every=1000)
        params = SCENE.resolve("paper", over)
        key = ["sloping_impact", {k: params[k] for k in sorted(params)}]
        case = cache.get(key, lambda: _sloping_case(params))
        if case.get("converged") and not (case["rebounded"] and case["t_separation"] < SLOPING_STEPS * params["dt"]):
            params = SCENE.resolve("paper", dict(over, n_steps=200))
            case = cache.get(["sloping_impact", {k: params[k] for k in sorted(params)}],
                             lambda: _sloping_case(params))
        paper = PAPER_TABLE2[variant]
        for q, pk in (("vx", "vx"), ("vy", "vy"), ("angle", "angle_deg")):
            ours = case.get(q) if case.get("converged") else None
            row[f"{variant}_{q}"] = ours
            if ours is None:
                facts[f"{variant}_{q}"] = False
                errs.append(10.0)
                continue
            if q == "angle":
                e = (ours - paper[pk]) / TABLE2_ANGLE_TOL_DEG
            else:
                e = (abs(ours) - paper[pk]) / (TABLE2_VELOCITY_TOL * paper[pk])
            facts[f"{variant}_{q}"] = bool(abs(e) <= 1.0)
            errs.append(e)
        row[f"{variant}_spin"] = case.get("spin")
    row.update(facts=facts, n_facts=int(sum(facts.values())),
               # RMS of the six errors in units of their tolerance (<= 1: all within)
               distance=float(np.sqrt(np.mean(np.square(errs)))))
    return row


def sloping_impact_readings(quick=False):
    """Stage 1: every combination of the discrete unknowns at the scan's c_N = 50: beam
    integration (1 or 2 points), rotary inertia (on/off), contact at the outer fibre or the
    axis, penalty per node or per length, start gap 0 or 0.25. (Consistent mass is not
    searched: the Newmark solver works with a diagonal mass. The start gap moves the numbers
    by < 0.01: two values.) quick: the paper preset's reading and two one-change neighbours."""
    if quick:
        base = SLOPING_PAPER_READING
        return [base, dict(base, integration="1"), dict(base, rotary_inertia=False)]
    return [dict(integration=i, rotary_inertia=j, contact_at=c, penalty=p, c_N=50.0, gap0=g)
            for i, j, c, p, g in itertools.product(("1", "2"), (True, False), ("outer", "axis"),
                                                   ("per_node", "per_length"), (0.0, 0.25))]


def reconstruct_sloping_impact(quick=False, cache=True, progress=None):
    """Stage 1 (``sloping_impact_readings``), then stage 2: the six best readings with
    c_N = 25, 100, 500 (the scan's 50 is legible; how much do the numbers move with it?)."""
    cache = Cache("sloping_impact", ["scenes/sloping_impact.py", "contact", "laws", "bodies/beam.py",
                                     "bodies/ring.py", "solver", "lab/reconstruct.py"], enabled=cache)
    readings = sloping_impact_readings(quick)
    try:
        rows = evaluate_all(readings, evaluate_sloping, cache, progress)
        if not quick:
            extra = [dict({k: best[k] for k in SLOPING_KEYS}, c_N=c) for best in rank(rows)[:6]
                     for c in (25.0, 100.0, 500.0)]
            rows += evaluate_all(extra, evaluate_sloping, cache)
    finally:
        cache.save()
    return rank(rows)


def sloping_table(rows, top=25):
    from ..scenes.sloping_impact import PAPER_TABLE2

    fl, fr = PAPER_TABLE2["frictionless"], PAPER_TABLE2["frictional"]
    f = lambda x, w=5, d=2: "  -  ".rjust(w) if x is None else f"{x:{w}.{d}f}"   # noqa: E731
    head = (f"{'rank':>4} {'int':>3} {'rot':>3} {'at':>5} {'penalty':>10} {'c_N':>5} {'gap0':>5} | "
            f"{'vx':>5} {'vy':>5} {'angle':>5} | {'vx':>5} {'vy':>5} {'angle':>5} {'facts':>5} {'dist':>5}")
    lines = [" " * 42 + "| frictionless       | frictional", head, "-" * len(head),
             f"{'paper':>42} | {f(fl['vx'])} {f(fl['vy'])} {f(fl['angle_deg'], 5, 1)} | "
             f"{f(fr['vx'])} {f(fr['vy'])} {f(fr['angle_deg'], 5, 1)}"]
    for i, r in enumerate(rows[:top], 1):
        lines.append(
            f"{i:4d} {r['integration']:>3} {'yes' if r['rotary_inertia'] else 'no':>3} {r['contact_at']:>5} "
            f"{r['penalty']:>10} {r['c_N']:5g} {r['gap0']:5.2f} | {f(r['frictionless_vx'])} {f(r['frictionless_vy'])} "
            f"{f(r['frictionless_angle'], 5, 1)} | {f(r['frictional_vx'])} {f(r['frictional_vy'])} "
            f"{f(r['frictional_angle'], 5, 1)} {r['n_facts']:3d}/6 {r['distance']:5.2f}")
    lines.append(f"facts: the six numbers of Table 2 within {TABLE2_VELOCITY_TOL:.0%} (velocities) or "
                 f"{TABLE2_ANGLE_TOL_DEG:g} deg (angles); dist: RMS of the six errors in units of those tolerances")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------
# command line
def _progress(label):
    import sys

    def show(i, n):
        if sys.stderr.isatty():
            print(f"\r{label}: {i}/{n} readings", end="\n" if i == n else "", file=sys.stderr, flush=True)
    return show


def _finite(obj):
    """JSON-able copy: numpy to Python, non-finite numbers (diverged readings) to None."""
    if isinstance(obj, dict):
        return {str(k): _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_finite(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj


def main(scene, quick=False, top=25, json_path=None, cache=True):
    """`contactfem reconstruct SCENE`: run the study, print the ranked table (and write JSON)."""
    if top < 1:
        raise ValueError(f"parameter top = {top} is out of range: allowed [1, inf)")
    if scene == "block":
        rows, geos = reconstruct_block(quick=quick, cache=cache, progress=_progress("block"))
        g = block_geometries()
        print(f"Block (Sec. 5.1): {len(g)} geometries within 1 % of the printed first residual "
              f"{PAPER_FIRST_RESIDUAL} (closest: {g[0]['first_residual']:.4f} at W = {g[0]['width']}, "
              f"H = {g[0]['height']}, {g[0]['nx']} x {g[0]['ny']}; none reaches the printed digits); "
              f"{len(rows)} readings of {len(geos)} of them run{' (quick profile)' if quick else ''}.")
        print(block_table(rows, top))
    elif scene == "sloping_impact":
        rows = reconstruct_sloping_impact(quick=quick, cache=cache, progress=_progress("sloping_impact"))
        print(f"Sloping impact (Sec. 5.3): {len(rows)} readings run{' (quick profile)' if quick else ''}, "
              "16 elements, dt = 0.1, Newmark 0.7 / 0.4, 200 steps (the paper's).")
        print(sloping_table(rows, top))
    else:
        raise ValueError(f"parameter scene = {scene!r} is not allowed: one of block|sloping_impact")
    if json_path:
        with open(json_path, "w") as fh:
            json.dump(_finite(rows), fh, indent=1)
    return rows
