"""One DPGT run, end to end: build the scene, integrate with a checkpoint, record the window, summarise.

Results layout of a run directory:
    results.nc     netCDF4 (xarray/h5py): body motion in R ("motion.q/v/a"), carrier/sun/ring in the
                   fixed frame ("fixed.q/v/a"), and element outputs "<family>.<key>" (e.g.
                   race_inner.load, pocket.force, guide.force, mesh_sa.force); attrs hold the run summary
                   and the bearing map (which family instances belong to which bearing)
    summary.json   the statistics users read (see :func:`summarize`)
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
from components.dpgt import RigSettings, build_dpgt
from components.params import DPGTParams
from components.scene import SceneOptions
from mbd.recorder import BodyMotion, ElementOutput, Recorder, atomic_write_text

from .analysis import bearing_equivalent_load, rms, window

__all__ = ["Integration", "RunConfig", "run_case", "summarize", "bearing_map", "run_fingerprint"]

_ROOT = Path(__file__).resolve().parent.parent
_CODE_DIGEST = None


def _code_digest() -> str:
    """Digest of the code that makes a run's numbers (engine, components, this runner and its analysis)."""
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        h = hashlib.sha256()
        files = sorted([*(_ROOT / "mbd").rglob("*.py"), *(_ROOT / "components").rglob("*.py"),
                        _ROOT / "scenarios" / "runner.py", _ROOT / "scenarios" / "analysis.py"])
        for f in files:
            h.update(str(f.relative_to(_ROOT)).encode())
            h.update(f.read_bytes())
        _CODE_DIGEST = h.hexdigest()
    return _CODE_DIGEST


