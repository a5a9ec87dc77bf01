"""What manufacturing tolerances do to load sharing and bearing life: the distribution of K_γ, planet-bearing loads
and lives over machines drawn from stated tolerances (docs/tolerances.md).

    python -m scenarios.tolerance_study [--samples 64] [--torques 0.25,0.5,1] [--conditions 3]
        [--directions forward,reverse] [--gear-class 5,7] [--pinhole-tolerance "10 um"] [--clearance-tolerance "5 um"]
        [--roller-lot "2 um"] [--dynamic 16] [--snapshots 16] [--seed 1] [--settle S] [--window S]
        [--params FILE.toml] [--set KEY=VALUE ...] [--workers N | --scheduler ADDR] [--force] [--overwrite] [--out DIR]

Every sample is one machine: its gears' teeth and runouts for an ISO 1328 class, its 2N pinholes, each bearing's
clearance and each roller's diameter drawn from their tolerances (:mod:`components.tolerance_sampling`: the
distributions, a scrambled Sobol sequence of ``--seed``). Each machine is solved quasi-statically
(:mod:`components.static`, ``--snapshots`` instants over a carrier revolution and the mesh cycle) at every class, condition,
direction and torque (``--torques``: fractions of the condition's rated output torque); the first ``--dynamic``
machines, and the perfect machine, also run dynamically (the runner of the other studies, on Dask) at the largest
torque, for the static solution's agreement and the dynamic increment. Each static solution is its own small file
(``static/…/sample_NNNN.json``, written atomically): a restarted or enlarged study reuses those made from the same
parameters and code, and refuses, without ``--overwrite``, a folder holding ones of other parameters.

Writes ``samples.csv`` (a row per machine, class, condition, direction and torque: the drawn errors, K_γ per planet
row and per mesh, bearing mean and largest load per bearing type, the weakest bearing's ISO 281 and ISO/TS 16281-style
lives), ``statistics.json`` (mean, P50, P90, P99 of K_γ and the loads, P10 of the lives, each with a 95 %
interval; the P90 of K_γ against the number of samples), ``agreement.csv`` (static against dynamic), the figures
``k_gamma_distribution.png``, ``k_gamma_torque.png``, ``life_cdf.png`` and ``answer.md`` (the answer in words).
"""
from __future__ import annotations

import argparse
import contextlib
import csv
import hashlib
import io
import json
import math
import sys
import time
import warnings
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
from scipy.stats import t as student_t

import mbd
from components.dpgt import build_dpgt
from components.static import DEFAULT_SNAPSHOTS, STATIC_LIVES_NOTE, static_summary
from components.tolerance_sampling import (DISTRIBUTIONS, TOLERANCE_DEFAULTS, ToleranceSpec, coordinates, draw_errors,
                                           replicate_of, sobol_points, teeth_seed)
from components.units import ParameterError, quantity, to_si
from components.results import Summary
from components.results.io import atomic_write_text

from .core import args
from .core.command import command
from .core.integrity import OtherResults, read_summary
from .core.lock import holds_out_folder
from .core.runner import RunConfig, code_digest
from .core.study import Study, StudyRun
from .core.points import Point, machine_overrides, point_label, point_order, point_words, points_of
from .core.sweep import Case, build_params, user_overrides, validate_cases
from .core.tasks import scheduling_share, solve_tasks

__all__ = ["main", "run", "parse_args", "QUANTITIES", "MESHES", "quantities_of", "percentile_ci", "statistics",
           "agreement_rows", "sample_rows", "sample_columns", "answer", "StaticTask", "static_tasks", "solve_static_task"]

MESHES = ("sun_inner", "inner_outer", "outer_ring")
KINDS = ("inner", "outer")
# what each machine yields, from a summary (static or dynamic): column -> (words, unit)
QUANTITIES = {
    "k_gamma_mesh": ("mesh load sharing K_γ, the largest of the three meshes", "1"),
    **{f"k_gamma_{m}": (f"load sharing K_γ of the {m.replace('_', '–')} mesh", "1") for m in MESHES},
    **{f"k_gamma_{k}": (f"load sharing of the {k} planet bearings", "1") for k in KINDS},
    **{f"bearing_load_mean_{k}_N": (f"mean load of the most loaded {k} planet bearing", "N") for k in KINDS},
    **{f"bearing_load_max_{k}_N": (f"largest load of any {k} planet bearing", "N") for k in KINDS},
    **{f"life_iso281_{k}_h": (f"ISO 281 L10 life of the weakest {k} planet bearing", "h") for k in KINDS},
    **{f"life_iso16281_{k}_h": (f"ISO/TS 16281-style L10 life of the weakest {k} planet bearing", "h") for k in KINDS},
}
LIVES = [k for k in QUANTITIES if k.startswith("life_")]
HEADLINE = "k_gamma_mesh"
AGREE = ("k_gamma_mesh", "k_gamma_inner", "k_gamma_outer", "bearing_load_mean_inner_N", "bearing_load_mean_outer_N",
         "bearing_load_max_inner_N", "bearing_load_max_outer_N")
PERCENTILES = {"p50": 50.0, "p90": 90.0, "p99": 99.0}
RECORD_VERSION = 1       # what a static result file holds (_kept); another version is solved again
TABLE_K_GAMMA = 1.0      # the rating tables' K_γ for up to three planets (docs/tolerances.md: what was found, cited)

EXAMPLES = ["{prog} --samples 64 --conditions 3 --gear-class 5,7 --dynamic 2 --out results/tolerances",
            "{prog} --samples 1024 --conditions 2,3 --torques 0.25,0.5,1 --workers 2",
            '{prog} --gear-class 6 --pinhole-tolerance "20 um" --clearance-tolerance "5 um" --dynamic 0']
WRITES = ("static/class{C}/c{condition}_{direction}_t{torque}/sample_NNNN.json and static/perfect_c{condition}_"
          "{direction}_t{torque}.json (one static solution each); "
          "c{condition}_{direction}_t{torque}_{classC_sNNNN|perfect}/{results.nc, summary.json} per dynamic run; "
          "samples.csv, statistics.json, agreement.csv, k_gamma_distribution.png, k_gamma_torque.png, life_cdf.png, "
          "answer.md (also printed), study.json")


