"""components.results.read_results (h5py alone) against xarray's open of the same file, the truth it must equal:
a short DPGT run's results.nc as the runner writes it, the same file with the sliced model's profiles appended in a
second session, the run re-written by xarray with an empty time axis, files written here with the recorder's calls
(hypothesis: dimension orders with equal lengths, string coordinates of any text, empty axes), the encodings it
decodes (fill values, compression) and those it refuses by name; and the files that are not results files."""
from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import h5netcdf
import h5py
import numpy as np
import pytest
import xarray as xr
from hypothesis import given
from hypothesis import strategies as st

from components.results import DamagedResults, Results, ResultsError, open_dataset, open_run, read_results


# ----------------------------------------------------------------------------------------------- the truth: xarray
def assert_same_as_xarray(path) -> Results:
    """read_results(path) equals xarray's open of it: the same variables, coordinates and data variables, each with
    its dims, dtype kind (strings as str), values (NaN where xarray has NaN) and attributes; the same global ones."""
    res = read_results(path)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert set(res.variables) == set(ds.variables)
        assert res.coords == set(ds.coords) and set(res.data_vars) == set(ds.data_vars)
        for k in ds.variables:
            want = ds[k].values
            assert res.dims[k] == ds[k].dims, k
            assert res[k].shape == want.shape and res[k].dtype.kind == want.dtype.kind, (k, res[k].dtype, want.dtype)
            if want.dtype.kind == "f":
                np.testing.assert_array_equal(res[k], want, err_msg=k)          # NaN where xarray has NaN
            else:
                assert res[k].tolist() == want.tolist(), k                      # str equals str, never bytes
            assert res.variable_attrs[k] == ds[k].attrs, k
        assert res.attrs == ds.attrs
        assert res.sizes == dict(ds.sizes)
    return res


# ----------------------------------------------------------------------------------------------- a recorded run
@pytest.fixture(scope="module")
def run_file(tmp_path_factory) -> Path:
    """A DPGT run of 1 ms (13 samples) as scenarios.core.runner writes it."""
    from components.presets import reference_dpgt
    from components.scene import SceneOptions
    from scenarios.core.runner import RunConfig, run_case

    out = tmp_path_factory.mktemp("reader_run")
    run_case(reference_dpgt(3, "forward"), RunConfig(settle=0.0005, window=0.0005, progress=False,
                                                     options=SceneOptions()), out)
    return out / "results.nc"


def test_a_recorded_run_reads_as_xarray_reads_it(run_file):
    res = assert_same_as_xarray(run_file)
    # what the recorder wrote, named: the axes in order, a string coordinate as str, the instance coordinates
    assert res.dims["motion.position"] == ("time", "motion.body", "axis")
    assert res.dims["race_inner.load"] == ("time", "race_inner.instance")
    assert res["motion.body"].dtype.kind == "U" and {"sun", "ring", "carrier", "a1"} <= set(res["motion.body"])
    assert res["axis"].tolist() == ["x", "y"]
    assert {"race_inner.bearing", "race_inner.pair", "time", "motion.body"} <= res.coords
    assert "race_inner.bearing" not in res.data_vars and "race_inner.load" in res.data_vars
    assert res["race_inner.pair"].dtype == np.int64 and res["time"].dtype == np.float64
    assert res.sizes["time"] == 13 and res["motion.position"].shape == (13, res.sizes["motion.body"], 2)
    assert res.json("meta")["rollers"] == 12 and res.variable_attrs["time"]["units"] == "s"
    assert open_run(run_file.parent).read().dims == res.dims            # a run folder's, through RunFiles


def test_a_read_of_some_variables_reads_them_and_every_coordinate(run_file):
    full = read_results(run_file)
    some = read_results(run_file, variables=["race_inner.load", "not.in.the.file"])
    assert set(some.variables) == {"race_inner.load"} | full.coords
    assert some.data_vars == ("race_inner.load",) and some.dims["race_inner.load"] == full.dims["race_inner.load"]
    np.testing.assert_array_equal(some["race_inner.load"], full["race_inner.load"])


