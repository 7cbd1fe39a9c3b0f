"""The pens of a recorded space: its primitives as whole pixels seen through a view
(:class:`Pixels`), drawn smooth at twice the size or flat in palette indices, and one
frame's moving layer (:class:`Layer`), with the boxes that changed since the frame before.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from PIL import Image, ImageDraw

from .camera import SHAPES, View
from .painter import SS, union_px
from .palette import GREY, INK, SPRING, TERM_RGB, blend, ink_index
from .recorded import Group, Shapes
from .world import LEAD

#: No public names: the pens behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Inks of the moving bodies, by their order in the space (then again from the start).
BODY_INKS = tuple(TERM_RGB[n] for n in ("A", "B", "K_rot", "K_spin", "U_g", "U_spring"))
#: Fill of static shapes.
STATIC_FILL = (232, 232, 232)
#: Outline and fill of a shape by its ink (-1, the last: static and kinematic shapes).
SHAPE_COLOURS = (*((rgb, blend(rgb, 0.33)) for rgb in BODY_INKS), (GREY, STATIC_FILL))
#: A spring's zig-zag: its coils, and its half-width at most (px at 640x360).
COILS, SPRING_WIDTH = 9, 5.0
#: Pixel coordinates are clipped to this far outside the frame (px) before drawing.
CLIP = 1e5

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

    def __init__(self, px: Pixels, panel: tuple[int, int], flat: bool) -> None:
        self.px = px
        self.panel = panel
        box = self.px.box
        self.box = self._clipped(box) if box is not None else None
        # Flat or smooth: decided when a set of shapes is first seen through a view.
        self.flat = flat

    @staticmethod
    def many_small(px: Pixels) -> bool:
        """Whether the shapes of ``px`` are drawn flat: at least :data:`FLAT_MANY` of them,
        each within :data:`FLAT_PX` px."""
        b = px.boxes[:px.n_shapes][px.ok[:px.n_shapes]]
        size = np.maximum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1]) - 2 if len(b) else b
        return px.n_shapes >= FLAT_MANY and bool((size <= FLAT_PX).all())

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
            r = union_px([hit, r])
        out.append(r)
    return out
