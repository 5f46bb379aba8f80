"""Bench study: what it costs to meet the contact conditions to a gap violation of 1e-8
(largest penetration / the scene's length), penalty against augmented Lagrangian, at three
penalties (the scene's c_N, 100 times smaller and 100 times larger), on Hertz and the block.

The penalty's gap falls like 1/c_N, so it meets 1e-8 only with an enormous c_N (the c_N it
would need is extrapolated from the measured gap, gap * c_N constant, and labelled so);
the augmented method meets it at any c_N, in outer (Uzawa) iterations whose number grows
as c_N falls. Counted: Newton linear solves (all outer iterations), outer iterations, wall
time of the scene's run().
"""

import time

from ...scenes import get_scene, run_scene

TARGET = 1e-8
CASES = {"hertz": {}, "block": {"law": "parabolic"}}


def _point(scene, preset, over):
    t0 = time.perf_counter()
    try:
        r = run_scene(scene, preset, over, error_bars=False)
    except Exception as err:  # a failed run is reported, not hidden
        return dict(ok=False, error=f"{type(err).__name__}: {err}"[:300], time_s=time.perf_counter() - t0)
    return dict(
        ok=True,
        solves=int(sum(r["newton_per_outer"])),
        outer=int(r["uzawa_iterations"]),
        gap_violation=r["gap_violation"],
        met=bool(r["gap_violation"] <= TARGET),
        time_s=time.perf_counter() - t0,
        length=r["gap_violation_length_is"],
    )


def enforcement_study(quick=False):
    """Penalty and augmented (uzawa_tol = 1e-8) on Hertz and the block at c_N / 100, c_N,
    100 c_N (c_N the scene's default)."""
    preset = "fast" if quick else "paper"
    out = dict(target=TARGET, preset=preset, scenes={})
    for scene, base in CASES.items():
        c0 = get_scene(scene).resolve(preset, base)["c_N"]
        rows = []
        for factor in (0.01, 1.0, 100.0):
            c = c0 * factor
            pen = _point(scene, preset, dict(base, c_N=c))
            if pen["ok"]:
                pen["c_N_needed_extrapolated"] = c * pen["gap_violation"] / TARGET
            aug = _point(scene, preset, dict(base, c_N=c, enforcement="augmented", uzawa_tol=TARGET))
            rows.append(dict(c_N=c, c_N_factor=factor, penalty=pen, augmented=aug))
        lengths = [p["length"] for r in rows for p in (r["penalty"], r["augmented"]) if p["ok"]]
        out["scenes"][scene] = dict(c_N_default=c0, length=lengths[0] if lengths else "", rows=rows)
    return out


def enforcement_markdown(res):
    """The BENCHMARKS.md section of the study."""
    L = [
        "## Enforcement: solves to a gap violation of 1e-8, penalty against augmented Lagrangian",
        "",
        f"Gap violation = largest penetration / the scene's length; target {res['target']:g}; "
        f"{res['preset']} presets. Penalty: one Newton solve per load step, its gap is what it is "
        "(the c_N it would need for the target is extrapolated, gap * c_N constant). Augmented: "
        "`enforcement=augmented uzawa_tol=1e-8`, Newton solves summed over the outer iterations.",
        "",
        "| scene | c_N | penalty: solves | penalty: gap violation | penalty: c_N needed (extrapolated) | "
        "augmented: solves | augmented: outer iterations | augmented: gap violation | augmented: time [s] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scene, s in res["scenes"].items():
        for r in s["rows"]:
            p, a = r["penalty"], r["augmented"]
            pen = (
                f"{p['solves']} | {p['gap_violation']:.1e} | {p['c_N_needed_extrapolated']:.1e}"
                if p["ok"]
                else "failed | - | -"
            )
            aug = (
                f"{a['solves']} | {a['outer']} | {a['gap_violation']:.1e} | {a['time_s']:.2f}"
                if a["ok"]
                else f"failed: {a['error'][:60]} | - | - | -"
            )
            L.append(f"| {scene} (length: {s['length']}) | {r['c_N']:.0e} | {pen} | {aug} |")
    return L + [""]
