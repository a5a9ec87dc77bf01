"""Tilt coordinates (docs/model.md §2.4): slope pairs with their rotating-frame and gyroscopic terms, scalar tilts.

Truths: the whirl frequencies of a spinning disk on an isotropic tilt spring (closed form of the rigid-rotor
equations), their shift by −Ω seen from a frame turning at Ω (frame invariance), the conserved Jacobi integral of
an undamped system integrated by HHT with α = 0 (the trapezoidal rule keeps quadratic invariants), finite
differences of the forces, and the planar model's own evaluation (a model without tilt coordinates, and the same
model with a decoupled tilted body appended, give the same numbers bit for bit)."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla

import mbd
from mbd.elements import CoordinateSpring, SlopeGyroscopic
from mbd.elements.springs import BodySpring, GroundSupport
from mbd.hht import NewtonCache

M_DISK, J_P, J_D = 3.0, 0.024, 0.015       # a steel disk: r ≈ 0.126 m, b ≈ 0.04 m (J_d = m r²/4 + m b²/12)
K_TILT = 4.0e4                               # [N m/rad] tilt spring
K_XY = 2.0e6                                 # [N/m] centre spring


def _disk(omega_frame: float, with_springs=True):
    b = mbd.ModelBuilder(mbd.Frame.rotating(omega_frame) if omega_frame else mbd.Frame.inertial())
    disk = b.add_body("disk", M_DISK, J_P)
    sx, sy = b.add_slopes(disk, J_D)
    if with_springs:
        b.add(CoordinateSpring("tilt_spring", [sx, sy], K_TILT))
        b.add(CoordinateSpring("centre_spring", [3 * disk.index, 3 * disk.index + 1], K_XY))
    b.add(SlopeGyroscopic("gyro", 3 * disk.index + 2, [[sx, sy]], J_P))
    return b.build(), (sx, sy)


def _whirl_closed_form(spin):
    """Inertial-frame whirl rates λ (s ∝ e^{iλt}) of J_d s̈ − i J_p ω ṡ + k s = 0: −J_d λ² + J_p ω λ + k = 0."""
    H = J_P * spin
    root = np.sqrt(H * H + 4 * J_D * K_TILT)
    return (H + root) / (2 * J_D), (H - root) / (2 * J_D)      # forward (> 0), backward (< 0)


def _slope_rates(model, idx, spin_rel):
    """Signed whirl rates of the slope block from the engine's linearisation (M, C, K) at rest with θ̇ = spin_rel."""
    q = np.zeros(model.ndof)
    v = np.zeros(model.ndof)
    v[model.full_to_free[2]] = spin_rel
    M, C, K = mbd.linearize(model, 0.0, q, v)
    i = model.full_to_free[list(idx)]
    M, C, K = M[np.ix_(i, i)], C[np.ix_(i, i)], K[np.ix_(i, i)]
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    lam, V = sla.eig(A)
    rates = []
    for k in np.flatnonzero(lam.imag > 0):       # s = s_x + i s_y ∝ e^{iλt}: λ = Im(lam) · sign of the rotation
        sx, sy = V[0, k], V[1, k]
        # x(t) = Re(V e^{i|λ|t}): s_y = −i s_x is s = e^{+i|λ|t} (forward whirl), s_y = +i s_x backward
        rates.append(-lam[k].imag * np.sign((sy / sx).imag))
    return np.sort(rates)


@pytest.mark.parametrize("spin", [0.0, 300.0, 1500.0, -900.0])
def test_spinning_disk_whirls_at_the_closed_form_forward_and_backward_rates(spin):
    model, idx = _disk(0.0)
    fwd, bwd = _whirl_closed_form(spin)
    if spin == 0.0:     # a still disk: one double rate √(k/J_d), its eigenvectors any pair (no sense of whirl)
        M, C, K = mbd.linearize(model, 0.0, np.zeros(model.ndof), np.zeros(model.ndof))
        i = model.full_to_free[list(idx)]
        w2 = sla.eigvals(K[np.ix_(i, i)], M[np.ix_(i, i)]).real
        np.testing.assert_allclose(np.sqrt(w2), [fwd, fwd], rtol=1e-12)
        return
    np.testing.assert_allclose(_slope_rates(model, idx, spin), sorted([fwd, bwd]), rtol=1e-12)
    if spin > 0:     # gyroscopic stiffening splits them: forward above, backward below the static √(k/J_d)
        assert fwd > np.sqrt(K_TILT / J_D) > -bwd


@pytest.mark.parametrize("omega_frame", [120.0, -450.0])
def test_whirl_seen_from_a_rotating_frame_is_the_inertial_whirl_shifted_by_the_frame_rate(omega_frame):
    """s_R = s_I e^{−iΩt}: every whirl rate shifts by −Ω, for the same absolute spin ω = Ω + θ̇."""
    spin = 1100.0
    model, idx = _disk(omega_frame)
    expected = np.sort(np.array(_whirl_closed_form(spin)) - omega_frame)
    np.testing.assert_allclose(_slope_rates(model, idx, spin - omega_frame), expected, rtol=1e-12)


