"""Spectrum check (the source's test rig): what an accelerometer on the housing reads.

    python -m scenarios.spectrum --out results/spectrum [--sensor housing|mesh|torque|bearing|axis]
                                 [--carrier-rpm 2000] [--power "200 kW"]

``--sensor housing`` (default): the rig's accelerometer on the housing at ψ_s (docs/model.md §12,
``rig.sensor.*``, :mod:`components.sensor`), the sum of its three paths along the sensor's axis: ``mesh``
(each outer planet's ring-mesh force weighted by a Hann window of its angular distance from the sensor, over
m_eq), ``torque`` (the housing's rocking under the ring's support torque) and ``bearing`` (the housing's
translation and rocking under the sun's and carrier's bearing forces and the ring's seat force); each path
alone with ``--sensor mesh|torque|bearing``. ``--sensor axis``: an ideal sensor at the carrier axis (w ≡ 1):
the carrier's acceleration in the fixed frame, x component.

Writes the one-sided amplitude spectrum (Hann window) to DIR/spectrum.csv (frequency_hz, amplitude = the
chosen sensor, then every path, their sum and the axis sensor's x and y), DIR/spectrum.png with f_m = z_r f_c
and f_m ± f_c, f_m ± 3 f_c marked, DIR/lines.csv (f_m + k f_c, |k| ≤ 6: the sensor's amplitude, over the
band's floor (the median of its bins between the carrier orders' main lobes,
:func:`scenarios.core.analysis.band_floor`), what lets a sensor see the line — planet phasing, the transfer path, or errors,
:func:`components.geometry.sideband_origin` — and every path's amplitude and amplitude over its own band
floor, with the path that carries the most of it), the strongest peaks near f_m in DIR/peaks.csv, and
DIR/summary.json (its keys with a unit end in it, as a run's summary: ``amplitude_m_s2``, ``f_m_hz``; the machine's
errors and the rig's parameters as text with their units). The spectrum covers the first whole tooth cycles of the
window (:func:`scenarios.core.analysis.tooth_cycle`: 12 carrier revolutions for z_r = 82, z_p = 24, after which the
planets' teeth meet the ring's as at the start; whole carrier revolutions when the window is shorter): every carrier
order and every line of the planets' tooth errors then falls on a bin. Its resolution is f_c/revolutions; the floor
needs at least 4 revolutions (default window: one tooth cycle, 0.36 s at 2000 r/min, 2.8 Hz against f_c = 33.3 Hz).
``--sensor-at carrier_bearing`` reads the same run with the accelerometer at the source's place
(:data:`components.presets.SENSOR_PRESETS`).

The machine is one argument of :func:`measure` (a :class:`components.params.DPGTParams`, built by
:func:`machine`), the sensor one option.
"""
from __future__ import annotations

import dataclasses
import csv
import io
import json
import sys
import warnings
from pathlib import Path

import numpy as np

import mbd
from components.geometry import check_design, sideband_origin
from components.params import flatten, overrides_from_toml, with_overrides
from components.presets import SENSOR_PRESETS, reference_dpgt, typical_errors
from components.results import read_results
from components.sensor import PATHS as SENSOR_PATHS
from components.results.io import atomic_write_text
from components.units import ParameterError

from .core.analysis import amplitude_spectrum, line_table, peak_table, sensor_paths, sideband_resolution, tooth_cycle
from .core.analysis import whole_revolutions as _whole_revolutions
from .core.plausibility import check_runs
from .core.runner import RunConfig, finished_run, run_case, run_report
from .core.sweep import say_design_warnings
from .core import args
from .core.command import command

