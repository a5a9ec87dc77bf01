"""One run per output folder (scenarios.core.lock): a second run refuses, a dead holder's lock is taken over with the
temporary files it left."""
from __future__ import annotations

import json
import os
import socket
import subprocess
import sys

import pytest

from scenarios import paper_study
from scenarios.core.lock import LOCK_NAME, FolderLocked, folder_lock, release_dead


def _hold(folder, pid):
    (folder / LOCK_NAME).write_text(json.dumps({"pid": pid, "host": socket.gethostname(), "started": "earlier"}))


def test_a_live_holder_keeps_the_folder(tmp_path, capsys):
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        _hold(tmp_path, other.pid)
        with pytest.raises(FolderLocked, match=f"in use by pid {other.pid}.*delete"):
            with folder_lock(tmp_path):
                pass
        # through a command: one line, exit 1, the results folder untouched
        assert paper_study.main(["--conditions", "4", "--out", str(tmp_path)]) == 1
        err = capsys.readouterr().err
        assert err.startswith("error: ") and f"pid {other.pid}" in err and err.count("\n") == 1
        assert not (tmp_path / "c4_forward").exists()
    finally:
        other.kill()
        other.wait()


def test_a_dead_holders_lock_is_taken_over_and_released(tmp_path):
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    _hold(tmp_path, gone.pid)
    with folder_lock(tmp_path):
        held = json.loads((tmp_path / LOCK_NAME).read_text())
        assert held["pid"] != gone.pid
        with folder_lock(tmp_path):          # re-entrant in the holding process
            pass
        assert (tmp_path / LOCK_NAME).exists()
    assert not (tmp_path / LOCK_NAME).exists()


def test_a_dead_holders_unfinished_writes_go_with_its_lock_and_no_one_elses(tmp_path):
    """A worker killed in a write leaves its temporary file (``.NAME.tmpPID``, mbd.recorder's atomic writes); taking
    its lock over removes that process's, in the folder and below, and leaves those of other processes."""
    from mbd.recorder import atomic_write_text
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    _hold(tmp_path, gone.pid)
    (tmp_path / "parts").mkdir()
    left = [tmp_path / f".checkpoint.npz.tmp{gone.pid}", tmp_path / "parts" / f".chunk_000003.npz.tmp{gone.pid}"]
    others = [tmp_path / f".checkpoint.npz.tmp{gone.pid}1", tmp_path / f".progress.json.tmp{os.getpid()}"]
    for p in (*left, *others):
        p.write_bytes(b"")
    atomic_write_text(tmp_path / "kept.json", "{}")       # a finished write: no temporary, the file stays
    with folder_lock(tmp_path):
        assert not any(p.exists() for p in left)
        assert all(p.exists() for p in others) and (tmp_path / "kept.json").exists()
    assert not release_dead(tmp_path)                     # nothing left to release


def test_a_live_or_foreign_holder_is_not_released(tmp_path):
    _hold(tmp_path, os.getpid())
    (tmp_path / f".summary.json.tmp{os.getpid()}").write_bytes(b"")
    assert not release_dead(tmp_path) and (tmp_path / LOCK_NAME).exists()
    (tmp_path / LOCK_NAME).write_text(json.dumps({"pid": 2 ** 22 + 7, "host": "another-host", "started": "earlier"}))
    assert not release_dead(tmp_path) and (tmp_path / LOCK_NAME).exists()


def test_an_ended_holder_not_yet_reaped_is_dead_and_one_ending_is_waited_for(tmp_path):
    """A worker that ended but whose parent has not reaped it yet (a zombie) holds nothing; a holder still ending is
    given ``wait`` seconds."""
    import time
    ended = subprocess.Popen([sys.executable, "-c", "pass"])
    time.sleep(1.0)                                     # ended; its parent (this process) has not waited for it
    _hold(tmp_path, ended.pid)
    assert release_dead(tmp_path) and not (tmp_path / LOCK_NAME).exists()
    ended.wait()
    ending = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(0.5)"])
    _hold(tmp_path, ending.pid)
    assert not release_dead(tmp_path)                   # still running, not waited for
    assert release_dead(tmp_path, wait=20.0) and not (tmp_path / LOCK_NAME).exists()
    ending.wait()
