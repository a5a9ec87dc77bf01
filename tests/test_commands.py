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
    assert capsys.readouterr().err.strip() == "error: --conditions takes 1, 2, 3 and/or 4 (PARAMETERS.md), got 7"
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
