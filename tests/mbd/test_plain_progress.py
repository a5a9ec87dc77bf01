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
