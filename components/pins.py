"""The planet pins as elastic beams (docs/model.md §8.8, ``bearing.pin``): the stiffness, at its bearing's centre, of a
pin clamped in the carrier's plates, and the pin's inertias.

A pin of diameter d (the bearing's inner raceway, d = d_m − D) with a bore d_i, of Young's modulus E and Poisson's
ratio ν (``bearing.elastic_modulus``, ``bearing.poisson_ratio``: the raceways' steel), I = π(d⁴ − d_i⁴)/64,
A = π(d² − d_i²)/4, G = E/(2(1 + ν)), carries its bearing's load at the bearing's centre (axial station ζ = 0): the
force F and the moment M the roller slices put on it (the sliced contact's −Σ F_k and −Σ ζ_k F_k). The pin section
under the bearing moves as one piece, by u and the slope s (its axis through u + ζ s): s is the turn of that rigid
section (Timoshenko's cross-section rotation ψ). The pin is short and thick (span over diameter 0.6–1.3), so it is a
Timoshenko beam: its deflection has a shear part, the shear strain γ = V/(κGA) under the shear force V, with
Cowper's shear coefficient of a circular tube (G. R. Cowper, "The shear coefficient in Timoshenko's beam theory",
*J. Appl. Mech.* 33 (1966) 335–340, Table 1), m = d_i/d,

    κ = 6(1 + ν)(1 + m²)² / ((7 + 6ν)(1 + m²)² + (20 + 12ν) m²)      (solid, m = 0: κ = 6(1 + ν)/(7 + 6ν)).

Clamped at ζ = +a (the shaft-side plate) and at ζ = −b (the far plate), the two Timoshenko beams between the clamps
and the station, condensed onto (u, s) per transverse direction, give, with φ_a = 12EI/(κGA a²) (φ_b likewise),

    [F; M] = EI/(1 + φ_a) [[12/a³, 6/a²], [6/a², (4 + φ_a)/a]] [u; s] + EI/(1 + φ_b) [[12/b³, −6/b²], [−6/b², (4 + φ_b)/b]] [u; s],

b → ∞ for a pin held in one plate only (a cantilever of overhang a); φ → 0 (G → ∞) is Euler–Bernoulli's beam. Each
span is the inverse of a cantilever's flexibility (Timoshenko & Gere, *Mechanics of Materials*; Roark's Table 8.1
cases 1a and 3a, W. C. Young, R. G. Budynas, *Roark's Formulas for Stress and Strain*, 7th ed., 2002, with the shear
deflection of §8.10): under an end load W, y = W a³/(3EI) + W a/(κGA), ψ = W a²/(2EI) — no shear term in the end
section's turn —; under an end moment M, ψ = M a/(EI), y = M a²/(2EI). Both ends fixed, a load W at the centre
deflects the station by W l³/(192 EI) + W l/(4κGA) (l = a + b) without turning it; ``tests/components/test_pins.py``
holds the matrix to those forms and, off the centre, to the Timoshenko equations integrated numerically.

Where the seat's slope differs from s: the rollers run on the pin's own surface, whose line is the pin's centre line
u(ζ), of slope ψ + γ, not ψ alone. The shear force, and so γ, steps at every roller load along the seat: a load at
the station leaves γ = V_a/(κGA) on the clamp side of the load and V_b/(κGA) beyond it, so a seat loaded evenly about
its centre has the mean γ = (V_a + V_b)/(2κGA) over its length, and a load toward one end the γ of the other side.
Under a centred load the shear forces on the two sides are opposite in a pin fixed in both plates, (V_a + V_b) = 0,
and the seat turns by ψ alone; in a cantilever V_b = 0, so the seat's line turns by W/(2κGA) more than ψ for a load
spread evenly over it, and by up to W/(κGA) for one at its outer end (0.31′ and 0.62′ at 10 kN on the reference pin,
against ψ = 0.68′). That local shear of the seat is left out with the seat's own bending (below): the station's s is
the rigid section's ψ, so the cantilever's slope under its load is a lower bound by W/(2κGA).

The pin's turn about its axis against the carrier: the torsion of the two clamped lengths, k_θ = G K (1/a + 1/b),
K = π(d⁴ − d_i⁴)/32 (Roark Table 10.1, case 1).

Left out: the pin's bending within the bearing's length (its curvature under the load bows the raceway by M z²/(2EI),
0.06 µm over a 9 mm roller at 12 kN: the section moves as one) and the seat's shear within it (above), the clamps' own
compliance (the plates' bores are rigid), and the beam theories' own limits for a span of 0.6–1.3 diameters (the load
spreads into the pin as a three-dimensional body: Timoshenko's beam is the first correction to Euler–Bernoulli's, not
an exact solution).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["PIN_MODELS", "PIN_MOUNTINGS", "second_moment", "shear_coefficient", "beam_stiffness", "pin_spans",
           "pin_stiffness", "pin_inertias"]

PIN_MODELS = ("rigid", "elastic")
PIN_MOUNTINGS = ("both_plates", "one_plate")


def second_moment(d: float, d_i: float = 0.0) -> float:
    """Second moment of area I [m⁴] of a tube of outer diameter d and bore d_i: π(d⁴ − d_i⁴)/64."""
    return math.pi * (d ** 4 - d_i ** 4) / 64.0


def shear_coefficient(nu: float, m: float = 0.0) -> float:
    """Cowper's (1966, Table 1) Timoshenko shear coefficient κ of a circular tube of bore-to-outer diameter ratio
    ``m`` (0: solid) and Poisson's ratio ``nu`` (module docstring)."""
    if not (0.0 <= m < 1.0 and -1.0 < nu <= 0.5):
        raise ValueError(f"shear_coefficient: m must be in [0, 1) and nu in (-1, 0.5], got m={m!r}, nu={nu!r}")
    w = (1.0 + m * m) ** 2
    return 6.0 * (1.0 + nu) * w / ((7.0 + 6.0 * nu) * w + (20.0 + 12.0 * nu) * m * m)


