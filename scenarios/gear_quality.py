"""What real gears do to the planet bearings: the forward/reverse study with ISO 1328-1 tooth classes.

    python -m scenarios.gear_quality [--conditions 1,2,3,4] [--directions forward,reverse] [--gear-class 5,6,8]
        [--seeds 1,2,3] [--systematic-share 0.5] [--settle S] [--window S] [--set KEY=VALUE ...]
        [--workers N | --scheduler ADDR] [--force] [--overwrite] [--out DIR]

Every operating point runs with perfect teeth and with the teeth of every gear drawn for each flank
tolerance class and seed (``errors.flank_class``: ISO 1328-1:2013, normal with the tolerance at 3σ, each
gear its own teeth; components.tolerances) — teeth only: no runout, no pinhole error, so that the change is
the teeth's. All runs use the tooth-pair mesh law where teeth are real (the perfect machine's law is its exact
reduction), the same window and the same runner as the paper study (resumable, on Dask).

Writes ``runs.csv`` (a row per run and bearing type: mean and largest bearing load, largest roller load, cage
guide and pocket-impact maxima, both lives, and per mesh type the simulated dynamic factor K_v (the mesh cycles'
peaks, and the 99th percentile, over the mean drive-flank force), ISO 6336-1 method B's K_v for the class and the
loaded transmission error's peak-to-peak), ``by_grade.csv`` (per condition, direction, class and bearing type the
mean over the seeds with their smallest and largest value, and the forward/reverse change of the mean load and
the life), ``findings.md`` (the answer in words) and ``quality.png``.
"""
from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path

import numpy as np

import mbd
from components.iso6336 import machine_dynamic_factors
from components.results.io import atomic_write_text
from components.results import percent_change

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.points import machine_overrides, point_label, point_order, point_words, points_of
from .core.sweep import Case, build_params, user_overrides

__all__ = ["main", "run", "make_cases", "rows_of", "by_grade", "findings", "QUANTITIES", "MESHES"]

MESHES = ("sun_inner", "inner_outer", "outer_ring")
# per bearing type: column -> (summary.json key, words, unit)
QUANTITIES = {
    "bearing_load_mean_N": ("bearing_load_mean_all_N", "mean bearing load", "N"),
    "bearing_load_max_N": ("bearing_load_max_N", "largest bearing load", "N"),
    "roller_max_N": (None, "largest roller load", "N"),
    "cage_guide_max_N": ("cage_guide_max_N", "largest cage-guide force", "N"),
    "pocket_impact_peak_max_N": ("pocket_impact_peak_max_N", "largest pocket impact", "N"),
    "pocket_impact_speed_max_m_s": ("pocket_impact_speed_max_m_s", "fastest pocket impact", "m/s"),
    "load_sharing_factor": ("load_sharing_factor", "load sharing K_γ", None),
    "life_iso281_h": ("life_iso281_h", "ISO 281 life (pair 1)", "h"),
    "life_iso16281_h": ("life_iso16281_h", "roller-load life (pair 1)", "h"),
}
# per mesh type: the simulated K_v (mean over mesh cycles of each cycle's peak drive-flank force over the mean), its
# 99th-percentile form, ISO 6336-1 method B's K_v for the class (components.iso6336) and the loaded TE peak-to-peak
MESH_COLUMNS = ("dynamic_factor", "dynamic_factor_p99", "kv_iso_b", "te_p2p_um")
COLUMNS = (["condition", "direction", "grade", "seed", "bearing", *QUANTITIES]
           + [f"{k}_{m}" for m in MESHES for k in MESH_COLUMNS])


EXAMPLES = ["{prog} --conditions 3 --gear-class 6 --seeds 1 --out results/gear_quality",
            "{prog} --conditions 1,2,3,4 --gear-class 5,6,8 --seeds 1,2,3 --workers 2",
            "{prog} --params my_machine.toml --gear-class 8 --systematic-share 0.2"]
WRITES = ("c{condition}_{direction}_{perfect|class{G}_seed{S}}/{results.nc, summary.json} per run; runs.csv (a "
          "row per run and bearing type), by_grade.csv (per class the mean over the seeds and their range, the "
          "forward/reverse change), findings.md (the answer in words, also printed), quality.png, study.json")


