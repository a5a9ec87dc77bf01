"""Involute geometry, layout, kinematics, mesh phasing and design checks (docs/model.md §1, docs/parameters.md)."""
import math
import warnings

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

from components import geometry as geo
from components.params import with_overrides
from components.presets import reference_dpgt
from components.units import ParameterError

RPM = 2 * math.pi / 60


@pytest.fixture(scope="module")
def ref():
    return reference_dpgt()


@pytest.fixture(scope="module")
def lay(ref):
    return ref.si().layout


def frac(x):
    return np.mod(x, 1.0)


def near_int(x, tol=1e-9):
    return np.abs(x - np.round(x)) < tol


# ------------------------------------------------------------------ derived numbers (docs/parameters.md)
def test_derived_numbers(lay):
    assert lay.r_ca == pytest.approx(82.5e-3, rel=1e-12)
    assert lay.r_cb == pytest.approx(87.0e-3, rel=1e-12)
    assert lay.l_ab == pytest.approx(72.0e-3, rel=1e-12)
    assert math.degrees(lay.delta_psi) == pytest.approx(50.19, abs=0.005)
    eps = {k: m.contact_ratio for k, m in lay.meshes.items()}
    assert eps["sun_inner"] == pytest.approx(1.63, abs=0.01)
    assert eps["inner_outer"] == pytest.approx(1.60, abs=0.01)
    assert eps["outer_ring"] == pytest.approx(1.91, abs=0.01)
    assert lay.sun_ratio == pytest.approx(-1.6452, abs=5e-5)
    assert lay.assembly_number == 17 and lay.assembles


def test_gear_radii(lay):
    sun, ring = lay.gears["sun"], lay.gears["ring"]
    assert (sun.pitch_radius, sun.tip_radius, sun.root_radius) == pytest.approx((46.5e-3, 49.5e-3, 42.75e-3))
    assert sun.base_radius == pytest.approx(46.5e-3 * math.cos(math.radians(20)))
    # internal gear: tip circle is the inner one
    assert (ring.pitch_radius, ring.tip_radius, ring.root_radius) == pytest.approx((123e-3, 120e-3, 126.75e-3))


def test_contact_ratio_standard_formula():
    g1 = geo.GearGeometry(teeth=20, module=1e-3, pressure_angle=math.radians(20))
    g2 = geo.GearGeometry(teeth=40, module=1e-3, pressure_angle=math.radians(20))
    a = 30e-3
    rb1, rb2 = g1.base_radius, g2.base_radius
    ref_eps = (math.sqrt(0.011 ** 2 - rb1 ** 2) + math.sqrt(0.021 ** 2 - rb2 ** 2) - a * math.sin(math.radians(20))) \
        / (math.pi * 1e-3 * math.cos(math.radians(20)))
    assert geo.contact_ratio(g1, g2, a) == pytest.approx(ref_eps, rel=1e-12)
    ring = geo.GearGeometry(teeth=80, module=1e-3, pressure_angle=math.radians(20), internal=True)
    a_i = 30e-3
    ref_int = (math.sqrt(0.011 ** 2 - rb1 ** 2) - math.sqrt(0.039 ** 2 - ring.base_radius ** 2)
               + a_i * math.sin(math.radians(20))) / (math.pi * 1e-3 * math.cos(math.radians(20)))
    assert geo.contact_ratio(g1, ring, a_i, internal=True) == pytest.approx(ref_int, rel=1e-12)


def test_planet_positions_and_handedness(lay):
    ca, cb = lay.centres_a, lay.centres_b
    assert np.linalg.norm(ca, axis=1) == pytest.approx(np.full(3, lay.r_ca))
    assert np.linalg.norm(cb, axis=1) == pytest.approx(np.full(3, lay.r_cb))
    assert np.linalg.norm(cb - ca, axis=1) == pytest.approx(np.full(3, lay.l_ab))
    assert lay.psi_a == pytest.approx([0, 2 * np.pi / 3, 4 * np.pi / 3])
    # h = -1: the outer planet trails its inner planet (negative angle from a to b)
    cross = ca[:, 0] * cb[:, 1] - ca[:, 1] * cb[:, 0]
    assert np.all(cross < 0)
    mirror = with_overrides(reference_dpgt(), {"gears.handedness": 1}).si().layout
    assert mirror.psi_b - mirror.psi_a == pytest.approx(np.full(3, lay.delta_psi))


