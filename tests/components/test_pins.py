"""The elastic planet pin (components.pins, mbd.elements.tilt.BeamSupport, docs/model.md §8.8).

Truths: Roark's Table 8.1 (W. C. Young, R. G. Budynas, *Roark's Formulas for Stress and Strain*, 7th ed., 2002) —
cantilever under an end load (case 1a) and an end moment (3a), both ends fixed under a load (1d) and a moment at the
centre (3d) — and the elastic curve of a beam fixed at both ends under a load at any point (AISC *Steel Construction
Manual*, Beam Diagrams and Formulas, case 16: Δ_x = P b² x² (3 a l − 3 a x − b x)/(6 E I l³), x < a), whose slope at
the load is differentiated here by hand. With shear (Timoshenko): the cantilever's and the centred fixed-fixed
beam's closed forms, Cowper's (1966) tabulated shear coefficients, the beam's equations integrated numerically (scipy's
solve_bvp) off the centre, and the Euler–Bernoulli limit as κGA → ∞. The element: finite differences, Newton's third law, its damper's power, and
its compiled twin against the numpy reference."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import mbd
from components import pins
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from components.units import ParameterError
from mbd.element import evaluate
from mbd.elements.tilt import BeamSupport
from mbd.model import FrameState

from tests.support.contact import compiled

EI = 1.0e4          # N m² (about the reference pin's: d = 31.5 mm, E = 210 GPa)


def _solve(K, F, M):
    """(u, s) of a station under force F and moment M."""
    return np.linalg.solve(K, [F, M])


# ------------------------------------------------------------------------------------------- the beam against Roark
@pytest.mark.parametrize("a", [0.012, 0.02, 0.035])
def test_a_cantilever_pin_deflects_and_slopes_as_roark_cases_1a_and_3a(a):
    """Clamped at ζ = +a only (the shaft-side plate): an end load W gives y = W a³/(3EI) and a slope of magnitude
    W a²/(2EI) falling away from the clamp (du/dζ < 0); an end moment M gives θ = M a/(EI), y = M a²/(2EI) (with the
    sign of the slope that lowers the station: −)."""
    K = pins.beam_stiffness(EI, a)
    W, M = 1.0e4, 30.0
    u, s = _solve(K, W, 0.0)
    np.testing.assert_allclose(u, W * a ** 3 / (3 * EI), rtol=1e-12)
    np.testing.assert_allclose(s, -W * a ** 2 / (2 * EI), rtol=1e-12)
    u, s = _solve(K, 0.0, M)
    np.testing.assert_allclose(s, M * a / EI, rtol=1e-12)
    np.testing.assert_allclose(u, -M * a ** 2 / (2 * EI), rtol=1e-12)


def test_a_pin_clamped_in_both_plates_has_no_slope_under_a_centred_load_and_roarks_centre_moment_slope():
    """Roark 1d at mid-span: y = W l³/(192 EI) and no slope (a symmetric load); 3d: a moment at the centre turns it by
    θ = M l/(16 EI) without deflecting it."""
    l = 0.04
    K = pins.beam_stiffness(EI, l / 2, l / 2)
    u, s = _solve(K, 1.0e4, 0.0)
    np.testing.assert_allclose(u, 1.0e4 * l ** 3 / (192 * EI), rtol=1e-12)
    assert abs(s) < 1e-15
    u, s = _solve(K, 0.0, 25.0)
    np.testing.assert_allclose(s, 25.0 * l / (16 * EI), rtol=1e-12)
    assert abs(u) < 1e-18


@pytest.mark.parametrize("a_x", [0.008, 0.015, 0.027])
def test_an_off_centre_station_of_a_fixed_fixed_pin_deflects_and_slopes_as_the_published_elastic_curve(a_x):
    """A load P at x = a_x from the left clamp of a beam of length l fixed at both ends: the deflection under it is
    P a³b³/(3EI l³) (Roark 1d, AISC 16) and its slope there d/dx Δ_x at x = a_x = P a²b²(b − a)/(2EI l³). In the
    module's axes the left clamp is at ζ = −a_x (``b`` = a_x) and the right one at ζ = +(l − a_x) (``a``)."""
    l, P = 0.04, 8.0e3
    a, b = a_x, l - a_x
    K = pins.beam_stiffness(EI, b, a)
    u, s = _solve(K, P, 0.0)
    np.testing.assert_allclose(u, P * a ** 3 * b ** 3 / (3 * EI * l ** 3), rtol=1e-12)
    # the AISC curve's slope at the load, differentiated by hand: d/dx[b²x²(3al − 3ax − bx)] = 3a²b²(b − a) at x = a
    slope = P * a ** 2 * b ** 2 * (b - a) / (2 * EI * l ** 3)
    np.testing.assert_allclose(s, slope, rtol=1e-12)
    # and against the curve itself, differenced (a check on the hand derivative)
    curve = lambda x: P * b ** 2 * x ** 2 * (3 * a * l - 3 * a * x - b * x) / (6 * EI * l ** 3)   # noqa: E731
    h = 1e-7
    np.testing.assert_allclose((curve(a) - curve(a - h)) / h, slope, rtol=1e-4)


# ----------------------------------------------------------------------------------- Timoshenko's beam (shear)
KGA = 5.0e7         # N: κGA about the reference pin's (κ = 0.886, G = 80.8 GPa, A = 7.8 cm²)


