"""Compiled kernel of the sliced roller–raceway contact (:class:`mbd.elements.sliced.SlicedRaceContact`,
docs/model.md §8.8), following the convention of :mod:`mbd.compiled`. The numpy kernel stays the reference.

Layout (one row of P per instance; G family-wide):

``SlicedRaceContact``  P (n, 13 + n_s): κ, race_marker x, y [m], pin_marker x, y [m], race slope s_0 x, y [rad],
                       R_race [m], D [m], K, c₀ = 2ζ·sqrt(m_roller·p·K), ζ_row [m], R_red [m], then the n_s profile
                       drops P_k [m];  G (11 + n_s,): exponent p, traction law id and coefficients (the race
                       contact's layout, :func:`mbd.compiled.contact.traction_g`), then the n_s slice stations z_k [m].
                       The local coordinates' count tells the layout: 7 an inner raceway on a rigid pin, 12
                       a raceway with its body's slope pair (the bore; an elastic pin's raceway, κ = +1).

One law, two kernels: :func:`evaluate_sliced_race` (forces, Jacobian) and :func:`outputs_sliced_race` (the outputs the
statistics read) take the law from the same small helpers (the section "the sliced race's law" below: the contact pass
with a contact's geometry and open bound, a slice's offset, rate and load, the contact point's speeds, the traction
coefficient), inlined into each kernel's loops; the contact pass is one compiled function both call.

How the kernel runs. Two passes over the contacts. The first takes each contact's geometry (kept for the second) and,
unless the reference's bound finds every slice open (δ_0 + max_k |z_k σ_r − ζ_k σ_c| ≤ 0: the contact is skipped),
every slice's offset and compression δ_k. Between the passes the slices' powers δ_k^((p−1)/2) of all the contacts at
once (:func:`_slice_roots`). The second pass gives each contact's slice loads (open slices masked, no branches) and
the sums the forces need (Σ F_k, Σ z_k F_k, Σ ζ_k F_k, Q = Σ q_k, Σ z_k q_k) and, with ``jac``, the slices'
derivative blocks summed against the powers of z_k; a contact without load has no force and (ad.where) no derivative.

The power. δ^p = δ (δ^((p−1)/2))², one power a slice shared by the load, its damping and their derivatives. When
(p − 1)/2 = 1/m for an integer m ≤ 31 (Palmgren's p = 10/9: m = 18) it is the m-th root by Halley's iteration on
y^m = δ from a start read off δ's bits (:func:`_root_start`, :func:`_root_halley`): arithmetic only, so the
compiler runs it in SIMD lanes over every loaded slice of the family, where np.power is a library call per slice. It
is the m-th root within 1.5 ulp from 1e-300 to 1e300 (tests/mbd/test_compiled_sliced.py, against a long-double
root); any other p, and δ outside that range, take np.power.

How the Jacobian is made. Every slice's offset is w_k = (p − c) + z_k σ_r − ζ_k σ_c with ζ_k = ζ_row + z_k, so along
any direction its change is dw_k = A + z_k B (A = d(p − c) − ζ_row dσ_c, B = dσ_r − dσ_c), the same for its rate; the
slice force's change is dF_k = M_k dw_k + N_k dẇ_k with

    M_k = κ n_k g_kᵀ + κ q_k (I − n_k n_kᵀ)/d_k,   N_k = −(∂q_k/∂δ̇_k) n_k n_kᵀ,
    g_k = ∂q_k/∂w_k = −κ (∂q_k/∂δ_k n_k + ∂q_k/∂δ̇_k (ẇ_k − n_k (n_k·ẇ_k))/d_k),   ∂q_k/∂ẇ_k = −κ ∂q_k/∂δ̇_k n_k,

so d Σ z_k^m F_k = Σ z_k^m M_k A + Σ z_k^(m+1) M_k B + (the same with N_k and the rates): the moments m = 0, 1, 2 of
M_k, N_k and of the load gradients carry every slice into the contact's 2 n_local directions, which are then
contact-level scalars (the geometry of e, σ_r, σ_c, the traction law, the generalised forces; the differential of
every line of the reference evaluated along each unit direction, as :mod:`mbd.compiled.contact`). Exact, no
differencing; the values are the reference's up to the order of the slice sums and the power's last bit. The
directions use the law's structure, as the planar race contact's: the velocity directions leave the geometry
unchanged and carry only the rate terms (a pass of their own); the roller's angle enters no force (its column is
zero); and a common translation (or velocity) of roller, race body and pin changes no force, so the roller's
translation columns are the negated sum of the race body's and the pin's (outer raceway; the inner raceway's pin is
its race body, whose columns are then the roller's negated). Each pass is a loop of a fixed count (16 directions for
an outer contact, 8 for an inner one; those past its n_local zero) without branches, which the compiler runs in SIMD
lanes; the derived columns are then overwritten.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.gear_mesh import SlicedGearMesh
from ..elements.sliced import SlicedRaceContact
from . import mesh, tooth_pairs
from .contact import EHL, _ehl_traction, _traction, traction_g

__all__ = ["pack_sliced_race", "evaluate_sliced_race", "pack_sliced_gear_mesh", "evaluate_sliced_gear_mesh",
           "SLICED_COLS", "MESH_EXTRA", "outputs_sliced_race", "SLICED_RACE_OUTPUTS", "sliced_race_output_names"]

_TWO_PI = 2.0 * np.pi

_ETA2 = 1e-24            # the reference's η² (mbd.elements.sliced._ETA2)
SLICED_COLS = 13         # P columns before the profile drops
_GZ = 11                 # G index of the first slice station
_NGEO = 48               # a contact's geometry the kernel's second pass reads


def pack_sliced_race(elem):
    if type(elem) is not SlicedRaceContact:
        raise NotImplementedError(f"{elem.name}: the compiled SlicedRaceContact kernel does not cover "
                                  f"{type(elem).__name__}")
    n = elem.n
    col = lambda a: np.broadcast_to(np.asarray(a, float), (n,))                       # noqa: E731
    cols = [col(elem.kappa), elem.race_marker[:, 0], elem.race_marker[:, 1], elem.pin_marker[:, 0],
            elem.pin_marker[:, 1], elem.race_slope[:, 0], elem.race_slope[:, 1], elem.R_race, elem.D, elem.K,
            elem._c0, elem.row_offset, elem.R_red]
    # the damping ramp δ_c after the profile drops (column SLICED_COLS + n_s)
    P = np.ascontiguousarray(np.column_stack([col(c) for c in cols] + [elem.drop, col(elem.damping_ramp)]),
                             dtype=np.float64)
    G = np.concatenate([traction_g(elem.name, elem.traction, elem.exponent), elem.z]).astype(np.float64)
    return P, G


@njit(cache=True)
def _zero(F, Jq, Jv, i, jac):
    """A contact without load: no force and (ad.where) no derivative."""
    nl = F.shape[1]
    for a in range(nl):
        F[i, a] = 0.0
        if jac:
            for b in range(nl):
                Jq[i, a, b] = 0.0
                Jv[i, a, b] = 0.0


@njit(cache=True)
def _moments(acc, blocks, ns, zs):
    """acc[m, :] = Σ_k z_k^m · blocks[k, :] over the slices k (an open slice's block is zero), m = 0, 1, 2 (a loop over
    the 12 columns inside: SIMD)."""
    acc[:, :] = 0.0
    for k in range(ns):
        zk = zs[k]
        z2 = zk * zk
        for c in range(12):
            x = blocks[k, c]
            acc[0, c] += x
            acc[1, c] += zk * x
            acc[2, c] += z2 * x


# δ^(1/m) by Halley's iteration (the slices' δ^((p−1)/2) when (p − 1)/2 = 1/m, Palmgren's p = 10/9: m = 18)
_ONE_BITS = 0x3FF0000000000000                  # the bits of 1.0
_ROOT_LO, _ROOT_HI = 1e-300, 1e300              # the iteration's range of x (y^m neither under- nor overflows)
_START_SHIFT = int(0.043 * 2.0 ** 52)           # centres the start's error (±0.045 in log2, 3.2 %)
_ROOT_MAX = 31                                  # the largest m of the iteration (p ≥ 1 + 2/31)
_LANES = 8                                      # the roots' buffers are padded to a multiple of a SIMD width


@njit(cache=True)
def root_index(pe):
    """m when pe = 1/m for an integer 1 ≤ m ≤ 31 (to 1e-12), else 0 (the slices then take np.power)."""
    if not pe > 0.0:
        return 0
    m = int(round(1.0 / pe))
    if m < 1 or m > _ROOT_MAX or abs(m * pe - 1.0) > 1e-12:
        return 0
    return m


@njit(cache=True, inline="always")
def _ipow(y, m):
    """y^m for 1 ≤ m ≤ 31 by squaring, without branches on y (a select per bit of m: SIMD)."""
    r, b = 1.0, y
    for bit in range(5):
        if (m >> bit) & 1:
            r = r * b
        b = b * b
    return r


@njit(cache=True, error_model="numpy")
def _root_start(xb, yb, n, inv_m):
    """A start for x^(1/m) from the bits of x: a positive double's bits read as an integer are 2^52 (log2 x + 1023)
    up to [−0.086, 0] in the log2 (the mantissa read linearly); their offset from 1.0's divided by m and read back
    give x^(1/m) within [−0.005, 0.086] in the log2, which the shift centres (±0.045, 3.2 %)."""
    for k in range(n):
        yb[k] = _ONE_BITS - _START_SHIFT + np.int64((xb[k] - _ONE_BITS) * inv_m)


@njit(cache=True, error_model="numpy")
def _root_halley(x, y, n, m):
    """Three Halley steps on y^m = x from the start, each a correction to y (its relative error ε → about
    (m² − 1)/12 ε³: 3.2 % → 3e-3 → 2e-6 → round-off for m ≤ 31; tests/mbd/test_compiled_sliced.py checks every m
    against a long-double root)."""
    a, b = m - 1.0, m + 1.0
    for k in range(n):
        xk, yk = x[k], y[k]
        for _ in range(3):
            ym = _ipow(yk, m)
            yk = yk - (2.0 * (ym - xk)) * (yk / (b * ym + a * xk))
        y[k] = yk


@njit(cache=True, error_model="numpy")
def _slice_roots(delta, x, y, rows, ns, npad, m, pe):
    """y[r npad + k] = δ[r, k]^pe for the rows r < rows of the slices' δ (x, y: flat buffers of rows of npad ≥ ns, a
    multiple of the SIMD width; an open slice's is anything finite). With m = root_index(pe) > 0 by Halley's
    iteration over all rows at once (vectorised: x^(1/m) within about an ulp, tests/mbd/test_compiled_sliced.py);
    else, and for a δ > 0 outside [1e-300, 1e300], np.power."""
    if m == 0:
        for r in range(rows):
            for k in range(ns):
                d = delta[r, k]
                y[r * npad + k] = d ** pe if d > 0.0 else 1.0
        return
    for r in range(rows):
        o = r * npad
        for k in range(ns):
            d = delta[r, k]
            d = d if d > _ROOT_LO else _ROOT_LO
            x[o + k] = d if d < _ROOT_HI else _ROOT_HI
        for k in range(ns, npad):
            x[o + k] = 1.0
    n = rows * npad
    _root_start(x.view(np.int64), y.view(np.int64), n, 1.0 / m)
    _root_halley(x, y, n, m)
    for r in range(rows):
        for k in range(ns):
            d = delta[r, k]
            if d > 0.0 and (d < _ROOT_LO or d > _ROOT_HI):
                y[r * npad + k] = d ** pe


@njit(cache=True)
def _u(j, m):
    return 1.0 if j == m else 0.0


@njit(cache=True)
def _derived_cols(Jq, Jv, i, outer):
    """The columns the direction passes leave out: the roller's angle (no force depends on it) and the translations
    a common one of roller, race body and pin gives (outer: the roller's = −(race body's + pin's); inner, whose pin
    is the race body: the race body's = −the roller's)."""
    for a in range(Jq.shape[1]):
        Jq[i, a, 2] = 0.0
        if outer:
            Jq[i, a, 0] = -(Jq[i, a, 4] + Jq[i, a, 9])
            Jq[i, a, 1] = -(Jq[i, a, 5] + Jq[i, a, 10])
            Jv[i, a, 0] = -(Jv[i, a, 4] + Jv[i, a, 9])
            Jv[i, a, 1] = -(Jv[i, a, 5] + Jv[i, a, 10])
        else:
            Jq[i, a, 4] = -Jq[i, a, 0]
            Jq[i, a, 5] = -Jq[i, a, 1]
            Jv[i, a, 4] = -Jv[i, a, 0]
            Jv[i, a, 5] = -Jv[i, a, 1]


@njit(cache=True)
def _race_cols(J, i, cols, outer):
    """Instance i's block (J_q or J_v) from a pass's columns: the roller's, the race body's, the race's slopes' and the
    pin's rows (inner: the pin is the race body, its rows added to the race body's)."""
    nl = J.shape[2]
    for c in range(nl):
        J[i, 0, c], J[i, 1, c], J[i, 2, c], J[i, 3, c] = cols[0, c], cols[1, c], cols[2, c], cols[3, c]
    if outer:
        for c in range(nl):
            J[i, 4, c], J[i, 5, c], J[i, 6, c] = cols[4, c], cols[5, c], cols[6, c]
            J[i, 7, c], J[i, 8, c] = -cols[7, c], -cols[8, c]
            J[i, 9, c], J[i, 10, c], J[i, 11, c] = -cols[9, c], -cols[10, c], cols[11, c]
    else:
        for c in range(nl):
            J[i, 4, c] = cols[4, c] - cols[9, c]
            J[i, 5, c] = cols[5, c] - cols[10, c]
            J[i, 6, c] = cols[6, c] + cols[11, c]


# ------------------------------------------------------------------------------------------- the sliced race's law
# One owner of SlicedRaceContact.kernel's law for the two kernels that take it, evaluate_sliced_race (the generalised
# forces and their Jacobian) and outputs_sliced_race (the outputs): the family's constants (_law), a contact's geometry
# (in the contact pass) and the open bound (_open), a slice's offset and compression (_slice_offset), its rate
# (_slice_rate), its load and the load's partials (_slice_load, _slice_load_partials), a contact's slices
# (_slice_pass: the compressions of every contact, their powers at once; _slice_loads, _slice_sums), the contact
# point's speeds (_rolling) and the traction coefficient (_coefficient). Inlined where they are called (each kernel
# compiles them into its own loops, SIMD where the slices run) but _law and _slice_pass, once a call: one compile
# serves both kernels (its flag a run-time bool, np.bool_(...), not a literal that would compile it twice).

@njit(cache=True)
def _law(G):
    """The family's law from G: (p, the traction law's id, (p − 1)/2, n_s, the slice stations z_k, max_k |z_k|)."""
    p = G[0]
    ns = G.shape[0] - _GZ
    zs = G[_GZ:]
    zmax = 0.0
    for k in range(ns):
        zmax = max(zmax, abs(zs[k]))
    return p, int(G[1]), 0.5 * (p - 1.0), ns, zs, zmax


@njit(cache=True, inline="always", error_model="numpy")
def _open(kap, R, D, row, zmax, tau, scx, scy, pcx, pcy):
    """SlicedRaceContact._open_bound: every slice certainly open, δ_0 + max_k |z_k σ_r − ζ_k σ_c| ≤ 0."""
    delta0 = 0.5 * D - kap * (np.sqrt(pcx * pcx + pcy * pcy) - R)
    reach = zmax * abs(tau) + (abs(row) + zmax) * np.sqrt(scx * scx + scy * scy)
    return delta0 + reach <= 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _slice_offset(pcx, pcy, srx, sry, scx, scy, zk, zeta, kap, R, D, drop):
    """Slice k's offset w_k = (p − c) + z_k σ_r − ζ_k σ_c, d_k = |w_k| (the safe norm) and compression
    δ_k = D/2 − κ(d_k − R) − P_k (the profile drop P_k)."""
    wx = pcx + zk * srx - zeta * scx
    wy = pcy + zk * sry - zeta * scy
    d = np.sqrt(wx * wx + wy * wy + _ETA2)
    return wx, wy, d, 0.5 * D - kap * (d - R) - drop


@njit(cache=True, inline="always", error_model="numpy")
def _slice_rate(wvx, wvy, dsrx, dsry, dscx, dscy, zk, zeta, nx, ny, kap):
    """Slice k's offset rate ẇ_k = (ṗ − ċ) + z_k σ̇_r − ζ_k σ̇_c, n_k·ẇ_k and the compression rate δ̇_k = −κ n_k·ẇ_k."""
    vwx = wvx + zk * dsrx - zeta * dscx
    vwy = wvy + zk * dsry - zeta * dscy
    nv = nx * vwx + ny * vwy
    return vwx, vwy, nv, -kap * nv


