"""Misalignment of the planet bearings, bearing by bearing: the ISO/TS 16281 life with slices relative to the aligned
bearing, and the edge pressure, against the pin's slope for each roller profile.

    python -m scenarios.bearing_misalignment --conditions 1,3 --out results/bearing_misalignment

For each operating condition and direction the machine's quasi-static solution (components.static, what
`paper_study --mode static` runs) gives the mean load of pair 1's inner and outer planet bearings; each bearing is
then solved alone (components.sliced_bearing, docs/model.md §8.8) under that load with its pin sloped γ against its
bore, in the load plane (radial) and across it (tangential), its rollers sliced and profiled. What it assumes: the
bearing sees the whole slope γ (the planet's tilt is not yet a degree of freedom and the meshes do not resist it),
the bore's slope is held, the rollers' centrifugal loads, traction and skew are left out, the load is the planar
model's mean pin reaction.
Writes DIR/misalignment.csv (every γ), DIR/misalignment.md (the table printed) and DIR/loads.json (the bearing loads
used, with the static solution's condition and direction).
"""
from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import numpy as np

from components.dpgt import build_dpgt
from components.params import overrides_from_toml, with_overrides
from components.presets import reference_dpgt
from components.profiles import PROFILES
from components.results.io import atomic_write_text
from components.sliced_bearing import ARCMIN, MISALIGNMENT_DIRECTIONS, misalignment_sweep
from components.static import static_summary
from components.units import ParameterError, quantity, to_si

from .core import args
from .core.command import command

EXAMPLES = ["{prog} --conditions 1,3 --out results/bearing_misalignment",
            '{prog} --load "12 kN" --gammas 0,4,10 --profiles straight,logarithmic',
            "{prog} --conditions 3 --set bearing.profile.design_load=\"5 kN\" --set bearing.slicing.slices=61"]
WRITES = ("misalignment.csv (life, life relative to aligned, edge pressure ratio, peak pressure and loaded length at "
          "every slope), misalignment.md (the table printed) and loads.json (the bearing loads used)")
EDGE_AT = 4.0          # arcmin: the slope at which the table shows the edge pressure ratio


def _gammas(text: str) -> list[float]:
    try:
        g = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise SystemExit(f"error: --gammas takes a comma list of slopes in arcmin >= 0, got {text!r}") from None
    if not g or any(not (x >= 0.0) for x in g) or len(set(g)) != len(g):
        raise SystemExit(f"error: --gammas takes a comma list of distinct slopes in arcmin >= 0, got {text!r}")
    return sorted(set(g) | {0.0})


def parse_args(argv):
    p = args.parser("bearing_misalignment", __doc__, examples=EXAMPLES, writes=WRITES, out="results/bearing_misalignment")
    p.add_argument("--gammas", default="0,2,4,6,10", help="pin slopes against the bore in arcmin (default 0,2,4,6,10; "
                                                          "0 is always added: the lives are relative to it)")
    p.add_argument("--profiles", default="straight,logarithmic,iso_16281", type=args.choice_list(PROFILES, "profile"),
                   help="roller profiles (default straight,logarithmic,iso_16281; their parameters: bearing.profile.*)")
    p.add_argument("--snapshots", type=args.count(1), default=8,
                   help="static solutions per condition and direction for the bearing loads (default 8)")
    p.add_argument("--positions", type=args.count(1), default=8,
                   help="cage positions over one roller pitch for the life (default 8)")
    p.add_argument("--load", default=None, type=args.quantity_of("force", positive_only=True),
                   help='one bearing load for every case instead of the static solutions (e.g. "12 kN")')
    args.add_shared(p, "conditions", "params", "set", "out", out="results/bearing_misalignment", conditions="1,3",
                    conditions_why="1 and 3: the slowest and the fastest loaded condition (1000 and 4200 rpm at "
                                   "200 kW), the two ends of the planets' centrifugal load")
    return p.parse_args(argv)


