"""Compile the engine's kernels once, in their own step (``make demo`` and ``make test`` run it first).

    python -m scenarios.warm

numba caches the compiled step loop on disk; the first run of the code on a machine compiles it (about a
minute on 2 cores), every later run loads it in about a second. Doing it here, once, says so in one line and
keeps it out of the runs that follow (and out of parallel test workers, which would each compile it).
"""
from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import mbd
from components.dpgt import build_dpgt
from components.presets import reference_dpgt
from components.statistics.accumulate import accumulators_cached, compile_accumulators
from mbd.compiled import kernels_cached
from mbd.compiled.runner import CompiledRunner


def main(argv=None) -> int:
    cached = kernels_cached() and kernels_cached("outputs.family_outputs") and accumulators_cached()
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # the reference machine's known design warnings
        scene = build_dpgt(reference_dpgt(3))
    s = mbd.PRODUCTION
    system = mbd.System(scene.model)
    CompiledRunner(system, s.stepper(), s.controller())
    _warm_outputs(system, scene)
    compile_accumulators()
    what = "loaded from the cache" if cached else "compiled and cached"
    print(f"engine kernels: {what} in {time.perf_counter() - t0:.0f} s", flush=True)
    return 0


def _warm_outputs(system, scene) -> None:
    """The compiled element outputs the statistics read (mbd.compiled.outputs), at the scene's start state."""
    z = {k: np.asarray(x)[None] for k, x in system.init_internal().items()}
    mbd.output_evaluator(system, "compiled").outputs_batch(np.zeros(1), scene.q0[None], scene.v0[None], z)


if __name__ == "__main__":
    sys.exit(main())
