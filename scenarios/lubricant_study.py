"""Which oil for which direction? The source study's open question, answered with the dynamic model.

    python -m scenarios.lubricant_study [--conditions 3] [--directions forward,reverse]
        [--oil VG32,VG68,VG150 | --viscosities "10,30,100 mPa*s"] [--settle S] [--window S]
        [--set KEY=VALUE ...] [--params FILE] [--workers N | --scheduler ADDR] [--out DIR]

Every condition × direction × lubricant runs through the one runner (resumable, on Dask like the paper
study) with the EHL traction law (``bearing.traction_law = "ehl"``: the oil's viscosity then drives the
roller–raceway traction as well as the film; ``--set bearing.traction_law=tanh`` keeps the dry law).
A grade sets the oil's viscosity at 40 and 100 °C (ISO VG, viscosity at the operating temperature by
Walther); a viscosity sets the dynamic viscosity at the operating temperature directly.

Writes ``summary.csv`` / ``summary.md`` (one row per run and bearing type: film with and without the thermal
reduction, Λ and its regime, traction, loads, cage guide, cage slip, pocket impacts, heat),
``film_and_slip.png`` (Λ with the regimes' bounds, film, cage slip, traction heat against the viscosity) and
the answer in words (``answer.md``, printed): per condition and direction each oil's
thinnest film as Λ = h_min/σ and its regime as the literature names them (Λ ≥ 3 full film; 1 ≤ Λ < 3 partial
EHL, i.e. mixed; Λ < 1 boundary-dominated), whether a cage skids (more than 5 % below its epicyclic speed:
the rollers slide instead of rolling), and the least viscosity for Λ ≥ 1.5 and for a full film (Λ ≥ 3) in
each direction (from the film's η^0.694 growth and its thermal reduction, at the oil nearest the bound) —
so whether reverse wants a stronger oil, and by how much.
"""
from __future__ import annotations

import csv
import io
import math
import sys
from pathlib import Path

from scipy.optimize import brentq

import mbd
from components.lubrication import FULL_FILM_LAMBDA, regime
from components.presets import OIL_GRADES, oil_grade

DEFAULT_GRADES = ("VG32", "VG68", "VG150")     # thin, the reference oil, thick: the study's default span
from components.units import ParameterError, quantity, to_si
from mbd.elements.ehl import FILM_MIN_U_EXPONENT, thermal_factor
from components.results.io import atomic_write_text
from components.skid import SKID_PCT

from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.points import file_without, machine_overrides, point_label, point_order, point_words, points_of
from .core.sweep import Case, build_params, user_overrides
from .core import args
from .core.command import command
from .core.lock import holds_out_folder

__all__ = ["main", "run", "LAMBDA_LEVELS", "SKID_PCT", "COLUMNS", "regime", "least_viscosity"]

LAMBDA_LEVELS = (1.5, FULL_FILM_LAMBDA)   # the least viscosity is reported for each: Λ ≥ 1.5, and full film
COLUMNS = ["condition", "direction", "lubricant", "viscosity_Pa_s", "bearing", "h_min_m", "h_min_isothermal_m",
           "h_mean_m", "thermal_factor_min", "thermal_loading_max", "lambda_min", "lambda_mean", "regime",
           "traction_coefficient_max", "roller_inner_race_rms_N", "roller_inner_race_max_N",
           "roller_outer_race_rms_N", "roller_outer_race_max_N", "cage_guide_rms_N", "cage_slip_pct",
           "pocket_impacts_per_rev", "heat_traction_W", "heat_land_W"]
_FROM_SUMMARY = {"h_min_m": "film_min_m", "h_mean_m": "film_mean_m", "h_min_isothermal_m": "film_min_isothermal_m",
                 "thermal_factor_min": "film_thermal_factor_min", "thermal_loading_max": "film_thermal_loading_max"}


EXAMPLES = ["{prog} --conditions 3 --out results/lubricant", "{prog} --replot --out results/lubricant",
            "{prog} --conditions 1,2,3,4 --oil VG32,VG68,VG150,VG220 --workers 2",
            '{prog} --viscosities "10,30,100 mPa*s" --directions reverse']
WRITES = ("c{condition}_{direction}_{oil}/{results.nc, summary.json} per run; summary.csv and summary.md (a row "
          "per run and bearing type: film with and without its thermal reduction, Λ and its regime, traction, "
          "loads, cage guide, cage slip, pocket impacts, heat); answer.md (the answer in words, also printed); "
          "film_and_slip.png; study.json")


