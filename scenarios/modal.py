"""Natural frequencies and mode shapes.

    python -m scenarios.modal --params FILE.toml --out results/modal     # (a) single planetary set
    python -m scenarios.modal --dpgt --out results/modal_dpgt             # (b) DPGT with linear bearings

(a) sun–planet–ring set on linear planet bearings, constant mesh stiffness, each mesh linearised on its
loaded flank, no speed (the lumped-parameter literature's model). (b) the reference DPGT with bearings as
linear springs and constant mesh stiffness, linearised about its loaded steady state at an operating
condition in the rotating carrier frame (centrifugal softening included, gyroscopic terms dropped from
the undamped problem). Prints frequencies [Hz] with each mode's class (rotational / translational /
planet / mixed) and multiplicity; writes DIR/summary.json (frequencies_hz ascending with rigid-body modes
as 0, mode_class, multiplicity), DIR/modes.csv and DIR/mode_shapes.png.
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
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.planetary import (EXAMPLE_PLANETARY, build_single_planetary, classify_modes, load_planetary_toml,
                                  planetary_modes)
from components.presets import reference_dpgt
from components.results.io import atomic_write_text
from components.scene import SceneOptions
from components.units import ParameterError

from .core import args
from .core.command import command
from .core.integrity import claim_for_inputs, command_inputs


EXAMPLES = ["{prog} --params my_planetary.toml --out results/modal", "{prog} --set planets=4",
            "{prog} --dpgt --conditions 3 --set bearing.linear_stiffness=\"5e8 N/m\" --out results/modal_dpgt"]
WRITES = ("summary.json (frequencies_hz ascending, rigid-body modes as 0, mode_class, multiplicity), modes.csv, "
          "mode_shapes.png")


def parse_args(argv):
    p = args.parser("modal", __doc__, examples=EXAMPLES, writes=WRITES, out="results/modal")
    p.add_argument("--params", default=None, type=args.existing_file, help="TOML file of the single planetary set (default: built-in example)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", type=args.key_value, help="override a key of the single planetary set, e.g. planets=4; with --dpgt a DPGT parameter "
                        "(keys: `dpgt params`) (repeatable)")
    p.add_argument("--dpgt", action="store_true", help="analyse the DPGT with linear bearings instead")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="DPGT: seconds to reach the loaded steady state")
    # --params and --set describe a single planetary set here (or, with --dpgt, --set the DPGT's keys)
    args.add_shared(p, "conditions", "out", "overwrite", "no-progress", out="results/modal", conditions="3",
                    one_condition_only=True)
    return p.parse_args(argv)


def _multiplicity(groups, n):
    mult = np.ones(n, dtype=int)
    for g in groups:
        for i in g:
            mult[i] = len(g)
    return mult


def planetary(a):
    try:
        spec = load_planetary_toml(a.params, args.parse_sets(a.set)) if a.params else None
        built = build_single_planetary(spec if spec is not None else EXAMPLE_PLANETARY,
                                       overrides=None if a.params else args.parse_sets(a.set))
    except (ParameterError, OSError) as exc:
        raise SystemExit(f"error: {exc}") from None
    modes = planetary_modes(built)
    return built, modes.frequencies_hz, modes.shapes, list(modes.kind), modes.groups


def dpgt(a):
    if a.params:      # the file is a single planetary set's; the DPGT takes its own parameters through --set
        raise SystemExit(f"error: --params {a.params} describes a single planetary set; with --dpgt give DPGT "
                         "parameters with --set KEY=VALUE")
    try:
        params = with_overrides(reference_dpgt(int(a.conditions), "forward"), args.parse_sets(a.set))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            built = build_dpgt(params, SceneOptions(bearings="linear", mesh_stiffness="constant", gravity=False))
    except ParameterError as exc:
        raise SystemExit(f"error: {exc}") from None
    setting = dataclasses.replace(mbd.PRODUCTION, h_max=2e-5)     # linear bearings: larger steps are fine
    r = mbd.simulate(built.model, built.q0, built.v0, a.settle, stepper=setting.stepper(),
                     controller=setting.controller(), progress=False, engine=setting.engine)
    res = mbd.modal_analysis(built.model, r.state.t, r.state.q, r.state.v, r.state.z)
    modes = classify_modes(built.model, res.frequencies_hz, res.shapes, tol=1e-3, freq_tol=1e-3)
    return built, modes.frequencies_hz, modes.shapes, list(modes.kind), modes.groups


def run(a) -> dict:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    identity = claim_for_inputs(out, command_inputs(a), a.overwrite)     # other inputs' results: --overwrite
    built, f, X, kind, groups = dpgt(a) if a.dpgt else planetary(a)
    mult = _multiplicity(groups, f.size)
    m = built.model
    labels = [m.coordinate_name(int(i)) for i in m.free]
    summary = {"model": "dpgt_linear_bearings" if a.dpgt else "single_planetary",
               "frequencies_hz": [float(x) for x in f], "mode_class": kind, "multiplicity": mult.tolist(),
               "dof": int(m.ndof), **identity}
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2))
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["mode", "frequency_hz", "class", "multiplicity"])
    for i, (fi, k, mu) in enumerate(zip(f, kind, mult)):
        w.writerow([i + 1, f"{fi:.6g}", k, mu])
    atomic_write_text(out / "modes.csv", buf.getvalue())
    # shapes: scale rotations by a representative radius so x, y and θ bars compare (metres of arc)
    radius = 0.05
    scale = np.where(m.free % 3 == 2, radius, 1.0)[:, None]
    nz = np.flatnonzero(f > 0)
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    fig = vp.mode_shapes(f[nz], (X[:, nz] * scale).T, labels, out / "mode_shapes.png", numbers=nz + 1,
                         title="Mode shapes (θ scaled by 50 mm; the rigid-body modes at 0 Hz left out)")
    print(f"{summary['model']}: {m.ndof} DOF")
    for i, (fi, k, mu) in enumerate(zip(f, kind, mult)):
        print(f"  mode {i + 1:3d}: {fi:12.2f} Hz  {k:<13} ×{mu}")
    print(f"written: {out / 'summary.json'}, {out / 'modes.csv'}, {fig}")
    return summary


@command
def main(argv=None) -> int:
    run(parse_args(sys.argv[1:] if argv is None else argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
