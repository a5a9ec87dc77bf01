"""summary.json's names: every numeric key with a unit ends in its unit's suffix, every other numeric
key is on the explicit list of dimensionless ones, and every key is documented — in
components.outputs.SUMMARY_WORDS or in the README's summary.json section — checked on a real run's file.
And one indexing convention: planets and pairs counted from 1 as they are named (a1/b1 = pair 1) in messages,
plots and options; rollers and teeth by their index from 0 as the parameters give them. And results.nc through
viz.results.attribute_names: every variable, coordinate and dimension reachable by xarray's attribute access."""
from __future__ import annotations

import itertools
import json
import re
import warnings
from pathlib import Path

import pytest

from components.outputs import DIMENSIONLESS_KEYS, SUMMARY_WORDS, UNIT_SUFFIXES, unit_of_key
from components.params import with_overrides
from components.presets import reference_dpgt
from scenarios.core.runner import RunConfig, integration_record, run_case

README = Path(__file__).resolve().parent.parent / "README.md"


def _expand(token: str) -> list[str]:
    """`roller_{inner,outer}_race_{rms,max}_N` -> the four names it stands for."""
    parts = re.split(r"\{([^{}]*)\}", token)
    choices = [[p] if i % 2 == 0 else p.split(",") for i, p in enumerate(parts)]
    return ["".join(c) for c in itertools.product(*choices)]


def readme_summary_names() -> set[str]:
    text = README.read_text()
    start = text.index("### What `summary.json` holds")
    section = text[start:text.index("\n### Results files", start)]
    names = set()
    for token in re.findall(r"`([^`\s]+)`", section):
        names.update(part for n in _expand(token) for part in n.split(".")
                     if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", part))
    return names


def leaves(d: dict, path: str = ""):
    """(dotted path, key, value, parent key) of every entry of a nested summary; a list of numbers kept whole, a
    list of rows (dicts: the spectrum's lines and peaks) entered row by row as ``path[]``."""
    for k, v in d.items():
        p = f"{path}.{k}" if path else k
        yield p, k, v, path.rsplit(".", 1)[-1]
        if isinstance(v, dict) and k != "run_description":
            yield from leaves(v, p)
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for row in v:
                yield from leaves(row, f"{p}[]")


def _numeric(v) -> bool:
    if isinstance(v, bool):
        return False
    if isinstance(v, (int, float)):
        return True
    return isinstance(v, list) and bool(v) and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                   or x is None for x in v) and any(x is not None for x in v)


def unit_problems(summary: dict, dimensionless=DIMENSIONLESS_KEYS) -> list[str]:
    """Numeric keys that neither carry a unit suffix (theirs or their mapping's) nor are declared dimensionless."""
    bad = []
    for path, key, value, parent in leaves(summary):
        if not _numeric(value) or path.startswith("run_description"):
            continue
        if unit_of_key(key) or key in dimensionless or path in dimensionless or unit_of_key(parent):
            continue
        if path not in bad:
            bad.append(path)
    return bad


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("keys") / "run"
    p = with_overrides(reference_dpgt(3, "forward"), {"bearing.rollers": 8})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_case(p, RunConfig(settle=0.002, window=0.001, progress=False), out)
    return out


@pytest.fixture(scope="module")
def summary(run_dir):
    return json.loads((run_dir / "summary.json").read_text())


def test_every_numeric_key_has_a_unit_suffix_or_is_declared_dimensionless(summary):
    assert unit_problems(summary) == []
    # the renamed ones are there with their suffix, the old names gone
    for kind in ("inner", "outer"):
        d = summary[kind]
        for k in ("cage_acc_radial_rms_m_s2", "cage_acc_rel_magnitude_max_m_s2", "cage_acc_x_rms_m_s2",
                  "pocket_impact_speed_max_m_s", "pocket_impact_speed_mean_m_s", "cage_slip_all_pct",
                  "heat_traction_all_W", "heat_land_all_W"):
            assert k in d, (kind, k)
        assert "cage_acc_rel_radial_rms_m_s2" in d["all_cages"]
        assert not {"cage_acc_radial_rms", "pocket_impact_speed_max", "cage_slip_pct_all", "heat_land_W_all"} & set(d)
    assert set(summary["integration"]) == {"method", "alpha", "h_s", "h_max_s", "h_min_s", "atol_pos_m",
                                           "atol_rot_rad", "engine"}


