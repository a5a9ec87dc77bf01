"""The whole machine: :class:`DPGTParams` (gears, planet bearing, lubricant, supports, meshes, operating point,
rig, gravity, errors) and the sections its ``si()`` extends: the supports with the ring's torsional stiffness,
the operating point with its nominal kinematics (docs/model.md §1, §5.1, §10.3)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from .. import geometry as geo
from ..units import Quantity
from ._machinery import SI, Params, computed, fields_of, nested, nonneg, si_extends, si_of
from .bearing import BearingParams, BearingSI, LubricantParams, LubricantSI
from .errors import ErrorsParams, ErrorsSI
from .gears import GearSetParams, GearSetSI, MeshParams, MeshSI
from .operating import OperatingPoint, OperatingSI, RigParams, RigSI

__all__ = ["SupportParams", "SupportSI", "DPGTSupportSI", "DPGTOperatingSI", "DPGTParams", "DPGTSI"]


@dataclass(frozen=True, kw_only=True)
class SupportParams(Params["SupportSI"]):
    """Isotropic translational supports of sun, ring and carrier; torsional support of the ring.

    The ring's torsional support is given as a tangential stiffness k on u = r_r·θ_r (r_r its pitch
    radius); ``DPGTParams.si().support`` adds ring_torsional_stiffness = k·r_r^2 [N·m/rad].
    """

    _prefix: ClassVar[str] = "support"
    sun_stiffness: Quantity = nonneg("stiffness", "sun translational support stiffness")
    ring_stiffness: Quantity = nonneg("stiffness", "ring translational support stiffness")
    carrier_stiffness: Quantity = nonneg("stiffness", "carrier translational support stiffness")
    damping_ratio: Quantity = nonneg("dimensionless", "support damping ratio")
    ring_tangential_stiffness: Quantity = nonneg("stiffness", "ring torsional support as tangential stiffness "
                                                              "at the ring pitch radius")


@si_of(SupportParams)
class SupportSI(SI):
    sun_stiffness: float
    ring_stiffness: float
    carrier_stiffness: float
    damping_ratio: float
    ring_tangential_stiffness: float


# the operating point and the supports as the whole machine sees them (they need the gears)
@si_extends
class DPGTOperatingSI(OperatingSI):
    """An operating point with its nominal speeds [rad/s], frequencies [Hz] and torques [N m] (:class:`geometry.Kinematics`)."""
    sun_speed: float = computed("see geometry.Kinematics")
    inner_planet_speed: float = computed("see geometry.Kinematics")
    outer_planet_speed: float = computed("see geometry.Kinematics")
    carrier_frequency: float = computed("see geometry.Kinematics")
    mesh_frequency: float = computed("see geometry.Kinematics")
    sun_torque: float = computed("see geometry.Kinematics")
    carrier_torque: float = computed("see geometry.Kinematics")
    ring_torque: float = computed("see geometry.Kinematics")


@si_extends
class DPGTSupportSI(SupportSI):
    """Supports with the ring's torsional stiffness."""
    ring_torsional_stiffness: float = computed("ring_tangential_stiffness x r_ring^2 [N m/rad]")


@dataclass(frozen=True, kw_only=True)
class DPGTParams(Params["DPGTSI"]):
    """The whole machine: gears, planet bearing (with cage), lubricant, supports, meshes, operating
    point and gravity (magnitude, along −Y of the fixed frame).

    si() has one section per field plus ``layout`` (:class:`geometry.Layout`); ``support`` gains
    ring_torsional_stiffness and ``operating`` the fields of :class:`geometry.Kinematics`. It raises
    ParameterError if the gears cannot be laid out: run :func:`geometry.check_design` first.
    """

    _prefix: ClassVar[str] = ""
    gears: GearSetParams = nested(GearSetParams, "gear set")
    bearing: BearingParams = nested(BearingParams, "planet bearing")
    lubricant: LubricantParams = nested(LubricantParams, "lubricant")
    support: SupportParams = nested(SupportParams, "supports")
    mesh: MeshParams = nested(MeshParams, "meshes")
    operating: OperatingPoint = nested(OperatingPoint, "operating point")
    rig: RigParams = nested(RigParams, "test rig: carrier speed drive and load ramp")
    gravity: Quantity = nonneg("acceleration", "gravitational acceleration (0 switches gravity off)")
    errors: ErrorsParams = nested(ErrorsParams, "manufacturing errors and faults (every list empty: the perfect "
                                                "machine)")

    def _si_values(self, v):
        gears = _planets_with_bore(self.gears, v["gears"], v["bearing"].outer_raceway_radius)
        sup = v["support"]
        support = DPGTSupportSI(**fields_of(sup), ring_torsional_stiffness=(
            sup.ring_tangential_stiffness * gears.ring.pitch_radius ** 2))
        lay = geo.layout(self, gears_si=gears, mesh_si=v["mesh"])
        mesh = v["mesh"].replace(**{f"backlash_{k}": m.backlash for k, m in lay.meshes.items()})
        op = v["operating"]
        kin = geo.kinematics(gears.sun.teeth, gears.inner_planet.teeth, gears.outer_planet.teeth,
                             gears.ring.teeth, op.carrier_speed, op.output_power)
        operating = DPGTOperatingSI(**{**fields_of(op), **fields_of(kin)})
        return dict(gears=gears, support=support, mesh=mesh, operating=operating, layout=lay)


@si_of(DPGTParams)
class DPGTSI(SI):
    gears: GearSetSI = computed("gear set; planet inertias resolved with the bearing bore")
    bearing: BearingSI
    lubricant: LubricantSI
    support: DPGTSupportSI = computed("supports and the ring's torsional stiffness")
    mesh: MeshSI = computed("meshes, backlash resolved per mesh type")
    operating: DPGTOperatingSI = computed("operating point with its nominal speeds and torques")
    rig: RigSI
    gravity: float
    errors: ErrorsSI
    layout: geo.Layout = computed("planet positions, meshes, phases (geometry.Layout)")


def _planets_with_bore(gears: GearSetParams, g: "GearSetSI", bore: float) -> "GearSetSI":
    """The planets' inertia rule in a DPGT: an annulus m (r^2 + r_bore^2)/2, the bore being the
    bearing's outer raceway (given inertias stay)."""
    for name in ("inner_planet", "outer_planet"):
        if getattr(gears, name).inertia is None:
            gp = getattr(g, name)
            g = g.replace(**{name: gp.replace(inertia=0.5 * gp.mass * (gp.pitch_radius ** 2 + bore ** 2))})
    return g
