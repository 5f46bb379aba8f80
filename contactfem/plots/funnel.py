"""Figures 12 and 13 of the paper: the ring falling into a rigid funnel (Sec. 5.4).

    fig12_funnel_frictionless   Fig 12: (a) falling in, (b) rebound; outlines every 5 steps
    fig13_funnel_frictional     Fig 13: (a) falling in, (b) stuck in the funnel

The half ring of the computation is mirrored in the symmetry plane x = 0 to draw the
whole ring, and both walls of the funnel are drawn. Panel (a) holds the outlines up to
the deepest position of the centre, panel (b) those after it; panel (c) the height of
the centre against time. Panel (b) stops when the centre is back at its starting height.
Each draws a result it is given (``r=``: a lecture's own time loop) or runs the scene.
"""

from pathlib import Path

import numpy as np

from . import cached_run, default_outdir, figure, pyplot
from .data import save_figure

# what Figs 12-13 show of a run: the outcome (headline) and the drawn series
FUNNEL_KEYS = (
    "variant",
    "stuck",
    "v_c_final",
    "max_deformation",
    "y_c_start",
    "y_c_min",
    "t_y_c_min",
    "t",
    "y_c",
    "v_c",
    "outline_t",
    "outlines",
    "wall",
)


def funnel_data(r):
    """The numbers a funnel figure draws from a result ``r`` (FUNNEL_KEYS), and its verdict:
    "sticks" or "rebounds at 0.84 v0" (the summary's row reads the same)."""
    d = {k: r.get(k) for k in FUNNEL_KEYS}
    d["verdict"] = "sticks" if r["stuck"] else f"rebounds at {r['v_c_final'] / r['parameters']['v0']:.2f} v0"
    return d


def result(variant, preset="fast", **overrides):
    """The scene's result dict for one variant (cached: see plots.cached_run)."""
    return cached_run("funnel", preset, variant=variant, **overrides)


def draw_funnel(r, title):
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(13, 5.2), gridspec_kw=dict(width_ratios=[1, 1, 1.1]))
    wall = np.asarray(r["wall"])
    both = np.vstack([wall, wall[::-1] * [-1, 1]])  # left wall, vertex, mirrored right wall
    outlines, times = np.asarray(r["outlines"]), np.asarray(r["outline_t"])
    top = wall[:, 1].max()
    t_low = r["t_y_c_min"]
    # panel (b) ends when the centre is back at its starting height (a rebound) or at the end
    t, y_c = np.asarray(r["t"]), np.asarray(r["y_c"])
    back = np.flatnonzero((t > t_low) & (y_c >= r["y_c_start"]))
    t_end = t[back[0]] if back.size else t[-1]
    for ax, part, label in (
        (axes[0], times <= t_low + 1e-9, "(a) falling in"),
        (axes[1], (times >= t_low - 1e-9) & (times <= t_end + 1e-9), "(b) after the deepest point"),
    ):
        sel = np.flatnonzero(part & (outlines[:, :, 1].min(axis=1) < top))
        colors = plt.cm.viridis(np.linspace(0, 0.9, max(len(sel), 1)))
        for c, k in zip(colors, sel):
            P = outlines[k]
            ax.plot(P[:, 0], P[:, 1], color=c, lw=1.0)
        ax.plot(both[:, 0], both[:, 1], "k", lw=2)
        ax.axvline(0.0, color="0.6", ls="--", lw=0.8)
        ax.set_aspect("equal")
        ax.set_ylim(-1, top + 2)
        ax.set_xlim(-0.6 * top, 0.6 * top)
        ax.set_title(f"{label}\n{len(sel)} outlines, every {r['parameters']['outline_every']} steps", fontsize=9)
    ac = axes[2]
    ac.plot(r["t"], r["y_c"], "k", label="centre height y_c")
    ac.set_xlabel("t")
    ac.set_ylabel("y_c")
    ac2 = ac.twinx()
    ac2.plot(r["t"], r["v_c"], color="tab:red", lw=0.8, label="v_c")
    ac2.set_ylabel("v_c", color="tab:red")
    ac.set_title(f"{funnel_data(r)['verdict']}; max deformation {r['max_deformation']:.2f} R", fontsize=9)
    ac.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


@figure("fig12_funnel_frictionless", "Fig 12")
def fig12(preset="fast", outdir=None, r=None):
    r = r or result("frictionless", preset)
    fig = draw_funnel(
        r,
        f"Fig 12: ring falling into a funnel, frictionless (funnel wall at "
        f"{r['parameters']['phi_deg']:g} deg from the vertical: chosen)",
    )
    return save_figure(
        fig, Path(outdir or default_outdir(preset)) / "fig12_funnel_frictionless.png", funnel_data(r), r["parameters"]
    )


@figure("fig13_funnel_frictional", "Fig 13")
def fig13(preset="fast", outdir=None, r=None):
    r = r or result("frictional", preset)
    p = r["parameters"]
    fig = draw_funnel(
        r,
        f"Fig 13: ring falling into a funnel, frictional eq (10): n = {p['n']:g}, "
        f"alpha = {p['alpha']:g}, beta = {p['beta']:g} (wall at {p['phi_deg']:g} deg: chosen)",
    )
    return save_figure(fig, Path(outdir or default_outdir(preset)) / "fig13_funnel_frictional.png", funnel_data(r), p)
