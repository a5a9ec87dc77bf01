"""Misalignment of the planet bearings in the full machine: the sliced ISO/TS 16281 life relative to the aligned
machine and the edge pressure against the pins' slope, per roller profile, with and without the carrier's wind-up.

    python -m scenarios.misalignment_study --conditions 1,3 --workers 2 --out results/misalignment

Every case is the quasi-static solution (components.static, ``--snapshots`` instants over a carrier revolution and
the mesh cycle) of the whole machine with sliced planet bearings (``bearing.model = "sliced"``, docs/model.md §8.8):
planets free to tilt against their face-sliced meshes (§6.6), rollers free to tilt in their radial–axial planes.
Every pin of the carrier, inner and outer, is sloped by γ (``errors.pin_slope``) in one direction measured from its
planet's radial line: ``radial`` (0°) or ``tangential`` (90°); a negative γ slopes it the opposite way. With
``--windup on`` the carrier's wind-up (``gears.carrier_windup``: the carrier torque twists its plates, every pin
sloping tangentially, the sense set by the torque's) adds to it; a γ of each sign with the wind-up on is the pin error
that the wind-up adds to in one direction of rotation and takes from in the other. ``--pins`` adds elastic pins
(``bearing.pin``: a beam clamped in both carrier plates, or in one) that bend under their bearings' loads. The planet
follows its pin by the share its meshes leave it, so its bearing sees less than γ: the slope it sees
(``misalignment_mean_rad``) is reported with the life.

The life is the reference bearing's (pair 1) sliced ISO/TS 16281 life from the static solution's mean loads
(``life_iso16281_sliced_h``), relative to the same machine (condition, direction, profile) aligned, i.e. γ = 0, no
wind-up and rigid pins; the edge pressure ratio is its largest end-slice pin pressure over its largest middle-slice one.
``--mode dynamic`` makes every case a dynamic run instead (the life from the window's slice loads, the edge ratio the
window's largest; docs/model.md §13).

Writes ``misalignment.csv`` and ``misalignment.md`` (a row per case and bearing type), ``life_against_slope.png``
(L/L0 against γ per profile) and ``answer.md`` (the answer in words, also printed); each case's summary.json.
"""
from __future__ import annotations

import argparse
import csv
import io
import math
import sys
from functools import partial
from pathlib import Path

from components.params import with_overrides
from components.presets import reference_dpgt
from components.profiles import PROFILES
from components.results.io import atomic_write_text
from components.sliced_bearing import ARCMIN
from components.static import DEFAULT_SNAPSHOTS
from components.units import ParameterError

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.points import file_overrides, point_order, point_words
from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.sweep import Case, user_overrides

__all__ = ["main", "run", "SLOPES", "PINS", "COLUMNS", "EDGE_AT", "SHOWN_AT", "make_cases", "rows_of", "answer"]

SLOPES = {"radial": 0.0, "tangential": 90.0}      # the slope's direction from the planet's radial line [deg]
WINDUP = ("off", "on")
PINS = ("rigid", "both_plates", "one_plate")      # rigid, or elastic (bearing.pin.model) in this mounting
EDGE_AT = 4.0                                     # arcmin: the slope at which the answer gives the edge pressure ratio
SHOWN_AT = (2.0, 4.0, 6.0, 10.0)                  # arcmin: the slopes the answer gives the life at
SNAPSHOTS = 2       # instants per case: the relative life compares the same instants, aligned and sloped (see --help)
COLUMNS = ["condition", "direction", "profile", "pins", "windup", "slope", "gamma_arcmin", "bearing", "load_N",
           "seen_slope_arcmin", "seen_share", "life_sliced_h", "life_aligned_h", "life_relative", "edge_pressure_ratio",
           "contact_pressure_max_Pa", "slice_load_max_pin_N", "life_unsliced_h"]
OWNED = {"bearing.model": "this study (sliced)", "bearing.profile.shape": "--profiles",
         "gears.carrier_windup": "--windup", "errors.pin_slope": "--gammas and --slopes",
         "bearing.pin.model": "--pins", "bearing.pin.mounting": "--pins"}

