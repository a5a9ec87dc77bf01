"""The full-machine misalignment study (scenarios.misalignment_study, docs/model.md §8.8, docs/misalignment.md).

Truths: the planar machine (a straight roller on an aligned pin is the planar contact slice by slice, so the aligned
sliced machine's life is the planar machine's); the machine's mirror across its mid-plane (ζ → −ζ maps a pin
slope γ to −γ and every slope with it, so ±γ give the same life when nothing else slopes the pins); the
bearing-level calculation (components.sliced_bearing, an independent quasi-static bearing) under the slope the
bearing sees."""
from __future__ import annotations

import csv
import math
import warnings

import numpy as np
import pytest

from components import faults, static
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from components.sliced_bearing import ARCMIN, SlicedBearing, sliced_bearing_life
from scenarios import misalignment_study as ms


def _static(overrides: dict, snapshots: int = 1, condition: int = 3, direction: str = "forward"):
    p = with_overrides(reference_dpgt(condition, direction), overrides)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the reference design's known tip-circle warnings
        scene = build_dpgt(p)
        stats, sols = static.static_statistics(scene, snapshots)
    return p, scene, stats.summary(), sols


def test_aligned_is_the_planar_machine_and_plus_minus_gamma_give_the_same_life(tmp_path):
    """The study at condition 3 forward, straight rollers, γ = −4′, 0, 4′ radial (1 snapshot): the aligned case's
    sliced life is the planar machine's ISO/TS 16281 life (its own static solution) and its L/L0 is 1; −4′ and +4′
    give the same life, seen slope and edge ratio (the mid-plane mirror), both below the aligned life."""
    out = tmp_path / "m"
    code = ms.main(["--conditions", "3", "--directions", "forward", "--profiles", "straight", "--slopes", "radial",
                    "--gammas=-4,4", "--snapshots", "1", "--no-progress", "--out", str(out)])
    assert code == 0
    rows = list(csv.DictReader((out / "misalignment.csv").open(encoding="utf-8")))
    assert len(rows) == 6                       # (aligned, −4′, +4′) × (inner, outer)
    _, _, planar, _ = _static({})
    for kind in ("inner", "outer"):
        mine = {float(r["gamma_arcmin"]): r for r in rows if r["bearing"] == kind}
        assert set(mine) == {-4.0, 0.0, 4.0}
        assert float(mine[0.0]["life_relative"]) == 1.0
        assert float(mine[0.0]["life_sliced_h"]) == pytest.approx(planar[kind]["life_iso16281_h"], rel=1e-6)
        assert float(mine[0.0]["edge_pressure_ratio"]) == pytest.approx(1.0, abs=1e-9)
        for col in ("life_sliced_h", "seen_slope_arcmin", "edge_pressure_ratio"):
            assert float(mine[4.0][col]) == pytest.approx(float(mine[-4.0][col]), rel=1e-6), col
        assert float(mine[4.0]["life_relative"]) < 1.0 - 1e-4
        assert 0.0 < float(mine[4.0]["seen_share"]) < 1.0      # the planet follows its pin by some share
    assert (out / "life_against_slope.png").stat().st_size > 0
    assert "L/L0" in (out / "answer.md").read_text(encoding="utf-8")


def test_with_the_windup_plus_and_minus_tangential_slopes_differ_by_the_windups_sense():
    """The wind-up slopes every pin tangentially (forward: one sense): a tangential γ adds to it or takes from it, so
    −γ and +γ no longer mirror — the bearing sees ≈ |γ ± γ_w| along the tangent (the same share of each)."""
    seen = {}
    for g in (-4.0, 4.0):
        _, _, s, _ = _static({"bearing.model": "sliced", "gears.carrier_windup": True,
                                  "errors.pin_slope": ms.pin_slopes(["a1", "a2", "a3", "b1", "b2", "b3"], g,
                                                                    "tangential")})
        seen[g] = s["inner"]["misalignment_mean_rad"]
    si = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced", "gears.carrier_windup": True}).si()
    c = si.layout.centres_a[0]
    w = np.hypot(*faults.pin_slope(si, "a1", c))           # the wind-up's slope alone (windup on, no pin slope)
    w_sign = np.sign(faults.pin_slope(si, "a1", c) @ np.array([-c[1], c[0]]))
    g = 4.0 * ARCMIN
    big, small = (seen[4.0], seen[-4.0]) if w_sign > 0 else (seen[-4.0], seen[4.0])
    assert big > small
    # the share the bearing sees is the same for both (a linear split): seen ∝ |γ ± w|
    assert big / small == pytest.approx((g + w) / (g - w), rel=0.1)


