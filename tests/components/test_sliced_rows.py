"""Double-row sliced planet bearings (bearing.rows = 2 with bearing.model = "sliced", docs/model.md §8.8, §10.5) and
the sliced bearing rig: every row its own rollers at its axial station ±e_r/2, one cage.

Truths the code does not compute: the project's transcription of ISO/TS 16281:2008's laminae with its own solver
(tests/support/iso16281.py) for the rig's slice loads and the rows' split under a tilt; the planar model's folded rows
(one roller body standing for both rows) for a straight, aligned double row; the mirror ζ → −ζ for ±γ; finite
differences for the Jacobians; the numpy path for the compiled one; the series-system life of the rows,
L = (Σ_rows Σ_raceways L^(−9/8))^(−8/9), written out here."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import mbd
from components import life
from components.bearing import row_stations
from components.params import with_overrides
from components.presets import reference_bearing
from components.rig import build_bearing_rig, rig_loads, rig_quasi_static, rig_static_solution
from components.scene import SceneOptions
from components.units import ParameterError

from tests.support.iso16281 import iso_laminae, iso_solve

ARCMIN = math.pi / (180.0 * 60.0)
F = 10000.0                                  # N on the ring (a loaded planet bearing)
OPT = dict(cage="held", drag=False)


def _bearing(**over):
    return with_overrides(reference_bearing(), {"model": "sliced", **over}).si()


def _rig(b, gamma=0.0, direction="radial", load_angle=-0.5 * math.pi):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_bearing_rig(b, radial_load=F, load_angle=load_angle, options=SceneOptions(**OPT),
                                 misalignment=gamma, misalignment_direction=direction)


def _static(built, **kw):
    system = mbd.System(built.model)
    sol = rig_quasi_static(built, system=system, **kw)[0]
    return rig_loads(built, system, sol), sol, system


def test_row_stations_and_spacing():
    """Rows at ±e_r/2 about the bearing's centre, e_r = bearing.row_spacing (the roller length unless given); a spacing
    below the roller length is refused naming the parameter; the rig's double row has a body, a tilt, two race
    contacts and a pocket per roller of each row, one cage."""
    b = _bearing(rows=2)
    assert b.row_spacing == b.roller_length
    np.testing.assert_array_equal(row_stations(b), [-0.5 * b.roller_length, 0.5 * b.roller_length])
    assert row_stations(_bearing(rows=2, row_spacing="12 mm")) == pytest.approx([-6e-3, 6e-3], rel=1e-15)
    np.testing.assert_array_equal(row_stations(_bearing()), [0.0])
    with pytest.raises(ParameterError, match="bearing.row_spacing"):
        _bearing(rows=2, row_spacing="8 mm")
    r = _rig(b)
    Z = b.rollers
    h = r.bearing_handles
    assert h.rows == 2 and len(h.rollers) == 2 * Z and r.fold == 1
    assert (h.race_inner.stop - h.race_inner.start, h.pocket.stop - h.pocket.start) == (2 * Z, 2 * Z)
    # ring (3) + its slopes (2) + per roller x, y, θ and tilt; the pin and the held cage are fixed
    assert r.model.ndof == 3 + 2 + 4 * 2 * Z
    with pytest.raises(ParameterError, match="misalignment"):
        build_bearing_rig(reference_bearing().si(), radial_load=F, misalignment=ARCMIN)


# ------------------------------------------------------------------------------------- ISO/TS 16281
@pytest.mark.parametrize("rows", [1, 2])
@pytest.mark.parametrize("shape,direction", [("straight", "radial"), ("iso_16281", "tangential"),
                                             ("logarithmic", "radial")])
def test_rig_slice_loads_are_the_iso_16281_laminae(rows, shape, direction):
    """The rig's quasi-static state under 10 kN and a 4′ pin tilt (the ring's slope held): its ring displacement is the
    transcription's own solution and every slice of every roller of every row carries the transcription's lamina load,
    to 1e-6 where the standard's linear kinematics is exact (pitch diameter × 10⁴: its second order falls as 1/d_m, ≈ 1e-3
    at the reference geometry; module docstring of
    tests/support/iso16281.py). The loads are real (a load zone of several rollers, both rows loaded)."""
    b = _bearing(rows=rows, pitch_diameter="390 m", **{"profile.shape": shape})
    slope_dir = -0.5 * math.pi + (0.0 if direction == "radial" else 0.5 * math.pi)
    slope = 4 * ARCMIN * np.array([math.cos(slope_dir), math.sin(slope_dir)])
    rec, _, _ = _static(_rig(b, 4 * ARCMIN, direction))
    load = F * np.array([0.0, -1.0])
    u_iso = iso_solve(b, load, slope, 0.0, rows=row_stations(b))
    np.testing.assert_allclose(rec["ring"], u_iso, rtol=0, atol=1e-6 * np.hypot(*u_iso))
    q, _ = iso_laminae(b, rec["ring"], slope, 0.0, rows=row_stations(b))
    assert q.sum(-1).max() > 1500.0 and (q.sum(-1) > 0).sum() >= 4 * rows
    for got in (rec["slices_inner"], rec["slices_outer"]):
        np.testing.assert_allclose(got, q, rtol=0, atol=1e-6 * q.max())


def test_rows_split_under_a_tilt_as_the_iso_16281_laminae_say():
    """At the reference geometry (d_m = 39 mm) the rows' loads under 10 kN and a radial tilt split as the
    transcription's own solution says, to its second-order geometry (1e-3 of the load): at 4′ and 10′ the row on the
    side where the pin's axis is displaced towards the load zone carries more, and more at 10′."""
    b = _bearing(rows=2)
    load = F * np.array([0.0, -1.0])
    split = []
    for g in (4, 10):
        slope = g * ARCMIN * np.array([0.0, -1.0])
        rec, _, _ = _static(_rig(b, g * ARCMIN))
        q, _ = iso_laminae(b, iso_solve(b, load, slope, 0.0, rows=row_stations(b)), slope, 0.0,
                           rows=row_stations(b))
        got, want = rec["slices_inner"].sum(axis=(1, 2)), q.sum(axis=(1, 2))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-3 * want.sum())
        split.append(got[0] / got.sum())
    # the slope points along the load (−y), the zone lies at +y: row 0 (ζ < 0) sees the pin displaced by ζ s·e > 0
    assert 0.5 < split[0] < split[1] < 1.0


