"""The report figures of viz.plots read as figures: every axis says its unit, bars start at zero, legends name
only runs that exist, the % change written on a bar pair is (reverse − forward)/forward of the numbers given.

Each test captures the matplotlib Figure a plot function saves (``plots._save`` wrapped) and inspects its
objects; the PNG is still written and checked not to be blank. The truths are computed here from the inputs,
not taken from the plotting code. Synthetic data only: every test runs in well under a second or two.
"""
from __future__ import annotations

import re

import matplotlib.colors
import matplotlib.image as mpimg
import numpy as np
import pytest

from viz import plots

UNIT = re.compile(r"[\[(][^\])]+[\])]\s*$")          # "... [kN]" or "... (kN)" at the end of a label


@pytest.fixture
def captured(monkeypatch):
    """The Figures the plot functions save, in order."""
    figs = []
    save = plots._save

    def keep(fig, path):
        figs.append(fig)
        return save(fig, path)

    monkeypatch.setattr(plots, "_save", keep)
    return figs


def _visible_axes(fig):
    return [ax for ax in fig.axes if ax.get_visible() and ax.get_label() != "<colorbar>"]


def _legend_labels(fig) -> list[str]:
    labels = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    labels += [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
    return labels


def _pct_texts(ax) -> list:
    return [t for t in ax.texts if t.get_gid() == "pct_change"]


def _parse_pct(text: str) -> tuple[float, float]:
    """(value, half of the last written digit) of '+40 %', '−3.2 %'."""
    m = re.fullmatch(r"([+\-−])(\d+(?:\.(\d+))?) %", text)
    assert m, f"not a % change: {text!r}"
    value = float(m.group(2)) * (-1 if m.group(1) in "-−" else 1)
    decimals = len(m.group(3) or "")
    return value, 0.5 * 10.0 ** -decimals


def _not_blank(path):
    img = mpimg.imread(path)[..., :3]
    assert img.std() > 0.03 and np.mean(img.min(axis=-1) < 0.8) > 0.005


# ------------------------------------------------------------------------------ headline
def _headline_values():
    """Two conditions, both bearing types; condition 1's reverse run does not exist."""
    v = {}
    data = {3: {"inner": (9300.0, 13100.0, 58.0, 19.0), "outer": (12200.0, 9300.0, 23.0, 58.0)},
            1: {"inner": (14300.0, None, 78.0, None), "outer": (18300.0, None, 34.0, None)}}
    for c, by in data.items():
        for b, (lf, lr, hf, hr) in by.items():
            v[("bearing_load_mean_N", c, b, "forward")] = lf
            v[("life_iso281_h", c, b, "forward")] = hf
            if lr is not None:
                v[("bearing_load_mean_N", c, b, "reverse")] = lr
                v[("life_iso281_h", c, b, "reverse")] = hr
    return v


QUANT = (("bearing_load_mean_N", "mean bearing load", "N"), ("life_iso281_h", "L10 life, ISO 281", "h"))


def test_headline_writes_the_change_of_every_pair(tmp_path, captured):
    values = _headline_values()
    path = plots.forward_reverse_headline(values, tmp_path / "h.png", quantities=QUANT, title="headline")
    _not_blank(path)
    fig = captured[-1]
    axes = fig.axes
    assert len(axes) == 2 * 2                            # conditions 1 and 3 × two quantities
    for row, c in enumerate((1, 3)):
        for col, (key, _, _) in enumerate(QUANT):
            ax = axes[row * 2 + col]
            assert UNIT.search(ax.get_ylabel()), ax.get_ylabel()
            lo, hi = ax.get_ylim()
            if key == "bearing_load_mean_N":
                assert ax.get_yscale() == "linear" and lo <= 0.0 < hi        # loads: bars from zero
            else:                                        # lives: a log axis holding the shortest and the longest
                lives = [v for k, v in values.items() if k[:2] == (key, c) and v is not None]
                assert ax.get_yscale() == "log" and 0 < lo < min(lives) and max(lives) < hi
                assert all(p.get_y() == lo for p in ax.patches)             # each bar rises from the axis' foot
                np.testing.assert_allclose(sorted(p.get_y() + p.get_height() for p in ax.patches), sorted(lives))
    # loads over 1 kN are shown in kN: the tallest bar of condition 3's load panel is 13.1
    load3 = axes[1 * 2 + 0]
    assert "[kN]" in load3.get_ylabel()
    assert max(p.get_height() for p in load3.patches) == pytest.approx(13.1)
    # the % change: one per pair where both runs exist, equal to (rev − fwd)/fwd of the inputs
    for row, c in enumerate((1, 3)):
        for col, (key, _, _) in enumerate(QUANT):
            ax = axes[row * 2 + col]
            texts = sorted(_pct_texts(ax), key=lambda t: t.get_position()[0])
            if c == 1:
                assert texts == []                       # no reverse run: no change written
                continue
            assert len(texts) == 2
            for t, b in zip(texts, ("inner", "outer")):
                f, r = values[(key, c, b, "forward")], values[(key, c, b, "reverse")]
                truth = (r - f) / f * 100.0
                shown, tol = _parse_pct(t.get_text())
                assert abs(shown - truth) <= tol + 1e-9, (c, key, b, t.get_text(), truth)
    assert sorted(_legend_labels(fig)) == ["forward", "reverse"]


def test_headline_legend_names_only_runs_that_exist(tmp_path, captured):
    values = {k: v for k, v in _headline_values().items() if k[3] == "forward"}
    plots.forward_reverse_headline(values, tmp_path / "h.png", quantities=QUANT)
    fig = captured[-1]
    assert _legend_labels(fig) == ["forward"]
    assert not any(_pct_texts(ax) for ax in fig.axes)
    # forward bars only: two per panel (inner, outer), none for the missing reverse runs
    for ax in fig.axes:
        assert len([p for p in ax.patches if np.isfinite(p.get_height())]) == 2


def _overlaps(boxes) -> list:
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes[i].x0 < boxes[j].x1 and boxes[j].x0 < boxes[i].x1 and boxes[i].y0 < boxes[j].y1
            and boxes[j].y0 < boxes[i].y1]


