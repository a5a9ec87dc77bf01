"""ISO 6336-1:2019 for spur gears: the tooth stiffness parameters c' and c_γα (clause 9, method B) and the dynamic
factor K_v of method B (clause 6.5) (docs/model.md §1.5 and §13.8).

Every function works on SI floats: a stiffness per face width in N/m² (1 N/(mm·µm) = 1e9 N/m²), a line load in N/m
(100 N/mm = 1e5 N/m), lengths in m, masses per face width in kg/m.

Mesh stiffness (clause 9.3, method B):

    q'    = C1 + C2/z_n1 + C3/z_n2 + C4 x_1 + C5 x_1/z_n1 + C6 x_2 + C7 x_2/z_n2 + C8 x_1² + C9 x_2²   [mm·µm/N]
    c'_th = 1/q'                                         theoretical single stiffness (an internal gear: z_n2 = ∞)
    c'    = c'_th C_M C_R C_B cos β (w/100 N/mm)^0.25    single stiffness (the last factor only for w < 100 N/mm)
    c_γα  = c' (0.75 ε_α + 0.25)                         mean mesh stiffness

with w = F_t K_A / b the line load, C_M = 0.8 (measured against theoretical stiffness of solid gears), C_R = 1 for
solid blanks (a web of the full face width), C_B = ½(C_B1 + C_B2), C_Bi = [1 + 0.5 (1.2 − h_fPi/m)][1 − 0.02 (20° −
α_P)] the basic rack factor. Written as c' [1 + 0.75 (ε_α − 1)], c_γα is the mean of a rectangular wave of c' over
single contact and 1.75 c' over double contact (the fraction ε_α − 1 of a cycle): :data:`SINGLE_DOUBLE_RATIO`.

Dynamic factor, method B (clause 6.5): the resonance ratio N = n_1/n_E1 = f_m/f_E, f_E = √(c_γα/m_red)/2π the
mesh's natural frequency on its line of action (m_red per face width, :func:`planetary_reduced_mass`), and with
B_p = c' f_pb,eff/w, B_f = c' f_fα,eff/w, B_k = |1 − c' C_a/w| and the constants C_v1..C_v7 of the standard:

    N ≤ N_S (subcritical):             K_v = N (C_v1 B_p + C_v2 B_f + C_v3 B_k) + 1
    N_S < N ≤ 1.15 (main resonance):   K_v = C_v1 B_p + C_v2 B_f + C_v4 B_k + 1
    1.15 < N < 1.5 (intermediate):     K_v = K_v(1.5) + (K_v(1.15) − K_v(1.5)) (1.5 − N)/0.35
    N ≥ 1.5 (supercritical):           K_v = C_v5 B_p + C_v6 B_f + C_v7

N_S = 0.5 + 0.35 √(w/100 N/mm) below 100 N/mm, else 0.85.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .tolerances import flank_tolerances

__all__ = ["Q_PRIME_COEFFICIENTS", "MEASURED_FACTOR", "SOLID_BLANK_FACTOR", "REFERENCE_LINE_LOAD", "SINGLE_DOUBLE_RATIO",
           "CASE_HARDENED_RUNNING_IN", "RUNNING_IN_LIMIT",
           "theoretical_single_stiffness", "basic_rack_factor", "load_correction", "single_stiffness",
           "mesh_stiffness_per_width", "MeshStiffness", "mesh_stiffness", "pair_reduced_mass", "planetary_reduced_mass",
           "resonance_ratio", "running_in", "DynamicFactor", "dynamic_factor_method_b", "machine_dynamic_factors"]

# Table of the coefficients of q' (ISO 6336-1:2019 clause 9.3.2, method B), mm·µm/N
Q_PRIME_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
MEASURED_FACTOR = 0.8            # C_M: measured over theoretical single stiffness of solid disc gears
SOLID_BLANK_FACTOR = 1.0         # C_R of a solid blank (web as wide as the face)
REFERENCE_LINE_LOAD = 1e5        # 100 N/mm [N/m]: below it the single stiffness is corrected for the load
SINGLE_DOUBLE_RATIO = 1.75       # k_double/k_single of the wave whose mean is c'(0.75 ε_α + 0.25)
CASE_HARDENED_RUNNING_IN = 0.075  # y_α/f_pb (and y_f/f_fα) of case-hardened or nitrided steel
RUNNING_IN_LIMIT = 3e-6          # y_α ≤ 3 µm for case-hardened or nitrided steel [m]
_UNIT = 1e9                      # 1 N/(mm·µm) in N/m²


def theoretical_single_stiffness(zn1: float, zn2: float, x1: float, x2: float) -> float:
    """c'_th = 1/q' [N/m²] of gears with (virtual) teeth counts ``zn1``, ``zn2`` and profile shifts ``x1``, ``x2``
    (ISO 6336-1:2019 clause 9.3.2); an internal gear (the ring) enters with ``zn2 = math.inf``."""
    if not (zn1 > 0 and zn2 > 0):
        raise ValueError(f"theoretical_single_stiffness: teeth counts must be > 0, got {zn1!r}, {zn2!r}")
    C1, C2, C3, C4, C5, C6, C7, C8, C9 = Q_PRIME_COEFFICIENTS
    q = (C1 + C2 / zn1 + C3 / zn2 + C4 * x1 + C5 * x1 / zn1 + C6 * x2 + C7 * x2 / zn2 + C8 * x1 * x1
         + C9 * x2 * x2)
    return _UNIT / q


def basic_rack_factor(dedendum1: float, dedendum2: float, pressure_angle: float) -> float:
    """C_B = ½(C_B1 + C_B2), C_Bi = [1 + 0.5 (1.2 − h_fPi/m)][1 − 0.02 (20° − α_P)] (ISO 6336-1:2019 clause 9.3.5):
    ``dedendum`` h_fP/m of each gear's basic rack, ``pressure_angle`` α_P [rad]."""
    tilt = 1.0 - 0.02 * (20.0 - math.degrees(pressure_angle))
    return 0.5 * sum((1.0 + 0.5 * (1.2 - h)) * tilt for h in (dedendum1, dedendum2))