SENSORS = {
    "housing": "housing accelerometer (docs/model.md §12): the sum of its mesh, torque and bearing paths, along the "
               "sensor's axis [m/s^2]",
    "mesh": "the housing accelerometer's local ring-mesh path: Hann-windowed ring-mesh forces / m_eq [m/s^2]",
    "torque": "the housing accelerometer's torque path: the housing's rocking under the ring's support torque [m/s^2]",
    "bearing": "the housing accelerometer's bearing path: the housing's translation and rocking under the sun's and "
               "carrier's bearing forces and the ring's seat force [m/s^2]",
    "axis": "ideal sensor at the carrier axis: carrier acceleration in the fixed frame, x component [m/s^2]",
}
PATHS = (*SENSOR_PATHS, "housing")   # the housing sensor's paths and their sum, in lines.csv
# the lines planet phasing lets each sensor see on a perfect machine (components.geometry.sideband_origin):
# a window carries every allowed carrier order; the forces at the axis only k = ±1 (the torque path too, once
# gravity modulates each planet's force once per revolution: without it a net torque keeps only orders l z_r)
SEEN = {"housing": ("phasing", "transfer path"), "mesh": ("phasing", "transfer path"), "torque": ("phasing",),
        "bearing": ("phasing",), "axis": ("phasing",)}
SIDEBANDS = 6         # the line table covers f_m + k f_c, |k| <= SIDEBANDS


EXAMPLES = ["{prog} --out results/spectrum", "{prog} --sensor mesh --carrier-rpm 1500 --perfect",
            "{prog} --params my_rig_machine.toml --set rig.sensor.direction=tangential"]
WRITES = ("run/{results.nc, summary.json} (the run); spectrum.csv (the chosen sensor's amplitude, every path, their "
          "sum, the axis sensor), lines.csv (f_m + k f_c, |k| <= 6: amplitude, over the floor, origin, the path "
          "carrying it), peaks.csv, summary.json, spectrum.png")


def parse_args(argv):
    p = args.parser("spectrum", __doc__, examples=EXAMPLES, writes=WRITES, out="results/spectrum")
    p.add_argument("--carrier-rpm", type=args.positive("r/min"), default=2000.0, help="carrier speed [r/min] (default 2000)")
    p.add_argument("--sun-rpm", type=args.positive("r/min"), default=None,
                   help="sun speed [r/min] magnitude; must match the ring-fixed ratio (3290 at 2000)")
    p.add_argument("--power", default="200 kW", type=args.quantity_of("power"), help='output power with unit (default "200 kW")')
    p.add_argument("--direction", default="forward", choices=["forward", "reverse"])
    p.add_argument("--sensor", default="housing", choices=list(SENSORS),
                   help="housing: the rig's accelerometer (rig.sensor.*, default), the sum of its paths mesh, torque "
                        "and bearing (each alone by name); axis: ideal, at the carrier axis")
    p.add_argument("--perfect", action="store_true",
                   help="a perfect machine: no manufacturing errors (default: the errors of --gear-class)")
    args.renamed(p, "--grades", "--classes", "--gear-grade", new=args.GEAR_CLASS)
    p.add_argument(args.GEAR_CLASS, type=args.count(1, 11), default=None, metavar="CLASS",
                   help="ISO 1328-1 flank tolerance class of the gears behind the default manufacturing errors "
                        "(default 6: every gear's teeth drawn for that class, runouts F_r/2 of that grade, all "
                        "carrier pinholes within ±10 µm; components.presets.typical_errors); errors given by --params "
                        "or --set errors.* replace them; the operating point is this command's options")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.06,
                   help="seconds discarded (default 0.06: a lightly damped ~2.6 kHz mode rings for ~50 ms after the start)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="seconds analysed (default: one tooth cycle, the carrier revolutions after which the planets' "
                        "teeth meet the ring's as at the start — 12 for z_r = 82, z_p = 24: 0.36 s at 2000 r/min)")
    p.add_argument("--sensor-at", default="housing_top", choices=list(SENSOR_PRESETS),
                   help="where the accelerometer is read (components.presets.SENSOR_PRESETS): housing_top (the machine's "
                        "rig.sensor, default) or carrier_bearing (the source's place, on the carrier bearing's boss near "
                        "the axis); read from the same run"),
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=20000.0, help="recording rate [Hz]")
    p.add_argument("--option", action="append", default=[], metavar="KEY=VALUE", type=args.key_value, help="scene switch")
    p.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="initial step [s]")
    args.add_shared(p, "params", "set", "out", "overwrite", "force", "no-progress", out="results/spectrum")
    return p.parse_args(argv)


