"""Roller profiles (docs/model.md §8.8): the drop P(x) of a roller's radius at axial position x from its centre,
|x| ≤ l/2, chosen by ``bearing.profile.shape`` (:class:`components.params.ProfileParams`); the races are straight.

* ``straight``: P = 0.
* ``crowned``: straight over the middle length l_f, circular arcs beyond that reach the drop h at the ends:
  P = R_c − sqrt(R_c² − (|x| − l_f/2)²) for |x| > l_f/2, R_c = (c² + h²)/(2h), c = (l − l_f)/2 (the arc through
  the end point, tangent to the flat).
* ``logarithmic`` (Lundberg 1939; Johns & Gohar 1981, the finite end drop):
  P = Q_d/(π l E*) · ln[1/(1 − (1 − 0.3033 a/b)(2x/l)²)], a the Hertz half-width of the inner (pin) contact at the
  design load Q_d, a = sqrt(4 Q_d R/(π l E*)), 1/R = 2/D + 2/d_pin, b = l/2, E* = [(1 − ν²)/E + (1 − ν²)/E]⁻¹.
  At the ends P = Q_d/(π l E*) ln[b/(0.3033 a)]: finite.
* ``iso_16281``: ISO/TS 16281:2008's default profile for L_we ≤ 2.5 D_we, P = 0.00035 D ln[1/(1 − (2x/l)²)].
  It is infinite at the ends; the argument 2|x|/l is capped at 29/30, the end slice centre of the standard's
  30 laminae, so that the profile is one function of x whatever the slice count (at n_s = 30 it is the
  standard's slice values; finer slices see the same drop, 0.00035 D ln(900/59) ≈ 2.72·0.00035 D, over the
  last 1/60 of l at each end).
* ``table``: the user's points (x, P), linearly interpolated (held beyond the last point); all x ≥ 0: a
  symmetric profile, P(|x|).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["PROFILES", "ISO_16281_PROFILE_COEFFICIENT", "ISO_16281_CAP", "LUNDBERG_END_COEFFICIENT",
           "reduced_modulus", "roller_drop"]

PROFILES = ("straight", "crowned", "logarithmic", "iso_16281", "table")
ISO_16281_PROFILE_COEFFICIENT = 0.00035   # ISO/TS 16281:2008 default profile, × D_we
ISO_16281_CAP = 29.0 / 30.0               # 2|x|/l of the end lamina's centre at the standard's 30 laminae
LUNDBERG_END_COEFFICIENT = 0.3033         # Johns & Gohar (1981): 1 − 0.3033 a/b keeps the end drop finite


def reduced_modulus(b) -> float:
    """E* = [(1 − ν²)/E + (1 − ν²)/E]⁻¹ [Pa] of roller and raceway of the same material (Johnson's contact modulus:
    p_0 = sqrt(w E*/(π R)))."""
    return b.elastic_modulus / (2.0 * (1.0 - b.poisson_ratio ** 2))


def _lundberg(b, x):
    l, D = b.roller_length, b.roller_diameter
    E = reduced_modulus(b)
    Qd = b.profile.design_load
    R = 1.0 / (2.0 / D + 1.0 / b.inner_raceway_radius)
    a = math.sqrt(4.0 * Qd * R / (math.pi * l * E))
    k = 1.0 - LUNDBERG_END_COEFFICIENT * a / (0.5 * l)
    if not k > 0.0:
        raise ValueError(f"bearing.profile.design_load: the Hertz half-width at {Qd:g} N ({a * 1e3:.3g} mm) "
                         f"exceeds l/(2·0.3033); expected a smaller design load")
    return Qd / (math.pi * l * E) * -np.log1p(-k * (2.0 * x / l) ** 2)


def _crowned(b, x):
    l, lf, h = b.roller_length, b.profile.flat_length, b.profile.crown_drop
    if not lf <= l:
        raise ValueError(f"bearing.profile.flat_length: expected <= roller_length ({l * 1e3:g} mm), got {lf * 1e3:g} mm")
    c = 0.5 * (l - lf)
    if h == 0.0 or c == 0.0:
        return np.zeros_like(x)
    Rc = (c * c + h * h) / (2.0 * h)
    s = np.clip(np.abs(x) - 0.5 * lf, 0.0, c)
    return s * s / (Rc + np.sqrt(Rc * Rc - s * s))          # R_c − sqrt(R_c² − s²) without the cancellation


def _table(b, x):
    pts = b.profile.points
    if len(pts) < 2:
        raise ValueError(f"bearing.profile.points: a table profile needs >= 2 points, got {len(pts)}")
    xs = np.array([p.x for p in pts])
    ps = np.array([p.drop for p in pts])
    if np.any(np.diff(xs) <= 0.0):
        raise ValueError("bearing.profile.points: expected x strictly increasing [m]")
    return np.interp(np.abs(x) if xs[0] >= 0.0 else x, xs, ps)


def roller_drop(b, x) -> np.ndarray:
    """P(x) [m] of the bearing ``b`` (:class:`~components.params.BearingSI`) at axial positions ``x`` [m] from the
    roller centre (the module docstring's laws, chosen by ``b.profile.shape``)."""
    x = np.asarray(x, float)
    if np.any(np.abs(x) > 0.5 * b.roller_length * (1.0 + 1e-12)):
        raise ValueError(f"x: expected |x| <= l/2 = {0.5e3 * b.roller_length:g} mm")
    shape = b.profile.shape
    if shape == "straight":
        return np.zeros_like(x)
    if shape == "crowned":
        return _crowned(b, x)
    if shape == "logarithmic":
        return _lundberg(b, x)
    if shape == "iso_16281":
        u = np.minimum(np.abs(2.0 * x / b.roller_length), ISO_16281_CAP)
        return ISO_16281_PROFILE_COEFFICIENT * b.roller_diameter * -np.log1p(-u * u)
    if shape == "table":
        return _table(b, x)
    raise ValueError(f"bearing.profile.shape: expected one of {list(PROFILES)}, got {shape!r}")
