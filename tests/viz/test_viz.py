"""viz: matplotlib plots without a display, offscreen pyvista animations, the offscreen probe.

Animations are rendered tiny (200×100, 5 frames) and read back with imageio: the frame count must
match, frames must differ (things move, the time label changes) and must not be blank.  If this
machine cannot render offscreen the animation tests skip with the probe's reason.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import imageio.v3 as iio

from viz import plots, render_check

N_FRAMES = 5
SIZE = (200, 100)


# ----------------------------------------------------------------------------------- helpers
def _read_frames(path: Path) -> np.ndarray:
    frames = iio.imread(path, index=None)
    return np.asarray(frames)[..., :3]


def _assert_not_blank(img: np.ndarray, min_ink: float = 0.005) -> None:
    """Some structure (pixel spread) and some pixels that are clearly not the white background."""
    img = np.asarray(img, float)
    if img.max() <= 1.0:  # matplotlib reads PNGs as floats in [0, 1]
        img = img * 255.0
    rgb = img[..., :3]
    assert rgb.std() > 8.0, f"image looks blank (std {rgb.std():.2f})"
    ink = np.mean(rgb.min(axis=-1) < 200)
    assert ink > min_ink, f"only {ink:.4%} non-background pixels"


def _assert_animation(path: Path, n_frames: int, size: tuple[int, int]) -> np.ndarray:
    assert path.is_file() and path.stat().st_size > 0
    frames = _read_frames(path)
    assert frames.shape[0] == n_frames
    assert frames.shape[1:3] == (size[1], size[0])
    for f in frames:
        _assert_not_blank(f)
    diffs = [np.abs(frames[k + 1].astype(float) - frames[k].astype(float)).mean()
             for k in range(n_frames - 1)]
    assert min(diffs) > 0.05, f"consecutive frames (nearly) identical: {diffs}"
    return frames


def _red_pixels(img: np.ndarray) -> int:
    r, g, b = (img[..., c].astype(int) for c in range(3))
    return int(((r > 170) & (g < 90) & (b < 90)).sum())


def _red_centroid(img: np.ndarray) -> np.ndarray:
    r, g, b = (img[..., c].astype(int) for c in range(3))
    mask = (r > 170) & (g < 90) & (b < 90)
    assert mask.sum() > 0, "current-position marker not visible"
    ys, xs = np.nonzero(mask)
    return np.array([xs.mean(), ys.mean()])


@pytest.fixture(scope="module")
def animate(offscreen):
    from viz import animate
    return animate


def _orbit_data(n_t: int):
    t = np.linspace(0.0, 0.02, n_t)
    w = 2 * np.pi * 50.0
    C = 100e-6
    orbits = {"inner fwd": 0.8 * C * np.column_stack([np.cos(w * t), np.sin(w * t)]),
              "outer fwd": 0.6 * C * np.column_stack([np.cos(-w * t + 1), np.sin(-w * t + 1)])}
    Z = 6
    ph = np.arange(Z)
    rollers = {"inner fwd": 30e-6 * np.stack([np.cos(3 * w * t[:, None] + ph),
                                               np.sin(2 * w * t[:, None] + ph)], axis=-1)}
    return t, orbits, C, rollers


def _train_bodies(n_t: int):
    """Sun, one planet with a 6-roller bearing and cage, ring: a tiny but complete scene."""
    t = np.linspace(0.0, 0.004, n_t)
    zero = np.zeros((n_t, 2))
    wc = 2 * np.pi * 70.0
    bodies = [dict(kind="ring", radius=0.123, teeth=82, xy=zero, theta=-wc * t),
              dict(kind="gear", radius=0.0465, teeth=31, xy=zero, theta=3 * wc * t),
              dict(kind="carrier", radius=0.11, xy=zero, theta=0 * t)]
    c = np.array([0.08, 0.0])
    bodies.append(dict(kind="gear", radius=0.036, teeth=24, xy=zero + c, theta=-4 * wc * t))
    bodies.append(dict(kind="cage", radius=0.0215, xy=zero + c, theta=-1.6 * wc * t))
    for j in range(6):
        a = -1.6 * wc * t + 2 * np.pi * j / 6
        xy = c + 0.0195 * np.column_stack([np.cos(a), np.sin(a)])
        bodies.append(dict(kind="roller", radius=0.00375, xy=xy, theta=10 * wc * t,
                           force=500 * np.clip(np.cos(a), 0, None), ref=xy))
    return t, bodies


# ----------------------------------------------------------------------------------- plots
def _png_ok(path: Path, returned) -> None:
    assert Path(returned) == Path(path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image as mpimg
    _assert_not_blank(mpimg.imread(path))


def test_plots_without_display(tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    t = np.linspace(0, 0.05, 500)
    series = {"mesh force": (2000 + 100 * np.sin(800 * t), 2100 + 90 * np.sin(800 * t + 1)),
              "cage x acceleration": (np.sin(3000 * t), None)}
    p = tmp_path / "sub" / "th.png"  # parent is created
    _png_ok(p, plots.time_histories(t, series, {"mesh force": "N", "cage x acceleration": "m/s²"}, p))

    conds = ["0 kW", "30 kW"]
    table = {"RMS roller load": {"0 kW": (100, 110), "30 kW": (160, 175)},
             "max guide force": {"0 kW": (20, 40), "30 kW": (None, 45)}}  # gap allowed
    p = tmp_path / "bars.png"
    _png_ok(p, plots.bar_chart(conds, table, {"RMS roller load": "N", "max guide force": "N"}, p))

    f = np.linspace(0, 10000, 2001)
    fm, fc = 5740.0, 70.0
    amp = 1 / (1 + ((f - fm) / 20) ** 2) + 0.01
    marks = {"f_m": fm, "f_m+f_c": fm + fc, "f_m−f_c": fm - fc, "f_m+2f_c": fm + 2 * fc,
             "beyond fmax": 9500.0}
    p = tmp_path / "spec.png"
    _png_ok(p, plots.spectrum(f, {"forward": amp, "reverse": 0.7 * amp}, marks, p, fmax=8000,
                              quantity="cage acceleration", unit="m/s²"))

    rows = [("HHT", 1.0, 1e-2), ("HHT", 2.0, 2.5e-3), ("HHT", 4.0, 6e-4), ("Radau", 3.0, 1e-2),
            ("Radau", 6.0, 2e-3)]
    p = tmp_path / "wp.png"
    _png_ok(p, plots.work_precision(rows, p, error_label="relative error"))

    ang = 2 * np.pi * np.arange(12) / 12
    p = tmp_path / "polar.png"
    _png_ok(p, plots.load_distribution(ang, 900 * np.clip(np.cos(ang), 0, None), p))

    labels = ["sun x", "sun y", "sun θ", "carrier θ"]
    p = tmp_path / "modes.png"
    _png_ok(p, plots.mode_shapes([100.0, 250.0, 900.0], np.eye(3, 4) + 0.1, labels, p))


def test_plots_reject_inconsistent_input(tmp_path):
    with pytest.raises(ValueError, match="shapes"):
        plots.mode_shapes([1.0, 2.0], np.ones((2, 3)), ["a", "b"], tmp_path / "m.png")
    with pytest.raises(ValueError, match="empty"):
        plots.time_histories(np.arange(3.0), {}, {}, tmp_path / "t.png")


def test_plot_style_does_not_leak(tmp_path):
    """Plots use rc_context and Figure/Agg directly: the caller's rcParams are untouched."""
    import matplotlib as mpl
    before = dict(mpl.rcParams)
    plots.work_precision([("a", 1.0, 1e-3), ("a", 2.0, 1e-4)], tmp_path / "wp.png")
    assert dict(mpl.rcParams) == before