def machine(a):
    """The machine on the rig: the reference DPGT (or ``--params FILE.toml`` on it) at the operating point
    asked for, with ``--set`` overrides (a usage error names the parameter) and its manufacturing errors: those
    given (``--set errors.X`` / the TOML file), else the typical errors of ``--gear-class``, none with
    ``--perfect``. The operating point belongs to this command's options: a file or ``--set`` that sets it is
    refused, as is ``--perfect`` with errors given."""
    try:
        from_file = overrides_from_toml(Path(a.params).read_text(encoding="utf-8")) if a.params else {}
    except (ParameterError, ValueError) as exc:          # not TOML, not UTF-8, or a bad value
        raise SystemExit(f"error: --params {a.params}: {exc}".splitlines()[0]) from None
    given = {**from_file, **args.parse_sets(a.set)}
    options = {"operating.carrier_speed": "--carrier-rpm", "operating.output_power": "--power",
               "operating.direction": "--direction"}
    for key in given:
        if key.startswith("operating."):
            raise SystemExit(f"error: {key} is set by this command's {options.get(key, 'options')}, not by "
                             f"{'--params' if key in from_file else '--set'}")
    overrides = {"operating.carrier_speed": f"{a.carrier_rpm} rpm", "operating.output_power": a.power,
                 "operating.direction": a.direction, **given}
    try:
        params = with_overrides(reference_dpgt(2, a.direction), overrides)
        if a.perfect and not params.errors.perfect:
            raise SystemExit("error: --perfect contradicts the manufacturing errors given (--params / --set errors.*)")
        if a.gear_class is not None and (a.perfect or not params.errors.perfect):
            raise SystemExit(f"error: --gear-class {a.gear_class} contradicts "
                             f"{'--perfect' if a.perfect else 'the manufacturing errors given (--params / --set errors.*)'}")
        if not a.perfect and params.errors.perfect:      # the rig's machine, unless errors were given
            params = params.replace(errors=typical_errors(params, 6 if a.gear_class is None else a.gear_class))
        si = params.si()
    except ParameterError as exc:
        raise SystemExit(f"error: {exc}") from None
    sun_rpm = abs(si.operating.sun_speed) * 30 / np.pi
    if a.sun_rpm is not None and abs(a.sun_rpm - sun_rpm) > 0.001 * sun_rpm + 1.0:
        raise SystemExit(f"error: --sun-rpm {a.sun_rpm} does not match the ring-fixed kinematics: with the carrier at "
                         f"{a.carrier_rpm} r/min the sun turns at {sun_rpm:.1f} r/min (omega_s/omega_c = 1 - z_r/z_s)")
    return params


def cycle_of(params) -> int:
    """The machine's tooth cycle in carrier revolutions (:func:`scenarios.core.analysis.tooth_cycle`)."""
    g = params.si().gears
    return tooth_cycle(g.ring.teeth, (g.inner_planet.teeth, g.outer_planet.teeth))


def default_window(params, sample_rate: float) -> float:
    """One tooth cycle of ``params`` at its carrier speed [s], two samples to spare (the spectrum is cut to it)."""
    return round(cycle_of(params) / params.si().operating.carrier_frequency + 2.0 / sample_rate, 6)   # to the µs


def run_config(a, params=None) -> RunConfig:
    """The run settings from the command line (window — one tooth cycle of ``params`` unless given —, recording,
    integration, scene switches)."""
    window = a.window if a.window is not None else default_window(params if params is not None else machine(a),
                                                                  a.sample_rate)
    return RunConfig(settle=a.settle, window=window, sample_rate=a.sample_rate, options=args.scene_options(a.option),
                     integration=dataclasses.replace(mbd.PRODUCTION, h=a.h), progress=not a.no_progress)


