"""The strip of the energy time series: a window of :data:`WINDOW` s that scrolls with a
cursor (time ticks and labels move with it; faint lines mark the impacts, and a thin bar in a
particle's colour along the strip's foot the time it rests or rolls on the floor), on the
energy panel's fixed scale.

The curves of the whole animation lie on a long 'tape', drawn in pieces as the frames reach
them (only the pieces under the current window are kept, so memory does not grow with the
run's length); a frame pastes the window it shows, its time labels and the cursor.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from PIL import Image, ImageDraw

from .backdrop import Patch
from .bars import EnergyScale
from .frames import Frames
from .glyphs import Stamps, fmt_tick, nice_step
from .palette import GREY, LIGHT, TERM_RGB, WHITE, blend, palette, term_inks, to_palette

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []

#: Seconds of the energy time series the strip shows at once. The textbook spring's energy
#: terms oscillate at 20 Hz: over 1 s and ~390 px each oscillation is ~20 px wide and reads
#: as a line (over 2 s they merge into a hatched band; over the whole run, a pale band).
WINDOW = 1.0
#: Fraction of the strip's window after the cursor (what comes next).
AHEAD = 0.25
#: Opacity of what lies after the cursor (over white): it has not happened yet at the
#: frame's time, so it is drawn faded.
FUTURE = 0.25
#: Width (px) of the pieces the strip's tape is drawn in.
TAPE_CHUNK = 1024
#: Time ticks per window (about).
TIME_TICKS = 5
#: A term whose range within one pixel column is mostly wider than this (px) changes faster
#: than a column can show: it is drawn as a pale band of that range, not as a line.
BAND_PX = 3
#: Opacity of such a band.
BAND_ALPHA = 0.45
GRID = (238, 238, 238)     # the energy grid lines
IMPACT = (216, 216, 216)   # the impacts' faint lines
#: The names of the strip's axes: energy (left) and time (under it).
ENERGY_AXIS, TIME_AXIS = "J", "t (s)"
#: The strip, in units of u (px on the 640 x 360 reference frame).
PAD = 4          # between the strip's frame and the highest and lowest energy
TICK = 3         # length of a time tick under the strip (at least 2 px)
LABEL_GAP = 4    # between the strip and its tick labels
CONTACT_BAR = 1  # height of a lasting contact's bar at the foot (B lowest, A above it), below
#                  the zero line of the curves (PAD above the foot, LINE wide)
IMPACT_TICK = 4  # an impact's tick at the foot of the strip
LINE = 2         # width of the curves (at least 1 px)
CURSOR = 1.5     # width of the cursor (at least 1 px)
LABEL_OVERHANG = 3  # time labels may start this far left of the strip's frame
LABEL_EDGE = 2   # and end this far from the frame's right edge


@dataclass(frozen=True)
class Strip:
    """The strip's geometry for one animation: its ``box`` (px), the unit ``u``, the energy
    ``scale``; inside its frame it starts at ``inner_x`` and is ``inner_w`` wide (px); the
    tape is ``tape_w`` x ``tape_h`` px, pasted at ``tape_y``; it shows ``window`` s at
    ``px_per_s``, the cursor stops at ``cursor_px`` from the left, time ticks every
    ``t_step`` s, ``tick_len`` px long."""

    box: tuple[int, int, int, int]
    u: float
    scale: EnergyScale
    inner_x: int
    inner_w: int
    tick_len: int
    tape_y: int
    tape_h: int
    window: float
    px_per_s: float
    tape_w: int
    cursor_px: int
    t_step: float

    @classmethod
    def build(cls, box: tuple[int, int, int, int], u: float, scale: EnergyScale,
              t_end: float) -> Strip:
        """The strip in ``box`` for an animation ``t_end`` s long: it shows :data:`WINDOW` s
        (the whole animation when shorter), :data:`AHEAD` of it after the cursor."""
        sx0, sy0, sx1, sy1 = box
        inner_x, inner_w = sx0 + 1, sx1 - sx0 - 1    # inside the frame (px)
        tick_len = max(2, round(TICK * u))
        window = min(WINDOW, t_end)
        px_per_s = (inner_w - 1) / window
        return cls(box, u, scale, inner_x, inner_w, tick_len, sy0 + 1,
                   sy1 + tick_len - sy0, window, px_per_s,
                   max(inner_w, math.ceil(t_end * px_per_s) + 1),
                   round((1 - AHEAD) * (inner_w - 1)) if window < t_end else 0,
                   nice_step(window / TIME_TICKS))

    def y(self, value):
        """Pixel y of energy ``value`` (J, a float or an array) in the strip."""
        _, sy0, _, sy1 = self.box
        pad = PAD * self.u
        lo, hi = self.scale.lo, self.scale.hi
        return sy1 - pad - (sy1 - sy0 - 2 * pad) * (value - lo) / (hi - lo)

    def offset(self, t: float) -> tuple[int, int]:
        """For a frame at ``t`` (s): the tape column at the strip's left edge and the cursor's
        column in the tape (px). The cursor walks in until it reaches its place, then the tape
        scrolls under it, and at the end the cursor walks out to the right edge."""
        x = round(t * self.px_per_s)
        return min(max(0, x - self.cursor_px), self.tape_w - self.inner_w), x

    def draw_static(self, d: ImageDraw.ImageDraw, S: int, fs) -> None:
        """The parts of the strip that do not scroll, on a background ``S`` times the size:
        the frame (one crisp pixel on each side), the energy ticks and the axis names."""
        u = self.u
        sx0, sy0, sx1, sy1 = self.box
        d.rectangle([sx0 * S, sy0 * S, sx1 * S + S - 1, sy1 * S + S - 1], outline=LIGHT, width=S)
        for v in self.scale.ticks():
            y = self.y(v)
            d.text(((sx0 - LABEL_GAP * u) * S, y * S), fmt_tick(v), font=fs, fill=GREY,
                   anchor="rm")
        d.text(((sx0 - LABEL_GAP * u) * S, (sy0 - LABEL_GAP * u) * S), ENERGY_AXIS, font=fs,
               fill=GREY, anchor="rs")
        d.text(((sx0 - LABEL_GAP * u) * S, (sy1 + LABEL_GAP * u) * S), TIME_AXIS, font=fs,
               fill=GREY, anchor="rt")

    def curves(self, frames: Frames, names: Sequence[str]
               ) -> tuple[dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]], dict[str, bool]]:
        """The series ``names`` of ``frames`` as the strip draws them, E last (on top): for
        each term with at least two finite samples, its sample times (s), tape columns and
        rows (px from the tape's top), and whether it is drawn as a pale band (its range
        within one pixel column mostly wider than :data:`BAND_PX`: it changes faster than a
        column shows) or as a line."""
        order = [n for n in names if n != "E"] + ["E"]
        t = frames.series_t
        cols_all = np.floor(t * self.px_per_s).astype(np.int64)
        series: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        band: dict[str, bool] = {}
        for name in order:
            ys = self.y(frames.series[name]) - self.tape_y
            ok = np.isfinite(ys)
            if ok.sum() < 2:
                continue
            c, y = cols_all[ok], ys[ok]
            starts = np.flatnonzero(np.r_[True, c[1:] != c[:-1]])
            series[name] = (t[ok], c, y)
            band[name] = bool(np.median(np.maximum.reduceat(y, starts)
                                        - np.minimum.reduceat(y, starts)) > BAND_PX)
        return series, band

    def tape(self, frames: Frames, names: Sequence[str]) -> Tape:
        """The energy time series ``names`` of the whole animation as a :class:`Tape` at the
        strip's time scale, from which each frame crops the window it shows."""
        return Tape(self, frames, names)

    def draw(self, img: Image.Image, t: float, tape: Tape,
             patch: Callable[[tuple[int, int, int, int]], Patch], stamps: Stamps) -> None:
        """The window of ``tape`` a frame at ``t`` (s) shows, its time labels (on a crop from
        ``patch``, reaching to the frame's right edge) and the cursor."""
        left, x = self.offset(t)
        window = tape.crop((left, 0, left + self.inner_w, self.tape_h))
        # What lies after the cursor has not happened yet: faded, down to the strip's foot.
        future = (x - left + 1, 0, self.inner_w, tape.edge)
        if future[2] > future[0]:
            window.paste(window.crop(future).point(fade_table()), future[:2])
        img.paste(window, (self.inner_x, self.tape_y))
        sx0, _, _, sy1 = self.box
        u, W = self.u, img.width
        y = sy1 + self.tick_len + 1
        # Labels may reach past the frame's left edge, short of the axis name 't (s)'.
        x_min = sx0 - round(LABEL_OVERHANG * u)
        crop, (cx, cy), done = patch((x_min, y, W, img.height))
        first = math.ceil(left / self.px_per_s / self.t_step - 1e-9)
        last = math.floor((left + self.inner_w - 1) / self.px_per_s / self.t_step + 1e-9)
        for j in range(first, last + 1):
            xt = self.inner_x + j * self.t_step * self.px_per_s - left
            text = fmt_tick(j * self.t_step)
            half = stamps.width(text) / 2
            if xt - half >= x_min and xt + half <= W - LABEL_EDGE * u:
                stamps.draw(crop, (xt + 0.5 - cx, sy1 + LABEL_GAP * u - cy), text, GREY, "mt")
        done()
        xc = self.inner_x + x - left
        ImageDraw.Draw(img).line([(xc, self.tape_y), (xc, sy1 - 1)], fill=term_inks()["ink"],
                                 width=max(1, round(CURSOR * u)))


