"""The statistics layer (components.outputs.WindowStatistics) against truths it does not compute itself:
synthetic per-step quantities of known time-weighted mean, RMS, maximum, minimum, slip and impact count, fed
step by step on uneven steps, with the window's start, its end and every bearing's whole-revolution end inside
a step.

Seam: :meth:`WindowStatistics.snapshot` (the per-step quantities of a state) is overridden by a subclass that
returns the synthetic snapshot each synthetic step carries; everything downstream of it (accumulators,
windows, impacts, summary) is the production code. The index plan comes from a built (never simulated)
reference DPGT: 3 pairs, 6 bearings of 12 rollers.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import pytest

import mbd
from components.bearing import bearing_kinematics
from components.dpgt import build_dpgt
from components.life import raceway_ratings
from components.outputs import WindowStatistics, bearing_map, cage_period
from components.presets import reference_dpgt


@dataclass
class Step:
    """The part of a state the accumulators read (t, the pocket's internal state) and its snapshot."""
    t: float
    snap: dict
    z: dict = field(default_factory=dict)


class Synthetic(WindowStatistics):
    def snapshot(self, s):
        return s.snap


def synthetic(scene, t0, t1, **kw) -> Synthetic:
    """The statistics of ``scene``'s built model over [t0, t1], bound (index plan) and fed nothing yet."""
    bs, system, _ = scene
    stats = Synthetic(bs, t0, t1, **kw)
    stats.bind(bs.model, system, None)
    return stats


@pytest.fixture(scope="module")
def scene():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = build_dpgt(reference_dpgt(3, "forward"))
    system = mbd.System(bs.model)
    probe = WindowStatistics(bs, 0.0, 1.0)
    probe.bind(bs.model, system, None)
    s = mbd.PRODUCTION.stepper().initial_state(system, 0.0, bs.q0, bs.v0)
    template = {k: np.size(v) for k, v in probe.snapshot(s).items()}      # every quantity and its size
    return bs, system, template


def owners(bs):
    """Bearing of every roller (race_inner order, from the bearing map's instance ranges) and the nominal cage
    and planet speeds relative to the carrier per bearing."""
    bm = bearing_map(bs)
    roller = np.empty(sum(x["race_inner"][1] - x["race_inner"][0] for x in bm), int)
    for i, x in enumerate(bm):
        roller[x["race_inner"][0]:x["race_inner"][1]] = i
    sp, b = bs.speeds, bs.bearing
    planet = np.array([sp.planet(x["kind"]) - sp.carrier for x in bm])
    epi = np.array([bearing_kinematics(b, 0.0, w)[0] for w in planet])      # pin at rest: relative speeds
    return bm, roller, planet, epi


def uneven_steps(t_start, t_stop, h, seed):
    """Step ends from t_start past t_stop, steps uniformly random in [0.3 h, 1.7 h]."""
    rng = np.random.default_rng(seed)
    t = [t_start]
    while t[-1] < t_stop:
        t.append(t[-1] + h * rng.uniform(0.3, 1.7))
    return np.array(t)


def ramp_truth(a, b, u0, u1):
    """Mean, RMS, max, min of x = a + b u over u in [u0, u1] (exact; u is time in units of the window)."""
    du = u1 - u0
    mean = a + 0.5 * b * (u0 + u1)
    ms = a * a + a * b * (u0 + u1) + b * b * (u0 * u0 + u0 * u1 + u1 * u1) / 3.0
    ends = np.stack([a + b * u0, a + b * u1])
    return mean, np.sqrt(ms), ends.max(axis=0), ends.min(axis=0), ms * du


def test_accumulators_reproduce_ramps_on_uneven_steps_and_whole_cage_revolutions(scene):
    """Every quantity a linear ramp a + b t per instance (random a, b), fed on uneven steps (0.3–1.7 h, 3000
    per window): mean, max and min equal the ramp's over its window to round-off, the RMS to 1e-6 (trapezoid
    of x², measured ≤ 3e-8), where the window is [t0, t1] for the meshes and, for a bearing, from t0 to
    the instant its cage (turning at a constant speed, 1–3 % of slip) completes its whole revolutions
    relative to the carrier, 2π·n/|ω_cage| after t0 — all three inside a step. One cage slipping 8 % misses
    the 5 % margin: its window runs to the last step and whole_revolutions is false. The summary's RMS,
    mean and maximum fields, cage slip, revolutions and windows are the same truths."""
    bs, system, template = scene
    bm, roller_of, planet, epi = owners(bs)
    nb, Z = len(bm), bs.bearing.rollers
    b = bs.bearing
    sp = bs.speeds
    T_in = cage_period(b, sp.carrier, sp.inner_planet)
    T_out = cage_period(b, sp.carrier, sp.outer_planet)
    t0 = 0.0123
    W = 2.0 * T_in                                  # two inner-cage revolutions
    t1 = t0 + W
    stats = synthetic(scene, t0, t1)
    n_turns = {"inner": 2.0, "outer": float(max(round(W / T_out), 1))}
    np.testing.assert_array_equal(stats.target, [n_turns[x["kind"]] for x in bm])
    slip = np.array([0.01, 0.03, 0.02, -0.01, 0.08, 0.015])      # bearing 4 (pair 3 inner) misses the margin
    w_cage = (1.0 - slip) * epi
    goal = np.array([2 * math.pi * n_turns[x["kind"]] for x in bm])
    t_close = t0 + goal / np.abs(w_cage)
    assert np.all(t_close[slip < 0.04] < stats.t_end) and t_close[4] > stats.t_end
    ts = uneven_steps(t0 - 7.3e-6, stats.t_end + 2e-5, W / 3000, seed=1)
    t_last = ts[-1]
    t_close[4] = t_last
    assert not np.any(np.isin([t0, t1, *t_close[:4]], ts))          # every window end falls inside a step

    rng = np.random.default_rng(2)
    coef = {k: (rng.uniform(1.0, 2.0, n), rng.uniform(-1.0, 1.0, n)) for k, n in template.items()}
    # the reference roller of each bearing kind: the one nearest the load-zone centre, opposite the pin force
    zone = 2 * math.pi * 5 / Z + 0.05
    angles = (2 * math.pi * np.arange(Z) / Z + 0.1)[np.arange(roller_of.size) % Z]
    fixed = {"cage_speed_rel": w_cage, "planet_speed_rel": planet, "_roller_angle": angles,
             "load_x": np.full(nb, -1e3 * math.cos(zone)), "load_y": np.full(nb, -1e3 * math.sin(zone))}

    def snap(t):
        u = (t - t0) / W
        return {k: fixed[k].copy() if k in fixed else coef[k][0] + coef[k][1] * u for k in template}

    for ta, tb in zip(ts[:-1], ts[1:]):
        stats.step(Step(ta, snap(ta)), Step(tb, snap(tb)))

    checked = set()
    for key, n in template.items():
        if key.startswith("_") or key in fixed:
            continue
        # per bearing (6), per roller or pocket (72), else the global window (the meshes: one per pair)
        end = t_close if n == nb else t_close[roller_of] if n == roller_of.size else np.full(n, t1)
        checked.add("bearing" if n == nb else "roller" if n == roller_of.size else "global")
        a, c = coef[key]
        mean, rms, hi, lo, _ = ramp_truth(a, c, 0.0, (end - t0) / W)
        st = stats.stats(key)
        np.testing.assert_allclose(st["mean"], mean, rtol=1e-11, err_msg=key)
        np.testing.assert_allclose(st["rms"], rms, rtol=1e-6, err_msg=key)
        np.testing.assert_allclose(st["max"], hi, rtol=1e-11, err_msg=key)
        np.testing.assert_allclose(st["min"], lo, rtol=1e-11, err_msg=key)

    assert checked == {"bearing", "roller", "global"}
    s = stats.summary()
    assert s["window_duration_s"] == pytest.approx(W, rel=1e-12)
    u_end = (t_close - t0) / W
    for kind in ("inner", "outer"):
        d = s[kind]
        sel = np.flatnonzero([x["kind"] == kind for x in bm])
        ref = sel[0]
        r = np.flatnonzero(roller_of == ref)[5]                 # roller 5 sits 0.05 rad from the zone centre
        mine = np.isin(roller_of, sel)
        assert d["window_s"] == pytest.approx([t0, t_close[ref]], rel=1e-12)
        assert d["whole_revolutions"] == (kind == "outer")
        assert d["cage_slip_pct"] == pytest.approx(100 * slip[ref], rel=1e-9)
        assert d["cage_slip_all_pct"] == pytest.approx(100 * slip[sel].mean(), rel=1e-9)
        assert d["cage_revolutions"] == pytest.approx(n_turns[kind], rel=1e-12)
        for field_, key, i in (("roller_inner_race", "roller_inner_load", r), ("roller_outer_race", "roller_outer_load", r),
                               ("roller_cage", "pocket_force", r), ("cage_guide", "guide_force", ref)):
            a, c = coef[key]
            mean, rms, hi, _, _ = ramp_truth(a[i], c[i], 0.0, u_end[ref])
            assert d[f"{field_}_rms_N"] == pytest.approx(rms, rel=1e-6), field_
            assert d[f"{field_}_max_N"] == pytest.approx(hi, rel=1e-11), field_
            # every roller (or cage) of this kind pooled: sqrt(Σ ∫x² dt / Σ T)
            own = roller_of if key != "guide_force" else np.arange(nb)
            inst = np.flatnonzero(np.isin(own, sel))
            _, _, _, _, sq = ramp_truth(a[inst], c[inst], 0.0, u_end[own[inst]])
            pooled = math.sqrt(sq.sum() / u_end[own[inst]].sum())
            assert d["all_rollers"][f"{field_}_rms_N"] == pytest.approx(pooled, rel=1e-6), field_
        a, c = coef["roller_inner_load"]
        assert d["roller_inner_race_mean_N"] == pytest.approx(ramp_truth(a[r], c[r], 0.0, u_end[ref])[0], rel=1e-11)
        own = roller_of == ref                       # the spread of the rollers' mean loads, (max − min)/mean
        means = ramp_truth(a[own], c[own], 0.0, u_end[ref])[0]
        assert d["roller_inner_race_mean_spread"] == pytest.approx((means.max() - means.min()) / means.mean(), rel=1e-10)
        assert d["all_rollers"]["roller_inner_race_max_N"] == pytest.approx(
            ramp_truth(a[mine], c[mine], 0.0, u_end[roller_of[mine]])[2].max(), rel=1e-11)
        for view in ("", "rel_"):
            for comp in ("radial", "tangential", "magnitude"):
                a, c = coef[f"cage_acc_{view}{comp}"]
                assert d[f"cage_acc_{view}{comp}_rms_m_s2"] == pytest.approx(
                    ramp_truth(a[ref], c[ref], 0.0, u_end[ref])[1], rel=1e-6)
                _, _, _, _, sq = ramp_truth(a[sel], c[sel], 0.0, u_end[sel])
                assert d["all_cages"][f"cage_acc_{view}{comp}_rms_m_s2"] == pytest.approx(
                    math.sqrt(sq.sum() / u_end[sel].sum()), rel=1e-6)
        radial, tangential = (ramp_truth(*coef[k], 0.0, u_end)[0] for k in ("load_radial", "load_tangential"))
        assert d["bearing_load_radial_mean_N"] == pytest.approx(radial[ref], rel=1e-11)
        assert d["bearing_load_mean_N"] == pytest.approx(math.hypot(radial[ref], tangential[ref]), rel=1e-11)
        np.testing.assert_allclose(d["bearing_load_mean_per_planet_N"], np.hypot(radial, tangential)[sel], rtol=1e-11)
        # ISO 281's equivalent load from the window mean of P^(10/3) (here the ramp given as load_life)
        life_mean = ramp_truth(*coef["load_life"], 0.0, u_end)[0]
        assert d["equivalent_load_N"] == pytest.approx(life_mean[ref] ** 0.3, rel=1e-11)
        # the roller-load life from the window means of (Q/Q_c)^4.5 on the pin and (Q/Q_c)^4 on the bore (here
        # ramps given as those powers), over the rollers of pair 1's bearing and of every bearing of the kind
        qc_pin, qc_bore = raceway_ratings(b)
        fat = {k: ramp_truth(*coef[f"roller_{k}_fatigue"], 0.0, u_end[roller_of])[0] for k in ("inner", "outer")}
        for target, rollers in ((d, roller_of == ref), (d["all_rollers"], mine)):
            q_pin = qc_pin * fat["inner"][rollers].mean() ** (1 / 4.5)
            q_bore = qc_bore * fat["outer"][rollers].mean() ** (1 / 4)
            L = ((q_pin / qc_pin) ** 4.5 + (q_bore / qc_bore) ** 4.5) ** (-8 / 9)
            assert target["roller_equivalent_load_pin_N"] == pytest.approx(q_pin, rel=1e-11)
            assert target["roller_equivalent_load_bore_N"] == pytest.approx(q_bore, rel=1e-11)
            assert target["life_iso16281_Mrev"] == pytest.approx(L, rel=1e-11)
            assert target["life_iso16281_h"] == pytest.approx(L * 1e6 * 2 * math.pi / abs(planet[ref]) / 3600, rel=1e-11)
    for key in ("sun_inner", "inner_outer", "outer_ring"):
        mean, _, hi, lo, _ = ramp_truth(*coef[f"{key}_drive_force"], 0.0, 1.0)
        m = s["meshes"][key]
        assert m["drive_force_mean_N"] == pytest.approx(mean.mean(), rel=1e-11)
        assert m["drive_force_max_N"] == pytest.approx(hi.max(), rel=1e-11)
        x = ramp_truth(*coef[f"{key}_drive_deflection"], 0.0, 1.0)
        assert m["te_peak_to_peak_m"] == pytest.approx((x[2] - x[3]).max(), rel=1e-10)


def test_accumulators_average_a_sine_over_whole_periods_whatever_the_steps(scene):
    """x = c + A sin(2π t/P) with 7 periods in the window [t0, t1] (both inside a step), uneven steps of
    0.3–1.7 × P/400: the time mean is c and the RMS √(c² + A²/2) within the trapezoid rule's error (measured
    ≤ 2e-7; tolerance 2e-6), the maximum and minimum c ± A within the sampling of the crest, below
    1 − cos(π h_max/P) = 9e-5 A (measured 2e-8 A). An unweighted mean over the steps is off by 2–3e-3 here."""
    bs, system, template = scene
    P = 1.3e-3
    t0, t1 = 0.0211, 0.0211 + 7 * P
    stats = synthetic(scene, t0, t1, whole_revolutions=False)
    rng = np.random.default_rng(5)
    c, A = rng.uniform(1.0, 2.0, 3), rng.uniform(0.5, 1.0, 3)
    ts = uneven_steps(t0 - 1.1e-6, t1 + 3e-6, P / 400, seed=3)
    zeros = {k: np.zeros(n) for k, n in template.items()}
    zeros["cage_speed_rel"] = np.ones(template["cage_speed_rel"])

    def snap(t):
        return {**zeros, "sun_inner_drive_force": c + A * np.sin(2 * np.pi * t / P)}

    for ta, tb in zip(ts[:-1], ts[1:]):
        stats.step(Step(ta, snap(ta)), Step(tb, snap(tb)))
    st = stats.stats("sun_inner_drive_force")
    np.testing.assert_allclose(st["mean"], c, rtol=2e-6)
    np.testing.assert_allclose(st["rms"], np.sqrt(c * c + 0.5 * A * A), rtol=2e-6)
    np.testing.assert_allclose(st["max"], c + A, atol=9e-5 * A.max())
    np.testing.assert_allclose(st["min"], c - A, atol=9e-5 * A.max())
    assert stats.duration == pytest.approx(7 * P, rel=1e-12)


def test_pocket_impacts_count_onsets_in_each_bearings_window(scene):
    """Pocket impacts are contact onsets (the pocket's internal state, column 0: the approach speed, turns
    positive) faster than the element's speed floor, inside the bearing's own window: designed here, pair 1's
    inner bearing gets an impact at 0.5 m/s (peak 300 N), pair 2's one at 0.8 m/s still in contact when its
    cage closes its revolutions (it counts with the 500 N it reached), a touch at half the floor, one onset
    before t0 and one after the window closed (neither counts); an outer bearing gets one impact at 0.3 m/s.
    Pair 2's inner cage slips 2 %, so its window closes ≈ 20 steps after pair 1's: an onset in pair 1's bearing
    between the two closings is outside pair 1's window and does not count. Counts, speeds, peaks and impacts per
    cage revolution (2 whole revolutions of each of the 3 cages) are exactly the designed ones."""
    bs, system, template = scene
    bm, roller_of, planet, epi = owners(bs)
    nb = len(bm)
    b, sp = bs.bearing, bs.speeds
    T_in = cage_period(b, sp.carrier, sp.inner_planet)
    t0 = 0.005
    stats = synthetic(scene, t0, t0 + 2 * T_in)
    w_cage = epi * (1.0 - np.array([0.0, 0.0, 0.02, 0.0, 0.0, 0.0]))   # pair 2's inner cage closes last
    t_close = t0 + 2 * math.pi * stats.target / np.abs(w_cage)
    ts = uneven_steps(t0 - 5e-4, stats.t_end, T_in / 500, seed=9)
    v_floor = float(np.max(bs.model.element("pocket").v_min))     # the impact law's approach-speed floor
    n = template["pocket_force"]
    first = lambda i: int(np.flatnonzero(roller_of == i)[0])
    # (pocket, first step index of contact, steps in contact, approach speed, forces while in contact)
    k_close2 = int(np.searchsorted(ts, t_close[2]))
    k0 = int(np.searchsorted(ts, t0))
    k_close0 = int(np.searchsorted(ts, t_close[0]))
    assert k_close0 + 6 < k_close2 - 2
    events = [(first(0) + 3, k0 + 40, 3, 0.5, [100.0, 300.0, 200.0]),
              (first(2) + 7, k_close2 - 2, 6, 0.8, [400.0, 500.0, 900.0, 900.0, 900.0, 900.0]),
              (first(0) + 4, k0 + 80, 2, 0.5 * v_floor, [5.0, 6.0]),
              (first(0) + 5, 2, 3, 2.0, [700.0, 700.0, 700.0]),
              (first(4) + 1, int(np.searchsorted(ts, t_close[4])) + 3, 2, 3.0, [800.0, 800.0]),
              (first(1) + 2, k0 + 100, 2, 0.3, [50.0, 60.0]),
              (first(0) + 6, k_close0 + 2, 2, 1.5, [600.0, 600.0])]             # after pair 1's window closed
    z = np.zeros((ts.size, n))
    force = np.zeros((ts.size, n))
    for p, k, m, v, f in events:
        z[k:k + m, p] = v
        force[k:k + m, p] = f
    base = {k: np.ones(m) for k, m in template.items()}
    base["cage_speed_rel"], base["planet_speed_rel"] = w_cage, planet
    assert ts[2 + 3] < t0 < ts[k0] and ts[k_close2 - 1] < t_close[2] < ts[k_close2]
    steps = [Step(t, {**base, "pocket_force": force[i]}, {"pocket": z[i][:, None]}) for i, t in enumerate(ts)]
    for s0, s1 in zip(steps[:-1], steps[1:]):
        stats.step(s0, s1)
    s = stats.summary()
    d = s["inner"]
    assert d["pocket_impacts"] == 2
    assert d["pocket_impacts_per_rev"] == pytest.approx(2 / (3 * 2.0), rel=1e-12)
    assert d["pocket_touches_per_rev"] == pytest.approx(1 / (3 * 2.0), rel=1e-12)
    assert d["pocket_impact_speed_max_m_s"] == 0.8 and d["pocket_impact_speed_mean_m_s"] == pytest.approx(0.65)
    # the second impact's force rises from 500 to 900 N in the step where its window closes: the peak reached
    # within the window is the force there (linear in the step, as every window end is taken)
    k = k_close2 - 1
    peak = 500.0 + 400.0 * (t_close[2] - ts[k]) / (ts[k + 1] - ts[k])
    assert d["pocket_impact_peak_max_N"] == pytest.approx(peak, rel=1e-12)
    assert d["pocket_impact_peak_mean_N"] == pytest.approx(0.5 * (300.0 + peak), rel=1e-12)
    o = s["outer"]
    assert o["pocket_impacts"] == 1 and o["pocket_impacts_per_rev"] == pytest.approx(1 / (3 * stats.target[1]))
    assert o["pocket_impact_speed_max_m_s"] == 0.3 and o["pocket_impact_peak_max_N"] == 60.0
