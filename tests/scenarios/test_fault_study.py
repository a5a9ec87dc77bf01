"""The fault study end to end on a tiny window, and its characteristic frequencies."""
from __future__ import annotations

import csv

import pytest

from components.presets import reference_dpgt
from scenarios import fault_study


def test_characteristic_frequencies_follow_the_kinematics():
    """Condition 2 (2000 r/min): f_m = z_r f_c; a gear's rotation relative to the carrier is f_m / z; the
    roller-pass frequencies are Z × the cage's speed relative to the pin and to the bore."""
    si = reference_dpgt(2).si()
    fr = fault_study.characteristic_frequencies(si)
    z = {g: si.gears[g].teeth for g in ("sun", "outer_planet", "ring")}
    assert fr["f_c"] == pytest.approx(2000 / 60) and fr["f_m"] == pytest.approx(z["ring"] * fr["f_c"])
    assert fr["sun_rel"] == pytest.approx(fr["f_m"] / z["sun"])
    assert fr["outer_planet_rel"] == pytest.approx(fr["f_m"] / z["outer_planet"])
    Z = si.bearing.rollers
    assert fr["outer_roller_pass_pin"] == pytest.approx(Z * fr["outer_cage_rel"])
    # the cage rolls between pin and bore: its speed relative to each is shared by the raceway radii
    b = si.bearing
    Ri, Ro = 0.5 * (b.pitch_diameter - b.roller_diameter), 0.5 * (b.pitch_diameter + b.roller_diameter)
    assert fr["outer_roller_pass_pin"] / fr["outer_roller_pass_bore"] == pytest.approx(Ro / Ri)


@pytest.mark.slow
def test_fault_study_runs_end_to_end(tmp_path):
    out = tmp_path / "faults"
    machine = tmp_path / "bent_carrier.toml"        # a damaged machine described in TOML (README)
    machine.write_text('[[errors.pinhole]]\nplanet = "b1"\nradial = "0 um"\ntangential = "30 um"\n')
    args = ["--faults", "cracked_tooth", "--machine", f"bent={machine}", "--directions", "forward",
            "--settle", "0.002", "--window", "0.006", "--workers", "1", "--no-progress", "--out", str(out)]
    assert fault_study.main(args) == 0
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert {(r["fault"], r["bearing"]) for r in rows} == {(f, b) for f in ("perfect", "bent", "cracked_tooth")
                                                          for b in ("inner", "outer")}
    by = {(r["fault"], r["bearing"]): r for r in rows}
    # each fault's life relative to the perfect machine's, bearing kind by bearing kind (not to its own run)
    for (fault, kind), r in by.items():
        ratio = float(r["life_iso16281_h"]) / float(by[("perfect", kind)]["life_iso16281_h"])
        assert float(r["life_relative"]) == pytest.approx(ratio, rel=1e-12), (fault, kind)
        assert (abs(ratio - 1.0) > 1e-6) == (fault != "perfect"), (fault, kind, ratio)
    assert float(by[("bent", "outer")]["load_sharing_factor"]) > float(by[("perfect", "outer")]["load_sharing_factor"])
    assert float(by[("cracked_tooth", "outer")]["own_frequency"]) == pytest.approx(
        fault_study.characteristic_frequencies(reference_dpgt(2).si())["outer_planet_rel"])
    # 6 ms at 2000 r/min is 0.2 carrier revolutions: the sensor's lines mean nothing, so none is given, and why
    assert all(r["sensor_f_m-1f_c"] == "" and "carrier revolutions" in r["notes"] for r in rows)
    for f in ("summary.md", "findings.md", "loads.png", "spectra.png", "study.json"):
        assert (out / f).exists(), f
    text = (out / "findings.md").read_text()
    assert text.startswith("Machine: reference machine [")                 # the tables name the machine
    assert "forward:" in text and "cracked_tooth: life ×" in text and "bent: life ×" in text
    # a second call finds every run finished (resumes, nothing recomputed) and refuses other parameters
    assert fault_study.main(args) == 0
    assert fault_study.main(["--faults", "cracked_tooth", "--directions", "forward", "--settle", "0.003",
                             "--window", "0.006", "--workers", "1", "--no-progress", "--out", str(out)]) == 2


def test_a_sample_rate_that_cannot_resolve_the_sidebands_is_refused_in_either_direction(tmp_path, capsys):
    """Condition 2: f_m + 6 f_c = 2933 Hz needs more than 5867 Hz; 5500 Hz is refused forward and reverse (the
    reverse carrier frequency is negative, which must not lower the bound)."""
    for d in ("forward", "reverse"):
        assert fault_study.main(["--faults", "", "--directions", d, "--sample-rate", "5500", "--no-progress",
                                 "--out", str(tmp_path / d)]) == 2
        assert "--sample-rate: 5500 Hz cannot resolve" in capsys.readouterr().err


def test_several_operating_points_each_compare_with_their_own_perfect_machine(tmp_path):
    """--conditions 2,3 (or several --operating points): every machine at every point, each folder its own; the
    findings rank each point's faults against that point's perfect machine (a fault's life relative to the perfect
    machine of the other point would be meaningless)."""
    a = fault_study.parse_args(["--conditions", "2,3", "--faults", "pinhole", "--directions", "forward",
                                "--out", str(tmp_path)])
    cases = fault_study.make_cases(a, tmp_path)
    assert sorted((c.condition, c.tag) for c in cases) == [(2, "perfect"), (2, "pinhole"), (3, "perfect"), (3, "pinhole")]
    assert len({c.out_dir for c in cases}) == 4
    row = lambda fault, cond, life: {"fault": fault, "condition": cond, "direction": "forward", "bearing": "outer",
                                     "life_iso16281_h": life, "load_sharing_factor": 1.0, "bearing_load_max_N": 1e4,
                                     **{k: None for k in fault_study.SENSOR_LINES}}
    text = fault_study.findings([row("perfect", 2, 100.0), row("pinhole", 2, 90.0),
                                 row("perfect", 3, 50.0), row("pinhole", 3, 49.0)])
    assert "condition 2, forward:" in text and "condition 3, forward:" in text
    c2, c3 = text.split("condition 3, forward:")
    assert "0.90" in c2 and "0.98" in c3, text
