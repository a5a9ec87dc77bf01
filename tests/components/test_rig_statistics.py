"""The statistics of a run (components.outputs.WindowStatistics, what summary.json reports) on the bearing
rig, against closed forms: the roller-load life of a zero-clearance bearing under a pure radial load, the pin
reaction against the applied load, the cage slip against the epicyclic speed of the bearing kinematics and
against cages driven at a known speed.

The scene is the rig of components.rig twice over, in the form the statistics read (one planet pair): a
carrier at rest carries two pins 80 mm from its axis; on each a reference bearing (zero clearance, no
lubricant drag) and a ring loaded by a constant force (ramped in) and held at ±300 rad/s by a stiff speed
drive (1000 Hz, with an integral term: the ring's mean speed is the drive's), with the rig's settling
dashpot. Ring "a1" (the pair's inner bearing) carries 10 kN along its radial line, ring "b1" 6 kN at 0.4 rad
from it and turns the other way. The window is one cage revolution relative to the carrier.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

import mbd
from mbd.elements import ForceSource, GroundSupport, Ramp, SpeedDrive
from components.bearing import add_planet_bearing, bearing_kinematics
from components.dpgt import PairHandles, PlanetBearingScene, Speeds
from components.life import iso281_rating, raceway_ratings
from components.outputs import WindowStatistics, cage_period
from components.presets import reference_bearing, reference_bearing_rig
from components.rig import build_bearing_rig, rig_options
from components.scene import Scene, SceneOptions

W = 300.0             # rad/s, ring speed (2865 r/min): the rollers' centrifugal load ≈ 1.9 N against ≈ 3 kN
PIN_RADIUS = 0.08     # m
RINGS = (("a1", 0.3, 10e3, 0.0, W), ("b1", 2.0, 6e3, 0.4, -W))   # name, pin angle, F_r, load from radial, speed
DRIVEN = (0.97, 1.02)  # cage speed / epicyclic speed of the driven-cage run (slip +3 %, −2 %)


def bearing():
    return reference_bearing().replace(clearance="0 um").si()


def twin_rig(b, cage_speed=None):
    """The two-ring rig (module docstring) and the time its rings have settled [s]; ``cage_speed``: per ring a
    factor on the epicyclic cage speed at which a speed drive (2000 Hz, integral term) holds that ring's cage,
    or None for free cages."""
    rs = reference_bearing_rig().si()
    scene = Scene(options=rig_options(SceneOptions(cage="free", drag=False), has_lubricant=False))
    scene.body("carrier", 1.0, 1.0, fixed=True)
    handles, rings, forces, settle, ramp = [], [], [], 0.0, 0.0
    for j, (name, psi, F, beta, w) in enumerate(RINGS):
        c = PIN_RADIUS * np.array([math.cos(psi), math.sin(psi)])
        rings.append(scene.body(name, rs.ring_mass, rs.ring_inertia, pose=(*c, 0.0), vel=(0.0, 0.0, w)))
        h = add_planet_bearing(scene, f"{name}.pb", pin_body="carrier", pin_local=c, outer_body=name, bearing=b,
                               lubricant=None, pin_xy=c, pin_vel=(0.0, 0.0), omega_pin=0.0, omega_outer=w, damage={})
        handles.append(h)
        forces.append(F * np.array([math.cos(psi + beta), math.sin(psi + beta)]))
        # the single rig's mode, ramp and settling time for this load
        one = build_bearing_rig(b, radial_load=F, load_angle=psi + beta, outer_speed=w,
                                options=SceneOptions(cage="free", drag=False))
        settle, ramp = max(settle, one.t_settle), max(ramp, one.ramp)
        wd = 2 * np.pi * 1000.0
        J = rs.ring_inertia
        scene.add_element(SpeedDrive(f"{name}_drive", rings[-1], w, k=J * wd**2, c=2 * 0.7 * J * wd, k_i=J * wd**3 / 5))
        scene.add_element(GroundSupport(f"{name}_settle", [rings[-1]], kx=0.0,
                                        cx=2.0 * rs.settle_damping_ratio * math.sqrt(one.radial_stiffness * rs.ring_mass)))
        if cage_speed is not None:
            wd, J = 2 * np.pi * 2000.0, b.cage.inertia
            wc = cage_speed[j] * bearing_kinematics(b, 0.0, w)[0]
            scene.add_element(SpeedDrive(f"{name}_cage_drive", scene.index[h.cage], wc, k=J * wd**2, c=2 * 0.7 * J * wd,
                                         k_i=J * wd**3 / 5))
    scene.add_element(ForceSource("load", rings, np.array(forces), ramp=Ramp(0.0, ramp)))
    pair = PairHandles(RINGS[0][0], RINGS[1][0], RINGS[0][1], RINGS[1][1], *handles)
    # no sun, no meshes: its speed and torque are 0 (nothing reads them without meshes)
    built = scene.build(PlanetBearingScene, pairs=(pair,), bearing=b, lubricant=None, flanks={}, sun_torque=0.0,
                        speeds=Speeds(sun=0.0, inner_planet=RINGS[0][4], outer_planet=RINGS[1][4], carrier=0.0))
    return built, settle


def run(cage_speed=None):
    b = bearing()
    bs, t0 = twin_rig(b, cage_speed)
    stats = WindowStatistics(bs, t0, t0 + cage_period(b, 0.0, W))
    p = mbd.PRODUCTION
    mbd.simulate(bs.model, bs.q0, bs.v0, stats.t_end, stepper=p.stepper(), controller=p.controller(), progress=False,
                 observers=[stats])
    return bs, stats, stats.summary()


@pytest.fixture(scope="module")
def free():
    return run()


@pytest.fixture(scope="module")
def driven():
    return run(DRIVEN)


def closed_form(b, F, w):
    """Zero clearance, pure radial load F, continuous load zone Q = Q_max cos^n ψ (Stribeck): Q_max = F/(Z J_r);
    the pin's equivalent roller load (mean Q^4.5)^(1/4.5) (stationary relative to the load), the bore's
    (mean (Q + F_c)^4)^(1/4) (rotating; every roller presses the bore with its centrifugal force F_c as well),
    and the Lundberg–Palmgren life [(Q_e/Q_c)^4.5 summed]^(−8/9) [10^6 rev] — literal exponents, own integrals."""
    n = b.contact_exponent
    mean = lambda f: quad(f, -math.pi, math.pi, points=[-0.5 * math.pi, 0.5 * math.pi], limit=200)[0] / (2 * math.pi)
    cos = lambda x: max(math.cos(x), 0.0)
    q_max = F / (b.rollers * b.rows * mean(lambda x: cos(x) ** (n + 1)))
    F_c = b.roller_mass * 0.5 * b.pitch_diameter * bearing_kinematics(b, 0.0, w)[0] ** 2
    q_pin = mean(lambda x: (q_max * cos(x) ** n) ** 4.5) ** (1 / 4.5)
    q_bore = mean(lambda x: (q_max * cos(x) ** n + F_c) ** 4) ** 0.25
    qc_pin, qc_bore = raceway_ratings(b)
    life = (b.rows * ((q_pin / qc_pin) ** 4.5 + (q_bore / qc_bore) ** 4.5)) ** (-8 / 9)
    return q_pin, q_bore, life


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_run_level_life_is_the_closed_form_roller_orbit_life(free, kind):
    """Over one cage revolution every roller orbits through the load zone: the summary's equivalent roller
    loads are the closed forms' (pin, exponent 4.5: measured 3.3e-5 at 10 kN, 7.6e-5 at 6 kN; bore, exponent 4
    with the rollers' 1.9 N centrifugal load: 3.0e-5, 6.9e-5; tolerance 2e-4), and so is the life in 10^6
    revolutions and in hours at the ring's speed (measured 1.3e-4, 3.0e-4; tolerance 6e-4). A pin exponent of 4
    instead of 4.5 moves the pin's load by 3.5 % and the life by ≈ 10 %. ISO 281's: the bearing load's
    equivalent is F_r (a constant load; measured 5e-8) and its life (C_r/F_r)^(10/3) (2e-7)."""
    bs, stats, s = free
    b = bs.bearing
    d = s[kind]
    _, _, F, _, w = RINGS[0 if kind == "inner" else 1]
    q_pin, q_bore, life = closed_form(b, F, w)
    assert d["whole_revolutions"] and d["cage_revolutions"] == pytest.approx(1.0, abs=1e-9)
    for target in (d, d["all_rollers"]):          # one bearing of each kind: pair 1's is all of them
        assert target["roller_equivalent_load_pin_N"] == pytest.approx(q_pin, rel=2e-4)
        assert target["roller_equivalent_load_bore_N"] == pytest.approx(q_bore, rel=2e-4)
        assert target["life_iso16281_Mrev"] == pytest.approx(life, rel=6e-4)
        assert target["life_iso16281_h"] == pytest.approx(life * 1e6 * 2 * math.pi / abs(w) / 3600.0, rel=6e-4)
        assert target["life_iso281_Mrev"] == pytest.approx((iso281_rating(b) / F) ** (10 / 3), rel=1e-6)
    assert d["equivalent_load_N"] == pytest.approx(F, rel=1e-6)


@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_roller_load_rms_and_max_over_one_orbit(free, kind):
    """Over one cage revolution a roller passes once through the load zone at a steady speed: its raceway
    loads' time RMS is the orbit's, Q_max (mean cos₊^2n ψ)^(1/2) on the pin and (mean (Q + F_c)²)^(1/2) on the
    bore (pair 1's roller: measured 3.4e-4 at 10 kN, 2.1e-4 at 6 kN — the rollers of one set differ by
    0.2–0.3 % in mean load; tolerance 1e-3; every roller of the bearing pooled: 1.3e-5, 4e-6; tolerance 1e-4),
    its maximum Q_max (+ F_c) of the continuous zone (Z = 12 discrete rollers: measured −2.7e-4; tolerance
    1e-3) and its mean Q_max mean cos₊^n ψ (5.2e-4; tolerance 1e-3)."""
    bs, stats, s = free
    b = bs.bearing
    d = s[kind]
    _, _, F, _, w = RINGS[0 if kind == "inner" else 1]
    n = b.contact_exponent
    mean = lambda f: quad(f, -math.pi, math.pi, points=[-0.5 * math.pi, 0.5 * math.pi], limit=200)[0] / (2 * math.pi)
    cos = lambda x: max(math.cos(x), 0.0)
    q_max = F / (b.rollers * b.rows * mean(lambda x: cos(x) ** (n + 1)))
    F_c = b.roller_mass * 0.5 * b.pitch_diameter * bearing_kinematics(b, 0.0, w)[0] ** 2
    rms = {"inner": q_max * math.sqrt(mean(lambda x: cos(x) ** (2 * n))),
           "outer": math.sqrt(mean(lambda x: (q_max * cos(x) ** n + F_c) ** 2))}
    for race, extra in (("inner", 0.0), ("outer", F_c)):
        assert d[f"roller_{race}_race_rms_N"] == pytest.approx(rms[race], rel=1e-3)
        assert d["all_rollers"][f"roller_{race}_race_rms_N"] == pytest.approx(rms[race], rel=1e-4)
        assert d[f"roller_{race}_race_max_N"] == pytest.approx(q_max + extra, rel=1e-3)
    assert d["roller_inner_race_mean_N"] == pytest.approx(q_max * mean(lambda x: cos(x) ** n), rel=1e-3)


@pytest.mark.parametrize("run_", ["free", "driven"])
def test_pin_reaction_is_the_applied_load(request, run_):
    """The ring, its rollers and its cage get from outside only the applied load, the pin's contact forces and
    torques (drives; the settling dashpot's mean is nil at a standstill): the mean pin reaction is the load,
    vector for vector (measured ≤ 1.1e-7 F with free cages; ≤ 3.7e-6 F with driven cages, whose sliding
    rollers put tractions of up to 4.5 % of their loads on the pin; tolerance 1e-5 F). In the carrier's
    radial/tangential axes it is F (cos β, sin β) up to the turn of the ring's centre, displaced by its
    deflection along the load off the nominal radial line (measured ≤ 5.7e-5 F; tolerance 1e-4 F)."""
    bs, stats, s = request.getfixturevalue(run_)
    for i, (name, psi, F, beta, w) in enumerate(RINGS):
        d = s["inner" if i == 0 else "outer"]
        load = F * np.array([math.cos(psi + beta), math.sin(psi + beta)])
        pin = np.array([stats.stats("load_x")["mean"][i], stats.stats("load_y")["mean"][i]])
        np.testing.assert_allclose(pin, load, atol=1e-5 * F)
        assert d["bearing_load_mean_N"] == pytest.approx(F, rel=1e-5)
        assert d["bearing_load_radial_mean_N"] == pytest.approx(F * math.cos(beta), abs=1e-4 * F)
        assert d["bearing_load_tangential_mean_N"] == pytest.approx(F * math.sin(beta), abs=1e-4 * F)


def test_free_cage_turns_at_the_epicyclic_speed(free):
    """Free cages without drag (the rollers roll: nothing but the guide's friction holds them back): the cage
    closes its revolution after 2π/ω_m, ω_m = bearing_kinematics(pin 0, ring ±300 rad/s) (measured 2e-15;
    tolerance 1e-6), and the slip is nil (measured < 1e-5 %; tolerance 1e-4 %)."""
    bs, stats, s = free
    b = bs.bearing
    for kind, (_, _, _, _, w) in zip(("inner", "outer"), RINGS):
        d = s[kind]
        w_m = bearing_kinematics(b, 0.0, w)[0]
        assert d["window_s"][1] - d["window_s"][0] == pytest.approx(2 * math.pi / abs(w_m), rel=1e-6)
        assert abs(d["cage_slip_pct"]) < 1e-4


def test_a_cage_held_at_a_known_speed_slips_by_what_it_lags(driven):
    """Cages driven at 0.97 and 1.02 × the epicyclic speed ω_m = bearing_kinematics(pin, ring) while the rings
    are held at ±300 rad/s: cage_slip_pct = 100 (1 − ω_cage/ω_m) = +3 % and −2 % (measured 2.9932 and
    −1.9976 %: the drives hold the mean speeds to ≈ 7e-5; tolerance 0.02 points). Inverted (ω_m/ω_cage) it
    would read −3.09 % and +1.96 %."""
    bs, stats, s = driven
    for kind, f in zip(("inner", "outer"), DRIVEN):
        d = s[kind]
        assert d["cage_slip_pct"] == pytest.approx(100 * (1 - f), abs=0.02)
        assert d["whole_revolutions"] and d["cage_revolutions"] == pytest.approx(1.0, abs=1e-9)
