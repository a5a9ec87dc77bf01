"""Nothing a user does loses results: folders of other parameters, damaged files, disk full,
interrupted sweeps — one test per class, on a tiny window (8 rollers, 0.5 ms settle + 0.5 ms window)."""
from __future__ import annotations

import json
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from components.dpgt import build_dpgt
from components.presets import reference_dpgt
from scenarios import paper_study
from scenarios.core.integrity import DAMAGED, OtherResults, checkpoint_usable
from scenarios.core.runner import RunConfig
from scenarios.core.sweep import Case, _finished, build_params, check_folders, run_sweep

CFG = RunConfig(settle=0.0005, window=0.0005, progress=False)
TINY = ["--conditions", "4", "--directions", "forward", "--settle", "0.0005", "--window", "0.0005",
        "--no-progress", "--workers", "1"]


def _case(folder, rollers=8):
    return Case(4, "forward", str(folder), {"bearing.rollers": rollers})


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished tiny run (its folder is copied by each test that changes it)."""
    out = tmp_path_factory.mktemp("finished") / "c4_forward"
    r = run_sweep([_case(out)], CFG, workers=1, progress=False)["c4_forward"]
    assert "error" not in r
    return out


def _copy(finished, tmp_path):
    dst = tmp_path / "c4_forward"
    shutil.copytree(finished, dst)
    return dst


def _moved_aside(folder, name):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(name + DAMAGED))


def test_other_parameters_are_refused_unless_overwrite(finished, tmp_path, capsys):
    run = _copy(finished, tmp_path)
    before = (run / "summary.json").read_bytes()
    with pytest.raises(OtherResults, match="--overwrite"):
        check_folders([_case(run, rollers=10)], CFG)
    check_folders([_case(run, rollers=8)], CFG)                    # the same parameters: fine (resumes)
    check_folders([_case(run, rollers=10)], CFG, overwrite=True)   # asked for
    # through the command: a usage error in one line before anything runs, the finished results untouched
    code = paper_study.main(TINY + ["--set", "bearing.rollers=10", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: ") and "--overwrite" in err and err.count("\n") == 1
    assert (run / "summary.json").read_bytes() == before


def test_a_damaged_summary_is_moved_aside_and_recomputed(finished, tmp_path, capsys):
    run = _copy(finished, tmp_path)
    (run / "summary.json").write_text('{"inner": {"bearing_load_mean_N": 1')      # cut off mid-write
    assert _finished(_case(run), build_params(_case(run)), CFG) is None
    assert len(_moved_aside(run, "summary.json")) == 1 and "summary.json" in capsys.readouterr().err
    r = run_sweep([_case(run)], CFG, workers=1, progress=False)["c4_forward"]
    assert "error" not in r and json.loads((run / "summary.json").read_text())["rollers"] == 8


def test_a_finished_run_with_damaged_results_is_recomputed_not_skipped(finished, tmp_path, capsys):
    run = _copy(finished, tmp_path)
    data = (run / "results.nc").read_bytes()
    (run / "results.nc").write_bytes(data[: len(data) // 3])                      # truncated
    r = run_sweep([_case(run)], CFG, workers=1, progress=False)["c4_forward"]
    assert "skipped" not in r and "error" not in r
    assert len(_moved_aside(run, "results.nc")) == 1 and "results.nc is damaged" in capsys.readouterr().err
    import h5py
    with h5py.File(run / "results.nc", "r") as f:
        assert f["time"].shape[0] == r["samples"]


def test_a_damaged_checkpoint_or_chunk_is_moved_aside_and_the_run_starts_afresh(finished, tmp_path, capsys):
    import mbd
    from mbd.simulate import save_state

    run = _copy(finished, tmp_path)
    (run / "summary.json").unlink()                  # an unfinished run: the checkpoint is what it has
    (run / "checkpoint.npz").write_bytes(b"PK\x03\x04 cut off")
    assert not checkpoint_usable(run / "checkpoint.npz", run / "results.nc.parts")
    assert len(_moved_aside(run, "checkpoint.npz")) == 1
    # a loadable checkpoint whose recorder chunk is damaged cannot resume: both go aside
    state = mbd.State(0.001, np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), {})
    save_state(run / "checkpoint.npz", state, {"recorder": {"n_chunks": 1, "next_index": 5}})
    (run / "results.nc.parts").mkdir()
    (run / "results.nc.parts" / "chunk_000000.npz").write_bytes(b"garbage")
    assert not checkpoint_usable(run / "checkpoint.npz", run / "results.nc.parts")
    assert len(_moved_aside(run, "chunk_000000.npz")) == 1 and len(_moved_aside(run, "checkpoint.npz")) == 2
    # end to end: a damaged checkpoint of this very run (same fingerprint) never blocks it
    (run / "checkpoint.npz").write_bytes(b"not a zip file")
    r = run_sweep([_case(run)], CFG, workers=1, progress=False)["c4_forward"]
    assert "error" not in r and r["resumed_from_s"] is None
    assert len(_moved_aside(run, "checkpoint.npz")) == 3 and "checkpoint.npz is damaged" in capsys.readouterr().err


def _no_space_for(names, monkeypatch):
    """os.replace fails with ENOSPC when it would put one of ``names`` in place (the write itself went to a
    temporary file, as on a disk that fills up while a results file is written)."""
    import errno
    import os

    real = os.replace

    def replace(src, dst, *a, **k):
        if os.path.basename(dst) in names:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(dst))
        return real(src, dst, *a, **k)
    monkeypatch.setattr(os, "replace", replace)


def _leftovers(folder):
    return [p for p in folder.rglob("*") if ".tmp" in p.name]


def test_disk_full_keeps_earlier_results_and_leaves_no_temporary_files(finished, tmp_path, monkeypatch, capsys):
    from scenarios.core.command import FAILED, command
    from scenarios.core.runner import run_case

    run = _copy(finished, tmp_path)
    before = {n: (run / n).read_bytes() for n in ("results.nc", "summary.json")}
    _no_space_for({"results.nc"}, monkeypatch)
    code = paper_study.main(TINY + ["--set", "bearing.rollers=10", "--overwrite", "--out", str(tmp_path)])
    assert code == FAILED and "No space left on device" in capsys.readouterr().out
    assert {n: (run / n).read_bytes() for n in before} == before and not _leftovers(tmp_path)
    # the same fault outside a sweep reaches the command: one line, exit 1, what to do
    _no_space_for({"summary.json"}, monkeypatch)
    main = command(lambda argv: run_case(build_params(_case(run, 10)), CFG, run, overwrite=True))
    assert main([]) == FAILED
    err = capsys.readouterr().err
    assert err.startswith("error: No space left on device") and "run the same command again" in err
    assert err.count("\n") == 1 and (run / "summary.json").read_bytes() == before["summary.json"]
    assert not _leftovers(tmp_path)


def test_an_unwritable_output_folder_is_one_line(tmp_path, monkeypatch, capsys):
    import errno
    import os

    from scenarios.core.command import FAILED, command
    from mbd.recorder import atomic_write_text

    blocker = tmp_path / "a_file"
    blocker.write_text("")
    code = paper_study.main(TINY + ["--out", str(blocker / "out")])      # a folder that cannot exist
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: argument --out") and "a_file" in err and err.count("\n") == 1
    # a folder whose files cannot be replaced (read-only file system): the old file stays, no temporary left
    (tmp_path / "summary.json").write_text("old")
    real = os.replace
    monkeypatch.setattr(os, "replace", lambda s, d: (_ for _ in ()).throw(
        OSError(errno.EROFS, os.strerror(errno.EROFS), str(d))) if str(d).endswith("summary.json") else real(s, d))
    assert command(lambda argv: atomic_write_text(tmp_path / "summary.json", "new"))([]) == FAILED
    err = capsys.readouterr().err
    assert "Read-only file system" in err and "--out" in err and err.count("\n") == 1
    assert (tmp_path / "summary.json").read_text() == "old" and not _leftovers(tmp_path)


class _FakeFuture:
    def done(self):
        return False


class _FakeClient:
    """Stands in for dask.distributed.Client: records what the sweep asks of the scheduler."""
    made = []

    def __init__(self, address=None):
        self.address, self.submitted, self.cancelled, self.closed = address, [], [], False
        _FakeClient.made.append(self)

    def submit(self, fn, *a, **k):
        self.submitted.append(_FakeFuture())
        self.keys = [*getattr(self, "keys", []), k.get("key")]
        return self.submitted[-1]

    def cancel(self, futures, force=False):
        self.cancelled += list(futures)

    def close(self):
        self.closed = True

    def wait_for_workers(self, n_workers, timeout=None):     # the check of an existing scheduler's workers
        pass

    def run(self, fn):                                        # no worker to disagree with the client's code
        return {}

    def register_plugin(self, plugin):
        self.plugins = [*getattr(self, "plugins", []), plugin]


class _FakeCluster:
    made = []

    def __init__(self, **k):
        self.closed = False
        _FakeCluster.made.append(self)

    def close(self):
        self.closed = True


@pytest.mark.parametrize("scheduler", ["tcp://elsewhere:8786", None])
def test_an_interrupted_sweep_cancels_its_runs_and_stops_local_workers(scheduler, tmp_path, monkeypatch):
    import dask.distributed

    _FakeClient.made.clear()
    _FakeCluster.made.clear()
    monkeypatch.setattr(dask.distributed, "Client", _FakeClient)
    monkeypatch.setattr(dask.distributed, "LocalCluster", _FakeCluster)

    def ctrl_c(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(dask.distributed, "wait", ctrl_c)      # the user presses Ctrl-C while the runs are out
    cases = [_case(tmp_path / "a"), Case(4, "reverse", str(tmp_path / "b"), {"bearing.rollers": 8})]
    with pytest.raises(KeyboardInterrupt):
        run_sweep(cases, CFG, workers=2, scheduler=scheduler, progress=False)
    client, = _FakeClient.made
    assert len(client.submitted) == 2 and client.cancelled == client.submitted and client.closed
    assert [c.closed for c in _FakeCluster.made] == ([] if scheduler else [True])
    # the quick exit only for the workers of a cluster it started itself, never a scheduler's it was given
    assert [type(p).__name__ for p in getattr(client, "plugins", [])] == ([] if scheduler else ["QuickExit"])
    from dask.utils import key_split

    # the runs are one task group (Dask queues a large one on its scheduler, in the order submitted), keys unique
    assert {key_split(k) for k in client.keys} == {"run"} and len(set(client.keys)) == 2


def test_a_fixed_step_run_beyond_its_tolerance_warns(finished, tmp_path, capsys):
    from scenarios.core.runner import FIXED_STEP_ERROR_FACTOR

    # (the tiny run's start-up impacts also take Pan & Hamrock's film fit beyond its range: a validity warning)
    accuracy = lambda s: [w for w in s["warnings"] if "fixed step" in w]        # noqa: E731
    assert accuracy(json.loads((finished / "summary.json").read_text())) == []      # adaptive: none
    code = paper_study.main(TINY + ["--method", "hht-fixed", "--h", "1e-5", "--out", str(tmp_path)])
    s = json.loads((tmp_path / "c4_forward" / "summary.json").read_text())
    assert code == 0 and s["error_estimate"]["rms"] > FIXED_STEP_ERROR_FACTOR      # 10 us from the start: ~30 x
    assert len(accuracy(s)) == 1 and "fixed step h = 1e-05 s" in accuracy(s)[0]
    assert f"c4_forward: warning: {accuracy(s)[0]}" in capsys.readouterr().out


def test_wall_time_of_a_resumed_run_counts_every_segment(tmp_path, monkeypatch, capsys):
    """Interrupted late in its run, resumed from the checkpoint: wall_s is the first segment's time plus
    the second's, not the second's alone; before it runs, the sweep says it resumes and from which simulated time (the
    one the run then resumes from)."""
    import dataclasses
    import re
    import time

    import mbd
    from scenarios.core import runner
    from scenarios.core.sweep import resume_times, sweep

    real = mbd.simulate
    calls = []

    class CtrlC(mbd.Observer):
        def step(self, s0, s1):
            if s1.t > 0.8 * CFG.settle + 0.8 * CFG.window:
                raise KeyboardInterrupt

    def simulate(*a, observers=(), **k):
        calls.append(1)
        return real(*a, observers=[*observers, *([CtrlC()] if len(calls) == 1 else [])], **k)
    monkeypatch.setattr(mbd, "simulate", simulate)
    cfg = dataclasses.replace(CFG, checkpoint_every=20)
    params = build_params(_case(tmp_path))
    with pytest.raises(KeyboardInterrupt):
        runner.run_case(params, cfg, tmp_path)
    first = json.loads((tmp_path / "progress.json").read_text())["wall_s"]
    assert resume_times([_case(tmp_path, rollers=9)], cfg) == {}        # not a checkpoint of that run
    capsys.readouterr()
    t0 = time.perf_counter()
    s = sweep([_case(tmp_path)], cfg, workers=1, progress=False, announce=True)["c4_forward"].summary
    second = time.perf_counter() - t0
    assert s["resumed_from_s"] is not None and s["resumed_from_s"] > 0.5 * (CFG.settle + CFG.window)
    assert first < s["wall_s"] <= first + second
    said = re.search(r"runs: 1 to run, c4_forward from its checkpoint at ([\d.]+) ms, 0 reused", capsys.readouterr().out)
    assert said and float(said.group(1)) == pytest.approx(1e3 * s["resumed_from_s"], rel=5e-3)


def test_colliding_gears_are_refused_unless_forced(tmp_path, capsys):
    from scenarios.core.plausibility import check_runs

    code = paper_study.main(TINY + ["--planets", "4", "--out", str(tmp_path)])      # 4 pairs do not fit
    err = capsys.readouterr().err
    assert code == 2 and "would collide" in err and "--force" in err and err.count("\n") == 1
    assert not (tmp_path / "c4_forward").exists()
    params = build_params(Case(4, "forward", str(tmp_path), {"gears.planets": 4}))
    forced = check_runs([("c4_forward", params, CFG)], tmp_path, force=True)
    assert len(forced) == 1 and "gears.planets" in forced[0]


def test_output_size_is_estimated_and_checked_before_starting(tmp_path, monkeypatch, capsys):
    from scenarios.core import plausibility

    # 1 GHz over 0.5 ms: 5e5 samples of every recorded value (12 rollers: ~2000), 8 bytes, twice while joined
    assert paper_study.main(TINY + ["--sample-rate", "1e9", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = build_dpgt(reference_dpgt(4, "forward"))
    expect = plausibility.output_bytes(scene, 0.0005, 1e9)          # the recorder's own layout
    assert f"the recording would take {expect / 1e9:.1f} GB" in err and "more than 5 GB" in err
    assert "--sample-rate" in err and expect > 1e10
    monkeypatch.setattr(plausibility, "_free", lambda folder: 1e3)                  # a nearly full disk
    assert paper_study.main(TINY + ["--out", str(tmp_path)]) == 2
    assert "GB free" in capsys.readouterr().err and not (tmp_path / "c4_forward").exists()


def test_a_cluster_closes_behind_its_caller_and_at_once_on_an_error(monkeypatch):
    """dask_client(close_behind=timing): a block that ends normally returns before its client and local cluster are
    closed — a thread closes them while the caller goes on — and join_closing waits for that, its time in the timing;
    a block that raises closes them at once, before the error reaches the caller."""
    import threading

    import dask.distributed

    from scenarios.core import sweep as sw

    _FakeClient.made.clear()
    _FakeCluster.made.clear()
    monkeypatch.setattr(dask.distributed, "Client", _FakeClient)
    monkeypatch.setattr(dask.distributed, "LocalCluster", _FakeCluster)
    gate = threading.Event()
    monkeypatch.setattr(_FakeCluster, "close", lambda self: (gate.wait(10.0), setattr(self, "closed", True)))
    timing = {}
    with sw.dask_client(2, close_behind=timing):
        pass
    cluster, = _FakeCluster.made
    assert not cluster.closed and "cluster_close_s" not in timing       # still closing: the caller went on
    gate.set()
    assert sw.join_closing() >= 0.0 and cluster.closed and _FakeClient.made[0].closed
    assert timing["cluster_close_s"] >= 0.0 and timing["cluster_close_wait_s"] >= 0.0
    _FakeCluster.made.clear()
    with pytest.raises(RuntimeError, match="boom"):
        with sw.dask_client(2, close_behind={}):
            raise RuntimeError("boom")
    assert _FakeCluster.made[0].closed and sw._CLOSING == []


def test_one_run_left_runs_here_whatever_the_workers_asked(tmp_path, monkeypatch):
    """--workers 2 with one run left: no cluster is started for it (the run goes in this process)."""
    import dask.distributed

    from scenarios.core import sweep as sw

    monkeypatch.setattr(dask.distributed, "LocalCluster", lambda **k: pytest.fail("a cluster for one run"))
    monkeypatch.setattr(sw, "execute_case", lambda c, cfg, overwrite=False: sw.Outcome(c, sw.Status.FINISHED,
                                                                                         summary={}))
    monkeypatch.setattr(sw, "_is_finished", lambda c, cfg: False)
    timing = {}
    out = sw.sweep([_case(tmp_path / "a")], CFG, workers=2, progress=False, timing=timing)
    assert list(out) == [_case(tmp_path / "a").label] and timing["dask"] is False and timing["workers"] == 1


def test_the_estimate_deals_the_runs_to_the_workers_longest_first():
    """Runs of 0.1, 0.06 and 0.05 simulated seconds and a static solution on two workers: the longest alone on one,
    the next two on the other, the static solution onto the first to free (``R`` s of wall per simulated second,
    ``S`` per static solution); on one worker their sum; no runs, no time."""
    from scenarios.core.plausibility import STATIC_WALL_S as S, WALL_PER_SIMULATED_S as R, estimated_wall_s

    runs = [("a", 0.06), ("s", None), ("b", 0.1), ("c", 0.05)]
    assert S < 0.05 * R                     # the static solution is the shortest: it is dealt last
    assert estimated_wall_s(runs, 2) == pytest.approx(max(0.1 * R + S, 0.11 * R), rel=1e-12)
    assert estimated_wall_s(runs, 1) == pytest.approx(0.21 * R + S, rel=1e-12)
    assert estimated_wall_s(runs, 8) == pytest.approx(0.1 * R, rel=1e-12)     # one run a worker
    assert estimated_wall_s([], 2) == 0.0


def test_a_log_hears_of_the_running_runs_between_their_ends(tmp_path, monkeypatch, capsys):
    """Without a terminal (a log, a pipe) the runs' bars are off; every PLAIN_EVERY_S a line names each running run
    and its simulated time (from the progress.json its worker writes since the sweep began), a finished one no
    more."""
    from scenarios.core import sweep as sw
    cases = [_case(tmp_path / "a"), Case(4, "reverse", str(tmp_path / "b"), {"bearing.rollers": 8})]
    import os
    import time
    for c, t in zip(cases, (0.0125, 0.05)):
        Path(c.out_dir).mkdir(parents=True)
        (Path(c.out_dir) / "progress.json").write_text(json.dumps({"t": t, "t_end": 0.1, "wall_s": 1.0, "steps": 9}))
        os.utime(Path(c.out_dir) / "progress.json", (time.time() - 3600, time.time() - 3600))   # an hour ago
    monkeypatch.setattr(sw, "PLAIN_EVERY_S", 0.0)
    bars = sw._RunBars(cases, show=False, plain=True)
    bars.poll()
    assert capsys.readouterr().err == ""                 # written before the sweep: an interrupted run's, old news
    for c in cases:
        (Path(c.out_dir) / "progress.json").touch()      # written since: the workers' own
    bars.poll()
    assert capsys.readouterr().err == "runs: running c4_forward at t = 0.0125 of 0.1 s, c4_reverse at t = 0.05 of 0.1 s\n"
    bars.finish(cases[0])
    bars.poll()
    assert capsys.readouterr().err == "runs: running c4_reverse at t = 0.05 of 0.1 s\n"
    monkeypatch.setattr(sw, "PLAIN_EVERY_S", 3600.0)
    bars.poll()
    assert capsys.readouterr().err == ""                 # not again before its time
