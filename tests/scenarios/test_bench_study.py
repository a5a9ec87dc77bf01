"""Where a study's time goes (scenarios.bench_study --profile) and each run's own peak memory: the loop's timers
against delays planted in a recorder and an observer, the profile's arithmetic against a hand-made study, the
per-run peak against a known allocation."""
from __future__ import annotations

import time

import numpy as np
import pytest

import mbd
from components.planetary import build_single_planetary
from mbd.simulate import TIMING_PARTS
from scenarios.core.memory import RunPeak, process_peak_mb
from scenarios.numerics.bench_study import RUN_PARTS, profile, target

DELAY = 10e-3      # s per accepted step, planted in the observer or in the recorder


def _wait(s):
    if s > 0:                       # sleep(0) yields the CPU: on a loaded machine that alone takes milliseconds
        time.sleep(s)


class _Observer(mbd.Observer):
    def __init__(self, delay):
        self.delay = delay

    def step(self, s0, s1):
        _wait(self.delay)

    def on_block(self, block):
        _wait(self.delay * len(block))


class _Recorder(mbd.Recorder):
    """Records nothing, only takes its time: its part is the planted delay alone."""

    def __init__(self, path, delay):
        super().__init__(path, dt=1e-3, probes=[mbd.BodyMotion()])
        self.delay = delay

    def record(self, s0, s1, first=False):
        if not first:
            _wait(self.delay)

    def record_block(self, block):
        _wait(self.delay * len(block))

    def finalize(self, attrs=None):
        return self.path


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
@pytest.mark.parametrize("slow", ["observers_s", "recording_s"])
def test_the_loop_times_each_part_where_its_time_is_spent(tmp_path, engine, slow):
    """A delay planted in the observer lands in ``observers_s``, in the recorder in ``recording_s``: that part holds
    at least the delay, the other (doing nothing) less than half of it — swapped timers fail —, and the parts add up
    to no more than the call's wall time measured outside. (Sleeps, not work: on a loaded machine a sleep may
    overshoot, never undershoot.)"""
    built = build_single_planetary()
    other = {"observers_s": "recording_s", "recording_s": "observers_s"}[slow]
    rec = _Recorder(tmp_path / "r.nc", DELAY if slow == "recording_s" else 0.0)
    t0 = time.perf_counter()
    res = mbd.simulate(built.model, built.q0, built.v0, 0.004, controller=mbd.FixedStep(1e-4), recorder=rec,
                       observers=[_Observer(DELAY if slow == "observers_s" else 0.0)], progress=False, engine=engine)
    wall = time.perf_counter() - t0
    tm = res.timing
    assert set(tm) == set(TIMING_PARTS) and res.engine == engine
    n = res.steps                   # accepted steps: the recorder and the observer see each once
    assert n >= 40 and tm[slow] >= DELAY * n > 2 * tm[other]
    assert tm["engine_s"] > 0 and sum(tm.values()) <= wall


def _study(runs_start=1000.0):
    """A hand-made study: 2 workers, three runs (pid 1: a then b, pid 2: c), every phase a round number."""
    spans = {"a": {"pid": 1, "start_unix_s": runs_start + 2.0, "end_unix_s": runs_start + 22.0},
             "b": {"pid": 1, "start_unix_s": runs_start + 23.0, "end_unix_s": runs_start + 53.0},
             "c": {"pid": 2, "start_unix_s": runs_start + 3.0, "end_unix_s": runs_start + 43.0}}
    sweep = {"reuse_check_s": 0.5, "workers": 2, "dask": True, "cluster_start_s": 6.0, "cluster_close_s": 2.0,
             "runs_start_unix_s": runs_start, "runs_end_unix_s": runs_start + 54.0, "runs_s": 54.0}
    T = {"checks_s": 1.0, "prepare_s": 0.0, "sweep_s": 0.5 + 6.0 + 54.0 + 2.0 + 0.25, "sweep": sweep,
         "report_s": 12.0, "steps_s": {"figures": 8.0, "tables": 1.0}, "total_s": 76.0, "runs": spans}

    def run(total, engine):
        parts = dict.fromkeys(RUN_PARTS, 0.0) | {"engine_s": engine, "statistics_s": 1.0, "kernels_s": 1.0}
        parts["other_s"] = total - 0.5 - sum(parts.values())      # 0.5 s of each span outside the runner
        return parts | {"total_s": total - 0.5}

    return {"wall_s": 85.0, "study": T, "runs": {"a": run(20.0, 15.0), "b": run(30.0, 25.0), "c": run(40.0, 35.0)},
            "tree_peak_rss_MB": 0.0}


