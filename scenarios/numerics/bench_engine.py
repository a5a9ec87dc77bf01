"""Engine benchmark: a ring of M stiff, light bodies (roller-like) integrated with HHT and with
scipy's Radau (sparse Jacobian) on the same model; and (``--chain``) the network a compiled C++ engine
was measured on, timed on both engine paths.

    python -m scenarios.bench_engine [--sizes 10 50 100 250] [--steps 2000] [--repeats 3] [--json out.json]
    python -m scenarios.bench_engine --chain [--sizes 10 50 100 250] [--repeats 3]

The chain: M planar bodies (3 g, 2e-8 kg·m²), body 0 tied to the ground and each body to
the next per coordinate by linear spring-dampers (x, y: 3e8 N/m, 50 N·s/m; rotation 1e3 N·m/rad), 100 N
along x on the last body, 2000 fixed steps of 5 µs, HHT. Exudyn 1.13.6's fast module took 5.2 / 24.7 /
49.9 / 139 µs per step for M = 10 / 50 / 100 / 250 on this kind of machine (``EXUDYN_US_PER_STEP``).

Each body (3.1 g, 7.5 mm "roller") is joined to its two neighbours by BodySprings (3e8 N/m, light
damping) between markers at the midpoints of the chords and to its second neighbours by softer ties
(3e7 N/m) that make the ring rigid; a few bodies sit on GroundSupports, one
body is driven by an oscillating torque (500 Hz), another carries a constant load torque (both ramped
in) and all start at rest in the nominal pose.
The drive torque is a Python function of time, which the compiled engine cannot take: the ring's HHT runs on the
numpy engine path, and the command says so once, in one line, before the table (``engine`` in the JSON).
HHT runs ``steps`` fixed steps of h = 5 µs; the table reports the median wall time per step over
``repeats`` runs, Newton iterations per step and the factorization / residual / Jacobian counts.
Radau (rtol 1e-6, atol scaled to the µm motion) integrates the same span once; the agreement is the
largest difference of the final positions relative to the largest displacement from the nominal.
"""
from __future__ import annotations

import json
import re
import statistics
import sys
import time

import numpy as np

import mbd
from mbd.elements import BodySpring, ForceSource, GroundSupport, Ramp, TorqueSource, TorsionalSpring
from ..core import args
from ..core.command import command

ROLLER_D = 7.5e-3                      # m
ROLLER_M = 3.1e-3                      # kg
ROLLER_J = ROLLER_M * ROLLER_D ** 2 / 8
K_LINK = 3e8                           # N/m
ZETA = 0.02                            # damping ratio of one link on one roller mass
K_SUPPORT = 1e8                        # N/m
H = 5e-6                               # s


