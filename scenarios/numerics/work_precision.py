"""Work-precision study: error against wall time for every integrator on two problems.

    python -m scenarios.work_precision [--problems rig,dpgt] [--quick] [--out DIR] [--repeats R]
                                       [--figures DIR] [--cap S] [--window S] [--floor-check]

Problems: ``rig`` — one planet bearing on the rig (stiff Hertz contacts, traction, cage impacts, the
outer ring turning at the inner planet's relative speed of condition 3, 5 kN radial load); ``dpgt`` —
the full DPGT at condition 3 forward, N = 3, Z = 12. Each problem is settled once with a robust
setting (HHT α = −0.3, adaptive, atol 10 nm, h ≤ 5 µs; state cached in OUT/<problem>_settled.npz),
then a short window is integrated from that state by every contender.

Reference: HHT α = −0.1, fixed h_ref (0.25 µs; --quick 0.5 µs) with a 100× tighter Newton tolerance
(atol 0.1 nm); a check run at 2·h_ref shows it is converged (their difference is reported and must be
far below the smallest error plotted).

Contenders: HHT fixed step (h × α ∈ {0, −0.1, −0.3}), HHT adaptive (atol), solve_ivp Radau / BDF /
LSODA with the sparse analytic Jacobian, explicit RK45 / DOP853; every scipy run has a wall-time cap
(--cap) and a run that hits it is reported as not finished (tighter settings of that method are then
skipped, marked so in the CSV).

Errors on a common grid (Hermite interpolation between HHT steps, dense output for scipy):
(a) max-norm error of the reference bearing's pin-reaction magnitude over the window (absolute [N] and
relative to its maximum); (b) relative errors of the RMS of the reference roller's inner-race load, of
the cage–guide force and of the cage acceleration (relative to its planet).

Outputs in OUT: work_precision_<problem>.csv, work_precision_<problem>.png (error (a) against wall time)
and work_precision_<problem>_rms.png (error (b), inner race), work_precision.json (reference check,
fitted HHT orders, evaluation costs, the reference's pin-load range, and with --floor-check the HHT
α = 0 errors at the three smallest h for Newton tolerances 0.03, 1e-3 and 1e-5) and work_precision.md
(tables for docs/numerics.md).
"""
from __future__ import annotations

import csv
import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np

import mbd
from components.outputs import FAMILY

from .common import (dpgt_problem, error_metrics, eval_costs, machine_note, observables, peak_rss_mb,
                     rig_problem, run_hht, run_scipy, settled_state, warm_up, hht_reference)
from ..core import args
from ..core.command import command

__all__ = ["main", "study", "FIELDS"]

FIELDS = ["problem", "method", "setting", "alpha", "h_s", "tol", "completed", "wall_s", "steps",
          "residual_evals", "jacobian_evals", "factorizations", "newton_iterations", "rejected",
          "err_pin_max_N", "err_pin_rel", "err_rms_inner", "err_rms_guide", "err_rms_cage_acc", "message"]


def plan(quick: bool) -> dict:
    if quick:
        return {"window": 5e-4, "dt": 1e-5, "h_ref": 5e-7, "fixed_h": [2e-6, 5e-6, 1e-5], "alphas": [0.0, -0.3],
                "adaptive_atol": [1e-7, 1e-8], "implicit_tol": [1e-3, 1e-5], "explicit_tol": [1e-3], "cap": 15.0}
    return {"window": 2e-3, "dt": 5e-6, "h_ref": 2.5e-7, "fixed_h": [1e-6, 2e-6, 5e-6, 1e-5, 2e-5],
            "alphas": [0.0, -0.1, -0.3], "adaptive_atol": [1e-7, 1e-8, 1e-9, 1e-10],
            "implicit_tol": [1e-3, 1e-5, 1e-7], "explicit_tol": [1e-3, 1e-6], "cap": 60.0}


