"""Reduced-form smoke tests of the numerics scenarios: they run, write their documented outputs, and
the numbers in them are sane (errors finite and ordered, failures reported with a cause)."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import mbd

from scenarios.numerics import bench_breakdown, bench_sliced, bench_threads, benchmark, stability, work_precision
from scenarios.numerics.common import StateSampler, dpgt_problem, settled_state


def test_state_sampler_hermite_is_exact_for_cubics():
    # q(t) = t³ with v, a consistent: cubic Hermite in q with v reproduces it exactly
    import mbd

    s0 = mbd.State(1.0, np.array([1.0]), np.array([3.0]), np.array([6.0]), np.zeros(1))
    s1 = mbd.State(2.0, np.array([8.0]), np.array([12.0]), np.array([12.0]), np.zeros(1))
    smp = StateSampler([1.0, 1.25, 1.5, 2.0])
    smp.bind(None, None, s0)          # an observer: the start state at bind, then every accepted step
    smp.step(s0, s1)
    assert smp.complete
    assert np.allclose(np.ravel(smp.q), [1.0, 1.25**3, 1.5**3, 8.0], rtol=1e-14)
    assert np.allclose(np.ravel(smp.v), [3.0, 3 * 1.25**2, 3 * 1.5**2, 12.0], rtol=1e-14)


def test_work_precision_rig_quick(tmp_path):
    assert work_precision.main(["--problems", "rig", "--quick", "--window", "1e-4", "--cap", "3",
                                "--out", str(tmp_path), "--figures", str(tmp_path / "fig")]) == 0
    for f in ("work_precision_rig.csv", "work_precision_rig.png", "work_precision_rig_rms.png",
              "work_precision.json", "work_precision.md", "fig/work_precision_rig.png"):
        assert (tmp_path / f).stat().st_size > 0, f
    rows = list(csv.DictReader(open(tmp_path / "work_precision_rig.csv")))
    assert set(work_precision.FIELDS) == set(rows[0])
    methods = {r["method"] for r in rows}
    assert {"HHT", "HHT-adaptive", "Radau", "BDF", "LSODA", "RK45", "DOP853"} <= methods
    done = [r for r in rows if r["completed"] == "True"]
    assert done, "no contender finished"
    for r in done:
        assert np.isfinite(float(r["err_pin_rel"])) and float(r["wall_s"]) > 0
    for r in rows:
        if r["completed"] != "True":
            assert r["message"], "an unfinished run must say why"
    summ = json.loads((tmp_path / "work_precision.json").read_text())["problems"]["rig"]
    chk = summ["reference"]["check_vs_reference"]["err_pin_rel"]
    # the reference check (2 h_ref) lies below the coarsest HHT setting's error
    hht = [float(r["err_pin_rel"]) for r in done if r["method"] == "HHT"]
    assert chk < max(hht)
    # HHT with a 5× smaller step is more accurate (same alpha)
    e = {(r["alpha"], float(r["h_s"])): float(r["err_pin_rel"]) for r in done if r["method"] == "HHT"}
    assert e[("0.0", 2e-6)] < e[("0.0", 1e-5)]


def test_stability_reports_success_and_refusal(tmp_path):
    assert stability.main(["--cases", "nominal,Z24", "--window", "2e-4", "--cap", "3", "--out", str(tmp_path / "a")]) == 0
    assert stability.main(["--cases", "N4", "--window", "2e-4", "--cap", "3", "--no-radau", "--out", str(tmp_path / "b")]) == 0
    # partial runs (e.g. in parallel) merge into one table in CASES order
    assert stability.main(["--merge", f"{tmp_path / 'b'},{tmp_path / 'a'}", "--out", str(tmp_path)]) == 0
    rows = list(csv.DictReader(open(tmp_path / "stability.csv")))
    cases = [r["case"] for r in rows]
    assert cases[0] == "nominal" and cases[-1] == "Z24" and "N4" in cases      # CASES order, not argument order
    assert set(stability.FIELDS) == set(rows[0])
    by = {(r["case"], r["integrator"]): r for r in rows}
    nom = by[("nominal", "HHT α=-0.3 adaptive")]
    assert nom["completed"] == "True" and int(nom["steps"]) > 0 and float(nom["newton_per_step"]) >= 1
    assert float(nom["rms_pin_load_N"]) > 0
    assert ("nominal", "Radau rtol=1e-5") in by
    z24 = by[("Z24", "build")]
    assert z24["completed"] == "False" and "rollers" in z24["message"]      # refused with its cause
    # N = 4 pairs collide on the reference gears: the check only warns; the case is run and labelled
    n4 = by[("N4", "design check")]
    assert n4["completed"] == "warning" and "collide" in n4["message"]
    n4run = by[("N4", "HHT α=-0.3 adaptive")]
    assert "NON-PHYSICAL" in n4run["description"] and n4run["completed"] == "True"
    md = (tmp_path / "stability.md").read_text()
    assert "| nominal |" in md and "Z24" in md and "N4 (non-physical)" in md


def test_benchmark_json_last_line(tmp_path, capsys):
    assert benchmark.main(["--json", "--settle", "2e-4", "--window", "2e-4", "--ref-window", "1e-4",
                           "--h", "1e-5", "--scipy-cap", "3", "--repeats", "1", "--out", str(tmp_path),
                           "--stiff", "10", "--stiff-settle", "2e-4", "--stiff-window", "1e-4",
                           "--scipy-methods", "BDF"]) == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    d = json.loads(last)
    for k in ("wall_s", "simulated_s", "steps", "newton_per_step", "rel_error_rms_inner_race", "reference_wall_s",
              "speedup_vs_reference", "scipy_best_method", "scipy_best_wall_s", "scipy_rel_error", "per_step_over_eval"):
        assert k in d, k
    assert d["engine"] == "compiled" and d["reference_wall_s"] > 0 and d["speedup_vs_reference"] > 0
    assert d["scipy_same_residual"] is True          # scipy's solvers call the same compiled residual
    (stiff,) = d["stiff"]                            # the stiff comparison: contacts x10, HHT against scipy
    assert stiff["factor"] == 10 and stiff["hht_completed"] and stiff["scipy"][0]["engine"] == "compiled"
    # fixed step: a step whose Newton fails is retried with h/2, so at least window/h steps
    assert d["steps"] >= 20 and d["simulated_s"] == pytest.approx(2e-4)
    assert d["per_step_over_eval"] > 0 and d["wall_s"] > 0
    assert d["scipy_best_method"] in ("Radau", "BDF", "LSODA", "RK45")
    assert (tmp_path / "benchmark.json").exists()


def test_bench_breakdown_counts_the_engines_work_and_splits_its_time(tmp_path, capsys):
    """The breakdown's calls per step are the engine's own counters over the same window (an independent
    mbd.simulate from the same settled state), every contact family has its row, and the target's µs per step is
    3 s over the steps of 0.1 s."""
    window, h = 2e-4, 1e-5
    assert bench_breakdown.main(["--json", "--settle", "2e-4", "--window", str(window), "--h", str(h), "--samples", "2",
                                 "--rounds", "1", "--reps", "1", "--out", str(tmp_path)]) == 0
    d = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    prob = dpgt_problem(settle=2e-4)
    s0, _ = settled_state(prob, tmp_path / "dpgt_settled.npz")
    res = mbd.simulate(prob.model, t_end=s0.t + window, state=s0.copy(), stepper=mbd.HHT(alpha=-0.3),
                       controller=mbd.FixedStep(h), progress=False)
    c = res.counters
    assert d["steps"] == res.steps >= round(window / h)
    assert d["calls_per_step"]["residual"] == pytest.approx(c["residual"] / res.steps)
    assert d["calls_per_step"]["jacobian"] == pytest.approx(c["jacobian"] / res.steps)
    assert d["calls_per_step"]["solve"] == pytest.approx(c["newton"] / res.steps)
    parts = {r["part"]: r for r in d["rows"]}
    assert {"race", "pocket", "guide", "drag", "meshes"} <= set(parts)
    assert all(parts[f]["jacobian_us"] > 0 and parts[f]["residual_us"] > 0 for f in ("race", "pocket", "drag"))
    assert sum(r["us_per_step"] for r in d["rows"]) == pytest.approx(d["cpu_per_step_us"])
    assert d["target_us_per_step"] == pytest.approx(3.0 / (res.steps * 0.1 / window) * 1e6)
    assert (tmp_path / "breakdown.json").exists()


def test_bench_breakdown_splits_the_sliced_machines_step(tmp_path, capsys):
    """--slices: the sliced machine (more DOFs than the planar one) from the planar settled state, its calls per step
    the engine's own counters over the same window, the sliced race contacts in the race row."""
    window, h = 1e-4, 1e-5
    assert bench_breakdown.main(["--json", "--settle", "2e-4", "--window", str(window), "--h", str(h), "--samples", "2",
                                 "--rounds", "1", "--reps", "1", "--slices", "5", "--out", str(tmp_path)]) == 0
    d = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    planar = dpgt_problem(settle=2e-4)
    s0, _ = settled_state(planar, tmp_path / "dpgt_settled.npz")
    prob = dpgt_problem(settle=2e-4, overrides={"bearing.model": "sliced", "bearing.slicing.slices": 5})
    ext = lambda x: np.concatenate([x, np.zeros(prob.model.ndof - x.size)])           # noqa: E731
    s1 = mbd.State(s0.t, ext(s0.q), ext(s0.v), ext(s0.a), ext(s0.f), dict(s0.z))
    res = mbd.simulate(prob.model, t_end=s1.t + window, state=s1, stepper=mbd.HHT(alpha=-0.3),
                       controller=mbd.FixedStep(h), progress=False)
    c = res.counters
    assert d["slices"] == 5 and d["dofs"] == prob.model.ndof > planar.model.ndof
    assert d["steps"] == res.steps
    assert d["calls_per_step"]["residual"] == pytest.approx(c["residual"] / res.steps)
    assert d["calls_per_step"]["jacobian"] == pytest.approx(c["jacobian"] / res.steps)
    race = next(r for r in d["rows"] if r["part"] == "race")
    assert race["residual_us"] > 0 and race["jacobian_us"] > race["residual_us"]
    assert (tmp_path / "breakdown_sliced5.json").exists()


