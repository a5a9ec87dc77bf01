"""Studies on a real Dask cluster that shares no filesystem with the client: a `dask scheduler` and two `dask worker`
processes on loopback, each started in a temporary directory of its own (its own working directory and temporary
directory, so neither sees the client's --out), importing this checkout (its numba cache is warm: `make test` warms
it first). What the client finds in its --out is compared with the same study on a local cluster."""
from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import xarray as xr
from distributed import Client

from scenarios.core import cluster as clusterlib
from scenarios.core.runner import RunConfig, code_digest
from scenarios.core.sweep import Case, Status, dask_client, sweep

ROOT = Path(__file__).resolve().parents[2]
START_S = 180.0           # a scheduler and its workers start within this (a loaded 2-core machine imports slowly)
STUDY_S = 600.0           # a small study ends within this
SHORT = ["--settle", "0.002", "--window", "0.002", "--no-progress"]
RUN_TIMES = ("wall_s", "compile_s", "timing")     # what differs between two runs of the same case: the run's times


def _dask() -> list[str]:
    exe = Path(sys.executable).with_name("dask")
    return [str(exe)] if exe.exists() else [shutil.which("dask") or "dask"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _env(**extra) -> dict:
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path, "DPGT_PROGRESS": "0", **extra}


@dataclass
class Cluster:
    address: str
    home: Path
    procs: dict = field(default_factory=dict)      # name -> Popen (each the leader of its own process group)
    workers: dict = field(default_factory=dict)    # name -> the worker's address

    def start(self, name: str, argv: list[str], env: dict | None = None) -> None:
        d = self.home / name
        d.mkdir(parents=True, exist_ok=True)
        log = open(d / "log.txt", "w")
        self.procs[name] = subprocess.Popen(argv, cwd=d, env=env or _env(TMPDIR=str(d)), stdout=log,
                                            stderr=subprocess.STDOUT, start_new_session=True)

    def start_worker(self, name: str, env: dict | None = None) -> None:
        port = _free_port()
        self.workers[name] = f"tcp://127.0.0.1:{port}"
        d = self.home / name
        self.start(name, [*_dask(), "worker", self.address, "--nthreads", "1", "--no-dashboard", "--name", name,
                          "--host", "127.0.0.1", "--worker-port", str(port), "--local-directory", str(d)],
                   env or _env(TMPDIR=str(d)))

    def kill(self, name: str) -> None:
        p = self.procs.pop(name, None)
        if p is not None and p.poll() is None:
            try:
                os.killpg(p.pid, signal.SIGKILL)      # the nanny and its worker
            except ProcessLookupError:
                pass
            p.wait(timeout=30)

    def wait_for(self, n_workers: int) -> None:
        with Client(self.address, timeout=START_S, set_as_default=False) as c:
            c.wait_for_workers(n_workers, timeout=START_S)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    home = tmp_path_factory.mktemp("cluster")
    port = _free_port()
    c = Cluster(f"tcp://127.0.0.1:{port}", home)
    try:
        c.start("scheduler", [*_dask(), "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"])
        c.start_worker("w1")
        c.start_worker("w2")
        c.wait_for(2)
        yield c
    finally:
        for name in list(c.procs):
            c.kill(name)


def _study(module: str, argv: list[str], cwd: Path) -> subprocess.CompletedProcess:
    cwd.mkdir(parents=True, exist_ok=True)
    r = subprocess.run([sys.executable, "-m", f"scenarios.{module}", *argv], cwd=cwd, env=_env(), text=True,
                       capture_output=True, timeout=STUDY_S)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return r


def _summary(path: Path) -> dict:
    s = json.loads(path.read_text())
    return {k: v for k, v in s.items() if k not in RUN_TIMES}


def _same_run(a: Path, b: Path) -> None:
    """Two folders hold the same run: summaries equal but for the run's times, recordings equal in every variable."""
    assert _summary(a / "summary.json") == _summary(b / "summary.json")
    with xr.open_dataset(a / "results.nc") as da, xr.open_dataset(b / "results.nc") as db:
        xr.testing.assert_equal(da, db)
        assert da.sizes["time"] > 0


