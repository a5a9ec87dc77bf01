"""Gear-mesh eccentricity (docs/model.md §6.4, §11.2): the law on the geometric centres, in the numpy reference and
the compiled kernel. (Tooth faults and deviations: the tooth-pair law, tests/mbd/test_tooth_pairs.py.)

(a) reference vs compiled forces and Jacobians, and Jacobians vs finite differences, with offsets, also
    with the line of centres near ±π;
(b) no error (the default, explicit zero offsets) is bit-for-bit the error-free evaluation, also inside a
    fused family that mixes plain and eccentric meshes;
(c) eccentricity: the static deflection of a rigidly rolling pair follows the first-order law
    Δδ_f = ∂δ_f/∂d · Δd once per revolution of the eccentric gear; forces and moments balance exactly.
"""
from __future__ import annotations

import numpy as np
import pytest

from mbd import ModelError
from mbd.compiled import mesh
from mbd.element import evaluate
from mbd.elements import GearMesh, StiffnessShape

from tests.support.mesh import (ALPHA, FS0, K_MEAN, PAIRS, a0_of, assert_matches_reference, compiled, far_from_kinks,
                                full, jac_check, libm_arctan2, make_mesh, nominal, perturbed_state, rb)
from tests.support.strategies import assert_third_law

ECC = 2e-5               # eccentricity [m] (20 µm)
EPS, SMOOTH = 1.6, 0.05  # contact ratio and ramp width of the mesh
RECT = StiffnessShape.rectangular(EPS, ratio=1.5, smoothing=SMOOTH)


def sigma(pair):
    return -1.0 if PAIRS[pair][0] else 1.0


def rotated(o, th):
    """R(θ)·o for (n, 2) offsets and (n,) angles."""
    c, s = np.cos(th), np.sin(th)
    return np.column_stack([c * o[:, 0] - s * o[:, 1], s * o[:, 0] + c * o[:, 1]])


def error_case(pair, seed, near_pi=False, n=8):
    """(family, q, v) with random offsets on both gears, in perturbed states."""
    rng = np.random.default_rng(seed)
    psi = np.pi + rng.uniform(-3e-4, 3e-4, n) if near_pi else None
    p1, p2, q, v = perturbed_state(pair, rng, n, psi=psi)
    kw = dict(offset1=rng.normal(0.0, ECC, (n, 2)), offset2=rng.normal(0.0, ECC, (n, 2)))
    elem = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=rng.uniform(), **kw)
    return elem, q, v


# ----------------------------------------------------------------------------------------------------
# (a) reference vs compiled, and finite differences
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("near_pi", [False, True])
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_errors_match_reference_and_finite_differences(pair, near_pi):
    checked, sides = 0, set()
    for seed in range(4):
        elem, q, v = error_case(pair, seed, near_pi)
        assert elem.has_offset
        if near_pi:        # the line of centres on both sides of the branch cut
            ql = q[elem.dofs]
            d = elem.sigma[:, None] * (ql[:, 3:5] - ql[:, 0:2])
            angle = np.arctan2(d[:, 1], d[:, 0])
            assert np.abs(angle).min() > 3.0
            sides |= set(np.sign(angle))
        with libm_arctan2():
            assert_matches_reference(elem, 0.0, FS0, q, v)
        if far_from_kinks(elem, q, v):
            jac_check(elem, q, v)
            checked += 1
    assert checked >= 1
    assert sides == ({-1.0, 1.0} if near_pi else set())


def test_fused_error_family_matches_reference():
    """A fused family (plain external + eccentric internal) in the compiled kernel."""
    parts, qs, vs = [], [], []
    for pair, errors in (("sun_planet", None), ("planet_ring", "both")):
        if errors is None:
            rng = np.random.default_rng(5)
            p1, p2, q, v = perturbed_state(pair, rng, 3)
            e = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=0.3, name=pair)
        else:
            e, q, v = error_case(pair, 6, n=4)
        e.dofs = e.dofs + sum(x.size for x in qs)
        parts.append(e)
        qs.append(q)
        vs.append(v)
    fused = GearMesh.fuse(parts)
    assert fused.has_offset
    with libm_arctan2():
        assert_matches_reference(fused, 0.0, FS0, np.concatenate(qs), np.concatenate(vs))


