"""Which oil for which direction? The source study's open question, answered with the dynamic model.

    python -m scenarios.lubricant_study [--conditions 3] [--directions forward,reverse]
        [--grades VG32,VG68,VG150 | --viscosities "10,30,100 mPa*s"] [--settle S] [--window S]
        [--set KEY=VALUE ...] [--params FILE] [--workers N | --scheduler ADDR] [--out DIR]

Every condition × direction × lubricant runs through the one runner (resumable, on Dask like the paper
study) with the EHL traction law (``bearing.traction_law = "ehl"``: the oil's viscosity then drives the
roller–raceway traction as well as the film; ``--set bearing.traction_law=tanh`` keeps the dry law).
A grade sets the oil's viscosity at 40 and 100 °C (ISO VG, viscosity at the operating temperature by
Walther); a viscosity sets the dynamic viscosity at the operating temperature directly.

Writes ``summary.csv`` / ``summary.md`` (one row per run and bearing type: film, Λ, traction, loads, cage
guide, cage slip, pocket impacts, heat), ``film_and_slip.png`` and the answer in words (``answer.md``,
printed): per direction the oils that keep the thinnest film at Λ ≥ 1.5 (the customary bound of full film
separation: below it asperities carry load) with the cage at most 5 % below its epicyclic speed (beyond
that the cage skids: the rollers slide instead of rolling), and the least viscosity for a full film in
each direction (from the film's η^0.694 scaling) — so whether reverse wants a stronger oil, and by how much.
"""
from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import sys
import warnings
from pathlib import Path

import mbd
from components.presets import OIL_GRADES, oil_grade
from components.units import ParameterError, quantity, to_si
from mbd.recorder import atomic_write_text

from .paper_study import parse_sets
from .runner import RunConfig
from .plausibility import check_runs
from .sweep import Case, _case_cfg, build_params, check_folders, run_sweep, study_epilogue
from . import args
from .command import command
from .lock import holds_out_folder

__all__ = ["main", "run", "LAMBDA_MIN", "SKID_PCT", "COLUMNS"]

LAMBDA_MIN = 1.5      # full film: the thinnest film at least 1.5 composite roughnesses
SKID_PCT = 5.0        # cage slip beyond this: skidding
COLUMNS = ["condition", "direction", "lubricant", "viscosity_Pa_s", "bearing", "h_min_m", "h_mean_m", "lambda_min",
           "lambda_mean", "traction_coefficient_max", "roller_inner_race_rms_N", "roller_inner_race_max_N",
           "roller_outer_race_rms_N", "roller_outer_race_max_N", "cage_guide_rms_N", "cage_slip_pct",
           "pocket_impacts_per_rev", "heat_traction_W", "heat_land_W"]
_FROM_SUMMARY = {"h_min_m": "film_min_m", "h_mean_m": "film_mean_m"}


def parse_args(argv):
    p = args.Parser(prog="python -m scenarios.lubricant_study", description=__doc__.split("\n\n")[0])
    p.add_argument("--conditions", default="3", type=args.conditions, help="comma list of operating conditions 1-4 (default 3)")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--grades", default=None, type=args.choice_list(tuple(OIL_GRADES), "ISO VG grades"), help=f"comma list of ISO VG grades ({', '.join(OIL_GRADES)})")
    g.add_argument("--viscosities", default=None,
                   help='dynamic viscosities at the operating temperature, e.g. "10,30,100 mPa*s"')
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None, help="statistics window [s] (default: the study's rule)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=2000.0, help="recording rate [Hz] (statistics use every step)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", type=args.key_value, help="override a parameter (repeatable)")
    p.add_argument("--params", default=None, type=args.existing_file, help="TOML file of parameter overrides")
    args.add_sweep_options(p, "results/lubricant")
    return p.parse_args(argv)


