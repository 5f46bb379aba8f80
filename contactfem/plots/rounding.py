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

plots.data.differences then holds a fresh run within twice each recorded spread (RTOL elsewhere;
argued at plots.data.MARGIN), ``spread(stem, key)`` gives the spread of one headline number (the error bands
take max(band, spread)), and the study's runs are kept per condition in
$CONTACTFEM_CACHE/rounding/CODE/CONDITION/, so that an interrupted study goes on where it
stopped. The bench's figures draw the bench's file (bench.json): they run nothing.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

from . import cache_dir, default_outdir, load_all
from .data import ROUNDOFF, RTOL, code_version, dumps, is_number, load, source_hash

# the conditions: name -> (environment, what it changes). Three OpenBLAS kernels (each picks other
# instructions, so other summation orders, in every BLAS call), SuperLU in place of the band or
# dense LU (another factorisation and pivoting), and the initial state moved by 1e-13 of itself,
# a few hundred units in the last place: what a different order of summation in building it leaves
CONDITIONS = {
    "kernel Haswell": ({"OPENBLAS_CORETYPE": "Haswell"}, "OpenBLAS's Haswell kernels"),
    "kernel Prescott": ({"OPENBLAS_CORETYPE": "Prescott"}, "OpenBLAS's Prescott kernels (SSE3)"),
    "kernel Sandybridge": ({"OPENBLAS_CORETYPE": "Sandybridge"}, "OpenBLAS's Sandybridge kernels (AVX, no FMA)"),
    "factorisation": ({"CONTACTFEM_LINEAR_ALGEBRA": "sparse"}, "SuperLU for every system (--linear-algebra sparse)"),
    "perturbation": ({"CONTACTFEM_PERTURB": "1e-13"}, "the initial state perturbed by 1e-13 (--perturb 1e-13)"),
}


def stems():
    """The figures the study reruns: every registered figure that runs the library."""
    return sorted(s for s in load_all() if not s.startswith("bench_"))


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
    return out


# -- reading the recorded spread ----------------------------------------------------------------
def spread(stem, key, folder=None):
    """The recorded rounding spread (hi - lo, or a series' width) of figure ``stem``'s number at
    ``key`` (a path as plots.data.differences names it: "v_final", "runs[1].v", a series
    "x_err"); 0.0 where rounding moved it by less than plots.data.RTOL, None where the study
    recorded no number there (its length, a text) or the figure has no rounding section."""
    folder = Path(folder or default_outdir("paper"))
    section = load(folder / f"{stem}.json").get("rounding")
    if section is None:
        return None
    entry = section["spread"].get(key) or section["spread"].get(f"{key}[]")
    if entry is None:
        return 0.0
    if "width" in entry:
        return entry["width"]
    return entry["hi"] - entry["lo"] if "hi" in entry else None
