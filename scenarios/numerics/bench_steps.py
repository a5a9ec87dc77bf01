"""What sets the adaptive step at an operating point: which DOFs make the controller's local error estimate.

    python -m scenarios.bench_steps [--conditions 1] [--settle 0.03] [--window 0.01] [--set KEY=VALUE ...]

One dynamic run of each condition (forward, production settings, compiled engine, into a temporary folder). Every
accepted step's scaled local error estimate e_i = (β − 1/6) h² (a₁,ᵢ − a₀,ᵢ) / atol_i (the one the controller
accepts when its RMS ≤ 1, docs/numerics.md §1) is taken from the compiled runner's log, its squares summed per DOF
over the run. Printed per condition: accepted steps per simulated second, the median step (p10, p90), rejections,
Newton iterations per step, and the shares of Σe² of the bodies' coordinates — the rollers' x, y turned into radial
and tangential about their planet's centre, inner (a…) and outer (b…) bearings apart — with the largest single DOFs.
docs/numerics.md §5 ("What sets the step") quotes it.
"""
from __future__ import annotations

import json
import sys
import tempfile
import warnings
from collections import defaultdict

import numpy as np

import mbd.compiled.runner as runner_module

from components.params import with_overrides
from components.presets import reference_dpgt

from ..core import args
from ..core.runner import RunConfig, run_case
from ..core.command import command

EXAMPLES = ["{prog} --conditions 1,3", "{prog} --conditions 1 --set operating.output_power=\"2 kW\""]
WRITES = "one JSON object on the screen per condition"


def parse_args(argv):
    p = args.parser("bench_steps", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds before the window (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=0.01, help="seconds recorded (default 0.01)")
    args.add_shared(p, "conditions", "set", conditions="1",
                    conditions_why="condition 1 (the heaviest torque) takes the smallest steps")
    return p.parse_args(argv)


def error_squares(h: np.ndarray, a0: np.ndarray, a1: np.ndarray, errc: float, atol: np.ndarray) -> np.ndarray:
    """(steps, n) squared scaled local error estimates of accepted steps of sizes ``h`` (steps,), whose
    accelerations go from ``a0`` to ``a1`` (steps, n) each: the terms whose mean is the controller's RMS²."""
    e = errc * (h * h)[:, None] * (a1 - a0) / atol[None, :]
    return e * e


def roller_split(e2x, e2y, exy, ux, uy):
    """Radial and tangential parts of a roller's (x, y) error vector: its squared components along
    u = (ux, uy) and across it, from the squares e2x, e2y and the product exy of its x and y errors."""
    radial = e2x * ux * ux + 2.0 * exy * ux * uy + e2y * uy * uy
    return radial, e2x + e2y - radial


class _Tally:
    """Hooks :meth:`CompiledRunner.advance` and sums the error squares of every accepted step it logs."""

    def __init__(self):
        self.sums = defaultdict(float)
        self.per_dof = None
        self.h, self.accepted, self.rejected, self.newton = [], 0, 0, 0

    def take(self, runner, state, blk):
        n, log = runner.n, blk.log
        if not len(log):
            return
        names = runner.cs.model.body_names
        h = log[:, 1]
        a1 = log[:, 3 + 2 * n:3 + 3 * n]
        a0 = np.vstack([np.asarray(state.a, float)[None, :], a1[:-1]])
        e = runner.prm[3] * (h * h)[:, None] * (a1 - a0) / runner.atol[None, :]
        e2 = e * e
        self.per_dof = e2.sum(axis=0) + (0.0 if self.per_dof is None else self.per_dof)
        idx = {nm: i for i, nm in enumerate(names)}
        q = log[:, 3:3 + n]
        for i, nm in enumerate(names):
            if ".roller" not in nm:
                for c, xyz in enumerate("xyt"):
                    self.sums[f"{nm}.{xyz}"] += e2[:, 3 * i + c].sum()
                continue
            p = idx[nm.split(".")[0]]
            dx, dy = q[:, 3 * i] - q[:, 3 * p], q[:, 3 * i + 1] - q[:, 3 * p + 1]
            L = np.hypot(dx, dy)
            radial, tangential = roller_split(e2[:, 3 * i], e2[:, 3 * i + 1], e[:, 3 * i] * e[:, 3 * i + 1],
                                              dx / L, dy / L)
            side = "inner" if nm.startswith("a") else "outer"
            self.sums[f"{side} rollers radial"] += radial.sum()
            self.sums[f"{side} rollers tangential"] += tangential.sum()
            self.sums[f"{side} rollers spin"] += e2[:, 3 * i + 2].sum()
        self.h.extend(h)
        self.accepted += len(log)
        self.rejected += blk.counters["rejected"]
        self.newton += blk.counters["newton"]
        self.names = names

    def report(self, simulated: float) -> dict:
        total = sum(self.sums.values())
        h = np.array(self.h)
        shares = sorted(((k, v / total) for k, v in self.sums.items()), key=lambda kv: -kv[1])
        return {"accepted_per_simulated_s": self.accepted / simulated,
                "h_median_us": float(np.median(h) * 1e6), "h_p10_us": float(np.percentile(h, 10) * 1e6),
                "h_p90_us": float(np.percentile(h, 90) * 1e6),
                "rejected_share": self.rejected / max(self.accepted + self.rejected, 1),
                "newton_per_step": self.newton / max(self.accepted, 1),
                "error_share": {k: round(v, 4) for k, v in shares if v >= 0.005}}


def measure(condition: int, settle: float, window: float, sets: dict) -> dict:
    tally, original = _Tally(), runner_module.CompiledRunner.advance

    def advance(self, state, h, t_end, max_steps):
        blk = original(self, state, h, t_end, max_steps)
        tally.take(self, state, blk)
        return blk

    runner_module.CompiledRunner.advance = advance
    try:
        with warnings.catch_warnings(), tempfile.TemporaryDirectory() as d:
            warnings.simplefilter("ignore")
            p = with_overrides(reference_dpgt(condition, "forward"), sets)
            run_case(p, RunConfig(settle=settle, window=window, progress=False), d)
    finally:
        runner_module.CompiledRunner.advance = original
    return {"condition": condition, "set": sets, **tally.report(settle + window)}


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    for c in [int(x) for x in a.conditions.split(",")]:
        print(json.dumps(measure(c, a.settle, a.window, args.parse_sets(a.set))), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
