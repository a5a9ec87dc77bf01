"""Scenarios end to end in reduced form (short windows, few rollers): documented outputs, sane values."""
from __future__ import annotations

import csv
import json
import time

import numpy as np
import pytest

from scenarios import paper_study, spectrum

SUMMARY_KEYS = {"condition", "direction", "carrier_rpm", "sun_rpm", "power_W", "planets", "rollers", "window_s",
                "wall_s", "steps", "error_estimate", "inner", "outer"}
BEARING_KEYS = {"roller_cage_rms_N", "roller_cage_max_N", "cage_guide_rms_N", "cage_guide_max_N",
                "roller_inner_race_rms_N", "roller_inner_race_max_N", "roller_outer_race_rms_N",
                "roller_outer_race_max_N", "cage_acc_x_rms_m_s2", "cage_acc_y_rms_m_s2", "bearing_load_mean_N",
                "life_L10_relative", "all_rollers", "cage_acc_radial_rms_m_s2", "cage_acc_tangential_rms_m_s2",
                "cage_acc_magnitude_rms_m_s2", "cage_acc_rel_radial_rms_m_s2", "cage_acc_rel_tangential_rms_m_s2",
                "cage_acc_rel_magnitude_rms_m_s2", "pocket_impacts_per_rev", "pocket_impact_speed_max_m_s",
                "pocket_impact_peak_max_N", "cage_slip_pct", "life_iso281_h", "life_iso16281_h",
                "roller_equivalent_load_pin_N", "roller_equivalent_load_bore_N", "dynamic_load_rating_N"}

SIGNED = {"bearing_load_radial_mean_N", "bearing_load_tangential_mean_N", "cage_slip_pct", "cage_slip_all_pct",
          "roller_slip_load_zone_pct", "roller_slip_unloaded_pct", "roller_slip_entry_pct", "roller_entry_slide_roll"}

REDUCED = ["--settle", "0.002", "--window", "0.001", "--set", "bearing.rollers=8", "--no-progress",
           "--workers", "1"]


@pytest.fixture(scope="module")
def zero_power_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    r = paper_study.run(paper_study.parse_args(["--conditions", "4", "--out", str(out)] + REDUCED))
    return out, r


def test_study_writes_documented_outputs(zero_power_study):
    out, r = zero_power_study
    assert not r["failed"]
    for d in ("forward", "reverse"):
        s = json.loads((out / f"c4_{d}" / "summary.json").read_text())
        assert SUMMARY_KEYS <= set(s)
        assert s["condition"] == 4 and s["direction"] == d and s["rollers"] == 8 and s["planets"] == 3
        assert s["power_W"] == 0.0 and abs(abs(s["carrier_rpm"]) - 4200) < 1e-9
        assert s["window_s"] == pytest.approx([0.002, 0.003])
        for kind in ("inner", "outer"):
            assert BEARING_KEYS <= set(s[kind])
            for k, v in s[kind].items():
                if isinstance(v, float):        # magnitudes are >= 0; signed: mean load components, slip
                    assert np.isfinite(v) and (v >= 0 or k in SIGNED), (kind, k, v)
        for kind in ("inner", "outer"):       # both lives, pair 1's bearing and the kind pooled, consistent
            _check_lives(s[kind])
        assert (out / f"c4_{d}" / "results.nc").exists()
    rows = list(csv.DictReader((out / "comparison.csv").open()))
    assert {r["quantity"] for r in rows} >= {"bearing_load_mean_N", "roller_cage_rms_N", "life_L10_relative",
                                             "life_iso281_h", "life_iso16281_h"}
    assert "| bearing | quantity | forward | reverse | reverse − forward | change |" in \
        (out / "comparison.md").read_text()
    for name in ("bars.png", "bearing_load_life.png", "c4_bearing_loads.png", "c4_roller_contacts.png", "c4_cage.png",
                 "c4_mesh.png", "c4_cage_orbit_inner.png", "c4_cage_orbit_outer.png"):
        assert (out / name).stat().st_size > 10_000, name
    assert {p.name for p in r["figures"]} >= {"bars.png", "bearing_load_life.png", "c4_cage_orbit_inner.png"}


