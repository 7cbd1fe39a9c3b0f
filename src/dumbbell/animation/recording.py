"""Frames of a recorded pymunk space: the painter behind :class:`dumbbell.spaces.Recorder`.

The recorder (:mod:`dumbbell.spaces.recorder`, the user's API) keeps, per capture, the space's
shapes and constraints as primitives in the space's own units and hands them over as one
frozen :class:`~.recorded.Recording`. This module paints them (framed by :mod:`.camera`,
drawn with the pens of :mod:`.pens`) and writes the GIF or MP4 (:mod:`.writer`), with the discipline of ``render_gif``: one fixed palette; everything static drawn
once (at twice the size, then halved) and mapped to the palette once; per frame only what
moves drawn, on a crop, and mapped through the palette; numbers pasted from cached glyphs;
each GIF frame after the first holding only the rectangle that changed. Same recording, same
bytes.

**Sizes.** Whatever the view, every moving body is drawn at least
:data:`~.recorded.BODY_PX` across whichever way it turns (:meth:`~.recorded.Shapes.at_least`): a smaller one is drawn larger than to
scale, and the painter says which (``Painter.grown``, named in the recorder's note).
"""

from __future__ import annotations

import itertools
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from . import writer
from .backdrop import SS, Backdrop
from .bars import SWATCH, SWATCH_GAP, EnergyScale, bar_rows, draw_legend, draw_values
from .camera import View, all_box, auto_view, fit, scene_area
from .glyphs import TEXT_PX, PaletteText, Stamps, fmt_tick, font, nice_step
from .layout import unit
from .palette import GREY, INK, LIGHT, TERM_RGB, WHITE, blend, ink_index, to_palette
from .pens import Layer, Pixels, union_px
from .recorded import BODY_PX, Box, Recording, Shapes
from .strip import GRID, fade_table

#: No public names: the painter behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Colour of each energy row.
TERM_INKS = {"K_trans": TERM_RGB["K_cm"], "K_rot": TERM_RGB["K_rot"], "U_g": TERM_RGB["U_g"],
             "U_spring": TERM_RGB["U_spring"], "E": TERM_RGB["E"], "heat": TERM_RGB["E_lost"]}
#: Height of an energy bar's row at most (px at 640x360).
ROW_MAX = 26
#: The bars start at least this far right of the panel's left edge (px at 640x360) ...
LABEL_ROOM = 70
#: ... and this far right of the end of the longest row name.
NAME_GAP = 4




