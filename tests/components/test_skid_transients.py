"""Slip against time (components.skid.slip_series) and what a transient's numbers say (transient_numbers), against
synthetic recordings whose rollers' slip, load and orbit are given, and a synthetic exponential approach whose time
constant and settling time are known in closed form."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

from components.skid import slip_series, transient_numbers

Z = 4                   # rollers of the synthetic bearing
N = 400                 # samples over 1 s


def recording(slip_out):
    """One inner bearing "a1.pb" with Z rollers orbiting twice a second (90° apart, from 0.3 rad), loaded on the pin at orbit
    angles in [0, π/2) where they roll (slip 0), and slipping ``slip_out(t)`` % elsewhere; cage slip 2 t %."""
    t = (np.arange(N) + 0.5) / N
    angle = (2 * math.pi * 2 * t[:, None] + 2 * math.pi * np.arange(Z)[None, :] / Z + 0.3) % (2 * math.pi)
    loaded = angle < math.pi / 2
    slip = np.where(loaded, 0.0, slip_out(t)[:, None])
    rollers = [f"a1.pb.roller{i}" for i in range(Z)]
    bearings = [{"type": "rollers", "kind": "inner", "name": "a1.pb", "planet": "a1", "race_inner": [0, Z],
                 "rollers": rollers}]
    ds = xr.Dataset({"bearing.cage_slip": (("time", "bearing.cage_slip.instance"), (2.0 * t)[:, None]),
                     "bearing.roller_slip": (("time", "bearing.roller_slip.instance"), slip),
                     "race_inner.load": (("time", "race_inner.instance"), np.where(loaded, 100.0, 0.0)),
                     "race_inner.angle": (("time", "race_inner.instance"), angle)},
                    coords={"time": t, "bearing.cage_slip.instance": ["a1.pb"], "bearing.roller_slip.instance": rollers},
                    attrs={"bearings": json.dumps(bearings)})
    return ds, t, angle, loaded


def test_slip_series_bins_the_unloaded_rollers_and_the_cage():
    """Out of the load zone the rollers slip 30 + 40 t %: each bin's mean is that at the mean time of its unloaded
    samples; the cage's is 2 t at the mean time of its samples (bins of 0.0999 s from the first sample, whose
    edges fall between samples)."""
    ds, t, angle, loaded = recording(lambda t: 30.0 + 40.0 * t)
    w = 0.0999
    s = slip_series(ds, w)["inner"]
    np.testing.assert_allclose(s["time_s"], t[0] + w * (np.arange(s["time_s"].size) + 0.5), rtol=1e-12)
    for k in range(s["time_s"].size):
        inbin = (t >= t[0] + w * k) & (t < t[0] + w * (k + 1))
        assert s["cage"][k] == pytest.approx(2.0 * t[inbin].mean(), rel=1e-12)
        tt = np.broadcast_to(t[:, None], loaded.shape)[inbin[:, None] & ~loaded]
        assert s["unloaded"][k] == pytest.approx(30.0 + 40.0 * tt.mean(), rel=1e-12)


def test_slip_series_finds_each_entry_once_with_the_slip_just_before():
    """Each roller enters the load zone (angle 0) twice a second after three quarters of an orbit out of it: 2 Z
    entries a second, each carrying the slip of the sample before, 30 + 40 t %."""
    ds, t, angle, loaded = recording(lambda t: 30.0 + 40.0 * t)
    s = slip_series(ds, 0.1)["inner"]
    te, se = s["entries"]
    # the first orbit's entries count only once a roller has been out of the zone for a pitch (it starts loaded or not)
    assert 2 * Z - Z <= te.size <= 2 * Z
    np.testing.assert_allclose(se, 30.0 + 40.0 * te, rtol=1e-12)
    assert np.all(np.diff(np.sort(te)) > 0.0)
    entered = np.nonzero(~loaded[:-1] & loaded[1:])
    assert set(np.round(te, 9)) <= set(np.round(t[entered[0]], 9))


def test_a_flicker_at_the_zone_edge_is_not_an_entry():
    """A roller that leaves the zone and is loaded again within less than a roller pitch of its orbit (a contact
    opening and closing at the edge) does not enter: only real entries are counted."""
    ds, t, angle, loaded = recording(lambda t: 50.0 + 0.0 * t)
    load = ds["race_inner.load"].values.copy()
    edge = (angle > math.pi / 2 + 0.05) & (angle < math.pi / 2 + 0.1)    # just after leaving: loaded again
    load[edge] = 100.0
    flick = ds.assign({"race_inner.load": (("time", "race_inner.instance"), load)})
    te0 = slip_series(ds, 0.1)["inner"]["entries"][0]
    te1 = slip_series(flick, 0.1)["inner"]["entries"][0]
    np.testing.assert_array_equal(te0, te1)


def test_numbers_of_an_exponential_approach():
    """y = 60 − 58 e^{−(t − 0.1)/τ} after a change at 0.1 s (2 % before), τ = 0.05 s, sampled finely: the time to
    63 % of the way is τ, to 50 % τ ln 2, to 90 % τ ln 10 (to the sampling); settling within 10 % of 60 (6 points)
    takes τ ln(58/6); the peak is the last value; before and final the plateaus."""
    tau, t = 0.05, np.arange(0.0, 1.0, 1e-4)
    y = np.where(t < 0.1, 2.0, 60.0 - 58.0 * np.exp(-(t - 0.1) / tau))
    n = transient_numbers(t, y, 0.1, 60.0, 10.0, 1.0)
    assert n["before"] == pytest.approx(2.0)
    assert n["final"] == pytest.approx(60.0, abs=1e-4)
    assert n["t63_s"] == pytest.approx(tau, abs=2e-4)
    assert n["t50_s"] == pytest.approx(tau * math.log(2), abs=2e-4)
    assert n["t90_s"] == pytest.approx(tau * math.log(10), abs=2e-4)
    assert n["settle_s"] == pytest.approx(tau * math.log(58.0 / 6.0), abs=2e-4)
    assert n["peak"] == pytest.approx(y[-1]) and n["peak_after_s"] == pytest.approx(t[-1] - 0.1)


def test_numbers_of_a_fall_and_the_floor():
    """A fall from 40 to 0.5 %: the times follow the fall (fractions of the way, whatever its sign); settling on a
    steady 0.5 % uses the 1-point floor, not 10 % of 0.5; a series that never settles says None."""
    tau, t = 0.02, np.arange(0.0, 0.5, 1e-4)
    y = np.where(t < 0.05, 40.0, 0.5 + 39.5 * np.exp(-(t - 0.05) / tau))
    n = transient_numbers(t, y, 0.05, 0.5, 10.0, 1.0)
    assert n["t63_s"] == pytest.approx(tau, abs=2e-4)
    assert n["settle_s"] == pytest.approx(tau * math.log(39.5 / 1.0), abs=2e-4)
    assert transient_numbers(t, y, 0.05, 20.0, 10.0, 1.0)["settle_s"] is None
    assert transient_numbers(t, y, 0.05, None, 10.0, 1.0)["settle_s"] is None
