"""Plots and offscreen animations of saved results (plain numpy arrays in, PNG/GIF/MP4 out).

viz reads results only: it never imports an integrator or mbd.simulate.  The matplotlib plots are
imported eagerly; the pyvista animations load VTK, so they are imported on first use.
"""
from __future__ import annotations

from .plots import (bar_chart, cage_orbit_picture, forward_reverse_headline, load_distribution, mode_shapes,
                    spectrum, time_histories, time_history_group, work_precision)
from .render_check import check_offscreen, require_offscreen

__all__ = ["time_histories", "time_history_group", "bar_chart", "forward_reverse_headline", "cage_orbit_picture",
           "spectrum", "work_precision", "load_distribution", "mode_shapes", "cage_orbit_animation", "train_animation",
           "check_offscreen", "require_offscreen"]

_LAZY = {"cage_orbit_animation", "train_animation"}


def __getattr__(name: str):
    if name in _LAZY:
        from . import animate  # deferred: pyvista/VTK only when an animation is made
        return getattr(animate, name)
    raise AttributeError(f"module 'viz' has no attribute {name!r}")
