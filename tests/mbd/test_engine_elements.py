"""Generic element families: exact Jacobians vs finite differences, Newton's third law, frame
consistency of the elements defined in the fixed frame, and the system assembly."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

import mbd
from mbd.element import evaluate
from mbd.elements import BodySpring, GroundSupport, Ramp, SpeedDrive, TorqueSource, TorsionalSpring
from mbd.model import FrameState

from tests.support.strategies import (accelerating_profile, assert_jacobians_match, assert_third_law, dampings,
                                      fd_jacobians_full, frame_states, full_states, stiffnesses)

NB = 4   # bodies in the element tests; instances share bodies, which the full-vector checks handle


def _markers(draw, n):
    return np.array([[draw(st.floats(-0.05, 0.05)), draw(st.floats(-0.05, 0.05))] for _ in range(n)])


# ------------------------------------------------------------------------------ Jacobians (FD)
@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_ground_support_isotropic_jacobians(data, fs, state):
    q, v = state
    e = GroundSupport("sup", [0, 2, 3], kx=data.draw(stiffnesses()), cx=data.draw(dampings()),
                      anchor=(data.draw(st.floats(-0.1, 0.1)), 0.03),
                      k_theta=data.draw(stiffnesses(1, 1e4)), c_theta=data.draw(dampings()), theta0=0.2)
    assert_jacobians_match(e, 0.1, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_ground_support_anisotropic_jacobians_rotating_frame(data, fs, state):
    q, v = state
    e = GroundSupport("sup", [1, 3], kx=data.draw(stiffnesses()), ky=data.draw(stiffnesses()),
                      cx=data.draw(dampings()), cy=data.draw(dampings()), anchor=[[0.01, -0.02], [0.0, 0.05]])
    assert not e.isotropic
    assert_jacobians_match(e, 0.3, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_body_spring_jacobians_and_third_law(data, fs, state):
    q, v = state
    e = BodySpring("bush", [0, 1, 2], [1, 2, 3], k=data.draw(stiffnesses()), c=data.draw(dampings()),
                   marker_a=_markers(data.draw, 3), marker_b=_markers(data.draw, 3))
    assert_jacobians_match(e, 0.0, fs, q, v)
    assert_third_law(e, 0.0, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_torsional_spring_jacobians_and_third_law(data, fs, state):
    q, v = state
    e = TorsionalSpring("tors", [0, 3], [2, 1], k=data.draw(stiffnesses(1, 1e5)), c=data.draw(dampings()),
                        theta0=data.draw(st.floats(-1, 1)))
    assert_jacobians_match(e, 0.0, fs, q, v)
    assert_third_law(e, 0.0, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_speed_drive_jacobians_with_integral_state(data, fs, state):
    q, v = state
    e = SpeedDrive("drive", [1, 2], omega_ref=data.draw(st.floats(-400, 400)), k=data.draw(stiffnesses(1, 1e5)),
                   c=data.draw(dampings()), k_i=data.draw(stiffnesses(1, 1e3)), theta0=0.1)
    z = np.array([data.draw(st.floats(-1e-2, 1e-2)) for _ in range(2)])
    assert_jacobians_match(e, 0.02, fs, q, v, z)


@given(fs=frame_states(), state=full_states(NB))
def test_torque_source_has_zero_jacobian(fs, state):
    q, v = state
    e = TorqueSource("load", [0, 3], torque=[2.0, -1.0], ramp=Ramp(0.0, 1.0))
    F, _, Jq, Jv = evaluate(e, 0.5, fs, q, v, None, jac=True)
    assert np.all(Jq == 0) and np.all(Jv == 0)
    np.testing.assert_allclose(F[:, 2], np.array([2.0, -1.0]) * 0.5)   # smoothstep at mid-ramp = 1/2
    np.testing.assert_array_equal(F[:, :2], 0.0)


def test_fd_check_detects_a_wrong_jacobian():
    """The checker itself must fail on a kernel whose derivative is wrong (guards against a vacuous test)."""
    class Wrong(TorsionalSpring):
        def kernel(self, t, fs, q, v, z):
            f, out = super().kernel(t, fs, q, v, z)
            # value right, derivative lost: plain array instead of a Dual
            f = [x.val if hasattr(x, "val") else x for x in f]
            return f, out

    e = Wrong("wrong", 0, 1, k=100.0)
    q = np.array([0, 0, 0.1, 0, 0, -0.2])
    v = np.zeros(6)
    with pytest.raises(AssertionError, match="dF/dq"):
        assert_jacobians_match(e, 0.0, FrameState(0, 0, 0), q, v)


# ---------------------------------------------------------------------------- element physics
def test_body_spring_force_law_and_outputs():
    """Spring from A's marker to B's marker: F_B = −k d, A gets −F_B, both at B's marker."""
    e = BodySpring("s", 0, 1, k=1000.0, marker_a=(0.1, 0.0), marker_b=(0.0, 0.05))
    q = np.array([0.0, 0.0, np.pi / 2, 0.3, 0.1, 0.0])      # A's marker at (0, 0.1), B's at (0.3, 0.15)
    F, out, _, _ = evaluate(e, 0.0, FrameState(0, 0, 0), q, np.zeros(6), None, jac=False)
    d = np.array([0.3, 0.05])
    np.testing.assert_allclose(F[0, 3:5], -1000.0 * d)
    np.testing.assert_allclose(F[0, 0:2], 1000.0 * d)
    np.testing.assert_allclose(out["deflection"], np.hypot(*d))
    np.testing.assert_allclose([out["fx"][0], out["fy"][0]], -1000.0 * d)
    PB = np.array([0.3, 0.15])
    rA, rB = PB - q[0:2], PB - q[3:5]
    np.testing.assert_allclose(F[0, 2], rA[0] * F[0, 1] - rA[1] * F[0, 0])
    np.testing.assert_allclose(F[0, 5], rB[0] * F[0, 4] - rB[1] * F[0, 3])


