"""Figures of the verification scenes with closed forms (not figures of the paper):

verif_hertz_pressure     hertz: contact pressure profile against Hertz's p0 sqrt(1 - x^2/a^2)
verif_hertz_refinement   hertz: penalty per unit length against nodal penalty under mesh refinement
verif_bar_impact         bar_impact: contact stress against time, exact rho c v0 over 2 L / c
verif_patch              patch: interface pressure of one- and two-pass node-to-segment
"""

from pathlib import Path

import numpy as np

from . import cached_run, default_outdir, figure, pyplot
from .data import save_figure


def run_scene(scene, preset, overrides=None):
    """The scene's run, shared and kept on disk (plots.cached_run)."""
    return cached_run(scene, preset, **(overrides or {}))


def _save(fig, outdir, preset, stem, data, parameters):
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", data, parameters)


@figure("verif_hertz_pressure", "verification")
def verif_hertz_pressure(preset="fast", outdir=None):
    """Nodal contact pressure p_i = -f_i / w_i of the hertz scene against Hertz."""
    plt = pyplot()
    r = run_scene("hertz", preset)
    a, p0 = r["a_exact"], r["p0_exact"]
    x, p = np.asarray(r["profile_x"]), np.asarray(r["profile_p"])
    xs = np.linspace(0.0, 1.3 * a, 200)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.plot(xs / a, np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)), "k-", label="Hertz $p_0\\sqrt{1-x^2/a^2}$")
    ax.plot(x / a, p / p0, "o", ms=4, label=f"FE nodes ({r['n_quads']} quads)")
    ax.set_xlim(0, 1.3)
    ax.set_xlabel("$x / a$")
    ax.set_ylabel("$p / p_0$")
    ax.set_title(
        f"Hertz line contact: $p_0$ error {100 * r['error_p0']:+.2f} %, $a$ (fit) error {100 * r['error_a']:+.2f} %",
        fontsize=10,
    )
    ax.legend()
    return _save(
        fig,
        outdir,
        preset,
        "verif_hertz_pressure",
        {k: r[k] for k in ("a_exact", "p0_exact", "error_p0", "error_a", "n_quads", "profile_x", "profile_p")},
        r["parameters"],
    )


def hertz_refinement_data(preset="fast", c_N=1e7):
    """p0 error and penetration against the contact element size for a penalty per unit
    length c_N and a nodal penalty c_N * h_c (h_c of the coarsest mesh): the two agree on the
    coarsest mesh and part as the mesh is refined."""
    sizes = (8, 16, 32) if preset == "fast" else (16, 32, 64, 128)
    pl = [run_scene("hertz", preset, {"n_el": n, "c_N": c_N}) for n in sizes]
    c_nodal = c_N * pl[0]["h_contact"]
    nd = [run_scene("hertz", preset, {"n_el": n, "c_N": c_nodal, "penalty": "per_node"}) for n in sizes]
    keys = ("h_contact", "error_p0", "error_a", "penetration_max", "c_N_per_length_max")
    return dict(
        n_el=list(sizes),
        c_N=c_N,
        c_N_nodal=c_nodal,
        per_length={k: [r[k] for r in pl] for k in keys},
        nodal={k: [r[k] for r in nd] for k in keys},
    )


