"""Do the planet bearings skid? Cage slip against load and oil temperature, forward and reverse, held against the
bearing's catalogue minimum load.

    python -m scenarios.skidding_study [--speed "1000 rpm"] [--powers 2,20,200] [--oil-temperatures 40,80]
        [--oil VG32,VG68,VG150] [--directions forward,reverse] [--settle S] [--window S]
        [--transients startup,torque_drop [--ramp-time S] [--start-speed F] [--drop-time S] [--before S]
         [--after S] [--bin S] [--within PCT]]
        [--set KEY=VALUE ...] [--params FILE] [--workers N | --scheduler ADDR] [--out DIR]

Every output power × oil temperature (× ISO VG grade with ``--oil``: folders ``…_VG32``) × direction at one carrier
speed runs through the one runner (resumable, on
Dask like the other studies) with the laws that decide whether a lightly loaded roller set is driven or slides:
the EHL traction with its limiting shear (``bearing.traction_law = "ehl"``, docs/model.md §9.3), the film's rolling
resistance (``bearing.rolling_resistance = "houpert"``, §9.5) and the viscous churning of the oil–air mixture
(``bearing.drag_law = "viscous"``, §8.7); ``--set`` changes any of them (e.g. ``--set bearing.traction_law=tanh``)
or anything else of the machine (clearance, cage guidance, oil).

``--transients`` runs transients instead of the grid, each at every oil temperature × direction, through the
operating point's schedule (``operating.schedule``, docs/model.md §10.3), with the steady run at its final point
beside it (the grid's run of that point: the same folder, reused when it is there):

* ``startup``: the carrier held at ``--start-speed`` × ``--speed`` for ``--settle`` + ``--before``, then ramped
  linearly to ``--speed`` in ``--ramp-time``, the sun torque following the square of the speed up to the largest of
  ``--powers`` (the load a wind turbine's generator takes below rated speed, k ω², and the fan-and-pump law of an
  industrial drive; the torque at the start is ``--start-speed``² of it);
* ``torque_drop``: running at the largest of ``--powers``, the torque falls to the smallest in ``--drop-time``.

Each is recorded from ``--before`` ahead of the change to ``--after`` past its end. Writes ``transients.csv`` /
``transients.md`` (per transient, oil, direction, bearing type and series — cage, rollers out of the load zone, at
its entry: the slip before the change, its peak and when, its final and the steady run's value (the mean of its
recording's series, the same estimator; its summary's, taken on every step, beside), the time to settle within
``--within`` % of the steady value (at least one slip point) and the times to go 50, 63 and 90 % of the way),
``slip_transients.png`` (the slips against time in bins of ``--bin``, the speed and torque schedule on a second
axis) and ``transients_answer.md`` (printed).

Writes ``summary.csv`` / ``summary.md`` (a row per run and bearing type: the mean bearing load and the catalogue
minimum load 0.02 C_r with the load over it, cage slip of the reference bearing and of all bearings of the type,
the rollers' slip in the load zone, out of it and at its entry with the slide-to-roll ratio there and the
frictional power density p·Δv at entry and its largest (every bearing of the type pooled: summary.json's, docs/model.md
§13.5), traction coefficient, film parameter, heat of traction and land), ``slip_against_load.png`` (cage slip, roller slip out of the load zone and at its entry,
and the film parameter against the load over the catalogue minimum, a marker per oil temperature),
``roller_slip_by_angle.png`` (the rollers' slip and the share loaded against their angle about the pin from the
planet's radial direction, at the coldest oil, a marker per power) and the answer in words
(``answer.md``, printed): per oil temperature and direction each bearing type's cage slip from the lightest to
the heaviest load, whether a cage skids (more than :data:`SKID_PCT` % below its rolling speed) and how the slip
moves with load and with the oil's temperature.
"""
from __future__ import annotations

import csv
import io
import sys
from pathlib import Path

import numpy as np

import mbd
from components.presets import OIL_GRADES, oil_grade
from components.results import RESULTS_NAME, read_results
from components.results.io import atomic_write_text
from components.skid import (SERIES, SERIES_VARIABLES, SKID_PCT, ZONE_VARIABLES, roller_slip_zones, slip_series,
                             transient_numbers)

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.points import checked_point, machine_overrides, parse_point, point_label
from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.sweep import Case, build_params, user_overrides