# ------------------------------------------------------------------ kinematics
@pytest.mark.parametrize("n_c, n_s", [(4200, -6909.7), (2000, -3290.3), (-4200, 6909.7)])
def test_speed_ratio(n_c, n_s):
    assert geo.speed_ratio(31, 82) * n_c == pytest.approx(n_s, abs=0.05)


def test_mesh_frequency():
    k = reference_dpgt(3).si().operating
    assert k.carrier_frequency == pytest.approx(70.0)
    assert k.mesh_frequency == pytest.approx(82 * 70.0)
    assert geo.mesh_frequency(82, -70.0) == pytest.approx(5740.0)


@pytest.mark.parametrize("direction", ["forward", "reverse"])
def test_planet_speeds_roll_without_slip_at_every_pitch_point(direction):
    """Independent check of the planet speeds: in the fixed frame, the surface velocities of the two
    gears of each mesh are equal at the pitch point (ring fixed, carrier turning)."""
    p = reference_dpgt(3, direction)
    s = p.si()
    lay, k = s.layout, s.operating
    gs = s.gears

    def vel(w, centre, centre_vel, point):  # v = v_c + ω k × (P − c)
        r = point - centre
        return centre_vel + w * np.array([-r[1], r[0]])

    def carrier_vel(c):
        return k.carrier_speed * np.array([-c[1], c[0]])

    for ca, cb in zip(lay.centres_a, lay.centres_b):
        o = np.zeros(2)
        e = ca / np.linalg.norm(ca)
        p_sa = gs.sun.pitch_radius * e
        assert vel(k.sun_speed, o, o, p_sa) == pytest.approx(vel(k.inner_planet_speed, ca, carrier_vel(ca), p_sa))
        e = (cb - ca) / np.linalg.norm(cb - ca)
        p_ab = ca + gs.inner_planet.pitch_radius * e
        assert vel(k.inner_planet_speed, ca, carrier_vel(ca), p_ab) == \
            pytest.approx(vel(k.outer_planet_speed, cb, carrier_vel(cb), p_ab))
        p_br = gs.ring.pitch_radius * cb / np.linalg.norm(cb)
        assert vel(k.outer_planet_speed, cb, carrier_vel(cb), p_br) == pytest.approx(np.zeros(2), abs=1e-9)
    assert k.inner_planet_speed == pytest.approx(k.carrier_speed * (1 + 82 / 24))
    assert k.outer_planet_speed == pytest.approx(k.carrier_speed * (1 - 82 / 24))


@pytest.mark.parametrize("direction", ["forward", "reverse"])
@pytest.mark.parametrize("power_kw", [150.0, -150.0])
def test_torques_carry_the_power_and_braking_turns_them_over(direction, power_kw):
    """Lossless: the sun's torque times its speed is the output power P (> 0: driven in; < 0 braking: taken out),
    the carrier's the opposite; braking turns both torques over and keeps the speeds, so its loaded flanks are the
    other direction's (geometry.loaded_flanks follows the sun torque's sign)."""
    k = with_overrides(reference_dpgt(2, direction), {"operating.output_power": f"{power_kw} kW"}).si().operating
    assert k.sun_torque * k.sun_speed == pytest.approx(power_kw * 1e3, rel=1e-14)
    assert k.carrier_torque * k.carrier_speed == pytest.approx(-power_kw * 1e3, rel=1e-14)
    assert k.ring_torque == pytest.approx(-(k.sun_torque + k.carrier_torque), rel=1e-14)
    driving = with_overrides(reference_dpgt(2, direction), {"operating.output_power": "150 kW"}).si().operating
    assert k.sun_speed == driving.sun_speed and abs(k.sun_torque) == pytest.approx(abs(driving.sun_torque), rel=1e-15)
    other = "reverse" if direction == "forward" else "forward"
    flip = geo.loaded_flanks(np.sign(k.sun_torque))
    same = geo.loaded_flanks(np.sign(reference_dpgt(2, direction if power_kw > 0 else other).si().operating.sun_torque))
    assert flip == same


