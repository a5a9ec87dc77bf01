"""The one loop: stepper + controller + recorder + checkpoints + progress bar.

The run's counters are the loop's: the sum of the work each step reports in its StepInfo, plus
accepted/rejected steps (and the one force evaluation of the initial state when the loop makes it).
Checkpoints every K accepted steps save the state, the controller's h, the counters and the
recorder's position atomically; a run started again with ``resume=True`` continues from the last
checkpoint and ends with results identical to an uninterrupted run (a checkpoint also drops the
cached LU in both, so Newton iterates are the same either way).
"""
from __future__ import annotations

import io
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .assembly import System
from .compile_time import compiling
from .errors import IntegrationError, ModelError
from .hht import HHT, NewtonCache, StepInfo
from .model import Model, State
from .protocols import Controller, Observer, Recorder, require
from .recorder import atomic_write_bytes
from .settings import PRODUCTION

__all__ = ["simulate", "SimResult", "Checkpoint", "Counters", "TimeMean", "save_state", "load_state",
           "output_evaluator", "TIMING_PARTS"]

# SimResult.timing: wall seconds of one simulate call by part — "setup_s" choosing and building the engine path
# (the compiled runner: its kernels' load or compile included), "bind_s" binding the recorder and observers (the
# statistics load their output kernels here), "engine_s" the steps, "recording_s" the recorder's sampling and
# chunks, "observers_s" the observers, "checkpoints_s", "results_s" writing the results file, "other_s" the rest
# (progress, step statistics). A perf_counter pair per block (compiled) or per step (numpy: ms per step).
TIMING_PARTS = ("setup_s", "bind_s", "engine_s", "recording_s", "observers_s", "checkpoints_s", "results_s", "other_s")


@dataclass
class Counters:
    """Work of one simulate run (summed from the steps' StepInfo)."""
    residual: int = 0     # force evaluations without Jacobian
    jacobian: int = 0     # force + Jacobian evaluations
    factor: int = 0       # LU factorizations
    newton: int = 0       # Newton iterations
    accepted: int = 0
    rejected: int = 0

    def add(self, info: StepInfo) -> None:
        """Add one step's work (accepted or not: a rejected step's evaluations were made too)."""
        self.residual += info.residuals
        self.jacobian += info.jacobians
        self.factor += info.factorizations
        self.newton += info.iterations

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True)
class Checkpoint:
    path: str | os.PathLike
    every: int = 2000          # accepted steps between checkpoints

    def __post_init__(self):
        if self.every < 1:
            raise ModelError(f"Checkpoint.every must be >= 1 step, got {self.every!r}")


@dataclass
class SimResult:
    state: State
    counters: dict
    wall_s: float
    steps: int
    error_max: float           # largest scaled local error estimate of an accepted step
    error_rms: float           # RMS over accepted steps of the scaled local error estimates
    h_min_used: float
    h_max_used: float
    results_path: Path | None = None
    resumed_from: float | None = None
    engine: str = "numpy"      # which engine path ran ("compiled" or "numpy")
    engine_note: str | None = None   # why "auto" ran the numpy path (None: it did not fall back)
    timing: dict = field(default_factory=dict)   # wall seconds per part of this call (:data:`TIMING_PARTS`)

    def summary(self) -> dict:
        return {"wall_s": self.wall_s, "steps": self.steps, "error_estimate_max": self.error_max,
                "error_estimate_rms": self.error_rms, "h_min_s": self.h_min_used,
                "h_max_s": self.h_max_used, "engine": self.engine, "engine_note": self.engine_note,
                **{f"n_{k}": v for k, v in self.counters.items()}}


def save_state(path, s: State, extra: dict | None = None, arrays: dict | None = None) -> None:
    """State (with element internal states), JSON ``extra`` and named ``arrays`` in one atomic .npz."""
    bio = io.BytesIO()
    z = {f"z__{k}": v for k, v in s.z.items()}
    arr = {f"x__{k}": np.asarray(v) for k, v in (arrays or {}).items()}
    # numpy scalars (np.int64 counters, indices) are not JSON types: store them as Python numbers
    extra_json = json.dumps(extra or {}, default=lambda o: o.item() if isinstance(o, np.generic) else str(o))
    np.savez(bio, t=s.t, q=s.q, v=s.v, a=s.a, f=s.f, extra=extra_json, **z, **arr)
    atomic_write_bytes(path, bio.getvalue())