@given(state=full_states(NB), c=dampings(1e-2, 1e3, zero=False))
def test_dampers_only_dissipate(state, c):
    """Power of the damping part, Σ (F − F_spring)·v in I, is ≤ 0 for every state (passivity): for
    BodySpring it is −c|ḋ_A|² although the bodies spin and the markers are apart."""
    q, v = state
    fI = FrameState(0.0, 0.0, 0.0)
    pairs = [
        (BodySpring("b", [0, 1], [2, 3], k=1e3, c=c, marker_a=[[0.02, 0.01], [0, 0]], marker_b=[[-0.01, 0.03], [0.0, 0.0]]),
         BodySpring("b0", [0, 1], [2, 3], k=1e3, c=0.0, marker_a=[[0.02, 0.01], [0, 0]], marker_b=[[-0.01, 0.03], [0.0, 0.0]])),
        (GroundSupport("g", [0, 3], kx=1e3, ky=3e3, cx=c, cy=2 * c, c_theta=c, k_theta=5.0),
         GroundSupport("g0", [0, 3], kx=1e3, ky=3e3, k_theta=5.0)),
        (TorsionalSpring("t", 0, 1, k=7.0, c=c), TorsionalSpring("t0", 0, 1, k=7.0)),
        (SpeedDrive("d", 2, omega_ref=0.0, k=3.0, c=c), SpeedDrive("d0", 2, omega_ref=0.0, k=3.0)),
    ]
    for e, e0 in pairs:
        F, _, _, _ = evaluate(e, 0.0, fI, q, v, None, jac=False)
        F0, _, _, _ = evaluate(e0, 0.0, fI, q, v, None, jac=False)
        power = np.sum((F - F0) * v[e.dofs], axis=1)
        assert np.all(power <= 1e-12 * (1 + np.abs(F - F0).max() * np.abs(v).max())), (e.name, power)


