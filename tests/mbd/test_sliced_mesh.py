"""Face-sliced meshes (mbd.elements.gear_mesh.SlicedGearMesh, docs/model.md §6.6): the lumped law across the face.

Truths: the lumped law itself (uniform slices, no relative slope: GearMesh to round-off), the tilt stiffness of an
elastic strip of n_m equal slices, k Σ ζ_k²/n_m = k b²(1 − 1/n_m²)/12 → c_γ b³/12, the slices' potential energy
(the generalised forces are its negative gradient), finite differences for the Jacobians."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from mbd.elements import GearMesh, StiffnessShape
from mbd.elements.gear_mesh import SlicedGearMesh, mesh_u0

RB1, RB2, ALPHA, Z1 = 0.03, 0.045, np.radians(20.0), 20
A0 = (RB1 + RB2) / np.cos(ALPHA)
K_MESH, B = 4.0e8, 0.02


def _meshes(n_m=15, shape=None, c=0.0, backlash=0.0, offset2=None, internal=False, pairs=None):
    b = mbd.ModelBuilder()
    g1 = b.add_body("g1", 1.0, 1e-3)
    g2 = b.add_body("g2", 2.0, 3e-3, pose=(A0, 0.0, 0.0))
    s1, s2 = b.add_slopes(g1, 5e-4), b.add_slopes(g2, 8e-4)
    kw = dict(internal=internal, rb1=RB1, rb2=RB2, alpha=ALPHA, a0=A0, teeth1=Z1, k_mean=K_MESH, c_mesh=c,
              damping_ramp=1e-6 if c else 0.0, u0=mesh_u0(False, RB1, RB2, (0, 0, 0), (A0, 0, 0)), backlash=backlash,
              stiffness=shape, offset2=offset2, pairs=pairs)
    sliced = SlicedGearMesh("sliced", [g1], [g2], slopes1=[s1], slopes2=[s2], face_width=B, slices=n_m, **kw)
    b.add(sliced)
    model = b.build()
    lumped = GearMesh("lumped", [g1], [g2], **kw)
    return model, sliced, lumped, (s1, s2)


def _state(model, slopes, theta2=2e-4, ds=(0.0, 0.0), rng=None):
    q = np.zeros(model.n_full)
    q[3], q[5] = A0, theta2                # gear 2 turned: flank + compressed by ≈ r_b2 θ_2
    q[slopes[1][0]], q[slopes[1][1]] = ds
    v = np.zeros_like(q)
    if rng is not None:
        q[:6] += rng.standard_normal(6) * np.r_[1e-7, 1e-7, 1e-5, 1e-7, 1e-7, 1e-5]
        v[:6] = rng.standard_normal(6) * np.r_[1e-2, 1e-2, 10.0, 1e-2, 1e-2, 10.0]
        v[6:] = rng.standard_normal(4) * 0.1
        q[6:8] = rng.standard_normal(2) * 1e-4
    return q, v


@pytest.mark.parametrize("c, backlash, runout", [(0.0, 0.0, False), (2e3, 1e-5, True)])
def test_uniform_slices_are_the_lumped_mesh_to_round_off(c, backlash, runout):
    shape = StiffnessShape.rectangular(1.6, 1.5, 0.1)
    model, sliced, lumped, sl = _meshes(shape=shape, c=c, backlash=backlash,
                                        offset2=(3e-6, -2e-6) if runout else None)
    rng = np.random.default_rng(3)
    q, v = _state(model, sl, theta2=3e-4, rng=rng)
    q[6:10], v[6:10] = 0.0, 0.0            # no slopes: every slice alike
    fs = mbd.FrameState(0.0, 0.0, 0.0)
    Fs, outs = sliced.kernel(0.0, fs, list(q[sliced.dofs].T), list(v[sliced.dofs].T), None)
    Fl, outl = lumped.kernel(0.0, fs, list(q[lumped.dofs].T), list(v[lumped.dofs].T), None)
    scale = abs(outl["force"][0])
    assert scale > 1e3
    for i in range(6):
        assert np.asarray(Fs[i])[0] == pytest.approx(np.asarray(Fl[i])[0], rel=1e-12, abs=1e-12 * scale)
    for key, val in outl.items():
        assert outs[key][0] == pytest.approx(np.asarray(val)[0], rel=1e-12, abs=1e-12 * max(1.0, scale)), key
    assert all(abs(np.asarray(Fs[i])[0]) < 1e-12 * scale * B for i in range(6, 10))


@pytest.mark.parametrize("n_m", [5, 15, 41])
def test_tilt_stiffness_of_a_mesh_in_full_contact_is_k_b_squared_over_12(n_m):
    model, sliced, _, sl = _meshes(n_m=n_m)
    q, v = _state(model, sl, theta2=3e-4, ds=(1e-5, 2e-5))      # every slice compressed (δ ≈ 1.3e-5 m ≫ ζ Δs)
    system = mbd.System(model)
    ev = system.evaluate(0.0, q[model.free], v[model.free], {}, jac=True)
    _, _, K = system.matrices(ev)
    f = model.full_to_free
    i2 = f[list(sl[1])]
    K22 = K.toarray()[np.ix_(i2, i2)]
    # the line of action of flank +: g = −κ t − sin α e, e = (1, 0) from gear 1 to gear 2, t = (0, 1), κ = cos α
    g = np.array([-np.sin(ALPHA), -np.cos(ALPHA)])
    k_tilt = g @ K22 @ g
    exact = K_MESH * B ** 2 * (1 - 1 / n_m ** 2) / 12           # k Σ ζ_k² / n_m
    assert k_tilt == pytest.approx(exact, rel=1e-6)
    c_gamma = K_MESH / B
    assert k_tilt == pytest.approx(c_gamma * B ** 3 / 12, rel=1.01 / n_m ** 2)
    perp = np.array([g[1], -g[0]])
    assert abs(perp @ K22 @ perp) < 1e-6 * exact                 # a slope across the line of action: nothing


def _potential(sliced, q):
    """Σ over both flanks' slices of (k/n_m) ⟨δ_fk⟩²/2 (constant stiffness, no damping)."""
    fs = mbd.FrameState(0.0, 0.0, 0.0)
    cols, vz = list(q[sliced.dofs].T), list(np.zeros_like(q)[sliced.dofs].T)
    g = sliced._geometry(cols, vz)
    s1, s2 = q[sliced.dofs[0, 6:8]], q[sliced.dofs[0, 8:10]]
    ds = s2 - s1
    zeta = B / sliced.n_m * sliced._unit
    V = 0.0
    for f, d in ((1.0, g["d_plus"][0]), (-1.0, g["d_minus"][0])):
        gx = -f * g["kappa"][0] * g["tx"][0] - np.sin(ALPHA) * g["ex"][0]
        gy = -f * g["kappa"][0] * g["ty"][0] - np.sin(ALPHA) * g["ey"][0]
        dk = d + zeta * (gx * ds[0] + gy * ds[1])
        V += np.sum(K_MESH / sliced.n_m * np.maximum(dk, 0.0) ** 2 / 2)
    return V


