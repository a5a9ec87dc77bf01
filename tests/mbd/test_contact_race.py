"""The roller–raceway contact (RaceContact, docs/model.md §8.1): exact Jacobians, Newton's third law and the
element's kinematics on random states with both traction laws; Palmgren's load–deflection law and the bearing's
constant; damping that never pulls; zero traction at pure rolling in epicyclic kinematics, and a traction that
opposes any extra slip and only dissipates.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from mbd.element import evaluate
from mbd.elements.contact import RaceContact

from scipy.integrate import solve_ivp

from tests.support.contact import (DR, EHL, FS, K_HZ, LAW, LR, M_ROLLER, N, RCA, R_IN, R_OUT, SETTINGS, TANH,
                                   assert_balanced, assert_jacobians, floats, kcross, power_of, race_element,
                                   race_scene, race_states, rot)


TRACTIONS = {"tanh": TANH, "ehl": EHL}


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl"])
@pytest.mark.parametrize("ramp", [0.0, 1e-5])
@SETTINGS
@given(data=st.data())
def test_race_jacobian_balance_and_kinematics(kind, law, ramp, data):
    """With a damping ramp of 10 µm, compressions of 2–30 µm lie on its smoothstep and past it."""
    state = data.draw(race_states(kind))
    qf, vf, mk, R = race_scene(kind, *state)
    elem = race_element(kind, N, mk, R, TRACTIONS[law], damping_ramp=ramp)
    assert_jacobians(elem, qf, vf)
    F, out = assert_balanced(elem, qf, vf)
    deltas, slips = np.array(state[4]), np.array(state[7])
    # the element's kinematics agree with the scene's construction
    np.testing.assert_allclose(out["deflection"], deltas, rtol=0, atol=1e-15)
    np.testing.assert_allclose(out["slip_velocity"], slips, rtol=0, atol=1e-9)
    np.testing.assert_allclose(np.cos(out["angle"] - np.array(state[3])), 1.0, atol=1e-12)
    touch = deltas > 0
    assert np.all(out["load"][touch] > 0) and np.all(out["load"][~touch] == 0) and np.all(out["load"] >= 0)
    assert np.all(F[~touch] == 0)
    # traction opposes sliding (and vanishes out of contact)
    assert np.all(out["traction"] * out["slip_velocity"] <= 0)
    assert np.all(out["traction"][~touch] == 0)
    if law == "tanh":
        assert np.all(np.abs(out["traction"]) <= 0.08 * out["load"] * (1 + 1e-12))


def test_palmgren_constant_for_the_bearing():
    """K = 8.06e4·l^(8/9) N/mm^(10/9) with l = 9 mm is 1.22e9 N/m^(10/9) (docs/parameters.md), and it is the
    inverse of Palmgren's δ[mm] = 3.84e-5 Q^0.9 / l^0.8."""
    l_mm = LR * 1e3
    K_mm = 8.06e4 * l_mm ** (8 / 9)                 # Q[N] = K_mm · δ[mm]^(10/9)
    K_si = K_mm * (1e3) ** (10 / 9)                 # δ[mm] = 1e3 δ[m]
    assert round(K_si / 1e9, 2) == 1.22
    Q = 1500.0
    d_mm = 3.84e-5 * Q ** 0.9 / l_mm ** 0.8
    assert K_mm * d_mm ** (10 / 9) == pytest.approx(Q, rel=1e-3)
    # the element with this K reproduces Palmgren's deflection law
    for kind in ("inner", "outer"):
        qf, vf, mk, R = race_scene(kind, (0, 0, 0.3), (0, 0, 0), 0.2, [1.0], [d_mm * 1e-3], [0], [0], [0])
        elem = RaceContact("r", [1], 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_si, m_roller=M_ROLLER, **LAW)
        F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
        assert out["load"][0] == pytest.approx(Q, rel=1e-3)


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_race_static_load_is_hertz_palmgren(kind):
    deltas = [1e-7, 1e-6, 5e-6, 2e-5]
    qf, vf, mk, R = race_scene(kind, (1e-4, -2e-4, 0.8), (0, 0, 0), -0.4, [0.1, 1.2, 2.5, -2.0], deltas,
                               [0] * 4, [0] * 4, [0] * 4)
    elem = race_element(kind, 4, mk, R)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(out["load"], K_HZ * np.array(deltas) ** (10 / 9), rtol=1e-9)
    # the roller is pushed out of the raceway: outward from the pin, inward from the bore
    ang = 0.8 + np.array([0.1, 1.2, 2.5, -2.0])
    radial = F[:, 0] * np.cos(ang) + F[:, 1] * np.sin(ang)
    np.testing.assert_allclose(radial, (1 if kind == "inner" else -1) * out["load"], rtol=1e-12)
    np.testing.assert_allclose(out["traction"], 0.0, atol=0)


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_race_damping_never_pulls(kind):
    deltas = [1e-5, 1e-5, 1e-5, -1e-5]
    sep = [-0.01, 0.01, -50.0, -50.0]   # δ̇: v_normal is ρ̇, and δ̇ = −ρ̇ (inner), +ρ̇ (outer)
    vn = sep if kind == "outer" else [-s for s in sep]
    qf, vf, mk, R = race_scene(kind, (0, 0, 0), (0, 0, 0), 0.0, [0.3, 0.3, 0.3, 0.3], deltas, vn, [0] * 4,
                               [0.5] * 4)
    elem = race_element(kind, 4, mk, R)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    # the first two rollers: Q = Kδ^p + c(δ)δ̇ with c(δ) = 2ζ sqrt(m dQ/dδ)
    p = 10 / 9
    c = 2 * 0.05 * np.sqrt(M_ROLLER * p * K_HZ * 1e-5 ** (p - 1))
    np.testing.assert_allclose(out["load"][:2], K_HZ * 1e-5 ** p + c * np.array(sep[:2]), rtol=1e-9)
    assert out["load"][0] < K_HZ * 1e-5 ** p < out["load"][1]
    # fast separation: the damper would pull — the load is clipped to zero, so is the traction
    assert out["load"][2] == 0 and out["traction"][2] == 0 and np.all(F[2] == 0)
    # out of contact: nothing, whatever the velocity
    assert out["load"][3] == 0 and np.all(F[3] == 0)


