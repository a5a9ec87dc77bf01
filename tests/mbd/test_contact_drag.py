"""Lubricant drag on the rollers (LubricantDrag, docs/model.md §8.7): exact Jacobians, balance, magnitude
(1/8) C_d ρ D l (d_m Ω_m)² and direction against the orbit relative to the carrier on random states; no drag and
an exactly zero Jacobian at zero relative orbit; the sign of the drag either way. The viscous churning law: the orbit
drag with White's C_D(Re) and the spin's Couette moment in closed form, exact Jacobians, balance, dissipation.
"""
from __future__ import annotations

import numpy as np
from hypothesis import given

from mbd.element import evaluate

from tests.support.contact import (C_D, DM, DR, DRAG_COEF, FS, LR, RHO_OIL, SETTINGS, assert_balanced, assert_jacobians,
                                   drag_scene, drag_states, power_of)


@SETTINGS
@given(state=drag_states())
def test_drag_jacobian_balance_magnitude_direction(state):
    qf, vf, elem, omega_m = drag_scene(*state)
    F, out = assert_jacobians(elem, qf, vf)
    assert_balanced(elem, qf, vf)
    np.testing.assert_allclose(out["force"], DRAG_COEF * omega_m * np.abs(omega_m), rtol=1e-9,
                               atol=1e-9 * DRAG_COEF * np.max(omega_m ** 2))
    # the drag on the roller is tangential, of magnitude (1/8) C_d ρ D l (d_m Ω_m)², against the orbit
    # relative to the carrier: it removes power from the relative orbital motion
    fr = F[:, :2]
    np.testing.assert_allclose(np.hypot(fr[:, 0], fr[:, 1]), C_D * RHO_OIL * DR * LR * (DM * omega_m) ** 2 / 8,
                               rtol=1e-9, atol=1e-12)
    assert np.all(F[:, 2] == 0)
    assert np.all(power_of(F, vf, elem) <= 1e-12 * DRAG_COEF * np.max(np.abs(omega_m)) ** 3 * DM)


def test_drag_zero_relative_orbit():
    # the roller orbits exactly with the carrier: no drag, and ∂(Ω|Ω|)/∂Ω = 2|Ω| = 0 exactly
    qf, vf, elem, omega_m = drag_scene((0, 0, 0.2), (1.0, -2.0, 440.0), 0.3, [0.5, 2.0], [0, 1e-5],
                                       [440.0, 440.0], [0.0, 0.05], [100.0, 0.0])
    F, out, Jq, Jv = evaluate(elem, 0.0, FS, qf, vf, None, True)
    assert np.all(np.abs(F) <= 1e-20) and np.all(np.abs(Jq) <= 1e-12) and np.all(np.abs(Jv) <= 1e-12)


def test_drag_opposes_orbit():
    qf, vf, elem, omega_m = drag_scene((0, 0, 0.0), (0, 0, 440.0), 0.0, [0.0, np.pi / 2], [0, 0],
                                       [600.0, 300.0], [0, 0], [0, 0])
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    # roller 0 at angle 0 from the pin orbits faster than the carrier turns: drag along −y
    assert F[0, 1] < 0 and abs(F[0, 0]) < 1e-12 * abs(F[0, 1])
    # roller 1 at angle π/2 (t = (−1, 0)) orbits slower than the carrier: Ω_m < 0, drag −F·t along −x
    assert out["force"][1] < 0 and F[1, 0] < 0 and abs(F[1, 1]) < 1e-12 * abs(F[1, 0])
    np.testing.assert_allclose(out["force"], DRAG_COEF * omega_m * np.abs(omega_m), rtol=1e-12)


ETA_E = 1.3e-3       # [Pa·s] an oil–air mixture's viscosity: 5 % of a VG 68 oil at 60 °C


@SETTINGS
@given(state=drag_states())
def test_viscous_drag_jacobian_balance_and_closed_forms(state):
    """With the mixture's viscosity η_e: the orbit drag is ½ ρ D l v|v| C_D(Re), C_D = C_d + 10 Re^(−2/3) (White's
    cylinder in cross flow), Re = ρ|v|D/η_e, v = (d_m/2)Ω_m; the spin meets the moment of a cylinder turning in
    unbounded viscous fluid, 4π η_e a² l (ω_R − ω_carrier), a = D/2 (Couette, outer radius → ∞); dissipative."""
    qf, vf, elem, omega_m = drag_scene(*state, eta=ETA_E)
    F, out = assert_jacobians(elem, qf, vf)
    assert_balanced(elem, qf, vf)
    v = 0.5 * DM * omega_m
    Re = RHO_OIL * np.abs(v) * DR / ETA_E
    drag = 0.5 * RHO_OIL * DR * LR * v * np.abs(v) * (C_D + 10.0 * Re ** (-2.0 / 3.0))
    np.testing.assert_allclose(out["force"], drag, rtol=1e-9)
    spin_rel = vf[elem.dofs][:, 2] - vf[elem.dofs][:, 5]
    np.testing.assert_allclose(F[:, 2], -4.0 * np.pi * ETA_E * (DR / 2) ** 2 * LR * spin_rel, rtol=1e-12)
    assert np.all(power_of(F, vf, elem) <= 1e-12 * np.abs(F).max() * np.abs(vf).max())


def test_viscous_drag_zero_relative_motion():
    """Roller orbiting and spinning with the carrier: no drag and no moment (to round-off of Ω_m) in
    the orbit; the spin's moment is linear, so its column is −π η_e D² l."""
    qf, vf, elem, _ = drag_scene((0, 0, 0.2), (1.0, -2.0, 440.0), 0.3, [0.5, 2.0], [0, 1e-5], [440.0, 440.0],
                                 [0.0, 0.0], [440.0, 440.0], eta=ETA_E)
    F, out, Jq, Jv = evaluate(elem, 0.0, FS, qf, vf, None, True)
    assert np.all(np.abs(F) <= 1e-18) and np.all(np.abs(out["force"]) <= 1e-18)   # Ω_m at round-off
    c_s = np.pi * ETA_E * DR ** 2 * LR
    np.testing.assert_allclose(Jv[:, 2, 2], -c_s, rtol=1e-12)
    np.testing.assert_allclose(Jv[:, 2, 5], c_s, rtol=1e-12)
