"""Figures 14-17 of the paper: the champagne cork (Sec. 5.5).

    fig14_cork_mesh             Fig 14: the mesh of the free cork, and pressed into the neck
    fig15_cork_configurations   Fig 15: the cork at the paper's instants (0 ... 3.0 ms), mapped
                                onto our run (``scenes.cork.snapshot_times``)
    fig16_cork_pressure         Fig 16: the gas pressure on the cork against time
    fig17_cork_displacement     Fig 17: the axial displacement of the cork against time
    table_cork_sensitivity      exit velocity against the reconstructed data (lecture 08)
    cork_knife_edge             exit velocity or "stays in" over (mu, R_tip) and over p0, with the
                                static breakaway margin: the example sits on a knife's edge
    cork_exit_time              the exit time against the closing step of the contact and the
                                discretisation (.png, .md, .json): why the paper preset's exit
                                lies outside the paper's 2.6-2.7 ms

Figs 14-17 draw a result they are given (``r=``: a lecture's own time loops) or run the
scene. The problem is axisymmetric (x = r, y = z); the drawings mirror the meridian in the
axis to show the whole cork and both sides of the neck.
"""

import json
import os
from pathlib import Path
from dataclasses import replace

import numpy as np

from ..contact.masters import bottle_neck
from . import cached_run, default_outdir, figure, pyplot, stored
from .data import RTOL, save_figure, write_data
from .rounding import held, recorded
from .. import environment
from .. import lazy, scenes
from ..bodies.meshes import cork_mesh
from ..problem.scene import simulate
from ..scenes import cork as cork_scene

joblib = lazy.module("joblib")

# the cork run's headline numbers, in the data of each of Figs 14-17 (the summary's row reads them)
CORK_KEYS = (
    "exited",
    "exit_time_ms",
    "exit_velocity_m_s",
    "press_fit_normal_force_N",
    "press_fit_calibrated",
    "breakaway_pressure_static_MPa",
    "applied_pressure_MPa",
    "breakaway_margin_MPa",
)


def cork_data(r, *keys):
    """CORK_KEYS and ``keys`` of a cork result ``r``."""
    return {k: r.get(k) for k in CORK_KEYS + keys}


def _save(fig, r, outdir, preset, stem, data):
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", data, r["parameters"])


def result(preset="fast", **overrides):
    """The scene's result dict (cached: see plots.cached_run)."""
    return cached_run("cork", preset, **overrides)


def _geometry(params):
    P = params
    mesh = cork_mesh(P["R_tip"], P["R_cork"], P["L_neck"], P["L_neck"] + P["r_mouth"] + P["L_head"], P["n_r"], P["n_z"])
    neck = bottle_neck(P["R_neck"], P["L_neck"], P["r_mouth"], z_low=-P["gas_column"])
    return mesh, neck


def draw_mesh(ax, mesh, x, color="k", lw=0.6):
    """The quadrilaterals of `mesh` at node positions x (nn, 2), and their mirror image."""
    for sign in (1.0, -1.0):
        for quad in mesh.t.T:
            q = x[np.append(quad, quad[0])]
            ax.plot(sign * q[:, 0], q[:, 1], color=color, lw=lw)


def draw_neck(ax, neck, gas_column=None):
    """Both walls of the rigid neck (and the gas column below the cork)."""
    P = neck.outline()
    for sign in (1.0, -1.0):
        ax.plot(sign * P[:, 0], P[:, 1], color="0.25", lw=2.0)
    if gas_column is not None:
        R_neck = P[0, 0]  # the wall's radius: the neck's first point
        ax.fill_between([-R_neck, R_neck], -gas_column, 0.0, color="#cfe3f5", zorder=0)


@figure("fig14_cork_mesh", "Fig 14")
def fig14_cork_mesh(preset="fast", outdir=None, r=None):
    plt = pyplot()
    r = r or result(preset)
    mesh, neck = _geometry(r["parameters"])
    fig, axes = plt.subplots(1, 2, figsize=(9, 6.5), sharey=True)
    draw_mesh(axes[0], mesh, mesh.p.T)
    axes[0].set_title(f"free cork: {r['n_elements']} four-node elements")
    draw_neck(axes[1], neck, r["parameters"]["gas_column"])
    draw_mesh(axes[1], mesh, np.asarray(r["snapshots_x"][0]))
    fitted = "fitted through R_tip" if r.get("press_fit_calibrated") else "R_tip not the fitted value"
    axes[1].set_title(
        f"pressed in: normal force {r['press_fit_normal_force_N']:.0f} N (paper ~2500 N)\n"
        f"{fitted}; static breakaway margin {r['breakaway_margin_MPa']:+.3f} MPa",
        fontsize=10,
    )
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("r (mm)")
    axes[0].set_ylabel("z (mm)")
    fig.suptitle(f"Fig 14: the cork (axisymmetric, the meridian mirrored; R_tip = {r['parameters']['R_tip']:g} mm)")
    return _save(
        fig,
        r,
        outdir,
        preset,
        "fig14_cork_mesh",
        dict(cork_data(r, "n_elements"), x_free=mesh.p.T, x_pressed=r["snapshots_x"][0]),
    )