@pytest.mark.parametrize("lives", [
    {"inner": (1860.0, 35.0), "outer": (35.0, 1860.0)},                 # the shortest beside a life 53 times longer
    {"inner": (120000.0, 447.0), "outer": (1020.0, 556.0)},             # the cruise point: wide labels, close lives
    {"inner": (487000.0, 486000.0), "outer": (1860000.0, 1790000.0)},  # widest labels at one height
    {"inner": (12300000.0, 18600000.0), "outer": (12300000.0, 18600000.0)},   # millions: '12.3 M'
    {"inner": (999.6, 35.0), "outer": (35.0, 999.6)}])                  # rounds up into the next decade: '1 000'

def test_headline_value_labels_never_overlap_and_read_the_values(tmp_path, captured, lives):
    """Two bearings' forward and reverse lives: every value written over its bar with three significant digits
    (no power of ten), and no two of the panel's texts — values and changes — overlapping once drawn."""
    values = {}
    for b, (f, r) in lives.items():
        values[("life_iso281_h", 2, b, "forward")], values[("life_iso281_h", 2, b, "reverse")] = f, r
    plots.forward_reverse_headline(values, tmp_path / "h.png", quantities=QUANT[1:])
    fig = captured[-1]
    (ax,) = fig.axes
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if t.get_gid() == "value_label"]
    read = lambda s: float(s[:-1]) * 1e6 if s.endswith("M") else float(s)        # noqa: E731
    shown = sorted(read(t.get_text().replace("\u202f", "")) for t in labels)
    truth = sorted(float(f"{v:.3g}") for v in values.values())
    assert shown == truth and not any("e" in t.get_text() for t in labels)
    boxes = [t.get_window_extent(renderer) for t in labels + _pct_texts(ax)]
    assert len(boxes) == 6 and _overlaps(boxes) == []
    assert all(ax.bbox.x0 <= b.x0 and b.x1 <= ax.bbox.x1 and b.y1 <= ax.bbox.y1 for b in boxes)   # inside the panel


def test_headline_writes_a_tenfold_change_as_a_ratio_and_a_deep_fall_with_its_digits(tmp_path, captured):
    """461 h → 306 600 h is ×665 (a percentage, +66 408 %, means nothing in particular); 120 000 h → 447 h is
    −99.6 % (not −100 %)."""
    values = {("life_iso281_h", 1, "inner", "forward"): 461.0, ("life_iso281_h", 1, "inner", "reverse"): 306600.0,
              ("life_iso281_h", 1, "outer", "forward"): 120000.0, ("life_iso281_h", 1, "outer", "reverse"): 447.0}
    plots.forward_reverse_headline(values, tmp_path / "h.png", quantities=QUANT[1:])
    texts = sorted(_pct_texts(captured[-1].axes[0]), key=lambda t: t.get_position()[0])
    assert [t.get_text() for t in texts] == ["\u00d7665", "\u221299.6 %"]


# ------------------------------------------------------------------------------ bar chart
def test_bar_chart_from_zero_with_the_change_and_only_existing_runs(tmp_path, captured):
    table = {"roller load RMS": {"c3": (1400.0, 2600.0), "c4": (1300.0, 2500.0)},
             "cage slip": {"c3": (0.74, 0.71), "c4": (-0.2, 0.3)}}
    plots.bar_chart(["c3", "c4"], table, {"roller load RMS": "N", "cage slip": "%"}, tmp_path / "b.png")
    fig = captured[-1]
    axes = _visible_axes(fig)
    assert len(axes) == 2
    for ax, (q, by) in zip(axes, table.items()):
        assert UNIT.search(ax.get_ylabel())
        lo, hi = ax.get_ylim()
        assert lo <= 0.0 <= hi and lo <= min(min(p) for p in by.values())  # the negative slip is inside
        texts = sorted(_pct_texts(ax), key=lambda t: t.get_position()[0])
        same_sign = [c for c in ("c3", "c4") if by[c][0] * by[c][1] > 0]     # a sign change has no % change
        for t, c in zip(texts, same_sign):
            f, r = by[c]
            shown, tol = _parse_pct(t.get_text())
            assert abs(shown - (r - f) / f * 100.0) <= tol + 1e-9
        assert len(texts) == len(same_sign) == (2 if q == "roller load RMS" else 1)
    assert "[kN]" in axes[0].get_ylabel()
    assert sorted(_legend_labels(fig)) == ["forward", "reverse"]

    only_fwd = {q: {c: (p[0], None) for c, p in by.items()} for q, by in table.items()}
    plots.bar_chart(["c3", "c4"], only_fwd, {"roller load RMS": "N", "cage slip": "%"}, tmp_path / "b2.png")
    fig = captured[-1]
    assert _legend_labels(fig) == ["forward"]
    assert not any(_pct_texts(ax) for ax in fig.axes)


