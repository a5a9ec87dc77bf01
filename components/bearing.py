"""Planet bearing: Z rollers and a cage between a pin (inner raceway, on a body) and a bore (outer
raceway, the planet), or — when the scene asks for it — a linear radial spring.

All rollers of all bearings share one family per contact kind (race_inner, race_outer, pocket,
guide, drag), so adding a bearing adds instances, never element objects.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mbd.elements import BodySpring, SlopeGyroscopic
from mbd.elements.sliced import SlicedRaceContact, iso_16281_stiffness, slice_stations
from mbd.elements.pocket_film import CageDrag, PocketFilm
from mbd.elements.race_film import RaceFilm
from mbd.elements.contact import (IMPACT_LAWS, ROLLING_LAWS, TRACTION_LAWS, DryLand, EHLTraction, GuideContact,
                                  HoupertRolling, HydrodynamicLand, LubricantDrag, PocketContact, PocketRetention,
                                  RaceContact,
                                  RollingResistance, SlideRollTraction, TanhTraction, Traction)

from .families import FAMILY
from .lubrication import limiting_shear_slope, oil_density, reduced_modulus
from .params import BearingSI, LubricantSI
from .profiles import roller_drop
from .scene import Scene
from .units import ParameterError

__all__ = ["BearingHandles", "add_planet_bearing", "bearing_kinematics", "cage_slip_pct", "roller_slip_pct", "traction"]


@dataclass(frozen=True)
class BearingHandles:
    """What :func:`add_planet_bearing` added: body names and the instance slices of its contacts in the
    shared families (None where the scene leaves a part out)."""
    kind: str                                 # "rollers" (roller and cage model) or "linear" (radial spring)
    rollers: tuple[str, ...] = ()
    race_inner: slice | None = None
    race_outer: slice | None = None
    drag: slice | None = None
    pocket: slice | None = None
    retention: slice | None = None            # a roller-centred cage's radial pocket retention
    guide: slice | None = None
    pocket_film: slice | None = None          # the pockets' oil film (bearing.cage.pocket_law = "hydrodynamic")
    race_film_inner: slice | None = None      # the raceways' film of the open gaps (bearing.race_film)
    race_film_outer: slice | None = None
    cage_drag: slice | None = None            # the mixture's drag on the cage (bearing.drag_law = "viscous")
    cage: str | None = None
    spring: slice | None = None               # the linear bearing's spring
    omega_cage: float | None = None           # pure-rolling start speeds [rad/s]
    omega_roller: float | None = None
    rows: int = 1                             # roller rows built one by one (the sliced model; the planar model
                                              # folds its rows into one roller body: 1); rollers listed row by row


# each traction law from the bearing's SI parameters (a parameter, bearing.traction_law, names one)
def _ehl(b, lub):
    if lub is None:
        raise ParameterError.at("bearing.traction_law", "'ehl' needs a lubricant (its viscosity and limiting "
                                                        "shear); this scene has none")
    E_red = reduced_modulus(b.elastic_modulus, b.poisson_ratio, b.elastic_modulus, b.poisson_ratio)
    gamma_L = limiting_shear_slope(lub.limiting_shear_law, lub.limiting_shear_slope, lub.temperature,
                                   lub.limiting_shear_reference_temperature, lub.limiting_shear_pole_temperature)
    return EHLTraction(eta0=lub.oil_viscosity, alpha_p=lub.pressure_viscosity, E_red=E_red, length=b.roller_length,
                       tau_L0=lub.limiting_shear_stress, gamma_L=gamma_L,
                       G_e=lub.film_shear_modulus, u_reg=lub.film_speed_reg, beta=lub.temperature_viscosity,
                       k_oil=lub.thermal_conductivity)


_TRACTION_FROM = {
    "tanh": lambda b, lub: TanhTraction(mu_max=b.traction_mu_max, v0=b.traction_v0),
    "slide_roll": lambda b, lub: SlideRollTraction(
        A=b.slide_roll_traction.A, B=b.slide_roll_traction.B, C=b.slide_roll_traction.C,
        D=b.slide_roll_traction.D, u_reg=b.slide_roll_traction.rolling_speed_reg,
        s_eps=b.slide_roll_traction.ratio_reg),
    "ehl": _ehl,
}
assert set(_TRACTION_FROM) == set(TRACTION_LAWS)


def traction(b: BearingSI, lubricant: LubricantSI | None = None) -> Traction:
    """The roller–raceway traction law named by ``bearing.traction_law``, with its SI parameters (the
    lubricant's too, for the EHL law)."""
    return _TRACTION_FROM[b.traction_law](b, lubricant)


def rolling_resistance(b: BearingSI, lubricant: LubricantSI | None = None) -> RollingResistance | None:
    """The rolling-resistance law named by ``bearing.rolling_resistance`` (None for "none"), with the oil's
    viscosity and the rollers' reduced modulus and length."""
    if b.rolling_resistance == "none":
        return None
    if lubricant is None:
        raise ParameterError.at("bearing.rolling_resistance", f"{b.rolling_resistance!r} needs a lubricant (its "
                                                              "viscosity); this scene has none")
    assert set(ROLLING_LAWS) == {"houpert"}
    E_red = reduced_modulus(b.elastic_modulus, b.poisson_ratio, b.elastic_modulus, b.poisson_ratio)
    return HoupertRolling(eta0=lubricant.oil_viscosity, E_red=E_red, length=b.roller_length,
                          u_reg=lubricant.film_speed_reg)


def mixture(lubricant: LubricantSI) -> tuple[float, float]:
    """(density, dynamic viscosity) of the oil–air mixture of the viscous drag law: the oil's at the operating
    temperature times its volume fraction ``lubricant.oil_fraction`` (air's own density and viscosity, ≈ 1/700 and
    ≈ 1/1000 of the oil's, left out)."""
    X = lubricant.oil_fraction
    rho = oil_density(lubricant.oil_density, lubricant.thermal_expansion, lubricant.temperature)
    return X * rho, X * lubricant.oil_viscosity


def bearing_kinematics(b: BearingSI, omega_inner: float, omega_outer: float) -> tuple[float, float]:
    """(cage orbital speed, roller spin) in pure rolling, from the inner- and outer-raceway speeds.
    ω_m = (ω_i R_i + ω_o R_o')/(R_i + R_o') with R_o' = (d_m + D)/2; roller spin from rolling on the
    inner race: ω_R = ω_m − 2 (ω_i − ω_m) R_i / D."""
    d_m, D = b.pitch_diameter, b.roller_diameter
    Ri, Ro = 0.5 * (d_m - D), 0.5 * (d_m + D)
    wm = (omega_inner * Ri + omega_outer * Ro) / (Ri + Ro)
    return wm, wm - 2.0 * (omega_inner - wm) * Ri / D


def cage_slip_pct(b: BearingSI, cage_speed_rel, planet_speed_rel):
    """Cage slip [%], the one definition (results.nc's series and summary.json's ``cage_slip_pct``): how far the cage
    turns below its pure-rolling speed, both speeds relative to the pin (the carrier), 100 (1 − ω_cage/ω_m) with ω_m
    from :func:`bearing_kinematics` (pin at rest, the planet's bore at ``planet_speed_rel``). Arrays or scalars;
    NaN where the planet does not turn relative to its pin (no rolling speed to slip from)."""
    w_m, _ = bearing_kinematics(b, 0.0, np.asarray(planet_speed_rel, float))
    return 100.0 * (1.0 - np.asarray(cage_speed_rel, float) / np.where(w_m != 0.0, w_m, np.nan))


def roller_slip_pct(b: BearingSI, roller_speed_rel, planet_speed_rel):
    """Roller slip [%], the one definition: how far a roller spins below its pure-rolling spin, both speeds relative to
    the pin (the carrier), 100 (1 − ω_R/ω_R,epi) with ω_R,epi from :func:`bearing_kinematics` (pin at rest, the
    planet's bore at ``planet_speed_rel``) — the measure of Guo & Keller (NREL 2020), the rollers' speed against
    their epicyclic speed. Arrays or scalars; NaN where the planet does not turn relative to its pin."""
    _, w_r = bearing_kinematics(b, 0.0, np.asarray(planet_speed_rel, float))
    return 100.0 * (1.0 - np.asarray(roller_speed_rel, float) / np.where(w_r != 0.0, w_r, np.nan))


def entry_slide_roll(slip_pct):
    """Slide-to-roll ratio on the pin of a roller that meets the load zone at the roller slip ``slip_pct`` [%] (the one
    definition; :func:`roller_slip_pct`): with the roller's centre at the cage's rolling speed ω_m and its spin short of
    the rolling spin by s = slip/100, the sliding speed on the pin is s ω_m r and the entraining speed (1 − s/2) ω_m r
    (r the roller centre's radius about the pin), so SRR = s/(1 − s/2): 0 rolling, 2 for a roller that does not turn."""
    s = np.asarray(slip_pct, float) / 100.0
    return s / (1.0 - 0.5 * s)


def add_planet_bearing(scene: Scene, tag: str, *, pin_body: str, pin_local, outer_body: str, bearing: BearingSI,
                       lubricant: LubricantSI | None, pin_xy, pin_vel, omega_pin: float, omega_outer: float,
                       damage: dict, bore_tilt_inertia: float | None = None, bore_spin_inertia: float | None = None,
                       pin_slope=(0.0, 0.0)) -> BearingHandles:
    """Add one bearing (``bearing``: ``params.si().bearing``; ``lubricant``: ``params.si().lubricant``,
    needed when the scene has drag on). ``pin_local`` is the raceway centre in pin_body axes;
    ``pin_xy``/``pin_vel`` its position/velocity in the fixed frame at t = 0 (the kinematic steady
    state); ``omega_pin`` and ``omega_outer`` the absolute spin speeds of the inner and outer raceway
    bodies. The scene's option ``cage`` says "free", "held" (a fixed cage body: the rollers cannot
    orbit) or "none". ``damage``: {} for a perfect bearing, else (:mod:`components.faults`) ``D`` the (Z,)
    roller diameters and ``inner``/``outer`` the raceways' spall parameters. With ``bearing.model = "sliced"``
    (docs/model.md §8.8) the contacts are sliced: the bore body gets a slope pair of diametral inertia
    ``bore_tilt_inertia`` [kg·m²] with its gyroscopic terms (polar inertia ``bore_spin_inertia``, §2.4), every roller
    a tilt, and ``pin_slope`` (2,) is the pin's prescribed slope in pin-body axes [rad]. Returns handles."""
    b, opt = bearing, scene.options
    pin_local = np.asarray(pin_local, float)
    if opt.bearings == "linear":
        fam = scene.family(FAMILY["linear"], BodySpring, ("body_a", "body_b"))
        sl = fam.add(1, body_a=[pin_body], body_b=[outer_body], k=b.linear_stiffness, c=b.linear_damping,
                     marker_a=pin_local[None, :], marker_b=np.zeros((1, 2)))
        return BearingHandles("linear", spring=sl)

    Z, D, d_m = int(b.rollers), b.roller_diameter, b.pitch_diameter
    wm, wr = bearing_kinematics(b, omega_pin, omega_outer)
    if opt.cage == "held":
        # a held cage stops the orbit, so the rollers slide on both races; start them at the spin where
        # the two tractions balance for equal loads (equal slips): ω_R = (ω_o R_o − ω_i R_i)/D
        wm = 0.0
        wr = (omega_outer * 0.5 * (d_m + D) - omega_pin * b.inner_raceway_radius) / D
    psi = 2 * np.pi * np.arange(Z) / Z
    rho = 0.5 * d_m + 0.25 * b.clearance          # centred in the radial gap
    pin_xy = np.asarray(pin_xy, float)
    pin_vel = np.asarray(pin_vel, float)
    # the planar model folds identical rows into one roller body of rows × the mass (its contacts count each
    # physical roller b.rows times); the sliced model builds every row's rollers at their axial station
    rows, fold = (b.rows, 1) if b.model == "sliced" else (1, b.rows)
    names = [roller_name(tag, r, j) for r in range(rows) for j in range(Z)]
    for r in range(rows):
        for j in range(Z):
            off = rho * np.array([np.cos(psi[j]), np.sin(psi[j])])
            vel = pin_vel + wm * np.array([-off[1], off[0]])
            scene.body(roller_name(tag, r, j), fold * b.roller_mass, fold * b.roller_inertia,
                       pose=(*(pin_xy + off), 0.0), vel=(*vel, wr))
    marker = np.tile(pin_local, (Z, 1))
    common = dict(D=damage.get("D", D), K=b.contact_stiffness, zeta=b.contact_damping_ratio, m_roller=b.roller_mass,
                  multiplicity=b.rows, damping_ramp=b.race_damping_ramp)
    law = dict(traction=traction(b, lubricant), exponent=b.contact_exponent)     # family-wide laws
    rolling = rolling_resistance(b, lubricant)
    if rolling is not None:
        law["rolling"] = rolling
    if b.model == "sliced":
        return _add_sliced_contacts(scene, tag, b, names, psi, wm, wr, pin_body, pin_local, outer_body, lubricant,
                                    pin_xy, pin_vel, damage, law, bore_tilt_inertia, bore_spin_inertia, pin_slope)
    inner = scene.family(FAMILY["race_inner"], RaceContact, ("roller", "race_body"), kind="inner", **law)
    s_in = inner.add(Z, roller=names, race_body=[pin_body] * Z, race_marker=marker, R_race=b.inner_raceway_radius,
                     **common, **damage.get("inner", {}))
    outer = scene.family(FAMILY["race_outer"], RaceContact, ("roller", "race_body"), kind="outer", **law)
    s_out = outer.add(Z, roller=names, race_body=[outer_body] * Z, race_marker=np.zeros((Z, 2)),
                      R_race=b.outer_raceway_radius, **common, **damage.get("outer", {}))
    handles = BearingHandles("rollers", rollers=tuple(names), race_inner=s_in, race_outer=s_out, omega_cage=wm,
                             omega_roller=wr)
    if b.race_film != "none":
        handles = replace(handles, **_add_race_film(scene, b, names, pin_body, marker, outer_body, lubricant,
                                                    damage.get("D", D)))
    return _add_drag_and_cage(scene, tag, b, names, psi, wm, pin_body, marker, outer_body, lubricant, pin_xy,
                              pin_vel, handles)


def _add_race_film(scene, b, names, pin_body, marker, outer_body, lubricant, D) -> dict:
    """The oil film of every roller's open gap on the pin's and the bore's raceway (docs/model.md §8.9; the law
    bearing.race_film names), the oil at its operating temperature (the EHL laws' viscosity): the BearingHandles
    fields it fills."""
    if lubricant is None:
        raise ParameterError.at("bearing.race_film", f"{b.race_film!r} needs a lubricant (its viscosity); this scene "
                                                     "has none")
    Z = len(names)
    common = dict(D=D, length=b.roller_length, eta=lubricant.oil_viscosity, floor=b.race_film_floor,
                  multiplicity=b.rows)
    inner = scene.family(FAMILY["race_film_inner"], RaceFilm, ("roller", "race_body"), kind="inner",
                         law=b.race_film)
    s_in = inner.add(Z, roller=names, race_body=[pin_body] * Z, race_marker=marker, R_race=b.inner_raceway_radius,
                     **common)
    outer = scene.family(FAMILY["race_film_outer"], RaceFilm, ("roller", "race_body"), kind="outer",
                         law=b.race_film)
    s_out = outer.add(Z, roller=names, race_body=[outer_body] * Z, race_marker=np.zeros((Z, 2)),
                      R_race=b.outer_raceway_radius, **common)
    return {"race_film_inner": s_in, "race_film_outer": s_out}


def _add_drag_and_cage(scene, tag, b, names, psi, wm, pin_body, marker, outer_body, lubricant, pin_xy, pin_vel,
                       handles, fold=None):
    """The rollers' lubricant drag and the cage (as the scene's options ask), for either contact model: ``names``
    every roller body, row by row (``psi`` their pocket angles), ``fold`` the physical rollers one body stands for
    (default ``b.rows``: the planar model's folded rows; 1 for the sliced model's explicit rows)."""
    opt, Z, D, d_m = scene.options, len(names), b.roller_diameter, b.pitch_diameter
    fold = b.rows if fold is None else fold
    if opt.drag:
        if lubricant is None:
            raise ParameterError.at("lubricant", "the scene has lubricant drag on (option drag) but no lubricant "
                                                 "was given")
        drag = scene.family(FAMILY["drag"], LubricantDrag, ("roller", "race_body"))
        if b.drag_law == "viscous":         # the mixture's density and viscosity at the oil's temperature
            rho_e, eta_e = mixture(lubricant)
            visc = dict(rho=rho_e, eta=eta_e)
        else:
            visc = dict(rho=lubricant.density)
        drag_slice = drag.add(Z, roller=names, race_body=[pin_body] * Z, race_marker=marker,
                              C_d=lubricant.drag_coefficient, D=D, l=b.roller_length, d_m=d_m,
                              multiplicity=fold, **visc)
        handles = replace(handles, drag=drag_slice)
    if opt.cage != "none":
        handles = replace(handles, **_add_cage(scene, tag, b, names, psi, pin_xy, pin_vel, wm, outer_body,
                                               opt.cage == "held", lubricant, fold))
        if opt.drag and b.drag_law == "viscous" and opt.cage != "held":
            handles = replace(handles, cage_drag=_add_cage_drag(scene, b, handles.cage, pin_body, lubricant))
    return handles


def cage_faces(b: BearingSI) -> tuple[float, float]:
    """(inner, outer) radius [m] of the cage's side faces in the mixture: annuli from the pin's raceway to the bore,
    (d_m − D)/2 … (d_m + D)/2 — the most a bore-guided cage's side rings can span (an upper bound on their area)."""
    return 0.5 * (b.pitch_diameter - b.roller_diameter), 0.5 * (b.pitch_diameter + b.roller_diameter)


def _add_cage_drag(scene, b, cage, pin_body, lubricant):
    """The mixture's moment on the cage's faces, against its rotation relative to the pin's body (docs/model.md
    §8.7): Cochran's free disk with the mixture's density and viscosity."""
    rho_e, eta_e = mixture(lubricant)
    fam = scene.family(FAMILY["cage_drag"], CageDrag, ("cage", "carrier"))
    return fam.add(1, cage=[cage], carrier=[pin_body], coef=CageDrag.coefficient(rho_e, eta_e, *cage_faces(b)))


def roller_name(tag: str, row: int, j: int) -> str:
    """The body name of roller ``j`` of row ``row`` of the bearing ``tag`` (row 0: ``tag.roller<j>``, a one-row
    bearing's names; row r > 0: ``tag.row<r>.roller<j>``)."""
    return f"{tag}.roller{j}" if row == 0 else f"{tag}.row{row}.roller{j}"


def row_stations(b: BearingSI) -> np.ndarray:
    """(rows,) axial station ζ_row [m] of each row's roller centres on pin and bore, from the bearing's centre:
    ζ_i = (i − (rows − 1)/2) e_r, e_r = ``bearing.row_spacing`` (two rows at ±e_r/2; docs/model.md §8.8)."""
    return (np.arange(b.rows) - 0.5 * (b.rows - 1)) * b.row_spacing


def sliced_law(b: BearingSI) -> dict:
    """The sliced contact's slice stations ``z``, profile drops ``drop`` and constant ``K`` from the bearing's
    parameters (bearing.slicing, bearing.profile; docs/model.md §8.8)."""
    z, _ = slice_stations(b.roller_length, b.slicing.slices)
    K = b.contact_stiffness if b.slicing.stiffness == "palmgren" else iso_16281_stiffness(b.roller_length)
    return dict(z=z, drop=roller_drop(b, z), K=K)


def roller_tilt_inertia(b: BearingSI) -> float:
    """One roller's diametral moment of inertia [kg·m²], a solid cylinder: m (D²/16 + l²/12)."""
    return b.roller_mass * (b.roller_diameter ** 2 / 16.0 + b.roller_length ** 2 / 12.0)


def _sliced_dofs(kind: str, race_slopes: bool | None = None):
    """resolve(columns, scene) of a sliced family: its (n, n_local) dofs from the body names and the scene's tilt
    coordinates (known at build), the other columns as they are. ``race_slopes``: the race body's slope pair among
    them (the bore's always; an elastic pin's, whose race body is the pin body itself)."""
    with_slopes = kind == "outer" if race_slopes is None else race_slopes

    def resolve(cat, scene):
        idx = lambda names: np.array([scene.index[nm] for nm in names], np.int64)     # noqa: E731
        r, rb, pb = idx(cat.pop("roller")), idx(cat.pop("race_body")), idx(cat.pop("pin_body"))
        tilt = np.array([scene.tilt_index[nm] for nm in cat.pop("roller_name")], np.int64)
        cols = [3 * r, 3 * r + 1, 3 * r + 2, tilt, 3 * rb, 3 * rb + 1, 3 * rb + 2]
        slope_of = cat.pop("slope_body")
        if with_slopes:
            s = np.array([scene.slope_index[nm] for nm in slope_of], np.int64)
            cols += [s[:, 0], s[:, 1], 3 * pb, 3 * pb + 1, 3 * pb + 2]
        return dict(dofs=np.column_stack(cols), **cat)
    return resolve


def _gyro_dofs(cat, scene):
    """The gyroscopic family's arguments: each body's θ and slope pair (known at build)."""
    names = [str(x) for x in cat.pop("body")]
    return dict(spin=np.array([3 * scene.index[nm] + 2 for nm in names], np.int64),
                slopes=np.array([scene.slope_index[nm] for nm in names], np.int64), **cat)


def _add_sliced_contacts(scene, tag, b, names, psi, wm, wr, pin_body, pin_local, outer_body, lubricant, pin_xy,
                         pin_vel, damage, law, bore_tilt_inertia, bore_spin_inertia, pin_slope):
    """The sliced raceway contacts of one bearing (:class:`mbd.elements.sliced.SlicedRaceContact`), the bore's slope
    pair and the rollers' tilts; then drag and cage as the planar model's."""
    if b.race_film != "none":
        raise ParameterError.at("bearing.race_film", f"{b.race_film!r} has no sliced contact; use 'none' with "
                                                     "bearing.model 'sliced'")
    if "inner" in damage or "outer" in damage or "rolling" in law:
        raise ParameterError.at("bearing.model", "'sliced' has no raceway spall and no rolling resistance; use "
                                                 "'planar' for those")
    for what, J in (("diametral", bore_tilt_inertia), ("polar", bore_spin_inertia)):
        if J is None or not J > 0.0:
            raise ParameterError.at("bearing.model", f"'sliced' needs the bore body's {what} inertia > 0 kg m^2 "
                                                     f"(this scene gives {J!r})")
    Z = len(names)                          # every roller body: b.rows rows of b.rollers
    pin_local = np.asarray(pin_local, float)
    marker = np.tile(pin_local, (Z, 1))
    if outer_body not in scene._slopes:
        scene.slopes(outer_body, bore_tilt_inertia)
        scene.family(FAMILY["gyroscopic"], SlopeGyroscopic, (), resolve=_gyro_dofs).add(
            1, body=[outer_body], polar_inertia=bore_spin_inertia)
    J_r = roller_tilt_inertia(b)
    for nm in names:
        scene.tilt(nm, J_r)
    sl = sliced_law(b)
    D = np.tile(np.broadcast_to(np.asarray(damage.get("D", b.roller_diameter), float), (b.rollers,)), b.rows)
    common = dict(D=D, K=sl["K"], zeta=b.contact_damping_ratio, m_roller=b.roller_mass,
                  damping_ramp=b.race_damping_ramp)
    fam_law = dict(traction=law["traction"], exponent=law["exponent"], z=sl["z"], drop=sl["drop"])
    slope = np.tile(np.asarray(pin_slope, float), (Z, 1))
    row_offset = np.repeat(row_stations(b), b.rollers)      # ζ_row of every roller, row by row
    elastic = pin_body in scene._slopes          # an elastic pin (components.dpgt.add_elastic_pin): its slope pair
    extra = dict(race_slopes=True) if elastic else {}
    inner = scene.family(FAMILY["race_inner"], SlicedRaceContact, (), resolve=_sliced_dofs("inner", elastic),
                         kind="inner", **fam_law, **extra)
    s_in = inner.add(Z, roller=names, roller_name=names, race_body=[pin_body] * Z, pin_body=[pin_body] * Z,
                     slope_body=[pin_body if elastic else outer_body] * Z, race_marker=marker, pin_marker=marker,
                     race_slope=slope, R_race=b.inner_raceway_radius, row_offset=row_offset, **common)
    outer = scene.family(FAMILY["race_outer"], SlicedRaceContact, (), resolve=_sliced_dofs("outer"), kind="outer",
                         **fam_law)
    s_out = outer.add(Z, roller=names, roller_name=names, race_body=[outer_body] * Z, pin_body=[pin_body] * Z,
                      slope_body=[outer_body] * Z, race_marker=np.zeros((Z, 2)), pin_marker=marker,
                      race_slope=np.zeros((Z, 2)), R_race=b.outer_raceway_radius, row_offset=row_offset, **common)
    handles = BearingHandles("rollers", rollers=tuple(names), race_inner=s_in, race_outer=s_out, omega_cage=wm,
                             omega_roller=wr, rows=b.rows)
    return _add_drag_and_cage(scene, tag, b, names, np.tile(psi, b.rows), wm, pin_body, marker, outer_body,
                              lubricant, pin_xy, pin_vel, handles, fold=1)


def _land(c, lubricant):
    """The guide-land law named by ``bearing.cage.land_law`` (the hydrodynamic land needs the oil)."""
    if c.land_law == "dry":
        return DryLand()
    if lubricant is None:
        raise ParameterError.at("bearing.cage.land_law", "'hydrodynamic' needs a lubricant; this scene has none")
    return HydrodynamicLand(eta=lubricant.oil_viscosity, width=c.land_width, min_film=c.land_min_film)


def _add_cage(scene: Scene, tag: str, b: BearingSI, names, psi, pin_xy, pin_vel, wm, outer_body, held,
              lubricant, fold) -> dict:
    """The cage body, its pockets (one per roller body: a pocket of a double-row cage holds a roller of each row,
    each its own pocket contact) and (a free cage) what centres it — its guide land on the outer raceway
    (``bearing.cage.guidance = "outer_land"``) or its pockets' radial retention of the rollers (``"rollers"``,
    docs/model.md §8.5): the BearingHandles fields they fill."""
    c, Z, D = b.cage, len(names), b.roller_diameter
    cage = f"{tag}.cage"
    scene.body(cage, c.mass, c.inertia, pose=(*pin_xy, 0.0), vel=(*pin_vel, wm), fixed=held)
    law = IMPACT_LAWS[c.impact_law]()
    pocket = scene.family(FAMILY["pocket"], PocketContact, ("roller", "cage"), impact_law=law)
    pockets = pocket.add(Z, roller=names, cage=[cage] * Z, pocket_angle=psi, pitch_radius=0.5 * b.pitch_diameter,
                         clearance=c.pocket_clearance, K_p=c.pocket_stiffness, restitution=c.restitution,
                         v_min=c.impact_speed_floor, mu=c.pocket_friction, v_mu=c.friction_speed, D=D,
                         multiplicity=fold)
    films = None
    if c.pocket_law == "hydrodynamic":      # the oil film on the pocket walls (docs/model.md §8.5)
        if lubricant is None:
            raise ParameterError.at("bearing.cage.pocket_law", "'hydrodynamic' needs a lubricant; this scene has none")
        film = scene.family(FAMILY["pocket_film"], PocketFilm, ("roller", "cage"))
        films = film.add(Z, roller=names, cage=[cage] * Z, pocket_angle=psi, pitch_radius=0.5 * b.pitch_diameter,
                         clearance=c.pocket_clearance, D=D, length=b.roller_length, eta=lubricant.oil_viscosity,
                         min_film=c.pocket_min_film, multiplicity=fold)
    guides = retention = None     # a held cage has no guide land
    if not held and c.guidance == "rollers":     # roller-centred: the pockets hold the rollers radially, no land
        fam = scene.family(FAMILY["retention"], PocketRetention, ("roller", "cage"), impact_law=law)
        retention = fam.add(Z, roller=names, cage=[cage] * Z, pitch_radius=0.5 * b.pitch_diameter,
                            clearance=c.pocket_radial_clearance, K_r=c.pocket_stiffness, restitution=c.restitution,
                            v_min=c.impact_speed_floor, mu=c.pocket_friction, v_mu=c.friction_speed, D=D,
                            multiplicity=fold)
    elif not held:
        guide = scene.family(FAMILY["guide"], GuideContact, ("cage", "planet"), impact_law=law,
                             land=_land(c, lubricant))
        guides = guide.add(1, cage=[cage], planet=[outer_body], clearance=c.guide_clearance,
                           K_g=c.guide_stiffness, restitution=c.restitution, v_min=c.impact_speed_floor,
                           mu=c.guide_friction, v_mu=c.friction_speed,
                           land_radius=0.5 * (b.pitch_diameter + D))
    return {"pocket": pockets, "retention": retention, "guide": guides, "cage": cage, "pocket_film": films}