def _row(problem, r, metrics, alpha=None, h=None, tol=None) -> dict:
    c = r.costs()
    row = {"problem": problem, "method": r.method, "setting": r.setting, "alpha": alpha, "h_s": h, "tol": tol,
           "completed": r.completed, "wall_s": round(r.wall_s, 4), "steps": c["steps"],
           "residual_evals": c["residual_evals"], "jacobian_evals": c["jacobian_evals"],
           "factorizations": c["factorizations"], "newton_iterations": c["newton_iterations"],
           "rejected": c["rejected"], "message": r.message.replace("\n", " ")}
    for k in ("err_pin_max_N", "err_pin_rel", "err_rms_inner", "err_rms_guide", "err_rms_cage_acc"):
        row[k] = metrics.get(k, "") if metrics else ""
    return row


def _log(msg):
    print(msg, flush=True)


def study(problem: str, out: Path, quick: bool, repeats: int, cap: float | None, window: float | None,
          floor_check: bool = False) -> dict:
    P = plan(quick)
    if cap is not None:
        P["cap"] = cap
    if window is not None:
        P["window"] = window
    prob = dpgt_problem() if problem == "dpgt" else rig_problem()
    w0 = time.perf_counter()
    s0, extra = settled_state(prob, out / f"{problem}_settled.npz")
    _log(f"[{problem}] settled to t = {s0.t:.4f} s ({extra.get('settle_steps', '?')} steps, "
         f"{time.perf_counter() - w0:.1f} s here; cached)")
    # reference roller: the most loaded roller of the reference bearing at the start of the window (a
    # roller outside the load zone for the whole short window would have RMS 0 and no relative error)
    ri = mbd.System(prob.model).outputs(s0.t, s0.q, s0.v, s0.z)[FAMILY["race_inner"]]["load"][prob.race_inner]
    prob.roller = prob.race_inner.start + int(np.argmax(ri))
    warm_up(prob, s0)
    t0, t1 = s0.t, s0.t + P["window"]
    grid = t0 + P["dt"] * np.arange(int(round(P["window"] / P["dt"])) + 1)
    grid[-1] = min(grid[-1], t1)

    def obs_of(r):
        return observables(prob, grid, r.q, r.v, r.z)

    # reference and its convergence check
    def ref_run(h):
        return hht_reference(prob, s0, t1, grid, h)

    ref = ref_run(P["h_ref"])
    chk = ref_run(2 * P["h_ref"])
    if not (ref.completed and chk.completed):
        raise RuntimeError(f"reference run failed: {ref.message or chk.message}")
    ref_obs, chk_obs = obs_of(ref), obs_of(chk)
    # scipy's first-order form holds element internal states (the carrier drive's PI integral) at their
    # initial value; its errors are measured against a reference with the same frozen state, and the
    # difference of the two references (the model difference, not an integration error) is reported
    frozen = obs_of(hht_reference(prob, s0, t1, grid, P["h_ref"], frozen_z=True)) if s0.z else ref_obs
    frozen_diff = error_metrics(frozen, ref_obs)
    ref_check = error_metrics(chk_obs, ref_obs)
    _log(f"[{problem}] reference h={P['h_ref']:.2e} s ({ref.wall_s:.1f} s); check at 2h: pin max error "
         f"{ref_check['err_pin_max_N']:.3e} N ({ref_check['err_pin_rel']:.2e} rel), RMS inner "
         f"{ref_check['err_rms_inner']:.2e}, guide {ref_check['err_rms_guide']:.2e}, cage acc {ref_check['err_rms_cage_acc']:.2e}")

    rows = []

    def add(r, **kw):
        base = ref_obs if r.method.startswith("HHT") else frozen
        m = error_metrics(obs_of(r), base) if r.completed and r.q is not None else None
        rows.append(_row(problem, r, m, **kw))
        e = f"pin {m['err_pin_rel']:.2e}, rms_in {m['err_rms_inner']:.2e}" if m else r.message
        _log(f"[{problem}] {r.method:6s} {r.setting:22s} wall {r.wall_s:7.2f} s steps {r.steps:6d}  {e}")

    for alpha in P["alphas"]:
        for h in P["fixed_h"]:
            add(run_hht(prob, s0, t1, grid, alpha=alpha, h=h, repeats=repeats, label=f"fixed h={h:.0e} a={alpha:g}"),
                alpha=alpha, h=h)
    for atol in P["adaptive_atol"]:
        r = run_hht(prob, s0, t1, grid, alpha=-0.3, atol_pos=atol, repeats=repeats, label=f"adaptive atol={atol:.0e}")
        r.method = "HHT-adaptive"
        add(r, alpha=-0.3, tol=atol)
    for method, tols in (("Radau", P["implicit_tol"]), ("BDF", P["implicit_tol"]), ("LSODA", P["implicit_tol"]),
                         ("RK45", P["explicit_tol"]), ("DOP853", P["explicit_tol"])):
        capped = False
        for tol in tols:
            if capped:
                rows.append({**{k: "" for k in FIELDS}, "problem": problem, "method": method, "setting": f"rtol={tol:g}",
                             "tol": tol, "completed": False,
                             "message": "skipped: a looser setting of this method already hit the wall-time cap"})
                continue
            r = run_scipy(prob, s0, t1, grid, method=method, tol=tol, max_wall_s=P["cap"], repeats=repeats)
            add(r, tol=tol)
            capped = not r.completed
    orders = _hht_orders(rows, P["alphas"], ref_check)
    floor = _floor_check(problem, prob, s0, t1, grid, P["fixed_h"][:3], ref_obs, obs_of) if floor_check else []
    pin = ref_obs["pin_load"]
    ripple = {"max_N": float(pin.max()), "min_N": float(pin.min()), "pk_pk_N": float(pin.max() - pin.min()),
              "pk_pk_rel": float((pin.max() - pin.min()) / pin.max())}
    costs = eval_costs(prob.model, s0)
    _write(out, problem, rows)
    _plots(out, problem, rows, ref_check)
    return {"problem": problem, "ndof": int(prob.model.ndof), "window_s": [t0, t1], "grid_dt_s": P["dt"],
            "reference": {"h_s": P["h_ref"], "alpha": -0.1, "atol_pos_m": 1e-10, "wall_s": ref.wall_s,
                          "steps": ref.steps, "check_h_s": 2 * P["h_ref"], "check_vs_reference": ref_check,
                          "frozen_internal_state_vs_reference": frozen_diff},
            "reference_roller": prob.roller - prob.race_inner.start, "hht_order": orders, "eval_costs_s": costs, "cap_s": P["cap"], "repeats": repeats,
            "settle": extra, "floor_check": floor, "pin_load_reference": ripple, "rows": rows}


