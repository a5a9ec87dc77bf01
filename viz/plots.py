"""Shared matplotlib plots for the scenario reports.

Every function takes plain numpy arrays plus an output path (PNG), writes the figure and returns the
path as a :class:`pathlib.Path`.  Figures are made with ``matplotlib.figure.Figure`` and the Agg canvas
directly, so nothing here touches pyplot's global state or needs a display.

Conventions shared by all plots: forward rotation is a solid blue line, reverse a dashed orange line;
every axis carries a unit in square brackets ("[–]" for dimensionless quantities).
"""
from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib as mpl
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullLocator

from components.results import format_change, percent_change

__all__ = ["time_histories", "bar_chart", "spectrum", "work_precision", "load_distribution", "against_viscosity",
           "mode_shapes", "fault_spectra", "fault_loads", "FAULT_QUANTITIES", "gear_quality", "forward_reverse_headline",
           "time_history_group", "cage_orbit_picture", "display_unit", "format_pct", "HEADLINE_QUANTITIES", "FWD", "REV",
           "STYLE", "tolerance_distributions", "tolerance_against_torque", "tolerance_life_cdf", "damage_shares",
           "binned_series", "morris_heatmap", "sobol_heatmap", "life_against_misalignment",
           "slice_pressure_profiles", "slip_transients", "period_envelope", "sampling_repeat", "ENVELOPE_MIN_SAMPLES",
           "ENVELOPE_MAX_PERIODS"]

# One style for every figure, applied with rc_context so the caller's rcParams stay untouched.
STYLE = {
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.6,
    "legend.fontsize": 8,
    "legend.framealpha": 0.85,
    "lines.linewidth": 1.2,
    "savefig.dpi": 150,
    "figure.dpi": 100,
}
FWD = {"color": "#1f5fa8", "linestyle": "-", "label": "forward"}
REV = {"color": "#e07b00", "linestyle": "--", "label": "reverse"}
_MARK_COLOR = "#7a1f7a"


def _point_key(c):
    """Operating conditions 1-4 first, then a user's points by name."""
    return (isinstance(c, str), c)


def _point_words(c) -> str:
    return f"condition {c}" if isinstance(c, (int, np.integer)) else f"point {c}"


def _axis_label(name: str, unit: str | None) -> str:
    return f"{name} [{unit if unit else '–'}]"


def _save(fig: Figure, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(fig)
    dpi = mpl.rcParams["savefig.dpi"]
    layout = fig.get_layout_engine()
    if layout is not None and dpi != "figure":
        # laid out at the saved resolution, then the engine taken off: savefig with an engine on (even the
        # placeholder "none" leaves) draws the figure twice, a pass without rendering to lay it out, then the picture;
        # without one it draws once. The same pixels
        fig.set_dpi(dpi)
        layout.execute(fig)
        fig.set_layout_engine(None)
    # zlib level 3 instead of PIL's 6: the same pixels, 4-8 % larger files, 30-40 % less encoding time
    fig.savefig(path, format="png", dpi=dpi, pil_kwargs={"compress_level": 3})
    return path


def _time_scale(t: np.ndarray) -> tuple[float, str]:
    """Show short runs in ms: mesh periods are fractions of a millisecond."""
    span = float(np.nanmax(np.abs(t))) if t.size else 0.0
    return (1e3, "ms") if span < 2.0 else (1.0, "s")


def time_histories(t, series: Mapping[str, tuple], units: Mapping[str, str], path, *,
                   t_rev=None, title: str | None = None) -> Path:
    """Forward vs reverse overlays, one stacked subplot per series.

    t: (n,) times in s.  series: label -> (fwd, rev), each an (n,) array or None.  units: label -> unit
    string.  t_rev: times of the reverse run when it was sampled differently from the forward run.
    """
    t = np.asarray(t, float)
    tr = t if t_rev is None else np.asarray(t_rev, float)
    scale, tunit = _time_scale(np.concatenate([t, tr]))
    n = len(series)
    if n == 0:
        raise ValueError("series is empty")
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(7.0, 1.0 + 1.7 * n), layout="constrained")
        axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
        for ax, (label, pair) in zip(axes, series.items()):
            fwd, rev = pair
            if fwd is not None:
                ax.plot(t * scale, np.asarray(fwd, float), **FWD)
            if rev is not None:
                ax.plot(tr * scale, np.asarray(rev, float), **REV)
            ax.set_ylabel(_axis_label(label, units.get(label)))
            ax.legend(loc="upper right")
        axes[-1].set_xlabel(_axis_label("time", tunit))
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def bar_chart(conditions: Sequence[str], table: Mapping[str, Mapping[str, tuple]],
              units: Mapping[str, str], path, *, title: str | None = None,
              ylabels: Mapping[str, str] | None = None, ncols: int = 3) -> Path:
    """Grouped bars: one subplot per quantity (units differ), a forward/reverse pair per condition, the change of
    reverse against forward written over each pair; bars start at zero, forces in kN from 1 kN on.

    table: quantity -> {condition: (fwd, rev)}; a missing condition or a None value leaves a gap, and a
    direction with no value anywhere gets no legend entry.
    ylabels: optional quantity -> words for the y axis (default: the quantity, which is the panel title).
    ncols: panels per row (2 puts the inner and outer planet bearings of a quantity side by side).
    """
    conditions = list(conditions)
    if not table:
        raise ValueError("table is empty")
    x = np.arange(len(conditions))
    w = 0.38
    n = len(table)
    ncols = min(n, ncols)
    nrows = -(-n // ncols)
    present = set()
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.2 * ncols + 0.6, 2.8 * nrows + 0.6), layout="constrained")
        axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False).ravel())
        for ax, (quantity, by_cond) in zip(axes, table.items()):
            vals = np.full((len(conditions), 2), np.nan)
            for i, c in enumerate(conditions):
                pair = by_cond.get(c)
                if pair is not None:
                    vals[i] = [np.nan if v is None else float(v) for v in pair]
            scale, shown = display_unit(units.get(quantity), vals)
            for k, (d, st) in enumerate((("forward", FWD), ("reverse", REV))):
                if np.all(np.isnan(vals[:, k])):
                    continue
                present.add(d)
                ax.bar(x + (k - 0.5) * w, vals[:, k] * scale, w, color=st["color"], label=d,
                       hatch="//" if d == "reverse" else None, edgecolor="white", linewidth=0)
            top = float(np.nanmax(np.abs(vals))) * scale if np.any(np.isfinite(vals)) else 1.0
            for i in range(len(conditions)):
                p = _pct(*(None if np.isnan(v) else float(v) for v in vals[i]))
                if p is not None:
                    ax.text(x[i], 1.06 * float(np.nanmax(vals[i])) * scale, format_pct(p), ha="center", va="bottom",
                            fontsize=8, fontweight="bold", color="#333333", gid="pct_change")
            lo = min(0.0, float(np.nanmin(vals)) * scale) if np.any(np.isfinite(vals)) else 0.0
            ax.set_ylim(lo * 1.2, 1.25 * top if top > 0 else 1.0)
            ax.set_xticks(x, conditions, rotation=20 if len(conditions) > 3 else 0)
            ax.set_xlim(-0.7, len(conditions) - 0.3)
            ax.set_ylabel(_axis_label(_wrap((ylabels or {}).get(quantity, quantity), 26), shown))
            ax.set_title(quantity)
            ax.grid(axis="x", visible=False)
        for ax in axes[n:]:
            ax.set_visible(False)
        _direction_legend(fig, [d for d in ("forward", "reverse") if d in present], hatch=True)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


_MORE_COLORS = ("tab:green", "tab:purple", "tab:brown", "tab:gray", "tab:olive")


def spectrum(freq_hz, amplitude, marks: Mapping[str, float], path, fmax: float | None = None, *,
             quantity: str = "amplitude", unit: str = "a.u.", logy: bool = False,
             title: str | None = None, zoom: tuple[float, float] | None = None) -> Path:
    """Amplitude spectrum with characteristic frequencies marked (e.g. f_m, f_m ± k f_c).

    amplitude: (n,) array, or label -> (n,) array for overlays (forward/reverse).  marks: label ->
    frequency in Hz; marks above fmax are left out; labels are staggered so neighbours stay legible.
    zoom: (f_lo, f_hi) [Hz], a band of close marks (the side bands around f_m): a second panel shows it, its marks
    labelled there; the full panel shades the band and labels only the marks outside it.
    """
    f = np.asarray(freq_hz, float)
    curves = dict(amplitude) if isinstance(amplitude, Mapping) else {None: amplitude}
    fmax = float(np.nanmax(f)) if fmax is None else float(fmax)
    styles = [FWD, REV]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(7.5, 3.6 if zoom is None else 6.4), layout="constrained")
        axes = [fig.add_subplot()] if zoom is None else list(fig.subplots(2, 1, height_ratios=[1.0, 1.0]))
        spans = [(max(0.0, float(np.nanmin(f))), fmax)] + ([tuple(map(float, zoom))] if zoom is not None else [])
        for j, (ax, (lo, hi)) in enumerate(zip(axes, spans)):
            keep = (f >= lo) & (f <= hi)
            for i, (label, a) in enumerate(curves.items()):
                st = dict(styles[i % 2]) if label is not None else dict(FWD)
                st["linestyle"] = "-"
                st["label"] = label
                if i >= 2:       # beyond forward/reverse: colours of their own (the cycle would repeat theirs)
                    st["color"] = _MORE_COLORS[(i - 2) % len(_MORE_COLORS)]
                ax.plot(f[keep], np.asarray(a, float)[keep], **st)
            if logy:
                ax.set_yscale("log")
            ax.set_xlim(lo, hi)
            ax.set_xlabel(_axis_label("frequency", "Hz"))
            ax.set_ylabel(_axis_label(quantity, unit))
            if j == 0 and any(k is not None for k in curves):
                ax.legend(loc="best", fontsize=8, framealpha=0.9)
        if title:
            axes[0].set_title(title)
        if zoom is None:
            _mark_frequencies(fig, axes[0], marks, fmax)
        else:
            lo, hi = spans[1]
            axes[0].axvspan(lo, hi, color="0.85", alpha=0.6, lw=0, gid="zoom_band")
            outside = {k: v for k, v in marks.items() if not lo <= float(v) <= hi}
            _mark_frequencies(fig, axes[0], outside, fmax)
            _mark_frequencies(fig, axes[1], {k: v for k, v in marks.items() if lo <= float(v) <= hi}, hi)
            axes[1].set_title(f"zoom: {lo:.0f}–{hi:.0f} Hz (shaded above)", fontsize=9)
        return _save(fig, path)


