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
from contextlib import contextmanager, nullcontext

PARTS = ("bulk", "contact", "assembly", "solve", "newton")
NOT_TIMED = nullcontext()          # what an uninstrumented part enters (reusable, does nothing)


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
        self._newton = 0                # depth of Newton solves in progress

    @contextmanager
    def part(self, name):
        inside = self._newton > 0 or name == "newton"
        self._newton += name == "newton"
        t0 = self.clock()
        try:
            yield
        finally:
            (self.seconds if inside else self.outside)[name] += self.clock() - t0
            self._newton -= name == "newton"


def timed(instrument, name):
    """The context that times part `name` with the instrument (nothing without one)."""
    return NOT_TIMED if instrument is None else instrument.part(name)
