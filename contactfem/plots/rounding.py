"""What rounding does to the figures' numbers: measured, recorded beside them, and held.

``contactfem figures --rounding`` draws every figure again (paper preset) under each of
``CONDITIONS``, each in a process of its own, and records in each committed ``NAME.json`` a
``rounding`` section: the conditions, the code they ran, and ``spread``, every number that
moved past plots.data.RTOL under any of them, keyed by its place in the data (the paths
plots.data.differences names, a series of numbers as ``NAME[]``):

    {"lo": a, "hi": b}          a number: the least and the largest of the committed value and
                                the conditions' (a count at a tolerance's edge: its range)
    {"width": w}                a series: the largest spread of any of its entries
    {"len": [lo, hi]}           a list whose length moved (a run stopped at another step): its
                                entries are not compared
    {"texts": [...]}            a text whose numbers moved: compared by its words
    {"values": [...]}           a flag or a value without digits that moved: any of these

The printed files that hold numbers to these spreads are then redrawn from the committed data (summary.reprint).
plots.data.differences then holds a fresh run within twice each recorded spread (RTOL elsewhere;
argued at plots.data.MARGIN), ``spread(stem, key)`` gives the spread of one headline number (the error bands
take max(band, spread)), and the study's runs are kept per condition in
$CONTACTFEM_CACHE/rounding/CODE/CONDITION/, so that an interrupted study goes on where it
stopped. The bench's figures draw the bench's file (bench.json): they run nothing.
"""

import json
import math
import re
import os
import subprocess
import sys
from pathlib import Path

from . import cache_dir, default_outdir, load_all
from .data import MARGIN, ROUNDOFF, RTOL, code_version, dumps, is_number, load, source_hash

# the conditions: name -> (environment, what it changes). Two OpenBLAS kernels other than the one the
# project's machines pick (Haswell's, on an AMD EPYC): each takes other instructions, so other summation
# orders, in every BLAS call; SuperLU in place of the band or dense LU (another factorisation and
# pivoting); the initial state moved by 1e-13 of itself, a few hundred units in the last place: what a
# different order of summation in building it leaves
CONDITIONS = {
    "kernel Prescott": ({"OPENBLAS_CORETYPE": "Prescott"}, "OpenBLAS's Prescott kernels (SSE3)"),
    "kernel Sandybridge": ({"OPENBLAS_CORETYPE": "Sandybridge"}, "OpenBLAS's Sandybridge kernels (AVX, no FMA)"),
    "factorisation": ({"CONTACTFEM_LINEAR_ALGEBRA": "sparse"}, "SuperLU for every system (--linear-algebra sparse)"),
    "perturbation": ({"CONTACTFEM_PERTURB": "1e-13"}, "the initial state perturbed by 1e-13 (--perturb 1e-13)"),
}


def stems():
    """The figures the study reruns: every figure of this package that runs the library and writes its data
    (not the summary, which reads the others' data; not those the lab registers: the bench's draw bench.json,
    the inverse study's table is a study of readings, not of the paper's runs)."""
    here = __name__.rsplit(".", 1)[0]
    return sorted(s for s, (_, fn) in load_all().items() if fn.__module__.startswith(here + ".") and s != "summary")


def work_dir(condition):
    """Where the study keeps the figures drawn under ``condition`` for this code."""
    return cache_dir().parent / "rounding" / source_hash() / condition.replace(" ", "-")


def draw(stem, condition, base, log=print):
    """Draw figure ``stem`` under ``condition`` in a process of its own (kept: a second call for
    the same code reads it); the path of its JSON, or None if it failed (its log says why)."""
    out = work_dir(condition)
    path = out / f"{stem}.json"
    if path.exists():
        return path
    out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, **CONDITIONS[condition][0], MPLBACKEND="Agg")
    env.pop("CONTACTFEM_FIGURES", None)
    env["CONTACTFEM_SLOW"] = "1" if base.get("slow") else ""  # as the committed data was made
    cmd = [sys.executable, "-m", "contactfem", "figures", "--preset", "paper", "--only", stem, "--outdir", str(out)]
    with open(out / f"{stem}.log", "w") as f:
        done = subprocess.run(cmd, env=env, stdout=f, stderr=subprocess.STDOUT).returncode == 0
    log(f"{condition}: {stem} {'done' if done else 'failed: ' + str(out / (stem + '.log'))}")
    return path if done and path.exists() else None


