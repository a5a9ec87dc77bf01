"""Which assumed parameters each answer rests on: a global sensitivity analysis of the headline outputs over the
ranges of the [assumed] parameters (docs/sensitivity.md).

    python -m scenarios.sensitivity [--conditions 2,3] [--directions forward,reverse] [--parameters KEY,...]
        [--range KEY=LOW,HIGH[,log] ...] [--trajectories 10] [--levels 4] [--sobol 4] [--sobol-samples 32]
        [--snapshots 8] [--pinhole "10 um"] [--seed 1] [--params FILE.toml] [--set KEY=VALUE ...]
        [--workers N | --scheduler ADDR] [--overwrite] [--no-progress] [--out DIR]

The factors are the parameters whose assumed value carries its range (``assumed(value, note, span=Span(low, high,
basis, log))`` in :mod:`components.presets`; ``dpgt params`` shows the basis of each value), or those named by
``--parameters``; ``--range`` gives or replaces one. A factor is uniform over its range — over its logarithm for a
range over decades (``log``). The machine is the reference machine with one carrier pinhole error (planet a1's
pinhole ``--pinhole`` off tangentially: the tolerance study's ±10 µm at 3σ at its limit), so that load sharing is
not trivially 1.

Each evaluation is the quasi-static solution (:mod:`components.static`, ``--snapshots`` instants over a carrier
revolution) of one machine, solved on Dask workers and kept as its own small file named by what it was asked
(``evaluations/c{condition}_{direction}/<digest>.json``, written atomically): a restarted or enlarged study reuses
every evaluation made from the same parameters and code. Per operating point: the nominal machine; Morris's
elementary effects (SALib: ``--trajectories`` r trajectories on a ``--levels`` grid) over every factor for
screening; then Sobol's first-order and total indices (SALib: Saltelli's sampling on a scrambled Sobol sequence,
``--sobol-samples`` N base points, N (k + 2) evaluations) over the ``--sobol`` factors of the largest screened
effects, the others held at their reference values. Every interval is SALib's bootstrap 95 % interval.

The outputs (per planet bearing type): the most loaded bearing's mean load and the largest load of any bearing over
the snapshots, the row load sharing K_γ, the weakest bearing's ISO 281 and ISO/TS 16281-style L10 lives and the film
parameter Λ of the thinnest film; the mesh K_γ (the largest of the three meshes). What only a dynamic run gives —
cage slip (the static solution balances each cage but leaves its slip out of the summary), pocket impacts, cage
guide forces, the meshes' dynamic factor and the dynamic largest loads — is left out.

Writes ``ranking.csv`` and ``ranking.md`` (per operating point and output, the factors ranked by μ*, with μ, σ, μ*
as a share of the output's nominal value, and S1, ST where Sobol's indices were estimated), ``sensitivity.json``
(method, factors with their ranges and bases, nominal outputs, Morris and Sobol indices with intervals, cost),
``morris.png``, ``sobol.png`` and ``study.json``.
"""
from __future__ import annotations

import argparse
import csv
import functools
import hashlib
import io
import json
import math
import sys
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np

import mbd
from components.dpgt import build_dpgt
from components.names import did_you_mean
from components.params import DPGTParams, Span, assumed, spans, with_overrides
from components.results import Summary
from components.results.io import atomic_write_text
from components.static import static_summary
from components.units import ParameterError, quantity

from .core import args
from .core.command import command
from .core.integrity import OtherResults, read_summary
from .core.lock import holds_out_folder
from .core.runner import RunConfig, code_digest
from .core.study import Study, StudyRun
from .core.sweep import OPERATING_AXES, Case, build_params, user_overrides, validate_cases
from .core.tasks import solve_tasks

__all__ = ["main", "run", "parse_args", "OUTPUTS", "DYNAMIC_ONLY_OUTPUTS", "Factor", "factors", "Evaluation",
           "evaluate", "static_outputs", "outputs_of", "morris_design", "sobol_design", "morris_indices",
           "sobol_indices", "screen", "ranking_rows", "SensitivityStudy"]

