"""Animation frames drawn with Pillow straight into one fixed 256-colour palette.

A frame is the scene (floor, height ruler, particles at their true radius, the spring as a
zig-zag with a constant number of coils or a rigid rod, the centre of mass, the time and, in
2D, the axis angle from vertical), an energy panel (one bar per energy column with a pale bar
behind it up to the largest value since the previous frame, a stacked bar for E with a marker
at the total, one fixed scale for the whole animation) and optionally a strip of the energy
time series: a window of :data:`WINDOW` s that scrolls with the cursor (time ticks and labels
move with it; faint lines mark the impacts), on the same fixed energy scale.

Why a fixed palette: quantizing every RGB frame to 256 colours costs more than drawing it.
Everything static is drawn once (at twice the size, then halved, so edges are smooth) and
mapped to the palette once. Per frame only the dumbbell and the changing texts are drawn in
RGB (the dumbbell at twice the size) on small crops of the background and mapped to the palette
(fast: the palette holds the blends of every ink with white); numbers are pasted from cached
glyph masks; bars and the cursor are drawn straight into the palette image. The strip's curves
for the whole animation are drawn once on a long 'tape'; a frame pastes the window it shows.

The world-to-pixel mapping is fixed for the whole animation (from the extents of the
trajectory in the rendered window) and keeps the aspect ratio: 1 m is as long in x as in y.
"""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from ..model.energy import BOOKKEEPING, energy_columns
from ..model.scene import Scene

#: No public names: this is the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []
from ..plot.style import COLOURS

#: Supersampling factor of everything drawn with smooth edges.
SS = 2
#: Coils of the drawn spring; constant, so the spacing of the zig-zag shows the stretch.
COILS = 9
#: Smallest drawn particle radius (px); smaller particles are drawn as markers of this size.
MIN_RADIUS_PX = 3.5
#: Radius of the centre-of-mass symbol (px at 640x360); the spring's zig-zag is wider.
CM_RADIUS = 3.0
#: Least distance (px at 640x360) of the 2D particle labels from the centre of mass: beyond
#: the angle's arc (radius 20) and vertical line (25) with room for the letter.
LABEL_CLEAR = 32.0
#: Seconds of the energy time series the strip shows at once. The textbook spring's energy
#: terms oscillate at 20 Hz: over 1 s and ~390 px each oscillation is ~20 px wide and reads
#: as a line (over 2 s they merge into a hatched band; over the whole run, a pale band).
WINDOW = 1.0
#: Fraction of the strip's window after the cursor (what comes next).
AHEAD = 0.25
#: Width (px) of the pieces the strip's tape is drawn in.
TAPE_CHUNK = 1024

WHITE = (255, 255, 255)
BLACK = (0, 0, 0)
INK = (34, 34, 34)
GREY = (110, 110, 110)
LIGHT = (200, 200, 200)
FLOOR = (232, 232, 232)
SPRING = (70, 70, 70)


def _hex(colour: str) -> tuple[int, int, int]:
    named = {"black": "#000000"}
    colour = named.get(colour, colour)
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


#: Colours of the energy terms and particles, the same as the figures'.
TERM_RGB = {name: _hex(c) for name, c in COLOURS.items()}
TERM_RGB["E"] = BLACK


@lru_cache(maxsize=1)
def palette() -> tuple[bytes, int]:
    """The fixed palette as 768 RGB bytes, and the index kept free for 'unchanged' (GIF
    transparency): each ink blended with white in 15 steps, a grey ramp, the floor colour."""
    inks = [BLACK, INK, GREY, SPRING, *sorted(set(TERM_RGB.values()))]
    colours: list[tuple[int, int, int]] = [WHITE, FLOOR, LIGHT]
    for ink in inks:
        for level in range(1, 16):
            a = level / 15
            c = tuple(round(255 + (v - 255) * a) for v in ink)
            colours.append(c)  # type: ignore[arg-type]
    for v in range(0, 256, 8):
        colours.append((v, v, v))
    unique: list[tuple[int, int, int]] = []
    for c in colours:
        if c not in unique:
            unique.append(c)
    if len(unique) > 255:  # a GIF palette holds 256 colours, one kept for padding
        raise RuntimeError(f"the GIF palette needs {len(unique)} colours, more than 255")
    # Pad with white: ties go to the lowest index, so padding is never chosen.
    unique += [WHITE] * (256 - len(unique))
    return bytes(v for c in unique for v in c), 255


@lru_cache(maxsize=1)
def _palette_image() -> Image.Image:
    pal = Image.new("P", (1, 1))
    pal.putpalette(palette()[0])
    return pal


def to_palette(rgb: Image.Image) -> Image.Image:
    """Map an RGB image to the fixed palette (nearest colour, no dithering)."""
    return rgb.quantize(palette=_palette_image(), dither=Image.Dither.NONE)


@lru_cache(maxsize=8)
def font(size: int, bold: bool = False) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    """DejaVu Sans at ``size`` px: matplotlib ships it, so it is found without importing
    matplotlib (only its folder is looked up); Pillow's own font otherwise."""
    name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
    spec = importlib.util.find_spec("matplotlib")
    for folder in (spec.submodule_search_locations or []) if spec else []:
        path = Path(folder) / "mpl-data" / "fonts" / "ttf" / name
        if path.is_file():
            return ImageFont.truetype(str(path), size)
    return ImageFont.load_default(size)