def _mark_frequencies(fig: Figure, ax, marks: Mapping[str, float], fmax: float) -> None:
    """Dotted vertical lines with labels stacked in rows so that close marks (side bands) stay legible.

    Label widths are measured on a drawn canvas, then each label goes to the first row where it does
    not overlap the previous label of that row.
    """
    inside = sorted((float(v), str(k)) for k, v in marks.items() if 0 <= float(v) <= fmax)
    if not inside:
        return
    trans = ax.get_xaxis_transform()  # x in data, y in axes fraction
    texts = []
    for fv, label in inside:
        ax.axvline(fv, color=_MARK_COLOR, lw=0.8, ls=":", alpha=0.9)
        texts.append(ax.text(fv, 0.98, label, transform=trans, ha="center", va="top", fontsize=7,
                             color=_MARK_COLOR,
                             bbox={"boxstyle": "square,pad=0.15", "fc": "white", "ec": "none",
                                   "alpha": 0.8}))
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    row_h = 1.15 * max(tx.get_window_extent(renderer).height for tx in texts) / ax.bbox.height
    row_end: list[float] = []  # right edge (pixels) of the last label in each row
    for tx in texts:
        ext = tx.get_window_extent(renderer)
        pad = 2.0
        row = next((r for r, end in enumerate(row_end) if ext.x0 > end + pad), len(row_end))
        if row == len(row_end):
            row_end.append(ext.x1)
        else:
            row_end[row] = ext.x1
        tx.set_y(0.98 - row * row_h)


def work_precision(rows: Sequence[tuple], path, *, error_label: str = "error",
                   error_unit: str = "–", title: str | None = None) -> Path:
    """Log–log work-precision diagram: one line per method through its (wall time, error) points."""
    by_method: dict[str, list[tuple[float, float]]] = {}
    for method, wall, err in rows:
        by_method.setdefault(str(method), []).append((float(wall), float(err)))
    if not by_method:
        raise ValueError("rows is empty")
    markers = "osD^v<>p*h"
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(5.5, 4.2), layout="constrained")
        ax = fig.add_subplot()
        for i, (method, pts) in enumerate(by_method.items()):
            pts = np.array(sorted(pts))
            ax.loglog(pts[:, 0], pts[:, 1], marker=markers[i % len(markers)], label=method)
        ax.set_xlabel(_axis_label("wall time", "s"))
        ax.set_ylabel(_axis_label(error_label, error_unit))
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(loc="best")
        if title:
            ax.set_title(title)
        return _save(fig, path)


def load_distribution(angles_rad, loads_N, path, *, title: str | None = None, zero: str | None = None,
                      theory: tuple | None = None) -> Path:
    """Polar plot of roller loads at their angular positions: the angle in degrees (ticks every 30°), the load
    radially in kN from 1 kN on (:func:`display_unit`), its unit on the radial axis.

    loads_N: (Z,) array, or label -> (Z,) array (e.g. forward/reverse) sharing angles_rad. zero: what angle 0
    is (e.g. "the load-zone centre"), said in the title. theory: optional (label, angles [rad], loads [N]) drawn
    as open markers, e.g. the classical discrete-roller solution. Each roller is a stem from the centre plus a
    marker; the envelope is closed around the bearing. The radial labels sit opposite the loaded rollers, where
    they collide with nothing."""

    ang = np.asarray(angles_rad, float)
    curves = dict(loads_N) if isinstance(loads_N, Mapping) else {None: loads_N}
    every = [np.asarray(v, float) for v in curves.values()] + ([np.asarray(theory[2], float)] if theory else [])
    scale, unit = display_unit("N", np.concatenate(every))
    order = np.argsort(np.mod(ang, 2 * np.pi))
    styles = [FWD, REV]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(5.2, 5.6), layout="constrained")
        ax = fig.add_subplot(projection="polar")
        for i, (label, load) in enumerate(curves.items()):
            st = styles[i % 2]
            a = np.mod(ang, 2 * np.pi)[order]
            q = np.asarray(load, float)[order] * scale
            ax.vlines(a, 0.0, q, color=st["color"], lw=2.0, alpha=0.6)
            ax.plot(np.append(a, a[0]), np.append(q, q[0]), color=st["color"], ls=st["linestyle"],
                    marker="o", ms=3.5, label=label)
        if theory:
            ax.plot(np.mod(np.asarray(theory[1], float), 2 * np.pi), np.asarray(theory[2], float) * scale, ls="none",
                    marker="o", ms=8, mfc="none", mec="k", mew=0.9, label=theory[0])
        ax.set_thetagrids(np.arange(0, 360, 30), [f"{d}°" for d in range(0, 360, 30)])
        # a few round radial ticks, the outer circle one of them
        top = max(float(np.nanmax(np.concatenate(every))) * scale, 1e-12)
        ticks = MaxNLocator(4, steps=[1, 2, 2.5, 5, 10]).tick_values(0.0, top)
        ticks = ticks[: int(np.searchsorted(ticks, top - 1e-9 * top)) + 1]
        ax.set_rlim(0.0, ticks[-1])
        ax.set_rticks(ticks[1:])
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        # the radial labels opposite the loads' centre, between two angle grid lines, and the unit beyond them
        q_all = np.concatenate([np.asarray(v, float) for v in curves.values()])
        a_all = np.tile(ang, len(curves))
        centre = np.degrees(np.angle(np.sum(np.nan_to_num(q_all) * np.exp(1j * a_all)))) if np.any(q_all) else 0.0
        where = (round((centre + 180.0) / 30.0) * 30.0 + 15.0) % 360.0
        ax.set_rlabel_position(where)
        ax.text(np.radians(where), ticks[-1] * 1.25, f"roller load\n[{unit}]", ha="center", va="center",
                fontsize=8, gid="radial_unit")
        ax.set_xlabel(_axis_label("roller angle", "°"))
        if any(k is not None for k in curves) or theory:
            fig.legend(loc="outside lower center", ncols=2, frameon=False)
        ax.set_title("\n".join(t for t in (title, f"(0° = {zero})" if zero else None) if t), pad=14)
        return _save(fig, path)


def mode_shapes(freqs_hz, shapes, labels: Sequence[str], path, *, max_modes: int = 12,
                title: str | None = None, numbers: Sequence[int] | None = None) -> Path:
    """Bar chart of each mode shape (rows of `shapes`, one entry per coordinate in `labels`); ``numbers``: each
    mode's number as the caller's table counts it (default 1, 2, ...).

    Each shape is scaled to unit maximum magnitude, so the bars read as relative participation;
    pass comparable coordinates (e.g. rotations times a base radius) for that to be meaningful.
    """
    freqs = np.asarray(freqs_hz, float)
    shp = np.atleast_2d(np.asarray(shapes, float))
    if shp.shape != (freqs.size, len(labels)):
        raise ValueError(f"shapes must be (n_modes, n_coords) = ({freqs.size}, {len(labels)}), "
                         f"got {shp.shape}")
    n = min(freqs.size, max_modes)
    ncols = 1 if n < 3 else 2
    nrows = -(-n // ncols)
    x = np.arange(len(labels))
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(max(5.0, 0.28 * len(labels) + 1.5) * ncols, 1.9 * nrows + 0.6),
                     layout="constrained")
        axes = fig.subplots(nrows, ncols, squeeze=False).ravel()
        for i in range(n):
            ax = axes[i]
            s = shp[i]
            s = s / max(np.max(np.abs(s)), np.finfo(float).tiny)
            ax.bar(x, s, color=FWD["color"])
            ax.axhline(0.0, color="k", lw=0.6)
            ax.set_ylim(-1.1, 1.1)
            ax.set_title(f"mode {numbers[i] if numbers is not None else i + 1}: f = {freqs[i]:.4g} Hz")
            ax.set_xticks(x, labels, rotation=90, fontsize=7)
            ax.set_ylabel(_axis_label("amplitude", "–"))
            ax.set_xlabel(_axis_label("coordinate", "–"))
            ax.grid(axis="x", visible=False)
        for ax in axes[n:]:
            ax.set_visible(False)
        if freqs.size > n:       # say what is left out
            fig.text(0.5, 0.0, f"the first {n} of {freqs.size} modes shown", ha="center", va="bottom", fontsize=8)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def _plain_log(axis, decades: float = 2.0) -> None:
    """Tick labels of a log axis as plain numbers (0.3, 2, 40), not powers of ten; 1-2-3-5 ticks over a
    span of up to ``decades`` decades, one per decade beyond (they would crowd)."""
    lo, hi = axis.get_view_interval()
    wide = lo > 0 and hi / lo > 10.0 ** decades
    axis.set_major_locator(LogLocator(subs=(1.0,) if wide else (1.0, 2.0, 3.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(FuncFormatter(lambda v, _: ""))


_GROUP_MARKERS = "osD^vP"


def against_viscosity(series: Mapping[tuple, tuple], quantities: Sequence[tuple], path, *,
                      title: str | None = None, levels: Mapping[str, Mapping[float, str]] | None = None,
                      names: Mapping[str, float] | None = None,
                      xaxis: tuple = ("oil viscosity η", "mPa·s", 1e3)) -> Path:
    """Quantities against the oil's viscosity, forward vs reverse, one column per bearing type, one legend.

    series: (quantity key, bearing, direction[, group]) -> (viscosities [Pa·s], values [SI]); a group (e.g.
    "condition 3") is a line of its own with its own marker, named in the legend when there is more than one;
    quantities: (key, words, SI unit, log scale) — one row each, shown in a unit that suits the range (a film in
    µm); levels: quantity key -> {value: words}, dotted horizontal lines (e.g. the film regimes' bounds of Λ),
    each inside its panel with its words (below the line where there is no room above it); names: oil name ->
    its viscosity [Pa·s], written under the bottom row's ticks at the oils; xaxis: (words, unit, factor[, log]) of
    the abscissa, its SI values times the factor, on a log scale unless ``log`` is False (default the viscosity in
    mPa·s; another abscissa, e.g. a load ratio or an angle, the same way). Bearings, directions and groups are read from the series' keys."""

    bearings = sorted({k[1] for k in series})
    present = sorted({k[2] for k in series}, key=lambda d: {"forward": 0, "reverse": 1}.get(d, 2))
    groups = list(dict.fromkeys(k[3] if len(k) > 3 else None for k in series))
    marker = {g: _GROUP_MARKERS[i % len(_GROUP_MARKERS)] for i, g in enumerate(groups)}
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.4 * len(bearings) + 0.6, 2.5 * len(quantities) + 0.8), layout="constrained")
        axes = fig.subplots(len(quantities), len(bearings), squeeze=False, sharex=True)
        for r, (key, words, unit, log) in enumerate(quantities):
            ys = [v for k, (_, y) in series.items() if k[0] == key for v in y if v is not None]
            scale, shown = display_unit(unit, ys)
            for c, b in enumerate(bearings):
                ax = axes[r, c]
                for g in groups:
                    for d, style in (("forward", FWD), ("reverse", REV)):
                        k = (key, b, d) if g is None else (key, b, d, g)
                        if k in series:
                            x, y = series[k]
                            y = np.array([np.nan if v is None else v for v in y], float)
                            ax.plot(np.asarray(x) * xaxis[2], y * scale, marker=marker[g], ms=4.5, **style)
                if len(xaxis) < 4 or xaxis[3]:
                    ax.set_xscale("log")
                    _plain_log(ax.xaxis)
                if log:
                    ax.set_yscale("log")
                else:                 # from zero: auto-scaling would stretch a 0.1 % difference over the panel
                    _from_zero(ax)
                _levels(ax, {v * scale: words for v, words in (levels or {}).get(key, {}).items()})
                if log:
                    _plain_log(ax.yaxis)
                if r == 0:
                    ax.set_title(f"{b} planet bearings")
                ax.set_ylabel(_axis_label(_wrap(words, 24), shown))
                if r == len(quantities) - 1:
                    ax.set_xlabel(_axis_label(xaxis[0], xaxis[1]))
                    if names:
                        ax.set_xticks([1e3 * v for v in names.values()],
                                      [f"{1e3 * v:.3g}\n{n}" for n, v in names.items()])
                        ax.xaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
        handles = [Line2D([], [], color=st["color"], ls=st["linestyle"], label=d)
                   for d, st in (("forward", FWD), ("reverse", REV)) if d in present]
        if len(groups) > 1:
            handles += [Line2D([], [], color="0.3", ls="none", marker=marker[g], label=str(g)) for g in groups]
        if handles:
            fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 6), frameon=False)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def _levels(ax, levels: Mapping[float, str]) -> None:
    """Dotted horizontal lines at ``levels`` (value in the axis' unit -> words), each kept in view, its words
    inside the panel: above the line, or below it where the line runs near the panel's top."""
    if not levels:
        return
    lo, hi = ax.get_ylim()
    want_lo, want_hi = min(lo, *levels), max(hi, *levels)
    if ax.get_yscale() == "log":         # a margin of 4 % of the panel's height beyond a level at its edge
        span = np.log10(want_hi / want_lo)
        want_lo, want_hi = (want_lo / 10 ** (0.04 * span) if want_lo < lo else lo,
                            want_hi * 10 ** (0.04 * span) if want_hi > hi else hi)
    else:
        span = want_hi - want_lo
        want_lo, want_hi = (want_lo - 0.04 * span if want_lo < lo else lo, want_hi + 0.04 * span if want_hi > hi else hi)
    ax.set_ylim(want_lo, want_hi)
    to_axes = ax.transScale + ax.transLimits            # data -> axes fraction
    for value, words in levels.items():
        ax.axhline(value, color=_MARK_COLOR, lw=0.8, ls=":")
        frac = float(to_axes.transform((1.0, value))[1])
        top = frac > 0.85                                # no room above the line for its words
        ax.annotate(words, (0.02, frac), xycoords="axes fraction", xytext=(0, -2 if top else 2),
                    textcoords="offset points", fontsize=7, color=_MARK_COLOR, va="top" if top else "bottom",
                    gid="level")


