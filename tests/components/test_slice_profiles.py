"""The sliced model's outputs of a run (docs/model.md §8.8, §13): the pressure profile of each bearing's most loaded
roller at its peak instant, the equivalent slice loads per row, the rows' shares of the load and the rows' sliced life,
in summary.json and results.nc. Truths: the element outputs of the same states read here (the roller with the largest
pin load over the samples, its slices), Hertz's line-contact pressure written out, the rows' series-system life written
out from the standard's formula, a synthetic window for the peak tracker, and the file read back with xarray."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import mbd
from components import static
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from components.statistics.accumulate import PeakProfiles
from components.statistics.quantities import bearing_map


def test_the_peak_tracker_keeps_the_largest_roller_in_each_bearings_window():
    """Two bearings of two rollers, three slices: the tracker keeps per bearing the roller with the largest load among
    the states inside that bearing's window (a larger load after its window's end, or before its start, is left out;
    a sample without a time counts), with that state's slices and time."""
    pk = PeakProfiles(2, 3)
    owner = np.array([0, 0, 1, 1])
    t = np.array([0.0, 1.0, 2.0])
    Q = np.array([[5.0, 1.0, 2.0, 3.0], [4.0, 7.0, 9.0, 1.0], [50.0, 1.0, 1.0, 60.0]])
    pin = np.arange(3 * 4 * 3, dtype=float).reshape(3, 12)
    pk.add(t, Q, pin, -pin, owner, 0.5, np.array([np.inf, 1.5]))   # bearing 1's window ends at 1.5; both start at 0.5
    assert pk.load.tolist() == [50.0, 9.0] and pk.time.tolist() == [2.0, 1.0] and pk.roller.tolist() == [0, 0]
    np.testing.assert_array_equal(pk.pin[0], pin[2].reshape(4, 3)[0])
    np.testing.assert_array_equal(pk.bore[1], -pin[1].reshape(4, 3)[2])
    pk.add(np.array([np.nan]), np.array([[0.0, 80.0, 0.0, 0.0]]), pin[:1], pin[:1], owner, 0.5, np.array([0.0, 0.0]))
    assert pk.load.tolist() == [80.0, 9.0] and pk.roller.tolist() == [1, 0] and np.isnan(pk.time[0])


@pytest.fixture(scope="module")
def double_row():
    """The reference machine at condition 3 with double-row sliced bearings (ISO profile), a1's pin sloped 6′ radially,
    static statistics over two snapshots."""
    p = reference_dpgt(3, "forward")
    p = with_overrides(p, {"bearing.model": "sliced", "bearing.rows": 2, "bearing.profile.shape": "iso_16281",
                           "errors.pin_slope": [{"planet": "a1", "slope": "6 arcmin", "direction": "0 deg"}]})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = build_dpgt(p)
        stats, sols = static.static_statistics(scene, 2)
    return p.si().bearing, scene, stats, sols


def _slices(scene, sols):
    """(pin, bore, Q) per sample from the element outputs: (K, n_b, rows, Z, n_s) slice loads, (K, n_b, rows·Z)."""
    b = scene.bearing
    system = mbd.System(scene.model)
    nb = len(bearing_map(scene))
    out = []
    for s in sols:
        o = system.outputs(s.t, s.q, s.v, s.z)
        out.append([np.stack([o[fam][f"slice_load_{k}"] for k in range(b.slicing.slices)], -1)
                    .reshape(nb, b.rows, b.rollers, -1) for fam in ("race_inner", "race_outer")])
    pin, bore = (np.stack(x) for x in zip(*out))
    return pin, bore


