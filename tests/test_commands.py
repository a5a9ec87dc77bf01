"""How commands end (scenarios.command): one line and an exit code, a traceback only with --debug."""
from __future__ import annotations

import pytest

import mbd
from components.units import ParameterError
from scenarios import cli, paper_study
from scenarios.command import FAILED, INTERRUPTED, USAGE, command


def _raising(exc):
    @command
    def main(argv):
        raise exc
    return main


@pytest.mark.parametrize("exc,code,words", [
    (ParameterError.at("bearing.clearance", "must be >= 0 m, got -1 um"), USAGE, "error: bearing.clearance: must be"),
    (mbd.ModelError("scene option 'frame' must be one of ('rotating', 'fixed')"), USAGE, "error: scene option"),
    (SystemExit("error: --conditions takes 1, 2, 3 and/or 4"), USAGE, "error: --conditions"),
    (mbd.IntegrationError("step size fell below the minimum at t = 1e-3 s; failed_state.npz"), FAILED,
     "error: the run failed: step size"),
    (ZeroDivisionError("division by zero"), FAILED, "error: ZeroDivisionError: division by zero (run with --debug"),
    (KeyboardInterrupt(), INTERRUPTED, "interrupted: finished runs and checkpoints are kept"),
])
def test_every_ending_is_one_line_and_a_code(exc, code, words, capsys):
    assert _raising(exc)([]) == code
    err = capsys.readouterr().err
    assert err.startswith(words) and err.count("\n") == 1 and "Traceback" not in err


def test_debug_shows_the_traceback():
    with pytest.raises(ZeroDivisionError):
        _raising(ZeroDivisionError("division by zero"))(["--debug"])


def test_a_bad_condition_through_the_dpgt_command(tmp_path, capsys):
    assert cli.main(["paper_study", "--conditions", "7", "--out", str(tmp_path)]) == USAGE
    assert capsys.readouterr().err.strip() == "error: argument --conditions: takes 1, 2, 3 and/or 4 (PARAMETERS.md), got '7'"
    assert paper_study.main(["--set", 'bearing.clearance=-1 um', "--out", str(tmp_path)]) == USAGE
    assert "bearing.clearance" in capsys.readouterr().err


def test_a_failed_rerun_keeps_the_finished_summaries_in_the_tables(tmp_path):
    import json
    good, damaged = tmp_path / "c4_forward", tmp_path / "c4_reverse"
    good.mkdir()
    damaged.mkdir()
    (good / "summary.json").write_text(json.dumps({"inner": {"bearing_load_mean_N": 1.0}, "outer": {}}))
    (damaged / "summary.json").write_text("{not json")
    results = {"c4_forward": {"error": "boom"}, "c4_reverse": {"error": "bang"}}
    paper_study._keep_finished_on_disk(results, tmp_path)
    assert results["c4_forward"]["inner"] == {"bearing_load_mean_N": 1.0}
    assert results["c4_forward"]["stale_after_failure"] == "boom"      # still reported as failed
    assert results["c4_reverse"] == {"error": "bang"}                 # a damaged summary is not used