def test_cowpers_shear_coefficient_of_a_solid_and_a_thin_walled_circular_section():
    """Cowper (1966) Table 1: a solid circle κ = 6(1 + ν)/(7 + 6ν), 0.886 at ν = 0.3 (his tabulated value), 0.857 at
    ν = 0; a thin-walled tube (m → 1) 2(1 + ν)/(4 + 3ν), 0.530 at ν = 0.3."""
    assert pins.shear_coefficient(0.3) == pytest.approx(7.8 / 8.8, rel=1e-15)
    assert round(pins.shear_coefficient(0.3), 3) == 0.886
    assert pins.shear_coefficient(0.0) == pytest.approx(6.0 / 7.0, rel=1e-15)
    assert pins.shear_coefficient(0.3, 1.0 - 1e-9) == pytest.approx(2.6 / 4.9, rel=1e-8)
    # a bore lowers it monotonically between the two
    ks = [pins.shear_coefficient(0.3, m) for m in np.linspace(0.0, 0.99, 12)]
    assert all(x > y for x, y in zip(ks, ks[1:]))


@pytest.mark.parametrize("a", [0.012, 0.02, 0.035])
def test_a_timoshenko_cantilever_deflects_by_bending_plus_shear_and_its_end_section_turns_without_shear(a):
    """Clamped at ζ = +a: an end load W deflects the station by W a³/(3EI) + W a/(κGA) (Timoshenko's cantilever) and
    turns its section by W a²/(2EI), no shear term; an end moment M turns it by M a/EI and deflects it by M a²/(2EI),
    no shear term either (the shear force is nil)."""
    K = pins.beam_stiffness(EI, a, kGA=KGA)
    W, M = 1.0e4, 30.0
    u_w, s = _solve(K, W, 0.0)
    np.testing.assert_allclose(u_w, W * a ** 3 / (3 * EI) + W * a / KGA, rtol=1e-12)
    np.testing.assert_allclose(s, -W * a ** 2 / (2 * EI), rtol=1e-12)
    u, s = _solve(K, 0.0, M)
    np.testing.assert_allclose(s, M * a / EI, rtol=1e-12)
    np.testing.assert_allclose(u, -M * a ** 2 / (2 * EI), rtol=1e-12)
    # the shear part of the deflection is W a/(κGA): a factor 2 or a dropped κ would show
    u_eb = _solve(pins.beam_stiffness(EI, a), W, 0.0)[0]
    np.testing.assert_allclose(u_w - u_eb, W * a / KGA, rtol=1e-9)


def test_a_timoshenko_pin_fixed_at_both_ends_deflects_by_bending_plus_shear_under_a_centred_load():
    """Both ends fixed, a load W at the centre of the span l: W l³/(192 EI) + W l/(4κGA) (each half carries the shear
    W/2 over l/2) and no turn; a moment at the centre turns the section without deflecting it."""
    l, W = 0.04, 1.0e4
    K = pins.beam_stiffness(EI, l / 2, l / 2, KGA)
    u, s = _solve(K, W, 0.0)
    np.testing.assert_allclose(u, W * l ** 3 / (192 * EI) + W * l / (4 * KGA), rtol=1e-12)
    assert abs(s) < 1e-15
    u, s = _solve(K, 0.0, 25.0)
    assert abs(u) < 1e-18 and s > 25.0 * l / (16 * EI)        # shear softens the turn too


def _timoshenko_bvp(a, b, kGA, F, M):
    """(u, ψ) at the station of a Timoshenko beam clamped at ζ = +a and ζ = −b under a force F and a moment M there,
    by integrating the beam's equations — u' = ψ + V/(κGA), ψ' = M_b/(EI), M_b' = −V, V' = 0 on each side, u and ψ
    continuous at the station, V and M_b stepping by F and M — with scipy's collocation solver."""
    from scipy.integrate import solve_bvp

    def f(x, y):
        uL, pL, mL, vL, uR, pR, mR, vR = y
        return np.vstack([b * (pL + vL / kGA), b * mL / EI, -b * vL, 0 * vL,
                          a * (pR + vR / kGA), a * mR / EI, -a * vR, 0 * vR])

    def bc(ya, yb):        # x = 0: the clamp at −b (left) and the station (right); x = 1: the station and +a
        return np.array([ya[0], ya[1], yb[4], yb[5], yb[0] - ya[4], yb[1] - ya[5], yb[3] - ya[7] - F, yb[2] - ya[6] - M])

    x = np.linspace(0.0, 1.0, 11)
    sol = solve_bvp(f, bc, x, np.zeros((8, x.size)), tol=1e-10, bc_tol=1e-14, max_nodes=10000)
    assert sol.success
    return sol.sol(0.0)[4], sol.sol(0.0)[5]


@pytest.mark.parametrize("a_x", [0.008, 0.015, 0.027])
@pytest.mark.parametrize("kGA", [KGA, 0.1 * KGA])
def test_an_off_centre_station_of_a_fixed_fixed_timoshenko_pin_matches_the_beams_equations_integrated(a_x, kGA):
    """Off the centre, under a force and under a moment: the condensed stiffness against the Timoshenko beam's
    equations solved numerically (no closed form used)."""
    l = 0.04
    K = pins.beam_stiffness(EI, l - a_x, a_x, kGA)
    for F, M in ((8.0e3, 0.0), (0.0, 40.0)):
        np.testing.assert_allclose(_solve(K, F, M), _timoshenko_bvp(l - a_x, a_x, kGA, F, M), rtol=1e-7,
                                   atol=1e-7 * np.abs(_solve(K, F, M)).max())


