"""The table of the paper's examples, ours beside the paper's: every "ours" cell is computed
here from the figures' data (the runs the figures use), never typed.

    summary     figures/summary.md: one row per example of the paper

``contactfem figures --preset paper`` writes it with the other figures; the README carries the
same table in its block ``summary`` (contactfem/lab/readme.py builds it from the committed JSON).

The "paper's value" column quotes the paper (NOTES.md); where the scan lost a digit it
says so. Which rows depend on which scene and preset: ``ROWS`` below (one function a row).

The rows read the figures' data (plots.data: what NAME.json holds beside NAME.png): a row
function takes ``record(stem)``, the data of the figure ``stem``: ``fresh(preset)`` computes it
from this code's runs as the figure does, ``committed(folder)`` reads the figures' JSON files.
"""

import json
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..scenes.block import PAPER_TABLE1
from . import cached_run, default_outdir, figure
from .data import ROUNDOFF, load
from .rounding import held, recorded

HEAD = ["| paper | what | paper's value | ours | figure |", "|---|---|---|---|---|"]


def floor(x):
    """A residual or an equilibrium error: its digits where they are the run's, "below 1e-09 (round-off)"
    where they are rounding's (plots.data.ROUNDOFF: 1e-14 of the loads; another kernel prints others)."""
    return f"below {ROUNDOFF:.0e} (round-off)" if abs(x) < ROUNDOFF else f"{x:.0e}"


def held_number(preset, stem, data, key, decimals):
    """``data[key]`` of figure ``stem`` printed to the digits it holds (plots.rounding.held): with ±
    the larger of its error band (``band``) and the rounding spread recorded for it, where that reaches
    the printed digit."""
    return held(data[key], recorded(stem, preset).get(key), decimals, band(data, key))


def band(data, key):
    """The error band of headline number ``key`` in a figure's data: the entry of its ``uncertainty``
    section (a number, or a dict with "band"); 0.0 where it has none."""
    entry = (data.get("uncertainty") or {}).get(key, 0.0)
    return float(entry.get("band", 0.0) if isinstance(entry, dict) else entry)


def _links(*pairs):
    """Links to figures, relative to summary.md's folder (the README adds "figures/")."""
    return " ".join(f"[{label}]({stem})" for label, stem in pairs)


def fresh(preset):
    """record(stem): the data of figure ``stem`` computed from this code's runs (the same
    functions the figures write their JSON with), with its ``parameters``."""
    from . import block, cork, funnel, rolling_ring, sloping_impact

    def with_parameters(data, r):
        return dict(data, parameters=r["parameters"])

    def blk(law):
        return cached_run("block", preset, law=law)

    def ring(scene, variant):
        return cached_run(scene, preset, variant=variant)

    def exit_rows():
        from .cork import EXIT_CASES_QUICK, cached_exit_case

        return dict(cases=[cached_exit_case(c) for c in EXIT_CASES_QUICK if c[4] is not None])

    makers = {
        "fig07_block_conical_stresses": lambda: with_parameters(block.stress_data(blk("conical")), blk("conical")),
        "fig08_block_parabolic_stresses": lambda: with_parameters(
            dict(block.stress_data(blk("parabolic")), conical=block.stress_data(blk("conical"))), blk("parabolic")
        ),
        "table1_block_newton_residuals": lambda: block.residual_histories(preset),
        "fig09_rolling_ring": lambda: with_parameters(
            rolling_ring.fig09_data(cached_run("rolling_ring", preset)), cached_run("rolling_ring", preset)
        ),
        "fig10_sloping_impact_frictionless": lambda: with_parameters(
            sloping_impact.impact_data(ring("sloping_impact", "frictionless")), ring("sloping_impact", "frictionless")
        ),
        "fig11a_sloping_impact_frictional": lambda: with_parameters(
            sloping_impact.impact_data(ring("sloping_impact", "frictional")), ring("sloping_impact", "frictional")
        ),
        "fig12_funnel_frictionless": lambda: with_parameters(
            funnel.funnel_data(ring("funnel", "frictionless")), ring("funnel", "frictionless")
        ),
        "fig13_funnel_frictional": lambda: with_parameters(
            funnel.funnel_data(ring("funnel", "frictional")), ring("funnel", "frictional")
        ),
        "fig14_cork_mesh": lambda: with_parameters(
            cork.cork_data(cached_run("cork", preset)), cached_run("cork", preset)
        ),
        "cork_exit_time": exit_rows,
    }
    return lru_cache(maxsize=None)(lambda stem: makers[stem]())


