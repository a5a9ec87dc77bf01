"""A drive's or load's piecewise-linear schedule in time (:class:`mbd.elements.Schedule`, docs/model.md §5.3, §5.4):
its value against numpy's own linear interpolation, its integral against numerical quadrature, a scheduled speed
drive's reference against the schedule's integral, the compiled twins against the numpy kernels, and a schedule of
ones leaving the drives bit for bit as without one."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad

import mbd
from mbd.compiled import generic
from mbd.element import evaluate
from mbd.elements import Ramp, Schedule, SpeedDrive, TorqueSource
from mbd.model import FrameState

from tests.support.mesh import assert_matches_reference, compiled
from tests.support.strategies import dampings, frame_states, full_states, stiffnesses

NB = 4


@st.composite
def schedules(draw, max_knots=6):
    m = draw(st.integers(1, max_knots))
    gaps = draw(st.lists(st.floats(1e-3, 0.3), min_size=m, max_size=m))
    start = draw(st.floats(-0.2, 0.3))
    times = start + np.cumsum(gaps) - gaps[0]
    values = draw(st.lists(st.floats(-2.0, 3.0), min_size=m, max_size=m))
    return Schedule(tuple(times), tuple(values))


@given(s=schedules(), t=st.floats(-0.5, 2.5))
def test_schedule_is_its_piecewise_linear_definition(s, t):
    """f(t) is numpy's linear interpolation through the knots, held constant outside them; at every knot it is the
    knot's value."""
    assert s(t) == pytest.approx(np.interp(t, s.times, s.values), rel=1e-12, abs=1e-12)
    for tk, fk in zip(s.times, s.values):
        assert s(tk) == pytest.approx(fk, rel=1e-12, abs=1e-12)


@given(s=schedules(), t=st.floats(-0.5, 2.5))
def test_schedule_excess_is_the_integral_of_f_minus_one(s, t):
    """excess(t) = ∫_0^t (f − 1) dτ by adaptive quadrature (breakpoints at the knots)."""
    pts = [x for x in s.times if min(0.0, t) < x < max(0.0, t)]
    ref = quad(lambda x: np.interp(x, s.times, s.values) - 1.0, 0.0, t, points=pts or None, limit=200,
               epsabs=1e-13, epsrel=1e-12)[0]
    assert s.excess(t) == pytest.approx(ref, rel=1e-9, abs=1e-12)


def test_a_ramp_by_hand():
    """0.1 → 1 between 0.01 and 0.05 s: f(0.03) = 0.55; ∫_0^0.03 (f − 1) = 0.01·(−0.9) + 0.02·(−0.9 + 0.45/2)
    = −0.0225 s; after the ramp the excess stays at 0.01·(−0.9) + 0.04·(−0.45) = −0.027 s."""
    s = Schedule((0.01, 0.05), (0.1, 1.0))
    assert s(0.03) == pytest.approx(0.55, rel=1e-14)
    assert s.excess(0.03) == pytest.approx(-0.0225, rel=1e-13)
    assert s.excess(0.2) == pytest.approx(-0.027, rel=1e-13)
    assert s(-1.0) == 0.1 and s(9.0) == 1.0


@pytest.mark.parametrize("times, values, words", [
    ((), (), "at least one knot"), ((0.0, 1.0), (1.0,), "as many times"), ((0.0, 0.0), (1.0, 2.0), "increase"),
    ((0.0, np.nan), (1.0, 1.0), "finite"), ((0.0,), (np.inf,), "finite")])
def test_bad_schedules_are_refused(times, values, words):
    with pytest.raises(mbd.ModelError, match=words):
        Schedule(times, values)


def test_a_schedule_with_ripple_or_a_profile_is_refused():
    s = Schedule((0.0, 1.0), (0.5, 1.0))
    with pytest.raises(mbd.ModelError, match="schedule"):
        SpeedDrive("d", 0, omega_ref=10.0, k=1.0, ripple=[(10.0, 1.0, 0.0)], schedule=s)
    with pytest.raises(mbd.ModelError, match="schedule"):
        SpeedDrive("d", 0, omega_ref=lambda t: (np.array([t]), np.array([1.0])), k=1.0, schedule=s)
    with pytest.raises(mbd.ModelError, match="Schedule"):
        TorqueSource("tq", [0], torque=1.0, schedule=lambda t: 1.0)


@given(s=schedules(), w=st.floats(-400.0, 400.0), th0=st.floats(-1.0, 1.0), t=st.floats(0.0, 2.0))
def test_scheduled_speed_drive_reference_is_the_integral_of_its_speed(s, w, th0, t):
    """A body at rest at θ = 0 in an inertial frame sees the whole reference as its error: e = θ0 + ω ∫_0^t f dτ
    (quadrature) and ė = ω f(t); a pure spring-damper gives T = k e + c ė."""
    k, c = 40.0, 0.3
    d = SpeedDrive("d", 0, omega_ref=w, k=k, c=c, theta0=th0, schedule=s)
    pts = [x for x in s.times if 0.0 < x < t]
    integral = quad(lambda x: np.interp(x, s.times, s.values), 0.0, t, points=pts or None, limit=200,
                    epsabs=1e-13, epsrel=1e-12)[0] if t > 0 else 0.0
    e_ref, de_ref = th0 + w * integral, w * np.interp(t, s.times, s.values)
    q = v = np.zeros(3)
    F, out, _, _ = evaluate(d, t, FrameState(0.0, 0.0, 0.0), q, v, None, jac=True)
    assert out["angle_error"][0] == pytest.approx(e_ref, rel=1e-9, abs=1e-9 * (1 + abs(w)))
    assert F[0, 2] == pytest.approx(k * e_ref + c * de_ref, rel=1e-9, abs=1e-8 * (1 + abs(w)))


