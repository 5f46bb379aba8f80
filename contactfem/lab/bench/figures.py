"""Figures of `contactfem bench` (lecture 09): the tangent comparison, the
work-precision diagrams, the cost of a Newton iteration, and where the time of the
paper's runs goes (start-up and one iteration of each scene).

Data: the bench JSON named by $CONTACTFEM_BENCH, else the repository's bench.json (a
committed full run), else a quick bench run here (seconds)."""

import json
import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from ... import environment, lazy
from ...plots import default_outdir, figure, pyplot
from ...plots.data import save_figure
from ...scenes import jsonable
from . import STUDIES, run_bench
from .speed import PARTS
from .speed import SPEED_TARGETS as T

ticker = lazy.module("matplotlib.ticker")


def bench_json_path():
    """$CONTACTFEM_BENCH if set, else bench.json at the repository root (may not exist)."""
    env = environment.read("CONTACTFEM_BENCH")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3] / "bench.json"


def load_bench(preset="fast"):
    """The bench result: from the JSON if present, else a quick bench of the four studies
    the figures need (tangents, work_precision, cost, speed), computed once per process."""
    path = bench_json_path()
    if path.exists():
        return json.loads(path.read_text())
    return quick_bench()


@lru_cache(maxsize=4)
def quick_study(name):
    """One study's quick run, measured in this process once (for a figure whose bench JSON lacks it)."""
    return jsonable(STUDIES[name](True))


@lru_cache(maxsize=1)
def quick_bench():
    """The quick bench of the four studies the figures need (measured in this process: timings
    are not kept on disk)."""
    return run_bench(quick=True, only=("tangents", "work_precision", "cost", "speed"), progress=None)


@figure("bench_tangents", "bench")
def bench_tangents(preset="fast", outdir=None):
    """Linear solves to the same tolerance: consistent tangent vs symmetric, frozen, staggered."""
    plt = pyplot()
    tg = load_bench(preset)["tangents"]
    problems = [(f"block, {law}", rows) for law, rows in tg["block"].items()]
    problems.append((f"sloping impact\n({tg['sloping_impact_steps']} steps)", tg["sloping_impact"]))
    variants = ("consistent", "symmetric", "frozen", "staggered")
    colors = dict(consistent="C0", symmetric="C3", frozen="C1", staggered="C2")
    fig, axes = plt.subplots(1, len(problems), figsize=(4.2 * len(problems), 3.6))
    for ax, (title, rows) in zip(np.atleast_1d(axes), problems):
        top = max((r["iterations"] or 0) for r in rows.values()) or 1
        for i, v in enumerate(variants):
            r = rows[v]
            if r["converged"]:
                ax.bar(i, r["iterations"], color=colors[v])
                ax.text(
                    i, r["iterations"], f"{r['iterations']}\n{r['time_s']:.2g} s", ha="center", va="bottom", fontsize=8
                )
            else:
                ax.bar(i, top * 1.1, color="none", edgecolor=colors[v], hatch="//")
                ax.text(i, top * 0.5, "diverged", ha="center", rotation=90, fontsize=9)
        ax.set_xticks(range(len(variants)), variants, rotation=20)
        ax.set_title(title)
        ax.set_ylim(0, top * 1.35)
    np.atleast_1d(axes)[0].set_ylabel("linear solves to convergence")
    fig.suptitle("The consistent non-symmetric tangent (eqs 49-50) against the alternatives")
    fig.tight_layout()
    return _save(fig, outdir, preset, "bench_tangents", "tangents")


def _save(fig, outdir, preset, stem, section):
    """NAME.png and NAME.json: the bench's ``section`` (the numbers drawn), with the bench's
    source, kind and machine as the parameters."""
    b = load_bench(preset)
    path = bench_json_path()
    parameters = dict(
        source=path.name if path.exists() else "a quick bench run",
        quick=b.get("quick"),
        machine=b.get(f"{section}_machine", b.get("machine")),
    )
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", {section: b[section]}, parameters)


def _rows(block):
    return [r for r in block["rows"] if r.get("ok") and r.get("error_x_roll", r.get("error_p0")) is not None]


