"""The tooth-pair mesh law: transmission error tooth by tooth (docs/model.md §7).

A flank f = ±1 of a spur mesh is the sum of the tooth pairs that can touch on it. With ε the contact
ratio (1 < ε < 2) at most two pairs are engaged: the newest, which entered on flank f at its roll
coordinate u = 0, and the older one at u + 1; a pair leaves at u = ε. Pair j carries

    F_j = k_j(u_j)·(δ_f − g_j(u_j)) + c_j(u_j)·S((δ_f − g_j)/δ_c)·(δ̇_f − ġ_j),   while δ_f − g_j > 0 and F_j > 0

(else 0; S the damping share of :func:`damping_share`, growing over the pair's first δ_c
of compression)

with δ_f the flank compression of :mod:`mbd.elements.gear_mesh` (the same for every pair of perfect
involutes) and g_j the pair's *gap*: how much farther the flank must be compressed before that pair
touches. The force acts along the flank's line of action, like the lumped law's.

Gap (material excess counts negative, relief positive), both teeth of the pair:

    g_j = R_1(ξ_1) + R_2(ξ_2) − E_1(i_1, face_1; x_1) − E_2(i_2, face_2; x_2)

- ξ_b ∈ [0, 1]: where on gear b's active profile the pair touches, from its start of active profile
  (0) to its tip (1), linear in the roll length. On flank f, for σ f > 0 (σ = +1 external, −1 internal)
  contact starts at gear 1's root: ξ_1 = u/ε; for σ f < 0 at its tip: ξ_1 = 1 − u/ε. Always ξ_2 = 1 − ξ_1.
- E_b(i, face; x) = c0 + c1 x + c2 x² + c3 x³, x = 2ξ − 1, the material excess of tooth i's flank
  ``face`` [m] along the line of action: its position (cumulative pitch) deviation, profile slope
  (linear) and profile form (Legendre P2, P3: shapes with no straight-line part) in one cubic per flank.
  The face of gear 1 that flank f loads is σ f, of gear 2 it is f; face +1 is the tooth flank that faces
  the gear's counter-clockwise (+θ) side.
- R_b(ξ) = C_a·(max(ξ − ξ_a, 0)/(1 − ξ_a))^e: tip relief of amount C_a from ξ_a to the tip, linear
  (e = 1) or parabolic (e = 2).
- A tooth's stiffness factor c (1 healthy, < 1 a crack, 0 a missing tooth) scales every pair it forms.

Pair stiffness: the rectangular law's levels split over the pairs — k_j = k_mean·k_s/k_mean·c_1 c_2·
[(r/2)·B(u; 0, ε) + (1 − r/2)·B(u; ε − 1, 1)], B a window with the quintic-smoothstep edges of width s
(the rectangular wave's): r/2 of k_single near a pair's ends (where the other pair shares the load), the
whole of it in single contact. The two pairs of a perfect mesh then sum to the rectangular wave exactly
(r = k_double/k_single); c_j = c_m·k_j/K_0, K_0 the two pairs' stiffness without faults, shares the
mesh damping c_m the same way, so with every gap zero and no fault the pair law *is* the lumped law.

Which teeth: P_f = z_1(θ_1 − φ_e)/2π + h_f counts gear 1's teeth entering flank f (the pair of gear-1
tooth i enters at P_f ≡ −i mod z_1), Q_f = −σ z_2(θ_2 − φ_e)/2π + c_f counts gear 2's (its tooth k enters
at Q_f ≡ σk mod z_2); rolling keeps Q_f − P_f an integer up to the transmission error. With
m = floor(P_f + s/2) the newest pair has u = P_f − m ∈ [−s/2, 1 − s/2), gear-1 tooth −m, gear-2 tooth
σ·round(Q_f − u); the older pair u + 1, teeth −m + 1 and σ·(round(Q_f − u) − 1). Identities change only
where a pair's stiffness is zero, and a 2π jump of φ_e shifts both counts by whole revolutions.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import ad
from ..errors import ModelError

__all__ = ["ToothPairs", "TABLE_STRIDE", "FACES", "tooth_table", "flank_force", "smooth_box", "damping_share"]

_TWO_PI = 2.0 * np.pi
TABLE_STRIDE = 5       # per tooth and face: c0, c1, c2, c3 [m], stiffness factor
FACES = 2              # face +1 at index 0, face −1 at index 1


def tooth_table(z: int, excess=None, factor=None) -> np.ndarray:
    """A gear's flat tooth table (z·2·5,): ``excess`` (z, 2, 4) cubic coefficients [m] per tooth and face
    (zeros if None), ``factor`` (z,) stiffness factors (ones if None)."""
    t = np.zeros((int(z), FACES, TABLE_STRIDE))
    if excess is not None:
        t[:, :, :4] = np.asarray(excess, float)
    t[:, :, 4] = 1.0 if factor is None else np.asarray(factor, float)[:, None]
    return t.ravel()


@dataclass(frozen=True, eq=False)
class ToothPairs:
    """The tooth-pair data of n meshes (module docstring), SI.

    ``entry`` (n, 2): h_f [cycles] of flanks (+1, −1); ``phase2`` (n, 2): c_f [cycles]; ``relief1``,
    ``relief2`` (n, 3): (C_a [m], ξ_a, e) of gear 1's and gear 2's tip relief; ``table`` (T,): the gears'
    flat tooth tables (:func:`tooth_table`) one after another; ``start1``, ``start2`` (n,): where gear 1's
    and gear 2's table begin in it."""
    entry: np.ndarray
    phase2: np.ndarray
    relief1: np.ndarray
    relief2: np.ndarray
    table: np.ndarray
    start1: np.ndarray
    start2: np.ndarray

    def checked(self, name: str, n: int, z1: np.ndarray, z2: np.ndarray) -> "ToothPairs":
        """Validated copy with every array broadcast to n instances; errors name the field."""
        def arr(key, shape):
            a = np.asarray(getattr(self, key), float)
            try:
                a = np.broadcast_to(a, shape).astype(float)
            except ValueError:
                raise ModelError(f"{name}: tooth pairs {key!r} must have shape {shape} or broadcast to it, "
                                 f"got {np.shape(getattr(self, key))}") from None
            if not np.all(np.isfinite(a)):
                raise ModelError(f"{name}: tooth pairs {key!r} must be finite")
            return a
        entry, phase2 = arr("entry", (n, 2)), arr("phase2", (n, 2))
        r1, r2 = arr("relief1", (n, 3)), arr("relief2", (n, 3))
        table = np.asarray(self.table, float).ravel()
        if not np.all(np.isfinite(table)):
            raise ModelError(f"{name}: tooth pairs 'table' must be finite")
        for key, r in (("relief1", r1), ("relief2", r2)):
            bad = (r[:, 0] < 0) | (r[:, 1] < 0) | (r[:, 1] >= 1) | ~np.isin(r[:, 2], (1.0, 2.0))
            if np.any(bad):
                raise ModelError(f"{name}: tooth pairs {key!r} must be (C_a >= 0 [m], 0 <= xi_a < 1, exponent 1 or 2), "
                                 f"got {r[np.argmax(bad)].tolist()}")
        starts = []
        for key, z in (("start1", z1), ("start2", z2)):
            s = arr(key, (n,))
            if np.any(s != np.round(s)) or np.any(s < 0) or np.any(s + z * FACES * TABLE_STRIDE > table.size):
                raise ModelError(f"{name}: tooth pairs {key!r} must be whole offsets of a z*{FACES * TABLE_STRIDE}-long "
                                 f"table inside 'table' ({table.size} values)")
            starts.append(s)
        c = np.concatenate([table[int(s0) + TABLE_STRIDE - 1:int(s0) + int(zz) * FACES * TABLE_STRIDE:TABLE_STRIDE]
                            for s, zs in zip(starts, (z1, z2)) for s0, zz in zip(s, zs)])
        if np.any((c < 0) | (c > 1)):
            raise ModelError(f"{name}: tooth stiffness factors must be in [0, 1] (1 healthy, 0 missing tooth)")
        return ToothPairs(entry, phase2, r1, r2, table, starts[0], starts[1])

    @staticmethod
    def fuse(parts: list["ToothPairs"]) -> "ToothPairs":
        """The data of several families as one (tables appended, offsets moved along)."""
        shift = np.cumsum([0] + [p.table.size for p in parts[:-1]])
        cat = lambda key: np.concatenate([getattr(p, key) for p in parts])
        return ToothPairs(cat("entry"), cat("phase2"), cat("relief1"), cat("relief2"), cat("table"),
                          np.concatenate([p.start1 + s for p, s in zip(parts, shift)]),
                          np.concatenate([p.start2 + s for p, s in zip(parts, shift)]))

    def excess_bound(self, z1, z2, reach: float) -> np.ndarray:
        """(n,) an upper bound of −g (the most a pair's material excess can close its gap) for |x| ≤ reach:
        a flank compressed less than −bound has no pair in contact."""
        powers = reach ** np.arange(4)
        out = np.zeros(len(self.start1))
        for start, z in ((self.start1, z1), (self.start2, z2)):
            for i, (s0, zz) in enumerate(zip(start.astype(int), np.asarray(z, int))):
                t = self.table[s0:s0 + zz * FACES * TABLE_STRIDE].reshape(zz, FACES, TABLE_STRIDE)
                out[i] += np.max(np.abs(t[:, :, :4]) @ powers)
        return out


