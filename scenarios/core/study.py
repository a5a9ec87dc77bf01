"""One skeleton for every sweep study: cases → validate → check runs and folders → sweep → rows →
write → epilogue.

A study is a subclass of :class:`Study` that says what is particular to it — its run settings (:meth:`config`),
its cases (:meth:`cases`), its own check of a case (:meth:`check`) and what it makes of the runs
(:meth:`report`: rows, the headline table, files) — and inherits the rest, in the same order and with the same
words in every study:

1. every case's parameters converted and its design checked before anything runs (design warnings once);
2. the recordings checked against the limit and the disk (``--force``), the folders against results of other
   parameters (``--overwrite``); then the study's own work before its sweep, if any (:meth:`Study.prepare`);
3. the sweep (:func:`scenarios.core.sweep.sweep`): each case an :class:`~scenarios.core.sweep.Outcome`, finished, reused
   or failed; then, if the study chooses more cases from those results (:meth:`Study.second_phase`), their checks
   and a second sweep;
4. the study's report: its headline table first, then one line per post-processing step (:meth:`StudyRun.step`:
   tables, figures, animation);
5. the epilogue: each run's wall time and error estimate (a reused run marked "reused", with the wall time of
   the run that made it), its warnings, the failed runs, the files written.

A new study writes those four methods and a parser (:func:`scenarios.core.args.parser` and
:func:`scenarios.core.args.add_shared` for the shared options).
"""
from __future__ import annotations

import abc
import dataclasses
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, ClassVar

from components.results import Summary
from components.static import check_steady
from components.results.io import atomic_write_text, write_summary

from .args import parse_sets
from .integrity import read_summary
from .points import machine_identity
from .memory import process_peak_mb
from .plausibility import check_runs, estimated_wall_s
from .runner import RunConfig, run_report
from .sweep import (Beside, Case, Outcome, Status, _case_cfg, _is_finished, build_params, check_folders, join_closing,
                    resume_times, sweep, validate_cases)

__all__ = ["Study", "StudyRun", "run_lines", "runs_line", "TIMING_ENV"]

# a file name: Study.run writes there where the study's time went (wall seconds of the checks, the sweep and its
# phases, the report and each of its steps; the study process's peak memory; each run's process and span)
TIMING_ENV = "DPGT_TIMING"


@dataclass
class StudyRun:
    """A study after its sweep: its cases, their outcomes, and the files its report writes."""
    out: Path
    cases: list[Case]
    outcomes: dict[str, Outcome]
    files: list[Path] = field(default_factory=list)
    kept: dict[str, dict] = field(default_factory=dict)    # failed now, but finished before: the earlier summary
    step_s: dict[str, float] = field(default_factory=dict)  # wall seconds of each post-processing step
    beside: dict = field(default_factory=dict)   # what the work beside the runs gave, per group (Study.beside)

    @property
    def results(self) -> dict[str, Summary]:
        """{label: summary} of every run the tables can use: finished and reused ones, and a failed one's earlier
        summary (marked ``stale_after_failure`` with the error) when the study keeps those."""
        out = {k: Summary.of(o.summary) for k, o in self.outcomes.items() if o.ok}
        out.update({k: Summary({**s, "stale_after_failure": self.outcomes[k].error}) for k, s in self.kept.items()})
        return out

    @property
    def failed(self) -> dict[str, str]:
        """{label: what went wrong} of every failed run."""
        return {k: o.error for k, o in self.outcomes.items() if not o.ok}

    def step(self, what: str, make: Callable[..., list], *a, **kw) -> list[Path]:
        """One post-processing step (tables, figures, animation): make its files and say so in one line."""
        t0 = time.perf_counter()
        paths = [Path(p) for p in (make(*a, **kw) or [])]
        self.step_s[what] = self.step_s.get(what, 0.0) + time.perf_counter() - t0
        self.files += paths
        names = ", ".join(p.name for p in paths)
        print(f"{what}: {names if paths else 'nothing to write'}", flush=True)
        return paths


