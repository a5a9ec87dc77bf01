"""Manufacturing errors and faults (docs/model.md §11): lists of entries, none by default (a perfect machine).
Each entry names its gear or planet ("sun", "ring", "a1".."aN" inner, "b1".."bN" outer planets)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..units import Quantity
from ._machinery import SI, Params, entries, named, nonneg, param, param_fields, positive, si_of

__all__ = ["PinholeErrorParams", "PinholeErrorSI", "RunoutParams", "RunoutSI", "RollerDiameterErrorParams",
           "RollerDiameterErrorSI", "SpallParams", "SpallSI", "ToothFaultParams", "ToothFaultSI",
           "ToothDeviationParams", "ToothDeviationSI", "FlankClassParams", "FlankClassSI", "PinSlopeParams",
           "PinSlopeSI", "PinholeEndsParams", "PinholeEndsSI", "ErrorsParams", "ErrorsSI"]


_PLANET = r"[ab][1-9][0-9]*"
_PLANET_TEXT = "a planet name 'a1'..'aN' (inner) or 'b1'..'bN' (outer)"
_GEAR = r"sun|ring|" + _PLANET
_GEAR_TEXT = "a gear name: 'sun', 'ring', 'a1'..'aN' or 'b1'..'bN'"


@dataclass(frozen=True, kw_only=True)
class PinholeErrorParams(Params["PinholeErrorSI"]):
    """A carrier pinhole off its nominal position: the planet's pin (its bearing's inner raceway) is
    displaced on the carrier, radially (away from the carrier axis +) and tangentially (+ in the sense of
    increasing planet angle)."""
    _prefix: ClassVar[str] = "errors.pinhole"
    planet: str = named(_PLANET, _PLANET_TEXT, "the planet whose pin is displaced")
    radial: Quantity = param("length", "radial position error of the pin (+ outwards)")
    tangential: Quantity = param("length", "tangential position error of the pin (+ with the planet angle)")


@si_of(PinholeErrorParams)
class PinholeErrorSI(SI):
    planet: str
    radial: float
    tangential: float


@dataclass(frozen=True, kw_only=True)
class PinSlopeParams(Params["PinSlopeSI"]):
    """A planet's pin not parallel to the carrier axis (a pinhole's two ends off by different amounts across the
    face): the pin's axis slopes by ``slope`` in the direction ``direction`` measured in the carrier from the
    planet's radial line (0: radial, outwards at +ζ; 90 deg: tangential, with the planet angle). Seen only by the
    sliced bearing model (bearing.model = "sliced", docs/model.md §8.8). A pinhole measured at its two ends:
    errors.pinhole_ends."""
    _prefix: ClassVar[str] = "errors.pin_slope"
    planet: str = named(_PLANET, _PLANET_TEXT, "the planet whose pin slopes")
    slope: Quantity = nonneg("angle", "the pin's slope against the carrier axis (e.g. '4 arcmin')")
    direction: Quantity = param("angle", "its direction from the planet's radial line (0 radial, 90 deg tangential)")


@si_of(PinSlopeParams)
class PinSlopeSI(SI):
    planet: str
    slope: float
    direction: float


@dataclass(frozen=True, kw_only=True)
class PinholeEndsParams(Params["PinholeEndsSI"]):
    """A planet's pinhole as it is measured: the radial and tangential position errors of its pin's two ends, in the
    carrier's shaft-side plate (at ζ = +L_c/2) and in its far plate (at ζ = −L_c/2), L_c = gears.carrier_plate_span.
    The model takes their mean as the pin's position error (errors.pinhole) and their difference over L_c as its
    slope (errors.pin_slope: radial part (r_shaft − r_far)/L_c, tangential (t_shaft − t_far)/L_c;
    components.faults.pinhole_from_ends, docs/model.md §11.1). A planet's pinhole is given in this form or in the
    other two, not both. Ends that differ need the sliced bearing model (bearing.model = "sliced")."""
    _prefix: ClassVar[str] = "errors.pinhole_ends"
    planet: str = named(_PLANET, _PLANET_TEXT, "the planet whose pinhole is measured")
    radial_shaft_plate: Quantity = param("length", "radial position error of the pin's end in the shaft-side carrier "
                                                   "plate, at +L_c/2 (+ outwards)")
    tangential_shaft_plate: Quantity = param("length", "tangential position error of the pin's end in the shaft-side "
                                                       "plate (+ with the planet angle)")
    radial_far_plate: Quantity = param("length", "radial position error of the pin's end in the far carrier plate, at "
                                                 "-L_c/2 (+ outwards)")
    tangential_far_plate: Quantity = param("length", "tangential position error of the pin's end in the far plate "
                                                     "(+ with the planet angle)")


@si_of(PinholeEndsParams)
class PinholeEndsSI(SI):
    planet: str
    radial_shaft_plate: float
    tangential_shaft_plate: float
    radial_far_plate: float
    tangential_far_plate: float


@dataclass(frozen=True, kw_only=True)
class RunoutParams(Params["RunoutSI"]):
    """Eccentricity of a gear's teeth: their centre sits ``eccentricity`` from the gear's rotation centre,
    at ``phase`` in the gear's body axes (tooth 0 at phase 0), turning with the gear; the meshes see it
    through their exact kinematics. Radial runout (total indicator reading) = 2 × eccentricity."""
    _prefix: ClassVar[str] = "errors.runout"
    gear: str = named(_GEAR, _GEAR_TEXT, "the eccentric gear")
    eccentricity: Quantity = nonneg("length", "offset of the tooth centre from the rotation centre (runout / 2)")
    phase: Quantity = param("angle", "direction of the offset in the gear's body axes")


@si_of(RunoutParams)
class RunoutSI(SI):
    gear: str
    eccentricity: float
    phase: float


@dataclass(frozen=True, kw_only=True)
class RollerDiameterErrorParams(Params["RollerDiameterErrorSI"]):
    """One roller of a planet bearing larger (+) or smaller (−) than nominal (every row of that roller)."""
    _prefix: ClassVar[str] = "errors.roller_diameter"
    planet: str = named(_PLANET, _PLANET_TEXT, "the planet whose bearing has the roller")
    roller: int = param("count", "roller index 0..Z-1 (roller 0 starts along the fixed frame's +x axis from its pin, the others counter-clockwise)", lo=0.0,
                        bound_text=">= 0")
    deviation: Quantity = param("length", "diameter deviation of the roller (+ larger)")


@si_of(RollerDiameterErrorParams)
class RollerDiameterErrorSI(SI):
    planet: str
    roller: int
    deviation: float


@dataclass(frozen=True, kw_only=True)
class SpallParams(Params["SpallSI"]):
    """A local raceway defect: a roller over it loses ``depth`` of its contact deflection, ramped in over
    ``edge`` at both ends. On the pin (raceway "inner", fixed on the carrier: ``position`` measured from
    the carrier's radial line through the planet, + with the planet angle) or on the planet's bore
    (raceway "outer", turning with the planet: ``position`` in the planet's body axes)."""
    _prefix: ClassVar[str] = "errors.spall"
    planet: str = named(_PLANET, _PLANET_TEXT, "the planet whose bearing has the defect")
    raceway: str = param("choice", "inner (the pin) or outer (the planet bore)", choices=("inner", "outer"))
    position: Quantity = param("angle", "angular position of the defect's centre on its raceway")
    width: Quantity = positive("length", "length of the defect along the raceway")
    depth: Quantity = positive("length", "depth of the defect")
    edge: Quantity = positive("length", "length over which the depth ramps in at each end (<= width)")


@si_of(SpallParams)
class SpallSI(SI):
    planet: str
    raceway: str
    position: float
    width: float
    depth: float
    edge: float


@dataclass(frozen=True, kw_only=True)
class ToothFaultParams(Params["ToothFaultSI"]):
    """One tooth of a gear weakened (a crack: the stiffness of every tooth pair it forms scaled by
    ``stiffness_factor``) or missing (factor 0), in every mesh the tooth enters."""
    _prefix: ClassVar[str] = "errors.tooth_fault"
    gear: str = named(_GEAR, _GEAR_TEXT, "the gear with the faulty tooth")
    tooth: int = param("count", "tooth index 0..z-1 (tooth 0 on the gear's body x axis)", lo=0.0, bound_text=">= 0")
    stiffness_factor: Quantity = param("dimensionless", "stiffness of the faulty tooth's pairs / healthy (0: missing)",
                                                lo=0.0, hi=1.0, bound_text="in [0, 1]")


@si_of(ToothFaultParams)
class ToothFaultSI(SI):
    gear: str
    tooth: int
    stiffness_factor: float


_TOOTH_GEAR_TEXT = "a gear name: 'sun', 'ring', 'a1'..'aN' or 'b1'..'bN'"


@dataclass(frozen=True, kw_only=True)
class ToothDeviationParams(Params["ToothDeviationSI"]):
    """Deviations of one tooth's flank (or of every tooth) from the perfect involute, ISO 1328-1 quantities:
    the pitch as an arc on the reference circle (the model puts pitch·cos α on the line of action), the
    profile deviations along the line of action. ``flank`` "ccw" is the tooth flank that faces the gear's counter-clockwise
    (+θ, forward) side, "cw" the other; "both" sets both. Signs: ``pitch`` + = the flank sits ahead of its
    theoretical position in the counter-clockwise sense (a tooth with "both" at +5 µm is turned 5 µm
    forward: the single pitch deviations f_pt are the differences of neighbouring teeth's values);
    ``slope`` f_Hα + = more material at the tip than at the start of the active profile; ``form`` f_fα:
    the range of the deviation left after removing its straight line, + = more material mid-profile
    ("barrel") or towards the tip ("s"). Entries for the same tooth and flank add up."""
    _prefix: ClassVar[str] = "errors.tooth"
    gear: str = named(_GEAR, _TOOTH_GEAR_TEXT, "the gear whose tooth deviates")
    tooth: int | str = param("tooth", 'tooth index 0..z-1 (tooth 0 on the gear\'s body x axis) or "all"')
    flank: str = param("choice", "which flank of the tooth", choices=("ccw", "cw", "both"))
    pitch: Quantity = param("length", "cumulative pitch deviation F_pk, an arc on the reference circle: where the "
                                      "flank sits, + ahead counter-clockwise", default="0 um")
    slope: Quantity = param("length", "profile slope deviation f_Ha (+: material towards the tip)", default="0 um")
    form: Quantity = param("length", "profile form deviation f_fa, the range of the curved part (+: material "
                                     "mid-profile for 'barrel', towards the tip for 's')", default="0 um")
    form_shape: str = param("choice", "shape of the form deviation: barrel (a parabola) or s (a cubic)",
                            choices=("barrel", "s"), default="barrel")


@si_of(ToothDeviationParams)
class ToothDeviationSI(SI):
    gear: str
    tooth: int | str
    flank: str
    pitch: float
    slope: float
    form: float
    form_shape: str


@dataclass(frozen=True, kw_only=True)
class FlankClassParams(Params["FlankClassSI"]):
    """Tooth deviations drawn for gears of an ISO 1328-1:2013 flank tolerance class (``components.tolerances``):
    every tooth flank's cumulative pitch deviation, profile slope and profile form deviation, normal with
    the class's tolerance at 3σ (per tooth), the profile deviations split into a part common to every tooth
    of a gear flank (``systematic_share`` of their variance: one grinding set-up) and a tooth-to-tooth part.
    Every gear draws its own teeth (reproducibly from ``seed`` and its name)."""
    _prefix: ClassVar[str] = "errors.flank_class"
    gear: str = named(r"all|planets|" + _GEAR, "'all', 'planets' or " + _TOOTH_GEAR_TEXT, "the gears of this class")
    grade: int = param("count", "ISO 1328-1:2013 flank tolerance class 1 (finest) .. 11", lo=1, hi=11,
                       bound_text="in 1..11")
    seed: int = param("count", "seed of the random draw", lo=0, bound_text=">= 0")
    systematic_share: Quantity = param("dimensionless", "share of the profile deviations' variance common to every "
                                                        "tooth of a gear flank", lo=0.0, hi=1.0,
                                       bound_text="in [0, 1]")


@si_of(FlankClassParams)
class FlankClassSI(SI):
    gear: str
    grade: int
    seed: int
    systematic_share: float


@dataclass(frozen=True, kw_only=True)
class ErrorsParams(Params["ErrorsSI"]):
    """Manufacturing errors and faults of the machine (docs/model.md §11); every list empty: the perfect
    machine. In TOML each entry is a table, e.g. ``[[errors.pinhole]]`` with ``planet``, ``radial``,
    ``tangential`` (README, "A damaged machine")."""
    _prefix: ClassVar[str] = "errors"
    pinhole: tuple[PinholeErrorParams, ...] = entries(PinholeErrorParams, "carrier pinhole position errors")
    runout: tuple[RunoutParams, ...] = entries(RunoutParams, "gear eccentricities")
    roller_diameter: tuple[RollerDiameterErrorParams, ...] = entries(RollerDiameterErrorParams,
                                                                     "roller diameter deviations")
    spall: tuple[SpallParams, ...] = entries(SpallParams, "raceway spalls")
    tooth_fault: tuple[ToothFaultParams, ...] = entries(ToothFaultParams, "cracked or missing teeth")
    tooth: tuple[ToothDeviationParams, ...] = entries(ToothDeviationParams, "tooth flank deviations, tooth by tooth")
    flank_class: tuple[FlankClassParams, ...] = entries(FlankClassParams, "tooth deviations drawn for an ISO 1328-1 "
                                                                          "flank tolerance class")
    pin_slope: tuple[PinSlopeParams, ...] = entries(PinSlopeParams, "pin slopes (misalignment; the sliced bearing "
                                                                   "model)")
    pinhole_ends: tuple[PinholeEndsParams, ...] = entries(PinholeEndsParams, "pinhole errors measured at the pin's two "
                                                                             "ends (the carrier plates)")

    @property
    def perfect(self) -> bool:
        return not any(getattr(self, f.name) for f in param_fields(type(self)))


@si_of(ErrorsParams)
class ErrorsSI(SI):
    pinhole: tuple[PinholeErrorSI, ...]
    runout: tuple[RunoutSI, ...]
    roller_diameter: tuple[RollerDiameterErrorSI, ...]
    spall: tuple[SpallSI, ...]
    tooth_fault: tuple[ToothFaultSI, ...]
    tooth: tuple[ToothDeviationSI, ...]
    flank_class: tuple[FlankClassSI, ...]
    pin_slope: tuple[PinSlopeSI, ...]
    pinhole_ends: tuple[PinholeEndsSI, ...]
