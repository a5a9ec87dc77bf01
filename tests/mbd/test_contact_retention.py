"""The pocket's radial retention of a roller-centred cage (PocketRetention, docs/model.md §8.5): exact Jacobians,
balance and the impact law K_r x (1 + λ ẋ/v₀) on random states; the faces push the roller back to the pitch circle
through its centre (no moment on the cage without friction); a centred cage among uniformly spaced rollers feels no
net force; a displaced cage is pushed back by the pockets with the stiffness a hand calculation gives.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given

from mbd.element import evaluate
from mbd.elements.contact import ExactRestitution, PocketContact, PocketRetention

from tests.support.contact import (C_P, C_R, DM, DR, E_SET, FS, K_P, N, SETTINGS, V_MIN, assert_balanced,
                                   assert_jacobians, assert_objective, expected_impact_force, retention_scene,
                                   retention_states, stored_speeds)


@SETTINGS
@given(state=retention_states(), z=stored_speeds())
def test_retention_jacobian_balance_and_law(state, z):
    qf, vf, elem, _ = retention_scene(*state)
    radial = np.array(state[4])
    inside = np.abs(radial) < C_R
    for zz in (None, z):
        assert_jacobians(elem, qf, vf, z=zz)
        F, out = assert_balanced(elem, qf, vf, zz)
        # the scene puts the roller at d_m/2 + u along its radial line from the cage centre, moving radially at v_rad
        np.testing.assert_allclose(out["offset"], radial, rtol=0, atol=1e-15)
        assert np.all(F[inside] == 0) and np.all(out["force"][inside] == 0)
        # ẋ = sign(u)·ρ̇, ρ̇ the roller's radial speed relative to the cage (a roller on the pitch circle, u = 0
        # to round-off, has no nearer face)
        off = np.abs(radial) > 1e-12
        np.testing.assert_allclose(out["penetration_rate"][off], (np.sign(radial) * np.array(state[6]))[off], rtol=0,
                                   atol=1e-12)
        stored = np.zeros(N) if zz is None else zz[:, 0]
        Fe, v0 = expected_impact_force(K_P, np.abs(out["offset"]) - C_R, out["penetration_rate"], stored)
        np.testing.assert_allclose(np.abs(out["force"]), Fe, rtol=1e-12, atol=1e-12 * K_P * C_R)
        np.testing.assert_allclose(out["approach_speed"], v0, rtol=1e-12, atol=0)
        assert np.all(out["force"] * radial >= 0)                # + when the roller presses the cage outwards


@SETTINGS
@given(state=retention_states())
def test_retention_is_objective(state):
    qf, vf, elem, _ = retention_scene(*state)
    assert_objective(elem, qf, vf, 0.7, 30.0, (0.3, -0.1))


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_retention_pushes_the_roller_back_through_its_centre(side):
    """Without relative motion the force is K_r x along the cage's radial line, towards the pitch circle, with no
    moment on either body; with friction it brakes the roller's spin relative to the cage."""
    depth = 3e-5
    u = side * (C_R + depth)
    qf, vf, elem, psi = retention_scene((0.05, -0.01, 0.4), (0.0, 0.0, 0.0), [0, 5], [0.0, 0.0], [u, u],
                                        [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], mu=0.0)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(out["force"], side * K_P * depth, rtol=1e-9)
    beta = 0.4 + psi
    e = np.column_stack([np.cos(beta), np.sin(beta)])
    np.testing.assert_allclose(F[:, :2], -side * K_P * depth * e, rtol=1e-9, atol=1e-9 * K_P * depth)
    np.testing.assert_array_equal(F[:, 3:5], -F[:, :2])
    assert np.all(F[:, 2] == 0) and np.all(F[:, 5] == 0)
    # friction μ F on a roller spinning at ω relative to the cage: its moment −μ F D/2 sign(ω)
    qf, vf, elem, _ = retention_scene((0.05, -0.01, 0.4), (0.0, 0.0, 0.0), [0, 5], [0.0, 0.0], [u, u],
                                      [0.0, 0.0], [0.0, 0.0], [500.0, -500.0], mu=0.1)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(F[:, 2], -0.1 * K_P * depth * DR / 2 * np.array([1.0, -1.0]), rtol=1e-6)