# ----------------------------------------------------------------------------------- frames
@given(n_t=st.integers(1, 500), max_frames=st.one_of(st.none(), st.integers(1, 600)))
def test_frame_indices(n_t, max_frames):
    from viz.animate import frame_indices
    idx = frame_indices(n_t, max_frames)
    expected = n_t if max_frames is None else min(n_t, max_frames)
    assert idx.size == expected
    assert idx[-1] == n_t - 1                      # the final state is always shown
    assert idx[0] == (0 if expected > 1 else n_t - 1)
    assert np.all(np.diff(idx) > 0)


# ----------------------------------------------------------------------------------- animations
@pytest.mark.parametrize("ext", [".gif", ".mp4"])
def test_cage_orbit_animation(animate, tmp_path, ext):
    t, orbits, C, rollers = _orbit_data(N_FRAMES)
    path = tmp_path / f"orbit{ext}"
    out = animate.cage_orbit_animation(path, t, orbits, C, rollers=rollers, fps=10, size=SIZE)
    assert Path(out) == path
    frames = _assert_animation(path, N_FRAMES, SIZE)
    # the marker travels along the orbit: after half a revolution (frame 2 of 5 over one period)
    # it sits on the far side of the first panel's bore centre
    half = SIZE[0] // 2
    moved = _red_centroid(frames[2][:, :half]) - _red_centroid(frames[0][:, :half])
    assert np.linalg.norm(moved) > 5.0