def ring_model(M: int, frame=None) -> tuple[mbd.Model, np.ndarray, np.ndarray]:
    """Model and initial (q0, v0) of a ring of M bodies."""
    R = ROLLER_D / (2 * np.sin(np.pi / M))          # neighbours' centres one diameter apart
    psi = 2 * np.pi * np.arange(M) / M
    theta = psi + np.pi / 2                          # body x axis tangent to the ring
    centres = R * np.column_stack([np.cos(psi), np.sin(psi)])
    b = mbd.ModelBuilder(frame=frame)
    bodies = [b.add_body(f"r{i}", ROLLER_M, ROLLER_J, pose=(*centres[i], theta[i])) for i in range(M)]
    ia = np.arange(M)
    ib = (ia + 1) % M
    mid = 0.5 * (centres[ia] + centres[ib])

    def local(points, idx):                          # world offsets into body axes (zero preload)
        d = points - centres[idx]
        c, s = np.cos(theta[idx]), np.sin(theta[idx])
        return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])

    c_link = 2 * ZETA * np.sqrt(K_LINK * ROLLER_M)
    b.add(BodySpring("links", ia, ib, k=K_LINK, c=c_link, marker_a=local(mid, ia), marker_b=local(mid, ib)))
    # second neighbours (a cage-like tie) triangulate the ring: without them the pinned polygon has
    # M − 3 zero-stiffness mechanism modes between the supports
    ic = (ia + 2) % M
    mid2 = 0.5 * (centres[ia] + centres[ic])
    b.add(BodySpring("ties", ia, ic, k=0.1 * K_LINK, c=0.3 * c_link, marker_a=local(mid2, ia),
                     marker_b=local(mid2, ic)))
    sup = np.arange(0, M, max(1, M // 5))
    b.add(GroundSupport("supports", sup, kx=K_SUPPORT, cx=2 * ZETA * np.sqrt(K_SUPPORT * ROLLER_M),
                        anchor=centres[sup]))
    f_drive = 500.0
    b.add(TorqueSource("drive", bodies[0], torque=lambda t: 0.05 * np.sin(2 * np.pi * f_drive * t),
                       ramp=Ramp(0.0, 1e-3)))
    b.add(TorqueSource("load", bodies[M // 2], torque=-0.02, ramp=Ramp(0.0, 1e-3)))
    model = b.build()
    # start at rest in the nominal pose: the smoothly ramped torques excite the response
    q0 = np.column_stack([centres, theta]).ravel()
    v0 = np.zeros_like(q0)
    return model, q0, v0


EXUDYN_US_PER_STEP = {10: 5.2, 50: 24.7, 100: 49.9, 250: 139.0}


def chain_model(M: int) -> tuple[mbd.Model, np.ndarray, np.ndarray]:
    """The chain of the Exudyn comparison: coordinate springs (zero length: markers at the centres)."""
    b = mbd.ModelBuilder()
    for i in range(M):
        b.add_body(f"b{i}", 3e-3, 2e-8)
    ia = np.arange(M - 1)
    b.add(GroundSupport("ground", [0], kx=3e8, cx=50.0, k_theta=1e3))
    b.add(BodySpring("links", ia, ia + 1, k=3e8, c=50.0))
    b.add(TorsionalSpring("joints", ia, ia + 1, k=1e3))
    b.add(ForceSource("pull", [M - 1], force=(100.0, 0.0)))
    model = b.build()
    return model, np.zeros(model.ndof), np.zeros(model.ndof)


def run_chain(M: int, steps: int, repeats: int) -> dict:
    """µs per step of the chain on both engines (interleaved repeats, medians)."""
    model, q0, v0 = chain_model(M)
    walls, res = {"compiled": [], "numpy": []}, {}
    for _ in range(repeats):
        for engine in walls:
            t0 = time.perf_counter()
            res[engine] = mbd.simulate(model, q0, v0, steps * H, controller=mbd.FixedStep(H),
                                       stepper=mbd.HHT(alpha=-0.1), progress=False, engine=engine)
            walls[engine].append(time.perf_counter() - t0)
    c = res["compiled"]
    us = {k: 1e6 * statistics.median(v) / c.steps for k, v in walls.items()}
    return {"M": M, "ndof": model.ndof, "steps": c.steps, "us_per_step_compiled": us["compiled"],
            "us_per_step_numpy": us["numpy"], "exudyn_us_per_step": EXUDYN_US_PER_STEP.get(M),
            "newton_per_step": c.counters["newton"] / c.steps, "jacobian_evals": c.counters["jacobian"],
            "same_counters": c.counters == res["numpy"].counters,
            "max_state_difference_m": float(np.abs(c.state.q - res["numpy"].state.q).max())}


def chain_table(sizes, steps: int, repeats: int) -> list[dict]:
    hdr = f"{'M':>5} {'DOF':>6} {'compiled µs/step':>17} {'numpy µs/step':>14} {'Exudyn µs/step':>15} {'Newton/step':>11}"
    print(hdr)
    print("-" * len(hdr))
    rows = []
    for M in sizes:
        r = run_chain(M, steps, repeats)
        ex = f"{r['exudyn_us_per_step']:15.1f}" if r["exudyn_us_per_step"] else f"{'':>15}"
        print(f"{M:5d} {r['ndof']:6d} {r['us_per_step_compiled']:17.1f} {r['us_per_step_numpy']:14.1f} {ex}"
              f" {r['newton_per_step']:11.2f}", flush=True)
        rows.append(r)
    return rows


def ring_engine(M: int = 10) -> tuple[str, str | None]:
    """(the engine the ring runs on, why not the compiled one or None). The compiled engine is tried on the ring
    for zero steps; what it cannot take (the drive's 500 Hz torque is a Python function of time) is named, the
    function's memory address dropped, so that :func:`main` can say in one line what runs instead."""
    model, q0, v0 = ring_model(M)
    try:
        mbd.simulate(model, q0, v0, 0.0, controller=mbd.FixedStep(H), stepper=mbd.HHT(alpha=-0.1), progress=False,
                     engine="compiled")
    except mbd.ModelError as exc:
        why = str(exc).split("cannot run this model: ", 1)[-1]
        return "numpy", " ".join(re.sub(r"\s*\(<function [^()]*>\)", "", why).split())
    return "compiled", None


def run_hht(M: int, steps: int, repeats: int, engine: str = "auto") -> dict:
    times, res = [], None
    for _ in range(repeats):
        model, q0, v0 = ring_model(M)
        t0 = time.perf_counter()
        res = mbd.simulate(model, q0, v0, steps * H, controller=mbd.FixedStep(H), stepper=mbd.HHT(alpha=-0.1),
                           progress=False, engine=engine)
        times.append(time.perf_counter() - t0)
    c = res.counters
    return {"M": M, "ndof": model.ndof, "steps": res.steps, "engine": res.engine, "wall_s": statistics.median(times),
            "us_per_step": 1e6 * statistics.median(times) / res.steps, "newton_per_step": c["newton"] / res.steps,
            "factorizations": c["factor"], "residual_evals": c["residual"], "jacobian_evals": c["jacobian"],
            "rejected": c["rejected"], "q_end": res.state.q, "q0": q0}


def run_radau(M: int, steps: int, max_wall_s: float) -> dict:
    model, q0, v0 = ring_model(M)
    n = model.ndof
    rot = (model.free % 3) == 2
    # absolute tolerances scaled to the motion: ~µm displacements, ~1e-4 rad, ω up to ~6e5 rad/s
    atol_q = np.where(rot, 1e-9, 1e-11)
    atol = np.concatenate([atol_q, 1e5 * atol_q])
    r = mbd.solve_scipy(model, q0, v0, (0.0, steps * H), method="Radau", rtol=1e-6, atol=atol,
                        t_eval=[steps * H], max_wall_s=max_wall_s)
    out = {"success": r.success, "message": r.message, "wall_s": r.wall_s, "nfev": r.nfev, "njev": r.njev,
           "nlu": r.nlu}
    out["q_end"] = r.y[:n, -1] if r.success and r.y.shape[1] else None
    return out


def agreement(hht: dict, radau: dict, model: mbd.Model) -> float:
    if radau.get("q_end") is None:
        return float("nan")
    pos = (model.free % 3) != 2
    disp = np.abs(hht["q_end"][pos] - hht["q0"][pos]).max()
    return float(np.abs(hht["q_end"][pos] - radau["q_end"][pos]).max() / disp)


@command
def main(argv=None) -> int:
    p = args.parser("bench_engine", __doc__, examples=["{prog}", "{prog} --chain --sizes 10 50 --repeats 3", "{prog} --json bench.json"],
                     writes="a table on the screen; with --json the results to that JSON file", out=None)
    p.add_argument("--sizes", type=args.count(1), nargs="+", default=[10, 50, 100, 250], help="numbers of bodies M")
    p.add_argument("--steps", type=args.count(1), default=2000, help="HHT steps of h = 5 µs")
    p.add_argument("--repeats", type=args.count(1), default=3, help="HHT repeats (the median is reported)")
    p.add_argument("--no-radau", action="store_true", help="skip the solve_ivp(Radau) comparison")
    p.add_argument("--radau-max-wall", type=args.positive("s"), default=600.0, help="wall-time cap per Radau run [s]")
    p.add_argument("--json", help="write the results to this JSON file")
    p.add_argument("--chain", action="store_true", help="the Exudyn comparison chain on both engines")
    a = p.parse_args(argv)
    if a.chain:
        rows = chain_table(a.sizes, a.steps, a.repeats)
        if a.json:
            with open(a.json, "w") as fh:
                json.dump({"h_s": H, "steps": a.steps, "repeats": a.repeats, "chain": rows}, fh, indent=2)
        return 0

    engine, why = ring_engine()
    if why:         # said once, not by mbd on every run (its line would repeat per size and repeat)
        print(f"fallback: the ring's HHT runs on the numpy engine path, about 13x slower (the µs/step below are "
              f"its), because the compiled engine cannot take this model: {why}")
    rows = []
    hdr = (f"{'M':>5} {'DOF':>6} {'µs/step':>9} {'Newton/step':>11} {'LU':>5} {'residual':>9} {'Jacobian':>9}"
           f" {'Radau s':>9} {'Radau nfev':>10} {'agreement':>10}")
    print(hdr)
    print("-" * len(hdr))
    for M in a.sizes:
        h = run_hht(M, a.steps, a.repeats, engine)
        model, _, _ = ring_model(M)
        r = run_radau(M, a.steps, a.radau_max_wall) if not a.no_radau else {}
        agr = agreement(h, r, model) if r else float("nan")
        rad_s = f"{r['wall_s']:9.2f}" if r and r["success"] else ("  skipped" if not r else "   failed")
        print(f"{M:5d} {h['ndof']:6d} {h['us_per_step']:9.1f} {h['newton_per_step']:11.2f} {h['factorizations']:5d}"
              f" {h['residual_evals']:9d} {h['jacobian_evals']:9d} {rad_s} {r.get('nfev', 0):10d} {agr:10.2e}")
        if r and not r["success"]:
            print(f"      Radau: {r['message']}")
        sys.stdout.flush()
        row = {k: v for k, v in h.items() if k not in ("q_end", "q0")}
        if r:
            row["radau"] = {k: v for k, v in r.items() if k != "q_end"}
        row["agreement"] = agr
        rows.append(row)
    if a.json:
        with open(a.json, "w") as fh:
            json.dump({"h_s": H, "steps": a.steps, "repeats": a.repeats, "engine": engine, "engine_note": why,
                       "results": rows}, fh, indent=2)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