def parse_args(argv):
    p = args.parser("lubricant_study", __doc__, examples=EXAMPLES, writes=WRITES, out="results/lubricant")
    p.add_argument("--directions", default="forward,reverse", type=args.directions, help="comma list: forward, reverse")
    g = p.add_mutually_exclusive_group()
    args.renamed(p, "--grades", "--oils", new=args.OIL)
    g.add_argument(args.OIL, default=None, type=args.choice_list(tuple(OIL_GRADES), "ISO VG grades"), metavar="VG[,VG...]",
                   help=f"comma list of ISO VG grades ({', '.join(OIL_GRADES)}; default {','.join(DEFAULT_GRADES)})")
    g.add_argument("--viscosities", default=None,
                   help='dynamic viscosities at the operating temperature, e.g. "10,30,100 mPa*s"')
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None, help="statistics window [s] (default: the study's rule)")
    p.add_argument("--sample-rate", type=args.positive("Hz"), default=2000.0, help="recording rate [Hz] (statistics use every step)")
    p.add_argument("--replot", action="store_true",
                   help="redraw film_and_slip.png from --out's summary.csv and stop (runs nothing)")
    args.add_shared(p, out="results/lubricant", conditions="3")
    a = p.parse_args(argv)
    if a.replot:        # it runs nothing: an option about runs would be ignored without a word
        given = [act.option_strings[0] for act in p._actions if act.dest not in ("help", "replot", "out", "no_progress")
                 and act.option_strings and getattr(a, act.dest) != act.default]
        if given:
            p.error(f"--replot redraws the figure from --out's summary.csv and runs nothing: {', '.join(given)} "
                    f"would have no effect")
    return a


def lubricants(a) -> dict[str, dict]:
    """label -> parameter overrides of each oil of the study."""
    if a.viscosities:
        text = a.viscosities.strip()
        nums, _, unit = text.partition(" ")
        if not unit.strip():        # a bare number would silently be Pa·s
            raise ParameterError.at("--viscosities", f"give the unit, e.g. \"10,30,100 mPa*s\", got {text!r}")
        out = {}
        for x in nums.split(","):
            q = f"{x.strip()} {unit.strip()}"
            eta = to_si(quantity("--viscosities", q, "dynamic_viscosity"))
            if not eta > 0:
                raise ParameterError.at("--viscosities", f"expected positive viscosities, got {q!r}")
            out[q.replace(" ", "").replace("*", "")] = {"lubricant.oil_viscosity": q}   # a file-name-safe label
        return out
    grades = [s.strip() for s in (a.oil or ",".join(DEFAULT_GRADES)).split(",") if s.strip()]
    return {g: {k: v.value for k, v in oil_grade(g).items()} for g in grades}


def make_cases(a, out: Path) -> list[Case]:
    """Every point (:mod:`scenarios.core.points`) × direction × oil. A ``--params`` file that also sets an oil is
    taken: the sweep's oils replace it (said in one line); a ``--set`` of an oil is refused (it would relabel runs)."""
    dirs = [d.strip() for d in str(a.directions).split(",") if d.strip()]
    if not dirs or any(d not in ("forward", "reverse") for d in dirs):
        raise ParameterError.at("--directions", f"expected forward and/or reverse, got {a.directions!r}")
    oils = "--oil or --viscosities"
    owned = {"lubricant.viscosity_40": oils, "lubricant.viscosity_100": oils, "lubricant.oil_viscosity": oils}
    sets = args.parse_sets(a.set)
    points = points_of(a, sets)
    machine, replaced = file_without(a.params, owned)
    if replaced:
        print(f"note: {a.params} sets {', '.join(replaced)}; this study's oils ({oils}) replace it")
    params_file = None if replaced else a.params       # the file's other overrides travel in the cases then
    user = {"bearing.traction_law": "ehl", **(machine if replaced else {}),
            **machine_overrides(user_overrides(sets, None, owned), points)}
    cases = []
    for lab, ov in lubricants(a).items():
        for p in points:
            for d in ([p.direction] if p.direction else dirs):
                cases.append(Case.at(p, d, str(out / f"{point_label(p, d)}_{lab}"), {**user, **ov}, params_file,
                                     tag=lab))
    return cases


