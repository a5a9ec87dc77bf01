"""Where a step of the compiled engine goes: the benchmark's settled window (condition 3, HHT α = −0.3, fixed h)
split into its parts — each element family's kernel, the assembly around them, the LU, the solves, the
internal-state update and the rest of the step loop — in µs per accepted step against the loop's measured time.

    python -m scenarios.bench_breakdown [--window 0.01] [--samples 24] [--rounds 3] [--reps 20] [--target 3] [--json]
                                        [--slices N]

The engine runs the window from the settled state (the benchmark's, cached in OUT/dpgt_settled.npz) and counts its
work: residual-only assemblies, residual + Jacobian assemblies, LUs, Newton iterations (one solve each), accepted
steps. Each part's cost per call is measured in compiled loops of ``--reps`` calls (no Python in between) at
``--samples`` states of that window; per state the median over ``--rounds`` rounds, then the mean over the states.
The rounds interleave every part and the engine's own time (the compiled loop alone, blocks of 256 steps as
``mbd.simulate`` runs them), so all see the same machine load; everything is timed in the thread's CPU time (on
a shared machine a long run is descheduled for part of its wall, short timings mostly not: their walls would not
add up; the loop's wall is reported beside it). µs per step = calls per step × cost per call.
The parts are also replayed in a step's mix and order (the counted calls per step, spread over consecutive
steps, with the update after each): what that costs beyond their sum measured one part at a time is their
interaction (caches: alone, a part finds its data where it left it); the loop's time per step less the replay is
the rest of the step (predictor, norms and convergence tests, the log row, a compiled call per block). ``--target``
[s per 0.1 s] gives the µs per step a target needs (the target: 3 s per 0.1 s of condition 3) and how much must go.
``--slices N`` splits the sliced machine's step instead (bearing.model = "sliced", N slices per roller, docs/model.md
§8.8), from the planar machine's settled state with every slope and tilt at zero (the straight profile's exact
planar reduction: the state is settled for the sliced machine too).
"""
from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import mbd
from mbd.compiled.probe import repeat_assemble, repeat_kernel, repeat_lu, repeat_solve, repeat_update, replay
from mbd.compiled.registry import call
from mbd.compiled.runner import CompiledRunner
from mbd.compiled.system import _full

from .common import FAMILY_ROWS, dpgt_problem, load1, machine_note, progress_log, settled_state, warm_up
from ..core import args
from ..core.command import command

__all__ = ["main", "breakdown"]

EXAMPLES = ["{prog}", "{prog} --window 0.02 --samples 40 --rounds 5 --json"]
WRITES = ("breakdown.json (and the settled state dpgt_settled.npz, shared with the benchmark); the table on the "
          "screen, with --json one JSON object as the last line")

OTHER = "other families"
BLOCK = 256     # accepted steps per compiled call, as mbd.simulate runs them


# CPU time of this thread, not wall: on a shared machine a long run is descheduled for a share of its wall that
# short timings escape, so walls of the two would not add up (the wall is reported beside it)
_clock = time.thread_time


def _timed(fn, reps, *a) -> float:
    t0 = _clock()
    fn(reps, *a)
    return (_clock() - t0) / reps


def _timed_groups(fn, groups, reps, *a) -> float:
    """:func:`_timed` of a loop that reaches the family kernels: compiled for the system's kernel groups (a literal,
    :func:`mbd.compiled.registry.call`), and compiled before the clock starts."""
    call(fn, groups, 0, *a)
    t0 = _clock()
    call(fn, groups, reps, *a)
    return (_clock() - t0) / reps


