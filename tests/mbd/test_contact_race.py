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

from tests.support.contact import (DR, EHL, FS, K_HZ, LAW, LR, M_ROLLER, N, RCA, R_IN, R_OUT, SETTINGS, TANH,
                                   assert_balanced, assert_jacobians, floats, kcross, power_of, race_element,
                                   race_scene, race_states, rot)


TRACTIONS = {"tanh": TANH, "ehl": EHL}


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl"])
@SETTINGS
@given(data=st.data())
def test_race_jacobian_balance_and_kinematics(kind, law, data):
    state = data.draw(race_states(kind))
    qf, vf, mk, R = race_scene(kind, *state)
    elem = race_element(kind, N, mk, R, TRACTIONS[law])
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