@pytest.mark.parametrize("direction", ["radial", "tangential"])
def test_plus_and_minus_tilt_mirror_the_rows(direction):
    """−γ is +γ mirrored across the mid-plane (ζ → −ζ): row 0 carries row 1's slices reversed, tilts change sign, and
    the bearing's rows together are the same (its life the same)."""
    b = _bearing(rows=2, **{"profile.shape": "iso_16281"})
    p, _, _ = _static(_rig(b, 6 * ARCMIN, direction))
    m, _, _ = _static(_rig(b, -6 * ARCMIN, direction))
    scale = p["slices_inner"].max()
    for key in ("slices_inner", "slices_outer"):
        np.testing.assert_allclose(m[key], p[key][::-1, :, ::-1], rtol=0, atol=1e-9 * scale)
    # the tilts to the static solver's tolerance (1e-11 m of motion over the roller's half-length)
    np.testing.assert_allclose(m["tilt"], -p["tilt"][::-1], rtol=0, atol=1e-11 / (0.5 * b.roller_length))
    assert not np.allclose(p["slices_inner"][0], p["slices_inner"][1], atol=1e-2 * scale)      # not trivial


# ------------------------------------------------------------------------------------- the planar reduction
def test_an_aligned_straight_double_row_is_the_planar_models_folded_rows():
    """Straight rollers, no tilt: both rows carry the same slices, every slice Q/n_s, and the rig is the planar
    model's double row, whose one roller body stands for both rows (mass 2m, contacts counted twice): the same ring
    displacement and roller loads (quasi-static), and over 30 steps of a dynamic run from the kinematic start the same
    ring and roller trajectories, row by row, the tilts and the ring's slope at round-off."""
    bs, bp = _bearing(rows=2), with_overrides(reference_bearing(), {"rows": 2}).si()
    rs, rp = _rig(bs), _rig(bp)
    # both static solutions converged to 1e-13 m: at the solver's default 1e-11 m each stops where its own path's
    # round-off leaves it (the two rigs' loads then 1e-9 apart, the ring 5e-15 m), not at the models' difference
    ss, _, _ = _static(rs, length_tol=1e-13)
    sp, _, _ = _static(rp, length_tol=1e-13)
    n_s = bs.slicing.slices
    q = ss["slices_inner"]
    np.testing.assert_array_equal(q[0], q[1])
    assert np.ptp(q, axis=2).max() <= 1e-12 * q.max()
    np.testing.assert_allclose(q.sum(-1), np.stack([sp["load_inner"]] * 2), rtol=0, atol=1e-9 * sp["load_inner"].max())
    np.testing.assert_allclose(ss["ring"], sp["ring"], rtol=0, atol=1e-9 * np.hypot(*sp["ring"]))
    np.testing.assert_allclose(ss["pin_force"], sp["pin_force"], rtol=0, atol=1e-9 * F)
    assert q.max() * n_s > 1000.0
    # dynamics: the sliced rig's free DOFs are (ring, rollers row by row, then ring slopes and roller tilts)
    Z, h = bs.rollers, 2e-6
    run = lambda built: mbd.simulate(built.model, t_end=30 * h, q0=built.q0, v0=built.v0,            # noqa: E731
                                     stepper=mbd.PRODUCTION.stepper(), controller=mbd.FixedStep(h), progress=False,
                                     engine="numpy")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a, c = run(rs), run(rp)
    body = lambda built, name: 3 * built.model.body(name).index                                       # noqa: E731
    for built, res in ((rs, a), (rp, c)):
        assert res.steps == 30
    qs, qp = (r.model.full(r_.state.t, r_.state.q, r_.state.v)[0] for r, r_ in ((rs, a), (rp, c)))
    ring = slice(body(rs, "ring"), body(rs, "ring") + 3)
    np.testing.assert_allclose(qs[ring], qp[body(rp, "ring"): body(rp, "ring") + 3], rtol=0, atol=1e-15)
    for j in range(Z):
        want = qp[body(rp, f"pb.roller{j}"): body(rp, f"pb.roller{j}") + 3]
        for name in (f"pb.roller{j}", f"pb.row1.roller{j}"):
            np.testing.assert_allclose(qs[body(rs, name): body(rs, name) + 3], want, rtol=0, atol=1e-15)
    assert np.abs(qs[rs.model.n_body_coords:]).max() < 1e-15


