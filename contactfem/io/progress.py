"""A progress bar for long runs: tqdm's (``tqdm.auto``: a text bar on stderr, a widget in
Jupyter), drawn as

    ring [#######.......................]  35%  t = 0.7  12.1 s

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

from tqdm import tqdm as text_tqdm
from tqdm.auto import tqdm as auto_tqdm

FORMAT = "{desc}[{bar}] {percentage:3.0f}%  {where}  {elapsed_s:.1f} s{note}"


class _Fields:
    """Two more fields for tqdm's format: where the run is (``where``) and a note."""

    where = ""
    note = ""

    @property
    def format_dict(self):
        return dict(super().format_dict, where=self.where, note=f"  ({self.note})" if self.note else "")


class _TextBar(_Fields, text_tqdm):
    """The text bar, on a stream."""


class _AutoBar(_Fields, auto_tqdm):
    """A widget in Jupyter (with ipywidgets), else the text bar on stderr."""


def _bar(stream, **options):
    if stream is not None:  # a stream asked for: the text bar on it
        return _TextBar(file=stream, **options)
    try:
        return _AutoBar(file=sys.stderr, **options)
    except ImportError:  # Jupyter without ipywidgets: tqdm cannot draw its widget
        return _TextBar(file=sys.stderr, **options)


class ProgressBar:
    """As an integrate callback it measures progress by the time t between t0 and t_end; with
    `total` it counts calls of update(). Redrawn at most every `interval` seconds."""

    def __init__(self, total=None, t0=0.0, t_end=None, label="", width=30, stream=None, interval=0.2):
        if (total is None) == (t_end is None):
            raise ValueError("give exactly one of total (a number of steps) and t_end (the end time)")
        if total is not None and not total > 0:
            raise ValueError(f"parameter total = {total!r} is out of range: allowed (0, inf)")
        if t_end is not None and not t_end > t0:
            raise ValueError(f"parameter t_end = {t_end!r} must be > t0 = {t0!r}")
        self.total, self.t0, self.t_end = total, float(t0), t_end
        self.n, self.t = 0, float(t0)
        self.closed = False
        self._bar = _bar(
            stream,
            total=total if total is not None else 1.0,
            desc=f"{label} " if label else "",
            mininterval=float(interval),
            miniters=0,  # redrawn by time alone: a bar over [t0, t_end] moves by fractions of its total of 1
            ascii=".#",
            bar_format=FORMAT.replace("{bar}", f"{{bar:{int(width)}}}"),
        )
        self._bar.where = f"step 0/{total}" if total is not None else f"t = {self.t:.4g}"

    def _to(self, done, force=False):
        """Move the bar to `done` (steps, or the fraction of [t0, t_end]) and draw it."""
        done = min(max(done, 0.0), self._bar.total)
        self._bar.update(done - self._bar.n)
        if force:
            self._bar.refresh()

    def update(self, n=1):
        """Count n more steps (with total)."""
        self.n += n
        self._bar.where = f"step {self.n}/{self.total}"
        self._to(self.n, force=self.n >= self.total)

    def __call__(self, t, u=None, v=None, a=None):
        """The integrate callback: progress (t - t0) / (t_end - t0)."""
        self.t = float(t)
        self.n += 1
        if self.t_end is not None:
            self._bar.where = f"t = {self.t:.4g}"
            self._to((self.t - self.t0) / (self.t_end - self.t0))
        else:
            self._bar.where = f"step {self.n}/{self.total}"
            self._to(self.n)

    def finish(self, note=""):
        """The run is done before t_end by its own rule: draw 100 % with ``note`` saying why."""
        self._bar.note = str(note)
        self._to(self._bar.total, force=True)

    def close(self):
        """Draw the final state and end the line."""
        if not self.closed:
            self._bar.close()
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
