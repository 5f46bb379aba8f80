"""What the course grades: an exercise, its parts with their points, and the written questions."""

from dataclasses import dataclass


@dataclass(frozen=True)
class Part:
    """One graded part of an exercise: `check(**answers)` raises AssertionError with a hint."""

    name: str
    points: float
    check: object
    answers: tuple  # the names of the student's answers it reads


@dataclass(frozen=True)
class Exercise:
    name: str
    lecture: str
    difficulty: str  # easy, medium, hard
    implements: bool  # asks the student to implement part of the method
    parts: tuple
    what: str  # one line for the course plan

    @property
    def points(self):
        return sum(p.points for p in self.parts)


def exercise(name, lecture, difficulty, implements, what, *items):
    """An Exercise from (check, points) pairs: each check's parameters are the answers it reads."""
    ps = tuple(Part(f.__name__, pts, f, tuple(f.__code__.co_varnames[: f.__code__.co_argcount])) for f, pts in items)
    return Exercise(name, lecture, difficulty, implements, ps, what)


@dataclass(frozen=True)
class Manual:
    """A written question of a lecture, scored by the instructor: its prompt is a markdown
    cell holding ``<!-- manual: NAME -->``; the cells after it are the answer."""

    name: str
    lecture: str
    points: float
    what: str
