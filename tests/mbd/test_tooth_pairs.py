"""The tooth-pair mesh law (docs/model.md §7, mbd.elements.tooth_pairs): transmission error tooth by tooth.

(a) numpy reference = compiled kernel (forces, Jacobians), Jacobians = finite differences, with deviations,
    relief, faults and eccentricity, also across the line of centres' branch cut and in a fused family;
(b) perfect teeth: the pair law is the rectangular lumped law (forces, Jacobians, outputs) to round-off;
(c) which tooth: a faulty tooth lowers the stiffness to c·k_single in its single contact and to
    k_double (1 + c)/2 in its double contact, once per revolution of its gear, nowhere else;
(d) geometry: a tooth turned by p acts like its gear turned by p/r_b while its pair is alone in contact;
    a profile slope rises towards the tip on the driving gear's flank as contact runs root → tip;
(e) the classic tip-relief result: linear relief of C_a = 2F(r − 1)/(r k_single) over the double-contact
    zones makes the static transmission error flat at the design load F.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from mbd import ModelError
from mbd.element import evaluate
from mbd.elements import GearMesh, StiffnessShape
from mbd.elements.tooth_pairs import ToothPairs, tooth_table

from tests.support.mesh import (FS0, K_MEAN, PAIRS, assert_matches_reference, fd_jacobians, full, libm_arctan2,
                                make_mesh, nominal, perturbed_state, rb)

EPS, SMOOTH, RATIO = 1.6, 0.05, 1.5
RECT = StiffnessShape.rectangular(EPS, ratio=RATIO, smoothing=SMOOTH)
DEV = 5e-6          # deviations [m]


def sigma(pair):
    return -1.0 if PAIRS[pair][0] else 1.0


def pairs_of(pair, n, *, entry=0.0, entry_coast=None, phase2=0.0, phase2_coast=None, excess=(None, None),
             factor=(None, None), relief1=(0.0, 0.0, 1.0), relief2=(0.0, 0.0, 1.0)):
    """ToothPairs of n meshes sharing gear 1's and gear 2's tooth tables."""
    internal, z1, z2 = PAIRS[pair]
    t1, t2 = tooth_table(z1, excess[0], factor[0]), tooth_table(z2, excess[1], factor[1])
    e = np.column_stack(np.broadcast_arrays(entry, entry if entry_coast is None else entry_coast, np.zeros(n))[:2])
    c = np.column_stack(np.broadcast_arrays(phase2, phase2 if phase2_coast is None else phase2_coast, np.zeros(n))[:2])
    return ToothPairs(entry=e, phase2=c, relief1=np.array(relief1, float), relief2=np.array(relief2, float),
                      table=np.concatenate([t1, t2]), start1=np.zeros(n), start2=np.full(n, float(t1.size)))


def random_case(pair, seed, n=12, near_pi=False, offsets=False, ramp=0.0):
    """(family, q, v): random deviations on both gears, a missing and a cracked tooth, relief on both, and
    (``offsets``) eccentric gears, in perturbed states around nominal poses; ``ramp`` the damping ramp δ_c."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(seed)
    psi = np.pi + rng.uniform(-3e-4, 3e-4, n) if near_pi else None
    p1, p2, q, v = perturbed_state(pair, rng, n, psi=psi)
    f1, f2 = np.ones(z1), np.ones(z2)
    f1[rng.integers(z1)], f2[rng.integers(z2)] = 0.0, 0.4
    pp = pairs_of(pair, n, entry=rng.uniform(0, 3, n), entry_coast=rng.uniform(0, 3, n),
                  phase2=rng.uniform(-3, 3, n), phase2_coast=rng.uniform(-3, 3, n),
                  excess=(rng.normal(0, DEV, (z1, 2, 4)), rng.normal(0, DEV, (z2, 2, 4))), factor=(f1, f2),
                  relief1=(8e-6, 0.7, 2.0), relief2=(6e-6, 0.75, 1.0))
    kw = dict(offset1=rng.normal(0, 2e-5, (n, 2)), offset2=rng.normal(0, 2e-5, (n, 2))) if offsets else {}
    return make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, damping_ramp=ramp, p0=rng.uniform(), backlash=1e-5,
                     pairs=pp, **kw), q, v


