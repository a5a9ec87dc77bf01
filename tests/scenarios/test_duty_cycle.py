"""Bearing life over a duty cycle (scenarios.duty_cycle) against truths it does not compute itself: the lives of the
bins read from their own summary.json files and combined by hand (Palmgren–Miner in its time form, the revolution
shares from the bins' carrier speeds), a one-bin cycle against the paper study's run of the same point, a user point
equal to condition 3 against condition 3 to the bit, a synthetic time series of known times; bad cycles refused in
one line naming the row."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from scenarios import duty_cycle, paper_study

SNAPSHOTS = "2"       # a short static solution: the truths here hold for any number of snapshots
IDENTITY = {"fingerprint", "parameters_fingerprint", "run_description", "timing", "wall_s", "static_solver",
            "condition", "operating_point", "machine"}


def _cycle(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


TWO_BINS = '''
[[bin]]
name = "fast"
carrier_speed = "4200 rpm"
power = "200 kW"
hours = 3

[[bin]]
name = "back"
carrier_speed = "2000 rpm"
power = "150 kW"
direction = "reverse"
hours = 1
'''

ONE_BIN = '''
[[bin]]
name = "only"
carrier_speed = "4200 rpm"
power = "200 kW"
hours = 10
'''


# a logged series: 20 min at standstill, then 40 min at 4200 r/min and 450 N m (one bin), sampled every 5 min
SERIES = "time [s],carrier_speed [rpm],torque [N*m]\n" + "".join(
    f"{300 * k},{0 if k < 4 else 4200},{0 if k < 4 else 450}\n" for k in range(13))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The two-bin and the one-bin cycle, a logged series, and the paper study's condition 3 beside a user point
    equal to it."""
    tmp = tmp_path_factory.mktemp("duty")
    two = _cycle(tmp, "two.toml", TWO_BINS)
    one = _cycle(tmp, "one.toml", ONE_BIN)
    series = _cycle(tmp, "series.csv", SERIES)
    common = ["--snapshots", SNAPSHOTS, "--workers", "1", "--no-progress"]
    assert duty_cycle.main(["--cycle", str(two), "--out", str(tmp / "two"), *common]) == 0
    assert duty_cycle.main(["--cycle", str(one), "--out", str(tmp / "one"), *common]) == 0
    assert duty_cycle.main(["--cycle", str(series), "--out", str(tmp / "series"), *common]) == 0
    assert paper_study.main(["--mode", "static", "--conditions", "3", "--operating", "u3: 4200 rpm, 200 kW",
                             "--directions", "forward", "--out", str(tmp / "paper"), *common]) == 0
    return tmp


def _json(p):
    return json.loads(p.read_text())


def test_the_combined_life_is_the_hand_miner_sum_of_the_bins_own_lives(runs):
    """L = 1/Σ(τ_i/L_h,i) with the time shares τ_i and each bin's life in hours (at its own speed) read from its own
    summary.json, per bearing type, planet and life (1e-12); damage shares likewise; the reverse bin counted with its
    own (reverse) loads; the equivalent load (Σ u_i P_i^(10/3))^(3/10) with u_i ∝ t_i n_c,i from the bins' carrier
    speeds (the planets' speed relative to their pins is (z_r/z_planet) n_c)."""
    rec = _json(runs / "two" / "duty_cycle.json")
    s = {n: _json(runs / "two" / n / "summary.json") for n in ("fast", "back")}
    assert s["fast"]["direction"] == "forward" and s["back"]["direction"] == "reverse"
    assert s["back"]["inner"]["equivalent_load_N"] != s["fast"]["inner"]["equivalent_load_N"]
    tau = {"fast": 0.75, "back": 0.25}
    for kind, letter in (("inner", "a"), ("outer", "b")):
        for key in ("iso281", "iso16281"):
            for j in range(3):
                lh = {n: s[n][kind][f"life_{key}_per_planet_h"][j] for n in s}
                hand = 1.0 / math.fsum(tau[n] / lh[n] for n in s)
                got = rec["lives"][kind]["planets"][f"{letter}{j + 1}"][key]
                assert got["life_h"] == pytest.approx(hand, rel=1e-12, abs=0)
                d = [tau[n] / lh[n] * hand for n in ("fast", "back")]
                assert got["damage_shares"] == pytest.approx(d, rel=1e-12, abs=0)
        revs = {n: tau[n] * abs(s[n]["carrier_rpm"]) for n in s}
        u = {n: revs[n] / sum(revs.values()) for n in s}
        P = math.fsum(u[n] * s[n][kind]["equivalent_load_N"] ** (10 / 3) for n in s) ** 0.3
        assert rec["lives"][kind]["equivalent_load_N"] == pytest.approx(P, rel=1e-12, abs=0)
    assert set(rec["lives_ignore_dynamic_load"]) == {"fast", "back"} and "dynamic load" in rec["static_lives_note"]
    assert all(b["life_source"] == "static" and b["dynamic_load_included"] is False for b in rec["bins"])


