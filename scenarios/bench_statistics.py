"""What the statistics observer costs: the same settled DPGT window integrated with and without
:class:`components.outputs.WindowStatistics`, interleaved in one process, median of ``--repeats``.

    python -m scenarios.bench_statistics [--condition 3] [--window 0.001] [--h 5e-6] [--repeats 3]

Prints one JSON object: wall_plain_s, wall_stats_s, overhead (relative), steps.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import time
import warnings

import mbd
from components.dpgt import build_dpgt
from components.outputs import WindowStatistics
from components.presets import reference_dpgt


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m scenarios.bench_statistics", description=__doc__.split("\n\n")[0])
    p.add_argument("--condition", type=int, default=3, choices=(1, 2, 3, 4))
    p.add_argument("--settle", type=float, default=3e-3, help="s integrated before the timed window")
    p.add_argument("--window", type=float, default=1e-3, help="timed window [s]")
    p.add_argument("--h", type=float, default=5e-6, help="fixed step [s]")
    p.add_argument("--repeats", type=int, default=3)
    a = p.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = build_dpgt(reference_dpgt(a.condition, "forward"))
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
                      "steps": res.steps, "h_s": a.h, "condition": a.condition}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