def test_study_figures_show_the_runs_data(zero_power_study):
    """The time-history groups carry results.nc's series of pair 1 unchanged (SI; the figure converts), and the
    headline's values are the summaries' numbers."""
    import xarray as xr

    out, r = zero_power_study
    runs = {d: out / f"c4_{d}" / "results.nc" for d in ("forward", "reverse")}
    groups = paper_study.history_groups(runs)
    assert set(groups) == set(paper_study.HISTORY_GROUPS)
    assert groups["mesh"][1] == list(paper_study.MESH_COLUMNS)
    rows = {w: (u, by) for w, u, by in groups["bearing_loads"][0]}
    unit, by_col = rows["bearing load, radial (+ outward)"]
    assert unit == "N" and set(by_col) == {"inner", "outer"} and set(by_col["outer"]) == {"forward", "reverse"}
    with xr.open_dataset(runs["reverse"], engine="h5netcdf") as ds:
        names = list(ds["bearing.load_radial.instance"].values)
        t, y = by_col["outer"]["reverse"]
        np.testing.assert_array_equal(t, ds["time"].values)
        np.testing.assert_array_equal(y, ds["bearing.load_radial"].values[:, names.index("b1.pb")])
    # the mesh row is the drive flank's force minus the coast flank's: results.nc holds flank +1's minus flank
    # −1's, and the torque path loads flanks (−1, +1, +1) of (sun–inner, inner–outer, outer–ring) forward and the
    # others in reverse (components.geometry.loaded_flanks; the sun's speed decides it at zero power)
    mesh = {w: by for w, _, by in groups["mesh"][0]}
    assert set(mesh) == {paper_study.MESH_FORCE_WORDS, "loaded transmission error"}
    assert paper_study.MESH_FORCE_WORDS == "drive-flank force − coast-flank force"
    loaded = {"forward": {"sun_inner": -1, "inner_outer": 1, "outer_ring": 1}}
    loaded["reverse"] = {k: -f for k, f in loaded["forward"].items()}
    from components.families import MESH_FAMILY
    for d, path in runs.items():
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            for key, sign in loaded[d].items():
                t, y = mesh[paper_study.MESH_FORCE_WORDS][key][d]
                np.testing.assert_array_equal(y, sign * ds[f"{MESH_FAMILY[key]}.force"].values[:, 0])
                drive, coast = ("force_drive", "force_coast") if sign > 0 else ("force_coast", "force_drive")
                fam = MESH_FAMILY[key]     # the element's own flank forces: drive − coast, sample by sample
                np.testing.assert_allclose(y, ds[f"{fam}.{drive}"].values[:, 0] - ds[f"{fam}.{coast}"].values[:, 0],
                                           rtol=0, atol=1e-9 * max(1.0, float(np.abs(y).max())))
    vals = paper_study.headline_values(r["results"])
    for d in ("forward", "reverse"):
        s = json.loads((out / f"c4_{d}" / "summary.json").read_text())
        for kind in ("inner", "outer"):
            assert vals[("bearing_load_mean_N", 4, kind, d)] == s[kind]["bearing_load_mean_N"]
            assert vals[("life_iso16281_h", 4, kind, d)] == s[kind]["life_iso16281_h"]


def _check_lives(d):
    """The summary's lives follow from its own loads through components.life, in hours at the planet's
    speed relative to the pin; the ISO/TS 16281-style life sees the roller loads, not only the bearing's."""
    from components.life import iso281_life, lundberg_palmgren_life
    from components.presets import reference_bearing

    b = reference_bearing().replace(rollers=8).si()
    for target in (d, d["all_rollers"]):
        assert target["life_iso281_h"] > 0 and target["life_iso16281_h"] > 0
        assert target["life_iso16281_Mrev"] == pytest.approx(
            lundberg_palmgren_life(target["roller_equivalent_load_pin_N"], target["roller_equivalent_load_bore_N"], b),
            rel=1e-12)
        # one conversion to hours for both lives: the same relative speed
        assert target["life_iso281_h"] / target["life_iso281_Mrev"] == pytest.approx(
            target["life_iso16281_h"] / target["life_iso16281_Mrev"], rel=1e-12)
    assert d["life_iso281_Mrev"] == pytest.approx(iso281_life(d["equivalent_load_N"], b), rel=1e-12)
    # power means over the same rollers and windows: RMS (p = 2) < Q_e (p = 4, 4.5) < max
    al = d["all_rollers"]
    for race, key in (("inner", "pin"), ("outer", "bore")):
        assert al[f"roller_{race}_race_rms_N"] < al[f"roller_equivalent_load_{key}_N"] < al[f"roller_{race}_race_max_N"]