def _simulate(model, q0, v0, h, n, alpha=0.0):
    system = mbd.System(model)
    stepper = mbd.HHT(alpha=alpha, newton_tol=1e-12, reuse=False)
    s = stepper.initial_state(system, 0.0, q0, v0)
    cache = NewtonCache()
    out = [s]
    for _ in range(n):
        s, info = stepper.step(system, s, h, cache)
        assert info.converged, info.reason
        out.append(s)
    return out


def _jacobi(model, s, omega_frame, idx):
    """Jacobi integral in R (constant Ω): kinetic energy in R + springs − centrifugal potential, with the slope pair's
    own: ½ J_d |ṡ|² + ½ (k − J_d Ω² + Ω J_p ω) |s|² (ω = Ω + θ̇ stays constant: nothing torques θ)."""
    f = model.full_to_free
    x, y, th = (s.q[f[j]] for j in range(3))
    vx, vy, w = (s.v[f[j]] for j in range(3))
    sx, sy = s.q[f[idx[0]]], s.q[f[idx[1]]]
    dsx, dsy = s.v[f[idx[0]]], s.v[f[idx[1]]]
    W = omega_frame
    spin = W + w
    e_body = 0.5 * M_DISK * (vx ** 2 + vy ** 2) + 0.5 * J_P * w ** 2 + 0.5 * (K_XY - M_DISK * W * W) * (x * x + y * y)
    e_slope = 0.5 * J_D * (dsx ** 2 + dsy ** 2) + 0.5 * (K_TILT - J_D * W * W + W * J_P * spin) * (sx * sx + sy * sy)
    return e_body + e_slope


@pytest.mark.parametrize("omega_frame", [0.0, 150.0])
def test_a_spinning_tilted_disk_keeps_its_jacobi_integral_under_hht_alpha_0(omega_frame):
    model, idx = _disk(omega_frame)
    f = model.full_to_free
    q0, v0 = np.zeros(model.ndof), np.zeros(model.ndof)
    q0[f[idx[0]]], q0[f[idx[1]]] = 2e-3, -1e-3           # tilted, whirling, spinning, off centre
    v0[f[idx[0]]], v0[f[idx[1]]] = 0.4, 1.1
    v0[f[2]] = 900.0 - omega_frame
    q0[f[0]], v0[f[1]] = 1e-5, 0.01
    states = _simulate(model, q0, v0, 2e-5, 400)
    E = np.array([_jacobi(model, s, omega_frame, idx) for s in states])
    spin = 0.5 * J_P * v0[f[2]] ** 2             # the spin's own energy stays (θ̇ constant): judge the rest
    sl = np.array([np.hypot(s.q[f[idx[0]]], s.q[f[idx[1]]]) for s in states])
    assert sl.max() > 1.5e-3 and np.ptp(sl) > 1e-4           # it does whirl and nutate
    np.testing.assert_allclose(E - spin, E[0] - spin, rtol=1e-9)
    # HHT's numerical damping (α < 0) takes energy out: the integral is the right one, not a constant by accident
    damped = _simulate(model, q0, v0, 2e-5, 400, alpha=-0.3)
    assert _jacobi(model, damped[-1], omega_frame, idx) - spin < (E[0] - spin) * (1 - 1e-5)


def test_a_slope_pair_in_a_rotating_frame_is_a_point_of_mass_j_d_at_s():
    """The frame terms the engine adds to a slope pair equal those of a body of mass J_d at (x, y) = s."""
    W = 230.0
    b = mbd.ModelBuilder(mbd.Frame.rotating(W))
    disk = b.add_body("disk", M_DISK, J_P)
    point = b.add_body("point", J_D, 1.0)
    sx, sy = b.add_slopes(disk, J_D)
    model = b.build()
    system = mbd.System(model)
    rng = np.random.default_rng(3)
    q, v = rng.standard_normal(model.ndof) * 1e-3, rng.standard_normal(model.ndof)
    f = model.full_to_free
    q[f[3]], q[f[4]], v[f[3]], v[f[4]] = q[f[sx]], q[f[sy]], v[f[sx]], v[f[sy]]
    ev = system.evaluate(0.0, q, v, {}, jac=True)
    np.testing.assert_array_equal(ev.F[f[[sx, sy]]], ev.F[f[[3, 4]]])
    _, C, K = system.matrices(ev)
    for mat in (C.toarray(), K.toarray()):
        np.testing.assert_array_equal(mat[np.ix_(f[[sx, sy]], f[[sx, sy]])], mat[np.ix_(f[[3, 4]], f[[3, 4]])])


