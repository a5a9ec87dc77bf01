"""How commands end (scenarios.core.command): one line and an exit code, a traceback only with --debug."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from components.units import ParameterError
from scenarios import cli, paper_study
from scenarios.core.command import FAILED, INTERRUPTED, USAGE, command


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
    assert capsys.readouterr().err.strip() == "error: argument --conditions: takes 1, 2, 3 and/or 4 (docs/parameters.md), got '7'"
    assert paper_study.main(["--set", 'bearing.clearance=-1 um', "--out", str(tmp_path)]) == USAGE
    assert "bearing.clearance" in capsys.readouterr().err


def test_a_failed_rerun_keeps_the_finished_summaries_in_the_tables(tmp_path):
    import json

    from scenarios.core.study import Study, StudyRun
    from scenarios.core.sweep import Case, Outcome, Status
    good, damaged = tmp_path / "c4_forward", tmp_path / "c4_reverse"
    good.mkdir()
    damaged.mkdir()
    (good / "summary.json").write_text(json.dumps({"inner": {"bearing_load_mean_N": 1.0}, "outer": {}}))
    (damaged / "summary.json").write_text("{not json")
    run = StudyRun(tmp_path, [], {"c4_forward": Outcome(Case(4, "forward", str(good)), Status.FAILED, error="boom"),
                                  "c4_reverse": Outcome(Case(4, "reverse", str(damaged)), Status.FAILED, error="bang")})
    run.kept = Study._earlier(run)                                      # what the paper study does (keep_earlier)
    results = run.results
    assert results["c4_forward"]["inner"] == {"bearing_load_mean_N": 1.0}
    assert results["c4_forward"]["stale_after_failure"] == "boom"      # still reported as failed
    assert run.failed == {"c4_forward": "boom", "c4_reverse": "bang"}
    assert "c4_reverse" not in results                                # a damaged summary is not used


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
    ("lubricant_study", ["--oil", "VG999"], "--oil: takes ISO VG grades"),
    ("lubricant_study", ["--directions", ""], "--directions: expected a comma list"),
    ("skidding_study", ["--powers", "2,-20"], "--powers: must be >= 0 kW"),
    ("skidding_study", ["--oil-temperatures", "warm"], "--oil-temperatures: expected a number"),
    ("skidding_study", ["--speed", "1000 kW"], "--speed: expected an angular velocity"),
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
    # the shared grammar: --conditions everywhere (one condition where a command runs one), --params, --set
    ("modal", ["--conditions", "2,3"], "--conditions/--condition: this command runs one condition at a time"),
    ("fault_study", ["--condition", "7"], "--conditions: takes 1, 2, 3 and/or 4"),
    ("modal", ["--conditions", "3,4"], "this command runs one condition at a time, got '3,4'"),
    ("gear_quality", ["--params", "/no/such.toml"], "--params: no such file"),
    ("fault_study", ["--params", "/no/such.toml"], "--params: no such file"),
    ("bearing_rig", ["--set", "clearance"], "--set: expects KEY=VALUE"),
    ("spectrum", ["--workers", "2"], "unrecognized arguments: --workers"),       # one run: no sweep options
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


# the shared command grammar: one definition of every shared option, the same in every command
STUDIES = {"paper_study": "results/study", "demo": "results/demo", "lubricant_study": "results/lubricant",
           "fault_study": "results/faults", "gear_quality": "results/gear_quality",
           "tolerance_study": "results/tolerances", "sensitivity": "results/sensitivity"}
OTHERS = {"spectrum": "results/spectrum", "bearing_rig": "results/bearing_rig", "modal": "results/modal",
          "work_precision": "results/numerics", "stability": "results/numerics", "benchmark": "results/numerics",
          "bench_engine": None, "params": None, "animate": None, "duty_cycle": "results/duty_cycle",
          "bearing_misalignment": "results/bearing_misalignment",
          # static only, at the preset conditions (no --operating)
          "misalignment_study": "results/misalignment",
          # its own axes (carrier speed, powers, oil temperatures) in place of --conditions/--operating
          "skidding_study": "results/skidding"}
SHARED_OPTIONS = ("--params", "--set", "--out", "--overwrite", "--force", "--no-progress", "--workers",
                  "--scheduler", "--conditions")


def _help(name, capsys):
    assert cli.main([name, "--help"]) == 0
    return capsys.readouterr().out


@pytest.mark.parametrize("name", STUDIES)
def test_every_study_takes_the_shared_options_with_one_help_text(name, capsys):
    from scenarios.core.args import SHARED

    text = _help(name, capsys)
    assert text.startswith(f"usage: dpgt {name} ")             # under the console command it names itself so
    for option in SHARED_OPTIONS:
        assert option in text, option
    flat = " ".join(text.split())
    for key in ("params", "overwrite", "force", "no-progress", "scheduler"):     # the one definition's words
        assert " ".join(SHARED[key][1]["help"].split()) in flat, key
    assert f"output folder (default {STUDIES[name]})" in flat
    assert "examples:" in text and f"dpgt {name} --" in text.split("examples:")[1]
    assert f"writes (into --out, default {STUDIES[name]}):" in text and f"default --out: {STUDIES[name]}" in text


@pytest.mark.parametrize("name", OTHERS)
def test_every_other_command_lists_examples_what_it_writes_and_its_default_out(name, capsys):
    text = _help(name, capsys)
    assert text.startswith(f"usage: dpgt {name} ") and "examples:" in text and "writes" in text
    if OTHERS[name]:
        assert f"default --out: {OTHERS[name]}" in text and "--out DIR" in text


def test_outside_the_console_command_the_usage_names_the_module(capsys):
    from scenarios import lubricant_study

    assert lubricant_study.main(["--help"]) == 0
    assert capsys.readouterr().out.startswith("usage: python -m scenarios.lubricant_study ")


def test_one_condition_commands_take_conditions_and_the_former_spelling():
    from scenarios import fault_study, modal

    assert modal.parse_args(["--conditions", "3"]).conditions == 3
    assert modal.parse_args(["--condition", "1"]).conditions == 1              # the former spelling still works
    assert fault_study.parse_args([]).conditions == "2"                         # the source's rig speed
    assert fault_study.parse_args(["--conditions", "2,3"]).conditions == "2,3"  # the fault study: several points


def test_bench_engine_says_once_in_one_line_what_falls_back_and_why(tmp_path, capsys):
    """The ring's drive torque is a Python function of time, which the compiled engine cannot take: the ring's HHT
    runs on the numpy path. bench_engine says so once, before the table, in one line naming the engine path and
    the element (no memory address), instead of mbd's line on every run; the JSON records it."""
    import json

    import mbd
    from scenarios.numerics import bench_engine

    model, q0, v0 = bench_engine.ring_model(4)
    with pytest.raises(mbd.ModelError, match="Python callable of time"):     # the truth: it cannot be compiled
        mbd.simulate(model, q0, v0, 0.0, controller=mbd.FixedStep(bench_engine.H), progress=False, engine="compiled")
    out = tmp_path / "b.json"
    assert bench_engine.main(["--sizes", "4", "5", "--steps", "3", "--repeats", "2", "--no-radau",
                              "--json", str(out)]) == 0
    cap = capsys.readouterr()
    said = [line for line in (cap.out + cap.err).splitlines() if "numpy engine path" in line]
    assert len(said) == 1 and said[0] == cap.out.splitlines()[0], said
    assert said[0].startswith("fallback: the ring's HHT runs on the numpy engine path")
    assert "TorqueSource 'drive': torque given as a Python callable of time cannot be compiled" in said[0]
    assert "0x" not in said[0] and "<function" not in said[0]
    r = json.loads(out.read_text())
    assert r["engine"] == "numpy" and "TorqueSource 'drive'" in r["engine_note"]
    assert [row["engine"] for row in r["results"]] == ["numpy", "numpy"]


