"""The compiled engine path (mbd.compiled) against the numpy reference path: the same forces and
Jacobians, the same steps (counters) and states, and a fallback that says why.

From a DPGT state the roller spins of the unloaded zone are chaotic (pocket impacts with friction):
two runs whose only difference is round-off — numpy against numpy with the start velocities changed by
1e-15 relative — agree to 1e-11 m for ~150 steps of 5 µs and then drift apart, to 1e-2 rad/s of roller
spin after 300 steps. So the engines are held together over 150 steps exactly (counters) and to
1e-8 (states), and over 400 steps no further apart than round-off alone drives the reference.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import mbd
from components.planetary import build_single_planetary

from tests.support.dpgt_runs import ramp_state
from mbd.compiled.system import CompiledSystem

H = 5e-6


@pytest.fixture(scope="module")
def dpgt_state():
    """The DPGT 3 ms into its load ramp (every contact family active), by the compiled engine."""
    sc, s = ramp_state(0.003, "compiled")
    return sc.model, s


def _run(model, state, n, engine, observers=(), stepper=None):
    return mbd.simulate(model, t_end=state.t + n * H, state=state.copy(), stepper=stepper or mbd.PRODUCTION.stepper(),
                        controller=mbd.FixedStep(H), progress=False, engine=engine, observers=list(observers))


def test_compiled_assembly_equals_the_reference(dpgt_state):
    model, s = dpgt_state
    system = mbd.System(model)
    ref = system.evaluate(s.t, s.q, s.v, s.z, jac=True)
    got = CompiledSystem(system).evaluate(s.t, s.q, s.v, s.z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
    assert np.count_nonzero(ref.Jq) > 1000               # contacts, meshes and pockets are in the picture


@pytest.mark.parametrize("per_component", [True, False], ids=["per-component test", "max-norm test"])
def test_the_engines_take_the_same_steps_to_the_same_states(dpgt_state, per_component):
    """Both Newton convergence tests (the production one and the former max-norm one) are compiled."""
    model, s = dpgt_state
    st = dataclasses.replace(mbd.PRODUCTION.stepper(), per_component=per_component)
    c, r = _run(model, s, 150, "compiled", stepper=st), _run(model, s, 150, "numpy", stepper=st)
    assert (c.engine, r.engine) == ("compiled", "numpy")
    assert c.counters == r.counters and c.counters["rejected"] + c.counters["accepted"] >= 150
    np.testing.assert_allclose(c.state.q, r.state.q, rtol=0, atol=1e-8)
    np.testing.assert_allclose(c.state.v, r.state.v, rtol=0, atol=1e-8 / H)
    for k in r.state.z:
        np.testing.assert_allclose(c.state.z[k], r.state.z[k], rtol=0, atol=1e-6)


def test_the_engines_take_the_same_steps_with_the_race_damping_ramped(dpgt_state):
    """Every roller–raceway contact's damping over a 0.3 µm ramp (docs/model.md §8.1): the same steps and states on
    both engines, and not those of the law without it (the ramp is in the picture)."""
    import copy

    model, s = dpgt_state
    ramped = copy.deepcopy(model)
    races = [e for e in ramped.elements if type(e).__name__ == "RaceContact"]
    assert races
    for e in races:
        e.damping_ramp, e._ramped = np.full(e.n, 0.3e-6), True
    c, r = _run(ramped, s, 150, "compiled"), _run(ramped, s, 150, "numpy")
    assert c.counters == r.counters and c.counters["rejected"] + c.counters["accepted"] >= 150
    np.testing.assert_allclose(c.state.q, r.state.q, rtol=0, atol=1e-8)
    np.testing.assert_allclose(c.state.v, r.state.v, rtol=0, atol=1e-8 / H)
    plain = _run(model, s, 150, "compiled")
    assert not np.array_equal(plain.state.v, c.state.v)


@pytest.mark.parametrize("law", ["squeeze", "full"])
def test_the_engines_take_the_same_steps_with_the_raceway_film(dpgt_state, law):
    """The raceway film on every roller (docs/model.md §8.9; the same bodies and state, two more stateless
    families), the squeeze alone and the full law: the same steps and states on both engines, and not those of the
    machine without it."""
    import warnings

    from components.dpgt import build_dpgt
    from components.params import with_overrides
    from components.presets import reference_dpgt

    model, s = dpgt_state
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        filmed = build_dpgt(with_overrides(reference_dpgt(3, "forward"), {"bearing.race_film": law})).model
    assert sum(type(e).__name__ == "RaceFilm" for e in filmed.elements) == 2
    out = mbd.System(filmed).outputs(s.t, s.q, s.v, s.z, families=["race_film_inner", "race_film_outer"])
    assert np.count_nonzero(out["race_film_outer"]["force"]) > 0          # some rollers approach an open gap
    c, r = _run(filmed, s, 150, "compiled"), _run(filmed, s, 150, "numpy")
    assert (c.engine, r.engine) == ("compiled", "numpy")
    assert c.counters == r.counters and c.counters["rejected"] + c.counters["accepted"] >= 150
    np.testing.assert_allclose(c.state.q, r.state.q, rtol=0, atol=1e-8)
    np.testing.assert_allclose(c.state.v, r.state.v, rtol=0, atol=1e-8 / H)
    plain = _run(model, s, 150, "compiled")
    assert not np.array_equal(plain.state.v, c.state.v)


class _Log(mbd.Observer):
    def bind(self, *a):
        self.q = []

    def step(self, s0, s1):
        self.q.append(s1.q.copy())


def test_over_longer_runs_the_engines_differ_only_as_round_off_drives_the_reference(dpgt_state):
    model, s = dpgt_state
    logs = {k: _Log() for k in ("compiled", "numpy", "perturbed")}
    _run(model, s, 400, "compiled", [logs["compiled"]])
    _run(model, s, 400, "numpy", [logs["numpy"]])
    p = s.copy()
    p.v[:] = s.v * (1 + 1e-15 * np.random.default_rng(0).standard_normal(s.v.size))
    _run(model, p, 400, "numpy", [logs["perturbed"]])
    n = min(len(x.q) for x in logs.values())
    gap = lambda a, b: np.array([np.abs(a.q[i] - b.q[i]).max() for i in range(n)])
    engines, noise = gap(logs["compiled"], logs["numpy"]), gap(logs["perturbed"], logs["numpy"])
    # within a decade of what 1e-15 of round-off does to the reference, at every step (floor: 1e-12 m)
    assert np.all(engines <= 10 * np.maximum.accumulate(noise) + 1e-12)


def test_a_planetary_scene_runs_identically_on_both_engines():
    built = build_single_planetary()
    v0 = built.v0.copy()
    v0[2] = 30.0
    kw = dict(stepper=mbd.PRODUCTION.stepper(), controller=mbd.Adaptive(h0=1e-4, h_max=1e-4, h_min=1e-12),
              progress=False)
    c = mbd.simulate(built.model, built.q0, v0, 0.004, engine="compiled", **kw)
    r = mbd.simulate(built.model, built.q0, v0, 0.004, engine="numpy", **kw)
    assert c.counters == r.counters and c.counters["rejected"] > 0   # rejections and step changes included
    tol = mbd.PRODUCTION.stepper().tol.scale(built.model, None, None)   # the local error the controller holds
    assert np.all(np.abs(c.state.q - r.state.q) <= 0.05 * tol)       # Newton-tolerance round-off, 905 steps


def test_what_cannot_be_compiled_falls_back_or_says_why(capsys):
    """"auto" falls back to the numpy path and says so in one line on stderr, with the reason, which the result
    (and so summary.json) keeps; "compiled" refuses; a compiled run has no note."""
    mb = mbd.ModelBuilder()
    mb.add_body("wheel", 1.0, 0.01)
    mb.add(mbd.elements.TorqueSource("motor", [0], torque=lambda t: np.array([np.sin(t)])))
    model = mb.build()
    kw = dict(stepper=mbd.PRODUCTION.stepper(), controller=mbd.FixedStep(1e-3), progress=False)
    res = mbd.simulate(model, np.zeros(3), np.zeros(3), 0.01, engine="auto", **kw)
    assert res.engine == "numpy" and "motor" in res.engine_note and res.summary()["engine_note"] == res.engine_note
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("mbd: running the numpy engine path") and "motor" in err[0]
    mb2 = mbd.ModelBuilder()
    mb2.add_body("wheel", 1.0, 0.01)
    mb2.add(mbd.elements.TorqueSource("motor", [0], torque=1.0))
    ok = mbd.simulate(mb2.build(), np.zeros(3), np.zeros(3), 0.01, engine="auto", **kw)
    assert ok.engine == "compiled" and ok.engine_note is None
    with pytest.raises(mbd.ModelError, match="compiled engine cannot run.*motor.*callable"):
        mbd.simulate(model, np.zeros(3), np.zeros(3), 0.01, engine="compiled", **kw)
    with pytest.raises(mbd.ModelError, match="engine must be one of"):
        mbd.simulate(model, np.zeros(3), np.zeros(3), 0.01, engine="fast", **kw)


def test_a_family_without_a_compiled_twin_falls_back_and_says_so(capsys):
    """A family that declares no compiled twin (here a subclass: it does not inherit its parent's, since its law
    may differ) runs on the numpy path under "auto", announced in one line naming the family; "compiled" refuses."""
    class HandTorque(mbd.elements.TorqueSource):
        pass

    mb = mbd.ModelBuilder()
    mb.add_body("wheel", 1.0, 0.01)
    mb.add(HandTorque("hand", [0], torque=1.0))
    model = mb.build()
    kw = dict(stepper=mbd.PRODUCTION.stepper(), controller=mbd.FixedStep(1e-3), progress=False)
    res = mbd.simulate(model, np.zeros(3), np.zeros(3), 0.01, engine="auto", **kw)
    assert res.engine == "numpy" and "'hand' (HandTorque declares no compiled_twin)" in res.engine_note
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("mbd: running the numpy engine path") and "HandTorque" in err[0]
    assert res.state.v[2] == pytest.approx(1.0 * 0.01 / 0.01)       # ω = τ·t/J: the numpy path ran the inherited law
    with pytest.raises(mbd.ModelError, match="compiled engine cannot run.*HandTorque declares no compiled_twin"):
        mbd.simulate(model, np.zeros(3), np.zeros(3), 0.01, engine="compiled", **kw)


def test_a_module_s_cached_kernels_are_dropped_when_its_key_changes(tmp_path, monkeypatch):
    """numba caches a function against its own file only: the compiled package keeps each module's key beside the
    cache and drops the cached kernels of the modules whose key changed (a stale dispatch once kept an old race
    kernel); a cache without keys counts as changed throughout, files of other packages are left alone."""
    import importlib
    import json

    import mbd.compiled as mc
    from numba import config
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    stale = tmp_path / "registry.evaluate_kind-45.py311.nbi"
    stale.write_text("old")
    keep = tmp_path / "other_module.f-1.py311.nbi"
    keep.write_text("not ours")
    importlib.reload(mc)                       # no keys in tmp_path: every module counts as changed
    assert not stale.exists() and keep.exists()
    stamp = tmp_path / "compiled_sources.json"
    keys = json.loads(stamp.read_text())
    stale.write_text("fresh")                  # same sources: nothing is dropped
    importlib.reload(mc)
    assert stale.exists() and json.loads(stamp.read_text()) == keys
    kernel = tmp_path / "contact._race-398.py311.nbi"
    kernel.write_text("current")
    # the dispatch's key changed, not contact's (their sources, so the hash of all of them, too)
    stamp.write_text(json.dumps({**keys, "registry": "an older key", mc._ALL: "older sources"}))
    importlib.reload(mc)
    assert not stale.exists() and kernel.exists() and json.loads(stamp.read_text()) == keys


def test_unchanged_sources_are_not_parsed_again(tmp_path, monkeypatch):
    """The stamp's hash of every source together stands for the keys: with the sources unchanged, importing the
    compiled package parses none of them (the keys' import graph, ≈ 0.16 s in every process); with any change it
    does."""
    import ast
    import importlib
    import json

    import mbd.compiled as mc
    from numba import config
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    importlib.reload(mc)                       # writes the stamp
    stamp = tmp_path / "compiled_sources.json"
    keys = json.loads(stamp.read_text())
    assert keys == {**mc.source_keys(), mc._ALL: keys[mc._ALL]}

    class Parsed(Exception):
        pass

    def parse(*_a, **_k):
        raise Parsed

    monkeypatch.setattr(ast, "parse", parse)
    importlib.reload(mc)                       # the same sources: no parse
    stamp.write_text(json.dumps({**keys, mc._ALL: "older sources"}))
    with pytest.raises(Parsed):                # another hash: the keys are computed again
        importlib.reload(mc)
    monkeypatch.undo()
    importlib.reload(mc)


def _package_copy(tmp_path):
    """The compiled path's sources copied with their layout (mbd/compiled, mbd/rules.py, mbd/elements/ehl.py)."""
    import shutil

    import mbd.compiled as mc
    copies = []
    for src in mc._sources():
        rel = src.relative_to(src.parents[2] if src.parent.name in ("compiled", "elements") else src.parents[1])
        dst = tmp_path / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dst)
        copies.append(dst)
    return copies


