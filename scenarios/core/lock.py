"""One run per output folder: a lock file holding the holder's pid, host and start time. A second run refuses
with a clear message; a lock left by a process that no longer exists (on this host) is taken over, and the temporary
files that process left in the folder are removed with it."""
from __future__ import annotations

import contextlib
import functools
import json
import os
import socket
import time
from pathlib import Path

from mbd.recorder import temporaries

__all__ = ["FolderLocked", "folder_lock", "holds_out_folder", "release_dead", "LOCK_NAME"]

LOCK_NAME = ".dpgt.lock"


class FolderLocked(RuntimeError):
    """The output folder is in use by another run (the message says which and what to do)."""


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists and has not ended: a zombie (ended, not yet reaped by its parent) has."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:       # exists, another user's
        return True
    try:
        # /proc/PID/stat: "pid (name) state ...", the name may hold spaces and parentheses
        return Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0] != "Z"
    except (OSError, IndexError):  # no /proc (not Linux), or it ended just now: alive, the safe answer for a lock
        return True


def _holder(lock: Path) -> dict:
    try:
        return json.loads(lock.read_text() or "{}")
    except (OSError, ValueError):
        return {}


def _dead(held: dict) -> bool:
    return held.get("host") == socket.gethostname() and isinstance(held.get("pid"), int) and not _alive(held["pid"])


def release_dead(folder, wait: float = 0.0) -> bool:
    """Remove ``folder``'s lock if its holder was a process of this host that no longer exists (a worker stopped in
    the middle of a run), and the temporary files that process left below the folder; whether there was one.
    ``wait`` [s]: how long a holder of this host that still runs is given to end (a worker being stopped)."""
    lock = Path(folder) / LOCK_NAME
    held = _holder(lock)
    deadline = time.monotonic() + wait
    while not _dead(held) and held.get("host") == socket.gethostname() and time.monotonic() < deadline:
        time.sleep(0.05)
    if not _dead(held):
        return False
    for tmp in temporaries(folder, held["pid"]):
        tmp.unlink(missing_ok=True)
    lock.unlink(missing_ok=True)
    return True


@contextlib.contextmanager
def folder_lock(folder):
    """Hold ``folder``'s lock for the duration (re-entrant for this process: a study and its in-process runs)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / LOCK_NAME
    me = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            held = _holder(lock)
            if held.get("pid") == me["pid"] and held.get("host") == me["host"]:
                yield folder                          # this process holds it already
                return
            if release_dead(folder):                  # a dead holder on this host: take the lock over
                continue
            raise FolderLocked(f"{folder} is in use by pid {held.get('pid', '?')} on {held.get('host', '?')} since "
                               f"{held.get('started', '?')}; wait for that run, or delete {lock} if it is gone")
        with os.fdopen(fd, "w") as fh:
            json.dump(me, fh)
        try:
            yield folder
        finally:
            lock.unlink(missing_ok=True)
        return
    raise FolderLocked(f"{folder}: could not take the lock {lock}")


def holds_out_folder(run):
    """A study's ``run(args)`` holding the lock of ``args.out`` throughout (one study per folder at a time)."""
    @functools.wraps(run)
    def locked(a):
        with folder_lock(a.out):
            return run(a)
    return locked
