"""The quasi-static sliced planet bearing (components.sliced_bearing, docs/model.md §8.8), its roller profiles
(components.profiles) and the ISO/TS 16281 life with slices (components.life.sliced_life), against truths the code
does not compute: an independent transcription of ISO/TS 16281's lamina equations (its own small solver); the planar
bearing solved here with the planar contact law (straight, aligned rollers); the roller-load life of equal slices;
mirror and rotation invariances; slice-count convergence; the profiles' hand values; Hertz's line-contact pressure."""
from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from components import life
from components.params import overrides_from_toml, with_overrides
from components.presets import reference_bearing
from components.profiles import reduced_modulus, roller_drop
from components.sliced_bearing import ARCMIN, SlicedBearing, sliced_bearing_life
from tests.support.iso16281 import iso_laminae, iso_solve

P = 10.0 / 9.0
LOAD = np.array([12000.0, 0.0])          # N on the planet: the outer planet bearing's mean load at condition 3


def _bearing(**over):
    return with_overrides(reference_bearing(), over).si()


# ------------------------------------------------------------------------------------- ISO/TS 16281 transcription
_iso_laminae, _iso_solve = iso_laminae, iso_solve       # the transcription: tests/support/iso16281.py


@pytest.mark.parametrize("shape,stiffness", [("straight", "palmgren"), ("iso_16281", "palmgren"),
                                             ("logarithmic", "iso_16281"), ("crowned", "palmgren")])
@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_slice_loads_agree_with_an_independent_iso_16281_transcription(shape, stiffness, direction):
    """At a given bore displacement and pin slope (4′) the production's rollers — each a rigid body in force and
    moment equilibrium, exact-norm geometry — carry ISO/TS 16281's lamina loads. The standard's kinematics is the
    first-order expansion of the exact geometry: the two differ by terms (u_t² − ζ² s_t²)/(2r) of the offsets across
    a roller's radial line, so the agreement is 1e-6 where those vanish: (a) on the load line (the roller there has
    no tangential offset) at the reference geometry, (b) for every roller of a bearing whose pitch diameter is scaled
    by 1000 at the same displacements; and the difference at the reference geometry falls as 1/d_m (the geometry's
    second order, nothing else)."""
    g = 4 * ARCMIN
    dirn = np.array([1.0, 0.0]) if direction == "radial" else np.array([0.0, 1.0])
    slope, u = g * dirn, np.array([-3.3e-5, 0.0])             # the bore moves away from the load zone at ψ = π
    over = {"profile.shape": shape, "slicing.stiffness": stiffness}
    diffs = []
    for scale in (1, 10, 1000):
        b = _bearing(**over, pitch_diameter=f"{39 * scale} mm")
        st = SlicedBearing(b).rollers_at(u, slope, cage_angle=0.0)   # roller 6 at ψ = π: the load line
        q, _ = _iso_laminae(b, u, slope, 0.0)
        assert q.sum(1).max() > 2000.0 and (q > 0).any(axis=1).sum() >= 5   # a real load zone
        for got in (st.q_pin[0], st.q_bore[0]):
            diffs.append(np.abs(got - q).max() / q.max())
            if scale == 1 and direction == "radial":
                np.testing.assert_allclose(got[6], q[6], rtol=0, atol=1e-9 * q.max())
        if scale == 1000:
            assert max(diffs[-2:]) < 1e-6
    d1, d10 = diffs[0], diffs[2]
    assert 1e-5 < d1 < 3e-3 and d1 / d10 == pytest.approx(10.0, rel=0.02)


@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_the_bearing_solution_agrees_with_the_standards_own_solver(direction):
    """Under a load and a 6′ slope the bore displacement and every lamina load of the solved bearing agree with the
    ISO/TS 16281 transcription's own solution, to 1e-6 where its linear kinematics is exact (pitch diameter × 1000)."""
    b = _bearing(**{"profile.shape": "logarithmic"}, pitch_diameter="39 m")
    load = 9000.0 * np.array([math.cos(0.4), math.sin(0.4)])
    slope_dir = 0.4 + (0.0 if direction == "radial" else 0.5 * math.pi)
    slope = 6 * ARCMIN * np.array([math.cos(slope_dir), math.sin(slope_dir)])
    u_iso = _iso_solve(b, load, slope, 0.05)
    st = SlicedBearing(b).solve(load, 6 * ARCMIN, direction, cage_angle=0.05)
    np.testing.assert_allclose(st.u, u_iso, rtol=0, atol=1e-6 * np.hypot(*u_iso))
    q, _ = _iso_laminae(b, u_iso, slope, 0.05)
    np.testing.assert_allclose(st.q_pin[0], q, rtol=0, atol=2e-6 * q.max())
    # the bore is in equilibrium: the rollers' forces on it carry the load
    assert np.hypot(*(load + st.q_bore[0].sum(1) @ np.stack([np.cos(st.psi), np.sin(st.psi)], 1))) < 1e-5 * 9000