@given(fs=frame_states(), state=full_states(2), rigid_w=st.floats(-300, 300), k=stiffnesses(), c=dampings(1, 1e3, zero=False))
def test_body_spring_damping_is_objective(fs, state, rigid_w, k, c):
    """A rigid motion of the pair (any translation, any common spin) and the choice of reference
    frame produce no damping force: the deflection rate is measured in body A's frame."""
    q, _ = state
    e = BodySpring("s", 0, 1, k=k, c=c, marker_a=(0.02, -0.01), marker_b=(-0.03, 0.01))
    # rigid motion in I with spin rigid_w about body A's centre, seen in R
    W = fs.omega
    wI = rigid_w
    vA = np.array([0.3, -0.2])
    rel = q[3:5] - q[0:2]
    vB = vA + (wI - W) * np.array([-rel[1], rel[0]])     # R-velocity of B's centre for a rigid motion
    v = np.array([vA[0], vA[1], wI - W, vB[0], vB[1], wI - W])
    F_rigid, _, _, _ = evaluate(e, 0.0, fs, q, v, None, jac=False)
    F_static, _, _, _ = evaluate(e, 0.0, fs, q, np.zeros(6), None, jac=False)
    # the damping part of the force must vanish; compare with the spring alone
    e0 = BodySpring("s0", 0, 1, k=k, c=0.0, marker_a=(0.02, -0.01), marker_b=(-0.03, 0.01))
    F_spring, _, _, _ = evaluate(e0, 0.0, fs, q, v, None, jac=False)
    np.testing.assert_allclose(F_rigid, F_spring, rtol=1e-9, atol=1e-9 * (1 + np.abs(F_spring).max()))
    assert F_static.shape == F_rigid.shape


