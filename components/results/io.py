"""The writes of a run's files: every file a run or study writes is written atomically (a reader sees the old
content or the new, never a part), through the engine's public API (:func:`mbd.atomic_write_text`,
:func:`mbd.atomic_write_bytes`, which its recorder and checkpoints use too); :func:`write_summary` writes
summary.json in its one on-disk form (indented by 2, numpy scalars and arrays as JSON numbers and lists)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from mbd import atomic_write_bytes, atomic_write_text

from .reader import SUMMARY_NAME

__all__ = ["atomic_write_bytes", "atomic_write_text", "summary_text", "write_summary", "SLICE_PROFILE_VARIABLES",
           "append_slice_profiles"]


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)      # what JSON has no form for (a path, an enum) is kept as its text


def summary_text(summary) -> str:
    """summary.json's text of ``summary`` (a mapping)."""
    return json.dumps(summary, indent=2, default=_json_default)


def write_summary(folder, summary) -> Path:
    """Write ``summary`` as ``folder``/summary.json, atomically; return its path."""
    path = Path(folder) / SUMMARY_NAME
    atomic_write_text(path, summary_text(summary))
    return path


# the sliced model's profiles in results.nc (components.outputs.WindowStatistics.slice_profiles): name -> (dims, key,
# units, long name)
SLICE_PROFILE_VARIABLES = {
    "peak_profile.pressure_pin": (("sliced_bearing", "slice"), "pressure_pin", "Pa",
                                  "Hertz pressure on the pin along the most loaded roller at its peak instant"),
    "peak_profile.pressure_bore": (("sliced_bearing", "slice"), "pressure_bore", "Pa",
                                   "Hertz pressure on the bore along the most loaded roller at its peak instant"),
    "peak_profile.load_pin": (("sliced_bearing", "slice"), "load_pin", "N",
                              "pin slice loads of the most loaded roller at its peak instant"),
    "peak_profile.load_bore": (("sliced_bearing", "slice"), "load_bore", "N",
                               "bore slice loads of the most loaded roller at its peak instant"),
    "peak_profile.time": (("sliced_bearing",), "time", "s", "the peak instant (the largest pin load of any roller "
                                                             "of the bearing in its window)"),
    "peak_profile.roller": (("sliced_bearing",), "roller", "1", "the most loaded roller (index in its bearing, row "
                                                                "by row)"),
    "peak_profile.row": (("sliced_bearing",), "row", "1", "the most loaded roller's row"),
    "equivalent_slice_load.pin": (("sliced_bearing", "row", "slice"), "equivalent_pin", "N",
                                  "ISO/TS 16281 equivalent slice load on the pin over the window and the row's rollers "
                                  "(exponent 4.5)"),
    "equivalent_slice_load.bore": (("sliced_bearing", "row", "slice"), "equivalent_bore", "N",
                                   "ISO/TS 16281 equivalent slice load on the bore over the window and the row's "
                                   "rollers (exponent 4)"),
}


def append_slice_profiles(path, profiles: dict, z, rows) -> Path:
    """Add the sliced model's profiles (:meth:`components.outputs.WindowStatistics.slice_profiles`) to the results file
    ``path`` (:data:`SLICE_PROFILE_VARIABLES`, their coordinates: the bearings' names, ``z`` (n_s,) the slices' stations
    from the roller centre [m], ``rows`` (rows,) the rows' axial stations [m]), atomically (a copy written, then
    renamed over it)."""
    # deferred: HDF5 (≈ 0.1 s) only when a sliced run's results.nc is written
    import h5netcdf
    import h5py

    path = Path(path)
    tmp = path.with_name(path.name + ".profiles.tmp")
    shutil.copyfile(path, tmp)
    try:
        with h5netcdf.File(tmp, "a") as f:
            names = list(profiles["names"])
            for dim, size in (("sliced_bearing", len(names)), ("slice", len(z)), ("row", len(rows))):
                f.dimensions[dim] = size
            v = f.create_variable("sliced_bearing", ("sliced_bearing",), h5py.string_dtype())
            v[:] = np.array(names, dtype=object)
            v.attrs.update({"units": "1", "long_name": "planet bearing (its planet's name)"})
            for name, vals, words in (("slice", z, "slice centre's axial station from the roller centre"),
                                      ("row", rows, "row's axial station from the bearing's centre")):
                v = f.create_variable(name, (name,), float)
                v[:] = np.asarray(vals, float)
                v.attrs.update({"units": "m", "long_name": words})
            for name, (dims, key, units, words) in SLICE_PROFILE_VARIABLES.items():
                arr = np.asarray(profiles[key], float)
                v = f.create_variable(name, dims, float)
                v[...] = arr
                v.attrs.update({"units": units, "long_name": words})
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)
    return path
