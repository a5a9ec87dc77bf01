"""The statistics of a run (docs/model.md §13), in three layers and the observer that wires them:

* :mod:`.quantities` — the per-step quantities (pin reactions, roller loads and life terms, traction heat, film,
  pocket and guide forces, cage motion in the carrier frame, mesh flanks): pure functions of a block of states;
* :mod:`.accumulate` — their accumulators (time-weighted sums, extrema, windows, pocket impacts), one compiled
  loop over a block of steps;
* :mod:`.summaries` — the numbers of summary.json (loads, rollers, impacts, heat, film, lives, cage, meshes) from
  the accumulated sums;
* :mod:`.observer` — :class:`WindowStatistics`, the observer of the simulation loop, and the window's size.
"""
from .observer import WindowStatistics, cage_period, default_window
from .quantities import bearing_map, carrier_frame_motion, contact_film, pin_reactions, plan_of, radial_tangential

__all__ = ["WindowStatistics", "bearing_map", "cage_period", "carrier_frame_motion", "contact_film", "default_window",
           "pin_reactions", "plan_of", "radial_tangential"]
