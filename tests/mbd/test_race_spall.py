"""A local raceway defect (spall) and per-roller diameters in the roller–raceway contact (docs/model.md §8.3, §11.3–11.4),
in both engine paths: the law d(s) = h·B(s) against an independent smoothstep and a time difference of the
deflection (the rate term), exact Jacobians (finite differences; compiled = reference on random states, on the
edges of the defect, with the roller spinning), a family without a spall unchanged bit for bit, fusion, the
physics (the load lost over the defect, the load history of an orbiting roller) and the parameter errors.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, strategies as st

import mbd
from mbd.assembly import _fused_families
from mbd.compiled.contact import RACE_COLS, pack_race
from mbd.compiled.system import CompiledSystem
from mbd.element import evaluate
from mbd.elements import GroundSupport, SpeedDrive
from mbd.elements.contact import RaceContact
from mbd.errors import ModelError

from tests.support.contact import (DR, EHL, FILM, FS, K_HZ, LAW, M_ROLLER, N, R_IN, R_OUT, SETTINGS, TANH,
                                   assert_balanced, assert_jacobians, assert_matches_reference, compiled, race_scene,
                                   race_states)
from tests.support.dpgt_runs import build, faulty_machine

P = 10.0 / 9.0
LAWS = {"tanh": TANH, "ehl": EHL, "film": FILM}
REGIONS = ("deep", "ramp", "inner_edge", "outer_edge", "outside")


def spalled(kind, mk, R, traction=TANH, *, angle, width, depth, edge, D=DR, zeta=0.05, n=N, bodies=None,
            name="spall"):
    rollers, race_body = bodies if bodies is not None else (np.arange(1, n + 1), 0)
    return RaceContact(name, rollers, race_body, kind=kind, race_marker=mk, R_race=R, D=D, K=K_HZ, exponent=P,
                       zeta=zeta, m_roller=M_ROLLER, traction=traction, spall_angle=angle, spall_width=width,
                       spall_depth=depth, spall_edge=edge)


def smoothstep_depth(s, width, depth, edge):
    """d(s) written out independently: h for |s| ≤ (w − e)/2, 0 beyond (w + e)/2, 6x⁵ − 15x⁴ + 10x³ between."""
    x = np.clip((0.5 * (width + edge) - np.abs(s)) / edge, 0.0, 1.0)
    return depth * np.polyval([6.0, -15.0, 10.0, 0.0, 0.0, 0.0], x)


@st.composite
def spall_states(draw, kind, edges=True):
    """A race scene (rollers pressed in or lifted off, spinning, the race body moving) and a defect under each
    roller: deep inside, on a ramp, on its exact inner or outer edge, or outside it, on either side.
    ``edges`` False keeps off the law's kinks, for finite differences: B is C², so the rate term's Jacobian
    has a kink at the ramp's ends (B'' jumps in slope), which a difference straddling it misses by O(h·B⁽³⁾);
    the rollers keep 1 % of each region's length from its ends and δ − h stays 10 % of δ away from 0 (the
    contact's onset)."""
    state = draw(race_states(kind))
    R = R_IN if kind == "inner" else R_OUT
    width = draw(st.floats(5e-4, 3e-3))
    edge = width * draw(st.floats(0.05, 1.0 if edges else 0.98))
    lst = lambda s: draw(st.lists(s, min_size=N, max_size=N))  # noqa: E731
    if edges:
        depth = np.array(lst(st.floats(0.0, 3e-5)))
    else:
        depth = np.abs(state[4]) * np.array(lst(st.floats(0.0, 0.9) | st.floats(1.1, 3.0)))
    frac = np.array(lst(st.floats(0.0, 1.0) if edges else st.floats(0.01, 0.99)))
    lo, hi = 0.5 * (width - edge), 0.5 * (width + edge)
    at = {"deep": frac * lo, "ramp": lo + frac * edge, "inner_edge": lo + 0 * frac, "outer_edge": hi + 0 * frac,
          "outside": hi + frac * (np.pi * R - hi)}
    regions = lst(st.sampled_from(REGIONS if edges else ("deep", "ramp", "outside")))
    s = np.array([at[r][j] for j, r in enumerate(regions)]) * np.array(lst(st.sampled_from([-1.0, 1.0])))
    angle = np.array(state[3]) - s / R           # the roller sits at arc position s from the defect's centre
    return state, dict(angle=angle, width=width, depth=depth, edge=edge), s


