"""The compiled sliced race contact (mbd.compiled.sliced) equals the reference kernel (mbd.element.evaluate over
mbd.elements.sliced.SlicedRaceContact, whose Jacobians are mbd.ad's dual numbers) to round-off: forces, J_q and J_v
to 1e-10 of each instance's block (tests.support.contact.assert_matches_reference), inner and outer raceways, the
three traction laws, with damping, profile drops, row offsets, a pin slope, tilts and slopes drawn at random, and
contacts fully open (skipped by the bound), partly open (an edge load) and fully closed in one family; and its outputs
(outputs_sliced_race, what the window statistics read) equal the reference's."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from mbd.compiled.registry import OUTPUT_NAMES, kind_of, output_names
from mbd.compiled.sliced import _LANES, _slice_roots, outputs_sliced_race, root_index
from mbd.element import evaluate
from mbd.elements import StiffnessShape
from mbd.elements.gear_mesh import SlicedGearMesh, mesh_u0
from mbd.elements.sliced import SlicedRaceContact, slice_stations

from tests.support.contact import DR, EHL, FILM, FS, K_HZ, LR, M_ROLLER, TANH, assert_matches_reference, compiled
from tests.support.strategies import frame_states

SETTINGS = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
TRACTIONS = {"tanh": TANH, "slide_roll": EHL, "film": FILM}
R_IN, R_OUT = 15.75e-3, 23.26e-3
PIN = np.array([0.004, -0.002])          # the pin centre in the pin body's axes
N = 6                                    # rollers
# full-vector layout: pin body 0..2, planet 3..5, the planet's slopes 6, 7, roller b at 8 + 3b, its tilt 8 + 3N + b
ROLLER = lambda b: 8 + 3 * b             # noqa: E731
TILT = lambda b: 8 + 3 * N + b           # noqa: E731


def _family(kind, n_s, traction, *, zeta, drop, row, pin_slope, exponent=10.0 / 9.0, ramp=0.0):
    z, _ = slice_stations(LR, n_s)
    law = dict(D=DR, K=K_HZ, exponent=exponent, zeta=zeta, m_roller=M_ROLLER, traction=traction, z=z, drop=drop,
               row_offset=row, damping_ramp=ramp)
    rows = []
    for b in range(N):
        r = [ROLLER(b), ROLLER(b) + 1, ROLLER(b) + 2, TILT(b)]
        rows.append(r + ([0, 1, 2] if kind == "inner" else [3, 4, 5, 6, 7, 0, 1, 2]))
    if kind == "inner":
        return SlicedRaceContact("in", rows, kind="inner", race_marker=PIN, pin_marker=PIN, R_race=R_IN,
                                 race_slope=pin_slope, **law)
    return SlicedRaceContact("out", rows, kind="outer", race_marker=(0.0, 0.0), pin_marker=PIN, R_race=R_OUT,
                             race_slope=pin_slope, **law)


def _state(kind, rng, press, tilt, slope):
    """Rollers around the pin, each pressed by press[b] into the ``kind`` raceway (negative: a gap), tilted by tilt[b];
    the planet's slope ``slope``; small random offsets; random velocities."""
    nf = 8 + 4 * N
    q = np.zeros(nf)
    q[:3] = (0.01, 0.02, 0.1)
    pin_c = q[:2] + np.array([[np.cos(0.1), -np.sin(0.1)], [np.sin(0.1), np.cos(0.1)]]) @ PIN
    q[3:5] = pin_c + rng.uniform(-2e-6, 2e-6, 2)
    q[6:8] = slope
    for b in range(N):
        e = np.array([np.cos(2 * np.pi * b / N + 0.3), np.sin(2 * np.pi * b / N + 0.3)])
        radius = R_IN + DR / 2 - press[b] if kind == "inner" else R_OUT - DR / 2 + press[b]
        q[ROLLER(b):ROLLER(b) + 2] = pin_c + e * radius
        q[ROLLER(b) + 2] = rng.uniform(-3, 3)
        q[TILT(b)] = tilt[b]
    q[3:6] += rng.standard_normal(3) * (1e-7, 1e-7, 1e-3)
    v = rng.standard_normal(nf) * np.r_[[1e-2, 1e-2, 50.0] * 2, [0.5] * 2, [1e-2, 1e-2, 300.0] * N, [0.5] * N]
    return q, v


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "slide_roll", "film"])
@SETTINGS
@given(data=st.data(), fs=frame_states(), n_s=st.sampled_from([1, 5, 21]), zeta=st.sampled_from([0.0, 0.05, 0.3]),
       row=st.sampled_from([0.0, 3e-3, -6e-3]), seed=st.integers(0, 2 ** 31),
       exponent=st.sampled_from([10.0 / 9.0, 1.5, 1.3]), ramp=st.sampled_from([0.0, 0.5e-6, 5e-6]))
