"""The engine's kernels loaded or compiled in one step (``python -m scenarios.warm``; a cluster's cold workers).

numba caches the compiled step loop on disk; the first run of the code on a machine compiles it (about a minute on
2 cores), every later run loads it in about a second. Three groups of kernels, each cached on its own: the engine's
step loop (mbd.compiled.stepper.advance), the element outputs the statistics read (mbd.compiled.outputs.family_outputs)
and the statistics' accumulators (components.statistics.accumulate.accumulate_steps).
"""
from __future__ import annotations

import time
import warnings

import numpy as np

import mbd
from mbd.compile_time import compiled_here
from mbd.compiled.outputs import family_outputs
from mbd.compiled.runner import CompiledRunner
from mbd.compiled.stepper import advance

from .dpgt import build_dpgt
from .presets import reference_dpgt
from .statistics.accumulate import accumulate_steps, compile_accumulators

__all__ = ["warm", "warm_line"]


def warm() -> str:
    """Load or compile the three kernel groups; returns the line that says which (:func:`warm_line`)."""
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # the reference machine's known design warnings
        scene = build_dpgt(reference_dpgt(3))
    s = mbd.PRODUCTION
    system = mbd.System(scene.model)
    CompiledRunner(system, s.stepper(), s.controller())
    _warm_outputs(system, scene)
    compile_accumulators()
    return warm_line({"engine": advance, "outputs": family_outputs, "accumulators": accumulate_steps},
                     time.perf_counter() - t0)


def warm_line(groups: dict, seconds: float) -> str:
    """The one line warm prints: "loaded from the cache" only when every group's kernel (``groups``: name ->
    dispatcher) was loaded; otherwise "compiled", naming the groups compiled."""
    cold = [name for name, kernel in groups.items() if compiled_here(kernel)]
    if not cold:
        return f"engine kernels: loaded from the cache in {seconds:.0f} s"
    loaded = [name for name in groups if name not in cold]
    rest = f"; {', '.join(loaded)} loaded from the cache" if loaded else ""
    return f"engine kernels: compiled in {seconds:.0f} s ({', '.join(cold)} compiled{rest})"


def _warm_outputs(system, scene) -> None:
    """The compiled element outputs the statistics read (mbd.compiled.outputs), at the scene's start state."""
    z = {k: np.asarray(x)[None] for k, x in system.init_internal().items()}
    mbd.output_evaluator(system, "compiled").outputs_batch(np.zeros(1), scene.q0[None], scene.v0[None], z)
