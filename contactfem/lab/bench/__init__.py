"""`contactfem bench`: speed against accuracy, measured.

Eleven studies, each a module with a function returning a JSON-able dict; ``run_bench``
runs them all and ``write_markdown`` (report.py, the one report writer) turns the result
into the tables of BENCHMARKS.md. Files: common.py (targets, timing, observed order),
tangents.py, work_precision.py, cost.py, targets.py, enforcement.py, speed.py, semismooth.py,
scaling.py, coverage.py, adaptive.py, error_bars.py, report.py.

1. tangents        the paper's central claim (Sec. 4.2): Newton with the consistent
                   non-symmetric tangent (eqs 49-50) against a symmetrised tangent, the
                   tangent without the coupling c_N^s C ("frozen") and the staggered
                   normal-then-friction algorithm of Sec. 2.2 (contactfem.solver.staggered),
                   on the block (Sec. 5.1) and the frictional sloping impact (Sec. 5.3):
                   linear solves and time to the same tolerance; divergence is recorded.
2. work_precision  error against wall time under refinement: hertz (mesh; exact a, p0),
                   rolling ring (dt and mesh; exact rolling point of the rigid ring),
                   Newmark 0.7/0.4 against 0.5/0.25, implicit Newmark against explicit
                   central differences on bar_impact (exact contact duration), beam ring
                   against continuum ring. Observed orders: slope of log(error) against
                   log(h) by least squares.
3. cost            time of one Newton iteration split into bulk assembly (body.internal),
                   contact (contact.assemble), global assembly (summing into K) and linear
                   solve (the band LU where the System solves banded, SuperLU with two
                   orderings, pypardiso if installed), at the paper sizes and for the block
                   refined to about 1e5 unknowns; contact time against the number of
                   contact nodes (slope ~1: linear).
4. targets         every paper scene at the paper preset (wall time of the solve and of
                   the whole `contactfem run` process), against the targets.
5. enforcement     Newton solves to reach a gap violation of 1e-8, penalty against
                   augmented Lagrangian, at three penalties (Hertz and the block).
6. speed           start-up of whole processes, one Newton iteration of every paper scene
                   split into bulk, contact, assembly, solve and Python overhead (measured
                   inside a real run), and the Table 2 refinement study as `contactfem sweep`
                   runs it (speed.py).
7. semismooth      linear solves and time to a gap violation of 1e-10: penalty (at the c_N
                   the target needs), augmented Lagrangian (Uzawa) and the semi-smooth
                   Newton method with Lagrange multipliers (node-to-segment and mortar), on
                   Hertz and the block with Coulomb friction; and how far each one's
                   tractions are from the semi-smooth Newton method's.
8. scaling         Hertz on 1k, 4k, 16k and 65k quads against the same problem written as a
                   plain scikit-fem script (skfem.asm, scipy's spsolve, Newton on the active
                   set), in one process and as whole processes (imports included): the ratio
                   contactfem / plain per size (scaling.py).
9. coverage        do the error bands hold? Every scene over the ranges of its discretisations (step,
                   mesh, penalty, enforcement, integrator, both presets) and the physics that move
                   them, each run with its error bars against the true error (a closed form, or a
                   reference refined in step and mesh at once until two levels agree to 0.1 %):
                   coverage, silent-wrong runs, band efficiency (coverage.py).
10. adaptive        a tolerance against fixed steps: for each dynamic scene (sloping impact,
                    rolling ring, bar impact, cork) Newton iterations, residual evaluations and
                    wall time against the error of its headline quantities, a ladder of fixed
                    steps and the ``accuracy`` mode at several tolerances, against a reference
                    refined in time (adaptive.py); quick: the bar impact alone.
11. error_bars      what the error bars cost: every scene at its fast preset, (run + its ladders) /
                    run, and the median over the scenes (error_bars.py).

``quick`` shrinks every study (fast presets, fewer points) to seconds in all.
No timing enters a test: times depend on the machine and its load.
"""

import os
import platform

import numpy as np

from ... import lazy
from ...scenes import jsonable
from .common import PAPER_SCENES, TARGETS, observed_order, timed
from .cost import cost_study, iteration_cost
from .enforcement import enforcement_study
from .coverage import coverage_study
from .error_bars import error_bars_study
from .report import write_markdown, write_outputs
from .scaling import plain_hertz, scaling_study
from .semismooth import semismooth_study
from .speed import speed_study
from .tangents import VARIANTS, tangent_study
from .targets import targets_study
from .work_precision import work_precision
from .adaptive import adaptive_study

scipy = lazy.module("scipy")

STUDIES = {
    "tangents": tangent_study,
    "work_precision": work_precision,
    "cost": cost_study,
    "targets": targets_study,
    "enforcement": enforcement_study,
    "speed": speed_study,
    "semismooth": semismooth_study,
    "scaling": scaling_study,
    "coverage": coverage_study,
    "adaptive": adaptive_study,
    "error_bars": error_bars_study,
}


def machine():
    return dict(
        python=platform.python_version(),
        numpy=np.__version__,
        scipy=scipy.__version__,
        cpus=os.cpu_count(),
        platform=platform.platform(),
        load_average=list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    )


def run_bench(quick=False, only=None, progress=print):
    """Run the studies (all, or those named in `only`); returns the JSON-able dict."""
    out = dict(quick=bool(quick), machine=machine(), target_values=TARGETS)
    for name, fn in STUDIES.items():
        if only and name not in only:
            continue
        if progress:
            progress(f"bench: {name} ...")
        out[f"{name}_machine"] = machine()  # each study its own: a run with --only merges into an earlier one
        res, dt = timed(fn, quick)
        out[name] = res
        out[f"{name}_bench_s"] = dt
    return jsonable(out)


__all__ = [
    "run_bench",
    "STUDIES",
    "TARGETS",
    "PAPER_SCENES",
    "VARIANTS",
    "observed_order",
    "machine",
    "write_markdown",
    "write_outputs",
    "tangent_study",
    "work_precision",
    "cost_study",
    "iteration_cost",
    "targets_study",
    "enforcement_study",
    "speed_study",
    "semismooth_study",
    "scaling_study",
    "plain_hertz",
    "coverage_study",
    "error_bars_study",
    "adaptive_study",
]
