"""The rollers' slip of the planet bearings by their angle about the pin, from a run's recording (results.nc): each
roller's spin against its pure-rolling spin (:func:`components.bearing.roller_slip_pct`) at every recorded sample, by
its angle about the pin in the carrier frame measured from the planet's radial direction (the line from the carrier's
centre through the pin, outward: 0° is where the planet's centrifugal load points, the same place on every planet),
with the share of the samples loaded on the pin (the load zone; the bore carries every roller's centrifugal load all
round). The slip in the load zone, out of it and at its entry are every run's statistics, taken on every step
(summary.json: :func:`components.statistics.summaries.roller_slip_summary`); this is the figure's view of them.

:func:`slip_series` reads the same recording against time — the cage's slip (``bearing.cage_slip``) and the rollers'
(``bearing.roller_slip``) out of the load zone and at its entry, in bins of time — for a run whose operating point
follows a schedule (a start-up, a torque drop: ``operating.schedule``), and :func:`transient_numbers` says from it
what a user asks of a transient: the peak, when the slip settles near its steady value, how fast it moves.

The recording samples the window uniformly in time (``--sample-rate``), so every sample weighs the same, as the
statistics weigh equal steps (:mod:`components.statistics`); the means here are of the recorded samples, not of
every step, and a run's window of whole cage revolutions relative to the carrier brings every roller through every
angle alike. Kinematics only: no model is evaluated.
"""
from __future__ import annotations

import numpy as np

from .bearing import roller_slip_pct
from .results.reader import json_attr

__all__ = ["ANGLE_BINS", "SKID_PCT", "roller_slip_zones", "slip_series", "transient_numbers", "SERIES", "ZONE_VARIABLES",
           "SERIES_VARIABLES"]

SKID_PCT = 5.0           # [assumed] a cage or roller slipping more than this below its rolling speed skids
ANGLE_BINS = 24          # angle bins of the roller slip about the pin (15° each: 12 rollers, two samples apart)

# the variables of results.nc each function reads (besides the coordinates): a caller reads only these
# (components.results.read_results(path, ZONE_VARIABLES))
ZONE_VARIABLES = ("motion.angular_velocity", "motion.position", "motion.angle", "race_inner.load", "race_inner.angle")
SERIES_VARIABLES = ("time", "bearing.cage_slip", "bearing.roller_slip", "race_inner.load", "race_inner.angle")


def roller_slip_zones(ds, b, bins: int = ANGLE_BINS) -> dict:
    """Per bearing type (``"inner"``, ``"outer"``: every planet's bearing of the type pooled) from ``ds``, a run's
    results.nc read (:func:`components.results.read_results`, :data:`ZONE_VARIABLES` enough) or its xarray Dataset,
    and the bearing ``b`` (its BearingSI), by angle about the pin from the planet's radial
    direction on the carrier, positive in the carrier's sense of rotation (``angle_deg``, the bins' centres): the mean
    roller slip [%] over the samples in each bin (``slip_by_angle_pct``) and the share of them loaded on the pin
    (``loaded_by_angle``)."""
    w = np.asarray(ds["motion.angular_velocity"], float)
    body = {str(n): i for i, n in enumerate(np.asarray(ds["motion.body"]))}
    w_c = w[:, body["carrier"]]
    load_i = np.asarray(ds["race_inner.load"], float)
    angle = np.asarray(ds["race_inner.angle"], float)
    pos = np.asarray(ds["motion.position"], float)
    theta_c = np.asarray(ds["motion.angle"], float)[:, body["carrier"]]
    edges = np.linspace(0.0, 2.0 * np.pi, bins + 1)
    pooled: dict[str, list] = {}
    for bm in json_attr(ds.attrs, "bearings"):
        if bm.get("type") != "rollers":
            continue
        lo, hi = bm["race_inner"]
        rollers = [body[r] for r in bm["rollers"]]
        slip = roller_slip_pct(b, w[:, rollers] - w_c[:, None], (w[:, body[bm["planet"]]] - w_c)[:, None])
        loaded = load_i[:, lo:hi] > 0.0
        # the pin's direction from the carrier's centre, in the carrier's axes (race_inner.angle's axes)
        r = pos[:, body[bm["planet"]]] - pos[:, body["carrier"]]
        phi = np.arctan2(r[:, 1], r[:, 0]) - theta_c
        pooled.setdefault(bm["kind"], []).append((slip, loaded, np.mod(angle[:, lo:hi] - phi[:, None], 2.0 * np.pi)))
    out = {}
    for kind, parts in pooled.items():
        slip, loaded, ang = (np.concatenate([p[k].ravel() for p in parts]) for k in range(3))
        which = np.clip(np.digitize(ang, edges) - 1, 0, bins - 1)
        count = np.bincount(which, minlength=bins)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[kind] = {
                "angle_deg": list(np.degrees(0.5 * (edges[:-1] + edges[1:]))),
                "slip_by_angle_pct": list(np.bincount(which, slip, bins) / count),
                "loaded_by_angle": list(np.bincount(which, loaded.astype(float), bins) / count)}
    return out