# -------------------------------------------------------------------------------------- the law, numpy
@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl"])
@SETTINGS
@given(data=st.data())
def test_spall_law_jacobians_and_balance(kind, law, data):
    state, spall, s = data.draw(spall_states(kind, edges=False))
    qf, vf, mk, R = race_scene(kind, *state)
    elem = spalled(kind, mk, R, LAWS[law], **spall)
    F, out = assert_jacobians(elem, qf, vf)
    assert_balanced(elem, qf, vf)
    d = smoothstep_depth(s, spall["width"], spall["depth"], spall["edge"])
    np.testing.assert_allclose(out["deflection"], np.array(state[4]) - d, rtol=0, atol=1e-15)
    # the load is K δ^p + c(δ) δ̇ with the exact rate of δ_eff: a time difference along the motion
    tau = 2.0 ** -32
    rate = sum(c * evaluate(elem, 0.0, FS, qf + m * tau * vf, vf, None, False)[1]["deflection"]
               for m, c in ((1, 8), (-1, -8), (2, -1), (-2, 1))) / (12.0 * tau)
    de = out["deflection"]
    c0 = 2 * 0.05 * np.sqrt(M_ROLLER * P * K_HZ)
    with np.errstate(invalid="ignore"):
        Q = np.where(de > 0, K_HZ * de ** P + c0 * de ** (0.5 * (P - 1)) * rate, 0.0)
    np.testing.assert_allclose(out["load"], np.maximum(Q, 0.0), rtol=1e-6, atol=1e-6 * np.abs(Q).max())
    assert np.all(F[out["load"] == 0] == 0)


def test_the_smoothstep_is_c2_with_flat_ends():
    from mbd.elements.contact import spall_profile
    hi, e = 1.5e-3, 1e-3
    s = np.linspace(-2e-3, 2e-3, 40001)
    B, B_s = spall_profile(s, hi, e)
    np.testing.assert_allclose(B, smoothstep_depth(s, 2 * hi - e, 1.0, e), rtol=0, atol=1e-15)
    assert np.all(B[np.abs(s) <= hi - e] == 1.0) and np.all(B[np.abs(s) >= hi] == 0.0)
    np.testing.assert_allclose(B_s[1:-1], (B[2:] - B[:-2]) / (s[2] - s[0]), rtol=0, atol=1e-5 * 1.875 / e)
    # B'' (from the slope's difference) vanishes at both ends of the ramp: no jump in the contact stiffness rate
    B_ss = np.diff(B_s) / np.diff(s)
    for edge_at in (hi - e, hi):
        k = np.searchsorted(s[:-1], edge_at)
        assert np.abs(B_ss[k - 2:k + 2]).max() < 1e-2 * 5.8 / e ** 2    # max |B''| = 10/√3/e² ≈ 5.8/e²


# -------------------------------------------------------------------------------------- both engines
@pytest.mark.parametrize("kind", ["inner", "outer"])
@pytest.mark.parametrize("law", ["tanh", "ehl", "film"])
@SETTINGS
@given(data=st.data(), zeta=st.sampled_from([0.0, 0.05, 0.3]))
def test_spall_compiled_matches_reference(kind, law, data, zeta):
    state, spall, _ = data.draw(spall_states(kind))
    # a roller whose interference equals the defect's depth sits exactly on the contact's onset, where round-off
    # picks the branch (found by hypothesis: depth drawn equal to δ): both engines are right on either side
    assume(np.all(np.abs(np.abs(np.asarray(state[4])) - spall["depth"]) > 1e-12))
    qf, vf, mk, R = race_scene(kind, *state)
    elem = spalled(kind, mk, R, LAWS[law], zeta=zeta, **spall)
    assert pack_race(elem)[0].shape == (N, RACE_COLS + 4)
    assert_matches_reference(elem, FS, qf, vf)


