"""The spectrum's lines and floor against synthetic signals whose lines and floor are known (docs/faults.md, "The
spectrum's floor"): a sine of amplitude A reads A; white noise of standard deviation σ reads, at the median of the
floor's bins, the Rayleigh median of a Hann-windowed bin, σ √(6 ln 2 / n) (n samples); the machine's tooth-error
lines at non-integer carrier orders stay out of the carrier orders' bins and leave the floor near the noise's on a
record of whole tooth cycles, and fill it on three carrier revolutions."""
from __future__ import annotations

import math

import numpy as np
import pytest

from scenarios.core.analysis import (MIN_REVOLUTIONS, amplitude_spectrum, band_floor, carrier_orders, line_table,
                                     sideband_resolution, tooth_cycle, whole_revolutions)

FS = 20000.0
FC = 2000.0 / 60.0            # the rig's carrier at 2000 r/min
Z_R, Z_S, Z_P = 82, 31, 24    # the reference machine's ring, sun and planets
FM = Z_R * FC


def rayleigh_floor(sigma: float, n: int) -> float:
    """The median amplitude of a bin of white noise (σ) through the amplitude-corrected periodic Hann window of n
    samples: the bin's complex value is circular Gaussian with E|X|² = σ² Σw² (Σw² = 3n/8), the amplitude 2|X|/Σw
    (Σw = n/2) is Rayleigh, its median √(ln 2 · E|X|²)·2/Σw = σ √(6 ln 2 / n)."""
    return sigma * math.sqrt(6.0 * math.log(2.0) / n)


def carrier_lines():
    """Lines at f_m + k f_c, |k| <= 6, of known amplitude (the phasing-allowed orders 1.0, the source's others 0.3)."""
    return {k: (1.0 if (Z_R + k) % 3 == 0 else 0.0) + (0.3 if k in (0, 1, -3, 3) else 0.0) for k in range(-6, 7)}


def synthetic(revs: float, sigma: float, seed: int, tooth: float = 0.0):
    """``revs`` carrier revolutions of the carrier lines, white noise σ and, with ``tooth`` > 0, the planets' (order
    k·z_r/z_p) and the sun's (k·z_r/z_s) tooth-error lines around f_m, |k| <= 2, of amplitude ``tooth``."""
    n = int(round(revs / FC * FS))
    t = np.arange(n) / FS
    x = sum(a * np.cos(2 * np.pi * (FM + k * FC) * t + 0.3 * k) for k, a in carrier_lines().items())
    for j in (-2, -1, 1, 2):
        x = x + tooth * np.cos(2 * np.pi * (FM + j * Z_R / Z_P * FC) * t + j)
        x = x + tooth * np.cos(2 * np.pi * (FM + j * Z_R / Z_S * FC) * t + 2 * j)
    return t, x + np.random.default_rng(seed).normal(0.0, sigma, n)


def read(t, x, band_orders: float = 6.5):
    f, amp, _ = amplitude_spectrum(t, x)
    lines = {k: FM + k * FC for k in carrier_lines()}
    band = (FM - band_orders * FC, FM + band_orders * FC)
    rows = line_table(f, amp, lines, band, carrier_orders(FM, FC, band))
    return {k: r["amplitude"] for k, r in zip(lines, rows)}, band_floor(f, amp, band, carrier_orders(FM, FC, band))


def test_a_sine_reads_its_amplitude_its_neighbours_half_and_the_mean_its_value():
    """The amplitude correction (coherent gain Σw = n/2, the one-sided factor 2): a factor 2 or a window's gain
    wrong fails here. A line on a bin spreads A/2 to each neighbour and nothing beyond (periodic Hann)."""
    n = 4000
    t = np.arange(n) / FS
    f, amp, df = amplitude_spectrum(t, 0.7 + 2.5 * np.cos(2 * np.pi * 50 * FS / n * t + 0.4), detrend=False)
    assert df == pytest.approx(FS / n) and f[50] == pytest.approx(50 * df)
    assert amp[50] == pytest.approx(2.5, rel=1e-12)
    assert amp[49] == pytest.approx(1.25, rel=1e-12) and amp[51] == pytest.approx(1.25, rel=1e-12)
    assert np.max(np.abs(np.delete(amp[2:], [47, 48, 49]))) < 1e-12
    assert amp[0] == pytest.approx(0.7, rel=1e-12)           # the mean, not doubled (bin 1 holds its Hann half, doubled)
    # half a bin off: the Hann window's scalloping, |W(1/2)|/W(0) = 8/(3π) = 0.8488 (1.42 dB)
    _, amp, _ = amplitude_spectrum(t, 2.5 * np.cos(2 * np.pi * 50.5 * FS / n * t))
    assert max(amp[50], amp[51]) == pytest.approx(2.5 * 8.0 / (3.0 * np.pi), rel=1e-3)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_white_noise_reads_its_rayleigh_median_between_the_carrier_orders(seed):
    """Lines of known amplitude over white noise of known σ, on a record of whole carrier revolutions: every line
    reads its amplitude within the noise (four times its median bin, which a Rayleigh amplitude exceeds with probability
    2^−16 ≈ 1.5e-5), the floor between the carrier orders the noise's Rayleigh median within 10 % (its sampling error over
    ≈ 1900 correlated bins is ≈ 3 %; a rectangular window would read 0.82 of it, an amplitude without the one-sided
    factor 2 half)."""
    t, x = synthetic(24, sigma=0.05, seed=seed)
    amps, floor = read(t, x, band_orders=40.5)
    for k, a in carrier_lines().items():
        assert amps[k] == pytest.approx(a, abs=4.0 * rayleigh_floor(0.05, t.size)), k
    assert floor == pytest.approx(rayleigh_floor(0.05, t.size), rel=0.10)