# ------------------------------------------------------------------------------------------------------ parts
class _Parts:
    """Per-call costs of every part at one state (a method per part; each returns seconds per call)."""

    def __init__(self, runner: CompiledRunner, alpha: float, h: float):
        self.r, self.cs = runner, runner.cs
        system = self.cs.system
        self.rows = []                  # (row label, index of the family record)
        for idx, (e, _) in enumerate(system._evals):
            twin = type(e).compiled_twin
            self.rows.append((FAMILY_ROWS.get(twin, OTHER), idx))
        beta, gamma = runner.prm[1], runner.prm[2]
        self.c_C, self.c_K = (1.0 + alpha) * gamma * h, (1.0 + alpha) * beta * h * h
        self.omega = float(self.cs.sysd[3])

    def local(self, t, q, v):
        """Each family's (ql, vl) at a state, gathered as the assembly does."""
        free, fixed_idx, fixed_q_I, omega = self.cs.sysd[:4]
        qf, vf = _full(float(t), q, v, free, fixed_idx, fixed_q_I, omega, self.cs.sysd[12])
        return [(np.ascontiguousarray(qf[rec[1]]), np.ascontiguousarray(vf[rec[1]])) for rec in self.cs.fams]

    def kernels(self, t, q, v, z, reps) -> dict:
        """{(record index, jac): s per call}."""
        self.cs.set_internal(z)
        out = {}
        for idx, (ql, vl) in enumerate(self.local(t, q, v)):
            kind, dofs, P, G, zi = self.cs.fams[idx][:5]
            n, k = dofs.shape
            F, Jq, Jv = np.empty((n, k)), np.empty((n, k, k)), np.empty((n, k, k))
            zz = self.cs.zs[zi]
            for jac in (False, True):
                out[idx, jac] = _timed_groups(repeat_kernel, self.cs.groups, reps, kind, float(t), self.omega * t, self.omega, ql, vl, zz,
                                       P, G, F, Jq, Jv, jac)
        return out

    def assembly(self, t, q, v, z, reps) -> dict:
        self.cs.set_internal(z)
        F, Jq, Jv = np.empty(self.cs.ndof), np.empty(self.cs.nnz), np.empty(self.cs.nnz)
        return {jac: _timed_groups(repeat_assemble, self.cs.groups, reps, float(t), q, v, self.cs.fams, self.cs.zs, jac, self.cs.sysd,
                            F, Jq, Jv) for jac in (False, True)}

    def lu_and_solve(self, t, q, v, z, reps) -> tuple[float, float]:
        ev = self.cs.evaluate(t, q, v, z, jac=True)
        Mdata = self.r.pat[2]
        lu = self.r.lu[0]
        A = np.empty(self.cs.nnz)
        t_lu = _timed(repeat_lu, reps, self.c_C, self.c_K, Mdata, ev.Jq, ev.Jv, A, lu)
        if not repeat_lu(1, self.c_C, self.c_K, Mdata, ev.Jq, ev.Jv, A, lu):
            raise mbd.IntegrationError("bench_breakdown: a zero pivot in the sparse LU at a sampled state")
        b = np.ascontiguousarray(ev.F)
        t_solve = _timed(repeat_solve, reps, lu, b)
        return t_lu, t_solve

    def replay(self, s0, s1, calls, steps) -> float:
        """s per step of :func:`mbd.compiled.probe.replay` at s1 (s0: the state before, for the update)."""
        self.cs.set_internal(s1["z"])
        ev = self.cs.evaluate(s1["t"], s1["q"], s1["v"], s1["z"], jac=True)
        Mdata = self.r.pat[2]
        n = self.cs.ndof
        F, Jq, Jv, A = np.empty(n), np.empty(self.cs.nnz), np.empty(self.cs.nnz), np.empty(self.cs.nnz)
        return _timed_groups(replay, self.cs.groups, steps, calls["residual"], calls["jacobian"], calls["solve"], float(s1["t"]), s1["q"],
                      s1["v"], self.cs.fams, self.cs.zs, self.cs.sysd, F, Jq, Jv, self.c_C, self.c_K, Mdata, A,
                      self.r.lu[0], np.ascontiguousarray(ev.F), float(s0["t"]), s0["q"], s0["v"])

    def update(self, s0, s1, reps) -> float:
        self.cs.set_internal(s0["z"])
        dt = _timed_groups(repeat_update, self.cs.groups, reps, float(s0["t"]), float(s1["t"]), s0["q"], s0["v"], s1["q"], s1["v"],
                    self.cs.fams, self.cs.zs, self.cs.sysd)
        return dt