# -- the spread of a figure's numbers over samples ----------------------------------------------
def _moved(values, scale=0.0):
    """Whether numbers differ beyond plots.data's rule (RTOL, both below ROUNDOFF agree)."""
    lo, hi = min(values), max(values)
    if max(abs(lo), abs(hi)) < ROUNDOFF:
        return False
    return hi - lo > RTOL * max(abs(lo), abs(hi), scale)


def _spread(samples, where, out):
    first = samples[0]
    if all(isinstance(s, dict) for s in samples):
        for k in first:
            if k in ("code_version", "rounding") and not where:
                continue
            if all(k in s for s in samples):
                _spread([s[k] for s in samples], f"{where}.{k}" if where else k, out)
    elif all(isinstance(s, list) for s in samples):
        lengths = [len(s) for s in samples]
        if min(lengths) != max(lengths):
            out[where] = {"len": [min(lengths), max(lengths)]}
        elif first and all(is_number(x) for s in samples for x in s):
            scale = max(abs(float(x)) for s in samples for x in s)
            widths = [max(col) - min(col) for col in zip(*samples) if _moved(col, scale)]
            if widths:
                out[f"{where}[]"] = {"width": max(widths)}
        else:
            for i in range(len(first)):
                _spread([s[i] for s in samples], f"{where}[{i}]", out)
    elif all(is_number(s) for s in samples):
        if _moved(samples):
            out[where] = {"lo": min(samples), "hi": max(samples)}
    elif all(isinstance(s, str) for s in samples):
        if len(set(samples)) > 1:
            out[where] = {"texts": sorted(set(samples))}
    elif any(s != first for s in samples):
        out[where] = {"values": list({json.dumps(s): s for s in samples}.values())}


def spread_of(samples):
    """{path: spread} of the numbers that differ among ``samples`` (figure records: the committed
    one first), in the forms the module docstring lists."""
    out = {}
    _spread(list(samples), "", out)
    return out


def record(stem, folder, conditions):
    """Write ``folder``/stem.json's ``rounding`` section from the conditions' data (the committed
    numbers themselves are left as they are); returns the spread."""
    path = Path(folder) / f"{stem}.json"
    base = load(path)
    drawn = {c: load(p) for c, p in conditions.items() if p is not None}
    spread = spread_of([base, *drawn.values()])
    base["rounding"] = dict(
        code_version=code_version(),
        conditions={c: CONDITIONS[c][1] + ("" if c in drawn else ": failed") for c in conditions},
        spread=spread,
    )
    path.write_text(dumps(base))
    return spread


def study(folder=None, only=None, log=print):
    """The rounding study of the paper preset's figures in ``folder`` (default: figures/): each
    figure under each condition, then its ``rounding`` section. Returns {stem: spread}."""
    folder = Path(folder or default_outdir("paper"))
    todo = [s for s in stems() if (not only or only in s)]
    missing = [s for s in todo if not (folder / f"{s}.json").exists()]
    if missing:
        raise ValueError(
            f"--rounding measures the figures in {folder}, which lacks {', '.join(missing)}: "
            "draw them first (contactfem figures --preset paper)"
        )
    out = {}
    for stem in todo:
        base = load(folder / f"{stem}.json")
        out[stem] = record(stem, folder, {c: draw(stem, c, base, log) for c in CONDITIONS})
        log(f"{stem}: {len(out[stem])} number(s) moved under rounding")
    (folder / "rounding.md").write_text(markdown(folder))
    return out


# -- reading the recorded spread ----------------------------------------------------------------
def spread(stem, key, folder=None):
    """The recorded rounding spread (hi - lo, or a series' width) of figure ``stem``'s number at ``key``
    (a path as plots.data.differences names it: "v_final", "runs[1].v", a series "x_err"), in the
    committed figures (or ``folder``'s); 0.0 where none is recorded (rounding moved it by less than
    plots.data.RTOL), None where the study recorded no number there (a length, a text)."""
    entries = recorded(stem, folder=folder)
    entry = entries.get(key) or entries.get(f"{key}[]")
    if entry is None:
        return 0.0
    if "width" in entry:
        return entry["width"]
    return entry["hi"] - entry["lo"] if "hi" in entry else None