def test_zero_power_forward_and_reverse_agree(zero_power_study):
    """With no transmitted power the bearing load is centrifugal (+ gravity): the direction of rotation
    must not change the mean bearing load by more than 2 % (docs/model.md §15.6 in spirit). The relative life the
    study writes into each summary is ISO 281's (P_forward/P)^(10/3) of the two runs' equivalent loads (the
    forward run's is 1 by definition; the reverse's is what carries information)."""
    out, _ = zero_power_study
    f = json.loads((out / "c4_forward" / "summary.json").read_text())
    r = json.loads((out / "c4_reverse" / "summary.json").read_text())
    for kind in ("inner", "outer"):
        a, b = f[kind]["bearing_load_mean_N"], r[kind]["bearing_load_mean_N"]
        assert abs(b - a) / a < 0.02, (kind, a, b)
        assert f[kind]["life_L10_relative"] == 1.0
        ratio = f[kind]["equivalent_load_N"] / r[kind]["equivalent_load_N"]
        assert abs(ratio - 1.0) > 1e-6          # the two directions differ: the check below can fail
        assert r[kind]["life_L10_relative"] == pytest.approx(ratio ** (10 / 3), rel=1e-12), kind


def test_sweep_resume_skips_finished_runs(zero_power_study, capsys):
    out, _ = zero_power_study
    before = {d: (out / f"c4_{d}" / "summary.json").stat().st_mtime_ns for d in ("forward", "reverse")}
    results_before = (out / "c4_forward" / "results.nc").stat().st_mtime_ns
    r = paper_study.run(paper_study.parse_args(["--conditions", "4", "--out", str(out)] + REDUCED))
    assert not r["failed"]
    # results were not recomputed (summaries are rewritten only to refresh the relative life)
    assert (out / "c4_forward" / "results.nc").stat().st_mtime_ns == results_before
    assert r["results"]["c4_forward"]["steps"] > 0


def test_failing_run_is_reported_and_others_finish(tmp_path):
    from scenarios.core.runner import RunConfig
    from scenarios.core.sweep import Case, run_sweep

    cfg = RunConfig(settle=0.0005, window=0.0005, progress=False)
    good = Case(4, "forward", str(tmp_path / "good"), {"bearing.rollers": 8})
    bad = Case(4, "reverse", str(tmp_path / "bad"), {"bearing.rollers": 8, "gears.planets": 0})
    res = run_sweep([good, bad], cfg, workers=1, progress=False)
    assert "error" in res["c4_reverse"] and "gears.planets" in res["c4_reverse"]["error"]
    assert (tmp_path / "bad" / "error.json").exists() and not (tmp_path / "bad" / "summary.json").exists()
    assert "error" not in res["c4_forward"] and (tmp_path / "good" / "summary.json").exists()


def test_bad_set_gives_clear_error(tmp_path):
    with pytest.raises(SystemExit) as e:
        paper_study.run(paper_study.parse_args(["--out", str(tmp_path), "--set", "bearing.clearance=3 kg"]))
    assert "bearing.clearance" in str(e.value) and "length" in str(e.value)
    with pytest.raises(SystemExit) as e:
        paper_study.run(paper_study.parse_args(["--out", str(tmp_path), "--set", "bearing.clearence=30 um"]))
    assert "clearence" in str(e.value)
    with pytest.raises(SystemExit) as e:
        paper_study.run(paper_study.parse_args(["--out", str(tmp_path), "--set", "novalue"]))
    assert "KEY=VALUE" in str(e.value)


