"""Tooth deviations of the machine (components.teeth, components.tolerances): ISO 1328-1:2013 tolerances,
the class draws, the parameters' validation, and the conversion from TOML entries to the mesh law checked
against kinematics (every tooth turned by an arc p on the reference circle is the gear turned by p/r)."""
from __future__ import annotations

import math

import numpy as np
import pytest

import mbd
from components.dpgt import build_dpgt
from components.families import MESH_FAMILY
from components.params import with_overrides
from components.presets import reference_dpgt, typical_errors
from components.teeth import gear_table, mesh_pairs
from components.tolerances import _process, draw_teeth, flank_tolerances, pass_rate, radial_runout
from components.scene import SceneOptions
from components.units import ParameterError


# ----------------------------------------------------------------------------------------------------
# ISO 1328-1:2013
# ----------------------------------------------------------------------------------------------------
def test_flank_tolerances_by_hand():
    """Class 5, m = 2 mm, d = 100 mm, from the standard's Formulas (5)–(9) by hand: f_pT = 0.1 + 0.8 + 5 = 5.9,
    F_pT = 0.2 + 5.5 + 1.4 + 12 = 19.1, f_HαT = 0.8 + 0.1 + 4 = 4.9, f_fαT = 1.1 + 5 = 6.1 µm, F_αT = √(4.9² + 6.1²);
    each class step is √2 (class 7 = 2 × class 5)."""
    t = flank_tolerances(2e-3, 0.1, 5)
    for got, want in ((t.single_pitch, 5.9), (t.total_pitch, 19.1), (t.profile_slope, 4.9), (t.profile_form, 6.1),
                      (t.profile_total, math.hypot(4.9, 6.1))):
        assert got == pytest.approx(want * 1e-6, rel=1e-12)
    t7 = flank_tolerances(2e-3, 0.1, 7)
    assert t7.single_pitch == pytest.approx(2 * t.single_pitch, rel=1e-12)
    assert t7.profile_form == pytest.approx(2 * t.profile_form, rel=1e-12)
    # the rig's planets (m = 3, d = 72 mm) at class 6: f_pT = (0.072 + 1.2 + 5)·√2 = 8.87 µm
    assert flank_tolerances(3e-3, 0.072, 6).single_pitch == pytest.approx(6.272 * math.sqrt(2) * 1e-6, rel=1e-12)
    for bad in (0, 12, 6.0):
        with pytest.raises(ParameterError, match="1..11"):
            flank_tolerances(3e-3, 0.072, bad)


def test_radial_runout_by_hand():
    """The runout tolerance of the 2013 classes: F_rT = 0.9 F_pT (m = 2, d = 100, class 5: F_pT = 19.1 µm by hand)."""
    assert radial_runout(2e-3, 0.1, 5) == pytest.approx(0.9 * 19.1e-6, rel=1e-12)
    assert radial_runout(2e-3, 0.1, 7) == pytest.approx(2 * 0.9 * 19.1e-6, rel=1e-12)


def test_the_process_has_the_stated_distribution():
    """Before inspection (the process): single pitch deviations (neighbour differences of the positions) with
    σ = f_pT/3; profile slope and form with σ = T/3 per tooth, ``systematic`` of their variance common to a gear's
    flank: across many gears the variance of each gear's mean is ≈ share·σ² and the within-gear variance
    ≈ (1 − share)·σ²."""
    tol = flank_tolerances(3e-3, 0.072, 6)
    share, z = 0.5, 24
    rng = np.random.default_rng(4)
    draws = [_process(rng, z, tol, share) for i in range(600)]
    fpt = np.concatenate([np.diff(np.r_[d["pitch"], d["pitch"][:1]], axis=0).ravel() for d in draws])
    assert np.std(fpt) == pytest.approx(tol.single_pitch / 3, rel=0.03)
    for key, T in (("slope", tol.profile_slope), ("form", tol.profile_form)):
        x = np.array([d[key] for d in draws])                  # (gears, z, 2)
        sigma2 = (T / 3) ** 2
        assert np.var(x) == pytest.approx(sigma2, rel=0.05)
        assert np.var(x.mean(axis=1)) == pytest.approx(share * sigma2 + (1 - share) * sigma2 / z, rel=0.12)
        assert np.mean(np.var(x, axis=1, ddof=1)) == pytest.approx((1 - share) * sigma2, rel=0.05)


