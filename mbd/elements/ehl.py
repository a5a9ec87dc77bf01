"""Elastohydrodynamic line contact (docs/model.md §9.2): the one owner of the film-thickness and Hertz-strip
laws, written with :mod:`mbd.ad` so that the EHL traction law of the roller contacts differentiates
exactly; :mod:`components.lubrication` uses the same functions for the film outputs.

Film (isothermal, Pan & Hamrock 1989, J. Tribol. 111: 246–251), with U = η₀u/(E'R), W' = w'/(E'R),
G = α_p E' (u the entraining speed, w' the load per unit length, R the reduced radius):
    h_min / R = 1.714 W'^(−0.128) U^0.694 G^0.568,     h_c / R = 2.922 W'^(−0.166) U^0.692 G^0.470.
The fit is a regression of isothermal solutions; at heavy loads its two films cross, h_c/h_min =
1.705 G^(−0.098) W'^(−0.038) U^(−0.002) < 1 (above W' ≈ 1.2e-3 at G ≈ 5100, U ≈ 1e-10, the reference
bearing's oil and speeds): there it has left its range.

Thermal reduction (Murch & Wilson 1975, J. Lubr. Technol. 97: 212–216): shear heating of the oil in the
inlet, where the reverse flow shears it even in pure rolling, lowers its viscosity there and so the film.
Their inlet analysis (Newtonian oil, line contact, pure rolling) gives the factor on both films
    φ_T = 3.94 / (3.94 + L^0.62),     L = β η₀ u² / k   (the thermal loading number),
β = −(1/η) dη/dT the oil's temperature–viscosity coefficient at the inlet temperature, k its thermal
conductivity, u the mean entraining speed. φ_T = 1 at L = 0, 0.80 at L = 1, ½ at L ≈ 9.1. Sliding heats
the inlet more (Wilson & Sheu 1983; Gupta et al. 1992 add the slide-to-roll ratio): with slip this factor
is an upper bound on the film.
Hertz strip of a line contact: half width b = √(8w'R/(πE')), peak pressure p_max = √(w'E'/(2πR)),
p(x) = p_max √(1 − (x/b)²), mean pressure p̄ = w'/(2b) = π p_max / 4.
"""
from __future__ import annotations

import numpy as np

from .. import ad

__all__ = ["film_min", "film_central", "thermal_loading", "thermal_factor", "FILM_MIN_U_EXPONENT",
           "THERMAL_A", "THERMAL_EXPONENT", "hertz_peak_pressure", "hertz_half_width", "STRIP_NODES",
           "STRIP_WEIGHTS"]

# h_min ∝ U^0.694 (Pan & Hamrock): at fixed load and speed the film grows as η₀^0.694
FILM_MIN_U_EXPONENT = 0.694
# Murch & Wilson's (1975) thermal reduction φ_T = A / (A + L^m)
THERMAL_A, THERMAL_EXPONENT = 3.94, 0.62

# Gauss–Legendre nodes on the strip x/b ∈ (−1, 1) (halved weights: a mean over the strip), and the
# pressure profile √(1 − ξ²) at them
_XI, _WQ = np.polynomial.legendre.leggauss(8)
STRIP_NODES = np.sqrt(1.0 - _XI ** 2)
STRIP_WEIGHTS = 0.5 * _WQ


def _groups(u, w, R, eta0, alpha_p, E_red):
    return eta0 * u / (E_red * R), w * (1.0 / (E_red * R)), alpha_p * E_red


def film_min(u, w, R, eta0, alpha_p, E_red):
    """h_min [m]; u ≥ 0 the entraining speed [m/s], w > 0 the load per unit length [N/m]."""
    U, W, G = _groups(u, w, R, eta0, alpha_p, E_red)
    return R * 1.714 * G ** 0.568 * ad.power(W, -0.128) * ad.power(U, FILM_MIN_U_EXPONENT)


def film_central(u, w, R, eta0, alpha_p, E_red):
    """h_c [m] (arguments as :func:`film_min`)."""
    U, W, G = _groups(u, w, R, eta0, alpha_p, E_red)
    return R * 2.922 * G ** 0.470 * ad.power(W, -0.166) * ad.power(U, 0.692)


def thermal_loading(u, eta0, beta, k):
    """Murch & Wilson's thermal loading number L = β η₀ u² / k: u the entraining speed [m/s], eta0 [Pa·s],
    beta = −(1/η) dη/dT [1/K], k the oil's thermal conductivity [W/(m·K)]."""
    return u * u * (beta * eta0 / k)


def thermal_factor(L):
    """Murch & Wilson's thermal reduction φ_T = 3.94 / (3.94 + L^0.62) of the film (L ≥ 0)."""
    return THERMAL_A / (THERMAL_A + ad.power(L, THERMAL_EXPONENT))


def hertz_peak_pressure(w, R, E_red):
    """p_max [Pa] of a line contact carrying w [N/m] with reduced radius R [m]."""
    return ad.sqrt(w * (E_red / (2.0 * np.pi * R)))


def hertz_half_width(w, R, E_red):
    """b [m] of a line contact carrying w [N/m] with reduced radius R [m]."""
    return ad.sqrt(w * (8.0 * R / (np.pi * E_red)))
