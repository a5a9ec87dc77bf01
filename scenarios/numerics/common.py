"""Shared machinery of the numerics scenarios (work-precision, stability, benchmark).

- :func:`dpgt_problem` / :func:`rig_problem`: the two test problems, each a :class:`Problem` (built
  scene, which bearing is the "reference bearing", its roller/cage/planet, how to settle it).
- :func:`settled_state`: integrate the problem past its start-up transient with a robust setting once
  and cache the state (``mbd.save_state``) so every contender starts from exactly the same state.
- :class:`StateSampler`: a duck-typed recorder for :func:`mbd.simulate` that keeps (q, v) on a fixed
  time grid by the same cubic Hermite interpolation as :class:`mbd.Recorder`, at negligible cost (no
  element evaluation inside the timed loop); observables are computed afterwards, identically for
  every integrator (:func:`observables`).
- :func:`run_hht` and :func:`run_scipy`: one contender run, returning the sampled states and its costs.
  ``run_scipy`` calls ``solve_ivp`` with :class:`mbd.FirstOrderSystem` (the sparse analytic Jacobian)
  itself, rather than :func:`mbd.solve_scipy`, because the work-precision table needs the number of
  steps and the time reached when the wall-time cap stops a run.
- :func:`error_metrics`: (a) max-norm error of the reference bearing's pin-reaction magnitude on the
  common grid (absolute [N] and relative to the reference's max), (b) relative errors of the RMS of
  the reference roller's inner-race load, the cage–guide force and the cage acceleration.
"""
from __future__ import annotations

import dataclasses
import hashlib
import os
import platform
import resource
import statistics
import sys
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import mbd
from mbd.compiled.system import CompiledSystem
from mbd.recorder import hermite
from components.dpgt import build_dpgt
from components.geometry import design_findings
from components.outputs import FAMILY, pin_reactions
from components.params import with_overrides
from components.presets import reference_dpgt
from components.rig import build_bearing_rig

__all__ = ["Problem", "dpgt_problem", "rig_problem", "settled_state", "StateSampler", "RunResult",
           "run_hht", "run_scipy", "observables", "error_metrics", "scipy_atol", "peak_rss_mb",
           "eval_costs", "machine_note", "load1", "warm_up",
           "design_verdict", "FAMILY_ROWS"]

# a family's compiled twin -> its row of bench_breakdown's table (the other twins: supports, springs, drives)
FAMILY_ROWS = {"contact.race": "race", "contact.pocket": "pocket", "contact.guide": "guide", "contact.drag": "drag",
               "mesh.gear_mesh": "meshes", "sliced.sliced_race": "race", "sliced.sliced_gear_mesh": "meshes"}


@dataclass
class Problem:
    name: str
    built: object                 # components.dpgt.DPGTScene or components.rig.BearingRigScene
    race_inner: slice             # instances of the reference bearing in the race_inner family
    roller: int                   # reference roller (race_inner instance index)
    guide: int | None             # guide-family instance of the reference cage
    cage: str | None              # reference cage body name
    planet: str                   # outer-raceway body of the reference bearing
    settle: float                 # s: end of the settling run
    meta: dict = field(default_factory=dict)

    @property
    def model(self) -> mbd.Model:
        return self.built.model