def smooth_instances(elem, q, v, rtol=1e-6):
    """Instances whose finite-difference Jacobians at two step sizes agree (no contact switch within reach)."""
    (Aq, Av), (Bq, Bv) = fd_jacobians(elem, q, v), fd_jacobians(elem, q, v, hq=2.5e-9, hv=2.5e-5)
    ok = np.ones(elem.n, bool)
    for A, B in ((Aq, Bq), (Av, Bv)):
        scale = np.maximum(np.abs(A).max(axis=(1, 2)), 1.0)
        ok &= np.abs(A - B).max(axis=(1, 2)) <= rtol * scale
    return ok, Aq, Av


# ----------------------------------------------------------------------------------------------------
# (a) reference vs compiled, finite differences
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("near_pi, ramp", [(False, 0.0), (True, 0.0), (False, 2e-5)])
@pytest.mark.parametrize("offsets", [False, True])
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_pair_law_matches_compiled_and_finite_differences(pair, offsets, near_pi, ramp):
    checked = loaded = 0
    for seed in range(3):
        elem, q, v = random_case(pair, seed, near_pi=near_pi, offsets=offsets, ramp=ramp)
        with libm_arctan2():
            assert_matches_reference(elem, 0.0, FS0, q, v)
        F, out, Jq, Jv = evaluate(elem, 0.0, FS0, q, v, None, True)
        ok, fq, fv = smooth_instances(elem, q, v)
        for J, Jf in ((Jq, fq), (Jv, fv)):
            scale = np.maximum(np.abs(Jf).max(axis=(1, 2)), 1.0)[ok]
            err = np.abs(J - Jf).max(axis=(1, 2))[ok]
            assert np.all(err <= 1e-6 * scale), err / scale
        loaded_now = (out["force_drive"] + out["force_coast"] > 0) & ok
        checked += ok.sum()
        loaded += loaded_now.sum()
    assert checked >= 18 and loaded >= 6


def test_fused_pair_families_match_reference():
    """Families of different kinds fuse: tables appended, offsets moved; compiled = reference."""
    parts, qs, vs = [], [], []
    for pair, seed in (("sun_planet", 3), ("planet_ring", 4)):
        e, q, v = random_case(pair, seed, n=4)
        e.dofs = e.dofs + sum(x.size for x in qs)
        parts.append(e)
        qs.append(q)
        vs.append(v)
    fused = GearMesh.fuse(parts)
    q, v = np.concatenate(qs), np.concatenate(vs)
    with libm_arctan2():
        assert_matches_reference(fused, 0.0, FS0, q, v)
    F = evaluate(fused, 0.0, FS0, q, v, None, False)[0]
    for k, part in enumerate(parts):
        Fk = evaluate(part, 0.0, FS0, q, v, None, False)[0]
        np.testing.assert_array_equal(F[4 * k:4 * k + 4], Fk)


# ----------------------------------------------------------------------------------------------------
# (b) perfect teeth: the rectangular law
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_perfect_teeth_are_the_rectangular_law(pair):
    """Zero deviations, no relief, no fault, each flank's pairs phased like the lumped wave: forces,
    Jacobians and outputs equal the lumped rectangular law's to round-off: 1e-12 of the block's size
    (measured up to 2.3e-13: the pairs' shares are summed, the lumped law multiplies once)."""
    rng = np.random.default_rng(7)
    n = 24
    p1, p2, q, v = perturbed_state(pair, rng, n)
    p0 = rng.uniform(0, 1, n)
    lumped = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=p0, backlash=1e-5)
    paired = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=p0, backlash=1e-5,
                       pairs=pairs_of(pair, n, entry=p0 + rng.integers(-3, 3, n), phase2=rng.uniform(-9, 9, n)))
    F, out, Jq, Jv = evaluate(lumped, 0.0, FS0, q, v, None, True)
    G, out2, Gq, Gv = evaluate(paired, 0.0, FS0, q, v, None, True)
    for a, b in ((F, G), (Jq, Gq), (Jv, Gv)):
        scale = np.abs(a).reshape(n, -1).max(axis=1)
        assert np.all(np.abs(a - b).reshape(n, -1).max(axis=1) <= 1e-12 * np.maximum(scale, 1e-300))
    for key in ("force_drive", "force_coast", "stiffness"):
        np.testing.assert_allclose(out2[key], out[key], rtol=1e-12, atol=1e-9)
    assert (out["force_drive"] > 0).sum() >= 4 and (out["force_coast"] > 0).sum() >= 4
    with libm_arctan2():
        assert_matches_reference(paired, 0.0, FS0, q, v)