def test_the_pass_rate_of_inspection_by_hand():
    """With nothing systematic every checked deviation is an independent normal at T/3, which stays within T with
    P3 = erf(3/√2) = 0.99730: one tooth passes when its 2 faces' slope and form do (P3⁴: its pitch about the
    mean is zero), two teeth when also each face's single pitch |p1 − p2| does (P3^(8 + 2); F_p = |p1 − p2|
    < F_pT). A σ off by √2 or a wrong bound moves these by > 10 standard errors."""
    tol = flank_tolerances(3e-3, 0.072, 6)
    P3 = math.erf(3 / math.sqrt(2))
    for z, k in ((1, 4), (2, 10)):
        n = 20000
        got = pass_rate(z, tol, 0.0, n, seed=z)
        want = P3 ** k
        assert abs(got - want) < 4 * math.sqrt(want * (1 - want) / n), (z, got, want)


def test_shipped_gears_pass_their_class():
    """Every drawn gear is within its class (every tooth and face), and it is reproducible: the same seed and name
    give the same gear, another planet its own teeth. The reference ring (82 teeth) passes ≈ 44 % of the time, so
    draws that skip inspection would fail here for most seeds."""
    tol = flank_tolerances(3e-3, 0.246, 6)
    share, z = 0.5, 82
    draws = [draw_teeth(f"g{i}", z, tol, seed=4, systematic=share) for i in range(40)]
    for d in draws:
        p = d["pitch"] - d["pitch"].mean(axis=0)
        assert np.abs(p - np.roll(p, 1, axis=0)).max() <= tol.single_pitch
        assert np.ptp(p, axis=0).max() <= tol.total_pitch
        assert np.abs(d["slope"]).max() <= tol.profile_slope and np.abs(d["form"]).max() <= tol.profile_form
    assert sum(d["draws"] > 1 for d in draws) >= 10          # inspection scrapped gears of this lot
    a, b = draw_teeth("b1", z, tol, 4, share), draw_teeth("b1", z, tol, 4, share)
    assert all(np.array_equal(a[k], b[k]) for k in a)                       # reproducible
    c = draw_teeth("b2", z, tol, 4, share)
    assert not np.allclose(a["slope"], c["slope"])                           # every planet its own teeth


def test_drawn_pitch_goes_on_the_line_of_action_with_cos_alpha():
    """A class's drawn pitch deviations are arcs on the reference circle; the mesh law's table carries them along
    the line of action, cos α times as large (the base-pitch deviation): so the base-pitch σ is f_pT·cos α/3.
    The table's constant coefficient of face f is ±p·cos α + form/3 and its x² coefficient −form."""
    params = with_overrides(reference_dpgt(3), {"errors.flank_class": [
        {"gear": "sun", "grade": 6, "seed": 11, "systematic_share": 0.5}]})
    si = params.si()
    g = si.gears.sun
    table = gear_table(si, "sun").reshape(g.teeth, 2, 5)
    d = draw_teeth("sun", g.teeth, flank_tolerances(g.module, 2 * g.pitch_radius, 6), 11, 0.5)
    along = (table[:, :, 0] + table[:, :, 2] / 3.0) * np.array([1.0, -1.0])
    np.testing.assert_allclose(along, math.cos(math.radians(20.0)) * d["pitch"], rtol=1e-12, atol=1e-18)
    assert g.pressure_angle == pytest.approx(math.radians(20.0))


# ----------------------------------------------------------------------------------------------------
# parameters
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("overrides, where", [
    ({"errors.tooth": [{"gear": "b1", "tooth": 24, "flank": "both", "pitch": "5 um"}]}, "errors.tooth[0].tooth"),
    ({"errors.tooth": [{"gear": "b4", "tooth": 0, "flank": "ccw", "pitch": "5 um"}]}, "errors.tooth[0].gear"),
    ({"errors.tooth": [{"gear": "sun", "tooth": "all", "flank": "cw", "slope": "0.4 mm"}]}, "errors.tooth[0].slope"),
    ({"errors.tooth": [{"gear": "sun", "tooth": -1, "flank": "cw"}]}, "errors.tooth[0].tooth"),
    ({"errors.tooth": [{"gear": "sun", "tooth": 1, "flank": "left"}]}, "errors.tooth[0].flank"),
    ({"errors.flank_class": [{"gear": "all", "grade": 12, "seed": 1, "systematic_share": 0.5}]},
     "errors.flank_class[0].grade"),
    ({"errors.flank_class": [{"gear": "all", "grade": 6, "seed": 1, "systematic_share": 1.5}]},
     "errors.flank_class[0].systematic_share"),
    ({"errors.flank_class": [{"gear": "all", "grade": 6, "seed": 1, "systematic_share": 0.5},
                             {"gear": "b2", "grade": 5, "seed": 1, "systematic_share": 0.5}]}, "errors.flank_class[1].gear"),
    ({"gears.sun.tip_relief": "10 um", "gears.sun.tip_relief_length": "20 mm"}, "gears.sun.tip_relief_length"),
    ({"gears.sun.tip_relief": "10 um"}, "gears.sun.tip_relief_length"),
    ({"gears.ring.tip_relief": "0.5 mm", "gears.ring.tip_relief_length": "3 mm"}, "gears.ring.tip_relief"),
    ({"gears.sun.tip_relief_shape": "cubic"}, "gears.sun.tip_relief_shape"),
])
def test_bad_tooth_input_names_the_entry(overrides, where):
    with pytest.raises(ParameterError) as e:
        build_dpgt(with_overrides(reference_dpgt(), overrides), strict=False)
    msg = str(e.value)
    assert msg.startswith(where) and "\n" not in msg, msg


