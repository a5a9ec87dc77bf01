"""Planet bearing parameters: the cylindrical roller bearing with its cage, traction curve and life rating
factors, and the lubricant around its rollers (docs/model.md §8, §9, §14)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .. import geometry as geo
from ..units import ParameterError, Quantity
from ._machinery import SI, Params, computed, entries, nested, nonneg, param, positive, rule, si_of

__all__ = ["CageParams", "CageSI", "SlideRollTractionParams", "SlideRollTractionSI", "LifeParams", "LifeSI",
           "ProfilePointParams", "ProfilePointSI", "ProfileParams", "ProfileSI", "SlicingParams", "SlicingSI",
           "PinParams", "PinSI",
           "BearingParams", "BearingSI", "LubricantParams", "LubricantSI"]


@dataclass(frozen=True, kw_only=True)
class CageParams(Params["CageSI"]):
    """Cage of a planet bearing with Z pockets, centred by the planet bore's land (outer-raceway guided) or by its
    rollers (roller-centred: the pockets hold the rollers radially too), ``guidance``.

    :class:`CageSI` ``inertia`` stays None when the rule applies: the rule needs the bearing's pitch
    diameter, and ``BearingParams.si().cage`` has it resolved."""

    _prefix: ClassVar[str] = "bearing.cage"
    mass: Quantity = positive("mass", "cage mass")
    inertia: Quantity | None = rule("inertia", "assumed", "m (d_m/2)^2: mass on the pitch circle")
    pocket_clearance: Quantity = nonneg("length", "circumferential pocket clearance per side C_p")
    guide_clearance: Quantity = nonneg("length", "radial guiding clearance C_g")
    pocket_stiffness: Quantity = positive("stiffness", "pocket contact stiffness K_p")
    guide_stiffness: Quantity = positive("stiffness", "guide-land contact stiffness K_g")
    restitution: Quantity = param("dimensionless", "coefficient of restitution of pocket and guide impacts",
                                  lo=0.0, hi=1.0, lo_open=True, bound_text="in (0, 1]")
    pocket_friction: Quantity = nonneg("dimensionless", "pocket wall friction coefficient")
    guide_friction: Quantity = nonneg("dimensionless", "guide land friction coefficient")
    friction_speed: Quantity = positive("velocity", "sliding speed v_mu over which pocket and land friction "
                                                    "rise to mu (tanh regularisation)")
    impact_speed_floor: Quantity = positive("velocity", "smallest approach speed v0 in the impact damping "
                                                        "c = lambda(e)/v0 (slower contacts count as this speed)")
    impact_law: str = param("choice", "impact damping law lambda(e) of pocket and guide impacts "
                                      "(mbd.elements.IMPACT_LAWS)",
                            choices=("exact", "hunt_crossley", "lankarani_nikravesh", "flores"))
    land_law: str = param("choice", "guide land: dry (solid contact, Coulomb friction) or hydrodynamic (an oil "
                                    "film, short journal bearing)", choices=("dry", "hydrodynamic"))
    land_width: Quantity = positive("length", "axial width of the guide lands (both sides together), for the film")
    land_min_film: Quantity = positive("length", "thinnest film the hydrodynamic land keeps before the solid contact")
    guidance: str = param("choice", "what centres the cage: outer_land (the planet bore's land, GuideContact) or "
                                    "rollers (a roller-centred cage: its pockets on the rollers, no land contact)",
                          choices=("outer_land", "rollers"))
    pocket_radial_clearance: Quantity = nonneg("length", "radial play C_r of a roller in its pocket before the "
                                                         "bars' converging faces hold it (guidance rollers)")
    pocket_law: str = param("choice", "cage pocket: dry (solid contact with wall friction only) or hydrodynamic (an "
                                      "oil film on both pocket walls: wedge, squeeze film and shear of a rigid "
                                      "cylinder near a plane; the solid contact below its thinnest film)",
                            choices=("dry", "hydrodynamic"))
    pocket_min_film: Quantity = positive("length", "thinnest film the hydrodynamic pocket keeps (below it the film "
                                                   "is taken at this gap and the solid contact carries)")


@si_of(CageParams)
class CageSI(SI):
    mass: float
    inertia: float | None
    pocket_clearance: float
    guide_clearance: float
    pocket_stiffness: float
    guide_stiffness: float
    restitution: float
    pocket_friction: float
    guide_friction: float
    friction_speed: float
    impact_speed_floor: float
    impact_law: str
    land_law: str
    land_width: float
    land_min_film: float
    guidance: str
    pocket_radial_clearance: float
    pocket_law: str
    pocket_min_film: float


@dataclass(frozen=True, kw_only=True)
class SlideRollTractionParams(Params["SlideRollTractionSI"]):
    """Coefficients of the slide-to-roll traction curve μ(s) = (A + B s) e^(−C s) + D
    (:class:`mbd.elements.SlideRollTraction`), used when ``bearing.traction_law = "slide_roll"``."""

    _prefix: ClassVar[str] = "bearing.slide_roll_traction"
    A: Quantity = param("dimensionless", "curve coefficient A (A + D = 0: no traction in pure rolling)")
    B: Quantity = param("dimensionless", "curve coefficient B")
    C: Quantity = nonneg("dimensionless", "curve decay C")
    D: Quantity = param("dimensionless", "traction at large slide-to-roll ratio D")
    rolling_speed_reg: Quantity = positive("velocity", "rolling speed below which the slide-to-roll ratio is "
                                                       "regularised")
    ratio_reg: Quantity = positive("dimensionless", "slide-to-roll ratio smoothing at s = 0")


@si_of(SlideRollTractionParams)
class SlideRollTractionSI(SI):
    A: float
    B: float
    C: float
    D: float
    rolling_speed_reg: float
    ratio_reg: float


@dataclass(frozen=True, kw_only=True)
class LifeParams(Params["LifeSI"]):
    """Rating factors of the planet bearing's fatigue life (:mod:`components.life`): ISO 281's basic
    dynamic load rating C_r = b_m f_c (i l)^(7/9) Z^(3/4) D^(29/27), f_c ∝ λν, and the raceway ratings
    of the ISO/TS 16281-style life, which keep b_m but not λν (that life sums the roller loads itself)."""

    _prefix: ClassVar[str] = "bearing.life"
    material_factor: Quantity = positive("dimensionless", "rating factor b_m for contemporary material and "
                                                          "manufacturing quality (ISO 281:2007 Table 1)")
    reduction_factor: Quantity = param("dimensionless", "ISO 281's reduction λν of the Lundberg-Palmgren line-"
                                                        "contact rating (edge stresses, real stress distribution)",
                                       lo=0.0, hi=1.0, lo_open=True, bound_text="in (0, 1]")


@si_of(LifeParams)
class LifeSI(SI):
    material_factor: float
    reduction_factor: float


@dataclass(frozen=True, kw_only=True)
class ProfilePointParams(Params["ProfilePointSI"]):
    """One point of a user's roller profile: the drop of the roller's radius at an axial position."""
    _prefix: ClassVar[str] = "bearing.profile.points"
    x: Quantity = param("length", "axial position from the roller centre (all >= 0: a symmetric profile)")
    drop: Quantity = nonneg("length", "drop of the roller radius there")


@si_of(ProfilePointParams)
class ProfilePointSI(SI):
    x: float
    drop: float


@dataclass(frozen=True, kw_only=True)
class ProfileParams(Params["ProfileSI"]):
    """The rollers' axial profile: the drop P(x) of the roller radius along its length, races straight
    (:mod:`components.profiles`, docs/model.md §8.8). Read only by the sliced contact; the planar model's rollers
    are straight."""
    _prefix: ClassVar[str] = "bearing.profile"
    shape: str = param("choice", "straight; crowned (flat length, circular ends); logarithmic (Lundberg/Johns-Gohar "
                                 "at the design load); iso_16281 (ISO/TS 16281 default); table (the points)",
                       choices=("straight", "crowned", "logarithmic", "iso_16281", "table"))
    flat_length: Quantity = nonneg("length", "crowned: the straight middle length l_f (<= l)")
    crown_drop: Quantity = nonneg("length", "crowned: the drop h at the roller's ends")
    design_load: Quantity = positive("force", "logarithmic: the roller load Q_d whose pressure the profile makes "
                                              "uniform")
    points: tuple[ProfilePointParams, ...] = entries(ProfilePointParams, "table: the (x, drop) points, linearly interpolated")


@si_of(ProfileParams)
class ProfileSI(SI):
    shape: str
    flat_length: float
    crown_drop: float
    design_load: float
    points: tuple[ProfilePointSI, ...]


@dataclass(frozen=True, kw_only=True)
class SlicingParams(Params["SlicingSI"]):
    """The sliced (quasi-3D) roller contact (:mod:`mbd.elements.sliced`, docs/model.md §8.8): slice count and
    the slice law's constant. Used by the quasi-static sliced bearing (:mod:`components.sliced_bearing`) and, with
    bearing.model = "sliced", by the dynamic scenes' planet bearings."""
    _prefix: ClassVar[str] = "bearing.slicing"
    slices: int = param("count", "slices n_s per roller", lo=1, bound_text=">= 1")
    stiffness: str = param("choice", "slice law constant: palmgren (the planar law's K, K/n_s per slice) or "
                                     "iso_16281 (c_L = 35948 L^(8/9) for the two contacts in series)",
                           choices=("palmgren", "iso_16281"))


