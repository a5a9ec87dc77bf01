"""What errors and faults do to the planet bearings and to the rig's sensor (docs/model.md §11–12).

    python -m scenarios.fault_study [--conditions 2] [--directions forward,reverse]
        [--faults pinhole,runout,roller,spall_pin,spall_bore,cracked_tooth,missing_tooth]
        [--machine NAME=FILE.toml ...] [--settle S] [--window S] [--sample-rate HZ]
        [--params FILE.toml] [--set KEY=VALUE ...] [--workers N | --scheduler ADDR] [--force] [--overwrite] [--out DIR]

Every fault (the catalogue :data:`FAULTS`, each a stated size with its basis; or a damaged machine described
in a TOML file, README "A damaged machine") runs beside the perfect machine in every direction, through the
one runner (resumable, on Dask like the other studies). Per run and bearing type the table holds the
planet-bearing loads (per planet and the load-sharing factor K_γ), the most loaded roller, cage slip,
pocket impacts and cage acceleration, the bearing lives of pair 1 (whose planet b1 carries the catalogue's
faults: ISO 281's and the roller-load ISO/TS 16281-style life in hours, and the latter relative to the perfect
machine), and the housing sensor's lines f_m, f_m ± f_c, f_m ± 3 f_c and f_m ± the fault's own frequency
(roller-pass frequencies over pin and bore, the rotation of the faulty gear, the cage's revolution), each as
its amplitude over the band's floor (the median of its bins between the carrier orders and the marked lines:
scenarios.core.analysis.band_floor).

Writes ``summary.csv`` / ``summary.md``, ``findings.md`` (the table in words), ``spectra.png`` (each fault's sensor spectrum against the perfect
machine's, its characteristic frequencies marked), ``loads.png`` and ``study.json``.
"""
from __future__ import annotations

import argparse
import csv
import io
import sys
from pathlib import Path

import numpy as np

import mbd
from components.bearing import bearing_kinematics
from components.names import did_you_mean
from components.units import ParameterError
from components.results.io import atomic_write_text

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.runner import RunConfig
from .core.analysis import amplitude_spectrum, carrier_orders, line_table, sensor_signal, sideband_resolution, tooth_cycle
from .core.study import Study, StudyRun
from .core.points import file_without, machine_overrides, point_label, point_order, point_words, points_of
from .core.sweep import Case, build_params, user_overrides

__all__ = ["FAULTS", "main", "run", "characteristic_frequencies", "COLUMNS"]

# the catalogue: name -> (errors overrides, what it is and why this size)
FAULTS = {
    "pinhole": ({"errors.pinhole": [{"planet": "b1", "radial": "0 um", "tangential": "30 um"}]},
                "outer planet b1's pin 30 µm ahead (carrier pinhole position errors of tens of µm: Bodas & "
                "Kahraman 2004)"),
    "runout": ({"errors.runout": [{"gear": "sun", "eccentricity": "16 um", "phase": "0 deg"}]},
               "sun eccentric by 16 µm (radial runout 32 µm: ISO 1328-2 grade 7 for m = 3 mm, d = 93 mm)"),
    "roller": ({"errors.roller_diameter": [{"planet": "b1", "roller": 0, "deviation": "5 um"}]},
               "one roller of b1's bearing 5 µm oversize (a mis-sorted roller)"),
    "spall_pin": ({"errors.spall": [{"planet": "b1", "raceway": "inner", "position": "180 deg", "width": "2 mm",
                                     "depth": "20 um", "edge": "0.5 mm"}]},
                  "2 mm spall, 20 µm deep, on b1's pin in its load zone (facing the carrier axis: the planet's "
                  "centrifugal load draws the bore outwards, so the pin carries on its inner side)"),
    "spall_bore": ({"errors.spall": [{"planet": "b1", "raceway": "outer", "position": "0 deg", "width": "2 mm",
                                      "depth": "20 um", "edge": "0.5 mm"}]},
                   "the same spall on b1's bore (turning with the planet)"),
    "cracked_tooth": ({"errors.tooth_fault": [{"gear": "b1", "tooth": 0, "stiffness_factor": 0.5}]},
                      "a cracked tooth on outer planet b1: its pairs at half stiffness"),
    "missing_tooth": ({"errors.tooth_fault": [{"gear": "b1", "tooth": 0, "stiffness_factor": 0.0}]},
                      "the same tooth missing"),
}
COLUMNS = ["fault", "condition", "direction", "bearing", "load_sharing_factor", "bearing_load_mean_N", "bearing_load_max_N",
           "roller_max_N", "life_iso281_h", "life_iso16281_h", "life_relative", "cage_slip_pct",
           "pocket_impacts_per_rev", "cage_acc_rel_rms_m_s2",
           "sensor_f_m", "sensor_f_m-1f_c", "sensor_f_m+1f_c", "sensor_f_m-3f_c", "sensor_f_m+3f_c",
           "sensor_own", "own_frequency", "notes"]