@pytest.mark.parametrize("law", ["tanh", "ehl"])
@SETTINGS
@given(w_carrier=floats(-500, 500), w_cage=floats(-500, 500), w_planet=floats(-1500, 1500),
       vel=st.tuples(floats(-40, 40), floats(-40, 40)), theta=floats(-np.pi, np.pi),
       orbit=floats(-np.pi, np.pi), delta=floats(1e-6, 2e-5), dspin=floats(1.0, 200.0))
def test_traction_vanishes_for_pure_rolling(law, w_carrier, w_cage, w_planet, vel, theta, orbit, delta, dspin):
    """Epicyclic rolling kinematics (pin on a moving carrier, roller orbiting at the cage speed):
    the roller spin from the rolling condition gives zero slip and zero traction on both raceways;
    any extra spin gives a traction that opposes the slip and dissipates power."""
    a = DR / 2 - delta                                   # roller centre to contact point
    for kind, w_race, R in (("inner", w_carrier, R_IN), ("outer", w_planet, R_OUT)):
        mk = np.array([RCA, 0.0]) if kind == "inner" else np.zeros(2)
        pose = np.array([vel[0] * 1e-4, vel[1] * 1e-4, theta])
        vb = np.array([vel[0], vel[1], w_race])
        rc = rot(theta) @ mk
        c, vc = pose[:2] + rc, vb[:2] + kcross(w_race, rc)
        e = np.array([np.cos(orbit), np.sin(orbit)])
        rho = R + DR / 2 - delta if kind == "inner" else R - DR / 2 + delta
        p, pdot = c + rho * e, vc + kcross(w_cage, rho * e)
        if kind == "inner":
            w_roll = w_cage - (w_race - w_cage) * R / a
        else:
            w_roll = w_cage + (w_race - w_cage) * R / a
        qf = np.concatenate([pose, [p[0], p[1], 0.0], [p[0], p[1], 0.0]])
        vf = np.concatenate([vb, [pdot[0], pdot[1], w_roll], [pdot[0], pdot[1], w_roll + dspin]])
        elem = race_element(kind, 2, mk, R, TRACTIONS[law])
        F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
        assert out["load"][0] == pytest.approx(K_HZ * delta ** (10 / 9), rel=1e-9)
        speed_scale = abs(w_race) * R + abs(w_cage) * R + np.hypot(*vel) + abs(w_roll) * a
        assert abs(out["slip_velocity"][0]) <= 1e-12 * speed_scale
        assert abs(out["traction"][0]) <= 1e-9 * out["load"][0]
        # extra spin: slip = ±a·Δω, traction opposes it, and the element only dissipates (δ̇ = 0 here)
        assert out["slip_velocity"][1] == pytest.approx((-a if kind == "inner" else a) * dspin, rel=1e-6)
        assert out["traction"][1] * out["slip_velocity"][1] < 0
        P = power_of(F, vf, elem)
        # the floor: at denormal speeds (5e-324 rad/s) the power is a denormal round-off, not zero
        np.testing.assert_allclose(P, out["traction"] * out["slip_velocity"], rtol=1e-6,
                                   atol=1e-9 * out["load"][0] * speed_scale + 1e-300)


