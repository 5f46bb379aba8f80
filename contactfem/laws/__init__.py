"""Interface laws (paper Sec. 2): normal laws give t_N(g_N); friction laws give the
stick stiffness c_T and the slip bound Y(p, q). Both are small frozen objects, so a
student's new law is a small class with the same methods (see check_law)."""

from .friction import Coulomb, Frictionless, ParabolicSlip, SlipHardening
from .normal import ExponentialLaw, PowerLaw

__all__ = ["PowerLaw", "ExponentialLaw", "ParabolicSlip", "Coulomb", "SlipHardening", "Frictionless"]

from .check import LawReport, check_law  # noqa: E402  (check uses the return mapping)

__all__ += ["check_law", "LawReport"]