def recorded(stem, preset="paper", folder=None):
    """The spread the study recorded for figure ``stem`` in the committed figures (or ``folder``'s):
    NAME.json's rounding section; {} for another preset than the paper's (the study measures it) or
    where none is recorded."""
    path = Path(folder or Path(__file__).resolve().parents[2] / "figures") / f"{stem}.json"
    if preset != "paper" or not path.exists():
        return {}
    return (load(path).get("rounding") or {}).get("spread", {})


def held(value, entry, decimals, band=0.0):
    """``value`` printed with ``decimals`` decimals where rounding leaves that many digits (``entry``:
    its recorded spread, {} or None where none is recorded), else with the spread it has, rounded up to
    the printed digit: "29.7 ± 0.1". ``band``: an error band of the value (the discretisation's): the
    ± is the larger of the two, printed where it reaches the printed digit. A count (decimals 0) that
    rounding moves, without a band, prints as its range: "839-840"."""
    text = f"{value:.{decimals}f}"
    lo, hi = (min(entry["lo"], value), max(entry["hi"], value)) if entry and "lo" in entry else (value, value)
    unit = 10.0**-decimals
    if f"{lo:.{decimals}f}" == f"{hi:.{decimals}f}" and band < unit / 2:
        return text
    if decimals == 0 and not band and all(float(v).is_integer() for v in (lo, hi, value)):
        return f"{lo:.0f}-{hi:.0f}"
    return f"{text} ± {math.ceil(max(hi - lo, band) / unit - 1e-9) * unit:.{decimals}f}"


def extreme(data, side, spread=None):
    """A copy of figure record ``data`` with every number its spread records at ``side`` ("lo" or "hi")
    of its range: what a run under another rounding could have written (the printed tables must
    say the same of it)."""
    out = json.loads(json.dumps(data))
    for key, entry in (spread if spread is not None else (data.get("rounding") or {}).get("spread", {})).items():
        if side in entry:
            *path, last = _parts(key)
            _at(out, path)[last] = entry[side]
    return out


# -- the table of what rounding moves (figures/rounding.md, the README) ---------------------------
# where a figure's numbers are printed, and how: (figure, a pattern of the path) -> words; the first
# that matches
PRINTED = {
    ("cork_exit_time", r".*newton_failures"): "not printed",
    ("cork_exit_time", r".*steps"): "cork_exit_time.md: its range",
    ("cork_exit_time", r"cases\["): "cork_exit_time.md: with ± its spread",
    ("cork_exit_time", r"summary\."): "cork_exit_time.md, its figure's title: with ± its spread",
    ("cork_knife_edge", r"runs\[\d+\]\.v$"): "the knife edge's labels: with ± its spread",
    ("cork_knife_edge", r"p0\["): "plotted against p0, not printed",
    ("table_cork_sensitivity", r".*exit_velocity_m_s"): "table_cork_sensitivity.md: with ± its spread",
    ("table_cork_sensitivity", r".*outcome"): "not printed (the table prints the velocity held)",
    ("fig09b_rolling_ring_convergence", r""): "plotted, not printed",
    ("verif_bar_impact", r"error_"): "its figure's title, in percent to 2 and 1 decimals (the spread: 1e-8 %)",
    ("verif_bar_impact", r"contact_stress"): "plotted, not printed",
    ("verif_hertz_pressure", r"error_a"): "its figure's title, in percent to 2 decimals (the spread: 1e-8 %)",
    ("table1_block_newton_residuals", r"coulomb, symmetric tangent"): (
        "table1_block_newton_residuals.md: 'diverges (past 1e+15 in N solves)', the residuals before it"
    ),
    ("table1_block_newton_residuals", r"verdict\."): "table1_block_newton_residuals.md: the verdict",
}
TABLE_HEAD = ["| figure | number | committed | under rounding | printed | tested |", "|---|---|---|---|---|---|"]


