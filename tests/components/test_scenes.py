"""Scenes of the components package: the bearing rig (components.rig) and the single planetary set
(components.planetary), each against its classical reference (Stribeck / Lin & Parker)."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad

import mbd
from mbd.ad import wrap_angle
from components.bearing import bearing_kinematics
from components.planetary import (EXAMPLE_PLANETARY, build_single_planetary, load_planetary_toml,
                                  modal_state, planetary_modes, planetary_spec)
from components.presets import reference_bearing, reference_bearing_rig, reference_dpgt
from components.rig import (build_bearing_rig, discrete_load_distribution, rig_loads,
                            rig_static_solution, run_sampled)
from components.scene import SceneOptions
from components.units import ParameterError

F_R = 5000.0   # N: of the order of a planet bearing's load at condition 3


def bearing(clearance="20 um", **kw):
    return reference_bearing().replace(clearance=clearance, **kw)


# ============================================================================ classical reference
def test_discrete_reference_reproduces_stribeck_numbers():
    b = bearing("0 um").si()
    ref = discrete_load_distribution(b, F_R)
    # Z = 12, a roller on the load line, zero clearance: F_r = Q_max Σ cos^(1 + 10/9) over |ψ| < 90°
    expect = 12 / (1 + 2 * math.cos(math.pi / 6) ** (19 / 9) + 2 * math.cos(math.pi / 3) ** (19 / 9))
    assert ref.stribeck == pytest.approx(expect, rel=1e-9)
    assert ref.stribeck == pytest.approx(4.08, abs=0.01)
    np.testing.assert_allclose(np.sum(ref.loads * np.cos(ref.angles)), F_R, rtol=1e-10)
    # many rollers: the continuous line-contact integral (Stribeck's 4.08)
    integral = 1.0 / (quad(lambda p: np.cos(p) ** (19 / 9), -np.pi / 2, np.pi / 2)[0] / (2 * np.pi))
    many = discrete_load_distribution(dataclasses.replace(b, rollers=400), F_R)
    assert many.stribeck == pytest.approx(integral, rel=1e-4)
    # clearance concentrates the load: larger Q_max, smaller zone
    s = [discrete_load_distribution(bearing(c).si(), F_R) for c in ("0 um", "20 um", "40 um")]
    assert s[0].stribeck < s[1].stribeck < s[2].stribeck
    assert s[0].zone_angle == pytest.approx(np.pi) and s[0].zone_angle > s[1].zone_angle > s[2].zone_angle


# ============================================================================ the bearing rig
@pytest.fixture(scope="module")
def held_rig_solutions():
    """Cage held, ring at rest, F_r = 5 kN downwards, at three clearances."""
    out = {}
    for c in ("0 um", "20 um", "40 um"):
        rig = build_bearing_rig(bearing(c), radial_load=F_R, options=SceneOptions(cage="held"))
        out[c] = (rig, rig_static_solution(rig))
    return out


@pytest.mark.parametrize("clearance", ["0 um", "20 um", "40 um"])
def test_rig_matches_the_classical_load_distribution(held_rig_solutions, clearance):
    rig, sol = held_rig_solutions[clearance]
    ref = rig.reference
    # the load zone is opposite to the load on the ring (the pin is pressed along the load)
    assert rig.zone_angle == pytest.approx(np.pi / 2)
    np.testing.assert_allclose(sol.load_sum, sol.load_vector, atol=1e-3 * F_R)
    # the pin reaction the statistics read (components.outputs.pin_reactions: normal + traction) is the load
    # (measured ≤ 1.9e-5 F_r, the 40 samples' mean of the settling ring)
    np.testing.assert_allclose(sol.pin_force, sol.load_vector, atol=5e-5 * F_R)
    assert sol.stribeck == pytest.approx(ref.stribeck, rel=2e-3)
    assert sol.deflection == pytest.approx(ref.deflection, rel=2e-3)
    assert abs(sol.sideways) < 1e-3 * ref.deflection
    # roller by roller (ref angles are measured from the load-zone centre too)
    order = np.argsort(ref.angles)
    np.testing.assert_allclose(sol.angles, ref.angles[order], atol=1e-3)
    np.testing.assert_allclose(sol.loads, ref.loads[order], atol=2e-3 * ref.q_max)
    # inner and outer raceway carry the same load (no orbit: no centrifugal force on the rollers)
    np.testing.assert_allclose(sol.loads_outer, sol.loads, atol=1e-3 * ref.q_max)
    assert sol.zone_angle_continuous == pytest.approx(ref.zone_angle, abs=2e-3)


def test_rig_zero_clearance_gives_stribeck_4_08(held_rig_solutions):
    _, sol = held_rig_solutions["0 um"]
    assert sol.stribeck == pytest.approx(4.08, abs=0.015)
    _, sol20 = held_rig_solutions["20 um"]
    assert sol20.stribeck > sol.stribeck + 0.5


def test_rig_oblique_load_on_an_unsymmetric_roller_set():
    """Load at 100°: no roller on the load line; the ring also shifts sideways (2-D equilibrium)."""
    a = np.radians(100.0)
    rig = build_bearing_rig(bearing("10 um"), radial_load=F_R, load_angle=a, options=SceneOptions(cage="held"))
    sol = rig_static_solution(rig)
    ref = rig.reference
    np.testing.assert_allclose(sol.load_sum, F_R * np.array([np.cos(a), np.sin(a)]), atol=2e-3 * F_R)
    order = np.argsort(ref.angles)
    np.testing.assert_allclose(sol.loads, ref.loads[order], atol=3e-3 * ref.q_max)
    assert sol.deflection == pytest.approx(ref.deflection, rel=3e-3)
    assert sol.sideways == pytest.approx(ref.sideways, abs=3e-3 * ref.deflection)
    assert abs(ref.sideways) > 1e-3 * ref.deflection   # the asymmetry is real, not zero


def test_rig_turning_ring_with_free_cage():
    """Ring at 300 rad/s: the rollers orbit at about the cage's pure-rolling speed; the rollers' total
    contact force on the ring balances the load (normal + traction), and the binned loads still form a
    load zone around the zone centre."""
    w = 300.0
    lub = reference_dpgt(3, "forward").lubricant.replace(drag_coefficient=1.0, density="45 kg/m^3")
    rig = build_bearing_rig(bearing(), radial_load=F_R, outer_speed=w, options=SceneOptions(cage="free"), lubricant=lub)
    m = rig.model
    names = [e.name for e in m.elements]
    assert {"race_inner", "race_outer", "pocket", "guide", "drag", "radial_load", "ring_drive"} <= set(names)
    sol = rig_static_solution(rig, window=2e-3, samples=41)
    np.testing.assert_allclose(sol.ring_force, sol.load_vector, atol=2e-3 * F_R)
    np.testing.assert_allclose(sol.pin_force, sol.load_vector, atol=2e-3 * F_R)     # measured 6.8e-4 (41 samples)
    assert np.argmax(sol.loads) in (5, 6)            # the bins next to the zone centre
    assert abs(sol.angles[np.argmax(sol.loads)]) < np.pi / 12 + 1e-9
    assert np.all(sol.loads[np.abs(sol.angles) > np.radians(100)] < 1e-3 * sol.q_max)
    # cage speed: mean over the window from the cage angle
    sysm = mbd.System(m)
    st = run_sampled(m, rig.q0, rig.v0, [sol.t0, sol.t1], controller=mbd.Adaptive(h0=1e-6, h_max=1e-5), system=sysm)
    ic = 3 * m.body("pb.cage").index + 2
    w_cage = (m.full(st[1].t, st[1].q, st[1].v)[0][ic] - m.full(st[0].t, st[0].q, st[0].v)[0][ic]) / (sol.t1 - sol.t0)
    wm, _ = bearing_kinematics(rig.bearing, 0.0, w)
    assert w_cage == pytest.approx(wm, rel=0.03)
    assert w_cage < wm                                # drag and traction losses: the cage slips back


def test_rig_held_cage_with_turning_ring_starts_consistently():
    """A held cage stops the orbit: the rollers start without orbital speed (no pocket impact at t = 0)
    and stay in their pockets; the rollers' forces on the ring still balance the load."""
    rig = build_bearing_rig(bearing(), radial_load=F_R, outer_speed=300.0, options=SceneOptions(cage="held"))
    m = rig.model
    qf, vf = m.full(0.0, rig.q0, rig.v0)
    rollers = [m.body(n).index for n in rig.bearing_handles.rollers]
    np.testing.assert_allclose(vf[3 * np.array(rollers)], 0.0, atol=1e-12)
    np.testing.assert_allclose(vf[3 * np.array(rollers) + 1], 0.0, atol=1e-12)
    sysm = mbd.System(m)
    assert np.all(sysm.outputs(0.0, rig.q0, rig.v0, {})["pocket"]["force"] == 0.0)
    sol = rig_static_solution(rig, window=1e-3, samples=21)
    np.testing.assert_allclose(sol.ring_force, sol.load_vector, atol=2e-3 * F_R)
    b = rig.bearing
    start = wrap_angle(2 * np.pi * np.arange(b.rollers) / b.rollers - rig.zone_angle)    # the rig's wrap, (−π, π]
    # the two tractions push each loaded roller forwards (ω > 0) against its pocket wall: it sits within
    # the pocket clearance plus the wall's deflection under the traction force 2 μ Q
    offset = (sol.angles - np.sort(start)) * 0.5 * b.pitch_diameter      # sol.angles are sorted
    bound = b.cage.pocket_clearance + 2 * b.traction_mu_max * sol.q_max / b.cage.pocket_stiffness
    assert np.all(np.abs(offset) <= bound)
    assert np.all(offset[sol.loads > 0.1 * sol.q_max] > 0.5 * b.cage.pocket_clearance)


