"""Physically impossible error sizes are refused like the clearance check refuses a play the gears cannot take
, naming the entry and the limit; possible ones pass."""
from __future__ import annotations

import pytest

from components import faults
from components.params import with_overrides
from components.presets import reference_dpgt
from components.units import ParameterError

SPALL = {"planet": "b1", "position": "0 deg", "width": "2 mm", "edge": "0.5 mm"}


@pytest.mark.parametrize("overrides, message", [
    # the planet rim under the bore: root radius 32.25 mm − bore 23.26 mm = 8.99 mm
    ({"errors.spall": [{**SPALL, "raceway": "outer", "depth": "9 mm"}]}, "planet's rim under the bore, 8.99 mm"),
    # the solid pin: radius (39 − 7.5)/2 = 15.75 mm
    ({"errors.spall": [{**SPALL, "raceway": "inner", "depth": "16 mm"}]}, "the pin's radius, 15.8 mm"),
    # 1 mm moves b1's inner–outer centre distance by 1 mm + the play 2 × 10 µm: the tip–root gap (0.75 mm) is gone
    ({"errors.pinhole": [{"planet": "b1", "radial": "0 um", "tangential": "1 mm"}]},
     "inner-outer centre distance (with the bearing's play) by up to 1.020 mm, at which the teeth strike"),
    # two entries on one planet add up
    ({"errors.pinhole": [{"planet": "a1", "radial": "0.4 mm", "tangential": "0 um"},
                         {"planet": "a1", "radial": "0.4 mm", "tangential": "0 um"}]}, "moves a1 by 800 um"),
])
def test_impossible_error_sizes_are_refused(overrides, message):
    with pytest.raises(ParameterError) as e:
        faults.check_errors(with_overrides(reference_dpgt(), overrides).si())
    assert message in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_possible_error_sizes_pass():
    ok = {"errors.spall": [{**SPALL, "raceway": "outer", "depth": "0.5 mm"}],
          "errors.pinhole": [{"planet": "b1", "radial": "0 um", "tangential": "0.3 mm"}]}
    faults.check_errors(with_overrides(reference_dpgt(), ok).si())