def test_bench_statistics_takes_one_condition_through_the_shared_grammar(capsys):
    """--conditions with one value (the studies' spelling), --condition still accepted; a list of two, a condition
    out of range and a bad window are one-line usage errors before anything runs; no advice about an --out it
    does not have."""
    from scenarios.numerics import bench_statistics

    assert bench_statistics.parse_args(["--conditions", "2"]).conditions == 2
    assert bench_statistics.parse_args(["--condition", "1"]).conditions == 1
    assert bench_statistics.parse_args([]).conditions == 3
    for argv, words in ((["--conditions", "1,2"], "--conditions/--condition: this command runs one condition at a "
                                                  "time, got '1,2'; run it once per condition"),
                        (["--condition", "5"], "--conditions/--condition: must be a whole number in [1, 4]"),
                        (["--window", "-1"], "--window: must be > 0 s")):
        assert bench_statistics.main(argv) == USAGE
        err = capsys.readouterr().err
        assert err.startswith("error: ") and words in err and err.count("\n") == 1 and "--out" not in err, err
    assert bench_statistics.main(["--help"]) == 0
    text = capsys.readouterr().out
    assert "--conditions C, --condition C" in text and "examples:" in text


def test_bench_statistics_profile_splits_the_observers_time(capsys):
    """--profile: the observer's parts each a share of its time, the parts inside snapshots and the accumulators
    together no more than all of it, the contacts' outputs from the compiled kernels (the meshes' from numpy, inside
    that call), and the observer's time over the engine's in the same runs."""
    import json

    from scenarios import bench_statistics

    assert bench_statistics.main(["--settle", "5e-4", "--window", "2e-4", "--repeats", "1", "--profile"]) == 0
    r = json.loads(capsys.readouterr().out)
    prof = r["profile"]
    share = lambda k: prof[k]["share"]                                      # noqa: E731
    assert share("on_block") == 1.0 and 0.0 < r["overhead_in_run"] and 40 <= r["steps"] <= 41
    inside = [k for k in prof if k not in ("on_block", "snapshots (every per-step quantity of the block's states)",
                                           "accumulators (concatenation, compiled loop)", "element outputs, numpy kernels")]
    assert all(0.0 < share(k) < 1.0 for k in prof if k != "on_block")
    assert sum(share(k) for k in inside) <= share("snapshots (every per-step quantity of the block's states)")
    assert share("snapshots (every per-step quantity of the block's states)") + share(
        "accumulators (concatenation, compiled loop)") <= 1.0
    assert share("element outputs, numpy kernels") < share("element outputs, compiled kernels (the contacts)")



