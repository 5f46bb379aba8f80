"""A student's law cannot lie: every value a law returns is checked where it returns
(contactfem.laws.protocol), a law is checked over the range the scene meets before the
run, its fields keep their own defaults, and a law given where it does nothing is refused.

The scene runs go through the command line (in-process, as a user types it) and through
run_scene, never through the contact's internals."""

import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from contactfem.cli import main
from contactfem.lab.lawfile import load_class
from contactfem.laws import Coulomb, PowerLaw, Stribeck
from contactfem.laws.protocol import FrictionLaw, LawError, LawValueError, NormalLawView, as_friction_law, as_normal_law
from contactfem.scenes import get_scene, run_scene

DATA = Path(__file__).parent / "data"
LAWS = DATA / "lying_laws.py"
SCENES = ["block", "rolling_ring", "sloping_impact", "funnel", "cork"]
# a pressure each scene reaches in its fast preset (the block: its mean pressure p_y width / contact
# length = 227; the rings and the cork: a fraction of what a run with Coulomb's law meets)
REACHED = {"block": 50.0, "rolling_ring": 0.05, "sloping_impact": 0.2, "funnel": 0.1, "cork": 0.5}
# pressures strictly between lo and hi that each scene meets, none of the law file's quick probe
# (p = 0.5, 1, 2): such a law reaches the run with --no-check
WINDOW = {
    "block": (50.0, 1e12),
    "rolling_ring": (0.01, 0.45),
    "sloping_impact": (0.01, 0.45),
    "funnel": (0.01, 0.45),
    "cork": (0.01, 0.45),
}


def cli(capsys, *argv):
    rc = main(list(argv))
    out = capsys.readouterr()
    return rc, out.err.strip().splitlines(), out.out


def law(cls_name, **fields):
    """The law class of the data file, as the command line loads it (same record 'file')."""
    return load_class(f"{LAWS}:{cls_name}", "--any")(**fields)


def _one_line(lines, *needles):
    assert len(lines) == 1, lines
    for n in needles:
        assert re.search(n, lines[0]), (n, lines[0])


# ---- the adapters: each value checked where it returns ------------------------------------


@dataclass(frozen=True)
class Returns:
    """A friction law returning fixed arrays (Y, and optionally its derivatives)."""

    c_T: float = 1.0
    kind: str = "nan"

    def slip_bound(self, p, q):
        p = np.asarray(p, dtype=float)
        Y = 0.3 * p
        if self.kind == "nan":
            Y = np.where(p > 1.5, np.nan, Y)
        elif self.kind == "inf_deriv":
            return Y, np.where(p > 1.5, np.inf, 0.3), 0 * p
        elif self.kind == "negative":
            Y = np.where(p > 1.5, -Y, Y)
        elif self.kind == "shape":
            return Y[:1], 0.3 + 0 * p, 0 * p
        elif self.kind == "text":
            return "Y", 0.3 + 0 * p, 0 * p
        return Y, 0.3 + 0 * p, 0 * p


@pytest.mark.parametrize(
    "kind,message",
    [
        ("nan", r"^Returns\.slip_bound returned NaN or inf: Y = nan at p = 2, q = 0\.2$"),
        ("inf_deriv", r"^Returns\.slip_bound returned NaN or inf: dY/dp = inf at p = 2, q = 0\.2$"),
        ("negative", r"^Returns\.slip_bound returned a negative slip bound: Y = -0\.6 at p = 2, q = 0\.2 "),
        ("shape", r"^Returns\.slip_bound: Y has shape \(1,\), expected \(3,\)"),
        ("text", r"^Returns\.slip_bound: Y is not an array of numbers"),
    ],
)
def test_a_bad_value_is_one_line_naming_the_law_the_method_the_value_and_the_point(kind, message):
    L = as_friction_law(Returns(kind=kind))
    with pytest.raises(LawValueError, match=message) as err:
        L.slip_bound(np.array([0.5, 1.0, 2.0]), np.array([0.0, 0.1, 0.2]))
    assert "\n" not in str(err.value)
    assert not isinstance(err.value, FloatingPointError)  # Newton does not take it for a bad iterate


def test_a_point_the_solver_already_lost_is_not_blamed_on_the_law():
    """NaN in, NaN out: where the arguments are not finite the solver has failed, not the law."""
    L = as_friction_law(Returns(kind="ok"))
    Y = L.slip_bound(np.array([np.nan, 1.0]), np.zeros(2))[0]
    assert np.isnan(Y[0]) and Y[1] == 0.3