def test_cage_orbit_animation_legend_and_progress(animate, tmp_path, capsys):
    """The legend strip under the panels carries ink (its glyphs and words) where the frame without it has none;
    progress goes to stderr as plain lines when stderr is not a terminal: the frame count at the start and end."""
    t, orbits, C, rollers = _orbit_data(N_FRAMES)
    size = (480, 240)
    with_legend = animate.cage_orbit_animation(tmp_path / "a.gif", t, orbits, C, rollers=rollers, size=size)
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"animating a.gif: {N_FRAMES} frames"
    assert err[-1].startswith(f"animating a.gif: {N_FRAMES} frames in ") and err[-1].endswith(" s")
    without = animate.cage_orbit_animation(tmp_path / "b.gif", t, orbits, C, rollers=rollers, size=size,
                                           legend=False, progress=False)
    assert capsys.readouterr().err == ""
    # the legend's red dot (the cage centre's mark) sits in the bottom strip; without a legend the only red is the
    # markers on the orbits, higher up
    a, b = _read_frames(with_legend)[-1], _read_frames(without)[-1]
    low = slice(int(0.7 * size[1]), size[1])       # the strip: 30 % of this frame (three lines)
    assert _red_pixels(a[low]) > 0 and _red_pixels(b[low]) == 0
    assert np.mean(a[low].min(axis=-1) < 160) > 0.01                 # and words


def test_cage_orbit_max_frames_subsamples(animate, tmp_path):
    t, orbits, C, _ = _orbit_data(23)
    path = tmp_path / "orbit.gif"
    animate.cage_orbit_animation(path, t, orbits, C, size=SIZE, max_frames=N_FRAMES,
                                 title="cage orbits")
    _assert_animation(path, N_FRAMES, SIZE)


def test_the_animations_render_without_multisampling(animate):
    """pyvista's default 8× multisample anti-aliasing took ≈ 45 % of an animation's time in software OpenGL: the
    animations' plotters are made without it."""
    p = animate._plotter(window_size=SIZE)
    try:
        assert p.ren_win.GetMultiSamples() == 0
    finally:
        p.close()


@pytest.mark.parametrize("ext", [".gif", ".mp4"])
def test_train_animation(animate, tmp_path, ext):
    t, bodies = _train_bodies(N_FRAMES)
    path = tmp_path / f"train{ext}"
    animate.train_animation(path, t, bodies, magnify=2.0, fps=10, size=SIZE)
    frames = _assert_animation(path, N_FRAMES, SIZE)
    # the force colour map (viridis: strongly coloured, not grey) is drawn: rollers and colour bar
    f = frames[0].astype(int)
    chroma = f.max(axis=-1) - f.min(axis=-1)
    assert np.mean(chroma > 80) > 0.002


@pytest.mark.parametrize("forces, factor, unit, top, step", [
    ((0.0, 5150.0), 1e-3, "kN", 6.0, 2.0), ((0.0, 2600.0), 1e-3, "kN", 3.0, 1.0),
    ((0.0, 12345.0), 1e-3, "kN", 12.5, 2.5), ((0.0, 900.0), 1.0, "N", 1000.0, 200.0),
    ((0.0, 999.0), 1.0, "N", 1000.0, 200.0), ((0.0, 1000.0), 1e-3, "kN", 1.0, 0.2)])
