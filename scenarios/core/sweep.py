"""Sweeps of many runs on Dask: a local cluster by default, or an existing one (``scheduler``).

Each case is plain data (condition, direction, parameter overrides as strings, run config), so it
travels to any worker; the worker rebuilds the pint parameters itself. What becomes of a case is an
:class:`Outcome`: ``finished`` (run now), ``reused`` (its summary.json was made from the same parameters,
settings and code — its fingerprint, :func:`runner.run_fingerprint` — so a restarted sweep resumes; a stale
one is recomputed) or ``failed`` (it wrote error.json with its traceback and did not stop the others); every
file is written atomically. Which runs are reused is decided here, on the client, from the client's folders.

A local cluster's workers write into the case folders themselves (they share this machine's filesystem). On an
existing scheduler no filesystem is assumed shared (:mod:`scenarios.core.cluster`): its workers must run this
client's code (checked first), each runs a case in a scratch folder of its own and returns the run's files, which
this process writes into the case's folder under ``--out``; a run whose worker died is given to another worker by
the scheduler (up to Dask's ``distributed.scheduler.allowed-failures``, 3 by default), and the runs that finished
before it have landed already. An interrupted client (Ctrl-C) cancels its runs on the scheduler, and a local
cluster's workers stop with it.
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import signal
import sys
import threading
import time
import traceback
import warnings
from dataclasses import asdict, dataclass, field, replace
from enum import Enum
from pathlib import Path
from typing import Callable

from multiprocessing import resource_tracker

from tqdm.auto import tqdm

from components import faults
from components.geometry import check_design
from components.params import overrides_from_toml, with_overrides
from components.presets import reference_dpgt
from components.results import Summary
from components.results.io import atomic_write_text
from components.units import ParameterError

from .points import Point, file_overrides, point_overrides
from .cluster import check_workers, done_on_worker, folder_files, land, other_code, params_texts, relocated, scratch_folder
from .integrity import OtherResults, claim_folder, differences, read_summary
from .lock import release_dead
from .runner import (checkpoint_time, code_digest, finished_run, parameters_fingerprint, run_case, run_description,
                     run_fingerprint)

__all__ = ["Case", "Status", "Outcome", "Beside", "ALL", "Travelled", "sweep", "run_sweep", "execute_case", "execute_on_worker",
           "join_closing",
           "check_folders", "user_overrides", "validate_cases", "dask_client", "OPERATING_AXES", "RETRIES",
           "say_design_warnings"]

RETRIES = 2      # a task that raised (not a failed run: that is an Outcome) is tried again this many times


@dataclass(frozen=True)
class Case:
    condition: int | str                            # a preset 1-4, or a user point's name (then ``point`` is set)
    direction: str
    out_dir: str
    overrides: dict = field(default_factory=dict)   # dotted parameter path -> value string
    params_file: str | None = None
    window: float | None = None                     # per-case recorded window [s] (None: the config's)
    tag: str = ""                                   # tells apart cases of one operating point (e.g. the oil)
    point: dict | None = None                       # a user operating point (scenarios.core.points.Point as a dict)
    mode: str | None = None                         # per-case "static"/"dynamic" (None: the config's)

    @property
    def label(self) -> str:
        if self.point is not None:
            base = self.point["name"] if self.point.get("direction") else f"{self.point['name']}_{self.direction}"
        else:
            base = f"c{self.condition}_{self.direction}"
        return base + (f"_{self.tag}" if self.tag else "")

    @classmethod
    def at(cls, point, direction: str, out_dir: str, overrides: dict | None = None, params_file: str | None = None,
           **kw) -> "Case":
        """The case of the operating point ``point`` (:class:`scenarios.core.points.Point`) in ``direction`` (a point
        that fixes its direction keeps it): a preset's case is the condition's, exactly as before."""
        if point.is_preset:
            return cls(point.condition, direction, out_dir, dict(overrides or {}), params_file, **kw)
        return cls(point.name, point.direction or direction, out_dir, dict(overrides or {}), params_file,
                   point=point.as_dict(), **kw)


class Status(str, Enum):
    """What became of a case: run now, taken from an earlier run of the same parameters, settings and code, or
    failed (error.json in its folder says why)."""
    FINISHED = "finished"
    REUSED = "reused"
    FAILED = "failed"


@dataclass
class Outcome:
    """One case of a sweep after it: its :class:`Status`, its summary (finished or reused; a reused summary keeps
    the wall time of the run that made it) or what went wrong (failed)."""
    case: Case
    status: Status
    summary: Summary | None = None
    error: str | None = None
    traceback: str = ""
    span: dict = field(default_factory=dict)    # where and when it ran: {"pid", "start_unix_s", "end_unix_s"}

    @property
    def label(self) -> str:
        return self.case.label

    @property
    def ok(self) -> bool:
        return self.status is not Status.FAILED

    @property
    def wall_s(self) -> float | None:
        """Wall time of the run that made the results (for a reused one: when it ran)."""
        return None if self.summary is None else self.summary.get("wall_s")

    def as_dict(self) -> Summary:
        """The summary (reused: with ``"skipped": True``), or the failed-run form :meth:`Summary.failure`
        (``{"case", "error", "traceback"}``): :func:`run_sweep`'s form."""
        if self.status is Status.FAILED:
            return Summary.failure(self.label, self.error, self.traceback)
        s = Summary.of(self.summary)
        return Summary({**s, "skipped": True}) if self.status is Status.REUSED else s