EXAMPLES = ["{prog} --conditions 1,3 --workers 2 --out results/misalignment",
            "{prog} --conditions 3 --gammas 4 --slopes radial --profiles straight --windup off --directions forward",
            "{prog} --gammas=-4,4 --slopes tangential --windup on --set bearing.slicing.slices=21",
            "{prog} --gammas=-4,4 --slopes tangential --windup off,on --pins rigid,one_plate --profiles straight",
            "{prog} --mode dynamic --window 0.0071 --conditions 3 --directions forward --gammas 4 --slopes tangential "
            "--out results/misalignment_dynamic"]
WRITES = ("{label}/summary.json per case (c{condition}_{direction}_{profile}[_{pins}]_w{off|on}_{aligned | slope γ}); "
          "misalignment.csv and misalignment.md (a row per case and bearing type: the slope the bearing sees, the "
          "sliced life and its ratio to the aligned machine's, the edge pressure ratio, the peak pressure); "
          "life_against_slope.png; answer.md (the answer in words, also printed); study.json")


def _gammas(text: str) -> list[float]:
    try:
        g = [float(x) for x in str(text).split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"takes a comma list of slopes in arcmin, got {text!r}") from None
    if not g or any(not math.isfinite(x) for x in g) or len(set(g)) != len(g):
        raise argparse.ArgumentTypeError(f"takes a comma list of distinct finite slopes in arcmin, got {text!r}")
    return sorted(set(g) | {0.0})


