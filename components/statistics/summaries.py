"""The numbers users read (summary.json, README), as functions of the accumulated sums (:class:`.accumulate.
Accumulators`: time means, RMS values, extrema over each window): per bearing kind its load, rollers, pocket
impacts, heat, film, lives and cage; per mesh type its flanks. Nothing here sees a state.

Bearing lives (:mod:`components.life` owns the laws): ISO 281's from the bearing load's equivalent
(mean P^(10/3)), and the ISO/TS 16281-style one from every roller's raceway loads, accumulated as
(Q/Q_c)^4.5 on the pin (stationary relative to the load) and (Q/Q_c)^4 on the bore (rotating).
"""
from __future__ import annotations

import math

import numpy as np

from mbd.elements.ehl import thermal_factor

from ..bearing import cage_slip_pct, entry_slide_roll
from ..sliced_bearing import ARCMIN, pressure_scales
from ..life import (LIFE_EXPONENT, ROTATING_EXPONENT, STATIONARY_EXPONENT, equivalent_load, hours, iso281_life,
                    iso281_rating, lundberg_palmgren_life, minimum_load, sliced_life, sliced_raceway_ratings)

__all__ = ["run_summary", "bearing_summary", "load_summary", "roller_summary", "impact_summary", "life_summary",
           "heat_summary", "film_summary", "cage_summary", "mesh_summary", "roller_slip_summary", "pin_summary"]


def run_summary(sums, p, ref_roller, w_rel: dict, loaded: bool, flank=None) -> dict:
    """The statistics users read (see README: summary.json): the windows, the drive's speed error, per bearing kind
    :func:`bearing_summary`, per mesh type :func:`mesh_summary`. ``sums``: the :class:`~.accumulate.Accumulators`
    (impacts closed); ``p``: the :class:`~.quantities.Plan`; ``ref_roller``: the (inner, outer) reference rollers;
    ``w_rel``: {kind: the planet's speed relative to its pin [rad/s]} (a life's revolutions); ``loaded``: does the
    train transmit torque? ``flank``: the drive flanks' :class:`~.accumulate.FlankPeaks` (None: no dynamic factor)."""
    out: dict = {"window_s": [sums.t0, sums.t1], "window_duration_s": sums.duration}
    if "carrier_speed_error" in sums.acc:
        # the time mean: a settled drive oscillates about its reference (mesh dynamics), an unsettled one is off
        out["carrier_speed_error_mean_pct"] = float(100.0 * sums.stats("carrier_speed_error")["mean"][0])
    for kind in ("inner", "outer"):
        out[kind] = bearing_summary(sums, p, kind, ref_roller, w_rel[kind])
    out["meshes"] = mesh_summary(sums, p, loaded, flank)
    return out


def bearing_summary(sums, p, kind: str, ref_roller, w_rel: float) -> dict:
    """Every statistic of the bearings of ``kind`` ("inner"/"outer"): pair 1's (the reference) and all of this
    kind (arguments as :func:`run_summary`'s); ``whole_revolutions`` says whether every window of this kind
    ended on its cage's whole revolutions (not given for windows of the nominal length)."""
    sel = np.flatnonzero(p.kinds == kind)
    ref = int(sel[0])
    d: dict = {"window_s": [sums.t0, float(sums.t0 + sums.window_length(ref))]}
    if sums.has_target:
        d["whole_revolutions"] = bool(not sums.open[sel].any())
    load_summary(d, sums, ref, sel)
    if p.rollers:
        roller_summary(d, sums, p, ref_roller[0 if kind == "inner" else 1], sel)
        if "roller_loaded" in sums.acc:
            roller_slip_summary(d, sums, p, sel)
        if "roller_inner_slice_max" in sums.acc:
            slice_summary(d, sums, p, ref, sel)
        heat_summary(d, sums, ref, sel)
        if p.lubricant is not None:
            film_summary(d, sums, sel)
    if "pin_slope" in sums.acc:
        pin_summary(d, sums, ref, sel)
    life_summary(d, sums, p, w_rel, ref, sel)
    if p.cage is not None:
        cage_summary(d, sums, p, ref, sel)
    d["life_L10_relative"] = None     # filled by a study relative to its forward run
    return d


