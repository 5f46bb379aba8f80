"""A scene a user writes in a file of its own (contactfem/problem/files.py) runs like a shipped
one: `contactfem run FILE.py`, `show`, `sweep` with law.FIELD, `--friction`, `--json`, and
run_scene("FILE.py") from Python, with the same numbers; a broken file fails in one line
naming the file and the cause."""

import re
import json
import subprocess
import sys
from pathlib import Path

import pytest

from contactfem import run_scene
from contactfem.scenes import SceneError, get_scene

pytestmark = pytest.mark.slow  # end-to-end: command lines and processes (the fast tier leaves them out)

REPO = Path(__file__).resolve().parents[1]
EXAMPLE = REPO / "lectures" / "examples" / "disc_wall.py"
SHORT = {"n_steps": 40}  # the throw up to and through the first touch: a second's run

LAW = """
from dataclasses import dataclass
import numpy as np

@dataclass(frozen=True)
class Weakening:
    c_T: float = 1e3
    mu_s: float = 0.6
    mu_d: float = 0.2
    d_c: float = 0.05
    def slip_bound(self, p, q):
        return (self.mu_d + (self.mu_s - self.mu_d) * np.exp(-np.asarray(q) / self.d_c)) * np.asarray(p)
"""


def cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "contactfem", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300
    )


def test_the_example_is_short():
    assert len(EXAMPLE.read_text().splitlines()) < 70  # under 70 lines, all told


def test_cli_and_python_give_the_same_run(tmp_path):
    out = tmp_path / "disc.json"
    proc = cli("run", EXAMPLE, "--set", "n_steps=40", "--json", out)
    assert proc.returncode == 0, proc.stderr
    r_cli = json.loads(out.read_text())
    r_py = run_scene(str(EXAMPLE), "fast", SHORT)
    assert r_cli["scene"] == r_py["scene"] == "disc_wall"
    assert r_cli["scene_file"] == str(EXAMPLE)
    for key in ("rebound_vx", "rebound_vy", "newton_iterations_total", "energy_kinetic"):
        assert r_cli[key] == r_py[key], key  # one code path: bit for bit
    assert r_py["parameters"]["n_steps"] == 40


def test_show_lists_the_file_parameters():
    proc = cli("show", EXAMPLE)
    assert proc.returncode == 0, proc.stderr
    assert "disc_wall" in proc.stdout and "v0" in proc.stdout and "[0, 20]" in proc.stdout


def test_a_file_parameter_out_of_range_is_refused_before_the_run():
    proc = cli("run", EXAMPLE, "--set", "v0=50")
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "v0" in proc.stderr and "[0, 20]" in proc.stderr


def test_a_law_file_replaces_the_scene_law(tmp_path):
    law = tmp_path / "weak.py"
    law.write_text(LAW)
    out = tmp_path / "w.json"
    proc = cli(
        "run", EXAMPLE, "--set", "n_steps=40", "--friction", f"{law}:Weakening", "--set", "law.mu_s=0.8", "--json", out
    )
    assert proc.returncode == 0, proc.stderr
    r = json.loads(out.read_text())
    assert r["friction_law"]["class"] == "Weakening" and r["friction_law"]["fields"]["mu_s"] == 0.8
    assert "mu" not in r["parameters"] and "c_T" not in r["parameters"]  # the replaced law's parameters


def test_sweep_over_a_law_field(tmp_path):
    law = tmp_path / "weak.py"
    law.write_text(LAW)
    table = tmp_path / "t.csv"
    proc = cli(
        "sweep",
        EXAMPLE,
        "--set",
        "n_steps=40",
        "--friction",
        f"{law}:Weakening",
        "--set",
        "law.mu_d=0.1,0.3",
        "--out",
        table,
    )
    assert proc.returncode == 0, proc.stderr
    rows = table.read_text().splitlines()
    assert len(rows) == 3 and "disc_wall" in rows[1] and "disc_wall" in rows[2]


BROKEN = {
    "syntax": ("def build(:\n", "line 1: SyntaxError"),
    "import": ("import no_such_module_here\n", "line 1: ModuleNotFoundError"),
    "exit": ("import sys\nsys.exit(3)\n", "line 2: it calls sys.exit(3)"),
    "no_scene": ("x = 1\n", "defines no SCENE"),
    "not_a_scene": ("SCENE = 42\n", "SCENE is a int"),
}