def parse_args(argv):
    p = args.parser("misalignment_study", __doc__, examples=EXAMPLES, writes=WRITES, out="results/misalignment")
    p.add_argument("--gammas", default=[0.0, 2.0, 4.0, 6.0, 10.0], type=_gammas, metavar="G[,G...]",
                   help="pin slopes γ in arcmin (default 0,2,4,6,10; negative: the opposite sense, written "
                        "--gammas=-4,4; 0 is always added: the lives are relative to it)")
    p.add_argument("--slopes", default="radial,tangential", type=args.choice_list(tuple(SLOPES), "slope direction"),
                   help="directions of the pin slope from the planet's radial line (default radial,tangential)")
    p.add_argument("--profiles", default="straight,iso_16281", type=args.choice_list(PROFILES, "profile"),
                   help="roller profiles (default straight,iso_16281; also logarithmic, crowned, table; their "
                        "parameters: bearing.profile.*)")
    p.add_argument("--windup", default="off", type=args.choice_list(WINDUP, "wind-up"),
                   help="carrier wind-up off, on or off,on (default off; gears.carrier_torsional_stiffness, "
                        "gears.carrier_plate_span; the aligned machine without it, the reference of L/L0, is always "
                        "run)")
    p.add_argument("--pins", default="rigid", type=args.choice_list(PINS, "pin model"),
                   help="the pins: rigid, both_plates (elastic, clamped in both carrier plates) and/or one_plate "
                        "(elastic, a cantilever from the shaft-side plate) (default rigid; bearing.pin.*; the rigid "
                        "aligned machine, the reference of L/L0, is always run)")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--snapshots", type=args.count(1), default=SNAPSHOTS, metavar="N",
                   help=f"static solutions per case over a carrier revolution and the mesh cycle (default {SNAPSHOTS}: "
                        "the relative life compares the same instants aligned and sloped; the machine's own default "
                        f"is {DEFAULT_SNAPSHOTS})")
    p.add_argument("--mode", default="static", choices=("static", "dynamic"),
                   help="static: each case the machine's quasi-static solution (default); dynamic: each case a "
                        "dynamic run (HHT, the statistics over --window after --settle; the life from the window's "
                        "equivalent slice loads, the edge ratio the window's largest, docs/model.md §13)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03,
                   help="dynamic mode: seconds discarded after the start (default 0.03: load ramp and transients)")
    p.add_argument("--start", default="kinematic", choices=("kinematic", "static"),
                   help="dynamic mode: start from the kinematic state with the torque ramped in (default), or from "
                        "the static solution at the ramp's end (the sloped machine at rest in its frame: no tilt "
                        "transient from the start)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="dynamic mode: seconds analysed (default: the runner's, at least 0.02 s and a carrier "
                        "revolution in whole cage revolutions; the statistics rules ask for one cage revolution "
                        "relative to the carrier at least, 7.0 ms at condition 3)")
    args.add_shared(p, "conditions", "params", "set", "out", "overwrite", "force", "no-progress", "workers",
                    "scheduler", out="results/misalignment", conditions="1,3",
                    conditions_why="1 and 3: the highest torque (the largest wind-up) and the fastest loaded "
                                   "condition (1000 and 4200 rpm at 200 kW)")
    return p.parse_args(argv)


def _tag(profile: str, windup: str, slope: str | None, gamma: float, pins: str = "rigid") -> str:
    head = profile if pins == "rigid" else f"{profile}_{pins}"
    if gamma == 0.0:
        return f"{head}_w{windup}_aligned"
    return f"{head}_w{windup}_{slope}{'m' if gamma < 0 else ''}{abs(gamma):g}am"


def pin_overrides(pins: str) -> dict:
    """The ``bearing.pin`` overrides of a ``--pins`` choice (rigid: none, the default)."""
    return {} if pins == "rigid" else {"bearing.pin.model": "elastic", "bearing.pin.mounting": pins}


def pin_slopes(planets: list[str], gamma: float, slope: str) -> list[dict]:
    """``errors.pin_slope`` entries sloping every pin by ``gamma`` [arcmin] in the direction ``slope`` from its planet's
    radial line (a negative γ: the opposite sense, 180° on)."""
    chi = SLOPES[slope] + (180.0 if gamma < 0 else 0.0)
    return [{"planet": p, "slope": f"{abs(gamma):g} arcmin", "direction": f"{chi:g} deg"} for p in planets]


def _planets(params) -> list[str]:
    n = len(params.si().layout.centres_a)
    return [f"{k}{i + 1}" for k in "ab" for i in range(n)]


def make_cases(a, out: Path) -> list[Case]:
    """Every condition × direction × profile × pins × wind-up, aligned and at every γ ≠ 0 in every slope direction
    (and the rigid, aligned machine without wind-up: the reference)."""
    sets = args.parse_sets(a.set)
    user = user_overrides(sets, a.params, OWNED)
    cases = []
    for c in [int(x) for x in a.conditions.split(",")]:
        for d in [x for x in a.directions.split(",") if x]:
            try:
                base = build_base(c, d, a.params, user)
            except ParameterError as exc:
                raise SystemExit(f"error: {exc}".splitlines()[0]) from None
            planets = _planets(base)
            for profile in a.profiles.split(","):
                for pins in dict.fromkeys(["rigid", *a.pins.split(",")]):
                    for w in dict.fromkeys(["off", *a.windup.split(",")]):
                        if pins in a.pins.split(",") and w in a.windup.split(","):
                            gammas = a.gammas
                        elif pins == "rigid" and w == "off":
                            gammas = [0.0]                  # the reference only
                        else:
                            continue
                        ov = {**user, "bearing.model": "sliced", "bearing.profile.shape": profile,
                              "gears.carrier_windup": w == "on", **pin_overrides(pins)}
                        for slope in a.slopes.split(","):
                            for g in gammas:
                                if g == 0.0 and slope != a.slopes.split(",")[0]:
                                    continue                # one aligned case serves every direction
                                tag = _tag(profile, w, slope, g, pins)
                                o = dict(ov)
                                if g != 0.0:
                                    o["errors.pin_slope"] = pin_slopes(planets, g, slope)
                                cases.append(Case(c, d, str(out / f"c{c}_{d}_{tag}"), o, a.params, tag=tag))
    return cases


def build_base(condition: int, direction: str, params_file: str | None, user: dict):
    base = reference_dpgt(condition, direction)
    if params_file:
        base = with_overrides(base, file_overrides(params_file))
    return with_overrides(base, user)


def _case_axes(case: Case) -> dict:
    o = case.overrides
    entries = o.get("errors.pin_slope") or []
    if entries:
        g = float(entries[0]["slope"].split()[0])
        chi = float(entries[0]["direction"].split()[0])
        slope = "radial" if chi % 180.0 == 0.0 else "tangential"
        gamma = g if chi < 180.0 else -g
    else:
        slope, gamma = "aligned", 0.0
    pins = o.get("bearing.pin.mounting", "rigid") if o.get("bearing.pin.model") == "elastic" else "rigid"
    return {"condition": case.condition, "direction": case.direction, "profile": o["bearing.profile.shape"],
            "pins": pins, "windup": "on" if o["gears.carrier_windup"] else "off", "slope": slope, "gamma_arcmin": gamma}


def rows_of(cases: list[Case], results: dict) -> list[dict]:
    """A row per finished case and bearing type (:data:`COLUMNS`); L/L0 against the case of the same condition,
    direction and profile with γ = 0, no wind-up and rigid pins (None where that case is missing)."""
    rows = []
    for case in cases:
        s = results.get(case.label)
        if s is None or s.failed:
            continue
        ax = _case_axes(case)
        for kind in ("inner", "outer"):
            d = s[kind]
            seen = d.get("misalignment_mean_rad")
            rows.append({**ax, "bearing": kind, "load_N": d.get("bearing_load_mean_N"),
                         "seen_slope_arcmin": None if seen is None else seen / ARCMIN,
                         "seen_share": (seen / (abs(ax["gamma_arcmin"]) * ARCMIN)
                                        if seen is not None and ax["gamma_arcmin"] != 0.0 else None),
                         "life_sliced_h": d.get("life_iso16281_sliced_h"),
                         "edge_pressure_ratio": d.get("edge_pressure_ratio"),
                         "contact_pressure_max_Pa": d.get("contact_pressure_max_Pa"),
                         "slice_load_max_pin_N": d.get("slice_load_max_pin_N"),
                         "life_unsliced_h": d.get("life_iso16281_h")})
    ref = {(r["condition"], r["direction"], r["profile"], r["bearing"]): r["life_sliced_h"] for r in rows
           if r["gamma_arcmin"] == 0.0 and r["windup"] == "off" and r["pins"] == "rigid"}
    for r in rows:
        L0 = ref.get((r["condition"], r["direction"], r["profile"], r["bearing"]))
        r["life_aligned_h"] = L0
        r["life_relative"] = r["life_sliced_h"] / L0 if L0 and r["life_sliced_h"] is not None else None
    order = {"aligned": 0, "radial": 1, "tangential": 2}
    pin_order = {p: i for i, p in enumerate(PINS)}
    rows.sort(key=lambda r: (point_order(r["condition"]), r["direction"], r["bearing"], r["profile"],
                             pin_order[r["pins"]], r["windup"], order[r["slope"]], r["gamma_arcmin"]))
    return rows


def _f(v, fmt: str) -> str:
    return "–" if v is None else format(v, fmt)


def table(rows: list[dict]) -> str:
    """The answer's table: per condition, direction, bearing, profile, wind-up and slope direction, L/L0 at the
    slopes of :data:`SHOWN_AT` (those run), the slope the bearing sees at 4′ and the edge pressure ratio there."""
    gammas = sorted({r["gamma_arcmin"] for r in rows if r["gamma_arcmin"] != 0.0})
    head = ["condition", "direction", "planet", "profile", "pins", "wind-up", "slope", "L0 [h]", "L/L0 γ=0"] + \
        [f"L/L0 {g:g}′" for g in gammas] + [f"seen/γ {EDGE_AT:g}′", f"edge p ratio {EDGE_AT:g}′"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    groups: dict = {}
    for r in rows:
        k = (r["condition"], r["direction"], r["bearing"], r["profile"], r["pins"], r["windup"])
        groups.setdefault(k, []).append(r)
    for k, rr in groups.items():
        zero = next((r for r in rr if r["gamma_arcmin"] == 0.0), None)
        for slope in [s for s in SLOPES if any(r["slope"] == s for r in rr)]:
            by_g = {r["gamma_arcmin"]: r for r in rr if r["slope"] == slope}
            e = by_g.get(EDGE_AT)
            cells = [str(k[0]), k[1], k[2], k[3], k[4], k[5], slope, _f(zero and zero["life_aligned_h"], ".4g"),
                     _f(zero and zero["life_relative"], ".3f")]
            cells += [_f(by_g[g]["life_relative"], ".3f") if g in by_g else "–" for g in gammas]
            cells += [_f(e and e["seen_share"], ".3f"), _f(e and e["edge_pressure_ratio"], ".3f")]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def answer(rows: list[dict], mode: str = "static") -> str:
    """The question in plain words: how much life a pin slope costs each bearing type, per profile, forward and
    reverse, what share of the slope the bearing sees, and what the wind-up and elastic pins add."""
    how = "quasi-static" if mode == "static" else "dynamic runs"
    lines = [f"Life of the planet bearings against the pins' slope γ, full machine ({how}, planets and rollers "
             "free to tilt). L/L0: the reference bearing's sliced ISO/TS 16281 life over the same machine's aligned "
             "(γ = 0, no wind-up, rigid pins); seen: the slope the bearing sees (pin against bore) over γ; edge: "
             f"end-slice over middle-slice pin pressure at {EDGE_AT:g}′.", ""]
    key = lambda r: (r["condition"], r["direction"], r["bearing"], r["profile"], r["pins"], r["windup"],  # noqa: E731
                     r["slope"])
    groups: dict = {}
    for r in rows:
        groups.setdefault(key(r), {})[r["gamma_arcmin"]] = r
    for (c, d, b, prof, pins, w, slope), by_g in groups.items():
        pw = "" if pins == "rigid" else f", {pins.replace('_', ' ')} elastic pins"
        if slope == "aligned":
            r = by_g[0.0]
            if w == "on" or pins != "rigid":
                alone = " and ".join(x for x in ("the wind-up" if w == "on" else "", pw[2:]) if x)
                lines.append(f"{point_words(c)}, {d}, {b}, {prof}: {alone} alone: L/L0 "
                             f"{_f(r['life_relative'], '.3f')}, seen {_f(r['seen_slope_arcmin'], '.2f')}′, edge "
                             f"{_f(r['edge_pressure_ratio'], '.3f')}")
            continue
        parts = [f"{g:g}′ {_f(by_g[g]['life_relative'], '.3f')}" for g in sorted(by_g)]
        e = by_g.get(EDGE_AT)
        extra = (f"; at {EDGE_AT:g}′ seen {_f(e['seen_share'], '.2f')} of γ, edge "
                 f"{_f(e['edge_pressure_ratio'], '.3f')}" if e else "")
        lines.append(f"{point_words(c)}, {d}, {b}, {prof}{pw}, wind-up {w}, {slope}: L/L0 " + ", ".join(parts)
                     + extra)
    return "\n".join(lines)


def write_tables(rows: list[dict], out: Path, machine: str = "", mode: str = "static") -> list[Path]:
    head = [f"Machine: {machine}", ""] if machine else []
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS)
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "misalignment.csv", buf.getvalue())
    atomic_write_text(out / "misalignment.md", "\n".join(head + [table(rows)]) + "\n")
    atomic_write_text(out / "answer.md", "\n".join(head + [answer(rows, mode)]) + "\n")
    return [out / "misalignment.csv", out / "misalignment.md", out / "answer.md"]