def _cage_among_rollers(r_m, delta, phi, Z=12):
    """Cage and pocket/retention families of Z rollers fixed on a circle of radius r_m about the origin, the cage
    centre displaced by delta along phi, no motion. Returns the total force on the cage (x, y) and the moment."""
    psi = 2 * np.pi * np.arange(Z) / Z
    qf, vf = np.zeros(3 * (Z + 1)), np.zeros(3 * (Z + 1))
    qf[:2] = delta * np.array([np.cos(phi), np.sin(phi)])
    for j in range(Z):
        qf[3 * (j + 1):3 * (j + 1) + 2] = r_m * np.array([np.cos(psi[j]), np.sin(psi[j])])
    law = dict(restitution=E_SET, impact_law=ExactRestitution(), v_min=V_MIN, mu=0.1, v_mu=0.05, D=DR)
    rollers = np.arange(1, Z + 1)
    pocket = PocketContact("pocket", rollers, 0, pocket_angle=psi, pitch_radius=r_m, clearance=C_P, K_p=K_P, **law)
    retain = PocketRetention("retention", rollers, 0, pitch_radius=r_m, clearance=C_R, K_r=K_P, **law)
    total = np.zeros(3)
    for elem in (pocket, retain):
        F, _, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
        total += F[:, 3:].sum(axis=0)
    return total


def test_a_centred_cage_among_uniform_rollers_stays_centred():
    """Twelve rollers uniformly spaced, all pressing outwards beyond the radial play (a centrifugal field): the
    forces on the cage cancel (round-off of the twelve)."""
    Z, u = 12, C_R + 4e-5
    psi = 2 * np.pi * np.arange(Z) / Z
    qf, vf = np.zeros(3 * (Z + 1)), np.zeros(3 * (Z + 1))
    for j in range(Z):
        qf[3 * (j + 1):3 * (j + 1) + 2] = (DM / 2 + u) * np.array([np.cos(psi[j]), np.sin(psi[j])])
        vf[3 * (j + 1) + 2] = 700.0
    elem = PocketRetention("retention", np.arange(1, Z + 1), 0, pitch_radius=DM / 2, clearance=C_R, K_r=K_P,
                           restitution=E_SET, impact_law=ExactRestitution(), v_min=V_MIN, mu=0.1, v_mu=0.05, D=DR)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    f1 = K_P * 4e-5
    np.testing.assert_allclose(out["force"], f1, rtol=1e-6)
    assert np.abs(F[:, 3:5].sum(axis=0)).max() <= 1e-12 * f1
    # the spinning rollers' friction turns the cage (Z μ F D/2 ... about the cage centre): equal on every roller
    np.testing.assert_allclose(F[:, 5], F[0, 5], rtol=1e-9)


def test_pocket_centring_stiffness_against_a_hand_calculation():
    """A cage displaced by Δ along φ among Z = 12 rollers (pockets 30° apart, φ = 15°): roller j, at ψ_j − φ from
    the displacement, is offset radially by −Δ cos(ψ_j − φ) and along the pitch circle by Δ sin(ψ_j − φ) in its
    pocket (to first order in Δ/r_m), so the pockets push the cage back with
    K [Σ (Δ|cos| − C_r)⁺ |cos| + Σ (Δ|sin| − C_p)⁺ |sin|] (linear law at rest). At Δ = 0.3 mm the rollers at
    ±15°, ±45° (radially) and ±45°, ±75° (circumferentially) from the displacement touch, per side four each: the
    stiffness K (4 cos²15° + 4 cos²45° + 4 sin²45° + 4 sin²75°)·... = K (8 + 2√3). A large pitch radius
    (10 m) makes the first-order offsets exact to 1e-4 of the penetrations."""
    r_m, phi = 10.0, np.radians(15.0)
    a = np.radians(np.arange(12) * 30.0) - phi
    c, s = np.abs(np.cos(a)), np.abs(np.sin(a))

    def hand(delta):
        return K_P * (np.sum(np.maximum(delta * c - C_R, 0) * c) + np.sum(np.maximum(delta * s - C_P, 0) * s))

    n = np.array([np.cos(phi), np.sin(phi)])
    for delta in (0.25e-3, 0.3e-3):
        total = _cage_among_rollers(r_m, delta, phi)
        assert hand(delta) > 0
        np.testing.assert_allclose(total[:2] @ n, -hand(delta), rtol=2e-4)
        assert abs(total[:2] @ np.array([-n[1], n[0]])) <= 2e-4 * hand(delta)      # symmetric about φ
    k = -(_cage_among_rollers(r_m, 0.31e-3, phi)[:2] - _cage_among_rollers(r_m, 0.29e-3, phi)[:2]) @ n / 0.02e-3
    np.testing.assert_allclose(k, K_P * (8 + 2 * np.sqrt(3)), rtol=1e-3)
    # within both plays the cage floats free
    assert np.all(_cage_among_rollers(r_m, 0.09e-3, phi) == 0)


