"""Planet-bearing contacts (docs/model.md §8): roller–raceway Hertz line contact with traction,
roller–cage pocket impact (and the pocket's radial retention of a roller-centred cage), cage–guide-land impact and
lubricant drag on the rollers.

Every family covers all rollers (or cages) of all bearings at once; each instance couples two bodies
(k = 6: first body x, y, θ, then second body x, y, θ). Forces that act at a contact point are applied
at the *same* world point on both bodies, equal and opposite, so forces and moments balance exactly
about any point. Kernels are written with :mod:`mbd.ad` so the assembler gets exact Jacobians.

Regularisations (all smooth, documented where they are made):
- centre distances use a safe norm sqrt(x² + y² + η²), η = 1e-12 m: bitwise identical to |x| at any
  real bearing distance, finite derivatives when two centres coincide (a centred cage at t = 0);
- friction laws are tanh-regularised Coulomb laws (no stick state in a stateless element);
- the slide-to-roll traction curve uses a regularised slide-to-roll ratio (see :class:`SlideRollTraction`).

The pocket, pocket-retention and guide-land impacts carry internal state (the approach speed of the current impact,
for Hunt–Crossley damping that gives the set restitution at any speed), so those families are never fused.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from scipy.optimize import brentq

from .. import ad
from . import ehl
from .tooth_pairs import damping_share
from ..element import Element, body_dofs, marker, marker_velocity, point_force
from ..errors import ModelError

__all__ = ["Traction", "TanhTraction", "SlideRollTraction", "EHLTraction", "TRACTION_LAWS", "ImpactLaw", "ExactRestitution",
           "HuntCrossley", "LankaraniNikravesh", "Flores", "IMPACT_LAWS", "RaceContact", "PocketContact", "PocketRetention",
           "GuideContact", "LubricantDrag", "restitution_lambda", "LandLaw", "DryLand", "HydrodynamicLand",
           "LAND_LAWS", "spall_profile", "RollingResistance", "HoupertRolling", "ROLLING_LAWS"]

_ETA2 = 1e-24  # (1e-12 m)²: below round-off of any physical distance squared, keeps norms nonzero


def _norm(x, y):
    """Safe Euclidean norm (see module docstring)."""
    return ad.sqrt(x * x + y * y + _ETA2)


def _multiplicity(elem: Element, value) -> np.ndarray:
    """(n,) positive integer-valued multiplicity: identical parallel contacts acting as one instance."""
    a = elem._per_instance("multiplicity", value, positive=True)
    if np.any(a != np.round(a)):
        raise ModelError(f"{elem.name}: parameter 'multiplicity' must be a positive integer (number of identical "
                         f"parallel contacts), got {value!r}")
    return a


def _scaled(forces, mult, scale: bool):
    """Generalized forces of one physical contact times its multiplicity (skipped when all are 1)."""
    return [f * mult for f in forces] if scale else forces


def _restitution_lambda_one(e: float) -> float:
    """λ > 0 with ln((1 + λ)/(1 − λe)) = λ(1 + e), for 0 < e < 1.

    Root of h(λ) = g(λ)/λ², g the residual: h(0) = (e² − 1)/2 < 0 and h → +∞ as λ → 1/e. Near λ = 0
    h is summed from its series Σ_{k≥2} λ^(k−2)(e^k − (−1)^k)/k (no cancellation as e → 1); the unknown is
    y = −ln(1 − λe) ∈ (0, ∞), which keeps λ → 1/e resolvable for small e."""
    k = np.arange(2, 40)
    ck = np.where(k % 2 == 0, np.expm1(k * np.log(e)), e ** k + 1.0) / k

    def h(y):
        lam = -np.expm1(-y) / e
        if lam < 0.25:                       # series: terms fall by ≥ 4× each, 38 terms reach round-off
            return float(np.sum(ck * lam ** (k - 2)))
        return (np.log1p(lam) + y - lam * (1.0 + e)) / (lam * lam)

    y_hi = (1.0 + e) / e + 1.0              # g(y_hi) > y_hi − (1 + e)/e = 1 > 0
    y = brentq(h, 0.0, y_hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    return float(-np.expm1(-y) / e)


def restitution_lambda(e) -> np.ndarray:
    """Dimensionless Hunt–Crossley damping λ(e) = c·v₀ that gives the coefficient of restitution e exactly.

    For m ẍ = −K xⁿ (1 + c ẋ), v dv/(1 + c v) = −(K/m) xⁿ dx; integrated over the impact (x: 0 → 0, ẋ: v₀ →
    −e v₀) the potential term cancels:  ln((1 + λ)/(1 − λe)) = λ(1 + e),  λ = c v₀,  for any n, K, m.
    λ(1) = 0; λ ≈ 3(1 − e)/2 as e → 1 (Hunt–Crossley); λ → 1/e as e → 0. ``e`` in (0, 1], scalar or array."""
    e = np.asarray(e, dtype=float)
    u, inv = np.unique(e, return_inverse=True)
    lam = np.array([0.0 if x >= 1.0 else _restitution_lambda_one(float(x)) for x in u])
    return lam[inv].reshape(e.shape)


class ImpactLaw:
    """Base of the impact damping laws F = K x (1 + λ ẋ/v₀) (docs/model.md §8.4): a law is the dimensionless
    damping λ(e) = c·v₀ for a coefficient of restitution e, a small frozen dataclass registered in
    :data:`IMPACT_LAWS` by name (a parameter chooses one)."""

    def damping(self, e: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise TypeError(f"{type(self).__name__} must define damping(e)")


@dataclass(frozen=True)
class ExactRestitution(ImpactLaw):
    """λ(e) from ln((1 + λ)/(1 − λe)) = λ(1 + e) (:func:`restitution_lambda`): the body leaves with
    exactly e at any approach speed, for any exponent n of K xⁿ. The reference law."""

    def damping(self, e):
        return restitution_lambda(e)


@dataclass(frozen=True)
class HuntCrossley(ImpactLaw):
    """λ = 3(1 − e)/2 (Hunt & Crossley 1975): the limit of the exact law as e → 1; too little damping
    below e ≈ 0.9 (set e = 0.5, the body leaves at 0.66)."""

    def damping(self, e):
        return 1.5 * (1.0 - np.asarray(e, float))


@dataclass(frozen=True)
class LankaraniNikravesh(ImpactLaw):
    """λ = 3(1 − e²)/4 (Lankarani & Nikravesh 1990): energy balance with the Hertz-contact work; set
    e = 0.5, the body leaves at 0.73."""

    def damping(self, e):
        e = np.asarray(e, float)
        return 0.75 * (1.0 - e * e)


@dataclass(frozen=True)
class Flores(ImpactLaw):
    """λ = 8(1 − e)/(5e) (Flores et al. 2011): meant for soft impacts (small e); set e = 0.5, the body
    leaves at 0.47."""

    def damping(self, e):
        e = np.asarray(e, float)
        return 1.6 * (1.0 - e) / e


# the impact damping laws by name (a parameter chooses one)
IMPACT_LAWS = MappingProxyType({"exact": ExactRestitution, "hunt_crossley": HuntCrossley,
                                "lankarani_nikravesh": LankaraniNikravesh, "flores": Flores})


class _Impact(Element):
    """Hunt–Crossley impact with the real approach speed (docs/model.md §8.4), shared by the pocket and
    guide-land contacts. Subclasses define ``_gap(q, v) -> (x, ẋ)`` (penetration and its rate).

    F = K x (1 + c ẋ) for x > 0, clipped at ≥ 0 (never pulling), else 0;  c = λ(e)/v₀ with λ(e) from
    the element's :class:`ImpactLaw` and v₀ the approach speed ẋ at this impact's onset (internal state).
    Internal state z, (n, 4): [v₀ (0 = not in contact), x, ẋ, valid] — x, ẋ at the last accepted state
    (valid = 1 once set). After each accepted step: open at the end → v₀ = 0; closed and v₀ was 0 (a new
    impact) → v₀ = ẋ at the sign change of x, linearly interpolated between the step's ends (the end rate
    if the step started in contact); closed and v₀ > 0 → kept; always v₀ = max(v₀, v_min). Within the
    Newton iterations of the step where contact begins (stored v₀ = 0) the iterate's max(ẋ, v_min) is
    used, so the kernel is stateless within a step and differentiable."""

    def _impact_params(self, restitution, v_min, law):
        if not isinstance(law, ImpactLaw):
            raise ModelError(f"{self.name}: parameter 'impact_law' must be an ImpactLaw (one of "
                             f"{sorted(IMPACT_LAWS)}), got {law!r}")
        self.impact_law = law
        e = self._per_instance("restitution", restitution)
        if np.any(e <= 0.0) or np.any(e > 1.0):
            raise ModelError(f"{self.name}: parameter 'restitution' must lie in (0, 1] (0, perfectly plastic, "
                             f"would need infinite damping), got {restitution!r}")
        self.restitution = e
        self.v_min = self._per_instance("v_min", v_min, positive=True)
        self.lam = np.asarray(law.damping(e), float)

    def init_internal(self):
        return np.zeros((self.n, 4))

    def update_internal(self, z, t0, t1, fs0, fs1, q0, v0, q1, v1):
        x1, xd1 = self._gap(q1, v1)
        x0, xd0 = z[:, 1], z[:, 2]
        valid = z[:, 3] > 0
        if not np.all(valid):                              # first step: the start state is not cached
            xs, xds = self._gap(q0, v0)
            x0, xd0 = np.where(valid, x0, xs), np.where(valid, xd0, xds)
        closed = x1 > 0.0
        opened = x0 <= 0.0                                 # start out of contact: interpolate the onset
        den = np.where(opened & closed, x0 - x1, -1.0)
        theta = x0 / den
        onset = np.where(opened, xd0 + theta * (xd1 - xd0), xd1)
        v_app = np.where(z[:, 0] > 0.0, z[:, 0], onset)
        v_app = np.where(closed, np.maximum(v_app, self.v_min), 0.0)
        return np.column_stack([v_app, x1, xd1, np.ones(self.n)])

    def _impact_force(self, K, x, xd, z):
        """(F, v₀ in use): F = K x (1 + λ ẋ/v₀) ≥ 0 for x > 0, else 0."""
        v_min = self.v_min
        v_app = ad.where(ad.value(xd) > v_min, xd, v_min)  # contact beginning in this step
        if z is not None:
            v_app = ad.where(z[..., 0] > 0.0, z[..., 0], v_app)   # [..., 0]: also for K states at once
        F = K * x * (1.0 + self.lam * xd / v_app)
        touch = ad.value(x) > 0.0
        active = touch & (ad.value(F) > 0.0)
        return ad.where(active, F, 0.0), np.where(touch, ad.value(v_app), 0.0)


# --------------------------------------------------------------------------------------------
class Traction:
    """Base of the roller–raceway traction laws μ: smooth, odd and bounded (docs/model.md §8.2). A law is a
    small frozen dataclass registered in :data:`TRACTION_LAWS` by name; its fields have no defaults
    (every value comes from the parameters)."""
    needs_rolling_speed = False
    needs_load = False          # True: coefficient(v_s, u_roll, load, radius) — the contact's load Q [N] and
                                # reduced radius [m] as well (laws of the lubricant film)

    def _check(self, positive=(), nonneg=()):
        name = type(self).__name__
        for f in dataclasses.fields(self):
            if not np.isfinite(getattr(self, f.name)):
                raise ModelError(f"{name}: {f.name} must be finite, got {getattr(self, f.name)!r}")
        for f in positive:
            if getattr(self, f) <= 0:
                raise ModelError(f"{name}: {f} must be > 0, got {getattr(self, f)!r}")
        for f in nonneg:
            if getattr(self, f) < 0:
                raise ModelError(f"{name}: {f} must be >= 0, got {getattr(self, f)!r}")

    def coefficient(self, v_s, u_roll=None):  # pragma: no cover - abstract
        raise TypeError(f"{type(self).__name__} must define coefficient(v_s, u_roll)")


@dataclass(frozen=True)
class TanhTraction(Traction):
    """μ = mu_max·tanh(v_s / v0) of the sliding velocity v_s [m/s]."""
    mu_max: float
    v0: float

    def __post_init__(self):
        self._check(positive=("v0",), nonneg=("mu_max",))

    def coefficient(self, v_s, u_roll=None):
        return self.mu_max * ad.tanh(v_s * (1.0 / self.v0))


@dataclass(frozen=True)
class SlideRollTraction(Traction):
    """An EHL-type traction curve μ(s) = (A + B·s)·e^(−C·s) + D of the slide-to-roll ratio s ≥ 0, extended
    as an odd function. The ratio is regularised so that it stays finite when the rolling speed vanishes:
        s = v_s / sqrt(u_r² + u_reg²),   u_r = mean rolling (entrainment) speed of the two surfaces
    relative to the moving contact point. The odd extension is sign(s)·μ(|s|) with |s| smoothed to
    a = sqrt(s² + s_eps²): μ = (s/a)·[(A + B a)e^(−C a) + D], which is C^∞ and, when A + D = 0 (zero
    traction at pure rolling), follows the curve to O(s_eps²) with slope ≈ B − A·C at s = 0."""
    A: float
    B: float
    C: float
    D: float
    u_reg: float
    s_eps: float
    needs_rolling_speed = True

    def __post_init__(self):
        self._check(positive=("u_reg", "s_eps"), nonneg=("C",))

    def coefficient(self, v_s, u_roll=None):
        s = v_s / ad.sqrt(u_roll * u_roll + self.u_reg ** 2)
        a = ad.sqrt(s * s + self.s_eps ** 2)
        return (s / a) * ((self.A + self.B * a) * ad.exp(a * (-self.C)) + self.D)


@dataclass(frozen=True)
class EHLTraction(Traction):
    """EHL traction of a lubricated line contact (docs/model.md §9.3). Over the Hertz strip (8 Gauss points),
    the oil film shears with the effective viscosity of a Maxwell fluid crossing the contact,
    1/η_eff = 1/η(p) + u/(G_e b) (Barus η = eta0·e^(alpha_p·p); G_e the film's elastic shear modulus,
    b the Hertz half-width, u the entraining speed: a film element is sheared only for the transit time
    b/u, Johnson & Tevaarwerk 1977), limited by the limiting shear stress τ_L = tau_L0 + gamma_L·p
    (Bair & Winer 1979): τ = τ_L·tanh(η_eff v_s /(h_c τ_L)), smooth and odd in v_s; μ = mean τ / mean p.
    h_c is Pan & Hamrock's central film times Murch & Wilson's thermal reduction φ_T(L), L = beta·eta0·u²/k_oil
    (:mod:`mbd.elements.ehl`; beta = −(1/η)dη/dT [1/K], k_oil the oil's thermal conductivity [W/(m·K)];
    beta = 0: isothermal), with the entraining speed regularised to √(u² + u_reg²); the load per unit length
    is Q/length, E_red the reduced modulus E'. Without the
    elastic limit (G_e → ∞) Barus makes the low-slip slope astronomically steep (η e^(α p) ~ 1e12 Pa·s
    at 1.5 GPa); with alpha_p = gamma_L = 0 and G_e → ∞ it is the tanh law with μ_max = tau_L0/p̄ and
    v0 = h_c·tau_L0/eta0 (p̄ the mean Hertz pressure)."""
    eta0: float
    alpha_p: float
    E_red: float
    length: float
    tau_L0: float
    gamma_L: float
    G_e: float
    u_reg: float
    beta: float
    k_oil: float
    needs_rolling_speed = True
    needs_load = True

    def __post_init__(self):
        self._check(positive=("eta0", "E_red", "length", "tau_L0", "G_e", "u_reg", "k_oil"),
                    nonneg=("alpha_p", "gamma_L", "beta"))

    def coefficient(self, v_s, u_roll=None, load=None, radius=None):
        w = load * (1.0 / self.length)
        u = ad.sqrt(u_roll * u_roll + self.u_reg ** 2)
        h_c = ehl.film_central(u, w, radius, self.eta0, self.alpha_p, self.E_red)
        if self.beta > 0.0:
            h_c = h_c * ehl.thermal_factor(ehl.thermal_loading(u, self.eta0, self.beta, self.k_oil))
        p_max = ehl.hertz_peak_pressure(w, radius, self.E_red)
        elastic = u / (self.G_e * ehl.hertz_half_width(w, radius, self.E_red))   # transit-time compliance
        shear_rate = v_s / h_c
        tau = 0.0
        for a, wq in zip(ehl.STRIP_NODES, ehl.STRIP_WEIGHTS):
            p = p_max * a
            tau_L = self.tau_L0 + self.gamma_L * p
            eta_eff = 1.0 / (ad.exp(-self.alpha_p * p) * (1.0 / self.eta0) + elastic)
            tau = tau + wq * tau_L * ad.tanh(eta_eff * shear_rate / tau_L)
        return tau / (p_max * (0.25 * np.pi))


# the traction laws by name (a parameter chooses one)
TRACTION_LAWS = MappingProxyType({"tanh": TanhTraction, "slide_roll": SlideRollTraction,
                                  "ehl": EHLTraction})


# --------------------------------------------------------------------------------------------
class RollingResistance:
    """Base of the hydrodynamic rolling-resistance laws of a lubricated roller–raceway contact (docs/model.md §9.5):
    ``force(Q, u, R)`` the Poiseuille rolling force F_R [N] (signed as the entraining speed u) of a contact carrying
    Q [N] with reduced radius R [m]. A small frozen dataclass registered in :data:`ROLLING_LAWS` by name."""

    def force(self, Q, u, R):  # pragma: no cover - abstract
        raise TypeError(f"{type(self).__name__} must define force(Q, u, R)")


@dataclass(frozen=True)
class HoupertRolling(RollingResistance):
    """Hydrodynamic (Poiseuille) rolling force of a fully flooded line contact in pure rolling, Houpert's correlation
    (Biboulet & Houpert 2010, "Hydrodynamic force and moment in pure rolling lubricated contacts. Part 1: line
    contacts", Proc. IMechE J 224: 765–775): with their groups (eq. 14) U = 2η₀ũ/(E'R) (ũ the mean surface speed),
    W = w'/(E'R), w' = Q/L, and Moes' M = W/√U, the fully flooded moment per unit length in Hertzian units is
    (eq. 42)
        T* = M^(−3/2) · 1.4√M / (1 + ((1.4/1.45)√M)^10)^(1/10),
    between the isoviscous-rigid asymptote T* = 1.4/M (eq. 40: T̃ = 1.42 (UW)^(1/2)) and the elastohydrodynamic one
    T* = 1.45 M^(−3/2) (eq. 41: T̃ = 1.47 U^(3/4), independent of load and of α_p). T̃ = t/(E'R²) = T* p_h b²/(E'R²)
    = T*·8W^(3/2)/(π√(2π)), and the force per unit length is T̃·E'R (eq. 31: the moment is the rolling force times R,
    the pressure adding none), so F_R = E'RL·1.4k√(UW)·(1 + (1.4/1.45)^10 M⁵)^(−1/10), k = 8/(π√(2π)).
    Range: their EHL solutions cover Moes L = 4–16, M = 0.2–200 (steel, G = 4520: U = 6.1e-13–1.6e-10,
    W = 1.6e-7–2.5e-3), the IVR asymptote below; fully flooded (their starvation factor, eq. 44, is not applied),
    isothermal, Newtonian. ũ = √(u² + u_reg²) regularises the entraining speed; the force carries the sign of u:
    F = F_R(ũ)·u/ũ (odd and smooth in u, zero at rest). Zero load: zero force (as √Q).
    eta0 [Pa·s], E_red E' [Pa], length L [m], u_reg [m/s]."""
    eta0: float
    E_red: float
    length: float
    u_reg: float

    # eq. 42's constants: the IVR coefficient 1.4, the EHL one 1.45, the blend's exponent 10; Hertz's units to
    # classical ones, T̃/(T* W^(3/2)) = 8/(π √(2π))
    IVR, EHL, BLEND = 1.4, 1.45, 10.0
    HERTZ = 8.0 / (np.pi * np.sqrt(2.0 * np.pi))

    def __post_init__(self):
        for k in ("eta0", "E_red", "length", "u_reg"):
            if not (np.isfinite(getattr(self, k)) and getattr(self, k) > 0):
                raise ModelError(f"HoupertRolling: {k} must be > 0, got {getattr(self, k)!r}")

    def moment(self, U, W):
        """T̃ = t/(E'R²), the fully flooded moment per unit length (eq. 42 in the classical units), of arrays U, W."""
        M = W / ad.sqrt(U)
        s = (self.IVR / self.EHL) ** self.BLEND * ad.power(M, 0.5 * self.BLEND)
        return (self.IVR * self.HERTZ) * ad.sqrt(U * W) * ad.power(1.0 + s, -1.0 / self.BLEND)

    def force(self, Q, u, R):
        ut = ad.sqrt(u * u + self.u_reg ** 2)
        ER = self.E_red * R
        U, W = (2.0 * self.eta0) * ut / ER, Q * (1.0 / (ER * self.length))
        return (ER * self.length) * self.moment(U, W) * u / ut