@figure("bench_work_precision", "bench")
def bench_work_precision(preset="fast", outdir=None):
    """Error against wall time: hertz (mesh), rolling ring (dt, mesh, Newmark, beam vs
    continuum), bar impact (implicit Newmark vs explicit central differences)."""
    plt = pyplot()
    wp = load_bench(preset)["work_precision"]
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))

    ax = axes[0]
    rows = _rows(wp["hertz_mesh"])
    order = wp["hertz_mesh"]["order_p0"]
    slope = f" (slope {order:.1f} in h through all points)" if order else ""
    ax.loglog([r["time_s"] for r in rows], [abs(r["error_p0"]) for r in rows], "o-", label="|error p0|" + slope)
    ax.loglog([r["time_s"] for r in rows], [abs(r["error_a"]) for r in rows], "s--", label="|error a| (fit)")
    for r in rows:
        ax.annotate(
            f"{r['n_quads']} quads",
            (r["time_s"], abs(r["error_p0"])),
            fontsize=7,
            textcoords="offset points",
            xytext=(4, 4),
        )
    ax.set_title("Hertz, mesh refinement")
    ax.set_xlabel("wall time of the solve [s]")
    ax.set_ylabel("relative error")
    ax.legend(fontsize=7, loc="lower left")

    ax = axes[1]
    series = [
        ("ring_dt_newmark_0.7/0.4", "dt, Newmark 0.7/0.4", "o-"),
        ("ring_dt_newmark_0.5/0.25", "dt, Newmark 0.5/0.25", "v-"),
        ("ring_mesh", "mesh (n_el)", "s--"),
    ]
    for key, label, style in series:
        rows = [r for r in _rows(wp[key]) if r["error_x_roll"]]
        if rows:
            ax.loglog([r["time_s"] for r in rows], [r["error_x_roll"] for r in rows], style, label=label)
            if key == "ring_dt_newmark_0.7/0.4":  # the paper's Newmark: which dt is which
                for r in rows:
                    ax.annotate(
                        f"dt {r['dt']}",
                        (r["time_s"], r["error_x_roll"]),
                        fontsize=6,
                        textcoords="offset points",
                        xytext=(0, 6),
                        ha="center",
                    )
            elif key == "ring_dt_newmark_0.5/0.25":
                for r in rows:
                    ax.annotate(
                        f"dt {r['dt']}",
                        (r["time_s"], r["error_x_roll"]),
                        fontsize=6,
                        color="C1",
                        textcoords="offset points",
                        xytext=(4, -9),
                    )
            elif key == "ring_mesh":  # and which mesh (at dt = 0.01)
                for r in rows:
                    ax.annotate(
                        f"{r['n_el']} el",
                        (r["time_s"], r["error_x_roll"]),
                        fontsize=6,
                        textcoords="offset points",
                        xytext=(4, -8),
                    )
    for r in _rows(wp["ring_kind"]):
        if r["error_x_roll"]:
            ax.loglog(
                r["time_s"],
                r["error_x_roll"],
                "*" if r["kind"] == "continuum" else "D",
                ms=10,
                mfc="none" if r["kind"] == "beam" else None,
                mew=1.5,
                label=f"{r['kind']} ring ({r['n_el']} el, dt {r['dt']})",
            )
    ax.set_title(
        "Rolling ring: error of the rolling point x*\n(dt study on 120 elements; mesh study at dt 0.01)", fontsize=10
    )
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("|x_roll / x*_rigid - 1|")
    ax.legend(fontsize=6.5, loc="best")

    ax = axes[2]
    b = wp["bar_implicit_explicit"]
    for key, label, style in (
        ("newmark", "implicit Newmark 1/2, 1/4", "o-"),
        ("central_difference", "explicit central differences", "s-"),
    ):
        rows = b[key]
        ax.loglog([r["time_s"] for r in rows], [abs(r["error_duration"]) for r in rows], style, label=label)
        for r in rows:
            ax.annotate(
                f"c dt/h = {r['courant']}",
                (r["time_s"], abs(r["error_duration"])),
                fontsize=7,
                textcoords="offset points",
                xytext=(3, 3),
            )
    ax.set_title(f"Bar impact ({b['n_el']} elements): contact duration")
    for a in axes:
        a.xaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_xlabel("wall time of the run [s]")
    ax.set_ylabel("|duration / (2L/c) - 1|")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return _save(fig, outdir, preset, "bench_work_precision", "work_precision")


