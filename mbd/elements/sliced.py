"""Sliced roller–raceway contact (docs/model.md §8.8): the quasi-3D line contact of a roller that may tilt
against a raceway whose axis may slope, for many contacts at once.

A roller of effective length l is cut into n_s slices of width Δ = l/n_s at the axial stations
z_k = (k − (n_s + 1)/2) Δ, k = 1..n_s, measured from the roller centre. Every body's axis is a line through its
centre with a slope vector: the roller's axis passes through p + z σ_r at axial station z, the raceway's through
c + ζ σ_c (ζ = ζ_row + z_k the slice's station on the race body, ζ_row the row's axial offset). Per slice, in
the transverse plane and in the planar contact's exact-norm form (§8.1),

    w_k = p + z_k σ_r − c − ζ_k σ_c,   d_k = |w_k|,   n_k = w_k/d_k,
    δ_k = D/2 − κ (d_k − R) − P_k      (κ = +1 inner raceway, −1 outer),
    q_k = (K/n_s) ⟨δ_k⟩^p,

P_k the profile drop of the roller and of the raceway at the slice (constant geometry), K and p the planar
law's constant and exponent (Palmgren: p = 10/9, K = 8.06e4 l^(8/9) N/mm^(10/9)). The slice force on the roller
is F_k = κ q_k n_k at the slice's station on both bodies, the opposite on the race body. Independent (Winkler)
slices: no edge weighting of the end slices (ISO/TS 16281:2008's half-space refinement is not applied; an
edge load shows where the tilt gap z_k Δσ exceeds the profile drop, its peak underestimated at a straight
roller's corner). With a straight profile and no slope every slice carries Q/n_s and the sum is exactly the
planar law Q = K δ^p.

Generalised forces (virtual work δW = Σ_k F_k · δw_k):
    on p: Σ F_k;   on σ_r: Σ z_k F_k;   on c: −Σ F_k;   on σ_c: −Σ ζ_k F_k.
Σ z_k F_k is the moment about the roller centre expressed as the generalised force of its slope (the physical
moment vector is k̂ × ... rotated: M = (−Σ z_k F_y, Σ z_k F_x)). Exact Jacobian of the eight generalised forces
(p, σ_r, c, σ_c; 2 each) w.r.t. the same eight coordinates, from the slice blocks
    ∂F_k/∂w_k = −p q_k/δ_k n_k n_kᵀ + κ q_k (I − n_k n_kᵀ)/d_k,
summed over the slices into one 8×8 block per contact (symmetric: the law has a potential).

ISO/TS 16281:2008's lamina stiffness: c_L = 35948 L_we^(8/9) N/mm^(10/9) for the two contacts of a lamina in
series; one contact of the same exponent then has K = 2^(10/9) c_L (:func:`iso_16281_stiffness`), 3.7 % below
Palmgren's 8.06e4.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["SLICE_STIFFNESS", "ISO_16281_LAMINA_COEFFICIENT", "slice_stations", "iso_16281_stiffness",
           "SlicedContact", "SlicedResult"]

ISO_16281_LAMINA_COEFFICIENT = 35948.0   # N/mm^(10/9) per mm^(8/9): ISO/TS 16281:2008, two contacts in series
_PALMGREN_EXPONENT = 10.0 / 9.0          # the lamina law's exponent in ISO/TS 16281 (Palmgren's line contact)


def slice_stations(length: float, n_slices: int) -> tuple[np.ndarray, float]:
    """(z_k, Δ): the n_s slice centres z_k = (k − (n_s + 1)/2) Δ [m] from the roller centre and the width Δ = l/n_s."""
    n = int(n_slices)
    if n < 1 or n != n_slices:
        raise ModelError(f"slices: expected an integer >= 1, got {n_slices!r}")
    if not length > 0.0:
        raise ModelError(f"length: expected > 0 m, got {length!r}")
    width = length / n
    return (np.arange(1, n + 1) - 0.5 * (n + 1)) * width, width


def iso_16281_stiffness(length: float) -> float:
    """One roller–raceway contact's constant K [N/m^(10/9)] from ISO/TS 16281:2008's lamina constant
    c_L = 35948 L_we^(8/9) N/mm^(10/9) (L_we in mm) for the two contacts in series: K = 2^(10/9) c_L
    (two equal contacts of the same exponent in series share the approach equally)."""
    c_L = ISO_16281_LAMINA_COEFFICIENT * (1e3 * length) ** (8.0 / 9.0)          # N/mm^(10/9)
    return 2.0 ** _PALMGREN_EXPONENT * c_L * 1e3 ** _PALMGREN_EXPONENT          # N/m^(10/9)


# the slice law's constant by name: Palmgren's (the planar law's), or ISO/TS 16281's
SLICE_STIFFNESS = ("palmgren", "iso_16281")


@dataclass(frozen=True)
class SlicedResult:
    """What :meth:`SlicedContact.evaluate` gives, for n contacts and n_s slices:
    ``delta`` (n, n_s) slice compressions δ_k [m] (negative: a gap); ``load`` (n, n_s) slice loads q_k [N];
    ``normal`` (n, n_s, 2) unit vectors n_k; ``force`` (n, 2) Σ F_k on the roller [N]; ``roller_moment`` (n, 2)
    Σ z_k F_k [N m] (generalised force on the roller's slope); ``race_force`` (n, 2) −Σ F_k; ``race_moment``
    (n, 2) −Σ ζ_k F_k [N m]; ``jacobian`` (n, 8, 8) ∂(generalised forces)/∂(p, σ_r, c, σ_c) or None."""
    delta: np.ndarray
    load: np.ndarray
    normal: np.ndarray
    force: np.ndarray
    roller_moment: np.ndarray
    race_force: np.ndarray
    race_moment: np.ndarray
    jacobian: np.ndarray | None = None

    @property
    def generalized(self) -> np.ndarray:
        """(n, 8): the generalised forces on (p, σ_r, c, σ_c), in the Jacobian's order."""
        return np.concatenate([self.force, self.roller_moment, self.race_force, self.race_moment], axis=1)


class SlicedContact:
    """n sliced roller–raceway contacts (law in the module docstring), each a roller against one raceway.

    ``kind``: "inner" or "outer" (one for all, or per contact); ``R_race`` raceway radius [m]; ``D`` roller
    diameter [m]; ``K`` one physical contact's constant of the planar law [N/m^p]; ``exponent`` p ≥ 1;
    ``z`` (n_s,) slice stations on the roller [m] (:func:`slice_stations`); ``drop`` (n_s,) or (n, n_s) profile
    drop of roller plus raceway at each slice [m]; ``row_offset`` ζ_row [m] the roller centre's axial station
    on the race body (per contact or one). Per-contact values broadcast from scalars, and a law of scalars serves
    any number of contacts (the inputs' leading dimension)."""

    def __init__(self, *, kind, R_race, D, K, exponent, z, drop, row_offset):
        kinds = np.atleast_1d(np.asarray(kind))
        if not np.all(np.isin(kinds, ("inner", "outer"))):
            raise ModelError(f"kind: expected 'inner' or 'outer', got {kind!r}")
        self.z = np.asarray(z, float)
        if self.z.ndim != 1 or self.z.size < 1:
            raise ModelError(f"z: expected the (n_s,) slice stations [m], got shape {self.z.shape}")
        self.n_s = self.z.size
        self.exponent = float(exponent)
        if not (np.isfinite(self.exponent) and self.exponent >= 1.0):
            raise ModelError(f"exponent: expected >= 1, got {exponent!r}")
        per = np.broadcast_arrays(np.where(kinds == "inner", 1.0, -1.0), np.asarray(R_race, float),
                                  np.asarray(D, float), np.asarray(K, float), np.asarray(row_offset, float))
        self.kappa, self.R_race, self.D, self.K, self.row_offset = (np.atleast_1d(a).astype(float) for a in per)
        for name, a in (("R_race", self.R_race), ("D", self.D), ("K", self.K)):
            if not np.all(a > 0.0):
                raise ModelError(f"{name}: expected > 0, got {a!r}")
        self.n = self.kappa.size
        self.drop = np.broadcast_to(np.asarray(drop, float), (self.n, self.n_s))
        self.zeta = self.row_offset[:, None] + self.z[None, :]           # (n, n_s) stations on the race body

    def evaluate(self, p, sigma_r, c, sigma_c, jacobian: bool = False) -> SlicedResult:
        """Slice compressions, loads and the generalised forces (and their Jacobian) of all contacts at roller
        centres ``p`` (n, 2), roller slopes ``sigma_r`` (n, 2), raceway centres ``c`` (n, 2) and raceway slopes
        ``sigma_c`` (n, 2) [m, rad]."""
        args = [np.asarray(a, float) for a in (p, sigma_r, c, sigma_c)]
        n = np.broadcast_shapes((self.n,), *[a.shape[:-1] or (1,) for a in args])[0]
        p, sigma_r, c, sigma_c = (np.broadcast_to(a, (n, 2)) for a in args)
        per = lambda a: np.broadcast_to(a, (n,) + a.shape[1:])                         # noqa: E731
        kappa, D, R, K, zeta_all, drop = (per(a) for a in (self.kappa, self.D, self.R_race, self.K, self.zeta,
                                                            self.drop))
        z, zeta, kap = self.z[None, :, None], zeta_all[:, :, None], kappa[:, None]
        w = (p - c)[:, None, :] + z * sigma_r[:, None, :] - zeta * sigma_c[:, None, :]      # (n, n_s, 2)
        d = np.sqrt(np.einsum("nki,nki->nk", w, w))
        nrm = w / d[:, :, None]
        delta = 0.5 * D[:, None] - kap * (d - R[:, None]) - drop
        touch = delta > 0.0
        ds = np.where(touch, delta, 1.0)
        k_s = (K / self.n_s)[:, None]
        q = np.where(touch, k_s * ds ** self.exponent, 0.0)
        F = (kap * q)[:, :, None] * nrm                                                       # on the roller
        force = F.sum(axis=1)
        mom_r = np.einsum("k,nki->ni", self.z, F)
        mom_c = np.einsum("nk,nki->ni", zeta[:, :, 0], F)
        J = None
        if jacobian:
            dq = np.where(touch, self.exponent * q / ds, 0.0)                                 # ∂q/∂δ
            nn = nrm[:, :, :, None] * nrm[:, :, None, :]
            A = -dq[:, :, None, None] * nn + (kap * q / d)[:, :, None, None] * (np.eye(2) - nn)   # ∂F_k/∂w_k
            beta = np.stack([np.ones_like(zeta[:, :, 0]), np.broadcast_to(self.z, zeta.shape[:2]),
                             -np.ones_like(zeta[:, :, 0]), -zeta[:, :, 0]], axis=2)           # (n, n_s, 4)
            J = np.einsum("nka,nkb,nkij->naibj", beta, beta, A).reshape(n, 8, 8)
        return SlicedResult(delta=delta, load=q, normal=nrm, force=force, roller_moment=mom_r, race_force=-force,
                            race_moment=-mom_c, jacobian=J)
