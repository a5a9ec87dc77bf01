"""summary.json, typed: what a run's summary holds, the words and units of its keys, and the failed-run form.

A :class:`Summary` *is* the file's mapping (a ``dict``: ``json.dumps`` writes it unchanged, ``s["inner"]`` reads it
as before), with typed access on top: the bearing kinds' sections (:attr:`Summary.inner`, :meth:`Summary.bearing`),
the mesh types' (:attr:`Summary.meshes`), each a :class:`Section` whose :meth:`~Section.quantity` gives a value with
its unit and words; :attr:`Summary.failed` instead of ``"error" in s``; :meth:`Summary.failure` for a run that failed.

The words and units of every statistic (:data:`SUMMARY_WORDS`) are owned here; :mod:`components.statistics` computes
the statistics, :mod:`components.outputs` re-exports the table. Imports nothing of the project (viz reads through it without the engine).
"""
from __future__ import annotations

import numpy as np

from collections.abc import Iterator, Mapping, MutableMapping
from typing import Any, NamedTuple

__all__ = ["Summary", "Section", "Quantity", "BEARING_KINDS", "SUMMARY_WORDS", "UNIT_SUFFIXES", "DIMENSIONLESS_KEYS",
           "unit_of_key", "describe_key"]

BEARING_KINDS = ("inner", "outer")     # a summary's per-bearing-kind sections (the planet bearings of each planet row)

# what each summary key means, in words and units (for tables and plot axes; README: What summary.json holds).
# Every key of :meth:`WindowStatistics.summary` is here. A key with a unit ends in its suffix (UNIT_SUFFIXES);
# a key without one is dimensionless ("1": a count, a ratio, a factor) and is listed in DIMENSIONLESS_KEYS.
UNIT_SUFFIXES = {"_N": "N", "_m": "m", "_m_s": "m/s", "_m_s2": "m/s^2", "_s": "s", "_h": "h", "_W": "W", "_pct": "%",
                 "_Mrev": "10^6 rev", "_hz": "Hz", "_rpm": "r/min", "_rad": "rad", "_W_m2": "W/m^2",
                 "_MB": "MiB", "_arcmin": "arcmin"}


def _cage_acc_words() -> dict:
    views = {"": "cage acc.", "rel_": "cage acc. rel. planet"}
    stats = {"rms": "RMS", "max": "max"}
    out = {f"cage_acc_{v}{c}_{s}_m_s2": (f"{w} {stats[s]}, {c}", "m/s^2")
           for v, w in views.items() for c in ("radial", "tangential", "magnitude") for s in stats}
    out.update({f"cage_acc_{c}_rms_m_s2": (f"cage acc. rel. planet RMS, {c} (model axes)", "m/s^2") for c in ("x", "y")})
    return out


