"""The one reader of a run's files: ``results.nc`` (the recorded samples) and ``summary.json`` (the statistics).

* :func:`open_run` — a run's files (:class:`RunFiles`) from its folder or its results.nc; nothing is read until
  asked: :attr:`RunFiles.summary`, :meth:`RunFiles.read`, :meth:`RunFiles.dataset`, :meth:`RunFiles.samples`.
* :func:`read_results` — results.nc's arrays, dimension names, coordinates and attributes in memory
  (:class:`Results`), read with h5py alone: what a reader of arrays takes (viz, the studies' figures and tables),
  in 28–56 ms a seed-study file where xarray's open takes 218–250 ms.
* :func:`open_dataset` — results.nc as a lazily loaded :class:`xarray.Dataset` (for a caller that wants one: labelled
  selection, the user-facing API); :func:`json_attr` one of its JSON attributes ("meta", "bearings", "sensor", ...).
* :func:`load_summary` — summary.json as a :class:`~components.results.summary.Summary` (None when absent).
* :func:`count_samples` — how many time samples results.nc holds, without reading them.

A missing or foreign file is a :class:`ResultsError` whose message says which; a file that exists but does not
read (broken JSON, not a JSON object, not HDF5) is a :class:`DamagedResults` with the reason in the words the run
folder's integrity checks print (:mod:`scenarios.core.integrity` moves such a file aside). Imports nothing of the
project but the summary (viz reads through it without the engine); xarray and h5py are imported when used.
"""
from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .summary import Summary

__all__ = ["RESULTS_NAME", "SUMMARY_NAME", "ResultsError", "DamagedResults", "RunFiles", "open_run", "results_path",
           "Results", "read_results", "open_dataset", "json_attr", "load_summary", "count_samples"]

RESULTS_NAME = "results.nc"        # a run folder's recorded samples (netCDF4, written by mbd's Recorder)
SUMMARY_NAME = "summary.json"      # a run folder's statistics (written by components.results.io.write_summary)


class ResultsError(ValueError):
    """A results file that is missing, unreadable or not a DPGT results file (the message says which)."""


class DamagedResults(ResultsError):
    """A run's file that exists but does not read; ``why`` says how, in the integrity checks' words."""

    def __init__(self, path, why: str):
        self.path, self.why = Path(path), why
        super().__init__(f"{path} is damaged: {why}")

    def __reduce__(self):          # picklable with its fields (it may cross a Dask worker's boundary)
        return type(self), (self.path, self.why)


def results_path(path) -> Path:
    """The results file ``path`` names: the file itself, or a run folder's results.nc; a :class:`ResultsError`
    when there is none."""
    path = Path(path)
    if path.is_dir():
        if not (path / RESULTS_NAME).is_file():
            raise ResultsError(f"{path} is a directory without a {RESULTS_NAME}")
        return path / RESULTS_NAME
    if not path.exists():
        raise ResultsError(f"no such results file: {path}")
    if not path.is_file():
        raise ResultsError(f"{path} is not a file")
    return path


def open_dataset(path):
    """results.nc (or a run folder's) as an :class:`xarray.Dataset`, loaded lazily (close it, or use it in a
    ``with``). A file that is not netCDF4/HDF5 is a :class:`ResultsError`."""
    import xarray as xr  # deferred: ≈ 0.4 s; this reader is in every command's start-up (dpgt, viz)

    path = results_path(path)
    try:
        return xr.open_dataset(path, engine="h5netcdf")
    except Exception as exc:  # h5py/h5netcdf raise OSError, ValueError, ... for foreign files
        raise ResultsError(f"{path} is not a netCDF4/HDF5 results file ({type(exc).__name__}: {exc})") from None


# ---------------------------------------------------------------------------------------------------------------
# the fast read: h5py alone, no xarray
# ---------------------------------------------------------------------------------------------------------------
# netCDF4's bookkeeping on HDF5 objects (the netCDF-4 format's dimension scales and ids): never a user attribute
_NC4_HIDDEN = frozenset({"REFERENCE_LIST", "CLASS", "DIMENSION_LIST", "NAME", "_Netcdf4Dimid", "_Netcdf4Coordinates",
                         "_nc3_strict", "_NCProperties"})