__all__ = ["main", "run", "LAWS", "COLUMNS", "SKID_PCT", "make_cases", "rows_of", "answer", "TRANSIENTS",
           "transient_schedule", "make_transient_cases", "transient_rows", "TRANSIENT_COLUMNS"]

# the laws this study runs with unless --set says otherwise: traction with a limiting shear, the film's rolling
# resistance and viscous churning (docs/model.md §9.3, §9.5, §8.7)
LAWS = {"bearing.traction_law": "ehl", "bearing.rolling_resistance": "houpert", "bearing.drag_law": "viscous"}
COLUMNS = ["power_kW", "oil_temperature_C", "oil_grade", "direction", "bearing", "bearing_load_mean_N", "minimum_load_N",
           "load_over_minimum", "cage_slip_pct", "cage_slip_all_pct", "roller_slip_load_zone_pct",
           "roller_slip_unloaded_pct", "roller_slip_entry_pct", "roller_entry_slide_roll", "smearing_pv_entry_W_m2",
           "smearing_pv_max_W_m2", "traction_coefficient_max", "lambda_min", "heat_traction_W", "heat_land_W"]
_NUMBERS = COLUMNS[5:]
MACHINE_OIL = "machine"    # the oil_grade of a run with the machine's own oil (no --oil)

EXAMPLES = ["{prog} --out results/skidding",
            "{prog} --transients startup,torque_drop --oil-temperatures 40 --directions forward", '{prog} --speed "1500 rpm" --powers 0,5,50 --oil-temperatures 30,60,90',
            "{prog} --set bearing.clearance=40um --directions forward --workers 2",
            "{prog} --powers 2 --oil VG32,VG150 --directions forward"]
WRITES = ("p{power}kW_oil{T}C_{direction}/{results.nc, summary.json} per run; summary.csv and summary.md (a row per "
          "run and bearing type: load and catalogue minimum load, cage slip, traction, film, heat); answer.md (the "
          "answer in words, also printed); slip_against_load.png, roller_slip_by_angle.png; study.json; with "
          "--transients: p{power}kW_oil{T}C_{direction}_{transient}/ per transient run, transients.csv, transients.md, "
          "transients_answer.md, slip_transients.png")


def _numbers(unit: str):
    """A non-empty comma list of numbers ≥ 0 [unit] (a usage error naming the option otherwise)."""
    one = args.nonnegative(unit)

    def conv(text):
        return [one(x) for x in str(text).split(",") if x.strip()] or one("")
    return conv


def parse_args(argv):
    p = args.parser("skidding_study", __doc__, examples=EXAMPLES, writes=WRITES, out="results/skidding")
    p.add_argument("--speed", default="1000 rpm", type=args.quantity_of("angular_velocity", positive_only=True),
                   help='carrier speed (default "1000 rpm")')
    p.add_argument("--powers", default=[2.0, 20.0, 200.0], type=_numbers("kW"),
                   help="output powers [kW], comma list >= 0 (default 2,20,200; 0: no load)")
    p.add_argument("--oil-temperatures", default=[40.0, 80.0], type=_numbers("°C"),
                   help="oil temperatures [°C], comma list (default 40,80)")
    p.add_argument(args.OIL, default=None, type=args.choice_list(tuple(OIL_GRADES), "ISO VG grades"), metavar="VG[,VG...]",
                   help=f"comma list of ISO VG grades ({', '.join(OIL_GRADES)}), each run at every oil temperature "
                        "(default: the machine's own oil)")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None, help="statistics window [s] (default: the study's rule)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=2000.0, help="recording rate [Hz] (statistics use every step)")
    p.add_argument("--transients", default=None, type=args.choice_list(TRANSIENTS, "transients"),
                   help="comma list of startup, torque_drop: run these transients instead of the grid")
    p.add_argument("--ramp-time", type=args.positive("s"), default=0.2, help="startup: the speed ramp's length (default 0.2)")
    p.add_argument("--start-speed", type=args.positive("", upper=1.0), default=0.1,
                   help="startup: the speed it starts from, a fraction of --speed (default 0.1)")
    p.add_argument("--drop-time", type=args.positive("s"), default=0.002, help="torque_drop: the fall's length (default 0.002)")
    p.add_argument("--before", type=args.nonnegative("s"), default=0.02,
                   help="transients: recorded before the change, after --settle (default 0.02)")
    p.add_argument("--after", type=args.positive("s"), default=0.4, help="transients: simulated after the change (default 0.4)")
    p.add_argument("--bin", type=args.positive("s"), default=0.01, help="transients: the slip series' bins (default 0.01)")
    p.add_argument("--within", type=args.positive("%"), default=10.0,
                   help="transients: settled within this %% of the steady slip, at least 1 slip point (default 10)")
    args.add_shared(p, "params", "set", "out", "overwrite", "force", "no-progress", "workers", "scheduler",
                    out="results/skidding")
    return p.parse_args(argv)


