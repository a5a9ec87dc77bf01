"""Do the planet bearings skid? Cage slip against load and oil temperature, forward and reverse, held against the
bearing's catalogue minimum load.

    python -m scenarios.skidding_study [--speed "1000 rpm"] [--powers 2,20,200] [--oil-temperatures 40,80]
        [--directions forward,reverse] [--settle S] [--window S]
        [--set KEY=VALUE ...] [--params FILE] [--workers N | --scheduler ADDR] [--out DIR]

Every output power × oil temperature × direction at one carrier speed runs through the one runner (resumable, on
Dask like the other studies) with the laws that decide whether a lightly loaded roller set is driven or slides:
the EHL traction with its limiting shear (``bearing.traction_law = "ehl"``, docs/model.md §9.3), the film's rolling
resistance (``bearing.rolling_resistance = "houpert"``, §9.5) and the viscous churning of the oil–air mixture
(``bearing.drag_law = "viscous"``, §8.7); ``--set`` changes any of them (e.g. ``--set bearing.traction_law=tanh``)
or anything else of the machine (clearance, cage guidance, oil).

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

import mbd
from components.results import RESULTS_NAME, open_dataset
from components.results.io import atomic_write_text
from components.skid import SKID_PCT, roller_slip_zones

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.points import checked_point, machine_overrides, parse_point, point_label
from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.sweep import Case, build_params, user_overrides

__all__ = ["main", "run", "LAWS", "COLUMNS", "SKID_PCT", "make_cases", "rows_of", "answer"]

# the laws this study runs with unless --set says otherwise: traction with a limiting shear, the film's rolling
# resistance and viscous churning (docs/model.md §9.3, §9.5, §8.7)
LAWS = {"bearing.traction_law": "ehl", "bearing.rolling_resistance": "houpert", "bearing.drag_law": "viscous"}
COLUMNS = ["power_kW", "oil_temperature_C", "direction", "bearing", "bearing_load_mean_N", "minimum_load_N",
           "load_over_minimum", "cage_slip_pct", "cage_slip_all_pct", "roller_slip_load_zone_pct",
           "roller_slip_unloaded_pct", "roller_slip_entry_pct", "roller_entry_slide_roll", "smearing_pv_entry_W_m2",
           "smearing_pv_max_W_m2", "traction_coefficient_max", "lambda_min", "heat_traction_W", "heat_land_W"]
_NUMBERS = COLUMNS[4:]

EXAMPLES = ["{prog} --out results/skidding", '{prog} --speed "1500 rpm" --powers 0,5,50 --oil-temperatures 30,60,90',
            "{prog} --set bearing.clearance=40um --directions forward --workers 2"]
WRITES = ("p{power}kW_oil{T}C_{direction}/{results.nc, summary.json} per run; summary.csv and summary.md (a row per "
          "run and bearing type: load and catalogue minimum load, cage slip, traction, film, heat); answer.md (the "
          "answer in words, also printed); slip_against_load.png, roller_slip_by_angle.png; study.json")


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
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None, help="statistics window [s] (default: the study's rule)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=2000.0, help="recording rate [Hz] (statistics use every step)")
    args.add_shared(p, "params", "set", "out", "overwrite", "force", "no-progress", "workers", "scheduler",
                    out="results/skidding")
    return p.parse_args(argv)


def make_cases(a, out: Path) -> list[Case]:
    """Every power × oil temperature × direction at the carrier speed ``--speed``, each an operating point
    (:mod:`scenarios.core.points`) of the machine with :data:`LAWS` (a ``--set`` of a law replaces it)."""
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    powers, temps = a.powers, a.oil_temperatures
    sets = args.parse_sets(a.set)
    owned = {"operating.carrier_speed": "--speed", "operating.output_power": "--powers",
             "lubricant.temperature": "--oil-temperatures"}
    cases = []
    for P in powers:
        for T in temps:
            point = checked_point(parse_point(f"p{P:g}kW_oil{T:g}C: {a.speed}, {P:g} kW, oil {T:g} degC",
                                              where="--powers"), "--powers")
            user = {**LAWS, **machine_overrides(user_overrides(sets, a.params, owned), [point])}
            for d in dirs:
                cases.append(Case.at(point, d, str(out / point_label(point, d)), user, a.params))
    return cases


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
            row = {"power_kW": P, "oil_temperature_C": T, "direction": case.direction, "bearing": kind}
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
    with open_dataset(path) as ds:
        return roller_slip_zones(ds, build_params(case).si().bearing)


def answer(rows: list[dict]) -> str:
    """Per oil temperature, direction and bearing type: the cage slip from the lightest to the heaviest load with
    the load over the catalogue minimum, whether a cage skids, and the slip's trends with load and oil temperature."""
    lines = [f"Do the planet bearings skid? Cage slip [%] (+: the cage lags its rolling speed) at each load, the mean "
             f"bearing load over the catalogue minimum 0.02 C_r in brackets; skidding: |slip| > {SKID_PCT:g} %.", ""]
    key = lambda r: (r["oil_temperature_C"], r["direction"], r["bearing"])
    for k in sorted({key(r) for r in rows}, key=lambda k: (k[0], k[1] != "forward", k[2])):
        rr = sorted((r for r in rows if key(r) == k), key=lambda r: r["power_kW"])
        pts = ", ".join(f"{r['power_kW']:g} kW {r['cage_slip_pct']:+.2f} ({r['load_over_minimum']:.2f})" for r in rr)
        rol = ", ".join(f"{r['power_kW']:g} kW {_pct(r.get('roller_slip_entry_pct'))} / "
                        f"{_pct(r.get('roller_slip_unloaded_pct'))}" for r in rr)
        skid = [r["power_kW"] for r in rr if abs(r["cage_slip_pct"]) > SKID_PCT]
        lines.append(f"oil {k[0]:g} °C, {k[1]}, {k[2]}: {pts}"
                     + (f" -> skids at {', '.join(f'{p:g}' for p in skid)} kW" if skid else " -> no skid")
                     + (f"; roller slip at load-zone entry / out of the load zone: {rol}"
                        if any(r.get("roller_slip_entry_pct") is not None for r in rr) else ""))
    lines.append("")
    for col, words in (("cage_slip_pct", "cage |slip|"), ("roller_slip_unloaded_pct", "roller slip out of the load zone")):
        for what, axis in (("load", "power_kW"), ("oil temperature", "oil_temperature_C")):
            falls = rises = 0
            other = [c for c in ("power_kW", "oil_temperature_C") if c != axis][0]
            for k in {(r[other], r["direction"], r["bearing"]) for r in rows}:
                rr = sorted((r for r in rows if (r[other], r["direction"], r["bearing"]) == k and r.get(col) is not None),
                            key=lambda r: r[axis])
                if len(rr) > 1:
                    lo, hi = abs(rr[0][col]), abs(rr[-1][col])
                    falls += hi < lo
                    rises += hi > lo
            if falls + rises:
                lines.append(f"{words} falls as the {what} rises in {falls} of {falls + rises} series, rises in {rises}.")
    return "\n".join(lines)


