"""Stability on stiff and extreme cases: does each integrator get through, and at what cost?

    python -m scenarios.stability [--quick] [--out DIR] [--window S] [--cap S] [--cases a,b,...]

Every case is the full DPGT (condition 3 forward, N = 3, Z = 12 unless the case changes it) with one
change, integrated from the kinematic start through the sun-torque ramp (20 mesh periods ≈ 3.5 ms at
condition 3) for a short window: 5 ms (--quick: 1.5 ms). Start-up (ramp, first cage impacts) is the
hardest stretch numerically, so a short window from t = 0 is a fair stress test that keeps the whole
table to minutes.

Integrators per case: HHT α = −0.3, adaptive (atol 10 nm, h0 = 5 µs, h_max = 10 µs: the default of
scenarios.core.runner), and scipy Radau (rtol 1e-5, sparse analytic Jacobian) with a wall-time cap (--cap).
A failure is reported with its cause — for HHT the IntegrationError message names the time, the step
size and the element family with the largest force; a scene the design checks refuse is reported
as such — never hidden.

Sanity numbers (HHT, over the last third of the window, sampled every 20 µs): RMS pin-reaction of the
first inner planet bearing [N] and the largest roller–inner-race load of that bearing [N]; for Radau
the pin reaction at the end of the window against HHT's (relative difference).

Design-check verdicts are part of the outcome: a refused case (Z ≥ 16 on the reference bearing) gets a
"build" row with the check's message; N ≥ 4 planet pairs collide on the reference gears — the check
only warns — so those cases get a "design check" row and are run anyway, labelled NON-PHYSICAL.

Outputs in OUT: stability.csv, stability.json, stability.md (the table for docs/numerics.md).
``--merge DIR1,DIR2`` joins partial runs (e.g. two processes with disjoint --cases) into one table.
"""
from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np

import mbd
from components.outputs import FAMILY
from components.presets import reference_dpgt
from components.units import Q_

from .common import (Problem, StateSampler, design_verdict, dpgt_problem, machine_note, run_scipy,
                     warm_up)
from ..core import args
from ..core.command import command

__all__ = ["CASES", "case_overrides", "run_case_stability", "main", "FIELDS"]


def _contact_stiffness(factor):
    def f():
        K = reference_dpgt(3).si().bearing.contact_stiffness
        return {"bearing.contact_stiffness": Q_(factor * K, "N/m**(10/9)")}
    return f


# name -> (description, overrides or a callable returning them, build options)
CASES = {
    "nominal": ("reference machine, condition 3", {}, {}),
    "contact_x10": ("roller–raceway contact stiffness ×10", _contact_stiffness(10.0), {}),
    "contact_x100": ("roller–raceway contact stiffness ×100", _contact_stiffness(100.0), {}),
    "traction_slope_x100": ("traction slope ×100 (v0 = 3 mm/s)", {"bearing.traction_v0": "3 mm/s"}, {}),
    "speed_x2": ("carrier speed 2× (8400 r/min)", {"operating.carrier_speed": "8400 rpm"}, {}),
    "speed_x3": ("carrier speed 3× (12600 r/min)", {"operating.carrier_speed": "12600 rpm"}, {}),
    "clearance_0": ("zero diametral clearance", {"bearing.clearance": "0 um"}, {}),
    "clearance_x10": ("diametral clearance ×10 (200 µm)", {"bearing.clearance": "200 um"}, {}),
    "load_0": ("zero load (P = 0)", {"operating.output_power": "0 kW"}, {}),
    "load_x2": ("2× rated load (P = 400 kW)", {"operating.output_power": "400 kW"}, {}),
    "cage_mass_div10": ("cage mass ÷10 (4 g)", {"bearing.cage.mass": "0.004 kg"}, {}),
    **{f"N{n}": (f"N = {n} planet pairs", {"gears.planets": n}, {}) for n in (1, 2, 4, 5, 6)},
    # Z = 15 is the largest roller count the design check accepts for the reference bearing (Z = 16
    # leaves no cage bar between the pockets, Z ≥ 20 rollers overlap on the pitch circle)
    **{f"Z{z}": (f"Z = {z} rollers", {"bearing.rollers": z}, {}) for z in (8, 10, 14, 15, 16, 20, 24)},
    "torque_step": ("sudden torque step: full sun torque at t = 0, no ramp", {"rig.load_ramp_mesh_periods": 0.0}, {}),
}
QUICK = ["nominal", "contact_x100", "traction_slope_x100", "speed_x3", "clearance_0", "cage_mass_div10", "N1",
         "Z24", "torque_step"]

