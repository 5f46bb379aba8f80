"""Every call into a scene file is guarded like a law: its declaration when it is loaded (exit
code 2), the values its build and measure return during a run (exit code 1), each failure one
line naming the file, the function and the key, with nothing written; the laws given to a scene
file are checked before the run as on a shipped scene; a first step that fails from overlapping
bodies says so."""

from pathlib import Path

import pytest

from contactfem import AccuracyWarning, run_scene
from contactfem.cli import main
from contactfem.scenes import SceneError, get_scene

EXAMPLE = Path(__file__).resolve().parents[1] / "lectures" / "examples" / "disc_wall.py"
DATA = Path(__file__).parent / "data"


def edited(tmp_path, *changes, name="edited.py"):
    """The example with each (old, new) applied, beside a copy of its mesh."""
    text = EXAMPLE.read_text()
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new)
    (tmp_path / "disc.msh").write_bytes((EXAMPLE.parent / "disc.msh").read_bytes())
    path = tmp_path / name
    path.write_text(text)
    return path


def one_line(capsys, argv, code):
    """Run the command line with --json beside the scene file; its exit code must be `code`, its
    stderr one line (returned), and nothing written."""
    out = Path(argv[1]).with_name("written.json")
    assert main([str(a) for a in argv] + ["--json", str(out)]) == code
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and not out.exists(), err
    return err


MEASURE = "    return dict(rebound_vx=float(vx), rebound_vy=float(vy), energy_kinetic=hist.kinetic)"
RESULTS = {
    "complex": ("    return dict(rebound_vx=complex(vx, 1.0), rebound_vy=float(vy))", "rebound_vx is complex"),
    "object": ("    return dict(rebound_vx=object(), rebound_vy=float(vy))", "rebound_vx is of type object"),
    "nan": ("    return dict(rebound_vx=float('nan'), rebound_vy=float(vy))", "rebound_vx = nan is not finite"),
    "nan_in_list": ("    return dict(rebound_vx=[1.0, float('nan')])", r"rebound_vx[1] = nan is not finite"),
    "accuracy": ("    return dict(rebound_vx=float(vx), accuracy=0.5)", "accuracy is a float: accuracy is the run's"),
    "reserved": ("    return dict(rebound_vx=float(vx), wall_time_s=1.0)", "wall_time_s is a result the run sets"),
    "key": ("    return {1: float(vx)}", "the results has a key 1 that is not text"),
}


@pytest.mark.parametrize("case", RESULTS)
def test_a_bad_result_of_measure_is_one_line_naming_it(tmp_path, capsys, case):
    new, expected = RESULTS[case]
    path = edited(tmp_path, (MEASURE, new))
    line = one_line(capsys, ["run", path, "--set", "n_steps=2"], 1)
    assert line.startswith("contactfem: scene failed: scene file edited.py, measure: ") and expected in line, line
    with pytest.raises(SceneError, match=r"^scene file edited.py, measure: "):
        run_scene(str(path), "fast", {"n_steps": 2})


def test_the_scene_own_indicators_are_taken_into_the_accuracy_section(tmp_path):
    """accuracy, returned as a shipped scene returns it ({name: indicator(...)}), joins the run's section."""
    path = edited(
        tmp_path,
        (
            MEASURE,
            "    from contactfem.problem.accuracy import indicator\n"
            "    return dict(rebound_vx=float(vx), accuracy=dict(mine=indicator(0.5, 1.0, 'what', 'why')))",
        ),
    )
    r = run_scene(str(path), "fast", {"n_steps": 2})
    assert r["accuracy"]["mine"]["value"] == 0.5 and "equilibrium" in r["accuracy"]


MODEL = "    return Model(systems=(system,), stage=stage, sizes=sizes, parts=dict(disc=disc))"
MODELS = {
    "stage_tuple": (MODEL.replace("stage=stage", "stage=(stage,)"), "Model.stage is a tuple, not a Stage"),
    "system_list": (MODEL.replace("(system,)", "([system],)"), "Model.systems[0] is a list, not a System"),
    "sizes": (MODEL.replace("sizes=sizes", "sizes=dict(element=-1.0)"), "Model.sizes['element'] = -1.0 is not"),
    "size_name": (MODEL.replace("sizes=sizes", "sizes=dict(elements=1.0)"), "Model.sizes['elements'] is not a size"),
    "u0": (MODEL.replace("stage=stage", "stage=Stage(stage.stepper, stage.schedule, np.zeros(3))"), "Stage.u0 has"),
}


