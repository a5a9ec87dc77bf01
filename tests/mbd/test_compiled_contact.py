"""The compiled contact kernels (mbd.compiled.contact) equal the reference kernels (mbd.element.evaluate over
mbd.elements.contact) to round-off: forces, J_q and J_v to 1e-10 of each instance's largest entry of the block
(F row, J_q or J_v matrix), on random physical states (the contact scenes and strategies of tests.support.contact);
update_* equals update_internal.

The comparison (compiled, assert_matches_reference) and its tolerances, with why they are what they are
(J_v's floor per newton of force, the EHL film law's bounds), are in tests/support/contact.py beside their constants."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

import mbd.elements
from mbd.elements.pocket_film import CageDrag, PocketFilm
from mbd.elements.race_film import RaceFilm
from mbd.compiled.contact import TRACTION_IDS, pack_race
from mbd.compiled.registry import kind_of
from mbd.element import evaluate
from mbd.model import FrameState
from mbd.elements.contact import (IMPACT_LAWS, GuideContact, HoupertRolling, HydrodynamicLand, LubricantDrag,
                                  PocketContact, PocketRetention, RaceContact, SlideRollTraction, TanhTraction,
                                  Traction)

from tests.support.contact import (C_G, DM, DR, EHL, FILM, K_G, K_HZ, M_ROLLER, N, TANH, assert_matches_reference,
                                   compiled, drag_scene, drag_states, guide_scene, guide_states, pocket_scene,
                                   pocket_states, race_scene, race_states, retention_scene, retention_states,
                                   stored_speeds)
from tests.support.strategies import frame_states

SETTINGS = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
TRACTIONS = {"tanh": TANH, "ehl": EHL, "film": FILM}
LAWS = st.sampled_from(sorted(IMPACT_LAWS))
MULTS = st.one_of(st.just(1), st.lists(st.integers(1, 3), min_size=N, max_size=N))


def race(kind, mk, R, traction, *, exponent=10.0 / 9.0, zeta=0.05, multiplicity=1, name="race", bodies=None,
         ramp=0.0):
    rollers, race_body = bodies if bodies is not None else (np.arange(1, N + 1), 0)
    return RaceContact(name, rollers, race_body, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_HZ,
                       exponent=exponent, zeta=zeta, m_roller=M_ROLLER, traction=traction, multiplicity=multiplicity,
                       damping_ramp=ramp)


# a damping ramp δ_c of 0, of 5 µm (the drawn compressions of 2–30 µm on and past its smoothstep), per instance
RACE_LAW = dict(exponent=st.sampled_from([10.0 / 9.0, 1.5, 1.0]), zeta=st.sampled_from([0.0, 0.05, 0.3]),
                multiplicity=MULTS, ramp=st.one_of(st.sampled_from([0.0, 5e-6, 4e-5]),
                                                   st.lists(st.sampled_from([0.0, 1e-5]), min_size=N, max_size=N)))


# ---------------------------------------------------------------------------------------------- race
@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl", "film"])
@SETTINGS
@given(data=st.data(), fs=frame_states(), **RACE_LAW)
def test_race_matches_reference(kind, law, data, fs, exponent, zeta, multiplicity, ramp):
    qf, vf, mk, R = race_scene(kind, *data.draw(race_states(kind)))
    elem = race(kind, mk, R, TRACTIONS[law], exponent=exponent, zeta=zeta, multiplicity=multiplicity, ramp=ramp)
    assert_matches_reference(elem, fs, qf, vf)


def _joined(a, b):
    """Full state of two scenes side by side (the second's bodies renumbered after the first's)."""
    return np.concatenate([a[0], b[0]]), np.concatenate([a[1], b[1]])


@pytest.mark.parametrize("law", ["tanh", "ehl", "film"])
@SETTINGS
@given(data=st.data(), fs=frame_states(), m_in=MULTS, m_out=MULTS)
def test_fused_inner_outer_race_family(law, data, fs, m_in, m_out):
    """Inner and outer raceways fused into one family (per-instance κ, marker, radius, multiplicity)."""
    qi, vi, mki, Ri = race_scene("inner", *data.draw(race_states("inner")))
    qo, vo, mko, Ro = race_scene("outer", *data.draw(race_states("outer")))
    qf, vf = _joined((qi, vi), (qo, vo))
    tr = TRACTIONS[law]
    inner = race("inner", mki, Ri, tr, multiplicity=m_in, name="inner", ramp=1e-5)
    outer = race("outer", mko, Ro, tr, multiplicity=m_out, name="outer", bodies=(np.arange(N + 2, 2 * N + 2), N + 1))
    fused = RaceContact.fuse([inner, outer])
    P, G = pack_race(fused)
    np.testing.assert_array_equal(P[:, 0], [1.0] * N + [-1.0] * N)
    np.testing.assert_array_equal(P[:, 8], [1e-5] * N + [0.0] * N)          # the damping ramp, per instance
    assert_matches_reference(fused, fs, qf, vf)
    # the fused family's compiled forces are its parts' (compiled, separately)
    F, Jq, _ = compiled(fused, fs, qf, vf, None, True)
    for part, sl in ((inner, slice(0, N)), (outer, slice(N, 2 * N))):
        Fp, Jqp, _ = compiled(part, fs, qf, vf, None, True)
        np.testing.assert_array_equal(F[sl], Fp)
        np.testing.assert_array_equal(Jq[sl], Jqp)


def test_race_pack_layout_and_unknown_traction():
    qf, vf, mk, R = race_scene("inner", (0, 0, 0.3), (0, 0, 0), 0.2, [1.0], [1e-5], [0], [0], [0])
    P, G = pack_race(race("inner", mk, R, EHL, multiplicity=2, bodies=([1], 0), ramp=2e-7))
    assert P.shape == (1, 9) and P.flags.c_contiguous and P[0, 0] == 1.0 and P[0, 7] == 2.0 and P[0, 8] == 2e-7
    np.testing.assert_array_equal(G, [10.0 / 9.0, TRACTION_IDS[SlideRollTraction], EHL.A, EHL.B, EHL.C, EHL.D,
                                      EHL.u_reg, EHL.s_eps, 0.0, 0.0, 0.0])
    assert TRACTION_IDS[TanhTraction] == 0 and pack_race(race("inner", mk, R, TANH, bodies=([1], 0)))[1][1] == 0
    # the EHL law's last column: L / u² = β η₀ / k of its thermal reduction
    assert pack_race(race("inner", mk, R, FILM, bodies=([1], 0)))[1][10] == FILM.beta * FILM.eta0 / FILM.k_oil

    class Linear(Traction):
        def coefficient(self, v_s, u_roll=None):
            return 0.01 * v_s

    with pytest.raises(NotImplementedError, match="odd.*Linear"):
        pack_race(race("inner", mk, R, Linear(), name="odd", bodies=([1], 0)))


# -------------------------------------------------------------------------------------------- impacts
def _with_law(elem, name):
    """The element with another impact damping law (λ from its restitution)."""
    law = IMPACT_LAWS[name]()
    elem.impact_law, elem.lam = law, np.asarray(law.damping(elem.restitution), float)
    return elem


@st.composite
def impact_z(draw):
    """None-equivalent zeros, or stored approach speeds (some 0: an impact beginning in this step)."""
    return draw(st.one_of(st.just(np.zeros((N, 4))), stored_speeds()))


@SETTINGS
@given(state=pocket_states(), z=impact_z(), fs=frame_states(), law=LAWS, mult=MULTS,
       fast=st.one_of(st.none(), st.lists(st.floats(-5.0, 5.0), min_size=N, max_size=N)),
       mu=st.sampled_from([0.0, 0.1]))
def test_pocket_matches_reference(state, z, fs, law, mult, fast, mu):
    state = list(state)
    if fast is not None:          # fast circumferential motion: separation clips the force to zero
        state[5] = fast
    qf, vf, elem, _ = pocket_scene(*state, mu=mu, multiplicity=mult)
    assert_matches_reference(_with_law(elem, law), fs, qf, vf, z)


@pytest.mark.parametrize("land", ["dry", "hydrodynamic"])
@SETTINGS
@given(state=guide_states(), z=impact_z(), fs=frame_states(), law=LAWS,
       fast=st.one_of(st.none(), st.lists(st.floats(-5.0, 5.0), min_size=N, max_size=N)),
       mu=st.sampled_from([0.0, 0.1]))
def test_guide_matches_reference(land, state, z, fs, law, fast, mu):
    state = list(state)
    if fast is not None:          # fast radial motion
        state[4] = fast
    film = HydrodynamicLand(eta=0.025, width=4e-3, min_film=1e-6) if land == "hydrodynamic" else None
    qf, vf, elem = guide_scene(*state, mu=mu, land=film)
    assert_matches_reference(_with_law(elem, law), fs, qf, vf, z)


def test_impact_onset_force_does_not_depend_on_the_rate():
    """At an onset (no stored speed, ẋ > v_min) F = K x (1 + λ): the compiled ∂F/∂v is exactly 0 without friction,
    the reference's is round-off (the floor JV_FLOOR·|F| stands for)."""
    qf, vf, elem = guide_scene((0.07, -0.04, 0.2), (1.0, 2.0, 300.0), [C_G + 2e-5], [0.4], [0.3], [0.2], [50.0], mu=0.0)
    F, Jq, Jv = compiled(elem, FrameState(0.0, 0.0, 0.0), qf, vf, np.zeros((1, 4)), True)
    _, _, _, Jv_ref = evaluate(elem, 0.0, FrameState(0.0, 0.0, 0.0), qf, vf, None, True)
    assert F[0, 0] != 0 and np.all(Jv == 0) and np.abs(Jv_ref).max() <= 1e-14 * K_G * 2e-5 / 0.3