def test_bench_threads_model_is_amdahl_s_law_with_the_threaded_share():
    """The closed forms: no parallel share gives 1 on any thread count, a wholly parallel step n on n threads, half of
    it 4/3 on 2; an overhead o of the serial step adds to the time. The share is the threaded families' rows: their
    Jacobian calls on the planar machine (its residuals stay serial), every call on the sliced one."""
    assert bench_threads.amdahl(0.0, 8) == 1.0 and bench_threads.amdahl(1.0, 8) == pytest.approx(8.0)
    assert bench_threads.amdahl(0.5, 2) == pytest.approx(4 / 3) and bench_threads.amdahl(0.5, 2, 0.25) == 1.0
    assert set(bench_threads.THREADED_ROWS) == {"race", "pocket", "guide", "drag"}
    rows = [{"part": p, "residual_us": r, "jacobian_us": j, "us_per_step": 4 * r + 0.5 * j}
            for p, r, j in (("race", 6.0, 18.0), ("pocket", 3.0, 10.0), ("guide", 1.0, 2.0), ("drag", 1.0, 6.0),
                            ("meshes", 2.0, 3.0), ("assembly (gather, scatter, frame terms)", 3.0, 20.0))]
    bd = {"rows": rows, "cpu_per_step_us": 200.0, "calls_per_step": {"residual": 4.0, "jacobian": 0.5}, "slices": 0}
    planar = bench_threads.parallel_share(bd)
    assert planar["threaded_us"] == pytest.approx(0.5 * (18 + 10 + 2 + 6)) and planar["p"] == pytest.approx(18 / 200)
    sliced = bench_threads.parallel_share(bd | {"slices": 21})
    assert sliced["threaded_us"] == pytest.approx(4 * 11 + 0.5 * 36) and sliced["p"] == pytest.approx(62 / 200)