@figure("fig15_cork_configurations", "Fig 15")
def fig15_cork_configurations(preset="fast", outdir=None, r=None):
    plt = pyplot()
    r = r or result(preset)
    mesh, neck = _geometry(r["parameters"])
    xs, ts, tp = r["snapshots_x"], r["snapshot_times_ms"], r["snapshot_paper_times_ms"]
    fig, axes = plt.subplots(1, len(xs), figsize=(1.9 * len(xs), 5.5), sharey=True)
    top = max(np.max(np.asarray(x)[:, 1]) for x in xs)
    for ax, x, t, t_paper in zip(axes, xs, ts, tp):
        draw_neck(ax, neck)
        draw_mesh(ax, mesh, np.asarray(x), lw=0.4)
        ax.set_title(f"{t:.2f} ms\n(paper {t_paper:.1f})", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlim(-20, 20)
        ax.set_ylim(-4, top + 2)
        ax.set_xticks([])
    v = r["exit_velocity_m_s"]
    fig.suptitle(
        "Fig 15: the cork leaving the bottle"
        + (f"; exit velocity {v:.1f} m/s (paper ~28 m/s)" if v is not None else "; it did not leave")
    )
    return _save(
        fig,
        r,
        outdir,
        preset,
        "fig15_cork_configurations",
        cork_data(r, "snapshot_times_ms", "snapshot_paper_times_ms", "snapshots_x"),
    )


@figure("fig16_cork_pressure", "Fig 16")
def fig16_cork_pressure(preset="fast", outdir=None, r=None):
    plt = pyplot()
    r = r or result(preset)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.step(r["time_ms"], r["pressure_MPa"], where="pre", color="C0", label="gas pressure (used in the step)")
    if r["gas_release_time_ms"] is not None:
        ax.axvline(r["gas_release_time_ms"], color="0.5", ls="--", lw=0.8, label="bottom passes the mouth")
    P = r["parameters"]
    p0 = P["p_step"] * P["n_ramp"]
    L, gas = P["L_neck"], P["gas_column"]
    ax.axhline(
        p0 * gas / (gas + L),
        color="C3",
        ls=":",
        lw=1,
        label=f"Boyle at {L:g} mm travel: {p0:g} * {gas:g}/{gas + L:g} = {p0 * gas / (gas + L):.3g} MPa",
    )
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("p (MPa)")
    ax.set_title("Fig 16: the pressure on the cork")
    ax.legend(fontsize=8)
    return _save(
        fig,
        r,
        outdir,
        preset,
        "fig16_cork_pressure",
        dict(cork_data(r, "gas_release_time_ms", "time_ms", "pressure_MPa"), boyle_pressure_MPa=p0 * gas / (gas + L)),
    )


@figure("fig17_cork_displacement", "Fig 17")
def fig17_cork_displacement(preset="fast", outdir=None, r=None):
    plt = pyplot()
    r = r or result(preset)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(r["time_ms"], r["displacement_bottom_mm"], label="bottom centre")
    ax.plot(r["time_ms"], r["displacement_cm_mm"], label="centre of mass")
    ax.plot(r["time_ms"], r["displacement_top_mm"], label="top centre")
    ax.axhline(r["parameters"]["L_neck"], color="0.5", ls="--", lw=0.8, label="length of the neck")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("axial displacement (mm)")
    ax.set_title("Fig 17: the displacement of the cork")
    ax.legend(fontsize=8)
    return _save(
        fig,
        r,
        outdir,
        preset,
        "fig17_cork_displacement",
        cork_data(r, "time_ms", "displacement_bottom_mm", "displacement_cm_mm", "displacement_top_mm"),
    )


# The sensitivity study of lecture 08: one reconstructed datum changed at a time, each
# at the paper's final ramp pressure 0.8 MPa and at 0.9 MPa (one more ramp step).
SENSITIVITY = (
    ("as chosen", {}),
    ("mu = 0.09", {"mu": 0.09}),
    ("mu = 0.11", {"mu": 0.11}),
    ("rho = 2.4e-10 (240 kg/m^3, lighter)", {"rho": 2.4e-10}),
    ("R_tip = 10.5 mm (less taper)", {"R_tip": 10.5}),
)
P0_STEPS = (8, 9)  # n_ramp: p0 = 0.8 MPa (paper) and 0.9 MPa, at the paper's 0.1 MPa every 0.1 ms (t_ramp)


def _case(preset, over):
    """Exit velocity (m/s), 'stays in', or 'solver failed: ...' for one run."""
    try:
        r = result(preset, **over)
    except Exception as err:  # a NewtonError is a row of the table, not hidden
        return dict(v=f"solver failed ({type(err).__name__})", F=None, p=None, exit_velocity_m_s=None)
    v = f"{r['exit_velocity_m_s']:.1f}" if r["exited"] else "stays in"
    return dict(
        v=v,
        F=r["press_fit_normal_force_N"],
        p=r["breakaway_pressure_MPa"],
        exit_velocity_m_s=r["exit_velocity_m_s"] if r["exited"] else None,
    )


def sensitivity_runs(preset="fast", cases=SENSITIVITY, jobs=2):
    """The outcome of each case at each n_ramp of P0_STEPS (case, overrides, the run's exit
    velocity and press-fit force; "v": as the table prints it); the runs in parallel on `jobs`
    cores (joblib)."""
    todo = [(label, dict(over, n_ramp=n, t_ramp=n * _RAMP)) for label, over in cases for n in P0_STEPS]
    out = joblib.Parallel(n_jobs=jobs)(joblib.delayed(_case)(preset, over) for _, over in todo)
    return [dict(x, case=label, overrides=over) for (label, over), x in zip(todo, out)]


def sensitivity_rows(preset="fast", cases=SENSITIVITY, jobs=2, runs=None):
    """One row per case: label, press-fit force, and the outcome for each n_ramp of
    P0_STEPS (``runs``: sensitivity_runs made before, else made here)."""
    out = runs or sensitivity_runs(preset, cases, jobs)
    spread = recorded("table_cork_sensitivity", preset)  # an exit velocity rounding moves: with its spread

    def v(k):
        x = out[k]
        return (
            x["v"]
            if x["exit_velocity_m_s"] is None
            else held(x["exit_velocity_m_s"], spread.get(f"runs[{k}].exit_velocity_m_s"), 1)
        )

    rows = []
    for i, (label, _) in enumerate(cases):
        ks = range(i * len(P0_STEPS), (i + 1) * len(P0_STEPS))
        F = next((out[k]["F"] for k in ks if out[k]["F"] is not None), None)
        rows.append((label, F, [v(k) for k in ks]))
    return rows


def sensitivity_markdown(rows, preset):
    """The table's lines: a header and one line per row of ``sensitivity_rows``, then the note."""
    heads = " | ".join(f"v at p0 = {0.1 * n:.1f} MPa (m/s)" for n in P0_STEPS)
    lines = [f"| case | press-fit force (N) | {heads} |", "|---|---|" + "---|" * len(P0_STEPS)]
    for label, F, vs in rows:
        lines.append(f"| {label} | {'-' if F is None else format(F, '.0f')} | " + " | ".join(vs) + " |")
    lines.append("")
    lines.append(f"Paper: ~2500 N, 28 m/s at p0 = 0.8 MPa. Preset: {preset}.")
    return "\n".join(lines) + "\n"


def sensitivity_reprinted(d):
    """table_cork_sensitivity.md made again from its data (``d``: NAME.json's record), without a run."""
    keys = dict(v="outcome", F="press_fit_normal_force_N", exit_velocity_m_s="exit_velocity_m_s")
    runs = [{k: x[v] for k, v in keys.items()} for x in d["runs"]]
    return sensitivity_markdown(sensitivity_rows(d["preset"], runs=runs), d["preset"])


@figure("table_cork_sensitivity", "Sec 5.5")
def table_cork_sensitivity(preset="fast", outdir=None):
    """Markdown table of the exit velocity against the reconstructed data (and its numbers, .json)."""
    path = Path(outdir or default_outdir(preset)) / "table_cork_sensitivity.md"
    path.parent.mkdir(parents=True, exist_ok=True)
    runs = sensitivity_runs(preset)
    path.write_text(sensitivity_markdown(sensitivity_rows(preset, runs=runs), preset))
    data = dict(
        preset=preset,
        runs=[
            dict(
                case=x["case"],
                overrides=x["overrides"],
                exit_velocity_m_s=x["exit_velocity_m_s"],
                outcome=x["v"],
                press_fit_normal_force_N=x["F"],
                breakaway_pressure_MPa=x["p"],
            )
            for x in runs
        ],
    )
    parameters = dict(scenes.get_scene("cork").resolve(preset), cases=dict(SENSITIVITY), n_ramp=P0_STEPS)
    return [str(path), write_data(path.with_suffix(".json"), data, parameters)]


# The knife's edge. The static breakaway margin needs only the press fit (a few seconds a
# point): it is drawn as a field over (mu, R_tip). The exit needs the whole run (a cork that
# stays in is the slowest: it chatters between stick and slip until t_end), so full runs are
# made at a few points. The runs use the fast preset: the paper's mesh and press fit (the same
# margin) with coarser steps around the exit. CONTACTFEM_SLOW=1: the full grid.
KNIFE_PRESET = "fast"
KNIFE_GRID = dict(
    mu=(0.095, 0.1, 0.105),
    R_tip=(10.0, 10.05, 10.1),
    runs=((0.095, 10.0), (0.1, 10.0), (0.105, 10.0), (0.1, 10.05), (0.1, 10.1)),
    p0=(0.78, 0.8, 0.84),
)
KNIFE_GRID_SLOW = dict(
    mu=(0.09, 0.095, 0.0975, 0.1, 0.1025, 0.105, 0.11),
    R_tip=(10.0, 10.025, 10.05, 10.1, 10.15, 10.2),
    runs="all",
    p0=(0.72, 0.76, 0.78, 0.79, 0.8, 0.82, 0.84, 0.88),
)


def knife_grid():
    """The coarse grid, or the full one when CONTACTFEM_SLOW is set."""
    return KNIFE_GRID_SLOW if environment.read("CONTACTFEM_SLOW") else KNIFE_GRID


def _margin_case(preset, over):
    try:
        return dict(
            over, **stored(cork_scene.press_fit_only)(scenes.get_scene("cork").resolve(preset, over)), error=None
        )
    except Exception as err:  # a failed press fit is a point of the figure, not hidden
        return dict(over, breakaway_margin_MPa=None, error=type(err).__name__)


def _run_case(preset, over):
    """Outcome of one whole run: exit velocity (None: stays in), static breakaway margin, or the error."""
    try:
        r = result(preset, **over)
    except Exception as err:
        return dict(over, exited=None, v=None, margin=None, error=type(err).__name__)
    return dict(
        over,
        exited=bool(r["exited"]),
        v=r["exit_velocity_m_s"],
        margin=r["breakaway_margin_MPa"],
        force=r["press_fit_normal_force_N"],
        error=None,
    )


def knife_edge_data(preset=KNIFE_PRESET, grid=None, jobs=2):
    """Margins (press fit only) over the (mu, R_tip) grid, whole runs at grid["runs"] and over
    p0 (n_ramp = 8, p_step = p0 / 8) at the fitted mu, R_tip. Returns dict(field, runs, p0, preset)."""
    g = grid or knife_grid()
    field = [dict(mu=m, R_tip=R) for m in g["mu"] for R in g["R_tip"]]
    runs = [
        dict(mu=m, R_tip=R) for m, R in (g["runs"] if g["runs"] != "all" else [(f["mu"], f["R_tip"]) for f in field])
    ]
    line = [dict(p_step=p0 / 8.0, n_ramp=8) for p0 in g["p0"]]
    todo = [(_margin_case, o) for o in field] + [(_run_case, o) for o in runs + line]
    out = joblib.Parallel(n_jobs=jobs)(joblib.delayed(fn)(preset, o) for fn, o in todo)
    nf, nr = len(field), len(runs)
    for o in out[nf + nr :]:
        o["p0"] = o["p_step"] * o["n_ramp"]
    return dict(field=out[:nf], runs=out[nf : nf + nr], p0=out[nf + nr :], preset=preset)


@figure("cork_knife_edge", "Sec 5.5")
def cork_knife_edge(preset="fast", outdir=None, data=None):
    """Exit velocity (or "stays in") over (mu, R_tip) and over p0, on the field of the static
    breakaway margin p0 - mu N / (pi R^2); its zero line is the knife's edge. Always computed
    with KNIFE_PRESET (see above), whatever `preset`."""
    plt = pyplot()
    d = data or knife_edge_data()
    fig, (ax, ap) = plt.subplots(1, 2, figsize=(11.5, 4.8))
    mus = sorted({o["mu"] for o in d["field"]})
    Rs = sorted({o["R_tip"] for o in d["field"]})
    M = np.full((len(Rs), len(mus)), np.nan)
    for o in d["field"]:
        if o["breakaway_margin_MPa"] is not None:
            M[Rs.index(o["R_tip"]), mus.index(o["mu"])] = o["breakaway_margin_MPa"]
    if np.isfinite(M).all() and len(mus) > 1 and len(Rs) > 1:
        lim = np.max(np.abs(M))
        cs = ax.contourf(mus, Rs, M, levels=np.linspace(-lim, lim, 13), cmap="RdBu", alpha=0.45)
        fig.colorbar(cs, ax=ax, label="margin p0 - mu N / (pi R^2) (MPa)")
        if M.min() < 0 < M.max():
            ax.contour(mus, Rs, M, levels=[0.0], colors="k", linewidths=1.5)
    for o in d["field"]:
        if o["error"]:
            ax.plot(o["mu"], o["R_tip"], "k^", ms=7)
    spread = recorded("cork_knife_edge")  # the same runs whatever the preset (KNIFE_PRESET)
    for i, o in enumerate(d["runs"]):
        if o["error"]:
            text, style = "solver failed", dict(marker="^", color="k")
        elif o["exited"]:  # a velocity rounding moves: with its spread
            text, style = f"{held(o['v'], spread.get(f'runs[{i}].v'), 1)} m/s", dict(marker="o", color="tab:green")
        else:
            text, style = "stays in", dict(marker="x", color="tab:red", mew=2)
        ax.plot(o["mu"], o["R_tip"], ls="none", ms=9, **style)
        ax.annotate(text, (o["mu"], o["R_tip"]), fontsize=8, xytext=(5, 4), textcoords="offset points")
    ax.plot(0.1, 10.0, "s", mfc="none", mec="k", ms=18)
    dx, dy = 0.12 * (mus[-1] - mus[0]), 0.12 * (Rs[-1] - Rs[0])
    ax.set_xlim(mus[0] - dx, mus[-1] + 2 * dx)
    ax.set_ylim(Rs[0] - dy, Rs[-1] + dy)
    ax.set_xlabel("friction coefficient mu (paper: 0.1)")
    ax.set_ylabel("R_tip (mm); 10 fitted to the paper's ~2500 N")
    n_out = sum(1 for o in d["runs"] if o["exited"])
    ax.set_title(
        f"p0 = 0.8 MPa: the cork leaves in {n_out} of {len(d['runs'])} runs; black line: margin 0\n"
        "(static breakaway = applied pressure); square: the fitted point",
        fontsize=9,
    )
    line = sorted(d["p0"], key=lambda o: o["p0"])
    ok = [o for o in line if o["error"] is None]
    ap.plot([o["p0"] for o in ok], [o["v"] if o["exited"] else 0.0 for o in ok], "o:", color="tab:green", lw=0.8)
    for o in ok:
        if not o["exited"]:
            ap.annotate("stays in", (o["p0"], 0.0), fontsize=8, xytext=(0, 6), textcoords="offset points", ha="center")
    for o in line:
        if o["error"]:
            ap.annotate("solver failed", (o["p0"], 0.0), fontsize=8, xytext=(0, 16), textcoords="offset points")
    static = [o["p0"] - o["margin"] for o in ok]
    if static:
        ap.axvline(
            np.mean(static),
            color="k",
            ls="--",
            lw=1,
            label=f"static breakaway mu N / (pi R^2) = {np.mean(static):.3f} MPa",
        )
    ap.axhline(28.0, color="0.5", ls=":", lw=1, label="paper: ~28 m/s at 0.8 MPa")
    ap.set_xlabel("applied pressure p0 (MPa); mu = 0.1, R_tip = 10 mm")
    ap.set_ylabel("exit velocity (m/s); 0: stays in")
    ap.legend(fontsize=8, loc="center right")
    ap.set_title("over the applied pressure", fontsize=9)
    fig.suptitle(
        f"The cork's knife edge (preset {d['preset']}: the paper's mesh and press fit). "
        "The press-fit force is fitted through R_tip",
        fontsize=10,
    )
    fig.tight_layout()
    return save_figure(
        fig,
        Path(outdir or default_outdir(preset)) / "cork_knife_edge.png",
        d,
        dict(scenes.get_scene("cork").resolve(d["preset"]), grid=knife_grid()),
    )


# The exit time. The paper reports the exit "between 2.6 and 2.7 ms"; what moves ours? The
# closing step of the contact (contact/interface.py: a node that touches within a step starts
# its stick spring where it touched) switched off in the press fit, in the pop or in both; the
# press fit's increments; the time step in the neck with the pressure ramp kept at the paper's
# 8 steps of 0.1 ms (``ramp``); the steps near the exit (dt_fine, travel_max); c_T; the
# breakaway margin (mu, R_tip). Always the paper preset (the question is about its exit).
# The quick profile (CI, `contactfem figures --only cork_exit`): the closing step in each stage,
# the press fit refined eightfold, one refined time step; CONTACTFEM_SLOW=1: every case.
EXIT_PRESET = "paper"
_ON, _OFF = (True, True), (False, False)
_RAMP = 1e-4  # s: the paper's ramp, 8 steps of 0.1 MPa every 0.1 ms (t_ramp / n_ramp), kept when dt is refined
_STEP = "time step in the neck (ramp kept)"
EXIT_CASES_QUICK = (
    # group, label, scene overrides, (closing step in the press fit, in the pop), ramp step (s)
    ("closing step", "paper preset", {}, _ON, None),
    ("closing step", "without the closing step", {}, _OFF, None),
    ("closing step", "closing step in the press fit only", {}, (True, False), None),
    ("press-fit increments", "n_press = 160", {"n_press": 160}, _ON, None),
    ("press-fit increments", "n_press = 160", {"n_press": 160}, _OFF, None),
    (_STEP, "dt = 2.5e-05 s", {"dt": 2.5e-5}, _ON, _RAMP),
    (_STEP, "dt = 2.5e-05 s", {"dt": 2.5e-5}, _OFF, _RAMP),
)
EXIT_CASES_SLOW = EXIT_CASES_QUICK + (
    ("closing step", "closing step in the pop only", {}, (False, True), None),
    *(("press-fit increments", f"n_press = {n}", {"n_press": n}, rule, None) for n in (40, 80) for rule in (_ON, _OFF)),
    *((_STEP, f"dt = {dt:g} s", {"dt": dt}, rule, _RAMP) for dt in (5e-5, 1.25e-5) for rule in (_ON, _OFF)),
    *(
        (_STEP, f"dt = 2.5e-05 s, n_press = {n}", {"dt": 2.5e-5, "n_press": n}, rule, _RAMP)
        for n in (40, 80)
        for rule in (_ON, _OFF)
    ),
    *(
        ("steps near the exit", f"{k} = {v:g}", {k: v}, rule, None)
        for k, v in (("dt_fine", 2.5e-6), ("dt_fine", 1e-5), ("travel_max", 0.25), ("travel_max", 1.0))
        for rule in (_ON, _OFF)
    ),
    *(("stick stiffness", f"c_T = {c:g}", {"c_T": c}, rule, None) for c in (5.0, 20.0) for rule in (_ON, _OFF)),
    *(
        ("breakaway margin", f"{k} = {v:g}", {k: v}, rule, None)
        for k, v in (("mu", 0.098), ("mu", 0.102), ("R_tip", 10.02))
        for rule in (_ON, _OFF)
    ),
)


def exit_cases():
    """The quick profile, or every case when CONTACTFEM_SLOW is set."""
    return EXIT_CASES_SLOW if environment.read("CONTACTFEM_SLOW") else EXIT_CASES_QUICK


def exit_case(case, preset=EXIT_PRESET):
    """One run of the cork (the stages of scenes/cork.py, as the scene simulates them) with the
    closing step of its contact on or off in each stage and, with a ramp step, the time step
    refined under the unchanged pressure ramp. Returns the case with the exit time and
    velocity, the press-fit force and the slowest speed of the cork after the ramp (its stall)."""
    group, label, over, (fit_rule, pop_rule), ramp = case
    row = dict(
        group=group,
        label=label,
        overrides=dict(over),
        closing_step_press_fit=fit_rule,
        closing_step_pop=pop_rule,
        ramp_step_s=ramp,
    )
    try:
        P = scenes.get_scene("cork").resolve(preset, over)  # (the ramp is t_ramp's: a finer dt keeps it)
        model = cork_scene.build(P)
        contacts = model.parts["contacts"]
        rules = ([c.with_closing_step(fit_rule) for c in contacts], [c.with_closing_step(pop_rule) for c in contacts])
        systems = cork_scene.stage_systems(model.parts, P, contacts=rules)
        model = replace(model, systems=systems, stages=cork_scene.stages(systems, model.parts, P))
        records = simulate(model, P)
    except Exception as err:  # a failed run is a row of the study, not hidden
        return dict(row, exited=None, error=f"{type(err).__name__}: {str(err).splitlines()[0][:100]}")
    fit_last, pop = [r for r in records if r.stage == 0][-1], [r for r in records if r.stage == 1]
    exited, exit_time, _ = cork_scene.exit_of(pop)
    h = cork_scene.history(model, pop)
    after = np.flatnonzero(h["t"] > P["t_ramp"] * (1 + 1e-9))
    k = after[np.argmin(h["v_cm"][after])]
    return dict(
        row,
        exited=exited,
        error=None,
        exit_time_ms=exit_time * 1e3 if exited else None,
        exit_velocity_m_s=float(h["v_cm"][-1]) if exited else None,
        press_fit_normal_force_N=cork_scene.contact_forces(fit_last.contacts)["normal"],
        v_min_after_ramp_m_s=float(h["v_cm"][k]),
        t_v_min_ms=float(h["t"][k] * 1e3),
        steps=int(len(h["t"]) - 1),
        newton_failures=sum(len(rec.failures) for rec in pop),
    )


def stored_exit_case(case, preset=EXIT_PRESET):
    """``exit_case``, kept on disk for the same code (plots.stored): the summary's cork row and
    the study share the cases (as the figures share scene runs through plots.cached_run)."""
    return stored(exit_case)(case, preset)


def cached_exit_case(case, preset=EXIT_PRESET):
    """``exit_case`` (plots.stored: run once for the same code), a copy of the row."""
    return dict(stored_exit_case(case, preset))


def exit_time_data(cases=None, jobs=2):
    """Every case of ``exit_cases()`` (those not kept yet run in parallel on ``jobs`` cores with
    joblib)."""
    cases = cases or exit_cases()
    kept = stored(exit_case).kept
    todo = [c for c in {json.dumps(c, sort_keys=True): c for c in cases}.values() if not kept(c, EXIT_PRESET)]
    if todo:
        joblib.Parallel(n_jobs=jobs)(joblib.delayed(stored_exit_case)(c) for c in todo)
    return dict(preset=EXIT_PRESET, slow=cases is EXIT_CASES_SLOW, cases=[cached_exit_case(c) for c in cases])


def exit_time_summary(d):
    """What the study shows, computed from its rows: the paper preset's exit with and without
    the closing step; whether the closing step acts in the pop (the press fit alone decides);
    both rules with the press fit refined (its most increments) at the paper's time step; both
    rules at the finest time step in the neck (ramp kept)."""
    paper = scenes.get_scene("cork").resolve(d["preset"])
    rows = [r for r in d["cases"] if r["error"] is None]

    def rule(r):
        return r["closing_step_press_fit"], r["closing_step_pop"]

    def find(label, rl):
        return next((r for r in rows if r["label"] == label and rule(r) == rl), None)

    on, off = find("paper preset", _ON), find("without the closing step", _OFF)
    fit_only = find("closing step in the press fit only", (True, False))
    n_max = max(r["overrides"]["n_press"] for r in rows if r["group"] == "press-fit increments")
    fit = {name: find(f"n_press = {n_max}", rl)["exit_time_ms"] for name, rl in (("with", _ON), ("without", _OFF))}
    refined = [r for r in rows if r["group"] == _STEP and "n_press" not in r["overrides"]]
    dt_min = min(r["overrides"]["dt"] for r in refined)
    fine = {name: find(f"dt = {dt_min:g} s", rl)["exit_time_ms"] for name, rl in (("with", _ON), ("without", _OFF))}
    # a shift within RTOL of the exit (2e-8 ms on this machine) is rounding's, not the rule's: 0
    pop_shift = fit_only["exit_time_ms"] - on["exit_time_ms"]
    return dict(
        exit_ms=on["exit_time_ms"],
        exit_velocity_m_s=on["exit_velocity_m_s"],
        exit_without_ms=off["exit_time_ms"],
        shift_ms=on["exit_time_ms"] - off["exit_time_ms"],
        pop_rule_shift_ms=pop_shift if abs(pop_shift) > RTOL * on["exit_time_ms"] else 0.0,
        n_press=paper["n_press"],
        n_press_refined=n_max,
        press_fit_refined_ms=fit,
        dt_paper_s=paper["dt"],
        dt_refined_s=dt_min,
        refined_ms=fine,
        paper_window_ms=(2.6, 2.7),
    )


def exit_time_markdown(d):
    s = exit_time_summary(d)
    spread = recorded("cork_exit_time", d["preset"])  # a number rounding moves: with its spread (a count: range)

    def ms(*key):  # a number of the summary, to 3 decimals or to what rounding leaves of them
        return held(s[key[0]] if len(key) == 1 else s[key[0]][key[1]], spread.get(".".join(("summary",) + key)), 3)

    def apart(a, b):  # a difference of two of them, with at most the sum of their spreads
        entries = [spread.get("summary." + k) or {} for k in (a, b)]
        value = lambda k: s[k] if k in s else s[k.split(".")[0]][k.split(".")[1]]
        return held(value(a) - value(b), None, 3, sum(e["hi"] - e["lo"] for e in entries if "hi" in e))

    fit, ref = (
        {k: ms("press_fit_refined_ms", k) for k in ("with", "without")},
        {k: ms("refined_ms", k) for k in ("with", "without")},
    )
    lines = [
        "# The cork's exit time: the closing step and the discretisation (paper preset)",
        "",
        "Written by `contactfem figures --only cork_exit` (contactfem/plots/cork.py) with "
        + ("every case (CONTACTFEM_SLOW=1)." if d["slow"] else "the quick profile (CONTACTFEM_SLOW=1: every case).")
        + " The paper: exit between 2.6 and 2.7 ms at about 28 m/s.",
        "",
        f"- At the paper's time step in the neck ({s['dt_paper_s']:g} s) and the preset's {s['n_press']} press-fit "
        f"increments the cork leaves at {ms('exit_ms')} ms with the closing step, at "
        f"{ms('exit_without_ms')} ms without it (a shift of {ms('shift_ms')} ms).",
        "- The rule acts through the press fit: with the closing step in the press fit only, the exit "
        + (
            f"moves by {s['pop_rule_shift_ms']:+.1e} ms."
            if s["pop_rule_shift_ms"]
            else f"does not move (the two runs agree to {RTOL:.0e} of it: rounding)."
        ),
        f"- With the press fit refined to {s['n_press_refined']} increments both rules give {fit['with']} and "
        f"{fit['without']} ms: the closing step is "
        f"{apart('press_fit_refined_ms.with', 'exit_ms')} ms from that with {s['n_press']} increments, "
        f"the rule without it {apart('press_fit_refined_ms.without', 'exit_without_ms')} ms "
        "(it loads the stick springs of the nodes that touch during an increment with the travel "
        "made before touching, an error of the increment's size).",
        f"- With the time step in the neck refined to {s['dt_refined_s']:g} s (the pressure ramp kept at 8 x 0.1 ms) "
        f"both rules give {ref['with']} and {ref['without']} ms: the paper's step leaves a "
        f"time-discretisation error of {apart('exit_ms', 'refined_ms.with')} ms in the stall after the ramp.",
        "- The slowest speed after the ramp is that stall: the gas expands (Boyle), its pressure falls "
        "below the static breakaway, the cork slows down; how far it slows sets the exit time.",
        "",
        "| group | case | closing step (press fit, pop) | exit (ms) | exit velocity (m/s) | "
        "slowest after the ramp (m/s, at ms) | press-fit force (N) | steps |",
        "|---|---|---|---:|---:|---:|---:|---:|",
    ]
    onoff = {True: "on", False: "off"}
    spread = recorded("cork_exit_time", d["preset"])  # a number rounding moves: with its spread (a count: range)
    for i, r in enumerate(d["cases"]):
        f = lambda key, decimals: held(r[key], spread.get(f"cases[{i}].{key}"), decimals)  # noqa: E731
        if r["error"]:
            tail = f"| {r['error']} | | | | |"
        elif r["exited"]:
            tail = (
                f"| {f('exit_time_ms', 3)} | {f('exit_velocity_m_s', 2)} | {f('v_min_after_ramp_m_s', 2)} at "
                f"{f('t_v_min_ms', 2)} | {f('press_fit_normal_force_N', 1)} | {f('steps', 0)} |"
            )
        else:
            tail = (
                f"| stays in | - | {f('v_min_after_ramp_m_s', 2)} at {f('t_v_min_ms', 2)} | "
                f"{f('press_fit_normal_force_N', 1)} | {f('steps', 0)} |"
            )
        lines.append(
            f"| {r['group']} | {r['label']} | {onoff[r['closing_step_press_fit']]}, "
            f"{onoff[r['closing_step_pop']]} " + tail
        )
    return "\n".join(lines) + "\n"


@figure("cork_exit_time", "Sec 5.5")
def cork_exit_time(preset="fast", outdir=None, data=None):
    """Exit time of every case of the study (filled: with the closing step, hollow: without),
    the paper's window shaded; the markdown table and the data beside it. Always the paper
    preset (EXIT_PRESET), whatever `preset`."""
    plt = pyplot()
    d = data or exit_time_data()
    s = exit_time_summary(d)
    rows = d["cases"]
    labels = list(dict.fromkeys((r["group"], r["label"]) for r in rows))
    fig, ax = plt.subplots(figsize=(9, 0.32 * len(labels) + 1.8))
    ax.axvspan(*s["paper_window_ms"], color="0.85", label="paper: 2.6-2.7 ms")
    exits = [r["exit_time_ms"] for r in rows if r["exited"]]
    t_max, t_min = max(exits + [2.7]) + 0.05, min(exits + [2.6]) - 0.05
    for r in rows:
        y = labels.index((r["group"], r["label"]))
        on = r["closing_step_press_fit"]
        style = dict(marker="o", ms=7, color="tab:blue" if on else "tab:orange", mfc=None if on else "none")
        if r["exited"]:
            ax.plot(r["exit_time_ms"], y, ls="none", **style)
        else:
            ax.plot(t_max + 0.1, y, ls="none", **dict(style, marker=">"))
            ax.annotate(
                "stays in" if r["error"] is None else "failed",
                (t_max + 0.1, y),
                fontsize=7,
                xytext=(6, -3),
                textcoords="offset points",
            )
    ax.plot([], [], "o", color="tab:blue", label="closing step in the press fit (the code)")
    ax.plot([], [], "o", color="tab:orange", mfc="none", label="without it in the press fit")
    ax.set_yticks(range(len(labels)))
    ax.set_yticklabels([f"{g}: {lab}" for g, lab in labels], fontsize=7)
    ax.set_ylim(len(labels) - 0.5, -0.5)
    ax.set_xlabel("exit time (ms)")
    ax.set_xlim(t_min, t_max + 0.3)
    ax.grid(axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(
        f"The cork's exit time (paper preset): {s['exit_ms']:.2f} ms with the closing step, "
        f"{s['exit_without_ms']:.2f} without; with the press fit refined\n({s['n_press_refined']} "
        f"increments) both give {s['press_fit_refined_ms']['with']:.2f} ms, with the time step in the neck "
        f"refined ({s['dt_refined_s']:g} s) {s['refined_ms']['with']:.2f} ms",
        fontsize=9,
    )
    fig.tight_layout()
    out = Path(outdir or default_outdir(EXIT_PRESET))
    out.mkdir(parents=True, exist_ok=True)
    (out / "cork_exit_time.md").write_text(exit_time_markdown(d))
    png, data = save_figure(
        fig, out / "cork_exit_time.png", dict(d, summary=s), scenes.get_scene("cork").resolve(d["preset"])
    )
    return [png, str(out / "cork_exit_time.md"), data]