# ------------------------------------------------------------------------------------- planar reduction
def _planar_bearing(b, load, cage_angle):
    """The planar bearing solved here: each roller on its radial line e between the pin and the bore with one
    Palmgren contact Q = K⟨δ⟩^(10/9) on each (exact distances, as RaceContact; the bore's normal n = (p − u)/|p − u|),
    its radius where the contacts' radial forces balance, Q_pin = Q_bore (n·e) (the cage takes the rest), the bore
    where the rollers' forces carry the load. Returns (u, Q_pin (Z,), Q_bore (Z,))."""
    K = b.contact_stiffness
    psi = cage_angle + 2 * np.pi * np.arange(b.rollers) / b.rollers
    e = np.stack([np.cos(psi), np.sin(psi)], 1)
    Ri, Ro, D = b.inner_raceway_radius, b.outer_raceway_radius, b.roller_diameter
    q = lambda d: K * max(d, 0.0) ** P                                     # noqa: E731

    def rollers(u):
        Qi, Qo, n = np.zeros(len(e)), np.zeros(len(e)), np.zeros((len(e), 2))
        for j, ej in enumerate(e):
            gi = lambda r: Ri + D / 2 - r                                   # noqa: E731
            go = lambda r: np.hypot(*(r * ej - u)) + D / 2 - Ro            # noqa: E731
            cos = lambda r: ej @ (r * ej - u) / np.hypot(*(r * ej - u))    # noqa: E731
            r_mid = brentq(lambda r: gi(r) - go(r), Ri, Ro, xtol=1e-18, rtol=1e-15)
            n[j] = (r_mid * ej - u) / np.hypot(*(r_mid * ej - u))
            if gi(r_mid) > 0:
                r = brentq(lambda r: q(gi(r)) - q(go(r)) * cos(r), r_mid - 1e-4, r_mid + 1e-4, xtol=1e-18,
                           rtol=1e-15)
                Qi[j], Qo[j] = q(gi(r)), q(go(r))
                n[j] = (r * ej - u) / np.hypot(*(r * ej - u))
        return Qi, Qo, n

    def res(u):
        _, Qo, n = rollers(u)
        return (load + Qo @ n) / np.hypot(*load)
    u = fsolve(res, 3e-5 * load / np.hypot(*load), xtol=1e-13)
    return (u, *rollers(u)[:2])


def test_a_straight_aligned_bearing_is_the_planar_bearing_and_its_roller_load_life():
    """Straight rollers, no slope: every roller's slices sum to the planar bearing's roller load (solved here with the
    planar law), the rollers do not tilt, every slice of a roller carries the same load, and the sliced life is the
    existing roller-load life (lundberg_palmgren_life) of those roller loads."""
    b = _bearing()
    sb = SlicedBearing(b)
    states = sb.states(LOAD, 0.0, positions=4)
    Qs = []
    for s in states:
        u, Qi, Qo = _planar_bearing(b, LOAD, s.psi[0])
        np.testing.assert_allclose(s.q_pin[0].sum(1), Qi, rtol=0, atol=1e-9 * Qi.max())
        np.testing.assert_allclose(s.q_bore[0].sum(1), Qo, rtol=0, atol=1e-9 * Qi.max())
        np.testing.assert_allclose(s.u, u, rtol=0, atol=1e-9 * np.hypot(*u))
        assert np.abs(s.tilt).max() < 1e-12
        assert np.ptp(s.q_pin[0], axis=1).max() < 1e-9 * Qi.max()
        Qs.append((Qi, Qo))
    Qi, Qo = np.array(Qs).transpose(1, 0, 2)
    q_pin = np.mean(Qi ** life.STATIONARY_EXPONENT) ** (1 / life.STATIONARY_EXPONENT)
    q_bore = np.mean(Qo ** life.ROTATING_EXPONENT) ** (1 / life.ROTATING_EXPONENT)
    assert sliced_bearing_life(states, b) == pytest.approx(life.lundberg_palmgren_life(q_pin, q_bore, b), rel=1e-7)


