"""The checks of lecture 03: the return mapping."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "03_return_mapping"


def _coulomb_ref(t_bar, dg, p, c_T, mu):
    from ....laws import Coulomb
    from ....laws.return_map import return_map

    fr = return_map(
        Coulomb(c_T=c_T, mu=mu), np.array([-p]), np.array([0.0]), np.array([dg]), np.array([t_bar]), np.array([0.0])
    )
    return float(fr.t_T[0]), float(fr.lam[0])


def _coulomb_student(coulomb_return, t_bar, dg, p, c_T=30.0, mu=0.3):
    out = call(coulomb_return, "coulomb_return", t_bar, dg, p, c_T, mu)
    t_T, lam = parts(out, 2, "coulomb_return", "t_T and lambda")
    try:
        return float(t_T), float(lam)
    except (TypeError, ValueError):
        raise AssertionError(f"coulomb_return should return two numbers (t_T, lambda), got {out!r:.80}") from None


def coulomb_stick(coulomb_return):
    for t_bar, dg, p in ((0.1, 0.002, 1.0), (-0.2, -0.001, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        at = {"t_bar": t_bar, "dg_T": dg, "p": p}
        compare(
            "t_T in stick (c_T = 30, mu = 0.3)",
            t_T,
            want,
            at,
            rule="in stick t_T is the trial traction t_bar + c_T dg_T, eq (42)",
        )
        compare("lambda in stick", lam, 0.0, at)


def coulomb_slip(coulomb_return):
    for t_bar, dg, p in ((0.2, 0.05, 1.0), (0.29, 0.1, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        compare("t_T in slip (c_T = 30, mu = 0.3)", t_T, want, {"t_bar": t_bar, "dg_T": dg, "p": p})


def coulomb_slip_backwards(coulomb_return):
    for t_bar, dg, p in ((0.2, -0.05, 1.0), (-0.1, -0.1, 2.0)):
        t_T, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        want, _ = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        at = {"t_bar": t_bar, "dg_T": dg, "p": p}
        if math.isclose(t_T, -want, rel_tol=1e-8):
            raise AssertionError(
                f"your t_T is {t_T:.6g} at t_bar = {t_bar:g}, dg_T = {dg:g}, p = {p:g}, expected "
                f"{want:.6g}: the return goes along sign(t_tr), eq (43), here negative"
            )
        compare("t_T when sliding backwards", t_T, want, at)


def coulomb_lambda(coulomb_return):
    for t_bar, dg, p in ((0.2, 0.05, 1.0), (0.2, -0.05, 1.0), (0.29, 0.1, 2.0)):
        _, lam = _coulomb_student(coulomb_return, t_bar, dg, p)
        _, want = _coulomb_ref(t_bar, dg, p, 30.0, 0.3)
        compare(
            "lambda in slip (c_T = 30)",
            lam,
            want,
            {"t_bar": t_bar, "dg_T": dg, "p": p},
            rule="lambda = (|t_tr| - Y) / c_T >= 0, eq (44)",
        )


def _moduli_cases():
    from ....laws import ParabolicSlip, PowerLaw, SlipHardening

    normal = PowerLaw(c_N=50.0, m=1.5)
    cases = []
    for law, t_bar, dg, g_N in (
        (ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5), 0.3, 0.05, -0.05),
        (SlipHardening(c_T=30.0, mu=0.3, h=2.0), 0.1, 0.08, -0.1),
        (SlipHardening(c_T=30.0, mu=0.3, h=2.0), -0.1, -0.08, -0.1),
        (SlipHardening(c_T=30.0, mu=0.4, h=-3.0), 0.0, 0.1, -0.08),
    ):
        cases.append((law, normal, t_bar, dg, g_N))
    return cases


def _moduli(slip_moduli, case):
    from ....laws.return_map import return_map

    law, normal, t_bar, dg, g_N = case
    t_N, dt_N = normal.traction(np.array([g_N]))
    fr = return_map(law, t_N, dt_N, np.array([dg]), np.array([t_bar]), np.array([0.0]))
    p = -t_N[0]
    t_tr = t_bar + law.c_T * dg
    _, Y_p, Y_q = law.slip_bound(np.array([p]), fr.q)
    args = (t_tr, law.c_T, float(Y_p[0]), float(Y_q[0]), float(dt_N[0]))
    out = call(slip_moduli, "slip_moduli", *args)
    c_T_s, c_N_s = parts(out, 2, "slip_moduli", "c_T^s and c_N^s")
    at = {"t_tr": args[0], "c_T": args[1], "Y_p": args[2], "Y_q": args[3], "dt_N/dg_N": args[4]}
    return float(np.asarray(c_T_s)), float(np.asarray(c_N_s)), float(fr.c_T_s[0]), float(fr.c_N_s[0]), at


def moduli_c_T(slip_moduli):
    for case in _moduli_cases():
        got, _, want, _, at = _moduli(slip_moduli, case)
        compare("c_T^s = dt_T/dg_T", got, want, at)


def moduli_c_N(slip_moduli):
    for case in _moduli_cases():
        _, got, _, want, at = _moduli(slip_moduli, case)
        compare("c_N^s = dt_T/dg_N", got, want, at, rule="dp/dg_N = -dt_N/dg_N")


EXERCISES = [
    exercise(
        "ex03_coulomb_return",
        LECTURE,
        "medium",
        True,
        "trial state, check and return for one node with Coulomb friction (eqs 40-45)",
        (coulomb_stick, 1),
        (coulomb_slip, 2),
        (coulomb_slip_backwards, 1),
        (coulomb_lambda, 1),
    ),
    exercise(
        "ex03_slip_moduli",
        LECTURE,
        "hard",
        True,
        "the consistent moduli c_T^s, c_N^s (eqs 47-48)",
        (moduli_c_T, 2),
        (moduli_c_N, 3),
    ),
]


LIBRARY = {
    "ex03_coulomb_return": ("contactfem.laws.return_map:return_map", "contactfem.contact.reference:return_map"),
    "ex03_slip_moduli": ("contactfem.laws.return_map:return_map", "contactfem.contact.reference:return_map"),
}