# ------------------------------------------------------------------------------ time histories
def test_time_history_group_units_one_legend_shared_time(tmp_path, captured):
    t = np.linspace(0.030, 0.051, 300)
    load = 9000.0 + 800.0 * np.sin(2 * np.pi * 700 * t)
    rows = [("bearing load, radial", "N", {"inner": {"forward": (t, load), "reverse": (t, 1.4 * load)},
                                            "outer": {"forward": (t, 0.8 * load)}}),
            ("cage–guide force", "N", {"inner": {"forward": (t, 0.1 * load)}, "outer": {"forward": (t, 0.09 * load)}}),
            ("cage acc. rel. planet, radial", "m/s^2", {"inner": {"forward": (t, 3e3 * np.sin(9e3 * t))}}),
            ("transmission error", "m", {"outer": {"forward": (t, 3e-6 + 1e-6 * np.sin(6e3 * t))}})]
    path = plots.time_history_group(rows, tmp_path / "g.png", columns=["inner", "outer"], title="group")
    _not_blank(path)
    fig = captured[-1]
    axes = np.array(fig.axes).reshape(len(rows), 2)
    # one legend for the figure, naming the runs drawn; none on the panels
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
    assert sorted(_legend_labels(fig)) == ["forward", "reverse"]
    # y labels on the first column, with their display units; the time axis in ms on the bottom row
    assert [ax.get_ylabel().split("[")[-1] for ax in axes[:, 0]] == ["kN]", "N]", "m/s²]", "µm]"]
    assert all(UNIT.search(ax.get_xlabel()) and "[ms]" in ax.get_xlabel() for ax in axes[-1])
    # the data: kN and ms, the rows' panels on one y scale, all panels on one time axis
    line = axes[0, 0].get_lines()[0]
    np.testing.assert_allclose(line.get_xdata(), t * 1e3)
    np.testing.assert_allclose(line.get_ydata(), load / 1e3)
    np.testing.assert_allclose(axes[1, 1].get_lines()[0].get_ydata(), 0.09 * load)        # under 1 kN: N
    np.testing.assert_allclose(axes[3, 1].get_lines()[0].get_ydata(), (3e-6 + 1e-6 * np.sin(6e3 * t)) * 1e6)
    assert axes[0, 0].get_ylim() == axes[0, 1].get_ylim()
    assert len({ax.get_xlim() for ax in fig.axes}) == 1
    # the reverse run drawn with the study's style (only where it exists)
    assert [ln.get_label() for ln in axes[0, 0].get_lines()] == ["forward", "reverse"]
    assert [ln.get_label() for ln in axes[0, 1].get_lines()] == ["forward"]


def test_time_history_group_rejects_empty(tmp_path):
    with pytest.raises(ValueError, match="empty"):
        plots.time_history_group([], tmp_path / "x.png", columns=["inner"])


# ------------------------------------------------------------------------------ cage orbit picture
def test_cage_orbit_picture(tmp_path, captured):
    t = np.linspace(0.030, 0.040, 400)
    C = 150e-6
    w = 2 * np.pi * 300
    fwd = np.column_stack([190e-6 + 8e-6 * np.cos(w * t), 50e-6 + 8e-6 * np.sin(w * t)])
    rev = np.column_stack([180e-6 + 4e-6 * np.cos(-w * t), -50e-6 + 4e-6 * np.sin(-w * t)])
    path = plots.cage_orbit_picture([("forward", t, fwd, C), ("reverse", t, rev, C)], tmp_path / "o.png",
                                    title="orbits")
    _not_blank(path)
    fig = captured[-1]
    cbar = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(cbar) == 1 and cbar[0].get_ylabel() == "time [ms]"
    axes = _visible_axes(fig)
    assert len(axes) == 4                                   # whole clearance and zoom, per run
    for ax in axes:
        assert "[µm]" in ax.get_xlabel()
        assert ax.get_aspect() == 1.0                       # a circle is round
    assert all("[µm]" in ax.get_ylabel() for ax in axes[::2][:1])
    top = axes[:2]
    for ax, e in zip(top, (fwd, rev)):
        # the clearance circle in µm, centred on the bore centre
        circle = next(ln for ln in ax.get_lines() if ln.get_linestyle() == "--")
        r = np.hypot(circle.get_xdata(), circle.get_ydata())
        np.testing.assert_allclose(r, C * 1e6, rtol=1e-12)
        # the trail coloured by time: its segments are the offsets in µm, its colours the times in ms
        lc = ax.collections[0]
        segs = lc.get_segments()
        np.testing.assert_allclose(np.array([s[0] for s in segs]), e[:-1] * 1e6)
        np.testing.assert_allclose(lc.get_array(), 0.5 * (t[:-1] + t[1:]) * 1e3)
        # the whole clearance is in view
        assert ax.get_xlim()[1] > C * 1e6 and ax.get_ylim()[0] < -C * 1e6
    assert lc.norm.vmin == pytest.approx(t[0] * 1e3) and lc.norm.vmax == pytest.approx(t[-1] * 1e3)
    labels = _legend_labels(fig)
    assert {"guide clearance circle", "start", "end", "planet (bore) centre"} <= set(labels)
    # the frame is named: the cage centre relative to the planet centre, in axes turning with the carrier
    assert all("carrier axes" in ax.get_xlabel() for ax in axes) and "carrier axes" in axes[0].get_ylabel()
    assert "relative to the planet centre; axes turning with the carrier, not the planet" in \
        " ".join(fig._suptitle.get_text().split())
    # the zoom row shows the trails: each trail lies inside its zoom panel
    for ax, e in zip(axes[2:], (fwd, rev)):
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 < e[:, 0].min() * 1e6 and e[:, 0].max() * 1e6 < x1
        assert y0 < e[:, 1].min() * 1e6 and e[:, 1].max() * 1e6 < y1


