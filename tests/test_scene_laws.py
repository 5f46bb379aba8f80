"""Every scene takes law objects (normal=, friction=), and so does the command line
(--friction / --normal FILE.py:CLASS, fields with --set law.NAME=VALUE), recorded in
the JSON. A Coulomb law written in a law file gives the built-in law's results; a law's
fields keep their own defaults (a field without one takes the scene's parameter)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from contactfem.laws import Coulomb, PowerLaw
from contactfem.lab.lawfile import laws_from_options
from contactfem.scenes import get_scene, run_scene

REPO = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data"
SCENES = ["rolling_ring", "sloping_impact", "funnel", "cork", "block"]

# Each scene with its built-in law set up as Coulomb (eq 11) with coefficient `mu`,
# in a short run (the comparison needs no long one): overrides for the built-in run
# and the mu the law file's Coulomb law gets.
COULOMB_SETUPS = {
    "block": ({"law": "coulomb"}, "mu"),
    "rolling_ring": ({"t_end": 0.4}, "mu"),
    "sloping_impact": ({"variant": "frictional", "n": 1.0, "n_steps": 60}, "alpha+beta"),
    "funnel": ({"variant": "frictional", "n": 1.0, "n_steps": 40}, "alpha+beta"),
    "cork": ({"h": 0.0, "t_end": 0.001}, "mu"),
}


def _leaves(obj, prefix=""):
    """(path, float array) for every numeric leaf of a results dict."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k in ("wall_time_s", "parameters", "friction_law", "normal_law", "scene", "preset") or k.startswith(
                "paper"
            ):  # the paper's numbers: of its own laws, not a result
                continue
            yield from _leaves(v, f"{prefix}/{k}")
    else:
        try:
            a = np.asarray(obj, dtype=float)
        except (TypeError, ValueError):
            return
        yield prefix, a