def run(a) -> dict:
    params = machine(a)
    return measure(params, a.sensor, run_config(a, params), Path(a.out), force=a.force, overwrite=a.overwrite,
                   place=a.sensor_at)


def measure(params, sensor: str, cfg: RunConfig, out: Path, *, force: bool = False, overwrite: bool = False,
            place: str = "housing_top") -> dict:
    """Run ``params`` (:class:`components.params.DPGTParams`) on the rig, read ``sensor`` (a key of
    :data:`SENSORS`) at ``place`` (a key of :data:`components.presets.SENSOR_PRESETS`), and write its spectrum, line
    table and peaks into ``out`` (module docstring). ``force``: run despite the plausibility checks; ``overwrite``:
    replace a finished run of other parameters in ``out``."""
    if place not in SENSOR_PRESETS:
        raise SystemExit(f"error: --sensor-at {place!r}: expected one of {list(SENSOR_PRESETS)}")
    if sensor not in SENSORS:
        raise SystemExit(f"error: --sensor {sensor!r}: expected one of {list(SENSORS)}")
    out.mkdir(parents=True, exist_ok=True)
    with warnings.catch_warnings(record=True) as caught:  # the design warnings every command says
        warnings.simplefilter("always")
        check_design(params)
    say_design_warnings(caught)
    cfg = dataclasses.replace(cfg, sensor=True)          # every path is written, whichever sensor is read
    for w in check_runs([("spectrum", params, cfg)], out, force):
        print(f"warning (--force): {w}")
    s = finished_run(out / "run", params, cfg)       # the same machine, settings and code: read, not re-run
    if s is not None:
        print(f"{out / 'run'}: reused (same parameters, settings and code; {s.get('wall_s', 0.0):.1f} s wall when made)")
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = run_case(params, cfg, out / "run", label={"scenario": "spectrum", "sensor": sensor},
                         overwrite=overwrite)
    at = SENSOR_PRESETS[place](params)              # the sensor is read afterwards: every place from one run
    t, signals = _whole_revolutions(*_signals(out / "run" / "results.nc", sensor, at.si()), s["f_c_hz"], cycle_of(params))
    spectra = {k: amplitude_spectrum(t, x) for k, x in signals.items()}
    f, amp, df = spectra["amplitude"]
    f_c, f_m = s["f_c_hz"], s["f_m_hz"]
    gears = params.si().gears
    lines = _lines(f, spectra, f_m, f_c, int(gears.ring.teeth), int(gears.planets), sensor)
    coarse = sideband_resolution(t, f_c)        # too few carrier revolutions: say so, mark every line
    for r in lines:
        r["meaningful"] = coarse is None
    expected = {r["line"]: r["frequency_hz"] for r in lines}
    peaks = [_renamed(r, {"amplitude": "amplitude_m_s2"})                  # every sensor reads an acceleration
             for r in (peak_table(f, amp, f_m, (SIDEBANDS + 0.5) * f_c, expected, n=8) if amp.any() else [])]
    _write_csv(out / "spectrum.csv", [{"frequency_hz": fi, **{k: a[1][i] for k, a in spectra.items()}}
                                      for i, fi in enumerate(f.tolist())])
    _write_csv(out / "lines.csv", lines)
    _write_csv(out / "peaks.csv", peaks)
    summary = {"f_m_hz": f_m, "f_c_hz": f_c, "resolution_hz": df, "window_s": s["window_s"],
               "carrier_rpm": s["carrier_rpm"], "sun_rpm": s["sun_rpm"], "power_W": s["power_W"],
               "sensor": sensor, "sensor_at": place, "quantity": SENSORS[sensor],
               "revolutions": float(round((t[-1] - t[0] + (t[1] - t[0])) * f_c, 6)), "tooth_cycle": cycle_of(params),
               # the machine's errors and the rig as their parameters read, each value with its unit (as text)
               "errors": {k: [_as_text(e) for e in getattr(params.errors, k)] for k in params.si().errors.to_dict()},
               "sensor_parameters": _as_text(at),
               "carrier_ripple": _as_text(params.rig.carrier_ripple),
               "lines": lines, "peaks": peaks, "wall_s": s["wall_s"], "steps": s["steps"],
               "error_estimate": s["error_estimate"], "warnings": s["warnings"] + ([coarse] if coarse else [])}
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=float))
    fig = _plot(f, spectra, f_m, f_c, s, sensor, out, place)
    _report(lines, peaks, f_m, f_c, df, t, sensor)
    if coarse:
        print(f"warning: {coarse}")
    print("run time and accuracy: " + "\n".join(run_report(s)))
    print(f"written: {out / 'spectrum.csv'}, {out / 'lines.csv'}, {out / 'peaks.csv'}, {out / 'summary.json'}, {fig}")
    return summary