SUMMARY_WORDS = {
    "window_s": ("statistics window, start and end", "s"),
    "window_duration_s": ("length of the mesh statistics window", "s"),
    "carrier_speed_error_mean_pct": ("carrier speed against its drive's reference, time mean", "%"),
    "whole_revolutions": ("bearing windows end after whole cage revolutions", "1"),
    "bearing_load_mean_N": ("planet bearing load, mean", "N"),
    "bearing_load_mean_all_N": ("planet bearing load, mean of the bearings of the type", "N"),
    "bearing_load_mean_per_planet_N": ("planet bearing load, mean, per planet", "N"),
    "bearing_load_radial_mean_N": ("planet bearing load, mean, radial", "N"),
    "bearing_load_tangential_mean_N": ("planet bearing load, mean, tangential", "N"),
    "bearing_load_max_N": ("planet bearing load, max", "N"),
    "bearing_load_max_per_planet_N": ("planet bearing load, max, per planet", "N"),
    "load_sharing_factor": ("load sharing K_γ: most loaded planet over the mean", "1"),
    "equivalent_load_N": ("planet bearing equivalent load (ISO 281)", "N"),
    "dynamic_load_rating_N": ("basic dynamic load rating C_r (ISO 281)", "N"),
    "minimum_load_N": ("catalogue minimum load of the bearing, 0.02 C_r (SKF's rule for roller bearings)", "N"),
    "load_over_minimum": ("planet bearing load, mean, over the catalogue minimum load", "1"),
    "load_over_minimum_per_planet": ("planet bearing load, mean, over the catalogue minimum load, per planet", "1"),
    "roller_slip_load_zone_pct": ("roller slip in the load zone, mean of the type's rollers", "%"),
    "roller_slip_unloaded_pct": ("roller slip out of the load zone, mean of the type's rollers", "%"),
    "roller_loaded_share": ("share of the time a roller is loaded on the pin", "1"),
    "roller_entries": ("load-zone entries of the type's rollers in the window", "1"),
    "roller_slip_entry_pct": ("roller slip at load-zone entry, mean", "%"),
    "roller_entry_slide_roll": ("slide-to-roll ratio on the pin at load-zone entry", "1"),
    "smearing_pv_entry_W_m2": ("frictional power density p·Δv on the pin at load-zone entry, mean", "W/m^2"),
    "smearing_pv_max_W_m2": ("frictional power density p·Δv of a roller contact, largest", "W/m^2"),
    "misalignment_mean_rad": ("slope the bearing sees (pin against planet bore), time mean", "rad"),
    "misalignment_max_rad": ("slope the bearing sees (pin against planet bore), max", "rad"),
    "misalignment_mean_per_planet_rad": ("slope the bearing sees (pin against planet bore), time mean, per planet",
                                         "rad"),
    "pin_slope_mean_arcmin": ("elastic pin's bending slope against its pinhole, time mean", "arcmin"),
    "pin_slope_max_arcmin": ("elastic pin's bending slope against its pinhole, max", "arcmin"),
    "pin_slope_mean_per_planet_arcmin": ("elastic pin's bending slope against its pinhole, time mean, per planet",
                                         "arcmin"),
    "pin_slope_max_per_planet_arcmin": ("elastic pin's bending slope against its pinhole, max, per planet", "arcmin"),
    "pin_deflection_mean_m": ("elastic pin's deflection at its bearing's centre, time mean", "m"),
    "pin_deflection_max_m": ("elastic pin's deflection at its bearing's centre, max", "m"),
    "life_L10_relative": ("L10 life relative to forward", "1"),
    "life_iso281_Mrev": ("L10 life, ISO 281 from the bearing load", "10^6 rev"),
    "life_iso281_h": ("L10 life, ISO 281 from the bearing load", "h"),
    "life_iso16281_Mrev": ("L10 life, ISO/TS 16281-style from the roller loads", "10^6 rev"),
    "life_iso16281_h": ("L10 life, ISO/TS 16281-style from the roller loads", "h"),
    "life_iso281_per_planet_h": ("L10 life, ISO 281 from the bearing load, per planet", "h"),
    "life_iso16281_per_planet_h": ("L10 life, ISO/TS 16281-style from the roller loads, per planet", "h"),
    "roller_equivalent_load_pin_N": ("equivalent roller load on the pin (ISO/TS 16281)", "N"),
    "roller_equivalent_load_bore_N": ("equivalent roller load on the bore (ISO/TS 16281)", "N"),
    "roller_inner_race_rms_N": ("roller–inner race load RMS", "N"),
    "roller_inner_race_max_N": ("roller–inner race load max", "N"),
    "roller_inner_race_mean_N": ("roller–inner race load mean", "N"),
    "roller_inner_race_mean_spread": ("spread of the rollers' mean inner-race loads, (max − min)/mean", "1"),
    "roller_outer_race_rms_N": ("roller–outer race load RMS", "N"),
    "roller_outer_race_max_N": ("roller–outer race load max", "N"),
    "roller_outer_race_mean_N": ("roller–outer race load mean", "N"),
    "roller_cage_rms_N": ("roller–cage force RMS", "N"),
    "roller_cage_max_N": ("roller–cage force max", "N"),
    "cage_guide_rms_N": ("cage–guide force RMS", "N"),
    "cage_guide_max_N": ("cage–guide force max", "N"),
    "cage_guide_mean_N": ("cage–guide force mean", "N"),
    **_cage_acc_words(),
    "cage_slip_pct": ("cage slip", "%"),
    "cage_slip_all_pct": ("cage slip, mean of the bearings of the type", "%"),
    "cage_revolutions": ("cage revolutions relative to the carrier in the window", "1"),
    "pocket_impacts": ("pocket impacts in the window, all bearings of the type", "1"),
    "pocket_impacts_per_rev": ("pocket impacts per bearing and cage revolution (all its rollers)", "1"),
    "pocket_touches_per_rev": ("gentle pocket contacts (below the impact speed floor) per bearing and cage revolution",
                               "1"),
    "pocket_impact_speed_max_m_s": ("pocket impact speed max", "m/s"),
    "pocket_impact_speed_mean_m_s": ("pocket impact speed mean", "m/s"),
    "pocket_impact_peak_max_N": ("pocket impact peak force max", "N"),
    "pocket_impact_peak_mean_N": ("pocket impact peak force mean", "N"),
    "heat_traction_W": ("heat from roller–raceway traction, mean", "W"),
    "heat_traction_all_W": ("heat from roller–raceway traction, mean of the bearings of the type", "W"),
    "heat_land_W": ("heat from the cage land's friction, mean", "W"),
    "heat_land_all_W": ("heat from the cage land's friction, mean of the bearings of the type", "W"),
    "traction_coefficient_max": ("largest traction coefficient of a loaded contact", "1"),
    "film_min_m": ("thinnest EHL film h_min", "m"),
    "film_mean_m": ("thinnest EHL film, time mean", "m"),
    "film_min_isothermal_m": ("thinnest EHL film without the thermal reduction", "m"),
    "lambda_min": ("film parameter Λ = h_min/σ, smallest", "1"),
    "lambda_mean": ("film parameter Λ = h_min/σ, time mean", "1"),
    "film_min_thermal_loading": ("thermal loading L at the thinnest film", "1"),
    "film_thermal_loading_max": ("thermal loading L, largest", "1"),
    "film_thermal_factor_min": ("thermal reduction φ_T, smallest", "1"),
    "film_load_parameter_max": ("load parameter W′ = w′/(E′R), largest", "1"),
    "film_central_ratio_min": ("h_c/h_min, smallest", "1"),
    "drive_flank": ("the flank the torque path loads (+1/−1)", "1"),
    **{f"{f}_force_{s}_N": (f"{f} flank force {s}", "N") for f in ("drive", "coast") for s in ("mean", "max")},
    **{f"{f}_deflection_{s}_m": (f"{f} flank deflection {s}", "m") for f in ("drive", "coast") for s in ("mean", "max")},
    **{f"{f}_force_mean_per_pair_N": (f"{f} flank force mean, per pair", "N") for f in ("drive", "coast")},
    "te_peak_to_peak_m": ("loaded transmission error peak-to-peak, largest pair", "m"),
    "te_peak_to_peak_per_pair_m": ("loaded transmission error peak-to-peak, per pair", "m"),
    "drive_flank_peak_over_mean": ("largest drive-flank force over its mean in the window, largest pair", "1"),
    "drive_flank_peak_over_mean_per_pair": ("largest drive-flank force over its mean in the window, per pair", "1"),
    "dynamic_factor": ("dynamic factor K_v: mean over mesh cycles of each cycle's peak drive-flank force over the "
                       "mean force (whole carrier revolutions), largest pair", "1"),
    "dynamic_factor_per_pair": ("dynamic factor K_v from the mesh cycles' peaks, per pair", "1"),
    "dynamic_factor_p99": ("99th percentile of the drive-flank force over its mean (whole carrier revolutions), "
                           "largest pair", "1"),
    "dynamic_factor_p99_per_pair": ("99th percentile of the drive-flank force over its mean, per pair", "1"),
    "dynamic_factor_window_s": ("window of the dynamic factors: whole carrier revolutions from the window's start",
                                "s"),
    "dynamic_factor_carrier_revolutions": ("whole carrier revolutions in the dynamic factors' window (0: whole "
                                           "mesh cycles only)", "1"),
    "dynamic_factor_mesh_cycles": ("whole mesh cycles in the dynamic factors' window", "1"),
}

