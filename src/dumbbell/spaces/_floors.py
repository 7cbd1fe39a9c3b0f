"""The floors under falling bodies for the reach estimate (:mod:`.estimates`): the static and
kinematic shapes copied into a private pymunk space, the first one straight below a body
found through pymunk's spatial index, and slopes slid down to the next floor."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._scan import DYNAMIC, Scan, world_outline

#: Most floors followed down slopes from one body.
MAX_FLOORS = 16


def columns(sc: Scan, idx: np.ndarray, down: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Any]]:
    """For the bodies ``idx``: the lowest depth of their solid shapes now, and the swept
    circle that finds the floor under each: start (the centre of their bounding box),
    radius (half their width across gravity) and the filter of their first solid shape
    (None for a body without a solid shape)."""
    solid = np.flatnonzero(~sc.sensor)
    nb = len(sc.bodies)
    lo = np.full((nb, 2), np.inf)
    hi = np.full((nb, 2), -np.inf)
    np.minimum.at(lo, sc.owner[solid], sc.bb[solid, :2])
    np.maximum.at(hi, sc.owner[solid], sc.bb[solid, 2:])
    first: dict[int, Any] = {}
    for j in solid[::-1]:
        first[int(sc.owner[j])] = sc.shapes[int(j)].filter
    # A body without a solid shape keeps infinite bounds here; it gets no filter below.
    lo, hi = np.where(np.isfinite(lo), lo, 0.0)[idx], np.where(np.isfinite(hi), hi, 0.0)[idx]
    across = np.array([-down[1], down[0]])
    corners = [np.column_stack([x[:, 0], y[:, 1]]) for x in (lo, hi) for y in (lo, hi)]
    depth = np.max([c @ down for c in corners], axis=0)
    width = np.max([c @ across for c in corners], axis=0) - np.min(
        [c @ across for c in corners], axis=0)
    centre = 0.5 * (lo + hi)
    return depth, centre, 0.5 * width, [first.get(int(i)) for i in idx]


class Floors:
    """The static and kinematic shapes as floors: copies in a private pymunk space (so that
    pymunk's spatial index finds the one under a body), each with its lowest point on top."""

    def __init__(self, sc: Scan, down: np.ndarray, pymunk: Any) -> None:
        self.down = down
        self.space = pymunk.Space()
        self.low: dict[Any, tuple[float, np.ndarray]] = {}
        fixed = np.flatnonzero((sc.kind[sc.owner] != DYNAMIC) & ~sc.sensor)
        deepest = -math.inf
        static = self.space.static_body
        for j in fixed:
            shape = sc.shapes[int(j)]
            kind, pts, r = world_outline(shape, sc.bodies[int(sc.owner[j])], pymunk)
            if kind == "circle":
                copy = pymunk.Circle(static, r, tuple(pts[0]))
                low_point, low = pts[0], float(pts[0] @ down)
            elif kind == "segment":
                copy = pymunk.Segment(static, tuple(pts[0]), tuple(pts[1]), r)
                k = int(np.argmax(pts @ down))
                low_point, low = pts[k], float(pts[k] @ down) - r
            else:
                copy = pymunk.Poly(static, [tuple(p) for p in pts], radius=r)
                low_point, low = _poly_low(pts, down)
                low -= r
            copy.filter = shape.filter
            self.space.add(copy)
            self.low[copy] = (low, low_point)
            deepest = max(deepest, float((pts @ down).max()) + r)
        self.deepest = deepest
        self.fixed = fixed

    def level(self, start: Any, radius: float, filt: Any) -> float | None:
        """The depth a body's lowest point reaches on the floors under the swept circle from
        ``start`` (None when nothing is under it)."""
        if not self.low:
            return None
        down = self.down
        start = np.asarray(start, dtype=float)
        span = max(self.deepest - float(start @ down), 0.0) + 2.0 * radius + 1.0
        end = start + down * span
        hit = self.space.segment_query_first(tuple(start), tuple(end), radius, filt)
        if hit is None:
            return None
        seen = {hit.shape}
        low, point = self.low[hit.shape]
        level = low
        for _ in range(MAX_FLOORS):
            landed = float(np.array([hit.point.x, hit.point.y]) @ down)
            if not low > landed + 1e-9 * (1.0 + abs(landed)):
                break                         # a flat floor: nothing lower by sliding
            # Slid down to its lowest point: what is under that point?
            start = point - down * radius
            span = max(self.deepest - float(start @ down), 0.0) + 2.0 * radius + 1.0
            hits = [h for h in self.space.segment_query(tuple(start), tuple(start + down * span),
                                                         radius, filt) if h.shape not in seen]
            if not hits:
                break
            hit = min(hits, key=lambda h: h.alpha)
            seen.add(hit.shape)
            low, point = self.low[hit.shape]
            if not low > level:
                break                         # a wall at the end of the slope
            level = low
        return level

    def lowest_reachable(self, sc: Scan, idx: np.ndarray, held_level: np.ndarray,
                         own_reach: np.ndarray) -> float | None:
        """The deepest point anything solid can reach: the static and kinematic shapes'
        bottoms, and held bodies swung to their lowest (None if there is nothing)."""
        deepest = self.deepest if self.low else -math.inf
        held = ~np.isnan(held_level)
        if held.any():
            deepest = max(deepest, float((held_level[held] + own_reach[held]).max()))
        return None if math.isinf(deepest) else deepest


def _poly_low(pts: np.ndarray, down: np.ndarray) -> tuple[np.ndarray, float]:
    """The lowest point on a polygon's top (its vertices on edges that face up)."""
    edge = np.roll(pts, -1, axis=0) - pts
    normal = np.column_stack([edge[:, 1], -edge[:, 0]])     # outward for pymunk's CCW order
    up = normal @ down < 0
    top = np.unique(np.concatenate([np.flatnonzero(up), (np.flatnonzero(up) + 1) % len(pts)]))
    if len(top) == 0:
        top = np.arange(len(pts))
    depth = pts[top] @ down
    k = int(top[int(np.argmax(depth))])
    return pts[k], float(depth.max())
