"""Spectrum check (the source's test rig): carrier-housing acceleration in the fixed frame.

    python -m scenarios.spectrum --out results/spectrum [--carrier-rpm 2000] [--sun-rpm 3290] [--power "200 kW"]

A fixed accelerometer near the carrier axis reads the carrier's acceleration in the inertial frame. Its
one-sided amplitude spectrum (Hann window) is written to DIR/spectrum.csv (frequency_hz, amplitude =
x component; amplitude_y), with f_m = z_r f_c and the sidebands f_m ± f_c, f_m ± 3 f_c marked in
DIR/spectrum.png, the strongest peaks near f_m in DIR/peaks.csv, and DIR/summary.json (f_m_hz, f_c_hz,
resolution_hz, window_s, peaks). The frequency resolution is 1/window: resolve f_c sidebands with a
window of several carrier periods (default 0.1 s → 10 Hz against f_c = 33.3 Hz at 2000 r/min).
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
from mbd.recorder import atomic_write_text

from .analysis import amplitude_spectrum, peak_table
from .plausibility import check_runs
from .runner import RunConfig, run_case, run_report
from . import args
from .command import command


def parse_args(argv):
    p = args.Parser(prog="python -m scenarios.spectrum", description=__doc__.split("\n\n")[0])
    p.add_argument("--carrier-rpm", type=args.positive("r/min"), default=2000.0, help="carrier speed [r/min] (default 2000)")
    p.add_argument("--sun-rpm", type=args.positive("r/min"), default=None,
                   help="sun speed [r/min] magnitude; must match the ring-fixed ratio (3290 at 2000)")
    p.add_argument("--power", default="200 kW", type=args.quantity_of("power"), help='output power with unit (default "200 kW")')
    p.add_argument("--direction", default="forward", choices=["forward", "reverse"])
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.06,
                   help="seconds discarded (default 0.06: a lightly damped ~2.6 kHz mode rings for ~50 ms after the start)")
    p.add_argument("--window", type=args.positive("s"), default=0.1, help="seconds analysed (default 0.1 → 10 Hz resolution)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=20000.0, help="recording rate [Hz]")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", type=args.key_value, help="parameter override")
    p.add_argument("--option", action="append", default=[], metavar="KEY=VALUE", type=args.key_value, help="scene switch")
    p.add_argument("--h", type=args.positive("s", upper=1e-3), default=5e-6, help="initial step [s]")
    p.add_argument("--force", action="store_true",
                   help="run although the gears collide or the recording is too large for the limit or the disk")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--overwrite", action="store_true",
                   help="replace a finished run of other parameters or settings in --out (else refused)")
    p.add_argument("--out", default="results/spectrum", type=args.out_folder)
    return p.parse_args(argv)


def run(a) -> dict:
    from components.params import with_overrides
    from components.presets import reference_dpgt
    from components.scene import SceneOptions
    from components.units import ParameterError

    from .paper_study import _bool, parse_sets

    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    overrides = {"operating.carrier_speed": f"{a.carrier_rpm} rpm", "operating.output_power": a.power,
                 "operating.direction": a.direction, **parse_sets(a.set)}
    try:
        params = with_overrides(reference_dpgt(2, a.direction), overrides)
        si = params.si()
    except ParameterError as exc:
        raise SystemExit(f"error: {exc}") from None
    op = si.operating
    sun_rpm = abs(op.sun_speed) * 30 / np.pi
    if a.sun_rpm is not None and abs(a.sun_rpm - sun_rpm) > 0.001 * sun_rpm + 1.0:
        raise SystemExit(f"error: --sun-rpm {a.sun_rpm} does not match the ring-fixed kinematics: with the carrier at "
                         f"{a.carrier_rpm} r/min the sun turns at {sun_rpm:.1f} r/min (omega_s/omega_c = 1 - z_r/z_s)")
    opts = SceneOptions.from_dict({k: _bool(v) for k, v in parse_sets(a.option).items()})
    cfg = RunConfig(settle=a.settle, window=a.window, sample_rate=a.sample_rate, options=opts,
                    integration=dataclasses.replace(mbd.PRODUCTION, h=a.h), progress=not a.no_progress)
    for w in check_runs([("spectrum", params, cfg)], out, a.force):
        print(f"warning (--force): {w}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = run_case(params, cfg, out / "run", label={"scenario": "spectrum"}, overwrite=a.overwrite)
    import xarray as xr

    with xr.open_dataset(out / "run" / "results.nc", engine="h5netcdf") as ds:
        t = ds["time"].values
        ic = list(ds["fixed.body"].values).index("carrier")
        acc = ds["fixed.acceleration"].values[:, ic]
    f, ax, df = amplitude_spectrum(t, acc[:, 0])
    _, ay, _ = amplitude_spectrum(t, acc[:, 1])
    f_c, f_m = s["f_c_hz"], s["f_m_hz"]
    marks = {"f_m": f_m, **{f"f_m{'+' if k > 0 else '−'}{abs(k)}f_c": f_m + k * f_c for k in (-3, -1, 1, 3)}}
    expected = {f"f_m{k:+d}f_c" if k else "f_m": f_m + k * f_c for k in range(-6, 7)}
    peaks = peak_table(f, ax, f_m, 6.5 * f_c, expected, n=8)
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["frequency_hz", "amplitude", "amplitude_y"])
    w.writerows(zip(f.tolist(), ax.tolist(), ay.tolist()))
    atomic_write_text(out / "spectrum.csv", buf.getvalue())
    buf = io.StringIO()
    if peaks:
        w = csv.DictWriter(buf, fieldnames=list(peaks[0]))
        w.writeheader()
        w.writerows(peaks)
    atomic_write_text(out / "peaks.csv", buf.getvalue())
    summary = {"f_m_hz": f_m, "f_c_hz": f_c, "resolution_hz": df, "window_s": s["window_s"],
               "carrier_rpm": s["carrier_rpm"], "sun_rpm": s["sun_rpm"], "power_W": s["power_W"],
               "quantity": "carrier acceleration in the fixed frame, x component [m/s^2] (amplitude_y: y component)",
               "peaks": peaks, "wall_s": s["wall_s"], "steps": s["steps"], "error_estimate": s["error_estimate"],
               "warnings": s["warnings"]}
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=float))
    from viz import plots as vp

    fig = vp.spectrum(f, {"x": ax, "y": ay}, marks, out / "spectrum.png", fmax=min(f[-1], 2.5 * f_m),
                      quantity="carrier acceleration (fixed frame)", unit="m/s^2", logy=True,
                      title=f"Carrier housing acceleration, carrier {s['carrier_rpm']:.0f} r/min, sun {abs(s['sun_rpm']):.1f} r/min")
    print(f"f_c = {f_c:.2f} Hz, f_m = {f_m:.1f} Hz, resolution {df:.2f} Hz over {t[-1] - t[0]:.4g} s")
    print("strongest peaks near f_m:")
    for r in peaks:
        print(f"  {r['frequency_hz']:9.1f} Hz  amp {r['amplitude']:.3g} m/s^2   nearest {r['nearest']:>8} "
              f"({r['expected_hz']:.1f} Hz, {r['distance_bins']:+.2f} bins)")
    print("run time and accuracy: " + "\n".join(run_report(s)))
    print(f"written: {out / 'spectrum.csv'}, {out / 'peaks.csv'}, {out / 'summary.json'}, {fig}")
    return summary


@command
def main(argv=None) -> int:
    run(parse_args(sys.argv[1:] if argv is None else argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