def _hht_orders(rows, alphas, ref_check) -> dict:
    """HHT order on this problem: slope of log(error) against log(h) per α (errors well above the reference's)."""
    orders = {}
    for alpha in alphas:
        pts = [(r["h_s"], r["err_pin_max_N"]) for r in rows
               if r["method"] == "HHT" and r["alpha"] == alpha and r["completed"] and r["err_pin_max_N"] != ""
               and r["err_pin_max_N"] > 10 * ref_check["err_pin_max_N"]]
        if len(pts) >= 2:
            h_, e_ = np.log(np.array(pts, float)).T
            orders[str(alpha)] = {"order": float(np.polyfit(h_, e_, 1)[0]), "points": len(pts),
                                  "h_range_s": [float(np.exp(h_.min())), float(np.exp(h_.max()))]}
    return orders


def _floor_check(problem, prob, s0, t1, grid, steps, ref_obs, obs_of) -> list:
    """What limits the error at small h: the same HHT runs with the old (0.03), the default and a 100x
    tighter (1e-5) Newton tolerance; the grid points are step points for every h that divides dt, so the
    sampling adds no interpolation error there."""
    floor = []
    for nt in (0.03, 1e-3, 1e-5):
        for h in steps:
            r = run_hht(prob, s0, t1, grid, alpha=0.0, h=h, newton_tol=nt, label=f"newton_tol={nt:g}")
            m = error_metrics(obs_of(r), ref_obs) if r.completed else {}
            floor.append({"newton_tol": nt, "h_s": h, "alpha": 0.0, "completed": r.completed,
                          "err_pin_rel": m.get("err_pin_rel"), "err_pin_max_N": m.get("err_pin_max_N"),
                          "err_rms_inner": m.get("err_rms_inner"), "newton_per_step": r.newton / max(r.steps, 1)})
            _log(f"[{problem}] floor check newton_tol={nt:g} h={h:.0e}: "
                 + (f"pin {m['err_pin_rel']:.2e} ({m['err_pin_max_N']:.3f} N)" if m else r.message))
    return floor


