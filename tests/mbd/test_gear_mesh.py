"""Spur gear mesh element (docs/model.md §6, checks §15.2)."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from mbd import ModelBuilder, ModelError, System
from mbd.element import evaluate
from components.geometry import mesh_damping
from components.units import ParameterError
from mbd.elements.gear_mesh import STIFFNESS_SHAPES, GearMesh, StiffnessShape, contact_ratio_to_fraction, mesh_u0
from mbd.model import Frame, FrameState, to_reference

from tests.support.mesh import (ALPHA, FS0, K_MEAN, M_, PAIRS, SHAPES, a0_of, circ, far_from_kinks, full, jac_check,
                                make_mesh, nominal, perturbed_state, rb)
from tests.support.strategies import assert_jacobians_match, assert_third_law

# ---------------------------------------------------------------------------------------------
# 1. Jacobians
# ---------------------------------------------------------------------------------------------
@settings(suppress_health_check=[HealthCheck.filter_too_much])
@given(seed=st.integers(0, 2**32 - 1), pair=st.sampled_from(sorted(PAIRS)),
       shape=st.sampled_from(sorted(SHAPES)), backlash=st.sampled_from([0.0, 1e-5, 4e-5]),
       zeta=st.sampled_from([0.0, 0.07, 0.5]), ramp=st.sampled_from([0.0, 3e-6, 3e-5]))
def test_jacobian_matches_finite_differences(seed, pair, shape, backlash, zeta, ramp):
    rng = np.random.default_rng(seed)
    n = 4
    p1, p2, q, v = perturbed_state(pair, rng, n)
    internal, z1, z2 = PAIRS[pair]
    J1, J2 = 1e-3, 2e-3
    c = float(mesh_damping(zeta, K_MEAN, J1, J2, rb(z1), rb(z2)))
    elem = make_mesh(pair, p1, p2, backlash=backlash, shape=shape, c_mesh=c, damping_ramp=ramp, p0=rng.uniform())
    assume(far_from_kinks(elem, q, v))
    jac_check(elem, q, v)
    # and the suite's shared check on the full coordinate vector (steps small enough for the kinks); the deflection
    # is a difference of base radius × angle terms of many turns, whose round-off times the stiffness is the forces'
    theta = np.abs(q.reshape(-1, 3)[:, 2])
    noise = 16 * np.finfo(float).eps * 2 * K_MEAN * (rb(z1) + rb(z2)) * (1.0 + theta.max())
    assert_jacobians_match(elem, 0.0, FS0, q, v, rel=1e-9, force_noise=noise)


@pytest.mark.parametrize("pair", sorted(PAIRS))
@pytest.mark.parametrize("case", ["drive", "coast", "both", "none", "clipped"])
def test_jacobian_in_each_contact_situation(pair, case):
    """Named contact situations, each checked to be what it claims, then the Jacobian."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(7)
    p1, p2 = nominal(pair, 3, rng)
    e = (p1[:, :2] - p2[:, :2]) if internal else (p2[:, :2] - p1[:, :2])
    e /= np.linalg.norm(e, axis=1)[:, None]
    q1, q2 = p1.copy(), p2.copy()
    v1, v2 = np.zeros_like(p1), np.zeros_like(p2)
    v1[:, 2] = 300.0
    v2[:, 2] = (rb(z1) / rb(z2) if internal else -rb(z1) / rb(z2)) * 300.0
    backlash, c_mesh = 0.0, 2e3
    s = 1e-5   # transmission error [m]
    if case == "drive":
        q1[:, 2] += (-s if internal else s) / rb(z1)
    elif case == "coast":
        q1[:, 2] -= (-s if internal else s) / rb(z1)
    elif case == "both":   # centres pushed together (external) / planet pushed outwards (internal)
        q1[:, 2] += (-s if internal else s) / rb(z1) * 0.3
        q2[:, :2] -= 2e-5 * e
    elif case == "none":   # inside the backlash
        backlash = 4e-5
        q1[:, 2] += (-s if internal else s) / rb(z1)
    elif case == "clipped":  # drive flank compressed but separating fast: kδ + cδ̇ < 0
        q1[:, 2] += (-s if internal else s) / rb(z1)
        v2[:, :2] += 30.0 * e
    elem = make_mesh(pair, q1, q2, shape="rectangular", c_mesh=c_mesh, backlash=backlash)
    elem.u0 = mesh_u0(internal, rb(z1), rb(z2), p1, p2)   # zero error at the *nominal* poses
    q, v = full(q1, q2), full(v1, v2)
    assert far_from_kinks(elem, q, v)
    F, out = jac_check(elem, q, v)
    fd, fc = out["force_drive"], out["force_coast"]
    expect = {"drive": (fd > 0) & (fc == 0), "coast": (fd == 0) & (fc > 0), "both": (fd > 0) & (fc > 0),
              "none": (fd == 0) & (fc == 0), "clipped": (fd == 0) & (out["deflection"] > 0)}[case]
    assert np.all(expect), out
    if case in ("none", "clipped"):
        assert np.all(F == 0.0)


# ---------------------------------------------------------------------------------------------
# 2. Newton's third law
# ---------------------------------------------------------------------------------------------
@given(seed=st.integers(0, 2**32 - 1), pair=st.sampled_from(sorted(PAIRS)),
       shape=st.sampled_from(sorted(SHAPES)), backlash=st.sampled_from([0.0, 2e-5]),
       du=st.sampled_from([2e-5, 2e-4]))
