"""Involute spur geometry, planet layout, kinematics, mesh phasing and design checks (docs/model.md §1).

Everything here works on SI floats (metres, radians, rad/s). Two entry points take a whole
:class:`components.params.DPGTParams`: :func:`layout` (the nominal machine: centre distances, planet
positions, meshes with contact ratios, stiffness levels, damping and phases) and
:func:`design_findings` / :func:`check_design` (feasibility checks). ``DPGTParams.si()`` already
includes the layout, so a scene builder normally needs nothing else.

Conventions
-----------
* Planet pairs n = 0..N−1: inner planet a_n at angle ψ_an = ψ_0 + 2πn/N and radius r_ca, outer
  planet b_n at ψ_bn = ψ_an + h·Δψ and radius r_cb (angles in the reference frame R, sun axis at the
  origin, positive counter-clockwise).
* Meshes, gear 1 → gear 2: ``sun_inner`` sun → a_n (external), ``inner_outer`` a_n → b_n
  (external), ``outer_ring`` b_n → ring (internal, gear 1 is the planet). Line of centres φ_e: angle of
  the unit vector e from centre 1 to centre 2 (external) or from the ring centre to the planet centre
  (internal) — as in docs/model.md §6.1. In both cases the pitch point lies at angle φ_e seen from gear 1.
* Gear angles θ are 0 at assembly. Tooth k of gear g then has its centre line at angle
  θ_g + γ_g + 2πk/z_g; γ_sun = 0 (sun tooth 0 on the +x axis); the others follow from meshing
  (:func:`mesh_phases`).

Mesh position and phase
-----------------------
The mesh position of a mesh is ``p = z_1·(θ_1 − φ_e)/2π + p0 (mod 1)`` (docs/model.md §1.4): gear 1's
rotation relative to the line of centres counted in tooth pitches. With ``p0 = frac(z_1·γ_1/2π)``,
p ≡ 0 exactly when a tooth of gear 1 has its centre line on the line of centres, at the pitch point
(the mating gear then has a tooth space centred there: a tooth pair straddles the pitch point
symmetrically). The planet's position enters through φ_e, evaluated from the states: at assembly
(θ = 0, φ_e = nominal) the mesh position is ``p_assembly = frac(z_1·(γ_1 − φ_e)/2π)``. For the
sun–inner meshes p0 = 0 (γ_sun = 0) and p_assembly = frac(−z_s·ψ_an/2π), the familiar sequential
phasing; with ψ_0 = 0, pair 1 (a1) starts with the sun's tooth 0 on its pitch point (p = 0).

Flank f (docs/model.md §6.1) of a standard tooth (thickness half the circular pitch, no backlash) has its
contact on the pitch point when ``p ≡ −σf/4`` (σ = +1 external, −1 internal). Measured along that
flank's line of action from the pitch point, positive towards the end where gear 1's tip circle cuts
it, the contact points of the tooth pairs sit at ``s = (σ·f·p + 1/4 + k)·p_b`` for integers k, and a
pair carries load while ``−g_2 ≤ s ≤ g_1`` (``g_1``, ``g_2``: the parts of the path of contact in gear
1's and gear 2's addendum). :meth:`MeshGeometry.pairs_in_contact` evaluates this; its mean over p is
the contact ratio ε_α. The rectangular stiffness wave of docs/model.md §6.3 is this count, smoothed; its
phase depends on the loaded flank: :meth:`MeshGeometry.wave_p0` gives the phase for a wave whose
double contact starts at p' = 0, :func:`loaded_flanks` which flank the torque path loads.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import iso6336 as iso
from .units import ParameterError



__all__ = [
    "STANDARD_ADDENDUM", "STANDARD_DEDENDUM", "GearGeometry", "MeshGeometry", "Phasing", "Layout",
    "Kinematics", "Finding", "DesignWarning",
    "centre_distances", "pair_angle", "planet_angles", "speed_ratio", "planet_speed_ratios", "iso_minimum_backlash",
    "mesh_frequency", "SIDEBAND_ORIGINS", "sideband_origin", "contact_path", "contact_ratio", "assembly_number", "mesh_phases",
    "mesh_stiffness_levels", "nominal_tangential_force", "mesh_damping", "mesh_equivalent_mass", "palmgren_stiffness", "kinematics", "layout", "loaded_flanks",
    "design_findings", "check_design", "centre_distance_limit",
]

TWO_PI = 2.0 * math.pi
STANDARD_ADDENDUM = 1.0    # h_a / m
STANDARD_DEDENDUM = 1.25   # h_f / m
PALMGREN_COEFFICIENT = 8.06e4  # N/mm^(10/9) per mm^(8/9): inverse of δ = 3.84e-5 Q^0.9 / l^0.8 (mm, N)
RIM_BACKUP_RATIO = 1.2     # AGMA-style minimum (rim thickness under the root) / (tooth height)


# ---------------------------------------------------------------------------------------------
# single gears and meshes
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GearGeometry:
    """A standard (unshifted) involute spur gear; internal gears have their teeth pointing inwards."""

    teeth: int
    module: float
    pressure_angle: float
    internal: bool = False
    addendum_coefficient: float = STANDARD_ADDENDUM
    dedendum_coefficient: float = STANDARD_DEDENDUM

    @property
    def pitch_radius(self) -> float:
        return 0.5 * self.module * self.teeth

    @property
    def base_radius(self) -> float:
        return self.pitch_radius * math.cos(self.pressure_angle)

    @property
    def tip_radius(self) -> float:
        """Addendum circle: outside the pitch circle, or inside it for an internal gear."""
        s = -1.0 if self.internal else 1.0
        return self.pitch_radius + s * self.addendum_coefficient * self.module

    @property
    def root_radius(self) -> float:
        s = -1.0 if self.internal else 1.0
        return self.pitch_radius - s * self.dedendum_coefficient * self.module

    @property
    def base_pitch(self) -> float:
        return math.pi * self.module * math.cos(self.pressure_angle)


def contact_path(g1: GearGeometry, g2: GearGeometry, a: float, internal: bool) -> tuple[float, float, float]:
    """(g_1, g_2, α_w): the parts of the path of contact in gear 1's and gear 2's addendum, and the
    working pressure angle, for centre distance ``a``. Internal: gear 2 is the ring, whose tip circle
    is its inner one. Raises ParameterError when the gears cannot mesh at ``a``."""
    rb1, rb2 = g1.base_radius, g2.base_radius
    cos_w = (rb2 - rb1) / a if internal else (rb1 + rb2) / a
    if not (a > 0 and 0.0 < cos_w < 1.0):
        raise ParameterError.at("gears", f"no involute mesh at centre distance {a * 1e3:.3f} mm")
    tan_w = math.sqrt(1.0 - cos_w * cos_w) / cos_w
    g1_part = math.sqrt(g1.tip_radius ** 2 - rb1 ** 2) - rb1 * tan_w
    if internal:
        if g2.tip_radius < rb2:
            raise ParameterError.at("gears.ring", "tip circle lies inside the base circle (no involute there)")
        g2_part = rb2 * tan_w - math.sqrt(g2.tip_radius ** 2 - rb2 ** 2)
    else:
        g2_part = math.sqrt(g2.tip_radius ** 2 - rb2 ** 2) - rb2 * tan_w
    return g1_part, g2_part, math.acos(cos_w)


def contact_ratio(g1: GearGeometry, g2: GearGeometry, a: float, internal: bool = False) -> float:
    """Transverse contact ratio ε_α = (path of contact)/(base pitch) (standard formula)."""
    gp1, gp2, _ = contact_path(g1, g2, a, internal)
    return (gp1 + gp2) / g1.base_pitch


def mesh_stiffness_levels(k_mean: float, ratio: float, eps: float) -> tuple[float, float]:
    """(k_single, k_double) of a rectangular wave with mean ``k_mean``, k_double/k_single = ``ratio``
    and double-tooth contact over the fraction ε−1 of a cycle (clipped to [0, 1])."""
    frac = min(max(eps - 1.0, 0.0), 1.0)
    if frac == 1.0:                 # double contact throughout (ε ≥ 2): the mean is the double level
        return k_mean / ratio, k_mean
    k_single = k_mean / (1.0 + (ratio - 1.0) * frac)
    return k_single, ratio * k_single


def mesh_equivalent_mass(J1, J2, rb1, rb2):
    """m_eq = J1 J2 / (J1 r_b2² + J2 r_b1²) [kg]: the mass of the mesh's torsional mode on its line of action."""
    return J1 * J2 / (J1 * rb2 ** 2 + J2 * rb1 ** 2)


