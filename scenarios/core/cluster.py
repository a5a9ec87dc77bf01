"""Studies on a cluster that shares no filesystem with the client (``--scheduler ADDR``: cloud machines, Kubernetes, a
lab's spare computers; an HPC cluster whose nodes do share one works the same way).

* Before anything runs, every worker of the scheduler is asked for its code fingerprint
  (:func:`scenarios.core.runner.code_digest`, the one each run's fingerprint contains) and whether numba's cache holds
  the engine's kernels. A worker running other code is refused, both fingerprints named: mixed code would give mixed
  results under one fingerprint. A cold worker is named once: its first run compiles the kernels (about a minute).
  Every task carries the client's fingerprint too, so a worker that joins later with other code fails its task
  instead of running it.
* A worker runs a case in a scratch folder of its own (:func:`scratch_folder`, under its temporary directory, named
  by what the case is, so a retried run on the same machine resumes from its checkpoint) and returns the files the
  run left there as bytes (:func:`folder_files`); the client writes them atomically into its own ``--out``
  (:func:`land`), the summary last. A ``--params`` file travels as its text (:func:`params_texts`,
  :func:`relocated`). A finished run's scratch folder is removed; a failed or killed one stays for a resume.

What travels per run: its ``results.nc`` (about 18 kB per recorded sample: a default run of condition 3, 553
samples, is 10 MB; of condition 1, the longest default window, 2320 samples, 41 MB), its summary (about 25 kB) and
a few small files. Dask moves such results between worker and client as ordinary task results (its documentation
calls array chunks of 100 MB usual, docs.dask.org "Array best practices").
"""
from __future__ import annotations

import dataclasses
import hashlib
import shutil
import socket
import tempfile
from pathlib import Path

from components.results.io import atomic_write_bytes
from components.results.reader import SUMMARY_NAME

from .runner import code_digest

__all__ = ["worker_state", "check_workers", "warm_here", "other_code", "scratch_folder", "folder_files", "land", "params_texts",
           "relocated", "done_on_worker", "WORKER_WAIT_S", "SCRATCH"]

SCRATCH = "dpgt-scratch"       # the folder of the workers' scratch folders, in their temporary directory
WORKER_WAIT_S = 60.0           # how long a study waits for the first worker to join the scheduler
_NAMED_COLD: set = set()       # (scheduler, worker) named cold already by this process (a study connects more than once)
_LEFT_BEHIND = ("checkpoint.npz", "progress.json", ".dpgt.lock")   # a run's working files: they stay on the worker


def worker_state() -> dict:
    """What the client checks of a worker (run on each by ``client.run``): its code fingerprint, whether numba's disk
    cache holds the engine's kernels of this code, its host."""
    from mbd.compiled import kernels_cached   # deferred: numba is imported on the worker, not to check the client

    return {"code": code_digest(), "warm": kernels_cached(), "host": socket.gethostname()}


def other_code(client_code: str) -> str | None:
    """None when this process runs the client's code (``client_code``, its :func:`code_digest`), else the refusal."""
    mine = code_digest()
    if mine == client_code:
        return None
    return (f"this worker ({socket.gethostname()}) runs other code than the client: code fingerprint {mine[:16]} "
            f"here, {client_code[:16]} on the client; install the client's version of the project on every worker")


