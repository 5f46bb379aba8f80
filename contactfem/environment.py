"""The environment variables contactfem reads, in one table (the README prints it).

A few are for users (where caches and figures go, the lectures' preset, a traceback on an internal
error); the others carry a setting from a command to the processes it starts (a rounding study's
condition, the course website's notebook cache) or a signal back from them. The package reads them
through ``read``, which refuses a name the table does not declare, so that a new one cannot hide.
The test suite's own switches are pytest options (tests/conftest.py), not variables.
"""

import os

USER, TOOLKIT, CALLER = "you", "contactfem, for the processes it starts", "a program that starts contactfem"

# name -> (who sets it, what it does)
VARIABLES = {
    "CONTACTFEM_CACHE": (USER, "where studies keep their runs for the next call (default ~/.cache/contactfem)"),
    "CONTACTFEM_DEBUG": (USER, "1: an internal error prints its traceback, not one line"),
    "CONTACTFEM_ERROR_BARS": (
        USER,
        "0, off, no or false: runs leave out their error bars unless a call asks for them (--error-bars); 1, on, yes "
        "or true (the default): with them",
    ),
    "CONTACTFEM_PRESET": (USER, "the preset the lectures and the figures run (default fast)"),
    "CONTACTFEM_FIGURES": (
        USER,
        "the folder the lectures and the figures write to (default figures/ for the paper preset, "
        "figures/PRESET/ for another)",
    ),
    "CONTACTFEM_SLOW": (USER, "1: the cork's studies run every case, as the committed figures did"),
    "CONTACTFEM_BENCH": (USER, "the bench file the bench's figures draw (default bench.json)"),
    "CONTACTFEM_LINEAR_ALGEBRA": (TOOLKIT, "a rounding condition: the factorisation every System uses"),
    "CONTACTFEM_PERTURB": (TOOLKIT, "a rounding condition: the relative perturbation of every initial state"),
    "CONTACTFEM_READY_FILE": (CALLER, "a file the command line creates once it is ready to be signalled"),
    "CONTACTFEM_SITE_CACHE": (TOOLKIT, "the course website's notebook cache, for its page builder"),
    "CONTACTFEM_SITE_EXECUTE": (TOOLKIT, "how the course website's page builder runs the notebooks"),
}


def read(name, default=None):
    """The value of environment variable ``name`` (``default`` if unset); a name the table above does
    not declare is refused (KeyError)."""
    if name not in VARIABLES:
        raise KeyError(f"{name} is not one of contactfem's environment variables (contactfem.environment)")
    return os.environ.get(name, default)


def table():
    """The markdown table of the variables (the README's)."""
    rows = [f"| `{name}` | {who} | {what} |" for name, (who, what) in VARIABLES.items()]
    return "\n".join(["| variable | set by | what it does |", "|---|---|---|", *rows])