def fault_spectra(panels: Sequence[tuple], path, *, quantity: str = "sensor acceleration",
                  unit: str = "m/s^2", title: str | None = None) -> Path:
    """One panel per damaged machine (its title): its spectrum against the perfect machine's, on a band around
    the mesh frequency, with its characteristic frequencies marked; one legend for the figure.

    panels: (title, freq_hz, amplitude, reference amplitude, marks {label: Hz}, (f_lo, f_hi))."""
    shown = display_unit(unit)[1]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(7.5, 2.4 * len(panels) + 0.9), layout="constrained")
        axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
        for ax, (name, f, amp, ref, marks, (lo, hi)) in zip(axes, panels):
            f = np.asarray(f, float)
            keep = (f >= lo) & (f <= hi)
            ax.plot(f[keep], np.asarray(ref, float)[keep], color="0.6", lw=1.0)
            ax.plot(f[keep], np.asarray(amp, float)[keep], color=FWD["color"], lw=1.0)
            ax.set_yscale("log")
            _plain_log(ax.yaxis)
            ax.set_xlim(lo, hi)
            ax.set_ylabel(_axis_label(_wrap(quantity, 22), shown))
            ax.set_title(name, loc="left", fontsize=9)
            _mark_frequencies(fig, ax, {k: v for k, v in marks.items() if lo <= v <= hi}, hi)
        axes[-1].set_xlabel(_axis_label("frequency", "Hz"))
        fig.legend(handles=[Line2D([], [], color="0.6", lw=1.0, label="perfect machine"),
                            Line2D([], [], color=FWD["color"], lw=1.0, label="damaged machine (panel title)")],
                   loc="outside lower center", ncols=2, frameon=False)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


FAULT_QUANTITIES = (
    ("load_sharing_factor", "load sharing K_γ − 1: most loaded over the mean", "%", "excess"),
    ("bearing_load_max_N", "largest bearing load", "N", None),
    ("life_relative", "life change against the perfect machine", "%", "excess"),
    ("cage_slip_pct", "cage slip", "%", None),
    ("pocket_impacts_per_rev", "pocket impacts", "per bearing and cage rev.", None))


def fault_loads(rows: Sequence[Mapping], path, *, quantities: Sequence[tuple] = FAULT_QUANTITIES,
                title: str | None = None) -> Path:
    """Bars per fault (forward solid, reverse hatched), one row per quantity, one column per bearing type, one
    legend naming the directions that ran. rows: dicts with "fault", "direction", "bearing" and the quantities'
    keys (None: not available). quantities: (key, words, unit, how); how "excess" shows a ratio r (K_γ, a life
    against the perfect machine's) as its excess over 1 in %, 100 (r − 1) — bars from zero then read as the
    change, where bars of ratios near 1 would all look alike."""
    faults = list(dict.fromkeys(r["fault"] for r in rows))
    bearings = sorted({r["bearing"] for r in rows})
    present = [d for d in ("forward", "reverse") if any(r["direction"] == d for r in rows)]
    x = np.arange(len(faults))
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.8 * len(bearings) + 0.6, 2.0 * len(quantities) + 1.2), layout="constrained")
        axes = fig.subplots(len(quantities), len(bearings), squeeze=False, sharex=True)
        for r, spec in enumerate(quantities):
            key, words, unit = spec[:3]
            how = spec[3] if len(spec) > 3 else None
            raw = [row.get(key) for row in rows if row.get(key) is not None]
            scale, shown = (100.0, "%") if how == "excess" else display_unit(unit, raw)
            for c, b in enumerate(bearings):
                ax = axes[r, c]
                for k, (d, st) in enumerate((("forward", FWD), ("reverse", REV))):
                    if d not in present:
                        continue
                    val = {row["fault"]: row.get(key) for row in rows if row["bearing"] == b and row["direction"] == d}
                    y = np.array([np.nan if val.get(f) is None else float(val[f]) for f in faults])
                    y = (y - 1.0) * scale if how == "excess" else y * scale
                    ax.bar(x + (k - 0.5) * 0.38, y, width=0.38, color=st["color"], label=d,
                           hatch="//" if d == "reverse" else None, edgecolor="white", linewidth=0)
                ax.axhline(0.0, color="k", lw=0.6)
                lo, hi = ax.get_ylim()
                ax.set_ylim(min(lo, 0.0), max(hi, 0.0))
                ax.set_ylabel(_axis_label(_wrap(words, 26), shown))
                ax.grid(axis="x", visible=False)
                if r == 0:
                    ax.set_title(f"{b} planet bearings")
        for ax in axes[-1]:
            ax.set_xticks(x, faults, rotation=30, ha="right")
        _direction_legend(fig, present, hatch=True)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def gear_quality(groups: Sequence[Mapping], path, *, quantities: Sequence[tuple] = (
        ("bearing_load_mean_N", "mean bearing load", "kN", 1e-3), ("bearing_load_max_N", "largest bearing load", "kN", 1e-3),
        ("roller_max_N", "largest roller load", "kN", 1e-3), ("life_iso16281_h", "roller-load life, pair 1", "h", 1.0)),
        meshes: Sequence[str] = ("sun_inner", "inner_outer", "outer_ring"), title: str | None = None) -> Path:
    """Per condition, perfect teeth against each tooth class (markers: the seeds' mean, bars: their range),
    forward filled and reverse open; one row per quantity and a column per bearing type, and a last row with
    the ring mesh's dynamic factor K_v and loaded transmission error p2p (the mesh the rig's sensor hears; the
    printed findings name the largest K_v of any mesh). ``groups``: rows of :func:`scenarios.gear_quality.by_grade`."""
    grades = [None] + sorted({g["grade"] for g in groups if g["grade"] is not None})
    conds = sorted({g["condition"] for g in groups}, key=lambda c: (isinstance(c, str), c))   # conditions, then points
    at = {(g["condition"], g["direction"], g["grade"], g["bearing"]): g for g in groups}
    colors = ["#222222", "#2b8a3e", "#1f5fa8", "#c2255c", "#e07b00", "#7a1f7a"]
    width = 0.8 / len(grades)

    def series(ax, key, bearing, scale, direction, k, g):
        x, y, lo, hi = [], [], [], []
        for i, c in enumerate(conds):
            r = at.get((c, direction, g, bearing))
            if r is None or r.get(key) is None:
                continue
            x.append(i + (k - (len(grades) - 1) / 2) * width + (0.2 if direction == "reverse" else -0.2) * width)
            y.append(scale * r[key])
            lo.append(scale * (r[key] - r[f"{key}_min"]))
            hi.append(scale * (r[f"{key}_max"] - r[key]))
        if not x:
            return
        label = ("perfect" if g is None else f"class {g}") if direction == "forward" else None
        ax.errorbar(x, y, yerr=[lo, hi], fmt="o" if direction == "forward" else "s", ms=4.5, capsize=2,
                    color=colors[k % len(colors)], mfc=colors[k % len(colors)] if direction == "forward" else "white",
                    label=label, lw=1.0)

    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(9.0, 2.2 * (len(quantities) + 1) + 0.8), layout="constrained")
        axes = fig.subplots(len(quantities) + 1, 2, squeeze=False, sharex=True)
        for r, (key, words, unit, scale) in enumerate(quantities):
            for col, b in enumerate(("inner", "outer")):
                ax = axes[r, col]
                for k, g in enumerate(grades):
                    for d in ("forward", "reverse"):
                        series(ax, key, b, scale, d, k, g)
                ax.set_ylabel(_axis_label(words, unit))
                if key.startswith("life"):            # lives span decades between conditions
                    ax.set_yscale("log")
                    _plain_log(ax.yaxis, decades=1.5)
                if r == 0:
                    ax.set_title(f"{b} planet bearings")
        for col, (prefix, words, unit, scale) in enumerate((("dynamic_factor", "K_v", None, 1.0),
                                                            ("te_p2p_um", "loaded TE p2p", "µm", 1.0))):
            ax = axes[-1, col]
            for k, g in enumerate(grades):
                for d in ("forward", "reverse"):
                    for key in meshes[-1:]:           # the ring mesh: the one the rig's sensor hears
                        series(ax, f"{prefix}_{key}", "outer", scale, d, k, g)
            ax.set_ylabel(_axis_label(words + ", ring mesh", unit))
            ax.set_title("ring mesh (outer planets–ring)")       # not a bearing column: say so
        for ax in axes[-1]:
            ax.set_xticks(range(len(conds)), [f"condition {c}" if isinstance(c, (int, np.integer)) else f"point {c}"
                                              for c in conds])
            ax.set_xlim(-0.55, len(conds) - 0.45)
        axes[0, 0].legend(loc="best", title="filled: forward, open: reverse", title_fontsize=7)
        for ax in axes.ravel():
            if ax.get_yscale() == "linear":      # from zero, with room above the highest marker
                _from_zero(ax)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def _suptitle(fig: Figure, title: str) -> None:
    """The figure's title, each of its lines wrapped to the figure's width (a long machine label stays readable)."""
    width = max(30, int(fig.get_figwidth() * 11.5))
    fig.suptitle("\n".join(_wrap(line, width) for line in str(title).split("\n")))


