"""Linearization and modal analysis against closed-form spring–mass chains and a rotating oscillator."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from mbd.elements import BodySpring, GroundSupport, TorsionalSpring


def chain(n, m, J, k, kt, fixed_free: bool, frame=None, c=0.0):
    """n equal bodies in a line, neighbours joined by BodySprings (k) and TorsionalSprings (kt);
    fixed–free: body 0 also tied to ground by the same k and kt."""
    b = mbd.ModelBuilder(frame=frame)
    bodies = [b.add_body(f"b{i}", m, J, pose=(0.1 * i, 0.0, 0.0)) for i in range(n)]
    idx = np.arange(n)
    b.add(BodySpring("springs", idx[:-1], idx[1:], k=k, c=c))
    b.add(TorsionalSpring("twist", idx[:-1], idx[1:], k=kt))
    if fixed_free:
        b.add(GroundSupport("root", bodies[0], kx=k, cx=c, k_theta=kt))
    return b.build()


def chain_frequencies(n, k, m, fixed_free):
    """Closed form [Hz]: fixed–free ω_j = 2√(k/m)·sin((2j−1)π/(2(2n+1))), j = 1..n;
    free–free ω_j = 2√(k/m)·sin(jπ/(2n)), j = 0..n−1."""
    if fixed_free:
        j = np.arange(1, n + 1)
        w = 2 * np.sqrt(k / m) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))
    else:
        j = np.arange(n)
        w = 2 * np.sqrt(k / m) * np.sin(j * np.pi / (2 * n))
    return w / (2 * np.pi)


@pytest.mark.parametrize("fixed_free", [True, False], ids=["fixed-free", "free-free"])
def test_chain_frequencies_match_closed_form(fixed_free):
    n, m, J, k, kt = 5, 0.3, 2e-4, 4e5, 30.0
    model = chain(n, m, J, k, kt, fixed_free)
    q = np.zeros(3 * n)   # zero-rest-length springs: linearize about q = 0, where they are unloaded
    res = mbd.modal_analysis(model, 0.0, q, np.zeros(3 * n))
    trans = chain_frequencies(n, k, m, fixed_free)          # x and y chains
    tors = chain_frequencies(n, kt, J, fixed_free)          # θ chain
    expect = np.sort(np.concatenate([trans, trans, tors]))
    np.testing.assert_allclose(res.frequencies_hz, expect, rtol=1e-9, atol=1e-6 * expect.max())
    if not fixed_free:
        assert np.count_nonzero(res.frequencies_hz == 0.0) == 3       # two translations and one spin
    # mass-normalised shapes
    M = np.diag(model.mdiag)
    np.testing.assert_allclose(res.shapes.T @ M @ res.shapes, np.eye(3 * n), atol=1e-9)


def test_damped_modes_of_single_oscillator():
    m, k, c = 2.0, 8e4, 12.0
    b = mbd.ModelBuilder()
    a = b.add_body("a", m, 1.0)
    b.add(GroundSupport("s", a, kx=k, cx=c, k_theta=1e3, c_theta=0.0))
    model = b.build()
    res = mbd.modal_analysis(model, 0.0, np.zeros(3), np.zeros(3), damped=True)
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - zeta ** 2)
    np.testing.assert_allclose(res.frequencies_hz[-2:], wd / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(res.damping_ratio[-2:], zeta, rtol=1e-8)
    np.testing.assert_allclose(res.frequencies_hz[0], np.sqrt(1e3) / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(res.damping_ratio[0], 0.0, atol=1e-12)


def test_rotating_frame_splits_isotropic_mode_by_gyroscopic_coupling():
    """An isotropic support seen from R rotating at Ω: the x/y pair at ω_n appears at ω_n ± Ω
    (backward/forward whirl), which needs the 2mΩ terms in C and the −mΩ² in K."""
    m, k, W = 1.5, 6e4, 40.0
    b = mbd.ModelBuilder(frame=mbd.Frame.rotating(W))
    a = b.add_body("a", m, 1.0)
    b.add(GroundSupport("s", a, kx=k, k_theta=1e6))
    model = b.build()
    res = mbd.modal_analysis(model, 0.0, np.zeros(3), np.zeros(3), damped=True)
    wn = np.sqrt(k / m)
    f = np.sort(res.frequencies_hz)
    trans = [x for x in f if abs(x - np.sqrt(1e6) / (2 * np.pi)) > 1e-6]
    np.testing.assert_allclose(trans, np.array([wn - W, wn + W]) / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(res.damping_ratio, 0.0, atol=1e-10)
    # the undamped analysis ignores C: it sees only the softened K, √(ω_n² − Ω²)
    und = mbd.modal_analysis(model, 0.0, np.zeros(3), np.zeros(3))
    np.testing.assert_allclose(und.frequencies_hz[:2], np.sqrt(wn ** 2 - W ** 2) / (2 * np.pi), rtol=1e-10)


def test_linearize_about_a_stretched_state_uses_the_tangent_stiffness():
    """About a deflected, rotated state the offset-marker spring's tangent stiffness differs from the
    nominal one; linearize returns exactly the element Jacobians (compared with finite differences)."""
    b = mbd.ModelBuilder()
    g = b.add_body("g", 1.0, 1.0, fixed=True)
    a = b.add_body("a", 0.5, 1e-3)
    b.add(BodySpring("s", g, a, k=1e4, marker_b=(0.05, 0.0)))
    model = b.build()
    q = np.array([0.01, -0.02, 0.7])
    M, C, K = mbd.linearize(model, 0.0, q, np.zeros(3))
    sysm = mbd.System(model)
    Kfd = np.zeros((3, 3))
    for j in range(3):
        dq = np.zeros(3)
        dq[j] = 1e-7
        Kfd[:, j] = -(sysm.forces(0.0, q + dq, np.zeros(3), {}) - sysm.forces(0.0, q - dq, np.zeros(3), {})) / 2e-7
    np.testing.assert_allclose(K, Kfd, rtol=1e-6, atol=1e-6)
    np.testing.assert_array_equal(C, 0.0)
    assert M.shape == (3, 3)
