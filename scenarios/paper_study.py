"""Forward vs reverse carrier rotation: planet-bearing loads, cage collisions and vibration, bearing life.

    python -m scenarios.paper_study --conditions 3 --out results/study
    python -m scenarios.paper_study --conditions 1,2,3,4 --directions forward,reverse --workers 2 \\
        --set bearing.clearance="30 um" --out results/study

Writes DIR/c{condition}_{direction}/{results.nc, summary.json}, DIR/comparison.csv, DIR/comparison.md,
DIR/bearing_load_life.png (the headline: mean load and L10 life per bearing type, forward vs reverse, the change
in % or, from ten times, as a ratio), DIR/bars.png, per condition the time histories DIR/c{condition}_{bearing_loads,roller_contacts,cage,mesh}.png
and the cage orbits DIR/c{condition}_cage_orbit_{inner,outer}.png, and (with --animate) DIR/c{condition}_cage_orbits.gif.
"""
from __future__ import annotations

import argparse

import dataclasses
import csv
import io
import sys
from pathlib import Path

import numpy as np

import mbd
from components.families import MESH_FAMILY
from components.static import DEFAULT_SNAPSHOTS, DYNAMIC_ONLY, STATIC_LIVES_NOTE
from components.outputs import FAMILY, radial_tangential
from components.outputs import relative_life as iso_relative_life
from components.results import SUMMARY_WORDS, Summary, format_change, open_run, percent_change
from components.results.io import atomic_write_text, write_summary

from .core.integrity import read_summary
from .core.runner import SETTLED_SPEED_ERROR_PCT, RunConfig
from .core.study import Study, StudyRun
from .core.points import machine_identity, machine_overrides, point_label, point_order, point_tag, points_of
from .core.sweep import ALL, Beside, Case, user_overrides
from .core import args
from .core.command import command
from .core.lock import holds_out_folder

# the summary keys the comparison shows, with their units (words: components.results.SUMMARY_WORDS)
QUANTITIES = [(k, SUMMARY_WORDS[k][1]) for k in (
    "roller_cage_rms_N", "roller_cage_max_N", "cage_guide_rms_N", "cage_guide_max_N", "roller_inner_race_rms_N",
    "roller_inner_race_max_N", "roller_outer_race_rms_N", "roller_outer_race_max_N", "cage_acc_radial_rms_m_s2",
    "cage_acc_tangential_rms_m_s2", "cage_acc_rel_radial_rms_m_s2", "cage_acc_rel_tangential_rms_m_s2", "cage_slip_pct",
    "pocket_impacts_per_rev", "pocket_impact_speed_max_m_s", "pocket_impact_peak_max_N", "bearing_load_mean_N",
    "life_L10_relative", "life_iso281_h", "life_iso16281_h")]
# bar chart: RMS values, cage accelerations relative to the planet, radial/tangential (comparable between
# inner and outer planets, unlike x/y)
BAR_QUANTITIES = ["roller_cage_rms_N", "cage_guide_rms_N", "roller_inner_race_rms_N", "roller_outer_race_rms_N",
                  "cage_acc_rel_radial_rms_m_s2", "cage_acc_rel_tangential_rms_m_s2"]


EXAMPLES = ["{prog} --conditions 3 --out results/study",
            '{prog} --conditions 1,2,3,4 --directions forward,reverse --workers 2 --set bearing.clearance="30 um"',
            "{prog} --params my_machine.toml --animate --out results/mine"]
WRITES = ("c{condition}_{direction}/{results.nc, summary.json} per run; comparison.csv and comparison.md (every "
          "quantity forward vs reverse, the change in % or, from ten times, as a ratio); bearing_load_life.png (the headline: mean load and L10 "
          "life per bearing type), bars.png, per condition the time histories c{condition}_{bearing_loads, "
          "roller_contacts, cage, mesh}.png and the cage orbits c{condition}_cage_orbit_{inner,outer}.png; with "
          "--animate c{condition}_cage_orbits.gif")