@pytest.mark.parametrize("c_T", [-1.0, 0.0, float("nan"), float("inf")])
def test_c_T_is_checked_when_the_adapter_is_made(c_T):
    with pytest.raises(LawError, match=rf"Returns\.c_T = {c_T:g} is out of range: .* finite number > 0"):
        as_friction_law(Returns(c_T=c_T, kind="ok"))


def test_the_normal_adapter_checks_sign_values_and_says_when_a_law_has_no_energy():
    N = as_normal_law(law("Tensile"))
    t, dt = N.traction(np.array([0.1, -0.01]))
    assert t[0] == 0.0 and t[1] == pytest.approx(-0.1)
    with pytest.raises(
        LawValueError,
        match=r"^Tensile\.traction returned a tensile traction: t_N = 1 > 0 at "
        r"g_N = -0\.1 \(in contact",
    ):
        N.traction(np.array([-0.01, -0.1]))
    assert not N.has_energy and not hasattr(N, "energy")
    with pytest.raises(AttributeError, match="Tensile has no method energy"):
        N.energy(np.zeros(1))
    assert as_normal_law(PowerLaw(c_N=2.0)).has_energy and as_normal_law(N) is N
    with pytest.raises(LawError, match="is a friction law .* not as the normal law"):
        NormalLawView(Coulomb(c_T=1.0, mu=0.3))
    with pytest.raises(LawError, match="is a normal law .* not as the friction law"):
        FrictionLaw(PowerLaw(c_N=1.0))


def test_shipped_laws_are_called_directly_and_give_the_same_numbers():
    """The shipped laws are trusted (no guard, no conversion): the adapter returns what the
    law returns, with zeros for the arguments it does not take."""
    p, q = np.linspace(0.0, 3.0, 7), np.linspace(0.0, 1.0, 7)
    for lw in (Coulomb(c_T=2.0, mu=0.3), Stribeck(c_T=2.0, mu_s=0.5, mu_d=0.3, v_s=0.1)):
        L = as_friction_law(lw)
        assert L.trusted
        out = L.slip_bound(p, q, 0.1 * p)
        own = lw.slip_bound(p, q) if L.arity == 2 else lw.slip_bound(p, q, 0.1 * p)
        for a, b in zip(out, own):
            assert np.array_equal(a, b)
        assert len(out) == 5 and out[4].shape == (7, 0)
    assert not as_friction_law(law("OwnFields")).trusted


# ---- the scenes: a lying law stops the run, one line, nothing written ----------------------


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("check", [True, False], ids=["checked", "no-check"])
@pytest.mark.parametrize("which", ["NaNEverywhere", "NaNAbove", "NegativeAbove"])
def test_a_lying_law_exits_non_zero_with_one_line_and_writes_nothing(scene, check, which, capsys, tmp_path):
    out = tmp_path / "r.json"
    argv = ["run", scene, "--friction", f"{LAWS}:{which}", "--json", str(out)]
    if which != "NaNEverywhere":
        argv += ["--set", f"law.p_bad={REACHED[scene]}"]
    rc, err, _ = cli(capsys, *argv, *([] if check else ["--no-check"]))
    assert rc in (1, 2)
    value = r"Y = nan" if which.startswith("NaN") else r"Y = -[0-9.e+-]+ at p = "
    _one_line(err, rf"^contactfem: (error|law failed): .*{which}\.slip_bound returned", value)
    assert not out.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("scene", SCENES)
