"""The return mapping lives beside the laws it integrates, in ``contactfem.laws.return_map``;
this name is kept so that ``contactfem.contact.return_map`` still imports."""

from ..laws.return_map import (OPEN, SLIP, STATE_NAMES, STICK, FrictionState,  # noqa: F401
                               ReturnMapError, return_map)