class Stamps:
    """Text drawn from cached glyph masks: rendering a string with FreeType every frame costs
    more than the rest of the frame; pasting cached glyphs costs little. Digits of DejaVu Sans
    share one width, so changing numbers do not jitter."""

    def __init__(self, fnt: ImageFont.FreeTypeFont | ImageFont.ImageFont):
        self.font = fnt
        self.glyphs: dict[str, tuple[Image.Image, int, int, float]] = {}
        _, top, _, _ = fnt.getbbox("0", anchor="ls")
        self.cap = -top  # height of digits above the baseline (px)

    def _glyph(self, ch: str) -> tuple[Image.Image, int, int, float]:
        g = self.glyphs.get(ch)
        if g is None:
            # A padded cell of the full line height: FreeType's bounding boxes are rounded and
            # would clip the smooth edges of small glyphs such as '.'.
            ascent, descent = self.font.getmetrics()
            x0, _, x1, _ = self.font.getbbox(ch, anchor="ls")
            pad = 2
            mask = Image.new("L", (x1 - x0 + 2 * pad, ascent + descent + 2 * pad))
            ImageDraw.Draw(mask).text((pad - x0, pad + ascent), ch, font=self.font, fill=255,
                                      anchor="ls")
            g = self.glyphs[ch] = (mask, x0 - pad, -(pad + ascent), self.font.getlength(ch))
        return g

    def width(self, text: str) -> float:
        return sum(self._glyph(ch)[3] for ch in text)

    def draw(self, img: Image.Image, xy: tuple[float, float], text: str,
             ink: tuple[int, int, int], anchor: str = "lm") -> None:
        """Paste ``text`` onto RGB ``img``; anchor 'l', 'm' or 'r', then 'm' (middle of digits),
        't' (top of digits) or 's' (baseline)."""
        x, y = xy
        if anchor[0] == "r":
            x -= self.width(text)
        elif anchor[0] == "m":
            x -= self.width(text) / 2
        base = {"m": y + self.cap / 2, "t": y + self.cap, "s": y}[anchor[1]]
        for ch in text:
            mask, gx, gy, adv = self._glyph(ch)
            img.paste(ink, (round(x + gx), round(base + gy)), mask)
            x += adv


def _ink_index(rgb: tuple[int, int, int]) -> int:
    pal = palette()[0]
    for i in range(256):
        if tuple(pal[3 * i:3 * i + 3]) == rgb:
            return i
    raise KeyError(rgb)


@dataclass(frozen=True)
class Frames:
    """What the frames show. Per frame: time ``t`` (s), positions of A and B (m, (n, 2) arrays
    of x and height), every energy column (J), and in ``lo``/``hi`` the least and largest value
    of each column since the previous frame (J; what happened between two frames, an impact for
    example, stays visible). ``series_t``/``series`` are the samples the strip draws;
    ``impacts`` the impact times (s); ``t_end`` the end of the animation (s)."""

    t: np.ndarray
    A: np.ndarray
    B: np.ndarray
    energy: dict[str, np.ndarray]
    lo: dict[str, np.ndarray]
    hi: dict[str, np.ndarray]
    series_t: np.ndarray
    series: dict[str, np.ndarray]
    impacts: tuple[float, ...]
    t_end: float
    L_cm: np.ndarray | None = None  # angular momentum about the centre of mass (kg m^2/s), 2D


class Backdrop:
    """Frames drawn over a background made once: ``bg_rgb`` (RGB, ``W`` x ``H`` px) and
    ``bg_ss`` (the same at :data:`SS` times the size); what changes is drawn on crops."""

    W: int
    H: int
    bg_rgb: Image.Image
    bg_ss: Image.Image

    def _patch(self, img: Image.Image, box: tuple[int, int, int, int], ss: int):
        """An RGB crop of the background, ``ss`` times the size, its corner (px), and a function
        that maps it back into ``img`` through the palette."""
        x0, y0 = max(0, box[0]), max(0, box[1])
        x1, y1 = min(self.W, box[2]), min(self.H, box[3])
        src = self.bg_ss if ss == SS else self.bg_rgb
        crop = src.crop((x0 * ss, y0 * ss, max(x0, x1) * ss, max(y0, y1) * ss))

        def done() -> None:
            img.paste(to_palette(crop.reduce(ss) if ss > 1 else crop), (x0, y0))

        return crop, (x0, y0), done


#: Layout of a frame, in units of ``u`` (the frame's size over the 640 x 360 reference, so a
#: larger GIF scales everything alike), or as shares of the frame's width W or height H.
TOP_MARGIN = 34          # above the scene: the time label and the ruler's title
FLOOR_BAND = 18          # below the scene: the floor's band
RULER = 36               # left of the scene: the height ruler
RULER_GAP = 8            # between the ruler and the world's left edge
SCENE_RIGHT_PAD = 30     # right of the scene, before the energy panel
SCENE_MIN_WIDTH = 150    # the scene panel is at least this wide ...
SCENE_MIN_SHARE = 0.3    # ... and at least this share of W ...
SCENE_MAX_SHARE = 0.55   # ... and at most this share of W
PANEL_GAP = 10           # between the scene and the energy panel
EDGE = 8                 # between a panel and the frame's edge
BARS_SHARE = 0.52        # the energy bars' panel ends at this share of H when a strip follows
STRIP_TOP_SHARE = 0.59   # the strip starts at this share of H ...
STRIP_LEFT = 34          # ... this far right of the bars' panel (its value axis) ...
STRIP_RIGHT = 16         # ... and stops this far from the right edge ...
STRIP_BOTTOM = 22        # ... and this far from the bottom (its time axis)
WORLD_PAD = 0.05         # margin around everything the particles reach, a share of its span


