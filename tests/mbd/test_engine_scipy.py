"""The solve_ivp adapter: same physics as HHT; Radau, BDF and LSODA agree with HHT on a nonlinear
large-rotation problem."""
from __future__ import annotations

import numpy as np
import pytest

import mbd
from mbd.elements import BodySpring, GroundSupport, TorqueSource


def double_pendulum(frame=None):
    """Two bobs hanging from a fixed pivot by offset marker springs: large rotations, gravity,
    a damped link, a torque — nonlinear in every coordinate."""
    b = mbd.ModelBuilder(frame=frame, gravity=(0.0, -9.81))
    p = b.add_body("pivot", 1.0, 1.0, fixed=True)
    a = b.add_body("a", 0.5, 1e-3, pose=(0.1, 0.0, 0.0))
    c = b.add_body("c", 0.3, 5e-4, pose=(0.25, 0.0, 0.0))
    b.add(BodySpring("rod_a", p, a, k=2e4, marker_b=(-0.1, 0.0)))
    b.add(BodySpring("rod_c", a, c, k=1e4, c=2.0, marker_a=(0.05, 0.0), marker_b=(-0.1, 0.0)))
    b.add(GroundSupport("air", [a, c], kx=0.0, c_theta=1e-4))
    b.add(TorqueSource("kick", c, torque=0.02))
    return b.build()


Q0 = np.array([0.1, 0.0, 0.0, 0.25, 0.0, 0.0])
V0 = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 2.0])
T_END = 0.15


@pytest.fixture(scope="module")
def scipy_runs():
    model = double_pendulum()
    out = {}
    for method in ("Radau", "BDF", "LSODA"):
        r = mbd.solve_scipy(model, Q0, V0, (0.0, T_END), method=method, rtol=1e-8, atol=1e-10, t_eval=[T_END])
        assert r.success, r.message
        out[method] = r
    return out


def hht_final(h, alpha=-0.05):
    model = double_pendulum()
    res = mbd.simulate(model, Q0, V0, T_END, stepper=mbd.HHT(alpha=alpha, newton_tol=1e-8),
                       controller=mbd.FixedStep(h), progress=False)
    return np.concatenate([res.state.q, res.state.v])


def test_scipy_methods_agree(scipy_runs):
    y = {k: r.y[:, -1] for k, r in scipy_runs.items()}
    assert np.abs(y["Radau"][:6] - Q0).max() > 0.5       # the bobs swung through a large angle
    for m in ("BDF", "LSODA"):
        np.testing.assert_allclose(y[m][:6], y["Radau"][:6], atol=2e-6, err_msg=m)      # positions, angles
        np.testing.assert_allclose(y[m][6:], y["Radau"][6:], atol=2e-4, err_msg=m)      # velocities
    assert scipy_runs["Radau"].njev >= 1 and scipy_runs["Radau"].nlu >= 1


def test_hht_converges_to_scipy_solution(scipy_runs):
    """HHT's error against the tight Radau solution shrinks like h² and ends small."""
    ref = scipy_runs["Radau"].y[:, -1]
    errs = [np.abs(hht_final(h)[:6] - ref[:6]).max() for h in (4e-4, 2e-4)]
    assert 3.0 < errs[0] / errs[1] < 5.0, errs
    assert errs[1] < 1e-4, errs       # positions [m] and angles [rad] of a ~0.2 m, ~1 rad motion


def test_lsoda_uses_the_jacobian_on_a_stiff_problem():
    """LSODA switches to its stiff method here and must get a dense Jacobian from the adapter."""
    b = mbd.ModelBuilder()
    a = b.add_body("a", 1.0, 0.1)
    c = b.add_body("c", 1e-3, 1e-6, pose=(0.1, 0.0, 0.0))
    b.add(GroundSupport("g", a, kx=100.0, k_theta=10.0))
    b.add(BodySpring("s", a, c, k=1e8, c=1e3))
    model = b.build()
    q0 = np.array([0.01, 0, 0, 0.1, 0, 0.0])
    v0 = np.array([0, 0, 1.0, 0, 0.1, 0])
    r = mbd.solve_scipy(model, q0, v0, (0.0, 0.2), method="LSODA", rtol=1e-7, atol=1e-10)
    assert r.success, r.message
    assert r.njev > 0
    ref = mbd.solve_scipy(model, q0, v0, (0.0, 0.2), method="Radau", rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(r.y[:6, -1], ref.y[:6, -1], atol=1e-6)


def test_first_order_jacobian_matches_finite_differences():
    model = double_pendulum(frame=mbd.Frame.rotating(20.0))
    fo = mbd.FirstOrderSystem(model)
    rng = np.random.default_rng(1)
    y = np.concatenate([Q0 + 0.01 * rng.standard_normal(6), rng.standard_normal(6)])
    J = fo.jac(0.1, y).toarray()
    Jfd = np.zeros_like(J)
    for j in range(y.size):
        d = np.zeros_like(y)
        d[j] = 1e-7
        Jfd[:, j] = (fo.fun(0.1, y + d) - fo.fun(0.1, y - d)) / 2e-7
    np.testing.assert_allclose(J, Jfd, rtol=1e-6, atol=1e-4)
    P = fo.sparsity().toarray()
    assert np.all(P[np.abs(J) > 0] == 1.0)       # the pattern covers every nonzero


def test_max_wall_time_is_reported_not_hidden():
    model = double_pendulum()
    r = mbd.solve_scipy(model, Q0, V0, (0.0, 100.0), method="Radau", rtol=1e-10, atol=1e-12, max_wall_s=0.2)
    assert not r.success and "wall time" in r.message
    assert r.wall_s < 5.0
