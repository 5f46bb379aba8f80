"""The README's numbers, from the data the runs left in the repository.

Every number the README states from a run sits in a block between ``<!-- NAME:start -->`` and
``<!-- NAME:end -->``, and ``BLOCKS[NAME](repo)`` builds what the block holds from the committed data:
the JSON beside the figures (figures/NAME.json), the benchmarks' bench.json, the code's own tables.
The prose around the blocks is written by hand.

    readme(repo)            the README with every block filled
    first_difference(repo)  the name of the first block the README holds otherwise, or None
    write(repo)             README.md rewritten with its blocks filled; whether it changed

``contactfem readme`` writes it, ``contactfem readme --check`` names the first block that differs.
"""

import inspect
import json
import re
import textwrap
from pathlib import Path

from .. import environment, lazy
from ..laws.check import DEFAULT_RANGE, check_friction_law, check_law, check_normal_law
from ..plots import rounding, summary
from ..scenes.block import PAPER_TABLE1
from ..scenes.sloping_impact import PAPER_TABLE2
from . import reconstruct as rc
from .bench.coverage import readme_lines
from .bench.error_bars import error_bars_sentence
from .bench.report import adaptive_sentences

# the course's register: lazy, so that the students' edition (which leaves the course out) imports this module
course_checks = lazy.module("contactfem.lab.course.checks")

MARK = re.compile(r"<!-- ([\w-]+):start -->(.*?)<!-- \1:end -->", re.DOTALL)
WIDTH = 110


def paragraph(text, indent=""):
    """One paragraph wrapped at WIDTH; lines after the first indented by ``indent``."""
    return textwrap.fill(
        " ".join(text.split()),
        WIDTH,
        subsequent_indent=indent,
        break_long_words=False,
        break_on_hyphens=False,
    )


def prose(texts):
    """Paragraphs and lists: each text wrapped; a text that starts with "- " is a list item, and the items
    of one list follow each other without a blank line."""
    out = []
    for t in texts:
        item = t.startswith("- ")
        if out and not (item and out[-1].startswith("- ")):
            out.append("")
        out.append(paragraph(t, "  " if item else ""))
    return "\n".join(out)


def lines(*texts):
    """A block of whole lines: the texts one a line, between the markers' own lines."""
    return "\n" + "\n".join(texts) + "\n"


def _json(repo, name):
    return json.loads((Path(repo) / name).read_text())


# -- the blocks ------------------------------------------------------------------------------------


def resume_example_block(repo):
    """The example of a run resumed from a saved record: examples/resume.py, which a test runs."""
    return lines("```python", (Path(repo) / "examples" / "resume.py").read_text().rstrip("\n"), "```")


def summary_block(repo):
    """The table of the paper's examples, ours beside the paper's, from the figures' JSON."""
    rows = summary.summary_table("paper", summary.committed(Path(repo) / "figures"))
    return lines(*(row.replace("](", "](figures/") for row in rows))


def rounding_block(repo):
    """The table of the numbers rounding moves, from the figures' rounding sections."""
    return lines(*rounding.table_lines(Path(repo) / "figures"))


def coverage_block(repo):
    """The coverage study's account and what the error bars cost, from bench.json."""
    bench = _json(repo, "bench.json")
    return lines(prose(readme_lines(bench["coverage"]) + [error_bars_sentence(bench["error_bars"])]))


def adaptive_block(repo):
    """The adaptive study's lines, one a scene, from bench.json."""
    return lines(prose(adaptive_sentences(_json(repo, "bench.json")["adaptive"])))


def tangents_block(repo):
    """Newton's iterations on the block with each tangent the paper compares, from bench.json."""
    blk = _json(repo, "bench.json")["tangents"]["block"]

    def needs(variant):
        if not all(blk[law][variant]["converged"] for law in ("coulomb", "parabolic")):
            return "diverges once nodes slip"
        return f"needs {blk['coulomb'][variant]['iterations']} and {blk['parabolic'][variant]['iterations']}"

    return lines(
        paragraph(
            f"The consistent non-symmetric tangent {needs('consistent')} (Coulomb and parabolic); dropping the "
            f"coupling term of eq (50) {needs('frozen')}; the symmetrised tangent {needs('symmetric')}; the two-step "
            f"normal-then-friction algorithm {needs('staggered')}."
        )
    )


