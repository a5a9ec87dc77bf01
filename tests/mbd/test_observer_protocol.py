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


# --------------------------------------------------------------------------- the protocols simulate checks
import pytest  # noqa: E402

from mbd.elements import GroundSupport  # noqa: E402


def _oscillator():
    """One body on a ground spring (ω = 10 rad/s), displaced 1 mm: (model, q0, v0)."""
    mb = mbd.ModelBuilder()
    mb.add_body("m", 1.0, 0.01)
    mb.add(GroundSupport("spring", [0], kx=100.0))
    return mb.build(), np.array([1e-3, 0.0, 0.0]), np.zeros(3)


class DuckObserver:
    """Every method of mbd.Observer, without inheriting from it."""

    def __init__(self):
        self.bound, self.steps = 0, []

    def bind(self, model, system, state):
        self.bound += 1

    def step(self, s0, s1):
        self.steps.append((s0.t, s1.t))

    def on_block(self, block):
        for s0, s1, _, _ in block.steps:
            self.step(s0, s1)

    def state_dict(self):
        return {}

    def load_state_dict(self, d):
        pass


class NoBlock(DuckObserver):
    on_block = None          # an attribute that is not a method does not count


class OnlyInitial:
    def initial(self):
        return 1e-3


class StepsOnly(mbd.Observer):
    def on_block(self, block):
        pass


def _fails_at_once(match, extra=(), **kw):
    """simulate refuses before anything is bound or stepped, with one line naming the argument (observers[0] is a
    good observer that would see a bind or a step)."""
    model, q0, v0 = _oscillator()
    witness = DuckObserver()
    kw = {"controller": mbd.FixedStep(1e-3), "observers": [witness, *extra], **kw}
    with pytest.raises(mbd.ModelError, match=match) as err:
        mbd.simulate(model, q0, v0, 0.01, progress=False, engine="numpy", **kw)
    assert "\n" not in str(err.value) and witness.bound == 0 and witness.steps == []
    return str(err.value)


def test_an_observer_missing_a_method_fails_at_once_naming_it():
    msg = _fails_at_once(r"observers\[1\] \(NoBlock\) is missing on_block\(block\) of the Observer protocol",
                         extra=[NoBlock()])
    assert "step" not in msg.split("missing")[1].split(" of ")[0]          # only what is missing is named
    _fails_at_once(r"observers\[1\] \(object\) is missing bind\(model, system, state\), step\(s0, s1\), on_block\(block\), "
                   r"state_dict\(\), load_state_dict\(d\)", extra=[object()])


def test_a_controller_or_recorder_missing_a_method_fails_at_once_naming_it():
    _fails_at_once(r"controller \(OnlyInitial\) is missing decide\(h, converged, error\) of the Controller protocol",
                   controller=OnlyInitial())

    class NoBlocks:
        def __getattr__(self, name):          # every recorder method but record_block
            if name == "record_block":
                raise AttributeError(name)
            return lambda *a, **k: None

    _fails_at_once(r"recorder \(NoBlocks\) is missing record_block\(block\) of the Recorder protocol",
                   recorder=NoBlocks())


def test_observers_must_be_a_list():
    _fails_at_once(r"observers must be a list of observers, got DuckObserver", observers=DuckObserver())


def test_an_observer_of_blocks_only_is_refused_by_the_numpy_path_before_a_step():
    """mbd.Observer's step raises (it must be defined); an observer that defines on_block alone can run only on
    the compiled path, and the numpy path says so before its first step."""
    _fails_at_once(r"observers\[1\] \(StepsOnly\) does not define step\(s0, s1\)", extra=[StepsOnly()])


def test_the_engine_s_own_objects_satisfy_the_protocols_and_a_duck_typed_observer_runs():
    from components.outputs import WindowStatistics
    from scenarios.numerics.common import StateSampler

    assert isinstance(mbd.FixedStep(1e-3), mbd.Controller) and isinstance(mbd.Adaptive(h0=1e-3), mbd.Controller)
    assert issubclass(mbd.Recorder, mbd.protocols.Recorder)
    for cls in (mbd.TimeMean, WindowStatistics, StateSampler, StepLog):
        assert issubclass(cls, mbd.Observer), cls
    assert not isinstance(NoBlock(), mbd.Observer) and not isinstance(OnlyInitial(), mbd.Controller)
    model, q0, v0 = _oscillator()
    for engine in ("compiled", "numpy"):        # blocks (on_block) and single steps (step)
        duck = DuckObserver()
        res = mbd.simulate(model, q0, v0, 0.01, controller=mbd.FixedStep(1e-3), observers=[duck], progress=False,
                           engine=engine)
        assert res.engine == engine and duck.bound == 1 and len(duck.steps) == res.steps == 10
        assert all(a[1] == b[0] for a, b in zip(duck.steps, duck.steps[1:])) and duck.steps[-1][1] == res.state.t
