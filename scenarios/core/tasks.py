"""Many small independent tasks (static solutions of machines) on Dask: in this process with one worker, else on a
local cluster or an existing scheduler, a few tasks per worker in flight and the next submitted as one finishes
(thousands at once made a graph of tens of MB and held every task on the scheduler). A line every 10 s (or a bar on
a terminal) says how far it is; Ctrl-C takes the unfinished tasks off the scheduler (files already written stay).

What a task does and where it writes its result is the caller's function: it must not raise (a failure is a result
that says so), so that one failing machine never stops the others.
"""
from __future__ import annotations

import itertools
import os
import sys
import time
from typing import Callable, Iterable, TypeVar

from tqdm.auto import tqdm

from .sweep import dask_client

__all__ = ["solve_tasks"]

T = TypeVar("T")
R = TypeVar("R")


def solve_tasks(fn: Callable[..., R], todo: Iterable[T], *, workers: int | None, scheduler: str | None,
                progress: bool, what: str, failed: Callable[[R], bool] = lambda r: False, extra: tuple = ()) -> list[R]:
    """``[fn(task, *extra) for task in todo]`` in the order they finish, on Dask unless one worker (``workers`` 1 or
    one task) and no ``scheduler`` is asked. ``what``: the tasks' name in progress lines ("static solutions");
    ``failed(result)``: whether a result is a failure (counted in the progress lines)."""
    todo = list(todo)
    out: list[R] = []
    if not todo:
        return out
    bars = progress and sys.stderr.isatty()
    bar = tqdm(total=len(todo), desc=what, disable=not bars)
    t0 = last = time.perf_counter()

    def took(rec: R) -> None:
        nonlocal last
        out.append(rec)
        bar.update(1)
        now = time.perf_counter()
        if progress and not bars and (now - last > 10.0 or len(out) == len(todo)):
            last = now
            print(f"{what}: {len(out)}/{len(todo)} done ({sum(map(failed, out))} failed), {now - t0:.0f} s",
                  file=sys.stderr, flush=True)

    n = workers or min(len(todo), os.cpu_count() or 1)
    try:
        if scheduler is None and n <= 1:
            for t in todo:
                took(fn(t, *extra))
        else:
            from dask.distributed import as_completed  # deferred: Dask (≈ 0.2–0.4 s) only when solving on it

            with dask_client(n, scheduler) as client:
                queue = iter(todo)
                running = as_completed()
                try:
                    for t in itertools.islice(queue, 4 * n):
                        running.add(client.submit(fn, t, *extra, pure=False))
                    for fut in running:
                        took(fut.result())
                        for t in itertools.islice(queue, 1):
                            running.add(client.submit(fn, t, *extra, pure=False))
                except BaseException:      # Ctrl-C: take the tasks off the scheduler (finished files stay)
                    client.cancel(list(running.futures), force=True)
                    raise
    finally:
        bar.close()
    return out