def _write(out: Path, problem: str, rows: list) -> None:
    with open(out / f"work_precision_{problem}.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in FIELDS})


def _label(r) -> str:
    if r["method"] == "HHT":
        return f"HHT fixed α={r['alpha']:g}"
    if r["method"] == "HHT-adaptive":
        return f"HHT adaptive α={r['alpha']:g}"
    return f"{r['method']} (scipy)"


def _plots(out: Path, problem: str, rows: list, ref_check: dict) -> None:
    from viz.plots import work_precision  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn
    title = {"dpgt": "full DPGT, condition 3", "rig": "one planet bearing on the rig"}[problem]
    ok = [r for r in rows if r["completed"] is True and r["err_pin_rel"] != ""]
    floor = 1e-12
    work_precision([(_label(r), r["wall_s"], max(r["err_pin_rel"], floor)) for r in ok],
                   out / f"work_precision_{problem}.png", error_label="max error of pin load / max pin load",
                   title=f"{title}: bearing load history")
    work_precision([(_label(r), r["wall_s"], max(r["err_rms_inner"], floor)) for r in ok],
                   out / f"work_precision_{problem}_rms.png", error_label="rel. error of RMS inner-race load",
                   title=f"{title}: RMS roller–inner-race load")


def _fmt(x, f="{:.2e}"):
    return f.format(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and x != "" else str(x or "–")


def markdown(res: dict) -> str:
    p = res["problem"]
    rc = res["reference"]["check_vs_reference"]
    lines = [f"### {p}: window {res['window_s'][0]:.4f}–{res['window_s'][1]:.4f} s, {res['ndof']} DOF",
             "",
             f"Reference: HHT α = −0.1, h = {res['reference']['h_s'] * 1e6:g} µs, atol 0.1 nm "
             f"({res['reference']['steps']} steps, {res['reference']['wall_s']:.1f} s). Check run at "
             f"h = {res['reference']['check_h_s'] * 1e6:g} µs differs from it by {rc['err_pin_max_N']:.2e} N "
             f"({rc['err_pin_rel']:.1e} of the max pin load) in the load history and by {rc['err_rms_inner']:.1e} "
             f"(RMS inner race), {rc['err_rms_guide']:.1e} (RMS guide), {rc['err_rms_cage_acc']:.1e} (RMS cage acc).",
             "",
             f"scipy solvers hold the carrier drive's PI integral at its initial value; they are scored against a "
             f"reference with the same frozen state, which differs from the HHT reference by "
             f"{res['reference']['frozen_internal_state_vs_reference']['err_pin_rel']:.1e} (pin-load history) and "
             f"{res['reference']['frozen_internal_state_vs_reference']['err_rms_inner']:.1e} (RMS inner race).",
             "",
             "| method | setting | done | wall s | steps | f-evals | J-evals | LU | pin-load err (rel) | RMS inner | RMS guide | RMS cage acc |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in res["rows"]:
        done = "yes" if r["completed"] is True else "**no**"
        lines.append(f"| {r['method']} | {r['setting']} | {done} | {_fmt(r['wall_s'], '{:.2f}')} | {r['steps']} | "
                     f"{r['residual_evals']} | {r['jacobian_evals']} | {r['factorizations']} | {_fmt(r['err_pin_rel'])} | "
                     f"{_fmt(r['err_rms_inner'])} | {_fmt(r['err_rms_guide'])} | {_fmt(r['err_rms_cage_acc'])} |")
    notes = [r for r in res["rows"] if r["completed"] is not True]
    if notes:
        lines += ["", "Runs that did not finish:"]
        lines += [f"- {r['method']} {r['setting']}: {r['message']}" for r in notes]
    if res["hht_order"]:
        lines += ["", "Observed order of HHT (slope of log error (a) against log h): "
                  + ", ".join(f"α = {a}: {o['order']:.2f} ({o['points']} points, h {o['h_range_s'][0] * 1e6:g}–"
                              f"{o['h_range_s'][1] * 1e6:g} µs)" for a, o in res["hht_order"].items())]
    rp = res.get("pin_load_reference")
    if rp:
        lines += ["", f"Reference pin load: {rp['min_N']:.1f}–{rp['max_N']:.1f} N over the window (peak-to-peak "
                  f"{rp['pk_pk_N']:.1f} N = {rp['pk_pk_rel']:.1e} of its maximum: errors (a) are relative to the maximum)."]
    if res.get("floor_check"):
        lines += ["", "Newton-tolerance check (HHT α = 0; pin-load history error, relative):", "",
                  "| newton_tol | " + " | ".join(f"h = {h * 1e6:g} µs" for h in sorted({f['h_s'] for f in res['floor_check']})) + " |",
                  "|---|" + "---:|" * len({f['h_s'] for f in res['floor_check']})]
        for nt in sorted({f["newton_tol"] for f in res["floor_check"]}, reverse=True):
            fs = sorted((f for f in res["floor_check"] if f["newton_tol"] == nt), key=lambda f: f["h_s"])
            lines.append(f"| {nt:g} | " + " | ".join(_fmt(f["err_pin_rel"]) + f" ({f['newton_per_step']:.2f} it/step)" for f in fs) + " |")
    c = res["eval_costs_s"]
    lines += ["", f"One residual evaluation {c['residual_s'] * 1e3:.2f} ms, residual + Jacobian {c['jacobian_s'] * 1e3:.2f} ms."]
    return "\n".join(lines) + "\n"


@command
def main(argv=None) -> int:
    ap = args.parser("work_precision", __doc__, examples=["{prog} --quick --out results/numerics", "{prog} --problems rig --repeats 3 --figures docs/numerics"],
                      writes="work_precision_<problem>.csv, work_precision_<problem>.png (error against wall time), work_precision_<problem>_rms.png, work_precision.json, work_precision.md and the settled states <problem>_settled.npz", out="results/numerics")
    ap.add_argument("--problems", default="rig,dpgt", type=args.choice_list(("rig", "dpgt"), "problems"), help="comma-separated: rig, dpgt")
    ap.add_argument("--quick", action="store_true", help="short window, fewer settings (minutes, not tens of minutes)")
    args.add_shared(ap, "out", out="results/numerics")
    ap.add_argument("--repeats", type=args.count(1), default=1, help="timing repeats per contender (median reported)")
    ap.add_argument("--cap", type=args.positive("s"), default=None, help="wall-time cap per scipy run [s]")
    ap.add_argument("--window", type=args.positive("s"), default=None, help="integration window after settling [s]")
    ap.add_argument("--floor-check", action="store_true",
                    help="also rerun HHT alpha=0 at the three smallest h with Newton tolerances 0.03, 1e-3, 1e-5")
    ap.add_argument("--figures", default=None, type=args.out_folder, help="also copy the PNGs into this directory (e.g. docs/numerics)")
    a = ap.parse_args(argv)
    probs = [p.strip() for p in a.problems.split(",") if p.strip()]
    bad = set(probs) - {"rig", "dpgt"}
    if bad:
        ap.error(f"unknown problem(s) {sorted(bad)}; choose from rig, dpgt")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    _log(machine_note())
    results = {}
    for p in probs:
        results[p] = study(p, out, a.quick, a.repeats, a.cap, a.window, floor_check=a.floor_check)
    summary = {"machine": machine_note(), "peak_rss_mb": peak_rss_mb(),
               "problems": {p: {k: v for k, v in r.items() if k != "rows"} for p, r in results.items()}}
    (out / "work_precision.json").write_text(json.dumps(summary, indent=2, default=str))
    (out / "work_precision.md").write_text("\n".join(markdown(r) for r in results.values()))
    if a.figures:
        fig = Path(a.figures)
        fig.mkdir(parents=True, exist_ok=True)
        for p in probs:
            for suffix in ("", "_rms"):
                shutil.copy(out / f"work_precision_{p}{suffix}.png", fig / f"work_precision_{p}{suffix}.png")
    _log(f"wrote {out}/work_precision_*.csv, *.png, work_precision.json, work_precision.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
