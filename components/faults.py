"""Manufacturing errors and faults of the DPGT (docs/model.md §11) as element parameters.

``params.errors`` (:class:`components.params.ErrorsParams`) names planets ("a1".."aN" inner, "b1".."bN"
outer) and gears ("sun", "ring" or a planet). :func:`check_errors` checks those names and sizes against
the machine; the other functions resolve the errors into the per-instance parameters of the element
families that feel them:

* pinhole error → the pin's marker on the carrier (:func:`pin_position`); a pinhole measured at the pin's two ends
  → its mean position error and its slope (:func:`pinhole_from_ends`), which :func:`pin_position` and
  :func:`pin_slope` take with the others;
* roller diameter deviation → that roller's D in both raceway contacts (:func:`roller_diameters`);
* spall → the raceway contacts' defect parameters (:func:`spall_args`);
* runout → the mesh families' geometric-centre offsets (:func:`mesh_error_args`);
* tooth faults and deviations → the gears' tooth tables (:mod:`components.teeth`, checked here too).

A machine without errors gets none of these parameters: its elements are evaluated exactly as before.
A family that holds one damaged instance holds the "healthy" values (depth 0, factor 1, offset 0) for
the others, which its law reduces to exactly.
"""
from __future__ import annotations

import numpy as np

from . import teeth
from .geometry import centre_distance_limit
from .params import PinholeErrorSI, PinSlopeSI
from .units import ParameterError

__all__ = ["check_errors", "pin_position", "pin_slope", "pinhole_from_ends", "pinholes", "pin_slopes",
           "roller_diameters", "spall_args", "mesh_error_args", "GEAR_OF"]

TWO_PI = 2.0 * np.pi
GEAR_OF = {"sun": "sun", "ring": "ring", "a": "inner_planet", "b": "outer_planet"}   # name → si.gears field


def _gear_si(si, name: str):
    return si.gears[GEAR_OF[name if name in ("sun", "ring") else name[0]]]


def _planet_index(name: str) -> int:
    return int(name[1:]) - 1


def pinhole_from_ends(x, plate_span: float) -> tuple[PinholeErrorSI, PinSlopeSI]:
    """A pinhole measured at its pin's two ends (:class:`~components.params.errors.PinholeEndsSI`: radial r and
    tangential t errors in the shaft-side plate at ζ = +L_c/2 and in the far plate at ζ = −L_c/2, L_c = ``plate_span``
    [m]) as the pin's position error and slope it stands for: the pin's axis is the straight line through its two
    ends, so at the bearing's mid-plane (ζ = 0) it is off by the ends' mean, ((r_s + r_f)/2, (t_s + t_f)/2), and it
    slopes by (r_s − r_f)/L_c radially and (t_s − t_f)/L_c tangentially — the slope γ = |that| in the direction
    χ = atan2(tangential, radial) from the planet's radial line (errors.pin_slope's form: the axis at station ζ is
    off by ζ γ (cos χ, sin χ) in the planet's radial and tangential directions)."""
    L = float(plate_span)
    if not L > 0.0:
        raise ParameterError.at("gears.carrier_plate_span", f"must be > 0 m to place a pin's two ends, got {L!r}")
    rs, ts, rf, tf = x.radial_shaft_plate, x.tangential_shaft_plate, x.radial_far_plate, x.tangential_far_plate
    sr, st = (rs - rf) / L, (ts - tf) / L
    return (PinholeErrorSI(planet=x.planet, radial=0.5 * (rs + rf), tangential=0.5 * (ts + tf)),
            PinSlopeSI(planet=x.planet, slope=float(np.hypot(sr, st)), direction=float(np.arctan2(st, sr))))


def pinholes(si) -> tuple:
    """Every pinhole position error: errors.pinhole and the mean of each errors.pinhole_ends entry."""
    span = si.gears.carrier_plate_span
    return tuple(si.errors.pinhole) + tuple(pinhole_from_ends(x, span)[0] for x in si.errors.pinhole_ends)


def pin_slopes(si) -> tuple:
    """Every pin slope error: errors.pin_slope and the slope of each errors.pinhole_ends entry whose ends differ."""
    span = si.gears.carrier_plate_span
    ends = (pinhole_from_ends(x, span)[1] for x in si.errors.pinhole_ends)
    return tuple(si.errors.pin_slope) + tuple(s for s in ends if s.slope != 0.0)