def load_state(path, with_arrays: bool = False):
    """(state, extra) — and the named arrays with ``with_arrays``."""
    with np.load(path) as d:
        z = {k[3:]: d[k] for k in d.files if k.startswith("z__")}
        s = State(float(d["t"]), d["q"].copy(), d["v"].copy(), d["a"].copy(), d["f"].copy(), z)
        extra = json.loads(str(d["extra"]))
        arrays = {k[3:]: d[k].copy() for k in d.files if k.startswith("x__")}
    return (s, extra, arrays) if with_arrays else (s, extra)


class TimeMean(Observer):
    """Time mean of ``fn(system, state)`` (an array) over [t0, t1], by the trapezoidal rule on the
    accepted steps that end inside it (every contact event the integrator resolves is in the mean; a mean
    of samples at a fixed rate would alias impacts). Steps straddling t0 or t1 count from their ends."""

    def __init__(self, fn, t0: float, t1: float):
        if not t1 > t0:
            raise ModelError(f"TimeMean: need t1 > t0 [s], got t0={t0!r}, t1={t1!r}")
        self.fn, self.t0, self.t1 = fn, float(t0), float(t1)
        self._acc, self._T, self._prev = 0.0, 0.0, None

    def bind(self, model, system, state) -> None:
        self.system = system

    def step(self, s0: State, s1: State) -> None:
        if s1.t <= self.t0 or s0.t >= self.t1:
            return
        f0 = self._prev if self._prev is not None else np.asarray(self.fn(self.system, s0), float)
        f1 = np.asarray(self.fn(self.system, s1), float)
        self._acc = self._acc + 0.5 * (f0 + f1) * (s1.t - s0.t)
        self._T += s1.t - s0.t
        self._prev = f1

    def state_dict(self) -> dict:
        return {"acc": np.asarray(self._acc), "T": np.asarray(self._T),
                **({"prev": self._prev} if self._prev is not None else {})}

    def load_state_dict(self, d: dict) -> None:
        self._acc, self._T, self._prev = d["acc"], float(d["T"]), d.get("prev")

    @property
    def mean(self) -> np.ndarray:
        if self._T <= 0:
            raise ModelError(f"TimeMean: no accepted step ended in [{self.t0}, {self.t1}] s")
        return self._acc / self._T