def test_dpgt_params_lists_every_key_with_value_unit_source_and_meaning(capsys):
    from components.params import parameter_names
    from components.presets import reference_dpgt

    assert cli.main(["params", "--grep", "clearance"]) == 0
    lines = capsys.readouterr().out.splitlines()
    row = next(line for line in lines if line.startswith("bearing.clearance "))
    assert row.split()[1:4] == ["20", "µm", "[assumed]"] and "diametral clearance" in row
    assert all("clearance" in line.lower() for line in lines[1:])                   # only what --grep asks for
    assert cli.main(["params"]) == 0
    keys = [line.split()[0] for line in capsys.readouterr().out.splitlines()[1:]]
    assert keys == parameter_names(reference_dpgt())                                # every key, none twice
    assert cli.main(["params", "--grep", "bearing.clearance", "--set", "bearing.clearance=30 um"]) == 0
    assert capsys.readouterr().out.splitlines()[1].split()[1:4] == ["30", "µm", "[user]"]
    assert cli.main(["params", "--set", "bearing.clearence=30 um"]) == 2           # a near miss: did you mean
    assert "(did you mean 'bearing.clearance'?)" in capsys.readouterr().err


TINY_STUDY = ["--conditions", "4", "--directions", "forward", "--settle", "0.0005", "--window", "0.0005",
              "--set", "bearing.rollers=8", "--no-progress", "--workers", "1"]


