"""The statistics of a compiled run are taken a block of steps at a time: the element outputs of
every state of the block in one call per family (mbd.System.outputs_batch, vectorised; the contacts' from their
compiled kernels, mbd.compiled.outputs), the per-step quantities of all of them at once
(WindowStatistics.snapshots), then the compiled accumulators over the block. These tests hold that path to the
step-by-step one, which evaluates one state at a time (System.outputs, the reference the statistics-truth tests
and the element tests check), and the compiled outputs' summary to the numpy kernels'; the accumulators themselves
are held to synthetic truths in test_statistics_truths.py."""
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

import mbd
from components.dpgt import build_dpgt
from components.outputs import WindowStatistics
from components.presets import reference_dpgt
from components.scene import SceneOptions

from tests.support.dpgt_runs import OUTPUT_ROUND_OFF, faulty_machine, summary_numbers
from tests.support.scenes import spinning_scene
from tests.support.strategies import accelerating_profile


def build(params, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_dpgt(params, SceneOptions(**options))


def _compare_outputs(system, states):
    t = np.array([s.t for s in states])
    q, v = np.stack([s.q for s in states]), np.stack([s.v for s in states])
    z = {k: np.stack([np.asarray(s.z[k]) for s in states]) for k in states[0].z}
    batch = system.outputs_batch(t, q, v, z)
    n_keys = 0
    for i, s in enumerate(states):
        one = system.outputs(s.t, s.q, s.v, s.z)
        assert set(one) == set(batch)
        for fam, out in one.items():
            assert set(out) == set(batch[fam]), fam
            for key, val in out.items():
                got = batch[fam][key][i]
                np.testing.assert_allclose(got, np.broadcast_to(val, got.shape), rtol=1e-12,
                                           atol=OUTPUT_ROUND_OFF * np.max(np.abs(got), initial=0.0), err_msg=f"{fam}.{key}")
                n_keys += 1
    return n_keys


@pytest.mark.parametrize("frame", ["rotating", "fixed"])
def test_outputs_of_k_states_at_once_equal_one_state_at_a_time(frame):
    """Every output of every element family of the faulty machine (tooth pairs, spall, pockets with impact
    states, guides, drag, drive) at four states of its load ramp, in both frames: the batch equals the
    one-state evaluation to 1e-12 (and the round-off above)."""
    bs = build(faulty_machine(), frame=frame)
    seen = []

    class Keep(mbd.Observer):
        def step(self, s0, s1):
            if s1.t > 2e-3 and len(seen) < 4 and (not seen or s1.t > seen[-1].t + 2e-4):
                seen.append(s1)

    mbd.simulate(bs.model, bs.q0, bs.v0, 3e-3, stepper=mbd.PRODUCTION.stepper(),
                 controller=mbd.PRODUCTION.controller(), progress=False, observers=[Keep()])
    assert len(seen) == 4 and any(np.any(s.z[k][:, 0] > 0) for s in seen for k in s.z if "pocket" in k)
    assert _compare_outputs(mbd.System(bs.model), seen) > 100


def test_outputs_batch_with_fixed_bodies_in_an_accelerating_frame():
    """A housing at rest in the fixed frame seen from an accelerating frame (the fixed bodies' motion and the
    frame's state per state of the batch), a ground support acting along the fixed axes."""
    model = spinning_scene(mbd.Frame(profile=accelerating_profile(30.0, 400.0)), fixed_body=True)
    system = mbd.System(model)
    rng = np.random.default_rng(3)
    n = int(np.count_nonzero(~model.fixed)) * 3
    states = [mbd.State(t, rng.normal(0, 0.01, n), rng.normal(0, 1.0, n), np.zeros(n), np.zeros(n), {})
              for t in (0.0, 0.013, 0.05)]
    assert model.fixed.any() and _compare_outputs(system, states) > 10


class StepByStep(WindowStatistics):
    """The same statistics, one state at a time (mbd.Observer.on_block calls step per step)."""
    def on_block(self, block):
        mbd.Observer.on_block(self, block)


def test_block_statistics_equal_step_by_step_on_a_run_with_impacts_film_and_faults():
    """On the faulty machine, reverse (pocket impacts), the statistics of the compiled run taken in blocks equal
    those taken step by step from the same steps: every number of the summary to 1e-9, counts exactly; the
    window (shorter than a cage revolution: the nominal one) starts and ends inside blocks."""
    bs = build(faulty_machine("reverse"))
    t0, t1 = 4e-3, 6e-3
    block, single = WindowStatistics(bs, t0, t1), StepByStep(bs, t0, t1)
    sizes = []

    class Sizes(mbd.Observer):
        def on_block(self, blk):
            sizes.append((blk.start.t, float(blk.log[-1, 0]), len(blk)))

    res = mbd.simulate(bs.model, bs.q0, bs.v0, block.t_end + 3e-4, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, observers=[block, single, Sizes()])
    assert res.engine == "compiled" and max(n for *_, n in sizes) > 100
    assert any(a < t0 < b for a, b, _ in sizes) and any(a < t1 < b for a, b, _ in sizes)
    a, b = summary_numbers(block.summary()), summary_numbers(single.summary())
    assert set(a) == set(b) and len(a) > 200
    inner = a.get("inner.pocket_impacts", 0) + a.get("outer.pocket_impacts", 0)
    assert inner > 0 and math.isfinite(a["inner.film_min_m"])              # impacts and film are exercised
    for k in a:
        if isinstance(a[k], bool) or not isinstance(a[k], (int, float)):
            assert a[k] == b[k], k
        elif isinstance(a[k], int):
            assert a[k] == b[k], k
        else:
            assert a[k] == pytest.approx(b[k], rel=1e-9, abs=1e-300), k


def test_the_summary_through_the_compiled_outputs_equals_the_one_through_the_numpy_kernels():
    """The faulty machine in reverse (pocket impacts, film, a spall, a cracked tooth, class-6 teeth): the statistics
    of one run taken through the contacts' compiled outputs (mbd.compiled.outputs, the default) and through the
    reference kernels (outputs="numpy") give the same summary, every number to 1e-9 and every count and flag
    exactly; the window starts and ends inside blocks. (numpy's SIMD arctan2 and the C library's differ by an ulp
    in a few percent of calls: the pocket forces move by up to ~3e-12 of themselves, tests/mbd/test_compiled_outputs.py.)"""
    from mbd.compiled.outputs import CompiledOutputs

    bs = build(faulty_machine("reverse"))
    t0, t1 = 4e-3, 6e-3
    fast, ref = WindowStatistics(bs, t0, t1), WindowStatistics(bs, t0, t1, outputs="numpy")
    res = mbd.simulate(bs.model, bs.q0, bs.v0, fast.t_end + 3e-4, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, observers=[fast, ref])
    assert res.engine == "compiled"
    assert isinstance(fast._outputs, CompiledOutputs) and isinstance(ref._outputs, mbd.System)
    a, b = summary_numbers(fast.summary()), summary_numbers(ref.summary())
    assert set(a) == set(b) and len(a) > 200
    assert a["inner.pocket_impacts"] + a["outer.pocket_impacts"] > 0 and math.isfinite(a["inner.film_min_m"])
    for k in a:
        if isinstance(a[k], (bool, int)) or not isinstance(a[k], float):
            assert a[k] == b[k], k
        else:
            assert a[k] == pytest.approx(b[k], rel=1e-9, abs=1e-300), k
    with pytest.raises(mbd.ModelError, match=r"^outputs must be one of \('auto', 'compiled', 'numpy'\), got 'gpu'$"):
        WindowStatistics(bs, t0, t1, outputs="gpu")


def test_a_block_is_recorded_as_its_steps_are(tmp_path):
    """The recorder takes a compiled block at once (the element outputs of all its samples in one call): the
    results file equals the one recorded step by step from the same blocks (every variable to 1e-12, the
    same sample times), for the study's probes (bodies in both frames, element outputs with films, the
    bearing-load and cage-slip series, the housing loads) and samples falling anywhere in the steps."""
    import xarray as xr
    from scenarios.core.runner import _probes

    bs = build(faulty_machine())
    blocks = []

    class Keep(mbd.Observer):
        def on_block(self, blk):
            blocks.append(dataclasses.replace(blk, log=blk.log.copy()))

    res = mbd.simulate(bs.model, bs.q0, bs.v0, 2.5e-3, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, observers=[Keep()])
    system, start = mbd.System(bs.model), blocks[0].start
    files = []
    for how in ("block", "step"):
        rec = mbd.Recorder(tmp_path / f"{how}.nc", dt=1.0 / 37000.0, probes=_probes(bs, sensor=True), t_start=1e-3)
        rec.bind(bs.model, system, start)
        rec.reset()
        rec.record(start, None, first=True)
        for blk in blocks:
            if how == "block":
                rec.record_block(blk)
            else:
                for s0, s1, _, _ in blk.steps:
                    rec.record(s0, s1)
        files.append(rec.finalize())
    a, b = (xr.open_dataset(f) for f in files)
    assert res.engine == "compiled" and a.sizes["time"] == b.sizes["time"] > 50
    np.testing.assert_array_equal(a["time"].values, b["time"].values)
    assert set(a.data_vars) == set(b.data_vars) and len(a.data_vars) > 20
    for name in a.data_vars:
        x = a[name].values
        np.testing.assert_allclose(x, b[name].values, rtol=1e-12, atol=OUTPUT_ROUND_OFF * np.nanmax(np.abs(x), initial=0.0),
                                   err_msg=name)


def test_the_accumulators_compile_when_the_statistics_are_bound_and_say_so_when_cold(capsys, monkeypatch):
    """Binding the statistics (before a run's first step and its progress bar) compiles or loads the accumulators:
    silent when numba's cache holds them, one line before and one with the time after when it must compile (faked
    cold: the cache answers, so the test stays fast), as the engine's and the output kernels do."""
    import mbd.compiled as mc
    from components.statistics.accumulate import accumulate_steps, accumulators_cached

    bs = build(reference_dpgt(3, "forward"))
    system = mbd.System(bs.model)
    bind = lambda: WindowStatistics(bs, 0.0, 1.0, outputs="numpy").bind(bs.model, system, None)
    bind()
    assert accumulate_steps.signatures and accumulators_cached()      # compiled (or loaded) at bind, before a step
    capsys.readouterr()
    bind()
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(mc, "kernels_cached", lambda function="stepper.advance": False)
    bind()
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and err[0].startswith("mbd: compiling the statistics' accumulator kernels (") \
        and err[1].startswith("mbd: accumulator kernels compiled in ")