@njit(cache=True, inline="always", error_model="numpy")
def _slice_load(Ks, c0s, ramp, delta, dpe, delta_dot):
    """Slice k's load q_k = (K/n_s) δ^p + (c₀/n_s) δ^((p−1)/2) S(δ/δ_c) δ̇ for δ > 0, clipped at ≥ 0, else 0, from
    dpe = δ^((p−1)/2) (δ^p = δ dpe²; open slices masked); S the damping share over the ramp δ_c
    (:func:`.tooth_pairs.damping_share`; 1 without a ramp)."""
    S = tooth_pairs.damping_share(delta, ramp)[0] if ramp > 0.0 else 1.0
    q_raw = Ks * (delta * (dpe * dpe)) + c0s * dpe * S * delta_dot
    return q_raw if (delta > 0.0) & (q_raw > 0.0) else 0.0


@njit(cache=True, inline="always", error_model="numpy")
def _slice_load_partials(Ks, c0s, ramp, p, pe, delta, dpe, delta_dot, q):
    """∂q/∂δ and ∂q/∂δ̇ of :func:`_slice_load` at its load q (zero where it is: ad.where)."""
    on = q > 0.0
    q_d = Ks * p * (dpe * dpe) + c0s * pe * (dpe / delta) * delta_dot
    q_r = c0s * dpe
    if ramp > 0.0:                                   # with the damping share S(δ/δ_c)
        S, dS = tooth_pairs.damping_share(delta, ramp)
        q_d = Ks * p * (dpe * dpe) + c0s * (pe * (dpe / delta) * S + dpe * dS) * delta_dot
        q_r = c0s * dpe * S
    return (q_d if on else 0.0), (q_r if on else 0.0)


