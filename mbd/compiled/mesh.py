"""Compiled :class:`~mbd.elements.gear_mesh.GearMesh` (kernel convention in :mod:`mbd.compiled`).

The force law is the reference kernel's, operation for operation (so values agree to the round-off
of arctan2/cos/sin), with its Jacobians derived by hand. One family may mix external and internal
meshes (σ per instance, as after System fusion).

P, shape (n, 15 [+ 4] [+ 4] [+ 13]), one row per mesh (constants ``P_*`` below):

    0 σ (+1 external, −1 internal)   1 r_b1     2 r_b2      3 a0     4 sin α    5 κ0 = σ r_b1 + r_b2
    6 p_b base pitch                 7 z1       8 k_mean    9 c_m   10 u0      11 p0
    12 b backlash                   13 φ_ref   14 δ_c damping ramp
    RectangularStiffness only: 15 h = (ε_α − 1)/2   16 s smoothing   17 k_single/k_mean   18 ratio
    then, only in a family with eccentricity, from column G[1]: o1x, o1y, o2x, o2y [m]
    then, only in a family with the tooth-pair law, from column G[2]: its block (:mod:`.tooth_pairs`)

G = [shape, offset column or −1, pair column or −1, table start, shape coefficients, tooth tables]
(constants ``G_*``, ``SHAPE_*``):

    constant     [0, ., ., .]
    rectangular  [1, ., ., .]                                (its parameters are per instance, in P)
    fourier      [2, ., ., ., na, nb, a_1 … a_na, b_1 … b_nb]

and, with the tooth-pair law, the family's tooth tables from G[G[3]] on (:mod:`.tooth_pairs`).

A family without errors (G[1] = G[2] = −1) evaluates exactly as before they existed. With eccentricity,
the law is evaluated on the geometric centres (:func:`_to_geometric`) and the forces and Jacobians are
mapped back to the body coordinates by the chain rule (:func:`_from_geometric`). The tooth-pair law
(tooth deviations, relief, tooth faults) replaces the flank force and its gradient
(:func:`.tooth_pairs.flank_force`); the rest is shared.

Jacobians. With d the centre vector along e (σ(c2 − c1)), ḋ its rate, t = k × e, a = |d|, every
quantity is a function of (d, θ1, θ2) and (ḋ, ω1, ω2); the kernel carries gradients over these
8 variables and maps them to the 6 local coordinates at the end (∂d/∂c1 = −σ, ∂d/∂c2 = σ). Used:
∂e/∂d = t tᵀ/a, ∂t/∂d = −e tᵀ/a, ∂a/∂d = e, ∂φ_e/∂d = (−d_y, d_x)/a², so
∂(t·ḋ)/∂d = −t (e·ḋ)/a and ∂(e·ḋ)/∂d = t (t·ḋ)/a.
Branches follow :mod:`mbd.ad`: chosen by value, the derivative of the branch taken (0 when clipped).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.gear_mesh import ConstantStiffness, FourierStiffness, GearMesh, RectangularStiffness
from . import tooth_pairs

__all__ = ["pack_gear_mesh", "evaluate_gear_mesh"]

_TWO_PI = 2.0 * np.pi

(P_SIGMA, P_RB1, P_RB2, P_A0, P_SIN_ALPHA, P_KAPPA0, P_PITCH, P_TEETH1, P_K_MEAN, P_C_MESH, P_U0, P_P0,
 P_BACKLASH, P_PHI_REF, P_RAMP, P_RECT_H, P_RECT_S, P_RECT_SINGLE, P_RECT_RATIO) = range(19)
G_SHAPE, G_OFFSET, G_PAIRS, G_TABLE, G_FOURIER = 0, 1, 2, 3, 4
SHAPE_CONSTANT, SHAPE_RECTANGULAR, SHAPE_FOURIER = 0, 1, 2


def pack_gear_mesh(elem: GearMesh):
    """(P, G) of a GearMesh family (layouts in the module docstring)."""
    cols = [elem.sigma, elem.rb1, elem.rb2, elem.a0, elem.sin_alpha, elem.kappa0, elem.pitch, elem.teeth1,
            elem.k_mean, elem.c_mesh, elem.u0, elem.p0, elem.backlash, elem.phi_ref, elem.damping_ramp]
    shape, fourier = elem.stiffness, []
    if type(shape) is ConstantStiffness:
        kind = SHAPE_CONSTANT
    elif type(shape) is RectangularStiffness:
        kind = SHAPE_RECTANGULAR
        cols += list(elem._shape_args)          # (h, s, single, ratio) per instance, concatenated when fused
    elif type(shape) is FourierStiffness:
        kind, fourier = SHAPE_FOURIER, [len(shape.a), len(shape.b), *shape.a, *shape.b]
    else:
        raise NotImplementedError(f"GearMesh {elem.name!r}: the compiled path has no stiffness shape "
                                  f"{type(shape).__name__} (only constant, rectangular, fourier)")
    off = pcol = -1                             # error blocks only when the family has them
    if elem.has_offset:
        off = len(cols)
        cols += [elem.offset1[:, 0], elem.offset1[:, 1], elem.offset2[:, 0], elem.offset2[:, 1]]
    table = []
    if elem.pairs is not None:
        pcol, pp = len(cols), elem.pairs
        h, s = elem._shape_args[0], elem._shape_args[1]
        reach = 1.0 + 2.0 * float(np.max(s / (2.0 * h + 1.0)))        # |x| of any pair with stiffness
        cols += [*pp.entry.T, *pp.phase2.T, *pp.relief1.T, *pp.relief2.T, pp.start1, pp.start2,
                 pp.excess_bound(elem.teeth1, elem.teeth2, reach)]      # the order of tooth_pairs.Q_*
        table = list(pp.table)
    head = [kind, off, pcol, 0.0, *fourier]
    head[G_TABLE] = len(head)
    G = np.array(head + table, float)
    P = np.ascontiguousarray(np.column_stack([np.broadcast_to(np.asarray(c, float), (elem.n,)) for c in cols]))
    return P, G


@njit(cache=True)
def _wrap(x):
    """ad.wrap_angle: into (−π, π] by whole turns (derivative 1)."""
    return x - _TWO_PI * np.rint(x / _TWO_PI)


@njit(cache=True)
def _distance(p, centre, period):
    """(|p − centre| on a circle of circumference ``period``, its derivative in p), as gear_mesh._distance."""
    u = _wrap(_TWO_PI / period * (p - centre)) * (period / _TWO_PI)
    return abs(u), np.sign(u)                  # d|u|/du = sign(u) (0 at 0, as ad.abs_)


@njit(cache=True)
def _box(dist, ddist, half, s):
    """(w, dw/dp) of the smoothed window at distance dist (d dist/dp = ddist), as gear_mesh._box."""
    x = (half + 0.5 * s - dist) * (1.0 / s)
    dx = -ddist * (1.0 / s)
    if x > 1.0:
        x, dx = 1.0, 0.0
    elif x < 0.0:
        x, dx = 0.0, 0.0
    w = x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
    return w, 30.0 * x * x * (1.0 - x) * (1.0 - x) * dx


@njit(cache=True)
def _rect_factor(p, h, s, single, ratio):
    """(factor, dfactor/dp) of the smoothed rectangular wave, as gear_mesh._rect_factor."""
    dist, ddist = _distance(p, h, 1.0)
    w, dw = _box(dist, ddist, h, s)
    return single * (1.0 + (ratio - 1.0) * w), single * (ratio - 1.0) * dw


@njit(cache=True)
def _fourier_factor(p, G):
    """(factor, dfactor/dp) of 1 + Σ a_j cos 2πjp + b_j sin 2πjp, coefficients from G."""
    na, nb, a0 = int(G[G_FOURIER]), int(G[G_FOURIER + 1]), G_FOURIER + 2
    f, df = 1.0, 0.0
    for j in range(na):
        w = _TWO_PI * (j + 1)
        f = f + G[a0 + j] * np.cos(w * p)
        df -= G[a0 + j] * w * np.sin(w * p)
    for j in range(nb):
        w = _TWO_PI * (j + 1)
        f = f + G[a0 + na + j] * np.sin(w * p)
        df += G[a0 + na + j] * w * np.cos(w * p)
    return f, df


@njit(cache=True)
def _factor(shape, p, P, i, G):
    if shape == SHAPE_RECTANGULAR:
        return _rect_factor(p, P[i, P_RECT_H], P[i, P_RECT_S], P[i, P_RECT_SINGLE], P[i, P_RECT_RATIO])
    if shape == SHAPE_FOURIER:
        return _fourier_factor(p, G)
    return 1.0, 0.0


@njit(cache=True)
def _put_row(Jq, Jv, i, r, scale, h, sig):
    """Row r of instance i's Jacobians from scale·h, h the gradient over (d, θ1, θ2, ḋ, ω1, ω2)."""
    Jq[i, r, 0] = -sig * scale * h[0]
    Jq[i, r, 1] = -sig * scale * h[1]
    Jq[i, r, 2] = scale * h[2]
    Jq[i, r, 3] = sig * scale * h[0]
    Jq[i, r, 4] = sig * scale * h[1]
    Jq[i, r, 5] = scale * h[3]
    Jv[i, r, 0] = -sig * scale * h[4]
    Jv[i, r, 1] = -sig * scale * h[5]
    Jv[i, r, 2] = scale * h[6]
    Jv[i, r, 3] = sig * scale * h[4]
    Jv[i, r, 4] = sig * scale * h[5]
    Jv[i, r, 5] = scale * h[7]