def simulate(model: Model, q0=None, v0=None, t_end: float = 0.0, *, t0: float = 0.0,
             stepper: HHT | None = None, controller: Controller | None = None, recorder: Recorder | None = None,
             checkpoint: Checkpoint | None = None, resume: bool = False, progress: bool | None = None,
             failed_state_path=None, state: State | None = None, system: System | None = None,
             on_progress=None, observers=(), engine: str = "auto", threads: int = 1) -> SimResult:
    """Integrate from (t0, q0, v0) — or from ``state`` — to t_end.

    ``stepper`` defaults to ``mbd.PRODUCTION.stepper()``; ``controller`` is required (FixedStep or Adaptive), since
    the step size is the user's accuracy decision. ``engine``: "compiled" (:mod:`mbd.compiled`; an error
    when it cannot be built for this model), "numpy" (the reference path) or "auto" (compiled when it can
    be built, else numpy; ``SimResult.engine`` says which ran). Progress bar: on for runs of more than ~2 s
    wall unless ``progress=False`` or the environment sets DPGT_PROGRESS=0. ``on_progress(t, t_end,
    counters)`` is called at most twice a second (e.g. to report progress from a worker process).
    ``observers`` (:class:`~mbd.protocols.Observer`) see every accepted step, whatever the recorder's sample rate.
    The controller, the recorder and each observer are checked against their protocols (:mod:`mbd.protocols`)
    before anything is built: a missing method fails here, naming the argument. ``threads`` (compiled engine; 1 to
    the usable cores, default 1): the bearings' contact families evaluated on that many threads, the same steps and
    states to the bit (:mod:`mbd.compiled.system`); it pays on idle cores only (docs/numerics.md §5 "Threads").
    """
    if controller is None:
        raise ModelError("simulate: pass controller=FixedStep(h) or Adaptive(h0=..., ...)")
    observers = _check_arguments(controller, recorder, observers)
    if stepper is None:
        stepper = PRODUCTION.stepper()
    call0 = time.perf_counter()
    system = system or System(model)
    runner, engine, engine_note = _engine(engine, system, stepper, controller, threads)
    setup_s = time.perf_counter() - call0
    counters = Counters()
    if state is None:
        if q0 is None or v0 is None:
            raise ModelError("simulate: give q0 and v0 (free DOFs) or a State")
        state = stepper.initial_state(system, t0, q0, v0)
        counters.residual += 1       # initial_state evaluates the forces once
    if not (np.isfinite(t_end) and t_end >= state.t):
        raise ModelError(f"simulate: t_end must be >= the start time {state.t} s, got {t_end!r}")
    if runner is None:       # the numpy path hands over single steps: an on_block-only observer cannot take them
        for i, ob in enumerate(observers):
            if type(ob).step is Observer.step:
                raise ModelError(f"simulate: observers[{i}] ({type(ob).__name__}) does not define step(s0, s1), "
                                 "which the numpy engine path calls")
    bind0 = time.perf_counter()
    h, stats, counters, state, resumed_from = _begin(model, system, state, controller, counters, recorder,
                                                     observers, checkpoint, resume)
    bind_s = time.perf_counter() - bind0
    show = progress if progress is not None else os.environ.get("DPGT_PROGRESS", "1") != "0"
    loop = _Loop(recorder, observers, stats, counters, _Progress(state.t, t_end, show, on_progress), checkpoint)
    wall0 = time.perf_counter()
    try:
        if runner is None:
            state = _numpy_steps(loop, system, stepper, controller, state, h, t_end, failed_state_path)
        else:
            state = _compiled_steps(loop, system, runner, state, h, t_end, failed_state_path)
    except IntegrationError as exc:
        exc.counters = counters.as_dict()    # the work up to the failure, for the caller's report
        raise
    finally:
        loop.bar.close()
    wall = time.perf_counter() - wall0
    n = max(stats["steps"], 1)
    res = SimResult(state=state, counters=counters.as_dict(), wall_s=wall, steps=stats["steps"],
                    error_max=float(stats["err_max"]), error_rms=float(np.sqrt(stats["err_sq"] / n)),
                    h_min_used=float(stats["h_lo"]), h_max_used=float(stats["h_hi"]), resumed_from=resumed_from,
                    engine=engine, engine_note=engine_note)
    t_res = time.perf_counter()
    if recorder is not None:
        res.results_path = recorder.finalize(attrs={"run": res.summary()})
    res.timing = {"setup_s": setup_s, "bind_s": bind_s, **loop.timing, "results_s": time.perf_counter() - t_res}
    res.timing["other_s"] = max(time.perf_counter() - call0 - sum(res.timing.values()), 0.0)
    if checkpoint is not None and Path(checkpoint.path).exists():
        Path(checkpoint.path).unlink()
    return res


def _check_arguments(controller, recorder, observers) -> list:
    """The observers as a list, after checking every argument against its protocol."""
    require(Controller, controller, "controller")
    if recorder is not None:
        require(Recorder, recorder, "recorder")
    try:
        observers = list(observers)
    except TypeError:
        raise ModelError(f"simulate: observers must be a list of observers, got {type(observers).__name__}") from None
    for i, ob in enumerate(observers):
        require(Observer, ob, f"observers[{i}]")
    return observers


ENGINES = ("auto", "compiled", "numpy")


