"""Interface laws (paper Sec. 2): normal laws give t_N(g_N); friction laws give the
stick stiffness c_T and the slip bound Y(p, q), or Y(p, q, v, z) with a slip rate v
and internal variables z (contactfem.laws.protocol). All are small frozen objects, so
a student's new law is a small class with the same methods (see check_law).
return_map.py integrates a friction law over a step (eqs 40-48): the stick/slip return
and its moduli."""

from .friction import Coulomb, Frictionless, ParabolicSlip, SlipHardening
from .normal import ExponentialLaw, PowerLaw
from .protocol import FrictionLaw, LawError, LawValueError, NormalLawView, as_friction_law, as_normal_law
from .rate_state import ArchardWear, DieterichRuina, Stribeck
from .return_map import OPEN, SLIP, STICK, FrictionState, ReturnMapError, return_map
from .check import LawReport, check_law

__all__ = [
    "PowerLaw",
    "ExponentialLaw",
    "ParabolicSlip",
    "Coulomb",
    "SlipHardening",
    "Frictionless",
    "Stribeck",
    "DieterichRuina",
    "ArchardWear",
    "FrictionLaw",
    "NormalLawView",
    "as_friction_law",
    "as_normal_law",
    "LawError",
    "LawValueError",
    "return_map",
    "FrictionState",
    "ReturnMapError",
    "OPEN",
    "STICK",
    "SLIP",
    "check_law",
    "LawReport",
]