def test_a_law_the_run_meets_stops_it_where_it_returns(scene, capsys, tmp_path):
    """A law that is NaN only in a window of pressures the scene meets: with --no-check the
    run meets it and stops there (exit 1, one line with the point); checked first, it never
    starts (exit 2). The same from run_scene."""
    lo, hi = WINDOW[scene]
    out = tmp_path / "r.json"
    sets = ["--set", f"law.lo={lo}", "--set", f"law.hi={hi}"]
    rc, err, _ = cli(capsys, "run", scene, "--friction", f"{LAWS}:NaNWindow", *sets, "--no-check", "--json", str(out))
    assert rc == 1
    _one_line(
        err,
        r"^contactfem: law failed: NaNWindow\.slip_bound returned NaN or inf: Y = nan at p = ([0-9.e+-]+), "
        r"q = [0-9.e+-]+$",
    )
    p = float(re.search(r"at p = ([0-9.e+-]+)", err[0]).group(1))
    assert lo < p < hi
    rc, err, _ = cli(capsys, "run", scene, "--friction", f"{LAWS}:NaNWindow", *sets, "--json", str(out))
    assert rc == 2
    _one_line(err, r"^contactfem: error: friction law NaNWindow\.slip_bound returned NaN or inf: Y = nan at p = ")
    assert not out.exists()
    bad = law("NaNWindow", lo=lo, hi=hi)
    with pytest.raises(LawValueError, match=r"NaNWindow\.slip_bound returned NaN or inf: Y = nan at p = "):
        run_scene(scene, "fast", friction=bad, check=False)
    with pytest.raises(LawError, match=r"friction law NaNWindow\.slip_bound returned NaN or inf"):
        run_scene(scene, "fast", friction=bad)


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("c_T", ["-1", "0", "nan"])
def test_a_stick_stiffness_out_of_range_is_refused(scene, c_T, capsys, tmp_path):
    out = tmp_path / "r.json"
    rc, err, _ = cli(
        capsys, "run", scene, "--friction", f"{LAWS}:OwnFields", "--set", f"law.c_T={c_T}", "--json", str(out)
    )
    assert rc == 2 and not out.exists()
    _one_line(err, rf"^contactfem: error: .*OwnFields\.c_T = {c_T} is out of range")
    for check in (True, False):
        with pytest.raises(LawError, match=rf"OwnFields\.c_T = {c_T} is out of range"):
            run_scene(scene, "fast", friction=law("OwnFields", c_T=float(c_T)), check=check)


def test_a_tensile_normal_law_is_refused_before_and_stopped_during_the_run(capsys, tmp_path):
    """Tensile beyond a depth d = 0.03 (the quick probe of the file reaches 0.02; the block's
    range 3.25, its run with c_N = 1e3 about 0.2)."""
    sets = ("--set", "law.c_N=1e3", "--set", "law.d=0.03")
    rc, err, _ = cli(capsys, "run", "block", "--normal", f"{LAWS}:Tensile", *sets)
    assert rc == 2
    _one_line(err, r"^contactfem: error: normal law Tensile\.traction returned a tensile traction: t_N = ")
    rc, err, _ = cli(capsys, "run", "block", "--normal", f"{LAWS}:Tensile", *sets, "--no-check")
    assert rc == 1
    _one_line(
        err,
        r"^contactfem: law failed: Tensile\.traction returned a tensile traction: t_N = [0-9.e+-]+ > 0 at "
        r"g_N = -[0-9.e+-]+ ",
    )


def test_a_block_its_friction_law_cannot_hold_is_refused_before_any_solve(capsys):
    rc, err, _ = cli(capsys, "run", "block", "--friction", f"{LAWS}:OwnFields", "--set", "law.mu=0.1")
    assert rc == 2
    _one_line(
        err,
        r"no static equilibrium: the tangential load 195 exceeds the largest friction force 80 the "
        r"friction law OwnFields can carry",
    )
    with pytest.raises(LawError, match="no static equilibrium"):
        run_scene("block", "fast", friction=law("OwnFields", mu=0.1))
    rc, err, _ = cli(capsys, "run", "block", "--friction", f"{LAWS}:OwnFields", "--set", "law.mu=0.25")
    assert rc == 0, err  # 0.25 x 800 = 200 > 195: held


def test_a_wrong_derivative_is_a_warning_line_not_a_refusal(capsys):
    """The pre-flight compares the derivatives with finite differences: a wrong one is named
    in one warning line (before the run: Newton will converge slower), and the run goes on."""
    wrong = DATA / "wrong_derivative.py"
    rc, err, out = cli(capsys, "run", "block", "--friction", f"{wrong}:WrongSlope")
    assert rc == 0
    assert len(err) == 1 and err[0].startswith(
        "contactfem: warning: friction law WrongSlope: dY/dp does not match finite differences"
    ), err
    with pytest.warns(UserWarning, match="dY/dp does not match finite differences"):
        run_scene("block", "fast", friction=load_class(f"{wrong}:WrongSlope")())


# ---- explicit fields: the law's own defaults, CLI = Python --------------------------------