@pytest.mark.parametrize("case", BROKEN)
def test_a_broken_file_fails_in_one_line(tmp_path, case):
    text, expected = BROKEN[case]
    path = tmp_path / f"{case}.py"
    path.write_text(text)
    proc = cli("run", path)
    assert proc.returncode == 2, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and f"scene file {path.name}" in line and expected in line, line
    with pytest.raises(ValueError, match=re.escape(expected)):
        get_scene(str(path))


def _edited(tmp_path, old, new):
    """The example with one line changed, beside a copy of its mesh."""
    text = EXAMPLE.read_text()
    assert old in text
    (tmp_path / "disc.msh").write_bytes((EXAMPLE.parent / "disc.msh").read_bytes())
    path = tmp_path / "edited.py"
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize(
    "role, old, new",
    [
        ("build", "    system = System(", "    1 / 0\n    system = System("),
        (
            "build",
            "return Model(systems=(system,), stage=stage, sizes=sizes, parts=dict(disc=disc))",
            "return [system]",
        ),
        (
            "build",
            "return Model(systems=(system,), stage=stage, sizes=sizes, parts=dict(disc=disc))",
            "return dict(disc=disc, systems=[system], stage=stage)",
        ),  # a dict is not a Model
        ("build", "stage=stage, sizes=sizes,", "stage=None, sizes=sizes,"),  # nothing to march
        ("measure", "return dict(rebound_vx=", "return None and dict(rebound_vx="),
    ],
)
def test_an_error_in_the_file_code_names_the_function(tmp_path, role, old, new):
    path = _edited(tmp_path, old, new)
    proc = cli("run", path, "--set", "n_steps=2")
    assert proc.returncode == 1, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and line.startswith("contactfem: scene failed: scene file edited.py, " + role), line
    with pytest.raises(SceneError, match=f"edited.py, {role}"):
        run_scene(str(path), "fast", {"n_steps": 2})


def test_a_scene_file_sweep_resumes_and_makes_its_folders(tmp_path):
    """--out in folders that do not exist yet: made when the table is written; --resume on a
    scene file keeps the rows of its points (the rows name the Scene, the sweep the file)."""
    table = tmp_path / "new" / "deeper" / "t.csv"
    args = ("sweep", EXAMPLE, "--set", "n_steps=5", "--set", "mu=0.1,0.2", "--out", table)
    proc = cli(*args)
    assert proc.returncode == 0, proc.stderr
    first = table.read_text()
    proc = cli(*args, "--resume")
    assert proc.returncode == 0, proc.stderr
    assert "2 kept from the table" in proc.stdout + proc.stderr
    assert table.read_text() == first  # nothing ran again


def test_an_empty_law_name_is_refused():
    for option in ("--friction", "--normal"):
        proc = cli("run", EXAMPLE, option, "")
        assert proc.returncode == 2 and option in proc.stderr and "\n" not in proc.stderr.strip(), proc.stderr


def test_a_law_object_replaces_the_parameters_that_build_the_scene_law(tmp_path):
    law = tmp_path / "weak.py"
    law.write_text(LAW)
    out = tmp_path / "w.json"
    proc = cli("run", EXAMPLE, "--set", "n_steps=3", "--friction", f"{law}:Weakening", "--json", out)
    assert proc.returncode == 0, proc.stderr
    r = json.loads(out.read_text())
    assert not {"mu", "c_T"} & set(r["parameters"]), r["parameters"]
    assert r["friction_law"]["fields"]["c_T"] == 1e3


def test_a_scene_whose_build_returns_no_model_is_refused_naming_it():
    """A Scene built in Python (no file to guard) whose build returns a dict: one line naming
    the scene and what it returned, before anything is marched."""
    from contactfem.scenes import Param, Scene, run_scene

    scene = Scene(
        "dicty",
        "t",
        (Param("x", 1.0),),
        build=lambda params, **kw: {"systems": [], "stage": None},
        measure=lambda model, params, records: {},
    )
    with pytest.raises(TypeError, match=r"^scene dicty, build: returned dict, not a Model") as err:
        run_scene(scene, "fast")
    assert "\n" not in str(err.value)
