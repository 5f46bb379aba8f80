"""What a scene's ``build`` returns: the ``Model`` (its Systems, its march, what the shared
code reads of it, and the scene's own objects), and the ``Stage`` of one march."""

from dataclasses import dataclass, field
from typing import Callable

import numpy as np


@dataclass
class Stage:
    """One march of a scene (solver.march): the stepper, the schedule, the initial state,
    and how the progress bar and error messages name it."""

    stepper: object
    schedule: object
    u0: np.ndarray
    v0: np.ndarray = None
    t0: float = 0.0
    a0: np.ndarray = None
    name: str = ""
    label: Callable | None = None


@dataclass(frozen=True)
class Model:
    """What a scene's ``build`` returns: every System it built (``systems``), the march that
    runs it (``stage``; None for a scene with its own ``simulate``), the lengths the accuracy
    indicators compare the penetration with (``sizes``: ``element``, ``body``, and ``radius``
    for a ring), whether the scene reads a rebound after the impact (``rebound``), the name progress shows, and the
    scene's own objects (``parts``: bodies, contacts, node sets, closed forms) for its
    ``measure`` and plots."""

    systems: tuple
    stage: Stage | None = None
    sizes: dict = field(default_factory=dict)
    rebound: bool = False
    name: str = ""
    parts: dict = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "systems", tuple(self.systems))

    @property
    def system(self):
        """The first System the scene built (None if it built none)."""
        return self.systems[0] if self.systems else None
