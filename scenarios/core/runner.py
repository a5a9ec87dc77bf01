"""One DPGT run, end to end: build the scene, integrate with a checkpoint, record the window, summarise.

Results layout of a run directory:
    results.nc     netCDF4 (xarray/h5py), every variable with CF units and long_name: body motion in R
                   ("motion.position/angle/velocity/angular_velocity/acceleration/angular_acceleration"),
                   sun/carrier/ring in the fixed frame ("fixed.*", same names), and element outputs
                   "<family>.<key>" (e.g. race_inner.load, pocket.force, guide.force, mesh_sa.force) along
                   "<family>.instance", whose coordinates name each instance ("a1.pb.roller3", "sun-a1")
                   with its bearing, planet, pair, bearing_kind, roller (components.results.schema);
                   with RunConfig.sensor what the supports put on the housing ("housing.force_x/force_y/torque",
                   fixed frame) and the sensor's parameters (attrs "sensor"), from which the housing
                   accelerometer's paths are computed (docs/model.md §12, scenarios.spectrum.sensor_paths);
                   attrs hold the run summary and, as JSON, the bearing map, meta, label and geometry
    summary.json   the statistics users read, taken on every accepted step over the window
                   (:class:`components.outputs.WindowStatistics`; the recording is for plots only)
    checkpoint.npz while running; a run started again resumes from it
    fingerprint    what the run was made from (see :func:`run_fingerprint`): a checkpoint or a finished
                   summary from other parameters, settings or engine code is never reused
"""
from __future__ import annotations

import hashlib
import json
import time
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

import mbd
from components.dpgt import build_dpgt
from components.lubrication import BOUNDARY_LAMBDA
from components.params import DPGTParams, flatten
from components.scene import SceneOptions
from components.static import DEFAULT_SNAPSHOTS, check_steady, solve_snapshots, static_summary
from mbd.compile_time import compile_seconds
from mbd.recorder import BodyMotion, Recorder

from components.outputs import BearingSeries, WindowStatistics, bearing_map, cage_period, default_window
from components.sensor import HousingLoads
from components.results import Summary
from components.bearing import row_stations, sliced_law
from components.results.io import append_slice_profiles, atomic_write_text, write_summary
from components.results.schema import drawing_geometry, element_probes

from .integrity import checkpoint_usable, claim_folder, read_summary, results_intact
from .lock import folder_lock
from .memory import RunPeak

__all__ = ["RunConfig", "run_case", "engine_record", "time_record", "TIME_NOTE", "finished_run", "checkpoint_time", "run_fingerprint", "parameters_fingerprint", "run_description", "statistics_window", "run_report",
           "accuracy_line", "code_digest", "FIXED_STEP_ERROR_FACTOR"]

# A fixed-step run whose RMS local error estimate exceeds its tolerance (atol) by more than this factor ends
# with a warning. Measured at condition 3 from the kinematic start: h = 5 us (the cheapest setting,
# docs/numerics.md) 2.7-7.0 x atol; h = 2 us 0.85 x; h = 10 us ("do not use") 33 x.
FIXED_STEP_ERROR_FACTOR = 10.0

_ROOT = Path(__file__).resolve().parents[2]      # the repository (this file: scenarios/core/runner.py)
_CODE_DIGEST = None


def code_digest() -> str:
    """Digest of the code that makes a run's numbers (engine, components, this runner and its analysis)."""
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        h = hashlib.sha256()
        files = sorted([*(_ROOT / "mbd").rglob("*.py"), *(_ROOT / "components").rglob("*.py"),
                        _ROOT / "scenarios" / "core" / "runner.py"])
        for f in files:
            h.update(str(f.relative_to(_ROOT)).encode())
            h.update(f.read_bytes())
        _CODE_DIGEST = h.hexdigest()
    return _CODE_DIGEST


def _settings(cfg: "RunConfig") -> dict:
    """The run settings that identify a run (the progress display is not one; a dynamic run's static-mode
    settings are not either, so the results of runs made before static mode existed stay theirs)."""
    settings = asdict(replace(cfg, progress=False))
    del settings["threads"]          # the same results to the bit on any thread count (mbd.simulate)
    if cfg.mode == "dynamic":
        del settings["mode"], settings["snapshots"]
    if cfg.start == "kinematic":     # the default start: runs made before the choice existed stay theirs
        del settings["start"]
    return settings


