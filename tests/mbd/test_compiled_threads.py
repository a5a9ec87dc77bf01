"""The compiled engine on threads (mbd.compiled.system, ``threads`` > 1): the families of
registry.THREADED_KINDS — the race, pocket, guide and drag contacts of every bearing, the sliced race contacts — run
in chunks of instances on the threads, and everything they give equals the serial assembly's to the bit (a kernel's
instances are independent, the scatter keeps the family order): forces and Jacobians at a loaded DPGT state, planar
and sliced, both against each other and against the numpy reference to round-off; the same steps, counters and states
over a run; a thread count outside 1 to the usable cores refused in one line."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import mbd
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from mbd.compiled.registry import GROUPS, KIND_IDS, THREADED, THREADED_KINDS, groups_to_compile
from mbd.compiled.system import CompiledSystem, check_threads, usable_cores

from tests.support.dpgt_runs import ramp_state

two_cores = pytest.mark.skipif(usable_cores() < 2, reason="threads need two usable cores")
H = 5e-6


@pytest.fixture(scope="module")
def planar():
    """The DPGT 3 ms into its load ramp (every contact family active, many contacts loaded, many open)."""
    sc, s = ramp_state(0.003, "compiled")
    return sc.model, s


@pytest.fixture(scope="module")
def sliced(planar):
    """The sliced machine (21 slices a roller) at the planar state with every slope and tilt zero (the straight
    profile's exact planar reduction)."""
    _, s = planar
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(with_overrides(reference_dpgt(3, "forward"),
                                       {"bearing.model": "sliced", "bearing.slicing.slices": 21}))
    ext = lambda x: np.concatenate([x, np.zeros(sc.model.ndof - x.size)])       # noqa: E731
    return sc.model, mbd.State(s.t, ext(s.q), ext(s.v), ext(s.a), ext(s.f), dict(s.z))


def _threaded_twins(cs: CompiledSystem) -> set:
    names = {v: k for k, v in KIND_IDS.items()}
    return {names[int(cs.fams[int(r)][0])] for r in cs.sysd[13][0]}


@two_cores
@pytest.mark.parametrize("machine", ["planar", "sliced"])
def test_on_two_threads_the_assembly_is_bit_identical_and_equals_the_reference(machine, request):
    model, s = request.getfixturevalue(machine)
    system = mbd.System(model)
    one, two = CompiledSystem(system, 1), CompiledSystem(system, 2)
    assert one.groups & THREADED == 0 and two.groups & THREADED
    expected = {"contact.pocket", "contact.guide", "contact.drag"} | (
        {"sliced.sliced_race"} if machine == "sliced" else {"contact.race"})
    assert _threaded_twins(two) == expected             # the families under test are the ones on the threads
    ref = system.evaluate(s.t, s.q, s.v, s.z, jac=True)
    for jac in (True, False):
        a = one.evaluate(s.t, s.q, s.v, s.z, jac=jac)
        b = two.evaluate(s.t, s.q, s.v, s.z, jac=jac)
        for name in ("F", "Jq", "Jv") if jac else ("F",):
            x, y, r = getattr(a, name), getattr(b, name), getattr(ref, name)
            assert np.array_equal(x, y), (machine, jac, name, np.abs(x - y).max())
            assert np.abs(y - r).max() <= 1e-10 * np.abs(r).max(), (machine, jac, name)
    assert np.count_nonzero(ref.Jq) > 1000


@two_cores
def test_on_two_threads_the_engine_takes_the_same_steps_to_the_same_states(planar):
    model, s = planar

    def run(threads):
        return mbd.simulate(model, t_end=s.t + 60 * H, state=s.copy(), stepper=mbd.PRODUCTION.stepper(),
                            controller=mbd.FixedStep(H), progress=False, engine="compiled", threads=threads)

    one, two = run(1), run(2)
    assert one.counters == two.counters and one.counters["accepted"] >= 60 and one.counters["jacobian"] > 0
    for name in ("q", "v", "a", "f"):
        assert np.array_equal(getattr(one.state, name), getattr(two.state, name)), name
    for k in one.state.z:
        assert np.array_equal(one.state.z[k], two.state.z[k]), k


def test_a_thread_count_outside_one_to_the_cores_is_refused_in_one_line(planar):
    model, s = planar
    cores = usable_cores()
    assert check_threads(1) == 1 and check_threads(np.int64(cores)) == cores
    for bad in (0, -1, cores + 1, 1.5, "2", True, None):
        with pytest.raises(mbd.ModelError) as err:
            check_threads(bad)
        msg = str(err.value)
        assert "\n" not in msg and msg.startswith("threads must be an integer from 1 to the ")
        assert f"{cores} usable cores" in msg and repr(bad) in msg
    kw = dict(t_end=s.t + H, state=s.copy(), controller=mbd.FixedStep(H), progress=False)
    with pytest.raises(mbd.ModelError, match="threads must be an integer"):
        mbd.simulate(model, engine="compiled", threads=cores + 1, **kw)
    with pytest.raises(mbd.ModelError, match="threads must be 1 on the numpy engine"):
        mbd.simulate(model, engine="numpy", threads=2, **kw)


def test_a_serial_run_never_loads_the_threaded_assembly_nor_a_threaded_run_the_serial():
    """registry.groups_to_compile: a cached superset of the kernel groups is loaded only with the same THREADED flag."""
    c, g, m = GROUPS["contact"], GROUPS["generic"], GROUPS["mesh"]
    assert THREADED not in GROUPS.values() and all(THREADED & b == 0 for b in GROUPS.values())
    assert groups_to_compile(c | g, {c | g | m | THREADED}) == c | g
    assert groups_to_compile(c | g, {c | g | m | THREADED, c | g | m}) == c | g | m
    assert groups_to_compile(c | g | THREADED, {c | g | m}) == c | g | THREADED
    assert groups_to_compile(c | g | THREADED, {c | g | m | THREADED, c | g | m}) == c | g | m | THREADED


def test_every_threaded_family_is_a_registered_twin():
    """Every twin run on the threads is a registered one (a typo would leave a family serial without a word)."""
    assert set(THREADED_KINDS) <= set(KIND_IDS) and len(set(THREADED_KINDS)) == len(THREADED_KINDS)
