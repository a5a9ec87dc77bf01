"""The lubricant film of the roller contacts (components.lubrication, docs/model.md §9)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import mbd
from components.lubrication import (dowson_higginson_film, dynamic_viscosity, line_contact_film, oil_density,
                                    reduced_modulus, roller_contact_radius, temperature_viscosity, walther_slope,
                                    walther_viscosity)
from mbd.elements.ehl import thermal_factor, thermal_loading
from components.outputs import WindowStatistics
from components.params import with_overrides
from components.presets import OIL_GRADES, oil_grade, reference_dpgt
from components.units import ParameterError

from tests.support.dpgt_runs import ramp_state

E_STEEL = reduced_modulus(210e9, 0.3, 210e9, 0.3)


def test_walther_passes_through_its_data_and_thins_with_temperature():
    for grade in OIL_GRADES.values():
        nu40, nu100 = (float(grade[k].value.split()[0]) * 1e-6 for k in ("viscosity_40", "viscosity_100"))
        assert walther_viscosity(nu40, nu100, 313.15) == pytest.approx(nu40, rel=1e-12)
        assert walther_viscosity(nu40, nu100, 373.15) == pytest.approx(nu100, rel=1e-12)
        T = np.linspace(273.15, 423.15, 31)
        assert np.all(np.diff([walther_viscosity(nu40, nu100, x) for x in T]) < 0)


def test_reduced_modulus_and_radius():
    assert E_STEEL == pytest.approx(210e9 / (1 - 0.09), rel=1e-14)     # two equal bodies: E/(1 − ν²)
    D, R = 7.5e-3, 15.75e-3
    assert roller_contact_radius(D, R, True) == pytest.approx(1 / (2 / D + 1 / R), rel=1e-14)
    assert roller_contact_radius(D, R + D, False) == pytest.approx(1 / (2 / D - 1 / (R + D)), rel=1e-14)


@settings(max_examples=60, deadline=None)
@given(U=st.floats(-12, -9), W=st.floats(-5, -3), G=st.floats(3000, 7000))
def test_pan_hamrock_agrees_with_dowson_higginson(U, W, G):
    """Two published line-contact formulas, over the bearing range of the dimensionless groups: within
    11 % of each other (Pan–Hamrock's regression is the thinner, 0.90–0.97 of Dowson–Higginson)."""
    R, eta = 3e-3, 0.025
    u, w, alpha = 10 ** U * E_STEEL * R / eta, 10 ** W * E_STEEL * R, G / E_STEEL
    h_min, h_c = line_contact_film(u, w, R, eta, alpha, E_STEEL)
    ratio = h_min / dowson_higginson_film(u, w, R, eta, alpha, E_STEEL)
    assert 0.89 < ratio < 0.97
    # central film over the exit constriction: ≈ 1.3 in EHL; the two regressions meet at the heaviest loads
    assert 0.9 < h_c / h_min < 1.6


def test_film_grows_with_speed_and_viscosity_and_thins_weakly_with_load():
    R, eta, alpha = 3e-3, 0.025, 2.2e-8
    h = lambda u=5.0, w=3e5, eta=eta: line_contact_film(u, w, R, eta, alpha, E_STEEL)[0]   # noqa: E731
    assert h(u=10.0) / h() == pytest.approx(2 ** 0.694, rel=1e-12)
    assert h(eta=2 * eta) / h() == pytest.approx(2 ** 0.694, rel=1e-12)
    assert h(w=6e5) / h() == pytest.approx(2 ** -0.128, rel=1e-12)    # doubling the load: 8.5 % thinner
    assert h(u=-5.0) == h()                             # only the entraining speed's magnitude builds a film


def test_oil_grades_and_bad_viscosities():
    base = reference_dpgt(3, "forward")
    eta = [with_overrides(base, oil_grade(g)).si().lubricant.oil_viscosity for g in ("VG32", "VG68", "VG150")]
    assert eta[0] < eta[1] < eta[2]
    assert 0.020 < eta[1] < 0.030            # VG 68 at 60 °C: ≈ 29 mm²/s (data sheets: 27–31) × 870 kg/m³
    with pytest.raises(ParameterError, match="viscosity_100.*below"):
        with_overrides(base, {"lubricant.viscosity_100": "80 mm^2/s"}).si()
    with pytest.raises(ParameterError, match="lubricant grade"):
        oil_grade("VG47")
    assert with_overrides(base, {"lubricant.temperature": "80 degC"}).si().lubricant.oil_viscosity < eta[1]


@pytest.fixture(scope="module")
def loaded_state():
    """The DPGT 3 ms into its load ramp, and its scene."""
    return ramp_state(0.003, "auto")


def _snapshot(scene, state, lubricant):
    scene = dataclasses.replace(scene, lubricant=lubricant)
    stats = WindowStatistics(scene, 0.001, 0.002, whole_revolutions=False)
    stats.bind(scene.model, mbd.System(scene.model), state)
    return stats.snapshot(state)


def test_the_thinnest_film_of_each_bearing_scales_with_the_oil(loaded_state):
    """Same state, two oils: every bearing's thinnest isothermal film scales as η^0.694 (Pan–Hamrock); the
    thermal one is thinner, the more so for the thicker oil (L ∝ β η); Λ = h/σ."""
    sc, s = loaded_state
    base = reference_dpgt(3, "forward")
    thin, thick = (with_overrides(base, oil_grade(g)).si().lubricant for g in ("VG32", "VG150"))
    a, b = _snapshot(sc, s, thin), _snapshot(sc, s, thick)
    assert np.all(np.isfinite(a["film_thinnest"])) and np.all(a["film_thinnest"] > 0)
    np.testing.assert_allclose(b["film_thinnest_isothermal"] / a["film_thinnest_isothermal"],
                               (thick.oil_viscosity / thin.oil_viscosity) ** 0.694, rtol=1e-12)
    assert np.all(a["film_thinnest"] < a["film_thinnest_isothermal"])
    assert np.all(b["film_thinnest"] / b["film_thinnest_isothermal"] < a["film_thinnest"] / a["film_thinnest_isothermal"])
    np.testing.assert_allclose(a["film_lambda"], a["film_thinnest"] / thin.roughness, rtol=1e-15)
    # the film of one contact by hand: the most loaded roller of bearing 0 on its pin
    out = mbd.System(sc.model).outputs(s.t, s.q, s.v, s.z)["race_inner"]
    b0 = sc.bearing
    Z = b0.rollers
    j = int(np.argmax(out["load"][:Z]))
    R = roller_contact_radius(b0.roller_diameter, b0.inner_raceway_radius, True)
    E = reduced_modulus(b0.elastic_modulus, b0.poisson_ratio, b0.elastic_modulus, b0.poisson_ratio)
    h_j, _ = line_contact_film(out["rolling_speed"][j], out["load"][j] / b0.roller_length, R, thin.oil_viscosity,
                               thin.pressure_viscosity, E)
    assert a["film_thinnest_isothermal"][0] <= h_j * (1 + 1e-12)


def test_ehl_traction_is_selectable_and_runs_on_the_rig():
    """bearing.traction_law = "ehl" builds the EHL law from the lubricant; a loaded rig runs with it on
    the compiled engine."""
    from mbd.elements import EHLTraction
    from scenarios.numerics.common import rig_problem
    prob = rig_problem(overrides={"bearing.traction_law": "ehl"})
    law = prob.model.element("race_inner").traction
    lub = reference_dpgt(3, "forward").si().lubricant
    assert isinstance(law, EHLTraction) and law.eta0 == lub.oil_viscosity and law.G_e == lub.film_shear_modulus
    res = mbd.simulate(prob.model, prob.built.q0, prob.built.v0, 0.002, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False)
    assert res.engine == "compiled"
    out = mbd.System(prob.model).outputs(res.state.t, res.state.q, res.state.v, res.state.z)["race_inner"]
    loaded = out["load"] > 0
    assert loaded.any() and np.all(np.abs(out["traction"][loaded]) <= 0.08 * out["load"][loaded])


def test_a_given_viscosity_replaces_the_walther_value():
    base = reference_dpgt(3, "forward")
    p = with_overrides(base, {"lubricant.oil_viscosity": "30 mPa*s"})
    assert p.si().lubricant.oil_viscosity == pytest.approx(0.03, rel=1e-15)
    assert p.lubricant.source("oil_viscosity").tag == "user"


def test_heat_and_traction_coefficient_of_each_bearing(loaded_state):
    """Traction heat = Σ rows·|F_t v_s| over a bearing's rollers and raceways; land heat = |friction·v_t|;
    the largest |F_t|/Q of a loaded contact stays below the tanh law's μ_max."""
    sc, s = loaded_state
    snap = _snapshot(sc, s, reference_dpgt(3, "forward").si().lubricant)
    out = mbd.System(sc.model).outputs(s.t, s.q, s.v, s.z)
    Z = sc.bearing.rollers
    for k in range(len(snap["heat_traction"])):
        sl = slice(k * Z, (k + 1) * Z)
        by_hand = sum(np.sum(np.abs(out[f]["traction"][sl] * out[f]["slip_velocity"][sl]))
                      for f in ("race_inner", "race_outer"))
        assert snap["heat_traction"][k] == pytest.approx(by_hand, rel=1e-12)
        g = out["guide"]
        assert snap["heat_land"][k] == pytest.approx(abs(g["friction"][k] * g["sliding_speed"][k]), rel=1e-12)
    assert np.all(snap["traction_coefficient"] <= 0.08) and np.any(snap["traction_coefficient"] > 0)


def test_the_hydrodynamic_land_carries_the_cage_in_oil():
    """bearing.cage.land_law = "hydrodynamic": the rig's cage rides on the film inside its clearance (both
    engines) and the land's friction is the film's shear, Petroff's η v_t 2πRL/C up to the eccentricity
    factor 1/√(1−ε²)."""
    from mbd.elements import HydrodynamicLand
    from scenarios.numerics.common import rig_problem
    prob = rig_problem(overrides={"bearing.cage.land_law": "hydrodynamic"})
    land = prob.model.element("guide").land
    assert isinstance(land, HydrodynamicLand)
    res = mbd.simulate(prob.model, prob.built.q0, prob.built.v0, 0.003, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False)
    assert res.engine == "compiled"
    g = mbd.System(prob.model).outputs(res.state.t, res.state.q, res.state.v, res.state.z)["guide"]
    C = prob.model.element("guide").clearance[0]
    R = prob.model.element("guide").land_radius[0]
    eps = g["eccentricity"][0] / C
    assert eps < 1.0 and g["force"][0] == 0.0                     # no solid contact: the film carries it
    petroff = land.eta * abs(g["sliding_speed"][0]) * 2 * np.pi * R * land.width / C
    assert petroff <= abs(g["friction"][0]) <= petroff / np.sqrt(1 - min(eps, 1 - land.min_film / C) ** 2) * (1 + 1e-9)


def _race_film(scene, state):
    """The film the runner records for every contact (components.results.schema's probes), at ``state``."""
    from components.results.schema import element_probes
    out = mbd.System(scene.model).outputs(state.t, state.q, state.v, state.z)
    return {p.element: p.evaluate(out[p.element]) for p in element_probes(scene)
            if p.element in ("race_inner", "race_outer")}


def test_the_film_of_every_contact_agrees_with_the_bearing_statistics(loaded_state):
    """Per contact (every roller of every bearing, both raceways): h_min, h_c and Λ = h_min/σ, NaN exactly
    where a roller carries no load; per bearing the thinnest of them is the statistics' film_thinnest."""
    sc, s = loaded_state
    lub = reference_dpgt(3, "forward").si().lubricant
    snap = _snapshot(sc, s, lub)
    film = _race_film(sc, s)
    b0 = sc.bearing
    nb, Z = len(snap["film_thinnest"]), b0.rollers
    for fam, o in film.items():
        assert o["film_min"].shape == o["film_central"].shape == o["film_lambda"].shape == (nb * Z,)
        np.testing.assert_array_equal(np.isnan(o["film_min"]), o["load"] <= 0.0)
        np.testing.assert_array_equal(o["film_lambda"], o["film_min"] / lub.roughness)
        loaded = o["load"] > 0
        assert np.all(o["film_central"][loaded] > o["film_min"][loaded])
    per_bearing = np.fmin(*(np.nanmin(film[f]["film_min"].reshape(nb, Z), axis=1) for f in film))
    np.testing.assert_array_equal(per_bearing, snap["film_thinnest"])
    # one contact by hand: the most loaded roller of bearing 0 on its bore (outer raceway)
    o = film["race_outer"]
    j = int(np.argmax(o["load"][:Z]))
    R = roller_contact_radius(b0.roller_diameter, b0.outer_raceway_radius, False)
    E = reduced_modulus(b0.elastic_modulus, b0.poisson_ratio, b0.elastic_modulus, b0.poisson_ratio)
    h, hc = line_contact_film(o["rolling_speed"][j], o["load"][j] / b0.roller_length, R, lub.oil_viscosity,
                              lub.pressure_viscosity, E)
    # the thermal reduction by hand: Murch & Wilson's 3.94/(3.94 + L^0.62), L = β η₀ u²/k
    phi = 3.94 / (3.94 + (lub.temperature_viscosity * lub.oil_viscosity * o["rolling_speed"][j] ** 2
                          / lub.thermal_conductivity) ** 0.62)
    assert o["film_min_isothermal"][j] == h and o["film_thermal_factor"][j] == pytest.approx(phi, rel=1e-14)
    assert (o["film_min"][j], o["film_central"][j]) == pytest.approx((phi * h, phi * hc), rel=1e-14)


def test_no_film_is_recorded_without_a_lubricant(loaded_state):
    from components.results.schema import element_probes
    sc, _ = loaded_state
    keys = {k for p in element_probes(dataclasses.replace(sc, lubricant=None)) for k in p.keys}
    assert "load" in keys and not {k for k in keys if k.startswith("film_")}


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """A 1 ms DPGT run (runner, reference oil): its results.nc and summary."""
    from scenarios.core.runner import RunConfig, run_case
    out = tmp_path_factory.mktemp("film_run")
    summary = run_case(reference_dpgt(3, "forward"), RunConfig(settle=0.0005, window=0.0005, progress=False), out)
    return out / "results.nc", summary


def test_results_file_records_the_film_of_every_contact(short_run):
    """results.nc: race_inner/race_outer.{film_min, film_central, film_lambda} per roller and sample, with
    units; the thinnest recorded film of each bearing type is the summary's film_min_m up to the sampling
    (the summary takes every step, the file samples at 25 kHz between them)."""
    import xarray as xr
    path, summary = short_run
    sigma = reference_dpgt(3, "forward").si().lubricant.roughness
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        for race in ("race_inner", "race_outer"):
            h, lam = ds[f"{race}.film_min"], ds[f"{race}.film_lambda"]
            assert h.dims == ds[f"{race}.load"].dims == ("time", f"{race}.instance")
            assert h.attrs["units"] == ds[f"{race}.film_central"].attrs["units"] == "m" and lam.attrs["units"] == "1"
            np.testing.assert_array_equal(np.isnan(h.values), ds[f"{race}.load"].values <= 0.0)
            np.testing.assert_allclose(lam.values, h.values / sigma, rtol=1e-15)
            phi = ds[f"{race}.film_thermal_factor"].values
            assert ds[f"{race}.film_thermal_factor"].attrs["units"] == "1"
            np.testing.assert_array_equal(np.isnan(phi), np.isnan(h.values))
            assert np.all((phi[~np.isnan(phi)] > 0.5) & (phi[~np.isnan(phi)] < 1.0))
        for kind in ("inner", "outer"):
            thinnest = min(float(ds[f"{r}.film_min"].where(ds[f"{r}.bearing_kind"] == kind).min())
                           for r in ("race_inner", "race_outer"))
            # 25 kHz samples against every step (≈ 1e-5 s) of a thinning film: measured 0.03 % and 0.6 % here
            assert thinnest == pytest.approx(summary[kind]["film_min_m"], rel=0.02)


def test_summary_has_the_isothermal_film_and_the_thermal_factor(short_run):
    """summary.json per bearing type: the isothermal film beside the thermal one, the largest thermal loading
    L and its factor φ_T(L) = 3.94/(3.94 + L^0.62); the thinnest film's L from the rollers' pure-rolling
    entraining speed at condition 3, ū = ω_rel R_i R_o'/(R_i + R_o') = 14.1 m/s (ω_rel the planet's speed on
    its pin: the loaded rollers roll; lightly loaded ones that slide have up to ≈ 15.5 m/s, so the largest L
    is higher); W' and h_c/h_min of Pan & Hamrock's fit, and its warning exactly when h_c < h_min."""
    _, summary = short_run
    si = reference_dpgt(3, "forward").si()
    lub, b, op = si.lubricant, si.bearing, si.operating
    Ri, Ro = 0.5 * (b.pitch_diameter - b.roller_diameter), 0.5 * (b.pitch_diameter + b.roller_diameter)
    for kind in ("inner", "outer"):
        d = summary[kind]
        w_rel = abs(getattr(op, f"{kind}_planet_speed") - op.carrier_speed)
        u = w_rel * Ri * Ro / (Ri + Ro)
        assert 13.5 < u < 14.5
        L = lub.temperature_viscosity * lub.oil_viscosity * u ** 2 / lub.thermal_conductivity
        assert d["film_min_thermal_loading"] == pytest.approx(L, rel=0.05)         # loaded rollers slip a little
        assert d["film_min_thermal_loading"] <= d["film_thermal_loading_max"] < 1.3 * L
        assert d["film_thermal_factor_min"] == pytest.approx(3.94 / (3.94 + d["film_thermal_loading_max"] ** 0.62),
                                                             rel=1e-14)
        assert 0.7 < d["film_thermal_factor_min"] < 0.78
        # the thinnest thermal film: each contact's isothermal film times its φ_T ≥ φ_T,min
        h, h_iso, phi = d["film_min_m"], d["film_min_isothermal_m"], d["film_thermal_factor_min"]
        assert phi * h_iso * (1 - 1e-12) <= h < h_iso
        # at the run's start the most loaded rollers carry ≈ 6–8 kN: W' ≈ 1.2–1.3e-3, where the fit crosses
        assert 0.95 < d["film_central_ratio_min"] < 1.2 and 5e-4 < d["film_load_parameter_max"] < 2e-3
    crossed = [k for k in ("inner", "outer") if summary[k]["film_central_ratio_min"] < 1.0]
    fit = [w for w in summary["warnings"] if "Pan & Hamrock" in w]
    assert len(fit) == (1 if crossed else 0) and all(f"{k} planet bearings" in fit[0] for k in crossed)


def test_murch_wilson_thermal_factor_against_the_formulas_own_numbers():
    """φ_T = 3.94/(3.94 + L^0.62) (Murch & Wilson 1975): 1 at L = 0; at L = 1 the exponent drops out,
    3.94/4.94; 3.94/(3.94 + 10^0.62) = 0.485898 at L = 10; ½ where L^0.62 = 3.94, L = 9.13015; and
    φ_T L^0.62 → 3.94 at large L. A slip of the coefficient (×2: 0.887 at L = 1) or of the exponent
    (0.64: 0.4744 at L = 10) fails here."""
    assert thermal_factor(0.0) == 1.0
    assert thermal_factor(1.0) == pytest.approx(0.797571, rel=1e-6)
    assert thermal_factor(10.0) == pytest.approx(0.485898, rel=1e-6)
    assert thermal_factor(9.13015) == pytest.approx(0.5, rel=1e-6)
    big = 1e12
    assert thermal_factor(big) * big ** 0.62 == pytest.approx(3.94, rel=1e-6)
    L = np.logspace(-4, 3, 50)
    assert np.all(np.diff(thermal_factor(L)) < 0)
    # L = β η₀ u²/k by hand: VG 68 at 60 °C, 14.1 m/s, 0.13 W/(m K)
    assert thermal_loading(14.1, 0.0241, 0.0384, 0.13) == pytest.approx(0.0384 * 0.0241 * 14.1 ** 2 / 0.13, rel=1e-15)
    assert thermal_loading(14.1, 0.0241, 0.0384, 0.13) == pytest.approx(1.41528, rel=1e-5)


def test_the_temperature_viscosity_coefficient_is_the_walther_lines_slope():
    """β = −(1/η) dη/dT of η = ρ(T) ν(T) against a central difference of the viscosity–temperature law
    itself (Walther's ν and the density), for every grade and several temperatures."""
    alpha = 7.2e-4
    for grade in OIL_GRADES.values():
        nu40, nu100 = (float(grade[k].value.split()[0]) * 1e-6 for k in ("viscosity_40", "viscosity_100"))
        for T in (293.15, 333.15, 363.15, 393.15):
            dT = 1e-3
            fd = -(np.log(walther_viscosity(nu40, nu100, T + dT)) - np.log(walther_viscosity(nu40, nu100, T - dT))) / (2 * dT)
            assert walther_slope(nu40, nu100, T) == pytest.approx(fd, rel=1e-7)
            eta = lambda t: dynamic_viscosity(nu40, nu100, 870.0, alpha, t)          # noqa: E731
            fd = -(np.log(eta(T + dT)) - np.log(eta(T - dT))) / (2 * dT)
            assert temperature_viscosity(nu40, nu100, alpha, T) == pytest.approx(fd, rel=1e-7)
    # VG 68 at 60 °C: β ≈ 0.038 1/K, of which the density's expansion is 7.4e-4
    b = temperature_viscosity(68e-6, 8.7e-6, alpha, 333.15)
    assert 0.037 < b < 0.040 and b - walther_slope(68e-6, 8.7e-6, 333.15) == pytest.approx(alpha / (1 - alpha * 45), rel=1e-12)


def test_the_oil_density_and_viscosity_are_taken_at_the_operating_temperature():
    """ρ(60 °C) = 870 (1 − 7.2e-4 × 45) = 841.812 kg/m³ by hand; the preset's α_ρ is API MPMS 11.1's for
    lubricating oils (α₆₀ = K₁/ρ₆₀ per °F, K₁ = 0.34878 kg/m³) at 870 kg/m³; the linear law stays within
    0.05 % of that standard's exp(−α ΔT (1 + 0.8 α ΔT)) at 60 °C; η = ρ(T) ν(T), 3.2 % below the value
    with the density at 15 °C."""
    lub_p = reference_dpgt(3, "forward").lubricant
    lub = lub_p.si()
    assert oil_density(870.0, 7.2e-4, 333.15) == pytest.approx(841.812, rel=1e-12)
    assert lub.thermal_expansion == pytest.approx(1.8 * 0.34878 / 870.0, rel=3e-3)
    a60, dF = 0.34878 / 870.0, 45.0 * 1.8
    api = 870.0 * np.exp(-a60 * dF * (1 + 0.8 * a60 * dF))
    assert oil_density(870.0, lub.thermal_expansion, 333.15) == pytest.approx(api, rel=5e-4)
    nu = walther_viscosity(lub.viscosity_40, lub.viscosity_100, lub.temperature)
    assert lub.oil_viscosity == pytest.approx(841.812 * nu, rel=1e-12)
    assert lub.oil_viscosity / (870.0 * nu) == pytest.approx(0.9676, rel=1e-12)
    for key in ("thermal_expansion", "thermal_conductivity", "oil_density"):
        assert lub_p.source(key).tag == "assumed" and lub_p.source(key).note
    assert lub_p.source("temperature_viscosity").tag == "derived"


@pytest.mark.parametrize("key, value, match", [
    ("lubricant.thermal_conductivity", "-0.1 W/(m*K)", r"lubricant.thermal_conductivity: .*> 0"),
    ("lubricant.thermal_conductivity", "0.13 W/m", r"lubricant.thermal_conductivity: expected a thermal conductivity"),
    ("lubricant.thermal_expansion", "0.02 1/K", r"lubricant.thermal_expansion: .*\[0, 0.01\) 1/K"),
    ("lubricant.thermal_expansion", "7e-4 1/Pa", r"lubricant.thermal_expansion: expected a coefficient per kelvin"),
    ("lubricant.temperature_viscosity", "0 1/K", r"lubricant.temperature_viscosity: .*> 0"),
])
def test_bad_thermal_oil_parameters_are_refused(key, value, match):
    with pytest.raises(ParameterError, match=match):
        with_overrides(reference_dpgt(3, "forward"), {key: value}).si()


def test_a_given_temperature_viscosity_coefficient_replaces_walther():
    """β given directly (1/K) is used as is; with a viscosity given directly β stays the grade's at the
    operating temperature, so L grows as η."""
    base = reference_dpgt(3, "forward")
    p = with_overrides(base, {"lubricant.temperature_viscosity": "0.02 1/K"})
    assert p.si().lubricant.temperature_viscosity == pytest.approx(0.02, rel=1e-15)
    assert p.lubricant.source("temperature_viscosity").tag == "user"
    q = with_overrides(base, {"lubricant.oil_viscosity": "50 mPa*s"}).si().lubricant
    assert q.temperature_viscosity == base.si().lubricant.temperature_viscosity


def test_pan_hamrock_crosses_its_own_films_at_heavy_load():
    """h_c/h_min = 1.705 G^(−0.098) W'^(−0.038) U^(−0.002) from the published exponents falls below 1 at
    W' = (1.705 G^(−0.098) U^(−0.002))^(1/0.038): ≈ 1.15e-3 for the reference oil (G = 5077) at U = 1.2e-10
    (condition 1). The run warns once, naming the bearing types, when its contacts get there."""
    from scenarios.core.runner import validity_warnings
    R, eta, alpha = 3e-3, 0.0241, 2.2e-8
    G, U = alpha * E_STEEL, 1.2e-10
    u = U * E_STEEL * R / eta
    W_cross = ((2.922 / 1.714) * G ** -0.098 * U ** -0.002) ** (1 / 0.038)
    assert 1.0e-3 < W_cross < 1.3e-3
    for W, above in ((0.99 * W_cross, True), (1.01 * W_cross, False)):
        h_min, h_c = line_contact_film(u, W * E_STEEL * R, R, eta, alpha, E_STEEL)
        assert (h_c > h_min) == above
    si = reference_dpgt(1, "reverse").si()
    ok = {"film_central_ratio_min": 1.02, "film_load_parameter_max": 8e-4}
    bad = {"film_central_ratio_min": 0.995, "film_load_parameter_max": 1.2e-3}
    assert validity_warnings(si, {"inner": ok, "outer": ok}) == []
    w = validity_warnings(si, {"inner": bad, "outer": {**bad, "film_central_ratio_min": 0.99}})
    assert len(w) == 1 and "Pan & Hamrock" in w[0] and "inner planet bearings" in w[0] and "outer" in w[0]
    assert "0.995" in w[0] and "0.0012" in w[0]


# ------------------------------------------------------------------------------- limiting shear with temperature
def _dyson_slope(t_c):
    """Dyson's pressure slope of τ_L = G∞/4, G∞ = 1.2 p/(2.52 + 0.024 t) − 1e8 Pa (t in °C; Zhou & Hoeprich 1991,
    eqs. 36–37): 0.25 × 1.2/(2.52 + 0.024 t), by hand."""
    return 0.3 / (2.52 + 0.024 * t_c)


def _ehl_law(**lubricant):
    from components.bearing import traction
    p = with_overrides(reference_dpgt(), {"bearing.traction_law": "ehl",
                                          **{f"lubricant.{k}": v for k, v in lubricant.items()}}).si()
    return traction(p.bearing, p.lubricant)


def test_dyson_limiting_shear_slope_against_dysons_formula():
    """With γ_L set to Dyson's value at the reference temperature (60 °C: 0.3/3.96), the law gives Dyson's slope at
    other temperatures: 0.3/3.48 = 0.08621 at 40 °C, 0.3/4.44 = 0.06757 at 80 °C (a value from the source's formula
    by hand), and the traction law the scene builds carries it; τ_L0 keeps its value."""
    assert _dyson_slope(40.0) == pytest.approx(0.086207, rel=1e-5)
    assert _dyson_slope(80.0) == pytest.approx(0.067568, rel=1e-5)
    ref = _dyson_slope(60.0)
    for t_c in (40.0, 80.0, 110.0):
        law = _ehl_law(limiting_shear_law="dyson", limiting_shear_slope=ref, temperature=f"{t_c} degC",
                       limiting_shear_reference_temperature="60 degC")
        assert law.gamma_L == pytest.approx(_dyson_slope(t_c), rel=1e-12)
        assert law.tau_L0 == 2e6
    # τ_L(p) = τ_L0 + γ_L p: Dyson's rise of the limiting shear between 1 and 2 GPa at 40 °C, 86.2 MPa
    law = _ehl_law(limiting_shear_law="dyson", limiting_shear_slope=ref, temperature="40 degC")
    assert law.gamma_L * 1e9 == pytest.approx(0.25 * (1.2 * 2e9 - 1.2 * 1e9) / 3.48, rel=1e-12)


def test_constant_limiting_shear_is_the_given_slope_at_every_temperature():
    """The default law leaves γ_L exactly as given (the reference machine unchanged); the dyson law at its reference
    temperature gives it back exactly, falls as the oil warms and rises as it cools."""
    for t in ("20 degC", "60 degC", "95 degC"):
        assert _ehl_law(temperature=t).gamma_L == 0.07
    assert _ehl_law(limiting_shear_law="dyson").gamma_L == 0.07
    warm, cold = (_ehl_law(limiting_shear_law="dyson", temperature=t).gamma_L for t in ("80 degC", "40 degC"))
    assert warm < 0.07 < cold
    # the relative slope at the reference temperature: −1/(T − T₀) = −1/165 K
    h = 1e-3
    slope = (_ehl_law(limiting_shear_law="dyson", temperature=f"{60 + h} degC").gamma_L
             - _ehl_law(limiting_shear_law="dyson", temperature=f"{60 - h} degC").gamma_L) / (2 * h)
    assert slope / 0.07 == pytest.approx(-1.0 / 165.0, rel=1e-6)


def test_dyson_pole_above_the_oil_temperature_is_refused():
    with pytest.raises(ParameterError, match="lubricant.limiting_shear_pole_temperature"):
        with_overrides(reference_dpgt(), {"lubricant.limiting_shear_law": "dyson",
                                          "lubricant.limiting_shear_pole_temperature": "70 degC"}).si()
    # the constant law never reads the pole
    with_overrides(reference_dpgt(), {"lubricant.limiting_shear_pole_temperature": "70 degC"}).si()
