"""Operating points as data (scenarios.core.points): the grammar, the presets, a machine file's own point, the
conversions (a sun speed, a torque) checked by the kinematics they feed, and what is refused."""
from __future__ import annotations

import json
import math

import pytest

from components.presets import CONDITIONS, reference_dpgt
from components.units import ParameterError
from scenarios import fault_study, gear_quality, lubricant_study, paper_study, tolerance_study
from scenarios.core.points import Point, parse_point, point_overrides, preset
from scenarios.core.sweep import Case, build_params


@pytest.mark.parametrize("text, want", [
    ("cruise: 1500 rpm, 120 kW", Point("cruise", "1500 rpm", "carrier", "120 kW")),
    ("1500 rpm, 120 kW", Point("p1", "1500 rpm", "carrier", "120 kW")),
    ("up: sun 2400 rpm, 300 N*m, reverse, oil 80 degC", Point("up", "2400 rpm", "sun", "300 N*m", "reverse", "80 degC")),
    ("back: -1000 rpm, 50 kW", Point("back", "1000 rpm", "carrier", "50 kW", "reverse")),
])
def test_the_grammar(text, want):
    assert parse_point(text) == want


@pytest.mark.parametrize("text, message", [
    ("cruise: 1500 rpm", "needs a power or a torque"),
    ("cruise: 120 kW", "needs a speed"),
    ("cruise: 1500 rpm, 120 kW, 3 m", "'3 m' in"),
    ("cruise: 1500 Hz, 120 kW", "is not a speed"),
    ("3: 1500 rpm, 120 kW", "1-4 are the source's conditions"),
    ("c: 1500 rpm, 1600 rpm, 1 kW", "gives the speed twice"),
    ("c: -1500 rpm, 1 kW, forward", "a negative speed"),
])
def test_bad_points_are_refused_naming_the_item(text, message):
    with pytest.raises(ParameterError, match=None) as exc:
        parse_point(text)
    assert message in str(exc.value)


def test_a_preset_is_its_condition_and_its_case_is_the_condition_case():
    for c, (speed, power) in CONDITIONS.items():
        p = preset(c)
        assert p.condition == c and p.name == str(c)
        case = Case.at(p, "reverse", "x")
        assert case == Case(c, "reverse", "x") and case.label == f"c{c}_reverse"
        assert repr(build_params(case)) == repr(reference_dpgt(c, "reverse"))


def test_a_sun_speed_and_a_torque_come_back_through_the_kinematics():
    """A point given by the sun's speed and the sun's torque: the machine's kinematics (components.geometry) turn the
    carrier speed and power it becomes back into that sun speed and torque; a carrier torque times the carrier's
    speed is the power."""
    case = Case.at(parse_point("s: sun 3000 rpm, 250 N*m"), "forward", "x")
    op = build_params(case).si().operating
    assert abs(op.sun_speed) == pytest.approx(3000 * 2 * math.pi / 60, rel=1e-14)
    assert abs(op.sun_torque) == pytest.approx(250.0, rel=1e-14)
    op = build_params(Case.at(parse_point("c: 1500 rpm, 800 N*m"), "forward", "x")).si().operating
    assert op.output_power == pytest.approx(800.0 * 1500 * 2 * math.pi / 60, rel=1e-14)
    assert abs(op.carrier_torque) == pytest.approx(800.0, rel=1e-14)


def test_an_oil_outside_its_range_is_refused_and_braking_is_a_negative_power():
    machine = reference_dpgt()
    assert point_overrides(parse_point("b: 1000 rpm, -20 kW"), machine)["operating.output_power"] == "-20 kW"
    assert point_overrides(parse_point("t: 1000 rpm, -200 N*m"), machine)["operating.output_power"] == \
        f"{-200 * 1000 * 2 * math.pi / 60!r} W"
    with pytest.raises(ParameterError, match="outside the lubricant's range"):
        point_overrides(parse_point("h: 1000 rpm, 20 kW, oil 180 degC"), machine)
    assert point_overrides(parse_point("w: 1000 rpm, 20 kW, oil 90 degC"), machine)["lubricant.temperature"] == "90 degC"


@pytest.fixture()
def machine(tmp_path):
    """A user's machine file with its own operating point (what the studies used to refuse)."""
    p = tmp_path / "my_machine.toml"
    p.write_text('[bearing]\nclearance = "30 um"\n\n[operating]\ncarrier_speed = "1500 rpm"\n'
                 'output_power = "120 kW"\n')
    return p


