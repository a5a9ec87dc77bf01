"""Roller slip from a run's recording (components.skid, components.bearing.roller_slip_pct) against synthetic
recordings whose rollers spin at known fractions of the pure-rolling spin Ω(d_m + D)/(2D) (a roller rolling on a
pin at rest and on a bore turning at Ω: its centre at Ω R_o/(R_i + R_o), its spin Ω R_o/D, R_o = (d_m + D)/2)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

from components.bearing import roller_slip_pct
from components.presets import reference_dpgt
from components.skid import roller_slip_zones

B = reference_dpgt(3, "forward").si().bearing
OMEGA = 300.0                      # the planet's speed relative to the carrier [rad/s]
W_EPI = OMEGA * (B.pitch_diameter + B.roller_diameter) / (2.0 * B.roller_diameter)


@pytest.mark.parametrize("planet, roller, want", [(OMEGA, W_EPI, 0.0), (OMEGA, 0.75 * W_EPI, 25.0),
                                                   (-OMEGA, -0.5 * W_EPI, 50.0), (OMEGA, 0.0, 100.0)])
def test_roller_slip_is_the_spin_short_of_the_rolling_spin(planet, roller, want):
    assert roller_slip_pct(B, roller, planet) == pytest.approx(want, abs=1e-9)


def recording(carrier_speed: float, n: int = 720, slip_out: float = 25.0):
    """One inner bearing on planet a1 (at 90° on the carrier) with two rollers 180° apart orbiting at the cage's
    rolling speed; a roller is loaded on the pin at 0°–90° from the planet's radial direction and rolls there, and
    spins ``slip_out`` % short of rolling elsewhere. Speeds in a frame turning at ``carrier_speed`` relative to R."""
    t = (np.arange(n) + 0.25) / n          # no sample on a bin edge (round-off would place it either side)
    wm = OMEGA * (B.pitch_diameter + B.roller_diameter) / (2.0 * B.pitch_diameter)     # the cage's rolling speed
    psi = np.stack([2 * math.pi * t * 3, 2 * math.pi * t * 3 + math.pi], axis=1) % (2 * math.pi)   # from the radial
    loaded = psi < math.pi / 2
    spin = np.where(loaded, W_EPI, (1 - slip_out / 100) * W_EPI) + carrier_speed
    names = ["carrier", "a1", "a1.pb.roller0", "a1.pb.roller1"]
    w = np.column_stack([np.full(n, carrier_speed), np.full(n, OMEGA + carrier_speed), spin])
    theta_c = carrier_speed * t
    pos = np.zeros((n, 4, 2))
    pos[:, 1] = 0.1 * np.column_stack([np.cos(math.pi / 2 + theta_c), np.sin(math.pi / 2 + theta_c)])
    angle = np.zeros((n, 4))
    angle[:, 0] = theta_c
    bearings = [{"name": "a1.pb", "kind": "inner", "planet": "a1", "type": "rollers",
                 "rollers": names[2:], "race_inner": [0, 2], "race_outer": [0, 2]}]
    ds = xr.Dataset({"motion.angular_velocity": (("time", "motion.body"), w),
                     "motion.position": (("time", "motion.body", "axis"), pos),
                     "motion.angle": (("time", "motion.body"), angle),
                     "race_inner.load": (("time", "race_inner.instance"), np.where(loaded, 500.0, 0.0)),
                     "race_inner.angle": (("time", "race_inner.instance"), psi + math.pi / 2)},
                    coords={"motion.body": names}, attrs={"bearings": json.dumps(bearings)})
    return ds


@pytest.mark.parametrize("carrier_speed", [0.0, 104.7])
def test_zones_entry_and_angles_of_a_synthetic_recording(carrier_speed):
    """The slip by angle 0 in the bins of 0°–90° from the planet's radial direction (the load zone) and 25 %
    elsewhere, loaded there only — the same whether the recording's frame turns with the carrier or not."""
    z = roller_slip_zones(recording(carrier_speed), B, bins=8)["inner"]
    np.testing.assert_allclose(z["angle_deg"], 22.5 + 45.0 * np.arange(8))
    np.testing.assert_allclose(z["slip_by_angle_pct"], [0, 0, 25, 25, 25, 25, 25, 25], atol=1e-9)
    np.testing.assert_allclose(z["loaded_by_angle"], [1, 1, 0, 0, 0, 0, 0, 0], atol=1e-12)