def test_a_one_bin_cycle_has_the_single_runs_life(runs):
    """A cycle of one bin at condition 3's speed and power: its combined life is the paper study's condition-3 run's
    (static, same snapshots) for every planet and both lives."""
    rec = _json(runs / "one" / "duty_cycle.json")
    c3 = _json(runs / "paper" / "c3_forward" / "summary.json")
    for kind, letter in (("inner", "a"), ("outer", "b")):
        for key in ("iso281", "iso16281"):
            for j in range(3):
                got = rec["lives"][kind]["planets"][f"{letter}{j + 1}"][key]["life_h"]
                assert got == pytest.approx(c3[kind][f"life_{key}_per_planet_h"][j], rel=1e-12, abs=0)
        assert rec["lives"][kind]["equivalent_load_N"] == pytest.approx(c3[kind]["equivalent_load_N"], rel=1e-12)


def _strip(d):
    return {k: v for k, v in d.items() if k not in IDENTITY}


def test_a_user_point_equal_to_condition_3_reproduces_its_summary_to_the_bit(runs):
    c3 = _json(runs / "paper" / "c3_forward" / "summary.json")
    u3 = _json(runs / "paper" / "u3_forward" / "summary.json")
    assert _strip(c3) == _strip(u3)
    assert c3["condition"] == 3 and u3["condition"] == "u3" and u3["operating_point"]["speed"] == "4200 rpm"
    assert c3["fingerprint"] == u3["fingerprint"]        # the same parameters and settings: the same run


def test_every_output_names_the_machine(runs):
    rec = _json(runs / "two" / "duty_cycle.json")
    m = rec["machine"]
    assert m["name"] == "reference machine" and len(m["fingerprint"]) == 8
    assert _json(runs / "two" / "fast" / "summary.json")["machine"] == m
    assert m["label"] in (runs / "two" / "duty_cycle.md").read_text()
    assert (runs / "two" / "duty_cycle.csv").read_text().splitlines()[1].startswith(m["label"])
    assert (runs / "two" / "damage_share.png").stat().st_size > 10_000


def test_a_logged_series_is_binned_and_its_binning_drawn(runs):
    """The series' one bin holds its 40 moving minutes (the standstill left out) and binning.png is written."""
    rec = _json(runs / "series" / "duty_cycle.json")
    assert len(rec["bins"]) == 1 and rec["bins"][0]["name"].startswith("fwd_4200-4725rpm_450-")
    assert rec["bins"][0]["hours"] == pytest.approx(40 / 60, rel=1e-12)
    assert (runs / "series" / "binning.png").stat().st_size > 10_000