def test_whole_tooth_cycles_keep_the_tooth_lines_out_of_the_lines_and_the_floor():
    """The machine's case: tooth-error lines at the planets' (41/12) and the sun's (82/31) carrier orders, half
    the largest carrier line, 400× the noise floor. Over one tooth cycle (12 revolutions) every carrier line reads
    its amplitude within 1 % of the largest (0.4 % without noise: the sun's lines, off the bins, leak 4e-3 into
    them) and the floor lies within 1–1.6× the noise's (the tooth lines take a quarter of the floor's bins and
    lift its median so; seen 1.30–1.50× over four seeds). Over three
    revolutions (the former record) no floor bin is left, the band's median of all its bins reads 127× the noise
    floor and the lines are off by up to 30 % of the largest (a tooth line 0.25 bin from a carrier order's
    neighbour). A carrier-synchronous average over the same 12 revolutions (a rectangular window at the carrier
    orders) reads the lines 10× less accurately than the Hann window: the sun's lines leak into it as 1/m."""
    t, x = synthetic(12.2, sigma=0.05, seed=4, tooth=0.5)
    assert tooth_cycle(Z_R, (Z_P, Z_P)) == 12
    tc, sig = whole_revolutions(t, {"x": x}, FC, tooth_cycle(Z_R, (Z_P, Z_P)))
    assert tc.size == int(round(12 / FC * FS)) and sideband_resolution(tc, FC) is None
    amps, floor = read(tc, sig["x"])
    hann_error = max(abs(amps[k] - a) for k, a in carrier_lines().items())
    assert hann_error < 1e-2
    assert 1.0 <= floor / rayleigh_floor(0.05, tc.size) < 1.6
    # the carrier-synchronous average over the same revolutions
    per_rev = int(round(FS / FC))
    average = sig["x"].reshape(12, per_rev).mean(axis=0)
    orders = 2.0 * np.abs(np.fft.rfft(average)) / per_rev
    tsa_error = max(abs(orders[Z_R + k] - a) for k, a in carrier_lines().items())
    assert tsa_error > 0.03 and tsa_error > 4.0 * hann_error        # seen 0.041 against 0.0066
    # three revolutions: the carrier orders' main lobes fill the band
    t3, s3 = whole_revolutions(t, {"x": x}, FC)
    t3, x3 = t3[: int(round(3 / FC * FS))], s3["x"][: int(round(3 / FC * FS))]
    assert sideband_resolution(t3, FC) is not None
    amps3, floor3 = read(t3, x3)
    assert np.isnan(floor3)
    f3, a3, _ = amplitude_spectrum(t3, x3)
    band = (f3 >= FM - 6.5 * FC) & (f3 <= FM + 6.5 * FC)
    assert np.median(a3[band]) > 30.0 * rayleigh_floor(0.05, t3.size)
    assert max(abs(amps3[k] - a) for k, a in carrier_lines().items()) > 0.1


def test_the_floor_leaves_out_each_lines_main_lobe_and_nothing_else():
    """band_floor: bins within two bins of a listed line are left out (a line on a bin is exactly zero from two
    bins on), every other bin of the band counts; carrier_orders lists f_m + k f_c within the band."""
    f = np.arange(0.0, 100.0, 1.0)
    amp = np.full(f.size, 3.0)
    amp[[49, 50, 51]] = [5.0, 10.0, 5.0]
    amp[52] = 1.0                                           # two bins from the line: floor, not lobe
    assert band_floor(f, amp, (40.0, 60.0), [50.0]) == 3.0
    assert band_floor(f, amp, (50.0, 53.0), [50.0]) == 2.0        # bins 52, 53: 1 and 3
    assert np.isnan(band_floor(f, amp, (49.0, 51.0), [50.0]))
    assert carrier_orders(100.0, 10.0, (75.0, 125.0)) == [80.0, 90.0, 100.0, 110.0, 120.0]
    assert carrier_orders(100.0, 10.0, (80.0, 120.0)) == [80.0, 90.0, 100.0, 110.0, 120.0]


def test_the_tooth_cycle_and_whole_cycles_of_the_record():
    """z_p/gcd(z_p, z_r) revolutions per planet, their least common multiple; a record is cut to whole cycles
    where it holds one, to whole revolutions where it does not; a floor needs MIN_REVOLUTIONS."""
    assert tooth_cycle(82, (24, 24)) == 12 and tooth_cycle(82, (31,)) == 31 and tooth_cycle(82, (24, 31)) == 372
    assert tooth_cycle(80, (20,)) == 1 and tooth_cycle(84, (24, 28)) == 2
    t = np.arange(int(26.5 / FC * FS)) / FS
    assert whole_revolutions(t, {}, FC, 12)[0].size == int(round(24 / FC * FS))
    assert whole_revolutions(t, {}, FC)[0].size == int(round(26 / FC * FS))
    t = np.arange(int(7.5 / FC * FS)) / FS
    assert whole_revolutions(t, {}, FC, 12)[0].size == int(round(7 / FC * FS))
    assert MIN_REVOLUTIONS == 4
