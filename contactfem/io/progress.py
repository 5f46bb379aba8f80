"""A progress bar for long runs, on stderr, without dependencies.

    bar = ProgressBar(t0=0.0, t_end=2.0, label="ring")
    for rec in march(stepper, Steps(dt, t_end=2.0), 0.0, u0, v0):
        bar(rec.t)
    bar.close()

or, counting steps: ``bar = ProgressBar(total=200)`` and ``bar.update()`` per step. A run that
ends before t_end by its own rule (the cork stops some time after it has left the bottle) says
so: ``bar.finish("why")`` draws 100 % with that reason.
Several callbacks at once: ``chain(bar, recorder)``. A scene or ``integrate`` makes its own
bars with ``progress=progress_bar`` (one per time loop; solver.march.watch).
"""

import sys
import time


class ProgressBar:
    """`[#######.............]  35%  t = 0.7  12.1 s` on one line of stderr, redrawn at most
    every `interval` seconds. As an integrate callback it measures progress by the time t
    between t0 and t_end; with `total` it counts calls of update()."""

    def __init__(self, total=None, t0=0.0, t_end=None, label="", width=30, stream=None, interval=0.2):
        if (total is None) == (t_end is None):
            raise ValueError("give exactly one of total (a number of steps) and t_end (the end time)")
        if total is not None and not total > 0:
            raise ValueError(f"parameter total = {total!r} is out of range: allowed (0, inf)")
        if t_end is not None and not t_end > t0:
            raise ValueError(f"parameter t_end = {t_end!r} must be > t0 = {t0!r}")
        self.total, self.t0, self.t_end, self.label = total, float(t0), t_end, label
        self.width, self.interval = int(width), float(interval)
        self.stream = stream if stream is not None else sys.stderr
        self.n, self.fraction, self.t = 0, 0.0, float(t0)
        self.start = time.perf_counter()
        self._last = -1e300
        self._drawn_at = None
        self.closed = False
        self.note = ""

    def text(self):
        f = min(max(self.fraction, 0.0), 1.0)
        k = int(round(f * self.width))
        where = f"step {self.n}/{self.total}" if self.total is not None else f"t = {self.t:.4g}"
        head = f"{self.label} " if self.label else ""
        note = f"  ({self.note})" if self.note else ""
        return (f"{head}[{'#' * k}{'.' * (self.width - k)}] {100 * f:3.0f}%  {where}  "
                f"{time.perf_counter() - self.start:.1f} s{note}")

    def _draw(self, force=False):
        now = time.perf_counter()
        if force or now - self._last >= self.interval:
            self.stream.write("\r" + self.text())
            self.stream.flush()
            self._last = now
            self._drawn_at = self.fraction

    def update(self, n=1):
        """Count n more steps (with total)."""
        self.n += n
        self.fraction = self.n / self.total if self.total is not None else self.fraction
        self._draw(force=self.n >= (self.total or float("inf")))

    def __call__(self, t, u=None, v=None, a=None):
        """The integrate callback: progress (t - t0) / (t_end - t0)."""
        self.t = float(t)
        self.n += 1
        if self.t_end is not None:
            self.fraction = (self.t - self.t0) / (self.t_end - self.t0)
        elif self.total is not None:
            self.fraction = self.n / self.total
        self._draw(force=self.fraction >= 1.0)

    def finish(self, note=""):
        """The run is done before t_end by its own rule: draw 100 % with ``note`` saying why."""
        self.fraction, self.note = 1.0, str(note)
        self._draw(force=True)

    def close(self):
        """Draw the final state and end the line."""
        if not self.closed:
            if self._drawn_at != self.fraction:      # the final state is not on screen yet
                self._draw(force=True)
            self.stream.write("\n")
            self.stream.flush()
            self.closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def chain(*callbacks):
    """One integrate callback calling each of `callbacks` in turn (None entries skipped)."""
    fns = [c for c in callbacks if c is not None]

    def call(t, u, v, a):
        for fn in fns:
            fn(t, u, v, a)

    return call


def progress_bar(t0, t_end, label=""):
    """A ProgressBar over [t0, t_end]: what ``integrate(..., progress=progress_bar)`` and
    ``run_scene(..., progress=progress_bar)`` (``contactfem run --progress``) expect."""
    return ProgressBar(t0=t0, t_end=t_end, label=label)
