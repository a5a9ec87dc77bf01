"""Compiled tooth-pair flank force (:mod:`mbd.elements.tooth_pairs`), with its gradient by hand.

The law is the reference's operation for operation. Gradients are over the mesh kernel's 8 variables
(d_x, d_y, θ1, θ2, ḋ_x, ḋ_y, ω1, ω2) (:mod:`mbd.compiled.mesh`). Used: P_f and u have
∇u = z1/2π (−∂φ_e/∂d, 1, 0 | 0); u̇ = z1/2π (ω1 − φ̇_e) with φ̇_e = t·ḋ/a, ∂φ̇_e/∂d = −(t (e·ḋ) + e (t·ḋ))/a²,
∂φ̇_e/∂ḋ = t/a; a pair's rate δ̇_f − g'(u) u̇ has ∇ = ∇δ̇_f − g'' u̇ ∇u − g' ∇u̇.

Column block of P from ``col`` (``Q_*``): entry h_+, h_−, phase2 c_+, c_−, relief1 (C_a, ξ_a, e), relief2
(C_a, ξ_a, e), start1, start2 (offsets into the table, which starts at G[``tstart``]), bound (the most a
pair's material excess can close its gap: a flank compressed less than −bound has no pair in contact).
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["flank_force", "pair_setup", "pair_force", "damping_share", "NCOLS", "Q_BOUND"]

_TWO_PI = 2.0 * np.pi
(Q_ENTRY, Q_PHASE2, Q_RELIEF1, Q_RELIEF2, Q_START1, Q_START2, Q_BOUND) = (0, 2, 4, 7, 10, 11, 12)
NCOLS = 13
_STRIDE, _FACES = 5, 2


@njit(cache=True)
def _box(u, centre, half, s):
    """(w, dw/du, d²w/du²) of the smoothed window (tooth_pairs.smooth_box) at distance |u − centre|."""
    du = u - centre
    sg = 1.0 if du > 0.0 else (-1.0 if du < 0.0 else 0.0)
    x = (half + 0.5 * s - abs(du)) * (1.0 / s)
    if x >= 1.0 or x <= 0.0:
        return (1.0 if x >= 1.0 else 0.0), 0.0, 0.0
    dx = -sg / s
    w = x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
    return w, 30.0 * x * x * (1.0 - x) * (1.0 - x) * dx, 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) * dx * dx


@njit(cache=True)
def damping_share(comp, ramp):
    """(S, dS/dcomp): the damping share of :func:`mbd.elements.tooth_pairs.damping_share` ((1, 0) for ramp 0); the
    mesh kernels' and the roller–raceway kernels' (:mod:`.contact`, :mod:`.sliced`)."""
    if ramp <= 0.0:
        return 1.0, 0.0
    x = comp * (1.0 / ramp)              # the reference's order of operations
    if x >= 1.0:
        return 1.0, 0.0
    if x <= 0.0:
        return 0.0, 0.0
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x)), 30.0 * x * x * (1.0 - x) * (1.0 - x) / ramp


@njit(cache=True)
def _relief(xi, ca, xa, e):
    """(R, dR/dξ, d²R/dξ²) of tip relief."""
    if xi <= xa or ca == 0.0:
        return 0.0, 0.0, 0.0
    inv = 1.0 / (1.0 - xa)
    t = (xi - xa) * inv
    if e == 1.0:
        return ca * t, ca * inv, 0.0
    return ca * t * t, 2.0 * ca * t * inv, 2.0 * ca * inv * inv


@njit(cache=True)
def _cubic(G, base, x):
    """(E, dE/dx, d²E/dx²) of the cubic whose coefficients start at G[base]."""
    c0, c1, c2, c3 = G[base], G[base + 1], G[base + 2], G[base + 3]
    return (c0 + x * (c1 + x * (c2 + x * c3)), c1 + x * (2.0 * c2 + x * 3.0 * c3), 2.0 * c2 + 6.0 * c3 * x)


@njit(cache=True)
def pair_setup(f, P, i, col, G, tstart, sig, z1, z2, k_mean, h, s, single, ratio, th1, th2, phi_e, w1, inv_a,
               t_dd, kk, dk, gg, dg, d2g):
    """The two pairs of flank f of mesh i: per pair j its stiffness k_j (faults included) and k_j', its gap g_j, g_j',
    g_j'' (derivatives in u) into kk, dk, gg, dg, d2g (2,); returns (K_0, K_0', u̇): the pairs' stiffness without
    faults, its derivative in u, and the roll coordinate's rate."""
    eps = 2.0 * h + 1.0
    fi = 0 if f > 0 else 1
    c1 = z1 / _TWO_PI
    Pf = c1 * (th1 - phi_e) + P[i, col + Q_ENTRY + fi]
    Qf = -sig * z2 * (th2 - phi_e) * (1.0 / _TWO_PI) + P[i, col + Q_PHASE2 + fi]
    m = np.floor(Pf + 0.5 * s)
    u0 = Pf - m
    n2 = np.rint(Qf - u0)
    phi_dot = t_dd * inv_a
    udot = c1 * (w1 - phi_dot)
    fwd = sig * f > 0.0
    face1 = 0 if fwd else 1
    dxi = (1.0 if fwd else -1.0) / eps
    kmax = k_mean * single
    r1, r2 = col + Q_RELIEF1, col + Q_RELIEF2
    s1, s2 = tstart + int(P[i, col + Q_START1]), tstart + int(P[i, col + Q_START2])
    K0, dK0 = 0.0, 0.0
    for j in range(2):
        u = u0 + j
        i1 = int(np.mod(-m + j, z1))
        i2 = int(np.mod(sig * (n2 - j), z2))
        b1 = s1 + (i1 * _FACES + face1) * _STRIDE
        b2 = s2 + (i2 * _FACES + fi) * _STRIDE
        xi1 = (0.0 if fwd else 1.0) + dxi * u
        xi2 = 1.0 - xi1
        E1, dE1, d2E1 = _cubic(G, b1, 2.0 * xi1 - 1.0)
        E2, dE2, d2E2 = _cubic(G, b2, 2.0 * xi2 - 1.0)
        R1, dR1, d2R1 = _relief(xi1, P[i, r1], P[i, r1 + 1], P[i, r1 + 2])
        R2, dR2, d2R2 = _relief(xi2, P[i, r2], P[i, r2 + 1], P[i, r2 + 2])
        gg[j] = R1 + R2 - E1 - E2
        dg[j] = dxi * (dR1 - dR2 - 2.0 * dE1 + 2.0 * dE2)
        d2g[j] = dxi * dxi * (d2R1 + d2R2 - 4.0 * d2E1 - 4.0 * d2E2)
        wa, dwa, _ = _box(u, 0.5 * eps, 0.5 * eps, s)
        wb, dwb, _ = _box(u, 0.5 * eps, 1.0 - 0.5 * eps, s)
        sh = 0.5 * ratio * wa + (1.0 - 0.5 * ratio) * wb
        dsh = 0.5 * ratio * dwa + (1.0 - 0.5 * ratio) * dwb
        fac = G[b1 + 4] * G[b2 + 4]
        kk[j], dk[j] = kmax * sh * fac, kmax * dsh * fac
        K0 += kmax * sh
        dK0 += kmax * dsh
    return K0, dK0, udot


@njit(cache=True)
def pair_force(k, dkj, g, dgj, d2gj, K0, dK0, udot, c_m, ramp, delta, rate):
    """(F_j, ∂F_j/∂δ_f, ∂F_j/∂δ̇_f, ∂F_j/∂u, ∂F_j/∂u̇) of one pair at flank compression δ_f and rate δ̇_f (the pair's
    data from :func:`pair_setup`); all zero while the pair is open or would pull."""
    comp = delta - g
    if comp <= 0.0 or k == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    S, dS = damping_share(comp, ramp)
    cj = c_m * k / K0
    rj = rate - dgj * udot
    Fj = k * comp + cj * S * rj
    if Fj <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    dcj = c_m * (dkj * K0 - k * dK0) / (K0 * K0)
    kc = k + cj * rj * dS                                              # ∂F_j/∂comp
    a_u = dkj * comp - kc * dgj + dcj * S * rj - cj * S * d2gj * udot       # ∂F_j/∂u (comp = δ − g(u))
    a_ud = -cj * S * dgj                                                    # ∂F_j/∂u̇
    return Fj, kc, cj * S, a_u, a_ud


@njit(cache=True)
def flank_force(f, P, i, col, G, tstart, sig, z1, z2, k_mean, c_m, ramp, h, s, single, ratio, th1, th2, phi_e,
                w1, delta, rate, ex, ey, tx, ty, inv_a, t_dd, e_dd, ddelta, drate, grad, jac):
    """F_f of flank f of mesh i by the pair law; with ``jac`` its gradient into ``grad`` (8,), from the
    flank's ∇δ_f (``ddelta``) and ∇δ̇_f (``drate``)."""
    if jac:
        grad[:] = 0.0
    if delta + P[i, col + Q_BOUND] <= 0.0:
        return 0.0
    kk, dk, gg, dg, d2g = np.empty(2), np.empty(2), np.empty(2), np.empty(2), np.empty(2)
    K0, dK0, udot = pair_setup(f, P, i, col, G, tstart, sig, z1, z2, k_mean, h, s, single, ratio, th1, th2, phi_e,
                               w1, inv_a, t_dd, kk, dk, gg, dg, d2g)
    c1 = z1 / _TWO_PI
    F = 0.0
    # gradients of u and u̇ over (d, θ1, θ2, ḋ, ω1, ω2)
    gu0, gu1, gu2 = -c1 * tx * inv_a, -c1 * ty * inv_a, c1
    ia2 = inv_a * inv_a
    gv0 = c1 * (tx * e_dd + ex * t_dd) * ia2
    gv1 = c1 * (ty * e_dd + ey * t_dd) * ia2
    gv4, gv5, gv6 = -c1 * tx * inv_a, -c1 * ty * inv_a, c1
    for j in range(2):
        Fj, kc, cS, a_u, a_ud = pair_force(kk[j], dk[j], gg[j], dg[j], d2g[j], K0, dK0, udot, c_m, ramp, delta, rate)
        if not Fj > 0.0:
            continue
        F += Fj
        if not jac:
            continue
        for v in range(8):
            grad[v] += kc * ddelta[v] + cS * drate[v]
        grad[0] += a_u * gu0 + a_ud * gv0
        grad[1] += a_u * gu1 + a_ud * gv1
        grad[2] += a_u * gu2
        grad[4] += a_ud * gv4
        grad[5] += a_ud * gv5
        grad[6] += a_ud * gv6
    return F