def banded_block(repo):
    """How much faster the banded LU solves than SuperLU, over the banded cases of the cost study."""
    cases = _json(repo, "bench.json")["cost"]["cases"].values()
    ratios = [r["solve_splu_MMD_AT_PLUS_A_s"] / r["solve_banded_s"] for r in cases if r.get("solve_banded_s")]
    return f"{min(ratios):.1f} to {max(ratios):.1f} times"


def example_length_block(repo):
    """The length of the scene file the README shows."""
    return f"{len((Path(repo) / 'lectures' / 'examples' / 'disc_wall.py').read_text().splitlines())} lines"


def hertz_block(repo):
    """Hertz's peak pressure on the finest mesh of the verification figure, against the closed form."""
    d = _json(repo, "figures/verif_hertz_pressure.json")
    return f"p0 within {100 * abs(d['error_p0']):.2f} % on {d['n_quads']:,} quads"


def environment_block(repo):
    """The environment variables contactfem reads, from their one table (contactfem.environment)."""
    return lines(environment.table())


def law_range_block(repo):
    """check_law's default range."""
    r = DEFAULT_RANGE
    qv = f"q and v up to {r['q']:g}" if r["q"] == r["v"] else f"q up to {r['q']:g}, v up to {r['v']:g}"
    return f"p up to {r['p']:g}, {qv}, g up to {r['g']:g}"


def check_law_block(repo):
    """check_law's keywords as its docstring gives them, each with the laws whose check takes it."""
    entries = re.findall(r"^    ``(\w+)``\s+(.*?)(?=^    ``|^\s*$)", check_law.__doc__, re.M | re.S)
    takes = {
        k: inspect.signature(f).parameters for k, f in (("friction", check_friction_law), ("normal", check_normal_law))
    }
    rows = ["| keyword | law | meaning (default) |", "|---|---|---|"]
    for name, text in entries:
        laws = [k for k, params in takes.items() if name in params]
        text = " ".join(text.split()).removeprefix(f"{laws[0]}: ")
        rows.append(
            f"| `{name}` | {'both' if len(laws) == 2 else laws[0]} | {text.replace('``', '`').replace('|', '&#124;')} |"
        )
    return lines(*rows)


def exercises_block(repo):
    """The course's graded exercises, from the checks' register."""
    implements = sum(e.implements for e in course_checks.EXERCISES.values())
    return f"{len(course_checks.EXERCISES)} in all, {implements} of which implement part of the method"


def refined_angle_block(repo):
    """The frictionless rebound angle of the sloping impact's finest discretisation, from its study's JSON."""
    rows = _json(repo, "figures/table_sloping_impact_discretisation.json")["rows"]
    finest = next(r for r in rows if r["label"] == "128, 0.0125, 1/2 / 1/4")
    return f"{finest['frictionless']['angle']:.1f} deg"


def cork_refined_block(repo):
    """Where the cork's refined exit (both closing-step rules) lies against the paper's window."""
    s = _json(repo, "figures/cork_exit_time.json")["summary"]
    lo, hi = s["paper_window_ms"]
    first, last = sorted(s["refined_ms"].values())
    where = "within"
    if first > hi or last < lo:
        where = "just past" if first > hi else "just before"
    elif first < lo or last > hi:
        where = "across"
    shown = sorted({f"{t:.2f}" for t in (first, last)})
    return f"{where} the paper's window ({' and '.join(shown)} ms)"


# -- the inverse study of the scan's lost values (figures/table_reconstruct.json) ------------------------


def _findings(repo, scene):
    return _json(repo, "figures/table_reconstruct.json")[scene]


def _sci(x):
    """1e+06 as 1e6, 25 as 25."""
    return f"{x:g}".replace("e+0", "e").replace("e+", "e")


def _reading(r):
    """A block reading in words: geometry, mesh, the side load, the free end nodes, c_N, the plane."""
    pulls = (r["p_x_face"] == "right") == (r["p_x"] > 0)
    ends = f"{r['free_end_nodes']} free end node" + ("s" if r["free_end_nodes"] != 1 else "")
    return (
        f"{r['width']:g} x {r['height']:g}, {r['nx']} x {r['ny']}, {'pulled' if pulls else 'pushed'} from the "
        f"{r['p_x_face']} side, {ends}, c_N = {_sci(r['c_N'])} {r['penalty'].replace('_', ' ')}, plane {r['plane']}"
    )