@si_of(SlicingParams)
class SlicingSI(SI):
    slices: int
    stiffness: str


@dataclass(frozen=True, kw_only=True)
class PinParams(Params["PinSI"]):
    """The planet pin, the bearing's inner raceway (diameter d_m − D, Young's modulus bearing.elastic_modulus): rigid,
    or an elastic beam clamped in the carrier's plates whose bending slope and deflection at the bearing's centre are
    degrees of freedom (:mod:`components.pins`, docs/model.md §8.8). Read only by the sliced bearing model."""
    _prefix: ClassVar[str] = "bearing.pin"
    model: str = param("choice", "rigid (part of the carrier) or elastic (a beam in the carrier's plates: its "
                                 "slope and deflection at the bearing under the bearing's load; the sliced model)",
                       choices=("rigid", "elastic"))
    mounting: str = param("choice", "elastic pin: both_plates (clamped in both carrier plates, gears.carrier_plate_span "
                                    "apart, the bearing mid-span) or one_plate (a cantilever from the shaft-side "
                                    "plate, bearing.pin.overhang)", choices=("both_plates", "one_plate"))
    overhang: Quantity = positive("length", "one_plate: the clamp's face to the bearing's centre a")
    bore_diameter: Quantity = nonneg("length", "the pin's bore d_i (0: a solid pin)")
    density: Quantity = positive("density", "the pin's material density (its mass and inertias)")
    damping_ratio: Quantity = nonneg("dimensionless", "elastic pin: damping ratio of its deflection, slope and turn "
                                                      "(each against its own stiffness and inertia)")