# ------------------------------------------------------------------ assembly and phasing
def test_assembly_condition():
    assert geo.assembly_number(31, 82, 3) == 17
    assert geo.assembly_number(31, 82, 4) == 12.75
    l3 = reference_dpgt().si().layout
    l4 = with_overrides(reference_dpgt(), {"gears.planets": 4}).si().layout
    assert l3.assembles and not l4.assembles
    assert l3.phasing.ring_mismatch == pytest.approx(np.zeros(3), abs=1e-9)
    # the tooth chain sun → a → b → ring misses the ring by (z_r − z_s)·n/N pitches (wrapped)
    assert l4.phasing.ring_mismatch == pytest.approx([0.0, -0.25, -0.5, 0.25], abs=1e-9)


def test_sun_mesh_phases(lay):
    """Sequential sun–planet phasing: at assembly p_n = frac(−z_s·n/N), pair 0 with sun tooth 0 on its
    pitch point; the phase p0 is 0 (sun tooth 0 on the x axis), the planet angle enters through φ_e."""
    m = lay.meshes["sun_inner"]
    assert m.p_assembly == pytest.approx(frac(-31 * np.arange(3) / 3), abs=1e-12)
    assert m.p_assembly[0] == 0.0 and np.all(m.p0 == 0.0)
    for m in lay.meshes.values():  # p = z_1(θ_1 − φ_e)/2π + p0 at θ = 0 is the assembly position
        assert near_int(m.z1 * (0 - m.line_angle) / (2 * np.pi) + m.p0 - m.p_assembly).all()


def tooth_phase(z, gamma, theta, direction):
    """Phase of the point at angle ``direction`` (seen from the gear centre) w.r.t. the gear's teeth:
    0 = a tooth centre line points there, 1/2 = a tooth space is centred there."""
    return frac(z * (direction - gamma - theta) / (2 * np.pi))


@pytest.mark.parametrize("planets, handedness", [(3, -1), (3, 1), (4, -1), (5, 1), (1, -1)])
@pytest.mark.parametrize("turn", [0.0, 0.37, -2.9])
def test_tooth_positions_mesh_and_stay_in_mesh(planets, handedness, turn):
    """Explicit teeth: with the assembly tooth angles γ, every mesh has a tooth of one gear facing a space
    of the other at its pitch point, at assembly and after any rigid rolling (carrier frame, sun turned
    by ``turn``); the mesh position p = z_1(θ_1 − φ_e)/2π + p0 is minus gear 1's tooth phase there."""
    p = with_overrides(reference_dpgt(), {"gears.planets": planets, "gears.handedness": handedness})
    lay = p.si().layout
    ph = lay.phasing
    zs, za, zb, zr = 31, 24, 24, 82
    # rigid rolling relative to the carrier: z_s dθ_s = −z_a dθ_a = z_b dθ_b = z_r dθ_r
    th_s, th_a, th_b, th_r = turn, -zs * turn / za, zs * turn / zb, zs * turn / zr
    m = lay.meshes
    # sun–inner (external): phases at the pitch point add up to 1/2
    t_s = tooth_phase(zs, 0.0, th_s, lay.psi_a)
    t_a = tooth_phase(za, ph.gamma_inner, th_a, lay.psi_a + np.pi)
    assert near_int(t_s + t_a - 0.5).all()
    assert near_int(frac(zs * (th_s - lay.psi_a) / (2 * np.pi) + m["sun_inner"].p0) + t_s).all()
    # inner–outer (external)
    t_a2 = tooth_phase(za, ph.gamma_inner, th_a, lay.phi_ab)
    t_b = tooth_phase(zb, ph.gamma_outer, th_b, lay.phi_ab + np.pi)
    assert near_int(t_a2 + t_b - 0.5).all()
    assert near_int(frac(za * (th_a - lay.phi_ab) / (2 * np.pi) + m["inner_outer"].p0) + t_a2).all()
    # outer–ring (internal): same sense, phases differ by 1/2 — for every pair only if the set assembles
    t_b2 = tooth_phase(zb, ph.gamma_outer, th_b, lay.psi_b)
    t_r = tooth_phase(zr, ph.gamma_ring, th_r, lay.psi_b)
    ok = near_int(t_r - t_b2 - 0.5)
    assert ok[0]
    assert ok.all() == lay.assembles
    assert near_int(t_r - t_b2 - 0.5 - ph.ring_mismatch).all()
    assert near_int(frac(zb * (th_b - lay.psi_b) / (2 * np.pi) + m["outer_ring"].p0) + t_b2).all()