def _key(r, keys):
    return tuple(r[k] for k in keys)


def penetration_block(repo):
    """How deep the block's study lets a reading sink into its rigid foundation."""
    return f"{100 * rc.PENETRATION_FRACTION:g} %"


def block_push(f):
    best, pull = f["best"], f["pulled"]
    pushes = [(r["p_x_face"] == "right") != (r["p_x"] > 0) for r in f["tied"]]
    if not pushes[0]:
        return "- **The fit pulls, as the paper says.** The best reading pulls the block with p_x."
    text = (
        '- **The fit pushes where the paper pulls.** The paper\'s block is "pulled" by p_x; in the fitted reading '
        f"the traction acts along {'+' if best['p_x'] > 0 else '-'}x on the {best['p_x_face']} side, so it pushes. "
    )
    text += (
        "Every reading that meets as many of Table 1's facts does the same; "
        if all(pushes)
        else "Not every reading that meets as many of Table 1's facts does the same; "
    )
    if pull is None:
        return text + "no admissible reading pulls. The fitted reading contradicts the paper's text on this point."
    return text + (
        f"the best reading that pulls ranks {pull['rank']} with {pull['n_facts']} of {f['facts']} facts (its parabolic "
        f"case takes {pull['n_parabolic']} residuals, not {len(PAPER_TABLE1['parabolic'])}). The fitted reading "
        "contradicts the paper's text on this point."
    )


def block_first_residual(f):
    inf = float("inf")
    g, free = rc.block_geometries()[0], rc.block_geometries(block_aspect=inf, element_aspect=inf)[0]
    block_aspect, element_aspect = rc.block_geometries.__defaults__[-2:]
    return (
        "- **First residual**: at u = 0 it is the norm of the nodal load vector, a closed form of the width, height "
        "and mesh. No uniform mesh with round dimensions reproduces the printed 0.1713709e3: among the study's "
        f"geometries (blocks, width and height within a factor {block_aspect:g} of each other, meshed with elements "
        f"whose sides are within a factor {element_aspect:g}) the closest on its grid of step 0.25 is "
        f"{g['first_residual']:.3f} ({g['width']:g} x {g['height']:g}, {g['nx']} x {g['ny']}); without those filters "
        f"a {free['width']:g} x {free['height']:g} strip ({free['nx']} x {free['ny']}) gives "
        f"{free['first_residual']:.3f}, and on a grid of step 0.1, filtered or not, none comes within 3e-6. Out of "
        f"reach, so the study keeps the readings within 1 %; ours is {f['preset']['first_residual']:.2f}."
    )


def block_residual_pattern(f, repo):
    t = _json(repo, "figures/table1_block_newton_residuals.json")
    c07 = _json(repo, "figures/fig07_block_conical_stresses.json")
    con, par = t["conical"], t["parabolic"]
    paper_con, paper_par = PAPER_TABLE1["conical"], PAPER_TABLE1["parabolic"]
    last = "then one at rounding, below 1e-11" if con[-1] < 1e-11 else f"then {con[-1]:.1e}"
    ratio = [p / o for p, o in zip(paper_par[1:6], par[1:6])]
    mine, best, n = f["preset"], f["best"], f["outcomes"]
    tied, fig8 = f["tied"], {_key(r, rc.BLOCK_KEYS) for r in f["fig8"]}
    same = all(
        _key(r, ("nx", "ny", "width", "height", "p_x_face", "plane"))
        == (mine["nx"], mine["ny"], mine["width"], mine["height"], "left", "stress")
        for r in tied
    )
    fig8_tied = sum(_key(r, rc.BLOCK_KEYS) in fig8 for r in tied)
    ends = f"{best['free_end_nodes']} end node" + ("s" if best["free_end_nodes"] != 1 else "")
    return (
        "- **Residual pattern**: the preset gives conical "
        + ", ".join(f"{x:.2f}" for x in con[:-1])
        + f", {last} (paper "
        + ", ".join(f"{x:.2f}" for x in paper_con[:-1])
        + f", {paper_con[-1]:.1e}), {c07['n_slip']} nodes slip; parabolic {len(par)} residuals (paper "
        f"{len(paper_par)}), its 2nd to 5th residuals {min(ratio[:4]):.1f} to {max(ratio[:4]):.1f} times smaller than "
        f"the paper's and the 6th {ratio[4]:.0f} times smaller. The study runs {f['readings']} readings: "
        f"{f['admissible']} admissible readings are ranked ({n['no_equilibrium']} have no static equilibrium under one "
        f"of the laws, {n['rejected_penetration']} sink deeper than {100 * f['penetration_fraction']:g} % of the "
        f"height). Of them {len(tied)} meet {best['n_facts']} of the {f['facts']} facts (first residual within 1 %, "
        f"{len(paper_con)} conical and {len(paper_par)} parabolic residuals, conical slip; "
        + ("none meets Fig 8's remark)" if not fig8_tied else f"{fig8_tied} meet Fig 8's remark)")
        + (", all with this geometry, the load on the left side and plane stress" if same else "")
        + f"; ours ranks {mine['rank']} by the residual distance ({mine['distance']:.2f} against "
        f"{best['distance']:.2f} for the first, which keeps {ends} free and reads c_N, c_T "
        f"{best['penalty'].replace('_', ' ')}: the same fit within the distance's resolution). The conical slip is "
        f"marginal ({c07['n_slip']} of {len(c07['contact']['x'])} nodes): the fit is a reading that agrees with "
        "Table 1, not evidence for it. The other reading (4 x 3.5, 20 x 10, right side, plane strain, preset "
        "`canonical`) has no slip."
    )