def test_force_colour_bar_in_N_or_kN_with_round_labels(forces, factor, unit, top, step):
    """The train animation's colour bar: kN from 1 kN on (as the figures), its unit in the title, from 0 to a round
    top at or above the largest force, a label on every round step (VTK spaces n labels evenly over the limits)."""
    from viz.animate import force_colour_scale

    f, title, (lo, hi), n = force_colour_scale(np.array(forces), "roller load")
    assert (f, title) == (factor, f"roller load ({unit})")
    assert lo == 0.0 and hi == pytest.approx(top) and hi >= max(forces) * factor
    np.testing.assert_allclose(np.linspace(lo, hi, n), np.arange(n) * step, atol=1e-12)
    assert n <= 6


def test_train_animation_colours_rollers_in_the_bars_unit(animate, tmp_path, monkeypatch):
    """The discs' scalars are the forces in the colour bar's unit, and the bar's title names it."""
    import pyvista as pv

    seen = {}
    real_bar, real_mesh = pv.Plotter.add_scalar_bar, pv.Plotter.add_mesh

    def bar(self, *a, **kw):
        seen["bar"] = kw
        return real_bar(self, *a, **kw)

    def mesh(self, m, *a, **kw):
        if kw.get("scalars") == "force":
            seen["clim"], seen["first"] = kw["clim"], np.array(m.cell_data["force"])
        return real_mesh(self, m, *a, **kw)

    monkeypatch.setattr(pv.Plotter, "add_scalar_bar", bar)
    monkeypatch.setattr(pv.Plotter, "add_mesh", mesh)
    t, bodies = _train_bodies(N_FRAMES)
    for b in bodies:
        if b["kind"] == "roller":
            b["force"] = 8.0 * b["force"]             # up to 4 kN
    animate.train_animation(tmp_path / "t.gif", t, bodies, size=SIZE, force_label="roller load")
    assert seen["bar"]["title"] == "roller load (kN)"
    forces = np.array([b["force"][0] for b in bodies if b["kind"] == "roller"])
    np.testing.assert_allclose(seen["first"], forces / 1e3)
    assert seen["clim"][0] == 0.0 and seen["clim"][1] >= forces.max() / 1e3


def test_animation_argument_errors(tmp_path):
    from viz import animate
    t, orbits, C, _ = _orbit_data(4)
    with pytest.raises(ValueError, match="format"):
        animate.cage_orbit_animation(tmp_path / "x.avi", t, orbits, C)
    with pytest.raises(ValueError, match="shape"):
        animate.cage_orbit_animation(tmp_path / "x.gif", t[:3], orbits, C)
    t, bodies = _train_bodies(4)
    del bodies[-1]["ref"]
    with pytest.raises(ValueError, match="ref"):
        animate.train_animation(tmp_path / "x.gif", t, bodies, magnify=10.0)
    with pytest.raises(ValueError, match="kind"):
        animate.train_animation(tmp_path / "x.gif", t, [dict(bodies[0], kind="planet")])
    assert not any(tmp_path.iterdir())  # nothing was written


# ----------------------------------------------------------------------------------- probe
@pytest.fixture
def fresh_probe(monkeypatch):
    """Run the probe afresh and restore the environment variable it may export."""
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    render_check._check.cache_clear()
    yield monkeypatch
    render_check._check.cache_clear()


def test_probe_reports_missing_libraries(fresh_probe):
    fresh_probe.setattr(render_check, "_find_libs", lambda: {"EGL": None, "OSMesa": None})
    fresh_probe.delenv("DISPLAY", raising=False)
    ok, msg = render_check.check_offscreen()
    assert not ok
    with pytest.raises(RuntimeError, match="libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6"):
        render_check.require_offscreen()


def test_probe_survives_a_crashing_backend(fresh_probe):
    """Forcing VTK onto OSMesa where libOSMesa is missing segfaults VTK; only the probe dies."""
    if render_check._find_libs()["OSMesa"] is not None:
        pytest.skip("libOSMesa is installed here, so this backend does not crash")
    fresh_probe.setenv("VTK_DEFAULT_OPENGL_WINDOW", "vtkOSOpenGLRenderWindow")
    ok, msg = render_check.check_offscreen()
    assert not ok
    assert "vtkOSOpenGLRenderWindow" in msg and "apt-get install" in msg


