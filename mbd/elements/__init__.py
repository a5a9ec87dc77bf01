"""Element families. Generic ones (supports, springs, loads, drives) and the contact/mesh laws used by components.

Law variants are small classes registered by name (a parameter chooses one): :data:`TRACTION_LAWS`
(roller–raceway traction: tanh, slide_roll, ehl), :data:`IMPACT_LAWS` (pocket and guide-land impact damping), :data:`LAND_LAWS` (dry or
hydrodynamic guide land),
:data:`STIFFNESS_SHAPES` (mesh stiffness over a mesh cycle)."""
from .contact import (IMPACT_LAWS, LAND_LAWS, TRACTION_LAWS, DryLand, EHLTraction, HydrodynamicLand, LandLaw, ExactRestitution, Flores, GuideContact, HuntCrossley, ImpactLaw,
                      LankaraniNikravesh, LubricantDrag, PocketContact, PocketRetention, RaceContact, SlideRollTraction, TanhTraction,
                      Traction)
from .pocket_film import CageDrag, PocketFilm
from .race_film import RaceFilm
from .drives import Ramp, Schedule, SpeedDrive, TorqueSource
from .gear_mesh import (STIFFNESS_SHAPES, ConstantStiffness, FourierStiffness, GearMesh, RectangularStiffness,
                        StiffnessShape, mesh_offset, mesh_u0)
from .loads import ForceSource
from .springs import BodySpring, GroundSupport, TorsionalSpring
from .tilt import BeamSupport, CoordinateSpring, SlopeGyroscopic

__all__ = [
    "BodySpring", "CageDrag", "PocketFilm", "ForceSource", "GearMesh", "GroundSupport", "GuideContact", "LubricantDrag", "PocketContact",
    "PocketRetention", "BeamSupport", "CoordinateSpring", "RaceContact", "RaceFilm", "Ramp", "Schedule", "SlopeGyroscopic", "SpeedDrive", "TorqueSource", "TorsionalSpring",
    "Traction", "TanhTraction", "SlideRollTraction", "EHLTraction", "TRACTION_LAWS",
    "LandLaw", "DryLand", "HydrodynamicLand", "LAND_LAWS",
    "ImpactLaw", "ExactRestitution", "HuntCrossley", "LankaraniNikravesh", "Flores", "IMPACT_LAWS",
    "StiffnessShape", "ConstantStiffness", "RectangularStiffness", "FourierStiffness", "STIFFNESS_SHAPES",
    "mesh_offset", "mesh_u0",
]
