"""Text on the frames: the font, numbers pasted from cached glyph masks, and axis ticks."""

from __future__ import annotations

import importlib.util
import math
from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .palette import INK, WHITE, to_palette

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`
#: and :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Font sizes in px on the 640 x 360 reference frame (scaled by the frame's unit ``u``).
TEXT_PX = 12    # bar names and values
TIME_PX = 14    # the time label (bold)
NOTE_PX = 11    # notes, tick labels, the particles' letters
TITLE_PX = 13   # panel titles (bold)
SMALL_PX = 10   # the bars' explanatory note


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
        """Width of ``text`` (px)."""
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
        core = None
        for ch in text:
            mask, gx, gy, adv = self._glyph(ch)
            left, top = round(x + gx), round(base + gy)
            if core is None:
                img.paste(ink, (left, top), mask)  # readies img (loaded, writable) once
                core = img.im
            else:
                # What Image.paste does then, without its checks for every glyph.
                core.paste(ink, (left, top, left + mask.width, top + mask.height), mask.im)
            x += adv


def nice_step(raw: float) -> float:
    """A round tick step (1, 2 or 5 times a power of ten) near ``raw``."""
    if not (raw > 0 and math.isfinite(raw)):
        return 1.0
    p = 10 ** math.floor(math.log10(raw))
    for f in (1, 2, 5, 10):
        if raw <= f * p * 1.2:
            return f * p
    return 10 * p


def fmt_tick(v: float) -> str:
    """A tick label: 6 significant digits at most, and never "-0"."""
    text = f"{v:.6g}"
    return "0" if text in ("-0", "0") else text


class PaletteText:
    """Text pasted on a palette image from glyphs drawn once: each character drawn by
    ``stamps`` in ink on white at a whole pixel, mapped to the palette, pasted through the
    mask of the pixels it inks. For text on a white background: the same pixels as the
    stamps give there, without drawing in RGB and mapping back every frame."""

    #: White margin (px) around each glyph's cell.
    MARGIN = 4

    def __init__(self, stamps: Stamps) -> None:
        self.st = stamps
        self.glyphs: dict[str, tuple[Image.Image, Image.Image, int, int, float]] = {}

    def _glyph(self, ch: str) -> tuple[Image.Image, Image.Image, int, int, float]:
        g = self.glyphs.get(ch)
        if g is None:
            ascent, descent = self.st.font.getmetrics()
            m = self.MARGIN
            advance = self.st.width(ch)
            x0, _, x1, _ = self.st.font.getbbox(ch, anchor="ls")
            left = m + max(0, -x0)
            tile = Image.new("RGB", (left + max(x1, math.ceil(advance)) + m,
                                     ascent + descent + 2 * m), WHITE)
            self.st.draw(tile, (left, m + ascent), ch, INK, "ls")
            inked = (np.asarray(tile) != 255).any(axis=2)
            sprite, mask = to_palette(tile), Image.fromarray(inked)
            sprite.load()
            mask.load()
            g = self.glyphs[ch] = (sprite, mask, left, m + ascent, advance)
        return g

    def draw(self, img: Image.Image, xy: tuple[float, float], text: str, anchor: str) -> None:
        """Paste ``text`` on the palette image ``img`` at ``xy`` (px), anchored as
        :meth:`Stamps.draw` anchors it."""
        x, y = xy
        glyphs = [self._glyph(ch) for ch in text]
        if anchor[0] in "rm":
            x -= sum(g[4] for g in glyphs) / (1 if anchor[0] == "r" else 2)
        base = round({"m": y + self.st.cap / 2, "t": y + self.st.cap, "s": y}[anchor[1]])
        img.load()
        core = img.im  # pasted through Pillow's core: no per-call checks, both are "P"
        for sprite, mask, left, top, advance in glyphs:
            X, Y = round(x) - left, base - top
            core.paste(sprite.im, (X, Y, X + sprite.width, Y + sprite.height), mask.im)
            x += advance
