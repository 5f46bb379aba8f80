"""The hidden checks of lecture 03: the return map at a law and states drawn from the grader's seed."""

import numpy as np

from contactfem.lab.course.checks.answers import compare, draw
from contactfem.lab.course.checks.return_mapping import _coulomb_ref, _coulomb_student, _moduli


def _coulomb_other(coulomb_return, rng, slip):
    c_T, mu, p = draw(rng, 5.0, 50.0), draw(rng, 0.1, 0.8), draw(rng, 0.5, 5.0)
    t_bar = draw(rng, -0.9, 0.9) * mu * p
    Y = mu * p
    # a trial traction inside the slip surface (stick) or well past it (slip), either direction
    target = rng.choice([-1.0, 1.0]) * (draw(rng, 1.3, 3.0) if slip else draw(rng, 0.0, 0.8)) * Y
    dg = float(f"{(target - t_bar) / c_T:.3g}")
    got = _coulomb_student(coulomb_return, t_bar, dg, p, c_T=c_T, mu=mu)
    return got, _coulomb_ref(t_bar, dg, p, c_T, mu), {"t_bar": t_bar, "dg_T": dg, "p": p}, f"c_T = {c_T:g}, mu = {mu:g}"


def coulomb_stick_other(coulomb_return, rng):
    (t_T, lam), (want, _), at, law = _coulomb_other(coulomb_return, rng, slip=False)
    compare(f"t_T in stick ({law})", t_T, want, at, rule="t_T = t_bar + c_T dg_T in stick")
    compare(f"lambda in stick ({law})", lam, 0.0, at)


def coulomb_slip_other(coulomb_return, rng):
    for _ in range(3):
        (t_T, lam), (want_t, want_l), at, law = _coulomb_other(coulomb_return, rng, slip=True)
        compare(f"t_T in slip ({law})", t_T, want_t, at)
        compare(f"lambda in slip ({law})", lam, want_l, at)


def moduli_other(slip_moduli, rng):
    from contactfem.laws import ParabolicSlip, PowerLaw

    law = ParabolicSlip(
        c_T=draw(rng, 5.0, 50.0), alpha=draw(rng, 0.1, 0.5), beta=draw(rng, 0.05, 0.3), n=draw(rng, 0.4, 0.9)
    )
    normal = PowerLaw(c_N=draw(rng, 20.0, 200.0), m=draw(rng, 1.0, 2.5))
    g_N = -draw(rng, 0.05, 0.3)
    p = float(-normal.traction(np.array([g_N]))[0][0])
    Y = float(law.slip_bound(np.array([p]), np.array([0.0]))[0][0])
    t_bar = draw(rng, -0.5, 0.5) * Y
    dg = float(f"{rng.choice([-1.0, 1.0]) * draw(rng, 2.0, 4.0) * Y / law.c_T:.3g}")  # a slip step
    c_T_s, c_N_s, want_T, want_N, at = _moduli(slip_moduli, (law, normal, t_bar, dg, g_N))
    compare(f"c_T^s (parabolic law, c_T = {law.c_T:g})", c_T_s, want_T, at)
    compare(f"c_N^s (parabolic law, normal law c_N = {normal.c_N:g}, m = {normal.m:g})", c_N_s, want_N, at)


HIDDEN = {
    "coulomb_stick": [coulomb_stick_other],
    "coulomb_slip": [coulomb_slip_other],
    "moduli_c_T": [moduli_other],
    "moduli_c_N": [moduli_other],
}
