"""Bench study: what it costs to meet the contact conditions to a gap violation of 1e-10
(largest penetration / the scene's length) with the penalty method, the augmented
Lagrangian (Uzawa) and the semi-smooth Newton method (Lagrange multipliers as unknowns),
on Hertz and the block (Coulomb, mu = 0.3).

* penalty: its gap falls like 1/c_N, so it meets 1e-10 only at the c_N extrapolated from
  a run at the scene's c_N (gap * c_N constant) to half the target; it is run there, and
  what it reaches is recorded (a failed or inaccurate solve is reported, not hidden);
* Uzawa: ``enforcement = augmented``, ``uzawa_tol = 1e-10``, at the scene's c_N;
* semi-smooth Newton: ``enforcement = lagrange`` (no c_N to choose), node-to-segment and
  mortar.

Counted: Newton linear solves (over all outer iterations), outer iterations, wall time of
the scene's run(), the gap violation reached, and how far the tractions are from the
semi-smooth Newton method's (node-to-segment: the same discretisation), relative to their
largest value.
"""

import time

import numpy as np

from ...scenes import get_scene, run_scene

TARGET = 1e-10
CASES = {"hertz": {}, "block": {"law": "coulomb", "mu": 0.3}}


def _point(scene, preset, over):
    t0 = time.perf_counter()
    try:
        r = run_scene(scene, preset, over, error_bars=False)
    except Exception as err:  # a failed run is reported, not hidden
        return dict(ok=False, error=f"{type(err).__name__}: {err}"[:300], time_s=time.perf_counter() - t0)
    tractions = (
        np.concatenate([r["contact"]["t_N"], r["contact"]["t_T"]]) if scene == "block" else np.asarray(r["profile_p"])
    )
    return dict(
        ok=True,
        solves=int(sum(r["newton_per_outer"])),
        outer=int(r["uzawa_iterations"]),
        gap_violation=r["gap_violation"],
        met=bool(r["gap_violation"] <= TARGET),
        time_s=time.perf_counter() - t0,
        length=r["gap_violation_length_is"],
        unknowns=r["unknowns"],
        tractions=tractions,
    )


def semismooth_study(quick=False):
    """Penalty (at the c_N the target needs), Uzawa and the semi-smooth Newton method on
    Hertz and the block, to a gap violation of 1e-10."""
    preset = "fast" if quick else "paper"
    out = dict(target=TARGET, preset=preset, scenes={})
    for scene, base in CASES.items():
        c0 = get_scene(scene).resolve(preset, base)["c_N"]
        ref = _point(scene, preset, base)
        rows = {}
        if ref["ok"]:
            c = c0 * ref["gap_violation"] / (TARGET / 2)
            rows["penalty"] = dict(_point(scene, preset, dict(base, c_N=c)), c_N=c, c_N_is="extrapolated to the target")
        else:
            rows["penalty"] = dict(ref, c_N=c0, c_N_is="the scene's")
        rows["uzawa"] = dict(
            _point(scene, preset, dict(base, enforcement="augmented", uzawa_tol=TARGET)), c_N=c0, c_N_is="the scene's"
        )
        rows["semismooth"] = dict(_point(scene, preset, dict(base, enforcement="lagrange")), c_N=None, c_N_is="none")
        rows["semismooth_mortar"] = dict(
            _point(scene, preset, dict(base, enforcement="lagrange", contact_discretization="mortar")),
            c_N=None,
            c_N_is="none",
        )
        exact = rows["semismooth"].get("tractions")
        for key, r in rows.items():
            t = r.pop("tractions", None)
            ok = t is not None and exact is not None and key != "semismooth_mortar"
            r["traction_difference"] = float(np.max(np.abs(t - exact)) / np.max(np.abs(exact))) if ok else None
        ref.pop("tractions", None)
        length = next((r["length"] for r in rows.values() if r["ok"]), "")
        out["scenes"][scene] = dict(c_N_default=c0, penalty_at_default=ref, length=length, rows=rows)
    return out


LABELS = {
    "penalty": "penalty",
    "uzawa": "augmented Lagrangian (Uzawa)",
    "semismooth": "semi-smooth Newton",
    "semismooth_mortar": "semi-smooth Newton, mortar",
}


def semismooth_markdown(res):
    """The BENCHMARKS.md section of the study."""
    L = [
        "## Penalty, Uzawa, semi-smooth Newton: to a gap violation of 1e-10",
        "",
        f"Gap violation = largest penetration / the scene's length; target {res['target']:g}; {res['preset']} "
        "presets; node-to-segment unless said. Penalty: run at the c_N its gap extrapolates to for the target "
        "(gap * c_N constant, from a run at the scene's c_N). Uzawa: `enforcement=augmented uzawa_tol=1e-10` at "
        "the scene's c_N, linear solves summed over the outer iterations. Semi-smooth Newton: "
        "`enforcement=lagrange`, the tractions unknowns beside the displacements (more unknowns), one Newton "
        "solve. Traction difference: largest difference of the nodal tractions to the semi-smooth Newton "
        "method's, over their largest value (node-to-segment rows).",
        "",
        "| scene | method | c_N | linear solves | outer iterations | gap violation | met | traction difference | "
        "time [s] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scene, s in res["scenes"].items():
        for key, r in s["rows"].items():
            c = "-" if r["c_N"] is None else f"{r['c_N']:.1e}"
            d = "-" if r.get("traction_difference") is None else f"{r['traction_difference']:.1e}"
            if r["ok"]:
                L.append(
                    f"| {scene} (length: {s['length']}) | {LABELS[key]} | {c} | {r['solves']} | {r['outer']} | "
                    f"{r['gap_violation']:.1e} | {'yes' if r['met'] else 'no'} | {d} | {r['time_s']:.2f} |"
                )
            else:
                L.append(
                    f"| {scene} | {LABELS[key]} | {c} | failed: {r['error'][:60]} | - | - | no | - | "
                    f"{r['time_s']:.2f} |"
                )
    return L + [""]
