"""Compile the engine's kernels once, in their own step (``make demo`` and ``make test`` run it first).

    python -m scenarios.warm

numba caches the compiled step loop on disk; the first run of the code on a machine compiles it (about a minute on
2 cores), every later run loads it in about a second. Doing it here, once, says so in one line and keeps it out of
the runs that follow (and out of parallel test workers, which would each compile it). The line says "loaded from
the cache" only when numba loaded all three kernel groups (:mod:`components.warm`); it names those it had to compile
otherwise (numba's own count of cache hits and misses, read after the call).
"""
from __future__ import annotations

import sys

from components.warm import warm, warm_line

__all__ = ["main", "warm", "warm_line"]


def main(argv=None) -> int:
    print(warm(), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