@figure("bench_cost", "bench")
def bench_cost(preset="fast", outdir=None):
    """Time of one Newton iteration split into bulk, contact, assembly and solve; contact
    time against the number of contact nodes."""
    plt = pyplot()
    c = load_bench(preset)["cost"]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.2), gridspec_kw=dict(width_ratios=[2, 1]))
    names = list(c["cases"])
    parts = (
        ("bulk_s", "bulk (body.internal)", "C0"),
        ("contact_s", "contact", "C3"),
        ("assembly_s", "global assembly", "C7"),
        ("solve_s", "linear solve", "C2"),
    )
    bottom = np.zeros(len(names))
    for key, label, color in parts:
        vals = np.array([c["cases"][n][key] for n in names])
        tot = np.array([sum(c["cases"][n][k] for k, _, _ in parts) for n in names])
        ax.barh(range(len(names)), vals / tot, left=bottom, color=color, label=label)
        bottom += vals / tot
    for i, n in enumerate(names):
        tot = sum(c["cases"][n][k] for k, _, _ in parts)
        ax.text(1.01, i, f"{tot * 1e3:.3g} ms, {c['cases'][n]['ndof']} dofs", va="center", fontsize=8)
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.set_xlim(0, 1.45)
    ax.set_xlabel("share of one Newton iteration")
    ax.legend(fontsize=7, loc="lower right")
    sc = c["contact_scaling"]
    n = np.array([r["n_contact_nodes"] for r in sc])
    t = np.array([r["contact_s"] for r in sc])
    ax2.loglog(n, t * 1e3, "o-", label=f"contact.assemble (slope {c['contact_scaling_slope']:.2f})")
    ax2.loglog(n, t[-1] * 1e3 * n / n[-1], "k:", label="linear")
    ax2.set_xlabel("contact nodes")
    ax2.set_ylabel("time [ms]")
    ax2.legend(fontsize=8)
    ax2.set_title("contact cost is linear in the contact nodes")
    fig.tight_layout()
    return _save(fig, outdir, preset, "bench_cost", "cost")