def lubricants(a) -> dict[str, dict]:
    """label -> parameter overrides of each oil of the study."""
    if a.viscosities:
        text = a.viscosities.strip()
        nums, _, unit = text.partition(" ")
        out = {}
        for x in nums.split(","):
            q = f"{x.strip()} {unit.strip() or 'Pa*s'}"
            eta = to_si(quantity("--viscosities", q, "dynamic_viscosity"))
            if not eta > 0:
                raise ParameterError.at("--viscosities", f"expected positive viscosities, got {q!r}")
            out[q.replace(" ", "").replace("*", "")] = {"lubricant.oil_viscosity": q}   # a file-name-safe label
        return out
    grades = [s.strip() for s in (a.grades or ",".join(OIL_GRADES)).split(",") if s.strip()]
    return {g: {k: v.value for k, v in oil_grade(g).items()} for g in grades}


def make_cases(a, out: Path) -> list[Case]:
    conds = [int(c) for c in str(a.conditions).split(",") if c.strip()]
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    if not conds or not dirs or any(c not in (1, 2, 3, 4) for c in conds) \
            or any(d not in ("forward", "reverse") for d in dirs):
        raise ParameterError.at("--conditions/--directions", f"expected conditions 1-4 and forward/reverse, got "
                                                              f"{a.conditions!r}, {a.directions!r}")
    user = {"bearing.traction_law": "ehl", **parse_sets(a.set)}
    return [Case(c, d, str(out / f"c{c}_{d}_{lab}"), {**user, **ov}, a.params, tag=lab)
            for lab, ov in lubricants(a).items() for c in conds for d in dirs]


def rows_of(cases: list[Case], results: dict) -> list[dict]:
    rows = []
    for case in cases:
        s = results.get(case.label, {})
        if "error" in s or not s:
            continue
        eta = build_params(case).si().lubricant.oil_viscosity
        for kind in ("inner", "outer"):
            d = s[kind]
            row = {"condition": case.condition, "direction": case.direction, "lubricant": case.tag,
                   "viscosity_Pa_s": eta, "bearing": kind}
            for col in COLUMNS[5:]:
                v = d.get(_FROM_SUMMARY.get(col, col))
                row[col] = v if v is not None else d.get("all_rollers", {}).get(col)
            rows.append(row)
    return rows


def answer(rows: list[dict]) -> str:
    """The source's question in plain words: per condition and direction, the oils that keep Λ ≥ 1.5 in both
    bearing types with neither cage skidding."""
    lines = [f"Which oil? Full film: the thinnest film over every loaded roller contact at Λ ≥ {LAMBDA_MIN:g}; "
             f"no skid: cage slip ≤ {SKID_PCT:g} %. Per oil: Λ_min inner/outer, cage slip inner/outer.", ""]
    ok_by, need = {}, {}
    for (c, d) in sorted({(r["condition"], r["direction"]) for r in rows}):
        lines.append(f"condition {c}, {d}:")
        good = []
        for lab in sorted({r["lubricant"] for r in rows}, key=lambda x: _eta(rows, x)):
            rr = {r["bearing"]: r for r in rows if (r["condition"], r["direction"], r["lubricant"]) == (c, d, lab)}
            if set(rr) != {"inner", "outer"}:
                continue
            lam = min(rr[k]["lambda_min"] for k in rr)
            slip = max(abs(rr[k]["cage_slip_pct"]) for k in rr)
            fine = lam >= LAMBDA_MIN and slip <= SKID_PCT
            good += [lab] if fine else []
            lines.append(f"  {lab:>12} ({1e3 * _eta(rows, lab):.3g} mPa·s): Λ_min {rr['inner']['lambda_min']:.2f} / "
                         f"{rr['outer']['lambda_min']:.2f}, slip {rr['inner']['cage_slip_pct']:.2f} / "
                         f"{rr['outer']['cage_slip_pct']:.2f} % -> {'suits' if fine else 'does not suit'}")
        ok_by[(c, d)] = good
        need[(c, d)] = _needed_viscosity([r for r in rows if (r["condition"], r["direction"]) == (c, d)])
        lines.append(f"  suits: {', '.join(good) if good else 'none of the oils studied'}; full film from "
                     f"{1e3 * need[(c, d)]:.3g} mPa·s")
    for c in sorted({k[0] for k in ok_by}):
        f, r = ok_by.get((c, "forward")), ok_by.get((c, "reverse"))
        if f is not None and r is not None:
            same = "the same oils suit both directions" if f == r else \
                f"forward and reverse want different oils (forward: {', '.join(f) or 'none'}; reverse: " \
                f"{', '.join(r) or 'none'})"
            ratio = need[(c, "reverse")] / need[(c, "forward")]
            lines.append(f"condition {c}: {same}; for a full film reverse needs {100 * (ratio - 1):+.1f} % "
                         f"viscosity against forward ({1e3 * need[(c, 'forward')]:.3g} vs "
                         f"{1e3 * need[(c, 'reverse')]:.3g} mPa·s).")
    return "\n".join(lines)


