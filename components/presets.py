"""The reference machine of the source study, with the source of every value.

``reference_dpgt(condition=3, direction="forward")`` → :class:`DPGTParams`; change anything with
:func:`components.params.with_overrides`. Values from the study's tables are tagged [paper], values
computed from them [derived] (left None in the parameter objects so that they follow overrides: roller
mass, Palmgren stiffness, mean mesh stiffness), engineering estimates [assumed] with their basis.
"""
from __future__ import annotations

from types import MappingProxyType

from pathlib import Path

import numpy as np

from .params import (BearingParams, BearingRigParams, CageParams, CarrierRippleParams, DPGTParams, ErrorsParams,
                     FlankClassParams, GearParams, GearSetParams, HousingParams, LifeParams, LubricantParams, MeshParams,
                     OperatingPoint, PinParams, PinholeErrorParams, ProfileParams, RigParams, RunoutParams, SensorParams,
                     SlicingParams, SlideRollTractionParams, Span, SupportParams, assumed, derived,
                     overrides_from_toml, paper, with_overrides)
from .tolerances import radial_runout
from .units import Q_, ParameterError
from .names import did_you_mean

__all__ = ["CONDITIONS", "DIRECTIONS", "OIL_GRADES", "oil_grade", "operating_point", "reference_gears", "reference_bearing",
           "reference_dpgt", "reference_bearing_rig", "rig_accelerometer", "carrier_bearing_accelerometer", "SENSOR_PRESETS",
           "rig_housing", "ideal_carrier_drive", "load_toml",
           "perfect_machine", "typical_errors"]

# the study's four operating conditions: carrier speed n_c and output power P (ring fixed)
CONDITIONS = MappingProxyType({
    1: (Q_(1000, "rpm"), Q_(200, "kW")),
    2: (Q_(2000, "rpm"), Q_(200, "kW")),
    3: (Q_(4200, "rpm"), Q_(200, "kW")),
    4: (Q_(4200, "rpm"), Q_(0, "kW")),
})
DIRECTIONS = ("forward", "reverse")


def operating_point(condition: int = 3, direction: str = "forward") -> OperatingPoint:
    """Operating condition 1..4 of the study, forward (n_c > 0) or reverse (n_c < 0)."""
    if condition not in CONDITIONS:
        raise ParameterError.at("operating.condition", f"expected one of {sorted(CONDITIONS)}, got {condition!r}")
    if direction not in DIRECTIONS:
        raise ParameterError.at("operating.direction", f"expected one of {list(DIRECTIONS)}, got {direction!r}")
    speed, power = CONDITIONS[condition]
    return OperatingPoint(carrier_speed=paper(speed, f"condition {condition}"),
                          output_power=paper(power, f"condition {condition}"),
                          direction=paper(direction, "the study runs both senses"),
                          schedule=paper((), "the source's operating points are steady"))


def _gear(teeth, face_width, mass, internal=False) -> GearParams:
    profile = "standard full-depth involute teeth, no profile shift"
    return GearParams(teeth=paper(teeth), module=paper("3 mm"), pressure_angle=paper("20 deg"),
                      face_width=paper(face_width), mass=paper(mass),
                      internal=paper(internal, "internal gear" if internal else "external gear"),
                      addendum_coefficient=assumed(1.0, profile), dedendum_coefficient=assumed(1.25, profile),
                      tip_relief=paper("0 um", "the source states no profile modification"),
                      tip_relief_length=paper("0 mm", "no profile modification"),
                      tip_relief_shape=paper("linear", "no profile modification"))