def build_parser(name: str = "paper_study", out: str = "results/study", doc: str = __doc__,
                 examples: list[str] = EXAMPLES, animate: bool = False):
    """The study's options; ``animate``: the animation is on by default (the demo), and the help says so."""
    writes = WRITES.replace("with --animate", "and (unless --no-animate)") if animate else WRITES
    p = args.parser(name, doc, examples=examples, writes=writes, out=out)
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--planets", type=args.count(1), default=None, help="planet pairs N (default 3, the reference machine)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03,
                   help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="seconds recorded and analysed (default: max(0.02 s, one carrier revolution), rounded up "
                        "to whole revolutions of the slowest cage relative to the carrier)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=25000.0, help="recording rate [Hz]")
    p.add_argument("--method", default="hht-adaptive", choices=["hht-adaptive", "hht-fixed"])
    p.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="fixed step / initial step [s]")
    p.add_argument("--alpha", type=args.alpha, default=-0.3, help="HHT alpha in [-1/3, 0]")
    p.add_argument("--option", action="append", default=[], metavar="KEY=VALUE", type=args.key_value,
                   help="scene switch, e.g. --option drag=false --option bearings=linear")
    p.add_argument("--mode", default="dynamic", choices=["dynamic", "static"],
                   help="dynamic: time integration (default); static: the quasi-static solution of the same model "
                        "(mean loads, load sharing, lives in seconds; quantities only a dynamic run gives — cage "
                        "motion, impacts, RMS values, time histories — are left out and said so)")
    p.add_argument("--snapshots", type=args.count(1), default=DEFAULT_SNAPSHOTS,
                   help=f"static mode: instants over a carrier revolution and the mesh cycle averaged (default "
                        f"{DEFAULT_SNAPSHOTS})")
    p.add_argument("--animate", action=argparse.BooleanOptionalAction, default=animate,
                   help="write a cage-orbit animation per condition (forward beside reverse)"
                        + (" (default: on)" if animate else ""))
    args.add_shared(p, out=out, conditions="3")
    return p


def parse_args(argv):
    return build_parser().parse_args(argv)


def build_config(a) -> RunConfig:
    return RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate,
                     integration=dataclasses.replace(mbd.PRODUCTION, method=a.method, h=a.h, alpha=a.alpha),
                     options=args.scene_options(a.option), progress=not a.no_progress,
                     mode=getattr(a, "mode", "dynamic"), snapshots=getattr(a, "snapshots", DEFAULT_SNAPSHOTS))


def make_cases(a, out: Path) -> list[Case]:
    """Every point (``--conditions``, ``--operating``, the file's points: :mod:`scenarios.core.points`) in every
    direction of ``--directions`` (a point that fixes its direction runs in that one only)."""
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    for d in dirs:
        if d not in ("forward", "reverse"):
            raise SystemExit(f"error: --directions takes forward and/or reverse, got {d!r}")
    sets = args.parse_sets(a.set)
    points = points_of(a, sets)
    overrides = machine_overrides(user_overrides(sets, None, {}), points)
    if a.planets is not None:
        overrides["gears.planets"] = a.planets
    cases = {}
    for p in points:
        for d in ([p.direction] if p.direction else dirs):
            cases.setdefault(point_label(p, d), Case.at(p, d, str(out / point_label(p, d)), overrides, a.params))
    return list(cases.values())


def _at(results: dict, c, direction: str) -> Summary:
    """The run of point ``c`` (a condition's number or a point's name) in ``direction`` (an empty summary if none)."""
    for s in results.values():
        if s.get("condition") == c and s.get("direction") == direction:
            return s
    return Summary()


def _label_of(results: dict, c, direction: str) -> str | None:
    for k, s in results.items():
        if s.get("condition") == c and s.get("direction") == direction:
            return k
    return None


def _conds(results: dict) -> list:
    return sorted({s["condition"] for s in results.values() if not s.failed}, key=point_order)


def _title(c) -> str:
    return f"Condition {c}" if isinstance(c, int) else f"Point {c}"


