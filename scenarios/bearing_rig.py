"""One planet bearing on a rig: pin fixed, outer ring loaded radially, cage free or held.

    python -m scenarios.bearing_rig --radial-load "10 kN" --clearance "20 um" --out results/rig

Roller angles are measured from the centre of the load zone: the line along which the loaded outer ring
presses the rollers onto the pin (the ring is pulled along the load, so that centre lies opposite the
pull, on the pin's far side).
Writes DIR/summary.json (radial_load_N, clearance_m, roller_angle_deg from the load-zone centre,
roller_load_N time-mean per roller, q_max_N, stribeck_ratio = Q_max·Z/F_r, load_zone_deg, ring_deflection_m,
the classical discrete-roller solution for comparison, and how it ran: steps, error estimate, wall_s without the
kernels' compile, compile_s, engine and engine_note as a study's run gives them) and DIR/load_distribution.png (polar: the
angle in degrees from the load-zone centre, the roller loads in kN, the discrete-roller solution beside them).
"""
from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

import numpy as np

import mbd
from components.params import overrides_from_toml, with_overrides
from components.presets import reference_dpgt
from components.results.io import atomic_write_text
from components import life
from components.bearing import row_stations
from components.rig import (build_bearing_rig, check_rig_pin, discrete_load_distribution, rig_loads, rig_quasi_static,
                            rig_static_solution)
from components.sliced_bearing import pressure_scales
from mbd.elements.sliced import slice_stations
from components.scene import SceneOptions
from components.units import ParameterError, quantity, to_si

from .core import args
from .core.command import command
from .core.integrity import claim_for_inputs, command_inputs
from .core.runner import accuracy_line, engine_record, time_record

ATOL = mbd.PRODUCTION.atol_pos     # the rig runs the production stepper (components.rig.rig_static_solution)


EXAMPLES = ['{prog} --radial-load "10 kN" --clearance "20 um" --out results/rig', "{prog} --cage free --speed \"3000 rpm\"",
            '{prog} --params my_bearing.toml --set bearing.contact_damping_ratio=0.05']
WRITES = ("summary.json (roller loads against their angle from the load-zone centre, Q_max, Q_max·Z/F_r, load zone, "
          "ring deflection, the classical discrete-roller solution) and load_distribution.png")


def parse_args(argv):
    p = args.parser("bearing_rig", __doc__, examples=EXAMPLES, writes=WRITES, out="results/bearing_rig")
    p.add_argument("--radial-load", default="10 kN", type=args.quantity_of("force", positive_only=True), help='radial load on the outer ring (default "10 kN")')
    p.add_argument("--clearance", default=None, type=args.quantity_of("length"), help='diametral clearance P_d (default: preset, "20 um")')
    p.add_argument("--rollers", type=args.count(3), default=None, help="number of rollers Z (default 12)")
    p.add_argument("--roller-diameter", default=None, type=args.quantity_of("length", positive_only=True), help='roller diameter D (default "7.5 mm")')
    p.add_argument("--roller-length", default=None, type=args.quantity_of("length", positive_only=True), help='roller effective length l (default "9 mm")')
    p.add_argument("--pitch-diameter", default=None, type=args.quantity_of("length", positive_only=True), help='pitch diameter d_m (default "39 mm")')
    p.add_argument("--speed", default="0 rpm", type=args.quantity_of("angular_velocity"), help='outer ring speed (default "0 rpm": static)')
    p.add_argument("--cage", default="held", choices=["held", "free", "none"], help="cage held (default), free or absent")
    p.add_argument("--no-drag", action="store_true", help="switch lubricant drag off")
    p.add_argument("--model", default=None, choices=["planar", "sliced"],
                   help="roller contact model (default: the parameters', planar); sliced: slices, tilts, rows")
    p.add_argument("--rows", type=args.count(1), default=None, help="roller rows (default 1; the sliced model builds each)")
    p.add_argument("--misalignment", default="0 arcmin", type=args.quantity_of("angle"),
                   help='the pin\'s tilt against the ring, e.g. "4 arcmin" (sliced model; default "0 arcmin")')
    p.add_argument("--misalignment-direction", default="radial", choices=["radial", "tangential"],
                   help="the tilt in the load plane (radial, default) or across it (tangential)")
    # the bearing's parameters (bearing.*) from a file or --set; the options above win over them
    args.add_shared(p, "params", "set", "out", "overwrite", "no-progress", out="results/bearing_rig")
    return p.parse_args(argv)


def _file_overrides(path) -> dict:
    try:
        return overrides_from_toml(Path(path).read_text(encoding="utf-8")) if path else {}
    except (ParameterError, ValueError) as exc:          # not TOML, not UTF-8
        raise SystemExit(f"error: --params {path}: {exc}".splitlines()[0]) from None