def smooth_box(dist, half, s):
    """Window of half width ``half`` at distance ``dist`` from its centre: 1 inside, 0 outside,
    quintic-smoothstep edges (C², symmetric) of full width s centred on each edge; Dual-capable."""
    x = (half + 0.5 * s - dist) * (1.0 / s)
    x = ad.where(x > 1.0, 1.0, ad.where(x < 0.0, 0.0, x))
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


def _relief(xi, r):
    """(R, dR/dξ) of tip relief r = (C_a, ξ_a, e) columns at profile coordinate ξ."""
    ca, xa, e = r[:, 0], r[:, 1], r[:, 2]
    inv = 1.0 / (1.0 - xa)
    t = ad.pos(xi - xa) * inv
    lin = e == 1.0
    R = ca * ad.where(lin, t, t * t)
    dR = ca * inv * ad.where(lin, ad.where(ad.value(t) > 0.0, 1.0, 0.0), 2.0 * t)
    return R, dR


def _cubic(c, x):
    """(E, dE/dx) of the cubic with (n, 4) coefficients c at x."""
    E = c[..., 0] + x * (c[..., 1] + x * (c[..., 2] + x * c[..., 3]))
    dE = c[..., 1] + x * (2.0 * c[..., 2] + x * (3.0 * c[..., 3]))
    return E, dE


