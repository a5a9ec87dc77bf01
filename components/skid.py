"""The rollers' slip of the planet bearings by their angle about the pin, from a run's recording (results.nc): each
roller's spin against its pure-rolling spin (:func:`components.bearing.roller_slip_pct`) at every recorded sample, by
its angle about the pin in the carrier frame measured from the planet's radial direction (the line from the carrier's
centre through the pin, outward: 0° is where the planet's centrifugal load points, the same place on every planet),
with the share of the samples loaded on the pin (the load zone; the bore carries every roller's centrifugal load all
round). The slip in the load zone, out of it and at its entry are every run's statistics, taken on every step
(summary.json: :func:`components.statistics.summaries.roller_slip_summary`); this is the figure's view of them.

The recording samples the window uniformly in time (``--sample-rate``), so every sample weighs the same, as the
statistics weigh equal steps (:mod:`components.statistics`); the means here are of the recorded samples, not of
every step, and a run's window of whole cage revolutions relative to the carrier brings every roller through every
angle alike. Kinematics only: no model is evaluated.
"""
from __future__ import annotations

import numpy as np

from .bearing import roller_slip_pct
from .results.reader import json_attr

__all__ = ["ANGLE_BINS", "SKID_PCT", "roller_slip_zones"]

SKID_PCT = 5.0           # [assumed] a cage or roller slipping more than this below its rolling speed skids
ANGLE_BINS = 24          # angle bins of the roller slip about the pin (15° each: 12 rollers, two samples apart)


def roller_slip_zones(ds, b, bins: int = ANGLE_BINS) -> dict:
    """Per bearing type (``"inner"``, ``"outer"``: every planet's bearing of the type pooled) from the dataset ``ds``
    of a run's results.nc and the bearing ``b`` (its BearingSI), by angle about the pin from the planet's radial
    direction on the carrier, positive in the carrier's sense of rotation (``angle_deg``, the bins' centres): the mean
    roller slip [%] over the samples in each bin (``slip_by_angle_pct``) and the share of them loaded on the pin
    (``loaded_by_angle``)."""
    w = np.asarray(ds["motion.angular_velocity"].values, float)
    body = {str(n): i for i, n in enumerate(ds["motion.body"].values)}
    w_c = w[:, body["carrier"]]
    load_i = np.asarray(ds["race_inner.load"].values, float)
    angle = np.asarray(ds["race_inner.angle"].values, float)
    pos = np.asarray(ds["motion.position"].values, float)
    theta_c = np.asarray(ds["motion.angle"].values, float)[:, body["carrier"]]
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
