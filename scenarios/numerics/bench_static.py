"""What a quasi-static solution costs (components.static): the DPGT's static snapshots at one condition, the first
from the kinematic pose, the others each carried over from the last, and the 8-snapshot statistics a static run
reports — in one process, the medians over ``--repeats``. ``--laws tanh,ehl`` times one machine per traction law,
interleaved (law by law within every repeat, so that a busy machine's slow spells fall on both alike).

    python -m scenarios.bench_static [--conditions 3] [--directions forward] [--snapshots 8] [--repeats 3]
        [--laws tanh,ehl] [--set KEY=VALUE]

Prints one JSON object per law: first_s (a snapshot from the kinematic pose), warm_s (median of the carried-over
ones), steps_first, steps_warm (continuation steps), statistics_s (the whole static_statistics call), condition,
direction, law.
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
import warnings

import mbd
from components import static
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt

from ..core import args
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --conditions 2 --directions reverse --snapshots 16 --repeats 5",
            "{prog} --conditions 2 --laws tanh,ehl --repeats 5"]
WRITES = ("one JSON object on the screen per traction law: first_s, warm_s, statistics_s (medians over --repeats), "
          "steps_first, steps_warm, snapshots, condition, direction, law")
LAWS = ("tanh", "slide_roll", "ehl")


def laws(text):
    """A comma-separated list of traction laws (bearing.traction_law)."""
    out = [w.strip() for w in str(text).split(",") if w.strip()]
    bad = [w for w in out if w not in LAWS]
    if not out or bad:
        raise argparse.ArgumentTypeError(f"expects traction laws among {', '.join(LAWS)}, got {text!r}")
    return out


def parse_args(argv):
    p = args.parser("bench_static", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--directions", default="forward", choices=["forward", "reverse"], help="one direction")
    p.add_argument("--snapshots", type=args.count(1), default=static.DEFAULT_SNAPSHOTS,
                   help=f"snapshots per repeat (default {static.DEFAULT_SNAPSHOTS})")
    p.add_argument("--repeats", type=args.count(1), default=3, help="timed repeats (default 3)")
    p.add_argument("--laws", type=laws, default=None, metavar="LAW[,LAW...]",
                   help="time one machine per traction law, interleaved within every repeat (default: the machine's own)")
    args.add_shared(p, "conditions", "set", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


def measure(condition: int, direction: str, snapshots: int, repeats: int, overrides: dict | None = None,
            laws: list | None = None) -> list[dict]:
    """One record per traction law in ``laws`` (None: the machine's own), the repeats interleaved law by law."""
    runs = []
    for law in laws or [None]:
        ov = {**(overrides or {}), **({"bearing.traction_law": law} if law else {})}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = build_dpgt(with_overrides(reference_dpgt(condition, direction), ov))
        system = mbd.System(scene.model)
        times = static.snapshot_times(scene, snapshots)
        static.solve_snapshots(scene, times[:2], system=system)          # kernels loaded, caches warm
        runs.append(dict(law=scene.bearing.traction_law, scene=scene, system=system, times=times, first=[], warm=[],
                         steps_first=[], steps_warm=[], whole=[]))
    for _ in range(repeats):
        for r in runs:
            sols = static.solve_snapshots(r["scene"], r["times"], system=r["system"])
            r["first"].append(sols[0].wall_s)
            r["steps_first"].append(sols[0].steps)
            r["warm"] += [s.wall_s for s in sols[1:]]
            r["steps_warm"] += [s.steps for s in sols[1:]]
            t0 = time.perf_counter()
            static.static_statistics(r["scene"], snapshots)
            r["whole"].append(time.perf_counter() - t0)
    med = statistics.median
    return [{"first_s": med(r["first"]), "warm_s": med(r["warm"]) if r["warm"] else None,
             "steps_first": med(r["steps_first"]), "steps_warm": med(r["steps_warm"]) if r["steps_warm"] else None,
             "statistics_s": med(r["whole"]), "snapshots": snapshots, "condition": condition, "direction": direction,
             "law": r["law"]} for r in runs]


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    for rec in measure(int(a.conditions), a.directions, a.snapshots, a.repeats, args.parse_sets(a.set), a.laws):
        print(json.dumps(rec, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