def test_the_profile_adds_up_to_the_wall_time_and_shares_worker_seconds_over_the_workers():
    rows = {what: s for _, what, s in profile(_study())}
    assert sum(rows.values()) == pytest.approx(85.0, abs=1e-9)
    assert rows["interpreter start, imports, exit"] == pytest.approx(85.0 - 76.0)
    assert rows["engine: the integration steps"] == pytest.approx((15 + 25 + 35) / 2)
    assert rows["a worker's first task: the imports, transfer, start"] == pytest.approx((2 + 3) / 2)
    assert rows["between a worker's tasks: scheduling, transfer"] == pytest.approx(1 / 2)
    assert rows["idle at the end: waiting for the other worker's last run"] == \
        pytest.approx((1 + 11) / 2)
    assert rows["a run's case outside the runner (parameters, lock, folder checks)"] == pytest.approx(3 * 0.5 / 2)
    assert rows["report: figures"] == 8.0 and rows["report: relative lives into each summary.json, headline tables"] == 3.0
    assert rows["the study's rest (sweep bookkeeping, epilogue)"] == pytest.approx(76 - 1 - 62.75 - 12 + 0.25)


def test_the_target_is_the_work_shared_out_with_15_percent_and_the_runs_tail():
    """Runs of 20 and 30 s on worker 1 (its last ends at 1053), 40 s on worker 2 (ends at 1043) — the measured tail
    10 s; the bound (1 − 1/2) × 40 = 20 s; the engine's 15 + 25 + 35 = 75 s, the runs' 90 s."""
    t = target(_study())
    assert t["works_s"] == {"engine": 75.0, "runs": 90.0} and t["workers"] == 2
    assert t["tails_s"]["measured"] == pytest.approx(10.0) and t["tails_s"]["bound"] == pytest.approx(20.0)
    assert t["engine, measured"]["target_s"] == pytest.approx(1.15 * 75 / 2 + 10)
    assert t["runs, measured"]["target_s"] == pytest.approx(1.15 * 90 / 2 + 10)
    assert t["runs, bound"]["target_s"] == pytest.approx(71.75)
    assert t["runs, bound"]["ratio"] == pytest.approx(85.0 / 71.75)
    one = _study()
    one["study"]["sweep"]["workers"] = 1       # one worker: no tail bound, the runs one after another
    assert target(one)["runs, bound"]["target_s"] == pytest.approx(1.15 * 90.0)
    alone = _study()
    for k in ("a", "b", "c"):
        alone["study"]["runs"][k]["pid"] = 1     # worker 2 ran nothing: it ran out at the start (1000)
    assert target(alone)["tails_s"]["measured"] == pytest.approx(53.0)


def test_a_worker_that_ran_nothing_counts_as_idle():
    job = _study()
    spans = job["study"]["runs"]
    spans["c"] = {**spans["c"], "pid": 1, "start_unix_s": 1054.0, "end_unix_s": 1054.0}   # all on worker 1
    job["runs"]["c"] = {p: 0.0 for p in job["runs"]["c"]}
    job["study"]["sweep"]["runs_end_unix_s"] = 1054.0
    rows = {what: s for _, what, s in profile(job)}
    assert sum(rows.values()) == pytest.approx(85.0, abs=1e-9)
    assert rows["idle at the end: waiting for the other worker's last run"] == \
        pytest.approx((0 + 54) / 2)


