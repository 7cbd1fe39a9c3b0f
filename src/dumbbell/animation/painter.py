"""One painter for the frames of a scene and of a recorded pymunk space, in one fixed palette.

A frame is a picture panel on the left, the one part that differs: the scene's world
(:class:`.world.ScenePanel`: floor, height ruler, the dumbbell) or a recorded space's view
(:class:`.recording.ViewPanel`: the camera of :mod:`.camera`, the pens of :mod:`.pens`);
with energy, the bars (:class:`.bars.Bars`) and the strip (:class:`.strip.Strip`) on the
right, one implementation each for both; and the time label, top left.

:class:`Painter` owns what every frame shares. Everything static is drawn once (at
:data:`SS` times the size, then halved, so edges are smooth) and mapped to the palette once:
again only when the panel's static picture changes (a recorded space's static shapes, its
camera's view). Per frame only what changed is drawn, in RGB on crops of that background
(:meth:`Painter.patch`, at :data:`SS` times the size where edges must be smooth) mapped back
through the palette: fast, since the palette holds the blends of every ink with white. The
painter keeps the rectangle that changed since the frame before (:meth:`Painter.region`),
draws the time label and writes the frames (:meth:`Painter.write_gif`; the file, GIF or
MP4, by :mod:`.writer`). Text comes from the glyph caches of :mod:`.glyphs`, made here once.
Same frames, same bytes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO, Protocol

import numpy as np
from PIL import Image, ImageDraw

from .glyphs import NOTE_PX, TEXT_PX, TIME_PX, PaletteText, Stamps, font
from .layout import EDGE, unit
from .palette import GREY, INK, LIGHT, WHITE, ink_index, to_palette

#: No public names: the painter behind :func:`dumbbell.animation.render.render_gif` and
#: :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Supersampling factor of everything drawn with smooth edges.
SS = 2

#: A box on the frame (px: left, top, right, bottom).
Rect = tuple[float, float, float, float]
#: A crop of the background ``ss`` times the size, its corner (px), and the function that
#: maps it back into the frame through the palette.
Patch = tuple[Image.Image, tuple[int, int], Callable[[], None]]


def whole(box: Rect, width: int = 1 << 30, height: int = 1 << 30) -> tuple[int, int, int, int]:
    """The whole pixels that cover ``box`` (px: left, top, right, bottom), within the frame."""
    return (max(0, math.floor(box[0])), max(0, math.floor(box[1])),
            min(width, math.ceil(box[2])), min(height, math.ceil(box[3])))


def meets(a: Rect, b: Rect) -> bool:
    """Whether the boxes ``a`` and ``b`` (px) touch or overlap."""
    return not (a[2] < b[0] or a[0] > b[2] or a[3] < b[1] or a[1] > b[3])


def union_px(boxes: list[Rect]) -> Rect:
    """The smallest box (px) holding every one of ``boxes``."""
    return (min(b[0] for b in boxes), min(b[1] for b in boxes), max(b[2] for b in boxes),
            max(b[3] for b in boxes))


class Panel(Protocol):
    """The picture panel of a frame: what differs between a scene and a recorded space."""

    #: Frames drawn, and whether each starts from the whole background (a scene's: all of
    #: it changes anyway) or from the frame before (a space's: only what moved is drawn);
    #: the panel's width (px: the energy panel, if any, starts there) and its time label;
    #: whether the animation's text (the time, the bars' values) is pasted straight in the
    #: palette where its background is white (a space's; a scene's is always drawn on a
    #: crop mapped through the palette, as its GIFs always were).
    n: int
    fresh_every_frame: bool
    width: int
    clock: Clock
    text_on_white: bool

    def draw_base(self, d: ImageDraw.ImageDraw, S: int) -> None:
        """What lies under everything else, on the background ``S`` times the size."""

    def static_key(self, k: int) -> object:
        """What frame ``k``'s static picture depends on: a new key, a new background."""

    def draw_static(self, img: Image.Image, k: int) -> None:
        """Frame ``k``'s static picture on a copy of the base (RGB, :data:`SS` times the
        size)."""

    def draw(self, painter: Painter, img: Image.Image, k: int, fresh: bool) -> list[Rect] | None:
        """Frame ``k``'s moving picture on ``img``; the boxes drawn over a frame kept from
        before, or None when ``fresh`` (``img`` a new copy of the background)."""


@dataclass(frozen=True)
class Clock:
    """The time label, top left: frame k's ``text(k)`` (and ``note(k)`` under it, when
    given: a scene's axis angle) in ``box`` (px)."""

    box: Rect
    text: Callable[[int], str]
    note: Callable[[int], str | None] | None = None