# ------------------------------------------------------------------------------ fault and oil figures
def test_fault_loads_bars_from_zero_as_changes(tmp_path, captured):
    rows = []
    for fault, k_gamma, life in (("perfect", 1.0, 1.0), ("pinhole", 1.12, 0.7), ("runout", 1.03, 0.95)):
        for b in ("inner", "outer"):
            rows.append({"fault": fault, "direction": "forward", "bearing": b, "load_sharing_factor": k_gamma,
                         "bearing_load_max_N": 15000.0, "life_relative": life, "cage_slip_pct": 0.7,
                         "pocket_impacts_per_rev": 150.0})
    plots.fault_loads(rows, tmp_path / "f.png")
    fig = captured[-1]
    assert _legend_labels(fig) == ["forward"]               # no reverse run: no reverse entry
    axes = np.array(fig.axes).reshape(len(plots.FAULT_QUANTITIES), 2)
    for ax in axes.ravel():
        lo, hi = ax.get_ylim()
        assert lo <= 0.0 <= hi
        assert UNIT.search(ax.get_ylabel()), ax.get_ylabel()
    # K_γ and the life ratio as their change in %: 100 (r − 1) of the inputs
    heights = [p.get_height() for p in axes[0, 0].patches]
    np.testing.assert_allclose(heights, [0.0, 12.0, 3.0], atol=1e-9)
    heights = [p.get_height() for p in axes[2, 1].patches]
    np.testing.assert_allclose(heights, [0.0, -30.0, -5.0], atol=1e-9)
    assert "[kN]" in axes[1, 0].get_ylabel()


def test_against_viscosity_one_legend_film_in_micrometres(tmp_path, captured):
    eta = [0.012, 0.024, 0.05]
    series = {}
    for d, f in (("forward", 1.0), ("reverse", 1.05)):
        for b in ("inner", "outer"):
            series[("h_min_m", b, d)] = (eta, [f * 0.3e-6, f * 0.5e-6, f * 0.8e-6])
            series[("lambda_min", b, d)] = (eta, [f * 1.5, f * 2.5, f * 4.0])
    plots.against_viscosity(series, [("lambda_min", "Λ_min", "1", True), ("h_min_m", "h_min", "m", True)],
                            tmp_path / "v.png", levels={"lambda_min": {1.0: "boundary", 3.0: "full film"}})
    fig = captured[-1]
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
    assert sorted(_legend_labels(fig)) == ["forward", "reverse"]
    axes = np.array(fig.axes).reshape(2, 2)
    assert "[µm]" in axes[1, 0].get_ylabel() and "[–]" in axes[0, 0].get_ylabel()
    np.testing.assert_allclose(axes[1, 0].get_lines()[0].get_ydata(), [0.3, 0.5, 0.8])
    assert "[mPa·s]" in axes[1, 0].get_xlabel()
    levels = [ln.get_ydata()[0] for ln in axes[0, 1].get_lines() if ln.get_linestyle() == ":"]
    assert sorted(levels) == [1.0, 3.0]


# ------------------------------------------------------------------------------ helpers
@pytest.mark.parametrize("unit, values, factor, shown", [
    ("N", [900.0, -950.0], 1.0, "N"), ("N", [999.0, 1000.0], 1e-3, "kN"), ("m", [2e-6], 1e6, "µm"),
    ("m", [2e-3], 1e3, "mm"), ("s", [0.03], 1e3, "ms"), ("s", [5.0], 1.0, "s"), ("m/s^2", [1.0], 1.0, "m/s²"),
    ("percent", [1.0], 1.0, "%"), ("1", [1.0], 1.0, "–")])
def test_display_unit(unit, values, factor, shown):
    assert plots.display_unit(unit, values) == (factor, shown)


@pytest.mark.parametrize("p, text", [(40.0, "+40 %"), (-24.4, "−24 %"), (3.21, "+3.2 %"), (-0.04, "0.0 %"),
                                     (159.4, "+159 %"), (-99.63, "−99.6 %"), (66408.0, "×665")])
def test_format_pct(p, text):
    assert plots.format_pct(p) == text


def test_a_spectrum_of_several_paths_gives_each_its_own_colour(captured, tmp_path):
    """The housing sensor and its three paths (four curves): four colours, one legend entry each, and the
    marks and the unit on the axes."""
    f = np.linspace(0.0, 2000.0, 401)
    curves = {name: (k + 1.0) * (1.0 + np.abs(np.sin(f / (50.0 + k)))) for k, name in
              enumerate(("housing sensor", "mesh path", "torque path", "bearing path"))}
    plots.spectrum(f, curves, {"f_m": 900.0}, tmp_path / "s.png", quantity="housing accelerometer", unit="m/s²",
                   logy=True)
    fig = captured[-1]
    ax = _visible_axes(fig)[0]
    colours = [tuple(matplotlib.colors.to_rgba(line.get_color())) for line in ax.get_lines() if line.get_label() in curves]
    assert len(colours) == 4
    rgb = np.array(colours)[:, :3]
    apart = min(np.linalg.norm(rgb[i] - rgb[j]) for i in range(4) for j in range(i))
    assert apart > 0.25, apart          # told apart by eye, not only by value (two blues were 0.1 apart)
    assert _legend_labels(fig) == list(curves) and "[m/s²]" in ax.get_ylabel()