# every command checks all its arguments before anything runs: one line naming the argument, exit 2
BAD_ARGUMENTS = [
    ("paper_study", ["--conditions", ""], "--conditions: expected a comma list"),
    ("paper_study", ["--conditions", "3,x"], "--conditions: takes 1, 2, 3"),
    ("paper_study", ["--directions", " , "], "--directions: expected a comma list"),
    ("paper_study", ["--directions", "backward"], "--directions: takes directions"),
    ("paper_study", ["--window", "-0.01"], "--window: must be > 0 s"),
    ("paper_study", ["--window", "nan"], "--window: expected a finite number"),
    ("paper_study", ["--settle", "abc"], "--settle: expected a number >= 0 s"),
    ("paper_study", ["--h", "0"], "--h: must be > 0 and <= 0.001 s"),
    ("paper_study", ["--alpha", "0.2"], "--alpha: HHT alpha must be in [-1/3, 0]"),
    ("paper_study", ["--sample-rate", "0"], "--sample-rate: must be > 0 Hz"),
    ("paper_study", ["--workers", "0"], "--workers: must be a whole number in [1"),
    ("paper_study", ["--planets", "two"], "--planets: expected a whole number"),
    ("paper_study", ["--option", "drag"], "--option: expects KEY=VALUE"),
    ("paper_study", ["--params", "/no/such.toml"], "--params: no such file"),
    ("paper_study", ["--scheduler", "my laptop"], "--scheduler: expected a Dask scheduler address"),
    ("paper_study", ["--method", "rk4"], "--method: invalid choice"),
    ("paper_study", ["--frobnicate"], "unrecognized arguments: --frobnicate"),
    ("lubricant_study", ["--grades", "VG999"], "--grades: takes ISO VG grades"),
    ("lubricant_study", ["--directions", ""], "--directions: expected a comma list"),
    ("spectrum", ["--power", "200 kg"], "--power: expected a power"),
    ("spectrum", ["--carrier-rpm", "-5"], "--carrier-rpm: must be > 0 r/min"),
    ("bearing_rig", ["--radial-load", "0 N"], "--radial-load: must be > 0"),
    ("bearing_rig", ["--rollers", "2"], "--rollers: must be a whole number in [3"),
    ("bearing_rig", ["--speed", "70 Hz"], "--speed: expected an angular velocity (e.g. '4200 rpm'), got '70 Hz': "
                                          "needs an angle unit"),
    ("modal", ["--condition", "5"], "--condition: must be a whole number in [1, 4]"),
    ("stability", ["--scipy", "Radau:x"], "--scipy: expects METHOD:RTOL"),
    ("stability", ["--cases", "nonsense"], "--cases: takes cases"),
    ("work_precision", ["--problems", "ring"], "--problems: takes problems"),
    ("benchmark", ["--scipy-methods", "Euler"], "--scipy-methods: takes scipy methods"),
    ("bench_engine", ["--steps", "-1"], "--steps: must be a whole number"),
    # a near miss names the closest valid name, in every command and every kind of name (components.names)
    ("paper_study", ["--set", "bearing.clearence=30 um"],
     "bearing.clearence: unknown parameter (did you mean 'bearing.clearance'?)"),
    ("paper_study", ["--set", "bearng.clearance=30 um"], "(did you mean 'bearing.clearance'?)"),
    ("paper_study", ["--option", "frme=fixed"], "unknown scene option(s) ['frme'] (did you mean 'frame'?)"),
    ("paper_study", ["--option", "frame=fixd"], "got 'fixd' (did you mean 'fixed'?)"),
    ("paper_study", ["--condtions", "3"], "unrecognized arguments: --condtions 3 (did you mean '--conditions'?)"),
    ("paper_study", ["--method", "hht-adaptiv"], "invalid choice: 'hht-adaptiv'"),
    ("paper_study", ["--method", "hht-adaptiv"], "(did you mean 'hht-adaptive'?)"),
    ("paper_study", ["--set", "bearing.cage.impact_law=exakt"], "got 'exakt' (did you mean 'exact'?)"),
    ("lubricant_study", ["--set", "lubricant.viscosity_40s=68 mm^2/s"], "(did you mean 'lubricant.viscosity_40'?)"),
    ("lubricant_study", ["--set", "bearing.traction_law=EHL"], "got 'EHL' (did you mean 'ehl'?)"),
    ("fault_study", ["--faults", "cracked_teeth"], "--faults: unknown fault(s) ['cracked_teeth'] "
                                                   "(did you mean 'cracked_tooth'?)"),
    ("fault_study", ["--set", "bearing.cage.pocket_clearence=0.2 mm"],
     "(did you mean 'bearing.cage.pocket_clearance'?)"),
    ("gear_quality", ["--set", "mesh.dampng_ratio=0.1"], "(did you mean 'mesh.damping_ratio'?)"),
    ("spectrum", ["--sensor", "housng"], "(did you mean 'housing'?)"),
    ("spectrum", ["--set", "rig.sensor.angel=90 deg"], "(did you mean 'rig.sensor.angle'?)"),
    ("bearing_rig", ["--cage", "hold"], "(did you mean 'held'?)"),
    ("modal", ["--dpgt", "--set", "bearing.clearence=30 um"], "(did you mean 'bearing.clearance'?)"),
    ("modal", ["--set", "sun.mas=2 kg"], "sun.mas: unknown key (did you mean 'mass'?)"),
    ("stability", ["--cases", "torque_stepp"], "(did you mean 'torque_step'?)"),
    ("work_precision", ["--problems", "dpg"], "(did you mean 'dpgt'?)"),
    ("benchmark", ["--scipy-methods", "radau"], "(did you mean 'Radau'?)"),
]