@pytest.mark.slow
def test_spectrum_peaks_sit_on_mesh_sidebands(tmp_path):
    """The strongest peaks near f_m lie on f_m + k f_c (k small integers) within one frequency bin.
    Which k dominate is physics to report, not to tune. Linear bearings keep the run short.
    "Strongest" means within 30 dB of the largest peak: the weaker local maxima are weak lines of other
    orders (seen: 0.2 m/s² at f_m + 2f_c against 114 m/s² at f_m − f_c).
    Planet phasing (McFadden & Smith): with N equally spaced planets and the ring fixed, a fixed sensor
    sees the sidebands k with (z_r + k) ≡ 0 mod N; for z_r = 82, N = 3 the dominant one must be such a k.
    A sensor at the axis carries k = ±1 only (geometry.sideband_origin): every other line stays below 1 %
    of the dominant one (seen: 0.2 % at f_m + 2f_c, weak gravity/nonlinear orders; cancelled lines ≤ 5e-6)."""
    s = spectrum.run(spectrum.parse_args(["--out", str(tmp_path), "--settle", "0.06", "--window", "0.09",
                                          "--option", "bearings=linear", "--no-progress", "--sensor", "axis",
                                          "--perfect"]))
    assert s["f_c_hz"] == pytest.approx(2000 / 60) and s["f_m_hz"] == pytest.approx(82 * 2000 / 60)
    assert s["resolution_hz"] == pytest.approx(1 / 0.09, rel=0.01)
    big = s["peaks"][0]["amplitude_m_s2"] if s["peaks"] else 0.0
    top = [p for p in s["peaks"][:3] if p["amplitude_m_s2"] >= big * 10 ** (-30 / 20)]
    assert top, s["peaks"]
    k0 = round((top[0]["frequency_hz"] - s["f_m_hz"]) / s["f_c_hz"])
    assert (82 + k0) % 3 == 0, (k0, s["peaks"])
    for p in top:
        k = (p["frequency_hz"] - s["f_m_hz"]) / s["f_c_hz"]
        assert abs(k - round(k)) * s["f_c_hz"] <= s["resolution_hz"], p
        assert abs(round(k)) <= 6
    rows = list(csv.DictReader((tmp_path / "spectrum.csv").open()))
    assert set(rows[0]) >= {"frequency_hz", "amplitude"}
    assert (tmp_path / "spectrum.png").exists()
    lines = {r["k"]: r for r in s["lines"]}
    strongest = max(r["amplitude_m_s2"] for r in s["lines"])
    assert lines[-1]["origin"] == "phasing" and lines[-1]["amplitude_m_s2"] == strongest
    assert all(r["amplitude_m_s2"] < 0.01 * strongest for r in s["lines"] if r["origin"] != "phasing"), s["lines"]


@pytest.mark.slow
def test_spectrum_housing_sensor_on_a_perfect_machine(tmp_path, capsys):
    """The windowed housing sensor (docs/model.md §12) on a perfect machine: a passing-planet window carries every
    carrier order, so besides f_m − f_c the other lines planet phasing allows for z_r = 82, N = 3 appear —
    f_m + 2f_c, f_m − 4f_c, f_m + 5f_c stand out of the band's floor by ≥ 5× — while
    the lines phasing cancels, f_m, f_m + f_c and f_m ± 3f_c among them, stay below 1 % of the strongest
    (seen: ≤ 5e-4 %): the window alone does not bring f_m or f_m + f_c (McFadden & Smith 1985: "complete
    suppression of the component at the tooth meshing frequency"); errors (docs/model.md §11) must."""
    argv = ["--out", str(tmp_path), "--settle", "0.06", "--option", "bearings=linear", "--no-progress", "--perfect"]
    s = spectrum.run(spectrum.parse_args(argv))           # one tooth cycle: 12 carrier revolutions
    assert s["sensor"] == "housing" and s["resolution_hz"] == pytest.approx(s["f_c_hz"] / 12, rel=1e-3)
    # another sensor of the same machine reads the same run: reused, said so, not simulated again
    nc = tmp_path / "run" / "results.nc"
    made, capsys_before = nc.stat().st_mtime_ns, capsys.readouterr()
    assert spectrum.run(spectrum.parse_args([*argv, "--sensor", "axis"]))["sensor"] == "axis"
    assert nc.stat().st_mtime_ns == made and "run: reused (same parameters, settings and code" in capsys.readouterr().out
    s = spectrum.run(spectrum.parse_args(argv))
    lines = {r["k"]: r for r in s["lines"]}
    strongest = max(r["amplitude_m_s2"] for r in s["lines"])
    assert [k for k, r in lines.items() if r["perfect_machine_shows"] and abs(k) <= 5] == [-4, -1, 2, 5]
    for k in (-4, -1, 2, 5):
        assert lines[k]["over_median"] >= 5.0, lines[k]
    for r in s["lines"]:
        if r["origin"] == "errors":
            assert r["amplitude_m_s2"] < 0.01 * strongest, r
    rows = list(csv.DictReader((tmp_path / "lines.csv").open()))
    assert {r["origin"] for r in rows} == {"phasing", "transfer path", "errors"}
    # every path's line, over its own floor, and the path that carries it (the sum is the mesh path here; the
    # rig's radial sensor at the top does not see the rocking: its torque path is 0)
    for r in s["lines"]:
        assert r["housing_amplitude_m_s2"] == pytest.approx(r["amplitude_m_s2"], rel=1e-12)
        assert r["torque_amplitude_m_s2"] == 0.0 and r["carried_by"] == "mesh"
    assert lines[-1]["bearing_over_floor"] > 5.0 and lines[-1]["mesh_over_floor"] > 5.0
    assert {f"{p}_{q}" for p in ("mesh", "torque", "bearing", "housing") for q in ("amplitude_m_s2", "over_floor")} < set(rows[0])
    for sensor in ("mesh", "torque", "bearing", "axis"):
        _, signals = spectrum._signals(tmp_path / "run" / "results.nc", sensor)
        assert signals["amplitude"] is signals["axis_x" if sensor == "axis" else sensor]