def block_fig8(f, repo):
    shows, mine = f["fig8"], f["preset"]
    if not shows:
        return "- **Fig 8's remark**: none of the admissible readings shows it."
    one = shows[0]
    con = "no node slips" if not one["n_slip_conical"] else f"{one['n_slip_conical']} nodes slip"
    text = (
        "- **Fig 8's remark** (\"a considerable reduction of the frictional stress in the region of higher normal "
        'pressure"), measured as the study measures it (at every node in the top quartile of the conical pressure '
        f"the parabolic |t_T| at least 5 % lower): {len(shows)} of the {f['admissible']} admissible readings "
        f"show{'s' if len(shows) == 1 else ''} it, the one ranked {one['rank']} ({_reading(one)}: preset `fig8`). "
        f"It meets {one['n_facts']} of the {f['facts']} facts: its conical case takes {one['n_conical']} residuals "
        f"and {con}. "
    )
    if f["fig8_with_table1_conical"]:
        text += f"{f['fig8_with_table1_conical']} of them meet Table 1's conical facts (4 residuals, nodes slipping)."
    else:
        text += (
            "No reading that meets Table 1's conical facts (4 residuals, nodes slipping) shows the remark: with the "
            "conical slip that Table 1 needs, the highest pressure sits at the far corner where the nodes stick "
            "under both laws, so the parabolic law cannot lower the friction there."
        )
    text += (
        " The parabolic law lowers the friction at the slipping nodes (lecture 04). Fig 8 of both readings, side "
        "by side:"
    )
    d = _json(repo, "figures/fig08b_block_fig8_readings.json")["readings"]
    rows = []
    for name, r, links in (
        ("paper", mine, "[8](figures/fig08_block_parabolic_stresses.png) [8b](figures/fig08b_block_fig8_readings.png)"),
        ("fig8", one, "[8b](figures/fig08b_block_fig8_readings.png)"),
    ):
        x = d[name]
        rows.append(
            f"  | preset `{name}` | {r['rank']} | {r['n_facts']} of {f['facts']} | "
            f"{round(x['fig8_fraction'] * x['fig8_nodes'])} of {x['fig8_nodes']} | "
            f"{100 * x['fig8_min_reduction']:+.1f} % "
            f"| {links} |"
        )
    head = [
        (
            "  | reading | rank | facts | nodes of highest pressure with the friction 5 % lower | smallest reduction "
            "| figure |"
        ),
        "  |---|---|---|---|---|---|",
    ]
    return paragraph(text, "  ") + "\n\n" + "\n".join(head + rows)


def block_study_block(repo):
    """The block's study: what the fit is, its first residual, its residuals and Fig 8's remark."""
    f = _findings(repo, "block")
    items = [block_push(f), block_first_residual(f), block_residual_pattern(f, repo)]
    return lines("\n".join(paragraph(t, "  ") for t in items) + "\n" + block_fig8(f, repo))


def _velocities(r, variant):
    return f"{abs(r[variant + '_vx']):.2f}, {abs(r[variant + '_vy']):.2f}, {r[variant + '_angle']:.1f} deg"


