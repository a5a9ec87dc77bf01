"""Spectra for the scenarios, and the housing sensor's signals of a recorded run (the statistics of a run live in
components.outputs)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy import signal

from components.families import MESH_FAMILY
from components.results import json_attr, read_results
from components.sensor import paths as sensor_path_signals, sensor_from_dict

__all__ = ["amplitude_spectrum", "peak_table", "band_floor", "carrier_orders", "line_table", "sideband_resolution",
           "MIN_REVOLUTIONS", "tooth_cycle", "sensor_paths", "sensor_signal", "whole_revolutions"]

# carrier revolutions a spectrum needs to tell the f_c sidebands from the band's floor: N revolutions put N bins
# between two carrier orders, of which each order's Hann main lobe fills three; from 4 on the floor has bins of its own
MIN_REVOLUTIONS = 4


def amplitude_spectrum(t: np.ndarray, x: np.ndarray, detrend: bool = True):
    """One-sided amplitude spectrum with a Hann window (amplitude-corrected: a sine of amplitude A
    reads A at its bin). Samples must be equally spaced. Returns (frequency_hz, amplitude, df).

    :func:`scipy.signal.periodogram` with ``scaling="spectrum"`` gives the power of each bin over the window's
    coherent gain squared, (Σw)²; the amplitude is √(2P) (√P at 0 Hz, 2√P at the Nyquist bin of an even record,
    where the one-sided periodogram does not double). The window is the periodic Hann (period n, not n − 1): a line
    on a bin then spreads to its two neighbours only (A/2 each), exactly, so a line the record holds a whole number
    of periods of leaks nowhere else (the symmetric window leaks ~1e-4 of it to every bin, which hid lines planet
    phasing cancels)."""
    t = np.asarray(t, float)
    x = np.asarray(x, float)
    dt = np.median(np.diff(t))
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-12):
        raise ValueError("amplitude_spectrum needs equally spaced samples")
    n = x.size
    f, power = signal.periodogram(x, fs=1.0 / dt, window=signal.get_window("hann", n, fftbins=True),
                                  detrend="constant" if detrend else False, scaling="spectrum")
    amp = np.sqrt(2.0 * power)
    amp[0] = np.sqrt(power[0])
    if n % 2 == 0:
        amp[-1] = 2.0 * np.sqrt(power[-1])
    return f, amp, 1.0 / (n * dt)


def peak_table(f: np.ndarray, amp: np.ndarray, centre: float, span: float, expected: dict[str, float], n: int = 8):
    """The n strongest local maxima within centre ± span, each with the nearest expected frequency
    (label, its frequency, distance in Hz and in bins)."""
    df = f[1] - f[0]
    sel = np.flatnonzero((f >= centre - span) & (f <= centre + span))
    if sel.size < 3:
        return []
    a = amp[sel]
    is_peak = np.r_[False, (a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:]), False]
    idx = sel[is_peak]
    idx = idx[np.argsort(amp[idx])[::-1][:n]]
    rows = []
    for i in idx:
        lab = min(expected, key=lambda k: abs(expected[k] - f[i])) if expected else ""
        fe = expected.get(lab, np.nan)
        rows.append({"frequency_hz": float(f[i]), "amplitude": float(amp[i]), "nearest": lab,
                     "expected_hz": float(fe), "distance_hz": float(f[i] - fe),
                     "distance_bins": float((f[i] - fe) / df)})
    return rows


def band_floor(f: np.ndarray, amp: np.ndarray, band: tuple[float, float], lines) -> float:
    """The spectrum's floor in ``band`` [lo, hi]: the median amplitude of its bins outside the Hann main lobe
    (|f − f_l| < 2 bins) of every frequency of ``lines`` — the lines compared against it. A line on a bin fills its
    bin and half of each neighbour and is exactly zero from two bins on (the periodic Hann window), so the floor
    holds none of it: what it measures is what lies between the lines (other lines, the leakage of lines off the
    bins, broadband content). NaN when no bin is left (a record of fewer than :data:`MIN_REVOLUTIONS` carrier
    revolutions, whose band the carrier orders' main lobes fill)."""
    f, amp = np.asarray(f, float), np.asarray(amp, float)
    df = f[1] - f[0]
    keep = (f >= band[0]) & (f <= band[1])
    for fl in lines:
        keep &= np.abs(f - fl) >= 2.0 * df * (1.0 - 1e-9)
    return float(np.median(amp[keep])) if keep.any() else float("nan")


def carrier_orders(f_m: float, f_c: float, band: tuple[float, float]) -> list[float]:
    """Every line f_m + k f_c (k an integer) within ``band``: the carrier orders around the mesh frequency."""
    k = np.arange(np.ceil((band[0] - f_m) / f_c - 1e-9), np.floor((band[1] - f_m) / f_c + 1e-9) + 1)
    return (f_m + k * f_c).tolist()


def line_table(f: np.ndarray, amp: np.ndarray, lines: dict[str, float], band: tuple[float, float],
               between=None) -> list[dict]:
    """Each expected line: its amplitude (its bin; for a line between bins, the larger of the two that
    bracket it — a Hann window spreads such a line over both) and that amplitude over the band's floor
    (:func:`band_floor`: the median of the bins of [lo, hi] outside the main lobes of ``between``, default the
    lines themselves; NaN when none is left)."""
    f, amp = np.asarray(f, float), np.asarray(amp, float)
    df = f[1] - f[0]
    floor = band_floor(f, amp, band, lines.values() if between is None else between)
    rows = []
    for label, fl in lines.items():
        x = (fl - f[0]) / df
        lo, hi = (round(x),) * 2 if abs(x - round(x)) < 1e-6 else (int(np.floor(x)), int(np.ceil(x)))
        a = float(max(amp[lo], amp[hi])) if 0 <= lo and hi < f.size else float("nan")
        over = (a / floor if floor > 0 else float("inf") if a > 0 else float("nan")) if np.isfinite(floor) \
            else float("nan")     # nan: a signal that is 0, or no floor
        rows.append({"line": label, "frequency_hz": float(fl), "amplitude": a, "over_median": over})
    return rows


def sideband_resolution(t: np.ndarray, f_c: float) -> str | None:
    """Why a spectrum of the samples ``t`` cannot show the carrier sidebands f_m + k f_c, or None when it can. Over
    fewer than :data:`MIN_REVOLUTIONS` carrier revolutions the main lobes of the carrier orders (three bins each,
    bins f_c/N wide for N revolutions) fill the band: no bin between two lines is left for the floor
    (:func:`band_floor`), and "over the floor" has nothing to compare with (at one revolution every bin is a line)."""
    t = np.asarray(t, float)
    dt = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    span = float(t[-1] - t[0] + dt) if t.size > 1 else 0.0
    revs = span * abs(f_c)
    if revs >= MIN_REVOLUTIONS - 0.5 * dt * abs(f_c):           # whole revolutions to the nearest sample
        return None
    return (f"the spectrum covers {revs:.2g} carrier revolutions (< {MIN_REVOLUTIONS}): its resolution "
            f"{1.0 / span if span > 0 else float('inf'):.3g} Hz cannot tell the f_c = {abs(f_c):.3g} Hz sidebands from "
            f"the floor; its lines mean nothing (a window of at least {MIN_REVOLUTIONS / abs(f_c):.3g} s)")


# ---------------------------------------------------------------------------------------------------------------
# the housing accelerometer of a recorded run (docs/model.md §12): what the spectrum and the fault study read
# ---------------------------------------------------------------------------------------------------------------
def sensor_paths(path: Path, sensor=None) -> tuple[np.ndarray, dict]:
    """(t, {"mesh", "torque", "bearing", "housing"}): the housing accelerometer's paths and their sum [m/s^2] at
    every sample of a run's ``results.nc`` (recorded with ``RunConfig(sensor=True)``), by
    :func:`components.sensor.paths` from the recorded outer planets' angles and ring-mesh forces and the loads on
    the housing. ``sensor`` (:class:`components.params.SensorSI`): the run's own (stored with it) unless given.
    The one place a run's file becomes the sensor's signals: the spectrum and the fault study read through it."""
    fam = MESH_FAMILY["outer_ring"]
    ds = read_results(path, ("time", "motion.position", "motion.angle", "fixed.angle", f"{fam}.fx", f"{fam}.fy",
                             "housing.force_x", "housing.force_y", "housing.torque"))
    if "housing.force_x" not in ds:
        raise ValueError(f"{path}: the run recorded no loads on the housing (run it with RunConfig(sensor=True))")
    sensor = sensor if sensor is not None else sensor_from_dict(json_attr(ds.attrs, "sensor", path))
    t = ds["time"]
    bodies = list(ds["motion.body"])
    phi = (ds["fixed.angle"][:, list(ds["fixed.body"]).index("carrier")]
           - ds["motion.angle"][:, bodies.index("carrier")])                   # the frame's angle
    P = ds["motion.position"][:, [bodies.index(g) for g in ds[f"{fam}.gear1"]]]
    psi = np.arctan2(P[..., 1], P[..., 0]) + phi[:, None]
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    fx, fy = ds[f"{fam}.fx"], ds[f"{fam}.fy"]                                   # on the ring, in R
    ring = np.stack([c * fx - s * fy, s * fx + c * fy], axis=-1)
    force = np.column_stack([ds["housing.force_x"].sum(axis=1), ds["housing.force_y"].sum(axis=1)])
    torque = ds["housing.torque"].sum(axis=1)
    return t, sensor_path_signals(t, psi, ring, force, torque, sensor)


def sensor_signal(path: Path, f_c: float, sensor: str = "housing", cycle: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(t, a) of a run's housing sensor (or one of its paths, :func:`sensor_paths`) over the first whole number
    of carrier revolutions, of ``cycle`` revolutions where it can (:func:`whole_revolutions`): what every spectrum
    of the sensor is taken of."""
    t, signals = whole_revolutions(*sensor_paths(Path(path)), f_c, cycle)
    return t, signals[sensor]


def tooth_cycle(ring_teeth: int, planet_teeth) -> int:
    """Carrier revolutions after which every planet's teeth meet the ring's teeth as at the start: a planet of z_p
    teeth turns relative to the carrier at z_r/z_p carrier orders (its tooth errors' lines lie at multiples of
    it), a whole number after z_p/gcd(z_p, z_r) revolutions; the least common multiple over the planets.
    Reference machine: z_r = 82, z_p = 24 → 12 revolutions (the planets' lines at 41/12 orders). The sun's
    (z_s/gcd(z_s, z_r): 31 for z_s = 31) is left out: the whole train repeats only after lcm = 372 revolutions."""
    return math.lcm(*(int(z) // math.gcd(int(z), int(ring_teeth)) for z in planet_teeth))


def whole_revolutions(t, signals: dict, f_c: float, cycle: int = 1):
    """The first whole number of carrier revolutions of the samples (all of them if less than one), a multiple of
    ``cycle`` revolutions where the record holds one (:func:`tooth_cycle`): the lines f_m + k f_c then fall on
    frequency bins, and the Hann window's leakage stays within ±1 bin — with whole tooth cycles, the planets' tooth
    errors' lines too."""
    dt, fc = float(np.median(np.diff(t))), abs(f_c)
    revs = np.floor(len(t) * dt * fc + 1e-9) if fc > 0 else 0.0
    if revs >= cycle > 1:
        revs = cycle * np.floor(revs / cycle)
    n = min(int(round(revs / (fc * dt))), len(t)) if revs >= 1 else len(t)
    return t[:n], {k: x[:n] for k, x in signals.items()}