def mesh_damping(zeta, k_mean, J1, J2, rb1, rb2):
    """Mesh damping c_m = 2 ζ sqrt(k_mean m_eq) [N·s/m] (docs/model.md §1.5), m_eq from :func:`mesh_equivalent_mass`."""
    zeta, k_mean, J1, J2, rb1, rb2 = (np.asarray(x, float) for x in (zeta, k_mean, J1, J2, rb1, rb2))
    for name, x in (("zeta", zeta), ("k_mean", k_mean), ("J1", J1), ("J2", J2), ("rb1", rb1), ("rb2", rb2)):
        if not np.all(np.isfinite(x)) or np.any(x < 0 if name == "zeta" else x <= 0):
            raise ParameterError(f"mesh_damping: {name} must be finite and {'>= 0' if name == 'zeta' else '> 0'}, got {x!r}")
    return 2.0 * zeta * np.sqrt(k_mean * mesh_equivalent_mass(J1, J2, rb1, rb2))


def iso_minimum_backlash(centre_distance: float, module: float) -> float:
    """Minimum normal backlash of ISO/TR 10064-2 for steel gears in a steel housing [m]:
    j_bn,min = (2/3)(0.06 + 0.0005 a + 0.03 m_n) mm with a and m_n in mm (docs/model.md §1.5)."""
    a_mm, m_mm = 1e3 * centre_distance, 1e3 * module
    return (2.0 / 3.0) * (0.06 + 0.0005 * a_mm + 0.03 * m_mm) * 1e-3


def palmgren_stiffness(length: float) -> float:
    """Palmgren line-contact stiffness K [N/m^(10/9)] of one roller–raceway contact of length [m]:
    Q = K·δ^(10/9), K = 8.06e4·l[mm]^(8/9) N/mm^(10/9) = 8.06e10·l[m]^(8/9) N/m^(10/9)."""
    return PALMGREN_COEFFICIENT * 1e6 * length ** (8.0 / 9.0)


# ---------------------------------------------------------------------------------------------
# the double-planet layout
# ---------------------------------------------------------------------------------------------
def centre_distances(z_s: int, z_a: int, z_b: int, z_r: int, module: float) -> tuple[float, float, float]:
    """(r_ca, r_cb, L_ab) = m·(z_s+z_a)/2, m·(z_r−z_b)/2, m·(z_a+z_b)/2."""
    return 0.5 * module * (z_s + z_a), 0.5 * module * (z_r - z_b), 0.5 * module * (z_a + z_b)


def pair_angle(r_ca: float, r_cb: float, l_ab: float) -> float:
    """Δψ between the inner and outer planet of a pair seen from the sun axis (law of cosines)."""
    if min(r_ca, r_cb, l_ab) <= 0:
        raise ParameterError.at("gears", f"centre distances must be positive (r_ca={r_ca:.6g} m, "
                                         f"r_cb={r_cb:.6g} m, L_ab={l_ab:.6g} m): the ring needs more teeth")
    c = (r_ca ** 2 + r_cb ** 2 - l_ab ** 2) / (2.0 * r_ca * r_cb)
    if not -1.0 <= c <= 1.0:
        raise ParameterError.at("gears", f"no planet-pair triangle: r_ca={r_ca * 1e3:.4g} mm, "
                                         f"r_cb={r_cb * 1e3:.4g} mm, L_ab={l_ab * 1e3:.4g} mm violate the "
                                         f"triangle inequality (adjust the tooth counts)")
    return math.acos(c)


