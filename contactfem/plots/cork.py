"""Figures 14-17 of the paper: the champagne cork (Sec. 5.5).

    fig14_cork_mesh             Fig 14: the mesh of the free cork, and pressed into the neck
    fig15_cork_configurations   Fig 15: the cork at the paper's instants (0 ... 3.0 ms), mapped
                                onto our run (``scenes.cork.snapshot_times``)
    fig16_cork_pressure         Fig 16: the gas pressure on the cork against time
    fig17_cork_displacement     Fig 17: the axial displacement of the cork against time
    table_cork_sensitivity      exit velocity against the reconstructed data (lecture 08)
    cork_knife_edge             exit velocity or "stays in" over (mu, R_tip) and over p0, with the
                                static breakaway margin: the example sits on a knife's edge

The problem is axisymmetric (x = r, y = z); the drawings mirror the meridian in the
axis to show the whole cork and both sides of the neck.
"""


import os

import numpy as np

from ..contact.masters import bottle_neck
from ..scenes.base import jsonable
from . import cached_run, default_outdir, figure, pyplot, savefig


def result(preset="fast", **overrides):
    """The scene's result dict (cached: see plots.cached_run)."""
    return cached_run("cork", preset, **overrides)


def _geometry(params):
    from ..bodies.meshes import cork_mesh

    P = params
    mesh = cork_mesh(P["R_tip"], P["R_cork"], P["L_neck"], P["L_neck"] + P["r_mouth"] + P["L_head"],
                     P["n_r"], P["n_z"])
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
        R_neck = P[0, 0]                             # the wall's radius: the neck's first point
        ax.fill_between([-R_neck, R_neck], -gas_column, 0.0, color="#cfe3f5", zorder=0)


@figure("fig14_cork_mesh", "Fig 14")
def fig14_cork_mesh(preset="fast", outdir=None):
    plt = pyplot()
    r = result(preset)
    mesh, neck = _geometry(r["parameters"])
    fig, axes = plt.subplots(1, 2, figsize=(9, 6.5), sharey=True)
    draw_mesh(axes[0], mesh, mesh.p.T)
    axes[0].set_title(f"free cork: {r['n_elements']} four-node elements")
    draw_neck(axes[1], neck, r["parameters"]["gas_column"])
    draw_mesh(axes[1], mesh, np.asarray(r["snapshots_x"][0]))
    fitted = "fitted through R_tip" if r.get("press_fit_calibrated") else "R_tip not the fitted value"
    axes[1].set_title(f"pressed in: normal force {r['press_fit_normal_force_N']:.0f} N (paper ~2500 N)\n"
                      f"{fitted}; static breakaway margin {r['breakaway_margin_MPa']:+.3f} MPa", fontsize=10)
    for ax in axes:
        ax.set_aspect("equal")
        ax.set_xlabel("r (mm)")
    axes[0].set_ylabel("z (mm)")
    fig.suptitle(f"Fig 14: the cork (axisymmetric, the meridian mirrored; R_tip = {r['parameters']['R_tip']:g} mm)")
    return [savefig(fig, outdir or default_outdir(preset), "fig14_cork_mesh")]


@figure("fig15_cork_configurations", "Fig 15")
def fig15_cork_configurations(preset="fast", outdir=None):
    plt = pyplot()
    r = result(preset)
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
    fig.suptitle("Fig 15: the cork leaving the bottle"
                 + (f"; exit velocity {v:.1f} m/s (paper ~28 m/s)" if v is not None else "; it did not leave"))
    return [savefig(fig, outdir or default_outdir(preset), "fig15_cork_configurations")]


@figure("fig16_cork_pressure", "Fig 16")
def fig16_cork_pressure(preset="fast", outdir=None):
    plt = pyplot()
    r = result(preset)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.step(r["time_ms"], r["pressure_MPa"], where="pre", color="C0", label="gas pressure (used in the step)")
    if r["gas_release_time_ms"] is not None:
        ax.axvline(r["gas_release_time_ms"], color="0.5", ls="--", lw=0.8, label="bottom passes the mouth")
    P = r["parameters"]
    p0 = P["p_step"] * P["n_ramp"]
    L, gas = P["L_neck"], P["gas_column"]
    ax.axhline(p0 * gas / (gas + L), color="C3", ls=":", lw=1,
               label=f"Boyle at {L:g} mm travel: {p0:g} * {gas:g}/{gas + L:g} = {p0 * gas / (gas + L):.3g} MPa")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("p (MPa)")
    ax.set_title("Fig 16: the pressure on the cork")
    ax.legend(fontsize=8)
    return [savefig(fig, outdir or default_outdir(preset), "fig16_cork_pressure")]


