"""What threads buy one dynamic run: the compiled step loop on 1 and on N threads (``threads``: the bearings'
contact families in chunks of instances on the threads, mbd.compiled.system), condition 3,
the benchmark's settled window, the planar machine and the sliced one, with the serial-fraction model beside it.

    python -m scenarios.bench_threads [--threads 2] [--window 0.005] [--rounds 7] [--slices 21] [--json]

Three runners per machine, built before any clock: the serial engine (the default, ``threads`` = 1), the threaded
one on N threads, and the same threaded one held to one thread (numba.set_num_threads(1): its parallel regions
without a second thread, the threads' overhead). Each round runs the window with each, in an order
that rotates from round to round (one interleaved series: all see the same machine load); per runner the wall, the
process's CPU time (every thread) and the calling thread's CPU time; medians over the rounds, and the median of the
rounds' ratios. Every run's counters and end state must be bit-identical to the serial one's (else it stops).
On a machine whose cores are all busy the wall is no measure of the threads: a process gets a share of the cores per
runnable thread, so two threads get about twice the CPU of one. The calling thread's CPU time holds the serial parts
and its own chunk, not a sleeping wait for the other threads: the wall on idle cores, but for the joins.

The model (Amdahl's law with the measured parallel share): ``p`` the share of a serial step in the threaded parts,
from ``bench_breakdown``'s rows (the contact families of mbd.compiled.registry.THREADED_KINDS, the part of them
that runs threaded: their Jacobian calls on the planar machine, every call on the sliced one), ``o`` the threaded
engine's extra time per step on one thread; the time on N threads T(N) = T(1)·(1 − p + p/N) + o, the speed-up
T(1)/T(N). The shares are read from the breakdown's files in --out (``python -m scenarios.bench_breakdown`` and
``--slices N`` write breakdown.json and breakdown_slicedN.json).
"""
from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import numba
import numpy as np

import mbd
from mbd.compiled.registry import THREADED_KINDS
from mbd.compiled.runner import CompiledRunner
from mbd.compiled.system import check_threads

from .common import FAMILY_ROWS, dpgt_problem, load1, machine_note, progress_log, settled_state, warm_up
from ..core import args
from ..core.command import command

__all__ = ["main", "measure", "amdahl", "parallel_share"]

EXAMPLES = ["{prog}", "{prog} --threads 2 --rounds 9 --json", "{prog} --slices 0"]
WRITES = ("threads.json (reads breakdown.json and breakdown_slicedN.json of bench_breakdown there, and the settled "
          "state dpgt_settled.npz shared with the benchmark); the table on the screen, with --json one JSON object as "
          "the last line")
BLOCK = 256                 # accepted steps per compiled call, as mbd.simulate runs them
H = 5e-6
ALPHA = -0.3
# bench_breakdown's rows of the families that run on the threads
THREADED_ROWS = sorted({FAMILY_ROWS[t] for t in THREADED_KINDS if t in FAMILY_ROWS})


def amdahl(p: float, n: int, overhead: float = 0.0) -> float:
    """Speed-up on n threads of a step whose share p runs in parallel, with ``overhead`` (a share of the serial
    step) added by the threaded code: 1 / (1 − p + p/n + overhead)."""
    return 1.0 / (1.0 - p + p / n + overhead)


def parallel_share(breakdown: dict) -> dict:
    """The share of a serial step in the threaded parts, from a ``bench_breakdown`` result: the threaded families'
    rows, their Jacobian calls only on the planar machine (its residuals stay in the calling thread,
    mbd.compiled.system._partition), every call on the sliced one."""
    rows = {r["part"]: r for r in breakdown["rows"]}
    step = breakdown["cpu_per_step_us"]
    jac_calls = breakdown["calls_per_step"]["jacobian"]
    names = [n for n in THREADED_ROWS if n in rows]
    if breakdown.get("slices"):
        families = sum(rows[n]["us_per_step"] for n in names)
    else:
        families = sum(jac_calls * rows[n]["jacobian_us"] for n in names)
    return {"threaded_us": families, "step_us": step, "p": families / step}


class _Held:
    """A threaded runner held to one thread (its own numba setting replaced while it runs)."""

    def __init__(self, runner: CompiledRunner):
        self.runner = runner

    def drop_lu(self):
        self.runner.drop_lu()

    def advance(self, *a):
        cs = self.runner.cs
        threads, cs.threads = cs.threads, 1
        try:
            return self.runner.advance(*a)
        finally:
            cs.threads = threads