@njit(cache=True, inline="always", error_model="numpy")
def _contact_pass(P, ql, vl, zs, zmax, every, slot, geo, w_x, w_y, w_d, w_delta):
    """The first pass over the contacts: each one's geometry (SlicedRaceContact._geometry) — the raceway's centre
    offset rc (its marker turned) and velocity V_c; the pin's rp; u = p − pin centre, ρ_p = |u|, e = u/ρ_p,
    g = ṗ − V_pin, g·e and ė = (I − e eᵀ) g/ρ_p; the bore error s_0 turned (s0c), the race's slope σ_c = s0c + s and its
    rate; k0 = −k × s0c (the θ_b force's lever); the roller's slope σ_r = τ e and its rate; p − c and ṗ − V_c — and the
    open bound (:func:`_open`). A contact the bound finds loaded (with ``every``, any contact) takes the next row r: its
    geometry into geo[r] (:func:`_geometry`'s layout) and its slices' offsets and compressions (:func:`_slice_offset`)
    into row r of w_x, w_y, w_d, w_delta. slot[i]: r (loaded), −2 − r (open, with ``every``) or −1 (open, no row).
    Returns the rows taken. (The geometry is written out in the loop: an inlined helper returning its 32 values cost
    ≈ 18 ns a contact more, 7 % of a residual call.)"""
    n, ns = ql.shape[0], zs.shape[0]
    outer = ql.shape[1] == 12
    thb_last, cb, sb, thp_last, cp, sp = np.nan, 0.0, 0.0, np.nan, 0.0, 0.0
    rows = 0
    for i in range(n):
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
        # the raceway's centre and its velocity; the pin's centre and its velocity
        if thb != thb_last:              # a bearing's contacts follow each other: one race body's, one pin's angle
            thb_last, cb, sb = thb, np.cos(thb), np.sin(thb)
        rcx, rcy = cb * mx - sb * my, sb * mx + cb * my
        cx, cy = xb + rcx, yb + rcy
        Vcx, Vcy = vb0 - vb2 * rcy, vb1 + vb2 * rcx
        if thp != thp_last:
            thp_last, cp, sp = thp, np.cos(thp), np.sin(thp)
        rpx, rpy = cp * pmx - sp * pmy, sp * pmx + cp * pmy
        qpx, qpy = xp + rpx, yp + rpy
        Vpx, Vpy = vp0 - vp2 * rpy, vp1 + vp2 * rpx
        # e: pin centre → roller centre, and ė
        ux, uy = xr - qpx, yr - qpy
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
        # the roller's slope σ_r = τ e and its rate; p − c and ṗ − V_c
        srx, sry = tau * ex, tau * ey
        dsrx, dsry = dtau * ex + tau * edx, dtau * ey + tau * edy
        pcx, pcy = xr - cx, yr - cy
        wvx, wvy = vr0 - Vcx, vr1 - Vcy
        shut = _open(kap, R, D, row, zmax, tau, scx, scy, pcx, pcy)
        if shut and not every:
            slot[i] = -1
            continue
        r = rows
        slot[i] = -2 - r if shut else r
        rows += 1
        # what the second pass reads, in _geometry's order (stores one by one: a loop over a tuple costs twice as much)
        geo[r, 0], geo[r, 1], geo[r, 2], geo[r, 3], geo[r, 4], geo[r, 5] = kap, R, D, K, c0, row
        geo[r, 6], geo[r, 7], geo[r, 8], geo[r, 9], geo[r, 10], geo[r, 11] = Rr, tau, vr0, vr1, vr2, dtau
        geo[r, 12], geo[r, 13], geo[r, 14], geo[r, 15], geo[r, 16], geo[r, 17] = vb0, vb1, vb2, vp2, rcx, rcy
        geo[r, 18], geo[r, 19], geo[r, 20], geo[r, 21], geo[r, 22], geo[r, 23] = Vcx, Vcy, rpx, rpy, ux, uy
        geo[r, 24], geo[r, 25], geo[r, 26], geo[r, 27], geo[r, 28], geo[r, 29] = rho_p, ex, ey, gx, gy, ge
        geo[r, 30], geo[r, 31], geo[r, 32], geo[r, 33], geo[r, 34], geo[r, 35] = edx, edy, s0cx, s0cy, scx, scy
        geo[r, 36], geo[r, 37], geo[r, 38], geo[r, 39], geo[r, 40], geo[r, 41] = dscx, dscy, k0x, k0y, srx, sry
        geo[r, 42], geo[r, 43], geo[r, 44], geo[r, 45], geo[r, 46], geo[r, 47] = dsrx, dsry, pcx, pcy, wvx, wvy
        for k in range(ns):          # every slice's offset and compression: a loop without branches (SIMD)
            zk = zs[k]
            w_x[r, k], w_y[r, k], w_d[r, k], w_delta[r, k] = _slice_offset(pcx, pcy, srx, sry, scx, scy, zk, row + zk,
                                                                           kap, R, D, P[i, SLICED_COLS + k])
    return rows


@njit(cache=True, inline="always")
def _geometry(geo, r):
    """Row r of geo (:func:`_contact_pass`): κ, R, D, K, c₀, ζ_row, R_red, τ, the roller's velocities (ṗ, ω_r, τ̇),
    the race body's, the pin's ω, then the geometry of :func:`_contact_pass` (rc, V_c, rp, u, ρ_p, e, g, g·e, ė, s0c, σ_c,
    σ̇_c, k0, σ_r, σ̇_r, p − c, ṗ − V_c)."""
    g = geo[r]
    return (g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g[8], g[9], g[10], g[11], g[12], g[13], g[14], g[15],
            g[16], g[17], g[18], g[19], g[20], g[21], g[22], g[23], g[24], g[25], g[26], g[27], g[28], g[29], g[30],
            g[31], g[32], g[33], g[34], g[35], g[36], g[37], g[38], g[39], g[40], g[41], g[42], g[43], g[44], g[45],
            g[46], g[47])


