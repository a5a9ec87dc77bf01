"""results.nc carries each planet bearing's load and cage slip as time series (issue 24 §4), with units, and
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
