"""Frames of a recorded pymunk space: the painter behind :class:`dumbbell.spaces.Recorder`.

The recorder (:mod:`dumbbell.spaces.recorder`, the user's API) keeps, per capture, the space's
shapes and constraints as primitives in the space's own units and hands them over as one
frozen :class:`Recording`. This module frames them (the camera), paints them and writes the
GIF or MP4, with the discipline of ``render_gif``: one fixed palette; everything static drawn
once (at twice the size, then halved) and mapped to the palette once; per frame only what
moves drawn, on a crop, and mapped through the palette; numbers pasted from cached glyphs;
each GIF frame after the first holding only the rectangle that changed. Same recording, same
bytes.

Primitives (tuples; ``ink`` indexes :data:`BODY_INKS`, -1 is grey; ``body`` numbers the
moving body, dynamic or kinematic, that the shape belongs to, or that a constraint joins; -1
for static)::

    ("circle", ink, body, x, y, r, angle)      ("spring", ink, body, ax, ay, bx, by)
    ("seg", ink, body, ax, ay, bx, by, r)      ("line", ink, body, ax, ay, bx, by)
    ("poly", ink, body, (x0, y0, x1, y1, ...), r)   ("dot", ink, body, x, y)
    ("rotary", ink, body, x, y, twist)

**The camera.** ``"auto"`` chooses one view for the whole file, so nothing jitters. It pools
the positions of every moving element (each moving body's shapes, and each constraint that
holds one, static anchors included) at every frame, and keeps those whose centre lies within
:data:`FENCE` interquartile ranges of the middle half of all centres along x and along y
(Tukey's far-out fences; the range is the larger of x's and y's, and at least the median
element's size), and every element of the first frame. The view holds the kept elements: a body that flies away (or strays for a small
share of the time) leaves the picture instead of shrinking everything else. Static shapes
within :data:`NEAR` of that box (a share of its size along each axis) are added, a floor under
the bodies say; one that runs past the near zone on both sides along an axis (a long floor, a
tall wall) does not widen the view along it. The box is at least :data:`MIN_SIZE` times the
median element's size, padded by :data:`PAD` and fitted to the scene panel. ``"all"`` shows
everything ever captured, static shapes included; a fixed box is the user's; ``"follow"``
keeps one body at the centre of a view of fixed size.
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import signal
import threading
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, ImageDraw

from ..errors import DumbbellError
from ..io.files import atomic_output
from .backdrop import SS, Backdrop
from .bars import EnergyScale, bar_rows, draw_legend, draw_values
from .gif import write_frames
from .glyphs import Stamps, fmt_tick, font, nice_step
from .layout import unit
from .palette import (
    GREY,
    INK,
    LIGHT,
    SPRING,
    TERM_RGB,
    WHITE,
    blend,
    ink_index,
    palette,
    to_palette,
)
from .render import delays_cs
from .strip import GRID
from .world import zigzag

#: No public names: the painter behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Inks of the moving bodies, by their order in the space (then again from the start).
BODY_INKS = tuple(TERM_RGB[n] for n in ("A", "B", "K_rot", "K_spin", "U_g", "U_spring"))
#: Colour of each energy row.
TERM_INKS = {"K_trans": TERM_RGB["K_cm"], "K_rot": TERM_RGB["K_rot"], "U_g": TERM_RGB["U_g"],
             "U_spring": TERM_RGB["U_spring"], "E": TERM_RGB["E"], "heat": TERM_RGB["E_lost"]}
#: Fill of static shapes.
STATIC_FILL = (232, 232, 232)
#: Outline and fill of a shape by its ink (-1, the last: static and kinematic shapes).
SHAPE_COLOURS = (*((rgb, blend(rgb, 0.33)) for rgb in BODY_INKS), (GREY, STATIC_FILL))
#: Height of an energy bar's row at most (px at 640x360).
ROW_MAX = 26
#: The camera: a moving body's position counts unless it lies more than this many
#: interquartile ranges beyond the middle half of all positions (Tukey's far-out fences) ...
FENCE = 3.0
#: ... static shapes this near the bodies' box (a share of its size along each axis) count ...
NEAR = 0.25
#: ... the view is at least this many times the median body's size ...
MIN_SIZE = 4.0
#: ... with this margin (a share of its span) on each side.
PAD = 0.05
#: A spring's zig-zag: its coils, and its half-width at most (px at 640x360).
COILS, SPRING_WIDTH = 9, 5.0
#: Pixel coordinates are clipped to this far outside the frame (px) before drawing.
CLIP = 1e5
#: The shortest and longest span (space units) a view may have.
SPAN_MIN, SPAN_MAX = 1e-30, 1e30
#: Signals that end a script by default: while the file is written they remove its ``.part``
#: file first, then end the script as they would have.
STOP_SIGNALS = ("SIGTERM", "SIGHUP")

Box = tuple[float, float, float, float]  # x0, x1, y0, y1 with x0 <= x1, y0 <= y1


@dataclass(frozen=True)
class Recording:
    """Everything the painter needs, frozen: per frame its moving primitives, which static set
    it shows (``static_of`` indexes ``statics``) and its time; the frame ``size`` (px) and
    ``fps``; ``y_up``; the camera (``camera`` "auto", "all", "box" with ``box``, or
    "follow" with a centre per frame in ``follow`` and the view's larger side ``span``); the
    energy rows (name -> values shown, in ``energy``; None without bars) with their labels
    and ``energy_title``; ``heat`` (the last row is heat, and E's row shows E + heat pale);
    ``strip``; the ``title``; the time unit."""

    frames: tuple[tuple[tuple, ...], ...]
    statics: tuple[tuple[tuple, ...], ...]
    static_of: tuple[int, ...]
    t: tuple[float, ...]
    size: tuple[int, int]
    fps: int
    y_up: bool = True
    camera: str = "auto"
    box: Box | None = None
    follow: tuple[tuple[float, float], ...] = ()
    span: float = 0.0
    energy: Mapping[str, np.ndarray] | None = None
    labels: Mapping[str, str] | None = None
    energy_title: str = "Energy (J)"
    heat: bool = False
    strip: bool = True
    title: str = ""
    time_unit: str = "s"


# --- the camera --------------------------------------------------------------------------------


def item_box(it: tuple) -> Box:
    """World box of one primitive (nan where it has none)."""
    kind = it[0]
    if kind == "circle":
        _, _, _, x, y, r, _ = it
        return x - r, x + r, y - r, y + r
    if kind == "seg":
        _, _, _, ax, ay, bx, by, r = it
        return min(ax, bx) - r, max(ax, bx) + r, min(ay, by) - r, max(ay, by) + r
    if kind == "poly":
        flat, r = it[3], it[4]
        xs, ys = flat[0::2], flat[1::2]
        if not xs:
            return (math.nan,) * 4
        return min(xs) - r, max(xs) + r, min(ys) - r, max(ys) + r
    if kind in ("spring", "line"):
        _, _, _, ax, ay, bx, by = it
        return min(ax, bx), max(ax, bx), min(ay, by), max(ay, by)
    x, y = it[3], it[4]  # dot, rotary
    return x, x, y, y


def _finite(boxes: np.ndarray) -> np.ndarray:
    return boxes[np.isfinite(boxes).all(axis=1)] if len(boxes) else boxes.reshape(0, 4)


#: Kinds of primitive that are a body's shape (the others are constraints).
SHAPES = ("circle", "seg", "poly")


@dataclass(frozen=True)
class Measured:
    """One frame's primitives measured once: each one's world box (n x 4: x0, x1, y0, y1),
    a point that turns with it (n x 2: a polygon's first corner, the end of a circle's radius
    line, a segment's or constraint's first end; a rotary spring's twist and 0), and its
    element: the number of the moving body whose shape it is, or ``-1 - j`` for the j-th
    primitive (a constraint, or a shape on no moving body), alone."""

    box: np.ndarray
    turn: np.ndarray
    key: np.ndarray
    rotary: np.ndarray
    #: Indices of the polygons, by their number of coordinates (twice their corners).
    poly_groups: dict[int, list[int]]
    polys: list[int]

    @classmethod
    def of(cls, items: tuple[tuple, ...]) -> Measured:
        n = len(items)
        box, turn = np.full((n, 4), math.nan), np.full((n, 2), math.nan)
        groups: dict[Any, list[int]] = {}
        for j, it in enumerate(items):
            groups.setdefault(it[0] if it[0] != "poly" else len(it[3]), []).append(j)
        for kind, idx in groups.items():
            _measure(kind, [items[j] for j in idx], box, turn, np.array(idx))
        keys = [it[2] if it[0] in SHAPES and it[2] >= 0 else -1 - j
                for j, it in enumerate(items)]
        polys = [j for kind, idx in groups.items() if not isinstance(kind, str) for j in idx]
        return cls(box, turn, np.array(keys, dtype=int),
                   np.array([it[0] == "rotary" for it in items], dtype=bool),
                   {k: idx for k, idx in groups.items() if not isinstance(k, str)}, polys)

    def elements(self) -> np.ndarray:
        """World boxes of the elements (one per moving body, one per other primitive), finite
        ones only."""
        if not len(self.key):
            return np.zeros((0, 4))
        keys, inverse = np.unique(self.key, return_inverse=True)
        out = np.empty((len(keys), 4))
        out[:, [0, 2]], out[:, [1, 3]] = np.inf, -np.inf
        with np.errstate(invalid="ignore"):  # a body at nan is no element
            np.minimum.at(out[:, 0], inverse, self.box[:, 0])
            np.maximum.at(out[:, 1], inverse, self.box[:, 1])
            np.minimum.at(out[:, 2], inverse, self.box[:, 2])
            np.maximum.at(out[:, 3], inverse, self.box[:, 3])
        return _finite(out)


def _measure(kind: Any, items: list[tuple], box: np.ndarray, turn: np.ndarray,
             idx: np.ndarray) -> None:
    """Fill ``box`` and ``turn`` (see :class:`Measured`) at rows ``idx`` for ``items``, all
    of one kind (a polygon's kind: its number of coordinates)."""
    if not isinstance(kind, str):  # polygons with kind / 2 corners
        if not kind:
            return
        flat = np.array([it[3] for it in items], dtype=float)
        r = np.array([it[4] for it in items], dtype=float)
        xs, ys = flat[:, 0::2], flat[:, 1::2]
        box[idx] = np.stack([xs.min(1) - r, xs.max(1) + r, ys.min(1) - r, ys.max(1) + r], 1)
        turn[idx] = flat[:, :2]
        return
    a = np.array([it[3:] for it in items], dtype=float)
    if kind == "circle":  # x, y, r, angle
        x, y, r, ang = a.T
        box[idx] = np.stack([x - r, x + r, y - r, y + r], 1)
        turn[idx] = np.stack([x + r * np.cos(ang), y + r * np.sin(ang)], 1)
    elif kind in ("seg", "spring", "line"):  # ax, ay, bx, by (, r)
        r = a[:, 4] if kind == "seg" else 0.0
        box[idx] = np.stack([np.minimum(a[:, 0], a[:, 2]) - r, np.maximum(a[:, 0], a[:, 2]) + r,
                             np.minimum(a[:, 1], a[:, 3]) - r, np.maximum(a[:, 1], a[:, 3]) + r],
                            1)
        turn[idx] = a[:, :2]
    else:  # dot (x, y), rotary (x, y, twist)
        box[idx] = a[:, [0, 0, 1, 1]]
        turn[idx] = a[:, :2] if kind == "dot" else np.stack([a[:, 2], 0 * a[:, 2]], 1)


def element_boxes(measured: list[Measured]) -> tuple[np.ndarray, np.ndarray]:
    """World boxes (n x 4: x0, x1, y0, y1) of the moving elements of every frame, finite
    ones only, and the frame of each: each moving body's shapes (one box per body and frame),
    and each constraint."""
    parts = [m.elements() for m in measured]
    where = np.concatenate([np.full(len(p), k, dtype=int) for k, p in enumerate(parts)]
                           + [np.zeros(0, dtype=int)])
    return np.concatenate([*parts, np.zeros((0, 4))]), where


def _union(boxes: np.ndarray) -> Box | None:
    if not len(boxes):
        return None
    return (float(boxes[:, 0].min()), float(boxes[:, 1].max()), float(boxes[:, 2].min()),
            float(boxes[:, 3].max()))


def static_boxes(statics: tuple[tuple[tuple, ...], ...]) -> np.ndarray:
    """World boxes of every static primitive of every static set (finite ones)."""
    boxes = [item_box(it) for items in statics for it in items]
    return _finite(np.array(boxes, dtype=float).reshape(-1, 4))


def auto_box(frames: list[Measured], statics: tuple[tuple[tuple, ...], ...]) -> Box:
    """The automatic camera's world box (see the module's docstring for the rule)."""
    moving, where = element_boxes(frames)
    fixed = static_boxes(statics)
    if not len(moving):
        return _union(fixed) or (-1.0, 1.0, -1.0, 1.0)
    size = np.maximum(moving[:, 1] - moving[:, 0], moving[:, 3] - moving[:, 2])
    size = size[size > 0]
    typical = float(np.median(size)) if len(size) else 0.0
    keep = where == where.min()  # the first frame's elements, always
    centres = [(moving[:, 0] + moving[:, 1]) / 2, (moving[:, 2] + moving[:, 3]) / 2]
    quartiles = [np.quantile(c, (0.25, 0.75)) for c in centres]
    reach = FENCE * max(typical, *(float(q3 - q1) for q1, q3 in quartiles))
    inside = np.ones(len(moving), dtype=bool)
    for c, (q1, q3) in zip(centres, quartiles, strict=True):
        inside &= (c >= q1 - reach) & (c <= q3 + reach)
    x0, x1, y0, y1 = _union(moving[keep | inside])  # type: ignore[misc]
    x0, x1 = _at_least(x0, x1, MIN_SIZE * typical)
    y0, y1 = _at_least(y0, y1, MIN_SIZE * typical)
    if not max(x1 - x0, y1 - y0) > 0:
        # Only points move (pivots of bodies without shapes): show the static shapes, or
        # one unit around them.
        return _union(fixed) or (x0 - 0.5, x1 + 0.5, y0 - 0.5, y1 + 0.5)
    nx, ny = NEAR * (x1 - x0), NEAR * (y1 - y0)
    ex0, ex1, ey0, ey1 = x0 - nx, x1 + nx, y0 - ny, y1 + ny
    bx0, bx1, by0, by1 = x0, x1, y0, y1
    for sx0, sx1, sy0, sy1 in fixed.tolist():
        if sx1 < ex0 or sx0 > ex1 or sy1 < ey0 or sy0 > ey1:
            continue
        # Along an axis where the shape runs past the near zone on both sides, it does not
        # widen the view (a long floor, a tall wall); else the part of it near the bodies does.
        if not (sx0 <= ex0 and sx1 >= ex1):
            bx0, bx1 = min(bx0, max(sx0, ex0)), max(bx1, min(sx1, ex1))
        if not (sy0 <= ey0 and sy1 >= ey1):
            by0, by1 = min(by0, max(sy0, ey0)), max(by1, min(sy1, ey1))
    return bx0, bx1, by0, by1


def all_box(frames: list[Measured], statics: tuple[tuple[tuple, ...], ...]) -> Box:
    """Everything ever captured, static shapes included."""
    boxes = np.concatenate([element_boxes(frames)[0], static_boxes(statics)])
    return _union(boxes) or (-1.0, 1.0, -1.0, 1.0)


def _at_least(a: float, b: float, least: float) -> tuple[float, float]:
    """The interval a..b widened about its middle to at least ``least``."""
    if b - a >= least:
        return a, b
    mid = (a + b) / 2
    return mid - least / 2, mid + least / 2


def fit(box: Box, width: float, height: float, pad: float = PAD) -> Box:
    """``box`` padded by ``pad`` of its span on each side, widened about its middle to the
    aspect ratio ``width`` : ``height``, and kept resolvable (finite, with a span at least
    1e-9 of its coordinates and :data:`SPAN_MIN`)."""
    x0, x1, y0, y1 = box
    if not all(math.isfinite(v) for v in box):
        x0, x1, y0, y1 = -1.0, 1.0, -1.0, 1.0
    cx, cy = x0 / 2 + x1 / 2, y0 / 2 + y1 / 2
    w, h = (x1 / 2 - x0 / 2) * (2 + 4 * pad), (y1 / 2 - y0 / 2) * (2 + 4 * pad)
    floor = max(SPAN_MIN, 1e-9 * max(abs(cx), abs(cy)))
    w, h = min(max(w, floor), 1e300), min(max(h, floor), 1e300)
    if w / h < width / height:
        w = h * width / height
    else:
        h = w * height / width
    out = (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)
    if not (all(math.isfinite(v) for v in out) and out[1] > out[0] and out[3] > out[2]):
        return fit((-1.0, 1.0, -1.0, 1.0), width, height, pad)  # beyond what floats resolve
    return out


@dataclass(frozen=True)
class View:
    """A world box (``box``) on the scene panel: ``s`` px per unit, world (0, 0) at pixel
    (``ox``, ``oy``); ``flip`` is -1 when y is up in the picture, +1 when it is down."""

    box: Box
    s: float
    ox: float
    oy: float
    flip: int

    @classmethod
    def of(cls, box: Box, area: tuple[float, float, float, float], y_up: bool) -> View:
        """The view showing ``box`` (already of the area's aspect ratio) centred in ``area``
        (px: left, top, width, height)."""
        left, top, aw, ah = area
        x0, x1, y0, y1 = box
        s = min(aw / (x1 - x0), ah / (y1 - y0))
        flip = -1 if y_up else 1
        cx, cy = x0 / 2 + x1 / 2, y0 / 2 + y1 / 2
        return cls(box, s, left + aw / 2 - cx * s, top + ah / 2 - flip * cy * s, flip)

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Pixel of world point (x, y)."""
        return self.ox + x * self.s, self.oy + self.flip * y * self.s


def scene_area(width: int, height: int, energy: bool) -> tuple[int, int, int, int]:
    """Where the view is drawn on a ``width`` x ``height`` frame (px: left, top, width,
    height): under the time label, left of the energy panel if there is one."""
    u = unit(width, height)
    scene_w = round(0.56 * width) if energy else width
    top = round(30 * u)
    return round(8 * u), top, scene_w - round(16 * u), height - top - round(8 * u)


# --- the painter ---------------------------------------------------------------------------------


def _clip(v: float) -> float:
    return min(max(v, -CLIP), CLIP) if not math.isnan(v) else -CLIP


class Pen:
    """Draws primitives through ``view`` on ``d``, an image ``S`` times the size whose corner
    is the frame's pixel ``corner`` and which is ``size`` frame pixels large (``u``: the
    frame's length unit); what lies wholly outside it is skipped."""

    def __init__(self, d: ImageDraw.ImageDraw, u: float, S: int, view: View,
                 corner: tuple[float, float], size: tuple[float, float]) -> None:
        self.d, self.u, self.S, self.flip = d, u, S, view.flip
        self.width = max(1, round(1.5 * u * S))
        self.ox, self.oy = (view.ox - corner[0]) * S, (view.oy - corner[1]) * S
        self.sS = view.s * S
        self.lim_x, self.lim_y = size[0] * S, size[1] * S

    def draw(self, items: tuple[tuple, ...] | list[tuple],
             polys: dict[int, list[float]] | None = None,
             index: list[int] | None = None) -> None:
        """Draw ``items``; ``polys``: the corners of polygons in this image's pixels by
        ``index`` (the items' indices in their frame), where known."""
        for j, it in enumerate(items):
            if polys is not None and it[0] == "poly":
                self.poly(it, polys.get(index[j] if index is not None else j))
            else:
                getattr(self, it[0])(it)

    def P(self, x: float, y: float) -> tuple[float, float]:
        """The pixel (on this image) of world point (x, y), clipped."""
        return _clip(self.ox + x * self.sS), _clip(self.oy + y * self.flip * self.sS)

    def outside(self, xs: list[float], ys: list[float], m: float) -> bool:
        return (max(xs) < -m or min(xs) > self.lim_x + m or max(ys) < -m
                or min(ys) > self.lim_y + m)

    @staticmethod
    def colours(ink: int) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
        """Outline and fill of a shape of ``ink`` (-1: static or kinematic, grey)."""
        return SHAPE_COLOURS[ink]

    def circle(self, it: tuple) -> None:
        _, ink, _, x, y, r, angle = it
        (X, Y), R = self.P(x, y), min(max(r * self.sS, 1.5 * self.u * self.S), CLIP)
        if math.isnan(R) or self.outside([X], [Y], R):
            return
        out, fill = self.colours(ink)
        self.d.ellipse([X - R, Y - R, X + R, Y + R], fill=fill, outline=out, width=self.width)
        if math.isfinite(angle):
            self.d.line([(X, Y), (X + R * math.cos(angle), Y + self.flip * R * math.sin(angle))],
                        fill=out, width=self.width)

    def seg(self, it: tuple) -> None:
        _, ink, _, ax, ay, bx, by, r = it
        ends = [self.P(ax, ay), self.P(bx, by)]
        line = self.width
        w = max(line, round(min(2 * r * self.sS, CLIP))) if not math.isnan(r) else line
        if self.outside([e[0] for e in ends], [e[1] for e in ends], w):
            return
        out, fill = self.colours(ink)
        self.d.line(ends, fill=out, width=w)
        if w > 2 * line:
            # A fat segment: its outline, then its fill inside, with round ends.
            for width, ink_rgb in ((w, out), (w - 2 * line, fill)):
                for X, Y in ends:
                    self.d.ellipse([X - width / 2, Y - width / 2, X + width / 2,
                                    Y + width / 2], fill=ink_rgb)
                if ink_rgb == fill:
                    self.d.line(ends, fill=fill, width=width)

    def poly(self, it: tuple, px: list[float] | None = None) -> None:
        """A polygon; ``px``: its corners in this image's pixels (flat), if known."""
        _, ink, _, flat, _ = it
        if len(flat) < 4:
            return
        if px is None:
            ox, oy, sS, fS = self.ox, self.oy, self.sS, self.flip * self.sS
            px = [ox + v * sS if i % 2 == 0 else oy + v * fS for i, v in enumerate(flat)]
        xs, ys = px[0::2], px[1::2]
        if self.outside(xs, ys, self.width):
            return
        if not (-CLIP < min(xs) and max(xs) < CLIP and -CLIP < min(ys) and max(ys) < CLIP):
            px = [_clip(v) for v in px]  # far off, or not a number
        out, fill = SHAPE_COLOURS[ink]
        # Filled, then outlined with a closed line: Pillow's wide polygon outline draws
        # through a mask image per polygon, many times slower.
        self.d.polygon(px, fill=fill)
        self.d.line([*px, px[0], px[1]], fill=out, width=self.width, joint="curve")

    def spring(self, it: tuple) -> None:
        pa, pb = self.P(it[3], it[4]), self.P(it[5], it[6])
        if not self.outside([pa[0], pb[0]], [pa[1], pb[1]], 6 * self.u * self.S):
            # Coils at most a tenth of the spring's drawn length wide: a web of short springs
            # stays legible.
            amp = min(SPRING_WIDTH * self.u * self.S, 0.1 * math.dist(pa, pb))
            self.d.line(zigzag(pa, pb, amp, COILS), fill=SPRING, width=self.width,
                        joint="curve")

    def line(self, it: tuple) -> None:
        pa, pb = self.P(it[3], it[4]), self.P(it[5], it[6])
        if not self.outside([pa[0], pb[0]], [pa[1], pb[1]], self.width):
            self.d.line([pa, pb], fill=SPRING, width=self.width)

    def dot(self, it: tuple) -> None:
        X, Y = self.P(it[3], it[4])
        R = 3 * self.u * self.S
        if not self.outside([X], [Y], R):
            self.d.ellipse([X - R, Y - R, X + R, Y + R], fill=INK)

    def rotary(self, it: tuple) -> None:
        """A coil of 2.5 turns about the pivot, turned by the spring's twist."""
        _, _, _, x, y, twist = it
        X, Y = self.P(x, y)
        if self.outside([X], [Y], 12 * self.u * self.S) or not math.isfinite(twist):
            return
        pts = []
        for i in range(61):
            f = i / 60
            a = f * 2.5 * 2 * math.pi + twist
            rr = (4 + 8 * f) * self.u * self.S
            pts.append((X + rr * math.cos(a), Y + self.flip * rr * math.sin(a)))
        self.d.line(pts, fill=SPRING, width=self.width, joint="curve")


#: Redrawing: an element is drawn again once a coordinate crosses a grid of this many
#: pixels (smaller shifts change no pixel's blend level); past this share of the moving
#: elements changed, or this many separate boxes, the whole moving layer is drawn again.
QUANTUM, REDRAW_SHARE, MAX_RECTS = 0.1, 0.4, 24
#: Room (u) around each kind of primitive's box for what is drawn beyond it: outlines, the
#: smallest circle, a spring's coils, a rotary spring's coil, a pivot's dot.
ROOM = {"circle": 2.5, "seg": 2.0, "poly": 2.0, "spring": 6.0, "line": 2.0, "rotary": 13.0,
        "dot": 4.0}


class Layer:
    """One frame's moving primitives seen through a view: each one's pixel box (with room
    for what is drawn around it), and per element (a moving body's shapes, or one
    constraint) its signature: its box and turning point in pixels on a grid of
    :data:`QUANTUM` px (a rigid shape's pose to that grid). From the previous frame's layer,
    :meth:`damage` finds the boxes to draw again."""

    def __init__(self, items: tuple[tuple, ...], measured: Measured, view: View, u: float,
                 panel: tuple[int, int]) -> None:
        self.items = items
        self.panel = panel
        s, fs = view.s, view.flip * view.s
        room = np.array([ROOM[it[0]] * u for it in items]).reshape(-1)
        b = measured.box
        xa, xb = view.ox + b[:, 0] * s, view.ox + b[:, 1] * s
        ya, yb = view.oy + b[:, 2] * fs, view.oy + b[:, 3] * fs
        px = np.stack([xa - room, np.minimum(ya, yb) - room, xb + room,
                       np.maximum(ya, yb) + room], axis=1)
        self.boxes = px.tolist()
        inv = s / QUANTUM
        grid = np.concatenate([b * inv, measured.turn * inv], axis=1)
        # A rotary spring turns its coil, 12 u px out, by its twist.
        grid[measured.rotary, 4] = measured.turn[measured.rotary, 0] * 12 * u / QUANTUM
        with np.errstate(invalid="ignore"):
            grid = np.floor(grid)  # a value that is not a number never equals itself
        self.measured, self.view, self.corner = measured, view, None
        self.keys = measured.key.tolist()
        rows = map(tuple, grid.tolist())
        if len(set(self.keys)) == len(self.keys):  # one primitive per element
            self.sigs = dict(zip(self.keys, rows, strict=True))
        else:
            sigs: dict[int, list[tuple]] = {}
            for key, row in zip(self.keys, rows, strict=True):
                sigs.setdefault(key, []).append(row)
            self.sigs = {key: tuple(v) for key, v in sigs.items()}
        finite = px[np.isfinite(px).all(axis=1)]
        self.box = self._clipped((float(finite[:, 0].min()), float(finite[:, 1].min()),
                                  float(finite[:, 2].max()), float(finite[:, 3].max()))
                                 ) if len(finite) else None

    def _clipped(self, box: tuple[float, float, float, float]
                 ) -> tuple[float, float, float, float] | None:
        w, h = self.panel
        out = (max(box[0], 0), max(box[1], 0), min(box[2], w - 1), min(box[3], h))
        return out if out[2] > out[0] and out[3] > out[1] else None

    @functools.cached_property
    def element_boxes(self) -> dict[Any, tuple[float, float, float, float]]:
        """The pixel box of each element."""
        out: dict[Any, tuple[float, float, float, float]] = {}
        for key, box in zip(self.keys, self.boxes, strict=True):
            have = out.get(key)
            out[key] = box if have is None else _union_px([have, box])
        return out

    def damage(self, before: Layer) -> list[tuple[float, float, float, float]] | None:
        """The boxes (px) to draw again over the previous frame's picture: where an element
        changed, appeared or went; None when the whole layer must be drawn again."""
        changed = [k for k in self.sigs.keys() | before.sigs.keys()
                   if self.sigs.get(k) != before.sigs.get(k)]
        if len(changed) > REDRAW_SHARE * max(len(self.sigs), 1):
            return None
        now, then = self.element_boxes, before.element_boxes
        rects = [b for k in changed for b in (now.get(k), then.get(k)) if b is not None]
        if not all(math.isfinite(v) for b in rects for v in b):
            return None
        merged = _merge(rects)
        if len(merged) > MAX_RECTS:
            return None
        return [c for c in (self._clipped(r) for r in merged) if c is not None]

    def within(self, rect: tuple[float, float, float, float]) -> list[int]:
        """The indices of the primitives whose boxes meet ``rect``, in drawing order."""
        x0, y0, x1, y1 = rect
        return [j for j, b in enumerate(self.boxes)
                if not (b[2] < x0 or b[0] > x1 or b[3] < y0 or b[1] > y1)]

    def draw(self, pen: Pen, rect: tuple[float, float, float, float]) -> None:
        """Draw the primitives that meet ``rect`` with ``pen``: the polygons' corners placed
        in the pen's pixels all at once."""
        index = self.within(rect)
        wanted = set(index)
        polys: dict[int, list[float]] = {}
        for count, group in self.measured.poly_groups.items():
            idx = [j for j in group if j in wanted]
            if not count or not idx:
                continue
            flat = np.array([self.items[j][3] for j in idx], dtype=float)
            flat[:, 0::2] = pen.ox + flat[:, 0::2] * pen.sS
            flat[:, 1::2] = pen.oy + flat[:, 1::2] * (pen.flip * pen.sS)
            polys.update(zip(idx, flat.tolist(), strict=True))
        pen.draw([self.items[j] for j in index], polys, index)


def _union_px(boxes: list[tuple[float, float, float, float]]
              ) -> tuple[float, float, float, float]:
    return (min(b[0] for b in boxes), min(b[1] for b in boxes), max(b[2] for b in boxes),
            max(b[3] for b in boxes))


def _merge(rects: list[tuple[float, float, float, float]]
           ) -> list[tuple[float, float, float, float]]:
    """``rects`` (px: left, top, right, bottom) with every overlapping pair joined."""
    out: list[tuple[float, float, float, float]] = []
    for r in rects:
        while True:
            hit = next((o for o in out if not (o[2] < r[0] or o[0] > r[2] or o[3] < r[1]
                                                or o[1] > r[3])), None)
            if hit is None:
                break
            out.remove(hit)
            r = _union_px([hit, r])
        out.append(r)
    return out


class Painter(Backdrop):
    """Draws a :class:`Recording`'s frames in the fixed palette (see the module docstring)."""

    def __init__(self, rec: Recording) -> None:
        self.rec = rec
        self.W, self.H = rec.size
        self.n = len(rec.frames)
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
        self.measured = [Measured.of(items) for items in rec.frames]
        self._layout()
        if self.energy:
            self._energy_scale()
        self.base = self._base()
        self._views()
        self._bg_key: tuple[int, int] | None = None
        self._layer: Layer | None = None
        self._scene: Image.Image | None = None
        self._touched: list[tuple[float, float, float, float]] | None = None
        self.changed: tuple[float, float, float, float] | None = None

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
            box = fit(all_box(self.measured, rec.statics), aw, ah)
        else:
            box = fit(auto_box(self.measured, rec.statics), aw, ah)
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
        self.bar_left = bx0 + round(70 * self.u)
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
        Pen(ImageDraw.Draw(scene), self.u, S, view, (0, 0), (self.scene_w, self.H)).draw(
            self.rec.statics[version])
        img.paste(scene, (0, 0))
        if self.rec.title:
            ImageDraw.Draw(img).text(((self.scene_w - 8 * u) * S, 6 * u * S), self.rec.title,
                                     font=font(round(12 * u) * S, True), fill=INK, anchor="rt")
        self.bg = to_palette(img.reduce(S))
        self.bg_rgb = self.bg.convert("RGB")
        self.bg_ss = self.bg_rgb.resize((self.W * S, self.H * S), Image.Resampling.NEAREST)
        self._bg_key = key
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
        """Frame ``k`` as a palette image."""
        fresh = self.background(k)
        img = self.bg.copy()
        view = self.views[k]
        layer = Layer(self.rec.frames[k], self.measured[k], view, self.u,
                      (self.scene_w, self.H))
        rects = None if fresh or self._layer is None else layer.damage(self._layer)
        if rects is None:
            rects = [layer.box] if layer.box is not None else []
        else:
            img.paste(self._scene, (0, 0))
        touched = [*rects, *self._panel_boxes(k)]
        self.changed = None if fresh or self._touched is None else _union_px(
            touched + self._touched)
        self._touched = touched
        for rect in rects:
            crop, corner, done = self.patch(img, rect, SS)
            layer.draw(Pen(ImageDraw.Draw(crop), self.u, SS, view, corner,
                           (crop.width / SS, crop.height / SS)), rect)
            done()
        self._layer, self._scene = layer, img.crop((0, 0, self.scene_w, self.H))
        u = self.u
        crop, (cx, cy), done = self.patch(img, (4 * u, 2 * u, 150 * u, 24 * u), 1)
        label = f"t = {self.t[k]:.{self.t_decimals}f} {self.rec.time_unit}"
        self.st_time.draw(crop, (6 * u - cx, 6 * u - cy), label, INK, "lt")
        done()
        if self.energy:
            self._bars(img, k)
            if self.strip:
                _, sy0, _, sy1 = self.strip_box
                x = round(float(self.strip_x(self.t[k])))
                ImageDraw.Draw(img).line([(x, sy0 + 1), (x, sy1 - 1)], fill=self.idx["ink"],
                                         width=max(1, round(1.2 * u)))
        return img

    def _panel_boxes(self, k: int) -> list[tuple[float, float, float, float]]:
        """The boxes (px) frame ``k`` draws outside the moving layer: the time label, and
        the bars, their values and the strip's cursor."""
        u = self.u
        boxes = [(4 * u, 2 * u, 150 * u, 24 * u)]
        if self.energy:
            boxes.append((self.bars_box[0], self.rows[0][1] - 3, self.W,
                          self.rows[-1][2] + 3))
            if self.strip:
                x = float(self.strip_x(self.t[k]))
                boxes.append((x - 2 * u - 1, self.strip_box[1], x + 2 * u + 1,
                              self.strip_box[3]))
        return boxes

    def region(self, k: int) -> tuple[int, int, int, int] | None:
        """Where frame ``k`` (just drawn) can differ from frame k - 1 (px: left, top, right,
        bottom), or None: anywhere."""
        if self.changed is None:
            return None
        x0, y0, x1, y1 = self.changed
        return math.floor(x0) - 1, math.floor(y0) - 1, math.ceil(x1) + 2, math.ceil(y1) + 2

    def _bars(self, img: Image.Image, k: int) -> None:
        d = ImageDraw.Draw(img)
        values = {n: float(self.e[n][k]) for n in self.names}
        for name, top, bot in self.rows:
            v = values[name]
            if not math.isfinite(v):
                continue
            a, b = sorted((round(self.bar_px(0.0)), round(self.bar_px(v))))
            if name == "E" and self.rec.heat and values["heat"] > 0:
                # E + heat: what E was, were no energy lost to the contacts.
                h = round(self.bar_px(v + values["heat"]))
                if h > b:
                    d.rectangle([b, top, h - 1, bot - 1], fill=self.idx["heat"])
            if b > a:
                d.rectangle([a, top, b - 1, bot - 1], fill=self.idx[name])
        bx1 = self.bars_box[2]
        box = (self.bar_right + 2, self.rows[0][1] - 3, bx1, self.rows[-1][2] + 3)
        draw_values(self.patch(img, box, 1), self.rows,
                    lambda name: self.scale.text(values[name]), bx1, self.st_text)


# --- writing -----------------------------------------------------------------------------------


class _Stopped(BaseException):
    """A stop signal arrived while the file was being written."""


@contextlib.contextmanager
def _signals_end_cleanly() -> Iterator[None]:
    """While the block runs (in the main thread), a SIGTERM or SIGHUP that would end the
    script outright raises instead, so the ``.part`` file is removed; after the block the
    signal is sent again, with the script's own handling back in place."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []

    def stop(signum: int, frame: object) -> None:
        got.append(signum)
        raise _Stopped(signum)

    before = {}
    for name in STOP_SIGNALS:
        number = getattr(signal, name, None)
        if number is not None and signal.getsignal(number) is signal.SIG_DFL:
            before[number] = signal.SIG_DFL
            signal.signal(number, stop)
    try:
        yield
    except _Stopped:
        pass
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)
    if got:
        os.kill(os.getpid(), got[0])


def write(path: Path, rec: Recording, timing: dict[str, float] | None = None) -> Painter:
    """Paint ``rec`` and write it to ``path`` (.gif, or .mp4 through imageio's ffmpeg plugin),
    atomically; ``timing`` receives the seconds spent. Returns the painter (its ``view``)."""
    t0 = time.perf_counter()
    painter = Painter(rec)
    stats = {"setup": time.perf_counter() - t0}
    with _signals_end_cleanly():
        if path.suffix.lower() == ".mp4":
            _write_mp4(path, painter, rec.fps)
        else:
            with atomic_output(path) as tmp, open(tmp, "wb") as fh:
                stats["draw"], stats["encode"] = write_frames(
                    fh, (painter.W, painter.H), painter.frame, delays_cs(painter.n, rec.fps),
                    region=painter.region)
    stats.update(frames=painter.n, total=time.perf_counter() - t0)
    if timing is not None:
        timing.update(stats)
    return painter


def mp4_problem() -> str | None:
    """Why an MP4 cannot be written here (the optional extra is missing), or None."""
    import importlib.util

    for module in ("imageio", "imageio_ffmpeg"):
        if importlib.util.find_spec(module) is None:
            return "MP4 needs the optional extra: pip install 'dumbbell[mp4]' (imageio-ffmpeg)"
    return None


def _write_mp4(path: Path, painter: Painter, fps: int) -> None:
    problem = mp4_problem()
    if problem is not None:
        raise DumbbellError(f"{path}: {problem}")
    import imageio.v2 as imageio

    lut = np.frombuffer(palette()[0], dtype=np.uint8).reshape(256, 3)
    with atomic_output(path) as tmp:
        writer = imageio.get_writer(tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                    pixelformat="yuv420p", macro_block_size=2,
                                    ffmpeg_log_level="error")
        try:
            # yuv420p needs even sizes: an odd edge gets one more row or column of itself.
            pad = ((0, painter.H % 2), (0, painter.W % 2), (0, 0))
            for k in range(painter.n):
                writer.append_data(np.pad(lut[np.asarray(painter.frame(k))], pad, mode="edge"))
        finally:
            writer.close()