def test_sliced_mesh_forces_are_the_slices_potential_gradient():
    model, sliced, _, sl = _meshes(n_m=9, backlash=0.0)
    rng = np.random.default_rng(8)
    q, _ = _state(model, sl, theta2=1e-4, ds=(4e-4, -3e-4), rng=rng)     # partly open slices
    v = np.zeros_like(q)
    F = mbd.System(model).forces(0.0, q[model.free], v[model.free], {})
    h = np.r_[1e-10, 1e-10, 1e-8, 1e-10, 1e-10, 1e-8, [1e-8] * 4]
    for j in range(model.n_full):
        dq = np.zeros_like(q)
        dq[j] = h[j]
        grad = (_potential(sliced, q + dq) - _potential(sliced, q - dq)) / (2 * h[j])
        assert F[model.full_to_free[j]] == pytest.approx(-grad, rel=1e-5, abs=1e-7 * np.abs(F).max()), \
            model.coordinate_name(j)


def test_sliced_mesh_jacobians_match_finite_differences():
    model, sliced, _, sl = _meshes(n_m=9, shape=StiffnessShape.rectangular(1.6, 1.5, 0.1), c=2e3, backlash=1e-6,
                                   offset2=(3e-6, -2e-6))
    system = mbd.System(model)
    rng = np.random.default_rng(5)
    q, v = _state(model, sl, theta2=1e-4, ds=(3e-4, -2e-4), rng=rng)
    qf, vf = q[model.free], v[model.free]
    ev = system.evaluate(0.0, qf, vf, {}, jac=True)
    _, C, K = system.matrices(ev)
    hq = np.r_[1e-10, 1e-10, 1e-8, 1e-10, 1e-10, 1e-8, [1e-8] * 4]
    hv = np.r_[1e-5, 1e-5, 1e-3, 1e-5, 1e-5, 1e-3, [1e-4] * 4]
    for j in range(model.ndof):
        dq, dv = np.zeros_like(qf), np.zeros_like(vf)
        dq[j], dv[j] = hq[j], hv[j]
        fq = (system.forces(0.0, qf + dq, vf, {}) - system.forces(0.0, qf - dq, vf, {})) / (2 * hq[j])
        fv = (system.forces(0.0, qf, vf + dv, {}) - system.forces(0.0, qf, vf - dv, {})) / (2 * hv[j])
        np.testing.assert_allclose(-K.toarray()[:, j], fq, rtol=1e-5, atol=1e-6 * np.abs(fq).max() + 1e-3,
                                   err_msg=model.coordinate_name(j))
        np.testing.assert_allclose(-C.toarray()[:, j], fv, rtol=1e-5, atol=1e-6 * np.abs(fv).max() + 1e-6,
                                   err_msg=model.coordinate_name(j))