# the rolling-resistance laws by name (a parameter chooses one; None: no rolling resistance)
ROLLING_LAWS = MappingProxyType({"houpert": HoupertRolling})


# --------------------------------------------------------------------------------------------
def spall_profile(s, hi, edge):
    """(B(s), B'(s)) of a raceway defect: 1 for |s| ≤ hi − edge, 0 for |s| ≥ hi, and the C² quintic
    smoothstep B = x³(10 − 15x + 6x²), x = (hi − |s|)/edge, in between; B' = −sign(s)·30x²(1 − x)²/edge.
    Works on dual numbers (B' then carries B'' for the Jacobian of the rate term)."""
    x_raw = (hi - ad.abs_(s)) / edge
    xv = ad.value(x_raw)
    x = ad.where(xv >= 1.0, 1.0, ad.where(xv > 0.0, x_raw, 0.0))
    B = x * x * x * (10.0 + x * (6.0 * x - 15.0))
    u = 1.0 - x
    B_s = (-30.0 * ad.sign(s) / edge) * (x * x * u * u)
    return B, B_s


def race_surfaces(vr, vb, Vc, rc, ex, ey, tx, ty, rho, R, wx, wy):
    """The raceway contact's kinematics (:class:`RaceContact`): the contact point P = c + R e seen from the roller's
    centre (r_roll) and from the race body's centre (r_race), the slip v_s = (roller surface − raceway surface
    velocity at P)·t and the entraining speed u_e, the surfaces' mean speed along t relative to the geometric contact
    point P, whose velocity along t is ċ·t + R (ṗ − ċ)·t / ρ. vr, vb the bodies' velocities, Vc the raceway centre's,
    w = ṗ − ċ."""
    r_roll = ((R - rho) * ex, (R - rho) * ey)
    r_race = (rc[0] + R * ex, rc[1] + R * ey)
    Vr = marker_velocity(vr, r_roll)
    Vb = marker_velocity(vb, r_race)
    ur = Vr[0] * tx + Vr[1] * ty
    ub = Vb[0] * tx + Vb[1] * ty
    v_s = ur - ub
    vP = Vc[0] * tx + Vc[1] * ty + R * (wx * tx + wy * ty) / rho
    u_e = 0.5 * (ur + ub) - vP
    return r_roll, r_race, v_s, u_e