TRANSIENTS = ("startup", "torque_drop")
SETTLE_FLOOR_PCT = 1.0     # a bin's mean slip scatters by about a slip point (the settling band's floor)
_START_KNOTS = 4           # the start-up's torque ∝ speed² in this many linear pieces (0.3 % of the torque off at most
                           # with the default 0.1 start: (Δs)²/4 of a piece Δs = 0.225)


def transient_schedule(kind: str, a) -> tuple[list[dict], float, float]:
    """The operating point's schedule (``operating.schedule`` knots) of a transient, the time of its change [s] and
    the change's length [s] (see the module's text)."""
    t0 = a.settle + a.before
    if kind == "startup":
        s0 = a.start_speed
        knots = []
        for k in range(_START_KNOTS + 1):
            sp = s0 + (1.0 - s0) * k / _START_KNOTS
            knots.append({"time": f"{t0 + a.ramp_time * k / _START_KNOTS!r} s", "speed": sp, "torque": sp * sp})
        return knots, t0, a.ramp_time
    if kind == "torque_drop":
        lo, hi = min(a.powers), max(a.powers)
        if not hi > 0:
            raise SystemExit("skidding_study: --transients torque_drop needs a power > 0 in --powers")
        return ([{"time": f"{t0!r} s", "speed": 1.0, "torque": 1.0},
                 {"time": f"{t0 + a.drop_time!r} s", "speed": 1.0, "torque": lo / hi}], t0, a.drop_time)
    raise ValueError(f"unknown transient {kind!r}")


def _point_case(a, out: Path, P: float, T: float, d: str, extra: dict | None = None, **kw) -> Case:
    sets = args.parse_sets(a.set)
    owned = {"operating.carrier_speed": "--speed", "operating.output_power": "--powers",
             "lubricant.temperature": "--oil-temperatures", "operating.schedule": "--transients"}
    point = checked_point(parse_point(f"p{P:g}kW_oil{T:g}C: {a.speed}, {P:g} kW, oil {T:g} degC",
                                      where="--powers"), "--powers")
    user = {**LAWS, **machine_overrides(user_overrides(sets, a.params, owned), [point]), **(extra or {})}
    label = point_label(point, d) + (f"_{kw['tag']}" if kw.get("tag") else "")
    return Case.at(point, d, str(out / label), user, a.params, **kw)


def make_transient_cases(a, out: Path) -> list[Case]:
    """Per transient (``--transients``) × oil temperature × direction: the transient's case (tag: its name, its
    window from ``--before`` to ``--after`` past the change) and the steady case at its final point (the grid's)."""
    kinds = [k for k in str(a.transients).split(",") if k]
    if _grades(a) != [None]:
        raise SystemExit(f"skidding_study: {args.OIL} spans the grid; a transient runs the machine's oil "
                         f"(--set lubricant.viscosity_40=… for another)")
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    hi, lo = max(a.powers), min(a.powers)
    cases, steady = [], {}
    for kind in kinds:
        knots, t0, length = transient_schedule(kind, a)
        for T in a.oil_temperatures:
            for d in dirs:
                cases.append(_point_case(a, out, hi, T, d, {"operating.schedule": knots}, tag=kind,
                                         window=a.before + length + a.after))
                final = hi if kind == "startup" else lo
                c = _point_case(a, out, final, T, d)
                steady.setdefault(c.label, c)
    return cases + list(steady.values())


