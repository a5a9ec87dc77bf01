"""Compiled GearMesh and generic kernels (mbd.compiled.mesh, mbd.compiled.generic) against the reference
:func:`mbd.element.evaluate`: forces and Jacobians to 1e-10 of each instance's block, internal-state
updates to 1e-14, NotImplementedError for what cannot be compiled.

arctan2: numpy evaluates it with its own SIMD code, which differs from the C library's (numba's) by
one ulp in a few percent of calls. The mesh's transmission error s ≈ 1e-5 m is the small difference
of terms r_b·θ of order metres, so one ulp of φ_e moves the force by ~1e-11 of itself (more near
contact onset) — round-off of the reference, not a modelling difference. The strict comparison
therefore runs the reference with the C library's arctan2 (:func:`libm_arctan2`); a separate test
bounds the difference to the unchanged reference by that round-off.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mbd.elements
from mbd.compiled import generic, mesh
from mbd.compiled.registry import kind_of
from mbd.element import evaluate
from mbd.elements import (BeamSupport, BodySpring, CoordinateSpring, ForceSource, GearMesh, GroundSupport, Ramp, SlopeGyroscopic,
                          SpeedDrive, StiffnessShape, TorqueSource, TorsionalSpring)
from mbd.elements.gear_mesh import RectangularStiffness
from mbd.model import FrameState

from components.geometry import mesh_damping

from tests.support.mesh import (ATOL, K_MEAN, PAIRS, SHAPES, assert_matches_reference, libm_arctan2, make_mesh,
                                perturbed_state, rb)
from tests.support.strategies import dampings, frame_states, full_states, stiffnesses

RTOL_UPDATE = 1e-14
NB = 4                # bodies of the generic-family states
# the mesh suite's shapes, plus a Fourier series with unequal numbers of cosine and sine terms
MESH_SHAPES = {**SHAPES, "fourier_uneven": StiffnessShape.fourier(a=[0.1], b=[0.05, 0.02, -0.01])}


# --------------------------------------------------------------------------------------- mesh states
@st.composite
def mesh_cases(draw):
    """(family, q, v, fs): one mesh kind or the fused external+internal family, random shape, backlash,
    damping, rolling states with flanks in and out of contact (and fast separations, which clip)."""
    seed = draw(st.integers(0, 2**32 - 1))
    kind = draw(st.sampled_from(sorted(PAIRS) + ["fused"]))
    shape = MESH_SHAPES[draw(st.sampled_from(sorted(MESH_SHAPES)))]
    backlash = draw(st.sampled_from([0.0, 1e-5, 4e-5]))
    zeta = draw(st.sampled_from([0.0, 0.07, 0.5]))
    ramp = draw(st.sampled_from([0.0, 3e-6, 3e-5]))
    sep = draw(st.sampled_from([0.0, 3.0, 30.0]))   # m/s of random relative translation: clips the damper
    rng = np.random.default_rng(seed)

    def part(pair, name):
        p1, p2, q, v = perturbed_state(pair, rng, 3)
        internal, z1, z2 = PAIRS[pair]
        c = float(mesh_damping(zeta, K_MEAN, 1e-3, 2e-3, rb(z1), rb(z2)))
        v = v + sep * rng.normal(0.0, 1.0, v.size) * np.tile([1.0, 1.0, 0.0], v.size // 3)
        return make_mesh(pair, p1, p2, backlash=backlash, shape=shape, c_mesh=c, damping_ramp=ramp, p0=rng.uniform(),
                         name=name), q, v

    if kind == "fused":
        ea, qa, va = part("sun_planet", "ext")
        eb, qb, vb = part("planet_ring", "int")
        eb.dofs = eb.dofs + qa.size             # gear bodies after part a's
        elem = GearMesh.fuse([ea, eb])
        q, v = np.concatenate([qa, qb]), np.concatenate([va, vb])
    else:
        elem, q, v = part(kind, kind)
    return elem, q, v, draw(frame_states())


def flank_situations(elem, q, v, fs):
    """Set of contact situations present: drive/coast flank loaded, clipped (compressed, no force), open."""
    _, out, _, _ = evaluate(elem, 0.0, fs, q, v, None, jac=False)
    found = set()
    for d, f, name in ((out["deflection"], out["force_drive"], "drive"),
                       (out["deflection_coast"], out["force_coast"], "coast")):
        found |= {name} if np.any(f > 0) else set()
        found |= {"clipped"} if np.any((d > 0) & (f == 0)) else set()
        found |= {"open"} if np.any(d <= 0) else set()
    return found


# ------------------------------------------------------------------------------------------ mesh tests
@settings(max_examples=60)
@given(case=mesh_cases())
def test_gear_mesh_matches_reference(case):
    elem, q, v, fs = case
    with libm_arctan2():
        assert_matches_reference(elem, 0.0, fs, q, v)


def test_gear_mesh_cases_cover_every_contact_situation():
    """The states above do reach every branch (fixed draws, so the check is deterministic)."""
    found = set()
    for i in range(40):
        elem, q, v, fs = _fixed_mesh_case(i)
        found |= flank_situations(elem, q, v, fs)
        with libm_arctan2():
            assert_matches_reference(elem, 0.0, fs, q, v)
    assert found == {"drive", "coast", "clipped", "open"}, found


def _fixed_mesh_case(i):
    kinds = sorted(PAIRS)
    rng = np.random.default_rng(1000 + i)
    pair, shape = kinds[i % 3], MESH_SHAPES[sorted(MESH_SHAPES)[(i // 3) % 4]]
    p1, p2, q, v = perturbed_state(pair, rng, 4)
    v = v + (30.0 if i % 2 else 0.0) * rng.normal(0.0, 1.0, v.size) * np.tile([1.0, 1.0, 0.0], v.size // 3)
    elem = make_mesh(pair, p1, p2, backlash=[0.0, 1e-5][i % 2], shape=shape, c_mesh=2e3, p0=rng.uniform())
    return elem, q, v, FrameState(0.3 * i, 10.0 * i, 0.0)


@settings(max_examples=30)
@given(case=mesh_cases())
def test_gear_mesh_matches_unpatched_reference_to_its_round_off(case):
    """Against numpy's own arctan2: forces within the round-off of the transmission error (ε·k·|r_b θ|
    summed over its terms), Jacobians still to 1e-10."""
    elem, q, v, fs = case
    th1, th2 = q[elem.dofs[:, 2]], q[elem.dofs[:, 5]]
    size = elem.rb1 * (np.abs(th1) + np.pi) + elem.rb2 * (np.abs(th2) + np.pi) + np.abs(elem.u0)
    k_max = elem.k_mean * 3.0                         # bounds every shape's factor used here
    assert_matches_reference(elem, 0.0, fs, q, v, F_atol=16 * np.finfo(float).eps * k_max * size)


def test_rectangular_shape_parameters_are_per_instance_in_a_fused_family():
    rng = np.random.default_rng(3)
    parts, qs, vs = [], [], []
    for j, (pair, eps) in enumerate((("sun_planet", 1.6), ("planet_ring", 1.8))):
        p1, p2, q, v = perturbed_state(pair, rng, 3)
        e = make_mesh(pair, p1, p2, shape=StiffnessShape.rectangular(eps, ratio=1.2 + j, smoothing=0.05),
                      c_mesh=1e3, p0=rng.uniform(), name=pair)
        e.dofs = e.dofs + sum(x.size for x in qs)
        parts.append(e)
        qs.append(q)
        vs.append(v)
    fused = GearMesh.fuse(parts)
    P, G = mesh.pack_gear_mesh(fused)
    assert P.shape == (6, 19) and G[0] == mesh.SHAPE_RECTANGULAR
    np.testing.assert_array_equal(P[:, mesh.P_RECT_RATIO], [1.2] * 3 + [2.2] * 3)
    np.testing.assert_array_equal(P[:, mesh.P_SIGMA], [1.0] * 3 + [-1.0] * 3)
    with libm_arctan2():
        assert_matches_reference(fused, 0.0, FrameState(0.0, 0.0, 0.0), np.concatenate(qs), np.concatenate(vs))


def test_gear_mesh_unknown_shape_is_not_implemented():
    class Wobble(RectangularStiffness):
        pass
    rng = np.random.default_rng(0)
    p1, p2, _, _ = perturbed_state("sun_planet", rng, 2)
    e = make_mesh("sun_planet", p1, p2, shape=Wobble(1.6, 1.5, 0.05))
    with pytest.raises(NotImplementedError, match="GearMesh.*Wobble"):
        mesh.pack_gear_mesh(e)


# ---------------------------------------------------------------------------------- generic families
def _markers(draw, n):
    return np.array([[draw(st.floats(-0.05, 0.05)), draw(st.floats(-0.05, 0.05))] for _ in range(n)])


@given(data=st.data(), fs=frame_states(), state=full_states(NB), iso=st.booleans())
def test_ground_support_matches_reference(data, fs, state, iso):
    q, v = state
    aniso = {} if iso else dict(ky=data.draw(stiffnesses()), cy=data.draw(dampings()))
    e = GroundSupport("sup", [0, 2, 3], kx=data.draw(stiffnesses()), cx=data.draw(dampings()), **aniso,
                      anchor=_markers(data.draw, 3), k_theta=data.draw(stiffnesses(1, 1e4)),
                      c_theta=data.draw(dampings()), theta0=data.draw(st.floats(-1, 1)))
    assert e.isotropic == iso
    assert_matches_reference(e, 0.1, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_body_spring_matches_reference(data, fs, state):
    q, v = state
    e = BodySpring("bush", [0, 1, 2], [1, 2, 3], k=data.draw(stiffnesses()), c=data.draw(dampings()),
                   marker_a=_markers(data.draw, 3), marker_b=_markers(data.draw, 3))
    assert_matches_reference(e, 0.0, fs, q, v)


@given(data=st.data(), fs=frame_states(), state=full_states(NB))
def test_torsional_spring_matches_reference(data, fs, state):
    q, v = state
    e = TorsionalSpring("tors", [0, 3], [2, 1], k=data.draw(stiffnesses(1, 1e5)), c=data.draw(dampings()),
                        theta0=data.draw(st.floats(-1, 1)))
    assert_matches_reference(e, 0.0, fs, q, v)


_RAMPS = st.one_of(st.none(), st.tuples(st.floats(0.0, 0.5), st.floats(0.0, 0.5)).map(lambda r: Ramp(r[0], r[0] + r[1])))


@given(fs=frame_states(), state=full_states(NB), ramp=_RAMPS, t=st.floats(-0.1, 1.2),
       torque=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=2))
def test_torque_source_matches_reference(fs, state, ramp, t, torque):
    q, v = state
    assert_matches_reference(TorqueSource("load", [0, 3], torque=torque, ramp=ramp), t, fs, q, v)


@given(fs=frame_states(), state=full_states(NB), ramp=_RAMPS, t=st.floats(-0.1, 1.2),
       force=st.lists(st.floats(-1e3, 1e3), min_size=6, max_size=6))
def test_force_source_matches_reference(fs, state, ramp, t, force):
    q, v = state
    e = ForceSource("radial", [1, 2, 3], force=np.reshape(force, (3, 2)), ramp=ramp)
    assert_matches_reference(e, t, fs, q, v)


@st.composite
def speed_drives(draw):
    """A drive with or without an integral term, with no ripple or one to three harmonics (a rig's orders
    1, 2, 4 of its speed; Ω may be negative for a reverse-turning drive)."""
    integral = draw(st.booleans())
    w = draw(st.floats(-400, 400))
    orders = draw(st.sampled_from([(), (1,), (2, 4), (1, 2, 4)]))
    ripple = [(k * (w if abs(w) > 1.0 else 100.0), draw(st.floats(0, 20)), draw(st.floats(-4, 4))) for k in orders]
    e = SpeedDrive("drive", [1, 2], omega_ref=w, k=draw(stiffnesses(1, 1e5)),
                   c=draw(dampings()), k_i=draw(stiffnesses(1, 1e3)) if integral else 0.0,
                   theta0=[draw(st.floats(-1, 1)), draw(st.floats(-1, 1))], ripple=ripple or None)
    z = np.array([draw(st.floats(-1e-2, 1e-2)) for _ in range(2)]) if integral else None
    assert (e.init_internal() is None) == (not integral)
    return e, z


@given(drive=speed_drives(), fs=frame_states(), state=full_states(NB), t=st.floats(0.0, 2.0))
def test_speed_drive_matches_reference(drive, fs, state, t):
    e, z = drive
    q, v = state
    assert_matches_reference(e, t, fs, q, v, z)


@given(drive=speed_drives(), fs0=frame_states(), fs1=frame_states(), s0=full_states(NB), s1=full_states(NB),
       t0=st.floats(0.0, 2.0), dt=st.floats(1e-7, 1e-2))
def test_speed_drive_update_matches_update_internal(drive, fs0, fs1, s0, s1, t0, dt):
    e, z = drive
    (q0, v0), (q1, v1) = s0, s1
    t1 = t0 + dt
    d = e.dofs
    ref = e.update_internal(z, t0, t1, fs0, fs1, list(q0[d].T), list(v0[d].T), list(q1[d].T), list(v1[d].T))
    P, G = generic.pack_speed_drive(e)
    zz = np.zeros((e.n, 0)) if z is None else z.reshape(-1, 1).copy()
    z_before = zz.copy()
    z1 = generic.update_speed_drive(zz, t0, t1, q0[d], v0[d], q1[d], v1[d], P, G, fs0.phi, fs1.phi)
    np.testing.assert_array_equal(zz, z_before)                   # the input state is not modified
    if z is None:
        assert ref is None and z1.shape == (e.n, 0)
        return
    assert z1.shape == (e.n, 1)
    err = np.abs(z1[:, 0] - ref).max()
    assert err <= RTOL_UPDATE * np.abs(ref).max() + ATOL, (z1[:, 0], ref)


# ------------------------------------------------------------------------------- what cannot compile
@pytest.mark.parametrize("make, family", [
    (lambda: TorqueSource("tq", [0], torque=lambda t: np.sin(t)), "TorqueSource"),
    (lambda: TorqueSource("tq", [0], torque=1.0, ramp=lambda t: min(t, 1.0)), "TorqueSource"),
    (lambda: ForceSource("fs", [0], force=lambda t: [[t, 0.0]]), "ForceSource"),
    (lambda: ForceSource("fs", [0], force=(1.0, 0.0), ramp=lambda t: t), "ForceSource"),
    (lambda: SpeedDrive("sd", 0, omega_ref=lambda t: (10.0 * t, np.full(1, 10.0)), k=1.0), "SpeedDrive"),
])
def test_callables_of_time_are_not_implemented(make, family):
    e = make()
    pack = kind_of(type(e)).pack
    with pytest.raises(NotImplementedError, match=f"{family}.*callable"):
        pack(e)


def test_kernel_tables():
    families = lambda module: {c: kind_of(c) for c in vars(mbd.elements).values()      # noqa: E731
                               if isinstance(c, type) and str(getattr(c, "compiled_twin", None)).startswith(module)}
    tables = families("mesh."), families("generic.")
    assert set(tables[0]) == {GearMesh}
    assert set(tables[1]) == {GroundSupport, BodySpring, TorsionalSpring, TorqueSource, ForceSource, SpeedDrive,
                              SlopeGyroscopic, CoordinateSpring, BeamSupport}
    for table in tables:
        for cls, twin in table.items():
            assert callable(twin.pack) and callable(twin.evaluate)
            assert (twin.update is not None) == (cls is SpeedDrive)