@pytest.mark.parametrize("name,argv,words", BAD_ARGUMENTS)
def test_bad_arguments_are_one_line_usage_errors(name, argv, words, tmp_path, capsys):
    assert cli.main([name, *argv, *(["--out", str(tmp_path)] if name != "bench_engine" else [])]) == USAGE
    err = capsys.readouterr().err
    assert err.startswith("error: ") and words in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []        # nothing ran, nothing was written


def test_an_output_folder_that_cannot_exist_is_a_usage_error(tmp_path, capsys):
    (tmp_path / "a_file").write_text("")
    assert cli.main(["paper_study", "--out", str(tmp_path / "a_file" / "out")]) == USAGE
    assert "argument --out: cannot make the folder" in capsys.readouterr().err


def test_a_near_miss_in_a_params_file_names_the_closest_key(tmp_path, capsys):
    """--params file keys (a table's key, an error entry's field) get the suggestion --set gets."""
    out = tmp_path / "out"
    typo = tmp_path / "typo.toml"
    typo.write_text('[bearing]\nclearence = "30 um"\n')
    assert paper_study.main(["--params", str(typo), "--out", str(out)]) == USAGE
    err = capsys.readouterr().err
    assert "bearing.clearence: unknown parameter (did you mean 'bearing.clearance'?)" in err and err.count("\n") == 1
    entry = tmp_path / "entry.toml"
    entry.write_text('[[errors.pinhole]]\nplanet = "a1"\nradial = "10 um"\ntangental = "0 um"\n')
    assert cli.main(["fault_study", "--machine", f"mine={entry}", "--out", str(out)]) == USAGE
    err = capsys.readouterr().err
    assert "unknown keys: ['tangental'] (did you mean 'tangential'?)" in err and err.count("\n") == 1
    assert not out.exists() or list(out.iterdir()) == []          # nothing ran, nothing was written


def test_a_near_miss_scenario_and_animate_option(tmp_path, capsys):
    assert cli.main(["paper_stduy"]) == USAGE
    assert "unknown scenario 'paper_stduy' (did you mean 'paper_study'?)" in capsys.readouterr().err
    assert cli.main(["animate", str(tmp_path / "x.nc"), "--out", str(tmp_path / "x.gif"), "--kind", "cages"]) == USAGE
    assert "invalid choice: 'cages'" in (err := capsys.readouterr().err) and "(did you mean 'cage'?)" in err


def test_did_you_mean_is_one_helper_with_sane_matches():
    from components.names import argparse_hint, did_you_mean
    from components.presets import oil_grade

    assert did_you_mean("bearing.clearence", ["bearing.clearance", "bearing.rollers", "bearing.cage.guide_clearance"]) \
        == " (did you mean 'bearing.clearance'?)"                   # a clear near miss names one
    assert did_you_mean("vg100", ["VG68", "VG100", "VG150"]) == " (did you mean 'VG100'?)"     # case first
    assert did_you_mean("pinhol", ["pinhole_a1", "pinhole_b1", "spall_pin"]) == \
        " (did you mean 'pinhole_a1' or 'pinhole_b1'?)"
    assert did_you_mean("bearing", ["ring", "sun", "planet"]) == ""        # nothing close: no guess
    assert did_you_mean("zzz", []) == ""
    with pytest.raises(ParameterError, match=r"got 'vg100' \(did you mean 'VG100'\?\)"):
        oil_grade("vg100")
    import argparse
    p = argparse.ArgumentParser()
    p.add_argument("--conditions")
    assert argparse_hint(p, "unrecognized arguments: --condtions=3") == \
        "unrecognized arguments: --condtions=3 (did you mean '--conditions'?)"
    assert argparse_hint(p, "unrecognized arguments: --zzz") == "unrecognized arguments: --zzz"