def _digest(params: DPGTParams, cfg: "RunConfig", code: bool) -> str:
    settings = _settings(cfg)
    what = {"params": repr(params), "cfg": settings, **({"code": code_digest()} if code else {})}
    return hashlib.sha256(json.dumps(what, sort_keys=True, default=repr).encode()).hexdigest()[:16]


def run_fingerprint(params: DPGTParams, cfg: "RunConfig") -> str:
    """Identifies a run: parameters, run settings (the progress display excluded) and code."""
    return _digest(params, cfg, code=True)


def run_description(params: DPGTParams, cfg: "RunConfig") -> dict[str, str]:
    """Every parameter (dotted key) and run setting as text: what summary.json keeps so that a refusal to replace
    a folder's results can name what differs."""
    out = {k: str(v) for k, v in flatten(params).items()}
    out.update({f"settings.{k}": repr(v) for k, v in _settings(cfg).items()})
    return out


def parameters_fingerprint(params: DPGTParams, cfg: "RunConfig") -> str:
    """Identifies what a user asked for: parameters and run settings, not the code (a folder holding results
    of another one is refused unless --overwrite, :func:`scenarios.core.integrity.claim_folder`)."""
    return _digest(params, cfg, code=False)


@dataclass(frozen=True)
class RunConfig:
    settle: float = 0.03          # s discarded after the start (load ramp, drive and cage transients)
    window: float | None = None   # s recorded and analysed (None: :func:`statistics_window`)
    sample_rate: float = 25000.0  # Hz (> 4 f_m at condition 3)
    integration: mbd.IntegratorSettings = mbd.PRODUCTION
    options: SceneOptions = field(default_factory=SceneOptions)
    progress: bool = True
    checkpoint_every: int = 2000
    sensor: bool = False          # record what the housing accelerometer needs (rig.sensor, docs/model.md §12)
    mode: str = "dynamic"         # "static": the quasi-static solution of the same model (components.static)
    snapshots: int = DEFAULT_SNAPSHOTS    # static mode: instants over a carrier revolution and the mesh cycle
    start: str = "kinematic"      # dynamic mode: from the kinematic state with the torque ramped in (docs/model.md
    #                               §10.4), or "static": from the static solution at the ramp's end (components.static)
    threads: int = 1              # dynamic mode: threads of the run's compiled engine (mbd.simulate; the same results)

    def __post_init__(self):
        if self.mode not in ("dynamic", "static"):
            raise mbd.ModelError(f"mode must be 'dynamic' or 'static', got {self.mode!r}")
        if self.start not in ("kinematic", "static"):
            raise mbd.ModelError(f"start must be 'kinematic' or 'static', got {self.start!r}")
        if not (isinstance(self.snapshots, (int, np.integer)) and self.snapshots >= 1):
            raise mbd.ModelError(f"snapshots must be an integer >= 1, got {self.snapshots!r}")
        for k in ("settle", "window"):
            if getattr(self, k) is not None and not (np.isfinite(getattr(self, k)) and getattr(self, k) >= 0):
                raise mbd.ModelError(f"{k} must be >= 0 s, got {getattr(self, k)!r}")
        if self.window is not None and not self.window > 0:
            raise mbd.ModelError(f"window must be > 0 s, got {self.window!r}")
        if not self.sample_rate > 0:
            raise mbd.ModelError(f"sample_rate must be > 0 Hz, got {self.sample_rate!r}")
        if self.threads != 1 or isinstance(self.threads, bool):
            from mbd.compiled.system import check_threads   # deferred: numba, for a run that asks for threads only
            check_threads(self.threads)


def statistics_window(scene, base: float = 0.02) -> float:
    """Default window [s]: at least ``base`` and one carrier revolution, rounded up to whole revolutions
    of the slowest cage relative to the carrier (docs/model.md §13.3)."""
    sp, b = scene.speeds, scene.bearing
    wc = sp.carrier
    if wc != 0.0:
        base = max(base, 2 * np.pi / abs(wc))
    if scene.options.bearings != "rollers":
        return base
    return default_window(base, [cage_period(b, wc, sp.planet(k)) for k in ("inner", "outer")])


