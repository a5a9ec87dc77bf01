"""Gear parameters: one involute spur gear, the double planetary gear set (sun, inner and outer planets, ring,
carrier) and the meshes' stiffness, damping and backlash (docs/model.md §1.1, §1.5, §6)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .. import geometry as geo
from .. import iso6336 as iso
from ..units import Quantity
from ._machinery import SI, Params, Source, computed, nested, nonneg, param, positive, rule, si_of

__all__ = ["GearParams", "GearSI", "GearSetParams", "GearSetSI", "MeshParams", "MeshSI"]


def _backlash(which: str):
    """Normal backlash of one mesh type: >= 0, or None for the ISO/TR 10064-2 minimum (see geometry)."""
    return param("length", f"normal backlash j_bn of the {which} (0: both flanks touch, not a real gear)",
                 default=None, lo=0.0, bound_text=">= 0", optional=True,
                 rule=Source("derived", "ISO/TR 10064-2 minimum for steel gears in a steel housing: "
                                        "j_bn,min = (2/3)(0.06 + 0.0005 a + 0.03 m_n) mm, a and m_n in mm"))


@dataclass(frozen=True, kw_only=True)
class GearParams(Params["GearSI"]):
    """One standard involute spur gear (no profile shift).

    si() (:class:`GearSI`) adds pitch_radius, base_radius, tip_radius, root_radius and resolves ``inertia``.
    """

    _prefix: ClassVar[str] = "gear"
    teeth: int = param("count", "number of teeth", lo=3, bound_text=">= 3")
    module: Quantity = positive("length", "module m")
    pressure_angle: Quantity = param("angle", "pressure angle α", lo=0.0, hi=math.pi / 4, lo_open=True,
                                     hi_open=True, bound_text="between 0 and 45 deg")
    face_width: Quantity = positive("length", "face width")
    mass: Quantity = positive("mass", "mass")
    inertia: Quantity | None = rule("inertia", "assumed", "solid disc at the pitch radius, m r^2/2; a planet of a "
                                                          "DPGT: annulus m (r^2 + r_bore^2)/2 with its bearing bore "
                                                          "(internal gear: thin ring at the pitch radius, m r^2)")
    internal: bool = param("flag", "internal gear (teeth inside, the ring)", default=False)
    addendum_coefficient: Quantity = nonneg("dimensionless", "addendum h_a/m (standard 1)", default=1.0)
    dedendum_coefficient: Quantity = nonneg("dimensionless", "dedendum h_f/m (standard 1.25)", default=1.25)
    tip_relief: Quantity = nonneg("length", "tip relief C_a: material removed at the tip, along the line of action "
                                            "(a profile modification; 0: none)", default="0 um")
    tip_relief_length: Quantity = nonneg("length", "length L_a of the tip relief: roll length along the line of "
                                                   "action from the tip", default="0 mm")
    tip_relief_shape: str = param("choice", "how the relief grows from its start to the tip", default="linear",
                                  choices=("linear", "parabolic"))

    def _si_values(self, v):
        g = geo.GearGeometry(teeth=v["teeth"], module=v["module"], pressure_angle=v["pressure_angle"],
                             internal=v["internal"], addendum_coefficient=v["addendum_coefficient"],
                             dedendum_coefficient=v["dedendum_coefficient"])
        inertia = v["inertia"]
        if inertia is None:
            inertia = v["mass"] * g.pitch_radius ** 2 * (1.0 if self.internal else 0.5)
        return dict(inertia=inertia, pitch_radius=g.pitch_radius, base_radius=g.base_radius,
                    tip_radius=g.tip_radius, root_radius=g.root_radius)


@si_of(GearParams)
class GearSI(SI):
    teeth: int
    module: float
    pressure_angle: float
    face_width: float
    mass: float
    inertia: float = computed("polar moment of inertia [kg m^2] (given, or the rule)")
    internal: bool
    addendum_coefficient: float
    dedendum_coefficient: float
    tip_relief: float
    tip_relief_length: float
    tip_relief_shape: str
    pitch_radius: float = computed("pitch circle radius m z / 2 [m]")
    base_radius: float = computed("base circle radius [m]")
    tip_radius: float = computed("tip (addendum) circle radius [m]")
    root_radius: float = computed("root (dedendum) circle radius [m]")


@dataclass(frozen=True, kw_only=True)
class GearSetParams(Params["GearSetSI"]):
    """Sun, inner planets, outer planets, ring and carrier of the double planetary set.

    ``handedness`` h: the outer planet stands at ψ_b = ψ_a + h·Δψ (+1: it leads its inner planet in the
    positive angular direction). ``planet_angle`` ψ_0: angle of pair 1's inner planet (a1) at t = 0.
    """

    _prefix: ClassVar[str] = "gears"
    sun: GearParams = nested(GearParams, "sun gear")
    inner_planet: GearParams = nested(GearParams, "inner planets (mesh with the sun)")
    outer_planet: GearParams = nested(GearParams, "outer planets (mesh with the ring)")
    ring: GearParams = nested(GearParams, "ring gear (internal)")
    carrier_mass: Quantity = positive("mass", "carrier mass")
    carrier_inertia: Quantity | None = rule("inertia", "assumed", "disc of radius 1.2 r_cb, m (1.2 r_cb)^2/2")
    carrier_torsional_stiffness: Quantity = positive("torsional_stiffness", "torsional stiffness k_tc of the carrier's "
                                                     "shaft-side plate against its far plate (wind-up)")
    carrier_plate_span: Quantity = positive("length", "axial distance L_c between the carrier's two plates (the pins' "
                                                      "supports)")
    carrier_windup: bool = param("flag", "tilt the pins by the carrier's wind-up under its torque (the sliced "
                                         "bearing model; docs/model.md §8.8)")
    planets: int = param("count", "planet pairs N", lo=1, bound_text=">= 1")
    handedness: int = param("sign", "planet-pair handedness h = +1 or -1")
    planet_angle: Quantity = param("angle", "angle psi_0 of the first inner planet", default="0 deg")

    def _si_values(self, v):
        if v["carrier_inertia"] is not None:
            return {}
        r_cb = 0.5 * v["sun"].module * (v["ring"].teeth - v["outer_planet"].teeth)
        return dict(carrier_inertia=0.5 * v["carrier_mass"] * (1.2 * r_cb) ** 2)


@si_of(GearSetParams)
class GearSetSI(SI):
    sun: GearSI
    inner_planet: GearSI
    outer_planet: GearSI
    ring: GearSI
    carrier_mass: float
    carrier_inertia: float = computed("carrier polar moment of inertia [kg m^2] (given, or the rule)")
    carrier_torsional_stiffness: float
    carrier_plate_span: float
    carrier_windup: bool
    planets: int
    handedness: int
    planet_angle: float


@dataclass(frozen=True, kw_only=True)
class MeshParams(Params["MeshSI"]):
    """Mesh stiffness and damping of the three meshes.

    k_mean of a mesh = ``mean_stiffness`` if given, else c_γα × the mesh's common face width, c_γα given (then
    common to the three meshes) or ISO 6336-1's for each mesh; the time-varying stiffness is a smoothed rectangular
    wave with k_double/k_single = ``stiffness_ratio``; ``smoothing_width`` is the width of its steps as a fraction
    of one mesh cycle. Resolved per mesh in ``DPGTParams.si().layout.meshes``.
    """

    _prefix: ClassVar[str] = "mesh"
    c_gamma_alpha: Quantity | None = rule(
        "stiffness_per_width", "derived",
        "ISO 6336-1:2019 clause 9 (method B), per mesh: c_gamma_alpha = c' (0.75 eps_alpha + 0.25), c' = c'_th C_M "
        "C_R C_B (w / 100 N/mm)^0.25 for a line load w = F_t/b < 100 N/mm (F_t of the operating point, K_A = 1; "
        "no correction without load), c'_th = 1/q', q' = 0.04723 + 0.15551/z_1 + 0.25791/z_2 mm um/N (no profile "
        "shift; the ring: z_2 = infinity), C_M = 0.8, C_R = 1 (solid blanks), C_B = 1 + 0.5 (1.2 - h_f/m) at 20 deg",
        "mean mesh stiffness per face width c_gamma_alpha (given: the same for the three meshes)")
    mean_stiffness: Quantity | None = rule("stiffness", "derived", "c_gamma_alpha x common face width of each mesh")
    stiffness_ratio: Quantity | None = param(
        "dimensionless", "k_double / k_single of the stiffness wave", default=None, lo=1.0, bound_text=">= 1",
        optional=True, rule=Source("derived", "ISO 6336-1:2019 clause 9: 1.75, since c_gamma_alpha = c' (0.75 "
                                              "eps_alpha + 0.25) = c' [1 + 0.75 (eps_alpha - 1)] is the mean of c' in "
                                              "single and 1.75 c' in double contact"))
    smoothing_width: Quantity = param("dimensionless", "step width of the stiffness wave, fraction of a mesh cycle",
                                      lo=0.0, hi=0.5, lo_open=True, bound_text="in (0, 0.5]")
    damping_ratio: Quantity = nonneg("dimensionless", "mesh damping ratio zeta_m")
    damping_ramp: Quantity = nonneg("length", "compression over which a flank's (a tooth pair's) damping grows from 0 "
                                              "at first touch to zeta_m's (0: all of it at first touch)")
    face_slices: int = param("count", "slices n_m of each mesh's face width when the planets tilt (bearing.model = "
                                      "sliced; docs/model.md §6.6)", lo=1, bound_text=">= 1")
    backlash_sun_inner: Quantity | None = _backlash("sun-inner planet meshes")
    backlash_inner_outer: Quantity | None = _backlash("inner-outer planet meshes")
    backlash_outer_ring: Quantity | None = _backlash("outer planet-ring meshes")

    def _si_values(self, v):
        if v["stiffness_ratio"] is not None:
            return {}
        return dict(stiffness_ratio=iso.SINGLE_DOUBLE_RATIO)


@si_of(MeshParams)
class MeshSI(SI):
    c_gamma_alpha: float | None = computed("given c_gamma_alpha [N/m^2], or None: ISO 6336-1's per mesh "
                                           "(layout.meshes[...].stiffness)")
    mean_stiffness: float | None
    stiffness_ratio: float = computed("k_double / k_single (given, or the rule's 1.75)")
    smoothing_width: float
    damping_ratio: float
    damping_ramp: float
    face_slices: int
    backlash_sun_inner: float | None
    backlash_inner_outer: float | None
    backlash_outer_ring: float | None