def committed(folder):
    """record(stem): the data of figure ``stem`` as written in ``folder``/stem.json."""

    @lru_cache(maxsize=None)
    def record(stem):
        return json.loads((Path(folder) / f"{stem}.json").read_text())

    return record


def row_laws(preset, record=None):
    return (
        "Figs 1-4",
        "interface laws, slip surface, return-mapping geometry",
        "-",
        "-",
        _links(
            ("1", "fig01_true_contact_area.png"),
            ("2", "fig02_force_vs_microdisplacement.png"),
            ("3", "fig03_shear_vs_normal.png"),
            ("4", "fig04_parabolic_slip_surface.png"),
        ),
    )


def row_block_equilibrium(preset, record=None):
    r = (record or fresh(preset))("fig07_block_conical_stresses")
    ours = (
        f"equilibrium error {floor(r['equilibrium_error'])}; {-r['total_normal']:.0f} down, "
        f"{r['total_tangential']:.0f} along"
    )
    what = "block on a rough foundation, whole load in one step"
    if r.get("fitted"):
        what += " (" + ", ".join(r["fitted"]) + " FITTED to Table 1)"
    return ("Sec. 5.1, Fig 6", what, "-", ours, _links(("6", "fig06_block_mesh_deformed.png")))


def fig8_remark(preset, record=None):
    """The paper's Fig 8 remark, measured: at the contact nodes in the top quartile of
    normal pressure (parabolic run), the parabolic |t_T| relative to the conical one."""
    par = (record or fresh(preset))("fig08_block_parabolic_stresses")
    con = par["conical"]
    p = -np.asarray(par["contact"]["t_N"])
    top = p >= np.quantile(p[p > 0], 0.75) if np.any(p > 0) else np.zeros_like(p, bool)
    tp, tc = (np.abs(np.asarray(r["contact"]["t_T"]))[top] for r in (par, con))
    change = (tp - tc) / np.where(tc > 0, tc, np.inf)
    return dict(
        n_top=int(top.sum()),
        change_min=float(change.min(initial=0.0)),
        change_max=float(change.max(initial=0.0)),
        n_slip_parabolic=par["n_slip"],
        n_slip_conical=con["n_slip"],
    )


def row_block_stresses(preset, record=None):
    f = fig8_remark(preset, record)
    ours = (
        f"at the {f['n_top']} nodes of highest pressure (top quartile) the parabolic friction stress "
        f"differs from the conical by {100 * f['change_min']:+.0f} % to {100 * f['change_max']:+.0f} %; "
        f"nodes slipping: conical {f['n_slip_conical']}, parabolic {f['n_slip_parabolic']}"
    )
    return (
        "Figs 7-8",
        "contact stresses, conical and parabolic slip surface",
        "parabolic lowers friction where pressure is high",
        ours,
        _links(("7", "fig07_block_conical_stresses.png"), ("8", "fig08_block_parabolic_stresses.png")),
    )


def row_table1(preset, record=None):
    record = record or fresh(preset)
    c, t = record("fig07_block_conical_stresses"), record("table1_block_newton_residuals")
    rc, rp = t["conical"], t["parabolic"]
    ours = f"conical {len(rc)} ({c['n_slip']} nodes slip), parabolic {len(rp)}; first {rc[0]:.2f}; " + (
        f"last {floor(rc[-1])} in both"
        if floor(rc[-1]) == floor(rp[-1])
        else f"last {floor(rc[-1])} and {floor(rp[-1])}"
    )
    return (
        "Table 1",
        "residual norms of Newton, one load step" + (" (reading FITTED to this table)" if c.get("fitted") else ""),
        f"conical {len(PAPER_TABLE1['conical'])} residuals, parabolic {len(PAPER_TABLE1['parabolic'])}; "
        f"first {PAPER_TABLE1['conical'][0]:.2f}",
        ours,
        _links(("table", "table1_block_newton_residuals.md")),
    )


