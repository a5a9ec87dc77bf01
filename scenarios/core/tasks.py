"""Many small independent tasks (static solutions of machines) on Dask: in this process with one worker, else on a
local cluster or an existing scheduler. Tasks go to the workers in batches sized from the tasks' own measured time
(about :data:`BATCH_S` of work each, and at least two batches per worker while there are enough tasks), two batches
per worker in flight and the next submitted as one finishes: a task of 0.1 s would otherwise spend a noticeable part
of its time in Dask's own round trip (Dask's documentation reckons about 1 ms of scheduler overhead per task;
a submission and its result add a few more), and thousands of tasks at once made a graph of tens of MB and held every
task on the scheduler. A line every 10 s (or a bar on a terminal) says how far it is; Ctrl-C takes the unfinished
tasks off the scheduler (results already written stay).

What a task does is the caller's function ``fn``; it must not raise (a failure is a result that says so), so that
one failing machine never stops the others, and it writes nothing: each result is written by this process
(``write``), so the workers need not share a filesystem with it (:mod:`scenarios.core.cluster`; on an existing
scheduler the workers' code is checked first, and a ``--params`` file the tasks name travels as its text).
"""
from __future__ import annotations

import math
import os
import sys
import time
from typing import Callable, Iterable, TypeVar

from tqdm.auto import tqdm

from .cluster import other_code, params_texts, relocated
from .runner import code_digest
from .sweep import RETRIES, dask_client

__all__ = ["solve_tasks", "solve_batch", "scheduling_share", "BATCH_S"]

T = TypeVar("T")
R = TypeVar("R")

BATCH_S = 1.0     # the work [s] a batch of tasks aims at, from the tasks' measured time


def solve_batch(fn: Callable[..., R], tasks: list, extra: tuple, code: str | None = None,
                texts: dict | None = None) -> tuple[list, float]:
    """(``[fn(task, *extra) for task in tasks]``, the seconds they took) on a worker. ``code``: the client's code
    fingerprint (a worker running other code raises, naming both); ``texts``: the ``--params`` files the tasks name, as
    text (:func:`scenarios.core.cluster.params_texts`), for a worker that does not share the client's filesystem."""
    if code is not None:
        refused = other_code(code)
        if refused is not None:
            raise RuntimeError(refused)
    t0 = time.perf_counter()
    out = [fn(relocated(t, texts or {}), *extra) for t in tasks]
    return out, time.perf_counter() - t0


def _batch_size(left: int, n_workers: int, task_s: float | None) -> int:
    """How many of the ``left`` tasks the next batch takes: about :data:`BATCH_S` of work at ``task_s`` per task (one
    task until a task has been timed), and no more than leaves two batches per worker."""
    if task_s is None or left <= 0:
        return 1
    by_time = max(1, int(BATCH_S / max(task_s, 1e-6)))
    return max(1, min(by_time, math.ceil(left / (2 * n_workers))))


def solve_tasks(fn: Callable[..., R], todo: Iterable[T], *, workers: int | None, scheduler: str | None,
                progress: bool, what: str, write: Callable[[T, R], None], failed: Callable[[R], bool] = lambda r: False,
                extra: tuple = (), stats: dict | None = None) -> list[R]:
    """``[fn(task, *extra) for task in todo]`` in the order they finish, each written by ``write(task, result)`` here as
    it arrives; on Dask unless one worker (``workers`` 1 or one task) and no ``scheduler`` is asked. ``what``: the tasks'
    name in progress lines ("static solutions"); ``failed(result)``: whether a result is a failure (counted in the
    progress lines). ``stats``: a dict to fill with ``tasks``, ``batches``, ``workers``, ``start_s`` (Dask imported and
    the cluster started or reached), ``wall_s`` (from the first submission to the last result) and ``task_s`` (the
    seconds the tasks themselves took, summed), from which the scheduling's share of the workers' time is
    ``1 - task_s / (workers × wall_s)`` (:func:`scheduling_share`)."""
    todo = list(todo)
    out: list[R] = []
    stats = {} if stats is None else stats
    if not todo:
        return out
    bars = progress and sys.stderr.isatty()
    bar = tqdm(total=len(todo), desc=what, disable=not bars)
    t0 = last = time.perf_counter()

    def took(task: T, rec: R) -> None:
        nonlocal last
        write(task, rec)
        out.append(rec)
        bar.update(1)
        now = time.perf_counter()
        if progress and not bars and (now - last > 10.0 or len(out) == len(todo)):
            last = now
            print(f"{what}: {len(out)}/{len(todo)} done ({sum(map(failed, out))} failed), {now - t0:.0f} s",
                  file=sys.stderr, flush=True)

    n = workers or min(len(todo), os.cpu_count() or 1)
    busy, batches, t_runs = 0.0, 0, t0
    try:
        if scheduler is None and n <= 1:
            n = 1
            for t in todo:
                t1 = time.perf_counter()
                rec = fn(t, *extra)
                busy += time.perf_counter() - t1
                batches += 1
                took(t, rec)
        else:
            from dask.distributed import as_completed  # deferred: Dask (≈ 0.2–0.4 s) only when solving on it

            with dask_client(n, scheduler) as client:
                if scheduler is not None:   # the workers' own number; the tasks' files travel as text
                    n = max(1, len(client.scheduler_info().get("workers", {})))
                code, texts = (code_digest(), params_texts(todo)) if scheduler is not None else (None, None)
                left = list(reversed(todo))      # popped from the end: the tasks in their order
                running = as_completed()
                batch_of = {}
                timed = []                       # seconds per task of the batches back so far

                def submit():
                    size = min(len(left), _batch_size(len(left), n, sum(timed) / len(timed) if timed else None))
                    tasks = [left.pop() for _ in range(size)]
                    fut = client.submit(solve_batch, fn, tasks, extra, code, texts, pure=False, retries=RETRIES)
                    batch_of[fut.key] = tasks
                    running.add(fut)

                try:
                    t_runs = time.perf_counter()     # the cluster is up: the tasks' phase starts
                    for _ in range(2 * n):
                        if left:
                            submit()
                    for fut in running:
                        recs, seconds = fut.result()
                        tasks = batch_of.pop(fut.key)
                        busy += seconds
                        batches += 1
                        timed.append(seconds / len(tasks))
                        for t, rec in zip(tasks, recs):
                            took(t, rec)
                        if left:
                            submit()
                except BaseException:      # Ctrl-C: take the tasks off the scheduler (results written stay)
                    client.cancel(list(running.futures), force=True)
                    raise
    finally:
        bar.close()
        stats.update(tasks=len(out), batches=batches, workers=n, start_s=t_runs - t0,
                     wall_s=time.perf_counter() - t_runs, task_s=busy)
    return out


def scheduling_share(stats: dict) -> float | None:
    """The share of the workers' time not spent in the tasks themselves (Dask's round trips, the client writing the
    results, workers idle at the end) from :func:`solve_tasks`' ``stats``; None before any task ran."""
    if not stats.get("wall_s") or not stats.get("workers"):
        return None
    return max(0.0, 1.0 - stats["task_s"] / (stats["workers"] * stats["wall_s"]))