def relative_life(results: dict) -> None:
    """Fill life_L10_relative = (P_fwd / P)^(10/3) per condition and bearing kind (forward = 1)."""
    for label, s in results.items():
        if s.failed:
            continue
        fwd = _at(results, s["condition"], "forward") or None
        for kind in ("inner", "outer"):
            if fwd is None or fwd.failed:
                s[kind]["life_L10_relative"] = None
                continue
            P, Pf = s[kind]["equivalent_load_N"], fwd[kind]["equivalent_load_N"]
            s[kind]["life_L10_relative"] = iso_relative_life(P, Pf)


def comparison_rows(results: dict) -> list[dict]:
    rows = []
    conds = _conds(results)
    for c in conds:
        f, r = _at(results, c, "forward"), _at(results, c, "reverse")
        for kind in ("inner", "outer"):
            for q, unit in QUANTITIES:
                fv = f.get(kind, {}).get(q) if not f.failed else None
                rv = r.get(kind, {}).get(q) if not r.failed else None
                rows.append({"condition": c, "bearing": kind, "quantity": q, "description": SUMMARY_WORDS[q][0],
                             "unit": unit, "forward": fv, "reverse": rv,
                             "difference": rv - fv if fv is not None and rv is not None else None,
                             "difference_pct": percent_change(fv, rv)})
    return rows


def _fmt(x, nd=4):
    return "–" if x is None else f"{x:.{nd}g}"