def _engine_wall(runner: CompiledRunner, s0: mbd.State, h: float, t_end: float) -> tuple[float, float, dict]:
    """The compiled step loop alone over [s0.t, t_end] in blocks of 256 (a fresh LU at the start): CPU time, wall,
    counters."""
    runner.drop_lu()
    total = dict.fromkeys(("residual", "jacobian", "factor", "newton", "accepted", "rejected"), 0)
    state, t0, w0 = s0, _clock(), time.perf_counter()
    while state.t < t_end - 1e-12 * max(1.0, abs(t_end)):
        blk = runner.advance(state, h, t_end, BLOCK)
        if blk.failed is not None or not len(blk):
            raise mbd.IntegrationError(f"bench_breakdown: the window failed at t = {blk.state.t:.6g} s")
        for k, c in blk.counters.items():
            total[k] += c
        state, h = blk.state, blk.h
    return _clock() - t0, time.perf_counter() - w0, total


def breakdown(out: Path, window: float = 0.01, samples: int = 24, rounds: int = 3, reps: int = 20, h: float = 5e-6,
              alpha: float = -0.3, settle: float = 0.03, target_s_per_100ms: float = 3.0, log=print,
              slices: int = 0) -> dict:
    prob = dpgt_problem(settle=settle)
    s0, _ = settled_state(prob, out / "dpgt_settled.npz")
    if slices:              # the sliced machine from the planar one's settled state, every slope and tilt zero
        prob = dpgt_problem(settle=settle, overrides={"bearing.model": "sliced", "bearing.slicing.slices": slices})
        ext = lambda x: np.concatenate([x, np.zeros(prob.model.ndof - x.size)])           # noqa: E731
        s0 = mbd.State(s0.t, ext(s0.q), ext(s0.v), ext(s0.a), ext(s0.f), dict(s0.z))
    warm_up(prob, s0)
    system = mbd.System(prob.model)
    stepper = mbd.HHT(alpha=alpha)
    runner = CompiledRunner(system, stepper, mbd.FixedStep(h))
    load_before = load1()
    # the window's states: every accepted step's end from one untimed run, `samples` of them evenly spread
    states, blk_state, hh = [], s0, h
    while blk_state.t < s0.t + window - 1e-12:
        blk = runner.advance(blk_state, hh, s0.t + window, BLOCK)
        t_, q_, v_, _, z_ = blk.arrays()
        for i in range(1, t_.size):
            states.append({"t": t_[i], "q": np.ascontiguousarray(q_[i]), "v": np.ascontiguousarray(v_[i]),
                           "z": {k: np.array(val[i]) for k, val in z_.items()}})
        blk_state, hh = blk.state, blk.h
    pick = np.unique(np.linspace(1, len(states) - 1, samples).round().astype(int))
    parts = _Parts(runner, alpha, h)
    per = {"kernel": [], "assembly": [], "lu": [], "update": [], "replay": []}
    walls, cpus, counters = [], [], None
    for rnd in range(rounds):
        cpu, w, c = _engine_wall(runner, s0, h, s0.t + window)
        walls.append(w)
        cpus.append(cpu)
        if counters is not None and c != counters:
            raise RuntimeError(f"bench_breakdown: the window's counters changed between rounds ({counters} → {c})")
        counters = c
        kern, asm, lus, upd, rep = [], [], [], [], []
        mix = {k: c[k] / c["accepted"] for k in ("residual", "jacobian")} | {"solve": c["newton"] / c["accepted"]}
        for i in pick:
            s = states[i]
            kern.append(parts.kernels(s["t"], s["q"], s["v"], s["z"], reps))
            asm.append(parts.assembly(s["t"], s["q"], s["v"], s["z"], reps))
            lus.append(parts.lu_and_solve(s["t"], s["q"], s["v"], s["z"], reps))
            upd.append(parts.update(states[i - 1], s, reps))
            rep.append(parts.replay(states[i - 1], s, mix, reps))
        per["replay"].append(rep)
        per["kernel"].append(kern)
        per["assembly"].append(asm)
        per["lu"].append(lus)
        per["update"].append(upd)
        log(f"round {rnd + 1}/{rounds}: engine {cpu:.2f} s CPU ({w:.2f} s wall) for {c['accepted']} steps; 1-min load "
            f"{load1():.1f}")

    def cost(get):
        """Per state the median over the rounds, then the mean over the states [s per call]."""
        return float(np.mean([statistics.median(get(r, j) for r in range(rounds)) for j in range(pick.size)]))

    steps = counters["accepted"]
    calls = {"residual": counters["residual"] / steps, "jacobian": counters["jacobian"] / steps,
             "lu": counters["factor"] / steps, "solve": counters["newton"] / steps, "update": 1.0}
    fam = {}
    for label, idx in parts.rows:
        for jac in (False, True):
            fam.setdefault(label, {False: 0.0, True: 0.0})[jac] += cost(lambda r, j: per["kernel"][r][j][idx, jac])
    asm = {jac: cost(lambda r, j: per["assembly"][r][j][jac]) for jac in (False, True)}
    t_lu = cost(lambda r, j: per["lu"][r][j][0])
    t_solve = cost(lambda r, j: per["lu"][r][j][1])
    t_upd = cost(lambda r, j: per["update"][r][j])
    glue = {jac: asm[jac] - sum(f[jac] for f in fam.values()) for jac in (False, True)}
    cpu_step = cpu / steps
    cpu_step = cpu / steps
    rows = []

    def row(name, res_s, jac_s, us):
        rows.append({"part": name, "residual_us": res_s * 1e6 if res_s is not None else None,
                     "jacobian_us": jac_s * 1e6 if jac_s is not None else None, "us_per_step": us,
                     "share": us * 1e-6 / cpu_step})

    order = [r for r in ("race", "pocket", "guide", "drag", "meshes", OTHER) if r in fam]
    for name in order:
        f = fam[name]
        row(name, f[False], f[True], 1e6 * (calls["residual"] * f[False] + calls["jacobian"] * f[True]))
    row("assembly (gather, scatter, frame terms)", glue[False], glue[True],
        1e6 * (calls["residual"] * glue[False] + calls["jacobian"] * glue[True]))
    row("Newton matrix + sparse LU", None, t_lu, 1e6 * calls["lu"] * t_lu)
    row("solve (L U)", t_solve, None, 1e6 * calls["solve"] * t_solve)
    row("internal-state update", t_upd, None, 1e6 * t_upd)
    measured = sum(r["us_per_step"] for r in rows)
    t_replay = cost(lambda r, j: per["replay"][r][j])
    row("the parts called in a step's mix and order, over their sum alone", None, None, t_replay * 1e6 - measured)
    row("rest of the step loop (predictor, norms, tests, log; loop − the replay)", None, None,
        (cpu_step - t_replay) * 1e6)
    steps_per_100ms = steps * 0.1 / window
    target_us = target_s_per_100ms / steps_per_100ms * 1e6
    res = {"slices": slices, "dofs": int(prob.model.ndof), "window_s": window, "h_s": h, "alpha": alpha, "steps": steps, "counters": counters,
           "calls_per_step": calls, "samples": int(pick.size), "rounds": rounds, "reps": reps,
           "cpu_s": cpu, "cpus_s": cpus, "cpu_per_step_us": cpu_step * 1e6, "wall_s": statistics.median(walls),
           "walls_s": walls,
           "cpu_per_100ms_s": cpu * 0.1 / window,
           "replay_per_step_us": t_replay * 1e6, "assemble_residual_us": asm[False] * 1e6, "assemble_jacobian_us": asm[True] * 1e6,
           "rows": rows, "target_s_per_100ms": target_s_per_100ms, "target_us_per_step": target_us,
           "cut_needed_us_per_step": cpu_step * 1e6 - target_us, "speedup_needed": cpu_step * 1e6 / target_us,
           "clock": "thread CPU time (time.thread_time)",
           "machine": machine_note(), "load": {"before": load_before, "after": load1()}}
    return res


