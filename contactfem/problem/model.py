"""What a scene's ``build`` returns: the ``Model`` (its Systems, its marches, what the shared
code reads of it, and the scene's own objects), and the ``Stage`` of one march."""

from dataclasses import dataclass, field
from typing import Callable

import numpy as np


@dataclass
class Stage:
    """One march of a scene (solver.march): the stepper, the schedule, the initial state (u0,
    v0, a0 at t0, and the SystemState ``state`` to start from: None, the system's own start at
    u0), how the progress bar and error messages name it, and ``until``: the scene's rule of when
    to stop before the schedule's end, a function from the stage's records (an iterator) to those
    it keeps (a generator; the text it returns, if any, says on the progress bar why it stopped)."""

    stepper: object
    schedule: object
    u0: np.ndarray
    v0: np.ndarray = None
    t0: float = 0.0
    a0: np.ndarray = None
    name: str = ""
    label: Callable | None = None
    state: object = None
    until: Callable | None = None


@dataclass(frozen=True)
class Model:
    """What a scene's ``build`` returns: every System it built (``systems``), the marches that
    run it (``stages``, in turn: a Stage, or a function that builds the Stage from the last record
    of the stage before it; ``stage=``: a model of one), the lengths the accuracy
    indicators compare the penetration with (``sizes``: ``element``, ``body``, and ``radius``
    for a ring), whether the scene reads a rebound after the impact (``rebound``), the name progress shows, and the
    scene's own objects (``parts``: bodies, contacts, node sets, closed forms) for its
    ``measure`` and plots."""

    systems: tuple
    stage: Stage | None = None
    stages: tuple = ()
    sizes: dict = field(default_factory=dict)
    rebound: bool = False
    name: str = ""
    parts: dict = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "systems", tuple(self.systems))
        stages = tuple(self.stages) or ((self.stage,) if self.stage is not None else ())
        object.__setattr__(self, "stages", stages)
        if self.stage is None and stages and isinstance(stages[0], Stage):
            object.__setattr__(self, "stage", stages[0])  # the first march

    @property
    def system(self):
        """The first System the scene built (None if it built none)."""
        return self.systems[0] if self.systems else None
