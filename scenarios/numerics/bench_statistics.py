"""What the statistics observer costs: the same settled DPGT window integrated with and without
:class:`components.outputs.WindowStatistics`, interleaved in one process, median of ``--repeats``.

    python -m scenarios.bench_statistics [--conditions 3] [--window 0.001] [--h 5e-6] [--repeats 3] [--profile]

Prints one JSON object: wall_plain_s, wall_stats_s, overhead (relative), steps; with ``--profile`` also where the
observer's time goes (cProfile over the observer's runs: its parts in µs per step and as a share of it) and its
time over the engine's in the same runs (``overhead_in_run``: steadier than the ratio of two runs' medians on a
shared machine, whose load changes between runs).
"""
from __future__ import annotations

import cProfile
import dataclasses
import json
import pstats
import statistics
import sys
import time
import warnings

import mbd
from components.dpgt import build_dpgt
from components.outputs import WindowStatistics
from components.presets import reference_dpgt

from ..core import args
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --conditions 3 --settle 0.01 --window 0.005 --repeats 5",
            "{prog} --conditions 3 --settle 0.01 --window 0.005 --repeats 5 --profile"]
WRITES = ("one JSON object on the screen: wall_plain_s, wall_stats_s (medians over --repeats), overhead "
          "(relative), steps, h_s, condition; with --profile also overhead_in_run and profile")

# the observer's parts the profile reports: label -> (file, function); nested ones after the part they are in
PARTS = {
    "on_block": ("components/statistics/observer.py", "on_block"),
    "snapshots (every per-step quantity of the block's states)": ("components/statistics/quantities.py", "quantities"),
    "element outputs, compiled kernels (the contacts)": ("mbd/compiled/outputs.py", "outputs_batch"),
    "element outputs, numpy kernels": ("mbd/assembly.py", "outputs_batch"),
    "EHL film and its per-bearing extremes": ("components/statistics/quantities.py", "film_extremes"),
    "traction heat and coefficient": ("components/statistics/quantities.py", "traction_heat"),
    "carrier-frame motion": ("components/statistics/quantities.py", "carrier_frame_motion"),
    "pin reactions": ("components/statistics/quantities.py", "pin_reactions"),
    "accumulators (concatenation, compiled loop)": ("components/statistics/observer.py", "_accumulate"),
}


def parse_args(argv):
    p = args.parser("bench_statistics", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--settle", type=args.positive("s"), default=3e-3, help="s integrated before the timed window "
                                                                           "(default 0.003)")
    p.add_argument("--window", type=args.positive("s"), default=1e-3, help="timed window [s] (default 0.001)")
    p.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="fixed step [s] (default 5e-6)")
    p.add_argument("--repeats", type=args.count(1), default=3, help="timed repeats of each (default 3)")
    p.add_argument("--profile", action="store_true", help="profile the observer's runs (cProfile): its parts per "
                                                          "step and its time over the engine's in the same runs")
    # one condition, through the shared grammar (--condition: the former spelling)
    args.add_shared(p, "conditions", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


def _profile(prof: cProfile.Profile, wall_stats: float, steps: int) -> tuple[float, dict]:
    """(the observer's time over the engine's in its runs, {part: {"us_per_step", "share"}}) from the profile of
    the observer's runs (``wall_stats`` their summed wall time [s], ``steps`` their accepted steps)."""
    cum = {}
    for (path, _, name), (_, _, _, ct, callers) in pstats.Stats(prof).stats.items():
        for label, (suffix, fn) in PARTS.items():
            if name == fn and path.replace("\\", "/").endswith(suffix):
                # the output evaluator's load-or-compile call on an empty block when an observer binds is set-up,
                # not a step's work (and lies outside the snapshots the outputs are otherwise part of)
                setup = sum(c[3] for (cpath, _, cname), c in callers.items()
                            if cname == "<lambda>" and cpath.replace("\\", "/").endswith("mbd/compiled/outputs.py"))
                cum[label] = cum.get(label, 0.0) + ct - setup
    total = cum["on_block"]
    parts = {k: {"us_per_step": round(1e6 * cum[k] / steps, 2), "share": round(cum[k] / total, 4)}
             for k in PARTS if k in cum}
    return total / (wall_stats - total), parts


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = build_dpgt(reference_dpgt(a.conditions, "forward"))
    setting = dataclasses.replace(mbd.PRODUCTION, method="hht-fixed", h=a.h)
    kw = dict(stepper=setting.stepper(), controller=setting.controller(), progress=False)
    s0 = mbd.simulate(bs.model, bs.q0, bs.v0, a.settle, **kw).state
    run = lambda obs: mbd.simulate(bs.model, t_end=s0.t + a.window, state=s0.copy(), observers=obs, **kw)
    walls = {"plain": [], "stats": []}
    for _ in range(a.repeats):
        for kind in walls:   # interleaved: a busy machine slows both alike
            obs = [WindowStatistics(bs, s0.t, s0.t + a.window)] if kind == "stats" else []
            t = time.perf_counter()
            res = run(obs)
            walls[kind].append(time.perf_counter() - t)
    m = {k: statistics.median(v) for k, v in walls.items()}
    out = {"wall_plain_s": m["plain"], "wall_stats_s": m["stats"], "overhead": m["stats"] / m["plain"] - 1.0,
           "steps": res.steps, "h_s": a.h, "condition": a.conditions}
    if a.profile:        # more runs with the observer, under the profiler (the timed ones above stay unprofiled)
        prof, wall, steps = cProfile.Profile(), 0.0, 0
        for _ in range(a.repeats):
            obs = [WindowStatistics(bs, s0.t, s0.t + a.window)]
            t = time.perf_counter()
            prof.enable()
            steps += run(obs).steps
            prof.disable()
            wall += time.perf_counter() - t
        out["overhead_in_run"], out["profile"] = _profile(prof, wall, steps)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
