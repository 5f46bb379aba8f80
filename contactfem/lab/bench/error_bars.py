"""Bench study: what the error bars cost. Every scene at its fast preset (the run a user starts first),
with its error bars, in this process: the run's own wall time, the time of the ladder's runs
(``uncertainty.wall_time_s``), how many runs they were, and the ratio (run + error bars) / run; the
median of the ratios over the scenes is the overhead the README states. ``quick``: the block alone."""

import statistics
import warnings

from ...scenes import all_scenes, run_scene

REPEATS = 1  # each scene's run is timed once: the ratio of two times of one process, both under its load


def scene_cost(name, preset="fast"):
    """One scene's run with its error bars: run_s, bars_s, runs, failed runs, ratio."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its warnings are the coverage study's concern
        r = run_scene(name, preset, error_bars=True)
    u = r.get("uncertainty")
    if not u:
        return dict(scene=name, run_s=r["wall_time_s"], bars_s=0.0, runs=0, failed_runs=0, ratio=1.0)
    return dict(
        scene=name,
        run_s=r["wall_time_s"],
        bars_s=u["wall_time_s"],
        runs=u["runs"],
        failed_runs=u["failed_runs"],
        ratio=(r["wall_time_s"] + u["wall_time_s"]) / r["wall_time_s"],
        quantities={k: dict(band=q["band"], relative_band=q["relative_band"]) for k, q in u["quantities"].items()},
    )


def error_bars_study(quick=False):
    """Each scene's cost (fast preset) and the median ratio over the scenes."""
    names = ["block"] if quick else list(all_scenes())
    rows = [scene_cost(n) for n in names]
    return dict(rows=rows, median_ratio=statistics.median(r["ratio"] for r in rows), target=1.75)


def error_bars_markdown(res):
    """The BENCHMARKS.md section of the study."""
    L = [
        "## What the error bars cost",
        "",
        "Each scene at its fast preset with its error bars (contactfem/lab/bench/error_bars.py): the run alone, the "
        "runs of its ladders (coarser levels first, finer ones where the coarser levels are not monotone, fail or "
        "show an order far above the scheme's), and (run + error bars) / run. Median over the scenes: "
        f"**{res['median_ratio']:.2f}** (target {res['target']:g}).",
        "",
        "| scene | run [s] | error bars [s] | runs | failed | ratio |",
        "|---|---|---|---|---|---|",
    ]
    for r in res["rows"]:
        L.append(
            f"| {r['scene']} | {r['run_s']:.3g} | {r['bars_s']:.3g} | {r['runs']} | {r['failed_runs']} | "
            f"{r['ratio']:.2f} |"
        )
    return L + [""]


def error_bars_sentence(res):
    """The README's line on the study (in its block coverage, lab/readme.py)."""
    rows = ", ".join(f"{r['scene']} {r['ratio']:.2g}" for r in sorted(res["rows"], key=lambda r: r["ratio"]))
    met = "within" if res["median_ratio"] <= res["target"] else "**above**"
    return (
        f"What they cost (`contactfem bench --only error_bars`, each scene's fast preset, (run + error bars) / run): "
        f"{rows}; the median over the scenes {res['median_ratio']:.2f}, {met} the {res['target']:g} the design "
        "aimed at."
    )