def test_rig_handles_meta_and_instantaneous_loads():
    rig = build_bearing_rig(bearing(), radial_load=F_R, options=SceneOptions(cage="none", gravity=True))
    m = rig.model
    assert m.body("pin").index == 0 and bool(m.fixed[0])
    assert "pocket" not in [e.name for e in m.elements] and "drag" not in [e.name for e in m.elements]
    assert np.allclose(m.gravity, (0.0, -9.81))
    assert rig.ramp == pytest.approx(20 * rig.period)
    r = rig_loads(rig, mbd.System(m), mbd.PRODUCTION.stepper().initial_state(mbd.System(m), 0.0, rig.q0, rig.v0))
    assert r["load_inner"].shape == (12,) and np.all(r["load_inner"] == 0.0)   # centred rollers, no load at t = 0


@pytest.mark.parametrize("kwargs, parameter", [
    ({"radial_load": -1.0}, "radial_load"),
    ({"radial_load": float("nan")}, "radial_load"),
    ({"radial_load": F_R, "load_angle": float("inf")}, "load_angle"),
    ({"radial_load": F_R, "rig": {"ring_mass": 0.0}}, "rig"),
    ({"radial_load": F_R, "options": SceneOptions(bearings="linear")}, "options.bearings"),
    ({"radial_load": F_R, "options": SceneOptions(frame="rotating")}, "options.frame"),
    ({"radial_load": F_R, "options": SceneOptions(drag=True)}, "options.drag"),     # no lubricant given
])
def test_rig_bad_input_names_the_parameter(kwargs, parameter):
    with pytest.raises(ParameterError) as e:
        build_bearing_rig(bearing(), **kwargs)
    assert e.value.parameter == parameter