def test_pairs_in_contact_and_flank_convention(lay):
    p = np.linspace(0, 1, 200001)[:-1]
    for m in lay.meshes.values():
        for f in (1, -1):
            n = m.pairs_in_contact(p, f)
            assert set(np.unique(n)) == {1, 2}
            assert n.mean() == pytest.approx(m.contact_ratio, abs=1e-4)      # mean pairs = ε_α
            # flank f's contact is on the pitch point at p = −σf/4
            assert m.contact_position(-m.sigma * f / 4, f) == pytest.approx(0.0, abs=1e-15)
            # one pitch of p moves the contact one base pitch along the line of action
            assert abs(m.contact_position(0.3, f) - m.contact_position(0.2, f)) == pytest.approx(0.1 * m.base_pitch)


def test_flank_contact_position_matches_involute_teeth(lay):
    """Independent check of the flank convention with real involute teeth: gear 1 at the origin, line of
    centres along +x, tooth centre line at angle c (so p = z_1·c/2π). The face loaded on flank f is the
    one whose outward normal is minus the force on gear 1 (docs/model.md §6.2: −n_f external, n_f internal);
    its intersection with flank f's line of action must sit where contact_position says (mod p_b)."""
    from scipy.optimize import brentq

    def inv(x):
        return math.tan(x) - x

    for m in lay.meshes.values():
        g1 = lay.gears[m.gear1]
        z, r1, rb, ra, al = g1.teeth, g1.pitch_radius, g1.base_radius, g1.tip_radius, m.pressure_angle
        pitch_point = np.array([r1, 0.0])
        for f in (1, -1):
            force_on_1 = np.array([-math.sin(al), -f * math.cos(al)]) if not m.internal \
                else np.array([-math.sin(al), f * math.cos(al)])
            d = -force_on_1 if not m.internal else force_on_1  # line direction (any orientation)
            face = 1 if -force_on_1[1] > 0 else -1              # +t face if its outward normal points +y
            pd = pitch_point @ d
            tip = min((-pd + k * math.sqrt(pd * pd - r1 * r1 + ra * ra) for k in (1, -1)), key=abs)
            d = d * math.copysign(1.0, tip)                       # now +s runs towards gear 1's tip end
            # tooth angles that put the loaded face within ±0.4 base pitch of the pitch point
            for c in (np.linspace(-0.8, 0.8, 9) - face) * math.pi / (2 * z):
                def gap(s):
                    x = pitch_point + s * d
                    r = math.hypot(*x)
                    return math.atan2(x[1], x[0]) - (c + face * (math.pi / (2 * z) + inv(al) - inv(math.acos(rb / r))))
                s_grid = np.linspace(-0.6, 0.6, 121) * m.base_pitch
                vals = np.array([gap(s) for s in s_grid])
                i = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
                s0 = brentq(gap, s_grid[i], s_grid[i + 1], xtol=1e-15)
                pred = m.contact_position(z * c / (2 * math.pi), f)
                err = (s0 - pred + m.base_pitch / 2) % m.base_pitch - m.base_pitch / 2
                assert abs(err) < 1e-12, (m.name, f, c)


def test_wave_phase_reproduces_tooth_pair_count(lay):
    """A wave with double contact on p' ∈ [0, ε−1), p' = p − p0 + wave_p0(f), matches the pair count."""
    p = np.linspace(0, 1, 20001)[:-1]
    for m in lay.meshes.values():
        for f in (1, -1):
            for n in range(len(m.p0)):
                p_wave = frac(p - m.p0[n] + m.wave_p0(f)[n])
                double = p_wave < m.contact_ratio - 1
                count = m.pairs_in_contact(p, f)
                edge = np.minimum(np.abs(p_wave - (m.contact_ratio - 1)), np.minimum(p_wave, 1 - p_wave)) < 1e-9
                assert np.array_equal(double[~edge], count[~edge] == 2), (m.name, f, n)
        # the two flanks are phased differently: a mesh must be phased for its loaded flank
        assert not np.allclose(m.wave_p0(1), m.wave_p0(-1))