# ---------------------------------------------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------------------------------------------
def _tolerance(text: str) -> float:
    """A tolerance: a length >= 0 with its unit -> m."""
    try:
        x = to_si(quantity("value", text, "length"))
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(exc.problem or f"expected a length with its unit, got {text!r}") from None
    if not x >= 0.0:
        raise argparse.ArgumentTypeError(f"must be a length >= 0 (a tolerance), got {text!r}")
    return x


_tolerance.__name__ = "length with its unit"


def _fractions(text: str) -> list[float]:
    """A comma list of fractions > 0 of the rated torque (order kept, repeats refused)."""
    items = [x.strip() for x in str(text).split(",") if x.strip()]
    if not items:
        raise argparse.ArgumentTypeError(f"expected a comma list of fractions of the rated torque, got {text!r}")
    out = []
    for x in items:
        try:
            f = float(x)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected fractions of the rated torque (e.g. 0.5), got {x!r}") from None
        if not (math.isfinite(f) and f > 0.0):
            raise argparse.ArgumentTypeError(f"a fraction of the rated torque must be > 0, got {x!r}")
        out.append(f)
    if len(set(out)) < len(out):
        raise argparse.ArgumentTypeError(f"torque fractions repeat in {text!r}")
    return out


_fractions.__name__ = "comma list of torque fractions"