@st.composite
def cached_states(draw):
    """A stored state z: approach speed 0 or not, cached x, ẋ of a previous step, valid or not (first step)."""
    z = draw(stored_speeds())
    z[:, 3] = draw(st.lists(st.sampled_from([0.0, 1.0]), min_size=N, max_size=N))
    return z


@pytest.mark.parametrize("kind", ["pocket", "guide"])
@SETTINGS
@given(data=st.data(), z=cached_states())
def test_update_matches_update_internal(kind, data, z):
    if kind == "pocket":
        s0, s1 = data.draw(pocket_states()), data.draw(pocket_states())
        q0, v0, elem, _ = pocket_scene(*s0)
        q1, v1, _, _ = pocket_scene(*s1[:2], s0[2], *s1[3:])      # the same pockets
    else:
        s0, s1 = data.draw(guide_states()), data.draw(guide_states())
        q0, v0, elem = guide_scene(*s0)
        q1, v1, _ = guide_scene(*s1)
    twin = kind_of(type(elem))
    pack, update = twin.pack, twin.update
    P, G = pack(elem)
    loc = lambda a: np.ascontiguousarray(a[elem.dofs])    # noqa: E731
    cols = lambda a: list(a[elem.dofs].T)                  # noqa: E731
    fs0, fs1 = data.draw(frame_states()), data.draw(frame_states())
    # the pocket's s = (d_m/2)·(β − θ_g − ψ) carries an ulp of the angles (arctan2: numpy's and libm's differ
    # by one), so its absolute round-off is ~1e-16·d_m/2 whatever s; the guide's gap is bitwise the reference's
    ax = 1e-14 * DM / 2 if kind == "pocket" else 0.0
    for zz in (np.zeros((N, 4)), z):
        ref = elem.update_internal(zz.copy(), 0.1, 0.1 + 1e-6, fs0, fs1, cols(q0), cols(v0), cols(q1), cols(v1))
        got = update(zz.copy(), 0.1, 0.1 + 1e-6, loc(q0), loc(v0), loc(q1), loc(v1), P, G)
        np.testing.assert_array_equal(got[:, 3], ref[:, 3])
        # a roller centred in its pocket to round-off (|s| ≲ ulp): ḋ = sign(s)·ṡ takes the sign of that round-off
        centred = np.abs(elem._geometry(cols(q1), cols(v1))[3]) <= ax if kind == "pocket" else np.zeros(N, bool)
        np.testing.assert_allclose(got[~centred, 2], ref[~centred, 2], rtol=1e-14, atol=0)
        np.testing.assert_allclose(got[:, 1], ref[:, 1], rtol=1e-14, atol=ax)
        # an onset speed interpolated at x = 0 inherits the gaps' round-off through θ = x0/(x0 − x1)
        xs, xds = elem._gap(cols(q0), cols(v0))
        valid = zz[:, 3] > 0
        x0, xd0 = np.where(valid, zz[:, 1], xs), np.where(valid, zz[:, 2], xds)
        x1, xd1 = ref[:, 1], ref[:, 2]
        onset = (x0 <= 0) & (x1 > 0) & (zz[:, 0] == 0)
        spread = np.abs(xd1 - xd0) * 2 * ax / np.maximum(np.abs(x0 - x1), 1e-300)
        tol = 1e-14 * np.abs(ref[:, 0]) + np.where(onset, spread, 0.0)
        # a roller centred at the start: the start rate ḋ₀ = sign(s)·ṡ has the sign of s's round-off
        start_centred = np.abs(elem._geometry(cols(q0), cols(v0))[3]) <= ax if kind == "pocket" else centred
        ok = np.abs(got[:, 0] - ref[:, 0]) <= tol
        assert np.all(ok | (onset & start_centred)), (got[:, 0], ref[:, 0], tol)


