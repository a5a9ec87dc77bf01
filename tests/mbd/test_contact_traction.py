"""The traction laws of the roller–raceway contact (docs/model.md §8.2, §9.3): the slide-to-roll curve's shape and
its exact slope at rolling, the parameters' errors; the EHL film law — the tanh law in its no-pressure limit, exact
derivatives in slip, rolling speed and load, its shape (linear at low slip with the Maxwell film's Newtonian shear
and the thermal film reduction, the limiting-shear plateau), and in the race element, balanced.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

from mbd.elements.contact import TRACTION_LAWS, EHLTraction, SlideRollTraction, TanhTraction
from mbd.errors import ModelError

from tests.support.contact import EHL, FILM, LR, N, assert_balanced, race_element, race_scene


def test_ehl_curve_shape():
    tr = EHL
    s = np.array([-2.0, -0.1, -0.033, -1e-3, 0.0, 1e-3, 0.033, 0.1, 2.0])
    u = np.full(s.size, 10.0)
    v_s = s * np.sqrt(u ** 2 + tr.u_reg ** 2)
    mu = tr.coefficient(v_s, u)
    np.testing.assert_allclose(mu, -mu[::-1], atol=1e-15)                       # odd
    f = lambda x: (tr.A + tr.B * x) * np.exp(-tr.C * x) + tr.D                   # noqa: E731
    big = np.abs(s) >= 0.03
    np.testing.assert_allclose(mu[big], np.sign(s[big]) * f(np.abs(s[big])), rtol=1e-4)  # the curve
    # near rolling the regularised |s| deviates by O((s_eps/s)²): 0.5 % at s = 1e-3
    np.testing.assert_allclose(mu[[3, 5]], np.array([-1, 1]) * f(1e-3), rtol=1e-2)
    assert mu[4] == 0.0 and 0.07 < mu.max() < 0.075                              # peak ≈ 0.073
    # slope at pure rolling: B − A·C (the regularised sign changes it by O(C·s_eps)), exact Jacobian
    from mbd import ad
    x = ad.Dual(np.array([0.0]), np.array([[1.0]]))
    slope = tr.coefficient(x, np.array([10.0])).der[0, 0] * np.sqrt(100.0 + tr.u_reg ** 2)
    assert slope == pytest.approx(f(tr.s_eps) / tr.s_eps, rel=1e-9)           # d/ds (s/a)f(a) at 0
    assert slope == pytest.approx(tr.B - tr.A * tr.C, rel=tr.C * tr.s_eps)   # ≈ f'(0), to O(C s_eps)
    assert TRACTION_LAWS == {"tanh": TanhTraction, "slide_roll": SlideRollTraction, "ehl": EHLTraction}
    with pytest.raises(ModelError, match="v0"):
        TanhTraction(mu_max=0.08, v0=0.0)
    with pytest.raises(TypeError):          # no defaults: every coefficient comes from the parameters
        SlideRollTraction(A=-0.04, B=5.0, C=40.0, D=0.04)


def _film_mu(law, v_s, u=5.0, Q=2000.0, R=3e-3):
    return law.coefficient(np.asarray(v_s, float), np.full(np.shape(v_s), u), np.full(np.shape(v_s), Q),
                           np.full(np.shape(v_s), R))


def test_ehl_traction_is_the_tanh_law_without_pressure_effects():
    """γ_L = 0, a rigid film (G_e → ∞) and α_p·p ≪ 1 (viscosity and limiting shear uniform over the strip):
    the tanh law with μ_max = τ_L0/p̄ and v0 = h_c τ_L0/η₀ (docs/model.md §9.3's limit), to α_p·p_max."""
    from mbd.elements import ehl
    law = EHLTraction(eta0=0.025, alpha_p=1e-13, E_red=2.31e11, length=LR, tau_L0=2e6, gamma_L=0.0, G_e=1e300,
                      u_reg=0.1, beta=0.0, k_oil=0.13)
    u, Q, R = 5.0, 2000.0, 3e-3
    w = Q / LR
    p_max = ehl.hertz_peak_pressure(w, R, law.E_red)
    h_c = ehl.film_central(np.hypot(u, law.u_reg), w, R, law.eta0, law.alpha_p, law.E_red)
    tanh = TanhTraction(mu_max=law.tau_L0 / (0.25 * np.pi * p_max), v0=h_c * law.tau_L0 / law.eta0)
    v = np.linspace(-3.0, 3.0, 61) * tanh.v0
    np.testing.assert_allclose(_film_mu(law, v, u, Q, R), tanh.coefficient(v) * np.sum(ehl.STRIP_WEIGHTS),
                               rtol=2 * law.alpha_p * p_max, atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(v_s=st.floats(-0.5, 0.5), u=st.floats(1.0, 10.0), Q=st.floats(100.0, 5000.0), R=st.floats(2e-3, 5e-3))
@example(v_s=0.0, u=1.0, Q=100.0, R=2e-3)       # pure rolling: μ = 0 and ∂μ/∂u = ∂μ/∂Q = 0
def test_ehl_traction_derivatives_are_exact(v_s, u, Q, R):
    """The law's dual-number derivatives in v_s, u and Q against central differences, at bearing-like
    states (entraining speeds of m/s; at u → 0 the film vanishes and the law tends to a Coulomb step,
    where no finite difference resolves it). The race element's Jacobian is built from these."""
    from mbd import ad
    args = [np.array([x]) for x in (v_s, u, Q)]
    for j, step in enumerate((1e-7, 1e-6, 1e-3)):
        dual = [ad.Dual(a, np.array([[1.0 if k == j else 0.0]])) for k, a in enumerate(args)]
        d = FILM.coefficient(dual[0], dual[1], dual[2], np.array([R])).der[0, 0]
        f = lambda x: FILM.coefficient(*[np.array([x]) if k == j else a for k, a in enumerate(args)],  # noqa: E731
                                       np.array([R]))[0]
        x0 = args[j][0]
        fd = (8 * (f(x0 + step) - f(x0 - step)) - (f(x0 + 2 * step) - f(x0 - 2 * step))) / (12 * step)
        # differencing noise ~ ε·μ/step, with μ's scale 0.1 (at v_s = 0 both are 0, up to a denormal)
        assert d == pytest.approx(fd, rel=1e-5, abs=1e-9 * 0.1 / step)


def test_ehl_traction_in_the_race_contact_balances():
    """The race element with the EHL law: forces balance and the traction opposes the slip."""
    state = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 0.3, [0.1, 1.0, 2.0, 3.0], [1e-5, 2e-5, -1e-5, 5e-6], \
        [0.0] * 4, [3.0] * 4, [0.01, -0.02, 0.0, 0.2]
    qf, vf, mk, R = race_scene("inner", *state)
    elem = race_element("inner", N, mk, R, FILM)
    F, out = assert_balanced(elem, qf, vf)
    loaded = out["load"] > 0
    assert np.all(out["traction"][loaded] * np.array(state[7])[loaded] <= 0)
    assert np.all(np.abs(out["traction"][loaded]) < 0.08 * out["load"][loaded])


def test_ehl_traction_curve_shape():
    """Odd, linear at small slip, rising monotonically to the limiting-shear plateau
    Σ w_k τ_L(p_k) / p̄ (isothermal Bair–Winer: no thermal drop after the maximum)."""
    from mbd.elements import ehl
    v = np.concatenate([[1e-6, 2e-6], np.logspace(-4, 1, 60)])
    mu = _film_mu(FILM, v)
    np.testing.assert_allclose(_film_mu(FILM, -v), -mu, rtol=1e-14)
    assert mu[1] / mu[0] == pytest.approx(2.0, rel=1e-6)                  # linear at low slip
    # its slope: the Maxwell film's Newtonian shear, Σ w_k η_eff(p_k) / (h_c p̄), 1/η_eff = e^(−α p)/η₀ + u/(G_e b),
    # h_c the thermal film: Pan & Hamrock's times Murch & Wilson's 3.94/(3.94 + L^0.62), L = β η₀ u²/k
    u, w, R = np.hypot(5.0, FILM.u_reg), 2000.0 / LR, 3e-3
    p_max, b = ehl.hertz_peak_pressure(w, R, FILM.E_red), ehl.hertz_half_width(w, R, FILM.E_red)
    eta_eff = 1.0 / (np.exp(-FILM.alpha_p * p_max * ehl.STRIP_NODES) / FILM.eta0 + u / (FILM.G_e * b))
    phi = 3.94 / (3.94 + (FILM.beta * FILM.eta0 * u ** 2 / FILM.k_oil) ** 0.62)
    assert 0.91 < phi < 0.93                                              # L ≈ 0.18 at 5 m/s
    h_c = phi * ehl.film_central(u, w, R, FILM.eta0, FILM.alpha_p, FILM.E_red)
    slope = np.sum(ehl.STRIP_WEIGHTS * eta_eff) / (h_c * 0.25 * np.pi * p_max)
    assert mu[0] / v[0] == pytest.approx(slope, rel=1e-6)
    # the isothermal law (β = 0) shears the thicker film: its low-slip slope is φ_T times the thermal one's
    iso = dataclasses.replace(FILM, beta=0.0)
    assert _film_mu(iso, 1e-6) == pytest.approx(phi * mu[0], rel=1e-9)
    assert np.all(np.diff(mu) >= 0) and np.all(np.diff(mu[:8]) > 0)    # rises, then saturates (tanh = 1)
    w = 2000.0 / LR
    p_max = ehl.hertz_peak_pressure(w, 3e-3, FILM.E_red)
    plateau = np.sum(ehl.STRIP_WEIGHTS * (FILM.tau_L0 + FILM.gamma_L * p_max * ehl.STRIP_NODES)) / (0.25 * np.pi * p_max)
    assert mu[-1] == pytest.approx(plateau, rel=1e-6) and 0.06 < plateau < 0.08
    # a thicker oil builds a thicker film: where the film's elasticity limits the shear (η_eff ≈ G_e b/u,
    # independent of η at these pressures) the same slip shears it less; the plateau is the limiting shear
    thick = dataclasses.replace(FILM, eta0=0.1)
    assert _film_mu(thick, 1e-3) < _film_mu(FILM, 1e-3)
    assert _film_mu(thick, 10.0) == pytest.approx(_film_mu(FILM, 10.0), rel=1e-9)