@SETTINGS
@given(data=st.data())
def test_spalled_inner_and_outer_fuse_and_stay_apart_from_plain_families(data):
    (si, spi, _), (so, spo, _) = data.draw(spall_states("inner")), data.draw(spall_states("outer"))
    qi, vi, mki, Ri = race_scene("inner", *si)
    qo, vo, mko, Ro = race_scene("outer", *so)
    qf, vf = np.concatenate([qi, qo]), np.concatenate([vi, vo])
    inner = spalled("inner", mki, Ri, **spi, name="in")
    outer = spalled("outer", mko, Ro, **spo, name="out", bodies=(np.arange(N + 2, 2 * N + 2), N + 1))
    plain = RaceContact("plain", np.arange(1, N + 1), 0, kind="inner", race_marker=mki, R_race=Ri, D=DR, K=K_HZ,
                        m_roller=M_ROLLER, **LAW)
    fams = _fused_families([inner, plain, outer], True)
    assert [[n for n, _ in parts] for _, parts in fams] == [["in", "out"], ["plain"]]
    fused = fams[0][0]
    assert fused.has_spall and not fams[1][0].has_spall and pack_race(fams[1][0])[0].shape == (N, RACE_COLS)
    assert_matches_reference(fused, FS, qf, vf)
    F, Jq, Jv = compiled(fused, FS, qf, vf, None, True)
    for part, sl in ((inner, slice(0, N)), (outer, slice(N, 2 * N))):
        Fp, Jqp, Jvp = compiled(part, FS, qf, vf, None, True)
        np.testing.assert_array_equal(F[sl], Fp)
        np.testing.assert_array_equal(Jq[sl], Jqp)
        np.testing.assert_array_equal(Jv[sl], Jvp)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@SETTINGS
@given(data=st.data())
def test_no_spall_is_unchanged(kind, data):
    """A defect of depth 0, or one no roller is over, gives the plain family's evaluation bit for bit (both
    engines); the plain family packs no spall columns, so its compiled kernel does no spall work."""
    state, spall, s = data.draw(spall_states(kind))
    qf, vf, mk, R = race_scene(kind, *state)
    plain = RaceContact("r", np.arange(1, N + 1), 0, kind=kind, race_marker=mk, R_race=R, D=DR, K=K_HZ,
                        m_roller=M_ROLLER, **LAW)
    assert not plain.has_spall and pack_race(plain)[0].shape == (N, RACE_COLS)
    away = np.array(state[3]) + np.pi                # every defect on the far side of its raceway
    variants = (spalled(kind, mk, R, **{**spall, "depth": 0.0}), spalled(kind, mk, R, **{**spall, "angle": away}))
    for jac in (False, True):
        ref = evaluate(plain, 0.0, FS, qf, vf, None, jac)
        ref_c = compiled(plain, FS, qf, vf, None, jac)
        for elem in variants:
            got = evaluate(elem, 0.0, FS, qf, vf, None, jac)
            for a, b in zip(got[::2] + got[3:], ref[::2] + ref[3:]):
                np.testing.assert_array_equal(a, b)
            assert got[1].keys() == ref[1].keys()
            for key in ref[1]:
                np.testing.assert_array_equal(got[1][key], ref[1][key])
            for a, b in zip(compiled(elem, FS, qf, vf, None, jac), ref_c):
                np.testing.assert_array_equal(a, b)