def test_a_rigid_pin_run_has_no_pin_bending_keys_nor_variables(run_dir, summary):
    """The elastic pins' statistics and histories exist only where the pins are elastic (tests/components/test_pins.py
    holds their values): this run's rigid pins give neither ``pin_*`` keys nor ``pin_beam.*`` variables."""
    import xarray as xr

    assert not [k for kind in ("inner", "outer") for k in summary[kind] if k.startswith("pin_")]
    with xr.open_dataset(run_dir / "results.nc", engine="h5netcdf") as ds:
        assert "race_inner.load" in ds.variables and not [v for v in ds.variables if str(v).startswith("pin_beam")]


def test_each_runs_bearing_load_is_held_against_the_catalogue_minimum(summary):
    """summary.json's minimum load is 0.02 C_r (SKF's rule for roller bearings) and the load against it the mean
    bearing load over it, per planet too."""
    for kind in ("inner", "outer"):
        d = summary[kind]
        assert d["minimum_load_N"] == pytest.approx(0.02 * d["dynamic_load_rating_N"], rel=1e-12)
        assert d["load_over_minimum"] == pytest.approx(d["bearing_load_mean_N"] / d["minimum_load_N"], rel=1e-12)
        assert d["load_over_minimum_per_planet"] == pytest.approx(
            [x / d["minimum_load_N"] for x in d["bearing_load_mean_per_planet_N"]], rel=1e-12)


def test_the_check_catches_a_key_without_its_unit():
    """The check is not vacuous: the old names and a unit-less speed fail it; a mapping named with a unit passes."""
    assert unit_problems({"inner": {"cage_acc_radial_rms": 1.0, "pocket_impact_speed_max": 2.0}}) == \
        ["inner.cage_acc_radial_rms", "inner.pocket_impact_speed_max"]
    assert unit_problems({"backlash_m": {"sun_inner": 1e-4}, "window_s": [0.0, 0.1], "rollers": 12}) == []
    assert unit_problems({"rms": 1.0}) == ["rms"]            # dimensionless only where it is declared so
    assert unit_problems({"error_estimate": {"rms": 1.0}}) == []


@pytest.fixture(scope="module")
def spectrum_summary(tmp_path_factory):
    """A real (short) run of the rig's spectrum with the rig's machine (its errors), linear bearings."""
    from scenarios import spectrum

    out = tmp_path_factory.mktemp("spectrum")
    spectrum.run(spectrum.parse_args(["--out", str(out), "--settle", "0.002", "--window", "0.012", "--option",
                                      "bearings=linear", "--no-progress"]))
    return json.loads((out / "summary.json").read_text()), out


def test_the_spectrum_summary_follows_the_unit_suffix_rule(spectrum_summary):
    """The spectrum's summary.json by the same rule, its rows (lines, peaks) entered: amplitudes in m/s² say so;
    the over-the-floor ratios, k and the distance in bins are its declared dimensionless keys; the machine's errors
    and the rig's parameters are text with their units, not bare SI numbers."""
    import csv

    from scenarios.spectrum import DIMENSIONLESS_KEYS as SPECTRUM_DIMENSIONLESS

    s, out = spectrum_summary
    assert unit_problems(s, DIMENSIONLESS_KEYS | SPECTRUM_DIMENSIONLESS) == []
    assert s["lines"] and s["peaks"]                                   # the rows were checked, not skipped
    line, peak = s["lines"][0], s["peaks"][0]
    assert {"amplitude_m_s2", "housing_amplitude_m_s2", "mesh_amplitude_m_s2", "over_median"} <= set(line)
    assert "amplitude" not in line and "amplitude" not in peak and "amplitude_m_s2" in peak
    assert s["sensor_parameters"]["angle"] == "90 deg" and s["sensor_parameters"]["housing.mass"] == "50 kg"
    assert s["errors"]["pinhole"] and all(v.endswith(" µm") for e in s["errors"]["pinhole"]
                                           for k, v in e.items() if k != "planet")
    # lines.csv and peaks.csv carry the same names
    with open(out / "lines.csv") as fh:
        assert list(csv.DictReader(fh).fieldnames) == list(line)
    with open(out / "peaks.csv") as fh:
        assert list(csv.DictReader(fh).fieldnames) == list(peak)
    # before: bare amplitudes and SI numbers without units failed the rule
    old = {"lines": [{"amplitude": 1.0, "over_median": 2.0}], "sensor_parameters": {"angle": 1.57}}
    assert unit_problems(old, DIMENSIONLESS_KEYS | SPECTRUM_DIMENSIONLESS) == ["lines[].amplitude",
                                                                                "sensor_parameters.angle"]


