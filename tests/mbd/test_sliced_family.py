"""The sliced roller–raceway contact as an element family (mbd.elements.sliced.SlicedRaceContact, docs/model.md §8.8).

Truths: the slice law's own quasi-static implementation (SlicedContact, hand-written Jacobian) at the same geometry;
the planar contact (RaceContact) for a straight roller without tilt or slope; the potential energy of the slices
(the generalised forces must be its negative gradient: virtual work through e's dependence on the pin and the pin
slope's rotation with its body); finite differences for the Jacobians; the open-contact bound against the slices."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from mbd.elements import RaceContact, TanhTraction
from mbd.elements.sliced import SlicedContact, SlicedRaceContact, slice_stations

D, L, K, P_EXP = 7.5e-3, 9e-3, 8.06e4 * 9.0 ** (8 / 9) * 1e3 ** (10 / 9), 10 / 9
R_IN, R_OUT = 15.75e-3, 23.26e-3
PIN = np.array([0.004, -0.002])          # the pin centre in the pin body's axes


def _model(n_s=21, drop=None, zeta=0.0, mu=0.0, pin_slope=(0.0, 0.0), row_offset=0.0, ramp=0.0):
    b = mbd.ModelBuilder()
    pin = b.add_body("pin", 5.0, 0.02, pose=(0.01, 0.02, 0.1))
    planet = b.add_body("planet", 0.8, 1e-3, pose=(0.01 + 0.004 * np.cos(0.1) + 0.002 * np.sin(0.1),
                                                     0.02 + 0.004 * np.sin(0.1) - 0.002 * np.cos(0.1), 0.0))
    roller = b.add_body("roller", 3e-3, 2e-8)
    s = b.add_slopes(planet, 5e-4)
    tau = int(b.add_tilts([roller], 4e-8)[0])
    z, _ = slice_stations(L, n_s)
    drop = np.zeros(n_s) if drop is None else drop
    law = dict(D=D, K=K, exponent=P_EXP, zeta=zeta, m_roller=3e-3, traction=TanhTraction(mu_max=mu, v0=0.3), z=z,
               drop=drop, row_offset=row_offset, damping_ramp=ramp)
    r, pb, pl = roller.index, pin.index, planet.index
    inner = SlicedRaceContact("in", [[3 * r, 3 * r + 1, 3 * r + 2, tau, 3 * pb, 3 * pb + 1, 3 * pb + 2]], kind="inner",
                              race_marker=PIN, pin_marker=PIN, R_race=R_IN, race_slope=pin_slope, **law)
    outer = SlicedRaceContact("out", [[3 * r, 3 * r + 1, 3 * r + 2, tau, 3 * pl, 3 * pl + 1, 3 * pl + 2, s[0], s[1],
                                       3 * pb, 3 * pb + 1, 3 * pb + 2]], kind="outer", race_marker=(0.0, 0.0),
                              pin_marker=PIN, R_race=R_OUT, **law)
    b.add(inner)
    b.add(outer)
    return b.build(), inner, outer


def _state(model, rng, press=6e-6, tilt=2e-4, slope=(3e-4, -1e-4), spread=1.0):
    """A loaded state: the roller on the pin's load line, pressed into both races; small tilts and slopes."""
    q = np.zeros(model.n_full)
    q[:9] = np.concatenate([model.pose0[0], model.pose0[1], [0, 0, 0]])
    pin_c = model.pose0[0, :2] + np.array([[np.cos(0.1), -np.sin(0.1)], [np.sin(0.1), np.cos(0.1)]]) @ PIN
    e = np.array([np.cos(0.7), np.sin(0.7)])
    q[6:8] = pin_c + e * (R_IN + D / 2 - press)            # inner compression press
    q[3:5] = q[6:8] - e * (R_OUT - D / 2 + press)          # the bore centre: outer compression press
    q[9:11] = slope
    q[11] = tilt
    q = q + spread * rng.standard_normal(q.size) * np.r_[[1e-7] * 9, [1e-5] * 3]
    v = rng.standard_normal(q.size) * np.r_[[1e-2, 1e-2, 50.0] * 3, [0.5] * 3]
    return q, v


