"""Frame invariance (docs/model.md §15.5): the same scene integrated in I and in a rotating R gives the same
physical motion; frame conversions are consistent."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

import mbd
from mbd.elements import GroundSupport, SpeedDrive
from mbd.hht import NewtonCache
from mbd.model import FrameState

from tests.support.scenes import spinning_scene
from tests.support.strategies import accelerating_profile, frame_states, full_states


def initial_fixed(model):
    """Physical initial state in I (free bodies): positions near nominal, body b spinning fast."""
    P = model.pose0[~model.fixed].copy()
    P[:, 0] += [0.002, -0.001]
    V = np.array([[0.1, -0.2, 5.0], [0.0, 0.3, 120.0]])
    return P, V


def integrate(model, t_end, h):
    """HHT from the physical initial state; returns (Q, V) in I at 4 instants (free bodies)."""
    fs0 = model.frame.at(0.0)
    P, V = initial_fixed(model)
    q0, v0 = mbd.to_reference(P, V, fs0)
    system = mbd.System(model)
    stepper = mbd.HHT(alpha=-0.05, newton_tol=1e-6)
    s = stepper.initial_state(system, 0.0, q0.ravel(), v0.ravel())
    cache = NewtonCache()
    n = int(round(t_end / h))
    out = []
    for i in range(n + 1):
        if i % (n // 4) == 0:
            out.append(mbd.to_fixed(s.q.reshape(-1, 3), s.v.reshape(-1, 3), model.frame.at(s.t)))
        if i < n:
            s, info = stepper.step(system, s, h, cache)
            assert info.converged
    return out


def frame_difference(frame, gravity, fixed_body, h, t_end=0.02):
    """Largest I/R difference of positions [m] and angles [rad] along the trajectory."""
    ref = integrate(spinning_scene(mbd.Frame.inertial(), gravity, fixed_body=fixed_body), t_end, h)
    rot = integrate(spinning_scene(frame, gravity, fixed_body=fixed_body), t_end, h)
    dpos = max(np.abs(QR[:, :2] - QI[:, :2]).max() for (QI, _), (QR, _) in zip(ref, rot))
    dang = max(np.abs(QR[:, 2] - QI[:, 2]).max() for (QI, _), (QR, _) in zip(ref, rot))
    dvel = max(np.abs(VR - VI).max() for (_, VI), (_, VR) in zip(ref, rot))
    return np.array([dpos, dang, dvel]), ref


CASES = [("rotating", mbd.Frame.rotating(80.0), (0.0, 0.0), False),
         ("reverse-gravity", mbd.Frame.rotating(-150.0), (0.0, -9.81), False),
         ("rotating-gravity-housing", mbd.Frame.rotating(120.0), (0.0, -9.81), True),
         ("accelerating-gravity-housing", mbd.Frame(profile=accelerating_profile(40.0, 3000.0)), (0.0, -9.81), True)]


@pytest.mark.parametrize("frame, gravity, fixed_body", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_same_physical_trajectory_in_I_and_R(frame, gravity, fixed_body):
    """Both runs integrate the same physics: their difference is small and shrinks like h²
    (a wrong frame term would leave an O(1) difference that no step size removes)."""
    d1, ref = frame_difference(frame, gravity, fixed_body, 1e-4)
    d2, _ = frame_difference(frame, gravity, fixed_body, 5e-5)
    ratio = d1 / d2
    assert np.all((ratio > 3.5) & (ratio < 4.5)), (d1, d2)        # pure O(h²): no h-independent part
    # and small: R-frame positions orbit at ~0.15 m and ~20 m/s, body b spins up to ~1.5 rad
    assert d2[0] < 1e-5 and d2[1] < 1e-4 and d2[2] < 3e-2, d2
    spin = np.abs(ref[-1][0][1, 2] - ref[0][0][1, 2])              # body b spins (held by the mount)
    assert spin > (0.01 if fixed_body else 1.0)
    assert np.abs(ref[-1][0][:, :2] - ref[0][0][:, :2]).max() > 1e-3  # and move


def test_speed_drive_frame_invariant():
    """A speed drive holds a body at ω_ref in I whatever frame the model is written in."""
    res = {}
    for name, frame in (("I", mbd.Frame.inertial()), ("R", mbd.Frame.rotating(50.0))):
        b = mbd.ModelBuilder(frame=frame)
        a = b.add_body("rotor", 2.0, 0.01)
        b.add(SpeedDrive("motor", a, omega_ref=50.0, k=400.0, c=4.0, k_i=2000.0))
        b.add(GroundSupport("bearing", a, kx=1e5))
        m = b.build()
        q0, v0 = mbd.to_reference(np.zeros((1, 3)), np.array([[0.0, 0.0, 45.0]]), m.frame.at(0.0))
        r = mbd.simulate(m, q0.ravel(), v0.ravel(), 0.5, controller=mbd.FixedStep(1e-3), progress=False)
        Q, V = mbd.to_fixed(r.state.q.reshape(-1, 3), r.state.v.reshape(-1, 3), m.frame.at(r.state.t))
        res[name] = (Q, V, r.state.z["motor"])
    np.testing.assert_allclose(res["R"][0], res["I"][0], atol=1e-9)
    np.testing.assert_allclose(res["R"][1], res["I"][1], atol=1e-7)
    np.testing.assert_allclose(res["R"][2], res["I"][2], atol=1e-12)
    assert res["I"][1][0, 2] == pytest.approx(50.0, abs=0.05)     # the PI drive removed the error


# ------------------------------------------------------------------------------ conversions
@given(fs=frame_states(), state=full_states(3))
def test_to_fixed_and_to_reference_are_inverse(fs, state):
    q, v = (x.reshape(-1, 3) for x in state)
    Q, V = mbd.to_fixed(q, v, fs)
    q2, v2 = mbd.to_reference(Q, V, fs)
    np.testing.assert_allclose(q2, q, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-9)


@given(W0=st.floats(-300, 300), dW=st.floats(-1e4, 1e4), t=st.floats(0.0, 0.05))
def test_to_fixed_velocity_and_acceleration_are_time_derivatives(W0, dW, t):
    """Along a smooth R-trajectory, to_fixed's v and a equal the time derivatives of its positions."""
    profile = accelerating_profile(W0, dW)
    fsx = lambda tt: FrameState(*profile(tt))
    qR = lambda tt: np.array([[0.1 + 0.02 * np.sin(30 * tt), -0.05 * tt ** 2, 3 * tt + np.cos(7 * tt)]])
    vR = lambda tt: np.array([[0.6 * np.cos(30 * tt), -0.1 * tt, 3 - 7 * np.sin(7 * tt)]])
    aR = lambda tt: np.array([[-18 * np.sin(30 * tt), -0.1, -49 * np.cos(7 * tt)]])
    d = 1e-6
    Qp, Vp = mbd.to_fixed(qR(t + d), vR(t + d), fsx(t + d))
    Qm, Vm = mbd.to_fixed(qR(t - d), vR(t - d), fsx(t - d))
    Q, V, A = mbd.to_fixed(qR(t), vR(t), fsx(t), aR(t))
    np.testing.assert_allclose(V, (Qp - Qm) / (2 * d), rtol=1e-5, atol=1e-6 * (1 + abs(W0) + abs(dW) * 0.05))
    np.testing.assert_allclose(A, (Vp - Vm) / (2 * d), rtol=1e-5, atol=1e-5 * (1 + W0 ** 2 + abs(dW)))


def test_fixed_body_motion_is_rest_in_I():
    b = mbd.ModelBuilder(frame=mbd.Frame(profile=accelerating_profile(20.0, 100.0)))
    b.add_body("h", 1.0, 1.0, pose=(0.3, -0.1, 0.7), fixed=True)
    b.add_body("a", 1.0, 1.0)
    m = b.build()
    for t in (0.0, 0.013, 0.2):
        qf, vf = m.fixed_body_motion(t)
        Q, V = mbd.to_fixed(qf.reshape(-1, 3)[:1], vf.reshape(-1, 3)[:1], m.frame.at(t))
        np.testing.assert_allclose(Q[0], [0.3, -0.1, 0.7], atol=1e-14)
        np.testing.assert_allclose(V[0], 0.0, atol=1e-13)


def test_model_full_keeps_q_and_v_apart():
    """Regression: without fixed bodies Model.full once returned one array for both q and v."""
    b = mbd.ModelBuilder()
    b.add_body("a", 1.0, 1.0)
    m = b.build()
    qf, vf = m.full(0.0, np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]))
    assert qf is not vf
    np.testing.assert_array_equal(qf, [1, 2, 3])
    np.testing.assert_array_equal(vf, [4, 5, 6])
