"""Compiled kernels of the planet-bearing contact families (:mod:`mbd.elements.contact`), following the
convention of :mod:`mbd.compiled` (pack / evaluate / update / outputs). The numpy kernels stay the reference.

Layouts (P: one row per instance, columns in this order; G: family-wide values):

``RaceContact``   P (n, 9): κ (+1 inner, −1 outer: per instance, so a fused inner + outer family packs
                  as one), race_marker x, y [m], R_race [m], D [m], K, c₀ = 2ζ·sqrt(m_roller·p·K), multiplicity,
                  damping_ramp δ_c [m] (0: the damping whole at first touch);
                  a family with a spall packs 4 more columns, so the kernel decides from P's width (a family
                  without one pays nothing): spall_angle [rad], (w + e)/2 [m], depth h [m], edge e [m]
                  G (11,): exponent p, traction law id, then the law's coefficients (zero-padded):
                  law 0 (TanhTraction): mu_max, v0;  law 1 (SlideRollTraction): A, B, C, D, u_reg, s_eps;
                  law 2 (EHLTraction): eta0, alpha_p, E_red, length, tau_L0, gamma_L, G_e, u_reg,
                  beta·eta0/k_oil (L = that × u², the thermal loading number); a family with rolling resistance
                  (HoupertRolling) packs 5 more: 1, eta0, E_red, length, u_reg (G of 16: the kernel
                  decides from G's size, a family without it pays nothing)
``PocketContact`` P (n, 10): pocket_angle ψ, pitch_radius, clearance, K_p, λ (impact law damping), v_min, mu,
                  v_mu, D, multiplicity;  G (0,)
``PocketRetention`` P (n, 9): pitch_radius, clearance C_r, K_r, λ, v_min, mu, v_mu, D, multiplicity;  G (0,)
``GuideContact``  P (n, 7): clearance, K_g, λ, v_min, mu, v_mu, land_radius;  G (4,): land law (0 dry,
                  1 hydrodynamic), then for the film: eta, width, min_film
``LubricantDrag`` P (n, 4): race_marker x, y [m], coef = C_d ρ D l d_m²/8, multiplicity; with viscous churning
                  2 more: coef_visc (of Ω|Ω|^(1/3)), coef_spin = π η_e D² l (the kernel decides from P's width);
                  G (0,)

The impact families' internal state z (n, 4) is the reference's: [v₀, x, ẋ, valid].

How the Jacobians are made. Each kernel computes the reference kernel's values line by line, in the same
operation order (values agree with numpy to an ulp of the transcendental functions). When ``jac``, the
nonlinear scalar laws give their partial derivatives once per instance (traction μ(v_s, u), Hertz load
Q(δ, δ̇), impact force F(x, ẋ), friction tanh), and the hand-written differential of every line is then
evaluated along each of the 12 unit directions (6 local coordinates q, then 6 velocities v): a direction
is one column of J_q (j < 6) or J_v (j ≥ 6). All scalars, no temporaries, exact (no differencing). The race law,
the costliest, uses its structure: the forces see the two centres only through their difference (the race body's
translation columns are the roller's negated, exactly; the roller's angle column is zero), and the velocity
directions leave the geometry (ρ, e, t, the contact point) unchanged, so their columns carry only the rate terms.

Regularisations and branches mirror the reference: the safe norm sqrt(x² + y² + η²); ad.where / ad.pos
semantics (the branch is chosen on values, an inactive branch contributes a zero derivative); the impact
force K x (1 + λ ẋ/v₀) with v₀ the stored approach speed z[:, 0] if > 0, else max(ẋ, v_min) of the iterate,
clipped at ≥ 0; the derivative of arctan2 uses x² + y² (no η), as :func:`mbd.ad.arctan2`.

The frame state (φ, Ω, Ω̇) does not enter these forces (they depend on relative motion only).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..elements import ehl, pocket_film, race_film
from . import tooth_pairs
from ..elements.contact import (DryLand, EHLTraction, GuideContact, HoupertRolling, HydrodynamicLand, LubricantDrag,
                                PocketContact, PocketRetention, RaceContact, SlideRollTraction, TanhTraction)

__all__ = ["traction_g", "pack_race", "evaluate_race", "outputs_race", "pack_pocket", "evaluate_pocket", "outputs_pocket",
           "update_pocket", "pack_retention", "evaluate_retention", "outputs_retention", "update_retention",
           "pack_guide", "evaluate_guide", "outputs_guide", "update_guide", "pack_drag", "evaluate_drag", "pack_pocket_film", "evaluate_pocket_film",
           "pack_cage_drag", "evaluate_cage_drag", "pack_race_film", "evaluate_race_film", "TRACTION_IDS", "RACE_OUTPUTS", "POCKET_OUTPUTS", "RETENTION_OUTPUTS", "GUIDE_OUTPUTS"]

_ETA2 = 1e-24          # the reference's η² (mbd.elements.contact._ETA2)
_TWO_PI = 2.0 * np.pi
TANH, SLIDE_ROLL, EHL = 0, 1, 2
TRACTION_IDS = {TanhTraction: TANH, SlideRollTraction: SLIDE_ROLL, EHLTraction: EHL}
_STRIP_A, _STRIP_W = ehl.STRIP_NODES.copy(), ehl.STRIP_WEIGHTS.copy()
_THERMAL_A, _THERMAL_M = ehl.THERMAL_A, ehl.THERMAL_EXPONENT


# ------------------------------------------------------------------------------------------ pack
def _rows(*cols) -> np.ndarray:
    return np.ascontiguousarray(np.column_stack([np.asarray(c, dtype=float) for c in cols]), dtype=np.float64)


def _require(elem, cls):
    if type(elem) is not cls:
        raise NotImplementedError(f"{elem.name}: the compiled {cls.__name__} kernel does not cover "
                                  f"{type(elem).__name__}")


def traction_g(name, tr, exponent) -> np.ndarray:
    """G (11,) of a race law: the exponent, the traction law's id and its coefficients (module docstring)."""
    law = TRACTION_IDS.get(type(tr))
    if law == TANH:
        coef = [tr.mu_max, tr.v0]
    elif law == SLIDE_ROLL:
        coef = [tr.A, tr.B, tr.C, tr.D, tr.u_reg, tr.s_eps]
    elif law == EHL:
        coef = [tr.eta0, tr.alpha_p, tr.E_red, tr.length, tr.tau_L0, tr.gamma_L, tr.G_e, tr.u_reg,
                tr.beta * tr.eta0 / tr.k_oil]
    else:
        raise NotImplementedError(f"{name}: traction law {type(tr).__name__} has no "
                                  f"compiled kernel (compiled: {sorted(c.__name__ for c in TRACTION_IDS)})")
    G = np.zeros(11)
    G[:2 + len(coef)] = [exponent, float(law), *coef]
    return G


def pack_race(elem):
    _require(elem, RaceContact)
    G = traction_g(elem.name, elem.traction, elem.exponent)
    mk = elem.race_marker
    cols = [elem.kappa, mk[:, 0], mk[:, 1], elem.R_race, elem.D, elem.K, elem._c0, elem.multiplicity,
            elem.damping_ramp]
    if elem.has_spall:
        cols += [elem.spall_angle, elem._spall_hi, elem.spall_depth, elem.spall_edge]
    P = _rows(*cols)
    roll = elem.rolling
    if roll is not None:
        if type(roll) is not HoupertRolling:
            raise NotImplementedError(f"{elem.name}: RaceContact with rolling law {type(roll).__name__} has no "
                                      "compiled kernel (compiled: HoupertRolling)")
        G = np.concatenate([G, [1.0, roll.eta0, roll.E_red, roll.length, roll.u_reg]])
    return P, G


def pack_pocket(elem):
    _require(elem, PocketContact)
    P = _rows(elem.pocket_angle, elem.pitch_radius, elem.clearance, elem.K_p, elem.lam, elem.v_min, elem.mu,
              elem.v_mu, elem.D, elem.multiplicity)
    return P, np.zeros(0)


def pack_retention(elem):
    _require(elem, PocketRetention)
    P = _rows(elem.pitch_radius, elem.clearance, elem.K_r, elem.lam, elem.v_min, elem.mu, elem.v_mu, elem.D,
              elem.multiplicity)
    return P, np.zeros(0)


def pack_guide(elem):
    _require(elem, GuideContact)
    land = elem.land
    if type(land) is DryLand:
        G = np.zeros(4)
    elif type(land) is HydrodynamicLand:
        G = np.array([1.0, land.eta, land.width, land.min_film])
    else:
        raise NotImplementedError(f"{elem.name}: GuideContact with land law {type(land).__name__} has no "
                                  "compiled kernel (compiled: DryLand, HydrodynamicLand)")
    P = _rows(elem.clearance, elem.K_g, elem.lam, elem.v_min, elem.mu, elem.v_mu, elem.land_radius)
    return P, G


def pack_drag(elem):
    _require(elem, LubricantDrag)
    mk = elem.race_marker
    cols = [mk[:, 0], mk[:, 1], elem.coef, elem.multiplicity]
    if elem.viscous:
        cols += [elem.coef_visc, elem.coef_spin]
    return _rows(*cols), np.zeros(0)


# ----------------------------------------------------------------------------------- scalar helpers
@njit(cache=True, inline="always")
def _u(j, m):
    """1 if j == m else 0 (inlined: the callers pass m as a literal, one compiled copy per value otherwise)."""
    return 1.0 if j == m else 0.0


@njit(cache=True)
def _unit(j):
    """Direction j of (q, v) (6 + 6 local coordinates) as 12 scalars."""
    return (_u(j, 0), _u(j, 1), _u(j, 2), _u(j, 3), _u(j, 4), _u(j, 5),
            _u(j, 6), _u(j, 7), _u(j, 8), _u(j, 9), _u(j, 10), _u(j, 11))


@njit(cache=True)
def _sign(x):
    """np.sign (0 at 0)."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(cache=True)
def _wrap(x):
    """mbd.ad.wrap_angle: x − 2π·round(x/2π) (its derivative is 1)."""
    return x - _TWO_PI * np.round(x / _TWO_PI)


@njit(cache=True)
def _d_cross(rx, ry, drx, dry, fx, fy, dfx, dfy):
    """Differential of the torque r × f = rx·fy − ry·fx."""
    return drx * fy + rx * dfy - dry * fx - ry * dfx


@njit(cache=True)
def _col(J, i, c, m, f0, f1, f2, f3, f4, f5):
    """Column c of instance i's block of J, times m. (Its own function: choosing J_q or J_v by a branch inside one
    function, ``J = Jq if j < 6 else Jv``, made every column write cost ≈ 50–60 ns of array bookkeeping — most of
    the contact families' Jacobians, measured: docs/numerics.md §5.)"""
    J[i, 0, c], J[i, 1, c], J[i, 2, c] = f0 * m, f1 * m, f2 * m
    J[i, 3, c], J[i, 4, c], J[i, 5, c] = f3 * m, f4 * m, f5 * m


