"""The sliced roller–race contact's outputs from its compiled kernel (mbd.compiled.sliced.outputs_sliced_race, what the
window statistics read on the compiled path) against the reference's, SlicedRaceContact.kernel: every output of the
family (the planar race's, the tilt, the slopes, the load centroid, the slice loads and what the statistics take of
them), at random loaded states with tilts, slopes, profile drops, row offsets and damping, for both raceways, every
traction law and exponents on both of the kernel's power paths (the root iteration: 10/9, 1.5; np.power: 1.3).
Contacts with every slice closed, with an edge load and open ones (skipped by the bound) are in each family."""
from __future__ import annotations

import numpy as np
import pytest

from mbd.compiled.registry import OUTPUT_NAMES, kind_of, output_names
from mbd.compiled.sliced import outputs_sliced_race
from mbd.element import evaluate

from tests.mbd.test_compiled_sliced import N, TRACTIONS, _family, _state
from tests.support.contact import FS

RTOL = 1e-12       # the slices' power within 1.5 ulp, sums in the reference's order: seen below 1e-14


def _outputs(elem, qf, vf, t=0.25):
    """{name: (n,)} of the compiled kernel; O starts NaN so that every row must be written."""
    P, G = kind_of(type(elem)).pack(elem)
    ql, vl = np.ascontiguousarray(qf[elem.dofs]), np.ascontiguousarray(vf[elem.dofs])
    names = output_names(elem)
    O = np.full((len(names), elem.n), np.nan)
    outputs_sliced_race(t, FS.phi, FS.omega, FS.domega, ql, vl, np.zeros((elem.n, 0)), P, G, O)
    return dict(zip(names, O))


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", sorted(TRACTIONS))
@pytest.mark.parametrize("n_s, exponent", [(1, 10.0 / 9.0), (5, 1.5), (21, 10.0 / 9.0), (21, 1.3)])
@pytest.mark.parametrize("seed", [1, 2])
def test_sliced_race_outputs_equal_the_reference(kind, law, n_s, exponent, seed):
    rng = np.random.default_rng(seed)
    press = [6e-6, 1e-6, -30e-6, 4e-6, 0.5e-6, 2e-6]          # loaded, loaded, open (skipped), ...
    tilt = np.array([0.0, 8e-4, 0.0, -3e-4, 2e-4, 0.0]) + rng.uniform(-1e-4, 1e-4, N)
    pin_slope = rng.uniform(-3e-4, 3e-4, 2)
    drop = rng.uniform(0.0, 1e-6, (N, n_s))
    elem = _family(kind, n_s, TRACTIONS[law], zeta=0.05, drop=drop, row=3e-3 if seed == 2 else 0.0,
                   pin_slope=pin_slope, exponent=exponent)
    qf, vf = _state(kind, rng, press, tilt, rng.uniform(-5e-4, 5e-4, 2))
    _, ref, _, _ = evaluate(elem, 0.25, FS, qf, vf, None, False)
    got = _outputs(elem, qf, vf)
    assert set(ref) - set(got) == {"angle"} and set(got) <= set(ref)
    assert set(got) == set(OUTPUT_NAMES["sliced.sliced_race"]) | {f"slice_load_{k}" for k in range(n_s)}
    loads = elem.slice_loads(qf, vf)
    assert np.all(loads[2] == 0.0) and np.all(loads[0] > 0.0)                      # an open and a loaded contact
    if n_s > 1:
        assert np.any(loads[1] == 0.0) and np.any(loads[1] > 0.0)                   # an edge load
    for key, val in got.items():
        want = np.asarray(ref[key], float)
        assert np.all(np.isfinite(val)), key
        np.testing.assert_allclose(val, want, rtol=RTOL, atol=RTOL * np.abs(want).max(initial=0.0), err_msg=key)
    # what the statistics read of the slice loads, from the slice loads themselves
    np.testing.assert_array_equal(got["loaded_slices"], (loads > 0.0).sum(axis=1))
    np.testing.assert_allclose(got["load"], loads.sum(axis=1), rtol=1e-13)
    np.testing.assert_allclose(got["max_slice_load"], loads.max(axis=1), rtol=1e-13)