class Painter(Backdrop):
    """Draws a :class:`Recording`'s frames in the fixed palette (see the module docstring)."""

    def __init__(self, rec: Recording) -> None:
        self.rec = rec
        self.W, self.H = rec.size
        self.n = rec.n
        self.u = u = unit(self.W, self.H)
        self.t = np.asarray(rec.t, dtype=float)
        self.st_time = Stamps(font(max(9, round(14 * u)), bold=True))
        self.st_text = Stamps(font(max(8, round(12 * u))))
        self.energy = rec.energy is not None
        self.strip = rec.strip and self.energy
        self.names = list(rec.energy) if rec.energy is not None else []
        self.e = {k: np.asarray(v, dtype=float) for k, v in (rec.energy or {}).items()}
        self.idx = {name: ink_index(TERM_INKS[name]) for name in self.names}
        self.idx["heat"] = ink_index(blend(TERM_INKS["heat"], 0.6))
        self.idx["ink"] = ink_index(INK)
        span = self.t[-1] - self.t[0] if self.n else 0.0
        steps = np.diff(self.t)
        least = float(steps[steps > 0].min()) if (steps > 0).any() else 1.0
        self.t_decimals = max(2, min(6, math.ceil(-math.log10(least) - 1e-9)))
        self.t_end = max(float(span), 1e-300)
        self._layout()
        if self.energy:
            self._energy_scale()
        self.base = self._base()
        self.body_px = BODY_PX * max(1.0, u)
        self._views()
        self.tx_time, self.tx_text = PaletteText(self.st_time), PaletteText(self.st_text)
        # The time label's box: wider when the longest label needs it (a large t0, a long
        # time unit), so that each label is drawn over the whole of the one before.
        longest = max((self._time_label(k) for k in range(self.n)), key=len, default="")
        self.label_box = (4 * u, 2 * u, max(150 * u, self.st_time.width(longest) + 12 * u),
                          24 * u)
        self._bg_key: tuple[int, int] | None = None
        self._layer: Layer | None = None
        self._canvas: Image.Image | None = None
        self._shown: dict[str, Any] = {}
        self._flat: dict[tuple[int, int], bool] = {}
        self.changed: tuple[float, float, float, float] | None = None
        # The shapes drawn, each body at least BODY_PX across, per set of shapes and scale.
        self._drawn: dict[tuple[int, float], Shapes] = {}
        #: Numbers of the moving bodies drawn larger than to scale (to be body_px across).
        self.grown: set[int] = set()
        # Per moving body's number: in how many frames it is, and is in the picture.
        bodies = max((int(sh.number.max()) + 1 for sh in rec.shapes if sh.n), default=0)
        self.frames_in = np.zeros(bodies, dtype=np.int64)
        self.frames_shown = np.zeros(bodies, dtype=np.int64)
        self._present: dict[int, tuple] = {}

    # --- geometry -----------------------------------------------------------------------

    def _layout(self) -> None:
        u, W, H = self.u, self.W, self.H
        self.scene_w = round(0.56 * W) if self.energy else W
        self.area = scene_area(W, H, self.energy)
        right = self.scene_w + round(10 * u)
        self.bars_box = (right, round(8 * u), W - round(8 * u),
                         round(0.55 * H) if self.strip else H - round(8 * u))
        self.strip_box = (right + round(34 * u), round(0.62 * H), W - round(12 * u),
                          H - round(22 * u))

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

    def _energy_scale(self) -> None:
        vals = [self.e[n] for n in self.names]
        if self.rec.heat:
            vals.append(self.e["E"] + self.e["heat"])
        scale = EnergyScale.of(vals)
        if scale.span <= 1e-12 and scale.lo == 0 and not any(np.any(v != 0) for v in vals):
            scale = EnergyScale(0.0, 1.0, 2)  # nothing but zeros: a plain scale, not 1e-12
        self.scale = scale
        bx0, _, bx1, _ = self.bars_box
        widest = max(abs(scale.lo), scale.hi)
        self.value_w = round(self.st_text.width(f"-{widest:.{scale.decimals}f}") + 8 * self.u)
        # The bars start right of the longest name (a negative bar reaching the scale's
        # low end must not paint over it: issue 29), and at least LABEL_ROOM from the left.
        labels = self.rec.labels or {}
        name_font = font(round(TEXT_PX * self.u))
        names_end = (round(SWATCH * self.u) + SWATCH_GAP * self.u
                     + max(name_font.getlength(labels.get(n, n)) for n in self.names))
        self.bar_left = bx0 + max(round(LABEL_ROOM * self.u),
                                  math.ceil(names_end + NAME_GAP * self.u))
        self.bar_right = bx1 - self.value_w
        self.bar_scale = (self.bar_right - self.bar_left) / scale.span
        self.bar_zero = self.bar_left - scale.lo * self.bar_scale
        self.rows = bar_rows(self.names, self.bars_box, self.u, row_max=ROW_MAX)

    def bar_px(self, v: float) -> float:
        return self.bar_zero + v * self.bar_scale

    def strip_y(self, v: Any) -> Any:
        _, sy0, _, sy1 = self.strip_box
        pad = 3 * self.u
        lo, hi = self.scale.lo, self.scale.hi
        return sy1 - pad - (sy1 - sy0 - 2 * pad) * (v - lo) / (hi - lo)

    def strip_x(self, t: Any) -> Any:
        sx0, _, sx1, _ = self.strip_box
        return sx0 + 1 + (sx1 - sx0 - 2) * (t - self.t[0]) / self.t_end

    def _base(self) -> Image.Image:
        """The frame without its scene: white, the energy panel's legend and strip (RGB,
        :data:`SS` times the size)."""
        W, H, u, S = self.W, self.H, self.u, SS
        img = Image.new("RGB", (W * S, H * S), WHITE)
        d = ImageDraw.Draw(img)
        if self.energy:
            d.line([(self.scene_w * S, 8 * u * S), (self.scene_w * S, (H - 8 * u) * S)],
                   fill=LIGHT, width=S)
            labels = self.rec.labels or {}
            draw_legend(d, S, u, self.bars_box, self.rows, TERM_INKS.__getitem__, self.bar_zero,
                        title=self.rec.energy_title, label=lambda n: labels.get(n, n))
            if self.strip:
                self._strip_static(d, S)
        return img

    def background(self, k: int) -> bool:
        """Make frame ``k``'s background current (``bg``, ``bg_rgb``, ``bg_ss``): the base
        with the static shapes of its static set seen through its view, and the title.
        Returns whether it changed."""
        version, view = self.rec.static_of[k], self.views[k]
        key = (version, id(view))
        if key == self._bg_key:
            return False
        u, S = self.u, SS
        img = self.base.copy()
        scene = Image.new("RGB", (self.scene_w * S, self.H * S), WHITE)
        Pixels.of_items(self.rec.statics[version], view, self.u).draw(ImageDraw.Draw(scene),
                                                                      (0, 0))
        img.paste(scene, (0, 0))
        if self.rec.title:
            ImageDraw.Draw(img).text(((self.scene_w - 8 * u) * S, 6 * u * S), self.rec.title,
                                     font=font(round(12 * u) * S, True), fill=INK, anchor="rt")
        self.bg = to_palette(img.reduce(S))
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * S, self.H * S), Image.Resampling.NEAREST)
        self._bg_key = key
        # Text is pasted from glyphs drawn on white where the background is white.
        white = ink_index(WHITE)
        self._white = {name: bool((np.asarray(self.bg.crop(_whole(box, self.W, self.H)))
                                   == white).all())
                       for name, box in (("label", self.label_box),
                                         ("values", self._values_box()))}
        if self.energy:
            self._band_of = self._bands()
        if self.strip:
            # Inside the strip's frame: the whole run's curves, and the same faded, which a
            # frame shows after its cursor (what has not happened yet, as the GIF's strip).
            sx0, sy0, sx1, sy1 = (round(v) for v in self.strip_box)
            self._inner = (sx0 + 1, sy0 + 1, sx1, sy1)
            self._past = self.bg.crop(self._inner)
            self._future = self._past.point(fade_table())
        return True

    def _strip_static(self, d: ImageDraw.ImageDraw, S: int) -> None:
        u = self.u
        sx0, sy0, sx1, sy1 = self.strip_box
        fs = font(round(10 * u) * S)
        d.rectangle([sx0 * S, sy0 * S, sx1 * S + S - 1, sy1 * S + S - 1], outline=LIGHT, width=S)
        for v in self.scale.ticks():
            y = self.strip_y(v) * S
            d.line([((sx0 + 1) * S, y), ((sx1 - 1) * S, y)], fill=GRID, width=S)
            d.text(((sx0 - 4 * u) * S, y), fmt_tick(v), font=fs, fill=GREY, anchor="rm")
        t0, end = float(self.t[0]), float(self.t[-1])
        tstep = nice_step((end - t0) / 4) if end > t0 else 1.0
        for k in range(math.ceil(t0 / tstep - 1e-9), math.floor(end / tstep + 1e-9) + 1):
            x = self.strip_x(k * tstep) * S
            d.line([(x, sy1 * S), (x, (sy1 + 3 * u) * S)], fill=GREY, width=S)
            d.text((x, (sy1 + 5 * u) * S), fmt_tick(k * tstep), font=fs, fill=GREY, anchor="mt")
        d.text(((sx0 - 4 * u) * S, (sy1 + 5 * u) * S), f"t ({self.rec.time_unit})", font=fs,
               fill=GREY, anchor="rt")
        xs = self.strip_x(self.t) * S
        width = max(1, round(1.5 * u * S))
        series = [(n, TERM_INKS[n], self.e[n]) for n in self.names if n != "E"]
        if self.rec.heat:
            series.append(("E + heat", blend(TERM_INKS["heat"], 0.6), self.e["E"] + self.e["heat"]))
        series.append(("E", TERM_INKS["E"], self.e["E"]))
        for _, rgb, v in series:
            ys = self.strip_y(v) * S
            ok = np.isfinite(ys)
            if ok.sum() < 2:
                continue
            d.line(list(zip(xs[ok].tolist(), ys[ok].tolist(), strict=True)), fill=rgb,
                   width=width, joint="curve")

    # --- one frame --------------------------------------------------------------------------

    def frame(self, k: int) -> Image.Image:
        """Frame ``k`` as a palette image (the painter's canvas: drawn over by the next
        frame). From one frame to the next only what changed is drawn again: the moving
        layer's changed boxes (see :class:`Layer`), the time label, the bars and the cursor
        when theirs changed."""
        fresh = self.background(k)
        layer = self.layer(k)
        self._count(layer)
        touched: list[tuple[float, float, float, float]] | None = []
        if fresh or self._canvas is None or self._layer is None:
            self._canvas, self._shown, touched = self.bg.copy(), {}, None
            rects = [layer.box] if layer.box is not None else []
        else:
            rects = layer.damage(self._layer)
            if rects is None:
                # The whole layer again: the previous one's pixels go first.
                old = self._layer.box
                if old is not None:
                    self._restore(old)
                    touched.append(old)  # type: ignore[union-attr]
                rects = [layer.box] if layer.box is not None else []
            touched += rects  # type: ignore[operator]
        img = self._canvas
        for rect in rects:
            if layer.flat:
                # Straight in palette indices on a crop of the background.
                whole = _whole(rect, self.W, self.H)
                crop = self.bg.crop(whole)
                layer.draw(ImageDraw.Draw(crop), whole[:2], whole)
                img.paste(crop, whole[:2])
                continue
            crop, (cx, cy), done = self.patch(img, rect, SS)
            # Everything that meets the crop (whole pixels around the rectangle) is drawn.
            layer.draw(ImageDraw.Draw(crop), (cx, cy),
                       (cx, cy, cx + crop.width / SS, cy + crop.height / SS))
            done()
        self._layer = layer
        parts = self._label(img, k, [] if touched is None else touched)
        if self.energy:
            parts += self._bars(img, k)
            if self.strip:
                parts += self._cursor(img, k)
        if touched is None:
            self.changed = None
        else:
            touched += parts
            self.changed = union_px(touched) if touched else (0.0, 0.0, 0.0, 0.0)
        return img

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

    def _restore(self, box: tuple[float, float, float, float]) -> tuple[int, int, int, int]:
        """Put the background back over the whole pixels that cover ``box`` (px); returns
        them (left, top, right, bottom)."""
        whole = _whole(box, self.W, self.H)
        if whole[2] > whole[0] and whole[3] > whole[1]:
            # Through Pillow's core (both "P", the canvas a copy of its own): no per-call
            # checks.
            self._canvas.im.paste(self.bg.im.crop(whole), whole)  # type: ignore[union-attr]
        return whole

    def _label(self, img: Image.Image, k: int, scene: list[tuple[float, float, float, float]]
               ) -> list[tuple[float, float, float, float]]:
        """Draw the time label if it changed or the scene was drawn over it; the box
        touched."""
        u, box = self.u, self.label_box
        label = self._time_label(k)
        if self._shown.get("label") == label and not any(_meets(r, box) for r in scene):
            return []
        self._shown["label"] = label
        if self._white["label"]:
            self._restore(box)
            self.tx_time.draw(img, (6 * u, 6 * u), label, "lt")
        else:
            crop, (cx, cy), done = self.patch(img, box, 1)
            self.st_time.draw(crop, (6 * u - cx, 6 * u - cy), label, INK, "lt")
            done()
        return [box]

    def _time_label(self, k: int) -> str:
        return f"t = {self.t[k]:.{self.t_decimals}f} {self.rec.time_unit}"

    def _values_box(self) -> tuple[float, float, float, float]:
        """Where the bars' values are written (px)."""
        if not self.energy:
            return (0.0, 0.0, 1.0, 1.0)
        return (self.bar_right + 2, self.rows[0][1] - 3, self.bars_box[2], self.rows[-1][2] + 3)

    def region(self, k: int) -> tuple[int, int, int, int] | None:
        """Where frame ``k`` (just drawn) can differ from frame k - 1 (px: left, top, right,
        bottom), or None: anywhere."""
        if self.changed is None:
            return None
        x0, y0, x1, y1 = self.changed
        return math.floor(x0) - 1, math.floor(y0) - 1, math.ceil(x1) + 2, math.ceil(y1) + 2

    def _bands(self) -> list[tuple[int, int]]:
        """Each bar's band (px: top, bottom): from the middle of the gap above it to the
        middle of the gap below it (the panel's block, first and last); one band for all
        bars when a value's text would not fit in its own (so redrawing a band never touches
        another's)."""
        rows = self.rows
        edges = [rows[0][1] - 3]
        edges += [(bot + nxt) // 2 for (_, _, bot), (_, nxt, _) in itertools.pairwise(rows)]
        edges.append(rows[-1][2] + 3)
        ascent, descent = self.st_text.font.getmetrics()
        fits = all(lo <= round((top + bot) / 2 + self.st_text.cap / 2) - ascent - 2
                   and round((top + bot) / 2 + self.st_text.cap / 2) + descent + 2 <= hi
                   for (_, top, bot), lo, hi in zip(rows, edges, edges[1:]))
        if not fits or not self._white["values"]:
            return [(edges[0], edges[-1])] * len(rows)
        return list(itertools.pairwise(edges))

    def _bars(self, img: Image.Image, k: int) -> list[tuple[float, float, float, float]]:
        """Draw again the bars (with their values) that changed; the boxes touched."""
        values = {n: float(self.e[n][k]) for n in self.names}
        spans = self._spans(values)
        bands = self._band_of
        shown = self._shown.get("bars") or [None] * len(spans)
        redo = sorted({bands[j] for j, span in enumerate(spans) if span != shown[j]})
        if not redo:
            return []
        self._shown["bars"] = spans
        d = ImageDraw.Draw(img)
        bx1 = self.bars_box[2]
        boxes: list[tuple[float, float, float, float]] = []
        for band in redo:
            box = (self.bar_left - 1, band[0], self.W, band[1])
            self._restore(box)
            boxes.append(box)
            for j in (j for j, b in enumerate(bands) if b == band):
                name, top, bot = self.rows[j]
                extent, text = spans[j]
                if extent is not None:
                    a, b, h = extent
                    if h > b:
                        d.rectangle([b, top, h - 1, bot - 1], fill=self.idx["heat"])
                    if b > a:
                        d.rectangle([a, top, b - 1, bot - 1], fill=self.idx[name])
                if self._white["values"]:
                    self.tx_text.draw(img, (bx1, (top + bot) / 2), text, "rm")
            if not self._white["values"]:
                draw_values(self.patch(img, self._values_box(), 1), self.rows,
                            lambda name: self.scale.text(values[name]), bx1, self.st_text)
        return boxes

    def _spans(self, values: dict[str, float]) -> list[tuple[tuple[int, int, int] | None, str]]:
        """Each bar's pixels (its start, its end, the end of E + heat; None when its value is
        not finite) and its value's text."""
        spans: list[tuple[tuple[int, int, int] | None, str]] = []
        for name, _, _ in self.rows:
            v = values[name]
            if not math.isfinite(v):
                spans.append((None, self.scale.text(v)))
                continue
            a, b = sorted((round(self.bar_px(0.0)), round(self.bar_px(v))))
            h = b
            if name == "E" and self.rec.heat and values["heat"] > 0:
                # E + heat: what E was, were no energy lost to the contacts.
                h = max(b, round(self.bar_px(v + values["heat"])))
            spans.append(((a, b, h), self.scale.text(v)))
        return spans

    def _cursor(self, img: Image.Image, k: int) -> list[tuple[float, float, float, float]]:
        """Move the strip's cursor if it moved, the curves after it faded; the boxes
        touched."""
        u = self.u
        _, sy0, _, sy1 = self.strip_box
        x = round(float(self.strip_x(self.t[k])))
        before = self._shown.get("cursor")
        if before == x:
            return []
        self._shown["cursor"] = x
        half = 2 * u + 1
        boxes = [(x - half, sy0, x + half, sy1)]
        if before is not None:
            boxes.append(self._restore((before - half, sy0, before + half, sy1)))
        # The columns between the two cursors turn from future to past (or back).
        ix0, iy0, ix1, iy1 = self._inner
        lo = ix0 if before is None else max(ix0, math.floor(min(before, x) - half) - 1)
        hi = ix1 if before is None else min(ix1, math.ceil(max(before, x) + half) + 2)
        for a, b, src in ((lo, min(hi, x + 1), self._past), (max(lo, x + 1), hi, self._future)):
            if b > a:
                img.paste(src.crop((a - ix0, 0, b - ix0, iy1 - iy0)), (a, iy0))
        if hi > lo:
            boxes.append((lo, iy0, hi, iy1))
        ImageDraw.Draw(img).line([(x, sy0 + 1), (x, sy1 - 1)], fill=self.idx["ink"],
                                 width=max(1, round(1.2 * u)))
        return boxes



def _whole(box: tuple[float, float, float, float], width: int = 1 << 30,
           height: int = 1 << 30) -> tuple[int, int, int, int]:
    """The whole pixels that cover ``box`` (px: left, top, right, bottom), within the frame."""
    return (max(0, math.floor(box[0])), max(0, math.floor(box[1])),
            min(width, math.ceil(box[2])), min(height, math.ceil(box[3])))


def _meets(a: tuple[float, float, float, float], b: tuple[float, float, float, float]) -> bool:
    return not (a[2] < b[0] or a[0] > b[2] or a[3] < b[1] or a[1] > b[3])


def write(path: Path, rec: Recording, timing: dict[str, float] | None = None) -> Painter:
    """Paint ``rec`` and write it to ``path`` (.gif, or .mp4 through imageio's ffmpeg plugin),
    atomically; ``timing`` receives the seconds spent. Returns the painter (its ``view``)."""
    t0 = time.perf_counter()
    painter = Painter(rec)
    stats = {"setup": time.perf_counter() - t0}
    stats.update(writer.save(path, painter, rec.fps))
    stats.update(frames=painter.n, total=time.perf_counter() - t0)
    if timing is not None:
        timing.update(stats)
    return painter