def _needed_viscosity(rows: list[dict]) -> float:
    """The least viscosity for Λ_min = LAMBDA_MIN in both bearing types, from the oil whose Λ is nearest
    the bound: the film scales as η^0.694 at fixed load and speed (Pan & Hamrock), so
    η_needed = η (LAMBDA_MIN / Λ)^(1/0.694)."""
    best = min(rows, key=lambda r: abs(math.log(r["lambda_min"] / LAMBDA_MIN)))
    same = [r for r in rows if r["lubricant"] == best["lubricant"]]
    worst = min(r["lambda_min"] for r in same)
    return best["viscosity_Pa_s"] * (LAMBDA_MIN / worst) ** (1.0 / 0.694)


def _eta(rows, lab) -> float:
    return next(r["viscosity_Pa_s"] for r in rows if r["lubricant"] == lab)


def write_outputs(rows: list[dict], out: Path) -> list[Path]:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS)
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "summary.csv", buf.getvalue())
    md = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    md += ["| " + " | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in COLUMNS) + " |"
           for r in rows]
    atomic_write_text(out / "summary.md", "\n".join(md) + "\n")
    text = answer(rows)
    atomic_write_text(out / "answer.md", text + "\n")
    from viz.plots import against_viscosity

    series = {}
    for key in ("h_min_m", "cage_slip_pct", "heat_traction_W"):
        for r in sorted(rows, key=lambda r: r["viscosity_Pa_s"]):
            x, y = series.setdefault((key, r["bearing"], r["direction"]), ([], []))
            x.append(r["viscosity_Pa_s"])
            y.append(r[key])
    fig = against_viscosity(series, [("h_min_m", "thinnest film h_min", "m", True),
                                     ("cage_slip_pct", "cage slip", "%", False),
                                     ("heat_traction_W", "traction heat", "W", False)],
                            out / "film_and_slip.png", title="Film and cage against the oil's viscosity")
    return [out / "summary.csv", out / "summary.md", out / "answer.md", fig]


@holds_out_folder
def run(a) -> dict:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    cases = make_cases(a, out)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # design warnings of the reference machine are known
        for c in cases:
            build_params(c).si()             # every parameter checked before any run starts
    cfg = RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate, integration=mbd.PRODUCTION,
                    progress=not a.no_progress)
    for w in check_runs([(c.label, build_params(c), _case_cfg(c, cfg)) for c in cases], out, a.force):
        print(f"warning (--force): {w}")
    check_folders(cases, cfg, a.overwrite)      # never replace results of other parameters silently
    results = run_sweep(cases, cfg, workers=a.workers, scheduler=a.scheduler, progress=not a.no_progress,
                        overwrite=a.overwrite)
    rows = rows_of(cases, results)
    files = write_outputs(rows, out) if rows else []
    failed = {k: v["error"] for k, v in results.items() if "error" in v}
    atomic_write_text(out / "study.json", json.dumps({"cases": [dataclasses.asdict(c) for c in cases],
                                                      "failed": failed}, indent=2, default=str))
    return {"rows": rows, "failed": failed, "files": files, "answer": answer(rows) if rows else "", "results": results}


@command
def main(argv=None) -> int:
    r = run(parse_args(sys.argv[1:] if argv is None else argv))
    print(r["answer"])
    return study_epilogue(r)


if __name__ == "__main__":
    raise SystemExit(main())
