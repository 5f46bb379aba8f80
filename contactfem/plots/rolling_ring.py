"""Figure 9 of the paper, the rolling ring (Sec. 5.2), and a convergence study.

    fig09_rolling_ring               Fig 9: ring outlines at intervals along the plane, the
                                     computed and exact start of rolling, velocity profiles
                                     across the ring, and the centre velocity and spin vs time
    fig09b_rolling_ring_convergence  errors of x_roll and v_final against the rigid thin ring
                                     (a) refining mesh and step together (dt = 0.8 / n_el),
                                     (b) refining the step alone on the 120-element ring

fig09 draws a result it is given (``r=``: a lecture's own time loop) or runs the scene.
Exact: the rigid thin hoop (scenes.rings.rigid_ring_exact): x* = 229.4 cm,
v* = 150 cm/s, and x(2 s) = 376.5 cm.
"""

from pathlib import Path

import numpy as np

from ..scenes.rings import rigid_ring_exact
from . import cached_run, default_outdir, figure, pyplot
from .data import save_figure


def result(preset="fast", **overrides):
    """The scene's result dict (cached: see plots.cached_run)."""
    return cached_run("rolling_ring", preset, **overrides)


def joint_refinement(preset="fast"):
    """(n_el, dt) pairs refined together, dt = 0.8 / n_el (the paper: 120 elements, dt = 0.01)."""
    ns = (24, 40, 80) if preset == "fast" else (24, 40, 60, 80, 120, 160)
    return [(n, 0.8 / n) for n in ns]


def step_refinement(preset="fast"):
    """Time steps for the 120-element ring."""
    return (0.04, 0.02, 0.01) if preset == "fast" else (0.04, 0.02, 0.01, 0.005)


def convergence_study(preset="fast"):
    """Errors (relative to the thin hoop) of x_roll and v_final; returns a dict of arrays."""
    joint = [result(preset, n_el=n, dt=dt) for n, dt in joint_refinement(preset)]
    steps = [result(preset, n_el=120, dt=dt) for dt in step_refinement(preset)]

    def errs(runs):
        return (np.array([r["x_roll_rel_err"] for r in runs]), np.array([r["v_final_rel_err"] for r in runs]))

    xj, vj = errs(joint)
    xs, vs = errs(steps)
    return dict(
        n_el=np.array([n for n, _ in joint_refinement(preset)]),
        dt_joint=np.array([dt for _, dt in joint_refinement(preset)]),
        x_err_joint=xj,
        v_err_joint=vj,
        dt_step=np.array(step_refinement(preset)),
        x_err_step=xs,
        v_err_step=vs,
        iterations_joint=np.array([r["newton_iterations_total"] for r in joint]),
        iterations_step=np.array([r["newton_iterations_total"] for r in steps]),
    )


def slip_after_rolling(r):
    """The largest |slip velocity| of the contact point once rolling (0.1 s after t_roll), or
    None if the ring did not roll."""
    if not r["rolled"]:
        return None
    late = np.asarray(r["t"]) > r["t_roll"] + 0.1
    return float(np.max(np.abs(np.asarray(r["slip_velocity"])[late]), initial=0.0))


# what Fig 9 shows of a run: its headline numbers (the run's own keys) and the drawn series
FIG09_KEYS = (
    "kind",
    "rolled",
    "t_roll",
    "x_roll",
    "v_final",
    "omega_final",
    "x_end",
    "t_star_exact",
    "x_roll_exact",
    "v_final_exact",
    "x_end_exact",
    "exact_mu",
    "rolling_radius",
    "t",
    "x_c",
    "y_c",
    "vx_c",
    "omega",
    "slip_velocity",
    "vx_exact",
    "omega_exact",
    "outline_t",
    "outlines",
    "outline_vc",
    "outline_omega",
    "outline_node_y",
    "outline_node_vx",
)


def fig09_data(r):
    """The numbers Fig 9 draws from a rolling-ring result ``r``: FIG09_KEYS and
    ``slip_after_rolling`` (the summary's row reads the same)."""
    return dict({k: r.get(k) for k in FIG09_KEYS}, slip_after_rolling=slip_after_rolling(r))