@figure("bench_speed", "bench")
def bench_speed(preset="fast", outdir=None):
    """One Newton iteration of each paper scene split into bulk, contact, assembly, solve and
    overhead (CPU ms, with the targets), and the start-up of whole processes."""
    plt = pyplot()
    sp = load_bench(preset)["speed"]
    rows = sp["iterations"]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(13, 4.6), gridspec_kw=dict(width_ratios=[3, 2]))
    names = [
        r["scene"] + "".join(f", {v}" for v in r["overrides"].values()) + f"\n{r['ndof']} unknowns, "
        f"{r['linear_algebra']}"
        for r in rows
    ]
    colors = dict(bulk="C0", contact="C3", assembly="C7", solve="C2", overhead="C8")
    ms = np.array([[1e3 * r[f"{part}_s"] for part in PARTS] for r in rows])
    total = ms.sum(axis=1)
    # a linear axis for the small scenes; a row beyond it (cork, hertz) is drawn shrunk to the
    # axis, hatched, so that its parts keep their proportions
    xmax = 1.3 * max(t for t in total if t <= 6 * total.min())
    shrunk = total > xmax
    scale = np.where(shrunk, 0.98 * xmax / total, 1.0)
    left = np.zeros(len(rows))
    for k, part in enumerate(PARTS):
        ax.barh(
            range(len(rows)),
            ms[:, k] * scale,
            left=left,
            color=colors[part],
            label=part,
            hatch=["//" if s else "" for s in shrunk],
            edgecolor="w",
            linewidth=0,
        )
        left += ms[:, k] * scale
    goals = {
        ("sloping_impact", "frictional"): T["sloping_impact_iteration_s"],
        ("rolling_ring", None): T["rolling_ring_iteration_s"],
    }
    for i, r in enumerate(rows):
        label = f"{total[i]:.3g} ms" + (", shrunk to fit" if shrunk[i] else "")
        ax.text(
            left[i] * 0.99 if shrunk[i] else left[i] + 0.01 * xmax,
            i,
            label,
            va="center",
            ha="right" if shrunk[i] else "left",
            fontsize=8,
            color="w" if shrunk[i] else "k",
            bbox=dict(facecolor="k", alpha=0.7, lw=0, pad=1.5) if shrunk[i] else None,
        )
        goal = goals.get((r["scene"], r["overrides"].get("variant")))
        if goal and r["preset"] == "paper":
            ax.plot([1e3 * goal] * 2, [i - 0.4, i + 0.4], "k-", lw=2)
    ax.plot([], [], "k-", lw=2, label="target")
    ax.set_xlim(0, xmax)
    ax.set_yticks(range(len(rows)), names, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("one Newton iteration [ms CPU]")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=6)
    ax.set_title(f"{sp['preset']} preset: where an iteration goes", fontsize=9)
    st = sp["startup"]
    procs = (
        ("python", "python -c pass"),
        ("list", "contactfem list"),
        ("scipy_skfem", "import scipy.sparse.linalg, skfem"),
        ("run_block", "contactfem run block\n--preset paper"),
    )
    walls = [st[k]["wall_s"] for k, _ in procs]
    ax2.barh(range(len(procs)), walls, color=["C7", "C0", "C7", "C0"])
    for i, w in enumerate(walls):
        ax2.text(w * 1.02, i, f"{w:.3f} s", va="center", fontsize=8)
    block_goal = T["run_block_over_scipy_skfem"] * st["scipy_skfem"]["wall_s"]
    ax2.plot([T["list_s"]] * 2, [0.6, 1.4], "k-", lw=2)
    ax2.plot([block_goal] * 2, [2.6, 3.4], "k-", lw=2)
    ax2.set_yticks(range(len(procs)), [p for _, p in procs], fontsize=7)
    ax2.invert_yaxis()
    ax2.set_xlim(0, 1.15 * max(walls + [block_goal, T["list_s"]]))
    ax2.set_xlabel("whole process, wall [s] (median)")
    ax2.set_title(
        f"start-up: list {st['list_over_python']:.1f} x python, run block "
        f"{st['run_block_over_scipy_skfem']:.2f} x scipy + skfem",
        fontsize=9,
    )
    fig.tight_layout()
    return _save(fig, outdir, preset, "bench_speed", "speed")


def _section(name, preset):
    """A study of the bench JSON (adaptive, coverage), or its quick run here (seconds) where the JSON lacks it."""
    b = load_bench(preset)
    if name in b:
        machine = b.get(f"{name}_machine", b.get("machine"))
        return b[name], dict(source=bench_json_path().name, quick=b.get("quick"), machine=machine)
    return quick_study(name), dict(source="a quick bench run", quick=True)


