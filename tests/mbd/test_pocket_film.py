"""The oil film of a roller in its cage pocket (PocketFilm) and the cage's drag in the mixture (CageDrag),
docs/model.md §8.5 and §8.7: the closed forms' constants against a numerical solution of Reynolds' equation (quadrature,
not the closed forms) and against Martin's published film (h_min/R = 4.9 U/W', x_e = 0.475 √(2Rh)), the element's
loads and shears against those forms for known gaps and speeds, the squeeze film's time to close a gap, zero speed
and open-gap limits, exact Jacobians, balance, and the compiled twins against the numpy reference.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from mbd.element import evaluate
from mbd.elements import pocket_film as pf
from mbd.elements.pocket_film import CageDrag, PocketFilm
from mbd.errors import ModelError

from tests.support.contact import (C_P, DM, DR, FS, LR, N, SETTINGS, Z, assert_balanced, assert_jacobians,
                                   assert_matches_reference, floats, pocket_scene)
from tests.support.strategies import frame_states

ETA, H_MIN = 0.08, 1e-6           # Pa·s (a VG 220 gear oil near 50 °C), m
R = DR / 2


def film_scene(pose, vel, pockets, offsets, radial, v_circ, v_rad, spins, eta=ETA, min_film=H_MIN, multiplicity=1):
    """The pocket scene of tests.support.contact (body 0 the cage, bodies 1..n rollers) with the film family."""
    qf, vf, pocket, psi = pocket_scene(pose, vel, pockets, offsets, radial, v_circ, v_rad, spins)
    elem = PocketFilm("pocket_film", np.arange(1, len(pockets) + 1), 0, pocket_angle=psi, pitch_radius=DM / 2,
                      clearance=C_P, D=DR, length=LR, eta=eta, min_film=min_film, multiplicity=multiplicity)
    return qf, vf, elem


@st.composite
def film_states(draw):
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    pose = (0.08 + draw(floats(-2e-4, 2e-4)), 0.02 + draw(floats(-2e-4, 2e-4)), draw(floats(-np.pi, np.pi)))
    vel = (draw(floats(-20, 20)), draw(floats(-20, 20)), draw(floats(-300, 300)))
    pockets = lst(st.integers(0, Z - 1))
    # inside the pocket, near a wall, within the thinnest film and beyond the clearance (solid contact)
    offsets = lst(st.one_of(floats(-0.97 * C_P, 0.97 * C_P), floats(C_P - 5e-7, C_P + 2e-5),
                            floats(-C_P - 2e-5, -C_P + 5e-7)))
    radial = lst(floats(-2e-4, 2e-4))
    # the squeeze film's max(V, 0) has a kink at V = 0 where a difference quotient is O(step) off: a roller
    # moving with its pocket (V = 0 up to round-off) is the deterministic test below
    v_circ = lst(st.one_of(floats(-0.05, -1e-4), floats(1e-4, 0.05)))
    v_rad = lst(floats(-0.5, 0.5))
    # the wedge load's |ũ| has its kink at ũ = 0 (the same): the roller turns relative to its cage
    spins = [vel[2] + r for r in lst(st.one_of(floats(-3000, -1.0), floats(1.0, 3000)))]
    return pose, vel, pockets, offsets, radial, v_circ, v_rad, spins


# ------------------------------------------------------------------------- the constants, from Reynolds' equation
def _reynolds_rolling():
    """A rigid cylinder rolling on a plane, solved by quadrature of Reynolds' equation in x/√(2Rh): dp/dX ∝ (H − H_e)/H³
    with H = 1 + X², the outlet X_e from p(−∞) = p(X_e) = 0 by root finding; load, Poiseuille shear and the film's
    extent ∫dX/H as integrals of that pressure (no closed form used)."""
    def closing(Xe):
        He = 1.0 + Xe * Xe
        return quad(lambda X: (1.0 + X * X - He) / (1.0 + X * X) ** 3, -np.inf, Xe)[0]
    Xe = brentq(closing, 0.1, 1.0, xtol=1e-14)
    He = 1.0 + Xe * Xe
    P = lambda X: -quad(lambda u: (1.0 + u * u - He) / (1.0 + u * u) ** 3, X, Xe, epsabs=1e-13)[0]  # noqa: E731
    # p = 12 η ũ (2R/h)·(1/(2R))·√(2Rh)… in units: p = 12ηũ√(2Rh)/h² P(X); w = ∫p dx = 12ηũ(2R/h) ∫P dX
    load = 24.0 * quad(P, -np.inf, Xe, epsabs=1e-13)[0]                 # per η ũ R l / h
    poise = 6.0 * quad(lambda X: (1.0 + X * X - He) / (1.0 + X * X) ** 2, -np.inf, Xe)[0]   # per η ũ l √(2R/h)
    extent = quad(lambda X: 1.0 / (1.0 + X * X), -np.inf, Xe)[0]        # ∫dx/h per √(2R/h)
    return Xe, load, poise, extent


def test_constants_solve_reynolds_equation_and_match_martin():
    Xe, load, poise, extent = _reynolds_rolling()
    assert np.tan(pf.OUTLET_ANGLE) == pytest.approx(Xe, rel=1e-9)
    assert pf.WEDGE_LOAD == pytest.approx(load, rel=1e-7)
    assert pf.POISEUILLE_SHEAR == pytest.approx(poise, rel=1e-7)
    assert pf.COUETTE_EXTENT == pytest.approx(extent, rel=1e-9)
    # published: Martin's rigid-isoviscous film h_min/R = 4.9 U/W' (Hamrock et al.), outlet at 0.475 √(2Rh)
    assert pf.WEDGE_LOAD == pytest.approx(4.9, abs=0.006)
    assert Xe == pytest.approx(0.475, abs=5e-4)


def test_squeeze_constant_solves_reynolds_equation():
    """d/dx(h³ dp/dx) = 12 η dh/dt with h = h₀ + x²/(2R), p(±∞) = 0: the load of a cylinder approaching at V, by
    quadrature (in X = x/√(2Rh₀): p = 12ηV R/h₀² ∫_X^∞ u/(1+u²)³ du·…)."""
    h0, V = 3e-6, 0.02
    p = lambda x: 12.0 * ETA * V * quad(lambda u: u / (h0 + u * u / (2 * R)) ** 3, x, np.inf)[0]  # noqa: E731
    w = 2.0 * quad(p, 0.0, np.inf, limit=200)[0]
    assert pf.SQUEEZE_LOAD * ETA * V * (R / h0) ** 1.5 == pytest.approx(w, rel=1e-7)
    assert pf.SQUEEZE_LOAD == pytest.approx(3.0 * np.sqrt(2.0) * np.pi, rel=1e-15)


# ------------------------------------------------------------------------------ the element's loads and shears
def _one(offset, spin, cage_spin=0.0, v_circ=0.0, v_rad=0.0, **kw):
    qf, vf, elem = film_scene((0.0, 0.0, 0.0), (0.0, 0.0, cage_spin), [0], [offset], [0.0], [v_circ], [v_rad],
                              [spin + cage_spin], **kw)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    return F[0], {k: v[0] for k, v in out.items()}


def martin(u, h):
    """Martin's load with the published constant (4.896 of Hamrock et al.'s rigid-isoviscous film) [N]."""
    return 4.896 * ETA * abs(u) * R * LR / h


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_wedge_load_of_a_spinning_roller_is_martins(side):
    """A roller spinning in a still cage (Δω), its centre at rest in the pocket at gap h from one wall: each wall
    carries Martin's load at its own gap with ũ = ∓R Δω/2; the nearer pushes the roller back."""
    h, dw = 4e-6, 600.0
    F, out = _one(side * (C_P - h), dw)
    u = 0.5 * R * dw                             # the roller surface's speed over 2
    expected = side * (martin(u, h) - martin(u, 2 * C_P - h))
    assert out["force"] == pytest.approx(expected, rel=2e-3)
    # along the pitch circle the roller is pushed back with the load (its centre on the pitch circle)
    beta = side * (C_P - h) / (DM / 2)
    t = np.array([-np.sin(beta), np.cos(beta)])
    assert F[:2] @ t == pytest.approx(-out["force"], rel=1e-9)
    assert out["gap"] == pytest.approx(h, rel=1e-9)


