"""The view panel of a recorded pymunk space, and the painter of a recording: what draws
:class:`dumbbell.spaces.Recorder`'s file.

The recorder (:mod:`dumbbell.spaces.recorder`, the user's API) keeps, per capture, the space's
shapes and constraints as primitives in the space's own units and hands them over as one
frozen :class:`~.recorded.Recording`. This module frames them (:mod:`.camera`) and draws them
with the pens of :mod:`.pens` as the picture panel (:class:`ViewPanel`) of the one painter of
:mod:`.painter`, beside the energy bars and the strip every animation has (:mod:`.bars`,
:mod:`.strip`), which writes the GIF or MP4. Per frame only the moving layer's
boxes that changed are drawn again. Same recording, same bytes.

**Sizes.** Whatever the view, every moving body is drawn at least
:data:`~.recorded.BODY_PX` across whichever way it turns (:meth:`~.recorded.Shapes.at_least`):
a smaller one is drawn larger than to scale, and the panel says which (``ViewPanel.grown``,
named in the recorder's note).
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from .bars import Bars, Readings
from .camera import View, all_box, auto_view, fit
from .glyphs import TIME_PX, Stamps, font
from .layout import space_layout, unit
from .painter import SS, Clock, Painter, Rect, whole
from .palette import INK, WHITE
from .pens import Layer, Pixels
from .recorded import BODY_PX, Box, Recording, Shapes
from .strip import Strip

#: No public names: the painter behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: The title, this far left of the picture panel's right edge and from the top (px at
#: 640x360), in bold of this size.
TITLE_AT, TITLE_PX = (8, 6), 12


def _fitted(text: str, face: Any, room: float) -> str:
    """``text``, cut short with an ellipsis if it is longer than ``room`` (px) in ``face``
    (the title, beside the time label: never over it)."""
    if face.getlength(text) <= room:
        return text
    lo, hi = 0, len(text)  # the longest prefix that fits with the ellipsis: in [lo, hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if face.getlength(text[:mid] + "\u2026") <= room else (lo, mid)
    return text[:lo].rstrip() + "\u2026" if lo else ""


class ViewPanel:
    """The picture panel of a recorded space's frames (for :class:`~.painter.Painter`):
    ``rec`` framed by its camera onto ``area`` (px: left, top, width, height) of a panel
    ``scene_w`` px wide, at length unit ``u``. Its static shapes are the background (a new
    one when they or the view change); per frame only the moving layer's boxes that changed
    are drawn again."""

    fresh_every_frame = False
    text_on_white = True

    def __init__(self, rec: Recording, scene_w: int, area: tuple[int, int, int, int]) -> None:
        self.rec, self.scene_w, self.area = rec, scene_w, area
        self.W, self.H = rec.size
        self.u = u = unit(self.W, self.H)
        self.n = rec.n
        self.width = scene_w
        self.t = t = np.asarray(rec.t, dtype=float)
        self.t_decimals = time_decimals(t)
        # The time label's box: wider when the longest label needs it (a large t0, a long
        # time unit), so that each label is drawn over the whole of the one before.
        longest = max((self.label(k) for k in range(rec.n)), key=len, default="")
        stamps = Stamps(font(max(9, round(TIME_PX * u)), bold=True))
        box = (4 * u, 2 * u, max(150 * u, stamps.width(longest) + 12 * u), 24 * u)
        self.clock = Clock(box, self.label)
        self.body_px = BODY_PX * max(1.0, u)
        self._views()
        self._layer: Layer | None = None
        self._flat: dict[tuple[int, int], bool] = {}
        # The shapes drawn, each body at least BODY_PX across, per set of shapes and scale.
        self._drawn: dict[tuple[int, float], Shapes] = {}
        #: Numbers of the moving bodies drawn larger than to scale (to be body_px across).
        self.grown: set[int] = set()
        # Per moving body's number: in how many frames it is, and is in the picture.
        bodies = max((int(sh.number.max()) + 1 for sh in rec.shapes if sh.n), default=0)
        self.frames_in = np.zeros(bodies, dtype=np.int64)
        self.frames_shown = np.zeros(bodies, dtype=np.int64)
        self._present: dict[int, tuple] = {}

    def _views(self) -> None:
        """One view per frame (the same object while the camera holds still)."""
        rec = self.rec
        _, _, aw, ah = self.area
        if rec.camera == "follow":
            w, h = (rec.span, rec.span * ah / aw) if aw >= ah else (rec.span * aw / ah, rec.span)
            views, last = [], None
            for cx, cy in rec.follow:
                if math.isfinite(cx) and math.isfinite(cy) or last is None:
                    box = fit((cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2), aw, ah, 0.0)
                    last = View.of(box, self.area, rec.y_up)
                views.append(last)
            self.views = views
            return
        if rec.camera == "box" and rec.box is not None:
            box = fit(rec.box, aw, ah, 0.0)
        elif rec.camera == "all":
            box = fit(all_box(rec), aw, ah)
        else:
            box = auto_view(rec, aw, ah, self.body_px)
        self.views = [View.of(box, self.area, rec.y_up)] * self.n

    @property
    def view(self) -> Box:
        """The world box of the first frame's view (x0, x1, y0, y1; y0 < y1)."""
        return self.views[0].box

    def label(self, k: int) -> str:
        """Frame ``k``'s time label."""
        return f"t = {self.t[k]:.{self.t_decimals}f} {self.rec.time_unit}"

    def draw_base(self, d: ImageDraw.ImageDraw, S: int) -> None:
        pass  # the static shapes depend on the frame's view

    def static_key(self, k: int) -> object:
        return self.rec.static_of[k], id(self.views[k])

    def draw_static(self, img: Image.Image, k: int) -> None:
        """The static shapes of frame ``k``'s static set seen through its view, and the
        title, on ``img`` (RGB, :data:`SS` times the size)."""
        u, S = self.u, SS
        scene = Image.new("RGB", (self.scene_w * S, self.H * S), WHITE)
        Pixels.of_items(self.rec.statics[self.rec.static_of[k]], self.views[k],
                        self.u).draw(ImageDraw.Draw(scene), (0, 0))
        img.paste(scene, (0, 0))
        if self.rec.title:
            face = font(round(TITLE_PX * u) * S, True)
            right = (self.scene_w - TITLE_AT[0] * u) * S
            x, _, w, _ = self.clock.box
            room = right - (x + w + TITLE_AT[0] * u) * S  # right of the time label's box
            ImageDraw.Draw(img).text((right, TITLE_AT[1] * u * S),
                                     _fitted(self.rec.title, face, room), font=face,
                                     fill=INK, anchor="rt")

    def draw(self, painter: Painter, img: Image.Image, k: int, fresh: bool
             ) -> list[Rect] | None:
        """Frame ``k``'s moving layer: the whole of it on a ``fresh`` background, else only
        the boxes that changed (see :class:`~.pens.Layer`); the boxes drawn (None when
        fresh)."""
        layer = self.layer(k)
        self._count(layer)
        touched: list[Rect] | None = None
        if fresh or self._layer is None:
            rects = [layer.box] if layer.box is not None else []
        else:
            touched = []
            rects = layer.damage(self._layer)
            if rects is None:
                # The whole layer again: the previous one's pixels go first.
                old = self._layer.box
                if old is not None:
                    painter.restore(old)
                    touched.append(old)
                rects = [layer.box] if layer.box is not None else []
            touched += rects
        for rect in rects:
            if layer.flat:
                # Straight in palette indices on a crop of the background.
                box = whole(rect, self.W, self.H)
                crop = painter.bg.crop(box)
                layer.draw(ImageDraw.Draw(crop), box[:2], box)
                img.paste(crop, box[:2])
                continue
            crop, (cx, cy), done = painter.patch(img, rect, SS)
            # Everything that meets the crop (whole pixels around the rectangle) is drawn.
            layer.draw(ImageDraw.Draw(crop), (cx, cy),
                       (cx, cy, cx + crop.width / SS, cy + crop.height / SS))
            done()
        self._layer = layer
        return touched

    def layer(self, k: int) -> Layer:
        """Frame ``k``'s moving layer, flat or smooth as decided when its set of shapes was
        first seen through its view."""
        rec, view, i = self.rec, self.views[k], self.rec.shape_of[k]
        px = Pixels(self._shapes(i, view), rec.poses[k], rec.extras[k], view, self.u)
        key = (i, id(view))
        if key not in self._flat:
            self._flat[key] = Layer.many_small(px)
        return Layer(px, (self.scene_w, self.H), self._flat[key])

    def _shapes(self, i: int, view: View) -> Shapes:
        """Set ``i`` of moving shapes as drawn through ``view``: each body at least
        :attr:`body_px` across (:meth:`Shapes.at_least`); the same object for the same set
        and scale, so that frames compare their pixels."""
        key = (i, view.s)
        got = self._drawn.get(key)
        if got is None:
            got, grown = self.rec.shapes[i].at_least(view.s, self.body_px)
            self._drawn[key] = got
            self.grown.update(grown.tolist())
        return got

    def _count(self, layer: Layer) -> None:
        """Count the moving bodies of a frame, and those it shows (a shape of theirs drawn
        on the scene panel)."""
        px, n = layer.px, layer.px.n_shapes
        if not n or not len(self.frames_in):
            return
        shapes = px.shapes
        got = self._present.get(id(shapes))
        if got is None or got[0] is not shapes:
            number = shapes.number  # type: ignore[union-attr]
            mine = number >= 0
            present = np.bincount(number[mine], minlength=len(self.frames_in)) > 0
            got = self._present[id(shapes)] = (shapes, number, mine, present)
        _, number, mine, present = got
        self.frames_in += present
        box = px.box
        if box is not None and px.ok[:n].all() and box[0] >= 0 and box[1] >= 0 and (
                box[2] <= self.scene_w and box[3] <= self.H):
            self.frames_shown += present  # everything drawn is on the panel
            return
        shown = px.within((0.0, 0.0, float(self.scene_w), float(self.H)))[:n] & mine
        self.frames_shown += np.bincount(number[shown], minlength=len(self.frames_in)) > 0