def planet_angles(n_planets: int, delta_psi: float, handedness: int, psi0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(ψ_a, ψ_b), each (N,): ψ_an = ψ_0 + 2πn/N, ψ_bn = ψ_an + h·Δψ, n = 0..N−1."""
    psi_a = psi0 + TWO_PI * np.arange(n_planets) / n_planets
    return psi_a, psi_a + handedness * delta_psi


def speed_ratio(z_s: int, z_r: int) -> float:
    """ω_s/ω_c with the ring fixed, double-planet set: 1 − z_r/z_s (negative)."""
    return 1.0 - z_r / z_s


def planet_speed_ratios(z_a: int, z_b: int, z_r: int) -> tuple[float, float]:
    """(ω_a/ω_c, ω_b/ω_c): absolute spin speeds of the inner and outer planet, ring fixed.

    Rolling at the pitch points, relative to the carrier: outer planet in the fixed ring (internal,
    same sense) z_b(ω_b − ω_c) = z_r(0 − ω_c); inner–outer (external, opposite sense)
    z_a(ω_a − ω_c) = −z_b(ω_b − ω_c) = z_r ω_c. Hence ω_a = ω_c(1 + z_r/z_a), ω_b = ω_c(1 − z_r/z_b);
    the sun–inner mesh then gives ω_s = ω_c(1 − z_r/z_s). Each planet bearing turns at ω_planet − ω_c
    = ±(z_r/z_planet)·ω_c relative to its pin.
    """
    return 1.0 + z_r / z_a, 1.0 - z_r / z_b


def mesh_frequency(z_r: int, f_c: float) -> float:
    """f_m = z_r·|f_c| (ring fixed; all three meshes share it)."""
    return z_r * abs(f_c)


SIDEBAND_ORIGINS = ("phasing", "transfer path", "errors")


def sideband_origin(k: int, z_r: int, n_planets: int, harmonic: int = 1) -> str:
    """What lets a sensor fixed to the housing see the line harmonic·f_m + k·f_c of a ring-fixed train
    with N equally spaced, identical planets (sequence-of-planet phasing: McFadden & Smith 1985,
    Parker & Lin 2004, Inalpolat & Kahraman 2009).

    Everything planet n contributes is a function of its angle ψ_n = ψ_c + 2πn/N alone: its ring-mesh
    phase z_r ψ_n/2π, the transfer path's weight w(ψ_n − ψ_s), the direction its force acts in. Written as
    Σ_m c_m e^{i m ψ_n} (carrier orders m; the line l·f_m + k·f_c is m = l z_r + k), the sum over the N
    planets keeps c_m·N e^{i m ψ_c} when N divides m and cancels it otherwise. Hence:

    * ``"phasing"``: N | (l z_r + k) and |k| = 1 — a sensor at the axis reads a fixed-frame component of
      forces that turn with the carrier, e^{±iψ_n} times mesh orders l z_r, so it carries k = ±1 only
      (z_r = 82, N = 3: f_m − f_c alone);
    * ``"transfer path"``: N | (l z_r + k), |k| ≠ 1 — allowed, but only a path whose weight depends on the
      planet's angle (a passing-planet window) carries carrier order k (82, 3: f_m + 2f_c, f_m − 4f_c, ...);
    * ``"errors"``: N ∤ (l z_r + k) — cancelled in a perfect machine; something that differs between
      planets (docs/model.md §11 errors, bearing states that differ) brings it (82, 3: f_m, f_m ± 3f_c, f_m + f_c).

    Gravity (fixed in I) turns in the carrier frame and adds orders ±1 to each planet's force, so a sensor at
    the axis may also carry a weak k = 0, ±2 where N | (l z_r + k) (82, 3: f_m + 2f_c). The rule needs the
    planets to assemble ((z_r − z_s)/N integer); otherwise the sun meshes break the symmetry."""
    if n_planets < 1:
        raise ValueError(f"n_planets must be >= 1, got {n_planets!r}")
    if (harmonic * z_r + k) % n_planets:
        return "errors"
    return "phasing" if abs(k) == 1 else "transfer path"


def assembly_number(z_s: int, z_r: int, n_planets: int) -> float:
    """(z_r − z_s)/N: equally spaced double-planet pairs assemble iff this is an integer."""
    return (z_r - z_s) / n_planets


def _frac(x):
    """x mod 1 in [0, 1), with round-off next to 1 folded to 0."""
    f = np.mod(x, 1.0)
    return np.where(f > 1.0 - 1e-9, 0.0, f)


def _wrap_half(x):
    """x mod 1 in [−1/2, 1/2), round-off to 0."""
    w = np.mod(np.asarray(x) + 0.5, 1.0) - 0.5
    return np.where(np.abs(w) < 1e-9, 0.0, w)


@dataclass(frozen=True, eq=False)
class Phasing:
    """Tooth positions at assembly (all gear angles 0) and the resulting mesh phases, per pair (N,).

    ``p0_*``: phases for p = z_1(θ_1 − φ_e)/2π + p0 (module docstring); ``p_assembly_*``: the mesh
    positions p at assembly. ``gamma_*``: angle of tooth 0's centre line of each gear at assembly (mod
    one tooth pitch). ``ring_mismatch``: how far, in ring
    tooth pitches in [−1/2, 1/2), the ring's teeth as pair n needs them are from where pair 0 puts
    them; all zero iff (z_r − z_s)/N is an integer. The ring is taken where pair 0 needs it
    (``gamma_ring``); each pair's meshes are phased from the planets' real positions, so a mismatch
    only means that rigid, perfect gears would not assemble.
    """

    p0_sun_inner: np.ndarray
    p0_inner_outer: np.ndarray
    p0_outer_ring: np.ndarray
    p_assembly_sun_inner: np.ndarray
    p_assembly_inner_outer: np.ndarray
    p_assembly_outer_ring: np.ndarray
    gamma_inner: np.ndarray
    gamma_outer: np.ndarray
    gamma_ring: float
    ring_mismatch: np.ndarray


def mesh_phases(z_s: int, z_a: int, z_b: int, z_r: int, psi_a, psi_b, phi_ab) -> Phasing:
    """Phase the three meshes of every pair from the sun's tooth 0 (γ_sun = 0), along sun → a → b → ring.

    Meshing of an external pair: when gear 1 has a tooth centred on the pitch point (p ≡ 0), gear 2
    has a space there, i.e. gear 2's own tooth phase at the pitch point, q = z_2(θ_2 + γ_2 − φ_e − π)/2π,
    is 1/2; rolling makes dq = −dp, so p + q ≡ 1/2. Internal (ring, same sense of rotation):
    r = z_r(θ_r + γ_r − φ_e)/2π ≡ p + 1/2.
    """
    psi_a, psi_b, phi_ab = (np.asarray(x, dtype=float) for x in (psi_a, psi_b, phi_ab))
    # mesh positions at assembly, p = frac(z_1(γ_1 − φ_e)/2π), chained from the sun's teeth
    p_sa = _frac(-z_s * psi_a / TWO_PI)
    gamma_a = psi_a + math.pi + (TWO_PI / z_a) * (0.5 - p_sa)
    p_ab = _frac(z_a * (gamma_a - phi_ab) / TWO_PI)
    gamma_b = phi_ab + math.pi + (TWO_PI / z_b) * (0.5 - p_ab)
    p_br = _frac(z_b * (gamma_b - psi_b) / TWO_PI)
    ring_phase = z_r * psi_b / TWO_PI + p_br + 0.5  # = z_r·γ_r/2π that pair n needs (mod 1)
    mismatch = _wrap_half(ring_phase - ring_phase[0])
    gamma_r = float(np.mod(ring_phase[0], 1.0)) * TWO_PI / z_r
    # p = z_1(θ_1 − φ_e)/2π + p0 equals the assembly value at θ = 0 ⇒ p0 = frac(z_1·γ_1/2π)
    return Phasing(p0_sun_inner=np.zeros_like(p_sa), p0_inner_outer=_frac(z_a * gamma_a / TWO_PI),
                   p0_outer_ring=_frac(z_b * gamma_b / TWO_PI),
                   p_assembly_sun_inner=p_sa, p_assembly_inner_outer=p_ab, p_assembly_outer_ring=p_br,
                   gamma_inner=np.mod(gamma_a, TWO_PI / z_a), gamma_outer=np.mod(gamma_b, TWO_PI / z_b),
                   gamma_ring=gamma_r, ring_mismatch=mismatch)


@dataclass(frozen=True, eq=False)
class MeshGeometry:
    """One mesh type (all N pairs): geometry, stiffness levels, damping and phases (SI).

    ``line_angle`` and ``p0`` are (N,) arrays, one entry per planet pair. ``k_mean`` is the mean mesh
    stiffness (given, or c_γα × common face width); k_single/k_double the levels of the rectangular
    wave; ``damping`` = 2ζ_m·sqrt(k_mean·m_eq). ``stiffness`` holds ISO 6336-1's c'_th, c' and c_γα of this mesh
    at ``line_load`` (:func:`components.iso6336.mesh_stiffness`), whether or not the parameters override c_γα.
    """

    name: str
    gear1: str
    gear2: str
    internal: bool
    z1: int
    z2: int
    base_radius1: float
    base_radius2: float
    centre_distance: float
    pressure_angle: float          # working pressure angle (= nominal for standard centre distances)
    base_pitch: float
    path1: float                   # g_1: path of contact in gear 1's addendum
    path2: float                   # g_2: path of contact in gear 2's addendum
    contact_ratio: float
    face_width: float              # common face width
    k_mean: float
    k_single: float
    k_double: float
    m_eq: float
    damping: float
    backlash: float                # normal backlash j_bn along the line of action
    line_load: float               # nominal F_t/b of the operating point [N/m] (K_A = 1)
    stiffness: iso.MeshStiffness   # ISO 6336-1 c'_th, c', c_γα at line_load
    line_angle: np.ndarray = field(repr=False)   # φ_e at assembly, per pair
    p0: np.ndarray = field(repr=False)           # phase in p = z_1(θ_1 − φ_e)/2π + p0, per pair
    p_assembly: np.ndarray = field(repr=False)   # p at assembly (θ = 0), per pair

    @property
    def sigma(self) -> int:
        return -1 if self.internal else 1

    def contact_position(self, p, flank: int):
        """Position s [m] of the principal tooth pair on flank ``flank``'s line of action, from the
        pitch point towards gear 1's tip end, for mesh position p; other pairs at s + k·p_b."""
        return (self.sigma * flank * np.asarray(p, dtype=float) + 0.25) * self.base_pitch

    def wave_p0(self, flank: int) -> np.ndarray:
        """(N,) phases for a stiffness wave whose double-contact zone starts where a new tooth pair
        enters, p' ∈ [0, ε−1) (the convention of ``mbd.elements.gear_mesh.StiffnessShape.rectangular``):
        p' = z_1(θ_1 − φ_e)/2π + wave_p0(f) reproduces :meth:`pairs_in_contact` on flank f. The two
        flanks differ (by about half a cycle): phase each mesh for its loaded flank (:func:`loaded_flanks`)."""
        return _frac(self.p0 + self.entry_shift(flank))

    def entry_shift(self, flank: int) -> float:
        """Cycles from a new tooth pair's entry on ``flank`` to the moment its gear-1 tooth is centred on
        the pitch point: the pair whose gear-1 tooth is centred at p = p_i enters at p_i − entry_shift."""
        if self.sigma * flank > 0:   # contact runs from gear 2's tip end (s = −g_2) as p grows
            return 0.25 + self.path2 / self.base_pitch
        return self.path1 / self.base_pitch - 0.25   # contact runs from gear 1's tip end (s = g_1) as p grows

    def pairs_in_contact(self, p, flank: int):
        """Number of tooth pairs in contact on ``flank`` at mesh position p (rigid teeth, no load)."""
        x = self.contact_position(p, flank) / self.base_pitch
        hi = np.floor(self.path1 / self.base_pitch - x + 1e-12)
        lo = np.ceil(-self.path2 / self.base_pitch - x - 1e-12)
        return (hi - lo + 1).astype(int)