def test_load_run_holds_what_xarray_reads(run_file):
    """viz's Run: the same arrays as the file's variables through xarray, every data variable but motion/fixed an
    output, in float64."""
    from viz.results import load_run
    run = load_run(run_file)
    with xr.open_dataset(run_file, engine="h5netcdf") as ds:
        outputs = {k for k in ds.data_vars if not k.startswith(("motion.", "fixed."))}
        assert set(run.outputs) == outputs and len(outputs) > 20
        for k in outputs:
            assert run.outputs[k].dtype == np.float64
            np.testing.assert_array_equal(run.outputs[k], ds[k].values)
        assert run.bodies == tuple(ds["motion.body"].values.tolist())
        assert run.fixed_bodies == tuple(ds["fixed.body"].values.tolist())
        np.testing.assert_array_equal(run.t, ds["time"].values)
        np.testing.assert_array_equal(run.v[..., :2], ds["motion.velocity"].values)
        np.testing.assert_array_equal(run.a[..., 2], ds["motion.angular_acceleration"].values)
        np.testing.assert_array_equal(run.fixed_q[..., 2], ds["fixed.angle"].values)
        assert run.meta == json.loads(ds.attrs["meta"]) and list(run.bearings) == json.loads(ds.attrs["bearings"])


def test_a_file_appended_in_a_second_session_reads_as_xarray_reads_it(run_file, tmp_path):
    """The sliced model's profiles appended to a run's file (new dimensions, two of equal length, ids numbered on
    from the file's)."""
    from components.results.io import SLICE_PROFILE_VARIABLES, append_slice_profiles
    path = tmp_path / "results.nc"
    shutil.copyfile(run_file, path)
    names, z, rows = ["a1", "b1"], np.array([-1e-3, 0.0, 1e-3]), np.array([-2e-3, 2e-3])
    n = {"sliced_bearing": 2, "slice": 3, "row": 2}
    rng = np.random.default_rng(1)
    profiles = {"names": names, **{key: rng.normal(size=[n[d] for d in dims])
                                   for dims, key, _, _ in SLICE_PROFILE_VARIABLES.values()}}
    append_slice_profiles(path, profiles, z, rows)
    res = assert_same_as_xarray(path)
    for name, (dims, key, units, _) in SLICE_PROFILE_VARIABLES.items():
        assert res.dims[name] == dims and res.variable_attrs[name]["units"] == units
        np.testing.assert_array_equal(res[name], profiles[key])
    assert res["sliced_bearing"].tolist() == names


def test_an_empty_time_axis_reads_and_load_run_says_so(run_file, tmp_path):
    """The run re-written by xarray (its own writer: _FillValue NaN on every float variable) with no samples."""
    from viz.results import load_run
    path = tmp_path / "results.nc"
    with xr.open_dataset(run_file, engine="h5netcdf") as ds:
        ds.isel(time=slice(0, 0)).to_netcdf(path, engine="h5netcdf")
    res = assert_same_as_xarray(path)
    assert res["time"].shape == (0,) and res["motion.position"].shape[0] == 0 and res.sizes["time"] == 0
    with pytest.raises(ResultsError, match="hold no samples"):
        load_run(path)


# ----------------------------------------------------------------------------------------------- files written here
def _write(path, dims: dict[str, int], variables: dict, coords: dict, attrs: dict) -> None:
    """A file written with the recorder's calls (h5netcdf: dimensions, then variables; strings variable-length)."""
    with h5netcdf.File(path, "w") as f:
        for d, n in dims.items():
            f.dimensions[d] = n
        for k, v in attrs.items():
            f.attrs[k] = v
        for name, (d, values) in coords.items():
            if values.dtype.kind == "U":
                cv = f.create_variable(name, (d,), h5py.string_dtype())
                cv[:] = values.astype(object)
            else:
                cv = f.create_variable(name, (d,), values.dtype)
                cv[:] = values
        for name, (vdims, values, vattrs) in variables.items():
            v = f.create_variable(name, vdims, values.dtype)
            v[...] = values
            v.attrs.update(vattrs)


DIM_NAMES = ["time", "a.instance", "axis", "b.instance"]


