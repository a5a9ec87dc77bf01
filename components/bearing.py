"""Planet bearing: Z rollers and a cage between a pin (inner raceway, on a body) and a bore (outer
raceway, the planet), or — when the scene asks for it — a linear radial spring.

All rollers of all bearings share one family per contact kind (race_inner, race_outer, pocket,
guide, drag), so adding a bearing adds instances, never element objects.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mbd.elements import BodySpring
from mbd.elements.contact import (TRACTION_LAWS, ExactRestitution, GuideContact, LubricantDrag, PocketContact,
                                  RaceContact, SlideRollTraction, TanhTraction, Traction)

from .families import FAMILY
from .scene import Scene

__all__ = ["BearingSI", "add_planet_bearing", "bearing_kinematics", "bearing_si"]


@dataclass(frozen=True)
class BearingSI:
    """Planet-bearing data in SI floats (built once from the pint parameter objects)."""
    d_m: float
    D: float
    l: float
    Z: int
    rows: int                   # identical rows, moving as one (every per-roller force is per physical roller)
    clearance: float            # diametral P_d
    roller_mass: float          # one physical roller
    roller_inertia: float
    K: float                    # roller–raceway line contact stiffness [N/m^(10/9)]
    exponent: float             # load-deflection exponent (10/9)
    zeta: float                 # roller–raceway contact damping ratio
    traction: Traction          # roller–raceway traction law
    cage_mass: float
    cage_inertia: float
    C_p: float                  # circumferential pocket clearance per side
    C_g: float                  # radial guiding clearance
    K_p: float
    K_g: float
    restitution: float
    mu_pocket: float
    mu_guide: float
    C_d: float
    rho: float
    v_min: float                # smallest approach speed of the impact damping
    v_mu: float                 # friction regularisation speed at pocket walls and land
    linear_stiffness: float     # radial stiffness when bearings are linear springs [N/m]
    linear_damping: float       # [N·s/m]

    @property
    def R_i(self) -> float:
        return 0.5 * (self.d_m - self.D)

    @property
    def R_o(self) -> float:
        return 0.5 * (self.d_m + self.D + self.clearance)


# each traction law from the bearing's SI parameters (a parameter, bearing.traction_law, names one)
_TRACTION_FROM = {
    "tanh": lambda bs: TanhTraction(mu_max=bs.traction_mu_max, v0=bs.traction_v0),
    "slide_roll": lambda bs: SlideRollTraction(
        A=bs.slide_roll_traction.A, B=bs.slide_roll_traction.B, C=bs.slide_roll_traction.C,
        D=bs.slide_roll_traction.D, u_reg=bs.slide_roll_traction.rolling_speed_reg,
        s_eps=bs.slide_roll_traction.ratio_reg),
}
assert set(_TRACTION_FROM) == set(TRACTION_LAWS)


def bearing_si(bs, lub) -> BearingSI:
    """BearingSI from the SI views of BearingParams (``params.si().bearing``) and LubricantParams."""
    c = bs.cage
    return BearingSI(d_m=bs.pitch_diameter, D=bs.roller_diameter, l=bs.roller_length, Z=int(bs.rollers),
                     rows=int(bs.rows), clearance=bs.clearance, roller_mass=bs.roller_mass, roller_inertia=bs.roller_inertia,
                     K=bs.contact_stiffness, exponent=bs.contact_exponent, zeta=bs.contact_damping_ratio,
                     traction=_TRACTION_FROM[bs.traction_law](bs), cage_mass=c.mass, cage_inertia=c.inertia, C_p=c.pocket_clearance,
                     C_g=c.guide_clearance, K_p=c.pocket_stiffness, K_g=c.guide_stiffness,
                     restitution=c.restitution, mu_pocket=c.pocket_friction, mu_guide=c.guide_friction,
                     C_d=lub.drag_coefficient, rho=lub.density, v_min=c.impact_speed_floor, v_mu=c.friction_speed,
                     linear_stiffness=bs.linear_stiffness, linear_damping=bs.linear_damping)


def bearing_kinematics(b: BearingSI, omega_inner: float, omega_outer: float) -> tuple[float, float]:
    """(cage orbital speed, roller spin) in pure rolling, from the inner- and outer-raceway speeds.
    ω_m = (ω_i R_i + ω_o R_o')/(R_i + R_o') with R_o' = (d_m + D)/2; roller spin from rolling on the
    inner race: ω_R = ω_m − 2 (ω_i − ω_m) R_i / D."""
    Ri, Ro = 0.5 * (b.d_m - b.D), 0.5 * (b.d_m + b.D)
    wm = (omega_inner * Ri + omega_outer * Ro) / (Ri + Ro)
    return wm, wm - 2.0 * (omega_inner - wm) * Ri / b.D


def add_planet_bearing(scene: Scene, tag: str, *, pin_body: str, pin_local, outer_body: str, b: BearingSI,
                       pin_xy, pin_vel, omega_pin: float, omega_outer: float, cage_held: bool = False) -> dict:
    """Add one bearing. ``pin_local`` is the raceway centre in pin_body axes; ``pin_xy``/``pin_vel`` its
    position/velocity in the fixed frame at t = 0 (the kinematic steady state); ``omega_pin`` and
    ``omega_outer`` the absolute spin speeds of the inner and outer raceway bodies. Returns handles."""
    opt = scene.options
    pin_local = np.asarray(pin_local, float)
    if opt.bearings == "linear":
        fam = scene.family(FAMILY["linear"], BodySpring, ("body_a", "body_b"))
        sl = fam.add(1, body_a=[pin_body], body_b=[outer_body], k=b.linear_stiffness, c=b.linear_damping,
                     marker_a=pin_local[None, :], marker_b=np.zeros((1, 2)))
        return {"kind": "linear", "spring": sl}

    Z = int(b.Z)
    wm, wr = bearing_kinematics(b, omega_pin, omega_outer)
    if cage_held and opt.cage:
        # a held cage stops the orbit, so the rollers slide on both races; start them at the spin where
        # the two tractions balance for equal loads (equal slips): ω_R = (ω_o R_o − ω_i R_i)/D
        wm = 0.0
        wr = (omega_outer * 0.5 * (b.d_m + b.D) - omega_pin * b.R_i) / b.D
    psi = 2 * np.pi * np.arange(Z) / Z
    rho = 0.5 * b.d_m + 0.25 * b.clearance          # centred in the radial gap
    pin_xy = np.asarray(pin_xy, float)
    pin_vel = np.asarray(pin_vel, float)
    rollers = []
    for j in range(Z):
        off = rho * np.array([np.cos(psi[j]), np.sin(psi[j])])
        vel = pin_vel + wm * np.array([-off[1], off[0]])
        rollers.append(scene.body(f"{tag}.roller{j}", b.rows * b.roller_mass, b.rows * b.roller_inertia,
                                  pose=(*(pin_xy + off), 0.0), vel=(*vel, wr)))
    names = [f"{tag}.roller{j}" for j in range(Z)]
    marker = np.tile(pin_local, (Z, 1))
    traction = b.traction
    common = dict(D=b.D, K=b.K, zeta=b.zeta, m_roller=b.roller_mass, multiplicity=b.rows)
    law = dict(traction=traction, exponent=b.exponent)     # family-wide laws
    inner = scene.family(FAMILY["race_inner"], RaceContact, ("roller", "race_body"), kind="inner", **law)
    s_in = inner.add(Z, roller=names, race_body=[pin_body] * Z, race_marker=marker, R_race=b.R_i, **common)
    outer = scene.family(FAMILY["race_outer"], RaceContact, ("roller", "race_body"), kind="outer", **law)
    s_out = outer.add(Z, roller=names, race_body=[outer_body] * Z, race_marker=np.zeros((Z, 2)), R_race=b.R_o,
                      **common)
    h = {"kind": "rollers", "rollers": names, "race_inner": s_in, "race_outer": s_out,
         "omega_cage": wm, "omega_roller": wr}
    if opt.drag:
        drag = scene.family(FAMILY["drag"], LubricantDrag, ("roller", "race_body"))
        h["drag"] = drag.add(Z, roller=names, race_body=[pin_body] * Z, race_marker=marker, C_d=b.C_d,
                             rho=b.rho, D=b.D, l=b.l, d_m=b.d_m, multiplicity=b.rows)
    if opt.cage:
        cage = f"{tag}.cage"
        scene.body(cage, b.cage_mass, b.cage_inertia, pose=(*pin_xy, 0.0), vel=(*pin_vel, wm), fixed=cage_held)
        pocket = scene.family(FAMILY["pocket"], PocketContact, ("roller", "cage"), impact_law=ExactRestitution())
        h["pocket"] = pocket.add(Z, roller=names, cage=[cage] * Z, pocket_angle=psi, pitch_radius=0.5 * b.d_m,
                                 clearance=b.C_p, K_p=b.K_p, restitution=b.restitution, v_min=b.v_min,
                                 mu=b.mu_pocket, v_mu=b.v_mu, D=b.D, multiplicity=b.rows)
        if not cage_held:
            guide = scene.family(FAMILY["guide"], GuideContact, ("cage", "planet"), impact_law=ExactRestitution())
            h["guide"] = guide.add(1, cage=[cage], planet=[outer_body], clearance=b.C_g, K_g=b.K_g,
                                   restitution=b.restitution, v_min=b.v_min, mu=b.mu_guide, v_mu=b.v_mu,
                                   land_radius=0.5 * (b.d_m + b.D))
        h["cage"] = cage
    return h