@pytest.mark.parametrize("sun_torque_sign", [1, -1])
def test_loaded_flanks_follow_the_torque_path(sun_torque_sign):
    """docs/model.md §6.1 compressions for a driven chain: the sun turns by s·ε with its planet held, then each
    planet turns as it is driven with the next gear held; the compressed flank is the loaded one."""
    rb = {"s": 0.0437, "a": 0.0338, "b": 0.0338, "r": 0.1156}
    zs, za, zb = 31, 24, 24
    d_s = sun_torque_sign * 1e-4
    d_a = -zs / za * d_s
    d_b = -za / zb * d_a

    def compressed(delta):
        return [f for f in (1, -1) if delta(f) > 0]

    flanks = geo.loaded_flanks(sun_torque_sign)
    assert compressed(lambda f: f * rb["s"] * d_s) == [flanks["sun_inner"]]                   # external
    assert compressed(lambda f: f * rb["a"] * d_a) == [flanks["inner_outer"]]                 # external
    assert compressed(lambda f: f * (rb["r"] * 0.0 - rb["b"] * d_b)) == [flanks["outer_ring"]]  # internal
    forward = reference_dpgt(3, "forward").si().operating
    assert geo.loaded_flanks(np.sign(forward.sun_torque)) == {"sun_inner": -1, "inner_outer": 1, "outer_ring": 1}


def test_mesh_stiffness_and_damping(lay, ref):
    """ISO 6336-1's stiffness by hand at condition 3: w = F_t/b = (200 kW/|ω_s|)/(3 r_s)/32 mm with
    ω_s = (1 − 82/31) ω_c, c' = c'_th · 0.8 · C_B (w/100 N/mm)^0.25, C_B = 1 + 0.5(1.2 − 1.25) = 0.975; the wave's
    single level is c' b and its double level 1.75 c' b."""
    gs = ref.si().gears
    w_s = (82 / 31 - 1) * 4200 * RPM
    w = 200e3 / w_s / (3 * 46.5e-3) / 32e-3                                  # N/m
    assert w == pytest.approx(61.9e3, rel=1e-3)
    q = {"sun_inner": 0.04723 + 0.15551 / 31 + 0.25791 / 24, "inner_outer": 0.04723 + (0.15551 + 0.25791) / 24,
         "outer_ring": 0.04723 + 0.15551 / 24}                                # mm·µm/N; the ring's z_2 = ∞
    for key, m in lay.meshes.items():
        assert m.face_width == pytest.approx(32e-3)
        assert m.line_load == pytest.approx(w, rel=1e-12)
        c1 = 1e9 / q[key] * 0.8 * 0.975 * (w / 1e5) ** 0.25                   # N/m²
        assert m.k_single == pytest.approx(c1 * 32e-3, rel=1e-12), key
        assert m.k_double == pytest.approx(1.75 * c1 * 32e-3, rel=1e-12), key
        assert m.k_mean == pytest.approx(c1 * (0.75 * m.contact_ratio + 0.25) * 32e-3, rel=1e-12), key
        frac2 = m.contact_ratio - 1
        assert m.k_single * (1 - frac2) + m.k_double * frac2 == pytest.approx(m.k_mean)
        j1, j2 = gs[m.gear1].inertia, gs[m.gear2].inertia
        m_eq = j1 * j2 / (j1 * m.base_radius2 ** 2 + j2 * m.base_radius1 ** 2)
        assert m.damping == pytest.approx(2 * 0.07 * math.sqrt(m.k_mean * m_eq))
    k = with_overrides(ref, {"mesh.mean_stiffness": "5e8 N/m"}).si().layout.meshes["outer_ring"]
    assert k.k_mean == 5e8
    # a given c_γα is common to the three meshes; a given ratio replaces 1.75
    given = with_overrides(ref, {"mesh.c_gamma_alpha": "20 N/(mm*um)", "mesh.stiffness_ratio": 1.5}).si().layout
    for m in given.meshes.values():
        assert m.k_mean == pytest.approx(6.4e8) and m.k_double / m.k_single == pytest.approx(1.5)
    # without load (condition 4) the standard's load correction is not applied: c' at 100 N/mm
    idle = reference_dpgt(4).si().layout.meshes["sun_inner"]
    assert idle.line_load == 0.0
    assert idle.k_single == pytest.approx(1e9 / q["sun_inner"] * 0.8 * 0.975 * 32e-3, rel=1e-12)


