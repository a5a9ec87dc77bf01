"""The planet pins as elastic beams (docs/model.md §8.8, ``bearing.pin``): the stiffness, at its bearing's centre, of a
pin clamped in the carrier's plates, and the pin's inertias.

A pin of diameter d (the bearing's inner raceway, d = d_m − D) with a bore d_i, of Young's modulus E
(``bearing.elastic_modulus``), I = π(d⁴ − d_i⁴)/64, carries its bearing's load at the bearing's centre (axial station
ζ = 0): the force F and the moment M the roller slices put on it (the sliced contact's −Σ F_k and −Σ ζ_k F_k). The
pin section under the bearing moves as one piece, by u and the slope s (its axis through u + ζ s). Clamped at
ζ = +a (the shaft-side plate) and at ζ = −b (the far plate), the two Euler–Bernoulli beams between the clamps and the
station, condensed onto (u, s) per transverse direction, give

    [F; M] = EI [[12(1/a³ + 1/b³), 6(1/a² − 1/b²)], [6(1/a² − 1/b²), 4(1/a + 1/b)]] [u; s],

b → ∞ for a pin held in one plate only (a cantilever of overhang a). This is the flexibility of Roark's Table 8.1
(W. C. Young, R. G. Budynas, *Roark's Formulas for Stress and Strain*, 7th ed., 2002): cases 1a and 3a (a cantilever
under an end load W: y = W a³/(3EI), θ = W a²/(2EI); under an end moment M: θ = M a/(EI), y = M a²/(2EI)) and 1d
and 3d (both ends fixed: under the load y = W a³b³/(3EI l³), θ = W a²b²(b − a)/(2EI l³); under a moment at the centre
θ = M l/(16 EI), l = a + b); ``tests/components/test_pins.py`` holds the matrix to those formulas. The pin's turn about
its axis against the carrier: the torsion of the two clamped lengths, k_θ = G K (1/a + 1/b), K = π(d⁴ − d_i⁴)/32
(Roark Table 10.1, case 1), G = E/(2(1 + ν)).

Left out: shear deformation (for this short, thick pin, span over diameter 1.3, Roark §8.10's shear term
F l/(κ A G) is of the order of the bending deflection, so the bending slope here is a lower bound of the pin's), the
pin's bending within the bearing's length (its curvature under the load bows the raceway by M z²/(2EI), 0.06 µm over
a 9 mm roller at 12 kN: the section moves as one), the clamps' own compliance (the plates' bores are rigid).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["PIN_MODELS", "PIN_MOUNTINGS", "second_moment", "beam_stiffness", "pin_spans", "pin_stiffness",
           "pin_inertias"]

PIN_MODELS = ("rigid", "elastic")
PIN_MOUNTINGS = ("both_plates", "one_plate")


def second_moment(d: float, d_i: float = 0.0) -> float:
    """Second moment of area I [m⁴] of a tube of outer diameter d and bore d_i: π(d⁴ − d_i⁴)/64."""
    return math.pi * (d ** 4 - d_i ** 4) / 64.0


def beam_stiffness(EI: float, a: float, b: float = math.inf) -> np.ndarray:
    """(2, 2) stiffness [[k_uu, k_us], [k_us, k_ss]] [N/m, N/rad, N m/rad] of a beam's station against its clamps at
    distances ``a`` (toward +ζ) and ``b`` (toward −ζ; ``math.inf``: none) [m], per transverse direction (module
    docstring): the deflection u and the slope du/dζ under the station's force F and moment M solve K [u; s] = [F; M]."""
    if not (a > 0.0 and b > 0.0 and EI > 0.0):
        raise ValueError(f"beam_stiffness: EI, a and b must be > 0, got EI={EI!r}, a={a!r}, b={b!r}")
    ib = 0.0 if math.isinf(b) else 1.0 / b
    ia = 1.0 / a
    return EI * np.array([[12.0 * (ia ** 3 + ib ** 3), 6.0 * (ia ** 2 - ib ** 2)],
                          [6.0 * (ia ** 2 - ib ** 2), 4.0 * (ia + ib)]])


def pin_spans(b, span: float) -> tuple[float, float]:
    """(a, b) [m]: the bearing centre's distances to the clamps of its pin (``b`` the bearing's SI parameters,
    ``span`` the carrier's plate span L_c): both plates, the bearing mid-span (L_c/2 each side); one plate, the
    shaft-side plate at the overhang and no far clamp."""
    if b.pin.mounting == "one_plate":
        return b.pin.overhang, math.inf
    return 0.5 * span, 0.5 * span


def pin_stiffness(b, span: float) -> dict:
    """The pin's support at its bearing's centre (``b`` the bearing's SI parameters, ``span`` the carrier's plate span
    L_c [m]): k_uu, k_us, k_ss (:func:`beam_stiffness`) and the torsional k_theta, keys of
    :class:`mbd.elements.tilt.BeamSupport`."""
    d, d_i = 2.0 * b.inner_raceway_radius, b.pin.bore_diameter
    E = b.elastic_modulus
    a, c = pin_spans(b, span)
    K = beam_stiffness(E * second_moment(d, d_i), a, c)
    G = E / (2.0 * (1.0 + b.poisson_ratio))
    k_theta = G * math.pi * (d ** 4 - d_i ** 4) / 32.0 * (1.0 / a + (0.0 if math.isinf(c) else 1.0 / c))
    return dict(k_uu=float(K[0, 0]), k_us=float(K[0, 1]), k_ss=float(K[1, 1]), k_theta=float(k_theta))


def pin_inertias(b, span: float) -> dict:
    """The pin's mass [kg], polar and diametral inertias [kg m²] (a tube of the plate span's length, its bore d_i):
    m = ρ π(d² − d_i²) L/4, J_p = m(d² + d_i²)/8, J_d = J_p/2 + m L²/12."""
    d, d_i = 2.0 * b.inner_raceway_radius, b.pin.bore_diameter
    m = b.pin.density * math.pi * (d ** 2 - d_i ** 2) * span / 4.0
    J_p = m * (d ** 2 + d_i ** 2) / 8.0
    return dict(mass=m, polar=J_p, diametral=0.5 * J_p + m * span ** 2 / 12.0)