def test_probe_finds_a_working_backend(fresh_probe):
    ok, msg = render_check.check_offscreen()
    if not ok:
        pytest.skip(msg)
    assert "works via" in msg
    import os
    assert os.environ["VTK_DEFAULT_OPENGL_WINDOW"] in msg  # exported for in-process renders



def test_a_probe_started_beside_answers_the_caller_once(fresh_probe):
    """check_offscreen_beside starts the probe in a thread and returns before it ends; the caller's check_offscreen
    then waits for that probe's answer instead of starting a second subprocess."""
    import threading

    calls, release = [], threading.Event()

    def probe(cls, timeout):
        calls.append(cls)
        release.wait(10)            # the probe's subprocess, still running when the caller asks
        return True, f"offscreen rendering works via {cls}"

    fresh_probe.setattr(render_check, "_find_libs", lambda: {"EGL": "libEGL.so.1", "OSMesa": None})
    fresh_probe.setattr(render_check, "_probe", probe)
    render_check.check_offscreen_beside()
    for _ in range(200):            # the thread has started its probe
        if calls:
            break
        threading.Event().wait(0.01)
    assert calls == ["vtkEGLRenderWindow"]
    answer = []
    asking = threading.Thread(target=lambda: answer.append(render_check.check_offscreen()))
    asking.start()
    asking.join(0.2)
    assert asking.is_alive() and not answer       # the caller waits for the running probe
    release.set()
    asking.join(10)
    assert answer == [(True, "offscreen rendering works via vtkEGLRenderWindow (EGL: libEGL.so.1)")]
    assert calls == ["vtkEGLRenderWindow"]        # one probe for both


def test_a_probe_started_beside_leaves_the_environment_to_the_caller(fresh_probe):
    """The thread only finds the answer; the caller's check_offscreen exports the proven window class (the
    environment is not written while the caller imports VTK)."""
    import os
    import threading

    fresh_probe.setattr(render_check, "_find_libs", lambda: {"EGL": "libEGL.so.1", "OSMesa": None})
    fresh_probe.setattr(render_check, "_probe", lambda cls, timeout: (True, f"offscreen rendering works via {cls}"))
    render_check.check_offscreen_beside()
    for t in [t for t in threading.enumerate() if t.name == "dpgt-offscreen-check"]:
        t.join(10)
    assert render_check._check.cache_info().currsize == 1 and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ
    assert render_check.check_offscreen()[0] and os.environ["VTK_DEFAULT_OPENGL_WINDOW"] == "vtkEGLRenderWindow"

# ----------------------------------------------------------------------------------- GIF streaming
def _film(n: int, size=(240, 160)) -> list[np.ndarray]:
    """Synthetic frames of few colours: a square moving over a white ground, a bar growing, one frame repeated and
    one differing from its predecessor in a single pixel (the delta encoder's edge cases)."""
    W, H = size
    out = []
    for k in range(n):
        f = np.full((H, W, 3), 255, np.uint8)
        x = 5 + 3 * k % (W - 30)
        f[40:60, x:x + 20] = (213, 0, 0)
        f[H - 10:H - 4, 5:5 + 2 * k % (W - 10)] = (31, 95, 168)
        out.append(f)
    out[7] = out[6].copy()                    # the same picture twice
    out[9] = out[8].copy()
    out[9][0, 0] = (213, 0, 0)                # one pixel changed (to a colour of the palette)
    return out


