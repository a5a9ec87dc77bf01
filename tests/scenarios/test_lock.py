"""One run per output folder (scenarios.core.lock): a second run refuses, a dead holder's lock is taken over."""
from __future__ import annotations

import json
import socket
import subprocess
import sys

import pytest

from scenarios import paper_study
from scenarios.core.lock import LOCK_NAME, FolderLocked, folder_lock


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