def run(a) -> dict:
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    ov = {k: v for k, v in {"bearing.clearance": a.clearance, "bearing.rollers": a.rollers,
                            "bearing.roller_diameter": a.roller_diameter, "bearing.roller_length": a.roller_length,
                            "bearing.pitch_diameter": a.pitch_diameter, "bearing.model": a.model,
                            "bearing.rows": a.rows}.items() if v is not None}
    try:
        params = with_overrides(reference_dpgt(), {**_file_overrides(a.params), **args.parse_sets(a.set), **ov})
        F = to_si(quantity("radial_load", a.radial_load, "force"))
        w = to_si(quantity("speed", a.speed, "angular_velocity"))
        gamma = to_si(quantity("misalignment", a.misalignment, "angle"))
        if F <= 0:
            raise ParameterError.at("radial_load", f"must be > 0 N, got {a.radial_load!r}")
        if gamma != 0.0 and params.bearing.model != "sliced":
            raise ParameterError.at("misalignment", "a tilted rig bearing needs --model sliced (bearing.model)")
        check_rig_pin(params.bearing)
    except ParameterError as exc:
        raise SystemExit(f"error: {exc}") from None
    identity = claim_for_inputs(out, command_inputs(a), a.overwrite)     # other inputs' results: --overwrite
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        built = build_bearing_rig(params.bearing, lubricant=None if a.no_drag else params.lubricant, radial_load=F,
                                  outer_speed=w, options=SceneOptions(cage=a.cage, drag=not a.no_drag, gravity=False),
                                  misalignment=gamma, misalignment_direction=a.misalignment_direction)
    sol = rig_static_solution(built)
    b = built.bearing
    theory = discrete_load_distribution(b, F)
    order = np.argsort(sol.angles)
    summary = {
        "radial_load_N": F, "clearance_m": b.clearance, "rollers": b.rollers, "outer_speed_rad_s": w, "cage": a.cage,
        "roller_angle_deg": np.degrees(sol.angles[order]).tolist(),   # from the load-zone centre
        "angle_reference": "centre of the load zone (opposite the pull on the outer ring)",
        "roller_load_N": sol.loads[order].tolist(),
        "q_max_N": sol.q_max, "stribeck_ratio": sol.stribeck,
        "load_zone_deg": float(np.degrees(sol.zone_angle)),
        "load_zone_continuous_deg": float(np.degrees(sol.zone_angle_continuous)),
        "ring_deflection_m": sol.deflection,
        "load_vector_sum_N": sol.load_sum.tolist(),
        "load_balance_error": float(np.hypot(*(sol.load_sum - sol.load_vector)) / F),
        "window_s": [sol.t0, sol.t1], **time_record(sol.wall_s, sol.compile_s), "steps": sol.steps,
        **engine_record(sol.runs),
        "error_estimate": {"kind": "HHT local displacement error estimate, scaled by atol; RMS and max over "
                                   "accepted steps", "rms": sol.error_rms, "max": sol.error_max, "atol_m": ATOL},
        "discrete_theory": {"q_max_N": theory.q_max, "stribeck_ratio": theory.stribeck,
                            "ring_deflection_m": theory.deflection, "load_zone_deg": float(np.degrees(theory.zone_angle)),
                            "roller_angle_deg": np.degrees(theory.angles).tolist(), "roller_load_N": theory.loads.tolist(),
                            "note": "rigid rings, discrete rollers, no centrifugal force or traction"},
        **identity,
    }
    sliced = None
    if built.bearing.model == "sliced":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sliced = sliced_rig_report(params.bearing, a, F, w, gamma, sol)
        summary["sliced"] = sliced
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=float))
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    if sliced is not None:
        prof = sliced["pressure_profile_pin_Pa"]
        rows = len(prof["tilted"])
        pfig = vp.slice_pressure_profiles(sliced["slice_z_m"], sliced["row_stations_m"],
                                          {"aligned": prof["aligned"],
                                           f"tilted {a.misalignment} {a.misalignment_direction}": prof["tilted"]},
                                          out / "pressure_profile.png",
                                          title=f"Most loaded roller{' of each row' if rows > 1 else ''}: "
                                                f"F_r = {F / 1e3:.3g} kN, {b.profile.shape} rollers, quasi-static")
        print(f"sliced ({rows} row{'s' if rows > 1 else ''}, {b.profile.shape}): row shares of the pin load "
              f"{', '.join(f'{x:.3f}' for x in sliced['row_load_share']['tilted'])} tilted (quasi-static; dynamic "
              f"{', '.join(f'{x:.3f}' for x in sliced['row_load_share_dynamic'])}), life relative to aligned "
              f"{sliced['life_relative']:.3f}, edge pressure ratio {sliced['edge_pressure_ratio']['tilted']:.3f}; "
              f"written: {pfig}")

    fig = vp.load_distribution(sol.angles[order], {"simulated (time mean)": sol.loads[order]},
                               out / "load_distribution.png", zero="the load-zone centre",
                               theory=("discrete-roller theory (rigid rings)", theory.angles, theory.loads),
                               title=f"Roller loads, F_r = {F / 1e3:.3g} kN, P_d = {b.clearance * 1e6:.0f} µm, Z = {b.rollers}")
    print(f"F_r = {F:.0f} N, P_d = {b.clearance * 1e6:.1f} um, Z = {b.rollers}: Q_max = {sol.q_max:.0f} N, "
          f"Q_max·Z/F_r = {sol.stribeck:.2f}, load zone {np.degrees(sol.zone_angle):.0f} deg, "
          f"ring deflection {sol.deflection * 1e6:.2f} um, Σ roller loads vs F_r: {summary['load_balance_error']:.2e}")
    print(f"discrete-roller theory: Q_max = {theory.q_max:.0f} N, Q_max·Z/F_r = {theory.stribeck:.2f}, "
          f"ring deflection {theory.deflection * 1e6:.2f} um")
    print("run time and accuracy: " + accuracy_line(sol.wall_s, sol.steps, sol.error_rms, sol.error_max, ATOL,
                                                         sol.compile_s))
    print(f"written: {out / 'summary.json'}, {fig}")
    return summary