# ----------------------------------------------------------------------------------------------------
# (c) which tooth
# ----------------------------------------------------------------------------------------------------
def rigid_rotation(pair, cycles, per=40, seed=41):
    """Gear 1 and 2 at fixed centres rolling rigidly over ``cycles`` mesh cycles from a random start:
    (N1, N2 nominal poses per sample, q, v, P_rel mesh cycles from the start)."""
    internal, z1, z2 = PAIRS[pair]
    sig, r1, r2 = sigma(pair), rb(z1), rb(z2)
    P_rel = np.arange(int(cycles * per)) / per + 0.5 / per
    dth1 = 2 * np.pi * P_rel / z1
    P1, P2 = nominal(pair, 1, np.random.default_rng(seed), angle_span=3.0)
    m = dth1.size
    p1, p2 = np.repeat(P1, m, axis=0), np.repeat(P2, m, axis=0)
    p1[:, 2] += dth1
    p2[:, 2] += -sig * (r1 / r2) * dth1
    return np.repeat(P1, m, axis=0), np.repeat(P2, m, axis=0), full(p1, p2), np.zeros(6 * m), P_rel


def _gear_phases(elem, q):
    """(P, Q) of the samples without the entries: z1(θ1 − φ_e)/2π and −σ z2(θ2 − φ_e)/2π (unwrapped)."""
    ql = q[elem.dofs]
    d = elem.sigma[:, None] * (ql[:, 3:5] - ql[:, 0:2])
    phi = elem.phi_ref + np.angle(np.exp(1j * (np.arctan2(d[:, 1], d[:, 0]) - elem.phi_ref)))
    return (elem.teeth1 * (ql[:, 2] - phi) / (2 * np.pi),
            -elem.sigma * elem.teeth2 * (ql[:, 5] - phi) / (2 * np.pi))