# ----------------------------------------------------------------------------------------------- drag
@SETTINGS
@given(state=drag_states(), fs=frame_states(), mult=MULTS)
def test_drag_matches_reference(state, fs, mult):
    qf, vf, elem, _ = drag_scene(*state, multiplicity=mult)
    assert_matches_reference(elem, fs, qf, vf)


@SETTINGS
@given(state=drag_states(), fs=frame_states(), mult=MULTS, eta=st.sampled_from([1e-4, 1.3e-3, 0.5]))
def test_viscous_drag_matches_reference(state, fs, mult, eta):
    """The viscous churning law (C_d(Re) on the orbit, the spin's viscous moment)."""
    qf, vf, elem, _ = drag_scene(*state, multiplicity=mult, eta=eta)
    assert_matches_reference(elem, fs, qf, vf)


ROLL = HoupertRolling(eta0=0.025, E_red=2.31e11, length=9e-3, u_reg=0.1)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl", "film"])
@SETTINGS
@given(data=st.data(), fs=frame_states(), **RACE_LAW)
def test_race_with_rolling_resistance_matches_reference(kind, law, data, fs, exponent, zeta, multiplicity, ramp):
    qf, vf, mk, R = race_scene(kind, *data.draw(race_states(kind)))
    rollers, race_body = np.arange(1, N + 1), 0
    elem = RaceContact("race", rollers, race_body, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_HZ,
                       exponent=exponent, zeta=zeta, m_roller=M_ROLLER, traction=TRACTIONS[law],
                       multiplicity=multiplicity, rolling=ROLL, damping_ramp=ramp)
    assert_matches_reference(elem, fs, qf, vf)