def test_forces_and_moments_balance(seed, pair, shape, backlash, du):
    rng = np.random.default_rng(seed)
    n = 6
    p1, p2, q, v = perturbed_state(pair, rng, n, du=du)
    elem = make_mesh(pair, p1, p2, backlash=backlash, shape=shape, c_mesh=1e3)
    F, out, _, _ = evaluate(elem, 0.0, FS0, q, v, None, False)
    Fmax = np.abs(F).max()
    assume(Fmax > 0)
    ql = q[elem.dofs]
    fx, fy, T = F[:, [0, 3]], F[:, [1, 4]], F[:, [2, 5]]
    x, y = ql[:, [0, 3]], ql[:, [1, 4]]
    tol = 1e-12 * Fmax
    np.testing.assert_allclose(fx.sum(1), 0.0, atol=tol)
    np.testing.assert_allclose(fy.sum(1), 0.0, atol=tol)
    moment = (T + x * fy - y * fx).sum(1)
    np.testing.assert_allclose(moment, 0.0, atol=tol * (1.0 + np.abs(ql[:, [0, 1, 3, 4]]).max()))
    assert_third_law(elem, 0.0, FS0, q, v, rtol=1e-12)
    # the documented outputs: force = F_drive − F_coast, (fx, fy) is the force on gear 2
    np.testing.assert_array_equal(out["force"], out["force_drive"] - out["force_coast"])
    np.testing.assert_allclose(out["fx"], F[:, 3], atol=tol)
    np.testing.assert_allclose(out["fy"], F[:, 4], atol=tol)
    assert np.all(out["force_drive"] >= 0) and np.all(out["force_coast"] >= 0)