@pytest.mark.parametrize("c", [0.3, 0.0])
@pytest.mark.parametrize("gear", [1, 2])
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_faulty_tooth_stiffness_over_a_rigid_rotation(pair, gear, c):
    """Two revolutions of the faulty gear, 40 samples per mesh cycle. The mesh cycles are counted from the
    rotation; the entries are set so that the faulty tooth's pair enters at cycle 5: the pair of gear-1
    tooth i enters at P ≡ −i, that of gear-2 tooth k at Q ≡ σk."""
    internal, z1, z2 = PAIRS[pair]
    zf = z1 if gear == 1 else z2
    N1, N2, q, v, P_rel = rigid_rotation(pair, 2 * zf)
    m = P_rel.size
    probe = make_mesh(pair, N1, N2, shape=RECT)
    P0, Q0 = _gear_phases(probe, q)
    entry = P_rel[0] - P0[0]                      # P = P_rel
    phase2 = P_rel[0] - Q0[0]                     # Q = P_rel too (rolling keeps Q − P)
    enter = 5
    tooth = int(np.mod(-enter, z1)) if gear == 1 else int(np.mod(sigma(pair) * enter, z2))
    factors = [None, None]
    factors[gear - 1] = np.where(np.arange(zf) == tooth, c, 1.0)
    healthy = make_mesh(pair, N1, N2, shape=RECT, pairs=pairs_of(pair, m, entry=entry, phase2=phase2))
    faulty = make_mesh(pair, N1, N2, shape=RECT, pairs=pairs_of(pair, m, entry=entry, phase2=phase2, factor=factors))
    k_h = evaluate(healthy, 0.0, FS0, q, v, None, False)[1]["stiffness"]
    k = evaluate(faulty, 0.0, FS0, q, v, None, False)[1]["stiffness"]
    u = np.mod(P_rel - enter, zf)
    h = SMOOTH / 2
    single = (u >= EPS - 1 + h) & (u <= 1 - h)
    double = ((u >= h) & (u <= EPS - 1 - h)) | ((u >= 1 + h) & (u <= EPS - h))
    outside = (u >= EPS + h) & (u <= zf - h)
    assert single.sum() >= 20 and double.sum() >= 20
    np.testing.assert_allclose(k_h[single], K_MEAN * RECT.single, rtol=1e-12)
    np.testing.assert_allclose(k[single], c * K_MEAN * RECT.single, rtol=1e-12, atol=1e-3)
    np.testing.assert_allclose(k_h[double], K_MEAN * RECT.double, rtol=1e-12)
    np.testing.assert_allclose(k[double], K_MEAN * RECT.double * (1 + c) / 2, rtol=1e-12)
    np.testing.assert_array_equal(k[outside], k_h[outside])
    changed = k != k_h
    starts = np.flatnonzero(changed & ~np.roll(changed, 1))
    assert starts.size == 2
    np.testing.assert_allclose(np.diff(P_rel[starts]), zf, atol=1.0 / 40)


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_tooth_identities_are_immune_to_the_branch_of_the_line_of_centres(pair):
    """A rigid rotation of the whole pair (centres and gears, deviations, eccentricity) through φ_e = ±π
    changes nothing, although φ_e jumps by 2π (phi_ref = 0)."""
    internal, z1, z2 = PAIRS[pair]
    rng = np.random.default_rng(51)
    n = 6
    P1, P2 = nominal(pair, n, rng, psi=np.pi - 0.01)
    pp = pairs_of(pair, n, entry=rng.uniform(0, 3, n), phase2=rng.uniform(-3, 3, n),
                  excess=(rng.normal(0, DEV, (z1, 2, 4)), rng.normal(0, DEV, (z2, 2, 4))),
                  factor=(rng.uniform(0.2, 1, z1), rng.uniform(0.2, 1, z2)))
    elem = make_mesh(pair, P1, P2, shape=RECT, offset1=rng.normal(0, 2e-5, (n, 2)),
                     offset2=rng.normal(0, 2e-5, (n, 2)), pairs=pp)
    ref = None
    for beta in (0.0, 0.005, 0.015, 0.03):                         # φ_e: π − 0.01 → −π + 0.02
        R = np.array([[np.cos(beta), -np.sin(beta)], [np.sin(beta), np.cos(beta)]])
        q1, q2 = P1.copy(), P2.copy()
        q1[:, :2], q2[:, :2] = P1[:, :2] @ R.T, P2[:, :2] @ R.T
        q1[:, 2] += beta
        q2[:, 2] += beta
        F, out, _, _ = evaluate(elem, 0.0, FS0, full(q1, q2), np.zeros(6 * n), None, False)
        got = np.array([out["stiffness"], out["force_drive"], out["force_coast"]])
        if ref is None:
            ref = got
            assert np.any(got[1:] > 0)
        np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-6)


