"""Is the run a user asked for something a machine and a disk can take? Checked before any run starts.

* Colliding gears (two gears that do not mesh overlap even at their pitch circles, e.g. too many planet pairs
  for the layout; :class:`components.geometry.Finding` ``collides``) are refused: the model has no contact
  between them, so it would run a machine that cannot exist.
* The results are estimated before anything is written (samples = sample rate x window, values per sample
  from the recorder's own layout, 8 bytes each, twice while the chunks are joined into results.nc): a study
  above :data:`MAX_OUTPUT_BYTES`, or one that does not fit the free space of ``--out``, is refused.

Each refusal is :class:`Implausible` (a usage error naming the numbers); ``--force`` runs anyway.

What would run but mean little is said before the run too (:func:`check_runs`' ``advice``): a dynamic run whose
window is shorter than a revolution of a cage relative to the carrier (its roller and cage statistics would depend
on where the window starts), a settle shorter than the sun torque's ramp (the statistics would include the load
rising) or than the time the carrier drive takes to settle (the default ``--settle``, README: defaults); and an
estimate of the run time.
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

__all__ = ["Implausible", "check_runs", "output_bytes", "MAX_OUTPUT_BYTES", "run_advice", "estimated_wall_s"]

MAX_OUTPUT_BYTES = 5e9    # [assumed] more than 5 GB of histories is a mistaken --sample-rate, not a study
# [measured] wall seconds per simulated second of a dynamic run, two at a time on a shared 2-core machine: the seed
# study's runs 50 (condition 4) to 115 (condition 1), a new user's `make demo` beside other work 150; and of one
# static solution (16 snapshots): 0.8-2 s quiet, up to 12 s loaded (a new user's duty cycles and static studies).
# An order of magnitude for the estimate said before a study runs, not a benchmark (scenarios.bench_study)
WALL_PER_SIMULATED_S = 120.0
STATIC_WALL_S = 3.0


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


def run_advice(scene, cfg, window: float) -> list[str]:
    """What a dynamic run of ``scene`` with the settings ``cfg`` and the statistics window ``window`` [s] would get
    wrong, said before it runs (module docstring); nothing for a static solution."""
    # deferred: the runner (≈ 1 s) stays out of dpgt's start-up (command.py imports Implausible)
    from components.outputs import cage_period
    from .runner import RunConfig

    if cfg.mode == "static":
        return []
    out = []
    sp = scene.speeds
    if scene.options.bearings == "rollers" and sp.carrier != 0.0:
        periods = {k: cage_period(scene.bearing, sp.carrier, sp.planet(k)) for k in ("inner", "outer")}
        short = {k: T for k, T in periods.items() if np.isfinite(T) and window < T}
        if short:
            out.append(f"the window {window:.3g} s is shorter than a revolution of the cage relative to the carrier ("
                       + ", ".join(f"{k} {T:.3g} s" for k, T in short.items()) + "): the roller, cage and "
                       "per-revolution statistics would depend on where the window starts; --window "
                       f"\"{1e3 * max(short.values()):.3g} ms\" or more covers one")
    drive = RunConfig.settle                   # the default settle: the carrier drive's settling time (README)
    if cfg.settle < scene.ramp:
        out.append(f"the settle {cfg.settle:.3g} s ends before the sun torque's ramp ({scene.ramp:.3g} s): the "
                   f"statistics would include the load rising")
    elif cfg.settle < drive:
        out.append(f"the settle {cfg.settle:.3g} s is shorter than the {drive:g} s the carrier speed drive takes to "
                   f"settle: the window may hold its transient (said after the run if it does)")
    return out


def estimated_wall_s(runs: list[tuple[str, float | None]], workers: int) -> float:
    """The wall time [s] of ``runs`` ((label, simulated seconds, None for a static solution)) on ``workers`` at once,
    from the measured rates :data:`WALL_PER_SIMULATED_S` and :data:`STATIC_WALL_S`: each run's time, the runs dealt
    to the workers longest first."""
    times = sorted((STATIC_WALL_S if t is None else WALL_PER_SIMULATED_S * t for _, t in runs), reverse=True)
    load = [0.0] * max(1, min(workers, len(times) or 1))
    for t in times:
        load[load.index(min(load))] += t
    return max(load) if times else 0.0


def check_runs(runs, out, force: bool = False, advice: list | None = None) -> list[str]:
    """``runs``: (label, params, RunConfig) of every run to start into ``out``. Raises :class:`Implausible`
    for colliding gears or too much output (unless ``force``); returns what ``force`` let through. ``advice``: a
    list to fill with (label, what the run would get wrong) (:func:`run_advice`) and (label, simulated seconds or
    None for a static solution) as ``("time", label, seconds)``."""
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
        if advice is not None:
            power = params.si().operating.output_power
            if power < 0:       # meant, or a sign typed by mistake: said before it runs
                advice.append((label, f"the output power is negative ({power / 1e3:g} kW): the machine brakes — the "
                                      f"carrier drives the sun, the loaded flanks turn over (README: Operating points)"))
            advice += [(label, w) for w in run_advice(scene, cfg, window)]
            advice.append(("time", label, None if cfg.mode == "static" else cfg.settle + window))
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