# ---------------------------------------------------------------------------------------------
# 3. Small displacements: the lumped-parameter form
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_small_displacements_reduce_to_lumped_form(pair):
    """External δ_f = (u1 − u2)·n_f + f(r_b1θ1 + r_b2θ2) − b/2, n_f = sinα e + f cosα t;
    internal δ_f = (u2 − u1)·n_f + f(r_b2θ2 − r_b1θ1) − b/2, n_f = −sinα e + f cosα t (force on the planet);
    the error must be second order in the displacement."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(3)
    n, b = 8, 1e-5
    p1, p2 = nominal(pair, n, rng, angle_span=3.0)
    elem = make_mesh(pair, p1, p2, backlash=b)
    d = (p1 - p2) if internal else (p2 - p1)
    e = d[:, :2] / np.linalg.norm(d[:, :2], axis=1)[:, None]
    t = np.column_stack([-e[:, 1], e[:, 0]])
    dirs = rng.normal(size=(n, 6))
    errs = []
    for eps in (1e-6, 2e-6):
        u1, u2 = eps * dirs[:, 0:2], eps * dirs[:, 3:5]
        th1, th2 = eps * dirs[:, 2] / rb(z1), eps * dirs[:, 5] / rb(z2)
        q1, q2 = p1.copy(), p2.copy()
        q1[:, :2] += u1
        q2[:, :2] += u2
        q1[:, 2] += th1
        q2[:, 2] += th2
        out = evaluate(elem, 0.0, FS0, full(q1, q2), np.zeros(6 * n), None, False)[1]
        err = []
        for f, key in ((1, "deflection"), (-1, "deflection_coast")):
            if internal:
                nf = -np.sin(ALPHA) * e + f * np.cos(ALPHA) * t
                lumped = np.sum((u2 - u1) * nf, 1) + f * (rb(z2) * th2 - rb(z1) * th1) - b / 2
            else:
                nf = np.sin(ALPHA) * e + f * np.cos(ALPHA) * t
                lumped = np.sum((u1 - u2) * nf, 1) + f * (rb(z1) * th1 + rb(z2) * th2) - b / 2
            err.append(np.abs(out[key] - lumped))
        err = np.max(err, axis=0)
        a0 = a0_of(internal, z1, z2)
        assert np.all(err <= 20 * eps**2 / a0), (err, eps**2 / a0)
        errs.append(err.max())
    # second order: doubling the displacement quadruples the error
    assert 3.0 < errs[1] / errs[0] < 5.0, errs


# ---------------------------------------------------------------------------------------------
# 4. Rigid rolling: zero deflection and zero deflection rate, in any frame
# ---------------------------------------------------------------------------------------------
def rolling_motion(pair, t, w1, Wc, w2=None):
    """Physical (inertial) motion of a rigidly rolling pair: the line of centres turns at Wc about
    gear 2's centre (internal: the ring, at the origin) or gear 1's centre (external, at the origin);
    gear 1 spins at w1; gear 2's speed follows from zero transmission-error rate (unless given for
    the internal mesh, then w1 follows). Returns poses (2, 3) and velocities (2, 3) in I."""
    internal, z1, z2 = PAIRS[pair]
    r1, r2, a0 = rb(z1), rb(z2), a0_of(internal, z1, z2)
    psi0 = 0.4
    psi = psi0 + Wc * t
    if internal:
        # ṡ = r2 (w2 − Wc) − r1 (w1 − Wc) = 0
        w2 = 0.0 if w2 is None else w2
        w1 = Wc + r2 * (w2 - Wc) / r1
        c2, v2 = np.zeros(2), np.zeros(2)
        c1 = a0 * np.array([np.cos(psi), np.sin(psi)])
        v1 = a0 * Wc * np.array([-np.sin(psi), np.cos(psi)])
    else:
        # ṡ = r1 (w1 − Wc) + r2 (w2 − Wc) = 0
        w2 = Wc - r1 * (w1 - Wc) / r2
        c1, v1 = np.zeros(2), np.zeros(2)
        c2 = a0 * np.array([np.cos(psi), np.sin(psi)])
        v2 = a0 * Wc * np.array([-np.sin(psi), np.cos(psi)])
    th1, th2 = 0.3 + w1 * t, -1.1 + w2 * t
    P = np.array([[*c1, th1], [*c2, th2]])
    V = np.array([[*v1, w1], [*v2, w2]])
    return P, V, w1, w2


@pytest.mark.parametrize("pair", sorted(PAIRS))
@pytest.mark.parametrize("Wc", [0.0, 440.0, -440.0])          # carrier speed [rad/s] (4200 r/min)
@pytest.mark.parametrize("frame", ["inertial", "carrier", "other"])
def test_rigid_rolling_has_zero_deflection_and_rate(pair, Wc, frame):
    internal, z1, z2 = PAIRS[pair]
    W_R = {"inertial": 0.0, "carrier": Wc, "other": 0.37 * Wc + 150.0}[frame]
    P0, _, w1, w2 = rolling_motion(pair, 0.0, 720.0, Wc)
    elem = GearMesh("m", [0], [1], internal=internal, rb1=rb(z1), rb2=rb(z2), alpha=ALPHA,
                    a0=a0_of(internal, z1, z2), teeth1=z1, k_mean=K_MEAN, c_mesh=5e3,
                    u0=mesh_u0(internal, rb(z1), rb(z2), P0[0], P0[1]), p0=0.25,
                    stiffness=SHAPES["rectangular"])
    # over two carrier revolutions (the line of centres crosses ±π in I) and ~100 mesh cycles
    ts = np.linspace(0.0, 0.03, 61)
    pos = []
    ftol = K_MEAN * 1e-13
    for t in ts:
        P, V, _, _ = rolling_motion(pair, t, 720.0, Wc)
        fs = FrameState(W_R * t, W_R, 0.0)
        q, v = to_reference(P, V, fs)
        F, out, _, _ = evaluate(elem, t, fs, q.ravel(), v.ravel(), None, False)
        assert abs(out["deflection"][0]) < 1e-12 and abs(out["deflection_coast"][0]) < 1e-12
        assert abs(out["deflection_rate"][0]) < 1e-9          # rolling speeds ~30 m/s
        assert np.all(np.abs(F) < ftol)
        pos.append(out["position"][0])
    # the mesh position advances at z1 (w1 − Wc)/2π, the same in every frame
    expect = pos[0] + z1 * (w1 - Wc) / (2 * np.pi) * ts
    assert np.all(np.abs(circ(np.array(pos) - expect)) < 1e-9)


@pytest.mark.parametrize("Wc", [440.0, -440.0])
def test_rigid_rolling_ring_turning(Wc):
    """Internal mesh with the ring turning as well (w2 ≠ 0)."""
    pair = "planet_ring"
    internal, z1, z2 = PAIRS[pair]
    P0, _, _, _ = rolling_motion(pair, 0.0, 0.0, Wc, w2=-90.0)
    elem = make_mesh(pair, P0[:1], P0[1:], c_mesh=5e3, shape="fourier")
    for t in np.linspace(0.0, 0.02, 21):
        P, V, _, _ = rolling_motion(pair, t, 0.0, Wc, w2=-90.0)
        for W_R in (0.0, Wc, -300.0):
            fs = FrameState(W_R * t, W_R, 0.0)
            q, v = to_reference(P, V, fs)
            F, out, _, _ = evaluate(elem, t, fs, q.ravel(), v.ravel(), None, False)
            assert abs(out["deflection"][0]) < 1e-12 and abs(out["deflection_rate"][0]) < 1e-9
            assert np.all(np.abs(F) < K_MEAN * 1e-13)


def test_rigid_rolling_through_the_engine_with_a_fixed_ring():
    """Carrier frame R at Ω, ring fixed in I (a prescribed body), planet centre at rest in R and
    spinning at its kinematic speed: the assembled mesh forces and deflection rate are zero."""
    internal, z1, z2 = PAIRS["planet_ring"]
    W = 440.0
    a0 = a0_of(internal, z1, z2)
    b = ModelBuilder(frame=Frame.rotating(W))
    ring = b.add_body("ring", 6.07, 0.05, pose=(0.0, 0.0, 0.2), fixed=True)
    planet = b.add_body("planet", 0.557, 3e-4, pose=(a0, 0.0, 0.0))
    b.add(GearMesh("mesh", planet, ring, internal=True, rb1=rb(z1), rb2=rb(z2), alpha=ALPHA, a0=a0,
                   teeth1=z1, k_mean=K_MEAN, c_mesh=5e3,
                   u0=mesh_u0(True, rb(z1), rb(z2), (a0, 0.0, 0.0), (0.0, 0.0, 0.2)),
                   stiffness=SHAPES["rectangular"]))
    model = b.build()
    system = System(model)
    w_rel = rb(z2) * (0.0 - W) / rb(z1)       # planet speed relative to R: r1 w1_R = r2 w2_R
    for t in np.linspace(0.0, 0.02, 11):
        q = np.array([a0, 0.0, w_rel * t])
        v = np.array([0.0, 0.0, w_rel])
        out = system.outputs(t, q, v, {})["mesh"]
        assert abs(out["deflection"][0]) < 1e-12 and abs(out["deflection_rate"][0]) < 1e-9
        assert abs(out["force"][0]) < K_MEAN * 1e-13
        F = system.evaluate(t, q, v, {}, jac=True).F
        # only the centrifugal force m Ω² x remains
        np.testing.assert_allclose(F, [0.557 * W**2 * a0, 0.0, 0.0], atol=1e-9 * 0.557 * W**2 * a0)


@pytest.mark.parametrize("W", [0.0, 300.0])
def test_loaded_rolling_pair_settles_to_the_static_mesh_force(W):
    """Dynamic check through HHT: sun driven by torque T, planet held at its kinematic speed by a speed
    drive, centres on isotropic supports; after the ramp the mesh carries T/r_b1 along n_+, the sun
    centre sits at −F n_+/k_support, and rolling is rigid (δ̇ → 0) — in I and in a rotating frame."""
    from mbd import FixedStep, simulate
    from mbd.elements import GroundSupport, Ramp, SpeedDrive, TorqueSource
    from mbd.model import to_fixed
    internal, z1, z2 = PAIRS["sun_planet"]
    r1, r2, a0 = rb(z1), rb(z2), a0_of(internal, z1, z2)
    J1, J2, k_sup, T, w1 = 0.5 * 1.088 * (M_ * z1 / 2) ** 2, 0.5 * 0.557 * (M_ * z2 / 2) ** 2, 1e8, 200.0, 300.0
    w2 = -r1 * w1 / r2
    b = ModelBuilder(frame=Frame.rotating(W))
    sun = b.add_body("sun", 1.088, J1)
    planet = b.add_body("planet", 0.557, J2, pose=(a0, 0.0, 0.0))
    b.add(GroundSupport("support", [sun, planet], kx=k_sup, cx=2e3, anchor=[(0.0, 0.0), (a0, 0.0)]))
    b.add(TorqueSource("motor", sun, T, ramp=Ramp(0.0, 0.005)))
    b.add(SpeedDrive("load", planet, w2, k=2e4, c=20.0))
    b.add(GearMesh("mesh", sun, planet, internal=False, rb1=r1, rb2=r2, alpha=ALPHA, a0=a0, teeth1=z1,
                   k_mean=K_MEAN, c_mesh=float(mesh_damping(0.07, K_MEAN, J1, J2, r1, r2)),
                   u0=mesh_u0(False, r1, r2, (0, 0, 0), (a0, 0, 0))))
    model = b.build()
    q0, v0 = to_reference(np.array([[0, 0, 0], [a0, 0, 0.0]]), np.array([[0, 0, w1], [0, 0, w2]]), model.frame.at(0.0))
    s = simulate(model, q0.ravel(), v0.ravel(), 0.02, controller=FixedStep(2e-5), progress=False).state
    out = System(model).outputs(s.t, s.q, s.v, s.z)["mesh"]
    F = T / r1
    np.testing.assert_allclose(out["force"], F, rtol=1e-4)
    # rigid rolling: δ̇ is what is left of the rolling and orbiting speeds in this frame (in R the
    # residual is the integrator's O(h²) error of the rotating motion: it drops 4x when h halves)
    v_ref = r1 * abs(w1 - W) + a0 * abs(W)
    assert abs(out["deflection_rate"][0]) < 1e-5 * v_ref
    qI, vI = to_fixed(s.q.reshape(-1, 3), s.v.reshape(-1, 3), model.frame.at(s.t))
    c, si = np.cos(W * s.t), np.sin(W * s.t)
    f_I = np.array([c * out["fx"][0] - si * out["fy"][0], si * out["fx"][0] + c * out["fy"][0]])   # on the planet
    np.testing.assert_allclose(np.hypot(*f_I), F, rtol=1e-3)
    np.testing.assert_allclose(qI[0, :2], -f_I / k_sup, rtol=1e-3)        # the sun's support carries it
    np.testing.assert_allclose(qI[1, :2] - [a0, 0.0], f_I / k_sup, rtol=1e-3)
    np.testing.assert_allclose(vI[:, 2], [w1, w2], rtol=1e-6)


@given(seed=st.integers(0, 2**32 - 1), pair=st.sampled_from(sorted(PAIRS)))
def test_frame_invariance_and_deflection_rate(seed, pair):
    """An arbitrary loaded motion seen from I and from rotating frames: same deflections, forces
    rotated into R; δ̇ equals the time derivative of δ along the motion."""
    rng = np.random.default_rng(seed)
    internal, z1, z2 = PAIRS[pair]
    P0, _, _, _ = rolling_motion(pair, 0.0, 500.0, 300.0)
    P0[0, 2] += (-1 if internal else 1) * 8e-6 / rb(z1)      # preload the drive flank
    coef = rng.normal(0.0, 1.0, (3, 2, 3)) * np.array([1e-3, 1e-3, 1e-2])   # polynomial wobble

    def motion(t):
        P, V, _, _ = rolling_motion(pair, t, 500.0, 300.0)
        P = P + (P0 - rolling_motion(pair, 0.0, 500.0, 300.0)[0])
        P = P + coef[0] * t + coef[1] * t**2 / 2 + coef[2] * t**3 / 6
        V = V + coef[0] + coef[1] * t + coef[2] * t**2 / 2
        return P, V

    elem = make_mesh(pair, *rolling_motion(pair, 0.0, 500.0, 300.0)[0][:, None, :], c_mesh=3e3,
                     shape="rectangular", backlash=4e-6)
    t = float(rng.uniform(0.0, 0.01))
    ref = None
    for W_R in (0.0, 300.0, -700.0):
        fs = FrameState(W_R * t + 0.1, W_R, 0.0)
        P, V = motion(t)
        q, v = to_reference(P, V, fs)
        F, out, _, _ = evaluate(elem, t, fs, q.ravel(), v.ravel(), None, False)
        c, s = np.cos(fs.phi), np.sin(fs.phi)
        F_I = np.array([c * F[0, 3] - s * F[0, 4], s * F[0, 3] + c * F[0, 4]])   # on gear 2, in I
        if ref is None:
            ref = (out, F_I, F[0, [2, 5]])
            # δ̇ = dδ/dt along the motion (central difference in time, in this frame)
            h = 1e-7
            dd = []
            for sgn in (1, -1):
                fsh = FrameState(W_R * (t + sgn * h) + 0.1, W_R, 0.0)
                qh, vh = to_reference(*motion(t + sgn * h), fsh)
                dd.append(evaluate(elem, t, fsh, qh.ravel(), vh.ravel(), None, False)[1]["deflection"][0])
            np.testing.assert_allclose(out["deflection_rate"][0], (dd[0] - dd[1]) / (2 * h),
                                       rtol=1e-5, atol=1e-9)
        else:
            # δ is a difference of O(0.1 m) terms (r_b θ): its round-off is ~1e-15 m, whatever the frame
            datol, fatol = 1e-14, K_MEAN * 1e-14
            for key, atol in (("deflection", datol), ("deflection_coast", datol), ("deflection_rate", 1e-12),
                              ("force", fatol)):
                np.testing.assert_allclose(out[key], ref[0][key], rtol=1e-9, atol=atol)
            assert abs(circ(out["position"] - ref[0]["position"]))[0] < 1e-9
            np.testing.assert_allclose(F_I, ref[1], rtol=1e-9, atol=fatol)
            np.testing.assert_allclose(F[0, [2, 5]], ref[2], rtol=1e-9, atol=fatol * rb(82))


# ---------------------------------------------------------------------------------------------
# 5. Torque-held mesh: T/r_b along the line of action
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pair", sorted(PAIRS))
@pytest.mark.parametrize("loaded", [0, 1])          # which gear carries the torque T (the other is held)
@pytest.mark.parametrize("T", [250.0, -250.0])
@pytest.mark.parametrize("backlash", [0.0, 3e-5])
def test_torque_held_mesh(pair, loaded, T, backlash):
    """Gear A under torque T, gear B held, centres at nominal: the mesh reaction on A balances T with
    normal force T/r_bA along the line of action, i.e. tangential part T/r_wA = T cosα/r_bA (r_wA the
    operating pitch radius) and separating part (T/r_wA)·tanα; gear B gets the opposite force and the
    torque T·r_bB/r_bA."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(11)
    p1, p2 = nominal(pair, 1, rng, angle_span=3.0)
    elem = make_mesh(pair, p1, p2, backlash=backlash, shape="rectangular", c_mesh=2e3)
    q0 = full(p1, p2)
    jA = 3 * loaded + 2
    rA = rb(z1) if loaded == 0 else rb(z2)
    rB = rb(z2) if loaded == 0 else rb(z1)

    def residual(dth):
        q = q0.copy()
        q[elem.dofs[0, jA]] += dth
        F = evaluate(elem, 0.0, FS0, q, np.zeros(6), None, False)[0]
        return F[0, jA] + T, F, q

    span = 1e-3 / rA            # far beyond the deflection (µm) and the backlash, within ±p_b/2
    dth = brentq(lambda x: residual(x)[0], -span, span, xtol=1e-18, rtol=4 * np.finfo(float).eps)
    _, F, q = residual(dth)
    out = evaluate(elem, 0.0, FS0, q, np.zeros(6), None, False)[1]
    d = (p1 - p2)[0] if internal else (p2 - p1)[0]
    e = d[:2] / np.linalg.norm(d[:2])
    t = np.array([-e[1], e[0]])
    FA = F[0, 3 * loaded: 3 * loaded + 2]
    FB = F[0, 3 * (1 - loaded): 3 * (1 - loaded) + 2]
    np.testing.assert_allclose(F[0, jA], -T, rtol=1e-9)
    np.testing.assert_allclose(abs(out["force"][0]), abs(T) / rA, rtol=1e-9)
    np.testing.assert_allclose(np.hypot(*FA), abs(T) / rA, rtol=1e-9)
    Ft = abs(T) * np.cos(ALPHA) / rA
    np.testing.assert_allclose(abs(FA @ t), Ft, rtol=1e-9)
    np.testing.assert_allclose(abs(FA @ e), Ft * np.tan(ALPHA), rtol=1e-9)
    np.testing.assert_allclose(FB, -FA, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(abs(F[0, 3 * (1 - loaded) + 2]), abs(T) * rB / rA, rtol=1e-9)
    # only one flank loaded: which one follows the torque sign
    assert min(out["force_drive"][0], out["force_coast"][0]) == 0.0
    # the radial part pushes external gears apart and the planet towards the ring's centre
    F1, F2 = F[0, :2], F[0, 3:5]
    if internal:
        assert F1 @ e < 0 and F2 @ e > 0
    else:
        assert F2 @ e > 0 and F1 @ e < 0
    # B's reaction torque: external gears are turned the other way, a planet turns its ring the same way
    tau_B = F[0, 3 * (1 - loaded) + 2]
    assert np.sign(tau_B) == (np.sign(T) if internal else -np.sign(T))
    # the equilibrium deflection: δ = |T|/(r_bA k(p)) on the loaded flank
    dl = out["deflection"][0] if out["force_drive"][0] > 0 else out["deflection_coast"][0]
    np.testing.assert_allclose(dl, abs(T) / (rA * out["stiffness"][0]), rtol=1e-7)


# ---------------------------------------------------------------------------------------------
# 6. Stiffness shape
# ---------------------------------------------------------------------------------------------
def _dual_factor(shape, p):
    from mbd import ad
    x = ad.Dual(p.copy(), np.ones((p.size, 1)))
    r = shape.factor(x)
    return ad.value(r), r.der[:, 0]


@given(eps=st.floats(1.05, 1.95), ratio=st.floats(1.05, 2.5), sfrac=st.floats(0.05, 0.9))
def test_rectangular_stiffness_shape(eps, ratio, sfrac):
    smoothing = sfrac * min(eps - 1, 2 - eps)
    shape = StiffnessShape.rectangular(eps, ratio=ratio, smoothing=smoothing)
    N = 20000
    p = np.arange(N) / N
    k = shape.factor(p)
    ks, kd = shape.single, shape.double
    np.testing.assert_allclose(kd / ks, ratio, rtol=1e-12)
    np.testing.assert_allclose(k.mean(), 1.0, rtol=1e-9)                   # cycle mean = k_mean
    np.testing.assert_allclose([k.min(), k.max()], [ks, kd], rtol=1e-12)    # levels reached
    frac = np.mean(k > 0.5 * (ks + kd))
    assert abs(frac - contact_ratio_to_fraction(eps)) <= 2.0 / N            # double contact over ε−1
    # the edges sit at p = 0 (a new pair enters) and p = ε − 1
    np.testing.assert_allclose(shape.factor(np.array([0.0, eps - 1.0])), 0.5 * (ks + kd), rtol=1e-12)
    assert shape.factor(np.array([0.5 * (eps - 1)]))[0] == pytest.approx(kd, rel=1e-12)
    # periodic
    for m in (-3.0, 1.0, 17.0):
        np.testing.assert_allclose(shape.factor(p + m), k, rtol=1e-9)
    # C¹ across the whole line, wrap points included: the derivative moves by at most max|k''|·dp
    pp = np.linspace(-1.0, 2.0, 60001)
    val, der = _dual_factor(shape, pp)
    dp = pp[1] - pp[0]
    k2max = (kd - ks) * (10.0 / np.sqrt(3.0)) / smoothing**2     # quintic smoothstep's max curvature
    assert np.max(np.abs(np.diff(der))) <= 1.01 * k2max * dp
    assert np.max(np.abs(np.diff(val))) <= 1.01 * (kd - ks) * 1.875 / smoothing * dp
    # the exact derivative agrees with finite differences
    h = 1e-7
    fd = (shape.factor(pp + h) - shape.factor(pp - h)) / (2 * h)
    np.testing.assert_allclose(der, fd, atol=1e-5 * (kd - ks) / smoothing)


def test_fourier_and_constant_shapes():
    a, b = [0.1, -0.04, 0.02], [0.05]
    shape = StiffnessShape.fourier(a=a, b=b)
    p = np.arange(4096) / 4096
    expect = 1 + sum(aj * np.cos(2 * np.pi * j * p) for j, aj in enumerate(a, 1)) + 0.05 * np.sin(2 * np.pi * p)
    np.testing.assert_allclose(shape.factor(p), expect, rtol=1e-14)
    np.testing.assert_allclose(shape.factor(p).mean(), 1.0, rtol=1e-12)
    np.testing.assert_allclose(shape.factor(p + 5.0), expect, rtol=1e-12)
    assert StiffnessShape.constant().factor(p) == 1.0
    with pytest.raises(ModelError, match="> 0"):
        StiffnessShape.fourier(a=[1.2])


def test_mesh_stiffness_follows_mesh_position():
    """k in the kernel is k_mean·factor(p) with p = z1 (θ1 − φ_e)/2π + p0, from the states."""
    pair = "sun_planet"
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(5)
    p1, p2 = nominal(pair, 5, rng)
    p0 = rng.uniform(size=5)
    elem = make_mesh(pair, p1, p2, shape="rectangular", p0=p0)
    out = evaluate(elem, 0.0, FS0, full(p1, p2), np.zeros(30), None, False)[1]
    phi = np.arctan2(p2[:, 1] - p1[:, 1], p2[:, 0] - p1[:, 0])
    pos = np.mod(z1 * (p1[:, 2] - phi) / (2 * np.pi) + p0, 1.0)
    np.testing.assert_allclose(out["position"], pos, atol=1e-12)
    np.testing.assert_allclose(out["stiffness"], K_MEAN * SHAPES["rectangular"].factor(pos), rtol=1e-9)


# ---------------------------------------------------------------------------------------------
# Damping, validation
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_mesh_damping_gives_the_requested_damping_ratio(pair):
    """Two gears on fixed centres: the torsional mode of the loaded mesh, from the element's own
    K = −∂F/∂θ and C = −∂F/∂θ̇, has ω² = k/m_eq and damping ratio ζ."""
    internal, z1, z2 = PAIRS[pair]
    J1, J2, zeta = 4e-4, 2.5e-2, 0.07
    c = float(mesh_damping(zeta, K_MEAN, J1, J2, rb(z1), rb(z2)))
    rng = np.random.default_rng(2)
    p1, p2 = nominal(pair, 1, rng, angle_span=3.0)
    elem = make_mesh(pair, p1, p2, c_mesh=c)
    q = full(p1, p2)
    q[2] += (-1 if internal else 1) * 1e-5 / rb(z1)      # drive flank loaded
    _, out, Jq, Jv = evaluate(elem, 0.0, FS0, q, np.zeros(6), None, True)
    assert out["force_drive"][0] > 0
    th = [2, 5]
    K, C = -Jq[0][np.ix_(th, th)], -Jv[0][np.ix_(th, th)]
    Minv = np.diag([1 / J1, 1 / J2])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ K, -Minv @ C]])
    lam = np.linalg.eigvals(A)
    lam = lam[np.abs(lam) > 1.0]                          # drop the rigid rotation
    m_eq = J1 * J2 / (J1 * rb(z2) ** 2 + J2 * rb(z1) ** 2)
    np.testing.assert_allclose(np.abs(lam), np.sqrt(K_MEAN / m_eq), rtol=1e-9)
    np.testing.assert_allclose(-lam.real / np.abs(lam), zeta, rtol=1e-9)