def _probes(scene, sensor: bool = False) -> list:
    """Body motion in R (all bodies) and in the fixed frame (sun, carrier, ring), the element outputs of
    :mod:`components.results.schema` (units, long names, instance coordinates), and with ``sensor`` the
    loads on the housing (:class:`components.sensor.HousingLoads`)."""
    return [BodyMotion("motion", frame="reference"),
            BodyMotion("fixed", bodies=["sun", "carrier", "ring"], frame="fixed"),
            *element_probes(scene), *BearingSeries(scene).probes(),
            *(HousingLoads(scene).probes() if sensor else [])]


def finished_run(out_dir, params: DPGTParams, cfg: RunConfig) -> Summary | None:
    """The summary of ``out_dir`` if a run of these parameters, settings and code finished there and its results.nc
    is intact (it is then reused, not recomputed), else None."""
    out = Path(out_dir)
    s = read_summary(out / "summary.json")
    if s is None or s.get("fingerprint") != run_fingerprint(params, cfg):
        return None
    if s.get("mode") == "static":      # a static solution writes no results.nc
        return s
    return s if results_intact(out / "results.nc", s.get("samples")) else None


def _own_checkpoint(out_dir: Path, fp: str) -> bool:
    """Whether ``out_dir`` holds a checkpoint of the run whose fingerprint is ``fp`` (the folder's fingerprint file is
    written as a run starts)."""
    fp_file = out_dir / "fingerprint"
    return (out_dir / "checkpoint.npz").exists() and fp_file.exists() and \
        fp_file.read_text(errors="replace").strip() == fp


def checkpoint_time(out_dir, params: DPGTParams, cfg: RunConfig) -> float | None:
    """The simulated time [s] a run of these parameters, settings and code would resume from in ``out_dir`` (its
    checkpoint's), else None (no checkpoint of this run there, or one that does not load)."""
    out = Path(out_dir)
    if not _own_checkpoint(out, run_fingerprint(params, cfg)):
        return None
    try:
        with np.load(out / "checkpoint.npz") as d:
            return float(d["t"])
    except Exception:       # damaged: the run moves it aside and starts afresh (checkpoint_usable)
        return None


def run_case(params: DPGTParams, cfg: RunConfig, out_dir, label: dict | None = None, overwrite: bool = False) -> Summary:
    """Run one operating point; write results.nc and summary.json atomically into out_dir.
    An interrupted run resumes from out_dir/checkpoint.npz. One run at a time per folder (scenarios.core.lock).
    A folder holding finished results of other parameters is refused unless ``overwrite``
    (:func:`scenarios.core.integrity.claim_folder`); damaged files there are moved aside and recomputed."""
    with folder_lock(out_dir):
        how = claim_folder(out_dir, parameters_fingerprint(params, cfg), run_fingerprint(params, cfg), overwrite,
                           description=run_description(params, cfg))
        if how == "recompute":
            print(f"{out_dir}: recomputing, its results were made by other code")
        if cfg.mode == "static":
            return _run_static(params, cfg, Path(out_dir), label)
        return _run_case(params, cfg, Path(out_dir), label)


def run_timing(parts: dict, total: float, peak: RunPeak) -> dict:
    """summary.json's ``timing``: wall seconds of this segment of the run by part (README: What summary.json holds),
    the rest of ``total`` as ``other_s``, and the run's peak resident memory."""
    out = {k: float(v) for k, v in parts.items()}
    out["other_s"] = max(total - sum(out.values()), 0.0)
    out["total_s"] = total
    out["peak_rss_MB"] = peak.mb()
    out["peak_rss_per_run"] = peak.per_run
    return out