def test_gif_stream_writes_what_pillow_writes_from_the_whole_film(tmp_path):
    """The GIF written frame by frame decodes to the same pictures as Pillow's own writer given every frame at once
    (the earlier path): same palette frames, frame count, duration and loop."""
    from PIL import Image, ImageSequence

    from viz import animate

    frames = _film(30)
    idx = np.arange(len(frames))
    animate._write_film(tmp_path / "s.gif", 20.0, idx, lambda i: frames[i])
    pick = np.unique(np.linspace(0, len(frames) - 1, animate.GIF_PALETTE_FRAMES).astype(int))
    pal = animate._gif_palette([frames[i] for i in pick])
    ims = [Image.fromarray(f).quantize(palette=pal, dither=Image.Dither.NONE) for f in frames]
    ims[0].save(tmp_path / "p.gif", format="GIF", save_all=True, append_images=ims[1:], duration=50.0, loop=0,
                optimize=True)

    def decoded(path):
        with Image.open(path) as im:
            return ([np.asarray(f.convert("RGB")).copy() for f in ImageSequence.Iterator(im)],
                    [f.info.get("duration") for f in ImageSequence.Iterator(im)], im.info.get("loop"))

    mine, durations, loop = decoded(tmp_path / "s.gif")
    assert len(mine) == len(frames) and set(durations) == {50} and loop == 0
    # Pillow merges the repeated frame into its predecessor's duration: compare picture by picture in time
    ref, ref_durations, _ = decoded(tmp_path / "p.gif")
    ref_in_time = [f for f, d in zip(ref, ref_durations) for _ in range(round(d / 50))]
    assert len(ref_in_time) == len(mine)
    for k, (a, b) in enumerate(zip(mine, ref_in_time)):
        np.testing.assert_array_equal(a, b, err_msg=f"frame {k}")
    np.testing.assert_array_equal(mine[8][0, 0], (255, 255, 255))      # the one changed pixel is there
    np.testing.assert_array_equal(mine[9][0, 0], (213, 0, 0))
    assert not (tmp_path / ".s.gif.tmp").exists()


def test_gif_stream_keeps_a_few_frames_not_the_film(tmp_path):
    """Memory: the frames are written as they are rendered, so the peak holds the palette's frames and one or two
    more, not the film (the earlier writer kept every frame until the end: here 60)."""
    import tracemalloc

    from viz import animate

    frames = _film(60, size=(400, 300))
    one = frames[0].nbytes
    render = lambda i: frames[i].copy()       # a new array per render, as a screenshot is
    tracemalloc.start()
    try:
        animate._write_film(tmp_path / "m.gif", 20.0, np.arange(len(frames)), render)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < (2 * animate.GIF_PALETTE_FRAMES + 4) * one < len(frames) * one


def test_a_failed_film_leaves_no_file(tmp_path):
    from viz import animate

    frames = _film(12)

    def render(i):
        if i == 10:
            raise RuntimeError("renderer died")
        return frames[i]
    with pytest.raises(RuntimeError, match="renderer died"):
        animate._write_film(tmp_path / "f.gif", 20.0, np.arange(12), render)
    assert list(tmp_path.iterdir()) == []


def test_a_figure_is_laid_out_and_drawn_once_with_the_pixels_of_matplotlibs_own_save(tmp_path, monkeypatch):
    """plots._save takes the layout engine off after laying the figure out at the saved resolution: one draw instead
    of savefig's two, and the PNG pixel for pixel the one savefig writes with the engine on (a skipped or misplaced
    layout, or a layout at the figure's own dpi, moves pixels)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = np.linspace(0.0, 0.02, 400)
    rows = [("bearing load, radial", "N", {"inner": {"forward": (t, 9e3 + 800 * np.sin(900 * t)),
                                                     "reverse": (t, 1.2e4 + 500 * np.cos(700 * t))},
                                           "outer": {"forward": (t, 1.1e4 + 0 * t)}}),
            ("cage slip", "%", {"inner": {"forward": (t, 0.5 + 0.2 * np.sin(300 * t))}})]
    draws = []
    real_draw = Figure.draw
    monkeypatch.setattr(Figure, "draw", lambda self, r: (draws.append(1), real_draw(self, r))[1])
    ours = plots.time_history_group(rows, tmp_path / "ours.png", columns=["inner", "outer"], title="t",
                                    separate_runs=True)
    assert len(draws) == 1

    def plain(fig, path):
        FigureCanvasAgg(fig)
        fig.savefig(path, format="png")
        return Path(path)
    monkeypatch.setattr(plots, "_save", plain)
    theirs = plots.time_history_group(rows, tmp_path / "theirs.png", columns=["inner", "outer"], title="t",
                                      separate_runs=True)
    assert len(draws) == 3                                   # matplotlib's own: a layout pass, then the picture
    a, b = iio.imread(ours), iio.imread(theirs)
    assert a.shape == b.shape and np.array_equal(a, b)