def _untimed_rows(path: Path) -> list[dict]:
    """A table's rows without its time columns (``*_s``: the solver's own time)."""
    with open(path, newline="") as fh:
        rows = [{k: v for k, v in r.items() if not k.endswith("_s")} for r in csv.DictReader(fh)]
    assert rows
    return rows


def _scratch_left(c: Cluster) -> list[Path]:
    """The run folders left in the workers' scratch (a finished run's is removed once its files travelled)."""
    return [p for w in c.workers for p in (c.home / w / clusterlib.SCRATCH).glob("*") if p.name != "params"]


@pytest.mark.slow
def test_a_paper_study_lands_in_the_client_s_relative_out_as_on_a_local_cluster(cluster, tmp_path):
    """The bug this guards: a worker in another directory wrote a relative --out under its own directory."""
    argv = ["--conditions", "4", "--directions", "forward,reverse", *SHORT]
    r = _study("paper_study", [*argv, "--scheduler", cluster.address, "--out", "relout"], tmp_path / "client")
    out = tmp_path / "client" / "relout"
    assert "runs: 2 finished now" in r.stdout
    for w in cluster.workers:            # nothing under the workers' own directories
        assert not (cluster.home / w / "relout").exists()
    assert not _scratch_left(cluster)
    _study("paper_study", [*argv, "--workers", "2", "--out", str(tmp_path / "local")], tmp_path)
    for label in ("c4_forward", "c4_reverse"):
        _same_run(out / label, tmp_path / "local" / label)
    assert (out / "comparison.csv").read_bytes() == (tmp_path / "local" / "comparison.csv").read_bytes()


@pytest.mark.slow
def test_a_tolerance_study_s_batches_and_runs_land_as_on_a_local_cluster(cluster, tmp_path):
    argv = ["--samples", "3", "--dynamic", "1", "--gear-class", "5", "--torques", "1", "--conditions", "3",
            "--directions", "forward", "--snapshots", "2", *SHORT]
    remote, local = tmp_path / "remote", tmp_path / "local"
    _study("tolerance_study", [*argv, "--scheduler", cluster.address, "--out", str(remote)], tmp_path / "client")
    _study("tolerance_study", [*argv, "--workers", "2", "--out", str(local)], tmp_path)
    statics = sorted(p.relative_to(local) for p in (local / "static").rglob("*.json"))
    assert len(statics) == 4 and statics == sorted(p.relative_to(remote) for p in (remote / "static").rglob("*.json"))
    for rel in statics:
        a, b = json.loads((remote / rel).read_text()), json.loads((local / rel).read_text())
        for rec in (a, b):      # the solver's own times differ between two solutions of the same machine
            rec["static_solver"] = {k: v for k, v in rec.get("static_solver", {}).items() if not k.endswith("_s")}
        assert a == b and a["static_solver"]["steps"] > 0, rel
    assert _untimed_rows(remote / "samples.csv") == _untimed_rows(local / "samples.csv")
    dynamic = sorted(p.parent.name for p in local.glob("*/summary.json"))
    assert len(dynamic) == 2 and dynamic == sorted(p.parent.name for p in remote.glob("*/summary.json"))
    for label in dynamic:
        _same_run(remote / label, local / label)