def check_workers(client, scheduler: str, wait_s: float = WORKER_WAIT_S) -> dict:
    """Refuse a cluster with no worker (after ``wait_s``) or with a worker whose code fingerprint differs from this
    client's, both fingerprints named; name each worker whose kernels are not compiled yet, once. Returns {worker
    address: :func:`worker_state`}."""
    try:
        client.wait_for_workers(1, timeout=wait_s)
    except TimeoutError:
        raise SystemExit(f"error: no worker joined the scheduler {scheduler} within {wait_s:g} s; start workers with "
                         f"`dask worker {scheduler}` (README: On a cluster)") from None
    states = client.run(worker_state)
    mine = code_digest()
    other = {w: s for w, s in sorted(states.items()) if s["code"] != mine}
    if other:
        named = "; ".join(f"{w} ({s['host']}) runs code fingerprint {s['code'][:16]}" for w, s in other.items())
        raise SystemExit(f"error: refused: {named}, this client {mine[:16]}; install the client's version of the "
                         f"project on every worker (pip install, README: On a cluster) and restart them")
    for w, s in sorted(states.items()):
        if not s["warm"] and (scheduler, w) not in _NAMED_COLD:
            _NAMED_COLD.add((scheduler, w))
            print(f"worker {w} ({s['host']}): the engine's kernels of this code are not compiled there yet", flush=True)
    # the cluster warms up before the runs: one worker per machine compiles (a machine's workers share numba's cache)
    cold = {s["host"]: w for w, s in sorted(states.items()) if not s["warm"]}
    if cold:
        print(f"warming the cluster: compiling the kernels on {len(cold)} machine(s) before any run (about a minute "
              f"each, in parallel; `python -m scenarios.warm` on a worker does it beforehand)", flush=True)
        for w, line in sorted(client.run(warm_here, workers=sorted(cold.values())).items()):
            print(f"worker {w}: {line}", flush=True)
    return states


def warm_here() -> str:
    """Compile (or load) the engine's kernels on this worker (run by ``client.run``); the line saying which."""
    from components.warm import warm    # deferred: the engine is built on the worker, not on the client

    return warm()


def scratch_folder(what: str, label: str) -> Path:
    """The worker's own folder for a run (``what``: text that identifies the run; ``label``: its name): under the
    worker's temporary directory, the same for the same run, so a retry on this machine resumes its checkpoint."""
    digest = hashlib.sha256(what.encode()).hexdigest()[:16]
    return Path(tempfile.gettempdir()) / SCRATCH / f"{label}-{digest}"


def folder_files(folder) -> dict[str, bytes]:
    """{name: content} of the files a run left in ``folder`` (its working files — checkpoint, progress, lock — stay)."""
    folder = Path(folder)
    if not folder.is_dir():
        return {}
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file() and p.name not in _LEFT_BEHIND
            and not p.name.startswith(".")}


def land(folder, files: dict[str, bytes]) -> None:
    """Write ``files`` ({name: content}) into ``folder`` atomically each, the summary last (a summary on disk means
    the run's other files are there)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name in sorted(files, key=lambda n: n == SUMMARY_NAME):
        atomic_write_bytes(folder / name, files[name])


def done_on_worker(folder) -> None:
    """Remove a finished run's scratch folder (its files have been read to travel)."""
    shutil.rmtree(folder, ignore_errors=True)


def _params_fields(obj):
    """(path to the field, value) of every ``params_file`` field of ``obj`` and of the dataclasses it holds."""
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        return
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if f.name == "params_file" and v:
            yield v
        elif dataclasses.is_dataclass(v):
            yield from _params_fields(v)


def params_texts(objs) -> dict[str, str]:
    """{path: text} of the ``--params`` files ``objs`` (cases or tasks: dataclasses) name, read on the client."""
    return {p: Path(p).read_text(encoding="utf-8") for o in objs for p in _params_fields(o)}


def relocated(obj, texts: dict[str, str]):
    """``obj`` with each ``params_file`` it names replaced by a copy of the client's file written on this worker
    (``texts``: :func:`params_texts`), under its scratch directory, named by the content."""
    if not texts or not dataclasses.is_dataclass(obj):
        return obj
    changes = {}
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        if f.name == "params_file" and v in texts:
            changes[f.name] = str(_local_copy(v, texts[v]))
        elif dataclasses.is_dataclass(v):
            new = relocated(v, texts)
            if new is not v:
                changes[f.name] = new
    return dataclasses.replace(obj, **changes) if changes else obj


def _local_copy(path: str, text: str) -> Path:
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    local = Path(tempfile.gettempdir()) / SCRATCH / "params" / digest / Path(path).name
    if not local.exists():
        local.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(local, text.encode("utf-8"))
    return local

