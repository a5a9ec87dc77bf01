"""A machine's manufacturing errors drawn from stated tolerances: the samples of the tolerance study (docs/tolerances.md).

One sample is one machine. Its errors, each from its tolerance and a stated distribution:

========================  =====================================================================================
teeth (every gear)        ISO 1328-1:2013 flank tolerance class ``flank_class``: every tooth flank's pitch, profile
                          slope and form deviation, normal with the tolerance at 3σ (:mod:`components.tolerances`,
                          ``errors.flank_class``); drawn from a per-sample seed, not from the Sobol point (thousands
                          of teeth: plain Monte Carlo)
runout (every gear)       eccentricity vector (x, y) in the gear's axes, each component normal with
                          σ = F_r / (2 · 3.44): 99.73 % of gears have a total indicator reading 2e ≤ F_r (the
                          Rayleigh quantile √(−2 ln 0.0027) = 3.44); F_r the runout tolerance F_rT = 0.9 F_pT of
                          the flank class (:func:`components.tolerances.radial_runout`)
pinhole (all 2N pins)     radial and tangential position error, each normal with the tolerance ``pinhole`` at 3σ
clearance (each bearing)  diametral clearance uniform in nominal ± ``clearance`` (a band, no shape known inside it);
                          a bearing's clearance deviation ΔP_d is every one of its rollers ΔP_d/2 smaller: the
                          raceway contacts' deflection δ = D/2 − κ(ρ − R) is the same (the rollers' orbit radius
                          differs by ΔP_d/4, < 4 µm of 19.5 mm)
roller (each roller)      diameter uniform within ± ``roller_lot``/2 about its bearing's lot (ISO 3096 / ISO 12297
                          grades: a bearing's rollers from one lot whose diameter variation V_DwL is the grade)
========================  =====================================================================================

The coordinates of one machine (everything but the teeth) are a point of the unit cube, turned into each
distribution by its inverse CDF (``scipy.stats``' ``ppf``). The points are randomised quasi-Monte Carlo
(:func:`sobol_points`, ``scipy.stats.qmc``): R independent scramblings of the Sobol sequence (replicates), machine i
the (i // R)-th point of replicate i mod R. The points of one scrambled sequence are not independent, so a
statistic's interval comes from the spread of its R replicate estimates, which are (:func:`replicate_of`; the
tolerance study's ``--replicates``). The first n machines are the same whatever n is, so a study grown from 64 to
1024 samples keeps its first 64 machines. Two classes draw from the same points (the same machines, their gears
finer or coarser: common random numbers).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import norm, qmc

from .tolerances import radial_runout
from .units import ParameterError

__all__ = ["ToleranceSpec", "TOLERANCE_DEFAULTS", "DISTRIBUTIONS", "RUNOUT_SIGMAS", "coordinates", "sobol_points",
           "replicate_of",
           "teeth_seed", "draw_errors", "pin_names", "gear_names_of"]

# the Rayleigh quantile that 99.73 % of gears stay within (the 3σ coverage of a normal, in 2-D)
RUNOUT_SIGMAS = math.sqrt(-2.0 * math.log(0.0027))

# The tolerances a study draws from unless told otherwise: (value as a user types it, source tag, basis).
TOLERANCE_DEFAULTS = {
    "classes": ("5,7", "[assumed]", "a ground (5) and a good shaved/hobbed (7) gear quality"),
    "pinhole": ("10 um", "[assumed]", "a precision carrier's pinhole position tolerance, of the order Bodas & "
                                      "Kahraman (2004) study (the spectrum's typical errors use the same ±10 µm)"),
    "clearance": ("5 um", "[assumed]", "planet bearings without rings: the clearance is set at assembly by matching "
                                       "roller lots to bore and pin, a band narrower than an ISO 5753-1 group (those "
                                       "are 25 µm wide for this size: C2 0–25 µm for a 24–30 mm bore, 5–30 µm for "
                                       "30–40 mm; the pin raceway is 31.5 mm). Half a group, ±12.5 µm about the "
                                       "reference 20 µm, reaches clearances at which the static solution does not "
                                       "converge at condition 3 (>= 28 µm; docs/tolerances.md)"),
    "roller_lot": ("2 um", "[assumed]", "roller grade G2: the rollers of a bearing from one lot whose diameter "
                                        "variation V_DwL is 2 µm (ISO 3096 / ISO 12297 grade G2; SKF's needle "
                                        "rollers of grade G2 are sorted in 2 µm gauges)"),
    "systematic_share": (0.5, "[assumed]", "ground gears: half the profile deviations' variance common to a "
                                           "flank's teeth (one grinding set-up), as components.presets.typical_errors"),
}

# the distributions in words (answer.md, docs/tolerances.md)
DISTRIBUTIONS = {
    "teeth": "ISO 1328-1:2013 flank class per gear: pitch, profile slope and form deviation per tooth flank, "
             "normal with the tolerance at 3σ (components.tolerances), a per-sample seed",
    "runout": "eccentricity vector per gear, each component normal, σ = F_r/(2·3.44): 99.73 % within the "
              "runout tolerance F_rT = 0.9 F_pT of the flank class (ISO 1328-1:2013)",
    "pinhole": "radial and tangential position per pin (all 2N), each normal with the tolerance at 3σ",
    "clearance": "diametral clearance per bearing, uniform in nominal ± the tolerance",
    "roller": "diameter per roller, uniform within ± half the lot's diameter variation",
}


@dataclass(frozen=True)
class ToleranceSpec:
    """The tolerances of one machine class. Lengths in m."""
    flank_class: int            # ISO 1328-1:2013 flank tolerance class 1..11 (its runout tolerance F_rT = 0.9 F_pT)
    pinhole: float              # pin position tolerance per component, ± at 3σ
    clearance: float            # half-width of each bearing's diametral clearance band about the nominal
    roller_lot: float           # diameter variation V_DwL of a bearing's rollers (its lot)
    systematic_share: float     # share of the profile deviations' variance common to a flank's teeth

    def __post_init__(self):
        if not (isinstance(self.flank_class, (int, np.integer)) and 1 <= self.flank_class <= 11):
            raise ParameterError.at("flank_class", f"ISO 1328-1 flank tolerance class must be a whole number 1..11, "
                                                   f"got {self.flank_class!r}")
        for k in ("pinhole", "clearance", "roller_lot"):
            v = getattr(self, k)
            if not (np.isfinite(v) and v >= 0.0):
                raise ParameterError.at(k, f"must be a length >= 0 m, got {v!r}")
        if not 0.0 <= self.systematic_share <= 1.0:
            raise ParameterError.at("systematic_share", f"must be in [0, 1], got {self.systematic_share!r}")


def pin_names(N: int) -> list[str]:
    return [f"a{n + 1}" for n in range(N)] + [f"b{n + 1}" for n in range(N)]


def gear_names_of(N: int) -> list[str]:
    return ["sun", "ring", *pin_names(N)]


def coordinates(N: int, Z: int) -> list[str]:
    """The names of a machine's unit-cube coordinates, in order (N planets per row, Z rollers per bearing)."""
    out = []
    for g in gear_names_of(N):
        out += [f"runout_{g}_x", f"runout_{g}_y"]
    for p in pin_names(N):
        out += [f"pinhole_{p}_radial", f"pinhole_{p}_tangential"]
    out += [f"clearance_{p}" for p in pin_names(N)]
    out += [f"roller_{p}_{k}" for p in pin_names(N) for k in range(Z)]
    return out


