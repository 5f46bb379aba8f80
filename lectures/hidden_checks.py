"""The hidden checks of the course's exercises: instructor material, not part of the installed
package and not in the student notebooks.

`contactfem course grade` reads this file (from the folder given by --autograders, else from
the checkout's lectures/) and runs it in its own process, never in the submission's. A part of
an exercise scores its points when its public check (contactfem.lab.course.checks) and every
hidden check listed for it in HIDDEN pass: the hidden ones ask the same question at other
parameters and points, so an answer fitted to the public checks' values does not pass them.

HIDDEN maps the name of a public part to its hidden checks; each takes the same student
answers (by name) as the part it belongs to, and raises AssertionError with a hint.
"""

import numpy as np

from contactfem.lab.course.checks import (
    _band,
    _library_band,
    _tresca,
    call,
    compare,
    parts,
    tolerance_budget_at,
    tolerance_error_at,
    tolerance_indicators_at,
)


# -- lecture 01 ---------------------------------------------------------------------------------


def _power(power_law, g, c_N, m):
    return parts(call(power_law, "power_law", g, c_N, m), 2, "power_law", "t_N and dt_N/dg_N")


def power_law_open_far(power_law):
    g = np.array([1e-9, 3.0, 250.0])
    t_N, dt_N = _power(power_law, g, 37.0, 1.5)
    compare("t_N for an open gap", t_N, np.zeros(3), {"g_N": g}, rule="t_N = 0 where g_N >= 0")
    compare("dt_N/dg_N for an open gap", dt_N, np.zeros(3), {"g_N": g})


def power_law_traction_other(power_law):
    g = np.array([-0.003, -0.07, -0.9])
    for c_N, m in ((37.0, 1.5), (2.0e4, 3.0)):
        t_N, _ = _power(power_law, g, c_N, m)
        compare(
            f"t_N (c_N = {c_N:g}, m = {m:g})", t_N, -c_N * (-g) ** m, {"g_N": g}, rule="t_N = -c_N (-g_N)^m in contact"
        )


def power_law_derivative_other(power_law):
    g = np.array([-0.003, -0.07, -0.9])
    for c_N, m in ((37.0, 1.5), (2.0e4, 3.0)):
        _, dt_N = _power(power_law, g, c_N, m)
        compare(
            f"dt_N/dg_N (c_N = {c_N:g}, m = {m:g})",
            dt_N,
            c_N * m * (-g) ** (m - 1.0),
            {"g_N": g},
            rule="dt_N/dg_N = c_N m (-g_N)^(m-1) in contact",
        )


def _tresca_other(Tresca):
    law = _tresca(Tresca, c_T=7.0, tau_y=1.3)
    p = np.array([0.01, 2.0, 900.0, 0.01, 2.0, 900.0])
    q = np.array([0.0, 0.0, 0.0, 5.0, 5.0, 5.0])
    out = call(law.slip_bound, "Tresca(c_T=7.0, tau_y=1.3).slip_bound", p, q)
    return p, q, parts(out, 3, "slip_bound", "Y, dY/dp, dY/dq")


def tresca_bound_other(Tresca):
    p, q, (Y, _, _) = _tresca_other(Tresca)
    compare("slip bound Y (tau_y = 1.3)", Y, np.full(p.shape, 1.3), {"p": p, "q": q}, rule="Y = tau_y")