@lru_cache(maxsize=1)
def fade_table() -> list[int]:
    """For each palette index, the index of its colour at opacity :data:`FUTURE` over white
    (the nearest in the palette); the index kept for 'unchanged' stays itself."""
    pal, clear = palette()
    rgb = np.frombuffer(pal, dtype=np.uint8).reshape(256, 3).astype(float)
    faded = 255.0 + (rgb - 255.0) * FUTURE
    nearest = ((faded[:, None, :] - rgb[None, :clear, :]) ** 2).sum(axis=2).argmin(axis=1)
    table = nearest.tolist()
    table[clear] = clear
    return table


class Tape:
    """The energy time series ``names`` of the whole animation on one long palette strip at
    the ``strip``'s time scale (grid, bottom edge, time and impact ticks included), drawn
    :data:`TAPE_CHUNK` columns at a time when a frame first needs them: only the pieces
    under the latest window are kept, so a 600 s animation 4096 px wide needs a few MB, not
    the 2 GB of the whole tape. Each piece is what the whole tape held in those columns.

    Drawn without supersampling, unlike the rest: the strip scrolls, so its every line
    pixel is encoded again in every frame, and smooth edges make those pixels cost ~60 %
    more bytes (the textbook GIF would exceed 2 MB)."""

    def __init__(self, strip: Strip, frames: Frames, names: Sequence[str]):
        fr, S = frames, 1
        self.strip, self.width, self.height = strip, strip.tape_w, strip.tape_h
        self.grid_y = [(strip.y(v) - strip.tape_y) * S for v in strip.scale.ticks()]
        self.edge = (strip.box[3] - strip.tape_y) * S
        self.ticks = [k * strip.t_step
                      for k in range(math.floor(fr.t_end / strip.t_step + 1e-9) + 1)]
        self.impacts = [ti for ti in fr.impacts if ti <= fr.t_end]
        self.bar = max(1, round(CONTACT_BAR * strip.u)) * S
        self.contacts = [(self.edge - (1 if body == "B" else 2) * self.bar, TERM_RGB[body], t0,
                          min(t1, fr.t_end)) for body, t0, t1 in fr.contacts if t0 <= fr.t_end]
        # Fast terms as pale bands, the others as lines; E on top.
        self.series, self.band = strip.curves(fr, names)
        self.pieces: dict[int, Image.Image] = {}

    def piece(self, c0: int) -> Image.Image:
        """Columns ``c0`` to ``c0 + TAPE_CHUNK`` (or the tape's end) as a palette image."""
        strip, S = self.strip, 1
        u, p, h, edge = strip.u, strip.px_per_s, self.height, self.edge
        c1 = min(self.width, c0 + TAPE_CHUNK)
        img = Image.new("RGB", ((c1 - c0) * S, h * S), WHITE)
        d = ImageDraw.Draw(img)
        for y in self.grid_y:
            d.line([(0, y), ((c1 - c0) * S, y)], fill=GRID, width=S)
        d.rectangle([0, edge, (c1 - c0) * S, edge + S - 1], fill=LIGHT)
        for ti in self.ticks:
            x = (ti * p - c0) * S
            if -S <= x <= (c1 - c0 + 1) * S:
                d.line([(x, edge), (x, edge + (strip.tick_len + 1) * S)], fill=GREY, width=S)
        for ti in self.impacts:  # a faint line through the strip, a tick at its foot
            x = (ti * p - c0) * S
            if -S <= x <= (c1 - c0 + 1) * S:
                d.line([(x, 0), (x, edge)], fill=IMPACT, width=S)
                d.line([(x, edge - IMPACT_TICK * u * S), (x, edge)], fill=GREY, width=S)
        self._curves(img, d, c0, c1)
        for y, colour, t0, t1 in self.contacts:  # resting or rolling on the floor: a bar
            x0, x1 = (t0 * p - c0) * S, (t1 * p - c0) * S
            if x1 >= -S and x0 <= (c1 - c0 + 1) * S:
                d.rectangle([x0, y, x1, y + self.bar - 1], fill=colour)
        return to_palette(img)

    def _curves(self, img: Image.Image, d: ImageDraw.ImageDraw, c0: int, c1: int) -> None:
        """The series over columns ``c0`` to ``c1`` on the piece ``img``: fast terms as pale
        bands, the others as lines, E on top."""
        S, u, p = 1, self.strip.u, self.strip.px_per_s
        lo_t, hi_t = (c0 - 2) / p, (c1 + 2) / p
        lines = []
        for name, (ts, c, y) in self.series.items():
            i0 = max(0, int(np.searchsorted(ts, lo_t)) - 1)
            i1 = min(len(ts), int(np.searchsorted(ts, hi_t, side="right")) + 1)
            if i1 - i0 < 2:
                continue
            cc, yy = c[i0:i1] - c0 * S, y[i0:i1]
            if self.band[name]:
                starts = np.flatnonzero(np.r_[True, cc[1:] != cc[:-1]])
                top = np.minimum.reduceat(yy, starts)
                bot = np.maximum.reduceat(yy, starts)
                mask = Image.new("L", img.size, 0)
                dm = ImageDraw.Draw(mask)
                for x, a, b in zip(cc[starts].tolist(), top.tolist(), bot.tolist(),
                                   strict=True):
                    dm.line([(x, a), (x, b)], fill=255, width=1)
                img.paste(blend(TERM_RGB.get(name, GREY), BAND_ALPHA), (0, 0), mask)
            else:
                xs = (ts[i0:i1] * p - c0) * S
                lines.append((name, list(zip(xs.tolist(), yy.tolist(), strict=True))))
        width = max(1, round(LINE * u))
        for name, pts in lines:
            d.line(pts, fill=TERM_RGB.get(name, GREY), width=width, joint="curve")

    def crop(self, box: tuple[int, int, int, int]) -> Image.Image:
        """The tape's columns ``box[0]`` to ``box[2]`` (rows ``box[1]`` to ``box[3]``), as
        ``Image.crop`` of the whole tape would give them; the pieces left of ``box[0]`` are
        dropped (frames move forward)."""
        left, top, right, bottom = box
        first = max(0, left) // TAPE_CHUNK * TAPE_CHUNK
        out = Image.new("P", (right - left, bottom - top))
        for c0 in range(first, min(right, self.width), TAPE_CHUNK):
            if c0 not in self.pieces:
                self.pieces[c0] = self.piece(c0)
            out.paste(self.pieces[c0], (c0 - left, -top))
        for c0 in [c for c in self.pieces if c < first]:
            del self.pieces[c0]
        return out