def _tooth_pairs(rng):
    """Tooth-pair data of the test mesh: deviations on every flank, a cracked tooth, tip relief on both gears."""
    from mbd.elements.tooth_pairs import ToothPairs, tooth_table
    f1 = np.ones(Z1)
    f1[3] = 0.4
    t1 = tooth_table(Z1, rng.normal(0, 4e-6, (Z1, 2, 4)), f1)
    t2 = tooth_table(30, rng.normal(0, 4e-6, (30, 2, 4)), None)
    return ToothPairs(entry=np.array([[0.3, 0.6]]), phase2=np.array([[0.1, -0.2]]), relief1=np.array([6e-6, 0.7, 2.0]),
                      relief2=np.array([5e-6, 0.75, 1.0]), table=np.concatenate([t1, t2]), start1=np.zeros(1),
                      start2=np.full(1, float(t1.size)))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_uniform_slices_are_the_tooth_pair_mesh_to_round_off(seed):
    rng = np.random.default_rng(seed)
    shape = StiffnessShape.rectangular(1.6, 1.5, 0.1)
    model, sliced, lumped, sl = _meshes(n_m=7, shape=shape, c=2e3, backlash=1e-6, pairs=_tooth_pairs(rng))
    q, v = _state(model, sl, theta2=2e-4, rng=rng)
    q[6:10], v[6:10] = 0.0, 0.0
    fs = mbd.FrameState(0.0, 0.0, 0.0)
    Fs, outs = sliced.kernel(0.0, fs, list(q[sliced.dofs].T), list(v[sliced.dofs].T), None)
    Fl, outl = lumped.kernel(0.0, fs, list(q[lumped.dofs].T), list(v[lumped.dofs].T), None)
    scale = abs(outl["force"][0])
    assert scale > 1e3
    for i in range(6):
        assert np.asarray(Fs[i])[0] == pytest.approx(np.asarray(Fl[i])[0], rel=1e-11, abs=1e-11 * scale)
    for key in ("force", "force_drive", "force_coast", "stiffness"):
        assert outs[key][0] == pytest.approx(np.asarray(outl[key])[0], rel=1e-11, abs=1e-11 * scale), key