KINDS = ("inner", "outer")
MESHES = ("sun_inner", "inner_outer", "outer_ring")
# the headline outputs a static solution gives: key -> (words, unit)
OUTPUTS = {
    "k_gamma_mesh": ("mesh load sharing K_γ, the largest of the three meshes", "1"),
    **{f"k_gamma_{k}": (f"load sharing K_γ of the {k} planet bearings", "1") for k in KINDS},
    **{f"bearing_load_mean_{k}_N": (f"mean load of the most loaded {k} planet bearing", "N") for k in KINDS},
    **{f"bearing_load_max_{k}_N": (f"largest load of any {k} planet bearing over the snapshots", "N") for k in KINDS},
    **{f"life_iso281_{k}_h": (f"ISO 281 L10 life of the weakest {k} planet bearing", "h") for k in KINDS},
    **{f"life_iso16281_{k}_h": (f"ISO/TS 16281-style L10 life of the weakest {k} planet bearing", "h") for k in KINDS},
    **{f"lambda_min_{k}": (f"film parameter Λ of the thinnest film in the {k} planet bearings", "1") for k in KINDS},
}
# what needs a dynamic run (left out): output -> why
DYNAMIC_ONLY_OUTPUTS = {
    "cage slip": "the static solution balances each cage's rate, but its summary leaves the slip to dynamic runs "
                 "(components.static.DYNAMIC_ONLY)",
    "roller slip, load-zone entry, smearing indicator": "a roller's spin out of the load zone keeps the memory of its "
                                                         "inertia (components.static.DYNAMIC_ONLY)",
    "pocket impacts, cage guide forces, cage accelerations": "collisions and the cage's whirl are motion",
    "dynamic factor K_v, dynamic largest loads": "the meshes' and bearings' dynamic response",
}
RECORD_VERSION = 1             # what an evaluation file holds; another version is evaluated again
PINHOLE_PLANET = "a1"
CONFIDENCE = 0.95
RESAMPLES = 1000

EXAMPLES = ["{prog} --conditions 2,3 --trajectories 10 --sobol 4 --sobol-samples 32 --out results/sensitivity",
            "{prog} --conditions 3 --directions forward --parameters support.sun_stiffness,bearing.clearance --sobol 2",
            '{prog} --range support.sun_stiffness="1e5 N/m,1e9 N/m,log" --trajectories 4 --sobol 0']
WRITES = ("evaluations/c{condition}_{direction}/<digest>.json (one static solution each); ranking.csv, ranking.md, "
          "sensitivity.json, morris.png, sobol.png, study.json")


# ---------------------------------------------------------------------------------------------------------------
# the factors: the assumed parameters with their ranges
# ---------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Factor:
    """One ranged parameter: ``key`` (dotted), its range in SI (``low``, ``high``), ``log`` (uniform in log10), the
    reference value in SI, the SI unit its overrides are written in, how the range and the reference value read in
    their declared units, and the range's basis."""
    key: str
    low: float
    high: float
    log: bool
    nominal: float
    unit: str
    shown: str
    basis: str
    reference: str = ""

    def bounds(self) -> list[float]:
        """The factor's bounds in the design space SALib samples (log10 of the SI value for a log range)."""
        return [math.log10(self.low), math.log10(self.high)] if self.log else [self.low, self.high]

    def value(self, u: float) -> float:
        """The SI value of the design coordinate ``u``."""
        return float(10.0 ** u if self.log else u)

    def override(self, u: float):
        """The override of design coordinate ``u``: a number for a dimensionless factor, else "<SI value> <SI
        unit>"."""
        x = self.value(u)
        return x if self.unit == "dimensionless" else f"{x!r} {self.unit}"


def _range_option(text: str) -> tuple[str, str, str, bool]:
    """--range KEY=LOW,HIGH[,log] -> (key, low, high, log)."""
    key, eq, rest = str(text).partition("=")
    items = [x.strip() for x in rest.strip().strip('"').strip("'").split(",")]
    log = bool(items) and items[-1].lower() == "log"
    items = items[:-1] if log else items
    if not eq or not key.strip() or len(items) != 2 or not all(items):
        raise argparse.ArgumentTypeError(f'expects KEY=LOW,HIGH[,log] (e.g. support.sun_stiffness="1e6 N/m,1e10 N/m,'
                                         f'log"), got {text!r}')
    return key.strip(), items[0], items[1], log


_range_option.__name__ = "range"


def factors(params: DPGTParams, keys: list[str] | None = None, ranges: list[tuple] = ()) -> list[Factor]:
    """The factors of ``params``: every parameter holding an assumed value with its range (``spans``), each
    ``ranges`` entry (key, low, high, log) giving or replacing one (checked like a declared range: known key, a
    quantity of the parameter's kind, low < high, the reference value inside); ``keys`` keeps those named, in that
    order. An unknown or unranged key is refused in one line naming it and the ranged ones."""
    for key, low, high, log in ranges:
        current = _value_at(params, key)
        params = with_overrides(params, {key: assumed(current, "given a range by --range",
                                                      span=Span(low, high, "--range", log))})
    ranged = spans(params)
    chosen = list(ranged) if keys is None else keys
    if not chosen:
        raise ParameterError.at("--parameters", "no parameter to vary")
    out = []
    for key in chosen:
        if key not in ranged:
            raise ParameterError.at(key, f"has no range (not an assumed value with a declared range, nor given one by "
                                         f"--range){did_you_mean(key, ranged)}; ranged: {', '.join(ranged)}")
        s = ranged[key]
        lo, hi = s.low.to_base_units(), s.high.to_base_units()
        nominal = _value_at(params, key)
        out.append(Factor(key, float(lo.magnitude), float(hi.magnitude), s.log,
                          float(quantity(key, nominal, str(lo.units)).to_base_units().magnitude),
                          "dimensionless" if lo.dimensionless else f"{lo.units}",
                          f"{s.low:.3g~P} – {s.high:.3g~P}", s.basis, _shown(nominal)))
    if len({f.key for f in out}) < len(out):
        raise ParameterError.at("--parameters", "a parameter is named twice")
    return out


