"""Spur gear mesh: two flanks, optional backlash, time-varying stiffness (docs/model.md §6).

One :class:`GearMesh` family holds n meshes of one kind (all external or all internal). Local
coordinates are (x1, y1, θ1, x2, y2, θ2): gear 1 then gear 2. For the internal mesh gear 1 is the
planet and gear 2 the ring.

Compression of flank f = ±1 (exact for large motions, the same in every frame):

    external  δ_f = f·[r_b1(θ1 − φ_e) + r_b2(θ2 − φ_e) − u0] − (a − a0)·sin α − b/2,  e: c1 → c2
    internal  δ_f = f·[r_b2(θ2 − φ_e) − r_b1(θ1 − φ_e) − u0] + (a − a0)·sin α − b/2,  e: c2 → c1

with a = |c2 − c1| and φ_e the angle of e. The bracket (the transmission error s) is taken modulo
the base pitch p_b = 2π r_b1/z1, i.e. wrapped into (−p_b/2, p_b/2]: tooth pairs are identical, and
this removes the 2π jumps of φ_e = arctan2(...) when the line of centres turns through ±π (a
planet orbiting in the fixed frame) — such a jump shifts s by (z1 ± z2)·p_b, whole pitches.

Generalized forces are Q = −F_f ∇δ_f, with ∇δ_f written out analytically. Writing d for the centre
vector along e (external d = c2 − c1, internal d = c1 − c2), t = k × e, and κ = (r_b1 ± r_b2)/a:

    ∂δ_f/∂d = −f κ t − σ sin α e          (σ = +1 external, −1 internal)
    ∂δ_f/∂θ1 = σ f r_b1,   ∂δ_f/∂θ2 = f r_b2

At a = a0, κ = cos α and −∂δ_f/∂d is the spec's line of action n_f on the body at the head of d
(gear 2 external, the planet internal). δ is invariant under a rigid motion of both gears, so the
forces sum to zero and the moments balance about any point, exactly, in any state.

Flank force F_f = max(k(p) δ_f + c_m S(δ_f/δ_c) δ̇_f, 0) while δ_f > 0, else 0, with δ̇_f = ∇δ_f · q̇ (the
same in R and in I, because δ is frame-invariant). The damping grows with the compression over the first δ_c
(``damping_ramp``; S the quintic smoothstep, 0 at first touch, 1 from δ_c on), as the dissipation of a
contact grows with its compressed zone (the idea of Hunt & Crossley's law): a damping that switched on whole at
contact would make the force jump by c_m δ̇_f at every re-engagement. δ_c = 0 is that jump (Kelvin–Voigt). The mesh position p = z1 (θ1 − φ_e)/2π + p0 (mod 1) is
gear 1's angle relative to the line of centres, measured from the direction e that points from gear 1's
centre to its contact zone in both kinds (external: towards gear 2; internal: from the ring centre out
through the planet to where it touches the ring). It is computed from the states, never from time.

Mesh-cycle convention of :class:`RectangularStiffness`: double-tooth contact is centred
on p = (ε_α − 1)/2, i.e. it spans p ∈ [0, ε_α − 1) (a new tooth pair enters at p = 0) and single
contact spans [ε_α − 1, 1). Components choose p0 from the real tooth positions accordingly.

Manufacturing errors (docs/model.md §11; default none, and then the evaluation is exactly the error-free
one — the family skips them):

- Eccentricity / runout: gear b's geometric (tooth) centre sits at c_geo = c + R(θ_b)·o_b, o_b
  (``offset1``, ``offset2``) fixed in the gear's body axes. The law above is evaluated with the
  geometric centres in place of the body centres (their velocities v + ω k × R(θ)o), and the mesh force
  acts at the geometric centre: the body gets the force and the moment (R(θ)o) × F. Rigid-motion
  invariance, and so the exact force and moment balance, is kept.
- Tooth deviations, profile modification and tooth faults: the tooth-pair law (``pairs``,
  :mod:`mbd.elements.tooth_pairs`) replaces the flank forces F_f = k(p)·δ_f + c_m·δ̇_f by sums over the
  tooth pairs, each with its own gap; with every gap zero and no fault it is exactly the rectangular law.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from .. import ad
from ..element import Element, body_dofs, marker, marker_velocity
from ..errors import ModelError
from .tooth_pairs import ToothPairs, damping_share, flank_force, smooth_box

__all__ = ["StiffnessShape", "ConstantStiffness", "RectangularStiffness", "FourierStiffness", "STIFFNESS_SHAPES",
           "SlicedGearMesh",
           "GearMesh", "mesh_offset", "mesh_u0", "contact_ratio_to_fraction"]

_TWO_PI = 2.0 * np.pi


def contact_ratio_to_fraction(contact_ratio) -> float:
    """Fraction of a mesh cycle with two tooth pairs in contact, ε_α − 1 (needs 1 ≤ ε_α ≤ 2)."""
    eps = float(contact_ratio)
    if not (np.isfinite(eps) and 1.0 <= eps <= 2.0):
        raise ModelError(f"contact_ratio must be in [1, 2] for a spur mesh with single/double contact, got {contact_ratio!r}")
    return eps - 1.0


class StiffnessShape:
    """Base of the mesh-stiffness shapes k(p) = k_mean · factor(p), mean(factor) = 1, p the mesh position
    in cycles (any real; period 1). A shape is a small frozen dataclass registered in
    :data:`STIFFNESS_SHAPES` by name; :class:`GearMesh` evaluates it per family through ``fuse_key``,
    ``instance_args`` (per-instance arrays, so that families of one shape fuse) and ``family_factor``.
    The constructors :meth:`constant`, :meth:`rectangular`, :meth:`fourier` build the registered kinds."""
    single = 1.0     # k_single / k_mean and k_double / k_mean (1 unless the shape has two levels)
    double = 1.0

    def factor(self, p):  # pragma: no cover - abstract
        raise TypeError(f"{type(self).__name__} must define factor(p)")

    def fuse_key(self) -> tuple:
        """Families whose shapes have equal keys can be evaluated as one."""
        return (type(self).__name__, *(getattr(self, f.name) for f in dataclasses.fields(self)))

    def instance_args(self, n: int) -> tuple:
        """Per-instance (n,) arrays that ``family_factor`` reads (none: the shape is family-wide)."""
        return ()

    def family_factor(self, p, args: tuple):
        """factor(p) of a (fused) family, from its concatenated ``instance_args``; Dual-capable."""
        return self.factor(p)

    @staticmethod
    def constant() -> "ConstantStiffness":
        return ConstantStiffness()

    @staticmethod
    def rectangular(contact_ratio: float, ratio: float, smoothing: float) -> "RectangularStiffness":
        return RectangularStiffness(float(contact_ratio), float(ratio), float(smoothing))

    @staticmethod
    def fourier(a=(), b=()) -> "FourierStiffness":
        return FourierStiffness(a=tuple(np.atleast_1d(np.asarray(a, float))),
                                b=tuple(np.atleast_1d(np.asarray(b, float))))


@dataclass(frozen=True)
class ConstantStiffness(StiffnessShape):
    """factor 1: k = k_mean."""

    def factor(self, p):
        return 1.0


@dataclass(frozen=True)
class RectangularStiffness(StiffnessShape):
    """Smoothed rectangular wave between k_single and k_double = ratio·k_single: double contact over the
    fraction ε_α − 1 of each cycle (p ∈ [0, ε_α − 1) with the ramps centred on the edges); each edge is a
    quintic smoothstep (C², exactly periodic) of full width ``smoothing`` cycles, which must not exceed
    min(ε_α − 1, 2 − ε_α)."""
    contact_ratio: float
    ratio: float
    smoothing: float

    def __post_init__(self):
        frac = contact_ratio_to_fraction(self.contact_ratio)
        if not (np.isfinite(self.ratio) and self.ratio > 0):
            raise ModelError(f"StiffnessShape: ratio k_double/k_single must be > 0, got {self.ratio!r}")
        s_max = min(frac, 1.0 - frac)
        if not (np.isfinite(self.smoothing) and 0 < self.smoothing <= s_max):
            raise ModelError(
                f"StiffnessShape: smoothing (ramp width, fraction of a mesh cycle) must be in (0, {s_max:.4g}] "
                f"for contact_ratio {self.contact_ratio!r} (ramps may not overlap), got {self.smoothing!r}")

    @property
    def single(self) -> float:
        return 1.0 / (1.0 + (self.ratio - 1.0) * (self.contact_ratio - 1.0))

    @property
    def double(self) -> float:
        return self.ratio * self.single

    def _args(self):
        return 0.5 * (self.contact_ratio - 1.0), self.smoothing, self.single, self.ratio

    def factor(self, p):
        return _rect_factor(p, *self._args())

    def fuse_key(self):
        return ("RectangularStiffness",)      # parameters are per instance: any two rectangular families fuse

    def instance_args(self, n):
        return tuple(np.full(n, x) for x in self._args())

    def family_factor(self, p, args):
        return _rect_factor(p, *args)


@dataclass(frozen=True)
class FourierStiffness(StiffnessShape):
    """factor = 1 + Σ_j a_j cos(2πjp) + b_j sin(2πjp), j = 1, 2, ...; must stay > 0 over the cycle."""
    a: tuple
    b: tuple

    def __post_init__(self):
        a = np.asarray(self.a, float).ravel()
        b = np.asarray(self.b, float).ravel()
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise ModelError(f"StiffnessShape: Fourier coefficients a, b must be finite, got a={self.a!r}, b={self.b!r}")
        object.__setattr__(self, "a", tuple(a.tolist()))
        object.__setattr__(self, "b", tuple(b.tolist()))
        nh = max(len(self.a), len(self.b), 1)
        p = np.linspace(0.0, 1.0, 64 * nh, endpoint=False)
        if np.min(self.factor(p)) <= 0.0:
            raise ModelError("StiffnessShape: Fourier stiffness 1 + Σ a_j cos + b_j sin must stay > 0 over the cycle, "
                             f"got a={self.a!r}, b={self.b!r}")

    def factor(self, p):
        out = 1.0
        for j, aj in enumerate(self.a, start=1):
            out = out + aj * ad.cos(_TWO_PI * j * p)
        for j, bj in enumerate(self.b, start=1):
            out = out + bj * ad.sin(_TWO_PI * j * p)
        return out


# the mesh-stiffness shapes by name
STIFFNESS_SHAPES = MappingProxyType({"constant": ConstantStiffness, "rectangular": RectangularStiffness,
                                     "fourier": FourierStiffness})


def _distance(p, centre, period):
    """|p − centre| on a circle of circumference ``period``, in [0, period/2]."""
    return ad.abs_(ad.wrap_angle(_TWO_PI / period * (p - centre)) * (period / _TWO_PI))


_box = smooth_box


def _rect_factor(p, h, s, single, ratio):
    """Smoothed rectangular wave k/k_mean: double-contact window of half width h centred at p = h
    (period 1), quintic-smoothstep edges of width s. Parameters may be per-instance (n,) arrays."""
    return single * (1.0 + (ratio - 1.0) * _box(_distance(p, h, 1.0), h, s))


def mesh_offset(internal: bool, rb1, rb2, theta1, theta2, phi):
    """u0 for gear angles θ1, θ2 and line-of-centres angle φ_e: the transmission error is zero there,
    so both flanks sit at δ = −b/2 (the law of the module docstring with s = 0)."""
    rb1, rb2, th1, th2, phi = (np.asarray(x, float) for x in (rb1, rb2, theta1, theta2, phi))
    if internal:
        return rb2 * (th2 - phi) - rb1 * (th1 - phi)
    return rb1 * (th1 - phi) + rb2 * (th2 - phi)


def mesh_u0(internal: bool, rb1, rb2, pose1, pose2):
    """The u0 that makes the transmission error zero with the gears at poses (x, y, θ) (any one frame).

    Pass the nominal poses ((n, 3) or (3,)); with it both flanks sit at δ = −b/2."""
    p1 = np.atleast_2d(np.asarray(pose1, float))
    p2 = np.atleast_2d(np.asarray(pose2, float))
    d = (p1 - p2) if internal else (p2 - p1)
    return mesh_offset(internal, rb1, rb2, p1[:, 2], p2[:, 2], np.arctan2(d[:, 1], d[:, 0]))


class GearMesh(Element):
    """n spur meshes of one kind between gear 1 and gear 2 (see the module docstring for the law).

    Parameters (scalars or (n,) arrays, SI): ``rb1``, ``rb2`` base radii [m]; ``alpha`` operating
    pressure angle [rad]; ``a0`` nominal centre distance [m] (involute geometry requires
    r_b1 ± r_b2 = a0 cos α, checked); ``teeth1`` tooth count of gear 1 (r_b2/r_b1 must be a tooth-count
    ratio); ``k_mean`` mean mesh stiffness [N/m]; ``c_mesh`` mesh damping [N·s/m]; ``u0`` [m] from
    :func:`mesh_u0`; ``p0`` mesh phase [cycles]; ``backlash`` b ≥ 0 [m] (b = 0: both flanks touch at
    the nominal state with zero force); ``damping_ramp`` δ_c ≥ 0 [m], the compression over which the damping
    grows to c_m (0: all of it at first touch); ``stiffness`` a :class:`StiffnessShape` shared by the family;
    ``phi_ref`` [rad] the nominal angle of e: φ_e is taken in (phi_ref − π, phi_ref + π], so a u0
    computed with an unwrapped nominal angle matches exactly (any 2π offset costs whole base pitches,
    which the pitch wrap removes anyway).

    Errors (module docstring; default none): ``offset1``, ``offset2`` (2,) or (n, 2) [m] the geometric
    centre of gear 1 / gear 2 in its body axes (eccentricity / runout); a family whose offsets are all zero
    is evaluated exactly as one without them. ``pairs``: a :class:`~mbd.elements.tooth_pairs.ToothPairs`
    (tooth deviations, relief, tooth faults) for the tooth-pair law, which needs the rectangular stiffness.

    Outputs: ``force`` = F_drive − F_coast [N] (signed: > 0 when flank f = +1 carries the load);
    ``force_drive``, ``force_coast`` ≥ 0 (flanks f = +1, −1); ``deflection`` δ_+ and
    ``deflection_coast`` δ_− [m]; ``deflection_rate``, ``deflection_rate_coast`` δ̇_± [m/s]; ``stiffness`` k(p) [N/m];
    ``position`` p in [0, 1); ``fx``, ``fy`` the mesh force on gear 2 in R [N] (gear 1 gets minus it).
    """
    batched = True
    n_local = 6
    compiled_twin = "mesh.gear_mesh"

    def __init__(self, name, gear1, gear2, *, internal: bool, rb1, rb2, alpha, a0, teeth1, k_mean,
                 c_mesh=0.0, damping_ramp=0.0, u0=0.0, p0=0.0, backlash=0.0, stiffness: StiffnessShape | None = None,
                 phi_ref=0.0, offset1=None, offset2=None, pairs: ToothPairs | None = None):
        self.name = name
        self.dofs = body_dofs(gear1, gear2)
        self.internal = bool(internal)
        self.rb1 = self._per_instance("rb1", rb1, positive=True)
        self.rb2 = self._per_instance("rb2", rb2, positive=True)
        self.alpha = self._per_instance("alpha", alpha, positive=True)
        self.a0 = self._per_instance("a0", a0, positive=True)
        self.teeth1 = self._per_instance("teeth1", teeth1, positive=True)
        self.k_mean = self._per_instance("k_mean", k_mean, positive=True)
        self.c_mesh = self._per_instance("c_mesh", c_mesh, nonneg=True)
        self.damping_ramp = self._per_instance("damping_ramp", damping_ramp, nonneg=True)
        self.u0 = self._per_instance("u0", u0)
        self.p0 = self._per_instance("p0", p0)
        self.backlash = self._per_instance("backlash", backlash, nonneg=True)
        self.phi_ref = self._per_instance("phi_ref", phi_ref)
        self.stiffness = StiffnessShape.constant() if stiffness is None else stiffness
        if not isinstance(self.stiffness, StiffnessShape):
            raise ModelError(f"{name}: parameter 'stiffness' must be a StiffnessShape, got {stiffness!r}")
        if np.any(self.alpha >= 0.5 * np.pi):
            raise ModelError(f"{name}: parameter 'alpha' must be a pressure angle in (0, pi/2) rad, got {alpha!r}")
        if np.any(self.teeth1 != np.round(self.teeth1)):
            raise ModelError(f"{name}: parameter 'teeth1' must be whole tooth counts, got {teeth1!r}")
        if self.internal and np.any(self.rb2 <= self.rb1):
            raise ModelError(f"{name}: internal mesh needs the ring's base radius rb2 > the planet's rb1, got rb1={rb1!r}, rb2={rb2!r}")
        # involute geometry: the line of action is tangent to both base circles
        rsum = self.rb2 - self.rb1 if self.internal else self.rb1 + self.rb2
        if not np.allclose(rsum, self.a0 * np.cos(self.alpha), rtol=1e-6, atol=0.0):
            raise ModelError(f"{name}: parameters 'a0', 'alpha' must satisfy rb1 {'−' if self.internal else '+'} rb2"
                             f"{' (ring − planet)' if self.internal else ''} = a0·cos(alpha); got "
                             f"{rsum!r} vs {self.a0 * np.cos(self.alpha)!r}")
        # the transmission error is wrapped modulo the base pitch: rb2 must be a whole number of pitches
        z2 = self.rb2 / self.rb1 * self.teeth1
        if not np.allclose(z2, np.round(z2), rtol=0.0, atol=1e-6):
            raise ModelError(f"{name}: parameter 'rb2' must equal rb1·z2/teeth1 for a whole tooth count z2 "
                             f"(same base pitch), got z2 = {z2!r}")
        self.pitch = _TWO_PI * self.rb1 / self.teeth1      # base pitch p_b [m]
        self.kappa0 = rsum                                  # κ·a
        # per instance, so that families of different kinds can be evaluated as one (System fusion)
        self.sigma = np.full(self.n, -1.0 if self.internal else 1.0)
        self.sin_alpha = np.sin(self.alpha)
        self._shape_args = self.stiffness.instance_args(self.n)
        self.offset1, self.offset2 = (np.zeros((self.n, 2)) if o is None else self._per_instance_xy(k, o)
                                      for k, o in (("offset1", offset1), ("offset2", offset2)))
        self.has_offset = bool(np.any(self.offset1 != 0.0) or np.any(self.offset2 != 0.0))
        self.teeth2 = np.round(z2)
        self._init_pairs(pairs)

    def _init_pairs(self, pairs):
        """The tooth-pair law's data (None: the lumped law), validated."""
        self.pairs = None
        if pairs is None:
            return
        if not isinstance(self.stiffness, RectangularStiffness):
            raise ModelError(f"{self.name}: the tooth-pair law splits the rectangular stiffness over the pairs; "
                             f"parameter 'stiffness' must be rectangular, got {type(self.stiffness).__name__}")
        self.pairs = pairs.checked(self.name, self.n, self.teeth1, self.teeth2)

    _FUSED = ("dofs", "rb1", "rb2", "alpha", "a0", "teeth1", "teeth2", "k_mean", "c_mesh", "damping_ramp", "u0", "p0",
              "backlash",
              "phi_ref", "pitch", "kappa0", "sigma", "sin_alpha", "offset1", "offset2")

    def fuse_key(self):
        return ("GearMesh", *self.stiffness.fuse_key(), self.pairs is not None)

    @classmethod
    def fuse(cls, parts):
        """One family holding the instances of several (external and internal alike)."""
        f = super().fuse(parts)
        f.internal = None
        f.stiffness = parts[0].stiffness
        # the offsets are evaluated for the whole fused family when any part has them (the others' are
        # zero, which gives the same values)
        f.has_offset = any(p.has_offset for p in parts)
        f._shape_args = tuple(np.concatenate(cols) for cols in zip(*(p._shape_args for p in parts)))
        f.pairs = ToothPairs.fuse([p.pairs for p in parts]) if parts[0].pairs is not None else None
        return f

    def _factor(self, p):
        return self.stiffness.family_factor(p, self._shape_args)

    def kernel(self, t, fs, q, v, z):
        g = self._geometry(q, v)
        F_plus, F_minus, kp = self._flank_forces(g, g["d_plus"], g["d_minus"], g["r_plus"], g["r_minus"])
        return self._forces(g, F_plus, F_minus, kp)

    def _flank_forces(self, g, d_plus, d_minus, r_plus, r_minus, scale=1.0):
        """(F_+, F_−, k(p)) of flank compressions and rates (lumped or tooth-pair law); ``scale`` multiplies the
        stiffness and damping (a face slice's share)."""
        p = g["p"]
        if self.pairs is not None:     # tooth by tooth (tooth_pairs), each flank over its own pairs
            sig, th1, th2, phi_e, t_dd, inv_a, w1 = (g[k] for k in ("sig", "th1", "th2", "phi_e", "t_dd", "inv_a", "w1"))
            pair_args = (self.pairs, sig, self.teeth1, self.teeth2, self.k_mean * scale if scale != 1.0 else self.k_mean,
                         self.c_mesh * scale if scale != 1.0 else self.c_mesh, self.damping_ramp,
                         self._shape_args, th1, th2, phi_e, t_dd * inv_a, w1)
            F_plus, kp = flank_force(pair_args[0], 1, *pair_args[1:], d_plus, r_plus)
            F_minus, _ = flank_force(pair_args[0], -1, *pair_args[1:], d_minus, r_minus)
        else:
            kp = self.k_mean * self._factor(p)
            c, ramp = self.c_mesh, self.damping_ramp
            if scale != 1.0:
                kp, c = kp * scale, c * scale
            F_plus = ad.where(d_plus > 0.0, ad.pos(kp * d_plus + c * damping_share(d_plus, ramp) * r_plus), 0.0)
            F_minus = ad.where(d_minus > 0.0, ad.pos(kp * d_minus + c * damping_share(d_minus, ramp) * r_minus), 0.0)
        return F_plus, F_minus, kp

    def _geometry(self, q, v):
        """The flank compressions, their rates and the mesh geometry (module docstring) as a dict."""
        x1, y1, th1, x2, y2, th2 = q[:6]
        vx1, vy1, w1, vx2, vy2, w2 = v[:6]
        r1 = r2 = None
        if self.has_offset:   # the law in the geometric centres c + R(θ)·offset (eccentricity / runout)
            (x1, y1), r1 = marker((x1, y1, th1), self.offset1)
            (x2, y2), r2 = marker((x2, y2, th2), self.offset2)
            vx1, vy1 = marker_velocity((vx1, vy1, w1), r1)
            vx2, vy2 = marker_velocity((vx2, vy2, w2), r2)
        sig = self.sigma      # +1 external, −1 internal (per instance)
        # centre vector d along e (external c1 → c2, internal ring → planet) and its rate
        dx, dy, ddx, ddy = sig * (x2 - x1), sig * (y2 - y1), sig * (vx2 - vx1), sig * (vy2 - vy1)
        a = ad.hypot(dx, dy)
        inv_a = 1.0 / a
        ex, ey = dx * inv_a, dy * inv_a
        tx, ty = -ey, ex
        # φ_e on the branch (phi_ref − π, phi_ref + π]: continuous near the nominal line of centres
        phi_e = self.phi_ref + ad.wrap_angle(ad.arctan2(dy, dx) - self.phi_ref)
        raw = sig * self.rb1 * (th1 - phi_e) + self.rb2 * (th2 - phi_e) - self.u0
        roll = sig * self.rb1 * w1 + self.rb2 * w2
        pb = self.pitch
        s = ad.wrap_angle(raw * (_TWO_PI / pb)) * (pb / _TWO_PI)   # transmission error mod base pitch
        kappa = self.kappa0 * inv_a
        radial = sig * self.sin_alpha * (a - self.a0)
        half_b = 0.5 * self.backlash
        # rates: ṡ = roll − κ t·ḋ, ȧ = e·ḋ
        t_dd = tx * ddx + ty * ddy
        e_dd = ex * ddx + ey * ddy
        s_dot = roll - kappa * t_dd
        radial_dot = sig * self.sin_alpha * e_dd
        d_plus = s - radial - half_b
        d_minus = -1.0 * s - radial - half_b
        r_plus = s_dot - radial_dot
        r_minus = -1.0 * s_dot - radial_dot
        p = self.teeth1 * (th1 - phi_e) * (1.0 / _TWO_PI) + self.p0
        return dict(sig=sig, th1=th1, th2=th2, w1=w1, phi_e=phi_e, t_dd=t_dd, inv_a=inv_a, a=a, e_dd=e_dd,
                    kappa=kappa, ex=ex, ey=ey, tx=tx, ty=ty, r1=r1, r2=r2, p=p, d_plus=d_plus, d_minus=d_minus,
                    r_plus=r_plus, r_minus=r_minus)

    def _forces(self, g, F_plus, F_minus, kp, extra=None):
        """Generalized forces and outputs of the flank forces; ``extra`` (x, y): a further force on the body at the
        head of d (the face slices' terms)."""
        sig, kappa, ex, ey, tx, ty, r1, r2, p = (g[k] for k in ("sig", "kappa", "ex", "ey", "tx", "ty", "r1", "r2",
                                                                  "p"))
        # Q = −Σ F_f ∇δ_f; on the body at the head of d: (F+ − F−) κ t + σ (F+ + F−) sin α e
        F_net = F_plus - F_minus
        F_sum = F_plus + F_minus
        Fx_head = F_net * kappa * tx + sig * self.sin_alpha * F_sum * ex
        Fy_head = F_net * kappa * ty + sig * self.sin_alpha * F_sum * ey
        if extra is not None:
            Fx_head, Fy_head = Fx_head + extra[0], Fy_head + extra[1]
        T1 = -sig * self.rb1 * F_net
        T2 = -1.0 * self.rb2 * F_net
        # the head of d is gear 2 (external) or gear 1, the planet (internal)
        f1x, f1y, f2x, f2y = -sig * Fx_head, -sig * Fy_head, sig * Fx_head, sig * Fy_head
        if self.has_offset:   # the force acts at the geometric centre: its moment about the body centre
            T1 = T1 + (r1[0] * f1y - r1[1] * f1x)
            T2 = T2 + (r2[0] * f2y - r2[1] * f2x)
        outputs = {
            "force": F_net, "force_drive": F_plus, "force_coast": F_minus,
            "deflection": g["d_plus"], "deflection_coast": g["d_minus"],
            "deflection_rate": g["r_plus"], "deflection_rate_coast": g["r_minus"],
            "stiffness": np.broadcast_to(ad.value(kp), np.shape(ad.value(p))).astype(float),
            "position": np.mod(ad.value(p), 1.0),
            "fx": f2x, "fy": f2y,
        }
        return [f1x, f1y, T1, f2x, f2y, T2], outputs


