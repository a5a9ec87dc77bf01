"""The bearing-level misalignment study (scenarios.bearing_misalignment, docs/model.md §8.8): what it writes is the
sliced bearing's life under the given load, relative to the aligned bearing, for every case it lists."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from components.params import with_overrides
from components.presets import reference_bearing
from components.sliced_bearing import ARCMIN, SlicedBearing, sliced_bearing_life
from scenarios import bearing_misalignment


def test_the_study_writes_the_sliced_lives_relative_to_aligned(tmp_path, capsys):
    out = tmp_path / "bm"
    code = bearing_misalignment.main(["--load", "11 kN", "--conditions", "3", "--gammas", "4", "--profiles",
                                      "straight,iso_16281", "--positions", "2", "--out", str(out)])
    assert code == 0
    rows = list(csv.DictReader((out / "misalignment.csv").open(encoding="utf-8")))
    # 2 directions x 2 planets x 2 profiles x 2 slopes x (0 and 4 arcmin)
    assert len(rows) == 32
    assert {r["gamma_arcmin"] for r in rows} == {"0.0", "4.0"}
    assert all(float(r["life_relative"]) == 1.0 for r in rows if r["gamma_arcmin"] == "0.0")
    b = with_overrides(reference_bearing(), {"profile.shape": "iso_16281"}).si()
    sb = SlicedBearing(b)
    for slope in ("radial", "tangential"):
        lives = [sliced_bearing_life(sb.states(np.array([11e3, 0.0]), g * ARCMIN, slope, positions=2), b)
                 for g in (0.0, 4.0)]
        mine = [r for r in rows if r["profile"] == "iso_16281" and r["slope"] == slope and r["gamma_arcmin"] == "4.0"]
        assert len(mine) == 4
        for r in mine:
            assert float(r["life_Mrev"]) == pytest.approx(lives[1], rel=1e-12)
            assert float(r["life_relative"]) == pytest.approx(lives[1] / lives[0], rel=1e-12)
    assert len(json.loads((out / "loads.json").read_text(encoding="utf-8"))) == 4
    printed = capsys.readouterr().out
    assert "edge p ratio 4′" in printed and (out / "misalignment.md").read_text(encoding="utf-8").strip() in printed