def reference_gears() -> GearSetParams:
    """Table-1 gears; inertias follow the assumed rules (solid disc / thin ring / carrier disc)."""
    return GearSetParams(
        sun=_gear(31, "35.5 mm", "1.088 kg"),
        inner_planet=_gear(24, "32 mm", "0.557 kg"),
        outer_planet=_gear(24, "32 mm", "0.557 kg"),
        ring=_gear(82, "33 mm", "6.07 kg", internal=True),
        carrier_mass=paper("7.751 kg"),
        carrier_torsional_stiffness=assumed("5e6 N*m/rad", "the source gives none: three bridges 20 x 20 mm, 40 mm "
                                                       "long, clamped at both plates (12 E I/L^3 = 5.3e8 N/m each) at "
                                                       "85 mm radius give 1.1e7 N m/rad, halved for the plates' own "
                                                       "flexibility", span=Span("2e6 N*m/rad", "2e7 N*m/rad",
                                                                                "bridged two-plate carriers of this size",
                                                                                log=True)),
        carrier_plate_span=assumed("40 mm", "the planets' 32 mm face width and 4 mm on each side for washers"),
        carrier_windup=assumed(False, "the source's carrier is rigid; on: the pins tilt under the carrier torque"),
        planets=paper(3, "default planet count of the study"),
        handedness=assumed(-1, "outer planet trails its inner planet by delta_psi in the forward "
                               "(counter-clockwise) carrier direction"),
        planet_angle=assumed("0 deg", "pair 1 (planet a1) on the +x axis at t = 0"),
    )


# ISO VG grades (ISO 3448: the grade is the kinematic viscosity at 40 degC, mm^2/s) of mineral oils with a
# viscosity index near 100; the 100 degC values are typical of such oils' data sheets (VG 32, 68, 150, the lubricant
# study's) or of a reference table of typical values per grade (lubesolut.com "ISO VG reference table": the others)
_TABLE = "typical 100 degC value of a VI ~ 100 mineral oil (ISO VG reference table, lubesolut.com)"
_TYPICAL_100 = {"VG10": 2.5, "VG15": 3.5, "VG22": 4.5, "VG46": 6.5, "VG100": 11.4, "VG220": 19.0, "VG320": 24.5,
                "VG460": 32.0, "VG680": 42.0, "VG1000": 55.0, "VG1500": 74.0}
OIL_GRADES = {
    "VG32": {"viscosity_40": assumed("32 mm^2/s", "ISO 3448 grade VG 32"),
             "viscosity_100": assumed("5.4 mm^2/s", "mineral oil, VI ~ 100")},
    "VG68": {"viscosity_40": assumed("68 mm^2/s", "ISO 3448 grade VG 68; the source names no oil", span=Span("61.2 mm^2/s", "74.8 mm^2/s", "ISO 3448: a grade's 40 degC viscosity within +-10 %")),
             "viscosity_100": assumed("8.7 mm^2/s", "mineral oil, VI ~ 100")},
    "VG150": {"viscosity_40": assumed("150 mm^2/s", "ISO 3448 grade VG 150"),
              "viscosity_100": assumed("14.7 mm^2/s", "mineral oil, VI ~ 100")},
    **{g: {"viscosity_40": assumed(f"{g[2:]} mm^2/s", f"ISO 3448 grade VG {g[2:]}"),
           "viscosity_100": assumed(f"{v} mm^2/s", _TABLE)} for g, v in _TYPICAL_100.items()},
}
OIL_GRADES = dict(sorted(OIL_GRADES.items(), key=lambda kv: int(kv[0][2:])))


def oil_grade(name: str) -> dict:
    """Overrides {"lubricant.viscosity_40": ..., "lubricant.viscosity_100": ...} of an ISO VG grade."""
    if name not in OIL_GRADES:
        raise ParameterError.at("lubricant grade", f"expected one of {sorted(OIL_GRADES)}, got {name!r}"
                                                   f"{did_you_mean(name, OIL_GRADES)}")
    return {f"lubricant.{k}": v for k, v in OIL_GRADES[name].items()}


