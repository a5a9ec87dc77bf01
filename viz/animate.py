"""Offscreen pyvista animations of saved results (GIF or MP4, chosen by the file extension).

Both animations draw in 2-D: a parallel-projection camera looks down the z axis and every panel has a
fixed view, so frames are directly comparable.  Geometry is built once with a fixed topology; each frame
only moves points (vectorised over all bodies of a kind) and updates text, then a screenshot goes to the
writer.  Every frame carries a time label ("t = 12.3 ms") and a scale bar.

Inputs are plain numpy arrays in SI units; nothing here knows about the engine.
"""
from __future__ import annotations

import math
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path

import imageio.v2 as iio2
import numpy as np
import pyvista as pv
from PIL import GifImagePlugin, Image
from tqdm.auto import tqdm

from .plots import display_unit
from .render_check import require_offscreen

pv.OFF_SCREEN = True  # before any plotter exists: never try to open a window

__all__ = ["cage_orbit_animation", "excursion_factor", "train_animation", "frame_indices", "force_colour_scale"]

_BG = "white"
_INK = "black"
_KIND_COLOR = {"gear": "#1f4e8c", "ring": "#444444", "carrier": "#2e7d32", "cage": "#b5651d",
               "roller": "#333333"}
_PANEL_COLORS = ["#1f5fa8", "#e07b00", "#2e7d32", "#8e24aa", "#c62828", "#00838f"]
_KINDS = ("gear", "ring", "carrier", "roller", "cage")


# ----------------------------------------------------------------------------------------------
# small helpers

def frame_indices(n_t: int, max_frames: int | None) -> np.ndarray:
    """Indices of the samples that become frames: all of them, or max_frames spread evenly."""
    if n_t < 1:
        raise ValueError("t must contain at least one sample")
    if max_frames is None or max_frames >= n_t:
        return np.arange(n_t)
    if max_frames < 1:
        raise ValueError("max_frames must be >= 1")
    if max_frames == 1:   # a single frame shows the final state (the whole orbit trace)
        return np.array([n_t - 1])
    return np.unique(np.round(np.linspace(0, n_t - 1, int(max_frames))).astype(int))


def _nice_length(target: float) -> float:
    """Largest 1/2/5 × 10^k not above target (the scale-bar length)."""
    if not target > 0:
        raise ValueError("scene has no extent")
    e = 10.0 ** math.floor(math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * e <= target * (1 + 1e-9):
            return m * e
    return e


def _format_length(L: float) -> str:
    for unit, s in (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9)):
        if L >= s * (1 - 1e-9):
            return f"{L / s:g} {unit}"
    return f"{L:.3g} m"


def _time_formatter(t_frames: np.ndarray):
    """Fixed unit and just enough decimals to tell successive frames apart."""
    span = float(np.max(np.abs(t_frames))) if t_frames.size else 0.0
    scale, unit = (1e3, "ms") if span < 2.0 else (1.0, "s")
    dt = np.diff(t_frames) * scale
    dt = dt[dt > 0]
    # one digit finer than the frame spacing, so that successive labels differ
    dec = 1 if dt.size == 0 else int(np.clip(math.ceil(-math.log10(dt.min()) - 1e-9) + 1, 1, 6))
    return lambda tt: f"t = {tt * scale:.{dec}f} {unit}"


def _output_path(path, fps: float) -> Path:
    """Check the output arguments before any rendering starts."""
    if not float(fps) > 0:
        raise ValueError("fps must be positive")
    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"unsupported animation format {path.suffix!r}: use .gif or .mp4")
    return path


def _even_size(size: Sequence[int], path: Path) -> tuple[int, int]:
    w, h = int(size[0]), int(size[1])
    if w < 16 or h < 16:
        raise ValueError(f"size {size} is too small")
    if path.suffix.lower() == ".mp4":  # H.264 with yuv420p needs even dimensions
        w += w % 2
        h += h % 2
    return w, h


def _font(h_px: int, frac: float = 0.025, text: str | None = None, w_px: int | None = None) -> int:
    """VTK font size frac·h_px, reduced if needed so that `text` fits in w_px.

    VTK draws a cap height of about 1.45 × the font size and an average character about 0.8 × the
    font size wide, bold about 1.0 × (measured with the default Arial of the VTK wheels)."""
    fs = h_px * frac
    if text is not None and w_px is not None:
        fs = min(fs, 0.92 * w_px / (1.0 * max(len(text), 1)))  # bold text is wider
    return int(max(6, round(fs)))


GIF_PALETTE_FRAMES = 8     # frames spread over a GIF's film that its one palette is taken from
_CLEAR = 255               # the palette index a GIF's delta frames mark unchanged pixels with (255 colours: free)


def _write_film(path: Path, fps: float, idx: np.ndarray, render, bar: "_Progress | None" = None) -> None:
    """Render the frames ``idx`` (``render(i)``: frame i as an RGB array; it sets everything the frame shows, so frames
    can be rendered in any order) and write them one at a time: memory holds a frame or two, whatever the film's
    length. A GIF's one 255-colour palette is taken from GIF_PALETTE_FRAMES frames spread over the film, rendered
    first (a few more renders instead of every frame kept until the palette can be taken); an MP4 goes to ffmpeg."""
    if path.suffix.lower() == ".gif":
        pick = np.unique(np.linspace(0, idx.size - 1, GIF_PALETTE_FRAMES).astype(int))
        writer = _GifStream(path, fps, _gif_palette([render(idx[k]) for k in pick]))
    else:
        writer = _Mp4Stream(path, fps)
    with writer:
        for i in idx:
            writer.append(render(i))
            if bar is not None:
                bar.update()