def load_correction(line_load: float) -> float:
    """(w/100 N/mm)^0.25 for a line load 0 < w < 100 N/mm, else 1 [-] (ISO 6336-1:2019 clause 9.3.1). With no
    transmitted load (w ≤ 0) the standard's correction has no value; the factor is then 1 (the stiffness at
    100 N/mm), so that a train turning without load keeps a stiffness."""
    if 0.0 < line_load < REFERENCE_LINE_LOAD:
        return (line_load / REFERENCE_LINE_LOAD) ** 0.25
    return 1.0


def single_stiffness(c_th: float, blank_factor: float, rack_factor: float, line_load: float,
                     helix_angle: float) -> float:
    """c' = c'_th C_M C_R C_B cos β × :func:`load_correction` [N/m²] (ISO 6336-1:2019 clause 9.3.1)."""
    return c_th * MEASURED_FACTOR * blank_factor * rack_factor * math.cos(helix_angle) * load_correction(line_load)


def mesh_stiffness_per_width(c_single: float, eps_alpha: float) -> float:
    """c_γα = c'(0.75 ε_α + 0.25) [N/m²] (ISO 6336-1:2019 clause 9.4)."""
    return c_single * (0.75 * eps_alpha + 0.25)


@dataclass(frozen=True)
class MeshStiffness:
    """The stiffness parameters of one mesh [N/m²]: theoretical single c'_th, single c', mean c_γα; the factors C_B
    and of the load, and the line load w [N/m] they were taken at."""
    theoretical: float
    single: float
    mean: float
    rack_factor: float
    load_factor: float
    line_load: float


def mesh_stiffness(z1: int, z2: int, internal: bool, dedendum1: float, dedendum2: float, pressure_angle: float,
                   eps_alpha: float, line_load: float) -> MeshStiffness:
    """c'_th, c' and c_γα of a spur mesh of standard gears (no profile shift, solid blanks: C_R = 1) with teeth
    ``z1`` (the external gear) and ``z2`` (``internal``: the ring, z_n2 = ∞), at line load ``line_load`` [N/m]."""
    c_th = theoretical_single_stiffness(z1, math.inf if internal else z2, 0.0, 0.0)
    cb = basic_rack_factor(dedendum1, dedendum2, pressure_angle)
    c1 = single_stiffness(c_th, SOLID_BLANK_FACTOR, cb, line_load, 0.0)
    return MeshStiffness(theoretical=c_th, single=c1, mean=mesh_stiffness_per_width(c1, eps_alpha), rack_factor=cb,
                         load_factor=load_correction(line_load), line_load=line_load)