@dataclass(frozen=True)
class Layout:
    """Where everything goes on a ``W`` x ``H`` frame, computed once per animation: the length
    unit ``u`` (px), the world's scale ``s`` (px per m) and origin (``ox``, ``oy``, px), the
    world window (m) and the panels' boxes (px, left-top-right-bottom)."""

    W: int
    H: int
    u: float
    s: float
    ox: float
    oy: float
    world: tuple[float, float, float, float]
    ruler_x: int
    scene_w: int
    bars_box: tuple[int, int, int, int]
    strip_box: tuple[int, int, int, int]

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Pixel position of world point (x, y) in m."""
        return self.ox + x * self.s, self.oy - y * self.s


def layout(scene: Scene, frames: Frames, size: tuple[int, int], strip: bool) -> Layout:
    """The layout of ``frames`` of ``scene`` on a frame of ``size`` (px): the world window
    holds every position the particles reach (and the floor), at one scale in x and y."""
    W, H = size
    u = min(W / 640, H / 360)  # length unit of fonts and lines (px)
    r = max(scene.system.A.radius, scene.system.B.radius)
    xs = np.concatenate([frames.A[:, 0], frames.B[:, 0]])
    ys = np.concatenate([frames.A[:, 1], frames.B[:, 1]])
    finite = np.isfinite(xs) & np.isfinite(ys)
    xs, ys = (xs[finite], ys[finite]) if finite.any() else (np.zeros(1), np.zeros(1))
    x0, x1 = float(xs.min()) - r, float(xs.max()) + r
    y0, y1 = float(ys.min()) - r, float(ys.max()) + r
    if scene.system.floor is not None:
        y0 = min(y0, 0.0)
    span = max(x1 - x0, y1 - y0, 1e-6)
    pad = WORLD_PAD * span
    x0, x1, y0, y1 = x0 - pad, x1 + pad, y0 - pad, y1 + pad
    top = round(TOP_MARGIN * u)
    bottom = round(FLOOR_BAND * u)
    ruler = round(RULER * u)
    avail_h = H - top - bottom
    want_w = ruler + (x1 - x0) * avail_h / (y1 - y0) + round(SCENE_RIGHT_PAD * u)
    scene_w = int(min(max(want_w, SCENE_MIN_WIDTH * u, SCENE_MIN_SHARE * W),
                      SCENE_MAX_SHARE * W))
    avail_w = scene_w - ruler - round(SCENE_RIGHT_PAD * u)
    s = min(avail_h / (y1 - y0), avail_w / max(x1 - x0, 1e-9))  # px per m
    ox = ruler + round(RULER_GAP * u) + avail_w / 2 - (x0 + x1) / 2 * s
    # World bottom on the panel's bottom: room left over (a wide world) goes to the sky.
    oy = H - bottom + y0 * s
    right = scene_w + round(PANEL_GAP * u)
    bars_box = (right, round(EDGE * u), W - round(EDGE * u),
                round(BARS_SHARE * H) if strip else H - round(EDGE * u))
    strip_box = (right + round(STRIP_LEFT * u), round(STRIP_TOP_SHARE * H),
                 W - round(STRIP_RIGHT * u), H - round(STRIP_BOTTOM * u))
    return Layout(W, H, u, s, ox, oy, (x0, x1, y0, y1), round(ruler - 4 * u), scene_w,
                  bars_box, strip_box)


class Painter(Backdrop):
    """Draws the frames of one animation of ``scene`` at ``size`` (px) into the palette."""

    def __init__(self, scene: Scene, frames: Frames, size: tuple[int, int], strip: bool):
        self.scene = scene
        self.frames = frames
        self.W, self.H = size
        self.strip = strip
        self.L = layout(scene, frames, size, strip)
        self.u = self.L.u
        # The bars show E and its terms, and E_lost; its split (E_heat, E_err) is in the CSV.
        self.names = [n for n in energy_columns(scene) if n not in ("E_heat", "E_err")]
        self.terms = [n for n in self.names if n not in BOOKKEEPING]
        self.idx = {name: _ink_index(rgb) for name, rgb in TERM_RGB.items()}
        self.tint = {name: _ink_index(_blend(rgb, 0.33)) for name, rgb in TERM_RGB.items()}
        self.idx.update({"ink": _ink_index(INK), "grey": _ink_index(GREY)})
        u = self.u
        self.st_text = Stamps(font(max(8, round(12 * u))))
        self.st_time = Stamps(font(max(9, round(14 * u)), bold=True))
        self.st_label = Stamps(font(max(8, round(11 * u)) * SS, bold=True))
        self.st_small = Stamps(font(max(8, round(11 * u)) * SS))
        self.st_note = Stamps(font(max(8, round(11 * u))))
        self._energy_scale()
        if strip:
            self._strip_window()
            self.tape = self._tape()
        self.bg = self._background()
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * SS, self.H * SS), Image.Resampling.NEAREST)
        t, impacts = frames.t, np.asarray(frames.impacts)
        # Frames after which an impact happened since the previous frame.
        self.impact_frames = {int(k) for k in np.searchsorted(t, impacts, side="left")
                              if 0 < k < len(t)}

    # --- geometry --------------------------------------------------------------------------

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Pixel position of world point (x, y) in m."""
        return self.L.px(x, y)

    def _energy_scale(self) -> None:
        fr = self.frames
        values = [fr.series[n] for n in self.names if n != "E_lost"]
        values += [fr.hi[n] for n in self.names] + [fr.lo[n] for n in self.names]
        if "E_lost" in self.names:
            values.append(fr.series["E"] + fr.series["E_lost"])
        allv = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(1)])
        self.e_lo = min(0.0, float(allv.min()))
        self.e_hi = max(float(allv.max()), self.e_lo + 1e-12)
        span = self.e_hi - self.e_lo
        self.decimals = max(0, min(6, 2 - math.floor(math.log10(span))))
        bx0, _, bx1, _ = self.L.bars_box
        self.bar_left = bx0 + round(82 * self.u)
        self.bar_right = bx1 - round(self.st_text.width(f"-{span:.{self.decimals}f}") + 12 * self.u)
        self.bar_zero = self.bar_left + round((self.bar_right - self.bar_left) * (-self.e_lo) / span)
        self.bar_scale = (self.bar_right - self.bar_left) / span  # px per J

    def bar_px(self, value: float) -> float:
        """Pixel x of energy ``value`` (J) on the fixed bar scale."""
        return self.bar_zero + value * self.bar_scale

    def _bar_rows(self) -> list[tuple[str, int, int]]:
        """(name, top px, bottom px) of each row of the energy panel."""
        _, by0, _, by1 = self.L.bars_box
        head = round(22 * self.u)
        n = len(self.names)
        row = min((by1 - by0 - head) / n, 28 * self.u)
        return [(name, round(by0 + head + (i + 0.2) * row), round(by0 + head + (i + 0.8) * row))
                for i, name in enumerate(self.names)]

    # --- the background, drawn once -------------------------------------------------------

    def _background(self) -> Image.Image:
        W, H, u, S = self.W, self.H, self.u, SS
        img = Image.new("RGB", (W * S, H * S), WHITE)
        d = ImageDraw.Draw(img)
        fs = font(round(11 * u) * S)
        ft = font(round(12 * u) * S)
        if self.scene.system.floor is not None:
            _, fy = self.px(0.0, 0.0)
            d.rectangle([0, fy * S, self.L.scene_w * S, H * S], fill=FLOOR)
            d.line([(0, fy * S), (self.L.scene_w * S, fy * S)], fill=GREY, width=round(2 * u * S))
        # Height ruler.
        _, _, y0, y1 = self.L.world
        step = _nice_step((y1 - y0) / 5)
        rx = self.L.ruler_x * S
        lo, hi = math.ceil(y0 / step - 1e-9), math.floor(y1 / step + 1e-9)
        ya, yb = self.px(0, lo * step)[1], self.px(0, hi * step)[1]
        d.line([(rx, ya * S), (rx, yb * S)], fill=GREY, width=S)
        for k in range(lo, hi + 1):
            y = self.px(0, k * step)[1] * S
            d.line([(rx - 4 * u * S, y), (rx, y)], fill=GREY, width=S)
            d.text((rx - 6 * u * S, y), _fmt_tick(k * step), font=fs, fill=GREY, anchor="rm")
        d.text((4 * u * S, (H - 5 * u) * S), "height (m)", font=fs, fill=GREY, anchor="ls")
        d.line([(self.L.scene_w * S, 8 * u * S), (self.L.scene_w * S, (H - 8 * u) * S)],
               fill=LIGHT, width=S)
        self._bars_static(d, S, ft)
        if self.strip:
            self._strip_static(img, d, S, fs)
        return to_palette(img.reduce(S))

    def _bars_static(self, d: ImageDraw.ImageDraw, S: int, ft) -> None:
        u = self.u
        bx0, by0, _, _ = self.L.bars_box
        d.text((bx0 * S, by0 * S), "Energy (J)", font=font(round(13 * u) * S, True),
               fill=INK, anchor="lt")
        note_font = font(round(10 * u) * S)
        room = (self.L.bars_box[2] - bx0 - 80 * u) * S
        for note in ("fixed scale; pale: largest value since the last frame",
                     "pale: largest since last frame", "pale: since last frame"):
            if note_font.getlength(note) <= room:
                d.text(((bx0 + 80 * u) * S, (by0 + 1 * u) * S), note, font=note_font,
                       fill=GREY, anchor="lt")
                break
        rows = self._bar_rows()
        for name, top, bot in rows:
            mid = (top + bot) / 2
            sw = round(9 * u)
            d.rectangle([bx0 * S, (mid - sw / 2) * S, (bx0 + sw) * S, (mid + sw / 2) * S],
                        fill=TERM_RGB.get(name, GREY))
            d.text(((bx0 + sw + 5 * u) * S, mid * S), name, font=ft, fill=INK, anchor="lm")
        zx = self.bar_zero * S
        d.line([(zx, (rows[0][1] - 3) * S), (zx, (rows[-1][2] + 3) * S)], fill=GREY, width=S)

    def _strip_static(self, img: Image.Image, d: ImageDraw.ImageDraw, S: int, fs) -> None:
        """The parts of the strip that do not scroll: the frame (one crisp pixel on each side),
        the energy ticks and the axis names. The rest is pasted from the tape every frame."""
        u = self.u
        sx0, sy0, sx1, sy1 = self.L.strip_box
        d.rectangle([sx0 * S, sy0 * S, sx1 * S + S - 1, sy1 * S + S - 1], outline=LIGHT, width=S)
        for v in self._energy_ticks():
            y = self.strip_y(v)
            d.text(((sx0 - 4 * u) * S, y * S), _fmt_tick(v), font=fs, fill=GREY, anchor="rm")
        d.text(((sx0 - 4 * u) * S, (sy0 - 4 * u) * S), "J", font=fs, fill=GREY, anchor="rs")
        d.text(((sx0 - 4 * u) * S, (sy1 + 4 * u) * S), "t (s)", font=fs, fill=GREY, anchor="rt")

    def _energy_ticks(self) -> list[float]:
        step = _nice_step((self.e_hi - self.e_lo) / 2)
        lo, hi = math.ceil(self.e_lo / step - 1e-9), math.floor(self.e_hi / step + 1e-9)
        return [k * step for k in range(lo, hi + 1)]

    def _strip_window(self) -> None:
        """Time scale of the strip: it shows :data:`WINDOW` s (the whole animation when
        shorter), :data:`AHEAD` of it after the cursor, and scrolls with the cursor."""
        sx0, sy0, sx1, sy1 = self.L.strip_box
        self.inner_x, self.inner_w = sx0 + 1, sx1 - sx0 - 1    # inside the frame (px)
        self.tick_len = max(2, round(3 * self.u))
        self.tape_y, self.tape_h = sy0 + 1, sy1 + self.tick_len - sy0
        t_end = self.frames.t_end
        self.window = min(WINDOW, t_end)
        self.px_per_s = (self.inner_w - 1) / self.window
        self.tape_w = max(self.inner_w, math.ceil(t_end * self.px_per_s) + 1)
        self.cursor_px = round((1 - AHEAD) * (self.inner_w - 1)) if self.window < t_end else 0
        self.t_step = _nice_step(self.window / 5)

    def _tape(self) -> Image.Image:
        """The energy time series of the whole animation on one long palette image at the
        strip's time scale (grid, bottom edge, time and impact ticks included); each frame
        pastes the window it shows. Drawn in pieces so long runs need little memory.

        Drawn without supersampling, unlike the rest: the strip scrolls, so its every line
        pixel is encoded again in every frame, and smooth edges make those pixels cost ~60 %
        more bytes (the textbook GIF would exceed 2 MB)."""
        fr, u, S = self.frames, self.u, 1
        p, h = self.px_per_s, self.tape_h
        tape = Image.new("P", (self.tape_w, h))
        y_of = [(self.strip_y(v) - self.tape_y) * S for v in self._energy_ticks()]
        edge = (self.L.strip_box[3] - self.tape_y) * S
        ticks = [k * self.t_step for k in range(math.floor(fr.t_end / self.t_step + 1e-9) + 1)]
        impacts = [ti for ti in fr.impacts if ti <= fr.t_end]
        # Terms whose range per pixel column is mostly wider than 3 px (faster than a column
        # can show) are drawn as pale bands of that range; the others as lines; E on top.
        order = [n for n in self.names if n != "E"] + ["E"]
        t = fr.series_t
        cols_all = np.floor(t * p * S).astype(np.int64)
        series, band = {}, {}
        for name in order:
            ys = (self.strip_y(fr.series[name]) - self.tape_y) * S
            ok = np.isfinite(ys)
            if ok.sum() < 2:
                continue
            c, y = cols_all[ok], ys[ok]
            starts = np.flatnonzero(np.r_[True, c[1:] != c[:-1]])
            series[name] = (t[ok], c, y)
            band[name] = bool(np.median(np.maximum.reduceat(y, starts)
                                        - np.minimum.reduceat(y, starts)) > 3 * S)
        width = max(1, round(2 * u))
        for c0 in range(0, self.tape_w, TAPE_CHUNK):
            c1 = min(self.tape_w, c0 + TAPE_CHUNK)
            img = Image.new("RGB", ((c1 - c0) * S, h * S), WHITE)
            d = ImageDraw.Draw(img)
            for y in y_of:
                d.line([(0, y), ((c1 - c0) * S, y)], fill=(238, 238, 238), width=S)
            d.rectangle([0, edge, (c1 - c0) * S, edge + S - 1], fill=LIGHT)
            for ti in ticks:
                x = (ti * p - c0) * S
                if -S <= x <= (c1 - c0 + 1) * S:
                    d.line([(x, edge), (x, edge + (self.tick_len + 1) * S)], fill=GREY, width=S)
            for ti in impacts:  # a faint line through the strip, a tick at its foot
                x = (ti * p - c0) * S
                if -S <= x <= (c1 - c0 + 1) * S:
                    d.line([(x, 0), (x, edge)], fill=(216, 216, 216), width=S)
                    d.line([(x, edge - 4 * u * S), (x, edge)], fill=GREY, width=S)
            lo_t, hi_t = (c0 - 2) / p, (c1 + 2) / p
            lines = []
            for name, (ts, c, y) in series.items():
                i0 = max(0, int(np.searchsorted(ts, lo_t)) - 1)
                i1 = min(len(ts), int(np.searchsorted(ts, hi_t, side="right")) + 1)
                if i1 - i0 < 2:
                    continue
                cc, yy = c[i0:i1] - c0 * S, y[i0:i1]
                if band[name]:
                    starts = np.flatnonzero(np.r_[True, cc[1:] != cc[:-1]])
                    top = np.minimum.reduceat(yy, starts)
                    bot = np.maximum.reduceat(yy, starts)
                    mask = Image.new("L", img.size, 0)
                    dm = ImageDraw.Draw(mask)
                    for x, a, b in zip(cc[starts].tolist(), top.tolist(), bot.tolist(),
                                       strict=True):
                        dm.line([(x, a), (x, b)], fill=255, width=1)
                    img.paste(_blend(TERM_RGB.get(name, GREY), 0.45), (0, 0), mask)
                else:
                    xs = (ts[i0:i1] * p - c0) * S
                    lines.append((name, list(zip(xs.tolist(), yy.tolist(), strict=True))))
            for name, pts in lines:
                d.line(pts, fill=TERM_RGB.get(name, GREY), width=width, joint="curve")
            tape.paste(to_palette(img), (c0, 0))
        return tape

    def strip_offset(self, k: int) -> tuple[int, int]:
        """For frame ``k``: the tape column at the strip's left edge and the cursor's column
        in the tape (px). The cursor walks in until it reaches its place, then the tape
        scrolls under it, and at the end the cursor walks out to the right edge."""
        x = round(float(self.frames.t[k]) * self.px_per_s)
        return min(max(0, x - self.cursor_px), self.tape_w - self.inner_w), x

    def strip_y(self, value):
        """Pixel y of energy ``value`` (J, a float or an array) in the strip."""
        _, sy0, _, sy1 = self.L.strip_box
        pad = 4 * self.u
        return sy1 - pad - (sy1 - sy0 - 2 * pad) * (value - self.e_lo) / (self.e_hi - self.e_lo)

    # --- one frame -------------------------------------------------------------------------

    def frame(self, k: int) -> Image.Image:
        """Frame ``k`` as a palette image."""
        img = self.bg.copy()
        self._dumbbell(img, k)
        self._time_label(img, k)
        self._bars(img, k)
        self._momentum_label(img, k)
        if self.strip:
            self._strip(img, k)
        return img

    def _strip(self, img: Image.Image, k: int) -> None:
        """The window of the tape that frame ``k`` shows, its time labels and the cursor."""
        left, x = self.strip_offset(k)
        img.paste(self.tape.crop((left, 0, left + self.inner_w, self.tape_h)),
                  (self.inner_x, self.tape_y))
        sx0, _, _, sy1 = self.L.strip_box
        u, st = self.u, self.st_note
        y = sy1 + self.tick_len + 1
        # Labels may reach past the frame's left edge, short of the axis name 't (s)'.
        x_min = sx0 - round(3 * u)
        crop, (cx, cy), done = self._patch(img, (x_min, y, self.W, self.H), 1)
        first = math.ceil(left / self.px_per_s / self.t_step - 1e-9)
        last = math.floor((left + self.inner_w - 1) / self.px_per_s / self.t_step + 1e-9)
        for j in range(first, last + 1):
            xt = self.inner_x + j * self.t_step * self.px_per_s - left
            text = _fmt_tick(j * self.t_step)
            half = st.width(text) / 2
            if xt - half >= x_min and xt + half <= self.W - 2 * u:
                st.draw(crop, (xt + 0.5 - cx, sy1 + 4 * u - cy), text, GREY, "mt")
        done()
        xc = self.inner_x + x - left
        ImageDraw.Draw(img).line([(xc, self.tape_y), (xc, sy1 - 1)], fill=self.idx["ink"],
                                 width=max(1, round(1.5 * u)))

    def _dumbbell(self, img: Image.Image, k: int) -> None:
        fr, sc, u, S = self.frames, self.scene, self.u, SS
        (ax, ay), (bx, by) = fr.A[k].tolist(), fr.B[k].tolist()
        if not all(math.isfinite(v) for v in (ax, ay, bx, by)):
            return
        pa, pb = self.px(ax, ay), self.px(bx, by)
        ra = max(sc.system.A.radius * self.L.s, MIN_RADIUS_PX * u)
        rb = max(sc.system.B.radius * self.L.s, MIN_RADIUS_PX * u)
        spring, rigid = sc.system.spring, sc.system.rigid
        rest = spring.rest_length if spring else rigid.length if rigid else 0.0
        amp = max((CM_RADIUS + 1.5) * u, min(0.06 * rest * self.L.s, 8 * u))
        two_d = sc.system.dimensions == 2
        m = max(ra, rb, amp) + (18 if two_d else 8) * u
        impact = k in self.impact_frames and sc.system.floor is not None
        mx = m + (34 * u if two_d else 0)
        x0, x1 = min(pa[0], pb[0]) - mx, max(pa[0], pb[0]) + mx + 16 * u
        y0, y1 = min(pa[1], pb[1]) - mx, max(pa[1], pb[1]) + (mx if two_d else m)
        if impact:  # the mark on the floor and the word under it
            fy = self.px(0.0, 0.0)[1]
            low = pa if pa[1] > pb[1] else pb
            x0, x1 = min(x0, low[0] - 30 * u), max(x1, low[0] + 30 * u)
            y1 = max(y1, fy + 20 * u)
        box = (math.floor(x0), math.floor(y0), math.ceil(x1), math.ceil(y1))
        crop, (cx, cy), done = self._patch(img, box, SS)
        d = ImageDraw.Draw(crop)

        def P(p: tuple[float, float]) -> tuple[float, float]:
            return ((p[0] - cx) * S, (p[1] - cy) * S)

        w = sc.system.A.mass / sc.system.M
        pc = (w * pa[0] + (1 - w) * pb[0], w * pa[1] + (1 - w) * pb[1])
        if two_d:
            self._angle(d, P, pa, pb, pc)
        if impact:
            fy = self.px(0.0, 0.0)[1]
            low = pa if pa[1] > pb[1] else pb
            x, y = P((low[0], fy))
            d.line([(x - 14 * u * S, y), (x + 14 * u * S, y)], fill=BLACK, width=round(3 * u * S))
            self.st_small.draw(crop, (x, y + 4 * u * S), "impact", INK, "mt")
        if sc.system.rigid is not None:
            d.line([P(pa), P(pb)], fill=SPRING, width=round(3 * u * S))
        elif sc.system.spring is not None:
            d.line([P(p) for p in _zigzag(pb, pa, amp, COILS)], fill=SPRING,
                   width=max(2, round(1.5 * u * S)), joint="curve")
        else:
            d.line([P(pa), P(pb)], fill=LIGHT, width=S)
        # Labels sit beyond each particle along the axis, clear of the spring; in 2D at least
        # LABEL_CLEAR from the centre of mass (clear of the angle's arc and vertical line when
        # the spring is compressed) and above the floor; in 1D (and when the particles
        # touch) to the right.
        dx, dy = pa[0] - pb[0], pa[1] - pb[1]
        dist = math.hypot(dx, dy)
        ex, ey = (dx / dist, dy / dist) if two_d and dist > 0 else (0.0, 0.0)
        floor_y = self.px(0.0, 0.0)[1] if sc.system.floor is not None else math.inf
        for p, r, name, sign in ((pa, ra, "A", 1), (pb, rb, "B", -1)):
            x, y = P(p)
            d.ellipse([x - r * S, y - r * S, x + r * S, y + r * S], fill=TERM_RGB[name],
                      outline=INK, width=max(1, round(0.8 * u * S)))
            if ex or ey:
                reach = max(math.hypot(p[0] - pc[0], p[1] - pc[1]) + r + 7 * u, LABEL_CLEAR * u)
                lx, ly = pc[0] + sign * ex * reach, min(pc[1] + sign * ey * reach,
                                                        floor_y - 7 * u)
                self.st_label.draw(crop, P((lx, ly)), name, INK, "mm")
            else:
                self.st_label.draw(crop, (x + (r + 4 * u) * S, y), name, INK, "lm")
        # Centre of mass: the quartered-disc symbol, narrower than the spring's zig-zag so
        # the coils still show beside it when the spring is fully compressed.
        (x, y), rc = P(pc), CM_RADIUS * u * S
        bb = [x - rc, y - rc, x + rc, y + rc]
        d.ellipse(bb, fill=WHITE, outline=BLACK, width=max(1, round(0.8 * u * S)))
        d.pieslice(bb, 180, 270, fill=BLACK)
        d.pieslice(bb, 0, 90, fill=BLACK)
        done()

    def _angle(self, d: ImageDraw.ImageDraw, P, pa, pb, pc) -> None:
        """The axis through B and A, a vertical reference at the centre of mass and the arc
        between them (the angle's value is printed under the time)."""
        u, S = self.u, SS
        dx, dy = pa[0] - pb[0], pa[1] - pb[1]
        length = math.hypot(dx, dy)
        if length == 0:
            return
        theta = axis_angle(pa, pb)
        ex, ey = dx / length, dy / length
        reach = max(length / 2 + 12 * u, 24 * u)
        d.line([P((pc[0] - ex * reach, pc[1] - ey * reach)),
                P((pc[0] + ex * reach, pc[1] + ey * reach))], fill=LIGHT, width=S)
        rv = 20 * u
        x, y = P(pc)
        d.line([(x, y), (x, y - rv * 1.25 * S)], fill=GREY, width=S)
        start, end = sorted((-90.0, -90.0 + theta))
        d.arc([x - rv * S, y - rv * S, x + rv * S, y + rv * S], start, end, fill=GREY,
              width=max(1, round(1.3 * u * S)))


    def _time_label(self, img: Image.Image, k: int) -> None:
        u, fr = self.u, self.frames
        two_d = self.scene.system.dimensions == 2
        box = (round(4 * u), round(2 * u), self.L.scene_w - round(4 * u),
               round((34 if two_d else 22) * u))
        crop, (cx, cy), done = self._patch(img, box, 1)
        self.st_time.draw(crop, (6 * u - cx, 6 * u - cy), f"t = {fr.t[k]:.2f} s", INK, "lt")
        if two_d:
            (ax, ay), (bx, by) = fr.A[k].tolist(), fr.B[k].tolist()
            if all(math.isfinite(v) for v in (ax, ay, bx, by)) and (ax, ay) != (bx, by):
                theta = axis_angle(self.px(ax, ay), self.px(bx, by))
                self.st_note.draw(crop, (6 * u - cx, 24 * u - cy),
                                  f"axis {theta:+.0f}° from vertical", GREY, "lt")
        done()

    def _momentum_label(self, img: Image.Image, k: int) -> None:
        """L_cm (kg m^2/s) under the energy bars, right-aligned, where there is room (2D)."""
        fr, u = self.frames, self.u
        if fr.L_cm is None or not math.isfinite(float(fr.L_cm[k])):
            return
        below = self._bar_rows()[-1][2]
        limit = self.L.strip_box[1] - round(6 * u) if self.strip else self.H - round(4 * u)
        if limit - below < 14 * u:
            return
        y = (below + limit) / 2
        box = (self.L.bars_box[0], round(y - 8 * u), self.L.bars_box[2], round(y + 8 * u))
        text = f"L_cm = {float(fr.L_cm[k]):+.4f} kg m²/s (about the centre of mass)"
        if self.st_note.width(text) > box[2] - box[0]:
            text = f"L_cm = {float(fr.L_cm[k]):+.4f} kg m²/s"
        crop, (cx, cy), done = self._patch(img, box, 1)
        self.st_note.draw(crop, (box[2] - cx, y - cy), text, INK, "rm")
        done()

    def _bars(self, img: Image.Image, k: int) -> None:
        d = ImageDraw.Draw(img)
        fr = self.frames
        e = {name: float(v[k]) for name, v in fr.energy.items()}
        rows = self._bar_rows()
        for name, top, bot in rows:
            if name == "E":
                self._stacked(d, e, top, bot)
                continue
            ink = self.idx.get(name, self.idx["grey"])
            lo, hi = float(fr.lo[name][k]), float(fr.hi[name][k])
            self._span(d, min(lo, 0.0) if lo > 0 else lo, hi, top, bot, self.tint.get(name, ink))
            self._span(d, min(e[name], 0.0), max(e[name], 0.0), top, bot, ink)
        # The numbers change every frame: pasted glyphs in RGB, smooth edges.
        bx1 = self.L.bars_box[2]
        box = (self.bar_right + round(4 * self.u), rows[0][1] - 3, bx1, rows[-1][2] + 3)
        crop, (cx, cy), done = self._patch(img, box, 1)
        for name, top, bot in rows:
            v = e[name]
            text = f"{v:.{self.decimals}f}" if math.isfinite(v) else "n/a"
            self.st_text.draw(crop, (bx1 - cx, (top + bot) / 2 - cy), text, INK, "rm")
        done()

    def _span(self, d: ImageDraw.ImageDraw, a: float, b: float, top: int, bot: int,
              ink: int) -> None:
        """A bar from energy ``a`` to ``b`` (J)."""
        if not (math.isfinite(a) and math.isfinite(b)):
            return
        x0, x1 = round(self.bar_px(a)), round(self.bar_px(b))
        if x1 > x0:
            d.rectangle([x0, top, x1 - 1, bot - 1], fill=ink)

    def _stacked(self, d: ImageDraw.ImageDraw, e: dict[str, float], top: int, bot: int) -> None:
        """E as the terms stacked end to end, E_lost after them, and a marker at E."""
        x = 0.0
        for term in self.terms:
            v = e[term]
            if v > 0 and math.isfinite(v):
                self._span(d, x, x + v, top, bot, self.idx[term])
                x += v
        if "E_lost" in e and e["E_lost"] > 0:
            self._span(d, x, x + e["E_lost"], top + 3, bot - 3, self.tint["E_lost"])
        E = e["E"]
        if math.isfinite(E):
            xm = round(self.bar_px(E))
            w = max(3, round(4 * self.u))
            ink = self.idx["E"]
            d.rectangle([xm - 1, top - 3, xm, bot + 2], fill=ink)
            d.polygon([(xm - w, top - 3 - w), (xm + w - 1, top - 3 - w), (xm, top - 3)], fill=ink)