def run_fingerprint(params: DPGTParams, cfg: "RunConfig") -> str:
    """Identifies a run: parameters, run settings (the progress display excluded) and code."""
    settings = asdict(replace(cfg, progress=False))
    blob = json.dumps({"params": repr(params), "cfg": settings, "code": _code_digest()}, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Integration:
    """Integrator choice for a run. ``method``: "hht-adaptive" (default) or "hht-fixed"."""
    method: str = "hht-adaptive"
    alpha: float = -0.3
    h: float = 5e-6              # fixed step, or the initial step of the adaptive controller [s]
    h_max: float = 1e-5
    atol_pos: float = 1e-8       # m: local displacement error target of the adaptive controller
    atol_rot: float = 1e-6       # rad

    def __post_init__(self):
        if self.method not in ("hht-adaptive", "hht-fixed"):
            raise mbd.ModelError(f"integration.method must be 'hht-adaptive' or 'hht-fixed', got {self.method!r}")

    def stepper(self) -> mbd.HHT:
        return mbd.HHT(alpha=self.alpha, tol=mbd.Tolerance(atol_pos=self.atol_pos, atol_rot=self.atol_rot))

    def controller(self):
        if self.method == "hht-fixed":
            return mbd.FixedStep(self.h)
        return mbd.Adaptive(h0=self.h, h_max=self.h_max, h_min=1e-9)


@dataclass(frozen=True)
class RunConfig:
    settle: float = 0.03          # s discarded after the start (load ramp, drive and cage transients)
    window: float = 0.02          # s recorded and analysed
    sample_rate: float = 25000.0  # Hz (> 4 f_m at condition 3)
    integration: Integration = field(default_factory=Integration)
    options: SceneOptions = field(default_factory=SceneOptions)
    rig: RigSettings = field(default_factory=RigSettings)
    progress: bool = True
    checkpoint_every: int = 2000

    def __post_init__(self):
        for k in ("settle", "window"):
            if not (np.isfinite(getattr(self, k)) and getattr(self, k) >= 0):
                raise mbd.ModelError(f"{k} must be >= 0 s, got {getattr(self, k)!r}")
        if self.window <= 0:
            raise mbd.ModelError(f"window must be > 0 s, got {self.window!r}")
        if not self.sample_rate > 0:
            raise mbd.ModelError(f"sample_rate must be > 0 Hz, got {self.sample_rate!r}")


def bearing_map(scene) -> list[dict]:
    """Per bearing: name, kind (inner/outer), pair index, planet, cage, and the instance slices of the
    roller families (all rollers of all bearings share one family each, in bearing order)."""
    out = []
    for n, pair in enumerate(scene.handles["pairs"]):
        for kind in ("inner", "outer"):
            h = pair[f"{kind}_bearing"]
            rec = {"name": f"{pair[kind]}.pb", "kind": kind, "pair": n, "planet": pair[kind],
                   "type": h["kind"]}
            if h["kind"] == "rollers":
                rec.update({"rollers": h["rollers"], "race_inner": [h["race_inner"].start, h["race_inner"].stop],
                            "race_outer": [h["race_outer"].start, h["race_outer"].stop]})
                if "pocket" in h:
                    rec["pocket"] = [h["pocket"].start, h["pocket"].stop]
                if "guide" in h:
                    rec["guide"] = h["guide"].start
                    rec["cage"] = h["cage"]
            else:
                rec["spring"] = h["spring"].start
            out.append(rec)
    return out


def _probes(scene) -> list:
    fams = {e.name for e in scene.model.elements}
    probes = [BodyMotion("motion", frame="reference"),
              BodyMotion("fixed", bodies=["sun", "carrier", "ring"], frame="fixed")]
    wanted = {"race_inner": ["load", "fx", "fy", "angle", "deflection"], "race_outer": ["load", "fx", "fy"],
              "pocket": ["force", "offset"], "guide": ["force", "fx", "fy", "eccentricity"],
              "bearing_linear": ["fx", "fy"], "mesh_sa": ["force", "deflection", "fx", "fy"],
              "mesh_ab": ["force", "deflection", "fx", "fy"], "mesh_br": ["force", "deflection", "fx", "fy"],
              "carrier_drive": ["torque"]}
    probes += [ElementOutput(f, keys) for f, keys in wanted.items() if f in fams]
    return probes


def run_case(params: DPGTParams, cfg: RunConfig, out_dir, label: dict | None = None) -> dict:
    """Run one operating point; write results.nc and summary.json atomically into out_dir.
    An interrupted run resumes from out_dir/checkpoint.npz."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # design warnings were shown once by the caller
        scene = build_dpgt(params, cfg.options, cfg.rig)
    bmap = bearing_map(scene)
    meta = {k: v for k, v in scene.meta.items() if k != "bearing"}
    from viz.results import geometry_from_params   # drawing geometry travels with the results

    rec = Recorder(out_dir / "results.nc", dt=1.0 / cfg.sample_rate, probes=_probes(scene), t_start=cfg.settle,
                   attrs={"bearings": bmap, "meta": meta, "label": label or {},
                          "geometry": geometry_from_params(params)})
    integ = cfg.integration
    t_end = cfg.settle + cfg.window
    fp = run_fingerprint(params, cfg)
    fp_file = out_dir / "fingerprint"
    ckpt = out_dir / "checkpoint.npz"
    if ckpt.exists() and (not fp_file.exists() or fp_file.read_text().strip() != fp):
        # a checkpoint of another run (other parameters, settings or code): start afresh, say so
        print(f"{out_dir}: the checkpoint there is from a different run (parameters, settings or code); starting afresh")
        ckpt.unlink()
    atomic_write_text(fp_file, fp)
    wall0 = time.perf_counter()

    def report(t, t_end, counters):   # read by a sweep's progress display (another process)
        atomic_write_text(out_dir / "progress.json", json.dumps(
            {"t": t, "t_end": t_end, "wall_s": time.perf_counter() - wall0, "steps": counters.accepted}))

    res = mbd.simulate(scene.model, scene.q0, scene.v0, t_end, stepper=integ.stepper(), controller=integ.controller(),
                       recorder=rec, checkpoint=mbd.Checkpoint(out_dir / "checkpoint.npz", cfg.checkpoint_every),
                       resume=True, progress=cfg.progress, failed_state_path=out_dir / "failed_state.npz",
                       on_progress=report)
    (out_dir / "progress.json").unlink(missing_ok=True)
    wall = time.perf_counter() - wall0
    summary = summarize(out_dir / "results.nc", params, scene, cfg)
    summary.update(label or {})
    summary.update({
        "wall_s": wall, "steps": res.steps, "rejected_steps": res.counters["rejected"],
        "newton_per_step": res.counters["newton"] / max(res.steps, 1),
        "resumed_from_s": res.resumed_from,
        "error_estimate": {
            "kind": "HHT local displacement error estimate (Zienkiewicz-Xie, (beta-1/6) h^2 (a1-a0)), "
                    "scaled by atol; RMS and max over accepted steps",
            "rms": res.error_rms, "max": res.error_max, "atol_m": integ.atol_pos,
            "max_local_displacement_error_m": res.error_max * integ.atol_pos,
        },
        "integration": asdict(integ),
        "fingerprint": fp,
    })
    atomic_write_text(out_dir / "summary.json", json.dumps(summary, indent=2, default=_json_default))
    return summary


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


def summarize(path, params: DPGTParams, scene, cfg: RunConfig) -> dict:
    """Statistics of the recorded window (MODEL.md §5). RMS/max of the reference roller (roller 1 of
    planet pair 1) and the mean over all rollers of that bearing kind; cage acceleration relative to its
    planet in R; bearing load = magnitude of the time-mean pin reaction; equivalent load for ISO 281."""
    import xarray as xr

    si = params.si()
    op = si.operating
    bmap = bearing_map(scene)
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        t = ds["time"].values
        m = window(t, cfg.settle, cfg.settle + cfg.window)
        bodies = list(ds["motion.body"].values)
        acc = ds["motion.a"].values[m]
        get = lambda k: ds[k].values[m] if k in ds else None
        inner_fx, inner_fy, inner_Q = get("race_inner.fx"), get("race_inner.fy"), get("race_inner.load")
        outer_Q = get("race_outer.load")
        pocket = get("pocket.force")
        guide = get("guide.force")
        lin_fx, lin_fy = get("bearing_linear.fx"), get("bearing_linear.fy")
    out = {
        "condition": None, "direction": op.direction, "carrier_rpm": op.carrier_speed * 30 / np.pi,
        "sun_rpm": op.sun_speed * 30 / np.pi, "power_W": float(si.operating.output_power),
        "planets": int(si.gears.planets), "rollers": int(si.bearing.rollers),
        "window_s": [cfg.settle, cfg.settle + cfg.window], "samples": int(m.sum()),
        "f_m_hz": scene.meta["f_m_hz"], "f_c_hz": scene.meta["f_c_hz"],
    }
    for kind in ("inner", "outer"):
        group = [b for b in bmap if b["kind"] == kind]
        ref = group[0]
        d: dict = {}
        loads = []
        for b in group:
            if b["type"] == "rollers":
                sl = slice(*b["race_inner"])
                F = np.stack([-inner_fx[:, sl].sum(axis=1), -inner_fy[:, sl].sum(axis=1)], axis=1)
            else:
                F = np.stack([lin_fx[:, b["spring"]], lin_fy[:, b["spring"]]], axis=1)   # force on the planet
            loads.append(F)
        Fref = loads[0]
        d["bearing_load_mean_N"] = float(np.hypot(*Fref.mean(axis=0)))
        d["bearing_load_mean_all_N"] = float(np.mean([np.hypot(*F.mean(axis=0)) for F in loads]))
        d["equivalent_load_N"] = bearing_equivalent_load(np.hypot(Fref[:, 0], Fref[:, 1]))
        if ref["type"] == "rollers":
            r0 = ref["race_inner"][0]
            sl_all = np.concatenate([np.arange(*b["race_inner"]) for b in group])
            so_all = np.concatenate([np.arange(*b["race_outer"]) for b in group])
            ro0 = ref["race_outer"][0]
            d["roller_inner_race_rms_N"] = float(rms(inner_Q[:, r0]))
            d["roller_inner_race_max_N"] = float(inner_Q[:, r0].max())
            d["roller_outer_race_rms_N"] = float(rms(outer_Q[:, ro0]))
            d["roller_outer_race_max_N"] = float(outer_Q[:, ro0].max())
            d["all_rollers"] = {"roller_inner_race_rms_N": float(rms(inner_Q[:, sl_all]).mean()),
                                "roller_inner_race_max_N": float(inner_Q[:, sl_all].max(axis=0).mean()),
                                "roller_outer_race_rms_N": float(rms(outer_Q[:, so_all]).mean()),
                                "roller_outer_race_max_N": float(outer_Q[:, so_all].max(axis=0).mean())}
            if pocket is not None and "pocket" in ref:
                p0 = ref["pocket"][0]
                sp_all = np.concatenate([np.arange(*b["pocket"]) for b in group])
                d["roller_cage_rms_N"] = float(rms(pocket[:, p0]))
                d["roller_cage_max_N"] = float(np.abs(pocket[:, p0]).max())
                d["all_rollers"]["roller_cage_rms_N"] = float(rms(pocket[:, sp_all]).mean())
                d["all_rollers"]["roller_cage_max_N"] = float(np.abs(pocket[:, sp_all]).max(axis=0).mean())
            if guide is not None and "guide" in ref:
                g0 = ref["guide"]
                gi = [b["guide"] for b in group]
                d["cage_guide_rms_N"] = float(rms(guide[:, g0]))
                d["cage_guide_max_N"] = float(guide[:, g0].max())
                d["all_rollers"]["cage_guide_rms_N"] = float(rms(guide[:, gi]).mean())
                ic, ip = bodies.index(ref["cage"]), bodies.index(ref["planet"])
                rel = acc[:, ic, :2] - acc[:, ip, :2]
                d["cage_acc_x_rms"] = float(rms(rel[:, 0]))
                d["cage_acc_y_rms"] = float(rms(rel[:, 1]))
        d["life_L10_relative"] = None     # filled by the study relative to the forward run
        out[kind] = d
    return out