def make_cases(a, out: Path) -> list[Case]:
    """Every power × oil temperature × direction at the carrier speed ``--speed``, each an operating point
    (:mod:`scenarios.core.points`) of the machine with :data:`LAWS` (a ``--set`` of a law replaces it)."""
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    powers, temps = a.powers, a.oil_temperatures
    sets = args.parse_sets(a.set)
    owned = {"operating.carrier_speed": "--speed", "operating.output_power": "--powers",
             "lubricant.temperature": "--oil-temperatures"}
    grades = _grades(a)
    if grades != [None]:
        owned.update({"lubricant.viscosity_40": args.OIL, "lubricant.viscosity_100": args.OIL})
    cases = []
    for P in powers:
        for T in temps:
            for g in grades:
                name = f"p{P:g}kW_oil{T:g}C" + (f"_{g}" if g else "")
                point = checked_point(parse_point(f"{name}: {a.speed}, {P:g} kW, oil {T:g} degC",
                                                  where="--powers"), "--powers")
                user = {**LAWS, **machine_overrides(user_overrides(sets, a.params, owned), [point]),
                        **(oil_grade(g) if g else {})}
                for d in dirs:
                    cases.append(Case.at(point, d, str(out / point_label(point, d)), user, a.params))
    return cases


def _grades(a) -> list:
    """The ``--oil`` grades, or [None]: the machine's own oil."""
    oil = getattr(a, "oil", None)
    return [g.strip() for g in oil.split(",") if g.strip()] if oil else [None]


def grade_of(case: Case) -> str:
    """The case's ISO VG grade (its point's name ends in it), or :data:`MACHINE_OIL`."""
    tail = str(case.point["name"]).rsplit("_", 1)[-1]
    return tail if tail in OIL_GRADES else MACHINE_OIL


def _power_and_oil(case: Case) -> tuple[float, float]:
    p = case.point
    return float(p["load"].split()[0]), float(p["oil_temperature"].split()[0])


def rows_of(cases: list[Case], results: dict) -> list[dict]:
    """A row per finished run and bearing type (:data:`COLUMNS`): its summary's numbers, and for the figure its
    rollers' slip by angle about the pin from its recording (:func:`components.skid.roller_slip_zones`)."""
    rows = []
    for case in cases:
        s = results.get(case.label)
        if s is None or s.failed:
            continue
        P, T = _power_and_oil(case)
        zones = _roller_zones(case)
        for kind in ("inner", "outer"):
            d = s[kind]
            row = {"power_kW": P, "oil_temperature_C": T, "oil_grade": grade_of(case), "direction": case.direction,
                   "bearing": kind}
            row.update({c: d.get(c) for c in _NUMBERS})
            if kind in zones:        # by angle about the pin, for the figure (not a column)
                row["by_angle"] = {k: zones[kind][k] for k in ("angle_deg", "slip_by_angle_pct", "loaded_by_angle")}
            rows.append(row)
    return rows


def _roller_zones(case: Case) -> dict:
    """The rollers' slip by zone of a case's recording (none without one: a run whose results.nc was not kept)."""
    path = Path(case.out_dir) / RESULTS_NAME
    if not path.is_file():
        return {}
    return roller_slip_zones(read_results(path, ZONE_VARIABLES), build_params(case).si().bearing)