@dataclass(frozen=True, eq=False)
class Layout:
    """The nominal machine in SI: what a scene builder places (see the module docstring)."""

    gears: dict                    # name -> GearGeometry: sun, inner_planet, outer_planet, ring
    planets: int
    handedness: int
    r_ca: float
    r_cb: float
    l_ab: float
    delta_psi: float
    psi_a: np.ndarray              # (N,)
    psi_b: np.ndarray              # (N,)
    centres_a: np.ndarray          # (N, 2)
    centres_b: np.ndarray          # (N, 2)
    phi_ab: np.ndarray             # (N,) angle of c_b − c_a
    meshes: dict                   # "sun_inner", "inner_outer", "outer_ring" -> MeshGeometry
    phasing: Phasing
    sun_ratio: float               # ω_s/ω_c
    inner_ratio: float             # ω_a/ω_c
    outer_ratio: float             # ω_b/ω_c
    assembly_number: float         # (z_r − z_s)/N

    @property
    def assembles(self) -> bool:
        return abs(self.assembly_number - round(self.assembly_number)) < 1e-9


def _gear_geometries(gs) -> dict:
    return {name: GearGeometry(teeth=g.teeth, module=g.module, pressure_angle=g.pressure_angle,
                               internal=g.internal, addendum_coefficient=g.addendum_coefficient,
                               dedendum_coefficient=g.dedendum_coefficient)
            for name, g in ((n, gs[n]) for n in ("sun", "inner_planet", "outer_planet", "ring"))}