def test_figures_drawn_on_a_worker_leave_its_idle_rows_and_the_tail_leaves_the_rest():
    """Worker 2 draws for 4 s between its run's end (1043) and the phase's end (1054), worker 1 for 0.5 s in its
    1 s gap, and the client waits 3 s after the last run for a third drawing: each moves out of the row it would
    otherwise swell, and the rows still add up to the wall time."""
    job = _study()
    sw = job["study"]["sweep"]
    sw["beside_spans"] = [{"pid": 2, "start_unix_s": 1045.0, "end_unix_s": 1049.0},
                          {"pid": 1, "start_unix_s": 1022.25, "end_unix_s": 1022.75},
                          {"pid": 1, "start_unix_s": 1054.0, "end_unix_s": 1057.0}]
    sw["beside_tail_s"] = 3.0
    job["study"]["sweep_s"] += 3.0
    job["study"]["total_s"] += 3.0
    job["wall_s"] += 3.0
    rows = {what: s for _, what, s in profile(job)}
    assert sum(rows.values()) == pytest.approx(88.0, abs=1e-9)
    assert rows["figures beside the runs, drawn while runs were on (their share of a worker)"] == \
        pytest.approx((4 + 0.5) / 2)
    assert rows["figures beside the runs, waited for after the last run"] == 3.0
    assert rows["between a worker's tasks: scheduling, transfer"] == pytest.approx((1 - 0.5) / 2)
    assert rows["idle at the end: waiting for the other worker's last run"] == \
        pytest.approx((1 + 11 - 4) / 2)
    assert rows["the study's rest (sweep bookkeeping, epilogue)"] == pytest.approx(76 - 1 - 62.75 - 12 + 0.25)


def _touch(mb: int) -> np.ndarray:
    a = np.empty(mb * 2 ** 20 // 8)
    a[:] = 1.0                          # resident, not only reserved
    return a


def test_a_runs_peak_is_its_own_not_the_processes_so_far():
    """400 MiB held during one 'run', then a second 'run' that holds nothing: the second's peak is ~400 MiB lower,
    and the process's peak still counts the first."""
    first = RunPeak()
    if not first.per_run:
        pytest.skip("the high-water mark cannot be reset here (/proc/self/clear_refs)")
    base = first.mb()
    a = _touch(400)
    big = first.mb()
    del a
    second = RunPeak()
    small = second.mb()
    assert big - base >= 390 and small <= big - 350
    assert process_peak_mb() >= big - 1.0      # the kernel's RSS counters are batched per CPU: < 1 MiB behind


def test_a_cluster_closing_behind_the_report_counts_only_the_wait_for_it():
    """A cluster that closes behind the report (scenarios.core.sweep.dask_client, close_behind): its close (5 s) ran
    beside the report, outside the sweep; only the wait for it after the report (1.5 s, in total_s, not in report_s)
    is wall time, and the rows still add up to the wall time."""
    job = _study()
    T, sw = job["study"], job["study"]["sweep"]
    sw.update(cluster_close_s=5.0, cluster_close_wait_s=1.5)
    T["sweep_s"] -= 2.0                  # the close no longer inside the sweep
    T["total_s"] += -2.0 + 1.5           # the wait after the report
    job["wall_s"] += -2.0 + 1.5
    rows = {what: s for _, what, s in profile(job)}
    assert sum(rows.values()) == pytest.approx(job["wall_s"], abs=1e-9)
    assert rows["cluster close, waited for after the report (it closes behind the report)"] == 1.5
    assert "cluster close" not in rows
    assert rows["the study's rest (sweep bookkeeping, epilogue)"] == pytest.approx(0.25 + 76 - 1 - 62.75 - 12)