def parse_args(argv):
    d = TOLERANCE_DEFAULTS
    p = args.parser("tolerance_study", __doc__, examples=EXAMPLES, writes=WRITES, out="results/tolerances")
    p.add_argument("--samples", type=args.count(1), default=64, metavar="N",
                   help="machines drawn per class (randomised QMC: --replicates scrambled Sobol sequences of --seed; "
                        "default 64)")
    p.add_argument("--torques", type=_fractions, default=[1.0], metavar="F[,F...]",
                   help="fractions > 0 of each condition's rated output torque (default 1)")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    args.renamed(p, "--grades", "--classes", "--gear-grade", new=args.GEAR_CLASS)
    p.add_argument(args.GEAR_CLASS, type=args.int_list(1, 11, "ISO 1328 classes"), default=d["classes"][0],
                   metavar="CLASS[,CLASS...]",
                   help=f"ISO 1328-1:2013 flank tolerance classes 1..11, each with its runout tolerance 0.9 F_pT "
                        f"(default {d['classes'][0]})")
    p.add_argument("--pinhole-tolerance", type=_tolerance, default=d["pinhole"][0], metavar="LENGTH",
                   help=f"carrier pinhole position tolerance, radial and tangential, ± at 3σ, with its unit (default "
                        f"{d['pinhole'][0]} {d['pinhole'][1]})")
    p.add_argument("--clearance-tolerance", type=_tolerance, default=d["clearance"][0], metavar="LENGTH",
                   help=f"each bearing's diametral clearance uniform within the nominal ± this, with its unit (default "
                        f"{d['clearance'][0]} {d['clearance'][1]})")
    p.add_argument("--roller-lot", type=_tolerance, default=d["roller_lot"][0], metavar="LENGTH",
                   help=f"diameter variation of a bearing's rollers (roller grade), uniform, with its unit (default "
                        f"{d['roller_lot'][0]} {d['roller_lot'][1]}: grade G2)")
    p.add_argument("--dynamic", type=args.count(0), default=16, metavar="N",
                   help="the first N machines of each class, condition and direction also run dynamically (with the "
                        "perfect machine) at the largest torque, resumable (default 16; 0: static only)")
    p.add_argument("--snapshots", type=args.count(1), default=DEFAULT_SNAPSHOTS, metavar="N",
                   help=f"static solutions per machine over a carrier revolution and the mesh cycle (default "
                        f"{DEFAULT_SNAPSHOTS})")
    p.add_argument("--seed", type=args.count(0), default=1, help="seed of the Sobol sequences and of the teeth (default 1)")
    p.add_argument("--replicates", type=args.count(2), default=8, metavar="R",
                   help="independent scramblings of the Sobol sequence (randomised QMC): machine i belongs to replicate "
                        "i mod R, and every interval comes from the R replicates' spread (default 8)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="dynamic runs: seconds discarded (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="dynamic runs: seconds analysed (default: the paper study's, whole cage revolutions)")
    args.add_shared(p, out="results/tolerances", conditions="3")
    a = p.parse_args(argv)
    if "4" in a.conditions.split(","):
        p.error("argument --conditions: condition 4 transmits no torque (0 kW): there is no load to share; "
                "take 1, 2 and/or 3")
    a.torques = sorted(a.torques)
    a.spec = {c: ToleranceSpec(c, a.pinhole_tolerance, a.clearance_tolerance, a.roller_lot,
                               float(d["systematic_share"][0])) for c in a.gear_class}
    return a


# ---------------------------------------------------------------------------------------------------------------
# the machines and their static solutions
# ---------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StaticTask:
    """One machine at one operating point, solved statically (plain data: it travels to any worker)."""
    case: Case                   # the parameters: condition, direction, overrides (torque and errors), params file
    path: str                    # its result file
    snapshots: int
    flank_class: int | None      # None: the perfect machine (no errors; shared by every class)
    torque: float                # fraction of the rated output torque
    sample: int | None           # None: the perfect machine
    drawn: dict

    def key(self) -> tuple:
        return (self.flank_class, self.case.condition, self.case.direction, self.torque, self.sample)

    def fingerprints(self) -> tuple[str, str]:
        """(what was asked, that and the code): the parameters' description — base machine, overrides, the file's
        text, snapshots — cheap to compare for thousands of files (the parameters are built from it alone)."""
        text = Path(self.case.params_file).read_text(encoding="utf-8") if self.case.params_file else ""
        what = {"condition": self.case.condition, "direction": self.case.direction, "overrides": self.case.overrides,
                "params_file": text, "snapshots": self.snapshots, "record": RECORD_VERSION,
                **({"point": self.case.point} if self.case.point is not None else {})}
        asked = hashlib.sha256(json.dumps(what, sort_keys=True, default=repr).encode()).hexdigest()[:16]
        full = hashlib.sha256(f"{asked}:{code_digest()}".encode()).hexdigest()[:16]
        return asked, full


def _torque_tag(f: float) -> str:
    return f"t{f:g}"


def _nominal_power(condition: int, direction: str, params_file, user: dict) -> float:
    """The condition's rated output power [W] of the machine (the base of the torque fractions)."""
    return build_params(Case(condition, direction, "", dict(user), params_file)).si().operating.output_power


def machines(a, si) -> dict[int, tuple[dict, dict]]:
    """{class: [(overrides, drawn) per sample]}: every sample's errors (the same Sobol points for every class)."""
    N, Z = si.layout.planets, si.bearing.rollers
    u = sobol_points(a.samples, len(coordinates(N, Z)), a.seed, a.replicates)
    return {c: [draw_errors(si, a.spec[c], u[i], teeth_seed(a.seed, i)) for i in range(a.samples)] for c in a.gear_class}


def _scaled(p: Point, d: str, f: float, power: float, user: dict, params_file):
    """The case maker of point ``p`` in direction ``d`` at ``f`` × its power ``power`` [W]: a condition's case with
    the power overridden (as it always was), a user point's with its load replaced."""
    if p.is_preset:
        op = {**user, "operating.output_power": f"{f * power:.17g} W"}
        return lambda folder, ov=None: Case(p.condition, d, folder, {**op, **(ov or {})}, params_file)
    q = replace(p, load=f"{f * power:.17g} W")
    return lambda folder, ov=None: Case.at(q, d, folder, {**user, **(ov or {})}, params_file)


def static_tasks(a, out: Path, user: dict, points: list[Point]) -> list[StaticTask]:
    """The perfect machine and every sample at every class, operating point, direction and torque."""
    tasks = []
    for p in points:
        for d in ([p.direction] if p.direction else a.directions.split(",")):
            nominal = build_params(Case.at(p, d, "", dict(user), a.params))
            power = nominal.si().operating.output_power
            if power == 0:
                raise ParameterError.at(f"point {p.name}", "transmits no torque (0 W): there is no load to share")
            drawn = machines(a, nominal.si())
            for f in a.torques:
                case = _scaled(p, d, f, power, user, a.params)
                point = f"{point_label(p, d)}_{_torque_tag(f)}"
                tasks.append(StaticTask(case(str(out / "static")),
                                        str(out / "static" / f"perfect_{point}.json"), a.snapshots, None, f, None, {}))
                for c in a.gear_class:
                    folder = out / "static" / f"class{c}" / point
                    for i, (ov, dr) in enumerate(drawn[c]):
                        tasks.append(StaticTask(case(str(folder), ov),
                                                str(folder / f"sample_{i:04d}.json"), a.snapshots, c, f, i, dr))
    return tasks


def quantities_of(s: dict) -> dict:
    """The study's quantities of one machine from its summary (static or dynamic: the same keys)."""
    q = {}
    ks = {}
    for m in MESHES:
        per = np.asarray(s["meshes"][m]["drive_force_mean_per_pair_N"], float)
        ks[m] = float(per.max() / per.mean()) if per.mean() > 0.0 else float("nan")
    q["k_gamma_mesh"] = max(ks.values())
    q.update({f"k_gamma_{m}": v for m, v in ks.items()})
    for k in KINDS:
        b = s[k]
        q[f"k_gamma_{k}"] = b["load_sharing_factor"]
        q[f"bearing_load_mean_{k}_N"] = max(b["bearing_load_mean_per_planet_N"])
        q[f"bearing_load_max_{k}_N"] = max(b["bearing_load_max_per_planet_N"])
        q[f"life_iso281_{k}_h"] = min(b["life_iso281_per_planet_h"])
        q[f"life_iso16281_{k}_h"] = min(b["life_iso16281_per_planet_h"]) if "life_iso16281_per_planet_h" in b \
            else float("nan")
    return q


def solve_static_task(task: StaticTask) -> Summary:
    """Solve one machine (on whichever process): its record, which :func:`write_static` writes. A failure is a record
    too (with its error): the solution is deterministic, so the same parameters and code fail again — a re-run does
    not try it again unless the code changed."""
    asked, full = task.fingerprints()
    head = {"class": task.flank_class, "condition": task.case.condition, "direction": task.case.direction,
            "torque_fraction": task.torque, "sample": task.sample, "drawn": task.drawn,
            "parameters_fingerprint": asked, "fingerprint": full}
    try:
        params = build_params(task.case)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # design warnings were said once by the study
            scene = build_dpgt(params)
        s = static_summary(scene, task.snapshots)
        op = params.si().operating
        rec = Summary({**head, "summary": _kept(s), "output_torque_N_m": op.output_power / abs(op.carrier_speed),
                       "static_solver": s["static_solver"], "snapshots": s["snapshots"]})
    except Exception as exc:      # reported in the tables, never hidden; the others go on
        rec = Summary({**head, "error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"})
    return rec


def write_static(task: StaticTask, rec: Summary) -> None:
    """Write a machine's record as its result file, atomically (by the study's process: workers need not share its
    filesystem)."""
    Path(task.path).parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(Path(task.path), json.dumps(rec, indent=1, default=float))


# what a result file keeps of a summary: what :func:`quantities_of` reads (so a change of the study's quantities
# needs no new solutions)
_KEPT = {kind: ("load_sharing_factor", "bearing_load_mean_all_N", "bearing_load_mean_per_planet_N",
                "bearing_load_max_per_planet_N", "life_iso281_per_planet_h", "life_iso16281_per_planet_h")
         for kind in KINDS}


def _kept(s: dict) -> dict:
    out = {kind: {k: s[kind][k] for k in keys if k in s[kind]} for kind, keys in _KEPT.items()}
    out["meshes"] = {m: {"drive_force_mean_per_pair_N": s["meshes"][m]["drive_force_mean_per_pair_N"]} for m in MESHES}
    return out


def _with_quantities(rec: Summary) -> Summary:
    return Summary({**rec, "quantities": quantities_of(rec["summary"])}) if "summary" in rec else rec


def _earlier(tasks: list[StaticTask], overwrite: bool) -> tuple[dict, list[StaticTask]]:
    """({key: record} of the tasks solved before from the same parameters and code, the tasks to solve). A result
    file of other parameters is refused (:class:`OtherResults`) unless ``overwrite``; of other code, recomputed."""
    done, todo, others, stale = {}, [], [], 0
    for t in tasks:
        rec = read_summary(t.path)           # a damaged file is moved aside and recomputed
        if rec is None:
            todo.append(t)
            continue
        asked, full = t.fingerprints()
        if rec.get("fingerprint") == full:
            done[t.key()] = rec
            continue
        if rec.get("parameters_fingerprint") != asked and not overwrite:
            others.append(t.path)
        stale += rec.get("parameters_fingerprint") == asked
        todo.append(t)
    if others:
        raise OtherResults(f"{len(others)} static solutions (e.g. {others[0]}) were made from other parameters, "
                           f"tolerances or seed; pass --overwrite to replace them, or choose another --out")
    if stale:
        print(f"static: {stale} solutions were made by other code; recomputing them", flush=True)
    return done, todo


def solve_all(todo: list[StaticTask], workers: int | None, scheduler: str | None, progress: bool,
              stats: dict | None = None) -> dict:
    """{key: record} of ``todo`` solved in this process (one worker) or on Dask (:func:`scenarios.core.tasks.solve_tasks`:
    in batches of about a second of work, two per worker in flight; a line every 10 s, or a bar on a terminal, says how
    far it is), each result file written here as it arrives. ``stats``: filled as :func:`solve_tasks` does."""
    recs = solve_tasks(solve_static_task, todo, workers=workers, scheduler=scheduler, progress=progress,
                       what="static solutions", write=write_static, failed=lambda r: r.failed, stats=stats)
    return {(r["class"], r["condition"], r["direction"], r["torque_fraction"], r["sample"]): r for r in recs}


# ---------------------------------------------------------------------------------------------------------------
# statistics
# ---------------------------------------------------------------------------------------------------------------
def fewest_samples(q: float) -> int:
    """The fewest values of which Hazen's q-th percentile (q in %) is not simply the smallest or the largest: its
    plotting positions (i − ½)/m hold q/100 strictly between two of them only when ½/m < min(q, 100 − q)/100,
    m > 50/min(q, 100 − q) (P90 and P10: 6, P99: 51)."""
    return math.floor(50.0 / min(q, 100.0 - q) + 1e-9) + 1


def too_few_samples(samples: int, replicates: int) -> list[str]:
    """The percentiles the study reports (P50, P90, P99 of K_γ and loads, P10 of the lives) that ``samples`` machines
    in ``replicates`` replicates cannot give: each replicate's percentile would be its largest (or smallest) value."""
    m = samples // replicates
    out = []
    for name, q in (*PERCENTILES.items(), ("p10", 10.0)):
        need = fewest_samples(q)
        if m < need:
            out.append(f"{name.upper()} from {m} machine{'s' if m != 1 else ''} per replicate (--samples {samples} / "
                       f"--replicates {replicates}) is each replicate's {'largest' if q > 50 else 'smallest'} value, "
                       f"not a percentile: it needs {need} per replicate, --samples {need * replicates} or more")
    return out


def percentile_ci(x, q: float | None, replicate) -> dict:
    """{"value", "ci95"}: the mean (``q`` None) or the q-th percentile of ``x`` by randomised QMC: the statistic of each
    independent replicate (``replicate`` the replicate of each value,
    :func:`components.tolerance_sampling.replicate_of`) holding 2 or more values, their mean as the estimate and
    mean ± t(0.975, R − 1)·s_R/√R as its 95 % interval. Percentiles are Hazen's ((i − ½)/n plotting positions:
    unbiased on the evenly spread points of a Sobol net, where numpy's default is biased by half a point spacing).
    Fewer than 2 such replicates: the statistic of all values, no interval; equal values: no interval."""
    x, rep = np.asarray(x, float), np.asarray(replicate)
    ok = np.isfinite(x)
    x, rep = x[ok], rep[ok]
    if x.size == 0:
        return {"value": None, "ci95": None}
    stat = np.mean if q is None else (lambda v: np.percentile(v, q, method="hazen"))
    est = [stat(x[rep == r]) for r in np.unique(rep) if np.count_nonzero(rep == r) >= 2]
    if len(est) < 2:
        return {"value": float(stat(x)), "ci95": None}
    value = float(np.mean(est))
    if np.unique(x).size < 2:
        return {"value": value, "ci95": None}
    half = float(student_t.ppf(0.975, len(est) - 1) * np.std(est, ddof=1) / math.sqrt(len(est)))
    return {"value": value, "ci95": [value - half, value + half]}


def _order(key: tuple) -> tuple:
    c, cond, d, f, i = key
    return (-1 if c is None else c, point_order(cond), d, f, -1 if i is None else i)


def _groups(records: dict) -> dict:
    """{(class, condition, direction, torque): {"perfect": rec|None, "samples": [rec, ...] in sample order}}: every
    class's group with the perfect machine of its operating point."""
    g: dict = {}
    perfect = {k[1:4]: r for k, r in records.items() if k[4] is None}
    for (c, cond, d, f, i), rec in sorted(records.items(), key=lambda kv: _order(kv[0])):
        if i is not None:
            g.setdefault((c, cond, d, f), {"perfect": perfect.get((cond, d, f)), "samples": []})["samples"].append(rec)
    return g


def _column(samples: list[dict], key: str) -> np.ndarray:
    return np.array([r["quantities"][key] for r in samples if "quantities" in r], float)


def _replicates(samples: list[dict], replicates: int) -> np.ndarray:
    """The replicate of every sample of ``samples`` that has quantities (as :func:`_column` orders them)."""
    return replicate_of(np.array([r["sample"] for r in samples if "quantities" in r], int), replicates)


def convergence(x, replicate, replicates: int) -> dict:
    """The P90 of ``x`` (in sample order) with its interval at 2R, 4R, 8R, … samples (R = ``replicates``: every
    replicate as many) and all of them, and the smallest of those counts from which every later estimate lies inside
    the final interval."""
    x, rep = np.asarray(x, float), np.asarray(replicate)
    R = int(replicates)
    ns = [n for n in (R * 2 ** k for k in range(1, 30)) if n < x.size] + [x.size]
    steps = [{"samples": int(n), **percentile_ci(x[:n], 90.0, rep[:n])} for n in ns]
    final = steps[-1]["ci95"]
    settled = None
    if final is not None:
        for i, s in enumerate(steps):
            if all(final[0] <= t["value"] <= final[1] for t in steps[i:]):
                settled = s["samples"]
                break
    return {"p90": steps, "settled_at_samples": settled}


def statistics(records: dict, replicates: int, dynamic: dict | None = None) -> list[dict]:
    """Per class, condition, direction and torque: the perfect machine's quantities, the samples' mean, P50, P90 and
    P99 of every K_γ and load and the P10 of every life, each with its 95 % interval over the ``replicates``
    independent replicates (:func:`percentile_ci`), and the P90 of the
    mesh K_γ against the number of samples; where machines ran dynamically too (``dynamic``: {task key: summary}),
    the mean and P90 of K_γ over those machines, static and dynamic side by side."""
    out = []
    for (c, cond, d, f), e in _groups(records).items():
        ok = [r for r in e["samples"] if "quantities" in r]
        g = {"class": c, "condition": cond, "direction": d, "torque_fraction": f,
             "output_torque_N_m": (ok or [e["perfect"] or {}])[0].get("output_torque_N_m"),
             "samples": len(ok), "failed": [{"sample": r["sample"], "error": r.error}
                                            for r in map(Summary.of, e["samples"]) if r.failed],
             "perfect_machine": (e["perfect"] or {}).get("quantities"), "quantities": {}}
        rep = _replicates(ok, replicates)
        for key in QUANTITIES:
            x = _column(ok, key)
            if key in LIVES:
                g["quantities"][key] = {"p10": percentile_ci(x, 10.0, rep)}
            else:
                g["quantities"][key] = {"mean": percentile_ci(x, None, rep),
                                        **{k: percentile_ci(x, q, rep) for k, q in PERCENTILES.items()}}
        g["convergence"] = {HEADLINE: convergence(_column(ok, HEADLINE), rep, replicates)} if ok else {}
        both = [(r, dynamic[(c, cond, d, f, r["sample"])]) for r in ok if (c, cond, d, f, r["sample"]) in (dynamic or {})]
        if both:
            g["dynamic_subset"] = {"samples": len(both)}
            sub = replicate_of(np.array([r["sample"] for r, _ in both], int), replicates)
            for key in ("k_gamma_mesh", "k_gamma_inner", "k_gamma_outer"):
                st = np.array([r["quantities"][key] for r, _ in both])
                dy = np.array([quantities_of(sm)[key] for _, sm in both])
                g["dynamic_subset"][key] = {
                    way: {"mean": percentile_ci(x, None, sub), "p90": percentile_ci(x, 90.0, sub)}
                    for way, x in (("static", st), ("dynamic", dy))}
        out.append(g)
    return out


# ---------------------------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------------------------
def sample_rows(records: dict) -> list[dict]:
    """samples.csv: a row per machine (the perfect machine's rows marked ``perfect``), drawn errors and quantities."""
    rows = []
    for (c, cond, d, f, i), r in sorted(records.items(), key=lambda kv: _order(kv[0])):
        row = {"class": "" if c is None else c, "condition": cond, "direction": d, "torque_fraction": f,
               "output_torque_N_m": r.get("output_torque_N_m"),
               "sample": "perfect" if r["sample"] is None else r["sample"], **r.get("drawn", {}),
               **r.get("quantities", {k: None for k in QUANTITIES}),
               "static_solve_s": (r.get("static_solver") or {}).get("wall_s"), "error": Summary.of(r).error or ""}
        rows.append(row)
    return rows


def sample_columns(rows: list[dict]) -> list[str]:
    """samples.csv's columns: the operating point and sample, the drawn errors, the quantities, cost and error."""
    head = ["class", "condition", "direction", "torque_fraction", "output_torque_N_m", "sample"]
    tail = [*QUANTITIES, "static_solve_s", "error"]
    drawn = dict.fromkeys(k for r in rows for k in r if k not in head and k not in tail)
    return head + list(drawn) + tail


def agreement_rows(records: dict, dynamic: dict[tuple, dict]) -> list[dict]:
    """agreement.csv: per dynamic run (``dynamic``: {task key: its summary}) the static and dynamic values of
    K_γ and the bearing loads, the dynamic increment (dynamic − static) and, for loads, its share of the static
    value in %."""
    rows = []
    for key, s in sorted(dynamic.items(), key=lambda kv: _order(kv[0])):
        rec = records.get(key)
        if rec is None or "quantities" not in rec:
            continue
        dq = quantities_of(s)
        c, cond, d, f, i = key
        row = {"class": "" if c is None else c, "condition": cond, "direction": d, "torque_fraction": f,
               "sample": "perfect" if i is None else i}
        for q in AGREE:
            st, dy = rec["quantities"][q], dq[q]
            row[f"{q}_static"], row[f"{q}_dynamic"], row[f"{q}_increment"] = st, dy, dy - st
            if q.endswith("_N"):
                row[f"{q}_increment_pct"] = 100.0 * (dy - st) / st
        rows.append(row)
    return rows


def _write_csv(path: Path, rows: list[dict], cols: list[str] | None = None) -> Path:
    cols = cols or list(dict.fromkeys(k for r in rows for k in r))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols)
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(path, buf.getvalue())
    return path