def nominal_tangential_force(operating_si, sun: GearGeometry, ring: GearGeometry, planets: int) -> float:
    """F_t = |T_s|/(N r_s) [N]: the nominal tangential force at the reference circle of every mesh of the train (one
    module: the same F_t on the sun's, the planets' and the ring's meshes), T_s = P/|ω_s| of the operating point
    (``operating_si``: its carrier_speed [rad/s] and output_power [W]); 0 without power or without sun speed."""
    w_s = abs(speed_ratio(sun.teeth, ring.teeth) * operating_si.carrier_speed)
    if not (operating_si.output_power > 0 and w_s > 0):
        return 0.0
    return operating_si.output_power / w_s / (planets * sun.pitch_radius)


def layout(params, gears_si=None, mesh_si=None) -> Layout:
    """The nominal layout of ``params`` (a DPGTParams; or pass the SI views of its gears and mesh).

    Raises ParameterError (naming the parameter) when the gears cannot be laid out at all.
    """
    gs = gears_si if gears_si is not None else params.gears.si()
    ms = mesh_si if mesh_si is not None else params.mesh.si()
    G = _gear_geometries(gs)
    sun, ga, gb, ring = G["sun"], G["inner_planet"], G["outer_planet"], G["ring"]
    r_ca, r_cb, l_ab = centre_distances(sun.teeth, ga.teeth, gb.teeth, ring.teeth, sun.module)
    dpsi = pair_angle(r_ca, r_cb, l_ab)
    n, h = gs.planets, gs.handedness
    psi_a, psi_b = planet_angles(n, dpsi, h, gs.planet_angle)
    ca = r_ca * np.column_stack([np.cos(psi_a), np.sin(psi_a)])
    cb = r_cb * np.column_stack([np.cos(psi_b), np.sin(psi_b)])
    phi_ab = np.arctan2(cb[:, 1] - ca[:, 1], cb[:, 0] - ca[:, 0])
    ph = mesh_phases(sun.teeth, ga.teeth, gb.teeth, ring.teeth, psi_a, psi_b, phi_ab)

    f_t = nominal_tangential_force(params.operating.si(), sun, ring, n) if params is not None else 0.0

    def mesh(name, n1, n2, a, internal, line, p0, p_asm):
        g1, g2 = G[n1], G[n2]
        gp1, gp2, alpha_w = contact_path(g1, g2, a, internal)
        eps = (gp1 + gp2) / g1.base_pitch
        b = min(gs[n1].face_width, gs[n2].face_width)
        iso_k = iso.mesh_stiffness(g1.teeth, g2.teeth, internal, g1.dedendum_coefficient, g2.dedendum_coefficient,
                                   g1.pressure_angle, eps, f_t / b)
        c_ga = ms.c_gamma_alpha if ms.c_gamma_alpha is not None else iso_k.mean
        k_mean = ms.mean_stiffness if ms.mean_stiffness is not None else c_ga * b
        k1, k2 = mesh_stiffness_levels(k_mean, ms.stiffness_ratio, eps)
        args = (gs[n1].inertia, gs[n2].inertia, g1.base_radius, g2.base_radius)
        c, m_eq = float(mesh_damping(ms.damping_ratio, k_mean, *args)), float(mesh_equivalent_mass(*args))
        b_n = ms[f"backlash_{name}"]
        b_n = iso_minimum_backlash(a, g1.module) if b_n is None else b_n
        return MeshGeometry(name=name, gear1=n1, gear2=n2, internal=internal, z1=g1.teeth, z2=g2.teeth,
                            base_radius1=g1.base_radius, base_radius2=g2.base_radius, centre_distance=a,
                            pressure_angle=alpha_w, base_pitch=g1.base_pitch, path1=gp1, path2=gp2,
                            contact_ratio=eps, face_width=b, k_mean=k_mean, k_single=k1, k_double=k2,
                            m_eq=m_eq, damping=c, backlash=b_n, line_load=f_t / b, stiffness=iso_k, line_angle=np.asarray(line, dtype=float), p0=p0,
                            p_assembly=p_asm)

    meshes = {
        "sun_inner": mesh("sun_inner", "sun", "inner_planet", r_ca, False, psi_a, ph.p0_sun_inner,
                          ph.p_assembly_sun_inner),
        "inner_outer": mesh("inner_outer", "inner_planet", "outer_planet", l_ab, False, phi_ab,
                            ph.p0_inner_outer, ph.p_assembly_inner_outer),
        "outer_ring": mesh("outer_ring", "outer_planet", "ring", r_cb, True, psi_b, ph.p0_outer_ring,
                           ph.p_assembly_outer_ring),
    }
    ra, rb = planet_speed_ratios(ga.teeth, gb.teeth, ring.teeth)
    return Layout(gears=G, planets=n, handedness=h, r_ca=r_ca, r_cb=r_cb, l_ab=l_ab, delta_psi=dpsi,
                  psi_a=psi_a, psi_b=psi_b, centres_a=ca, centres_b=cb, phi_ab=phi_ab, meshes=meshes,
                  phasing=ph, sun_ratio=speed_ratio(sun.teeth, ring.teeth), inner_ratio=ra, outer_ratio=rb,
                  assembly_number=assembly_number(sun.teeth, ring.teeth, n))