def check_errors(si) -> None:
    """Every error names a planet/gear/roller/tooth the machine has; a spall fits its raceway."""
    e, N, b = si.errors, si.layout.planets, si.bearing

    def planet(path, name):
        if name not in ("sun", "ring") and _planet_index(name) >= N:
            raise ParameterError.at(path, f"{name!r} names planet {_planet_index(name) + 1}, but the machine has "
                                          f"{N} planets per row ('a1'..'a{N}', 'b1'..'b{N}')")

    for i, x in enumerate(e.pinhole):
        planet(f"errors.pinhole[{i}].planet", x.planet)
    for i, x in enumerate(e.pin_slope):
        planet(f"errors.pin_slope[{i}].planet", x.planet)
    both = {x.planet for x in e.pinhole} | {x.planet for x in e.pin_slope}
    for i, x in enumerate(e.pinhole_ends):
        planet(f"errors.pinhole_ends[{i}].planet", x.planet)
        if x.planet in both:
            raise ParameterError.at(f"errors.pinhole_ends[{i}]", f"{x.planet}'s pinhole is given at its two ends and also "
                                                                 "by errors.pinhole or errors.pin_slope: give one form")
    ends = [x.planet for x in e.pinhole_ends]
    if len(set(ends)) < len(ends):
        raise ParameterError.at("errors.pinhole_ends", "at most one entry per planet (its pin has two ends)")
    for i, x in enumerate(e.runout):
        planet(f"errors.runout[{i}].gear", x.gear)
    for i, x in enumerate(e.roller_diameter):
        planet(f"errors.roller_diameter[{i}].planet", x.planet)
        if x.roller >= b.rollers:
            raise ParameterError.at(f"errors.roller_diameter[{i}].roller", f"must be in 0..{b.rollers - 1} "
                                                                           f"(Z = {b.rollers}), got {x.roller}")
        if abs(x.deviation) >= 0.01 * b.roller_diameter:
            raise ParameterError.at(f"errors.roller_diameter[{i}].deviation",
                                    f"must be smaller than 1 % of the roller diameter ({0.01 * b.roller_diameter:.3g} m), "
                                    f"got {x.deviation:.3g} m")
    for i, x in enumerate(e.spall):
        planet(f"errors.spall[{i}].planet", x.planet)
        R = b.inner_raceway_radius if x.raceway == "inner" else b.outer_raceway_radius
        if x.edge > x.width:
            raise ParameterError.at(f"errors.spall[{i}].edge", f"must be <= the width ({x.width:.3g} m), got {x.edge:.3g} m")
        if x.width + x.edge >= np.pi * R:
            raise ParameterError.at(f"errors.spall[{i}].width", f"must be shorter than half the raceway "
                                                                f"({np.pi * R:.3g} m), got {x.width:.3g} m")
        # a defect cannot be deeper than the ring it is in: the solid pin, or the planet's rim under its bore
        planet_gear = si.gears["inner_planet" if x.planet[0] == "a" else "outer_planet"]
        ring, what = ((b.inner_raceway_radius, "the pin's radius") if x.raceway == "inner" else
                      (planet_gear.root_radius - b.outer_raceway_radius, "the planet's rim under the bore"))
        if x.depth >= ring:
            raise ParameterError.at(f"errors.spall[{i}].depth", f"must be smaller than the ring it is in ({what}, "
                                                                f"{ring * 1e3:.3g} mm), got {x.depth * 1e3:.3g} mm")
    keys = [(x.planet, x.raceway) for x in e.spall]
    if len(set(keys)) < len(keys):
        raise ParameterError.at("errors.spall", "at most one spall per raceway (two entries name the same "
                                                "planet and raceway)")
    for i, x in enumerate(e.tooth_fault):
        planet(f"errors.tooth_fault[{i}].gear", x.gear)
        z = _gear_si(si, x.gear).teeth
        if x.tooth >= z:
            raise ParameterError.at(f"errors.tooth_fault[{i}].tooth", f"must be in 0..{z - 1} ({x.gear} has {z} teeth), "
                                                                      f"got {x.tooth}")
    runout = [x.gear for x in e.runout]
    if len(set(runout)) < len(runout):
        raise ParameterError.at("errors.runout", "at most one runout entry per gear")
    _check_pinholes(si)
    teeth.check_teeth(si)


def _check_pinholes(si) -> None:
    """A pinhole error moves its planet, and so its centre distances, by its size (plus the bearing's play c/2):
    the gears must take that (no tip striking a root, ε_α ≥ 1; :func:`geometry.centre_distance_limit`), as the
    clearance check asks of the play alone."""
    e, lay = si.errors, si.layout
    play = 0.5 * si.bearing.clearance
    moved: dict[str, float] = {}
    first: dict[str, str] = {}
    named = [(f"errors.pinhole[{i}]", x) for i, x in enumerate(e.pinhole)]
    named += [(f"errors.pinhole_ends[{i}]", x) for i, x in enumerate(pinholes(si)[len(e.pinhole):])]
    for path, x in named:
        moved[x.planet] = moved.get(x.planet, 0.0) + float(np.hypot(x.radial, x.tangential))
        first.setdefault(x.planet, path)
    for planet, d in moved.items():
        n = _planet_index(planet)
        other = moved.get(("b" if planet[0] == "a" else "a") + planet[1:], 0.0)     # the pair's other planet
        meshes = (("sun_inner", d + play), ("inner_outer", d + other + 2 * play)) if planet[0] == "a" else \
                 (("inner_outer", d + other + 2 * play), ("outer_ring", d + play))
        for key, da in meshes:
            what = centre_distance_limit(lay.meshes[key], lay.gears, da)
            if what:
                raise ParameterError.at(first[planet],
                                        f"moves {planet} by {d * 1e6:.4g} um, its {key.replace('_', '-')} centre distance "
                                        f"(with the bearing's play) by up to {da * 1e3:.3f} mm, at which {what}: the "
                                        f"gears allow less (pair {n + 1})")


