"""Lubricant film of the roller–raceway contacts (docs/model.md §9): the one owner of these laws.

* :func:`walther_viscosity` — kinematic viscosity at a temperature from its values at 40 °C and 100 °C
  (Walther's equation, ASTM D341: log₁₀ log₁₀(ν + 0.7) = A − B log₁₀ T, ν in mm²/s, T in K), and
  :func:`walther_slope`, its −(1/ν) dν/dT = B (ν + 0.7) ln(ν + 0.7) / (ν T).
* :func:`oil_density` — ρ(T) = ρ₁₅ (1 − α_ρ (T − 15 °C)), the linear form of the petroleum volume
  correction (API MPMS 11.1 / ASTM D1250 give α_ρ for lubricating oils); :func:`dynamic_viscosity`
  η = ρ(T) ν(T) and :func:`temperature_viscosity` β = −(1/η) dη/dT = −(1/ν) dν/dT + α_ρ / (1 − α_ρ (T − 15 °C)),
  the temperature–viscosity coefficient of the film's thermal reduction.
* :func:`reduced_modulus` — E' = 2 / ((1 − ν₁²)/E₁ + (1 − ν₂²)/E₂) (Hamrock's convention).
* :func:`roller_contact_radius` — the reduced radius R of a roller (diameter D) on a raceway of radius
  R_race: 1/R = 2/D + 1/R_race on the inner raceway (convex on convex), 2/D − 1/R_race on the outer one.
* :func:`line_contact_film` — isothermal EHL film of a rectangular (line) contact (the formulas live in
  :mod:`mbd.elements.ehl`, shared with the EHL traction law, as does the thermal reduction
  :func:`bearing_film` applies), Pan & Hamrock (1989,
  J. Tribol. 111: 246–251): with U = η₀u/(E'R), W' = w'/(E'R), G = α_p E' (u the entraining speed, w'
  the load per unit length),
      h_min / R = 1.714 W'^(−0.128) U^0.694 G^0.568,    h_c / R = 2.922 W'^(−0.166) U^0.692 G^0.470.
  Dowson & Higginson's classic h_min/R = 2.65 U^0.70 G^0.54 W'^(−0.13) is :func:`dowson_higginson_film`
  (a cross-check: the two agree within ≈ 15 % over bearing conditions).
* :func:`limiting_shear_slope` — the pressure slope γ_L of the limiting shear stress τ_L = τ_L0 + γ_L p at the
  oil's temperature (docs/model.md §9.3). ``"constant"``: γ_L as given, at every temperature. ``"dyson"``: the
  temperature form of Dyson's limiting shear stress of a mineral oil, τ_L = G_∞/4 with
  G_∞ = 1.2 p/(2.52 + 0.024 t) − 10⁸ (Dyson 1970, Phil. Trans. R. Soc. A 266: 1–33, as Zhou & Hoeprich 1991,
  J. Tribol. 113: 590–597, eqs. 36–37 quote it; t the temperature, taken in °C: the quoting paper prints no unit
  with it and gives its temperatures in °C), whose pressure slope 0.3/(2.52 + 0.024 t) = 12.5/(t + 105 °C) falls as
  1/(T − T₀) with the pole T₀ = −105 °C: the given γ_L holds at the reference temperature T_ref and
  γ_L(T) = γ_L (T_ref − T₀)/(T − T₀). Dyson's offset −10⁸/4 is not taken (in Pa it would make τ_L negative below
  ≈ 0.3 GPa, where light rollers run); τ_L0 keeps its value.
* The film parameter Λ = h_min / σ, σ the composite roughness of the two surfaces, and its regime as the
  literature names it (:func:`regime`): Λ ≥ 3 full film; 1 ≤ Λ < 3 partial EHL (mixed: asperities carry part
  of the load); Λ < 1 boundary-dominated.

Scalars or numpy arrays (broadcast); SI units throughout.
"""
from __future__ import annotations

import numpy as np

from mbd.elements.ehl import film_central, film_min, hertz_peak_pressure, thermal_factor, thermal_loading

__all__ = ["walther_viscosity", "walther_slope", "oil_density", "dynamic_viscosity", "temperature_viscosity",
           "reduced_modulus", "roller_contact_radius", "line_contact_film", "dowson_higginson_film",
           "bearing_film", "contact_pressure", "regime", "limiting_shear_slope", "LIMITING_SHEAR_LAWS",
           "FULL_FILM_LAMBDA", "BOUNDARY_LAMBDA"]