def test_rig_parameters_are_checked_with_their_names_and_units():
    with pytest.raises(ParameterError, match=r"^bearing_rig\.ring_mass: must be > 0"):
        reference_bearing_rig().replace(ring_mass="0 kg")
    with pytest.raises(ParameterError, match=r"^bearing_rig\.drive_bandwidth: expected a frequency"):
        reference_bearing_rig().replace(drive_bandwidth="3 m")
    assert reference_bearing_rig().source("settle_damping_ratio").tag == "assumed"


def test_scene_option_cage_vocabulary():
    """cage is "free" | "held" | "none" everywhere; old true/false input maps to "free"/"none"."""
    assert SceneOptions(cage=True).cage == "free" and SceneOptions(cage=False).cage == "none"
    assert SceneOptions.from_dict({"cage": "held"}).cage == "held"
    with pytest.raises(mbd.ModelError, match="'cage' must be one of"):
        SceneOptions(cage="loose")
    # the rig takes its own values only where the user gave none, and keeps the user's
    rig = build_bearing_rig(bearing(), radial_load=F_R, options=SceneOptions(cage="none"))
    assert rig.options.cage == "none" and np.allclose(rig.model.gravity, 0.0)
    assert build_bearing_rig(bearing(), radial_load=F_R).options.cage == "free"
    from components.dpgt import build_dpgt
    with pytest.raises(ParameterError, match=r"^options\.cage: 'held' is a bearing-rig option"):
        build_dpgt(reference_dpgt(3), SceneOptions(cage="held"))


def test_rig_rollers_that_do_not_fit():
    with pytest.raises(ParameterError) as e:
        build_bearing_rig(bearing(rollers=20), radial_load=F_R)
    assert e.value.parameter == "bearing.rollers"
    with pytest.raises(ParameterError) as e:
        build_bearing_rig("not a bearing", radial_load=F_R)
    assert e.value.parameter == "bearing"


# ============================================================================ single planetary set
def _modes(N, **over):
    built = build_single_planetary(overrides={"planets": N, **over})
    return built, planetary_modes(built)


