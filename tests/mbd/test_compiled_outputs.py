"""The element outputs through the compiled kernels (mbd.compiled.outputs.CompiledOutputs: each output written by
the compiled force law where it computes that value for the residual) against the reference,
mbd.System.outputs_batch over the numpy kernels (the statistics taken through either give the same summary:
tests/components/test_block_statistics.py).

Round-off: numpy's SIMD arctan2 and the C library's (numba's) differ by an ulp in a few percent of calls
(tests/mbd/test_compiled_mesh.py). A pocket's penetration is the small difference of the roller's angle in the cage
and its clearance, times d_m/2, so that ulp moves a pocket force by up to ~3e-12 of the family's largest
(measured). The output comparison therefore runs the reference with the C library's arctan2 (as the mesh
kernel's own test does) and holds every output to the floor of the block-vs-state outputs test
(tests.support.dpgt_runs.OUTPUT_ROUND_OFF: 1e-12 of the family's largest value, and 1e-12 relative).
"""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from components.params import with_overrides
from components.presets import reference_dpgt
from mbd.compiled.outputs import CompiledOutputs
from mbd.compiled.registry import output_names

from tests.support.dpgt_runs import OUTPUT_ROUND_OFF, build, faulty_machine
from tests.support.mesh import libm_arctan2

# what the compiled kernels leave out of the reference's outputs (not by-products of the force law)
LEFT_OUT = {"RaceContact": {"angle"}, "SlicedRaceContact": {"angle"}}
# an output whose value cancels by symmetry has its round-off floor from the size of its terms, not of itself: the
# sliced race's load centroid Σ z_k q_k / Q of a roller without tilt (its z_k up to the half length) [m]
TERM_SCALE = {("SlicedRaceContact", "centroid"): lambda e: float(np.abs(e.z).max())}


def _block_states(bs, t_end=3e-3, start=2e-3):
    """(t, q, v, a, z) of the compiled run's accepted steps after ``start`` (one block's arrays, up to 256 states)."""
    blocks = []

    class Keep(mbd.Observer):
        def on_block(self, blk):
            if float(blk.log[-1, 0]) > start:
                blocks.append(blk)

    res = mbd.simulate(bs.model, bs.q0, bs.v0, t_end, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, observers=[Keep()])
    assert res.engine == "compiled"
    t, q, v, a, z = blocks[-1].arrays()
    return t, q, v, z


def _compare(bs):
    """Every output the compiled kernels give at a block of states equals the reference's (C library's arctan2) to
    the round-off floor; the other families come from the numpy kernels unchanged. Returns (families compiled,
    number of outputs compared)."""
    t, q, v, z = _block_states(bs)
    system = mbd.System(bs.model)
    co = CompiledOutputs(system)
    got = co.outputs_batch(t, q, v, z)
    plain = system.outputs_batch(t, q, v, z)
    with libm_arctan2():
        ref = system.outputs_batch(t, q, v, z)
    assert set(got) == set(ref) == {e.name for e in bs.model.elements}
    n = 0
    for e in bs.model.elements:
        fam = e.name
        if co.engines[fam] == "numpy":       # the reference kernels themselves
            assert set(got[fam]) == set(plain[fam]), fam
            for key, val in got[fam].items():
                np.testing.assert_array_equal(val, plain[fam][key], err_msg=f"{fam}.{key}")
            continue
        assert set(ref[fam]) - set(got[fam]) == LEFT_OUT.get(type(e).__name__, set()), fam
        assert tuple(got[fam]) == output_names(e), fam
        for key, val in got[fam].items():
            want = np.broadcast_to(ref[fam][key], val.shape)
            assert val.shape == (t.size, e.n), (fam, key)
            scale = max(np.max(np.abs(want), initial=0.0), TERM_SCALE.get((type(e).__name__, key), lambda e: 0.0)(e))
            np.testing.assert_allclose(val, want, rtol=1e-12, atol=OUTPUT_ROUND_OFF * scale, err_msg=f"{fam}.{key}")
            n += 1
    return {f for f, how in co.engines.items() if how == "compiled"}, n


@pytest.mark.parametrize("frame", ["rotating", "fixed"])
def test_compiled_outputs_equal_the_reference_on_a_faulty_machine(frame):
    """Class-6 teeth (the tooth-pair mesh law with runouts), a spall on a pin and a cracked tooth, in the load ramp
    where pockets take impacts (stored approach speeds), in both frames: every output the compiled kernels give
    (roller–race, pocket, guide) equals the reference's at 200+ states, the other families' are the numpy kernels'."""
    bs = build(faulty_machine("reverse"), frame=frame)
    compiled, n = _compare(bs)
    assert compiled == {"race_inner", "race_outer", "pocket", "guide"}
    assert n == 2 * 7 + 5 + 8                     # every output of the race, pocket and guide kernels


@pytest.mark.parametrize("overrides, options", [
    ({"bearing.rows": 2, "bearing.cage.land_law": "hydrodynamic"}, {}),     # fx, fy per physical roller; the film
    ({"bearing.traction_law": "tanh"}, {}),
    ({"bearing.traction_law": "slide_roll"}, {"cage": "none"}),
    ({}, {"bearings": "linear"}),                                             # no compiled family
    ({"bearing.cage.guidance": "rollers"}, {}),                               # the pockets' retention, no land
    ({"bearing.model": "sliced"}, {}),                                        # the sliced races, face-sliced meshes
], ids=["double_row_oil_land", "tanh", "slide_roll_no_cage", "linear_bearings", "roller_centred_cage", "sliced"])
def test_compiled_outputs_equal_the_reference_for_each_law_variant(overrides, options):
    """The law variants the kernels branch on: both rows of a double-row bearing (the outputs are per physical
    roller, the forces times two), the hydrodynamic cage land (its shear in the friction), the tanh and
    slide-to-roll traction laws, no cage, linear bearings (every output from the numpy kernels), a roller-centred
    cage (the pockets' radial retention instead of the land) and the sliced bearing (its races' slice loads, tilts and
    slopes: tests/mbd/test_compiled_sliced.py holds them at random tilted states)."""
    bs = build(with_overrides(reference_dpgt(3, "forward"), overrides), **options)
    compiled, n = _compare(bs)
    centring = "pocket_retention" if overrides.get("bearing.cage.guidance") == "rollers" else "guide"
    want = {"race_inner", "race_outer"} | ({"pocket", centring} if options.get("cage") != "none" else set())
    assert compiled == (set() if options.get("bearings") == "linear" else want)
    assert n >= (0 if options.get("bearings") == "linear" else 10)


def test_the_outputs_engine_is_checked_and_a_compile_is_announced(capsys, monkeypatch):
    """An unknown engine is refused in one line naming the argument; building the compiled outputs when numba's
    cache does not hold them says so before it compiles, and gives the time (faked cold: the cache answers)."""
    import mbd.compiled as mc

    bs = build(reference_dpgt(3, "forward"))
    with pytest.raises(mbd.ModelError, match=r"^output_evaluator: engine must be one of"):
        mbd.output_evaluator(mbd.System(bs.model), "gpu")
    system = mbd.System(bs.model)
    assert mbd.output_evaluator(system, "numpy") is system
    CompiledOutputs(system)                  # compiled (and cached) here if this is the first time
    capsys.readouterr()
    CompiledOutputs(system)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(mc, "kernels_cached", lambda function="stepper.advance", groups=None: False)
    CompiledOutputs(system)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("mbd: compiling the element output kernels") and err[1].startswith(
        "mbd: output kernels compiled in ")