def _window(runner, s0: mbd.State, t_end: float):
    """The window in blocks of 256 from s0 (a fresh LU): wall, process CPU, thread CPU, counters, end state."""
    runner.drop_lu()
    total = dict.fromkeys(("residual", "jacobian", "factor", "newton", "accepted", "rejected"), 0)
    state, h = s0, H
    w0, p0, t0 = time.perf_counter(), time.process_time(), time.thread_time()
    while state.t < t_end - 1e-12 * max(1.0, abs(t_end)):
        blk = runner.advance(state, h, t_end, BLOCK)
        if blk.failed is not None or not len(blk):
            raise mbd.IntegrationError(f"bench_threads: the window failed at t = {blk.state.t:.6g} s")
        for k, c in blk.counters.items():
            total[k] += c
        state, h = blk.state, blk.h
    return time.perf_counter() - w0, time.process_time() - p0, time.thread_time() - t0, total, state


def _same(a: mbd.State, b: mbd.State) -> bool:
    return (a.t == b.t and all(np.array_equal(x, y) for x, y in ((a.q, b.q), (a.v, b.v), (a.a, b.a), (a.f, b.f)))
            and all(np.array_equal(a.z[k], b.z[k]) for k in a.z))


def measure(threads: int, window: float, rounds: int, slices: int, out: Path, log=print) -> dict:
    """The interleaved series on one machine (``slices`` 0: planar; else the sliced machine, as bench_breakdown)."""
    prob = dpgt_problem()
    s0, _ = settled_state(prob, out / "dpgt_settled.npz")
    if slices:              # the sliced machine from the planar one's settled state, every slope and tilt zero
        prob = dpgt_problem(overrides={"bearing.model": "sliced", "bearing.slicing.slices": slices})
        ext = lambda x: np.concatenate([x, np.zeros(prob.model.ndof - x.size)])           # noqa: E731
        s0 = mbd.State(s0.t, ext(s0.q), ext(s0.v), ext(s0.a), ext(s0.f), dict(s0.z))
    warm_up(prob, s0)
    system = mbd.System(prob.model)
    stepper = mbd.HHT(alpha=ALPHA)
    serial = CompiledRunner(system, stepper, mbd.FixedStep(H))
    threaded = CompiledRunner(system, stepper, mbd.FixedStep(H), threads=threads)
    runners = {"serial": serial, "threaded, 1 thread": _Held(threaded), f"threaded, {threads} threads": threaded}
    names = list(runners)
    t_end = s0.t + window
    for name in names:                 # untimed: every entry loaded, the threads started
        _window(runners[name], s0, s0.t + 20 * H)
    res = {name: {"wall_s": [], "process_cpu_s": [], "thread_cpu_s": []} for name in names}
    ref_counters = ref_state = None
    load_before = load1()
    for rnd in range(rounds):
        order = names[rnd % len(names):] + names[:rnd % len(names)]
        for name in order:
            wall, pcpu, tcpu, counters, state = _window(runners[name], s0, t_end)
            if ref_state is None:
                ref_counters, ref_state = counters, state
            elif counters != ref_counters or not _same(state, ref_state):
                raise RuntimeError(f"bench_threads: {name} is not bit-identical to the first run "
                                   f"({counters} against {ref_counters})")
            for k, x in (("wall_s", wall), ("process_cpu_s", pcpu), ("thread_cpu_s", tcpu)):
                res[name][k].append(x)
        log(f"round {rnd + 1}/{rounds}: " + ", ".join(f"{n} {res[n]['wall_s'][-1]:.2f} s wall" for n in names)
            + f"; 1-min load {load1():.1f}")
    steps = ref_counters["accepted"]
    par = names[2]
    out_rows = {}
    for name in names:
        r = res[name]
        out_rows[name] = {k: statistics.median(v) for k, v in r.items()} | {
            "wall_us_per_step": 1e6 * statistics.median(r["wall_s"]) / steps,
            "wall_ratio_to_serial": statistics.median(
                a / b for a, b in zip(res["serial"]["wall_s"], r["wall_s"])),
            "cpu_ratio_to_serial": statistics.median(
                a / b for a, b in zip(res["serial"]["process_cpu_s"], r["process_cpu_s"])),
            "thread_cpu_ratio_to_serial": statistics.median(
                a / b for a, b in zip(res["serial"]["thread_cpu_s"], r["thread_cpu_s"]))}
    return {"slices": slices, "dofs": int(prob.model.ndof), "threads": threads, "window_s": window, "h_s": H,
            "alpha": ALPHA, "steps": steps, "counters": ref_counters, "rounds": rounds, "runs": res, "rows": out_rows,
            "speedup_wall": out_rows[par]["wall_ratio_to_serial"],
            "speedup_calling_thread": out_rows[par]["thread_cpu_ratio_to_serial"],
            "overhead_share_at_1": 1.0 / out_rows[names[1]]["cpu_ratio_to_serial"] - 1.0,
            "bit_identical": True, "threading_layer": numba.threading_layer(),
            "machine": machine_note(), "load": {"before": load_before, "after": load1()}}