#: The time label's text, this far from the frame's left and top edges (px at 640x360) ...
TIME_AT = 6
#: ... and the note under it (a scene's axis angle), this far from the top edge.
ANGLE_AT = 24


class Painter:
    """Draws the frames of one animation in the fixed palette (see the module notes), of
    ``size`` (px): the ``panel`` (a scene's world or a space's view) with its time label,
    and the ``bars`` and the ``strip`` (None without: a :class:`.bars.Bars` and a
    :class:`.strip.Strip`, which import this module, so it names them only here) of the
    ``readings`` (per frame: its time ``t``, each row's ``energy``; see
    :class:`.bars.Readings`)."""

    def __init__(self, size: tuple[int, int], panel: Panel, bars: Any = None,
                 strip: Any = None, readings: Any = None) -> None:
        self.W, self.H = size
        self.u = u = unit(*size)
        self.scene_w = panel.width
        self.panel, self.clock, self.bars, self.strip = panel, panel.clock, bars, strip
        #: What the bars and the strip read per frame (see :meth:`.bars.Bars.draw`).
        self.readings = readings
        self.n = panel.n
        # The glyphs, one cache per font.
        self.values = Stamps(font(max(8, round(TEXT_PX * u))))
        self.time = Stamps(font(max(9, round(TIME_PX * u)), bold=True))
        self.note = Stamps(font(max(8, round(NOTE_PX * u))))
        self.letters = Stamps(font(max(8, round(NOTE_PX * u)) * SS, bold=True))
        self.small = Stamps(font(max(8, round(NOTE_PX * u)) * SS))
        self.tx_time, self.tx_values = PaletteText(self.time), PaletteText(self.values)
        self.base = self._base()
        self._bg_key: object = None
        self._canvas: Image.Image | None = None
        #: What the frame on the canvas shows (the label, the bars' spans, the cursor).
        self.shown: dict[str, Any] = {}
        self.changed: Rect | None = None
        # Made with each background: where it is white, the bars' bands, the strip's source.
        self.white: dict[str, bool] = {}
        self.bars_bands: list[tuple[int, int]] = []
        self.strip_source: Any = None

    def _base(self) -> Image.Image:
        """The frame without its static picture: white, what lies under the panel, the line
        between the panels, the energy panel's legend and the strip's frame (RGB,
        :data:`SS` times the size)."""
        W, H, u, S = self.W, self.H, self.u, SS
        img = Image.new("RGB", (W * S, H * S), WHITE)
        d = ImageDraw.Draw(img)
        self.panel.draw_base(d, S)
        if self.bars is not None:
            x = self.scene_w * S  # the line between the picture and the energy panel
            d.line([(x, EDGE * u * S), (x, (H - EDGE * u) * S)], fill=LIGHT, width=S)
            self.bars.draw_static(d, S)
            if self.strip is not None:
                self.strip.draw_static(d, S)
        return img

    def background(self, k: int) -> bool:
        """Make frame ``k``'s background current (``bg``, ``bg_rgb``, ``bg_ss``): the base
        with the panel's static picture of frame ``k``. Returns whether it changed."""
        key = self.panel.static_key(k)
        if key == self._bg_key:
            return False
        S = SS
        img = self.base.copy()
        self.panel.draw_static(img, k)
        self.bg = to_palette(img.reduce(S))
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * S, self.H * S), Image.Resampling.NEAREST)
        self._bg_key = key
        # Text is pasted from glyphs drawn on white where the background is white.
        white = ink_index(WHITE)
        boxes = {"label": self.clock.box}
        if self.bars is not None:
            boxes["values"] = self.bars.values_box
        self.white = {name: bool((np.asarray(self.bg.crop(whole(box, self.W, self.H)))
                                  == white).all())
                      for name, box in boxes.items()}
        if self.bars is not None:
            self.bars_bands = self.bars.bands(self.values, self.on_white("values"))
        if self.strip is not None:
            # What the frames crop the strip from: a scene's tape, a space's whole run.
            self.strip_source = self.strip.source(self.bg, self.readings, self.bars.names)
        return True

    def on_white(self, name: str) -> bool:
        """Whether the text of the box ``name`` ("label", "values") is pasted straight in
        the palette: its background is white and the animation's text is drawn so."""
        return self.panel.text_on_white and self.white.get(name, False)

    def patch(self, img: Image.Image, box: Rect, ss: int) -> Patch:
        """An RGB crop of the background over the whole pixels that cover ``box`` (px, left,
        top, right, bottom; clipped to the frame), ``ss`` times the size, its corner (px), and
        a function that maps it back into ``img`` through the palette."""
        x0, y0, x1, y1 = whole(box, self.W, self.H)
        src = self.bg_ss if ss == SS else self.bg_rgb
        crop = src.crop((x0 * ss, y0 * ss, max(x0, x1) * ss, max(y0, y1) * ss))

        def done() -> None:
            img.paste(to_palette(crop.reduce(ss) if ss > 1 else crop), (x0, y0))

        return crop, (x0, y0), done

    def restore(self, box: Rect) -> tuple[int, int, int, int]:
        """Put the background back over the whole pixels that cover ``box`` (px); returns
        them (left, top, right, bottom)."""
        w = whole(box, self.W, self.H)
        if w[2] > w[0] and w[3] > w[1]:
            # Through Pillow's core (both "P", the canvas a copy of its own): no per-call
            # checks.
            self._canvas.im.paste(self.bg.im.crop(w), w)  # type: ignore[union-attr]
        return w

    def frame(self, k: int) -> Image.Image:
        """Frame ``k`` as a palette image (the painter's canvas: drawn over by the next
        frame, unless the panel starts every frame from the background). From one frame to
        the next only what changed is drawn again: the panel's changed boxes, the time
        label, the bars and the strip's cursor when theirs changed."""
        fresh = self.background(k)
        if fresh or self.panel.fresh_every_frame or self._canvas is None:
            self._canvas, self.shown, fresh = self.bg.copy(), {}, True
        img = self._canvas
        touched = self.panel.draw(self, img, k, fresh)
        parts = self._label(img, k, touched or [])
        if self.bars is not None:
            parts += self.bars.draw(self, img, k, fresh)
        if self.strip is not None:
            parts += self.strip.draw(self, img, k)
        if touched is None:
            self.changed = None
        else:
            touched += parts
            self.changed = union_px(touched) if touched else (0.0, 0.0, 0.0, 0.0)
        return img

    def _label(self, img: Image.Image, k: int, scene: list[Rect]) -> list[Rect]:
        """Draw the time label if it changed or the picture was drawn over it; the box
        touched."""
        u, clock = self.u, self.clock
        box, label = clock.box, clock.text(k)
        if self.shown.get("label") == label and not any(meets(r, box) for r in scene):
            return []
        self.shown["label"] = label
        if self.on_white("label"):
            self.restore(box)
            self.tx_time.draw(img, (TIME_AT * u, TIME_AT * u), label, "lt")
            return [box]
        crop, (cx, cy), done = self.patch(img, box, 1)
        self.time.draw(crop, (TIME_AT * u - cx, TIME_AT * u - cy), label, INK, "lt")
        note = clock.note(k) if clock.note is not None else None
        if note is not None:
            self.note.draw(crop, (TIME_AT * u - cx, ANGLE_AT * u - cy), note, GREY, "lt")
        done()
        return [box]

    def region(self, k: int) -> tuple[int, int, int, int] | None:
        """Where frame ``k`` (just drawn) can differ from frame k - 1 (px: left, top, right,
        bottom), or None: anywhere."""
        if self.changed is None:
            return None
        x0, y0, x1, y1 = self.changed
        return math.floor(x0) - 1, math.floor(y0) - 1, math.ceil(x1) + 2, math.ceil(y1) + 2

    def save(self, path: Path, fps: int) -> dict[str, float]:
        """Write every frame to ``path`` at ``fps``: a GIF, or an MP4 through imageio's
        ffmpeg plugin when the name ends in .mp4; atomically, a stop signal removing the
        partial file (:mod:`dumbbell.files` does, for every output). Returns the seconds
        spent drawing and encoding (GIF only)."""
        from .writer import binary_output, write_mp4

        stats: dict[str, float] = {}
        if path.suffix.lower() == ".mp4":
            write_mp4(path, (self.W, self.H), self.n, self.frame, fps)
        else:
            with binary_output(path) as fh:
                stats["draw"], stats["encode"] = self.write_gif(fh, fps)
        return stats

    def write_gif(self, fh: BinaryIO, fps: int, on_frame: Callable[[], object] | None = None
                  ) -> tuple[float, float]:
        """Write every frame as a GIF at ``fps`` to the binary file ``fh`` (``on_frame``
        called after each: a progress bar); returns the seconds spent drawing and
        encoding."""
        from .gif import write_frames
        from .timing import _delays

        return write_frames(fh, (self.W, self.H), self.frame, _delays(self.n, fps),
                            on_frame=on_frame, region=self.region)