@pytest.mark.parametrize("b", [0.02, math.inf])
def test_the_timoshenko_stiffness_becomes_euler_bernoullis_as_the_shear_stiffness_grows(b):
    """G → ∞: the stiffness tends to Euler–Bernoulli's (the Roark cases above) as 1/(κGA), exactly at κGA = ∞."""
    eb = pins.beam_stiffness(EI, 0.02, b)
    np.testing.assert_array_equal(pins.beam_stiffness(EI, 0.02, b, math.inf), eb)
    err = [np.abs(pins.beam_stiffness(EI, 0.02, b, k) - eb).max() / np.abs(eb).max() for k in (1e12, 1e14, 1e16)]
    assert err[0] < 1e-2 and err[1] < 1e-4 and err[2] < 1e-6
    np.testing.assert_allclose(np.array(err[:-1]) / np.array(err[1:]), 100.0, rtol=1e-2)


def test_the_reference_pin_stiffness_comes_from_its_raceway_diameter_modulus_and_the_plate_span():
    """d = d_m − D = 31.5 mm, E = 210 GPa, ν = 0.3, L_c = 40 mm, Timoshenko's spans with φ = 12EI/(κGA a²),
    κ = 6(1 + ν)/(7 + 6ν): k_uu = 2·12EI/(a³(1 + φ)), k_us = 0, k_ss = 2EI(4 + φ)/(a(1 + φ)) both plates (a = L_c/2);
    EI/(1 + φ)·(12/a³, 6/a², (4 + φ)/a) one plate (a = 20 mm); a bore d_i lowers I to π(d⁴ − d_i⁴)/64, A to
    π(d² − d_i²)/4 and κ by Cowper's tube formula."""
    p = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced", "bearing.pin.model": "elastic"})
    si = p.si()
    d, E, nu, L, a = 0.0315, 210e9, 0.3, 0.04, 0.02
    G = E / (2 * (1 + nu))
    I, A = math.pi * d ** 4 / 64, math.pi * d ** 2 / 4
    phi = 12 * E * I / ((6 * (1 + nu) / (7 + 6 * nu)) * G * A * a ** 2)
    k = pins.pin_stiffness(si.bearing, si.gears.carrier_plate_span)
    np.testing.assert_allclose([k["k_uu"], k["k_us"], k["k_ss"]],
                               [24 * E * I / (a ** 3 * (1 + phi)), 0.0, 2 * E * I * (4 + phi) / (a * (1 + phi))],
                               rtol=1e-12, atol=1e-6)
    assert 5.0 < phi < 6.0          # the reference pin: shear five times as compliant as bending over a half-span
    one = with_overrides(p, {"bearing.pin.mounting": "one_plate", "bearing.pin.bore_diameter": "10 mm"}).si()
    m = 0.01 / d
    I1, A1 = math.pi * (d ** 4 - 0.01 ** 4) / 64, math.pi * (d ** 2 - 0.01 ** 2) / 4
    kap = 6 * (1 + nu) * (1 + m * m) ** 2 / ((7 + 6 * nu) * (1 + m * m) ** 2 + (20 + 12 * nu) * m * m)
    phi1 = 12 * E * I1 / (kap * G * A1 * a ** 2)
    k1 = pins.pin_stiffness(one.bearing, L)
    np.testing.assert_allclose([k1["k_uu"], k1["k_us"], k1["k_ss"]],
                               np.array([12 / a ** 3, 6 / a ** 2, (4 + phi1) / a]) * E * I1 / (1 + phi1), rtol=1e-12)
    # torsion: G K (1/a + 1/b), K = π d⁴/32 (Roark Table 10.1 case 1), G = E/(2(1 + ν))
    np.testing.assert_allclose(k["k_theta"], E / 2.6 * math.pi * 0.0315 ** 4 / 32 * (2 / 0.02), rtol=1e-12)


# ------------------------------------------------------------------------------------------------ the element
MARKERS = np.array([[0.06, 0.01], [-0.03, 0.05]])


def _element(c=(0.0, 0.0, 0.0)):
    K = pins.beam_stiffness(EI, 0.02)              # a cantilever: the coupling k_us ≠ 0
    return BeamSupport("beam", [0, 0], [1, 2], [[9, 10], [11, 12]], marker_a=MARKERS,
                       k_uu=K[0, 0], k_us=K[0, 1], k_ss=K[1, 1], k_theta=4e5, c_u=c[0], c_s=c[1], c_theta=c[2])


def _state(rng):
    """Carrier 0..2, two pin bodies 3..5 and 6..8 near their markers (µm), their slopes 9..12 (~1e-4 rad), rates of
    a turning carrier."""
    q = np.zeros(13)
    q[:3] = (1e-5, -2e-5, 0.3)
    c, s = np.cos(0.3), np.sin(0.3)
    for k, (mx, my) in enumerate(MARKERS):
        b = 3 + 3 * k
        q[b:b + 2] = q[:2] + np.array([c * mx - s * my, s * mx + c * my]) + rng.uniform(-3e-6, 3e-6, 2)
        q[b + 2] = 0.3 + rng.uniform(-1e-4, 1e-4)
    q[9:] = rng.uniform(-2e-4, 2e-4, 4)
    v = rng.standard_normal(13) * np.array([0.1, 0.1, 3.0, 0.1, 0.1, 3.0, 0.1, 0.1, 3.0, 0.05, 0.05, 0.05, 0.05])
    return q, v