def test_bench_sliced_counts_the_step_loops_work_as_the_engine_does():
    """The step loop timed alone does the work mbd.simulate counts over the same fixed steps from the same state (both
    start without a Jacobian), on both machines; the ratio is of the two CPU medians."""
    out = bench_sliced.measure(3, 5, 2, 1, 2e-4, numpy=False, loop_steps=3, budget=1.0)
    assert out["repeats"] == 1 and out["loop_steps"] == 3
    assert out["sliced_over_planar_loop_cpu"] == pytest.approx(out["sliced_compiled_loop_cpu_us_per_step"]
                                                               / out["planar_compiled_loop_cpu_us_per_step"])
    import warnings
    from components.dpgt import build_dpgt
    from components.presets import reference_dpgt
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # the reference machine's known design warnings (tip overlaps)
        planar = build_dpgt(reference_dpgt(3, "forward"))
    s = mbd.simulate(planar.model, planar.q0, planar.v0, 2e-4, stepper=mbd.PRODUCTION.stepper(),
                     controller=mbd.PRODUCTION.controller(), progress=False, engine="compiled").state
    res = mbd.simulate(planar.model, t_end=s.t + 3 * bench_sliced.H, state=s, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.FixedStep(bench_sliced.H), progress=False, engine="compiled")
    calls = out["planar_compiled_calls_per_step"]
    assert calls["residual"] == pytest.approx(res.counters["residual"] / res.steps)
    assert calls["jacobian"] == pytest.approx(res.counters["jacobian"] / res.steps)
    assert calls["newton"] == pytest.approx(res.counters["newton"] / res.steps)