def loaded_flanks(sun_torque_sign: float) -> dict:
    """Flank f = ±1 of each mesh that the torque path loads when the sun is driven with a torque of
    this sign (quasi-static, planets free to spin, ring held): the sun compresses flank sign(T_s) of
    the sun–inner meshes; the planets' spin balance then loads flank −sign(T_s) of the inner–outer and
    outer–ring meshes. Forward operation (T_s < 0): {-1, +1, +1}; reverse flips all three."""
    s = 1 if sun_torque_sign > 0 else -1
    return {"sun_inner": s, "inner_outer": -s, "outer_ring": -s}


@dataclass(frozen=True)
class Kinematics:
    """Nominal steady state of an operating point, ring fixed (signed: + = counter-clockwise).

    Speeds in rad/s (absolute), frequencies in Hz, torques in N·m acting on the body: the sun gets
    T_s = P/|ω_s| along ω_s (driving motor), the carrier T_c = −P/ω_c (loading motor), the ring the
    reaction T_r = −(T_s + T_c) (lossless, steady).
    """

    carrier_speed: float
    sun_speed: float
    inner_planet_speed: float
    outer_planet_speed: float
    carrier_frequency: float
    mesh_frequency: float
    output_power: float
    sun_torque: float
    carrier_torque: float
    ring_torque: float


def kinematics(z_s: int, z_a: int, z_b: int, z_r: int, carrier_speed: float, output_power: float) -> Kinematics:
    """Nominal speeds and torques for signed carrier speed [rad/s] and output power [W]: P > 0 driving (the power
    flows from the sun to the carrier), P < 0 braking (from the carrier to the sun). Lossless: T_s = P/ω_s,
    T_c = −P/ω_c, so T_s ω_s + T_c ω_c = 0."""
    w_c = carrier_speed
    w_s = speed_ratio(z_s, z_r) * w_c
    ra, rb = planet_speed_ratios(z_a, z_b, z_r)
    if output_power != 0 and w_c == 0:
        raise ParameterError.at("operating.output_power",
                                f"{output_power:g} W cannot be transmitted at carrier speed 0")
    if output_power != 0 and w_s == 0:
        raise ParameterError.at("gears.ring.teeth", "z_r = z_s: with the ring fixed the sun does not turn, "
                                                    "so no power can be driven in")
    t_s = output_power / w_s if output_power != 0 else 0.0      # P/ω_s: along ω_s when driving, against it braking
    t_c = -output_power / w_c if output_power != 0 else 0.0
    if not (math.isfinite(t_s) and math.isfinite(t_c)):
        raise ParameterError.at("operating.carrier_speed", f"{abs(w_c):.3g} rad/s is too slow to transmit "
                                                           f"{output_power:g} W: the torques P/omega overflow")
    f_c = abs(w_c) / TWO_PI
    return Kinematics(carrier_speed=w_c, sun_speed=w_s, inner_planet_speed=ra * w_c, outer_planet_speed=rb * w_c,
                      carrier_frequency=f_c, mesh_frequency=mesh_frequency(z_r, f_c), output_power=output_power,
                      sun_torque=t_s, carrier_torque=t_c, ring_torque=-(t_s + t_c))


# ---------------------------------------------------------------------------------------------
# design checks
# ---------------------------------------------------------------------------------------------
class DesignWarning(UserWarning):
    """A design check found something a real machine would not have; the model still runs."""


@dataclass(frozen=True)
class Finding:
    severity: str      # "error" | "warning"
    parameter: str     # dotted parameter name (or the group at fault, e.g. "gears")
    message: str
    collides: bool = False   # gears overlap even at their pitch circles: the machine could not be built

    def __str__(self) -> str:
        return f"{self.parameter}: {self.message}"


_TAG = {"inner_planet": "a", "outer_planet": "b"}     # planets are named a1..aN, b1..bN (components.dpgt)


def _addendum_fix(overlap: float, *gears: tuple[str, "GearGeometry"]) -> str:
    """The parameters that would remove a tip-circle overlap: each gear's addendum coefficient shortened by the
    overlap over its module (its tip radius moves by h_a m)."""
    return " (e.g. " + " or ".join(f"gears.{n}.addendum_coefficient <= {g.addendum_coefficient - overlap / g.module:.3g}"
                                   for n, g in gears) + ")"


def _overlap_findings(out, name_i, name_j, ci, cj, ri, rj, parameter, same=False, pitch=None, tags=("", ""),
                      fix: str = ""):
    """Warn about the worst tip-circle overlap between two families of gear centres (non-meshing). ``tags``: the
    planets' name letters ("a" inner, "b" outer): a planet is named as everywhere else, a1..aN (pair n from 1).
    ``fix``: a callable of the overlap [m] naming the parameters that would remove it."""
    ci, cj = np.atleast_2d(ci), np.atleast_2d(cj)
    d = np.linalg.norm(ci[:, None, :] - cj[None, :, :], axis=-1)
    if same:
        d = d + np.where(np.eye(len(ci), dtype=bool), np.inf, 0.0)  # a gear does not clash with itself
    ov = ri + rj - d
    k = np.unravel_index(np.argmax(ov), ov.shape)
    if ov[k] > 1e-12:
        i, j = (int(k[0]), int(k[1]))
        who_i = f"{name_i} {tags[0]}{i + 1}" if tags[0] else name_i
        who_j = f"{name_j} {tags[1]}{j + 1}" if tags[1] else name_j
        what = f"tip circles of {who_i} and {who_j} (not in mesh) overlap by {ov[k] * 1e3:.2f} mm " \
               f"(centre distance {d[k] * 1e3:.2f} mm < {(ri + rj) * 1e3:.2f} mm)"
        collides = bool(pitch is not None and d[k] < sum(pitch))
        if collides:
            # the model has no contact between these bodies, so it still runs; the machine could not exist
            what += "; even their pitch circles overlap: the gears would collide"
        else:
            what += "; a real design needs profile shift, shorter addenda or an axial offset" + (fix(ov[k]) if fix else "")
        out.append(Finding("warning", parameter, what, collides))