@SETTINGS
@given(data=st.data(), fs=frame_states(), m_in=MULTS, m_out=MULTS)
def test_fused_race_family_with_rolling_resistance(data, fs, m_in, m_out):
    """Inner and outer raceways with rolling resistance fused into one family: per-instance κ and R_red."""
    qi, vi, mki, Ri = race_scene("inner", *data.draw(race_states("inner")))
    qo, vo, mko, Ro = race_scene("outer", *data.draw(race_states("outer")))
    qf, vf = _joined((qi, vi), (qo, vo))
    mk = dict(D=DR, K=K_HZ, exponent=10.0 / 9.0, zeta=0.05, m_roller=M_ROLLER, traction=FILM, rolling=ROLL)
    inner = RaceContact("inner", np.arange(1, N + 1), 0, kind="inner", race_marker=mki, R_race=Ri, multiplicity=m_in,
                        **mk)
    outer = RaceContact("outer", np.arange(N + 2, 2 * N + 2), N + 1, kind="outer", race_marker=mko, R_race=Ro,
                        multiplicity=m_out, **mk)
    assert inner.fuse_key() == outer.fuse_key()
    assert_matches_reference(RaceContact.fuse([inner, outer]), fs, qf, vf)


def test_default_packs_are_unchanged_by_the_opt_in_laws():
    """Without rolling resistance or viscous churning the packs are the plain laws' (G of 11, P of 4 columns):
    the kernels take the plain branches."""
    qf, vf, mk, R = race_scene("inner", (0, 0, 0), (0, 0, 0), 0.0, [0.3], [1e-5], [0.0], [2.0], [0.0])
    plain = race("inner", mk, R, TANH, bodies=([1], 0))
    assert pack_race(plain)[1].size == 11
    rolled = RaceContact("race", [1], 0, kind="inner", race_marker=mk, R_race=R, D=DR, K=K_HZ, exponent=10 / 9,
                         zeta=0.05, m_roller=M_ROLLER, traction=TANH, rolling=ROLL)
    assert pack_race(rolled)[1].size == 16
    assert plain.fuse_key() != rolled.fuse_key()
    _, _, drag, _ = drag_scene((0, 0, 0), (0, 0, 0), 0.0, [0.0], [0.0], [1.0], [0.0], [0.0])
    assert kind_of(LubricantDrag).pack(drag)[0].shape[1] == 4