def _shown(value) -> str:
    return f"{value:.4g~P}" if hasattr(value, "units") else f"{value:.4g}"


def _value_at(params, key: str):
    owner = params
    *path, name = key.split(".")
    try:
        for p in path:
            owner = getattr(owner, p)
        return getattr(owner, name)
    except AttributeError:
        with_overrides(params, {key: None})      # raises the one-line unknown-parameter error, with its near misses
        raise


def problem_of(fs: list[Factor]) -> dict:
    """SALib's problem: the factors' names and bounds in the design space."""
    return {"num_vars": len(fs), "names": [f.key for f in fs], "bounds": [f.bounds() for f in fs]}


# ---------------------------------------------------------------------------------------------------------------
# the evaluations
# ---------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Evaluation:
    """One machine at one operating point (plain data: it travels to any worker): the overrides of its factors'
    values on top of the study's base overrides."""
    condition: int
    direction: str
    overrides: dict            # dotted key -> value (the base machine's and the factors')
    params_file: str | None
    snapshots: int
    evaluator: str             # module:function of the evaluator (its name is part of what was asked)
    folder: str
    varied: tuple = ()         # the factors' keys among the overrides (the rest is the base machine, built once)

    def fingerprints(self) -> tuple[str, str]:
        """(what was asked, that and the code)."""
        text = Path(self.params_file).read_text(encoding="utf-8") if self.params_file else ""
        what = {"condition": self.condition, "direction": self.direction, "overrides": self.overrides,
                "params_file": text, "snapshots": self.snapshots, "evaluator": self.evaluator,
                "record": RECORD_VERSION}
        asked = hashlib.sha256(json.dumps(what, sort_keys=True, default=repr).encode()).hexdigest()[:20]
        return asked, hashlib.sha256(f"{asked}:{code_digest()}".encode()).hexdigest()[:20]

    @property
    def path(self) -> Path:
        return Path(self.folder) / f"{self.fingerprints()[0]}.json"


def outputs_of(s: dict) -> dict:
    """The headline outputs (:data:`OUTPUTS`) of one static summary."""
    q = {}
    ks = []
    for m in MESHES:
        per = np.asarray(s["meshes"][m]["drive_force_mean_per_pair_N"], float)
        ks.append(float(per.max() / per.mean()) if per.mean() > 0.0 else float("nan"))
    q["k_gamma_mesh"] = max(ks)
    for k in KINDS:
        b = s[k]
        q[f"k_gamma_{k}"] = b["load_sharing_factor"]
        q[f"bearing_load_mean_{k}_N"] = max(b["bearing_load_mean_per_planet_N"])
        q[f"bearing_load_max_{k}_N"] = max(b["bearing_load_max_per_planet_N"])
        q[f"life_iso281_{k}_h"] = min(b["life_iso281_per_planet_h"])
        q[f"life_iso16281_{k}_h"] = min(b["life_iso16281_per_planet_h"])
        q[f"lambda_min_{k}"] = b.get("lambda_min", float("nan"))
    return {k: float(q[k]) for k in OUTPUTS}


def static_outputs(params: DPGTParams, snapshots: int) -> dict:
    """The study's evaluator: the quasi-static solution of ``params`` and its headline outputs."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # design warnings were said once by the study
        scene = build_dpgt(params)
    return outputs_of(static_summary(scene, snapshots))


def _evaluator_name(fn: Callable) -> str:
    """What an evaluation file records as its evaluator: ``static`` for the study's own (whether this module runs as
    ``__main__`` or is imported: the same evaluations), else the function's module and name."""
    if fn.__qualname__ == static_outputs.__qualname__ and fn.__module__ in (__name__, "scenarios.sensitivity"):
        return "static"
    return f"{fn.__module__}:{fn.__qualname__}"


def evaluate(task: Evaluation, evaluator: Callable) -> Summary:
    """Evaluate one machine (on whichever process): its record, which :func:`write_evaluation` writes; a failure is a
    record too, with its error (deterministic: the same parameters and code fail again)."""
    asked, full = task.fingerprints()
    head = {"condition": task.condition, "direction": task.direction, "overrides": task.overrides,
            "parameters_fingerprint": asked, "fingerprint": full}
    t0 = time.perf_counter()
    try:
        base = {k: v for k, v in task.overrides.items() if k not in task.varied}
        params = with_overrides(_base_machine(task.condition, task.direction, task.params_file,
                                              json.dumps(base, sort_keys=True)),
                                {k: task.overrides[k] for k in task.varied})
        rec = Summary({**head, "outputs": evaluator(params, task.snapshots), "wall_s": time.perf_counter() - t0})
    except Exception as exc:          # reported, never hidden; the others go on
        rec = Summary({**head, "error": f"{type(exc).__name__}: {' '.join(str(exc).split())}"})
    return rec