def plot(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """life_against_slope.png: L/L0 against γ, a panel per condition and slope direction and bearing type, a line per
    profile, direction and wind-up."""
    from viz.plots import life_against_misalignment   # deferred: matplotlib only when the figures are drawn
    rows = [r for r in rows if r["pins"] == "rigid"]   # the figure: rigid pins (elastic ones: the tables)
    return [life_against_misalignment(rows, out / "life_against_slope.png",
                                      title="Planet bearing life against the pins' slope, full machine (quasi-static)"
                                            + (f" — {machine}" if machine else ""))]


class MisalignmentStudy(Study):
    """Every condition × direction × profile × wind-up × slope (:class:`scenarios.core.study.Study`), each the
    machine's quasi-static solution: the answer first, then the tables and the figure."""

    def config(self) -> RunConfig:
        if self.a.mode == "dynamic":
            return RunConfig(settle=self.a.settle, window=self.a.window, start=self.a.start,
                             progress=not self.a.no_progress)
        return RunConfig(mode="static", snapshots=self.a.snapshots, progress=not self.a.no_progress)

    def cases(self) -> list[Case]:
        return make_cases(self.a, self.out)

    def report(self, run: StudyRun) -> dict:
        return self.table_report(run, rows_of(run.cases, run.results), partial(answer, mode=self.a.mode),
                                 partial(write_tables, mode=self.a.mode), plot)


@holds_out_folder
def run(a) -> dict:
    return MisalignmentStudy(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