def _params(a, condition: int, direction: str):
    try:
        text = Path(a.params).read_text(encoding="utf-8") if a.params else ""
        return with_overrides(reference_dpgt(condition, direction), {**overrides_from_toml(text),
                                                                      **args.parse_sets(a.set)})
    except (ParameterError, ValueError) as exc:
        raise SystemExit(f"error: {exc}".splitlines()[0]) from None


def bearing_loads(a) -> list[dict]:
    """Pair 1's inner and outer planet bearing loads [N] of each condition and direction: the static solution's mean
    pin reaction, or --load."""
    out = []
    for c in [int(x) for x in a.conditions.split(",")]:
        for d in ("forward", "reverse"):
            params = _params(a, c, d)
            if a.load is not None:
                F = to_si(quantity("load", a.load, "force"))
                loads = {k: F for k in ("inner", "outer")}
            else:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")      # the reference design's known tip-circle warnings
                    s = static_summary(build_dpgt(params), a.snapshots)
                loads = {k: s[k]["bearing_load_mean_N"] for k in ("inner", "outer")}
            for k, F in loads.items():
                out.append({"condition": c, "direction": d, "planet": k, "load_N": float(F), "params": params})
            print(f"condition {c} {d}: bearing loads inner {loads['inner'] / 1e3:.2f} kN, outer "
                  f"{loads['outer'] / 1e3:.2f} kN", flush=True)
    return out


def study(a) -> list[dict]:
    gammas = _gammas(a.gammas)
    rows = []
    for case in bearing_loads(a):
        base = case["params"].bearing
        for profile in a.profiles.split(","):
            b = with_overrides(base, {"profile.shape": profile}).si()
            for direction in MISALIGNMENT_DIRECTIONS:
                sweep = misalignment_sweep(b, np.array([case["load_N"], 0.0]), [g * ARCMIN for g in gammas],
                                           direction, positions=a.positions)
                for g, r in zip(gammas, sweep):
                    rows.append({"condition": case["condition"], "direction": case["direction"],
                                 "planet": case["planet"], "load_N": case["load_N"], "profile": profile,
                                 "slope": direction, "gamma_arcmin": g, "slices": b.slicing.slices,
                                 **{k: v for k, v in r.items() if k not in ("gamma_rad", "direction")}})
    return rows


def table(rows: list[dict]) -> str:
    gammas = sorted({r["gamma_arcmin"] for r in rows})
    shown = [g for g in gammas if g > 0]
    head = ["condition", "direction", "planet", "load", "profile", "slope", "L10 aligned"] + \
        [f"L/L0 {g:g}′" for g in shown] + [f"edge p ratio {EDGE_AT:g}′"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    key = lambda r: (r["condition"], r["direction"], r["planet"], r["profile"], r["slope"])  # noqa: E731
    groups: dict = {}
    for r in rows:
        groups.setdefault(key(r), {})[r["gamma_arcmin"]] = r
    for k, by_g in groups.items():
        r0 = by_g[0.0]
        edge = by_g.get(EDGE_AT)
        cells = [str(k[0]), k[1], k[2], f"{r0['load_N'] / 1e3:.2f} kN", k[3], k[4], f"{r0['life_Mrev']:.4g} Mrev"]
        cells += [f"{by_g[g]['life_relative']:.3f}" for g in shown]
        cells.append(f"{edge['edge_ratio']:.3f}" if edge else "–")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def run(a) -> dict:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = study(a)
    with (out / "misalignment.csv").open("w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    md = table(rows)
    atomic_write_text(out / "misalignment.md", md + "\n")
    loads = sorted({(r["condition"], r["direction"], r["planet"], r["load_N"]) for r in rows})
    atomic_write_text(out / "loads.json", json.dumps([dict(zip(("condition", "direction", "planet", "load_N"), x))
                                                      for x in loads], indent=1))
    print(md)
    print(f"written: {out / 'misalignment.csv'}, {out / 'misalignment.md'}, {out / 'loads.json'}")
    return {"rows": rows}


@command
def main(argv=None) -> int:
    run(parse_args(argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
