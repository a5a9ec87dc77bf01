"""HHT-α stepper and step controllers: order, spectral radius, energy, stiff stability, reuse policy."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

import mbd
from mbd.elements import BodySpring, GroundSupport
from mbd.hht import NewtonCache

ALPHAS = [0.0, -0.1, -0.3]


def oscillator(m=1.0, k=(2 * np.pi) ** 2, c=0.0):
    """One body on an isotropic support: x and y are independent oscillators ω = sqrt(k/m)."""
    b = mbd.ModelBuilder()
    a = b.add_body("a", m, 1.0)
    b.add(GroundSupport("sup", a, kx=k, cx=c, k_theta=k, c_theta=c))
    return b.build()


def exact_oscillator(t, x0, v0, m, k, c):
    """Damped (underdamped) free response."""
    wn = np.sqrt(k / m)
    z = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - z * z)
    A, B = x0, (v0 + z * wn * x0) / wd
    return np.exp(-z * wn * t) * (A * np.cos(wd * t) + B * np.sin(wd * t))


def run_stepper(model, q0, v0, h, nsteps, alpha, **kw):
    """Drive HHT.step directly (no controller); return the states after every step and the run's
    counters summed from the steps' StepInfo (+ the initial state's force evaluation), as simulate does."""
    system = mbd.System(model)
    stepper = mbd.HHT(alpha=alpha, newton_tol=kw.pop("newton_tol", 1e-10), **kw)
    s = stepper.initial_state(system, 0.0, q0, v0)
    counters = mbd.Counters(residual=1)
    cache = NewtonCache()
    out = [s]
    for _ in range(nsteps):
        s, info = stepper.step(system, s, h, cache)
        assert info.converged, info.reason
        counters.add(info)
        out.append(s)
    return out, counters


def test_hht_coefficients():
    assert mbd.hht_coefficients(0.0) == (0.25, 0.5)
    b, g = mbd.hht_coefficients(-0.3)
    assert b == pytest.approx(1.3 ** 2 / 4) and g == pytest.approx(0.8)
    b, g = mbd.hht_coefficients(-1.0 / 3.0)
    assert b == pytest.approx(4.0 / 9.0) and g == pytest.approx(5.0 / 6.0)


@pytest.mark.parametrize("alpha", ALPHAS)
@pytest.mark.parametrize("c", [0.0, 0.4], ids=["undamped", "damped"])
def test_observed_order_is_two(alpha, c):
    m, k = 1.0, (2 * np.pi) ** 2
    model = oscillator(m, k, c)
    T = 1.0
    errs = []
    for n in (32, 64, 128):                       # h, h/2, h/4 (powers of 2: t lands exactly on T)
        h = T / n
        states, _ = run_stepper(model, np.array([0.01, -0.02, 0.0]), np.array([0.0, 0.05, 0.0]), h, n, alpha)
        s = states[-1]
        assert s.t == T
        ex = np.array([exact_oscillator(T, 0.01, 0.0, m, k, c), exact_oscillator(T, -0.02, 0.05, m, k, c)])
        errs.append(np.abs(s.q[:2] - ex).max())
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all((slopes >= 1.8) & (slopes <= 2.2)), f"observed orders {slopes}, errors {errs}"


def amplification_matrix(alpha, omega_h, h=1e-3):
    """3×3 map (q, h v, h² a)_n -> (q, h v, h² a)_{n+1} of the *real* stepper on x' ' = −ω² x,
    built column by column from unit initial conditions (f_n = F(q_n) for the linear system)."""
    k = (omega_h / h) ** 2
    model = oscillator(1.0, k)
    system = mbd.System(model)
    stepper = mbd.HHT(alpha=alpha, newton_tol=1e-6)   # above the round-off floor of a unit state
    A = np.zeros((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = 1.0
        q = np.array([e[0], 0.0, 0.0])
        v = np.array([e[1] / h, 0.0, 0.0])
        a = np.array([e[2] / h ** 2, 0.0, 0.0])
        f = system.forces(0.0, q, v, {})
        s0 = mbd.State(0.0, q, v, a, f, {})
        s1, info = stepper.step(system, s0, h, NewtonCache())
        assert info.converged
        A[:, j] = [s1.q[0], h * s1.v[0], h * h * s1.a[0]]
    return A


@pytest.mark.parametrize("alpha", ALPHAS + [-1.0 / 3.0])
def test_spectral_radius_at_infinity(alpha):
    rho = np.abs(np.linalg.eigvals(amplification_matrix(alpha, 1e6))).max()
    # at α = −1/3 all three roots coincide at −1/2 (a defective eigenvalue): a perturbation ε of A
    # (here 1/(ωh)² and round-off) moves them by ~ε^(1/3), so that case is checked to 1e-3 only
    rel = 1e-3 if alpha == -1.0 / 3.0 else 1e-5
    assert rho == pytest.approx((1 + alpha) / (1 - alpha), rel=rel)


@pytest.mark.parametrize("alpha", ALPHAS)
def test_spectral_radius_low_frequency_near_one(alpha):
    """Accurate for resolved modes: ρ(ωh = 0.01) = 1 to O((ωh)^3) — no spurious low-frequency damping."""
    rho = np.abs(np.linalg.eigvals(amplification_matrix(alpha, 1e-2))).max()
    assert 1 - 1e-5 < rho <= 1 + 1e-12


def test_alpha_zero_conserves_energy_of_undamped_linear_system():
    """Trapezoidal rule (α = 0) on M a = −K q keeps ½vᵀMv + ½qᵀKq to round-off."""
    b = mbd.ModelBuilder()
    bodies = [b.add_body(f"b{i}", m, J) for i, (m, J) in enumerate([(1.0, 0.1), (0.3, 0.02), (2.0, 0.5)])]
    b.add(GroundSupport("sup", bodies[0], kx=1e4, k_theta=50.0))
    b.add(BodySpring("s", bodies[:2], bodies[1:], k=[3e3, 7e4]))
    model = b.build()
    _, _, K = mbd.linearize(model, 0.0, np.zeros(9), np.zeros(9))
    M = np.diag(model.mdiag)
    q0 = np.array([0.01, 0.0, 0.1, -0.02, 0.01, 0.3, 0.0, 0.005, -0.2])
    v0 = np.array([0.0, 0.3, 0.0, 0.1, 0.0, -2.0, 0.5, 0.0, 1.0])
    energy = lambda s: 0.5 * s.v @ M @ s.v + 0.5 * s.q @ K @ s.q
    states, counters = run_stepper(model, q0, v0, 2e-3, 5000, 0.0)
    E = np.array([energy(s) for s in states])
    assert np.abs(E - E[0]).max() / E[0] < 1e-10
    assert counters.factor == 1             # fixed h, linear system: one LU for the whole run


def test_alpha_negative_dissipates_energy_monotonically():
    model = oscillator(1.0, 1e6)
    M = np.diag(model.mdiag)
    states, _ = run_stepper(model, np.array([0.01, 0.0, 0.0]), np.zeros(3), 1e-2, 50, -0.2)
    E = np.array([0.5 * s.v @ M @ s.v + 0.5 * 1e6 * (s.q @ s.q) for s in states])
    assert np.all(np.diff(E) <= 1e-12 * E[0]) and E[-1] < 1e-3 * E[0]


@pytest.mark.parametrize("alpha", ALPHAS)
def test_stiff_oscillator_bounded_and_damped(alpha):
    """ωh = 1e4: unconditionally stable; for α < 0 the unresolved mode is damped at ρ∞ per step."""
    h, wh = 1e-4, 1e4
    k = (wh / h) ** 2
    model = oscillator(1.0, k)
    n = 40
    # q₁ is formed from predictor terms (ωh)² times larger than q: its round-off floor is
    # ~eps·(ωh)²·|q| (1e-4 of the position scale here), so a Newton tolerance below that stagnates
    states, _ = run_stepper(model, np.array([1e-3, 0.0, 0.0]), np.zeros(3), h, n, alpha, newton_tol=1e-3)
    x = np.array([s.q[0] for s in states])
    assert np.all(np.isfinite(x)) and np.abs(x).max() <= 1e-3 * (1 + 1e-9)
    rho_inf = (1 + alpha) / (1 - alpha)
    if alpha < 0:
        # the unresolved mode decays (the near-double root −ρ∞ makes it ~ n·ρ∞^n, not a clean ρ∞^n)
        assert np.abs(x[-5:]).max() < 0.05 * 1e-3
        assert np.abs(x[-5:]).max() < 40 ** 2 * rho_inf ** 35 * 1e-3
    else:
        assert np.abs(x[-10:]).max() > 0.5e-3    # trapezoidal: not damped at all


@pytest.mark.parametrize("reuse", [True, False])
def test_jacobian_reuse_policy_counts(reuse):
    model = oscillator(1.0, 1e4)
    states, c = run_stepper(model, np.array([0.01, 0, 0]), np.zeros(3), 1e-3, 100, -0.1, reuse=reuse)
    if reuse:
        assert c.factor == 1 and c.jacobian == 1
    else:
        assert c.factor == 100 and c.jacobian == 100
    # every Newton iteration evaluates the forces once: a residual, or right after a refresh the forces the
    # Jacobian evaluation computed at that very point (+ 1: the initial state's forces)
    assert c.residual + c.jacobian == c.newton + 1 and c.newton >= 100


def test_stale_jacobian_is_refreshed_on_a_nonlinear_problem():
    """A body swinging on an offset marker spring (large rotation) changes its tangent stiffness:
    the stale LU must be refreshed when Newton slows, and every step still converges."""
    b = mbd.ModelBuilder()
    g = b.add_body("g", 1.0, 1.0, fixed=True)
    a = b.add_body("a", 1.0, 0.01, pose=(0.0, 0.0, 0.0))
    b.add(BodySpring("s", g, a, k=1e4, marker_b=(0.2, 0.0)))
    model = b.build()
    res = mbd.simulate(model, np.array([-0.2, 0.0, 0.0]), np.array([0.0, 0.0, 30.0]), 0.3,
                       controller=mbd.FixedStep(1e-3), stepper=mbd.HHT(alpha=-0.05), progress=False)
    c = res.counters
    assert res.steps == 300 and c["rejected"] == 0
    assert 1 < c["factor"] < 300                 # refreshed sometimes, not every step
    assert c["newton"] / res.steps < 4


@given(alpha=st.floats(-1 / 3, 0.0), wh=st.floats(1e-3, 1e5))
def test_spectral_radius_never_exceeds_one(alpha, wh):
    rho = np.abs(np.linalg.eigvals(amplification_matrix(alpha, wh))).max()
    assert rho <= 1 + 1e-9


# ---------------------------------------------------------------------------------- controllers
def test_fixed_step_lands_on_t_end_and_counts_steps():
    model = oscillator()
    res = mbd.simulate(model, np.array([0.01, 0, 0]), np.zeros(3), 0.25, controller=mbd.FixedStep(1 / 64),
                       progress=False)
    assert res.steps == 16 and res.state.t == pytest.approx(0.25, abs=1e-15)
    assert res.h_min_used == res.h_max_used == 1 / 64


@pytest.mark.parametrize("alpha", [0.0, -0.2])
def test_adaptive_controller_meets_tolerance(alpha):
    """Adaptive steps keep every accepted local error estimate ≤ 1 and track the exact solution."""
    m, k = 1.0, (2 * np.pi * 5) ** 2
    model = oscillator(m, k)
    tol = mbd.Tolerance(rtol=1e-5, atol_pos=1e-8, atol_rot=1e-8)
    res = mbd.simulate(model, np.array([1e-3, 0, 0]), np.zeros(3), 1.0, stepper=mbd.HHT(alpha=alpha, tol=tol),
                       controller=mbd.Adaptive(h0=1e-2, h_min=1e-8), progress=False)
    assert res.error_max <= 1.0
    assert res.h_max_used > res.h_min_used          # it did adapt
    assert res.counters["rejected"] >= 1            # the initial h0 was too large
    ex = exact_oscillator(res.state.t, 1e-3, 0.0, m, k, 0.0)
    assert abs(res.state.q[0] - ex) < 2e-5          # global error: a few hundred local tolerances


def test_adaptive_decide_rules():
    c = mbd.Adaptive(h0=1e-3, h_min=1e-9, grow_max=2.0, shrink_min=0.2, hold=1.2)
    assert c.decide(1e-3, False, 0.1) == (False, pytest.approx(2.5e-4))    # Newton failure
    ok, h = c.decide(1e-3, True, 8.0)
    assert not ok and h == pytest.approx(1e-3 * 0.9 * 8 ** (-1 / 3))
    ok, h = c.decide(1e-3, True, 1e-12)
    assert ok and h == pytest.approx(2e-3)                                   # growth limited
    ok, h = c.decide(1e-3, True, 0.6)                                        # 0.9·0.6^(-1/3) ≈ 1.07: hold
    assert ok and h == 1e-3
    f = mbd.FixedStep(1e-3, max_halvings=3)
    assert f.decide(1e-3, False, 0.0) == (False, 5e-4)
    assert f.decide(5e-4, True, 50.0) == (True, 1e-3)                       # error only reported
    assert f.h_min == pytest.approx(1.25e-4)
