"""Compiled generic families: supports, springs, drives and loads (kernel convention in :mod:`mbd.compiled`).

Each kernel repeats the reference kernel's operations in the same order and writes its Jacobians
by hand; (φ, Ω) are the reference frame's angle and speed. Layouts (one row of P per instance):

GroundSupport    P = [kx, ky, cx, cy, anchor_x, anchor_y, k_θ, c_θ, θ0]      G = [isotropic (1/0)]
BodySpring       P = [k, c, marker_a x, marker_a y, marker_b x, marker_b y]   G = []
TorsionalSpring  P = [k, c, θ0]                                               G = []
TorqueSource     P = [torque] (+ SCHEDULE)                                    G = RAMP
ForceSource      P = [F_X, F_Y] (fixed frame)                                 G = RAMP
SpeedDrive       P = [k, c, k_i, θ0, ω_ref] (+ SCHEDULE)                      G = [Ω_j, A_j, φ_j per ripple harmonic]
SlopeGyroscopic  P = [J_p]                                                    G = []
CoordinateSpring P = [k, c, q0]                                               G = []
BeamSupport      P = [marker_a x, y, k_uu, k_us, k_ss, k_θ, c_u, c_s, c_θ]     G = []

RAMP = [has_ramp (1/0), t0, t1]: a :class:`~mbd.elements.drives.Ramp` (or none). A load or speed
profile given as an arbitrary Python callable of t cannot be compiled: ``pack`` raises
NotImplementedError. SCHEDULE = :attr:`~mbd.elements.drives.Schedule.packed` appended to every row of P when the
element has a schedule (a row without one is the plain layout: the kernels then run the plain arithmetic).
SpeedDrive's internal state z is (n, 1) (the integral of the angle error) when
any k_i > 0, else (n, 0), as ``init_internal`` gives (n,) or None.

SpeedDrive's update needs the frame angle at both ends of the step (its error is measured in the
fixed frame), which the convention's update signature does not carry: ``update_speed_drive`` takes
them as two extra trailing arguments phi0, phi1.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.drives import Ramp, SpeedDrive, TorqueSource
from ..elements.loads import ForceSource
from ..elements.springs import BodySpring, GroundSupport, TorsionalSpring
from ..elements.tilt import BeamSupport, CoordinateSpring, SlopeGyroscopic

__all__ = ["pack_ground_support", "evaluate_ground_support", "pack_body_spring", "evaluate_body_spring",
           "pack_torsional_spring", "evaluate_torsional_spring", "pack_torque_source", "evaluate_torque_source",
           "pack_force_source", "evaluate_force_source", "pack_speed_drive", "evaluate_speed_drive",
           "update_speed_drive", "pack_slope_gyroscopic", "evaluate_slope_gyroscopic", "pack_coordinate_spring",
           "evaluate_coordinate_spring", "pack_beam_support", "evaluate_beam_support"]

_NO_G = np.zeros(0)


def _columns(n, *cols):
    return np.ascontiguousarray(np.column_stack([np.broadcast_to(np.asarray(c, float), (n,)) for c in cols]))


def _ramp_g(family, elem, ramp):
    """RAMP layout of an optional Ramp; any other callable cannot be compiled."""
    if ramp is None:
        return np.array([0.0, 0.0, 0.0])
    if type(ramp) is not Ramp:
        raise NotImplementedError(f"{family} {elem.name!r}: ramp {ramp!r} is a Python callable of time, which the "
                                  "compiled path cannot evaluate (use mbd.elements.Ramp or the numpy path)")
    return np.array([1.0, ramp.t0, ramp.t1])


@njit(cache=True)
def _ramp(t, G):
    """Ramp.__call__ from the RAMP layout (1 without a ramp)."""
    if G[0] == 0.0:
        return 1.0
    t0, t1 = G[1], G[2]
    if t >= t1:
        return 1.0
    if t <= t0:
        return 0.0
    s = (t - t0) / (t1 - t0)
    return s * s * (3.0 - 2.0 * s)


def _with_schedule(P, schedule):
    """P with the packed schedule appended to every row (P itself without a schedule)."""
    if schedule is None:
        return P
    S = schedule.packed
    return np.ascontiguousarray(np.column_stack([P, np.broadcast_to(S, (P.shape[0], S.size))]))


@njit(cache=True)
def _excess_from_start(P, i, o, t):
    """mbd.elements.drives._excess_from_start of the schedule packed in row i of P from column o."""
    m = int(P[i, o])
    if t <= P[i, o + 1]:
        f = P[i, o + 1 + m]
        return f, (f - 1.0) * (t - P[i, o + 1])
    if t >= P[i, o + m]:
        f = P[i, o + 2 * m]
        return f, P[i, o + 3 * m] + (f - 1.0) * (t - P[i, o + m])
    k = 0
    while P[i, o + 2 + k] <= t:
        k += 1
    tk, fk = P[i, o + 1 + k], P[i, o + 1 + m + k]
    f = fk + (P[i, o + 2 + m + k] - fk) * (t - tk) / (P[i, o + 2 + k] - tk)
    return f, P[i, o + 1 + 2 * m + k] + (t - tk) * ((fk - 1.0) + 0.5 * (f - fk))


@njit(cache=True)
def _schedule_at(P, i, o, t):
    """(f(t), ∫_0^t (f − 1) dτ): mbd.elements.drives.schedule_at, operation for operation."""
    f, e = _excess_from_start(P, i, o, t)
    return f, e - _excess_from_start(P, i, o, 0.0)[1]


@njit(cache=True)
def _zero_jacobians(Jq, Jv, i):
    for r in range(Jq.shape[1]):
        for c in range(Jq.shape[2]):
            Jq[i, r, c] = 0.0
            Jv[i, r, c] = 0.0


# ------------------------------------------------------------------------------------ GroundSupport
def pack_ground_support(elem: GroundSupport):
    P = _columns(elem.n, elem.kx, elem.ky, elem.cx, elem.cy, elem.anchor[:, 0], elem.anchor[:, 1],
                 elem.k_theta, elem.c_theta, elem.theta0)
    return P, np.array([1.0 if elem.isotropic else 0.0])


@njit(cache=True)
def evaluate_ground_support(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    c, s = np.cos(phi), np.sin(phi)
    W = omega
    iso = G[0] != 0.0
    for i in range(ql.shape[0]):
        kx, ky, cx, cy, ax, ay = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5]
        k_th, c_th, th0 = P[i, 6], P[i, 7], P[i, 8]
        x, y, th = ql[i, 0], ql[i, 1], ql[i, 2]
        # displacement from the anchor and ground-relative velocity, in R
        dx = x - (c * ax + s * ay)
        dy = y - (-s * ax + c * ay)
        ux = vl[i, 0] - W * y
        uy = vl[i, 1] + W * x
        if iso:
            F[i, 0] = -kx * dx - cx * ux
            F[i, 1] = -kx * dy - cx * uy
        else:  # the law is axis-aligned in I: rotate in, apply, rotate back
            dX, dY = c * dx - s * dy, s * dx + c * dy
            uX, uY = c * ux - s * uy, s * ux + c * uy
            FX = -kx * dX - cx * uX
            FY = -ky * dY - cy * uY
            F[i, 0] = c * FX + s * FY
            F[i, 1] = -s * FX + c * FY
        F[i, 2] = -k_th * (th + phi - th0) - c_th * (vl[i, 2] + W)
        if not jac:
            continue
        _zero_jacobians(Jq, Jv, i)
        if iso:   # u = v + Ω k × q: ∂ux/∂y = −Ω, ∂uy/∂x = Ω
            Jq[i, 0, 0], Jq[i, 0, 1] = -kx, cx * W
            Jq[i, 1, 0], Jq[i, 1, 1] = -cx * W, -kx
            Jv[i, 0, 0], Jv[i, 1, 1] = -cx, -cx
        else:
            # ∂(FX, FY)/∂(x, y) and ∂/∂(vx, vy), then rotated back to R
            aXx, aXy = -kx * c - cx * (-s * W), -kx * (-s) - cx * (-c * W)
            aYx, aYy = -ky * s - cy * (c * W), -ky * c - cy * (-s * W)
            bXx, bXy = -cx * c, -cx * (-s)
            bYx, bYy = -cy * s, -cy * c
            Jq[i, 0, 0], Jq[i, 0, 1] = c * aXx + s * aYx, c * aXy + s * aYy
            Jq[i, 1, 0], Jq[i, 1, 1] = -s * aXx + c * aYx, -s * aXy + c * aYy
            Jv[i, 0, 0], Jv[i, 0, 1] = c * bXx + s * bYx, c * bXy + s * bYy
            Jv[i, 1, 0], Jv[i, 1, 1] = -s * bXx + c * bYx, -s * bXy + c * bYy
        Jq[i, 2, 2] = -k_th
        Jv[i, 2, 2] = -c_th


# --------------------------------------------------------------------------------------- BodySpring
def pack_body_spring(elem: BodySpring):
    P = _columns(elem.n, elem.stiffness, elem.damping, elem.marker_a[:, 0], elem.marker_a[:, 1],
                 elem.marker_b[:, 0], elem.marker_b[:, 1])
    return P, _NO_G


@njit(cache=True)
def evaluate_body_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    # gradients over (q_a, q_b, v_a, v_b), 12 entries, allocated once
    gdx, gdy, gux, guy, gFx, gFy = np.zeros(12), np.zeros(12), np.zeros(12), np.zeros(12), np.zeros(12), np.zeros(12)
    for i in range(ql.shape[0]):
        k, cd = P[i, 0], P[i, 1]
        ca, sa = np.cos(ql[i, 2]), np.sin(ql[i, 2])
        cb, sb = np.cos(ql[i, 5]), np.sin(ql[i, 5])
        rax, ray = ca * P[i, 2] - sa * P[i, 3], sa * P[i, 2] + ca * P[i, 3]
        rbx, rby = cb * P[i, 4] - sb * P[i, 5], sb * P[i, 4] + cb * P[i, 5]
        wa, wb = vl[i, 2], vl[i, 5]
        dx = (ql[i, 3] + rbx) - (ql[i, 0] + rax)
        dy = (ql[i, 4] + rby) - (ql[i, 1] + ray)
        # ḋ_A: velocity of P_B relative to the point of A under it
        ux = (vl[i, 3] - wb * rby) - (vl[i, 0] - wa * ray) + wa * dy
        uy = (vl[i, 4] + wb * rbx) - (vl[i, 1] + wa * rax) - wa * dx
        Fx = -k * dx - cd * ux
        Fy = -k * dy - cd * uy
        F[i, 0] = -Fx
        F[i, 1] = -Fy
        F[i, 2] = (rax + dx) * (-Fy) - (ray + dy) * (-Fx)     # A is loaded at P_B
        F[i, 3] = Fx
        F[i, 4] = Fy
        F[i, 5] = rbx * Fy - rby * Fx
        if not jac:
            continue
        for j in range(12):
            gdx[j] = gdy[j] = gux[j] = guy[j] = 0.0
        # ∂r/∂θ = k × r
        gdx[0], gdx[2], gdx[3], gdx[5] = -1.0, ray, 1.0, -rby
        gdy[1], gdy[2], gdy[4], gdy[5] = -1.0, -rax, 1.0, rbx
        for j in range(6):
            gux[j] = wa * gdy[j]
            guy[j] = -wa * gdx[j]
        gux[2] += wa * rax
        gux[5] += -wb * rbx
        guy[2] += wa * ray
        guy[5] += -wb * rby
        gux[6], gux[8], gux[9], gux[11] = -1.0, ray + dy, 1.0, -rby
        guy[7], guy[8], guy[10], guy[11] = -1.0, -rax - dx, 1.0, rbx
        for j in range(12):
            gFx[j] = -k * gdx[j] - cd * gux[j]
            gFy[j] = -k * gdy[j] - cd * guy[j]
        for j in range(12):
            J, col = (Jq, j) if j < 6 else (Jv, j - 6)
            # ∂r_a/∂θ_a and ∂r_b/∂θ_b enter the torques' lever arms
            drax = -ray if j == 2 else 0.0
            dray = rax if j == 2 else 0.0
            drbx = -rby if j == 5 else 0.0
            drby = rbx if j == 5 else 0.0
            J[i, 0, col] = -gFx[j]
            J[i, 1, col] = -gFy[j]
            J[i, 2, col] = (-(drax + gdx[j]) * Fy - (rax + dx) * gFy[j]
                            + (dray + gdy[j]) * Fx + (ray + dy) * gFx[j])
            J[i, 3, col] = gFx[j]
            J[i, 4, col] = gFy[j]
            J[i, 5, col] = drbx * Fy + rbx * gFy[j] - drby * Fx - rby * gFx[j]


# ---------------------------------------------------------------------------------- TorsionalSpring
def pack_torsional_spring(elem: TorsionalSpring):
    return _columns(elem.n, elem.stiffness, elem.damping, elem.theta0), _NO_G


@njit(cache=True)
def evaluate_torsional_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    for i in range(ql.shape[0]):
        k, c = P[i, 0], P[i, 1]
        T = -k * (ql[i, 5] - ql[i, 2] - P[i, 2]) - c * (vl[i, 5] - vl[i, 2])
        zero = 0.0 * ql[i, 0]
        F[i, 0], F[i, 1], F[i, 2], F[i, 3], F[i, 4], F[i, 5] = zero, zero, -T, zero, zero, T
        if not jac:
            continue
        _zero_jacobians(Jq, Jv, i)
        Jq[i, 2, 2], Jq[i, 2, 5], Jq[i, 5, 2], Jq[i, 5, 5] = -k, k, k, -k
        Jv[i, 2, 2], Jv[i, 2, 5], Jv[i, 5, 2], Jv[i, 5, 5] = -c, c, c, -c


# ------------------------------------------------------------------------------------- TorqueSource
def pack_torque_source(elem: TorqueSource):
    if elem.fn is not None:
        raise NotImplementedError(f"TorqueSource {elem.name!r}: torque given as a Python callable of time "
                                  f"({elem.fn!r}) cannot be compiled (use a constant with a Ramp, or the numpy path)")
    return _with_schedule(_columns(elem.n, elem.torque), elem.schedule), _ramp_g("TorqueSource", elem, elem.ramp)


@njit(cache=True)
def evaluate_torque_source(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    r = _ramp(t, G)
    scheduled = P.shape[1] > 1
    for i in range(ql.shape[0]):
        T = P[i, 0] * r
        if scheduled:
            T = T * _schedule_at(P, i, 1, t)[0]
        F[i, 0], F[i, 1], F[i, 2] = 0.0, 0.0, T
        if jac:
            _zero_jacobians(Jq, Jv, i)


# -------------------------------------------------------------------------------------- ForceSource
def pack_force_source(elem: ForceSource):
    if elem.fn is not None:
        raise NotImplementedError(f"ForceSource {elem.name!r}: force given as a Python callable of time "
                                  f"({elem.fn!r}) cannot be compiled (use a constant with a Ramp, or the numpy path)")
    return _columns(elem.n, elem.force[:, 0], elem.force[:, 1]), _ramp_g("ForceSource", elem, elem.ramp)


@njit(cache=True)
def evaluate_force_source(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    r = _ramp(t, G)
    c, sn = np.cos(phi), np.sin(phi)
    for i in range(ql.shape[0]):
        FX, FY = r * P[i, 0], r * P[i, 1]
        F[i, 0], F[i, 1], F[i, 2] = c * FX + sn * FY, -sn * FX + c * FY, 0.0     # fixed frame → R
        if jac:
            _zero_jacobians(Jq, Jv, i)


# --------------------------------------------------------------------------------------- SpeedDrive
def pack_speed_drive(elem: SpeedDrive):
    if elem.omega_ref is None:
        raise NotImplementedError(f"SpeedDrive {elem.name!r}: speed profile {elem.profile!r} is a Python callable "
                                  "of time, which the compiled path cannot evaluate (use a constant omega_ref, or "
                                  "the numpy path)")
    P = _columns(elem.n, elem.stiffness, elem.damping, elem.k_i, elem.theta0, elem.omega_ref)
    return _with_schedule(P, elem.schedule), np.ascontiguousarray(elem.ripple.ravel())


@njit(cache=True)
def _ripple(t, G):
    """(Δθ_ref, Δω_ref) of the ripple harmonics in G, summed in SpeedDrive._rippled's order."""
    dth, dw = 0.0, 0.0
    for j in range(G.shape[0] // 3):
        Om, A, ph = G[3 * j], G[3 * j + 1], G[3 * j + 2]
        dth = dth + A / Om * np.sin(Om * t + ph)
        dw = dw + A * np.cos(Om * t + ph)
    return dth, dw


@njit(cache=True)
def _angle_error(t, phi, P, G, i, theta):
    if P.shape[1] > 5:                        # a speed schedule (never with ripple): θ0 + ω t + ω ∫(f − 1)
        return ((P[i, 3] + P[i, 4] * t) + P[i, 4] * _schedule_at(P, i, 5, t)[1]) - (theta + phi)
    if G.shape[0] == 0:                       # no ripple: the constant-speed reference, term for term
        return (P[i, 3] + P[i, 4] * t) - (theta + phi)
    return ((P[i, 3] + P[i, 4] * t) + _ripple(t, G)[0]) - (theta + phi)


@njit(cache=True)
def evaluate_speed_drive(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    has_z = z.shape[1] > 0
    dw = _ripple(t, G)[1]
    scheduled = P.shape[1] > 5
    for i in range(ql.shape[0]):
        e = _angle_error(t, phi, P, G, i, ql[i, 2])
        if scheduled:
            de = P[i, 4] * _schedule_at(P, i, 5, t)[0] - (vl[i, 2] + omega)
        else:
            de = (P[i, 4] + dw if G.shape[0] else P[i, 4]) - (vl[i, 2] + omega)
        T = P[i, 0] * e + P[i, 1] * de
        if has_z:
            T = T + P[i, 2] * z[i, 0]
        zero = 0.0 * ql[i, 0]
        F[i, 0], F[i, 1], F[i, 2] = zero, zero, T
        if jac:
            _zero_jacobians(Jq, Jv, i)
            Jq[i, 2, 2] = -P[i, 0]
            Jv[i, 2, 2] = -P[i, 1]


@njit(cache=True)
def update_speed_drive(z, t0, t1, ql0, vl0, ql1, vl1, P, G, phi0, phi1):
    """The integral of the angle error after a step (trapezoidal rule), as SpeedDrive.update_internal;
    phi0, phi1 the frame angle at t0 and t1."""
    z1 = z.copy()
    if z.shape[1] == 0:
        return z1
    for i in range(z.shape[0]):
        e0 = _angle_error(t0, phi0, P, G, i, ql0[i, 2])
        e1 = _angle_error(t1, phi1, P, G, i, ql1[i, 2])
        z1[i, 0] = z[i, 0] + 0.5 * (t1 - t0) * (e0 + e1)
    return z1



# ---------------------------------------------------------------------------------- SlopeGyroscopic
def pack_slope_gyroscopic(elem: SlopeGyroscopic):
    return _columns(elem.n, elem.polar_inertia), _NO_G


@njit(cache=True)
def evaluate_slope_gyroscopic(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    for i in range(ql.shape[0]):
        Jp = P[i, 0]
        H = Jp * (omega + vl[i, 0])
        ax = vl[i, 2] + omega * ql[i, 1]
        ay = vl[i, 1] - omega * ql[i, 2]
        F[i, 0], F[i, 1], F[i, 2] = 0.0 * ql[i, 0], -H * ax, H * ay
        if not jac:
            continue
        _zero_jacobians(Jq, Jv, i)
        Jq[i, 1, 1] = -H * omega
        Jq[i, 2, 2] = -H * omega
        Jv[i, 1, 0], Jv[i, 1, 2] = -Jp * ax, -H
        Jv[i, 2, 0], Jv[i, 2, 1] = Jp * ay, H


# --------------------------------------------------------------------------------- CoordinateSpring
def pack_coordinate_spring(elem: CoordinateSpring):
    return _columns(elem.n, elem.stiffness, elem.damping, elem.q0), _NO_G


@njit(cache=True)
def evaluate_coordinate_spring(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    for i in range(ql.shape[0]):
        F[i, 0] = -P[i, 0] * (ql[i, 0] - P[i, 2]) - P[i, 1] * vl[i, 0]
        if jac:
            Jq[i, 0, 0], Jv[i, 0, 0] = -P[i, 0], -P[i, 1]


# ------------------------------------------------------------------------------------------------ BeamSupport
def pack_beam_support(elem: BeamSupport):
    return _columns(elem.n, elem.marker_a[:, 0], elem.marker_a[:, 1], elem.k_uu, elem.k_us, elem.k_ss, elem.k_theta,
                    elem.c_u, elem.c_s, elem.c_theta), _NO_G


@njit(cache=True)
def evaluate_beam_support(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """BeamSupport's forces; its Jacobian column by column, the differential of every line along each of the 16
    unit directions of (q, v) (as mbd.compiled.sliced)."""
    dq, dv = np.zeros(8), np.zeros(8)
    for i in range(ql.shape[0]):
        mx, my, kuu, kus, kss, kth, cu, cs, cth = (P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5], P[i, 6],
                                                   P[i, 7], P[i, 8])
        xa, ya, tha, xb, yb, thb, sx, sy = (ql[i, 0], ql[i, 1], ql[i, 2], ql[i, 3], ql[i, 4], ql[i, 5], ql[i, 6],
                                            ql[i, 7])
        va0, va1, va2, vb0, vb1, vb2, vsx, vsy = (vl[i, 0], vl[i, 1], vl[i, 2], vl[i, 3], vl[i, 4], vl[i, 5],
                                                  vl[i, 6], vl[i, 7])
        ca, sa = np.cos(tha), np.sin(tha)
        rax, ray = ca * mx - sa * my, sa * mx + ca * my
        Vax, Vay = va0 - va2 * ray, va1 + va2 * rax
        dx, dy = xb - (xa + rax), yb - (ya + ray)
        udx, udy = vb0 - Vax + va2 * dy, vb1 - Vay - va2 * dx
        usx, usy = vsx + va2 * sy, vsy - va2 * sx
        Kx, Ky = -kuu * dx - kus * sx, -kuu * dy - kus * sy
        Cx, Cy = -cu * udx, -cu * udy
        Dx, Dy = -cs * usx, -cs * usy
        Mx, My = -kus * dx - kss * sx + Dx, -kus * dy - kss * sy + Dy
        T = -kth * (thb - tha) - cth * (vb2 - va2)
        ex, ey = rax + dx, ray + dy
        tA = -(rax * Ky - ray * Kx) - (ex * Cy - ey * Cx) + (Dx * sy - Dy * sx) - T
        F[i, 0], F[i, 1], F[i, 2], F[i, 3] = -(Kx + Cx), -(Ky + Cy), tA, Kx + Cx
        F[i, 4], F[i, 5], F[i, 6], F[i, 7] = Ky + Cy, T, Mx, My
        if not jac:
            continue
        for j in range(16):
            dq[:] = 0.0
            dv[:] = 0.0
            if j < 8:
                dq[j] = 1.0
            else:
                dv[j - 8] = 1.0
            drax, dray = -ray * dq[2], rax * dq[2]
            ddx, ddy = dq[3] - dq[0] - drax, dq[4] - dq[1] - dray
            dVax = dv[0] - dv[2] * ray - va2 * dray
            dVay = dv[1] + dv[2] * rax + va2 * drax
            dudx = dv[3] - dVax + dv[2] * dy + va2 * ddy
            dudy = dv[4] - dVay - dv[2] * dx - va2 * ddx
            dusx = dv[6] + dv[2] * sy + va2 * dq[7]
            dusy = dv[7] - dv[2] * sx - va2 * dq[6]
            dKx, dKy = -kuu * ddx - kus * dq[6], -kuu * ddy - kus * dq[7]
            dCx, dCy = -cu * dudx, -cu * dudy
            dDx, dDy = -cs * dusx, -cs * dusy
            dMx, dMy = -kus * ddx - kss * dq[6] + dDx, -kus * ddy - kss * dq[7] + dDy
            dT = -kth * (dq[5] - dq[2]) - cth * (dv[5] - dv[2])
            dex, dey = drax + ddx, dray + ddy
            dtA = (-(drax * Ky + rax * dKy - dray * Kx - ray * dKx) - (dex * Cy + ex * dCy - dey * Cx - ey * dCx)
                   + (dDx * sy + Dx * dq[7] - dDy * sx - Dy * dq[6]) - dT)
            J = Jq if j < 8 else Jv
            c = j if j < 8 else j - 8
            J[i, 0, c], J[i, 1, c], J[i, 2, c], J[i, 3, c] = -(dKx + dCx), -(dKy + dCy), dtA, dKx + dCx
            J[i, 4, c], J[i, 5, c], J[i, 6, c], J[i, 7, c] = dKy + dCy, dT, dMx, dMy
