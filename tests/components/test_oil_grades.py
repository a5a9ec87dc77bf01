"""Every ISO VG grade from VG 10 to VG 1500 is a lubricant the study takes: its Walther line passes
through the grade at 40 °C (ISO 3448's definition) and its typical 100 °C value, and thicker grades are thicker at
the bearings' 60 °C."""
from __future__ import annotations

import pytest

from components.lubrication import walther_viscosity
from components.params import with_overrides
from components.presets import OIL_GRADES, oil_grade, reference_dpgt
from scenarios import lubricant_study


def test_every_grade_is_its_own_viscosity_at_40_degC_and_thicker_grades_are_thicker():
    eta = []
    for g in OIL_GRADES:
        v = {k.split(".")[1]: x for k, x in oil_grade(g).items()}
        lub = with_overrides(reference_dpgt(), {k: x.value for k, x in oil_grade(g).items()}).si().lubricant
        assert walther_viscosity(lub.viscosity_40, lub.viscosity_100, 313.15) == pytest.approx(int(g[2:]) * 1e-6, rel=1e-9)
        assert v["viscosity_40"].source.tag == "assumed" and v["viscosity_100"].source.tag == "assumed"
        eta.append(lub.oil_viscosity)
    assert eta == sorted(eta) and len(OIL_GRADES) == 14


def test_the_study_takes_any_grade_and_keeps_its_default_span(tmp_path):
    a = lubricant_study.parse_args(["--oil", "VG46,VG220", "--conditions", "3", "--out", str(tmp_path)])
    assert sorted(lubricant_study.lubricants(a)) == ["VG220", "VG46"]
    a = lubricant_study.parse_args(["--conditions", "3", "--out", str(tmp_path)])
    assert list(lubricant_study.lubricants(a)) == ["VG32", "VG68", "VG150"]