def test_spinning_roller_is_braked_by_both_walls_shear():
    """A centred roller spinning at Δω in a still cage: no net load or force, the moment of both walls' Couette and
    Poiseuille shear −2 R² η l Δω √(2R/C_p)(2.0144 + 3.2535/2), the opposite on the cage."""
    dw = 800.0
    F, out = _one(0.0, dw)
    M = -2.0 * R ** 2 * ETA * LR * dw * np.sqrt(2 * R / C_P) * (2.0144 + 3.2535 / 2)
    assert F[2] == pytest.approx(M, rel=1e-4)
    assert F[5] == pytest.approx(-M, rel=1e-4)
    assert abs(out["force"]) <= 1e-12 * abs(M) / R and np.all(np.abs(F[[0, 1, 3, 4]]) <= 1e-12 * abs(M) / R)


def test_couette_shear_of_a_roller_sliding_along_the_wall():
    """A roller not spinning, its centre sliding radially at v in the cage, centred: each wall shears it with
    −η l v √(2R/h)·2.0144 (Couette) and pushes it along with 3.2535 η l (v/2) √(2R/h) (the wall, still, is entrained
    at −v/2 relative to the contact point: the Poiseuille force on the roller is along −v/2·(−1)… summed below)."""
    v = 0.3
    F, out = _one(0.0, 0.0, v_rad=v)
    per_wall = ETA * LR * np.sqrt(2 * R / C_P) * (-2.0144 * v + 3.2535 * (-0.5 * v))
    assert out["shear"] == pytest.approx(2 * per_wall, rel=1e-4)
    assert F[0] == pytest.approx(2 * per_wall, rel=1e-4)     # e_r = +x at the pocket ψ = 0
    assert F[3] == pytest.approx(-2 * per_wall, rel=1e-4)


