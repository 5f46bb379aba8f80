"""The automatic checks of the course's exercises, one module per lecture.

The checks of lecture ``NN_topic`` live in ``checks/topic.py`` (``01_interface_laws``:
:mod:`.interface_laws`): the functions of its parts, each raising AssertionError with a hint
a student can act on ("your dt_N/dg_N is off by a factor 2.5 at g_N = -0.1"), and

* ``EXERCISES``: its exercises (:func:`.exercise.exercise`: name, lecture, difficulty, whether
  it implements part of the method, one line for the course plan, the parts with points);
* ``LIBRARY`` (optional): for an exercise that asks for part of the method, the library's own
  implementation of that part ("module:Name"), left out of the students' edition of the
  library that the submissions of the lecture are graded with;
* ``BUILDS_ON`` (optional): the exercises that build on the library on purpose, and on what;
* ``MANUAL`` (optional): its written questions, scored by the instructor.

Their hidden checks (other parameters, drawn from a seed while grading) are instructor
material beside the lectures: ``lectures/hidden_checks/NN_topic.py``.

`contactfem course build` writes every part into the notebook as a test of the grading tool
(otter-grader), with its points; `grader.check("NAME")` in the student's notebook runs them,
and `contactfem course grade` runs them, with the hidden ones, on the submissions.
"""

from . import (
    beyond_node_to_segment,
    block,
    cork,
    funnel,
    interface_laws,
    kinematics_linearisation,
    return_mapping,
    rolling_ring,
    sloping_impact,
    speed_accuracy,
    where_1990_stops,
    write_your_own_law,
)
from .exercise import Exercise, Manual, Part  # noqa: F401

LECTURES = (
    interface_laws,
    kinematics_linearisation,
    return_mapping,
    block,
    rolling_ring,
    sloping_impact,
    funnel,
    cork,
    speed_accuracy,
    write_your_own_law,
    where_1990_stops,
    beyond_node_to_segment,
)
EXERCISES = {e.name: e for m in LECTURES for e in m.EXERCISES}
LIBRARY = {k: v for m in LECTURES for k, v in getattr(m, "LIBRARY", {}).items()}
BUILDS_ON = {k: v for m in LECTURES for k, v in getattr(m, "BUILDS_ON", {}).items()}
MANUAL = {q.name: q for m in LECTURES for q in getattr(m, "MANUAL", ())}


def module_of(lecture):
    """The module of a lecture's checks ("01_interface_laws": interface_laws)."""
    return next(m for m in LECTURES if m.LECTURE == lecture)


def run(name, env):
    """Run the parts of exercise `name` on the names in `env` (a notebook's globals):
    [(part, points scored, message)]. For the instructor and the tests; the grading goes
    through otter."""
    out = []
    for part in EXERCISES[name].parts:
        try:
            part.check(**{a: env.get(a) for a in part.answers})
            out.append((part.name, part.points, "passed"))
        except AssertionError as err:
            out.append((part.name, 0.0, str(err)))
    return out