def _from_zero(ax) -> None:
    """A linear y axis that holds zero, with room beyond the farthest value: differences read against the values
    themselves (an auto-scaled axis stretches a 0.1 % difference over the panel's height)."""
    lo, hi = ax.get_ylim()
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    span = hi - lo
    ax.set_ylim(lo - (0.06 * span if lo < 0 else 0.0), hi + (0.06 * span if hi > 0 else 0.0))


# ----------------------------------------------------------------------------------------------
# the tolerance study: distributions over machines drawn from their tolerances

_CLASS_COLORS = ("#1f5fa8", "#c2255c", "#2b8a3e", "#e07b00", "#7a1f7a", "#222222")


def _ecdf(x) -> tuple[np.ndarray, np.ndarray]:
    """The empirical CDF as a post-step line: (values, share at or below), from 0 at the smallest value up a step
    per machine (empty for no finite value)."""
    x = np.sort(np.asarray([v for v in np.ravel(np.asarray(x, float)) if np.isfinite(v)]))
    if not x.size:
        return x, x
    return np.r_[x[0], x], np.r_[0.0, np.arange(1, x.size + 1) / x.size]


def _class_direction_legend(fig: Figure, classes: Sequence, directions: Sequence[str], extra=()) -> None:
    handles = [Line2D([], [], color=_CLASS_COLORS[i % len(_CLASS_COLORS)], lw=2, label=f"ISO 1328 class {c}")
               for i, c in enumerate(classes)]
    handles += [Line2D([], [], color="#444444", ls=(FWD if d == "forward" else REV)["linestyle"], label=d)
                for d in directions]
    # below the panels: above them it would collide with a suptitle
    fig.legend(handles=[*handles, *extra], loc="outside lower center", frameon=False,
               ncol=min(len(handles) + len(extra), max(2, int(fig.get_figwidth() / 2.4))))


def tolerance_distributions(dist: Mapping[tuple, Mapping[tuple, Sequence[float]]], path, *, table: float = 1.0,
                            title: str | None = None) -> Path:
    """The distribution of the mesh K_γ over the machines (empirical CDF, a step per machine): a panel per
    (condition, torque fraction), a colour per class, solid forward and dashed reverse; the rating tables' value
    and the P90 level dotted. ``dist``: {(condition, torque fraction): {(class, direction): K_γ values}}."""
    conds = sorted({k[0] for k in dist}, key=_point_key)
    torques = sorted({k[1] for k in dist})
    classes = sorted({c for v in dist.values() for c, _ in v})
    directions = [d for d in ("forward", "reverse") if any(dd == d for v in dist.values() for _, dd in v)]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(max(6.5, 3.4 * len(torques) + 0.6), 2.8 * len(conds) + 1.2), layout="constrained")
        axes = fig.subplots(len(conds), len(torques), squeeze=False, sharex=True, sharey=True)
        for r, c in enumerate(conds):
            for k, f in enumerate(torques):
                ax = axes[r, k]
                for (cl, d), x in sorted(dist.get((c, f), {}).items()):
                    xs, ys = _ecdf(x)
                    if xs.size:
                        ax.step(xs, ys, where="post", color=_CLASS_COLORS[classes.index(cl) % len(_CLASS_COLORS)],
                                ls=(FWD if d == "forward" else REV)["linestyle"], lw=1.3)
                ax.axvline(table, color=_MARK_COLOR, ls=":", lw=0.9)
                ax.axhline(0.9, color="#888888", ls=":", lw=0.8)
                ax.set_ylim(0.0, 1.02)
                ax.set_title(f"{_point_words(c)}, {f:g} × rated torque")
                ax.set_xlabel(_axis_label("mesh load sharing K_γ", None))
                if k == 0:
                    ax.set_ylabel(_axis_label("share of machines at or below", None))
        extra = [Line2D([], [], color=_MARK_COLOR, ls=":", label=f"rating tables, 3 planets ({table:g})"),
                 Line2D([], [], color="#888888", ls=":", label="P90 level")]
        _class_direction_legend(fig, classes, directions, extra)
        if title:
            fig.suptitle(_wrap(title, max(40, int(11 * fig.get_figwidth()))))
        return _save(fig, path)


def tolerance_against_torque(bands: Mapping[tuple, Mapping[int, Sequence[tuple]]], path, *, table: float = 1.0,
                             title: str | None = None) -> Path:
    """The mesh K_γ against the output torque: the machines' median (line and markers) and the band up to their
    P90 (shaded, its edge thin), a panel per (condition, direction), a colour per class. ``bands``:
    {(condition, direction): {class: [(output torque N·m, P50, P90), ...]}}."""
    conds = sorted({k[0] for k in bands}, key=_point_key)
    directions = [d for d in ("forward", "reverse") if any(k[1] == d for k in bands)]
    classes = sorted({c for v in bands.values() for c in v})
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(max(6.5, 4.2 * len(directions) + 0.6), 2.9 * len(conds) + 1.2), layout="constrained")
        axes = fig.subplots(len(conds), len(directions), squeeze=False, sharey=True)
        for r, c in enumerate(conds):
            for k, d in enumerate(directions):
                ax = axes[r, k]
                for cl, pts in sorted(bands.get((c, d), {}).items()):
                    pts = sorted((t, p50, p90) for t, p50, p90 in pts if p50 is not None and p90 is not None)
                    if not pts:
                        continue
                    t, p50, p90 = (np.array(v, float) for v in zip(*pts))
                    color = _CLASS_COLORS[classes.index(cl) % len(_CLASS_COLORS)]
                    ax.fill_between(t, p50, p90, color=color, alpha=0.18, lw=0)
                    ax.plot(t, p90, color=color, lw=0.8, marker="_", ms=9, mew=1.4)   # marked: one torque has no band
                    ax.plot(t, p50, color=color, lw=1.4, marker="o", ms=4)
                ax.axhline(table, color=_MARK_COLOR, ls=":", lw=0.9)
                ax.set_xlim(0.0, 1.06 * ax.get_xlim()[1])        # from zero torque, the last marker inside
                ax.set_title(f"{_point_words(c)}, {d}")
                ax.set_xlabel(_axis_label("output torque", "N·m"))
                if k == 0:
                    ax.set_ylabel(_axis_label("mesh load sharing K_γ", None))
        extra = [Line2D([], [], color="#444444", lw=1.4, marker="o", ms=4, label="median (P50)"),
                 Line2D([], [], color="#444444", lw=0.8, marker="_", ms=9, mew=1.4, label="P90 (band: P50–P90)"),
                 Line2D([], [], color=_MARK_COLOR, ls=":", label=f"rating tables, 3 planets ({table:g})")]
        handles = [Line2D([], [], color=_CLASS_COLORS[i % len(_CLASS_COLORS)], lw=2, label=f"ISO 1328 class {c}")
                   for i, c in enumerate(classes)]
        fig.legend(handles=[*handles, *extra], loc="outside lower center", frameon=False,
                   ncol=min(len(handles) + 3, max(2, int(fig.get_figwidth() / 2.4))))
        if title:
            fig.suptitle(_wrap(title, max(40, int(11 * fig.get_figwidth()))))
        return _save(fig, path)


def tolerance_life_cdf(cdfs: Mapping[tuple, Mapping[tuple, tuple]], path, *, title: str | None = None) -> Path:
    """The weakest planet bearing's L10 life over the machines (empirical CDF, log hours) against the perfect
    machine's (a dotted vertical line per direction, black forward, grey reverse): a row per (condition, bearing
    type), a column per life standard, a colour per class. ``cdfs``: {(condition, bearing type, standard):
    {(class, direction): (lives in h, the perfect machine's life in h)}}."""
    rows = sorted({(k[0], k[1]) for k in cdfs}, key=lambda r: (_point_key(r[0]), r[1]))
    stds = sorted({k[2] for k in cdfs}, key=lambda s: "16281" in s)
    classes = sorted({c for v in cdfs.values() for c, _ in v})
    directions = [d for d in ("forward", "reverse") if any(dd == d for v in cdfs.values() for _, dd in v)]
    nominal_color = {"forward": "#000000", "reverse": "#888888"}
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(max(6.5, 4.2 * len(stds) + 0.6), 2.6 * len(rows) + 1.2), layout="constrained")
        axes = fig.subplots(len(rows), len(stds), squeeze=False, sharey=True)
        for r, (c, kind) in enumerate(rows):
            for k, std in enumerate(stds):
                ax = axes[r, k]
                nominal = {}
                for (cl, d), (x, nom) in sorted(cdfs.get((c, kind, std), {}).items()):
                    xs, ys = _ecdf(x)
                    if xs.size:
                        ax.step(xs, ys, where="post", color=_CLASS_COLORS[classes.index(cl) % len(_CLASS_COLORS)],
                                ls=(FWD if d == "forward" else REV)["linestyle"], lw=1.3)
                    if nom:
                        nominal[d] = nom
                for d, nom in nominal.items():
                    ax.axvline(nom, color=nominal_color[d], ls=":", lw=1.0)
                ax.set_xscale("log")
                _plain_log(ax.xaxis, decades=1.0)
                ax.axhline(0.1, color="#888888", ls=":", lw=0.6)
                ax.set_ylim(0.0, 1.02)
                ax.set_title(f"{_point_words(c)}, {kind} planet bearings, {std}")
                ax.set_xlabel(_axis_label("L10 life of the weakest bearing", "h"))
                if k == 0:
                    ax.set_ylabel(_axis_label("share of machines at or below", None))
        extra = [Line2D([], [], color=nominal_color[d], ls=":", label=f"perfect machine, {d}") for d in directions]
        extra.append(Line2D([], [], color="#888888", ls=":", lw=0.6, label="P10 level"))
        _class_direction_legend(fig, classes, directions, extra)
        if title:
            fig.suptitle(_wrap(title, max(40, int(11 * fig.get_figwidth()))))
        return _save(fig, path)


