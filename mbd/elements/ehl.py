"""Elastohydrodynamic line contact (MODEL.md §3.8): the one owner of the film-thickness and Hertz-strip
laws, written with :mod:`mbd.ad` so that the EHL traction law of the roller contacts differentiates
exactly; :mod:`components.lubrication` uses the same functions for the film outputs.

Film (isothermal, Pan & Hamrock 1989, J. Tribol. 111: 246–251), with U = η₀u/(E'R), W' = w'/(E'R),
G = α_p E' (u the entraining speed, w' the load per unit length, R the reduced radius):
    h_min / R = 1.714 W'^(−0.128) U^0.694 G^0.568,     h_c / R = 2.922 W'^(−0.166) U^0.692 G^0.470.
Hertz strip of a line contact: half width b = √(8w'R/(πE')), peak pressure p_max = √(w'E'/(2πR)),
p(x) = p_max √(1 − (x/b)²), mean pressure p̄ = w'/(2b) = π p_max / 4.
"""
from __future__ import annotations

import numpy as np

from .. import ad

__all__ = ["film_min", "film_central", "hertz_peak_pressure", "hertz_half_width", "STRIP_NODES", "STRIP_WEIGHTS"]

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
    return R * 1.714 * G ** 0.568 * ad.power(W, -0.128) * ad.power(U, 0.694)


def film_central(u, w, R, eta0, alpha_p, E_red):
    """h_c [m] (arguments as :func:`film_min`)."""
    U, W, G = _groups(u, w, R, eta0, alpha_p, E_red)
    return R * 2.922 * G ** 0.470 * ad.power(W, -0.166) * ad.power(U, 0.692)


def hertz_peak_pressure(w, R, E_red):
    """p_max [Pa] of a line contact carrying w [N/m] with reduced radius R [m]."""
    return ad.sqrt(w * (E_red / (2.0 * np.pi * R)))


def hertz_half_width(w, R, E_red):
    """b [m] of a line contact carrying w [N/m] with reduced radius R [m]."""
    return ad.sqrt(w * (8.0 * R / (np.pi * E_red)))