def write_evaluation(task: Evaluation, rec: Summary) -> None:
    """Write an evaluation's record as its file, atomically (by the study's process: workers need not share its
    filesystem)."""
    task.path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(task.path, json.dumps(rec, indent=1, default=float))


@functools.lru_cache(maxsize=8)
def _base_machine(condition: int, direction: str, params_file: str | None, base: str) -> DPGTParams:
    """The machine every evaluation of an operating point starts from (``base``: its overrides as JSON), built once
    per process: building the reference machine costs about as much as a fifth of a static solution."""
    return build_params(Case(condition, direction, "", json.loads(base), params_file))


def _failed(rec) -> bool:
    return rec is None or Summary.of(rec).failed


def _earlier(tasks: list[Evaluation]) -> tuple[dict, list[Evaluation]]:
    """({digest: record} of the evaluations made before from the same parameters and code, the ones to make)."""
    done, todo, stale = {}, [], 0
    for t in dict((t.fingerprints()[0], t) for t in tasks).values():
        rec = read_summary(t.path)              # a damaged file is moved aside and made again
        asked, full = t.fingerprints()
        if rec is not None and rec.get("fingerprint") == full:
            done[asked] = dict(rec)
        else:
            stale += rec is not None
            todo.append(t)
    if stale:
        print(f"evaluations: {stale} were made by other code; evaluating them again", flush=True)
    return done, todo


# ---------------------------------------------------------------------------------------------------------------
# the designs and their indices (SALib)
# ---------------------------------------------------------------------------------------------------------------
def morris_design(fs: list[Factor], trajectories: int, levels: int, seed: int) -> np.ndarray:
    """Morris's r trajectories of k + 1 points each on a ``levels`` grid, in the design space (SALib)."""
    from SALib.sample import morris as morris_sample  # deferred: SALib (≈ 0.5 s) only when a design is made

    return morris_sample.sample(problem_of(fs), trajectories, num_levels=levels, seed=seed)


def sobol_design(fs: list[Factor], samples: int, seed: int) -> np.ndarray:
    """Saltelli's N (k + 2) points for first-order and total indices, on a scrambled Sobol sequence (SALib)."""
    from SALib.sample import sobol as sobol_sample  # deferred: SALib only when a design is made

    return sobol_sample.sample(problem_of(fs), samples, calc_second_order=False, scramble=True, seed=seed)


def morris_indices(fs: list[Factor], X: np.ndarray, Y: np.ndarray, levels: int, seed: int) -> dict:
    """{factor: {"mu", "mu_star", "mu_star_ci95", "sigma"}} of one output (SALib's analysis): the elementary effect
    of a factor is the change of the output over a step of the grid divided by that step as a fraction of the
    factor's range, so μ* is the output's mean absolute change over the whole range (of the log for a log factor).
    Trajectories holding a failed evaluation (NaN) are left out; {} if none is whole."""
    from SALib.analyze import morris  # deferred: SALib only when indices are estimated

    k = len(fs)
    Xt, Yt = X.reshape(-1, k + 1, k), np.asarray(Y, float).reshape(-1, k + 1)
    whole = np.isfinite(Yt).all(axis=1)
    if not whole.any():
        return {}
    Xw, Yw = Xt[whole].reshape(-1, k), Yt[whole].reshape(-1)
    r = morris.analyze(problem_of(fs), Xw, Yw, num_resamples=RESAMPLES, conf_level=CONFIDENCE, num_levels=levels,
                       seed=seed)
    out = {}
    for i, f in enumerate(fs):
        ms, half = float(r["mu_star"][i]), float(r["mu_star_conf"][i])
        out[f.key] = {"mu": float(r["mu"][i]), "mu_star": ms, "mu_star_ci95": [ms - half, ms + half],
                      "sigma": float(r["sigma"][i]), "trajectories": int(whole.sum())}
    return out


def sobol_indices(fs: list[Factor], Y: np.ndarray, seed: int) -> dict:
    """{factor: {"S1", "S1_ci95", "ST", "ST_ci95"}} of one output (SALib's Saltelli/Jansen estimators and bootstrap
    intervals); {} if an evaluation failed or the output does not vary."""
    from SALib.analyze import sobol  # deferred: SALib only when indices are estimated

    Y = np.asarray(Y, float)
    if not np.isfinite(Y).all() or not np.ptp(Y) > 0.0:
        return {}
    r = sobol.analyze(problem_of(fs), Y, calc_second_order=False, num_resamples=RESAMPLES, conf_level=CONFIDENCE,
                      seed=seed)
    out = {}
    for i, f in enumerate(fs):
        s1, c1, st, ct = (float(r[x][i]) for x in ("S1", "S1_conf", "ST", "ST_conf"))
        out[f.key] = {"S1": s1, "S1_ci95": [s1 - c1, s1 + c1], "ST": st, "ST_ci95": [st - ct, st + ct]}
    return out


