"""Frames drawn over a background made once: what changes is drawn on small crops of it.

Everything static is drawn once (at :data:`SS` times the size, then halved, so edges are
smooth) and mapped to the palette once. Per frame only what moves is drawn in RGB on a crop
of the background (at :data:`SS` times the size where edges must be smooth) and mapped back
through the palette: fast, since the palette holds the blends of every ink with white.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from PIL import Image

from .palette import to_palette

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`.
__all__: list[str] = []

#: Supersampling factor of everything drawn with smooth edges.
SS = 2

#: A crop of the background ``ss`` times the size, its corner (px), and the function that
#: maps it back into the frame through the palette.
Patch = tuple[Image.Image, tuple[int, int], Callable[[], None]]


class Backdrop:
    """Frames drawn over a background made once: ``bg_rgb`` (RGB, ``W`` x ``H`` px) and
    ``bg_ss`` (the same at :data:`SS` times the size); what changes is drawn on crops."""

    W: int
    H: int
    bg_rgb: Image.Image
    bg_ss: Image.Image

    def patch(self, img: Image.Image, box: tuple[float, float, float, float], ss: int
              ) -> Patch:
        """An RGB crop of the background over the whole pixels that cover ``box`` (px, left,
        top, right, bottom; clipped to the frame), ``ss`` times the size, its corner (px), and
        a function that maps it back into ``img`` through the palette."""
        x0, y0 = max(0, math.floor(box[0])), max(0, math.floor(box[1]))
        x1, y1 = min(self.W, math.ceil(box[2])), min(self.H, math.ceil(box[3]))
        src = self.bg_ss if ss == SS else self.bg_rgb
        crop = src.crop((x0 * ss, y0 * ss, max(x0, x1) * ss, max(y0, y1) * ss))

        def done() -> None:
            img.paste(to_palette(crop.reduce(ss) if ss > 1 else crop), (x0, y0))

        return crop, (x0, y0), done