def test_mode_shapes_are_numbered_as_the_table_and_say_what_is_left_out(captured, tmp_path):
    """The modal table counts the rigid-body mode at 0 Hz as mode 1; the figure leaves it out but keeps its numbers,
    and says how many modes it does not show."""
    f = np.array([10.0, 20.0, 30.0, 40.0])
    plots.mode_shapes(f, np.eye(4), ["a", "b", "c", "d"], tmp_path / "m.png", max_modes=3, numbers=[2, 3, 4, 5])
    fig = captured[-1]
    titles = [ax.get_title() for ax in _visible_axes(fig)]
    assert titles == ["mode 2: f = 10 Hz", "mode 3: f = 20 Hz", "mode 4: f = 30 Hz"]
    assert any(t.get_text() == "the first 3 of 4 modes shown" for t in fig.texts)


# ------------------------------------------------------------------------------ bearing rig: polar load distribution
def _boxes_apart(fig, texts):
    """No two of the drawn texts' boxes overlap (pixels, after drawing)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(r)) for t in texts if t.get_visible() and t.get_text()]
    for i, (a, ba) in enumerate(boxes):
        for b, bb in boxes[:i]:
            assert not ba.overlaps(bb), (a, b)


def test_load_distribution_degrees_kN_and_labels_apart(tmp_path, captured):
    """The bearing rig's polar plot: angle ticks in degrees every 30°, what 0° is in the title, the loads in kN on
    the radial axis with the unit written there, the radial labels opposite the loaded rollers, and no label on
    another (the angle and radial labels collided before)."""
    Z = 12
    ang = 2 * np.pi * np.arange(Z) / Z - np.pi             # -180° .. 150°, the load zone centred on 0°
    load = 3844.8 * np.clip(np.cos(ang), 0.0, None) ** 1.5
    theory = ("theory", 2 * np.pi * np.arange(Z) / Z, 3843.5 * np.clip(np.cos(2 * np.pi * np.arange(Z) / Z), 0, None) ** 1.5)
    path = plots.load_distribution(ang, {"simulated": load}, tmp_path / "p.png", title="rig",
                                   zero="the load-zone centre", theory=theory)
    _not_blank(path)
    fig = captured[-1]
    ax = fig.axes[0]
    assert "0° = the load-zone centre" in ax.get_title() and "rig" in ax.get_title()
    assert [t.get_text() for t in ax.get_xticklabels()] == [f"{d}°" for d in range(0, 360, 30)]
    np.testing.assert_allclose(np.degrees(ax.get_xticks()), np.arange(0, 360, 30))
    # the data in kN: the envelope's radii are the loads / 1000, in angle order
    order = np.argsort(np.mod(ang, 2 * np.pi))
    env = next(ln for ln in ax.get_lines() if ln.get_label() == "simulated")
    np.testing.assert_allclose(env.get_ydata()[:-1], load[order] / 1e3)
    np.testing.assert_allclose(env.get_xdata()[:-1], np.mod(ang, 2 * np.pi)[order])
    th = next(ln for ln in ax.get_lines() if ln.get_label() == "theory")
    np.testing.assert_allclose(th.get_ydata(), theory[2] / 1e3)
    unit = [t for t in ax.texts if t.get_gid() == "radial_unit"]
    assert len(unit) == 1 and "[kN]" in unit[0].get_text()
    # round radial ticks, the outer circle one of them, covering the largest load
    ticks = ax.get_yticks()
    assert ax.get_ylim()[0] == 0.0 and ax.get_ylim()[1] == ticks[-1] >= load.max() / 1e3
    assert [t.get_text() for t in ax.get_yticklabels()] == [f"{v:g}" for v in ticks]
    # the radial labels on the unloaded side (the loads sit around 0°)
    where = ax.get_rlabel_position()
    assert 120.0 < where % 360.0 < 240.0, where
    _boxes_apart(fig, [*ax.get_xticklabels(), *ax.get_yticklabels(), *unit, ax.title])
    assert sorted(_legend_labels(fig)) == ["simulated", "theory"]


def test_load_distribution_below_a_kilonewton_in_newtons(tmp_path, captured):
    ang = 2 * np.pi * np.arange(8) / 8
    plots.load_distribution(ang, 600.0 * np.clip(np.cos(ang - np.pi / 2), 0, None), tmp_path / "p.png")
    ax = captured[-1].axes[0]
    assert "[N]" in next(t.get_text() for t in ax.texts if t.get_gid() == "radial_unit")
    assert 120.0 < (ax.get_rlabel_position() - 90.0) % 360.0 < 240.0       # opposite the loads, centred on 90°


def _inside(fig, ax, texts):
    """Every text's drawn box lies inside the axes' box (pixels)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    box = ax.get_window_extent(r)
    for t in texts:
        e = t.get_window_extent(r)
        assert box.x0 <= e.x0 and e.x1 <= box.x1 and box.y0 <= e.y0 and e.y1 <= box.y1, (t.get_text(), e, box)