def test_squeeze_film_closes_a_gap_in_the_closed_form_time():
    """A constant load W pushes a non-spinning roller at its pocket wall: the squeeze film lets the gap close as
    dh/dt = −W h^(3/2)/(3√2π η l R^(3/2)), so from h₁ to h₂ it takes 2·3√2π η l R^(3/2)(h₂^(−1/2) − h₁^(−1/2))/W.
    Integrated with the element's own force (the far wall opens and carries nothing)."""
    W, h1, h2 = 5.0, 40e-6, 4e-6

    def rate(t, y):
        _, out = _one(C_P - y[0], 0.0, v_circ=1.0)              # approach at 1 m/s: the force per unit speed
        return [-W / out["force"]]
    ev = lambda t, y: y[0] - h2  # noqa: E731
    ev.terminal = True
    sol = solve_ivp(rate, (0.0, 1.0), [h1], events=ev, rtol=1e-10, atol=1e-15)
    t_closed = 2.0 * 3.0 * np.sqrt(2.0) * np.pi * ETA * LR * R ** 1.5 * (h2 ** -0.5 - h1 ** -0.5) / W
    assert sol.t_events[0][0] == pytest.approx(t_closed, rel=1e-6)


def test_limits_at_rest_on_separation_and_far_from_the_walls():
    F, out = _one(0.4 * C_P, 0.0)                                   # at rest: nothing
    assert np.all(F == 0.0) and out["force"] == 0.0
    F, out = _one(C_P - 3e-6, 0.0, v_circ=-0.2)                     # leaving the wall: the film cavitates
    _, out_app = _one(C_P - 3e-6, 0.0, v_circ=0.2)
    assert out["force"] == pytest.approx(-pf.SQUEEZE_LOAD * ETA * LR * 0.2 * (R / (2 * C_P - 3e-6)) ** 1.5,
                                         rel=1e-9)                  # only the far wall, approached
    assert out_app["force"] == pytest.approx(pf.SQUEEZE_LOAD * ETA * LR * 0.2 * (R / 3e-6) ** 1.5, rel=1e-9)
    # the loads fall as 1/h: a pocket ten times wider carries a tenth at the same offset ratio
    _, o1 = _one(0.5 * C_P, 500.0)
    qf, vf, _ = film_scene((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), [0], [0.5 * C_P], [0.0], [0.0], [0.0], [500.0])
    wide = PocketFilm("w", [1], 0, pocket_angle=0.0, pitch_radius=DM / 2, clearance=10 * C_P, D=DR, length=LR,
                      eta=ETA, min_film=H_MIN)
    qf[3:5] = [(DM / 2) * np.cos(5 * C_P / (DM / 2)), (DM / 2) * np.sin(5 * C_P / (DM / 2))]
    _, o10, _, _ = evaluate(wide, 0.0, FS, qf, vf, None, False)
    assert o10["force"][0] == pytest.approx(o1["force"] / 10, rel=1e-6)