# ---------------------------------------------------------------------------------------------
# dynamic factor, method B
# ---------------------------------------------------------------------------------------------
def pair_reduced_mass(J1: float, J2: float, rb1: float, rb2: float, face_width: float) -> float:
    """m_red = J1* J2*/(J1* r_b2² + J2* r_b1²) [kg/m] of two gears with polar moments of inertia J [kg m²] per face
    width (ISO 6336-1:2019 clause 6.5.9: the reduced mass of a gear pair on its line of action)."""
    return J1 * J2 / (J1 * rb2 ** 2 + J2 * rb1 ** 2) / face_width


def planetary_reduced_mass(mesh: str, planets: int, J_sun: float, J_planet: float, rb_sun: float,
                           rb_planet: float, face_width: float, J_planet2: float | None = None,
                           rb_planet2: float | None = None) -> float:
    """m_red [kg/m] per face width of a mesh of a planetary train (ISO 6336-1:2019 clause 6.5.9), with m* = J/(r_b² b)
    each gear's mass on its line of action:

    * ``"sun_planet"``: m_red = m*_P m*_S/(m*_S + N m*_P) — the sun is shared by the N planets;
    * ``"planet_ring"``: m_red = m*_P — the ring (held, heavy) counts as infinitely heavy;
    * ``"planet_planet"`` (a double planetary; not in the standard): the pair's m*_a m*_b/(m*_a + m*_b), the
      two planets' own masses (``J_planet2``, ``rb_planet2``: the second planet)."""
    m_p = J_planet / (rb_planet ** 2 * face_width)
    if mesh == "sun_planet":
        m_s = J_sun / (rb_sun ** 2 * face_width)
        return m_p * m_s / (m_s + planets * m_p)
    if mesh == "planet_ring":
        return m_p
    if mesh == "planet_planet":
        m_b = J_planet2 / (rb_planet2 ** 2 * face_width)
        return m_p * m_b / (m_p + m_b)
    raise ValueError(f"planetary_reduced_mass: mesh must be sun_planet, planet_ring or planet_planet, got {mesh!r}")


def resonance_ratio(mesh_frequency: float, c_gamma_alpha: float, reduced_mass: float) -> float:
    """N = n_1/n_E1 = f_m/f_E [-], f_E = √(c_γα/m_red)/2π (ISO 6336-1:2019 clause 6.5.3: n_E1 = 30 000/(π z_1)
    √(c_γα/m_red) r/min with c_γα in N/(mm·µm) and m_red in kg/mm; z_1 n_1/60 is the mesh frequency)."""
    return mesh_frequency / (math.sqrt(c_gamma_alpha / reduced_mass) / (2.0 * math.pi))


def running_in(deviation: float) -> float:
    """Running-in allowance y [m] of case-hardened or nitrided steel: 0.075 × the deviation, at most 3 µm
    (ISO 6336-1:2019 clause 8.3.5, y_α; used for f_pb and f_fα alike)."""
    return min(CASE_HARDENED_RUNNING_IN * deviation, RUNNING_IN_LIMIT)


def _constants(eps_gamma: float) -> tuple:
    """C_v1..C_v7 of ISO 6336-1:2019 clause 6.5.9 (its table of the constants), for the total contact ratio ε_γ."""
    if eps_gamma <= 2.0:
        cv2, cv3, cv4, cv6 = 0.34, 0.23, 0.90, 0.47
    else:
        cv2, cv3 = 0.57 / (eps_gamma - 0.3), 0.096 / (eps_gamma - 1.56)
        cv4, cv6 = (0.57 - 0.05 * eps_gamma) / (eps_gamma - 1.44), 0.12 / (eps_gamma - 1.74)
    if eps_gamma <= 1.5:
        cv7 = 0.75
    elif eps_gamma <= 2.5:
        cv7 = 0.125 * math.sin(math.pi * (eps_gamma - 2.0)) + 0.875
    else:
        cv7 = 1.0
    return 0.32, cv2, cv3, cv4, 0.47, cv6, cv7


@dataclass(frozen=True)
class DynamicFactor:
    """K_v of method B with what it is made of: the resonance ratio N, its range ("subcritical", "main resonance",
    "intermediate", "supercritical"), N_S and B_p, B_f, B_k."""
    K_v: float
    N: float
    range: str
    N_S: float
    B_p: float
    B_f: float
    B_k: float