def _cli(*args, cwd=REPO):
    return subprocess.run([sys.executable, "-m", "contactfem", *args], capture_output=True, text=True, cwd=cwd)


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_cli_runs_every_scene_with_a_law_file(scene, tmp_path):
    """contactfem run SCENE --friction tests/data/saturating.py:Saturating: exit 0, the JSON
    records the law (class, file, fields: the law's own defaults, not the scene's c_T), the
    variant is the law, and the scene parameters the law replaces are not in the record."""
    out = tmp_path / "r.json"
    proc = _cli("run", scene, "--friction", "tests/data/saturating.py:Saturating", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    assert "note" not in proc.stderr  # every field has a default: none from the scene
    res = json.loads(out.read_text())
    rec = res["friction_law"]
    assert rec == {
        "class": "Saturating",
        "file": "tests/data/saturating.py",
        "fields": {"c_T": 30.0, "mu0": 0.3, "p0": 1000.0},
    }
    sc = get_scene(scene)
    assert not set(sc.law_params["friction"]) & set(res["parameters"])
    if "variant" in res:
        assert res["variant"] == "Saturating"


@pytest.mark.slow
@pytest.mark.parametrize("scene", SCENES)
def test_a_coulomb_law_file_equals_the_built_in_law(scene):
    over, mu_from = COULOMB_SETUPS[scene]
    params = get_scene(scene).resolve("fast", over)
    mu = params["alpha"] + params["beta"] if mu_from == "alpha+beta" else params["mu"]
    law = laws_from_options(friction=f"{DATA / 'coulomb_law.py'}:MyCoulomb", scene_params=dict(params, mu=mu))[
        "friction"
    ]
    assert type(law).__name__ == "MyCoulomb" and law.mu == mu and law.c_T == params["c_T"]
    built_in = run_scene(scene, "fast", over)
    sc = get_scene(scene)
    mine = run_scene(
        scene, "fast", {k: v for k, v in over.items() if sc.law_param_kind(k, v) != "friction"}, friction=law
    )
    assert mine["friction_law"]["fields"] == {"c_T": params["c_T"], "mu": mu}
    if scene == "rolling_ring":
        # the rigid ring's closed forms are reference values for the Coulomb class the toolkit
        # knows, not results of the run: a law class of one's own has none (None)
        from contactfem.scenes.rolling_ring import CLOSED_FORM_KEYS

        assert all(mine[k] is None for k in CLOSED_FORM_KEYS) and built_in["exact_mu"] == mu
        mine = {k: v for k, v in mine.items() if k not in CLOSED_FORM_KEYS}
        built_in = {k: v for k, v in built_in.items() if k not in CLOSED_FORM_KEYS}
        # so are the accuracy indicators that measure the run against them
        refs = ("v_final", "x_end")
        assert all(k in built_in["accuracy"] and k not in mine["accuracy"] for k in refs)
        built_in["accuracy"] = {k: v for k, v in built_in["accuracy"].items() if k not in refs}
    # the converged residual over the force scale is round-off (1e-9 of it here): both within its threshold
    assert mine["accuracy"]["equilibrium"]["ok"] and built_in["accuracy"]["equilibrium"]["ok"]
    mine["accuracy"].pop("equilibrium"), built_in["accuracy"].pop("equilibrium")
    a, b = dict(_leaves(mine)), dict(_leaves(built_in))
    assert a.keys() == b.keys() and len(a) > 3
    for key in b:
        assert a[key].shape == b[key].shape, key
        assert np.array_equal(np.isnan(a[key]), np.isnan(b[key])), key  # None (not reached) in both
        x, y = a[key][~np.isnan(b[key])], b[key][~np.isnan(b[key])]
        scale = max(float(np.max(np.abs(y), initial=0.0)), 1e-300)
        assert np.all(np.abs(x - y) <= 1e-10 * scale), (key, np.max(np.abs(x - y)))


def test_a_shipped_law_object_from_python():
    """The Python side: run_scene(..., friction=Coulomb(...), normal=PowerLaw(...)) equals the
    parameters that build the same laws, and records both laws (file None: shipped)."""
    over = {"law": "coulomb", "mu": 0.35, "c_N": 2e5}
    p = get_scene("block").resolve("fast", over)
    a = run_scene("block", "fast", over)
    b = run_scene("block", "fast", friction=Coulomb(c_T=p["c_T"], mu=0.35), normal=PowerLaw(c_N=2e5, m=p["m"]))
    assert b["friction_law"] == {"class": "Coulomb", "file": None, "fields": {"c_T": p["c_T"], "mu": 0.35}}
    assert b["normal_law"]["class"] == "PowerLaw"
    assert a["total_tangential"] == b["total_tangential"] and a["newton_residuals"] == b["newton_residuals"]


@pytest.mark.slow
def test_cli_law_fields_and_errors(tmp_path):
    out = tmp_path / "b.json"
    ok = _cli(
        "run",
        "block",
        "--friction",
        "tests/data/saturating.py:Saturating",
        "--set",
        "law.mu0=0.6",
        "--set",
        "law.p0=500",
        "--json",
        str(out),
    )
    assert ok.returncode == 0, ok.stderr
    assert json.loads(out.read_text())["friction_law"]["fields"] == {"c_T": 30.0, "mu0": 0.6, "p0": 500.0}
    for args, pattern in [
        (
            ("--friction", "tests/data/saturating.py:Saturating", "--set", "law.mu0=-1"),
            "parameter mu0 = -1.0 is out of range",
        ),
        (("--friction", "tests/data/broken_syntax.py:Broken"), "law file broken_syntax.py, line 8: SyntaxError"),
        (("--friction", "tests/data/math_law.py:MathTanh"), "law file math_law.py, line 11: .*math.tanh"),
        (("--friction", "tests/data/nowhere.py:X"), "law file tests/data/nowhere.py not found"),
        (("--set", "law.mu0=1"), "needs --friction"),
    ]:
        bad = _cli("run", "block", *args)
        assert bad.returncode == 2, (args, bad.stderr)
        lines = bad.stderr.strip().splitlines()
        assert len(lines) == 1 and __import__("re").search(pattern, lines[0]), (args, bad.stderr)