def _engine(engine: str, system: System, stepper, controller, threads: int = 1):
    """(compiled runner or None, the engine that will run, why "auto" falls back to numpy or None). A fallback
    is said on stderr in one line: the numpy path is ≈ 13× slower, never silently."""
    if engine not in ENGINES:
        raise ModelError(f"simulate: engine must be one of {ENGINES}, got {engine!r}")
    if engine == "numpy":
        if not (threads == 1 and not isinstance(threads, bool)):
            raise ModelError(f"simulate: threads must be 1 on the numpy engine (threads run the compiled one), "
                             f"got {threads!r}")
        return None, "numpy", None
    try:
        from .compiled.runner import CompiledRunner  # deferred: numba kernels, optional (numpy falls back)
        with compiling():        # its twin of the system and its step loop compile or load here, before any step
            return CompiledRunner(system, stepper, controller, threads), "compiled", None
    except (ImportError, NotImplementedError) as exc:
        if engine == "compiled":
            raise ModelError(f"simulate: the compiled engine cannot run this model: {exc}") from None
        note = f"{type(exc).__name__}: {exc}".splitlines()[0]
        print(f"mbd: running the numpy engine path (about 13x slower): the compiled one cannot run this model "
              f"({note})", file=sys.stderr, flush=True)
        return None, "numpy", note


def output_evaluator(system: System, engine: str = "auto"):
    """What evaluates the element outputs of K states at once (its ``outputs_batch(t, q, v, z, families)``, as
    :meth:`System.outputs_batch`): "numpy" the System itself (the reference); "compiled" the compiled kernels
    (:class:`mbd.compiled.outputs.CompiledOutputs`: the families whose twin gives outputs, the others through
    numpy); "auto" the compiled ones when numba is there (else numpy: the engine falls back too, and says so)."""
    if engine not in ENGINES:
        raise ModelError(f"output_evaluator: engine must be one of {ENGINES}, got {engine!r}")
    if engine == "numpy":
        return system
    try:
        from .compiled.outputs import CompiledOutputs  # deferred: numba kernels, optional (numpy falls back)
    except ImportError as exc:
        if engine == "compiled":
            raise ModelError(f"output_evaluator: the compiled outputs cannot run: {exc}") from None
        return system
    with compiling():            # the output kernels compile or load here
        return CompiledOutputs(system)


class _Loop:
    """What happens after every accepted step, whichever engine took it: recorder, observers,
    statistics, progress and checkpoints."""

    def __init__(self, recorder, observers, stats, counters, bar, checkpoint):
        self.recorder, self.observers, self.stats, self.counters = recorder, observers, stats, counters
        self.bar, self.checkpoint = bar, checkpoint
        self.timing = dict.fromkeys(("engine_s", "recording_s", "observers_s", "checkpoints_s"), 0.0)

    def steps_to_checkpoint(self) -> int | None:
        ck = self.checkpoint
        return None if ck is None else ck.every - self.stats["steps"] % ck.every

    def accepted(self, s0: State, s1: State, error: float, h_try: float, h_next: float) -> bool:
        """Hand the step to everyone; True when a checkpoint was written (the LU is then dropped)."""
        t0 = time.perf_counter()
        if self.recorder is not None:
            self.recorder.record(s0, s1)
        t1 = time.perf_counter()
        for ob in self.observers:
            ob.step(s0, s1)
        self._time(t0, t1)
        return self._count(s1, error, h_try, h_next)

    def accepted_block(self, blk) -> bool:
        """The same for a compiled block of steps: the recorder and each observer take the block in one call;
        a checkpoint can only fall on the block's last step (the runner ends blocks there)."""
        t0 = time.perf_counter()
        if self.recorder is not None:
            self.recorder.record_block(blk)
        t1 = time.perf_counter()
        for ob in self.observers:
            ob.on_block(blk)
        self._time(t0, t1)
        last = len(blk) - 1
        for i in range(last):
            t1, h_try, err = (float(x) for x in blk.log[i, :3])
            _add_step(self.stats, err, h_try)
            self.bar.update(t1, self.counters)
        return self._count(blk.state, float(blk.log[last, 2]), float(blk.log[last, 1]), blk.h)

    def _time(self, t0: float, t1: float) -> None:
        """The recorder took t0..t1, the observers t1..now."""
        self.timing["recording_s"] += t1 - t0
        self.timing["observers_s"] += time.perf_counter() - t1

    def _count(self, s1: State, error: float, h_try: float, h_next: float) -> bool:
        _add_step(self.stats, error, h_try)
        self.bar.update(s1.t, self.counters)
        if self.checkpoint is not None and self.stats["steps"] % self.checkpoint.every == 0:
            t0 = time.perf_counter()
            _save_checkpoint(self.checkpoint, s1, h_next, self.stats, self.counters, self.recorder, self.observers)
            self.timing["checkpoints_s"] += time.perf_counter() - t0
            return True
        return False