def _run_static(params: DPGTParams, cfg: RunConfig, out_dir: Path, label: dict | None) -> Summary:
    """The quasi-static solution (:mod:`components.static`) of one operating point: summary.json in the dynamic
    run's keys, those only a dynamic run gives left out (listed in ``omitted``); no results.nc."""
    t0, peak = time.perf_counter(), RunPeak()
    check_steady(params)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # design warnings were shown once by the caller
        scene = build_dpgt(params, cfg.options)
    out_dir.mkdir(parents=True, exist_ok=True)
    summary = _run_info(params, scene, None)
    summary["statistics"] = (f"quasi-static: the mean of {cfg.snapshots} static solutions spread over the mesh and "
                             "roller positions (components.static); max over them")
    summary.update(static_summary(scene, cfg.snapshots))
    summary.update(label or {})
    summary.update({"warnings": validity_warnings(params.si(), summary), "wall_s": summary["static_solver"]["wall_s"],
                    "fingerprint": run_fingerprint(params, cfg),
                    "parameters_fingerprint": parameters_fingerprint(params, cfg),
                    "run_description": run_description(params, cfg)})
    summary["timing"] = run_timing({"static_s": summary["static_solver"]["wall_s"]}, time.perf_counter() - t0, peak)
    write_summary(out_dir, summary)
    return Summary(summary)


def _earlier_times(out_dir: Path, resuming: bool) -> tuple[float, float]:
    """(wall, compile) time [s] of the earlier segments of a resumed run (progress.json keeps the running totals)."""
    try:
        d = json.loads((out_dir / "progress.json").read_text()) if resuming else {}
        return float(d.get("wall_s", 0.0)), float(d.get("compile_s", 0.0))
    except (OSError, ValueError, TypeError, AttributeError):
        return 0.0, 0.0


TIME_NOTE = ("wall_s: the run's wall time without compiling or loading the compiled kernels; compile_s: that compile "
             "or load (numba: about a second from its cache, a minute or more on the first run of the code on a machine)")


def time_record(wall_s: float, compile_s: float) -> dict:
    """summary.json's run times: ``wall_s`` the run without the kernels' compile or load, ``compile_s`` that (timed
    where it happens, :mod:`mbd.compile_time`), and ``time_note`` saying which is which."""
    return {"wall_s": wall_s, "compile_s": compile_s, "time_note": TIME_NOTE}


def _static_start(scene, settle: float):
    """(q, v, t) of the static solution at the load ramp's end, or the first of the instants a third of a mesh period
    apart after it (up to the settling time) that has one (components.static.solve_snapshots: an instant resting on a
    force's jump has none)."""
    step = 1.0 / (3.0 * scene.f_m) if scene.f_m > 0 else settle
    first = None
    for t in [min(scene.ramp + k * step, settle) for k in range(6)]:
        try:
            s = solve_snapshots(scene, [t])[0]
            return s.q, s.v, s.t
        except mbd.ModelError as exc:
            first = first or exc
    raise first


