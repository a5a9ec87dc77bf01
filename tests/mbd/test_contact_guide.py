"""The cage–guide land contact (GuideContact, docs/model.md §8.6, §9.4): the hydrodynamic land's film forces against
the quadrature of the short-bearing (Ocvirk) π-film pressure and its steady load and attitude angle, its friction
against Petroff's film shear; exact Jacobians and balance on random states, the impact law with stored approach
speeds, a centred cage regular, the restoring force and the land friction's direction and size.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from mbd.element import evaluate
from mbd.elements.contact import ExactRestitution, GuideContact, HydrodynamicLand

from tests.support.contact import (C_G, FS, K_G, N, R_LAND, SETTINGS, V_MIN, assert_balanced, assert_jacobians,
                                   expected_impact_force, guide_scene, guide_states, power_of, stored_speeds)


def _pi_film_forces(eps, eps_dot, wbar, eta, R, L, C, n=20001):
    """Short-bearing (Ocvirk) π-film forces on the journal by quadrature of the pressure: with θ from the
    widest gap (h = C(1 + ε cos θ)) in the sense of the surfaces' mean motion, Reynolds' short-bearing
    equation integrated over the width gives ∫p dz = −(L³/12)·12η/h³·(−(ω̄/2)Cε sin θ + C ε̇ cos θ), taken
    over the converging half θ ∈ (0, π). Returns (F_n, F_t) along n (widest gap → narrowest) and t = k × n."""
    th = np.linspace(0.0, np.pi, n)
    h = C * (1.0 + eps * np.cos(th))
    p = -(L ** 3 / 12.0) * 12.0 * eta / h ** 3 * (-(wbar / 2.0) * C * eps * np.sin(th) + C * eps_dot * np.cos(th))
    # force on the journal: −∫ p (cos θ, sin θ) R dθ in (x̂ towards the widest gap, ŷ = k × x̂); n = −x̂, t = −ŷ
    Fx = -np.trapezoid(p * np.cos(th), th) * R
    Fy = -np.trapezoid(p * np.sin(th), th) * R
    return -Fx, -Fy


@pytest.mark.parametrize("eps,eps_dot", [(0.3, 0.0), (0.7, 0.0), (0.5, 40.0), (0.6, -25.0)])
def test_hydrodynamic_land_matches_the_short_bearing_pressure(eps, eps_dot):
    """The land's closed-form film forces equal the quadrature of the short-bearing π-film pressure; the
    steady load and attitude angle are Ocvirk's: W = (η ω̄R L³/4C²) ε √(16ε² + π²(1−ε²)) / (1−ε²)²,
    tan φ = π√(1−ε²)/(4ε)."""
    land = HydrodynamicLand(eta=0.025, width=4e-3, min_film=1e-6)
    C, R, w_cage, w_planet = C_G, R_LAND, 900.0, 400.0
    e_abs = eps * C
    # cage centre at angle 0.4 from the bore centre, moving radially at eps_dot·C, no whirl
    n = np.array([np.cos(0.4), np.sin(0.4)])
    qf, vf = np.zeros(6), np.zeros(6)
    qf[3:5] = e_abs * n
    vf[3:6] = (*(eps_dot * C * n), w_cage)
    vf[2] = w_planet
    elem = GuideContact("g", [1], 0, clearance=C, K_g=K_G, restitution=0.8, impact_law=ExactRestitution(),
                        v_min=V_MIN, mu=0.1, v_mu=0.05, land_radius=R, land=land)
    Fn, Ft, _ = land.film(qf[3] - qf[0], qf[4] - qf[1], list(vf[3:6]), list(vf[0:3]), R, C)
    qn, qt = _pi_film_forces(eps, eps_dot, w_cage + w_planet, land.eta, R, land.width, C)
    assert float(Fn) == pytest.approx(qn, rel=1e-6) and float(Ft) == pytest.approx(qt, rel=1e-6)
    if eps_dot == 0.0:
        U = (w_cage + w_planet) * R
        W = land.eta * U * land.width ** 3 / (4 * C * C) * eps * np.sqrt(16 * eps ** 2 + np.pi ** 2 * (1 - eps ** 2)) \
            / (1 - eps ** 2) ** 2
        assert np.hypot(float(Fn), float(Ft)) == pytest.approx(W, rel=1e-12)
        assert float(Ft) / -float(Fn) == pytest.approx(np.pi * np.sqrt(1 - eps ** 2) / (4 * eps), rel=1e-12)
    # the element applies it (inside the clearance: no solid contact), balanced, with exact Jacobians
    F, out = assert_balanced(elem, qf, vf)
    assert out["force"][0] == 0.0
    assert_jacobians(elem, qf, vf)


def test_hydrodynamic_land_friction_is_the_film_shear():
    """Nearly centred cage (ε ≈ 7e-4): no film force to speak of, and the land friction is Petroff's
    −η v_t 2πRL/C."""
    land = HydrodynamicLand(eta=0.025, width=4e-3, min_film=1e-6)
    Fn, Ft, shear = land.film(1e-7, 0.0, [0.0, 0.0, 900.0], [0.0, 0.0, 400.0], R_LAND, C_G)
    assert abs(float(Fn)) < 1e-6 and abs(float(Ft)) < 2e-3
    v_t = 900.0 * R_LAND - 400.0 * (R_LAND + 1e-7)          # the bore's point is e further out
    assert float(shear) == pytest.approx(-0.025 * v_t * 2 * np.pi * R_LAND * 4e-3 / C_G, rel=1e-6)


@SETTINGS
@given(state=guide_states(), z=stored_speeds())
def test_guide_jacobian_and_balance(state, z):
    qf, vf, elem = guide_scene(*state)
    ecc = np.array(state[2])
    free = ecc < C_G
    for zz in (None, z):
        F, out = assert_jacobians(elem, qf, vf, z=zz)
        assert_balanced(elem, qf, vf, zz)
        np.testing.assert_allclose(out["eccentricity"], ecc, rtol=0, atol=1e-15)
        assert np.all(F[free] == 0) and np.all(out["force"][free] == 0) and np.all(out["force"] >= 0)
        # ε̇ = v_rad (the direction n of a tiny eccentricity carries round-off of the centres' positions)
        np.testing.assert_allclose(out["penetration_rate"][ecc > 0], np.array(state[4])[ecc > 0], rtol=1e-9,
                                   atol=1e-9)
        stored = np.zeros(N) if zz is None else zz[:, 0]
        Fe, v0 = expected_impact_force(K_G, ecc - C_G, np.array(state[4]), stored)
        np.testing.assert_allclose(out["force"], Fe, rtol=1e-9, atol=1e-12 * K_G * C_G)
        # without a stored speed v₀ is the iterate's ε̇: the same round-off as the penetration rate above
        np.testing.assert_allclose(out["approach_speed"], v0, rtol=1e-9, atol=0)


def test_guide_centred_cage_is_regular():
    qf, vf, elem = guide_scene((0.07, -0.04, 0.0), (1.0, 2.0, 300.0), [0.0, 0.0], [0.0, 1.0], [0.0, 0.1],
                               [0.0, 0.5], [0.0, -200.0])
    F, out, Jq, Jv = evaluate(elem, 0.0, FS, qf, vf, None, True)
    assert np.all(F == 0) and np.all(Jq == 0) and np.all(Jv == 0)
    assert np.all(out["eccentricity"] == 0) and np.all(np.isfinite(Jq))


def test_guide_restoring_and_land_friction():
    d = 4e-5
    ang = np.array([0.3, 2.0])
    w_planet, spins = 400.0, [100.0, 700.0]
    qf, vf, elem = guide_scene((0.07, -0.04, 0.5), (0.0, 0.0, w_planet), [C_G + d] * 2, ang, [0.0] * 2,
                               [0.0] * 2, spins)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    n = np.column_stack([np.cos(ang), np.sin(ang)])
    t = np.column_stack([-n[:, 1], n[:, 0]])
    np.testing.assert_allclose(out["force"], K_G * d, rtol=1e-9)
    np.testing.assert_allclose(np.sum(F[:, :2] * n, axis=1), -K_G * d, rtol=1e-9)     # cage back to the centre
    np.testing.assert_allclose(np.sum(F[:, 3:5] * n, axis=1), K_G * d, rtol=1e-9)     # planet the other way
    # land surface speed of the cage relative to the bore at the contact: (θ̇_g − θ̇_o)·r_L (centres at rest
    # apart from the bore's rotation carrying the point e + r_L n)
    v_rel = (np.array(spins) - w_planet) * R_LAND - w_planet * (C_G + d)
    fric = np.sum(F[:, :2] * t, axis=1)
    assert np.all(fric * v_rel < 0)
    np.testing.assert_allclose(out["friction"], fric, rtol=1e-12)
    np.testing.assert_allclose(np.abs(fric), 0.1 * np.tanh(np.abs(v_rel) / 0.05) * K_G * d, rtol=1e-9)
    # the friction torque brakes the relative spin of the cage
    assert np.all(F[:, 2] * (np.array(spins) - w_planet) < 0)
    assert np.all(power_of(F, vf, elem) < 0)