@njit(cache=True)
def evaluate_gear_mesh(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """Forces (and Jacobians) of n meshes; the mesh is frame-invariant, so phi/omega/domega are unused."""
    off = int(G[G_OFFSET])
    if off < 0:                      # no eccentricity: the law on the body centres, written in place
        _meshes(ql, vl, P, G, F, Jq, Jv, jac)
        return
    n = ql.shape[0]
    qg, vg, r, Fg = np.empty((n, 6)), np.empty((n, 6)), np.empty((n, 4)), np.empty((n, 6))
    Jqg, Jvg = np.empty((n if jac else 0, 6, 6)), np.empty((n if jac else 0, 6, 6))
    _to_geometric(ql, vl, P, off, qg, vg, r)
    _meshes(qg, vg, P, G, Fg, Jqg, Jvg, jac)
    _from_geometric(Fg, Jqg, Jvg, r, vl, F, Jq, Jv, jac)


@njit(cache=True)
def _to_geometric(ql, vl, P, off, qg, vg, r):
    """Local coordinates and rates of the geometric centres c + R(θ)·o (θ, ω unchanged); r ← (R(θ1)o1, R(θ2)o2)."""
    for i in range(ql.shape[0]):
        for b in range(2):
            k = 3 * b
            th, w = ql[i, k + 2], vl[i, k + 2]
            c, s = np.cos(th), np.sin(th)
            ox, oy = P[i, off + 2 * b], P[i, off + 2 * b + 1]
            rx = c * ox - s * oy
            ry = s * ox + c * oy
            qg[i, k], qg[i, k + 1], qg[i, k + 2] = ql[i, k] + rx, ql[i, k + 1] + ry, th
            vg[i, k], vg[i, k + 1], vg[i, k + 2] = vl[i, k] - w * ry, vl[i, k + 1] + w * rx, w
            r[i, 2 * b], r[i, 2 * b + 1] = rx, ry


@njit(cache=True)
def _from_geometric(Fg, Jqg, Jvg, r, vl, F, Jq, Jv, jac):
    """Body forces Q = Aᵀ F_g from the forces F_g on the geometric centres (A = ∂q_g/∂q), and
    ∂Q/∂q = Aᵀ(J_q A + J_v B) + (∂Aᵀ/∂θ) F_g, ∂Q/∂v = Aᵀ J_v A with B = ∂v_g/∂q.
    Per gear A = [[1, 0, −r_y], [0, 1, r_x], [0, 0, 1]] and B's only column, θ's, is −ω (r_x, r_y, 0); local
    coordinates after the two gears' six (a face-sliced mesh's slopes) are the same in both (A = I there)."""
    nl = Fg.shape[1]
    for i in range(Fg.shape[0]):
        for j in range(nl):
            F[i, j] = Fg[i, j]
        for b in range(2):
            k, rx, ry = 3 * b, r[i, 2 * b], r[i, 2 * b + 1]
            F[i, k + 2] = Fg[i, k + 2] + (rx * Fg[i, k + 1] - ry * Fg[i, k])     # + the moment r × F_g
        if not jac:
            continue
        for row in range(nl):        # columns: J_q A + J_v B and J_v A
            for col in range(nl):
                Jq[i, row, col] = Jqg[i, row, col]
                Jv[i, row, col] = Jvg[i, row, col]
            for b in range(2):
                k, rx, ry, w = 3 * b, r[i, 2 * b], r[i, 2 * b + 1], vl[i, 3 * b + 2]
                Jq[i, row, k + 2] += (-ry * Jqg[i, row, k] + rx * Jqg[i, row, k + 1]
                                      - w * (rx * Jvg[i, row, k] + ry * Jvg[i, row, k + 1]))
                Jv[i, row, k + 2] += -ry * Jvg[i, row, k] + rx * Jvg[i, row, k + 1]
        for b in range(2):           # rows: Aᵀ (the θ rows gain r × the force rows), then (∂Aᵀ/∂θ) F_g
            k, rx, ry = 3 * b, r[i, 2 * b], r[i, 2 * b + 1]
            for col in range(nl):
                Jq[i, k + 2, col] += -ry * Jq[i, k, col] + rx * Jq[i, k + 1, col]
                Jv[i, k + 2, col] += -ry * Jv[i, k, col] + rx * Jv[i, k + 1, col]
            Jq[i, k + 2, k + 2] -= rx * Fg[i, k] + ry * Fg[i, k + 1]


@njit(cache=True)
def _lumped_flanks(shape, P, i, G, p_geo, z1, k_mean, c, phx, phy, d_plus, d_minus, r_plus, r_minus, ds, dr, dsd,
                   drd, dkp, gp, gm, jac):
    """(F_+, F_−) of the lumped law k(p) δ_f + c_m S(δ_f/δ_c) δ̇_f (gated, no pull) and, with ``jac``, their
    gradients into gp, gm from those of s, the radial term and their rates."""
    fac, dfac = _factor(shape, p_geo + P[i, P_P0], P, i, G)
    kp = k_mean * fac
    S_plus, dS_plus = tooth_pairs.damping_share(d_plus, P[i, P_RAMP])
    S_minus, dS_minus = tooth_pairs.damping_share(d_minus, P[i, P_RAMP])
    g_plus = kp * d_plus + c * S_plus * r_plus
    g_minus = kp * d_minus + c * S_minus * r_minus
    on_plus = d_plus > 0.0 and g_plus > 0.0          # flank in contact and not pulling
    on_minus = d_minus > 0.0 and g_minus > 0.0
    if jac:
        dpdth = z1 * (1.0 / _TWO_PI)
        dk = k_mean * dfac
        dkp[0], dkp[1], dkp[2] = -dk * dpdth * phx, -dk * dpdth * phy, dk * dpdth
        kp_plus, kp_minus = kp + c * r_plus * dS_plus, kp + c * r_minus * dS_minus     # ∂F/∂δ
        for j in range(8):
            gp[j] = (dkp[j] * d_plus + kp_plus * (ds[j] - dr[j]) + c * S_plus * (dsd[j] - drd[j])) if on_plus else 0.0
            gm[j] = (dkp[j] * d_minus + kp_minus * (-ds[j] - dr[j]) + c * S_minus * (-dsd[j] - drd[j])) \
                if on_minus else 0.0
    return (g_plus if on_plus else 0.0), (g_minus if on_minus else 0.0)


@njit(cache=True)
def _meshes(ql, vl, P, G, F, Jq, Jv, jac):
    """The mesh law at local coordinates ql, rates vl (the body centres, or the geometric centres)."""
    shape, pcol, tstart = int(G[G_SHAPE]), int(G[G_PAIRS]), int(G[G_TABLE])
    # gradients over (dx, dy, θ1, θ2, ḋx, ḋy, ω1, ω2), allocated once
    ds, dsd, dr, drd, dkp = np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8)
    gp, gm, hx, hy, hnet = np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8)
    dd_p, dd_m, dv_p, dv_m = np.zeros(8), np.zeros(8), np.zeros(8), np.zeros(8)
    for i in range(ql.shape[0]):
        sig, rb1, rb2 = P[i, P_SIGMA], P[i, P_RB1], P[i, P_RB2]
        sa, kappa0, pb, z1 = P[i, P_SIN_ALPHA], P[i, P_KAPPA0], P[i, P_PITCH], P[i, P_TEETH1]
        x1, y1, th1, x2, y2, th2 = ql[i, 0], ql[i, 1], ql[i, 2], ql[i, 3], ql[i, 4], ql[i, 5]
        vx1, vy1, w1, vx2, vy2, w2 = vl[i, 0], vl[i, 1], vl[i, 2], vl[i, 3], vl[i, 4], vl[i, 5]
        # --- values, in the reference kernel's order of operations
        dx, dy, ddx, ddy = sig * (x2 - x1), sig * (y2 - y1), sig * (vx2 - vx1), sig * (vy2 - vy1)
        r2 = dx * dx + dy * dy
        a = np.sqrt(r2)
        inv_a = 1.0 / a
        ex, ey = dx * inv_a, dy * inv_a
        tx, ty = -ey, ex
        phi_ref = P[i, P_PHI_REF]
        phi_e = phi_ref + _wrap(np.arctan2(dy, dx) - phi_ref)
        raw = sig * rb1 * (th1 - phi_e) + rb2 * (th2 - phi_e) - P[i, P_U0]
        roll = sig * rb1 * w1 + rb2 * w2
        s = _wrap(raw * (_TWO_PI / pb)) * (pb / _TWO_PI)
        kappa = kappa0 * inv_a
        radial = sig * sa * (a - P[i, P_A0])
        half_b = 0.5 * P[i, P_BACKLASH]
        t_dd = tx * ddx + ty * ddy
        e_dd = ex * ddx + ey * ddy
        s_dot = roll - kappa * t_dd
        radial_dot = sig * sa * e_dd
        d_plus = s - radial - half_b
        d_minus = -1.0 * s - radial - half_b
        r_plus = s_dot - radial_dot
        r_minus = -1.0 * s_dot - radial_dot
        phx, phy = -dy / r2, dx / r2                      # ∂φ_e/∂d
        if jac:                  # gradients of s, the radial term and their rates
            ds[0], ds[1], ds[2], ds[3] = -kappa0 * phx, -kappa0 * phy, sig * rb1, rb2
            dr[0], dr[1] = sig * sa * ex, sig * sa * ey
            ka = kappa * inv_a
            dsd[0], dsd[1] = ka * (ex * t_dd + tx * e_dd), ka * (ey * t_dd + ty * e_dd)
            dsd[4], dsd[5], dsd[6], dsd[7] = -kappa * tx, -kappa * ty, sig * rb1, rb2
            drd[0], drd[1] = sig * sa * inv_a * tx * t_dd, sig * sa * inv_a * ty * t_dd
            drd[4], drd[5] = sig * sa * ex, sig * sa * ey
        k_mean, c = P[i, P_K_MEAN], P[i, P_C_MESH]
        if pcol >= 0:            # the tooth-pair law, flank by flank
            for j in range(8):
                dd_p[j], dd_m[j] = ds[j] - dr[j], -ds[j] - dr[j]
                dv_p[j], dv_m[j] = dsd[j] - drd[j], -dsd[j] - drd[j]
            h, sw, single, ratio = P[i, P_RECT_H], P[i, P_RECT_S], P[i, P_RECT_SINGLE], P[i, P_RECT_RATIO]
            z2 = np.rint(rb2 / rb1 * z1)
            ramp = P[i, P_RAMP]
            F_plus = tooth_pairs.flank_force(1.0, P, i, pcol, G, tstart, sig, z1, z2, k_mean, c, ramp, h, sw, single,
                                             ratio, th1, th2, phi_e, w1, d_plus, r_plus, ex, ey, tx, ty, inv_a,
                                             t_dd, e_dd, dd_p, dv_p, gp, jac)
            F_minus = tooth_pairs.flank_force(-1.0, P, i, pcol, G, tstart, sig, z1, z2, k_mean, c, ramp, h, sw,
                                              single, ratio, th1, th2, phi_e, w1, d_minus, r_minus, ex, ey, tx, ty,
                                              inv_a, t_dd, e_dd, dd_m, dv_m, gm, jac)
        else:
            F_plus, F_minus = _lumped_flanks(shape, P, i, G, z1 * (th1 - phi_e) * (1.0 / _TWO_PI), z1, k_mean, c,
                                             phx, phy, d_plus, d_minus, r_plus, r_minus, ds, dr, dsd, drd, dkp,
                                             gp, gm, jac)
        F_net = F_plus - F_minus
        F_sum = F_plus + F_minus
        Fx_head = F_net * kappa * tx + sig * sa * F_sum * ex
        Fy_head = F_net * kappa * ty + sig * sa * F_sum * ey
        F[i, 0] = -sig * Fx_head
        F[i, 1] = -sig * Fy_head
        F[i, 2] = -sig * rb1 * F_net
        F[i, 3] = sig * Fx_head
        F[i, 4] = sig * Fy_head
        F[i, 5] = -1.0 * rb2 * F_net
        if not jac:
            continue
        # --- head force (F_net κ t + σ F_sum sin α e) and torques
        for j in range(8):
            dnet, dsum = gp[j] - gm[j], gp[j] + gm[j]
            hnet[j] = dnet
            hx[j] = dnet * kappa * tx + sig * sa * dsum * ex
            hy[j] = dnet * kappa * ty + sig * sa * dsum * ey
        # d-dependence of κ, t, e (only the two d components)
        for j in range(2):
            ej = ex if j == 0 else ey
            tj = tx if j == 0 else ty
            dkappa = -ka * ej
            hx[j] += F_net * (dkappa * tx - kappa * ex * tj * inv_a) + sig * sa * F_sum * tx * tj * inv_a
            hy[j] += F_net * (dkappa * ty - kappa * ey * tj * inv_a) + sig * sa * F_sum * ty * tj * inv_a
        _put_row(Jq, Jv, i, int(0), -sig, hx, sig)           # int(r): a run-time row (a literal would compile
        _put_row(Jq, Jv, i, int(1), -sig, hy, sig)           # _put_row once per row)
        _put_row(Jq, Jv, i, int(2), -sig * rb1, hnet, sig)
        _put_row(Jq, Jv, i, int(3), sig, hx, sig)
        _put_row(Jq, Jv, i, int(4), sig, hy, sig)
        _put_row(Jq, Jv, i, int(5), -1.0 * rb2, hnet, sig)

