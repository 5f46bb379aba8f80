"""Figures 10, 11a, 11b and Table 2 of the paper: the sloping impact of a ring (Sec. 5.3).

    fig10_sloping_impact_frictionless    Fig 10: ring outlines at intervals, frictionless
    fig11a_sloping_impact_frictional     Fig 11a: frictional contact, eq (10)
    fig11b_sloping_impact_viscoplastic   Fig 11b: frictional contact, viscoplastic ring
    table2_sloping_impact                Table 2: rebound velocity and angle, ours vs paper

Each figure draws the outer surface of the ring every `outline_every` steps (default 20,
i.e. every 2 time units) over the plane, the path of the centre, and below it the
energy histories (kinetic, strain, contact, their sum, and the frictional dissipation).
Each draws a result it is given (``r=``, ``results=``: a lecture's own time loop) or runs
the scene.
"""

from pathlib import Path

import numpy as np

from ..scenes.sloping_impact import PAPER_TABLE2
from ..problem.time_integration import newmark_of
from . import cached_run, default_outdir, figure, fitted_words, pyplot
from .data import save_figure, write_data
from .. import scenes

# what Figs 10-11b show of a run: the rebound (headline) and the drawn series
IMPACT_KEYS = (
    "variant",
    "rebound_vx",
    "rebound_vy",
    "rebound_angle_deg",
    "rebound_spin",
    "fitted",
    "t",
    "x_c",
    "y_c",
    "outline_t",
    "outlines",
    "energy_kinetic",
    "energy_strain",
    "energy_contact",
    "energy_dissipation",
    "energy_total",
)


def impact_data(r):
    """The numbers a sloping-impact figure draws from a result ``r`` (IMPACT_KEYS)."""
    return {k: r.get(k) for k in IMPACT_KEYS}


def _save(fig, r, outdir, preset, stem):
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", impact_data(r), r["parameters"])


def result(variant, preset="fast", **overrides):
    """The scene's result dict for one variant (cached: see plots.cached_run)."""
    return cached_run("sloping_impact", preset, variant=variant, **overrides)


def draw_impact(r, title):
    """Outlines over the plane (top) and energy histories (bottom); returns the figure."""
    plt = pyplot()
    r = impact_data(r)
    fig, (ax, ae) = plt.subplots(2, 1, figsize=(9, 7.5), gridspec_kw=dict(height_ratios=[1.6, 1]))
    outlines, times = np.asarray(r["outlines"]), np.asarray(r["outline_t"])
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(outlines)))
    for P, t, c in zip(outlines, times, colors):
        ax.plot(P[:, 0], P[:, 1], color=c, lw=1.2)
        ax.text(P[:, 0].mean(), P[:, 1].max() + 0.6, f"{t:g}", ha="center", fontsize=7, color=c)
    ax.plot(r["x_c"], r["y_c"], "k:", lw=0.8, label="centre of mass")
    x_lo, x_hi = outlines[:, :, 0].min() - 2, outlines[:, :, 0].max() + 2
    ax.fill_between([x_lo, x_hi], [-2, -2], [0, 0], color="0.8", hatch="///", edgecolor="0.5")
    ax.axhline(0.0, color="k", lw=1.0)
    ax.set_xlim(x_lo, x_hi)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fitted = fitted_words(r, "Table 2")
    ax.set_title(
        f"{title}\nrebound v = ({r['rebound_vx']:.2f}, {r['rebound_vy']:.2f}), "
        f"angle {r['rebound_angle_deg']:.1f} deg from the normal, spin {r['rebound_spin']:.3f}; "
        "labels: time" + (f"\n{fitted} (points per beam element)" if fitted else ""),
        fontsize=9,
    )
    ax.legend(loc="upper left", fontsize=8)
    t = np.asarray(r["t"])
    for key, label in (
        ("energy_kinetic", "kinetic"),
        ("energy_strain", "strain"),
        ("energy_contact", "contact"),
        ("energy_dissipation", "frictional dissipation"),
    ):
        ae.plot(t, r[key], label=label)
    ae.plot(t, r["energy_total"], "k", lw=2, label="kinetic + strain + contact")
    ae.set_xlabel("t")
    ae.set_ylabel("energy")
    ae.legend(fontsize=8, ncol=3)
    ae.grid(alpha=0.3)
    fig.tight_layout()
    return fig