@given(state=full_states(3), fs=frame_states(), aniso=st.booleans(), k=stiffnesses(), c=dampings())
def test_fixed_frame_elements_agree_in_R_and_I(state, fs, aniso, k, c):
    """GroundSupport (defined in I), SpeedDrive (angle in I), TorsionalSpring and BodySpring give the
    same physical forces when the same physical state is expressed in R or in I."""
    q, v = state
    extra = dict(ky=2.5 * k, cy=0.5 * c) if aniso else {}
    elems = [GroundSupport("g", [0, 1], kx=k, cx=c, anchor=(0.02, -0.01), k_theta=10.0, c_theta=0.1, theta0=0.3, **extra),
             SpeedDrive("d", 2, omega_ref=30.0, k=50.0, c=0.2, theta0=0.1),
             TorsionalSpring("t", 0, 2, k=20.0, c=0.3),
             BodySpring("b", 0, 1, k=k, c=c, marker_a=(0.01, 0.02), marker_b=(-0.02, 0.0))]
    QI, VI = mbd.to_fixed(q.reshape(-1, 3), v.reshape(-1, 3), fs)
    fI = FrameState(0.0, 0.0, 0.0)
    R = fs.rot()
    for e in elems:
        FR, _, _, _ = evaluate(e, 0.7, fs, q, v, None, jac=False)
        FI, _, _, _ = evaluate(e, 0.7, fI, QI.ravel(), VI.ravel(), None, jac=False)
        for b in range(e.n_local // 3):
            fr = R @ FR[:, 3 * b: 3 * b + 2].T        # rotate R-components into I
            scale = 1e-9 * (1 + np.abs(FI).max())
            np.testing.assert_allclose(fr.T, FI[:, 3 * b: 3 * b + 2], atol=scale, err_msg=e.name)
            np.testing.assert_allclose(FR[:, 3 * b + 2], FI[:, 3 * b + 2], atol=scale, err_msg=e.name)


def test_ground_support_anisotropic_axes_are_fixed_frame_axes():
    """kx acts along I's x axis whatever the frame angle."""
    e = GroundSupport("g", 0, kx=100.0, ky=1.0)
    phi = np.pi / 2                                     # R's x axis is I's y axis
    fs = FrameState(phi, 0.0, 0.0)
    q = np.array([0.01, 0.0, 0.0])                      # displaced along R-x = I-y: the soft direction
    F, _, _, _ = evaluate(e, 0.0, fs, q, np.zeros(3), None, jac=False)
    np.testing.assert_allclose(F[0, :2], [-0.01, 0.0], atol=1e-15)


def test_speed_drive_profile_and_integral_update():
    e = SpeedDrive("d", 0, omega_ref=lambda t: (np.array([2.0 * t]), np.array([2.0])), k=10.0, c=1.0, k_i=5.0)
    z = e.init_internal()
    assert z.shape == (1,)
    fs = FrameState(0.0, 0.0, 0.0)
    cols = lambda a: list(np.asarray(a, float)[None, :].T)
    # trapezoidal integral of the angle error between two states
    z1 = e.update_internal(z, 0.0, 0.1, fs, fs, cols([0, 0, 0.0]), cols([0, 0, 0]), cols([0, 0, 0.1]), cols([0, 0, 1]))
    np.testing.assert_allclose(z1, 0.5 * 0.1 * (0.0 + (0.2 - 0.1)))
    F, out, _, _ = evaluate(e, 0.1, fs, np.array([0, 0, 0.1]), np.array([0, 0, 1.0]), z1, jac=False)
    np.testing.assert_allclose(F[0, 2], 10 * 0.1 + 1.0 * 1.0 + 5.0 * z1[0])
    np.testing.assert_allclose(out["angle_error"], 0.1)
    assert SpeedDrive("p", 0, omega_ref=1.0, k=1.0).init_internal() is None   # no integral term, no state


def test_speed_drive_ripple_reference_by_hand():
    """A body exactly on the constant-speed line θ0 + ω t sees the ripple's whole reference as its error:
    e = Σ (A/Ω) sin(Ω t + φ), ė = Σ A cos(Ω t + φ) (hand values), so T = k e + c ė; the ripple does not
    enter the Jacobians (it is a function of time only). ω_ref is dθ_ref/dt: a central difference agrees."""
    w, t = 200.0, 0.0137
    rip = [(w, 3.0, 0.4), (4 * w, 0.5, -1.1)]
    e = SpeedDrive("d", 0, omega_ref=w, k=40.0, c=0.3, theta0=0.2, ripple=rip)
    fs = FrameState(0.0, 0.0, 0.0)
    q, v = np.array([0.0, 0.0, 0.2 + w * t]), np.array([0.0, 0.0, w])
    F, out, Jq, Jv = evaluate(e, t, fs, q, v, None, jac=True)
    err = 3.0 / w * np.sin(w * t + 0.4) + 0.5 / (4 * w) * np.sin(4 * w * t - 1.1)
    derr = 3.0 * np.cos(w * t + 0.4) + 0.5 * np.cos(4 * w * t - 1.1)
    np.testing.assert_allclose(out["angle_error"], err, rtol=1e-12)
    np.testing.assert_allclose(F[0, 2], 40.0 * err + 0.3 * derr, rtol=1e-12)
    assert Jq[0, 2, 2] == -40.0 and Jv[0, 2, 2] == -0.3
    th = lambda t: e.profile(t)[0][0]
    h = 1e-6
    np.testing.assert_allclose((th(t + h) - th(t - h)) / (2 * h), e.profile(t)[1][0], rtol=1e-8)
    with pytest.raises(mbd.ModelError, match="ripple"):
        SpeedDrive("d", 0, omega_ref=w, k=1.0, ripple=[(0.0, 1.0, 0.0)])
    with pytest.raises(mbd.ModelError, match="ripple"):
        SpeedDrive("d", 0, omega_ref=lambda t: (np.array([t]), np.array([1.0])), k=1.0, ripple=rip)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_speed_drive_with_ripple_jacobians(data, fs, state):
    q, v = state
    e = SpeedDrive("drive", [1, 2], omega_ref=data.draw(st.floats(-400, 400)), k=data.draw(stiffnesses(1, 1e5)),
                   c=data.draw(dampings()), k_i=data.draw(stiffnesses(1, 1e3)), theta0=0.1,
                   ripple=[(150.0, data.draw(st.floats(0, 20)), 0.3), (-600.0, data.draw(st.floats(0, 5)), 1.0)])
    z = np.array([data.draw(st.floats(-1e-2, 1e-2)) for _ in range(2)])
    assert_jacobians_match(e, 0.02, fs, q, v, z)


# ---------------------------------------------------------------------------------- assembly
def _assembly_model(frame):
    b = mbd.ModelBuilder(frame=frame, gravity=(0.3, -9.81))
    g = b.add_body("ground", 1.0, 1.0, pose=(0.05, -0.02, 0.4), fixed=True)
    a = b.add_body("a", 0.7, 2e-3, pose=(0.1, 0.0, 0.0))
    c = b.add_body("c", 1.3, 5e-3, pose=(0.2, 0.05, 0.0))
    d = b.add_body("d", 0.2, 1e-4, pose=(0.1, 0.1, 0.0))
    b.add(GroundSupport("sup", [a, d], kx=2e4, cx=3.0, ky=[1e4, 5e3], cy=1.0, k_theta=50.0, c_theta=0.1))
    b.add(BodySpring("bush", [g, a, c], [a, c, d], k=[1e5, 3e4, 2e4], c=[2.0, 1.0, 0.5],
                     marker_a=[[0.01, 0.0], [0.0, 0.02], [-0.01, 0.01]], marker_b=[[0.0, -0.01], [0.02, 0.0], [0.0, 0.0]]))
    b.add(TorsionalSpring("tors", [a, g], [c, d], k=[30.0, 10.0], c=0.05))
    b.add(SpeedDrive("drive", c, omega_ref=20.0, k=100.0, c=0.5))
    b.add(TorqueSource("load", d, torque=0.3))
    return b.build()


@pytest.mark.parametrize("frame", [mbd.Frame.inertial(), mbd.Frame.rotating(37.0),
                                   mbd.Frame(profile=accelerating_profile(25.0, 400.0))],
                         ids=["inertial", "rotating", "accelerating"])
def test_newton_matrix_equals_finite_differences_of_forces(frame):
    """newton_matrix(ev, c_M, c_C, c_K) = c_M M − c_C ∂F/∂v − c_K ∂F/∂q, frame terms (Ω̇ ≠ 0) included,
    with a fixed body whose coupling entries must be dropped from the pattern."""
    model = _assembly_model(frame)
    sys_ = mbd.System(model)
    rng = np.random.default_rng(3)
    n = model.ndof
    q = 0.05 * rng.standard_normal(n)
    v = 0.5 * rng.standard_normal(n)
    t = 0.137
    z = sys_.init_internal()
    ev = sys_.evaluate(t, q, v, z, jac=True)
    F0 = ev.F
    Kfd = np.zeros((n, n))
    Cfd = np.zeros((n, n))
    for j in range(n):
        for x, out in ((q, Kfd), (v, Cfd)):
            hstep = 1e-6 * max(1.0, abs(x[j]))
            xp, xm = x.copy(), x.copy()
            xp[j] += hstep
            xm[j] -= hstep
            fp = sys_.forces(t, xp, v, z) if out is Kfd else sys_.forces(t, q, xp, z)
            fm = sys_.forces(t, xm, v, z) if out is Kfd else sys_.forces(t, q, xm, z)
            out[:, j] = -(fp - fm) / (2 * hstep)       # K = −∂F/∂q, C = −∂F/∂v
    cM, cC, cK = 1.3, 2e-3, 4e-6
    A = sys_.newton_matrix(ev, cM, cC, cK).toarray()
    ref = cM * np.diag(model.mdiag) + cC * Cfd + cK * Kfd
    np.testing.assert_allclose(A, ref, rtol=0, atol=1e-7 * np.abs(ref).max())
    M, C, K = (x.toarray() for x in sys_.matrices(ev))
    np.testing.assert_allclose(K, Kfd, atol=1e-6 * np.abs(Kfd).max())
    np.testing.assert_allclose(C, Cfd, atol=1e-6 * np.abs(Cfd).max() + 1e-9)
    np.testing.assert_array_equal(M, np.diag(model.mdiag))
    # forces with and without Jacobians agree exactly
    np.testing.assert_array_equal(F0, sys_.forces(t, q, v, z))
    if not frame.is_inertial:
        assert np.abs(C - C.T).max() > 1.0, "gyroscopic (skew) 2mΩ terms expected in C"


def test_system_forces_include_frame_terms_exactly():
    """A lone body with no elements: F = m(Ω²x + 2Ωẏ + Ω̇y + g_Rx, Ω²y − 2Ωẋ − Ω̇x + g_Ry), T = −JΩ̇."""
    W0, dW, t = 12.0, 30.0, 0.4
    b = mbd.ModelBuilder(frame=mbd.Frame(profile=accelerating_profile(W0, dW)), gravity=(0.0, -9.81))
    b.add_body("a", 2.0, 0.3)
    model = b.build()
    s = mbd.System(model)
    q = np.array([0.1, -0.2, 0.5])
    v = np.array([0.3, 0.4, -1.0])
    F = s.forces(t, q, v, {})
    phi, W = W0 * t + 0.5 * dW * t * t, W0 + dW * t
    gR = -9.81 * np.array([np.sin(phi), np.cos(phi)])   # g_R = −g (sin φ, cos φ), docs/model.md §2.3
    expect = np.array([2.0 * (W * W * 0.1 + 2 * W * 0.4 + dW * -0.2) + 2.0 * gR[0],
                       2.0 * (W * W * -0.2 - 2 * W * 0.3 - dW * 0.1) + 2.0 * gR[1],
                       -0.3 * dW])
    np.testing.assert_allclose(F, expect, rtol=1e-13)


def test_system_holds_no_evaluation_results():
    """An evaluation returns its results; the System's attributes are the same before and after, and a
    later evaluation leaves an earlier one's arrays untouched."""
    model = _assembly_model(mbd.Frame.rotating(37.0))
    s = mbd.System(model)
    z = s.init_internal()
    q = 0.05 * np.random.default_rng(1).standard_normal(model.ndof)
    before = {k: (id(v), v.copy() if isinstance(v, np.ndarray) else None) for k, v in vars(s).items()}
    res = s.evaluate(0.0, q, q, z)
    assert res.Jq is None and res.Jv is None
    ev = s.evaluate(0.0, q, q, z, jac=True)
    kept = (ev.F.copy(), ev.Jq.copy(), ev.Jv.copy())
    assert ev.Jq.shape == ev.Jv.shape == (s.nnz,)
    s.evaluate(0.1, 2 * q, -q, z, jac=True)
    for a, b in zip((ev.F, ev.Jq, ev.Jv), kept):
        np.testing.assert_array_equal(a, b)
    assert set(vars(s)) == set(before)
    for k, v in vars(s).items():
        assert id(v) == before[k][0], k
        if before[k][1] is not None:
            np.testing.assert_array_equal(v, before[k][1])
    with pytest.raises(mbd.ModelError, match="jac=True"):
        s.newton_matrix(res, 1.0, 1.0, 1.0)


def test_fd_helper_matches_known_linear_stiffness():
    """Sanity of the finite-difference helper on a linear spring: ∂F/∂q = −k on the x, y block."""
    e = BodySpring("s", 0, 1, k=123.0)
    q = np.array([0.0, 0.0, 0.0, 0.1, 0.0, 0.0])
    JQ, _ = fd_jacobians_full(e, 0.0, FrameState(0, 0, 0), q, np.zeros(6))
    np.testing.assert_allclose(JQ[3, 3], -123.0, rtol=1e-8)
    np.testing.assert_allclose(JQ[3, 0], 123.0, rtol=1e-8)
