"""Hydrodynamic rolling resistance of the roller–raceway contact (HoupertRolling, RaceContact(rolling=...),
docs/model.md §9.5): Houpert's correlation against the numbers Biboulet & Houpert (2010) print — its two asymptotes'
values at their reference points, eq. 42 at both ends of its range in Moes' M — its scaling in each regime (IVR:
√(UW); EHL: U^(3/4), load- and α-free), odd in the entraining speed, zero at rest and at zero load; in the race
element: exact Jacobians, forces and moments balanced, the power −2F·u_e exactly (dissipative),
the roller's moment (ρ − R)F, nothing where the contact is open, and the default (no rolling law) untouched.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from mbd.element import evaluate
from mbd.elements.contact import ROLLING_LAWS, HoupertRolling
from mbd.errors import ModelError

from tests.support.contact import (DR, FILM, LR, N, R_IN, R_OUT, SETTINGS, TANH, assert_balanced, assert_jacobians,
                                   assert_objective, power_of, race_element, race_scene, race_states)

ETA0, E_RED, U_REG = 0.025, 2.31e11, 0.1
ROLL = HoupertRolling(eta0=ETA0, E_red=E_RED, length=LR, u_reg=U_REG)


def _element(kind, mk, R, traction=TANH, multiplicity=1):
    e = race_element(kind, N, mk, R, traction=traction, multiplicity=multiplicity)
    from mbd.elements.contact import RaceContact
    return RaceContact("race", e.dofs[:, 0] // 3, 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=e.K[0],
                       exponent=e.exponent, zeta=e.zeta[0], m_roller=e.m_roller[0], traction=traction,
                       multiplicity=multiplicity, rolling=ROLL)


def test_houpert_against_the_papers_numbers():
    """Biboulet & Houpert (2010) §3.5 print their fully flooded moment per unit length at reference points:
    T̃*_IVR = 14.2e-9 at U = 1e-10, W = 1e-6 (M = 0.1) and T̃*_EHL∞ = 8.26e-9 at U = 1e-11 (load-free); eq. 42 in
    Hertzian units, T* = 1.4/M (IVR) and 1.45 M^(−3/2) (EHL), at the ends of their range M = 0.2 … 200."""
    np.testing.assert_allclose(ROLL.moment(np.array([1e-10]), np.array([1e-6])), 14.2e-9, rtol=3e-3)
    for W in (1e-3, 1e-2):                                   # M = 316, 3162: deep in the EHL regime
        np.testing.assert_allclose(ROLL.moment(np.array([1e-11]), np.array([W])), 8.26e-9, rtol=5e-3)
    # eq. 42 in Hertzian units: T* = T̃ / (8 W^(3/2)/(π√(2π)))
    U = 1e-10
    T_star = lambda M: ROLL.moment(np.array([U]), np.array([M * np.sqrt(U)]))[0] / (             # noqa: E731
        8.0 * (M * np.sqrt(U)) ** 1.5 / (np.pi * np.sqrt(2 * np.pi)))
    assert T_star(1e-3) == pytest.approx(1.4 / 1e-3, rel=1e-12)          # IVR: 1.4/M
    assert T_star(200.0) == pytest.approx(1.45 * 200.0 ** -1.5, rel=1e-6)  # EHL: 1.45 M^(−3/2)
    # at the regimes' crossing √M = 1.45/1.4 the blend is 2^(−1/10) below either asymptote
    Mc = (1.45 / 1.4) ** 2
    assert T_star(Mc) == pytest.approx(1.4 / Mc * 2 ** -0.1, rel=1e-12)
    assert ROLLING_LAWS == {"houpert": HoupertRolling}


def test_houpert_force_at_a_bearing_contact():
    """The force of one roller on the reference bearing's pin, Q = 2 kN, u = 5 m/s, R = 3.029 mm, L = 9 mm,
    η₀ = 0.025 Pa·s, E' = 2.31e11 Pa, by hand: U = 2η₀u/(E'R) = 3.57e-10, W = Q/(E'RL) = 3.18e-4, M = 16.8 (EHL):
    T̃ ≈ 1.47 U^(3/4) = 1.21e-7 and F_R = E'RL·T̃ ≈ 0.76 N, a rolling friction coefficient F_R/Q ≈ 4e-4."""
    R = 1.0 / (2.0 / DR + 1.0 / R_IN)
    F = ROLL.force(np.array([2000.0]), np.array([5.0]), R)[0]
    U = 2 * ETA0 * np.hypot(5.0, U_REG) / (E_RED * R)
    assert F == pytest.approx(E_RED * R * LR * 1.47 * U ** 0.75 * 5.0 / np.hypot(5.0, U_REG), rel=5e-3)
    assert F == pytest.approx(0.76, abs=0.01)


def test_houpert_scaling_and_limits():
    """IVR (light load): F ∝ (η₀ u Q)^(1/2); EHL (heavy load): F ∝ (η₀ u)^(3/4), load-free; odd in u; zero at u = 0
    and at Q = 0."""
    R = 3e-3
    F = lambda Q, u=40.0, law=ROLL: law.force(np.array([Q]), np.array([u]), R)[0]          # noqa: E731
    thick = HoupertRolling(eta0=2 * ETA0, E_red=E_RED, length=LR, u_reg=U_REG)
    q_ivr = 1e-4                                     # M ≈ 5e-6: (1 + s)^(−1/10) = 1 to 1e-27
    assert F(4 * q_ivr) / F(q_ivr) == pytest.approx(2.0, rel=1e-9)
    assert F(q_ivr, law=thick) / F(q_ivr) == pytest.approx(np.sqrt(2.0), rel=1e-9)
    heavy, heavier = 1e7, 1e8                        # M ≈ 1e3, 1e4: (1 + s)^(−1/10) at its power law to 1e-15
    assert F(heavier) / F(heavy) == pytest.approx(1.0, rel=1e-9)
    assert F(heavy, law=thick) / F(heavy) == pytest.approx(2 ** 0.75, rel=1e-9)
    assert F(heavy, u=80.0) / F(heavy) == pytest.approx(2 ** 0.75, rel=1e-5)   # (u_reg/u)² = 6e-6
    assert F(1e3, u=-40.0) == -F(1e3)
    assert F(1e3, u=0.0) == 0.0
    assert F(0.0) == 0.0
    with pytest.raises(ModelError, match="eta0"):
        HoupertRolling(eta0=0.0, E_red=E_RED, length=LR, u_reg=U_REG)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("traction", ["tanh", "film"])
@SETTINGS
@given(state=st.data())
def test_race_with_rolling_jacobians_balance_power(kind, traction, state):
    qf, vf, mk, R = race_scene(kind, *state.draw(race_states(kind)))
    tr = TANH if traction == "tanh" else FILM
    elem = _element(kind, mk, R, tr)
    plain = race_element(kind, N, mk, R, traction=tr)
    if traction == "tanh":   # (the film law's slope at rest is too steep for finite differences: its own test
        assert_jacobians(elem, qf, vf)       # checks its derivatives, and the compiled kernel's agreement below)
    F, out = assert_balanced(elem, qf, vf)
    F0, out0, _, _ = evaluate(plain, 0.0, elem_fs(), qf, vf, None, False)
    for key in out0:                                  # the contact's outputs are the law's without rolling
        np.testing.assert_array_equal(out[key], out0[key])
    Q, u = out["load"], out["rolling_speed"]
    FR = np.where(Q > 0, ROLL.force(np.where(Q > 0, Q, 1.0), u, elem.R_red), 0.0)
    dF = F - F0
    # the power of the rolling forces: −2 F_R u_e (u_e relative to the moving contact point), never positive
    dP = power_of(F, vf, elem) - power_of(F0, vf, elem)
    scale = np.abs(FR * u).max() + 1e-6 * np.abs(F0 * vf[elem.dofs]).sum(axis=1).max() + 1e-300   # F − F0's round-off
    np.testing.assert_allclose(dP, -2.0 * FR * u, rtol=1e-9, atol=1e-9 * scale)
    assert np.all(dP <= 1e-9 * scale)
    # on the roller: the force F_R(2R/ρ − 1) along t and the moment (ρ − R)F_R; nothing where the contact is open
    x = qf[elem.dofs]
    c = x[:, 3:5] + (np.array([[np.cos(x[0, 5]), -np.sin(x[0, 5])], [np.sin(x[0, 5]), np.cos(x[0, 5])]]) @ mk)
    d = x[:, :2] - c
    rho = np.hypot(d[:, 0], d[:, 1])
    t = np.column_stack([-d[:, 1], d[:, 0]]) / rho[:, None]
    big = 1e-13 * np.abs(F0).max()                    # the difference F − F0 carries the round-off of F0
    np.testing.assert_allclose(dF[:, :2], (FR * (2 * R / rho - 1))[:, None] * t, rtol=1e-9, atol=big)
    np.testing.assert_allclose(dF[:, 2], (rho - R) * FR, rtol=1e-9, atol=big * DR)
    assert np.all(dF[Q == 0] == 0.0)


def elem_fs():
    from tests.support.contact import FS
    return FS


@SETTINGS
@given(state=st.data(), alpha=st.floats(-np.pi, np.pi), w=st.floats(-300, 300))
def test_race_with_rolling_objective(state, alpha, w):
    qf, vf, mk, R = race_scene("inner", *state.draw(race_states("inner")))
    assert_objective(_element("inner", mk, R), qf, vf, alpha, w, (0.3, -0.2))


def test_roller_moment_opposes_rolling_on_a_still_pin():
    """A roller rolling on the still pin (carrier frame): its surface at rest on the pin, its centre orbiting
    forward: the rolling resistance brakes both its spin and its orbit."""
    qf, vf, mk, R = race_scene("inner", (0, 0, 0), (0, 0, 0), 0.0, [0.3], [1e-5], [0.0], [2.0], [0.0])
    from mbd.elements.contact import RaceContact
    e0 = race_element("inner", 1, mk, R)
    elem = RaceContact("race", [1], 0, kind="inner", race_marker=mk, R_race=R, D=DR, K=e0.K[0], exponent=e0.exponent,
                       zeta=0.0, m_roller=e0.m_roller[0], traction=TANH, rolling=ROLL)
    F, out, _, _ = evaluate(elem, 0.0, elem_fs(), qf, vf, None, False)
    F0, _, _, _ = evaluate(e0, 0.0, elem_fs(), qf, vf, None, False)
    dF = (F - F0)[0]
    orbit_dir = np.array([-np.sin(0.3), np.cos(0.3)])
    assert out["rolling_speed"][0] < 0                # the surfaces move backwards past the advancing contact
    assert dF[:2] @ orbit_dir < 0                     # the orbit is braked
    assert dF[2] * vf[5] < 0                          # so is the spin