FIELDS = ["case", "description", "integrator", "completed", "t_reached_s", "steps", "newton_per_step", "rejected",
          "factorizations", "jacobian_evals", "wall_s", "rms_pin_load_N", "max_inner_load_N", "pin_load_end_N",
          "radau_vs_hht_pin_end", "fraction_of_window", "message"]


def case_overrides(name: str) -> tuple[dict, dict]:
    _, ov, rig = CASES[name]
    return (ov() if callable(ov) else dict(ov)), dict(rig)


def _build(name: str, strict: bool = True) -> Problem:
    ov, _ = case_overrides(name)
    return dpgt_problem(overrides=ov, strict=strict)


def _pin_and_roller(prob: Problem, system, t, q, v, z):
    o = system.outputs(t, q, v, z)[FAMILY["race_inner"]]
    sl = prob.race_inner
    return float(np.hypot(o["fx"][sl].sum(), o["fy"][sl].sum())), float(o["load"][sl].max())


# cases whose machine cannot exist but whose equations are still worth integrating (labelled
# non-physical): N ≥ 4 planet pairs overlap on the reference gears (the design check only *warns*
# that they "would collide"; no planet–planet contact is modelled). Z ≥ 16 is not run: the check
# refuses it (no cage bar between the pockets at 16, rollers overlapping from 20 on), a bearing that
# cannot be made; the nearest feasible variant, Z = 15, is in the table.
RUN_NONPHYSICAL = {"N4", "N5", "N6"}


def run_case_stability(name: str, window: float, cap: float, radau: bool = True, hht: bool = True,
                       scipy_runs=(("Radau", 1e-5),)) -> list[dict]:
    """Rows for one case: design-check verdicts, HHT (unless ``hht=False``), then each scipy
    (method, rtol) of ``scipy_runs`` (unless ``radau=False``), each capped at ``cap`` s wall."""
    desc = CASES[name][0]
    base = {"case": name, "description": desc}
    pre = []
    ov, _ = case_overrides(name)
    verdict = design_verdict(ov)
    if verdict["collides"] or verdict["assembly"]:
        bad = [m for m in verdict["messages"] if "collide" in m or "do not assemble" in m]
        pre.append({**base, "integrator": "design check", "completed": "warning", "message": " | ".join(bad)})
        if verdict["collides"]:
            base = {"case": name, "description": desc + " — NON-PHYSICAL (gears collide; run anyway)"}
    try:
        prob = _build(name)
    except Exception as exc:     # design checks and parameter validation: report, do not hide
        refusal = {**base, "integrator": "build", "completed": False,
                   "message": f"{type(exc).__name__}: {' '.join(str(exc).split())}"}
        if name not in RUN_NONPHYSICAL:
            return pre + [refusal]
        pre.append(refusal)
        base = {"case": name, "description": desc + " — NON-PHYSICAL (design check refused; built with strict=False)"}
        prob = _build(name, strict=False)
    model = prob.model
    system = mbd.System(model)
    stepper = mbd.PRODUCTION.stepper()
    s0 = stepper.initial_state(system, 0.0, prob.built.q0, prob.built.v0)
    rows, row = [], {}
    if hht:
        row = _hht_row(prob, system, stepper, s0, base, window)
        rows = pre + [row]
    for method, tol in (scipy_runs if radau else ()):
        r = run_scipy(prob, s0, window, [window], method=method, tol=tol, max_wall_s=cap)
        rr = {**base, "integrator": f"{method} rtol={tol:g}".replace("e-0", "e-"), "completed": r.completed, "t_reached_s": r.t_reached,
              "steps": r.steps, "factorizations": r.factor, "jacobian_evals": r.jacobian,
              "wall_s": round(r.wall_s, 3), "message": " ".join(r.message.split()) if not r.completed else "",
              "fraction_of_window": round(float(r.t_reached) / window, 3) if np.isfinite(r.t_reached) else ""}
        if r.completed and r.q is not None:
            pin = _pin_and_roller(prob, system, window, r.q[-1], r.v[-1], r.z[-1])[0]
            rr["pin_load_end_N"] = round(pin, 2)
            if row.get("pin_load_end_N"):
                rr["radau_vs_hht_pin_end"] = round(abs(pin - row["pin_load_end_N"]) / max(row["pin_load_end_N"], 1e-9), 4)
        rows.append(rr)
    return rows


