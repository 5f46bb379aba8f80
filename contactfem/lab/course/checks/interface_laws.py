"""The checks of lecture 01: the interface laws."""

import numpy as np

from .answers import args_text, call, compare, defined, parts
from .exercise import exercise, Manual

LECTURE = "01_interface_laws"


def _power_law_call(power_law, g_N, c_N, m):
    out = call(power_law, "power_law", g_N, c_N, m)
    return parts(out, 2, "power_law", "t_N and dt_N/dg_N")


def power_law_open(power_law):
    g = np.array([0.01, 0.2, 0.0])
    t_N, dt_N = _power_law_call(power_law, g, 100.0, 2.5)
    compare("t_N for an open gap", t_N, np.zeros(3), {"g_N": g}, rule="no contact, no traction: t_N = 0 where g_N >= 0")
    compare("dt_N/dg_N for an open gap", dt_N, np.zeros(3), {"g_N": g})


def power_law_traction(power_law):
    g = np.array([-0.01, -0.1, -0.5, -0.01, -0.1, -0.5])
    m = np.array([1.0, 1.0, 1.0, 2.5, 2.5, 2.5])
    for mm in (1.0, 2.5):
        sel = m == mm
        t_N, _ = _power_law_call(power_law, g[sel], 100.0, mm)
        compare(f"t_N (c_N = 100, m = {mm:g})", t_N, -100.0 * (-g[sel]) ** mm, {"g_N": g[sel]})


def power_law_derivative(power_law):
    g = np.array([-0.01, -0.1, -0.5])
    for mm in (1.0, 2.5):
        _, dt_N = _power_law_call(power_law, g, 100.0, mm)
        compare(f"dt_N/dg_N (c_N = 100, m = {mm:g})", dt_N, 100.0 * mm * (-g) ** (mm - 1.0), {"g_N": g})


def _tresca(Tresca, **kw):
    defined(Tresca, "Tresca", "class")
    try:
        return Tresca(**kw)
    except Exception as err:
        raise AssertionError(f"Tresca({args_text((), kw)}) raised {type(err).__name__}: {err}") from None


def tresca_fields(Tresca):
    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    if getattr(law, "c_T", None) != 30.0 or getattr(law, "tau_y", None) != 0.2:
        raise AssertionError(
            "Tresca(c_T=30.0, tau_y=0.2) should keep its fields c_T and tau_y "
            "(a dataclass with the fields c_T: float and tau_y: float)"
        )
    if not callable(getattr(law, "slip_bound", None)):
        raise AssertionError("a Tresca law needs a method slip_bound(self, p, q)")
    out = call(law.slip_bound, "Tresca(c_T=30.0, tau_y=0.2).slip_bound", np.array([1.0]), np.array([0.0]))
    parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def _tresca_bound(Tresca):
    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    p = np.array([0.5, 1.0, 4.0, 0.5, 1.0, 4.0])
    q = np.array([0.0, 0.0, 0.0, 0.3, 0.3, 0.3])
    out = call(law.slip_bound, "Tresca(c_T=30.0, tau_y=0.2).slip_bound", p, q)
    return p, q, parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def tresca_bound(Tresca):
    p, q, (Y, _, _) = _tresca_bound(Tresca)
    Yb = np.broadcast_to(np.asarray(Y, dtype=float), p.shape) if np.ndim(Y) <= 1 else np.asarray(Y)
    if np.all(np.isfinite(Yb)) and np.allclose(Yb / p, Yb[0] / p[0]) and not np.allclose(Yb, Yb[0]):
        raise AssertionError(
            f"your Y grows with the pressure (Y/p = {Yb[0] / p[0]:.4g} at every p): that is "
            "Coulomb's law; Tresca's bound is the constant shear strength tau_y, whatever p"
        )
    compare("slip bound Y (tau_y = 0.2)", Y, np.full(p.shape, 0.2), {"p": p, "q": q})


def tresca_derivatives(Tresca):
    p, q, (_, Y_p, Y_q) = _tresca_bound(Tresca)
    compare("dY/dp", Y_p, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on p")
    compare("dY/dq", Y_q, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on q")


def tresca_check_law(Tresca):
    from ....laws.check import check_law

    law = _tresca(Tresca, c_T=30.0, tau_y=0.2)
    report = check_law(law)
    if not report.ok:
        failed = [s for ok, s in report.checks if not ok]
        raise AssertionError("check_law(Tresca(c_T=30.0, tau_y=0.2)) fails: " + failed[0])


EXERCISES = [
    exercise(
        "ex01_power_law",
        LECTURE,
        "easy",
        True,
        "the normal law of eq (4) and its derivative",
        (power_law_open, 1),
        (power_law_traction, 2),
        (power_law_derivative, 2),
    ),
    exercise(
        "ex01_tresca",
        LECTURE,
        "medium",
        True,
        "a Tresca friction law, passing check_law",
        (tresca_fields, 1),
        (tresca_bound, 2),
        (tresca_derivatives, 1),
        (tresca_check_law, 1),
    ),
]


LIBRARY = {
    "ex01_power_law": ("contactfem.laws.normal:PowerLaw", "contactfem.contact.reference:power_law"),
    "ex01_tresca": ("contactfem.laws.friction:Coulomb", "contactfem.laws.friction:ParabolicSlip"),
}


MANUAL = [
    Manual(
        "ex01_discussion",
        LECTURE,
        2,
        "a short discussion: what the penalty law's stiffness c_N trades off (penetration against conditioning)",
    ),
]