@given(s=schedules(), t=st.floats(-0.1, 1.5), torque=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=2),
       ramp=st.one_of(st.none(), st.just(Ramp(0.0, 0.2))))
def test_scheduled_torque_is_torque_times_ramp_times_f(s, t, torque, ramp):
    e = TorqueSource("tq", [0, 1], torque=torque, ramp=ramp, schedule=s)
    r = ramp(t) if ramp else 1.0
    np.testing.assert_allclose(e.torque_at(t), np.asarray(torque) * r * np.interp(t, s.times, s.values),
                               rtol=1e-12, atol=1e-9)


# ------------------------------------------------------------------------------------------ compiled twins
@given(s=schedules(), fs=frame_states(), state=full_states(NB), t=st.floats(-0.1, 1.5),
       torque=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=2), ramp=st.one_of(st.none(), st.just(Ramp(0.0, 0.2))))
def test_scheduled_torque_source_matches_reference(s, fs, state, t, torque, ramp):
    q, v = state
    assert_matches_reference(TorqueSource("load", [0, 3], torque=torque, ramp=ramp, schedule=s), t, fs, q, v)


@st.composite
def scheduled_drives(draw):
    integral = draw(st.booleans())
    e = SpeedDrive("drive", [1, 2], omega_ref=draw(st.floats(-400, 400)), k=draw(stiffnesses(1, 1e5)),
                   c=draw(dampings()), k_i=draw(stiffnesses(1, 1e3)) if integral else 0.0,
                   theta0=[draw(st.floats(-1, 1)), draw(st.floats(-1, 1))], schedule=draw(schedules()))
    z = np.array([draw(st.floats(-1e-2, 1e-2)) for _ in range(2)]) if integral else None
    return e, z


@given(drive=scheduled_drives(), fs=frame_states(), state=full_states(NB), t=st.floats(0.0, 2.0))
def test_scheduled_speed_drive_matches_reference(drive, fs, state, t):
    e, z = drive
    q, v = state
    assert_matches_reference(e, t, fs, q, v, z)


@given(drive=scheduled_drives(), fs0=frame_states(), fs1=frame_states(), s0=full_states(NB), s1=full_states(NB),
       t0=st.floats(0.0, 2.0), dt=st.floats(1e-7, 1e-2))
def test_scheduled_speed_drive_update_matches_update_internal(drive, fs0, fs1, s0, s1, t0, dt):
    e, z = drive
    (q0, v0), (q1, v1) = s0, s1
    d = e.dofs
    ref = e.update_internal(z, t0, t0 + dt, fs0, fs1, list(q0[d].T), list(v0[d].T), list(q1[d].T), list(v1[d].T))
    P, G = generic.pack_speed_drive(e)
    zz = np.zeros((e.n, 0)) if z is None else z.reshape(-1, 1).copy()
    z1 = generic.update_speed_drive(zz, t0, t0 + dt, q0[d], v0[d], q1[d], v1[d], P, G, fs0.phi, fs1.phi)
    if z is None:
        assert ref is None and z1.shape == (e.n, 0)
        return
    np.testing.assert_allclose(z1[:, 0], ref, rtol=1e-12, atol=1e-15)


# ------------------------------------------------------------------------------- a schedule of ones changes nothing
@given(fs=frame_states(), state=full_states(NB), t=st.floats(0.0, 2.0), knots=st.integers(1, 4))
def test_a_schedule_of_ones_is_the_plain_drive_and_load_bit_for_bit(fs, state, t, knots):
    """Ones at any knots: the speed drive's reference is θ0 + ω t + ω·0 and ω·1, the torque T·ρ·1 — the plain
    elements' forces exactly, on both engine paths."""
    q, v = state
    ones = Schedule(tuple(0.37 * np.arange(knots)), (1.0,) * knots)
    for plain, scheduled in (
            (SpeedDrive("d", [1, 2], omega_ref=123.4, k=5e3, c=2.0, k_i=70.0, theta0=[0.1, -0.3]),
             SpeedDrive("d", [1, 2], omega_ref=123.4, k=5e3, c=2.0, k_i=70.0, theta0=[0.1, -0.3], schedule=ones)),
            (TorqueSource("tq", [0, 3], torque=[3.0, -7.5], ramp=Ramp(0.0, 0.3)),
             TorqueSource("tq", [0, 3], torque=[3.0, -7.5], ramp=Ramp(0.0, 0.3), schedule=ones))):
        z = plain.init_internal()
        z = None if z is None else z + 1e-3
        np.testing.assert_array_equal(evaluate(scheduled, t, fs, q, v, z, jac=True)[0],
                                      evaluate(plain, t, fs, q, v, z, jac=True)[0])
        np.testing.assert_array_equal(compiled(scheduled, t, fs, q, v, z)[0], compiled(plain, t, fs, q, v, z)[0])
