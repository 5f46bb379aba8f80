"""The checks of lecture 08: the cork."""

import math

import numpy as np

from .answers import call, compare, parts
from .exercise import exercise

LECTURE = "08_cork"


def _gas(gas_pressure, du, p0=0.8, V0=9424.778, area=314.159, travel=24.0):
    return np.asarray(call(gas_pressure, "gas_pressure", p0, V0, area, du, travel), dtype=float)


def gas_at_rest(gas_pressure):
    got = _gas(gas_pressure, np.array([0.0]))
    compare("pressure before the cork moves", got, np.array([0.8]), {"du": 0.0}, rule="p = p0 at du = 0")


def gas_boyle(gas_pressure):
    du = np.array([1.0, 5.0, 12.0, 23.9])
    got = _gas(gas_pressure, du)
    want = 0.8 * 9424.778 / (9424.778 + 314.159 * du)
    if got.shape == want.shape and np.allclose(got, 0.8 * (9424.778 + 314.159 * du) / 9424.778):
        raise AssertionError(
            "your pressure rises as the cork moves out: the gas expands, V grows and p falls, p = p0 V0 / V (Boyle)"
        )
    compare(
        "gas pressure (Boyle, p0 = 0.8 MPa)",
        got,
        want,
        {"du": du},
        rule="p = p0 V0 / (V0 + area du): the volume grows by the swept area times the travel",
    )


def gas_release(gas_pressure):
    du = np.array([23.0, 24.0, 30.0])
    got = _gas(gas_pressure, du)
    want = np.array([0.8 * 9424.778 / (9424.778 + 314.159 * 23.0), 0.0, 0.0])
    compare(
        "gas pressure at and past the mouth",
        got,
        want,
        {"du": du},
        rule="once the bottom has travelled `travel` (the length in the neck) the gas escapes: p = 0",
    )


def _hardening_return(hardening_return, t_bar, dg, p, q_bar, c_T=10.0, mu0=0.1, h=0.01):
    out = call(hardening_return, "hardening_return", t_bar, dg, p, q_bar, c_T, mu0, h)
    t_T, lam, q = parts(out, 3, "hardening_return", "t_T, lambda and q")
    try:
        return float(t_T), float(lam), float(q)
    except (TypeError, ValueError):
        raise AssertionError(
            f"hardening_return should return three numbers (t_T, lambda, q), got {out!r:.80}"
        ) from None


def _hardening_ref(t_bar, dg, p, q_bar, c_T=10.0, mu0=0.1, h=0.01):
    from ....laws import SlipHardening
    from ....laws.return_map import return_map

    fr = return_map(
        SlipHardening(c_T=c_T, mu=mu0, h=h),
        np.array([-p]),
        np.array([0.0]),
        np.array([dg]),
        np.array([t_bar]),
        np.array([q_bar]),
    )
    return float(fr.t_T[0]), float(fr.lam[0]), float(fr.q[0])


HARDENING_SLIP = ((0.1, 0.05, 2.0, 0.3), (-0.2, -0.08, 3.0, 1.0), (0.15, -0.1, 1.0, 0.0), (0.0, 0.2, 4.0, 5.0))


def hardening_stick(hardening_return):
    for case in ((0.1, 0.005, 2.0, 0.3), (-0.05, 0.002, 3.0, 0.0)):
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        compare("t_T in stick", t_T, want[0], at, rule="in stick t_T = t_bar + c_T dg_T (eq 42)")
        compare("lambda in stick", lam, 0.0, at)
        compare("q in stick", q, case[3], at, rule="no slip, no change of the accumulated slip")


def hardening_slip(hardening_return):
    for case in HARDENING_SLIP:
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        t_tr = case[0] + 10.0 * case[1]
        soft = (abs(t_tr) - (0.1 + 0.01 * case[3]) * case[2]) / 10.0
        if math.isclose(lam, soft, rel_tol=1e-8) and not math.isclose(lam, want[1], rel_tol=1e-8):
            raise AssertionError(
                f"your lambda {lam:.6g} at {', '.join(f'{k} = {v:g}' for k, v in at.items())} is "
                f"the one without hardening in the consistency condition; the bound grows with the "
                f"slip of the step itself: |t_tr| - c_T lambda - (mu0 + h (q_bar + lambda)) p = 0, "
                f"lambda = {want[1]:.6g}"
            )
        compare("t_T in slip", t_T, want[0], at, rule="t_T = sign(t_tr) (mu0 + h q) p on the slip surface")


def hardening_lambda_q(hardening_return):
    for case in HARDENING_SLIP:
        t_T, lam, q = _hardening_return(hardening_return, *case)
        want = _hardening_ref(*case)
        at = dict(zip(("t_bar", "dg_T", "p", "q_bar"), case))
        compare("lambda in slip", lam, want[1], at, rule="lambda = (|t_tr| - (mu0 + h q_bar) p) / (c_T + h p)")
        compare("q after the step", q, want[2], at, rule="q = q_bar + lambda")


EXERCISES = [
    exercise(
        "ex08_gas_pressure",
        LECTURE,
        "easy",
        True,
        "the explicit gas coupling: Boyle's law from the converged travel, and the release at the mouth",
        (gas_at_rest, 1),
        (gas_boyle, 2),
        (gas_release, 1),
    ),
    exercise(
        "ex08_hardening_return",
        LECTURE,
        "medium",
        True,
        "the return map of the slip-hardening Coulomb law (closed form of the local Newton)",
        (hardening_stick, 1),
        (hardening_slip, 2),
        (hardening_lambda_q, 2),
    ),
]


LIBRARY = {
    "ex08_gas_pressure": ("contactfem.bodies.loads:GasPressure",),
    "ex08_hardening_return": ("contactfem.laws.return_map:return_map", "contactfem.laws.friction:SlipHardening"),
}