# -------------------------------------------------------------------------------------- physics
@pytest.mark.parametrize("kind", ["inner", "outer"])
def test_the_defect_takes_its_depth_off_the_deflection(kind):
    """Rollers held at δ0: over the fully deep part the load falls by exactly K·(δ0^p − (δ0 − h)^p), at the
    middle of a ramp by K·(δ0^p − (δ0 − h/2)^p), outside not at all (both engines)."""
    w, e, h, d0 = 2e-3, 0.5e-3, 4e-6, 1e-5
    s = np.array([0.0, 0.3e-3, 0.5 * w, -0.5 * w, 0.5 * w + e])        # centre, deep, mid-ramp ×2, outside
    ang = np.array([0.4, -1.3, 2.9, -2.9, 1.0])
    qf, vf, mk, R = race_scene(kind, (1e-4, -2e-4, 0.8), (0, 0, 0), -0.4, ang, [d0] * 5, [0] * 5, [0] * 5, [0] * 5)
    elem = spalled(kind, mk, R, angle=ang - s / R, width=w, depth=h, edge=e, n=5)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    Q0 = K_HZ * d0 ** P
    expected = Q0 - K_HZ * (d0 ** P - (d0 - np.array([h, h, h / 2, h / 2, 0.0])) ** P)
    # (to the round-off of δ0 rebuilt from the rollers' positions: an ulp of ρ is 1e-12 of δ)
    np.testing.assert_allclose(out["load"], expected, rtol=1e-10)
    np.testing.assert_allclose(Q0 - out["load"][:2], K_HZ * (d0 ** P - (d0 - h) ** P), rtol=1e-9)
    radial = np.hypot(*compiled(elem, FS, qf, vf, None, False)[0][:, :2].T)    # no slip: no traction
    np.testing.assert_allclose(radial, out["load"], rtol=1e-13)


def test_orbiting_roller_load_dips_once_per_orbit_at_the_spall():
    """A roller rolling round a stationary pin at constant δ0 (three orbits, sampled as one family of
    instances): the load dips once per orbit, centred on the defect (placed across the ±π seam of the angle),
    to K(δ0 − h)^p; the damping sees the surface drop away on entry (less load than quasi-static on the
    entry ramp) and rise on exit (more). Both engines give the same history."""
    w, e, h, d0, omega = 2e-3, 0.5e-3, 4e-6, 1e-5, 150.0        # orbit speed [rad/s]
    psi = np.pi - 0.03
    n = 3000
    t = np.arange(n) * (3 * 2 * np.pi / omega) / n
    ang = omega * t
    rho0 = R_IN + DR / 2 - d0
    qf, vf, mk, R = race_scene("inner", (0, 0, 0.2), (0, 0, 0), 0.7, ang, [d0] * n, [0] * n, rho0 * omega * np.ones(n),
                               [0] * n)
    elem = spalled("inner", mk, R, angle=psi, width=w, depth=h, edge=e, n=n)
    F, out, _, _ = evaluate(elem, 0.0, FS, qf, vf, None, False)
    Q0, Q_deep = K_HZ * d0 ** P, K_HZ * (d0 - h) ** P
    dip = out["load"] < 0.5 * (Q0 + Q_deep)
    starts = np.flatnonzero(dip[1:] & ~dip[:-1]) + 1
    assert starts.size == 3 and not dip[0] and not dip[-1]
    for k in starts:
        run = np.arange(k, k + np.argmin(dip[k:]))
        centre = np.angle(np.mean(np.exp(1j * out["angle"][run])))
        assert abs(np.angle(np.exp(1j * (centre - psi)))) < 2 * omega * (t[1] - t[0])
        np.testing.assert_allclose(out["load"][run].min(), Q_deep, rtol=1e-10)     # B' = 0 over the deep part
    np.testing.assert_allclose(out["load"][~dip].max(), Q0, rtol=1e-10)
    # entry (s < 0 as the angle grows) and exit ramps at mid-depth: the damping's sign
    s = R * np.angle(np.exp(1j * (out["angle"] - psi)))
    mid = np.abs(np.abs(s) - 0.5 * w) < 0.1 * e
    Q_mid = K_HZ * (out["deflection"][mid]) ** P
    entry, load_mid = s[mid] < 0, out["load"][mid]
    assert entry.any() and (~entry).any()
    assert np.all(load_mid[entry] < Q_mid[entry]) and np.all(load_mid[~entry] > Q_mid[~entry])
    radial = np.hypot(*compiled(elem, FS, qf, vf, None, False)[0][:, :2].T)
    np.testing.assert_allclose(radial, np.hypot(out["load"], out["traction"]), rtol=1e-12, atol=1e-9 * Q0)