# ----------------------------------------------------------------------------------------------
# display units: data stay SI, figures show a unit that suits the range

_PRETTY = {"m/s^2": "m/s²", "rad/s^2": "rad/s²", "percent": "%", "1": "–", "": "–", "N m": "N·m"}


def display_unit(unit: str | None, values=()) -> tuple[float, str]:
    """(factor, unit) to show SI ``values`` of ``unit`` with: forces in kN from 1 kN on, lengths in µm or mm,
    times in ms below 2 s, exponents written as superscripts. Multiply the data by the factor."""
    unit = unit or ""
    v = np.ravel(np.asarray(values, dtype=float))
    v = v[np.isfinite(v)]
    big = float(np.max(np.abs(v))) if v.size else 0.0
    if unit == "N":
        return (1e-3, "kN") if big >= 1e3 else (1.0, "N")
    if unit == "m":
        if big < 1e-3:
            return 1e6, "µm"
        return (1e3, "mm") if big < 1.0 else (1.0, "m")
    if unit == "s":
        return (1e3, "ms") if big < 2.0 else (1.0, "s")
    return 1.0, _PRETTY.get(unit, unit)


def _wrap(text: str, width: int) -> str:
    return "\n".join(textwrap.wrap(text, width, break_long_words=False)) or text


def _pct(fwd, rev) -> float | None:
    """The change of reverse against forward in % (None when either is missing, forward is 0 or the sign changes:
    :func:`components.results.percent_change`)."""
    return percent_change(fwd, rev)


def format_pct(p: float) -> str:
    """The change ``p`` [%] as every figure and table writes it: '+40 %', '−24 %', '+3.2 %', '−99.6 %', '×665'
    (the rule: :func:`components.results.format_change`)."""
    return format_change(p)


def _direction_legend(fig: Figure, present: Sequence[str], *, hatch: bool = False) -> None:
    """One legend for the whole figure, above the panels, naming only the directions that were drawn."""
    handles = []
    for d, st in (("forward", FWD), ("reverse", REV)):
        if d in present:
            handles.append(Patch(facecolor=st["color"], hatch="//" if (hatch and d == "reverse") else None,
                                 edgecolor="white" if hatch else st["color"], label=d) if hatch
                           else Line2D([], [], color=st["color"], ls=st["linestyle"], label=d))
    if handles:      # below the panels: above them it would collide with a suptitle
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), frameon=False)


HEADLINE_QUANTITIES = (("bearing_load_mean_N", "mean bearing load", "N"),
                       ("life_iso281_h", "L10 life, ISO 281", "h"),
                       ("life_iso16281_h", "L10 life, from the roller loads", "h"))


LOG_UNITS = ("h",)       # quantities on a log axis in the headline: lives, which span decades between bearings
_FILL = 0.72             # the tallest bar's top, as a share of its panel's height: room for its label and the change


def forward_reverse_headline(values: Mapping[tuple, float | None], path, *,
                             quantities: Sequence[tuple] = HEADLINE_QUANTITIES, bearings: Sequence[str] = ("inner", "outer"),
                             title: str | None = None) -> Path:
    """The study's headline: per condition (a row) and quantity (a column), each bearing type's forward and
    reverse bar with its value, and the change of reverse against forward written at the top of the panel above the
    pair (:func:`format_pct`: '−99.6 %', '×665').

    values: (quantity key, condition, bearing, direction) -> value in SI units (None or absent: no such run).
    quantities: (key, words, SI unit). Lives (a unit of :data:`LOG_UNITS`) are drawn on a log axis, as bearing
    engineers read them: 35 h beside 60 000 h stays a bar, the axis holding the shortest and the longest life with
    at least 0.3 decades below the shortest; other quantities on a linear axis from zero, forces in kN from 1 kN on.
    Each value is written over its bar with three significant digits (no powers of ten), the forward value ending
    and the reverse value starting at the pair's centre, so that the two never overlap whatever their heights."""
    conds = sorted({k[1] for k in values}, key=lambda c: (isinstance(c, str), c))   # conditions 1-4, then points
    if not conds:
        raise ValueError("values is empty")
    present = [d for d in ("forward", "reverse")
               if any(k[3] == d and v is not None and np.isfinite(v) for k, v in values.items())]
    x = np.arange(len(bearings))
    w = 0.36
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(2.9 * len(quantities) + 0.4, 2.5 * len(conds) + 0.7), layout="constrained")
        axes = fig.subplots(len(conds), len(quantities), squeeze=False)
        for c_i, c in enumerate(conds):
            for q_i, (key, words, unit) in enumerate(quantities):
                ax = axes[c_i, q_i]
                scale, shown = display_unit(unit, [v for k, v in values.items() if k[0] == key and v is not None])
                ys = {d: np.array([np.nan if values.get((key, c, b, d)) is None else float(values[(key, c, b, d)])
                                   for b in bearings]) * scale for d in ("forward", "reverse")}
                drawn = np.concatenate(list(ys.values()))
                drawn = drawn[np.isfinite(drawn)]
                log = unit in LOG_UNITS and drawn.size > 0 and bool(np.all(drawn > 0))
                top = float(drawn.max()) if drawn.size else 0.0
                if log:
                    ax.set_yscale("log")
                    base = 10.0 ** np.floor(np.log10(float(drawn.min())) - 0.3)
                    ax.set_ylim(base, base * (top / base) ** (1.0 / _FILL))
                else:
                    base = 0.0
                    ax.set_ylim(min(0.0, float(drawn.min()) / _FILL) if drawn.size else 0.0,
                                top / _FILL if top > 0 else 1.0)
                for k, (d, st) in enumerate((("forward", FWD), ("reverse", REV))):
                    y = ys[d]
                    if np.all(np.isnan(y)):
                        continue
                    ax.bar(x + (k - 0.5) * w, y - base, w, bottom=base, color=st["color"], label=d,
                           hatch="//" if d == "reverse" else None, edgecolor="white", linewidth=0)
                    for i, v in enumerate(y):
                        if np.isfinite(v):
                            ax.annotate(_value_text(v), (x[i], v), xytext=(-1.5 if k == 0 else 1.5, 1.5),
                                        textcoords="offset points", ha="right" if k == 0 else "left", va="bottom",
                                        fontsize=7, gid="value_label")
                for i, b in enumerate(bearings):
                    p = _pct(values.get((key, c, b, "forward")), values.get((key, c, b, "reverse")))
                    if p is not None:
                        ax.text(x[i], 0.97, format_pct(p), transform=ax.get_xaxis_transform(), ha="center",
                                va="top", fontsize=8.5, fontweight="bold", color="#333333", gid="pct_change")
                if log:
                    # a tick per decade (1-2-5 where the axis spans less than two: one decade would leave it one
                    # tick) and no minor ones: the values are written on the bars, and each minor tick is an artist
                    # the layout measures (a third of the figure's time)
                    lo, hi = ax.get_ylim()
                    ax.yaxis.set_major_locator(LogLocator(subs=(1.0,) if hi / lo > 100.0 else (1.0, 2.0, 5.0)))
                    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: _value_text(v)))
                    ax.yaxis.set_minor_locator(NullLocator())
                ax.set_xticks(x, [f"{b} planet\nbearing" for b in bearings])
                ax.set_xlim(-0.6, len(bearings) - 0.4)
                ax.grid(axis="x", visible=False)
                ax.set_ylabel(_axis_label(_wrap(words, 24), shown))
                where = f"condition {c}" if isinstance(c, (int, np.integer)) else f"point {c}"
                ax.set_title(where if len(conds) > 1 else words, fontsize=9)
        _direction_legend(fig, present, hatch=True)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def _value_text(v: float) -> str:
    """A value as a bar's label or a log axis' tick: three significant digits without a power of ten, thousands
    grouped by a narrow space ('35.3', '1 860', '50 700', '0.978')."""
    v = float(v)
    if v == 0.0 or not np.isfinite(v):
        return f"{v:g}"
    v = float(f"{v:.3g}")                    # rounded first: 999.6 is 1 000, not 1e+03
    mag = int(np.floor(np.log10(abs(v))))
    if mag < 3:
        return f"{v:.3g}"
    if mag >= 6:                             # millions: '12.3 M' stays as wide as '12 300'
        return f"{v / 1e6:.3g}\u202fM"
    return f"{round(v, 2 - mag):,.0f}".replace(",", "\u202f")