@pytest.mark.parametrize("case", MODELS)
def test_a_bad_model_of_build_is_one_line_naming_it(tmp_path, capsys, case):
    new, expected = MODELS[case]
    path = edited(tmp_path, (MODEL, new))
    line = one_line(capsys, ["run", path, "--set", "n_steps=2"], 1)
    assert line.startswith("contactfem: scene failed: scene file edited.py, build: ") and expected in line, line


PARAM = '    Param("mu", 0.3, "", 0.0, 2.0, doc="Coulomb friction coefficient (friction law)"),'
DECLARATIONS = {
    "twice": (PARAM + '\n    Param("mu", 0.5),', "SCENE: two parameters are named mu"),
    "accuracy": (PARAM + '\n    Param("accuracy", 0.0),', "SCENE: parameter accuracy is a name the run reserves"),
    "tolerance": (PARAM + '\n    Param("tolerance", 0.0),', "SCENE: parameter tolerance is a name the run reserves"),
    "not_a_name": (PARAM + '\n    Param("law.x", 0.0),', "SCENE: parameter name 'law.x' is not a name"),
    "default": (PARAM + '\n    Param("x", 5.0, "", 0.0, 1.0),', "SCENE: a default is not allowed: parameter x = 5"),
    "not_a_param": (PARAM + '\n    ("x", 1.0),', "SCENE: params holds a tuple, not a Param"),
}


@pytest.mark.parametrize("case", DECLARATIONS)
def test_a_bad_declaration_is_refused_at_load(tmp_path, capsys, case):
    new, expected = DECLARATIONS[case]
    path = edited(tmp_path, (PARAM, new))
    line = one_line(capsys, ["run", path], 2)
    assert line.startswith("contactfem: error: scene file edited.py, ") and expected in line, line
    with pytest.raises(ValueError, match="scene file edited.py, SCENE"):
        get_scene(str(path))


QUANTITIES = '    quantities=(Quantity("rebound_vx", "length/time"), Quantity("rebound_vy", "length/time")),'
STEP = '    discretisations=(time_step("dt", count="n_steps"),),'
ERROR_BARS = {
    "controls": (
        (QUANTITIES, QUANTITIES.replace('"length/time")),', '"length/time", controls=("mesh",))),')),
        "SCENE: quantity rebound_vy is controlled by 'mesh', not a discretisation of the file "
        "(its discretisations: step",
    ),
    "none": ((STEP, ""), "SCENE: quantity rebound_vx is controlled by 'step', not a discretisation of the file"),
    "dt": ((STEP, STEP.replace('time_step("dt"', 'time_step("dtt"')), "SCENE: discretisation step reads 'dtt', not a"),
    "count": ((STEP, STEP.replace('"n_steps"', '"nsteps"')), "SCENE: discretisation step reads 'nsteps', not a"),
    "kind": ((STEP, '    discretisations=("step",),'), "SCENE: discretisations is not a tuple of Discretisation"),
}


@pytest.mark.parametrize("case", ERROR_BARS)
def test_a_bad_error_bar_declaration_is_refused_at_load_by_run_and_show(tmp_path, capsys, case):
    change, expected = ERROR_BARS[case]
    path = edited(tmp_path, change)
    line = one_line(capsys, ["run", path], 2)
    assert line.startswith("contactfem: error: scene file edited.py, ") and expected in line, line
    assert main(["show", str(path)]) == 2  # not an internal error
    err = capsys.readouterr().err.strip()
    assert err.startswith("contactfem: error: scene file edited.py, SCENE") and "\n" not in err, err


@pytest.mark.slow
def test_the_example_says_why_its_velocities_get_no_band(tmp_path):
    """The README: at its default step the example's contact is unresolved and its finer levels oscillate; each
    velocity warns that it has no band, naming it and the time step (about 20 s: the run and four levels)."""
    with pytest.warns(AccuracyWarning) as caught:
        r = run_scene(str(edited(tmp_path)), "fast", error_bars=True)
    said = [str(w.message) for w in caught]
    assert r["accuracy"]["penalty_steps"]["ok"] is False
    for name in ("rebound_vx", "rebound_vy"):
        assert r["uncertainty"]["quantities"][name]["band"] is None
        assert any(
            f"{name}_band: no error band of {name}" in m and "time step:" in m and "oscillatory" in m for m in said
        )


