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
element's size), and every element of the first frame. The box of the kept elements, at
least :data:`MIN_SIZE` times the median element's size, is where the bodies move: a body
that flies away (or strays for a small share of the time) leaves the picture instead of
shrinking everything else. Static shapes within :data:`NEAR` of that box (a share of its
size along each axis) are shown too, a floor under the bodies say (one that runs past the
near zone on both sides along an axis, a long floor or a tall wall, does not widen the view
along it), as long as that leaves every moving body at least :data:`BODY_PX` across to
scale; else the view widens only that far (not at all if the bodies' box alone is too
large), placed to hold as much of them as it can: static shapes never shrink a body below
:data:`BODY_PX`, and those farther away never count. The box is padded by :data:`PAD` and
fitted to the scene panel. ``"all"`` shows everything ever captured, static shapes included;
a fixed box is the user's; ``"follow"`` keeps one body at the centre of a view of fixed size.

**Sizes.** Whatever the view, every moving body is drawn at least :data:`BODY_PX` across
whichever way it turns (:meth:`Shapes.at_least`): a smaller one is drawn larger than to
scale, and the painter says which (``Painter.grown``, named in the recorder's note).
"""

from __future__ import annotations

import contextlib
import functools
import itertools
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
from .bars import SWATCH, SWATCH_GAP, EnergyScale, bar_rows, draw_legend, draw_values
from .gif import write_frames
from .glyphs import TEXT_PX, Stamps, fmt_tick, font, nice_step
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
from .strip import GRID
from .timing import delays_cs
from .world import LEAD

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
#: The bars start at least this far right of the panel's left edge (px at 640x360) ...
LABEL_ROOM = 70
#: ... and this far right of the end of the longest row name.
NAME_GAP = 4
#: The camera: a moving body's position counts unless it lies more than this many
#: interquartile ranges beyond the middle half of all positions (Tukey's far-out fences) ...
FENCE = 3.0
#: ... static shapes this near the bodies' box (a share of its size along each axis) are
#: shown where the view has room for them, never by widening it ...
NEAR = 0.25
#: ... the view is at least this many times the median body's size ...
MIN_SIZE = 4.0
#: ... with this margin (a share of its span) on each side.
PAD = 0.05
#: Every moving body is drawn at least this many px across (its larger side, whichever
#: way it turns; times the frame's size unit when larger than 640x360), larger than to scale
#: if need be (the recorder's note names those), ...
BODY_PX = 4.0
#: ... measured on its box turned this many times in a quarter turn.
TURNS = 16
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


@dataclass(frozen=True, eq=False)
class Group:
    """Shapes of one kind of a :class:`Shapes` (polygons: of one number of corners): their
    places in its order (``at``), their points in their bodies' coordinates (``local``,
    m x p x 2: a circle's centre, a segment's two ends, a polygon's corners) and radii
    (``r``)."""

    kind: str
    at: np.ndarray
    local: np.ndarray
    r: np.ndarray
    #: Each shape's body (its row in a frame's poses), and whether all the group's points
    #: are their bodies' origins (circles centred on their bodies: placed without turning).
    rows: np.ndarray
    origin: bool


@dataclass(frozen=True, eq=False)
class Shapes:
    """A set of shapes in their bodies' coordinates, in drawing order: each one's body (its
    row in a frame's poses: x, y, angle), ink (-1 grey) and moving body's number (-1 for a
    shape on a static body), grouped by kind. A frame is a pose per body: the shapes are
    placed by numpy, all of a group at once, never one by one in Python."""

    body: np.ndarray
    ink: np.ndarray
    number: np.ndarray
    groups: tuple[Group, ...]

    @classmethod
    def of(cls, tags: list[tuple[str, int, int, int]], local: list[list[tuple[float, float]]],
           r: list[float]) -> Shapes:
        """From per-shape lists: ``tags`` (kind ("circle", "seg", "poly"), body row, ink,
        number), points in body coordinates and radius."""
        kinds = [t[0] for t in tags]
        body, ink, number = ([t[i] for t in tags] for i in (1, 2, 3))
        by: dict[tuple[str, int], list[int]] = {}
        for j, (kind, pts) in enumerate(zip(kinds, local, strict=True)):
            by.setdefault((kind, len(pts)), []).append(j)
        rows = np.array(body, dtype=np.intp)
        groups = []
        for (kind, p), idx in by.items():
            pts = np.array([local[j] for j in idx], dtype=float).reshape(len(idx), p, 2)
            at = np.array(idx, dtype=np.intp)
            groups.append(Group(kind, at, pts, np.array([r[j] for j in idx], dtype=float),
                                rows[at], bool(p) and not pts.any()))
        return cls(rows, np.array(ink, dtype=int), np.array(number, dtype=int), tuple(groups))

    @property
    def n(self) -> int:
        return len(self.body)

    def place(self, pose: np.ndarray, g: Group) -> tuple[np.ndarray, np.ndarray]:
        """Group ``g``'s points in the world (..., m, p, 2) and its bodies' angles (..., m), at
        ``pose`` (..., bodies, 3: x, y, angle; leading axes: frames)."""
        p = pose[..., g.rows, :]
        angle = p[..., 2]
        if g.origin:  # x + cos 0 - sin 0 is x
            return p[..., None, :2], angle
        c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
        lx, ly = g.local[..., 0], g.local[..., 1]
        x = p[..., 0, None] + c * lx - s * ly
        y = p[..., 1, None] + s * lx + c * ly
        return np.stack([x, y], axis=-1), angle

    def boxes(self, pose: np.ndarray) -> np.ndarray:
        """World box (x0, x1, y0, y1) of each shape at ``pose`` (..., bodies, 3): (..., n, 4);
        nan where a shape has none."""
        out = np.full((*pose.shape[:-2], self.n, 4), math.nan)
        for g in self.groups:
            if not g.local.shape[1]:
                continue
            pts, _ = self.place(pose, g)
            r = g.r
            out[..., g.at, 0] = pts[..., 0].min(axis=-1) - r
            out[..., g.at, 1] = pts[..., 0].max(axis=-1) + r
            out[..., g.at, 2] = pts[..., 1].min(axis=-1) - r
            out[..., g.at, 3] = pts[..., 1].max(axis=-1) + r
        return out

    @functools.cached_property
    def least(self) -> tuple[np.ndarray, np.ndarray]:
        """Per body row: how small the body can look, the least over its turns of the larger
        side of its shapes' box (world units; nan for a row without shapes), and the middle
        of that box in the body's coordinates (rows x 2)."""
        rows = int(self.body.max()) + 1 if self.n else 0
        a = np.arange(TURNS) * (math.pi / 2 / TURNS)  # the box repeats every quarter turn
        c, s = np.cos(a), np.sin(a)
        # Each shape's extent along x and y turned by each angle (n x 2 x turns) ...
        lo = np.full((self.n, 2, TURNS), math.inf)
        hi = np.full((self.n, 2, TURNS), -math.inf)
        for g in self.groups:
            if not g.local.shape[1]:
                continue
            x, y = g.local[..., 0, None], g.local[..., 1, None]  # m x p x 1
            r = g.r[:, None, None]
            along = np.stack([x * c + y * s, y * c - x * s], axis=2)  # m x p x 2 x turns
            lo[g.at], hi[g.at] = along.min(axis=1) - r, along.max(axis=1) + r
        # ... then each body's (its shapes together).
        order = np.argsort(self.body, kind="stable")
        starts = np.flatnonzero(np.r_[True, np.diff(self.body[order]) != 0]) if self.n else order
        body_lo, body_hi = np.full((rows, 2, TURNS), math.inf), np.full((rows, 2, TURNS), -math.inf)
        if self.n:
            at = self.body[order][starts]
            body_lo[at] = np.minimum.reduceat(lo[order], starts, axis=0)
            body_hi[at] = np.maximum.reduceat(hi[order], starts, axis=0)
        with np.errstate(invalid="ignore"):
            # (Between two of the turns measured the side can be at most this much smaller.)
            side = (body_hi - body_lo).max(axis=1).min(axis=1) * math.cos(math.pi / 4 / TURNS)
            middle = (body_lo[:, :, 0] + body_hi[:, :, 0]) / 2
        side[~(side >= 0)] = math.nan
        return side, middle

    def at_least(self, s: float, px: float) -> tuple[Shapes, np.ndarray]:
        """The shapes drawn at ``s`` px per unit with every body at least ``px`` px across
        whichever way it turns (its larger side): a body that would be drawn smaller is
        drawn larger than to scale, its shapes grown about the middle of their box. Returns
        the shapes to draw (these, when none is grown) and the numbers of the moving bodies
        grown."""
        side, middle = self.least
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            # (A body exactly px across, as a view made for it draws it, is not grown.)
            grow = np.where(side * s < px * (1 - 1e-9), px / (side * s), 1.0)
        grow[~np.isfinite(grow) | (side <= 0)] = 1.0  # nothing to grow (no size, no shapes)
        if not (grow > 1).any():
            return self, np.zeros(0, dtype=int)
        groups = []
        for g in self.groups:
            f = grow[g.rows]
            if not (f > 1).any():
                groups.append(g)
                continue
            m = middle[g.rows][:, None, :]
            local = m + f[:, None, None] * (g.local - m)
            groups.append(Group(g.kind, g.at, local, g.r * f, g.rows,
                                bool(local.shape[1]) and not local.any()))
        grown = np.unique(self.number[(grow[self.body] > 1) & (self.number >= 0)])
        return Shapes(self.body, self.ink, self.number, tuple(groups)), grown

    def items(self, pose: np.ndarray) -> list[tuple]:
        """The shapes at ``pose`` as primitives (see the module docstring), in order."""
        out: list[tuple | None] = [None] * self.n
        ink, number = self.ink.tolist(), self.number.tolist()
        for g in self.groups:
            pts, angle = self.place(pose, g)
            for j, flat, a, r in zip(g.at.tolist(), pts.reshape(len(g.at), -1).tolist(),
                                     angle.tolist(), g.r.tolist(), strict=True):
                if g.kind == "circle":
                    out[j] = ("circle", ink[j], number[j], flat[0], flat[1], r, a)
                elif g.kind == "seg":
                    out[j] = ("seg", ink[j], number[j], *flat, r)
                else:
                    out[j] = ("poly", ink[j], number[j], tuple(flat), r)
        return out  # type: ignore[return-value]


@dataclass(frozen=True)
class Recording:
    """Everything the painter needs, frozen: per frame its moving shapes (``shape_of`` indexes
    ``shapes``, the sets of moving shapes) with its bodies' poses (``poses``, one row per body
    of the set: x, y, angle), its other moving primitives (``extras``: the constraints), which
    static set it shows (``static_of`` indexes ``statics``) and its time; the frame ``size``
    (px) and ``fps``; ``y_up``; the camera (``camera`` "auto", "all", "box" with ``box``, or
    "follow" with a centre per frame in ``follow`` and the view's larger side ``span``); the
    energy rows (name -> values shown, in ``energy``; None without bars) with their labels
    and ``energy_title``; ``heat`` (the last row is heat, and E's row shows E + heat pale);
    ``strip``; the ``title``; the time unit."""

    shapes: tuple[Shapes, ...]
    shape_of: tuple[int, ...]
    poses: tuple[np.ndarray, ...]
    extras: tuple[tuple[tuple, ...], ...]
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

    @property
    def n(self) -> int:
        """Number of frames."""
        return len(self.t)

    def items(self, k: int) -> list[tuple]:
        """Frame ``k``'s moving primitives (its shapes, then its extras)."""
        return [*self.shapes[self.shape_of[k]].items(self.poses[k]), *self.extras[k]]


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
#: Frames whose shapes are placed together when the camera measures them (bounds memory).
CHUNK = 64


def element_boxes(rec: Recording) -> tuple[np.ndarray, np.ndarray]:
    """World boxes (n x 4: x0, x1, y0, y1) of the moving elements of every frame, finite
    ones only, and the frame of each: each moving body's shapes (one box per body and frame),
    each shape on no moving body, and each extra (constraint)."""
    parts: list[np.ndarray] = []
    where: list[np.ndarray] = []
    for i, shapes in enumerate(rec.shapes):
        frames = [k for k, s in enumerate(rec.shape_of) if s == i]
        if not shapes.n or not frames:
            continue
        # The elements: one per moving body number, one per shape on none.
        key = np.where(shapes.number >= 0, shapes.number, -1 - np.arange(shapes.n))
        order = np.argsort(key, kind="stable")
        starts = np.flatnonzero(np.r_[True, np.diff(key[order]) != 0])
        for c in range(0, len(frames), CHUNK):
            chunk = frames[c:c + CHUNK]
            box = shapes.boxes(np.stack([rec.poses[k] for k in chunk]))[:, order]
            with np.errstate(invalid="ignore"):  # a body at nan is no element
                out = np.stack([np.minimum.reduceat(box[..., 0], starts, axis=1),
                                np.maximum.reduceat(box[..., 1], starts, axis=1),
                                np.minimum.reduceat(box[..., 2], starts, axis=1),
                                np.maximum.reduceat(box[..., 3], starts, axis=1)], axis=-1)
            parts.append(out.reshape(-1, 4))
            where.append(np.repeat(np.array(chunk, dtype=int), len(starts)))
    for k, extras in enumerate(rec.extras):
        if extras:
            parts.append(np.array([item_box(it) for it in extras], dtype=float).reshape(-1, 4))
            where.append(np.full(len(extras), k, dtype=int))
    boxes = np.concatenate([*parts, np.zeros((0, 4))])
    frame = np.concatenate([*where, np.zeros(0, dtype=int)])
    ok = np.isfinite(boxes).all(axis=1)
    return boxes[ok], frame[ok]


def _union(boxes: np.ndarray) -> Box | None:
    if not len(boxes):
        return None
    return (float(boxes[:, 0].min()), float(boxes[:, 1].max()), float(boxes[:, 2].min()),
            float(boxes[:, 3].max()))


def static_boxes(statics: tuple[tuple[tuple, ...], ...]) -> np.ndarray:
    """World boxes of every static primitive of every static set (finite ones)."""
    boxes = [item_box(it) for items in statics for it in items]
    return _finite(np.array(boxes, dtype=float).reshape(-1, 4))


def auto_boxes(rec: Recording) -> tuple[Box, Box]:
    """The automatic camera's boxes (see the module's docstring for the rule): where the
    bodies move (dynamic and kinematic, with their constraints), which the view holds at
    its scale; and that box with the static shapes near it, which the view holds where it
    has room."""
    moving, where = element_boxes(rec)
    fixed = static_boxes(rec.statics)
    if not len(moving):
        box = _union(fixed) or (-1.0, 1.0, -1.0, 1.0)
        return box, box
    size = np.maximum(moving[:, 1] - moving[:, 0], moving[:, 3] - moving[:, 2])
    size = size[size > 0]
    # The median (as np.median, which would import numpy.ma).
    size = np.sort(size)
    typical = float(size[(len(size) - 1) // 2] + size[len(size) // 2]) / 2 if len(size) else 0.0
    keep = where == where.min()  # the first frame's elements, always
    centres = [(moving[:, 0] + moving[:, 1]) / 2, (moving[:, 2] + moving[:, 3]) / 2]
    quartiles = [_quartiles(c) for c in centres]
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
        box = _union(fixed) or (x0 - 0.5, x1 + 0.5, y0 - 0.5, y1 + 0.5)
        return box, box
    nx, ny = NEAR * (x1 - x0), NEAR * (y1 - y0)
    ex0, ex1, ey0, ey1 = x0 - nx, x1 + nx, y0 - ny, y1 + ny
    bx0, bx1, by0, by1 = x0, x1, y0, y1
    for sx0, sx1, sy0, sy1 in fixed.tolist():
        if sx1 < ex0 or sx0 > ex1 or sy1 < ey0 or sy0 > ey1:
            continue
        # Along an axis where the shape runs past the near zone on both sides, it does not
        # move the view (a long floor, a tall wall); else the part of it near the bodies does.
        if not (sx0 <= ex0 and sx1 >= ex1):
            bx0, bx1 = min(bx0, max(sx0, ex0)), max(bx1, min(sx1, ex1))
        if not (sy0 <= ey0 and sy1 >= ey1):
            by0, by1 = min(by0, max(sy0, ey0)), max(by1, min(sy1, ey1))
    return (x0, x1, y0, y1), (bx0, bx1, by0, by1)


def auto_view(rec: Recording, width: float, height: float, body_px: float = 0.0) -> Box:
    """The automatic camera's view, of the aspect ratio ``width`` : ``height`` (px): the box
    where the bodies move with the static shapes near them (:func:`auto_boxes`), fitted
    (:func:`fit`), as long as that leaves every moving body at least ``body_px`` across; else
    the view is only as large as keeps them so (the box where the bodies move, if even that
    is too large), placed to hold as much of the static shapes near them as it can: static
    shapes never make a body smaller than ``body_px``."""
    core, near = auto_boxes(rec)
    wide = fit(near, width, height)
    if near == core:
        return wide
    tight = fit(core, width, height)
    least = [float(np.nanmin(sh.least[0])) for sh in rec.shapes
             if sh.n and np.isfinite(sh.least[0]).any()]
    # The largest view (world units across) that draws the smallest body body_px across.
    most = min(least, default=math.inf) * width / body_px if body_px > 0 else math.inf
    if wide[1] - wide[0] <= most:
        return wide
    span = max(tight[1] - tight[0], most)
    spans = (span, span * height / width)
    out: list[float] = []
    for size, (c0, c1), (n0, n1) in zip(spans, (core[:2], core[2:]), (near[:2], near[2:]),
                                        strict=True):
        # The view holds the bodies' box, padded as fit pads it, and is centred on the
        # shapes near them as far as that allows.
        half, mid = (c1 / 2 - c0 / 2) * (1 + 2 * PAD), c0 / 2 + c1 / 2
        lo = min(max(n0 / 2 + n1 / 2 - size / 2, mid + half - size), mid - half)
        out += [lo, lo + size]
    box = (out[0], out[1], out[2], out[3])
    return box if all(math.isfinite(v) for v in box) else tight


def _quartiles(values: np.ndarray) -> tuple[float, float]:
    """The first and third quartiles of ``values``, interpolated linearly between the sorted
    values (as np.quantile does by default; it would import numpy.ma)."""
    v = np.sort(values)
    out = []
    for q in (0.25, 0.75):
        h = (len(v) - 1) * q
        lo = math.floor(h)
        hi = min(lo + 1, len(v) - 1)
        out.append(float(v[lo] + (h - lo) * (v[hi] - v[lo])))
    return out[0], out[1]


def all_box(rec: Recording) -> Box:
    """Everything ever captured, static shapes included."""
    boxes = np.concatenate([element_boxes(rec)[0], static_boxes(rec.statics)])
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


def line_width(u: float) -> int:
    """Width of outlines and lines (px at :data:`SS` times the size)."""
    return max(1, round(1.5 * u * SS))


def _snap(v: np.ndarray) -> np.ndarray:
    """Pixel coordinates (floats) as whole pixels, clipped to :data:`CLIP` (nan: -CLIP)."""
    return np.rint(np.fmin(np.fmax(v, -CLIP), CLIP)).astype(np.int64)


def _to_pixels(pts: np.ndarray, view: View) -> np.ndarray:
    """World points (..., 2) as whole pixels at :data:`SS` times the size (..., 2)."""
    S = SS
    return _snap(pts * (view.s * S, view.flip * view.s * S) + (view.ox * S, view.oy * S))


def shape_pixels(g: Group, pts: np.ndarray, angle: np.ndarray, view: View, u: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Group ``g``'s shapes (one kind, radii ``g.r``) at world points ``pts`` (m x p x 2) and
    (circles) their bodies' angles, seen through ``view``: their whole-pixel coordinates at :data:`SS` times
    the size (m x w integers: a circle's centre, the end of its radius line (the centre
    without one) and radius; a segment's ends and width; a polygon's corners: points first,
    x then y, then at most one length), their boxes (m x 4, frame
    px: left, top, right, bottom, with room for outlines and smoothing), and which can be
    drawn (m)."""
    S, line = SS, line_width(u)
    kind, r = g.kind, g.r
    m, p = pts.shape[:2]
    P = _to_pixels(pts, view)
    ok = ~np.isnan(pts).reshape(m, -1).any(axis=1) if p else np.zeros(m, dtype=bool)
    if kind == "circle":
        XY = P[:, 0]
        R, known = _radii(r, view, u)
        ok &= known
        turns = np.isfinite(angle)
        every = bool(turns.all())
        a = angle if every else np.where(turns, angle, 0.0)
        end = _snap(XY + R[:, None] * np.stack([np.cos(a), view.flip * np.sin(a)], axis=1))
        if not every:
            end[~turns] = XY[~turns]  # no radius line
        ints = np.concatenate([XY, end, R[:, None]], axis=1)
        lo, hi = XY - (R + line)[:, None], XY + (R + line)[:, None]
    elif kind == "seg":
        W = _widths(r, view, u)
        ints = np.concatenate([P.reshape(m, 4), W[:, None]], axis=1)
        reach = (W / 2 + line)[:, None]
        lo, hi = P.min(axis=1) - reach, P.max(axis=1) + reach
    else:
        ok &= p >= 2
        ints = P.reshape(m, -1)
        if p:
            lo, hi = P.min(axis=1) - line, P.max(axis=1) + line
        else:
            lo = hi = np.zeros((m, 2))
    boxes = np.concatenate([lo / S - 1, hi / S + 1], axis=1)
    if not ok.all():
        boxes[~ok] = math.nan
    return ints, boxes, ok


def _radii(r: np.ndarray, view: View, u: float) -> tuple[np.ndarray, np.ndarray]:
    """Circles' radii (whole pixels at :data:`SS` times the size; at least 1.5 u) and which
    are numbers; the same for a set of shapes and a view, so kept for the last few."""
    key = ("radii", id(r), view, u)
    got = _KEPT.get(key)
    if got is None or got[0] is not r:
        radius = np.fmin(np.maximum(r * (view.s * SS), 1.5 * u * SS), CLIP)
        known = ~np.isnan(radius)
        got = _keep(key, (r, (np.rint(np.where(known, radius, 0.0)).astype(np.int64), known)))
    return got[1]


def _widths(r: np.ndarray, view: View, u: float) -> np.ndarray:
    """Segments' widths (whole pixels at :data:`SS` times the size; at least a line's)."""
    key = ("widths", id(r), view, u)
    got = _KEPT.get(key)
    if got is None or got[0] is not r:
        wide = np.rint(np.fmin(2 * np.where(np.isnan(r), 0.0, r) * (view.s * SS), CLIP))
        got = _keep(key, (r, np.maximum(line_width(u), wide).astype(np.int64)))
    return got[1]


#: What :func:`_radii` and :func:`_widths` keep (their arrays held, so an id is not reused).
_KEPT: dict[tuple, tuple] = {}


def _keep(key: tuple, value: tuple) -> tuple:
    if len(_KEPT) >= 64:
        _KEPT.clear()
    _KEPT[key] = value
    return value


def _zigzags(ends: np.ndarray, u: float) -> np.ndarray:
    """Springs from whole-pixel ends (m x 2 x 2, at :data:`SS` times the size) as zig-zags in
    whole pixels (m x 2(2 COILS + 4), flat x, y): straight leads of LEAD of the length at each
    end and COILS zig-zags between, at most SPRING_WIDTH u or a tenth of the spring's length
    wide (a web of short springs stays legible); all springs at once, as
    :func:`~dumbbell.animation.world.zigzag` draws one."""
    m = len(ends)
    p0 = ends[:, 0].astype(float)
    d = ends[:, 1] - ends[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    amp = np.minimum(SPRING_WIDTH * u * SS, 0.1 * length)
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / length[:, None] * amp[:, None]
    normal[length == 0] = 0.0  # a spring of no length: all its points at its ends
    i = np.arange(2 * COILS)
    f = np.r_[0.0, LEAD, LEAD + (1 - 2 * LEAD) * (i + 0.5) / (2 * COILS), 1 - LEAD, 1.0]
    side = np.r_[0.0, 0.0, np.where(i % 2 == 0, 1.0, -1.0), 0.0, 0.0]
    pts = p0[:, None] + d[:, None] * f[None, :, None] + side[None, :, None] * normal[:, None]
    return np.rint(pts).astype(np.int64).reshape(m, 2 * len(f))


def extra_pixels(items: tuple[tuple, ...] | list[tuple], view: View, u: float
                 ) -> tuple[list[tuple | None], np.ndarray]:
    """Constraints' primitives seen through ``view`` in whole pixels at :data:`SS` times the
    size (a spring's zig-zag, a line, a pivot's dot, a rotary spring's coil; None where one
    cannot be drawn), and their boxes (m x 4, frame px: left, top, right, bottom)."""
    S, line = SS, line_width(u)
    m = len(items)
    boxes = np.full((m, 4), math.nan)
    out: list[tuple | None] = [None] * m
    if not m:
        return out, boxes
    # Every primitive's first point (and second, for springs and lines) at once.
    pts = np.array([(it[3], it[4], it[5], it[6]) if it[0] in ("spring", "line") else
                    (it[3], it[4], it[3], it[4]) for it in items], dtype=float)
    whole = _to_pixels(pts.reshape(m, 2, 2), view)
    ends = whole.reshape(m, 4).tolist()
    # Springs and lines, the many: their points and boxes all at once.
    for kind, flat in (("spring", lambda w: _zigzags(w, u)),
                       ("line", lambda w: w.reshape(len(w), 4))):
        at = [j for j, it in enumerate(items) if it[0] == kind]
        if not at:
            continue
        xy_all = flat(whole[at])
        lo = np.stack([xy_all[:, 0::2].min(axis=1), xy_all[:, 1::2].min(axis=1)], axis=1)
        hi = np.stack([xy_all[:, 0::2].max(axis=1), xy_all[:, 1::2].max(axis=1)], axis=1)
        boxes[at] = np.concatenate([(lo - line) / S - 1, (hi + line) / S + 1], axis=1)
        for j, xy in zip(at, xy_all.tolist(), strict=True):
            out[j] = (kind, xy)
    for j, (it, (ax, ay, _, _)) in enumerate(zip(items, ends, strict=True)):
        kind = it[0]
        room = line
        if kind in ("spring", "line"):
            continue
        if kind == "dot":
            xy = [ax, ay]
            room = round(3 * u * S)
            px = ("dot", ax, ay, room)
        elif kind == "rotary" and math.isfinite(it[5]):
            # A coil of 2.5 turns about the pivot, turned by the spring's twist.
            xy = []
            for i in range(61):
                f = i / 60
                a = f * 2.5 * 2 * math.pi + it[5]
                rr = (4 + 8 * f) * u * S
                xy += [round(ax + rr * math.cos(a)), round(ay + view.flip * rr * math.sin(a))]
            px = ("rotary", xy)
        else:
            continue
        out[j] = px
        xs, ys = xy[0::2], xy[1::2]
        boxes[j] = ((min(xs) - room) / S - 1, (min(ys) - room) / S - 1,
                    (max(xs) + room) / S + 1, (max(ys) + room) / S + 1)
    return out, boxes


class Pixels:
    """Primitives seen through a view, in whole pixels at :data:`SS` times the size and in
    drawing order: shapes (``groups`` of one kind, each with the shapes' places, integer
    coordinates, inks and whether each can be drawn; see :func:`shape_pixels`), then
    ``extras`` (constraints; see :func:`extra_pixels`); ``boxes`` (n x 4, frame px) and ``ok``
    (can be drawn) per primitive. Being whole pixels, a primitive drawn on a crop whose corner
    is a whole pixel gives the same pixels as drawn on the whole frame; and two frames whose
    numbers for a primitive agree draw it alike."""

    def __init__(self, shapes: Shapes | None, pose: np.ndarray | None,
                 extras: tuple[tuple, ...] | list[tuple], view: View, u: float) -> None:
        self.shapes, self.view, self.u = shapes, view, u
        self.n_shapes = shapes.n if shapes is not None else 0
        self.n = self.n_shapes + len(extras)
        self.boxes = np.full((self.n, 4), math.nan)
        self.groups: list[tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        if shapes is not None and pose is not None:
            for g in shapes.groups:
                pts, angle = shapes.place(pose, g)
                ints, boxes, ok = shape_pixels(g, pts, angle, view, u)
                self.boxes[g.at] = boxes
                self.groups.append((g.kind, g.at, ints, shapes.ink[g.at], ok))
        self.extras, self.boxes[self.n_shapes:] = extra_pixels(extras, view, u)
        self.ok = np.isfinite(self.boxes).all(axis=1)

    @classmethod
    def of_items(cls, items: tuple[tuple, ...] | list[tuple], view: View, u: float) -> Pixels:
        """Primitives given as tuples (see the module docstring): the static shapes."""
        shapes = [it for it in items if it[0] in SHAPES]
        extras = [it for it in items if it[0] not in SHAPES]
        if not shapes:
            return cls(None, None, extras, view, u)
        # Each shape its own body: a circle's centre is its body's position, turned by its
        # angle; the other shapes' points are world points on a body at the origin.
        local = [[(0.0, 0.0)] if it[0] == "circle" else
                 [(it[3], it[4]), (it[5], it[6])] if it[0] == "seg" else
                 list(zip(it[3][0::2], it[3][1::2], strict=True)) for it in shapes]
        r = [it[5] if it[0] == "circle" else it[7] if it[0] == "seg" else it[4]
             for it in shapes]
        set_ = Shapes.of([(it[0], j, it[1], it[2]) for j, it in enumerate(shapes)], local, r)
        pose = np.array([(it[3], it[4], it[6]) if it[0] == "circle" else (0.0, 0.0, 0.0)
                         for it in shapes], dtype=float).reshape(-1, 3)
        return cls(set_, pose, extras, view, u)

    @functools.cached_property
    def box(self) -> tuple[float, float, float, float] | None:
        """The box (frame px) of everything that can be drawn."""
        b = self.boxes[self.ok]
        if not len(b):
            return None
        return (float(b[:, 0].min()), float(b[:, 1].min()), float(b[:, 2].max()),
                float(b[:, 3].max()))

    def changed(self, before: Pixels) -> np.ndarray | None:
        """Which primitives are drawn differently from ``before`` (the previous frame's), or
        None when the two cannot be compared (other shapes, another view)."""
        if (before.shapes is not self.shapes or before.view is not self.view
                or len(before.extras) != len(self.extras)):
            return None
        out = np.zeros(self.n, dtype=bool)
        for (_, at, ints, _, ok), (_, _, ints0, _, ok0) in zip(self.groups, before.groups,
                                                                 strict=True):
            out[at] = (ok != ok0) | (ok & (ints != ints0).any(axis=1))
        for j, (a, b) in enumerate(zip(self.extras, before.extras, strict=True)):
            out[self.n_shapes + j] = a != b
        return out

    def within(self, rect: tuple[float, float, float, float]) -> np.ndarray:
        """Whether each primitive's box meets ``rect`` (frame px) and it can be drawn."""
        x0, y0, x1, y1 = rect
        b = self.boxes
        return self.ok & ~((b[:, 2] < x0) | (b[:, 0] > x1) | (b[:, 3] < y0) | (b[:, 1] > y1))

    def draw(self, d: ImageDraw.ImageDraw, corner: tuple[int, int],
             want: np.ndarray | None = None, flat: bool = False) -> None:
        """Draw the primitives (those ``want`` says, else all that can be drawn) in order on
        ``d``, whose pixel (0, 0) is the frame's pixel ``corner``: an RGB image :data:`SS`
        times the size (smooth edges once halved), or, ``flat``, a palette image of the
        frame's size (flat edges, as pygame draws: each whole-pixel number halved)."""
        S = SS
        want = self.ok if want is None else want & self.ok
        ox, oy = corner[0] * S, corner[1] * S
        places, kinds, inks, coords = [], [], [], []
        for kind, at, ints, ink, _ in self.groups:
            rows = np.flatnonzero(want[at])
            if not len(rows):
                continue
            w = ints.shape[1]
            shift = np.zeros(w, dtype=np.int64)
            points = w if kind == "poly" else 4  # then a radius or width
            shift[0:points:2], shift[1:points:2] = ox, oy
            places.append(at[rows])
            kinds += [kind] * len(rows)
            inks += ink[rows].tolist()
            shifted = ints[rows] - shift
            coords += (((shifted + 1) // S) if flat else shifted).tolist()
        pen = _FlatPen(d) if flat else _Pen(d, self.u)
        if places:
            order = np.argsort(np.concatenate(places), kind="stable").tolist()
            for i in order:
                getattr(pen, kinds[i])(inks[i], coords[i])
        for j in np.flatnonzero(want[self.n_shapes:]).tolist():
            px = self.extras[j]
            getattr(pen, px[0])(px, ox, oy)  # type: ignore[index]


@functools.cache
def _inks() -> tuple[list[tuple[int, int]], int, int, dict[int, tuple[int, int, int]]]:
    """Pillow's inks on an RGB image: of each shape colour pair (outline, fill), of springs,
    of pivots, and the colour of each ink."""
    ink = ImageDraw.Draw(Image.new("RGB", (1, 1))).draw.draw_ink
    pairs = [(ink(out), ink(fill)) for out, fill in SHAPE_COLOURS]
    rgb = {ink(c): c for c in (*(c for pair in SHAPE_COLOURS for c in pair), SPRING, INK)}
    return pairs, ink(SPRING), ink(INK), rgb


class _Pen:
    """Draws whole-pixel primitives on an RGB image :data:`SS` times the size: shapes filled
    and outlined in their ink's colours (grey for ink -1), constraints in the spring colour,
    pivots in ink; through Pillow's drawing core."""

    def __init__(self, d: ImageDraw.ImageDraw, u: float) -> None:
        self.d, self.core, self.u = d, d.draw, u
        self.width = line_width(u)
        self.inks, self.spring_ink, self.dot_ink, self.rgb = _inks()

    def _lines(self, xy: list[int], ink: int, width: int, closed: bool = False) -> None:
        if closed:
            xy = [*xy, xy[0], xy[1]]
        if width > 4 and len(xy) > 4:
            # Pillow rounds the joints of wide lines itself (as ImageDraw.line(joint="curve")).
            self.d.line(xy, fill=self.rgb[ink], width=width, joint="curve")
        else:
            self.core.draw_lines(xy, ink, width)

    def circle(self, ink: int, c: list[int]) -> None:
        X, Y, EX, EY, R = c
        out, fill = self.inks[ink]
        box = (X - R, Y - R, X + R, Y + R)
        self.core.draw_ellipse(box, fill, 1)
        if out != fill:
            self.core.draw_ellipse(box, out, 0, self.width)
        if EX != X or EY != Y:
            self.core.draw_lines((X, Y, EX, EY), out, self.width)

    def seg(self, ink: int, c: list[int]) -> None:
        AX, AY, BX, BY, W = c
        out, fill = self.inks[ink]
        line = self.width
        self.core.draw_lines((AX, AY, BX, BY), out, W)
        if W > 2 * line:
            # A fat segment: its outline, then its fill inside, with round ends.
            for width, colour in ((W, out), (W - 2 * line, fill)):
                h = width // 2
                for X, Y in ((AX, AY), (BX, BY)):
                    self.core.draw_ellipse((X - h, Y - h, X - h + width, Y - h + width),
                                           colour, 1)
                if colour == fill:
                    self.core.draw_lines((AX, AY, BX, BY), fill, width)

    def poly(self, ink: int, c: list[int]) -> None:
        out, fill = self.inks[ink]
        # Filled, then outlined with a closed line: Pillow's wide polygon outline draws
        # through a mask image per polygon, many times slower.
        self.core.draw_polygon(c, fill, 1)
        self._lines(c, out, self.width, closed=True)

    def _shifted(self, pts: list[int], ox: int, oy: int) -> list[int]:
        if not (ox or oy):
            return pts
        out = pts[:]
        out[0::2] = [v - ox for v in pts[0::2]]
        out[1::2] = [v - oy for v in pts[1::2]]
        return out

    def spring(self, px: tuple, ox: int, oy: int) -> None:
        self._lines(self._shifted(px[1], ox, oy), self.spring_ink, self.width)

    def line(self, px: tuple, ox: int, oy: int) -> None:
        self._lines(self._shifted(px[1], ox, oy), self.spring_ink, self.width)

    def rotary(self, px: tuple, ox: int, oy: int) -> None:
        self._lines(self._shifted(px[1], ox, oy), self.spring_ink, self.width)

    def dot(self, px: tuple, ox: int, oy: int) -> None:
        _, X, Y, R = px
        X, Y = X - ox, Y - oy
        self.core.draw_ellipse((X - R, Y - R, X + R, Y + R), self.dot_ink, 1)


@functools.cache
def _flat_inks() -> tuple[list[tuple[int, int]], int, int]:
    """Palette indices of each shape colour pair (outline, fill), of springs and pivots."""
    return ([(ink_index(out), ink_index(fill)) for out, fill in SHAPE_COLOURS],
            ink_index(SPRING), ink_index(INK))


class _FlatPen:
    """Draws primitives flat, at the frame's size, straight in palette indices (1 px lines
    and outlines): what :class:`_Pen` draws smooth, with each whole-pixel number halved."""

    def __init__(self, d: ImageDraw.ImageDraw) -> None:
        self.core = d.draw
        self.inks, self.spring_ink, self.dot_ink = _flat_inks()

    def circle(self, ink: int, c: list[int]) -> None:
        X, Y, EX, EY, R = c
        out, fill = self.inks[ink]
        box = (X - R, Y - R, X + R, Y + R)
        self.core.draw_ellipse(box, fill, 1)
        self.core.draw_ellipse(box, out, 0, 1)
        if EX != X or EY != Y:
            self.core.draw_lines((X, Y, EX, EY), out, 1)

    def seg(self, ink: int, c: list[int]) -> None:
        AX, AY, BX, BY, W = c
        out, fill = self.inks[ink]
        self.core.draw_lines((AX, AY, BX, BY), out if W <= 2 else fill, W)

    def poly(self, ink: int, c: list[int]) -> None:
        out, fill = self.inks[ink]
        self.core.draw_polygon(c, fill, 1)
        self.core.draw_lines([*c, c[0], c[1]], out, 1)

    def _halved(self, pts: list[int], ox: int, oy: int) -> list[int]:
        out = pts[:]
        out[0::2] = [(v - ox + 1) // SS for v in pts[0::2]]
        out[1::2] = [(v - oy + 1) // SS for v in pts[1::2]]
        return out

    def spring(self, px: tuple, ox: int, oy: int) -> None:
        self.core.draw_lines(self._halved(px[1], ox, oy), self.spring_ink, 1)

    line = rotary = spring

    def dot(self, px: tuple, ox: int, oy: int) -> None:
        _, X, Y, R = px
        X, Y = self._halved([X, Y], ox, oy)
        R = (R + 1) // SS
        self.core.draw_ellipse((X - R, Y - R, X + R, Y + R), self.dot_ink, 1)


#: Flat drawing (no smoothing) for many small bodies: a set of at least FLAT_MANY moving
#: shapes, each drawn within FLAT_PX px (its box, outline included) when the set is first
#: seen through a view, is drawn flat with 1 px outlines, as pygame_util draws.
FLAT_MANY, FLAT_PX = 100, 20

#: Redrawing: the whole moving layer is drawn again when more than this many primitives
#: changed, when the boxes to draw again are more than this many, or when their area (px),
#: each counted with this many more for its own cost, exceeds the whole layer's.
MAX_CHANGED, MAX_RECTS, RECT_COST = 64, 24, 4000.0


class Layer:
    """One frame's moving primitives (:class:`Pixels`) on the scene panel (``panel``: its
    width and height, px). From the previous frame's layer, :meth:`damage` finds the boxes to
    draw again: where a primitive's whole-pixel numbers changed (so every other primitive
    there is drawn as it was)."""

    def __init__(self, rec: Recording, k: int, view: View, u: float,
                 panel: tuple[int, int], flat: dict[tuple[int, int], bool] | None = None,
                 shapes: Shapes | None = None) -> None:
        shapes = rec.shapes[rec.shape_of[k]] if shapes is None else shapes
        self.px = Pixels(shapes, rec.poses[k], rec.extras[k], view, u)
        self.panel = panel
        box = self.px.box
        self.box = self._clipped(box) if box is not None else None
        # Flat or smooth: decided when a set of shapes is first seen through a view.
        key = (rec.shape_of[k], id(view))
        known = flat if flat is not None else {}
        if key not in known:
            b = self.px.boxes[:self.px.n_shapes][self.px.ok[:self.px.n_shapes]]
            size = np.maximum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) - 2 if len(b) else b
            known[key] = self.px.n_shapes >= FLAT_MANY and bool((size <= FLAT_PX).all())
        self.flat = known[key]

    def _clipped(self, box: tuple[float, float, float, float]
                 ) -> tuple[float, float, float, float] | None:
        w, h = self.panel
        out = (max(box[0], 0), max(box[1], 0), min(box[2], w - 1), min(box[3], h))
        return out if out[2] > out[0] and out[3] > out[1] else None

    def damage(self, before: Layer) -> list[tuple[float, float, float, float]] | None:
        """The boxes (px) to draw again over the previous frame's picture: where a primitive
        changed, appeared or went; None when the whole layer must be drawn again."""
        changed = self.px.changed(before.px)
        if changed is None or self.flat != before.flat:
            return None
        idx = np.flatnonzero(changed)
        if len(idx) > MAX_CHANGED:
            return None
        rects = [tuple(b) for px in (self.px, before.px)
                 for b in px.boxes[idx[px.ok[idx]]].tolist()]
        merged = [c for c in (self._clipped(r) for r in _merge(rects))  # type: ignore[arg-type]
                  if c is not None]
        if len(merged) > MAX_RECTS:
            return None
        whole = self.box
        cost = sum((r[2] - r[0]) * (r[3] - r[1]) + RECT_COST for r in merged)
        if whole is not None and cost > (whole[2] - whole[0]) * (whole[3] - whole[1]):
            return None
        return merged

    def draw(self, d: ImageDraw.ImageDraw, corner: tuple[int, int],
             rect: tuple[float, float, float, float]) -> None:
        """Draw the primitives that meet ``rect`` (frame px) on ``d``, whose pixel (0, 0) is
        the frame's pixel ``corner`` (see :meth:`Pixels.draw`; flat when the layer is)."""
        self.px.draw(d, corner, self.px.within(rect), self.flat)


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
        self.tx_time, self.tx_text = _Text(self.st_time), _Text(self.st_text)
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
        view = self.views[k]
        layer = Layer(self.rec, k, view, self.u, (self.scene_w, self.H), self._flat,
                      self._shapes(self.rec.shape_of[k], view))
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
            self.changed = _union_px(touched) if touched else (0.0, 0.0, 0.0, 0.0)
        return img

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
        """Move the strip's cursor if it moved; the boxes touched."""
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


class _Text:
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