def answer(rows: list[dict]) -> str:
    """Per oil temperature, direction and bearing type: the cage slip from the lightest to the heaviest load with
    the load over the catalogue minimum, whether a cage skids, and the slip's trends with load and oil temperature."""
    lines = [f"Do the planet bearings skid? Cage slip [%] (+: the cage lags its rolling speed) at each load, the mean "
             f"bearing load over the catalogue minimum 0.02 C_r in brackets; skidding: |slip| > {SKID_PCT:g} %.", ""]
    key = lambda r: (r["oil_temperature_C"], r.get("oil_grade", MACHINE_OIL), r["direction"], r["bearing"])
    for k in sorted({key(r) for r in rows}, key=lambda k: (k[0], _viscosity(k[1]), k[2] != "forward", k[3])):
        rr = sorted((r for r in rows if key(r) == k), key=lambda r: r["power_kW"])
        pts = ", ".join(f"{r['power_kW']:g} kW {r['cage_slip_pct']:+.2f} ({r['load_over_minimum']:.2f})" for r in rr)
        rol = ", ".join(f"{r['power_kW']:g} kW {_pct(r.get('roller_slip_entry_pct'))} / "
                        f"{_pct(r.get('roller_slip_unloaded_pct'))}" for r in rr)
        skid = [r["power_kW"] for r in rr if abs(r["cage_slip_pct"]) > SKID_PCT]
        lines.append(f"oil {k[0]:g} °C{_grade_words(k[1])}, {k[2]}, {k[3]}: {pts}"
                     + (f" -> skids at {', '.join(f'{p:g}' for p in skid)} kW" if skid else " -> no skid")
                     + (f"; roller slip at load-zone entry / out of the load zone: {rol}"
                        if any(r.get("roller_slip_entry_pct") is not None for r in rr) else ""))
    lines.append("")
    for col, words in (("cage_slip_pct", "cage |slip|"), ("roller_slip_unloaded_pct", "roller slip out of the load zone")):
        for what, axis in (("load", "power_kW"), ("oil temperature", "oil_temperature_C"), ("oil grade", "grade_viscosity")):
            falls = rises = 0
            others = [c for c in ("power_kW", "oil_temperature_C", "grade_viscosity") if c != axis]
            at = lambda r, c: _viscosity(r.get("oil_grade", MACHINE_OIL)) if c == "grade_viscosity" else r[c]  # noqa: E731
            group = lambda r: (*(at(r, c) for c in others), r["direction"], r["bearing"])  # noqa: E731
            for k in {group(r) for r in rows}:
                rr = sorted((r for r in rows if group(r) == k and r.get(col) is not None), key=lambda r: at(r, axis))
                if len(rr) > 1:
                    lo, hi = abs(rr[0][col]), abs(rr[-1][col])
                    falls += hi < lo
                    rises += hi > lo
            if falls + rises:
                lines.append(f"{words} falls as the {what} rises in {falls} of {falls + rises} series, rises in {rises}.")
    return "\n".join(lines)


def _viscosity(grade: str) -> float:
    """The grade's viscosity at 40 °C [mm²/s] (its ISO VG number; the machine's own oil: 0, first in a sort)."""
    return float(grade[2:]) if grade in OIL_GRADES else 0.0


def _grade_words(grade: str) -> str:
    return "" if grade == MACHINE_OIL else f" {grade}"


def _pct(v) -> str:
    return "–" if v is None else f"{v:.1f} %"


def _cell(v) -> str:
    return "–" if v is None else f"{v:.4g}" if isinstance(v, float) else str(v)


def _write_row_tables(rows: list[dict], columns: list[str], out: Path, stem: str, answer_name: str, text: str,
                      machine: str) -> list[Path]:
    """``stem``.csv and ``stem``.md (a row per row, :data:`columns`) and the answer ``text`` in ``answer_name``, the
    markdown files headed by ``machine``."""
    head = [f"Machine: {machine}", ""] if machine else []
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / f"{stem}.csv", buf.getvalue())
    md = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    md += ["| " + " | ".join(_cell(r[c]) for c in columns) + " |" for r in rows]
    atomic_write_text(out / f"{stem}.md", "\n".join(head + md) + "\n")
    atomic_write_text(out / answer_name, "\n".join(head + [text]) + "\n")
    return [out / f"{stem}.csv", out / f"{stem}.md", out / answer_name]


def write_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """summary.csv, summary.md and answer.md (the markdown files headed by ``machine``)."""
    return _write_row_tables(rows, COLUMNS, out, "summary", "answer.md", answer(rows), machine)