def beam_stiffness(EI: float, a: float, b: float = math.inf, kGA: float = math.inf) -> np.ndarray:
    """(2, 2) stiffness [[k_uu, k_us], [k_us, k_ss]] [N/m, N/rad, N m/rad] of a beam's station against its clamps at
    distances ``a`` (toward +ζ) and ``b`` (toward −ζ; ``math.inf``: none) [m], per transverse direction (module
    docstring): the deflection u and the section's turn s under the station's force F and moment M solve
    K [u; s] = [F; M]. ``kGA`` [N]: the shear stiffness κGA (``math.inf``: Euler–Bernoulli's beam, no shear)."""
    if not (a > 0.0 and b > 0.0 and EI > 0.0 and kGA > 0.0):
        raise ValueError(f"beam_stiffness: EI, a, b and kGA must be > 0, got EI={EI!r}, a={a!r}, b={b!r}, kGA={kGA!r}")
    K = np.zeros((2, 2))
    for length, sign in ((a, 1.0), (b, -1.0)):
        if math.isinf(length):
            continue
        phi = 12.0 * EI / (kGA * length * length)          # 0 for kGA = inf
        K += EI / (1.0 + phi) * np.array([[12.0 / length ** 3, sign * 6.0 / length ** 2],
                                          [sign * 6.0 / length ** 2, (4.0 + phi) / length]])
    return K


def pin_spans(b, span: float) -> tuple[float, float]:
    """(a, b) [m]: the bearing centre's distances to the clamps of its pin (``b`` the bearing's SI parameters,
    ``span`` the carrier's plate span L_c): both plates, the bearing mid-span (L_c/2 each side); one plate, the
    shaft-side plate at the overhang and no far clamp."""
    if b.pin.mounting == "one_plate":
        return b.pin.overhang, math.inf
    return 0.5 * span, 0.5 * span


def pin_stiffness(b, span: float) -> dict:
    """The pin's support at its bearing's centre (``b`` the bearing's SI parameters, ``span`` the carrier's plate span
    L_c [m]): k_uu, k_us, k_ss (:func:`beam_stiffness`, Timoshenko's beam with Cowper's κ) and the torsional k_theta,
    keys of :class:`mbd.elements.tilt.BeamSupport`."""
    d, d_i = 2.0 * b.inner_raceway_radius, b.pin.bore_diameter
    E, nu = b.elastic_modulus, b.poisson_ratio
    a, c = pin_spans(b, span)
    G = E / (2.0 * (1.0 + nu))
    kGA = shear_coefficient(nu, d_i / d) * G * math.pi * (d ** 2 - d_i ** 2) / 4.0
    K = beam_stiffness(E * second_moment(d, d_i), a, c, kGA)
    k_theta = G * math.pi * (d ** 4 - d_i ** 4) / 32.0 * (1.0 / a + (0.0 if math.isinf(c) else 1.0 / c))
    return dict(k_uu=float(K[0, 0]), k_us=float(K[0, 1]), k_ss=float(K[1, 1]), k_theta=float(k_theta))


def pin_inertias(b, span: float) -> dict:
    """The pin's mass [kg], polar and diametral inertias [kg m²] (a tube of the plate span's length, its bore d_i):
    m = ρ π(d² − d_i²) L/4, J_p = m(d² + d_i²)/8, J_d = J_p/2 + m L²/12."""
    d, d_i = 2.0 * b.inner_raceway_radius, b.pin.bore_diameter
    m = b.pin.density * math.pi * (d ** 2 - d_i ** 2) * span / 4.0
    J_p = m * (d ** 2 + d_i ** 2) / 8.0
    return dict(mass=m, polar=J_p, diametral=0.5 * J_p + m * span ** 2 / 12.0)