def replicate_of(sample, replicates: int):
    """The replicate (independent scrambling) that machine ``sample`` belongs to (module docstring)."""
    return np.asarray(sample) % int(replicates)


def sobol_points(n: int, d: int, seed: int, replicates: int) -> np.ndarray:
    """(n, d) points of the unit cube: machine i is the (i // R)-th point of the scrambled Sobol sequence of replicate
    i mod R (``replicates`` = R independent scramblings from ``seed``; each drawn as a power of two, so its balance
    holds and any n keeps the same first points)."""
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ParameterError.at("samples", f"must be a whole number >= 1, got {n!r}")
    if not (isinstance(replicates, (int, np.integer)) and replicates >= 1):
        raise ParameterError.at("replicates", f"must be a whole number >= 1, got {replicates!r}")
    R = int(replicates)
    u = np.empty((n, d))
    for r in range(min(R, n)):
        count = len(range(r, n, R))
        m = max(0, math.ceil(math.log2(count)))
        seq = np.random.default_rng(np.random.SeedSequence([int(seed), r]))
        u[r::R] = qmc.Sobol(d, scramble=True, seed=seq).random_base2(m)[:count]
    # a scrambled point is never exactly 0 or 1 in exact arithmetic; keep the inverse CDFs finite all the same
    return np.clip(u, 1e-12, 1.0 - 1e-12)