def plot(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """slip_against_load.png: cage slip, roller slip out of the load zone and at its entry, and the film parameter
    against the mean bearing load over the catalogue minimum, forward vs reverse, a marker per oil temperature; and
    roller_slip_by_angle.png (:func:`_by_angle`)."""
    from viz.plots import against_viscosity  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    series = {}
    for key in ("cage_slip_pct", "roller_slip_unloaded_pct", "roller_slip_entry_pct", "lambda_min"):
        for r in sorted(rows, key=lambda r: r["load_over_minimum"]):
            k = (key, r["bearing"], r["direction"],
                 f"oil {r['oil_temperature_C']:g} °C{_grade_words(r.get('oil_grade', MACHINE_OIL))}")
            x, y = series.setdefault(k, ([], []))
            x.append(r["load_over_minimum"])
            y.append(r[key])
    return [against_viscosity(series, [("cage_slip_pct", "cage slip (+: lags)", "%", False),
                                       ("roller_slip_unloaded_pct", "roller slip out of the load zone", "%", False),
                                       ("roller_slip_entry_pct", "roller slip at load-zone entry", "%", False),
                                       ("lambda_min", "film parameter Λ_min", "1", True)],
                              out / "slip_against_load.png",
                              title="Cage and roller slip against the bearing load" + (f" — {machine}" if machine else ""),
                              levels={"cage_slip_pct": {SKID_PCT: f"{SKID_PCT:g} %: skidding above"}},
                              xaxis=("bearing load / catalogue minimum 0.02 C_r", None, 1.0))] + _by_angle(rows, out, machine)


def _by_angle(rows: list[dict], out: Path, machine: str) -> list[Path]:
    """roller_slip_by_angle.png: the rollers' slip and the share of them loaded on the pin against their angle about
    the pin from the planet's radial direction, at the coldest oil, forward vs reverse, a marker per power."""
    from viz.plots import against_viscosity  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    have = [r for r in rows if "by_angle" in r]
    if not have:
        return []
    cold = min(r["oil_temperature_C"] for r in have)
    series = {}
    for r in sorted(have, key=lambda r: r["power_kW"]):
        if r["oil_temperature_C"] != cold:
            continue
        a = r["by_angle"]
        for key, values in (("slip", a["slip_by_angle_pct"]), ("loaded", a["loaded_by_angle"])):
            series[(key, r["bearing"], r["direction"], f"{r['power_kW']:g} kW")] = (a["angle_deg"], values)
    return [against_viscosity(series, [("slip", "roller slip", "%", False),
                                       ("loaded", "share of the rollers loaded on the pin", "1", False)],
                              out / "roller_slip_by_angle.png",
                              title=f"Roller slip around the pin, oil {cold:g} °C" + (f" — {machine}" if machine else ""),
                              xaxis=("roller angle from the planet's radial line", "°", 1.0, False))]


TRANSIENT_COLUMNS = ["transient", "oil_temperature_C", "direction", "bearing", "series", "before_pct", "peak_pct",
                     "peak_after_s", "final_pct", "steady_pct", "steady_every_step_pct", "settle_s", "t50_s", "t63_s",
                     "t90_s"]
_STEADY_KEY = {"cage": "cage_slip_all_pct", "unloaded": "roller_slip_unloaded_pct", "entry": "roller_slip_entry_pct"}
_SERIES_WORDS = {"cage": "cage", "unloaded": "rollers out of the load zone", "entry": "rollers at load-zone entry"}


def transient_rows(cases: list[Case], results: dict, a) -> tuple[list[dict], list[dict]]:
    """A row per transient run, bearing type and series (:data:`TRANSIENT_COLUMNS`, times from the change), from its
    recording (:func:`components.skid.slip_series`, :func:`~components.skid.transient_numbers`) and the steady run
    at its final point (the mean of its recording's series, the same estimator; the summary's value on every step
beside it); and per transient run its binned series and schedule for the figure."""
    rows, series = [], []
    steady = {(_power_and_oil(c)[0], _power_and_oil(c)[1], c.direction): c for c in cases if not c.tag}
    hi, lo = max(a.powers), min(a.powers)
    for case in cases:
        s = results.get(case.label)
        if not case.tag or s is None or s.failed:
            continue
        path = Path(case.out_dir) / RESULTS_NAME
        if not path.is_file():
            continue
        _, T = _power_and_oil(case)
        knots, t0, length = transient_schedule(case.tag, a)
        ref_case = steady.get((hi if case.tag == "startup" else lo, T, case.direction))
        ref = None if ref_case is None else results.get(ref_case.label)
        ref_binned = _steady_series(ref_case, a.bin) if ref is not None and not ref.failed else {}
        binned = slip_series(read_results(path, SERIES_VARIABLES), a.bin)
        series.append({"transient": case.tag, "oil_temperature_C": T, "direction": case.direction, "change_s": t0,
                       "length_s": length, "knots": knots, "binned": binned})
        for kind in ("inner", "outer"):
            if kind not in binned:
                continue
            b = binned[kind]
            for name in SERIES:
                every = None if ref is None or ref.failed else ref[kind].get(_STEADY_KEY[name])
                rb = ref_binned.get(kind, {}).get(name)
                st = float(np.nanmean(rb)) if rb is not None and np.isfinite(rb).any() else None
                n = transient_numbers(b["time_s"], b[name], t0, st, a.within, SETTLE_FLOOR_PCT)
                rows.append({"transient": case.tag, "oil_temperature_C": T, "direction": case.direction,
                             "bearing": kind, "series": name, "before_pct": n["before"], "peak_pct": n["peak"],
                             "peak_after_s": n["peak_after_s"], "final_pct": n["final"], "steady_pct": n["steady"],
                             "steady_every_step_pct": every,
                             "settle_s": n["settle_s"], "t50_s": n["t50_s"], "t63_s": n["t63_s"], "t90_s": n["t90_s"]})
    return rows, series


def _steady_series(case: Case | None, bin_s: float) -> dict:
    """The steady run's slip series from its recording (the transient's own estimator: its mean is the value a settled
    transient is held to; the summary's, taken on every step, is beside it in the table)."""
    path = None if case is None else Path(case.out_dir) / RESULTS_NAME
    if path is None or not path.is_file():
        return {}
    return slip_series(read_results(path, SERIES_VARIABLES), bin_s)


def _v(x, fmt=".1f", unit="") -> str:
    return "–" if x is None else f"{x:{fmt}}{unit}"


def transient_answer(rows: list[dict]) -> str:
    """Per transient, oil, direction and bearing type, in words: each slip series before the change, its peak, its
    final and steady values and when it settles."""
    lines = ["Slip [%] in transients (times from the start of the change): before → peak (when) → final, against the "
             "steady run's; settled: within the band of the steady value from then on; t63: 63 % of the way.", ""]
    for r in rows:
        lines.append(f"{r['transient']}, oil {r['oil_temperature_C']:g} °C, {r['direction']}, {r['bearing']} planets, "
                     f"{_SERIES_WORDS[r['series']]}: {_v(r['before_pct'])} → {_v(r['peak_pct'])} "
                     f"({_v(r['peak_after_s'], '.3f', ' s')}) → {_v(r['final_pct'])} (steady {_v(r['steady_pct'])}, on every "
                     f"step {_v(r['steady_every_step_pct'])}); "
                     f"settled after {_v(r['settle_s'], '.3f', ' s') if r['settle_s'] is not None else 'not within the run'}"
                     f", t63 {_v(r['t63_s'], '.3f', ' s')}")
    return "\n".join(lines)


def write_transient_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """transients.csv, transients.md and transients_answer.md."""
    return _write_row_tables(rows, TRANSIENT_COLUMNS, out, "transients", "transients_answer.md",
                             transient_answer(rows), machine)


def plot_transients(series: list[dict], out: Path, machine: str = "") -> list[Path]:
    """slip_transients.png (:func:`viz.plots.slip_transients`): per transient run and bearing type, the slips against
    time with the schedule on a second axis."""
    from viz.plots import slip_transients  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    if not series:
        return []
    panels = []
    for s in series:
        k = s["knots"]
        sched = ([float(x["time"].split()[0]) for x in k], [x["speed"] for x in k], [x["torque"] for x in k])
        for kind in ("inner", "outer"):
            if kind in s["binned"]:
                panels.append((f"{s['transient'].replace('_', ' ')}, {kind} planets, oil {s['oil_temperature_C']:g} °C, "
                               f"{s['direction']}", s["binned"][kind], sched, s["change_s"]))
    return [slip_transients(panels, out / "slip_transients.png",
                            title="Slip in transients" + (f" — {machine}" if machine else ""))]


class SkiddingStudy(Study):
    """Every power × oil temperature × direction (:class:`scenarios.core.study.Study`): the answer first, then the
    tables and the figure."""

    def config(self) -> RunConfig:
        a = self.a
        return RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate, integration=mbd.PRODUCTION,
                         progress=not a.no_progress)

    def cases(self) -> list[Case]:
        if self.a.transients:
            return make_transient_cases(self.a, self.out)
        return make_cases(self.a, self.out)

    def report(self, run: StudyRun) -> dict:
        if self.a.transients:
            a = self.a
            rows, series = transient_rows(run.cases, run.results, a)
            return self.table_report(run, rows, transient_answer, write_transient_tables,
                                     lambda r, out, machine: plot_transients(series, out, machine))
        return self.table_report(run, rows_of(run.cases, run.results), answer, write_tables, plot)


@holds_out_folder
def run(a) -> dict:
    return SkiddingStudy(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