def test_a_study_says_what_happens_and_marks_reused_runs(tmp_path, capsys):
    """Typed outcomes (finished, reused, failed); the headline table first, one line per post-processing step; a
    run taken from an earlier one is reported as reused, with the wall time of the run that made it."""
    import json

    from scenarios.core.sweep import Status

    r = paper_study.run(paper_study.parse_args([*TINY_STUDY, "--out", str(tmp_path)]))
    assert r["outcomes"]["c4_forward"].status is Status.FINISHED and not r["failed"]
    first = capsys.readouterr().out
    assert "runs: 1 finished now, 0 reused" in first and ": reused (" not in first
    wall = json.loads((tmp_path / "c4_forward" / "summary.json").read_text())["wall_s"]
    r = paper_study.run(paper_study.parse_args([*TINY_STUDY, "--out", str(tmp_path)]))
    o = r["outcomes"]["c4_forward"]
    assert o.status is Status.REUSED and o.wall_s == pytest.approx(wall)
    text = capsys.readouterr().out
    assert "runs: 0 to run, 1 reused" in text and "runs: 0 finished now, 1 reused" in text
    line = next(x for x in text.splitlines() if x.startswith("  c4_forward: reused ("))
    assert f"{wall:.1f} s wall" in line                          # the original run's wall time
    lines = text.splitlines()
    head, table, tables, figures = (next(i for i, x in enumerate(lines) if x.startswith(w))
                                    for w in ("headline (", "### Condition 4", "tables: ", "figures: "))
    assert head < table < tables < figures                         # the headline table first
    assert lines[head + 3].startswith("| 4 | inner | ") and " / – " in lines[head + 3]   # no reverse run: no change
    assert lines[tables] == "tables: comparison.csv, comparison.md" and "bearing_load_life.png" in lines[figures]
    assert sum(x.startswith(("tables: ", "figures: ", "animation: ")) for x in lines) == 2   # one line per step


def test_a_failed_run_is_an_outcome_not_a_dict(tmp_path):
    from scenarios.core.runner import RunConfig
    from scenarios.core.sweep import Case, Status, sweep

    bad = Case(4, "reverse", str(tmp_path / "bad"), {"bearing.rollers": 8, "gears.planets": 0})
    o = sweep([bad], RunConfig(settle=0.0005, window=0.0005, progress=False), workers=1, progress=False)["c4_reverse"]
    assert o.status is Status.FAILED and not o.ok and o.summary is None and "gears.planets" in o.error
    assert o.as_dict()["error"] == o.error                         # run_sweep's plain form, for old callers


def test_the_python_entry_point_runs_reuses_and_opens_a_run(tmp_path, capsys):
    """scenarios.run: the run every study makes, from a script or a notebook; the same run again is reused. Its
    statistics warnings (here: a 0.5 ms window, a fraction of a cage revolution) are printed, as the commands do."""
    import scenarios

    kw = dict(condition=4, set={"bearing.rollers": 8}, settle=0.0005, window=0.0005, progress=False)
    first = scenarios.run(out=tmp_path / "run", **kw)
    assert first.status == "finished" and first.summary["rollers"] == 8 and first.summary["condition"] == 4
    said = [x for x in capsys.readouterr().err.splitlines() if x.startswith("warning: ")]
    assert said and len(said) == len(first.summary["warnings"]) and any("cage revolution" in x for x in said)
    again = scenarios.run(scenarios.parameters(4, set={"bearing.rollers": 8}), tmp_path / "run",
                          **{k: v for k, v in kw.items() if k not in ("condition", "set")})
    assert again.status == "reused" and again.wall_s == first.wall_s
    with again.dataset() as ds:
        assert ds["race_inner.load"].attrs["units"] == "N" and ds.sizes["time"] == first.summary["samples"]


