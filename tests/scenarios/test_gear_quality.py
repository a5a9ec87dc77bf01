"""The gear-quality study: its tables against numbers worked by hand, and end to end on a tiny window."""
from __future__ import annotations

import csv
import json

import pytest

from scenarios import gear_quality


def _row(c, d, g, seed, b, load, life, kv=1.2):
    r = {k: 1.0 for k in gear_quality.QUANTITIES}
    r.update(condition=c, direction=d, grade=g, seed=seed, bearing=b, bearing_load_mean_N=load, life_iso16281_h=life,
             bearing_load_max_N=2 * load, roller_max_N=0.4 * load)
    r.update({f"{k}_{m}": kv for m in gear_quality.MESHES for k in gear_quality.MESH_COLUMNS})
    return r


def test_by_grade_takes_mean_range_and_reverse_change_over_the_seeds():
    """Seeds 1000 and 1200 N forward, 1500 and 1500 N reverse: mean 1100 [1000, 1200] and 1500, reverse change
    1500/1100 − 1 = +36.36 %; lives 100 and 50 h forward, 25 h reverse: change 25/75 − 1 = −66.67 %."""
    rows = [_row(3, "forward", 6, 1, "inner", 1000.0, 100.0), _row(3, "forward", 6, 2, "inner", 1200.0, 50.0),
            _row(3, "reverse", 6, 1, "inner", 1500.0, 25.0), _row(3, "reverse", 6, 2, "inner", 1500.0, 25.0),
            _row(3, "forward", None, None, "inner", 1000.0, 100.0), _row(3, "reverse", None, None, "inner", 1400.0, 30.0)]
    g = {(r["direction"], r["grade"]): r for r in gear_quality.by_grade(rows)}
    f = g[("forward", 6)]
    assert (f["bearing_load_mean_N"], f["bearing_load_mean_N_min"], f["bearing_load_mean_N_max"]) == (1100.0, 1000.0, 1200.0)
    assert f["seeds"] == 2 and g[("reverse", 6)]["bearing_load_mean_N"] == 1500.0
    assert f["bearing_load_mean_N_reverse_change_pct"] == pytest.approx(100 * (1500 / 1100 - 1))
    assert f["life_iso16281_h_reverse_change_pct"] == pytest.approx(100 * (25 / 75 - 1))
    assert g[("forward", None)]["bearing_load_mean_N_reverse_change_pct"] == pytest.approx(40.0)
    text = gear_quality.findings(gear_quality.by_grade(rows))
    assert "class 6: mean load +10.0 %" in text and "perfect +40.0 %, class 6 +36.4 %" in text
    assert "K_v 1.20/1.20/1.20 (ISO 6336-1 method B 1.20/1.20/1.20" in text


@pytest.mark.slow
def test_gear_quality_study_runs_end_to_end(tmp_path):
    out = tmp_path / "quality"
    args = ["--conditions", "3", "--directions", "forward", "--gear-class", "6", "--seeds", "1", "--settle", "0.004",
            "--window", "0.004", "--workers", "1", "--no-progress", "--out", str(out)]
    assert gear_quality.main(args) == 0
    rows = list(csv.DictReader((out / "runs.csv").open()))
    assert {(r["grade"], r["bearing"]) for r in rows} == {(g, b) for g in ("", "6") for b in ("inner", "outer")}
    by = {r["grade"]: r for r in rows if r["bearing"] == "outer"}
    # real teeth excite the mesh: its transmission error and dynamic load exceed perfect teeth's
    for m in gear_quality.MESHES:
        assert float(by["6"][f"te_p2p_um_{m}"]) > float(by[""][f"te_p2p_um_{m}"])
        # method B's K_v of class 6 exceeds perfect teeth's (B_p, B_f > 0), both from the standard
        assert float(by["6"][f"kv_iso_b_{m}"]) > float(by[""][f"kv_iso_b_{m}"]) > 1.0
    for f in ("by_grade.csv", "findings.md", "quality.png", "study.json"):
        assert (out / f).exists(), f
    assert "condition 3:" in (out / "findings.md").read_text()
    assert (out / "findings.md").read_text().startswith("Machine: reference machine [")      # names the machine
    s = json.loads(next(out.glob("c3_*_class6_*")).joinpath("summary.json").read_text())
    assert s["machine"]["label"] == (out / "findings.md").read_text().split("\n")[0][len("Machine: "):]
    assert gear_quality.main(args) == 0                     # finished: resumes, nothing recomputed
    assert gear_quality.main([*args[:-2], "--systematic-share", "0.2", "--out", str(out)]) == 2   # other parameters


@pytest.mark.parametrize("argv, message", [
    (["--gear-class", "12"], "--gear-class"), (["--gear-class", "6,6"], "--gear-class"), (["--seeds", "-1"], "--seeds"),
    (["--systematic-share", "1.5"], "--systematic-share"), (["--conditions", "5"], "--conditions")])
def test_bad_arguments_name_the_option(argv, message, capsys):
    assert gear_quality.main(argv + ["--out", "/tmp/never_written_gq"]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
