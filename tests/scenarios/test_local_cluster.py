"""The local cluster a sweep starts (scenarios.core.sweep.dask_client): its workers leave without finalising their
interpreters (scenarios.core.quick_exit) — what their tasks wrote is whole, and the processes are gone once the
cluster is closed — and each is handed its next task only when it has none left. A fresh study starts it while it
checks its runs (start_early), and the sweep takes that one over."""
import os
import time

import pytest

from scenarios.core.quick_exit import QuickExit
from scenarios.core.sweep import dask_client


def test_teardown_exits_a_closing_worker_at_once_with_a_clean_code_and_leaves_a_running_one(monkeypatch):
    """A worker that closes leaves with code 0; a teardown while it runs (the plugin registered again, which removes
    the first) leaves it alone."""
    from types import SimpleNamespace

    from distributed.core import Status

    codes = []

    def exit_(code):
        codes.append(code)
        raise SystemExit(code)
    monkeypatch.setattr(os, "_exit", exit_)
    QuickExit().teardown(worker=SimpleNamespace(status=Status.running))
    assert codes == []
    for status in (Status.closing, Status.closing_gracefully):
        with pytest.raises(SystemExit):
            QuickExit().teardown(worker=SimpleNamespace(status=status))
    assert codes == [0, 0]


def _write(path: str, n: int) -> int:
    import numpy as np

    np.save(path, np.arange(n, dtype=float))        # whole before the task returns
    return os.getpid()


def _gone(pid: int, wait_s: float = 10.0) -> bool:
    t0 = time.monotonic()
    while time.monotonic() - t0 < wait_s:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.05)
    return False


def test_a_local_clusters_workers_exit_after_their_work_is_written(tmp_path):
    with dask_client(2) as client:
        futs = [client.submit(_write, str(tmp_path / f"a{i}.npy"), 100_000 + i, pure=False) for i in range(4)]
        pids = set(client.gather(futs))
    import numpy as np

    for i in range(4):
        assert np.array_equal(np.load(tmp_path / f"a{i}.npy"), np.arange(100_000 + i, dtype=float))
    assert pids and os.getpid() not in pids and all(_gone(p) for p in pids)


def test_registering_the_quick_exit_again_leaves_the_workers_running():
    with dask_client(1) as client:
        client.register_plugin(QuickExit())          # a second time: Dask removes the first (its teardown)
        assert client.submit(os.getpid, pure=False).result(timeout=30) > 0


def test_a_local_cluster_hands_a_worker_its_next_task_only_when_it_has_none_left():
    """Worker saturation 1 on the clusters a sweep starts (Dask's default, 1.1, queues one more task per worker)."""
    with dask_client(2) as client:
        assert client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.WORKER_SATURATION) == 1.0


def test_a_cluster_started_early_is_the_one_the_sweep_takes_or_is_closed():
    """start_early starts a local cluster in a thread and returns at once; dask_client of that many local workers
    takes it (no second cluster, the workers' SIGINT blocked as the cluster's own start would leave it); of another
    size it closes it and starts its own; drop_early closes one nobody took."""
    import threading

    from scenarios.core import sweep as sw

    made = []
    real = sw._local_cluster

    def recorded(n):
        cluster = real(n)
        made.append((threading.current_thread().name, cluster))
        return cluster

    mp = pytest.MonkeyPatch()
    mp.setattr(sw, "_local_cluster", recorded)
    try:
        t0 = time.perf_counter()
        sw.start_early(2)
        assert time.perf_counter() - t0 < 0.5 and sw._EARLY["n"] == 2        # returned before the workers started
        with dask_client(2) as client:
            blocked = client.run(_sigint_blocked)
            assert len(blocked) == 2 and all(blocked.values())
        assert [name for name, _ in made] == ["dpgt-dask-start"] and not sw._EARLY
        assert made[0][1].status.name == "closed"

        sw.start_early(2)
        with dask_client(1) as client:                                        # another size: its own cluster
            assert len(client.scheduler_info()["workers"]) == 1
        assert [name for name, _ in made[1:]] == ["dpgt-dask-start", threading.current_thread().name]
        assert made[1][1].status.name == "closed" and not sw._EARLY

        sw.start_early(2)
        sw.drop_early()                                                       # nobody took it
        assert made[3][1].status.name == "closed" and not sw._EARLY
    finally:
        sw.drop_early()
        mp.undo()


def test_an_early_cluster_that_failed_to_start_raises_where_it_is_taken(monkeypatch):
    from scenarios.core import sweep as sw

    def broken(n):
        raise OSError("no free port")

    monkeypatch.setattr(sw, "_local_cluster", broken)
    sw.start_early(2)
    with pytest.raises(OSError, match="no free port"):
        with dask_client(2):
            pass
    assert not sw._EARLY


def _sigint_blocked() -> bool:
    import signal

    return signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())


TINY = ["--conditions", "3,4", "--directions", "forward", "--settle", "0.0005", "--window", "0.0005",
        "--set", "bearing.rollers=8", "--no-progress"]


class _Sentinel(Exception):
    pass


@pytest.mark.parametrize("workers, finished, starts", [(2, False, [2]), (2, True, []), (1, False, []),
                                                       (3, False, [2])],
                         ids=["fresh", "a run finished before", "one worker", "more workers than runs"])
def test_a_fresh_study_on_a_local_cluster_starts_it_before_its_checks(tmp_path, monkeypatch, workers, finished, starts):
    """A study whose runs all run (no summary.json in their folders) starts its local cluster of min(workers, runs)
    right after its parameters are checked; one that may reuse runs, or runs on one worker, starts none early."""
    from scenarios import paper_study
    from scenarios.core import study

    calls = []
    monkeypatch.setattr(study, "start_early", calls.append)

    def sweep(*a, **k):
        raise _Sentinel

    monkeypatch.setattr(study, "sweep", sweep)
    monkeypatch.setattr(study, "check_folders", lambda *a, **k: None)      # the planted summary is no real run's
    if finished:
        (tmp_path / "c3_forward").mkdir()
        (tmp_path / "c3_forward" / "summary.json").write_text("{}")
    with pytest.raises(_Sentinel):
        paper_study.run(paper_study.parse_args([*TINY, "--workers", str(workers), "--out", str(tmp_path)]))
    assert calls == starts


def test_a_study_refused_after_its_cluster_started_closes_it(tmp_path, monkeypatch):
    from scenarios import paper_study
    from scenarios.core import study
    from scenarios.core import sweep as sw

    made = []
    real = sw._local_cluster
    monkeypatch.setattr(sw, "_local_cluster", lambda n: made.append(real(n)) or made[-1])

    def refuse(*a, **k):
        raise _Sentinel

    monkeypatch.setattr(study, "check_folders", refuse)
    with pytest.raises(_Sentinel):
        paper_study.run(paper_study.parse_args([*TINY, "--workers", "2", "--out", str(tmp_path)]))
    assert len(made) == 1 and made[0].status.name == "closed" and not sw._EARLY