def model(res: dict, breakdown: dict, upto=(2, 4, 6, 8, 16)) -> dict:
    """The serial-fraction model of one machine: p from the breakdown, the overhead from the 1-thread run."""
    share = parallel_share(breakdown)
    o = max(res["overhead_share_at_1"], 0.0)
    return share | {"overhead": o, "predicted": {n: amdahl(share["p"], n, o) for n in upto},
                    "limit": 1.0 / (1.0 - share["p"] + o)}


def table(results: list) -> str:
    lines = []
    for res in results:
        what = f"sliced machine, {res['slices']} slices" if res["slices"] else "planar machine"
        lines += [f"{what} ({res['dofs']} DOF): {res['steps']} steps of {res['h_s']:.0e} s, {res['rounds']} "
                  f"interleaved rounds, threading layer {res['threading_layer']}; every run bit-identical to the serial",
                  "", "| runner | wall µs/step | wall s | process CPU s | calling thread CPU s | serial / this: wall, "
                      "process CPU, calling thread CPU (medians of the rounds' ratios) |", "|---|---|---|---|---|---|"]
        for name, r in res["rows"].items():
            lines.append(f"| {name} | {r['wall_us_per_step']:.1f} | {r['wall_s']:.3f} | {r['process_cpu_s']:.3f} | "
                         f"{r['thread_cpu_s']:.3f} | {r['wall_ratio_to_serial']:.3f}, {r['cpu_ratio_to_serial']:.3f}, "
                         f"{r['thread_cpu_ratio_to_serial']:.3f} |")
        m = res.get("model")
        if m:
            lines += ["", f"model: parallel share p = {m['p']:.3f} ({m['threaded_us']:.1f} µs of the threaded families "
                          f"in {m['step_us']:.1f} µs), overhead at "
                          f"1 thread {100 * m['overhead']:.1f} %: predicted speed-up "
                          + ", ".join(f"{n} threads {s:.2f}×" for n, s in m["predicted"].items())
                          + f", limit {m['limit']:.2f}×; measured at {res['threads']} threads: wall "
                          f"{res['speedup_wall']:.2f}×, the calling thread's CPU {res['speedup_calling_thread']:.2f}×"]
        lines.append("")
    return "\n".join(lines)


@command
def main(argv=None) -> int:
    ap = args.parser("bench_threads", __doc__, examples=EXAMPLES, writes=WRITES, out="results/numerics")
    ap.add_argument("--json", action="store_true", help="print one JSON object on the last line")
    ap.add_argument("--threads", type=args.count(2), default=2, help="threads of the threaded runner (≤ the cores)")
    ap.add_argument("--window", type=args.positive("s"), default=0.005, help="settled window each run steps [s]")
    ap.add_argument("--rounds", type=args.count(1), default=7, help="interleaved rounds (medians)")
    ap.add_argument("--slices", type=args.count(0), default=21,
                    help="the sliced machine's slices per roller, measured after the planar one (0: planar only)")
    args.add_shared(ap, "out", out="results/numerics")
    a = ap.parse_args(argv)
    try:
        check_threads(a.threads)
    except mbd.ModelError as exc:
        ap.error(f"--threads: {exc}")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    log = progress_log(a.json)
    log(machine_note())
    results = []
    machines = (0, a.slices) if a.slices else (0,)
    files = {n: out / (f"breakdown_sliced{n}.json" if n else "breakdown.json") for n in machines}
    for n, f in files.items():
        if not f.is_file():
            ap.error(f"{f} is missing: run python -m scenarios.bench_breakdown --out {out}"
                     + (f" --slices {n}" if n else "") + " first (the model's parallel share)")
    for n in machines:
        res = measure(a.threads, a.window, a.rounds, n, out, log)
        res["model"] = model(res, json.loads(files[n].read_text()))
        results.append(res)
    (out / "threads.json").write_text(json.dumps(results, indent=2, default=str))
    log(table(results))
    if a.json:
        print(json.dumps(results, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
