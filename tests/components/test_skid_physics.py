"""The opt-in skid physics in motion (docs/model.md §8.7, §9.5): on the bearing rig, a roller free of its raceways
spins down under the viscous churning moment alone as its closed form ω₀e^(−t/τ), τ = J/(π η_e D² l); in a
two-body model, a roller pressed with a known load onto a turning ring and braked by a known moment settles at the
slip the traction curve gives for that moment (tanh law: v_s = v₀ artanh(M/(r μ_max Q))), and, with the rolling
resistance on, at the slip of that moment plus the rolling resistance's own; a loaded, turning rig with both laws
runs alike on the compiled and numpy engines.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

import mbd
from components.bearing import mixture
from components.presets import reference_bearing, reference_dpgt
from components.rig import build_bearing_rig
from components.scene import SceneOptions
from mbd.elements import ForceSource, GroundSupport, SpeedDrive, TorqueSource
from mbd.elements.contact import HoupertRolling, RaceContact, TanhTraction

SETTINGS = mbd.PRODUCTION


def _integrate(model, q0, v0, t_end):
    return mbd.simulate(model, q0, v0, t_end, stepper=SETTINGS.stepper(),
                        controller=mbd.Adaptive(h0=1e-6, h_max=1e-4), progress=False)


def test_roller_spins_down_under_the_churning_moment_alone():
    """Rig without load, speed or cage: each roller sits centred in its 5 µm radial gaps, touching nothing, and
    spins down under M = −π η_e D² l ω. A thick mixture (η_e = 0.5 Pa·s) makes τ ≈ 28 ms."""
    b = reference_bearing().replace(drag_law="viscous").si()
    lub = reference_dpgt().lubricant.replace(oil_viscosity="0.5 Pa*s", oil_fraction=1.0).si()
    built = build_bearing_rig(b, radial_load=0.0, outer_speed=0.0, lubricant=lub,
                              options=SceneOptions(cage="none", drag=True))
    m = built.model
    rollers = built.bearing_handles.rollers
    spin = np.array([m.full_to_free[3 * m.body(r).index + 2] for r in rollers])
    omega0 = np.linspace(-600.0, 900.0, len(rollers))
    v0 = built.v0.copy()
    v0[spin] = omega0
    _, eta_e = mixture(lub)
    assert eta_e == pytest.approx(0.5, rel=1e-12)
    J = b.roller_inertia * b.rows
    tau = J / (np.pi * eta_e * b.roller_diameter ** 2 * b.roller_length * b.rows)
    assert 0.02 < tau < 0.04
    t_end = 0.03
    res = _integrate(m, built.q0, v0, t_end)
    np.testing.assert_allclose(res.state.v[spin], omega0 * np.exp(-t_end / tau), rtol=1e-4, atol=1e-9)
    # nothing else moved: no contact was made
    others = np.setdiff1d(np.arange(m.ndof), spin)
    assert np.abs(res.state.v[others]).max() < 1e-9


D, L, DENS = 7.5e-3, 9e-3, 7850.0
M_R = DENS * np.pi * D ** 2 / 4 * L
J_R = M_R * D ** 2 / 8
R_RING = 23.76e-3                      # the outer raceway's radius
K, P = 1.22e9, 10.0 / 9.0
TANH = TanhTraction(mu_max=0.08, v0=0.3)
ROLL = HoupertRolling(eta0=0.025, E_red=2.31e11, length=L, u_reg=0.1)


def _held_roller(Q, omega_ring, moment, rolling=None):
    """Ring (outer raceway, centre held at the origin, turned at omega_ring by a stiff speed drive) and a roller on
    its +x side pressed outwards with the force Q, held tangentially by a stiff ground spring, braked by the
    constant moment ``moment`` (against its spin). Returns the model, its start state and the roller's ρ."""
    delta = (Q / K) ** (1.0 / P)
    rho = R_RING - D / 2 + delta
    b = mbd.ModelBuilder()
    ring = b.add_body("ring", 1.0, 1e-3)
    roller = b.add_body("roller", M_R, J_R, pose=(rho, 0.0, 0.0))
    b.add(GroundSupport("ring_centre", [ring.index], kx=1e9, cx=1e3))
    b.add(SpeedDrive("ring_drive", ring.index, omega_ring, k=1e4, c=50.0))
    b.add(GroundSupport("roller_y", [roller.index], kx=0.0, cx=0.0, ky=1e8, cy=50.0, anchor=(rho, 0.0)))
    b.add(ForceSource("press", [roller.index], np.array([Q, 0.0])))
    b.add(TorqueSource("brake", [roller.index], -moment * np.sign(omega_ring)))
    b.add(RaceContact("race", [roller.index], ring.index, kind="outer", race_marker=(0.0, 0.0), R_race=R_RING, D=D,
                      K=K, exponent=P, zeta=0.05, m_roller=M_R, traction=TANH, rolling=rolling))
    m = b.build()
    w_free = omega_ring * R_RING / (R_RING - rho)      # pure rolling on the ring
    q0 = np.array([0.0, 0.0, 0.0, rho, 0.0, 0.0])
    v0 = np.array([0.0, 0.0, omega_ring, 0.0, 0.0, w_free])
    return m, q0, v0, rho