def test_unloaded_nominal_state_with_zero_backlash():
    """b = 0: both flanks touch at the nominal state (δ = 0) and carry no force; any tiny rolling
    offset loads exactly one flank, linearly (a two-sided spring k on the transmission error)."""
    for pair in PAIRS:
        internal, z1, z2 = PAIRS[pair]
        rng = np.random.default_rng(4)
        p1, p2 = nominal(pair, 3, rng)
        elem = make_mesh(pair, p1, p2, backlash=0.0)
        F, out, _, _ = evaluate(elem, 0.0, FS0, full(p1, p2), np.zeros(18), None, False)
        assert np.all(np.abs(out["deflection"]) < 1e-12) and np.all(np.abs(out["deflection_coast"]) < 1e-12)
        assert np.all(np.abs(F) < K_MEAN * 1e-13)
        for s in (1e-7, -1e-7):
            q1 = p1.copy()
            q1[:, 2] += (-s if internal else s) / rb(z1)
            out = evaluate(elem, 0.0, FS0, full(q1, p2), np.zeros(18), None, False)[1]
            np.testing.assert_allclose(out["force"], K_MEAN * s, rtol=1e-6)


@pytest.mark.parametrize("pair", sorted(PAIRS))
@pytest.mark.parametrize("turns", [-2, 0, 1, 3])
def test_u0_and_phi_ref_with_unwrapped_nominal_angles(pair, turns):
    """A builder may compute u0 from an unwrapped line-of-centres angle φ0 + 2πk (and pass it as
    phi_ref, or not): the nominal state still has zero transmission error and no force."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(8)
    p1, p2 = nominal(pair, 4, rng)
    d = (p1 - p2) if internal else (p2 - p1)
    phi = np.arctan2(d[:, 1], d[:, 0]) + 2 * np.pi * turns
    r1, r2 = rb(z1), rb(z2)
    u0 = (r2 * (p2[:, 2] - phi) - r1 * (p1[:, 2] - phi)) if internal else (r1 * (p1[:, 2] - phi) + r2 * (p2[:, 2] - phi))
    for phi_ref in (phi, 0.0):
        elem = GearMesh("m", np.arange(4), 4 + np.arange(4), internal=internal, rb1=r1, rb2=r2, alpha=ALPHA,
                        a0=a0_of(internal, z1, z2), teeth1=z1, k_mean=K_MEAN, u0=u0, phi_ref=phi_ref,
                        backlash=1e-6)
        F, out, _, _ = evaluate(elem, 0.0, FS0, full(p1, p2), np.zeros(24), None, False)
        np.testing.assert_allclose(out["deflection"], -0.5e-6, atol=1e-13)
        np.testing.assert_allclose(out["deflection_coast"], -0.5e-6, atol=1e-13)
        assert np.all(F == 0.0)


def test_parameter_validation_names_the_parameter():
    internal, z1, z2 = PAIRS["sun_planet"]
    kw = dict(internal=False, rb1=rb(z1), rb2=rb(z2), alpha=ALPHA, a0=a0_of(False, z1, z2), teeth1=z1,
              k_mean=K_MEAN)
    GearMesh("ok", 0, 1, **kw)
    for key, bad, msg in (("backlash", -1e-6, "backlash"), ("k_mean", 0.0, "k_mean"), ("c_mesh", -1.0, "c_mesh"),
                          ("a0", 1.01 * kw["a0"], "a0"), ("rb2", 1.1 * rb(z2), "rb2"), ("teeth1", 31.5, "teeth1"),
                          ("alpha", 1.6, "alpha"), ("u0", np.nan, "u0")):
        if key == "rb2":   # keep a0 consistent so that the tooth-count check is the one that fires
            bad_kw = dict(kw, rb2=bad, a0=(rb(z1) + bad) / np.cos(ALPHA))
        else:
            bad_kw = dict(kw, **{key: bad})
        with pytest.raises(ModelError, match=msg):
            GearMesh("bad", 0, 1, **bad_kw)
    with pytest.raises(ModelError, match="smoothing"):
        StiffnessShape.rectangular(1.96, ratio=1.5, smoothing=0.05)
    with pytest.raises(ModelError, match="contact_ratio"):
        StiffnessShape.rectangular(2.3, ratio=1.5, smoothing=0.05)
    assert set(STIFFNESS_SHAPES) == {"constant", "rectangular", "fourier"}
    assert all(issubclass(cls, StiffnessShape) for cls in STIFFNESS_SHAPES.values())
    with pytest.raises(ParameterError, match="J2"):
        mesh_damping(0.07, K_MEAN, 1e-3, 0.0, 0.03, 0.03)


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_the_damping_grows_from_zero_at_first_touch(pair):
    """A flank closing at δ̇ = 0.05 m/s: with the damping ramp δ_c the force is continuous at contact — at
    δ = 1e-12 m it is k·δ plus S(1e-7)·c·δ̇, nothing of the c·δ̇ = 100 N a Kelvin–Voigt contact (δ_c = 0) jumps
    to — half-way up the ramp the damping share is S(½) = ½, and from δ_c on the law is the undamped-start one,
    k δ + c δ̇, to round-off."""
    rng = np.random.default_rng(3)
    p1, p2 = nominal(pair, 1, rng)
    internal, z1, z2 = PAIRS[pair]
    ramp, c = 2e-6, 2e3
    e = (p1[:, :2] - p2[:, :2]) if internal else (p2[:, :2] - p1[:, :2])
    forces = {}
    for width in (0.0, ramp):
        elem = make_mesh(pair, p1, p2, shape="constant", c_mesh=c, damping_ramp=width)
        for delta in (1e-12, 0.5 * ramp, 1.5 * ramp):
            q1, v1 = p1.copy(), np.zeros_like(p1)
            sgn = -1.0 if internal else 1.0          # turning gear 1 forward compresses the drive flank
            q1[:, 2] += sgn * delta / rb(z1)
            v1[:, 2] = sgn * 0.05 / rb(z1)
            _, out, _, _ = evaluate(elem, 0.0, FS0, full(q1, p2), full(v1, np.zeros_like(p2)), None, False)
            assert out["deflection"][0] == pytest.approx(delta, rel=1e-6, abs=1e-15)
            assert out["deflection_rate"][0] == pytest.approx(0.05, rel=1e-9)
            forces[width, delta] = out["force_drive"][0]
    assert forces[0.0, 1e-12] == pytest.approx(c * 0.05 + K_MEAN * 1e-12, rel=1e-6)     # the jump
    assert forces[ramp, 1e-12] < 2 * K_MEAN * 1e-12                                  # none with the ramp
    half = 0.5 * ramp * K_MEAN
    assert forces[ramp, 0.5 * ramp] == pytest.approx(half + 0.5 * c * 0.05, rel=1e-6)
    assert forces[ramp, 1.5 * ramp] == pytest.approx(forces[0.0, 1.5 * ramp], rel=1e-12)


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_jacobian_inside_the_damping_ramp(pair):
    """Both flanks' dampers inside the ramp (drive flank at a third, closing at 0.2 m/s; small angles, so that a
    coordinate step of 1e-10 m resolves the ramp's curvature): the Jacobians against central differences."""
    rng = np.random.default_rng(5)
    internal, z1, z2 = PAIRS[pair]
    p1, p2 = nominal(pair, 2, rng, angle_span=0.5)
    ramp = 3e-6
    elem = make_mesh(pair, p1, p2, shape="rectangular", c_mesh=3e3, damping_ramp=ramp, p0=0.3)
    sgn = -1.0 if internal else 1.0
    q1, v1 = p1.copy(), np.zeros_like(p1)
    q1[:, 2] += sgn * ramp / 3.0 / rb(z1)
    v1[:, 2] = sgn * 0.2 / rb(z1)
    v1[:, :2] = rng.normal(0.0, 0.01, (2, 2))
    q, v = full(q1, p2), full(v1, np.zeros_like(p2))
    out = evaluate(elem, 0.0, FS0, q, v, None, False)[1]
    assert np.all((out["deflection"] > 0) & (out["deflection"] < ramp))
    jac_check(elem, q, v, hq=1e-10)
