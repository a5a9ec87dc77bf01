"""One run per output folder: a lock file holding the holder's pid, host and start time. A second run refuses
with a clear message; a lock left by a process that no longer exists (on this host) is taken over."""
from __future__ import annotations

import contextlib
import functools
import json
import os
import socket
import time
from pathlib import Path

__all__ = ["FolderLocked", "folder_lock", "holds_out_folder", "LOCK_NAME"]

LOCK_NAME = ".dpgt.lock"


class FolderLocked(RuntimeError):
    """The output folder is in use by another run (the message says which and what to do)."""


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:       # exists, another user's
        return True
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
            try:
                held = json.loads(lock.read_text() or "{}")
            except (OSError, ValueError):
                held = {}
            if held.get("pid") == me["pid"] and held.get("host") == me["host"]:
                yield folder                          # this process holds it already
                return
            if held.get("host") == me["host"] and isinstance(held.get("pid"), int) and not _alive(held["pid"]):
                lock.unlink(missing_ok=True)          # a dead holder on this host: take the lock over
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
