"""components.results: the typed summary, the reader and the writer, against truths they do not
compute: a hand-written summary.json, the words and units table, a damaged file, a file the test writes itself."""
from __future__ import annotations

import json

import numpy as np
import pytest

from components.results import (DamagedResults, ResultsError, Summary, count_samples, load_summary, open_dataset,
                                open_run)


def test_summary_is_the_file_mapping_with_typed_sections_and_the_failed_form(tmp_path):
    raw = {"condition": 3, "direction": "reverse", "warnings": ["w"],
           "inner": {"bearing_load_mean_N": 1234.5, "cage_slip_pct": 2.0, "lambda_min": 1.5, "odd_key": 7},
           "outer": {"bearing_load_mean_N": 99.0}, "meshes": {"sun_inner": {"drive_flank": -1}}}
    (tmp_path / "summary.json").write_text(json.dumps(raw))
    s = open_run(tmp_path).summary
    assert isinstance(s, Summary) and s == raw and not s.failed and s.error is None and s.has_bearings
    assert s.inner["bearing_load_mean_N"] == 1234.5 and s.bearing("outer")["bearing_load_mean_N"] == 99.0
    q = s.inner.quantity("bearing_load_mean_N")
    assert q == (1234.5, "N", "planet bearing load, mean")
    assert s.inner.quantity("cage_slip_pct").unit == "%" and s.inner.quantity("lambda_min").unit == "1"
    assert s.inner.quantity("odd_key") == (7, None, None)        # neither suffix nor listed: no unit claimed
    assert s.meshes["sun_inner"].quantity("drive_flank").unit == "1" and s.warnings == ["w"]
    s.inner["life_L10_relative"] = 0.5                            # a section edited in place reaches the file form
    assert s["inner"]["life_L10_relative"] == 0.5
    with pytest.raises(ValueError, match="bearing kind must be one of"):
        s.bearing("middle")
    with pytest.raises(KeyError, match="no 'nope'"):
        s.inner.quantity("nope")

    f = Summary.failure("c4_forward", "ValueError: x", "Traceback ...")
    assert f == {"case": "c4_forward", "error": "ValueError: x", "traceback": "Traceback ..."}
    assert f.failed and f.error == "ValueError: x" and not f.has_bearings and "error" in f
    assert Summary.failure("c1_reverse", "E") == {"case": "c1_reverse", "error": "E"}
    with pytest.raises(KeyError, match="failed: E"):
        Summary.failure("c1_reverse", "E").inner


def test_summary_written_in_the_format_on_disk(tmp_path):
    from components.results.io import write_summary
    s = {"samples": np.int64(5), "x_m": np.float64(0.25), "v": np.arange(2), "inner": {"a_N": 1.0}}
    path = write_summary(tmp_path, s)
    text = path.read_text()
    assert path.name == "summary.json" and text.startswith('{\n  "samples": 5,')       # indent 2, numpy as numbers
    assert json.loads(text) == {"samples": 5, "x_m": 0.25, "v": [0, 1], "inner": {"a_N": 1.0}}
    assert load_summary(path) == json.loads(text) and load_summary(tmp_path) == json.loads(text)
    assert not [p for p in tmp_path.iterdir() if p.name != "summary.json"]           # no temporary file left


def test_damaged_and_missing_files_say_so(tmp_path):
    assert load_summary(tmp_path / "summary.json") is None
    (tmp_path / "summary.json").write_text('{"inner": {"a": 1')
    with pytest.raises(DamagedResults) as e:
        load_summary(tmp_path / "summary.json")
    assert e.value.why == "not readable JSON: JSONDecodeError"
    (tmp_path / "summary.json").write_text("[1, 2]")
    with pytest.raises(DamagedResults, match="not a JSON object"):
        open_run(tmp_path).summary
    (tmp_path / "results.nc").write_text("not netCDF")
    with pytest.raises(DamagedResults, match="does not open as netCDF4/HDF5"):
        count_samples(tmp_path / "results.nc")
    with pytest.raises(ResultsError, match="not a netCDF4/HDF5 results file"):
        open_run(tmp_path).dataset()
    with pytest.raises(ResultsError, match="no such results file"):
        open_dataset(tmp_path / "other.nc")
    with pytest.raises(ResultsError, match="directory without a results.nc"):
        open_dataset(tmp_path / "..")


def test_the_reader_opens_a_results_file_lazily(tmp_path):
    xr = pytest.importorskip("xarray")
    t = np.linspace(0.0, 1.0, 7)
    xr.Dataset({"time": ("time", t), "a.load": (("time", "a.instance"), np.outer(t, [1.0, 2.0]))},
               attrs={"meta": json.dumps({"direction": "forward"})}).to_netcdf(tmp_path / "results.nc", engine="h5netcdf")
    run = open_run(tmp_path / "results.nc")
    assert run.folder == tmp_path and run.summary is None and run.samples() == 7
    with run.dataset() as ds:
        assert np.array_equal(ds["a.load"].values[:, 1], 2 * t)
        from components.results import json_attr
        assert json_attr(ds.attrs, "meta") == {"direction": "forward"}


@pytest.mark.parametrize("before, after, text", [
    (100.0, 140.0, "+40 %"), (100.0, 75.6, "−24 %"), (100.0, 103.21, "+3.2 %"), (100.0, 698.0, "+598 %"),
    (120000.0, 447.0, "−99.6 %"),         # 0.37 % left: one decimal keeps its one digit
    (487000.0, 1420.0, "−99.7 %"),
    (10000.0, 4.0, "−99.96 %"),           # 0.04 % left
    (100.0, 2.4, "−98 %"),                # 2.4 % left: whole percents keep its digit
    (100.0, 0.0, "−100 %"),               # nothing left
    (461.0, 306600.0, "\u00d7665"),       # +66 408 %: the ratio
    (100.0, 999.0, "+899 %"), (100.0, 1000.0, "\u00d710"), (100.0, 1234.0, "\u00d712.3"),
    (1.0, 12345.0, "\u00d712345"),
    (100.0, 999.6, "\u00d710"),           # +899.6 % shows as +900: the digits shown decide the form
    (100.0, 99950.0, "\u00d71000"),        # ×999.5: no power of ten
    (10000.0, 9999.6, "0.0 %"),            # −0.004 %: no sign on nothing
    (1.0, 1e-9, "\u2212100 %"),            # 1e-7 % left: below four decimals, the fall reads whole
    (100.0, 99.96, "0.0 %")])
def test_a_change_is_written_with_the_digits_it_needs_and_as_a_ratio_from_ten_times(before, after, text):
    """The one rule of every table and figure (format_change): the truths from the pairs of values by hand."""
    from components.results import format_change, percent_change
    assert format_change(percent_change(before, after)) == text


def test_a_change_that_is_not_a_number_is_refused():
    from components.results import format_change
    for bad in (float("nan"), None):
        with pytest.raises(ValueError, match="pct: expected a finite change"):
            format_change(bad)