def _run_case(params: DPGTParams, cfg: RunConfig, out_dir: Path, label: dict | None) -> Summary:
    start, compile0, peak = time.perf_counter(), compile_seconds(), RunPeak()

    def times():     # (wall, compile) of this segment [s]: the compile is timed where it happens, and taken out
        c = compile_seconds() - compile0
        return time.perf_counter() - start - c, c

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # design warnings were shown once by the caller
        scene = build_dpgt(params, cfg.options)
    bmap = bearing_map(scene)
    window = cfg.window if cfg.window is not None else statistics_window(scene)
    stats = WindowStatistics(scene, cfg.settle, cfg.settle + window)
    sensor = {"sensor": params.si().rig.sensor.to_dict()} if cfg.sensor else {}
    rec = Recorder(out_dir / "results.nc", dt=1.0 / cfg.sample_rate, probes=_probes(scene, cfg.sensor), t_start=cfg.settle,
                   attrs={"Conventions": "CF-1.10",
                          "title": f"DPGT run: carrier {params.si().operating.carrier_speed * 30 / np.pi:.0f} r/min, "
                                   f"{params.si().operating.output_power / 1e3:.0f} kW, {params.si().operating.direction}",
                          "bearings": bmap, "meta": scene.run_metadata(), "label": label or {},
                          "geometry": drawing_geometry(params), **sensor})
    integ = cfg.integration
    t_end = stats.t_end          # the window plus a margin for slipping cages (WindowStatistics)
    fp = run_fingerprint(params, cfg)
    fp_file = out_dir / "fingerprint"
    ckpt = out_dir / "checkpoint.npz"
    if ckpt.exists() and not _own_checkpoint(out_dir, fp):
        # a checkpoint of another run (other parameters, settings or code): start afresh, say so
        print(f"{out_dir}: the checkpoint there is from a different run (parameters, settings or code); starting afresh")
        ckpt.unlink()
    resuming = checkpoint_usable(ckpt, rec.parts)     # a damaged checkpoint or chunk is moved aside
    atomic_write_text(fp_file, fp)
    earlier = _earlier_times(out_dir, resuming)      # wall_s and compile_s count every segment
    scene_s, c_scene = times()      # the scene, statistics, recorder and folder (and any kernels they loaded)

    def report(t, t_end, counters):   # read by a sweep's progress display (another process) and a resume
        wall, comp = (a + b for a, b in zip(times(), earlier))
        atomic_write_text(out_dir / "progress.json", json.dumps(
            {"t": t, "t_end": t_end, "wall_s": wall, "compile_s": comp, "steps": counters.accepted}))

    q0, v0, t0 = scene.q0, scene.v0, 0.0
    if cfg.start == "static":       # the machine at rest in its frame under its full load, at the ramp's end
        q0, v0, t0 = _static_start(scene, cfg.settle)
    res = mbd.simulate(scene.model, q0, v0, t_end, t0=t0, stepper=integ.stepper(), controller=integ.controller(),
                       engine=integ.engine, threads=cfg.threads,
                       recorder=rec, checkpoint=mbd.Checkpoint(out_dir / "checkpoint.npz", cfg.checkpoint_every),
                       resume=True, progress=cfg.progress, failed_state_path=out_dir / "failed_state.npz",
                       on_progress=report, observers=[stats])
    (out_dir / "progress.json").unlink(missing_ok=True)
    wall, compile_s = (a + b for a, b in zip(times(), earlier))
    t_stats = time.perf_counter()
    summary = _run_info(params, scene, stats)
    summary.update(stats.summary())
    profiles = stats.slice_profiles()          # the sliced model's: along the most loaded rollers, into results.nc
    if profiles is not None and res.results_path is not None:
        b = scene.bearing
        append_slice_profiles(res.results_path, profiles, sliced_law(b)["z"], row_stations(b))
    stats_summary_s = time.perf_counter() - t_stats
    summary["samples"] = int(rec.next_index)      # recorded (for plots); the statistics use every step
    summary.update(label or {})
    summary.update({
        "warnings": (accuracy_warnings(integ, res.error_rms) + statistics_warnings(summary, scene.ramp, cfg.settle)
                     + validity_warnings(params.si(), summary)),
        **time_record(wall, compile_s), "steps": res.steps, "rejected_steps": res.counters["rejected"],
        "newton_per_step": res.counters["newton"] / max(res.steps, 1),
        **engine_record([res]),
        "resumed_from_s": res.resumed_from,
        "error_estimate": {
            "kind": "HHT local displacement error estimate (Zienkiewicz-Xie, (beta-1/6) h^2 (a1-a0)), "
                    "scaled by atol; RMS and max over accepted steps",
            "rms": res.error_rms, "max": res.error_max, "atol_m": integ.atol_pos,
            "max_local_displacement_error_m": res.error_max * integ.atol_pos,
        },
        "integration": integration_record(integ),
        "fingerprint": fp, "parameters_fingerprint": parameters_fingerprint(params, cfg),
        "run_description": run_description(params, cfg),
    })
    tm, kernels = res.timing, compile_seconds() - compile0
    # this segment's parts; kernels_s is the compile or load of every kernel group, which happened in simulate's
    # set-up (the runner) and binding (the outputs, the statistics' accumulators): taken out of those
    summary["timing"] = run_timing({
        "scene_s": scene_s, "runner_setup_s": tm["setup_s"] + tm["bind_s"] - (kernels - c_scene),
        "kernels_s": kernels,
        "engine_s": tm["engine_s"], "statistics_s": tm["observers_s"] + stats_summary_s,
        "recording_s": tm["recording_s"], "results_write_s": tm["results_s"], "checkpoints_s": tm["checkpoints_s"]},
        time.perf_counter() - start, peak)
    write_summary(out_dir, summary)
    return Summary(summary)