# ------------------------------------------------------------------------- the damping share at first touch
P_HZ, ZETA = 10.0 / 9.0, 0.05


def _share(x):
    """The quintic smoothstep written out: 10x³ − 15x⁴ + 6x⁵ on [0, 1], 1 beyond (docs/model.md §7, §8.1)."""
    x = np.clip(x, 0.0, 1.0)
    return 10.0 * x ** 3 - 15.0 * x ** 4 + 6.0 * x ** 5


def _closed_form(delta, delta_dot, ramp):
    """Q = K δ^p + S(δ/δ_c) 2ζ sqrt(m p K δ^(p−1)) δ̇ for δ > 0, clipped at ≥ 0 (S = 1 for δ_c = 0)."""
    delta, delta_dot = np.asarray(delta, float), np.asarray(delta_dot, float)
    d = np.where(delta > 0.0, delta, 1.0)
    share = _share(d / ramp) if ramp > 0.0 else 1.0
    q = K_HZ * d ** P_HZ + share * 2.0 * ZETA * np.sqrt(M_ROLLER * P_HZ * K_HZ * d ** (P_HZ - 1.0)) * delta_dot
    return np.where((delta > 0.0) & (q > 0.0), q, 0.0)


def _loads(kind, deltas, rates, ramp):
    """The element's loads at compressions ``deltas`` closing at ``rates`` (δ̇ > 0: the roller comes in)."""
    n = len(deltas)
    vn = [-r if kind == "inner" else r for r in rates]          # v_normal is ρ̇: δ̇ = −ρ̇ (inner), +ρ̇ (outer)
    qf, vf, mk, R = race_scene(kind, (0, 0, 0), (0, 0, 0), 0.0, list(np.linspace(-2.0, 2.0, n)), list(deltas), vn,
                               [0.0] * n, [0.0] * n)
    elem = race_element(kind, n, mk, R, damping_ramp=ramp)
    _, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    np.testing.assert_allclose(out["deflection"], deltas, rtol=1e-6, atol=1e-15)     # the scene's geometry, to round-off
    return out["load"], out["deflection"]


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_race_damping_share_is_the_smoothstep_and_the_law_past_the_ramp(kind):
    """Over the first δ_c of compression the damping is S(δ/δ_c) of the law's (S = 10x³ − 15x⁴ + 6x⁵, 1/2 at
    δ_c/2); from δ_c on the load is the law without a ramp; at first touch the load is continuous (the damping share
    vanishes as x³) where the law without a ramp jumps by most of its damping force at once."""
    ramp, rate = 0.5e-6, 0.02
    x = np.array([1e-5, 0.1, 0.25, 0.5, 0.75, 0.999, 1.0, 2.0, 40.0])
    deltas = x * ramp
    got, d = _loads(kind, deltas, [rate] * x.size, ramp)          # d: the element's δ (the scene's to round-off)
    np.testing.assert_allclose(got, _closed_form(d, rate, ramp), rtol=1e-9)
    elastic = K_HZ * d ** P_HZ
    damping = _closed_form(d, rate, 0.0) - elastic
    np.testing.assert_allclose((got - elastic)[3], 0.5 * damping[3], rtol=1e-6)              # S(1/2) = 1/2
    past = x >= 1.0
    np.testing.assert_array_equal(got[past], _loads(kind, deltas, [rate] * x.size, 0.0)[0][past])   # same states
    # first touch: with the ramp the load is the Hertz load to 1e-12 of the damping the law without it adds at once
    assert abs(got[0] - elastic[0]) < 1e-12 * damping[0]
    assert damping[0] > 0.4 * damping[-1] and damping[0] > 100.0 * elastic[0]     # the jump the ramp removes