# ----------------------------------------------------------------------------------------------------
# (b) no error: exactly the error-free evaluation
# ----------------------------------------------------------------------------------------------------
def _all_outputs(elem, q, v):
    F, out, Jq, Jv = evaluate(elem, 0.0, FS0, q, v, None, True)
    F0, out0, _, _ = evaluate(elem, 0.0, FS0, q, v, None, False)
    return (F, Jq, Jv, F0, *compiled(elem, 0.0, FS0, q, v)), out0


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_zero_offsets_are_bit_for_bit(pair):
    rng = np.random.default_rng(11)
    n = 6
    p1, p2, q, v = perturbed_state(pair, rng, n)
    plain = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=0.4)
    quiet = make_mesh(pair, p1, p2, shape=RECT, c_mesh=2e3, p0=0.4, offset1=np.zeros((n, 2)), offset2=(0.0, 0.0))
    assert not quiet.has_offset
    (P, G), (Pq, Gq) = mesh.pack_gear_mesh(plain), mesh.pack_gear_mesh(quiet)
    assert P.shape == (n, 19) and list(G) == [mesh.SHAPE_RECTANGULAR, -1, -1, 4]  # no error columns or tables
    np.testing.assert_array_equal(Pq, P)
    np.testing.assert_array_equal(Gq, G)
    (ref, out), (got, out_q) = _all_outputs(plain, q, v), _all_outputs(quiet, q, v)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)
    for key in out:
        np.testing.assert_array_equal(out_q[key], out[key])


def test_fusing_plain_and_error_families_keeps_each_instance_exact():
    """The fused family evaluates the offsets for all its instances; the plain ones (zero offsets) still get
    exactly their own values, the eccentric ones exactly theirs (numpy and compiled)."""
    rng = np.random.default_rng(12)
    p1, p2, qa, va = perturbed_state("sun_planet", rng, 3)
    plain = make_mesh("sun_planet", p1, p2, shape=RECT, c_mesh=2e3, p0=0.2, name="plain")
    err, qb, vb = error_case("planet_ring", 13, n=5)
    shifted = GearMesh.fuse([err])            # the same family with its bodies after the plain one's
    shifted.dofs = err.dofs + qa.size
    fused = GearMesh.fuse([plain, shifted])
    assert fused.has_offset and mesh.pack_gear_mesh(fused)[0].shape == (8, 19 + 4)
    q, v = np.concatenate([qa, qb]), np.concatenate([va, vb])
    (got, _), (ref_a, _), (ref_b, _) = _all_outputs(fused, q, v), _all_outputs(plain, qa, va), _all_outputs(err, qb, vb)
    for g, a, b in zip(got, ref_a, ref_b):
        np.testing.assert_array_equal(g[:3], a)
        np.testing.assert_array_equal(g[3:], b)


# ----------------------------------------------------------------------------------------------------
# (c) eccentricity: kinematics and balance
# ----------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("gear", [1, 2])
@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_eccentricity_deflection_follows_the_first_order_law(pair, gear):
    """Fixed centres, both gears rolling rigidly (Δθ2 = −σ r_b1/r_b2 Δθ1, zero error without offsets),
    gear ``gear`` eccentric by e at phase γ. The geometric centre vector changes by
    Δd = σ (R(θ2) o2 − R(θ1) o1), so to first order Δδ_f = ∂δ_f/∂d · Δd with
    ∂δ_f/∂d = −f κ t − σ sin α e, κ = cos α at a = a0: |∂δ_f/∂d| = 1, i.e. each flank's deflection
    swings by exactly ±e (the eccentricity on its line of action), once per revolution of that gear.
    The remainder is second order, bounded by e²/a0·(1 + (r_b1 + r_b2)/a0)."""
    internal, z1, z2 = PAIRS[pair]
    sig, r1, r2, a0 = sigma(pair), rb(z1), rb(z2), a0_of(internal, z1, z2)
    rng = np.random.default_rng(21)
    P1, P2 = nominal(pair, 1, rng, angle_span=3.0)
    m = 96
    turn = np.linspace(0.0, 2 * np.pi, m, endpoint=False)            # one revolution of the eccentric gear
    dth1 = turn if gear == 1 else -sig * (r2 / r1) * turn
    p1, p2 = np.repeat(P1, m, axis=0), np.repeat(P2, m, axis=0)
    p1[:, 2] += dth1
    p2[:, 2] += -sig * (r1 / r2) * dth1
    gamma = rng.uniform(-np.pi, np.pi)
    o = np.zeros((m, 2))
    o[:] = ECC * np.array([np.cos(gamma), np.sin(gamma)])
    kw = {"offset1": o} if gear == 1 else {"offset2": o}
    q, v = full(p1, p2), np.zeros(6 * m)
    N1, N2 = np.repeat(P1, m, axis=0), np.repeat(P2, m, axis=0)    # u0 from the nominal poses
    out0 = evaluate(make_mesh(pair, N1, N2, shape=RECT), 0.0, FS0, q, v, None, False)[1]
    out = evaluate(make_mesh(pair, N1, N2, shape=RECT, **kw), 0.0, FS0, q, v, None, False)[1]
    assert np.abs(out0["deflection"]).max() < 1e-12            # rigid rolling: no error without offsets
    d = sig * (P2[0, :2] - P1[0, :2])
    e = d / np.linalg.norm(d)
    t = np.array([-e[1], e[0]])
    dd = sig * (rotated(o, p2[:, 2]) if gear == 2 else -rotated(o, p1[:, 2]))
    bound = ECC**2 / a0 * (1.0 + (r1 + r2) / a0)
    for f, key in ((1.0, "deflection"), (-1.0, "deflection_coast")):
        grad = -f * np.cos(ALPHA) * t - sig * np.sin(ALPHA) * e
        assert np.linalg.norm(grad) == pytest.approx(1.0, rel=1e-12)
        pred = dd @ grad
        got = out[key] - out0[key]
        assert np.abs(got - pred).max() < bound, (np.abs(got - pred).max(), bound)
        # the spectrum over the revolution: the first harmonic with amplitude e, nothing else above the bound
        spec = 2.0 * np.abs(np.fft.rfft(got)) / m
        assert spec[1] == pytest.approx(ECC, abs=bound)
        assert np.delete(spec, 1).max() < bound