def test_the_bearing_level_calculation_under_the_seen_slope_gives_the_machines_life():
    """The planet held by its meshes where they hold it: the bearing-level sliced bearing (components.sliced_bearing:
    pin fixed, bore loaded by the machine's mean bearing load, no centrifugal roller loads, traction or gyroscopic
    terms) with the slope the machine's bearing sees (pin against bore, its mean vector over the snapshots, in the
    planet's radial–tangential axes) loses the machine's life to within 35 % of the loss (what the bearing level
    leaves out; a slope off by a factor 2 or in the wrong plane changes the loss several-fold)."""
    prof = "straight"
    base = {"bearing.model": "sliced", "bearing.profile.shape": prof}
    planets = ["a1", "a2", "a3", "b1", "b2", "b3"]
    _, _, aligned, _ = _static(base)
    p, scene, s, sols = _static({**base, "errors.pin_slope": ms.pin_slopes(planets, 4.0, "tangential")})
    m, si = scene.model, p.si()
    pairs = {m.body_names[m.extra_owner[i - m.n_body_coords]]: (i, j) for i, j in m.slope_pairs}
    b = si.bearing
    sb = SlicedBearing(b)
    for kind, name, c in (("inner", "a1", si.layout.centres_a[0]), ("outer", "b1", si.layout.centres_b[0])):
        e_r = np.asarray(c) / np.hypot(*c)
        e_t = np.array([-e_r[1], e_r[0]])
        pin = faults.pin_slope(si, name, c)
        v = np.mean([pin - m.full(x.t, x.q, x.v)[0][list(pairs[name])] for x in sols], axis=0)
        v = np.array([v @ e_r, v @ e_t])
        assert np.hypot(*v) == pytest.approx(s[kind]["misalignment_mean_rad"], rel=1e-6)
        F = np.array([s[kind]["bearing_load_radial_mean_N"], s[kind]["bearing_load_tangential_mean_N"]])
        L0 = sliced_bearing_life(sb.states(F, 0.0, "radial", positions=8), b)
        L1 = sliced_bearing_life(sb.states(F, float(np.hypot(*v)), math.atan2(v[1], v[0]), positions=8), b)
        machine = s[kind]["life_iso16281_sliced_h"] / aligned[kind]["life_iso16281_sliced_h"]
        assert 1.0 - machine > 1e-3
        assert (1.0 - L1 / L0) == pytest.approx(1.0 - machine, rel=0.35), kind


def test_cases_and_rows_name_their_axes_and_lives_are_relative_to_the_aligned_machine_without_windup(tmp_path):
    a = ms.parse_args(["--conditions", "3", "--directions", "reverse", "--profiles", "straight,iso_16281",
                       "--gammas=2,-4", "--windup", "on", "--out", str(tmp_path / "x")])
    cases = ms.make_cases(a, tmp_path / "x")
    # per profile: the aligned reference without wind-up, then with it aligned and at −4, 2 in both directions
    assert len(cases) == 2 * (1 + 1 + 2 * 2)
    axes = [ms._case_axes(c) for c in cases]
    assert {(x["windup"], x["slope"], x["gamma_arcmin"]) for x in axes} == {
        ("off", "aligned", 0.0), ("on", "aligned", 0.0), ("on", "radial", -4.0), ("on", "radial", 2.0),
        ("on", "tangential", -4.0), ("on", "tangential", 2.0)}
    tang = next(c for c in cases if c.tag == "iso_16281_won_tangentialm4am")
    assert [e["direction"] for e in tang.overrides["errors.pin_slope"]] == ["270 deg"] * 6
    assert tang.overrides["gears.carrier_windup"] is True and tang.overrides["bearing.profile.shape"] == "iso_16281"

    class S(dict):
        failed = False
    results = {}
    for c, x in zip(cases, axes):
        life = 100.0 * (1.0 - 0.01 * abs(x["gamma_arcmin"])) * (0.9 if x["windup"] == "on" else 1.0)
        results[c.label] = S({k: {"life_iso16281_sliced_h": life * (2.0 if k == "outer" else 1.0),
                                  "misalignment_mean_rad": 0.5 * abs(x["gamma_arcmin"]) * ARCMIN,
                                  "edge_pressure_ratio": 1.0, "bearing_load_mean_N": 1e4} for k in ("inner", "outer")})
    rows = ms.rows_of(cases, results)
    r = next(r for r in rows if r["windup"] == "on" and r["gamma_arcmin"] == -4.0 and r["bearing"] == "outer")
    assert r["life_relative"] == pytest.approx(0.96 * 0.9, rel=1e-12) and r["seen_share"] == pytest.approx(0.5)
    windup_alone = next(r for r in rows if r["windup"] == "on" and r["slope"] == "aligned")
    assert windup_alone["life_relative"] == pytest.approx(0.9)


