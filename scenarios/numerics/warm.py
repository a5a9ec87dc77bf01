"""Compile the engine's kernels once, in their own step (``make demo`` and ``make test`` run it first).

    python -m scenarios.warm [--jobs N]

numba caches the compiled kernels on disk; the first run of the code on a machine compiles them (about 45 s of CPU,
docs/numerics.md "The compile"), every later run loads them in about a second. Doing it here, once, says so and
keeps it out of the runs that follow (and out of parallel test workers, which would each compile it). With two idle
cores or more (``--jobs``: by default the usable cores less the 1-minute load; 1 compiles in this process only) the
assembly and its family kernels compile in a second process while this one compiles the rest
(:mod:`components.warm`); each part is announced with its estimate and reported with its CPU and wall seconds. The
last line says "loaded from the cache" only when numba loaded all three kernel groups; it names those it had to
compile otherwise (numba's own count of cache hits and misses, read after the call).
"""
from __future__ import annotations

import argparse
import sys

from components.warm import warm, warm_line

__all__ = ["main", "warm", "warm_line"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m scenarios.warm", description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=None,
                        help="processes compiling at once (default: the idle cores, the usable ones less the "
                             "1-minute load; 1: this process only)")
    jobs = parser.parse_args(argv).jobs
    if jobs is not None and jobs < 1:
        parser.error(f"--jobs: expected a whole number >= 1, got {jobs}")
    print(warm(jobs), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
