"""A roller-centred cage (bearing.cage.guidance = "rollers", docs/model.md §8.5–8.6): the scene builds no guide land
and the pockets' radial retention instead; by symmetry a centred cage among uniformly spaced rollers stays centred on
both engines, which agree to round-off."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from components.presets import reference_bearing, reference_dpgt
from components.rig import build_bearing_rig
from components.scene import SceneOptions
from components.units import ParameterError


def _rig(guidance, radial_load=0.0, **cage):
    b = reference_bearing()
    b = b.replace(cage=b.cage.replace(guidance=guidance, **cage))
    lub = reference_dpgt().lubricant
    return build_bearing_rig(b, radial_load=radial_load, outer_speed=300.0, lubricant=lub,
                             options=SceneOptions(cage="free", drag=True))


def test_the_scene_builds_only_what_centres_its_cage():
    names = {g: {e.name for e in _rig(g).model.elements} for g in ("outer_land", "rollers")}
    assert "guide" in names["outer_land"] and "pocket_retention" not in names["outer_land"]
    assert "pocket_retention" in names["rollers"] and "guide" not in names["rollers"]
    assert names["rollers"] - {"pocket_retention"} == names["outer_land"] - {"guide"}


def test_guidance_is_checked_with_its_name():
    b = reference_bearing()
    with pytest.raises(ParameterError, match="bearing.cage.guidance"):
        b.replace(cage=b.cage.replace(guidance="inner_land")).si()


def test_a_centred_cage_stays_centred_on_both_engines():
    """No load, the ring turning: every roller presses outwards on the bore (centrifugal) and, with a radial play
    of 2 µm, on its pocket's outer faces; the forces on the cage cancel and it stays at the pin centre (within
    1e-9 m after 1 ms), the two engines alike to round-off."""
    built = _rig("rollers", pocket_radial_clearance="2 um")
    m = built.model
    kw = dict(stepper=mbd.PRODUCTION.stepper(), controller=mbd.FixedStep(2e-6), progress=False)
    c = mbd.simulate(m, built.q0, built.v0, 0.001, engine="compiled", **kw)
    r = mbd.simulate(m, built.q0, built.v0, 0.001, engine="numpy", **kw)
    assert c.engine == "compiled" and r.engine == "numpy"
    i = 3 * m.body("pb.cage").index
    for res in (c, r):
        q = m.full(res.state.t, res.state.q, res.state.v)[0]
        assert np.hypot(q[i], q[i + 1]) <= 1e-9
    out = mbd.System(m).outputs(c.state.t, c.state.q, c.state.v, c.state.z)["pocket_retention"]
    assert np.all(out["force"] > 0)                 # every pocket holds its roller
    np.testing.assert_allclose(out["force"], out["force"].mean(), rtol=1e-6)
    tol = mbd.PRODUCTION.stepper().tol.scale(m, None, None)
    assert np.all(np.abs(c.state.q - r.state.q) <= 1e-6 * tol)
    np.testing.assert_allclose(c.state.v, r.state.v, rtol=0, atol=1e-10 * np.abs(r.state.v).max())