def reference_bearing() -> BearingParams:
    """The planet bearing (same for inner and outer planets) and its cage."""
    cage = CageParams(
        mass=assumed("0.04 kg", "machined brass cage with side rings", span=Span("0.03 kg", "0.06 kg", "machined brass cages of this size, lighter or heavier side rings")),
        pocket_clearance=assumed("0.10 mm", "circumferential, per side", span=Span("0.05 mm", "0.2 mm", "pocket play of machined cages")),
        guide_clearance=assumed("0.15 mm", "radial, outer-raceway guided", span=Span("0.08 mm", "0.3 mm", "land play of ring-guided cages, ~0.2-0.7 % of the land diameter")),
        pocket_stiffness=assumed("2e7 N/m", span=Span("5e6 N/m", "1e8 N/m", "a brass cage bar against a roller: its bending to the line contact", log=True)),
        guide_stiffness=assumed("2e7 N/m", span=Span("5e6 N/m", "1e8 N/m", "a brass land on the bore: the cage ring's bending to the contact", log=True)),
        restitution=assumed(0.8, "Hunt-Crossley, pocket and guide impacts"),
        pocket_friction=assumed(0.1, "not stated by the source", span=Span(0.05, 0.15, "lubricated steel on brass")),
        guide_friction=assumed(0.1, "not stated by the source", span=Span(0.05, 0.15, "lubricated steel on brass")),
        friction_speed=assumed("0.01 m/s", "tanh-regularised Coulomb friction: full mu above ~2 cm/s of sliding"),
        impact_speed_floor=assumed("0.01 m/s", "bounds the Hunt-Crossley damping of slow, quasi-static pocket "
                                               "and land contacts; a roller at 1 cm/s carries ~1e-7 J"),
        land_law=assumed("dry", "the source's model; 'hydrodynamic' runs the land in the oil film"),
        land_width=assumed("4 mm", "two side rails of about 2 mm"),
        land_min_film=assumed("1 um", "a few composite roughnesses"),
        guidance=assumed("outer_land", "the source's model: a cage guided on the planet bore; rollers: a "
                                       "roller-centred cage (catalogue cages of cylindrical roller bearings come "
                                       "both ways, e.g. SKF's MA outer-ring and M roller centred)"),
        pocket_radial_clearance=assumed("0.15 mm", "radial play of a roller in a roller-centred cage's pocket, "
                                                   "the order of its circumferential play", span=Span("0.05 mm", "0.3 mm", "pocket shapes of roller-centred machined cages")),
        pocket_law=assumed("dry", "the source's model; 'hydrodynamic' runs the rollers in oiled pockets"),
        pocket_min_film=assumed("1 um", "a few composite roughnesses, as the land's"),
        impact_law=derived("exact", "lambda(e) from ln((1+lambda)/(1-lambda e)) = lambda (1+e): the set e holds "
                                    "at any approach speed (docs/model.md §8.4)"),
    )
    return BearingParams(
        pitch_diameter=paper("39 mm"),
        roller_diameter=paper("7.5 mm"),
        roller_length=paper("9 mm"),
        rollers=paper(12),
        rows=paper(1, "one row in the source's table"),
        model=assumed("planar", "the source's model; sliced: edge loading under misalignment (docs/model.md §8.8)"),
        clearance=assumed("20 um", "diametral", span=Span("5 um", "40 um", "mounted clearance: ISO 5753-1 groups 2 to N at this bore, less fit and warm pin")),
        roller_density=assumed("7850 kg/m^3", "bearing steel"),
        contact_exponent=derived(10.0 / 9.0, "Palmgren line contact Q = K delta^(10/9) (docs/model.md §8.1)"),
        contact_damping_ratio=assumed(0.05, "of critical, gated to compression", span=Span(0.02, 0.15, "EHL and Hertzian contact damping, a few to 15 % of critical")),
        race_damping_ramp=assumed("0 um", "the contact damping whole at first touch: these contacts run on a full "
                                           "film (lambda ~ 3), whose squeeze damps the approach before the surfaces "
                                           "touch; a ramp over the asperities' scale (~ the composite roughness, "
                                           "0.15 um) is the dry contact's law (Hunt & Crossley), elastic at low "
                                           "approach speeds",
                                  span=Span("0 um", "0.45 um", "the damping whole at first touch to a dry contact's "
                                                               "ramp over three composite roughnesses")),
        race_film=assumed("none", "the source's model; squeeze: the oil's squeeze film damps a roller's approach to "
                                  "its raceway before touch; full: the open gap's wedge load and Couette and "
                                  "Poiseuille shear as well (docs/model.md §8.9)"),
        race_film_floor=assumed("1 um", "a few composite roughnesses (0.15 um), twice the loaded contact's film "
                                        "(lambda ~ 3): below it the film's pressure at a chattering roller's approach "
                                        "flattens the surfaces and thickens the oil (docs/model.md §8.9)",
                                span=Span("0.5 um", "2 um", "the loaded contact's film to where the rigid-isoviscous "
                                                           "law holds within ~ 15 %")),
        traction_law=assumed("tanh", "a smooth, bounded Coulomb-like law (docs/model.md §8.2); slide_roll: an EHL-type curve of the slide-to-roll ratio"),
        drag_law=assumed("inertial", "quadratic drag of the oil-air mixture on the roller orbit (docs/model.md "
                                     "§8.7); viscous: with the oil's viscosity, and a moment on the roller spin"),
        rolling_resistance=assumed("none", "houpert: the contacts' Poiseuille rolling force (docs/model.md §9.5)"),
        traction_mu_max=assumed(0.08, "mu = 0.08 tanh(v_s / 0.3 m/s)", span=Span(0.04, 0.1, "traction plateaus of mineral oils in EHL contacts")),
        traction_v0=assumed("0.3 m/s", span=Span("0.1 m/s", "1 m/s", "slip speed at which the traction saturates: a few tenths of a m/s", log=True)),
        slide_roll_traction=SlideRollTractionParams(
            A=assumed(-0.04, "A + D = 0: no traction in pure rolling"), B=assumed(5.0),
            C=assumed(40.0, "peak mu ~ 0.073 at s ~ 0.033"), D=assumed(0.04, "mu at large slip"),
            rolling_speed_reg=assumed("0.1 m/s", "far below the rolling speeds of m/s: matters only near rest"),
            ratio_reg=assumed(1e-4)),
        linear_stiffness=assumed("5e8 N/m", "a planet bearing's radial stiffness near its loaded state"),
        linear_damping=assumed("2000 N*s/m"),
        elastic_modulus=assumed("210 GPa", "bearing steel"),
        poisson_ratio=assumed(0.3, "bearing steel"),
        cage=cage,
        life=LifeParams(
            material_factor=derived(1.1, "ISO 281:2007 Table 1: b_m = 1.1 for cylindrical roller bearings"),
            reduction_factor=derived(0.83, "ISO 281:2007 f_c = 207.9 λν ... with λν = 0.83 (ISO/TR 1281-1; "
                                           "ISO/TS 16281:2008 undoes it for its raceway ratings)")),
        profile=ProfileParams(
            shape=assumed("straight", "the source gives no profile; the planar model's rollers are straight"),
            flat_length=assumed("5 mm", "a crowned roller's straight middle, ~55 % of l"),
            crown_drop=assumed("10 um", "a crowned roller's end drop, ~0.13 % of D"),
            design_load=assumed("4 kN", "about the most loaded roller at condition 3 (4.08 F_r/Z at F_r ~ 12 kN)"),
            points=assumed((), "no user table")),
        slicing=SlicingParams(
            slices=assumed(31, "odd, > 30 (ISO/TS 16281 uses 30): the sliced life within 1 % of n_s = 121 "
                               "(docs/model.md §8.8)"),
            stiffness=assumed("palmgren", "the planar law's constant: a straight, aligned roller is the planar "
                                          "contact")),
        pin=PinParams(
            model=assumed("rigid", "the source's pins are part of a rigid carrier; elastic: the pin bends under its "
                                   "bearing's load (docs/model.md §8.8)"),
            mounting=assumed("both_plates", "the two-plate carrier the wind-up presumes (gears.carrier_plate_span)"),
            overhang=assumed("20 mm", "one_plate: half the 40 mm plate span, the planet's 16 mm half face width and "
                                      "a 4 mm washer"),
            bore_diameter=assumed("0 mm", "a solid pin; the source gives none"),
            density=assumed("7850 kg/m^3", "steel"),
            damping_ratio=assumed(0.02, "a steel part pressed in its bores: a few percent of critical")),
    )