def write_tables(rows: list[dict], out: Path, machine: dict | None = None) -> tuple[Path, Path, str]:
    """comparison.csv (every row, the change as a number: ``difference_pct``) and comparison.md (per point, the change
    written as the headline writes it, :func:`components.results.format_change`); returns their paths and the
    markdown."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]) if rows else ["condition"])
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "comparison.csv", buf.getvalue())
    md = []
    for c in sorted({r["condition"] for r in rows}, key=point_order):
        md.append(f"\n### {_title(c)}\n\n| bearing | quantity | forward | reverse | reverse − forward | change "
                  f"|\n|---|---|---|---|---|---|")
        for r in rows:
            if r["condition"] == c:
                pct = format_change(r["difference_pct"]) if r["difference_pct"] is not None \
                    else "–" if r["difference"] is None \
                    else "– (sign changes)" if (r["forward"] or 0) * (r["reverse"] or 0) < 0 else "–"
                md.append(f"| {r['bearing']} | {r['description']} [{r['unit']}] | {_fmt(r['forward'])} | "
                          f"{_fmt(r['reverse'])} | {_fmt(r['difference'])} | {pct} |")
    text = "\n".join(md).strip() + "\n"
    if machine is not None:        # the machine the tables are of: its file, a short fingerprint, the overrides
        text = f"Machine: {machine['label']}\n\n" + text
    atomic_write_text(out / "comparison.md", text)
    return out / "comparison.csv", out / "comparison.md", text


HEADLINE = (("bearing_load_mean_N", "mean load", 1e-3, "kN"), ("life_iso281_h", "L10 ISO 281", 1.0, "h"),
            ("life_iso16281_h", "L10 roller loads", 1.0, "h"))


def meaningless(results: dict) -> str:
    """Why the runs' statistics do not mean anything, in one line ('' when they do): a bearing whose cage turned less
    than once relative to the carrier in the window, or a carrier drive off its speed by more than
    :data:`scenarios.core.runner.SETTLED_SPEED_ERROR_PCT` on average (each run's warnings say it in full)."""
    why = []
    for label, s in sorted(results.items()):
        if not s.has_bearings:
            continue
        short = [k for k in ("inner", "outer") if (s[k].get("cage_revolutions") or 1.0) < 1.0]
        if short:
            why.append(f"{label}: the window covers less than one cage revolution ({', '.join(short)})")
        err = s.get("carrier_speed_error_mean_pct")
        if err is not None and abs(err) > SETTLED_SPEED_ERROR_PCT:
            why.append(f"{label}: the carrier drive had not settled ({err:+.2g} %)")
    return "; ".join(why)


def headline_table(rows: list[dict]) -> str:
    """The study's answer in a few lines (what the headline figure shows): per condition and bearing type the mean
    bearing load and both L10 lives, forward / reverse and the change as the figure writes it
    (:func:`components.results.format_change`: '−99.6 %', '×665'), from the comparison's rows."""
    at = {(r["condition"], r["bearing"], r["quantity"]): r for r in rows}
    num = lambda x, k: "–" if x is None else f"{x * k:.3g}"
    head = "".join(f" | {w} fwd / rev [{u}] (change)" for _, w, _, u in HEADLINE)
    lines = [f"headline (pair 1's planet bearings, forward vs reverse):\n| condition | bearing{head} |",
             "|---|---" + "|---" * len(HEADLINE) + "|"]
    for c, b in sorted({(r["condition"], r["bearing"]) for r in rows}, key=lambda x: (point_order(x[0]), x[1])):
        cells = []
        for q, _, k, _ in HEADLINE:
            r = at.get((c, b, q))
            if r is None:
                cells.append("–")
                continue
            d = r["difference_pct"]
            cells.append(f"{num(r['forward'], k)} / {num(r['reverse'], k)}" + ("" if d is None else f" ({format_change(d)})"))
        lines.append(f"| {c} | {b} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _runs_of(results: dict, out: Path, c) -> dict[str, Path]:
    """direction -> results.nc of point ``c``'s runs that finished (a missing run is left out, not faked)."""
    runs = {}
    for d in ("forward", "reverse"):
        label = _label_of(results, c, d)
        p = out / str(label) / "results.nc"
        s = results.get(label)
        if label is not None and p.exists() and s is not None and not s.failed:
            runs[d] = p
    return runs


# the groups of time histories, each its own figure: file stem -> (title, columns)
HISTORY_GROUPS = {"bearing_loads": "planet bearing loads (pin reaction, pair 1)",
                  "roller_contacts": "roller contacts (reference roller 0, pair 1)",
                  "cage": "cages (pair 1)",
                  "mesh": "gear meshes (pair 1)"}
MESH_COLUMNS = {"sun_inner": "sun – inner planet", "inner_outer": "inner – outer planet",
                "outer_ring": "outer planet – ring"}
MESH_FORCE_WORDS = "drive-flank force − coast-flank force"     # drive: the flank the torque path loads


def history_groups(runs: dict) -> dict[str, tuple[list, list[str]]]:
    """The time histories of one condition's runs in readable groups (:data:`HISTORY_GROUPS`): group -> (rows of
    :func:`viz.plots.time_history_group`, its columns). ``runs``: direction -> results.nc, or that file read
    already (:func:`viz.results.load_run`: a point's figures read each file once). SI values from results.nc;
    the cage accelerations relative to the planet are split radial/tangential here (physics stays out of viz)."""
    from viz.results import Run, load_run  # deferred: matplotlib (viz), only when the figures are drawn

    rows: dict[str, dict[tuple, dict]] = {g: {} for g in HISTORY_GROUPS}   # group -> (words, unit) -> col -> run

    def put(group, words, unit, col, run, t, y):
        rows[group].setdefault((words, unit), {}).setdefault(col, {})[run] = (t, np.asarray(y, float))

    for d, r in runs.items():
        run = r if isinstance(r, Run) else load_run(r)
        out = run.outputs
        # the flank the torque path loads, per mesh, as the run recorded it (reverse loads the other flanks)
        drive = {k: m.get("drive_flank")
                 for k, m in (read_summary(open_run(run.path).summary_path) or Summary()).meshes.items()}
        t = run.t
        bodies = list(run.bodies)
        for i, b in enumerate(run.bearings):
            if b["pair"] != 0:
                continue
            col = b["kind"]
            if "bearing.load_radial" in out:
                put("bearing_loads", "bearing load, radial (+ outward)", "N", col, d, t,
                    out["bearing.load_radial"][:, i])
                put("bearing_loads", "bearing load, tangential (+ counter-clockwise)", "N", col, d, t,
                    out["bearing.load_tangential"][:, i])
            if b["type"] != "rollers":
                continue
            put("roller_contacts", "roller–inner race load", "N", col, d, t,
                out[f"{FAMILY['race_inner']}.load"][:, b["race_inner"][0]])
            put("roller_contacts", "roller–outer race load", "N", col, d, t,
                out[f"{FAMILY['race_outer']}.load"][:, b["race_outer"][0]])
            if "pocket" in b:
                put("roller_contacts", "roller–cage pocket force", "N", col, d, t,
                    out[f"{FAMILY['pocket']}.force"][:, b["pocket"][0]])
            if "guide" in b:
                put("cage", "cage–guide force", "N", col, d, t, out[f"{FAMILY['guide']}.force"][:, b["guide"]])
                a, pos = run.a[..., :2], run.q[..., :2]         # the bodies' x, y in R
                ic, ip, ik = (bodies.index(x) for x in (b["cage"], b["planet"], "carrier"))
                rad, tan = radial_tangential(a[:, ic] - a[:, ip], pos[:, ip], pos[:, ik])
                put("cage", "cage acc. rel. planet, radial", "m/s^2", col, d, t, rad)
                put("cage", "cage acc. rel. planet, tangential", "m/s^2", col, d, t, tan)
            if "bearing.cage_slip" in out:
                put("cage", "cage slip", "%", col, d, t, out["bearing.cage_slip"][:, i])
        for key in MESH_COLUMNS:
            fam = MESH_FAMILY[key]
            if f"{fam}.force" in out and drive.get(key) in (1, -1):
                # the file's force is flank +1's minus flank −1's: times the drive flank's sign it reads
                # drive − coast, > 0 while the loaded flank carries the load, in either direction
                put("mesh", MESH_FORCE_WORDS, "N", key, d, t, drive[key] * out[f"{fam}.force"][:, 0])
            if f"{fam}.transmission_error" in out:
                put("mesh", "loaded transmission error", "m", key, d, t, out[f"{fam}.transmission_error"][:, 0])
    out = {}
    for g, by_row in rows.items():
        if by_row:
            cols = list(MESH_COLUMNS) if g == "mesh" else ["inner", "outer"]
            out[g] = ([(w, u, by_col) for (w, u), by_col in by_row.items()], cols)
    return out


def headline_values(results: dict) -> dict[tuple, float | None]:
    """(quantity, condition, bearing, direction) -> value of :data:`viz.plots.HEADLINE_QUANTITIES`, from the runs
    that finished (a failed or missing run has no entry)."""
    from viz.plots import HEADLINE_QUANTITIES  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    vals = {}
    for s in results.values():
        if not s.has_bearings:
            continue
        for kind in ("inner", "outer"):
            for key, _, _ in HEADLINE_QUANTITIES:
                vals[(key, s["condition"], kind, s["direction"])] = s[kind].get(key)
    return vals


# a point's figures in two pieces of about equal work, drawn at once on two workers beside the runs (each reads the
# point's two results files): the time histories of the bearing loads, the roller contacts and the meshes; the cage
# histories and the cage orbits
POINT_PIECES = (("bearing_loads", "roller_contacts", "mesh"), ("cage", "cage_orbits"))
# the figures across the points, each a piece of its own beside the last point's (:func:`across_figures`)
ACROSS_PIECES = ("headline", "bars")


def point_figures(results: dict, out: Path, c, figures=None) -> list[Path]:
    """Point ``c``'s own figures: its time histories in groups (:data:`HISTORY_GROUPS`) and its cage orbits
    ("cage_orbits"), forward and reverse; ``figures``: those of them (None: all)."""
    # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn
    from viz import plots as vp
    from viz.results import load_run, study_cage_pictures

    runs = _runs_of(results, out, c)
    if not runs:
        return []
    runs = {d: load_run(p) for d, p in runs.items()}        # each file read once for all the point's figures
    paths = []
    f_m = [results[_label_of(results, c, d)].get("f_m_hz") for d in runs]
    mesh_period = 1.0 / f_m[0] if f_m and f_m[0] else None
    for g, (rows, cols) in history_groups(runs).items():
        if figures is not None and g not in figures:
            continue
        titles = {"inner": "inner planet bearing", "outer": "outer planet bearing", **MESH_COLUMNS}
        # forward and reverse in rows of their own; the mesh histories, too coarsely sampled or too long to draw
        # cycle by cycle, per whole mesh cycle (viz.plots.time_history_group's envelope)
        paths.append(vp.time_history_group(rows, out / f"{point_tag(c)}_{g}.png", columns=cols,
                                           column_titles=titles, title=f"{_title(c)}: {HISTORY_GROUPS[g]}",
                                           separate_runs=True, envelope=mesh_period if g == "mesh" else None,
                                           envelope_words="mesh cycle"))
    if figures is None or "cage_orbits" in figures:
        paths += study_cage_pictures(runs, out, prefix=f"{point_tag(c)}_",
                                     title=f"{_title(c)}: cage orbits in the guide clearance")
    return paths


def point_work(results: dict, out: Path, c, piece) -> list[Path]:
    """One piece of what a point's finished runs give on their own — some of its figures (a :data:`POINT_PIECES`
    of :func:`point_figures`) or its animation ("animation") — done beside the other points' runs
    (:meth:`PaperStudy.beside`)."""
    return animate(results, out, only=[c]) if piece == "animation" else point_figures(results, out, c, piece)


def plots(results: dict, out: Path, machine: str = "", drawn=(), across=True) -> list[Path]:
    """Every figure of a dynamic study, the points in ``drawn`` (their figures made beside the runs) left out of the
    per-point ones, and the figures across the points unless ``across`` is False (made beside the runs too);
    ``machine``: the machine's label, in the headline figure's title."""
    paths = []
    for c in _conds(results):
        if c not in drawn:
            paths += point_figures(results, out, c)
    return paths + (across_figures(results, out, machine) if across else [])


def across_figures(results: dict, out: Path, machine: str = "", figures=None) -> list[Path]:
    """The figures across a dynamic study's points: the headline (mean load and lives, forward vs reverse,
    "headline") and the bars of RMS values ("bars"); ``figures``: those of them (None: both)."""
    want = ACROSS_PIECES if figures is None else figures
    return [*(_headline(results, out, machine) if "headline" in want else []),
            *(_bars(results, out) if "bars" in want else [])]


def _headline(results: dict, out: Path, machine: str, how: str = "") -> list[Path]:
    """bearing_load_life.png: mean load and L10 lives, forward vs reverse (none without a bearing's values); ``how``
    says how the values were found (", quasi-static")."""
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    vals = headline_values(results)
    if not vals:
        return []
    conds = _conds(results)
    one = f", {_title(conds[0]).lower()}" if len(conds) == 1 else ""
    return [vp.forward_reverse_headline(vals, out / "bearing_load_life.png",
                                        title=f"Planet bearings (pair 1){how}: mean load and L10 life, forward vs "
                                              f"reverse{one}" + (f"\n{machine}" if machine else ""))]


def _bars(results: dict, out: Path) -> list[Path]:
    """bars.png: the RMS values of :data:`BAR_QUANTITIES` per point, forward vs reverse, each bearing type."""
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    conds = _conds(results)
    table, bar_units, ylabels = {}, {}, {}
    for q, unit in QUANTITIES:
        if q not in BAR_QUANTITIES:
            continue
        for kind in ("inner", "outer"):
            key = f"{kind} planets\n{SUMMARY_WORDS[q][0]}"
            table[key] = {}
            bar_units[key] = unit
            ylabels[key] = SUMMARY_WORDS[q][0]
            for c in conds:
                f, r = _at(results, c, "forward"), _at(results, c, "reverse")
                fv = f.get(kind, {}).get(q) if not f.failed else None
                rv = r.get(kind, {}).get(q) if not r.failed else None
                table[key][c] = (fv, rv)
    if not (conds and table):
        return []
    return [vp.bar_chart([_title(c).lower() for c in conds], {k: {_title(c).lower(): v for c, v in by.items()}
                                                              for k, by in table.items()},
                         bar_units, out / "bars.png", ylabels=ylabels, ncols=2,
                         title=("RMS per condition: forward vs reverse" if len(conds) > 1 else
                                f"RMS at {_title(conds[0]).lower()}: forward vs reverse"))]


def static_plots(results: dict, out: Path, machine: str = "") -> list[Path]:
    """Static mode's figure: the headline (mean load and lives, forward vs reverse); the others need time series."""
    return _headline(results, out, machine, how=", quasi-static")


def animate(results: dict, out: Path, only=None) -> list[Path]:
    """The cage-orbit animation of every point (``only``: of those), forward beside reverse."""
    pairs = []
    for c in (_conds(results) if only is None else only):
        f = out / str(_label_of(results, c, "forward")) / "results.nc"
        r = out / str(_label_of(results, c, "reverse")) / "results.nc"
        if f.exists() and r.exists():
            pairs.append((c, f, r))
        else:      # the animation sets forward beside reverse
            missing = "reverse" if f.exists() else "forward"
            print(f"animation of {_title(c).lower()} skipped: it shows forward beside reverse, and "
                  f"{point_tag(c)}_{missing} was not run (--directions forward,reverse)")
    if not pairs:
        return []
    # deferred: matplotlib and VTK (viz), only for --animate
    from viz.render_check import check_offscreen, check_offscreen_beside

    # the offscreen probe (a subprocess, ≈ 1.4 s) runs while VTK is imported and the runs are read: the animation
    # waits for its answer before its first render (viz.animate's require_offscreen)
    check_offscreen_beside()
    try:
        from viz.results import study_cage_animation  # deferred: as above
    except ImportError as exc:   # pragma: no cover - viz integration missing
        print(f"animation skipped: {exc}")
        return []
    paths = []
    for c, f, r in pairs:
        try:
            paths.append(Path(study_cage_animation(f, r, out / f"{point_tag(c)}_cage_orbits.gif", max_frames=150)))
        except RuntimeError:
            ok, msg = check_offscreen()
            if ok:              # the animation's own error, not the machine's rendering
                raise
            print(f"animation skipped: {msg}")
            return paths
    return paths


class PaperStudy(Study):
    """Forward vs reverse per condition (:class:`scenarios.core.study.Study`): the comparison table first, then its
    files, the figures and (``--animate``) the cage-orbit animations. A run that fails now but finished before
    keeps its summary in the tables."""

    keep_earlier = True
    record = False

    def config(self) -> RunConfig:
        return build_config(self.a)

    def cases(self) -> list[Case]:
        return make_cases(self.a, self.out)

    def beside(self, cfg: RunConfig) -> Beside | None:
        """A dynamic study draws each point's figures (and animation) as soon as both its runs are in, in pieces on
        the workers while the other points run, and the figures across the points once every run is in, beside the
        last point's; the report is left with the tables. One point (the demo) has its pieces drawn side by side on
        the workers its two runs leave free; one point on one worker, or of one run, has nothing to draw beside (its
        figures wait for its runs either way: the report draws them, after the headline)."""
        cases = self.cases()
        if cfg.mode == "static" or (len({c.condition for c in cases}) < 2 and (self.a.workers == 1 or len(cases) < 2)):
            return None
        out, animation = self.out, bool(self.a.animate)
        machine = self.machine_identity()["label"]

        def task(c, outcomes):
            if not all(o.ok for o in outcomes.values()):    # a failed run: the report draws what it can
                return None
            results = {label: Summary.of(o.summary) for label, o in outcomes.items()}
            # in pieces, each on a worker: the last point's figures do not wait on one worker while the other idles;
            # the animation, the longest piece, first
            return [(point_work, (results, out, c, piece)) for piece in ((("animation",) if animation else ())
                                                                         + POINT_PIECES)]

        def last(outcomes):
            """The figures across the points, beside the last point's, once every run is in (a failed run: the
            report draws them, with the earlier results it keeps)."""
            if not all(o.ok for o in outcomes.values()):
                return None
            results = {label: Summary.of(o.summary) for label, o in outcomes.items()}
            return [(across_figures, (results, out, machine, (piece,))) for piece in ACROSS_PIECES]

        return Beside(key=lambda case: case.condition, task=task, last=last)

    def machine_identity(self) -> dict:
        over = {k: v for k, v in args.parse_sets(self.a.set).items() if not k.startswith("operating.")}
        if self.a.planets is not None:
            over["gears.planets"] = self.a.planets
        return machine_identity(self.a.params, over)

    def report(self, run: StudyRun) -> dict:
        results = run.results
        relative_life(results)
        for label, s in results.items():   # store the relative life in each run's summary (atomic rewrite)
            if "stale_after_failure" not in s:
                write_summary(run.outcomes[label].case.out_dir, s)
        static = getattr(self.a, "mode", "dynamic") == "static"
        rows = comparison_rows(results)
        if static:         # a quantity only a dynamic run gives is not in the tables at all (not a row of dashes)
            rows = [r for r in rows if r["forward"] is not None or r["reverse"] is not None]
        machine = self.machine_identity()
        csv_p, md_p, text = write_tables(rows, self.out, machine)
        doubts = meaningless(results)
        if doubts:          # a headline of runs whose statistics mean nothing is not a finding: said above it
            text = f"**Not a finding**: {doubts}.\n\n" + text
            atomic_write_text(md_p, text)
        print(("\nnot a finding: " + doubts + "\n" if doubts else "\n") + headline_table(rows))   # the headline first
        print("\n" + text)
        if static:
            # what a static solution cannot give (components.static.DYNAMIC_ONLY), not what a failed run left empty
            left = sorted(q for q, _ in QUANTITIES if q.startswith(DYNAMIC_ONLY))
            print(f"static mode ({self.a.snapshots} snapshots): left out, as only a dynamic run gives them: "
                  f"{', '.join(left)}; no time histories, cage orbits, bars of RMS values or animation")
            print(f"note: {STATIC_LIVES_NOTE}")
            atomic_write_text(md_p, text + f"\nNote: {STATIC_LIVES_NOTE}.\n")
        run.step("tables", lambda: [csv_p, md_p])
        # figures made beside the runs: each point's, and those across the points (key ALL)
        made = {c: v for c, v in run.beside.items() if isinstance(v, list)}
        for c, v in run.beside.items():
            if not isinstance(v, list) and v is not None:
                what = "across the points" if c is ALL else f"of {_title(c).lower()}"
                print(f"figures {what} beside the runs failed ({v}); drawn now")
        across_made = made.pop(ALL, None)
        early = [p for c in _conds(results) for p in made.get(c, [])] + (across_made or [])
        figs = run.step("figures beside the runs", lambda: [p for p in early if p.suffix != ".gif"]) if early else []
        anims = (run.step("animation beside the runs", lambda: [p for p in early if p.suffix == ".gif"])
                 if any(p.suffix == ".gif" for p in early) else [])
        left = [c for c in _conds(results) if c not in made]
        if static:
            figs += run.step("figures", static_plots, results, self.out, machine["label"])
        elif left or across_made is None:       # what was not drawn beside the runs (none, or a piece failed there)
            figs += run.step("figures", plots, results, self.out, machine["label"], drawn=set(made),
                             across=across_made is None)
        if self.a.animate and not static and left:
            anims += run.step("animation", animate, results, self.out, only=left)
        return {"rows": rows, "figures": figs, "animations": anims}


@holds_out_folder
def run(a) -> dict:
    return PaperStudy(a).run()


def finish(r: dict) -> int:
    """The exit code of a finished study: 1 if a run failed."""
    return Study.exit_code(r)


@command
def main(argv=None) -> int:
    return finish(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