# the parameters every study's sweep sets itself (its axes), and the option that sets them
OPERATING_AXES = {"operating.carrier_speed": "--conditions", "operating.output_power": "--conditions",
                  "operating.direction": "--directions"}


def user_overrides(sets: dict, params_file: str | None, owned: dict[str, str], merge_file: bool = False) -> dict:
    """The ``--set`` overrides of a study, after checking that neither they nor the ``--params`` file touch a
    parameter the study's sweep owns (``owned``: dotted key or prefix → the option that sets it). Such an override
    would silently relabel runs — a folder ``c3_forward`` holding a reverse run — so it is refused in one line
    naming the key, where it came from and the option to use. A file that is not UTF-8 TOML is a usage error
    naming the file. ``merge_file``: the file's overrides are returned too (under the ``--set`` ones), for a study
    whose cases carry their own files."""
    from_file = {}
    if params_file:
        try:
            from_file = overrides_from_toml(Path(params_file).read_text(encoding="utf-8"))
        except (ParameterError, ValueError) as exc:          # not UTF-8, not TOML, a bad value
            raise SystemExit(f"error: --params {params_file}: {exc}".splitlines()[0]) from None
    for where, given in (("--set", sets), (f"--params {params_file}", from_file)):
        for key in given:
            for axis, option in owned.items():
                if key == axis or key.startswith(axis + ".") or axis.startswith(key + "."):
                    raise SystemExit(f"error: {key} is set by this study's {option}, not by {where}")
    return {**from_file, **sets} if merge_file else dict(sets)