@figure("verif_hertz_refinement", "verification")
def verif_hertz_refinement(preset="fast", outdir=None):
    plt = pyplot()
    d = hertz_refinement_data(preset)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.8))
    for key, style, label in (
        ("per_length", "o-", f"per length $c_N$ = {d['c_N']:.0e} MPa/mm"),
        ("nodal", "s--", f"nodal $c_N$ = {d['c_N_nodal']:.2e} N/mm"),
    ):
        h = np.asarray(d[key]["h_contact"])
        ax1.semilogx(h, 100 * np.asarray(d[key]["error_p0"]), style, label=label)
        ax2.loglog(h, d[key]["penetration_max"], style, label=label)
    ax1.set_xlabel("contact element size $h$ (mm)")
    ax1.set_ylabel("$p_0$ error (%)")
    ax1.axhline(0, color="k", lw=0.5)
    ax1.invert_xaxis()
    ax2.legend(fontsize=8, loc="lower left")
    ax2.set_xlabel("contact element size $h$ (mm)")
    ax2.set_ylabel("largest penetration (mm)")
    ax2.invert_xaxis()
    h = np.asarray(d["nodal"]["h_contact"])
    pen = {k: np.asarray(d[k]["penetration_max"]) for k in ("per_length", "nodal")}
    slope = {k: float(np.polyfit(np.log(h), np.log(pen[k]), 1)[0]) for k in pen}
    ax2.set_title(
        f"penetration ~ h^{slope['nodal']:.2f} (nodal), h^{slope['per_length']:.2f} (per length)", fontsize=10
    )
    fig.subplots_adjust(wspace=0.35)
    e = {k: 100 * np.asarray(d[k]["error_p0"]) for k in ("per_length", "nodal")}
    fig.suptitle(
        "Hertz under mesh refinement: p0 error "
        + "; ".join(f"{k.replace('_', ' ')} {e[k][0]:+.2f} % -> {e[k][-1]:+.2f} %" for k in ("per_length", "nodal")),
        fontsize=10,
    )
    return _save(
        fig,
        outdir,
        preset,
        "verif_hertz_refinement",
        dict(d, penetration_slope=slope),
        dict(run_scene("hertz", preset)["parameters"], n_el=d["n_el"], c_N=d["c_N"]),
    )


@figure("verif_bar_impact", "verification")
def verif_bar_impact(preset="fast", outdir=None):
    plt = pyplot()
    r = run_scene("bar_impact", preset)
    T, s0 = r["duration_exact"], r["stress_exact"]
    t, s = np.asarray(r["time"]), np.asarray(r["contact_stress"])
    E = np.asarray(r["energy_total"])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.6))
    ax1.plot([0, 0, 1, 1, t[-1] / T], [0, 1, 1, 0, 0], "k-", label="exact: $\\rho c v_0$ for $2L/c$")
    ax1.plot(t / T, s / s0, ".-", ms=3, label="FE (Newmark 1/2, 1/4)")
    ax1.set_xlabel("$t / (2L/c)$")
    ax1.set_ylabel("contact stress / $\\rho c v_0$")
    ax1.set_title(
        f"duration {100 * r['error_duration']:+.1f} %, mean stress "
        f"{100 * r['error_stress_mean']:+.2f} %, rebound {100 * r['error_rebound']:+.1f} %",
        fontsize=9,
    )
    ax1.legend(fontsize=8)
    ax2.plot(t / T, (E - E[0]) / E[0], "-")
    ax2.set_xlabel("$t / (2L/c)$")
    ax2.set_ylabel("$(E - E_0) / E_0$")
    ax2.set_title("total energy (kinetic + strain + penalty)", fontsize=10)
    return _save(
        fig,
        outdir,
        preset,
        "verif_bar_impact",
        {
            k: r[k]
            for k in (
                "duration_exact",
                "stress_exact",
                "error_duration",
                "error_stress_mean",
                "error_rebound",
                "time",
                "contact_stress",
                "energy_total",
            )
        },
        r["parameters"],
    )


@figure("verif_patch", "verification")
def verif_patch(preset="fast", outdir=None):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.6))
    data = {}
    for passes, style in ((1, "o-"), (2, "s--")):
        r = run_scene("patch", preset, {"passes": passes})
        data[f"passes_{passes}"] = {
            k: r[k] for k in ("pressure_deviation_max", "stress_deviation_max", "interface_x", "interface_pressure")
        }
        p = r["parameters"]["p"]
        ax.plot(
            r["interface_x"],
            np.asarray(r["interface_pressure"]) / p,
            style,
            label=f"{passes}-pass: max deviation {100 * r['pressure_deviation_max']:.2f} %, "
            f"$\\sigma_{{yy}}$ {100 * r['stress_deviation_max']:.2f} %",
        )
    ax.axhline(1.0, color="k", lw=1, label="exact (uniform)")
    ax.set_xlabel("$x$ (mm)")
    ax.set_ylabel("interface pressure / $p$")
    ax.set_title("Contact patch test, non-matching meshes", fontsize=10)
    ax.legend(fontsize=8)
    return _save(fig, outdir, preset, "verif_patch", data, dict(r["parameters"], passes=[1, 2]))