def test_a_laws_own_fields_keep_their_defaults_and_cli_equals_python(capsys, tmp_path):
    """OwnFields has fields m and delta, as the scene has parameters m (the normal law's
    exponent) and delta (Newmark's): they keep the law's own defaults. The command line and
    run_scene with the same law give the same JSON."""
    out = tmp_path / "r.json"
    rc, err, _ = cli(
        capsys,
        "run",
        "rolling_ring",
        "--friction",
        f"{LAWS}:OwnFields",
        "--set",
        "t_end=0.3",
        "--set",
        "law.delta=0.05",
        "--json",
        str(out),
    )
    # (no note: the fields have defaults; the ring's contact is not resolved by its step, and its accuracy says so)
    assert rc == 0 and [e for e in err if "warning: accuracy: penalty_steps" not in e] == [], err
    a = json.loads(out.read_text())
    assert a["friction_law"]["fields"] == {"c_T": 10.0, "mu": 0.2, "m": 0.5, "delta": 0.05}
    assert a["parameters"]["m"] == 1.0 and a["parameters"]["delta"] == 0.7  # the scene's own, untouched
    b = run_scene("rolling_ring", "fast", {"t_end": 0.3}, friction=law("OwnFields", delta=0.05))
    a.pop("wall_time_s")
    b.pop("wall_time_s")
    assert a.pop("import_time_s") >= 0 and "import_time_s" not in b  # the process's: command line only
    assert a == json.loads(json.dumps(b))


def test_a_field_without_default_takes_the_scenes_parameter_and_says_so(capsys, tmp_path):
    out = tmp_path / "r.json"
    rc, err, _ = cli(capsys, "run", "block", "--friction", f"{DATA / 'coulomb_law.py'}:MyCoulomb", "--json", str(out))
    assert rc == 0
    assert err == [
        "contactfem: note: friction law MyCoulomb: c_T = 10000, mu = 0.3 from the scene's parameters "
        "(fields without a default; --set law.NAME=VALUE sets them)"
    ]
    assert json.loads(out.read_text())["friction_law"]["fields"] == {"c_T": 1e4, "mu": 0.3}


@pytest.mark.parametrize(
    "args,pattern",
    [
        (
            ("--set", "mu=0.4"),
            r"parameter mu builds the scene's friction law, which the friction law OwnFields replaces: "
            r"set OwnFields's own field instead: --set law\.mu=0\.4",
        ),
        (("--set", "c_T=10"), r"parameter c_T builds .* --set law\.c_T=10"),
        (("--set", "alpha=0.1"), r"OwnFields has no field alpha \(its fields: c_T, mu, m, delta\)"),
        (
            ("--set", "law=coulomb"),
            r"parameter law = coulomb chooses the scene's friction law, which the friction law "
            r"OwnFields replaces: leave law out",
        ),
    ],
)
def test_scene_parameters_a_law_replaces_are_refused_with_a_hint(args, pattern, capsys):
    rc, err, _ = cli(capsys, "run", "block", "--friction", f"{LAWS}:OwnFields", *args)
    assert rc == 2
    _one_line(err, pattern)


@pytest.mark.parametrize("scene", ["hertz", "patch", "bar_impact"])
def test_a_friction_law_on_a_frictionless_scene_is_refused(scene, capsys):
    rc, err, _ = cli(capsys, "run", scene, "--friction", f"{LAWS}:OwnFields")
    assert rc == 2
    _one_line(
        err,
        rf"^contactfem: error: scene {scene} has no friction law .*; scenes with a friction law: block, "
        r"cork, funnel, rolling_ring, sloping_impact$",
    )
    with pytest.raises(ValueError, match=f"scene {scene} has no friction law"):
        run_scene(scene, "fast", friction=law("OwnFields"))


def test_the_variant_is_the_users_law(capsys, tmp_path):
    out = tmp_path / "r.json"
    rc, err, _ = cli(
        capsys, "run", "sloping_impact", "--friction", f"{LAWS}:OwnFields", "--set", "n_steps=30", "--json", str(out)
    )
    assert rc == 0, err
    res = json.loads(out.read_text())
    assert res["variant"] == "OwnFields" and "variant" not in res["parameters"]
    assert (
        get_scene("sloping_impact").variant_of({"variant": "viscoplastic"}, law("OwnFields"))
        == "viscoplastic with OwnFields"
    )


@pytest.mark.parametrize(
    "spec,kind,cls",
    [
        ("stribeck", "friction", "Stribeck"),
        ("DieterichRuina", "friction", "DieterichRuina"),
        ("archard_wear", "friction", "ArchardWear"),
        ("contactfem.laws:Coulomb", "friction", "Coulomb"),
        ("contactfem.laws.PowerLaw", "normal", "PowerLaw"),
        ("exponential_law", "normal", "ExponentialLaw"),
    ],
)
def test_shipped_laws_and_module_paths_are_named_on_the_command_line(spec, kind, cls):
    assert load_class(spec, f"--{kind}").__name__ == cls


