"""Gear accuracy: ISO 1328 tolerances and tooth deviations drawn for a tolerance class.

ISO 1328-1:2013 (flank tolerance classes 1..11; §5.3, Formulas (5)–(9)), with m the normal module and d the
reference diameter in mm, values in µm at class A:

    f_pT  = (0.001 d + 0.4 m + 5)              · √2^(A−5)     single pitch
    F_pT  = (0.002 d + 0.55 √d + 0.7 m + 12)  · √2^(A−5)     total cumulative pitch
    f_HαT = (0.4 m + 0.001 d + 4)              · √2^(A−5)     profile slope
    f_fαT = (0.55 m + 5)                       · √2^(A−5)     profile form
    F_αT  = √(f_HαT² + f_fαT²)                                total profile

The standard rounds published values (§5.2.3); the draws here use the unrounded ones. Its range of
application is 5 ≤ z ≤ 1000, 5 mm ≤ d ≤ 15 000 mm, 0.5 mm ≤ m ≤ 70 mm.

Draws (:func:`draw_teeth`), per gear and per flank face, normal with the tolerance at 3σ (a process
capability C_p = 1: 99.7 % of the teeth within the class):

- position (cumulative pitch) deviation of each flank independent, σ = f_pT/(3√2), so that the single
  pitch deviations f_pt — differences of neighbours — have σ = f_pT/3. The long-wave part of the
  cumulative pitch (eccentricity) is the runout error, a separate entry (:func:`radial_runout`).
- profile slope and form deviation: σ = f_HαT/3 and f_fαT/3 per tooth, a share ``systematic`` of the
  variance common to every tooth of that flank face (one grinding set-up), the rest tooth to tooth; the
  form deviation is a barrel of signed range (``ToothDeviationParams``).

The runout of :func:`radial_runout` is ISO 1328-2:1997 Annex B's F_r = 0.8 F_p with ISO 1328-1:1995's
F_p = (0.3 m + 1.25 √d + 7) √2^(Q−5) µm (grades 1..12).
"""
from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np

from .units import ParameterError

__all__ = ["FlankTolerances", "flank_tolerances", "radial_runout", "draw_teeth"]


@dataclass(frozen=True)
class FlankTolerances:
    """ISO 1328-1:2013 flank tolerances of one gear [m], unrounded."""
    single_pitch: float          # f_pT
    total_pitch: float           # F_pT
    profile_slope: float         # f_HαT
    profile_form: float          # f_fαT

    @property
    def profile_total(self) -> float:
        """F_αT = √(f_HαT² + f_fαT²)."""
        return math.hypot(self.profile_slope, self.profile_form)


def flank_tolerances(module: float, diameter: float, grade: int) -> FlankTolerances:
    """ISO 1328-1:2013 tolerances of class ``grade`` (1..11) for normal module and reference diameter [m]."""
    if not (isinstance(grade, (int, np.integer)) and 1 <= grade <= 11):
        raise ParameterError.at("grade", f"ISO 1328-1:2013 flank tolerance class must be an integer 1..11, got {grade!r}")
    m, d = 1e3 * module, 1e3 * diameter
    step = math.sqrt(2.0) ** (grade - 5)
    um = 1e-6 * step
    return FlankTolerances(single_pitch=(0.001 * d + 0.4 * m + 5.0) * um,
                           total_pitch=(0.002 * d + 0.55 * math.sqrt(d) + 0.7 * m + 12.0) * um,
                           profile_slope=(0.4 * m + 0.001 * d + 4.0) * um,
                           profile_form=(0.55 * m + 5.0) * um)


def radial_runout(module: float, diameter: float, grade: int) -> float:
    """Radial runout tolerance F_r [m] of ISO 1328 accuracy ``grade`` (module, reference diameter in m):
    ISO 1328-2:1997 Annex B, F_r = 0.8 F_p, with ISO 1328-1:1995's F_p at grade 5 × √2 per grade."""
    if not (isinstance(grade, (int, np.integer)) and 1 <= grade <= 12):
        raise ParameterError.at("grade", f"ISO 1328 accuracy grade must be an integer 1..12, got {grade!r}")
    m, d = 1e3 * module, 1e3 * diameter
    F_p = (0.3 * m + 1.25 * d ** 0.5 + 7.0) * 2.0 ** (0.5 * (grade - 5))
    return 0.8 * F_p * 1e-6


def draw_teeth(name: str, teeth: int, tol: FlankTolerances, seed: int, systematic: float) -> dict:
    """Deviations of every tooth flank of gear ``name`` (module docstring): {"pitch", "slope", "form"}, each
    (teeth, 2) [m] for faces (ccw, cw). The stream depends on the seed and the gear's name only, so every
    gear (every planet) draws its own teeth and adding a gear changes no other's."""
    rng = np.random.default_rng([int(seed), zlib.crc32(name.encode())])
    z = int(teeth)

    def profile(sigma):
        common = rng.normal(0.0, sigma * math.sqrt(systematic), (1, 2))
        return common + rng.normal(0.0, sigma * math.sqrt(1.0 - systematic), (z, 2))

    pitch = rng.normal(0.0, tol.single_pitch / (3.0 * math.sqrt(2.0)), (z, 2))
    slope = profile(tol.profile_slope / 3.0)
    form = profile(tol.profile_form / 3.0)
    return {"pitch": pitch, "slope": slope, "form": form}
