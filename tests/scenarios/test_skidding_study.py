"""The skidding study (scenarios.skidding_study): its cases are the operating points it says, with the skid laws
unless --set says otherwise, and its answer reads synthetic rows as they are."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from scenarios import skidding_study
from scenarios.core.sweep import build_params


def test_the_cases_are_every_power_oil_and_direction_at_the_speed_with_the_skid_laws(tmp_path):
    a = skidding_study.parse_args(["--speed", "1500 rpm", "--powers", "0,50", "--oil-temperatures", "30,90",
                                   "--directions", "reverse", "--set", "bearing.drag_law=inertial",
                                   "--out", str(tmp_path)])
    cases = skidding_study.make_cases(a, Path(tmp_path))
    assert [c.label for c in cases] == ["p0kW_oil30C_reverse", "p0kW_oil90C_reverse", "p50kW_oil30C_reverse",
                                        "p50kW_oil90C_reverse"]
    seen = set()
    for c in cases:
        si = build_params(c).si()
        assert abs(si.operating.carrier_speed) == pytest.approx(1500 * 2 * math.pi / 60)     # 1500 r/min in rad/s
        seen.add((round(abs(si.operating.output_power)), round(si.lubricant.temperature - 273.15, 6)))
        assert si.bearing.traction_law == "ehl" and si.bearing.rolling_resistance == "houpert"
        assert si.bearing.drag_law == "inertial"                   # --set replaces the study's law
    assert seen == {(0, 30.0), (0, 90.0), (50000, 30.0), (50000, 90.0)}


def test_oil_grades_are_an_axis_of_the_grid_with_their_iso_viscosities(tmp_path):
    """--oil VG32,VG150: every power and temperature once per grade, the grade's ISO 3448 viscosity at 40 °C and the
    folders named for it; a --set of the viscosity the grade owns is refused by name."""
    a = skidding_study.parse_args(["--powers", "2", "--oil-temperatures", "40", "--oil", "VG32,VG150",
                                   "--directions", "forward", "--out", str(tmp_path)])
    cases = skidding_study.make_cases(a, Path(tmp_path))
    assert [c.label for c in cases] == ["p2kW_oil40C_VG32_forward", "p2kW_oil40C_VG150_forward"]
    nu40 = [build_params(c).si().lubricant.viscosity_40 for c in cases]
    assert nu40 == pytest.approx([32e-6, 150e-6])                      # mm²/s in m²/s
    assert [skidding_study.grade_of(c) for c in cases] == ["VG32", "VG150"]
    plain = skidding_study.make_cases(skidding_study.parse_args(["--powers", "2", "--oil-temperatures", "40",
                                                                 "--directions", "forward", "--out", str(tmp_path)]),
                                      Path(tmp_path))
    assert skidding_study.grade_of(plain[0]) == skidding_study.MACHINE_OIL
    with pytest.raises(SystemExit, match="lubricant.viscosity_40"):
        skidding_study.make_cases(skidding_study.parse_args(["--oil", "VG32", "--set", "lubricant.viscosity_40=40 mm^2/s",
                                                             "--out", str(tmp_path)]), Path(tmp_path))


def test_the_answer_reads_the_trend_with_the_oil_grade():
    """Slip 60 % with VG32 and 40 % with VG150 at one load and temperature: it falls as the grade rises."""
    rows = [_row(2, 40, "forward", "outer", 0.7, 1.1), _row(2, 40, "forward", "outer", 0.6, 1.1)]
    for r, g, unloaded in zip(rows, ("VG32", "VG150"), (60.0, 40.0)):
        r.update(oil_grade=g, roller_slip_unloaded_pct=unloaded, roller_slip_entry_pct=70.0)
    text = skidding_study.answer(rows)
    assert "oil 40 °C VG32, forward, outer: 2 kW +0.70 (1.10)" in text
    assert "roller slip out of the load zone falls as the oil grade rises in 1 of 1 series, rises in 0." in text


def _row(P, T, d, kind, slip, ratio):
    return {"power_kW": P, "oil_temperature_C": T, "direction": d, "bearing": kind, "cage_slip_pct": slip,
            "load_over_minimum": ratio}


def test_the_answer_reads_skid_and_trends_from_synthetic_rows():
    """Slip 8 % at 2 kW (above SKID_PCT = 5 %) and 0.5 % at 200 kW in cold oil, 3 % and 0.2 % in warm oil: the
    cold 2 kW point skids, nothing else; |slip| falls with load in both series and with temperature in both."""
    rows = [_row(2, 40, "forward", "inner", 8.0, 0.9), _row(200, 40, "forward", "inner", 0.5, 12.0),
            _row(2, 80, "forward", "inner", 3.0, 0.9), _row(200, 80, "forward", "inner", -0.2, 12.0)]
    text = skidding_study.answer(rows)
    assert "oil 40 °C, forward, inner: 2 kW +8.00 (0.90), 200 kW +0.50 (12.00) -> skids at 2 kW" in text
    assert "oil 80 °C, forward, inner: 2 kW +3.00 (0.90), 200 kW -0.20 (12.00) -> no skid" in text
    assert "cage |slip| falls as the load rises in 2 of 2 series, rises in 0." in text
    assert "cage |slip| falls as the oil temperature rises in 2 of 2 series, rises in 0." in text
    assert "roller slip" not in text                  # rows without a recording: no roller numbers


def test_the_answer_counts_the_rollers_trends_where_the_rows_have_them():
    """Roller slip out of the load zone 60 → 2 % from 2 to 200 kW and 60 → 50 % from 40 to 80 °C: it falls with load
    and with oil temperature in every series, and each line names the rollers' numbers."""
    rows = [_row(2, 40, "forward", "outer", 0.7, 1.1), _row(200, 40, "forward", "outer", 0.1, 19.0),
            _row(2, 80, "forward", "outer", 0.7, 1.1)]
    for r, unloaded, entry in zip(rows, (60.0, 2.0, 50.0), (75.0, 3.0, 65.0)):
        r.update(roller_slip_unloaded_pct=unloaded, roller_slip_entry_pct=entry)
    text = skidding_study.answer(rows)
    assert "roller slip at load-zone entry / out of the load zone: 2 kW 75.0 % / 60.0 %, 200 kW 3.0 % / 2.0 %" in text
    assert "roller slip out of the load zone falls as the load rises in 1 of 1 series, rises in 0." in text
    assert "roller slip out of the load zone falls as the oil temperature rises in 1 of 1 series, rises in 0." in text