SERIES = ("cage", "unloaded", "entry")     # the slip series of slip_series: the cage, the rollers out of the zone, at entry


def _entries(loaded: np.ndarray, angle: np.ndarray, pitch: float) -> np.ndarray:
    """(samples, rollers) True at the last sample out of the load zone before a roller takes load, after at least
    one roller pitch ``pitch`` [rad] of its orbit about the pin out of it (docs/model.md §13.5: a contact that opens
    and closes again at the zone's edge is not an entry), from the loaded flags and the orbit angles."""
    unwrapped = np.unwrap(angle, axis=0)
    out = np.zeros_like(loaded)
    left = np.full(loaded.shape[1], np.nan)           # the orbit angle where each roller last left the zone
    for j in range(1, loaded.shape[0]):                 # over samples (not rollers): each roller's history
        leaving = loaded[j - 1] & ~loaded[j]
        left = np.where(leaving, unwrapped[j], left)
        entering = ~loaded[j - 1] & loaded[j]
        out[j - 1] = entering & (np.abs(unwrapped[j - 1] - left) >= pitch)
    return out


def slip_series(ds, bin_s: float) -> dict:
    """Per bearing type (``"inner"``, ``"outer"``: every planet's bearing of the type pooled) from ``ds``, a run's
    results.nc read (:func:`components.results.read_results`, :data:`SERIES_VARIABLES` enough) or its xarray
    Dataset: in bins of ``bin_s`` [s] from the recording's start, the bins' centres ``time_s``, the
    cage slip [%] (mean over the samples and bearings, ``cage``), the roller slip out of the load zone (mean over
    the samples and rollers not loaded on the pin, ``unloaded``) and at its entry (mean over the entries in the bin,
    ``entry``: the slip at the last sample before a roller takes load after a roller pitch of its orbit out of the
    zone, §13.5 at the recording's resolution); NaN where a bin has none. ``entries``: each entry's (time, slip)."""
    if not bin_s > 0:
        raise ValueError(f"bin_s must be > 0 s, got {bin_s!r}")
    t = np.asarray(ds["time"], float)
    cage = np.asarray(ds["bearing.cage_slip"], float)
    roller = np.asarray(ds["bearing.roller_slip"], float)
    load_i = np.asarray(ds["race_inner.load"], float)
    angle = np.asarray(ds["race_inner.angle"], float)
    roller_names = [str(x) for x in np.asarray(ds["bearing.roller_slip.instance"])]
    bearing_names = [str(x) for x in np.asarray(ds["bearing.cage_slip.instance"])]
    edges = t[0] + bin_s * np.arange(int(np.floor((t[-1] - t[0]) / bin_s + 1e-9)) + 2)
    which = np.clip(np.digitize(t, edges) - 1, 0, edges.size - 2)
    nb = edges.size - 1

    def binned(values, weights):
        w = np.bincount(np.repeat(which, values.shape[1]), weights.ravel().astype(float), nb)
        v = np.bincount(np.repeat(which, values.shape[1]), (np.nan_to_num(values) * weights).ravel(), nb)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(w > 0, v / np.where(w > 0, w, 1.0), np.nan)

    pooled: dict[str, list] = {}
    for bm in json_attr(ds.attrs, "bearings"):
        if bm.get("type") != "rollers":
            continue
        lo, hi = bm["race_inner"]
        cols = [roller_names.index(r) for r in bm["rollers"]]
        loaded = load_i[:, lo:hi] > 0.0
        entry = _entries(loaded, angle[:, lo:hi], 2.0 * np.pi / len(cols))
        pooled.setdefault(bm["kind"], []).append((cage[:, bearing_names.index(bm["name"])], roller[:, cols], loaded, entry))
    out = {}
    for kind, parts in pooled.items():
        c = np.column_stack([p[0] for p in parts])
        r = np.concatenate([p[1] for p in parts], axis=1)
        loaded = np.concatenate([p[2] for p in parts], axis=1)
        entry = np.concatenate([p[3] for p in parts], axis=1)
        ok = np.isfinite(r)
        rows, cols = np.nonzero(entry & ok)
        out[kind] = {"time_s": 0.5 * (edges[:-1] + edges[1:]),
                     "cage": binned(c, np.isfinite(c)),
                     "unloaded": binned(r, ~loaded & ok),
                     "entry": binned(r, entry & ok),
                     "entries": (t[rows], r[rows, cols])}
    return out


