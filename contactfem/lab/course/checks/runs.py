"""The answers that run a scene: one run per answer and arguments, the scene's parts handed to
the answer as recipes, and what a check reads from the runs' records."""

import numpy as np

from .answers import Recipe, parts

_MEMO = {}


def memo(key, thunk):
    """thunk() once per key (the student's function and its arguments): the parts of an
    exercise that run a time loop share one run; a failure is remembered as well."""
    if key not in _MEMO:
        try:
            _MEMO[key] = (True, thunk())
        except AssertionError as err:
            _MEMO[key] = (False, err)
    ok, value = _MEMO[key]
    if not ok:
        raise AssertionError(str(value))
    return value


def scene_model(name, overrides):
    """A fresh model of a scene (its build, fast preset): stepper, schedule, u0, v0 of its stage."""
    from ....scenes import get_scene

    scene = get_scene(name)
    params = scene.resolve("fast", overrides)
    return scene.build(params), params


class ScenePart(Recipe):
    """A part of a scene's model for an answer, e.g. ``ScenePart("block", {"law": "conical"},
    "parts", "stepper")``: the model built in the answer's own process (an attribute, or a key
    of a dict, at each step of the path)."""

    def __init__(self, scene, overrides, *path):
        self.scene, self.overrides, self.path = scene, dict(overrides), path

    def make(self, built):
        key = (self.scene, tuple(sorted(self.overrides.items())))
        if key not in built:
            built[key] = scene_model(self.scene, self.overrides)[0]
        return walk(built[key], self.path)

    def data(self):
        return {"t": "scene", "scene": self.scene, "set": self.overrides, "path": list(self.path)}

    def __repr__(self):
        return ".".join(self.path) if self.path else self.scene


def walk(obj, path):
    for step in path:
        obj = obj[step] if isinstance(obj, dict) else getattr(obj, step)
    return obj


def counts(rec):
    """(nodes in contact, nodes slipping) of a record's first converged contact state."""
    from ....laws.return_map import OPEN, SLIP

    st = rec.contacts[0]
    return int(np.count_nonzero(st.slip != OPEN)), int(np.count_nonzero(st.slip == SLIP))


def as_list(out, n, name, what):
    values = [np.asarray(v, dtype=float).ravel() for v in parts(out, n, name, what)]
    sizes = {v.size for v in values}
    if len(sizes) != 1:
        raise AssertionError(
            f"{name} should return {n} arrays of one length (one entry per step), "
            f"got lengths {[v.size for v in values]}"
        )
    return values