def table(res: dict) -> str:
    c = res["calls_per_step"]
    what = f"sliced machine, {res['slices']} slices" if res.get("slices") else "planar machine"
    lines = [f"{what} ({res.get('dofs')} DOF), settled window {res['window_s']:g} s, h = {res['h_s']:.0e} s, α = {res['alpha']:g}: {res['steps']} steps; "
             f"per step {c['residual']:.2f} residuals, {c['jacobian']:.3f} residual+Jacobians, {c['lu']:.3f} LUs, "
             f"{c['solve']:.2f} solves",
             f"engine {res['cpu_s']:.3f} s CPU (median of {res['rounds']}; wall {res['wall_s']:.3f} s) = "
             f"{res['cpu_per_step_us']:.1f} µs per step = {res['cpu_per_100ms_s']:.2f} s per 0.1 s; one assembly "
             f"{res['assemble_residual_us']:.1f} µs, with the Jacobian {res['assemble_jacobian_us']:.1f} µs (CPU time "
             "throughout)",
             "", "| part | µs per residual call | µs per Jacobian call | µs per step | share |", "|---|---|---|---|---|"]
    fmt = lambda x: "—" if x is None else f"{x:.2f}"   # noqa: E731
    for r in res["rows"]:
        lines.append(f"| {r['part']} | {fmt(r['residual_us'])} | {fmt(r['jacobian_us'])} | {r['us_per_step']:.1f} | "
                     f"{100 * r['share']:.1f} % |")
    lines.append(f"| **the step loop, measured** | | | **{res['cpu_per_step_us']:.1f}** | 100 % |")
    lines += ["", f"target {res['target_s_per_100ms']:g} s per 0.1 s = {res['target_us_per_step']:.1f} µs per step: "
                  f"{res['cut_needed_us_per_step']:.1f} µs per step must go ({res['speedup_needed']:.2f}× faster)"]
    return "\n".join(lines)