# numeric summary keys without a unit (counts, ratios, factors, signs): the only ones without a UNIT_SUFFIXES suffix
DIMENSIONLESS_KEYS = frozenset(k for k, (_, unit) in SUMMARY_WORDS.items() if unit == "1") | {
    # what the runner adds (scenarios.core.runner): counts and the error estimate in units of the tolerance
    "condition", "planets", "rollers", "rows", "samples", "steps", "rejected_steps", "newton_per_step",
    "error_estimate.rms", "error_estimate.max", "integration.alpha"}


def unit_of_key(key: str) -> str | None:
    """The unit a summary key's suffix names (None: no unit suffix)."""
    for suffix in sorted(UNIT_SUFFIXES, key=len, reverse=True):
        if key.endswith(suffix):
            return UNIT_SUFFIXES[suffix]
    return None


def describe_key(key: str) -> tuple[str | None, str | None]:
    """(unit, words) of a summary key: from :data:`SUMMARY_WORDS` when listed, else the unit its suffix names
    ("1" for a listed dimensionless key) and no words; (None, None) for a key neither listed nor suffixed."""
    if key in SUMMARY_WORDS:
        words, unit = SUMMARY_WORDS[key]
        return unit, words
    unit = unit_of_key(key)
    return ("1" if unit is None and key in DIMENSIONLESS_KEYS else unit), None