def test_spectrum_rejects_inconsistent_sun_speed(tmp_path):
    with pytest.raises(SystemExit) as e:
        spectrum.run(spectrum.parse_args(["--out", str(tmp_path), "--carrier-rpm", "2000", "--sun-rpm", "3000"]))
    assert "3290" in str(e.value)


def test_bearing_rig_scenario(tmp_path, capsys):
    from scenarios import bearing_rig

    s = bearing_rig.run(bearing_rig.parse_args(["--radial-load", "5 kN", "--clearance", "20 um", "--out", str(tmp_path)]))
    for k in ("radial_load_N", "clearance_m", "roller_angle_deg", "roller_load_N", "q_max_N", "load_zone_deg",
              "ring_deflection_m"):
        assert k in s
    assert s["radial_load_N"] == pytest.approx(5000.0) and s["clearance_m"] == pytest.approx(20e-6)
    assert len(s["roller_angle_deg"]) == len(s["roller_load_N"]) == 12
    # the rollers carry the load: their vector sum balances F_r, and the peak agrees with the
    # quasi-static discrete-roller solution
    assert s["load_balance_error"] < 0.01
    assert s["q_max_N"] == pytest.approx(s["discrete_theory"]["q_max_N"], rel=0.02)
    assert 0 < s["load_zone_deg"] < 180 and s["ring_deflection_m"] > 0
    assert (tmp_path / "load_distribution.png").exists()
    # run time and accuracy, stored and printed like the study's (an adaptive run holds its tolerance)
    e = s["error_estimate"]
    assert s["steps"] > 0 and 0 < e["rms"] <= e["max"] <= 1.5 and e["atol_m"] == 1e-8
    assert "run time and accuracy: " in capsys.readouterr().out
    # which engine ran, in run_case's keys (numba is installed here: the compiled path, no fallback to explain)
    assert s["engine"] == "compiled" and s["engine_note"] is None
    assert json.loads((tmp_path / "summary.json").read_text())["engine"] == "compiled"
    with pytest.raises(SystemExit, match="radial-load: expected a force"):
        bearing_rig.parse_args(["--radial-load", "5 m", "--out", str(tmp_path)])


def test_the_bearing_rig_refuses_an_elastic_pin_in_one_line(tmp_path):
    """The rig's pin is a fixed body: ``bearing.pin.model = "elastic"`` is refused (not silently rigid), by the command
    before it claims a folder and by the builder, in one line naming the parameter."""
    from components.params import with_overrides
    from components.presets import reference_dpgt
    from components.rig import build_bearing_rig
    from components.units import ParameterError
    from scenarios import bearing_rig

    out = tmp_path / "rig"
    with pytest.raises(SystemExit) as e:
        bearing_rig.run(bearing_rig.parse_args(["--radial-load", "5 kN", "--model", "sliced", "--out", str(out),
                                                "--set", "bearing.pin.model=elastic"]))
    msg = str(e.value)
    assert "bearing.pin.model" in msg and "fixed" in msg and "\n" not in msg
    assert not (out / "summary.json").exists()
    b = with_overrides(reference_dpgt(), {"bearing.model": "sliced", "bearing.pin.model": "elastic"}).bearing
    with pytest.raises(ParameterError, match=r"bearing\.pin\.model.*fixed"):
        build_bearing_rig(b, radial_load=5e3)
    build_bearing_rig(with_overrides(reference_dpgt(), {"bearing.model": "sliced"}).bearing, radial_load=5e3)