FSTATE = FrameState(0.2, 300.0, 0.0)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_beam_support_jacobians_match_central_differences(seed):
    el = _element((2e3, 5.0, 1.0))
    q, v = _state(np.random.default_rng(seed))
    F, _, Jq, Jv = evaluate(el, 0.0, FSTATE, q, v, None, True)
    n_l = el.n_local
    for j in range(n_l):
        for J, x, h in ((Jq, q, 1e-9), (Jv, v, 1e-5)):
            cols = []
            for i in range(el.n):
                dof = el.dofs[i, j]
                xp, xm = x.copy(), x.copy()
                xp[dof] += h
                xm[dof] -= h
                args_p = (xp, v) if x is q else (q, xp)
                args_m = (xm, v) if x is q else (q, xm)
                Fp = evaluate(el, 0.0, FSTATE, *args_p, None, False)[0][i]
                Fm = evaluate(el, 0.0, FSTATE, *args_m, None, False)[0][i]
                cols.append((Fp - Fm) / (2 * h))
            fd = np.array(cols)
            got = J[:, :, j]
            scale = np.abs(got).max() + 1e-30
            assert np.abs(got - fd).max() <= 1e-6 * scale, (j, x is q)


def test_the_beam_support_is_newtons_third_law_and_its_damper_only_dissipates():
    """Σ forces = 0 on the planar bodies; the z-moment about the origin of the planar forces is the slope pair's
    k_us d × s (U invariant under a rigid turn: Σ moments + M·(k × s) = 0); without damping the stiffness is the
    Hessian of a potential (symmetric J_q); the damper's power is −c_u|ḋ_A|² − c_s|ṡ_A|² − c_θ(θ̇_B − θ̇_A)²."""
    rng = np.random.default_rng(7)
    q, v = _state(rng)
    el = _element()
    el1 = BeamSupport("one", 0, 1, [[9, 10]], marker_a=[0.06, 0.01], k_uu=el.k_uu[0], k_us=el.k_us[0],
                      k_ss=el.k_ss[0], k_theta=4e5)
    f, _ = el1.kernel(0.0, FSTATE, list(q[el1.dofs].T), list(v[el1.dofs].T), None)
    f = np.array([np.asarray(x, float)[0] for x in f])
    assert abs(f[0] + f[3]) < 1e-9 * abs(f[0]) and abs(f[1] + f[4]) < 1e-9 * abs(f[1])
    moment = f[2] + f[5] + q[0] * f[1] - q[1] * f[0] + q[3] * f[4] - q[4] * f[3]
    s = q[9:11]
    assert abs(moment + (f[6] * -s[1] + f[7] * s[0])) < 1e-9 * np.abs(f[:2]).max() * 0.06
    _, _, Jq, _ = evaluate(el1, 0.0, FSTATE, q, v, None, True)
    np.testing.assert_allclose(Jq[0], Jq[0].T, rtol=0, atol=1e-9 * np.abs(Jq[0]).max())
    # the damper's power
    c = (2e3, 5.0, 1.0)
    eld = BeamSupport("d", 0, 1, [[9, 10]], marker_a=[0.06, 0.01], k_uu=el.k_uu[0], k_us=el.k_us[0], k_ss=el.k_ss[0],
                      k_theta=4e5, c_u=c[0], c_s=c[1], c_theta=c[2])
    fd, _ = eld.kernel(0.0, FSTATE, list(q[eld.dofs].T), list(v[eld.dofs].T), None)
    fd = np.array([np.asarray(x, float)[0] for x in fd]) - f
    power = fd @ v[eld.dofs[0]]
    ra = np.array([np.cos(0.3) * 0.06 - np.sin(0.3) * 0.01, np.sin(0.3) * 0.06 + np.cos(0.3) * 0.01])
    d = q[3:5] - q[:2] - ra
    wA = v[2]
    dd = v[3:5] - (v[:2] + wA * np.array([-ra[1], ra[0]])) - wA * np.array([-d[1], d[0]])
    ds = v[9:11] - wA * np.array([-s[1], s[0]])
    expect = -c[0] * dd @ dd - c[1] * ds @ ds - c[2] * (v[5] - v[2]) ** 2
    np.testing.assert_allclose(power, expect, rtol=1e-9)


def test_a_rigid_turn_of_carrier_pin_and_slope_makes_no_damping_force():
    """Every point turning at w about the origin, both bodies at θ̇ = w, the slope turning with them (ṡ = w k × s):
    the rates seen from the carrier vanish, so the damped family's forces are the undamped one's."""
    rng = np.random.default_rng(9)
    q, _ = _state(rng)
    w = 37.0
    v = np.zeros_like(q)
    for b in (0, 1, 2):
        v[3 * b:3 * b + 2] = w * np.array([-q[3 * b + 1], q[3 * b]])
        v[3 * b + 2] = w
    for k in (9, 11):
        v[k:k + 2] = w * np.array([-q[k + 1], q[k]])
    damped, undamped = _element((2e3, 5.0, 1.0)), _element()
    Fd = evaluate(damped, 0.0, FSTATE, q, v, None, False)[0]
    Fu = evaluate(undamped, 0.0, FSTATE, q, v, None, False)[0]
    np.testing.assert_allclose(Fd, Fu, rtol=0, atol=1e-12 * np.abs(Fu).max())


@pytest.mark.parametrize("seed", [4, 5])
def test_the_compiled_beam_support_equals_the_reference(seed):
    el = _element((2e3, 5.0, 1.0))
    q, v = _state(np.random.default_rng(seed))
    Fr, _, Jqr, Jvr = evaluate(el, 0.1, FSTATE, q, v, None, True)
    F, Jq, Jv = compiled(el, FSTATE, q, v, None, True, 0.1)
    for A, B in ((F, Fr), (Jq, Jqr), (Jv, Jvr)):
        assert np.abs(A - B).max() <= 1e-13 * np.abs(B).max()