@figure("fig17_cork_displacement", "Fig 17")
def fig17_cork_displacement(preset="fast", outdir=None):
    plt = pyplot()
    r = result(preset)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(r["time_ms"], r["displacement_bottom_mm"], label="bottom centre")
    ax.plot(r["time_ms"], r["displacement_cm_mm"], label="centre of mass")
    ax.plot(r["time_ms"], r["displacement_top_mm"], label="top centre")
    ax.axhline(r["parameters"]["L_neck"], color="0.5", ls="--", lw=0.8, label="length of the neck")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("axial displacement (mm)")
    ax.set_title("Fig 17: the displacement of the cork")
    ax.legend(fontsize=8)
    return [savefig(fig, outdir or default_outdir(preset), "fig17_cork_displacement")]


# The sensitivity study of lecture 08: one reconstructed datum changed at a time, each
# at the paper's final ramp pressure 0.8 MPa and at 0.9 MPa (one more ramp step).
SENSITIVITY = (
    ("as chosen", {}),
    ("mu = 0.09", {"mu": 0.09}),
    ("mu = 0.11", {"mu": 0.11}),
    ("rho = 2.4e-10 (240 kg/m^3, lighter)", {"rho": 2.4e-10}),
    ("R_tip = 10.5 mm (less taper)", {"R_tip": 10.5}),
)
P0_STEPS = (8, 9)      # n_ramp: p0 = 0.8 MPa (paper) and 0.9 MPa


def _case(preset, over):
    """Exit velocity (m/s), 'stays in', or 'solver failed: ...' for one run."""
    try:
        r = result(preset, **over)
    except Exception as err:                        # a NewtonError is a row of the table, not hidden
        return dict(v=f"solver failed ({type(err).__name__})", F=None, p=None)
    v = f"{r['exit_velocity_m_s']:.1f}" if r["exited"] else "stays in"
    return dict(v=v, F=r["press_fit_normal_force_N"], p=r["breakaway_pressure_MPa"])


def sensitivity_rows(preset="fast", cases=SENSITIVITY, jobs=2):
    """One row per case: label, press-fit force, and the outcome for each n_ramp of
    P0_STEPS; the runs in parallel on `jobs` cores (joblib, if installed; else one by one)."""
    todo = [(label, dict(over, n_ramp=n)) for label, over in cases for n in P0_STEPS]
    try:
        from joblib import Parallel, delayed
    except ImportError:
        out = [_case(preset, over) for _, over in todo]
    else:
        out = Parallel(n_jobs=jobs)(delayed(_case)(preset, over) for _, over in todo)
    rows = []
    for i, (label, _) in enumerate(cases):
        res = out[i * len(P0_STEPS):(i + 1) * len(P0_STEPS)]
        F = next((x["F"] for x in res if x["F"] is not None), None)
        rows.append((label, F, [x["v"] for x in res]))
    return rows


@figure("table_cork_sensitivity", "Sec 5.5")
def table_cork_sensitivity(preset="fast", outdir=None):
    """Markdown table of the exit velocity against the reconstructed data."""
    from pathlib import Path

    rows = sensitivity_rows(preset)
    heads = " | ".join(f"v at p0 = {0.1 * n:.1f} MPa (m/s)" for n in P0_STEPS)
    lines = [f"| case | press-fit force (N) | {heads} |", "|---|---|" + "---|" * len(P0_STEPS)]
    for label, F, vs in rows:
        lines.append(f"| {label} | {'-' if F is None else format(F, '.0f')} | " + " | ".join(vs) + " |")
    lines.append("")
    lines.append(f"Paper: ~2500 N, 28 m/s at p0 = 0.8 MPa. Preset: {preset}.")
    path = Path(outdir or default_outdir(preset)) / "table_cork_sensitivity.md"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return [str(path)]


# The knife's edge. The static breakaway margin needs only the press fit (a few seconds a
# point): it is drawn as a field over (mu, R_tip). The exit needs the whole run (a cork that
# stays in is the slowest: it chatters between stick and slip until t_end), so full runs are
# made at a few points. The runs use the fast preset: the paper's mesh and press fit (the same
# margin) with coarser steps around the exit. CONTACTFEM_SLOW=1: the full grid.
KNIFE_PRESET = "fast"
KNIFE_GRID = dict(mu=(0.095, 0.1, 0.105), R_tip=(10.0, 10.05, 10.1),
                  runs=((0.095, 10.0), (0.1, 10.0), (0.105, 10.0), (0.1, 10.05), (0.1, 10.1)),
                  p0=(0.78, 0.8, 0.84))
