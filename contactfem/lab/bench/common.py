"""What the bench studies share: the targets, timing and the observed order of convergence."""

import time

import numpy as np

TARGETS = dict(scene_s=10.0, all_s=60.0, hertz_process_s=1.5, hertz_p0_error=0.005, hertz_quads=4000)
PAPER_SCENES = ("block", "rolling_ring", "sloping_impact", "funnel", "cork")


def timed(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def observed_order(h, err):
    """Slope p of log(err) = p log(h) + c by least squares (err ~ C h^p); None with
    fewer than two positive errors."""
    h, err = np.asarray(h, float), np.abs(np.asarray(err, float))
    ok = (err > 0) & np.isfinite(err)
    if np.count_nonzero(ok) < 2:
        return None
    return float(np.polyfit(np.log(h[ok]), np.log(err[ok]), 1)[0])


def best_of(fn, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        out, dt = timed(fn)
        best = min(best, dt)
    return out, best