def test_the_double_row_machine_reports_its_rows_profiles_and_life(double_row):
    b, scene, stats, sols = double_row
    pin, bore = _slices(scene, sols)
    K, nb, rows, Z, n_s = pin.shape
    d = stats.summary()
    names = [x["name"] for x in bearing_map(scene)]
    ref = names.index("a1.pb")
    # the rows' shares of the reference bearing's (a1, the sloped pin) mean pin load, row by row from ζ = −e_r/2
    row_load = pin[:, ref].sum(axis=(2, 3)).mean(axis=0)
    np.testing.assert_allclose(d["inner"]["row_load_share"], row_load / row_load.sum(), rtol=1e-12)
    assert abs(d["inner"]["row_load_share"][0] - 0.5) > 0.02                  # the slope splits them
    # the sliced life of a1 with its rows combined, written out: per row and slice the equivalent loads over the
    # samples and the row's rollers (pin 4.5, bore 4), L = [Σ_rows Σ_k (q_e/q_c)^(9/2) over both raceways]^(−8/9)
    g = b.roller_diameter / b.pitch_diameter
    D, l = 1e3 * b.roller_diameter, 1e3 * b.roller_length
    common = 552.0 * 1.1 * g ** (2 / 9) * D ** (29 / 27) * l ** (7 / 9) * b.rollers ** -0.25 * n_s ** (-7 / 9)
    qc_pin, qc_bore = common * (1 - g) ** (29 / 27) / (1 + g) ** 0.25, common * (1 + g) ** (29 / 27) / (1 - g) ** 0.25
    qe_pin = np.mean(pin[:, ref] ** 4.5, axis=(0, 2)) ** (1 / 4.5)          # (rows, n_s)
    qe_bore = np.mean(bore[:, ref] ** 4.0, axis=(0, 2)) ** 0.25
    L = (np.sum((qe_pin / qc_pin) ** 4.5) + np.sum((qe_bore / qc_bore) ** 4.5)) ** (-8 / 9)
    assert d["inner"]["life_iso16281_sliced_Mrev"] == pytest.approx(L, rel=1e-9)
    # the profiles: each bearing's most loaded roller over the samples, its slices at that sample
    pr = stats.slice_profiles()
    assert pr["names"] == names
    E = b.elastic_modulus / (2 * (1 - b.poisson_ratio ** 2))
    width = b.roller_length / n_s
    for i in range(nb):
        Q = pin[:, i].sum(-1).reshape(K, rows * Z)
        k, j = np.unravel_index(np.argmax(Q), Q.shape)
        assert (pr["roller"][i], pr["row"][i], pr["time"][i]) == (j, j // Z, sols[k].t)
        q = pin[k, i].reshape(rows * Z, n_s)[j]
        # the statistics read the compiled kernel's slice loads: the reference's to round-off (its slice power within
        # 1.5 ulp, tests/mbd/test_compiled_sliced.py)
        np.testing.assert_allclose(pr["load_pin"][i], q, rtol=1e-12)
        np.testing.assert_allclose(pr["load_bore"][i], bore[k, i].reshape(rows * Z, n_s)[j], rtol=1e-12)
        p_pin = np.sqrt(q / width * E / math.pi * (2 / b.roller_diameter + 2 / (b.pitch_diameter - b.roller_diameter)))
        np.testing.assert_allclose(pr["pressure_pin"][i], p_pin, rtol=1e-12)
        assert p_pin.max() > 5e8                                             # a loaded roller (Pa)
    np.testing.assert_allclose(pr["equivalent_pin"][ref], qe_pin, rtol=1e-12)
    np.testing.assert_allclose(pr["equivalent_bore"][ref], qe_bore, rtol=1e-12)
    # the edge of a1's most loaded roller: the ISO profile under 6′ loads one end more than the other
    p = pr["pressure_pin"][ref]
    assert abs(p[0] - p[-1]) > 0.05 * p.max()


def test_the_profiles_go_into_results_nc_with_their_units(double_row, tmp_path):
    """append_slice_profiles adds the profiles to an existing results file atomically, each with its units and long
    name, read back by xarray as written."""
    import h5netcdf
    import xarray as xr
    from components.bearing import row_stations, sliced_law
    from components.results.io import SLICE_PROFILE_VARIABLES, append_slice_profiles
    b, scene, stats, _ = double_row
    path = tmp_path / "results.nc"
    with h5netcdf.File(path, "w") as f:          # a run's file: a time axis and a series
        f.dimensions["time"] = 3
        v = f.create_variable("time", ("time",), float)
        v[:] = [0.0, 1.0, 2.0]
    pr = stats.slice_profiles()
    append_slice_profiles(path, pr, sliced_law(b)["z"], row_stations(b))
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds["time"].size == 3
        assert list(ds["sliced_bearing"].values) == pr["names"]
        np.testing.assert_array_equal(ds["slice"].values, sliced_law(b)["z"])
        np.testing.assert_array_equal(ds["row"].values, row_stations(b))
        for name, (dims, key, units, words) in SLICE_PROFILE_VARIABLES.items():
            assert ds[name].dims == dims and ds[name].attrs["units"] == units and ds[name].attrs["long_name"] == words
            np.testing.assert_array_equal(ds[name].values, np.asarray(pr[key], float))
    assert not list(tmp_path.glob("*.tmp"))