def _numpy_steps(loop: _Loop, system, stepper, controller, state, h, t_end, failed_state_path) -> State:
    cache = NewtonCache()
    h_floor = getattr(controller, "h_min", 0.0)
    span = max(abs(t_end), 1.0)
    while state.t < t_end - 1e-12 * span:
        h_try = min(h, t_end - state.t)
        t0 = time.perf_counter()
        new, info = stepper.step(system, state, h_try, cache)
        loop.timing["engine_s"] += time.perf_counter() - t0
        loop.counters.add(info)
        ok, h_next = controller.decide(h_try, info.converged, info.error)
        if not ok:
            loop.counters.rejected += 1
            if h_next < h_floor:
                _fail(system, state, h_next, info, failed_state_path)
            h = h_next
            continue
        loop.counters.accepted += 1
        if loop.accepted(state, new, info.error, h_try, h_next):
            cache.lu = None
        state, h = new, h_next
    return state


BLOCK = 256      # accepted steps per compiled call (then the recorder and observers see them)


def _compiled_steps(loop: _Loop, system, runner, state, h, t_end, failed_state_path) -> State:
    span = max(abs(t_end), 1.0)
    while state.t < t_end - 1e-12 * span:
        todo = loop.steps_to_checkpoint()
        t0 = time.perf_counter()
        blk = runner.advance(state, h, t_end, BLOCK if todo is None else min(BLOCK, todo))
        loop.timing["engine_s"] += time.perf_counter() - t0
        for k, val in blk.counters.items():
            setattr(loop.counters, k, getattr(loop.counters, k) + val)
        if len(blk) and loop.accepted_block(blk):
            runner.drop_lu()
        state, h = blk.state, blk.h
        if blk.failed is not None:
            _fail(system, state, h, blk.failed, failed_state_path)
    return state


def _begin(model, system, state, controller, counters, recorder, observers, checkpoint, resume):
    """Bind recorder and observers; resume from the checkpoint when asked and one exists.
    Returns (h, stats, counters, state, resumed_from)."""
    h = controller.initial()
    stats = {"steps": 0, "err_max": 0.0, "err_sq": 0.0, "h_lo": np.inf, "h_hi": 0.0}
    if recorder is not None:
        recorder.bind(model, system, state)
    for ob in observers:
        ob.bind(model, system, state)
    if checkpoint is not None and resume and Path(checkpoint.path).exists():
        state, extra, arrays = load_state(checkpoint.path, with_arrays=True)
        if recorder is not None:
            recorder.restore(extra["recorder"])
        for i, ob in enumerate(observers):
            pre = f"obs{i}__"
            ob.load_state_dict({k[len(pre):]: v for k, v in arrays.items() if k.startswith(pre)})
        return extra["h"], extra["stats"], Counters(**extra["counters"]), state, state.t
    if recorder is not None:
        recorder.reset()
        recorder.record(state, None, first=True)
    return h, stats, counters, state, None


def _add_step(stats: dict, error: float, h: float) -> None:
    """Error and step-size statistics of the accepted steps."""
    stats["steps"] += 1
    stats["err_max"] = max(stats["err_max"], error)
    stats["err_sq"] += error ** 2
    stats["h_lo"] = min(stats["h_lo"], h)
    stats["h_hi"] = max(stats["h_hi"], h)