def test_a_machine_files_operating_point_is_run_under_its_name(machine, tmp_path):
    a = paper_study.parse_args(["--params", str(machine), "--out", str(tmp_path / "o")])
    cases = paper_study.make_cases(a, tmp_path / "o")
    assert [c.label for c in cases] == ["my_machine_forward", "my_machine_reverse"]
    si = build_params(cases[1]).si()
    assert si.operating.carrier_speed == pytest.approx(-1500 * 2 * math.pi / 60, rel=1e-14)
    assert si.operating.output_power == pytest.approx(120e3) and si.bearing.clearance == pytest.approx(30e-6)


def test_points_in_a_file_and_on_the_command_line(tmp_path):
    f = tmp_path / "pts.toml"
    f.write_text('[[operating_point]]\nname = "idle"\ncarrier_speed = "800 rpm"\ntorque = "100 N*m"\n'
                 'direction = "reverse"\n')
    a = paper_study.parse_args(["--params", str(f), "--operating", "cruise: 1500 rpm, 120 kW", "--conditions", "2",
                                "--out", str(tmp_path / "o")])
    labels = [c.label for c in paper_study.make_cases(a, tmp_path / "o")]
    assert labels == ["c2_forward", "c2_reverse", "cruise_forward", "cruise_reverse", "idle"]
    assert [c.label for c in gear_quality.make_cases(gear_quality.parse_args(
        ["--operating", "cruise: 1500 rpm, 120 kW", "--gear-class", "6", "--seeds", "1", "--directions", "forward"]),
        tmp_path / "g")] == ["cruise_forward_perfect", "cruise_forward_class6_seed1"]
    a = fault_study.parse_args(["--operating", "cruise: 1500 rpm, 120 kW", "--faults", "", "--out", str(tmp_path)])
    assert [c.label for c in fault_study.make_cases(a, tmp_path)] == ["cruise_forward_perfect", "cruise_reverse_perfect"]