def test_binning_a_synthetic_series_gives_its_known_times_and_revolutions():
    """Segments of constant speed and torque with dyadic, uneven sample steps: each bin's hours are the segment's
    time exactly, its revolutions speed × time, standstill left out, reverse apart from forward."""
    segments = [(1000.0, 800.0, 7.5), (2000.0, 600.0, 12.25), (0.0, 0.0, 3.0), (-1500.0, 700.0, 5.5),
                (1000.0, 800.0, 2.5)]                       # rpm, N m, minutes
    t, n, T = [0.0], [], []
    rng = np.random.default_rng(3)
    for rpm, tq, minutes in segments:
        left = minutes * 60.0
        while left > 0:
            dt = min(left, float(rng.choice([0.5, 1.0, 2.0, 4.0])))
            n.append(rpm * 2 * math.pi / 60)
            T.append(tq)
            t.append(t[-1] + dt)
            left -= dt
    n.append(0.0)
    T.append(0.0)
    c = duty_cycle.bin_series(np.array(t), np.array(n), np.array(T), speed_bin="250 rpm", torque_bin="100 N*m")
    got = {b.point.name: b for b in c.bins}
    assert set(got) == {"fwd_1000-1250rpm_800-900Nm", "fwd_2000-2250rpm_600-700Nm", "rev_1500-1750rpm_700-800Nm"}
    want = {"fwd_1000-1250rpm_800-900Nm": (1000.0, 10.0), "fwd_2000-2250rpm_600-700Nm": (2000.0, 12.25),
            "rev_1500-1750rpm_700-800Nm": (1500.0, 5.5)}
    for name, (rpm, minutes) in want.items():
        b = got[name]
        assert b.hours == minutes / 60.0                                   # exactly
        speed_rpm = float(b.point.speed.split()[0])
        assert speed_rpm * minutes == pytest.approx(rpm * minutes, rel=1e-15)  # revolutions = speed × time
        assert b.point.direction == ("reverse" if name.startswith("rev") else "forward")
    assert c.binning["standstill_h"] == 3.0 / 60.0
    assert sum(b.share for b in c.bins) == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize("text, message", [
    ('[[bin]]\nname = "a"\ncarrier_speed = "1000 rpm"\npower = "50 kW"\nhours = -2\n', "[[bin]] #1: time must be >= 0"),
    ('title = "nothing"\n', "the bin table is empty"),
    ('[[bin]]\nname = "fast"\ncarrier_speed = "5000 rpm"\npower = "50 kW"\nhours = 1\n',
     "[[bin]] #1: carrier speed 5000 rpm is above the machine's rated 4200 rpm"),
    ('[[bin]]\nname = "hot"\ncarrier_speed = "1000 rpm"\npower = "50 kW"\nhours = 1\noil_temperature = "200 degC"\n',
     "[[bin]] #1: oil temperature 200 degC is outside the lubricant's range"),
])
def test_a_bad_cycle_is_refused_in_one_line_naming_the_row(text, message, tmp_path, capsys):
    p = _cycle(tmp_path, "bad.toml", text)
    assert duty_cycle.main(["--cycle", str(p), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err, err


def test_a_bad_csv_row_is_named_by_its_line(tmp_path, capsys):
    p = _cycle(tmp_path, "bad.csv", "name,carrier_speed [rpm],torque [N*m],hours [h]\na,1000,500,2\nb,1500,400,-1\n")
    assert duty_cycle.main(["--cycle", str(p), "--out", str(tmp_path / "out")]) == 2
    assert "bad.csv row 3: time must be >= 0" in capsys.readouterr().err


def test_shares_not_summing_to_one_are_normalised_with_a_warning_naming_the_sum(tmp_path):
    p = _cycle(tmp_path, "s.csv", "name,carrier_speed [rpm],power [kW],share\na,1000,50,0.3\nb,2000,80,0.5\n")
    c = duty_cycle.read_cycle(p)
    assert [b.share for b in c.bins] == pytest.approx([0.375, 0.625], rel=1e-15)
    assert len(c.notes) == 1 and "sum to 0.8, not 1: normalised" in c.notes[0]


def test_the_example_cycles_read(tmp_path):
    """The shipped examples: forward only, 10 % of the time reversed (each forward bin mirrored at a tenth of its
    time), and the time series (binned)."""
    root = duty_cycle.Path(duty_cycle.__file__).resolve().parents[1] / "examples" / "duty_cycles"
    fwd = duty_cycle.read_cycle(root / "forward.toml")
    rev = duty_cycle.read_cycle(root / "reverse_10pct.toml")
    assert sum(b.hours for b in fwd.bins) == sum(b.hours for b in rev.bins)
    assert sum(b.share for b in rev.bins if b.point.direction == "reverse") == pytest.approx(0.1, rel=1e-12)
    series = duty_cycle.read_cycle(root / "series.csv", "500 rpm", "200 N*m")
    assert series.binning is not None and any(b.point.direction == "reverse" for b in series.bins)


def test_a_machine_file_with_its_own_points_is_refused_beside_a_cycle(tmp_path, capsys):
    """The cycle's bins are the operating points: a --params file's points would be ignored silently."""
    m = _cycle(tmp_path, "m.toml", '[[operating_point]]\nname = "x"\ncarrier_speed = "1000 rpm"\npower = "1 kW"\n')
    c = _cycle(tmp_path, "c.toml", ONE_BIN)
    assert duty_cycle.main(["--cycle", str(c), "--params", str(m), "--out", str(tmp_path / "o")]) == 2
    assert "[[operating_point]] tables are not used here" in capsys.readouterr().err


# ---------------------------------------------------------------------------------------------------------------
# --dynamic auto: the bins that carry the damage
# ---------------------------------------------------------------------------------------------------------------
def test_one_bearing_takes_its_most_damaging_bins_until_the_share_is_reached():
    """One bearing: the bins in falling order of damage until the share (hand-sorted: 0.4, 0.3, 0.2, 0.1)."""
    d = {"a": [0.1, 0.4, 0.2, 0.3]}
    assert duty_cycle.dominant_bins(d, 0.5) == [1, 3]
    assert duty_cycle.dominant_bins(d, 0.7) == [1, 3]          # exactly reached counts
    assert duty_cycle.dominant_bins(d, 0.71) == [1, 2, 3]
    assert duty_cycle.dominant_bins(d, 0.4) == [1]
    assert duty_cycle.dominant_bins(d, 1.0) == [0, 1, 2, 3]


def test_several_bearings_share_a_bin_that_matters_to_both():
    """Picked by hand: bearing A needs {0, 1} or {0, 2} (0.91), bearing B needs bin 2 (0.9). Each bearing's own top
    bins are A {0, 1}, B {2} — their union holds three bins; {0, 2} serves both with two. No single bin serves both
    (A's largest is 0.46)."""
    d = {"A": [0.46, 0.45, 0.45, 0.0, 0.0], "B": [0.0, 0.0, 0.9, 0.1, 0.0], "C": [0.2, 0.0, 0.7, 0.0, 0.1]}
    assert duty_cycle.dominant_bins(d, 0.9) == [0, 2]
    # equally few: {0, 2} and {1, 2} both serve A and B at 0.8; {0, 2} carries more (C: 0.9 against 0.7)
    assert duty_cycle.dominant_bins(d, 0.8) == [0, 2]


def test_the_chosen_bins_carry_the_share_of_every_bearing_and_no_fewer_bins_do():
    """A random damage table: the chosen set reaches the share for every bearing, and no set of one bin fewer does
    (every such subset enumerated)."""
    import itertools
    rng = np.random.default_rng(7)
    raw = rng.dirichlet(np.full(7, 0.5), size=4)
    d = {f"b{i}": list(r) for i, r in enumerate(raw)}
    for share in (0.5, 0.8, 0.95):
        got = duty_cycle.dominant_bins(d, share)
        assert all(sum(r[i] for i in got) >= share - 1e-12 for r in raw)
        assert not any(all(sum(r[i] for i in sub) >= share - 1e-12 for r in raw)
                       for sub in itertools.combinations(range(7), len(got) - 1))


def test_dynamic_share_needs_auto_and_a_share_in_range(tmp_path, capsys):
    c = _cycle(tmp_path, "one.toml", ONE_BIN)
    assert duty_cycle.main(["--cycle", str(c), "--dynamic-share", "0.9", "--out", str(tmp_path / "o")]) == 2
    assert "--dynamic auto" in capsys.readouterr().err
    assert duty_cycle.main(["--cycle", str(c), "--dynamic", "auto", "--dynamic-share", "1.5",
                            "--out", str(tmp_path / "o")]) == 2
    assert "(0, 1]" in capsys.readouterr().err


DYN = ["--settle", "0.002", "--window", "0.002"]     # short dynamic runs: the truths here hold for any window


@pytest.fixture(scope="module")
def auto(tmp_path_factory):
    """The two-bin cycle with --dynamic auto (its output kept), run twice (the second resumes); the one-bin cycle with
    --dynamic auto beside the paper study's dynamic run of the same point and settings."""
    tmp = tmp_path_factory.mktemp("auto")
    two = _cycle(tmp, "two.toml", TWO_BINS)
    one = _cycle(tmp, "one.toml", ONE_BIN)
    common = ["--snapshots", SNAPSHOTS, "--workers", "1", "--no-progress", *DYN]
    out = {}
    for k in ("first", "again"):
        import contextlib
        import io as _io
        buf = _io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert duty_cycle.main(["--cycle", str(two), "--dynamic", "auto", "--out", str(tmp / "two"),
                                    *common]) == 0
        out[k] = buf.getvalue()
    assert duty_cycle.main(["--cycle", str(one), "--dynamic", "auto", "--out", str(tmp / "one"), *common]) == 0
    assert paper_study.main(["--conditions", "3", "--directions", "forward", "--out", str(tmp / "paper"),
                             "--workers", "1", "--no-progress", *DYN]) == 0
    return tmp, out


def test_auto_chooses_the_bins_a_hand_count_of_the_static_damage_picks(auto):
    """The damage shares by hand from the bins' static summaries, τ_i/L_h,i normalised per bearing: the fast bin
    carries more than 0.9 of every bearing's damage and the reverse bin less, so the fewest bins for 0.9 are {fast};
    said before the dynamic run starts, with the dynamic run in its own folder."""
    tmp, out = auto
    s = {n: _json(tmp / "two" / n / "summary.json") for n in ("fast", "back")}
    assert s["fast"]["mode"] == "static" and s["back"]["mode"] == "static"
    tau = {"fast": 0.75, "back": 0.25}
    fast_share = []
    for kind in ("inner", "outer"):
        for key in ("iso281", "iso16281"):
            for j in range(3):
                dmg = {n: tau[n] / s[n][kind][f"life_{key}_per_planet_h"][j] for n in s}
                fast_share.append(dmg["fast"] / (dmg["fast"] + dmg["back"]))
    assert min(fast_share) > 0.9 > max(1 - x for x in fast_share)
    rec = _json(tmp / "two" / "duty_cycle.json")
    assert rec["dynamic_selection"]["bins"] == ["fast"]
    carried = rec["dynamic_selection"]["carried"]
    assert min(carried.values()) == pytest.approx(min(fast_share), rel=1e-12)
    text = out["first"]
    said = text.index("dynamic bins (--dynamic auto")
    assert text.index("runs: 2 to run") < said < text.index("runs: 1 to run")      # statics, choice, dynamic run
    assert "fast (1 of 2)" in text[said:said + 300]
    dyn = _json(tmp / "two" / "fast_dynamic" / "summary.json")
    assert dyn.get("mode") != "static" and "error_estimate" in dyn             # a time integration


def test_auto_combines_the_dynamic_bins_dynamic_lives_with_the_static_bins_by_hand_miner(auto):
    """L = 1/Σ(τ_i/L_h,i) with the fast bin's life from its dynamic run's summary and the reverse bin's from its
    static one (1e-12); the static bin flagged in the record and its share of the damage stated."""
    tmp, _ = auto
    rec = _json(tmp / "two" / "duty_cycle.json")
    s = {"fast": _json(tmp / "two" / "fast_dynamic" / "summary.json"),
         "back": _json(tmp / "two" / "back" / "summary.json")}
    tau = {"fast": 0.75, "back": 0.25}
    for kind, letter in (("inner", "a"), ("outer", "b")):
        for key in ("iso281", "iso16281"):
            for j in range(3):
                lh = {n: s[n][kind][f"life_{key}_per_planet_h"][j] for n in s}
                hand = 1.0 / math.fsum(tau[n] / lh[n] for n in s)
                assert rec["lives"][kind]["planets"][f"{letter}{j + 1}"][key]["life_h"] == \
                    pytest.approx(hand, rel=1e-12, abs=0)
                ign = rec["damage_share_ignoring_dynamic_load"][f"{kind} {letter}{j + 1} " +
                                                                ("ISO 281" if key == "iso281" else "ISO/TS 16281-style")]
                assert ign == pytest.approx(tau["back"] / lh["back"] * hand, rel=1e-12)
    src = {b["name"]: (b["life_source"], b["dynamic_load_included"]) for b in rec["bins"]}
    assert src == {"fast": ("dynamic", True), "back": ("static", False)}
    assert rec["lives_ignore_dynamic_load"] == ["back"] and "no dynamic increment is carried" in rec["static_lives_note"]
    assert "back" in (tmp / "two" / "duty_cycle.md").read_text().split("Note:")[0]


def test_auto_resumes_every_run_and_chooses_the_same_bins(auto):
    tmp, out = auto
    assert "runs: 0 to run, 2 reused" in out["again"] and "runs: 0 to run, 1 reused" in out["again"]
    assert "fast (1 of 2)" in out["again"]


def test_a_one_bin_cycle_with_auto_has_the_single_dynamic_runs_life(auto):
    """A one-bin cycle carries all its damage in its one bin: auto runs it dynamically, and the combined lives are
    the paper study's dynamic run of the same point and settings, for every planet and both lives."""
    tmp, _ = auto
    rec = _json(tmp / "one" / "duty_cycle.json")
    c3 = _json(tmp / "paper" / "c3_forward" / "summary.json")
    assert c3.get("mode") != "static" and "error_estimate" in c3 and rec["dynamic_selection"]["bins"] == ["only"]
    for kind, letter in (("inner", "a"), ("outer", "b")):
        for key in ("iso281", "iso16281"):
            for j in range(3):
                got = rec["lives"][kind]["planets"][f"{letter}{j + 1}"][key]["life_h"]
                assert got == pytest.approx(c3[kind][f"life_{key}_per_planet_h"][j], rel=1e-12, abs=0)
    assert rec["lives_ignore_dynamic_load"] == [] and rec["static_lives_note"] is None


def test_the_table_reads_its_speeds_as_given(runs):
    """1000 r/min round-trips through rad/s to 1000.0000000000001; the table writes 12 digits."""
    import csv
    with open(runs / "two" / "duty_cycle.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["bin"]: r["carrier_rpm"] for r in rows} == {"fast": "4200", "back": "2000"}
    assert all(len(r["hours"]) <= 14 for r in rows)


IDLE_BIN = '''
[[bin]]
name = "idle"
carrier_speed = "1500 rpm"
power = "0 kW"
hours = 100

[[bin]]
name = "rated"
carrier_speed = "4200 rpm"
power = "200 kW"
hours = 10
'''


def test_a_cycle_with_an_idle_bin_has_lives(tmp_path):
    """An idle bin (1500 r/min, no power: the gears float in their backlash at the start, the drag torques close the
    planets' flanks, docs/model.md §16) is solved quasi-statically like any other: the cycle's life is the hand
    Miner sum of both bins' own lives (time shares 100/110 and 10/110), the idle bin's life far longer than the rated
    one's (its pins carry the centrifugal force alone, ≈ 1.3 kN against ≈ 9 kN) and its damage share the smaller."""
    p = _cycle(tmp_path, "idle.toml", IDLE_BIN)
    assert duty_cycle.main(["--cycle", str(p), "--out", str(tmp_path / "out"), "--snapshots", SNAPSHOTS,
                            "--workers", "1", "--no-progress"]) == 0
    rec = _json(tmp_path / "out" / "duty_cycle.json")
    s = {n: _json(tmp_path / "out" / n / "summary.json") for n in ("idle", "rated")}
    tau = {"idle": 100 / 110, "rated": 10 / 110}
    for kind, letter in (("inner", "a"), ("outer", "b")):
        assert 1e3 < s["idle"][kind]["bearing_load_mean_N"] < 0.2 * s["rated"][kind]["bearing_load_mean_N"]
        for key in ("iso281", "iso16281"):
            for j in range(3):
                lh = {n: s[n][kind][f"life_{key}_per_planet_h"][j] for n in s}
                assert np.isfinite(lh["idle"]) and lh["idle"] > 10 * lh["rated"], (kind, key, lh)
                hand = 1.0 / math.fsum(tau[n] / lh[n] for n in s)
                got = rec["lives"][kind]["planets"][f"{letter}{j + 1}"][key]
                assert got["life_h"] == pytest.approx(hand, rel=1e-12, abs=0)
                assert got["damage_shares"][0] < got["damage_shares"][1]