# summary.json's numeric keys without a unit suffix (components.results.UNIT_SUFFIXES): ratios and counts
DIMENSIONLESS_KEYS = frozenset({"over_median", "k", "distance_bins", "revolutions", "tooth_cycle", *(f"{p}_over_floor" for p in PATHS)})


def _renamed(row: dict, names: dict) -> dict:
    """``row`` with its keys renamed by ``names``, in its order (the CSV's columns)."""
    return {names.get(k, k): v for k, v in row.items()}


def _as_text(params) -> dict:
    """{dotted key: value with its unit, as text} of a parameter group (a dimensionless one as its number's text):
    what the parameters say, with units, in summary.json."""
    out = {}
    for k, v in flatten(params).items():
        if hasattr(v, "unitless"):               # a pint quantity (an angle keeps its degree)
            v = f"{v.magnitude:g}" if v.unitless else f"{v:~P}"
        out[k] = str(v)
    return out


def _signals(path: Path, sensor: str, at=None) -> tuple[np.ndarray, dict]:
    """Sample times and the signals of a run: "amplitude" (the sensor read), every path of the housing sensor
    (``at``: its :class:`components.params.SensorSI`, the run's own unless given) and their sum, and the axis
    sensor's x and y."""
    t, signals = sensor_paths(path, at)
    ds = read_results(path, ("fixed.acceleration",))
    acc = ds["fixed.acceleration"][:, list(ds["fixed.body"]).index("carrier")]
    signals.update({"axis_x": acc[:, 0], "axis_y": acc[:, 1]})
    return t, {"amplitude": signals["axis_x" if sensor == "axis" else sensor], **signals}


def _lines(f, spectra, f_m, f_c, z_r: int, planets: int, sensor: str) -> list[dict]:
    """f_m + k f_c, |k| <= SIDEBANDS: the sensor's amplitude, over the band's floor, what lets a sensor see it,
    whether a perfect machine shows it to this sensor (:data:`SEEN`), and per path of the housing sensor (and
    their sum) its amplitude and amplitude over its own band floor; ``carried_by``: the path with the largest
    amplitude at the line. ``spectra``: name -> (f, amplitude, df) with "amplitude" the sensor read."""
    ks = range(-SIDEBANDS, SIDEBANDS + 1)
    marks = {f"f_m{k:+d}f_c" if k else "f_m": f_m + k * f_c for k in ks}
    band = (f_m - (SIDEBANDS + 0.5) * f_c, f_m + (SIDEBANDS + 0.5) * f_c)
    table = {name: line_table(f, spectra[name][1], marks, band) for name in ("amplitude", *PATHS)}
    rows = [_renamed(r, {"amplitude": "amplitude_m_s2"}) for r in table["amplitude"]]   # accelerations, m/s²
    for i, (k, r) in enumerate(zip(ks, rows)):
        r["k"] = k
        r["origin"] = sideband_origin(k, z_r, planets)
        r["perfect_machine_shows"] = r["origin"] in SEEN[sensor]
        for name in PATHS:
            r[f"{name}_amplitude_m_s2"] = table[name][i]["amplitude"]
            r[f"{name}_over_floor"] = table[name][i]["over_median"]
        r["carried_by"] = max(SENSOR_PATHS, key=lambda name: r[f"{name}_amplitude_m_s2"])
    return rows


