"""Is the run a user asked for something a machine and a disk can take? Checked before any run starts.

* Colliding gears (two gears that do not mesh overlap even at their pitch circles, e.g. too many planet pairs
  for the layout; :class:`components.geometry.Finding` ``collides``) are refused: the model has no contact
  between them, so it would run a machine that cannot exist.
* The results are estimated before anything is written (samples = sample rate x window, values per sample
  from the recorder's own layout, 8 bytes each, twice while the chunks are joined into results.nc): a study
  above :data:`MAX_OUTPUT_BYTES`, or one that does not fit the free space of ``--out``, is refused.

Each refusal is :class:`Implausible` (a usage error naming the numbers); ``--force`` runs anyway.
"""
from __future__ import annotations

import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np

import mbd
from components.geometry import design_findings
from mbd.recorder import Recorder

__all__ = ["Implausible", "check_runs", "output_bytes", "MAX_OUTPUT_BYTES"]

MAX_OUTPUT_BYTES = 5e9    # [assumed] more than 5 GB of histories is a mistaken --sample-rate, not a study


class Implausible(Exception):
    """The requested run is implausible (the message names the numbers and says --force runs it anyway)."""


def _collisions(params) -> list[str]:
    return [str(f) for f in design_findings(params) if f.collides]


def output_bytes(scene, window: float, sample_rate: float) -> float:
    """Peak disk use of one run's recording [bytes]: chunks and the results file both exist while it is
    joined. Values per sample from the recorder bound to the scene (the file's own layout)."""
    from .runner import _probes  # deferred: the runner (≈ 1 s, scene builders, outputs) stays out of dpgt's start-up

    with tempfile.TemporaryDirectory() as d:
        rec = Recorder(Path(d) / "probe.nc", dt=1.0 / sample_rate, probes=_probes(scene))
        system = mbd.System(scene.model)
        rec.bind(scene.model, system, mbd.PRODUCTION.stepper().initial_state(system, 0.0, scene.q0, scene.v0))
    per_sample = 1 + sum(int(np.prod([rec.dims.get(x, 2 if x == "axis" else len(rec.coords[x][1]))
                                      for x in dims[1:]])) for dims, _ in rec.vars.values())
    return 2 * 8.0 * per_sample * (window * sample_rate + 1)


def _free(folder) -> float:
    p = Path(folder)
    while not p.exists():
        p = p.parent
    return float(shutil.disk_usage(p).free)


def check_runs(runs, out, force: bool = False) -> list[str]:
    """``runs``: (label, params, RunConfig) of every run to start into ``out``. Raises :class:`Implausible`
    for colliding gears or too much output (unless ``force``); returns what ``force`` let through."""
    # deferred: the scene builders and the runner (≈ 1 s) stay out of dpgt's start-up (command.py imports Implausible)
    from components.dpgt import build_dpgt
    from .runner import statistics_window

    problems, total, sizes = [], 0.0, {}
    for label, params, cfg in runs:
        problems += [f"{label}: {c}" for c in _collisions(params)]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = build_dpgt(params, cfg.options)
        window = cfg.window if cfg.window is not None else statistics_window(scene)
        sizes[label] = output_bytes(scene, window, cfg.sample_rate)
        total += sizes[label]
    if total > MAX_OUTPUT_BYTES:
        big = max(sizes, key=sizes.get)
        problems.append(f"the recording would take {total / 1e9:.1f} GB (largest run {big}: {sizes[big] / 1e9:.1f} GB "
                        f"at its sample rate and window), more than {MAX_OUTPUT_BYTES / 1e9:g} GB; lower --sample-rate "
                        f"(the statistics use every step, the recording is for plots)")
    free = _free(out)
    if total > free:
        problems.append(f"the recording needs {total / 1e9:.2f} GB and {out} has {free / 1e9:.2f} GB free")
    if problems and not force:
        raise Implausible("; ".join(problems) + "; pass --force to run anyway")
    return problems
