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

A class is an inspected lot: a gear is shipped only if its measured deviations are within the class, so
:func:`draw_teeth` draws whole gears from the process until one passes (:func:`passes_inspection`; rejection, not
truncation of single teeth: the gear is what is accepted or scrapped, and rejection keeps the process's
tooth-to-tooth correlations inside the shipped gears). Inspection covers every tooth and both flank faces:
the single pitch deviations |f_pt| ≤ f_pT (differences of neighbouring positions about their mean), the
cumulative pitch range F_p ≤ F_pT, every |f_Hα| ≤ f_HαT and |f_fα| ≤ f_fαT. :func:`pass_rate` is the
share of drawn gears that pass.

Pitch deviations are ISO 1328-1 quantities: arcs on the reference circle. A tooth displaced by f_pt moves its
flank along the line of action by f_pt·cos α (the base-pitch deviation of ISO 6336-1); the conversion is made
where the deviations become the mesh law's data (:mod:`components.teeth`). Profile deviations are measured
along the line of action already.

The runout of :func:`radial_runout` is the runout tolerance that belongs with the 2013 flank classes,
F_rT = 0.9 F_pT (ISO 1328-1:2013's runout guidance, identical to ANSI/AGMA 2015-1-A01's), at the flank class of
the same number.
"""
from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np

from .units import ParameterError

__all__ = ["FlankTolerances", "flank_tolerances", "radial_runout", "draw_teeth", "passes_inspection", "pass_rate",
           "MAX_DRAWS"]

# a class the process cannot make: no gear of this many draws passes inspection (a pass rate below 1 / MAX_DRAWS)
MAX_DRAWS = 1000


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
    """Radial runout tolerance F_rT [m] of ISO 1328-1:2013 flank class ``grade`` (module, reference diameter in m):
    F_rT = 0.9 F_pT (module docstring)."""
    return 0.9 * flank_tolerances(module, diameter, grade).total_pitch


def _process(rng, z: int, tol: FlankTolerances, systematic: float) -> dict:
    """One gear from the process (module docstring), before inspection."""
    def profile(sigma):
        common = rng.normal(0.0, sigma * math.sqrt(systematic), (1, 2))
        return common + rng.normal(0.0, sigma * math.sqrt(1.0 - systematic), (z, 2))

    pitch = rng.normal(0.0, tol.single_pitch / (3.0 * math.sqrt(2.0)), (z, 2))
    slope = profile(tol.profile_slope / 3.0)
    form = profile(tol.profile_form / 3.0)
    return {"pitch": pitch, "slope": slope, "form": form}


def passes_inspection(teeth: dict, tol: FlankTolerances) -> bool:
    """Does a gear (:func:`draw_teeth`'s dict) pass its class: every tooth and flank face within f_pT, F_pT, f_HαT,
    f_fαT? Pitch: positions about their mean per face, single pitch = neighbours' difference around the gear."""
    p = teeth["pitch"] - teeth["pitch"].mean(axis=0)
    fpt = p - np.roll(p, 1, axis=0)
    return bool(np.abs(fpt).max() <= tol.single_pitch and np.ptp(p, axis=0).max() <= tol.total_pitch
                and np.abs(teeth["slope"]).max() <= tol.profile_slope and np.abs(teeth["form"]).max() <= tol.profile_form)


def draw_teeth(name: str, teeth: int, tol: FlankTolerances, seed: int, systematic: float) -> dict:
    """Deviations of every tooth flank of a shipped gear ``name`` (module docstring): {"pitch", "slope", "form"},
    each (teeth, 2) [m] for faces (ccw, cw), pitch as an arc on the reference circle, and "draws", how many gears
    the process made until this one passed inspection. The stream depends on the seed and the gear's name only,
    so every gear (every planet) draws its own teeth and adding a gear changes no other's."""
    rng = np.random.default_rng([int(seed), zlib.crc32(name.encode())])
    for n in range(1, MAX_DRAWS + 1):
        d = _process(rng, int(teeth), tol, systematic)
        if passes_inspection(d, tol):
            return {**d, "draws": n}
    raise ParameterError.at("errors.flank_class", f"no gear {name!r} ({int(teeth)} teeth) of {MAX_DRAWS} drawn at the "
                                                  f"class's tolerances at 3σ passes inspection: the process cannot "
                                                  f"make this class for this gear")


def pass_rate(teeth: int, tol: FlankTolerances, systematic: float, gears: int, seed: int) -> float:
    """The share of ``gears`` gears from the process that pass inspection (:func:`passes_inspection`)."""
    rng = np.random.default_rng(int(seed))
    return sum(passes_inspection(_process(rng, int(teeth), tol, systematic), tol) for _ in range(int(gears))) / int(gears)
