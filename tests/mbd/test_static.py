"""The quasi-static solution (mbd.static): closed forms on small scenes, its exact Jacobian, bad input.
The DPGT's static solution against the dynamic runs' means is in tests/components/test_load_path.py (same runs)."""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import mbd
from mbd.elements import BodySpring, ForceSource, GroundSupport, TorqueSource
from mbd.static import SteadyMotion, _directions, _evaluator, _Problem, solve_static

M, K, F, W = 2.0, 4.0e6, 150.0, 900.0        # kg, N/m, N, rad/s (m W² = 1.62e6 N/m: the centrifugal term matters)


def _state(mb, vel):
    model = mb.build()
    q0 = model.pose0.ravel()[model.free]
    return model, q0, np.asarray(vel, float)[model.free]


def test_a_spring_in_a_turning_frame_stretches_by_the_centrifugal_closed_form():
    """A body at rest in a frame turning at W, on a ground spring K and damper c, pushed by F along x. At rest in R
    it moves through the fixed frame at W k × r, so the damper pulls it back along the turn:
    (K − M W²) x − c W y = F, (K − M W²) y + c W x = 0."""
    mb = mbd.ModelBuilder(frame=mbd.Frame.rotating(W))
    b = mb.add_body("b", M, 0.1)
    mb.add(GroundSupport("s", [b.index], kx=K, cx=50.0, k_theta=1e4))
    mb.add(ForceSource("f", [b.index], (F, 0.0)))
    model, q0, v0 = _state(mb, np.zeros(3))
    sol = solve_static(model, SteadyMotion.from_state(model, q0, v0, np.zeros(1)), 0.0, length_tol=1e-15, force_rtol=0.0)
    a, b = K - M * W ** 2, 50.0 * W
    np.testing.assert_allclose(sol.q[:2], [F * a / (a * a + b * b), -F * b / (a * a + b * b)], rtol=1e-9)


def test_an_orbiting_body_moves_out_by_its_centripetal_closed_form():
    """A body circling the origin at W in an inertial frame, on a zero-length ground spring K, pushed outwards by
    F at the instant it crosses the x axis: K ρ − M W² ρ = F (its place on the circle held)."""
    mb = mbd.ModelBuilder()
    b = mb.add_body("b", M, 0.1, pose=(0.05, 0.0, 0.0))
    mb.add(GroundSupport("s", [b.index], kx=K))
    mb.add(ForceSource("f", [b.index], (F, 0.0)))
    model, q0, v0 = _state(mb, [0.0, W * 0.05, 0.0])
    motion = SteadyMotion.from_state(model, q0, v0, np.array([W]))
    np.testing.assert_allclose(motion.centre[0], [0.0, 0.0], atol=1e-15)
    sol = solve_static(model, motion, 0.0, length_tol=1e-15, force_rtol=0.0)
    np.testing.assert_allclose(sol.q[0], F / (K - M * W ** 2), rtol=1e-9)
    np.testing.assert_allclose(sol.v[1], W * sol.q[0], rtol=1e-12)          # the circle at the displaced radius
    np.testing.assert_allclose(sol.a[0], -W ** 2 * sol.q[0], rtol=1e-12)


def test_a_spin_rate_settles_where_torque_and_damping_balance():
    """A body driven by a torque T against a torsional damper c: the solved spin rate is T/c, whatever it started at;
    held instead, its equation's residual is the reaction T − c ω₀."""
    T, c, w0 = 3.0, 0.02, 40.0
    mb = mbd.ModelBuilder()
    b = mb.add_body("b", M, 0.1)
    mb.add(GroundSupport("s", [b.index], kx=K, c_theta=c))
    mb.add(TorqueSource("t", [b.index], T))
    model, q0, v0 = _state(mb, [0.0, 0.0, w0])
    motion = SteadyMotion.from_state(model, q0, v0, np.zeros(1))
    sol = solve_static(model, motion, 0.0, rates=[(0, [])])
    np.testing.assert_allclose(sol.v[2], T / c, rtol=1e-9)
    held = solve_static(model, motion, 0.0, hold=[2])
    np.testing.assert_allclose(held.residual[2], T - c * w0, rtol=1e-12)


