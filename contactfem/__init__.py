"""contactfem: large-deformation impact-contact with friction after
Wriggers, Vu Van & Stein (1990), on scikit-fem. A teaching and reference toolkit.

Importing the package loads nothing else (not even numpy): the command line starts at once
and answers Ctrl-C from its first moment; ``contactfem.check_law`` is loaded on first use."""

__version__ = "0.1.0"
__all__ = ["check_law"]


def __dir__():
    return sorted(list(globals()) + ["check_law"])


def __getattr__(name):
    if name == "check_law":
        from .laws import check_law

        return check_law
    raise AttributeError(f"module 'contactfem' has no attribute {name!r}")
