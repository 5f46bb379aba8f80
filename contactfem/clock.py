"""A run's clock: wall time with the time spent importing modules taken out.

contactfem loads its libraries on first use (scikit-fem when a scene builds a continuum,
scipy when a K is sparse), so the first run in a fresh interpreter pays imports that
later runs do not. ``imports_timed()`` sums, while it is active, the wall time of every
``import`` statement that loads a module (the outermost statement only: the imports it
triggers are inside its time; an import that fails counts too): ``run_scene`` subtracts
it from the run's wall time (``wall_time_s``, the run's own time, in every entry point),
and the command line reports what its process spent importing (``import_time_s``).

It wraps ``builtins.__import__`` while active (``importlib.import_module`` is not seen;
the imports a module's body makes are). Not for threads importing at the same time. A
SIGINT handler may hold a Ctrl-C until the import statement it met returns
(``defer_interrupt``).
Imports nothing of contactfem (the command line starts it before loading anything else).
"""

import builtins
import sys
import time
from contextlib import contextmanager

_running = []           # the accumulators ([seconds]) of the clocks active now
_inside = [False]       # within a timed import statement (its nested imports are its own time)
_wrapped = [None]       # the __import__ found when the first clock started
_pending = [False]      # a Ctrl-C met inside a timed import: raised when the import statement returns


def defer_interrupt():
    """Called by a SIGINT handler: True if an import statement is running under a clock, and
    then its KeyboardInterrupt is raised when that statement returns (a C extension met by
    the interrupt inside its own import prints a traceback and turns it into an ImportError:
    numpy's import_array does); False if not, or if an interrupt is already pending (a second
    Ctrl-C is raised at once)."""
    if _inside[0] and not _pending[0]:
        _pending[0] = True
        return True
    return False


def _timed_import(name, globals=None, locals=None, fromlist=(), level=0):
    if _inside[0] or not _running:
        return _wrapped[0](name, globals, locals, fromlist, level)
    loaded = len(sys.modules)
    _inside[0] = True
    t0 = time.perf_counter()
    failed = True
    try:
        module = _wrapped[0](name, globals, locals, fromlist, level)
        failed = False
        return module
    finally:
        _inside[0] = False
        if failed or len(sys.modules) != loaded:
            dt = time.perf_counter() - t0
            for acc in _running:
                acc[0] += dt
        if _pending[0]:
            _pending[0] = False
            raise KeyboardInterrupt


@contextmanager
def imports_timed():
    """Yields a one-element list: the seconds spent loading modules so far inside the block."""
    acc = [0.0]
    if builtins.__import__ is not _timed_import:
        _wrapped[0], builtins.__import__ = builtins.__import__, _timed_import
    _running.append(acc)
    try:
        yield acc
    finally:
        del _running[next(i for i, a in enumerate(_running) if a is acc)]    # this clock, not an equal one
        if not _running and builtins.__import__ is _timed_import:
            builtins.__import__ = _wrapped[0]
