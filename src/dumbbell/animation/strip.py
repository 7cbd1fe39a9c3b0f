"""The strip of the energy time series, on the energy panel's fixed scale, with a cursor at
the frame's time and what lies after it faded, for a scene and for a recorded space.

A scene's strip is a window of :data:`WINDOW` s that scrolls with the cursor (time ticks and
labels move with it; faint lines mark the impacts, and a thin bar in a particle's colour
along the strip's foot the time it rests or rolls on the floor). Its curves lie on a long
'tape', drawn in pieces as the frames reach them (only the pieces under the current window
are kept, so memory does not grow with the run's length); a frame pastes the window it
shows, its time labels and the cursor. A recorded space's strip shows the whole recording at
once, drawn with the background (:meth:`Strip.whole_run`): a frame moves the cursor and
fades the columns after it (:class:`Sheet`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from PIL import Image, ImageDraw

from .bars import SPACE_INKS, EnergyScale, Readings
from .frames import Frames
from .glyphs import NOTE_PX, Stamps, fmt_tick, font, nice_step
from .layout import unit
from .painter import Painter, Patch, Rect
from .palette import (
    GREY,
    INK,
    LIGHT,
    TERM_RGB,
    WHITE,
    blend,
    ink_index,
    palette,
    term_inks,
    to_palette,
)

if TYPE_CHECKING:  # for the annotations only
    from .recorded import Recording

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`
#: and :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Seconds of the energy time series the strip shows at once. The textbook spring's energy
#: terms oscillate at 20 Hz: over 1 s and ~390 px each oscillation is ~20 px wide and reads
#: as a line (over 2 s they merge into a hatched band; over the whole run, a pale band).
WINDOW = 1.0
#: The share of the strip's window after the cursor (what comes next), and the opacity of
#: what lies there (over white): it has not happened yet at the frame's time, so it is
#: drawn faded.
AHEAD, FUTURE = 0.25, 0.25
#: Width (px) of the pieces the strip's tape is drawn in.
TAPE_CHUNK = 1024
#: Time ticks per window (about).
TIME_TICKS = 5
#: A term whose range within one pixel column is mostly wider than BAND_PX (px) changes
#: faster than a column can show: it is drawn as a pale band of that range, at opacity
#: BAND_ALPHA, not as a line.
BAND_PX, BAND_ALPHA = 3, 0.45
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
#: A recorded space's strip, in units of u: the curves keep this far from the frame (the
#: scene's: PAD), its labels' font (the scene's: NOTE_PX), its time labels this far under
#: the strip, about this many time ticks over the whole recording, its curves and its
#: cursor this wide.
WHOLE_PAD, WHOLE_FONT, WHOLE_LABEL_GAP, WHOLE_TICKS, WHOLE_LINE, WHOLE_CURSOR = 3, 10, 5, 4, 1.5, 1.2
#: A recorded space's energy axis: about this many steps between its ticks; its tick labels
#: are divided by a power of ten (named with the unit above the axis) when the largest is
#: 10**WHOLE_SCALED[1] or more, or under 10**(WHOLE_SCALED[0] + 1), so that they fit beside
#: it.
WHOLE_ENERGY_TICKS, WHOLE_SCALED = 3, (-3, 4)
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
#: Opacity of E + heat's curve (a recorded space's, with a heat counter).
HEAT_ALPHA = 0.6


@dataclass(frozen=True)
class Strip:
    """The strip's geometry for one animation: its ``box`` (px), the unit ``u``, the energy
    ``scale``; inside its frame it starts at ``inner_x`` and is ``inner_w`` wide (px); the
    tape is ``tape_w`` x ``tape_h`` px, pasted at ``tape_y``; it shows ``window`` s at
    ``px_per_s``, the cursor stops at ``cursor_px`` from the left, time ticks every
    ``t_step`` s, ``tick_len`` px long; the curves keep ``pad`` px from the frame.

    A recorded space's (``scrolls`` False: :meth:`whole_run`) shows its whole recording,
    from ``t0`` to ``t_last``, its ``lines`` ((colour, times, values), ...) drawn with
    the background, its labels in a font of ``font_px`` u, the time axis named
    ``time_axis``."""

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
    pad: float = 0.0
    scrolls: bool = True
    t0: float = 0.0
    t_last: float = 0.0
    lines: tuple[tuple[tuple[int, int, int], np.ndarray, np.ndarray], ...] = ()
    font_px: float = NOTE_PX
    time_axis: str = TIME_AXIS
    energy_axis: str = ENERGY_AXIS

    #: The fields a page (:meth:`.picture.Picture.document`) is not given: the scene's
    #: strip draws with the constants the page has.
    PAGE_SKIPS = ("pad", "scrolls", "t0", "t_last", "lines", "font_px", "time_axis",
                  "energy_axis")

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
                   nice_step(window / TIME_TICKS), PAD * u)

    @classmethod
    def whole_run(cls, box: tuple[int, int, int, int], scale: EnergyScale, rec: Recording,
                  readings: Readings) -> Strip:
        """A recorded space's strip in ``box``: the whole of ``rec`` (its ``readings``: the
        frames' times, each row's energy; E last, with a heat counter E + heat before
        it)."""
        sx0, sy0, sx1, sy1 = box
        u, t, energy = unit(*rec.size), readings.t, readings.energy
        t0, end = float(t[0]), float(t[-1])
        window = max(float(t[-1] - t[0]), 1e-300)
        series = [(SPACE_INKS[n], energy[n]) for n in energy if n != "E"]
        if rec.heat:
            series.append((blend(SPACE_INKS["heat"], HEAT_ALPHA), energy["E"] + energy["heat"]))
        series.append((SPACE_INKS["E"], energy["E"]))
        return cls(box, u, scale, sx0 + 1, sx1 - sx0 - 1, 0, sy0 + 1, sy1 - sy0, window,
                   (sx1 - sx0 - 2) / window, sx1 - sx0 - 1, 0,
                   nice_step((end - t0) / WHOLE_TICKS) if end > t0 else 1.0,
                   WHOLE_PAD * u, False, t0, end, tuple((rgb, t, v) for rgb, v in series),
                   WHOLE_FONT, f"t ({rec.time_unit})", rec.energy_unit)

    def energy_ticks(self) -> tuple[list[tuple[float, str]], str]:
        """The energy axis: each tick's value (J) and label, and the axis' name. A scene's
        (scrolling) strip: about two steps, labelled as they are, named J beside the axis; a
        recorded space's: at least two of about :data:`WHOLE_ENERGY_TICKS` steps, labelled
        divided by :func:`tick_power`'s power of ten, named by the unit and that power
        ('×10³ kg px²/s²'; '' when the space's unit is not named and no power is needed),
        written above the axis."""
        if self.scrolls:
            return [(v, fmt_tick(v)) for v in self.scale.ticks()], ENERGY_AXIS
        ticks = self.scale.ticks(WHOLE_ENERGY_TICKS, least=2)
        power = tick_power(ticks)
        name = " ".join(part for part in (
            f"×10{str(power).translate(_SUPERSCRIPT)}" if power else "", self.energy_axis)
            if part)
        return [(v, fmt_tick(round(v / 10.0 ** power, 9))) for v in ticks], name

    def y(self, value):
        """Pixel y of energy ``value`` (J, a float or an array) in the strip."""
        _, sy0, _, sy1 = self.box
        pad = self.pad
        lo, hi = self.scale.lo, self.scale.hi
        return sy1 - pad - (sy1 - sy0 - 2 * pad) * (value - lo) / (hi - lo)

    def x(self, t):
        """Pixel x of time ``t`` (s, a float or an array) in a whole run's strip."""
        sx0, _, sx1, _ = self.box
        return sx0 + 1 + (sx1 - sx0 - 2) * (t - self.t0) / self.window

    def offset(self, t: float) -> tuple[int, int]:
        """For a frame at ``t`` (s): the tape column at the strip's left edge and the cursor's
        column in the tape (px). The cursor walks in until it reaches its place, then the tape
        scrolls under it, and at the end the cursor walks out to the right edge."""
        x = round(t * self.px_per_s)
        return min(max(0, x - self.cursor_px), self.tape_w - self.inner_w), x

    def draw_static(self, d: ImageDraw.ImageDraw, S: int) -> None:
        """The parts of the strip that do not scroll, on a background ``S`` times the size:
        the frame (one crisp pixel on each side), the energy ticks and the axis names; a
        whole run's grid, time ticks and curves too."""
        u = self.u
        sx0, sy0, sx1, sy1 = self.box
        fs = font(round(self.font_px * u) * S)
        d.rectangle([sx0 * S, sy0 * S, sx1 * S + S - 1, sy1 * S + S - 1], outline=LIGHT, width=S)
        ticks, name = self.energy_ticks()
        for v, label in ticks:
            y = self.y(v)
            if not self.scrolls:
                d.line([((sx0 + 1) * S, y * S), ((sx1 - 1) * S, y * S)], fill=GRID, width=S)
            d.text(((sx0 - LABEL_GAP * u) * S, y * S), label, font=fs, fill=GREY, anchor="rm")
        if not self.scrolls and name:  # the unit (and the power of ten) above the axis
            d.text((sx0 * S, (sy0 - LABEL_GAP * u) * S), name, font=fs, fill=GREY, anchor="ls")
        if self.scrolls:
            d.text(((sx0 - LABEL_GAP * u) * S, (sy0 - LABEL_GAP * u) * S), name,
                   font=fs, fill=GREY, anchor="rs")
            d.text(((sx0 - LABEL_GAP * u) * S, (sy1 + LABEL_GAP * u) * S), TIME_AXIS,
                   font=fs, fill=GREY, anchor="rt")
            return
        step = self.t_step
        for k in range(math.ceil(self.t0 / step - 1e-9), math.floor(self.t_last / step + 1e-9) + 1):
            x = self.x(k * step) * S
            d.line([(x, sy1 * S), (x, (sy1 + TICK * u) * S)], fill=GREY, width=S)
            d.text((x, (sy1 + WHOLE_LABEL_GAP * u) * S), fmt_tick(k * step), font=fs,
                   fill=GREY, anchor="mt")
        d.text(((sx0 - LABEL_GAP * u) * S, (sy1 + WHOLE_LABEL_GAP * u) * S), self.time_axis,
               font=fs, fill=GREY, anchor="rt")
        width = max(1, round(WHOLE_LINE * u * S))
        for rgb, t, v in self.lines:
            xs, ys = self.x(t) * S, self.y(v) * S
            ok = np.isfinite(ys)
            if ok.sum() < 2:
                continue
            d.line(list(zip(xs[ok].tolist(), ys[ok].tolist(), strict=True)), fill=rgb,
                   width=width, joint="curve")

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

    def source(self, bg: Image.Image, frames: Frames, names: Sequence[str]) -> Tape | Sheet:
        """What the frames crop the strip's pixels from, for the background ``bg``: a
        scene's :class:`Tape` of ``names`` of ``frames``, a whole run's :class:`Sheet`."""
        return self.tape(frames, names) if self.scrolls else Sheet(self, bg)

    def draw(self, painter: Painter, img: Image.Image, k: int) -> list[Rect]:
        """Frame ``k``'s strip on ``img``; the boxes touched."""
        t = float(painter.readings.t[k])
        source = painter.strip_source
        if isinstance(source, Sheet):
            return source.cursor(painter, img, t)
        self.scroll(img, t, source, lambda box: painter.patch(img, box, 1), painter.note)
        return [(self.box[0] - LABEL_OVERHANG * self.u, self.box[1], img.width, img.height)]

    def scroll(self, img: Image.Image, t: float, tape: Tape,
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


class Sheet:
    """A whole run's strip as the background holds it (inside its frame: every curve), and
    the same faded, which a frame shows after its cursor (what has not happened yet)."""

    def __init__(self, strip: Strip, bg: Image.Image) -> None:
        self.strip = strip
        sx0, sy0, sx1, sy1 = (round(v) for v in strip.box)
        self.inner = (sx0 + 1, sy0 + 1, sx1, sy1)
        self.past = bg.crop(self.inner)
        self.future = self.past.point(fade_table())

    def cursor(self, painter: Painter, img: Image.Image, t: float) -> list[Rect]:
        """Move the cursor to ``t`` if it moved, the curves after it faded; the boxes
        touched."""
        strip = self.strip
        u = strip.u
        _, sy0, _, sy1 = strip.box
        x = round(float(strip.x(t)))
        before = painter.shown.get("cursor")
        if before == x:
            return []
        painter.shown["cursor"] = x
        half = 2 * u + 1
        boxes: list[Rect] = [(x - half, sy0, x + half, sy1)]
        if before is not None:
            boxes.append(painter.restore((before - half, sy0, before + half, sy1)))
        # The columns between the two cursors turn from future to past (or back).
        ix0, iy0, ix1, iy1 = self.inner
        lo = ix0 if before is None else max(ix0, math.floor(min(before, x) - half) - 1)
        hi = ix1 if before is None else min(ix1, math.ceil(max(before, x) + half) + 2)
        for a, b, src in ((lo, min(hi, x + 1), self.past), (max(lo, x + 1), hi, self.future)):
            if b > a:
                img.paste(src.crop((a - ix0, 0, b - ix0, iy1 - iy0)), (a, iy0))
        if hi > lo:
            boxes.append((lo, iy0, hi, iy1))
        ImageDraw.Draw(img).line([(x, sy0 + 1), (x, sy1 - 1)], fill=ink_index(INK),
                                 width=max(1, round(WHOLE_CURSOR * u)))
        return boxes


def tick_power(ticks: Sequence[float]) -> int:
    """The power of ten a whole run's energy tick labels are divided by: 0 unless the
    largest is 10 000 or more or under 0.01 (:data:`WHOLE_SCALED`); a multiple of 3 then,
    as an engineer writes it (×10³, ×10⁶, ×10⁻³)."""
    top = max((abs(v) for v in ticks), default=0.0)
    if not (top > 0 and math.isfinite(top)):
        return 0
    e = math.floor(math.log10(top))
    return 3 * math.floor(e / 3) if not WHOLE_SCALED[0] < e < WHOLE_SCALED[1] else 0


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