def sliced_rig_report(bearing, a, F: float, w: float, gamma: float, sol, positions: int = 4) -> dict:
    """The sliced rig bearing's quasi-static answer (:func:`components.rig.rig_quasi_static`, the ring's slope held),
    aligned and tilted by ``gamma``, at ``positions`` cage positions over one roller pitch (the load turned against the
    rollers): per row its share of the pin load and the most loaded roller's slice loads and pin pressures (at the
    first position: the rollers symmetric about the load line), the edge pressure ratio, and the ISO/TS 16281 life
    with slices of the rows combined (:func:`components.life.sliced_life`) relative to aligned; the dynamic run's
    (``sol``, at the given speed and cage) row shares beside them. The quasi-static rig is the standard's case: the
    ring at rest, the cage held, no drag (no centrifugal load, no traction; an unloaded roller of a turning ring has no
    static spin)."""
    b = bearing.si() if hasattr(bearing, "si") else bearing
    c_pin, c_bore = pressure_scales(b, b.slicing.slices)
    out = {"slice_z_m": slice_stations(b.roller_length, b.slicing.slices)[0].tolist(), "rows": b.rows,
           "row_stations_m": row_stations(b).tolist()}
    cases = {"aligned": 0.0, "tilted": gamma}
    lives, share, profile, loads, edge = {}, {}, {}, {}, {}
    for name, g in cases.items():
        recs = []
        for k in range(positions):
            load_angle = -0.5 * np.pi + 2 * np.pi * k / (positions * b.rollers)
            built = build_bearing_rig(b, radial_load=F, load_angle=load_angle, outer_speed=0.0,
                                      options=SceneOptions(cage="held", drag=False, gravity=False), misalignment=g,
                                      misalignment_direction=a.misalignment_direction)
            system = mbd.System(built.model)
            recs.append(rig_loads(built, system, rig_quasi_static(built, system=system)[0]))
        q_pin = np.stack([r["slices_inner"] for r in recs])            # (positions, rows, Z, n_s)
        q_bore = np.stack([r["slices_outer"] for r in recs])
        pe = life.equivalent_load(np.mean(q_pin ** life.STATIONARY_EXPONENT, axis=(0, 2)), life.STATIONARY_EXPONENT)
        be = life.equivalent_load(np.mean(q_bore ** life.ROTATING_EXPONENT, axis=(0, 2)), life.ROTATING_EXPONENT)
        lives[name] = life.sliced_life(pe, be, b)
        first = q_pin[0]
        row_sum = first.sum(axis=(1, 2))
        share[name] = (row_sum / row_sum.sum()).tolist()
        top = first.sum(-1).argmax(axis=1)                             # each row's most loaded roller
        loads[name] = [first[r, top[r]].tolist() for r in range(b.rows)]
        profile[name] = [(c_pin * np.sqrt(first[r, top[r]])).tolist() for r in range(b.rows)]
        p = np.array(profile[name])
        mid = p[:, p.shape[1] // 2]
        edge[name] = float(np.max(np.maximum(p[:, 0], p[:, -1])) / np.max(mid)) if np.max(mid) > 0 else None
    dyn = sol.loads_rows.sum(axis=1)
    out.update({"misalignment_rad": gamma, "misalignment_direction": a.misalignment_direction,
                "row_load_share": share, "row_load_share_dynamic": (dyn / dyn.sum()).tolist(),
                "most_loaded_roller_slice_load_pin_N": loads, "pressure_profile_pin_Pa": profile,
                "edge_pressure_ratio": edge, "life_iso16281_sliced_Mrev": lives,
                "life_relative": lives["tilted"] / lives["aligned"] if lives["aligned"] and lives["tilted"] else None,
                "note": "quasi-static: ISO/TS 16281's case (the ring at rest, its slope held, the rollers at their held "
                        "pockets' centres, no centrifugal load or traction), the life over "
                        f"{positions} cage positions of one roller pitch; the row shares also from the dynamic run"})
    return out


@command
def main(argv=None) -> int:
    run(parse_args(sys.argv[1:] if argv is None else argv))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
