"""The energy panel: one bar per energy term on one fixed scale for the whole animation, a pale
bar behind each up to its largest value since the previous frame, E as the terms stacked end
to end with a marker at the total, and the values printed on the right."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw

from ..model.energy import BOOKKEEPING
from .backdrop import SS, Patch
from .frames import Frames
from .glyphs import SMALL_PX, TEXT_PX, TITLE_PX, Stamps, font, nice_step
from .palette import GREY, INK, TERM_RGB, term_inks, term_tints

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []

#: The energy panel, in units of u (px on the 640 x 360 reference frame).
LABEL_ROOM = 82     # left of the bars: the colour swatch and the term's name
VALUE_PAD = 12      # between the bars' right end and the widest printed value
VALUE_GAP = 4       # between the bars' right end and the printed values' crop
HEAD = 22           # above the first row: the panel's title
ROW_MAX = 28        # a row is at most this tall
ROW_TOP, ROW_BOTTOM = 0.2, 0.8  # a bar fills its row from this share to that one
SWATCH = 9          # the colour swatch before a name ...
SWATCH_GAP = 5      # ... and the gap after it
NOTE_X = 80         # the note beside the title starts this far right of the panel
ZERO_OVERHANG = 3   # the zero line reaches this far (px) above and below the rows
LOST_INSET = 3      # E_lost's bar is this much (px) thinner at top and bottom than E's
MARKER = 4          # half-width of the marker at E (at least 3 px)
MOMENTUM_GAP = 6    # L_cm's label keeps this far above the strip ...
MOMENTUM_EDGE = 4   # ... or from the frame's bottom edge without a strip ...
MOMENTUM_ROOM = 14  # ... and is left out with less room than this ...
MOMENTUM_HALF = 8   # ... its crop reaches this far above and below its middle
#: The note beside the title, longest first: the first that fits is drawn.
NOTES = ("fixed scale; pale: largest value since the last frame",
         "pale: largest since last frame", "pale: since last frame")
#: The panel's title.
TITLE = "Energy (J)"
#: L_cm's line under the bars: before its value, after it, and the note that follows when
#: it fits.
MOMENTUM_TEXT = ("L_cm = ", " kg m²/s", " (about the centre of mass)")


@dataclass(frozen=True)
class EnergyScale:
    """One energy scale for a whole animation: from ``lo`` (J, at most 0) to ``hi`` (J), and
    the decimals a value is printed with (three significant digits of the span)."""

    lo: float
    hi: float
    decimals: int

    @classmethod
    def of(cls, values: Sequence[np.ndarray]) -> EnergyScale:
        """The scale that holds every finite value of ``values`` (J) and 0."""
        allv = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(1)])
        lo = min(0.0, float(allv.min()))
        hi = max(float(allv.max()), lo + 1e-12)
        return cls(lo, hi, max(0, min(6, 2 - math.floor(math.log10(hi - lo)))))

    @property
    def span(self) -> float:
        """hi - lo (J)."""
        return self.hi - self.lo

    def ticks(self) -> list[float]:
        """Round energies (J) about two steps apart across the scale."""
        step = nice_step((self.hi - self.lo) / 2)
        lo, hi = math.ceil(self.lo / step - 1e-9), math.floor(self.hi / step + 1e-9)
        return [k * step for k in range(lo, hi + 1)]

    def text(self, value: float) -> str:
        """``value`` (J) as printed beside its bar."""
        return fixed(value, self.decimals) if math.isfinite(value) else "n/a"


def fixed(value: float, decimals: int, sign: str = "") -> str:
    """``value`` with ``decimals`` decimals; a value that rounds to zero prints as 0, never as
    "-0.000" (a residue of -1e-17 J after a landing is no negative energy)."""
    return f"{round(value, decimals) + 0.0:{sign}.{decimals}f}"


Row = tuple[str, int, int]


def bar_rows(names: Sequence[str], box: tuple[int, int, int, int], u: float,
             row_max: float = ROW_MAX) -> tuple[Row, ...]:
    """(name, top px, bottom px) of each bar in the panel ``box`` (px), under its title, each
    row at most ``row_max`` u tall."""
    _, by0, _, by1 = box
    head = round(HEAD * u)
    row = min((by1 - by0 - head) / len(names), row_max * u)
    return tuple((name, round(by0 + head + (i + ROW_TOP) * row),
                  round(by0 + head + (i + ROW_BOTTOM) * row)) for i, name in enumerate(names))


def draw_legend(d: ImageDraw.ImageDraw, S: int, u: float, box: tuple[int, int, int, int],
                rows: Sequence[Row], colour: Callable[[str], tuple[int, int, int]],
                zero_x: float, title: str = TITLE,
                label: Callable[[str], str] | None = None) -> None:
    """The panel's static parts on a background ``S`` times the size: its ``title``, a swatch
    and the name of each row (``label(name)`` if given), and the zero line at ``zero_x``
    (px)."""
    bx0, by0, _, _ = box
    d.text((bx0 * S, by0 * S), title, font=font(round(TITLE_PX * u) * S, True),
           fill=INK, anchor="lt")
    ft = font(round(TEXT_PX * u) * S)
    for name, top, bot in rows:
        mid = (top + bot) / 2
        sw = round(SWATCH * u)
        d.rectangle([bx0 * S, (mid - sw / 2) * S, (bx0 + sw) * S, (mid + sw / 2) * S],
                    fill=colour(name))
        d.text(((bx0 + sw + SWATCH_GAP * u) * S, mid * S), label(name) if label else name,
               font=ft, fill=INK, anchor="lm")
    zx = zero_x * S
    d.line([(zx, (rows[0][1] - ZERO_OVERHANG) * S), (zx, (rows[-1][2] + ZERO_OVERHANG) * S)],
           fill=GREY, width=S)


def draw_values(patch: Patch, rows: Sequence[Row], text: Callable[[str], str], right: int,
                stamps: Stamps) -> None:
    """Each row's value, right-aligned at ``right`` (px), pasted on the crop ``patch``:
    numbers change every frame, so they are pasted glyphs in RGB with smooth edges."""
    crop, (cx, cy), done = patch
    for name, top, bot in rows:
        stamps.draw(crop, (right - cx, (top + bot) / 2 - cy), text(name), INK, "rm")
    done()


@dataclass(frozen=True)
class Bars:
    """The energy panel of one animation: its box (px), the unit ``u``, the terms shown
    (``names``; E's own terms in ``terms``), the fixed ``scale``, where the bars run (``left``
    to ``right``, 0 J at ``zero``, px; ``px_per_j``), the rows, and the note beside the title
    (the longest of :data:`NOTES` that fits; None when none does)."""

    box: tuple[int, int, int, int]
    u: float
    names: tuple[str, ...]
    terms: tuple[str, ...]
    scale: EnergyScale
    left: int
    right: int
    zero: int
    px_per_j: float
    rows: tuple[Row, ...]
    note: str | None = None

    @classmethod
    def build(cls, box: tuple[int, int, int, int], u: float, names: Sequence[str],
              scale: EnergyScale, values: Stamps) -> Bars:
        """The panel in ``box`` for ``names`` on ``scale``, room left for the widest value
        printed with ``values``."""
        bx0, _, bx1, _ = box
        span = scale.span
        left = bx0 + round(LABEL_ROOM * u)
        right = bx1 - round(values.width(f"-{span:.{scale.decimals}f}") + VALUE_PAD * u)
        zero = left + round((right - left) * (-scale.lo) / span)
        terms = tuple(n for n in names if n not in BOOKKEEPING)
        note_font = font(round(SMALL_PX * u) * SS)
        room = (bx1 - bx0 - NOTE_X * u) * SS
        note = next((n for n in NOTES if note_font.getlength(n) <= room), None)
        return cls(box, u, tuple(names), terms, scale, left, right, zero,
                   (right - left) / span, bar_rows(names, box, u), note)

    def px(self, value: float) -> float:
        """Pixel x of energy ``value`` (J) on the fixed scale."""
        return self.zero + value * self.px_per_j

    def draw_static(self, d: ImageDraw.ImageDraw, S: int) -> None:
        """Title, note, swatches, names and the zero line, on a background ``S`` times the
        size."""
        u = self.u
        draw_legend(d, S, u, self.box, self.rows, lambda name: TERM_RGB.get(name, GREY),
                    self.zero)
        bx0, by0, _, _ = self.box
        if self.note is not None:
            d.text(((bx0 + NOTE_X * u) * S, (by0 + 1 * u) * S), self.note,
                   font=font(round(SMALL_PX * u) * S), fill=GREY, anchor="lt")

    def draw(self, img: Image.Image, frames: Frames, k: int,
             patch: Callable[[tuple[int, int, int, int]], Patch], values: Stamps) -> None:
        """Frame ``k``'s bars straight into the palette image ``img``, and its values on a
        crop from ``patch``."""
        d = ImageDraw.Draw(img)
        inks, tints = term_inks(), term_tints()
        e = {name: float(v[k]) for name, v in frames.energy.items()}
        for name, top, bot in self.rows:
            if name == "E":
                self._stacked(d, e, top, bot)
                continue
            ink = inks.get(name, inks["grey"])
            lo, hi = float(frames.lo[name][k]), float(frames.hi[name][k])
            self._span(d, min(lo, 0.0) if lo > 0 else lo, hi, top, bot, tints.get(name, ink))
            self._span(d, min(e[name], 0.0), max(e[name], 0.0), top, bot, ink)
        bx1 = self.box[2]
        box = (self.right + round(VALUE_GAP * self.u), self.rows[0][1] - ZERO_OVERHANG, bx1,
               self.rows[-1][2] + ZERO_OVERHANG)
        draw_values(patch(box), self.rows, lambda name: self.scale.text(e[name]), bx1, values)

    def _span(self, d: ImageDraw.ImageDraw, a: float, b: float, top: int, bot: int,
              ink: int) -> None:
        """A bar from energy ``a`` to ``b`` (J)."""
        if not (math.isfinite(a) and math.isfinite(b)):
            return
        x0, x1 = round(self.px(a)), round(self.px(b))
        if x1 > x0:
            d.rectangle([x0, top, x1 - 1, bot - 1], fill=ink)

    def _stacked(self, d: ImageDraw.ImageDraw, e: Mapping[str, float], top: int, bot: int
                 ) -> None:
        """E as the terms stacked end to end, E_lost after them, and a marker at E."""
        inks = term_inks()
        x = 0.0
        for term in self.terms:
            v = e[term]
            if v > 0 and math.isfinite(v):
                self._span(d, x, x + v, top, bot, inks[term])
                x += v
        if "E_lost" in e and e["E_lost"] > 0:
            # Thinner than E's bar, but never inside out on a small frame's thin row.
            inset = min(LOST_INSET, (bot - top - 1) // 2)
            self._span(d, x, x + e["E_lost"], top + inset, bot - inset, term_tints()["E_lost"])
        E = e["E"]
        if math.isfinite(E):
            xm = round(self.px(E))
            w = max(3, round(MARKER * self.u))
            ink = inks["E"]
            d.rectangle([xm - 1, top - 3, xm, bot + 2], fill=ink)
            d.polygon([(xm - w, top - 3 - w), (xm + w - 1, top - 3 - w), (xm, top - 3)], fill=ink)

    def draw_momentum(self, value: float, limit: int,
                      patch: Callable[[tuple[int, int, int, int]], Patch],
                      stamps: Stamps) -> None:
        """L_cm = ``value`` (kg m^2/s) under the bars, right-aligned, above ``limit`` (px),
        where there is room."""
        u = self.u
        below = self.rows[-1][2]
        if limit - below < MOMENTUM_ROOM * u:
            return
        y = (below + limit) / 2
        box = (self.box[0], round(y - MOMENTUM_HALF * u), self.box[2],
               round(y + MOMENTUM_HALF * u))
        before, after, note = MOMENTUM_TEXT
        text = f"{before}{fixed(value, 4, '+')}{after}{note}"
        if stamps.width(text) > box[2] - box[0]:
            text = f"{before}{fixed(value, 4, '+')}{after}"
        crop, (cx, cy), done = patch(box)
        stamps.draw(crop, (box[2] - cx, y - cy), text, INK, "rm")
        done()