EXAMPLES = ["{prog} --faults cracked_tooth,spall_pin --directions forward --out results/faults",
            "{prog} --conditions 2 --machine bent=bent_carrier.toml --faults ''",
            '{prog} --set bearing.clearance="30 um" --workers 2']
WRITES = ("c{condition}_{direction}_{fault}/{results.nc, summary.json} per run (…_perfect: the perfect machine); "
          "summary.csv and summary.md (per run and bearing type: load sharing, bearing and roller loads, lives, cage "
          "slip, pocket impacts, the housing sensor's lines over the floor); findings.md (the table in words); "
          "loads.png, spectra.png, study.json")


def parse_args(argv):
    p = args.parser("fault_study", __doc__, examples=EXAMPLES, writes=WRITES, out="results/faults")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--faults", default=",".join(FAULTS), type=_fault_list,
                   help=f"comma list from {', '.join(FAULTS)} ('' for none: only --machine)")
    p.add_argument("--machine", action="append", default=[], metavar="NAME=FILE.toml", type=_machine,
                   help="a damaged machine described in a TOML file (repeatable)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=0.1801,
                   help="seconds analysed (default 0.1801: 6 carrier revolutions at 2000 r/min, a sample to spare; 5.6 Hz "
                        "resolution, three bins of floor between two carrier orders; 0.3601 for one tooth cycle, 12 "
                        "revolutions, as the spectrum command)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=20000.0, help="recording rate [Hz] (> 2 f_m)")
    # its folders are named by operating point, direction and machine
    args.add_shared(p, out="results/faults", conditions="2",
                    conditions_why="condition 2, 2000 rpm: the speed of the source's test rig, whose sensor spectra the "
                                   "faults' lines are read against")
    return p.parse_args(argv)


def _fault_list(text: str) -> list[str]:
    names = [f.strip() for f in text.split(",") if f.strip()]
    unknown = [f for f in names if f not in FAULTS]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown fault(s) {unknown}{did_you_mean(unknown[0], FAULTS)}; the catalogue "
                                         f"has {', '.join(FAULTS)}")
    return names


def _machine(text: str) -> tuple[str, str]:
    name, _, path = text.partition("=")
    if not name.strip() or not path.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=FILE.toml, got {text!r}")
    return name.strip(), args.existing_file(path.strip())


def make_cases(a, out: Path) -> list[Case]:
    """The perfect machine, each catalogue fault and each ``--machine`` in every direction. The sweep owns the
    operating point and the errors: ``--set`` may not touch either, a machine's file not the operating point,
    and a machine may not take the name of the perfect machine or of a catalogue fault."""
    operating = {"operating.carrier_speed": "--conditions", "operating.output_power": "--conditions",
                 "operating.direction": "--directions"}
    machines: dict[str, tuple[dict, str | None]] = {"perfect": ({}, None)}
    machines.update({f: (FAULTS[f][0], None) for f in a.faults})
    for name, path in a.machine:
        if name in machines or name in FAULTS:
            what = "the perfect machine" if name == "perfect" else "a catalogue fault"
            raise SystemExit(f"error: --machine {name}={path}: the name {name!r} is {what}'s; choose another")
        user_overrides({}, str(path), operating)
        machines[name] = ({}, str(path))
    # the operating points (--conditions, --operating, the --params file's points); --set may not move them
    sets = args.parse_sets(a.set)
    points = points_of(a, sets)
    # --params holds what every machine shares (not its errors): read into the overrides, so that a machine's own
    # file can sit beside it
    errors = {"errors": "--faults or --machine NAME=FILE.toml"}
    user_overrides(sets, a.params, errors)           # neither --set nor --params may set the errors
    shared, _ = file_without(a.params, {})
    user = {**shared, **machine_overrides(sets, points)}
    # a run's folder is named as its progress and time lines name it (Case.label: c{condition}_{direction}_{machine})
    return [Case.at(point, d, str(out / f"{point_label(point, d)}_{name}"), {**user, **ov}, path, tag=name)
            for point in points for name, (ov, path) in machines.items()
            for d in ([point.direction] if point.direction else a.directions.split(","))]


