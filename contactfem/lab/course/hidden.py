"""The hidden checks: instructor material beside the lectures, one file per lecture.

``lectures/hidden_checks/NN_topic.py`` (in an instructor build: ``autograder/hidden_checks/``)
holds ``HIDDEN``: for a public part of an exercise of that lecture (by its name), the hidden
checks that must pass with it. Each takes the part's answers by name and ``rng``, a random
generator seeded by the grader: they ask the same question at parameters drawn from it, so an
answer fitted to any constants it could read does not pass them. They are not in the package,
not in the student notebooks, and never on the disk of a submission's sandbox: the grader reads
them once, before any submission runs, and runs them in its own processes.
"""

import types
import zlib
from pathlib import Path

import numpy as np

FOLDER = "hidden_checks"


def hidden_folder(material=None, repo=None):
    """MATERIAL/hidden_checks if it is there, else the checkout's lectures/hidden_checks (None: neither)."""
    from .lectures import REPO

    for folder in ([Path(material)] if material else []) + [Path(repo or REPO) / "lectures"]:
        if (folder / FOLDER).is_dir():
            return folder / FOLDER
    return None


def read_hidden(folder):
    """{lecture: the source of its hidden checks} of a hidden_checks folder (empty for None)."""
    if folder is None:
        return {}
    return {p.stem: p.read_text() for p in sorted(Path(folder).glob("[0-9][0-9]_*.py"))}


def load_hidden(source, lecture):
    """{public part name: [hidden check functions]} of one lecture's hidden checks, run from
    their source text; ValueError naming the file when it does not define HIDDEN as it should."""
    name = f"{FOLDER}/{lecture}.py"
    mod = types.ModuleType(f"contactfem_hidden_{lecture}")
    try:
        exec(compile(source, name, "exec"), mod.__dict__)
    except Exception as err:
        raise ValueError(f"{name}: {type(err).__name__}: {err}") from None
    hidden = getattr(mod, "HIDDEN", None)
    if not isinstance(hidden, dict) or not all(isinstance(k, str) for k in hidden):
        raise ValueError(f"{name}: HIDDEN should map the names of public parts to lists of checks")
    out = {k: list(v) if isinstance(v, (list, tuple)) else [v] for k, v in hidden.items()}
    if not all(callable(f) for fs in out.values() for f in fs):
        raise ValueError(f"{name}: HIDDEN lists something that is not a function")
    return out


def rng_for(seed, part, check):
    """The random generator of one hidden check of one part: from the grader's seed and their
    names, so that a check draws the same parameters whatever runs before it."""
    return np.random.default_rng([seed, zlib.crc32(part.encode()), zlib.crc32(check.encode())])