def test_equal_slices_give_the_roller_sum_for_any_slice_count():
    """L of n_s equal slices Q_e/n_s with q_c = Q_c n_s^(−7/9) is the roller-load life, for every n_s (an exponent
    other than −7/9 or a sum over a wrong count would not cancel); identical rows count b.rows times."""
    b = _bearing()
    for n_s in (1, 3, 30, 31, 200):
        for qp, qb in ((2500.0, 3100.0), (800.0, 0.0)):
            ref = life.lundberg_palmgren_life(qp, qb, b)
            got = life.sliced_life(np.full(n_s, qp / n_s), np.full(n_s, qb / n_s), b)
            assert got == pytest.approx(ref, rel=1e-12)
            two = life.sliced_life(np.full((2, n_s), qp / n_s), np.full((2, n_s), qb / n_s), b)
            assert two == pytest.approx(ref * 2 ** (-8 / 9), rel=1e-12)
    # a slice carrying all of a roller's load lives (n_s^(7/9))^(4) shorter than the whole roller: q_c's scaling
    n_s = 31
    q = np.zeros(n_s)
    q[5] = 2500.0
    assert life.sliced_life(q, 0 * q, b) == pytest.approx(life.lundberg_palmgren_life(2500.0, 0.0, b)
                                                          * n_s ** (-4 * 7 / 9), rel=1e-12)
    assert life.sliced_life(0 * q, 0 * q, b) is None


# ------------------------------------------------------------------------------------- invariances
@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_plus_and_minus_slope_mirror_the_slices_and_give_the_same_life(direction):
    b = _bearing(**{"profile.shape": "iso_16281"})
    sb = SlicedBearing(b)
    plus = sb.states(LOAD, 6 * ARCMIN, direction, positions=3)
    minus = sb.states(LOAD, -6 * ARCMIN, direction, positions=3)
    for a, m in zip(plus, minus):
        np.testing.assert_allclose(m.q_pin, a.q_pin[..., ::-1], rtol=0, atol=1e-9 * a.q_pin.max())
        np.testing.assert_allclose(m.q_bore, a.q_bore[..., ::-1], rtol=0, atol=1e-9 * a.q_bore.max())
        np.testing.assert_allclose(m.tilt, -a.tilt, rtol=0, atol=1e-9 * np.abs(a.tilt).max())
    assert not np.allclose(plus[0].q_pin, plus[0].q_pin[..., ::-1], atol=1e-3 * plus[0].q_pin.max())   # not trivial
    assert sliced_bearing_life(minus, b) == pytest.approx(sliced_bearing_life(plus, b), rel=1e-9)


@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_a_slope_turning_with_the_load_changes_nothing(direction):
    """Load, slope and cage turned together by any angle: the same rollers carry the same slices."""
    b = _bearing(**{"profile.shape": "logarithmic"})
    sb = SlicedBearing(b)
    a = sb.solve(LOAD, 5 * ARCMIN, direction, cage_angle=0.1)
    for turn in (0.9, 2.5, -2.0):
        c, s = math.cos(turn), math.sin(turn)
        t = sb.solve(np.array([[c, -s], [s, c]]) @ LOAD, 5 * ARCMIN, direction, cage_angle=0.1 + turn)
        np.testing.assert_allclose(t.q_pin, a.q_pin, rtol=0, atol=1e-9 * a.q_pin.max())
        np.testing.assert_allclose(t.tilt, a.tilt, rtol=0, atol=1e-9 * np.abs(a.tilt).max())
        assert t.edge_ratio() == pytest.approx(a.edge_ratio(), rel=1e-9)


# ------------------------------------------------------------------------------------- convergence and outputs
@pytest.mark.parametrize("shape", ["straight", "logarithmic", "iso_16281"])
def test_life_converges_in_the_slice_count(shape):
    """The reference slice count n_s = 31 gives the life of n_s = 121 within 1 %, aligned and at 10′ both ways."""
    b = _bearing(**{"profile.shape": shape})
    assert b.slicing.slices == 31
    for g, d in ((0.0, "radial"), (10.0, "radial"), (10.0, "tangential")):
        L = [sliced_bearing_life(SlicedBearing(b, slices=n).states(LOAD, g * ARCMIN, d, positions=4), b)
             for n in (31, 121)]
        assert L[0] == pytest.approx(L[1], rel=0.01), (g, d, L)