def _planar(extra_body: bool):
    b = mbd.ModelBuilder(mbd.Frame.rotating(80.0), gravity=(0.0, -9.81))
    ground = b.add_body("ground", 1.0, 1.0, fixed=True)
    a = b.add_body("a", 2.0, 0.01, pose=(0.1, 0.0, 0.0))
    c = b.add_body("c", 1.5, 0.02, pose=(0.0, 0.12, 0.3))
    if extra_body:
        t = b.add_body("tilted", 1.0, 0.01, pose=(0.5, 0.5, 0.0))
    b.add(GroundSupport("sup", a, 3e5, cx=20.0, k_theta=100.0))
    b.add(BodySpring("bush", a, c, 2e5, c=15.0, marker_a=(0.01, 0.02), marker_b=(-0.01, 0.0)))
    if extra_body:
        sx, sy = b.add_slopes(t, 0.005)
        b.add(CoordinateSpring("tilt", [sx, sy], 1e3))
        b.add(SlopeGyroscopic("gyro", 3 * t.index + 2, [[sx, sy]], 0.01))
        b.add(GroundSupport("sup_t", t, 1e4))
        b.add_tilts([t], 1e-4)
    return b.build()


def test_tilt_coordinates_leave_the_planar_bodies_numbers_bit_identical():
    plain, tilted = _planar(False), _planar(True)
    assert not plain.has_tilt and tilted.has_tilt and tilted.n_full == plain.n_full + 3 + 3
    rng = np.random.default_rng(5)
    q, v = rng.standard_normal(plain.ndof) * 1e-3, rng.standard_normal(plain.ndof)
    q2, v2 = rng.standard_normal(tilted.ndof) * 1e-3, rng.standard_normal(tilted.ndof)
    n = plain.ndof                       # the planar bodies' free DOFs come first, in the same order
    q2[:n], v2[:n] = q, v
    e1 = mbd.System(plain).evaluate(0.01, q, v, {}, jac=True)
    sys2 = mbd.System(tilted)
    e2 = sys2.evaluate(0.01, q2, v2, {}, jac=True)
    np.testing.assert_array_equal(e1.F, e2.F[:n])
    _, C1, K1 = mbd.System(plain).matrices(e1)
    _, C2, K2 = sys2.matrices(e2)
    np.testing.assert_array_equal(K1.toarray(), K2.toarray()[:n, :n])
    np.testing.assert_array_equal(C1.toarray(), C2.toarray()[:n, :n])
    assert np.all(plain.angle_dofs == tilted.angle_dofs[:n]) and tilted.angle_dofs[-3:].all()


@pytest.mark.parametrize("omega_frame", [0.0, 300.0])
def test_tilt_jacobians_match_finite_differences(omega_frame):
    model = _planar(True) if omega_frame else _disk(0.0)[0]
    system = mbd.System(model)
    rng = np.random.default_rng(11)
    q, v = rng.standard_normal(model.ndof) * 1e-3, rng.standard_normal(model.ndof) * 10
    ev = system.evaluate(0.02, q, v, {}, jac=True)
    _, C, K = system.matrices(ev)
    hq, hv = 1e-7, 1e-4        # q ~ 1e-3 m, v ~ 10 m/s: steps well above the forces' round-off
    for j in range(model.ndof):
        dq, dv = np.zeros(model.ndof), np.zeros(model.ndof)
        dq[j], dv[j] = hq, hv
        fq = (system.forces(0.02, q + dq, v, {}) - system.forces(0.02, q - dq, v, {})) / (2 * hq)
        fv = (system.forces(0.02, q, v + dv, {}) - system.forces(0.02, q, v - dv, {})) / (2 * hv)
        np.testing.assert_allclose(-K.toarray()[:, j], fq, rtol=1e-6, atol=1e-6 * max(1.0, np.abs(fq).max()))
        np.testing.assert_allclose(-C.toarray()[:, j], fv, rtol=1e-6, atol=1e-6 * max(1.0, np.abs(fv).max()))


def test_compiled_assembly_equals_the_reference_with_tilt_coordinates():
    pytest.importorskip("numba")
    from mbd.compiled.system import CompiledSystem
    model = _planar(True)
    system = mbd.System(model)
    cs = CompiledSystem(system)
    rng = np.random.default_rng(2)
    q, v = rng.standard_normal(model.ndof) * 1e-3, rng.standard_normal(model.ndof) * 10
    a, b = system.evaluate(0.03, q, v, {}, jac=True), cs.evaluate(0.03, q, v, {}, jac=True)
    np.testing.assert_allclose(b.F, a.F, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(b.Jq, a.Jq, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(b.Jv, a.Jv, rtol=1e-13, atol=1e-12)


def test_bad_tilt_input_is_refused_in_one_line():
    b = mbd.ModelBuilder()
    d = b.add_body("d", 1.0, 1.0)
    with pytest.raises(mbd.ModelError, match="diametral inertia must be > 0"):
        b.add_slopes(d, -1.0)
    b.add_slopes(d, 1.0)
    with pytest.raises(mbd.ModelError, match="slope coordinates already"):
        b.add_slopes(d, 1.0)
    with pytest.raises(mbd.ModelError, match="add every body before"):
        b.add_body("late", 1.0, 1.0)
    with pytest.raises(mbd.ModelError, match="tilt inertia must be > 0"):
        b.add_tilts([d], 0.0)