def runs_line(outcomes: dict[str, Outcome]) -> str:
    """How many runs finished now, were reused from earlier runs and failed, in one line."""
    n = {st: sum(o.status is st for o in outcomes.values()) for st in Status}
    return (f"runs: {n[Status.FINISHED]} finished now, {n[Status.REUSED]} reused (finished earlier with the same "
            f"parameters, settings and code), {n[Status.FAILED]} failed")


def run_lines(outcomes: dict[str, Outcome]) -> list[str]:
    """Each run's wall time, steps and error estimate, then its warnings, a line each; a reused run is marked so,
    with the wall time of the run that made its results."""
    lines = []
    for k, o in sorted(outcomes.items()):
        if not o.ok or not ("error_estimate" in (o.summary or {}) or (o.summary or {}).get("mode") == "static"):
            continue
        first, *warns = run_report(o.summary)
        if o.status is Status.REUSED:
            first = f"reused (its results are from an earlier run of the same parameters and code: {first})"
        lines += [f"  {k}: {first}", *(f"  {k}: {w}" for w in warns)]
    return lines


class Study(abc.ABC):
    """The skeleton of a sweep study (module docstring). ``a``: the parsed command line, with at least the shared
    options ``--out``, ``--force``, ``--overwrite``, ``--workers``, ``--scheduler`` and ``--no-progress``."""

    keep_earlier: ClassVar[bool] = False   # a run that fails now but finished before keeps its summary in the tables
    record: ClassVar[bool] = True          # write study.json: the cases and the failed runs

    def __init__(self, a):
        self.a = a
        self.out = Path(a.out)

    # -- what a study says ------------------------------------------------------------------------------------
    @abc.abstractmethod
    def config(self) -> RunConfig:
        """The runs' settings (step, window, recording)."""

    @abc.abstractmethod
    def cases(self) -> list[Case]:
        """Every run of the study."""

    def _check(self, case: Case, cfg: RunConfig) -> None:
        """The checks every study makes of a case (a static solution needs a steady operating point), then its own."""
        if _case_cfg(case, cfg).mode == "static":
            check_steady(build_params(case))
        self.check(case, cfg)

    def check(self, case: Case, cfg: RunConfig) -> None:
        """A study's own check of a case before anything runs (raise ParameterError to refuse it)."""

    @abc.abstractmethod
    def report(self, run: StudyRun) -> dict:
        """Rows, the headline table (printed first) and the files (:meth:`StudyRun.step`); returns what the
        study's result holds besides results, outcomes, failed and files."""

    def study_record(self) -> dict:
        """What study.json holds besides the cases and the failed runs."""
        return {}

    def machine_identity(self) -> dict:
        """The machine the study runs (said first, kept in study.json): its ``--params`` file's name, a short
        fingerprint and the ``--set`` overrides (not the operating point's), :func:`scenarios.core.points.machine_identity`."""
        sets = {k: v for k, v in parse_sets(getattr(self.a, "set", None) or []).items() if not k.startswith("operating.")}
        return machine_identity(getattr(self.a, "params", None), sets)

    def prepare(self, cfg: RunConfig, cases: list[Case]) -> None:
        """A study's own work after every check and before its sweep (the tolerance study's static solutions)."""

    def table_report(self, run: StudyRun, rows: list[dict], answer: Callable, tables: Callable,
                     figures: Callable) -> dict:
        """The report of a study that is one table of rows: ``answer(rows)`` in words first, then ``tables`` and
        ``figures`` (each called with the rows, the out folder and the machine's label)."""
        text = answer(rows) if rows else ""
        print(text)                          # the headline first
        if rows:
            label = self.machine_identity()["label"]
            run.step("tables", tables, rows, self.out, label)
            run.step("figures", figures, rows, self.out, label)
        return {"rows": rows, "answer": text}

    def beside(self, cfg: RunConfig) -> Beside | None:
        """Work done group by group while the other runs go on (:class:`~scenarios.core.sweep.Beside`: a point's
        figures as soon as its runs are in); its results reach :meth:`report` as ``run.beside``. None by default."""
        return None

    def second_phase(self, run: StudyRun) -> list[Case]:
        """Cases chosen from the first sweep's results, run in a second sweep with the same checks before it starts
        (the duty cycle's dynamic runs of the bins that carry the damage); none by default."""
        return []

    # -- the skeleton -----------------------------------------------------------------------------------------
    def run(self) -> dict:
        """Cases → validate → check runs and folders → sweep → report → epilogue; returns {"results",
        "outcomes", "failed", "files", ...the report's}. With the environment variable ``DPGT_TIMING`` set to a file
        name, where the study's time went is written there as JSON (:data:`TIMING_ENV`; ``scenarios.bench_study
        --profile`` reads it)."""
        a = self.a
        t0 = time.perf_counter()
        cfg = self.config()
        if getattr(a, "threads", 1) != 1:     # a run's engine threads (--threads): the same results, not a setting
            cfg = dataclasses.replace(cfg, threads=a.threads)
        cases = self.cases()
        validate_cases(cases, lambda c: self._check(c, cfg))     # every parameter checked before any run starts
        machine = self.machine_identity()
        print(f"machine: {machine['label']}", flush=True)
        self.out.mkdir(parents=True, exist_ok=True)
        advice: list = []
        for w in check_runs([(c.label, build_params(c), _case_cfg(c, cfg)) for c in cases], self.out, a.force, advice):
            print(f"warning (--force): {w}")
        check_folders(cases, cfg, a.overwrite)                  # never replace results of other parameters silently
        self.say_before(cases, cfg, advice)
        t_prepare = time.perf_counter()
        self.prepare(cfg, cases)
        t_sweep, sweep_timing = time.perf_counter(), {}
        beside = self.beside(cfg)
        # the local cluster closes behind the study (its workers' exit, seconds) while the report is drawn
        outcomes = sweep(cases, cfg, workers=a.workers, scheduler=a.scheduler, progress=not a.no_progress,
                         overwrite=a.overwrite, announce=True, timing=sweep_timing, beside=beside, close_behind=True)
        self._stamp(outcomes, machine)
        run = StudyRun(self.out, cases, outcomes, beside=beside.done if beside is not None else {})
        more = self.second_phase(run)
        if more:                          # the same checks, then a second sweep; its outcomes join the first's
            validate_cases(more, lambda c: self._check(c, cfg))
            advice = []
            for w in check_runs([(c.label, build_params(c), _case_cfg(c, cfg)) for c in more], self.out, a.force,
                                advice):
                print(f"warning (--force): {w}")
            check_folders(more, cfg, a.overwrite)
            self.say_before(more, cfg, advice)
            join_closing()              # the first sweep's cluster closed before the second one's starts
            second = sweep(more, cfg, workers=a.workers, scheduler=a.scheduler, progress=not a.no_progress,
                           overwrite=a.overwrite, announce=True, timing=sweep_timing.setdefault("second_phase", {}),
                           close_behind=True)
            self._stamp(second, machine)
            outcomes = {**outcomes, **second}
            cases = [*cases, *more]
            run = StudyRun(self.out, cases, outcomes, beside=run.beside)
        print(runs_line(outcomes), flush=True)
        t_report = time.perf_counter()
        if self.keep_earlier:
            run.kept = self._earlier(run)
        extra = self.report(run)
        t_join = time.perf_counter()
        join_closing()                  # the cluster closing behind the report (sweep_timing: cluster_close_wait_s)
        t_end = time.perf_counter()
        if os.environ.get(TIMING_ENV):
            atomic_write_text(Path(os.environ[TIMING_ENV]), json.dumps({
                "checks_s": t_prepare - t0, "prepare_s": t_sweep - t_prepare, "sweep_s": t_report - t_sweep,
                "sweep": sweep_timing, "report_s": t_join - t_report, "steps_s": run.step_s, "total_s": t_end - t0,
                "peak_rss_MB": process_peak_mb(), "runs": {k: o.span for k, o in outcomes.items()}}, indent=1))
        if self.record:
            atomic_write_text(self.out / "study.json", json.dumps(
                {"machine": machine, "cases": [dataclasses.asdict(c) for c in cases], **self.study_record(),
                 "failed": run.failed},
                indent=2, default=str))
        r = {"results": run.results, "outcomes": outcomes, "failed": run.failed, "files": run.files, **extra}
        self.epilogue(run)
        return r

    def say_before(self, cases: list[Case], cfg: RunConfig, advice: list) -> None:
        """Before the sweep: what the runs would get wrong (:func:`scenarios.core.plausibility.run_advice`), each
        distinct warning once with the runs it concerns, and the estimated wall time of the runs still to run."""
        said: dict[str, list[str]] = {}
        for item in advice:
            if item[0] != "time":
                said.setdefault(item[1], []).append(item[0])
        for msg, labels in said.items():
            who = ", ".join(labels[:3]) + (f" and {len(labels) - 3} more" if len(labels) > 3 else "")
            print(f"warning before the run ({who}): {msg}", flush=True)
        todo = [c for c in cases if not _is_finished(c, cfg)]
        done, labels = resume_times(todo, cfg), {c.label for c in todo}    # a resumed run: only the rest of its time
        runs = [(label, t if t is None else max(t - done.get(label, 0.0), 0.0))
                for kind, label, t in (x for x in advice if x[0] == "time") if label in labels]
        if not runs:
            return
        workers = getattr(self.a, "workers", None) or min(len(runs), os.cpu_count() or 1)
        n_dyn = sum(t is not None for _, t in runs)
        est = estimated_wall_s(runs, workers)
        print(f"estimated run time: ≈ {_duration(est)} for {len(runs)} run{'s' if len(runs) > 1 else ''} to run "
              f"({n_dyn} dynamic, {len(runs) - n_dyn} static) on {workers} worker{'s' if workers > 1 else ''} "
              f"(measured rates of a shared 2-core machine; yours differ)", flush=True)

    @staticmethod
    def _stamp(outcomes: dict[str, Outcome], machine: dict) -> None:
        """Every run's summary.json names the machine it ran."""
        for o in outcomes.values():
            if o.ok and o.summary.get("machine") != machine:
                o.summary["machine"] = machine
                write_summary(o.case.out_dir, o.summary)

    @staticmethod
    def _earlier(run: StudyRun) -> dict[str, dict]:
        """A run that failed this time but finished before keeps its summary in the tables: a re-run in which
        nothing succeeds never replaces good tables with empty ones (its failure is still reported). A damaged
        summary is moved aside, not used."""
        kept = {}
        for k, o in run.outcomes.items():
            if not o.ok:
                old = read_summary(Path(o.case.out_dir) / "summary.json")
                if old is not None and old.has_bearings:
                    kept[k] = old
        return kept

    def epilogue(self, run: StudyRun) -> None:
        """Every run's time, error estimate and warnings (reused ones marked), the failed runs, the files."""
        print("\nrun time and accuracy per run:", *run_lines(run.outcomes), sep="\n")
        for k, o in run.outcomes.items():
            if not o.ok:
                kept = "; its earlier results stay in the tables" if k in run.kept else ""
                print(f"FAILED {k}: {o.error}  (details in {Path(o.case.out_dir) / 'error.json'}{kept})")
        runs = [Path(o.case.out_dir) / name for o in run.outcomes.values() if o.ok
                for name in ("summary.json", "results.nc") if (Path(o.case.out_dir) / name).exists()]
        print("\nwritten:\n" + "\n".join(f"  {p}" for p in [*run.files, *runs]))

    @staticmethod
    def exit_code(r: dict) -> int:
        return 1 if r["failed"] else 0


def _duration(seconds: float) -> str:
    """A wall time in words: "40 s", "12 min", "3.5 h"."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