@figure("fig10_sloping_impact_frictionless", "Fig 10")
def fig10(preset="fast", outdir=None, r=None):
    r = r or result("frictionless", preset)
    p = r["parameters"]
    newmark = "/".join(map(format, newmark_of(p)))
    fig = draw_impact(r, f"Fig 10: sloping impact, frictionless contact (Newmark {newmark}, dt = {p['dt']:g})")
    return _save(fig, r, outdir, preset, "fig10_sloping_impact_frictionless")


@figure("fig11a_sloping_impact_frictional", "Fig 11a")
def fig11a(preset="fast", outdir=None, r=None):
    r = r or result("frictional", preset)
    p = r["parameters"]
    fig = draw_impact(
        r,
        f"Fig 11a: sloping impact, frictional contact (eq 10: n = {p['n']:g}, alpha = {p['alpha']:g}, "
        f"beta = {p['beta']:g})",
    )
    return _save(fig, r, outdir, preset, "fig11a_sloping_impact_frictional")


@figure("fig11b_sloping_impact_viscoplastic", "Fig 11b")
def fig11b(preset="fast", outdir=None, r=None):
    r = r or result("viscoplastic", preset)
    eta = r["parameters"]["eta"]
    fig = draw_impact(
        r, f"Fig 11b: frictional contact, viscoplastic ring (N0 = 1, Q0 = 0.5, M0 = 0.25; eta = {eta:g} chosen)"
    )
    return _save(fig, r, outdir, preset, "fig11b_sloping_impact_viscoplastic")


def table2_rows(preset="fast", refined_n_el=32, results=None):
    """Rows of Table 2: per variant, ours (the paper's 16 elements; ``results``: variant ->
    a result to take instead of the scene's run), ours on a refined ring (refined_n_el
    elements) and the paper's values."""
    rows = []
    for variant in ("frictionless", "frictional", "viscoplastic"):
        r = (results or {}).get(variant) or result(variant, preset)
        f = result(variant, preset, n_el=refined_n_el)
        p = PAPER_TABLE2.get(variant)
        rows.append(
            dict(
                variant=variant,
                vx=r["rebound_vx"],
                vy=r["rebound_vy"],
                angle=r["rebound_angle_deg"],
                spin=r["rebound_spin"],
                n_el=r["parameters"]["n_el"],
                vx_ref=f["rebound_vx"],
                vy_ref=f["rebound_vy"],
                angle_ref=f["rebound_angle_deg"],
                n_el_ref=refined_n_el,
                paper_vx=p["vx"] if p else None,
                paper_vy=p["vy"] if p else None,
                paper_angle=p["angle_deg"] if p else None,
            )
        )
    return rows


def _fmt(x, f="{:.2f}"):
    return "-" if x is None else f.format(x)


def table2_cells(rows):
    """Table 2's header and rows of cells, formatted as the markdown and the image print them."""
    n_ref = rows[0]["n_el_ref"]
    head = [
        "contact",
        "ours v_x",
        "ours v_y",
        "ours angle",
        "ours spin",
        f"{n_ref} el. v_x",
        f"{n_ref} el. v_y",
        f"{n_ref} el. angle",
        "paper v_x",
        "paper v_y",
        "paper angle",
    ]
    body = [
        [
            r["variant"],
            _fmt(r["vx"]),
            _fmt(r["vy"]),
            _fmt(r["angle"], "{:.1f}"),
            _fmt(r["spin"], "{:.3f}"),
            _fmt(r["vx_ref"]),
            _fmt(r["vy_ref"]),
            _fmt(r["angle_ref"], "{:.1f}"),
            _fmt(r["paper_vx"]),
            _fmt(r["paper_vy"]),
            _fmt(r["paper_angle"], "{:.0f}"),
        ]
        for r in rows
    ]
    return head, body