def rows_of(cases: list[Case], results: dict) -> list[dict]:
    rows = []
    for case in cases:
        s = results.get(case.label)
        if s is None or s.failed:
            continue
        eta = build_params(case).si().lubricant.oil_viscosity
        for kind in ("inner", "outer"):
            d = s[kind]
            row = {"condition": case.condition, "direction": case.direction, "lubricant": case.tag,
                   "viscosity_Pa_s": eta, "bearing": kind}
            for col in COLUMNS[5:]:
                v = d.get(_FROM_SUMMARY.get(col, col))
                row[col] = v if v is not None else d.get("all_rollers", {}).get(col)
            row["regime"] = regime(row["lambda_min"])
            rows.append(row)
    return rows


def answer(rows: list[dict]) -> str:
    """The source's question in plain words: per condition and direction, each oil's thinnest film (Λ) and
    its regime, cage skid, and the least viscosity for Λ ≥ 1.5 and for a full film; reverse against forward."""
    lo, hi = LAMBDA_LEVELS
    lines = ["Which oil? Λ = thinnest film (with its thermal reduction) / composite roughness over every loaded "
             "roller contact of both bearing types. Regimes: Λ ≥ 3 full film; 1 ≤ Λ < 3 partial EHL (mixed); "
             f"Λ < 1 boundary-dominated. Skid: cage slip > {SKID_PCT:g} %. Per oil: Λ_min inner/outer, cage slip "
             "inner/outer.", ""]
    need = {}
    for (c, d) in sorted({(r["condition"], r["direction"]) for r in rows}, key=lambda x: (point_order(x[0]), x[1])):
        lines.append(f"{point_words(c)}, {d}:")
        for lab in sorted({r["lubricant"] for r in rows}, key=lambda x: _eta(rows, x)):
            rr = {r["bearing"]: r for r in rows if (r["condition"], r["direction"], r["lubricant"]) == (c, d, lab)}
            if set(rr) != {"inner", "outer"}:
                continue
            lam = min(rr[k]["lambda_min"] for k in rr)
            skid = max(abs(rr[k]["cage_slip_pct"]) for k in rr) > SKID_PCT
            lines.append(f"  {lab:>12} ({1e3 * _eta(rows, lab):.3g} mPa·s): Λ_min {rr['inner']['lambda_min']:.2f} / "
                         f"{rr['outer']['lambda_min']:.2f}, slip {rr['inner']['cage_slip_pct']:.2f} / "
                         f"{rr['outer']['cage_slip_pct']:.2f} % -> {regime(lam)}{', a cage skids' if skid else ''}")
        here = [r for r in rows if (r["condition"], r["direction"]) == (c, d)]
        need[(c, d)] = {level: _needed_viscosity(here, level) for level in LAMBDA_LEVELS}
        lines.append(f"  least viscosity: Λ ≥ {lo:g} from {1e3 * need[(c, d)][lo]:.3g} mPa·s; full film (Λ ≥ {hi:g}) "
                     f"from {1e3 * need[(c, d)][hi]:.3g} mPa·s")
    for c in sorted({k[0] for k in need}, key=point_order):
        f, r = need.get((c, "forward")), need.get((c, "reverse"))
        if f is not None and r is not None:
            parts = [f"Λ ≥ {x:g} {100 * (r[x] / f[x] - 1):+.1f} % ({1e3 * f[x]:.3g} vs {1e3 * r[x]:.3g} mPa·s)"
                     for x in LAMBDA_LEVELS]
            lines.append(f"{point_words(c)}: reverse needs against forward: {'; '.join(parts)}.")
    return "\n".join(lines)


def least_viscosity(eta: float, lam: float, L: float, target: float) -> float:
    """The viscosity η' at which an oil of viscosity ``eta`` with thinnest film ``lam`` (Λ) and thermal loading
    ``L`` there reaches Λ = ``target``, at the same loads and speeds: the isothermal film grows as η^0.694
    (Pan & Hamrock) and L as η, so Λ(η') = lam (η'/eta)^0.694 φ_T(L η'/eta) / φ_T(L) (Murch & Wilson),
    rising in η' (d ln Λ / d ln η = 0.694 − 0.62 x/(3.94 + x) > 0.07, x = L^0.62). β is held at the oil's."""
    def gap(s):      # ln Λ(η' = eta e^s) − ln target
        return (math.log(lam / target) + FILM_MIN_U_EXPONENT * s
                + math.log(thermal_factor(L * math.exp(s)) / thermal_factor(L)))
    return eta * math.exp(brentq(gap, -60.0, 60.0, xtol=1e-12, rtol=1e-12))


