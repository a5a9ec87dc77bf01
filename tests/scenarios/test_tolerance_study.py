"""The tolerance study (docs/tolerances.md): the static load sharing against truths it does not compute itself — a
perfect, symmetric machine shares exactly; a single pinhole error raises K_γ in proportion to its size — the sampler
against the distributions it claims, the statistics against synthetic data, bad input, and the files' schema."""
from __future__ import annotations

import csv
import json
import math
import warnings

import numpy as np
import pytest

from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from components.static import static_summary
from components.tolerance_sampling import (RUNOUT_SIGMAS, ToleranceSpec, coordinates, draw_errors, pin_names,
                                           replicate_of, sobol_points, teeth_seed)
from components.tolerances import radial_runout
from scenarios import cli, tolerance_study
from scenarios.core.command import USAGE

# no gravity and a mesh stiffness that does not vary along the mesh cycle: the three planets of a perfect machine are
# then the same at every instant (the 120° symmetry), whatever the mesh phases of the sequentially phased meshes
SYMMETRIC = {"gravity": "0 m/s^2", "mesh.stiffness_ratio": 1.0}


def _summary(overrides, snapshots, condition=3, direction="forward"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = build_dpgt(with_overrides(reference_dpgt(condition, direction), overrides))
    return static_summary(scene, snapshots)


def _k(s):
    q = tolerance_study.quantities_of(s)
    return np.array([q[k] for k in ("k_gamma_mesh", "k_gamma_sun_inner", "k_gamma_inner_outer", "k_gamma_outer_ring",
                                    "k_gamma_inner", "k_gamma_outer")])


def test_the_perfect_symmetric_machine_shares_its_load_exactly():
    """Perfect gears, equal planets, no gravity and a constant mesh stiffness: every planet is in the same state, so
    every K_γ (each mesh's and each bearing row's) is 1 to the static solver's convergence: its displacement
    tolerance (``length_tol``) over the smallest mesh deflection bounds a share's relative error (3e-6; measured
    1.2e-9–2.4e-8).

    The reference machine's static K_γ is not exactly 1 (below): its meshes are sequentially phased (31 sun teeth
    over 3 planets), so at one instant the planets sit at different points of the single/double-contact stiffness
    cycle and take different shares, and gravity turns once per carrier revolution in the carrier frame; the
    snapshots' average over the mesh phases and the revolution brings it towards 1."""
    import inspect

    from mbd.static import solve_static

    s = _summary(SYMMETRIC, 2)
    length_tol = inspect.signature(solve_static).parameters["length_tol"].default
    bound = length_tol / min(s["meshes"][m]["drive_deflection_mean_m"] for m in tolerance_study.MESHES)
    assert bound < 1e-5
    np.testing.assert_array_less(np.abs(_k(s) - 1.0), bound)


def test_the_reference_machine_s_shares_average_to_equal_over_the_revolution_and_mesh_cycle():
    """The reference machine, perfect, with gravity and its single/double tooth contact: the snapshots sample one
    carrier revolution (gravity's once-per-revolution share cancels) and every mesh phase stratum once (the
    sequentially phased meshes' shares average out), so K_γ − 1 falls fast with the snapshots — measured: meshes
    6.2e-4 at 8, 3.5e-5 at 32; bearing rows 3.7e-5 / 8.7e-5 at 8, 5.8e-6 / 4.7e-6 at 32. (Snapshots over one cage
    revolution, half a carrier revolution, left gravity's share: bearing rows 8.5e-4 at 64 snapshots; golden-ratio
    mesh phases left the meshes at 1.7e-3 at 8 and 3.2e-4 at 32 without gravity.)"""
    k8 = _k(_summary({}, 8)) - 1.0
    k32 = _k(_summary({}, 32)) - 1.0
    assert np.all(k32 > 0.0) and np.all(k32 < 0.2 * k8), (k8, k32)
    assert k32[0] < 1e-4 and k32[4:].max() < 2e-5, k32


@pytest.mark.parametrize("machine, snapshots", [("symmetric", 2), ("reference", 4)])
def test_k_gamma_rises_with_a_growing_pinhole_error_in_proportion(machine, snapshots):
    """Outer planet b1's pin 0, 5, 10, 20 µm ahead (tangential): every K_γ rises with the error. On the symmetric
    machine it starts at exactly 1 and K_γ − 1 is proportional to the error (a load share taken by the path's
    stiffness, linear while every contact stays closed; measured within 0.05 % for the meshes, 0.4 % for the
    bearing rows: the bearings' Hertz law is the nonlinearity, and the load's change is small against the load)."""
    base = SYMMETRIC if machine == "symmetric" else {}
    sizes = (0.0, 5.0, 10.0, 20.0)
    k = []
    for e in sizes:
        ov = dict(base)
        if e:
            ov["errors.pinhole"] = [{"planet": "b1", "radial": "0 um", "tangential": f"{e} um"}]
        k.append(_k(_summary(ov, snapshots)))
    k = np.array(k)
    assert np.all(np.diff(k, axis=0) > 0.0), k          # every mesh and both bearing rows, at every step
    if machine == "symmetric":
        per_um = (k[1:] - 1.0) / np.array(sizes[1:])[:, None]
        np.testing.assert_allclose(per_um, np.broadcast_to(per_um[1], per_um.shape), rtol=0.01)
        assert per_um[1, 0] > 1e-3                        # the mesh: > 0.1 % of its load per µm (measured 0.34 %)


# ---------------------------------------------------------------------------------------------------------------
# the sampler against the distributions it states
# ---------------------------------------------------------------------------------------------------------------
N_SAMPLES = 1024


@pytest.fixture(scope="module")
def draws():
    si = reference_dpgt(3, "forward").si()
    spec = ToleranceSpec(7, 10e-6, 5e-6, 2e-6, 0.5)
    u = sobol_points(N_SAMPLES, len(coordinates(3, 12)), 1, 8)
    return si, spec, [draw_errors(si, spec, u[i], teeth_seed(1, i)) for i in range(N_SAMPLES)]


def _within_standard_errors(x, mean, sd, n_se=3.0):
    """Mean and standard deviation of ``x`` against the truth, within ``n_se`` standard errors of a random sample
    (σ/√n and σ/√(2n)): what any honest sampler meets, a quasi-random one comfortably."""
    n = x.size
    assert abs(x.mean() - mean) < n_se * sd / math.sqrt(n), (x.mean(), mean)
    assert abs(x.std(ddof=1) / sd - 1.0) < n_se / math.sqrt(2 * n), (x.std(ddof=1), sd)


def test_pinholes_are_normal_with_the_tolerance_at_three_sigma(draws):
    _, spec, ds = draws
    for p in pin_names(3):
        for comp in ("radial", "tangential"):
            x = np.array([d[f"pinhole_{p}_{comp}_um"] for _, d in ds])
            _within_standard_errors(x, 0.0, 1e6 * spec.pinhole / 3.0)
            inside = np.mean(np.abs(x) <= 1e6 * spec.pinhole)
            assert abs(inside - 0.9973) < 3 * math.sqrt(0.9973 * 0.0027 / x.size), inside


def test_runouts_cover_the_iso_1328_tolerance_for_99_7_percent_of_gears(draws):
    """Eccentricity e = |(x, y)|, x and y normal with σ = F_r/(2·3.44): Rayleigh, mean σ√(π/2); 2e ≤ F_r for 99.73 %;
    its direction uniform (mean of cos and sin 0)."""
    si, spec, ds = draws
    for g, gear in (("sun", si.gears.sun), ("ring", si.gears.ring), ("b2", si.gears.outer_planet)):
        F_r = radial_runout(gear.module, 2.0 * gear.pitch_radius, spec.flank_class)
        sigma = 1e6 * F_r / (2.0 * RUNOUT_SIGMAS)
        e = np.array([d[f"runout_{g}_um"] for _, d in ds])
        phase = np.radians([d[f"runout_{g}_phase_deg"] for _, d in ds])
        sd_e = sigma * math.sqrt(2.0 - math.pi / 2.0)
        assert abs(e.mean() - sigma * math.sqrt(math.pi / 2.0)) < 3 * sd_e / math.sqrt(e.size)
        inside = np.mean(2.0 * e <= 1e6 * F_r)
        assert abs(inside - 0.9973) < 3 * math.sqrt(0.9973 * 0.0027 / e.size), inside
        assert abs(np.cos(phase).mean()) < 3 / math.sqrt(2 * e.size) and abs(np.sin(phase).mean()) < 3 / math.sqrt(2 * e.size)


def test_clearances_and_rollers_are_uniform_in_their_bands(draws):
    """Each bearing's clearance uniform in nominal ± tolerance (variance tol²/3); its rollers within ± lot/2 about
    the bearing's shift of −ΔP_d/2 (so each roller's deviation + ΔP_d/2 is uniform with variance lot²/12)."""
    si, spec, ds = draws
    nominal, tol, lot = 1e6 * si.bearing.clearance, 1e6 * spec.clearance, 1e6 * spec.roller_lot
    for p in pin_names(3):
        c = np.array([d[f"clearance_{p}_um"] for _, d in ds])
        assert c.min() >= nominal - tol and c.max() <= nominal + tol
        _within_standard_errors(c, nominal, tol / math.sqrt(3.0))
    rel = []
    for ov, d in ds[:64]:
        for r in ov["errors.roller_diameter"]:
            dP = d[f"clearance_{r['planet']}_um"] - nominal
            rel.append(1e6 * float(r["deviation"].split()[0]) + 0.5 * dP)
    rel = np.array(rel)
    assert rel.size == 64 * 6 * 12 and np.abs(rel).max() <= 0.5 * lot + 1e-9
    _within_standard_errors(rel, 0.0, lot / math.sqrt(12.0))


def test_the_sobol_sequences_keep_their_first_machines_and_zero_tolerances_draw_nothing():
    """Machine i is the (i // R)-th point of replicate i mod R: a longer study keeps its first machines; every
    replicate is its own scrambling (another seed, other points), and each replicate's points are a Sobol net
    (balanced: 8 points of a base-2 net put one point in each eighth of every coordinate)."""
    d = len(coordinates(3, 12))
    np.testing.assert_array_equal(sobol_points(64, d, 5, 4), sobol_points(1000, d, 5, 4)[:64])
    assert not np.array_equal(sobol_points(8, d, 5, 4), sobol_points(8, d, 6, 4))
    u = sobol_points(64, d, 5, 8)
    for r in range(8):
        rep = u[replicate_of(np.arange(64), 8) == r]
        assert all(sorted(np.floor(8 * rep[:, k]).astype(int)) == list(range(8)) for k in range(d))
    assert not np.allclose(u[0::8], u[1::8])
    si = reference_dpgt(3, "forward").si()
    ov, drawn = draw_errors(si, ToleranceSpec(5, 0.0, 0.0, 0.0, 0.5), sobol_points(1, d, 1, 8)[0], 7)
    assert all(float(x["radial"].split()[0]) == 0.0 == float(x["tangential"].split()[0]) for x in ov["errors.pinhole"])
    assert ov["errors.roller_diameter"] == []
    assert ov["errors.flank_class"] == [{"gear": "all", "grade": 5, "seed": 7, "systematic_share": 0.5}]


def test_every_machine_draws_its_own_teeth():
    """Two machines of a study have different teeth: their tooth seeds differ, and so do their gears' tables."""
    from components.teeth import gear_table
    seeds = [teeth_seed(1, i) for i in range(64)]
    assert len(set(seeds)) == 64
    tables = []
    for i in (0, 1):
        p = with_overrides(reference_dpgt(3), {"errors.flank_class": [
            {"gear": "all", "grade": 6, "seed": seeds[i], "systematic_share": 0.5}]})
        tables.append(gear_table(p.si(), "sun"))
    assert np.abs(tables[0] - tables[1]).max() > 1e-7


# ---------------------------------------------------------------------------------------------------------------
# statistics against synthetic truths
# ---------------------------------------------------------------------------------------------------------------
def test_replicate_intervals_cover_the_truth_at_their_level():
    """Randomised QMC done right: over 300 studies (seeds) of 256 points in 8 replicates, the 95 % intervals of the
    mean of a step function (the share of points with u1 + u2 < 0.7: 0.245) and of the P90 and P10 of a standard
    normal (±1.2816) hold the truth in 88–99 % of the studies (measured 95 %, 91 %, 91 %). Intervals without the
    1/√R hold it in every study; numpy's default percentiles, biased on a net's evenly spread points, in 1 %."""
    from scipy.stats import norm
    hits = np.zeros(3)
    n, R, studies = 256, 8, 300
    rep = replicate_of(np.arange(n), R)
    for seed in range(studies):
        u = sobol_points(n, 3, seed, R)
        m = tolerance_study.percentile_ci((u[:, 0] + u[:, 1] < 0.7).astype(float), None, rep)
        z = norm.ppf(u[:, 2])
        p90, p10 = (tolerance_study.percentile_ci(z, q, rep) for q in (90.0, 10.0))
        hits += [m["ci95"][0] < 0.245 < m["ci95"][1], p90["ci95"][0] < 1.2816 < p90["ci95"][1],
                 p10["ci95"][0] < -1.2816 < p10["ci95"][1]]
    cover = hits / studies
    assert np.all((cover >= 0.88) & (cover <= 0.99)), cover


def test_percentiles_read_the_right_tail_and_the_convergence_is_of_the_p90():
    """Synthetic samples 0..999 in 8 replicates (replicate r holds r, r + 8, …): Hazen's P10 of each is r + 96 and its
    P90 r + 896, so the estimates are 99.5 and 899.5, the mean 499.5; equal values have no interval; the convergence
    steps are 16, 32, … samples (2R, 4R, …), each the P90 of its prefix, and the P90 settles inside the final
    interval."""
    x = np.arange(1000.0)
    rep = replicate_of(np.arange(1000), 8)
    assert tolerance_study.percentile_ci(x, 10.0, rep)["value"] == pytest.approx(99.5)
    assert tolerance_study.percentile_ci(x, 90.0, rep)["value"] == pytest.approx(899.5)
    assert tolerance_study.percentile_ci(x, None, rep)["value"] == pytest.approx(499.5)
    assert tolerance_study.percentile_ci([1.0, 1.0, 1.0, 1.0], 90.0, [0, 1, 0, 1]) == {"value": 1.0, "ci95": None}
    rng = np.random.default_rng(3)
    y = rng.normal(1.05, 0.02, 256)
    r = replicate_of(np.arange(256), 8)
    conv = tolerance_study.convergence(y, r, 8)
    assert [s["samples"] for s in conv["p90"]] == [16, 32, 64, 128, 256]
    assert [s["value"] for s in conv["p90"]] == pytest.approx(
        [np.mean([np.percentile(y[:n][r[:n] == k], 90, method="hazen") for k in range(8)]) for n in (16, 32, 64, 128, 256)])
    lo, hi = conv["p90"][-1]["ci95"]
    settled = conv["settled_at_samples"]
    assert all(lo <= s["value"] <= hi for s in conv["p90"] if s["samples"] >= settled)
    earlier = [s for s in conv["p90"] if s["samples"] < settled]
    assert not earlier or not (lo <= earlier[-1]["value"] <= hi)


# ---------------------------------------------------------------------------------------------------------------
# the command: bad input in one line, the files and their schema
# ---------------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("argv, words", [
    (["--pinhole-tolerance", "10"], "argument --pinhole-tolerance: expected a length (e.g. '20 um'), got '10'"),
    (["--pinhole-tolerance", "10 kg"], "argument --pinhole-tolerance: expected a length"),
    (["--clearance-tolerance", "-5 um"], "argument --clearance-tolerance: must be a length >= 0"),
    (["--gear-class", "12"], "argument --gear-class: must be a whole number in [1, 11], got '12'"),
    (["--gear-class", "0,5"], "argument --gear-class: must be a whole number in [1, 11], got '0'"),
    (["--samples", "0"], "argument --samples: must be a whole number in [1, ∞], got '0'"),
    (["--samples", "-3"], "argument --samples: must be a whole number in [1, ∞], got '-3'"),
    (["--torques", "0.5,0"], "argument --torques: a fraction of the rated torque must be > 0, got '0'"),
    (["--torques", "-1"], "argument --torques: a fraction of the rated torque must be > 0, got '-1'"),
    (["--conditions", "3,4"], "argument --conditions: condition 4 transmits no torque"),
    (["--set", "errors.pinhole=[]"], "errors.pinhole is set by this study's the tolerance options"),
    (["--set", "operating.output_power=100 kW"], "operating.output_power is set by this study's --conditions"),
])
def test_bad_input_is_one_line_naming_the_option(argv, words, tmp_path, capsys):
    assert cli.main(["tolerance_study", *argv, "--out", str(tmp_path / "out")]) == USAGE
    err = capsys.readouterr().err
    assert err.startswith("error: ") and words in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def _study(out, *more):
    return tolerance_study.main(["--samples", "3", "--snapshots", "1", "--dynamic", "0", "--gear-class", "5",
                                 "--directions", "forward", "--workers", "1", "--no-progress", "--out", str(out), *more])