def _slow_first_compile(monkeypatch, delay: float) -> None:
    """Make the first compiled runner built from now on take ``delay`` s longer to compile: a known compile time."""
    from mbd.compiled.runner import CompiledRunner

    original, left = CompiledRunner._compile, [1]

    def slow(self):
        if left.pop() if left else 0:
            time.sleep(delay)
        original(self)
    monkeypatch.setattr(CompiledRunner, "_compile", slow)


COMPILE_DELAY = 2.0      # s, the compile injected
OUTSIDE_S = 0.5          # s, what run_case does outside its own timing (lock, folder claim, summary): 0.09 s measured


def test_run_times_leave_the_compile_out(tmp_path, monkeypatch):
    """summary.json's wall_s leaves the kernels' compile out and compile_s holds it: with a compile known to take
    2 s longer, compile_s holds those 2 s, wall_s does not, and the two add up to the call's outer wall time (less
    the folder claim and summary writing outside run_case's timing, 0.09 s measured). The rig the same way."""
    import warnings

    from components.presets import reference_dpgt
    from components.rig import build_bearing_rig, rig_static_solution
    from components.scene import SceneOptions
    from scenarios.core.runner import TIME_NOTE, RunConfig, run_case

    p = reference_dpgt(3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _slow_first_compile(monkeypatch, COMPILE_DELAY)
        t0 = time.perf_counter()
        s = run_case(p, RunConfig(settle=5e-4, window=5e-4, progress=False), tmp_path / "run")
        outer = time.perf_counter() - t0
    assert s["compile_s"] >= COMPILE_DELAY and s["wall_s"] <= outer - COMPILE_DELAY
    assert 0.0 <= outer - (s["wall_s"] + s["compile_s"]) <= OUTSIDE_S
    assert s["time_note"] == TIME_NOTE and "without compiling" in TIME_NOTE

    rig = build_bearing_rig(p.bearing, radial_load=5e3, options=SceneOptions(cage="held", gravity=False))
    _slow_first_compile(monkeypatch, COMPILE_DELAY)
    t0 = time.perf_counter()
    sol = rig_static_solution(rig, samples=5)
    outer = time.perf_counter() - t0
    assert sol.compile_s >= COMPILE_DELAY and sol.wall_s <= outer - COMPILE_DELAY
    assert 0.0 <= outer - (sol.wall_s + sol.compile_s) <= OUTSIDE_S


def test_bearing_rig_says_it_fell_back_when_numba_is_missing(tmp_path):
    """With numba hidden (``import numba`` raising, as on a machine where it does not install) the rig runs the
    numpy path and its summary.json says so: engine "numpy" and the reason (numba's import) in engine_note."""
    import os
    import subprocess
    import sys

    from tests.support import ROOT

    code = ('import sys; sys.modules["numba"] = None\n'
            'from scenarios import bearing_rig\n'
            f'bearing_rig.run(bearing_rig.parse_args(["--radial-load", "5 kN", "--out", {str(tmp_path)!r}]))\n')
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["engine"] == "numpy" and "numba" in s["engine_note"]
    assert "mbd: running the numpy engine path" in r.stderr         # said on screen, not only in the file


def test_modal_scenario_single_planetary(tmp_path):
    from scenarios import modal

    s = modal.run(modal.parse_args(["--out", str(tmp_path)]))
    f = np.array(s["frequencies_hz"])
    assert f.size == s["dof"] == 3 * (3 + 3) and len(s["mode_class"]) == f.size
    assert np.all(np.diff(f) >= 0) and f[0] == 0.0          # ascending, the free rotation as 0
    # Lin & Parker: N = 3 → translational modes come in pairs, no planet modes
    assert all(m == 2 for m, k in zip(s["multiplicity"], s["mode_class"]) if k == "translational")
    assert "planet" not in s["mode_class"]
    s4 = modal.run(modal.parse_args(["--out", str(tmp_path / "n4"), "--set", "planets=4"]))
    assert s4["mode_class"].count("planet") == 3 * (4 - 3)   # one planet-mode family of multiplicity N−3
    assert (tmp_path / "mode_shapes.png").exists() and (tmp_path / "modes.csv").exists()


def test_stale_results_are_recomputed_not_reused(zero_power_study, tmp_path):
    """A finished case is reused only when its parameters, settings and code are the same: the
    fingerprint in summary.json decides (changing a parameter into the same folder recomputes, with --overwrite)."""
    from dataclasses import replace

    from scenarios.core.runner import run_fingerprint
    from scenarios.core.sweep import _case_cfg, _finished, build_params

    import shutil

    out = tmp_path / "study"
    shutil.copytree(zero_power_study[0], out)       # this test changes the folder
    a = paper_study.parse_args(["--conditions", "4", "--out", str(out)] + REDUCED)
    case = paper_study.make_cases(a, out)[0]
    cfg = _case_cfg(case, paper_study.build_config(a))
    params = build_params(case)
    s = json.loads((out / "c4_forward" / "summary.json").read_text())
    assert s["fingerprint"] == run_fingerprint(params, cfg)
    assert _finished(case, params, cfg) is not None
    assert _finished(case, params, replace(cfg, window=2 * cfg.window)) is None
    other = replace(case, overrides={**case.overrides, "bearing.rollers": "10"})
    assert _finished(other, build_params(other), cfg) is None
    # a checkpoint left by another run is not resumed: run_case starts afresh (and says so); the finished
    # results of other parameters are replaced only when asked (--overwrite, scenarios.core.integrity)
    a2 = paper_study.parse_args(["--conditions", "4", "--directions", "forward", "--out", str(out), "--settle", "0.002",
                                 "--window", "0.001", "--set", "bearing.rollers=10", "--no-progress", "--workers", "1",
                                 "--overwrite"])
    (out / "c4_forward" / "checkpoint.npz").write_bytes(b"not this run's checkpoint")
    r = paper_study.run(a2)
    assert not r["failed"]
    assert json.loads((out / "c4_forward" / "summary.json").read_text())["rollers"] == 10


@pytest.mark.slow
def test_spectrum_rig_machine_errors_bring_the_cancelled_lines(tmp_path):
    """The rig's machine by default carries modest manufacturing errors (ISO 1328-1 class-6 teeth on every gear,
    class-6 runouts, all six carrier pinholes within 10 µm: components.presets.typical_errors). They break the
    planets' symmetry, so every line planet phasing cancels for a perfect machine rises far above its perfect
    level on the housing sensor, the largest line in f_m ± 6 f_c stays f_m − f_c (one of the source's measured
    lines), and the net force of the unequal load sharing puts f_m + f_c on the bearing path (docs/model.md §12.3:
    static planet-to-planet errors add just f_m + f_c to the net carrier force): far above the perfect machine's
    there and above the path's floor (seen 50×). With linear bearings the cancelled lines of the sum stand out of
    its floor over one tooth cycle: f_m 5.6×, f_m ± 3f_c 4.8× / 4.9×, f_m + f_c 4.8× (seen); with the roller
    bearings of the full model the floor is higher and they do not (1.3–1.6×, docs/gear_quality.md). The perfect
    machine's floor with linear bearings is the integrator's, so its cancelled lines' height over it says nothing;
    their amplitudes in m/s² are compared."""
    common = ["--settle", "0.06", "--option", "bearings=linear", "--no-progress"]     # one tooth cycle
    perfect = spectrum.run(spectrum.parse_args(["--out", str(tmp_path / "perfect"), "--perfect", *common]))
    rig = spectrum.run(spectrum.parse_args(["--out", str(tmp_path / "rig"), *common]))
    assert any(rig["errors"].values()) and not any(perfect["errors"].values())
    p = {r["k"]: r for r in perfect["lines"]}
    r = {x["k"]: x for x in rig["lines"]}
    for k in (0, 1, -3, 3):
        assert p[k]["origin"] == "errors" and r[k]["amplitude_m_s2"] > 30 * p[k]["amplitude_m_s2"], (k, p[k], r[k])
    assert max(r.values(), key=lambda x: x["amplitude_m_s2"])["k"] == -1
    print({k: (r[k]["amplitude_m_s2"], r[k]["over_median"]) for k in (-1, 0, 1, -3, 3)})
    assert r[1]["bearing_over_floor"] > 5.0
    assert r[1]["bearing_amplitude_m_s2"] > 10.0 * p[1]["bearing_amplitude_m_s2"]
    assert all(r[k]["over_median"] > 3.0 for k in (0, 1, -3, 3)), r
    assert all(x["carried_by"] == "mesh" for x in r.values())


def test_spectrum_params_file_is_a_users_machine_and_its_conflicts_are_refused(tmp_path):
    """``--params FILE.toml`` puts a user's machine on the rig (its errors replace the --gear-class ones); the
    operating point belongs to the command's options, and --perfect with errors given is a contradiction."""
    machine = tmp_path / "m.toml"
    machine.write_text('[[errors.tooth]]\ngear = "b1"\ntooth = 3\nflank = "both"\npitch = "5 um"\n')
    p = spectrum.machine(spectrum.parse_args(["--params", str(machine), "--out", str(tmp_path / "o")]))
    e = p.si().errors
    assert [(x.gear, x.tooth, x.pitch) for x in e.tooth] == [("b1", 3, pytest.approx(5e-6))] and not e.flank_class
    assert not e.runout and not e.pinhole
    op = tmp_path / "op.toml"
    op.write_text('[operating]\ncarrier_speed = "100 rpm"\n')
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe not text")
    for argv, words in ((["--params", str(op)], "operating.carrier_speed is set by this command's --carrier-rpm"),
                        (["--params", str(bad)], f"--params {bad}"),
                        (["--params", str(machine), "--perfect"], "--perfect contradicts"),
                        (["--set", "operating.output_power=1 kW"], "--power, not by --set")):
        with pytest.raises(SystemExit) as exc:
            spectrum.machine(spectrum.parse_args([*argv, "--out", str(tmp_path / "o")]))
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


def test_headline_table_writes_each_change_as_the_figure_does():
    """The headline table's change is the figure's (components.results.format_change): a deep fall with the digits
    it needs (120 000 → 447 h: −99.6 %, not −100 %), a tenfold rise as the ratio (461 → 306 600 h: ×665, not
    +66 408 %), a change of sign none; from rows built by hand."""
    from components.results import percent_change
    pairs = {("inner", "bearing_load_mean_N"): (6851.0, 973.9), ("inner", "life_iso281_h"): (461.0, 306600.0),
             ("inner", "life_iso16281_h"): (1459.0, -1.0),
             ("outer", "bearing_load_mean_N"): (5290.0, 6350.0), ("outer", "life_iso281_h"): (120000.0, 447.0),
             ("outer", "life_iso16281_h"): (3530.0, 1860.0)}
    rows = [{"condition": "cruise", "bearing": b, "quantity": q, "forward": f, "reverse": r,
             "difference_pct": percent_change(f, r)} for (b, q), (f, r) in pairs.items()]
    lines = paper_study.headline_table(rows).splitlines()
    inner = next(x for x in lines if x.startswith("| cruise | inner |"))
    outer = next(x for x in lines if x.startswith("| cruise | outer |"))
    assert inner == "| cruise | inner | 6.85 / 0.974 (\u221286 %) | 461 / 3.07e+05 (\u00d7665) | 1.46e+03 / -1 |"
    assert outer == "| cruise | outer | 5.29 / 6.35 (+20 %) | 1.2e+05 / 447 (\u221299.6 %) | 3.53e+03 / 1.86e+03 (\u221247 %) |"


def test_the_spectrum_title_gives_the_speeds_with_their_signs(tmp_path, monkeypatch):
    """Ring fixed, the sun turns against the carrier: at 2000 r/min, −3290.3 r/min (ω_s/ω_c = 1 − z_r/z_s =
    1 − 82/31); the title keeps the sign (a true minus)."""
    from viz import plots as vp
    seen = {}
    monkeypatch.setattr(vp, "spectrum", lambda *a, **k: seen.update(k))
    f = np.linspace(0.0, 7000.0, 701)
    spectra = {k: (f, 1.0 + 0 * f, 10.0) for k in ("housing", *spectrum.SENSOR_PATHS)}
    sun = 2000.0 * (1 - 82 / 31)
    spectrum._plot(f, spectra, 2733.3, 33.33, {"carrier_rpm": 2000.0, "sun_rpm": sun}, "housing", tmp_path)
    assert seen["title"].startswith("Housing accelerometer, carrier 2000 r/min, sun \u22123290.3 r/min")
