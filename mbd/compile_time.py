"""Time this process spends compiling or loading the compiled kernels (numba), so that a run reports its wall time
without it and the compile beside it (the first run of the code on a machine compiles for a minute or more, every
later one loads the kernels in about a second: neither is the run's own time).

Each place that compiles or loads kernels runs inside :func:`compiling`: :func:`mbd.simulate` building the compiled
runner (the compiled twin of the system and its step loop), :func:`mbd.output_evaluator` building the compiled
outputs, and :func:`mbd.compiled.compile_announced` (the statistics' accumulators). :func:`compile_seconds` is the running total; a run
takes the difference over its span. Imports nothing of numba (the numpy path has nothing to time).
"""
from __future__ import annotations

import time
from contextlib import contextmanager

__all__ = ["compiling", "compile_seconds", "compiled_here"]

_total = 0.0
_depth = 0          # a timed block inside another is counted once, by the outer one


@contextmanager
def compiling():
    """Time the block as compiling or loading kernels (added to :func:`compile_seconds`)."""
    global _total, _depth
    _depth += 1
    t0 = time.perf_counter()
    try:
        yield
    finally:
        _depth -= 1
        if _depth == 0:
            _total += time.perf_counter() - t0


def compile_seconds() -> float:
    """Seconds this process has spent in :func:`compiling` blocks so far."""
    return _total


def compiled_here(kernel) -> bool:
    """Did this process compile ``kernel`` (a numba dispatcher) instead of loading it from the disk cache? True when
    numba counted a cache miss, or no hit at all (a kernel not called, or a cache that could not be read, was not
    loaded from it)."""
    st = kernel.stats
    return sum(st.cache_misses.values()) > 0 or sum(st.cache_hits.values()) == 0