def test_thinnest_film_holds_the_load_continuous():
    """Below h_min the film is taken at h_min: the load is continuous there and constant beyond."""
    dw = 700.0

    def near(s):                    # the near wall's load: the total and the far wall's (at 2 C_p − h) back
        _, out = _one(s, dw)
        return out["force"] + pf.WEDGE_LOAD * ETA * (0.5 * R * dw) * R * LR / (C_P + s), out["gap"]
    at, _ = near(C_P - H_MIN)
    past, _ = near(C_P - 0.2 * H_MIN)
    touch, gap = near(C_P + 1e-5)
    assert past == pytest.approx(at, rel=1e-12) and touch == pytest.approx(at, rel=1e-12)
    assert at == pytest.approx(martin(0.5 * R * dw, H_MIN), rel=2e-3)
    assert gap < 0


def test_clearance_must_exceed_the_thinnest_film():
    with pytest.raises(ModelError, match="clearance"):
        PocketFilm("f", [1], 0, pocket_angle=0.0, pitch_radius=DM / 2, clearance=1e-6, D=DR, length=LR, eta=ETA,
                   min_film=1e-6)


@pytest.mark.parametrize("name, factor", [("WEDGE_LOAD", 2.0), ("POISEUILLE_SHEAR", -1.0), ("COUETTE_EXTENT", 2.0)])
def test_a_planted_error_is_caught(monkeypatch, name, factor):
    """The closed-form checks above fail if a constant's factor or sign is wrong (the kernel reads the module's)."""
    monkeypatch.setattr(pf, name, getattr(pf, name) * factor)
    with pytest.raises(AssertionError):
        test_wedge_load_of_a_spinning_roller_is_martins(1.0)
        test_spinning_roller_is_braked_by_both_walls_shear()
        test_couette_shear_of_a_roller_sliding_along_the_wall()


# ------------------------------------------------------------------------------ Jacobians, balance, compiled
@SETTINGS
@given(state=film_states(), mult=st.sampled_from([1, 2]))
def test_film_jacobian_and_balance(state, mult):
    qf, vf, elem = film_scene(*state, multiplicity=mult)
    assert_jacobians(elem, qf, vf)
    assert_balanced(elem, qf, vf)


def test_film_jacobian_at_rest_in_a_centred_pocket():
    """At V = 0 exactly both walls' max(V, 0) take the slope 1/2: the centred roller's two walls sum to the smooth
    law they form there (the difference quotient's)."""
    qf, vf, elem = film_scene((0.08, 0.02, 0.0), (0.0, 0.0, 0.0), [0, 3], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0],
                              [0.0, 0.0], [0.0, 0.0])
    _, _, _, Jv = evaluate(elem, 0.0, FS, qf, vf, None, True)
    c = 2 * 0.5 * pf.SQUEEZE_LOAD * ETA * LR * (R / C_P) ** 1.5      # both walls, slope 1/2 each
    assert np.abs(Jv[0, :2, :2]).max() == pytest.approx(c, rel=1e-9)
    assert_jacobians(elem, qf, vf)


@SETTINGS
@given(state=film_states(), fs=frame_states(), mult=st.sampled_from([1, 2]))
def test_film_compiled_matches_reference(state, fs, mult):
    qf, vf, elem = film_scene(*state, multiplicity=mult)
    assert_matches_reference(elem, fs, qf, vf)


def cage_drag_scene(spins, carrier_spin):
    n = len(spins)
    qf, vf = np.zeros(3 * (n + 1)), np.zeros(3 * (n + 1))
    vf[2] = carrier_spin
    vf[5::3] = spins
    coef = CageDrag.coefficient(60.0, 0.01, (DM - DR) / 2, (DM + DR) / 2)
    return qf, vf, CageDrag("cage_drag", np.arange(1, n + 1), 0, coef=coef), coef