def table2_markdown(preset="fast", refined_n_el=32, results=None):
    """figures/table2_sloping_impact.md: Table 2 from the runs (``table2_rows``; ``results``:
    variant -> result for the columns "ours")."""
    rows = table2_rows(preset, refined_n_el, results)
    given = results or {}
    ours = lambda v: given.get(v) or result(v, preset)  # noqa: E731
    head, body = table2_cells(rows)
    n_el = rows[0]["n_el"]
    P = ours("frictionless")["parameters"]
    lines = [
        "# Table 2: rebound of the ring after the sloping impact (Sec. 5.3)",
        "",
        f"Centre-of-mass velocity after rebound and angle of reflection from the normal, "
        f"atan(|v_x|/|v_y|) in degrees. 'ours': the paper's mesh ({n_el} beam elements), "
        f"Newmark {'/'.join(map(format, newmark_of(P)))}, dt = {P['dt']:g}, {P['n_steps']} steps; "
        f"'{refined_n_el} el.': the same on a refined ring. "
        "The paper gives no viscoplastic row (it reports a lower bounce). Spin: angular velocity "
        "about the centre of mass after rebound (counter-clockwise positive). Beam integration: "
        + "; ".join(
            f"{v} {ours(v).get('integration_points', 1)} point(s)"
            for v in ("frictionless", "frictional", "viscoplastic")
        )
        + (
            " (2 points FITTED to this table: `contactfem reconstruct sloping_impact`; the scan does not "
            "say; the viscoplastic ring keeps the midpoint rule)"
            if ours("frictionless").get("fitted")
            else ""
        )
        + ".",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    lines += ["| " + " | ".join(b) + " |" for b in body]
    return "\n".join(lines) + "\n"


@figure("table2_sloping_impact", "Table 2")
def table2(preset="fast", outdir=None, refined_n_el=32, results=None):
    """Table 2 (.md and .png); ``results``: variant -> result for the columns "ours"."""
    rows = table2_rows(preset, refined_n_el, results)
    given = results or {}
    ours = lambda v: given.get(v) or result(v, preset)  # noqa: E731
    n_el = rows[0]["n_el"]
    head, body = table2_cells(rows)
    out = outdir or default_outdir(preset)
    Path(out).mkdir(parents=True, exist_ok=True)
    md = Path(out) / "table2_sloping_impact.md"
    md.write_text(table2_markdown(preset, refined_n_el, results))

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(12, 1.9))
    ax.axis("off")
    tab = ax.table(cellText=body, colLabels=head, loc="center", cellLoc="center")
    tab.auto_set_font_size(False)
    tab.set_fontsize(8)
    tab.scale(1.0, 1.5)
    fitted = fitted_words(ours("frictionless"), "this table")
    ax.set_title(
        f"Table 2: rebound after the sloping impact, ours ({n_el} and {refined_n_el} elements) vs paper"
        + (f"\nours, frictionless and frictional rows: {fitted} (points per beam element)" if fitted else ""),
        fontsize=9,
    )
    return [
        str(md),
        *save_figure(
            fig,
            Path(out) / "table2_sloping_impact.png",
            dict(rows=rows, fitted=ours("frictionless").get("fitted")),
            ours("frictionless")["parameters"],
        ),
    ]