def test_the_hash_of_all_sources_follows_every_byte_and_name_of_them(tmp_path):
    """The stamp's hash (mbd.compiled.sources_hash), which stands for the keys: the same for a copy of the sources
    elsewhere, another after an edit of one source's content (its name kept) or a rename; the keys move with it."""
    import mbd.compiled as mc
    copies = _package_copy(tmp_path)
    here = Path(mc.__file__).resolve().parent.parent
    before, keys = mc.sources_hash(copies, tmp_path / "mbd"), mc.source_keys(copies)
    assert before == mc.sources_hash(mc._sources(), here)
    target = next(p for p in copies if p.name == "contact.py")
    text = target.read_text()
    target.write_text(text.replace("return", "return ", 1))          # one byte more, the name kept
    assert mc.sources_hash(copies, tmp_path / "mbd") != before and mc.source_keys(copies) != keys
    target.write_text(text)
    assert mc.sources_hash(copies, tmp_path / "mbd") == before
    renamed = target.with_name("contact2.py")
    target.rename(renamed)
    assert mc.sources_hash([renamed if p == target else p for p in copies], tmp_path / "mbd") != before


@pytest.mark.parametrize("edited, stale", [
    ("mesh.py", {"mesh", "sliced", "registry", "system", "stepper", "outputs", "probe", "runner"}),
    ("stepper.py", {"stepper", "runner"}),
    ("ehl.py", {"ehl", "contact", "sliced", "registry", "system", "stepper", "outputs", "probe", "runner"}),
    ("sparse_lu.py", {"sparse_lu", "stepper", "probe", "runner"}),
], ids=["a kernel module", "the step loop", "the film law", "the sparse LU"])
def test_an_edit_makes_stale_the_module_and_those_compiled_from_it_only(tmp_path, edited, stale):
    """The keys (mbd.compiled.source_keys) follow the imports: an edit of a module changes its key and the keys of
    every module importing it, directly or through others (the sets written out from the package's imports), and no
    other; the cache of the family kernels outside that set survives an edit of the step loop."""
    import mbd.compiled as mc
    copies = _package_copy(tmp_path)
    before = mc.source_keys(copies)
    assert set(before) == {p.stem for p in copies}
    target = next(p for p in copies if p.name == edited)
    target.write_text(target.read_text() + "\n# an edit\n")
    assert mc.stale_modules(before, mc.source_keys(copies)) == stale
    assert mc.stale_modules(before, before) == set()