def poiseuille_forces(F, rho, tx, ty, rc, R):
    """Generalized forces (roller, race body) of a film's Poiseuille shear F at the raceway contact point P along −t
    on both surfaces (against the entraining direction) with the pressure's tangential resultant 2F along +t shared
    through the centres of curvature, a_roller = 2R/ρ, a_race = 2(ρ − R)/ρ (:class:`RaceContact`, docs/model.md
    §9.5): on the roller F(2R/ρ − 1) along t and the moment (ρ − R)F; on the race body the opposite force and the
    moment −rc × f − R F."""
    g = F * (2.0 * R / rho - 1.0)
    fx, fy = g * tx, g * ty
    Mb = -1.0 * (rc[0] * fy - rc[1] * fx) - R * F
    return [fx, fy, (rho - R) * F, -1.0 * fx, -1.0 * fy, Mb]


class RaceContact(Element):
    """Roller–raceway Hertz line contact (Palmgren) with damping and traction.

    Instances couple a roller (first 3 coordinates) with the body carrying the raceway (last 3): the
    carrier for an inner raceway (``race_marker`` = pin centre in carrier axes), the planet for an outer
    one (``race_marker`` = (0, 0), the bore centre). With c the raceway centre, ρ = |p − c|, e = (p − c)/ρ:
        inner: δ = R + D/2 − ρ (roller pushed along +e),  outer: δ = ρ + D/2 − R (pushed along −e).
    Normal load Q = K δ^p + S(δ/δ_c) c(δ) δ̇ for δ > 0, clipped at ≥ 0, with c(δ) = 2ζ sqrt(m_roller · dQ/dδ)
    and dQ/dδ = p K δ^(p−1): a damping ratio ζ of the local contact oscillator. c(δ) ∝ δ^((p−1)/2) = δ^0.056 for
    p = 10/9 is all but a jump at first touch (Kelvin–Voigt's discontinuity at impact: Machado et al. 2012, Mech.
    Mach. Theory 53, 99–121); the damping share S (:func:`mbd.elements.tooth_pairs.damping_share`, the quintic
    smoothstep over the first ``damping_ramp`` δ_c of compression, the mesh's law) lets the dissipation grow with the
    compressed zone from zero, as Hunt & Crossley's (1975, J. Appl. Mech. 42, 440–445) does, and leaves the law
    unchanged from δ ≥ δ_c on (δ_c = 0, the default: S = 1, the damping whole at first touch).
    Traction: v_s = (roller surface point − raceway surface point velocity)·t, t = k × e, at the contact
    point P = c + R e (line of centres, raceway surface); force −μ·Q along t on the roller. The normal
    and traction forces act at P on both bodies, equal and opposite.

    ``multiplicity`` (default 1, a positive integer): the instance stands for that many identical parallel
    contacts (a double-row bearing modelled as one row): the law above is one physical contact's (K, and
    m_roller the mass of one physical roller), and the generalized forces are multiplied by it.

    Local raceway defect (spall, docs/model.md §8.3; all four per instance, or all None = no spall, the default):
    ``spall_angle`` [rad] the defect's centre, an angle about the raceway centre in the race body's axes (as
    the output "angle": the defect is fixed on the race body); ``spall_width`` w > 0 [m] its arc length along
    the raceway; ``spall_depth`` h ≥ 0 [m]; ``spall_edge`` e in (0, w] [m] the length over which the depth
    ramps in, and w + e < 2πR. With s = R·wrap(angle − spall_angle) the roller's arc position from the
    defect centre, the deflection loses d(s) = h·B(s): B = 1 for |s| ≤ (w − e)/2, 0 for |s| ≥ (w + e)/2 and
    the C² quintic smoothstep x³(10 − 15x + 6x²), x = ((w + e)/2 − |s|)/e, in between. δ_eff = δ − d(s)
    (= δ without a spall) replaces δ everywhere (contact gate, stiffness and damping terms), and its rate
    is the exact time derivative δ̇_eff = δ̇ − h·B'(s)·ṡ, ṡ = R·(angle rate): the surface dropping away
    under a rolling roller is an opening of the contact like any other, and a damping term without it
    would see a rate that is not the rate of the deflection it damps (dissipation at a constant δ_eff).
    The contact point and the traction geometry are unchanged. A family without a spall evaluates
    exactly as before (no extra work).

    Hydrodynamic rolling resistance (docs/model.md §9.5; ``rolling`` a :class:`RollingResistance`, or None = none,
    the default, evaluated exactly as without it): where the contact carries Q > 0, the film's Poiseuille shear
    F = rolling.force(Q, u_e, R_red) acts at P along −t on *both* surfaces (against the entraining direction), and
    the pressure's tangential resultant, equal to the two shears together (the film's force balance), acts along
    +t through each body's centre of curvature, shared as a_roller = 2R/ρ, a_race = 2(ρ − R)/ρ (the curvatures'
    shares of 1/R_red for the parabolic gap; a pressure normal to a circular surface has no moment about its
    centre). Forces and moments balance exactly; the roller keeps the moment (ρ − R)F against its rolling, and the
    power is −2F·u_e ≤ 0 (u_e relative to the moving contact point).

    Outputs, all per physical contact: "load" Q ≥ 0 [N]; "deflection" δ_eff [m] (negative: a gap); "traction"
    tangential force on the roller along t [N] (opposes v_s); "slip_velocity" v_s [m/s]; "rolling_speed"
    the entraining speed u_e = (u_roller + u_race)/2 relative to the contact point [m/s] (what builds an
    EHL film); "angle" the roller centre's angle about the raceway centre measured in the race body's
    axes [rad] (wrapped to (−π, π]);
    "fx", "fy" the contact force on one physical roller, in R [N].
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.race"

    def __init__(self, name, roller, race_body, *, kind, race_marker, R_race, D, K, exponent, zeta, m_roller,
                 traction: Traction, multiplicity=1, spall_angle=None, spall_width=None, spall_depth=None,
                 spall_edge=None, rolling: "RollingResistance | None" = None, damping_ramp=0.0):
        self.name = name
        self.dofs = body_dofs(roller, race_body)
        if kind not in ("inner", "outer"):
            raise ModelError(f"{name}: kind must be 'inner' or 'outer', got {kind!r}")
        if not isinstance(traction, Traction):
            raise ModelError(f"{name}: traction must be a Traction, got {type(traction).__name__}")
        self.kind = kind
        self.kappa = 1.0 if kind == "inner" else -1.0  # δ = D/2 − κ(ρ − R), normal on roller κ·e
        self.race_marker = self._per_instance_xy("race_marker", race_marker)
        self.R_race = self._per_instance("R_race", R_race, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.K = self._per_instance("K", K, positive=True)
        self.exponent = float(exponent)
        if not (np.isfinite(self.exponent) and self.exponent >= 1.0):
            # p < 1 would make dQ/dδ infinite at first touch
            raise ModelError(f"{name}: parameter 'exponent' must be >= 1, got {exponent!r}")
        self.zeta = self._per_instance("zeta", zeta, nonneg=True)
        self.m_roller = self._per_instance("m_roller", m_roller, positive=True)
        self.damping_ramp = self._per_instance("damping_ramp", damping_ramp, nonneg=True)
        self.traction = traction
        if rolling is not None and not isinstance(rolling, RollingResistance):
            raise ModelError(f"{name}: parameter 'rolling' must be a RollingResistance (one of "
                             f"{sorted(ROLLING_LAWS)}) or None, got {rolling!r}")
        self.rolling = rolling
        self._c0 = 2.0 * self.zeta * np.sqrt(self.m_roller * self.exponent * self.K)
        self.kappa = np.full(self.n, self.kappa)   # per instance: inner and outer families can be fused
        self.R_red = 1.0 / (2.0 / self.D + self.kappa / self.R_race)   # reduced radius: convex inner, concave outer
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))
        self._ramped = bool(np.any(self.damping_ramp > 0.0))
        self._spall_params(spall_angle, spall_width, spall_depth, spall_edge)

    _SPALL = ("spall_angle", "spall_width", "spall_depth", "spall_edge")
    _FUSED = ("dofs", "race_marker", "R_race", "D", "K", "zeta", "m_roller", "_c0", "kappa", "R_red", "multiplicity",
              "damping_ramp")

    def _spall_params(self, angle, width, depth, edge):
        """The defect's per-instance arrays (``has_spall`` False: none given); ``_spall_hi`` = (w + e)/2."""
        given = dict(zip(self._SPALL, (angle, width, depth, edge)))
        missing = [k for k, val in given.items() if val is None]
        self.has_spall = not missing
        if missing and len(missing) < 4:
            raise ModelError(f"{self.name}: a spall needs all of {', '.join(self._SPALL)}; "
                             f"missing {', '.join(missing)}")
        if missing:
            return
        self.spall_angle = self._per_instance("spall_angle", angle)
        self.spall_width = self._per_instance("spall_width", width, positive=True)
        self.spall_depth = self._per_instance("spall_depth", depth, nonneg=True)
        self.spall_edge = self._per_instance("spall_edge", edge, positive=True)
        if np.any(self.spall_edge > self.spall_width):
            raise ModelError(f"{self.name}: parameter 'spall_edge' must lie in (0, spall_width] [m], got {edge!r} "
                             f"with spall_width {width!r}")
        if np.any(self.spall_width + self.spall_edge >= 2.0 * np.pi * self.R_race):
            raise ModelError(f"{self.name}: parameter 'spall_width' plus spall_edge must be < 2π·R_race (the "
                             f"raceway's circumference) [m], got {width!r} + {edge!r}")
        self._spall_hi = 0.5 * self.spall_width + 0.5 * self.spall_edge

    def fuse_key(self):
        return ("RaceContact", self.exponent, self.traction, self.has_spall, self.rolling)

    @classmethod
    def fuse(cls, parts):
        """One family holding the instances of several (inner and outer raceways alike; with a spall or
        without, as the fuse key keeps them apart)."""
        f = super().fuse(parts)
        f.kind, f.exponent, f.traction, f.rolling = None, parts[0].exponent, parts[0].traction, parts[0].rolling
        f._multi = bool(np.any(f.multiplicity != 1.0))
        f._ramped = bool(np.any(f.damping_ramp > 0.0))
        f.has_spall = parts[0].has_spall
        for a in cls._SPALL + ("_spall_hi",) if f.has_spall else ():
            setattr(f, a, np.concatenate([getattr(p, a) for p in parts]))
        return f

    def _spalled(self, delta, delta_dot, angle, dx, dy, wx, wy, w_race):
        """(δ − d(s), its exact rate δ̇ − h·B'(s)·ṡ) over the defect (law in the class docstring)."""
        R, h = self.R_race, self.spall_depth
        s = R * ad.wrap_angle(angle - self.spall_angle)
        s_dot = R * ((dx * wy - dy * wx) / (dx * dx + dy * dy + _ETA2) - w_race)
        B, B_s = spall_profile(s, self._spall_hi, self.spall_edge)
        return delta - h * B, delta_dot - h * B_s * s_dot

    def _rolling_forces(self, Q, u_e, rho, tx, ty, rc, R):
        """Generalized forces of the rolling resistance (class docstring)."""
        loaded = ad.value(Q) > 0.0
        F = ad.where(loaded, self.rolling.force(ad.where(loaded, Q, 1.0), u_e, self.R_red), 0.0)
        return poiseuille_forces(F, rho, tx, ty, rc, R)

    def kernel(self, t, fs, q, v, z):
        qr, qb, vr, vb = q[:3], q[3:], v[:3], v[3:]
        R, kap, p = self.R_race, self.kappa, self.exponent
        (cx, cy), rc = marker(qb, self.race_marker)
        dx, dy = qr[0] - cx, qr[1] - cy
        rho = _norm(dx, dy)
        ex, ey = dx / rho, dy / rho
        tx, ty = -1.0 * ey, ex
        delta = 0.5 * self.D - kap * (rho - R)
        Vc = marker_velocity(vb, rc)
        wx, wy = vr[0] - Vc[0], vr[1] - Vc[1]            # roller centre relative to raceway centre
        delta_dot = -kap * (ex * wx + ey * wy)
        angle = ad.wrap_angle(ad.arctan2(dy, dx) - qb[2])
        if self.has_spall:
            delta, delta_dot = self._spalled(delta, delta_dot, angle, dx, dy, wx, wy, vb[2])
        # normal load; powers are taken of a safe positive δ and selected afterwards (no 0^negative)
        touch = ad.value(delta) > 0.0
        ds = ad.where(touch, delta, 1.0)
        c = self._c0 * ad.power(ds, 0.5 * (p - 1.0))
        if self._ramped:                # S(δ/δ_c) (class docstring); without a ramp the law as written, to the bit
            c = c * damping_share(ds, self.damping_ramp)
        Q_raw = self.K * ad.power(ds, p) + c * delta_dot
        Q = ad.where(touch & (ad.value(Q_raw) > 0.0), Q_raw, 0.0)
        r_roll, r_race, v_s, u_e = race_surfaces(vr, vb, Vc, rc, ex, ey, tx, ty, rho, R, wx, wy)
        tr = self.traction
        if tr.needs_load:           # a law of the film: the load per contact (1 N where none: F_t = −μQ = 0)
            mu = tr.coefficient(v_s, u_e, ad.where(ad.value(Q) > 0.0, Q, 1.0), self.R_red)
        else:
            mu = tr.coefficient(v_s, u_e) if tr.needs_rolling_speed else tr.coefficient(v_s)
        Ft = -1.0 * mu * Q
        Fx = kap * Q * ex + Ft * tx
        Fy = kap * Q * ey + Ft * ty
        forces = point_force(r_roll, (Fx, Fy)) + point_force(r_race, (-1.0 * Fx, -1.0 * Fy))
        if self.rolling is not None:
            forces = [a + b for a, b in zip(forces, self._rolling_forces(Q, u_e, rho, tx, ty, rc, R))]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"load": Q, "deflection": delta, "traction": Ft, "slip_velocity": v_s, "angle": angle,
                        "rolling_speed": u_e, "fx": Fx, "fy": Fy}   # fx, fy: force on one physical roller, in R


