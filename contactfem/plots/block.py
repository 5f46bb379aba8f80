"""Figures 6-8 and Table 1 of the paper: the elastic block on a rough rigid
foundation (Sec. 5.1), whole load in one step.

    fig06_block_mesh_deformed         Fig 6: system, discretisation, deformed configuration
    fig07_block_conical_stresses      Fig 7: normal and friction stress on the contact side, conical slip surface
    fig08_block_parabolic_stresses    Fig 8: the same for the parabolic slip surface
    fig08b_block_fig8_readings        Fig 8 of the preset beside Fig 8 of the reading (preset fig8)
                                      that shows the paper's remark (figures/NAME.json: the numbers)
    table1_block_newton_residuals     Table 1: ||G|| per Newton iteration, ours beside the paper's (.md and .png)

Each function draws from results it is given (a lecture passes the result of its own
time loop: ``fig07(preset, outdir, r=...)``, ``fig06(..., body=..., records=...)``) or, given
none, runs the scene (``contactfem figures``). The paper's figures also show Oden & Pires'
results; their numbers are not available here, so only ours are drawn. The stresses are tractions (force per
unit length of the contact side); the normal stress is drawn as the pressure
|t_N|, the friction stress as t_T (> 0: the foundation holds the block back).
"""

import math
from pathlib import Path

import numpy as np

from ..scenes.block import SCENE, solve
from ..scenes.block import FIG8_DROP, PAPER_TABLE1, PAPER_TABLE1_UNCERTAIN, fig8_remark
from ..solver.newton import NewtonError
from . import cached_run, default_outdir, describe_newton, diverged_at, figure  # noqa: F401
from . import fitted_words, pyplot, savefig  # noqa: F401
from .data import save_figure
from .. import lazy

mcollections = lazy.module("matplotlib.collections")

STATE_COLORS = {"stick": "tab:blue", "slip": "tab:red", "open": "0.6"}


def result(preset="fast", **overrides):
    """The block scene's JSON result (cached: see plots.cached_run)."""
    return cached_run("block", preset, **overrides)


def draw_mesh(ax, X, t, **kw):
    """Outline every quadrilateral of the mesh (nodes X (nn, 2), connectivity t (4, nel))."""
    ax.add_collection(mcollections.PolyCollection(X[t.T], facecolors="none", **kw))


@figure("fig06_block_mesh_deformed", "Fig 6")
def fig06(preset="fast", outdir=None, law="conical", params=None, body=None, records=None):
    """Fig 6 from the records of a block run (``body`` and ``records`` of a march, ``params``
    its parameters), or from a run of the scene (``law``) if none are given."""
    plt = pyplot()
    P = params if params is not None else SCENE.resolve(preset, {"law": law})
    law = P["law"]
    if records is None:
        s = solve(P)
        body, u, rep = s["body"], s["u"], s["report"]
    else:
        u, rep = records[-1].u, records[-1].contacts[0].report()
    X, t = body.X, body.mesh.t
    x = X + u[body.xdofs]
    W, H = X[:, 0].max(), X[:, 1].max()
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    ax = axes[0]
    draw_mesh(ax, X, t, edgecolors="k", linewidths=0.6)
    for xi in np.linspace(0, W, 9):  # pressure p_y on the top
        ax.annotate("", (xi, H), (xi, H + 0.5), arrowprops=dict(arrowstyle="->", color="tab:green"))
    right = P["p_x_face"] == "right"  # traction p_x on a lateral side
    x0 = W if right else 0.0
    for yi in np.linspace(0, H, 8):
        tail = (x0, yi) if right else (x0 - 0.5, yi)
        ax.annotate("", (tail[0] + 0.5, yi), tail, arrowprops=dict(arrowstyle="->", color="tab:purple"))
    ax.text(W / 2, H + 0.6, f"p_y = {P['p_y']:g}", ha="center", color="tab:green")
    ax.text(
        W + 0.55 if right else -0.55,
        H / 2,
        f"p_x = {P['p_x']:g}",
        va="center",
        ha="left" if right else "right",
        color="tab:purple",
    )
    Xs = rep["X"]
    ax.plot(Xs[:, 0], Xs[:, 1], "o", ms=4, color="tab:orange", label=f"contact nodes ({len(Xs)})")
    fitted = " (FITTED to Table 1)" if preset in ("fast", "paper") else ""
    ax.set_title(
        f"system and discretisation: {P['nx']} x {P['ny']} quads, width {W:g},\n"
        f"height {H:g}, plane {P['plane']}{fitted}",
        fontsize=9,
    )
    ax.legend(loc="lower left", fontsize=8)
    ax = axes[1]
    draw_mesh(ax, X, t, edgecolors="0.8", linewidths=0.5)
    draw_mesh(ax, x, t, edgecolors="k", linewidths=0.6)
    for state, color in STATE_COLORS.items():
        sel = rep["state"] == state
        if sel.any():
            ax.plot(rep["x"][sel, 0], rep["x"][sel, 1], "o", ms=4, color=color, label=state)
    data = dict(
        law=law,
        X=X,
        x=x,
        max_displacement=float(np.linalg.norm(u[body.xdofs], axis=1).max()),
        contact=dict(X=Xs, x=rep["x"], state=[str(v) for v in rep["state"]]),
    )
    ax.set_title(
        f"deformed ({law} law), displacements at true scale (x1):\nmax |u| = "
        f"{data['max_displacement']:.2f}; grey: undeformed",
        fontsize=9,
    )
    ax.legend(loc="lower left", fontsize=8)
    for ax in axes:
        ax.axhline(0.0, color="k", lw=2.5)
        ax.fill_between([-1.5, W + 1.5], -0.4, 0.0, color="0.85", alpha=0.5, lw=0, zorder=0)
        ax.set_xlim(-1.5, W + 1.5)
        ax.set_ylim(-0.45, H + 1.0)
        ax.set_aspect("equal")
    fig.suptitle("Fig 6: elastic block on a rigid rough foundation, whole load in one step", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, Path(outdir or default_outdir(preset)) / "fig06_block_mesh_deformed.png", data, P)