def engine_record(results) -> dict:
    """summary.json's ``engine`` (which engine path ran: "compiled" or "numpy") and ``engine_note`` (why "auto" fell
    back to numpy; None when it did not), from the :class:`mbd.SimResult` of each ``simulate`` call of one run (one
    for :func:`run_case`, one per sampled piece for the bearing rig). The pieces of a run share its system and
    settings, so one path ran; a mix would be a bug, and is refused rather than reported as one of them."""
    paths = {(r.engine, r.engine_note) for r in results}
    if len(paths) != 1:
        raise mbd.ModelError(f"engine_record: expected the results of one engine path, got {sorted(paths, key=str)}")
    engine, note = paths.pop()
    return {"engine": engine, "engine_note": note}


# the unit of each IntegratorSettings field, as summary.json's key suffix (README: What summary.json holds)
INTEGRATION_UNITS = {"h": "s", "h_max": "s", "h_min": "s", "atol_pos": "m", "atol_rot": "rad"}


def integration_record(integ: mbd.IntegratorSettings) -> dict:
    """The integrator settings as summary.json keeps them: every field with a unit carries it as a suffix
    (``h_s``, ``atol_pos_m``, ``atol_rot_rad``)."""
    return {(f"{k}_{INTEGRATION_UNITS[k]}" if k in INTEGRATION_UNITS else k): v for k, v in asdict(integ).items()}


def accuracy_warnings(integ: mbd.IntegratorSettings, error_rms: float) -> list[str]:
    """Why a run's accuracy is doubtful (an adaptive run holds its tolerance; a fixed step may not)."""
    if integ.method == "hht-fixed" and error_rms > FIXED_STEP_ERROR_FACTOR:
        return [f"fixed step h = {integ.h:g} s: RMS local error estimate {error_rms:.1f} x the tolerance "
                f"{integ.atol_pos:g} m (more than {FIXED_STEP_ERROR_FACTOR:g} x); use a smaller --h or hht-adaptive"]
    return []


SETTLED_SPEED_ERROR_PCT = 0.1     # the carrier drive counts as settled within 0.1 % of its speed (README: --settle)


def statistics_warnings(summary: dict, ramp: float, settle: float) -> list[str]:
    """Statistics that cannot mean anything, said instead of reported silently: a bearing whose cage turned less
    than once relative to the carrier in the window (its rollers have not all passed the load zone: per-revolution
    counts, roller and cage statistics depend on where the window started), a carrier drive not settled in the
    window (its speed off by more than 0.1 % on average: the 80 runs of the gear-quality study, real teeth shaking
    it by up to 1.3 %, averaged ≤ 0.06 % after the default 30 ms), a load ramp (``ramp`` [s]) that ends inside
    the window."""
    out = []
    for kind in ("inner", "outer"):
        d = summary.get(kind, {})
        revs = d.get("cage_revolutions")
        if revs is not None and revs < 1.0:
            span = d["window_s"][1] - d["window_s"][0]
            out.append(f"{kind} planet bearings: the window covers {revs:.2f} cage revolutions relative to the carrier "
                       f"(< 1): roller, cage and per-revolution statistics do not mean anything; a window of at least "
                       f"{span / max(revs, 1e-9):.3g} s covers one")
    err = summary.get("carrier_speed_error_mean_pct")
    if err is not None and abs(err) > SETTLED_SPEED_ERROR_PCT:
        out.append(f"the carrier drive had not settled: its speed is off by {err:+.2g} % on average over the window "
                   f"(more than {SETTLED_SPEED_ERROR_PCT:g} %); a longer --settle than {settle:g} s discards the transient")
    if ramp > settle:
        out.append(f"the sun-torque ramp ({ramp:.3g} s) ends inside the window (settle {settle:g} s): the statistics "
                   "include the load rising")
    return out