# ------------------------------------------------------------------------------------- Jacobians and engines
@pytest.fixture(scope="module")
def tilted():
    b = _bearing(rows=2, **{"profile.shape": "logarithmic"})
    r = _rig(b, 6 * ARCMIN, "tangential")
    rec, sol, system = _static(r)
    rng = np.random.default_rng(5)
    q, v = sol.q.copy(), sol.v.copy()
    nb = 3 * r.model.n_bodies - 3 * int(r.model.fixed.sum())            # the free body DOFs come first
    q[nb:] += rng.standard_normal(q.size - nb) * 2e-4                    # every tilt and the ring's slope moved
    v += rng.standard_normal(v.size) * 1e-3
    return r, system, sol.t, q, v, sol.z


def test_the_double_row_rig_jacobians_are_its_forces_derivatives(tilted):
    """J_q and J_v of the whole rig (both rows, roller tilts, the ring's slope and its support) against central
    differences of the forces, at a loaded state with every tilt and the ring's slope perturbed."""
    r, system, t, q, v, z = tilted
    _, C, K = system.matrices(system.evaluate(t, q, v, z, jac=True))
    for J, x, other, hstep in ((-K.toarray(), q, v, 1e-10), (-C.toarray(), v, q, 1e-7)):
        cols = range(x.size)
        fd = np.empty_like(J)
        for i in cols:
            xp, xm = x.copy(), x.copy()
            xp[i] += hstep
            xm[i] -= hstep
            args = (xp, other) if x is q else (other, xp)
            argm = (xm, other) if x is q else (other, xm)
            fd[:, i] = (system.evaluate(t, *args, z).F - system.evaluate(t, *argm, z).F) / (2 * hstep)
        assert np.abs(J).max() > 0.0
        np.testing.assert_allclose(J, fd, rtol=0, atol=1e-5 * np.abs(J).max())