def dynamic_factor_method_b(N: float, line_load: float, c_single: float, f_pb_eff: float, f_falpha_eff: float,
                            tip_relief: float, eps_gamma: float) -> DynamicFactor:
    """K_v of ISO 6336-1:2019 clause 6.5 (method B; the module docstring): resonance ratio ``N``, line load
    w = F_t K_A/b [N/m] (> 0), single stiffness c' [N/m²], the effective base pitch and profile form deviations
    after running-in [m], the tip relief C_a [m] and the total contact ratio ε_γ (> 1)."""
    if not (line_load > 0 and eps_gamma > 1.0 and N >= 0):
        raise ValueError(f"dynamic_factor_method_b: needs line_load > 0, eps_gamma > 1 and N >= 0, got "
                         f"{line_load!r}, {eps_gamma!r}, {N!r}")
    cv1, cv2, cv3, cv4, cv5, cv6, cv7 = _constants(eps_gamma)
    B_p = c_single * f_pb_eff / line_load
    B_f = c_single * f_falpha_eff / line_load
    B_k = abs(1.0 - c_single * tip_relief / line_load)
    N_S = 0.5 + 0.35 * math.sqrt(line_load / REFERENCE_LINE_LOAD) if line_load < REFERENCE_LINE_LOAD else 0.85
    main = cv1 * B_p + cv2 * B_f + cv4 * B_k + 1.0
    above = cv5 * B_p + cv6 * B_f + cv7
    if N <= N_S:
        kv, where = N * (cv1 * B_p + cv2 * B_f + cv3 * B_k) + 1.0, "subcritical"
    elif N <= 1.15:
        kv, where = main, "main resonance"
    elif N < 1.5:
        kv, where = above + (main - above) * (1.5 - N) / 0.35, "intermediate"
    else:
        kv, where = above, "supercritical"
    return DynamicFactor(K_v=kv, N=N, range=where, N_S=N_S, B_p=B_p, B_f=B_f, B_k=B_k)


# the standard's rule for each mesh type of the double planetary train (planetary_reduced_mass)
_MESH_KIND = {"sun_inner": "sun_planet", "inner_outer": "planet_planet", "outer_ring": "planet_ring"}


def machine_dynamic_factors(si, grade: int | None) -> dict[str, DynamicFactor | None]:
    """Method B's K_v of each mesh type of a DPGT (``si``: ``DPGTParams.si()``) with every gear of ISO 1328-1:2013
    flank tolerance class ``grade`` (None: perfect teeth, f_pb = f_fα = 0), None where the train transmits no load.

    Per mesh: c' and c_γα the model's (k_single and k_mean per face width: ISO's unless overridden), w the nominal
    line load (K_A = 1), N from the mesh frequency relative to the carrier z_r f_c and the reduced mass of
    :func:`planetary_reduced_mass` with the gears' inertias, f_pb = f_pT cos α and f_fα = f_fαT the larger of the
    two gears' tolerances, less the case-hardened running-in allowance (:func:`running_in`), C_a the larger tip
    relief of the two gears, ε_γ = ε_α (spur)."""
    lay, gs = si.layout, si.gears
    out = {}
    for key, m in lay.meshes.items():
        if m.line_load <= 0.0:
            out[key] = None
            continue
        g1, g2 = gs[m.gear1], gs[m.gear2]
        b = m.face_width
        planet = g2 if key == "sun_inner" else g1         # the planet of the mesh (inner–outer: the inner one)
        m_red = planetary_reduced_mass(_MESH_KIND[key], gs.planets, gs.sun.inertia, planet.inertia,
                                       gs.sun.base_radius, planet.base_radius, b, g2.inertia, g2.base_radius)
        N = resonance_ratio(si.operating.mesh_frequency, m.k_mean / b, m_red)
        f_pb = f_fa = 0.0
        if grade is not None:
            tol = [flank_tolerances(g.module, 2.0 * g.pitch_radius, grade) for g in (g1, g2)]
            f_pb = max(t.single_pitch for t in tol) * math.cos(g1.pressure_angle)
            f_fa = max(t.profile_form for t in tol)
        out[key] = dynamic_factor_method_b(N, m.line_load, m.k_single / b, f_pb - running_in(f_pb),
                                           f_fa - running_in(f_fa), max(g1.tip_relief, g2.tip_relief),
                                           m.contact_ratio)
    return out
