"""A study's sweep owns its axes: an override of one by --set or a --params file would silently
relabel runs (a folder c3_forward holding a reverse run), so every study refuses it in one line naming the key,
where it came from and the option to use; a --params file that is not UTF-8 TOML is a usage error naming it.
Two exceptions, by design: a machine file's whole [operating] table (speed and power) is that machine's own
operating point (scenarios.core.points), and a file that sets the oil is taken by the lubricant study, whose
sweep's oils replace it (said in one line)."""
from __future__ import annotations

import pytest

from scenarios import fault_study, gear_quality, lubricant_study, paper_study


@pytest.fixture()
def files(tmp_path):
    rev = tmp_path / "rev.toml"
    rev.write_text('[operating]\ndirection = "reverse"\n')
    oil = tmp_path / "oil.toml"
    oil.write_text('[lubricant]\nviscosity_40 = "20 mm^2/s"\n')
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe not text")
    dent = tmp_path / "dent.toml"
    dent.write_text('[[errors.pinhole]]\nplanet = "b1"\nradial = "0 um"\ntangential = "30 um"\n')
    return {"rev": rev, "oil": oil, "bad": bad, "dent": dent}


@pytest.mark.parametrize("study, argv, message", [
    (paper_study, ["--params", "{rev}"], "operating.direction is set by this study's --directions, not by --params"),
    (paper_study, ["--set", "operating.direction=reverse"], "operating.direction is set by this study's --directions, not by --set"),
    (paper_study, ["--set", "operating.carrier_speed=100 rpm"], "operating.carrier_speed is set by this study's --conditions"),
    (paper_study, ["--params", "{bad}"], "--params {bad}: 'utf-8' codec"),
    (lubricant_study, ["--set", "lubricant.oil_viscosity=0.02 Pa*s"], "lubricant.oil_viscosity is set by this study's"),
    (lubricant_study, ["--viscosities", "30"], "--viscosities: give the unit"),
    (fault_study, ["--set", "errors.tooth_fault=[]"], "errors.tooth_fault is set by this study's --faults or --machine"),
    (fault_study, ["--machine", "runout={dent}"], "the name 'runout' is a catalogue fault's"),
    (fault_study, ["--machine", "perfect={dent}"], "the name 'perfect' is the perfect machine's"),
    (fault_study, ["--machine", "mine={rev}"], "operating.direction is set by this study's --directions, not by --params"),
    (gear_quality, ["--set", "errors.flank_class=[]"], "errors.flank_class is set by this study's --gear-class and --seeds"),
])
def test_a_study_refuses_overrides_of_its_own_axes(study, argv, message, files, tmp_path, capsys):
    argv = [x.format(**files) for x in argv]
    assert study.main([*argv, "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert message.format(**files) in err and "\n" not in err, err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_other_overrides_still_pass(files, tmp_path):
    """Parameters no sweep axis owns go through, from --set and from a file."""
    a = paper_study.parse_args(["--params", str(files["dent"]), "--set", "bearing.clearance=30 um", "--out",
                                str(tmp_path / "o")])
    case = paper_study.make_cases(a, tmp_path / "o")[0]
    from scenarios.core.sweep import build_params
    p = build_params(case)
    assert p.si().bearing.clearance == pytest.approx(30e-6) and p.si().errors.pinhole[0].tangential == pytest.approx(30e-6)
    assert p.si().operating.direction == case.direction


@pytest.mark.parametrize("module, argv, message", [
    ("spectrum", ["--perfect", "--gear-class", "8"], "--gear-class 8 contradicts --perfect"),
    ("spectrum", ["--params", "{dent}", "--gear-class", "8"], "--gear-class 8 contradicts the manufacturing errors"),
    ("modal", ["--dpgt", "--params", "{dent}"], "describes a single planetary set; with --dpgt"),
    ("modal", ["--dpgt", "--set", "bearing.clearence=30 um"], "bearing.clearence"),
])
def test_contradicting_or_ignored_options_are_refused(module, argv, message, files, tmp_path, capsys):
    """Options that contradict each other, or that one mode of a command would silently ignore, end in one line."""
    import importlib
    mod = importlib.import_module(f"scenarios.{module}")
    argv = [x.format(**files) for x in argv]
    assert mod.main([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err, err