@pytest.mark.parametrize("moment", [2e-3, 1.5e-2])
def test_roller_settles_at_the_slip_the_traction_curve_gives(moment):
    """Q = 100 N, ring at 200 rad/s: the roller's spin settles where traction × lever balances the brake, μ(v_s)Q
    (R − ρ) = M; the tanh law inverts in closed form, v_s = v₀ artanh(M/((R − ρ) μ_max Q))."""
    Q, w = 100.0, 200.0
    m, q0, v0, rho = _held_roller(Q, w, moment)
    res = _integrate(m, q0, v0, 0.01)
    q, v = res.state.q, res.state.v
    lever = R_RING - (q[3] - q[0])                     # the contact point from the roller centre (ring centre at q[0:2])
    vs = v[5] * lever - v[2] * R_RING                  # roller surface minus ring surface at P (along t = +y)
    expected = -TANH.v0 * np.arctanh(moment / (lever * TANH.mu_max * Q))    # braked: the roller lags the ring
    assert vs == pytest.approx(expected, rel=1e-5)
    assert abs(q[3] - q[0] - rho) < 1e-10              # Q held: the roller at its Hertz deflection


def test_rolling_resistance_adds_its_moment_to_the_brake():
    """With the rolling resistance on, the settled traction balances the brake plus the film's rolling moment
    (ρ − R)F_R at the settled rolling speed: μ(v_s)Q(R − ρ) = M + (R − ρ)F_R — the slip the curve gives for the sum."""
    Q, w, moment = 100.0, 200.0, 2e-3
    m, q0, v0, rho = _held_roller(Q, w, moment, rolling=ROLL)
    res = _integrate(m, q0, v0, 0.01)
    q, v = res.state.q, res.state.v
    lever = R_RING - (q[3] - q[0])
    vs = v[5] * lever - v[2] * R_RING
    u_e = 0.5 * (v[5] * lever + v[2] * R_RING)         # contact point at rest: the surfaces' mean speed
    R_red = 1.0 / (2.0 / D - 1.0 / R_RING)
    F_R = ROLL.force(np.array([Q]), np.array([u_e]), R_red)[0]
    assert F_R > 0.3                                   # a real share of the brake: (R − ρ)F_R ≈ 1.2 M (M ≈ 0.7: IVR–EHL)
    # the roller's moment balance about its centre: traction, rolling resistance and brake
    expected = -brentq(lambda x: TANH.mu_max * np.tanh(x / TANH.v0) * Q * lever - moment - lever * F_R, 0.0, 1.0)
    assert vs == pytest.approx(expected, rel=1e-5)
    plain = _integrate(*_held_roller(Q, w, moment)[:3], 0.01).state
    p_lever = R_RING - (plain.q[3] - plain.q[0])
    assert abs(vs) > abs(plain.v[5] * p_lever - plain.v[2] * R_RING)   # more slip than the brake alone gives