def test_the_double_row_rig_runs_compiled_as_on_the_numpy_path(tilted):
    """Forces and Jacobians of the compiled assembly equal the reference's to round-off at the tilted state, and twenty
    steps from it give the same states on both engines."""
    from mbd.compiled.system import CompiledSystem
    r, system, t, q, v, z = tilted
    ref = system.evaluate(t, q, v, z, jac=True)
    got = CompiledSystem(system).evaluate(t, q, v, z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
    # twenty steps from the tilted state: the same step counts and states on both engines
    h = 2e-6
    st = mbd.PRODUCTION.stepper().initial_state(system, t, q, v)
    run = lambda eng: mbd.simulate(r.model, t_end=t + 20 * h, state=st.copy(), stepper=mbd.PRODUCTION.stepper(),  # noqa: E731
                                   controller=mbd.FixedStep(h), progress=False, engine=eng)
    rc, rn = run("compiled"), run("numpy")
    assert (rc.engine, rn.engine) == ("compiled", "numpy") and rc.counters == rn.counters
    np.testing.assert_allclose(rc.state.q, rn.state.q, rtol=0, atol=1e-12)
    assert np.abs(rn.state.q - q).max() > 1e-9                     # it moved


# ------------------------------------------------------------------------------------- dynamic rig and life
def test_the_dynamic_rig_settles_on_its_quasi_static_state():
    """The dynamic rig (held cage, ring at rest, 4′ radial tilt, the ring's slope on its housing support): its window
    mean of each row's roller loads is the quasi-static state of the same model (the slope solved against the support)
    within 1e-3 of the load, and the rows split as under the held slope within the support's compliance (1e-2). What
    separates dynamics from the static state: the static rollers sit at their pockets' centres, the dynamic ones creep
    within the pockets' clearance under the tangential part of the exact-norm contact forces, resisted only by the
    traction's slope μQ/v_0 (measured: the ring 9 nm lower at the window's start, 2.7e-8 m four times later, the
    largest roller-load difference growing with it from 1.7 N)."""
    b = _bearing(rows=2)
    r = _rig(b, 4 * ARCMIN)
    free, _, _ = _static(r, hold_tilt=False)
    held, _, _ = _static(r)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = rig_static_solution(r, samples=10)
    got = sol.loads_rows                                   # (rows, Z) in bins from the load-zone centre
    want = np.sort(free["slices_inner"].sum(-1), axis=1)
    np.testing.assert_allclose(np.sort(got, axis=1), want, rtol=0, atol=1e-3 * F)
    rows_h = held["slices_inner"].sum(axis=(1, 2))
    np.testing.assert_allclose(got.sum(1), rows_h, rtol=1e-2)
    assert got.sum(1)[0] > 2.0 * got.sum(1)[1]


def test_rows_combine_as_a_series_system_not_as_one_pooled_row():
    """The life of rows loaded differently: per row its raceways' equivalent loads, L = (Σ_rows Σ_k L_k^(−9/8))^(−8/9)
    with L_k = (Q_c/Q_e)^4 — written out here — which pooling both rows' rollers into one equivalent load misses (the
    rotating raceway's term is not linear in the rows' means); identical rows give b.rows times one row's terms."""
    b = _bearing(rows=2)
    qc_pin, qc_bore = life.raceway_ratings(b)
    pin, bore = np.array([3000.0, 900.0]), np.array([3300.0, 1100.0])
    L_k = np.concatenate([(qc_pin / pin) ** 4, (qc_bore / bore) ** 4])
    want = np.sum(L_k ** (-9 / 8)) ** (-8 / 9)
    assert life.lundberg_palmgren_life(pin, bore, b) == pytest.approx(want, rel=1e-12)
    assert life.lundberg_palmgren_life(pin[[0, 0]], bore[[0, 0]], b) == pytest.approx(
        life.lundberg_palmgren_life(pin[0], bore[0], b), rel=1e-12)
    pooled = (np.mean(bore ** 4) ** 0.25, np.mean(pin ** 4.5) ** (1 / 4.5))
    assert life.lundberg_palmgren_life(pooled[1], pooled[0], b) > 1.005 * want       # 0.9 % here: the bore term


def test_the_rig_command_reports_the_sliced_double_row(tmp_path):
    """python -m scenarios.bearing_rig --model sliced --rows 2 --misalignment "4 arcmin": aligned, the rows share the load
    equally and the pressure along the most loaded roller is flat (edge ratio 1); tilted, the first row (ζ < 0, the
    pin's axis displaced into the load zone) carries more, quasi-static and dynamic alike (the support's compliance:
    1e-2), the life falls, and the figure is written."""
    from scenarios.bearing_rig import parse_args, run
    s = run(parse_args(["--model", "sliced", "--rows", "2", "--misalignment", "4 arcmin", "--radial-load", "10 kN",
                        "--out", str(tmp_path), "--no-progress"]))["sliced"]
    np.testing.assert_allclose(s["row_load_share"]["aligned"], [0.5, 0.5], rtol=0, atol=1e-12)
    flat = np.array(s["pressure_profile_pin_Pa"]["aligned"])
    assert np.ptp(flat) <= 1e-9 * flat.max() and s["edge_pressure_ratio"]["aligned"] == pytest.approx(1.0, abs=1e-9)
    tilt = s["row_load_share"]["tilted"]
    assert tilt[0] > 0.7 and sum(tilt) == pytest.approx(1.0, rel=1e-12)
    np.testing.assert_allclose(s["row_load_share_dynamic"], tilt, rtol=0, atol=1e-2)
    assert 0.0 < s["life_relative"] < 1.0
    assert (tmp_path / "pressure_profile.png").stat().st_size > 10000