def transient_numbers(time_s, series, change_s: float, steady: float | None, within_pct: float,
                      floor_pct: float) -> dict:
    """What a user asks of one binned slip series (:func:`slip_series`) of a run whose operating point changes from
    ``change_s`` [s] on: ``before`` (mean of the bins before the change), ``peak`` (largest bin after it, with its
    time from the change ``peak_after_s``), ``final`` (mean of the last fifth of the bins), ``steady`` (the steady
    run's value, given) and ``settle_s``: the time from the change after which every bin lies within ``within_pct``
    % of the steady value (at least ``floor_pct`` slip points: a bin's mean scatters by about that), None if the last
    bin does not; ``t50_s``, ``t63_s``, ``t90_s``: the first time from the change at which the series has gone 50,
    63 (1 − 1/e: an exponential approach's time constant) and 90 % of the way from ``before`` to ``final``."""
    t = np.asarray(time_s, float)
    y = np.asarray(series, float)
    good = np.isfinite(y)
    pre, post = good & (t < change_s), good & (t >= change_s)
    tail = good & (t >= t[0] + 0.8 * (t[-1] - t[0]))
    before = float(np.mean(y[pre])) if pre.any() else None
    final = float(np.mean(y[tail])) if tail.any() else None
    out = {"before": before, "final": final, "steady": steady, "peak": None, "peak_after_s": None, "settle_s": None}
    if post.any():
        k = np.flatnonzero(post)[np.argmax(y[post])]
        out.update(peak=float(y[k]), peak_after_s=float(t[k] - change_s))
    if steady is not None and post.any():
        band = max(abs(steady) * within_pct / 100.0, floor_pct)
        tp, yp = t[post], y[post]
        outside = np.flatnonzero(np.abs(yp - steady) > band)
        if outside.size == 0:
            out["settle_s"] = float(tp[0] - change_s)
        elif outside[-1] < yp.size - 1:
            out["settle_s"] = float(tp[outside[-1] + 1] - change_s)
    for share in (50, 63, 90):
        key = f"t{share}_s"
        out[key] = None
        if before is None or final is None or final == before or not post.any():
            continue
        frac = (y[post] - before) / (final - before)
        reached = np.flatnonzero(frac >= share / 100.0)
        if reached.size:
            out[key] = float(t[post][reached[0]] - change_s)
    return out