def screen(morris_by_point: dict, keys: list[str], n: int, outputs: list[str] | None = None) -> list[str]:
    """The ``n`` factors of the largest screened effects on ``outputs`` (default: every output): each factor's share
    of an output is its μ* over that output's largest μ* (at one operating point); its score the largest share over
    those outputs and every operating point, ties broken by the mean share; the highest scores, with score > 0."""
    shares: dict[str, list[float]] = {k: [] for k in keys}
    for by_output in morris_by_point.values():
        for out, res in by_output.items():
            if outputs is not None and out not in outputs:
                continue
            top = max((v["mu_star"] for v in res.values()), default=0.0)
            if top > 0.0:
                for key, v in res.items():
                    shares[key].append(v["mu_star"] / top)
    score = {k: (max(v, default=0.0), float(np.mean(v)) if v else 0.0) for k, v in shares.items()}
    ranked = sorted((k for k in keys if score[k][0] > 0.0), key=lambda k: (-score[k][0], -score[k][1]))
    return ranked[:n]


# ---------------------------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------------------------
def ranking_rows(points: dict) -> list[dict]:
    """ranking.csv: per operating point and output, every factor ranked by μ*, with μ, σ, μ* as a share of the
    output's nominal value and, where estimated, Sobol's S1 and ST with their 95 % intervals."""
    rows = []
    for label, p in points.items():
        for out, res in p["morris"].items():
            nominal = (p["nominal"] or {}).get(out)
            sob = p.get("sobol", {}).get(out, {})
            for rank, (key, v) in enumerate(sorted(res.items(), key=lambda kv: -kv[1]["mu_star"]), start=1):
                s = sob.get(key, {})
                rows.append({"condition": p["condition"], "direction": p["direction"], "output": out, "rank": rank,
                             "parameter": key, "mu_star": v["mu_star"], "mu_star_lo": v["mu_star_ci95"][0],
                             "mu_star_hi": v["mu_star_ci95"][1], "mu": v["mu"], "sigma": v["sigma"],
                             "nominal": nominal, "mu_star_pct": (100.0 * v["mu_star"] / abs(nominal)
                                                                 if nominal else None),
                             "S1": s.get("S1"), "S1_lo": (s.get("S1_ci95") or [None])[0],
                             "S1_hi": (s.get("S1_ci95") or [None, None])[1], "ST": s.get("ST"),
                             "ST_lo": (s.get("ST_ci95") or [None])[0], "ST_hi": (s.get("ST_ci95") or [None, None])[1]})
    return rows


def _g(x, fmt=".3g") -> str:
    return "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:{fmt}}"


def factor_table(fs: list[Factor]) -> str:
    """The factors as a markdown table: key, reference value and range in SI, log or linear, basis."""
    L = ["| parameter | reference | range | spread | basis |", "|---|---|---|---|---|"]
    for f in fs:
        L.append(f"| `{f.key}` | {f.reference} | {f.shown} | {'log-uniform' if f.log else 'uniform'} | {f.basis} |")
    return "\n".join(L)


def ranking_markdown(points: dict, top: int = 5, fs: list[Factor] | None = None) -> str:
    """ranking.md: per operating point and output, the ``top`` factors by μ* (with its interval and its share of the
    nominal value) and Sobol's S1, ST with their intervals where estimated; then the factors' ranges (``fs``)."""
    L = ["# Which assumed parameters move the headline outputs", "",
         "μ*: the mean absolute change of the output over the parameter's whole range (Morris's elementary effects, "
         "SALib; for a log range, over its decades), 95 % bootstrap interval in brackets; % of the nominal machine's "
         "value. S1, ST: Sobol's first-order and total indices (shares of the output's variance over the screened "
         "parameters' ranges, the others at their reference values), 95 % intervals in brackets.", ""]
    rows = ranking_rows(points)
    for label, p in points.items():
        L += [f"## Condition {p['condition']}, {p['direction']}", ""]
        for out, (words, unit) in _outputs(p).items():
            mine = [r for r in rows if r["condition"] == p["condition"] and r["direction"] == p["direction"]
                    and r["output"] == out][:top]
            if not mine:
                continue
            L += [f"**{out}** — {words}; nominal {_g(mine[0]['nominal'], '.5g')}" + (f" {unit}" if unit != "1" else ""),
                  "",
                  "| rank | parameter | μ* | % of nominal | μ | σ | S1 | ST |", "|---|---|---|---|---|---|---|---|"]
            for r in mine:
                s1 = f"{_g(r['S1'], '.3f')} ({_g(r['S1_lo'], '.3f')}–{_g(r['S1_hi'], '.3f')})" if r["S1"] is not None \
                    else "–"
                st = f"{_g(r['ST'], '.3f')} ({_g(r['ST_lo'], '.3f')}–{_g(r['ST_hi'], '.3f')})" if r["ST"] is not None \
                    else "–"
                L.append(f"| {r['rank']} | `{r['parameter']}` | {_g(r['mu_star'])} ({_g(r['mu_star_lo'])}–"
                         f"{_g(r['mu_star_hi'])}) | {_g(r['mu_star_pct'], '.2f')} | {_g(r['mu'])} | {_g(r['sigma'])} "
                         f"| {s1} | {st} |")
            L.append("")
    if fs:
        L += ["## The parameters and their ranges", "", factor_table(fs), ""]
    return "\n".join(L)