FULL_FILM_LAMBDA, BOUNDARY_LAMBDA = 3.0, 1.0     # Λ bounds of full film and of boundary-dominated contact

T_DENSITY = 288.15     # 15 °C: the reference temperature of an oil's density (ISO 3675, ASTM D1298)


def _walther_line(nu40: float, nu100: float) -> tuple[float, float]:
    """(A, B) of the line log₁₀ log₁₀(ν + 0.7) = A − B log₁₀ T through ν at 40 and 100 °C (ν in mm²/s)."""
    T40, T100 = 313.15, 373.15
    ll = lambda nu: np.log10(np.log10(nu * 1e6 + 0.7))          # noqa: E731  (mm²/s inside the law)
    B = (ll(nu40) - ll(nu100)) / (np.log10(T100) - np.log10(T40))
    return ll(nu40) + B * np.log10(T40), B


def walther_viscosity(nu40: float, nu100: float, temperature: float) -> float:
    """Kinematic viscosity [m²/s] at ``temperature`` [K] from ν at 40 °C and 100 °C [m²/s] (ASTM D341)."""
    A, B = _walther_line(nu40, nu100)
    return float((10.0 ** (10.0 ** (A - B * np.log10(temperature))) - 0.7) * 1e-6)


def walther_slope(nu40: float, nu100: float, temperature: float) -> float:
    """−(1/ν) dν/dT [1/K] of Walther's line at ``temperature`` [K]: with Z = ν + 0.7 (mm²/s),
    ln Z = ln 10 · 10^(A − B log₁₀ T), so dZ/dT = −B Z ln Z / T."""
    _, B = _walther_line(nu40, nu100)
    Z = walther_viscosity(nu40, nu100, temperature) * 1e6 + 0.7
    return float(B * Z * np.log(Z) / ((Z - 0.7) * temperature))


def oil_density(rho15: float, expansion: float, temperature: float) -> float:
    """ρ [kg/m³] at ``temperature`` [K] of an oil of density ``rho15`` at 15 °C and volumetric thermal
    expansion ``expansion`` α_ρ [1/K]."""
    return rho15 * (1.0 - expansion * (temperature - T_DENSITY))


def dynamic_viscosity(nu40: float, nu100: float, rho15: float, expansion: float, temperature: float) -> float:
    """η [Pa·s] = ρ(T) ν(T): Walther's kinematic viscosity times the density at the same temperature."""
    return oil_density(rho15, expansion, temperature) * walther_viscosity(nu40, nu100, temperature)


def temperature_viscosity(nu40: float, nu100: float, expansion: float, temperature: float) -> float:
    """β = −(1/η) dη/dT [1/K] of η = ρ(T) ν(T): Walther's slope plus the density's −(1/ρ) dρ/dT."""
    return walther_slope(nu40, nu100, temperature) + expansion / (1.0 - expansion * (temperature - T_DENSITY))


LIMITING_SHEAR_LAWS = ("constant", "dyson")     # lubricant.limiting_shear_law: γ_L's temperature dependence


def limiting_shear_slope(law: str, gamma_ref: float, temperature: float, reference_temperature: float,
                         pole_temperature: float) -> float:
    """γ_L at ``temperature`` [K] (module docstring): ``gamma_ref`` itself for ``"constant"``; for ``"dyson"``
    γ_L(T) = γ_ref (T_ref − T₀)/(T − T₀), T₀ = ``pole_temperature`` below both temperatures [K]."""
    if law == "constant":
        return gamma_ref
    if law != "dyson":
        raise ValueError(f"limiting_shear_slope: law must be one of {LIMITING_SHEAR_LAWS}, got {law!r}")
    return gamma_ref * (reference_temperature - pole_temperature) / (temperature - pole_temperature)


def reduced_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E' [Pa] of two elastic bodies."""
    return 2.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)


def roller_contact_radius(D, R_race, inner: bool):
    """Reduced radius [m] of a roller of diameter D on the inner (convex) or outer (concave) raceway."""
    curv = 2.0 / np.asarray(D, float) + (1.0 if inner else -1.0) / np.asarray(R_race, float)
    return 1.0 / curv


