"""The engine's kernels loaded or compiled in one step (``python -m scenarios.warm``; a cluster's cold workers).

numba caches the compiled kernels on disk; the first run of the code on a machine compiles them, every later run
loads them in about a second. Three groups, each cached on its own: the engine's step loop
(mbd.compiled.stepper.advance, with the assembly and the element families' kernels it calls), the element outputs
the statistics read (mbd.compiled.outputs.family_outputs) and the statistics' accumulators
(components.statistics.accumulate.accumulate_steps). The reference machine's scene (condition 3) has every family
group the scenes compile (contact, generic, mesh), so after a warm every scene of those groups loads instead of
compiling (:func:`mbd.compiled.registry.groups_to_compile`).

With two idle cores or more (:func:`idle_cores`) the compile runs in two processes sharing numba's cache: a second
process compiles the assembly with the family kernels (the largest part, :func:`_compile_assembly`), first branch of
the dispatch first; this one meanwhile compiles the family kernels last branch first (the second process loads those
it reaches after they are cached), the internal-state update, the accumulators and the outputs, then the step loop,
which loads the assembly the second process cached. Each part is announced with its estimate (:data:`ESTIMATES`) and
reported with its time.
"""
from __future__ import annotations

import os
import resource
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import current_process, get_context

import numpy as np
from numba import typeof

import mbd
from mbd import compiled as _compiled
from mbd.compile_time import compiled_here
from mbd.compiled.outputs import family_outputs
from mbd.compiled.registry import entry, kind_of
from mbd.compiled.runner import CompiledRunner
from mbd.compiled.stepper import advance
from mbd.compiled.system import CompiledSystem, assemble, update_internal

from .dpgt import build_dpgt
from .presets import reference_dpgt
from .statistics.accumulate import accumulate_steps, accumulators_cached, compile_accumulators

__all__ = ["warm", "warm_line", "ESTIMATES", "usable_cores", "idle_cores"]

# CPU seconds of the first compile, measured on the reference machine (2 cores shared with other work, 1-minute load
# 3.2-4.5, numba 0.68, condition 3's scene, an empty cache; docs/numerics.md "The compile"): what warm announces. In one
# process (47.0 and 48.6 s) or two (52.7 s: the second costs its own start and kernels both reach); "wall, two
# processes": estimated from that run's parts for two free cores (the first process's start, then the longer of the
# second's assembly, 20 s, and this one's kernels, update, accumulators and outputs, 19 s, then the step loop, 10 s);
# the parts: "assembly" in the second process, with its start; "update" the internal-state update.
ESTIMATES = {"one process": 47.0, "two processes": 52.0, "wall, two processes": 33.0, "assembly": 20.0, "update": 2.0}


def usable_cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # pragma: no cover - not Linux
        return os.cpu_count() or 1


def idle_cores() -> int:
    """The usable cores less the 1-minute load average (at least 1): a second compiling process only helps on a core
    nobody else uses — on a busy machine it costs CPU (its own start, kernels both processes reach) and saves no
    wall."""
    try:
        load = os.getloadavg()[0]
    except OSError:                 # pragma: no cover - no load average
        load = 0.0
    return max(1, usable_cores() - int(round(load)))


def _scene():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # the reference machine's known design warnings
        scene = build_dpgt(reference_dpgt(3))
    return scene, mbd.System(scene.model)


def _assembly_args(cs: CompiledSystem, jac: bool = True) -> tuple:
    """Arguments of the compiled assembly as the step loop passes them (the same numba types: one compiled copy)."""
    z = np.zeros(cs.ndof)
    J = np.zeros(cs.nnz)
    return 0.0, z, z.copy(), cs.fams, cs.zs, bool(jac), cs.sysd, z.copy(), J, J.copy()


def _compile_assembly() -> float:
    """In the second process: compile (or load) the assembly and the family kernels for the scene's groups, into
    numba's disk cache (the step loop then loads them); returns this process's CPU seconds."""
    _, system = _scene()
    cs = CompiledSystem(system)
    entry(assemble, cs.groups, *_assembly_args(cs))
    return time.process_time()


def _compile_kernels_reversed(cs: CompiledSystem) -> None:
    """The family kernels the assembly calls, for its argument types, last branch of the dispatch first: the second
    process compiles them first branch first and loads from the cache those this one has compiled when it gets there."""
    kinds = {k.id: k for k in (kind_of(type(e)) for e, _ in cs.system._evals)}
    seen = set()
    for rec in reversed(list(cs.fams)):
        kind_id, dofs, P, G, zi, keep, mp, ql, vl, Fl, Jql, Jvl = rec
        if kind_id not in seen:
            seen.add(kind_id)
            args = (0.0, 0.0, 0.0, 0.0, ql, vl, cs.zs[zi], P, G, Fl, Jql, Jvl, True)
            kinds[kind_id].evaluate.compile(tuple(typeof(a) for a in args))


