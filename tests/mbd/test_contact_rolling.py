"""Hydrodynamic rolling resistance of the roller–raceway contact (HoupertRolling, RaceContact(rolling=...),
docs/model.md §9.5): the published law's form — its constant and exponents at a hand-evaluated point, its scaling
in load, speed, viscosity, pressure–viscosity and radius, odd in the entraining speed, zero at rest and at zero
load; in the race element: exact Jacobians, forces and moments balanced, the power −2F·u_e exactly (dissipative),
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

ETA0, ALPHA, E_RED, U_REG = 0.025, 2.2e-8, 2.31e11, 0.1
ROLL = HoupertRolling(eta0=ETA0, alpha_p=ALPHA, E_red=E_RED, length=LR, u_reg=U_REG)


def _element(kind, mk, R, traction=TANH, multiplicity=1):
    e = race_element(kind, N, mk, R, traction=traction, multiplicity=multiplicity)
    from mbd.elements.contact import RaceContact
    return RaceContact("race", e.dofs[:, 0] // 3, 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=e.K[0],
                       exponent=e.exponent, zeta=e.zeta[0], m_roller=e.m_roller[0], traction=traction,
                       multiplicity=multiplicity, rolling=ROLL)


def test_houpert_law_at_a_hand_evaluated_point():
    """F_R = (29.2/α) R L (U G)^0.648 W^0.246 (Biboulet & Houpert 2010, line contacts), evaluated by hand for a
    roller on the reference bearing's pin: Q = 2 kN, u = 5 m/s, R = 3.029 mm, L = 9 mm, η₀ = 0.025 Pa·s,
    α = 2.2e-8 1/Pa, E' = 2.31e11 Pa. U = η₀u/(E'R) = 1.79e-10, G = 5082, W = Q/(E'RL) = 3.18e-4:
    UG = 9.08e-7, (UG)^0.648 = 1.22e-4, W^0.246 = 0.138, (29.2/α) R L = 3.62e4 N: F_R = 0.606 N (a rolling
    friction coefficient F_R/Q ≈ 3e-4)."""
    R, Q, u = 1.0 / (2.0 / DR + 1.0 / R_IN), 2000.0, 5.0
    ut = np.hypot(u, U_REG)
    U, G, W = ETA0 * ut / (E_RED * R), ALPHA * E_RED, Q / (E_RED * R * LR)
    by_hand = 29.2 / ALPHA * R * LR * (U * G) ** 0.648 * W ** 0.246 * u / ut
    F = ROLL.force(np.array([Q]), np.array([u]), R)[0]
    assert F == pytest.approx(by_hand, rel=1e-13)
    assert F == pytest.approx(0.606, abs=5e-4)       # the hand evaluation in the docstring
    assert ROLLING_LAWS == {"houpert": HoupertRolling}


def test_houpert_scaling_and_limits():
    """The exponents as published: F ∝ Q^0.246, ∝ η₀^0.648, ∝ u^0.648 (far above u_reg), ∝ α^(0.648 − 1),
    ∝ R^(1 − 0.648 − 0.246), ∝ L^(1 − 0.246); odd in u; zero at u = 0 and at Q = 0."""
    R, Q, u = 3e-3, np.array([1500.0]), np.array([40.0])
    F = lambda law=ROLL, Q=Q, u=u, R=R: law.force(Q, u, R)[0]            # noqa: E731
    law = lambda **kw: HoupertRolling(**{**dict(eta0=ETA0, alpha_p=ALPHA, E_red=E_RED, length=LR, u_reg=U_REG),  # noqa: E731
                                          **kw})
    assert F(Q=2 * Q) / F() == pytest.approx(2 ** 0.246, rel=1e-13)
    assert F(law(eta0=2 * ETA0)) / F() == pytest.approx(2 ** 0.648, rel=1e-13)
    assert F(law(alpha_p=2 * ALPHA)) / F() == pytest.approx(2 ** -0.352, rel=1e-13)
    assert F(R=2 * R) / F() == pytest.approx(2 ** 0.106, rel=1e-13)
    assert F(law(length=2 * LR)) / F() == pytest.approx(2 ** 0.754, rel=1e-13)
    assert F(u=2 * u) / F() == pytest.approx(2 ** 0.648, rel=1e-5)        # (u_reg/u)² = 6e-6
    assert F(u=-u) == -F()
    assert F(u=np.array([0.0])) == 0.0
    assert F(Q=np.array([0.0])) == 0.0
    with pytest.raises(ModelError, match="alpha_p"):
        law(alpha_p=0.0)


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
    scale = np.abs(FR * u).max() + 1e-13 * np.abs(power_of(F0, vf, elem)).max() + 1e-300
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
