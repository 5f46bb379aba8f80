"""Node-to-segment frictional contact (paper Secs 3.2, 4.2, 4.3): kinematics, masters, the
contact element, the contact's state as a value, and the interface that puts them together."""

from .element import contact_element, normal_element, to_coo
from .interface import NodeToSegment, tributary_lengths
from .kinematics import segment_geometry, segment_variations
from .masters import BodySurface, RigidArc, RigidComposite, RigidLine, RigidPolyline
from .state import ContactHistory, ContactState
from ..laws.return_map import OPEN, SLIP, STICK

__all__ = [
    "NodeToSegment",
    "tributary_lengths",
    "RigidLine",
    "RigidPolyline",
    "RigidArc",
    "RigidComposite",
    "BodySurface",
    "ContactHistory",
    "ContactState",
    "contact_element",
    "normal_element",
    "to_coo",
    "segment_geometry",
    "segment_variations",
    "OPEN",
    "STICK",
    "SLIP",
]