def test_sliced_race_matches_reference(kind, law, data, fs, n_s, zeta, row, seed, exponent, ramp):
    """Palmgren's p = 10/9 and p = 1.5 take the slices' root iteration ((p − 1)/2 = 1/18, 1/4), p = 1.3 np.power; a
    damping ramp δ_c of 0.5 and 5 µm puts slices of the drawn compressions (0.3–8 µm) on and past its smoothstep."""
    rng = np.random.default_rng(seed)
    press = data.draw(st.lists(st.sampled_from([-20e-6, -1e-6, 0.3e-6, 2e-6, 8e-6]), min_size=N, max_size=N))
    tilt = rng.uniform(-1e-3, 1e-3, N)
    slope = rng.uniform(-5e-4, 5e-4, 2)
    pin_slope = rng.uniform(-3e-4, 3e-4, 2) if data.draw(st.booleans()) else (0.0, 0.0)
    drop = rng.uniform(0.0, 1e-6, (N, n_s)) if data.draw(st.booleans()) else np.zeros(n_s)
    elem = _family(kind, n_s, TRACTIONS[law], zeta=zeta, drop=drop, row=row, pin_slope=pin_slope, exponent=exponent,
                   ramp=ramp)
    qf, vf = _state(kind, rng, press, tilt, slope)
    Fr = assert_matches_reference(elem, fs, qf, vf)
    assert np.any(Fr != 0.0) or min(press) < 0.0


def test_loaded_open_and_edge_contacts_in_one_family():
    """The equality holds where it matters: a contact with every slice closed, one with an edge load (tilt beyond
    the compression) and one skipped as open are all in the family, and the open one is exactly zero."""
    rng = np.random.default_rng(7)
    press = [6e-6, 1e-6, -30e-6, 4e-6, 0.5e-6, 2e-6]
    tilt = [0.0, 8e-4, 0.0, -3e-4, 2e-4, 0.0]
    for kind in ("inner", "outer"):
        elem = _family(kind, 21, TANH, zeta=0.05, drop=np.zeros(21), row=0.0, pin_slope=(0.0, 0.0))
        qf, vf = _state(kind, rng, press, tilt, (2e-4, -1e-4))
        loads = elem.slice_loads(qf, vf)
        assert np.all(loads[0] > 0.0) and np.any(loads[1] == 0.0) and np.any(loads[1] > 0.0)
        assert np.all(loads[2] == 0.0)
        assert_matches_reference(elem, FS, qf, vf)
        F, Jq, Jv = compiled(elem, FS, qf, vf, None, True)
        assert np.all(F[2] == 0.0) and np.all(Jq[2] == 0.0) and np.all(Jv[2] == 0.0)