# --------------------------------------------------------------------------------------------
class PocketContact(_Impact):
    """Roller–cage pocket impact with wall friction (docs/model.md §8.5).

    Instances couple a roller (first 3 coordinates) with its cage (last 3). Circumferential offset of
    the roller in pocket j: s = (d_m/2)·wrap(β − θ_g − ψ_j), β the angle of (p − c_g) in R. Penetration
    d = |s| − C_p, rate ḋ = sign(s)·ṡ; for d > 0 the contact force is Hunt–Crossley with the real approach
    speed (see :class:`_Impact`): F = K_p d (1 + λ(e) ḋ/v₀) ≥ 0, v₀ = ḋ at this impact's onset. It is
    applied in potential form, generalized force −F·∂d/∂q, which balances forces and moments exactly: the
    roller is pushed back along the pitch circle towards the pocket centre, the cage gets the opposite
    force and the moment F·sign(s)·d_m/2.
    Wall friction: the roller touches the wall at P_w = p + sign(s)·(D/2)·t (t = k × e_r, e_r radial
    from the cage centre); μ·tanh(v/v_mu)·F along ∓e_r opposes the radial sliding v of the roller surface
    on the wall (the wall taken along the roller's radial line), applied at P_w on both bodies.
    ``multiplicity`` (default 1): identical parallel pockets per instance; the law is one physical contact's,
    the generalized forces are multiplied by it.

    Internal state ``z`` (n, 4): column 0 is v₀ [m/s], the approach speed of the current impact (0 = not
    in contact; it becomes > 0 in the first accepted step that ends in contact, so an onset is a 0 → > 0
    change of column 0); columns 1, 2, 3 are d [m], ḋ [m/s] at the last accepted state and a valid flag.

    Outputs, per physical contact: "force" signed tangential force F·sign(s) [N] (+ when the roller pushes
    the cage forward); "offset" s [m]; "penetration" max(d, 0) [m]; "penetration_rate" ḋ [m/s] (+ when
    closing); "approach_speed" v₀ in use [m/s] (0 out of contact).
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.pocket"

    def __init__(self, name, roller, cage, *, pocket_angle, pitch_radius, clearance, K_p, restitution,
                 impact_law, v_min, mu, v_mu, D, multiplicity=1):
        self.name = name
        self.dofs = body_dofs(roller, cage)
        self.pocket_angle = self._per_instance("pocket_angle", pocket_angle)
        self.pitch_radius = self._per_instance("pitch_radius", pitch_radius, positive=True)
        self.clearance = self._per_instance("clearance", clearance, nonneg=True)
        self.K_p = self._per_instance("K_p", K_p, positive=True)
        self._impact_params(restitution, v_min, impact_law)
        self.mu = self._per_instance("mu", mu, nonneg=True)
        self.v_mu = self._per_instance("v_mu", v_mu, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))

    def _geometry(self, q, v):
        qr, qg, vr, vg = q[:3], q[3:], v[:3], v[3:]
        rm = self.pitch_radius
        dx, dy = qr[0] - qg[0], qr[1] - qg[1]
        rho2 = dx * dx + dy * dy + _ETA2
        s = rm * ad.wrap_angle(ad.arctan2(dy, dx) - qg[2] - self.pocket_angle)
        sg = ad.sign(s)
        wx, wy = vr[0] - vg[0], vr[1] - vg[1]
        s_dot = rm * ((dx * wy - dy * wx) / rho2 - vg[2])
        return dx, dy, rho2, s, sg, ad.abs_(s) - self.clearance, sg * s_dot

    def _gap(self, q, v):
        g = self._geometry(q, v)
        return g[5], g[6]

    def kernel(self, t, fs, q, v, z):
        vr, vg = v[:3], v[3:]
        rm = self.pitch_radius
        dx, dy, rho2, s, sg, pen, pen_dot = self._geometry(q, v)
        F, v_app = self._impact_force(self.K_p, pen, pen_dot, z)
        Fs = F * sg
        # −Fs ∂s/∂q: ∂s/∂p = rm (−dy, dx)/ρ², ∂s/∂c_g = −∂s/∂p, ∂s/∂θ_g = −rm
        gx, gy = rm * (-1.0 * dy) / rho2, rm * dx / rho2
        fnx, fny = -1.0 * Fs * gx, -1.0 * Fs * gy
        # wall friction at the roller's contact point with the wall
        rho = ad.sqrt(rho2)
        ex, ey = dx / rho, dy / rho
        half = 0.5 * self.D * sg
        r_w = (-1.0 * half * ey, half * ex)                 # sign(s)·(D/2)·t from the roller centre
        r_wg = (dx + r_w[0], dy + r_w[1])                   # the same point from the cage centre
        Vr = marker_velocity(vr, r_w)
        Vg = marker_velocity(vg, r_wg)
        v_rad = (Vr[0] - Vg[0]) * ex + (Vr[1] - Vg[1]) * ey
        f = -1.0 * self.mu * ad.tanh(v_rad / self.v_mu) * F
        fr = point_force(r_w, (f * ex, f * ey))
        fg = point_force(r_wg, (-1.0 * f * ex, -1.0 * f * ey))
        forces = [fnx + fr[0], fny + fr[1], fr[2],
                  -1.0 * fnx + fg[0], -1.0 * fny + fg[1], Fs * rm + fg[2]]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"force": Fs, "offset": s, "penetration": ad.pos(pen), "penetration_rate": pen_dot,
                        "approach_speed": v_app}


# --------------------------------------------------------------------------------------------
class PocketRetention(_Impact):
    """Radial retention of a roller in its pocket, for a roller-centred cage (docs/model.md §8.5).

    Instances couple a roller (first 3 coordinates) with its cage (last 3). The roller's radial offset from the
    cage's pitch circle u = ρ − d_m/2, ρ = |p − c_g| (safe norm), and the penetration beyond the radial pocket
    play C_r, x = |u| − C_r, ẋ = sign(u)·ρ̇: the pocket's bars converge below and above the pitch circle, so a
    roller displaced radially in its pocket by more than C_r meets them (a roller-centred cage rides on its
    rollers). For x > 0 the force is the impact law of :class:`_Impact` (K_r, restitution, approach speed),
    F = K_r x (1 + λ(e) ẋ/v₀) ≥ 0, applied in potential form −F ∂x/∂q: the roller is pushed back towards the
    pitch circle along e_r = (p − c_g)/ρ, the cage the opposite, both at the roller centre (the converging
    faces' normal forces meet there: no moment on the cage). Friction of the faces on the turning roller,
    −μ tanh(v_t/v_mu)·F along t = k × e_r, at the roller's surface point P = p + sign(u)(D/2) e_r on both
    bodies (v_t the sliding speed of roller on cage there; the two faces' friction lumped at one point).
    ``multiplicity`` as :class:`PocketContact`'s.

    Internal state ``z`` (n, 4): as :class:`PocketContact`'s, with x the radial penetration.

    Outputs, per physical contact: "force" F·sign(u) [N] (+ when the roller presses the cage outwards);
    "offset" u [m]; "penetration" max(x, 0) [m]; "penetration_rate" ẋ [m/s]; "approach_speed" v₀ in use [m/s];
    "friction" the friction force on the roller along t [N].
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.retention"

    def __init__(self, name, roller, cage, *, pitch_radius, clearance, K_r, restitution, impact_law, v_min, mu,
                 v_mu, D, multiplicity=1):
        self.name = name
        self.dofs = body_dofs(roller, cage)
        self.pitch_radius = self._per_instance("pitch_radius", pitch_radius, positive=True)
        self.clearance = self._per_instance("clearance", clearance, nonneg=True)
        self.K_r = self._per_instance("K_r", K_r, positive=True)
        self._impact_params(restitution, v_min, impact_law)
        self.mu = self._per_instance("mu", mu, nonneg=True)
        self.v_mu = self._per_instance("v_mu", v_mu, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))

    def _geometry(self, q, v):
        qr, qg, vr, vg = q[:3], q[3:], v[:3], v[3:]
        dx, dy = qr[0] - qg[0], qr[1] - qg[1]
        rho = _norm(dx, dy)
        u = rho - self.pitch_radius
        sg = ad.sign(u)
        wx, wy = vr[0] - vg[0], vr[1] - vg[1]
        rho_dot = (dx * wx + dy * wy) / rho
        return dx, dy, rho, u, sg, ad.abs_(u) - self.clearance, sg * rho_dot

    def _gap(self, q, v):
        g = self._geometry(q, v)
        return g[5], g[6]

    def kernel(self, t, fs, q, v, z):
        vr, vg = v[:3], v[3:]
        dx, dy, rho, u, sg, pen, pen_dot = self._geometry(q, v)
        F, v_app = self._impact_force(self.K_r, pen, pen_dot, z)
        Fu = F * sg
        ex, ey = dx / rho, dy / rho
        fnx, fny = -1.0 * Fu * ex, -1.0 * Fu * ey            # −F ∂x/∂p on the roller (the cage: the opposite)
        half = 0.5 * self.D * sg
        r_w = (half * ex, half * ey)                          # the roller's surface point on the faces it presses
        r_wg = (dx + r_w[0], dy + r_w[1])                     # the same point from the cage centre
        tx, ty = -1.0 * ey, ex
        Vr = marker_velocity(vr, r_w)
        Vg = marker_velocity(vg, r_wg)
        v_t = (Vr[0] - Vg[0]) * tx + (Vr[1] - Vg[1]) * ty
        f = -1.0 * self.mu * ad.tanh(v_t / self.v_mu) * F
        fr = point_force(r_w, (f * tx, f * ty))
        fg = point_force(r_wg, (-1.0 * f * tx, -1.0 * f * ty))
        forces = [fnx + fr[0], fny + fr[1], fr[2], -1.0 * fnx + fg[0], -1.0 * fny + fg[1], fg[2]]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"force": Fu, "offset": u, "penetration": ad.pos(pen), "penetration_rate": pen_dot,
                        "approach_speed": v_app, "friction": f}


