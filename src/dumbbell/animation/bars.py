"""The energy panel of a scene and of a recorded space: one bar per energy term on one fixed
scale for the whole animation, with the values printed on the right.

A scene's panel shows a pale bar behind each term up to its largest value since the previous
frame and E as the terms stacked end to end with a marker at the total; a space's shows E as
a plain bar, and with a heat counter, E + heat pale after it. One :class:`Bars` draws both:
per frame, each row's spans are computed and only the rows whose spans changed are drawn
again (a band of the panel each)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
from PIL import Image, ImageDraw

from ..model.energy import BOOKKEEPING
from .glyphs import SMALL_PX, TEXT_PX, TITLE_PX, Stamps, font, nice_step
from .layout import unit
from .painter import SS, Painter, Patch, Rect
from .palette import GREY, INK, TERM_RGB, TINT, blend, ink_index

if TYPE_CHECKING:  # for the annotations only
    from .recorded import Recording

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`
#: and :class:`dumbbell.spaces.Recorder`.
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
#: A recorded space's panel: its rows are at most this tall (px at 640x360) ...
SPACE_ROW_MAX = 26
#: ... its bars start at least this far right of the panel's left edge ...
SPACE_LABEL_ROOM = 70
#: ... and this far right of the end of the longest row name ...
NAME_GAP = 4
#: ... with this much room right of the widest value (px at 640x360), the values' crop
#: starting this many px right of the bars, ...
SPACE_VALUE_PAD, SPACE_VALUE_GAP = 8, 2
#: ... and E + heat drawn at this opacity of heat's colour.
HEAT_ALPHA = 0.6
#: Colour of each row of a space's panel.
SPACE_INKS = {"K_trans": TERM_RGB["K_cm"], "K_rot": TERM_RGB["K_rot"], "U_g": TERM_RGB["U_g"],
              "U_spring": TERM_RGB["U_spring"], "E": TERM_RGB["E"], "heat": TERM_RGB["E_lost"]}
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
    def of(cls, values: Sequence[np.ndarray], plain: bool = False) -> EnergyScale:
        """The scale that holds every finite value of ``values`` (J) and 0; with ``plain``,
        values that are all zero get the scale 0 to 1 J (not 0 to 1e-12 J)."""
        allv = np.concatenate([v[np.isfinite(v)] for v in values] + [np.zeros(1)])
        lo = min(0.0, float(allv.min()))
        hi = max(float(allv.max()), lo + 1e-12)
        if plain and hi - lo <= 1e-12 and lo == 0 and not any(np.any(v != 0) for v in values):
            return cls(0.0, 1.0, 2)
        return cls(lo, hi, max(0, min(6, 2 - math.floor(math.log10(hi - lo)))))

    @property
    def span(self) -> float:
        """hi - lo (J)."""
        return self.hi - self.lo

    def ticks(self, parts: int = 2, least: int = 1) -> list[float]:
        """Round energies (J) about ``parts`` steps apart across the scale, at least ``least``
        of them (a smaller round step when the first gives fewer)."""
        step = nice_step((self.hi - self.lo) / parts)
        while True:
            lo, hi = math.ceil(self.lo / step - 1e-9), math.floor(self.hi / step + 1e-9)
            if hi - lo + 1 >= least or not step > 0:
                return [k * step for k in range(lo, hi + 1)]
            step = nice_step(step / 2.1)  # the next round step down (1, 2, 5 x 10^n)

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


def draw_values(patch: Patch, rows: Sequence[Row], text: Callable[[str], str], right: int,
                stamps: Stamps) -> None:
    """Each row's value, right-aligned at ``right`` (px), pasted on the crop ``patch``:
    numbers change every frame, so they are pasted glyphs in RGB with smooth edges."""
    crop, (cx, cy), done = patch
    for name, top, bot in rows:
        stamps.draw(crop, (right - cx, (top + bot) / 2 - cy), text(name), INK, "rm")
    done()


@dataclass(frozen=True)
class Readings:
    """What the bars and the strip read per frame of a recorded space: its time ``t`` and the
    ``energy`` of each row (a scene's :class:`~.frames.Frames` carries, besides, each term's
    least and largest value since the previous frame, ``lo`` and ``hi``, and ``L_cm``)."""

    t: np.ndarray
    energy: Mapping[str, np.ndarray]
    lo: Mapping[str, np.ndarray] | None = None
    hi: Mapping[str, np.ndarray] | None = None
    L_cm: np.ndarray | None = None


#: A frame's drawing of one row: ("rect", x0, y0, x1, y1, ink) and ("poly", points, ink),
#: in palette indices.
Spans = tuple[tuple[Any, ...], ...]


@dataclass(frozen=True)
class Bars:
    """The energy panel of one animation: its box (px), the unit ``u``, the terms shown
    (``names``; E's own terms in ``terms``), the fixed ``scale``, where the bars run (``left``
    to ``right``, 0 J at ``zero``, px; ``px_per_j``), the rows, and the note beside the title
    (the longest of :data:`NOTES` that fits; None when none does). The panel's ``title``, each
    row's ``labels`` (by name; the name itself when absent) and colour (``inks``), whether E
    is drawn as its terms stacked (``stacked``: a scene's) or as a plain bar followed, when
    ``heat``, by E + heat (the last row is heat: a space's), and the values' crop, starting
    ``value_gap`` px right of the bars."""

    box: tuple[int, int, int, int]
    u: float
    names: tuple[str, ...]
    terms: tuple[str, ...]
    scale: EnergyScale
    left: int
    right: int
    zero: float
    px_per_j: float
    rows: tuple[Row, ...]
    note: str | None = None
    title: str = TITLE
    labels: Mapping[str, str] = field(default_factory=dict)
    inks: Mapping[str, tuple[int, int, int]] = field(default_factory=lambda: TERM_RGB)
    stacked: bool = True
    heat: bool = False
    value_gap: int = 0

    #: The fields a page (:meth:`.picture.Picture.document`) is not given: the scene's are
    #: the defaults, its own constants.
    PAGE_SKIPS = ("title", "labels", "inks", "stacked", "heat", "value_gap")

    @classmethod
    def build(cls, box: tuple[int, int, int, int], u: float, names: Sequence[str],
              scale: EnergyScale, values: Stamps) -> Bars:
        """A scene's panel in ``box`` for ``names`` on ``scale``, room left for the widest
        value printed with ``values``."""
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
                   (right - left) / span, bar_rows(names, box, u), note,
                   value_gap=round(VALUE_GAP * u))

    @classmethod
    def of_space(cls, box: tuple[int, int, int, int], rec: Recording, readings: Readings
                 ) -> Bars:
        """A recorded space's panel in ``box`` for the rows of ``rec`` (their ``readings``),
        with their labels and title, on the scale of all of them (and of E + heat with a
        heat counter)."""
        u = unit(*rec.size)
        e, names, labels = readings.energy, tuple(readings.energy), rec.labels or {}
        vals = [e[n] for n in names] + ([e["E"] + e["heat"]] if rec.heat else [])
        scale = EnergyScale.of(vals, plain=True)
        bx0, _, bx1, _ = box
        widest = max(abs(scale.lo), scale.hi)
        values = Stamps(font(max(8, round(TEXT_PX * u))))
        value_w = round(values.width(f"-{widest:.{scale.decimals}f}") + SPACE_VALUE_PAD * u)
        # The bars start right of the longest name (a negative bar reaching the scale's
        # low end must not paint over it: issue 29), and at least SPACE_LABEL_ROOM from
        # the left.
        name_font = font(round(TEXT_PX * u))
        names_end = (round(SWATCH * u) + SWATCH_GAP * u
                     + max(name_font.getlength(labels.get(n, n)) for n in names))
        left = bx0 + max(round(SPACE_LABEL_ROOM * u), math.ceil(names_end + NAME_GAP * u))
        right = bx1 - value_w
        px_per_j = (right - left) / scale.span
        return cls(box, u, names, names, scale, left, right, left - scale.lo * px_per_j,
                   px_per_j, bar_rows(names, box, u, row_max=SPACE_ROW_MAX), None,
                   rec.energy_title, dict(labels), SPACE_INKS, False, rec.heat,
                   SPACE_VALUE_GAP)

    def px(self, value: float) -> float:
        """Pixel x of energy ``value`` (J) on the fixed scale."""
        return self.zero + value * self.px_per_j

    @property
    def values_box(self) -> tuple[int, int, int, int]:
        """Where the values are printed (px)."""
        return (self.right + self.value_gap, self.rows[0][1] - ZERO_OVERHANG, self.box[2],
                self.rows[-1][2] + ZERO_OVERHANG)

    @cached_property
    def _inks(self) -> tuple[dict[str, int], dict[str, int]]:
        """Each row's palette index, and its pale one (opacity :data:`TINT` over white; a
        space's heat: :data:`HEAT_ALPHA`)."""
        inks = {name: ink_index(rgb) for name, rgb in self.inks.items()}
        inks["grey"] = ink_index(GREY)
        tints = {name: ink_index(blend(rgb, HEAT_ALPHA if self.heat else TINT))
                 for name, rgb in self.inks.items()}
        if self.heat:
            inks["heat"] = tints["heat"]  # heat's bar is as pale as E + heat's
        return inks, tints

    def draw_static(self, d: ImageDraw.ImageDraw, S: int) -> None:
        """Title, note, each row's swatch and name, and the zero line, on a background ``S``
        times the size."""
        u = self.u
        bx0, by0, _, _ = self.box
        d.text((bx0 * S, by0 * S), self.title, font=font(round(TITLE_PX * u) * S, True),
               fill=INK, anchor="lt")
        ft = font(round(TEXT_PX * u) * S)
        for name, top, bot in self.rows:
            mid = (top + bot) / 2
            sw = round(SWATCH * u)
            d.rectangle([bx0 * S, (mid - sw / 2) * S, (bx0 + sw) * S, (mid + sw / 2) * S],
                        fill=self.inks.get(name, GREY))
            d.text(((bx0 + sw + SWATCH_GAP * u) * S, mid * S), self.labels.get(name, name),
                   font=ft, fill=INK, anchor="lm")
        zx = self.zero * S
        d.line([(zx, (self.rows[0][1] - ZERO_OVERHANG) * S),
                (zx, (self.rows[-1][2] + ZERO_OVERHANG) * S)], fill=GREY, width=S)
        if self.note is not None:
            d.text(((bx0 + NOTE_X * u) * S, (by0 + 1 * u) * S), self.note,
                   font=font(round(SMALL_PX * u) * S), fill=GREY, anchor="lt")

    def bands(self, values: Stamps, on_white: bool) -> list[tuple[int, int]]:
        """Each bar's band (px: top, bottom): from the middle of the gap above it to the
        middle of the gap below it (the panel's block, first and last); one band for all
        bars when a value's text would not fit in its own or is not pasted on white (so
        redrawing a band never touches another's)."""
        rows = self.rows
        edges = [rows[0][1] - 3]
        edges += [(bot + nxt) // 2 for (_, _, bot), (_, nxt, _) in itertools.pairwise(rows)]
        edges.append(rows[-1][2] + 3)
        ascent, descent = values.font.getmetrics()
        fits = all(lo <= round((top + bot) / 2 + values.cap / 2) - ascent - 2
                   and round((top + bot) / 2 + values.cap / 2) + descent + 2 <= hi
                   for (_, top, bot), lo, hi in zip(rows, edges, edges[1:]))
        if not fits or not on_white:
            return [(edges[0], edges[-1])] * len(rows)
        return list(itertools.pairwise(edges))

    def _span(self, a: float, b: float, top: int, bot: int, ink: int) -> Spans:
        """A bar from energy ``a`` to ``b`` (J)."""
        if not (math.isfinite(a) and math.isfinite(b)):
            return ()
        x0, x1 = round(self.px(a)), round(self.px(b))
        return (("rect", x0, top, x1 - 1, bot - 1, ink),) if x1 > x0 else ()

    def spans(self, readings: Any, k: int) -> list[tuple[Spans, str]]:
        """Frame ``k``'s drawing of each row, and its value's text."""
        inks, tints = self._inks
        e = {name: float(v[k]) for name, v in readings.energy.items()}
        out: list[tuple[Spans, str]] = []
        for name, top, bot in self.rows:
            v = e[name]
            ink = inks.get(name, inks["grey"])
            if name == "E" and self.stacked:
                out.append((self._stacked(e, top, bot), self.scale.text(v)))
                continue
            spans: Spans = ()
            if readings.lo is not None:  # the pale bar: the range since the previous frame
                lo, hi = float(readings.lo[name][k]), float(readings.hi[name][k])
                spans += self._span(min(lo, 0.0) if lo > 0 else lo, hi, top, bot,
                                    tints.get(name, ink))
            if name == "E" and self.heat and math.isfinite(v) and e["heat"] > 0:
                # E + heat: what E was, were no energy lost to the contacts.
                b = round(self.px(max(v, 0.0)))
                h = max(b, round(self.px(v + e["heat"])))
                if h > b:
                    spans += (("rect", b, top, h - 1, bot - 1, tints["heat"]),)
            spans += self._span(min(v, 0.0), max(v, 0.0), top, bot, ink)
            out.append((spans, self.scale.text(v)))
        return out

    def _stacked(self, e: Mapping[str, float], top: int, bot: int) -> Spans:
        """E as the terms stacked end to end, E_lost after them, and a marker at E."""
        inks, tints = self._inks
        spans: Spans = ()
        x = 0.0
        for term in self.terms:
            v = e[term]
            if v > 0 and math.isfinite(v):
                spans += self._span(x, x + v, top, bot, inks[term])
                x += v
        if "E_lost" in e and e["E_lost"] > 0:
            # Thinner than E's bar, but never inside out on a small frame's thin row.
            inset = min(LOST_INSET, (bot - top - 1) // 2)
            spans += self._span(x, x + e["E_lost"], top + inset, bot - inset, tints["E_lost"])
        E = e["E"]
        if math.isfinite(E):
            xm = round(self.px(E))
            w = max(3, round(MARKER * self.u))
            ink = inks["E"]
            spans += (("rect", xm - 1, top - 3, xm, bot + 2, ink),
                      ("poly", ((xm - w, top - 3 - w), (xm + w - 1, top - 3 - w), (xm, top - 3)),
                       ink))
        return spans

    def draw(self, painter: Painter, img: Image.Image, k: int, fresh: bool) -> list[Rect]:
        """Draw again the bars (with their values) of frame ``k`` that changed, straight into
        the palette image ``img``, and L_cm under them when the readings have it; the boxes
        touched."""
        spans = self.spans(painter.readings, k)
        bands = painter.bars_bands
        shown = painter.shown.get("bars") or [None] * len(spans)
        redo = sorted({bands[j] for j, span in enumerate(spans) if span != shown[j]})
        boxes: list[Rect] = []
        if redo:
            painter.shown["bars"] = spans
            d = ImageDraw.Draw(img)
            bx1 = self.box[2]
            on_white = painter.on_white("values")
            for band in redo:
                box = (self.left - 1, band[0], painter.W, band[1])
                if not fresh:
                    painter.restore(box)
                boxes.append(box)
                for j in (j for j, b in enumerate(bands) if b == band):
                    _, top, bot = self.rows[j]
                    for kind, *args in spans[j][0]:
                        if kind == "rect":
                            d.rectangle(args[:4], fill=args[4])
                        else:
                            d.polygon(list(args[0]), fill=args[1])
                    if on_white:
                        painter.tx_values.draw(img, (bx1, (top + bot) / 2), spans[j][1], "rm")
                if not on_white:
                    text = dict(zip(self.names, (s[1] for s in spans), strict=True))
                    draw_values(painter.patch(img, self.values_box, 1), self.rows,
                                text.__getitem__, bx1, painter.values)
        L = painter.readings.L_cm
        if L is not None and math.isfinite(float(L[k])):
            u, strip = self.u, painter.strip
            limit = (strip.box[1] - round(MOMENTUM_GAP * u) if strip is not None
                     else painter.H - round(MOMENTUM_EDGE * u))
            box = self.draw_momentum(float(L[k]), limit,
                                     lambda b: painter.patch(img, b, 1), painter.note)
            boxes += [box] if box is not None else []
        return boxes

    def draw_momentum(self, value: float, limit: int,
                      patch: Callable[[tuple[int, int, int, int]], Patch],
                      stamps: Stamps) -> tuple[int, int, int, int] | None:
        """L_cm = ``value`` (kg m^2/s) under the bars, right-aligned, above ``limit`` (px),
        where there is room; the box drawn (None: none)."""
        u = self.u
        below = self.rows[-1][2]
        if limit - below < MOMENTUM_ROOM * u:
            return None
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
        return box
