"""Element families. Generic ones (supports, springs, loads, drives) and the contact/mesh laws used by components."""
from .contact import (TRACTION_LAWS, GuideContact, LubricantDrag, PocketContact, RaceContact, SlideRollTraction,
                      TanhTraction, Traction)
from .drives import Ramp, SpeedDrive, TorqueSource
from .gear_mesh import GearMesh, StiffnessShape, mesh_offset, mesh_u0
from .loads import ForceSource
from .springs import BodySpring, GroundSupport, TorsionalSpring

__all__ = [
    "BodySpring", "ForceSource", "GearMesh", "GroundSupport", "GuideContact", "LubricantDrag", "PocketContact",
    "RaceContact", "Ramp", "SpeedDrive", "StiffnessShape", "TorqueSource", "TorsionalSpring", "Traction", "TanhTraction", "SlideRollTraction", "TRACTION_LAWS",
    "mesh_offset", "mesh_u0",
]