def time_history_group(rows: Sequence[tuple], path, *, columns: Sequence[str], title: str | None = None,
                       column_titles: Mapping[str, str] | None = None, separate_runs: bool = False,
                       envelope: float | None = None, envelope_words: str = "period") -> Path:
    """A readable group of time histories: one row per quantity, one column per part (e.g. the inner and the
    outer planet bearing), every panel on one time axis in ms, rows sharing their y scale, one legend.

    rows: (words, SI unit, {column: {run: (t [s], y [SI])}}); a run named "forward"/"reverse" gets the
    study's styles, any other name the next colour. Forces are shown in kN from 1 kN on.
    ``separate_runs``: each quantity gets a row per run (forward above reverse), the rows of a quantity on one y
    scale, so that two runs never lie over each other. ``envelope``: a period [s] (the mesh period) whose waveform
    the panel cannot show sample by sample — fewer than :data:`ENVELOPE_MIN_SAMPLES` samples per period (they alias
    it) or more than :data:`ENVELOPE_MAX_PERIODS` periods in the window (solid ink at a panel's width): such a
    series is drawn over its whole periods from its first sample (:func:`period_envelope`) as the band of each
    period's samples, minimum to maximum, and the line of the running mean over the m whole periods after which the
    samples fall at the same phases again (:func:`sampling_repeat`; one point per period at the centre of its m, so
    that the line spans only whole windows and carries no ripple of the sampling); the partial period at the end is
    left out, and the legend and a note heading it say so (``envelope_words`` names the period)."""
    if not rows:
        raise ValueError("rows is empty")
    columns = list(columns)
    ts = [np.asarray(t, float) for _, _, by_col in rows for runs in by_col.values() for t, _ in runs.values()]
    if not ts:
        raise ValueError("rows hold no series")
    tscale, tunit = display_unit("s", np.concatenate(ts))
    styles: dict[str, dict] = {"forward": FWD, "reverse": REV}
    extra = iter(["#2e7d32", "#8e24aa", "#c62828", "#00838f", "#555555"])
    handles: dict[str, object] = {}
    shown_rows = []                 # (words, unit, by_col, run label or None, quantity index)
    for q, (words, unit, by_col) in enumerate(rows):
        names = sorted({r for runs in by_col.values() for r in runs}, key=lambda k: {"forward": 0, "reverse": 1}.get(k, 2))
        if separate_runs and len(names) > 1:
            shown_rows += [(words, unit, {c: {n: runs[n]} for c, runs in by_col.items() if n in runs}, n, q)
                           for n in names]
        else:
            shown_rows.append((words, unit, by_col, None, q))
    enveloped = []
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.3 * len(columns) + 0.9, 1.75 * len(shown_rows) + 0.9 + (0.3 if envelope else 0)),
                     layout="constrained")
        axes = fig.subplots(len(shown_rows), len(columns), squeeze=False, sharex=True, sharey="row")
        for r, (words, unit, by_col, run_name, q) in enumerate(shown_rows):
            ys = [np.asarray(y, float) for runs in rows[q][2].values() for _, y in runs.values()]
            scale, shown = display_unit(unit, np.concatenate(ys) if ys else [])
            for c, col in enumerate(columns):
                ax = axes[r, c]
                for run, (t, y) in by_col.get(col, {}).items():
                    if run not in styles:
                        styles[run] = {"color": next(extra, "#555555"), "linestyle": "-", "label": run}
                    st = {**styles[run], "label": run}
                    t = np.asarray(t, float)
                    y = np.asarray(y, float) * scale
                    per = envelope / float(np.median(np.diff(t))) if envelope and t.size > 2 else None
                    many = (t[-1] - t[0]) / envelope if per is not None else 0.0
                    edges = None
                    if per is not None and (per < ENVELOPE_MIN_SAMPLES or many > ENVELOPE_MAX_PERIODS):
                        edges, lo, hi, mean = period_envelope(t, y, envelope)
                    m = sampling_repeat(per) if per is not None else 1
                    if edges is not None and edges.size > m:
                        ax.fill_between(edges * tscale, np.append(lo, lo[-1]), np.append(hi, hi[-1]), step="post",
                                        color=st["color"], alpha=0.25, lw=0, gid="period_range")
                        # the mean over m whole periods, one point per period, only where all m are in the window
                        (ln,) = ax.plot(0.5 * (edges[:-m] + edges[m:]) * tscale, np.convolve(mean, np.ones(m) / m, "valid"),
                                        lw=1.0, gid="period_mean", **st)
                        enveloped.append((per, many, m))
                    else:
                        # many samples: thinner lines, so that two overlaid runs stay apart
                        lw = 1.2 if t.size < 200 else 0.9 if t.size < 1000 else 0.6
                        (ln,) = ax.plot(t * tscale, y, lw=lw, **st)
                    handles.setdefault(run, ln)
                if r == 0:
                    ax.set_title((column_titles or {}).get(col, col))
                if c == 0:
                    label = _wrap(words, 22) + (f"\n{run_name}" if run_name else "")
                    ax.set_ylabel(_axis_label(label, shown))
                if r == len(shown_rows) - 1:
                    ax.set_xlabel(_axis_label("time", tunit))
        for q in range(len(rows)):      # the rows of one quantity on one y scale
            group = [axes[r, c] for r, row in enumerate(shown_rows) if row[4] == q for c in range(len(columns))
                     if axes[r, c].has_data()]
            if len(group) > 1:
                lo = min(ax.get_ylim()[0] for ax in group)
                hi = max(ax.get_ylim()[1] for ax in group)
                for ax in group:
                    ax.set_ylim(lo, hi)
        note = None
        if enveloped:
            few, many = min(e[0] for e in enveloped), max(e[1] for e in enveloped)
            ms = sorted({e[2] for e in enveloped})
            why = ([f"{few:.1f} samples per {envelope_words}: too few to draw its waveform (they alias it)"]
                   if few < ENVELOPE_MIN_SAMPLES else []) + \
                  ([f"{many:.0f} {envelope_words}s in the time shown: too many to draw one by one"]
                   if many > ENVELOPE_MAX_PERIODS else [])
            over = f"{ms[0]} {envelope_words}s" if ms[0] > 1 else f"one {envelope_words}"
            if len(ms) > 1:
                over = f"{'–'.join(map(str, (ms[0], ms[-1])))} {envelope_words}s"
            note = _wrap("; ".join(why) + f". Shown per whole {envelope_words} from the first sample, the partial last "
                         f"one left out; the mean over {over}, after which the samples fall at the same points of the "
                         f"{envelope_words} again (fewer would leave a ripple of the sampling in it); peaks of every "
                         f"step: summary.json", int(15 * fig.get_figwidth()))
            mean_words = f"line: mean over {over}"
        if handles:
            order = sorted(handles, key=lambda k: {"forward": 0, "reverse": 1}.get(k, 2))
            shown_handles, labels = [handles[k] for k in order], list(order)
            if enveloped:
                shown_handles += [Patch(color="0.55", alpha=0.4, lw=0), Line2D([], [], color="0.3", lw=1.0)]
                labels += [f"band: range of the samples in each {envelope_words}", mean_words]
            legend = fig.legend(shown_handles, labels, loc="outside lower center", ncols=len(labels), frameon=False,
                                title=note, title_fontsize=7)
            if note:            # the note heads the legend, where the layout keeps room for it
                legend.get_title().set_gid("envelope_note")
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


ENVELOPE_MIN_SAMPLES = 8     # samples per period below which a history is drawn as its envelope (time_history_group)
ENVELOPE_MAX_PERIODS = 50    # periods in a window above which a history is drawn as its envelope: at a panel's
                             # width (~450 px at 150 dpi) a period then gets under 9 px, too few to show its shape


def sampling_repeat(samples_per_period: float, most: int = 10, tol: float = 0.01) -> int:
    """The fewest whole periods m (1 to ``most``) after which a uniform sampling falls at the same points of a
    period again: m·s within ``tol`` of a whole number of samples, relative to m·s (s = ``samples_per_period``; the
    m with the smallest such misfit if none is within it). Over m periods the samples' phases fill the period on a
    grid of m·s points, so a mean over them holds no ripple of the sampling — over one period it does: at 4.36
    samples per period the phases drift 0.36 of a sample per period and the one-period mean beats with that drift
    (m = 3: 13.07 samples)."""
    s = float(samples_per_period)
    if not s > 0.0:
        raise ValueError(f"samples_per_period: expected > 0, got {s}")
    m = np.arange(1, int(most) + 1)
    misfit = np.abs(m * s - np.round(m * s)) / (m * s)
    ok = np.flatnonzero(misfit <= tol)
    return int(m[ok[0]] if ok.size else m[np.argmin(misfit)])


def period_envelope(t, y, period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A sampled history over its whole periods: (edges (n+1,), minimum (n,), maximum (n,), mean (n,)).

    The periods run from the first sample, ``t[0] + k·period``; only the n whole ones that end by the last sample
    count (the partial one at the end is left out, so no statistic mixes a fraction of a period in). Minimum and
    maximum are those of the samples in [edge_k, edge_k+1) (NaN where a period holds no sample); the mean is the
    time average over the period of the straight lines between the samples — the exact integral of the piecewise
    linear interpolant, so that a ramp's mean is its value at the period's centre whatever the sampling, and a
    period need not hold a whole number of samples."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    period = float(period)
    if t.size < 2 or not period > 0.0:
        raise ValueError(f"period_envelope: expected two samples or more and a period > 0 s, got {t.size} and {period}")
    n = int(np.floor((t[-1] - t[0]) / period * (1.0 + 1e-12)))
    edges = t[0] + period * np.arange(n + 1)
    if n == 0:
        return edges, *(np.empty(0),) * 3
    edges[-1] = min(edges[-1], t[-1])                       # round-off: the last edge is at most the last sample
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t))])     # ∫ y dt up to each sample
    k = np.clip(np.searchsorted(t, edges, side="right") - 1, 0, t.size - 2)
    dt = edges - t[k]
    slope = (y[k + 1] - y[k]) / (t[k + 1] - t[k])
    integral = cum[k] + y[k] * dt + 0.5 * slope * dt ** 2  # ∫ y dt up to each edge
    mean = np.diff(integral) / np.diff(edges)
    start = np.searchsorted(t, edges, side="left")
    start[-1] = np.searchsorted(t, edges[-1], side="right")     # the last period holds a sample on its end
    empty = start[1:] == start[:-1]
    first = np.minimum(start[:-1], start[-1] - 1)
    lo = np.minimum.reduceat(y[:start[-1]], first)
    hi = np.maximum.reduceat(y[:start[-1]], first)
    lo[empty], hi[empty] = np.nan, np.nan
    return edges, lo, hi, mean


# the axes of a cage orbit (viz.results.view_angle's frames): (the axis labels' words, the title's words)
ORBIT_FRAMES = {"carrier": ("carrier axes", "axes turning with the carrier, not the planet"),
                "fixed": ("housing axes", "the housing's fixed axes")}


