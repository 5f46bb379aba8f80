"""Figures and tables of the paper, drawn from code.

Each module here draws the figures of one example. A figure function is
registered with ``@figure("fig07_block_conical_stresses", "Fig 7")`` and has the
signature ``fn(preset="fast", outdir="figures") -> list[str]`` (the files it
wrote). The lectures call these same functions; ``contactfem figures`` calls all
of them."""

import importlib
import os
import pkgutil
from functools import lru_cache
from pathlib import Path

from ..solver.rounding import current
from .. import environment
from .data import source_hash
import textwrap
from .. import lazy, scenes

plt = lazy.module("matplotlib.pyplot")
joblib = lazy.module("joblib")

REGISTRY = {}  # file stem -> (paper label, function)


def figure(stem, label):
    """Register a function drawing the paper's figure/table `label` into `stem`.*"""

    def deco(fn):
        REGISTRY[stem] = (label, fn)
        fn.figure_stem = stem
        return fn

    return deco


def default_outdir(preset=None):
    """$CONTACTFEM_FIGURES if set (the tests use a temporary folder), else the repo's figures/
    for the paper preset (the figures kept with the code) and figures/<preset>/ for another
    (default: $CONTACTFEM_PRESET or fast), so a quick run never writes over the paper's figures."""
    env = environment.read("CONTACTFEM_FIGURES")
    if env:
        return env
    preset = preset or default_preset()
    repo = Path(__file__).resolve().parents[2]
    base = repo / "figures" if (repo / "pyproject.toml").exists() else Path("figures")
    return str(base if preset == "paper" else base / preset)


def default_preset():
    """$CONTACTFEM_PRESET if set, else "fast" (what the lectures use)."""
    return environment.read("CONTACTFEM_PRESET", "fast")


def load_all():
    for info in pkgutil.iter_modules(__path__):
        if not info.name.startswith("_"):
            importlib.import_module(f"{__name__}.{info.name}")
    return REGISTRY


def make_all(preset="fast", outdir=None, only=None):
    """Draw every registered figure (or those whose stem contains `only`)."""
    outdir = outdir or default_outdir(preset)
    Path(outdir).mkdir(parents=True, exist_ok=True)
    written = []
    for stem, (label, fn) in sorted(load_all().items()):
        if only and only not in stem:
            continue
        written += fn(preset=preset, outdir=outdir)
    return written


def pyplot():
    """matplotlib.pyplot, imported only when a figure is drawn."""
    return plt


def cache_dir():
    """Where the figures keep their runs between processes: $CONTACTFEM_CACHE/figures (default
    ~/.cache/contactfem/figures); under a rounding condition (solver.rounding) a folder of its own,
    figures-TAG, so that runs of one condition never answer for another."""
    tag = current().tag()
    base = Path(environment.read("CONTACTFEM_CACHE") or Path.home() / ".cache" / "contactfem")
    return base / (f"figures-{tag}" if tag else "figures")


def stored(fn):
    """``fn`` with its results kept on disk (joblib.Memory in ``cache_dir()``), keyed on its
    arguments and the hash of the package's sources (plots.data.source_hash): a later process
    with the same code answers from the disk, a change of the code anywhere runs it again. ``fn``
    must be a module-level function of JSON-like arguments."""
    kept = joblib.Memory(str(cache_dir()), verbose=0).cache(_with_code)

    def call(*args, **kwargs):
        return kept(fn, source_hash(), args, kwargs)

    call.__wrapped__ = fn
    call.kept = lambda *args, **kwargs: kept.check_call_in_cache(fn, source_hash(), args, kwargs)  # on disk?
    return call


def _with_code(fn, code, args, kwargs):
    """What ``stored`` keeps: fn(*args, **kwargs); ``code`` is only part of the key."""
    return fn(*args, **kwargs)


def _run(scene, preset, changed):
    return scenes.run_scene(scene, preset, dict(changed), error_bars=False)  # (the figures draw the runs, not bands)


@lru_cache(maxsize=64)
def _cached(scene, preset, changed, condition):
    return stored(_run)(scene, preset, changed)  # the condition is in cache_dir()


def cached_run(scene, preset="fast", **overrides):
    """A scene's result dict, cached on the resolved parameters: figures, tables and
    lectures share runs, and an override equal to the preset's value is no new run. Kept in
    the process and on disk for the same code (``stored``): a second ``contactfem figures``
    reads the runs of the first."""
    sc = scenes.get_scene(scene)
    base, full = sc.resolve(preset), sc.resolve(preset, overrides)
    return _cached(scene, preset, tuple(sorted((k, v) for k, v in full.items() if v != base[k])), current())


def savefig(fig, outdir, stem):
    """Save a matplotlib figure as outdir/stem.png and close it."""
    path = Path(outdir) / f"{stem}.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return str(path)


def fitted_words(r, to, width=95):
    """ "FITTED to <to>: name = value, ..." from a run's JSON ``fitted`` (the values the scan lost
    that a study chose so the result lands near the paper's), wrapped to ``width``; "" for a run
    without fitted values. Figures that show a fitted reading put it in their title."""
    fitted = r.get("fitted") or {}
    if not fitted:
        return ""
    fmt = lambda v: f"{v:g}" if isinstance(v, float) else str(v)  # noqa: E731
    text = f"FITTED to {to}: " + ", ".join(f"{k} = {fmt(v)}" for k, v in fitted.items())
    return "\n".join(textwrap.wrap(text, width))


# A residual past DIVERGED has left every scale of the problems here (loads 1e2-1e3, first residuals
# 1e2): its iterate is 1e12 or more times the solution, where one rounding error of a product of the
# tangent (1e-16 of terms far larger than the residual itself) decides the next iterate. Its digits are
# rounding (the block's symmetrised tangent, the 8th residual: 1.2e+19 under one OpenBLAS kernel, 3.3e+18
# under another), only that it passed the bound holds.
DIVERGED = 1e15


def diverged_at(history):
    """The number of solves after which a residual history first passed DIVERGED (None: never)."""
    return next((k for k, v in enumerate(history) if float(v) > DIVERGED), None)


def describe_newton(history, converged):
    """What a Newton residual history shows, in words computed from the numbers (for
    figure titles and table notes): "converges in k linear solves", "diverges (past 1e+15 in
    k solves)" when a residual passed DIVERGED (its digits are rounding), "diverges (||G||
    grows from a to b in k solves)" when the last residuals exceed the first tenfold, else
    "does not converge in k solves (||G|| = b)"."""
    h = [float(v) for v in history]
    k = len(h) - 1
    if converged:
        return f"converges in {k} linear solves"
    if diverged_at(h) is not None:
        return f"diverges (past {DIVERGED:.0e} in {diverged_at(h)} solves)"
    if max(h[-3:]) > 10.0 * h[0]:
        return f"diverges (||G|| grows from {h[0]:.2e} to {max(h[-3:]):.2e} in {k} solves)"
    return f"does not converge in {k} solves (||G|| = {h[-1]:.2e})"