@pytest.mark.parametrize("N", [3, 4, 5])
def test_lin_parker_mode_structure(N):
    """Equally spaced planets (Lin & Parker 1999): 3(N+3) modes = 6 rotational (single) + 6 pairs of
    translational modes + 3 planet-mode frequencies of multiplicity N−3; the example set holds the
    ring torsionally and leaves sun and carrier free, so exactly one rigid-body (zero) mode, rotational."""
    built, pm = _modes(N)
    assert built.model.ndof == 3 * (N + 3) == pm.frequencies_hz.size
    assert "mixed" not in pm.kind
    assert np.all(pm.frequencies_hz >= 0.0)
    zero = np.flatnonzero(pm.frequencies_hz == 0.0)
    assert zero.size == 1 and pm.kind[zero[0]] == "rotational"
    assert np.all(pm.frequencies_hz[1:] > 100.0)
    assert pm.multiplicities("rotational") == [1] * 6
    assert pm.multiplicities("translational") == [2] * 6
    assert pm.multiplicities("planet") == ([N - 3] * 3 if N > 3 else [])
    assert sum(pm.kind.count(k) for k in ("rotational", "translational", "planet")) == 3 * (N + 3)


def _planet_local_motion(built, shape):
    """(N, 3): each planet's modal displacement in its own radial/tangential axes, and its rotation."""
    m = built.model
    full = np.zeros(3 * m.n_bodies)
    full[m.free] = shape
    out = []
    for name, psi in zip(built.planets, built.psi):
        i = 3 * m.body(name).index
        c, s = np.cos(psi), np.sin(psi)
        x, y = full[i], full[i + 1]
        out.append((c * x + s * y, -s * x + c * y, full[i + 2]))
    return np.array(out)


def test_rotational_modes_move_every_planet_alike_and_planet_modes_do_not_depend_on_n():
    built4, pm4 = _modes(4)
    for i, kind in enumerate(pm4.kind):
        if kind == "rotational":
            local = _planet_local_motion(built4, pm4.shapes[:, i])
            np.testing.assert_allclose(local, np.broadcast_to(local[0], local.shape),
                                       atol=1e-9 * np.abs(local).max() + 1e-12)
    _, pm5 = _modes(5)
    f4 = np.unique(np.round(pm4.frequencies_hz[np.array(pm4.kind) == "planet"], 6))
    f5 = np.unique(np.round(pm5.frequencies_hz[np.array(pm5.kind) == "planet"], 6))
    np.testing.assert_allclose(f4, f5, rtol=1e-9)   # planet modes involve the planets alone


@pytest.mark.parametrize("torsion, n_zero", [
    ({"ring.torsional_stiffness": "0 N*m/rad"}, 2),          # rigid rotation + the free differential
    ({"sun.torsional_stiffness": "1e5 N*m/rad", "carrier.torsional_stiffness": "1e6 N*m/rad"}, 0),
])
def test_zero_modes_follow_the_torsional_supports(torsion, n_zero):
    _, pm = _modes(4, **torsion)
    assert np.count_nonzero(pm.frequencies_hz == 0.0) == n_zero
    assert all(pm.kind[i] == "rotational" for i in np.flatnonzero(pm.frequencies_hz == 0.0))
    if n_zero == 0:
        assert pm.frequencies_hz.min() > 10.0
        assert pm.multiplicities("rotational") == [1] * 6


@pytest.mark.parametrize("sign", [1, -1])
def test_modal_state_loads_each_mesh_on_its_flank(sign):
    built = build_single_planetary(torque_sign=sign)
    q, v = modal_state(built, preload=1e-9)
    sysm = mbd.System(built.model)
    out = sysm.outputs(0.0, q, v, {})
    for fam in ("mesh_sp", "mesh_rp"):
        loaded = out[fam]["deflection"] if sign > 0 else out[fam]["deflection_coast"]
        other = out[fam]["deflection_coast"] if sign > 0 else out[fam]["deflection"]
        np.testing.assert_allclose(loaded, 1e-9, rtol=1e-6)
        np.testing.assert_allclose(other, -1e-9, rtol=1e-6)
    # the nominal state itself has both flanks just touching: no mesh stiffness there
    _, _, K0 = sysm.matrices(sysm.evaluate(0.0, built.q0, built.v0, {}, jac=True))
    _, _, K1 = sysm.matrices(sysm.evaluate(0.0, q, v, {}, jac=True))
    assert np.abs(K1 - K0).max() > 1e7


