"""Compiled kernel of the sliced roller–raceway contact (:class:`mbd.elements.sliced.SlicedRaceContact`,
docs/model.md §8.8), following the convention of :mod:`mbd.compiled`. The numpy kernel stays the reference.

Layout (one row of P per instance; G family-wide):

``SlicedRaceContact``  P (n, 13 + n_s): κ, race_marker x, y [m], pin_marker x, y [m], race slope s_0 x, y [rad],
                       R_race [m], D [m], K, c₀ = 2ζ·sqrt(m_roller·p·K), ζ_row [m], R_red [m], then the n_s profile
                       drops P_k [m];  G (11 + n_s,): exponent p, traction law id and coefficients (the race
                       contact's layout, :func:`mbd.compiled.contact.traction_g`), then the n_s slice stations z_k [m].
                       The local coordinates' count tells the kind: 7 inner, 12 outer.

How the Jacobian is made. The slice loop runs once per contact: it gives the slice loads and the sums the forces
need (Σ F_k, Σ z_k F_k, Σ ζ_k F_k, Q = Σ q_k, Σ z_k q_k) and, with ``jac``, the slices' derivative blocks summed
against the powers of z_k. Every slice's offset is w_k = (p − c) + z_k σ_r − ζ_k σ_c with ζ_k = ζ_row + z_k, so along
any direction its change is dw_k = A + z_k B (A = d(p − c) − ζ_row dσ_c, B = dσ_r − dσ_c), the same for its rate; the
slice force's change is dF_k = M_k dw_k + N_k dẇ_k with

    M_k = κ n_k g_kᵀ + κ q_k (I − n_k n_kᵀ)/d_k,   N_k = −(∂q_k/∂δ̇_k) n_k n_kᵀ,
    g_k = ∂q_k/∂w_k = −κ (∂q_k/∂δ_k n_k + ∂q_k/∂δ̇_k (ẇ_k − n_k (n_k·ẇ_k))/d_k),   ∂q_k/∂ẇ_k = −κ ∂q_k/∂δ̇_k n_k,

so d Σ z_k^m F_k = Σ z_k^m M_k A + Σ z_k^(m+1) M_k B + (the same with N_k and the rates): the moments m = 0, 1, 2 of
M_k, N_k and of the load gradients carry every slice into the contact's 2 n_local directions, which are then
contact-level scalars (the geometry of e, σ_r, σ_c, the traction law, the generalised forces; the differential of
every line of the reference evaluated along each unit direction, as :mod:`mbd.compiled.contact`). Exact, no
differencing; the values are the reference's in its operation order up to the order of the slice sums.

Contacts whose every slice is open by the reference's bound (δ_0 + max_k |z_k σ_r − ζ_k σ_c| ≤ 0) are skipped before
the slice loop; a contact without load has no force and (ad.where) no derivative.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.sliced import SlicedRaceContact
from .contact import EHL, _ehl_traction, _traction, traction_g

__all__ = ["pack_sliced_race", "evaluate_sliced_race", "SLICED_COLS"]

_ETA2 = 1e-24            # the reference's η² (mbd.elements.sliced._ETA2)
SLICED_COLS = 13         # P columns before the profile drops
_GZ = 11                 # G index of the first slice station


def pack_sliced_race(elem):
    if type(elem) is not SlicedRaceContact:
        raise NotImplementedError(f"{elem.name}: the compiled SlicedRaceContact kernel does not cover "
                                  f"{type(elem).__name__}")
    n = elem.n
    col = lambda a: np.broadcast_to(np.asarray(a, float), (n,))                       # noqa: E731
    cols = [col(elem.kappa), elem.race_marker[:, 0], elem.race_marker[:, 1], elem.pin_marker[:, 0],
            elem.pin_marker[:, 1], elem.race_slope[:, 0], elem.race_slope[:, 1], elem.R_race, elem.D, elem.K,
            elem._c0, elem.row_offset, elem.R_red]
    P = np.ascontiguousarray(np.column_stack([col(c) for c in cols] + [elem.drop]), dtype=np.float64)
    G = np.concatenate([traction_g(elem.name, elem.traction, elem.exponent), elem.z]).astype(np.float64)
    return P, G


@njit(cache=True)
def evaluate_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    p, law = G[0], int(G[1])
    pe = 0.5 * (p - 1.0)
    ns = G.shape[0] - _GZ
    zs = G[_GZ:]
    zmax = 0.0
    for k in range(ns):
        zmax = max(zmax, abs(zs[k]))
    nl = ql.shape[1]
    outer = nl == 12
    acc = np.zeros((3, 12))          # moments m = 0, 1, 2 of M_k (4), N_k (4), g_k (2), ∂q_k/∂ẇ_k (2)
    dq, dv = np.zeros(12), np.zeros(12)
    dS, dQm = np.zeros((2, 2)), np.zeros(2)
    for i in range(ql.shape[0]):
        kap, mx, my, pmx, pmy, s0x, s0y = P[i, 0], P[i, 1], P[i, 2], P[i, 3], P[i, 4], P[i, 5], P[i, 6]
        R, D, K, c0, row, Rr = P[i, 7], P[i, 8], P[i, 9], P[i, 10], P[i, 11], P[i, 12]
        xr, yr, tau = ql[i, 0], ql[i, 1], ql[i, 3]
        xb, yb, thb = ql[i, 4], ql[i, 5], ql[i, 6]
        vr0, vr1, vr2, dtau = vl[i, 0], vl[i, 1], vl[i, 2], vl[i, 3]
        vb0, vb1, vb2 = vl[i, 4], vl[i, 5], vl[i, 6]
        if outer:
            sx, sy, vsx, vsy = ql[i, 7], ql[i, 8], vl[i, 7], vl[i, 8]
            xp, yp, thp, vp0, vp1, vp2 = ql[i, 9], ql[i, 10], ql[i, 11], vl[i, 9], vl[i, 10], vl[i, 11]
        else:
            sx, sy, vsx, vsy = 0.0, 0.0, 0.0, 0.0
            xp, yp, thp, vp0, vp1, vp2 = xb, yb, thb, vb0, vb1, vb2
        # the raceway's centre and its velocity; the pin's centre and its velocity (SlicedRaceContact._geometry)
        cb, sb = np.cos(thb), np.sin(thb)
        rcx, rcy = cb * mx - sb * my, sb * mx + cb * my
        cx, cy = xb + rcx, yb + rcy
        Vcx, Vcy = vb0 - vb2 * rcy, vb1 + vb2 * rcx
        cp, sp = np.cos(thp), np.sin(thp)
        rpx, rpy = cp * pmx - sp * pmy, sp * pmx + cp * pmy
        pcx, pcy = xp + rpx, yp + rpy
        Vpx, Vpy = vp0 - vp2 * rpy, vp1 + vp2 * rpx
        # e: pin centre → roller centre, and ė
        ux, uy = xr - pcx, yr - pcy
        rho_p = np.sqrt(ux * ux + uy * uy + _ETA2)
        ex, ey = ux / rho_p, uy / rho_p
        gx, gy = vr0 - Vpx, vr1 - Vpy
        ge = ex * gx + ey * gy
        edx, edy = (gx - ge * ex) / rho_p, (gy - ge * ey) / rho_p
        # the race's slope σ_c and its rate; k0 = ∂σ_c/∂θ_b turned (the θ_b force's lever)
        s0cx, s0cy = cb * s0x - sb * s0y, sb * s0x + cb * s0y
        scx, scy = s0cx + sx, s0cy + sy
        dscx, dscy = -1.0 * vb2 * s0cy + vsx, vb2 * s0cx + vsy
        k0x, k0y = s0cy, -1.0 * s0cx
        srx, sry = tau * ex, tau * ey
        dsrx, dsry = dtau * ex + tau * edx, dtau * ey + tau * edy
        pcx_, pcy_ = xr - cx, yr - cy
        wvx, wvy = vr0 - Vcx, vr1 - Vcy
        for j in range(F.shape[1]):
            F[i, j] = 0.0
        if jac:
            for a in range(nl):
                for b in range(nl):
                    Jq[i, a, b] = 0.0
                    Jv[i, a, b] = 0.0
        # the open bound (SlicedRaceContact._open_bound)
        delta0 = 0.5 * D - kap * (np.sqrt(pcx_ * pcx_ + pcy_ * pcy_) - R)
        reach = zmax * abs(tau) + (abs(row) + zmax) * np.sqrt(scx * scx + scy * scy)
        if delta0 + reach <= 0.0:
            continue
        # the slice loop
        S0x, S0y, S1x, S1y, S2x, S2y, Q, Qz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if jac:
            acc[:, :] = 0.0
        Ks, c0s = K / ns, c0 / ns
        for k in range(ns):
            zk = zs[k]
            zeta = row + zk
            wx = pcx_ + zk * srx - zeta * scx
            wy = pcy_ + zk * sry - zeta * scy
            vwx = wvx + zk * dsrx - zeta * dscx
            vwy = wvy + zk * dsry - zeta * dscy
            d = np.sqrt(wx * wx + wy * wy + _ETA2)
            nx, ny = wx / d, wy / d
            delta = 0.5 * D - kap * (d - R) - P[i, SLICED_COLS + k]
            if not delta > 0.0:
                continue
            nv = nx * vwx + ny * vwy
            delta_dot = -kap * nv
            dpe = delta ** pe
            q = Ks * delta ** p + c0s * dpe * delta_dot
            if not q > 0.0:
                continue
            Fx, Fy = kap * q * nx, kap * q * ny
            S0x += Fx
            S0y += Fy
            S1x += zk * Fx
            S1y += zk * Fy
            S2x += zeta * Fx
            S2y += zeta * Fy
            Q += q
            Qz += zk * q
            if not jac:
                continue
            q_d = Ks * p * delta ** (p - 1.0) + c0s * pe * delta ** (pe - 1.0) * delta_dot     # ∂q/∂δ
            q_r = c0s * dpe                                                                   # ∂q/∂δ̇
            hx, hy = (vwx - nx * nv) / d, (vwy - ny * nv) / d
            gqx, gqy = -kap * (q_d * nx + q_r * hx), -kap * (q_d * ny + q_r * hy)
            gvx, gvy = -kap * q_r * nx, -kap * q_r * ny
            qd = kap * q / d
            m00 = kap * nx * gqx + qd * (1.0 - nx * nx)
            m01 = kap * nx * gqy - qd * nx * ny
            m10 = kap * ny * gqx - qd * nx * ny
            m11 = kap * ny * gqy + qd * (1.0 - ny * ny)
            zm = 1.0
            for m in range(3):
                acc[m, 0] += zm * m00
                acc[m, 1] += zm * m01
                acc[m, 2] += zm * m10
                acc[m, 3] += zm * m11
                acc[m, 4] += zm * (kap * nx * gvx)
                acc[m, 5] += zm * (kap * nx * gvy)
                acc[m, 6] += zm * (kap * ny * gvx)
                acc[m, 7] += zm * (kap * ny * gvy)
                acc[m, 8] += zm * gqx
                acc[m, 9] += zm * gqy
                acc[m, 10] += zm * gvx
                acc[m, 11] += zm * gvy
                zm *= zk
        if not Q > 0.0:
            continue
        # traction as the planar contact's on Q, applied at the load centroid z̄
        rho = np.sqrt(pcx_ * pcx_ + pcy_ * pcy_ + _ETA2)
        ecx, ecy = pcx_ / rho, pcy_ / rho
        tx, ty = -ecy, ecx
        rl = R - rho
        rrx, rry = rl * ecx, rl * ecy
        rbx, rby = rcx + R * ecx, rcy + R * ecy
        Vrx, Vry = vr0 - vr2 * rry, vr1 + vr2 * rrx
        Vbx, Vby = vb0 - vb2 * rby, vb1 + vb2 * rbx
        ur, ub = Vrx * tx + Vry * ty, Vbx * tx + Vby * ty
        v_s = ur - ub
        wt = wvx * tx + wvy * ty
        u_e = 0.5 * (ur + ub) - (Vcx * tx + Vcy * ty + R * wt / rho)
        mu_Q = 0.0
        if law == EHL:
            mu, mu_s, mu_u, mu_Q = _ehl_traction(G, v_s, u_e, Q, Rr)
        else:
            mu, mu_s, mu_u = _traction(law, G, v_s, u_e)
        Ft = -mu * Q
        Ftx, Fty = Ft * tx, Ft * ty
        zbar = Qz / Q
        T1x, T1y = S1x + zbar * Ftx, S1y + zbar * Fty
        T2x, T2y = S2x + (zbar + row) * Ftx, S2y + (zbar + row) * Fty
        s1e = ex * T1x + ey * T1y
        Gx, Gy = tau * (T1x - s1e * ex) / rho_p, tau * (T1y - s1e * ey) / rho_p
        F[i, 0] = S0x + Gx + Ftx
        F[i, 1] = S0y + Gy + Fty
        F[i, 2] = rrx * Fty - rry * Ftx
        F[i, 3] = s1e
        F[i, 4] = -S0x - Ftx
        F[i, 5] = -S0y - Fty
        F[i, 6] = -(rcx * S0y - rcy * S0x) + (rbx * (-Fty) - rby * (-Ftx)) + (T2x * k0x + T2y * k0y)
        pin_t = -(rpx * Gy - rpy * Gx)
        if outer:
            F[i, 7], F[i, 8] = -T2x, -T2y
            F[i, 9], F[i, 10], F[i, 11] = -Gx, -Gy, pin_t
        else:
            F[i, 4] += -Gx
            F[i, 5] += -Gy
            F[i, 6] += pin_t
        if not jac:
            continue
        # every direction: position (j < nl) and velocity (j ≥ nl) unit vectors of the local coordinates
        for j in range(2 * nl):
            dq[:] = 0.0
            dv[:] = 0.0
            if j < nl:
                dq[j] = 1.0
            else:
                dv[j - nl] = 1.0
            dxr, dyr, dta, dxb, dyb, dthb = dq[0], dq[1], dq[3], dq[4], dq[5], dq[6]
            dvr0, dvr1, dvr2, ddta, dvb0, dvb1, dvb2 = dv[0], dv[1], dv[2], dv[3], dv[4], dv[5], dv[6]
            if outer:
                dsx, dsy, dvsx, dvsy = dq[7], dq[8], dv[7], dv[8]
                dxp, dyp, dthp, dvp0, dvp1, dvp2 = dq[9], dq[10], dq[11], dv[9], dv[10], dv[11]
            else:
                dsx, dsy, dvsx, dvsy = 0.0, 0.0, 0.0, 0.0
                dxp, dyp, dthp, dvp0, dvp1, dvp2 = dxb, dyb, dthb, dvb0, dvb1, dvb2
            drcx, drcy = -dthb * rcy, dthb * rcx
            dVcx = dvb0 - dvb2 * rcy - vb2 * drcy
            dVcy = dvb1 + dvb2 * rcx + vb2 * drcx
            drpx, drpy = -dthp * rpy, dthp * rpx
            dVpx = dvp0 - dvp2 * rpy - vp2 * drpy
            dVpy = dvp1 + dvp2 * rpx + vp2 * drpx
            dux, duy = dxr - (dxp + drpx), dyr - (dyp + drpy)
            drho_p = (ux * dux + uy * duy) / rho_p
            dex, dey = (dux - ex * drho_p) / rho_p, (duy - ey * drho_p) / rho_p
            dgx, dgy = dvr0 - dVpx, dvr1 - dVpy
            dge = dex * gx + ex * dgx + dey * gy + ey * dgy
            dedx = (dgx - dge * ex - ge * dex - edx * drho_p) / rho_p
            dedy = (dgy - dge * ey - ge * dey - edy * drho_p) / rho_p
            ds0cx, ds0cy = -dthb * s0cy, dthb * s0cx
            dscx_ = ds0cx + dsx
            dscy_ = ds0cy + dsy
            ddscx = -dvb2 * s0cy - vb2 * ds0cy + dvsx
            ddscy = dvb2 * s0cx + vb2 * ds0cx + dvsy
            dk0x, dk0y = ds0cy, -ds0cx
            dsrx_, dsry_ = dta * ex + tau * dex, dta * ey + tau * dey
            ddsrx = ddta * ex + dtau * dex + dta * edx + tau * dedx
            ddsry = ddta * ey + dtau * dey + dta * edy + tau * dedy
            ddx, ddy = dxr - (dxb + drcx), dyr - (dyb + drcy)          # d(p − c)
            dwvx, dwvy = dvr0 - dVcx, dvr1 - dVcy                      # d(ṗ − ċ)
            Ax, Ay = ddx - row * dscx_, ddy - row * dscy_
            Bx, By = dsrx_ - dscx_, dsry_ - dscy_
            Avx, Avy = dwvx - row * ddscx, dwvy - row * ddscy
            Bvx, Bvy = ddsrx - ddscx, ddsry - ddscy
            # d Σ z^m F_k and d Σ z^m q_k, m = 0, 1
            for m in range(2):
                a0, a1 = acc[m], acc[m + 1]
                dS[m, 0] = (a0[0] * Ax + a0[1] * Ay + a1[0] * Bx + a1[1] * By
                            + a0[4] * Avx + a0[5] * Avy + a1[4] * Bvx + a1[5] * Bvy)
                dS[m, 1] = (a0[2] * Ax + a0[3] * Ay + a1[2] * Bx + a1[3] * By
                            + a0[6] * Avx + a0[7] * Avy + a1[6] * Bvx + a1[7] * Bvy)
                dQm[m] = (a0[8] * Ax + a0[9] * Ay + a1[8] * Bx + a1[9] * By
                          + a0[10] * Avx + a0[11] * Avy + a1[10] * Bvx + a1[11] * Bvy)
            dS0x, dS0y, dS1x, dS1y = dS[0, 0], dS[0, 1], dS[1, 0], dS[1, 1]
            dS2x, dS2y = row * dS0x + dS1x, row * dS0y + dS1y
            dQ, dQz = dQm[0], dQm[1]
            # traction
            drho = (pcx_ * ddx + pcy_ * ddy) / rho
            decx, decy = (ddx - ecx * drho) / rho, (ddy - ecy * drho) / rho
            dtx, dty = -decy, decx
            drrx, drry = -drho * ecx + rl * decx, -drho * ecy + rl * decy
            drbx, drby = drcx + R * decx, drcy + R * decy
            dVrx, dVry = dvr0 - dvr2 * rry - vr2 * drry, dvr1 + dvr2 * rrx + vr2 * drrx
            dVbx, dVby = dvb0 - dvb2 * rby - vb2 * drby, dvb1 + dvb2 * rbx + vb2 * drbx
            dur = dVrx * tx + Vrx * dtx + dVry * ty + Vry * dty
            dub = dVbx * tx + Vbx * dtx + dVby * ty + Vby * dty
            dwt = dwvx * tx + wvx * dtx + dwvy * ty + wvy * dty
            dvP = dVcx * tx + Vcx * dtx + dVcy * ty + Vcy * dty + R * (dwt - wt * drho / rho) / rho
            du = 0.5 * (dur + dub) - dvP
            dmu = mu_s * (dur - dub) + mu_u * du + mu_Q * dQ
            dFt = -(dmu * Q + mu * dQ)
            dFtx, dFty = dFt * tx + Ft * dtx, dFt * ty + Ft * dty
            dzbar = (dQz - zbar * dQ) / Q
            dT1x = dS1x + dzbar * Ftx + zbar * dFtx
            dT1y = dS1y + dzbar * Fty + zbar * dFty
            dT2x = dS2x + dzbar * Ftx + (zbar + row) * dFtx
            dT2y = dS2y + dzbar * Fty + (zbar + row) * dFty
            ds1e = dex * T1x + ex * dT1x + dey * T1y + ey * dT1y
            dGx = (dta * (T1x - s1e * ex) + tau * (dT1x - ds1e * ex - s1e * dex) - Gx * drho_p) / rho_p
            dGy = (dta * (T1y - s1e * ey) + tau * (dT1y - ds1e * ey - s1e * dey) - Gy * drho_p) / rho_p
            f0 = dS0x + dGx + dFtx
            f1 = dS0y + dGy + dFty
            f2 = drrx * Fty + rrx * dFty - drry * Ftx - rry * dFtx
            f4, f5 = -dS0x - dFtx, -dS0y - dFty
            f6 = (-(drcx * S0y + rcx * dS0y - drcy * S0x - rcy * dS0x)
                  - (drbx * Fty + rbx * dFty - drby * Ftx - rby * dFtx)
                  + dT2x * k0x + T2x * dk0x + dT2y * k0y + T2y * dk0y)
            dpin = -(drpx * Gy + rpx * dGy - drpy * Gx - rpy * dGx)
            J = Jq if j < nl else Jv
            c = j if j < nl else j - nl
            J[i, 0, c], J[i, 1, c], J[i, 2, c], J[i, 3, c] = f0, f1, f2, ds1e
            if outer:
                J[i, 4, c], J[i, 5, c], J[i, 6, c] = f4, f5, f6
                J[i, 7, c], J[i, 8, c] = -dT2x, -dT2y
                J[i, 9, c], J[i, 10, c], J[i, 11, c] = -dGx, -dGy, dpin
            else:
                J[i, 4, c], J[i, 5, c], J[i, 6, c] = f4 - dGx, f5 - dGy, f6 + dpin