def _write_csv(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    if rows:
        w = csv.DictWriter(buf, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    atomic_write_text(path, buf.getvalue())


def _plot(f, spectra, f_m, f_c, s, sensor, out, place="housing_top"):
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    shown = {"housing": ["housing", *SENSOR_PATHS], "axis": ["axis_x", "axis_y"]}.get(sensor, [sensor, "housing"])
    names = {"housing": "housing sensor", "mesh": "mesh path", "torque": "torque path", "bearing": "bearing path",
             "axis_x": "x", "axis_y": "y"}
    marks = {"f_m": f_m, **{f"f_m{'+' if k > 0 else '−'}{abs(k)}f_c": f_m + k * f_c for k in (-3, -1, 1, 3)}}
    where = "carrier acceleration (fixed frame)" if sensor == "axis" else (
        "accelerometer on the carrier bearing's boss" if place == "carrier_bearing" else "housing accelerometer")
    zero = [k for k in shown if not np.any(spectra[k][1])]      # a log axis cannot draw them: said in the title
    # the speeds with their signs (the sun turns against the carrier, ω_s/ω_c = 1 − z_r/z_s < 0), a true minus
    speed = lambda rpm, nd: f"{rpm:.{nd}f}".replace("-", "\u2212") + " r/min"
    title = f"{where.capitalize()}, carrier {speed(s['carrier_rpm'], 0)}, sun {speed(s['sun_rpm'], 1)}" + (
        f"\n({', '.join(names[k] for k in zero)} zero for this sensor, not drawn)" if zero else "")
    return vp.spectrum(f, {names[k]: spectra[k][1] for k in shown if k not in zero}, marks, out / "spectrum.png",
                       fmax=min(f[-1], 2.5 * f_m), quantity=where, unit="m/s²", logy=True, title=title,
                       zoom=(f_m - 5 * f_c, f_m + 5 * f_c))


def _report(lines, peaks, f_m, f_c, df, t, sensor) -> None:
    print(f"sensor: {SENSORS[sensor]}")
    print(f"f_c = {f_c:.2f} Hz, f_m = {f_m:.1f} Hz, resolution {df:.2f} Hz over {t[-1] - t[0]:.4g} s")
    print("lines f_m + k f_c (origin: phasing = a perfect machine shows it at the axis; transfer path = "
          "phasing allows it through a position-dependent path; errors = cancelled in a perfect machine); "
          "each path's amplitude over its own band floor, and the path that carries the line:")
    print("  (amp in m/s²; 'x median' and the path columns: amplitude over that signal's own band floor; "
          "'perfect': a perfect machine shows the line; –: the path is zero for this sensor)")
    print(f"  {'line':>9} {'freq':>9}    {'amp':>9}  {'x median':>8}   {'origin':<13} {'perfect':8} "
          + " ".join(f"{p:>8}" for p in PATHS) + "  carried by")
    ratio = lambda x: f"{x:8.2f}" if np.isfinite(x) else f"{'–':>8}"
    for r in lines:
        print(f"  {r['line']:>9} {r['frequency_hz']:6.1f} Hz  {r['amplitude_m_s2']:9.3g}  {r['over_median']:8.1f}   "
              f"{r['origin']:<13} {'yes' if r['perfect_machine_shows'] else 'no':8} "
              + " ".join(ratio(r[f'{p}_over_floor']) for p in PATHS) + f"  {r['carried_by']}")
    print("strongest peaks near f_m:")
    for r in peaks:
        print(f"  {r['frequency_hz']:9.1f} Hz  amp {r['amplitude_m_s2']:.3g} m/s^2   nearest {r['nearest']:>8} "
              f"({r['expected_hz']:.1f} Hz, {r['distance_bins']:+.2f} bins)")


@command
def main(argv=None) -> int:
    run(parse_args(sys.argv[1:] if argv is None else argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