@st.composite
def layouts(draw):
    """Dimensions (any of them empty, several of one length), variables over them in any order, string coordinates
    of any text, a non-dimension coordinate named by the variables' ``coordinates`` attribute."""
    sizes = {d: draw(st.integers(0, 3)) for d in draw(st.lists(st.sampled_from(DIM_NAMES), min_size=1, max_size=4,
                                                               unique=True))}
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    variables = {}
    for i in range(draw(st.integers(1, 4))):
        vdims = tuple(draw(st.permutations(list(sizes)))[:draw(st.integers(1, len(sizes)))])
        variables[f"v{i}.out"] = (vdims, rng.normal(size=[sizes[d] for d in vdims]), {"units": "N"})
    text = st.text(st.characters(exclude_categories=("Cs",), exclude_characters="\x00"), max_size=6)
    coords = {}
    for d, n in sizes.items():
        if draw(st.booleans()):
            coords[d] = (d, np.array(draw(st.lists(text, min_size=n, max_size=n)), dtype=str).reshape(n))
        else:
            coords[d] = (d, np.arange(n, dtype=np.int64))
    d0 = next(iter(sizes))
    coords[f"{d0}.label"] = (d0, np.array([f"x{i}" for i in range(sizes[d0])], dtype=str).reshape(sizes[d0]))
    for name, (vdims, _, vattrs) in variables.items():
        if d0 in vdims:
            vattrs["coordinates"] = f"{d0}.label"
    return sizes, variables, coords


# the netCDF-4 dimension ids a file may lack: a writer that puts no _Netcdf4Coordinates on one-dimensional or data
# variables (netCDF-C), or no ids at all; the dimensions then come from the HDF5 dimension lists
STRIPPED = {"none": (), "axes' ids": ("_Netcdf4Coordinates",), "all ids": ("_Netcdf4Coordinates", "_Netcdf4Dimid")}


@given(layouts(), st.sampled_from(sorted(STRIPPED)))
def test_dims_in_axis_order_and_strings_as_str_whatever_the_layout(layout, stripped):
    sizes, variables, coords = layout
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "results.nc"
        _write(path, sizes, variables, coords, {"meta": json.dumps({"frame": "rotating"})})
        with h5py.File(path, "r+") as f:
            for obj in f.values():
                for key in STRIPPED[stripped]:
                    if key in obj.attrs:
                        del obj.attrs[key]
        res = assert_same_as_xarray(path)
    for name, (vdims, values, _) in variables.items():
        assert res.dims[name] == vdims                                       # the axes' names as written, in order
        np.testing.assert_array_equal(res[name], values)
    named = {c for _, _, vattrs in variables.values() for c in vattrs.get("coordinates", "").split()}
    for name, (d, values) in coords.items():
        assert res.dims[name] == (d,) and res[name].tolist() == values.tolist()
        assert (name in res.coords) == (name == d or name in named)             # a coordinate: a dimension's or named
    assert res.json("meta") == {"frame": "rotating"}


def test_compressed_and_chunked_variables_and_fill_values_read_as_xarray_reads_them(tmp_path):
    t = np.linspace(0.0, 1.0, 50)
    x = np.outer(t, [1.0, -2.0, 3.0])
    x[3, 1] = -999.0
    ds = xr.Dataset({"a.load": (("time", "a.instance"), x, {"units": "N"}),
                     "b.load": (("time", "a.instance"), 2 * x)},
                    coords={"time": ("time", t, {"units": "s"}), "a.instance": ["r0", "r1", "r2"]},
                    attrs={"meta": "{}", "count": 3, "scale": 0.5})
    path = tmp_path / "results.nc"
    ds.to_netcdf(path, engine="h5netcdf", encoding={
        "a.load": {"zlib": True, "complevel": 4, "shuffle": True, "chunksizes": (7, 2), "_FillValue": -999.0},
        "b.load": {"compression": "lzf", "chunksizes": (50, 1)}})
    res = assert_same_as_xarray(path)
    assert np.isnan(res["a.load"][3, 1]) and np.isfinite(np.delete(res["a.load"].ravel(), 3 * 3 + 1)).all()
    np.testing.assert_array_equal(res["b.load"], 2 * x)
    assert res.attrs["count"] == 3 and res.attrs["scale"] == 0.5