def test_a_cage_and_its_roller_turn_where_the_torque_meets_the_drag():
    """A 'cage' driven by a torque T carries a 'roller' on a spring k from a marker at radius ρ; a translational
    damper c on the roller drags it. One rate W for both: T = c W r², r = ρ + d the roller's displaced radius,
    k d = m W² r — whatever rate they started at."""
    T, c, rho, w0, k, m, kc = 0.9, 30.0, 0.04, 100.0, 1e7, 0.02, 1e13
    mb = mbd.ModelBuilder()
    cage = mb.add_body("cage", 0.5, 1e-3)
    roller = mb.add_body("roller", m, 1e-6, pose=(rho, 0.0, 0.0))
    mb.add(GroundSupport("s", [cage.index, roller.index], kx=[kc, 0.0], cx=[0.0, c]))
    mb.add(BodySpring("k", cage.index, roller.index, k, marker_a=(rho, 0.0)))
    mb.add(TorqueSource("t", [cage.index], T))
    model, q0, v0 = _state(mb, [0.0, 0.0, w0, 0.0, w0 * rho, 0.0])
    motion = SteadyMotion.from_state(model, q0, v0, np.array([0.0, w0]), host=np.array([-1, 0]))
    sol = solve_static(model, motion, 0.0, rates=[(0, [1])], hold=[5], length_tol=1e-15, rate_tol=1e-12, force_rtol=0.0)
    w, r = T / (c * rho ** 2), rho
    for _ in range(100):                     # the closed form's two equations, by fixed point
        d = m * w * w * r / k
        r = rho + d + k * d / kc
        w = T / (c * r * r)
    np.testing.assert_allclose(sol.v[2], w, rtol=1e-9)
    np.testing.assert_allclose(sol.q[3], r, rtol=1e-9)
    np.testing.assert_allclose(sol.v[4], w * sol.q[3], rtol=1e-12)


@pytest.mark.parametrize("law", ["tanh", "ehl"])
def test_a_roller_between_two_races_settles_at_the_slip_its_traction_curve_gives_for_its_drag_moment(law):
    """One roller pressed between a pin turning at ω_i and a ring at rest (4 µm interference on each race), orbiting
    the pin's centre at a rate W and spinning at ω_R — both solved, W as a group's rate (the bracketed continuation
    of a cage's rate), ω_R as the roller's own — against a drag moment M on its spin and nothing on its orbit. By
    hand: the orbit carries no tangential force, so the two tractions are equal and opposite, and the spin's balance
    gives each |F_t| = M/(r_i + r_o), r_i, r_o the contact points' distances from the roller's centre. Each contact
    then slips at the v_s where the traction curve gives that force: μ(v_s, u_e, Q)·Q = M/(r_i + r_o) — for tanh the
    closed form v_s = v₀ artanh(F_t/(μ_max Q)), for EHL the root of the law's curve (scipy's brentq, the law's
    coefficient at the contact's load and entraining speed). M puts the tractions at 85 % of what the curve gives at
    5 m/s of slip, on its shoulder, where the slip is most sensitive to M (measured: tanh 0.38 m/s, EHL 1.3–1.6 mm/s:
    the film's traction saturates within millimetres per second); the solve starts 30 rad/s off the kinematic orbit
    rate and 100 rad/s off the rolling spin."""
    from scipy.optimize import brentq
    from components.bearing import traction
    from components.presets import reference_dpgt
    from mbd.elements import RaceContact
    si = reference_dpgt(2, "forward").si()
    b = si.bearing
    tr = traction(dataclasses.replace(b, traction_law=law), si.lubricant)
    D, rho, m_r, dz = b.roller_diameter, 0.5 * b.pitch_diameter, b.roller_mass, 4e-6
    Ri, Ro = rho - 0.5 * D + dz, rho + 0.5 * D - dz
    Kc, w_i = 5e8, 400.0                       # N/m (a linear contact: Q ≈ 2 kN per race), rad/s
    mb = mbd.ModelBuilder()
    pin = mb.add_body("pin", 1.0, 1e-4)
    ring = mb.add_body("ring", 1.0, 1e-4, fixed=True)
    roller = mb.add_body("roller", m_r, m_r * D * D / 8, pose=(rho, 0.0, 0.0))
    common = dict(D=D, K=Kc, exponent=1.0, zeta=0.0, m_roller=m_r, traction=tr)
    mb.add(RaceContact("ri", [roller.index], [pin.index], kind="inner", race_marker=(0.0, 0.0), R_race=Ri, **common))
    mb.add(RaceContact("ro", [roller.index], [ring.index], kind="outer", race_marker=(0.0, 0.0), R_race=Ro, **common))
    # the largest traction the curve gives at the nominal load and entraining speed, and 85 % of it as the drag
    W_m = w_i * Ri / (Ri + Ro)                  # rolling: the orbit's rate, the roller's spin
    w_R = -(w_i - W_m) * Ri / (0.5 * D)
    u_e, Q0 = 0.5 * (w_i - W_m) * Ri, Kc * dz
    R_red = 1.0 / (2.0 / D + 1.0 / Ri)
    mu = (lambda v: tr.coefficient(v, u_e, Q0, R_red)) if law == "ehl" else (
        lambda v: tr.coefficient(v, u_e) if tr.needs_rolling_speed else tr.coefficient(v))
    M = 0.85 * float(mu(5.0)) * Q0 * D
    mb.add(TorqueSource("drag", [roller.index], M))     # against the roller's (negative) spin
    model = mb.build()
    q0 = model.pose0.ravel()[model.free]
    W0, s0 = W_m + 30.0, w_R + 100.0
    v0 = np.array([0.0, 0.0, w_i, 0.0, 0.0, 0.0, 0.0, W0 * rho, s0])[model.free]
    orbit = np.array([0.0, 0.0, W0])
    motion = SteadyMotion.from_state(model, q0, v0, orbit)
    sol = solve_static(model, motion, 0.0, hold=[0, 1, 2], rates=[(-1, [roller.index]), (roller.index, [])],
                       max_rate_step=10.0)
    out = mbd.System(model).outputs(sol.t, sol.q, sol.v, sol.z)
    ri, ro = out["ri"], out["ro"]
    r = np.hypot(sol.q[3], sol.q[4])
    arms = (r - Ri, Ro - r)
    F_t = M / sum(arms)
    np.testing.assert_allclose(ri["traction"][0], -ro["traction"][0], rtol=1e-6)      # nothing on the orbit
    np.testing.assert_allclose(abs(ri["traction"][0]), F_t, rtol=1e-6)                # the spin's balance
    for o, Rr in ((ri, R_red), (ro, 1.0 / (2.0 / D - 1.0 / Ro))):
        Q, u, vs = float(o["load"][0]), float(o["rolling_speed"][0]), float(o["slip_velocity"][0])
        if law == "tanh":
            v_hand = tr.v0 * np.arctanh(F_t / (tr.mu_max * Q))
        else:
            v_hand = brentq(lambda v: tr.coefficient(v, u, Q, Rr) * Q - F_t, 0.0, 5.0, xtol=1e-14)
        np.testing.assert_allclose(abs(vs), v_hand, rtol=1e-4)
        assert np.sign(vs) == -np.sign(o["traction"][0])               # the traction opposes the slip
    assert F_t > 0.8 * float(mu(5.0)) * float(ri["load"][0])           # on the curve's shoulder


