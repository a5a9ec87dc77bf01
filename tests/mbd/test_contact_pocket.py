"""The roller–cage pocket contact (PocketContact, docs/model.md §8.5): exact Jacobians, balance and the impact law
K_p d (1 + λ ḋ/v₀) on random states with and without stored approach speeds; the wall pushes the roller back and
moves the cage by force × d_m/2, wall friction opposes the roller's sliding; Hunt–Crossley damping with the
iterate's and with a stored approach speed, clipped at zero.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from mbd.element import evaluate
from mbd.elements.contact import restitution_lambda

from tests.support.contact import (C_P, DM, DR, E_SET, FS, K_P, N, SETTINGS, V_MIN, assert_balanced, assert_jacobians,
                                   expected_impact_force, pocket_scene, pocket_states, stored_speeds)


@SETTINGS
@given(state=pocket_states(), z=stored_speeds())
def test_pocket_jacobian_and_balance(state, z):
    qf, vf, elem, _ = pocket_scene(*state)
    offsets = np.array(state[3])
    inside = np.abs(offsets) < C_P
    for zz in (None, z):
        assert_jacobians(elem, qf, vf, z=zz)
        F, out = assert_balanced(elem, qf, vf, zz)
        np.testing.assert_allclose(out["offset"], offsets, rtol=0, atol=1e-12)
        assert np.all(F[inside] == 0) and np.all(out["force"][inside] == 0)
        assert np.all(out["force"] * offsets >= 0)                       # + when pushing the cage forward
        np.testing.assert_allclose(out["penetration"], np.maximum(np.abs(offsets) - C_P, 0), rtol=0, atol=1e-12)
        # the law: K_p d (1 + λ ḋ/v₀) ≥ 0 (ḋ = sign(s)·ṡ)
        rate = np.sign(out["offset"]) * (DM / 2) * np.array(state[5]) / (DM / 2 + np.array(state[4]))
        np.testing.assert_allclose(out["penetration_rate"], rate, rtol=1e-9, atol=1e-12)
        stored = np.zeros(N) if zz is None else zz[:, 0]
        Fe, v0 = expected_impact_force(K_P, np.abs(offsets) - C_P, out["penetration_rate"], stored)
        np.testing.assert_allclose(np.abs(out["force"]), Fe, rtol=1e-9, atol=1e-12 * K_P * C_P)
        # without a stored speed v₀ is the iterate's ε̇: the same round-off as the penetration rate above
        np.testing.assert_allclose(out["approach_speed"], v0, rtol=1e-9, atol=0)
        assert np.all(out["force"][~inside][Fe[~inside] > 0] * offsets[~inside][Fe[~inside] > 0] > 0)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_pocket_pushes_roller_back_and_cage_moment(side):
    depth = 3e-5
    # no relative velocity: the force is K_p·d; mu = 0: the cage moment is exactly force × d_m/2
    qf, vf, elem, psi = pocket_scene((0.05, -0.01, 0.4), (0.3, -0.2, 50.0), [0, 5], [side * (C_P + depth)] * 2,
                                     [0.0, 1e-4], [0.0, 0.0], [0.0, 0.0], [800.0, -800.0], mu=0.0)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(out["force"], side * K_P * depth, rtol=1e-6)
    np.testing.assert_allclose(F[:, 5], out["force"] * DM / 2, rtol=1e-12)
    beta = 0.4 + psi + side * (C_P + depth) / (DM / 2)
    t = np.column_stack([-np.sin(beta), np.cos(beta)])
    e = np.column_stack([np.cos(beta), np.sin(beta)])
    tang = np.sum(F[:, :2] * t, axis=1)
    assert np.all(np.sign(tang) == -side)                               # back towards the pocket centre
    np.testing.assert_allclose(np.sum(F[:, :2] * e, axis=1), 0.0, atol=1e-9 * abs(tang).max())
    np.testing.assert_allclose(np.abs(tang[0]), K_P * depth, rtol=1e-6)   # on the pitch circle: F itself
    assert np.all(F[:, 2] == 0)                                         # no spin torque without friction
    # with wall friction: it opposes the radial sliding of the roller surface on the wall
    qf, vf, elem, psi = pocket_scene((0.05, -0.01, 0.4), (0.3, -0.2, 50.0), [0, 5], [side * (C_P + depth)] * 2,
                                     [0.0, 1e-4], [0.0, 0.0], [0.0, 0.0], [800.0, -800.0], mu=0.1)
    F2, out2, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    friction_e = np.sum((F2[:, :2] - F[:, :2]) * e, axis=1)             # radial part added by friction
    # radial sliding of the roller surface point p + sign(s)(D/2)t on the cage wall: sign(s)(D/2)(θ̇_g − spin)
    spins = np.array([800.0, -800.0])
    v_slide = side * (DR / 2) * (50.0 - spins)
    assert np.all(friction_e * v_slide < 0)
    np.testing.assert_allclose(np.abs(friction_e), 0.1 * np.tanh(np.abs(v_slide) / 0.05) * K_P * depth, rtol=1e-6)
    assert np.all(F2[:, 2] * (spins - 50.0) < 0)                         # and brakes the relative spin
    assert_balanced(elem, qf, vf)


def test_pocket_hunt_crossley_damping():
    d = 2e-5
    lam = float(restitution_lambda(E_SET))
    # relative circumferential velocity into the wall (s > 0 growing) stiffens, out of it softens, clipped at 0
    qf, vf, elem, _ = pocket_scene((0, 0, 0), (0, 0, 0), [1, 1, 1, 1], [C_P + d] * 4, [0] * 4,
                                   [0.05, -0.005, -1.0, 0.001], [0] * 4, [0] * 4, mu=0.0)
    # no stored approach speed (the impact begins in this step): v₀ = max(ḋ, v_min) of the iterate
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    expect = K_P * d * np.array([1 + lam, 1 - lam * 0.005 / V_MIN, 0.0, 1 + lam * 0.001 / V_MIN])
    np.testing.assert_allclose(out["force"], expect, rtol=1e-9)
    np.testing.assert_allclose(out["approach_speed"], [0.05, V_MIN, V_MIN, V_MIN], rtol=1e-12)
    assert np.all(F[2] == 0)
    # a stored approach speed v₀: c = λ/v₀
    z = np.zeros((4, 4))
    z[:, 0] = [0.5, 0.5, 0.3, 3.0]
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, z, False)
    rate = np.array([0.05, -0.005, -1.0, 0.001])
    expect = np.maximum(K_P * d * (1 + lam * rate / z[:, 0]), 0.0)
    np.testing.assert_allclose(out["force"], expect, rtol=1e-9)
    np.testing.assert_allclose(out["approach_speed"], z[:, 0], rtol=0)
    assert out["force"][2] == 0 and np.all(F[2] == 0)
    # out of contact: no force, approach speed 0 (whatever is stored)
    qf, vf, elem, _ = pocket_scene((0, 0, 0), (0, 0, 0), [1, 1], [C_P - d, -(C_P - d)], [0] * 2,
                                   [0.05, -0.05], [0] * 2, [0] * 2, mu=0.0)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, z[:2], False)
    assert np.all(F == 0) and np.all(out["approach_speed"] == 0)
    np.testing.assert_allclose(out["penetration_rate"], [0.05, 0.05], rtol=1e-12)   # closing on either side
