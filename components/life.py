"""Fatigue life of a planet bearing (docs/model.md §14): the laws, defined once. The statistics that feed them
(the bearing load and every roller's raceway loads on every accepted step) are taken by
:class:`components.outputs.WindowStatistics` (:mod:`components.statistics`; the lives from them in
:mod:`components.statistics.summaries`).

Two lives, both the basic rating life L10 (90 % reliability, a_1 = a_ISO = 1), in 10^6 revolutions of the
planet relative to its pin and in hours at that relative speed:

* **ISO 281** (ISO 281:2007 §6.1, §6.3): L10 = (C_r/P)^(10/3) from the bearing's load P (the pin reaction,
  its time equivalent (mean P^(10/3))^(3/10)) and the basic dynamic radial load rating
  C_r = b_m f_c (i l cos α)^(7/9) Z^(3/4) D^(29/27) [N, mm] (ISO 281:2007 eq. (7), f_c from the formula
  behind its Table 7, ISO/TR 1281-1). It knows nothing of how the rollers share the load, of the
  clearance, of the rollers' centrifugal load on the bore or of which ring turns.

* **ISO/TS 16281-style** (Lundberg & Palmgren 1952, line contact; ISO/TS 16281:2008 §5.3 without
  misalignment, i.e. every lamina of a roller equally loaded, so the lamina sum is the whole-roller sum;
  Harris & Kotzalas, *Rolling Bearing Analysis* 5th ed. vol. 2 ch. 8): per raceway the equivalent roller
  load Q_e from the roller loads, the raceway's rating Q_c from the geometry, its life (Q_c/Q_e)^4, and
  the bearing's life L = (Σ_rows Σ_raceways L_k^(−9/8))^(−8/9) (Weibull slope e = 9/8 for line contact).
  Q_e averages the roller loads Q over the rollers and the time window (whole cage revolutions):

  - a raceway that **rotates relative to the load** passes every point of its track through the whole
    load zone: Q_e = (mean Q^4)^(1/4) (each point sees the mean damage);
  - a raceway **stationary relative to the load** keeps each point of its track at one place of the load
    zone for ever; its points fail independently (weakest link, Weibull e), so
    Q_e = (mean Q^(4e))^(1/(4e)) = (mean Q^4.5)^(1/4.5).

  **In a planet bearing** the load — the vector sum of the planet's mesh forces and the centrifugal force,
  fixed on the carrier — stands still relative to the **pin** (the inner raceway, fixed on the carrier):
  the pin is the stationary raceway (exponent 4.5). The **planet bore** (the outer raceway) turns
  through the load zone at the planet's speed relative to the carrier: it is the rotating raceway
  (exponent 4). This is the reverse of the case ISO 281's C_r is written for (inner ring rotating, outer
  ring stationary relative to the load); ISO 281 since 1990 has no rotation factor for it, the roller
  sum has.

  Raceway ratings (Lundberg & Palmgren; Harris & Kotzalas eq. for line contact, N and mm):
  Q_c = 552 b_m (1 ∓ γ)^(29/27)/(1 ± γ)^(1/4) γ^(2/9) D^(29/27) l^(7/9) Z^(−1/4), upper sign the inner
  raceway, γ = D/d_m. These are the ratings ISO/TS 16281 obtains by inverting ISO 281's C_r (its
  Q_c = C_r/(λν 0.378 Z) [1 + (1.038 ((1−γ)/(1+γ))^(143/108))^(9/2)]^(2/9), 207.9 = 552·0.3767): b_m kept,
  ISO 281's reduction λν = 0.83 taken out, because ISO/TS 16281 accounts for edge stresses through the
  roller profile and tilt. This planar model has neither: its rollers carry a uniform line load (the
  ideal profile, no tilt), so this life is the upper end of what ISO/TS 16281 gives for a real profile.

  Under a pure radial load F_r at zero clearance (continuous load zone: Stribeck's integrals J_r, J_1,
  J_2 of the load distribution Q = Q_max cos^n ψ) the sum gives exactly L = (C_LP/F_r)^4 with the
  Lundberg–Palmgren rating C_LP = i^(7/9) Z J_r [(Q_c,rot/J_1)^(−9/2) + (Q_c,stat/J_2)^(−9/2)]^(−2/9)
  (:func:`lundberg_palmgren_rating`); for the inner ring rotating and ISO's n = 1.1, λν C_LP = C_r. So
  this life is ISO 281's (C_r/(λν F_r))^4 where ISO 281 says (C_r/F_r)^(10/3): the two agree only at
  F_r = λν^6 C_r; at planet-bearing loads (F_r ≈ C_r/3) the roller sum gives about 4× ISO 281's life.
  The exponent 4 is the line-contact theory's; ISO 281's 10/3 is its compromise for real rollers.

* **ISO/TS 16281 with slices** (ISO/TS 16281:2008 §5.3 with its laminae; the sliced contact of docs/model.md §8.8):
  the roller cut into n_s slices, per raceway and slice k an equivalent slice load q_e,k over the rollers and the
  window (exponents 4.5 and 4 as above) and the slice rating q_c = Q_c n_s^(−7/9); the bearing's
  L = [Σ_rows Σ_k ((q_e,k,pin/q_c,pin)^(9/2) + (q_e,k,bore/q_c,bore)^(9/2))]^(−8/9) (:func:`sliced_life`).
  Equal slices q_e,k = Q_e/n_s give exactly the roller sum above: n_s (n_s^(−2/9))^(9/2) = 1.

* **Rows.** ISO/TS 16281:2008 §5.3 gives a bearing's life from its raceways' lives as a series system of Weibull
  members, L = (Σ L_k^(−e))^(−1/e), e = 9/8; its scope (clause 1) extends the calculation to multi-row bearings
  through the same equations. Each row's raceways are members of that system: each row has its own equivalent loads
  (over its own rollers, with the exponents above) and its own raceway lives, and the bearing's life is the sum over
  rows and raceways. Identical rows (the planar model's folded rows) count ``b.rows`` times one row's terms; rows
  loaded differently (the sliced model's explicit rows under a tilt) are passed row by row. Pooling the rows'
  rollers into one equivalent load would be wrong for the rotating raceway, whose (mean Q^4)^(9/8) is not linear in
  the rows' means.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

__all__ = ["LIFE_EXPONENT", "LINE_EXPONENT", "WEIBULL_SLOPE", "ROTATING_EXPONENT", "STATIONARY_EXPONENT",
           "relative_life", "iso281_rating", "iso281_life", "raceway_ratings", "equivalent_load",
           "lundberg_palmgren_life", "lundberg_palmgren_rating", "load_zone_integrals", "hours",
           "sliced_raceway_ratings", "sliced_life", "revolution_shares", "miner_life", "damage_shares",
           "spectrum_equivalent_load"]

LIFE_EXPONENT = 10.0 / 3.0     # ISO 281, roller bearings: L10 ∝ P^(−10/3)
LINE_EXPONENT = 4.0            # Lundberg–Palmgren line contact: raceway life (Q_c/Q_e)^4
WEIBULL_SLOPE = 9.0 / 8.0      # Lundberg–Palmgren line contact: e = 9/8
ROTATING_EXPONENT = LINE_EXPONENT                    # Q_e = (mean Q^4)^(1/4)
STATIONARY_EXPONENT = LINE_EXPONENT * WEIBULL_SLOPE  # Q_e = (mean Q^4.5)^(1/4.5)
_LP_CONSTANT = 552.0           # N, mm: Lundberg–Palmgren line contact (Harris & Kotzalas); 207.9 = 552 J_r/J_1
_ISO281_FC = 207.9             # ISO 281:2007 / ISO/TR 1281-1: f_c = 207.9 λν ...
_ISO281_J_RATIO = 1.04         # ISO 281's rounding of J_2/J_1 = 1.0366 (n = 1.1)


def relative_life(P: float, P_ref: float) -> float | None:
    """ISO 281 basic rating life ratio L10/L10_ref = (P_ref/P)^(10/3) for roller bearings (None for P ≤ 0)."""
    return float((P_ref / P) ** LIFE_EXPONENT) if P > 0 else None


def _gamma(b) -> float:
    g = b.roller_diameter / b.pitch_diameter
    if not 0.0 < g < 1.0:
        raise ValueError(f"bearing: roller_diameter/pitch_diameter must be in (0, 1), got {g!r}")
    return g


def iso281_rating(b) -> float:
    """ISO 281:2007 eq. (7) basic dynamic radial load rating C_r [N] of the radial cylindrical roller bearing
    ``b`` (:class:`~components.params.BearingSI`; contact angle 0, ``rows`` rows): b_m f_c (i l)^(7/9)
    Z^(3/4) D^(29/27) with D, l in mm and f_c = 207.9 λν γ^(2/9) (1−γ)^(29/27)/(1+γ)^(1/4)
    [1 + (1.04 ((1−γ)/(1+γ))^(143/108))^(9/2)]^(−2/9) (the formula of ISO 281 Table 7, ISO/TR 1281-1)."""
    g, lf = _gamma(b), b.life
    r = (1.0 - g) / (1.0 + g)
    fc = _ISO281_FC * lf.reduction_factor * g ** (2 / 9) * (1 - g) ** (29 / 27) / (1 + g) ** 0.25 \
        * (1.0 + (_ISO281_J_RATIO * r ** (143 / 108)) ** 4.5) ** (-2 / 9)
    D, l = 1e3 * b.roller_diameter, 1e3 * b.roller_length
    return lf.material_factor * fc * (b.rows * l) ** (7 / 9) * b.rollers ** 0.75 * D ** (29 / 27)


# a roller bearing's requisite minimum load as a fraction of its basic dynamic load rating: SKF's rule for roller
# bearings (SKF, Rolling bearings catalogue, PUB BU/P1 17000 EN, 2018, "Requisite minimum load": 0.02 C for roller
# bearings, 0.01 C for ball bearings; below it "skidding and smearing of raceways or cage damage often prevail").
# SKF's product sections refine it per bearing with catalogue factors (cylindrical roller bearings:
# F_rm = k_r (6 + 4 n/n_r)(d_m/100)² kN, k_r and the reference speed n_r from the product tables), which a planet
# bearing without a catalogue designation does not have.
MINIMUM_LOAD_RATIO = 0.02


def minimum_load(b) -> float:
    """The catalogue minimum load [N] of bearing ``b``: SKF's rule F_min = 0.02 C (:data:`MINIMUM_LOAD_RATIO`), C
    the basic dynamic load rating of ISO 281 (:func:`iso281_rating`)."""
    return MINIMUM_LOAD_RATIO * iso281_rating(b)


def iso281_life(P: float, b) -> float | None:
    """ISO 281 basic rating life L10 = (C_r/P)^(10/3) [10^6 revolutions] (None for P ≤ 0)."""
    return float((iso281_rating(b) / P) ** LIFE_EXPONENT) if P > 0 else None


def raceway_ratings(b) -> tuple[float, float]:
    """Basic dynamic load ratings (Q_c,pin, Q_c,bore) [N] of one roller contact on the inner raceway (the
    pin) and on the outer raceway (the planet bore) of one row: Lundberg–Palmgren line contact times b_m
    (module docstring; no λν)."""
    g = _gamma(b)
    D, l = 1e3 * b.roller_diameter, 1e3 * b.roller_length
    common = _LP_CONSTANT * b.life.material_factor * g ** (2 / 9) * D ** (29 / 27) * l ** (7 / 9) \
        * b.rollers ** -0.25
    return (common * (1 - g) ** (29 / 27) / (1 + g) ** 0.25,
            common * (1 + g) ** (29 / 27) / (1 - g) ** 0.25)


def equivalent_load(power_mean, exponent: float):
    """Q_e = (mean of Q^p)^(1/p) from the mean of Q^p (a number or an array)."""
    return np.asarray(power_mean, float) ** (1.0 / exponent)


def lundberg_palmgren_life(q_pin, q_bore, b) -> float | None:
    """Basic reference rating life [10^6 revolutions of the bore relative to the pin] from the raceways'
    equivalent roller loads ``q_pin``, ``q_bore`` [N] (per physical roller; the caller has taken each with its
    raceway's exponent): numbers, one row's share of ``b.rows`` identical rows, or arrays (rows,), each row's own
    (rows loaded differently: the sliced model's explicit rows). L_k = (Q_c,k/Q_e,k)^4 per raceway and row, the
    bearing L = (Σ_rows Σ_k L_k^(−e))^(−1/e) (module docstring). None when no roller is loaded."""
    qc_pin, qc_bore = raceway_ratings(b)
    per_row = np.ndim(q_pin) > 0
    q_pin, q_bore = np.asarray(q_pin, float), np.asarray(q_bore, float)
    if not (np.all(q_pin >= 0.0) and np.all(q_bore >= 0.0)) or q_pin.shape != q_bore.shape:
        raise ValueError(f"equivalent roller loads must be >= 0 N of equal shapes, got pin {q_pin!r}, bore {q_bore!r}")
    e = WEIBULL_SLOPE
    damage = float(np.sum((q_pin / qc_pin) ** (LINE_EXPONENT * e) + (q_bore / qc_bore) ** (LINE_EXPONENT * e)))
    damage *= 1.0 if per_row else b.rows
    return float(damage ** (-1.0 / e)) if damage > 0 else None


def sliced_raceway_ratings(b, n_slices: int) -> tuple[float, float]:
    """(q_c,pin, q_c,bore) [N] of one slice of n_s: the raceway ratings times n_s^(−7/9) (ISO/TS 16281:2008:
    the rating scales with the length as l^(7/9))."""
    return tuple(q * float(n_slices) ** (-7.0 / 9.0) for q in raceway_ratings(b))


def sliced_life(q_pin, q_bore, b) -> float | None:
    """ISO/TS 16281 life with slices [10^6 revolutions] from the slices' equivalent loads ``q_pin``, ``q_bore`` [N]
    (per physical roller; each taken with its raceway's exponent by the caller): arrays (rows, n_s), or (n_s,) for
    ``b.rows`` identical rows. L = [Σ_rows Σ_k ((q_pin,k/q_c,pin)^(4e) + (q_bore,k/q_c,bore)^(4e))]^(−1/e),
    q_c = :func:`sliced_raceway_ratings`, e = 9/8. None when no slice is loaded."""
    q_pin, q_bore = np.asarray(q_pin, float), np.asarray(q_bore, float)
    if q_pin.shape != q_bore.shape or q_pin.ndim not in (1, 2):
        raise ValueError(f"slice loads: expected equal shapes (n_s,) or (rows, n_s), got {q_pin.shape}, {q_bore.shape}")
    if not (np.all(q_pin >= 0.0) and np.all(q_bore >= 0.0)):
        raise ValueError("slice equivalent loads must be >= 0 N")
    qc_pin, qc_bore = sliced_raceway_ratings(b, q_pin.shape[-1])
    p = LINE_EXPONENT * WEIBULL_SLOPE
    damage = float(np.sum((q_pin / qc_pin) ** p) + np.sum((q_bore / qc_bore) ** p))
    damage *= b.rows if q_pin.ndim == 1 else 1.0
    return damage ** (-1.0 / WEIBULL_SLOPE) if damage > 0 else None


def load_zone_integrals(n: float) -> tuple[float, float, float]:
    """Stribeck/Lundberg integrals of a zero-clearance radial load zone Q = Q_max cos^n ψ (|ψ| < 90°):
    J_r = F_r/(Z Q_max), J_1 = (mean Q^4)^(1/4)/Q_max, J_2 = (mean Q^4.5)^(1/4.5)/Q_max (means over the
    whole circle)."""
    mean = lambda p: quad(lambda x: math.cos(x) ** p, -0.5 * math.pi, 0.5 * math.pi)[0] / (2.0 * math.pi)
    return (mean(n + 1.0), mean(ROTATING_EXPONENT * n) ** (1 / ROTATING_EXPONENT),
            mean(STATIONARY_EXPONENT * n) ** (1 / STATIONARY_EXPONENT))


def lundberg_palmgren_rating(b, rotating: str = "outer", n: float | None = None) -> float:
    """Closed form: the radial load [N] for which :func:`lundberg_palmgren_life` gives 10^6 revolutions under
    a pure radial load at zero clearance with a continuous load zone Q = Q_max cos^n ψ (default n: the
    bearing's contact exponent). ``rotating``: which raceway turns relative to the load, "outer" (a planet
    bearing) or "inner" (the case ISO 281 is written for; then λν·rating = C_r for n = 1.1)."""
    if rotating not in ("inner", "outer"):
        raise ValueError(f"rotating must be 'inner' or 'outer', got {rotating!r}")
    Jr, J1, J2 = load_zone_integrals(b.contact_exponent if n is None else n)
    qc_pin, qc_bore = raceway_ratings(b)
    j_pin, j_bore = (J1, J2) if rotating == "inner" else (J2, J1)
    p = -LINE_EXPONENT * WEIBULL_SLOPE
    return b.rows ** (7 / 9) * b.rollers * Jr * ((qc_pin / j_pin) ** p + (qc_bore / j_bore) ** p) ** (1 / p)


def hours(million_revolutions: float | None, relative_speed: float) -> float | None:
    """A life in 10^6 revolutions as hours at ``relative_speed`` [rad/s] (None if either is missing or 0)."""
    w = abs(relative_speed)
    if million_revolutions is None or w == 0.0:
        return None
    return float(million_revolutions * 1e6 * 2.0 * math.pi / w / 3600.0)


# ---------------------------------------------------------------------------------------------------------------
# a load spectrum: lives of its bins combined (Palmgren–Miner)
# ---------------------------------------------------------------------------------------------------------------
def revolution_shares(revolutions) -> np.ndarray:
    """u_i = N_i / Σ N_j: each bin's share of the revolutions of a duty cycle (N_i ≥ 0, not all 0)."""
    n = np.asarray(revolutions, float)
    if n.ndim != 1 or n.size == 0 or not np.all(np.isfinite(n)) or np.any(n < 0) or not n.sum() > 0:
        raise ValueError(f"revolutions must be >= 0 and not all 0, got {n.tolist()!r}")
    return n / n.sum()


def miner_life(lives, shares) -> float | None:
    """The life under a spectrum by the Palmgren–Miner rule, L = 1 / Σ_i (u_i / L_i).

    Bin i runs N_i revolutions per duty cycle at conditions under which the bearing's life is L_i revolutions; it
    uses up the fraction N_i/L_i of the life (Miner's linear damage sum). One cycle of N = Σ N_i revolutions uses
    D = Σ N_i/L_i, so the bearing lasts 1/D cycles, L = N/D = 1/Σ (u_i/L_i) revolutions with u_i = N_i/N — the
    form of ISO 281:2007's variable-conditions note and of ISO/TS 16281:2008 (Palmgren 1924; Miner 1945; Harris &
    Kotzalas, *Rolling Bearing Analysis* 5th ed. vol. 2 §8.8). ``lives`` and ``shares`` in the same unit of
    revolutions and summing to one; the same sum with time shares τ_i and lives in hours, each at its bin's own
    speed, gives the life in hours (N_i/L_i = t_i/L_h,i). A bin with no life (None: no load) does no damage;
    None when no bin does."""
    u = np.asarray(shares, float)
    if len(u) != len(lives):
        raise ValueError(f"{len(lives)} lives for {len(u)} shares")
    if any(L is not None and not float(L) > 0 for L in lives):
        raise ValueError(f"lives must be > 0, got {list(lives)!r}")
    total = math.fsum(ui / float(L) for ui, L in zip(u, lives) if L is not None and ui > 0)
    return 1.0 / total if total > 0 else None


def damage_shares(lives, shares) -> list[float | None]:
    """Each bin's share of the damage, (u_i/L_i) / Σ_j (u_j/L_j) (they sum to one); None for a bin without a life,
    all None when no bin does damage."""
    d = [ui / float(L) if L is not None and ui > 0 else (0.0 if L is not None else None)
         for ui, L in zip(np.asarray(shares, float), lives)]
    total = math.fsum(x for x in d if x is not None)
    return [None if x is None or total == 0 else x / total for x in d]


def spectrum_equivalent_load(loads, shares, exponent: float = LIFE_EXPONENT) -> float:
    """The constant load of the same life as the spectrum, P = (Σ_i u_i P_i^p)^(1/p) with u_i the revolution shares
    and p the life exponent (ISO 281: 10/3): with L_i = (C/P_i)^p, 1/L = Σ u_i/L_i = Σ u_i P_i^p / C^p
    (:func:`miner_life`)."""
    P, u = np.asarray(loads, float), np.asarray(shares, float)
    return float(math.fsum(u * P ** exponent) ** (1.0 / exponent))
