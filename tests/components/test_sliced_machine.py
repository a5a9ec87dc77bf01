"""The sliced planet bearings in the full machine (bearing.model = "sliced", docs/model.md §8.8).

Truth: the planar model. A straight roller without tilt or slope is the planar contact slice by slice, so the
sliced machine started from a planar state must give the planar forces, Jacobians, outputs and steps to round-off,
its tilts staying at zero."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import mbd
from components.dpgt import build_dpgt
from components.presets import reference_dpgt
from components.units import ParameterError

from tests.support.dpgt_runs import ramp_state

H = 5e-6


@pytest.fixture(scope="module")
def machines():
    sp, s = ramp_state(0.003, "compiled")
    p = reference_dpgt(3, "forward")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ss = build_dpgt(p.replace(bearing=p.bearing.replace(model="sliced")))
    return sp, ss, s


def _extended(ss, sp, x):
    """A planar state's free DOFs with the sliced machine's tilt coordinates (after them) at zero."""
    y = np.zeros(ss.model.ndof)
    y[: sp.model.ndof] = x
    return y


def test_the_sliced_machine_has_the_spec_degrees_of_freedom(machines):
    sp, ss, _ = machines
    m = ss.model
    # the planar DOFs, + 2 slopes per planet, + one tilt per roller (docs: 261 + 24 + 72 = 345 on the reference)
    n_rollers = sum(len(pair.inner_bearing.rollers) + len(pair.outer_bearing.rollers) for pair in sp.pairs)
    assert m.ndof == sp.model.ndof + 2 * 2 * len(sp.pairs) + n_rollers
    assert m.slope_pairs.shape == (2 * len(sp.pairs), 2)
    # the planar bodies keep their indices: a planar state is the sliced state's first entries
    np.testing.assert_array_equal(m.free[: sp.model.ndof], sp.model.free)


def test_straight_aligned_sliced_machine_is_the_planar_machine_to_round_off(machines):
    sp, ss, s = machines
    nP = sp.model.ndof
    sysP, sysS = mbd.System(sp.model), mbd.System(ss.model)
    q, v = _extended(ss, sp, s.q), _extended(ss, sp, s.v)
    eP, eS = sysP.evaluate(s.t, s.q, s.v, s.z, jac=True), sysS.evaluate(s.t, q, v, s.z, jac=True)
    scale = np.abs(eP.F).max()
    assert np.abs(eS.F[:nP] - eP.F).max() <= 1e-13 * scale
    assert np.abs(eS.F[nP:]).max() <= 1e-13 * scale * 1e-2          # no moment on any tilt (l ~ 1e-2 m)
    _, CP, KP = sysP.matrices(eP)
    _, CS, KS = sysS.matrices(eS)
    for A, B in ((KS, KP), (CS, CP)):
        A, B = A.toarray(), B.toarray()
        assert np.abs(A[:nP, :nP] - B).max() <= 1e-13 * np.abs(B).max()
    oP, oS = sysP.outputs(s.t, s.q, s.v, s.z), sysS.outputs(s.t, q, v, s.z)
    for fam in ("race_inner", "race_outer"):
        assert oP[fam]["load"].max() > 1e3                              # the load zones are loaded
        for key, val in oP[fam].items():
            np.testing.assert_allclose(oS[fam][key], val, rtol=0, atol=1e-12 * max(1.0, np.abs(val).max()), err_msg=key)
    # forty steps on the numpy path: the same steps, the same states, the tilts at round-off
    st = mbd.State(s.t, q, v, _extended(ss, sp, s.a), _extended(ss, sp, s.f), dict(s.z))
    run = lambda model, state: mbd.simulate(model, t_end=s.t + 40 * H, state=state, stepper=mbd.PRODUCTION.stepper(),
                                            controller=mbd.FixedStep(H), progress=False, engine="numpy")   # noqa: E731
    rP, rS = run(sp.model, s.copy()), run(ss.model, st)
    assert rP.counters == rS.counters
    np.testing.assert_allclose(rS.state.q[:nP], rP.state.q, rtol=0, atol=1e-12)
    assert np.abs(rS.state.q[nP:]).max() < 1e-14 and np.abs(rS.state.v[nP:]).max() < 1e-9


def test_the_sliced_model_refuses_what_it_does_not_build():
    p = reference_dpgt(3, "forward")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ParameterError, match="bearing.model"):
            build_dpgt(p.replace(bearing=p.bearing.replace(model="sliced", rolling_resistance="houpert")))


@pytest.mark.parametrize("condition, bound", [(1, 1e-5), (3, 1e-4)])
def test_a_rollers_gyroscopic_terms_are_negligible_against_its_tilt_stiffness(condition, bound):
    """Ω_c (J_p ω_r − J_d Ω_c) of a roller (Ω_c its radial plane's absolute rate, the cage's; ω_r its absolute spin)
    against its two contacts' tilt stiffness 2 p (Q/δ) l²/12 at a 4 kN roller load (condition 3's largest; 1 kN at
    condition 1): what leaving them out of the tilt equation costs."""
    from components.bearing import roller_tilt_inertia
    p = reference_dpgt(condition, "forward")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(p)
    b = p.si().bearing
    Q = 4e3 if condition == 3 else 1e3
    delta = (Q / b.contact_stiffness) ** (1 / b.contact_exponent)
    k_tilt = 2 * b.contact_exponent * Q / delta * b.roller_length ** 2 / 12
    for pair in sc.pairs:
        for h in (pair.inner_bearing, pair.outer_bearing):
            wc, wr = h.omega_cage, h.omega_roller
            gyro = abs(wc * (b.roller_inertia * wr - roller_tilt_inertia(b) * wc))
            assert 0 < gyro / k_tilt < bound


def _family_stiffness(model, names, t, q, v, z):
    """K = −∂F/∂q (full coordinates) of the element families ``names`` alone."""
    from mbd.element import evaluate
    fs = model.frame.at(t)
    qf, vf = model.full(t, q, v)
    K = np.zeros((model.n_full, model.n_full))
    for e in model.elements:
        if e.name in names:
            _, _, Jq, _ = evaluate(e, t, fs, qf, vf, z.get(e.name), True)
            for i in range(e.n):
                K[np.ix_(e.dofs[i], e.dofs[i])] -= Jq[i]
    return K


def test_a_planet_follows_its_sloped_pin_by_the_bearing_share_of_the_tilt_stiffness(machines):
    """A small pin slope γ on a1 (tangential), the machine linearised at a loaded state: the planets' and rollers'
    static tilt response (K_TT s = f_γ over every loaded tilt coordinate) puts a1's slope at
    (k_b + k_m + k_own)⁻¹ k_b γ, k_b the bearing's tilt stiffness with its rollers' tilts condensed, k_m its two
    meshes' (2×2 matrices: a mesh resists a slope along its line of action only), k_own = Ω(J_p ω − J_d Ω) I the
    slope's own stiffness in the rotating frame; the bearing sees the rest of γ."""
    from components.params.errors import PinSlopeParams
    from components.units import Q_
    sp, ss, s = machines
    p = reference_dpgt(3, "forward")
    ps = p.replace(bearing=p.bearing.replace(model="sliced"))
    pg = ps.replace(errors=ps.errors.replace(pin_slope=(PinSlopeParams(planet="a1", slope=Q_("0.01 arcmin"),
                                                                       direction=Q_("90 deg")),)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sg = build_dpgt(pg)
    m, nP = ss.model, sp.model.ndof
    q, v = _extended(ss, sp, s.q), _extended(ss, sp, s.v)
    system = mbd.System(m)
    ev = system.evaluate(s.t, q, v, s.z, jac=True)
    K = system.matrices(ev)[2].toarray()
    f = mbd.System(sg.model).evaluate(s.t, q, v, s.z).F - ev.F        # the pin slope's forcing (linear: γ tiny)
    T = np.arange(nP, m.ndof)
    loaded = T[np.abs(np.diag(K)[T]) > 1e-9 * np.abs(np.diag(K)[T]).max()]   # unloaded rollers have no tilt stiffness
    assert m.ndof - nP - loaded.size < len(sp.pairs) * 2 * 12
    response = np.zeros(m.ndof)
    response[loaded] = np.linalg.solve(K[np.ix_(loaded, loaded)], f[loaded])
    a1 = m.slope_pairs[[m.body_names[m.extra_owner[j - m.n_body_coords]] for j in m.slope_pairs[:, 0]].index("a1")]
    psi = ps.si().layout.psi_a[0]
    gamma = np.radians(0.01 / 60) * np.array([-np.sin(psi), np.cos(psi)])
    got = response[m.full_to_free[a1]]
    Km = _family_stiffness(m, {"mesh_sa", "mesh_ab", "mesh_br"}, s.t, q, v, s.z)[np.ix_(a1, a1)]
    Kb = _family_stiffness(m, {"race_inner", "race_outer"}, s.t, q, v, s.z)
    rollers = [m.n_body_coords + j for j in range(m.extra_owner.size)
               if m.body_names[m.extra_owner[j]].startswith("a1.pb.roller")]
    rollers = [r for r in rollers if Kb[r, r] > 1e-9 * np.abs(Kb).max()]
    k_b = Kb[np.ix_(a1, a1)] - Kb[np.ix_(a1, rollers)] @ np.linalg.solve(Kb[np.ix_(rollers, rollers)],
                                                                          Kb[np.ix_(rollers, a1)])
    # the slope's own stiffness in R: centrifugal −J_d Ω² and gyroscopic Ω J_p ω (§2.4), ≈ 400 N m/rad at condition 3
    i = m.full_to_free[a1]
    k_own = K[np.ix_(i, i)] - Km - Kb[np.ix_(a1, a1)]
    W = m.frame.omega
    spin = W + s.v[m.full_to_free[3 * m.body("a1").index + 2]]
    J_p, J_d = m.element("planet_gyroscopic").polar_inertia[0], m.mdiag[i[0]]
    np.testing.assert_allclose(k_own, W * (J_p * spin - J_d * W) * np.eye(2), rtol=1e-9, atol=1e-9 * abs(W * J_p * spin))
    split = np.linalg.solve(k_b + Km + k_own, k_b @ gamma)
    np.testing.assert_allclose(got, split, rtol=0, atol=0.12 * np.linalg.norm(split))
    # the meshes are ~20 times stiffer in tilt than the bearing: the planet follows by a few %, the bearing sees ~95 %
    assert 0.01 < np.linalg.norm(got) / np.linalg.norm(gamma) < 0.1


def test_carrier_windup_tilts_the_pins_tangentially_by_the_formula_and_reverse_tilts_them_back():
    from components import faults
    slopes = {}
    for direction in ("forward", "reverse"):
        p = reference_dpgt(3, direction)
        p = p.replace(gears=p.gears.replace(carrier_windup=True))
        si = p.si()
        G, lay = si.gears, si.layout
        for n, c in enumerate(lay.centres_a):
            r = np.hypot(*c)
            e_t = np.array([-c[1], c[0]]) / r
            expect = r * si.operating.carrier_torque / G.carrier_torsional_stiffness / G.carrier_plate_span * e_t
            got = faults.pin_slope(si, f"a{n + 1}", c)
            np.testing.assert_allclose(got, expect, rtol=1e-12)
            assert np.linalg.norm(got) > 1e-6
            slopes[direction, n] = got
    for n in range(len(lay.centres_a)):
        np.testing.assert_allclose(slopes["reverse", n], -slopes["forward", n], rtol=1e-12)


def test_a_pin_slope_needs_the_sliced_model():
    from components.params.errors import PinSlopeParams
    from components.units import Q_
    p = reference_dpgt(3, "forward")
    p = p.replace(errors=p.errors.replace(pin_slope=(PinSlopeParams(planet="a1", slope=Q_("2 arcmin"),
                                                                    direction=Q_("0 deg")),)))
    with pytest.raises(ParameterError, match="errors.pin_slope.*sliced"):
        build_dpgt(p)


def test_the_summary_reports_the_slices_and_the_misalignment_each_bearing_sees():
    """Static statistics (2 snapshots) of the sliced machine. Aligned: every slice carries Q/n_s, so the largest
    slice load is the largest roller load over n_s, the edge ratio is 1 and no bearing sees a slope. With a1's pin
    sloped 4′ tangentially: a1's bearing sees |γ − s_a1| (the planet's slope from the solutions), the others what
    their planets' slopes are, and a1's rollers load their ends."""
    from components import static
    from components.params.errors import PinSlopeParams
    from components.units import Q_
    p = reference_dpgt(3, "forward")
    ps = p.replace(bearing=p.bearing.replace(model="sliced"))
    n_s = ps.si().bearing.slicing.slices
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        aligned = static.static_summary(build_dpgt(ps), 2)
        gamma = np.radians(4.0 / 60.0)
        pg = ps.replace(errors=ps.errors.replace(pin_slope=(PinSlopeParams(planet="a1", slope=Q_("4 arcmin"),
                                                                           direction=Q_("90 deg")),)))
        scene = build_dpgt(pg)
        stats, sols = static.static_statistics(scene, 2)
    for kind in ("inner", "outer"):
        d = aligned[kind]
        # uniform slices: q_k = Q/n_s and q_c,k = Q_c n_s^(-7/9), so the sliced life is the roller loads' life
        assert d["life_iso16281_sliced_h"] == pytest.approx(d["life_iso16281_h"], rel=1e-9)
        assert d["all_rollers"]["life_iso16281_sliced_h"] == pytest.approx(d["all_rollers"]["life_iso16281_h"], rel=1e-9)
        assert d["slice_load_max_pin_N"] * n_s == pytest.approx(d["all_rollers"]["roller_inner_race_max_N"], rel=1e-9)
        assert d["edge_pressure_ratio"] == pytest.approx(1.0, abs=1e-9)
        assert d["misalignment_max_rad"] < 1e-12 * gamma
        assert not [k for k in d if k.startswith("pin_")]        # rigid pins: no pin bending keys
    d = stats.summary()["inner"]
    m = scene.model
    psi = pg.si().layout.psi_a[0]
    pin = gamma * np.array([-np.sin(psi), np.cos(psi)])
    pairs = {m.body_names[m.extra_owner[i - m.n_body_coords]]: (i, j) for i, j in m.slope_pairs}
    seen = []
    for s in sols:
        qf, _ = m.full(s.t, s.q, s.v)
        seen.append(np.hypot(*(pin - qf[list(pairs["a1"])])))
    assert d["misalignment_mean_rad"] == pytest.approx(np.mean(seen), rel=1e-9)
    assert 0.7 * gamma < d["misalignment_mean_rad"] < 1.0 * gamma        # the planet follows its pin by a little
    assert max(d["misalignment_mean_per_planet_rad"][1:]) < 0.1 * gamma
    assert d["edge_pressure_ratio"] > 1.01          # one end loaded more (the roller takes half the slope: a few %)
    # the misaligned bearing's slices cost it life; the aligned ones' sliced life stays their roller loads' life
    assert d["life_iso16281_sliced_h"] < d["life_iso16281_h"] * (1 - 1e-3)
    lives = d["life_iso16281_sliced_per_planet_h"], d["life_iso16281_per_planet_h"]
    np.testing.assert_allclose(lives[0][1:], lives[1][1:], rtol=1e-3)


def test_pin_slopes_and_windup_round_trip_through_toml_and_name_what_is_wrong(tmp_path):
    import re
    from components.params import to_toml, with_overrides
    from components.presets import load_toml
    over = {"bearing.model": "sliced", "gears.carrier_windup": True,
            "errors.pin_slope": [{"planet": "b2", "slope": "3 arcmin", "direction": "90 deg"}]}
    p = with_overrides(reference_dpgt(), over)
    f = tmp_path / "tilted.toml"
    f.write_text(to_toml(p))
    back = load_toml(f)
    assert back.errors == p.errors and back.gears == p.gears and back.bearing.model == "sliced"
    assert back.si().errors.pin_slope[0].slope == pytest.approx(np.radians(3 / 60), rel=1e-12)
    for entry, where in (({"planet": "b2", "slope": "3 mm", "direction": "0 deg"}, "errors.pin_slope[0].slope"),
                         ({"planet": "c2", "slope": "3 arcmin", "direction": "0 deg"}, "errors.pin_slope[0].planet"),
                         ({"planet": "b2", "slope": "-1 arcmin", "direction": "0 deg"}, "errors.pin_slope[0].slope")):
        with pytest.raises(ParameterError, match="^" + re.escape(where)) as info:
            with_overrides(reference_dpgt(), {"errors.pin_slope": [entry]})
        assert "\n" not in str(info.value)
    with pytest.raises(ParameterError, match="^bearing.model"):
        with_overrides(reference_dpgt(), {"bearing.model": "tilted"})


def test_every_planet_of_the_sliced_machine_has_its_gyroscopic_terms(machines):
    """One SlopeGyroscopic instance per planet, on its θ and slope pair, with its polar inertia."""
    sp, ss, _ = machines
    m = ss.model
    gyro = m.element("planet_gyroscopic")
    si = reference_dpgt(3, "forward").si()
    assert gyro.n == 2 * len(sp.pairs)
    for dofs, J in zip(gyro.dofs, gyro.polar_inertia):
        body = m.body_names[dofs[0] // 3]
        assert dofs[0] % 3 == 2 and m.coordinate_name(dofs[1]) == f"{body}.s_x" and m.coordinate_name(dofs[2]) == f"{body}.s_y"
        assert J == (si.gears.inner_planet if body.startswith("a") else si.gears.outer_planet).inertia


def test_the_sliced_machine_accelerates_alike_in_the_rotating_and_the_fixed_frame(machines):
    """One state of the sliced machine with a sloped pin, tilted planets and rollers and their rates, seen from R and
    from I: every acceleration (bodies, slopes as points of R, tilts as they are) maps from R to I to round-off —
    the frame terms of the slopes, the gyroscopic family's ω = Ω + θ̇ and the pin slope turning with the carrier."""
    from components.params.errors import PinSlopeParams
    from components.scene import SceneOptions
    from components.units import Q_
    sp, _, s = machines
    p = reference_dpgt(3, "forward")
    pg = p.replace(bearing=p.bearing.replace(model="sliced"),
                   errors=p.errors.replace(pin_slope=(PinSlopeParams(planet="a1", slope=Q_("4 arcmin"),
                                                                     direction=Q_("30 deg")),)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rot, fix = build_dpgt(pg), build_dpgt(pg, SceneOptions(frame="fixed"))
    mR, mI = rot.model, fix.model
    assert mR.frame.omega != 0.0 and mI.frame.is_inertial and np.array_equal(mR.free, mI.free)
    rng = np.random.default_rng(21)
    q, v = _extended(rot, sp, s.q), _extended(rot, sp, s.v)
    nP = sp.model.ndof
    q[nP:] = rng.uniform(-1e-4, 1e-4, mR.ndof - nP)
    v[nP:] = rng.uniform(-0.05, 0.05, mR.ndof - nP)
    F = mbd.System(mR).evaluate(s.t, q, v, s.z).F
    qf, vf = mR.full(s.t, q, v)
    af = np.zeros_like(qf)
    af[mR.free] = F / mR.mdiag
    fs = mR.frame.at(s.t)

    def to_I(x_full, v_full, a_full):
        """Bodies' (x, y, θ) and slope pairs (as points of R) into I; tilts unchanged."""
        X, V, A = (mR.poses(x) for x in (x_full, v_full, a_full))
        XI, VI, AI = mbd.to_fixed(X, V, fs, A)
        out = [np.array(x_full, float), np.array(v_full, float), np.array(a_full, float)]
        for o, arr in zip(out, (XI, VI, AI)):
            o[: mR.n_body_coords] = arr.ravel()
        for ix, iy in mR.slope_pairs:
            P = np.array([[x_full[ix], x_full[iy], 0.0]])
            Vs = np.array([[v_full[ix], v_full[iy], 0.0]])
            As = np.array([[a_full[ix], a_full[iy], 0.0]])
            pI, vI, aI = mbd.to_fixed(P, Vs, fs, As)
            for o, arr in zip(out, (pI, vI, aI)):
                o[ix], o[iy] = arr[0, 0], arr[0, 1]
        return out

    qI, vI, a_expect = to_I(qf, vf, af)
    FI = mbd.System(mI).evaluate(s.t, qI[mI.free], vI[mI.free], s.z).F
    a_I = FI / mI.mdiag
    got = a_expect[mI.free]
    tilt = mI.free >= mI.n_body_coords
    for part in (~tilt, tilt):
        scale = np.abs(got[part]).max()
        np.testing.assert_allclose(a_I[part], got[part], rtol=0, atol=1e-9 * scale)
    assert np.abs(got[tilt]).max() > 1.0                 # the tilts do accelerate


def test_the_sliced_machine_runs_compiled_as_on_the_numpy_path(machines):
    """The compiled twins of the sliced race contact and the face-sliced mesh (mbd.compiled.sliced): at a state with
    every planet sloped and every roller tilted (≈ 1e-4 rad) the compiled assembly is the reference's to round-off,
    and twenty steps give the same step counts and states on both engines."""
    from mbd.compiled.system import CompiledSystem
    sp, ss, s = machines
    nP, n = sp.model.ndof, ss.model.ndof
    rng = np.random.default_rng(3)
    q, v = _extended(ss, sp, s.q), _extended(ss, sp, s.v)
    q[nP:], v[nP:] = rng.standard_normal(n - nP) * 1e-4, rng.standard_normal(n - nP) * 1e-2
    system = mbd.System(ss.model)
    ref = system.evaluate(s.t, q, v, s.z, jac=True)
    got = CompiledSystem(system).evaluate(s.t, q, v, s.z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
    assert np.abs(ref.F[nP:]).max() > 1.0           # the tilts and slopes carry moments (≈ 20 N m at most here)
    st = mbd.State(s.t, q, v, _extended(ss, sp, s.a), _extended(ss, sp, s.f), dict(s.z))
    run = lambda eng: mbd.simulate(ss.model, t_end=s.t + 20 * H, state=st.copy(), stepper=mbd.PRODUCTION.stepper(),
                                   controller=mbd.FixedStep(H), progress=False, engine=eng)           # noqa: E731
    rc, rn = run("compiled"), run("numpy")
    assert (rc.engine, rn.engine) == ("compiled", "numpy") and rc.counters == rn.counters
    np.testing.assert_allclose(rc.state.q, rn.state.q, rtol=0, atol=1e-10)
    np.testing.assert_allclose(rc.state.v, rn.state.v, rtol=0, atol=1e-10 / H)


@pytest.mark.parametrize("model", ["planar", "sliced"])
def test_the_race_damping_ramp_reaches_every_raceway_contact(model):
    """bearing.race_damping_ramp is every roller–raceway instance's δ_c, planar and sliced, in metres; the default
    (0) keeps the damping whole at first touch."""
    from mbd.elements import RaceContact
    from mbd.elements.sliced import SlicedRaceContact

    p = reference_dpgt(3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for value, want in (("0.2 um", 2e-7), (None, 0.0)):
            b = p.bearing.replace(model=model, **({"race_damping_ramp": value} if value else {}))
            races = [e for e in build_dpgt(p.replace(bearing=b)).model.elements
                     if isinstance(e, (RaceContact, SlicedRaceContact))]
            assert sum(e.n for e in races) == 2 * 3 * 2 * 12          # inner and outer, 6 bearings, 12 rollers
            for e in races:
                np.testing.assert_array_equal(e.damping_ramp, want)
