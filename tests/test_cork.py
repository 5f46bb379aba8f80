"""The champagne cork (paper Sec. 5.5): one fast run shared by the tests, the
paper preset (about half a minute), the static breakaway mechanism and its knife's edge,
the neck's kinematics against finite differences, Boyle's law, failures reported.

Where the tolerances come from. The paper prints "about 2500 N", "about 250 N",
"about 0.8 MPa" and "about 28 m/s": one or two significant digits, i.e. +-2 % to
+-20 %. Our press-fit force is FITTED (R_tip chosen to give ~2500 N), so agreement there
is by construction; the exit velocity sits on a knife's edge (the static breakaway
margin is +0.014 MPa of 0.8), so it is tested against the paper only with tolerances
argued below, and the mechanism (margin > 0) is asserted for both presets."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from contactfem.bodies.loads import swept_volume
from contactfem.scenes import run_scene
from contactfem.bodies.meshes import cork_mesh
from contactfem.contact.masters import bottle_neck as Neck
from contactfem.scenes import cork as cork_scene
from contactfem.scenes.cork import PAPER
from contactfem.solver import NewtonError
from conftest import assert_locate_matches_fd

PAPER_V = PAPER["exit_velocity_m_s"]  # 28 m/s


@pytest.fixture(scope="module")
def fast():
    return run_scene("cork", "fast")


@pytest.mark.slow
def test_fast_run_completes_and_the_cork_leaves(fast):
    # InvertedElementError (det F <= 0) would have ended the run as a NewtonError
    assert fast["exited"], "the cork did not leave the bottle in the fast preset"
    assert fast["min_element_area_ratio"] > 0.5, fast["min_element_area_ratio"]
    assert fast["newton_iterations_total"] > 0


@pytest.mark.slow
def test_penetration_stays_below_two_percent_of_the_radius(fast):
    # stated bound: |g_N| < 2 % of the neck radius, press fit and exit included
    assert fast["max_penetration_ratio"] < 0.02, fast["max_penetration_ratio"]


@pytest.mark.slow
def test_fast_preset_exit_velocity_is_near_the_paper(fast, paper):
    # paper "about 28 m/s" (two digits: +-2 %). The fast preset differs from the paper preset
    # only by its coarser steps around the exit (dt_fine 2e-5 instead of 5e-6 s, 1 mm of travel
    # per step instead of 0.5, fewer press-fit increments): a time-discretisation error, held
    # here to half the tolerance against the paper preset's run. Tolerance 15 %: that error at
    # most twice, plus the paper's rounding
    v, v_paper = fast["exit_velocity_m_s"], paper["exit_velocity_m_s"]
    assert abs(v - v_paper) / v_paper < 0.075, f"fast {v:.2f} m/s, paper preset {v_paper:.2f} m/s"
    assert abs(v - PAPER_V) / PAPER_V < 0.15, f"paper {PAPER_V} m/s, ours {v:.2f} m/s, tolerance 15 %"


@pytest.mark.slow
def test_press_fit_force_and_breakaway(fast):
    # paper: normal force "about 2500 N" (one to two digits: the scan prints no more). Ours is
    # fitted through R_tip, so this checks the calibration holds (2 %: the rounding of "2500"),
    # not a prediction; the JSON says so
    assert fast["press_fit_calibrated"] is True
    assert abs(fast["press_fit_normal_force_N"] - 2500) / 2500 < 0.02, fast["press_fit_normal_force_N"]
    assert fast["breakaway_pressure_MPa"] is not None and fast["breakaway_pressure_MPa"] <= 0.8 + 1e-9


@pytest.mark.slow
def test_fast_preset_leaves_by_static_breakaway(fast):
    # the mechanism of the paper preset (test below): the applied pressure exceeds the static
    # friction reserve mu N / (pi R^2), so the cork leaves; a coarser mesh would overestimate
    # the press fit and leave only by dynamic overshoot (margin < 0), a different mechanism
    assert fast["breakaway_margin_MPa"] > 0, fast["breakaway_margin_MPa"]
    assert fast["exited"]


@pytest.mark.slow
def test_the_knife_edge_more_friction_and_the_cork_stays_in():
    # mu = 0.105 instead of 0.1: the static breakaway rises above 0.8 MPa (margin < 0) and
    # the whole run confirms it: the cork does not leave
    r = run_scene("cork", "fast", {"mu": 0.105})
    assert r["breakaway_margin_MPa"] < 0, r["breakaway_margin_MPa"]
    assert not r["exited"] and r["exit_velocity_m_s"] is None


@pytest.mark.slow
def test_press_fit_only_gives_the_same_margin(fast):
    from contactfem.scenes.cork import SCENE, press_fit_only

    m = press_fit_only(SCENE.resolve("fast"))
    assert m["breakaway_margin_MPa"] == pytest.approx(fast["breakaway_margin_MPa"], rel=1e-9)
    assert not press_fit_only(SCENE.resolve("fast", {"R_tip": 10.05}))["press_fit_calibrated"]


@pytest.mark.slow
def test_boyle_pressure_is_explicit_in_the_volume(fast):
    # p_k = p0 V0 / V_(k-1) on every Boyle step (pressure from the last converged state)
    P = fast["parameters"]
    t, p, V = (np.asarray(fast[k]) for k in ("time_ms", "pressure_MPa", "gas_volume_mm3"))
    V0 = np.pi * P["R_neck"] ** 2 * P["gas_column"]
    p0 = P["p_step"] * P["n_ramp"]
    t_ramp = P["t_ramp"] * 1e3
    boyle = np.flatnonzero((t > t_ramp + 1e-9) & (p > 0))
    assert len(boyle) > 5
    assert np.allclose(p[boyle], p0 * V0 / V[boyle - 1], rtol=1e-12)
    # just before the exit: Boyle at 24 mm of travel, p0 * 30 / 54 = 0.444 MPa. Measured 0.005
    # below on both presets (the volume is taken one step late, explicit coupling, and the
    # bottom face is not flat). 0.03 MPa is the pressure change over ~4 mm of travel
    # (p0 V0 / V^2 dV = 0.8 * 30 / 54^2 = 0.008 MPa per mm): the exit located within 4 mm
    assert abs(fast["pressure_before_exit_MPa"] - 0.8 * 30 / 54) < 0.03, fast["pressure_before_exit_MPa"]
    assert p[-1] == 0.0  # the gas escaped


def _near_the_mouth(gap, speed):
    """The fast cork's model, moved bodily along its axis so that its bottom corner lies ``gap`` below the
    mouth and flies at ``speed`` (mm/s): a record of its pop after the gas's ramp (Boyle's pressure)."""
    scene = cork_scene.SCENE
    P = scene.resolve("fast")
    parts = scene.build(P).parts
    cork, gas = parts["cork"], parts["gas"]
    u, v = np.zeros(cork.ndof), np.zeros(cork.ndof)
    u[cork.xdofs[:, 1]] = P["L_neck"] - gap - gas.edge_z(u)
    v[cork.xdofs[:, 1]] = speed
    t = 2.7e-3
    state = gas.update(u, t, gas.start(np.zeros(cork.ndof)))
    return P, gas, cork, SimpleNamespace(k=50, t=t, dt=1e-6, u=u, v=v, state=SimpleNamespace(loads=(state,)))


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_a_run_at_a_tolerance_releases_the_gas_within_its_share(tol):
    # the step in which the corner passes the mouth acts with the pressure p of the state before it for all of
    # its length, while the gas escapes inside it: the cork gains up to p A h / M too much velocity. At a
    # tolerance that is held at half the tolerance of the exit velocity's scale (without the limit, the fast
    # cork at accuracy = 1e-3 erred by 1.2e-3 against its reference refined in time, at 1e-2 by 1.1e-3)
    speed = 28e3  # mm/s, the exit's
    P, gas, cork, rec = _near_the_mouth(gap=0.01, speed=speed)
    p = gas.pressure(rec.t, rec.state.loads[0])
    assert 0.3 < p < 0.8  # Boyle's, after the ramp
    h = cork_scene.release_step(P, gas, cork, rec, tol)
    M = P["rho"] * np.pi * P["R_cork"] ** 2 * (P["L_neck"] + P["r_mouth"] + P["L_head"])
    W = P["p_step"] * P["n_ramp"] * np.pi * P["R_neck"] ** 2 * (P["L_neck"] + P["r_mouth"])  # the gas's largest work
    scale = np.sqrt(2 * W / M)  # the speed it could give the cork: the exit velocity's scale
    assert speed * h > 0.01  # a step of h reaches the mouth
    assert p * np.pi * P["R_neck"] ** 2 * h / M <= 0.5 * tol * scale * (1 + 1e-12)
    # far from the mouth the steps are not held to it, they cover half the way to it (a few steps more)
    P, gas, cork, rec = _near_the_mouth(gap=5.0, speed=speed)
    far = cork_scene.release_step(P, gas, cork, rec, tol)
    assert far == pytest.approx(0.5 * 5.0 / speed, rel=1e-9) and far > h
    # once the gas has escaped, nothing is held
    released = SimpleNamespace(
        **dict(vars(rec), state=SimpleNamespace(loads=(replace(rec.state.loads[0], released=True),)))
    )
    assert cork_scene.release_step(P, gas, cork, released, tol) == np.inf


def test_swept_volume_closed_form():
    r = np.linspace(0.0, 10.0, 7)
    assert swept_volume(np.column_stack([r, np.full(7, 3.0)])) == pytest.approx(np.pi * 100 * 3.0, rel=1e-12)
    # a cone z = r: int 2 pi r^2 dr = 2 pi R^3 / 3
    assert swept_volume(np.column_stack([r, r])) == pytest.approx(2 * np.pi * 1000 / 3, rel=1e-12)


def test_neck_normal_points_into_the_neck_and_is_continuous():
    neck = Neck(10.0, 24.0, 2.0)
    x = np.array(
        [
            [9.0, 5.0],
            [10.1, 5.0],
            [10.0 - 1e-9, 24.0 - 1e-9],
            [10.0 - 1e-9, 24.0 + 1e-9],
            [12.0 - 1e-9, 26.0 + 1e-9],
            [12.0 + 1e-9, 26.0 + 1e-9],
        ]
    )
    k = neck.locate(x, np.zeros(len(x)), None)
    assert k["g_N"][0] > 0 and k["g_N"][1] < 0  # inside the neck open, in the glass closed
    assert np.allclose(k["n"][0], [-1, 0])  # towards the cork (the axis)
    assert np.allclose(k["n"][2], k["n"][3], atol=1e-6) and abs(k["s"][2] - k["s"][3]) < 1e-6
    assert np.allclose(k["n"][4], k["n"][5], atol=1e-6) and abs(k["s"][4] - k["s"][5]) < 1e-6
    assert np.allclose(k["n"], np.stack([-k["t"][:, 1], k["t"][:, 0]], axis=1))  # n = e3 x t (eq 18)


@pytest.mark.parametrize("x", [[10.2, 7.0], [10.3, 24.8], [11.4, 25.7], [14.0, 25.9]])
def test_neck_variations_match_finite_differences(x):
    assert_locate_matches_fd(Neck(10.0, 24.0, 2.0, shift=0.3), x, atol=1e-6, atol2=1e-5, same_segment=False)


def test_mesh_has_the_papers_element_count():
    mesh = cork_mesh(10.0, 12.0, 24.0, 48.0, 6, 19)
    assert mesh.t.shape[1] == 114
    assert mesh.p[0].max() == pytest.approx(12.0)


def test_newton_failure_is_raised_not_hidden():
    with pytest.raises(NewtonError):
        run_scene("cork", "fast", {"maxit": 1, "max_cuts": 0})


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="R_tip"):
        run_scene("cork", "fast", {"R_tip": 13.0})
    with pytest.raises(ValueError, match="dt"):
        run_scene("cork", "fast", {"dt": -1.0})


@pytest.fixture(scope="module")
def paper():
    # the paper preset runs in CI (about 10 s of CPU, half a minute on a busy machine); shared
    # with the figure code's cache (the summary row and the exit-time study read the same run)
    from contactfem.plots import cached_run

    return cached_run("cork", "paper")


@pytest.mark.slow
def test_paper_preset_leaves_by_static_breakaway_near_28_m_s(paper):
    r = paper
    assert r["press_fit_calibrated"] is True
    assert r["breakaway_margin_MPa"] > 0, r["breakaway_margin_MPa"]  # the mechanism
    assert r["exited"]
    v = r["exit_velocity_m_s"]
    # paper "about 28 m/s" (two digits, +-2 %). Tolerance 10 %: on the knife's edge
    # (margin +0.014 MPa) the exit velocity moves by ~1 m/s over the neighbouring exiting
    # points of the knife-edge study (mu 0.095: 30.4, p0 0.84: 30.9, fast preset), i.e. 3-4 %;
    # that twice, plus the rounding
    assert abs(v - PAPER_V) / PAPER_V < 0.10, f"paper {PAPER_V} m/s, ours {v:.2f} m/s, tolerance 10 %"
    assert r["max_penetration_ratio"] < 0.02


@pytest.mark.slow
def test_knife_edge_figure_draws_from_its_data(tmp_path, monkeypatch):
    # the figure is computed by `contactfem figures` (minutes); here it is drawn from data of
    # the same shape, and the grid switches to the full one with CONTACTFEM_SLOW
    import matplotlib

    matplotlib.use("Agg")
    from contactfem.plots import cork as F

    field = [
        dict(mu=m, R_tip=R, breakaway_margin_MPa=0.8 - m * 2470 * (1 + (R - 10)) / (np.pi * 100), error=None)
        for m in (0.095, 0.1, 0.105)
        for R in (10.0, 10.1)
    ]
    runs = [
        dict(mu=0.1, R_tip=10.0, exited=True, v=30.7, margin=0.014, error=None),
        dict(mu=0.105, R_tip=10.0, exited=False, v=None, margin=-0.028, error=None),
        dict(mu=0.1, R_tip=10.1, exited=None, v=None, margin=None, error="NewtonError"),
    ]
    line = [
        dict(p0=p, p_step=p / 8, n_ramp=8, exited=p > 0.79, v=30.0 if p > 0.79 else None, margin=p - 0.786, error=None)
        for p in (0.78, 0.8)
    ]
    files = F.cork_knife_edge(outdir=str(tmp_path), data=dict(field=field, runs=runs, p0=line, preset="fast"))
    assert all((tmp_path / f).exists() for f in ("cork_knife_edge.png", "cork_knife_edge.json")), files
    monkeypatch.delenv("CONTACTFEM_SLOW", raising=False)
    assert F.knife_grid() is F.KNIFE_GRID
    monkeypatch.setenv("CONTACTFEM_SLOW", "1")
    assert F.knife_grid() is F.KNIFE_GRID_SLOW


# ---------------------------------------------------------------------------------------
# The exit time. The paper: "between 2.6 and 2.7 ms". The paper preset's exit lies outside that
# window; the study plots.cork.cork_exit_time (figures/cork_exit_time.md, lecture 08 Sec. 5)
# says why, and these tests check that it still does, on its quick profile (seven runs of the
# paper preset, about a minute and a half).
PAPER_WINDOW_MS = (2.6, 2.7)
# The exit time is recorded at the end of a step; near the exit the step is dt_fine = 5e-6 s of
# the paper preset, so two runs whose exits differ by less than 0.005 ms leave in the same step.
ONE_STEP_MS = 5e-3


@pytest.fixture(scope="module")
def exit_study():
    from contactfem.plots import cork as F

    d = F.exit_time_data(F.EXIT_CASES_QUICK)
    return d, F.exit_time_summary(d)


@pytest.mark.slow
def test_exit_study_reads_the_scene(exit_study, paper):
    """The study's paper-preset case (the stages with the closing step on) is the scene's own
    run: the same exit time and velocity."""
    d, s = exit_study
    assert paper["exited"] and all(r["error"] is None and r["exited"] for r in d["cases"])
    assert s["exit_ms"] == pytest.approx(paper["exit_time_ms"], abs=1e-9)
    assert s["exit_velocity_m_s"] == pytest.approx(paper["exit_velocity_m_s"], rel=1e-9)
    assert (s["dt_paper_s"], s["n_press"]) == (paper["parameters"]["dt"], paper["parameters"]["n_press"])


@pytest.mark.slow
def test_the_closing_step_is_the_converged_rule(exit_study):
    """Why the closing step is kept: it acts through the press fit only (switched off in the pop,
    the exit stays in its step), and with the preset's press-fit increments it already gives the
    exit that both rules reach with eight times as many; the rule without it is off by many
    steps (the travel before touching loads its stick springs)."""
    d, s = exit_study
    assert abs(s["pop_rule_shift_ms"]) < ONE_STEP_MS
    fit = s["press_fit_refined_ms"]
    assert abs(fit["with"] - fit["without"]) < 2 * ONE_STEP_MS
    assert abs(s["exit_ms"] - fit["with"]) < 2 * ONE_STEP_MS
    assert abs(s["exit_without_ms"] - fit["without"]) > 10 * ONE_STEP_MS


@pytest.mark.slow
def test_refined_exit_lies_within_the_paper_steps_error_of_the_window(exit_study, paper):
    """Lecture 08: refined in the neck (the ramp kept), both rules leave at the same
    time, and the paper's window lies within the discretisation error of the paper's own step
    (1e-4 s, the paper preset's: the paper's run carries an error of that size) of that exit:
    the gap between the refined exit and the window (0 inside it) is at most the difference
    between the exit at the paper's step and the refined one. A model whose refined exit falls
    inside the window passes; one further from it than that error fails. Both rules agree to two
    steps of the recording near the exit (ONE_STEP_MS each). (Where the refined exit lies against the
    window, the front page says from figures/cork_exit_time.json: its block cork-refined.)"""
    d, s = exit_study
    on, off = s["refined_ms"]["with"], s["refined_ms"]["without"]
    assert abs(on - off) < 2 * ONE_STEP_MS
    error = abs(paper["exit_time_ms"] - on)  # the paper step's discretisation error
    gap = max(PAPER_WINDOW_MS[0] - on, on - PAPER_WINDOW_MS[1], 0.0)
    assert gap <= error, (gap, error)


@pytest.mark.slow
def test_published_exit_numbers_are_the_run(exit_study, paper):
    """summary.md, figures/cork_exit_time.md and its full study print what the
    runs give: the paper preset's exit time and velocity, the refined exit of either rule."""
    from pathlib import Path

    d, s = exit_study
    repo = Path(__file__).resolve().parents[1]
    summary = (repo / "figures" / "summary.md").read_text()
    assert f"exit {paper['exit_time_ms']:.2f} ms at {paper['exit_velocity_m_s']:.1f} m/s" in summary
    fine = [r for r in d["cases"] if r["ramp_step_s"] is not None]
    assert f"({fine[0]['exit_time_ms']:.2f} ms with the step in the neck refined" in summary
    study = (repo / "figures" / "cork_exit_time.md").read_text()
    assert "every case (CONTACTFEM_SLOW=1)" in study  # the committed table is the full one
    onoff = {True: "on", False: "off"}
    rows = {tuple(c.strip() for c in line.split("|")[1:4]): line.split("|")[4:6] for line in study.splitlines()}

    def printed(cell):  # "2.786 ± 0.093" or "2.856": the value and the rounding spread printed with it
        value, _, spread = cell.strip().partition(" ± ")
        return float(value), float(spread or 0.0)

    for r in d["cases"]:
        key = (r["group"], r["label"], f"{onoff[r['closing_step_press_fit']]}, {onoff[r['closing_step_pop']]}")
        assert key in rows, f"figures/cork_exit_time.md lacks the case {key!r}: regenerate it"
        # the quick run's numbers as printed: to the printed digit (half a unit), or within the spread printed
        # beside them (what rounding moves them by, measured: plots/rounding.py)
        for cell, value, unit in zip(rows[key], (r["exit_time_ms"], r["exit_velocity_m_s"]), (1e-3, 1e-2)):
            shown, spread = printed(cell)
            assert abs(value - shown) <= max(spread, unit / 2) + 1e-12, (key, value, cell)