@pytest.mark.parametrize("top", [2.96, 3.0, 4.1, 1.4])
def test_film_regime_labels_stay_inside_their_panels(tmp_path, captured, top):
    """The regimes' bounds Λ = 1 and 3 are drawn in every Λ panel with their words inside it — also when the
    thinnest film reaches just under, at or over a bound at the panel's top edge (the Λ = 3 label was clipped
    there), or when no oil comes near it."""
    eta = [0.0128, 0.0241]
    series = {("lambda_min", b, "forward"): (eta, [0.7 * top, top]) for b in ("inner", "outer")}
    plots.against_viscosity(series, [("lambda_min", "Λ_min", "1", True)], tmp_path / "v.png",
                            levels={"lambda_min": {1.0: "Λ = 1: below, boundary-dominated", 3.0: "Λ = 3: full film above"}})
    fig = captured[-1]
    for ax in fig.axes:
        lo, hi = ax.get_ylim()
        assert lo < 1.0 and 3.0 < hi                       # both bounds in view
        labels = [t for t in ax.texts if t.get_gid() == "level"]
        assert sorted(t.get_text()[:5] for t in labels) == ["Λ = 1", "Λ = 3"]
        _inside(fig, ax, labels)


def test_against_viscosity_a_line_and_a_marker_per_condition(tmp_path, captured):
    """Several conditions: each its own line (a study over conditions 1-4 drew one zig-zag line through all of
    them) with its own marker, named once in the legend beside the directions."""
    eta = [0.0128, 0.0241, 0.0476]
    series = {("lambda_min", b, d, f"condition {c}"): (eta, [c * 0.5, c * 0.8, c * 1.2])
              for b in ("inner", "outer") for d in ("forward", "reverse") for c in (1, 3)}
    plots.against_viscosity(series, [("lambda_min", "Λ_min", "1", True)], tmp_path / "v.png",
                            names={"VG32": 0.0128, "VG68": 0.0241, "VG150": 0.0476})
    fig = captured[-1]
    assert _legend_labels(fig) == ["forward", "reverse", "condition 1", "condition 3"]
    for ax in fig.axes:
        lines = [ln for ln in ax.get_lines() if ln.get_linestyle() != ":"]
        assert len(lines) == 4                              # 2 conditions × 2 directions, 3 points each
        assert all(len(ln.get_xdata()) == 3 for ln in lines)
        assert {ln.get_marker() for ln in lines if ln.get_ydata()[0] == 0.5} != \
            {ln.get_marker() for ln in lines if ln.get_ydata()[0] == 1.5}
        assert [t.get_text() for t in ax.get_xticklabels()] == ["12.8\nVG32", "24.1\nVG68", "47.6\nVG150"]


# ------------------------------------------------------------------------------ readable runs, envelopes, bands
def test_separate_runs_put_forward_and_reverse_in_rows_of_their_own_on_one_scale(tmp_path, captured):
    t = np.linspace(0.03, 0.05, 300)
    rows = [("bearing load", "N", {"inner": {"forward": (t, 9e3 + 0 * t), "reverse": (t, 13e3 + 0 * t)},
                                    "outer": {"forward": (t, 12e3 + 0 * t), "reverse": (t, 9e3 + 0 * t)}})]
    plots.time_history_group(rows, tmp_path / "g.png", columns=["inner", "outer"], separate_runs=True)
    axes = np.array(captured[-1].axes).reshape(2, 2)
    assert [ln.get_label() for ax in axes[0] for ln in ax.get_lines()] == ["forward", "forward"]
    assert [ln.get_label() for ax in axes[1] for ln in ax.get_lines()] == ["reverse", "reverse"]
    assert "forward" in axes[0, 0].get_ylabel() and "reverse" in axes[1, 0].get_ylabel()
    assert len({ax.get_ylim() for ax in axes.ravel()}) == 1            # one quantity, one scale
    np.testing.assert_allclose(axes[1, 0].get_lines()[0].get_ydata(), 13.0)      # kN


def _band_and_mean(ax):
    band = next(c for c in ax.collections if c.get_gid() == "period_range")
    mean = next(ln for ln in ax.get_lines() if ln.get_gid() == "period_mean")
    return band.get_paths()[0].vertices, mean.get_xdata(), mean.get_ydata()


