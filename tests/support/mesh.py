"""Gear-mesh test scenes and checks shared by the mesh tests (tests/mbd: test_gear_mesh, test_gear_mesh_errors,
test_tooth_pairs, test_compiled_mesh): the Table-1 gear pairs on random poses, the GearMesh family built on them,
finite-difference Jacobians; and the compiled kernels of the mesh and generic families against the reference
(:func:`mbd.element.evaluate`), with the C library's arctan2 in the reference where the kernel must be matched to
its last bits (test_compiled_mesh's docstring says why)."""
from __future__ import annotations

import contextlib
import math
from unittest import mock

import numpy as np

from mbd import ad
from mbd.compiled.registry import kind_of
from mbd.element import evaluate
from mbd.elements.gear_mesh import GearMesh, StiffnessShape, mesh_u0
from mbd.model import FrameState

# Table-1 gears: module 3 mm, 20°; sun 31, planets 24, ring 82
M_ = 3e-3
ALPHA = np.deg2rad(20.0)
K_MEAN = 6.4e8
FS0 = FrameState(0.0, 0.0, 0.0)


def rb(z):
    return M_ * z * np.cos(ALPHA) / 2.0


# (internal, z1, z2): sun–inner planet, inner–outer planet (external), outer planet–ring (internal)
PAIRS = {"sun_planet": (False, 31, 24), "planet_planet": (False, 24, 24), "planet_ring": (True, 24, 82)}

SHAPES = {
    "constant": StiffnessShape.constant(),
    "rectangular": StiffnessShape.rectangular(1.63, ratio=1.5, smoothing=0.05),
    "fourier": StiffnessShape.fourier(a=[0.12, -0.03], b=[0.05, 0.02]),
}


def a0_of(internal, z1, z2):
    return M_ * ((z2 - z1) if internal else (z1 + z2)) / 2.0


def nominal(pair, n, rng, angle_span=50.0, spread=0.2, psi=None):
    """Nominal poses (n, 3) of gear 1 and gear 2: centres a0 apart in a random direction (or along the
    angles ``psi`` of e), anywhere within ``spread`` of the origin, random (large) angles."""
    internal, z1, z2 = PAIRS[pair]
    a0 = a0_of(internal, z1, z2)
    psi = rng.uniform(-np.pi, np.pi, n) if psi is None else np.broadcast_to(np.asarray(psi, float), (n,))
    e = np.column_stack([np.cos(psi), np.sin(psi)])
    base = rng.uniform(-spread, spread, (n, 2))
    p1, p2 = np.zeros((n, 3)), np.zeros((n, 3))
    if internal:        # e: ring centre → planet centre
        p2[:, :2] = base
        p1[:, :2] = base + a0 * e
    else:               # e: gear 1 → gear 2
        p1[:, :2] = base
        p2[:, :2] = base + a0 * e
    p1[:, 2] = rng.uniform(-angle_span, angle_span, n)
    p2[:, 2] = rng.uniform(-angle_span, angle_span, n)
    return p1, p2


def make_mesh(pair, p1, p2, *, backlash=0.0, shape="constant", c_mesh=0.0, damping_ramp=0.0, p0=0.0, name="mesh",
              **errors):
    """A family of n meshes with u0 from the nominal poses p1, p2; ``errors``: GearMesh's error arguments."""
    internal, z1, z2 = PAIRS[pair]
    n = p1.shape[0]
    return GearMesh(name, np.arange(n), n + np.arange(n), internal=internal, rb1=rb(z1), rb2=rb(z2),
                    alpha=ALPHA, a0=a0_of(internal, z1, z2), teeth1=z1, k_mean=K_MEAN, c_mesh=c_mesh,
                    damping_ramp=damping_ramp,
                    u0=mesh_u0(internal, rb(z1), rb(z2), p1, p2), p0=p0, backlash=backlash,
                    stiffness=SHAPES[shape] if isinstance(shape, str) else shape, **errors)


def circ(x):
    """Difference of mesh positions on the unit circle, in [-1/2, 1/2)."""
    return np.mod(x + 0.5, 1.0) - 0.5


def full(p1, p2):
    """Full coordinate vector of bodies 0..n-1 (gear 1) and n..2n-1 (gear 2)."""
    return np.concatenate([p1.ravel(), p2.ravel()])


def fd_jacobians(elem, q, v, hq=1e-8, hv=1e-4):
    """Central finite differences of the local forces, (n, k, k) for q and v."""
    n, k = elem.dofs.shape
    Jq, Jv = np.zeros((n, k, k)), np.zeros((n, k, k))
    for j in range(k):
        idx = elem.dofs[:, j]
        for J, x, h in ((Jq, q, hq), (Jv, v, hv)):
            xp, xm = x.copy(), x.copy()
            xp[idx] += h
            xm[idx] -= h
            args_p = (xp, v) if x is q else (q, xp)
            args_m = (xm, v) if x is q else (q, xm)
            Fp = evaluate(elem, 0.0, FS0, *args_p, None, False)[0]
            Fm = evaluate(elem, 0.0, FS0, *args_m, None, False)[0]
            J[:, :, j] = (Fp - Fm) / (2 * h)
    return Jq, Jv