def _hht_row(prob, system, stepper, s0, base, window) -> dict:
    """HHT α = −0.3 adaptive from the kinematic start; sanity numbers over the last third."""
    grid = np.arange(2.0 * window / 3.0, window + 1e-12, 2e-5)
    smp = StateSampler(grid)
    row = {**base, "integrator": f"HHT α={mbd.PRODUCTION.alpha:g} adaptive"}
    warm_up(prob, s0)                 # kernels loaded before the clock starts (once per process matters)
    w0 = time.perf_counter()
    try:
        res = mbd.simulate(prob.model, t_end=window, state=s0, stepper=stepper, observers=[smp], system=system,
                           controller=mbd.PRODUCTION.controller(), progress=False)
        row.update(completed=True, t_reached_s=res.state.t, message="", fraction_of_window=1.0)
        end, c = res.state, res.counters
    except mbd.IntegrationError as exc:
        t_fail = exc.state.t if exc.state is not None else np.nan
        row.update(completed=False, t_reached_s=t_fail, message=" ".join(str(exc).split()),
                   fraction_of_window=round(float(t_fail) / window, 3) if np.isfinite(t_fail) else "")
        end, c = None, exc.counters      # the loop's totals up to the failure
    row.update(wall_s=round(time.perf_counter() - w0, 3), steps=c["accepted"], rejected=c["rejected"],
               newton_per_step=round(c["newton"] / max(c["accepted"], 1), 2), factorizations=c["factor"],
               jacobian_evals=c["jacobian"])
    if end is not None and smp.complete:
        pl = [_pin_and_roller(prob, system, t, q, v, z) for t, q, v, z in zip(grid, smp.q, smp.v, smp.z)]
        pins, rollers = np.array(pl).T
        row.update(rms_pin_load_N=round(float(np.sqrt(np.mean(pins ** 2))), 2),
                   max_inner_load_N=round(float(rollers.max()), 2),
                   pin_load_end_N=round(_pin_and_roller(prob, system, end.t, end.q, end.v, end.z)[0], 2))
    return row


