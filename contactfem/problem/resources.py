"""What a run will need: its size from the scene's parameters (elements, unknowns, steps) and
the memory a model calibrated on the continuum scenes estimates, against the limits that
`contactfem run` enforces unless --force."""

import math


def estimate(size, linear_algebra="auto"):
    """The size {elements, unknowns, steps} as counts, and the memory it needs in bytes: the
    sparse LU factors and the assembled tangents dominate, and a solver the user forces adds
    its own matrices (linear_algebra: dense or banded; auto chooses these only where they are
    small)."""
    est = {k: _count(v) for k, v in size.items()}
    n = max(est.get("unknowns", 0), 1)
    memory = MEMORY_BASE + MEMORY_PER_UNKNOWN * n * math.log2(max(n, 2)) + MEMORY_PER_STEP * est.get("steps", 0)
    if linear_algebra == "dense":
        memory += DENSE_BYTES * float(n) ** 2
    elif linear_algebra == "banded":
        memory += BAND_BYTES * float(n) ** 1.5
    est["memory_bytes"] = _count(memory)
    return est


def _count(x):
    """A count from a float estimate: rounded up, overflow (inf, nan) as 1e18."""
    x = float(x)
    return int(math.ceil(x - 1e-9)) if math.isfinite(x) and x < 1e18 else 10**18


# Resource model (Scene.estimate) and the limits that `contactfem run` enforces unless --force.
# Calibrated on hertz (peak resident memory): 45,602 unknowns 312 MB, 181,202 unknowns 1.08 GB,
# i.e. about 310 bytes per unknown and per log2(unknowns) (the LU fill grows like n log n).
MEMORY_BASE = 100e6  # the interpreter with numpy, scipy and scikit-fem loaded
MEMORY_PER_UNKNOWN = 310.0  # bytes per unknown and per log2(unknowns)
MEMORY_PER_STEP = 2.0e3  # bytes per time step (recorded histories)
LIMITS = {"memory_bytes": 2e9, "unknowns": 1e6, "steps": 1e6}
# A forced dense solve holds K (n x n doubles) and the copy LAPACK factorises: 16 bytes per entry.
# A forced band LU holds n (2 kl + ku + 1) doubles; a 2-D mesh renumbered by reverse Cuthill-McKee
# has kl = ku of about 3 sqrt(n) (Hertz: 1026 at n = 132,098, 2.8 sqrt(n); its peak 3.8 GB against
# 0.8 GB sparse): 8 * 9 = 72 bytes per n^1.5, an upper estimate (a ring's band is a few dofs wide).
DENSE_BYTES = 16.0
BAND_BYTES = 72.0


def check_resources(scene, params, force=False, linear_algebra="auto"):
    """ValueError naming the estimate when a run would exceed LIMITS (unless force);
    returns the estimate (or None for a scene without a size model)."""
    est = scene.estimate(params, linear_algebra)
    if est is None or force:
        return est
    over = [k for k, lim in LIMITS.items() if est.get(k, 0) > lim]
    if over:
        raise ValueError(
            f"{scene.name} would need {describe(est)}: above the limit of "
            + ", ".join(_fmt(k, LIMITS[k]) for k in over)
            + " (add --force to run it anyway)"
        )
    return est


def _fmt(key, value):
    if key == "memory_bytes":
        return f"{value / 1e9:.2g} GB" if value >= 1e8 else f"{value / 1e6:.0f} MB"
    return f"{value:,.0f} {key[:-1] if round(value) == 1 else key}"  # 1 step, 2 steps


def describe(est):
    """'4,000,000 elements, 8,004,002 unknowns, 1 step, about 21 GB'"""
    parts = [_fmt(k, est[k]) for k in ("elements", "unknowns", "steps") if k in est]
    return ", ".join(parts) + f", about {_fmt('memory_bytes', est['memory_bytes'])}"
