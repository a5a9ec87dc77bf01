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

from .. import ad
from ..element import Element, marker, marker_velocity, point_force
from ..errors import ModelError
from .contact import Traction
from .tooth_pairs import damping_share

__all__ = ["SLICE_STIFFNESS", "ISO_16281_LAMINA_COEFFICIENT", "slice_stations", "iso_16281_stiffness",
           "SlicedContact", "SlicedResult", "SlicedRaceContact"]

_ETA2 = 1e-24  # (1e-12 m)²: keeps norms nonzero, as the planar contact's

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


# ------------------------------------------------------------------------------------------------------------------
# The sliced contact as an element family of the dynamic model (docs/model.md §8.8)
class SlicedRaceContact(Element):
    """Sliced roller–raceway contact of the dynamic model: the law of :class:`SlicedContact` (module docstring) with
    damping per slice, traction at the load centroid, on the engine's tilt coordinates (docs/model.md §8.8).

    Local coordinates: the roller (x, y, θ) and its tilt τ (one coordinate, ``roller_tilt``); the race body (x, y,
    θ); for the outer raceway (the planet's bore) the planet's slope pair (s_x, s_y) and the pin body (x, y, θ).
    The roller's slope is σ_r = τ e, e the unit vector from the pin centre to the roller centre (the roller tilts in
    its radial–axial plane); the raceway's slope is σ_c = Rot(θ_b) s_0 (inner: the pin's prescribed slope s_0 in the
    race body's axes) or s + Rot(θ_b) s_0 (outer: the planet's slope coordinates plus a bore error s_0, default 0).
    An inner raceway on a pin that bends (``race_slopes=True``; the pin a body of its own with a slope pair,
    :class:`mbd.elements.tilt.BeamSupport`) takes the outer raceway's layout with the pin body in both places: its
    slope s + Rot(θ_b) s_0 is the pin's bending slope plus its prescribed one.

    Per slice k, w_k = p + z_k σ_r − c − ζ_k σ_c, δ_k = D/2 − κ(|w_k| − R) − P_k as :class:`SlicedContact`, and

        q_k = (K/n_s) δ_k^p + S(δ_k/δ_c) (c_0/n_s) δ_k^((p−1)/2) δ̇_k   (δ_k > 0, clipped at ≥ 0),   c_0 = 2ζ √(m_r p K),

    the planar contact's law (RaceContact, its damping share S over the first ``damping_ramp`` δ_c of a slice's
    compression included) per unit length of roller: a straight roller without tilt or slope gives every slice 1/n_s
    of the planar load, damping included (its slices sum to the planar law). The slice force
    F_k = κ q_k w_k/|w_k| acts on the roller at station z_k and, opposite, on the race body at ζ_k = ζ_row + z_k.
    Traction: the planar law's (RaceContact) on the total load Q = Σ q_k, from the roller's and the raceway's
    in-plane motion at the contact point P = c + R e_c, applied at the load centroid z̄ = Σ z_k q_k / Q (its moments on
    τ and on the race's slope; in the plane as the planar contact). Generalised forces by virtual work: on p, Σ F_k
    plus the dependence of e on p (τ (I − e eᵀ) Σ z_k F_k / ρ_p, the opposite on the pin centre); on τ, e·Σ z_k F_k;
    on c, −Σ F_k and on the race body's θ the moment of −Σ F_k about its centre and −Σ ζ_k F_k·(k × Rot(θ_b) s_0);
    on s, −Σ ζ_k F_k. Exact Jacobians by :mod:`mbd.ad` through all of it.

    Contacts whose slices are all open are skipped before the slice loop: the largest slice compression is bounded by
    the in-plane compression δ_0 = D/2 − κ(|p − c| − R) plus max_k |z_k σ_r − ζ_k σ_c| (profiles only lower it), so a
    contact with that bound ≤ 0 carries nothing (``tests/mbd/test_sliced_family.py`` checks the bound).

    One physical contact per instance (no multiplicity: a double row is two rows of rollers). No raceway spall, no
    rolling resistance (the planar contact has them). Outputs as RaceContact's ("load" Q, "deflection" δ_0,
    "traction", "slip_velocity", "angle", "rolling_speed", "fx", "fy"), and "tilt" τ, "slope" the race's slope
    against the roller's along e [rad] (what the contact sees), "centroid" z̄ [m], "max_slice_load" [N], "edge_load"
    the larger of the two end slices' loads [N], "mid_load" the middle slice's [N] (slice (n_s + 1)/2, the middle
    one of an odd count), "loaded_slices" the number loaded, "race_slope_x", "race_slope_y" the race's slope σ_c in
    R [rad], "slice_load_<k>" slice k's load (k = 0..n_s − 1) [N]; ``slice_loads`` (n, n_s) [N] by :meth:`slice_loads`.
    """
    batched = False
    compiled_twin = "sliced.sliced_race"

    def __init__(self, name, dofs, *, kind, race_marker, pin_marker, R_race, D, K, exponent, zeta, m_roller,
                 traction, z, drop, row_offset=0.0, race_slope=(0.0, 0.0), race_slopes=None, damping_ramp=0.0):
        self.name = name
        if kind not in ("inner", "outer"):
            raise ModelError(f"{name}: kind must be 'inner' or 'outer', got {kind!r}")
        self.kind = kind
        # the race body's slope pair among the coordinates: always for the bore, for the pin when it bends
        self.race_slopes = kind == "outer" if race_slopes is None else bool(race_slopes)
        if kind == "outer" and not self.race_slopes:
            raise ModelError(f"{name}: an outer raceway (the bore) takes its planet's slope pair (race_slopes)")
        self.n_local = 12 if self.race_slopes else 7
        d = np.asarray(dofs, dtype=np.int64)
        if d.ndim != 2 or d.shape[1] != self.n_local:
            raise ModelError(f"{name}: dofs must be (n, {self.n_local}) full indices for a {kind} contact "
                             f"(roller x y θ, tilt, race body x y θ{', slope x y, pin body x y θ' if self.race_slopes else ''}), "
                             f"got shape {d.shape}")
        self.dofs = d
        if not isinstance(traction, Traction):
            raise ModelError(f"{name}: traction must be a Traction, got {type(traction).__name__}")
        self.traction = traction
        self.kappa = 1.0 if kind == "inner" else -1.0
        self.race_marker = self._per_instance_xy("race_marker", race_marker)
        self.pin_marker = self._per_instance_xy("pin_marker", pin_marker)
        self.race_slope = self._per_instance_xy("race_slope", race_slope)
        self.R_race = self._per_instance("R_race", R_race, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.K = self._per_instance("K", K, positive=True)
        self.exponent = float(exponent)
        if not (np.isfinite(self.exponent) and self.exponent >= 1.0):
            raise ModelError(f"{name}: parameter 'exponent' must be >= 1, got {exponent!r}")
        self.zeta = self._per_instance("zeta", zeta, nonneg=True)
        self.m_roller = self._per_instance("m_roller", m_roller, positive=True)
        self.damping_ramp = self._per_instance("damping_ramp", damping_ramp, nonneg=True)
        self._ramped = bool(np.any(self.damping_ramp > 0.0))
        self.row_offset = self._per_instance("row_offset", row_offset)
        self.z = np.asarray(z, float)
        if self.z.ndim != 1 or self.z.size < 1 or not np.all(np.isfinite(self.z)):
            raise ModelError(f"{name}: parameter 'z' must be the (n_s,) slice stations [m], got {z!r}")
        self.n_s = self.z.size
        drop = np.asarray(drop, float)
        if drop.shape not in ((self.n_s,), (self.n, self.n_s)) or not np.all(np.isfinite(drop) & (drop >= 0)):
            raise ModelError(f"{name}: parameter 'drop' must be (n_s,) or (n, n_s) profile drops >= 0 [m], got shape "
                             f"{drop.shape}")
        self.drop = np.broadcast_to(drop, (self.n, self.n_s)).copy()
        self._c0 = 2.0 * self.zeta * np.sqrt(self.m_roller * self.exponent * self.K)
        self.R_red = 1.0 / (2.0 / self.D + self.kappa / self.R_race)
        self._zmax = float(np.abs(self.z).max())

    # ---------------------------------------------------------------------------------------------------------
    def _geometry(self, q, v):
        """In-plane geometry and the slopes (Duals or arrays, one per instance)."""
        qr, tau, qb = q[:3], q[3], q[4:7]
        vr, dtau, vb = v[:3], v[3], v[4:7]
        if self.race_slopes:
            s, ds, qp, vp = q[7:9], v[7:9], q[9:12], v[9:12]
        else:
            s, ds, qp, vp = None, None, qb, vb
        (cx, cy), rc = marker(qb, self.race_marker)
        Vc = marker_velocity(vb, rc)
        (px, py), rp = marker(qp, self.pin_marker)
        Vp = marker_velocity(vp, rp)
        # e: pin centre → roller centre, and its rate ė = (I − e eᵀ)(ṗ − ċ_pin)/ρ_p
        ux, uy = qr[0] - px, qr[1] - py
        rho_p = ad.sqrt(ux * ux + uy * uy + _ETA2)
        ex, ey = ux / rho_p, uy / rho_p
        gx, gy = vr[0] - Vp[0], vr[1] - Vp[1]
        ge = ex * gx + ey * gy
        dex, dey = (gx - ge * ex) / rho_p, (gy - ge * ey) / rho_p
        # the race's slope σ_c and its rate
        cth, sth = ad.cos(qb[2]), ad.sin(qb[2])
        s0x, s0y = self.race_slope[:, 0], self.race_slope[:, 1]
        scx, scy = cth * s0x - sth * s0y, sth * s0x + cth * s0y
        dscx, dscy = -1.0 * vb[2] * scy, vb[2] * scx
        kx, ky = scy, -1.0 * scx          # −k × Rot(θ_b)s_0: ∂σ_c/∂θ_b = k × σ_c0, kept for the θ_b force
        if s is not None:
            scx, scy = scx + s[0], scy + s[1]
            dscx, dscy = dscx + ds[0], dscy + ds[1]
        return dict(qr=qr, vr=vr, tau=tau, dtau=dtau, qb=qb, vb=vb, c=(cx, cy), rc=rc, Vc=Vc, rp=rp,
                    rho_p=rho_p, e=(ex, ey), de=(dex, dey), sc=(scx, scy), dsc=(dscx, dscy), k0=(kx, ky))

    def _slices(self, g, idx):
        """Slice compressions and loads of the contacts ``idx`` (flattened (m·n_s,))."""
        ns = self.n_s
        T = lambda x: ad.repeat_each(ad.take(x, idx), ns)                  # noqa: E731
        m = idx.size
        z = np.tile(self.z, m)
        zeta = np.repeat(self.row_offset[idx], ns) + z
        ex, ey, dex, dey = T(g["e"][0]), T(g["e"][1]), T(g["de"][0]), T(g["de"][1])
        tau, dtau = T(g["tau"]), T(g["dtau"])
        srx, sry = tau * ex, tau * ey
        dsrx, dsry = dtau * ex + tau * dex, dtau * ey + tau * dey
        scx, scy, dscx, dscy = T(g["sc"][0]), T(g["sc"][1]), T(g["dsc"][0]), T(g["dsc"][1])
        cx, cy = g["c"]
        qr, vr, Vc = g["qr"], g["vr"], g["Vc"]
        wx = T(qr[0] - cx) + z * srx - zeta * scx
        wy = T(qr[1] - cy) + z * sry - zeta * scy
        vwx = T(vr[0] - Vc[0]) + z * dsrx - zeta * dscx
        vwy = T(vr[1] - Vc[1]) + z * dsry - zeta * dscy
        d = ad.sqrt(wx * wx + wy * wy + _ETA2)
        nx, ny = wx / d, wy / d
        kap = self.kappa
        delta = np.repeat(0.5 * self.D[idx], ns) - kap * (d - np.repeat(self.R_race[idx], ns)) - self.drop[idx].ravel()
        delta_dot = -kap * (nx * vwx + ny * vwy)
        touch = ad.value(delta) > 0.0
        dsafe = ad.where(touch, delta, 1.0)
        p = self.exponent
        Ks, c0s = np.repeat(self.K[idx] / ns, ns), np.repeat(self._c0[idx] / ns, ns)
        c = c0s * ad.power(dsafe, 0.5 * (p - 1.0))
        if self._ramped:                # S(δ_k/δ_c) (class docstring); without a ramp the law as written, to the bit
            c = c * damping_share(dsafe, np.repeat(self.damping_ramp[idx], ns))
        q_raw = Ks * ad.power(dsafe, p) + c * delta_dot
        q = ad.where(touch & (ad.value(q_raw) > 0.0), q_raw, 0.0)
        return dict(q=q, n=(nx, ny), z=z, zeta=zeta, delta=delta)

    def _open_bound(self, g):
        """(n,) True where every slice is certainly open (class docstring): δ_0 + max|z σ_r − ζ σ_c| ≤ 0."""
        qr, (cx, cy) = g["qr"], g["c"]
        dx, dy = ad.value(qr[0] - cx), ad.value(qr[1] - cy)
        delta0 = 0.5 * self.D - self.kappa * (np.sqrt(dx * dx + dy * dy) - self.R_race)
        tau = np.abs(ad.value(g["tau"]))
        sc = np.hypot(ad.value(g["sc"][0]), ad.value(g["sc"][1]))
        reach = self._zmax * tau + (np.abs(self.row_offset) + self._zmax) * sc
        return delta0 + reach <= 0.0

    def kernel(self, t, fs, q, v, z):
        n, ns = self.n, self.n_s
        g = self._geometry(q, v)
        m_der = q[0].der.shape[1] if isinstance(q[0], ad.Dual) else 0
        idx = np.flatnonzero(~self._open_bound(g))
        sl = self._slices(g, idx)
        qk, (nx, ny), zk, zetak = sl["q"], sl["n"], sl["z"], sl["zeta"]
        kap = self.kappa
        Fx, Fy = kap * qk * nx, kap * qk * ny
        m = idx.size
        S = lambda x: ad.group_sum(x, m, ns)                                              # noqa: E731
        P = lambda x: ad.spread(x, idx, n, m_der)                                 # noqa: E731
        Q = P(S(qk))
        S0x, S0y = P(S(Fx)), P(S(Fy))
        S1x, S1y = P(S(zk * Fx)), P(S(zk * Fy))
        S2x, S2y = P(S(zetak * Fx)), P(S(zetak * Fy))
        Qz = P(S(zk * qk))
        # in-plane traction, as the planar contact, on the total load, applied at the load centroid z̄
        qr, vr, qb, vb, (cx, cy), rc, Vc = g["qr"], g["vr"], g["qb"], g["vb"], g["c"], g["rc"], g["Vc"]
        R = self.R_race
        dx, dy = qr[0] - cx, qr[1] - cy
        rho = ad.sqrt(dx * dx + dy * dy + _ETA2)
        ecx, ecy = dx / rho, dy / rho
        tx, ty = -1.0 * ecy, ecx
        r_roll = ((R - rho) * ecx, (R - rho) * ecy)
        r_race = (rc[0] + R * ecx, rc[1] + R * ecy)
        Vr = marker_velocity(vr, r_roll)
        Vb = marker_velocity(vb, r_race)
        ur, ub = Vr[0] * tx + Vr[1] * ty, Vb[0] * tx + Vb[1] * ty
        v_s = ur - ub
        wx, wy = vr[0] - Vc[0], vr[1] - Vc[1]
        vP = Vc[0] * tx + Vc[1] * ty + R * (wx * tx + wy * ty) / rho
        u_e = 0.5 * (ur + ub) - vP
        tr = self.traction
        loaded = ad.value(Q) > 0.0
        if tr.needs_load:
            mu = tr.coefficient(v_s, u_e, ad.where(loaded, Q, 1.0), self.R_red)
        else:
            mu = tr.coefficient(v_s, u_e) if tr.needs_rolling_speed else tr.coefficient(v_s)
        Ft = -1.0 * mu * Q
        Ftx, Fty = Ft * tx, Ft * ty
        zbar = ad.where(loaded, Qz / ad.where(loaded, Q, 1.0), 0.0)
        S1x, S1y = S1x + zbar * Ftx, S1y + zbar * Fty
        S2x, S2y = S2x + (zbar + self.row_offset) * Ftx, S2y + (zbar + self.row_offset) * Fty
        # generalised forces (class docstring)
        ex, ey = g["e"]
        tau, rho_p, rp = g["tau"], g["rho_p"], g["rp"]
        s1e = ex * S1x + ey * S1y
        Gx, Gy = tau * (S1x - s1e * ex) / rho_p, tau * (S1y - s1e * ey) / rho_p   # τ (I − e eᵀ) S1 / ρ_p
        tr_roll = point_force(r_roll, (Ftx, Fty))
        tr_race = point_force(r_race, (-1.0 * Ftx, -1.0 * Fty))
        k0x, k0y = g["k0"]
        f_roller = [S0x + Gx + tr_roll[0], S0y + Gy + tr_roll[1], tr_roll[2], s1e]
        f_race = [-1.0 * S0x + tr_race[0], -1.0 * S0y + tr_race[1],
                  -1.0 * (rc[0] * S0y - rc[1] * S0x) + tr_race[2] + (S2x * k0x + S2y * k0y)]
        f_pin = [-1.0 * Gx, -1.0 * Gy, -1.0 * (rp[0] * Gy - rp[1] * Gx)]
        if not self.race_slopes:         # the pin body is the race body
            forces = f_roller + [a + b for a, b in zip(f_race, f_pin)]
        else:
            forces = f_roller + f_race + [-1.0 * S2x, -1.0 * S2y] + f_pin
        delta0 = 0.5 * self.D - kap * (rho - R)
        qv = np.zeros((n, ns))
        qv[idx] = ad.value(qk).reshape(m, ns)
        scx, scy = g["sc"]
        outputs = {"load": Q, "deflection": delta0, "traction": Ft, "slip_velocity": v_s,
                   "angle": ad.wrap_angle(ad.arctan2(dy, dx) - qb[2]), "rolling_speed": u_e,
                   "fx": S0x + Ftx, "fy": S0y + Fty, "tilt": tau,
                   "slope": ad.value(scx) * ad.value(ex) + ad.value(scy) * ad.value(ey) - ad.value(tau),
                   "centroid": zbar, "max_slice_load": qv.max(axis=1),
                   "edge_load": np.maximum(qv[:, 0], qv[:, -1]), "mid_load": qv[:, ns // 2],
                   "race_slope_x": ad.value(scx), "race_slope_y": ad.value(scy),
                   **{f"slice_load_{k}": qv[:, k] for k in range(ns)},
                   "loaded_slices": (qv > 0.0).sum(axis=1).astype(float)}
        return forces, outputs

    def slice_loads(self, q_full, v_full) -> np.ndarray:
        """(n, n_s) slice loads [N] at full coordinates (q_full, v_full) (damping included)."""
        g = self._geometry(list(np.asarray(q_full)[self.dofs].T), list(np.asarray(v_full)[self.dofs].T))
        return self._slices(g, np.arange(self.n))["q"].reshape(self.n, self.n_s)