# ----------------------------------------------------------------------------------------------------
# (d) geometry of the deviations
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("flank", [1, -1])
@pytest.mark.parametrize("gear", [1, 2])
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_a_turned_tooth_acts_like_its_gear_turned(pair, gear, flank):
    """Tooth 3 of gear ``gear`` turned counter-clockwise by p (pitch deviation p on both its flanks), at a
    fixed compression of the loaded flank over one revolution: while that tooth's pair is alone in contact
    the flank force equals that of perfect teeth with the whole gear turned by p/r_b; elsewhere the turned
    tooth changes nothing; this happens in one window of single contact per revolution."""
    internal, z1, z2 = PAIRS[pair]
    zb = z1 if gear == 1 else z2
    sig, r1, r2 = sigma(pair), rb(z1), rb(z2)
    N1, N2, q, v, P_rel = rigid_rotation(pair, zb, per=20, seed=61)
    m = P_rel.size
    # compress the loaded flank by 10 µm: turn gear 1 so that f·(σ r_b1 Δθ1) = 10 µm
    q = q.reshape(-1, 3)
    q[:m, 2] += flank * sig * 1e-5 / r1
    q = q.ravel()
    p = 4e-6
    ex = np.zeros((zb, 2, 4))
    ex[3, :, 0] = [p, -p]                                     # ccw face +p, cw face −p: the tooth turned ahead
    excess = (ex, None) if gear == 1 else (None, ex)
    pp = dict(entry=0.3, entry_coast=0.8, phase2=0.3 - 2.0, phase2_coast=0.8 + 1.0)
    turned = make_mesh(pair, N1, N2, shape=RECT, pairs=pairs_of(pair, m, excess=excess, **pp))
    perfect = make_mesh(pair, N1, N2, shape=RECT, pairs=pairs_of(pair, m, **pp))
    key = "force_drive" if flank > 0 else "force_coast"
    F_dev = evaluate(turned, 0.0, FS0, q, v, None, False)[1][key]
    F_0 = evaluate(perfect, 0.0, FS0, q, v, None, False)[1][key]
    qg = q.reshape(-1, 3).copy()
    qg[(0 if gear == 1 else m):(m if gear == 1 else 2 * m), 2] += p / (r1 if gear == 1 else r2)
    F_gear = evaluate(perfect, 0.0, FS0, qg.ravel(), v, None, False)[1][key]
    assert np.all(F_0 > 0)
    same = np.isclose(F_dev, F_gear, rtol=1e-9, atol=0.0) & ~np.isclose(F_gear, F_0, rtol=1e-3)
    untouched = F_dev == F_0
    assert untouched.sum() >= m - 2 * EPS * 20 - 2              # all but the tooth's own pairs
    runs = np.flatnonzero(same & ~np.roll(same, 1))
    assert runs.size == 1                                        # one window per revolution
    width = same.sum() / 20.0                                    # in mesh cycles
    assert (2 - EPS) - SMOOTH - 0.1 <= width <= (2 - EPS) + 0.1


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_profile_slope_rises_towards_the_tip_of_the_driving_gear(pair):
    """Profile slope deviation f_Hα > 0 on every tooth of gear 1 (more material at its tips). On the
    driving gear contact runs from the root to the tip: rolling forward at a fixed compression, the force of
    single contact grows on the flank where gear 1 drives (its torque opposes its rotation) and falls on the
    other, by k_single·f_Hα/ε per mesh cycle."""
    internal, z1, z2 = PAIRS[pair]
    sig, r1 = sigma(pair), rb(z1)
    f_Ha = 6e-6
    N1, N2, q0, v, P_rel = rigid_rotation(pair, 3, per=100, seed=71)
    m = P_rel.size
    ex = np.zeros((z1, 2, 4))
    ex[:, :, 1] = 0.5 * f_Ha
    for flank in (1, -1):
        q = q0.reshape(-1, 3).copy()
        q[:m, 2] += flank * sig * 1.5e-5 / r1
        q = q.ravel()
        elem = make_mesh(pair, N1, N2, shape=RECT, pairs=pairs_of(pair, m, entry=0.0, excess=(ex, None)))
        F, out, _, _ = evaluate(elem, 0.0, FS0, q, v, None, False)
        key = "force_drive" if flank > 0 else "force_coast"
        gear1_drives = F[np.argmax(out[key]), 2] < 0              # rolling forward: ω1 > 0
        u = np.mod(_gear_phases(elem, q)[0], 1.0)
        single = (u > EPS - 1 + SMOOTH) & (u < 1 - SMOOTH)
        assert single.sum() > 60
        slope = np.polyfit(u[single], out[key][single], 1)[0]
        expect = K_MEAN * RECT.single * f_Ha / EPS
        assert slope == pytest.approx(expect if gear1_drives else -expect, rel=1e-6)