def parse_args(argv):
    p = args.parser("gear_quality", __doc__, examples=EXAMPLES, writes=WRITES, out="results/gear_quality")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument(args.GEAR_CLASS, default="5,6,8", type=args.int_list(1, 11, "flank tolerance classes"),
                   metavar="CLASS[,CLASS...]", help="ISO 1328-1:2013 flank tolerance classes 1..11 (default 5,6,8)")
    args.renamed(p, "--grades", "--classes", "--gear-grade", new=args.GEAR_CLASS)
    p.add_argument("--seeds", default="1,2,3", type=args.int_list(0, None, "seeds"), help="seeds of the draws (default 1,2,3)")
    p.add_argument("--systematic-share", type=_share, default=0.5,
                   help="share of the profile deviations' variance common to a gear flank's teeth (default 0.5)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="seconds analysed (default: the paper study's, whole cage revolutions)")
    args.add_shared(p, out="results/gear_quality", conditions="1,2,3,4",
                    conditions_why="all four: what a tooth class does depends on the mesh frequency against the "
                                   "train's natural frequencies and on the load, so every speed and load of the "
                                   "source is asked")
    return p.parse_args(argv)


def _share(text: str) -> float:
    x = args.nonnegative("")(text)
    if x > 1.0:
        raise argparse.ArgumentTypeError(f"must be in [0, 1], got {text!r}")
    return x


def _tag(grade, seed) -> str:
    return "perfect" if grade is None else f"class{grade}_seed{seed}"


def make_cases(a, out: Path) -> list[Case]:
    """Perfect teeth, and every class × seed, at every condition and direction."""
    sets = args.parse_sets(a.set)
    points = points_of(a, sets)
    user = machine_overrides(user_overrides(sets, a.params, {"errors.flank_class": "--gear-class and --seeds"}), points)
    machines = [(None, None)] + [(g, s) for g in a.gear_class for s in a.seeds]
    cases = []
    for p in points:
        for d in ([p.direction] if p.direction else a.directions.split(",")):
            for g, s in machines:
                ov = dict(user)
                if g is not None:
                    ov["errors.flank_class"] = [{"gear": "all", "grade": g, "seed": s,
                                                 "systematic_share": a.systematic_share}]
                cases.append(Case.at(p, d, str(out / f"{point_label(p, d)}_{_tag(g, s)}"), ov, a.params,
                                     tag=_tag(g, s)))
    return cases


def _grade_seed(case: Case):
    fc = case.overrides.get("errors.flank_class")
    return (None, None) if not fc else (fc[0]["grade"], fc[0]["seed"])


def rows_of(cases: list[Case], results: dict) -> list[dict]:
    """A row per finished run and bearing type (module docstring)."""
    rows = []
    for case in cases:
        s = results.get(case.label)
        if s is None or s.failed:
            continue
        g, seed = _grade_seed(case)
        iso_b = machine_dynamic_factors(build_params(case).si(), g)
        mesh = {}
        for m in MESHES:
            d = s["meshes"][m]
            # K_v needs a load to scale: none where the train transmits no torque (summary.json says null there)
            loaded = bool(s.get("power_W", 1.0))
            mesh[f"dynamic_factor_{m}"] = d.get("dynamic_factor") if loaded else None
            mesh[f"dynamic_factor_p99_{m}"] = d.get("dynamic_factor_p99") if loaded else None
            mesh[f"kv_iso_b_{m}"] = iso_b[m].K_v if iso_b.get(m) is not None else None
            mesh[f"te_p2p_um_{m}"] = 1e6 * d["te_peak_to_peak_m"]
        for kind in ("inner", "outer"):
            b = s[kind]
            row = {"condition": case.condition, "direction": case.direction, "grade": g, "seed": seed, "bearing": kind}
            for col, (key, _, _) in QUANTITIES.items():
                row[col] = max(b["roller_inner_race_max_N"], b["roller_outer_race_max_N"]) if key is None else b.get(key)
            rows.append({**row, **mesh})
    return rows


def by_grade(rows: list[dict]) -> list[dict]:
    """Per condition, direction, class (None: perfect) and bearing: mean, min and max over the seeds of every
    quantity, and the reverse/forward change (in %) of the mean bearing load and the roller-load life."""
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((r["condition"], r["direction"], r["grade"], r["bearing"]), []).append(r)
    cols = [c for c in COLUMNS if c not in ("condition", "direction", "grade", "seed", "bearing")]
    out = []
    for (c, d, g, b), rs in sorted(groups.items(), key=lambda kv: (point_order(kv[0][0]), kv[0][1], kv[0][2] or 0,
                                                                   kv[0][3])):
        row = {"condition": c, "direction": d, "grade": g, "bearing": b, "seeds": len(rs)}
        for col in cols:
            v = np.array([np.nan if r[col] is None else float(r[col]) for r in rs])
            row[col] = float(np.nanmean(v)) if np.any(np.isfinite(v)) else None
            row[f"{col}_min"] = float(np.nanmin(v)) if np.any(np.isfinite(v)) else None
            row[f"{col}_max"] = float(np.nanmax(v)) if np.any(np.isfinite(v)) else None
        out.append(row)
    index = {(r["condition"], r["direction"], r["grade"], r["bearing"]): r for r in out}
    for r in out:
        f = index.get((r["condition"], "forward", r["grade"], r["bearing"]))
        rev = index.get((r["condition"], "reverse", r["grade"], r["bearing"]))
        for col in ("bearing_load_mean_N", "life_iso16281_h"):
            r[f"{col}_reverse_change_pct"] = percent_change(f[col], rev[col]) if f and rev else None
    return out


def findings(groups: list[dict]) -> str:
    """The answer in words: per condition and bearing type, what each class does against perfect teeth
    (mean and largest bearing load, largest roller load, life, K_v), the spread between seeds, and whether the
    forward/reverse change of the mean load keeps its sign and size."""
    at = {(g["condition"], g["direction"], g["grade"], g["bearing"]): g for g in groups}
    grades = sorted({g["grade"] for g in groups if g["grade"] is not None})
    lines = ["What real teeth do (ISO 1328-1:2013 flank tolerance class, every gear its own teeth; mean of the "
             "seeds, their range in brackets; against perfect teeth at the same operating point).", ""]
    pct = lambda x, y: percent_change(y, x)      # loads and lives: positive, so always a percentage
    for c in sorted({g["condition"] for g in groups}, key=point_order):
        lines.append(f"{point_words(c)}:")
        for d in ("forward", "reverse"):
            for b in ("inner", "outer"):
                p = at.get((c, d, None, b))
                if p is None:
                    continue
                parts = []
                for g in grades:
                    q = at.get((c, d, g, b))
                    if q is None:
                        continue
                    kv = "/".join(f"{q[f'dynamic_factor_{m}']:.2f}" if q[f"dynamic_factor_{m}"] is not None else "–"
                                  for m in MESHES)
                    kb = "/".join(f"{q[f'kv_iso_b_{m}']:.2f}" if q[f"kv_iso_b_{m}"] is not None else "–"
                                  for m in MESHES)
                    parts.append(
                        f"class {g}: mean load {pct(q['bearing_load_mean_N'], p['bearing_load_mean_N']):+.1f} %, "
                        f"largest {pct(q['bearing_load_max_N'], p['bearing_load_max_N']):+.0f} % "
                        f"[{pct(q['bearing_load_max_N_min'], p['bearing_load_max_N']):+.0f}, "
                        f"{pct(q['bearing_load_max_N_max'], p['bearing_load_max_N']):+.0f}], roller "
                        f"{pct(q['roller_max_N'], p['roller_max_N']):+.0f} %, life "
                        f"{pct(q['life_iso16281_h'], p['life_iso16281_h']):+.1f} %, K_v {kv} (ISO 6336-1 "
                        f"method B {kb}; sun-inner/inner-outer/outer-ring)")
                lines.append(f"  {d:>7} {b} bearings ({p['bearing_load_mean_N'] / 1e3:.1f} kN mean, "
                             f"{p['bearing_load_max_N'] / 1e3:.1f} kN largest with perfect teeth): " + "; ".join(parts))
        for b in ("inner", "outer"):
            ch = [(g, at.get((c, "forward", g, b))) for g in [None, *grades]]
            ch = [(g, r["bearing_load_mean_N_reverse_change_pct"]) for g, r in ch if r and
                  r.get("bearing_load_mean_N_reverse_change_pct") is not None]
            if ch:
                lines.append(f"  reverse vs forward, {b} bearings' mean load: "
                             + ", ".join(f"{'perfect' if g is None else f'class {g}'} {v:+.1f} %" for g, v in ch))
        lines.append("")
    return "\n".join(lines)


def _write_csv(path: Path, rows: list[dict], columns=None) -> None:
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(columns or rows[0]))
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def write_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """runs.csv, by_grade.csv and findings.md (headed by ``machine``, the machine's name)."""
    groups = by_grade(rows)
    _write_csv(out / "runs.csv", rows, COLUMNS)
    _write_csv(out / "by_grade.csv", groups)
    atomic_write_text(out / "findings.md", (f"Machine: {machine}\n\n" if machine else "") + findings(groups) + "\n")
    return [out / "runs.csv", out / "by_grade.csv", out / "findings.md"]


def plot(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """quality.png."""
    from viz.plots import gear_quality  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    return [gear_quality(by_grade(rows), out / "quality.png",
                         title="Gear tooth quality (ISO 1328 flank class) against perfect teeth: planet bearings and the ring mesh"
                               + (f" — {machine}" if machine else ""))]


def write_outputs(rows: list[dict], out: Path) -> list[Path]:
    """The tables and the figure (module docstring)."""
    return write_tables(rows, out) + plot(rows, out)


class GearQualityStudy(Study):
    """Perfect teeth and every class × seed at every condition and direction (:class:`scenarios.core.study.Study`):
    the findings first, then the tables and the figure."""

    def config(self) -> RunConfig:
        a = self.a
        return RunConfig(settle=a.settle, window=a.window, integration=mbd.PRODUCTION, progress=not a.no_progress)

    def cases(self) -> list[Case]:
        return make_cases(self.a, self.out)

    def report(self, run: StudyRun) -> dict:
        rows = rows_of(run.cases, run.results)
        if rows:
            print(findings(by_grade(rows)))      # the headline first
            run.step("tables", write_tables, rows, self.out, self.machine_identity()["label"])
            run.step("figures", plot, rows, self.out, self.machine_identity()["label"])
        return {"rows": rows}


@holds_out_folder
def run(a) -> dict:
    return GearQualityStudy(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