def _say(text: str) -> None:
    print(f"warm: {text}", file=sys.stderr, flush=True)


def _timed(name: str, fn, cold: bool, say, announce: bool = True) -> None:
    """Run ``fn``; when ``cold``, announce it with its estimate first (unless the part announces itself) and say
    its CPU and wall seconds after."""
    if cold and announce:
        say(f"compiling the {name} (about {ESTIMATES[name]:.0f} s of CPU)")
    c0, w0 = time.process_time(), time.perf_counter()
    fn()
    if cold:
        say(f"{name}: {time.process_time() - c0:.0f} s CPU, {time.perf_counter() - w0:.0f} s wall")


def warm(jobs: int | None = None, say=_say) -> str:
    """Load or compile the three kernel groups (in two processes when ``jobs`` — by default the idle cores — is
    2 or more, the step loop must compile and this process may start others); returns the line that says which
    (:func:`warm_line`), with the CPU seconds of every process taking part."""
    t0, c0 = time.perf_counter(), time.process_time()
    children0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    jobs = idle_cores() if jobs is None else int(jobs)
    if current_process().daemon:      # a cluster's worker (a daemon process) may not start processes of its own
        jobs = 1
    scene, system = _scene()
    cs = CompiledSystem(system)
    cold = not _compiled.kernels_cached(groups=cs.groups)
    pool = future = None
    if cold:
        total = ESTIMATES["two processes" if jobs > 1 else "one process"]
        wall = ESTIMATES["wall, two processes"] if jobs > 1 else total
        say(f"the engine's kernels of this code are not compiled on this machine yet: compiling them once, about "
            f"{total:.0f} s of CPU, {'two processes, ' if jobs > 1 else ''}about {wall:.0f} s wall on free cores")
    if cold and jobs > 1:
        say(f"compiling the assembly and the family kernels in a second process "
            f"(about {ESTIMATES['assembly']:.0f} s of CPU)")
        pool = ProcessPoolExecutor(1, mp_context=get_context("spawn"))
        future = pool.submit(_compile_assembly)
    try:
        if future is not None:       # the kernels first, last branch first: cached before the other process gets there
            _timed("family kernels", lambda: _compile_kernels_reversed(cs), True, say, announce=False)
        if cold:
            z = np.zeros(cs.ndof)
            _timed("update", lambda: entry(update_internal, cs.groups, 0.0, 0.0, z, z, z, z, cs.fams, cs.zs, cs.sysd),
                   not _compiled.kernels_cached(update_internal), say)
        _timed("accumulators", compile_accumulators, not accumulators_cached(), say, announce=False)
        _timed("outputs", lambda: _warm_outputs(system, scene), not _compiled.kernels_cached("outputs.family_outputs"),
               say, announce=False)
        if future is not None:
            c_other = future.result()
            say(f"assembly (second process): {c_other:.0f} s CPU")
    finally:
        if pool is not None:
            pool.shutdown()
    s = mbd.PRODUCTION
    _timed("step loop", lambda: CompiledRunner(system, s.stepper(), s.controller()), cold, say, announce=False)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = time.process_time() - c0 + (children.ru_utime + children.ru_stime
                                      - children0.ru_utime - children0.ru_stime)
    return warm_line({"engine": advance, "outputs": family_outputs, "accumulators": accumulate_steps},
                     time.perf_counter() - t0, cpu)


def warm_line(groups: dict, seconds: float, cpu: float | None = None) -> str:
    """The one line warm prints: "loaded from the cache" only when every group's kernel (``groups``: name ->
    dispatcher) was loaded; otherwise "compiled", naming the groups compiled (with ``cpu``: the CPU seconds)."""
    cold = [name for name, kernel in groups.items() if compiled_here(kernel)]
    if not cold:
        return f"engine kernels: loaded from the cache in {seconds:.0f} s"
    loaded = [name for name in groups if name not in cold]
    rest = f"; {', '.join(loaded)} loaded from the cache" if loaded else ""
    spent = f", {cpu:.0f} s CPU" if cpu is not None else ""
    return f"engine kernels: compiled in {seconds:.0f} s{spent} ({', '.join(cold)} compiled{rest})"


def _warm_outputs(system, scene) -> None:
    """The compiled element outputs the statistics read (mbd.compiled.outputs), at the scene's start state."""
    z = {k: np.asarray(x)[None] for k, x in system.init_internal().items()}
    mbd.output_evaluator(system, "compiled").outputs_batch(np.zeros(1), scene.q0[None], scene.v0[None], z)