@si_of(PinParams)
class PinSI(SI):
    model: str
    mounting: str
    overhang: float
    bore_diameter: float
    density: float
    damping_ratio: float


@dataclass(frozen=True, kw_only=True)
class BearingParams(Params["BearingSI"]):
    """Cylindrical roller planet bearing (same for inner and outer planets), with its cage.

    Inner raceway = carrier pin, diameter d_m − D; outer raceway = planet bore, diameter d_m + D + P_d
    (P_d the diametral clearance). si() adds inner_raceway_radius, outer_raceway_radius and resolves
    roller_mass, roller_inertia, contact_stiffness and cage.inertia.
    """

    _prefix: ClassVar[str] = "bearing"
    pitch_diameter: Quantity = positive("length", "pitch diameter d_m")
    roller_diameter: Quantity = positive("length", "roller diameter D")
    roller_length: Quantity = positive("length", "effective roller length l")
    rollers: int = param("count", "rollers Z per bearing", lo=3, bound_text=">= 3")
    rows: int = param("count", "roller rows (identical rows move as one in the planar model; the sliced model "
                               "builds each row's rollers at its axial station)", lo=1, bound_text=">= 1")
    row_spacing: Quantity | None = rule("length", "derived", "rows side by side: the roller length l (no rib "
                                                             "between them)",
                                        "axial distance between the centres of neighbouring roller rows (>= l)")
    model: str = param("choice", "roller-raceway contact model: planar (one line contact per roller) or sliced "
                                 "(bearing.slicing slices per roller, the planets' slopes and the rollers' tilts "
                                 "as degrees of freedom; every row its own rollers)", choices=("planar", "sliced"))
    clearance: Quantity = nonneg("length", "diametral clearance P_d")
    roller_density: Quantity = positive("density", "roller material density")
    roller_mass: Quantity | None = rule("mass", "derived", "solid cylinder: density x pi D^2 l / 4")
    roller_inertia: Quantity | None = rule("inertia", "derived", "solid cylinder: m D^2 / 8")
    contact_stiffness: Quantity | None = rule("contact_stiffness", "derived",
                                              "Palmgren line contact: K = 8.06e4 l^(8/9) N/mm^(10/9), l in mm")
    contact_exponent: Quantity = param("dimensionless", "load-deflection exponent p of Q = K delta^p", lo=1.0,
                                       bound_text=">= 1")
    contact_damping_ratio: Quantity = nonneg("dimensionless", "roller-raceway contact damping ratio")
    race_damping_ramp: Quantity = nonneg("length", "compression over which a roller-raceway contact's (a slice's) "
                                                   "damping grows from 0 at first touch to the damping ratio's (0: "
                                                   "all of it at first touch)")
    race_film: str = param("choice", "oil film on the roller-raceway gaps while open: none; squeeze (the squeeze "
                                     "film of a roller approaching its raceway, rigid cylinder near a plane, "
                                     "cavitating on separation); full (squeeze and wedge loads, Couette and "
                                     "Poiseuille shear); planar model only",
                           choices=("none", "squeeze", "full"))
    race_film_floor: Quantity = positive("length", "gap h_f across which the raceway squeeze film hands over to the "
                                                   "Hertz contact (the rigid law above it, zero at touch)")
    traction_law: str = param("choice", "roller-raceway traction law (ehl: from the lubricant's film)",
                              choices=("tanh", "slide_roll", "ehl"))
    drag_law: str = param("choice", "lubricant drag on the rollers: inertial (quadratic drag on the orbit, C_d "
                                    "constant) or viscous (C_d(Re) of a cylinder and a viscous moment on the "
                                    "roller spin, with the oil-air mixture's viscosity, and the mixture's moment "
                                    "on the cage's faces)",
                          choices=("inertial", "viscous"))
    rolling_resistance: str = param("choice", "hydrodynamic rolling resistance of the loaded roller-raceway "
                                              "contacts: none, or houpert (Biboulet-Houpert's fully flooded "
                                              "rolling force of the line contact, IVR to EHL)",
                                    choices=("none", "houpert"))
    traction_mu_max: Quantity = nonneg("dimensionless", "traction curve maximum mu_max (mu = mu_max tanh(v/v0))")
    traction_v0: Quantity = positive("velocity", "traction curve slip velocity scale v0")
    slide_roll_traction: SlideRollTractionParams = nested(SlideRollTractionParams, "slide-to-roll traction curve")
    linear_stiffness: Quantity = positive("stiffness", "radial stiffness of a bearing modelled as a linear spring "
                                                       "(scene option bearings=linear)")
    linear_damping: Quantity = nonneg("damping", "radial damping of a bearing modelled as a linear spring")
    elastic_modulus: Quantity = positive("pressure", "Young's modulus of rollers and raceways (EHL film)")
    poisson_ratio: Quantity = param("dimensionless", "Poisson's ratio of rollers and raceways", lo=0.0, hi=0.5,
                                    hi_open=True, bound_text="in [0, 0.5)")
    cage: CageParams = nested(CageParams, "cage")
    life: LifeParams = nested(LifeParams, "fatigue life rating factors")
    profile: ProfileParams = nested(ProfileParams, "roller profile (sliced contact)")
    slicing: SlicingParams = nested(SlicingParams, "sliced contact: slices and slice law")
    pin: PinParams = nested(PinParams, "the planet pin: rigid or an elastic beam (sliced contact)")

    def _si_values(self, v):
        dm, dr, ln = v["pitch_diameter"], v["roller_diameter"], v["roller_length"]
        m = v["roller_mass"] if v["roller_mass"] is not None else v["roller_density"] * math.pi * dr ** 2 * ln / 4.0
        cage = v["cage"]
        if cage.inertia is None:
            cage = cage.replace(inertia=cage.mass * (dm / 2.0) ** 2)
        spacing = v["row_spacing"] if v["row_spacing"] is not None else ln
        if spacing < ln:
            raise ParameterError.at("bearing.row_spacing", f"expected >= the roller length {ln * 1e3:g} mm (rows "
                                                           f"cannot overlap), got {spacing * 1e3:g} mm")
        return dict(roller_mass=m, row_spacing=spacing,
                    roller_inertia=v["roller_inertia"] if v["roller_inertia"] is not None else m * dr ** 2 / 8.0,
                    contact_stiffness=(v["contact_stiffness"] if v["contact_stiffness"] is not None
                                       else geo.palmgren_stiffness(ln)),
                    cage=cage, inner_raceway_radius=(dm - dr) / 2.0,
                    outer_raceway_radius=(dm + dr + v["clearance"]) / 2.0)