class Quantity(NamedTuple):
    """A summary value with its unit (None: none claimed) and words (None: not in :data:`SUMMARY_WORDS`)."""
    value: Any
    unit: str | None
    words: str | None


class Section(MutableMapping):
    """One section of a summary (a bearing kind's, a mesh type's): a view of the file's own mapping, so an edit
    (e.g. a relative life filled in by a study) is in the summary that is written back."""
    __slots__ = ("name", "_data")

    def __init__(self, name: str, data: dict):
        if not isinstance(data, dict):
            raise TypeError(f"summary section {name!r} must be a JSON object, got {type(data).__name__}")
        self.name, self._data = name, data

    def __getitem__(self, key):
        return self._data[key]

    def __setitem__(self, key, value) -> None:
        self._data[key] = value

    def __delitem__(self, key) -> None:
        del self._data[key]

    def __iter__(self) -> Iterator:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return f"Section({self.name!r}, {self._data!r})"

    def quantity(self, key: str) -> Quantity:
        """The value of ``key`` with its unit and words (:func:`describe_key`)."""
        if key not in self._data:
            raise KeyError(f"no {key!r} in the summary's {self.name!r} section")
        return Quantity(self._data[key], *describe_key(key))


class Summary(dict):
    """A run's summary.json: the file's mapping itself, with typed sections (module docstring). The failed-run
    form (:meth:`failure`) holds ``case``, ``error`` and, when there is one, ``traceback``."""

    @classmethod
    def of(cls, s: Mapping) -> "Summary":
        """``s`` as a Summary (itself when it is one; a plain mapping's top level copied, its sections shared)."""
        if isinstance(s, cls):
            return s
        if not isinstance(s, Mapping):
            raise TypeError(f"a summary must be a mapping (summary.json's object), got {type(s).__name__}")
        return cls(s)

    @classmethod
    def failure(cls, case: str, error: str, traceback: str = "") -> "Summary":
        """The form of a run that failed: its case label, the error in one line, the traceback when there is one."""
        return cls({"case": case, "error": error, **({"traceback": traceback} if traceback else {})})

    @property
    def failed(self) -> bool:
        """Whether this is a failed run's form (it holds an error, no statistics)."""
        return "error" in self

    @property
    def error(self) -> str | None:
        return self.get("error")

    @property
    def has_bearings(self) -> bool:
        """Whether the run finished with its planet bearings' statistics (every bearing kind's section)."""
        return not self.failed and all(k in self for k in BEARING_KINDS)

    def bearing(self, kind: str) -> Section:
        """The section of a bearing kind ("inner" or "outer")."""
        if kind not in BEARING_KINDS:
            raise ValueError(f"bearing kind must be one of {BEARING_KINDS}, got {kind!r}")
        return self._section(kind)

    @property
    def inner(self) -> Section:
        return self.bearing("inner")

    @property
    def outer(self) -> Section:
        return self.bearing("outer")

    @property
    def meshes(self) -> dict[str, Section]:
        """{mesh type: its section} (empty when the summary has none)."""
        if self.failed:
            self._section("meshes")           # says the run failed
        return {k: Section(k, v) for k, v in (self.get("meshes") or {}).items()}

    @property
    def warnings(self) -> list[str]:
        return self.get("warnings", [])

    def _section(self, name: str) -> Section:
        if name in self:
            return Section(name, self[name])
        if self.failed:
            raise KeyError(f"the summary has no {name!r} section: the run {self.get('case', '')} failed: {self.error}")
        raise KeyError(f"the summary has no {name!r} section")