def markdown(rows: list[dict], window: float, cap: float) -> str:
    lines = [f"Window 0 → {window * 1e3:g} ms from the kinematic start (through the load ramp); scipy runs capped at "
             f"{cap:g} s wall (every scipy run).", "",
             "| case | integrator | done | reached | steps | Newton/step | rejected | LU | wall s | RMS pin load N | max roller load N | scipy vs HHT (pin, end) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        # a capped scipy run has no solution object: its step and LU counts are unknown, not -1 / 0
        unknown = r.get("integrator", "").split()[0] in ("Radau", "RK45", "BDF", "LSODA", "DOP853") and not r.get("completed")
        g = lambda k: "–" if unknown and k in ("steps", "factorizations") else ("" if r.get(k) in (None, "") else r[k])
        done = "warned" if r.get("completed") == "warning" else ("yes" if r.get("completed") else "**no**")
        frac = r.get("fraction_of_window")
        reach = f"{float(frac):.0%}" if frac not in (None, "") else ""
        name = r["case"] + (" (non-physical)" if "NON-PHYSICAL" in r.get("description", "") else "")
        lines.append(f"| {name} | {r['integrator']} | {done} | {reach} | {g('steps')} | {g('newton_per_step')} | "
                     f"{g('rejected')} | {g('factorizations')} | {g('wall_s')} | {g('rms_pin_load_N')} | "
                     f"{g('max_inner_load_N')} | {g('radau_vs_hht_pin_end')} |")
    warned = [r for r in rows if r.get("completed") == "warning"]
    if warned:
        lines += ["", "Design-check warnings (the check warns, it does not refuse):"]
        lines += [f"- **{r['case']}**: {r['message']}" for r in warned]
    fails = [r for r in rows if not r.get("completed")]
    if fails:
        lines += ["", "Failures and their causes:"]
        lines += [f"- **{r['case']}** ({r['description']}), {r['integrator']}: {r['message']}" for r in fails]
    return "\n".join(lines) + "\n"


def _scipy_runs(text: str) -> list[tuple[str, float]]:
    """METHOD:RTOL,... -> [(method, rtol)] (a usage error names the bad item)."""
    runs = []
    for item in (x.strip() for x in text.split(",") if x.strip()):
        method, _, tol = item.partition(":")
        try:
            runs.append((method, args.positive("")(tol)))
        except argparse.ArgumentTypeError:
            raise argparse.ArgumentTypeError(f"expects METHOD:RTOL with RTOL > 0, e.g. Radau:1e-5, got {item!r}") from None
    return runs


@command
def main(argv=None) -> int:
    ap = args.parser("stability", __doc__, examples=["{prog} --quick --out results/numerics", "{prog} --cases nominal,contact_x10,N4 --no-radau"],
                      writes="stability.csv, stability.json, stability.md (the table for docs/numerics.md)", out="results/numerics")
    ap.add_argument("--quick", action="store_true", help="fewer cases, 1.5 ms window")
    args.add_shared(ap, "out", out="results/numerics")
    ap.add_argument("--window", type=args.positive("s"), default=None, help="simulated time per case [s]")
    ap.add_argument("--cap", type=args.positive("s"), default=None, help="wall-time cap of each Radau run [s]")
    ap.add_argument("--cases", default=None, type=args.choice_list(tuple(CASES), "cases"), help=f"comma-separated subset of: {', '.join(CASES)}")
    ap.add_argument("--no-radau", action="store_true", help="skip the scipy comparison")
    ap.add_argument("--scipy", default="Radau:1e-5", type=_scipy_runs, help="scipy runs per case, METHOD:RTOL,... (default Radau:1e-5)")
    ap.add_argument("--no-hht", action="store_true", help="scipy rows only (to --merge into an existing table)")
    ap.add_argument("--merge", default=None,
                    help="comma-separated directories of partial runs (same window and cap, e.g. run in parallel "
                         "with disjoint --cases): write their rows, in CASES order, as one table into --out")
    a = ap.parse_args(argv)
    if a.merge:
        parts = [json.loads((Path(d) / "stability.json").read_text()) for d in a.merge.split(",")]
        if len({(p["window_s"], p["radau_cap_s"]) for p in parts}) != 1:
            ap.error("--merge: the partial runs differ in window or Radau cap")
        order = {c: i for i, c in enumerate(CASES)}
        rows = sorted((r for p in parts for r in p["rows"]), key=lambda r: order[r["case"]])
        _write_outputs(Path(a.out), rows, parts[0]["window_s"], parts[0]["radau_cap_s"],
                       "; ".join(p["machine"] for p in parts))
        return 0
    window = a.window if a.window is not None else (1.5e-3 if a.quick else 5e-3)
    cap = a.cap if a.cap is not None else (10.0 if a.quick else 30.0)
    names = [c.strip() for c in a.cases.split(",")] if a.cases else (QUICK if a.quick else list(CASES))
    bad = set(names) - set(CASES)
    if bad:
        ap.error(f"unknown case(s) {sorted(bad)}")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    print(machine_note(), flush=True)
    rows = []
    for n in names:
        runs = a.scipy
        rs = run_case_stability(n, window, cap, radau=not a.no_radau, hht=not a.no_hht, scipy_runs=runs)
        for r in rs:
            print(f"{r['case']:20s} {r['integrator']:20s} {'ok ' if r.get('completed') else 'FAIL'} "
                  f"steps {r.get('steps', '')!s:>6} wall {r.get('wall_s', '')!s:>7} {r.get('message', '')[:150]}", flush=True)
        rows += rs
    _write_outputs(out, rows, window, cap, machine_note())
    return 0


def _write_outputs(out: Path, rows: list, window: float, cap: float, machine: str) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "stability.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in FIELDS})
    (out / "stability.json").write_text(json.dumps({"machine": machine, "window_s": window, "radau_cap_s": cap,
                                                     "rows": rows}, indent=2, default=str))
    (out / "stability.md").write_text(markdown(rows, window, cap))
    print(f"wrote {out}/stability.csv, stability.json, stability.md")


if __name__ == "__main__":
    sys.exit(main())