def teeth_seed(seed: int, sample: int) -> int:
    """The seed of sample ``sample``'s teeth (``errors.flank_class``): one stream per study seed and sample."""
    return int(np.random.SeedSequence([int(seed), int(sample)]).generate_state(1)[0])


def _uniform(u, half):
    """The inverse CDF of the uniform distribution on [−half, half] (half = 0: exactly 0)."""
    return (2.0 * np.asarray(u, float) - 1.0) * half


def draw_errors(si, spec: ToleranceSpec, u, tooth_seed: int) -> tuple[dict, dict]:
    """(overrides, drawn) of one machine: ``overrides`` the ``errors.*`` entries (dotted key -> list of entries,
    lengths as strings with their unit: plain data for any worker), ``drawn`` the drawn values by name for a table
    (µm, degrees). ``si``: the nominal machine's SI parameters; ``u``: its point of the unit cube
    (:func:`coordinates` order)."""
    N, Z = si.layout.planets, si.bearing.rollers
    names = coordinates(N, Z)
    u = np.asarray(u, float)
    if u.shape != (len(names),):
        raise ParameterError.at("u", f"expects {len(names)} coordinates for N = {N}, Z = {Z}, got shape {u.shape}")
    at = dict(zip(names, u))
    m = lambda x: f"{x:.17g} m"
    drawn: dict[str, float] = {"teeth_seed": tooth_seed}
    runout = []
    for g in gear_names_of(N):
        gear = si.gears[{"sun": "sun", "ring": "ring"}.get(g, "inner_planet" if g[0] == "a" else "outer_planet")]
        sigma = radial_runout(gear.module, 2.0 * gear.pitch_radius, spec.flank_class) / (2.0 * RUNOUT_SIGMAS)
        x, y = norm.ppf([at[f"runout_{g}_x"], at[f"runout_{g}_y"]]) * sigma
        e, phase = float(np.hypot(x, y)), float(np.arctan2(y, x))
        runout.append({"gear": g, "eccentricity": m(e), "phase": f"{phase:.17g} rad"})
        drawn[f"runout_{g}_um"], drawn[f"runout_{g}_phase_deg"] = 1e6 * e, math.degrees(phase)
    pinhole = []
    for p in pin_names(N):
        r, t = norm.ppf([at[f"pinhole_{p}_radial"], at[f"pinhole_{p}_tangential"]]) * (spec.pinhole / 3.0)
        pinhole.append({"planet": p, "radial": m(r), "tangential": m(t)})
        drawn[f"pinhole_{p}_radial_um"], drawn[f"pinhole_{p}_tangential_um"] = 1e6 * r, 1e6 * t
    rollers = []
    for p in pin_names(N):
        dP = float(_uniform(at[f"clearance_{p}"], spec.clearance))
        dev = _uniform(np.array([at[f"roller_{p}_{k}"] for k in range(Z)]), 0.5 * spec.roller_lot)
        dev = dev - 0.5 * dP             # a larger clearance: every roller of the bearing that much smaller
        rollers += [{"planet": p, "roller": k, "deviation": m(float(x))} for k, x in enumerate(dev) if x != 0.0]
        drawn[f"clearance_{p}_um"] = 1e6 * (si.bearing.clearance + dP)
        drawn[f"roller_{p}_range_um"] = 1e6 * float(np.ptp(dev))
    overrides = {"errors.runout": runout, "errors.pinhole": pinhole, "errors.roller_diameter": rollers,
                 "errors.flank_class": [{"gear": "all", "grade": int(spec.flank_class), "seed": int(tooth_seed),
                                         "systematic_share": float(spec.systematic_share)}]}
    return overrides, drawn