TOML = """
kind = "single_planetary"
planets = 4
module = "3 mm"
pressure_angle = "20 deg"
teeth = { sun = 30, planet = 30, ring = 90 }
mesh_stiffness = { sun_planet = "5e8 N/m", ring_planet = "4e8 N/m" }
[sun]
mass = "1 kg"
inertia = "1e-3 kg*m^2"
support_stiffness = "1e8 N/m"
torsional_stiffness = "0 N*m/rad"
[ring]
mass = "4 kg"
inertia = "3e-2 kg*m^2"
support_stiffness = "2e8 N/m"
torsional_stiffness = "1e8 N*m/rad"
[carrier]
mass = "3 kg"
inertia = "1.5e-2 kg*m^2"
support_stiffness = "1e8 N/m"
torsional_stiffness = "0 N*m/rad"
[planet]
mass = "500 g"
inertia = "3e-4 kg*m^2"
bearing_stiffness = "1e5 N/mm"
"""


def test_planetary_toml_round_trip(tmp_path):
    path = tmp_path / "set.toml"
    path.write_text(TOML)
    spec = load_planetary_toml(path)
    assert spec.planets == 4 and (spec.z_sun, spec.z_planet, spec.z_ring) == (30, 30, 90)
    assert spec.module == pytest.approx(3e-3) and spec.pressure_angle == pytest.approx(np.radians(20))
    assert spec.planet_mass == pytest.approx(0.5) and spec.bearing_stiffness == pytest.approx(1e8)
    assert spec.k_ring_planet == pytest.approx(4e8) and spec.ring.support_stiffness == pytest.approx(2e8)
    assert spec.radii["carrier"] == pytest.approx(0.09)
    built = build_single_planetary(spec)
    m = built.model
    assert m.ndof == 21 and m.body_names[:3] == ("sun", "ring", "carrier")
    bear = m.element("bearing")
    np.testing.assert_allclose(np.hypot(*bear.marker_a.T), 0.09)
    assert m.element("mesh_sp").n == 4 and m.element("mesh_rp").internal
    # overrides through the file loader
    assert load_planetary_toml(path, overrides={"planets": 5}).planets == 5


@pytest.mark.parametrize("overrides, parameter", [
    ({"planets": 0}, "planets"),
    ({"planets": 2.5}, "planets"),
    ({"sun.mass": "1 m"}, "sun.mass"),
    ({"sun.mass": "-1 kg"}, "sun.mass"),
    ({"planet.bearing_stiffness": "-1 N/m"}, "planet.bearing_stiffness"),
    ({"ring.torsional_stiffness": "5 N/m"}, "ring.torsional_stiffness"),
    ({"teeth.ring": 91}, "teeth.ring"),
    ({"sun.colour": "red"}, "sun.colour"),
    ({"kind": "double_planetary"}, "kind"),
    ({"pressure_angle": 0.35}, "pressure_angle"),
    ({"mesh_stiffness.sun_planet": "0 N/m"}, "mesh_stiffness.sun_planet"),
    ({"speed": "100 rpm"}, "speed"),
])
def test_planetary_bad_input_names_the_key(overrides, parameter):
    with pytest.raises(ParameterError) as e:
        build_single_planetary(overrides=overrides)
    assert e.value.parameter == parameter


def test_planetary_missing_table_and_assembly_warning():
    spec = dict(EXAMPLE_PLANETARY)
    del spec["planet"]
    with pytest.raises(ParameterError, match=r"^planet: "):
        planetary_spec(spec)
    from components.geometry import DesignWarning
    with pytest.warns(DesignWarning, match="not an integer"):   # (31 + 91)/4 = 30.5
        built = build_single_planetary(overrides={"planets": 4, "teeth.sun": 31, "teeth.ring": 91})
    assert built.model.ndof == 21
    with pytest.warns(DesignWarning, match="overlap"):
        build_single_planetary(overrides={"planets": 6})


def test_traction_law_is_chosen_by_a_parameter():
    """bearing.traction_law selects the law from the registry; its coefficients come from the parameters."""
    import warnings

    from components.dpgt import build_dpgt
    from components.params import with_overrides
    from components.presets import reference_dpgt
    from components.scene import SceneOptions
    from mbd.elements import SlideRollTraction, TanhTraction

    for law, cls in (("tanh", TanhTraction), ("slide_roll", SlideRollTraction)):
        p = with_overrides(reference_dpgt(3), {"bearing.traction_law": law, "bearing.slide_roll_traction.C": 35.0})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            bs = build_dpgt(p, SceneOptions(gravity=False))
        tr = bs.model.element("race_inner").traction
        assert type(tr) is cls and tr == bs.model.element("race_outer").traction
        if law == "slide_roll":
            assert tr.C == 35.0 and tr.needs_rolling_speed
        else:
            assert tr.mu_max == pytest.approx(0.08) and tr.v0 == pytest.approx(0.3)
