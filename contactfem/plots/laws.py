"""Figures 1-4 of the paper: the interface laws of Sec. 2, drawn from the package's laws.

The small formula functions below are the parts of Sec. 2 that only the figures
need (eqs 3, 6-9, 13); the laws used in computations live in contactfem.laws.

    fig01_true_contact_area            Fig 1, eq (3)
    fig02_force_vs_microdisplacement   Fig 2, eq (5) then sliding (return mapping, eqs 40-44)
    fig03_shear_vs_normal              Fig 3, eqs (6)-(11)
    fig04_parabolic_slip_surface       Fig 4, eq (10) with the return-mapping geometry (eqs 13, 14)
"""

from pathlib import Path

import numpy as np

from ..laws.return_map import return_map
from ..laws import Coulomb, ParabolicSlip, SlipHardening
from ..laws.validation import require
from . import default_outdir, figure, pyplot
from .data import save_figure


def _save(fig, outdir, preset, stem, data, parameters):
    return save_figure(fig, Path(outdir or default_outdir(preset)) / f"{stem}.png", data, parameters)


# -- formulas of Sec. 2 used only by the figures ------------------------------


def true_contact_area_ratio(p_over_H, n):
    """Eq (3) (Tabor, Kragelski): A_r / A = (|t_N| / (A H))^n, with p_over_H = |t_N| / (A H)
    the nominal pressure over the hardness H; n in [2/3, 1] (2/3: elastic spherical
    asperities, constant number of contact spots; 1: plastic asperities, Meyer's law)."""
    require("n", n, 2.0 / 3.0 - 1e-12, 1.0)
    p = np.asarray(p_over_H, dtype=float)
    if np.any(p < 0) or not np.all(np.isfinite(p)):
        raise ValueError("parameter p_over_H must be finite and >= 0")
    return p**n


def junction_shear_strength(p_r, tau_0, beta):
    """Eq (6): shear strength of the real contact spots tau = tau_0 + beta p_r at the
    real pressure p_r = |t_N| / A_r (so that |t_T| = tau_0 A_r + beta |t_N|)."""
    require("tau_0", tau_0, 0.0)
    require("beta", beta, 0.0)
    return tau_0 + beta * np.asarray(p_r, dtype=float)


def friction_coefficient(p_r, tau_0, beta):
    """Eq (7): mu = |t_T| / |t_N| = tau_0 / p_r + beta; it falls as the real pressure
    p_r rises and is constant once p_r reaches the hardness H."""
    p_r = np.asarray(p_r, dtype=float)
    if np.any(p_r <= 0):
        raise ValueError("parameter p_r must be > 0 (the real contact pressure)")
    return tau_0 / p_r + beta


def parabolic_alpha(tau_0, H, n, A=1.0):
    """Eqs (8)-(10): putting eq (3) into eq (6) gives |t_T| = alpha |t_N|^n + beta |t_N|
    with alpha = A tau_0 / (A H)^n: the coefficient of the parabolic slip surface."""
    require("tau_0", tau_0, 0.0)
    require("H", H, 0.0, low_open=True)
    require("n", n, 0.0, 1.0, low_open=True)
    require("A", A, 0.0, low_open=True)
    return A * tau_0 / (A * H) ** n


def drive_slip_history(law, p, g_T):
    """Tangential traction along a prescribed history of the tangential displacement
    g_T (a 1D array, starting from 0) at constant pressure p: one return mapping
    (eqs 40-44) per increment, committing t_T and the accumulated slip q after each.
    Returns (t_T, state, q), arrays of len(g_T)."""
    g_T = np.asarray(g_T, dtype=float)
    t_N = np.array([-float(p)])
    t_T, q = np.zeros(1), np.zeros(1)
    out_t, out_s, out_q = [0.0], [1], [0.0]
    for dg in np.diff(g_T):
        fr = return_map(law, t_N, np.zeros(1), np.array([dg]), t_T, q)
        t_T, q = fr.t_T, fr.q
        out_t.append(float(t_T[0]))
        out_s.append(int(fr.state[0]))
        out_q.append(float(q[0]))
    return np.array(out_t), np.array(out_s), np.array(out_q)