def line_contact_film(u, w_per_length, R, eta0, alpha_p, E_red):
    """(h_min, h_c) [m] of Pan & Hamrock (1989) (:mod:`mbd.elements.ehl` owns the formulas; the EHL
    traction law uses the same). ``u`` entraining speed [m/s] (its magnitude counts), ``w_per_length``
    load per unit length [N/m] (> 0), ``R`` reduced radius [m], ``eta0`` dynamic viscosity at the inlet
    [Pa·s], ``alpha_p`` pressure–viscosity coefficient [1/Pa], ``E_red`` E' [Pa]."""
    u, w, R = np.abs(np.asarray(u, float)), np.asarray(w_per_length, float), np.asarray(R, float)
    return film_min(u, w, R, eta0, alpha_p, E_red), film_central(u, w, R, eta0, alpha_p, E_red)


def dowson_higginson_film(u, w_per_length, R, eta0, alpha_p, E_red):
    """h_min [m] of Dowson & Higginson's line-contact formula (the classic cross-check)."""
    U = eta0 * np.abs(u) / (E_red * R)
    W = np.asarray(w_per_length, float) / (E_red * R)
    return R * 2.65 * U ** 0.70 * (alpha_p * E_red) ** 0.54 * W ** -0.13


def bearing_film(load, rolling_speed, bearing, lubricant, inner: bool) -> dict[str, np.ndarray]:
    """The film of every roller contact of one raceway, NaN where a roller carries no load:
    "film_min", "film_central" h_min and h_c with the thermal reduction [m], "film_min_isothermal" [m],
    "film_thermal_loading" L and "film_thermal_factor" φ_T (Murch & Wilson), "film_load_parameter" W'.
    ``load``: per physical roller [N]; ``rolling_speed``: the entraining speed [m/s]; ``bearing``,
    ``lubricant``: the SI objects of :class:`~components.params.BearingParams` and
    :class:`~components.params.LubricantParams`."""
    b, lub = bearing, lubricant
    R_race = b.inner_raceway_radius if inner else b.outer_raceway_radius
    R = roller_contact_radius(b.roller_diameter, R_race, inner)
    E_red = reduced_modulus(b.elastic_modulus, b.poisson_ratio, b.elastic_modulus, b.poisson_ratio)
    load = np.asarray(load, float)
    loaded = load > 0.0
    w = np.where(loaded, load, 1.0) / b.roller_length
    u = np.abs(np.asarray(rolling_speed, float))
    h_min, h_c = line_contact_film(u, w, R, lub.oil_viscosity, lub.pressure_viscosity, E_red)
    L = thermal_loading(u, lub.oil_viscosity, lub.temperature_viscosity, lub.thermal_conductivity)
    phi = thermal_factor(L)
    out = {"film_min": phi * h_min, "film_central": phi * h_c, "film_min_isothermal": h_min,
           "film_thermal_loading": L, "film_thermal_factor": phi, "film_load_parameter": w / (E_red * R)}
    return {k: np.where(loaded, v, np.nan) for k, v in out.items()}


def contact_pressure(load, bearing, inner: bool):
    """Hertz peak pressure p_max = √(w'E'/(2πR)) [Pa] of each roller's line contact on one raceway (Johnson, *Contact
    Mechanics*, 1985, eq. 4.45; :func:`mbd.elements.ehl.hertz_peak_pressure`), the roller's ``load`` [N, per
    physical roller] spread evenly over its effective length l (w' = Q/l), the reduced radius R and modulus E' as
    :func:`bearing_film` takes them; 0 where a roller carries no load."""
    b = bearing
    R_race = b.inner_raceway_radius if inner else b.outer_raceway_radius
    R = roller_contact_radius(b.roller_diameter, R_race, inner)
    E_red = reduced_modulus(b.elastic_modulus, b.poisson_ratio, b.elastic_modulus, b.poisson_ratio)
    return hertz_peak_pressure(np.maximum(np.asarray(load, float), 0.0) / b.roller_length, R, E_red)


def regime(lam: float) -> str:
    """The lubrication regime of a film parameter Λ, as the literature names it."""
    return ("full film" if lam >= FULL_FILM_LAMBDA else "partial EHL (mixed)" if lam >= BOUNDARY_LAMBDA
            else "boundary-dominated")