def test_the_figures_are_drawn_from_rows_with_and_without_a_recording(tmp_path):
    """slip_against_load.png always; roller_slip_by_angle.png from the coldest oil's rows that carry angles."""
    rows = [_row(2, 40, "forward", "inner", 0.7, 0.9), _row(200, 40, "forward", "inner", -1.2, 6.4)]
    for r in rows:
        r.update(roller_slip_unloaded_pct=50.0, roller_slip_entry_pct=70.0, lambda_min=2.5,
                 by_angle={"angle_deg": [45.0, 135.0, 225.0, 315.0], "slip_by_angle_pct": [80.0, 0.0, 20.0, 60.0],
                           "loaded_by_angle": [0.0, 1.0, 0.0, 0.0]})
    files = skidding_study.plot(rows, tmp_path)
    assert [f.name for f in files] == ["slip_against_load.png", "roller_slip_by_angle.png"]
    assert all(f.stat().st_size > 10_000 for f in files)
    for r in rows:
        del r["by_angle"]
    assert [f.name for f in skidding_study.plot(rows, tmp_path / "x")] == ["slip_against_load.png"]


def test_the_transients_schedules_say_what_the_options_ask(tmp_path):
    """startup: the speed from --start-speed to 1 in --ramp-time from --settle + --before, the torque the square of
    the speed at every knot (k ω²); torque_drop: from the largest to the smallest of --powers in --drop-time."""
    a = skidding_study.parse_args(["--transients", "torque_drop,startup", "--powers", "5,250", "--settle", "0.01",
                                   "--before", "0.02", "--ramp-time", "0.08", "--start-speed", "0.2",
                                   "--drop-time", "0.004", "--out", str(tmp_path)])
    knots, t0, length = skidding_study.transient_schedule("startup", a)
    assert t0 == pytest.approx(0.03) and length == 0.08
    times = [float(k["time"].split()[0]) for k in knots]
    assert times[0] == pytest.approx(0.03) and times[-1] == pytest.approx(0.11)
    assert knots[0]["speed"] == pytest.approx(0.2) and knots[-1]["speed"] == 1.0
    for k in knots:
        assert k["torque"] == pytest.approx(k["speed"] ** 2, rel=1e-15)
    knots, t0, length = skidding_study.transient_schedule("torque_drop", a)
    assert [k["torque"] for k in knots] == [1.0, pytest.approx(5 / 250)] and [k["speed"] for k in knots] == [1.0, 1.0]
    assert float(knots[1]["time"].split()[0]) - float(knots[0]["time"].split()[0]) == pytest.approx(0.004)