@njit(cache=True)
def _write(F, Jq, Jv, i, j, m, f0, f1, f2, f3, f4, f5):
    """Generalized forces (j < 0) or the derivative column j of instance i, times the multiplicity m."""
    if j < 0:
        F[i, 0], F[i, 1], F[i, 2] = f0 * m, f1 * m, f2 * m
        F[i, 3], F[i, 4], F[i, 5] = f3 * m, f4 * m, f5 * m
    elif j < 6:
        _col(Jq, i, j, m, f0, f1, f2, f3, f4, f5)
    else:
        _col(Jv, i, j - 6, m, f0, f1, f2, f3, f4, f5)


@njit(cache=True)
def _mirror_cols(Jq, Jv, i):
    """The columns a two-body law that sees the bodies' centres only through their difference need not compute: the
    second body's translations (position and velocity) are the first's negated, exactly (every line of the
    differential is odd in the direction), and the first body's angle (column 2 of J_q) moves no force."""
    for a in range(6):
        Jq[i, a, 2] = 0.0
        Jq[i, a, 3], Jq[i, a, 4] = -Jq[i, a, 0], -Jq[i, a, 1]
        Jv[i, a, 3], Jv[i, a, 4] = -Jv[i, a, 0], -Jv[i, a, 1]


@njit(cache=True)
def _zero(F, Jq, Jv, i, jac):
    """An inactive instance: no force, and (ad.where) no derivative."""
    for a in range(6):
        F[i, a] = 0.0
        if jac:
            for b in range(6):
                Jq[i, a, b] = 0.0
                Jv[i, a, b] = 0.0


@njit(cache=True)
def _traction(law, G, v_s, u):
    """Traction coefficient μ(v_s, u_roll) and its partials ∂μ/∂v_s, ∂μ/∂u_roll (G layout: module doc) of
    the laws that do not depend on the load (tanh, slide_roll)."""
    if law == TANH:
        mu_max, v0 = G[2], G[3]
        th = np.tanh(v_s * (1.0 / v0))
        return mu_max * th, mu_max * (1.0 - th * th) / v0, 0.0
    A, B, C, D, u_reg, s_eps = G[2], G[3], G[4], G[5], G[6], G[7]
    h = np.sqrt(u * u + u_reg ** 2)
    s = v_s / h                                # regularised slide-to-roll ratio
    a = np.sqrt(s * s + s_eps ** 2)            # smoothed |s|
    ex = np.exp(a * (-C))
    g = (A + B * a) * ex + D
    r = s / a
    dg = (B - C * (A + B * a)) * ex            # g'(a)
    # d/ds [(s/a)·g(a)] with da/ds = s/a; d(s/a)/ds = (1 − r²)/a = s_eps²/a³, written without the cancellation
    # of 1 − r² at |s| ≫ s_eps (the reference's dual numbers carry it: see the test module)
    dmu_ds = g * (s_eps * s_eps / (a * a * a)) + r * r * dg
    return r * g, dmu_ds / h, -dmu_ds * s * u / (h * h)


@njit(cache=True)
def _ehl_traction(G, v_s, u, Q, Rr):
    """EHLTraction.coefficient (the reference's operations) and ∂μ/∂v_s, ∂μ/∂u, ∂μ/∂Q for a contact of
    reduced radius Rr. Film h_c = C w^−0.166 ũ^0.692 φ_T(c ũ²), p_max, b ∝ √w, so each scales as a power
    of Q; φ_T = a/(a + x), x = (c ũ²)^m: d ln φ_T / d ln ũ = −2m x/(a + x)."""
    eta0, alpha, E, length, tauL0, gam, G_e, u_reg, c_T = G[2], G[3], G[4], G[5], G[6], G[7], G[8], G[9], G[10]
    w = Q * (1.0 / length)
    ut = np.sqrt(u * u + u_reg ** 2)
    U, W, Gm = eta0 * ut / (E * Rr), w * (1.0 / (E * Rr)), alpha * E
    h_c = Rr * 2.922 * Gm ** 0.470 * W ** -0.166 * U ** 0.692
    n_u = 0.692                                        # d ln h_c / d ln ũ
    if c_T > 0.0:
        x = (ut * ut * c_T) ** _THERMAL_M
        h_c *= _THERMAL_A / (_THERMAL_A + x)
        n_u -= 2.0 * _THERMAL_M * x / (_THERMAL_A + x)
    hc_u, hc_Q = n_u * h_c * u / (ut * ut), -0.166 * h_c / Q
    p_max = np.sqrt(w * (E / (2.0 * np.pi * Rr)))
    b = np.sqrt(w * (8.0 * Rr / (np.pi * E)))
    el = ut / (G_e * b)
    el_u, el_Q = (u / ut) / (G_e * b), -0.5 * el / Q
    sr = v_s / h_c
    tau, t_s, t_u, t_Q = 0.0, 0.0, 0.0, 0.0
    for k in range(_STRIP_A.size):
        p = p_max * _STRIP_A[k]
        p_Q = 0.5 * p / Q
        L = tauL0 + gam * p
        inv_eta = np.exp(-alpha * p) * (1.0 / eta0)
        e = 1.0 / (inv_eta + el)
        X = e * sr / L
        th = np.tanh(X)
        wk = _STRIP_W[k]
        tau += wk * L * th
        dX = L * (1.0 - th * th)                       # ∂τ/∂X; ∂τ/∂L|_X = th, ∂X/∂L = −X/L
        e2 = e * e
        # v_s: only the shear rate; u: the film and the elastic compliance; Q: all of p, L, η, b, h_c
        t_s += wk * dX * e / (h_c * L)
        de_u = -e2 * el_u
        t_u += wk * dX * (de_u * sr - e * sr * hc_u / h_c) / L
        L_Q = gam * p_Q
        de_Q = -e2 * (-alpha * inv_eta * p_Q + el_Q)
        X_Q = (de_Q * sr - e * sr * hc_Q / h_c) / L - X * L_Q / L
        t_Q += wk * (th * L_Q + dX * X_Q)
    pbar = 0.25 * np.pi * p_max
    mu = tau / pbar
    return mu, t_s / pbar, t_u / pbar, t_Q / pbar - mu * 0.5 / Q


_RG = 11                                        # G index of the rolling-resistance block (pack_race)
_R_IVR, _R_EHL, _R_BLEND, _R_HERTZ = HoupertRolling.IVR, HoupertRolling.EHL, HoupertRolling.BLEND, HoupertRolling.HERTZ


@njit(cache=True)
def _rolling(G, Q, u, Rr):
    """HoupertRolling.force (the reference's operations) and its partials. F_R = c√(UW)(1 + s)^(−1/10), s ∝ W⁵/U^(5/2):
    ∂ln F_R/∂ln W = ½/(1 + s), ∂ln F_R/∂ln U = ½ + ¼ s/(1 + s); F = F_R(ũ) u/ũ."""
    eta0, E, L, u_reg = G[_RG + 1], G[_RG + 2], G[_RG + 3], G[_RG + 4]
    ut = np.sqrt(u * u + u_reg ** 2)
    ER = E * Rr
    U, W = (2.0 * eta0) * ut / ER, Q * (1.0 / (ER * L))
    M = W / np.sqrt(U)
    s = (_R_IVR / _R_EHL) ** _R_BLEND * M ** (0.5 * _R_BLEND)
    FR = (ER * L) * ((_R_IVR * _R_HERTZ) * np.sqrt(U * W) * (1.0 + s) ** (-1.0 / _R_BLEND))
    F = FR * u / ut
    n_u = 0.5 + 0.25 * s / (1.0 + s)
    return F, 0.5 * F / (Q * (1.0 + s)), (FR / ut) * (n_u * u * u + u_reg * u_reg) / (ut * ut)


@njit(cache=True)
def _approach(v_min, xd, v_stored):
    """(v₀, dv₀/dẋ): the stored approach speed if > 0, else max(ẋ, v_min) of the iterate."""
    if v_stored > 0.0:
        return v_stored, 0.0
    if xd > v_min:
        return xd, 1.0
    return v_min, 0.0


@njit(cache=True)
def _impact(K, lam, v_min, x, xd, v_stored):
    """Impact force F = K x (1 + λ ẋ/v₀) ≥ 0 for x > 0 (else 0) and its partials ∂F/∂x, ∂F/∂ẋ (0 where
    F is clipped). v₀ = v_stored if > 0, else max(ẋ, v_min) of the iterate (then v₀ follows ẋ)."""
    if not x > 0.0:
        return 0.0, 0.0, 0.0
    v_app, dv = _approach(v_min, xd, v_stored)
    F = K * x * (1.0 + lam * xd / v_app)
    if not F > 0.0:
        return 0.0, 0.0, 0.0
    return F, K * (1.0 + lam * xd / v_app), K * x * lam * (1.0 - dv * xd / v_app) / v_app


@njit(cache=True)
def _impact_state(v0, x0, xd0, x1, xd1, v_min):
    """Approach speed after an accepted step (the rule of ``_Impact.update_internal``)."""
    closed = x1 > 0.0
    opened = x0 <= 0.0                          # start out of contact: interpolate the onset
    den = x0 - x1 if (opened and closed) else -1.0
    theta = x0 / den
    onset = xd0 + theta * (xd1 - xd0) if opened else xd1
    v_app = v0 if v0 > 0.0 else onset
    if not closed:
        return 0.0
    return v_min if v_min > v_app else v_app    # np.maximum(v_app, v_min)


# ----------------------------------------------------------------------------------- race contact
@njit(cache=True)
def _race_out(O, i, Q, delta, Ft, v_s, u, Fx, Fy):
    """Row order of :data:`RACE_OUTPUTS`."""
    O[0, i], O[1, i], O[2, i], O[3, i] = Q, delta, Ft, v_s
    O[4, i], O[5, i], O[6, i] = u, Fx, Fy


RACE_COLS = 9                                   # P columns of a race family without a spall


@njit(cache=True)
def _spall(P, i, R, dx, dy, wx, wy, thb, vb2):
    """The defect's loss of deflection d = h·B(s), its rate h·B'(s)·ṡ, and h·B', h·B'', ṡ for the
    Jacobian (RaceContact._spalled, spall_profile: the reference's operations). s = R·wrap(angle − ψ),
    angle = wrap(atan2(dy, dx) − θ_race)."""
    psi, hi, h, e = P[i, RACE_COLS], P[i, RACE_COLS + 1], P[i, RACE_COLS + 2], P[i, RACE_COLS + 3]
    s = R * _wrap(_wrap(np.arctan2(dy, dx) - thb) - psi)
    s_dot = R * ((dx * wy - dy * wx) / (dx * dx + dy * dy + _ETA2) - vb2)
    x = (hi - abs(s)) / e
    B_ss = 0.0
    if x >= 1.0:
        x = 1.0
    elif x > 0.0:
        B_ss = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / (e * e)
    else:
        x = 0.0
    B = x * x * x * (10.0 + x * (6.0 * x - 15.0))
    u = 1.0 - x
    B_s = (-30.0 * _sign(s) / e) * (x * x * u * u)
    return h * B, h * B_s * s_dot, h * B_s, h * B_ss, s_dot


