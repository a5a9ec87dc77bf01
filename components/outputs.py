"""What the model outputs (docs/model.md §13), defined once.

Every derived quantity a user reads — a planet bearing's load (pin reaction), roller and cage forces,
each mesh flank's force and deflection, cage accelerations in the carrier frame (own, relative to the
planet, radial/tangential), cage slip, pocket impacts — and every statistic of them is taken by
:class:`WindowStatistics`, an observer of the one simulation loop (:func:`mbd.simulate`), in
:mod:`components.statistics`:

* :mod:`~components.statistics.quantities` — the per-step quantities, pure functions of a block of states;
* :mod:`~components.statistics.accumulate` — their accumulators, one compiled loop over a block of steps:
  on **every accepted integrator step**, never on recorded samples: means and RMS values are time-weighted
  (trapezoid over the steps), maxima are maxima over the steps, so neither depends on a recorder's sample rate;
* :mod:`~components.statistics.summaries` — the numbers of summary.json from the accumulated sums;
* :mod:`~components.statistics.observer` — :class:`WindowStatistics`, which wires them to the loop, over a
  **window** that the runner sizes with :func:`default_window` (whole revolutions of the slowest cage relative
  to the carrier: every roller passes the load zone equally often).

The **carrier frame** C turns at the nominal carrier speed (the pin and the load zone are fixed on the
carrier); *radial* is from the carrier axis through the planet's centre, *tangential* 90° ahead.

This module keeps the recorded histories of the bearings (:class:`BearingSeries`, for results.nc) and re-exports
the statistics' public names. The rig's accelerometer on the housing (docs/model.md §12) and its transfer paths
are in :mod:`components.sensor`. Element family names come from :mod:`components.families` (re-exported here).
"""
from __future__ import annotations

import numpy as np

import mbd

from .bearing import cage_slip_pct, roller_slip_pct
from .families import FAMILY, MESH_FAMILY
from .life import LIFE_EXPONENT, relative_life
# the words and units of summary keys: owned by the results module, re-exported here
from .results.summary import DIMENSIONLESS_KEYS, SUMMARY_WORDS, UNIT_SUFFIXES, unit_of_key
from .statistics import (WindowStatistics, bearing_map, cage_period, carrier_frame_motion, contact_film,
                         default_window, pin_reactions, plan_of, radial_tangential)

__all__ = ["FAMILY", "MESH_FAMILY", "BearingSeries", "LIFE_EXPONENT", "bearing_map", "default_window", "cage_period",
           "WindowStatistics", "carrier_frame_motion", "radial_tangential", "pin_reactions", "relative_life",
           "contact_film", "SUMMARY_WORDS", "UNIT_SUFFIXES", "DIMENSIONLESS_KEYS", "unit_of_key"]


class BearingSeries:
    """Each planet bearing's load (the pin reaction), its cage's slip and each roller's slip at every recorded
    sample, for results.nc (the statistics take every step; these are the histories to plot). The load is split as
    the statistics split it — radial from the carrier axis through the planet, tangential 90° ahead — the cage's slip
    is its speed below its epicyclic speed, both relative to the carrier, as ``cage_slip_pct``, and a roller's its
    spin below its pure-rolling spin, as ``roller_slip_pct`` (with ``race_inner.load`` > 0 it is in the load zone)."""

    def __init__(self, scene):
        self.plan = plan_of(scene, scene.model)        # the bodies and families, as the statistics index them
        bm = bearing_map(scene)
        self.names = tuple(b["name"] for b in bm)
        self.rollers = tuple(r for b in bm for r in b.get("rollers", ()))
        self._last = None          # (t, outputs, loads) of the last samples: radial and tangential share them

    def load(self, t, X, V, A, outputs) -> np.ndarray:
        """(radial, tangential) pin reaction per bearing [N]: (2, nb) at one sample (X (nb, 3), outputs (n,)), (2, S,
        nb) at S samples (X (S, nb, 3), outputs (S, n); each sample's pin reaction as one sample's, the same sums)."""
        last = self._last
        if last is not None and last[0] is t and last[1] is outputs:
            return last[2]
        p = self.plan
        X = np.asarray(X, float)
        if p.rollers:
            ri = outputs[FAMILY["race_inner"]]
            if X.ndim == 2:
                pin = pin_reactions(ri, slice(None), p.roller_bearing, p.planet.size, p.rows)
            else:       # sample by sample: a matrix product of all rows would sum in another order (round-off)
                fx, fy = np.asarray(ri["fx"], float), np.asarray(ri["fy"], float)
                pin = np.stack([pin_reactions({"fx": fx[n], "fy": fy[n]}, slice(None), p.roller_bearing, p.planet.size,
                                              p.rows) for n in range(fx.shape[0])])
        else:
            lin = outputs[FAMILY["linear"]]
            fx, fy = np.asarray(lin["fx"], float), np.asarray(lin["fy"], float)
            pin = -np.stack([fx[..., p.spring], fy[..., p.spring]], axis=-1)
        out = np.array(radial_tangential(pin, X[..., p.planet, :2], X[..., p.carrier, None, :2]))
        self._last = (t, outputs, out)
        return out

    def slip(self, t, X, V, A, outputs) -> np.ndarray:
        """Cage slip per bearing [%] (:func:`components.bearing.cage_slip_pct`) from the body speeds ``V`` (nb, 3), or
        at S samples (S, nb, 3)."""
        p = self.plan
        w_c = V[..., p.carrier, None, 2]
        return cage_slip_pct(p.bearing, V[..., p.cage, 2] - w_c, V[..., p.planet, 2] - w_c)

    def roller_slip(self, t, X, V, A, outputs) -> np.ndarray:
        """Roller slip per roller [%] (:func:`components.bearing.roller_slip_pct`) from the body speeds ``V`` (nb, 3),
        or at S samples (S, nb, 3)."""
        p = self.plan
        w_c = V[..., p.carrier, None, 2]
        return roller_slip_pct(p.bearing, V[..., p.roller_body, 2] - w_c, V[..., p.planet[p.roller_bearing], 2] - w_c)

    def probes(self) -> list:
        """The recorded series; each takes a block's samples at once (``batched``)."""
        where = "radial: from the carrier axis through the planet; tangential 90 deg ahead"
        out = [mbd.DerivedOutput("bearing.load_radial", lambda *a: self.load(*a)[0], "N",
                                 f"planet bearing load (pin reaction), radial component ({where})",
                                 instances=self.names, batched=True),
               mbd.DerivedOutput("bearing.load_tangential", lambda *a: self.load(*a)[1], "N",
                                 f"planet bearing load (pin reaction), tangential component ({where})",
                                 instances=self.names, batched=True)]
        if self.plan.cage is not None:
            out.append(mbd.DerivedOutput("bearing.cage_slip", self.slip, "percent",
                                         "cage speed below its epicyclic speed, relative to the carrier",
                                         instances=self.names, batched=True))
        if self.plan.rollers:
            out.append(mbd.DerivedOutput("bearing.roller_slip", self.roller_slip, "percent",
                                         "roller spin below its pure-rolling spin, relative to the carrier",
                                         instances=self.rollers, batched=True))
        return out
