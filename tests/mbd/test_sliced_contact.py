"""The sliced roller–raceway law (mbd.elements.sliced, docs/model.md §8.8): with a straight roller and no slope it is
the planar contact (RaceContact) to round-off; its Jacobian against finite differences; a tilted roller on a linear
(exponent 1) foundation against the closed-form force and moment of a linear Winkler wedge; a partly lifted roller
against the integral of the 10/9 law; ISO/TS 16281's lamina constant against two contacts in series; the slice
stations; mirror symmetry."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from mbd.element import marker
from mbd.elements.contact import RaceContact, TanhTraction
from mbd.elements.sliced import SlicedContact, iso_16281_stiffness, slice_stations
from mbd.errors import ModelError

from tests.support.contact import DR, FS, K_HZ, LR, M_ROLLER, N, R_IN, R_OUT, SETTINGS, race_scene, race_states

P = 10.0 / 9.0


def _law(kind, n_s, drop=0.0, exponent=P, K=K_HZ, row_offset=0.0, n=1):
    z, _ = slice_stations(LR, n_s)
    R = R_IN if kind == "inner" else R_OUT
    return SlicedContact(kind=[kind] * n, R_race=R, D=DR, K=K, exponent=exponent, z=z, drop=drop,
                         row_offset=row_offset)


def test_slice_stations_are_the_midpoints_of_equal_slices():
    z, w = slice_stations(9e-3, 3)
    np.testing.assert_allclose(z, [-3e-3, 0.0, 3e-3], atol=1e-18)
    assert w == pytest.approx(3e-3, rel=1e-15)
    z, w = slice_stations(9e-3, 4)
    np.testing.assert_allclose(z, [-3.375e-3, -1.125e-3, 1.125e-3, 3.375e-3], atol=1e-18)
    with pytest.raises(ModelError, match="slices"):
        slice_stations(9e-3, 0)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("n_s", [1, 7, 30])
@SETTINGS
@given(data=st.data())
def test_a_straight_aligned_roller_is_the_planar_contact(kind, n_s, data):
    """Random roller states of the planar contact's tests (no damping, no traction: the normal law): the slices' sum
    is RaceContact's load and force to round-off, whatever the slice count."""
    pose, vel, psi, angles, deltas, *_ = data.draw(race_states(kind))
    zeros = [0.0] * N
    qf, vf, mk, R = race_scene(kind, pose, (0.0, 0.0, 0.0), psi, angles, deltas, zeros, zeros, zeros)
    planar = RaceContact("race", np.arange(1, N + 1), 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_HZ,
                         exponent=P, zeta=0.0, m_roller=M_ROLLER, traction=TanhTraction(mu_max=0.0, v0=0.3))
    ql = qf[planar.dofs]
    _, out = planar.kernel(0.0, FS, list(ql.T), list(np.zeros_like(ql).T), None)
    p = ql[:, 0:2]
    (cx, cy), _ = marker(list(ql[:, 3:].T), planar.race_marker)      # the race centre exactly as the element has it
    c = np.stack([cx, cy], axis=1)
    res = _law(kind, n_s, n=N).evaluate(p, np.zeros((N, 2)), c, np.zeros((N, 2)))
    np.testing.assert_allclose(res.load.sum(axis=1), out["load"], rtol=1e-13, atol=0.0)
    np.testing.assert_allclose(res.force[:, 0], out["fx"], rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(res.force[:, 1], out["fy"], rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(res.delta, np.repeat(np.asarray(deltas)[:, None], n_s, 1), rtol=0, atol=1e-15)
    np.testing.assert_allclose(res.race_force, -res.force, rtol=0, atol=0)
    # no tilt, no profile: every slice the same, no moment on either body's slope
    np.testing.assert_allclose(res.roller_moment, 0.0, atol=1e-9 * LR * np.abs(res.force).max() + 1e-300)


def _state(kind, rng, n):
    """Rollers near contact with a tilt, the race sloped and displaced: loaded, partly lifted and open rollers."""
    psi = rng.uniform(-np.pi, np.pi, n)
    e = np.stack([np.cos(psi), np.sin(psi)], 1)
    t = np.stack([-e[:, 1], e[:, 0]], 1)
    R = R_IN if kind == "inner" else R_OUT
    kap = 1.0 if kind == "inner" else -1.0
    delta0 = rng.uniform(-1.5e-5, 1.5e-5, n)
    c = rng.uniform(-1e-5, 1e-5, (n, 2))
    p = c + (R + kap * (DR / 2 - delta0))[:, None] * e + rng.uniform(-3e-6, 3e-6, n)[:, None] * t
    sig_r = rng.uniform(-1e-3, 1e-3, (n, 2))
    sig_c = rng.uniform(-1e-3, 1e-3, (n, 2))
    return p, sig_r, c, sig_c


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_jacobian_against_finite_differences(kind):
    rng = np.random.default_rng(7)
    n, n_s = 40, 21
    z, _ = slice_stations(LR, n_s)
    drop = 2e-6 * (2 * z / LR) ** 2
    law = SlicedContact(kind=kind, R_race=R_IN if kind == "inner" else R_OUT, D=DR, K=K_HZ, exponent=P, z=z,
                        drop=drop, row_offset=rng.uniform(-2e-3, 2e-3, n))
    x = np.concatenate(_state(kind, rng, n), axis=1)                       # (n, 8)
    split = lambda v: (v[:, 0:2], v[:, 2:4], v[:, 4:6], v[:, 6:8])  # noqa: E731
    res = law.evaluate(*split(x), jacobian=True)
    loaded = (res.load > 0).any(axis=1)
    assert loaded.sum() > 10 and (~loaded).sum() > 2 and ((res.load > 0).sum(1) < n_s).sum() > 3
    steps = np.array([2.0 ** -32] * 2 + [2.0 ** -34] * 2 + [2.0 ** -32] * 2 + [2.0 ** -34] * 2)
    J = np.empty((n, 8, 8))
    for j in range(8):
        def g(m):
            y = x.copy()
            y[:, j] += m * steps[j]
            return law.evaluate(*split(y)).generalized
        J[:, :, j] = (8.0 * (g(1) - g(-1)) - (g(2) - g(-2))) / (12.0 * steps[j])
    scale = np.abs(res.jacobian).max(axis=(1, 2), keepdims=True) + 1.0
    # fourth-order differences reach ~1e-8 of the largest entry (a slice within 2h of touch would be off by its
    # share; none is in this draw)
    assert np.abs(J - res.jacobian).max() / scale.max() < 1e-7
    np.testing.assert_allclose(res.jacobian, np.swapaxes(res.jacobian, 1, 2), rtol=0,
                               atol=1e-12 * scale.max())                   # a potential: symmetric


def test_a_tilted_roller_on_a_linear_foundation_is_the_winkler_wedge():
    """Exponent 1, inner raceway, roller pressed δ0 at its centre and tilted τ in its radial plane, fully in contact:
    the slices are a linear Winkler foundation of modulus K/l: F = K δ0 along e, moment Σ z q = −K τ Σz²/n_s with
    Σ z_k² = l² (n_s² − 1)/(12 n_s) (the midpoint sum), centroid −τ l² (1 − 1/n_s²)/(12 δ0)."""
    K, d0, tau = 2.0e8, 8e-6, 1.2e-3                 # τ l/2 = 5.4 µm < δ0: every slice in contact
    psi = 0.7
    e = np.array([np.cos(psi), np.sin(psi)])
    for n_s in (1, 2, 9, 31):
        law = _law("inner", n_s, exponent=1.0, K=K)
        p = (R_IN + DR / 2 - d0) * e
        res = law.evaluate(p[None], tau * e[None], np.zeros((1, 2)), np.zeros((1, 2)))
        F = res.force[0] @ e
        M = res.roller_moment[0] @ e
        assert F == pytest.approx(K * d0, rel=1e-12)
        assert M == pytest.approx(-K * tau * LR ** 2 * (n_s ** 2 - 1) / (12.0 * n_s ** 2), rel=1e-10, abs=1e-15)
        if n_s > 1:
            assert M / F == pytest.approx(-tau * LR ** 2 * (1 - 1 / n_s ** 2) / (12 * d0), rel=1e-10)
        # the race's slope sees the same forces at the same stations (row at ζ_row = 0): −Σ ζ F = −Σ z F
        np.testing.assert_allclose(res.race_moment[0], -res.roller_moment[0], rtol=1e-14, atol=0)
        # an outer raceway pressed the same way (the roller tilted −τ: the same wedge) pushes the roller inwards, and
        # its moment on the roller's slope turns sign with the force
        lo = _law("outer", n_s, exponent=1.0, K=K)
        po = (R_OUT - DR / 2 + d0) * e
        ro = lo.evaluate(po[None], -tau * e[None], np.zeros((1, 2)), np.zeros((1, 2)))
        assert ro.force[0] @ e == pytest.approx(-K * d0, rel=1e-12)
        assert ro.roller_moment[0] @ e == pytest.approx(K * tau * LR ** 2 * (n_s ** 2 - 1) / (12 * n_s ** 2),
                                                         rel=1e-10, abs=1e-15)


def test_a_partly_lifted_roller_follows_the_integral_of_the_10_9_law():
    """A wedge δ(z) = δ0 − τ z that lifts the roller's +z end: the slices converge to the continuous foundation
    (K/l) ∫ ⟨δ0 − τz⟩^(10/9) dz = (K/l)(δ0 + τl/2)^(19/9)/((19/9)τ), and its moment to the closed-form integral."""
    d0, tau = 3e-6, 2e-3                              # lifts beyond z0 = δ0/τ = 1.5 mm
    a = d0 + tau * LR / 2
    F_exact = K_HZ / LR * a ** (19 / 9) / (19 / 9 * tau)
    # ∫ z (δ0 − τz)^p dz over [−l/2, z0], with s = δ0 − τz: z = (δ0 − s)/τ
    M_exact = K_HZ / LR / tau ** 2 * (d0 * a ** (19 / 9) / (19 / 9) - a ** (28 / 9) / (28 / 9))
    n_s = 4001
    res = _law("inner", n_s).evaluate(np.array([[R_IN + DR / 2 - d0, 0.0]]), np.array([[tau, 0.0]]),
                                      np.zeros((1, 2)), np.zeros((1, 2)))
    assert res.force[0, 0] == pytest.approx(F_exact, rel=2e-6)
    assert res.roller_moment[0, 0] == pytest.approx(M_exact, rel=2e-6)
    loaded = res.load[0] > 0
    assert loaded[:n_s // 2].all() and not loaded[-n_s // 3:].any()


def test_iso_16281_constant_is_two_contacts_in_series():
    """ISO/TS 16281's lamina constant c_L = 35948 L^(8/9) N/mm^(10/9) for the two contacts of a roller in series: one
    contact of K = iso_16281_stiffness(l) twice in series (each δ/2, the same load) gives c_L δ^(10/9); it is 3.7 %
    below Palmgren's 8.06e4 l^(8/9)."""
    K = iso_16281_stiffness(LR)
    delta_mm = 0.012
    q_series = K * (0.5 * delta_mm * 1e-3) ** P                 # each contact carries q at half the approach
    assert q_series == pytest.approx(35948.0 * 9.0 ** (8 / 9) * delta_mm ** P, rel=1e-12)
    assert 1.0 - K / (8.06e4 * 9.0 ** (8 / 9) * 1e3 ** P) == pytest.approx(1.0 - 35948.0 * 2 ** P / 8.06e4, rel=1e-12)
    assert 1.0 - 35948.0 * 2 ** P / 8.06e4 == pytest.approx(0.0366, abs=5e-5)


def test_mirror_and_row_offset():
    """z → −z mirrors the slices (a tilt and a race slope of opposite sign); a row offset ζ_row moves the race's
    stations only: the race moment gains ζ_row times the force, the roller's is unchanged."""
    rng = np.random.default_rng(3)
    p, sr, c, sc = _state("inner", rng, 25)
    z, _ = slice_stations(LR, 15)
    drop = 3e-6 * (2 * z / LR) ** 4
    law = _law("inner", 15, drop=drop, n=25)
    a = law.evaluate(p, sr, c, sc)
    b = law.evaluate(p, -sr, c, -sc)
    np.testing.assert_allclose(b.load, a.load[:, ::-1], rtol=1e-12, atol=1e-12 * a.load.max())
    np.testing.assert_allclose(b.roller_moment, -a.roller_moment, rtol=1e-10, atol=1e-9 * LR * a.load.max())
    shift = 1.7e-3
    lo = _law("inner", 15, drop=drop, n=25, row_offset=shift)
    s = lo.evaluate(p, sr, c - shift * sc, sc)                   # the same race axis point at each slice
    np.testing.assert_allclose(s.load, a.load, rtol=1e-12, atol=1e-12 * a.load.max())
    np.testing.assert_allclose(s.race_moment, a.race_moment - shift * a.force, rtol=1e-10,
                               atol=1e-12 * a.load.max() * LR)


def test_a_law_of_scalars_serves_any_number_of_contacts():
    rng = np.random.default_rng(11)
    state = _state("outer", rng, 9)
    one = _law("outer", 11)                       # n = 1 from its parameters
    many = _law("outer", 11, n=9)
    a, b = one.evaluate(*state, jacobian=True), many.evaluate(*state, jacobian=True)
    np.testing.assert_array_equal(a.load, b.load)
    np.testing.assert_array_equal(a.jacobian, b.jacobian)
    assert a.load.shape == (9, 11)