STRESS_KEYS = ("total_normal", "total_tangential", "equilibrium_error", "n_slip", "n_stick", "n_open", "fitted")


def stress_data(r):
    """What Figs 7 and 8 draw of a block run: STRESS_KEYS and the contact side's x, t_N, t_T,
    slip bound and states."""
    return dict(
        {k: r.get(k) for k in STRESS_KEYS},
        contact={k: r["contact"][k] for k in ("x", "t_N", "t_T", "slip_bound", "state")},
    )


def draw_stresses(ax, r, label="", style="-", faint=False):
    """Pressure |t_N| and friction stress t_T along the contact side (reference x),
    the slip bound Y(|t_N|) dashed, each node marked by its state."""
    c = r["contact"]
    x, p, tT, Y = (np.asarray(c[k]) for k in ("x", "t_N", "t_T", "slip_bound"))
    p = -p
    state = np.asarray(c["state"])
    if faint:
        ax.plot(x, p, style, color="0.6", lw=1, label=f"|t_N| {label}")
        ax.plot(x, tT, style, color="0.6", lw=1, marker="x", ms=4, label=f"t_T {label}")
        return
    ax.plot(x, p, style, color="k", lw=1.3, marker="+", ms=7, label=f"|t_N| {label}")
    ax.plot(x, tT, style, color="tab:red", lw=1.3, label=f"t_T {label}")
    ax.plot(x, Y, "--", color="tab:red", lw=0.8, alpha=0.7, label=f"slip bound Y(|t_N|) {label}")
    for st, color in STATE_COLORS.items():
        sel = state == st
        if sel.any():
            ax.plot(x[sel], tT[sel], "o", color=color, ms=5, label=f"{st} ({sel.sum()})")


def _stress_axes(ax, title):
    ax.set_xlabel("x-coordinate (reference)")
    ax.set_ylabel("contact stress (force / length)")
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7, ncol=2)


@figure("fig07_block_conical_stresses", "Fig 7")
def fig07(preset="fast", outdir=None, r=None):
    """Fig 7 from a block result ``r`` with the conical law (default: the scene's run)."""
    plt = pyplot()
    r = r or result(preset, law="conical")
    P = r["parameters"]
    fig, ax = plt.subplots(figsize=(7.5, 5))
    draw_stresses(ax, r, "(conical)")
    _stress_axes(
        ax,
        "Fig 7: stresses on the contact area, conical slip surface "
        f"(n = 1, alpha + beta = {P['alpha'] + P['beta']:g})\n"
        f"sum |t_N| w = {-r['total_normal']:.6g}, sum t_T w = {r['total_tangential']:.6g}; "
        + slip_words(r)
        + _fitted_line(r),
    )
    return save_figure(
        fig, Path(outdir or default_outdir(preset)) / "fig07_block_conical_stresses.png", stress_data(r), P
    )