@command
def main(argv=None) -> int:
    ap = args.parser("bench_breakdown", __doc__, examples=EXAMPLES, writes=WRITES, out="results/numerics")
    ap.add_argument("--json", action="store_true", help="print one JSON object on the last line")
    ap.add_argument("--window", type=args.positive("s"), default=0.01, help="settled window run and sampled [s]")
    ap.add_argument("--samples", type=args.count(2), default=24, help="states of the window the parts are timed at")
    ap.add_argument("--rounds", type=args.count(1), default=3, help="interleaved rounds (medians)")
    ap.add_argument("--reps", type=args.count(1), default=20, help="calls per timing, in one compiled loop")
    ap.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="HHT fixed step [s]")
    ap.add_argument("--alpha", type=args.alpha, default=-0.3, help="HHT alpha in [-1/3, 0]")
    ap.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="settling time before the window [s]")
    ap.add_argument("--target", type=args.positive("s"), default=3.0, help="target wall per 0.1 s simulated [s]")
    ap.add_argument("--slices", type=args.count(0), default=0,
                    help="split the sliced machine's step (N slices per roller; 0: the planar machine)")
    args.add_shared(ap, "out", out="results/numerics")
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    log = progress_log(a.json)
    log(machine_note())
    res = breakdown(out, a.window, a.samples, a.rounds, a.reps, a.h, a.alpha, a.settle, a.target, log, a.slices)
    (out / (f"breakdown_sliced{a.slices}.json" if a.slices else "breakdown.json")).write_text(json.dumps(res, indent=2, default=str))
    log(table(res))
    if a.json:
        print(json.dumps(res, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