def characteristic_frequencies(si) -> dict[str, float]:
    """[Hz] the frequencies faults excite, in the fixed frame: carrier f_c, mesh f_m, each gear's rotation
    relative to the carrier, and per bearing type the cage's revolution relative to the carrier and the
    roller-pass frequencies over the pin (Z·|ω_cage − ω_c|) and over the bore (Z·|ω_cage − ω_planet|)."""
    op, b = si.operating, si.bearing
    wc = op.carrier_speed
    hz = lambda w: abs(w) / (2 * np.pi)
    out = {"f_c": hz(wc), "f_m": op.mesh_frequency, "sun_rel": hz(op.sun_speed - wc)}
    for kind, w in (("inner", op.inner_planet_speed), ("outer", op.outer_planet_speed)):
        wm, _ = bearing_kinematics(b, wc, w)
        out[f"{kind}_planet_rel"] = hz(w - wc)
        out[f"{kind}_cage_rel"] = hz(wm - wc)
        out[f"{kind}_roller_pass_pin"] = b.rollers * hz(wm - wc)
        out[f"{kind}_roller_pass_bore"] = b.rollers * hz(wm - w)
    return out


def _own_frequency(case: Case, si, fr: dict) -> float | None:
    """The sideband spacing a fault of this case should bring in around f_m (None: none specific)."""
    e = si.errors
    kind = lambda planet: "inner" if planet[0] == "a" else "outer"
    if e.tooth_fault or e.runout:          # the first faulty gear's rotation relative to the carrier
        g = (e.tooth_fault + e.runout)[0].gear
        return fr["f_c"] if g == "ring" else fr["sun_rel"] if g == "sun" else fr[f"{kind(g)}_planet_rel"]
    if e.spall:
        x = e.spall[0]
        return fr[f"{kind(x.planet)}_roller_pass_{'pin' if x.raceway == 'inner' else 'bore'}"]
    if e.roller_diameter:
        return fr[f"{kind(e.roller_diameter[0].planet)}_cage_rel"]
    return fr["f_c"] if e.pinhole else None


def sensor_spectrum(run_dir: Path, f_c: float, cycle: int = 1):
    """(f, amplitude, why) of the recorded housing sensor of a run (scenarios.spectrum's definition: whole tooth
    cycles of ``cycle`` carrier revolutions where the record holds one); ``why`` says why its lines mean nothing (too
    few carrier revolutions), None when they do."""
    t, x = sensor_signal(run_dir / "results.nc", f_c, cycle=cycle)
    f, amp, _ = amplitude_spectrum(t, x)
    return f, amp, sideband_resolution(t, f_c)


def rows_of(cases: list[Case], results: dict) -> tuple[list[dict], dict]:
    rows, spectra = [], {}
    perfect = {(c.condition, c.direction): results.get(c.label, {}) for c in cases if c.tag == "perfect"}
    for case in cases:
        s = results.get(case.label)
        if s is None or s.failed:
            continue
        si = build_params(case).si()
        fr = characteristic_frequencies(si)
        g = si.gears
        f, amp, coarse = sensor_spectrum(Path(case.out_dir), fr["f_c"],
                                         tooth_cycle(g.ring.teeth, (g.inner_planet.teeth, g.outer_planet.teeth)))
        own = _own_frequency(case, si, fr)
        spectra[(case.tag, case.condition, case.direction)] = (f, amp, fr, own)
        fm, fc = fr["f_m"], fr["f_c"]
        marks = {f"sensor_f_m{k:+d}f_c" if k else "sensor_f_m": fm + k * fc for k in (-3, -1, 0, 1, 3)}
        if own is not None:
            marks.update({"own-": fm - own, "own+": fm + own})
        band = (fm - 6.5 * max(fc, own or 0.0), fm + 6.5 * max(fc, own or 0.0))
        # the floor: between the carrier orders and the marked lines; lines that cannot mean anything are left
        # out, not interpreted (the note says why)
        between = carrier_orders(fm, fc, band) + list(marks.values())
        sensor = {r["line"]: None if coarse else r["over_median"] for r in line_table(f, amp, marks, band, between)}
        for kind in ("inner", "outer"):
            d, p0 = s[kind], perfect.get((case.condition, case.direction), {}).get(kind)
            life = d["life_iso16281_h"] / p0["life_iso16281_h"] if p0 else None
            row = {"fault": case.tag, "condition": case.condition, "direction": case.direction, "bearing": kind,
                   "load_sharing_factor": d.get("load_sharing_factor"),
                   "bearing_load_mean_N": d["bearing_load_mean_all_N"], "bearing_load_max_N": d["bearing_load_max_N"],
                   "roller_max_N": max(d["roller_inner_race_max_N"], d["roller_outer_race_max_N"]),
                   "life_iso281_h": d["life_iso281_h"], "life_iso16281_h": d["life_iso16281_h"],
                   "life_relative": life, "cage_slip_pct": d.get("cage_slip_pct"),
                   "pocket_impacts_per_rev": d.get("pocket_impacts_per_rev"),
                   "cage_acc_rel_rms_m_s2": d.get("cage_acc_rel_magnitude_rms_m_s2"),
                   **{k: v for k, v in sensor.items() if k.startswith("sensor")},
                   "sensor_own": min(sensor["own-"], sensor["own+"]) if own is not None and not coarse else None,
                   "own_frequency": own,
                   "notes": "; ".join([w for w in s.get("warnings", []) if kind in w or "carrier drive" in w
                                       or "ramp" in w] + ([coarse] if coarse else []))}
            rows.append(row)
    return rows, spectra