@figure("fig08_block_parabolic_stresses", "Fig 8")
def fig08(preset="fast", outdir=None, r=None, conical=None):
    """Fig 8 from block results with the parabolic law ``r`` and the conical one ``conical``
    (default: the scene's runs)."""
    plt = pyplot()
    r = r or result(preset, law="parabolic")
    rc = conical or result(preset, law="conical")
    fig, ax = plt.subplots(figsize=(7.5, 5))
    draw_stresses(ax, rc, "conical", style=":", faint=True)
    draw_stresses(ax, r, "(parabolic)")
    P = r["parameters"]
    _stress_axes(
        ax,
        "Fig 8: stresses on the contact area, parabolic slip surface "
        f"(n = {P['n']:g}, alpha = {P['alpha']:g}, beta = {P['beta']:g})\n"
        f"{slip_words(r)}; grey: the conical case (Fig 7)" + _fitted_line(r),
    )
    return save_figure(
        fig,
        Path(outdir or default_outdir(preset)) / "fig08_block_parabolic_stresses.png",
        dict(stress_data(r), conical=stress_data(rc)),
        P,
    )


def fig8_reading_data(preset="fast", other="fig8"):
    """What fig08b draws, for the block's ``preset`` and the reading of preset ``other``: per
    reading the measure of Fig 8's remark (scenes.block.fig8_remark: fig8_fraction,
    fig8_min_reduction, fig8_nodes), each law's n_slip and newton_residuals, and the stresses along
    the contact side; and the parameters of both runs."""
    data, params = {"fig8_drop": FIG8_DROP, "readings": {}}, {}
    for name in (preset, other):
        runs = {law: result(name, law=law) for law in ("conical", "parabolic")}
        c, p = runs["conical"]["contact"], runs["parabolic"]["contact"]
        frac, red, n_top = fig8_remark(c["t_N"], c["t_T"], p["t_T"])
        data["readings"][name] = dict(
            fig8_fraction=frac,
            fig8_min_reduction=red,
            fig8_nodes=n_top,
            **{law: dict(n_slip=r["n_slip"], newton_residuals=r["newton_residuals"]) for law, r in runs.items()},
            x=c["x"],
            t_N_conical=c["t_N"],
            t_T_conical=c["t_T"],
            t_T_parabolic=p["t_T"],
        )
        params[name] = {k: v for k, v in runs["conical"]["parameters"].items() if k != "law"}
    return data, params


def _reading_words(P):
    return (
        f"{P['width']:g} x {P['height']:g}, {P['nx']} x {P['ny']}, p_x on the {P['p_x_face']} side, "
        f"{P['free_end_nodes']} free end node{'s' if P['free_end_nodes'] > 1 else ''}, c_N = {P['c_N']:g} "
        f"{P['penalty'].replace('_', ' ')}, plane {P['plane']}"
    )


@figure("fig08b_block_fig8_readings", "Fig 8")
def fig08b(preset="fast", outdir=None, other="fig8"):
    """Fig 8 of the block's ``preset`` beside Fig 8 of preset ``other`` (the best-ranked reading of
    `contactfem reconstruct block` that shows the paper's remark); the nodes in the top quartile
    of the conical pressure, where the remark is measured, shaded. Writes NAME.json beside the
    PNG (plots.data)."""
    plt = pyplot()
    data, params = fig8_reading_data(preset, other)
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.8))
    for ax, (name, d) in zip(axes, data["readings"].items()):
        P = params[name]
        x, pN = np.asarray(d["x"]), np.abs(np.asarray(d["t_N_conical"]))
        tc, tp = np.abs(d["t_T_conical"]), np.abs(d["t_T_parabolic"])
        top = pN >= np.quantile(pN, 0.75)
        ax.plot(x, pN, "k+-", lw=1.1, ms=6, label="|t_N| (conical)")
        ax.plot(x, tc, ":", color="0.5", marker="x", ms=4, label="|t_T| conical")
        ax.plot(x, tp, "-", color="tab:red", marker="o", ms=3, label="|t_T| parabolic")
        for xi in x[top]:
            ax.axvspan(xi - 0.04, xi + 0.04, color="gold", alpha=0.35, lw=0)
        holds = d["fig8_fraction"] == 1.0
        ax.set_title(
            f"preset {name}: {_reading_words(P)}\nthe {d['fig8_nodes']} nodes of highest conical pressure "
            f"(shaded): parabolic |t_T| lower\nby at least {100 * data['fig8_drop']:g} % at "
            f"{round(d['fig8_fraction'] * d['fig8_nodes'])} of them, smallest reduction "
            f"{100 * d['fig8_min_reduction']:+.1f} %\nremark {'SHOWN' if holds else 'not shown'}; Newton: "
            f"conical {len(d['conical']['newton_residuals'])}, parabolic "
            f"{len(d['parabolic']['newton_residuals'])} residuals (Table 1: "
            f"{len(PAPER_TABLE1['conical'])}, {len(PAPER_TABLE1['parabolic'])}); nodes slipping: conical "
            f"{d['conical']['n_slip']}, parabolic {d['parabolic']['n_slip']}",
            fontsize=8,
        )
        ax.set_xlabel("x-coordinate (reference)")
        ax.set_ylabel("contact stress (force / length)")
        ax.set_ylim(0, None)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(
        "Fig 8's remark, 'a considerable reduction of the frictional stress in the region of higher "
        "normal pressure', on two readings of the values the scan lost\n(neither is the paper's: the preset "
        "FITTED to Table 1, preset fig8 the study's best-ranked reading that shows the remark)",
        fontsize=10,
    )
    fig.tight_layout()
    outdir = outdir or default_outdir(preset)
    return save_figure(fig, Path(outdir) / "fig08b_block_fig8_readings.png", data, params)