def validate_cases(cases: list[Case], check=None) -> None:
    """Before any run starts: every case's parameters convert, its errors name what the machine has and its design
    is checked (``check(case)``, optional, adds a study's own checks). A ParameterError ends the study with its one
    line; each distinct design warning (the reference machine's known tip-circle overlaps) is said once for the
    whole study, not once per run."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for c in cases:
                params = build_params(c)
                check_design(params)
                faults.check_errors(params.si())
                if check is not None:
                    check(c)
    except ParameterError as exc:
        raise SystemExit(f"error: {exc}") from None
    say_design_warnings(caught)


def say_design_warnings(caught) -> None:
    """Each distinct design warning among the caught warnings once, as every command says them."""
    for msg in sorted({str(w.message) for w in caught if issubclass(w.category, UserWarning)}):
        print(f"design {msg}" if msg.startswith("warning: ") else f"design warning: {msg}")


def build_params(case: Case):
    """The case's parameters: a preset's reference machine at its condition and direction, the ``--params`` file,
    the overrides; a user point's machine (the file and overrides at the reference condition 3) put at the point
    (:func:`scenarios.core.points.point_overrides`)."""
    if case.point is None:
        base = reference_dpgt(case.condition, case.direction)
        if case.params_file:
            base = with_overrides(base, file_overrides(case.params_file))
        return with_overrides(base, case.overrides)
    base = reference_dpgt(3, case.direction)
    if case.params_file:
        base = with_overrides(base, file_overrides(case.params_file))
    machine = with_overrides(base, case.overrides)
    ops = point_overrides(Point(**case.point), machine)
    ops.setdefault("operating.direction", case.direction)
    return with_overrides(machine, ops)


def _case_cfg(case: Case, cfg):
    if case.mode is not None and case.mode != cfg.mode:
        cfg = replace(cfg, mode=case.mode)
    return cfg if case.window is None else replace(cfg, window=case.window)


def _finished(case: Case, params, cfg) -> Summary | None:
    """The case's summary if it was finished from the same parameters, settings and code and its results.nc
    is intact, else None (then recomputed, not reused; damaged files are moved aside, scenarios.core.integrity)."""
    return finished_run(case.out_dir, params, cfg)


def check_folders(cases: list[Case], cfg, overwrite: bool = False) -> None:
    """Before any run starts: refuse (:class:`~scenarios.core.integrity.OtherResults`) when a case's folder holds
    finished results of other parameters or settings and ``overwrite`` is not given; list every such folder."""
    others = []
    for c in cases:
        params, ccfg = build_params(c), _case_cfg(c, cfg)
        try:
            claim_folder(c.out_dir, parameters_fingerprint(params, ccfg), run_fingerprint(params, ccfg), overwrite)
        except OtherResults:
            s = read_summary(Path(c.out_dir) / "summary.json") or {}
            others.append(c.out_dir + differences(s.get("run_description"), run_description(params, ccfg), most=2))
    if others:
        raise OtherResults(f"{', '.join(others)} hold{'s' if len(others) == 1 else ''} finished results of other "
                           f"parameters or settings; pass --overwrite to replace them, or choose another --out")


def resume_times(cases: list[Case], cfg) -> dict[str, float]:
    """{label: simulated time [s]} of the cases that will resume from a checkpoint of their own run."""
    out = {}
    for c in cases:
        try:
            t = checkpoint_time(c.out_dir, build_params(c), _case_cfg(c, cfg))
        except Exception:     # bad parameters: execute_case reports them
            t = None
        if t is not None:
            out[c.label] = t
    return out


def _is_finished(case: Case, cfg) -> bool:
    try:
        return _finished(case, build_params(case), _case_cfg(case, cfg)) is not None
    except Exception:     # bad parameters: execute_case reports them
        return False


def execute_case(case: Case, cfg, overwrite: bool = False) -> Outcome:
    """Run one case (on whichever process), or reuse its finished results. Never raises: a failure is an
    :class:`Outcome` of status failed (and error.json in the case's folder). Its ``span`` says which process ran it
    and when (wall clock: a study's profile relates the runs to the Dask phases)."""
    start = time.time()
    o = _execute(case, cfg, overwrite)
    o.span = {"pid": os.getpid(), "start_unix_s": start, "end_unix_s": time.time()}
    return o


def _execute(case: Case, cfg, overwrite: bool) -> Outcome:
    out = Path(case.out_dir)
    try:
        params = build_params(case)
        cfg = _case_cfg(case, cfg)
        done = _finished(case, params, cfg)
        if done is not None:
            return Outcome(case, Status.REUSED, summary=done)
        label = {"condition": case.condition, "direction": case.direction}
        if case.point is not None:       # a user point: its name stands where a condition's number does
            label["operating_point"] = dict(case.point)
        s = run_case(params, cfg, out, label=label, overwrite=overwrite)
        err = out / "error.json"
        if err.exists():
            err.unlink()
        return Outcome(case, Status.FINISHED, summary=s)
    except Exception as exc:  # reported, never hidden; the sweep goes on
        out.mkdir(parents=True, exist_ok=True)
        info = Summary.failure(case.label, f"{type(exc).__name__}: {exc}", traceback.format_exc())
        try:
            atomic_write_text(out / "error.json", json.dumps(info, indent=2))
        except OSError:       # disk full or unwritable: the caller still gets the report
            pass
        return Outcome(case, Status.FAILED, error=info.error, traceback=info.get("traceback", ""))


SETTLED_ESTIMATE = 0.1      # share of a run's simulated time after which its time left is shown
PLAIN_EVERY_S = 30.0        # a log or a pipe gets a line on the running runs this often (a terminal: their bars)


@dataclass
class Travelled:
    """What a worker that shares no filesystem with the client returns for a case: its :class:`Outcome` and the files
    the run left in the worker's scratch folder ({name: content}), for the client to write into the case's folder."""
    outcome: Outcome
    files: dict = field(default_factory=dict)


def execute_on_worker(case: Case, cfg, overwrite: bool, code: str, texts: dict) -> Travelled:
    """:func:`execute_case` on a worker of another machine: refused (a failed outcome naming both fingerprints) when
    this worker runs other code than the client (``code``, its :func:`~scenarios.core.runner.code_digest`); else run in
    a scratch folder of this worker (:func:`scenarios.core.cluster.scratch_folder`; the ``--params`` file from its text,
    ``texts``) and return the files the run left there. A finished run's scratch folder is removed; a failed one stays
    (a retry here resumes from its checkpoint)."""
    start = time.time()
    refused = other_code(code)
    if refused is not None:
        o = Outcome(case, Status.FAILED, error=refused)
        o.span = {"pid": os.getpid(), "start_unix_s": start, "end_unix_s": time.time()}
        return Travelled(o)
    what = json.dumps({"case": {**asdict(case), "out_dir": ""}, "params": texts.get(case.params_file or ""),
                       "cfg": repr(cfg), "code": code}, sort_keys=True, default=repr)
    scratch = scratch_folder(what, case.label)
    o = execute_case(replace(relocated(case, texts), out_dir=str(scratch)), cfg, overwrite)
    files = folder_files(scratch)
    if o.ok:
        done_on_worker(scratch)
    if o.status is Status.REUSED:      # finished here by an attempt whose result never reached the client
        o.status = Status.FINISHED
    o.case = case
    return Travelled(o, files)


class _AllRuns:
    """The key of :class:`Beside`'s work across every case (``Beside.last``): a key no case's group can have."""

    def __repr__(self) -> str:
        return "ALL"


ALL = _AllRuns()


@dataclass
class Beside:
    """Work to do beside the runs, e.g. one operating point's figures: the cases fall into groups (``key(case)``;
    None: in none), and once every case of a group has its outcome, ``task(key, {label: outcome})`` gives
    ``(function, args)``, a list of them (pieces of the group's work that can run at once: on a cluster, on as many
    workers; the last group's work then does not wait on one worker while the others idle) or None. On a local
    cluster each function runs on a worker, ahead of the runs still queued, while the other runs go on; without
    Dask, or on a cluster whose workers share no filesystem with this process, it runs here at that moment.
    A sweep that runs nothing (every case reused) does nothing beside.
    ``last(outcomes)``: the work that needs every case's outcome (figures across the groups), in the same form as
    ``task``'s, done beside the last groups' work as soon as the last run is in; its value is under the key
    :data:`ALL`. ``done``: {key: its return value (pieces that return lists: their lists joined, in the order of
    the pieces), or the exception one of its pieces raised}."""
    key: Callable[[Case], object]
    task: Callable[[object, dict], tuple | None]
    last: Callable[[dict], tuple | list | None] | None = None
    done: dict = field(default_factory=dict)
    spans: list = field(default_factory=list)   # where and when each piece of work ran (as Outcome.span)

    def groups(self, cases: list[Case]) -> dict:
        out: dict = {}
        for c in cases:
            k = self.key(c)
            if k is not None:
                out.setdefault(k, []).append(c.label)
        if self.last is not None:       # after the groups: the last group's pieces go first
            out[ALL] = [c.label for c in cases]
        return out

    def ready(self, groups: dict, results: dict, started: set):
        """(key, (function, args)) of every piece of every group whose cases all have outcomes now, each once."""
        for k, labels in groups.items():
            if k not in started and all(lab in results for lab in labels):
                started.add(k)
                got = {lab: results[lab] for lab in labels}
                work = self.last(got) if k is ALL else self.task(k, got)
                for piece in ([] if work is None else work if isinstance(work, list) else [work]):
                    yield k, piece

    def here(self, k, work) -> None:
        fn, fargs = work
        self.took(k, timed_call(fn, *fargs))

    def took(self, k, got: tuple) -> None:
        """Keep what :func:`timed_call` gave for a piece of group ``k``: its value (or exception; a group's first
        exception stays) and its span. Pieces are taken in the order :meth:`ready` gave them."""
        value, span = got
        if k not in self.done:
            self.done[k] = value
        elif not isinstance(self.done[k], BaseException):
            self.done[k] = (value if isinstance(value, BaseException)
                            else [*self.done[k], *value] if isinstance(value, list) and isinstance(self.done[k], list)
                            else value)
        self.spans.append(span)


def timed_call(fn: Callable, *args) -> tuple:
    """(fn(*args) or the exception it raised, {"pid", "start_unix_s", "end_unix_s"}): work beside the runs with
    where and when it ran, so a study's time profile can tell a worker drawing figures from one waiting. A figure
    that fails is reported with the study's files, not fatal."""
    start = time.time()
    try:
        value = fn(*args)
    except Exception as exc:
        value = exc
    return value, {"pid": os.getpid(), "start_unix_s": start, "end_unix_s": time.time()}


class _RunBars:
    """One bar per running case, fed from the progress.json each worker writes (simulated time); with ``plain`` (a
    log or a pipe), a line on standard error every :data:`PLAIN_EVERY_S` with each running case's simulated time."""

    def __init__(self, cases, show, plain: bool = False):
        self.show, self.plain = show, plain
        self.cases, self.done, self.said = list(cases), set(), time.monotonic()
        # a progress.json from before the sweep (an interrupted run's, queued again) is old news; a second's margin
        # for a file system's coarse clock
        self.since = time.time() - 1.0
        self.bars = {}
        if show:
            for i, c in enumerate(cases):
                self.bars[c.label] = (c, tqdm(total=1.0, desc=c.label, position=i + 1, leave=False, unit="",
                                              bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix}"))

    def _read(self, c) -> dict | None:
        p = Path(c.out_dir) / "progress.json"
        try:
            return json.loads(p.read_text()) if p.stat().st_mtime >= self.since else None
        except (OSError, ValueError):
            return None

    def poll(self):
        if self.plain and time.monotonic() - self.said >= PLAIN_EVERY_S:
            self.said = time.monotonic()
            running = [(c.label, d) for c in self.cases if c.label not in self.done and (d := self._read(c))]
            if running:
                print("runs: running " + ", ".join(f"{k} at t = {d['t']:.4g} of {d['t_end']:.4g} s"
                                                   for k, d in running), file=sys.stderr, flush=True)
        for label, (c, b) in self.bars.items():
            d = self._read(c)
            if d is None:
                continue
            b.n = min(1.0, d["t"] / d["t_end"]) if d["t_end"] else 0.0
            rate = d["steps"] / max(d["wall_s"], 1e-9)
            left = (d["t_end"] - d["t"]) / max(d["t"], 1e-12) * d["wall_s"]
            # the kinematic start is slow and the compile counts in the first seconds: an estimate from them
            # would be many times too long, so it is shown once the run is past its start
            settled = d["t"] >= SETTLED_ESTIMATE * d["t_end"] and d["wall_s"] > 2.0
            b.set_postfix_str(f"t={d['t']:.4f}/{d['t_end']:.4f} s, {rate:.0f} steps/s, "
                              + (f"~{left:.0f} s left" if settled else "estimating the time left"))

    def finish(self, c):
        self.done.add(c.label)
        if c.label in self.bars:
            b = self.bars[c.label][1]
            b.n = 1.0
            b.refresh()

    def close(self):
        for _, b in self.bars.values():
            b.close()


def run_sweep(cases: list[Case], cfg, workers: int | None = None, scheduler: str | None = None,
              progress: bool = True, overwrite: bool = False) -> dict[str, Summary]:
    """:func:`sweep` as summaries: {label: summary (reused: ``"skipped": True``) or the failed-run form
    (:meth:`Summary.failure`)}."""
    return {k: o.as_dict() for k, o in sweep(cases, cfg, workers, scheduler, progress, overwrite).items()}


def sweep(cases: list[Case], cfg, workers: int | None = None, scheduler: str | None = None,
          progress: bool = True, overwrite: bool = False, announce: bool = False,
          timing: dict | None = None, beside: Beside | None = None, close_behind: bool = False) -> dict[str, Outcome]:
    """Run every case; returns {label: :class:`Outcome`}. One case runs in-process (no cluster).
    ``overwrite``: replace finished results of other parameters (else :func:`check_folders` refuses);
    ``announce``: say first how many runs will run and how many are reused; ``timing``: a dict to fill with the
    sweep's phases (wall seconds: ``reuse_check_s``, on Dask ``cluster_start_s`` — Dask imported, scheduler and
    workers started —, ``runs_s`` from the first submission to the last result, ``cluster_close_s``; the runs'
    phase as wall-clock stamps ``runs_start_unix_s``, ``runs_end_unix_s``; ``workers``, ``dask``); ``beside``: work
    done group by group as the runs finish (:class:`Beside`), its wall seconds after the last run ``beside_tail_s``
    and each piece's span ``beside_spans`` (:func:`timed_call`); ``close_behind``: a local cluster closes behind the
    caller once its runs are in (:func:`dask_client`; the caller's :func:`join_closing` waits for it, and sets
    ``cluster_close_s`` and ``cluster_close_wait_s``)."""
    timing = {} if timing is None else timing
    groups, started = (beside.groups(cases), set()) if beside is not None else ({}, set())

    def ready(results):
        return list(beside.ready(groups, results, started)) if beside is not None else []

    t0 = time.perf_counter()
    todo = [c for c in cases if not _is_finished(c, cfg)]
    if announce:
        resumes = resume_times(todo, cfg)
        said = "".join(f", {k} from its checkpoint at {1e3 * t:.3g} ms" for k, t in resumes.items())
        print(f"runs: {len(todo)} to run{said}, {len(cases) - len(todo)} reused (finished earlier with the same "
              f"parameters, settings and code)", flush=True)
        if todo and len(todo) < len(cases):
            print(f"resuming: {len(cases) - len(todo)} of {len(cases)} runs finished earlier", flush=True)
    results = {c.label: execute_case(c, cfg) for c in cases if c not in todo}   # finished: just load
    timing["reuse_check_s"] = time.perf_counter() - t0
    if not todo:            # nothing runs: nothing to draw beside (the caller's report draws it, after its headline)
        return results
    # never more workers than runs left: one run left runs here, without starting a cluster for it
    n_workers = min(workers or os.cpu_count() or 1, len(todo))
    timing.update(workers=n_workers, dask=not (scheduler is None and n_workers <= 1), runs_start_unix_s=time.time())
    # bars on a terminal; a log file or a pipe gets one plain line per finished run instead of escape codes
    plain = progress and not sys.stderr.isatty()
    bars = progress and not plain
    if scheduler is None and n_workers <= 1:
        for i, c in enumerate(tqdm(todo, desc="runs", disable=not bars or len(todo) == 1)):
            results[c.label] = execute_case(c, cfg, overwrite)
            if plain:
                print(f"runs: {i + 1}/{len(todo)} done ({c.label})", file=sys.stderr, flush=True)
            for k, work in ready(results):
                beside.here(k, work)
        timing["runs_end_unix_s"] = time.time()
        timing["runs_s"] = timing["runs_end_unix_s"] - timing["runs_start_unix_s"]
        timing["beside_spans"] = list(beside.spans) if beside is not None else []
        return results
    wcfg = replace(cfg, progress=False)   # per-run bars would interleave; the sweep bar shows progress
    futs, side = {}, []           # side: (group, future) of each piece of work beside the runs
    t_start = time.perf_counter()
    with _dead_runs_released(todo, scheduler is None), \
            dask_client(n_workers, scheduler, close_behind=timing if close_behind else None) as client:
        from dask.distributed import wait as dask_wait  # deferred: Dask, imported by dask_client just now
        timing["cluster_start_s"] = time.perf_counter() - t_start
        timing["runs_start_unix_s"] = time.time()
        try:
            if scheduler is None:     # a local cluster: its workers write into the case folders (absolute paths)
                futs = {client.submit(execute_case, replace(c, out_dir=str(Path(c.out_dir).resolve())), wcfg,
                                      overwrite, pure=False, retries=RETRIES, key=f"run-{c.label}-{time.time_ns()}"): c
                        for c in todo}
            else:                     # no shared filesystem: the runs' files travel back (scenarios.core.cluster)
                code, texts = code_digest(), params_texts(todo)
                futs = {client.submit(execute_on_worker, c, wcfg, overwrite, code, texts, pure=False,
                                      retries=RETRIES, key=f"run-{c.label}-{time.time_ns()}"): c for c in todo}
            bar = tqdm(total=len(futs), desc="runs", disable=not bars, position=0)
            runs = _RunBars(todo, bars, plain)
            while True:
                done = [f for f in futs if f.done() and futs[f].label not in results]
                if not done:
                    if all(futs[f].label in results for f in futs):
                        break
                    runs.poll()
                    # back as soon as a run ends (its point's figures start then), the bars fed every 0.5 s
                    with contextlib.suppress(TimeoutError):
                        dask_wait([f for f in futs if not f.done()], timeout=0.5, return_when="FIRST_COMPLETED")
                    continue
                fut = done[0]
                c = futs[fut]
                try:
                    got = fut.result()
                except Exception as exc:   # its workers died (Dask gave it to others, then gave up): report, go on
                    got = _worker_failure(c, exc)
                if isinstance(got, Travelled):
                    land(c.out_dir, got.files)         # the run's files, written here (the summary last)
                    got = got.outcome
                    if got.ok:                         # an earlier failure's report no longer holds
                        (Path(c.out_dir) / "error.json").unlink(missing_ok=True)
                got.case = c
                results[c.label] = got
                bar.update(1)
                runs.finish(c)
                if plain:
                    n_done = sum(futs[f].label in results for f in futs)
                    print(f"runs: {n_done}/{len(futs)} done ({c.label})", file=sys.stderr, flush=True)
                if not results[c.label].ok:
                    bar.write(f"run {c.label} failed: {results[c.label].error}")
                for k, (fn, fargs) in ready(results):
                    if scheduler is None:       # a worker shares this filesystem: there, ahead of the queued runs
                        side.append((k, client.submit(timed_call, fn, *fargs, pure=False, priority=1,
                                                      key=f"beside-{time.time_ns()}")))
                    else:
                        beside.here(k, (fn, fargs))
            runs.close()
            bar.close()
            timing["runs_end_unix_s"] = time.time()
            for k, f in side:
                try:
                    beside.took(k, f.result())
                except Exception as exc:      # the worker itself was lost
                    beside.done[k] = exc
        except BaseException:       # Ctrl-C or a failure of the client: take its runs off the scheduler
            client.cancel([*futs, *(f for _, f in side)], force=True)
            raise
        timing["runs_s"] = timing["runs_end_unix_s"] - timing["runs_start_unix_s"]
        timing["beside_tail_s"] = time.time() - timing["runs_end_unix_s"]
        timing["beside_spans"] = list(beside.spans) if beside is not None else []
        t_close = time.perf_counter()
    if not close_behind:
        timing["cluster_close_s"] = time.perf_counter() - t_close
    return results


@contextlib.contextmanager
def _dead_runs_released(cases: list[Case], local: bool):
    """On Ctrl-C or a failure, once a local cluster has stopped (the block inside this one closes it): the locks and
    unfinished writes its workers left in the cases' folders removed (:func:`scenarios.core.lock.release_dead`)."""
    try:
        yield
    except BaseException:
        if local:               # a worker stopped by the close may take a moment to end: 5 s for them all
            deadline = time.monotonic() + 5.0
            for c in cases:
                release_dead(c.out_dir, wait=max(0.0, deadline - time.monotonic()))
        raise


def _worker_failure(case: Case, exc: BaseException) -> Outcome:
    """A case whose task never returned (its workers died, or it raised ``RETRIES`` + 1 times): a failed outcome, and
    error.json in the case's folder saying so."""
    what = f"{type(exc).__name__}: {exc}"
    info = Summary.failure(case.label, f"worker failure: {' '.join(what.split())}; run the same command again to "
                                       f"retry it", "")
    try:
        Path(case.out_dir).mkdir(parents=True, exist_ok=True)
        atomic_write_text(Path(case.out_dir) / "error.json", json.dumps(info, indent=2))
    except OSError:
        pass
    return Outcome(case, Status.FAILED, error=info.error)


_CLOSING: list = []      # (thread, timing dict) of the local clusters closing behind their study (dask_client)


def join_closing() -> float:
    """Wait for the clusters still closing behind this process's work (:func:`dask_client` with ``close_behind``);
    the seconds waited. Each one's own close time is in its sweep's timing (``cluster_close_s``), the wait added as
    ``cluster_close_wait_s``."""
    t0 = time.perf_counter()
    while _CLOSING:
        thread, timing = _CLOSING.pop()
        t = time.perf_counter()
        thread.join()
        timing["cluster_close_wait_s"] = timing.get("cluster_close_wait_s", 0.0) + time.perf_counter() - t
    return time.perf_counter() - t0


@contextlib.contextmanager
def dask_client(n_workers: int, scheduler: str | None = None, close_behind: dict | None = None):
    """A Dask client of the scheduler at ``scheduler`` (its workers checked first:
    :func:`scenarios.core.cluster.check_workers`), or of a local cluster of ``n_workers`` single-threaded processes
    that stops with it (its workers with it).

    A Ctrl-C at the terminal reaches the whole foreground process group: a local cluster's workers hit by it printed
    their own tracebacks (and the nanny its ``CancelledError``) while this process stopped them. So its processes are
    started with SIGINT blocked, a mask they keep (:func:`_ctrl_c_held`), and only this process takes the Ctrl-C: held
    while the cluster starts, raised once it has (then it is stopped cleanly), and the command says "interrupted: ..."
    alone. Its log messages are silenced below CRITICAL for the same reason (a failed run is reported by its
    outcome).

    A local cluster's workers exit without their interpreter's finalisation (:mod:`scenarios.core.quick_exit`).
    ``close_behind`` (a timing dict): a block that ends normally leaves the client and a local cluster to close in a
    thread of this process while the caller goes on; :func:`join_closing` waits for it, as the interpreter does
    before it exits. The close's wall seconds go into ``close_behind["cluster_close_s"]``. An exception or Ctrl-C
    closes at once."""
    cluster = client = None
    with _ctrl_c_held(scheduler is None) as release:
        try:
            import dask  # deferred: Dask (≈ 0.2–0.4 s) only when a sweep runs on it
            from dask.distributed import Client, LocalCluster  # deferred: as above

            if scheduler is None:
                # ":0": the scheduler's HTTP server on a free port (None still asks for 8787, and a second study running
                # beside the first warned that it was taken)
                # the runs ("run-...") are one task group, which Dask queues on its scheduler once it outnumbers twice
                # the workers' threads, handing each worker its next task in the order submitted (the longest runs
                # first) as it frees; worker saturation 1 hands it over when the worker has none left, not one more
                # to wait behind its running task (Dask's default, 1.1) until work stealing moves it
                with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
                    cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True,
                                           dashboard_address=":0", silence_logs=logging.CRITICAL)
                client = Client(cluster)
                from .quick_exit import QuickExit  # deferred: it imports Dask's distributed

                client.register_plugin(QuickExit())      # its workers leave without finalising their interpreters
            else:
                client = Client(scheduler)
            release()               # a Ctrl-C pressed while the cluster started is raised here
            if scheduler is not None:
                check_workers(client, scheduler)      # same code everywhere; cold workers named
            yield client
            if close_behind is not None:
                thread = threading.Thread(target=_close, args=(client, cluster, close_behind), name="dpgt-dask-close")
                thread.start()
                _CLOSING.append((thread, close_behind))
                client = cluster = None
        finally:
            if client is not None:
                client.close()
            if cluster is not None:
                cluster.close()


def _close(client, cluster, timing: dict) -> None:
    """Close ``client`` and ``cluster`` (None: none), its wall seconds into ``timing["cluster_close_s"]``."""
    t0 = time.perf_counter()
    try:
        client.close()
        if cluster is not None:
            cluster.close()
    finally:
        timing["cluster_close_s"] = time.perf_counter() - t0


@contextlib.contextmanager
def _ctrl_c_held(hold: bool):
    """While the block starts processes (``hold``, in the main thread): SIGINT blocked in this thread — before Dask
    starts any thread, as a thread inherits the mask of the one that starts it and a process the mask of the thread
    that spawns it (multiprocessing's resource tracker, started first, unblocks SIGINT in the thread that starts it;
    running already, it leaves the mask alone) — and a Ctrl-C delivered to another thread of this process noted
    instead of raised. Yields ``release()``: from then on Ctrl-C is this process's again, and one pressed meanwhile is
    raised (KeyboardInterrupt); the block's end releases too."""
    if not hold or threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    pressed = []
    resource_tracker.ensure_running()
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    handler = signal.signal(signal.SIGINT, lambda *_: pressed.append(True))
    state = {"held": True}

    def release():
        if state["held"]:
            state["held"] = False
            signal.signal(signal.SIGINT, handler)
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
            if pressed:
                raise KeyboardInterrupt

    try:
        yield release
    finally:
        if state["held"]:
            state["held"] = False
            signal.signal(signal.SIGINT, handler)
            signal.pthread_sigmask(signal.SIG_SETMASK, mask)