def _outputs(p: dict) -> dict:
    return {k: OUTPUTS.get(k, (k, "")) for k in p["morris"]}


def _write_csv(path: Path, rows: list[dict]) -> Path:
    cols = list(dict.fromkeys(k for r in rows for k in r))
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols)
    w.writeheader()
    w.writerows(rows)
    atomic_write_text(path, buf.getvalue())
    return path


# ---------------------------------------------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------------------------------------------
def parse_args(argv):
    p = args.parser("sensitivity", __doc__, examples=EXAMPLES, writes=WRITES, out="results/sensitivity")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    p.add_argument("--parameters", default=None, metavar="KEY[,KEY...]",
                   help="the ranged parameters to vary (default: every assumed value with a declared range; "
                        "`dpgt params` lists them)")
    p.add_argument("--range", action="append", default=[], type=_range_option, metavar="KEY=LOW,HIGH[,log]",
                   help='give or replace a parameter\'s range, e.g. --range support.sun_stiffness="1e6 N/m,1e10 N/m,'
                        'log" (repeatable)')
    p.add_argument("--trajectories", type=args.count(2), default=10, metavar="R",
                   help="Morris trajectories (screening: R (k + 1) evaluations per operating point; default 10)")
    p.add_argument("--levels", type=args.count(2), default=4, metavar="P",
                   help="Morris grid levels (even; default 4)")
    p.add_argument("--sobol", type=args.count(0), default=4, metavar="K",
                   help="Sobol indices for the K screened parameters of the largest effects (0: Morris only; "
                        "default 4)")
    p.add_argument("--sobol-outputs", type=args.choice_list(tuple(OUTPUTS), "outputs"), default=None,
                   metavar="OUT[,OUT...]",
                   help="screen for the Sobol indices by these outputs only (e.g. k_gamma_mesh: the load sharing's "
                        "own strongest parameters; default: every output)")
    p.add_argument("--sobol-samples", type=args.count(2), default=32, metavar="N",
                   help="Sobol base samples N, a power of 2 (N (K + 2) evaluations per operating point; default 32)")
    p.add_argument("--snapshots", type=args.count(1), default=8, metavar="N",
                   help="static solutions per machine over a carrier revolution and the mesh cycle (default 8)")
    p.add_argument("--pinhole", type=args.quantity_of("length"), default="10 um", metavar="LENGTH",
                   help=f"tangential pinhole error of planet {PINHOLE_PLANET} (default 10 um: the tolerance study's "
                        f"±10 µm at 3σ at its limit; 0 um: the perfect machine, K_γ = 1)")
    p.add_argument("--seed", type=args.count(0), default=1, help="seed of the designs and bootstraps (default 1)")
    args.add_shared(p, out="results/sensitivity", conditions="2,3",
                    conditions_why="2 and 3: a middle and the fastest loaded speed (2000 and 4200 rpm at 200 kW), "
                                   "to show whether the ranking of the parameters moves with speed")
    a = p.parse_args(argv)
    if "4" in a.conditions.split(","):
        p.error("argument --conditions: condition 4 transmits no torque (0 kW): there is no load to share; "
                "take 1, 2 and/or 3")
    if a.levels % 2:
        p.error(f"argument --levels: Morris needs an even number of levels, got {a.levels}")
    if a.sobol_samples & (a.sobol_samples - 1):
        p.error(f"argument --sobol-samples: must be a power of 2 (Sobol sequence), got {a.sobol_samples}")
    a.parameters = None if a.parameters is None else [x.strip() for x in a.parameters.split(",") if x.strip()]
    a.sobol_outputs = None if a.sobol_outputs is None else a.sobol_outputs.split(",")
    return a