@pytest.mark.parametrize("variable, encoding, words", [
    (np.linspace(0.0, 1.0, 4), {"dtype": "int16", "scale_factor": 0.01, "_FillValue": -1}, "scale_factor"),
    (np.arange(4, dtype=np.int64), {"_FillValue": -1}, "integers with a fill value"),
    (np.array([b"ab", b"cd", b"ef", b"gh"]), {}, "fixed-length byte strings"),
    (np.array(["2020-01-01", "2020-01-02", "2020-01-03", "2020-01-04"], dtype="datetime64[ns]"), {}, "since"),
    (np.array([True, False, True, True]), {}, "dtype"),
])
def test_encodings_it_does_not_decode_are_refused_by_name(tmp_path, variable, encoding, words):
    path = tmp_path / "results.nc"
    xr.Dataset({"odd.var": ("time", variable)}, coords={"time": np.arange(4.0)}).to_netcdf(
        path, engine="h5netcdf", encoding={"odd.var": encoding})
    with pytest.raises(ResultsError, match=f"'odd.var'.*{words}.*open_dataset reads the file"):
        read_results(path)


# ----------------------------------------------------------------------------------------------- not results files
def test_files_that_are_not_results_files_say_so(run_file, tmp_path):
    from viz.results import load_run
    with pytest.raises(ResultsError, match="no such results file"):
        read_results(tmp_path / "nope.nc")
    with pytest.raises(ResultsError, match="directory without a results.nc"):
        read_results(tmp_path)
    text = tmp_path / "notes.nc"
    text.write_text("not a results file\n")
    for reader in (read_results, open_dataset):                  # the two readers say it in the same words
        with pytest.raises(ResultsError, match="is not a netCDF4/HDF5 results file"):
            reader(text)
    cut = tmp_path / "cut.nc"                                     # a results file cut short: no longer HDF5
    cut.write_bytes(run_file.read_bytes()[: run_file.stat().st_size // 2])
    with pytest.raises(ResultsError, match="is not a netCDF4/HDF5 results file"):
        read_results(cut)
    plain = tmp_path / "plain.h5"                                 # HDF5, not netCDF: axes without dimension names
    with h5py.File(plain, "w") as f:
        f["x"] = np.arange(3.0)
        f.create_group("g")["y"] = np.arange(2.0)
    with pytest.raises(ResultsError, match="'x' has no dimension names for its 1 axes"):
        read_results(plain)
    foreign = tmp_path / "other.nc"                               # netCDF, not a DPGT file: read, then refused
    xr.Dataset({"x": ("time", np.arange(3.0))}, coords={"time": np.arange(3.0)}).to_netcdf(foreign, engine="h5netcdf")
    assert_same_as_xarray(foreign)
    with pytest.raises(ResultsError, match="not a DPGT results file: it lacks motion.position, motion.angle"):
        load_run(foreign)


def test_a_dataset_that_does_not_read_is_damaged(run_file, tmp_path):
    """A file whose header opens but whose data does not (a filter the machine lacks, as a damaged chunk reads):
    DamagedResults in the words of the run folder's integrity checks."""
    path = tmp_path / "results.nc"
    shutil.copyfile(run_file, path)
    with h5py.File(path, "r+") as f:                 # a chunked dataset whose chunk is overwritten by garbage
        f.create_dataset("junk", data=np.arange(13.0), chunks=(13,), compression="gzip")
        f["junk"].attrs["_Netcdf4Coordinates"] = np.array([0], np.int32)
        offset = f["junk"].id.get_chunk_info(0).byte_offset
    with open(path, "r+b") as fh:
        fh.seek(offset)
        fh.write(b"\xff" * 4)
    with pytest.raises(DamagedResults, match="does not open as netCDF4/HDF5: OSError") as e:
        read_results(path)
    assert e.value.why.startswith("does not open as netCDF4/HDF5")


def test_the_slip_readers_give_from_a_read_of_their_variables_what_they_give_from_xarray(run_file):
    """components.skid reads a run's file by the names it declares (ZONE_VARIABLES, SERIES_VARIABLES): the same
    numbers from read_results of those alone as from xarray's Dataset of the whole file."""
    from components.presets import reference_dpgt
    from components.skid import SERIES_VARIABLES, ZONE_VARIABLES, roller_slip_zones, slip_series
    b = reference_dpgt(3).si().bearing
    with xr.open_dataset(run_file, engine="h5netcdf") as ds:
        zones, series = roller_slip_zones(ds, b, bins=8), slip_series(ds, 2e-4)
    assert set(zones) == {"inner", "outer"} and np.isfinite(zones["inner"]["slip_by_angle_pct"]).any()
    np.testing.assert_equal(roller_slip_zones(read_results(run_file, ZONE_VARIABLES), b, bins=8), zones)
    np.testing.assert_equal(slip_series(read_results(run_file, SERIES_VARIABLES), 2e-4), series)