def load_summary(d, sums, ref, sel) -> None:
    """The bearing load (pin reaction): its time-mean vector's length, components and maximum, per planet; the
    load sharing between the planets of this row (ISO 6336's K_γ: the most loaded over the mean); the ISO 281
    equivalent load (mean P^(10/3))^(3/10)."""
    lr, lt, lm = sums.stats("load_radial"), sums.stats("load_tangential"), sums.stats("load_magnitude")
    mean_vec = np.hypot(lr["mean"], lt["mean"])
    d["bearing_load_mean_N"] = float(mean_vec[ref])
    d["bearing_load_mean_all_N"] = float(mean_vec[sel].mean())
    d["bearing_load_mean_per_planet_N"] = [float(x) for x in mean_vec[sel]]
    d["load_sharing_factor"] = float(mean_vec[sel].max() / mean_vec[sel].mean())
    d["bearing_load_radial_mean_N"] = float(lr["mean"][ref])
    d["bearing_load_tangential_mean_N"] = float(lt["mean"][ref])
    d["bearing_load_max_N"] = float(lm["max"][ref])
    d["bearing_load_max_per_planet_N"] = [float(x) for x in lm["max"][sel]]
    d["equivalent_load_N"] = float(sums.stats("load_life")["mean"][ref] ** (1.0 / LIFE_EXPONENT))


def roller_summary(d, sums, p, r: int, sel) -> None:
    """Raceway and pocket forces of the reference roller ``r`` (RMS, max, mean) and, in ``all_rollers``, of every
    roller of the bearings ``sel``; the spread of the rollers' mean loads (0 over whole cage revolutions)."""
    mine = np.isin(p.roller_bearing, sel)
    al = {}
    for name, key in (("inner_race", "roller_inner_load"), ("outer_race", "roller_outer_load")):
        st = sums.stats(key)
        d[f"roller_{name}_rms_N"] = float(st["rms"][r])
        d[f"roller_{name}_max_N"] = float(st["max"][r])
        d[f"roller_{name}_mean_N"] = float(st["mean"][r])
        al[f"roller_{name}_rms_N"] = sums.aggregate_rms(key, sel)
        al[f"roller_{name}_max_N"] = float(st["max"][mine].max())
    mean_loads = sums.stats("roller_inner_load")["mean"][p.roller_bearing == p.roller_bearing[r]]
    d["roller_inner_race_mean_spread"] = float((mean_loads.max() - mean_loads.min()) / mean_loads.mean())
    if p.pocket_bearing is not None:
        st = sums.stats("pocket_force")
        pk = np.isin(p.pocket_bearing, sel)
        # pocket instances follow the rollers one to one
        d["roller_cage_rms_N"] = float(st["rms"][r])
        d["roller_cage_max_N"] = float(max(st["max"][r], -st["min"][r]))
        al["roller_cage_rms_N"] = sums.aggregate_rms("pocket_force", sel)
        al["roller_cage_max_N"] = float(max(st["max"][pk].max(), -st["min"][pk].min()))
        if sums.impact is not None:
            impact_summary(d, sums, pk, sel)
    d["all_rollers"] = al