def associated_direction(law, t_N, t_T):
    """Eq (13): the associated slip direction df/dt = (df/dt_N, df/dt_T), unit length,
    of f = ||t_T|| - Y(|t_N|). Since df/dt_N = dY/dp > 0 it has a normal part: the
    associated rule would open the gap (uplift) while slipping."""
    p = -np.asarray(t_N, dtype=float)
    _, Y_p, _ = law.slip_bound(p, np.zeros_like(p))
    d = np.stack([Y_p, np.sign(t_T) * np.ones_like(p)], axis=-1)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


# -- the figures ----------------------------------------------------------------


@figure("fig01_true_contact_area", "Fig 1")
def fig01_true_contact_area(preset="fast", outdir=None):
    """Fig 1: true contact area ratio vs dimensionless pressure, eq (3), log-log."""
    plt = pyplot()
    p = np.geomspace(1e-4, 1.0, 200)
    fig, ax = plt.subplots(figsize=(5.0, 4.0))
    ns = (
        (2 / 3, "n = 2/3 (elastic, Tabor)"),
        (0.8, "n = 0.8"),
        (0.9, "n = 0.9 (Kragelski, elastic)"),
        (1.0, "n = 1 (plastic, Meyer)"),
    )
    data = dict(p_over_H=p, area_ratio={label: true_contact_area_ratio(p, n) for n, label in ns})
    for n, label in ns:
        ax.loglog(p, data["area_ratio"][label], label=label)
    ax.set_xlabel(r"dimensionless pressure $|t_N| / (A H)$")
    ax.set_ylabel(r"true contact area ratio $A_r / A$")
    ax.set_title(r"Fig 1: $A_r/A = (|t_N|/(AH))^n$, eq (3)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, outdir, preset, "fig01_true_contact_area", data, dict(n=[n for n, _ in ns]))


def fig02_history(n_up=60, n_back=60):
    """The slip history of Fig 2: push to g_T = 3 g_stick, reverse to -1 g_stick (in units
    of the stick length g_stick = mu p / c_T)."""
    return np.concatenate([np.linspace(0.0, 3.0, n_up), np.linspace(3.0, -1.0, n_back)[1:]])


@figure("fig02_force_vs_microdisplacement", "Fig 2")
def fig02_force_vs_microdisplacement(preset="fast", outdir=None):
    """Fig 2: tangential force vs micro-displacement: the stick law t_T = c_T g_T (eq 5,
    zone 1) up to the slip bound, then sliding (zone 2), and the elastic unloading on
    reversal. Computed by the return mapping over a ramped displacement history."""
    plt = pyplot()
    c_T, mu, p = 30.0, 0.3, 1.0
    g_stick = mu * p / c_T
    g = fig02_history() * g_stick
    fig, ax = plt.subplots(figsize=(5.5, 4.0))
    data = dict(g_T_over_g_stick=g / g_stick, t_T_over_mu_p={})
    for law, label in (
        (Coulomb(c_T=c_T, mu=mu), "Coulomb, eq (11)"),
        (SlipHardening(c_T=c_T, mu=mu, h=5.0), "slip hardening, h = 5"),
        (SlipHardening(c_T=c_T, mu=mu, h=-5.0), "slip softening, h = -5"),
    ):
        t_T, state, _ = drive_slip_history(law, p, g)
        data["t_T_over_mu_p"][label] = t_T / (mu * p)
        ax.plot(g / g_stick, t_T / (mu * p), label=label)
    ax.axhline(1.0, color="0.6", lw=0.8, ls=":")
    ax.axhline(-1.0, color="0.6", lw=0.8, ls=":")
    ax.annotate(
        "zone 1: stick\n$t_T = c_T\\, g_T$ (eq 5)",
        xy=(0.5, 0.5),
        xytext=(0.9, 0.15),
        arrowprops=dict(arrowstyle="->"),
        fontsize=8,
    )
    ax.annotate(
        "zone 2: sliding\n$|t_T| = Y(|t_N|, q)$",
        xy=(2.2, 1.0),
        xytext=(1.6, 0.45),
        arrowprops=dict(arrowstyle="->"),
        fontsize=8,
    )
    ax.set_xlabel(r"micro-displacement $g_T / (\mu |t_N| / c_T)$")
    ax.set_ylabel(r"tangential force $t_T / (\mu |t_N|)$")
    ax.set_title("Fig 2: tangential force vs micro-displacement")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    return _save(
        fig, outdir, preset, "fig02_force_vs_microdisplacement", data, dict(c_T=c_T, mu=mu, p=p, h=[5.0, -5.0])
    )


@figure("fig03_shear_vs_normal", "Fig 3")
def fig03_shear_vs_normal(preset="fast", outdir=None):
    """Fig 3: shear vs normal stress. Left: the junction shear strength tau = tau_0 + beta p_r
    (eq 6) and the friction coefficient mu = tau_0/p_r + beta (eq 7). Right: the nominal
    slip bound |t_T| = alpha |t_N|^n + beta |t_N| (eqs 8-10) against Coulomb's line (eq 11)."""
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11.0, 4.2), layout="constrained")
    H, tau_0, beta = 1.0, 0.1, 0.2
    p_r = np.linspace(0.02, 1.0, 200) * H
    data = dict(
        p_r_over_H=p_r / H,
        tau_over_H=junction_shear_strength(p_r, tau_0, beta) / H,
        mu=friction_coefficient(p_r, tau_0, beta),
    )
    a1.plot(p_r / H, junction_shear_strength(p_r, tau_0, beta) / H, label=r"$\tau = \tau_0 + \beta p_r$ (eq 6)")
    a1.set_xlabel(r"real pressure $p_r / H$")
    a1.set_ylabel(r"shear strength $\tau / H$")
    b = a1.twinx()
    b.plot(p_r / H, friction_coefficient(p_r, tau_0, beta), "C1--", label=r"$\mu = \tau_0/p_r + \beta$ (eq 7)")
    b.set_ylim(0, 1.5)
    b.set_ylabel(r"friction coefficient $\mu$")
    a1.legend(loc="upper left", fontsize=8)
    b.legend(loc="upper right", fontsize=8)
    a1.set_title(r"junctions: $\tau_0 = 0.1 H$, $\beta = 0.2$")
    p = np.linspace(0.0, 4.0, 300)
    alpha, beta2 = 0.2, 0.3
    for n in (1.0, 0.8, 0.5):
        Y, _, _ = ParabolicSlip(c_T=1.0, alpha=alpha, beta=beta2, n=n).slip_bound(p, 0 * p)
        data.setdefault("slip_bound", {})[f"n = {n:g}"] = Y
        a2.plot(p, Y, label=f"n = {n:g}" + (" (Coulomb, eq 11)" if n == 1 else " (eq 10)"))
    a2.set_xlabel(r"normal stress $|t_N|$")
    a2.set_ylabel(r"shear stress $|t_T|$ at slip")
    a2.set_title(rf"$|t_T| = \alpha |t_N|^n + \beta |t_N|$, $\alpha = {alpha}$, $\beta = {beta2}$")
    a2.grid(True, alpha=0.3)
    a2.legend(fontsize=8)
    fig.suptitle("Fig 3: shear vs normal stress")
    data["t_N_abs"] = p
    return _save(
        fig,
        outdir,
        preset,
        "fig03_shear_vs_normal",
        data,
        dict(H=H, tau_0=tau_0, beta_junction=beta, alpha=alpha, beta=beta2, n=[1.0, 0.8, 0.5]),
    )