def test_params_files_reach_every_case_of_the_studies_that_gained_them(tmp_path):
    """--params in the fault study (beside each machine's own file) and in the gear-quality study."""
    from scenarios import fault_study, gear_quality
    from scenarios.core.sweep import build_params

    common, dent = tmp_path / "common.toml", tmp_path / "dent.toml"
    common.write_text('[bearing]\nclearance = "30 um"\n')
    dent.write_text('[[errors.pinhole]]\nplanet = "b1"\nradial = "0 um"\ntangential = "30 um"\n')
    a = fault_study.parse_args(["--params", str(common), "--machine", f"bent={dent}", "--faults", "runout",
                                "--directions", "forward", "--out", str(tmp_path / "f")])
    by = {c.tag: build_params(c).si() for c in fault_study.make_cases(a, tmp_path / "f")}
    assert set(by) == {"perfect", "runout", "bent"}
    assert all(si.bearing.clearance == pytest.approx(30e-6) for si in by.values())
    assert by["bent"].errors.pinhole and by["runout"].errors.runout and not by["perfect"].errors.pinhole
    a = gear_quality.parse_args(["--params", str(common), "--conditions", "3", "--gear-class", "6", "--seeds", "1",
                                 "--out", str(tmp_path / "g")])
    assert all(build_params(c).si().bearing.clearance == pytest.approx(30e-6)
               for c in gear_quality.make_cases(a, tmp_path / "g"))


# ---------------------------------------------------------------------------------------------------------------
# one vocabulary: the same option name for the same thing in every command
# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,old,new,value", [
    ("gear_quality", "--grades", "--gear-class", "6"), ("tolerance_study", "--classes", "--gear-class", "5"),
    ("spectrum", "--gear-grade", "--gear-class", "8"), ("lubricant_study", "--grades", "--oil", "VG68"),
    ("gear_quality", "--classes", "--gear-class", "6"), ("tolerance_study", "--gear-grade", "--gear-class", "5"),
])
def test_a_retired_option_name_is_refused_in_one_line_naming_the_new_one(name, old, new, value, capsys):
    import importlib
    mod = importlib.import_module(f"scenarios.{name}")
    assert mod.main([old, value, "--out", "unused"]) == USAGE
    err = capsys.readouterr().err
    assert err.startswith(f"error: {old} ") and f"use {new}" in err and err.count("\n") == 1


def test_the_tooth_class_and_the_oil_have_one_name_each():
    """--gear-class is the ISO 1328 class wherever a command takes one, --oil the ISO VG grade; no command keeps the
    old spellings in its --help."""
    from scenarios import gear_quality, lubricant_study, spectrum, tolerance_study
    assert gear_quality.parse_args(["--gear-class", "5,8"]).gear_class == [5, 8]
    assert tolerance_study.parse_args(["--gear-class", "6"]).gear_class == [6]
    assert spectrum.parse_args(["--gear-class", "8"]).gear_class == 8
    assert lubricant_study.parse_args(["--oil", "VG46,VG220"]).oil == "VG46,VG220"


@pytest.mark.parametrize("name", ["gear_quality", "tolerance_study", "spectrum", "lubricant_study"])
def test_help_names_no_retired_option(name, capsys):
    import importlib
    mod = importlib.import_module(f"scenarios.{name}")
    with pytest.raises(SystemExit):
        mod.parse_args(["--help"])
    text = capsys.readouterr().out
    assert not any(o in text for o in ("--grades", "--classes", "--gear-grade"))


def test_a_command_whose_default_conditions_differ_says_why():
    """The default --conditions is 3; a command with another default refuses to be built without the reason, and
    every --help states its default's reason."""
    import argparse

    from scenarios.core import args
    p = argparse.ArgumentParser(prog="x")
    with pytest.raises(ValueError, match="say why"):
        args.add_shared(p, "conditions", conditions="1,2")
    from scenarios import bearing_misalignment, fault_study, gear_quality, misalignment_study, paper_study, sensitivity
    for mod in (paper_study, fault_study, gear_quality, sensitivity, bearing_misalignment, misalignment_study):
        text = _help_text(mod)
        block = text[text.index("--conditions C"):].split("\n  --")[0]
        assert ":" in block.split("default", 1)[1], f"{mod.__name__}: {block}"