def write_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """summary.csv, summary.md and findings.md (the markdown files headed by ``machine``, the machine's name)."""
    head = [f"Machine: {machine}", ""] if machine else []
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS)
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(out / "summary.csv", buf.getvalue())
    fmt = lambda v: f"{v:.4g}" if isinstance(v, float) else ("" if v is None else str(v))
    md = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    md += ["| " + " | ".join(fmt(r[c]) for c in COLUMNS) + " |" for r in rows]
    atomic_write_text(out / "summary.md", "\n".join(head + md) + "\n")
    atomic_write_text(out / "findings.md", "\n".join(head + [findings(rows)]) + "\n")
    return [out / "summary.csv", out / "summary.md", out / "findings.md"]


def plots(rows: list[dict], spectra: dict, out: Path, machine: str = "") -> list[Path]:
    """loads.png and (with a perfect machine to compare against) spectra.png; ``machine`` names the machine in the
    titles."""
    on = f" — {machine}" if machine else ""
    from viz.plots import fault_loads, fault_spectra  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    files = [fault_loads(rows, out / "loads.png", title=f"What each fault does to the planet bearings (pair 1){on}")]
    panels = _spectrum_panels(spectra)
    if panels:
        files.append(fault_spectra(panels, out / "spectra.png",
                                   title=f"The housing sensor around the mesh frequency: each fault against the perfect "
                                         f"machine{on}"))
    return files


def write_outputs(rows: list[dict], spectra: dict, out: Path) -> list[Path]:
    """The tables and the figures (module docstring)."""
    return write_tables(rows, out) + plots(rows, spectra, out)


SENSOR_LINES = ("sensor_f_m", "sensor_f_m-1f_c", "sensor_f_m+1f_c", "sensor_f_m-3f_c", "sensor_f_m+3f_c", "sensor_own")


def _where(row: dict) -> str:
    """A row's operating point and direction, as the headline names them."""
    return f"{point_words(row['condition'])}, {row['direction']}"


def findings(rows: list[dict]) -> str:
    """The table in words: per direction the faults ranked by the shortest planet-bearing life they leave
    (pair 1, ISO/TS 16281-style, the shorter of the inner and outer bearing's: the one that governs), against
    the perfect machine's, with the load sharing, the largest bearing load against the perfect machine's, and
    whether the housing sensor hears the fault: a marked line at least 3× its perfect level and 2× the floor."""
    lines = ["What each fault does (life: the shorter of pair 1's two planet-bearing lives, ISO/TS 16281-style, "
             "against the perfect machine's; sensor: the marked line that rose most over the floor).", ""]
    groups = sorted({(r["condition"], r["direction"]) for r in rows}, key=lambda cd: (point_order(cd[0]), cd[1]))
    for c, d in groups:
        by = {}
        for r in rows:
            if (r["condition"], r["direction"]) == (c, d):
                by.setdefault(r["fault"], {})[r["bearing"]] = r
        if "perfect" not in by:
            continue
        lines.append(f"{point_words(c)}, {d}:" if len(groups) > 1 and len({g[0] for g in groups}) > 1 else f"{d}:")
        shortest = lambda f: min(by[f].values(), key=lambda r: r["life_iso16281_h"])
        p = shortest("perfect")
        ranked = sorted((f for f in by if f != "perfect"), key=lambda f: shortest(f)["life_iso16281_h"])
        for fault in ranked:
            w = shortest(fault)
            ref = by["perfect"][w["bearing"]]
            rise = {k[7:]: w[k] / ref[k] for k in SENSOR_LINES[:-1] if w[k] and ref[k] and w[k] >= 2.0}
            loud = max(rise, key=rise.get) if rise else None
            heard = (f"the sensor hears it ({loud} × {rise[loud]:.1f} over the perfect machine's)"
                     if loud and rise[loud] >= 3.0 else "the sensor does not hear it")
            if w["sensor_f_m"] is None or ref["sensor_f_m"] is None:      # too short a window: no verdict
                heard = "the sensor's lines mean nothing here (too few carrier revolutions)"
            own = w.get("sensor_own")
            lines.append(f"  {fault:>14}: life × {w['life_iso16281_h'] / p['life_iso16281_h']:.2f} ({w['bearing']} planet "
                         f"bearing {w['life_iso16281_h']:.0f} h), K_γ {max(r['load_sharing_factor'] for r in by[fault].values()):.3f}, "
                         f"largest bearing load × {w['bearing_load_max_N'] / ref['bearing_load_max_N']:.2f}; {heard}"
                         + (f"; its own sidebands f_m ± {w['own_frequency']:.0f} Hz at {own:.1f}× the floor" if own else "")
                         + (f" [not meaningful: {w['notes']}]" if w.get("notes") else ""))
    return "\n".join(lines)


