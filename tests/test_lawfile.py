"""Laws from files for the command line: FILE.py:CLASS, fields set like scene
parameters and validated the same way, one line naming file, line and cause for any
error in the file."""

from pathlib import Path

import pytest

from contactfem.lab.lawfile import describe, laws_from_options, load_class, make_law, split_sets

DATA = Path(__file__).parent / "data"
SAT = f"{DATA / 'saturating.py'}:Saturating"


def test_load_and_set_fields():
    laws = laws_from_options(friction=SAT, law_sets=split_sets({"law.mu0": "0.6", "dt": "0.1"})[1])
    law = laws["friction"]
    assert type(law).__name__ == "Saturating" and law.mu0 == 0.6 and law.c_T == 30.0
    rec = describe(law)
    assert rec["class"] == "Saturating" and rec["file"].endswith("saturating.py")
    assert rec["fields"] == {"c_T": 30.0, "mu0": 0.6, "p0": 1000.0}


def test_fields_default_to_the_scene_parameters_of_the_same_name():
    law = laws_from_options(friction=f"{DATA / 'coulomb_law.py'}:MyCoulomb", scene_params={"c_T": 7.0, "mu": 0.15})[
        "friction"
    ]
    assert (law.c_T, law.mu) == (7.0, 0.15)
    law = laws_from_options(
        friction=f"{DATA / 'coulomb_law.py'}:MyCoulomb",
        scene_params={"c_T": 7.0, "mu": 0.15},
        law_sets=split_sets({"law.mu": "0.3"})[1],
    )["friction"]
    assert law.mu == 0.3


def test_split_sets():
    scene, laws = split_sets({"mu": "0.3", "law.mu0": "1", "normal.c_N": "2", "friction.c_T": "3"})
    assert scene == {"mu": "0.3"} and laws == {"law": {"mu0": "1"}, "friction": {"c_T": "3"}, "normal": {"c_N": "2"}}


@pytest.mark.parametrize(
    "spec,sets,pattern",
    [
        ("saturating.py", {}, r"--friction expects FILE.py:CLASS"),
        ("nowhere.py:X", {}, r"law file .*nowhere.py not found"),
        ("saturating.py:Nope", {}, r"law file saturating.py has no class Nope \(it defines: Saturating\)"),
        ("broken_syntax.py:Broken", {}, r"^law file broken_syntax.py, line 8: SyntaxError"),
        ("math_law.py:MathTanh", {}, r"^law file math_law.py, line 11: .*np.tanh, not math.tanh"),
        ("saturating.py:Saturating", {"law.mu0": "-1"}, r"parameter mu0 = -1.0 is out of range: allowed \[0, inf\)"),
        ("saturating.py:Saturating", {"law.mu0": "abc"}, r"law parameter mu0 must be a number, got 'abc'"),
        (
            "saturating.py:Saturating",
            {"law.nu": "1"},
            r"unknown law parameter law.nu for Saturating: known are c_T, mu0, p0",
        ),
        ("coulomb_law.py:MyCoulomb", {}, r"law parameter c_T of MyCoulomb has no default .*--set law.c_T=VALUE"),
    ],
)
def test_errors_are_one_line(spec, sets, pattern):
    with pytest.raises(ValueError, match=pattern) as err:
        laws_from_options(friction=str(DATA / spec), law_sets=split_sets(sets)[1])
    assert "\n" not in str(err.value)


def test_law_sets_need_a_law_file():
    with pytest.raises(ValueError, match="--set law.mu0 needs --friction"):
        laws_from_options(law_sets=split_sets({"law.mu0": "1"})[1])
    with pytest.raises(ValueError, match="--set normal.c_N needs --normal"):
        laws_from_options(friction=SAT, law_sets=split_sets({"normal.c_N": "1"})[1])


def test_runtime_error_in_a_law_names_the_file_and_line(tmp_path):
    f = tmp_path / "bad.py"
    f.write_text(
        "from dataclasses import dataclass\n\n\n@dataclass(frozen=True)\nclass Bad:\n    c_T: float = 1.0\n\n"
        "    def slip_bound(self, p, q):\n        return p / undefined_name\n"
    )
    with pytest.raises(
        ValueError,
        match=r"^law file bad.py, line 9: Bad.slip_bound raised NameError: name 'undefined_name' is not defined",
    ):
        make_law(load_class(f"{f}:Bad"))


def test_a_normal_law_from_a_file(tmp_path):
    f = tmp_path / "normal.py"
    f.write_text(
        "from dataclasses import dataclass\nimport numpy as np\n\n\n@dataclass(frozen=True)\nclass Lin:\n"
        "    c_N: float = 10.0\n\n    def traction(self, g):\n        g = np.asarray(g, float)\n"
        "        return np.where(g < 0, self.c_N * g, 0.0), np.where(g < 0, self.c_N, 0.0)\n"
    )
    laws = laws_from_options(normal=f"{f}:Lin", friction=SAT, law_sets=split_sets({"law.c_N": "3"})[1])
    assert laws["normal"].c_N == 3.0 and laws["friction"].mu0 == 0.3


def test_an_integer_field_takes_integers_only(tmp_path):
    """A field annotated int takes 3, "3", "3.0" (the integer 3) and refuses 2.5 as not an integer."""
    path = tmp_path / "stepped.py"
    path.write_text(
        "from dataclasses import dataclass\nimport numpy as np\n\n\n@dataclass(frozen=True)\nclass Stepped:\n"
        "    c_T: float = 10.0\n    k: int = 2\n\n    def slip_bound(self, p, q):\n"
        "        return 0.1 * self.k * np.asarray(p)\n"
    )
    for text in ("3", "3.0", "3e0"):
        law = laws_from_options(friction=f"{path}:Stepped", law_sets=split_sets({"law.k": text})[1])["friction"]
        assert law.k == 3 and type(law.k) is int
    with pytest.raises(ValueError, match=r"^law parameter k must be an integer, got '2.5'$"):
        laws_from_options(friction=f"{path}:Stepped", law_sets=split_sets({"law.k": "2.5"})[1])