def _lookup(table, start, tooth, face):
    """(..., n, 5) table rows of tooth ``tooth`` (..., n) int, face index ``face`` (..., n) int."""
    base = start.astype(np.int64) + (tooth * FACES + face) * TABLE_STRIDE
    return table[base[..., None] + np.arange(TABLE_STRIDE)]


def damping_share(delta, ramp):
    """S(δ/δ_c): the share of a contact's damping at compression δ (a tooth pair's, the mesh's flanks'; the
    roller–raceway contacts', :class:`mbd.elements.contact.RaceContact` and its slices), the quintic smoothstep over
    [0, δ_c]: a contact's dissipation grows with its compressed zone (as in Hunt & Crossley's law) instead of
    switching on whole at first touch (δ_c = 0: S = 1, the Kelvin–Voigt jump). Dual-capable in δ; ``ramp`` per
    instance. The one owner of the law (the compiled twin: :func:`mbd.compiled.tooth_pairs.damping_share`)."""
    width = np.where(ramp > 0.0, ramp, 1.0)
    x = delta * (1.0 / width)
    x = ad.where(x > 1.0, 1.0, ad.where(x < 0.0, 0.0, x))
    return ad.where(ramp > 0.0, x * x * x * (10.0 + x * (-15.0 + 6.0 * x)), 1.0)