def time_decimals(t: np.ndarray) -> int:
    """Decimals of the time labels of frames at times ``t``: enough to tell the closest two
    apart (2 to 6)."""
    steps = np.diff(t)
    least = float(steps[steps > 0].min()) if (steps > 0).any() else 1.0
    return max(2, min(6, math.ceil(-math.log10(least) - 1e-9)))


def painter_of(rec: Recording) -> Painter:
    """The painter of ``rec``: its view panel, and with energy the bars (and the strip) of
    its rows."""
    W, H = rec.size
    energy = rec.energy is not None
    strip = rec.strip and energy
    scene_w, area, bars_box, strip_box = space_layout(W, H, energy, strip)
    panel = ViewPanel(rec, scene_w, area)
    readings = Readings(panel.t, {k: np.asarray(v, dtype=float)
                                  for k, v in (rec.energy or {}).items()})
    bars = Bars.of_space(bars_box, rec, readings) if energy else None
    panel_strip = Strip.whole_run(strip_box, bars.scale, rec, readings) if strip else None
    return Painter((W, H), panel, bars, panel_strip, readings)


def write(path: Path, rec: Recording, timing: dict[str, float] | None = None) -> ViewPanel:
    """Paint ``rec`` and write it to ``path`` (.gif, or .mp4 through imageio's ffmpeg plugin),
    atomically; ``timing`` receives the seconds spent. Returns the view panel (its ``view``,
    the bodies it grew, the frames each body is in and shown)."""
    t0 = time.perf_counter()
    painter = painter_of(rec)
    stats = {"setup": time.perf_counter() - t0}
    stats.update(painter.save(path, rec.fps))
    stats.update(frames=painter.n, total=time.perf_counter() - t0)
    if timing is not None:
        timing.update(stats)
    return painter.panel