def row_rolling_ring(preset, record=None):
    r = (record or fresh(preset))("fig09_rolling_ring")
    f = lambda key: held_number(preset, "fig09_rolling_ring", r, key, 1)  # noqa: E731
    x_roll = "did not roll" if not r["rolled"] else f"x_roll = {f('x_roll')} cm"
    ours = f"{x_roll}, x(2 s) = {f('x_end')} cm, v = {f('v_final')} cm/s"
    return (
        "Sec. 5.2, Fig 9",
        "ring sliding, then rolling (exact: rigid thin ring)",
        "rolling at x = 23x (229), later 382 (376), 149 (150) cm/s",
        ours,
        _links(("9", "fig09_rolling_ring.png"), ("conv.", "fig09b_rolling_ring_convergence.png")),
    )


def row_sloping_impact(preset, record=None):
    record = record or fresh(preset)
    parts = []
    for variant, stem in (
        ("frictionless", "fig10_sloping_impact_frictionless"),
        ("frictional", "fig11a_sloping_impact_frictional"),
    ):
        r = record(stem)
        f = lambda key, decimals: held_number(preset, stem, r, key, decimals)  # noqa: E731
        parts.append(f"{variant} ({f('rebound_vx', 2)}, {f('rebound_vy', 2)}), {f('rebound_angle_deg', 1)} deg")
    n_el = record("fig10_sloping_impact_frictionless")["parameters"]["n_el"]
    ours = "; ".join(parts) + f" ({n_el} elements)"
    fitted = record("fig10_sloping_impact_frictionless").get("fitted") or {}
    what = "sloping impact, rebound" + (
        f" (beam integration FITTED to this table: {fitted['integration']} points)" if "integration" in fitted else ""
    )
    return (
        "Sec. 5.3, Table 2",
        what,
        "frictionless (2, 1.7), 50 deg; frictional (1.2, 1.7), 35 deg",
        ours,
        _links(
            ("10", "fig10_sloping_impact_frictionless.png"),
            ("11a", "fig11a_sloping_impact_frictional.png"),
            ("11b", "fig11b_sloping_impact_viscoplastic.png"),
            ("table", "table2_sloping_impact.md"),
        ),
    )


def row_funnel(preset, record=None):
    record = record or fresh(preset)
    f, g = record("fig12_funnel_frictionless"), record("fig13_funnel_frictional")
    phi = f["parameters"]["phi_deg"]
    return (
        "Sec. 5.4, Figs 12-13",
        f"ring into a funnel (angle chosen: {phi:g} deg)",
        "frictionless rebounds, frictional sticks",
        f"{f['verdict']}; {g['verdict']}",
        _links(("12", "fig12_funnel_frictionless.png"), ("13", "fig13_funnel_frictional.png")),
    )


def cork_refined_exit(preset, record=None):
    """The cork's exit time with the time step in the neck refined (the pressure ramp kept), with
    and without the closing step: the refined cases of the exit-time study (plots.cork), as the
    study's data ``record("cork_exit_time")`` holds them."""
    from .cork import EXIT_CASES_QUICK

    cases = [c for c in EXIT_CASES_QUICK if c[4] is not None]
    rows = (record or fresh(preset))("cork_exit_time")["cases"]
    key = lambda g, label, fit, pop: (g, label, bool(fit), bool(pop))  # noqa: E731
    by_key = {key(r["group"], r["label"], r["closing_step_press_fit"], r["closing_step_pop"]): r for r in rows}
    return [by_key[key(c[0], c[1], *c[3])] for c in cases], cases[0][2]["dt"]