def _sloping_label(r):
    """How a sloping-impact reading differs from the preset's, in words."""
    paper = rc.SLOPING_PAPER_READING
    words = ["two-point" if r["integration"] == "2" else "one-point"]
    if r["rotary_inertia"] != paper["rotary_inertia"]:
        words.append("with rotary inertia" if r["rotary_inertia"] else "without rotary inertia")
    if r["contact_at"] != paper["contact_at"]:
        words.append(f"contact at the {r['contact_at']}")
    if r["penalty"] != paper["penalty"]:
        words.append(f"penalty {r['penalty'].replace('_', ' ')}")
    if r["c_N"] != paper["c_N"]:
        words.append(f"c_N = {r['c_N']:g} (against the legible {paper['c_N']:g})")
    if r["gap0"] != paper["gap0"]:
        words.append(f"start gap {r['gap0']:g}")
    return ", ".join(words)


def sloping_table_block(repo):
    """Table 2 against the study's readings: the paper's, the preset's, the midpoint's and the closest."""
    f = _findings(repo, "sloping_impact")
    n = len(f["scored"])

    def paper(variant):
        p = PAPER_TABLE2[variant]
        return f"{p['vx']:g}, {p['vy']:g}, {p['angle_deg']:g} deg"

    rows = [
        ("paper", f"{paper('frictionless')} | {paper('frictional')} | "),
        ("two-point beam (preset `paper`, FITTED)", f["preset"]),
        ("midpoint beam (preset `midpoint`, one-point integration)", f["midpoint"]),
        (f"closest of all: {_sloping_label(f['best'])}", f["best"]),
    ]
    out = [
        "| reading | frictionless v_x, v_y, angle | frictional v_x, v_y, angle | scored numbers within 10 % |",
        "|---|---|---|---|",
    ]
    for label, r in rows:
        if isinstance(r, str):
            out.append(f"| {label} | {r}|")
        else:
            out.append(
                f"| {label} | {_velocities(r, 'frictionless')} | {_velocities(r, 'frictional')} | "
                f"{r['n_facts']} of {n} |"
            )
    return lines(*out)


def sloping_reach_block(repo):
    """How far the study's readings come, and how far its unknowns move the scored numbers."""
    f = _findings(repo, "sloping_impact")
    pre, mid = f["preset"], f["midpoint"]
    rule = [abs(pre[k]) - abs(mid[k]) for k in f["scored"]]
    reach = (
        "**Out of reach**: no reading that keeps the paper's mass and integrator brings any of the three within "
        "10 % of the paper's."
        if f["best_n_facts"] == 0
        else f"The closest reading brings {f['best_n_facts']} of the three within 10 % of the paper's."
    )
    fitted = (
        " The two-point ring is FITTED because every two-point reading comes closer than every one-point reading "
        "(the study's distance), not because it reproduces a number."
        if f["two_point_first"]
        else ""
    )
    return lines(
        paragraph(
            f"{reach} The angles lie within 5 deg of the printed ones, but they add no evidence: the frictionless "
            "angle is v_y under a looser tolerance, and the frictional one agrees because v_x and v_y are both too "
            "low by a similar factor. Within each beam rule, rotary inertia, contact at the axis, the penalty's unit "
            f"and the start gap move the three numbers by at most {f['minor_spread']:.2f}; the beam rule (preset "
            f"`paper` against `midpoint`) moves the frictionless v_y by {rule[0]:.2f} and the frictional v_x, v_y by "
            f"{rule[1]:.2f} and {rule[2]:.2f}; c_N = {f['c_N_range'][0]:g} ... {f['c_N_range'][1]:g} moves them by "
            f"at most {f['c_N_spread']:.2f}.{fitted}"
        )
    )