def test_the_cache_of_a_kernel_outside_the_package_is_read_from_its_own_index(tmp_path, monkeypatch):
    """kernels_cached(f) for a cached numba function of another package (the statistics' accumulators): false before
    its first call, true once numba has written its index, false again when its source is newer than the index (an
    edit: numba would compile it again)."""
    import importlib
    import os
    import sys

    import mbd.compiled as mc
    src = tmp_path / "probe_kernel.py"
    src.write_text("from numba import njit\n\n\n@njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "probe_kernel", raising=False)
    twice = importlib.import_module("probe_kernel").twice
    assert not mc.kernels_cached(twice)
    assert twice(1.5) == 3.0
    assert mc.kernels_cached(twice)
    later = os.stat(src).st_mtime + 10.0
    os.utime(src, (later, later))
    assert not mc.kernels_cached(twice)


def test_a_run_that_must_compile_says_so_before_its_first_step(capsys, monkeypatch):
    """When numba's cache does not hold the step loop, building the compiled runner says so in one line, compiles
    before any step (a progress bar's ETA then leaves it out) and gives the time; with the cache warm it is
    silent. (The compile is faked cold: the cache answers, so the test stays fast.)"""
    import mbd.compiled as mc
    from mbd.compiled.runner import CompiledRunner

    mb = mbd.ModelBuilder()
    mb.add_body("wheel", 1.0, 0.01)
    mb.add(mbd.elements.TorqueSource("motor", [0], torque=1.0))
    system = mbd.System(mb.build())
    args = (system, mbd.PRODUCTION.stepper(), mbd.FixedStep(1e-3))
    runner = CompiledRunner(*args)
    assert mc.kernels_cached(groups=runner.cs.groups) and runner.cs.groups in mc.cached_groups()
    capsys.readouterr()
    CompiledRunner(*args)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(mc, "kernels_cached", lambda function="stepper.advance", groups=None: False)
    CompiledRunner(*args)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("mbd: compiling the engine's kernels") and err[1].startswith("mbd: kernels compiled in ")


def test_a_system_runs_a_cached_set_of_family_groups_that_contains_its_own():
    """The groups to compile (registry.groups_to_compile): the system's own set when cached, else the smallest
    cached set containing it (loaded in a second), else its own (compiled)."""
    from mbd.compiled.registry import GROUPS, groups_to_compile

    c, g, m = GROUPS["contact"], GROUPS["generic"], GROUPS["mesh"]
    assert len({c, g, m}) == 3 and c | g | m == c + g + m             # one bit per kernel module
    assert groups_to_compile(c | g, {c | g, c | g | m}) == c | g
    assert groups_to_compile(c | g, {c | g | m, g, m | g}) == c | g | m
    assert groups_to_compile(g, {c | g | m, c | g, m | g}) in (c | g, m | g)
    assert groups_to_compile(g, {c | g | m, c | g}) == c | g
    assert groups_to_compile(c | g, {g, m | g}) == c | g              # no superset cached: its own
    assert groups_to_compile(c | g, set()) == c | g


def test_a_set_of_family_groups_compiles_only_those_groups_kernels():
    """The dispatch compiled for a set of groups holds the kernels of those groups and none of the others (the
    bearing rig never compiles the meshes): read from the compiled code of the internal-state update dispatch
    (its kernels are small), for the generic families alone and with the contacts."""
    from numba import njit

    from mbd.compiled.registry import GROUPS, update_for

    def symbols(groups):
        @njit
        def update(z, q, P, G):
            return update_for(groups, 0, z, 0.0, 1.0, 0.0, 0.0, q, q, q, q, P, G)
        z = np.zeros((1, 4))
        update(z, np.zeros((1, 6)), np.zeros((1, 10)), np.zeros(0))
        return update.inspect_llvm(update.signatures[0])

    generic_only = symbols(GROUPS["generic"])
    with_contacts = symbols(GROUPS["generic"] | GROUPS["contact"])
    assert "update_speed_drive" in generic_only and "update_speed_drive" in with_contacts
    assert "update_pocket" not in generic_only and "update_guide" not in generic_only
    assert "update_pocket" in with_contacts and "update_guide" in with_contacts


def test_one_compiled_assembly_serves_residuals_and_jacobians():
    """The step loop passes ``jac`` to the assembly as a run-time flag, not a literal True / False: numba compiles the
    assembly and every family kernel once, not twice (read from numba's cache index of the assembly after a compiled
    run: every entry types jac as a plain bool)."""
    from numba.core import types

    from mbd.compiled.runner import CompiledRunner
    from mbd.compiled.system import assemble

    built = build_single_planetary()
    CompiledRunner(mbd.System(built.model), mbd.PRODUCTION.stepper(), mbd.FixedStep(1e-4))
    entries = assemble._cache._cache_file._load_index()
    jacs = {key[0][6] for key in entries}
    assert jacs == {types.boolean}, jacs