@pytest.mark.parametrize("pocket", ["dry", "hydrodynamic"])
def test_the_engines_run_the_skid_physics_alike(pocket):
    """A loaded, turning rig with the opt-in laws (the viscous drag with the cage's, the rolling resistance; dry or
    oiled pockets), 1000 fixed steps: the compiled and numpy engines reach the same
    state to round-off. (With adaptive steps an accept/reject decision at the edge of the error bound can go either
    way on an ulp, after which the runs differ by the controller's tolerance, not by round-off: fixed steps compare
    the laws, not the controller's coin flips.)"""
    ref = reference_bearing()
    b = ref.replace(drag_law="viscous", rolling_resistance="houpert",
                    cage=ref.cage.replace(pocket_law=pocket)).si()
    lub = reference_dpgt().lubricant.replace(temperature="40 degC").si()
    built = build_bearing_rig(b, radial_load=2000.0, outer_speed=300.0, lubricant=lub,
                              options=SceneOptions(cage="free", drag=True))
    kw = dict(stepper=SETTINGS.stepper(), controller=mbd.FixedStep(2e-6), progress=False)
    c = mbd.simulate(built.model, built.q0, built.v0, 0.002, engine="compiled", **kw)
    r = mbd.simulate(built.model, built.q0, built.v0, 0.002, engine="numpy", **kw)
    assert c.engine == "compiled" and r.engine == "numpy"
    assert c.counters == r.counters
    tol = SETTINGS.stepper().tol.scale(built.model, None, None)
    assert np.all(np.abs(c.state.q - r.state.q) <= 1e-6 * tol)          # seen: 1e-13 of it
    np.testing.assert_allclose(c.state.v, r.state.v, rtol=0, atol=1e-12 * np.abs(r.state.v).max())


def test_the_scenes_build_the_oiled_pocket_and_the_cage_drag_when_asked():
    """The default machine has neither family; bearing.drag_law = "viscous" adds the mixture's moment on each free
    cage (Cochran's disk over the faces from the pin's raceway to the bore, with the mixture's ρ_e, η_e), and
    bearing.cage.pocket_law = "hydrodynamic" a film per pocket in the oil's own viscosity; without oil it is refused."""
    from components.bearing import cage_faces
    from components.dpgt import build_dpgt
    from components.families import FAMILY
    from components.units import ParameterError
    from mbd.elements.pocket_film import CageDrag
    from components.params import with_overrides
    names = lambda sc: {e.name for e in sc.model.elements}  # noqa: E731
    base = reference_dpgt(3)
    assert not {FAMILY["pocket_film"], FAMILY["cage_drag"]} & names(build_dpgt(base))
    p = with_overrides(base, {"bearing.drag_law": "viscous", "bearing.cage.pocket_law": "hydrodynamic"})
    sc = build_dpgt(p)
    si = p.si()
    film, drag = sc.model.element(FAMILY["pocket_film"]), sc.model.element(FAMILY["cage_drag"])
    assert film.n == sc.model.element(FAMILY["pocket"]).n
    assert np.all(film.eta == si.lubricant.oil_viscosity) and np.all(film.clearance == si.bearing.cage.pocket_clearance)
    rho_e, eta_e = mixture(si.lubricant)
    ri, ro = cage_faces(si.bearing)
    assert (ri, ro) == ((si.bearing.pitch_diameter - si.bearing.roller_diameter) / 2,
                        (si.bearing.pitch_diameter + si.bearing.roller_diameter) / 2)
    np.testing.assert_allclose(drag.coef, 0.616 * np.pi * np.sqrt(rho_e * eta_e) * (ro ** 4 - ri ** 4), rtol=1e-12)
    assert isinstance(drag, CageDrag) and drag.n == sc.model.element(FAMILY["guide"]).n      # one per free cage
    b = reference_bearing().replace(cage=reference_bearing().cage.replace(pocket_law="hydrodynamic")).si()
    with pytest.raises(ParameterError, match=r"^bearing\.cage\.pocket_law"):
        build_bearing_rig(b, radial_load=2000.0, outer_speed=300.0, lubricant=None,
                          options=SceneOptions(cage="free", drag=False))