def axis_angle(pa: tuple[float, float], pb: tuple[float, float]) -> float:
    """Angle of the axis from B to A from vertical (degrees, positive towards +x, like the
    scene's ``tilt``), from pixel positions (pixel y points down)."""
    return math.degrees(math.atan2(pa[0] - pb[0], pb[1] - pa[1]))


def _blend(rgb: tuple[int, int, int], a: float) -> tuple[int, int, int]:
    """``rgb`` at opacity ``a`` over white, snapped to the palette's 15 blend levels."""
    level = max(1, min(15, round(a * 15))) / 15
    return tuple(round(255 + (v - 255) * level) for v in rgb)  # type: ignore[return-value]


def _zigzag(p0: tuple[float, float], p1: tuple[float, float], amp: float, coils: int
            ) -> list[tuple[float, float]]:
    """Points of a spring from ``p0`` to ``p1`` (px): straight leads of 12 % at each end and
    ``coils`` zig-zags of half-width ``amp`` (px) between them: the spacing follows the length."""
    ax, ay = p1[0] - p0[0], p1[1] - p0[1]
    length = math.hypot(ax, ay)
    if length == 0:
        return [p0, p1]
    nx, ny = -ay / length * amp, ax / length * amp
    lead = 0.12
    pts = [p0, (p0[0] + ax * lead, p0[1] + ay * lead)]
    for i in range(2 * coils):
        f = lead + (1 - 2 * lead) * (i + 0.5) / (2 * coils)
        s = 1 if i % 2 == 0 else -1
        pts.append((p0[0] + ax * f + s * nx, p0[1] + ay * f + s * ny))
    pts += [(p0[0] + ax * (1 - lead), p0[1] + ay * (1 - lead)), p1]
    return pts


def _nice_step(raw: float) -> float:
    """A round tick step (1, 2 or 5 times a power of ten) near ``raw``."""
    if not (raw > 0 and math.isfinite(raw)):
        return 1.0
    p = 10 ** math.floor(math.log10(raw))
    for f in (1, 2, 5, 10):
        if raw <= f * p * 1.2:
            return f * p
    return 10 * p


def _fmt_tick(v: float) -> str:
    text = f"{v:.6g}"
    return "0" if text in ("-0", "0") else text