def test_warm_says_loaded_only_when_every_group_was_loaded():
    """scenarios.warm's line: "loaded from the cache" only when numba loaded the engine, output and accumulator
    kernels all three; a single group compiled makes it "compiled", naming that group (numba's hit/miss counts)."""
    from collections import Counter
    from types import SimpleNamespace

    from scenarios.numerics.warm import warm_line

    sig = ("float64[:]",)
    hit = SimpleNamespace(stats=SimpleNamespace(cache_hits=Counter({sig: 1}), cache_misses=Counter()))
    miss = SimpleNamespace(stats=SimpleNamespace(cache_hits=Counter(), cache_misses=Counter({sig: 1})))
    never = SimpleNamespace(stats=SimpleNamespace(cache_hits=Counter(), cache_misses=Counter()))   # not called
    assert warm_line({"engine": hit, "outputs": hit, "accumulators": hit}, 1.2) == \
        "engine kernels: loaded from the cache in 1 s"
    assert warm_line({"engine": hit, "outputs": miss, "accumulators": hit}, 14.6) == \
        "engine kernels: compiled in 15 s (outputs compiled; engine, accumulators loaded from the cache)"
    assert warm_line({"engine": miss, "outputs": miss, "accumulators": never}, 70) == \
        "engine kernels: compiled in 70 s (engine, outputs, accumulators compiled)"


def test_warm_reads_numba_s_own_count_of_compiles(tmp_path):
    """compiled_here against numba itself: a cached kernel in a scratch NUMBA_CACHE_DIR is compiled by the first
    process and loaded by the second (a one-line kernel: cheap, unlike the engine's)."""
    import os
    import subprocess
    import sys

    from tests.support import ROOT

    (tmp_path / "tiny_kernel.py").write_text("from numba import njit\n\n@njit(cache=True)\ndef f(x):\n    return 2 * x\n")
    code = ("import tiny_kernel\nfrom mbd.compile_time import compiled_here\n"
            "tiny_kernel.f(1.0)\nprint(compiled_here(tiny_kernel.f))\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)]),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    said = [subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=300).stdout.strip() for _ in range(2)]
    assert said == ["True", "False"]


_AFTER_WARM = """
import warnings
import numpy as np
import mbd
from components.dpgt import build_dpgt
from components.planetary import build_single_planetary
from components.presets import reference_dpgt
from components.statistics.accumulate import accumulate_steps, compile_accumulators
from mbd.compiled.outputs import family_outputs
from mbd.compiled.runner import CompiledRunner
from mbd.compiled.stepper import advance
from scenarios.numerics.common import rig_problem

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    scenes = [build_dpgt(reference_dpgt(c)) for c in (1, 3)] + [rig_problem().built, build_single_planetary()]
s = mbd.PRODUCTION
for scene in scenes:
    system = mbd.System(scene.model)
    CompiledRunner(system, s.stepper(), s.controller())
    z = {k: np.asarray(x)[None] for k, x in system.init_internal().items()}
    mbd.output_evaluator(system, "compiled").outputs_batch(np.zeros(1), scene.q0[None], scene.v0[None], z)
compile_accumulators()
for kernel in (advance, family_outputs, accumulate_steps):
    print(sum(kernel.stats.cache_misses.values()), sum(kernel.stats.cache_hits.values()) > 0)
"""


@pytest.mark.slow
def test_after_warm_the_default_scenes_compile_nothing():
    """`python -m scenarios.warm` compiles every kernel group the default scenes need: after it, a fresh process
    building the DPGT at conditions 1 and 3, the bearing rig and a single planetary stage (each its compiled step loop
    and outputs) and the statistics' accumulators loads every one from numba's cache — numba's own count: no miss,
    hits (the scenes' family groups are subsets of the warmed one, registry.groups_to_compile). Run in this
    checkout's cache: after `make warm` the warm step itself only loads; on a cold cache it compiles first."""
    import os
    import subprocess
    import sys

    from tests.support import ROOT

    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    warm = subprocess.run([sys.executable, "-m", "scenarios.warm"], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=3000)
    assert warm.returncode == 0, warm.stderr
    assert warm.stdout.startswith("engine kernels: ")
    after = subprocess.run([sys.executable, "-c", _AFTER_WARM], cwd=ROOT, env=env, capture_output=True, text=True,
                           timeout=600)
    assert after.returncode == 0, after.stderr
    assert after.stdout.split("\n")[:3] == ["0 True"] * 3, after.stdout + after.stderr
    assert "mbd: compiling" not in after.stderr
