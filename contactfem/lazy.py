"""What is loaded lazily, declared where it is used (scientific Python's SPEC 1, in a few lines).

A module names its heavy libraries at its top, as lazy modules, and uses them as modules:

    from ..lazy import module

    sparse = module("scipy.sparse")     # loaded on first use: sparse.csr_matrix(...)

so ``contactfem list`` loads neither scipy nor scikit-fem nor matplotlib, and a reader still
sees every dependency at the top of the file. A package's ``__init__`` offers the names of its
submodules the same way (SPEC 1's ``attach``):

    __getattr__, __dir__ = attach(__name__, {"run_scene": "scenes", "LawError": "laws"}, globals())

The load goes through the import system (``importlib.import_module``) when an attribute is
first read, so a run's clock (clock.imports_timed) sees it and takes it out of the run's wall
time. (lazy_loader's ``load`` executes the module outside the import system, unseen by the
clock, and imports the parents at once: scipy for scipy.sparse.) Every attribute is read from
the loaded module each time, so a monkeypatch on that module is seen.
Imports nothing of contactfem.
"""

import importlib


class _Lazy:
    """A module not loaded yet: imported on the first attribute read, then kept."""

    __slots__ = ("_name", "_module")

    def __init__(self, name):
        object.__setattr__(self, "_name", name)
        object.__setattr__(self, "_module", None)

    def __getattr__(self, attr):
        if self._module is None:
            object.__setattr__(self, "_module", importlib.import_module(self._name))
        return getattr(self._module, attr)

    def __setattr__(self, attr, value):
        raise AttributeError(f"set {attr!r} on the module {self._name!r}, not on its lazy name")

    def __repr__(self):
        return f"<lazy module {self._name!r}>"


def module(name):
    """The module `name` (absolute), loaded when one of its attributes is first read."""
    return _Lazy(name)


def attach(package, homes, namespace):
    """A package's ``__getattr__`` and ``__dir__`` (PEP 562) that offer each name of `homes`
    (name -> the submodule it lives in, relative to `package`), loaded on first use."""

    def __getattr__(name):
        if name not in homes:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f".{homes[name]}", package), name)

    def __dir__():
        return sorted(set(namespace) | set(homes))

    return __getattr__, __dir__