def fig04_geometry(law, t_N, t_T_trial):
    """The return-mapping geometry drawn in Fig 4: the non-associated return (eq 14) of the
    trial point along t_T (the package's return_map), and the closest point of the slip
    surface with the associated direction there (eq 13). Returns a dict of points."""
    fr = return_map(law, np.array([t_N]), np.zeros(1), np.array([t_T_trial / law.c_T]), np.zeros(1), np.zeros(1))
    p = np.linspace(1e-9, 3.0 * max(-t_N, 1e-9), 4000)
    Y, _, _ = law.slip_bound(p, 0 * p)
    d2 = (-p - t_N) ** 2 + (np.sign(t_T_trial) * Y - t_T_trial) ** 2
    k = int(np.argmin(d2))
    closest = np.array([-p[k], np.sign(t_T_trial) * Y[k]])
    return dict(
        trial=np.array([t_N, t_T_trial]),
        nonassociated=np.array([t_N, fr.t_T[0]]),
        state=int(fr.state[0]),
        closest=closest,
        associated=associated_direction(law, np.array([closest[0]]), np.array([closest[1]]))[0],
    )


@figure("fig04_parabolic_slip_surface", "Fig 4")
def fig04_parabolic_slip_surface(preset="fast", outdir=None):
    """Fig 4: the parabolic slip surface f(t_N, t_T) = 0 (eq 10) in the (t_N, t_T) plane with
    Coulomb's cone (eq 11), a trial state outside it, its non-associated return along t_T
    (eq 14, what the package does) and the associated direction (eq 13) that would lift off."""
    plt = pyplot()
    law = ParabolicSlip(c_T=30.0, alpha=0.2, beta=0.3, n=0.5)
    coul = Coulomb(c_T=30.0, mu=0.5)
    p = np.linspace(0.0, 4.0, 400)
    Y, _, _ = law.slip_bound(p, 0 * p)
    Yc, _, _ = coul.slip_bound(p, 0 * p)
    fig, ax = plt.subplots(figsize=(6.0, 4.8))
    ax.fill_between(-p, -Y, Y, color="C0", alpha=0.12, label="admissible: $f \\leq 0$ (stick)")
    ax.plot(-p, Y, "C0", label=r"$f = -\alpha|t_N|^n - \beta|t_N| + |t_T| = 0$, n = 0.5 (eq 10)")
    ax.plot(-p, -Y, "C0")
    ax.plot(-p, Yc, "C7--", lw=1, label=r"Coulomb $\mu = \alpha + \beta$ (eq 11)")
    ax.plot(-p, -Yc, "C7--", lw=1)
    g = fig04_geometry(law, t_N=-2.0, t_T_trial=1.9)
    tr, na, cl, d = g["trial"], g["nonassociated"], g["closest"], g["associated"]
    ax.plot(*tr, "ko")
    ax.annotate("trial $t_T^{tr}$ (eq 42)", tr, xytext=(tr[0] + 0.12, tr[1] + 0.1), fontsize=8)
    ax.annotate("", xy=na, xytext=tr, arrowprops=dict(arrowstyle="->", color="C3", lw=2))
    ax.plot(*na, "o", color="C3")
    ax.annotate(
        "non-associated return\nalong $t_T$ (eq 14): $\\Delta g_N^s = 0$",
        na,
        xytext=(na[0] + 0.12, na[1] + 0.35),
        fontsize=8,
        color="C3",
    )
    ax.plot([tr[0], cl[0]], [tr[1], cl[1]], ":", color="C2")
    ax.annotate("", xy=cl + 0.8 * d, xytext=cl, arrowprops=dict(arrowstyle="->", color="C2", lw=2))
    ax.plot(*cl, "o", color="C2")
    ax.annotate(
        "associated $\\partial f/\\partial t$ (eq 13):\nnormal part, uplift",
        cl + 0.8 * d,
        xytext=(-3.9, 2.15),
        fontsize=8,
        color="C2",
    )
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlim(-4.0, 0.6)
    ax.set_ylim(-2.0, 2.6)
    ax.set_xlabel(r"normal traction $t_N$ (compression < 0)")
    ax.set_ylabel(r"tangential traction $t_T$")
    ax.set_title(rf"Fig 4: parabolic slip surface, $\alpha = {law.alpha:g}$, $\beta = {law.beta:g}$")
    ax.legend(fontsize=7, loc="lower left")
    return _save(
        fig,
        outdir,
        preset,
        "fig04_parabolic_slip_surface",
        dict(g, t_N_abs=p, slip_bound=Y, coulomb=Yc),
        dict(c_T=law.c_T, alpha=law.alpha, beta=law.beta, n=law.n, mu_coulomb=coul.mu, t_N=-2.0, t_T_trial=1.9),
    )