def validity_warnings(si, summary: dict) -> list[str]:
    """Where a finished run left the model's range of validity. The EHL traction law is a law of the film alone:
    where the thinnest film falls below Λ ≈ 1 (too slow, or too thin an oil: boundary-dominated) asperities
    carry much of the load and friction, which the model does not have, so its traction there is not to be
    trusted (between Λ = 1 and 3, partial EHL, they carry some). Pan & Hamrock's film
    fit is a regression: where it gives h_c < h_min (the heaviest loaded contacts) it is outside its range
    (one warning per run, naming the bearing types)."""
    out = []
    if si.bearing.traction_law == "ehl":
        for kind in ("inner", "outer"):
            lam = summary.get(kind, {}).get("lambda_min")
            if lam is not None and lam < BOUNDARY_LAMBDA:
                out.append(f"{kind} planet bearings: thinnest film Λ_min = {lam:.2f} < {BOUNDARY_LAMBDA:g} "
                           f"(h_min {summary[kind]['film_min_m'] * 1e6:.3g} µm): boundary-dominated at this speed and "
                           f"oil, outside the EHL traction law's validity (no asperity friction is modelled)")
    beyond = {k: summary[k] for k in ("inner", "outer")
              if summary.get(k, {}).get("film_central_ratio_min", 1.0) < 1.0}
    if beyond:
        where = "; ".join(f"{k} planet bearings: W' up to {d['film_load_parameter_max']:.3g}, h_c/h_min down to "
                          f"{d['film_central_ratio_min']:.4f}" for k, d in beyond.items())
        out.append(f"Pan & Hamrock's film fit used beyond its range (it gives h_c < h_min at the most loaded "
                   f"contacts) — {where}: the films there are extrapolated")
    return out


def accuracy_line(wall_s: float, steps: int, error_rms: float, error_max: float, atol_m: float,
                  compile_s: float | None = None) -> str:
    """Run time and error estimate, as every scenario prints them; with ``compile_s`` the kernels' compile or load
    beside the wall time, which leaves it out."""
    comp = f" (+ {compile_s:.1f} s compiling or loading the kernels)" if compile_s is not None else ""
    return (f"{wall_s:.1f} s wall{comp}, {steps} steps, local error estimate rms {error_rms:.2f} / max {error_max:.2f} "
            f"x {atol_m:.0e} m")


def run_report(s: dict) -> list[str]:
    """Lines for a finished run's summary: run time and error estimate (a static solution: its snapshots and
    continuation steps), then any warning."""
    if s.get("mode") == "static":
        head = (f"{s['wall_s']:.1f} s wall, quasi-static: {s['snapshots']} snapshots, "
                f"{s['static_solver']['steps']} continuation steps")
    else:
        e = s["error_estimate"]
        head = accuracy_line(s["wall_s"], s["steps"], e["rms"], e["max"], e["atol_m"], s.get("compile_s"))
    return [head, *(f"warning: {w}" for w in s.get("warnings", []))]


def sweep_report(results: dict) -> list[str]:
    """Run time, error estimate and warnings of every finished run of a sweep ({label: summary}), a line each."""
    lines = []
    for k, s in sorted(results.items()):
        if not Summary.of(s).failed and ("error_estimate" in s or s.get("mode") == "static"):
            first, *warns = run_report(s)
            lines += [f"  {k}: {first}", *(f"  {k}: {w}" for w in warns)]
    return lines


def _run_info(params: DPGTParams, scene, stats: WindowStatistics) -> dict:
    """What was run: operating point, machine size, window, characteristic frequencies."""
    si = params.si()
    op = si.operating
    return {
        "condition": None, "direction": op.direction, "carrier_rpm": op.carrier_speed * 30 / np.pi,
        "sun_rpm": op.sun_speed * 30 / np.pi, "power_W": float(op.output_power),
        "planets": int(si.gears.planets), "rollers": int(si.bearing.rollers), "rows": int(si.bearing.rows),
        "backlash_m": {k: m.backlash for k, m in si.layout.meshes.items()},
        "f_m_hz": scene.f_m, "f_c_hz": scene.f_c,
        "statistics": "time-weighted over every accepted step in the window (trapezoid); max over the steps; "
                      "radial/tangential in the carrier frame (radial: carrier axis -> planet centre)",
    }