@njit(cache=True)
def _race_surfaces(R, rho, ex, ey, tx, ty, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, wx, wy):
    """Contact point P = c + R e seen from the roller centre (rr) and from the race body's centre (rb), the
    surfaces' velocities there, their speeds along t, the slip v_s = u_r − u_b, (ṗ − ċ)·t and the rolling
    speed u relative to the moving contact point (the traction laws and the outputs read them)."""
    rl = R - rho
    rrx, rry = rl * ex, rl * ey
    rbx, rby = rcx + R * ex, rcy + R * ey
    Vrx, Vry = vr0 - vr2 * rry, vr1 + vr2 * rrx
    Vbx, Vby = vb0 - vb2 * rby, vb1 + vb2 * rbx
    ur = Vrx * tx + Vry * ty
    ub = Vbx * tx + Vby * ty
    wt = wx * tx + wy * ty
    u = 0.5 * (ur + ub) - (Vcx * tx + Vcy * ty + R * wt / rho)
    return rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, ur - ub, wt, u


# the outputs of RaceContact the compiled kernel gives (rows of O in outputs_race), as the reference names them;
# not its "angle" (an arctan2 per contact, ≈ 4 µs a state for 144 contacts, that nothing reading these needs)
RACE_OUTPUTS = ("load", "deflection", "traction", "slip_velocity", "rolling_speed", "fx", "fy")


@njit(cache=True)
def evaluate_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    _race(ql, vl, P, G, F, Jq, Jv, jac, np.empty((0, 0)))