def test_typical_errors_of_the_rig():
    """Class-Q teeth on every gear, a runout on every gear and pinhole errors on all six pins within ±10 µm."""
    p = reference_dpgt(2)
    e = typical_errors(p, 6).si()
    assert sorted(x.planet for x in e.pinhole) == ["a1", "a2", "a3", "b1", "b2", "b3"]
    assert all(abs(x.radial) <= 10e-6 and abs(x.tangential) <= 10e-6 for x in e.pinhole)
    assert len(e.runout) == 8 and [(c.gear, c.grade) for c in e.flank_class] == [("all", 6)]
    with pytest.raises(ParameterError, match="1..11"):
        typical_errors(p, 12)


# ----------------------------------------------------------------------------------------------------
# from the entries to the mesh law: a whole gear of turned teeth is the gear turned
# ----------------------------------------------------------------------------------------------------
OPTS = SceneOptions(mesh_stiffness="constant", bearings="linear", gravity=False)


def _mesh_forces(params, turns):
    """Both flanks' forces of every mesh family at the initial state, with bodies turned counter-clockwise
    ({name: angle [rad]}). Constant mesh stiffness (the pair law splits a constant over the pairs): a
    turned gear then changes nothing but the compression."""
    bs = build_dpgt(params, OPTS, strict=False)
    system = mbd.System(bs.model)
    q = bs.q0.copy()
    for name, angle in turns.items():
        q[bs.model.full_to_free[3 * bs.model.body(name).index + 2]] += angle
    out = system.outputs(0.0, q, bs.v0, system.init_internal())
    return {k: np.r_[out[f]["force_drive"], out[f]["force_coast"]] for k, f in MESH_FAMILY.items()}


@pytest.mark.parametrize("gear, gear_type", [("sun", "sun"), ("b2", "outer_planet"), ("ring", "ring")])
def test_every_tooth_turned_is_the_gear_turned(gear, gear_type):
    """``[[errors.tooth]] gear = X, tooth = "all", flank = "both", pitch = p`` turns every tooth of X forward by p
    along its base circle: every mesh of the machine then carries what it carries with perfect teeth and
    gear X turned by p/r (p an arc on the reference circle; to 1e-9 of the largest force), in a loaded state (no backlash, every gear turned by
    a few µm: one flank of every mesh compressed), through both kinds of mesh that X enters. A sign or face
    slip would turn X backwards."""
    p = 3e-6
    base = with_overrides(reference_dpgt(3), {
        "errors.tooth_fault": [{"gear": "sun", "tooth": 0, "stiffness_factor": 1.0}],  # the pair law, perfect teeth
        **{f"mesh.backlash_{k}": "0 um" for k in MESH_FAMILY}})              # every mesh closed: all of them loaded
    dev = with_overrides(base, {"errors.tooth": [{"gear": gear, "tooth": "all", "flank": "both", "pitch": f"{p} m"}]})
    si = base.si()
    rng = np.random.default_rng(3)
    types = {"sun": "sun", "ring": "ring", **{f"{c}{n}": t for c, t in (("a", "inner_planet"), ("b", "outer_planet"))
                                             for n in (1, 2, 3)}}
    load = {g: rng.uniform(-6e-6, 6e-6) / si.gears[t].base_radius for g, t in types.items()}
    got = _mesh_forces(dev, load)
    want = _mesh_forces(base, {**load, gear: load[gear] + p / si.gears[gear_type].pitch_radius})
    ref = _mesh_forces(base, load)
    scale = max(np.abs(v).max() for v in want.values())
    assert scale > 1e3
    for k in want:
        np.testing.assert_allclose(got[k], want[k], rtol=0, atol=1e-9 * scale)
    changed = [k for k in want if np.abs(want[k] - ref[k]).max() > 1e-3 * scale]
    assert sorted(changed) == sorted({"sun": ["sun_inner"], "b2": ["inner_outer", "outer_ring"],
                                      "ring": ["outer_ring"]}[gear])           # X's meshes felt the turn


