"""What a quasi-static solution costs (components.static): the DPGT's static snapshots at one condition, the first
from the kinematic pose, the others each carried over from the last, and the 8-snapshot statistics a static run
reports — in one process, the medians over ``--repeats``.

    python -m scenarios.bench_static [--conditions 3] [--directions forward] [--snapshots 8] [--repeats 3]

Prints one JSON object: first_s (a snapshot from the kinematic pose), warm_s (median of the carried-over ones),
steps_first, steps_warm (continuation steps), statistics_s (the whole static_statistics call), condition, direction.
"""
from __future__ import annotations

import json
import statistics
import sys
import time
import warnings

import mbd
from components import static
from components.dpgt import build_dpgt
from components.presets import reference_dpgt

from ..core import args
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --conditions 2 --directions reverse --snapshots 16 --repeats 5"]
WRITES = ("one JSON object on the screen: first_s, warm_s (medians over --repeats), steps_first, steps_warm, "
          "statistics_s, snapshots, condition, direction")


def parse_args(argv):
    p = args.parser("bench_static", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--directions", default="forward", choices=["forward", "reverse"], help="one direction")
    p.add_argument("--snapshots", type=args.count(1), default=static.DEFAULT_SNAPSHOTS,
                   help=f"snapshots per repeat (default {static.DEFAULT_SNAPSHOTS})")
    p.add_argument("--repeats", type=args.count(1), default=3, help="timed repeats (default 3)")
    args.add_shared(p, "conditions", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


def measure(condition: int, direction: str, snapshots: int, repeats: int) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = build_dpgt(reference_dpgt(condition, direction))
    system = mbd.System(scene.model)
    times = static.snapshot_times(scene, snapshots)
    static.solve_snapshots(scene, times[:2], system=system)          # kernels loaded, caches warm
    first, warm, steps_first, steps_warm, whole = [], [], [], [], []
    for _ in range(repeats):
        sols = static.solve_snapshots(scene, times, system=system)
        first.append(sols[0].wall_s)
        steps_first.append(sols[0].steps)
        warm += [s.wall_s for s in sols[1:]]
        steps_warm += [s.steps for s in sols[1:]]
        t0 = time.perf_counter()
        static.static_statistics(scene, snapshots)
        whole.append(time.perf_counter() - t0)
    med = statistics.median
    return {"first_s": med(first), "warm_s": med(warm) if warm else None, "steps_first": med(steps_first),
            "steps_warm": med(steps_warm) if steps_warm else None, "statistics_s": med(whole),
            "snapshots": snapshots, "condition": condition, "direction": direction}


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    print(json.dumps(measure(int(a.conditions), a.directions, a.snapshots, a.repeats), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