def draw_rolling(r, title):
    """Outlines along the plane (top), velocity profiles (bottom left), histories (bottom right)."""
    plt = pyplot()
    fig = plt.figure(figsize=(12, 8.5))
    gs = fig.add_gridspec(2, 2, height_ratios=[1.0, 1.1])
    ax = fig.add_subplot(gs[0, :])
    ap = fig.add_subplot(gs[1, 0])
    ah = fig.add_subplot(gs[1, 1])

    outlines, times = np.asarray(r["outlines"]), np.asarray(r["outline_t"])
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(outlines)))
    for k, (P, t, c) in enumerate(zip(outlines, times, colors)):
        ax.plot(P[:, 0], P[:, 1], color=c, lw=1.0)
        ax.text(P[:, 0].mean(), P[:, 1].max() + (3 if k % 2 == 0 else 11), f"{t:g} s", ha="center", fontsize=7, color=c)
    # velocity profiles as arrows on the vertical diameter (the paper's Fig 9), every 0.5 s
    a, prm = r["rolling_radius"], r["parameters"]
    scale = 0.1  # cm of arrow per cm/s
    for P, t, c, vc, om in zip(outlines, times, colors, r["outline_vc"], r["outline_omega"]):
        if abs(t / 0.5 - round(t / 0.5)) > 1e-6:
            continue
        xc, yc = P[:, 0].mean(), 0.5 * (P[:, 1].max() + P[:, 1].min())
        hh = yc + a * np.linspace(-1, 1, 5)
        vx = vc[0] - om * (hh - yc)  # rigid-body profile v + omega e3 x r
        ax.quiver(
            np.full(5, xc), hh, scale * vx, np.zeros(5), angles="xy", scale_units="xy", scale=1, color=c, width=0.0025
        )
        ax.plot([xc, xc], [hh[0], hh[-1]], color=c, lw=0.6)
    t = np.asarray(r["t"])
    ax.plot(r["x_c"], r["y_c"], "k:", lw=0.8)
    x_lo, x_hi = outlines[:, :, 0].min() - 10, outlines[:, :, 0].max() + 10
    ax.fill_between([x_lo, x_hi], [-8, -8], [0, 0], color="0.85", hatch="///", edgecolor="0.6")
    ax.axhline(0.0, color="k", lw=1.0)
    if r["rolled"]:
        ax.plot([r["x_roll"]], [0], "r^", ms=10, label=f"rolling starts, computed x = {r['x_roll']:.1f} cm")
    closed = r.get("x_roll_exact") is not None  # None: a friction law without a closed form
    if closed:
        ax.plot(
            [r["x_roll_exact"]],
            [0],
            "kv",
            ms=10,
            mfc="none",
            label=f"exact (rigid thin ring) x* = {r['x_roll_exact']:.1f} cm",
        )
    ax.plot(
        [r["x_end"]],
        [r["y_c"][-1]],
        "r+",
        ms=10,
        label=f"centre at {t[-1]:g} s: {r['x_end']:.1f} cm" + (f" (exact {r['x_end_exact']:.1f})" if closed else ""),
    )
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(-8, outlines[:, :, 1].max() + 18)
    ax.set_aspect("equal")
    ax.set_xlabel("x [cm]")
    ax.set_ylabel("y [cm]")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=8, ncol=3)
    ax.set_title(
        title + f"\narrows: horizontal velocity on the vertical diameter ({1 / scale:g} cm/s per cm of arrow)",
        fontsize=10,
    )

    # velocity profiles: horizontal velocity of the contact nodes against their height
    pick = np.unique(np.searchsorted(times, [0.0, 0.5, r["t_roll"] or 1.0, times[-1]]).clip(0, len(times) - 1))
    for i in pick:
        c = colors[i]
        y, vx = np.asarray(r["outline_node_y"][i]), np.asarray(r["outline_node_vx"][i])
        ap.plot(vx, y, ".", color=c, ms=3)
        yc = np.mean(y)
        hh = np.linspace(yc - a, yc + a, 3)
        if r.get("exact_mu") is not None:  # the rigid ring's profile (Coulomb friction)
            ex = rigid_ring_exact(prm["v0"], r["exact_mu"], prm["g"], prm["R"], t=[times[i]])
            ap.plot(ex["v"][0] - ex["omega"][0] * (hh - yc), hh, "--", color=c, lw=1, label=f"t = {times[i]:.2f} s")
    ap.axvline(0.0, color="k", lw=0.6)
    ap.set_xlabel("horizontal velocity v_x [cm/s] (dots: nodes; dashed: rigid ring)")
    ap.set_ylabel("height y [cm]")
    ap.legend(fontsize=7)
    ap.grid(alpha=0.3)
    if r["rolled"]:
        s_late = slip_after_rolling(r)
        verdict = (
            f"once rolling, the contact point slips at most {s_late:.2g} cm/s ({100 * s_late / prm['v0']:.1g} % of v0)"
        )
    else:
        verdict = "the ring did not start rolling"
    ap.set_title("velocity profiles across the ring; " + verdict, fontsize=9)

    ah.plot(t, r["vx_c"], "C0", label="centre v_x")
    ah.plot(t, -np.asarray(r["omega"]) * a, "C1", label="-omega a (a = rolling radius)")
    ah.plot(t, r["slip_velocity"], "C2", lw=0.8, label="slip v_x + omega a")
    if r.get("vx_exact") is not None:
        ah.plot(t, r["vx_exact"], "k--", lw=1, label="exact (rigid thin ring)")
        ah.plot(t, -np.asarray(r["omega_exact"]) * prm["R"], "k--", lw=1)
        ah.axvline(r["t_star_exact"], color="k", lw=0.8, ls=":", label=f"t* = {r['t_star_exact']:.3f} s")
    if r["rolled"]:
        ah.axvline(r["t_roll"], color="r", lw=0.8, ls=":", label=f"t_roll = {r['t_roll']:.3f} s")
    ah.set_xlabel("t [s]")
    ah.set_ylabel("[cm/s]")
    ah.legend(fontsize=7)
    ah.grid(alpha=0.3)
    fig.tight_layout()
    return fig