def _spectrum_panels(spectra: dict) -> list[tuple]:
    """Each damaged machine's sensor spectrum against the perfect one's (same operating point and direction), around
    f_m."""
    panels = []
    several = len({c for _, c, _ in spectra}) > 1
    for (tag, cond, direction), (f, amp, fr, own) in spectra.items():
        ref = spectra.get(("perfect", cond, direction))
        if ref is None or tag == "perfect":
            continue
        fm, fc = fr["f_m"], fr["f_c"]
        marks = {"f_m": fm, **{f"f_m{k:+d}f_c": fm + k * fc for k in (-3, -1, 1, 3)}}
        if own is not None and abs(own - fc) > 1e-9 * fc:
            marks.update({"f_m−f_x": fm - own, "f_m+f_x": fm + own})
        half = max(6.5 * fc, 1.3 * (own or 0.0))
        where = f"{point_words(cond)}, {direction}" if several else direction
        panels.append((f"{tag}, {where}", f, amp, ref[1], marks, (fm - half, fm + half)))
    return panels


class FaultStudy(Study):
    """The perfect machine, each fault and each damaged machine in every direction
    (:class:`scenarios.core.study.Study`): per damaged machine a line first, then the tables and the figures."""

    def config(self) -> RunConfig:
        a = self.a
        return RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate, integration=mbd.PRODUCTION,
                         progress=not a.no_progress, sensor=True)

    def cases(self) -> list[Case]:
        return make_cases(self.a, self.out)

    def check(self, case: Case, cfg: RunConfig) -> None:
        _check_case(case, cfg)

    def study_record(self) -> dict:
        return {"faults": {k: v[1] for k, v in FAULTS.items()}}

    def report(self, run: StudyRun) -> dict:
        rows, spectra = rows_of(run.cases, run.results)
        for row in rows:                     # the headline first
            if row["bearing"] == "outer":
                print(f"{row['fault']:>14} {_where(row)}, outer planet bearings: K_γ {row['load_sharing_factor']:.3f}, "
                      f"max bearing load {row['bearing_load_max_N']:.0f} N, life {row['life_relative'] or float('nan'):.2f}, "
                      + (f"sensor f_m / floor {row['sensor_f_m']:.3g}" if row["sensor_f_m"] is not None
                         else "sensor lines not meaningful (too short a window)"))
        if rows:
            run.step("tables", write_tables, rows, self.out, self.machine_identity()["label"])
            run.step("figures", plots, rows, spectra, self.out, self.machine_identity()["label"])
        return {"rows": rows}


@holds_out_folder
def run(a) -> dict:
    return FaultStudy(a).run()


def _check_case(case: Case, cfg: RunConfig) -> None:
    """The recording resolves the mesh sidebands of the case (fails before any run)."""
    si = build_params(case).si()
    need = 2 * (si.operating.mesh_frequency + 6 * abs(si.operating.carrier_frequency))   # f_m + 6 f_c, reverse too
    if cfg.sample_rate <= need:
        raise ParameterError.at("--sample-rate", f"{cfg.sample_rate:g} Hz cannot resolve the mesh sidebands: needs "
                                                 f"> {need:.0f} Hz")


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
