"""A student's law that breaks the protocol in a way the checks once missed: one number for all
contact nodes (named by its shape, not blamed on the complex step or on Newton), a complex slip
bound (refused, not cut to its real part), a law file that exits when imported (one line naming
the file, exit 2)."""

import textwrap

import pytest

from contactfem import check_law
from contactfem.cli import main
from contactfem.lab.lawfile import load_class

LAWS = '''
import sys
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MeanLaw:
    """One number for all nodes: the mean pressure's bound."""
    c_T: float = 1.0e4
    mu: float = 0.5

    def slip_bound(self, p, q):
        return self.mu * np.mean(p)


@dataclass(frozen=True)
class ConstantLaw:
    """One number for all nodes that does not depend on them (a Tresca bound): allowed."""
    c_T: float = 1.0e4
    Y0: float = 80.0

    def slip_bound(self, p, q):
        return self.Y0, 0.0, 0.0


@dataclass(frozen=True)
class ComplexLaw:
    """A slip bound with an imaginary part."""
    c_T: float = 1.0e4
    mu: float = 0.5

    def slip_bound(self, p, q):
        return self.mu * p + 0.1j * self.mu * p, self.mu + 0.1j * self.mu, 0.0 * p
'''


@pytest.fixture
def lawfile(tmp_path):
    path = tmp_path / "laws.py"
    path.write_text(LAWS)
    return path


def _one_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0], err
    return err[0]


def test_one_number_for_all_nodes_is_named_by_its_shape(lawfile, capsys):
    law = load_class(f"{lawfile}:MeanLaw")()
    report = check_law(law)
    text = str(report)
    assert not report.ok and "one number for all" in text and "shape" in text
    assert "complex step" not in text, text
    assert main(["run", "block", "--friction", f"{lawfile}:MeanLaw"]) == 2
    line = _one_line(capsys)
    assert "MeanLaw.slip_bound returned one number for all" in line and "np.mean(p)" in line, line


def test_one_number_that_does_not_change_is_one_for_every_node(lawfile):
    assert check_law(load_class(f"{lawfile}:ConstantLaw")()).errors == []


def test_a_complex_slip_bound_is_refused(lawfile, capsys):
    report = check_law(load_class(f"{lawfile}:ComplexLaw")())
    assert not report.ok and "is complex" in str(report), str(report)
    code = main(["run", "block", "--friction", f"{lawfile}:ComplexLaw"])
    line = _one_line(capsys)
    assert code in (1, 2) and "ComplexLaw.slip_bound: Y is complex" in line, line


def test_a_law_file_that_exits_at_import_is_one_line(tmp_path, capsys):
    path = tmp_path / "quits.py"
    path.write_text(
        textwrap.dedent("""
        import sys
        sys.exit(3)
    """)
    )
    assert main(["run", "block", "--friction", f"{path}:Anything"]) == 2
    line = _one_line(capsys)
    assert "law file quits.py, line 3" in line and "sys.exit(3)" in line, line


def test_a_complex_normal_traction_is_refused():
    from dataclasses import dataclass

    import numpy as np

    from contactfem.laws.protocol import LawValueError, as_normal_law

    @dataclass(frozen=True)
    class ComplexPenalty:
        c_N: float = 10.0

        def traction(self, g_N):
            return self.c_N * np.sqrt(g_N + 0j), self.c_N * 0.5 / np.sqrt(g_N + 0j)  # imaginary where g_N < 0

    with pytest.raises(LawValueError, match=r"ComplexPenalty.traction: t_N is complex, .* at g_N = -0.5"):
        as_normal_law(ComplexPenalty()).traction(np.array([0.5, -0.5]))