def design_findings(params) -> list[Finding]:
    """All design findings for ``params``; never raises for a constructible parameter set.

    Sign and type checks of single values (positive masses, clearances ≥ 0, N ≥ 1, Z ≥ 3, h = ±1...)
    happen when the parameter objects are made; this function checks how the values fit together.
    """
    out: list[Finding] = []
    gs = params.gears.si()
    G = _gear_geometries(gs)
    _gear_findings(gs, G, out)
    if any(f.severity == "error" for f in out):
        return out
    try:
        lay = layout(params, gears_si=gs)
    except ParameterError as e:
        out.append(Finding("error", e.parameter or "gears", e.problem or str(e)))
        return out
    _mesh_findings(lay, out)
    _interference_findings(lay, G, out)
    _bearing_findings(params.bearing.si(), G, out)
    _clearance_findings(lay, params.bearing.si(), G, out)
    os_ = params.operating.si()
    try:
        kinematics(G["sun"].teeth, G["inner_planet"].teeth, G["outer_planet"].teeth, G["ring"].teeth,
                   os_.carrier_speed, os_.output_power)
    except ParameterError as e:
        out.append(Finding("error", e.parameter, e.problem))
    return out


_GEARS = ("sun", "inner_planet", "outer_planet", "ring")


def _gear_findings(gs, G, out) -> None:
    """Gears that mesh need one module and pressure angle; only the ring is internal; undercut, roots."""
    for n in _GEARS[1:]:
        if abs(gs[n].module - gs.sun.module) > 1e-12 * gs.sun.module:
            out.append(Finding("error", f"gears.{n}.module", f"{gs[n].module * 1e3:g} mm differs from the sun's "
                                                             f"{gs.sun.module * 1e3:g} mm: meshing gears need one module"))
        if abs(gs[n].pressure_angle - gs.sun.pressure_angle) > 1e-12:
            out.append(Finding("error", f"gears.{n}.pressure_angle", "differs from the sun's: meshing gears need "
                                                                     "one pressure angle"))
    for n in _GEARS:
        if gs[n].internal != (n == "ring"):
            out.append(Finding("error", f"gears.{n}.internal", "only the ring is an internal gear"))
    for n in _GEARS[:3]:
        g = G[n]
        z_min = 2.0 * g.addendum_coefficient / math.sin(g.pressure_angle) ** 2
        if g.teeth < z_min:
            out.append(Finding("warning", f"gears.{n}.teeth", f"{g.teeth} teeth < {z_min:.1f}: the generated "
                                                              f"profile is undercut (no profile shift modelled)"))
        if g.root_radius <= 0:
            out.append(Finding("error", f"gears.{n}.dedendum_coefficient", "root circle radius is not positive"))


def _mesh_findings(lay, out) -> None:
    """Contact ratios, and the assembly condition of equally spaced double-planet pairs."""
    for m in lay.meshes.values():
        if m.contact_ratio < 1.0:
            out.append(Finding("error", f"gears.{m.gear1}", f"{m.name} contact ratio {m.contact_ratio:.3f} < 1: "
                                                            f"contact is not continuous"))
        elif m.contact_ratio >= 2.0:
            out.append(Finding("warning", f"gears.{m.gear1}",
                               f"{m.name} contact ratio {m.contact_ratio:.3f} >= 2: the single/double tooth "
                               f"stiffness wave does not describe triple contact"))
    if not lay.assembles:
        mis = ", ".join(f"{x:+.3g}" for x in lay.phasing.ring_mismatch[1:])
        out.append(Finding("warning", "gears.planets",
                           f"(z_r - z_s)/N = {lay.assembly_number:.4g} is not an integer: equally spaced pairs do "
                           f"not assemble (pairs 2..{lay.planets} are off the ring's teeth by {mis} pitch); each pair's meshes "
                           f"are phased from its real position"))


def _interference_findings(lay, G, out) -> None:
    """Tip-circle interference between gears that do not mesh."""
    ra = {n: G[n].tip_radius for n in _GEARS}
    zero = np.zeros((1, 2))
    _overlap_findings(out, "the sun", "outer planet", zero, lay.centres_b, ra["sun"], ra["outer_planet"], "gears.sun",
                      pitch=(G["sun"].pitch_radius, G["outer_planet"].pitch_radius), tags=("", "b"),
                      fix=lambda ov: _addendum_fix(ov, ("sun", G["sun"]), ("outer_planet", G["outer_planet"])))
    # inner planet inside the ring: its outermost point must stay inside the ring's tip (inner) circle
    reach = lay.r_ca + ra["inner_planet"]
    if reach > ra["ring"] + 1e-12:
        what = f"tip circles of the inner planets and the ring (not in mesh) overlap by " \
               f"{(reach - ra['ring']) * 1e3:.2f} mm (r_ca + r_a,inner = {reach * 1e3:.2f} mm > ring tip radius " \
               f"{ra['ring'] * 1e3:.2f} mm)"
        collides = bool(lay.r_ca + G["inner_planet"].pitch_radius > G["ring"].pitch_radius)
        if collides:
            what += "; even their pitch circles overlap: the gears would collide"
        else:
            what += ("; a real design needs profile shift, shorter addenda or an axial offset"
                     + _addendum_fix(reach - ra["ring"], ("inner_planet", G["inner_planet"]), ("ring", G["ring"])))
        out.append(Finding("warning", "gears.ring", what, collides))
    ca, cb = lay.centres_a, lay.centres_b
    if lay.planets > 1:
        rp = {n: G[n].pitch_radius for n in _GEARS}
        for (ni, ci), (nj, cj) in ((("inner_planet", ca), ("inner_planet", ca)),
                                   (("outer_planet", cb), ("outer_planet", cb)),
                                   (("inner_planet", ca), ("outer_planet", cb))):  # a_n vs b_m, n != m
            _overlap_findings(out, ni.replace("_", " "), nj.replace("_", " "), ci, cj, ra[ni], ra[nj],
                              "gears.planets", same=True, pitch=(rp[ni], rp[nj]), tags=(_TAG[ni], _TAG[nj]))