def perfect_machine() -> ErrorsParams:
    """No manufacturing errors or faults: the machine the source models (docs/model.md §11)."""
    return ErrorsParams(**{f: paper((), "the source models a perfect machine")
                           for f in ("pinhole", "runout", "roller_diameter", "spall", "tooth_fault", "tooth",
                                     "flank_class", "pin_slope", "pinhole_ends")})


def typical_errors(params: DPGTParams, grade: int) -> ErrorsParams:
    """A modest, stated set of manufacturing errors for gears of ISO 1328 accuracy ``grade`` (1..11): every
    gear's teeth drawn for ISO 1328-1:2013 flank tolerance class ``grade`` (seed 1, each gear its own teeth,
    half the profile deviations' variance systematic: :mod:`components.tolerances`), every gear eccentric by
    half its grade's runout tolerance (:func:`components.tolerances.radial_runout`) at an arbitrary but fixed
    phase, and all 2N carrier pinholes off by up to 10 µm (a precision carrier's position tolerance, of the
    order Bodas & Kahraman (2004) study; drawn uniformly, seed 2). What the spectrum scenario puts on the rig
    by default (docs/model.md §11.8)."""
    si = params.si()
    G, N = si.gears, si.layout.planets
    note = f"ISO 1328-1:2013 class {grade}: eccentricity = F_rT/2, F_rT = 0.9 F_pT; phase arbitrary"

    def runout(gear, g, phase_deg):
        e = 0.5 * radial_runout(g.module, g.pitch_radius * 2.0, grade)
        return {"gear": gear, "eccentricity": assumed(Q_(1e6 * e, "um"), note),
                "phase": assumed(Q_(phase_deg, "deg"), "arbitrary assembly phase")}
    runouts = [runout("sun", G.sun, 0.0), runout("ring", G.ring, 90.0)]
    runouts += [runout(f"a{n + 1}", G.inner_planet, 60.0 + 110.0 * n) for n in range(N)]
    runouts += [runout(f"b{n + 1}", G.outer_planet, 200.0 + 70.0 * n) for n in range(N)]
    pin = "carrier pinhole position error within +-10 um (assumed precision carrier), uniform, seed 2"
    rt = np.round(np.random.default_rng(2).uniform(-10.0, 10.0, (2 * N, 2)), 1)
    planets = [f"a{n + 1}" for n in range(N)] + [f"b{n + 1}" for n in range(N)]
    pinholes = [{"planet": p, "radial": assumed(Q_(float(r), "um"), pin), "tangential": assumed(Q_(float(t), "um"), pin)}
                for p, (r, t) in zip(planets, rt)]
    teeth = "ISO 1328-1:2013 flank tolerance class, normal with the tolerance at 3 sigma (components.tolerances)"
    flank = {"gear": "all", "grade": assumed(grade, teeth), "seed": assumed(1, "a fixed draw"),
             "systematic_share": assumed(0.5, "ground gears: the profile deviations of a flank are largely common "
                                              "to its teeth (one grinding set-up); half their variance assumed")}
    return ErrorsParams(runout=assumed([RunoutParams(**x) for x in runouts], note),
                        pinhole=assumed([PinholeErrorParams(**x) for x in pinholes], pin),
                        flank_class=assumed([FlankClassParams(**flank)], teeth),
                        roller_diameter=assumed((), "no roller errors"), spall=assumed((), "no damage"),
                        tooth_fault=assumed((), "no damage"), tooth=assumed((), "the class's draw only"))


