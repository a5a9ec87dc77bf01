"""What the sliced planet bearings cost (bearing.model = "sliced", docs/model.md §8.8): the DPGT's step at one
condition with the planar contacts and with the sliced ones, from the same loaded state, interleaved, medians.

    python -m scenarios.bench_sliced [--conditions 3] [--slices 21] [--steps 20] [--repeats 5] [--no-numpy]
                                     [--loop-steps 200] [--budget 120]

The loaded state is the planar machine ``--settle`` seconds into its load ramp (compiled engine); the sliced
machine starts from it with every slope and tilt at zero. Each repeat times ``--steps`` fixed steps of 5 µs of:
the planar machine on the compiled path and on the numpy path, the sliced machine on the compiled path and on the
numpy path (``--no-numpy``: the compiled paths only), each a call of :func:`mbd.simulate` (its set-up — the
compiled system, the LU's symbolic analysis — included, in wall time).

The step itself: each repeat also runs ``--loop-steps`` fixed steps of each machine in the compiled step loop alone
(one :class:`mbd.compiled.runner.CompiledRunner` per machine, built before the clock; a fresh Jacobian at the start)
and times it in the thread's CPU time (a shared machine deschedules a run for part of its wall); the engine's
counters give the residuals, Jacobians and Newton iterations per step. Repeats stop early when ``--budget`` seconds
have passed (at least one). Prints one JSON object: seconds per step (medians) and the ratios sliced/planar.
"""
from __future__ import annotations

import json
import os
import statistics
import sys
import time
import warnings

import numpy as np

import mbd
from mbd.compiled.runner import CompiledRunner
from components.dpgt import build_dpgt
from components.presets import reference_dpgt

from ..core import args
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --conditions 3 --slices 31 --steps 40 --repeats 3"]
WRITES = "one JSON object on the screen: seconds per step (medians over --repeats) and the ratios"
H = 5e-6


def parse_args(argv):
    p = args.parser("bench_sliced", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--slices", type=args.count(1), default=21, help="slices per roller n_s (default 21)")
    p.add_argument("--steps", type=args.count(1), default=20, help="fixed steps of 5 us per timing (default 20)")
    p.add_argument("--repeats", type=args.count(1), default=5, help="interleaved timed repeats (default 5)")
    p.add_argument("--settle", type=float, default=0.004, help="seconds of load ramp before timing (default 0.004)")
    p.add_argument("--no-numpy", action="store_true", help="time the compiled paths only")
    p.add_argument("--loop-steps", type=args.count(1), default=200,
                   help="fixed steps per timing of the compiled step loop alone, CPU time (default 200)")
    p.add_argument("--budget", type=args.positive("s"), default=120.0,
                   help="no further repeat starts after this many seconds (default 120)")
    args.add_shared(p, "conditions", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


def _loop(runner, state, steps):
    """CPU seconds per step of ``steps`` fixed steps of the compiled step loop alone, and its counters per step."""
    runner.drop_lu()
    t_end = state.t + steps * H
    total = dict.fromkeys(("residual", "jacobian", "factor", "newton", "accepted", "rejected"), 0)
    s, h, t0 = state, H, time.thread_time()
    while s.t < t_end - 1e-12:
        blk = runner.advance(s, h, t_end, 256)
        if blk.failed is not None or not len(blk):
            raise mbd.IntegrationError(f"bench_sliced: the loop failed at t = {blk.state.t:.6g} s")
        for k, c in blk.counters.items():
            total[k] += c
        s, h = blk.state, blk.h
    cpu = time.thread_time() - t0
    acc = max(total["accepted"], 1)
    return cpu / acc, {k: total[k] / acc for k in ("residual", "jacobian", "newton")}


def _run(model, state, steps, engine):
    t0 = time.perf_counter()
    res = mbd.simulate(model, t_end=state.t + steps * H, state=state.copy(), stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.FixedStep(H), progress=False, engine=engine)
    return (time.perf_counter() - t0) / max(res.counters["accepted"], 1)


def measure(condition: int, slices: int, steps: int, repeats: int, settle: float, numpy: bool = True,
            loop_steps: int = 200, budget: float = 120.0) -> dict:
    p = reference_dpgt(condition, "forward")
    ps = p.replace(bearing=p.bearing.replace(model="sliced", slicing=p.bearing.slicing.replace(slices=slices)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        planar, sliced = build_dpgt(p), build_dpgt(ps)
    res = mbd.simulate(planar.model, planar.q0, planar.v0, settle, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, engine="compiled")
    s = res.state
    n = planar.model.ndof
    ext = lambda x: np.concatenate([x, np.zeros(sliced.model.ndof - n)])          # noqa: E731
    s_sl = mbd.State(s.t, ext(s.q), ext(s.v), ext(s.a), ext(s.f), dict(s.z))
    runs = {"planar_compiled": (planar.model, s, "compiled"), "sliced_compiled": (sliced.model, s_sl, "compiled")}
    if numpy:
        runs.update(planar_numpy=(planar.model, s, "numpy"), sliced_numpy=(sliced.model, s_sl, "numpy"))
    for model, st, eng in runs.values():
        _run(model, st, 2, eng)                                                   # kernels loaded, caches warm
    stepper = mbd.PRODUCTION.stepper()
    loops = {k: (CompiledRunner(mbd.System(model), stepper, mbd.FixedStep(H)), st)
             for k, (model, st, eng) in runs.items() if eng == "compiled"}
    t = {k: [] for k in runs}
    cpu = {k: [] for k in loops}
    counts = {}
    start = time.perf_counter()
    for r in range(repeats):                                                      # interleaved
        for k, (model, st, eng) in runs.items():
            t[k].append(_run(model, st, steps, eng))
        for k, (runner, st) in loops.items():
            c, counts[k] = _loop(runner, st, loop_steps)
            cpu[k].append(c)
        if time.perf_counter() - start > budget:
            break
    med = {k: statistics.median(v) for k, v in t.items()}
    loop = {k: statistics.median(v) for k, v in cpu.items()}
    out = {"condition": condition, "slices": slices, "steps": steps, "repeats": len(cpu["planar_compiled"]),
           "dofs_planar": n, "dofs_sliced": sliced.model.ndof,
           "loop_steps": loop_steps, **{f"{k}_loop_cpu_us_per_step": 1e6 * v for k, v in loop.items()},
           "sliced_over_planar_loop_cpu": loop["sliced_compiled"] / loop["planar_compiled"],
           **{f"{k}_calls_per_step": v for k, v in counts.items()},
           "loop_cpu_us_all": {k: [round(1e6 * x, 1) for x in v] for k, v in cpu.items()},
           **{f"{k}_s_per_step": v for k, v in med.items()},
           "sliced_over_planar_compiled": med["sliced_compiled"] / med["planar_compiled"],
           "load1": os.getloadavg()[0]}
    if numpy:
        out.update(sliced_over_planar_numpy=med["sliced_numpy"] / med["planar_numpy"],
                   sliced_numpy_over_planar_compiled=med["sliced_numpy"] / med["planar_compiled"])
    return out


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    print(json.dumps(measure(int(a.conditions), a.slices, a.steps, a.repeats, a.settle, not a.no_numpy,
                                     a.loop_steps, a.budget), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