def _impact(law, v0, t_end=60e-6):
    """A roller (mass m) falling onto a rigid raceway at v0: (δ, δ̇) under m δ̈ = −law(δ, δ̇) from touch until it
    leaves; returns the coefficient of restitution |δ̇_out| / v0."""
    def rhs(t, y):
        return [y[1], -law(y[0], y[1]) / M_ROLLER]

    def leaves(t, y):
        return y[0] + 1e-15
    leaves.terminal, leaves.direction = True, -1
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, v0], method="DOP853", rtol=1e-11, atol=[1e-16, 1e-12], events=leaves,
                    max_step=2e-8)
    assert sol.status == 1, "the roller must leave the raceway"
    return -sol.y_events[0][0][1] / v0


@pytest.mark.parametrize("v0, ramp", [(0.02, 0.15e-6), (0.02, 0.5e-6), (0.3, 0.15e-6)])
def test_race_impact_dissipates_the_closed_form_laws_energy(v0, ramp):
    """A roller's impact on its raceway: the energy the element's law dissipates (1 − e², e its coefficient of
    restitution) is that of the closed form's ODE (to 1e-6 of itself: the element's δ carries the scene's round-off of
    1e-17 m), with the ramp less than without it (0.02 m/s, ≈ 0.1 µm deep: 4.4 % of the energy with δ_c = 0.15 µm,
    0.2 % with 0.5 µm, against 26.8 % at any speed without a ramp; 0.3 m/s, ≈ 1 µm deep: 25.6 %)."""
    def element(ramp_):
        def law(delta, delta_dot):
            return float(_loads("inner", [delta], [delta_dot], ramp_)[0][0]) if delta > 0.0 else 0.0
        return law

    def closed(ramp_):
        return lambda delta, delta_dot: float(_closed_form(delta, delta_dot, ramp_)) if delta > 0.0 else 0.0

    e_ramp = _impact(element(ramp), v0)
    e_ref = _impact(closed(ramp), v0)
    assert 1.0 - e_ramp ** 2 == pytest.approx(1.0 - e_ref ** 2, rel=1e-6)
    e_jump = _impact(closed(0.0), v0)
    assert 0.0 < 1.0 - e_ramp ** 2 < 1.0 - e_jump ** 2
    # without a ramp the dissipated share is the same at any speed (the law is self-similar in v0): Kelvin–Voigt's
    assert 1.0 - e_jump ** 2 == pytest.approx(1.0 - _impact(closed(0.0), 10.0 * v0) ** 2, rel=1e-6)
    assert 1.0 - e_jump ** 2 == pytest.approx(1.0 - _impact(element(0.0), v0) ** 2, rel=1e-6)