def test_the_spectrum_reads_the_sensor_at_the_sources_place_from_the_same_run(spectrum_summary, capsys):
    """--sensor-at carrier_bearing reads the same run (reused, not simulated again) with the sensor on the carrier
    bearing's boss: its parameters in summary.json are the preset's (m_eq = ring 6.07 kg + housing 50 kg)."""
    from scenarios import spectrum

    _, out = spectrum_summary
    capsys.readouterr()
    s = spectrum.run(spectrum.parse_args(["--out", str(out), "--settle", "0.002", "--window", "0.012", "--option",
                                          "bearings=linear", "--no-progress", "--sensor-at", "carrier_bearing"]))
    assert "run: reused (same parameters, settings and code" in capsys.readouterr().out
    assert s["sensor_at"] == "carrier_bearing" and s["sensor_parameters"]["equivalent_mass"] == "56.07 kg"
    assert s["sensor_parameters"]["window_width"] == "360 deg" and s["sensor_parameters"]["radius"] == "0.05 m"


def test_every_key_of_a_real_run_is_documented(summary):
    documented = set(SUMMARY_WORDS) | readme_summary_names()
    missing = sorted({key for path, key, _, _ in leaves(summary)
                      if not path.startswith("run_description.") and key not in documented})
    assert missing == []
    assert "pocket_touches_per_rev" in SUMMARY_WORDS and "pocket_touches_per_rev" in readme_summary_names()


def test_summary_words_units_agree_with_the_suffixes():
    """Each statistic's unit in SUMMARY_WORDS (what tables and axes print) is the one its name's suffix says, and
    every unit-less one is declared dimensionless."""
    for key, (words, unit) in SUMMARY_WORDS.items():
        assert words, key
        if unit == "1":
            assert key in DIMENSIONLESS_KEYS and unit_of_key(key) is None, key
        else:
            assert unit_of_key(key) == unit, (key, unit)
    assert unit_of_key("cage_acc_radial_rms_m_s2") == "m/s^2" and unit_of_key("pocket_impact_speed_max_m_s") == "m/s"
    assert unit_of_key("film_min_m") == "m" and unit_of_key("cage_acc_radial_rms") is None
    assert set(UNIT_SUFFIXES) >= {"_N", "_m", "_h", "_pct", "_W"}


def test_integration_record_names_its_units():
    import mbd

    r = integration_record(mbd.PRODUCTION)
    assert r["h_s"] == mbd.PRODUCTION.h and r["atol_pos_m"] == mbd.PRODUCTION.atol_pos
    assert r["atol_rot_rad"] == mbd.PRODUCTION.atol_rot and "h" not in r


# ------------------------------------------------------------------------------------------------------------
# one indexing convention
# ------------------------------------------------------------------------------------------------------------
def test_design_messages_name_planets_and_pairs_from_1():
    from components.geometry import design_findings

    found = {f.parameter: f.message for f in design_findings(reference_dpgt(3, "forward"))}
    assert "the sun and outer planet b1 (not in mesh)" in found["gears.sun"]          # was "outer planet 0"
    four = [f.message for f in design_findings(with_overrides(reference_dpgt(3, "forward"), {"gears.planets": 4}))]
    assert any("pairs 2..4 are off the ring's teeth by -0.25, -0.5, +0.25 pitch" in m for m in four), four
    # inner planet a1 against outer planet b2: the planets as the parameters name them (a1..aN, b1..bN)
    assert any("inner planet a1 and outer planet b2" in m for m in four), four
    assert not any(re.search(r"planet \d", m) for m in four)