@pytest.mark.slow
def test_a_worker_killed_during_a_run_loses_no_finished_run_and_the_run_completes(cluster, tmp_path):
    """One short run lands; the worker of the long one is killed mid-run: the scheduler gives the run to the other
    worker (or, if it gives up, the run is named failed and the same sweep again completes it)."""
    short = Case(4, "forward", str(tmp_path / "out" / "short"), window=0.002)
    # long enough that the short run lands while it runs, on a loaded machine too
    long = Case(4, "reverse", str(tmp_path / "out" / "long"), window=0.06)
    cfg = RunConfig(settle=0.002, progress=False)
    got, raised = {}, []

    def study():
        try:
            got.update(sweep([short, long], cfg, scheduler=cluster.address, progress=False))
        except BaseException as exc:        # said by the assertion below, not lost in the thread
            raised.append(exc)
    t = threading.Thread(target=study)
    t.start()
    landed = Path(short.out_dir) / "summary.json"
    deadline = time.monotonic() + STUDY_S
    victim = None
    # not the default client: the sweep in the thread holds that, and closing out of order would leave dask
    # configured for a scheduler no client serves (xarray then fails to write netCDF in later tests)
    with Client(cluster.address, timeout=30, set_as_default=False) as watch:
        while victim is None and time.monotonic() < deadline and t.is_alive():
            running_long = [w for w, keys in watch.processing().items()
                            if any(k.startswith(f"run-{long.label}-") for k in keys)]    # the sweep's task keys
            if landed.exists() and running_long:
                time.sleep(1.0)                  # into the run
                victim = next(n for n, a in cluster.workers.items() if a == running_long[0])
                before = landed.read_bytes()
                cluster.kill(victim)
            else:
                time.sleep(0.2)
    t.join(STUDY_S)
    assert not raised and victim is not None and not t.is_alive(), (raised, landed.exists())
    assert landed.read_bytes() == before                      # the finished run is kept as it landed
    if got["c4_reverse"].status is Status.FAILED:             # Dask gave up on it: named, and a re-run completes it
        assert "worker failure" in got["c4_reverse"].error
        got = sweep([short, long], cfg, scheduler=cluster.address, progress=False)
        assert got["c4_forward"].status is Status.REUSED
    assert got["c4_reverse"].status is Status.FINISHED and got["c4_reverse"].ok
    with xr.open_dataset(Path(long.out_dir) / "results.nc") as ds:
        assert ds.sizes["time"] == json.loads((Path(long.out_dir) / "summary.json").read_text())["samples"] > 0
    again = sweep([short, long], cfg, scheduler=cluster.address, progress=False)   # decided here, from this folder
    assert {k: o.status for k, o in again.items()} == {"c4_forward": Status.REUSED, "c4_reverse": Status.REUSED}


def test_a_worker_running_other_code_is_refused_naming_both_fingerprints(cluster, tmp_path):
    other = tmp_path / "other"
    for pkg in ("mbd", "components", "scenarios"):
        shutil.copytree(ROOT / pkg, other / pkg, ignore=shutil.ignore_patterns("__pycache__", "*.nb[ic]"))
    with open(other / "components" / "__init__.py", "a") as fh:
        fh.write("\n# another version of the code\n")
    env = {**_env(), "PYTHONPATH": str(other), "TMPDIR": str(tmp_path / "w3")}
    theirs = subprocess.run([sys.executable, "-c", "from scenarios.core.runner import code_digest; "
                             "print(code_digest())"], cwd=other, env=env, text=True, capture_output=True,
                            check=True, timeout=START_S).stdout.strip()
    assert theirs != code_digest()
    cluster.start_worker("w3", env)
    try:
        cluster.wait_for(len(cluster.procs) - 1)       # every worker started (the scheduler is one of the procs)
        with pytest.raises(SystemExit) as refused:
            with dask_client(1, cluster.address):
                pass
        words = str(refused.value)
        assert theirs[:16] in words and code_digest()[:16] in words and cluster.workers["w3"] in words
    finally:
        cluster.kill("w3")


def test_a_task_on_a_worker_of_other_code_fails_naming_both_fingerprints(tmp_path):
    """The guard every task carries (a worker that joined after the check): a failed outcome, nothing run."""
    from scenarios.core.sweep import execute_on_worker

    fake = "0" * 64
    t = execute_on_worker(Case(4, "forward", str(tmp_path / "c4")), RunConfig(progress=False), False, fake, {})
    assert t.outcome.status is Status.FAILED and not t.files
    assert fake[:16] in t.outcome.error and code_digest()[:16] in t.outcome.error
    assert not (tmp_path / "c4").exists()


class _Client:
    def __init__(self, states):
        self.states = states
        self.warmed = []

    def wait_for_workers(self, n, timeout):
        if not self.states:
            raise TimeoutError

    def run(self, fn, workers=None):
        if fn is clusterlib.warm_here:
            self.warmed.append(list(workers))
            return {w: "engine kernels: compiled in 1 s" for w in workers}
        return self.states


