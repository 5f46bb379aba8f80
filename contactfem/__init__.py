"""contactfem: large-deformation impact-contact with friction after
Wriggers, Vu Van & Stein (1990), on scikit-fem. A teaching and reference toolkit.

Importing the package loads nothing else (not even numpy): the command line starts at once
and answers Ctrl-C from its first moment; what it offers at the top, loaded on first use:

    from contactfem import run_scene, check_law, LawError, LawValueError, AccuracyWarning

(AccuracyWarning: the one warning class of a run's accuracy indicators, for warnings filters.)
"""

from .lazy import attach

__version__ = "0.1.0"
__all__ = ["run_scene", "check_law", "LawError", "LawValueError", "AccuracyWarning"]
_HOMES = {
    "run_scene": "scenes",
    "check_law": "laws",
    "LawError": "laws",
    "LawValueError": "laws",
    "AccuracyWarning": "problem.accuracy",
}


__getattr__, __dir__ = attach(__name__, _HOMES, globals())
