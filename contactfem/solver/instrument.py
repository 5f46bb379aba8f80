"""Where the time of Newton iterations goes: an instrument a System is built with.

    timings = Timings()
    system = System(bodies, contacts, loads, instrument=timings)
    ... run ...
    timings.seconds            # bulk, contact, assembly, solve, newton (CPU seconds, summed)
    timings.solves             # linear solves

The System times its evaluation's parts (bulk: the bodies' internal forces and tangents;
contact: the contacts' states and their scatter; assembly: the loads and summing into K)
and the steppers hand the instrument to Newton, which times its linear solves and itself.
Without an instrument (the default) nothing is timed. CPU time of the running thread:
OpenBLAS's idle worker threads, spinning on another core after a library call, do not count.
"""

import time
from contextlib import nullcontext

PARTS = ("bulk", "contact", "assembly", "solve", "newton")
NOT_TIMED = nullcontext()  # what an uninstrumented part enters (reusable, does nothing)


class Timings:
    """CPU seconds of each part (PARTS), summed over every evaluation and Newton solve, and
    the number of linear solves. ``seconds``: the parts timed inside Newton (its iterations);
    ``outside``: those timed outside it (the initial state's evaluation, which also pays for
    what a first evaluation loads and builds: scipy's modules, the tangent's pattern)."""

    def __init__(self, clock=time.thread_time):
        self.clock = clock
        self.seconds = dict.fromkeys(PARTS, 0.0)
        self.outside = dict.fromkeys(PARTS, 0.0)
        self.solves = 0
        self._newton = 0  # depth of Newton solves in progress
        self._parts = {name: _Part(self, name) for name in PARTS}

    def part(self, name):
        """The context that times part `name` (made once per part: a timed part costs the
        instrument two clock readings and little else)."""
        return self._parts[name]


class _Part:
    """Times one part of a Timings: ``with timings.part(name): ...`` adds the CPU time spent
    inside to the part's sum (``seconds`` inside a Newton solve, else ``outside``)."""

    def __init__(self, timings, name):
        self.timings, self.name, self.starts = timings, name, []

    def __enter__(self):
        t = self.timings
        t._newton += self.name == "newton"
        self.starts.append(t.clock())  # a stack: a part may be entered again inside itself

    def __exit__(self, *exc):
        t = self.timings
        elapsed = t.clock() - self.starts.pop()
        (t.seconds if t._newton > 0 else t.outside)[self.name] += elapsed
        t._newton -= self.name == "newton"
        return False


def timed(instrument, name):
    """The context that times part `name` with the instrument (nothing without one)."""
    return NOT_TIMED if instrument is None else instrument.part(name)