class SlicedGearMesh(GearMesh):
    """The lumped mesh law of :class:`GearMesh` with each flank cut into n_m slices across the face width b, so that
    the mesh resists its gears' relative slope (docs/model.md §6.6). Gear i's section at axial station ζ is displaced
    by ζ s_i (s_i its slope pair, or none: a gear without slopes), so flank f's compression there is

        δ_f(ζ) = δ_f + ζ g_f·(s_2 − s_1),   g_f = ∂δ_f/∂c_2 = −σ f κ t − sin α e,

    the planar compression's gradient in gear 2's centre (at a = a0, |g_f| = 1: the line of action). Slice k, at
    ζ_k = (k − (n_m + 1)/2) b/n_m, carries (k(p)/n_m) δ_f(ζ_k) + (c_m/n_m) S(δ_f(ζ_k)/δ_c) δ̇_f(ζ_k) while δ_f(ζ_k) > 0
    (clipped at ≥ 0): with s_1 = s_2 every slice carries 1/n_m of today's flank force and their sum is the lumped law.
    Generalised forces −Σ_k F_fk ∇δ_f(ζ_k): the lumped ones with F_f = Σ_k F_fk, on the slopes ∓Σ_f M_f g_f
    (M_f = Σ_k ζ_k F_fk, the flank's moment), and on the centres −Σ_f M_f ∂(g_f·Δs)/∂d, the second-order change of the
    line of action with the centre distance. With every slice in contact the mesh's tilt stiffness along g_f is
    k b²(1 − 1/n_m²)/12 ≈ c_γ b³/12 (c_γ = k/b per unit face width).

    With ``pairs`` the tooth-pair law (mbd.elements.tooth_pairs) takes the lumped law's place slice by slice: every
    slice has its mesh's teeth, gaps and pairs' shares, with 1/n_m of the stiffness and damping (uniform slices: the
    tooth-pair mesh to round-off).

    Local coordinates: gear 1 (x, y, θ), gear 2 (x, y, θ), then gear 1's slopes (if ``slopes1``), gear 2's (if
    ``slopes2``): full indices (n, 2) or None. ``face_width`` b [m] per mesh; ``slices`` n_m. Outputs: GearMesh's and "tilt_moment" M_+ − M_− [N m], "relative_slope" g·Δs of the loaded
    flank's line [rad]."""
    compiled_twin = "sliced.sliced_gear_mesh"
    batched = True             # its slices along the instance axis: K states (K, n) in one call (ad.repeat_each)

    def __init__(self, name, gear1, gear2, *, slopes1=None, slopes2=None, face_width, slices, **kw):
        super().__init__(name, gear1, gear2, **kw)
        self.has1, self.has2 = slopes1 is not None, slopes2 is not None
        cols = [self.dofs]
        for has, sl, key in ((self.has1, slopes1, "slopes1"), (self.has2, slopes2, "slopes2")):
            if has:
                sl = np.asarray(sl, np.int64)
                if sl.shape != (self.n, 2):
                    raise ModelError(f"{name}: parameter {key!r} must be ({self.n}, 2) full slope indices, got {sl.shape}")
                cols.append(sl)
        self.dofs = np.hstack(cols)
        self.n_local = self.dofs.shape[1]
        self.face_width = self._per_instance("face_width", face_width, positive=True)
        n_m = int(slices)
        if n_m < 1 or n_m != slices:
            raise ModelError(f"{name}: parameter 'slices' must be an integer >= 1, got {slices!r}")
        self.n_m = n_m
        self._unit = np.arange(1, n_m + 1) - 0.5 * (n_m + 1)          # ζ_k / (b/n_m)
        if self.pairs is not None:      # every slice of a mesh has its mesh's teeth: the per-mesh rows repeated
            pp = self.pairs
            rep = lambda a: np.repeat(a, n_m, axis=0)                     # noqa: E731
            self._slice_pairs = ToothPairs(rep(pp.entry), rep(pp.phase2), rep(pp.relief1), rep(pp.relief2), pp.table,
                                           rep(pp.start1), rep(pp.start2))

    def fuse_key(self):
        return None

    def kernel(self, t, fs, q, v, z):
        g = self._geometry(q, v)
        n, nm = self.n, self.n_m
        j = 6
        zero = 0.0 * q[0]
        s1x = s1y = v1x = v1y = zero
        s2x = s2y = v2x = v2y = zero
        if self.has1:
            s1x, s1y, v1x, v1y = q[j], q[j + 1], v[j], v[j + 1]
            j += 2
        if self.has2:
            s2x, s2y, v2x, v2y = q[j], q[j + 1], v[j], v[j + 1]
        dsx, dsy, dvx, dvy = s2x - s1x, s2y - s1y, v2x - v1x, v2y - v1y
        sig, kappa, ex, ey, tx, ty, a = (g[k] for k in ("sig", "kappa", "ex", "ey", "tx", "ty", "a"))
        t_dd, e_dd, sa = g["t_dd"], g["e_dd"], self.sin_alpha
        t_s, e_s = tx * dsx + ty * dsy, ex * dsx + ey * dsy           # t·Δs, e·Δs
        # rates of e, t, κ (ė = t (t·ḋ)/a, ṫ = −e (t·ḋ)/a, κ̇ = −κ (e·ḋ)/a)
        kp = self.k_mean * self._factor(g["p"]) if self.pairs is None else None
        zeta = ad.repeat_each(self.face_width / nm, nm) * np.tile(self._unit, n)
        R = lambda x: ad.repeat_each(x, nm)                                   # noqa: E731
        if self.pairs is not None:      # the tooth-pair law per slice, each slice 1/n_m of the mesh's stiffness
            pair_args = (self._slice_pairs, R(sig), R(self.teeth1), R(self.teeth2), R(self.k_mean / nm),
                         R(self.c_mesh / nm), R(self.damping_ramp), tuple(R(x) for x in self._shape_args),
                         R(g["th1"]), R(g["th2"]), R(g["phi_e"]), R(t_dd * g["inv_a"]), R(g["w1"]))
            K_sum = 0.0
        F, M, gvec, gsv = {}, {}, {}, {}
        for f, d_f, r_f in ((1.0, g["d_plus"], g["r_plus"]), (-1.0, g["d_minus"], g["r_minus"])):
            gx = -sig * f * kappa * tx - sa * ex
            gy = -sig * f * kappa * ty - sa * ey
            gs = gx * dsx + gy * dsy
            # (g·Δs)˙ = ġ·Δs + g·Δṡ, ġ = σ f κ ((e·ḋ) t + (t·ḋ) e)/a − sin α t (t·ḋ)/a
            gs_dot = (sig * f * kappa * (e_dd * t_s + t_dd * e_s) - sa * t_dd * t_s) / a + gx * dvx + gy * dvy
            d_k = R(d_f) + zeta * R(gs)
            r_k = R(r_f) + zeta * R(gs_dot)
            if self.pairs is not None:
                F_k, K_k = flank_force(pair_args[0], int(f), *pair_args[1:], d_k, r_k)
                if f > 0:
                    K_sum = ad.group_sum(K_k, n, nm)
            else:
                k_k, c_k = R(kp / nm), R(self.c_mesh / nm)
                F_k = ad.where(d_k > 0.0, ad.pos(k_k * d_k + c_k * damping_share(d_k, R(self.damping_ramp)) * r_k),
                               0.0)
            F[f], M[f] = ad.group_sum(F_k, n, nm), ad.group_sum(zeta * F_k, n, nm)
            gvec[f], gsv[f] = (gx, gy), gs
        # −Σ_f M_f ∂(g_f·Δs)/∂d on the head of d; ∂(g_f·Δs)/∂d = σ f κ ((t·Δs) e + (e·Δs) t)/a − sin α (t·Δs) t/a
        hx = hy = zero
        for f in (1.0, -1.0):
            cx = (sig * f * kappa * t_s) / a
            ct = (sig * f * kappa * e_s - sa * t_s) / a
            hx = hx - M[f] * (cx * ex + ct * tx)
            hy = hy - M[f] * (cx * ey + ct * ty)
        forces, outputs = self._forces(g, F[1.0], F[-1.0], kp if self.pairs is None else K_sum, extra=(hx, hy))
        qsx = M[1.0] * gvec[1.0][0] + M[-1.0] * gvec[-1.0][0]
        qsy = M[1.0] * gvec[1.0][1] + M[-1.0] * gvec[-1.0][1]
        if self.has1:
            forces += [qsx, qsy]
        if self.has2:
            forces += [-1.0 * qsx, -1.0 * qsy]
        outputs["tilt_moment"] = M[1.0] - M[-1.0]
        outputs["relative_slope"] = ad.value(gsv[1.0])
        return forces, outputs