def rig_housing() -> HousingParams:
    """The housing under the accelerometer (docs/model.md §12), as two rigid-body modes on its feet. The source
    describes neither housing nor mounting: a cast-iron housing around the 246 mm ring, bolted by four feet
    to a stiff bed, sized here from the gears."""
    feet = "four bolted feet of ~5e8 N/m each on a stiff bed"
    return HousingParams(
        mass=assumed("50 kg", "cast-iron housing around the ring: ~320 mm outside diameter, 160 mm long, 15 mm "
                              "walls, two 20 mm end covers with the bearing seats, feet (~6.6 dm^3 of cast iron)"),
        translation_frequency=assumed("1.0 kHz", f"{feet}: sqrt(2e9 N/m / 50 kg)/2 pi; gearbox housings' first "
                                                 "modes lie in the low kHz"),
        translation_damping_ratio=assumed(0.05, "bolted joints and a cast housing: a few percent of critical"),
        rocking_inertia=assumed("2.9 kg*m^2", "about the foot plane: J_cm + m h^2 = 50 kg x (0.13 m)^2 + "
                                              "50 kg x (0.2 m)^2"),
        rocking_frequency=assumed("630 Hz", f"{feet} at +-150 mm: k_theta = 4 x 5e8 N/m x (0.15 m)^2 = 4.5e7 "
                                            "N m/rad, sqrt(k_theta / J_O)/2 pi"),
        rocking_damping_ratio=assumed(0.05, "bolted joints and a cast housing: a few percent of critical"),
        rocking_centre_depth=assumed("0.2 m", "a foot-mounted housing rocks about its foot plane's elastic "
                                              "centre, below the axis by the housing's centre height"),
    )