def test_the_pocket_brake_of_a_centred_spinning_roller_is_both_walls_shear():
    """components.pocket_brake at the oiled rig's start (rollers centred in their pockets, orbiting with the cage, spinning
    at Δω in it): each roller is braked by −M of both walls, M = 2R²ηl|Δω|√(2R/C_p)(π/2 + γ_e + c_P/2)
    (docs/model.md §8.5), the solid contact open; the dry pockets brake nothing there."""
    from components.pocket_brake import pocket_brake
    ref = reference_bearing()
    lub = reference_dpgt().lubricant.replace(temperature="40 degC").si()
    for law in ("hydrodynamic", "dry"):
        b = ref.replace(cage=ref.cage.replace(pocket_law=law)).si()
        built = build_bearing_rig(b, radial_load=2000.0, outer_speed=300.0, lubricant=lub,
                                  options=SceneOptions(cage="free", drag=True))
        m = built.model
        qf, vf = m.full(0.0, built.q0, built.v0)
        brake, touch = pocket_brake(m, 0.0, qf, vf)
        assert not touch.any()
        R, dw = b.roller_diameter / 2, abs(built.bearing_handles.omega_roller - built.bearing_handles.omega_cage)
        M = 2 * R ** 2 * lub.oil_viscosity * b.roller_length * dw * np.sqrt(2 * R / b.cage.pocket_clearance) \
            * (np.pi / 2 + 0.443554 + 3.25345 / 2)
        np.testing.assert_allclose(brake, M if law == "hydrodynamic" else 0.0, rtol=1e-5, atol=1e-15)


def test_the_scenes_build_the_raceway_squeeze_film_when_asked():
    """The default machine has no raceway film; bearing.race_film = "squeeze" adds one per roller on the pin and one
    in the bore, with the oil's own viscosity at its temperature, the roller's length and diameter, the raceways'
    radii and the floor in metres (so the reduced radii are the convex pin's and the concave bore's); the sliced
    model and a scene without oil are refused, naming the parameter."""
    from components.dpgt import build_dpgt
    from components.families import FAMILY
    from components.params import with_overrides
    from components.units import ParameterError
    from mbd.elements.race_film import RaceFilm
    names = lambda sc: {e.name for e in sc.model.elements}  # noqa: E731
    base = reference_dpgt(3)
    assert not {FAMILY["race_film_inner"], FAMILY["race_film_outer"]} & names(build_dpgt(base))
    p = with_overrides(base, {"bearing.race_film": "squeeze", "bearing.race_film_floor": "0.7 um"})
    sc = build_dpgt(p)
    si, b = p.si(), p.si().bearing
    for key, R_race, kap in (("inner", b.inner_raceway_radius, 1.0), ("outer", b.outer_raceway_radius, -1.0)):
        film, race = sc.model.element(FAMILY[f"race_film_{key}"]), sc.model.element(FAMILY[f"race_{key}"])
        assert isinstance(film, RaceFilm) and film.n == race.n == 6 * 12
        np.testing.assert_array_equal(film.dofs, race.dofs)             # the same roller and race body, in order
        np.testing.assert_array_equal(film.race_marker, race.race_marker)
        assert np.all(film.eta == si.lubricant.oil_viscosity) and np.all(film.floor == 7e-7)
        assert np.all(film.length == b.roller_length) and np.all(film.R_race == R_race)
        np.testing.assert_allclose(film.R_red, 1.0 / (2.0 / b.roller_diameter + kap / R_race), rtol=1e-15)
    sliced = with_overrides(p, {"bearing.model": "sliced"})
    with pytest.raises(ParameterError, match=r"^bearing\.race_film"):
        build_dpgt(sliced)
    rb = reference_bearing().replace(race_film="squeeze").si()
    with pytest.raises(ParameterError, match=r"^bearing\.race_film"):
        build_bearing_rig(rb, radial_load=2000.0, outer_speed=300.0, lubricant=None,
                          options=SceneOptions(cage="free", drag=False))