@njit(cache=True, error_model="numpy")
def _slice_pass(P, ql, vl, zs, zmax, pe, every):
    """Every contact's geometry and its slices' compressions (:func:`_contact_pass`), then the slices' powers
    δ_k^((p−1)/2) of all the rows at once (:func:`_slice_roots`): (slot, geo, w_x, w_y, w_d, w_delta, the powers (row
    r's at r·npad), npad)."""
    n, ns = ql.shape[0], zs.shape[0]
    npad = -(-ns // _LANES) * _LANES
    slot, geo = np.empty(n, np.int64), np.empty((n, _NGEO))
    w_x, w_y, w_d, w_delta = np.empty((n, ns)), np.empty((n, ns)), np.empty((n, ns)), np.empty((n, ns))
    w_c, w_root = np.empty(n * npad), np.empty(n * npad)     # δ clipped to the root's range, δ^((p−1)/2)
    rows = _contact_pass(P, ql, vl, zs, zmax, every, slot, geo, w_x, w_y, w_d, w_delta)
    _slice_roots(w_delta, w_c, w_root, rows, ns, npad, root_index(pe), pe)
    return slot, geo, w_x, w_y, w_d, w_delta, w_root, npad


@njit(cache=True, inline="always", error_model="numpy")
def _slice_loads(r, o, zs, kap, Ks, c0s, ramp, row, wvx, wvy, dsrx, dsry, dscx, dscy, w_x, w_y, w_d, w_delta, w_root, w_q,
                 w_Fx, w_Fy):
    """Row r's slice loads q_k (:func:`_slice_load`; its powers from w_root[o:]) into w_q and the slice forces on the
    roller F_k = κ q_k n_k into w_Fx, w_Fy: a loop without branches (SIMD)."""
    for k in range(zs.shape[0]):
        zk = zs[k]
        d = w_d[r, k]
        nx, ny = w_x[r, k] / d, w_y[r, k] / d
        delta_dot = _slice_rate(wvx, wvy, dsrx, dsry, dscx, dscy, zk, row + zk, nx, ny, kap)[3]
        q = _slice_load(Ks, c0s, ramp, w_delta[r, k], w_root[o + k], delta_dot)
        w_q[k] = q
        w_Fx[k], w_Fy[k] = kap * q * nx, kap * q * ny


@njit(cache=True, inline="always", error_model="numpy")
def _slice_sums(zs, row, w_q, w_Fx, w_Fy):
    """Σ F_k, Σ z_k F_k, Σ ζ_k F_k, Q = Σ q_k and Σ z_k q_k, in the slices' order."""
    S0x, S0y, S1x, S1y, S2x, S2y, Q, Qz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for k in range(zs.shape[0]):
        zk, Fx, Fy, q = zs[k], w_Fx[k], w_Fy[k], w_q[k]
        zeta = row + zk
        S0x += Fx
        S0y += Fy
        S1x += zk * Fx
        S1y += zk * Fy
        S2x += zeta * Fx
        S2y += zeta * Fy
        Q += q
        Qz += zk * q
    return S0x, S0y, S1x, S1y, S2x, S2y, Q, Qz


@njit(cache=True, inline="always", error_model="numpy")
def _rolling(R, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, pcx, pcy, wvx, wvy):
    """The traction's kinematics, as the planar contact's (SlicedRaceContact.kernel): ρ = |p − c|, e_c, the tangent
    t = k × e_c, the contact point's lever from the roller's centre r_r = (R − ρ) e_c and from the race body's
    r_b = rc + R e_c, their velocities V_r, V_b, the tangential speeds u_r, u_b, (ṗ − V_c)·t, the slip v_s = u_r − u_b
    and the rolling speed u_e = (u_r + u_b)/2 − the contact point's own tangential speed."""
    rho = np.sqrt(pcx * pcx + pcy * pcy + _ETA2)
    ecx, ecy = pcx / rho, pcy / rho
    tx, ty = -ecy, ecx
    rl = R - rho
    rrx, rry = rl * ecx, rl * ecy
    rbx, rby = rcx + R * ecx, rcy + R * ecy
    Vrx, Vry = vr0 - vr2 * rry, vr1 + vr2 * rrx
    Vbx, Vby = vb0 - vb2 * rby, vb1 + vb2 * rbx
    ur, ub = Vrx * tx + Vry * ty, Vbx * tx + Vby * ty
    wt = wvx * tx + wvy * ty
    u_e = 0.5 * (ur + ub) - (Vcx * tx + Vcy * ty + R * wt / rho)
    return rho, ecx, ecy, tx, ty, rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, wt, ur - ub, u_e


@njit(cache=True, inline="always", error_model="numpy")
def _coefficient(law, G, v_s, u_e, Q, Rr):
    """The traction coefficient μ on the load Q and its partials ∂μ/∂v_s, ∂μ/∂u_e, ∂μ/∂Q (the race contact's laws,
    :mod:`mbd.compiled.contact`)."""
    if law == EHL:
        return _ehl_traction(G, v_s, u_e, Q, Rr)
    mu, mu_s, mu_u = _traction(law, G, v_s, u_e)
    return mu, mu_s, mu_u, 0.0


@njit(cache=True, error_model="numpy")
def evaluate_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    p, law, pe, ns, zs, zmax = _law(G)
    nl = ql.shape[1]
    outer = nl == 12
    js0, js1 = (7, 8) if outer else (-1, -1)            # the race's slope pair's columns (none: inner, rigid pin)
    jp0, jp1, jp2 = (9, 10, 11) if outer else (4, 5, 6)  # the pin body's (inner: the race body is the pin)
    # a pass's columns (f0 … f6, dT2x, dT2y, dGx, dGy, dpin): every direction of a SIMD width's multiple jn ≥ nl, those
    # past nl zero, the derived ones overwritten (_derived_cols): a loop of a fixed count without branches (SIMD)
    jn = 16 if outer else 8
    cols = np.empty((12, 16))
    acc = np.zeros((3, 12))          # moments m = 0, 1, 2 of M_k (4), N_k (4), g_k (2), ∂q_k/∂ẇ_k (2)
    # every contact's geometry and slice compressions, then their powers all at once (the SIMD lanes full)
    slot, geo, w_x, w_y, w_d, w_delta, w_root, npad = _slice_pass(P, ql, vl, zs, zmax, pe, np.bool_(False))
    w_q, w_Fx, w_Fy = np.empty(ns), np.empty(ns), np.empty(ns)
    blocks = np.empty((ns if jac else 0, 12))           # the slices' derivative blocks (zero: open)
    for i in range(ql.shape[0]):
        r = slot[i]
        if r < 0:
            _zero(F, Jq, Jv, i, jac)
            continue
        (kap, R, D, K, c0, row, Rr, tau, vr0, vr1, vr2, dtau, vb0, vb1, vb2, vp2, rcx, rcy, Vcx, Vcy, rpx, rpy, ux,
         uy, rho_p, ex, ey, gx, gy, ge, edx, edy, s0cx, s0cy, scx, scy, dscx, dscy, k0x, k0y, srx, sry, dsrx, dsry,
         pcx_, pcy_, wvx, wvy) = _geometry(geo, r)
        Ks, c0s = K / ns, c0 / ns
        ramp = P[i, SLICED_COLS + ns]                   # the damping share's δ_c (0: none, the law as written)
        o = r * npad
        _slice_loads(r, o, zs, kap, Ks, c0s, ramp, row, wvx, wvy, dsrx, dsry, dscx, dscy, w_x, w_y, w_d, w_delta, w_root, w_q,
                     w_Fx, w_Fy)
        if jac:
            for k in range(ns):      # the slices' derivative blocks (zero: open), a loop of its own (SIMD)
                zk, q = zs[k], w_q[k]
                d = w_d[r, k]
                nx, ny = w_x[r, k] / d, w_y[r, k] / d
                vwx, vwy, nv, delta_dot = _slice_rate(wvx, wvy, dsrx, dsry, dscx, dscy, zk, row + zk, nx, ny, kap)
                q_d, q_r = _slice_load_partials(Ks, c0s, ramp, p, pe, w_delta[r, k], w_root[o + k], delta_dot, q)
                i_d = 1.0 / d
                hx, hy = (vwx - nx * nv) * i_d, (vwy - ny * nv) * i_d
                gqx, gqy = -kap * (q_d * nx + q_r * hx), -kap * (q_d * ny + q_r * hy)
                gvx, gvy = -kap * q_r * nx, -kap * q_r * ny
                qd = kap * q * i_d
                blocks[k, 0] = kap * nx * gqx + qd * (1.0 - nx * nx)
                blocks[k, 1] = kap * nx * gqy - qd * nx * ny
                blocks[k, 2] = kap * ny * gqx - qd * nx * ny
                blocks[k, 3] = kap * ny * gqy + qd * (1.0 - ny * ny)
                blocks[k, 4], blocks[k, 5] = kap * nx * gvx, kap * nx * gvy
                blocks[k, 6], blocks[k, 7] = kap * ny * gvx, kap * ny * gvy
                blocks[k, 8], blocks[k, 9], blocks[k, 10], blocks[k, 11] = gqx, gqy, gvx, gvy
        S0x, S0y, S1x, S1y, S2x, S2y, Q, Qz = _slice_sums(zs, row, w_q, w_Fx, w_Fy)
        if not Q > 0.0:
            _zero(F, Jq, Jv, i, jac)
            continue
        if jac:
            _moments(acc, blocks, ns, zs)
        # traction as the planar contact's on Q, applied at the load centroid z̄
        (rho, ecx, ecy, tx, ty, rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, wt, v_s,
         u_e) = _rolling(R, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, pcx_, pcy_, wvx, wvy)
        mu, mu_s, mu_u, mu_Q = _coefficient(law, G, v_s, u_e, Q, Rr)
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
        a0_0, a0_1, a0_2, a0_3, a0_4, a0_5, a0_6, a0_7, a0_8, a0_9, a0_10, a0_11 = (
            acc[0, 0], acc[0, 1], acc[0, 2], acc[0, 3], acc[0, 4], acc[0, 5],
            acc[0, 6], acc[0, 7], acc[0, 8], acc[0, 9], acc[0, 10], acc[0, 11])
        a1_0, a1_1, a1_2, a1_3, a1_4, a1_5, a1_6, a1_7, a1_8, a1_9, a1_10, a1_11 = (
            acc[1, 0], acc[1, 1], acc[1, 2], acc[1, 3], acc[1, 4], acc[1, 5],
            acc[1, 6], acc[1, 7], acc[1, 8], acc[1, 9], acc[1, 10], acc[1, 11])
        a2_0, a2_1, a2_2, a2_3, a2_4, a2_5, a2_6, a2_7, a2_8, a2_9, a2_10, a2_11 = (
            acc[2, 0], acc[2, 1], acc[2, 2], acc[2, 3], acc[2, 4], acc[2, 5],
            acc[2, 6], acc[2, 7], acc[2, 8], acc[2, 9], acc[2, 10], acc[2, 11])
        irp, irho, iQ = 1.0 / rho_p, 1.0 / rho, 1.0 / Q
        # Positions (no velocity moves along them). The roller's angle (column 2) enters no force. The forces see the
        # roller, the race body and the pin only through their relative positions: a common translation changes
        # nothing, so the roller's translation columns are the race body's and the pin's negated and summed (outer:
        # computed from them; inner, whose pin is the race body: the race body's are the roller's negated, exactly).
        for j in range(jn):
            dxr, dyr, dta, dxb, dyb, dthb = _u(j, 0), _u(j, 1), _u(j, 3), _u(j, 4), _u(j, 5), _u(j, 6)
            dsx, dsy, dxp, dyp, dthp = _u(j, js0), _u(j, js1), _u(j, jp0), _u(j, jp1), _u(j, jp2)
            drcx, drcy = -dthb * rcy, dthb * rcx
            dVcx, dVcy = -vb2 * drcy, vb2 * drcx
            drpx, drpy = -dthp * rpy, dthp * rpx
            dVpx, dVpy = -vp2 * drpy, vp2 * drpx
            dux, duy = dxr - (dxp + drpx), dyr - (dyp + drpy)
            drho_p = (ux * dux + uy * duy) * irp
            dex, dey = (dux - ex * drho_p) * irp, (duy - ey * drho_p) * irp
            dgx, dgy = -dVpx, -dVpy
            dge = dex * gx + ex * dgx + dey * gy + ey * dgy
            dedx = (dgx - dge * ex - ge * dex - edx * drho_p) * irp
            dedy = (dgy - dge * ey - ge * dey - edy * drho_p) * irp
            ds0cx, ds0cy = -dthb * s0cy, dthb * s0cx
            dscx_ = ds0cx + dsx
            dscy_ = ds0cy + dsy
            ddscx, ddscy = -vb2 * ds0cy, vb2 * ds0cx
            dk0x, dk0y = ds0cy, -ds0cx
            dsrx_, dsry_ = dta * ex + tau * dex, dta * ey + tau * dey
            ddsrx = dtau * dex + dta * edx + tau * dedx
            ddsry = dtau * dey + dta * edy + tau * dedy
            ddx, ddy = dxr - (dxb + drcx), dyr - (dyb + drcy)          # d(p − c)
            dwvx, dwvy = -dVcx, -dVcy                                  # d(ṗ − ċ)
            Ax, Ay = ddx - row * dscx_, ddy - row * dscy_
            Bx, By = dsrx_ - dscx_, dsry_ - dscy_
            Avx, Avy = dwvx - row * ddscx, dwvy - row * ddscy
            Bvx, Bvy = ddsrx - ddscx, ddsry - ddscy
            # d Σ z^m F_k and d Σ z^m q_k, m = 0, 1 (the moments as scalars: no array views in this loop)
            dS0x = (a0_0 * Ax + a0_1 * Ay + a1_0 * Bx + a1_1 * By
                  + a0_4 * Avx + a0_5 * Avy + a1_4 * Bvx + a1_5 * Bvy)
            dS0y = (a0_2 * Ax + a0_3 * Ay + a1_2 * Bx + a1_3 * By
                  + a0_6 * Avx + a0_7 * Avy + a1_6 * Bvx + a1_7 * Bvy)
            dQ = (a0_8 * Ax + a0_9 * Ay + a1_8 * Bx + a1_9 * By
                  + a0_10 * Avx + a0_11 * Avy + a1_10 * Bvx + a1_11 * Bvy)
            dS1x = (a1_0 * Ax + a1_1 * Ay + a2_0 * Bx + a2_1 * By
                  + a1_4 * Avx + a1_5 * Avy + a2_4 * Bvx + a2_5 * Bvy)
            dS1y = (a1_2 * Ax + a1_3 * Ay + a2_2 * Bx + a2_3 * By
                  + a1_6 * Avx + a1_7 * Avy + a2_6 * Bvx + a2_7 * Bvy)
            dQz = (a1_8 * Ax + a1_9 * Ay + a2_8 * Bx + a2_9 * By
                  + a1_10 * Avx + a1_11 * Avy + a2_10 * Bvx + a2_11 * Bvy)
            dS2x, dS2y = row * dS0x + dS1x, row * dS0y + dS1y
            # traction
            drho = (pcx_ * ddx + pcy_ * ddy) * irho
            decx, decy = (ddx - ecx * drho) * irho, (ddy - ecy * drho) * irho
            dtx, dty = -decy, decx
            drrx, drry = -drho * ecx + rl * decx, -drho * ecy + rl * decy
            drbx, drby = drcx + R * decx, drcy + R * decy
            dVrx, dVry = -vr2 * drry, vr2 * drrx
            dVbx, dVby = -vb2 * drby, vb2 * drbx
            dur = dVrx * tx + Vrx * dtx + dVry * ty + Vry * dty
            dub = dVbx * tx + Vbx * dtx + dVby * ty + Vby * dty
            dwt = dwvx * tx + wvx * dtx + dwvy * ty + wvy * dty
            dvP = dVcx * tx + Vcx * dtx + dVcy * ty + Vcy * dty + R * (dwt - wt * drho * irho) * irho
            du = 0.5 * (dur + dub) - dvP
            dmu = mu_s * (dur - dub) + mu_u * du + mu_Q * dQ
            dFt = -(dmu * Q + mu * dQ)
            dFtx, dFty = dFt * tx + Ft * dtx, dFt * ty + Ft * dty
            dzbar = (dQz - zbar * dQ) * iQ
            dT1x = dS1x + dzbar * Ftx + zbar * dFtx
            dT1y = dS1y + dzbar * Fty + zbar * dFty
            dT2x = dS2x + dzbar * Ftx + (zbar + row) * dFtx
            dT2y = dS2y + dzbar * Fty + (zbar + row) * dFty
            ds1e = dex * T1x + ex * dT1x + dey * T1y + ey * dT1y
            dGx = (dta * (T1x - s1e * ex) + tau * (dT1x - ds1e * ex - s1e * dex) - Gx * drho_p) * irp
            dGy = (dta * (T1y - s1e * ey) + tau * (dT1y - ds1e * ey - s1e * dey) - Gy * drho_p) * irp
            f0 = dS0x + dGx + dFtx
            f1 = dS0y + dGy + dFty
            f2 = drrx * Fty + rrx * dFty - drry * Ftx - rry * dFtx
            f4, f5 = -dS0x - dFtx, -dS0y - dFty
            f6 = (-(drcx * S0y + rcx * dS0y - drcy * S0x - rcy * dS0x)
                  - (drbx * Fty + rbx * dFty - drby * Ftx - rby * dFtx)
                  + dT2x * k0x + T2x * dk0x + dT2y * k0y + T2y * dk0y)
            dpin = -(drpx * Gy + rpx * dGy - drpy * Gx - rpy * dGx)
            cols[0, j], cols[1, j], cols[2, j], cols[3, j], cols[4, j], cols[5, j] = f0, f1, f2, ds1e, f4, f5
            cols[6, j], cols[7, j], cols[8, j], cols[9, j], cols[10, j], cols[11, j] = f6, dT2x, dT2y, dGx, dGy, dpin
        _race_cols(Jq, i, cols, outer)
        # Velocities: they leave the geometry (e, σ_c's turn, the contact point, the levers) and move only the rates.
        # A common velocity of the roller, the race body and the pin changes no force (as for the positions).
        for j in range(jn):
            dvr0, dvr1, dvr2, ddta, dvb0, dvb1, dvb2 = _u(j, 0), _u(j, 1), _u(j, 2), _u(j, 3), _u(j, 4), _u(j, 5), _u(j, 6)
            dvsx, dvsy, dvp0, dvp1, dvp2 = _u(j, js0), _u(j, js1), _u(j, jp0), _u(j, jp1), _u(j, jp2)
            dVcx, dVcy = dvb0 - dvb2 * rcy, dvb1 + dvb2 * rcx
            dVpx, dVpy = dvp0 - dvp2 * rpy, dvp1 + dvp2 * rpx
            dgx, dgy = dvr0 - dVpx, dvr1 - dVpy
            dge = ex * dgx + ey * dgy
            dedx, dedy = (dgx - dge * ex) * irp, (dgy - dge * ey) * irp
            ddscx, ddscy = -dvb2 * s0cy + dvsx, dvb2 * s0cx + dvsy
            ddsrx, ddsry = ddta * ex + tau * dedx, ddta * ey + tau * dedy
            dwvx, dwvy = dvr0 - dVcx, dvr1 - dVcy                      # d(ṗ − ċ)
            Avx, Avy = dwvx - row * ddscx, dwvy - row * ddscy
            Bvx, Bvy = ddsrx - ddscx, ddsry - ddscy
            dS0x = a0_4 * Avx + a0_5 * Avy + a1_4 * Bvx + a1_5 * Bvy
            dS0y = a0_6 * Avx + a0_7 * Avy + a1_6 * Bvx + a1_7 * Bvy
            dQ = a0_10 * Avx + a0_11 * Avy + a1_10 * Bvx + a1_11 * Bvy
            dS1x = a1_4 * Avx + a1_5 * Avy + a2_4 * Bvx + a2_5 * Bvy
            dS1y = a1_6 * Avx + a1_7 * Avy + a2_6 * Bvx + a2_7 * Bvy
            dQz = a1_10 * Avx + a1_11 * Avy + a2_10 * Bvx + a2_11 * Bvy
            dS2x, dS2y = row * dS0x + dS1x, row * dS0y + dS1y
            dVrx, dVry = dvr0 - dvr2 * rry, dvr1 + dvr2 * rrx
            dVbx, dVby = dvb0 - dvb2 * rby, dvb1 + dvb2 * rbx
            dur = dVrx * tx + dVry * ty
            dub = dVbx * tx + dVby * ty
            dwt = dwvx * tx + dwvy * ty
            dvP = dVcx * tx + dVcy * ty + R * dwt * irho
            du = 0.5 * (dur + dub) - dvP
            dmu = mu_s * (dur - dub) + mu_u * du + mu_Q * dQ
            dFt = -(dmu * Q + mu * dQ)
            dFtx, dFty = dFt * tx, dFt * ty
            dzbar = (dQz - zbar * dQ) * iQ
            dT1x = dS1x + dzbar * Ftx + zbar * dFtx
            dT1y = dS1y + dzbar * Fty + zbar * dFty
            dT2x = dS2x + dzbar * Ftx + (zbar + row) * dFtx
            dT2y = dS2y + dzbar * Fty + (zbar + row) * dFty
            ds1e = ex * dT1x + ey * dT1y
            dGx = tau * (dT1x - ds1e * ex) * irp
            dGy = tau * (dT1y - ds1e * ey) * irp
            f0 = dS0x + dGx + dFtx
            f1 = dS0y + dGy + dFty
            f2 = rrx * dFty - rry * dFtx
            f4, f5 = -dS0x - dFtx, -dS0y - dFty
            f6 = -(rcx * dS0y - rcy * dS0x) - (rbx * dFty - rby * dFtx) + dT2x * k0x + dT2y * k0y
            dpin = -(rpx * dGy - rpy * dGx)
            cols[0, j], cols[1, j], cols[2, j], cols[3, j], cols[4, j], cols[5, j] = f0, f1, f2, ds1e, f4, f5
            cols[6, j], cols[7, j], cols[8, j], cols[9, j], cols[10, j], cols[11, j] = f6, dT2x, dT2y, dGx, dGy, dpin
        _race_cols(Jv, i, cols, outer)
        _derived_cols(Jq, Jv, i, outer)


# ------------------------------------------------------------------------------------------------ SlicedGearMesh
# P: the GearMesh layout (mbd.compiled.mesh: its eccentricity and tooth-pair blocks when the family has them), then 4
# columns: face width b [m], slices n_m, gear 1 has slopes (1/0), gear 2 has slopes (1/0);  G: the GearMesh layout.
MESH_EXTRA = 4


def pack_sliced_gear_mesh(elem):
    if type(elem) is not SlicedGearMesh:
        raise NotImplementedError(f"{elem.name}: the compiled SlicedGearMesh kernel does not cover "
                                  f"{type(elem).__name__}")
    P, G = mesh.pack_gear_mesh(elem)
    n = elem.n
    extra = np.column_stack([elem.face_width, np.full(n, float(elem.n_m)), np.full(n, float(elem.has1)),
                             np.full(n, float(elem.has2))])
    return np.ascontiguousarray(np.hstack([P, extra])), G


@njit(cache=True)
def evaluate_sliced_gear_mesh(t, phi, omega, domega, ql, vl, z, P, G, F, Jq, Jv, jac):
    """The face-sliced mesh law (SlicedGearMesh.kernel, docs/model.md §6.6) and its exact Jacobian. Without
    eccentricity the law on the body centres (:func:`_sliced_meshes`); with it (G[G_OFFSET] ≥ 0) on the geometric
    centres c + R(θ)·o, the forces and Jacobians mapped back to the body coordinates by the chain rule as the
    unsliced mesh's (mbd.compiled.mesh._to_geometric, _from_geometric; the slopes are the same coordinates in both)."""
    off = int(G[mesh.G_OFFSET])
    if off < 0:
        _sliced_meshes(ql, vl, P, G, F, Jq, Jv, jac)
        return
    n, nl = ql.shape
    qg, vg, r, Fg = ql.copy(), vl.copy(), np.empty((n, 4)), np.empty((n, nl))
    Jqg, Jvg = np.empty((n if jac else 0, nl, nl)), np.empty((n if jac else 0, nl, nl))
    mesh._to_geometric(ql, vl, P, off, qg, vg, r)
    _sliced_meshes(qg, vg, P, G, Fg, Jqg, Jvg, jac)
    mesh._from_geometric(Fg, Jqg, Jvg, r, vl, F, Jq, Jv, jac)


@njit(cache=True, inline="always")
def _unit(p, q):
    return 1.0 if p == q else 0.0


@njit(cache=True)
def _sliced_meshes(ql, vl, P, G, F, Jq, Jv, jac):
    """The face-sliced law at local coordinates ql, rates vl (body or geometric centres): the slice loop once per
    flank, its derivative blocks summed against the powers of ζ_k, then the differential of every line of the reference
    at the mesh level along the law's own directions (δd = σ(d2 − d1), θ1, θ2, Δs = s2 − s1 and their rates): every
    column of the local coordinates is a ±1 multiple of one of them, exactly. Lumped law: a slice's force is
    (k(p)/n_m) δ_k + (c_m/n_m) S δ̇_k, its derivative blocks ∂F_k/∂δ_k, ∂F_k/∂δ̇_k and (for k(p)) δ_k. Tooth-pair law
    (G[G_PAIRS] ≥ 0): the pairs' stiffness, gaps and roll coordinate u are the mesh's (every slice has its mesh's
    teeth: :func:`.tooth_pairs.pair_setup` once per flank), each slice their sum at its own δ_k, δ̇_k with 1/n_m of
    the stiffness and damping (:func:`.tooth_pairs.pair_force`), and the blocks gain ∂F_k/∂u and ∂F_k/∂u̇, moved along
    a direction by du = z_1/2π (dθ_1 − dφ_e) and du̇ = z_1/2π (dω_1 − d(t·ḋ/a))."""
    shape, pcol, tstart = int(G[mesh.G_SHAPE]), int(G[mesh.G_PAIRS]), int(G[mesh.G_TABLE])
    pairs = pcol >= 0
    nl = ql.shape[1]
    e0 = P.shape[1] - MESH_EXTRA
    # per flank: Σ ζ^m A_k, Σ ζ^m B_k, Σ ζ^m d_k (m = 0, 1, 2), Σ ζ^m U_k, Σ ζ^m V_k (m = 0, 1)
    mom = np.zeros((2, 13))
    Ff, Mf = np.zeros(2), np.zeros(2)
    kk, dk, gg, dg, d2g = np.empty(2), np.empty(2), np.empty(2), np.empty(2), np.empty(2)
    for i in range(ql.shape[0]):
        sig, rb1, rb2 = P[i, mesh.P_SIGMA], P[i, mesh.P_RB1], P[i, mesh.P_RB2]
        sa, kappa0, pb, z1 = P[i, mesh.P_SIN_ALPHA], P[i, mesh.P_KAPPA0], P[i, mesh.P_PITCH], P[i, mesh.P_TEETH1]
        bw, nm, has1, has2 = P[i, e0], int(P[i, e0 + 1]), P[i, e0 + 2] != 0.0, P[i, e0 + 3] != 0.0
        x1, y1, th1, x2, y2, th2 = ql[i, 0], ql[i, 1], ql[i, 2], ql[i, 3], ql[i, 4], ql[i, 5]
        vx1, vy1, w1, vx2, vy2, w2 = vl[i, 0], vl[i, 1], vl[i, 2], vl[i, 3], vl[i, 4], vl[i, 5]
        j1 = 6
        s1x, s1y, u1x, u1y, s2x, s2y, u2x, u2y = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if has1:
            s1x, s1y, u1x, u1y = ql[i, 6], ql[i, 7], vl[i, 6], vl[i, 7]
            j1 = 8
        if has2:
            s2x, s2y, u2x, u2y = ql[i, j1], ql[i, j1 + 1], vl[i, j1], vl[i, j1 + 1]
        dsx, dsy, dvx, dvy = s2x - s1x, s2y - s1y, u2x - u1x, u2y - u1y
        # the mesh geometry (GearMesh._geometry, mbd.compiled.mesh._meshes)
        dx, dy, ddx, ddy = sig * (x2 - x1), sig * (y2 - y1), sig * (vx2 - vx1), sig * (vy2 - vy1)
        r2 = dx * dx + dy * dy
        a = np.sqrt(r2)
        inv_a = 1.0 / a
        ex, ey = dx * inv_a, dy * inv_a
        tx, ty = -ey, ex
        phi_ref = P[i, mesh.P_PHI_REF]
        phi_e = phi_ref + mesh._wrap(np.arctan2(dy, dx) - phi_ref)
        raw = sig * rb1 * (th1 - phi_e) + rb2 * (th2 - phi_e) - P[i, mesh.P_U0]
        roll = sig * rb1 * w1 + rb2 * w2
        s = mesh._wrap(raw * (_TWO_PI / pb)) * (pb / _TWO_PI)
        kappa = kappa0 * inv_a
        radial = sig * sa * (a - P[i, mesh.P_A0])
        half_b = 0.5 * P[i, mesh.P_BACKLASH]
        t_dd = tx * ddx + ty * ddy
        e_dd = ex * ddx + ey * ddy
        s_dot = roll - kappa * t_dd
        radial_dot = sig * sa * e_dd
        fac, dfac = mesh._factor(shape, z1 * (th1 - phi_e) * (1.0 / _TWO_PI) + P[i, mesh.P_P0], P, i, G)
        k_mean, c_m, ramp = P[i, mesh.P_K_MEAN], P[i, mesh.P_C_MESH], P[i, mesh.P_RAMP]
        kp = k_mean * fac
        kk_, cc = kp / nm, c_m / nm
        t_s, e_s = tx * dsx + ty * dsy, ex * dsx + ey * dsy
        hx, hy, qsx, qsy = 0.0, 0.0, 0.0, 0.0
        if jac:
            mom[:, :] = 0.0
        for fi in range(2):
            f = 1.0 if fi == 0 else -1.0
            d_f = f * s - radial - half_b
            r_f = f * s_dot - radial_dot
            gx = -sig * f * kappa * tx - sa * ex
            gy = -sig * f * kappa * ty - sa * ey
            gs = gx * dsx + gy * dsy
            gs_dot = (sig * f * kappa * (e_dd * t_s + t_dd * e_s) - sa * t_dd * t_s) / a + gx * dvx + gy * dvy
            FF, MM = 0.0, 0.0
            if pairs:
                bound = P[i, pcol + tooth_pairs.Q_BOUND]
                # no slice reaches a pair (δ_k ≤ δ_f + |ζ_k g·Δs| ≤ −bound): the flank carries nothing
                if d_f + 0.5 * bw * abs(gs) + bound <= 0.0:
                    Ff[fi], Mf[fi] = 0.0, 0.0
                    continue
                z2 = np.rint(rb2 / rb1 * z1)
                K0, dK0, udot = tooth_pairs.pair_setup(f, P, i, pcol, G, tstart, sig, z1, z2, k_mean / nm,
                                                       P[i, mesh.P_RECT_H], P[i, mesh.P_RECT_S],
                                                       P[i, mesh.P_RECT_SINGLE], P[i, mesh.P_RECT_RATIO], th1, th2,
                                                       phi_e, w1, inv_a, t_dd, kk, dk, gg, dg, d2g)
            for k in range(nm):
                zeta = bw / nm * (k + 1 - 0.5 * (nm + 1))
                d_k = d_f + zeta * gs
                if pairs:
                    if d_k + bound <= 0.0:
                        continue
                    r_k = r_f + zeta * gs_dot
                    F_k, A_k, B_k, U_k, V_k = 0.0, 0.0, 0.0, 0.0, 0.0
                    for j in range(2):
                        Fj, kc, cS, a_u, a_ud = tooth_pairs.pair_force(kk[j], dk[j], gg[j], dg[j], d2g[j], K0, dK0,
                                                                       udot, cc, ramp, d_k, r_k)
                        if not Fj > 0.0:
                            continue
                        F_k += Fj
                        A_k += kc
                        B_k += cS
                        U_k += a_u
                        V_k += a_ud
                    if not F_k > 0.0:
                        continue
                    FF += F_k
                    MM += zeta * F_k
                    if jac:
                        mom[fi, 0] += A_k
                        mom[fi, 1] += zeta * A_k
                        mom[fi, 2] += zeta * zeta * A_k
                        mom[fi, 3] += B_k
                        mom[fi, 4] += zeta * B_k
                        mom[fi, 5] += zeta * zeta * B_k
                        mom[fi, 9] += U_k
                        mom[fi, 10] += zeta * U_k
                        mom[fi, 11] += V_k
                        mom[fi, 12] += zeta * V_k
                    continue
                if not d_k > 0.0:
                    continue
                r_k = r_f + zeta * gs_dot
                S, dS = tooth_pairs.damping_share(d_k, ramp)
                F_k = kk_ * d_k + cc * S * r_k
                if not F_k > 0.0:
                    continue
                FF += F_k
                MM += zeta * F_k
                if jac:
                    A_k, B_k = kk_ + cc * dS * r_k, cc * S
                    zm = 1.0
                    for m in range(3):
                        mom[fi, m] += zm * A_k
                        mom[fi, 3 + m] += zm * B_k
                        mom[fi, 6 + m] += zm * d_k
                        zm *= zeta
            Ff[fi], Mf[fi] = FF, MM
            cx = (sig * f * kappa * t_s) / a
            ct = (sig * f * kappa * e_s - sa * t_s) / a
            hx = hx - MM * (cx * ex + ct * tx)
            hy = hy - MM * (cx * ey + ct * ty)
            qsx += MM * gx
            qsy += MM * gy
        F_net, F_sum = Ff[0] - Ff[1], Ff[0] + Ff[1]
        Fhx = F_net * kappa * tx + sig * sa * F_sum * ex + hx
        Fhy = F_net * kappa * ty + sig * sa * F_sum * ey + hy
        F[i, 0], F[i, 1], F[i, 2] = -sig * Fhx, -sig * Fhy, -sig * rb1 * F_net
        F[i, 3], F[i, 4], F[i, 5] = sig * Fhx, sig * Fhy, -1.0 * rb2 * F_net
        if has1:
            F[i, 6], F[i, 7] = qsx, qsy
        if has2:
            F[i, j1], F[i, j1 + 1] = -qsx, -qsy
        if not jac:
            continue
        # the law depends on the local coordinates through (δd, θ1, θ2, Δs) and their rates only, linearly in each
        # derivative: the derivative along each of these 12 directions (4 without slopes), then every column of
        # the local coordinates a ±1 multiple of one of them (exact)
        slopes = has1 or has2
        for p in range(12):
            if not slopes and (p == 4 or p == 5 or p == 10 or p == 11):
                continue
            pdx, pdy, pth1, pth2 = _unit(p, 0), _unit(p, 1), _unit(p, 2), _unit(p, 3)
            pdsx, pdsy = _unit(p, 4), _unit(p, 5)
            vdx, vdy, pw1, pw2 = _unit(p, 6), _unit(p, 7), _unit(p, 8), _unit(p, 9)
            pdvx, pdvy = _unit(p, 10), _unit(p, 11)
            tdd_ = tx * pdx + ty * pdy                          # t·δd
            da = ex * pdx + ey * pdy
            dex, dey = tx * tdd_ * inv_a, ty * tdd_ * inv_a
            dtx, dty = -ex * tdd_ * inv_a, -ey * tdd_ * inv_a
            dkappa = -kappa * da * inv_a
            dphi = (-dy * pdx + dx * pdy) / r2
            ds = sig * rb1 * (pth1 - dphi) + rb2 * (pth2 - dphi)
            droll = sig * rb1 * pw1 + rb2 * pw2
            dradial = sig * sa * da
            dt_dd = dtx * ddx + dty * ddy + tx * vdx + ty * vdy
            de_dd = dex * ddx + dey * ddy + ex * vdx + ey * vdy
            ds_dot = droll - dkappa * t_dd - kappa * dt_dd
            dradial_dot = sig * sa * de_dd
            dkp = k_mean * dfac * z1 * (pth1 - dphi) * (1.0 / _TWO_PI)
            du = z1 * (1.0 / _TWO_PI) * (pth1 - dphi)                   # the pairs' roll coordinate and its rate
            dudot = z1 * (1.0 / _TWO_PI) * (pw1 - (dt_dd * inv_a - t_dd * da * inv_a * inv_a))
            dt_s = dtx * dsx + dty * dsy + tx * pdsx + ty * pdsy
            de_s = dex * dsx + dey * dsy + ex * pdsx + ey * pdsy
            dFnet, dFsum, dhx, dhy, dqsx, dqsy = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            for fi in range(2):
                f = 1.0 if fi == 0 else -1.0
                dd_f = f * ds - dradial
                dr_f = f * ds_dot - dradial_dot
                gx = -sig * f * kappa * tx - sa * ex
                gy = -sig * f * kappa * ty - sa * ey
                dgx = -sig * f * (dkappa * tx + kappa * dtx) - sa * dex
                dgy = -sig * f * (dkappa * ty + kappa * dty) - sa * dey
                dgs = dgx * dsx + dgy * dsy + gx * pdsx + gy * pdsy
                Nn = sig * f * kappa * (e_dd * t_s + t_dd * e_s) - sa * t_dd * t_s
                dN = (sig * f * (dkappa * (e_dd * t_s + t_dd * e_s)
                                 + kappa * (de_dd * t_s + e_dd * dt_s + dt_dd * e_s + t_dd * de_s))
                      - sa * (dt_dd * t_s + t_dd * dt_s))
                dgs_dot = dN / a - Nn * da / (a * a) + dgx * dvx + dgy * dvy + gx * pdvx + gy * pdvy
                mo = mom[fi]
                dF = mo[0] * dd_f + mo[1] * dgs + mo[3] * dr_f + mo[4] * dgs_dot + dkp * mo[6] / nm
                dM = mo[1] * dd_f + mo[2] * dgs + mo[4] * dr_f + mo[5] * dgs_dot + dkp * mo[7] / nm
                if pairs:
                    dF += mo[9] * du + mo[11] * dudot
                    dM += mo[10] * du + mo[12] * dudot
                MM = Mf[fi]
                dFnet += f * dF
                dFsum += dF
                cx = (sig * f * kappa * t_s) / a
                ct = (sig * f * kappa * e_s - sa * t_s) / a
                dcx = sig * f * (dkappa * t_s + kappa * dt_s) / a - cx * da / a
                dct = (sig * f * (dkappa * e_s + kappa * de_s) - sa * dt_s) / a - ct * da / a
                dhx -= dM * (cx * ex + ct * tx) + MM * (dcx * ex + cx * dex + dct * tx + ct * dtx)
                dhy -= dM * (cx * ey + ct * ty) + MM * (dcx * ey + cx * dey + dct * ty + ct * dty)
                dqsx += dM * gx + MM * dgx
                dqsy += dM * gy + MM * dgy
            dFhx = (dFnet * kappa * tx + F_net * (dkappa * tx + kappa * dtx)
                    + sig * sa * (dFsum * ex + F_sum * dex) + dhx)
            dFhy = (dFnet * kappa * ty + F_net * (dkappa * ty + kappa * dty)
                    + sig * sa * (dFsum * ey + F_sum * dey) + dhy)
            J = Jq if p < 6 else Jv
            if p == 0 or p == 1 or p == 6 or p == 7:                 # δd = σ(d2 − d1): columns d1 (−σ) and d2 (σ)
                cs = (p % 2, 3 + p % 2)
                sc = (-sig, sig)
            elif p == 2 or p == 3 or p == 8 or p == 9:               # θ1, θ2
                cs = (2 + 3 * (p % 2), -1)
                sc = (1.0, 0.0)
            else:                                                   # Δs = s2 − s1
                cs = (6 + p % 2 if has1 else -1, j1 + p % 2 if has2 else -1)
                sc = (-1.0, 1.0)
            for e in range(2):
                c = cs[e]
                if c < 0:
                    continue
                w = sc[e]
                gx_, gy_, gn, gqx, gqy = w * dFhx, w * dFhy, w * dFnet, w * dqsx, w * dqsy
                J[i, 0, c], J[i, 1, c], J[i, 2, c] = -sig * gx_, -sig * gy_, -sig * rb1 * gn
                J[i, 3, c], J[i, 4, c], J[i, 5, c] = sig * gx_, sig * gy_, -1.0 * rb2 * gn
                if has1:
                    J[i, 6, c], J[i, 7, c] = gqx, gqy
                if has2:
                    J[i, j1, c], J[i, j1 + 1, c] = -gqx, -gqy


# ------------------------------------------------------------------------------------------- SlicedRaceContact outputs
# the rows outputs_sliced_race writes (the reference's names but "angle", not a by-product of the force law, as the
# planar race's), then one row per slice: "slice_load_<k>", k = 0 .. n_s − 1 (:func:`sliced_race_output_names`)
SLICED_RACE_OUTPUTS = ("load", "deflection", "traction", "slip_velocity", "rolling_speed", "fx", "fy", "tilt", "slope",
                       "centroid", "max_slice_load", "edge_load", "mid_load", "race_slope_x", "race_slope_y",
                       "loaded_slices")


def sliced_race_output_names(n_slices: int) -> tuple:
    """The names of the rows :func:`outputs_sliced_race` writes for a family of ``n_slices`` slices."""
    return SLICED_RACE_OUTPUTS + tuple(f"slice_load_{k}" for k in range(n_slices))


@njit(cache=True, error_model="numpy")
def outputs_sliced_race(t, phi, omega, domega, ql, vl, z, P, G, O):
    """The outputs of every contact (:func:`sliced_race_output_names`: SlicedRaceContact.kernel's) into the rows of O
    (16 + n_s, n): the law of :func:`evaluate_sliced_race` (its helpers) without its generalised forces and Jacobian —
    the geometry, the slices' compressions δ_k and their powers (:func:`_slice_pass`, all contacts at once), the slice
    loads (:func:`_slice_loads`: open slices 0), their sums, and the traction on Q at the load centroid — for every
    contact, those the open bound finds open too (their load 0, their geometry, slip and rolling speeds as the
    reference gives them). Equal to the reference's outputs to round-off (tests/mbd/test_compiled_sliced.py)."""
    p, law, pe, ns, zs, zmax = _law(G)
    slot, geo, w_x, w_y, w_d, w_delta, w_root, npad = _slice_pass(P, ql, vl, zs, zmax, pe, np.bool_(True))
    w_q, w_Fx, w_Fy = np.empty(ns), np.empty(ns), np.empty(ns)
    for i in range(ql.shape[0]):
        r = slot[i]
        loaded = r >= 0
        r = r if loaded else -2 - r
        (kap, R, D, K, c0, row, Rr, tau, vr0, vr1, vr2, dtau, vb0, vb1, vb2, vp2, rcx, rcy, Vcx, Vcy, rpx, rpy, ux,
         uy, rho_p, ex, ey, gx, gy, ge, edx, edy, s0cx, s0cy, scx, scy, dscx, dscy, k0x, k0y, srx, sry, dsrx, dsry,
         pcx_, pcy_, wvx, wvy) = _geometry(geo, r)
        if loaded:
            _slice_loads(r, r * npad, zs, kap, K / ns, c0 / ns, P[i, SLICED_COLS + ns], row, wvx, wvy, dsrx, dsry, dscx, dscy, w_x, w_y, w_d,
                         w_delta, w_root, w_q, w_Fx, w_Fy)
        else:
            for k in range(ns):
                w_q[k], w_Fx[k], w_Fy[k] = 0.0, 0.0, 0.0
        S0x, S0y, S1x, S1y, S2x, S2y, Q, Qz = _slice_sums(zs, row, w_q, w_Fx, w_Fy)
        qmax, nload = 0.0, 0.0
        for k in range(ns):
            q = w_q[k]
            O[16 + k, i] = q
            qmax = max(qmax, q)
            nload += 1.0 if q > 0.0 else 0.0
        # traction as the planar contact's on Q (SlicedRaceContact.kernel)
        (rho, ecx, ecy, tx, ty, rl, rrx, rry, rbx, rby, Vrx, Vry, Vbx, Vby, ur, ub, wt, v_s,
         u_e) = _rolling(R, rcx, rcy, vr0, vr1, vr2, vb0, vb1, vb2, Vcx, Vcy, pcx_, pcy_, wvx, wvy)
        on = Q > 0.0
        Ft = -_coefficient(law, G, v_s, u_e, Q if on else 1.0, Rr)[0] * Q
        O[0, i], O[1, i], O[2, i], O[3, i], O[4, i] = Q, 0.5 * D - kap * (rho - R), Ft, v_s, u_e
        O[5, i], O[6, i], O[7, i] = S0x + Ft * tx, S0y + Ft * ty, tau
        O[8, i], O[9, i] = scx * ex + scy * ey - tau, Qz / Q if on else 0.0
        O[10, i], O[11, i], O[12, i] = qmax, max(O[16, i], O[15 + ns, i]), O[16 + ns // 2, i]
        O[13, i], O[14, i], O[15, i] = scx, scy, nload