def test_transient_cases_run_at_the_largest_power_beside_the_grids_steady_runs(tmp_path):
    """Each transient × oil × direction is a case at the largest power with its schedule and window; the steady run
    at its final point is the grid's own case (same label and parameters: a run of the grid is reused)."""
    a = skidding_study.parse_args(["--transients", "startup,torque_drop", "--powers", "2,200", "--oil-temperatures",
                                   "40", "--directions", "forward", "--out", str(tmp_path)])
    cases = skidding_study.make_transient_cases(a, Path(tmp_path))
    assert [c.label for c in cases] == ["p200kW_oil40C_forward_startup", "p200kW_oil40C_forward_torque_drop",
                                        "p200kW_oil40C_forward", "p2kW_oil40C_forward"]
    start, drop = cases[0], cases[1]
    assert start.window == pytest.approx(a.before + a.ramp_time + a.after)
    assert drop.window == pytest.approx(a.before + a.drop_time + a.after)
    si = build_params(drop).si()
    assert si.operating.output_power == pytest.approx(200e3) and si.bearing.traction_law == "ehl"
    assert [k.torque for k in si.operating.schedule] == [1.0, pytest.approx(0.01)]
    grid = {c.label: c for c in skidding_study.make_cases(a, Path(tmp_path))}
    for steady in cases[2:]:
        assert steady.overrides == grid[steady.label].overrides and steady.window is None
        assert not build_params(steady).si().operating.schedule


def test_an_unknown_transient_is_a_usage_error(tmp_path):
    with pytest.raises(SystemExit, match=r"--transients: .* got 'startp' \(did you mean 'startup'\?\)"):
        skidding_study.parse_args(["--transients", "startp", "--out", str(tmp_path)])


@pytest.mark.slow
def test_after_a_torque_drop_the_slip_settles_on_the_steady_runs(tmp_path):
    """200 → 2 kW in 2 ms at 1000 r/min, oil 40 °C, the study's laws; 60 ms later (two cage revolutions relative to
    the carrier) the cage and roller slip of the last fifth of the recording (components.skid.slip_series, 5 ms
    bins) equal the steady 2 kW run's summary: the cage within 0.1 slip points, the rollers out of the load zone
    within 3 and at its entry within 5 (the recording's samples against every step, and the few entries of 14 ms;
    the study's own 0.45 s run: 0.00 / 1.2 / 2.6 points). A drop that did not happen is off by ≈ 50 points out of
    the load zone, one to 20 kW by 5–8 (the steady 20 kW runs)."""
    import dataclasses
    import warnings

    from components.results import open_dataset
    from components.skid import slip_series, transient_numbers
    from scenarios.core.runner import RunConfig, run_case

    a = skidding_study.parse_args(["--transients", "torque_drop", "--powers", "2,200", "--oil-temperatures", "40",
                                   "--directions", "forward", "--before", "0.01", "--after", "0.06", "--out",
                                   str(tmp_path)])
    cases = skidding_study.make_transient_cases(a, Path(tmp_path))
    drop, steady = cases[0], cases[1]
    cfg = skidding_study.SkiddingStudy(a).config()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s_steady = run_case(build_params(steady), cfg, Path(steady.out_dir))
        run_case(build_params(drop), dataclasses.replace(cfg, window=drop.window), Path(drop.out_dir))
    _, t0, _ = skidding_study.transient_schedule("torque_drop", a)
    with open_dataset(Path(drop.out_dir) / "results.nc") as ds:
        series = slip_series(ds, 0.005)
    for kind in ("inner", "outer"):
        for name, key, tol in (("cage", "cage_slip_all_pct", 0.1), ("unloaded", "roller_slip_unloaded_pct", 3.0),
                               ("entry", "roller_slip_entry_pct", 5.0)):
            n = transient_numbers(series[kind]["time_s"], series[kind][name], t0, s_steady[kind][key], 10.0, 1.0)
            assert n["final"] == pytest.approx(n["steady"], abs=tol), (kind, name, n)
