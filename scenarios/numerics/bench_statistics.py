"""What the statistics observer costs: the same settled DPGT window integrated with and without
:class:`components.outputs.WindowStatistics`, interleaved in one process, median of ``--repeats``.

    python -m scenarios.bench_statistics [--conditions 3] [--window 0.001] [--h 5e-6] [--repeats 3]

Prints one JSON object: wall_plain_s, wall_stats_s, overhead (relative), steps.
"""
from __future__ import annotations

import dataclasses
import json
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

EXAMPLES = ["{prog}", "{prog} --conditions 3 --settle 0.01 --window 0.005 --repeats 5"]
WRITES = ("one JSON object on the screen: wall_plain_s, wall_stats_s (medians over --repeats), overhead "
          "(relative), steps, h_s, condition")


def parse_args(argv):
    p = args.parser("bench_statistics", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--settle", type=args.positive("s"), default=3e-3, help="s integrated before the timed window "
                                                                           "(default 0.003)")
    p.add_argument("--window", type=args.positive("s"), default=1e-3, help="timed window [s] (default 0.001)")
    p.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="fixed step [s] (default 5e-6)")
    p.add_argument("--repeats", type=args.count(1), default=3, help="timed repeats of each (default 3)")
    # one condition, through the shared grammar (--condition: the former spelling)
    args.add_shared(p, "conditions", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = build_dpgt(reference_dpgt(a.conditions, "forward"))
    setting = dataclasses.replace(mbd.PRODUCTION, method="hht-fixed", h=a.h)
    kw = dict(stepper=setting.stepper(), controller=setting.controller(), progress=False)
    s0 = mbd.simulate(bs.model, bs.q0, bs.v0, a.settle, **kw).state
    walls = {"plain": [], "stats": []}
    for _ in range(a.repeats):
        for kind in walls:   # interleaved: a busy machine slows both alike
            obs = [WindowStatistics(bs, s0.t, s0.t + a.window)] if kind == "stats" else []
            t = time.perf_counter()
            res = mbd.simulate(bs.model, t_end=s0.t + a.window, state=s0.copy(), observers=obs, **kw)
            walls[kind].append(time.perf_counter() - t)
    m = {k: statistics.median(v) for k, v in walls.items()}
    print(json.dumps({"wall_plain_s": m["plain"], "wall_stats_s": m["stats"], "overhead": m["stats"] / m["plain"] - 1.0,
                      "steps": res.steps, "h_s": a.h, "condition": a.conditions}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