def _roots(delta, pe):
    delta = np.asarray(delta, float)
    npad = -(-delta.size // _LANES) * _LANES
    x, y = np.empty(npad), np.empty(npad)
    _slice_roots(delta[None, :], x, y, 1, delta.size, npad, root_index(pe), pe)
    return y[:delta.size]


@pytest.mark.skipif(np.finfo(np.longdouble).nmant < 63, reason="needs x86's 64-bit long double mantissa")
@pytest.mark.parametrize("m", range(1, 32))
def test_slice_roots_are_the_long_double_roots(m):
    """δ^(1/m) by the kernel's Halley iteration is the m-th root within 1.5 ulp (the truth: np.power in long double,
    x86's 64-bit mantissa, whose own error is ≈ 0.3 ulp of a double) from 1e-300 to 1e300 and over the contacts'
    range 1e-12..1 m; np.power(δ, 1/m) in double is farther (its exponent 1/m is rounded: up to 115 ulp at 1e±300)."""
    assert root_index(1.0 / m) == m
    rng = np.random.default_rng(m)
    x = np.concatenate([10.0 ** rng.uniform(-300, 300, 20000), 10.0 ** rng.uniform(-12, 0, 20000),
                        [1e-300, 1e300, 0.5, 1.0, 2.0, 3e-6]])
    truth = np.power(x.astype(np.longdouble), np.longdouble(1) / m)
    ulps = np.abs(_roots(x, 1.0 / m) - truth) / np.spacing(truth.astype(float))
    assert ulps.max() <= 1.5


def test_slice_roots_outside_the_iteration_are_numpys_power():
    """(p − 1)/2 not the reciprocal of an integer ≤ 31 (p = 1.3, p = 1 + 2/40), and any δ > 0 outside [1e-300, 1e300]
    (subnormal, huge), take np.power; an open slice (δ ≤ 0) gets a finite value (its load is masked)."""
    assert root_index(0.15) == 0 and root_index(1.0 / 40.0) == 0 and root_index(0.0) == 0
    x = np.array([3e-6, 1e-9, 0.7, 5e-320, 1e-305, 1e305, 0.0, -2e-6])
    for pe in (0.15, 1.0 / 40.0, 1.0 / 18.0):
        y = _roots(x, pe)
        inside = (x > 0.0) & ((x < 1e-300) | (x > 1e300) | (root_index(pe) == 0))
        assert np.all(y[inside] == np.power(x[inside], pe))
        assert np.all(np.isfinite(y))


def test_family_declares_its_twin():
    assert kind_of(SlicedRaceContact).evaluate.__name__ == "evaluate_sliced_race"


# ------------------------------------------------------------------------------------------------ SlicedGearMesh
RB1, RB2, ALPHA, Z1 = 0.03, 0.045, np.radians(20.0), 20
RBR = 0.12                               # a ring's base radius (internal meshes: gear 1 the planet, gear 2 the ring)
K_MESH, BW = 4.0e8, 0.02
SHAPES = {"constant": StiffnessShape.constant(), "rectangular": StiffnessShape.rectangular(1.6, 1.5, 0.1),
          "fourier": StiffnessShape.fourier(a=(0.1, 0.03), b=(0.05,))}


def _mesh_family(internal, shape, n_m, c, backlash, has1, has2):
    """Three meshes of one kind (gear bodies 0..5, slopes from 18), their slope pairs as asked."""
    rb2 = RBR if internal else RB2
    a0 = ((rb2 - RB1) if internal else (RB1 + rb2)) / np.cos(ALPHA)
    g1, g2 = np.arange(0, 3), np.arange(3, 6)
    s1 = np.array([[18 + 2 * m, 19 + 2 * m] for m in range(3)]) if has1 else None
    s2 = np.array([[24 + 2 * m, 25 + 2 * m] for m in range(3)]) if has2 else None
    poses1, poses2 = _nominal(a0, internal)
    return SlicedGearMesh("mesh", g1, g2, slopes1=s1, slopes2=s2, face_width=BW, slices=n_m, internal=internal,
                          rb1=RB1, rb2=rb2, alpha=ALPHA, a0=a0, teeth1=Z1, k_mean=K_MESH, c_mesh=c,
                          damping_ramp=1e-6 if c else 0.0, backlash=backlash, stiffness=shape,
                          u0=mesh_u0(internal, RB1, rb2, poses1, poses2), phi_ref=LINE), a0


# the meshes' lines of centres [rad], and gear 1 near the origin: the transmission error is the small difference of
# terms r_b (θ − φ_e) that grow with φ_e, whose round-off (an ulp of arctan2 apart between numpy and numba) the
# damping share's slope 60/δ_c² carries into J to ≈ 2e-10 of the block at φ_e ≈ 4.4 rad; at |φ_e| ≤ 1.1 it stays
# at the contact tests' 1e-10
LINE = np.array([0.4, 1.1, -0.7])


def _nominal(a0, internal):
    """(3, 3) nominal poses of gears 1 and 2: gear 2 at a0 along LINE (internal: the planet, gear 1, at a0 from the
    ring along LINE)."""
    p1 = np.column_stack([0.01 * np.arange(3), -0.01 * np.arange(3), np.zeros(3)])
    e = np.column_stack([np.cos(LINE), np.sin(LINE), np.zeros(3)])
    return p1, p1 + (-1.0 if internal else 1.0) * a0 * e


def _mesh_state(rng, a0, internal, turn, slope):
    """Gear 2 of mesh m at a0 from gear 1 (internal: the planet, gear 1, inside at a0 from the ring), turned by turn[m]
    (flank + compressed by ≈ r_b2 θ_2); slopes of ≈ ``slope``; random offsets and velocities."""
    q, v = np.zeros(30), np.zeros(30)
    p1, p2 = _nominal(a0, internal)
    q[:9], q[9:18] = p1.ravel(), p2.ravel()
    q[11:18:3] = turn
    q[:18] += rng.standard_normal(18) * np.tile([1e-7, 1e-7, 1e-6], 6)
    q[18:] = rng.standard_normal(12) * slope
    v[:18] = rng.standard_normal(18) * np.tile([1e-2, 1e-2, 10.0], 6)
    v[18:] = rng.standard_normal(12) * 0.1
    return q, v


@pytest.mark.parametrize("internal", [False, True])
@pytest.mark.parametrize("shape", sorted(SHAPES))
@SETTINGS
@given(fs=frame_states(), n_m=st.sampled_from([1, 4, 11]), c=st.sampled_from([0.0, 2e3]),
       backlash=st.sampled_from([0.0, 1e-5]), has=st.sampled_from([(True, True), (True, False), (False, True)]),
       turn=st.lists(st.sampled_from([-3e-4, -2e-5, 2e-5, 3e-4]), min_size=3, max_size=3),
       slope=st.sampled_from([1e-5, 1e-4, 1e-3]), seed=st.integers(0, 2 ** 31))
def test_sliced_mesh_matches_reference(internal, shape, fs, n_m, c, backlash, has, turn, slope, seed):
    """Flanks open, in the damping ramp (r_b2 · 2e-5 ≈ 0.9 δ_c) and beyond it, slices partly open. Not a flank at
    ≈ 1e-8 m in the ramp: its compression is the difference of terms ≈ 0.05 m, so its round-off is ≈ 1e-9 of itself
    and the share S ∝ δ³ carries that into J_v (seen 3e-10 of the block, structured, in both kernels alike)."""
    elem, a0 = _mesh_family(internal, SHAPES[shape], n_m, c, backlash, *has)
    qf, vf = _mesh_state(np.random.default_rng(seed), a0, internal, turn, slope)
    floor_q, floor_v = _roundoff_floor(elem, fs, qf, vf)
    F = assert_matches_reference(elem, fs, qf, vf, jq_floor=floor_q, jv_floor=floor_v)
    assert np.all(np.isfinite(F))


def _roundoff_floor(elem, fs, qf, vf, trials=4):
    """Per instance: 4 × the largest change of the reference's J_q and J_v when its positions move by a few ulps —
    what a second evaluation of the same law in another order of operations may differ by. A flank compressed by
    ≈ 1e-8 m is the difference of terms ≈ 0.05 m, so the last bits of q move it by ≈ 1e-9 of itself, and the share
    S ∝ δ³ of the damping ramp carries that into both Jacobians (seen 1.3e-10 of the J_q block, seed 17887). A sign,
    a factor 2 or a wrong term is a change of order one of its entries, far above this floor."""
    _, _, Jq0, Jv0 = evaluate(elem, 0.25, fs, qf, vf, None, True)
    rng = np.random.default_rng(0)
    dq, dv = np.zeros(Jq0.shape[0]), np.zeros(Jv0.shape[0])
    for _ in range(trials):
        q = qf * (1.0 + rng.choice([-2.0, 2.0], qf.shape) * np.finfo(float).eps)
        _, _, Jq, Jv = evaluate(elem, 0.25, fs, q, vf, None, True)
        dq = np.maximum(dq, np.abs(Jq - Jq0).reshape(len(dq), -1).max(axis=1))
        dv = np.maximum(dv, np.abs(Jv - Jv0).reshape(len(dv), -1).max(axis=1))
    return 4.0 * dq, 4.0 * dv


def _pairs(rng, n, z2, faults):
    """Tooth-pair data of n meshes of gear 1 (Z1 teeth) with gear 2 (z2 teeth): a cubic excess on every flank face of
    every tooth (≈ 4 µm), with ``faults`` a cracked tooth on gear 1 and a missing one on gear 2, tip relief on both."""
    from mbd.elements.tooth_pairs import ToothPairs, tooth_table
    tables, s1, s2 = [], [], []
    for m in range(n):
        f1, f2 = np.ones(Z1), np.ones(z2)
        if faults:
            f1[3 + m], f2[5] = 0.4, 0.0
        t1 = tooth_table(Z1, rng.normal(0, 4e-6, (Z1, 2, 4)), f1)
        t2 = tooth_table(z2, rng.normal(0, 4e-6, (z2, 2, 4)), f2)
        off = sum(t.size for t in tables)
        s1.append(off)
        s2.append(off + t1.size)
        tables += [t1, t2]
    return ToothPairs(entry=rng.uniform(0, 1, (n, 2)), phase2=rng.uniform(-0.5, 0.5, (n, 2)),
                      relief1=np.array([6e-6, 0.7, 2.0]), relief2=np.array([5e-6, 0.75, 1.0]),
                      table=np.concatenate(tables), start1=np.array(s1, float), start2=np.array(s2, float))


def _error_family(internal, n_m, c, backlash, has1, has2, runout, pairs, rng):
    """_mesh_family's three meshes (rectangular stiffness) with eccentricity of both gears (``runout``: ≈ 5 µm, one
    mesh without) and/or the tooth-pair law (``pairs``)."""
    rb2 = RBR if internal else RB2
    a0 = ((rb2 - RB1) if internal else (RB1 + rb2)) / np.cos(ALPHA)
    s1 = np.array([[18 + 2 * m, 19 + 2 * m] for m in range(3)]) if has1 else None
    s2 = np.array([[24 + 2 * m, 25 + 2 * m] for m in range(3)]) if has2 else None
    poses1, poses2 = _nominal(a0, internal)
    o1 = o2 = None
    if runout:
        o1, o2 = rng.normal(0, 5e-6, (3, 2)), rng.normal(0, 5e-6, (3, 2))
        o1[1], o2[1] = 0.0, 0.0
    pp = _pairs(rng, 3, int(round(rb2 / RB1 * Z1)), faults=True) if pairs else None
    return SlicedGearMesh("mesh", np.arange(0, 3), np.arange(3, 6), slopes1=s1, slopes2=s2, face_width=BW, slices=n_m,
                          internal=internal, rb1=RB1, rb2=rb2, alpha=ALPHA, a0=a0, teeth1=Z1, k_mean=K_MESH, c_mesh=c,
                          damping_ramp=1e-6 if c else 0.0, backlash=backlash, stiffness=SHAPES["rectangular"],
                          u0=mesh_u0(internal, RB1, rb2, poses1, poses2), phi_ref=LINE, offset1=o1, offset2=o2,
                          pairs=pp), a0


@pytest.mark.parametrize("internal", [False, True])
@pytest.mark.parametrize("errors", ["runout", "pairs", "both"])
@SETTINGS
@given(fs=frame_states(), n_m=st.sampled_from([1, 4, 11]), c=st.sampled_from([0.0, 2e3]),
       backlash=st.sampled_from([0.0, 1e-5]), has=st.sampled_from([(True, True), (True, False), (False, True)]),
       turn=st.lists(st.sampled_from([-3e-4, -2e-5, 2e-5, 3e-4]), min_size=3, max_size=3),
       slope=st.sampled_from([1e-5, 1e-4, 1e-3]), seed=st.integers(0, 2 ** 31))
def test_sliced_mesh_with_runout_and_teeth_matches_reference(internal, errors, fs, n_m, c, backlash, has, turn, slope,
                                                             seed):
    """The face-sliced mesh with eccentric gears (the law on the geometric centres, mapped back by the chain rule)
    and the tooth-pair law slice by slice (deviations on every tooth, a cracked and a missing tooth, tip relief):
    the compiled kernel equals the reference (dual numbers through SlicedGearMesh.kernel) to round-off, forces and
    both Jacobians, every slice situation of the lumped test (flanks open, in the ramp, beyond, slices partly open)."""
    rng = np.random.default_rng(seed)
    elem, a0 = _error_family(internal, n_m, c, backlash, *has, runout=errors != "pairs", pairs=errors != "runout",
                             rng=rng)
    qf, vf = _mesh_state(rng, a0, internal, turn, slope)
    floor_q, floor_v = _roundoff_floor(elem, fs, qf, vf)
    F = assert_matches_reference(elem, fs, qf, vf, jq_floor=floor_q, jv_floor=floor_v)
    assert np.all(np.isfinite(F))


@pytest.mark.parametrize("internal", [False, True])
@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_compiled_uniform_slices_are_the_compiled_mesh_with_runout_and_teeth(internal, seed):
    """No relative slope: every slice of the compiled face-sliced kernel is 1/n_m of the compiled unsliced mesh
    (GearMesh, mbd.compiled.mesh), eccentricity and tooth-pair law included — forces and the gears' Jacobian blocks
    to round-off, and no force on the slopes (the slices' moments cancel)."""
    from mbd.elements.gear_mesh import GearMesh
    rng = np.random.default_rng(seed)
    elem, a0 = _error_family(internal, 7, 2e3, 1e-6, True, True, runout=True, pairs=True, rng=rng)
    kw = {k: getattr(elem, k) for k in ("rb1", "rb2", "alpha", "a0", "teeth1", "k_mean", "c_mesh", "damping_ramp",
                                        "u0", "backlash", "phi_ref", "offset1", "offset2", "pairs")}
    lumped = GearMesh("lumped", np.arange(0, 3), np.arange(3, 6), internal=internal, stiffness=elem.stiffness, **kw)
    loaded = 0
    for turn in ([3e-4, -3e-4, 3e-4], [-3e-4, 3e-4, -3e-4]):
        qf, vf = _mesh_state(rng, a0, internal, turn, 0.0)
        qf[18:], vf[18:] = 0.0, 0.0
        Fs, Jqs, Jvs = compiled(elem, FS, qf, vf, None, True)
        Fl, Jql, Jvl = compiled(lumped, FS, qf, vf, None, True)
        for i in range(3):
            scale = np.abs(Fl[i]).max()
            loaded += scale > 1e3
            np.testing.assert_allclose(Fs[i, :6], Fl[i], rtol=0, atol=1e-11 * scale + 1e-9)
            np.testing.assert_allclose(Fs[i, 6:], 0.0, atol=1e-11 * scale * BW + 1e-9)
            for A, B in ((Jqs, Jql), (Jvs, Jvl)):
                np.testing.assert_allclose(A[i, :6, :6], B[i], rtol=0, atol=1e-11 * np.abs(B[i]).max() + 1e-9)
    assert loaded >= 4


def test_family_with_runout_and_teeth_packs_both_error_blocks():
    """The packed layout holds the eccentricity and tooth-pair blocks (G's columns of mbd.compiled.mesh) ahead of the
    face-sliced columns: the kernel finds both."""
    from mbd.compiled import mesh as cmesh
    elem, _ = _error_family(False, 5, 0.0, 0.0, True, True, runout=True, pairs=True, rng=np.random.default_rng(0))
    P, G = kind_of(SlicedGearMesh).pack(elem)
    assert G[cmesh.G_OFFSET] >= 0 and G[cmesh.G_PAIRS] > G[cmesh.G_OFFSET]
    np.testing.assert_array_equal(P[:, int(G[cmesh.G_OFFSET]):int(G[cmesh.G_OFFSET]) + 2], elem.offset1)
    np.testing.assert_array_equal(P[:, -4], elem.face_width)


# ------------------------------------------------------------------------------------------- the sliced race's outputs
# The outputs from the compiled kernel (outputs_sliced_race, what the window statistics read on the compiled path)
# against the reference's, SlicedRaceContact.kernel: every output of the family (the planar race's, the tilt, the slopes,
# the load centroid, the slice loads and what the statistics take of them) at random loaded states with tilts, slopes,
# profile drops, row offsets and damping, both raceways, every traction law and both power paths (the root iteration:
# 10/9, 1.5; np.power: 1.3); contacts with every slice closed, with an edge load and open ones in each family.

OUTPUTS_RTOL = 1e-12       # the slices' power within 1.5 ulp, sums in the reference's order: seen below 1e-14


def _compiled_outputs(elem, qf, vf, t=0.25):
    """{name: (n,)} of the compiled kernel; O starts NaN so that every row must be written."""
    P, G = kind_of(type(elem)).pack(elem)
    ql, vl = np.ascontiguousarray(qf[elem.dofs]), np.ascontiguousarray(vf[elem.dofs])
    names = output_names(elem)
    O = np.full((len(names), elem.n), np.nan)
    outputs_sliced_race(t, FS.phi, FS.omega, FS.domega, ql, vl, np.zeros((elem.n, 0)), P, G, O)
    return dict(zip(names, O))


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", sorted(TRACTIONS))
@pytest.mark.parametrize("n_s, exponent", [(1, 10.0 / 9.0), (5, 1.5), (21, 10.0 / 9.0), (21, 1.3)])
@pytest.mark.parametrize("seed, ramp", [(1, 0.0), (2, 0.0), (3, 3e-6)])
def test_sliced_race_outputs_equal_the_reference(kind, law, n_s, exponent, seed, ramp):
    """Every output of the compiled kernel is the reference's to 1e-12 (of itself or of the family's largest), and the
    load, the largest slice load and the loaded slices' count are those of the family's own slice loads."""
    rng = np.random.default_rng(seed)
    press = [6e-6, 1e-6, -30e-6, 4e-6, 0.5e-6, 2e-6]          # loaded, loaded, open (skipped), ...
    tilt = np.array([0.0, 8e-4, 0.0, -3e-4, 2e-4, 0.0]) + rng.uniform(-1e-4, 1e-4, N)
    pin_slope = rng.uniform(-3e-4, 3e-4, 2)
    drop = rng.uniform(0.0, 1e-6, (N, n_s))
    elem = _family(kind, n_s, TRACTIONS[law], zeta=0.05, drop=drop, row=3e-3 if seed == 2 else 0.0,
                   pin_slope=pin_slope, exponent=exponent, ramp=ramp)
    qf, vf = _state(kind, rng, press, tilt, rng.uniform(-5e-4, 5e-4, 2))
    _, ref, _, _ = evaluate(elem, 0.25, FS, qf, vf, None, False)
    got = _compiled_outputs(elem, qf, vf)
    assert set(ref) - set(got) == {"angle"} and set(got) <= set(ref)
    assert set(got) == set(OUTPUT_NAMES["sliced.sliced_race"]) | {f"slice_load_{k}" for k in range(n_s)}
    loads = elem.slice_loads(qf, vf)
    assert np.all(loads[2] == 0.0) and np.all(loads[0] > 0.0)                      # an open and a loaded contact
    if n_s > 1:
        assert np.any(loads[1] == 0.0) and np.any(loads[1] > 0.0)                   # an edge load
    for key, val in got.items():
        want = np.asarray(ref[key], float)
        assert np.all(np.isfinite(val)), key
        np.testing.assert_allclose(val, want, rtol=OUTPUTS_RTOL, atol=OUTPUTS_RTOL * np.abs(want).max(initial=0.0), err_msg=key)
    # what the statistics read of the slice loads, from the slice loads themselves
    np.testing.assert_array_equal(got["loaded_slices"], (loads > 0.0).sum(axis=1))
    np.testing.assert_allclose(got["load"], loads.sum(axis=1), rtol=1e-13)
    np.testing.assert_allclose(got["max_slice_load"], loads.max(axis=1), rtol=1e-13)
