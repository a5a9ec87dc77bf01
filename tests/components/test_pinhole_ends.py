"""A pinhole given at its pin's two ends (errors.pinhole_ends, docs/model.md §11.1): the radial and tangential errors
in the shaft-side plate (ζ = +L_c/2) and in the far plate (ζ = −L_c/2), L_c = gears.carrier_plate_span.

Truths: hand values of the straight line through two points (its mid-point and its slope; 20 µm over 50 mm is
4e-4 rad = 1.375'), the pin axis's direction in the carrier's axes from the two end points, and the equivalent entries
of the other form (errors.pinhole + errors.pin_slope written by hand), whose machine must have the same static state."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from components import faults
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.params import PinholeEndsSI
from components.presets import reference_dpgt
from components.static import snapshot_times, solve_snapshots
from components.units import ParameterError

UM = 1e-6
ARCMIN = math.pi / 180 / 60


def _ends(planet="a1", rs=0.0, ts=0.0, rf=0.0, tf=0.0):
    return PinholeEndsSI(planet=planet, radial_shaft_plate=rs * UM, tangential_shaft_plate=ts * UM,
                         radial_far_plate=rf * UM, tangential_far_plate=tf * UM)


@pytest.mark.parametrize("ends, mean, slope_arcmin, direction_deg", [
    # +10 / −10 µm radially over 50 mm: no mean error, 20 µm / 50 mm = 4e-4 rad = 1.37510' radially outwards at +ζ
    ((10, 0, -10, 0), (0, 0), 1.3750987, 0.0),
    # the far end out by 10 µm: the axis leans inwards towards the shaft side (direction 180°), mean 5 µm out
    ((0, 0, 10, 0), (5, 0), 0.6875494, 180.0),
    # tangential only: +0 / −8 µm → 8 µm / 50 mm = 1.6e-4 rad with the planet angle (90°); both ends 6 µm out
    ((6, 0, 6, -8), (6, -4), 0.5500395, 90.0),
    # a 3-4-5 triangle: 6 µm radial and 8 µm tangential difference, 10 µm / 50 mm = 2e-4 rad at atan(4/3) = 53.130°
    ((3, 4, -3, -4), (0, 0), 0.6875494, 53.130102),
    # equal ends: a pure position error, no slope
    ((7, -2, 7, -2), (7, -2), 0.0, 0.0),
])
def test_the_ends_are_the_mean_position_and_the_slope_with_direction(ends, mean, slope_arcmin, direction_deg):
    hole, slope = faults.pinhole_from_ends(_ends("b2", *ends), 0.050)
    assert hole.planet == slope.planet == "b2"
    assert hole.radial == pytest.approx(mean[0] * UM, abs=1e-18) and hole.tangential == pytest.approx(mean[1] * UM,
                                                                                                       abs=1e-18)
    assert slope.slope / ARCMIN == pytest.approx(slope_arcmin, rel=1e-7, abs=1e-12)
    if slope_arcmin:
        assert math.degrees(slope.direction) == pytest.approx(direction_deg, abs=1e-6)


def test_the_pin_axis_is_the_line_through_its_two_ends_in_the_carriers_axes():
    """The built machine's pin slope and pin centre (components.faults.pin_slope, pin_position) against the line
    through the two end points placed in the carrier's axes by the planet's angle ψ: its mid-point and its direction
    (P_shaft − P_far)/L_c."""
    p = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced", "errors.pinhole_ends": [
        {"planet": "b2", "radial_shaft_plate": "15 um", "tangential_shaft_plate": "-6 um", "radial_far_plate": "5 um",
         "tangential_far_plate": "2 um"}]})
    si = p.si()
    L, psi = si.gears.carrier_plate_span, si.layout.psi_b[1]
    e_r, e_t = np.array([math.cos(psi), math.sin(psi)]), np.array([-math.sin(psi), math.cos(psi)])
    c = np.asarray(si.layout.centres_b[1], float)
    shaft, far = c + 15 * UM * e_r - 6 * UM * e_t, c + 5 * UM * e_r + 2 * UM * e_t
    np.testing.assert_allclose(faults.pin_position(si, "b2", c), 0.5 * (shaft + far), rtol=0, atol=1e-15)
    # the ends' difference carries the round-off of |c| ≈ 0.06 m (a few 1e-18 m) into the wanted slope: 1e-15 rad
    np.testing.assert_allclose(faults.pin_slope(si, "b2", c), (shaft - far) / L, rtol=0,
                               atol=4 * np.finfo(float).eps * np.abs(c).max() / L)
    np.testing.assert_array_equal(faults.pin_slope(si, "a2", si.layout.centres_a[1]), 0.0)


def _build(overrides):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_dpgt(with_overrides(reference_dpgt(3, "forward"), overrides))


def test_both_forms_for_one_planet_are_refused_in_one_line():
    ends = [{"planet": "a1", "radial_shaft_plate": "5 um", "tangential_shaft_plate": "0 um",
             "radial_far_plate": "-5 um", "tangential_far_plate": "0 um"}]
    for other in ({"errors.pinhole": [{"planet": "a1", "radial": "3 um", "tangential": "0 um"}]},
                  {"errors.pin_slope": [{"planet": "a1", "slope": "1 arcmin", "direction": "0 deg"}]}):
        with pytest.raises(ParameterError, match=r"^errors\.pinhole_ends\[0\]: a1's pinhole is given at its two ends "
                                                 r"and also by errors\.pinhole or errors\.pin_slope") as e:
            _build({"bearing.model": "sliced", "errors.pinhole_ends": ends, **other})
        assert "\n" not in str(e.value)
    with pytest.raises(ParameterError, match=r"^errors\.pinhole_ends: at most one entry per planet"):
        _build({"bearing.model": "sliced", "errors.pinhole_ends": ends * 2})
    # another planet's pinhole in the other form is fine
    _build({"bearing.model": "sliced", "errors.pinhole_ends": ends,
            "errors.pinhole": [{"planet": "b1", "radial": "3 um", "tangential": "0 um"}]})


def test_the_planar_model_takes_equal_ends_as_a_position_error_and_refuses_a_slope():
    equal = [{"planet": "a2", "radial_shaft_plate": "8 um", "tangential_shaft_plate": "-3 um",
              "radial_far_plate": "8 um", "tangential_far_plate": "-3 um"}]
    a = _build({"errors.pinhole_ends": equal})
    b = _build({"errors.pinhole": [{"planet": "a2", "radial": "8 um", "tangential": "-3 um"}]})
    np.testing.assert_array_equal(a.q0, b.q0)
    sloped = [dict(equal[0], radial_far_plate="4 um")]
    with pytest.raises(ParameterError, match=r"^errors\.pinhole_ends: a pinhole's two ends differ, so its pin slopes: "
                                             r"a pin slope is seen only by the sliced bearing model"):
        _build({"errors.pinhole_ends": sloped})


def test_a_sliced_machines_static_state_is_that_of_the_equivalent_position_error_and_pin_slope():
    """b2's pinhole 15/−6 µm (shaft-side plate) and 5/+2 µm (far plate), L_c = 40 mm (the reference carrier): the
    mean (10, −2) µm and the slope ((15 − 5), (−6 − 2)) µm / 40 mm = (2.5e-4, −2e-4) rad, i.e. 3.2016e-4 rad at
    atan2(−2, 2.5) = −38.66°, written by hand in the other form: the same static solution of the loaded machine
    (condition 3), its planets and rollers tilted by the slope."""
    ends = {"bearing.model": "sliced", "errors.pinhole_ends": [
        {"planet": "b2", "radial_shaft_plate": "15 um", "tangential_shaft_plate": "-6 um", "radial_far_plate": "5 um",
         "tangential_far_plate": "2 um"}]}
    gamma, chi = math.hypot(2.5e-4, -2e-4), math.degrees(math.atan2(-2.0, 2.5))
    other = {"bearing.model": "sliced",
             "errors.pinhole": [{"planet": "b2", "radial": "10 um", "tangential": "-2 um"}],
             "errors.pin_slope": [{"planet": "b2", "slope": f"{gamma!r} rad", "direction": f"{chi!r} deg"}]}
    sa, sb = _build(ends), _build(other)
    np.testing.assert_allclose(sa.q0, sb.q0, rtol=0, atol=1e-15)
    xa, xb = (solve_snapshots(s, snapshot_times(s, 1))[0] for s in (sa, sb))
    m = sa.model
    tilts = m.free >= m.n_body_coords
    assert np.abs(xb.q[tilts]).max() > 1e-5                  # the slope is felt: planets and rollers tilt
    np.testing.assert_allclose(xa.q, xb.q, rtol=0, atol=1e-12 * max(1.0, np.abs(xb.q).max()))
    np.testing.assert_allclose(xa.q[tilts], xb.q[tilts], rtol=0, atol=1e-9 * np.abs(xb.q[tilts]).max())