def percent_change(before, after) -> float | None:
    """(after − before)/before in %, where a percentage means something: both values finite, of the same sign and
    ``before`` not zero; else None (a change of sign, e.g. a cage slip from +0.2 % to −0.3 %, is −250 % of nothing
    in particular: show the two values and their difference in the quantity's unit instead)."""
    if before is None or after is None:
        return None
    before, after = float(before), float(after)
    if not (np.isfinite(before) and np.isfinite(after)) or before == 0.0 or before * after < 0.0:
        return None
    return (after - before) / before * 100.0


RATIO_FROM = 10.0       # a change to ten times the value or more is written as the ratio (format_change)


def format_change(pct: float) -> str:
    """A change in % (:func:`percent_change`) as a reader reads it, the one rule of every table and figure:

    * up to ten times the value: in %, one decimal below 10 %, whole percents above ('+3.2 %', '−24 %', '+598 %'),
      a true minus sign, no sign on a change that rounds to nothing ('0.0 %');
    * ten times the value or more (+900 % and beyond as shown, :data:`RATIO_FROM`): the ratio after/before with
      three significant digits ('×665', '×12.3'; whole numbers from ×1000) — '+66434 %' reads as nothing in
      particular;
    * a fall to a tenth or less (−90 % and beyond): in % with the decimals that keep one significant digit of what
      is left, 100 % + pct, four at most ('−99.6 %' where 0.4 % is left, '−99.96 %' where 0.04 % is); a fall that
      leaves less than 0.00005 % reads '−100 %'."""
    if pct is None or not np.isfinite(float(pct)):
        raise ValueError(f"pct: expected a finite change in %, got {pct}")
    pct = float(pct)
    decimals = 1 if abs(pct) < 9.95 else 0
    left = 100.0 + pct                       # what a fall leaves, in % of the value before
    if 0.0 < left < 10.0:                    # one significant digit of it, four decimals at most
        decimals = min(max(decimals, -int(np.floor(np.log10(left)))), 4)
    text = f"{pct:+.{decimals}f}"
    if 1.0 + float(text) / 100.0 >= RATIO_FROM:      # the digits shown decide the form: +899.5 % shows as ×10
        ratio = max(float(f"{1.0 + pct / 100.0:.3g}"), RATIO_FROM)
        return "\u00d7" + (f"{ratio:.3g}" if ratio < 1000.0 else f"{1.0 + pct / 100.0:.0f}")
    if float(text) == 0.0:                   # a change that rounds to nothing has no sign
        text = f"{0.0:.{decimals}f}"
    elif float(text) == -100.0:              # what is left rounds away: the fall reads whole
        text = "-100"
    return text.replace("-", "\u2212") + " %"