def _finite(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def roller_slip_summary(d, sums, p, sel) -> None:
    """The rollers' slip (:func:`components.bearing.roller_slip_pct`) over every roller of the bearings ``sel``
    pooled, time-weighted over their windows: in the load zone (loaded on the pin) and out of it, the share of the
    time in it; at the load zone's entry (a roller unloaded at a step's start and loaded at its end) its slip at the
    last state out of it, the slide-to-roll ratio on the pin that means (:func:`components.bearing.entry_slide_roll`)
    and the frictional power density p·Δv of its pin contact at the first state in it, and the largest p·Δv of any
    roller contact in the windows (the smearing indicator: no published threshold is applied). None where there is
    nothing to average (no loaded time, no entry, no rolling speed)."""
    mine = np.isin(p.roller_bearing, sel)
    T = sums.time("roller_loaded")[mine].sum()
    L = sums.integral("roller_loaded")[mine].sum()
    zone = sums.integral("roller_slip_loaded")[mine].sum()
    free = sums.integral("roller_slip_unloaded")[mine].sum()
    d["roller_slip_load_zone_pct"] = _finite(zone / L) if L > 0 else None
    d["roller_slip_unloaded_pct"] = _finite(free / (T - L)) if T - L > 0 else None
    d["roller_loaded_share"] = float(L / T) if T > 0 else None
    n = int(sums.entry[0][mine].sum()) if sums.entry is not None else 0
    d["roller_entries"] = n
    s_e = _finite(sums.entry[1][mine].sum() / n) if n else None
    d["roller_slip_entry_pct"] = s_e
    d["roller_entry_slide_roll"] = float(entry_slide_roll(s_e)) if s_e is not None else None
    d["smearing_pv_entry_W_m2"] = _finite(sums.entry[2][mine].sum() / n) if n else None
    d["smearing_pv_max_W_m2"] = _finite(sums.stats("roller_pv")["max"][mine].max())


def slice_summary(d, sums, p, ref, sel) -> None:
    """The sliced contact's statistics (docs/model.md §8.8): the largest slice load of any roller of these bearings
    on the pin and on the bore, and the largest contact pressure (the pin's, the convex raceway); the edge ratio of
    the reference bearing, its largest end-slice pin pressure over its largest middle-slice one in the window
    (√ of the loads' ratio); the misalignment each bearing sees, its time mean (reference, per planet) and maximum;
    with explicit rows (bearing.rows > 1), each row's share of the reference bearing's mean pin load, row by row from
    the axial station −e_r/2 (``row_load_share``)."""
    mine = np.isin(p.roller_bearing, sel)
    own = p.roller_bearing == ref
    q_in, q_out = (float(sums.stats(k)["max"][mine].max()) for k in ("roller_inner_slice_max", "roller_outer_slice_max"))
    c_pin, c_bore = pressure_scales(p.bearing, p.bearing.slicing.slices)
    d["slice_load_max_pin_N"], d["slice_load_max_bore_N"] = q_in, q_out
    d["contact_pressure_max_Pa"] = float(max(c_pin * np.sqrt(q_in), c_bore * np.sqrt(q_out)))
    edge, mid = (float(sums.stats(k)["max"][own].max()) for k in ("roller_inner_edge_load", "roller_inner_mid_load"))
    d["edge_pressure_ratio"] = float(np.sqrt(edge / mid)) if mid > 0 else None
    if p.explicit_rows > 1:     # the reference bearing's rows: each row's share of its rollers' mean pin load
        m = sums.stats("roller_inner_load")["mean"]
        total = float(m[own].sum())
        d["row_load_share"] = [float(m[own & (p.roller_row == r)].sum() / total) if total > 0 else None
                               for r in range(p.explicit_rows)]
    mis = sums.stats("planet_misalignment")
    d["misalignment_mean_rad"] = float(mis["mean"][ref])
    d["misalignment_max_rad"] = float(mis["max"][ref])
    d["misalignment_mean_per_planet_rad"] = [float(x) for x in mis["mean"][sel]]


def pin_summary(d, sums, ref, sel) -> None:
    """The elastic pins' bending (``bearing.pin.model = "elastic"``, docs/model.md §8.8; :func:`.quantities.pin_bending`):
    the slope magnitude of the pin against its pinhole — the reference bearing's time mean and maximum, each planet's
    — in arcmin, and the reference pin's deflection at its bearing's centre, time mean and maximum. The slope the
    bearing itself sees (the pin's against its planet's) is ``misalignment_*_rad`` (:func:`slice_summary`)."""
    sl, de = sums.stats("pin_slope"), sums.stats("pin_deflection")
    d["pin_slope_mean_arcmin"] = float(sl["mean"][ref] / ARCMIN)
    d["pin_slope_max_arcmin"] = float(sl["max"][ref] / ARCMIN)
    d["pin_slope_mean_per_planet_arcmin"] = [float(x / ARCMIN) for x in sl["mean"][sel]]
    d["pin_slope_max_per_planet_arcmin"] = [float(x / ARCMIN) for x in sl["max"][sel]]
    d["pin_deflection_mean_m"] = float(de["mean"][ref])
    d["pin_deflection_max_m"] = float(de["max"][ref])


def impact_summary(d, sums, pk, sel) -> None:
    """Pocket impacts of the pockets ``pk`` (a mask) in the windows of the bearings ``sel``: their count over the
    bearings, per bearing and cage revolution relative to the carrier (the count over their revolutions summed;
    touches too), approach speed and peak force (max and mean)."""
    im = sums.impact
    count = im["count"][pk].sum()
    revs = sums.cage_revolutions(sel)
    d["pocket_impacts"] = int(count)
    d["pocket_impacts_per_rev"] = float(count / revs) if revs > 0 else None
    d["pocket_touches_per_rev"] = float(im["touches"][pk].sum() / revs) if revs > 0 else None
    d["pocket_impact_speed_max_m_s"] = float(im["speed_max"][pk].max())
    d["pocket_impact_speed_mean_m_s"] = float(im["speed_sum"][pk].sum() / count) if count else 0.0
    d["pocket_impact_peak_max_N"] = float(im["peak_max"][pk].max())
    d["pocket_impact_peak_mean_N"] = float(im["peak_sum"][pk].sum() / count) if count else 0.0


def life_summary(d, sums, p, w_rel, ref, sel) -> None:
    """ISO 281 L10 from the bearing load and the ISO/TS 16281-style L10 from the roller loads
    (:mod:`components.life`), in 10^6 revolutions of the planet relative to its pin and in hours at the
    nominal relative speed ``w_rel``: pair 1's bearing, in ``all_rollers`` every bearing of this kind pooled,
    and each planet's own."""
    b = p.bearing
    d["dynamic_load_rating_N"] = iso281_rating(b)
    # the catalogue minimum load and the mean bearing load against it (below 1: under the catalogue's minimum)
    d["minimum_load_N"] = minimum_load(b)
    d["load_over_minimum"] = d["bearing_load_mean_N"] / d["minimum_load_N"]
    d["load_over_minimum_per_planet"] = [x / d["minimum_load_N"] for x in d["bearing_load_mean_per_planet_N"]]
    cases = [(d, np.array([ref]))]
    if p.rollers:
        cases.append((d["all_rollers"], sel))
    # each planet's own bearing: the most loaded one's life is what unequal load sharing costs
    each = [({}, np.array([i])) for i in sel]
    for out, bearings in cases + each:
        P = float(np.mean(sums.stats("load_life")["mean"][bearings]) ** (1.0 / LIFE_EXPONENT))
        out["life_iso281_Mrev"] = iso281_life(P, b)
        out["life_iso281_h"] = hours(out["life_iso281_Mrev"], w_rel)
        if not p.rollers:
            continue
        mine = np.isin(p.roller_bearing, bearings)
        q_pin = p.qc[0] * float(equivalent_load(sums.stats("roller_inner_fatigue")["mean"][mine].mean(),
                                                STATIONARY_EXPONENT))
        q_bore = p.qc[1] * float(equivalent_load(sums.stats("roller_outer_fatigue")["mean"][mine].mean(),
                                                 ROTATING_EXPONENT))
        out["roller_equivalent_load_pin_N"], out["roller_equivalent_load_bore_N"] = q_pin, q_bore
        if p.explicit_rows > 1:    # every row its raceways' equivalent loads, the rows combined (life.py)
            q_pin, q_bore = (c * equivalent_load(np.array([sums.stats(key)["mean"][mine & (p.roller_row == r)].mean()
                                                           for r in range(p.explicit_rows)]), e)
                             for key, c, e in (("roller_inner_fatigue", p.qc[0], STATIONARY_EXPONENT),
                                               ("roller_outer_fatigue", p.qc[1], ROTATING_EXPONENT)))
            out["roller_equivalent_load_pin_per_row_N"] = q_pin.tolist()
            out["roller_equivalent_load_bore_per_row_N"] = q_bore.tolist()
        out["life_iso16281_Mrev"] = lundberg_palmgren_life(q_pin, q_bore, b)
        out["life_iso16281_h"] = hours(out["life_iso16281_Mrev"], w_rel)
        if "slice_inner_fatigue" in sums.acc:
            out["life_iso16281_sliced_Mrev"] = _sliced_life(sums, p, bearings)
            out["life_iso16281_sliced_h"] = hours(out["life_iso16281_sliced_Mrev"], w_rel)
    d["life_iso281_per_planet_h"] = [e["life_iso281_h"] for e, _ in each]
    if p.rollers:
        d["life_iso16281_per_planet_h"] = [e["life_iso16281_h"] for e, _ in each]
    if "slice_inner_fatigue" in sums.acc:
        d["life_iso16281_sliced_per_planet_h"] = [e["life_iso16281_sliced_h"] for e, _ in each]


def _sliced_life(sums, p, bearings) -> float | None:
    """ISO/TS 16281 life with slices of the bearings ``bearings`` [10^6 revolutions] (components.life.sliced_life):
    per slice, the equivalent loads of the pin and the bore over the window and over the bearings' rollers, as the
    roller loads' life takes them, q_e,k = q_c,k (mean (q_k/q_c,k)^e)^(1/e)."""
    b = p.bearing
    qc = sliced_raceway_ratings(b, p.slices)
    keys = (("slice_inner_fatigue", qc[0], STATIONARY_EXPONENT), ("slice_outer_fatigue", qc[1], ROTATING_EXPONENT))
    if p.explicit_rows > 1:       # per row (rows, n_s): the rows' raceways combined as the standard's (life.py)
        mine = np.isin(p.roller_bearing, bearings)
        q = [c * equivalent_load(np.stack([sums.stats(key)["mean"].reshape(-1, p.slices)[mine & (p.roller_row == r)]
                                           .mean(axis=0) for r in range(p.explicit_rows)]), e) for key, c, e in keys]
        return sliced_life(q[0], q[1], b)
    mine = np.isin(np.repeat(p.roller_bearing, p.slices), bearings)
    q = [c * equivalent_load(sums.stats(key)["mean"][mine].reshape(-1, p.slices).mean(axis=0), e)
         for key, c, e in keys]
    return sliced_life(q[0], q[1], b)


def equivalent_slice_loads(sums, p) -> tuple[np.ndarray, np.ndarray]:
    """(pin, bore) (n_bearings, rows, n_s): each bearing's equivalent slice loads per row over its window and the row's
    rollers, as its sliced life takes them (:func:`_sliced_life`), q_e,k = q_c,k (mean (q_k/q_c,k)^e)^(1/e), e 4.5 on the
    pin, 4 on the bore [N]."""
    qc = sliced_raceway_ratings(p.bearing, p.slices)
    nb, rows = p.planet.size, p.explicit_rows
    out = []
    for key, c, e in (("slice_inner_fatigue", qc[0], STATIONARY_EXPONENT), ("slice_outer_fatigue", qc[1], ROTATING_EXPONENT)):
        m = sums.stats(key)["mean"].reshape(nb, rows, -1, p.slices)            # rollers bearing by bearing, row by row
        out.append(c * equivalent_load(m.mean(axis=2), e))
    return out[0], out[1]


def heat_summary(d, sums, ref, sel) -> None:
    """Heat from traction and land friction (time means, W): the reference bearing's and the mean of its
    kind; the largest traction coefficient of a loaded contact."""
    for key, name in (("heat_traction", "traction"), ("heat_land", "land")):
        if key in sums.acc:
            m = sums.stats(key)["mean"]
            d[f"heat_{name}_W"] = float(m[ref])
            d[f"heat_{name}_all_W"] = float(m[sel].mean())
    d["traction_coefficient_max"] = float(sums.stats("traction_coefficient")["max"][sel].max())


def film_summary(d, sums, sel) -> None:
    """The thinnest EHL film of the bearings ``sel`` (every bearing of this kind): its smallest value in
    the window and its time mean (the worst bearing's), in metres and as Λ = h_min/σ; the smallest
    isothermal film; the largest thermal loading L at the thinnest film's contact, and of any loaded
    contact with its factor φ_T(L) (the smallest); the largest load parameter W' and the smallest h_c/h_min
    of Pan & Hamrock's fit."""
    h, lam = sums.stats("film_thinnest"), sums.stats("film_lambda")
    d["film_min_m"] = float(h["min"][sel].min())
    d["film_mean_m"] = float(h["mean"][sel].min())
    d["lambda_min"] = float(lam["min"][sel].min())
    d["lambda_mean"] = float(lam["mean"][sel].min())
    d["film_min_isothermal_m"] = float(sums.stats("film_thinnest_isothermal")["min"][sel].min())
    d["film_min_thermal_loading"] = float(sums.stats("film_thinnest_loading")["max"][sel].max())
    L = float(sums.stats("film_thermal_loading")["max"][sel].max())
    d["film_thermal_loading_max"] = L
    d["film_thermal_factor_min"] = float(thermal_factor(L))      # φ_T falls as L grows
    d["film_load_parameter_max"] = float(sums.stats("film_load_parameter")["max"][sel].max())
    d["film_central_ratio_min"] = float(sums.stats("film_central_ratio")["min"][sel].min())


def cage_summary(d, sums, p, ref, sel) -> None:
    """The cage's acceleration in the carrier frame (own and relative to its planet: RMS and largest magnitude
    of each component) of the reference bearing and, in ``all_cages``, RMS over every cage of this kind; its slip
    below the epicyclic speed (time-mean speeds) and revolutions; the guide-land force."""
    for view in ("", "rel_"):
        for comp in ("radial", "tangential", "magnitude"):
            st = sums.stats(f"cage_acc_{view}{comp}")
            d[f"cage_acc_{view}{comp}_rms_m_s2"] = float(st["rms"][ref])
            d[f"cage_acc_{view}{comp}_max_m_s2"] = float(max(st["max"][ref], -st["min"][ref]))
    for comp in ("x", "y"):
        d[f"cage_acc_{comp}_rms_m_s2"] = float(sums.stats(f"cage_acc_{comp}")["rms"][ref])
    # every cage of this bearing type: RMS over all their windows (steadier than one cage's)
    d["all_cages"] = {f"cage_acc_{view}{comp}_rms_m_s2": sums.aggregate_rms(f"cage_acc_{view}{comp}", sel)
                      for view in ("", "rel_") for comp in ("radial", "tangential", "magnitude")}
    slip = cage_slip_pct(p.bearing, sums.stats("cage_speed_rel")["mean"], sums.stats("planet_speed_rel")["mean"])
    d["cage_slip_pct"] = float(slip[ref])
    d["cage_slip_all_pct"] = float(slip[sel].mean())
    d["cage_revolutions"] = float(abs(sums.angle[ref]) / (2 * math.pi))
    if p.guide is not None:
        st = sums.stats("guide_force")
        d["cage_guide_rms_N"] = float(st["rms"][ref])
        d["cage_guide_max_N"] = float(st["max"][ref])
        d["cage_guide_mean_N"] = float(st["mean"][ref])
        d.setdefault("all_rollers", {})["cage_guide_rms_N"] = sums.aggregate_rms("guide_force", sel)
        d["all_cages"]["cage_guide_rms_N"] = d["all_rollers"]["cage_guide_rms_N"]


def mesh_summary(sums, p, loaded: bool, flank=None) -> dict:
    """Per mesh type, over all planet pairs: mean (average of the pairs) and max of each flank; the loaded
    transmission error's peak-to-peak (the drive flank's compression, max − min over the window); the drive flank's
    largest force over its mean in the window (``drive_flank_peak_over_mean``: it grows with the window, a record,
    not a factor); and the dynamic factor K_v as ISO 6336-1 means it — the dynamic over the nominal tooth load — from
    ``flank`` (:class:`~.accumulate.FlankPeaks`, whole carrier revolutions): ``dynamic_factor`` the mean over the
    mesh cycles of each cycle's peak drive-flank force, over the mean force, and ``dynamic_factor_p99`` the 99th
    percentile of the drive-flank force in time over its mean. Each the largest of the pairs and per pair; None
    when the train transmits no torque (``loaded`` false: no nominal load to scale)."""
    out = {}
    res = flank.results() if flank is not None and loaded else None
    for key in p.meshes:
        d = {"drive_flank": int(p.flanks.get(key, 1))}
        for flank_name in ("drive", "coast"):
            f, x = sums.stats(f"{key}_{flank_name}_force"), sums.stats(f"{key}_{flank_name}_deflection")
            d[f"{flank_name}_force_mean_N"] = float(f["mean"].mean())
            d[f"{flank_name}_force_max_N"] = float(f["max"].max())
            d[f"{flank_name}_deflection_mean_m"] = float(x["mean"].mean())
            d[f"{flank_name}_deflection_max_m"] = float(x["max"].max())
            d[f"{flank_name}_force_mean_per_pair_N"] = [float(y) for y in f["mean"]]
        f, x = sums.stats(f"{key}_drive_force"), sums.stats(f"{key}_drive_deflection")
        te = x["max"] - x["min"]
        d["te_peak_to_peak_m"] = float(te.max())
        d["te_peak_to_peak_per_pair_m"] = [float(y) for y in te]
        peak = f["max"] / np.where(loaded & (f["mean"] > 0), f["mean"], np.nan)
        _largest_and_pairs(d, "drive_flank_peak_over_mean", peak)
        r = res.get(f"{key}_drive_force") if res is not None else None
        mean = np.where(r["mean"] > 0, r["mean"], np.nan) if r is not None else None
        _largest_and_pairs(d, "dynamic_factor", r["cycle_peak_mean"] / mean if r is not None else None)
        _largest_and_pairs(d, "dynamic_factor_p99", r["percentile"] / mean if r is not None else None)
        if r is not None:
            d["dynamic_factor_window_s"] = [flank.t0, flank.t_end]
            d["dynamic_factor_carrier_revolutions"] = flank.revolutions
            d["dynamic_factor_mesh_cycles"] = int(np.min(r["cycles"]))
        out[key] = d
    return out


def _largest_and_pairs(d: dict, name: str, x) -> None:
    """d[name] the largest finite entry of ``x`` (per pair) or None, d[name + "_per_pair"] each (None where not
    finite; an infinite percentile, beyond the bins, is None too)."""
    if x is None:
        d[name], d[f"{name}_per_pair"] = None, None
        return
    x = np.asarray(x, float)
    ok = np.isfinite(x)
    d[name] = float(np.max(x[ok])) if ok.any() else None
    d[f"{name}_per_pair"] = [float(y) if np.isfinite(y) else None for y in x]