@pytest.mark.parametrize("pair", sorted(PAIRS))
def test_eccentric_mesh_forces_and_moments_balance(pair):
    """Σ F = 0 and the moments about any point vanish with the offsets' moments included; the force acts
    at the geometric centre: T_b = (mesh torque) + (R(θ_b) o_b) × F_b."""
    internal, z1, z2 = PAIRS[pair]
    sig = sigma(pair)
    elem, q, v = error_case(pair, 31, n=8)
    elem.offset1 *= 50.0                         # 1 mm: the offset moments are not negligible
    elem.offset2 *= 50.0
    F, out, _, _ = evaluate(elem, 0.0, FS0, q, v, None, False)
    loaded = np.abs(out["force"]) > 0
    assert loaded.sum() >= 2
    ql = q[elem.dofs]
    fx, fy, T = F[:, [0, 3]], F[:, [1, 4]], F[:, [2, 5]]
    x, y = ql[:, [0, 3]], ql[:, [1, 4]]
    tol = 1e-12 * np.abs(F).max()
    np.testing.assert_allclose(fx.sum(1), 0.0, atol=tol)
    np.testing.assert_allclose(fy.sum(1), 0.0, atol=tol)
    for px, py in ((0.0, 0.0), (0.37, -1.2)):
        moment = (T + (x - px) * fy - (y - py) * fx).sum(1)
        np.testing.assert_allclose(moment, 0.0, atol=tol * (1.0 + np.abs(ql[:, [0, 1, 3, 4]]).max() + 1.3))
    assert_third_law(elem, 0.0, FS0, q, v, rtol=1e-12)
    r1, r2 = rotated(elem.offset1, ql[:, 2]), rotated(elem.offset2, ql[:, 5])
    np.testing.assert_allclose(T[:, 0], -sig * rb(z1) * out["force"] + r1[:, 0] * F[:, 1] - r1[:, 1] * F[:, 0],
                               atol=tol * rb(z2))
    np.testing.assert_allclose(T[:, 1], -rb(z2) * out["force"] + r2[:, 0] * F[:, 4] - r2[:, 1] * F[:, 3],
                               atol=tol * rb(z2))


def test_error_parameters_are_validated():
    internal, z1, z2 = PAIRS["sun_planet"]
    kw = dict(internal=False, rb1=rb(z1), rb2=rb(z2), alpha=ALPHA, a0=a0_of(False, z1, z2), teeth1=z1,
              k_mean=K_MEAN)
    GearMesh("ok", [0, 1], [2, 3], **kw, offset1=(1e-5, 0.0))
    for bad in (np.zeros(3), np.full((2, 2), np.inf)):
        with pytest.raises(ModelError, match="offset2"):
            GearMesh("bad", [0, 1], [2, 3], **kw, offset2=bad)


def test_the_error_kernels_are_covered_by_the_compiled_cache_hash():
    """mbd.compiled drops its numba cache when a file it hashes changes (mbd/compiled/*.py among them):
    every compiled mesh function, the error and tooth-pair ones included, must live in such a file."""
    from pathlib import Path

    from numba.core.registry import CPUDispatcher
    import mbd.compiled as mc
    here = Path(mc.__file__).resolve().parent
    from mbd.compiled import tooth_pairs
    jitted = [f for m in (mesh, tooth_pairs) for f in vars(m).values() if isinstance(f, CPUDispatcher)]
    assert {"_to_geometric", "_from_geometric", "_distance", "_box", "flank_force", "_relief", "_cubic"} <= \
        {f.__name__ for f in jitted}
    for f in jitted:
        assert Path(f.py_func.__code__.co_filename).resolve().parent == here, f.__name__