def test_the_static_jacobian_is_the_derivative_of_the_residual():
    """K = −∂g/∂x of the DPGT's static problem (displacements, the cages' rates carrying their rollers' orbits,
    the rollers' spins) against central differences at a displaced state with changed rates."""
    from components import static
    from components.dpgt import build_dpgt
    from components.presets import reference_dpgt
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(reference_dpgt(3, "forward"))
    m = sc.model
    system = mbd.System(m)
    motion = static.steady_motion(sc)
    rates = static.rate_groups(sc)
    held = np.zeros(m.ndof, bool)
    held[static.held_dofs(sc)] = True
    held[m.full_to_free[[3 * sb + 2 for sb, _ in rates]]] = True
    B, _, _ = _directions(m, motion, 0.0045, held, False)
    prob = _Problem(system, _evaluator(system, "numpy"), motion, 0.0045, B, rates, system.init_internal())
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.normal(0.0, 3e-6, B.shape[1]), rng.normal(0.0, 2.0, len(rates))])
    g, Kx = prob.residual(x, jac=True)
    Kx = np.asarray(Kx)
    for j in rng.choice(x.size, 40, replace=False):
        h = 1e-11 if j < B.shape[1] else 1e-4        # a contact's curvature needs a short difference
        e = np.zeros(x.size)
        e[j] = h
        fd = -(prob.residual(x + e)[0] - prob.residual(x - e)[0]) / (2 * h)
        scale = max(np.abs(Kx[:, j]).max(), np.abs(fd).max())
        roundoff = 10 * np.finfo(float).eps * np.abs(g).max() / h       # the difference of two residuals of size |g|
        err = np.abs(fd - Kx[:, j]).max()
        assert err <= 1e-5 * scale + roundoff, (prob.label(int(j)), err, scale, roundoff)


