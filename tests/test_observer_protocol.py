"""The one simulation loop and its observers: an observer sees every accepted step, in order, chained."""
from __future__ import annotations

import numpy as np

import mbd
from components.planetary import build_single_planetary


class StepLog(mbd.Observer):
    """Records every (s0, s1) the loop hands over."""

    def bind(self, model, system, state):
        self.start, self.steps = state.t, []

    def step(self, s0, s1):
        self.steps.append((s0.t, s1.t, s0.q.copy(), s1.q.copy()))


def test_an_observer_sees_every_accepted_step_of_a_scene():
    built = build_single_planetary()
    v0 = built.v0.copy()
    v0[2] = 30.0                  # spin the sun so that meshes load and unload: steps get rejected and resized
    log = StepLog()
    ctrl = mbd.Adaptive(h0=1e-4, h_max=1e-4, h_min=1e-12)
    res = mbd.simulate(built.model, built.q0, v0, 0.004, stepper=mbd.PRODUCTION.stepper(), controller=ctrl,
                       observers=[log], progress=False)
    assert len(log.steps) == res.steps == res.counters["accepted"] > 10
    assert log.steps[0][0] == log.start == 0.0 and log.steps[-1][1] == res.state.t == 0.004
    for (t0, t1, q0, q1), (u0, _, p0, _) in zip(log.steps, log.steps[1:]):
        assert t1 > t0 and u0 == t1 and np.array_equal(p0, q1)     # each step starts where the last ended
    np.testing.assert_array_equal(log.steps[-1][3], res.state.q)
