"""The dynamic factors of docs/model.md §13.8 against synthetic drive-flank forces with known answers
(components.statistics.accumulate.FlankPeaks, the accumulator the run's observer feeds on every accepted step):
the 99th percentile in time over the mean, the mean over mesh cycles of each cycle's peak over the mean; both
independent of how the signal is cut into steps, and converging on a stationary signal where the maximum grows."""
import math

import numpy as np
import pytest

from components.statistics.accumulate import FlankPeaks

T_M = 1e-3                          # one mesh cycle [s]
F = 1000.0                          # mean force [N]


def run(t, x, cycles, scale=F, t0=0.0):
    """FlankPeaks over [t0, t0 + cycles·T_M] of one instance, fed in blocks of 7 steps (as the compiled engine
    hands them over); returns its results and the stream's max."""
    fp = FlankPeaks(["m_drive_force"], [1], t0, t0 + cycles * T_M, T_M, scale, 0)
    for a in range(0, t.size - 1, 7):
        b = min(a + 8, t.size)
        fp.add_steps(t[a:b], {"m_drive_force": x[a:b, None]})
    r = fp.results()["m_drive_force"]
    return {k: float(np.asarray(v)[0]) for k, v in r.items()}


def test_percentile_level_on_a_uniform_distribution():
    """A triangle wave between 0 and 2F spends equal times at every force: its P99 is 1.98 F exactly (P98 1.96,
    P99.9 1.998), its mean F, every cycle's peak 2F. The nominal scale (0.8 F here) must not enter the ratios."""
    n = 40
    t = np.arange(2 * n + 1) * T_M / 2
    x = np.where(np.arange(t.size) % 2 == 0, 0.0, 2 * F)
    r = run(t, x, n, scale=0.8 * F)
    assert r["mean"] == pytest.approx(F, rel=1e-12)
    assert r["percentile"] / r["mean"] == pytest.approx(1.98, abs=2e-4)
    assert r["cycle_peak_mean"] / r["mean"] == pytest.approx(2.0, rel=1e-12)
    assert r["cycles"] == n


def test_sinusoid_and_step_rate_independence():
    """F(1 + 0.5 sin 2πt/T_m): mean F over whole cycles, P99/mean = 1 + 0.5 sin(0.49π) = 1.49975, every cycle's
    peak 1.5 F; irregular steps of ~1/400 cycle give the same as regular ones of 1/250 (within the linear
    interpolation's error)."""
    rng = np.random.default_rng(3)
    out = []
    for per_cycle, jitter in ((400, 0.4), (250, 0.0)):
        n = 12 * per_cycle
        t = (np.arange(n + 1) + jitter * rng.uniform(-1, 1, n + 1) * (np.arange(n + 1) % n != 0)) * T_M / per_cycle
        t = np.sort(t)
        out.append(run(t, F * (1 + 0.5 * np.sin(2 * np.pi * t / T_M)), 12))
    for r in out:
        assert r["mean"] == pytest.approx(F, rel=1e-4)
        assert r["percentile"] / r["mean"] == pytest.approx(1 + 0.5 * math.sin(0.49 * math.pi), abs=1e-3)
        assert r["cycle_peak_mean"] / r["mean"] == pytest.approx(1.5, abs=1e-4)
    assert out[0]["percentile"] == pytest.approx(out[1]["percentile"], abs=1e-3 * F)


def test_periodic_peak_train_has_the_mean_cycle_peak():
    """Base F and, in the middle of each mesh cycle, a triangular spike of width T_m/10, 2F and 3F high in turn:
    peaks 3F and 4F, mean F(1 + 0.05·2.5) = 1.125 F, so the cycle-peak factor is 3.5/1.125 = 3.111; counted in
    cycles twice as long it would be 4/1.125, half as long 2.25/1.125. A step added on a straight piece changes
    nothing (the statistics do not depend on where the steps fall)."""
    n = 20
    pts = []
    for k in range(n):
        h = 2 * F if k % 2 == 0 else 3 * F
        c = (k + 0.5) * T_M
        pts += [(k * T_M, F), (c - 0.05 * T_M, F), (c, F + h), (c + 0.05 * T_M, F)]
    pts.append((n * T_M, F))
    t, x = map(np.array, zip(*pts))
    r = run(t, x, n)
    assert r["mean"] == pytest.approx(1.125 * F, rel=1e-12)
    assert r["cycle_peak_mean"] / r["mean"] == pytest.approx(3.5 / 1.125, rel=1e-12)
    assert r["cycles"] == n
    # a step inserted halfway up each spike's rising flank: the same line, the same statistics
    t2 = np.sort(np.r_[t, (np.arange(n) + 0.475) * T_M])
    r2 = run(t2, np.interp(t2, t, x), n)
    for k in ("mean", "cycle_peak_mean", "percentile"):
        assert r2[k] == pytest.approx(r[k], rel=1e-9), k


def test_statistics_converge_where_the_maximum_grows():
    """A stationary random force (smoothed Gaussian noise, 15 % RMS, 20 samples a cycle): from 200 to 3200 mesh
    cycles of one stream the largest force over the mean grows (a record: by ≈ 0.15 (√(2 ln 64000) − √(2 ln 4000))
    ≈ 0.1), the P99 and the mean cycle peak stay within their estimators' scatter (≈ 0.01 and 0.005 at 200 cycles)."""
    rng = np.random.default_rng(0)
    n_long, per, n_short = 3200, 20, 200
    e = rng.standard_normal(n_long * per + 1)
    noise = np.convolve(e, np.ones(5) / math.sqrt(5), mode="same")
    t = np.arange(n_long * per + 1) * T_M / per
    x = F * (1 + 0.15 * noise)
    short, long_ = run(t[: n_short * per + 1], x[: n_short * per + 1], n_short), run(t, x, n_long)
    peak = lambda m: x[: m * per + 1].max() / x[: m * per + 1].mean()
    assert peak(n_long) - peak(n_short) > 0.05
    assert abs(long_["percentile"] / long_["mean"] - short["percentile"] / short["mean"]) < 0.025
    assert abs(long_["cycle_peak_mean"] / long_["mean"] - short["cycle_peak_mean"] / short["mean"]) < 0.01
    assert long_["cycles"] == n_long and short["cycles"] == n_short


def test_window_cuts_steps_and_ignores_what_lies_outside():
    """The window [t0, t0 + n T_m] cuts the steps that cross it; forces before and after do not count."""
    t = np.linspace(-2 * T_M, 7 * T_M, 901)
    x = np.where((t >= 0) & (t <= 4 * T_M), F * (1 + 0.5 * np.sin(2 * np.pi * t / T_M)), 50 * F)
    x[(t > 4 * T_M)] = 50 * F
    r = run(t, x, 4)
    assert r["mean"] == pytest.approx(F, rel=1e-4)
    assert r["cycle_peak_mean"] / r["mean"] == pytest.approx(1.5, abs=1e-4)
    assert r["cycles"] == 4