def cage_orbit_picture(panels: Sequence[tuple], path, *, title: str | None = None, frame: str = "carrier") -> Path:
    """Static cage orbits, one column per run side by side: the guide clearance circle, the cage centre's trail
    coloured by time (one colour bar, in ms), its start and end, the bore centre; the top row shows the whole
    clearance on one scale in µm for all runs, the bottom row zooms onto each trail (one span for all, so the
    orbits' sizes compare).

    panels: (label, t [s] (n,), offset of the cage centre from the bore centre [m] (n, 2), guide clearance
    C_g [m]) — the offset as :func:`viz.results.cage_orbits` gives it. ``frame``: the axes the offsets are in, a key
    of :data:`ORBIT_FRAMES` ("carrier", :func:`viz.results.cage_orbits`' default, or "fixed"), named in the axis
    labels and in a line of the title: the picture is of the cage centre relative to the planet's (the bore's)
    centre, and the axes do not turn with the planet. A cage pressed into its
    land sits beyond the circle by the land contact's deflection: that band, from the circle to the farthest the
    trail reaches, is shaded and named in the legend with its depth."""

    if not panels:
        raise ValueError("panels is empty")
    if frame not in ORBIT_FRAMES:
        raise ValueError(f"frame: expected one of {list(ORBIT_FRAMES)}, got {frame!r}")
    axes_words, frame_words = ORBIT_FRAMES[frame]
    t_all = np.concatenate([np.asarray(p[1], float) for p in panels])
    tscale, tunit = display_unit("s", t_all)
    norm = Normalize(float(np.min(t_all)) * tscale, float(np.max(t_all)) * tscale)
    um = 1e6
    es = [np.asarray(p[2], float) * um for p in panels]
    reach = max(max(float(p[3]) * um, float(np.nanmax(np.hypot(*e.T)))) for p, e in zip(panels, es)) * 1.12
    half = 0.6 * max(max(float(np.nanmax(np.ptp(e, axis=0))), 1e-3) for e in es)     # zoom: one span for all
    cmap = mpl.colormaps["viridis"]
    circle = np.linspace(0, 2 * np.pi, 3601)
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.3 * len(panels) + 1.2, 7.6), layout="constrained")
        fig.get_layout_engine().set(hspace=0.06)          # the zoom row's titles clear the x labels above
        axes = fig.subplots(2, len(panels), squeeze=False)
        lc = None
        beyond = 0.0
        for k, ((label, t, _, clearance), e) in enumerate(zip(panels, es)):
            t = np.asarray(t, float) * tscale
            C = float(clearance) * um
            seg = np.stack([e[:-1], e[1:]], axis=1)
            mid = np.nanmean(e, axis=0)
            r_out = float(np.nanmax(np.hypot(*e.T)))
            for row, ax in enumerate(axes[:, k]):
                if r_out > C:             # beyond the circle: the cage presses into its land, an elastic contact
                    ring = np.concatenate([C * np.exp(1j * circle), r_out * np.exp(-1j * circle)])
                    # the axes' limits are set below: added as an artist, its 7202 vertices are not scanned for
                    # data limits (Axes.fill's add_patch: a second a figure)
                    ax.add_artist(Polygon(np.column_stack([ring.real, ring.imag]), closed=True, color="#f2c14e",
                                          alpha=0.35, lw=0, gid="land_deflection"))
                    beyond = max(beyond, r_out - C)
                ax.plot(C * np.cos(circle), C * np.sin(circle), color="0.45", lw=1.4, ls="--")
                ax.plot([0], [0], marker="+", color="0.35", ms=9, mew=1.2, ls="none")
                lc = LineCollection(seg, cmap=cmap, norm=norm, linewidths=1.3 if row == 0 else 1.6)
                lc.set_array(0.5 * (t[:-1] + t[1:]))
                ax.add_collection(lc)
                ax.plot(*e[0], marker="o", mfc="white", mec="k", ms=6, ls="none")
                ax.plot(*e[-1], marker="s", color="#d50000", ms=6, ls="none")
                if row == 0:
                    ax.set_xlim(-reach, reach)
                    ax.set_ylim(-reach, reach)
                    ax.set_title(label)
                    zoom = (mid[0] - half, mid[0] + half, mid[1] - half, mid[1] + half)
                    ax.plot([zoom[0], zoom[1], zoom[1], zoom[0], zoom[0]], [zoom[2], zoom[2], zoom[3], zoom[3], zoom[2]],
                            color="k", lw=0.7)
                else:
                    ax.set_xlim(mid[0] - half, mid[0] + half)
                    ax.set_ylim(mid[1] - half, mid[1] + half)
                    ax.set_title(f"{label}: zoom on the trail", fontsize=8.5)
                ax.set_aspect("equal")
                ax.set_xlabel(_axis_label(f"cage centre offset x, {axes_words}", "µm"))
                if k == 0:
                    ax.set_ylabel(_axis_label(f"cage centre offset y, {axes_words}", "µm"))
        cb = fig.colorbar(lc, ax=axes.ravel().tolist(), shrink=0.6, pad=0.02)
        cb.set_label(_axis_label("time", tunit))
        handles = [Line2D([], [], color="0.45", lw=1.4, ls="--", label="guide clearance circle"),
                   Line2D([], [], color=cmap(0.6), lw=1.3, label="cage centre (colour: time)"),
                   Line2D([], [], marker="o", mfc="white", mec="k", ls="none", label="start"),
                   Line2D([], [], marker="s", color="#d50000", ls="none", label="end"),
                   Line2D([], [], marker="+", color="0.35", mew=1.2, ls="none", label="planet (bore) centre"),
                   Line2D([], [], color="k", lw=0.7, label="zoomed area")]
        if beyond > 0:
            handles.append(Patch(color="#f2c14e", alpha=0.35, label=f"beyond the circle: the land contact's "
                                                                   f"deflection (up to {beyond:.3g} µm)"))
        fig.legend(handles=handles, loc="outside lower center", ncols=3, frameon=False, fontsize=7.5)
        where = f"cage centre relative to the planet centre; {frame_words}"
        _suptitle(fig, f"{title}\n{where}" if title else where)
        return _save(fig, path)


def damage_shares(bins: Sequence[str], time_shares: Sequence[float], shares: Mapping[str, Sequence[float]], path, *,
                  title: str | None = None) -> Path:
    """A duty cycle's damage per bin: for each bin its share of the cycle's time (grey) beside each bearing type's
    and life's share of the damage (bars from zero, in %); a bin that does more damage than its time share is
    where the life goes."""
    n, k = len(bins), len(shares)
    x = np.arange(n)
    w = 0.8 / (k + 1)
    colors = ["#1f5fa8", "#e07b00", "#6aa2d8", "#f2b066", "#4d9a4d", "#a64d79"]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(min(12.0, max(6.0, 1.2 * n + 2.0)), 4.4), layout="constrained")
        ax = fig.subplots()
        ax.bar(x - 0.4 + w / 2, 100 * np.asarray(time_shares, float), w, color="#bbbbbb", label="time share")
        for i, (name, vals) in enumerate(shares.items()):
            y = np.array([np.nan if v is None else 100 * float(v) for v in vals])
            bars = ax.bar(x - 0.4 + w * (i + 1.5), y, w, color=colors[i % len(colors)], label=name,
                          hatch="//" if "16281" in name else None, edgecolor="white", linewidth=0)
            ax.bar_label(bars, labels=["" if not v >= 1.0 else f"{v:.0f}" for v in y], fontsize=6, padding=1)
        ax.set_xticks(x, [textwrap.fill(b, 18) for b in bins], fontsize=7.5, rotation=0 if n <= 6 else 30,
                      ha="center" if n <= 6 else "right")
        ax.set_ylim(0.0, None)
        ax.set_ylabel(_axis_label("share of the cycle", "%"))
        ax.grid(axis="x", visible=False)
        ax.legend(loc="upper left", fontsize=7)
        if title:
            fig.suptitle(textwrap.fill(title, 110), fontsize=9.5)
        return _save(fig, path)


def binned_series(series: Mapping[str, Sequence[float]], names: Sequence[str], path, *,
                  title: str | None = None) -> Path:
    """A time series and its bins: speed and torque against time, each sample coloured by its bin (grey: at
    standstill, in no bin); time in the unit that suits the span."""
    t = np.asarray(series["t"], float)
    b = np.asarray(series["bin"], int)
    scale, unit = (1 / 3600, "h") if t[-1] - t[0] > 7200 else ((1 / 60, "min") if t[-1] - t[0] > 120 else (1, "s"))
    cmap = mpl.colormaps["tab10" if len(names) <= 10 else "tab20"]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(8.0, 5.6 + 0.2 * ((len(names) + 2) // 3)), layout="constrained")
        axes = fig.subplots(2, 1, sharex=True)
        for ax, key, words, u in ((axes[0], "speed_rpm", "carrier speed", "rpm"),
                                  (axes[1], "torque_N_m", "output torque", "N m")):
            y = np.asarray(series[key], float)
            ax.step(t * scale, y, where="post", color="#888888", linewidth=0.6)
            for j in range(len(names)):
                sel = np.flatnonzero(b == j)
                if sel.size:
                    # sample k holds over [t_k, t_k+1): a horizontal segment per sample in its bin's colour
                    segs = [[(t[i] * scale, y[i]), (t[i + 1] * scale, y[i])] for i in sel]
                    ax.add_collection(LineCollection(segs, colors=[cmap(j % cmap.N)], linewidths=2.2,
                                                     label=names[j] if key == "speed_rpm" else None))
            ax.set_ylabel(_axis_label(words, u))
        axes[1].set_xlabel(_axis_label("time", unit))
        fig.legend(loc="outside lower center", ncols=min(3, max(1, len(names))), fontsize=7, title="bin",
                   title_fontsize=7.5)
        if title:
            fig.suptitle(textwrap.fill(title, 100), fontsize=9.5)
        return _save(fig, path)


# ----------------------------------------------------------------------------------------------
# sensitivity (scenarios.sensitivity)

def morris_heatmap(rel: Mapping[str, Mapping[str, Mapping[str, float]]], parameters: Sequence[str], path, *,
                   title: str | None = None) -> Path:
    """Morris screening as a heat map per operating point: a row per parameter, a column per output, the colour the
    parameter's μ* as a share of the output's nominal value in % (log colour scale from 0.01 % to 100 %; below it
    white), the value written in each cell ≥ 0.1 %. ``rel``: {point label: {output: {parameter: μ*/|nominal|}}};
    ``parameters``: the rows, top to bottom (sorted here by their largest share over all cells)."""
    from matplotlib.colors import LogNorm  # deferred: only this figure uses it

    labels = list(rel)
    outputs = list(dict.fromkeys(o for v in rel.values() for o in v))
    worst = {k: max((rel[p][o].get(k, 0.0) or 0.0 for p in labels for o in rel[p]
                     if np.isfinite(rel[p][o].get(k, np.nan))), default=0.0) for k in parameters}
    rows = sorted(parameters, key=lambda k: -worst[k])
    norm = LogNorm(1e-2, 1e2, clip=True)
    with mpl.rc_context(STYLE):
        cols = min(2, len(labels))
        nrows = (len(labels) + cols - 1) // cols
        fig = Figure(figsize=(2.6 + 0.42 * len(outputs) * cols, 0.9 + (1.9 + 0.24 * len(rows)) * nrows),
                     layout="constrained")
        grid = fig.subplots(nrows, cols, squeeze=False, sharey=True)
        axes = list(grid.flat)
        for ax in axes[len(labels):]:
            ax.set_visible(False)
        img = None
        for ax, label in zip(axes, labels):
            m = np.array([[100.0 * rel[label].get(o, {}).get(k, np.nan) for o in outputs] for k in rows], float)
            shown = np.where(m >= 1e-2, m, np.nan)
            img = ax.imshow(shown, norm=norm, cmap="viridis", aspect="auto")
            for (i, j), v in np.ndenumerate(m):
                if np.isfinite(v) and v >= 0.1:
                    ax.text(j, i, f"{v:.2g}", ha="center", va="center", fontsize=6,
                            color="white" if v < 3.0 else "black")
            ax.set_xticks(range(len(outputs)), outputs, rotation=90, fontsize=7)
            ax.set_yticks(range(len(rows)), rows, fontsize=7)
            ax.grid(False)
            ax.set_title(label.replace("_", " "))
        fig.colorbar(img, ax=axes[:len(labels)], label=_axis_label("μ* / nominal", "%"), shrink=0.6)
        if title:
            fig.suptitle(_wrap(title, max(40, int(11 * fig.get_figwidth()))))
        return _save(fig, path)


def sobol_heatmap(sobol: Mapping[str, Mapping[str, Mapping[str, Mapping]]], parameters: Sequence[str], path, *,
                  title: str | None = None) -> Path:
    """Sobol indices as a heat map per operating point: a row per parameter, a column per output, the colour the
    first-order index S1 (0–1), each cell written "S1 / ST" (ST the total index; their intervals are in the tables).
    ``sobol``: {point label: {output: {parameter: {"S1", "ST", ...}}}}."""
    labels = [p for p in sobol if sobol[p]]
    outputs = list(dict.fromkeys(o for p in labels for o, v in sobol[p].items() if v))
    norm = Normalize(0.0, 1.0)
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.2 + 0.55 * len(outputs), 0.6 + (1.7 + 0.42 * len(parameters)) * len(labels)),
                     layout="constrained")
        axes = fig.subplots(len(labels), 1, squeeze=False, sharex=True)
        img = None
        for n, ax in enumerate(axes.flat):
            if n >= len(labels):
                ax.set_visible(False)
                continue
            label = labels[n]
            s1 = np.array([[sobol[label].get(o, {}).get(k, {}).get("S1", np.nan) for o in outputs] for k in parameters])
            st = np.array([[sobol[label].get(o, {}).get(k, {}).get("ST", np.nan) for o in outputs] for k in parameters])
            img = ax.imshow(np.clip(s1, 0.0, 1.0), norm=norm, cmap="viridis", aspect="auto")
            for (i, j), v in np.ndenumerate(s1):
                if np.isfinite(v):
                    ax.text(j, i, f"{v:.2f}\n{st[i, j]:.2f}", ha="center", va="center", fontsize=5.5,
                            color="white" if v < 0.6 else "black")
            ax.set_xticks(range(len(outputs)), outputs, rotation=90, fontsize=7)
            ax.set_yticks(range(len(parameters)), parameters, fontsize=7)
            ax.grid(False)
            ax.set_title(label.replace("_", " "))
        fig.colorbar(img, ax=list(axes.flat), label="S1 [–]", shrink=0.6)
        if title:
            fig.suptitle(_wrap(title, max(40, int(11 * fig.get_figwidth()))))
        return _save(fig, path)