# --------------------------------------------------------------------------------------------
class LandLaw:
    """Base of the cage guide-land laws (docs/model.md §8.6, §9.4), registered in :data:`LAND_LAWS` by name."""


@dataclass(frozen=True)
class DryLand(LandLaw):
    """The land runs dry: only the solid contact beyond the clearance, with Coulomb friction μ_g·F_n."""


@dataclass(frozen=True)
class HydrodynamicLand(LandLaw):
    """The land as a short journal bearing (Ocvirk; π-film: the film carries load over the half where it
    converges, the other half cavitates) of width ``width`` [m] in oil of viscosity ``eta`` [Pa·s]. With C the
    radial clearance, R the land radius, ε = |e|/C (capped at 1 − min_film/C: the solid contact of
    §3.5 takes over beyond the clearance), ε̇ its rate, φ̇ the whirl of e, ω̄ = ω_cage + ω_planet − 2φ̇ and
    σ the sign of ω_cage + ω_planet (the side of the converging film), K₀ = η R L³ / (2C²), the film force on
    the cage along n = e/|e| and t = k × n is
        F_n = −K₀ [2σε²ω̄/(1−ε²)² + π(1+2ε²) ε̇/(1−ε²)^(5/2)],
        F_t = σ K₀ [πσεω̄/(2(1−ε²)^(3/2)) + 4εε̇/(1−ε²)²],
    and the film's shear on the land, −η v_t 2πRL / (C √(1−ε²)), replaces the dry friction (Petroff with
    eccentricity; v_t the land's sliding speed)."""
    eta: float
    width: float
    min_film: float

    def __post_init__(self):
        for k in ("eta", "width", "min_film"):
            if not (np.isfinite(getattr(self, k)) and getattr(self, k) > 0):
                raise ModelError(f"HydrodynamicLand: {k} must be > 0, got {getattr(self, k)!r}")

    def film(self, ex, ey, vg, vo, R, C):
        """(F_n, F_t, shear friction along t) of the film, from e = c_cage − c_bore and both velocities.
        Written with ε·φ̇ and ε²·φ̇ (bounded and smooth as e → 0) rather than the whirl φ̇ itself, which a
        nearly centred cage makes singular; the film side follows the sign of the surfaces' spin sum."""
        e2 = ex * ex + ey * ey + _ETA2
        e_abs = ad.sqrt(e2)
        dex, dey = vg[0] - vo[0], vg[1] - vo[1]
        eps_cap = 1.0 - self.min_film / C
        eps_raw = e_abs / C
        act = ad.value(eps_raw) < eps_cap
        eps = ad.where(act, eps_raw, eps_cap)
        eps_dot = ad.where(act, (ex * dex + ey * dey) / (e_abs * C), 0.0)
        cross = ex * dey - ey * dex                          # |e|² φ̇
        spin = vg[2] + vo[2]
        sgn = np.where(ad.value(spin) >= 0.0, 1.0, -1.0)
        # ε ω̄ and ε² ω̄ with ω̄ = spin − 2φ̇, on the side of the spin (ε taken at its cap beyond it)
        scale = ad.where(act, 1.0, eps_cap / eps_raw)        # ε / ε_raw
        e_w = sgn * (eps * spin - 2.0 * scale * cross / (e_abs * C))
        e2_w = sgn * (eps * eps * spin - 2.0 * scale * scale * cross / (C * C))
        K0 = self.eta * R * self.width ** 3 / (2.0 * C * C)
        s = 1.0 - eps * eps
        Fn = -1.0 * K0 * (2.0 * e2_w / (s * s) + np.pi * (1.0 + 2.0 * eps * eps) * eps_dot / (s * s * ad.sqrt(s)))
        Ft = sgn * K0 * (np.pi * e_w / (2.0 * s * ad.sqrt(s)) + 4.0 * eps * eps_dot / (s * s))
        nx, ny = ex / e_abs, ey / e_abs
        tx, ty = -1.0 * ny, nx
        Vg, Vo = marker_velocity(vg, (R * nx, R * ny)), marker_velocity(vo, (ex + R * nx, ey + R * ny))
        v_t = (Vg[0] - Vo[0]) * tx + (Vg[1] - Vo[1]) * ty
        shear = -1.0 * self.eta * v_t * (2.0 * np.pi * R * self.width) / (C * ad.sqrt(s))
        return Fn, Ft, shear