def test_palmgren_stiffness():
    assert geo.palmgren_stiffness(9e-3) == pytest.approx(1.22e9, rel=5e-3)
    assert geo.palmgren_stiffness(9e-3) == pytest.approx(8.06e4 * 9 ** (8 / 9) * 1e3 ** (10 / 9), rel=1e-12)


# ------------------------------------------------------------------ design checks
def test_reference_design_warns_about_the_two_overlaps(ref):
    with pytest.warns(geo.DesignWarning) as record:
        found = geo.check_design(ref)
    assert all(f.severity == "warning" for f in found)
    by_param = {f.parameter: f.message for f in found}
    assert set(by_param) == {"gears.sun", "gears.ring"}
    assert "sun and outer planet" in by_param["gears.sun"] and "1.50 mm" in by_param["gears.sun"]
    assert "inner planets and the ring" in by_param["gears.ring"] and "1.50 mm" in by_param["gears.ring"]
    assert len(record) == 2


def test_four_planets_warn_about_assembly_and_collisions(ref):
    p = with_overrides(ref, {"gears.planets": 4})
    found = geo.design_findings(p)
    assert not [f for f in found if f.severity == "error"]
    msgs = [f.message for f in found if f.parameter == "gears.planets"]
    assert any("12.75 is not an integer" in m for m in msgs)
    assert any("would collide" in m for m in msgs)   # 4 pairs of these gears do not fit around the sun
    with pytest.warns(geo.DesignWarning):
        geo.check_design(p)


def test_shorter_addenda_remove_the_overlap_warnings(ref):
    p = with_overrides(ref, {"gears.sun.addendum_coefficient": 0.45, "gears.ring.addendum_coefficient": 0.45})
    found = geo.design_findings(p)
    assert not [f for f in found if f.parameter in ("gears.sun", "gears.ring")]


@pytest.mark.parametrize("overrides, parameter", [
    ({"bearing.rollers": 20}, "bearing.rollers"),
    ({"bearing.roller_diameter": "40 mm"}, "bearing.roller_diameter"),
    ({"bearing.pitch_diameter": "60 mm"}, "bearing.pitch_diameter"),
    ({"bearing.cage.pocket_clearance": "1.5 mm"}, "bearing.cage.pocket_clearance"),
    ({"bearing.clearance": "30 mm"}, "bearing.clearance"),        # its bore misses the planets' roots, too
    ({"gears.ring.module": "2 mm"}, "gears.ring.module"),
    ({"gears.inner_planet.internal": True}, "gears.inner_planet.internal"),
    ({"gears.ring.teeth": 200}, "gears"),                  # no planet-pair triangle
    ({"gears.ring.teeth": 20}, "gears"),                   # outer planets do not fit in the ring
    ({"operating.carrier_speed": "0 rpm"}, "operating.output_power"),
])
def test_design_errors_raise_naming_the_parameter(ref, overrides, parameter):
    p = with_overrides(ref, overrides)
    errors = [f for f in geo.design_findings(p) if f.severity == "error"]
    assert parameter in {f.parameter for f in errors}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", geo.DesignWarning)
        with pytest.raises(ParameterError) as exc:
            geo.check_design(p)
    assert parameter in str(exc.value).splitlines()[0] and exc.value.parameter == errors[0].parameter
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        found = geo.check_design(p, strict=False)                  # errors are warned, not raised
    assert found == geo.design_findings(p)
    assert any(str(w.message).startswith(f"error: {parameter}:") for w in rec)
    assert all(issubclass(w.category, geo.DesignWarning) for w in rec)