@si_of(BearingParams)
class BearingSI(SI):
    pitch_diameter: float
    roller_diameter: float
    roller_length: float
    rollers: int
    rows: int
    row_spacing: float = computed("axial distance between neighbouring rows' centres [m] (given, or the rule)")
    model: str
    clearance: float
    roller_density: float
    roller_mass: float = computed("mass of one physical roller [kg] (given, or the rule)")
    roller_inertia: float = computed("polar moment of inertia of one roller [kg m^2] (given, or the rule)")
    contact_stiffness: float = computed("roller-raceway line contact stiffness K [N/m^(10/9)] (given, or Palmgren)")
    contact_exponent: float
    contact_damping_ratio: float
    race_damping_ramp: float
    race_film: str
    race_film_floor: float
    traction_law: str
    drag_law: str
    rolling_resistance: str
    traction_mu_max: float
    traction_v0: float
    slide_roll_traction: SlideRollTractionSI
    linear_stiffness: float
    linear_damping: float
    elastic_modulus: float
    poisson_ratio: float
    cage: CageSI
    life: LifeSI
    profile: ProfileSI
    slicing: SlicingSI
    pin: PinSI
    inner_raceway_radius: float = computed("R_i = (d_m - D)/2, the pin [m]")
    outer_raceway_radius: float = computed("R_o = (d_m + D + P_d)/2, the planet bore [m]")