def _pct(v) -> str:
    return "–" if v is None else f"{v:.1f} %"


def write_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """summary.csv, summary.md and answer.md (the markdown files headed by ``machine``)."""
    head = [f"Machine: {machine}", ""] if machine else []
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS, extrasaction="ignore")
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "summary.csv", buf.getvalue())
    md = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    md += ["| " + " | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in COLUMNS) + " |"
           for r in rows]
    atomic_write_text(out / "summary.md", "\n".join(head + md) + "\n")
    atomic_write_text(out / "answer.md", "\n".join(head + [answer(rows)]) + "\n")
    return [out / "summary.csv", out / "summary.md", out / "answer.md"]


def plot(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """slip_against_load.png: cage slip, roller slip out of the load zone and at its entry, and the film parameter
    against the mean bearing load over the catalogue minimum, forward vs reverse, a marker per oil temperature; and
    roller_slip_by_angle.png (:func:`_by_angle`)."""
    from viz.plots import against_viscosity  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    series = {}
    for key in ("cage_slip_pct", "roller_slip_unloaded_pct", "roller_slip_entry_pct", "lambda_min"):
        for r in sorted(rows, key=lambda r: r["load_over_minimum"]):
            k = (key, r["bearing"], r["direction"], f"oil {r['oil_temperature_C']:g} °C")
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


class SkiddingStudy(Study):
    """Every power × oil temperature × direction (:class:`scenarios.core.study.Study`): the answer first, then the
    tables and the figure."""

    def config(self) -> RunConfig:
        a = self.a
        return RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate, integration=mbd.PRODUCTION,
                         progress=not a.no_progress)

    def cases(self) -> list[Case]:
        return make_cases(self.a, self.out)

    def report(self, run: StudyRun) -> dict:
        return self.table_report(run, rows_of(run.cases, run.results), answer, write_tables, plot)


@holds_out_folder
def run(a) -> dict:
    return SkiddingStudy(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