def test_bad_gammas_are_refused_in_one_line():
    for bad in ("x", "4,4", "nan"):
        with pytest.raises(SystemExit) as info:
            ms.parse_args(["--gammas", bad])
        msg = str(info.value.code)
        assert "--gammas" in msg and "arcmin" in msg and "\n" not in msg


def test_elastic_pins_are_an_axis_and_their_lives_are_relative_to_the_rigid_aligned_machine(tmp_path):
    a = ms.parse_args(["--conditions", "3", "--directions", "forward", "--profiles", "straight", "--gammas=-4,4",
                       "--slopes", "tangential", "--windup", "off,on", "--pins", "rigid,one_plate",
                       "--out", str(tmp_path / "x")])
    cases = ms.make_cases(a, tmp_path / "x")
    # per pin model and wind-up state: aligned, −4′ and +4′
    assert len(cases) == 2 * 2 * 3
    one = next(c for c in cases if c.tag == "straight_one_plate_woff_aligned")
    assert one.overrides["bearing.pin.model"] == "elastic" and one.overrides["bearing.pin.mounting"] == "one_plate"
    assert all("bearing.pin.model" not in c.overrides for c in cases if "one_plate" not in c.tag)
    axes = [ms._case_axes(c) for c in cases]
    assert {x["pins"] for x in axes} == {"rigid", "one_plate"}

    class S(dict):
        failed = False
    results = {}
    for c, x in zip(cases, axes):
        life = 100.0 * (0.8 if x["pins"] == "one_plate" else 1.0) * (1.0 - 0.01 * abs(x["gamma_arcmin"]))
        results[c.label] = S({k: {"life_iso16281_sliced_h": life, "misalignment_mean_rad": 0.0,
                                  "edge_pressure_ratio": 1.0, "bearing_load_mean_N": 1e4} for k in ("inner", "outer")})
    rows = ms.rows_of(cases, results)
    r = next(r for r in rows if r["pins"] == "one_plate" and r["gamma_arcmin"] == 0.0 and r["windup"] == "off")
    assert r["life_relative"] == pytest.approx(0.8, rel=1e-12)      # against the rigid aligned machine
    assert "one plate elastic pins alone" in ms.answer(rows)
    # only the rigid aligned machine is run besides the asked elastic pins when rigid is not asked
    b = ms.parse_args(["--conditions", "3", "--directions", "forward", "--profiles", "straight", "--gammas", "4",
                       "--slopes", "tangential", "--pins", "both_plates", "--out", str(tmp_path / "y")])
    tags = [c.tag for c in ms.make_cases(b, tmp_path / "y")]
    assert tags == ["straight_woff_aligned", "straight_both_plates_woff_aligned", "straight_both_plates_woff_tangential4am"]


def test_the_dynamic_mode_runs_each_case_over_the_window_asked():
    a = ms.parse_args(["--mode", "dynamic", "--window", "0.0071", "--settle", "0.05", "--start", "static"])
    cfg = ms.MisalignmentStudy(a).config()
    assert (cfg.mode, cfg.window, cfg.settle, cfg.start) == ("dynamic", 0.0071, 0.05, "static")
    assert ms.MisalignmentStudy(ms.parse_args([])).config().mode == "static"


def test_a_static_start_is_a_run_setting_and_the_default_start_leaves_every_fingerprint_as_it_was():
    """The start from the static solution identifies a run (its settings say so); the kinematic start, the default,
    is not among the settings at all, so runs made before the choice existed keep their fingerprints."""
    from mbd import ModelError
    from scenarios.core.runner import RunConfig, _settings
    assert "start" not in _settings(RunConfig()) and "start" not in _settings(RunConfig(window=0.01))
    assert _settings(RunConfig(start="static"))["start"] == "static"
    with pytest.raises(ModelError, match="start must be"):
        RunConfig(start="warm")
