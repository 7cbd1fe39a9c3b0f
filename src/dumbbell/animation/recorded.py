"""What a recorded pymunk space hands its painter: the sets of moving shapes in their
bodies' coordinates (:class:`Shapes`), and everything captured, frozen (:class:`Recording`).

Primitives (tuples; ``ink`` indexes :data:`BODY_INKS`, -1 is grey; ``body`` numbers the
moving body, dynamic or kinematic, that the shape belongs to, or that a constraint joins; -1
for static)::

    ("circle", ink, body, x, y, r, angle)      ("spring", ink, body, ax, ay, bx, by)
    ("seg", ink, body, ax, ay, bx, by, r)      ("line", ink, body, ax, ay, bx, by)
    ("poly", ink, body, (x0, y0, x1, y1, ...), r)   ("dot", ink, body, x, y)
    ("rotary", ink, body, x, y, twist)

**Sizes.** Whatever the view, every moving body is drawn at least :data:`BODY_PX` across
whichever way it turns (:meth:`Shapes.at_least`): a smaller one is drawn larger than to
scale, and the view panel says which (``ViewPanel.grown`` of :mod:`.recording`, named in
the recorder's note).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

#: No public names: the recording behind :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

#: Every moving body is drawn at least this many px across (its larger side, whichever
#: way it turns; times the frame's size unit when larger than 640x360), larger than to scale
#: if need be (the recorder's note names those), ...
BODY_PX = 4.0
#: ... measured on its box turned this many times in a quarter turn.
TURNS = 16

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

    @property
    def energy_unit(self) -> str:
        """The energy's unit, as the bars' title gives it in parentheses ('Energy (J)');
        '' when the title names none."""
        title = self.energy_title or ""
        if "(" not in title or ")" not in title:
            return ""
        return title[title.find("(") + 1:title.rfind(")")]

    def items(self, k: int) -> list[tuple]:
        """Frame ``k``'s moving primitives (its shapes, then its extras)."""
        return [*self.shapes[self.shape_of[k]].items(self.poses[k]), *self.extras[k]]