def test_a_history_sampled_a_few_times_per_period_is_drawn_as_its_envelope(tmp_path, captured):
    """4.36 samples per period (the mesh at 5740 Hz recorded at 25 kHz) of a periodic waveform of mean A with three
    harmonics: the band of each whole period's samples (by hand here with a plain loop), from the first sample to
    the last whole period; the mean line only where its periods are whole, and on the waveform's mean A (closed
    form) — over the 3 periods after which the samples fall at the same phases again (13.07 samples), where a
    one-period mean beats with the sampling; the legend and the note say so."""
    T = 1 / 5740.0
    t = np.arange(0.03, 0.052, 1 / 25000.0)
    A, B = 2000.0, 500.0
    ph = 2 * np.pi * t / T
    y = A + B * np.sin(ph) + 0.5 * B * np.sin(2 * ph + 1.0) + 0.3 * B * np.sin(3 * ph + 2.0)
    rows = [("mesh force", "N", {"m": {"forward": (t, y)}})]
    plots.time_history_group(rows, tmp_path / "e.png", columns=["m"], envelope=T, envelope_words="mesh cycle")
    fig = captured[-1]
    verts, xm, ym = _band_and_mean(fig.axes[0])
    n = int((t[-1] - t[0]) / T)                                     # whole periods in the record
    hand_lo, hand_hi = [], []
    for i in range(n):
        inside = [v for tk, v in zip(t, y) if t[0] + i * T - 1e-12 <= tk < t[0] + (i + 1) * T - 1e-12]
        hand_lo.append(min(inside))
        hand_hi.append(max(inside))
    x_ms = verts[:, 0]
    assert x_ms.min() == pytest.approx(t[0] * 1e3) and x_ms.max() == pytest.approx((t[0] + n * T) * 1e3)
    assert x_ms.max() < t[-1] * 1e3                                  # the partial last period is left out
    assert verts[:, 1].max() == pytest.approx(max(hand_hi) / 1e3) and verts[:, 1].min() == pytest.approx(min(hand_lo) / 1e3)
    for lo, hi in zip(hand_lo, hand_hi):                            # each period's range is a step of the band
        assert np.any(np.isclose(verts[:, 1], lo / 1e3, rtol=1e-12)) and np.any(np.isclose(verts[:, 1], hi / 1e3, rtol=1e-12))
    m = 3                                                           # 3 × 4.355 = 13.07 samples
    assert plots.sampling_repeat(25000.0 * T) == m
    assert xm.min() == pytest.approx((t[0] + m * T / 2) * 1e3) and xm.max() == pytest.approx((t[0] + (n - m / 2) * T) * 1e3)
    assert np.abs(ym * 1e3 - A).max() < 0.005 * B                   # on the mean, no edge jump, no sampling ripple
    one = plots.period_envelope(t, y, T)[3]                         # what one period's mean would show: a ripple
    assert np.abs(one - A).max() > 0.02 * B
    labels = _legend_labels(fig)
    assert "band: range of the samples in each mesh cycle" in labels and "line: mean over 3 mesh cycles" in labels
    note = next(tx for lg in fig.legends for tx in [lg.get_title()] if tx.get_gid() == "envelope_note")
    assert "4.4 samples per mesh cycle" in note.get_text() and "partial last one left out" in note.get_text()
    t2 = np.arange(0.03, 0.032, T / 20)                             # 20 samples per period, 11 periods: drawn
    plots.time_history_group([("mesh force", "N", {"m": {"forward": (t2, 0 * t2 + 1.0)}})], tmp_path / "f.png",
                             columns=["m"], envelope=T)
    assert not captured[-1].axes[0].collections and not any(lg.get_title().get_text() for lg in captured[-1].legends)


def test_a_history_of_many_periods_is_drawn_as_its_envelope_and_a_ramp_reads_as_its_mean(tmp_path, captured):
    """40 samples per period but 120 periods (condition 1's record: solid ink sample by sample): drawn as the band
    and the mean of each whole period; the mean of a ramp under a sine over a period is the ramp at the period's
    centre (closed form), and its line starts half a period after the first sample."""
    T = 1 / 1366.0
    t = np.arange(0.0, 120.5 * T, T / 40)
    ramp = 3000.0 + 4e4 * t
    y = ramp + 800.0 * np.sin(2 * np.pi * t / T + 0.7)
    plots.time_history_group([("mesh force", "N", {"m": {"forward": (t, y)}})], tmp_path / "g.png", columns=["m"],
                             envelope=T, envelope_words="mesh cycle")
    fig = captured[-1]
    verts, xm, ym = _band_and_mean(fig.axes[0])
    centres = t[0] + (np.arange(120) + 0.5) * T
    np.testing.assert_allclose(xm, centres * 1e3, rtol=1e-12)       # one point per whole period, none past them
    np.testing.assert_allclose(ym * 1e3, 3000.0 + 4e4 * centres, rtol=1e-6)
    note = fig.legends[0].get_title().get_text()
    assert "120 mesh cycles in the time shown: too many to draw one by one" in note and "samples per" not in note
    assert "line: mean over one mesh cycle" in _legend_labels(fig)


@pytest.mark.parametrize("per, m", [(25000 / 5740, 3), (40.0, 1), (8.0, 1), (25000 / 2733.333, 5), (2.5, 2)])
def test_the_sampling_repeats_after_the_fewest_whole_periods_that_hold_a_whole_number_of_samples(per, m):
    """4.355 samples per period: 13.07 in 3 periods; 9.146: 45.73 in 5 (within 1 %); 2.5: 5 in 2."""
    assert plots.sampling_repeat(per) == m
    assert abs(m * per - round(m * per)) <= 0.01 * m * per


def test_the_cage_orbit_picture_names_the_housing_frame_and_refuses_an_unknown_one(tmp_path, captured):
    t = np.linspace(0, 0.02, 200)
    e = 100e-6 * np.column_stack([np.cos(t * 300), np.sin(t * 300)])
    plots.cage_orbit_picture([("forward", t, e, 150e-6)], tmp_path / "o.png", frame="fixed", title="orbits")
    fig = captured[-1]
    assert all("housing axes" in ax.get_xlabel() for ax in _visible_axes(fig))
    title = fig._suptitle.get_text()
    assert title.startswith("orbits\n")            # the caller's title, then the frame (wrapped to the figure's width)
    assert " ".join(title.split()[1:]) == "cage centre relative to the planet centre; the housing's fixed axes"
    with pytest.raises(ValueError, match="frame: expected one of"):
        plots.cage_orbit_picture([("forward", t, e, 150e-6)], tmp_path / "p.png", frame="planet")


