"""The operating point's schedule (``operating.schedule``, docs/model.md §10.3) on the DPGT: bad knots named, a
schedule of ones runs the plain machine bit for bit, a start-up begins on the kinematic state at its first speed
with the drive tuned as for the full speed, and the carrier follows a speed ramp."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from components.dpgt import schedules
from components.params import with_overrides
from components.presets import reference_dpgt
from components.units import ParameterError
from scenarios.core.runner import RunConfig, run_case

from tests.support.dpgt_runs import CONTROLLER, FAST_DRIVE, build


def _knots(*rows):
    return [{"time": f"{t} s", "speed": s, "torque": q} for t, s, q in rows]


def test_bad_schedules_are_named():
    p = reference_dpgt(3)
    with pytest.raises(ParameterError, match=r"^operating.schedule\[1\].time: must be later"):
        with_overrides(p, {"operating.schedule": _knots((0.01, 1, 1), (0.01, 1, 1))})
    with pytest.raises(ParameterError, match=r"^operating.schedule\[0\].speed: must be >= 0"):
        with_overrides(p, {"operating.schedule": _knots((0.0, -0.5, 1))})
    with pytest.raises(ParameterError, match=r"^operating.schedule\[0\].time: expected"):
        with_overrides(p, {"operating.schedule": [{"time": "3 m", "speed": 1, "torque": 1}]})
    with pytest.raises(ParameterError, match=r"^operating.schedule: a schedule cannot be combined with rig.carrier_ripple"):
        build(with_overrides(p, {"operating.schedule": _knots((0.0, 0.5, 1), (0.1, 1, 1)),
                                 "rig.carrier_ripple.amplitude_1": "1 rad/s"}), bearings="linear")


def test_schedules_are_the_knots():
    p = with_overrides(reference_dpgt(3), {"operating.schedule": _knots((0.01, 0.2, 0.04), (0.03, 1.0, 1.0))})
    speed, torque = schedules(p.si().operating)
    assert speed.times == torque.times == (0.01, 0.03)
    assert speed.values == (0.2, 1.0) and torque.values == (0.04, 1.0)
    assert schedules(reference_dpgt(3).si().operating) == (None, None)


def _short_run(params, t_end=2e-3):
    scene = build(params)
    res = mbd.simulate(scene.model, scene.q0, scene.v0, t_end, controller=CONTROLLER, engine="compiled")
    return res.state.q, res.state.v


def test_a_schedule_of_ones_runs_the_plain_machine_bit_for_bit():
    """Knots of ones (speed and torque) at any times leave every force as without a schedule: 2 ms of the
    reference machine with its roller bearings end on the same state to the last bit (compiled engine)."""
    p = with_overrides(reference_dpgt(3), FAST_DRIVE)
    ones = with_overrides(p, {"operating.schedule": _knots((0.0, 1, 1), (0.0007, 1, 1), (0.0013, 1, 1))})
    q0, v0 = _short_run(p)
    q1, v1 = _short_run(ones)
    np.testing.assert_array_equal(q1, q0)
    np.testing.assert_array_equal(v1, v0)


def test_a_start_up_begins_on_the_kinematic_state_at_its_first_speed():
    """Every body's initial velocity is the first knot's speed times the steady point's (a ring-fixed train's
    kinematic state scales with the carrier's speed), poses unchanged; the carrier drive's gains are the full
    speed's (tuned on the train's kinetic inertia, J_eff = 2T/ω_c², which does not depend on the speed)."""
    p = reference_dpgt(3)
    s = with_overrides(p, {"operating.schedule": _knots((0.005, 0.25, 0.0625), (0.05, 1.0, 1.0))})
    plain, start = build(p, frame="fixed"), build(s, frame="fixed")    # velocities in I
    np.testing.assert_array_equal(start.q0, plain.q0)
    np.testing.assert_allclose(start.v0, 0.25 * plain.v0, rtol=1e-15, atol=1e-12)
    d0, d1 = plain.model.element("carrier_drive"), start.model.element("carrier_drive")
    np.testing.assert_array_equal(d1.stiffness, d0.stiffness)
    np.testing.assert_array_equal(d1.k_i, d0.k_i)
    assert start.model.element("sun_torque").torque_at(1.0)[0] == pytest.approx(
        plain.model.element("sun_torque").torque_at(1.0)[0], rel=1e-15)
    assert start.model.element("sun_torque").torque_at(0.0025)[0] == pytest.approx(
        0.0625 * plain.model.element("sun_torque").torque_at(0.0025)[0], rel=1e-14)


@pytest.mark.slow
def test_the_carrier_follows_a_speed_ramp():
    """The carrier ramped from 50 % to 100 % of 1000 r/min between 2 and 12 ms (stiff 200 Hz drive, linear bearings):
    the angle it turns through over the ramp is ω_c ∫ f dt = ω_c · 7.5 ms (the trapezoid of the ramp) within 1 %,
    and its fixed-frame speed at the ramp's end is ω_c within 1 % (measured: 0.23 %; the drive then rings by about
    1 % around the ramp's corner for a few ms)."""
    p = with_overrides(reference_dpgt(3), {**FAST_DRIVE, "operating.carrier_speed": "1000 rpm",
                                           "operating.schedule": _knots((0.002, 0.5, 1.0), (0.012, 1.0, 1.0))})
    scene = build(p, bearings="linear")
    m = scene.model
    w = p.si().operating.carrier_speed
    i = m.full_to_free[3 * m.body("carrier").index + 2]
    angle, speed = [], []
    for t_end in (0.002, 0.012):
        res = mbd.simulate(m, scene.q0, scene.v0, t_end, controller=CONTROLLER, engine="compiled")
        fs = m.frame.at(t_end)
        angle.append(res.state.q[i] + fs.phi)
        speed.append(res.state.v[i] + fs.omega)
    assert angle[1] - angle[0] == pytest.approx(w * 0.0075, rel=1e-2)
    assert speed[1] == pytest.approx(w, rel=1e-2)


def test_a_static_solution_of_a_schedule_is_refused_before_it_solves(tmp_path):
    """A start-up has no steady state: the static mode refuses the schedule by name, in a study before any run."""
    p = with_overrides(reference_dpgt(3, "forward"), {"operating.schedule": _knots((0.0, 0.5, 1), (0.1, 1, 1))})
    with pytest.raises(ParameterError, match=r"^operating.schedule: a static solution is of a steady operating point"):
        run_case(p, RunConfig(mode="static", progress=False), tmp_path / "run")
    assert not (tmp_path / "run" / "summary.json").exists()
