"""The local cluster a sweep starts (scenarios.core.sweep.dask_client): its workers leave without finalising their
interpreters (scenarios.core.quick_exit) — what their tasks wrote is whole, and the processes are gone once the
cluster is closed — and each is handed its next task only when it has none left."""
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