# The discretisation study of lecture 06: the one-point ring (integration = 1) of the paper's run,
# refined in the mesh, the step and the integrator, up to t = 20 (the paper's 200 steps of 0.1).
# About a minute; the table is kept in figures/ (`contactfem figures --only discretisation`) and
# tests/test_sloping_impact.py recomputes its 16-element rows (CONTACTFEM_SLOW=1: every row).
AVERAGE = dict(delta=0.5, beta_newmark=0.25)
DISCRETISATION = (
    ("16, 0.1, 0.7/0.4 (the paper's run)", dict(n_el=16, dt=0.1, n_steps=200), ("frictionless", "frictional")),
    ("16, 0.0125, 1/2 / 1/4", dict(n_el=16, dt=0.0125, n_steps=1600, **AVERAGE), ("frictionless", "frictional")),
    ("32, 0.025, 1/2 / 1/4", dict(n_el=32, dt=0.025, n_steps=800, **AVERAGE), ("frictionless", "frictional")),
    ("128, 0.0125, 0.7/0.4", dict(n_el=128, dt=0.0125, n_steps=1600), ("frictionless", "frictional")),
    ("128, 0.0125, 1/2 / 1/4", dict(n_el=128, dt=0.0125, n_steps=1600, **AVERAGE), ("frictionless", "frictional")),
    (
        "continuum ring 64 x 2, 0.025, 1/2 / 1/4",
        dict(kind="continuum", n_el=64, dt=0.025, n_steps=800, **AVERAGE),
        ("frictionless",),
    ),
)


def discretisation_rows(preset="fast", quick=False):
    """The rebound (v_x, v_y, angle, and the energy left, E_end / E_0) of each row of
    DISCRETISATION and variant; ``quick``: the 16-element rows only."""
    rows = []
    for label, over, variants in DISCRETISATION:
        if quick and over["n_el"] != 16:
            continue
        row = dict(label=label, overrides=over)
        for v in variants:
            kw = dict(over) if over.get("kind") == "continuum" else dict(over, integration="1")
            r = result(v, preset, **kw)
            E = np.asarray(r["energy_total"])
            row[v] = dict(
                vx=r["rebound_vx"], vy=r["rebound_vy"], angle=r["rebound_angle_deg"], energy_left=float(E[-1] / E[0])
            )
        rows.append(row)
    return rows


def discretisation_markdown(rows):
    """The study as a markdown table (what figures/table_sloping_impact_discretisation.md holds)."""

    def frictionless(row):
        r = row.get("frictionless")
        return ("", "") if r is None else (f"{r['vy']:.2f}, {r['angle']:.1f} deg", f"{r['energy_left']:.3f}")

    def frictional(row):
        r = row.get("frictional")
        return (
            ("", "")
            if r is None
            else (f"{r['vx']:.2f}, {r['vy']:.2f}, {r['angle']:.1f} deg", f"{r['energy_left']:.3f}")
        )

    lines = [
        "# The sloping impact against its discretisation (lecture 06)",
        "",
        "The one-point beam ring of the paper's run (integration = 1), frictionless and frictional, refined in "
        "the mesh (elements), the step (dt) and the integrator (Newmark delta / beta) up to t = 20. Rebound "
        "velocity of the centre of mass and the angle of reflection from the normal; E_end / E_0: the "
        "mechanical energy left at the end. Paper, Table 2: frictionless (2, 1.7), 50 deg; frictional "
        "(1.2, 1.7), 35 deg.",
        "",
        "| elements, dt, Newmark | frictionless v_y, angle | frictionless E_end / E_0 | frictional v_x, v_y, "
        "angle | frictional E_end / E_0 |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        lines.append("| " + " | ".join([row["label"], *frictionless(row), *frictional(row)]) + " |")
    return "\n".join(lines) + "\n"


@figure("table_sloping_impact_discretisation", "Table 2 (discretisation)")
def table_sloping_impact_discretisation(preset="fast", outdir=None, rows=None):
    """The discretisation study (.md, and .json with its numbers); ``rows``: discretisation_rows
    computed before (default: computed here, about a minute)."""
    rows = rows if rows is not None else discretisation_rows(preset)
    out = Path(outdir or default_outdir(preset))
    out.mkdir(parents=True, exist_ok=True)
    md = out / "table_sloping_impact_discretisation.md"
    md.write_text(discretisation_markdown(rows))
    base = scenes.get_scene("sloping_impact").resolve(preset, {"variant": "frictionless"})
    return [
        str(md),
        write_data(
            out / "table_sloping_impact_discretisation.json",
            dict(preset=preset, rows=rows),
            dict(base, rows=[row["overrides"] for row in rows]),
        ),
    ]