def _save_checkpoint(checkpoint, state, h, stats, counters, recorder, observers) -> None:
    rec = recorder.checkpoint_state() if recorder is not None else {}
    obs = {f"obs{i}__{k}": v for i, ob in enumerate(observers) for k, v in ob.state_dict().items()}
    save_state(checkpoint.path, state, {"h": h, "stats": stats, "counters": counters.as_dict(), "recorder": rec},
               arrays=obs)


def _fail(system: System, state: State, h: float, info, path) -> None:
    fam = system.family_forces(state.t, state.q, state.v, state.z)
    top = max(fam, key=lambda k: (np.nan_to_num(fam[k], nan=np.inf))) if fam else "none"
    saved = None
    if path is not None:
        save_state(path, state, {"reason": info.reason})
        saved = str(path)
    raise IntegrationError(
        f"step size fell below the minimum at t = {state.t:.9e} s (h = {h:.3e} s; Newton: {info.reason or 'error test'}, "
        f"rate {info.rate:.3g}); the element family with the largest force is {top!r} "
        f"(|F| = {fam.get(top, float('nan')):.3e}); last good state "
        + (f"saved to {saved}" if saved else "attached to this exception as .state"),
        state=state, saved_to=saved)


class _Progress:
    """tqdm bar over simulated time: shows the simulated time, steps per second and time left. When stderr is
    not a terminal (a log file, a pipe, CI) it writes a plain line every ``PLAIN_EVERY`` seconds instead of a
    bar's escape codes."""
    PLAIN_EVERY = 10.0

    def __init__(self, t0, t1, show, callback=None):
        self.callback = callback
        self.t_end = t1
        self._last_cb = 0.0
        self.bar = None
        self.t_last = t0
        self.t0 = t0
        self._last_post = time.perf_counter()
        self._start = self._last_post
        self.show = show
        self.total = t1 - t0
        self._steps = 0

    def update(self, t, counters):
        self._steps += 1
        now = time.perf_counter()
        if self.callback is not None and now - self._last_cb > 0.5:
            self._last_cb = now
            self.callback(t, self.t_end, counters)
        if not self.show:
            return
        if self.bar is None:
            if now - self._start < 2.0:   # short runs stay silent
                return
            if not sys.stderr.isatty():
                if now - self._last_post >= self.PLAIN_EVERY:
                    self._last_post = now
                    left = (self.t_end - t) / max(t - self.t0, 1e-300) * (now - self._start)
                    print(f"simulating: t = {t:.4g} of {self.t_end:.4g} s, {self._steps / (now - self._start):.0f} "
                          f"steps/s, " + (f"about {left:.0f} s left" if self._settled(t) else "time left: estimating"),
                          file=sys.stderr, flush=True)
                return
            from tqdm.auto import tqdm  # deferred: ≈ 45 ms (probes Jupyter), only for a bar on a terminal
            self.bar = tqdm(total=self.total, unit="s", unit_scale=True, desc="simulating",
                            bar_format=self.EARLY_FORMAT)
        if self.bar.bar_format == self.EARLY_FORMAT and self._settled(t):
            self.bar.bar_format = self.FORMAT
        self.bar.update(t - self.t_last)
        self.t_last = t
        if now - self._last_post > 0.5:
            self.bar.set_postfix_str(f"{self._steps / (now - self._start):.0f} steps/s, rej {counters.rejected}")
            self._last_post = now

    # the run's start (the kinematic start's short steps) would extrapolate to many times the real time left: the
    # estimate is shown once this share of the simulated time is done
    SETTLED_SHARE = 0.1
    FORMAT = "{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} s [{elapsed}<{remaining}{postfix}]"
    EARLY_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| t={n:.4g}/{total:.4g} s [{elapsed}, time left: estimating{postfix}]"

    def _settled(self, t) -> bool:
        return t - self.t0 >= self.SETTLED_SHARE * (self.t_end - self.t0)

    def close(self):
        if self.bar is not None:
            self.bar.close()