def sloping_mass_block(repo):
    """The preset with the consistent mass and with the energy-consistent stepper, against the text."""
    f = _findings(repo, "sloping_impact")
    pre, cm, ec, both = f["preset"], f["consistent_mass"], f["energy_consistent"], f["both"]
    n = len(f["scored"])

    def d(r, k):
        return abs(r[k]) - abs(pre[k])

    return lines(
        paragraph(
            "**Mass and time integration: the energy the ring keeps.** The study runs the preset, the midpoint "
            "reading and the closest reading also with the consistent mass (`mass_matrix=consistent`) and with the "
            "energy-consistent stepper (`contact_integration=energy_consistent`): against the text, so shown and not "
            "ranked (`--json` lists them with their outcome). For the preset the consistent mass changes the "
            f"frictionless v_y by {d(cm, 'frictionless_vy'):+.2f}, the frictional v_x, v_y by "
            f"{d(cm, 'frictional_vx'):+.2f} and {d(cm, 'frictional_vy'):+.2f}. The energy-consistent stepper keeps the "
            f"energy the damped Newmark removes (the frictionless ring ends with {ec['frictionless_energy_final']:.2f} "
            f"E0 against {pre['frictionless_energy_final']:.2f} E0 at t = {f['steps'] * 0.1:g}, where the study stops; "
            "Newmark's damping goes on while the ring flies and vibrates, so the scene's run to t = 20 ends lower) and "
            f"moves the frictionless v_y by {d(ec, 'frictionless_vy'):+.2f} to {ec['frictionless_vy']:.2f} "
            f"({ec['frictionless_angle']:.1f} deg), the frictional v_x by {d(ec, 'frictional_vx'):+.2f} to "
            f"{ec['frictional_vx']:.2f} and its v_y by {d(ec, 'frictional_vy'):+.2f} to {ec['frictional_vy']:.2f} "
            f"({ec['frictional_angle']:.1f} deg), {ec['n_facts']} of {n} scored numbers within 10 %. Both together: "
            f"{both['frictionless_vy']:.2f}; {both['frictional_vx']:.2f} and {both['frictional_vy']:.2f} "
            f"({both['n_facts']} of {n})."
        )
    )


BLOCKS = {
    "resume-example": resume_example_block,
    "environment": environment_block,
    "summary": summary_block,
    "rounding": rounding_block,
    "coverage": coverage_block,
    "adaptive": adaptive_block,
    "tangents": tangents_block,
    "banded": banded_block,
    "law-range": law_range_block,
    "hertz": hertz_block,
    "example-length": example_length_block,
    "check-law": check_law_block,
    "exercises": exercises_block,
    "refined-angle": refined_angle_block,
    "cork-refined": cork_refined_block,
    "penetration": penetration_block,
    "block-study": block_study_block,
    "sloping-table": sloping_table_block,
    "sloping-reach": sloping_reach_block,
    "sloping-mass": sloping_mass_block,
}


def checkout():
    """The checkout this package lives in (the folder of its README.md)."""
    repo = Path(__file__).resolve().parents[2]
    if not (repo / "README.md").is_file():
        raise ValueError(f"{repo} has no README.md: contactfem readme works in a checkout of the repository")
    return repo


# -- filling them ----------------------------------------------------------------------------------


def blocks(text):
    """The README's blocks in order: (name, what it holds)."""
    return [(m.group(1), m.group(2)) for m in MARK.finditer(text)]


def _check_names(text):
    names = [name for name, _ in blocks(text)]
    unknown = sorted(set(names) - set(BLOCKS))
    if unknown:
        raise ValueError(f"README.md has blocks no function builds: {', '.join(unknown)}")
    missing = [name for name in BLOCKS if names.count(name) != 1]
    if missing:
        raise ValueError(f"README.md must hold each block once: {', '.join(missing)}")


def filled(text, repo):
    """``text`` with every block between its markers replaced by what ``BLOCKS`` builds."""
    _check_names(text)
    built = {name: fn(repo) for name, fn in BLOCKS.items()}
    return MARK.sub(lambda m: f"<!-- {m.group(1)}:start -->{built[m.group(1)]}<!-- {m.group(1)}:end -->", text)


def readme(repo):
    """The README of ``repo`` with every block filled from the repository's data."""
    return filled((Path(repo) / "README.md").read_text(), repo)


def first_difference(repo, text=None):
    """The name of the first block that ``text`` (default: the README) holds otherwise than the data
    give it, or None when every block is what its function builds."""
    text = (Path(repo) / "README.md").read_text() if text is None else text
    _check_names(text)
    for name, held in blocks(text):
        if held != BLOCKS[name](repo):
            return name
    return None


def write(repo):
    """README.md with its blocks filled, written in place; whether it changed."""
    path = Path(repo) / "README.md"
    old = path.read_text()
    new = filled(old, repo)
    if new != old:
        path.write_text(new)
    return new != old