# the guide-land laws by name (a parameter chooses one)
LAND_LAWS = MappingProxyType({"dry": DryLand, "hydrodynamic": HydrodynamicLand})


class GuideContact(_Impact):
    """Cage–guide-land impact for an outer-raceway-guided cage (docs/model.md §8.6).

    Instances couple a cage (first 3 coordinates) with its planet (last 3; the planet's centre is the
    bore centre). e = c_g − c_o, ε = |e|, n = e/ε, penetration x = ε − C_g, rate ẋ = ε̇. For x > 0 the
    normal force is Hunt–Crossley with the real approach speed (see :class:`_Impact`):
    F_n = K_g x (1 + λ(e_r) ε̇/v₀) ≥ 0, v₀ = ε̇ at this impact's onset; it pushes the cage along −n (back to
    the bore centre) and the planet along +n. Both act at the land contact point P = c_g + land_radius·n.
    Land friction μ·tanh(v_t/v_mu)·F_n opposes the relative surface speed v_t = (V_cage(P) − V_planet(P))·t,
    t = k × n. The centred cage (ε = 0) is regular: the safe norm keeps n finite and the forces are zero.

    Internal state ``z`` (n, 4): column 0 is v₀ [m/s], the approach speed of the current impact (0 = not
    in contact; an onset is a 0 → > 0 change of column 0 after an accepted step); columns 1, 2, 3 are x [m],
    ẋ [m/s] at the last accepted state and a valid flag.

    Outputs: "force" F_n ≥ 0 [N]; "eccentricity" ε [m]; "friction" tangential force on the cage along t [N];
    "sliding_speed" v_t of the cage land on the bore [m/s];
    "fx", "fy" force on the cage, in R [N]; "penetration_rate" ε̇ [m/s]; "approach_speed" v₀ in use [m/s]
    (0 out of contact).
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.guide"

    def __init__(self, name, cage, planet, *, clearance, K_g, restitution, impact_law, v_min, mu, v_mu,
                 land_radius, land: "LandLaw"):
        self.name = name
        self.dofs = body_dofs(cage, planet)
        self.clearance = self._per_instance("clearance", clearance, nonneg=True)
        self.K_g = self._per_instance("K_g", K_g, positive=True)
        self._impact_params(restitution, v_min, impact_law)
        self.mu = self._per_instance("mu", mu, nonneg=True)
        self.v_mu = self._per_instance("v_mu", v_mu, positive=True)
        self.land_radius = self._per_instance("land_radius", land_radius, positive=True)
        if not isinstance(land, LandLaw):
            raise ModelError(f"{name}: parameter 'land' must be a LandLaw (one of {sorted(LAND_LAWS)}), got {land!r}")
        if isinstance(land, HydrodynamicLand) and np.any(self.clearance <= land.min_film):
            raise ModelError(f"{name}: the hydrodynamic land needs a clearance above its min_film "
                             f"{land.min_film!r} m, got {clearance!r}")
        self.land = land

    def _geometry(self, q, v):
        qg, qo, vg, vo = q[:3], q[3:], v[:3], v[3:]
        ex, ey = qg[0] - qo[0], qg[1] - qo[1]
        eps = _norm(ex, ey)
        nx, ny = ex / eps, ey / eps
        eps_dot = nx * (vg[0] - vo[0]) + ny * (vg[1] - vo[1])
        return ex, ey, nx, ny, eps - self.clearance, eps_dot

    def _gap(self, q, v):
        g = self._geometry(q, v)
        return g[4], g[5]

    def kernel(self, t, fs, q, v, z):
        vg, vo = v[:3], v[3:]
        ex, ey, nx, ny, pen, eps_dot = self._geometry(q, v)
        tx, ty = -1.0 * ny, nx
        F, v_app = self._impact_force(self.K_g, pen, eps_dot, z)
        rL = self.land_radius
        r_g = (rL * nx, rL * ny)
        r_o = (ex + r_g[0], ey + r_g[1])
        Vg = marker_velocity(vg, r_g)
        Vo = marker_velocity(vo, r_o)
        v_t = (Vg[0] - Vo[0]) * tx + (Vg[1] - Vo[1]) * ty
        fr = -1.0 * self.mu * ad.tanh(v_t / self.v_mu) * F
        if isinstance(self.land, HydrodynamicLand):       # the oil film carries the cage; its shear is the friction
            Fn_film, Ft_film, fr_film = self.land.film(ex, ey, vg, vo, rL, self.clearance)
            fr = fr + fr_film
        else:
            Fn_film = Ft_film = 0.0
        Fx = -1.0 * F * nx + fr * tx + Fn_film * nx + Ft_film * tx
        Fy = -1.0 * F * ny + fr * ty + Fn_film * ny + Ft_film * ty
        forces = point_force(r_g, (Fx, Fy)) + point_force(r_o, (-1.0 * Fx, -1.0 * Fy))
        ecc = np.hypot(ad.value(ex), ad.value(ey))  # the plain norm for the record
        return forces, {"force": F, "eccentricity": ecc, "friction": fr, "fx": Fx, "fy": Fy,  # fx, fy on the cage, in R
                        "sliding_speed": v_t, "penetration_rate": eps_dot, "approach_speed": v_app}


# --------------------------------------------------------------------------------------------
class LubricantDrag(Element):
    """Lubricant (oil–air mixture) drag on the rollers' orbital motion (docs/model.md §8.7).

    Instances couple a roller (first 3 coordinates) with the body carrying the inner raceway (last 3:
    the carrier, ``race_marker`` = pin centre in its axes). Ω_m = orbital angular speed of the roller
    centre about the pin centre minus the race body's angular speed;
        F_d = (1/8) C_d ρ D l d_m² Ω_m |Ω_m|   (signed, smooth),
    applied at the roller centre along −t (t = k × e, e from pin centre to roller): it opposes the
    orbital motion relative to the race body. The race body gets the reaction at the same point.

    ``multiplicity`` (default 1): identical parallel rollers per instance; C_d, D, l are one roller's and
    the generalized forces are multiplied by it.

    Viscous churning (docs/model.md §8.7; ``eta`` the mixture's dynamic viscosity η_e [Pa·s] per instance, or None =
    none, the default, evaluated exactly as without it). The orbit drag takes the drag coefficient of a circular
    cylinder in cross flow with its Reynolds number Re = ρ|v|D/η_e, v = (d_m/2)Ω_m (White, Fluid Mechanics:
    C_D ≈ 1 + 10 Re^(−2/3) for 1 ≤ Re ≤ 2·10⁵), C_D = C_d + 10 Re^(−2/3):
        F_d = (1/8) C_d ρ D l d_m² Ω_m|Ω_m| + 5 l D^(1/3) ρ^(1/3) η_e^(2/3) (d_m/2)^(4/3) Ω_m|Ω_m|^(1/3);
    and the roller's spin ω_R relative to the race body meets the moment of a cylinder turning in unbounded viscous
    fluid, the exact Couette solution u_θ = ω a²/r (Landau & Lifshitz, Fluid Mechanics, §18, problem 2, with the
    outer cylinder's radius → ∞: wall shear 2η_e ω, moment 4π η_e ω a² l, a = D/2):
        M_s = −π η_e D² l (ω_R − ω_race)   on the roller, the opposite on the race body.

    Output: "force" signed F_d [N] on one physical roller (the drag on it is −force·t).
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.drag"

    def __init__(self, name, roller, race_body, *, race_marker, C_d, rho, D, l, d_m, multiplicity=1, eta=None):
        self.name = name
        self.dofs = body_dofs(roller, race_body)
        self.race_marker = self._per_instance_xy("race_marker", race_marker)
        C_d = self._per_instance("C_d", C_d, nonneg=True)
        rho = self._per_instance("rho", rho, nonneg=True)
        D = self._per_instance("D", D, positive=True)
        l = self._per_instance("l", l, positive=True)
        d_m = self._per_instance("d_m", d_m, positive=True)
        self.coef = 0.125 * C_d * rho * D * l * d_m * d_m
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))
        self.viscous = eta is not None
        if self.viscous:
            eta = self._per_instance("eta", eta, positive=True)
            self.coef_visc = 5.0 * l * np.cbrt(D * rho) * eta ** (2.0 / 3.0) * (0.5 * d_m) ** (4.0 / 3.0)
            self.coef_spin = np.pi * eta * D * D * l

    def kernel(self, t, fs, q, v, z):
        qr, qb, vr, vb = q[:3], q[3:], v[:3], v[3:]
        (cx, cy), rc = marker(qb, self.race_marker)
        dx, dy = qr[0] - cx, qr[1] - cy
        rho2 = dx * dx + dy * dy + _ETA2
        rho = ad.sqrt(rho2)
        Vc = marker_velocity(vb, rc)
        wx, wy = vr[0] - Vc[0], vr[1] - Vc[1]
        om = (dx * wy - dy * wx) / rho2 - vb[2]
        Fd = self.coef * om * ad.abs_(om)
        if self.viscous:             # Ω|Ω|^(1/3) as sign(Ω)|Ω|^(4/3): its derivative (4/3)|Ω|^(1/3) is finite at 0
            Fd = Fd + self.coef_visc * ad.sign(om) * ad.power(ad.abs_(om), 4.0 / 3.0)
        Fx, Fy = Fd * dy / rho, -1.0 * Fd * dx / rho   # −Fd·t, t = (−dy, dx)/ρ
        zero = 0.0 * qr[0]
        forces = [Fx, Fy, zero] + point_force((rc[0] + dx, rc[1] + dy), (-1.0 * Fx, -1.0 * Fy))
        if self.viscous:
            Ms = -1.0 * self.coef_spin * (vr[2] - vb[2])
            forces[2] = forces[2] + Ms
            forces[5] = forces[5] - Ms
        return _scaled(forces, self.multiplicity, self._multi), {"force": Fd}