@pytest.mark.parametrize("argv, message", [
    (["--conditions", "3", "--params", "{machine}"], "operating.carrier_speed is set by this study's --conditions or "
                                                     "--operating, not by --params"),
    (["--operating", "x: 1000 rpm, 1 kW", "--set", "operating.output_power=5 kW"], "operating.output_power is set by"),
    (["--operating", "x: 1000 rpm, 1 kW", "--operating", "x: 2000 rpm, 1 kW"], "the point 'x' is named twice"),
    (["--operating", "x: 1000 rpm, 1 kW, oil 70 degC", "--set", "lubricant.temperature=60 degC"],
     "lubricant.temperature: --set sets it, but the point x sets its own oil temperature"),
    (["--operating", "x: 1000 rpm"], "--operating: point 'x' needs a power or a torque"),
])
def test_a_point_that_is_fought_is_refused_in_one_line(argv, message, machine, tmp_path, capsys):
    argv = [x.format(machine=machine) for x in argv]
    assert paper_study.main([*argv, "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err, err


def test_the_lubricant_study_takes_a_file_that_sets_an_oil_and_says_so(tmp_path, capsys):
    f = tmp_path / "oily.toml"
    f.write_text('[lubricant]\nviscosity_40 = "20 mm^2/s"\nviscosity_100 = "4 mm^2/s"\n[bearing]\nclearance = "30 um"\n')
    a = lubricant_study.parse_args(["--params", str(f), "--oil", "VG150", "--directions", "forward"])
    cases = lubricant_study.make_cases(a, tmp_path)
    out = capsys.readouterr().out.strip()
    assert out.count("\n") == 0 and "lubricant.viscosity_100, lubricant.viscosity_40" in out and "replace it" in out
    si = build_params(cases[0]).si()
    assert si.lubricant.viscosity_40 == pytest.approx(150e-6) and si.bearing.clearance == pytest.approx(30e-6)


def test_braking_loads_the_flanks_reverse_driving_loads(tmp_path, capsys):
    """Forward braking (the carrier drives the sun) loads the flanks that reverse driving loads, with the same
    torque-path force (the meshes carry |T|, the centrifugal load does not depend on the sign): a static solution of
    each, drive-flank forces within 1 %. The braking point is said to brake before it runs (a sign typed by mistake
    shows), the driving one not."""
    out = tmp_path / "o"
    assert paper_study.main(["--mode", "static", "--snapshots", "2", "--operating", "brake: 2000 rpm, -150 kW, forward",
                             "--operating", "drive: 2000 rpm, 150 kW, reverse", "--out", str(out), "--workers", "1",
                             "--no-progress"]) == 0
    said = [ln for ln in capsys.readouterr().out.splitlines() if "the machine brakes" in ln]
    assert said == ["warning before the run (brake): the output power is negative (-150 kW): the machine brakes — "
                    "the carrier drives the sun, the loaded flanks turn over (README: Operating points)"]
    import json
    b, d = (json.loads((out / n / "summary.json").read_text()) for n in ("brake", "drive"))
    assert b["power_W"] == -150e3 and b["direction"] == "forward" and d["direction"] == "reverse"
    for mesh in ("sun_inner", "inner_outer", "outer_ring"):
        mb, md = b["meshes"][mesh], d["meshes"][mesh]
        assert mb["drive_flank"] == md["drive_flank"]
        assert mb["drive_force_mean_N"] == pytest.approx(md["drive_force_mean_N"], rel=0.01)
        assert mb["coast_force_mean_N"] == 0.0


def test_the_tolerance_study_scales_a_points_torque(tmp_path):
    """Its torques are fractions of the point's own load: at 0.5 and 1 × "120 kW" the machines run 60 and 120 kW at
    the point's speed; a point that transmits nothing is refused."""
    from scenarios import tolerance_study
    a = tolerance_study.parse_args(["--samples", "2", "--gear-class", "5", "--torques", "0.5,1", "--operating",
                                    "cruise: 1500 rpm, 120 kW", "--directions", "forward", "--out", str(tmp_path)])
    tasks = tolerance_study.ToleranceStudy(a).tasks
    powers = {(t.torque, t.sample): build_params(t.case).si().operating for t in tasks}
    assert {k[0]: v.output_power for k, v in powers.items()} == {0.5: pytest.approx(60e3), 1.0: pytest.approx(120e3)}
    assert all(v.carrier_speed == pytest.approx(1500 * math.pi / 30) for v in powers.values())
    assert {t.path.split("/")[-2] for t in tasks if t.sample is not None} == {"cruise_forward_t0.5", "cruise_forward_t1"}
    a = tolerance_study.parse_args(["--operating", "idle: 1500 rpm, 0 kW", "--out", str(tmp_path)])
    with pytest.raises(ParameterError, match="point idle: transmits no torque"):
        tolerance_study.ToleranceStudy(a)


def _static_solves(out):
    """(steps, snapshots) of every static solution a study wrote under ``out``."""
    recs = [json.loads(f.read_text()) for f in out.rglob("*.json")]
    return [(r["static_solver"]["steps"], r["snapshots"]) for r in recs if "static_solver" in r]


@pytest.mark.parametrize("study, argv", [
    (paper_study, ["--mode", "static", "--conditions", "2", "--snapshots", "8"]),
    pytest.param(tolerance_study, ["--samples", "1", "--conditions", "2", "--gear-class", "7", "--dynamic", "0"],
                 marks=pytest.mark.slow),
])
def test_the_static_solution_takes_the_ehl_traction_law(study, argv, tmp_path):
    """The EHL traction law's steady cage and roller speeds are part of the static state (docs/model.md §16): a static
    study of it runs (nothing refused) and its snapshots solve in a few continuation steps each — on average fewer
    than 40 (measured at condition 2: the reference machine ≈ 10, 28 from the kinematic pose and 6–9 carried over;
    a class-7 tolerance sample 18–24, where some carried-over starts fail and the kinematic pose solves), where a
    cage rate whose Newton steps jump across its traction's narrow step ends at the 200-step limit."""
    out = tmp_path / "out"
    assert study.main([*argv, "--set", "bearing.traction_law=ehl", "--out", str(out), "--no-progress"]) == 0
    solved = _static_solves(out)
    assert solved, sorted(str(f.relative_to(out)) for f in out.rglob("*.json"))
    for steps, snapshots in solved:
        assert steps < 40 * snapshots, (steps, snapshots)


def test_a_point_without_a_static_state_fails_in_one_line_naming_it(tmp_path, capsys, monkeypatch):
    """Where a point has no static state (planted: every instant refused), its run fails in one line naming the
    operating point and what the solver found, and the study's note lists only what a static solution cannot give
    (cage slip, pocket impacts, ...), not the loads and lives that the failed run left empty."""
    import mbd
    from components import static

    def refuse(*args, **kwargs):
        raise mbd.ModelError("solve_static: no static state at t = 0.01 s (planted)")
    monkeypatch.setattr(static, "solve_static", refuse)
    assert paper_study.main(["--mode", "static", "--snapshots", "2", "--operating", "idle: 1500 rpm, 0 kW",
                             "--directions", "forward", "--workers", "1", "--out", str(tmp_path),
                             "--no-progress"]) == 1
    out = capsys.readouterr().out
    failed = [line for line in out.splitlines() if line.startswith("FAILED idle_forward")]
    assert len(failed) == 1, out
    assert "carrier speed 1500 r/min, sun torque 0 N m" in failed[0] and "(planted)" in failed[0], failed[0]
    left = next(line for line in out.splitlines() if "left out, as only a dynamic run gives them" in line)
    assert "cage_slip_pct" in left and "pocket_impacts_per_rev" in left
    for given in ("bearing_load_mean_N", "life_iso281_h", "life_iso16281_h", "roller_inner_race_max_N"):
        assert given not in left, left