def _needed_viscosity(rows: list[dict], target: float) -> float:
    """The least viscosity for Λ_min = ``target`` in both bearing types, from the oil whose Λ is nearest the
    bound (its worse bearing type), by :func:`least_viscosity`."""
    best = min(rows, key=lambda r: abs(math.log(r["lambda_min"] / target)))
    worst = min((r for r in rows if r["lubricant"] == best["lubricant"]), key=lambda r: r["lambda_min"])
    return least_viscosity(worst["viscosity_Pa_s"], worst["lambda_min"], worst["thermal_loading_max"], target)


def _eta(rows, lab) -> float:
    return next(r["viscosity_Pa_s"] for r in rows if r["lubricant"] == lab)


def write_tables(rows: list[dict], out: Path, machine: str = "") -> list[Path]:
    """summary.csv, summary.md and answer.md (the markdown files headed by ``machine``, the machine's name)."""
    head = [f"Machine: {machine}", ""] if machine else []
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=COLUMNS)
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
    """film_and_slip.png: Λ, film, cage slip and traction heat against the viscosity, a line per condition and
    direction (the conditions' own markers when there are several)."""
    from viz.plots import against_viscosity  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn

    conds = sorted({r["condition"] for r in rows}, key=point_order)
    series = {}
    for key in ("lambda_min", "h_min_m", "cage_slip_pct", "heat_traction_W"):
        for r in sorted(rows, key=lambda r: r["viscosity_Pa_s"]):
            k = (key, r["bearing"], r["direction"]) + ((point_words(r["condition"]),) if len(conds) > 1 else ())
            x, y = series.setdefault(k, ([], []))
            x.append(r["viscosity_Pa_s"])
            y.append(r[key])
    at = f", {point_words(conds[0])}" if len(conds) == 1 else ""
    return [against_viscosity(series, [("lambda_min", "film parameter Λ_min = h_min/σ", "1", True),
                                       ("h_min_m", "thinnest film h_min", "m", True),
                                       ("cage_slip_pct", "cage slip", "%", False),
                                       ("heat_traction_W", "traction heat", "W", False)],
                              out / "film_and_slip.png",
                              title=f"Film and cage against the oil's viscosity (at the operating temperature){at}"
                                    + (f" — {machine}" if machine else ""),
                              # the grades by name; a viscosity given as such is its own tick label
                              names={r["lubricant"]: r["viscosity_Pa_s"] for r in rows if r["lubricant"] in OIL_GRADES}
                              or None,
                              levels={"lambda_min": {1.0: "Λ = 1: below, boundary-dominated",
                                                     FULL_FILM_LAMBDA: f"Λ = {FULL_FILM_LAMBDA:g}: full film above"}})]


_TEXT_COLUMNS = ("direction", "lubricant", "bearing", "regime")


def read_rows(path) -> list[dict]:
    """The rows of a study's summary.csv (:data:`COLUMNS`) with their types: the condition a whole number, the
    words as text, every other value a float (None where the study had none)."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    if not rows or set(COLUMNS) - set(rows[0]):
        raise ParameterError.at("--replot", f"{path} is not a lubricant study's summary.csv (columns "
                                            f"{', '.join(sorted(set(COLUMNS) - set(rows[0] if rows else {})))} missing)")
    return [{c: (int(r[c]) if r[c].isdigit() else r[c]) if c == "condition" else r[c] if c in _TEXT_COLUMNS else
             (float(r[c]) if r[c] != "" else None) for c in COLUMNS} for r in rows]


def replot(out: Path) -> list[Path]:
    """film_and_slip.png redrawn from ``out``/summary.csv, without running anything (``--replot``)."""
    path = Path(out) / "summary.csv"
    if not path.is_file():
        raise ParameterError.at("--replot", f"no summary.csv in {out} (run the study there first)")
    files = plot(read_rows(path), Path(out))
    print("figures: " + ", ".join(str(f) for f in files))
    return files


def write_outputs(rows: list[dict], out: Path) -> list[Path]:
    """The tables and the figure (module docstring)."""
    return write_tables(rows, out) + plot(rows, out)


class LubricantStudy(Study):
    """Every condition × direction × oil (:class:`scenarios.core.study.Study`): the answer first, then the tables and
    the figure."""

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
    if a.replot:
        return {"failed": {}, "files": replot(Path(a.out))}
    return LubricantStudy(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