def _ci(v: dict, fmt: str = ".3f") -> str:
    if v is None or v.get("value") is None:
        return "–"
    ci = v.get("ci95")
    return f"{v['value']:{fmt}}" + (f" ({ci[0]:{fmt}}–{ci[1]:{fmt}})" if ci else "")


def answer(stats: list[dict], agree: list[dict], a_record: dict) -> str:
    """The answer in words (answer.md): per condition and class the K_γ a designer should use at this tolerance
    (P90 and P99 of the mesh K_γ at the rated torque, forward and reverse), against the rating tables' 1.0 for three
    planets; the planet bearings' load sharing and weakest lives against the perfect machine's; how K_γ changes with
    torque; how many samples the P90 took; the static solution against the dynamic runs."""
    L = ["# What the tolerances do to load sharing and bearing life", "",
         f"{a_record['samples']} machines per class drawn from: {a_record['tolerances']}. K_γ of a mesh: the most loaded "
         "planet pair's mean drive-flank force over the mean of the pairs (ISO 6336's mesh load factor); of a "
         "bearing row: the most loaded planet bearing's mean load over the row's mean (the bearing load includes "
         "the planets' centrifugal load). Values: the statistic with its 95 % interval (over the independent "
         "replicates) in brackets. The lives' percentiles are static: " + STATIC_LIVES_NOTE + ".", ""]
    top = max(g["torque_fraction"] for g in stats)
    for cond in sorted({g["condition"] for g in stats}, key=point_order):
        L.append(f"## {point_words(cond).capitalize()}")
        for c in sorted({g["class"] for g in stats}):
            rated = {g["direction"]: g for g in stats if g["condition"] == cond and g["class"] == c
                     and g["torque_fraction"] == top}
            if not rated:
                continue
            L.append(f"### ISO 1328 class {c}, {top:g} × rated torque")
            for d, g in rated.items():
                k = g["quantities"][HEADLINE]
                perf = (g["perfect_machine"] or {}).get(HEADLINE, float("nan"))
                conv = g["convergence"].get(HEADLINE, {})
                L.append(f"- {d}: design mesh K_γ P90 = {_ci(k['p90'])}, P99 = {_ci(k['p99'])} (median "
                         f"{_ci(k['p50'])}; the perfect machine's static K_γ {perf:.4f}) against the rating tables' "
                         f"{TABLE_K_GAMMA:.1f} for three planets: the table is "
                         f"{'unconservative' if (k['p90']['value'] or 0) > TABLE_K_GAMMA else 'conservative'} for "
                         f"9 in 10 machines by {100 * ((k['p90']['value'] or 1) - TABLE_K_GAMMA):.1f} % of the mean "
                         f"mesh load. {g['samples']} samples"
                         + (f" ({len(g['failed'])} more failed: the static solver found no state; left out, listed in "
                            f"statistics.json — if failures favour large errors, the upper percentiles are low)"
                            if g["failed"] else "")
                         + ("; the P90 against the number of samples: " + ", ".join(
                             f"{x['samples']}: {x['value']:.4f}" for x in conv.get("p90", []))
                            + (f" (inside the final interval from {conv['settled_at_samples']} samples on)"
                               if conv.get("settled_at_samples") else "") + "." if conv.get("p90") else "."))
                sub = g.get("dynamic_subset")
                if sub:
                    st, dy = sub[HEADLINE]["static"], sub[HEADLINE]["dynamic"]
                    runs = "s also run" if sub["samples"] != 1 else " also runs"
                    L.append(f"  - the {sub['samples']} machine{runs} dynamically: mesh K_γ mean {_ci(dy['mean'])}, "
                             f"P90 {_ci(dy['p90'])} dynamic against mean {_ci(st['mean'])}, P90 {_ci(st['p90'])} "
                             f"static (the same machines)")
                for kind in KINDS:
                    kb = g["quantities"][f"k_gamma_{kind}"]
                    parts = []
                    for life in (f"life_iso281_{kind}_h", f"life_iso16281_{kind}_h"):
                        p10 = g["quantities"][life]["p10"]
                        nominal = (g["perfect_machine"] or {}).get(life)
                        if p10["value"] is not None and nominal:
                            parts.append(f"{'ISO 281' if '281_' in life and '16281' not in life else 'ISO/TS 16281-style'} "
                                         f"P10 {p10['value']:.1f} h ({100 * (p10['value'] / nominal - 1):+.1f} % against "
                                         f"the perfect machine's {nominal:.1f} h)")
                    L.append(f"  - {kind} planet bearings: load sharing P90 {_ci(kb['p90'], '.4f')}; weakest bearing's "
                             f"life " + "; ".join(parts))
            if len(rated) == 2:
                f_, r_ = (rated[x]["quantities"][HEADLINE]["p90"] for x in ("forward", "reverse"))
                if f_["ci95"] and r_["ci95"]:
                    overlap = f_["ci95"][0] <= r_["ci95"][1] and r_["ci95"][0] <= f_["ci95"][1]
                    L.append(f"- reverse against forward: P90 {r_['value']:.4f} against {f_['value']:.4f}: "
                             + ("their intervals overlap — no difference this sample resolves."
                                if overlap else "their intervals do not overlap — rotation sense changes it."))
            torques = sorted({g["torque_fraction"] for g in stats if g["condition"] == cond and g["class"] == c})
            if len(torques) > 1:
                for d in sorted({g["direction"] for g in stats}):
                    seq = [g for t in torques for g in stats if g["condition"] == cond and g["class"] == c
                           and g["direction"] == d and g["torque_fraction"] == t]
                    L.append(f"- {d}, K_γ against torque (P50 / P90): " + ", ".join(
                        f"{g['torque_fraction']:g} × ({g['output_torque_N_m']:.0f} N·m): "
                        f"{g['quantities'][HEADLINE]['p50']['value']:.4f} / {g['quantities'][HEADLINE]['p90']['value']:.4f}"
                        for g in seq))
            L.append("")
    if agree:
        L += ["## Static against dynamic", ""]
        for cond in sorted({r["condition"] for r in agree}, key=point_order):
            for d in sorted({r["direction"] for r in agree if r["condition"] == cond}):
                rs = [r for r in agree if r["condition"] == cond and r["direction"] == d and r["sample"] != "perfect"]
                p = [r for r in agree if r["condition"] == cond and r["direction"] == d and r["sample"] == "perfect"]
                if not rs and not p:
                    continue
                inc = np.array([r[f"{HEADLINE}_increment"] for r in rs])
                loads = np.array([r[f"bearing_load_mean_{k}_N_increment_pct"] for r in rs for k in KINDS])
                words = (f"- {point_words(cond)}, {d}: over {len(rs)} machine{'s' if len(rs) > 1 else ''} the dynamic mesh "
                         f"K_γ minus the static one is {inc.mean():+.4f} on average (from {inc.min():+.4f} to "
                         f"{inc.max():+.4f}, RMS {np.sqrt(np.mean(inc ** 2)):.4f}) — the dynamic increment and the static "
                         f"estimate's error together (its snapshots see each mesh's teeth at a few instants of a carrier "
                         f"revolution, a dynamic run at every one); "
                         f"the most loaded bearings' mean loads differ by {np.abs(loads).max():.2f} % at most"
                         if rs else f"- {point_words(cond)}, {d}:")
                if p:
                    words += (f"; the perfect machine: static {p[0][f'{HEADLINE}_static']:.4f}, dynamic "
                              f"{p[0][f'{HEADLINE}_dynamic']:.4f}")
                L.append(words + ".")
        L.append("")
    cost = a_record.get("static_cost") or {}
    if cost.get("per_machine_s_median"):
        L += ["## Cost", "", f"Static solutions: {cost['solved_now']} solved now in {cost['wall_s']:.0f} s wall, "
              f"{cost['per_machine_s_median']:.2f} s per machine ({cost['per_snapshot_s_median'] * 1e3:.0f} ms per "
              f"snapshot; medians of the solver's own time), {cost['reused']} reused, {cost['failed']} failed.", ""]
    L += ["The rating tables: up to three planets K_γ = 1.0 (ABS, as the FVA Workbench documents it: 4 planets 1.2, "
          "5: 1.3, 6 and more: 1.4); AGMA 6123-B06 gives a table of K_γ by the number of planets that published work "
          "calls vague as to tolerance and load (docs/tolerances.md cites both). A floating or semi-floating sun is "
          "what lets three planets share equally; here the sun sits on 1e8 N/m [assumed].", ""]
    return "\n".join(L)