# ---------------------------------------------------------------------------------------------------------------
# the study
# ---------------------------------------------------------------------------------------------------------------
class SensitivityStudy(Study):
    """Everything happens before the (empty) sweep (:meth:`prepare`: per operating point the nominal machine, the
    Morris design, then the Sobol design of the screened factors); :meth:`report` writes the tables and figures."""

    def __init__(self, a, evaluator: Callable = static_outputs):
        super().__init__(a)
        self.evaluator = evaluator
        self.user = user_overrides(args.parse_sets(a.set), a.params, dict(OPERATING_AXES))
        self.base = {**self.user}
        if not any(k.startswith("errors.") for k in self.user):
            self.base["errors.pinhole"] = [{"planet": PINHOLE_PLANET, "radial": "0 um", "tangential": a.pinhole}]
        self.points = [(int(c), d) for c in a.conditions.split(",") for d in a.directions.split(",")]
        reference = build_params(Case(*self.points[0], "", self.base, a.params))
        self.factors = factors(reference, a.parameters, a.range)
        self.records: dict = {}
        self.results: dict = {}
        self.cost = {"evaluated": 0, "reused": 0, "failed": 0, "wall_s": 0.0}

    def config(self) -> RunConfig:
        return RunConfig(integration=mbd.PRODUCTION, progress=not self.a.no_progress)

    def cases(self) -> list[Case]:
        return []                    # static evaluations only (prepare)

    def _tasks(self, cond: int, d: str, fs: list[Factor], X: np.ndarray) -> list[Evaluation]:
        folder = str(self.out / "evaluations" / f"c{cond}_{d}")
        name = _evaluator_name(self.evaluator)
        keys = tuple(f.key for f in fs)
        return [Evaluation(cond, d, {**self.base, **{f.key: f.override(u) for f, u in zip(fs, row)}}, self.a.params,
                           self.a.snapshots, name, folder, keys) for row in np.atleast_2d(X)]

    def _solve(self, tasks: list[Evaluation], what: str) -> list[dict | None]:
        """The records of ``tasks`` in their order (earlier ones reused)."""
        done, todo = _earlier(tasks)
        t0 = time.perf_counter()
        new = solve_tasks(evaluate, todo, workers=self.a.workers, scheduler=self.a.scheduler,
                          progress=not self.a.no_progress, what=what, write=write_evaluation, failed=_failed,
                          extra=(self.evaluator,))
        self.cost["wall_s"] += time.perf_counter() - t0
        self.cost["evaluated"] += len(new)
        self.cost["reused"] += len(done)
        recs = {**done, **{r["parameters_fingerprint"]: r for r in new}}
        out = [recs.get(t.fingerprints()[0]) for t in tasks]
        bad = [Summary.of(r) for r in recs.values() if _failed(r)]
        self.cost["failed"] += len(bad)
        for error in dict.fromkeys(r.error for r in bad):
            n = sum(r.error == error for r in bad)
            print(f"{n} evaluation{'s' if n > 1 else ''} failed (left out of the indices; a Morris trajectory holding "
                  f"one is dropped): {error}", flush=True)
        return out

    @staticmethod
    def _matrix(recs: list[dict | None], outputs: list[str]) -> dict[str, np.ndarray]:
        return {o: np.array([(r or {}).get("outputs", {}).get(o, np.nan) for r in recs], float) for o in outputs}

    def prepare(self, cfg: RunConfig, cases: list[Case]) -> None:
        a = self.a
        validate_cases([Case(c, d, "", self.base, a.params) for c, d in self.points])
        self._refuse_other_settings()
        fs = self.factors
        X = morris_design(fs, a.trajectories, a.levels, a.seed)
        print(f"sensitivity: {len(fs)} parameters, Morris {a.trajectories} trajectories × {len(fs) + 1} points = "
              f"{len(X)} evaluations per operating point, {len(self.points)} operating points", flush=True)
        nominal = np.array([[math.log10(f.nominal) if f.log else f.nominal for f in fs]])
        tasks = {p: (self._tasks(*p, fs, nominal), self._tasks(*p, fs, X)) for p in self.points}
        recs = self._solve([t for p in self.points for part in tasks[p] for t in part], "Morris evaluations")
        at = 0
        for p in self.points:
            n0, n1 = len(tasks[p][0]), len(tasks[p][1])
            nom, mor = recs[at:at + n0], recs[at + n0:at + n0 + n1]
            at += n0 + n1
            outputs = list((nom[0] or {}).get("outputs") or next((r["outputs"] for r in mor if r and "outputs" in r),
                                                                   {}))
            Y = self._matrix(mor, outputs)
            self.results[p] = {"condition": p[0], "direction": p[1], "nominal": (nom[0] or {}).get("outputs"),
                               "morris": {o: morris_indices(fs, X, Y[o], a.levels, a.seed) for o in outputs},
                               "morris_failed": int(sum(map(_failed, mor)))}
        chosen = screen({p: r["morris"] for p, r in self.results.items()}, [f.key for f in fs], a.sobol,
                        a.sobol_outputs)
        self.sobol_factors = [f for f in fs if f.key in chosen]
        self.sobol_factors.sort(key=lambda f: chosen.index(f.key))
        if not self.sobol_factors:
            return
        sf = self.sobol_factors
        Xs = sobol_design(sf, a.sobol_samples, a.seed)
        print(f"sensitivity: Sobol indices of {', '.join(f.key for f in sf)}: {len(Xs)} evaluations per operating "
              f"point", flush=True)
        tasks = {p: self._tasks(*p, sf, Xs) for p in self.points}
        recs = self._solve([t for p in self.points for t in tasks[p]], "Sobol evaluations")
        for i, p in enumerate(self.points):
            mine = recs[i * len(Xs):(i + 1) * len(Xs)]
            Y = self._matrix(mine, list(self.results[p]["morris"]))
            self.results[p]["sobol"] = {o: sobol_indices(sf, Y[o], a.seed) for o in Y}
            self.results[p]["sobol_failed"] = int(sum(map(_failed, mine)))

    def _settings(self) -> dict:
        a = self.a
        return {"conditions": a.conditions, "directions": a.directions, "trajectories": a.trajectories,
                "levels": a.levels, "sobol": a.sobol, "sobol_samples": a.sobol_samples,
                "sobol_outputs": a.sobol_outputs, "snapshots": a.snapshots,
                "seed": a.seed, "base_overrides": self.base, "params_file": a.params,
                "evaluator": _evaluator_name(self.evaluator),
                "factors": [asdict(f) for f in self.factors]}

    def _refuse_other_settings(self) -> None:
        """An --out holding a study of other settings is refused without --overwrite (its evaluations of other
        parameters would stay beside the new ones; its tables would be replaced)."""
        old = read_summary(self.out / "sensitivity.json")
        if old is None or self.a.overwrite:
            return
        mine = json.loads(json.dumps(self._settings(), default=repr))
        if old.get("settings") != mine:
            raise OtherResults(f"{self.out / 'sensitivity.json'} holds a study of other settings; pass --overwrite "
                               f"to replace it, or choose another --out")

    def study_record(self) -> dict:
        return {"settings": self._settings(), "cost": self.cost}

    def report(self, run: StudyRun) -> dict:
        points = {f"c{c}_{d}": r for (c, d), r in self.results.items()}
        text = ranking_markdown(points, top=5, fs=self.factors)
        print(text)
        sf = [f.key for f in getattr(self, "sobol_factors", [])]

        def tables():
            rows = ranking_rows(points)
            files = [_write_csv(self.out / "ranking.csv", rows)]
            atomic_write_text(self.out / "ranking.md", text + "\n")
            atomic_write_text(self.out / "sensitivity.json", json.dumps({
                "settings": json.loads(json.dumps(self._settings(), default=repr)),
                "method": {"screening": "Morris elementary effects (SALib.sample.morris, SALib.analyze.morris): "
                                        "mu_star = mean |EE|, EE = change of the output over a grid step / the step "
                                        "as a fraction of the range (of log10 for a log factor)",
                           "indices": "Sobol first-order S1 and total ST (SALib.sample.sobol without second order, "
                                      "SALib.analyze.sobol), the screened factors uniform over their ranges, the "
                                      "others at their reference values",
                           "intervals": f"{CONFIDENCE:.0%} bootstrap ({RESAMPLES} resamples), SALib's",
                           "machine": f"reference machine with planet {PINHOLE_PLANET}'s pinhole off tangentially by "
                                      f"{self.a.pinhole}",
                           "dynamic_only": DYNAMIC_ONLY_OUTPUTS},
                "outputs": {k: {"words": w, "unit": u} for k, (w, u) in OUTPUTS.items()},
                "sobol_parameters": sf, "cost": self.cost, "points": points}, indent=1, default=float))
            return files + [self.out / "ranking.md", self.out / "sensitivity.json"]

        run.step("tables", tables)
        if points and any(r["morris"] for r in points.values()):
            run.step("figures", _plots, points, self.factors, sf, self.out)
        print(f"evaluations: {self.cost['evaluated']} made now in {self.cost['wall_s']:.0f} s wall, "
              f"{self.cost['reused']} reused, {self.cost['failed']} failed", flush=True)
        return {"points": points, "sobol_parameters": sf}

    @staticmethod
    def exit_code(r: dict) -> int:
        return 1 if r["failed"] or any(p.get("morris_failed") or p.get("sobol_failed") for p in r["points"].values()) \
            else 0


def _plots(points: dict, fs: list[Factor], sobol_keys: list[str], out: Path) -> list[Path]:
    # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn
    from viz.plots import morris_heatmap, sobol_heatmap

    rel = {label: {o: {k: (v["mu_star"] / abs(p["nominal"][o]) if p["nominal"] and p["nominal"].get(o) else np.nan)
                       for k, v in res.items()} for o, res in p["morris"].items()} for label, p in points.items()}
    files = [morris_heatmap(rel, [f.key for f in fs], out / "morris.png",
                            title="Morris μ* of each assumed parameter over its range, as a share of the nominal "
                                  "output (white: below 0.01 %)")]
    if sobol_keys and any(p.get("sobol") for p in points.values()):
        files.append(sobol_heatmap({label: p.get("sobol", {}) for label, p in points.items()}, sobol_keys,
                                   out / "sobol.png", title="Sobol indices of the screened parameters: in each cell "
                                                            "first-order S1 above total ST (intervals: ranking.md)"))
    return files


@holds_out_folder
def run(a) -> dict:
    return SensitivityStudy(a).run()


@command
def main(argv=None) -> int:
    return SensitivityStudy.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