def test_a_shipped_law_runs_from_the_command_line_with_its_own_defaults(capsys, tmp_path):
    out = tmp_path / "r.json"
    rc, err, _ = cli(
        capsys,
        "run",
        "block",
        "--friction",
        "stribeck",
        "--set",
        "law.mu_s=0.5",
        "--set",
        "law.mu_d=0.4",
        "--set",
        "law.v_s=0.1",
        "--json",
        str(out),
    )
    assert rc == 0, err
    fields = json.loads(out.read_text())["friction_law"]["fields"]
    assert fields["delta"] == 2.0 and fields["mu_v"] == 0.0 and fields["c_T"] == 1e4  # delta: its own, not Newmark's
    rc, err, _ = cli(capsys, "run", "block", "--friction", "power_law")
    _one_line(err, r"--friction power_law: PowerLaw is a normal law \(it has traction\): give it with --normal")
    rc, err, _ = cli(capsys, "run", "block", "--friction", "nosuch")
    _one_line(err, r"--friction nosuch: not a shipped law \(friction: coulomb, parabolic_slip")


# ---- check_law's range ----------------------------------------------------------------------


def test_check_law_reaches_the_pressures_a_scene_meets():
    """A law NaN only above p = 50: the default range reaches it (1e4 scale), and so does a
    scene's range; a range below it says so in the report's first line of values."""
    from contactfem import check_law

    bad = law("NaNAbove", p_bad=50.0)
    report = check_law(bad)
    assert not report.ok and "Y = nan at p = " in report.errors[0]
    assert check_law(bad, p_max=40.0).ok
    assert "p in [0, 40]" in str(check_law(bad, p_max=40.0))
    range_ = get_scene("block").law_range(get_scene("block").resolve("fast"))
    assert not check_law(bad, p_max=range_["p"]).ok


def test_check_laws_keywords_are_documented_in_its_docstring():
    """Every keyword check_law accepts (those of the friction and the normal checks) is in its docstring,
    and no other (the front page's table of them is generated from it: tests/test_readme.py)."""
    import inspect

    from contactfem.laws.check import check_friction_law, check_law, check_normal_law

    accepted = {n for f in (check_friction_law, check_normal_law) for n in inspect.signature(f).parameters} - {"law"}
    documented = set(re.findall(r"^    ``(\w+)``", check_law.__doc__, re.M))
    assert accepted == documented, (accepted, documented)


@pytest.mark.parametrize("no_check", [False, True])
def test_a_lying_law_is_named_with_its_value_and_point(capsys, no_check):
    """A Coulomb law that is NaN above p = 50, run in the block: refused before the run (exit 2) by the
    check, or stopped during it (exit 1) with --no-check; one line naming the law, the method, the value
    and the point, above p = 50."""
    import os

    cmd = ["run", "block", "--friction", "tests/data/lying_laws.py:NaNAbove"] + (["--no-check"] if no_check else [])
    cwd = os.getcwd()
    os.chdir(Path(__file__).resolve().parents[1])
    try:
        code = main(cmd)
    finally:
        os.chdir(cwd)
    line = capsys.readouterr().err.strip()
    head = "law failed:" if no_check else "error: friction law"
    m = re.fullmatch(
        rf"contactfem: {head} NaNAbove\.slip_bound returned NaN or inf: Y = nan at p = ([\d.e+-]+), q = ([\d.e+-]+)",
        line,
    )
    assert code == (1 if no_check else 2) and m, (code, line)
    assert float(m.group(1)) > 50


@pytest.mark.parametrize("field,value", [("mu", "nan"), ("mu", "inf"), ("delta", "-inf")])
def test_a_field_that_is_not_finite_is_refused_when_the_law_is_built(field, value, capsys):
    rc, err, _ = cli(capsys, "run", "rolling_ring", "--friction", f"{LAWS}:OwnFields", "--set", f"law.{field}={value}")
    assert rc == 2
    _one_line(err, rf"OwnFields\.{field} = {value}: a law's field must be a finite number")
    with pytest.raises(LawError, match=rf"OwnFields\.{field} = {value}"):
        run_scene("rolling_ring", "fast", friction=law("OwnFields", **{field: float(value)}), check=False)