# -------------------------------------------------------------------------------------- roller diameters
def test_a_larger_roller_carries_the_load_the_law_predicts():
    """Rollers pinched between a pin and a bore (one inner and one outer family, per-roller D): each roller's
    equilibrium (Newton on its centre with the compiled Jacobian) shares the interference i + ΔD equally
    between its two contacts, so it carries K((i + ΔD)/2)^p; a roller 2 µm larger carries that much more.
    Compiled = reference at the equilibrium."""
    i = 8e-6                                             # diametral interference of the nominal roller
    dD = np.array([0.0, 2e-6, -1e-6])
    ang = np.array([0.3, 2.2, -2.0])
    R_i, R_o = R_IN, R_IN + DR - i                       # R_o − R_i − D_nominal = −i: one roller spans the gap
    # body 0: the carrier with its pin at the origin, body 1: the planet (bore) centred there; rollers 2..
    n = dD.size
    e = np.column_stack([np.cos(ang), np.sin(ang)])
    r = np.full(n, R_i + DR / 2 - i / 4)                 # both contacts closed for every roller
    rollers = np.arange(2, n + 2)
    common = dict(D=DR + dD, K=K_HZ, m_roller=M_ROLLER, **LAW)
    inner = RaceContact("in", rollers, 0, kind="inner", race_marker=(0, 0), R_race=R_i, **common)
    outer = RaceContact("out", rollers, 1, kind="outer", race_marker=(0, 0), R_race=R_o, **common)
    qf, vf = np.zeros(3 * (n + 2)), np.zeros(3 * (n + 2))
    for _ in range(30):       # Newton on each roller's radius (between concentric races it is free to roll round)
        qf.reshape(-1, 3)[2:, :2] = r[:, None] * e
        f = k = 0.0
        for el in (inner, outer):
            Fe, Jqe, _ = compiled(el, FS, qf, vf, None, True)
            f = f + np.einsum("ja,ja->j", Fe[:, :2], e)
            k = k + np.einsum("ja,jab,jb->j", e, Jqe[:, :2, :2], e)
        step = -f / k
        r += step
        if np.abs(step).max() < 1e-18:
            break
    qf.reshape(-1, 3)[2:, :2] = r[:, None] * e
    oi, oo = (evaluate(el, 0.0, FS, qf, vf, None, False)[1] for el in (inner, outer))
    expected = K_HZ * (0.5 * (i + dD)) ** P
    np.testing.assert_allclose(oi["load"], expected, rtol=1e-9)
    np.testing.assert_allclose(oo["load"], expected, rtol=1e-9)
    np.testing.assert_allclose(oi["deflection"], 0.5 * (i + dD), rtol=1e-9)
    assert oi["load"][1] / oi["load"][0] == pytest.approx(((i + 2e-6) / i) ** P, rel=1e-9)
    for el in (inner, outer):
        assert_matches_reference(el, FS, qf, vf)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@SETTINGS
@given(data=st.data())
def test_per_roller_diameters_in_both_engines(kind, data):
    """D per instance adds ΔD/2 to each roller's deflection; compiled = reference (with a spall too)."""
    state, spall, s = data.draw(spall_states(kind))
    dD = np.array(data.draw(st.lists(st.floats(-3e-6, 3e-6), min_size=N, max_size=N)))
    qf, vf, mk, R = race_scene(kind, *state)
    plain = RaceContact("r", np.arange(1, N + 1), 0, kind=kind, race_marker=mk, R_race=R, D=DR + dD, K=K_HZ,
                        m_roller=M_ROLLER, **LAW)
    out = evaluate(plain, 0.0, FS, qf, vf, None, False)[1]
    np.testing.assert_allclose(out["deflection"], np.array(state[4]) + dD / 2, rtol=0, atol=1e-15)
    assert_matches_reference(plain, FS, qf, vf)
    assert_matches_reference(spalled(kind, mk, R, D=DR + dD, **spall), FS, qf, vf)