# ---------------------------------------------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------------------------------------------
def plots(records: dict, stats: list[dict], out: Path, machine: str = "") -> list[Path]:
    """The study's three figures; ``machine`` names the machine in their titles."""
    # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn
    from viz.plots import tolerance_against_torque, tolerance_distributions, tolerance_life_cdf

    on = f" — {machine}" if machine else ""
    groups = _groups(records)
    dist = {(cond, f): {} for (_, cond, _, f) in groups}
    for (c, cond, d, f), e in groups.items():
        dist[(cond, f)][(c, d)] = _column(e["samples"], HEADLINE)
    failed = sum(1 for e in groups.values() for r in e["samples"] if "quantities" not in r)
    files = [tolerance_distributions(dist, out / "k_gamma_distribution.png",
                                     title="Mesh load sharing K_γ of machines drawn from their tolerances"
                                           + (f" ({failed} without a static solution left out)" if failed else "") + on)]
    bands = {}
    for g in stats:
        k = g["quantities"][HEADLINE]
        bands.setdefault((g["condition"], g["direction"]), {}).setdefault(g["class"], []).append(
            (g["output_torque_N_m"], k["p50"]["value"], k["p90"]["value"]))
    files.append(tolerance_against_torque(bands, out / "k_gamma_torque.png",
                                          title="Mesh K_γ against the output torque: median and P90 of the machines" + on))
    top = max(f for (_, _, _, f) in groups)
    cdfs = {}
    for (c, cond, d, f), e in groups.items():
        if f != top:
            continue
        for life in LIVES:
            kind = "inner" if "_inner_" in life else "outer"
            std = "ISO/TS 16281-style" if "16281" in life else "ISO 281"
            nominal = (e["perfect"] or {}).get("quantities", {}).get(life)
            cdfs.setdefault((cond, kind, std), {})[(c, d)] = (_column(e["samples"], life), nominal)
    files.append(tolerance_life_cdf(cdfs, out / "life_cdf.png",
                                    title=f"Weakest planet bearing's L10 life at {top:g} × rated torque against the "
                                          f"perfect machine's (dotted){on}"))
    return files