def test_drag_zero_relative_orbit_has_zero_jacobian():
    qf, vf, elem, _ = drag_scene((0, 0, 0.2), (1.0, -2.0, 440.0), 0.3, [0.5, 2.0], [0, 1e-5], [440.0, 440.0],
                                 [0.0, 0.05], [100.0, 0.0])
    F, Jq, Jv = compiled(elem, FrameState(0.3, 40.0, 0.0), qf, vf, None, True)
    assert np.all(np.abs(F) <= 1e-20) and np.all(np.abs(Jq) <= 1e-12) and np.all(np.abs(Jv) <= 1e-12)


def test_every_family_has_kernels():
    kinds = {c: kind_of(c) for c in vars(mbd.elements).values()
             if isinstance(c, type) and str(getattr(c, "compiled_twin", None)).startswith("contact.")}
    assert set(kinds) == {RaceContact, PocketContact, PocketRetention, GuideContact, LubricantDrag, PocketFilm, CageDrag,
                          RaceFilm}
    assert kinds[PocketFilm].update is None and kinds[CageDrag].update is None and kinds[RaceFilm].update is None
    assert kinds[RaceContact].update is None and kinds[LubricantDrag].update is None
    assert all(kinds[c].update is not None for c in (PocketContact, PocketRetention, GuideContact))


# ------------------------------------------------------------------------------------------ retention
@SETTINGS
@given(state=retention_states(), z=impact_z(), fs=frame_states(), law=LAWS, mult=MULTS,
       fast=st.one_of(st.none(), st.lists(st.floats(-5.0, 5.0), min_size=N, max_size=N)),
       mu=st.sampled_from([0.0, 0.1]))
def test_retention_matches_reference(state, z, fs, law, mult, fast, mu):
    state = list(state)
    if fast is not None:          # fast radial motion: separation clips the force to zero
        state[6] = fast
    qf, vf, elem, _ = retention_scene(*state, mu=mu, multiplicity=mult)
    assert_matches_reference(_with_law(elem, law), fs, qf, vf, z)


@SETTINGS
@given(data=st.data(), z=cached_states())
def test_retention_update_matches_update_internal(data, z):
    s0, s1 = data.draw(retention_states()), data.draw(retention_states())
    q0, v0, elem, _ = retention_scene(*s0)
    q1, v1, _, _ = retention_scene(*s1[:2], s0[2], *s1[3:])      # the same pockets
    twin = kind_of(type(elem))
    P, G = twin.pack(elem)
    loc = lambda a: np.ascontiguousarray(a[elem.dofs])    # noqa: E731
    cols = lambda a: list(a[elem.dofs].T)                  # noqa: E731
    fs0, fs1 = data.draw(frame_states()), data.draw(frame_states())
    for zz in (np.zeros((N, 4)), z):
        ref = elem.update_internal(zz.copy(), 0.1, 0.1 + 1e-6, fs0, fs1, cols(q0), cols(v0), cols(q1), cols(v1))
        got = twin.update(zz.copy(), 0.1, 0.1 + 1e-6, loc(q0), loc(v0), loc(q1), loc(v1), P, G)
        np.testing.assert_array_equal(got, ref)          # the radial gap is bitwise the reference's
