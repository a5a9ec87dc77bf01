"""The sliced machine with real gears runs on the compiled path and equals the numpy path (scenarios.bench_sliced_teeth,
docs/model.md §6.6). Truth: the numpy engine path (the reference kernels, dual-number Jacobians). The machine: the
reference DPGT at condition 3 with the rig's typical errors for flank class 6 (every gear's teeth drawn: the
tooth-pair law on every face slice; every gear eccentric; the pinholes off), bearing.model = "sliced", every pin sloped
4' tangentially (the planets tilt: the face slices carry different loads), from a loaded state."""
from __future__ import annotations

import math

import pytest

from scenarios.numerics import bench_sliced_teeth as bench


@pytest.fixture(scope="module")
def paths():
    planar, sliced = bench.machines(3, 6, 4.0)
    state = bench.loaded_state(planar, sliced, 0.003)
    _, rc, sc = bench.run(sliced, state, 20, "compiled")
    _, rn, sn = bench.run(sliced, state, 20, "numpy")
    return sliced, rc, rn, sc, sn


def test_the_machine_has_face_sliced_meshes_with_teeth_and_runout(paths):
    sliced = paths[0]
    meshes = [e for e in sliced.model.elements if type(e).__name__ == "SlicedGearMesh"]
    assert len(meshes) == 3
    assert all(m.pairs is not None and m.has_offset for m in meshes)


def test_compiled_and_numpy_paths_take_the_same_steps_to_the_same_states(paths):
    """The same accepted steps and Newton iterations, and states apart by round-off carried over 20 steps."""
    _, rc, rn, sc, sn = paths
    out = bench.compare(rc, rn, sc, sn)
    assert out["engines"] == ["compiled", "numpy"]
    assert out["counters_equal"] and out["counters"]["accepted"] == 20
    assert out["max_dq"] < 1e-12                         # m, rad: positions ~0.1 m, rotations ~10 rad
    assert out["max_dv_over_max_v"] < 1e-10


def test_the_window_statistics_agree(paths):
    """Every summary number of the window (meshes, bearings, slices, misalignment) to 1e-8 of itself; the planets
    tilt (the misalignment the bearings see is the pin's slope less the planet's, of the order of 4')."""
    _, rc, rn, sc, sn = paths
    out = bench.compare(rc, rn, sc, sn)
    assert out["summary_numbers"] > 300 and not out["summary_keys_only_in_one"]
    assert out["summary_max_rel_diff"] < 1e-8, out["summary_worst_key"]
    assert out["summary_small_max_abs_diff"] <= 1e-12
    mis = bench.numbers(sn)["inner.misalignment_mean_rad"]
    assert 0.5 * math.radians(4.0 / 60) < mis < 1.01 * math.radians(4.0 / 60)