# ----------------------------------------------------------------------------------------------------
# (e) tip relief: the flat transmission error of the design load
# ----------------------------------------------------------------------------------------------------
def _static_te(one, q, load):
    """The compression δ of flank +1 at which the mesh force of ``one`` (a single mesh) equals ``load``, at
    every sample of q (gear 1 turned to compress)."""
    q = q.reshape(-1, 3)
    m = q.shape[0] // 2
    sig, r1 = one.sigma[0], one.rb1[0]
    out = np.empty(m)
    for i in range(m):
        def force(d):
            qq = q[[i, m + i]].copy()
            qq[0, 2] += sig * d / r1
            return evaluate(one, 0.0, FS0, qq.ravel(), np.zeros(6), None, False)[1]["force_drive"][0] - load
        out[i] = brentq(force, -1e-6, 2e-4, xtol=1e-15)
    return out


def test_linear_tip_relief_flattens_the_transmission_error_at_its_design_load():
    """External mesh, flank +1 (gear 1 drives, contact from gear 1's root): linear tip relief on both gears
    over the roll length of double contact, C_a = 2F(r − 1)/(r k_single). In double contact the two pairs
    then carry r/2·k_single (2δ − C_a) = F at δ = F/k_single, the single-contact compression: the static
    transmission error is flat (only the smoothing ramps remain), while without relief it steps by
    F/k_single·(1 − 1/r). At twice the load the step comes back (half of it)."""
    pair = "planet_planet"
    N1, N2, q, v, P_rel = rigid_rotation(pair, 1, per=60, seed=81)
    k_s = K_MEAN * RECT.single
    F = 4000.0
    C_a = 2 * F * (RATIO - 1) / (RATIO * k_s)
    xi_a = 1 - (EPS - 1) / EPS                     # relief over the double-contact roll length
    relieved = make_mesh(pair, N1[:1], N2[:1], shape=RECT, pairs=pairs_of(pair, 1, relief1=(C_a, xi_a, 1.0),
                                                                          relief2=(C_a, xi_a, 1.0)))
    plain = make_mesh(pair, N1[:1], N2[:1], shape=RECT, pairs=pairs_of(pair, 1))
    u = np.mod(_gear_phases(make_mesh(pair, N1, N2, shape=RECT), q)[0], 1.0)
    far = (np.abs(u - 0.0) > SMOOTH) & (np.abs(u - 1.0) > SMOOTH) & (np.abs(u - (EPS - 1)) > SMOOTH)
    te_plain = _static_te(plain, q, F)[far]
    te_rel = _static_te(relieved, q, F)[far]
    step = F / k_s * (1 - 1 / RATIO)
    assert np.ptp(te_plain) == pytest.approx(step, rel=1e-6)
    assert np.ptp(te_rel) < 1e-6 * step
    np.testing.assert_allclose(te_rel, F / k_s, rtol=1e-9)
    te2 = _static_te(relieved, q, 2 * F)[far]
    assert np.ptp(te2) == pytest.approx(0.5 * 2 * step, rel=1e-6)


def test_pair_parameters_are_validated():
    internal, z1, z2 = PAIRS["sun_planet"]
    rng = np.random.default_rng(1)
    p1, p2, q, v = perturbed_state("sun_planet", rng, 2)
    good = pairs_of("sun_planet", 2)
    make_mesh("sun_planet", p1, p2, shape=RECT, pairs=good)
    with pytest.raises(ModelError, match="rectangular"):
        make_mesh("sun_planet", p1, p2, shape="constant", pairs=good)
    bad = [dict(relief1=(1e-6, 1.0, 1.0)), dict(relief2=(1e-6, 0.5, 3.0)), dict(relief1=(-1e-6, 0.5, 1.0)),
           dict(factor=(np.full(z1, 1.5), None))]
    for kw in bad:
        with pytest.raises(ModelError, match="relief|stiffness factors"):
            make_mesh("sun_planet", p1, p2, shape=RECT, pairs=pairs_of("sun_planet", 2, **kw))
    short = ToothPairs(good.entry, good.phase2, good.relief1, good.relief2, good.table[:-1], good.start1, good.start2)
    with pytest.raises(ModelError, match="start2"):
        make_mesh("sun_planet", p1, p2, shape=RECT, pairs=short)
