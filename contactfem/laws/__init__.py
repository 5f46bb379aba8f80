"""Interface laws (paper Sec. 2): normal laws give t_N(g_N); friction laws give the
stick stiffness c_T and the slip bound Y(p, q), or Y(p, q, v, z) with a slip rate v
and internal variables z (contactfem.laws.protocol). All are small frozen objects, so
a student's new law is a small class with the same methods (see check_law)."""

from .friction import Coulomb, Frictionless, ParabolicSlip, SlipHardening
from .normal import ExponentialLaw, PowerLaw
from .protocol import FrictionLaw, LawError
from .rate_state import ArchardWear, DieterichRuina, Stribeck

__all__ = ["PowerLaw", "ExponentialLaw", "ParabolicSlip", "Coulomb", "SlipHardening", "Frictionless",
           "Stribeck", "DieterichRuina", "ArchardWear", "FrictionLaw", "LawError"]

from .check import LawReport, check_law  # noqa: E402  (check uses the return mapping)

__all__ += ["check_law", "LawReport"]