# attributes xarray's CF decoding takes out of a variable's attrs (into its encoding)
_CF_DECODED = frozenset({"coordinates", "_FillValue", "missing_value", "_Encoding"})
# CF encodings this read does not decode (packing, unsigned ints, dates, booleans): refused by name, never misread
_CF_REFUSED = ("scale_factor", "add_offset", "_Unsigned", "calendar", "dtype")
_NOT_A_VARIABLE = b"This is a netCDF dimension but not a netCDF variable."   # a dimension without a coordinate
_NON_COORD = "_nc4_non_coord_"             # the HDF5 name of a variable named as a dimension it does not index


@dataclass(frozen=True, eq=False)
class Results:
    """A results file in memory, read by :func:`read_results`: every variable of the file's root group as a numpy
    array (``results[name]``; strings as ``str`` arrays, numbers in the file's dtype), with

    * ``dims`` — each variable's dimension names, in the order of its axes;
    * ``coords`` — the names of the coordinates: every variable named as a dimension (``time``, ``motion.body``,
      ``race_inner.instance``...) and every variable another names in its ``coordinates`` attribute
      (``race_inner.bearing``...); the rest are data variables (:attr:`data_vars`);
    * ``attrs`` — the file's global attributes (the JSON ones as the strings they are: :meth:`json`);
    * ``variable_attrs`` — each variable's own attributes (``units``, ``long_name``).

    The same names, arrays, dims, coordinates and attributes as :func:`open_dataset` gives, without a Dataset."""
    path: Path
    variables: Mapping[str, Any]
    dims: Mapping[str, tuple[str, ...]]
    coords: frozenset[str]
    attrs: Mapping[str, Any]
    variable_attrs: Mapping[str, Mapping[str, Any]]

    def __getitem__(self, name: str):
        try:
            return self.variables[name]
        except KeyError:
            raise KeyError(f"{self.path} has no variable {name!r}") from None

    def __contains__(self, name) -> bool:
        return name in self.variables

    def __iter__(self):
        return iter(self.variables)

    def __len__(self) -> int:
        return len(self.variables)

    @property
    def data_vars(self) -> tuple[str, ...]:
        """The variables that are not coordinates, in the file's order."""
        return tuple(k for k in self.variables if k not in self.coords)

    @property
    def sizes(self) -> dict[str, int]:
        """Each dimension's length."""
        return {d: n for k, v in self.variables.items() for d, n in zip(self.dims[k], v.shape)}

    def json(self, key: str):
        """The global attribute ``key`` decoded from JSON (:func:`json_attr`)."""
        return json_attr(self.attrs, key, self.path)