@SETTINGS
@given(state=retention_states(), z=stored_speeds())
def test_retention_multiplicity_scales_forces_not_outputs(state, z):
    qf, vf, one, _ = retention_scene(*state)
    _, _, two, _ = retention_scene(*state, multiplicity=2)
    F1, o1, J1, V1 = evaluate(one, 0.0, FS, qf, vf, z, True)
    F2, o2, J2, V2 = evaluate(two, 0.0, FS, qf, vf, z, True)
    np.testing.assert_array_equal(F2, 2 * F1)
    np.testing.assert_array_equal(J2, 2 * J1)
    np.testing.assert_array_equal(V2, 2 * V1)
    for key in o1:
        np.testing.assert_array_equal(o2[key], o1[key])


def test_retention_parameter_errors_name_the_parameter():
    from mbd.errors import ModelError
    ok = dict(pitch_radius=DM / 2, clearance=C_R, K_r=K_P, restitution=E_SET, impact_law=ExactRestitution(),
              v_min=V_MIN, mu=0.1, v_mu=0.05, D=DR)
    PocketRetention("r", [1], 0, **ok)
    for key, bad in (("clearance", -1e-5), ("K_r", 0.0), ("pitch_radius", 0.0), ("restitution", 0.0),
                     ("mu", -0.1), ("D", 0.0)):
        with pytest.raises(ModelError, match=key):
            PocketRetention("r", [1], 0, **{**ok, key: bad})
    with pytest.raises(TypeError):
        PocketRetention("r", [1], 0, **{k: v for k, v in ok.items() if k != "K_r"})


def test_without_retention_the_pockets_leave_a_displaced_cage_free():
    """The circumferential pocket contact alone cannot centre a cage: displace it by Δ and put each roller where its
    pocket's centre line from the displaced cage centre crosses the rollers' orbit (the rollers re-spaced along their
    orbits, those in line with Δ moved radially in their pockets) — every pocket is centred and no force acts; the
    radial retention then pushes the cage back."""
    Z, r_m, delta, phi = 12, DM / 2, 0.4e-3, 0.3
    c = delta * np.array([np.cos(phi), np.sin(phi)])
    psi = 2 * np.pi * np.arange(Z) / Z
    qf, vf = np.zeros(3 * (Z + 1)), np.zeros(3 * (Z + 1))
    qf[:2] = c
    for j in range(Z):
        e = np.array([np.cos(psi[j]), np.sin(psi[j])])
        s = -c @ e + np.sqrt((c @ e) ** 2 - c @ c + r_m ** 2)   # |c + s e| = r_m: on the orbit about the origin
        qf[3 * (j + 1):3 * (j + 1) + 2] = c + s * e
    law = dict(restitution=E_SET, impact_law=ExactRestitution(), v_min=V_MIN, mu=0.1, v_mu=0.05, D=DR)
    rollers = np.arange(1, Z + 1)
    pocket = PocketContact("pocket", rollers, 0, pocket_angle=psi, pitch_radius=r_m, clearance=C_P, K_p=K_P, **law)
    F, out, _, _ = evaluate(pocket, 0.0, FS, qf, vf, None, False)
    assert np.all(F == 0) and np.abs(out["offset"]).max() <= 1e-15
    retain = PocketRetention("retention", rollers, 0, pitch_radius=r_m, clearance=C_R, K_r=K_P, **law)
    F, out, _, _ = evaluate(retain, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(out["offset"], -delta * np.cos(psi - phi), rtol=0, atol=delta ** 2 / r_m)
    assert F[:, 3:5].sum(axis=0) @ c < 0                       # back towards the centre
