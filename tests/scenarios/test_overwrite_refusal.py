"""The refusal to replace a folder's finished results of other parameters names what differs; what changes no result
(the engine's threads) is not among what it compares."""
from __future__ import annotations

import argparse
import warnings

import pytest

from components.params import with_overrides
from components.presets import reference_dpgt
from mbd import ModelError
from mbd.compiled.system import usable_cores
from scenarios import paper_study
from scenarios.core.integrity import OtherResults, command_inputs, differences
from scenarios.core.runner import (RunConfig, _settings, parameters_fingerprint, run_case, run_description,
                                   run_fingerprint)


def test_differences_lists_the_changed_keys_with_both_values():
    old = {"a": "1", "b": "2", "c": "3"}
    assert differences(old, dict(old)) == "" and differences(None, old) == ""
    assert differences(old, {"a": "1", "b": "5", "c": "3"}) == " (b: 2 → 5)"
    assert differences(old, {"a": "0", "b": "0", "d": "4"}, most=2) == " (a: 1 → 0, b: 2 → 0 and 2 more)"


def test_a_refused_run_names_the_parameters_and_settings_that_differ(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_case(reference_dpgt(3), RunConfig(settle=0.001, window=0.001, progress=False), tmp_path)
        other = with_overrides(reference_dpgt(3), {"bearing.clearance": "30 um"})
        with pytest.raises(OtherResults) as e:
            run_case(other, RunConfig(settle=0.0015, window=0.001, progress=False), tmp_path)
    msg = str(e.value)
    assert "bearing.clearance: 20 micrometer → 30 micrometer" in msg and "settings.settle: 0.001 → 0.0015" in msg
    assert "--overwrite" in msg and "\n" not in msg


def test_the_engine_s_threads_are_no_run_setting_and_a_bad_count_is_refused():
    """Threads change no result (mbd.simulate, bit for bit): a run on 2 threads has the fingerprints of one on 1, so
    the folder of either is reused by the other and never refused; --threads is not among a command's inputs; a
    count outside 1 to the usable cores is refused in one line."""
    params, one = reference_dpgt(3), RunConfig()
    assert "threads" not in _settings(one) and "settings.threads" not in run_description(params, one)
    if usable_cores() >= 2:
        two = RunConfig(threads=2)
        assert run_fingerprint(params, two) == run_fingerprint(params, one)
        assert parameters_fingerprint(params, two) == parameters_fingerprint(params, one)
    assert run_fingerprint(params, RunConfig(window=0.01)) != run_fingerprint(params, one)    # a setting does change it
    for bad in (0, usable_cores() + 1, 1.5):
        with pytest.raises(ModelError, match=r"^threads must be an integer from 1 to the \d+ usable cores"):
            RunConfig(threads=bad)
    a = paper_study.parse_args(["--threads", "1"])
    assert a.threads == 1 and paper_study.parse_args([]).threads == 1
    assert "threads" not in command_inputs(argparse.Namespace(threads=2, conditions="3", out="x"), files=())