def tresca_derivatives_other(Tresca):
    p, q, (_, Y_p, Y_q) = _tresca_other(Tresca)
    compare("dY/dp (tau_y = 1.3)", Y_p, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on p")
    compare("dY/dq (tau_y = 1.3)", Y_q, np.zeros(p.shape), {"p": p, "q": q}, rule="Y does not depend on q")


def tresca_fields_other(Tresca):
    law = _tresca(Tresca, c_T=7.0, tau_y=1.3)
    if getattr(law, "c_T", None) != 7.0 or getattr(law, "tau_y", None) != 1.3:
        raise AssertionError("Tresca(c_T=7.0, tau_y=1.3) should keep the fields it is given")


# -- lecture 02 ---------------------------------------------------------------------------------


def circle_gap_value_other(circle_gap):
    x_s = np.array([[-2.0, 1.4], [-1.0, 0.5], [-2.3, 0.1], [0.5, -3.0]])
    c, R = np.array([-2.0, 0.5]), 0.7
    g_N, n = parts(call(circle_gap, "circle_gap", x_s, c, R), 2, "circle_gap", "g_N and n")
    d = x_s - c
    r = np.linalg.norm(d, axis=1)
    at = {"x_s": [f"({x:g}, {y:g})" for x, y in x_s]}
    compare("g_N (centre (-2, 0.5), R = 0.7)", g_N, r - R, at, rule="g_N = |x_s - centre| - R")
    compare(
        "n (centre (-2, 0.5), R = 0.7)",
        np.asarray(n, float),
        d / r[:, None],
        {"x_s": np.repeat(np.array(at["x_s"])[:, None], 2, axis=1)},
        rule="n = (x_s - centre)/|x_s - centre|",
    )


# -- lecture 12 ---------------------------------------------------------------------------------


def _cn_other(C_N):
    from contactfem.contact.complementarity import normal_complementarity

    t_N = np.array([-7.0, -0.1, 0.0, -0.4, -2.5])
    g_N = np.array([-0.2, 0.05, 1.0, -0.001, 0.4])
    C, dt, dg = (
        np.asarray(x, float) for x in parts(call(C_N, "C_N", t_N, g_N, 3.0), 3, "C_N", "C_N, dC_N/dt_N and dC_N/dg_N")
    )
    return C, dt, dg, normal_complementarity(t_N, g_N, 3.0), {"t_N": t_N, "g_N": g_N}


def cn_values_other(C_N):
    C, _, _, want, at = _cn_other(C_N)
    compare("C_N (c_N = 3)", C, want[0], at, rule="C_N = p - max(0, p - c_N g_N) with p = -t_N")


def cn_derivatives_other(C_N):
    _, dt, dg, want, at = _cn_other(C_N)
    compare("dC_N/dt_N (c_N = 3)", dt, want[1], at)
    compare("dC_N/dg_N (c_N = 3)", dg, want[2], at)


# -- lecture 02: the tangent at another segment -------------------------------------------------


def normal_tangent_fd_other(normal_tangent):
    from contactfem.lab.course.checks import LABELS6, _residual_fd

    case = (np.array([-0.2, 0.45]), np.array([-1.0, 0.3]), np.array([0.8, 0.6]), 7.0)
    K = np.asarray(call(normal_tangent, "normal_tangent", *case), dtype=float)
    fd = _residual_fd(*case)
    if K.shape != (6, 6):
        raise AssertionError(f"normal_tangent should return a 6x6 matrix, it returned shape {K.shape}")
    if np.abs(K - fd).max() > 1e-6 * np.abs(fd).max():
        i, j = np.unravel_index(np.argmax(np.abs(K - fd)), K.shape)
        raise AssertionError(
            f"at x_s = (-0.2, 0.45), x_1 = (-1, 0.3), x_2 = (0.8, 0.6), c_N = 7 your K_N entry "
            f"({LABELS6[i]}, {LABELS6[j]}) is {K[i, j]:.6g}, finite differences give {fd[i, j]:.6g}"
        )


# -- lecture 03 --------------------------------------------------------------------------------


def _coulomb_other(coulomb_return, t_bar, dg, p):
    from contactfem.lab.course.checks import _coulomb_ref, _coulomb_student

    got = _coulomb_student(coulomb_return, t_bar, dg, p, c_T=12.0, mu=0.45)
    return got, _coulomb_ref(t_bar, dg, p, 12.0, 0.45), {"t_bar": t_bar, "dg_T": dg, "p": p}


def coulomb_stick_other(coulomb_return):
    (t_T, lam), (want, _), at = _coulomb_other(coulomb_return, 0.3, 0.01, 1.5)
    compare("t_T in stick (c_T = 12, mu = 0.45)", t_T, want, at, rule="t_T = t_bar + c_T dg_T in stick")
    compare("lambda in stick (c_T = 12, mu = 0.45)", lam, 0.0, at)


def coulomb_slip_other(coulomb_return):
    for case in ((0.5, 0.2, 1.5), (-0.6, -0.3, 3.0), (0.6, -0.4, 1.5)):
        (t_T, lam), (want_t, want_l), at = _coulomb_other(coulomb_return, *case)
        compare("t_T in slip (c_T = 12, mu = 0.45)", t_T, want_t, at)
        compare("lambda in slip (c_T = 12, mu = 0.45)", lam, want_l, at)


def moduli_other(slip_moduli):
    from contactfem.lab.course.checks import _moduli
    from contactfem.laws import ParabolicSlip, PowerLaw

    case = (ParabolicSlip(c_T=12.0, alpha=0.4, beta=0.1, n=0.7), PowerLaw(c_N=80.0, m=2.0), -0.2, -0.1, -0.07)
    c_T_s, c_N_s, want_T, want_N, at = _moduli(slip_moduli, case)
    compare("c_T^s (parabolic law, c_T = 12)", c_T_s, want_T, at)
    compare("c_N^s (parabolic law, normal law c_N = 80, m = 2)", c_N_s, want_N, at)


# -- lecture 09 ----------------------------------------------------------------------------------


def observed_order_other(observed_order):
    h = np.array([0.3, 0.2, 0.1, 0.07, 0.04])
    e = -0.7 * h**3 * np.array([1.0, 0.9, 1.2, 1.05, 0.97])
    want = np.polyfit(np.log(h), np.log(np.abs(e)), 1)[0]
    compare(
        "observed order of e ~ -0.7 h^3 (noisy)",
        call(observed_order, "observed_order", h, e),
        want,
        {"h": "0.3 ... 0.04"},
        rtol=1e-8,
    )


def convergence_order_other(convergence_order):
    r = [0.9, 0.6]
    for _ in range(3):
        r.append(0.8 * r[-1] ** 3)
    r = np.array(r)
    want = np.log(r[-1] / r[-2]) / np.log(r[-2] / r[-3])
    compare(
        "convergence order of r_(k+1) = 0.8 r_k^3 (last three)",
        call(convergence_order, "convergence_order", r),
        want,
        {"r": "0.9, 0.6, ..."},
        rtol=1e-8,
    )


def tolerance_indicators_tight(settings_for):
    tolerance_indicators_at(settings_for, 0.01)


def tolerance_error_tight(settings_for):
    tolerance_error_at(settings_for, 0.01)


def tolerance_budget_tight(settings_for):
    tolerance_budget_at(settings_for, 0.01)


def band_other_levels(band_from_three):
    """Other monotone levels and ratios: the order, the extrapolation and the band as the library's."""
    for f, r, p_th in (((3.0, 2.9, 2.6), 2.0, 1.0), ((0.5, 0.51, 0.53), 1.7, 2.0), ((10.0, 10.4, 11.5), 3.0, 2.0)):
        p, f_ex, band = _band(band_from_three, f, r, p_th)
        want = _library_band(f, r, p_th)
        compare(
            f"observed order of {f}, r = {r:g}",
            p,
            want["observed_order"],
            {"f": ", ".join(f"{x:.6g}" for x in f)},
            rtol=1e-8,
        )
        compare(
            f"Richardson's value of {f}", f_ex, want["richardson"], {"f": ", ".join(f"{x:.6g}" for x in f)}, rtol=1e-8
        )
        compare(
            f"the band of {f}, p_th = {p_th:g}", band, want["band"], {"f": ", ".join(f"{x:.6g}" for x in f)}, rtol=1e-8
        )


# -- lecture 10 ----------------------------------------------------------------------------------


def hardening_other(LinearHardening):
    law = LinearHardening(c_T=5.0, mu_0=0.12, h=2.0)
    p = np.array([0.01, 3.0, 50.0, 0.01, 3.0, 50.0])
    q = np.array([0.0, 0.0, 0.0, 0.05, 1.0, 2.5])
    Y, Y_p, Y_q = parts(
        call(law.slip_bound, "LinearHardening(c_T=5.0, mu_0=0.12, h=2.0).slip_bound", p, q),
        3,
        "slip_bound",
        "Y, dY/dp, dY/dq",
    )
    at = {"p": p, "q": q}
    compare("Y (mu_0 = 0.12, h = 2)", Y, (0.12 + 2.0 * q) * p, at, rule="Y = (mu_0 + h q) p")
    compare("dY/dp (mu_0 = 0.12, h = 2)", Y_p, 0.12 + 2.0 * q + 0 * p, at)
    compare("dY/dq (mu_0 = 0.12, h = 2)", Y_q, 2.0 * p, at)


def quadratic_other(QuadraticNormal):
    law = QuadraticNormal(c_N=7.0)
    g = np.array([0.3, -0.002, -0.6, -2.0])
    t_N, dt_N = parts(call(law.traction, "QuadraticNormal(c_N=7.0).traction", g), 2, "traction", "t_N, dt_N/dg_N")
    compare("t_N (c_N = 7)", t_N, np.where(g < 0, -7.0 * g**2, 0.0), {"g_N": g})
    compare("dt_N/dg_N (c_N = 7)", dt_N, np.where(g < 0, -14.0 * g, 0.0), {"g_N": g})


def quadratic_energy_other(QuadraticNormal):
    law = QuadraticNormal(c_N=7.0)
    g = np.array([0.3, -0.002, -0.6, -2.0])
    E = np.asarray(call(law.energy, "QuadraticNormal(c_N=7.0).energy", g), dtype=float)
    compare(
        "energy (c_N = 7)",
        E,
        np.where(g < 0, 7.0 * (-g) ** 3 / 3.0, 0.0),
        {"g_N": g},
        rule="the energy whose derivative is t_N = -c_N g_N^2: c_N (-g_N)^3 / 3",
    )


# -- lecture 11 ----------------------------------------------------------------------------------


def uzawa_other(uzawa_1dof):
    from contactfem.lab.course.checks import _uzawa

    k, P, g0, c_N, tol = 50.0, 20.0, 0.2, 500.0, 1e-11
    u, lam, n = _uzawa(uzawa_1dof, k, P, g0, c_N, tol)
    at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
    compare("u (k = 50, P = 20, g0 = 0.2)", u, g0, at, rtol=1e-8, atol=1e-9)
    compare("lambda (k = 50, P = 20, g0 = 0.2)", lam, k * g0 - P, at, rtol=1e-6, atol=1e-8)


def secant_other(secant_traction):
    from contactfem.laws import PowerLaw

    law = PowerLaw(c_N=7.0, m=1.7)
    for g0, g1 in ((0.3, -0.2), (-0.5, -0.45), (-0.1, -0.9)):
        F = float(np.asarray(call(secant_traction, "secant_traction", law, g0, g1), dtype=float))
        want = float((law.energy(np.array([g1])) - law.energy(np.array([g0])))[0] / (g1 - g0))
        compare(
            "secant traction (c_N = 7, m = 1.7)",
            F,
            want,
            {"g0": g0, "g1": g1},
            rule="F (g1 - g0) = energy(g1) - energy(g0)",
        )


# -- lectures 04-08 (the closed forms) -----------------------------------------------------------------


def margin_other(slip_margin):
    from contactfem.laws import Coulomb

    law = Coulomb(c_T=50.0, mu=0.6)
    t_N = -np.array([3.0, 0.5, 12.0, 7.0])
    t_T = np.array([-1.0, 0.3, 7.2, -9.0])
    got = np.asarray(call(slip_margin, "slip_margin", t_N, t_T, law), dtype=float)
    compare("f = |t_T| - mu |t_N| (Coulomb, mu = 0.6)", got, np.abs(t_T) + 0.6 * t_N, {"t_N": t_N, "t_T": t_T})


def rolling_other(rolling_point):
    from contactfem.scenes.rings import rigid_ring_exact

    case = (120.0, 0.4, 981.0, 30.0, 400.0)
    got = parts(call(rolling_point, "rolling_point", *case), 3, "rolling_point", "t*, x*, v*")
    ref = rigid_ring_exact(*case)
    compare(
        "(t*, x*, v*) at v0 = 120, mu = 0.4, a = 30, k^2 = 400",
        np.array([float(np.asarray(x)) for x in got]),
        np.array([ref["t_star"], ref["x_star"], ref["v_star"]]),
        {"value": ["t*", "x*", "v*"]},
    )


def rebound_other(rebound):
    from contactfem.lab.course.checks import _rebound_case

    v, contact = _rebound_case(k_last=4, n=9)
    v[5:] = (-0.7, 2.4)
    out = parts(call(rebound, "rebound", v, contact), 3, "rebound", "v_x, v_y and the angle")
    got = np.array([float(np.asarray(x)) for x in out])
    want = np.array([-0.7, 2.4, np.degrees(np.arctan2(0.7, 2.4))])
    compare("(v_x, v_y, angle) leaving at (-0.7, 2.4)", got, want, {"value": ["v_x", "v_y", "angle"]})


def energy_other(interface_energy):
    from contactfem.lab.course.checks import _energy_ref, _interface

    g = np.array([-0.4, 0.1, -0.01])
    t_T = np.array([0.5, 0.0, -3.0])
    w = np.array([0.25, 1.0, 3.0])
    got = _interface(interface_energy, g, t_T, w, 9.0, 2.0, 4.0)
    compare(
        "interface energy (c_N = 9, m = 2, c_T = 4)",
        got,
        _energy_ref(g, t_T, w, 9.0, 2.0, 4.0),
        {"g_N": "-0.4, 0.1, -0.01"},
    )


def escape_other(escape_angle):
    p = np.array([0.02, 0.7, 25.0])
    got = np.asarray(call(escape_angle, "escape_angle", p, 0.5, 0.05, 0.6), dtype=float)
    compare(
        "escape angle (deg; alpha = 0.5, beta = 0.05, n = 0.6)",
        got,
        np.degrees(np.arctan(0.5 * p**-0.4 + 0.05)),
        {"p": p},
        rule="tan(phi) = alpha p^(n-1) + beta",
    )


def gas_other(gas_pressure):
    du = np.array([0.0, 2.0, 9.9, 10.0, 11.0])
    got = np.asarray(call(gas_pressure, "gas_pressure", 2.5, 1000.0, 50.0, du, 10.0), dtype=float)
    want = np.where(du < 10.0, 2.5 * 1000.0 / (1000.0 + 50.0 * du), 0.0)
    compare("gas pressure (p0 = 2.5, V0 = 1000, area = 50, travel = 10)", got, want, {"du": du})


def hardening_return_other(hardening_return):
    from contactfem.lab.course.checks import _hardening_ref, _hardening_return

    for case in ((0.5, 0.3, 1.2, 0.4), (-0.3, -0.5, 2.0, 2.0)):
        got = _hardening_return(hardening_return, *case, c_T=6.0, mu0=0.25, h=0.3)
        want = _hardening_ref(*case, c_T=6.0, mu0=0.25, h=0.3)
        compare(
            "(t_T, lambda, q) (c_T = 6, mu0 = 0.25, h = 0.3)",
            np.array(got),
            np.array(want),
            {"value": ["t_T", "lambda", "q"]},
        )


# -- lecture 12 -----------------------------------------------------------------------------------


def ct_other(C_T):
    from contactfem.lab.course.checks import _ct, _ct_ref

    t_T = np.array([0.2, 0.9, -1.5, 0.05, -0.3])
    dg = np.array([0.1, 0.01, -0.2, 0.0, 0.3])
    xi = np.array([-0.5, 4.0, 1.0, 2.0, 1.5])
    got, want = _ct(C_T, t_T, dg, xi, 6.0, 0.5), _ct_ref(t_T, dg, xi, 6.0, 0.5)
    at = {"t_T": t_T, "dg_T": dg, "xi": xi}
    for k, name in enumerate(("C_T", "dC_T/dt_T", "dC_T/d(dg_T)", "dC_T/dxi")):
        compare(f"{name} (Coulomb mu = 0.5, c_T = 6)", got[k], want[k], at)


def ssn_other(semismooth_1dof):
    from contactfem.lab.course.checks import _ssn

    k, P, g0, c_N = 40.0, 30.0, 0.25, 300.0
    u, p, n = _ssn(semismooth_1dof, k, P, g0, c_N)
    at = {"k": k, "P": P, "g0": g0, "c_N": c_N}
    compare("u (k = 40, P = 30, g0 = 0.25)", u, g0, at)
    compare("p (k = 40, P = 30, g0 = 0.25)", p, P - k * g0, at)


# -- the time loops (lectures 04 and 07): another number of steps ------------------------------------


def load_steps_two(load_steps):
    from contactfem.lab.course.checks import _load_steps, _load_steps_ref

    t, its, slip = _load_steps(load_steps, 2)
    want = _load_steps_ref(2)
    if t.size != 2:
        raise AssertionError(f"load_steps(stepper, 2) should give one entry per load step, 2, got {t.size}")
    compare(
        "the load in two steps: (t, solves, slipping nodes)",
        np.r_[t, its, slip],
        np.r_[want[0], want[1], want[2]],
        {"entry": ["t1", "t2", "solves1", "solves2", "slip1", "slip2"]},
        rule="Steps(1 / n, n_steps=n), rec.iterations, the SLIP states of each record",
    )


def _census_short(census):
    """The census of the funnel's first 12 steps (its schedule's step, fewer of them)."""
    from contactfem.lab.course.checks import _as_list, _counts, _scene_model, memo
    from contactfem.solver import Steps
    from contactfem.solver.march import march

    def stage():
        model, _ = _scene_model("funnel", {"variant": "frictional"})
        st = model.stage
        return st, Steps(st.schedule.dt, n_steps=12, t0=st.schedule.t0)

    def student():
        st, short = stage()
        return call(census, "census", st.stepper, short, st.u0, st.v0, timeout=120.0)

    def reference():
        st, short = stage()
        recs = list(march(st.stepper, short, st.t0, st.u0, st.v0))
        c = np.array([_counts(r) for r in recs], float)
        return np.array([r.t for r in recs]), c[:, 0], c[:, 1]

    got = _as_list(memo(("census_short", census), student), 3, "census", "times, contact and slip counts")
    return got, memo(("census_short_ref",), reference)


def census_short(census):
    (t, n_c, n_s), (w_t, w_c, w_s) = _census_short(census)
    if t.size != w_t.size:
        raise AssertionError(
            f"on a schedule of 12 steps your census has {t.size} entries, the run {w_t.size} "
            "records (the initial state included): loop over the schedule you are given"
        )
    at = {"record": np.arange(t.size)}
    compare("time of each record (12 steps)", t, w_t, at)
    compare("nodes in contact (12 steps)", n_c, w_c, at)
    compare("slipping nodes (12 steps)", n_s, w_s, at)


HIDDEN = {
    "power_law_open": [power_law_open_far],
    "power_law_traction": [power_law_traction_other],
    "power_law_derivative": [power_law_derivative_other],
    "tresca_fields": [tresca_fields_other],
    "tresca_bound": [tresca_bound_other],
    "tresca_derivatives": [tresca_derivatives_other],
    "circle_gap_value": [circle_gap_value_other],
    "cn_values": [cn_values_other],
    "cn_derivatives": [cn_derivatives_other],
    "normal_tangent_fd": [normal_tangent_fd_other],
    "coulomb_stick": [coulomb_stick_other],
    "coulomb_slip": [coulomb_slip_other],
    "moduli_c_T": [moduli_other],
    "moduli_c_N": [moduli_other],
    "observed_order_least_squares": [observed_order_other],
    "convergence_order_quadratic": [convergence_order_other],
    "tolerance_indicators": [tolerance_indicators_tight],
    "tolerance_error": [tolerance_error_tight],
    "tolerance_budget": [tolerance_budget_tight],
    "band_order": [band_other_levels],
    "band_richardson": [band_other_levels],
    "band_factor_of_safety": [band_other_levels],
    "hardening_bound": [hardening_other],
    "hardening_derivatives": [hardening_other],
    "quadratic_traction": [quadratic_other],
    "quadratic_energy": [quadratic_energy_other],
    "uzawa_multiplier": [uzawa_other],
    "secant_energy": [secant_other],
    "margin_coulomb": [margin_other],
    "rolling_time": [rolling_other],
    "rolling_position": [rolling_other],
    "rolling_speed": [rolling_other],
    "rebound_velocity": [rebound_other],
    "rebound_angle": [rebound_other],
    "energy_friction": [energy_other],
    "escape_values": [escape_other],
    "gas_boyle": [gas_other],
    "gas_release": [gas_other],
    "hardening_slip": [hardening_return_other],
    "hardening_lambda_q": [hardening_return_other],
    "ct_stick_slip": [ct_other],
    "ct_derivatives": [ct_other],
    "ssn_contact": [ssn_other],
    "load_steps_times": [load_steps_two],
    "load_steps_slipping": [load_steps_two],
    "census_times": [census_short],
    "census_contact": [census_short],
    "census_slip": [census_short],
}