def _bearing_findings(bs, G, out) -> None:
    """Planet bearing: pin, rollers, cage bars, the bore inside each planet's root circle."""
    dm, d, z = bs.pitch_diameter, bs.roller_diameter, bs.rollers
    if d >= dm:
        out.append(Finding("error", "bearing.roller_diameter", f"{d * 1e3:g} mm leaves no pin: the inner raceway "
                                                               f"diameter d_m - D = {(dm - d) * 1e3:g} mm must be > 0"))
    chord = dm * math.sin(math.pi / z)
    if chord <= d:
        out.append(Finding("error", "bearing.rollers", f"{z} rollers of {d * 1e3:g} mm do not fit on the "
                                                       f"{dm * 1e3:g} mm pitch circle (centre spacing {chord * 1e3:.3f} mm)"))
    else:
        bar = math.pi * dm / z - d - 2.0 * bs.cage.pocket_clearance
        if bar <= 0:
            out.append(Finding("error", "bearing.cage.pocket_clearance",
                               f"pockets ({d * 1e3:g} mm + 2 x {bs.cage.pocket_clearance * 1e3:g} mm) leave no cage bar "
                               f"between {z} rollers on the pitch circle"))
    bore = bs.outer_raceway_radius
    for n in ("inner_planet", "outer_planet"):
        rim = G[n].root_radius - bore
        height = (G[n].addendum_coefficient + G[n].dedendum_coefficient) * G[n].module
        if rim <= 0:
            out.append(Finding("error", "bearing.pitch_diameter",
                               f"the bore ({2 * bore * 1e3:.3f} mm: pitch diameter {dm * 1e3:g} + roller diameter "
                               f"{d * 1e3:g} + clearance {bs.clearance * 1e3:g} mm) does not fit inside the "
                               f"{n.replace('_', ' ')}'s root circle ({2 * G[n].root_radius * 1e3:.3f} mm)"))
        elif rim < RIM_BACKUP_RATIO * height:
            out.append(Finding("warning", "bearing.pitch_diameter",
                               f"{n.replace('_', ' ')} rim under the teeth is {rim * 1e3:.2f} mm, less than "
                               f"{RIM_BACKUP_RATIO} x tooth height ({height * 1e3:.2f} mm): a thin rim is flexible, "
                               f"which the rigid planet model ignores"))


def _tip_root_clearances(g1: GearGeometry, g2: GearGeometry, a: float, internal: bool) -> float:
    """The smaller radial gap between a tooth tip and the mating gear's root circle at centre distance a
    (c*·m = 0.25 m for standard teeth at the nominal distance)."""
    if internal:   # gear 2 the ring: the planet's tip against the ring's root, the ring's tip against the planet's root
        return min(g2.root_radius - (a + g1.tip_radius), g2.tip_radius - (a + g1.root_radius))
    return min(a - g1.tip_radius - g2.root_radius, a - g2.tip_radius - g1.root_radius)


def centre_distance_limit(mg, G, da: float) -> str | None:
    """Why mesh ``mg``'s gears cannot take their centre distance moved by ±da, or None: the teeth must neither
    strike the mating roots (tip–root gap > 0) nor lose continuous contact (ε_α ≥ 1), which the mesh model has
    neither of."""
    g1, g2 = G[mg.gear1], G[mg.gear2]
    for a in (mg.centre_distance - da, mg.centre_distance + da):
        gap = _tip_root_clearances(g1, g2, a, mg.internal)
        try:
            eps = contact_ratio(g1, g2, a, mg.internal)
        except ParameterError:
            eps = 0.0
        if gap <= 0.0 or eps < 1.0:
            return (f"the teeth strike the mating roots (tip-root gap {gap * 1e3:.3f} mm)" if gap <= 0.0 else
                    f"the contact ratio falls to {eps:.3f} < 1")
    return None


def _clearance_findings(lay, bs, G, out) -> None:
    """A bearing clearance bigger than the gears allow: a planet free to move c/2 on its pin (the inner–outer
    mesh: both planets, c) changes its centre distances by that much (:func:`centre_distance_limit`)."""
    play = 0.5 * bs.clearance
    for key, mg in lay.meshes.items():
        da = 2.0 * play if key == "inner_outer" else play
        what = centre_distance_limit(mg, G, da)
        if what:
            out.append(Finding("error", "bearing.clearance",
                               f"{bs.clearance * 1e3:g} mm lets the {key.replace('_', '-')} centre distance move by "
                               f"{da * 1e3:.3f} mm, at which {what}: the gears allow less"))
            return


def check_design(params, strict: bool = True) -> list[Finding]:
    """Run :func:`design_findings`; warn (:class:`DesignWarning`) for each warning; with ``strict``
    raise ParameterError listing every error, else warn for errors too. Returns the findings."""
    found = design_findings(params)
    errors = [f for f in found if f.severity == "error"]
    for f in found:
        if f.severity == "warning" or not strict:
            # a DesignWarning says it is a warning; an error let through (strict=False) says it is one
            warnings.warn(str(f) if f.severity == "warning" else f"{f.severity}: {f}", DesignWarning, stacklevel=2)
    if strict and errors:
        lines = "\n".join(f"  {f}" for f in errors)
        first = errors[0]
        named = ", ".join(dict.fromkeys(f.parameter for f in errors))      # every parameter at fault, in order
        raise ParameterError(f"{named}: design check failed with {len(errors)} error(s):\n{lines}",
                             parameter=first.parameter, problem=first.message)
    return found
