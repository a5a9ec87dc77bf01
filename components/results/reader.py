"""The one reader of a run's files: ``results.nc`` (the recorded samples) and ``summary.json`` (the statistics).

* :func:`open_run` — a run's files (:class:`RunFiles`) from its folder or its results.nc; nothing is read until
  asked: :attr:`RunFiles.summary`, :meth:`RunFiles.dataset`, :meth:`RunFiles.samples`.
* :func:`open_dataset` — results.nc as a lazily loaded :class:`xarray.Dataset`; :func:`json_attr` one of its JSON
  attributes ("meta", "bearings", "sensor", ...).
* :func:`load_summary` — summary.json as a :class:`~components.results.summary.Summary` (None when absent).
* :func:`count_samples` — how many time samples results.nc holds, without reading them.

A missing or foreign file is a :class:`ResultsError` whose message says which; a file that exists but does not
read (broken JSON, not a JSON object, not HDF5) is a :class:`DamagedResults` with the reason in the words the run
folder's integrity checks print (:mod:`scenarios.core.integrity` moves such a file aside). Imports nothing of the
project but the summary (viz reads through it without the engine); xarray and h5py are imported when used.
"""
from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from .summary import Summary

__all__ = ["RESULTS_NAME", "SUMMARY_NAME", "ResultsError", "DamagedResults", "RunFiles", "open_run", "results_path",
           "open_dataset", "json_attr", "load_summary", "count_samples"]

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