def _help_text(mod):
    import contextlib
    import io
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), pytest.raises(SystemExit):
        mod.parse_args(["--help"]) if hasattr(mod, "parse_args") else mod.main(["--help"])
    return " ".join(buf.getvalue().split("\n")).replace("  ", " ")


@pytest.mark.parametrize("text,unit,value", [
    ("0.01", "s", 0.01), ("10 ms", "s", 0.01), ("2 ms", "s", 0.002), ("1.5 s", "s", 1.5), ("250 us", "s", 2.5e-4),
    ("20 kHz", "Hz", 2e4), ("25000", "Hz", 25000.0), ("2000 rpm", "r/min", 2000.0), ("2000", "r/min", 2000.0),
])
def test_every_time_option_takes_a_quantity_or_plain_seconds(text, unit, value):
    """The shared number grammar: a plain number in the option's unit, or a quantity with its own unit, converted
    (1 ms = 1e-3 s, 1 kHz = 1e3 Hz)."""
    from scenarios.core import args
    assert args.positive(unit)(text) == pytest.approx(value, rel=1e-12)


def test_time_options_of_the_commands_read_quantities():
    from scenarios import duty_cycle, fault_study, gear_quality, lubricant_study, paper_study, spectrum, \
        tolerance_study
    for mod in (paper_study, fault_study, gear_quality, lubricant_study, tolerance_study, spectrum):
        a = mod.parse_args(["--settle", "10 ms", "--window", "2 ms"])
        assert (a.settle, a.window) == (pytest.approx(0.01), pytest.approx(0.002)), mod.__name__
    a = duty_cycle.parse_args(["--cycle", "examples/duty_cycles/forward.toml", "--settle", "5 ms"])
    assert a.settle == pytest.approx(0.005)


@pytest.mark.parametrize("text,words", [("10 kg", "a time with its unit"), ("-1 ms", "must be > 0 s"),
                                        ("soon", "a time with its unit")])
def test_a_bad_time_is_refused_in_one_line(text, words, tmp_path, capsys):
    assert paper_study.main(["--window", text, "--out", str(tmp_path)]) == USAGE
    err = capsys.readouterr().err
    assert "--window" in err and words in err and err.count("\n") == 1


def test_an_out_folder_that_cannot_be_made_is_refused_naming_out(tmp_path, capsys):
    """A file, a folder under a file, a place where nothing can be made (the kernel's /proc, whatever its
    permissions say): one line naming --out, exit 2; a folder that can be made leaves no trace of the check."""
    import os
    from pathlib import Path
    (tmp_path / "a_file").write_text("x")
    cases = [(tmp_path / "a_file", "exists and is not a folder"), (tmp_path / "a_file" / "sub", "is a file")]
    if os.path.isdir("/proc/self"):
        cases.append((Path("/proc/dpgt_out"), "cannot make a folder in '/proc'"))
    for out, words in cases:
        assert paper_study.main(["--mode", "static", "--out", str(out)]) == USAGE
        err = capsys.readouterr().err
        assert err.startswith("error: argument --out: ") and words in err and err.count("\n") == 1, err
    assert paper_study.parse_args(["--out", str(tmp_path / "new" / "deep")]).out == str(tmp_path / "new" / "deep")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


@pytest.mark.parametrize("unit, words", [("r/min", "or an angular velocity with its unit"),
                                         ("s", "or a time with its unit")])
def test_a_quantity_of_the_wrong_kind_is_named_with_its_article(unit, words):
    import argparse
    import re

    from scenarios.core.args import _float
    with pytest.raises(argparse.ArgumentTypeError, match=re.escape(words)):
        _float("3 kg", "a number", unit)