def test_the_framework_accuracy_param_is_welcome(tmp_path):
    path = edited(
        tmp_path,
        (
            "from contactfem.solver",
            "from contactfem.problem.time_integration import ACCURACY_PARAM\nfrom contactfem.solver",
        ),
        (PARAM, PARAM + "\n    ACCURACY_PARAM,"),
    )
    assert get_scene(str(path)).param("accuracy").default == 0.0


def test_a_preset_the_file_lacks_is_refused(tmp_path, capsys):
    """disc_wall has no presets: fast is its defaults, and --preset paper is no preset of it."""
    line = one_line(capsys, ["run", edited(tmp_path), "--preset", "paper"], 2)
    assert "parameter preset = 'paper' is not allowed for disc_wall: one of fast" in line, line
    path = edited(
        tmp_path, ("    law_range=law_range,\n", "    law_range=law_range,\n    presets={'paper': {'nx': 3}},\n")
    )
    line = one_line(capsys, ["run", path], 2)
    assert "SCENE: preset paper sets 'nx', not a parameter of the file" in line, line


def test_an_initial_overlap_is_named(tmp_path, capsys):
    """The disc placed half inside the floor: its first step fails, and the line says why."""
    path = edited(
        tmp_path, ("WALL = [(-3.0, 0.0), (1.0, 0.0), (4.0, 2.0)]", "WALL = [(-3.0, 1.0), (1.0, 1.0), (4.0, 3.0)]")
    )
    assert main(["run", str(path), "--set", "n_steps=3"]) == 1
    err = capsys.readouterr().err
    assert "the initial configuration overlaps: contact wall, " in err and "nodes up to 0.95 inside its master" in err
    assert "(scene file edited.py, build: place the bodies apart)" in err


def test_a_law_with_a_wrong_derivative_is_named_before_the_run(tmp_path, capsys):
    """dY/dp twice what it is: the same warning on the scene file as on the block, before the run."""
    law = tmp_path / "laws.py"
    law.write_text(
        "from dataclasses import dataclass\nimport numpy as np\n\n\n@dataclass(frozen=True)\nclass WrongDeriv:\n"
        "    c_T: float = 1e3\n    mu: float = 0.3\n\n    def slip_bound(self, p, q):\n"
        "        p = np.asarray(p, dtype=float)\n        return self.mu * p, 2 * self.mu + 0 * p, 0 * p\n"
    )
    warning = "contactfem: warning: friction law WrongDeriv: dY/dp does not match finite differences"
    for scene in ("block", EXAMPLE, edited(tmp_path, ("    law_range=law_range,\n", ""))):  # the last: no law_range
        assert main(["run", str(scene), "--friction", f"{law}:WrongDeriv", "--set", "n_steps=1"]) == 0
        err = capsys.readouterr().err
        assert err.startswith(warning), err


@pytest.mark.parametrize("scene", [EXAMPLE, "no_range"])
def test_a_law_that_returns_nan_is_refused_before_the_run(tmp_path, capsys, scene):
    """NaN above p = 50: refused (exit 2) before the run, over the file's law_range, or over check_law's
    default range where the file declares none."""
    scene = edited(tmp_path, *([("    law_range=law_range,\n", "")] if scene == "no_range" else []))
    line = one_line(capsys, ["run", scene, "--friction", f"{DATA / 'lying_laws.py'}:NaNAbove"], 2)
    assert line.startswith("contactfem: error: friction law NaNAbove.slip_bound returned NaN or inf"), line


@pytest.mark.parametrize(
    "returned, expected",
    [
        ("dict(p=0.0, dt=0.01)", "law_range: p = 0.0 is not a finite number > 0"),
        ("dict(p=1.0, q=float('nan'))", "law_range: q = nan is not a finite number >= 0"),
        ("dict(pressure=1.0)", "law_range: 'pressure' is not one of p, q, v, dt, g, hold"),
        ("[1.0]", "law_range: returned list, not a dict"),
    ],
)
def test_a_bad_law_range_is_one_line_naming_it(tmp_path, capsys, returned, expected):
    path = edited(tmp_path, ('    return dict(p=p["c_N"] * R,', f"    return {returned}\n    dict(p=p['c_N'] * R,"))
    law = f"{DATA / 'coulomb_law.py'}:MyCoulomb"
    line = one_line(capsys, ["run", path, "--friction", law, "--set", "law.c_T=1e3", "--set", "law.mu=0.3"], 1)
    assert line == f"contactfem: scene failed: scene file edited.py, {expected}", line
