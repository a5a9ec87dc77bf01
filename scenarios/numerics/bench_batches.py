"""What Dask's scheduling costs many small tasks, one per task against in batches (:mod:`scenarios.core.tasks`): tasks
of a known length (a sleep, so that the measure is the machinery's, not the solver's) on two worker processes.

    python -m scenarios.bench_batches [--tasks 500] [--task-ms 40] [--workers 2] [--scheduler ADDR]

Without ``--scheduler`` it starts a local cluster of ``--workers`` processes and reaches it as an existing scheduler
(the workers persist across the passes, as on a cluster). A first pass lets every worker import the project (a
one-off of a few seconds, left out); then two passes each of batches (:data:`scenarios.core.tasks.BATCH_S` of work a
batch) and of one task per submission. Each line: batches, the wall time from the first submission to the last
result, the tasks' own time summed, and the share of the workers' time not spent in the tasks
(:func:`scenarios.core.tasks.scheduling_share`).
"""
from __future__ import annotations

import argparse
import contextlib
import logging
import sys
import time

from ..core import args
from ..core import tasks
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --tasks 2000 --task-ms 10", "{prog} --scheduler tcp://127.0.0.1:8786"]
WRITES = "a line per pass on the screen: batches, wall time, the tasks' own time, the share not in the tasks"


def _milliseconds(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a task length in ms > 0, got {text!r}")
    return v


def parse_args(argv):
    p = args.parser("bench_batches", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--tasks", type=args.count(1), default=500, help="tasks per pass (default 500)")
    p.add_argument("--task-ms", type=_milliseconds, default=40.0, help="each task's length in ms (default 40)")
    args.add_shared(p, "workers", "scheduler")
    return p.parse_args(argv)


def one_pass(address: str, n: int, seconds: float, batch_s: float) -> dict:
    """One pass of ``n`` sleeps of ``seconds`` on the scheduler at ``address``, batched for ``batch_s`` of work (0: one
    task per submission); :func:`scenarios.core.tasks.solve_tasks`' stats."""
    keep, stats = tasks.BATCH_S, {}
    tasks.BATCH_S = batch_s
    try:
        tasks.solve_tasks(time.sleep, [seconds] * n, workers=None, scheduler=address, progress=False, what="sleeps",
                          write=lambda task, r: None, stats=stats)
    finally:
        tasks.BATCH_S = keep
    return stats


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    with contextlib.ExitStack() as stack:
        address = a.scheduler
        if address is None:
            from dask.distributed import LocalCluster  # deferred: Dask only when this benchmark runs

            cluster = stack.enter_context(LocalCluster(n_workers=a.workers or 2, threads_per_worker=1, processes=True,
                                                       dashboard_address=":0", silence_logs=logging.CRITICAL))
            address = cluster.scheduler_address
        one_pass(address, 4 * (a.workers or 2), a.task_ms / 1e3, tasks.BATCH_S)      # the workers import the project
        for batch_s in (tasks.BATCH_S, 0.0, tasks.BATCH_S, 0.0):
            st = one_pass(address, a.tasks, a.task_ms / 1e3, batch_s)
            how = f"batches of ~{batch_s:g} s" if batch_s else "one task per submission"
            print(f"{how}: {st['tasks']} tasks of {a.task_ms:g} ms in {st['batches']} submissions on {st['workers']} "
                  f"workers, {st['wall_s']:.2f} s wall, the tasks {st['task_s']:.2f} s: "
                  f"{100 * tasks.scheduling_share(st):.1f} % of the workers' time not in the tasks", flush=True)
    return 0