def rig_accelerometer() -> SensorParams:
    """The housing accelerometer of docs/model.md §12, at the top of the housing over the ring: it hears the planet
    passing beneath it. The source gives only "on the carrier bearing housing near the carrier axis"
    (:func:`carrier_bearing_accelerometer` puts it there); where on the housing, how wide a planet is heard and
    through what mass, and the housing's modes (:func:`rig_housing`) are assumed."""
    return SensorParams(
        angle=assumed("90 deg", "top of the housing (+Y of the fixed frame), where a rig's accelerometer is "
                                "usually mounted; the source does not say"),
        radius=assumed("0.1 m", "on the housing's top, over the ring; it enters only the rocking lever, 0 for a "
                                "radial sensor at the top (the source's place: carrier_bearing_accelerometer)"),
        window_width=assumed("120 deg", "Hann window (McFadden & Smith 1985; Inalpolat & Kahraman 2009) as wide "
                                        "as the spacing of N = 3 planets: the sensor hears one planet at a time"),
        equivalent_mass=assumed("6.07 kg", "the ring gear's mass (Table 1): the mass a ring-mesh force "
                                           "accelerates before it reaches the housing"),
        direction=assumed("radial", "an accelerometer screwed onto the housing's outer surface"),
        housing=rig_housing(),
    )


def carrier_bearing_accelerometer(params: DPGTParams) -> SensorParams:
    """The source's accelerometer where the source put it: "on the carrier bearing housing near the carrier axis"
    — on the boss of the carrier's bearing in the end cover, at radius r_s from the axis, read radially at the top
    (the side is not stated). Its paths' strengths follow from that place (:mod:`components.sensor`):

    * mesh path, window: the ring meshes lie at r_r from the axis, so a sensor at r_s < r_r is at a distance
      between r_r − r_s and r_r + r_s from every planet's mesh — none is out of reach: the window spans the
      whole circle (the widest Hann window, cos²(Δψ/2); an inverse-distance weight would hear a planet 120°
      away at (r_r − r_s)/|r_r e^{i 120°} − r_s| = 0.47 of the nearest, this window at 0.25);
    * mesh path, mass: a ring-mesh force reaches the boss only through the ring's seat and the housing, which
      it moves together: m_eq = the ring's mass + the housing's;
    * torque and bearing paths: the housing's modes (``params.rig.sensor.housing``), read at r_s; radial at the
      top the rocking moves the sensor across its axis (no torque path, :func:`components.sensor.rocking_lever`).

    The housing and every other path law are those of ``params``' own sensor (:func:`rig_accelerometer`)."""
    base = params.rig.sensor
    m_eq = params.gears.ring.mass + base.housing.mass
    return SensorParams(
        angle=assumed("90 deg", "top of the housing (+Y of the fixed frame); the source does not say"),
        radius=assumed("0.05 m", "the carrier bearing's boss in the end cover, near the carrier axis (the source): "
                                 "a bearing of ~80 mm outside diameter in a 10 mm wall; the source gives no size"),
        window_width=derived("360 deg", "a sensor at r_s = 0.05 m < r_r = 0.123 m (the ring's pitch radius) is "
                                        "within r_r +- r_s of every planet's ring mesh: the window spans the circle"),
        equivalent_mass=derived(m_eq.to("kg"), f"the ring's mass ({params.gears.ring.mass:~P}) + the housing's "
                                              f"({base.housing.mass:~P}): a ring-mesh force reaches the carrier "
                                              "bearing's boss only through the ring's seat and the housing"),
        direction=assumed("radial", "an accelerometer screwed onto the boss's outer surface"),
        housing=base.housing,
    )


# the rig's accelerometer at each place: name -> the sensor's parameters for a machine
SENSOR_PRESETS = MappingProxyType({
    "housing_top": lambda params: params.rig.sensor,
    "carrier_bearing": carrier_bearing_accelerometer,
})