def dpgt_problem(condition: int = 3, direction: str = "forward", overrides: dict | None = None,
                 options=None, settle: float = 0.03, strict: bool = True) -> Problem:
    """Full DPGT (reference_dpgt(condition, direction) with ``overrides``); reference bearing = the
    first inner planet's bearing, reference roller = its roller 0. ``strict=False`` builds a machine the
    design check refuses (e.g. overlapping planets: no planet–planet contact is modelled, so such a
    machine is non-physical, but its equations can still be integrated for cost and stability numbers)."""
    params = with_overrides(reference_dpgt(condition, direction), overrides or {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # design warnings (tip overlap, N not assemblable) are known
        sc = build_dpgt(params, options, strict=strict)
    h = sc.pairs[0].inner_bearing
    if h.kind != "rollers":
        raise mbd.ModelError("the numerics scenarios need the roller bearing model")
    return Problem("dpgt", sc, h.race_inner, h.race_inner.start, h.guide.start if h.guide is not None else None,
                   h.cage, sc.pairs[0].inner, settle, {"params": params})


def rig_problem(radial_load: float = 5000.0, overrides: dict | None = None, outer_speed: float | None = None) -> Problem:
    """One planet bearing on the rig: the reference bearing under ``radial_load`` [N] with the outer
    ring turning at the inner planet's speed relative to the carrier at condition 3 (the bearing's own
    operating point in the DPGT), lubricant drag on, cage free."""
    params = with_overrides(reference_dpgt(3, "forward"), overrides or {})
    if outer_speed is None:
        op = params.si().operating
        outer_speed = op.inner_planet_speed - op.carrier_speed
    sc = build_bearing_rig(params.bearing, radial_load=radial_load, outer_speed=outer_speed,
                           lubricant=params.lubricant)
    h = sc.bearing_handles
    return Problem("rig", sc, h.race_inner, h.race_inner.start, h.guide.start, h.cage, sc.ring,
                   float(sc.t_settle), {"params": params, "outer_speed": outer_speed})


# ----------------------------------------------------------------------------------------------
def settled_state(prob: Problem, cache: Path | None = None, h: float = 5e-6) -> tuple[mbd.State, dict]:
    """State at t = prob.settle from a robust setting (HHT α = −0.3, adaptive, atol 10 nm, h ≤ h);
    loaded from ``cache`` when it exists (and was made for the same settle time and DOF count)."""
    fp = model_fingerprint(prob.model)
    if cache is not None and Path(cache).exists():
        s, extra = mbd.load_state(cache)
        if abs(s.t - prob.settle) < 1e-12 and s.q.size == prob.model.ndof and extra.get("fingerprint") == fp:
            return s, extra
    setting = dataclasses.replace(mbd.PRODUCTION, h=min(h, 1e-6), h_max=h, h_min=1e-10)
    res = mbd.simulate(prob.model, prob.built.q0, prob.built.v0, prob.settle, stepper=setting.stepper(),
                       controller=setting.controller(), progress=False, engine=setting.engine)
    extra = {"fingerprint": fp, "settle_wall_s": res.wall_s, "settle_steps": res.steps, "setting": repr(setting)}
    if cache is not None:
        Path(cache).parent.mkdir(parents=True, exist_ok=True)
        mbd.save_state(cache, res.state, extra)
    return res.state, extra


def model_fingerprint(model: mbd.Model) -> str:
    """Hash of the bodies and every element family's numeric parameters (a cached settled state is
    reused only for the same model: the builders change while the project evolves)."""
    h = hashlib.sha1()
    for a in (model.mass, model.inertia, model.pose0, model.mdiag, np.asarray(model.gravity)):
        h.update(np.ascontiguousarray(a, float).tobytes())
    h.update(repr(model.frame.omega).encode())
    for e in model.elements:
        h.update(f"{type(e).__name__}:{e.name}".encode())
        for k in sorted(vars(e)):
            val = vars(e)[k]
            if isinstance(val, np.ndarray) and val.dtype.kind in "fiub":
                h.update(k.encode() + np.ascontiguousarray(val).tobytes())
            elif isinstance(val, (int, float, str, bool)):
                h.update(f"{k}={val!r}".encode())
            elif hasattr(val, "__dataclass_fields__"):
                h.update(f"{k}={val!r}".encode())
    return h.hexdigest()


class StateSampler(mbd.Observer):
    """(q, v, z) at the grid times, cubic Hermite between accepted steps (:func:`mbd.recorder.hermite`,
    the recorder's interpolation). An observer of the one loop; no element evaluation while timing."""

    def __init__(self, grid):
        self.grid = np.asarray(grid, float)
        self.i = 0
        self.q, self.v, self.z = [], [], []

    def _take(self, q, v, z):
        self.q.append(q)
        self.v.append(v)
        self.z.append(z)
        self.i += 1

    def bind(self, model, system, state):
        tol = 1e-12 * max(1.0, abs(state.t))
        while self.i < self.grid.size and self.grid[self.i] <= state.t + tol:
            self._take(state.q.copy(), state.v.copy(), state.z)

    def step(self, s0, s1):
        tol = 1e-12 * max(1.0, abs(s1.t))
        h = s1.t - s0.t
        while self.i < self.grid.size and self.grid[self.i] <= s1.t + tol:
            th = min(1.0, max(0.0, (self.grid[self.i] - s0.t) / h))
            q, v, _ = hermite(s0, s1, th, h)
            self._take(np.array(q, copy=True), np.array(v, copy=True), s0.z)

    @property
    def complete(self) -> bool:
        return self.i == self.grid.size


@dataclass
class RunResult:
    method: str
    setting: str
    completed: bool
    message: str
    wall_s: float
    walls: list
    steps: int
    residual: int
    jacobian: int
    factor: int
    newton: int = 0
    rejected: int = 0
    t_reached: float = np.nan
    q: np.ndarray | None = None
    engine: str = ""
    v: np.ndarray | None = None
    z: list | None = None

    def costs(self) -> dict:
        return {"method": self.method, "setting": self.setting, "completed": self.completed,
                "message": self.message, "wall_s": self.wall_s, "steps": self.steps,
                "residual_evals": self.residual, "jacobian_evals": self.jacobian, "factorizations": self.factor,
                "newton_iterations": self.newton, "rejected": self.rejected, "t_reached": self.t_reached,
                "wall_repeats": self.walls}


def warm_up(prob: Problem, state: mbd.State) -> None:
    """Two compiled steps from ``state``, untimed: the first compiled run of a process loads every kernel from
    numba's disk cache (≈ 0.3–1 s), which would otherwise be charged to whichever contender runs first."""
    mbd.simulate(prob.model, t_end=state.t + 2e-7, state=state.copy(), stepper=mbd.PRODUCTION.stepper(),
                 controller=mbd.FixedStep(1e-7), progress=False)


def run_hht(prob: Problem, state: mbd.State, t_end: float, grid, *, alpha: float, h: float | None = None,
            atol_pos: float | None = None, repeats: int = 1, h_max: float = 2e-5, label: str = "",
            newton_tol: float | None = None, tol: mbd.Tolerance | None = None,
            freeze_internal: bool = False, engine: str = "auto", per_component: bool = True) -> RunResult:
    """The one way the numerics scripts run HHT from a state and sample it on ``grid``: fixed step
    (``h``) or adaptive (``atol_pos``; atol_rot = 100·atol_pos) from ``state``; ``newton_tol`` and ``tol``
    override the HHT defaults (error-floor study, references); ``freeze_internal`` holds element internal
    states (the equations the scipy adapter integrates); ``engine`` as in :func:`mbd.simulate`;
    ``per_component=False`` runs Newton's former convergence test (the max norm's
    rate, :class:`mbd.hht.NewtonPolicy`) for before/after comparisons."""
    if (h is None) == (atol_pos is None):
        raise ValueError("give exactly one of h (fixed step) or atol_pos (adaptive)")
    if tol is None:
        tol = mbd.Tolerance() if atol_pos is None else mbd.Tolerance(atol_pos=atol_pos, atol_rot=100 * atol_pos)
    extra = {} if newton_tol is None else {"newton_tol": newton_tol}
    stepper = mbd.HHT(alpha=alpha, tol=tol, per_component=per_component, **extra)
    walls, res, sampler = [], None, None
    for r in range(max(1, repeats)):
        ctrl = mbd.FixedStep(h) if h is not None else mbd.Adaptive(h0=min(5e-6, h_max), h_max=h_max, h_min=1e-10)
        smp = StateSampler(grid) if r == 0 else None
        system = mbd.System(prob.model, freeze_internal=freeze_internal)
        w0 = time.perf_counter()
        try:
            res = mbd.simulate(prob.model, t_end=t_end, state=state.copy(), stepper=stepper, controller=ctrl,
                               engine=engine,
                               observers=[smp] if smp is not None else [], progress=False, system=system)
        except mbd.IntegrationError as exc:
            c = exc.counters      # the loop's totals up to the failure
            return RunResult("HHT", label, False, str(exc), time.perf_counter() - w0, [time.perf_counter() - w0],
                             c["accepted"], c["residual"], c["jacobian"], c["factor"], c["newton"], c["rejected"],
                             t_reached=float(exc.state.t) if getattr(exc, "state", None) is not None else np.nan)
        walls.append(time.perf_counter() - w0)
        if r == 0:
            sampler = smp
    c = res.counters
    return RunResult("HHT", label, True, "", statistics.median(walls), walls, res.steps, c["residual"], c["jacobian"],
                     c["factor"], c["newton"], c["rejected"], t_reached=res.state.t,
                     q=np.array(sampler.q), v=np.array(sampler.v), z=sampler.z, engine=res.engine)


def hht_reference(prob, s0, t1, grid, h, frozen_z=False):
    """Reference-quality HHT run (the reference of work_precision and benchmark): α = −0.1, fixed h, Newton tolerance scaled by atol 0.1 nm / 10 nrad.
    ``frozen_z``: hold element internal states at their initial value (what the scipy adapter does)."""
    r = run_hht(prob, s0, t1, grid, alpha=-0.1, h=h, tol=mbd.Tolerance(atol_pos=1e-10, atol_rot=1e-8),
                freeze_internal=frozen_z, label=f"fixed h={h:.2e}")
    r.method = "HHT-ref"
    return r


def scipy_atol(model: mbd.Model, tol: float) -> np.ndarray:
    """Absolute tolerances for y = (q, v) at a scipy setting ``tol`` (= rtol): positions 1e-2·tol m
    (tol = 1e-6 → 10 nm, HHT's default length scale), angles tol rad, velocities 1e3× those per s."""
    rot = (model.free % 3) == 2
    aq = np.where(rot, tol, 1e-2 * tol)
    return np.concatenate([aq, 1e3 * aq])


class _WallCap(Exception):
    pass


def run_scipy(prob: Problem, state: mbd.State, t_end: float, grid, *, method: str, tol: float,
              max_wall_s: float, repeats: int = 1) -> RunResult:
    """solve_ivp from ``state`` with the sparse analytic Jacobian (implicit methods; LSODA gets it
    dense, as its Fortran core needs), evaluated by the compiled engine where it can be built (the same
    residual HHT uses). Stops with completed=False at ``max_wall_s``."""
    walls, out = [], None
    for r in range(max(1, repeats)):
        fo = mbd.FirstOrderSystem(prob.model, z={k: np.array(v) for k, v in state.z.items()})
        y0 = np.concatenate([state.q, state.v])
        t_last = [state.t]
        start = time.perf_counter()

        def fun(t, y):
            if time.perf_counter() - start > max_wall_s:
                raise _WallCap(t)
            t_last[0] = max(t_last[0], t)
            return fo.fun(t, y)

        opts = {}
        if method == "LSODA":
            opts["jac"] = lambda t, y: fo.jac(t, y).toarray()
        elif method in ("Radau", "BDF"):
            opts["jac"] = fo.jac
        ok, msg, sol = False, "", None
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = solve_ivp(fun, (state.t, t_end), y0, method=method, rtol=tol, atol=scipy_atol(prob.model, tol),
                                dense_output=True, **opts)
            ok, msg = bool(sol.success), str(sol.message)
        except _WallCap:
            msg = f"stopped by the wall-time cap of {max_wall_s:.0f} s at t = {t_last[0]:.6e} s " \
                  f"({(t_last[0] - state.t) / (t_end - state.t):.0%} of the window)"
        wall = time.perf_counter() - start
        walls.append(wall)
        nlu = int(getattr(sol, "nlu", 0) or 0) if sol is not None else 0
        res = RunResult(method, f"rtol={tol:g}", ok, msg, wall, walls, len(sol.t) - 1 if sol is not None else -1,
                        fo.nfev, fo.njev, nlu, t_reached=float(sol.t[-1]) if sol is not None else t_last[0],
                        engine=fo.engine)
        if r == 0:
            out = res
            if ok:
                Y = sol.sol(np.asarray(grid, float))
                n = prob.model.ndof
                out.q, out.v = Y[:n].T.copy(), Y[n:].T.copy()
                out.z = [fo.z] * len(grid)
        if not ok:
            break
    out.walls = walls
    out.wall_s = statistics.median(walls)
    return out


# ----------------------------------------------------------------------------------------------
def observables(prob: Problem, grid, q, v, z) -> dict[str, np.ndarray]:
    """Time series on the grid: the reference bearing's pin-reaction magnitude [N], the reference
    roller's inner-race load [N], the reference cage's guide force [N] and its acceleration relative
    to its planet (x, y in R) [m/s²] (a = M⁻¹F at the sampled state, the same for every integrator)."""
    system = mbd.System(prob.model)
    m = prob.model
    f2f = m.full_to_free
    ic = m.body(prob.cage).index if prob.cage else None
    ip = m.body(prob.planet).index
    sl = prob.race_inner
    b = prob.built.bearing
    rows = 1 if b.model == "sliced" else b.rows          # physical rollers per roller body (the planar model folds rows)
    out = {k: [] for k in ("pin_load", "inner_load", "guide_force", "cage_acc_x", "cage_acc_y")}
    for t, qi, vi, zi in zip(grid, q, v, z):
        o = system.outputs(t, qi, vi, zi)
        ri = o[FAMILY["race_inner"]]
        out["pin_load"].append(np.hypot(*pin_reactions(ri, sl, np.zeros(sl.stop - sl.start, int), 1, rows)[0]))
        out["inner_load"].append(ri["load"][prob.roller])
        out["guide_force"].append(o[FAMILY["guide"]]["force"][prob.guide] if prob.guide is not None else 0.0)
        if ic is not None:
            a = system.forces(t, qi, vi, zi) / m.mdiag
            acc = [a[f2f[3 * ic + j]] - (a[f2f[3 * ip + j]] if f2f[3 * ip + j] >= 0 else 0.0) for j in (0, 1)]
        else:
            acc = [0.0, 0.0]
        out["cage_acc_x"].append(acc[0])
        out["cage_acc_y"].append(acc[1])
    return {k: np.asarray(x, float) for k, x in out.items()}


def _rms(x):
    return float(np.sqrt(np.mean(np.square(x))))


def summary_stats(obs: dict) -> dict:
    return {"rms_inner_load_N": _rms(obs["inner_load"]), "rms_guide_N": _rms(obs["guide_force"]),
            "rms_cage_acc": _rms(np.hypot(obs["cage_acc_x"], obs["cage_acc_y"])),
            "max_pin_load_N": float(np.max(obs["pin_load"]))}


def error_metrics(obs: dict, ref: dict) -> dict:
    """(a) pin-load max-norm error [N] and relative to max|reference|; (b) relative RMS errors."""
    e = float(np.max(np.abs(obs["pin_load"] - ref["pin_load"])))
    s, r = summary_stats(obs), summary_stats(ref)
    rel = lambda k: abs(s[k] - r[k]) / r[k] if r[k] > 0 else float("nan")
    return {"err_pin_max_N": e, "err_pin_rel": e / max(np.max(np.abs(ref["pin_load"])), 1e-30),
            "err_rms_inner": rel("rms_inner_load_N"), "err_rms_guide": rel("rms_guide_N"),
            "err_rms_cage_acc": rel("rms_cage_acc"), **s}


def eval_costs(model: mbd.Model, state: mbd.State, n: int = 200) -> dict:
    """Median wall time [s] of one residual and of one residual+Jacobian evaluation (batches of 20), on
    the numpy path (``residual_s``, ``jacobian_s``) and the compiled one (``compiled_…``), interleaved."""
    system = mbd.System(model)
    paths = {"": system, "compiled_": CompiledSystem(system)}
    batches = {f"{p}{k}": [] for p in paths for k in ("residual_s", "jacobian_s")}
    for _ in range(5):
        for s in paths.values():
            s.evaluate(state.t, state.q, state.v, state.z, jac=True)
    for _ in range(max(1, n // 20)):
        for prefix, s in paths.items():
            for jac in (False, True):
                t0 = time.perf_counter()
                for _ in range(20):
                    s.evaluate(state.t, state.q, state.v, state.z, jac=jac)
                batches[f"{prefix}{'jacobian_s' if jac else 'residual_s'}"].append((time.perf_counter() - t0) / 20)
    return {k: statistics.median(v) for k, v in batches.items()}


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0   # Linux: kB


def machine_note() -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"numpy {np.__version__}; 1-min load average at start {load:.2f} (machine shared with other jobs)")


def progress_log(json_out: bool):
    """The scripts' progress printer: to stderr when stdout carries the JSON result (``--json``), else stdout."""
    stream = sys.stderr if json_out else sys.stdout
    return lambda m: print(m, file=stream, flush=True)


def load1() -> float:
    """1-min load average (nan where the OS has none)."""
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")


def design_verdict(overrides: dict | None = None, condition: int = 3, direction: str = "forward") -> dict:
    """The design check's findings for reference_dpgt with ``overrides``, summarised: ``refused`` (an
    error: build_dpgt raises unless strict=False), ``collides`` (a warning that gears' pitch circles
    overlap — the check only warns, but such a machine cannot exist: no planet–planet contact is
    modelled, so its simulation is non-physical), ``assembly`` (a warning that equally spaced pairs
    do not assemble), and the messages."""
    params = with_overrides(reference_dpgt(condition, direction), overrides or {})
    found = design_findings(params)
    msgs = [f"{f.severity}: {' '.join(str(f).split())}" for f in found]
    return {"refused": any(f.severity == "error" for f in found),
            "collides": any("collide" in str(f) for f in found),
            "assembly": any("do not assemble" in str(f) for f in found),
            "messages": msgs}