def test_pressure_and_edge_indicators():
    """Aligned straight rollers: Hertz's line-contact peak pressure sqrt(w E*/(π R)) of the most loaded roller's
    load per length, on the pin (1/R = 2/D + 1/R_i) and the bore (2/D − 1/R_o); a flat pressure profile (edge ratio
    1, whole length loaded). A radial slope loads one end: edge ratio above 1 and growing with the slope."""
    b = _bearing()
    sb = SlicedBearing(b)
    s = sb.solve(LOAD)
    Q = s.q_pin[0].sum(1).max()
    E = b.elastic_modulus / (2 * (1 - b.poisson_ratio ** 2))
    assert reduced_modulus(b) == pytest.approx(E, rel=1e-15)
    w = Q / b.roller_length
    p_pin = math.sqrt(w * E / math.pi * (2 / b.roller_diameter + 1 / b.inner_raceway_radius))
    p_bore = math.sqrt(w * E / math.pi * (2 / b.roller_diameter - 1 / b.outer_raceway_radius))
    assert s.max_pressure == pytest.approx(p_pin, rel=1e-9)
    assert s.p_bore.max() == pytest.approx(p_bore, rel=1e-9)
    np.testing.assert_allclose(s.pressure_profile(), p_pin, rtol=1e-9)
    assert s.edge_ratio() == pytest.approx(1.0, abs=1e-9) and s.loaded_length() == 1.0
    ratios = [sb.solve(LOAD, g * ARCMIN, "radial").edge_ratio() for g in (2, 4, 8)]
    assert 1.0 < ratios[0] < ratios[1] < ratios[2]


def test_bad_input_names_the_parameter():
    sb = SlicedBearing(_bearing())
    with pytest.raises(ValueError, match="direction"):
        sb.solve(LOAD, ARCMIN, "axial")
    with pytest.raises(ValueError, match="load"):
        sb.solve([0.0, 0.0])
    with pytest.raises(ValueError, match="bearing.profile.points"):
        SlicedBearing(_bearing(**{"profile.shape": "table"}))


# ------------------------------------------------------------------------------------- profiles
def test_profiles_against_their_hand_values():
    l, D = 9e-3, 7.5e-3
    x = np.array([0.0, 1.0e-3, 2.5e-3, 3.0e-3, 4.5e-3])
    np.testing.assert_array_equal(roller_drop(_bearing(), x), 0.0)
    # crowned: flat over 5 mm, circular arc through 10 µm at the end: the arc's radius (2^2 + 0.01^2)/(2·0.01) mm
    cr = roller_drop(_bearing(**{"profile.shape": "crowned"}), x)
    getcontext().prec = 40                                               # R_c − sqrt(R_c² − s²) in 40 digits
    Rc = (Decimal("2e-3") ** 2 + Decimal("1e-5") ** 2) / Decimal("2e-5")
    arc = float(Rc - (Rc ** 2 - Decimal("0.5e-3") ** 2).sqrt())
    np.testing.assert_allclose(cr, [0, 0, 0, arc, 1e-5], rtol=1e-12, atol=1e-20)
    # ISO/TS 16281: 0.00035 D ln(1/(1 − (2x/l)²)), capped at 2|x|/l = 29/30
    iso = roller_drop(_bearing(**{"profile.shape": "iso_16281"}), x)
    u = np.minimum(2 * x / l, 29 / 30)
    np.testing.assert_allclose(iso, 0.00035 * D * np.log(1 / (1 - u ** 2)), rtol=1e-12, atol=1e-20)
    assert iso[1] == pytest.approx(0.00035 * 7.5e-3 * math.log(81 / 77), rel=1e-12)
    # Lundberg / Johns–Gohar at Q_d = 4 kN: a from Hertz, end drop Q_d/(π l E*) ln(b/(0.3033 a))
    b = _bearing(**{"profile.shape": "logarithmic"})
    E = 210e9 / (2 * (1 - 0.09))
    R = 1 / (2 / D + 2 / (39e-3 - D))
    a = math.sqrt(4 * 4000.0 * R / (math.pi * l * E))
    lo = roller_drop(b, x)
    assert lo[-1] == pytest.approx(4000.0 / (math.pi * l * E) * math.log(0.5 * l / (0.3033 * a)), rel=1e-12)
    assert lo[1] == pytest.approx(-4000.0 / (math.pi * l * E) * math.log(1 - (1 - 0.3033 * a / (0.5 * l)) * (2 / 9) ** 2),
                                  rel=1e-12)
    # a user's table, symmetric, interpolated
    tb = _bearing(**{"profile.shape": "table", "profile.points": [{"x": "0 mm", "drop": "0 um"},
                                                                  {"x": "3 mm", "drop": "1 um"},
                                                                  {"x": "4.5 mm", "drop": "7 um"}]})
    np.testing.assert_allclose(roller_drop(tb, np.array([-4.5e-3, -2.0e-3, 1.5e-3, 3.75e-3])),
                               [7e-6, 2e-6 / 3, 0.5e-6, 4e-6], rtol=1e-12)