def test_the_beam_support_refuses_a_stiffness_that_is_not_positive_definite():
    with pytest.raises(mbd.ModelError, match="positive definite"):
        BeamSupport("b", 0, 1, [[6, 7]], marker_a=(0.0, 0.0), k_uu=1.0, k_us=2.0, k_ss=1.0, k_theta=1.0)


# -------------------------------------------------------------------------------------------------- the machine
def _machine(pin, condition=3, **extra):
    ov = {"bearing.model": "sliced", **extra}
    if pin != "rigid":
        ov.update({"bearing.pin.model": "elastic", "bearing.pin.mounting": pin})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_dpgt(with_overrides(reference_dpgt(condition, "forward"), ov))


def test_rigid_pins_build_the_sliced_machine_as_before_and_elastic_ones_need_the_sliced_model():
    rigid = _machine("rigid")
    assert rigid.model.ndof == 345 and "pin_beam" not in {e.name for e in rigid.model.elements}
    elastic = _machine("both_plates")
    # six pin bodies (x, y, θ) with a slope pair each
    assert elastic.model.ndof == 345 + 6 * 5
    with pytest.raises(ParameterError, match="bearing.pin.model"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            build_dpgt(with_overrides(reference_dpgt(3, "forward"), {"bearing.pin.model": "elastic"}))
    # the pins' mass moves from the carrier to the pin bodies: the total stays
    m_r, m_e = rigid.model, elastic.model
    mass = lambda m: m.mdiag[(m.free < m.n_body_coords) & (m.free % 3 == 0)].sum()      # noqa: E731
    np.testing.assert_allclose(mass(m_e), mass(m_r), rtol=1e-12)


def test_the_elastic_machine_runs_compiled_as_on_the_numpy_path():
    """At a state with every pin deflected and sloped, planets and rollers tilted: the compiled assembly (the beam's
    twin and the sliced contact's 12-coordinate layout with the pin body in both places) is the reference's."""
    from mbd.compiled.system import CompiledSystem
    sc = _machine("one_plate")
    m = sc.model
    rng = np.random.default_rng(5)
    q, v = sc.q0.copy(), sc.v0.copy()
    tilt = m.free >= m.n_body_coords
    q[tilt] += rng.standard_normal(tilt.sum()) * 1e-4
    v[tilt] += rng.standard_normal(tilt.sum()) * 1e-2
    system = mbd.System(m)
    z = system.init_internal()
    ref = system.evaluate(0.01, q, v, z, jac=True)
    got = CompiledSystem(system).evaluate(0.01, q, v, z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name


@pytest.fixture(scope="module")
def static_pins():
    from components.static import static_statistics
    out = {}
    for pin in ("one_plate", "both_plates"):
        sc = _machine(pin)
        stats, sols = static_statistics(sc, 1)
        out[pin] = (sc, sols[0], stats.summary())
    return out


def test_a_cantilever_pin_slopes_as_roark_under_its_bearings_static_load_and_a_two_plate_pin_does_not(static_pins):
    """In the static solution at condition 3: the cantilever pin's slope is Roark's W a²/(2EI) + M a/(EI) (1a + 3a;
    Timoshenko's end section turns without a shear term) and its deflection W a³/(3EI) + W a/(κGA) + M a²/(2EI)
    under the force W the beam carries and the moment M on the pin's slope from the contacts, its direction that of
    the load falling away from the shaft-side plate; a pin clamped in both plates under its centred bearing slopes
    by M L/(16 EI) alone (3d), the load's share none (1d at mid-span) — under a thousandth of the cantilever's.
    summary.json says the same: the pin slope keys are Roark's slope's magnitude in arcmin (1′ = π/10800 rad), the
    deflection keys Roark's deflection's, per planet too; the slope the bearing sees is the pin's slope against its
    planet's, |s_pin − s_planet|."""
    sc, sol, summary = static_pins["one_plate"]
    m = sc.model
    si = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced"}).si()
    EIp = si.bearing.elastic_modulus * math.pi * (2 * si.bearing.inner_raceway_radius) ** 4 / 64
    nu = si.bearing.poisson_ratio
    kGA = (6 * (1 + nu) / (7 + 6 * nu) * si.bearing.elastic_modulus / (2 * (1 + nu))
           * math.pi * (2 * si.bearing.inner_raceway_radius) ** 2 / 4)
    a = 0.02
    beam = m.element("pin_beam")
    slopes = {}
    for planet in ("a1", "b1"):
        i = [m.body_names[j // 3] for j in beam.dofs[:, 3]].index(f"{planet}.pin")
        qf, vf = m.full(sol.t, sol.q, sol.v)
        s = qf[beam.dofs[i, 6:8]]
        slopes[planet] = s
        # the beam's force on the pin and the moment on the pin's slope, from the element itself
        Fb, _, _, _ = evaluate(beam, sol.t, m.frame.at(sol.t), qf, vf, None, False)
        W = -Fb[i, 3:5]                  # what the pin puts on the beam: the bearing's load and the pin's inertia
        M = -Fb[i, 6:8]
        d = qf[beam.dofs[i, 3:5]] - qf[beam.dofs[i, 0:2]] - np.array(
            [np.cos(qf[beam.dofs[i, 2]]) * beam.marker_a[i, 0] - np.sin(qf[beam.dofs[i, 2]]) * beam.marker_a[i, 1],
             np.sin(qf[beam.dofs[i, 2]]) * beam.marker_a[i, 0] + np.cos(qf[beam.dofs[i, 2]]) * beam.marker_a[i, 1]])
        expect = -W * a ** 2 / (2 * EIp) + M * a / EIp
        np.testing.assert_allclose(s, expect, rtol=1e-9, atol=1e-9 * np.linalg.norm(expect))
        np.testing.assert_allclose(d, W * a ** 3 / (3 * EIp) + W * a / kGA - M * a ** 2 / (2 * EIp), rtol=1e-9,
                                   atol=1e-9 * np.linalg.norm(d))
        # the bearing's load dominates: the slope lies along the load (the moment's share is small)
        assert np.linalg.norm(W) > 5e3 and abs(np.dot(s, W)) > 0.99 * np.linalg.norm(s) * np.linalg.norm(W)
        assert np.linalg.norm(s) > np.radians(0.5 / 60)
        # summary.json (one static solution: mean = max = the solution's): Roark's slope and deflection
        d = summary["inner" if planet.startswith("a") else "outer"]
        arcmin = math.pi / 10800.0
        roark_slope = np.linalg.norm(expect) / arcmin
        roark_deflection = np.linalg.norm(W * a ** 3 / (3 * EIp) + W * a / kGA - M * a ** 2 / (2 * EIp))
        for key in ("pin_slope_mean_arcmin", "pin_slope_max_arcmin"):
            assert d[key] == pytest.approx(roark_slope, rel=1e-9), key
        assert d["pin_slope_mean_per_planet_arcmin"][0] == pytest.approx(roark_slope, rel=1e-9)
        assert d["pin_slope_max_per_planet_arcmin"][0] == pytest.approx(roark_slope, rel=1e-9)
        for key in ("pin_deflection_mean_m", "pin_deflection_max_m"):
            assert d[key] == pytest.approx(roark_deflection, rel=1e-9), key
        # the bearing sees its pin's slope against its planet's (the planet's slope pair from the solution)
        pairs = {m.body_names[m.extra_owner[i - m.n_body_coords]]: (i, j) for i, j in m.slope_pairs}
        planet_slope = qf[list(pairs[planet])]
        assert d["misalignment_mean_rad"] == pytest.approx(np.linalg.norm(s - planet_slope), rel=1e-9)
    sc2, sol2, summary2 = static_pins["both_plates"]
    m2 = sc2.model
    beam2 = m2.element("pin_beam")
    qf2, _ = m2.full(sol2.t, sol2.q, sol2.v)
    for planet in ("a1", "b1"):
        i = [m2.body_names[j // 3] for j in beam2.dofs[:, 3]].index(f"{planet}.pin")
        assert np.linalg.norm(qf2[beam2.dofs[i, 6:8]]) < 1e-3 * np.linalg.norm(slopes[planet])
        d2 = summary2["inner" if planet.startswith("a") else "outer"]
        assert d2["pin_slope_max_arcmin"] == pytest.approx(np.linalg.norm(qf2[beam2.dofs[i, 6:8]]) / (math.pi / 10800),
                                                           rel=1e-9)


def _perturbed(sc, seed):
    """The scene's kinematic state with every tilt coordinate (slopes, tilts) and the pins' centres and turns moved a
    little, and rates on them."""
    m = sc.model
    rng = np.random.default_rng(seed)
    q, v = sc.q0.copy(), sc.v0.copy()
    tilt = m.free >= m.n_body_coords
    q[tilt] += rng.uniform(-1e-4, 1e-4, tilt.sum())
    v[tilt] += rng.uniform(-0.05, 0.05, tilt.sum())
    for name in m.body_names:
        if name.endswith(".pin"):
            i = m.full_to_free[3 * m.body(name).index + np.arange(3)]
            q[i] += rng.uniform(-2e-6, 2e-6, 3) * (1, 1, 10)
            v[i] += rng.uniform(-1e-3, 1e-3, 3)
    return q, v


def test_the_elastic_machines_jacobian_in_its_pins_coordinates_matches_central_differences():
    """Every column of a pin (its centre, turn and slope pair): the assembled J_q and J_v — the beam, the pin's
    gyroscopic terms and the sliced inner raceway on the pin body twice (race body and pin body) — against central
    differences of the assembled forces."""
    sc = _machine("one_plate")
    m = sc.model
    q, v = _perturbed(sc, 8)
    system = mbd.System(m)
    z = system.init_internal()
    ev = system.evaluate(0.01, q, v, z, jac=True)
    _, C, K = system.matrices(ev)
    K, C = K.toarray(), C.toarray()
    pin = m.body("a1.pin").index
    beam = m.element("pin_beam")
    row = [m.body_names[j // 3] for j in beam.dofs[:, 3]].index("a1.pin")
    cols = m.full_to_free[np.r_[3 * pin + np.arange(3), beam.dofs[row, 6:8]]]
    for j in cols:
        for x, h, J in ((q, 1e-9, K), (v, 1e-6, C)):
            xp, xm = x.copy(), x.copy()
            xp[j] += h
            xm[j] -= h
            Fp = system.forces(0.01, *((xp, v) if x is q else (q, xp)), z)
            Fm = system.forces(0.01, *((xm, v) if x is q else (q, xm)), z)
            fd = (Fp - Fm) / (2 * h)
            np.testing.assert_allclose(-J[:, j], fd, rtol=0, atol=2e-6 * np.abs(fd).max() + 1e-6)


def test_the_elastic_machine_accelerates_alike_in_the_rotating_and_the_fixed_frame():
    """A state with deflected and sloped cantilever pins, tilted planets and rollers, seen from R and from I: every
    acceleration maps from R to I to round-off (the beam's damping on rates seen from the carrier, the pins' slopes
    and gyroscopic terms)."""
    from components.scene import SceneOptions
    ov = {"bearing.model": "sliced", "bearing.pin.model": "elastic", "bearing.pin.mounting": "one_plate"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = with_overrides(reference_dpgt(3, "forward"), ov)
        rot, fix = build_dpgt(p), build_dpgt(p, SceneOptions(frame="fixed"))
    mR, mI = rot.model, fix.model
    q, v = _perturbed(rot, 21)
    t = 0.004
    sysR = mbd.System(mR)
    F = sysR.evaluate(t, q, v, sysR.init_internal()).F
    qf, vf = mR.full(t, q, v)
    af = np.zeros_like(qf)
    af[mR.free] = F / mR.mdiag
    fs = mR.frame.at(t)
    X, V, A = (mR.poses(x) for x in (qf, vf, af))
    XI, VI, AI = mbd.to_fixed(X, V, fs, A)
    out = [np.array(x, float) for x in (qf, vf, af)]
    for o, arr in zip(out, (XI, VI, AI)):
        o[: mR.n_body_coords] = arr.ravel()
    for ix, iy in mR.slope_pairs:
        P3 = [np.array([[x[ix], x[iy], 0.0]]) for x in (qf, vf, af)]
        pI, vI, aI = mbd.to_fixed(*P3[:2], fs, P3[2])
        for o, arr in zip(out, (pI, vI, aI)):
            o[ix], o[iy] = arr[0, 0], arr[0, 1]
    qI, vI, a_expect = out
    sysI = mbd.System(mI)
    a_I = sysI.evaluate(t, qI[mI.free], vI[mI.free], sysI.init_internal()).F / mI.mdiag
    got = a_expect[mI.free]
    tilt = mI.free >= mI.n_body_coords
    for part in (~tilt, tilt):
        np.testing.assert_allclose(a_I[part], got[part], rtol=0, atol=1e-9 * np.abs(got[part]).max())


def _kinematic_run(sc, t):
    """The scene's run from its kinematic start (t = 0, ``sc.q0``) to ``t`` on the compiled engine with the production
    controller: a state on the machine's own trajectory during or after the load ramp. (``sc.q0`` itself is the state
    at t = 0 only: in R the ground turns at −Ω, so at a later time the ring's torsional support wants the ring
    elsewhere: at 1 ms of condition 3 it sits 0.44 rad off its support, a torque of 6.7 MN m.)"""
    return mbd.simulate(sc.model, sc.q0, sc.v0, t, controller=mbd.PRODUCTION.controller(), progress=False,
                        engine="compiled")


def test_the_elastic_machine_steps_alike_on_both_engines():
    """Ten fixed steps from the kinematic start's state at the load ramp's end, the pins loaded by their bearings and
    set moving and turning a little: the same step counts and states on the compiled and the numpy engine."""
    sc = _machine("one_plate")
    s = _kinematic_run(sc, sc.ramp).state
    q, v, t0 = s.q.copy(), s.v.copy(), s.t
    for name in sc.model.body_names:            # the pins moving off their loaded places, turning a little
        if name.endswith(".pin"):
            i = sc.model.full_to_free[3 * sc.model.body(name).index + np.arange(3)]
            v[i] += (1e-3, 0.0, 0.01)
    h = 5e-6
    run = lambda eng: mbd.simulate(sc.model, q, v, t0 + 10 * h, t0=t0, stepper=mbd.PRODUCTION.stepper(),   # noqa: E731
                                   controller=mbd.FixedStep(h), progress=False, engine=eng)
    rc, rn = run("compiled"), run("numpy")
    assert (rc.engine, rn.engine) == ("compiled", "numpy") and rc.counters == rn.counters
    np.testing.assert_allclose(rc.state.q, rn.state.q, rtol=0, atol=1e-10)
    np.testing.assert_allclose(rc.state.v, rn.state.v, rtol=0, atol=1e-10 / h)


def test_the_cantilever_pins_modes_are_damped_about_the_static_state(static_pins):
    """Linearised about the static solution at condition 3 (K = −∂F/∂q, C = −∂F/∂v, M; the model's exact Jacobians),
    the first-order system's eigenvalues: the modes carried by the pins (over half their kinetic energy in the pins'
    centres, turns and slopes) are the pins' five coordinates each, 6 × 5 pairs, and every one decays (Re λ < 0):
    no flutter of a pin in its beam, its bearing's contacts and their traction."""
    import scipy.linalg as sla

    from mbd.modal import linearize
    sc, sol, _ = static_pins["one_plate"]
    m = sc.model
    M, C, K = linearize(m, sol.t, sol.q, sol.v)
    n, mi = M.shape[0], 1.0 / np.diag(M)
    lam, V = sla.eig(np.block([[np.zeros((n, n)), np.eye(n)], [-mi[:, None] * K, -mi[:, None] * C]]))
    cols = m.full_to_free[m.element("pin_beam").dofs[:, 3:8].ravel()]
    energy = np.abs(V[:n]) ** 2 * np.diag(M)[:, None]
    pin = energy[cols].sum(0) > 0.5 * energy.sum(0)
    assert pin.sum() == 2 * 6 * 5
    assert lam.real[pin].max() < 0.0


def test_a_cantilever_pin_machine_run_from_its_kinematic_start_bends_its_pins_to_their_static_state(static_pins):
    """From the kinematic start through the load ramp and 1 ms beyond (compiled engine, production controller): every
    cantilever pin's slope and deflection over the last millisecond stay about their static values (the static
    solution of the same machine; its mean within 10 %, its largest within 1.5×), and its torsion below what its
    bearing's whole load at the pin's radius could twist it by (a traction coefficient of 1): the pins bend and settle,
    they do not flutter."""
    sc, sol, _ = static_pins["one_plate"]
    m = sc.model
    system = mbd.System(m)
    beam = m.element("pin_beam")
    static = system.outputs(sol.t, sol.q, sol.v, system.init_internal(), families=["pin_beam"])["pin_beam"]
    s_static = np.hypot(static["slope_x"], static["slope_y"])
    r = _kinematic_run(sc, sc.ramp)
    theta = m.full_to_free[3 * (beam.dofs[:, 3] // 3) + 2]
    carrier = m.full_to_free[3 * m.body("carrier").index + 2]
    slopes, deflections, torsions = [], [], []
    state = r.state
    for k in range(1, 11):                      # 10 samples over the millisecond after the ramp
        state = mbd.simulate(m, None, None, sc.ramp + k * 1e-4, state=state, controller=mbd.PRODUCTION.controller(),
                             progress=False, engine="compiled", system=system).state
        o = system.outputs(state.t, state.q, state.v, state.z, families=["pin_beam"])["pin_beam"]
        slopes.append(np.hypot(o["slope_x"], o["slope_y"]))
        deflections.append(o["deflection"])
        torsions.append(np.abs(state.q[theta] - state.q[carrier]))
    slopes, deflections, torsions = map(np.array, (slopes, deflections, torsions))
    np.testing.assert_allclose(slopes.mean(0), s_static, rtol=0.1)
    np.testing.assert_allclose(deflections.mean(0), static["deflection"], rtol=0.1)
    assert (slopes.max(0) < 1.5 * s_static).all() and (deflections.max(0) < 1.5 * static["deflection"]).all()
    load = np.hypot(static["fx"], static["fy"])
    si = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced"}).si()
    assert (torsions.max(0) < load * si.bearing.inner_raceway_radius / beam.k_theta).all()


def test_an_elastic_pin_run_records_its_bending_in_results_nc_and_summary(tmp_path):
    """A short dynamic run (from the static solution) of cantilever pins: results.nc holds each pin's bending slope
    (x, y in R and its magnitude, rad) and deflection (m) along ``pin_beam.instance`` (a1.pin …, with its bearing);
    the deflection is the pin's centre from its pinhole as the recorded body motion places them (the carrier's pose
    and the pinhole's place on it); the statistics take every step, so the summary's maximum slope is at least every
    recorded sample's in the window (and the mean, of a pin bent by its bearing's load, over half an arcminute as in the
    static solution)."""
    import xarray as xr

    from scenarios.core.runner import RunConfig, run_case

    p = with_overrides(reference_dpgt(3, "forward"), {"bearing.model": "sliced", "bearing.pin.model": "elastic",
                                                      "bearing.pin.mounting": "one_plate", "bearing.rollers": 8})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = run_case(p, RunConfig(settle=0.0005, window=0.0005, progress=False, start="static"), tmp_path / "run")
        sc = build_dpgt(p)
    ds = xr.open_dataset(tmp_path / "run" / "results.nc", engine="h5netcdf")
    assert list(ds["pin_beam.instance"].values) == ["a1.pin", "b1.pin", "a2.pin", "b2.pin", "a3.pin", "b3.pin"]
    assert list(ds["pin_beam.bearing"].values[:2]) == ["a1.pb", "b1.pb"]
    for key, unit in (("slope", "rad"), ("slope_x", "rad"), ("slope_y", "rad"), ("deflection", "m")):
        assert ds[f"pin_beam.{key}"].attrs["units"] == unit, key
    np.testing.assert_allclose(ds["pin_beam.slope"], np.hypot(ds["pin_beam.slope_x"], ds["pin_beam.slope_y"]),
                               rtol=1e-12)
    # the deflection from the recorded motion: pin centre − (carrier centre + Rot(θ_c) pinhole marker)
    beam = sc.model.element("pin_beam")
    pos = ds["motion.position"]
    ang = ds["motion.angle"].sel({"motion.body": "carrier"}).values
    c = pos.sel({"motion.body": "carrier"}).values
    for i, name in enumerate(ds["pin_beam.instance"].values):
        mx, my = beam.marker_a[i]
        hole = c + np.stack([np.cos(ang) * mx - np.sin(ang) * my, np.sin(ang) * mx + np.cos(ang) * my], axis=-1)
        d = np.linalg.norm(pos.sel({"motion.body": name}).values - hole, axis=-1)
        np.testing.assert_allclose(ds["pin_beam.deflection"].values[:, i], d, rtol=1e-6, atol=1e-12)
        assert d.min() > 1e-6                    # µm: the load bends the pin
    arcmin = math.pi / 10800.0
    for kind, i in (("inner", 0), ("outer", 1)):
        d = s[kind]
        t0, t1 = d["window_s"]
        w = ds["pin_beam.slope"].sel(time=slice(t0, t1)).values[:, i] / arcmin
        assert w.size >= 2
        assert d["pin_slope_max_arcmin"] >= w.max() * (1 - 1e-12)
        assert d["pin_slope_max_arcmin"] == d["pin_slope_max_per_planet_arcmin"][0]
        assert 0.5 < d["pin_slope_mean_arcmin"] <= d["pin_slope_max_arcmin"]
        dfl = ds["pin_beam.deflection"].sel(time=slice(t0, t1)).values[:, i]
        assert d["pin_deflection_max_m"] >= dfl.max() * (1 - 1e-12)
