"""Element families. Generic ones (supports, springs, drives) and the contact/mesh laws used by components."""
from .springs import GroundSupport, BodySpring, TorsionalSpring
from .drives import TorqueSource, SpeedDrive, Ramp

__all__ = ["GroundSupport", "BodySpring", "TorsionalSpring", "TorqueSource", "SpeedDrive", "Ramp"]