def test_slice_loads_are_the_quasi_static_law_at_the_same_geometry():
    model, inner, outer = _model(pin_slope=(2e-4, 5e-4), drop=np.linspace(0, 2e-6, 21) ** 1 * 0 + 1e-7)
    rng = np.random.default_rng(1)
    q, _ = _state(model, rng)
    v = np.zeros_like(q)
    z, _ = slice_stations(L, 21)
    pin_c = q[0:2] + np.array([[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]]) @ PIN
    p, tau = q[6:8], q[11]
    e = (p - pin_c) / np.linalg.norm(p - pin_c)
    s_pin = np.array([[np.cos(q[2]), -np.sin(q[2])], [np.sin(q[2]), np.cos(q[2])]]) @ np.array([2e-4, 5e-4])
    law = dict(D=D, K=K, exponent=P_EXP, z=z, drop=np.full(21, 1e-7), row_offset=0.0)
    ref_in = SlicedContact(kind="inner", R_race=R_IN, **law).evaluate(p[None], (tau * e)[None], pin_c[None], s_pin[None])
    ref_out = SlicedContact(kind="outer", R_race=R_OUT, **law).evaluate(p[None], (tau * e)[None], q[3:5][None],
                                                                        q[9:11][None])
    got_in, got_out = inner.slice_loads(q, v), outer.slice_loads(q, v)
    assert (ref_in.load > 0).sum() >= 15 and (ref_out.load > 0).sum() >= 15     # both contacts loaded, unevenly
    assert np.ptp(ref_in.load[ref_in.load > 0]) > 0.05 * ref_in.load.max()
    np.testing.assert_allclose(got_in, ref_in.load, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(got_out, ref_out.load, rtol=1e-12, atol=1e-9)
    # the generalised forces on the roller: Σ F_k and e·Σ z_k F_k of both contacts (the e-terms act on p only)
    system = mbd.System(model)
    F = system.forces(0.0, q[model.free], v[model.free], {})
    f = model.full_to_free
    tau_force = e @ (ref_in.roller_moment[0] + ref_out.roller_moment[0])
    assert F[f[11]] == pytest.approx(tau_force, rel=1e-12)


def _potential(model, inner, outer, q):
    """Σ over both contacts' slices of (K/n_s) ⟨δ_k⟩^{p+1}/(p+1): the slices' elastic energy."""
    V = 0.0
    for fam in (inner, outer):
        qk = fam.slice_loads(q, np.zeros_like(q))                # (K/n_s) δ^p at zero rates
        k_s = K / fam.n_s
        delta = (qk / k_s) ** (1 / P_EXP)
        V += np.sum(k_s * delta ** (P_EXP + 1) / (P_EXP + 1))
    return V


@pytest.mark.parametrize("pin_slope", [(0.0, 0.0), (4e-4, -3e-4)])
def test_generalised_forces_are_the_slices_potential_gradient(pin_slope):
    """No damping, no traction: Q = −∂V/∂q on every coordinate (the pin body's θ through its slope and marker, the
    roller's and the pin's position through e, the tilt, the slopes)."""
    model, inner, outer = _model(pin_slope=pin_slope)
    rng = np.random.default_rng(4)
    q, _ = _state(model, rng)
    v = np.zeros_like(q)
    F = mbd.System(model).forces(0.0, q[model.free], v[model.free], {})
    h = np.r_[[1e-10] * 9, [1e-8] * 3]
    for j in range(model.n_full):
        dq = np.zeros_like(q)
        dq[j] = h[j]
        grad = (_potential(model, inner, outer, q + dq) - _potential(model, inner, outer, q - dq)) / (2 * h[j])
        assert F[model.full_to_free[j]] == pytest.approx(-grad, rel=2e-6, abs=1e-6 * np.abs(F).max() * (
            1.0 if j < 9 else 1e-3)), model.coordinate_name(j)


@pytest.mark.parametrize("ramp", [0.0, 1e-5])
def test_straight_roller_without_tilt_is_the_planar_contact(ramp):
    """With a damping ramp of 10 µm the 6 µm compressions sit on its smoothstep: the slices' share is the planar one."""
    model, inner, outer = _model(zeta=0.05, mu=0.08, ramp=ramp)
    rng = np.random.default_rng(7)
    q, v = _state(model, rng, tilt=0.0, slope=(0.0, 0.0))
    q[9:12], v[9:12] = 0.0, 0.0
    law = dict(D=D, K=K, exponent=P_EXP, zeta=0.05, m_roller=3e-3, traction=TanhTraction(mu_max=0.08, v0=0.3),
               damping_ramp=ramp)
    planar_in = RaceContact("pi", [2], [0], kind="inner", race_marker=PIN, R_race=R_IN, **law)
    planar_out = RaceContact("po", [2], [1], kind="outer", race_marker=(0.0, 0.0), R_race=R_OUT, **law)
    fs = mbd.FrameState(0.0, 0.0, 0.0)
    for sliced, planar in ((inner, planar_in), (outer, planar_out)):
        Fs, outs = sliced.kernel(0.0, fs, list(q[sliced.dofs].T), list(v[sliced.dofs].T), None)
        Fp, outp = planar.kernel(0.0, fs, list(q[planar.dofs].T), list(v[planar.dofs].T), None)
        assert outp["load"][0] > 100.0
        for key in ("load", "traction", "slip_velocity", "rolling_speed", "fx", "fy", "deflection"):
            assert outs[key][0] == pytest.approx(outp[key][0], rel=1e-12, abs=1e-12 * outp["load"][0]), key
        loc = [0, 1, 2, 4, 5, 6]          # roller and race body (x, y, θ)
        np.testing.assert_allclose([np.asarray(Fs[i])[0] for i in loc], [np.asarray(f)[0] for f in Fp], rtol=1e-11,
                                   atol=1e-12 * outp["load"][0])
        assert abs(np.asarray(Fs[3])[0]) < 1e-12 * outp["load"][0] * L     # no moment on the tilt


def test_sliced_jacobians_match_finite_differences():
    model, _, _ = _model(zeta=0.05, mu=0.08, pin_slope=(3e-4, 1e-4), drop=np.linspace(-1, 1, 21) ** 2 * 2e-6,
                         row_offset=1e-3)
    system = mbd.System(model)
    rng = np.random.default_rng(9)
    q, v = _state(model, rng)
    qf, vf = q[model.free], v[model.free]
    ev = system.evaluate(0.0, qf, vf, {}, jac=True)
    _, C, Km = system.matrices(ev)
    hq = np.r_[[1e-10, 1e-10, 1e-8] * 3, [1e-8] * 3]      # lengths, angles, slopes and tilt: round-off of 1e6 N forces
    hv = np.r_[[1e-7, 1e-7, 1e-3] * 3, [1e-5] * 3]
    scale = np.abs(ev.F).max()
    for j in range(model.ndof):
        dq, dv = np.zeros_like(qf), np.zeros_like(vf)
        dq[j], dv[j] = hq[j], hv[j]
        fq = (system.forces(0.0, qf + dq, vf, {}) - system.forces(0.0, qf - dq, vf, {})) / (2 * hq[j])
        fv = (system.forces(0.0, qf, vf + dv, {}) - system.forces(0.0, qf, vf - dv, {})) / (2 * hv[j])
        np.testing.assert_allclose(-Km.toarray()[:, j], fq, rtol=1e-5, atol=1e-6 * np.abs(fq).max() + 1e-9 * scale,
                                   err_msg=model.coordinate_name(j))
        np.testing.assert_allclose(-C.toarray()[:, j], fv, rtol=1e-5, atol=1e-6 * np.abs(fv).max() + 1e-12 * scale,
                                   err_msg=model.coordinate_name(j))


def test_a_contact_skipped_as_open_has_every_slice_open():
    """The bound δ_0 + max|z σ_r − ζ σ_c| ≤ 0 never skips a loaded slice (random geometries near the edge)."""
    model, inner, outer = _model(n_s=11)
    rng = np.random.default_rng(12)
    skipped = 0
    for _ in range(300):
        q, v = _state(model, rng, press=rng.uniform(-2e-5, 4e-6), tilt=rng.uniform(-3e-3, 3e-3),
                      slope=rng.uniform(-3e-3, 3e-3, 2))
        for fam in (inner, outer):
            g = fam._geometry(list(q[fam.dofs].T), list(v[fam.dofs].T))
            open_ = fam._open_bound(g)
            if open_[0]:
                skipped += 1
                all_idx = np.arange(fam.n)
                sl = fam._slices(g, all_idx)
                assert np.all(sl["delta"] <= 0.0)
    assert skipped > 50