def _parts(key):
    """The steps of a spread's path: "runs[2].v" -> ["runs", 2, "v"] (a series' "[]" dropped)."""
    return [int(p[1:-1]) if p.startswith("[") else p for p in re.findall(r"[^.\[\]]+|\[\d+\]", key)]


def _at(data, key):
    """The committed value at a path of the spread ("runs[2].v", "x[]"; or its steps), or None."""
    node = data
    for part in _parts(key) if isinstance(key, str) else key:
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            return None
    return node


def _which(data, key):
    """Words naming the entry of a list a path goes through ("mu = 0.098, closing step off, off"), or ""."""
    node, words = data, []
    for part in _parts(key):
        node = node[part] if isinstance(node, (dict, list)) else None
        if isinstance(part, int) and isinstance(node, dict):
            words += [str(node[k]) for k in ("label", "case") if k in node]
            if "closing_step_press_fit" in node:
                words.append(
                    "closing step "
                    + ", ".join(("off", "on")[node[k]] for k in ("closing_step_press_fit", "closing_step_pop"))
                )
            words += [f"n_ramp = {node['overrides']['n_ramp']}"] if "n_ramp" in node.get("overrides", {}) else []
            words += [f"mu = {node['mu']:g}, R_tip = {node['R_tip']:g}"] if {"mu", "R_tip"} <= set(node) else []
    return ", ".join(words)


def _describe(entry, value):
    """(committed, under rounding, tested) in words, for one entry of a spread."""
    if "lo" in entry:
        w = entry["hi"] - entry["lo"]
        return (
            f"{value:.6g}",
            f"{entry['lo']:.6g} to {entry['hi']:.6g} (spread {w:.2g})",
            f"within {MARGIN:g} x {w:.2g}",
        )
    if "width" in entry:
        return (
            "a series",
            f"its entries move by up to {entry['width']:.2g}",
            f"each within {MARGIN:g} x {entry['width']:.2g}",
        )
    if "len" in entry:
        lo, hi = entry["len"]
        n = len(value) if isinstance(value, list) else "-"
        return f"{n} entries", f"{lo} to {hi} entries", "its length within the range widened by its width"
    if "texts" in entry:
        return f"{value}", " / ".join(entry["texts"]), "by its words (its numbers move)"
    return f"{value}", " / ".join(json.dumps(v) for v in entry["values"]), "any of these"


def table_lines(folder=None):
    """The table's lines: every number of the committed figures that rounding moves past plots.data.RTOL,
    with how it is printed (PRINTED) and tested."""
    folder = Path(folder or default_outdir("paper"))
    lines = list(TABLE_HEAD)
    for stem in stems():
        path = folder / f"{stem}.json"
        data = load(path) if path.exists() else {}
        for key, entry in (data.get("rounding") or {}).get("spread", {}).items():
            committed, moved, tested = _describe(entry, _at(data, key))
            printed = next(
                (text for (s, pattern), text in PRINTED.items() if s == stem and re.match(pattern, key)), "-"
            )
            which = _which(data, key)
            cells = [stem, f"`{key}`" + (f" ({which})" if which else ""), committed, moved, printed, tested]
            lines.append("| " + " | ".join(c.replace("|", "\\|").replace("\n", " ") for c in cells) + " |")
        if unmeasured(data):
            moved = f"not measured under {', '.join(unmeasured(data))}"
            lines.append(
                f"| {stem} | every number | - | {moved} | as the others measured | within twice what they moved |"
            )
    return lines


def unmeasured(data):
    """The conditions a figure record's rounding section lacks or names as failed (all, where it has none)."""
    drawn = (data.get("rounding") or {}).get("conditions", {})
    return [c for c in CONDITIONS if c not in drawn or drawn[c].endswith(": failed")]


def markdown(folder=None):
    """figures/rounding.md: the table, under a title and what it was measured with."""
    conditions = "; ".join(f"{c}: {text}" for c, (_, text) in CONDITIONS.items())
    return "\n".join(
        [
            "# What rounding does to the published numbers",
            "",
            "Written by `contactfem figures --preset paper --rounding` (contactfem/plots/rounding.py) from the "
            f"figures' rounding sections. Conditions: {conditions}. Every number that moved past 1e-8 of itself.",
            "",
            *table_lines(folder),
            "",
        ]
    )