def test_tooth_pair_sliced_mesh_jacobians_match_finite_differences():
    rng = np.random.default_rng(6)
    model, sliced, _, sl = _meshes(n_m=5, shape=StiffnessShape.rectangular(1.6, 1.5, 0.1), c=2e3, backlash=1e-6,
                                   pairs=_tooth_pairs(rng))
    system = mbd.System(model)
    q, v = _state(model, sl, theta2=1e-4, ds=(3e-4, -2e-4), rng=rng)
    qf, vf = q[model.free], v[model.free]
    ev = system.evaluate(0.0, qf, vf, {}, jac=True)
    _, C, K = system.matrices(ev)
    hq = np.r_[1e-10, 1e-10, 1e-8, 1e-10, 1e-10, 1e-8, [1e-8] * 4]
    hv = np.r_[1e-5, 1e-5, 1e-3, 1e-5, 1e-5, 1e-3, [1e-4] * 4]
    for j in range(model.ndof):
        dq, dv = np.zeros_like(qf), np.zeros_like(vf)
        dq[j], dv[j] = hq[j], hv[j]
        fq = (system.forces(0.0, qf + dq, vf, {}) - system.forces(0.0, qf - dq, vf, {})) / (2 * hq[j])
        fv = (system.forces(0.0, qf, vf + dv, {}) - system.forces(0.0, qf, vf - dv, {})) / (2 * hv[j])
        np.testing.assert_allclose(-K.toarray()[:, j], fq, rtol=1e-5, atol=1e-6 * np.abs(fq).max() + 1e-3,
                                   err_msg=model.coordinate_name(j))
        np.testing.assert_allclose(-C.toarray()[:, j], fv, rtol=1e-5, atol=1e-6 * np.abs(fv).max() + 1e-6,
                                   err_msg=model.coordinate_name(j))


@pytest.mark.parametrize("law", ["lumped", "tooth_pairs"])
def test_outputs_of_many_states_at_once_are_each_states_own(law, monkeypatch):
    """System.outputs_batch evaluates the face-sliced mesh at K states in one call (the slices along the instance
    axis of (K, n) arrays): every output equals the kernel's at each state alone, bit for bit, with relative slopes,
    rates, damping, backlash and a runout (the lumped law) or the tooth-pair law."""
    rng = np.random.default_rng(11)
    shape = StiffnessShape.rectangular(1.6, 1.5, 0.1)
    pairs = _tooth_pairs(rng) if law == "tooth_pairs" else None
    model, sliced, _, sl = _meshes(n_m=7, shape=shape, c=2e3, backlash=1e-6, pairs=pairs,
                                   offset2=(3e-6, -2e-6) if pairs is None else None)
    states = [_state(model, sl, theta2=2e-4, ds=tuple(rng.standard_normal(2) * 2e-4), rng=rng) for _ in range(12)]
    q, v = np.array([s[0] for s in states]), np.array([s[1] for s in states])
    assert model.ndof == model.n_full == q.shape[1]
    t = np.linspace(0.0, 1e-3, q.shape[0])
    system = mbd.System(model)
    got = system.outputs_batch(t, q, v, {})["sliced"]
    monkeypatch.setattr(SlicedGearMesh, "batched", False)        # the reference: one state at a time
    ref = system.outputs_batch(t, q, v, {})["sliced"]
    assert set(got) == set(ref) and {"force", "tilt_moment", "relative_slope", "stiffness"} <= set(got)
    assert np.all(np.abs(ref["tilt_moment"]) > 0.0) and np.abs(ref["force"]).max() > 1e3
    for key, val in ref.items():
        np.testing.assert_array_equal(got[key], val, err_msg=key)
    fs = mbd.FrameState(0.0, 0.0, 0.0)
    _, one = sliced.kernel(t[3], fs, list(q[3][sliced.dofs].T), list(v[3][sliced.dofs].T), None)
    assert got["force"][3, 0] == one["force"][0]