def test_a_larger_clearance_solves_and_leaves_the_bearing_loads_where_the_gears_put_them():
    """The planet bearings' mean loads are set by the gear forces and the planets' centrifugal load, not by the
    bearings' clearance (the dynamic runs: 9329.7–9332.4 N at 20–32 µm, condition 3). The static solution at 40 µm
    (it did not converge at ≥ 28 µm before a rate's step was bounded: components.static.RATE_STEP) gives the 20 µm
    loads within 0.1 % (measured 0.026 %)."""
    from components.dpgt import build_dpgt
    from components.params import with_overrides
    from components.presets import reference_dpgt
    from components.static import static_summary
    loads = []
    for c in ("20 um", "40 um"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sc = build_dpgt(with_overrides(reference_dpgt(3, "forward"), {"bearing.clearance": c}))
        s = static_summary(sc, 2)
        loads.append([s[k]["bearing_load_mean_N"] for k in ("inner", "outer")])
    np.testing.assert_allclose(loads[1], loads[0], rtol=1e-3)


def test_an_instant_resting_on_a_force_jump_is_moved_within_its_mesh_phase():
    """Class-7 gears (tolerance study machine 0 of seed 1, condition 3) with a damper that switches on whole at
    contact (``mesh.damping_ramp = 0``, Kelvin–Voigt): at its eighth snapshot of eight a gear rests on a tooth
    pair's damping jump and has no static state. solve_snapshots moves the snapshot by 2 % of a mesh period
    (MOVES), where it solves; the moved state stands for the instant — the gears' displacements agree with those
    5 % of a mesh period on within 1 % of the largest (measured 0.12 %). With the default damping ramp the same
    instant has a static state."""
    from pathlib import Path

    from components import static
    from components.dpgt import build_dpgt
    from scenarios import tolerance_study as ts
    from scenarios.core.points import points_of
    a = ts.parse_args(["--samples", "1", "--gear-class", "7", "--conditions", "3", "--directions", "forward"])
    jump = {"mesh.damping_ramp": "0 m"}
    points = points_of(a, {})
    task = next(t for t in ts.static_tasks(a, Path("unused"), jump, points) if t.sample == 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(ts.build_params(task.case))
    m, motion = sc.model, static.steady_motion(sc)
    kw = dict(hold=static.held_dofs(sc), rates=static.rate_groups(sc), max_rate_step=static.RATE_STEP)
    t, period = static.snapshot_times(sc, 8)[7], 1.0 / sc.f_m
    with pytest.raises(mbd.ModelError, match="no static state"):
        solve_static(m, motion, t, **kw)
    ramped = build_dpgt(ts.build_params(next(x for x in ts.static_tasks(a, Path("unused"), {}, points)
                                             if x.sample == 0).case))
    solve_static(ramped.model, static.steady_motion(ramped), t, hold=static.held_dofs(ramped),
                 rates=static.rate_groups(ramped), max_rate_step=static.RATE_STEP)
    moved = static.solve_snapshots(sc, [t])[0]
    assert moved.t == pytest.approx(t + static.MOVES[0] * period, rel=1e-12)
    near = solve_static(m, motion, t + 0.05 * period, **kw)
    gears = [m.body(n).index for n in ("sun", "a1", "a2", "a3", "b1", "b2", "b3")]

    def shift(sol):
        X = np.zeros((m.n_bodies, 3))
        X.ravel()[m.free] = sol.q
        return (X - motion.poses(sol.t))[gears, :2]
    d0, d1 = shift(moved), shift(near)
    assert np.abs(d1 - d0).max() < 0.01 * np.abs(d0).max(), (d0, d1)


@pytest.mark.parametrize("clearance, load_deg", [("0 um", -90.0), ("20 um", -90.0), ("40 um", -90.0), ("10 um", 100.0)])
def test_the_rig_s_static_state_is_the_classical_load_distribution(clearance, load_deg):
    """The bearing rig with its cage held and its ring at rest (components.rig): its static state — the rollers kept
    on their circles about the pin (``circles``: each moves only radially, as the held pockets hold them), the ring
    free — is the classical discrete load distribution (Stribeck 4.08 at zero clearance; the values the dynamic rig
    is held to in tests/components/test_scenes.py, within 2e-3): every roller's load within 1e-3 of the largest
    (measured 3.3e-4 to 6.3e-4; against the settled dynamic rig 5.3e-4 at 0 µm, 7.9e-4 at 20 µm), the ring's deflection
    within 1e-3 (measured 2.4e-4 to 3.2e-4 short), inner and outer raceway loads equal, and the rollers' loads on
    the pin summing to the load (2.1e-4 to 2.7e-4 short)."""
    from components.presets import reference_bearing
    from components.rig import build_bearing_rig, rig_loads
    from components.scene import SceneOptions
    from mbd.ad import wrap_angle
    F, a = 5000.0, np.radians(load_deg)
    rig = build_bearing_rig(reference_bearing().replace(clearance=clearance), radial_load=F, load_angle=a,
                            options=SceneOptions(cage="held"))
    m = rig.model
    rollers = [m.body(r).index for r in rig.bearing_handles.rollers]
    motion = SteadyMotion.from_state(m, rig.q0, rig.v0, np.zeros(m.n_bodies), circles={r: (0.0, 0.0) for r in rollers})
    sol = solve_static(m, motion, 1.01 * rig.ramp)
    r = rig_loads(rig, mbd.System(m), mbd.State(sol.t, sol.q, sol.v, sol.a, np.zeros_like(sol.q), sol.z))
    ref = rig.reference
    # each roller against the reference roller at its angle (both from the load-zone centre)
    match = np.argmin(np.abs(wrap_angle(r["angle"][:, None] - ref.angles[None, :])), axis=1)
    assert np.abs(wrap_angle(r["angle"] - ref.angles[match])).max() < 1e-9
    np.testing.assert_allclose(r["load_inner"], ref.loads[match], atol=1e-3 * ref.q_max)
    np.testing.assert_allclose(r["load_outer"], r["load_inner"], atol=1e-5 * ref.q_max)
    np.testing.assert_allclose(r["load_sum"], F * np.array([np.cos(a), np.sin(a)]), atol=1e-3 * F)
    u = np.array([np.cos(a), np.sin(a)])
    assert r["ring"] @ u == pytest.approx(ref.deflection, rel=1e-3)
    assert r["ring"] @ np.array([-u[1], u[0]]) == pytest.approx(ref.sideways, abs=1e-2 * ref.deflection)


def test_bad_input_is_refused_in_one_line():
    mb = mbd.ModelBuilder()
    b = mb.add_body("b", M, 0.1)
    mb.add(ForceSource("f", [b.index], (F, 0.0)))
    model, q0, _ = _state(mb, np.zeros(3))
    with pytest.raises(mbd.ModelError, match="body 'b' moves in the reference frame .* no orbit rate"):
        SteadyMotion.from_state(model, q0, np.array([1.0, 0.0, 0.0]), np.zeros(1))
    with pytest.raises(mbd.ModelError, match="orbit: one finite rate"):
        SteadyMotion.from_state(model, q0, np.zeros(3), np.zeros(2))
    motion = SteadyMotion.from_state(model, q0, np.zeros(3), np.zeros(1))
    with pytest.raises(mbd.ModelError, match=r"no static state .*\(worst unknown: b\.x\)"):
        solve_static(model, motion, 0.0, max_steps=30)       # a force and nothing to hold the body


def test_the_paper_study_in_static_mode(tmp_path):
    """--mode static: each run's summary.json says so, that its lives leave out the dynamic load, and lists what it
    leaves out, there is no results.nc, the comparison has the static quantities only and says what its lives
    ignore, and the reverse inner planet bearing carries more than forward (the load path's sign, as the dynamic
    study finds it)."""
    import csv
    import json

    from scenarios import paper_study
    assert paper_study.main(["--mode", "static", "--snapshots", "4", "--conditions", "3", "--out", str(tmp_path),
                             "--no-progress"]) == 0
    s = json.loads((tmp_path / "c3_reverse" / "summary.json").read_text())
    assert s["mode"] == "static" and s["snapshots"] == 4 and "cage_slip_pct" in s["omitted"]
    assert s["lives_ignore_dynamic_load"] is True
    assert s["machine"]["label"].startswith("reference machine [")                 # the machine it ran
    assert "leave out the dynamic load" in (tmp_path / "comparison.md").read_text()
    assert not (tmp_path / "c3_reverse" / "results.nc").exists()
    rows = list(csv.DictReader((tmp_path / "comparison.csv").open()))
    quantities = {r["quantity"] for r in rows}
    assert "bearing_load_mean_N" in quantities and "cage_slip_pct" not in quantities
    inner = next(r for r in rows if r["bearing"] == "inner" and r["quantity"] == "bearing_load_mean_N")
    assert float(inner["reverse"]) > 1.2 * float(inner["forward"])
