"""Statistics that cannot mean anything are said, never reported silently or interpreted: a window
shorter than one cage revolution relative to the carrier, a carrier drive not settled, a load ramp inside the
window, a spectrum over fewer than four carrier revolutions."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from components.presets import reference_dpgt
from scenarios.core.analysis import MIN_REVOLUTIONS, sideband_resolution
from scenarios.fault_study import findings
from scenarios.core.runner import SETTLED_SPEED_ERROR_PCT, RunConfig, run_case, statistics_warnings


def _summary(revs=3.0, err=0.0, span=0.021):
    b = {"cage_revolutions": revs, "window_s": [0.03, 0.03 + span]}
    return {"inner": dict(b), "outer": dict(b), "carrier_speed_error_mean_pct": err}


def test_statistics_warnings_at_their_thresholds():
    """One cage revolution, 0.1 % of mean speed error and a ramp ending at the settle are the limits."""
    assert statistics_warnings(_summary(), 0.01, 0.03) == []
    assert statistics_warnings(_summary(revs=1.0, err=SETTLED_SPEED_ERROR_PCT), 0.03, 0.03) == []
    w = statistics_warnings(_summary(revs=0.25, span=0.005), 0.0, 0.03)
    assert len(w) == 2 and all("0.25 cage revolutions" in x and "0.02 s covers one" in x for x in w)
    w = statistics_warnings(_summary(err=-0.15), 0.0, 0.002)
    assert w == [w[0]] and "-0.15 %" in w[0] and "--settle than 0.002 s" in w[0]
    w = statistics_warnings(_summary(), 0.004, 0.002)
    assert w == [w[0]] and "ramp (0.004 s) ends inside the window" in w[0]


def test_a_too_short_run_says_what_its_statistics_cannot_mean(tmp_path):
    """Condition 3, settle 2 ms (inside the 3.5 ms load ramp, before the drive settles), window 4 ms (0.6 cage
    revolutions): all three warnings in summary.json, with the run's own numbers (measured +0.61 % speed error)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = run_case(reference_dpgt(3), RunConfig(settle=0.002, window=0.004, progress=False), tmp_path)
    text = "\n".join(s["warnings"])
    revs = s["inner"]["cage_revolutions"]
    assert 0.4 < revs < 0.8 and f"{revs:.2f} cage revolutions" in text
    assert abs(s["carrier_speed_error_mean_pct"]) > SETTLED_SPEED_ERROR_PCT and "had not settled" in text
    assert "ramp" in text and "ends inside the window" in text


def test_a_spectrum_needs_four_carrier_revolutions():
    """Over N carrier revolutions each carrier order's Hann main lobe fills 3 of the N bins between two orders: from
    4 on the floor has bins of its own (scenarios.core.analysis.band_floor)."""
    fc, dt = 33.3, 5e-5
    for revs, ok in ((2.9, False), (MIN_REVOLUTIONS, True), (4.0, True), (1.0, False)):
        t = np.arange(int(round(revs / fc / dt))) * dt
        why = sideband_resolution(t, fc)
        assert (why is None) == ok, (revs, why)
        if not ok:
            assert f"{revs:.2g} carrier revolutions" in why


def test_fault_findings_give_no_sensor_verdict_on_too_short_a_window():
    row = lambda fault, life, line, notes="": {
        "fault": fault, "condition": 2, "direction": "forward", "bearing": "outer", "life_iso16281_h": life,
        "load_sharing_factor": 1.0, "bearing_load_max_N": 1.0, "sensor_f_m": line, "sensor_f_m-1f_c": line, "sensor_f_m+1f_c": line,
        "sensor_f_m-3f_c": line, "sensor_f_m+3f_c": line, "sensor_own": None, "own_frequency": None, "notes": notes}
    text = findings([row("perfect", 100.0, None, "too few"), row("pinhole", 50.0, None, "the spectrum covers 0.33")])
    assert "mean nothing here" in text and "hears it" not in text and "[not meaningful: the spectrum covers 0.33]" in text
    text = findings([row("perfect", 100.0, 2.0), row("pinhole", 50.0, 20.0)])
    assert "the sensor hears it" in text and "not meaningful" not in text