# -------------------------------------------------------------------------------------- parameters
def test_spall_parameter_errors_name_the_parameter():
    base = dict(kind="inner", race_marker=(0, 0), R_race=R_IN, D=DR, K=K_HZ, m_roller=M_ROLLER, **LAW)
    ok = dict(spall_angle=0.3, spall_width=2e-3, spall_depth=5e-6, spall_edge=5e-4)
    assert RaceContact("r", [1, 2], 0, **base, **ok).has_spall
    with pytest.raises(ModelError, match="missing spall_depth, spall_edge"):
        RaceContact("r", [1], 0, **base, spall_angle=0.3, spall_width=2e-3)
    bad = [("spall_edge", 3e-3, r"'spall_edge' must lie in \(0, spall_width\]"), ("spall_edge", 0.0, "spall_edge"),
           ("spall_width", -1e-3, "spall_width"), ("spall_depth", -1e-6, "spall_depth"),
           ("spall_angle", np.nan, "spall_angle"), ("spall_width", [1e-3, 2e-3, 3e-3], "spall_width"),
           ("spall_width", 2 * np.pi * R_IN, "spall_width.*2π·R_race")]
    for key, val, msg in bad:
        with pytest.raises(ModelError, match=msg):
            RaceContact("r", [1, 2], 0, **base, **{**ok, key: val, "spall_edge": val if key == "spall_edge" else 1e-4})


# -------------------------------------------------------------------------------------- in the engine
I_PINCH, W_SP, E_SP, H_SP = 8e-6, 2e-3, 0.5e-3, 3e-6     # interference; the pin spall's width, edge, depth


def _pinched_scene(spall: bool):
    """Three rollers pinched (8 µm) between a fixed pin and a bore on stiff supports, driven at 200 rad/s, the
    rollers rolling; roller 0 starts at the outer edge of a pin spall (when ``spall``). Returns the model, the
    free coordinates and the time roller 0 takes to reach the defect's centre."""
    R_o, rho = R_IN + DR - I_PINCH, R_IN + DR / 2 - I_PINCH / 2
    ang = np.array([0.3, 2.4, -1.9])
    hi = 0.5 * (W_SP + E_SP)
    mb = mbd.ModelBuilder()
    mb.add_body("carrier", 1.0, 1e-3, fixed=True)
    planet = mb.add_body("planet", 0.2, 5e-5)
    rollers = [mb.add_body(f"roller{j}", M_ROLLER, M_ROLLER * DR ** 2 / 8) for j in range(3)]
    mb.add(GroundSupport("support", [planet], kx=1e10, cx=1e4))
    mb.add(SpeedDrive("drive", planet, omega_ref=200.0, k=50.0, c=0.5))
    law = dict(D=DR, K=K_HZ, m_roller=M_ROLLER, **LAW)
    defect = dict(spall_angle=ang[0] + hi / R_IN, spall_width=W_SP, spall_depth=H_SP, spall_edge=E_SP)
    mb.add(RaceContact("race_inner", rollers, 0, kind="inner", race_marker=(0, 0), R_race=R_IN, **law,
                       **(defect if spall else {})))
    mb.add(RaceContact("race_outer", rollers, planet, kind="outer", race_marker=(0, 0), R_race=R_o, **law))
    v_c = 200.0 * R_o / 2                            # pure rolling on the fixed pin: the centre at half the bore's speed
    q0 = np.concatenate([[0, 0, 0]] + [[rho * np.cos(a), rho * np.sin(a), 0.0] for a in ang])
    v0 = np.concatenate([[0, 0, 200.0]] + [[-v_c * np.sin(a), v_c * np.cos(a), 2 * v_c / DR] for a in ang])
    return mb.build(), q0, v0, hi / (R_IN * v_c / rho)