# ---------------------------------------------------------------------------------------------------------------
# the study
# ---------------------------------------------------------------------------------------------------------------
class ToleranceStudy(Study):
    """Static solutions of every machine first (:meth:`prepare`), then the dynamic subset through the skeleton's
    sweep, then the tables, figures and answer (:meth:`report`)."""

    def __init__(self, a):
        super().__init__(a)
        sets = args.parse_sets(a.set)
        self.points = points_of(a, sets)
        self.user = machine_overrides(user_overrides(sets, a.params, {
            "errors": "the tolerance options (--gear-class, --pinhole-tolerance, --clearance-tolerance, --roller-lot)"}),
            self.points)
        self.tasks = static_tasks(a, self.out, self.user, self.points)
        self.too_few = too_few_samples(a.samples, a.replicates)
        for w in self.too_few:                   # said before anything runs, and again above the answer
            print(f"warning before the run: {w}", flush=True)
        self.records: dict = {}
        self.cost: dict = {}

    def config(self) -> RunConfig:
        a = self.a
        return RunConfig(settle=a.settle, window=a.window, integration=mbd.PRODUCTION, progress=not a.no_progress)

    def _dynamic_tasks(self) -> list[StaticTask]:
        top = max(self.a.torques)
        return [t for t in self.tasks if self.a.dynamic > 0 and t.torque == top
                and (t.sample is None or t.sample < self.a.dynamic)]

    def cases(self) -> list[Case]:
        out = []
        for t in self._dynamic_tasks():
            who = "perfect" if t.sample is None else f"class{t.flank_class}_s{t.sample:04d}"
            tag = f"{_torque_tag(t.torque)}_{who}"
            label = replace(t.case, tag=tag).label          # c3_forward_TAG, or the point's name and TAG
            out.append(replace(t.case, out_dir=str(self.out / label), tag=tag))
        return out

    def study_record(self) -> dict:
        a = self.a
        return {"samples": a.samples, "seed": a.seed, "replicates": a.replicates, "snapshots": a.snapshots,
                "torques": a.torques,
                "classes": a.gear_class, "tolerances": self._tolerance_words(),
                "distributions": DISTRIBUTIONS, "sampler": "randomised QMC: --replicates independently scrambled scipy.stats.qmc.Sobol "
                                                       "sequences of --seed, machine i in replicate i mod R; inverse CDFs",
                "defaults": {k: {"value": v[0], "source": v[1], "basis": v[2]} for k, v in TOLERANCE_DEFAULTS.items()},
                "static_cost": self.cost}

    def _tolerance_words(self) -> str:
        a = self.a
        return (f"ISO 1328 classes {', '.join(map(str, a.gear_class))} (teeth and runout), pinholes ± "
                f"{a.pinhole_tolerance * 1e6:g} µm at 3σ, bearing clearance nominal ± {a.clearance_tolerance * 1e6:g} µm "
                f"(uniform), roller lot {a.roller_lot * 1e6:g} µm (uniform)")

    def prepare(self, cfg: RunConfig, cases: list[Case]) -> None:
        """Check the static tasks (each operating point's perfect machine and first sample; refuse other
        parameters' results), then solve every machine not solved before."""
        firsts = {}
        for t in self.tasks:
            firsts.setdefault((t.key()[:4], t.sample is None), t.case)
        # the design warnings were said once already if the sweep has cases (the same machine)
        with contextlib.redirect_stdout(io.StringIO()) if cases else contextlib.nullcontext():
            validate_cases(list(firsts.values()))
        done, todo = _earlier(self.tasks, self.a.overwrite)
        failed = sum(r.failed for r in done.values())
        print(f"static: {len(todo)} solutions to solve, {len(done)} reused (same parameters and code"
              + (f"; {failed} of them failed, and fail again with them" if failed else "") + f"); "
              f"{len(self.tasks)} machines × operating points", flush=True)
        t0, dask_stats = time.perf_counter(), {}
        new = solve_all(todo, self.a.workers, self.a.scheduler, not self.a.no_progress, dask_stats)
        wall = time.perf_counter() - t0
        self.records = {k: _with_quantities(r) for k, r in {**done, **new}.items()}
        solved = [r["static_solver"]["wall_s"] for r in new.values() if "static_solver" in r]
        self.cost = {"solved_now": len(solved), "reused": len(done),
                     "failed": sum(r.failed for r in self.records.values()),
                     "wall_s": wall, "per_machine_s_median": float(np.median(solved)) if solved else None,
                     "per_snapshot_s_median": float(np.median(solved)) / self.a.snapshots if solved else None,
                     "batches": dask_stats.get("batches", 0), "scheduling_share": scheduling_share(dask_stats)}
        if solved:
            share = self.cost["scheduling_share"]
            print(f"static: {len(solved)} solved in {wall:.0f} s wall ({dask_stats.get('workers', 1)} workers, "
                  f"{self.cost['batches']} batches), {self.cost['per_machine_s_median']:.2f} s per machine "
                  f"({self.a.snapshots} snapshots; median); the workers spent {100 * (1 - share):.1f} % of their time "
                  f"solving", flush=True)

    def report(self, run: StudyRun) -> dict:
        a = self.a
        by_label = {c.label: t.key() for c, t in zip(run.cases, self._dynamic_tasks())}
        dynamic = {by_label[k]: s for k, s in run.results.items() if k in by_label}
        stats = statistics(self.records, a.replicates, dynamic)
        agree = agreement_rows(self.records, dynamic)
        record = {"samples": a.samples, "tolerances": self._tolerance_words(), "static_cost": self.cost}
        text = answer(stats, agree, record)
        if self.too_few:                          # a percentile that is an extreme value is not a finding
            text = "\n".join(["**Not findings** — these percentiles are extreme values of too few samples (the "
                               "others stand):",
                               *(f"- {w}" for w in self.too_few), "", text])
        print(text)                               # the headline first
        rows = sample_rows(self.records)

        def tables():
            files = [_write_csv(self.out / "samples.csv", rows, sample_columns(rows))]
            atomic_write_text(self.out / "statistics.json", json.dumps(
                {"method": {**self.study_record(), "intervals": "95 %: the statistic over all machines ± "
                                                                "t(0.975, R − 1)·s_R/√R, s_R its spread over the R "
                                                                "replicates"},
                 "quantities": {k: {"words": w, "unit": u} for k, (w, u) in QUANTITIES.items()},
                 "groups": stats}, indent=1, default=float))
            files.append(self.out / "statistics.json")
            if agree:
                files.append(_write_csv(self.out / "agreement.csv", agree))
            atomic_write_text(self.out / "answer.md", f"Machine: {self.machine_identity()['label']}\n\n" + text + "\n")
            return files + [self.out / "answer.md"]

        run.step("tables", tables)
        if any("quantities" in r for r in self.records.values()):
            run.step("figures", plots, self.records, stats, self.out, self.machine_identity()["label"])
        return {"statistics": stats, "agreement": agree, "static": self.records}

    @staticmethod
    def exit_code(r: dict) -> int:
        failed = bool(r["failed"]) or any(x.failed for x in r["static"].values())
        return 1 if failed else 0


@holds_out_folder
def run(a) -> dict:
    return ToleranceStudy(a).run()


@command
def main(argv=None) -> int:
    return ToleranceStudy.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
