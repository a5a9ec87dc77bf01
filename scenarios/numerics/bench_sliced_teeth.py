"""The sliced machine with real gears on both engine paths (bearing.model = "sliced", docs/model.md §6.6): the DPGT
with the rig's typical errors (``components.presets.typical_errors``: every gear's teeth drawn for an ISO 1328-1 flank
class — the tooth-pair law, face slice by face slice —, every gear eccentric by half its runout tolerance, the
pinholes off) and every pin sloped by ``--pin-slope`` tangentially (so that planets and rollers tilt and the face
slices differ), its speed on the compiled path against the numpy path and the two paths' results side by side.

    python -m scenarios.bench_sliced_teeth [--conditions 3] [--grade 6] [--pin-slope 4] [--steps 200] [--repeats 3]
                                           [--settle 0.003]

The loaded state is the planar machine with the same errors ``--settle`` seconds into its load ramp (compiled engine);
the sliced machine starts from it with every slope and tilt at zero. Each repeat runs ``--steps`` fixed steps of 5 µs
on each path, interleaved, the engine alone (wall and process CPU time per accepted step — a shared machine
deschedules a run for part of its wall —, the compiled system's set-up included, its kernels loaded before the clock).
Then one run of each path with the window statistics of the run (:class:`components.statistics.WindowStatistics` over
the steps; the compiled run's outputs from the compiled kernels where a family has them, the numpy run's from the
reference kernels), timed too. Prints one JSON object: seconds per step of each path (medians; wall and CPU) and their
ratios; both paths' counters (equal while no Newton decision falls differently on the two round-offs); the largest
difference of the final positions [m or rad] and of the rates relative to the largest rate; and the largest difference
of the window's summary numbers relative to each number's size (with its key), over the numbers larger than 1e-12 in
their SI unit (smaller ones, e.g. a slope of 1e-20 rad, are round-off's zeros: their largest difference is given
apart).
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import statistics
import sys
import time
import warnings

import numpy as np

import mbd
from components.dpgt import build_dpgt
from components.params import PinSlopeParams
from components.presets import reference_dpgt, typical_errors
from components.statistics import WindowStatistics
from components.units import Q_

from ..core import args
from ..core.command import command

EXAMPLES = ["{prog}", "{prog} --grade 8 --steps 20 --repeats 1"]
WRITES = "one JSON object on the screen: seconds per step of both paths, their ratio and the paths' differences"
H = 5e-6
SIGNIFICANT = 1e-12          # summary numbers at most this (SI) are round-off's zeros


def parse_args(argv):
    p = args.parser("bench_sliced_teeth", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--grade", type=args.count(1, 11), default=6,
                   help="ISO 1328-1 flank tolerance class of every gear (1..11, default 6)")
    p.add_argument("--pin-slope", type=args.nonnegative("arcmin"), default=4.0,
                   help="every pin's slope, tangential [arcmin] (default 4; 0: none)")
    p.add_argument("--steps", type=args.count(1), default=200, help="fixed steps of 5 us per run (default 200)")
    p.add_argument("--repeats", type=args.count(1), default=3, help="interleaved timed repeats (default 3)")
    p.add_argument("--settle", type=args.positive("s"), default=0.003,
                   help="seconds of the planar machine's load ramp before the runs (default 0.003)")
    args.add_shared(p, "conditions", conditions="3", one_condition_only=True)
    return p.parse_args(argv)


def machines(condition: int, grade: int, pin_slope: float = 0.0):
    """(planar, sliced) scenes of the reference machine with the typical errors of flank class ``grade``; the sliced
    one with every pin sloped by ``pin_slope`` arcmin tangentially (the planar model has no slopes)."""
    p = reference_dpgt(condition, "forward")
    p = dataclasses.replace(p, errors=typical_errors(p, grade))
    n = p.si().layout.planets
    slopes = tuple(PinSlopeParams(planet=f"{k}{i + 1}", slope=Q_(pin_slope, "arcmin"), direction=Q_(90.0, "deg"))
                   for k in "ab" for i in range(n)) if pin_slope > 0.0 else ()
    ps = p.replace(bearing=p.bearing.replace(model="sliced"), errors=p.errors.replace(pin_slope=slopes))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_dpgt(p), build_dpgt(ps)


def loaded_state(planar, sliced, settle: float) -> mbd.State:
    """The planar machine ``settle`` into its load ramp, as a state of the sliced machine (slopes and tilts zero)."""
    res = mbd.simulate(planar.model, planar.q0, planar.v0, settle, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, engine="compiled")
    s, n = res.state, planar.model.ndof
    ext = lambda x: np.concatenate([x, np.zeros(sliced.model.ndof - n)])          # noqa: E731
    return mbd.State(s.t, ext(s.q), ext(s.v), ext(s.a), ext(s.f), dict(s.z))


def run(sliced, state: mbd.State, steps: int, engine: str, with_statistics: bool = True):
    """((wall, CPU) seconds per accepted step, the SimResult, the window's summary or None) of ``steps`` fixed steps
    on ``engine``, with the window statistics or the engine alone."""
    stats = WindowStatistics(sliced, state.t, state.t + steps * H, whole_revolutions=False,
                             outputs="numpy" if engine == "numpy" else "compiled") if with_statistics else None
    t0, c0 = time.perf_counter(), time.process_time()
    res = mbd.simulate(sliced.model, t_end=state.t + steps * H, state=state.copy(), stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.FixedStep(H), progress=False, engine=engine,
                       observers=[stats] if stats is not None else [])
    n = max(res.counters["accepted"], 1)
    return (((time.perf_counter() - t0) / n, (time.process_time() - c0) / n), res,
            stats.summary() if stats is not None else None)


def numbers(d, prefix=""):
    """A summary's finite numbers flattened to {"key.sub": value}."""
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(numbers(v, f"{prefix}{k}."))
        elif isinstance(v, (list, tuple)):
            out.update(numbers(dict(enumerate(v)), f"{prefix}{k}."))
        elif isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            out[prefix + str(k)] = float(v)
    return out


def compare(rc, rn, sc: dict, sn: dict) -> dict:
    """The two paths' differences: final positions and rates, the summaries' numbers (relative to each number)."""
    a, b = rc.state, rn.state
    nc, nn = numbers(sc), numbers(sn)
    common = sorted(set(nc) & set(nn))
    big = [k for k in common if abs(nn[k]) > SIGNIFICANT]
    rel = {k: abs(nc[k] - nn[k]) / abs(nn[k]) for k in big}
    worst = max(rel, key=rel.get) if rel else None
    small = max((abs(nc[k] - nn[k]) for k in common if k not in rel), default=0.0)
    return {"counters_equal": rc.counters == rn.counters, "counters": dict(rn.counters),
            "counters_compiled": dict(rc.counters),
            "engines": [rc.engine, rn.engine],
            "max_dq": float(np.abs(a.q - b.q).max()), "max_dv_over_max_v": float(np.abs(a.v - b.v).max()
                                                                                 / np.abs(b.v).max()),
            "summary_numbers": len(common), "summary_keys_only_in_one": sorted(set(nc) ^ set(nn)),
            "summary_max_rel_diff": rel[worst] if worst else 0.0, "summary_worst_key": worst,
            "summary_worst_value": nn[worst] if worst else None, "summary_small_numbers": len(common) - len(rel),
            "summary_small_max_abs_diff": small}


def measure(condition: int, grade: int, steps: int, repeats: int, settle: float, pin_slope: float = 4.0) -> dict:
    planar, sliced = machines(condition, grade, pin_slope)
    state = loaded_state(planar, sliced, settle)
    engines = ("compiled", "numpy")
    for eng in engines:
        run(sliced, state, 2, eng)                       # the kernels loaded (compiled once per machine), warm
    t = {e: [] for e in engines}
    for _ in range(repeats):                             # interleaved, the engine alone
        for eng in engines:
            t[eng].append(run(sliced, state, steps, eng, with_statistics=False)[0])
    med = {e: statistics.median(w for w, _ in v) for e, v in t.items()}
    cpu = {e: statistics.median(c for _, c in v) for e, v in t.items()}
    last = {eng: run(sliced, state, steps, eng) for eng in engines}          # with the window statistics
    fam = {type(e).__name__ for e in sliced.model.elements}
    return {"condition": condition, "grade": grade, "pin_slope_arcmin": pin_slope, "steps": steps, "repeats": repeats,
            "t0": state.t,
            "dofs": sliced.model.ndof, "face_sliced_meshes": "SlicedGearMesh" in fam,
            **{f"{e}_s_per_step": v for e, v in med.items()},
            **{f"{e}_cpu_s_per_step": v for e, v in cpu.items()},
            "numpy_over_compiled": med["numpy"] / med["compiled"],
            "numpy_over_compiled_cpu": cpu["numpy"] / cpu["compiled"], "load1": os.getloadavg()[0],
            **{f"{e}_with_statistics_cpu_s_per_step": last[e][0][1] for e in engines},
            **compare(last["compiled"][1], last["numpy"][1], last["compiled"][2], last["numpy"][2])}


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    print(json.dumps(measure(int(a.conditions), a.grade, a.steps, a.repeats, a.settle, a.pin_slope), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