@njit(cache=True)
def outputs_race(t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs :data:`RACE_OUTPUTS` of every instance into the rows of O (7, n): the force law of
    :func:`evaluate_race`, evaluated once (the reference's outputs; per physical contact)."""
    n = ql.shape[0]
    _race(ql, vl, P, G, np.empty((n, 6)), np.empty((0, 6, 6)), np.empty((0, 6, 6)), False, O)


@njit(cache=True)
def _race(ql, vl, P, G, F, Jq, Jv, jac, O):
    """The race law: forces into F (and Jacobians); with O of 7 rows, the outputs too (else O is (0, 0))."""
    p, law = G[0], int(G[1])
    roll = G.size > _RG                         # rolling resistance (decided at pack time)
    need_u = law != TANH or roll                # the Jacobian needs the rolling speed's differential
    pe = 0.5 * (p - 1.0)                        # exponent of the damping's δ factor
    spall = P.shape[1] > RACE_COLS              # decided at pack time (see the module docstring)
    out = O.shape[0] > 0
    th_last, cth, sth = np.nan, 0.0, 0.0
    for i in range(ql.shape[0]):
        kap, mx, my, R, D, K, c0, mult = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5], P[i, 6], P[i, 7]
        xr, yr = ql[i, 0], ql[i, 1]
        xb, yb, thb = ql[i, 3], ql[i, 4], ql[i, 5]
        vr0, vr1, vr2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vb0, vb1, vb2 = vl[i, 3], vl[i, 4], vl[i, 5]
        # raceway centre c = c_b + rc, roller centre relative to it, normal e and tangent t = k × e
        if thb != th_last:                       # a bearing's contacts follow each other: one race body's angle
            th_last, cth, sth = thb, np.cos(thb), np.sin(thb)
        rcx, rcy = cth * mx - sth * my, sth * mx + cth * my
        dx, dy = xr - (xb + rcx), yr - (yb + rcy)
        rho = np.sqrt(dx * dx + dy * dy + _ETA2)
        ex, ey = dx / rho, dy / rho
        tx, ty = -ey, ex
        delta = 0.5 * D - kap * (rho - R)
        Vcx, Vcy = vb0 - vb2 * rcy, vb1 + vb2 * rcx
        wx, wy = vr0 - Vcx, vr1 - Vcy
        delta_dot = -kap * (ex * wx + ey * wy)
        hBs, hBss, s_dot = 0.0, 0.0, 0.0
        if spall:                                # δ_eff = δ − d(s) and its exact rate
            d_s, d_rate, hBs, hBss, s_dot = _spall(P, i, R, dx, dy, wx, wy, thb, vb2)
            delta, delta_dot = delta - d_s, delta_dot - d_rate
        # Hertz load with contact damping, clipped at >= 0 (ad.where: zero derivative when clipped); the damping
        # times its share S(δ/δ_c) when the instance has a ramp (tooth_pairs.damping_share, the reference's law)
        ramp = P[i, 8]
        Q, dpe, S, dS = 0.0, 0.0, 1.0, 0.0
        if delta > 0.0:
            dpe = delta ** pe
            if ramp > 0.0:
                S, dS = tooth_pairs.damping_share(delta, ramp)
                Q = K * delta ** p + c0 * dpe * S * delta_dot
            else:
                Q = K * delta ** p + c0 * dpe * delta_dot
        if not Q > 0.0:
            _zero(F, Jq, Jv, i, jac)
            if out:                              # no load, no traction; the kinematics as for a loaded one
                k = _race_surfaces(R, rho, ex, ey, tx, ty, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, wx, wy)
                _race_out(O, i, 0.0, delta, 0.0, k[11], k[13], 0.0, 0.0)
            continue
        # contact point, surface speeds, slip and rolling speed (relative to the moving contact point)
        rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, v_s, wt, u = _race_surfaces(
            R, rho, ex, ey, tx, ty, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, wx, wy)
        mu_Q = 0.0
        if law == EHL:                           # the film's law needs the load and the reduced radius
            mu, mu_s, mu_u, mu_Q = _ehl_traction(G, v_s, u, Q, 1.0 / (2.0 / D + kap / R))
        else:
            mu, mu_s, mu_u = _traction(law, G, v_s, u)
        Ft = -mu * Q
        Fx = kap * Q * ex + Ft * tx
        Fy = kap * Q * ey + Ft * ty
        FR, FR_Q, FR_u, a1, g, fRx, fRy, MRr, MRb = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if roll:          # Poiseuille shear at P on both bodies, the pressure's share through each centre
            FR, FR_Q, FR_u = _rolling(G, Q, u, 1.0 / (2.0 / D + kap / R))
            a1 = 2.0 * R / rho
            g = FR * (a1 - 1.0)
            fRx, fRy = g * tx, g * ty
            MRr = (rho - R) * FR
            MRb = -(rcx * fRy - rcy * fRx) - R * FR
            _write(F, Jq, Jv, i, -1, mult, Fx + fRx, Fy + fRy, rrx * Fy - rry * Fx + MRr, -Fx + -fRx, -Fy + -fRy,
                   rbx * (-Fy) - rby * (-Fx) + MRb)
        else:
            _write(F, Jq, Jv, i, -1, mult, Fx, Fy, rrx * Fy - rry * Fx, -Fx, -Fy, rbx * (-Fy) - rby * (-Fx))
        if out:
            _race_out(O, i, Q, delta, Ft, v_s, u, Fx, Fy)
        if not jac:
            continue
        Q_d = K * p * delta ** (p - 1.0) + c0 * pe * delta ** (pe - 1.0) * delta_dot   # ∂Q/∂δ
        Q_r = c0 * dpe                                                                  # ∂Q/∂δ̇
        if ramp > 0.0:
            Q_d = K * p * delta ** (p - 1.0) + c0 * (pe * delta ** (pe - 1.0) * S + dpe * dS) * delta_dot
            Q_r = c0 * dpe * S
        rho2 = dx * dx + dy * dy + _ETA2
        num = dx * wy - dy * wx
        # Positions: the law sees the roller's and the race body's centres only through (dx, dy), so a shift of the
        # race body is a shift of the roller reversed (J_q columns 3, 4 = −columns 0, 1, exactly), and not the
        # roller's angle (column 2 = 0); only θ_race also turns the marker. No velocity moves along these.
        for j in (0, 1, 5):
            dxr, dyr, dthb = _u(j, 0), _u(j, 1), _u(j, 5)
            drcx, drcy = -dthb * rcy, dthb * rcx
            ddx, ddy = dxr - drcx, dyr - drcy
            drho = (dx * ddx + dy * ddy) / rho
            dex, dey = (ddx - ex * drho) / rho, (ddy - ey * drho) / rho
            dtx, dty = -dey, dex
            dVcx, dVcy = -vb2 * drcy, vb2 * drcx
            dwx, dwy = -dVcx, -dVcy
            ddelta = -kap * drho
            ddelta_dot = -kap * (dex * wx + ex * dwx + dey * wy + ey * dwy)
            if spall:                            # chain rule through s (the marker turns with θ_race too)
                ds = R * ((dx * ddy - dy * ddx) / (dx * dx + dy * dy) - dthb)     # ad.arctan2: no η
                dnum = ddx * wy + dx * dwy - ddy * wx - dy * dwx
                ds_dot = R * ((dnum - num * 2.0 * (dx * ddx + dy * ddy) / rho2) / rho2)
                ddelta -= hBs * ds
                ddelta_dot -= hBss * ds * s_dot + hBs * ds_dot
            dQ = Q_d * ddelta + Q_r * ddelta_dot
            drrx, drry = -drho * ex + rl * dex, -drho * ey + rl * dey
            drbx, drby = drcx + R * dex, drcy + R * dey
            dVrx, dVry = -vr2 * drry, vr2 * drrx
            dVbx, dVby = -vb2 * drby, vb2 * drbx
            dur = dVrx * tx + Vrx * dtx + dVry * ty + Vry * dty
            dub = dVbx * tx + Vbx * dtx + dVby * ty + Vby * dty
            dmu = mu_s * (dur - dub) + mu_Q * dQ
            du = 0.0
            if need_u:
                dwt = dwx * tx + wx * dtx + dwy * ty + wy * dty
                dvP = dVcx * tx + Vcx * dtx + dVcy * ty + Vcy * dty + R * (dwt - wt * drho / rho) / rho
                du = 0.5 * (dur + dub) - dvP
                if law != TANH:
                    dmu += mu_u * du
            dFt = -(dmu * Q + mu * dQ)
            dFx = kap * (dQ * ex + Q * dex) + dFt * tx + Ft * dtx
            dFy = kap * (dQ * ey + Q * dey) + dFt * ty + Ft * dty
            dMr = _d_cross(rrx, rry, drrx, drry, Fx, Fy, dFx, dFy)
            dMb = -_d_cross(rbx, rby, drbx, drby, Fx, Fy, dFx, dFy)
            if roll:
                dFR = FR_Q * dQ + FR_u * du
                dg = dFR * (a1 - 1.0) - FR * 2.0 * R * drho / (rho * rho)
                dfRx, dfRy = dg * tx + g * dtx, dg * ty + g * dty
                dFx, dFy = dFx + dfRx, dFy + dfRy
                dMr += drho * FR + (rho - R) * dFR
                dMb += -_d_cross(rcx, rcy, drcx, drcy, fRx, fRy, dfRx, dfRy) - R * dFR
            _write(F, Jq, Jv, i, j, mult, dFx, dFy, dMr, -dFx, -dFy, dMb)
            if j < 2:
                _write(F, Jq, Jv, i, j + 3, mult, -dFx, -dFy, -dMr, dFx, dFy, -dMb)
        _write(F, Jq, Jv, i, 2, mult, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        # Velocities: they move δ̇ and the surface speeds only (not ρ, e, t or the contact point)
        for j in range(6, 12):
            dvr0, dvr1, dvr2, dvb0, dvb1, dvb2 = _u(j, 6), _u(j, 7), _u(j, 8), _u(j, 9), _u(j, 10), _u(j, 11)
            dVcx, dVcy = dvb0 - dvb2 * rcy, dvb1 + dvb2 * rcx
            dwx, dwy = dvr0 - dVcx, dvr1 - dVcy
            ddelta_dot = -kap * (ex * dwx + ey * dwy)
            if spall:
                ddelta_dot -= hBs * (R * ((dx * dwy - dy * dwx) / rho2 - dvb2))
            dQ = Q_r * ddelta_dot
            dVrx, dVry = dvr0 - dvr2 * rry, dvr1 + dvr2 * rrx
            dVbx, dVby = dvb0 - dvb2 * rby, dvb1 + dvb2 * rbx
            dur = dVrx * tx + dVry * ty
            dub = dVbx * tx + dVby * ty
            dmu = mu_s * (dur - dub) + mu_Q * dQ
            du = 0.0
            if need_u:
                dvP = dVcx * tx + dVcy * ty + R * (dwx * tx + dwy * ty) / rho
                du = 0.5 * (dur + dub) - dvP
                if law != TANH:
                    dmu += mu_u * du
            dFt = -(dmu * Q + mu * dQ)
            dFx = kap * (dQ * ex) + dFt * tx
            dFy = kap * (dQ * ey) + dFt * ty
            dMr, dMb = rrx * dFy - rry * dFx, -(rbx * dFy - rby * dFx)
            if roll:         # velocities leave ρ, t and the markers: only F_R moves
                dFR = FR_Q * dQ + FR_u * du
                dfRx, dfRy = dFR * (a1 - 1.0) * tx, dFR * (a1 - 1.0) * ty
                dFx, dFy = dFx + dfRx, dFy + dfRy
                dMr += (rho - R) * dFR
                dMb += -(rcx * dfRy - rcy * dfRx) - R * dFR
            _write(F, Jq, Jv, i, j, mult, dFx, dFy, dMr, -dFx, -dFy, dMb)


# ----------------------------------------------------------------------------------- pocket contact
@njit(cache=True)
def _pocket_gap(xr, yr, xg, yg, thg, vr0, vr1, vg0, vg1, vg2, psi, rm, clearance):
    """Pocket geometry (PocketContact._geometry): dx, dy, ρ², s, wx, wy, penetration d, rate ḋ."""
    dx, dy = xr - xg, yr - yg
    rho2 = dx * dx + dy * dy + _ETA2
    s = rm * _wrap(np.arctan2(dy, dx) - thg - psi)
    wx, wy = vr0 - vg0, vr1 - vg1
    s_dot = rm * ((dx * wy - dy * wx) / rho2 - vg2)
    return dx, dy, rho2, s, wx, wy, abs(s) - clearance, _sign(s) * s_dot


# the outputs of PocketContact the compiled kernel gives (rows of O in outputs_pocket), as the reference names them
POCKET_OUTPUTS = ("force", "offset", "penetration", "penetration_rate", "approach_speed")


@njit(cache=True)
def evaluate_pocket(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    _pocket(ql, vl, z, P, F, Jq, Jv, jac, np.empty((0, 0)))


@njit(cache=True)
def outputs_pocket(t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs :data:`POCKET_OUTPUTS` into the rows of O (5, n), by the law of :func:`evaluate_pocket`."""
    n = ql.shape[0]
    _pocket(ql, vl, z, P, np.empty((n, 6)), np.empty((0, 6, 6)), np.empty((0, 6, 6)), False, O)


@njit(cache=True)
def _pocket(ql, vl, z, P, F, Jq, Jv, jac, O):
    """The pocket law: forces into F (and Jacobians); with O of 5 rows, the outputs too (else O is (0, 0))."""
    out = O.shape[0] > 0
    for i in range(ql.shape[0]):
        psi, rm, clr, Kp, lam, v_min = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5]
        mu, v_mu, D, mult = P[i, 6], P[i, 7], P[i, 8], P[i, 9]
        xr, yr, xg, yg, thg = ql[i, 0], ql[i, 1], ql[i, 3], ql[i, 4], ql[i, 5]
        vr0, vr1, vr2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vg0, vg1, vg2 = vl[i, 3], vl[i, 4], vl[i, 5]
        dx, dy, rho2, s, wx, wy, pen, pen_dot = _pocket_gap(xr, yr, xg, yg, thg, vr0, vr1, vg0, vg1, vg2, psi,
                                                            rm, clr)
        Fi, F_x, F_xd = _impact(Kp, lam, v_min, pen, pen_dot, z[i, 0])
        sg = _sign(s)
        Fs = Fi * sg
        if out:            # (the reference's v₀ in use is 0 where the pocket is open)
            touch = pen > 0.0
            O[0, i], O[1, i], O[2, i], O[3, i] = Fs, s, pen if touch else 0.0, pen_dot
            O[4, i] = _approach(v_min, pen_dot, z[i, 0])[0] if touch else 0.0
        if Fi == 0.0:
            _zero(F, Jq, Jv, i, jac)
            continue
        # potential form −Fs ∂s/∂q: ∂s/∂p = rm (−dy, dx)/ρ² = (gx, gy)
        gx, gy = rm * (-dy) / rho2, rm * dx / rho2
        fnx, fny = -Fs * gx, -Fs * gy
        # wall friction at the roller's contact point with the wall: r_w from the roller, r_g from the cage
        rho = np.sqrt(rho2)
        ex, ey = dx / rho, dy / rho
        half = 0.5 * D * sg
        rwx, rwy = -half * ey, half * ex
        rgx, rgy = dx + rwx, dy + rwy
        Vrx, Vry = vr0 - vr2 * rwy, vr1 + vr2 * rwx
        Vgx, Vgy = vg0 - vg2 * rgy, vg1 + vg2 * rgx
        v_rad = (Vrx - Vgx) * ex + (Vry - Vgy) * ey
        th = np.tanh(v_rad / v_mu)
        f = -mu * th * Fi
        fx, fy = f * ex, f * ey
        _write(F, Jq, Jv, i, -1, mult, fnx + fx, fny + fy, rwx * fy - rwy * fx, -fnx - fx, -fny - fy,
               Fs * rm + (rgx * (-fy) - rgy * (-fx)))
        if not jac:
            continue
        r2 = dx * dx + dy * dy                   # ad.arctan2's derivative: no η
        num = dx * wy - dy * wx
        f_v = -mu * (1.0 - th * th) / v_mu * Fi  # ∂f/∂v_rad
        for j in range(12):
            if j == 2 or j == 3 or j == 4 or j == 9 or j == 10:     # _mirror_cols: the roller's angle, the cage's
                continue                                              # translations
            dxr, dyr, _, dxg, dyg, dthg, dvr0, dvr1, dvr2, dvg0, dvg1, dvg2 = _unit(j)
            ddx, ddy = dxr - dxg, dyr - dyg
            ds = rm * (ddy * (dx / r2) - ddx * (dy / r2) - dthg)
            drho2 = 2.0 * (dx * ddx + dy * ddy)
            dwx, dwy = dvr0 - dvg0, dvr1 - dvg1
            dnum = ddx * wy + dx * dwy - ddy * wx - dy * dwx
            ds_dot = rm * ((dnum - num * drho2 / rho2) / rho2 - dvg2)
            dFi = F_x * sg * ds + F_xd * sg * ds_dot       # d = |s| − C, ḋ = sign(s)·ṡ
            dFs = dFi * sg
            dgx, dgy = (-rm * ddy - gx * drho2) / rho2, (rm * ddx - gy * drho2) / rho2
            dfnx, dfny = -(dFs * gx + Fs * dgx), -(dFs * gy + Fs * dgy)
            drho = 0.5 * drho2 / rho
            dex, dey = (ddx - ex * drho) / rho, (ddy - ey * drho) / rho
            drwx, drwy = -half * dey, half * dex
            drgx, drgy = ddx + drwx, ddy + drwy
            dVrx, dVry = dvr0 - dvr2 * rwy - vr2 * drwy, dvr1 + dvr2 * rwx + vr2 * drwx
            dVgx, dVgy = dvg0 - dvg2 * rgy - vg2 * drgy, dvg1 + dvg2 * rgx + vg2 * drgx
            dv_rad = (dVrx - dVgx) * ex + (Vrx - Vgx) * dex + (dVry - dVgy) * ey + (Vry - Vgy) * dey
            df = f_v * dv_rad - mu * th * dFi
            dfx, dfy = df * ex + f * dex, df * ey + f * dey
            _write(F, Jq, Jv, i, j, mult, dfnx + dfx, dfny + dfy, _d_cross(rwx, rwy, drwx, drwy, fx, fy, dfx, dfy),
                   -dfnx - dfx, -dfny - dfy, dFs * rm - _d_cross(rgx, rgy, drgx, drgy, fx, fy, dfx, dfy))
        _mirror_cols(Jq, Jv, i)


@njit(cache=True)
def update_pocket(z, t0, t1, ql0, vl0, ql1, vl1, P, G):
    n = z.shape[0]
    z1 = np.empty((n, 4))
    for i in range(n):
        psi, rm, clr, v_min = P[i, 0], P[i, 1], P[i, 2], P[i, 5]
        g1 = _pocket_gap(ql1[i, 0], ql1[i, 1], ql1[i, 3], ql1[i, 4], ql1[i, 5], vl1[i, 0], vl1[i, 1],
                         vl1[i, 3], vl1[i, 4], vl1[i, 5], psi, rm, clr)
        x1, xd1 = g1[6], g1[7]
        x0, xd0 = z[i, 1], z[i, 2]
        if not z[i, 3] > 0:                      # first step: the start state is not cached
            g0 = _pocket_gap(ql0[i, 0], ql0[i, 1], ql0[i, 3], ql0[i, 4], ql0[i, 5], vl0[i, 0], vl0[i, 1],
                             vl0[i, 3], vl0[i, 4], vl0[i, 5], psi, rm, clr)
            x0, xd0 = g0[6], g0[7]
        z1[i, 0] = _impact_state(z[i, 0], x0, xd0, x1, xd1, v_min)
        z1[i, 1], z1[i, 2], z1[i, 3] = x1, xd1, 1.0
    return z1


# ----------------------------------------------------------------------------------- pocket retention
@njit(cache=True)
def _retention_gap(xr, yr, xg, yg, vr0, vr1, vg0, vg1, rm, clearance):
    """Retention geometry (PocketRetention._geometry): dx, dy, ρ, u, wx, wy, penetration x, rate ẋ."""
    dx, dy = xr - xg, yr - yg
    rho = np.sqrt(dx * dx + dy * dy + _ETA2)
    u = rho - rm
    wx, wy = vr0 - vg0, vr1 - vg1
    rho_dot = (dx * wx + dy * wy) / rho
    return dx, dy, rho, u, wx, wy, abs(u) - clearance, _sign(u) * rho_dot


# the outputs of PocketRetention the compiled kernel gives (rows of O in outputs_retention), as the reference names them
RETENTION_OUTPUTS = ("force", "offset", "penetration", "penetration_rate", "approach_speed", "friction")


@njit(cache=True)
def evaluate_retention(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    _retention(ql, vl, z, P, F, Jq, Jv, jac, np.empty((0, 0)))


@njit(cache=True)
def outputs_retention(t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs :data:`RETENTION_OUTPUTS` into the rows of O (6, n), by the law of :func:`evaluate_retention`."""
    n = ql.shape[0]
    _retention(ql, vl, z, P, np.empty((n, 6)), np.empty((0, 6, 6)), np.empty((0, 6, 6)), False, O)


@njit(cache=True)
def _retention(ql, vl, z, P, F, Jq, Jv, jac, O):
    """The retention law: forces into F (and Jacobians); with O of 6 rows, the outputs too (else O is (0, 0))."""
    out = O.shape[0] > 0
    for i in range(ql.shape[0]):
        rm, clr, Kr, lam, v_min = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4]
        mu, v_mu, D, mult = P[i, 5], P[i, 6], P[i, 7], P[i, 8]
        vr0, vr1, vr2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vg0, vg1, vg2 = vl[i, 3], vl[i, 4], vl[i, 5]
        dx, dy, rho, u, wx, wy, pen, pen_dot = _retention_gap(ql[i, 0], ql[i, 1], ql[i, 3], ql[i, 4], vr0, vr1,
                                                              vg0, vg1, rm, clr)
        Fi, F_x, F_xd = _impact(Kr, lam, v_min, pen, pen_dot, z[i, 0])
        sg = _sign(u)
        Fu = Fi * sg
        ex, ey = dx / rho, dy / rho
        half = 0.5 * D * sg
        rwx, rwy = half * ex, half * ey
        rgx, rgy = dx + rwx, dy + rwy
        tx, ty = -ey, ex
        Vrx, Vry = vr0 - vr2 * rwy, vr1 + vr2 * rwx
        Vgx, Vgy = vg0 - vg2 * rgy, vg1 + vg2 * rgx
        v_t = (Vrx - Vgx) * tx + (Vry - Vgy) * ty
        th = np.tanh(v_t / v_mu)
        f = -mu * th * Fi
        if out:            # (the reference's v₀ in use is 0 where the pocket is open)
            touch = pen > 0.0
            O[0, i], O[1, i], O[2, i], O[3, i] = Fu, u, pen if touch else 0.0, pen_dot
            O[4, i] = _approach(v_min, pen_dot, z[i, 0])[0] if touch else 0.0
            O[5, i] = f
        if Fi == 0.0:
            _zero(F, Jq, Jv, i, jac)
            continue
        fnx, fny = -Fu * ex, -Fu * ey
        fx, fy = f * tx, f * ty
        _write(F, Jq, Jv, i, -1, mult, fnx + fx, fny + fy, rwx * fy - rwy * fx, -fnx - fx, -fny - fy,
               rgx * (-fy) - rgy * (-fx))
        if not jac:
            continue
        rho_dot = sg * pen_dot
        f_v = -mu * (1.0 - th * th) / v_mu * Fi  # ∂f/∂v_t
        for j in range(12):
            dxr, dyr, _, dxg, dyg, _, dvr0, dvr1, dvr2, dvg0, dvg1, dvg2 = _unit(j)
            ddx, ddy = dxr - dxg, dyr - dyg
            drho = (dx * ddx + dy * ddy) / rho
            dwx, dwy = dvr0 - dvg0, dvr1 - dvg1
            drho_dot = (ddx * wx + dx * dwx + ddy * wy + dy * dwy - rho_dot * drho) / rho
            dFi = F_x * sg * drho + F_xd * sg * drho_dot          # x = |u| − C, ẋ = sign(u)·ρ̇
            dFu = dFi * sg
            dex, dey = (ddx - ex * drho) / rho, (ddy - ey * drho) / rho
            dfnx, dfny = -(dFu * ex + Fu * dex), -(dFu * ey + Fu * dey)
            drwx, drwy = half * dex, half * dey
            drgx, drgy = ddx + drwx, ddy + drwy
            dtx, dty = -dey, dex
            dVrx, dVry = dvr0 - dvr2 * rwy - vr2 * drwy, dvr1 + dvr2 * rwx + vr2 * drwx
            dVgx, dVgy = dvg0 - dvg2 * rgy - vg2 * drgy, dvg1 + dvg2 * rgx + vg2 * drgx
            dv_t = (dVrx - dVgx) * tx + (Vrx - Vgx) * dtx + (dVry - dVgy) * ty + (Vry - Vgy) * dty
            df = f_v * dv_t - mu * th * dFi
            dfx, dfy = df * tx + f * dtx, df * ty + f * dty
            _write(F, Jq, Jv, i, j, mult, dfnx + dfx, dfny + dfy, _d_cross(rwx, rwy, drwx, drwy, fx, fy, dfx, dfy),
                   -dfnx - dfx, -dfny - dfy, -_d_cross(rgx, rgy, drgx, drgy, fx, fy, dfx, dfy))


@njit(cache=True)
def update_retention(z, t0, t1, ql0, vl0, ql1, vl1, P, G):
    n = z.shape[0]
    z1 = np.empty((n, 4))
    for i in range(n):
        rm, clr, v_min = P[i, 0], P[i, 1], P[i, 4]
        g1 = _retention_gap(ql1[i, 0], ql1[i, 1], ql1[i, 3], ql1[i, 4], vl1[i, 0], vl1[i, 1], vl1[i, 3],
                            vl1[i, 4], rm, clr)
        x1, xd1 = g1[6], g1[7]
        x0, xd0 = z[i, 1], z[i, 2]
        if not z[i, 3] > 0:                      # first step: the start state is not cached
            g0 = _retention_gap(ql0[i, 0], ql0[i, 1], ql0[i, 3], ql0[i, 4], vl0[i, 0], vl0[i, 1], vl0[i, 3],
                                vl0[i, 4], rm, clr)
            x0, xd0 = g0[6], g0[7]
        z1[i, 0] = _impact_state(z[i, 0], x0, xd0, x1, xd1, v_min)
        z1[i, 1], z1[i, 2], z1[i, 3] = x1, xd1, 1.0
    return z1


# ----------------------------------------------------------------------------------- guide contact
@njit(cache=True)
def _guide_gap(xg, yg, xo, yo, vg0, vg1, vo0, vo1, clearance):
    """Guide geometry (GuideContact._geometry): e = c_g − c_o, ε, n = e/ε, penetration x, rate ε̇."""
    ex, ey = xg - xo, yg - yo
    eps = np.sqrt(ex * ex + ey * ey + _ETA2)
    nx, ny = ex / eps, ey / eps
    return ex, ey, eps, nx, ny, eps - clearance, nx * (vg0 - vo0) + ny * (vg1 - vo1)


@njit(cache=True)
def _film(C, eta, width, min_film, R, ex, ey, e_abs, wx, wy, w_g, w_o, v_t):
    """HydrodynamicLand.film (the reference's operations, with ε·φ̇ and ε²·φ̇ from e × ė): F_n, F_t, the
    shear, and the intermediates its differentials need."""
    cap = 1.0 - min_film / C
    r_raw = e_abs / C
    act = r_raw < cap
    r = r_raw if act else cap
    rdot = (ex * wx + ey * wy) / (e_abs * C) if act else 0.0
    cross = ex * wy - ey * wx
    spin = w_g + w_o
    sgn = 1.0 if spin >= 0.0 else -1.0
    scale = 1.0 if act else cap / r_raw
    e_w = sgn * (r * spin - 2.0 * scale * cross / (e_abs * C))
    e2_w = sgn * (r * r * spin - 2.0 * scale * scale * cross / (C * C))
    K0 = eta * R * width ** 3 / (2.0 * C * C)
    s = 1.0 - r * r
    ss = np.sqrt(s)
    Fn = -1.0 * K0 * (2.0 * e2_w / (s * s) + np.pi * (1.0 + 2.0 * r * r) * rdot / (s * s * ss))
    Ft = sgn * K0 * (np.pi * e_w / (2.0 * s * ss) + 4.0 * r * rdot / (s * s))
    ks = eta * (2.0 * np.pi * R * width) / C
    sh = -1.0 * v_t * ks / ss
    return Fn, Ft, sh, r, rdot, sgn, cross, spin, scale, e_w, e2_w, s, act, K0, ks, cap, r_raw


@njit(cache=True)
def _dfilm(film, ex, ey, e_abs, wx, wy, dex, dey, de_abs, dwx, dwy, dw_g, dw_o, v_t, dv_t, C):
    """Differentials of (F_n, F_t, shear) along one direction (inputs' differentials given)."""
    Fn, Ft, sh, r, rdot, sgn, cross, spin, scale, e_w, e2_w, s, act, K0, ks, cap, r_raw = film
    dr = de_abs / C if act else 0.0
    drdot = ((dex * wx + ex * dwx + dey * wy + ey * dwy) / (e_abs * C) - rdot * de_abs / e_abs) if act else 0.0
    dcross = dex * wy + ex * dwy - dey * wx - ey * dwx
    dspin = dw_g + dw_o
    dscale = 0.0 if act else -cap * (de_abs / C) / (r_raw * r_raw)
    de_w = sgn * (dr * spin + r * dspin - 2.0 * (dscale * cross / (e_abs * C) + scale * dcross / (e_abs * C)
                                                 - scale * cross * de_abs / (e_abs * e_abs * C)))
    de2_w = sgn * (2.0 * r * dr * spin + r * r * dspin - 2.0 * (2.0 * scale * dscale * cross + scale * scale * dcross)
                   / (C * C))
    ds = -2.0 * r * dr
    ss = np.sqrt(s)
    dA = 2.0 * de2_w / (s * s) - 4.0 * e2_w * ds / (s * s * s)
    dB = np.pi * (4.0 * r * dr * rdot + (1.0 + 2.0 * r * r) * drdot) / (s * s * ss) \
        - 2.5 * np.pi * (1.0 + 2.0 * r * r) * rdot * ds / (s * s * s * ss)
    dCc = np.pi * de_w / (2.0 * s * ss) - 1.5 * np.pi * e_w * ds / (2.0 * s * s * ss)
    dDd = 4.0 * (dr * rdot + r * drdot) / (s * s) - 8.0 * r * rdot * ds / (s * s * s)
    dsh = -1.0 * ks * (dv_t / ss - 0.5 * v_t * ds / (s * ss))
    return -1.0 * K0 * (dA + dB), sgn * K0 * (dCc + dDd), dsh


# the outputs of GuideContact the compiled kernel gives (rows of O in outputs_guide), as the reference names them
GUIDE_OUTPUTS = ("force", "eccentricity", "friction", "fx", "fy", "sliding_speed", "penetration_rate",
                 "approach_speed")


@njit(cache=True)
def evaluate_guide(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    _guide(ql, vl, z, P, G, F, Jq, Jv, jac, np.empty((0, 0)))


@njit(cache=True)
def outputs_guide(t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs :data:`GUIDE_OUTPUTS` into the rows of O (8, n), by the law of :func:`evaluate_guide`."""
    n = ql.shape[0]
    _guide(ql, vl, z, P, G, np.empty((n, 6)), np.empty((0, 6, 6)), np.empty((0, 6, 6)), False, O)


@njit(cache=True)
def _guide(ql, vl, z, P, G, F, Jq, Jv, jac, O):
    """The guide law: forces into F (and Jacobians); with O of 8 rows, the outputs too (else O is (0, 0))."""
    hydro = G.size > 0 and G[0] == 1.0
    out = O.shape[0] > 0
    for i in range(ql.shape[0]):
        clr, Kg, lam, v_min, mu, v_mu, rL = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5], P[i, 6]
        vg0, vg1, vg2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vo0, vo1, vo2 = vl[i, 3], vl[i, 4], vl[i, 5]
        ex, ey, eps, nx, ny, pen, eps_dot = _guide_gap(ql[i, 0], ql[i, 1], ql[i, 3], ql[i, 4], vg0, vg1, vo0,
                                                       vo1, clr)
        Fi, F_x, F_xd = _impact(Kg, lam, v_min, pen, eps_dot, z[i, 0])
        if Fi == 0.0 and not hydro and not out:     # (the outputs need the sliding speed all the same)
            _zero(F, Jq, Jv, i, jac)
            continue
        tx, ty = -ny, nx
        # land contact point from the cage centre (rg) and from the planet's (ro)
        rgx, rgy = rL * nx, rL * ny
        rox, roy = ex + rgx, ey + rgy
        Vgx, Vgy = vg0 - vg2 * rgy, vg1 + vg2 * rgx
        Vox, Voy = vo0 - vo2 * roy, vo1 + vo2 * rox
        v_t = (Vgx - Vox) * tx + (Vgy - Voy) * ty
        th = np.tanh(v_t / v_mu)
        fr = -mu * th * Fi
        wx, wy = vg0 - vo0, vg1 - vo1
        Fn_f, Ft_f, sh = 0.0, 0.0, 0.0
        if hydro:      # the oil film carries the cage; its shear adds to the friction (docs/model.md §9.4)
            film = _film(clr, G[1], G[2], G[3], rL, ex, ey, eps, wx, wy, vg2, vo2, v_t)
            Fn_f, Ft_f, sh = film[0], film[1], film[2]
        Fnt, Ftt = -Fi + Fn_f, fr + sh + Ft_f
        Fx = Fnt * nx + Ftt * tx
        Fy = Fnt * ny + Ftt * ty
        _write(F, Jq, Jv, i, -1, 1.0, Fx, Fy, rgx * Fy - rgy * Fx, -Fx, -Fy, rox * (-Fy) - roy * (-Fx))
        if out:            # the impact force, the land's friction with the film's shear, the force on the cage
            O[0, i], O[1, i], O[2, i], O[3, i], O[4, i] = Fi, np.hypot(ex, ey), fr + sh, Fx, Fy
            O[5, i], O[6, i] = v_t, eps_dot
            O[7, i] = _approach(v_min, eps_dot, z[i, 0])[0] if pen > 0.0 else 0.0
        if not jac:
            continue
        f_v = -mu * (1.0 - th * th) / v_mu * Fi  # ∂fr/∂v_t
        for j in range(12):
            dxg, dyg, _, dxo, dyo, _, dvg0, dvg1, dvg2, dvo0, dvo1, dvo2 = _unit(j)
            dex, dey = dxg - dxo, dyg - dyo
            deps = (ex * dex + ey * dey) / eps
            dnx, dny = (dex - nx * deps) / eps, (dey - ny * deps) / eps
            dwx, dwy = dvg0 - dvo0, dvg1 - dvo1
            deps_dot = dnx * wx + nx * dwx + dny * wy + ny * dwy
            dFi = F_x * deps + F_xd * deps_dot
            dtx, dty = -dny, dnx
            drgx, drgy = rL * dnx, rL * dny
            drox, droy = dex + drgx, dey + drgy
            dVgx, dVgy = dvg0 - dvg2 * rgy - vg2 * drgy, dvg1 + dvg2 * rgx + vg2 * drgx
            dVox, dVoy = dvo0 - dvo2 * roy - vo2 * droy, dvo1 + dvo2 * rox + vo2 * drox
            dv_t = (dVgx - dVox) * tx + (Vgx - Vox) * dtx + (dVgy - dVoy) * ty + (Vgy - Voy) * dty
            dfr = f_v * dv_t - mu * th * dFi
            dFn_f, dFt_f, dsh = 0.0, 0.0, 0.0
            if hydro:
                dFn_f, dFt_f, dsh = _dfilm(film, ex, ey, eps, wx, wy, dex, dey, deps, dwx, dwy, dvg2, dvo2, v_t,
                                           dv_t, clr)
            dFnt, dFtt = -dFi + dFn_f, dfr + dsh + dFt_f
            dFx = dFnt * nx + Fnt * dnx + dFtt * tx + Ftt * dtx
            dFy = dFnt * ny + Fnt * dny + dFtt * ty + Ftt * dty
            _write(F, Jq, Jv, i, j, 1.0, dFx, dFy, _d_cross(rgx, rgy, drgx, drgy, Fx, Fy, dFx, dFy),
                   -dFx, -dFy, -_d_cross(rox, roy, drox, droy, Fx, Fy, dFx, dFy))


@njit(cache=True)
def update_guide(z, t0, t1, ql0, vl0, ql1, vl1, P, G):
    n = z.shape[0]
    z1 = np.empty((n, 4))
    for i in range(n):
        clr, v_min = P[i, 0], P[i, 3]
        g1 = _guide_gap(ql1[i, 0], ql1[i, 1], ql1[i, 3], ql1[i, 4], vl1[i, 0], vl1[i, 1], vl1[i, 3], vl1[i, 4], clr)
        x1, xd1 = g1[5], g1[6]
        x0, xd0 = z[i, 1], z[i, 2]
        if not z[i, 3] > 0:                      # first step: the start state is not cached
            g0 = _guide_gap(ql0[i, 0], ql0[i, 1], ql0[i, 3], ql0[i, 4], vl0[i, 0], vl0[i, 1], vl0[i, 3],
                            vl0[i, 4], clr)
            x0, xd0 = g0[5], g0[6]
        z1[i, 0] = _impact_state(z[i, 0], x0, xd0, x1, xd1, v_min)
        z1[i, 1], z1[i, 2], z1[i, 3] = x1, xd1, 1.0
    return z1


# ----------------------------------------------------------------------------------- lubricant drag
@njit(cache=True)
def evaluate_drag(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    visc = P.shape[1] > 4                       # viscous churning (decided at pack time)
    th_last, cth, sth = np.nan, 0.0, 0.0
    for i in range(ql.shape[0]):
        mx, my, coef, mult = P[i, 0], P[i, 1], P[i, 2], P[i, 3]
        xr, yr = ql[i, 0], ql[i, 1]
        xb, yb, thb = ql[i, 3], ql[i, 4], ql[i, 5]
        vr0, vr1 = vl[i, 0], vl[i, 1]
        vb0, vb1, vb2 = vl[i, 3], vl[i, 4], vl[i, 5]
        if thb != th_last:                       # the race body's angle repeats along a bearing's rollers
            th_last, cth, sth = thb, np.cos(thb), np.sin(thb)
        rcx, rcy = cth * mx - sth * my, sth * mx + cth * my
        dx, dy = xr - (xb + rcx), yr - (yb + rcy)
        rho2 = dx * dx + dy * dy + _ETA2
        rho = np.sqrt(rho2)
        Vcx, Vcy = vb0 - vb2 * rcy, vb1 + vb2 * rcx
        wx, wy = vr0 - Vcx, vr1 - Vcy
        num = dx * wy - dy * wx
        om = num / rho2 - vb2                   # orbital speed relative to the race body
        Fd = coef * om * abs(om)
        cs, Ms, Fd_om = 0.0, 0.0, 2.0 * coef * abs(om)    # d(Ω|Ω|)/dΩ = 2|Ω|
        if visc:         # C_D(Re) of the orbit: sign(Ω)|Ω|^(4/3); the spin's viscous moment
            cv, cs = P[i, 4], P[i, 5]
            a43 = abs(om) ** (4.0 / 3.0)
            Fd = Fd + cv * _sign(om) * a43
            Fd_om += cv * (4.0 / 3.0) * abs(om) ** (1.0 / 3.0)
            Ms = -cs * (vl[i, 2] - vb2)
        Fx, Fy = Fd * dy / rho, -Fd * dx / rho   # −Fd·t at the roller centre
        px, py = rcx + dx, rcy + dy              # roller centre from the race body's centre
        if visc:
            _write(F, Jq, Jv, i, -1, mult, Fx, Fy, Ms, -Fx, -Fy, px * (-Fy) - py * (-Fx) - Ms)
        else:
            _write(F, Jq, Jv, i, -1, mult, Fx, Fy, 0.0, -Fx, -Fy, px * (-Fy) - py * (-Fx))
        if not jac:
            continue
        for j in range(12):
            if j == 2 or j == 3 or j == 4 or j == 9 or j == 10 or (j == 8 and not visc):    # _mirror_cols
                continue
            dxr, dyr, _, dxb, dyb, dthb, dvr0, dvr1, dvr2, dvb0, dvb1, dvb2 = _unit(j)
            drcx, drcy = -dthb * rcy, dthb * rcx
            ddx, ddy = dxr - dxb - drcx, dyr - dyb - drcy
            drho2 = 2.0 * (dx * ddx + dy * ddy)
            drho = 0.5 * drho2 / rho
            dVcx, dVcy = dvb0 - dvb2 * rcy - vb2 * drcy, dvb1 + dvb2 * rcx + vb2 * drcx
            dwx, dwy = dvr0 - dVcx, dvr1 - dVcy
            dnum = ddx * wy + dx * dwy - ddy * wx - dy * dwx
            dFd = Fd_om * ((dnum - num * drho2 / rho2) / rho2 - dvb2)
            dFx = (dFd * dy + Fd * ddy - Fx * drho) / rho
            dFy = (-dFd * dx - Fd * ddx - Fy * drho) / rho
            dMb = -_d_cross(px, py, drcx + ddx, drcy + ddy, Fx, Fy, dFx, dFy)
            if visc:
                dMs = -cs * (dvr2 - dvb2)
                _write(F, Jq, Jv, i, j, mult, dFx, dFy, dMs, -dFx, -dFy, dMb - dMs)
            else:
                _write(F, Jq, Jv, i, j, mult, dFx, dFy, 0.0, -dFx, -dFy, dMb)
        _mirror_cols(Jq, Jv, i)
        if not visc:                             # the roller's spin moves no force without the viscous moment
            for a in range(6):
                Jv[i, a, 2] = 0.0



# ----------------------------------------------------------------------------------- pocket film, cage drag
# ``PocketFilm`` P (n, 8): pocket_angle ψ, pitch_radius, clearance C_p, D, η·l, min_film, multiplicity, 0;  G (0,)
# ``CageDrag``   P (n, 1): coef (of sign(Δω)|Δω|^(3/2));  G (0,)
# (mbd.elements.pocket_film; stateless, no compiled outputs: theirs come from the numpy kernels)
_PF_W, _PF_S = pocket_film.WEDGE_LOAD, pocket_film.SQUEEZE_LOAD
_PF_C, _PF_P = pocket_film.COUETTE_EXTENT, pocket_film.POISEUILLE_SHEAR


def pack_pocket_film(elem):
    _require(elem, pocket_film.PocketFilm)
    P = _rows(elem.pocket_angle, elem.pitch_radius, elem.clearance, elem.D, elem.eta * elem.length, elem.min_film,
              elem.multiplicity, np.zeros(elem.n))
    return P, np.zeros(0)


def pack_cage_drag(elem):
    _require(elem, pocket_film.CageDrag)
    return _rows(elem.coef), np.zeros(0)


@njit(cache=True)
def _film_wall(w, C, hmin, R, el, s, s_dot, v_c, dw):
    """One wall's film (PocketFilm.kernel): W (its normal load), T (the roller's force along e_r), poi (the
    Poiseuille shear), and what the differentials need."""
    h = C - w * s
    act = h > hmin
    hb = h if act else hmin
    rr = R * (1.0 / hb)                         # the reference's reciprocal products, in its order
    root = np.sqrt(2.0 * rr)
    ue = -0.5 * v_c - (0.5 * w) * R * dw
    du = v_c - w * R * dw
    V = w * s_dot
    srr = np.sqrt(rr)
    Vp = V if V > 0.0 else 0.0
    W = (_PF_W * el) * abs(ue) * rr + (_PF_S * el) * rr * srr * Vp
    poi = (_PF_P * el) * ue * root
    T = -1.0 * (_PF_C * el) * du * root + poi
    return W, T, poi, act, hb, root, ue, du, V, rr, srr, Vp


@njit(cache=True)
def _dfilm_wall(w, R, el, ds, ds_dot, dv_c, ddw, act, hb, root, ue, du, V, rr, srr, Vp):
    """Differentials (dW, dT, dpoi) of :func:`_film_wall` along one direction."""
    dhb = -w * ds if act else 0.0
    droot = -0.5 * root * dhb / hb
    due = -0.5 * dv_c - (0.5 * w) * R * ddw
    ddu = dv_c - w * R * ddw
    drr = -rr * dhb / hb
    dVp = w * ds_dot if V > 0.0 else (0.5 * w * ds_dot if V == 0.0 else 0.0)
    dW = (_PF_W * el) * (_sign(ue) * due * rr + abs(ue) * drr) \
        + (_PF_S * el) * (1.5 * srr * drr * Vp + rr * srr * dVp)
    dpoi = (_PF_P * el) * (due * root + ue * droot)
    dT = -1.0 * (_PF_C * el) * (ddu * root + du * droot) + dpoi
    return dW, dT, dpoi


@njit(cache=True)
def evaluate_pocket_film(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The pocket's oil film (docs/model.md §8.5): both walls' wedge and squeeze loads in the pocket's potential
    form, their shear at the wall points with the Poiseuille couple."""
    for i in range(ql.shape[0]):
        psi, rm, C, D, el, hmin, mult = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5], P[i, 6]
        R = 0.5 * D
        xr, yr, xg, yg, thg = ql[i, 0], ql[i, 1], ql[i, 3], ql[i, 4], ql[i, 5]
        vr0, vr1, vr2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vg0, vg1, vg2 = vl[i, 3], vl[i, 4], vl[i, 5]
        dx, dy = xr - xg, yr - yg
        rho2 = dx * dx + dy * dy + _ETA2
        inv_r2 = 1.0 / rho2
        inv_r = 1.0 / np.sqrt(rho2)
        rho = np.sqrt(rho2)
        ex, ey = dx * inv_r, dy * inv_r
        s = rm * _wrap(np.arctan2(dy, dx) - thg - psi)
        wx, wy = vr0 - vg0, vr1 - vg1
        num = dx * wy - dy * wx
        s_dot = rm * (num * inv_r2 - vg2)
        v_c = wx * ex + wy * ey
        dw = vr2 - vg2
        a = _film_wall(1.0, C, hmin, R, el, s, s_dot, v_c, dw)
        b = _film_wall(-1.0, C, hmin, R, el, s, s_dot, v_c, dw)
        N = a[0] - b[0]
        f0, f1, f2, f3, f4, f5 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(2):
            w = 1.0 if k == 0 else -1.0
            T, poi = (a[1], a[2]) if k == 0 else (b[1], b[2])
            rwx, rwy = -w * R * ey, w * R * ex
            rgx, rgy = dx + rwx, dy + rwy
            Tx, Ty = T * ex, T * ey
            cpl = (w * 2.0) * R * poi
            f0, f1, f2 = f0 + Tx, f1 + Ty, f2 + (rwx * Ty - rwy * Tx) + cpl
            f3, f4, f5 = f3 - Tx, f4 - Ty, f5 + (rgx * (-Ty) - rgy * (-Tx)) - cpl
        fnx, fny = N * rm * dy * inv_r2, -1.0 * N * rm * dx * inv_r2
        _write(F, Jq, Jv, i, -1, mult, f0 + fnx, f1 + fny, f2, f3 - fnx, f4 - fny, f5 + N * rm)
        if not jac:
            continue
        r2 = dx * dx + dy * dy                   # ad.arctan2's derivative: no η
        for j in range(12):
            dxr, dyr, _, dxg, dyg, dthg, dvr0, dvr1, dvr2, dvg0, dvg1, dvg2 = _unit(j)
            ddx, ddy = dxr - dxg, dyr - dyg
            ds = rm * (ddy * (dx / r2) - ddx * (dy / r2) - dthg)
            drho2 = 2.0 * (dx * ddx + dy * ddy)
            drho = 0.5 * drho2 / rho
            dex, dey = (ddx - ex * drho) / rho, (ddy - ey * drho) / rho
            dwx, dwy = dvr0 - dvg0, dvr1 - dvg1
            dnum = ddx * wy + dx * dwy - ddy * wx - dy * dwx
            ds_dot = rm * ((dnum - num * drho2 / rho2) / rho2 - dvg2)
            dv_c = dwx * ex + wx * dex + dwy * ey + wy * dey
            ddw = dvr2 - dvg2
            da = _dfilm_wall(1.0, R, el, ds, ds_dot, dv_c, ddw, a[3], a[4], a[5], a[6], a[7], a[8], a[9], a[10],
                             a[11])
            db = _dfilm_wall(-1.0, R, el, ds, ds_dot, dv_c, ddw, b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10],
                             b[11])
            dN = da[0] - db[0]
            g0, g1, g2, g3, g4, g5 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            for k in range(2):
                w = 1.0 if k == 0 else -1.0
                T, dT, dpoi = (a[1], da[1], da[2]) if k == 0 else (b[1], db[1], db[2])
                rwx, rwy = -w * R * ey, w * R * ex
                drwx, drwy = -w * R * dey, w * R * dex
                rgx, rgy = dx + rwx, dy + rwy
                drgx, drgy = ddx + drwx, ddy + drwy
                Tx, Ty = T * ex, T * ey
                dTx, dTy = dT * ex + T * dex, dT * ey + T * dey
                dcpl = (w * 2.0) * R * dpoi
                g0, g1 = g0 + dTx, g1 + dTy
                g2 = g2 + _d_cross(rwx, rwy, drwx, drwy, Tx, Ty, dTx, dTy) + dcpl
                g3, g4 = g3 - dTx, g4 - dTy
                g5 = g5 - _d_cross(rgx, rgy, drgx, drgy, Tx, Ty, dTx, dTy) - dcpl
            dfnx = rm * (dN * dy + N * ddy) / rho2 - fnx * drho2 / rho2
            dfny = -rm * (dN * dx + N * ddx) / rho2 - fny * drho2 / rho2
            _write(F, Jq, Jv, i, j, mult, g0 + dfnx, g1 + dfny, g2, g3 - dfnx, g4 - dfny, g5 + dN * rm)


@njit(cache=True)
def evaluate_cage_drag(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The mixture's moment on the cage's faces (docs/model.md §8.7): −coef·sign(Δω)|Δω|^(3/2), Δω = ω_cage −
    ω_carrier, on the cage; the opposite on the carrier."""
    for i in range(ql.shape[0]):
        coef = P[i, 0]
        dw = vl[i, 2] - vl[i, 5]
        M = -coef * _sign(dw) * abs(dw) ** 1.5
        _write(F, Jq, Jv, i, -1, 1.0, 0.0, 0.0, M, 0.0, 0.0, -M)
        if not jac:
            continue
        dM = -1.5 * coef * abs(dw) ** 0.5
        for a in range(6):
            for b in range(6):
                Jq[i, a, b] = 0.0
                Jv[i, a, b] = 0.0
        Jv[i, 2, 2], Jv[i, 2, 5], Jv[i, 5, 2], Jv[i, 5, 5] = dM, -dM, -dM, dM


# ----------------------------------------------------------------------------------------------- raceway film
# ``RaceFilm`` P (n, 10): κ (+1 inner, −1 outer), race_marker x, y [m], R_race [m], D [m],
#              coef = SQUEEZE_LOAD·η·l·R_red^(3/2), floor h_f [m], multiplicity, η·l [Pa·s·m], R_red [m];
#              G (1,): 1 for the law "full" (squeeze, wedge and shear), 0 for "squeeze"
# (mbd.elements.race_film; stateless, no compiled outputs: theirs come from the numpy kernel)
def pack_race_film(elem):
    _require(elem, race_film.RaceFilm)
    mk = elem.race_marker
    P = _rows(elem.kappa, mk[:, 0], mk[:, 1], elem.R_race, elem.D, elem.coef, elem.floor, elem.multiplicity,
              elem.el, elem.R_red)
    return P, np.array([1.0 if elem.law == "full" else 0.0])


@njit(cache=True, inline="always")
def _film_geometry(P, ql, vl, i):
    """Instance i's raceway geometry for the film kernels (RaceContact's, §8.1): the raceway centre's offset rc and
    velocity V_c, p − c = (dx, dy), ρ, e, the deflection δ, the roller's velocity relative to V_c and the approach
    speed V = δ̇."""
    kap, mx, my, R, D = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4]
    xr, yr = ql[i, 0], ql[i, 1]
    xb, yb, thb = ql[i, 3], ql[i, 4], ql[i, 5]
    vr0, vr1 = vl[i, 0], vl[i, 1]
    vb0, vb1, vb2 = vl[i, 3], vl[i, 4], vl[i, 5]
    cth, sth = np.cos(thb), np.sin(thb)
    rcx, rcy = cth * mx - sth * my, sth * mx + cth * my
    dx, dy = xr - (xb + rcx), yr - (yb + rcy)
    rho = np.sqrt(dx * dx + dy * dy + _ETA2)
    ex, ey = dx / rho, dy / rho
    delta = 0.5 * D - kap * (rho - R)
    Vcx, Vcy = vb0 - vb2 * rcy, vb1 + vb2 * rcx
    wx, wy = vr0 - Vcx, vr1 - Vcy
    V = -kap * (ex * wx + ey * wy)
    return kap, R, D, vb2, rcx, rcy, dx, dy, rho, ex, ey, delta, Vcx, Vcy, wx, wy, V


@njit(cache=True, inline="always")
def _film_dgeometry(j, kap, vb2, rcx, rcy, dx, dy, rho, ex, ey, wx, wy):
    """The derivatives of :func:`_film_geometry`'s values along direction j (:func:`_unit`): drc, dρ, de, dV_c, dw
    and dV, then the direction's velocity components (roller v_x, v_y, ω; race body v_x, v_y, ω)."""
    dxr, dyr, _, dxb, dyb, dthb, dvr0, dvr1, dvr2, dvb0, dvb1, dvb2 = _unit(j)
    drcx, drcy = -rcy * dthb, rcx * dthb
    ddx, ddy = dxr - dxb - drcx, dyr - dyb - drcy
    drho = (dx * ddx + dy * ddy) / rho
    dex, dey = (ddx - ex * drho) / rho, (ddy - ey * drho) / rho
    dVcx, dVcy = dvb0 - dvb2 * rcy - vb2 * drcy, dvb1 + dvb2 * rcx + vb2 * drcx
    dwx, dwy = dvr0 - dVcx, dvr1 - dVcy
    dV = -kap * (dex * wx + ex * dwx + dey * wy + ey * dwy)
    return drcx, drcy, drho, dex, dey, dVcx, dVcy, dwx, dwy, dV, dvr0, dvr1, dvr2, dvb0, dvb1, dvb2


@njit(cache=True)
def evaluate_race_film(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The raceway squeeze film while the gap is open (docs/model.md §8.9): W = coef·max(h, h_f)^(−3/2)·S(h/h_f)·
    max(V, 0), h = −δ, V = δ̇, along κe at the contact point (through the roller's centre), the opposite on the race
    body."""
    if G[0] > 0.0:
        _race_film_full(ql, vl, P, F, Jq, Jv, jac)
        return
    for i in range(ql.shape[0]):
        coef, hf, mult = P[i, 5], P[i, 6], P[i, 7]
        kap, R, D, vb2, rcx, rcy, dx, dy, rho, ex, ey, delta, Vcx, Vcy, wx, wy, V = _film_geometry(P, ql, vl, i)
        h = -delta
        if not (h > 0.0 and V > 0.0):
            _zero(F, Jq, Jv, i, jac)
            continue
        floored = not h > hf
        hs = hf if floored else h
        S, dS = tooth_pairs.damping_share(h, hf)
        hp = hs ** -1.5
        c = coef * hp * S
        W = c * V
        Fx, Fy = kap * W * ex, kap * W * ey
        _write(F, Jq, Jv, i, -1, mult, Fx, Fy, 0.0, -Fx, -Fy, -(rcx * Fy - rcy * Fx))
        if not jac:
            continue
        dhp = 0.0 if floored else -1.5 * hp / hs            # d(hs^-1.5)/dh
        dc_dh = coef * (dhp * S + hp * dS)
        for j in range(12):
            drcx, drcy, drho, dex, dey, _, _, _, _, dV, _, _, _, _, _, _ = _film_dgeometry(
                j, kap, vb2, rcx, rcy, dx, dy, rho, ex, ey, wx, wy)
            dh = kap * drho                                   # h = κ(ρ − R) − D/2
            dW = dc_dh * dh * V + c * dV
            dFx, dFy = kap * (dW * ex + W * dex), kap * (dW * ey + W * dey)
            dM = -(drcx * Fy + rcx * dFy - drcy * Fx - rcy * dFx)
            _write(F, Jq, Jv, i, j, mult, dFx, dFy, 0.0, -dFx, -dFy, dM)


@njit(cache=True)
def _race_film_full(ql, vl, P, F, Jq, Jv, jac):
    """The law "full" of the raceway film (docs/model.md §8.9): S(h/h_f)·(the gap's wedge and squeeze loads, Couette
    and Poiseuille shear) of the pocket film's gap law (:func:`_film_wall`'s constants) with the raceway contact's
    kinematics (:func:`_race_surfaces`), the load along κe and the Couette shear along t at P, the Poiseuille shear
    with the pressure's tangential resultant through the centres (as the race contact's rolling resistance)."""
    for i in range(ql.shape[0]):
        hf, mult, el, Rr = P[i, 6], P[i, 7], P[i, 8], P[i, 9]
        kap, R, D, vb2, rcx, rcy, dx, dy, rho, ex, ey, delta, Vcx, Vcy, wx, wy, V = _film_geometry(P, ql, vl, i)
        vr0, vr1, vr2 = vl[i, 0], vl[i, 1], vl[i, 2]
        vb0, vb1 = vl[i, 3], vl[i, 4]
        tx, ty = -ey, ex
        h = -delta
        if not h > 0.0:
            _zero(F, Jq, Jv, i, jac)
            continue
        rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, v_s, wt, u = _race_surfaces(
            R, rho, ex, ey, tx, ty, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, wx, wy)
        floored = not h > hf
        hs = hf if floored else h
        S, dS = tooth_pairs.damping_share(h, hf)
        rr = Rr / hs
        root = np.sqrt(2.0 * rr)
        srr = np.sqrt(rr)
        Vp = V if V > 0.0 else 0.0
        Wg = (_PF_W * el) * abs(u) * rr + (_PF_S * el) * rr * srr * Vp
        Tg = -(_PF_C * el) * v_s * root
        Pg = (_PF_P * el) * u * root
        W, T, FP = S * Wg, S * Tg, S * Pg
        Fx, Fy = kap * W * ex + T * tx, kap * W * ey + T * ty
        a1 = 2.0 * R / rho
        g = FP * (a1 - 1.0)
        gx, gy = g * tx, g * ty
        _write(F, Jq, Jv, i, -1, mult, Fx + gx, Fy + gy, rrx * Fy - rry * Fx + (rho - R) * FP, -Fx - gx, -Fy - gy,
               -(rbx * Fy - rby * Fx) - (rcx * gy - rcy * gx) - R * FP)
        if not jac:
            continue
        for j in range(12):
            drcx, drcy, drho, dex, dey, dVcx, dVcy, dwx, dwy, dV, dvr0, dvr1, dvr2, dvb0, dvb1, dvb2 = _film_dgeometry(
                j, kap, vb2, rcx, rcy, dx, dy, rho, ex, ey, wx, wy)
            dtx, dty = -dey, dex
            dh = kap * drho                                   # h = κ(ρ − R) − D/2
            drrx, drry = -drho * ex + rl * dex, -drho * ey + rl * dey
            drbx, drby = drcx + R * dex, drcy + R * dey
            dVrx, dVry = dvr0 - dvr2 * rry - vr2 * drry, dvr1 + dvr2 * rrx + vr2 * drrx
            dVbx, dVby = dvb0 - dvb2 * rby - vb2 * drby, dvb1 + dvb2 * rbx + vb2 * drbx
            dur = dVrx * tx + Vrx * dtx + dVry * ty + Vry * dty
            dub = dVbx * tx + Vbx * dtx + dVby * ty + Vby * dty
            dwt = dwx * tx + wx * dtx + dwy * ty + wy * dty
            dvP = dVcx * tx + Vcx * dtx + dVcy * ty + Vcy * dty + R * (dwt - wt * drho / rho) / rho
            du = 0.5 * (dur + dub) - dvP
            dvs = dur - dub
            dhs = 0.0 if floored else dh
            drr = -rr * dhs / hs
            droot = -0.5 * root * dhs / hs
            dVp = dV if V > 0.0 else 0.0
            dWg = (_PF_W * el) * (_sign(u) * du * rr + abs(u) * drr) \
                + (_PF_S * el) * (1.5 * srr * drr * Vp + rr * srr * dVp)
            dTg = -(_PF_C * el) * (dvs * root + v_s * droot)
            dPg = (_PF_P * el) * (du * root + u * droot)
            dSh = dS * dh
            dW, dT, dFP = dSh * Wg + S * dWg, dSh * Tg + S * dTg, dSh * Pg + S * dPg
            dFx = kap * (dW * ex + W * dex) + dT * tx + T * dtx
            dFy = kap * (dW * ey + W * dey) + dT * ty + T * dty
            dg = dFP * (a1 - 1.0) - FP * 2.0 * R * drho / (rho * rho)
            dgx, dgy = dg * tx + g * dtx, dg * ty + g * dty
            dMr = _d_cross(rrx, rry, drrx, drry, Fx, Fy, dFx, dFy) + drho * FP + (rho - R) * dFP
            dMb = -_d_cross(rbx, rby, drbx, drby, Fx, Fy, dFx, dFy) - _d_cross(rcx, rcy, drcx, drcy, gx, gy, dgx, dgy) \
                - R * dFP
            _write(F, Jq, Jv, i, j, mult, dFx + dgx, dFy + dgy, dMr, -dFx - dgx, -dFy - dgy, dMb)