def pin_position(si, planet: str, nominal) -> np.ndarray:
    """The pin centre of ``planet`` in the carrier's axes: nominal plus its pinhole errors (radial along the
    planet's angle ψ, tangential along ψ + 90°; :func:`pinholes`)."""
    n = _planet_index(planet)
    psi = (si.layout.psi_a if planet[0] == "a" else si.layout.psi_b)[n]
    er, et = np.array([np.cos(psi), np.sin(psi)]), np.array([-np.sin(psi), np.cos(psi)])
    out = np.array(nominal, float)
    for x in pinholes(si):
        if x.planet == planet:
            out = out + x.radial * er + x.tangential * et
    return out


def pin_slope(si, planet: str, nominal) -> np.ndarray:
    """The slope (2,) [rad] of ``planet``'s pin axis in the carrier's axes (docs/model.md §8.8): its errors.pin_slope
    entries and its errors.pinhole_ends' slope (:func:`pin_slopes`: γ along the direction χ from the planet's radial
    line) plus, with gears.carrier_windup, the carrier's
    wind-up: the shaft-side plate (at +ζ) turns by Δθ = T_c/k_tc against the far plate (T_c the carrier's torque,
    k_tc gears.carrier_torsional_stiffness), so a pin at radius r_p (``nominal`` its centre) slopes by r_p Δθ/L_c
    along the tangential direction (L_c gears.carrier_plate_span): forward and reverse tilt it opposite ways."""
    n = _planet_index(planet)
    psi = (si.layout.psi_a if planet[0] == "a" else si.layout.psi_b)[n]
    out = np.zeros(2)
    for x in pin_slopes(si):
        if x.planet == planet:
            out = out + x.slope * np.array([np.cos(psi + x.direction), np.sin(psi + x.direction)])
    G = si.gears
    if G.carrier_windup:
        nominal = np.asarray(nominal, float)
        r_p = float(np.hypot(*nominal))
        e_t = np.array([-nominal[1], nominal[0]]) / r_p
        dtheta = si.operating.carrier_torque / G.carrier_torsional_stiffness
        out = out + r_p * dtheta / G.carrier_plate_span * e_t
    return out


def roller_diameters(si, planet: str) -> np.ndarray:
    """(Z,) roller diameters of ``planet``'s bearing [m]."""
    D = np.full(si.bearing.rollers, si.bearing.roller_diameter)
    for x in si.errors.roller_diameter:
        if x.planet == planet:
            D[x.roller] += x.deviation
    return D


def spall_args(si, planet: str, raceway: str, angle_of_planet: float) -> dict:
    """Spall parameters of the Z contacts of ``planet``'s ``raceway`` ({} when the machine has no spall at
    all; depth 0 on a healthy raceway of a machine that has one). On the pin the position counts from the
    carrier's radial line through the planet (``angle_of_planet`` ψ), on the bore in the planet's axes."""
    if not si.errors.spall:
        return {}
    Z = si.bearing.rollers
    hit = [x for x in si.errors.spall if x.planet == planet and x.raceway == raceway]
    if not hit:       # a healthy raceway in a family that has a spall: depth 0 (any valid width and edge)
        w = 1e-3 * si.bearing.roller_diameter
        return dict(spall_angle=np.zeros(Z), spall_width=np.full(Z, w), spall_depth=np.zeros(Z), spall_edge=np.full(Z, w))
    x = hit[0]
    angle = x.position + (angle_of_planet if raceway == "inner" else 0.0)
    return dict(spall_angle=np.full(Z, angle), spall_width=np.full(Z, x.width), spall_depth=np.full(Z, x.depth),
                spall_edge=np.full(Z, x.edge))


def _offset(si, gear: str) -> np.ndarray:
    for x in si.errors.runout:
        if x.gear == gear:
            return x.eccentricity * np.array([np.cos(x.phase), np.sin(x.phase)])
    return np.zeros(2)


def mesh_error_args(si, gear1: list[str], gear2: list[str]) -> dict:
    """Runout offsets of one mesh family's gears (``gear1``/``gear2`` the gear names per instance); {} for a
    machine without runout. (Tooth faults and deviations are the tooth-pair law's: :mod:`components.teeth`.)"""
    if not si.errors.runout:
        return {}
    return {"offset1": np.array([_offset(si, g) for g in gear1]), "offset2": np.array([_offset(si, g) for g in gear2])}