KNIFE_GRID_SLOW = dict(mu=(0.09, 0.095, 0.0975, 0.1, 0.1025, 0.105, 0.11),
                       R_tip=(10.0, 10.025, 10.05, 10.1, 10.15, 10.2),
                       runs="all", p0=(0.72, 0.76, 0.78, 0.79, 0.8, 0.82, 0.84, 0.88))


def knife_grid():
    """The coarse grid, or the full one when CONTACTFEM_SLOW is set."""
    return KNIFE_GRID_SLOW if os.environ.get("CONTACTFEM_SLOW") else KNIFE_GRID


def _margin_case(preset, over):
    from ..scenes import get_scene
    from ..scenes.cork import press_fit_only

    try:
        return dict(over, **press_fit_only(get_scene("cork").resolve(preset, over)), error=None)
    except Exception as err:                        # a failed press fit is a point of the figure, not hidden
        return dict(over, breakaway_margin_MPa=None, error=type(err).__name__)


def _run_case(preset, over):
    """Outcome of one whole run: exit velocity (None: stays in), static breakaway margin, or the error."""
    try:
        r = result(preset, **over)
    except Exception as err:
        return dict(over, exited=None, v=None, margin=None, error=type(err).__name__)
    return dict(over, exited=bool(r["exited"]), v=r["exit_velocity_m_s"], margin=r["breakaway_margin_MPa"],
                force=r["press_fit_normal_force_N"], error=None)


def knife_edge_data(preset=KNIFE_PRESET, grid=None, jobs=2):
    """Margins (press fit only) over the (mu, R_tip) grid, whole runs at grid["runs"] and over
    p0 (n_ramp = 8, p_step = p0 / 8) at the fitted mu, R_tip. Returns dict(field, runs, p0, preset)."""
    g = grid or knife_grid()
    field = [dict(mu=m, R_tip=R) for m in g["mu"] for R in g["R_tip"]]
    runs = [dict(mu=m, R_tip=R) for m, R in (g["runs"] if g["runs"] != "all" else
                                             [(f["mu"], f["R_tip"]) for f in field])]
    line = [dict(p_step=p0 / 8.0, n_ramp=8) for p0 in g["p0"]]
    todo = [(_margin_case, o) for o in field] + [(_run_case, o) for o in runs + line]
    try:
        from joblib import Parallel, delayed
    except ImportError:
        out = [fn(preset, o) for fn, o in todo]
    else:
        out = Parallel(n_jobs=jobs)(delayed(fn)(preset, o) for fn, o in todo)
    nf, nr = len(field), len(runs)
    for o in out[nf + nr:]:
        o["p0"] = o["p_step"] * o["n_ramp"]
    return dict(field=out[:nf], runs=out[nf:nf + nr], p0=out[nf + nr:], preset=preset)


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
    for o in d["runs"]:
        if o["error"]:
            text, style = "solver failed", dict(marker="^", color="k")
        elif o["exited"]:
            text, style = f"{o['v']:.1f} m/s", dict(marker="o", color="tab:green")
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
    ax.set_title(f"p0 = 0.8 MPa: the cork leaves in {n_out} of {len(d['runs'])} runs; black line: margin 0\n"
                 "(static breakaway = applied pressure); square: the fitted point", fontsize=9)
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
        ap.axvline(np.mean(static), color="k", ls="--", lw=1,
                   label=f"static breakaway mu N / (pi R^2) = {np.mean(static):.3f} MPa")
    ap.axhline(28.0, color="0.5", ls=":", lw=1, label="paper: ~28 m/s at 0.8 MPa")
    ap.set_xlabel("applied pressure p0 (MPa); mu = 0.1, R_tip = 10 mm")
    ap.set_ylabel("exit velocity (m/s); 0: stays in")
    ap.legend(fontsize=8, loc="center right")
    ap.set_title("over the applied pressure", fontsize=9)
    fig.suptitle(f"The cork's knife edge (preset {d['preset']}: the paper's mesh and press fit). "
                 "The press-fit force is fitted through R_tip", fontsize=10)
    fig.tight_layout()
    import json
    from pathlib import Path

    out = Path(outdir or default_outdir(preset))
    out.mkdir(parents=True, exist_ok=True)
    (out / "cork_knife_edge.json").write_text(json.dumps(jsonable(d), indent=1))   # the data, to redraw
    return [savefig(fig, str(out), "cork_knife_edge"), str(out / "cork_knife_edge.json")]