def test_animate_pair_option_counts_from_1(run_dir, monkeypatch, capsys):
    """dpgt animate --pair n shows pair n (planets an, bn): --pair 0 and a pair the run lacks are usage errors."""
    from viz import cli, render_check
    import viz.animate as animate
    import viz.results as results

    nc = str(run_dir / "results.nc")
    assert cli.main([nc, "--out", "x.gif", "--pair", "0"]) == 2
    assert "--pair" in capsys.readouterr().err
    assert cli.main([nc, "--out", "x.gif", "--pair", "4"]) == 2
    assert "pairs 1..3" in capsys.readouterr().err
    seen = {}
    real = results.cage_panels
    def panels(runs, pair, rollers):
        seen["pair"] = pair
        return real(runs, pair=pair, rollers=rollers)

    monkeypatch.setattr(cli, "cage_panels", panels)
    monkeypatch.setattr(render_check, "check_offscreen", lambda: (True, ""))
    monkeypatch.setattr(animate, "cage_orbit_animation",
                        lambda out, *a, title, **k: seen.setdefault("title", title) and Path(out))
    cli.main([nc, "--out", str(run_dir / "x.gif"), "--pair", "2", "--max-frames", "2"])
    assert seen["pair"] == 1                          # pair 2 is index 1: planets a2 and b2
    assert "planet pair 2" in seen["title"]
    run = results.load_run(nc)
    assert run.bearing("inner", 1)["planet"] == "a2"


# ------------------------------------------------------------------------------------------------------------
# results.nc: names attribute access can use
# ------------------------------------------------------------------------------------------------------------
def test_results_reachable_by_attribute_access_and_the_readers_unchanged(run_dir):
    xr = pytest.importorskip("xarray")
    import numpy as np
    from viz.results import attribute_name, attribute_names, load_run, open_results

    raw = xr.open_dataset(run_dir / "results.nc", engine="h5netcdf")
    ds = open_results(run_dir)
    assert "race_inner.load" in raw.variables and not hasattr(raw, "race_inner")      # the trap
    for name in [*raw.variables, *raw.dims]:
        new = attribute_name(name)
        assert new.isidentifier() and "." not in new, name
        if name in raw.variables:
            got = getattr(ds, new)                                  # attribute access reaches it
            assert isinstance(got, xr.DataArray) and got.name == new
            np.testing.assert_array_equal(got.values, raw[name].values)
            assert got.attrs.get("units") == raw[name].attrs.get("units"), name
            if new != name:
                assert got.attrs["results_name"] == name
        else:
            assert new in ds.dims
    load = ds.race_inner_load.sel(race_inner_instance="a1.pb.roller0")
    np.testing.assert_array_equal(load.values, raw["race_inner.load"].sel({"race_inner.instance": "a1.pb.roller0"}).values)
    assert ds.race_inner_load.attrs["units"] == "N" and ds.bearing_load_radial.dims == ("time", "bearing_load_radial_instance")
    assert json.loads(ds.attrs["results_names"])["motion_position"] == "motion.position"
    assert ds.attrs["Conventions"] == raw.attrs["Conventions"]
    assert open_results(run_dir, attribute_access=False).identical(raw)
    # the file keeps its names: the one reader loads it as before
    run = load_run(run_dir)
    assert run.output("race_inner.load").shape == raw["race_inner.load"].shape


def test_attribute_names_refuses_names_that_would_meet_or_hide():
    xr = pytest.importorskip("xarray")
    import numpy as np
    from viz.results import ResultsError, attribute_names

    a = np.zeros(2)
    with pytest.raises(ResultsError, match="would meet: \\['a_b'\\]"):
        attribute_names(xr.Dataset({"a.b": ("t", a), "a_b": ("t", a)}))
    with pytest.raises(ResultsError, match="hide behind Dataset attributes: \\['mean'\\]"):
        attribute_names(xr.Dataset({"mean": ("t", a)}))
    ok = attribute_names(xr.Dataset({"x.y": ("t.n", a)}))
    assert ok.x_y.dims == ("t_n",) and ok.x_y.attrs["results_name"] == "x.y"