def perturbed_state(pair, rng, n, du=2e-5, psi=None):
    """Nominal poses plus displacements of ~du (so flanks open and close), rolling + random speeds."""
    internal, z1, z2 = PAIRS[pair]
    p1, p2 = nominal(pair, n, rng, psi=psi)
    q = full(p1, p2)
    q1 = q.copy().reshape(-1, 3)
    q1[:, :2] += rng.normal(0.0, du, (2 * n, 2))
    q1[:n, 2] += rng.normal(0.0, du / rb(z1), n)
    q1[n:, 2] += rng.normal(0.0, du / rb(z2), n)
    w1 = rng.uniform(-400, 400, n)
    w2 = (rb(z1) / rb(z2) if internal else -rb(z1) / rb(z2)) * w1
    v = rng.normal(0.0, 0.05, (2 * n, 3))
    v[:n, 2] += w1
    v[n:, 2] += w2
    return p1, p2, q1.ravel(), v.ravel()


def jac_check(elem, q, v, hq=1e-8):
    """The element's Jacobians against central differences (``hq`` the coordinate step: smaller than a tenth of
    a thousandth of any smooth ramp the law has, so that the differences' truncation stays below 1e-6)."""
    F, out, Jq, Jv = evaluate(elem, 0.0, FS0, q, v, None, True)
    Jq_fd, Jv_fd = fd_jacobians(elem, q, v, hq=hq)
    for Ja, Jf in ((Jq, Jq_fd), (Jv, Jv_fd)):
        scale = max(np.abs(Ja).max(), np.abs(Jf).max(), 1.0)
        np.testing.assert_allclose(Ja, Jf, rtol=1e-6, atol=1e-6 * scale)
    return F, out


def far_from_kinks(elem, q, v, margin_d=1e-7, margin_f=200.0):
    """No flank within finite-difference reach of its contact switch or of its clip max(kδ + c S(δ) δ̇, 0), nor
    damped inside the damping ramp, whose curvature the default steps do not resolve (a test of its own)."""
    from mbd.elements.tooth_pairs import damping_share
    out = evaluate(elem, 0.0, FS0, q, v, None, False)[1]
    ok = True
    for d, r in ((out["deflection"], out["deflection_rate"]), (out["deflection_coast"], out["deflection_rate_coast"])):
        arg = out["stiffness"] * d + elem.c_mesh * damping_share(d, elem.damping_ramp) * r
        ok &= np.all(np.abs(d) > margin_d) and np.all((d <= 0) | (np.abs(arg) > margin_f))
        ok &= not np.any((d > 0) & (d < elem.damping_ramp) & (elem.c_mesh * np.abs(r) > margin_f))
    return bool(ok)


# ------------------------------------------------------------------------- compiled kernel = reference
RTOL = 1e-10          # of the largest entry of each instance's block (F row, J_q, J_v matrices)
ATOL = 1e-300         # only so that an all-zero block must be matched by (signed) zeros

_atan2 = np.frompyfunc(math.atan2, 2, 1)
_ad_arctan2 = ad.arctan2


def _arctan2_libm(y, x):
    """ad.arctan2 with the C library's value (numba's); derivatives unchanged."""
    out = _ad_arctan2(y, x)
    val = _atan2(ad.value(y), ad.value(x)).astype(float)
    if isinstance(out, ad.Dual):
        return ad.Dual(val, out.der)
    return val


@contextlib.contextmanager
def libm_arctan2():
    with mock.patch.object(ad, "arctan2", _arctan2_libm):
        yield


def compiled(elem, t, fs, q, v, z=None, jac=True):
    """F, J_q, J_v of a family from its compiled kernel (and a check that jac=False gives the same F)."""
    twin = kind_of(type(elem))
    pack, kern = twin.pack, twin.evaluate
    P, G = pack(elem)
    n, k = elem.dofs.shape
    ql, vl = np.ascontiguousarray(q[elem.dofs]), np.ascontiguousarray(v[elem.dofs])
    zz = np.zeros((n, 0)) if z is None else np.ascontiguousarray(np.reshape(z, (n, -1)), dtype=float)
    F, Jq, Jv = np.full((n, k), np.nan), np.full((n, k, k), np.nan), np.full((n, k, k), np.nan)
    kern(t, fs.phi, fs.omega, fs.domega, ql, vl, zz, P, G, F, Jq, Jv, jac)
    F0 = np.full((n, k), np.nan)
    kern(t, fs.phi, fs.omega, fs.domega, ql, vl, zz, P, G, F0, Jq[:0], Jv[:0], False)
    np.testing.assert_array_equal(F0, F, err_msg=f"{elem.name}: forces differ between jac=True and jac=False")
    return F, Jq, Jv


def assert_block_close(name, A, B, rtol=RTOL, atol=0.0):
    """Per instance: |A − B| <= rtol·max|B| + ATOL (+ atol, (n,), when given) over the instance's block."""
    n = B.shape[0]
    a, b = A.reshape(n, -1), B.reshape(n, -1)
    assert np.all(np.isfinite(a)), f"{name}: non-finite (unwritten?) entries"
    err = np.abs(a - b).max(axis=1)
    bound = rtol * np.abs(b).max(axis=1) + ATOL + atol
    bad = err > bound
    assert not bad.any(), (f"{name}: instances {np.flatnonzero(bad)} differ by {err[bad]} "
                           f"(bound {bound[bad]}, scale {np.abs(b).max(axis=1)[bad]})")


def assert_matches_reference(elem, t, fs, q, v, z=None, F_atol=0.0):
    F, _, Jq, Jv = evaluate(elem, t, fs, q, v, z, jac=True)
    Fc, Jqc, Jvc = compiled(elem, t, fs, q, v, z)
    assert_block_close(f"{elem.name} F", Fc, F, atol=F_atol)
    assert_block_close(f"{elem.name} J_q", Jqc, Jq)
    assert_block_close(f"{elem.name} J_v", Jvc, Jv)