@figure("bench_adaptive", "bench")
def bench_adaptive(preset="fast", outdir=None):
    """Work against precision of the dynamic scenes: residual evaluations against the error of
    the headline quantities, fixed steps against the adaptive mode at several tolerances."""
    plt = pyplot()
    study, parameters = _section("adaptive", preset)
    scenes = study["scenes"]
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.6 * len(scenes), 4.0), squeeze=False)
    for ax, (name, s) in zip(axes[0], scenes.items()):
        fixed = [f for f in s["fixed"] if f.get("error")]
        adaptive = [a for a in s["adaptive"] if a.get("error")]
        ax.loglog(
            [f["error"] for f in fixed],
            [f["residual_evaluations"] for f in fixed],
            "o-",
            color="C0",
            label=f"fixed {s['step']}, preset",
        )
        for f in fixed:
            ax.annotate(
                f"{f['h']:g}",
                (f["error"], f["residual_evaluations"]),
                fontsize=6,
                color="C0",
                textcoords="offset points",
                xytext=(3, 3),
            )
        trap = [f for f in s.get("fixed_trapezoidal", []) if f.get("error")]
        if trap:
            ax.loglog(
                [f["error"] for f in trap],
                [f["residual_evaluations"] for f in trap],
                "^-",
                color="C2",
                label=f"fixed {s['step']}, trapezoidal rule",
            )
            for f in trap:
                ax.annotate(
                    f"{f['h']:g}",
                    (f["error"], f["residual_evaluations"]),
                    fontsize=6,
                    color="C2",
                    textcoords="offset points",
                    xytext=(3, -9),
                )
        ax.loglog(
            [a["error"] for a in adaptive],
            [a["residual_evaluations"] for a in adaptive],
            "s--",
            color="C3",
            label="accuracy = TOL",
        )
        for a in adaptive:
            ax.annotate(
                f"TOL {a['accuracy']:g}",
                (a["error"], a["residual_evaluations"]),
                fontsize=6,
                color="C3",
                textcoords="offset points",
                xytext=(3, -9),
            )
        if s.get("reference_change"):
            ax.axvspan(
                ax.get_xlim()[0],
                s["reference_change"],
                color="0.85",
                zorder=0,
                label="below the reference's own change",
            )
        ax.set_title(
            f"{name} ({s['preset']}): {', '.join(s['keys'])}\nreference: {s['step']} = {s['h_reference']:g} "
            f"({s.get('reference_with', 'preset')})",
            fontsize=9,
        )
        ax.xaxis.set_minor_formatter(ticker.NullFormatter())
        ax.set_xlabel("largest relative error of the headline quantities")
        ax.set_ylabel("residual evaluations (Newton iterations, rejected steps too)")
        ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return save_figure(
        fig, Path(outdir or default_outdir(preset)) / "bench_adaptive.png", {"adaptive": study}, parameters
    )


@figure("bench_coverage", "bench")
def bench_coverage(preset="fast", outdir=None):
    """True error against the error band of every headline quantity of the coverage study, log-log, with the
    diagonal: below it the band holds the error. Quantities with no band are drawn at the band axis' foot."""
    plt = pyplot()
    study, parameters = _section("coverage", preset)
    pairs = [
        (r["scene"], q, bool(r["warnings"]))
        for r in study["rows"]
        for q in r["quantities"].values()
        if q["kind"] in ("covered", "uncovered", "no band") and q["error"] > 0
    ]
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    floor = 1e-6
    lo = max(floor, min([q["error"] for _, q, _ in pairs] + [q["band"] for _, q, _ in pairs if q["band"]] + [1.0]))
    scenes = sorted({s for s, _, _ in pairs})
    for i, name in enumerate(scenes):
        for warned in (False, True):
            mine = [q for s, q, w in pairs if s == name and w == warned]
            if not mine:
                continue
            ax.loglog(
                [max(q["band"] or 0.0, lo / 3) for q in mine],
                [max(q["error"], floor) for q in mine],
                "o" if warned else "s",
                color=f"C{i}",
                mfc="none" if warned else f"C{i}",
                ms=5,
                label=f"{name}" + (" (warned)" if warned else ""),
            )
    top = max([q["error"] for _, q, _ in pairs] + [q["band"] or 0 for _, q, _ in pairs] + [1.0])
    ax.loglog([lo / 3, 2 * top], [lo / 3, 2 * top], "k-", lw=0.8, label="true error = band")
    ax.axhline(study["tol"], color="0.5", ls=":", lw=0.8)
    ax.axvline(study["tol"], color="0.5", ls=":", lw=0.8)
    ax.set_xlabel("relative error band (no band: at the left edge)")
    ax.set_ylabel("relative true error")
    cov = study.get("coverage")
    ax.set_title(
        f"{study['runs']} runs: the bands hold {'-' if cov is None else f'{100 * cov:.1f} %'} of the "
        f"{study['runs_with_bands']} with bands; {study['silent_wrong']} silent-wrong (dotted: the tolerance)",
        fontsize=9,
    )
    ax.legend(fontsize=6, loc="lower right", ncol=2)
    fig.tight_layout()
    return save_figure(
        fig, Path(outdir or default_outdir(preset)) / "bench_coverage.png", {"coverage": study}, parameters
    )