def test_a_double_row_bearing_under_twice_the_load_is_two_single_rows_and_its_rows_combine():
    """Aligned: two rows under 2F carry per roller what one row carries under F, and the life is the single row's
    times 2^(−8/9) (Σ_rows L^(−9/8)); under a radial slope the rows sit at ±l/2 on the pin and carry different
    loads — the row where the pin's axis ζ s is displaced towards the load zone (ζ < 0 for a slope along F: the
    zone lies opposite F) more — and the life falls."""
    one, two = _bearing(), _bearing(rows=2)
    s1 = SlicedBearing(one).states(LOAD, 0.0, positions=2)
    s2 = SlicedBearing(two).states(2 * LOAD, 0.0, positions=2)
    for a, b2 in zip(s1, s2):
        for r in range(2):
            np.testing.assert_allclose(b2.q_pin[r], a.q_pin[0], rtol=0, atol=1e-9 * a.q_pin.max())
    L1, L2 = sliced_bearing_life(s1, one), sliced_bearing_life(s2, two)
    assert L2 == pytest.approx(L1 * 2 ** (-8 / 9), rel=1e-9)
    tilted = SlicedBearing(two).states(2 * LOAD, 4 * ARCMIN, "radial", positions=2)
    rows = tilted[0].q_pin.sum(axis=(1, 2))
    assert rows[0] - rows[1] > 0.05 * rows.sum()
    assert sliced_bearing_life(tilted, two) < L2


def test_the_bore_balance_jacobian_through_the_rollers_against_differences():
    """∂G/∂u of the bore's balance with every roller re-solved (the Schur complement the solver uses) against central
    differences of G, under a slope and a profile (rollers tilted, some edge-loaded)."""
    sb = SlicedBearing(_bearing(**{"profile.shape": "logarithmic"}))
    slope = 8 * ARCMIN * np.array([0.6, 0.8])
    u = np.array([2.9e-5, 0.8e-5])
    G, J, _ = sb.bore_balance(u, LOAD, slope, 0.13)
    h = 2.0 ** -34
    fd = np.column_stack([(sb.bore_balance(u + h * ei, LOAD, slope, 0.13)[0]
                           - sb.bore_balance(u - h * ei, LOAD, slope, 0.13)[0]) / (2 * h) for ei in np.eye(2)])
    assert np.abs(J).max() > 1e8
    np.testing.assert_allclose(J, fd, rtol=0, atol=1e-6 * np.abs(J).max())


def test_a_profile_is_read_from_toml_like_every_parameter():
    text = """
[bearing.profile]
shape = "table"

[[bearing.profile.points]]
x = "0 mm"
drop = "0 um"

[[bearing.profile.points]]
x = "4.5 mm"
drop = "9 um"

[bearing.slicing]
slices = 41
stiffness = "iso_16281"
"""
    b = with_overrides(reference_bearing(), {k.removeprefix("bearing."): v
                                             for k, v in overrides_from_toml(text).items()}).si()
    assert b.slicing.slices == 41 and b.slicing.stiffness == "iso_16281"
    np.testing.assert_allclose(roller_drop(b, np.array([-2.25e-3, 4.5e-3])), [4.5e-6, 9e-6], rtol=1e-12)
    assert SlicedBearing(b).n_s == 41
