"""The refusal to replace a folder's finished results of other parameters names what differs."""
from __future__ import annotations

import warnings

import pytest

from components.params import with_overrides
from components.presets import reference_dpgt
from scenarios.core.integrity import OtherResults, differences
from scenarios.core.runner import RunConfig, run_case


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