def test_a_small_study_writes_its_files_reuses_its_solutions_and_refuses_others(tmp_path, capsys):
    """Three machines, one snapshot, static only: samples.csv has a row per machine (the perfect one marked) with the
    drawn errors and every quantity; statistics.json every statistic with its interval; a re-run solves nothing;
    other tolerances in the same folder are refused in one line unless --overwrite."""
    out = tmp_path / "tol"
    assert _study(out) == 0
    text = capsys.readouterr().out
    assert "static: 4 solutions to solve, 0 reused" in text and "design mesh K_γ P90 = " in text
    rows = list(csv.DictReader((out / "samples.csv").open()))
    assert [r["sample"] for r in rows] == ["perfect", "0", "1", "2"]
    cols = rows[0].keys()
    for k in [*tolerance_study.QUANTITIES, "pinhole_b3_tangential_um", "runout_ring_um", "clearance_a1_um",
              "roller_b2_range_um", "teeth_seed", "output_torque_N_m", "static_solve_s", "error"]:
        assert k in cols, k
    assert all(r["error"] == "" for r in rows) and float(rows[1]["k_gamma_mesh"]) > 1.0
    stats = json.loads((out / "statistics.json").read_text())
    g, = stats["groups"]
    assert (g["class"], g["condition"], g["direction"], g["torque_fraction"], g["samples"]) == (5, 3, "forward", 1.0, 3)
    for k, v in g["quantities"].items():
        assert set(v) == ({"p10"} if k.startswith("life_") else {"mean", "p50", "p90", "p99"}), k
        assert all(set(x) == {"value", "ci95"} for x in v.values())
    assert g["perfect_machine"]["k_gamma_mesh"] == pytest.approx(float(rows[0]["k_gamma_mesh"]))
    assert stats["method"]["defaults"]["pinhole"]["source"] == "[assumed]"
    assert "lives' percentiles are static" in (out / "answer.md").read_text()        # what the lives leave out
    assert (out / "answer.md").read_text().startswith("Machine: reference machine [")
    for f in ("answer.md", "k_gamma_distribution.png", "k_gamma_torque.png", "life_cdf.png", "study.json"):
        assert (out / f).stat().st_size > 0, f
    assert _study(out) == 0
    assert "static: 0 solutions to solve, 4 reused" in capsys.readouterr().out
    assert _study(out, "--pinhole-tolerance", "20 um") == USAGE
    err = capsys.readouterr().err
    assert "were made from other parameters" in err and "--overwrite" in err and err.count("\n") == 1
    assert _study(out, "--pinhole-tolerance", "20 um", "--overwrite") == 0


def test_agreement_rows_give_the_dynamic_increment(tmp_path):
    """agreement.csv's rows from a static record and a 'dynamic' summary whose bearing loads are 2 % higher: the
    increments are the differences, the load increments 2 %."""
    s = _summary({}, 1)
    rec = {"summary": tolerance_study._kept(s)}
    rec["quantities"] = tolerance_study.quantities_of(rec["summary"])
    dyn = json.loads(json.dumps(s))
    for kind in ("inner", "outer"):
        for k in ("bearing_load_mean_per_planet_N", "bearing_load_max_per_planet_N"):
            dyn[kind][k] = [1.02 * x for x in dyn[kind][k]]
    key = (5, 3, "forward", 1.0, 0)
    row, = tolerance_study.agreement_rows({key: rec}, {key: dyn})
    assert row["k_gamma_mesh_increment"] == 0.0 and row["sample"] == 0
    for kind in ("inner", "outer"):
        assert row[f"bearing_load_mean_{kind}_N_increment_pct"] == pytest.approx(2.0)
        assert row[f"bearing_load_max_{kind}_N_increment_pct"] == pytest.approx(2.0)
