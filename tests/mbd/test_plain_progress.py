"""Progress that is not written to a terminal is plain lines, not a bar's escape codes."""
from __future__ import annotations

import importlib
import io

import numpy as np

sim = importlib.import_module("mbd.simulate")     # the module (mbd.simulate is also the function)


class _Pipe(io.StringIO):
    def isatty(self):
        return False


def test_simulation_progress_to_a_pipe_is_plain_lines(monkeypatch):
    pipe = _Pipe()
    monkeypatch.setattr(sim.sys, "stderr", pipe)
    clock = iter(np.arange(0.0, 1000.0, 1.5))              # 1.5 s of wall time between updates
    monkeypatch.setattr(sim.time, "perf_counter", lambda: next(clock))
    p = sim._Progress(0.0, 1.0, show=True)
    counters = sim.Counters()
    for t in np.linspace(0.05, 1.0, 20):
        p.update(t, counters)
    p.close()
    raw = pipe.getvalue()
    lines = raw.splitlines()
    assert "\r" not in raw and "\x1b" not in raw                 # no carriage returns, no escape codes
    assert lines and all(line.startswith("simulating: t = ") for line in lines)
    assert len(lines) <= 20 * 1.5 / sim._Progress.PLAIN_EVERY + 1           # one line every PLAIN_EVERY seconds


def test_the_time_left_is_said_only_once_the_run_is_past_its_start(monkeypatch):
    """The kinematic start's short steps extrapolate to many times the real time left: no estimate before
    SETTLED_SHARE of the simulated time, then the plain extrapolation (here exact: 10 s per 0.1 s simulated)."""
    pipe = _Pipe()
    monkeypatch.setattr(sim.sys, "stderr", pipe)
    clock = iter(np.arange(0.0, 1000.0, 10.0))              # 10 s of wall time between updates
    monkeypatch.setattr(sim.time, "perf_counter", lambda: next(clock))
    p = sim._Progress(0.0, 1.0, show=True)
    counters = sim.Counters()
    for t in (0.05, 0.09, 0.2):                 # wall 10, 20, 30 s after the start
        p.update(t, counters)
    lines = pipe.getvalue().splitlines()
    assert [("estimating" in line, "s left" in line) for line in lines] == [(True, False), (True, False), (False, True)]
    assert lines[-1].endswith("about 120 s left")     # (1 − 0.2)/0.2 × 30 s