@figure("fig09_rolling_ring", "Fig 9")
def fig09(preset="fast", outdir=None, r=None, **overrides):
    """Fig 9 from a rolling-ring result ``r`` (a lecture's own run), else from the scene's run
    with ``overrides``."""
    r = r or result(preset, **overrides)
    p, d = r["parameters"], fig09_data(r)
    title = (
        f"Fig 9: ring sliding then rolling ({d['kind']}, {p['n_el']} elements, dt = {p['dt']:g} s, "
        f"mu = {p['mu']:g}); v_final = {d['v_final']:.1f} cm/s (exact {d['v_final_exact']:.0f})"
    )
    stem = "fig09_rolling_ring" + (
        "" if not overrides else "_" + "_".join(f"{k}{v}" for k, v in sorted(overrides.items()))
    )
    fig = draw_rolling(dict(r, **d), title)
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", d, p)


@figure("fig09b_rolling_ring_convergence", "Fig 9 (convergence)")
def fig09b(preset="fast", outdir=None):
    c = convergence_study(preset)
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    n = c["n_el"]
    a1.loglog(n, np.abs(c["x_err_joint"]), "o-", label="|x_roll error|")
    a1.loglog(n, np.abs(c["v_err_joint"]), "s-", label="|v_final error|")
    a1.loglog(n, np.abs(c["v_err_joint"][0]) * (n / n[0]) ** -2.0, "k:", label="slope -2")
    a1.set_xticks(n, [str(k) for k in n])
    a1.xaxis.set_minor_formatter(plt.NullFormatter())
    a1.set_xlabel("elements around the ring, n_el (dt = 0.8 / n_el)")
    a1.set_ylabel("relative error vs rigid thin ring")
    a1.set_title("(a) mesh and step refined together", fontsize=10)
    a1.grid(alpha=0.3, which="both")
    a1.legend(fontsize=8)
    d = c["dt_step"]
    a2.loglog(d, np.abs(c["x_err_step"]), "o-", label="|x_roll error|")
    a2.loglog(d, np.abs(c["v_err_step"]), "s-", label="|v_final error|")
    a2.set_xticks(d, [f"{x:g}" for x in d])
    a2.xaxis.set_minor_formatter(plt.NullFormatter())
    a2.set_xlabel("time step dt [s] (120 elements)")
    a2.set_title("(b) step refined on the paper's 120-element ring", fontsize=10)
    a2.invert_xaxis()
    a2.grid(alpha=0.3, which="both")
    a2.legend(fontsize=8)
    fig.suptitle(
        "Rolling ring: error of the start of rolling x_roll and of the rolling speed v_final; at dt = "
        f"{d[0]:g} s on 120 elements |v_final error| = {abs(c['v_err_step'][0]):.3f}",
        fontsize=10,
    )
    fig.tight_layout()
    return save_figure(
        fig,
        Path(outdir or default_outdir(preset)) / "fig09b_rolling_ring_convergence.png",
        c,
        dict(
            result(preset)["parameters"],
            joint_n_el=c["n_el"],
            joint_dt=c["dt_joint"],
            step_n_el=120,
            step_dt=c["dt_step"],
        ),
    )