_PROFILE_MARKERS = {"straight": "o", "iso_16281": "s", "logarithmic": "^", "crowned": "D", "table": "v"}


def life_against_misalignment(rows: Sequence[Mapping], path, *, title: str | None = None) -> Path:
    """The bearing life relative to the aligned machine against the pins' slope γ: a row of panels per operating
    point and slope direction (radial, tangential), a column per bearing type (inner, outer); a line per roller
    profile (its marker) and direction (forward solid blue, reverse dashed orange), the wind-up's lines lighter.

    rows: mappings with ``condition``, ``direction``, ``bearing``, ``profile``, ``windup`` ("off"/"on"), ``slope``
    ("aligned", "radial", "tangential"), ``gamma_arcmin`` and ``life_relative`` (None: not drawn); an aligned row
    (γ = 0) starts every slope direction's lines."""
    conds = sorted({r["condition"] for r in rows}, key=_point_key)
    slopes = [s for s in ("radial", "tangential") if any(r["slope"] == s for r in rows)]
    bearings = [b for b in ("inner", "outer") if any(r["bearing"] == b for r in rows)]
    panels = [(c, s) for c in conds for s in slopes]
    profiles = list(dict.fromkeys(r["profile"] for r in rows))
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(3.4 * len(bearings) + 0.6, 2.4 * max(len(panels), 1) + 0.9), layout="constrained")
        axes = fig.subplots(max(len(panels), 1), len(bearings), squeeze=False, sharex=True)
        for i, (c, s) in enumerate(panels):
            for j, b in enumerate(bearings):
                ax = axes[i, j]
                for prof in profiles:
                    for w in ("off", "on"):
                        for d, style in (("forward", FWD), ("reverse", REV)):
                            mine = [r for r in rows if r["condition"] == c and r["bearing"] == b and r["profile"] == prof
                                    and r["windup"] == w and r["direction"] == d and r["slope"] in ("aligned", s)
                                    and r["life_relative"] is not None]
                            if len(mine) < 2:
                                continue
                            mine.sort(key=lambda r: r["gamma_arcmin"])
                            ax.plot([r["gamma_arcmin"] for r in mine], [r["life_relative"] for r in mine],
                                    marker=_PROFILE_MARKERS.get(prof, "x"), ms=4.5, alpha=1.0 if w == "off" else 0.45,
                                    color=style["color"], linestyle=style["linestyle"])
                ax.axhline(1.0, color="0.5", lw=0.6)
                _from_zero(ax)          # a 1 % loss is not stretched over the panel
                if i == 0:
                    ax.set_title(f"{b} planet bearings")
                ax.set_ylabel(_axis_label(_wrap(f"L/L0, {_point_words(c)}, {s} slope", 26), None))
                if i == len(panels) - 1:
                    ax.set_xlabel(_axis_label("pin slope γ", "arcmin"))
        handles = [Line2D([], [], color=st["color"], ls=st["linestyle"], label=d) for d, st in
                   (("forward", FWD), ("reverse", REV)) if any(r["direction"] == d for r in rows)]
        handles += [Line2D([], [], color="0.3", ls="none", marker=_PROFILE_MARKERS.get(p, "x"), label=p)
                    for p in profiles]
        if any(r["windup"] == "on" for r in rows):
            handles.append(Line2D([], [], color="0.3", alpha=0.45, label="with carrier wind-up"))
        fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 6), frameon=False)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def slice_pressure_profiles(z_m, stations_m, curves: Mapping[str, Sequence], path, *, title: str | None = None) -> Path:
    """The contact pressure along the most loaded roller of each row, as a bearing engineer reads it: the axial position
    across the bearing [mm] (each row's roller drawn at its station, its length shaded) against the pin's slice
    pressure [MPa] (the convex raceway, the higher one), a line per case (e.g. aligned solid blue, tilted dashed red).

    z_m: (n_s,) slice centres from the roller centre [m]; stations_m: (rows,) the rows' axial stations [m];
    curves: label -> (rows, n_s) pressures [Pa]."""
    z = np.asarray(z_m, float) * 1e3
    st = np.atleast_1d(np.asarray(stations_m, float)) * 1e3
    half = 0.5 * (z[-1] - z[0]) + (0.5 * (z[1] - z[0]) if z.size > 1 else 0.5)
    styles = [{"color": "#1f5fa8", "linestyle": "-"}, {"color": "#b2182b", "linestyle": "--"},
              {"color": "#e07b00", "linestyle": ":"}, {"color": "0.3", "linestyle": "-."}]
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(4.2 + 2.2 * st.size, 3.6), layout="constrained")
        ax = fig.add_subplot()
        for r, c in enumerate(st):
            ax.axvspan(c - half, c + half, color="0.93" if r % 2 == 0 else "0.88", zorder=0)
            if st.size > 1:
                ax.text(c, 1.0, f"row {r + 1}", transform=ax.get_xaxis_transform(), ha="center", va="bottom",
                        fontsize="small")
        for i, (label, p) in enumerate(curves.items()):
            p = np.atleast_2d(np.asarray(p, float))
            for r, c in enumerate(st):
                ax.plot(c + z, p[r] * 1e-6, marker="o", ms=2.5, label=label if r == 0 else None,
                        **styles[i % len(styles)])
        ax.set_xlim(st.min() - 1.08 * half, st.max() + 1.08 * half)
        ax.set_xlabel(_axis_label("axial position from the bearing's centre", "mm"))
        ax.set_ylabel(_axis_label("contact pressure on the pin", "MPa"))
        _from_zero(ax)
        ax.legend(loc="best")
        if title:
            _suptitle(fig, title)
        return _save(fig, path)


def slip_transients(panels: Sequence[tuple], path, *, title: str | None = None) -> Path:
    """Slip against time in transients, a panel per (run, bearing type), two columns: ``panels`` of
    (heading, binned, (times, speed, torque), change_s) with ``binned`` a :func:`components.skid.slip_series` entry
    (``time_s``, ``cage``, ``unloaded``, ``entry`` [%] and the single ``entries``) and the schedule's knots (times [s],
    speed and torque as fractions of the operating point), drawn on a second axis in % of the operating point and
    held outside the knots; a vertical line where the change starts."""
    n = len(panels)
    if n == 0:
        raise ValueError("panels is empty")
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    with mpl.rc_context(STYLE):
        fig = Figure(figsize=(5.2 * cols, 0.8 + 2.9 * rows), layout="constrained")
        axes = fig.subplots(rows, cols, squeeze=False).ravel()
        twins = []
        for ax, (heading, b, (kt, ks, kq), change) in zip(axes, panels):
            t = np.asarray(b["time_s"], float)
            te, se = b["entries"]
            ax.scatter(te, se, s=4, color="#c0392b", alpha=0.25, linewidths=0, label="a roller entering")
            ax.plot(t, b["entry"], color="#c0392b", marker=".", label="rollers at load-zone entry")
            ax.plot(t, b["unloaded"], color="#1f5fa8", marker=".", label="rollers out of the load zone")
            ax.plot(t, b["cage"], color="black", label="cage")
            ax.axvline(change, color=_MARK_COLOR, linewidth=0.8, linestyle=":")
            ax.set_title(heading)
            ax.set_xlabel(_axis_label("time", "s"))
            ax.set_ylabel(_axis_label("slip", "%"))
            tw = ax.twinx()
            twins.append(tw)
            tt = np.concatenate([[min(t[0], kt[0])], kt, [max(t[-1], kt[-1])]])
            for values, style, label in ((ks, "--", "carrier speed (schedule)"), (kq, ":", "torque (schedule)")):
                v = 100.0 * np.asarray(values, float)
                tw.plot(tt, np.concatenate([[v[0]], v, [v[-1]]]), color="grey", linestyle=style, label=label)
            tw.set_ylabel(_axis_label("schedule", "% of the operating point"))
            tw.set_ylim(0.0, 105.0)
            tw.grid(False)
            ax.set_xlim(t[0] - 0.5 * (t[1] - t[0]) if t.size > 1 else t[0], t[-1])
        for ax in axes[n:]:
            ax.set_visible(False)
        h1, l1 = axes[0].get_legend_handles_labels()
        h2, l2 = twins[0].get_legend_handles_labels()
        fig.legend(h1 + h2, l1 + l2, loc="outside lower center", ncol=3)
        if title:
            _suptitle(fig, title)
        return _save(fig, path)