def _fitted_line(r):
    """The title's line naming the block's fitted reading (from the run's JSON), or ""."""
    words = fitted_words(r, "Table 1")
    return "\n" + words if words else ""


def slip_words(r):
    """How many contact nodes slip, stick and are open in a block run, in words."""
    n_slip = r["n_slip"]
    text = "no node reaches the slip bound" if n_slip == 0 else f"{n_slip} of {len(r['contact']['x'])} nodes slip"
    return text + f" ({r['n_stick']} stick, {r['n_open']} open)"


def residual_histories(preset="fast", results=None):
    """Our ||G|| per iteration for the paper's two laws, Coulomb mu = 0.3 and the
    Coulomb case with the tangent without the c_N^s coupling ('frozen'). ``results``:
    block results by law ("conical", ...) to take instead of the scene's runs."""
    given = results or {}
    pick = lambda law: given.get(law) or result(preset, law=law)  # noqa: E731
    out = {law: pick(law)["newton_residuals"] for law in ("conical", "parabolic", "coulomb")}
    out["coulomb, frozen tangent"] = result(preset, law="coulomb", tangent="frozen")["newton_residuals"]
    out["verdict"] = {key: describe_newton(hist, True) for key, hist in out.items()}
    try:
        out["coulomb, symmetric tangent"] = result(preset, law="coulomb", tangent="symmetric", maxit=12)[
            "newton_residuals"
        ]
        out["verdict"]["coulomb, symmetric tangent"] = describe_newton(out["coulomb, symmetric tangent"], True)
    except NewtonError as err:  # the residuals up to the first past DIVERGED: after it, they are rounding
        out["coulomb, symmetric tangent"] = list(err.history[: diverged_at(err.history)])
        out["verdict"]["coulomb, symmetric tangent"] = describe_newton(err.history, False)
    out["parameters"] = pick("conical")["parameters"]
    out["fitted"] = pick("conical").get("fitted") or {}
    return out


# Rounding moves a residual norm by a few units in the last place of the loads it balances: OpenBLAS's
# Prescott kernels move Table 1's parabolic residual 2.384512e-08 by 1.5e-14, 1e-16 of the first residual
# (172). Digits below RESIDUAL_DIGITS of the first residual, a hundred times that, are rounding's.
RESIDUAL_DIGITS = 1e-14


def residual_text(r, first):
    """A residual norm of a history whose first is ``first``, printed to the digits rounding leaves it (at most
    7): "2.3845e-08"; where fewer than two are left, its order only: "3e-12 (round-off)"."""
    decimals = math.floor(math.log10(r)) - math.floor(math.log10(RESIDUAL_DIGITS * first))
    return f"{r:.0e} (round-off)" if decimals < 1 else f"{r:.{min(6, decimals)}e}"


