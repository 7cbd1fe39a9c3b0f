"""The camera of a recorded space: the world box each frame shows, and the view that maps it
onto the scene panel.

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .recorded import Box, Recording

#: No public names: the camera behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

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
#: The shortest and longest span (space units) a view may have.
SPAN_MIN, SPAN_MAX = 1e-30, 1e30

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
