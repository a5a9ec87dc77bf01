"""Every run's roller slip and smearing indicator (components.statistics: roller_slip_quantities, the accumulators'
load-zone entries, roller_slip_summary) against truths the code does not compute: a roller spinning at a known
fraction of its rolling spin, Johnson's Hertz line contact in his own convention, and synthetic step sequences of
rollers whose load zone, slip, entries and p·Δv are set by construction."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from components.bearing import entry_slide_roll
from components.families import FAMILY
from components.lubrication import contact_pressure
from components.presets import reference_dpgt
from components.statistics import quantities as Q
from components.statistics.accumulate import Accumulators
from components.statistics.summaries import roller_slip_summary

B = reference_dpgt(3, "forward").si().bearing
OMEGA = 300.0                                           # planet relative to the carrier [rad/s]
W_EPI = OMEGA * (B.pitch_diameter + B.roller_diameter) / (2.0 * B.roller_diameter)   # rolling spin on a fixed pin


def johnson_peak_pressure(Q_roller: float, inner: bool) -> float:
    """Johnson (Contact Mechanics 1985, eq. 4.45): p0 = √(P E*/(π R)) with P the load per length, E* = E/(2(1 − ν²))
    for two bodies of one steel, 1/R = 1/R1 ± 1/R2 (roller radius D/2; + on the convex pin, − in the concave bore)."""
    R_race = B.inner_raceway_radius if inner else B.outer_raceway_radius
    R = 1.0 / (2.0 / B.roller_diameter + (1.0 if inner else -1.0) / R_race)
    E_star = B.elastic_modulus / (2.0 * (1.0 - B.poisson_ratio ** 2))
    return math.sqrt(Q_roller / B.roller_length * E_star / (math.pi * R))


@pytest.mark.parametrize("inner", [True, False])
def test_contact_pressure_is_johnsons_line_contact(inner):
    p = contact_pressure(np.array([500.0, 0.0, -3.0]), B, inner)
    assert p[0] == pytest.approx(johnson_peak_pressure(500.0, inner), rel=1e-12)
    assert p[0] == pytest.approx((0.821 if inner else 0.676) * 1e9, rel=2e-3)    # by hand: R = 3.03, 4.47 mm
    assert p[1] == 0.0 and p[2] == 0.0                  # an open contact carries no pressure


@pytest.mark.parametrize("slip, srr", [(0.0, 0.0), (100.0, 2.0), (50.0, 0.5 / 0.75), (-20.0, -0.2 / 1.1)])
def test_entry_slide_roll(slip, srr):
    """SRR = v_s/v_e of a roller whose spin is short by s: a roller that does not turn slides at twice its
    entraining speed; one spinning too fast (s < 0) slides the other way."""
    assert entry_slide_roll(slip) == pytest.approx(srr, rel=1e-12, abs=1e-15)


def test_roller_slip_quantities_from_known_speeds():
    """Two rollers of one bearing, in the carrier frame (its own speed immaterial): one rolls, one spins 25 % short;
    one is loaded on the pin (500 N, sliding 0.2 m/s), the other only on the bore (20 N, sliding 1.5 m/s)."""
    w_c = 104.7
    V = np.zeros((1, 4, 3))                               # bodies: carrier, planet, roller0, roller1
    V[0, :, 2] = [w_c, w_c + OMEGA, w_c + W_EPI, w_c + 0.75 * W_EPI]
    p = SimpleNamespace(carrier=0, planet=np.array([1]), roller_body=np.array([2, 3]),
                        roller_bearing=np.array([0, 0]), bearing=B)
    out = {FAMILY["race_inner"]: {"load": np.array([[500.0, 0.0]]), "slip_velocity": np.array([[0.2, -3.0]])},
           FAMILY["race_outer"]: {"load": np.array([[510.0, 20.0]]), "slip_velocity": np.array([[-0.1, -1.5]])}}
    q = Q.roller_slip_quantities(p, out, V)
    np.testing.assert_allclose(q[Q.ROLLER_SLIP], [[0.0, 25.0]], atol=1e-9)
    np.testing.assert_array_equal(q[Q.ROLLER_LOADED], [[1.0, 0.0]])
    np.testing.assert_allclose(q["roller_slip_loaded"], [[0.0, 0.0]], atol=1e-9)
    np.testing.assert_allclose(q["roller_slip_unloaded"], [[0.0, 25.0]], atol=1e-9)
    pin0 = johnson_peak_pressure(500.0, True) * 0.2
    np.testing.assert_allclose(q[Q.ROLLER_PV_PIN], [[pin0, 0.0]], rtol=1e-12)
    np.testing.assert_allclose(q["roller_pv"], [[max(pin0, johnson_peak_pressure(510.0, False) * 0.1),
                                                 johnson_peak_pressure(20.0, False) * 1.5]], rtol=1e-12)


KEYS = (Q.ROLLER_LOADED, "roller_slip_loaded", "roller_slip_unloaded", "roller_pv")


def synthetic_steps(t, slip_out, offsets, pv_entry=3.0e6, orbit_hz=7.0, flicker=None):
    """Rollers of two bearings (two each; bearing 0 "inner", 1 "outer") orbiting at ``orbit_hz`` about their pins
    from the angles ``offsets``; each is loaded on the pin over the first quarter of its orbit, rolls there and
    spins ``slip_out`` % short out of it (per roller); its pin contact's p·Δv is ``pv_entry`` while loaded.
    ``flicker`` (a, b): the pin contact opens again between the angles a and b just inside the zone, the roller
    already rolling (a roller chattering at the zone's edge)."""
    psi = np.mod(2 * math.pi * orbit_hz * t[:, None] + np.asarray(offsets)[None, :], 2 * math.pi)
    zone = psi < math.pi / 2
    slip = np.where(zone, 0.0, np.asarray(slip_out)[None, :])
    if flicker is not None:
        zone &= ~((psi >= flicker[0]) & (psi < flicker[1]))
    loaded = zone.astype(float)
    pv = pv_entry * loaded
    rows = {Q.ROLLER_LOADED: loaded, "roller_slip_loaded": slip * loaded, "roller_slip_unloaded": slip * (1 - loaded),
            "roller_pv": pv + 1e5 * (1 - loaded), Q.ROLLER_SLIP: slip, Q.ROLLER_PV_PIN: pv}
    return rows, psi


def accumulate(t, rows, target=None, t0=0.1, t1=1.1, blocks=3, dwell=None):
    own = np.array([0, 0, 1, 1])
    sums = Accumulators(2, t0, t1, target, np.zeros(0, np.int64), np.zeros(0), dwell)
    keys = list(rows)
    sums.layout({k: 4 for k in keys}, {k: own for k in keys}, cage_speed="cage_speed_rel", pocket_force="pocket_force",
                entry_keys=(Q.ROLLER_LOADED, Q.ROLLER_SLIP, Q.ROLLER_PV_PIN))
    cuts = np.linspace(0, t.size - 1, blocks + 1).astype(int)
    for a, b in zip(cuts[:-1], cuts[1:]):             # blocks share their end states, as the observer hands them
        sums.add_steps(t[a:b + 1], {k: v[a:b + 1] for k, v in rows.items()}, np.zeros((b + 1 - a, 0)))
    return sums


@pytest.mark.parametrize("blocks", [1, 4])
def test_zones_and_entries_of_synthetic_steps(blocks):
    """Out of the load zone the inner bearing's rollers slip 20 and 40 %: pooled over equal unloaded times, 30 %;
    in it 0 %; a quarter of the time loaded; every entry comes from the slip out of the zone (mean 30 %: the two
    rollers enter equally often), with the pin's p·Δv 3 MW/m² and the SRR of 30 % slip; the entries counted are
    those in [t0, t1] only: 7 orbits a second over 1 s, 7 per roller (offsets keep them off the window's ends)."""
    t = np.sort(np.concatenate([np.linspace(0.0, 1.2, 12001), np.random.default_rng(1).uniform(0, 1.2, 3000)]))
    rows, _ = synthetic_steps(t, slip_out=[20.0, 40.0, 10.0, 10.0], offsets=[0.3, 0.3 + math.pi, 1.0, 2.0])
    sums = accumulate(t, rows, blocks=blocks)
    d: dict = {}
    roller_slip_summary(d, sums, SimpleNamespace(roller_bearing=np.array([0, 0, 1, 1])), np.array([0]))
    assert d["roller_slip_load_zone_pct"] == pytest.approx(0.0, abs=1e-12)
    assert d["roller_slip_unloaded_pct"] == pytest.approx(30.0, abs=0.05)
    assert d["roller_loaded_share"] == pytest.approx(0.25, abs=2e-3)
    assert d["roller_entries"] == 14
    assert d["roller_slip_entry_pct"] == pytest.approx(30.0, abs=1e-12)
    assert d["roller_entry_slide_roll"] == pytest.approx(0.3 / 0.85, rel=1e-12)
    assert d["smearing_pv_entry_W_m2"] == pytest.approx(3.0e6, rel=1e-12)
    assert d["smearing_pv_max_W_m2"] == pytest.approx(3.0e6, rel=1e-12)
    # the outer bearing is its own: 10 % out of its zone
    e: dict = {}
    roller_slip_summary(e, sums, SimpleNamespace(roller_bearing=np.array([0, 0, 1, 1])), np.array([1]))
    assert e["roller_slip_unloaded_pct"] == pytest.approx(10.0, abs=1e-9)
    assert e["roller_slip_entry_pct"] == pytest.approx(10.0, abs=1e-12)


@pytest.mark.parametrize("blocks", [1, 5])
def test_a_roller_chattering_at_the_zones_edge_enters_it_once(blocks):
    """The pin contact opens again for 0.05–0.1 rad of the orbit just after each entry, the roller already rolling:
    with a dwell of one roller pitch out of the zone (12 rollers: 1/84 s at 7 orbits a second) only the true entries
    count — 14, from 30 % slip — while without a dwell each chatter counts as another entry from 0 % slip (28 entries,
    mean 15 %)."""
    t = np.linspace(0.0, 1.2, 24001)
    rows, _ = synthetic_steps(t, slip_out=[20.0, 40.0, 10.0, 10.0], offsets=[0.3, 0.3 + math.pi, 1.0, 2.0],
                              flicker=(0.05, 0.1))
    summary = SimpleNamespace(roller_bearing=np.array([0, 0, 1, 1]))
    for dwell, n, slip in ((np.full(2, 1.0 / 84.0), 14, 30.0), (None, 28, 15.0)):
        d: dict = {}
        roller_slip_summary(d, accumulate(t, rows, blocks=blocks, dwell=dwell), summary, np.array([0]))
        assert d["roller_entries"] == n
        assert d["roller_slip_entry_pct"] == pytest.approx(slip, abs=1e-12)


def test_entries_end_with_each_bearings_window_and_survive_a_checkpoint():
    """With whole cage revolutions a bearing's window ends when its cage has turned them (here a cage speed of 2π
    rad/s relative to the carrier and 0.5 revolutions: 0.5 s after t0); the entries after that are not counted, and
    the sums restored from a checkpoint go on counting as before."""
    t = np.linspace(0.0, 1.2, 6001)
    rows, _ = synthetic_steps(t, slip_out=[20.0, 40.0, 10.0, 10.0], offsets=[0.3, 0.3 + math.pi, 1.0, 2.0])
    rows["cage_speed_rel"] = np.tile([2 * math.pi, 2 * math.pi], (t.size, 1))
    own = {k: np.array([0, 0, 1, 1]) for k in rows}
    own["cage_speed_rel"] = np.array([0, 1])

    def fresh():
        s = Accumulators(2, 0.1, 1.1, np.array([0.5, 0.5]), np.zeros(0, np.int64), np.zeros(0))
        s.layout({k: v.shape[1] for k, v in rows.items()}, own, cage_speed="cage_speed_rel",
                 pocket_force="pocket_force", entry_keys=(Q.ROLLER_LOADED, Q.ROLLER_SLIP, Q.ROLLER_PV_PIN))
        return s

    whole = fresh()
    whole.add_steps(t, rows, np.zeros((t.size, 0)))
    assert whole.t_close == pytest.approx([0.6, 0.6], abs=1e-9)
    # 0.5 s at 7 orbits a second: entries at 7 t + offset/2π ∈ (0.7, 4.2] → 3 or 4 per roller, counted by hand
    first = lambda off: np.arange(0, 10) - off / (2 * math.pi)
    expect = [int(np.sum((first(o) / 7 > 0.1) & (first(o) / 7 <= 0.6))) for o in (0.3, 0.3 + math.pi)]
    np.testing.assert_array_equal(whole.entry[0][:2], expect)
    half = fresh()
    k = 2500
    half.add_steps(t[:k + 1], {n: v[:k + 1] for n, v in rows.items()}, np.zeros((k + 1, 0)))
    again = fresh()
    again.load_state_dict({n: np.array(v, copy=True) for n, v in half.state_dict().items()})
    again.layout({n: v.shape[1] for n, v in rows.items()}, own, cage_speed="cage_speed_rel",
                 pocket_force="pocket_force", entry_keys=(Q.ROLLER_LOADED, Q.ROLLER_SLIP, Q.ROLLER_PV_PIN))
    again.add_steps(t[k:], {n: v[k:] for n, v in rows.items()}, np.zeros((t.size - k, 0)))
    np.testing.assert_allclose(again.entry, whole.entry, rtol=1e-12)


@pytest.fixture(scope="module")
def condition_3_summary(tmp_path_factory):
    import json
    import warnings

    from scenarios import api

    out = tmp_path_factory.mktemp("entries") / "run"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        api.run(condition=3, out=out, settle=0.01, progress=False, sample_rate=2000.0)
    return json.loads((out / "summary.json").read_text())


def test_a_run_counts_one_entry_per_roller_and_cage_revolution(condition_3_summary):
    """Over its window of whole cage revolutions relative to the carrier each roller passes the load zone once a
    revolution: Z rollers × N planets × n revolutions entries, one more per roller at most (a roller at the zone's
    edge at the window's start enters again at its end); the roller's slip there is a percentage, the SRR its
    s/(1 − s/2), the p·Δv at entry not above the window's largest."""
    s = condition_3_summary
    for kind in ("inner", "outer"):
        d = s[kind]
        assert d["whole_revolutions"]
        n = round(d["cage_revolutions"])
        expect = s["rollers"] * s["planets"] * n
        assert expect <= d["roller_entries"] <= expect + s["rollers"] * s["planets"]
        assert -100.0 < d["roller_slip_entry_pct"] < 100.0
        assert d["roller_entry_slide_roll"] == pytest.approx(entry_slide_roll(d["roller_slip_entry_pct"]), rel=1e-12)
        assert 0.0 < d["smearing_pv_entry_W_m2"] <= d["smearing_pv_max_W_m2"]
        assert 0.0 < d["roller_loaded_share"] < 1.0