def test_a_cage_beyond_its_clearance_circle_is_drawn_in_the_land_deflection_band(tmp_path, captured):
    """A trail 30 µm beyond the 150 µm circle: the band from the circle to the trail's farthest point is shaded and
    the legend names its depth; a trail inside the circle: no band."""
    t = np.linspace(0, 0.02, 200)
    ang = np.linspace(0, 0.3, 200)
    e = 180e-6 * np.column_stack([np.cos(ang), np.sin(ang)])
    plots.cage_orbit_picture([("forward", t, e, 150e-6)], tmp_path / "o.png")
    fig = captured[-1]
    assert any(p.get_gid() == "land_deflection" for ax in fig.axes for p in ax.patches)
    assert any("land contact's deflection (up to 30 µm)" in s for s in _legend_labels(fig))
    plots.cage_orbit_picture([("forward", t, 0.5 * e, 150e-6)], tmp_path / "p.png")
    fig = captured[-1]
    assert not any(p.get_gid() == "land_deflection" for ax in fig.axes for p in ax.patches)


def test_the_cage_orbit_animations_excursion_factor():
    """A cage pressed into its land moving ±2 µm in a 150 µm clearance: half the clearance over 2 µm is 37.5,
    rounded down to 20 (1, 2, 5 × 10^k); the smallest need of several panels wins; a cage already moving over half
    its clearance is not magnified."""
    from viz.animate import excursion_factor
    ang = np.linspace(0, 2 * np.pi, 400)
    circ = np.column_stack([np.cos(ang), np.sin(ang)])
    small = np.array([0.0, -160e-6]) + 2e-6 * circ
    assert excursion_factor({"a": small}, {"a": 150e-6}) == 20.0
    assert excursion_factor({"a": small, "b": np.array([0, -160e-6]) + 6e-6 * circ}, {"a": 150e-6, "b": 150e-6}) == 10.0
    assert excursion_factor({"a": 100e-6 * circ}, {"a": 150e-6}) == 1.0


def test_no_percent_change_of_a_quantity_whose_sign_changes(tmp_path, captured):
    """Cage slip +0.2 % forward, −0.3 % reverse: no '% change' on the bars (the two values are drawn); same-sign
    values keep theirs, (rev − fwd)/fwd."""
    from components.results import percent_change
    assert percent_change(0.2, -0.3) is None and percent_change(0.0, 1.0) is None
    assert percent_change(-0.2, -0.3) == pytest.approx(50.0) and percent_change(2.0, 3.0) == pytest.approx(50.0)
    plots.bar_chart(["condition 3"], {"cage slip": {"condition 3": (0.2, -0.3)}, "load": {"condition 3": (2.0, 3.0)}},
                    {"cage slip": "%", "load": "N"}, tmp_path / "b.png")
    fig = captured[-1]
    texts = [t.get_text() for ax in fig.axes for t in _pct_texts(ax)]
    assert texts == ["+50 %"]


def test_the_spectrum_zooms_on_the_side_bands_and_labels_them_there(tmp_path, captured):
    f = np.linspace(0, 12000, 6001)
    a = 1e-3 + np.exp(-((f - 5740) / 5) ** 2)
    f_m, f_c = 5740.0, 70.0
    marks = {"f_m": f_m, "f_m−1f_c": f_m - f_c, "f_m+1f_c": f_m + f_c, "2f_m": 2 * f_m}
    plots.spectrum(f, a, marks, tmp_path / "s.png", zoom=(f_m - 5 * f_c, f_m + 5 * f_c))
    full, zoom = captured[-1].axes
    assert sorted(t.get_text() for t in full.texts) == ["2f_m"]
    assert sorted(t.get_text() for t in zoom.texts) == sorted(["f_m", "f_m−1f_c", "f_m+1f_c"])
    assert zoom.get_xlim() == pytest.approx((f_m - 5 * f_c, f_m + 5 * f_c))


def test_a_small_difference_is_drawn_against_zero_in_the_oil_figure(tmp_path, captured):
    """Cage-guide heat 100.0 W against 100.1 W (0.1 %): the linear axis holds zero, so the two lines lie together
    as their values do; a signed quantity (slip −0.2 … +0.3 %) keeps both signs and zero in view."""
    x = np.array([0.01, 0.03, 0.1])
    series = {("heat", "inner", "forward"): (x, [100.0, 100.05, 100.1]),
              ("heat", "inner", "reverse"): (x, [100.0, 100.0, 100.0]),
              ("slip", "inner", "forward"): (x, [-0.2, 0.1, 0.3])}
    plots.against_viscosity(series, [("heat", "heat", "W", False), ("slip", "slip", "%", False)], tmp_path / "z.png")
    heat, slip = captured[-1].axes[:2]
    assert heat.get_ylim()[0] == 0.0 and heat.get_ylim()[1] >= 100.1
    lo, hi = slip.get_ylim()
    assert lo <= -0.2 and hi >= 0.3 and lo < 0.0 < hi


def test_a_narrow_life_axis_still_reads_at_two_ticks_at_least(tmp_path, captured):
    """Lives within a decade (an idle point's 421 000 and 516 000 h) on the log axis: 1-2-5 ticks, not the one
    decade tick a wider axis gets, every label plain."""
    values = {("life_iso281_h", 2, b, d): v for b, pair in (("inner", (509000.0, 516000.0)),
                                                           ("outer", (421000.0, 421000.0)))
              for d, v in zip(("forward", "reverse"), pair)}
    plots.forward_reverse_headline(values, tmp_path / "h.png", quantities=QUANT[1:])
    (ax,) = captured[-1].axes
    lo, hi = ax.get_ylim()
    ticks = [t for t in ax.get_yticks() if lo <= t <= hi]
    assert len(ticks) >= 2 and all("e" not in ax.yaxis.get_major_formatter()(t, 0) for t in ticks)