def row_cork(preset, record=None):
    record = record or fresh(preset)
    r = record("fig14_cork_mesh")
    f = lambda key, decimals: held_number(preset, "fig14_cork_mesh", r, key, decimals)  # noqa: E731
    exit_text = (
        f"exit {f('exit_time_ms', 2)} ms at {f('exit_velocity_m_s', 1)} m/s" if r["exited"] else "the cork stays in"
    )
    if r["exited"] and preset == "paper":
        fine, dt = cork_refined_exit(preset, record)
        t = [f["exit_time_ms"] for f in fine if f["exited"]]
        if len(t) == len(fine):
            rules = (
                "with or without the closing step"
                if f"{min(t):.2f}" == f"{max(t):.2f}"
                else f"{min(t):.2f}-{max(t):.2f} ms over the closing-step rules"
            )
            exit_text += f" ({t[0]:.2f} ms with the step in the neck refined to {dt:g} s, {rules})"
    ours = f"{r['press_fit_normal_force_N']:.0f} N"
    if r["press_fit_calibrated"]:
        ours += " (fitted: R_tip chosen to give ~2500 N)"
    ours += (
        f", {exit_text}; static breakaway {r['breakaway_pressure_static_MPa']:.3f} MPa against "
        f"{r['applied_pressure_MPa']:g} applied (margin {r['breakaway_margin_MPa']:+.3f} MPa)"
    )
    return (
        "Sec. 5.5, Figs 14-17",
        "champagne cork (dimensions reconstructed; the press fit is calibrated through R_tip)",
        "press fit ~2500 N, exit ~2.6-2.7 ms at ~28 m/s",
        ours,
        _links(
            ("14", "fig14_cork_mesh.png"),
            ("15", "fig15_cork_configurations.png"),
            ("16", "fig16_cork_pressure.png"),
            ("17", "fig17_cork_displacement.png"),
            ("knife edge", "cork_knife_edge.png"),
            ("exit time", "cork_exit_time.md"),
        ),
    )


# row function -> the scenes (and variants) it runs
ROWS = (
    (row_laws, ()),
    (row_block_equilibrium, ("block",)),
    (row_block_stresses, ("block",)),
    (row_table1, ("block",)),
    (row_rolling_ring, ("rolling_ring",)),
    (row_sloping_impact, ("sloping_impact",)),
    (row_funnel, ("funnel",)),
    (row_cork, ("cork",)),
)


def summary_table(preset="paper", record=None):
    """The table's lines (head and one row per example), every "ours" cell from the figures'
    data: ``record`` (default ``fresh(preset)``: this code's runs; ``committed(folder)``: the
    JSON files beside the figures)."""
    record = record or fresh(preset)
    lines = list(HEAD)
    for fn, _ in ROWS:
        cells = [str(c).replace("|", "/") for c in fn(preset, record)]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def summary_markdown(preset="paper", record=None):
    return "\n".join(
        [
            "# The paper's examples: ours beside the paper's",
            "",
            f"Written by `contactfem figures --preset {preset}` (contactfem/plots/summary.py): "
            "every value in the column 'ours' is computed by the run behind the figures.",
            "",
            *summary_table(preset, record),
            "",
        ]
    )


def table_lines(text):
    """The markdown table lines of summary.md."""
    return [ln.strip() for ln in text.splitlines() if ln.strip().startswith("|")]


@figure("summary", "README table")
def summary(preset="fast", outdir=None):
    path = Path(outdir or default_outdir(preset)) / "summary.md"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(summary_markdown(preset))
    return [str(path)]


def reprint(folder, todo):
    """The printed files that hold numbers to their recorded spread, redrawn from the data in ``folder``
    (no runs): the cork's exit-time and sensitivity tables and its knife edge among the figures ``todo``;
    for the committed figures, summary.md. Their paths. (The README's blocks: lab.readme.)"""
    from . import cork as F

    folder, done = Path(folder), []
    if "cork_exit_time" in todo:
        d = load(folder / "cork_exit_time.json")
        done += F.cork_exit_time("paper", str(folder), data={k: d[k] for k in ("preset", "slow", "cases")})
    if "cork_knife_edge" in todo:
        d = load(folder / "cork_knife_edge.json")
        done += F.cork_knife_edge("paper", str(folder), data={k: d[k] for k in ("field", "runs", "p0", "preset")})
    if "table_cork_sensitivity" in todo:
        path = folder / "table_cork_sensitivity.md"
        path.write_text(F.sensitivity_reprinted(load(folder / "table_cork_sensitivity.json")))
        done.append(path)
    repo = Path(__file__).resolve().parents[2]
    if folder.resolve() == (repo / "figures").resolve():
        (folder / "summary.md").write_text(summary_markdown("paper", committed(folder)))
        done.append(folder / "summary.md")
    return [str(p) for p in done]