def test_cage_drag_is_cochrans_free_disk_moment():
    """Both faces of an annulus: 0.616 π ρ √ν (r_o⁴ − r_i⁴) ω^(3/2) (Schlichting: 2M = 0.616πρR⁴√(νω³) of a
    disk wetted on both sides, C_M = 3.87/√Re)."""
    qf, vf, elem, coef = cage_drag_scene([150.0, -40.0, 100.0], 100.0)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    rho, eta, ri, ro = 60.0, 0.01, (DM - DR) / 2, (DM + DR) / 2
    for k, dw in enumerate([50.0, -140.0, 0.0]):
        M = -np.sign(dw) * 0.616 * np.pi * rho * np.sqrt(eta / rho) * (ro ** 4 - ri ** 4) * abs(dw) ** 1.5
        assert F[k, 2] == pytest.approx(M, rel=1e-12, abs=0.0) and F[k, 5] == -F[k, 2]
    # a full disk (r_i = 0, both faces) against Schlichting's moment coefficient C_M = M/(ρω²R⁵/2) = 3.87/√Re,
    # Re = R²ω/ν, and against von Kármán's wall shear τ = ρ r ω^(3/2) ν^(1/2) G'(0), G'(0) = −0.6159 (Cochran),
    # integrated over both faces: 2·∫ r τ 2πr dr = π ρ R⁴ √(ν ω³)·0.6159
    Rd, w = 0.02, 30.0
    M = CageDrag.coefficient(rho, eta, 0.0, Rd) * w ** 1.5
    assert M / (0.5 * rho * w ** 2 * Rd ** 5) == pytest.approx(3.87 / np.sqrt(Rd ** 2 * w * rho / eta), rel=1e-3)
    assert M == pytest.approx(np.pi * rho * Rd ** 4 * np.sqrt(eta / rho * w ** 3) * 0.6159, rel=1e-3)


def test_cage_drag_jacobian_and_compiled():
    qf, vf, elem, _ = cage_drag_scene([150.0, -40.0, 100.3], 100.0)
    assert_jacobians(elem, qf, vf)
    assert_balanced(elem, qf, vf)
    for fs in (FS,):
        assert_matches_reference(elem, fs, qf, vf)


# ------------------------------------------------------------------------------ a roller in an oiled pocket
@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_spinning_roller_pushed_at_its_wall_settles_at_martins_gap(engine):
    """A roller held at Δω = 600 rad/s (a speed drive) in a fixed cage's pocket, its centre held radially (a
    support along x), pushed by a constant 1 N along the pitch circle: it settles where the two walls' wedge loads
    carry the push, F = 4.896 η (RΔω/2) R l [1/h − 1/(2C_p − h)] (Martin's published constant, solved for h
    here), the squeeze film damping the approach."""
    import mbd
    from mbd.elements import ForceSource, GroundSupport, SpeedDrive
    F, dw, rm = 1.0, 600.0, DM / 2
    h = brentq(lambda h: 4.896 * ETA * (0.5 * R * dw) * R * LR * (1 / h - 1 / (2 * C_P - h)) - F, 1e-7, C_P)
    mb = mbd.ModelBuilder()
    cage = mb.add_body("cage", 0.04, 1.5e-5, fixed=True)
    m_r = 7800 * np.pi * R ** 2 * LR
    roller = mb.add_body("roller", m_r, m_r * R ** 2 / 2, pose=(rm, 0.0, 0.0))
    mb.add(PocketFilm("pocket_film", [roller.index], cage.index, pocket_angle=0.0, pitch_radius=rm, clearance=C_P,
                      D=DR, length=LR, eta=ETA, min_film=H_MIN))
    mb.add(GroundSupport("radial", [roller.index], kx=1e7, cx=50.0, ky=0.0, cy=0.0, anchor=(rm, 0.0)))
    mb.add(ForceSource("push", [roller.index], (0.0, F)))
    mb.add(SpeedDrive("spin", roller.index, dw, k=50.0, c=1.0))
    model = mb.build()
    assert model.ndof == 3                       # the roller's x, y, θ
    res = mbd.simulate(model, np.array([rm, 0.0, 0.0]), np.array([0.0, 0.0, dw]), 0.01, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, engine=engine)
    assert res.engine == engine
    out = mbd.System(model).outputs(res.state.t, res.state.q, res.state.v, res.state.z)["pocket_film"]
    assert out["gap"][0] == pytest.approx(h, rel=1e-3)
    assert out["force"][0] == pytest.approx(F, rel=1e-3)
