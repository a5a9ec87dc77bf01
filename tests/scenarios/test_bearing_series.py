"""results.nc carries each planet bearing's load and cage slip as time series, with units, and
the file says what it is (Conventions, title). The series are samples of the quantities the statistics take on
every step (held to closed forms in tests/components/test_statistics_truths.py and test_rig_statistics.py): their
time means over the window agree with summary.json to the sampling."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from components.presets import reference_dpgt
from scenarios.core.runner import RunConfig, run_case


@pytest.mark.slow
def test_bearing_load_and_cage_slip_series(tmp_path):
    import xarray as xr
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = run_case(reference_dpgt(3), RunConfig(settle=0.03, window=0.021, progress=False), tmp_path)
    with xr.open_dataset(tmp_path / "results.nc", engine="h5netcdf") as ds:
        assert ds.attrs["Conventions"] == "CF-1.10" and "4200 r/min" in ds.attrs["title"]
        names = list(ds["bearing.load_radial.instance"].values)
        assert names == ["a1.pb", "b1.pb", "a2.pb", "b2.pb", "a3.pb", "b3.pb"]
        assert ds["bearing.load_radial"].attrs["units"] == "N" and ds["bearing.cage_slip"].attrs["units"] == "percent"
        t = ds["time"].values
        win = (t >= s["inner"]["window_s"][0]) & (t <= s["inner"]["window_s"][1])
        mean = lambda key, i: float(ds[key].values[win, i].mean())
        for kind, i in (("inner", 0), ("outer", 1)):
            d = s[kind]
            assert mean("bearing.load_radial", i) == pytest.approx(d["bearing_load_radial_mean_N"], rel=5e-3)
            assert mean("bearing.load_tangential", i) == pytest.approx(d["bearing_load_tangential_mean_N"],
                                                                      abs=5e-3 * d["bearing_load_mean_N"])
            assert mean("bearing.cage_slip", i) == pytest.approx(d["cage_slip_pct"], abs=0.01)
        assert np.all(np.isfinite(ds["bearing.cage_slip"].values))


def test_cage_slip_series_against_pure_rolling():
    """results.nc's slip series at a state whose cages turn at known speeds: a cage's pure-rolling speed relative to
    the carrier (the pin) is that of its roller centres at d_m/2, which move at half the bore's surface speed
    (ω_p − ω_c)(d_m + D)/2 (the pin's surface is at rest), i.e. (ω_p − ω_c)(d_m + D)/(2 d_m); a cage turning at
    (1 − s) times that slips 100 s %. A sign or a factor wrong in the series' formula fails here (the statistic
    calls the same function, components.bearing.cage_slip_pct)."""
    from components.outputs import BearingSeries
    from tests.support.dpgt_runs import build

    scene = build(reference_dpgt(3))
    series = BearingSeries(scene)
    b, m = scene.bearing, scene.model
    w_c = 440.0                                                    # rad/s, carrier
    w_p = np.array([-1500.0, 900.0, -1400.0, 950.0, -1300.0, 1000.0])   # rad/s, each bearing's planet
    s = np.array([0.007, -0.02, 0.0, 0.05, 0.2, 0.0071])           # the slips given to the cages
    rolling = (w_p - w_c) * (b.pitch_diameter + b.roller_diameter) / (2.0 * b.pitch_diameter)
    V = np.zeros((m.n_bodies, 3))
    V[series.plan.carrier, 2] = w_c
    V[series.plan.planet, 2] = w_p
    V[series.plan.cage, 2] = w_c + (1.0 - s) * rolling
    np.testing.assert_allclose(series.slip(0.0, np.zeros_like(V), V, np.zeros_like(V), {}), 100.0 * s,
                               rtol=0, atol=1e-11)
    V[series.plan.planet, 2] = w_c                                     # a planet at rest on its pin: nothing to slip from
    assert np.all(np.isnan(series.slip(0.0, np.zeros_like(V), V, np.zeros_like(V), {})))


def test_roller_slip_series_against_pure_rolling():
    """results.nc's roller slip series at a state whose rollers spin at known speeds: a roller rolling on a pin at
    rest has its contact point there at rest, so its spin relative to the carrier is its centre's speed over D/2;
    the centre moves at half the bore's surface speed (ω_p − ω_c)(d_m + D)/2, so the rolling spin is
    (ω_p − ω_c)(d_m + D)/(2 D); a roller spinning at (1 − s) times that slips 100 s %. The instances are the rollers,
    bearing by bearing."""
    from components.outputs import BearingSeries
    from tests.support.dpgt_runs import build

    scene = build(reference_dpgt(3))
    series = BearingSeries(scene)
    b, m, p = scene.bearing, scene.model, series.plan
    assert len(series.rollers) == p.roller_body.size == 6 * int(b.rollers)
    assert series.rollers[0].startswith("a1.pb") and series.rollers[-1].startswith("b3.pb")
    w_c = -310.0
    w_p = np.array([-1500.0, 900.0, -1400.0, 950.0, -1300.0, 1000.0])
    s = np.linspace(-0.1, 0.8, p.roller_body.size)
    rolling = (w_p[p.roller_bearing] - w_c) * (b.pitch_diameter + b.roller_diameter) / (2.0 * b.roller_diameter)
    V = np.zeros((m.n_bodies, 3))
    V[p.carrier, 2] = w_c
    V[p.planet, 2] = w_p
    V[p.roller_body, 2] = w_c + (1.0 - s) * rolling
    got = series.roller_slip(0.0, np.zeros_like(V), V, np.zeros_like(V), {})
    np.testing.assert_allclose(got, 100.0 * s, rtol=0, atol=1e-10)
    assert "bearing.roller_slip" in [o.name for o in series.probes()]