def table1_markdown(hist):
    """Table 1 as markdown: the paper's values beside ours (ours to the digits rounding leaves them: residual_text;
    linear solves = rows - 1)."""

    def cell(values, k, law=None):
        if k >= len(values):
            return ""
        text = f"{values[k]:.6e}" if law else residual_text(values[k], values[0])
        if law and k in PAPER_TABLE1_UNCERTAIN.get(law, ()):
            text += " (scan?)"
        return text

    n = max(len(PAPER_TABLE1["parabolic"]), len(hist["conical"]), len(hist["parabolic"]), len(hist["coulomb"]))
    P = hist["parameters"]
    lines = [
        "# Table 1: norm of the residual ||G|| per Newton iteration, whole load in one step",
        "",
        f"Block of Sec. 5.1: E = {P['E']:g}, nu = {P['nu']:g}, c_T = {P['c_T']:g} ({P['penalty']}) from the scan; "
        f"FITTED to this table (the scan lost them; `contactfem reconstruct block`): width {P['width']:g}, "
        f"height {P['height']:g}, {P['nx']} x {P['ny']} quads, p_x on the {P['p_x_face']} side, "
        f"{P['free_end_nodes']} free end nodes, c_N = {P['c_N']:g}, plane {P['plane']}. Iteration 1 is the "
        "initial state u = 0: its residual is the nodal load vector (top pressure and side traction; the "
        "contact forces at g_N0 = -1e-12 are ~1e-8); no uniform mesh reproduces the printed first value. "
        "(scan?): exponent garbled in the scan, value uncertain. Ours are printed to the digits rounding leaves "
        f"them, down to {RESIDUAL_DIGITS:.0e} of the first residual; below that, their order (round-off).",
        "",
        f"| iteration | paper conical | ours conical | paper parabolic | ours parabolic | ours Coulomb mu = "
        f"{P['mu']:g} |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for k in range(n):
        lines.append(
            f"| {k + 1} | {cell(PAPER_TABLE1['conical'], k, 'conical')} | {cell(hist['conical'], k)} | "
            f"{cell(PAPER_TABLE1['parabolic'], k, 'parabolic')} | {cell(hist['parabolic'], k)} | "
            f"{cell(hist['coulomb'], k)} |"
        )
    lines += [
        "",
        f"Linear solves: paper conical {len(PAPER_TABLE1['conical']) - 1}, "
        f"parabolic {len(PAPER_TABLE1['parabolic']) - 1}; ours conical "
        f"{len(hist['conical']) - 1}, parabolic {len(hist['parabolic']) - 1}, Coulomb {len(hist['coulomb']) - 1}; "
        f"Coulomb with the tangent without the c_N^s coupling (frozen): {len(hist['coulomb, frozen tangent']) - 1}; "
        f"with the symmetrised tangent: {hist['verdict']['coulomb, symmetric tangent']}; residuals "
        + ", ".join(f"{v:.2e}" for v in hist["coulomb, symmetric tangent"][:6])
        + ", ...",
        "",
    ]
    return "\n".join(lines)


@figure("table1_block_newton_residuals", "Table 1")
def table1(preset="fast", outdir=None, results=None):
    """Table 1 (.md and .png); ``results``: block results by law to use instead of the scene's
    runs (residual_histories)."""
    plt = pyplot()
    outdir = outdir or default_outdir(preset)
    hist = residual_histories(preset, results)
    md = Path(outdir) / "table1_block_newton_residuals.md"
    md.parent.mkdir(parents=True, exist_ok=True)
    md.write_text(table1_markdown(hist))
    fig, ax = plt.subplots(figsize=(7.5, 5))
    colors = {"conical": "tab:blue", "parabolic": "tab:red"}
    for law, color in colors.items():
        paper = np.array(PAPER_TABLE1[law])
        k = np.arange(1, len(paper) + 1)
        ok = np.array([i not in PAPER_TABLE1_UNCERTAIN[law] for i in range(len(paper))])
        ax.semilogy(k, paper, ":", color=color, lw=1)
        ax.semilogy(k[ok], paper[ok], "s", mfc="none", color=color, label=f"paper, {law}")
        if (~ok).any():
            ax.semilogy(
                k[~ok],
                paper[~ok],
                "s",
                mfc="none",
                color=color,
                alpha=0.4,
                label=f"paper, {law}: exponent uncertain (scan?)",
            )
        ours = hist[law]
        ax.semilogy(
            np.arange(1, len(ours) + 1),
            ours,
            "-o",
            color=color,
            label=f"ours{' (FITTED reading)' if hist['fitted'] else ''}, {law}",
        )
    for key, style in (("coulomb", "-^"), ("coulomb, frozen tangent", "--v")):
        ours = hist[key]
        ax.semilogy(
            np.arange(1, len(ours) + 1),
            ours,
            style,
            color="tab:green" if key == "coulomb" else "0.5",
            label=f"ours, {key} (mu = {hist['parameters']['mu']:g})",
        )
    ax.set_xlabel("iteration (1 = initial state)")
    ax.set_ylabel("||G||")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(
        "Table 1: residual norm per Newton iteration, whole load in one step"
        + _fitted_line(dict(fitted=hist["fitted"])),
        fontsize=9,
    )
    data = {k: v for k, v in hist.items() if k != "parameters"}
    return [str(md), *save_figure(fig, Path(outdir) / "table1_block_newton_residuals.png", data, hist["parameters"])]