def ideal_carrier_drive() -> CarrierRippleParams:
    """No speed ripple: the reference machine's carrier drive (docs/model.md §10.3: 0 for the reference machine)."""
    ideal = "an ideal drive (docs/model.md §10.3: no ripple on the reference machine)"
    return CarrierRippleParams(**{f"amplitude_{k}": assumed("0 rad/s", ideal) for k in CarrierRippleParams.ORDERS},
                               **{f"phase_{k}": assumed("0 deg", "immaterial without ripple")
                                  for k in CarrierRippleParams.ORDERS})


def reference_dpgt(condition: int = 3, direction: str = "forward") -> DPGTParams:
    """The reference DPGT (every value in docs/parameters.md, generated from here), at operating ``condition`` (1..4) and ``direction``."""
    return DPGTParams(
        gears=reference_gears(),
        bearing=reference_bearing(),
        lubricant=LubricantParams(
            drag_coefficient=assumed(1.0, span=Span(0.5, 2.0, "a cylinder's drag coefficient over Re 1e2-1e5, rollers shielding one another")),
            density=assumed("45 kg/m^3", "oil-air mixture: 5 % oil of 870 kg/m^3", span=Span("15 kg/m^3", "90 kg/m^3", "2-10 % oil by volume")),
            oil_density=assumed("870 kg/m^3", "mineral oil at 15 degC"),
            thermal_expansion=assumed("7.2e-4 1/K", "lubricating oils, API MPMS 11.1 (ASTM D1250-04): "
                                                    "alpha_60 = K1/rho_60 per degF, K1 = 0.34878 kg/m^3: "
                                                    "1.8 x 0.34878/870 per K"),
            viscosity_40=OIL_GRADES["VG68"]["viscosity_40"],
            viscosity_100=OIL_GRADES["VG68"]["viscosity_100"],
            temperature=assumed("60 degC", "oil in the bearings of a running gearbox; not stated by the source", span=Span("40 degC", "90 degC", "a cool rig to a hot industrial gearbox's oil")),
            pressure_viscosity=assumed("2.2e-8 1/Pa", "mineral oil (Hamrock, Fundamentals of Fluid Film "
                                                      "Lubrication: 1.5-2.5e-8 1/Pa)", span=Span("1.5e-8 1/Pa", "2.5e-8 1/Pa", "Hamrock's range for mineral oils")),
            thermal_conductivity=assumed("0.13 W/(m*K)", "mineral oils: 0.12-0.15 W/(m K) in handbooks, "
                                                         "slowly falling with temperature; not measured for "
                                                         "this oil"),
            roughness=assumed("0.15 um", "composite Rq of a ground raceway (~0.1 um) and a roller (~0.1 um)", span=Span("0.1 um", "0.3 um", "superfinished to plain ground surfaces")),
            limiting_shear_stress=assumed("2 MPa", "Bair and Winer (1979): small at zero pressure"),
            limiting_shear_slope=assumed(0.07, "Bair and Winer (1979), mineral oils: tau_L/p ~ 0.05-0.1; with "
                                               "it the EHL traction plateau is near the tanh law's 0.08"),
            film_speed_reg=assumed("0.1 m/s", "far below the entraining speeds of m/s: matters only near rest"),
            film_shear_modulus=assumed("1 GPa", "Johnson and Tevaarwerk (1977): 0.5-2 GPa for mineral oils in EHL "
                                                "contacts"),
            limiting_shear_law=assumed("constant", "gamma_L is not referred to a temperature; dyson: its "
                                                   "temperature form (docs/model.md §9.3)"),
            limiting_shear_reference_temperature=assumed("60 degC", "the reference oil temperature: the dyson law "
                                                                    "keeps gamma_L = 0.07 there"),
            limiting_shear_pole_temperature=assumed("-105 degC", "Dyson (1970) via Zhou & Hoeprich (1991, J. Tribol. "
                                                                 "113, eqs. 36-37): tau_L = G/4, G = 1.2 p/(2.52 + "
                                                                 "0.024 t) - 1e8, a mineral oil, t taken in degC: "
                                                                 "t = -2.52/0.024"),
        ),
        support=SupportParams(
            sun_stiffness=assumed("1e8 N/m", span=Span("1e6 N/m", "1e10 N/m", "a floating sun (held by its coupling only) to a rigid seat", log=True)),
            ring_stiffness=assumed("1e8 N/m", span=Span("1e7 N/m", "1e10 N/m", "a ring on a loose spline fit to one shrunk into a stiff housing", log=True)),
            carrier_stiffness=assumed("1e8 N/m", span=Span("3e7 N/m", "3e9 N/m", "rolling bearings of this size (1e8-1e9 N/m) in a compliant or stiff housing", log=True)),
            damping_ratio=assumed(0.02, span=Span(0.01, 0.05, "bolted joints and bearings: 1-5 % of critical")),
            ring_tangential_stiffness=assumed("1e9 N/m", "ring fixed: k_theta = 1e9 N/m x r_r^2", span=Span("1e8 N/m", "1e10 N/m", "a torque arm or splines to a bolted flange", log=True)),
        ),
        mesh=MeshParams(
            smoothing_width=assumed(0.05, "the source gives none: 5 % of a mesh cycle per step, "
                                          "smooth enough for Newton, sharp enough to keep the wave", span=Span(0.02, 0.09, "from under half the step to the widest the outer-ring mesh's contact ratio 1.91 allows")),
            damping_ratio=assumed(0.07, span=Span(0.03, 0.17, "mesh damping ratios the gear dynamics literature reports")),
            damping_ramp=assumed("1 um", "a contact's damping grows with its compressed zone (Hunt & Crossley); "
                                         "about a third of the least compressed loaded flank at rated load (2.9 um, "
                                         "the ring mesh at condition 3; up to 18 um at condition 1), so loaded "
                                         "flanks keep their whole damping",
                                 span=Span("0 um", "2 um", "no ramp (the Kelvin-Voigt jump) to two thirds of the least compressed loaded flank")),
            face_slices=assumed(11, "odd (a slice on the mid-plane); the tilt stiffness k b^2 (1 - 1/n_m^2)/12 is "
                                    "within 1 % of c_gamma b^3/12"),
        ),
        operating=operating_point(condition, direction),
        rig=RigParams(
            carrier_drive_bandwidth=assumed("80 Hz", "carrier speed error < 0.1 rad/s by 30 ms (measured; at 30 Hz "
                                                     "it still swung 8 rad/s), far below the mesh frequency"),
            carrier_drive_damping_ratio=assumed(0.7),
            carrier_ripple=ideal_carrier_drive(),
            load_ramp_mesh_periods=assumed(20.0, "no impulse at the start (docs/model.md §10.4)"),
            load_ramp_max=assumed("0.05 s", "near-zero speeds have no mesh period"),
            sensor=rig_accelerometer()),
        gravity=assumed("9.81 m/s^2", "standard gravity along -Y of the fixed frame"),
        errors=perfect_machine(),
    )


