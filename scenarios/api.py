"""The Python entry point for scripts and notebooks: one run of the DPGT, as the commands make it.

    import scenarios

    params = scenarios.parameters(condition=3, direction="reverse", set={"bearing.clearance": "30 um"})
    run = scenarios.run(params, "results/mine", settle=0.03)       # or scenarios.run(condition=3, ...)
    run.summary["outer"]["bearing_load_mean_N"]                    # summary.json (README: what it holds)
    ds = run.dataset()                                              # results.nc, opened with xarray

The run is the one every study makes (:func:`scenarios.core.runner.run_case`: the production integrator, statistics
on every accepted step, results.nc and summary.json written atomically, checkpoints, resume). A folder holding
the finished run of the same parameters, settings and code is reused (``run.status == "reused"``); one holding
results of other parameters is refused unless ``overwrite=True``.
"""
from __future__ import annotations

import sys
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import mbd
from components import faults
from components.geometry import check_design
from components.params import with_overrides
from components.presets import load_toml, reference_dpgt
from components.results import Summary, open_dataset
from components.scene import SceneOptions

from .core.runner import RunConfig, finished_run, run_case

__all__ = ["Run", "run", "parameters"]


@dataclass(frozen=True)
class Run:
    """A finished run: its folder, its summary (summary.json) and whether it ran now (``"finished"``) or was
    taken from an earlier run of the same parameters, settings and code (``"reused"``)."""
    out: Path
    summary: Summary
    status: str

    @property
    def results(self) -> Path:
        """results.nc of the run."""
        return self.out / "results.nc"

    @property
    def wall_s(self) -> float:
        """Wall time of the run that made the results (for a reused one: when it ran)."""
        return self.summary["wall_s"]

    def dataset(self):
        """results.nc as an :class:`xarray.Dataset` (close it when done, or use it in a ``with``)."""
        return open_dataset(self.results)

    def __repr__(self) -> str:
        return f"Run({str(self.out)!r}, {self.status}, {self.summary.get('wall_s', float('nan')):.1f} s wall)"


def parameters(condition: int = 3, direction: str = "forward", set: dict | None = None, params_file=None):
    """The reference machine at an operating condition (docs/parameters.md) and direction, with a TOML file's and then
    ``set``'s dotted overrides (the keys `dpgt params` lists): a :class:`components.params.DPGTParams`."""
    params = reference_dpgt(condition, direction)
    if params_file is not None:
        params = load_toml(params_file, base=params)
    return with_overrides(params, set)


def run(params=None, out=None, *, condition: int = 3, direction: str = "forward", set: dict | None = None,
        settle: float = 0.03, window: float | None = None, sample_rate: float = 25000.0, options: dict | None = None,
        integration=None, sensor: bool = False, progress: bool = True, overwrite: bool = False, threads: int = 1) -> Run:
    """Run ``params`` (default: :func:`parameters` of ``condition`` and ``direction``; ``set`` overrides either)
    into the folder ``out`` (default: a new temporary folder) and return the :class:`Run`.

    ``settle``, ``window`` [s] and ``sample_rate`` [Hz] as the commands' options (``window`` None: whole cage
    revolutions, README "Defaults"); ``options``: scene switches (:class:`components.scene.SceneOptions` fields,
    e.g. ``{"drag": False}``); ``integration``: :class:`mbd.IntegratorSettings` (default ``mbd.PRODUCTION``);
    ``sensor``: record what the housing accelerometer needs; ``threads``: the engine's threads (the same results; on
    idle cores only, docs/numerics.md §5 "Threads"). The design is checked first (its warnings are
    Python warnings); bad parameters raise :class:`components.units.ParameterError`."""
    label = {}
    if params is None:
        params = parameters(condition, direction, set)
        label = {"condition": condition, "direction": direction}
    elif set:
        params = with_overrides(params, set)
    check_design(params)
    faults.check_errors(params.si())
    cfg = RunConfig(settle=settle, window=window, sample_rate=sample_rate, integration=integration or mbd.PRODUCTION,
                    options=SceneOptions.from_dict(options), progress=progress, sensor=sensor, threads=threads)
    out = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="dpgt-run-"))
    s = finished_run(out, params, cfg)
    if s is not None:
        return _said(Run(out, s, "reused"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the design's warnings were given above
        s = run_case(params, cfg, out, label=label, overwrite=overwrite)
    return _said(Run(out, s, "finished"))


def _said(run: "Run") -> "Run":
    """The run's statistics warnings (summary.json ``warnings``: a window too short to mean anything, an unsettled
    drive), one line each on stderr, as the commands print them."""
    for w in run.summary.get("warnings", []):
        print(f"warning: {w}", file=sys.stderr, flush=True)
    return run