@dataclass(frozen=True, kw_only=True)
class LubricantParams(Params["LubricantSI"]):
    """The oil and the oil–air mixture around the rollers (docs/model.md §8.7, §9).

    Drag: F = C_d ρ D l (d_m Ω_m)^2 / 8 with the mixture density. Film: the oil's kinematic viscosity at
    40 °C and 100 °C (an ISO VG grade's data sheet) gives its viscosity at the operating temperature by
    Walther's equation (ASTM D341), times its density at that temperature (from the density at 15 °C and
    the thermal expansion); with the pressure–viscosity coefficient and the surfaces' composite roughness
    it sets the EHL film of every roller contact, thinned by inlet shear heating through the oil's thermal
    conductivity and its temperature–viscosity coefficient β (:mod:`components.lubrication`).
    ``oil_viscosity`` (the dynamic viscosity at the operating temperature [Pa·s]) and
    ``temperature_viscosity`` (β [1/K]) follow from these unless given; a viscosity given directly (a study
    of viscosity) keeps β of the grade's line at the operating temperature."""

    _prefix: ClassVar[str] = "lubricant"
    drag_coefficient: Quantity = nonneg("dimensionless", "drag coefficient C_d")
    density: Quantity = nonneg("density", "oil-air mixture density")
    oil_density: Quantity = positive("density", "density of the oil itself at 15 degC")
    thermal_expansion: Quantity = param("per_temperature", "volumetric thermal expansion alpha_rho of the oil: "
                                                           "rho(T) = rho_15 (1 - alpha_rho (T - 15 degC))",
                                        lo=0.0, hi=0.01, hi_open=True, bound_text="in [0, 0.01) 1/K")
    viscosity_40: Quantity = positive("kinematic_viscosity", "kinematic viscosity at 40 degC (ISO VG: the grade)")
    viscosity_100: Quantity = positive("kinematic_viscosity", "kinematic viscosity at 100 degC")
    temperature: Quantity = positive("temperature", "oil temperature in the bearing")
    pressure_viscosity: Quantity = positive("pressure_viscosity", "pressure-viscosity coefficient alpha_p (Barus)")
    thermal_conductivity: Quantity = positive("thermal_conductivity", "thermal conductivity k of the oil (the film's "
                                                                      "thermal reduction, Murch-Wilson)")
    roughness: Quantity = positive("length", "composite roughness sigma = sqrt(Rq1^2 + Rq2^2) of roller and raceway")
    limiting_shear_stress: Quantity = positive("pressure", "limiting shear stress at zero pressure tau_L0 "
                                                           "(EHL traction)")
    limiting_shear_slope: Quantity = nonneg("dimensionless", "pressure slope gamma_L of the limiting shear stress "
                                                             "tau_L = tau_L0 + gamma_L p (Bair-Winer)")
    film_speed_reg: Quantity = positive("velocity", "entraining speed below which the EHL traction's film is "
                                                    "regularised")
    film_shear_modulus: Quantity = positive("pressure", "elastic shear modulus G_e of the film in the contact (EHL "
                                                        "traction's linear region, Johnson-Tevaarwerk)")
    limiting_shear_law: str = param("choice", "temperature dependence of gamma_L: constant (gamma_L at every "
                                              "temperature) or dyson (gamma_L (T_ref - T_0)/(T - T_0), Dyson's "
                                              "mineral-oil form)", choices=("constant", "dyson"))
    limiting_shear_reference_temperature: Quantity = positive("temperature", "temperature T_ref at which "
                                                                             "limiting_shear_slope holds (law dyson)")
    limiting_shear_pole_temperature: Quantity = positive("temperature", "pole T_0 of the dyson law, below every "
                                                                        "oil temperature")

    oil_viscosity: Quantity | None = rule("dynamic_viscosity", "derived", "Walther (ASTM D341) at the temperature, "
                                                                         "times the oil density there")
    temperature_viscosity: Quantity | None = rule("per_temperature", "derived",
                                                  "beta = -(1/eta) d(eta)/dT of Walther's line and the density "
                                                  "at the temperature")
    oil_fraction: Quantity | None = rule("dimensionless", "derived", "the mixture density over the oil's density "
                                                                    "at the temperature",
                                         "volume fraction X of oil in the bearing's free space (the viscous drag "
                                         "law's mixture: density X rho_oil, viscosity X eta_oil)")

    def _si_values(self, v):
        # deferred: components.lubrication imports the engine (mbd.elements, numba), which parameters do not need
        from ..lubrication import dynamic_viscosity, oil_density, temperature_viscosity
        if not v["viscosity_100"] < v["viscosity_40"]:
            raise ParameterError.at("lubricant.viscosity_100", "must be below lubricant.viscosity_40 "
                                                                 "(an oil thins as it warms)")
        line = (v["viscosity_40"], v["viscosity_100"])
        if not oil_density(v["oil_density"], v["thermal_expansion"], v["temperature"]) > 0.0:
            raise ParameterError.at("lubricant.temperature", "the oil's density at this temperature would be <= 0 "
                                                             "with lubricant.thermal_expansion")
        eta = v["oil_viscosity"]
        beta = v["temperature_viscosity"]
        X = v["oil_fraction"]
        if X is None:
            X = v["density"] / oil_density(v["oil_density"], v["thermal_expansion"], v["temperature"])
        if not 0.0 < X <= 1.0:
            raise ParameterError.at("lubricant.oil_fraction", f"must lie in (0, 1] (a volume fraction), got {X!r}")
        if v["limiting_shear_law"] == "dyson":
            T0 = v["limiting_shear_pole_temperature"]
            if not (T0 < v["temperature"] and T0 < v["limiting_shear_reference_temperature"]):
                raise ParameterError.at("lubricant.limiting_shear_pole_temperature",
                                        f"must lie below lubricant.temperature and "
                                        f"lubricant.limiting_shear_reference_temperature (K), got {T0!r} K")
        return dict(
            oil_fraction=X,
            oil_viscosity=eta if eta is not None else dynamic_viscosity(*line, v["oil_density"],
                                                                        v["thermal_expansion"], v["temperature"]),
            temperature_viscosity=beta if beta is not None else temperature_viscosity(*line, v["thermal_expansion"],
                                                                                      v["temperature"]))


@si_of(LubricantParams)
class LubricantSI(SI):
    drag_coefficient: float
    density: float
    oil_density: float
    thermal_expansion: float
    viscosity_40: float
    viscosity_100: float
    temperature: float
    pressure_viscosity: float
    thermal_conductivity: float
    roughness: float
    limiting_shear_stress: float
    limiting_shear_slope: float
    film_speed_reg: float
    film_shear_modulus: float
    limiting_shear_law: str
    limiting_shear_reference_temperature: float
    limiting_shear_pole_temperature: float
    oil_viscosity: float = computed("dynamic viscosity at the operating temperature [Pa s] (given, or Walther)")
    temperature_viscosity: float = computed("temperature-viscosity coefficient beta at the operating "
                                            "temperature [1/K] (given, or Walther)")
    oil_fraction: float = computed("volume fraction of oil in the bearing's free space (given, or the mixture "
                                   "density over the oil's at the temperature)")