def test_a_spalled_family_runs_in_both_engines():
    """Three rollers pinched between a pin and a stiffly held bore, roller 0 rolling into a pin spall. Assembled
    with a plain outer family (kept apart by the fuse key), the compiled system equals the reference on the
    defect's ramp; both engines take the same steps to the same state; over the deep part roller 0's pin load
    is the no-spall run's times ((i − h + u)/(i + u'))^p (its two contacts share the interference i less the
    depth h, plus u, u' the give of the bore's support in the two runs); the other rollers' loads move only by
    that give (< 2 %)."""
    model, q0, v0, t_c = _pinched_scene(True)
    system = mbd.System(model)
    assert sorted(len(parts) for e, parts in system._evals if isinstance(e, RaceContact)) == [1, 1]
    z = system.init_internal()
    q_ramp = q0.copy()
    a_ramp = 0.3 + 0.25e-3 / R_IN                          # s = −1 mm: half way down the entry ramp
    q_ramp[3:5] = np.hypot(*q0[3:5]) * np.array([np.cos(a_ramp), np.sin(a_ramp)])
    ref = system.evaluate(0.0, q_ramp, v0, z, jac=True)
    got = CompiledSystem(system).evaluate(0.0, q_ramp, v0, z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
    H = 5e-6
    n = int(round(t_c / H))

    def run(m, q, v, engine):
        return mbd.simulate(m, q, v, n * H, stepper=mbd.HHT(alpha=-0.1), controller=mbd.FixedStep(H), progress=False,
                            engine=engine)

    runs = [run(model, q0, v0, eng) for eng in ("compiled", "numpy")]
    assert [r.engine for r in runs] == ["compiled", "numpy"] and runs[0].counters == runs[1].counters
    np.testing.assert_allclose(runs[0].state.q, runs[1].state.q, rtol=0, atol=1e-12)
    plain_model, _, _, _ = _pinched_scene(False)
    plain = run(plain_model, q0, v0, "compiled").state
    s = runs[0].state
    out = system.outputs(s.t, s.q, s.v, s.z)["race_inner"]
    inner = next(e for e in model.elements if e.name == "race_inner")
    s_0 = R_IN * (out["angle"][0] - inner.spall_angle[0])
    assert abs(s_0) < 0.1 * (W_SP - E_SP) / 2                # roller 0 is at the middle of the defect
    load = out["load"]
    load_plain = mbd.System(plain_model).outputs(plain.t, plain.q, plain.v, plain.z)["race_inner"]["load"]
    # the bore's support gives way (ΔQ/k, here 1 % of the pinch): u = its shift away from roller 0
    e0 = s.q[3:5] / np.hypot(*s.q[3:5])
    u, u_plain = -s.q[:2] @ e0, -plain.q[:2] @ e0
    law = ((I_PINCH - H_SP + u) / (I_PINCH + u_plain)) ** P
    print(f"pin load over the spall / without: {load[0] / load_plain[0]:.5f}, law {law:.5f}, rigid bore "
          f"{((I_PINCH - H_SP) / I_PINCH) ** P:.5f}")
    assert load[0] / load_plain[0] == pytest.approx(law, rel=2e-3)
    np.testing.assert_allclose(load[1:], load_plain[1:], rtol=0.02)


def test_the_race_kernels_match_the_reference_on_the_faulty_machines_loaded_states():
    """The compiled race law's structured Jacobian (the race body's translation columns are the roller's negated,
    the roller's angle column is left zero, the velocity columns carry no geometry terms) against the reference's
    dual numbers, at real loaded states: the faulty machine (a spall on b1's pin, class-6 teeth, a cracked tooth)
    2–2.5 ms into its load ramp, every race family, forces and both Jacobians (tests.support.contact's bounds)."""
    bs = build(faulty_machine())
    kept = []

    class Keep(mbd.Observer):
        def on_block(self, blk):
            t, q, v, _, _ = blk.arrays()
            kept.extend((t[i], q[i], v[i]) for i in range(1, t.size) if t[i] > 2e-3)

    mbd.simulate(bs.model, bs.q0, bs.v0, 2.5e-3, stepper=mbd.PRODUCTION.stepper(),
                 controller=mbd.PRODUCTION.controller(), progress=False, engine="compiled", observers=[Keep()])
    races = [e for e in bs.model.elements if isinstance(e, RaceContact)]
    assert any(e.has_spall for e in races) and len(kept) >= 10
    loaded = 0
    for t, q, v in kept[::max(1, len(kept) // 10)]:
        qf, vf = bs.model.full(t, q, v)
        for e in races:
            loaded += int(np.count_nonzero(np.abs(assert_matches_reference(e, FS, qf, vf)).max(axis=1) > 1.0))
    assert loaded > 100                     # most contacts of the loaded zones carry load (N), not a test of zeros