def _gif_palette(frames: Sequence[np.ndarray]) -> Image.Image:
    """One palette for a film (these figures have few colours): mapping each frame to it is ≈ 20× faster than
    Pillow's per-frame median-cut quantisation and keeps colours steady from frame to frame."""
    return Image.fromarray(np.concatenate([_rgb(f) for f in frames], axis=0)).quantize(
        colors=255, method=Image.Quantize.FASTOCTREE)


def _rgb(img: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(img[..., :3], dtype=np.uint8)


class _Mp4Stream:
    """Frames to an MP4 (ffmpeg/H.264) as they come."""

    def __init__(self, path: Path, fps: float):
        path.parent.mkdir(parents=True, exist_ok=True)
        self._mp4 = iio2.get_writer(str(path), format="FFMPEG", mode="I", fps=float(fps), codec="libx264",
                                    pixelformat="yuv420p", quality=8, macro_block_size=2, ffmpeg_log_level="error")

    def __enter__(self) -> "_Mp4Stream":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self._mp4.close()

    def append(self, img: np.ndarray) -> None:
        self._mp4.append_data(_rgb(img))


class _GifStream:
    """A looping GIF written frame by frame (Pillow's GIF frame encoder), atomically (a temporary file replaced at
    the end; removed if the film fails). Every frame is mapped to ``palette`` (the global colour table); after the
    first, a frame is written as the box around the pixels that changed, the unchanged ones inside it transparent
    (as Pillow's optimize=True writes a film it holds whole)."""

    def __init__(self, path: Path, fps: float, palette: Image.Image):
        path.parent.mkdir(parents=True, exist_ok=True)
        self.path, self.palette, self.ms = path, palette, 1000.0 / float(fps)
        self.tmp = path.with_name(f".{path.name}.tmp")
        self._fp = open(self.tmp, "wb")
        self._prev: np.ndarray | None = None

    def __enter__(self) -> "_GifStream":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is None and self._prev is not None:
                self._fp.write(b";")          # trailer
                self._fp.close()
                self.tmp.replace(self.path)
        finally:
            self._fp.close()
            self.tmp.unlink(missing_ok=True)

    def append(self, img: np.ndarray) -> None:
        im = Image.fromarray(_rgb(img)).quantize(palette=self.palette, dither=Image.Dither.NONE)
        cur = np.asarray(im)
        if self._prev is None:     # duration in ms per frame; loop=0 repeats forever
            header, _ = GifImagePlugin.getheader(im, info={"loop": 0, "duration": self.ms})
            self._write(header + GifImagePlugin.getdata(im, (0, 0), duration=self.ms))
        else:
            changed = cur != self._prev
            rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
            if rows.size == 0:     # the same picture: one pixel, unchanged, keeps the frame's time
                rows, cols = np.zeros(1, int), np.zeros(1, int)
            box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
            delta = Image.fromarray(np.where(changed[box], cur[box], _CLEAR).astype(np.uint8), "P")
            delta.putpalette(im.getpalette())
            self._write(GifImagePlugin.getdata(delta, (int(cols[0]), int(rows[0])), duration=self.ms,
                                               transparency=_CLEAR))
        self._prev = cur

    def _write(self, chunks) -> None:
        for c in chunks:
            self._fp.write(c)


def _lines_cells(segments: Sequence[Sequence[int]]) -> np.ndarray:
    """VTK connectivity for a list of point-index polylines."""
    out = []
    for s in segments:
        out.append(len(s))
        out.extend(int(i) for i in s)
    return np.asarray(out, dtype=np.int64)


def _xyz(xy: np.ndarray, z: float) -> np.ndarray:
    return np.column_stack([xy, np.full(len(xy), z)])


class _View:
    """A fixed 2-D parallel-projection view of one renderer and the overlays every frame shares."""

    def __init__(self, plotter: pv.Plotter, panel: tuple[int, int], px_size: tuple[int, int],
                 centre: tuple[float, float], half_w: float, half_h: float, band=(0.0, 1.0, 0.0, 1.0)):
        """Fit the box centre ± (half_w, half_h) inside the viewport fraction band = (x0, x1, y0, y1)."""
        self.p, self.panel = plotter, panel
        self.w_px, self.h_px = px_size
        aspect = self.w_px / self.h_px
        bx0, bx1, by0, by1 = band
        # parallel_scale is half the visible height; choose it so the box fits both ways.
        hs = max(half_h / (by1 - by0), half_w / ((bx1 - bx0) * aspect))
        self.hs, self.aspect = hs, aspect
        # shift the focal point so the box centre lands in the middle of the band
        fx, fy = (bx0 + bx1) / 2, (by0 + by1) / 2
        cx = centre[0] - (2 * fx - 1) * hs * aspect
        cy = centre[1] - (2 * fy - 1) * hs
        self.cx, self.cy = cx, cy
        plotter.subplot(*panel)
        d = 10.0 * hs
        plotter.camera_position = [(cx, cy, d), (cx, cy, 0.0), (0.0, 1.0, 0.0)]
        plotter.enable_parallel_projection()
        plotter.camera.parallel_scale = hs
        plotter.camera.clipping_range = (1e-3 * d, 100.0 * d)
        self.z_step = 1e-3 * hs  # layer spacing: later layers sit nearer the camera

    def world(self, fx: float, fy: float) -> tuple[float, float]:
        """World point at viewport fraction (fx, fy)."""
        return (self.cx + (2 * fx - 1) * self.hs * self.aspect, self.cy + (2 * fy - 1) * self.hs)

    def text(self, s: str, pos: tuple[float, float], size: int, justify="left", color=_INK,
             bold=False, valign="bottom"):
        self.p.subplot(*self.panel)
        actor = self.p.add_text(s, position=pos, viewport=True, font_size=size, color=color)
        actor.prop.justification_horizontal = justify
        actor.prop.justification_vertical = valign
        actor.prop.bold = bold
        return actor

    def scale_bar(self, fx0=0.05, fy0=0.05, frac=0.3, size=9):
        """A nice-length segment with end ticks at the lower left, its length written above it."""
        width = 2 * self.hs * self.aspect
        L = _nice_length(frac * width)
        x0, y0 = self.world(fx0, fy0)
        tick = 0.02 * 2 * self.hs
        z = 50 * self.z_step
        pts = np.array([[x0, y0, z], [x0 + L, y0, z], [x0, y0 - tick, z], [x0, y0 + tick, z],
                        [x0 + L, y0 - tick, z], [x0 + L, y0 + tick, z]])
        bar = pv.PolyData(pts, lines=_lines_cells([[0, 1], [2, 3], [4, 5]]))
        self.p.subplot(*self.panel)
        self.p.add_mesh(bar, color=_INK, line_width=2, lighting=False)
        self.text(_format_length(L), (fx0, fy0 + 0.035), size, justify="left")
        return L

    def line_height(self, size: int) -> float:
        """Height of one text line of font size `size`, as a fraction of the viewport."""
        return 1.5 * size / self.h_px


def _circle(n: int) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([np.cos(a), np.sin(a)])


def _screenshot(plotter: pv.Plotter, size: tuple[int, int]) -> np.ndarray:
    plotter.render()  # screenshot() alone re-reads the old buffer after the first frame
    img = plotter.screenshot(return_img=True)
    if img.shape[:2] != (size[1], size[0]):
        raise RuntimeError(f"renderer returned {img.shape[1]}x{img.shape[0]}, expected "
                           f"{size[0]}x{size[1]}")
    return img


class _Progress:
    """Progress of a frame loop on stderr: a tqdm bar on a terminal, otherwise plain lines (one at the start, one
    every ``PLAIN_EVERY`` seconds, one at the end) — a log file or a pipe gets no escape codes."""
    PLAIN_EVERY = 10.0

    def __init__(self, total: int, path: Path, show: bool = True):
        self.total, self.path, self.show, self.n = int(total), path, bool(show), 0
        self._time = time.perf_counter
        self._start = self._last = self._time()
        self.bar = None
        if not self.show:
            return
        if sys.stderr.isatty():
            self.bar = tqdm(total=self.total, desc=f"animating {path.name}", unit="frame", leave=False)
        else:
            print(f"animating {path.name}: {self.total} frames", file=sys.stderr, flush=True)

    def update(self) -> None:
        self.n += 1
        if not self.show:
            return
        if self.bar is not None:
            self.bar.update(1)
            return
        now = self._time()
        if now - self._last >= self.PLAIN_EVERY and self.n < self.total:
            self._last = now
            left = (self.total - self.n) * (now - self._start) / self.n
            print(f"animating {self.path.name}: frame {self.n} of {self.total}, about {left:.0f} s left",
                  file=sys.stderr, flush=True)

    def close(self) -> None:
        if not self.show:
            return
        if self.bar is not None:
            self.bar.close()
        print(f"animating {self.path.name}: {self.n} frames in {self._time() - self._start:.1f} s",
              file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------------------------
# cage orbits

def _orbit_inputs(t, orbits, clearance_m, rollers):
    """Checked arrays of :func:`cage_orbit_animation`: (t, labels, orbits, clearances, roller offsets)."""
    t = np.asarray(t, float)
    if not orbits:
        raise ValueError("orbits is empty")
    labels = list(orbits)
    n_t = t.size
    orb = {k: np.asarray(v, float) for k, v in orbits.items()}
    for k, v in orb.items():
        if v.shape != (n_t, 2):
            raise ValueError(f"orbits[{k!r}] has shape {v.shape}, expected ({n_t}, 2)")
    clr = {k: float(clearance_m[k] if isinstance(clearance_m, Mapping) else clearance_m)
           for k in labels}
    if any(not c > 0 for c in clr.values()):
        raise ValueError("clearance_m must be positive")
    rol = {}
    for k, v in (rollers or {}).items():
        if k not in orb:
            raise ValueError(f"rollers[{k!r}] has no matching orbit")
        v = np.asarray(v, float)
        if v.ndim != 3 or v.shape[0] != n_t or v.shape[2] != 2:
            raise ValueError(f"rollers[{k!r}] has shape {v.shape}, expected ({n_t}, Z, 2)")
        rol[k] = v
    return t, labels, orb, clr, rol


def _plotter(**kw) -> pv.Plotter:
    """An offscreen plotter without pyvista's default 8× multisample anti-aliasing: in Mesa's software OpenGL it
    cost ≈ 45 % of an animation (condition 3's 150 frames: 3.3–4.1 s against 6.4–7.3 s, alternated), for edges the
    GIF's 255-colour palette keeps only in part (the GIF half the size); text stays anti-aliased (FreeType)."""
    p = pv.Plotter(off_screen=True, **kw)
    p.disable_anti_aliasing(all_renderers=True)
    return p


def _panels_with_title(W, H, n, title, legend: float = 0.0):
    """An offscreen plotter with n panels side by side under an optional title strip and over an optional
    legend strip of height fraction ``legend``: (plotter, row of the panels, height fraction of the title strip,
    row of the legend or None, height fraction of the legend strip)."""
    strip = 0.13 if title else 0.0
    leg = float(legend)
    weights = ([strip] if title else []) + [1 - strip - leg] + ([leg] if legend else [])
    rows = len(weights)
    row = 1 if title else 0
    leg_row = row + 1 if legend else None
    groups = ([(0, np.s_[:])] if title else []) + ([(leg_row, np.s_[:])] if legend else [])
    if rows > 1:
        p = _plotter(window_size=(W, H), shape=(rows, n), row_weights=weights, groups=groups, border=False)
    else:
        p = _plotter(window_size=(W, H), shape=(1, n), border=False)
    p.set_background(_BG, all_renderers=True)
    if title:
        p.subplot(0, 0)
        tt = p.add_text(title, position=(0.5, 0.5), viewport=True, font_size=_font(H, 0.045, title, W), color=_INK)
        tt.prop.justification_horizontal = "center"
        tt.prop.justification_vertical = "center"
        tt.prop.bold = True
    return p, row, strip, leg_row, leg


def _legend_strip(p, row: int, px: tuple[int, int], entries: Sequence[tuple], fs: int) -> None:
    """A legend across the strip ``row``: entries (glyph, colour, words), glyph "line", "dot" or "ring"; the
    glyphs are drawn as geometry (VTK's font has no symbols), the words as text whose widths are measured on the
    rendered strip. The font shrinks to fit the width, down to a legible minimum; below it the entries go on
    as many lines as they need — nothing is clipped."""
    W, H = px
    p.subplot(row, 0)
    glyph_w, pad, gap = 24.0, 5.0, 16.0          # [px]
    texts = [p.add_text(words, position=(0.0, 0.5), viewport=True, font_size=fs, color=_INK) for _, _, words in entries]
    for t in texts:
        t.prop.justification_horizontal = "left"
        t.prop.justification_vertical = "center"
    bb = [0.0] * 4

    def widths():
        p.render()
        out = []
        for t in texts:
            t.GetBoundingBox(p.renderer, bb)
            out.append(glyph_w + pad + (bb[1] - bb[0]) + gap)
        return out

    def lines(ws):
        """Entries split into consecutive lines, each at most 0.97 W wide."""
        out, cur, width = [], [], 0.0
        for i, w in enumerate(ws):
            if cur and width + w - gap > 0.97 * W:
                out.append(cur)
                cur, width = [], 0.0
            cur.append(i)
            width += w
        return out + [cur]

    size = int(texts[0].prop.font_size)          # VTK's own units (pyvista scales font_size)
    ws = widths()
    while len(lines(ws)) > 1 and size > 12:      # shrink first, down to a legible size
        size -= 1
        for t in texts:
            t.prop.font_size = size
        ws = widths()
    rows = lines(ws)
    # the strip's camera: one world unit per pixel, origin at the lower left
    p.camera_position = [(W / 2, H / 2, 10.0 * W), (W / 2, H / 2, 0.0), (0.0, 1.0, 0.0)]
    p.enable_parallel_projection()
    p.camera.parallel_scale = H / 2
    p.camera.clipping_range = (1.0, 100.0 * W)
    for k, members in enumerate(rows):
        y = H * (1.0 - (k + 0.5) / len(rows))
        x = 0.5 * (W - sum(ws[i] for i in members) + gap)
        for i in members:
            glyph, color, _ = entries[i]
            if glyph == "line":
                pts = np.array([[x, y, 0.0], [x + glyph_w, y, 0.0]])
                p.add_mesh(pv.PolyData(pts, lines=_lines_cells([[0, 1]])), color=color, line_width=2, lighting=False)
            elif glyph == "dot":
                p.add_mesh(pv.PolyData(np.array([[x + glyph_w / 2, y, 0.0]])), color=color, point_size=max(5, size // 3),
                           render_points_as_spheres=True, lighting=False)
            else:   # ring
                c = _circle(32) * 0.3 * glyph_w + [x + glyph_w / 2, y]
                p.add_mesh(pv.PolyData(_xyz(c, 0.0), lines=_lines_cells([list(range(32)) + [0]])), color=color,
                           line_width=1.5, lighting=False)
            texts[i].position = ((x + glyph_w + pad) / W, y / H)
            x += ws[i]


def _legend_height(W: int, H: int, n_entries: int) -> float:
    """Height fraction of the legend strip: one line of text (≈ 30 px), two where the frame is narrow."""
    lines = 1 if W >= 1100 or n_entries <= 3 else (2 if W >= 560 else 3)
    return min(0.3, max(0.07, lines * 26.0 / H))


def _orbit_panel(p, view, orbit, clearance, extent, col, panel_px):
    """Static parts of one orbit panel (clearance circle, bore-centre cross) and the moving trail and
    marker, which are returned."""
    z = view.z_step
    circ = pv.PolyData(_xyz(clearance * _circle(180), z), lines=_lines_cells([list(range(180)) + [0]]))
    p.add_mesh(circ, color="#888888", line_width=2, lighting=False)
    cross = 0.06 * extent  # bore centre
    cpts = np.array([[-cross, 0, z], [cross, 0, z], [0, -cross, z], [0, cross, z]])
    p.add_mesh(pv.PolyData(cpts, lines=_lines_cells([[0, 1], [2, 3]])), color="#888888", line_width=1,
               lighting=False)
    trail = pv.PolyData(_xyz(orbit, 2 * z), lines=_lines_cells([[0, 0]]))
    p.add_mesh(trail, color=col, line_width=1.5, lighting=False)
    marker = pv.PolyData(_xyz(orbit[:1], 3 * z))
    p.add_mesh(marker, color="#d50000", point_size=max(5, panel_px[1] // 40), render_points_as_spheres=True,
               lighting=False)
    return trail, marker


def _roller_ring(p, view, Z, ring_r, r_roll, col):
    """Z schematic rollers on a ring: grey ideal positions and a moving copy (returned with the ideal
    centres and the roller outline, for the frame loop)."""
    z = view.z_step
    ang = 2 * np.pi * np.arange(Z) / Z
    ideal = ring_r * np.column_stack([np.cos(ang), np.sin(ang)])
    unit = _circle(32)
    # one closed polyline per roller; ideal positions stay put, the others move
    cells = _lines_cells([list(range(32 * i, 32 * i + 32)) + [32 * i] for i in range(Z)])
    ghost = (ideal[:, None, :] + r_roll * unit[None]).reshape(-1, 2)
    p.add_mesh(pv.PolyData(_xyz(ghost, z), lines=cells), color="#bbbbbb", line_width=1, lighting=False)
    moving = pv.PolyData(_xyz(ghost, 2 * z), lines=cells)
    p.add_mesh(moving, color=col, line_width=1.5, lighting=False)
    return moving, ideal, r_roll * unit


def _orbit_scales(orb, clr, rol, magnify):
    """Panel geometry of the orbit animation: E bounds each orbit; rollers sit on a schematic ring
    (radius ring_r, drawn radius r_roll) outside it; one roller-offset magnification for all panels, so
    that they compare (auto: the largest offset moves a roller by half its drawn radius in the
    tightest panel)."""
    E = {k: 1.08 * max(clr[k], float(np.nanmax(np.hypot(v[:, 0], v[:, 1])))) for k, v in orb.items()}
    ring_r = {k: 1.45 * E[k] for k in rol}
    r_roll = {k: min(0.32 * 2 * np.pi * ring_r[k] / v.shape[1], 0.22 * E[k]) for k, v in rol.items()}
    max_off = {k: float(np.nanmax(np.hypot(v[..., 0], v[..., 1]))) for k, v in rol.items()}
    if magnify is not None:
        mag = float(magnify)
    else:
        ratios = [0.5 * r_roll[k] / max_off[k] for k in rol if max_off[k] > 0]
        mag = min(ratios) if ratios else 1.0
    return E, ring_r, r_roll, max_off, mag


EXCURSION_SPAN = 0.5     # the magnified excursion reaches about this fraction of the guide clearance


def excursion_factor(orbits: Mapping[str, np.ndarray], clearance: Mapping[str, float]) -> float:
    """One magnification of the cage centre's excursion about its mean for every panel (so that they compare): the
    largest excursion reaches :data:`EXCURSION_SPAN` of its clearance in the panel where that needs the least
    magnification, rounded down to 1, 2 or 5 × 10^k; 1 when the cages already move that far."""
    ratios = []
    for lab, e in orbits.items():
        dev = float(np.nanmax(np.hypot(*(e - np.nanmean(e, axis=0)).T)))
        if dev > 0:
            ratios.append(EXCURSION_SPAN * float(clearance[lab]) / dev)
    k = min(ratios) if ratios else 1.0
    if k <= 2.0:
        return 1.0
    decade = 10.0 ** np.floor(np.log10(k))
    return float(max(m for m in (1.0, 2.0, 5.0) if m * decade <= k) * decade)


def cage_orbit_animation(path, t, orbits: Mapping[str, np.ndarray], clearance_m,
                         magnify: float | None = None, rollers: Mapping[str, np.ndarray] | None = None,
                         fps: float = 20, size: Sequence[int] = (800, 400), title: str | None = None,
                         max_frames: int | None = None, legend: bool = True, progress: bool = True,
                         excursion: float | None = None) -> Path:
    """Cage-centre orbits inside the guiding clearance, one panel per label, side by side.

    t: (n_t,) s.  orbits: label -> (n_t, 2) cage-centre offset from the bore centre, m.
    clearance_m: radial guiding clearance C_g (float, or label -> float).  Each panel shows the
    clearance circle, the orbit drawn so far and a marker at the current point, all to true scale
    (the scale bar reads offsets).
    rollers: optional label -> (n_t, Z, 2) roller-centre offsets from their ideal pocket positions, m.
    They are drawn schematically as Z small circles on a ring around the clearance circle (grey:
    ideal position, coloured: displaced position); the offsets are multiplied by `magnify` (None:
    chosen so the largest offset is about half a roller-circle radius; the factor is written in the legend).
    legend: a strip under the panels saying what each mark is (the clearance circle, the cage centre and its
    trail, the rollers), with the guide clearance and the rollers' magnification. progress: frames rendered, on
    stderr (:class:`_Progress`). excursion: the cage centre drawn at its mean position plus ``excursion`` times its
    excursion from it (None: :func:`excursion_factor`, so that a cage pressed into its land at speed, moving a
    few µm, is seen moving; 1 when it already moves over a good part of the clearance); the factor is in the legend.
    """
    path = _output_path(path, fps)
    t, labels, orb, clr, rol = _orbit_inputs(t, orbits, clearance_m, rollers)
    k_exc = excursion_factor(orb, clr) if excursion is None else float(excursion)
    if k_exc != 1.0:
        orb = {lab: np.nanmean(e, axis=0) + k_exc * (e - np.nanmean(e, axis=0)) for lab, e in orb.items()}
    n_t = t.size
    require_offscreen()
    W, H = _even_size(size, path)
    idx = frame_indices(n_t, max_frames)
    tfmt = _time_formatter(t[idx])

    n = len(labels)
    n_entries = 5 if rol else 3
    p, row, strip, leg_row, leg = _panels_with_title(W, H, n, title, _legend_height(W, H, n_entries) if legend else 0.0)
    try:
        panel_px = (W // n, int(round(H * (1 - strip - leg))))
        longest = max(labels, key=len)
        fs = _font(panel_px[1], 0.04, longest, panel_px[0])
        fs_small = _font(panel_px[1], 0.03, "t = 00.00 ms", 0.6 * panel_px[0])

        E, ring_r, r_roll, max_off, mag = _orbit_scales(orb, clr, rol, magnify)
        first_rol = next((k for k in labels if k in rol), None)  # gets the magnification note
        views, trails, markers, time_actors, roller_meshes = [], [], [], [], []
        for j, lab in enumerate(labels):
            e = orb[lab]
            extent = E[lab]
            if lab in rol:
                extent = ring_r[lab] + r_roll[lab] + mag * max_off[lab]
            # text rows: label (and the magnification note, without a legend) on top; scale bar and time below
            note = lab == first_rol and not legend
            top = 0.98 - 1.5 * (fs + (fs_small if note else 0)) / panel_px[1] - 0.02
            bottom = 0.085 + 1.5 * fs_small / panel_px[1] + 0.02
            view = _View(p, (row, j), panel_px, (0.0, 0.0), extent, extent,
                         band=(0.03, 0.97, bottom, top))
            views.append(view)
            col = _PANEL_COLORS[j % len(_PANEL_COLORS)]
            trail, marker = _orbit_panel(p, view, e, clr[lab], E[lab], col, panel_px)
            trails.append(trail)
            markers.append(marker)
            if lab in rol:
                moving, ideal, ring_pts = _roller_ring(p, view, rol[lab].shape[1], ring_r[lab], r_roll[lab], col)
                roller_meshes.append((moving, ideal, ring_pts, lab))
                if note:  # one factor for all panels: say it once
                    view.text(f"rollers' offsets in their pockets at ×{mag:.3g} the orbits' scale", (0.5, 0.98 - view.line_height(fs)),
                              fs_small, justify="center", color="#666666", valign="top")
            view.text(lab, (0.5, 0.98), fs, justify="center", bold=True, valign="top")
            view.scale_bar(frac=0.25, size=fs_small)
            time_actors.append(view.text(tfmt(t[idx[0]]), (0.97, 0.05), fs_small, justify="right"))

        if legend:
            Cs = sorted({round(c * 1e6, 1) for c in clr.values()})
            centre = "cage centre" if k_exc == 1.0 else f"cage centre: mean + excursion ×{k_exc:.3g}"
            entries = [("line", "#888888", "guide clearance C_g = " + " / ".join(f"{c:g}" for c in Cs) + " µm"),
                       ("dot", "#d50000", centre), ("line", _PANEL_COLORS[0], "its trail (panel colour)")]
            if rol:
                entries += [("ring", "#bbbbbb", "roller, centred in its pocket"),
                            ("ring", _PANEL_COLORS[0], f"roller, its offset in the pocket at ×{mag:.3g} the orbits' scale")]
            _legend_strip(p, leg_row, (W, int(round(H * leg))), entries, fs_small)

        def render(i):
            for j, lab in enumerate(labels):
                seg = np.arange(i + 1) if i > 0 else np.zeros(2, int)  # orbit so far
                trails[j].lines = np.r_[seg.size, seg]
                markers[j].points = _xyz(orb[lab][i:i + 1], 3 * views[j].z_step)
                time_actors[j].input = tfmt(t[i])
            for moving, ideal, ring_pts, lab in roller_meshes:
                c = ideal + mag * rol[lab][i]
                moving.points = _xyz((c[:, None, :] + ring_pts[None]).reshape(-1, 2),
                                     2 * views[labels.index(lab)].z_step)
            return _screenshot(p, (W, H))

        bar = _Progress(idx.size, path, progress)
        _write_film(path, fps, idx, render, bar)
        bar.close()
    finally:
        p.close()
    return path


# ----------------------------------------------------------------------------------------------
# gear train

def _body_template(b: Mapping, kind: str) -> tuple[np.ndarray, np.ndarray, list[list[int]]]:
    """Body-local polar points (r, a) and polylines for one outline body.

    Circle outline; teeth as short radial ticks (outward on gears, inward on the ring, about one
    module long); a radial reference line so that rotation is visible on toothless bodies.
    """
    R = float(b["radius"])
    nseg = 96 if kind != "ring" else 180
    a = np.linspace(0, 2 * np.pi, nseg, endpoint=False)
    r_pts = [np.full(nseg, R)]
    a_pts = [a]
    segs = [list(range(nseg)) + [0]]
    k = nseg
    teeth = b.get("teeth")
    if teeth:
        z = int(teeth)
        m = 2 * R / z  # the module, when radius is the pitch radius
        at = 2 * np.pi * np.arange(z) / z
        r_in, r_out = (R, R + m) if kind != "ring" else (R - m, R)
        r_pts += [np.full(z, r_in), np.full(z, r_out)]
        a_pts += [at, at]
        segs += [[k + i, k + z + i] for i in range(z)]
        k += 2 * z
    if kind in ("gear", "carrier", "cage"):
        r_pts.append(np.array([0.0, 0.7 * R]))
        a_pts.append(np.zeros(2))
        segs.append([k, k + 1])
        k += 2
    return np.concatenate(r_pts), np.concatenate(a_pts), segs


def _train_bodies(bodies, n_t: int, mag: float) -> list[dict]:
    """Checked bodies of :func:`train_animation`, displacements from ``ref`` magnified by ``mag``."""
    if not bodies:
        raise ValueError("bodies is empty")
    parsed = []
    for i, b in enumerate(bodies):
        kind = b.get("kind")
        if kind not in _KINDS:
            raise ValueError(f"bodies[{i}]: kind must be one of {_KINDS}, got {kind!r}")
        R = float(b.get("radius", 0.0))
        if not R > 0:
            raise ValueError(f"bodies[{i}]: radius must be positive")
        xy = np.asarray(b["xy"], float)
        th = np.asarray(b["theta"], float)
        if xy.shape != (n_t, 2) or th.shape != (n_t,):
            raise ValueError(f"bodies[{i}]: xy must be ({n_t}, 2) and theta ({n_t},), got "
                             f"{xy.shape} and {th.shape}")
        if mag != 1.0:
            if "ref" in b:
                ref = np.broadcast_to(np.asarray(b["ref"], float), (n_t, 2))
            elif kind == "roller":
                raise ValueError(f"bodies[{i}]: a roller needs 'ref' (its nominal centre) when "
                                 "magnify != 1")
            else:
                ref = xy.mean(axis=0)
            xy = ref + mag * (xy - ref)
        f = None
        if b.get("force") is not None:
            f = np.asarray(b["force"], float)
            if f.shape != (n_t,):
                raise ValueError(f"bodies[{i}]: force must be ({n_t},), got {f.shape}")
        parsed.append({**b, "kind": kind, "radius": R, "xy": xy, "theta": th, "force": f})
    return parsed


def _outline_groups(parsed) -> list[dict]:
    """Outline groups, one PolyData per kind so each kind keeps its colour."""
    groups = []
    for kind in ("ring", "carrier", "gear", "cage", "roller"):
        members = [b for b in parsed if b["kind"] == kind]
        if not members:
            continue
        bi, rl, al, segs, off = [], [], [], [], 0
        for m_i, b in enumerate(members):
            r_loc, a_loc, s = _body_template(b, kind)
            bi.append(np.full(r_loc.size, m_i))
            rl.append(r_loc)
            al.append(a_loc)
            segs += [[off + q for q in seg] for seg in s]
            off += r_loc.size
        g = {"kind": kind, "bi": np.concatenate(bi), "r": np.concatenate(rl),
             "a": np.concatenate(al), "xy": np.stack([b["xy"] for b in members]),
             "th": np.stack([b["theta"] for b in members])}
        g["mesh"] = pv.PolyData(np.zeros((off, 3)), lines=_lines_cells(segs))
        groups.append(g)
    return groups


def _place_outline(g, i, zz):
    """Points of an outline group at frame i, at depth zz."""
    c = g["xy"][g["bi"], i]
    ang = g["th"][g["bi"], i] + g["a"]
    return np.column_stack([c[:, 0] + g["r"] * np.cos(ang), c[:, 1] + g["r"] * np.sin(ang),
                            np.full(c.shape[0], zz)])


_DISC_SIDES = 24


def force_colour_scale(forces_N, words: str) -> tuple[float, str, list[float], int]:
    """The colour bar of roller forces [N]: (factor to the unit shown — kN from 1 kN on, as the figures
    (:func:`viz.plots.display_unit`) —, the bar's title ``words (unit)``, colour limits in that unit from 0 (or a
    negative least force) to a round top, the number of labels that puts a label on every round step)."""
    f = np.asarray(forces_N, float)
    f = f[np.isfinite(f)]
    lo, hi = (min(0.0, float(f.min())), float(f.max())) if f.size else (0.0, 0.0)
    factor, unit = display_unit("N", [lo, hi])
    lo, hi = lo * factor, hi * factor
    span = hi - lo if hi > lo else 1.0
    e = 10.0 ** math.floor(math.log10(span / 5.0))
    step = next(m * e for m in (1.0, 2.0, 2.5, 5.0, 10.0) if span / (m * e) <= 5.0 + 1e-9)   # at most 5 steps
    lo, top = math.floor(lo / step + 1e-9) * step, math.ceil(hi / step - 1e-9) * step
    top = max(top, lo + step)
    # VTK's font draws "[" and "]" as "(" and ")": the unit in parentheses
    return factor, f"{words} ({unit})", [lo, top], int(round((top - lo) / step)) + 1


def _roller_discs(p, rollers, idx, n_t, has_force, force_label, fs):
    """Filled roller discs: one polygon per roller, coloured by its force (cell data, in the unit of the colour
    bar: :func:`force_colour_scale`) with a colour bar. Returns (the disc mesh, the (n_r, n_t) forces in that
    unit or None)."""
    nd = _DISC_SIDES
    faces = np.hstack([np.r_[nd, np.arange(nd) + nd * k] for k in range(len(rollers))])
    disc = pv.PolyData(np.zeros((nd * len(rollers), 3)), faces=faces)
    if not has_force:
        p.add_mesh(disc, color="#9ecae1", lighting=False)
        return disc, None
    fr = np.stack([b["force"] if b["force"] is not None else np.full(n_t, np.nan) for b in rollers])
    factor, title, clim, n_labels = force_colour_scale(fr[:, idx], force_label)
    fr = fr * factor
    disc.cell_data["force"] = fr[:, idx[0]]
    p.add_mesh(disc, scalars="force", cmap="viridis", clim=clim, lighting=False, nan_color="#cccccc",
               show_scalar_bar=False)
    p.add_scalar_bar(title=title, vertical=True, position_x=0.83, position_y=0.12, width=0.07, height=0.72,
                     n_labels=n_labels, title_font_size=fs, label_font_size=fs, color=_INK, fmt="%.3g",
                     unconstrained_font_size=True)
    return disc, fr


_LAYER = {"ring": 2, "carrier": 3, "gear": 4, "cage": 5, "roller": 6}   # drawing order, back to front


def _train_extent(parsed, idx):
    """(centre, half extents) of everything drawn over the frames shown, with a 3 % margin."""
    lo = np.full(2, np.inf)
    hi = np.full(2, -np.inf)
    for b in parsed:
        pad = b["radius"] * (1 + (2.0 / b["teeth"] if b.get("teeth") else 0.0))
        lo = np.minimum(lo, b["xy"][idx].min(axis=0) - pad)
        hi = np.maximum(hi, b["xy"][idx].max(axis=0) + pad)
    return (hi + lo) / 2, (hi - lo) / 2 * 1.03


def train_animation(path, t, bodies: Sequence[Mapping], magnify: float = 1.0, fps: float = 20,
                    size: Sequence[int] = (600, 600), title: str | None = None,
                    max_frames: int | None = None, force_label: str = "roller force") -> Path:
    """Animate a gear train: outlines rotating with θ, rollers as discs coloured by contact force.

    bodies: dicts with
      kind: "gear" | "ring" | "carrier" | "roller" | "cage";  radius: m (pitch radius for toothed bodies)
      teeth: optional tooth count (ticks at the teeth);  xy: (n_t, 2) centre, m;  theta: (n_t,) rad
      force: optional (n_t,) N, colours a roller;  ref: optional (2,) or (n_t, 2) nominal centre.
    force_label: words of the colour bar's title; its unit (N, or kN from 1 kN on) is added in parentheses
    (:func:`force_colour_scale`).
    magnify: displacements xy − ref are drawn multiplied by this factor.  Without `ref` the time-mean
    position is the reference, which is right only for bodies whose nominal centre is fixed in the
    plotted frame; rollers travel round their bearing, so magnify != 1 requires `ref` for them.
    """
    path = _output_path(path, fps)
    t = np.asarray(t, float)
    n_t = t.size
    parsed = _train_bodies(bodies, n_t, float(magnify))
    require_offscreen()
    W, H = _even_size(size, path)
    idx = frame_indices(n_t, max_frames)
    tfmt = _time_formatter(t[idx])

    centre, half = _train_extent(parsed, idx)

    rollers = [b for b in parsed if b["kind"] == "roller"]
    forces = [b["force"] for b in rollers if b["force"] is not None]
    has_force = bool(forces)
    band_x1 = 0.8 if has_force else 0.98

    p = _plotter(window_size=(W, H), border=False)
    try:
        p.set_background(_BG)
        view = _View(p, (0, 0), (W, H), tuple(centre), half[0], half[1],
                     band=(0.02, band_x1, 0.1, 0.9 if title else 0.94))
        z = view.z_step
        fs = _font(H, 0.028)

        groups = _outline_groups(parsed)
        disc, fr = None, None
        if rollers:
            disc, fr = _roller_discs(p, rollers, idx, n_t, has_force, force_label, fs)
            rr = np.array([b["radius"] for b in rollers])
            disc_xy = np.stack([b["xy"] for b in rollers])  # (n_r, n_t, 2)
            unit = _circle(_DISC_SIDES)

        for g in groups:
            g["mesh"].points = _place_outline(g, idx[0], _LAYER[g["kind"]] * z)
            width = 1.0 if g["kind"] == "roller" else 1.6
            p.add_mesh(g["mesh"], color=_KIND_COLOR[g["kind"]], line_width=width, lighting=False)

        if title:     # shrink a long title to fit the width rather than let it run off the frame
            view.text(title, (0.02, 0.96), min(fs, _font(H, 0.028, title, int(0.96 * W))), bold=True,
                      valign="top")
        view.scale_bar(fx0=0.04, fy0=0.04, frac=0.22, size=fs)
        time_actor = view.text(tfmt(t[idx[0]]), (band_x1, 0.02), fs, justify="right")

        def render(i):
            for g in groups:
                g["mesh"].points = _place_outline(g, i, _LAYER[g["kind"]] * z)
            if disc is not None:
                c = disc_xy[:, i, :]
                pts = (c[:, None, :] + rr[:, None, None] * unit[None]).reshape(-1, 2)
                disc.points = _xyz(pts, z)
                if has_force:
                    disc.cell_data["force"] = fr[:, i]
            time_actor.input = tfmt(t[i])
            return _screenshot(p, (W, H))

        _write_film(path, fps, idx, render)
    finally:
        p.close()
    return path