def test_layout_refuses_impossible_gears(ref):
    with pytest.raises(ParameterError, match=r"^gears: no planet-pair triangle"):
        with_overrides(ref, {"gears.ring.teeth": 200}).si()


def test_undercut_and_thin_rim_warnings(ref):
    p = with_overrides(ref, {"gears.sun.teeth": 12, "gears.ring.teeth": 63, "bearing.pitch_diameter": "45 mm"})
    found = {f.parameter: f for f in geo.design_findings(p)}
    assert found["gears.sun.teeth"].severity == "warning" and "undercut" in found["gears.sun.teeth"].message
    assert found["bearing.pitch_diameter"].severity == "warning" and "rim" in found["bearing.pitch_diameter"].message


# ------------------------------------------------------------------ property test over random gear sets
gear_sets = st.fixed_dictionaries({
    "gears.sun.teeth": st.integers(8, 80),
    "gears.inner_planet.teeth": st.integers(8, 50),
    "gears.outer_planet.teeth": st.integers(8, 50),
    "gears.ring.teeth": st.integers(20, 220),
    "gears.planets": st.integers(1, 7),
    "gears.handedness": st.sampled_from([-1, 1]),
    "gears.planet_angle": st.floats(-180, 180).map(lambda x: f"{x} deg"),
    "gears.sun.pressure_angle": st.floats(14.5, 25),
    "gears.sun.module": st.floats(0.5, 8).map(lambda x: f"{x} mm"),
})


@settings(max_examples=80, deadline=None)
@given(gear_sets)
def test_random_gear_sets(values):
    alpha = f"{values.pop('gears.sun.pressure_angle')} deg"
    module = values["gears.sun.module"]
    for g in ("inner_planet", "outer_planet", "ring"):
        values[f"gears.{g}.pressure_angle"] = alpha
        values[f"gears.{g}.module"] = module
    values["gears.sun.pressure_angle"] = alpha
    p = with_overrides(reference_dpgt(), values)
    found = geo.design_findings(p)                                 # never raises
    assert all(f.severity in ("error", "warning") for f in found)
    gear_errors = [f for f in found if f.severity == "error" and f.parameter.startswith("gears")]
    assume(not gear_errors)
    s = p.si()
    lay = s.layout
    n = values["gears.planets"]
    assert np.linalg.norm(lay.centres_a, axis=1) == pytest.approx(np.full(n, lay.r_ca))
    assert np.linalg.norm(lay.centres_b - lay.centres_a, axis=1) == pytest.approx(np.full(n, lay.l_ab))
    assert np.linalg.norm(lay.centres_b, axis=1) == pytest.approx(np.full(n, lay.r_cb))
    for m in lay.meshes.values():
        assert m.contact_ratio >= 1.0
        assert np.all((m.p0 >= 0) & (m.p0 < 1))
        assert m.k_single <= m.k_mean <= m.k_double
    assert lay.assembles == near_int((values["gears.ring.teeth"] - values["gears.sun.teeth"]) / n)
    assert lay.assembles == bool(np.all(np.abs(lay.phasing.ring_mismatch) < 1e-9))
    assert s.gears.sun.pitch_radius == pytest.approx(0.5 * s.gears.sun.module * values["gears.sun.teeth"])
    assert s.operating.sun_speed == pytest.approx(lay.sun_ratio * s.operating.carrier_speed)


def test_a_bearing_clearance_bigger_than_the_gears_allow_is_a_design_error():
    """A planet free to move c/2 on its pin moves its centre distances by that much (the inner-outer mesh by
    c): past the tip-root gap c*·m = 0.75 mm the teeth would strike roots the mesh model does not have.
    The inner-outer mesh reaches it first, at c = 0.75 mm; the reference 20 µm is far inside."""
    from components.geometry import design_findings
    from components.params import with_overrides
    from components.presets import reference_dpgt

    def errors(c):
        return [f for f in design_findings(with_overrides(reference_dpgt(), {"bearing.clearance": c}))
                if f.severity == "error" and f.parameter == "bearing.clearance"]
    assert errors("20 um") == [] and errors("0.74 mm") == []
    (f,) = errors("0.76 mm")
    assert "inner-outer" in f.message and "tip-root gap -0.010 mm" in f.message