def _attr_value(value):
    """An HDF5 attribute's value as h5netcdf gives it: fixed-length strings decoded, a one-element array its element,
    a string array a list."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "surrogateescape")
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "S":
            value = [b.decode("utf-8", "surrogateescape") for b in value.flat]
        elif value.dtype.kind == "O":
            value = value.tolist()
        if len(value) == 1:
            return value[0]
    return value


def read_results(path, variables: Iterable[str] | None = None) -> Results:
    """results.nc (or a run folder's) in memory as :class:`Results`, read with h5py alone.

    The file is netCDF-4 (HDF5 with the netCDF-4 conventions), written by the engine's recorder or by xarray through
    h5netcdf. Each HDF5 dataset of the root group is a variable, but the dimension scales that stand for a dimension
    without a coordinate (their NAME says "not a netCDF variable"); a variable's dimensions are read from its
    ``_Netcdf4Coordinates`` attribute (the netCDF-4 dimension ids of its axes) mapped through the dimension scales'
    ``_Netcdf4Dimid``: integers in attributes, where the HDF5 dimension-list references (``DIMENSION_LIST``) need an
    object look-up per axis — which is most of what xarray's open costs. A variable without the ids (a file of another
    writer: netCDF-C writes them only on multi-dimensional coordinates) has them from its dimension list; a dimension
    scale without either is its own one dimension. Every variable's axes are checked against its dimension names and
    every dimension has one length across the file.

    Decoded as xarray decodes them: variable-length strings to ``str`` arrays; a float variable's ``_FillValue`` and
    ``missing_value`` to NaN; chunked and compressed datasets (HDF5 filters h5py has) read as any. Refused with a
    :class:`ResultsError` naming the variable, never misread: packed or unsigned data (``scale_factor``,
    ``add_offset``, ``_Unsigned``), dates (``calendar``, units "... since ..."), encoded booleans (``dtype``), a fill
    value on an integer or string variable, fixed-length byte strings, compound or other dtypes, a variable whose
    axes have no dimension names, an unlimited dimension whose variables differ in length — :func:`open_dataset`
    reads what this refuses. Groups other than the root are not read (nor by :func:`open_dataset`).

    ``variables``: read only these (and every coordinate); None reads all. A name the file lacks is no error (the
    caller tests ``name in results``).

    A missing file is a :class:`ResultsError`; a file that is not netCDF4/HDF5 one with :func:`open_dataset`'s words
    ("is not a netCDF4/HDF5 results file"); a dataset that does not read (a damaged chunk) is
    :class:`DamagedResults` ("does not open as netCDF4/HDF5", the words of :func:`count_samples`)."""
    import h5py  # deferred: HDF5 only when a file is read, not in every command's start-up

    path = results_path(path)
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # h5py raises OSError (and others) for a file that is not HDF5
        raise ResultsError(f"{path} is not a netCDF4/HDF5 results file ({type(exc).__name__}: {exc})") from None
    wanted = None if variables is None else set(variables)
    with f:
        try:
            return _read_open(f, path, wanted, h5py)
        except ResultsError:
            raise
        except Exception as exc:  # h5py raises OSError, KeyError, ValueError... for a broken file
            raise DamagedResults(path, f"does not open as netCDF4/HDF5: {type(exc).__name__}") from None


def _read_open(f, path: Path, wanted: set | None, h5py) -> Results:
    """:func:`read_results` of the open HDF5 file ``f`` (``h5py``: the module, imported by the caller)."""
    def refuse(name, why):
        raise ResultsError(f"{path}: variable {name!r} {why}; this reader reads the DPGT recorder's layout "
                           "(open_dataset reads the file)")

    entries = []                   # (variable name, dataset, its attrs, their names): every variable
    dimids: dict[int, str] = {}    # netCDF-4 dimension id -> dimension name
    scales: set[str] = set()
    for hname, obj in f.items():
        if not isinstance(obj, h5py.Dataset):
            continue               # a group or a named datatype: not a variable of the root group
        attrs = obj.attrs
        keys = set(attrs.keys())
        name = hname[len(_NON_COORD):] if hname.startswith(_NON_COORD) else hname
        if "CLASS" in keys and attrs["CLASS"] == b"DIMENSION_SCALE":
            scales.add(hname)
            if "_Netcdf4Dimid" in keys:
                dimids[int(attrs["_Netcdf4Dimid"])] = hname
            if "NAME" in keys and _attr_value(attrs["NAME"]).startswith(_NOT_A_VARIABLE.decode()):
                continue           # a dimension without a coordinate variable
        entries.append((name, obj, attrs, keys))

    dims: dict[str, tuple[str, ...]] = {}
    for name, obj, attrs, keys in entries:
        d = None
        if "_Netcdf4Coordinates" in keys:
            ids = [int(i) for i in np.atleast_1d(attrs["_Netcdf4Coordinates"])]
            if all(i in dimids for i in ids):
                d = tuple(dimids[i] for i in ids)
        if d is None or len(d) != obj.ndim:
            if "DIMENSION_LIST" in keys:        # an HDF5 object look-up per axis: its last scale's name
                refs = attrs["DIMENSION_LIST"]
                d = tuple(f[r[-1]].name.rsplit("/", 1)[-1] for r in refs) if all(len(r) for r in refs) else None
            elif obj.ndim == 1 and obj.name.rsplit("/", 1)[-1] in scales:
                d = (name,)
            elif obj.ndim == 0:
                d = ()
        if d is None or len(d) != obj.ndim:
            refuse(name, f"has no dimension names for its {obj.ndim} axes")
        dims[name] = d

    coords = {n for n in dims if n in {x for d in dims.values() for x in d}}
    for name, obj, attrs, keys in entries:
        if "coordinates" in keys:
            coords.update(str(_attr_value(attrs["coordinates"])).split())
    gkeys = [k for k in f.attrs.keys() if k not in _NC4_HIDDEN]
    gattrs = {k: _attr_value(f.attrs[k]) for k in gkeys}
    if "coordinates" in gattrs:
        coords.update(str(gattrs.pop("coordinates")).split())
    coords &= dims.keys()

    values, vattrs, sizes = {}, {}, {}
    for name, obj, attrs, keys in entries:
        for dim, n in zip(dims[name], obj.shape):
            if sizes.setdefault(dim, n) != n:
                refuse(name, f"has {n} along {dim!r}, other variables {sizes[dim]} (an unlimited dimension of "
                             "ragged variables)")
        if wanted is not None and name not in wanted and name not in coords:
            continue
        va = {k: _attr_value(attrs[k]) for k in keys if k not in _NC4_HIDDEN}
        refused = [k for k in _CF_REFUSED if k in va]
        if " since " in str(va.get("units", "")):
            refused.append(f"units {va['units']!r}")
        if refused:
            refuse(name, f"is CF-encoded ({', '.join(refused)})")
        sinfo = h5py.check_string_dtype(obj.dtype)
        fills = [va[k] for k in ("_FillValue", "missing_value") if k in va]
        if sinfo is not None:
            if sinfo.length is not None:
                refuse(name, f"holds fixed-length byte strings ({obj.dtype})")
            if fills:
                refuse(name, "holds strings with a fill value")
            arr = np.asarray(obj.asstr()[()], dtype=str)
        elif obj.dtype.kind in "fiu":
            arr = np.asarray(obj[()])
            if fills:
                if obj.dtype.kind != "f":
                    refuse(name, f"holds integers with a fill value ({obj.dtype})")
                fv = np.asarray(fills, dtype=obj.dtype).ravel()
                hit = np.isin(arr, fv[~np.isnan(fv)])
                if hit.any():
                    arr = np.where(hit, np.nan, arr).astype(obj.dtype, copy=False)
        else:
            refuse(name, f"has dtype {obj.dtype}, not a number or a string")
        values[name] = arr
        vattrs[name] = {k: v for k, v in va.items() if k not in _CF_DECODED}
    return Results(path=path, variables=values, dims={k: dims[k] for k in values}, coords=frozenset(coords),
                   attrs=gattrs, variable_attrs=vattrs)


def json_attr(attrs: Mapping, key: str, path=None):
    """The results file's attribute ``key`` decoded from JSON (an attribute already decoded is returned as it is);
    ``path`` names the file in the error of one that is not JSON."""
    val = attrs[key]
    if isinstance(val, bytes):
        val = val.decode()
    if isinstance(val, str):
        try:
            return json.loads(val)
        except json.JSONDecodeError as exc:
            raise ResultsError(f"{path or 'the results file'} is not a DPGT results file: attribute {key!r} is not "
                               f"JSON ({exc})") from None
    return val


def load_summary(path) -> Summary | None:
    """summary.json at ``path`` (or in the run folder ``path``) as a :class:`Summary`; None when there is none.
    A file that is not a JSON object is :class:`DamagedResults`."""
    path = Path(path)
    if path.is_dir():
        path = path / SUMMARY_NAME
    if not path.exists():
        return None
    try:
        s = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise DamagedResults(path, f"not readable JSON: {type(exc).__name__}") from None
    if not isinstance(s, dict):
        raise DamagedResults(path, "not a JSON object")
    return Summary(s)


def count_samples(path) -> int:
    """The number of time samples in results.nc (or a run folder's), read from its shape alone. A file that does
    not open as netCDF4/HDF5, or holds no time axis, is :class:`DamagedResults`."""
    import h5py  # deferred: HDF5 only when a file is counted, not in every command's start-up

    path = results_path(path)
    try:
        with h5py.File(path, "r") as f:
            return int(f["time"].shape[0])
    except Exception as exc:        # h5py raises OSError, KeyError, ValueError... for a broken file
        raise DamagedResults(path, f"does not open as netCDF4/HDF5: {type(exc).__name__}") from None


@dataclass(frozen=True)
class RunFiles:
    """A run's files: its ``folder`` and its results file (``results``, the folder's results.nc unless a file of
    another name was opened). Reads nothing until asked."""
    folder: Path
    results: Path

    @property
    def summary_path(self) -> Path:
        return self.folder / SUMMARY_NAME

    @property
    def summary(self) -> Summary | None:
        """The folder's summary.json, read now (None when there is none; :class:`DamagedResults` if it is)."""
        return load_summary(self.summary_path)

    def read(self, variables: Iterable[str] | None = None) -> Results:
        """results.nc in memory (:func:`read_results`)."""
        return read_results(self.results, variables)

    def dataset(self):
        """results.nc as a lazily loaded :class:`xarray.Dataset` (:func:`open_dataset`)."""
        return open_dataset(self.results)

    def samples(self) -> int:
        """How many time samples results.nc holds (:func:`count_samples`)."""
        return count_samples(self.results)


def open_run(path) -> RunFiles:
    """The files of the run in folder ``path``, or of the results file ``path`` (its folder: the file's)."""
    path = Path(path)
    if path.is_file() or path.suffix == ".nc":
        return RunFiles(path.parent, path)
    if path.name == SUMMARY_NAME:
        return RunFiles(path.parent, path.parent / RESULTS_NAME)
    return RunFiles(path, path / RESULTS_NAME)