def reference_bearing_rig() -> BearingRigParams:
    """The single-bearing rig (docs/model.md §10.5): a planet-like outer ring, its speed drive and the
    aids that let the loaded ring settle (they do not change the static solution)."""
    return BearingRigParams(
        ring_mass=assumed("0.557 kg", "a planet-like outer ring: the reference planet's mass"),
        ring_radius=assumed("0.036 m", "the reference planet's pitch radius (36 mm)"),
        drive_bandwidth=assumed("100 Hz", "holds the ring's spin; far above the rig's slow settling"),
        tilt_support_stiffness=assumed("1e7 N*m/rad", "a stiff housing: 400-2700x the reference bearing's tilt "
                                                      "stiffness at 10 kN (measured: 3.7e3 N m/rad one row, 2.6e4 two "
                                                      "rows, at 4 arcmin), so the ring's slope stays within 0.3 % of "
                                                      "the tilt"),
        drive_damping_ratio=assumed(0.7),
        settle_damping_ratio=assumed(0.2, "of the ring's radial mode: settles in a few periods"),
        load_ramp_periods=assumed(20.0, "of the ring's radial mode: no impulse at the start"),
        gravity=assumed("9.81 m/s^2", "standard gravity along -y, when the scene option gravity is on"),
    )


def load_toml(path, base: DPGTParams | None = None) -> DPGTParams:
    """``base`` (default: the reference machine) with the overrides in the TOML file ``path``."""
    base = reference_dpgt() if base is None else base
    return with_overrides(base, overrides_from_toml(Path(path).read_text(encoding="utf-8")))
