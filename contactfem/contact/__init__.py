"""Node-to-segment frictional contact (paper Secs 3.2, 4.2, 4.3)."""

from .element import contact_element, to_coo
from .interface import NodeToSegment, tributary_lengths
from .kinematics import segment_geometry, segment_variations
from .masters import BodySurface, RigidArc, RigidLine, RigidPolyline
from ..laws.return_map import OPEN, SLIP, STICK, FrictionState, ReturnMapError, return_map

__all__ = ["NodeToSegment", "tributary_lengths", "RigidLine", "RigidPolyline", "RigidArc", "BodySurface",
           "return_map", "FrictionState", "ReturnMapError", "contact_element", "to_coo",
           "segment_geometry", "segment_variations", "OPEN", "STICK", "SLIP"]