def test_the_cluster_warms_up_before_the_runs_one_worker_per_machine(capsys):
    mine = code_digest()
    states = {"tcp://a:1": {"code": mine, "warm": False, "host": "a"},
              "tcp://a:2": {"code": mine, "warm": False, "host": "a"},     # shares machine a's numba cache
              "tcp://b:1": {"code": mine, "warm": True, "host": "b"},
              "tcp://c:1": {"code": mine, "warm": False, "host": "c"}}
    client = _Client(states)
    clusterlib.check_workers(client, "tcp://s:2")
    assert client.warmed == [["tcp://a:2", "tcp://c:1"]]               # one cold worker per machine, once, together
    out = capsys.readouterr().out
    assert "warming the cluster: compiling the kernels on 2 machine(s) before any run" in out
    assert "worker tcp://c:1: engine kernels: compiled in 1 s" in out
    warm = _Client({w: {**s, "warm": True} for w, s in states.items()})
    clusterlib.check_workers(warm, "tcp://s:2")
    assert warm.warmed == [] and "warming" not in capsys.readouterr().out


def test_a_cold_worker_is_named_once_and_no_worker_is_a_one_line_error(capsys):
    mine = code_digest()
    states = {"tcp://a:1": {"code": mine, "warm": False, "host": "a"}, "tcp://b:1": {"code": mine, "warm": True,
                                                                                     "host": "b"}}
    clusterlib.check_workers(_Client(states), "tcp://s:1")
    out = capsys.readouterr().out
    assert out.count("not compiled") == 1 and "tcp://a:1" in out and "tcp://b:1" not in out
    clusterlib.check_workers(_Client(states), "tcp://s:1")       # the study's next connection: said already
    assert "not compiled" not in capsys.readouterr().out
    with pytest.raises(SystemExit, match="no worker joined the scheduler tcp://s:1"):
        clusterlib.check_workers(_Client({}), "tcp://s:1", wait_s=0.1)


def test_a_run_s_files_land_atomically_with_the_summary_last(tmp_path, monkeypatch):
    order = []
    real = clusterlib.atomic_write_bytes
    monkeypatch.setattr(clusterlib, "atomic_write_bytes", lambda p, b: (order.append(Path(p).name), real(p, b)))
    files = {"summary.json": b"{}", "results.nc": b"\x89HDF", "fingerprint": b"abc"}
    clusterlib.land(tmp_path / "run", files)
    assert order[-1] == "summary.json" and sorted(order) == sorted(files)
    assert clusterlib.folder_files(tmp_path / "run") == files


@pytest.mark.slow
@pytest.mark.parametrize("when", ["cluster starting", "runs running"])
def test_ctrl_c_of_a_study_on_a_local_cluster_says_interrupted_and_nothing_else(when, tmp_path):
    """Ctrl-C reaches the terminal's whole process group: the local cluster's workers too. The command ends with its
    one line, no worker's or nanny's traceback, and leaves no process, lock or temporary file behind."""
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "scenarios.paper_study", "--conditions", "4", "--directions",
                          "forward,reverse", "--settle", "0.002", "--window", "0.05", "--workers", "2", "--no-progress",
                          "--out", str(out)], cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, start_new_session=True,
                         # a terminal's command takes Ctrl-C; a pytest-xdist worker ignores SIGINT, and a child
                         # would inherit that
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + STUDY_S
        if when == "cluster starting":      # the sweep says how many runs it has, then starts its cluster
            for line in p.stdout:
                if line.startswith("runs:") or time.monotonic() > deadline:
                    break
        else:                               # a run writes its progress once it integrates
            while not list(out.glob("*/progress.json")) and p.poll() is None and time.monotonic() < deadline:
                time.sleep(0.2)
        assert p.poll() is None, p.stderr.read()
        os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate(timeout=120)
        assert p.returncode == 130, err
        assert err.strip().splitlines()[-1].startswith("interrupted: finished runs and checkpoints are kept"), err
        assert "Traceback" not in err and "CancelledError" not in err and "Error" not in err, err
        # the stopped workers' locks and unfinished writes are gone; their checkpoints stay for the resume
        left = sorted(str(f.relative_to(out)) for f in [*out.rglob(".dpgt.lock"), *out.rglob(".*.tmp*")])
        assert left == [], left
        time.sleep(2.0)
        with pytest.raises(ProcessLookupError):    # the workers stopped with it
            os.killpg(p.pid, 0)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)
        p.wait(timeout=30)