def flank_force(pp: ToothPairs, f: int, sig, z1, z2, k_mean, c_mesh, damping_ramp, shape_args, th1, th2, phi_e,
                phi_dot, w1, delta, delta_rate):
    """(F_f, K_f) of flank f of n meshes by the pair law (module docstring); Dual-capable in the angles,
    rates and δ_f, δ̇_f. ``shape_args`` = (h, s, k_single/k_mean, ratio) of the rectangular stiffness
    (ε = 2h + 1); ``phi_dot`` the line of centres' angular speed; ``damping_ramp`` δ_c, over which a pair's
    damping grows with its compression (:func:`damping_share`). K_f: the engaged pairs'
    stiffness."""
    h, s, single, ratio = shape_args
    eps = 2.0 * h + 1.0
    fi = 0 if f > 0 else 1
    P = z1 * (th1 - phi_e) * (1.0 / _TWO_PI) + pp.entry[:, fi]
    Q = -sig * z2 * (th2 - phi_e) * (1.0 / _TWO_PI) + pp.phase2[:, fi]
    m = np.floor(ad.value(P) + 0.5 * s)
    u0 = P - m                                       # newest pair's roll coordinate (derivative of P)
    n2 = np.rint(ad.value(Q) - ad.value(u0))         # σ × the newest pair's gear-2 tooth
    udot = z1 * (w1 - phi_dot) * (1.0 / _TWO_PI)
    fwd = sig * f > 0                                # contact starts at gear 1's root
    face1 = np.where(fwd, 0, 1)
    face2 = np.full(np.shape(face1), fi)
    dxi1 = np.where(fwd, 1.0, -1.0) / eps            # dξ_1/du
    half_b = 1.0 - 0.5 * eps
    kmax = k_mean * single
    F, K, K0 = 0.0, 0.0, 0.0
    pairs = []
    for j in (0, 1):
        u = u0 + float(j)
        i1 = np.mod(-m + j, z1).astype(np.int64)
        i2 = np.mod(sig * (n2 - j), z2).astype(np.int64)
        row1, row2 = _lookup(pp.table, pp.start1, i1, face1), _lookup(pp.table, pp.start2, i2, face2)
        xi1 = ad.where(fwd, 0.0, 1.0) + dxi1 * u
        xi2 = 1.0 - xi1
        E1, dE1 = _cubic(row1, 2.0 * xi1 - 1.0)
        E2, dE2 = _cubic(row2, 2.0 * xi2 - 1.0)
        R1, dR1 = _relief(xi1, pp.relief1)
        R2, dR2 = _relief(xi2, pp.relief2)
        gap = R1 + R2 - E1 - E2
        dgap = dxi1 * (dR1 - dR2 - 2.0 * dE1 + 2.0 * dE2)          # dg/du
        dist = ad.abs_(u - 0.5 * eps)
        share = 0.5 * ratio * smooth_box(dist, 0.5 * eps, s) + (1.0 - 0.5 * ratio) * smooth_box(dist, half_b, s)
        k0 = kmax * share
        pairs.append((k0 * (row1[..., 4] * row2[..., 4]), gap, dgap))
        K0 = K0 + k0
    for k, gap, dgap in pairs:
        comp = delta - gap
        force = k * comp + (c_mesh * k / K0) * damping_share(comp, damping_ramp) * (delta_rate - dgap * udot)
        F = F + ad.where(comp > 0.0, ad.pos(force), 0.0)
        K = K + ad.value(k)
    return F, K