@pytest.mark.parametrize("name,argv", [("bearing_rig", ["--radial-load", "{}"]), ("modal", ["--set", "planets={}"])])
def test_bearing_rig_and_modal_take_overwrite_and_no_progress(name, argv, tmp_path, capsys):
    """A second run with other inputs into the same folder is refused naming what differs; --overwrite replaces it;
    --no-progress is accepted."""
    import importlib
    import json
    mod = importlib.import_module(f"scenarios.{name}")
    first, second = ("10 kN", "12 kN") if name == "bearing_rig" else ("3", "4")
    fill = lambda v: [x.format(v) for x in argv]                                     # noqa: E731
    assert mod.main([*fill(first), "--out", str(tmp_path), "--no-progress"]) == 0
    assert mod.main([*fill(first), "--out", str(tmp_path)]) == 0                     # the same inputs: runs again
    capsys.readouterr()
    assert mod.main([*fill(second), "--out", str(tmp_path)]) == USAGE
    err = capsys.readouterr().err
    assert "other parameters or settings" in err and "--overwrite" in err and second in err
    assert mod.main([*fill(second), "--out", str(tmp_path), "--overwrite"]) == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert second in json.dumps(s["run_description"])


# ---------------------------------------------------------------------------------------------------------------
# said before the run
# ---------------------------------------------------------------------------------------------------------------
def test_a_window_shorter_than_a_cage_revolution_is_said_before_the_run_as_the_run_then_measures(tmp_path, capsys):
    """Before the run: the window is shorter than a cage revolution relative to the carrier, with the window that
    covers one; after it, the run's own count of the cage's revolutions agrees (its measured period within 1 %), and
    a settle shorter than the torque ramp is said too, with the estimated run time — all before the sweep starts."""
    import re
    assert paper_study.main(["--conditions", "3", "--directions", "forward", "--settle", "2 ms", "--window", "2 ms",
                             "--workers", "1", "--no-progress", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    start = out.index("runs: 1 to run")
    before, after = out[:start], out[start:]
    assert "warning before the run (c3_forward): the window 0.002 s is shorter than a revolution of the cage" in before
    assert "ends before the sun torque's ramp" in before and "estimated run time: ≈" in before
    predicted = float(re.search(r'--window "([\d.]+) ms" or more covers one', before).group(1)) * 1e-3
    measured = float(re.search(r"inner planet bearings: the window covers [\d.]+ cage revolutions.*?a window of at "
                               r"least ([\d.e-]+) s covers one", after).group(1))
    assert predicted == pytest.approx(measured, rel=0.01)
    # the headline of such a run is not printed as a finding: the reason stands above it, and above comparison.md
    flag = after.index("not a finding: c3_forward: the window covers less than one cage revolution (inner, outer)")
    assert flag < after.index("headline (pair 1's planet bearings")
    assert (tmp_path / "comparison.md").read_text().startswith("**Not a finding**: c3_forward: the window covers")


def test_a_resumed_study_says_how_many_runs_finished_earlier(tmp_path, capsys):
    tiny = ["--conditions", "4", "--settle", "0.0005", "--window", "0.0005", "--no-progress", "--workers", "1",
            "--out", str(tmp_path)]
    assert paper_study.main([*tiny, "--directions", "forward"]) == 0
    capsys.readouterr()
    assert paper_study.main([*tiny, "--directions", "forward,reverse"]) == 0
    assert "resuming: 1 of 2 runs finished earlier" in capsys.readouterr().out


@pytest.mark.parametrize("q", [10.0, 50.0, 90.0, 99.0])
def test_the_fewest_samples_for_a_percentile_are_where_it_stops_being_the_extreme_value(q):
    """numpy's Hazen percentile of m distinct values is the largest (or smallest) value for m below the count the
    tolerance study asks for, and strictly inside the values from that count on."""
    from scenarios.tolerance_study import fewest_samples
    rng = np.random.default_rng(3)
    need = fewest_samples(q)
    for m in range(1, need + 3):
        x = rng.permutation(np.arange(m, dtype=float))
        v = np.percentile(x, q, method="hazen")
        extreme = v == (x.max() if q > 50 else x.min())
        assert extreme == (m < need), (q, m, v)


def test_too_few_samples_for_a_percentile_are_said_before_the_run_and_above_the_answer(capsys):
    from scenarios.tolerance_study import too_few_samples
    few = too_few_samples(4, 1)                       # a P90 from 4 machines
    assert any(w.startswith("P90 from 4 machines") and "--samples 6 or more" in w for w in few)
    assert any(w.startswith("P99") and "--samples 51 or more" in w for w in few)
    assert [w.split()[0] for w in too_few_samples(64, 8)] == ["P99"]   # 8 per replicate: P90 and P10 stand
    assert [w.split()[0] for w in too_few_samples(400, 8)] == ["P99"]   # 50 per replicate: P99 is the largest
    assert too_few_samples(408, 8) == []


def test_params_refuses_a_machine_that_cannot_be_built_as_a_run_would(capsys):
    """A 40 mm roller on a 39 mm pitch circle leaves no pin: `dpgt params` refuses it in the words of the design
    check a run makes, not a table of a machine that cannot exist."""
    from scenarios import params
    assert params.main(["--set", "bearing.roller_diameter=40 mm"]) == USAGE
    err = capsys.readouterr().err
    assert err.startswith("error: bearing.roller_diameter") and "leaves no pin" in err and err.count("\n") == 1
    assert params.main(["--set", "bearing.roller_diameter=7 mm", "--grep", "roller_diameter"]) == 0
    assert "7 mm" in capsys.readouterr().out


def test_spectrum_says_the_design_warnings_the_other_commands_say(tmp_path, monkeypatch, capsys):
    """The reference machine's two tip-circle overlaps, said before anything runs (the run stopped right after)."""
    from scenarios import spectrum

    def stop(*a, **k):
        raise SystemExit("error: stopped after the checks")
    monkeypatch.setattr(spectrum, "check_runs", stop)
    assert spectrum.main(["--out", str(tmp_path)]) == USAGE
    out = capsys.readouterr().out
    assert out.count("design warning: gears.") == 2 and "tip circles" in out


@pytest.mark.parametrize("key,words", [("gears.inner_planet.addendum_coefficient", "the inner planets and the ring"),
                                       ("gears.ring.addendum_coefficient", "the inner planets and the ring"),
                                       ("gears.sun.addendum_coefficient", "the sun and outer planet"),
                                       ("gears.outer_planet.addendum_coefficient", "the sun and outer planet")])
def test_a_design_warning_names_the_parameter_value_that_removes_it(key, words):
    """The tip-circle overlap's warning names each gear's addendum coefficient that removes it: at that value the
    warning is gone, a hundredth above it is still there (the tip radius moves by h_a m)."""
    import re
    import warnings

    from components.geometry import design_findings
    from components.params import with_overrides
    from components.presets import reference_dpgt
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = [str(f) for f in design_findings(reference_dpgt(3)) if words in str(f)]
        assert len(found) == 1
        limit = float(re.search(re.escape(key) + r" <= ([\d.]+)", found[0]).group(1))
        at = [str(f) for f in design_findings(with_overrides(reference_dpgt(3), {key: limit})) if words in str(f)]
        above = [str(f) for f in design_findings(with_overrides(reference_dpgt(3), {key: limit + 0.01}))
                 if words in str(f)]
    assert at == [] and len(above) == 1


def test_a_reader_that_stops_reading_ends_the_command_quietly():
    """`dpgt params | head`: the pipe closed before the command writes is not an error (no message, exit 0)."""
    import subprocess
    import sys as _sys
    p = subprocess.Popen([_sys.executable, "-m", "scenarios.params"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()                                    # the reader is gone before anything is written
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 0 and err == "", err