# ----------------------------------------------------------------------------------------------------
# from the parameters to the shapes ISO 1328-1 and the relief define
# ----------------------------------------------------------------------------------------------------
def _profile(si, gear, tooth, face, x):
    g = si.gears[{"sun": "sun", "ring": "ring"}.get(gear, "outer_planet")]
    c = gear_table(si, gear).reshape(g.teeth, 2, 5)[tooth, face, :4]
    return c[0] + x * (c[1] + x * (c[2] + x * c[3]))


@pytest.mark.parametrize("shape, mid_high", [("barrel", True), ("s", False)])
def test_tooth_entries_have_the_iso_profile_shapes(shape, mid_high):
    """``[[errors.tooth]]`` entries read from parameters, evaluated over the active profile (x = −1 its start, +1
    the tip) along the line of action: a slope deviation f_Hα = 4 µm is the difference tip − start (more material at
    the tip); a form deviation f_fα = 3 µm is the range of what is left after the profile's straight line
    (least squares) is removed, and has no straight-line part of its own, with material mid-profile for a barrel and
    towards the tip for an s-form; entries on
    other teeth or faces leave this one perfect."""
    x = np.linspace(-1.0, 1.0, 2001)
    params = with_overrides(reference_dpgt(3), {"errors.tooth": [
        {"gear": "b2", "tooth": 5, "flank": "ccw", "slope": "4 um"},
        {"gear": "b2", "tooth": 7, "flank": "cw", "form": "3 um", "form_shape": shape}]})
    si = params.si()
    slope = _profile(si, "b2", 5, 0, x)
    assert slope[-1] - slope[0] == pytest.approx(4e-6, rel=1e-12)
    np.testing.assert_allclose(np.diff(slope), np.diff(slope)[0], rtol=1e-9)      # a straight line
    form = _profile(si, "b2", 7, 1, x)
    line = np.polyfit(x, form, 1)
    assert abs(line[0]) < 5e-3 * 3e-6                     # a form deviation has no slope of its own
    curved = form - np.polyval(line, x)
    assert np.ptp(curved) == pytest.approx(3e-6, rel=5e-3)       # a discrete fit: within 0.15 % of the L2 one
    if mid_high:
        assert curved[1000] == curved.max() and curved[0] == curved[-1] == pytest.approx(curved.min())
    else:
        assert form[-1] > form[0] and form[-1] == pytest.approx(form.max())
    assert np.all(_profile(si, "b2", 5, 1, x) == 0.0) and np.all(_profile(si, "b2", 6, 0, x) == 0.0)


def test_tip_relief_starts_its_length_from_the_tip():
    """``gears.sun.tip_relief = 10 µm`` over ``tip_relief_length`` L_a = 40 % of the sun–inner path of contact,
    linear: the sun's relief in that mesh is C_a at the sun's tip (ξ = 1), C_a/2 at L_a/2 from the tip along the
    roll length, nothing L_a or farther from the tip; parabolic: C_a/4 at L_a/2."""
    from components.geometry import layout
    from mbd.elements.tooth_pairs import _relief
    mg = layout(reference_dpgt(3)).meshes["sun_inner"]
    path = mg.contact_ratio * mg.base_pitch
    L_a = 0.4 * path
    for shape, half in (("linear", 0.5), ("parabolic", 0.25)):
        params = with_overrides(reference_dpgt(3), {"gears.sun.tip_relief": "10 um",
                                                    "gears.sun.tip_relief_length": f"{L_a} m",
                                                    "gears.sun.tip_relief_shape": shape})
        pp = mesh_pairs(params.si(), mg, ["sun"], ["a1"])
        xi = 1.0 - np.array([0.0, 0.5 * L_a, L_a, 1.2 * L_a, 0.9 * path]) / path
        R, _ = _relief(xi, np.repeat(pp.relief1, xi.size, axis=0))
        np.testing.assert_allclose(R, [10e-6, half * 10e-6, 0.0, 0.0, 0.0], atol=1e-15)
        assert np.all(pp.relief2[:, 0] == 0.0)                       # the planet has none
