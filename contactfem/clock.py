"""A run's clock: wall time with the time spent importing modules taken out.

contactfem loads its libraries on first use (scikit-fem when a scene builds a continuum,
scipy when a K is sparse), so the first run in a fresh interpreter pays imports that
later runs do not. ``imports_timed()`` sums, while it is active, the wall time of loading
every module (the outermost one only: the modules its body loads are inside its time; a
module whose body fails counts too): ``run_scene`` subtracts
it from the run's wall time (``wall_time_s``, the run's own time, in every entry point),
and the command line reports what its process spent importing (``import_time_s``).

It watches imports through the import system's own extension point, a finder first on
``sys.meta_path`` while a clock is active (PEP 451): the loader of a module it finds times the
execution of the module's body, then hands the module back to its own loader (the module
never sees the timing one). Nothing of Python is replaced. Finding a module on the path is
not counted, loading it is (``importlib.import_module`` too). Not for threads importing at
the same time. A SIGINT handler may hold a Ctrl-C until the module being loaded returns
(``defer_interrupt``).
Imports nothing of contactfem (the command line starts it before loading anything else).
"""

import sys
import time
from contextlib import contextmanager

_running = []  # the accumulators ([seconds]) of the clocks active now
_inside = [False]  # within a timed module body (the modules it loads are its own time)
_pending = [False]  # a Ctrl-C met inside a timed module body: raised when the body returns


def defer_interrupt():
    """Called by a SIGINT handler: True if a module is being loaded under a clock, and then
    its KeyboardInterrupt is raised when that module's body returns (a C extension met by
    the interrupt inside its own import prints a traceback and turns it into an ImportError:
    numpy's import_array does); False if not, or if an interrupt is already pending (a second
    Ctrl-C is raised at once)."""
    if _inside[0] and not _pending[0]:
        _pending[0] = True
        return True
    return False


class _TimedLoader:
    """The loader of one module found while a clock runs: creates the module with its own
    loader, puts that loader back on the module, and times the module's body."""

    def __init__(self, loader):
        self.loader = loader

    def create_module(self, spec):
        return self.loader.create_module(spec)

    def exec_module(self, module):
        module.__spec__.loader = module.__loader__ = self.loader  # the module sees its own loader only
        if _inside[0] or not _running:
            return self.loader.exec_module(module)
        _inside[0] = True
        t0 = time.perf_counter()
        try:
            return self.loader.exec_module(module)
        finally:
            _inside[0] = False
            dt = time.perf_counter() - t0
            for acc in _running:
                acc[0] += dt
            if _pending[0]:
                _pending[0] = False
                raise KeyboardInterrupt


class _Finder:
    """First on sys.meta_path while a clock runs: asks the finders after it, and gives the module
    it finds a _TimedLoader (a module found again, or loaded inside a timed one, is not timed)."""

    def find_spec(self, name, path=None, target=None):
        if _inside[0] or not _running:
            return None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            if finder is self or find is None:
                continue
            spec = find(name, path, target)
            if spec is None:
                continue
            if spec.loader is not None and hasattr(spec.loader, "exec_module"):
                spec.loader = _TimedLoader(spec.loader)
            return spec
        return None


_FINDER = _Finder()


@contextmanager
def imports_timed():
    """Yields a one-element list: the seconds spent loading modules so far inside the block."""
    acc = [0.0]
    if _FINDER not in sys.meta_path:
        sys.meta_path.insert(0, _FINDER)
    _running.append(acc)
    try:
        yield acc
    finally:
        del _running[next(i for i, a in enumerate(_running) if a is acc)]  # this clock, not an equal one
        if not _running and _FINDER in sys.meta_path:
            sys.meta_path.remove(_FINDER)
