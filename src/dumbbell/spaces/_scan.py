"""A snapshot of a pymunk space for the step-size guard: every body's and shape's numbers read
once into numpy arrays, so that each check is linear (or N log N) in bodies and shapes.

Bodies are numbered by their place in ``space.bodies`` ("body 3" in every message); bodies a
shape or a constraint uses without being in the space (``space.static_body``, a static body
only joints use) get the numbers after those. Positions, velocities and angles come from
``pymunk.batch`` in one call; masses, moments, centres of gravity and shape geometry from
one attribute read each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ._layout import body_function

#: pymunk's body types.
DYNAMIC, KINEMATIC, STATIC = 0, 1, 2


@dataclass
class Scan:
    """The numbers of one space at one moment (see the module docstring). Per body (arrays of
    length ``len(bodies)``): ``kind`` (DYNAMIC, KINEMATIC, STATIC), ``mass``, ``moment``,
    ``cog`` (centre of gravity in body coordinates), ``cg`` (in world coordinates), ``v`` (its
    velocity), ``w`` (angular velocity), ``angle``, ``field`` (True: a custom velocity_func
    moves it). Per shape (length ``len(shapes)``): ``owner`` (body number), ``bb`` (left,
    bottom, right, top), ``size`` (thinnest extent), ``reach`` (farthest point from its body's
    centre of gravity), ``sensor``, ``group``, ``categories``, ``mask``, ``elasticity``. Per
    shape of a fixed body (static or kinematic), ``rest``: the world points of its outline
    (for the floors under falling bodies, see :mod:`._floors`)."""

    space: Any
    bodies: list[Any]
    in_space: int
    kind: np.ndarray
    mass: np.ndarray
    moment: np.ndarray
    cog: np.ndarray
    cg: np.ndarray
    pos: np.ndarray
    v: np.ndarray
    w: np.ndarray
    angle: np.ndarray
    field: np.ndarray
    shapes: list[Any]
    owner: np.ndarray
    bb: np.ndarray
    size: np.ndarray
    reach: np.ndarray
    sensor: np.ndarray
    group: np.ndarray
    categories: np.ndarray
    mask: np.ndarray
    elasticity: np.ndarray
    gravity: np.ndarray
    index: dict[int, int]

    def label(self, i: int) -> str:
        """Body ``i``'s name in reports: 'body N' by its place in ``space.bodies``."""
        if i < self.in_space:
            return f"body {i}"
        return "static body" if self.bodies[i] is self.space.static_body else "body (not in the space)"

    def number(self, body: Any) -> int:
        """The number of ``body``, adding it (with its numbers) if the space does not hold it."""
        i = self.index.get(id(body))
        if i is None:
            i = self._add(body)
        return i

    def _add(self, body: Any) -> int:
        i = len(self.bodies)
        self.bodies.append(body)
        self.index[id(body)] = i
        row = _body_row(body)
        p, a, v, w = (body.position.x, body.position.y), body.angle, body.velocity, body.angular_velocity
        self.kind = np.append(self.kind, int(body.body_type))
        self.mass = np.append(self.mass, row[0])
        self.moment = np.append(self.moment, row[1])
        self.cog = np.vstack([self.cog, row[2:4]])
        self.pos = np.vstack([self.pos, p])
        self.angle = np.append(self.angle, a)
        self.v = np.vstack([self.v, (v.x, v.y)])
        self.w = np.append(self.w, w)
        self.field = np.append(self.field, row[4])
        self.cg = np.vstack([self.cg, _to_world(self.pos[-1:], self.angle[-1:], self.cog[-1:])])
        return i

    @property
    def dynamic(self) -> np.ndarray:
        """Numbers of the dynamic bodies."""
        return np.flatnonzero(self.kind == DYNAMIC)

    @property
    def g(self) -> float:
        """The gravity's magnitude (length units/s^2)."""
        return float(np.hypot(*self.gravity))

    def down(self) -> np.ndarray:
        """The unit vector along gravity ((0, -1) without gravity)."""
        g = self.g
        return self.gravity / g if g > 0 else np.array([0.0, -1.0])


def _body_row(body: Any) -> tuple[float, float, float, float, bool]:
    cog = body.center_of_gravity
    field = body._velocity_func is not None and body_function(body, "velocity_func") is not None
    return (float(body.mass), float(body.moment), float(cog.x), float(cog.y), bool(field))


def _to_world(pos: np.ndarray, angle: np.ndarray, local: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    x = pos[:, 0] + c * local[:, 0] - s * local[:, 1]
    y = pos[:, 1] + s * local[:, 0] + c * local[:, 1]
    return np.column_stack([x, y])


def _motion(space: Any, bodies: list[Any]) -> np.ndarray:
    """(n, 6): x, y, angle, vx, vy, angular velocity of ``bodies``, in their order (see
    :func:`batch`)."""
    ids, rows = batch(space, ("POSITION", "ANGLE", "VELOCITY", "ANGULAR_VELOCITY"))
    where = {int(k): j for j, k in enumerate(ids)}
    order = [where.get(int(b.id), -1) for b in bodies]
    if -1 not in order:
        return rows[order].copy()
    out = np.empty((len(bodies), 6))
    for i, b in enumerate(bodies):
        p, v = b.position, b.velocity
        out[i] = (p.x, p.y, b.angle, v.x, v.y, b.angular_velocity)
    return out


def batch(space: Any, fields: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The ids of the space's bodies and the ``fields`` of each (rows of floats, in the order
    of pymunk's ``BodyFields``: position x, y, angle, velocity x, y, spin, force x, y,
    torque), through ``pymunk.batch`` when it can, else one body at a time."""
    names = {"POSITION": ("position", 2), "ANGLE": ("angle", 1), "VELOCITY": ("velocity", 2),
             "ANGULAR_VELOCITY": ("angular_velocity", 1), "FORCE": ("force", 2),
             "TORQUE": ("torque", 1)}
    width = sum(names[f][1] for f in fields)
    try:
        import pymunk.batch as pb

        flags = pb.BodyFields.BODY_ID
        for f in fields:
            flags |= getattr(pb.BodyFields, f)
        buf = pb.Buffer()
        pb.get_space_bodies(space, flags, buf)
        rows = np.frombuffer(buf.float_buf(), dtype=float).reshape(-1, width)
        ids = np.frombuffer(buf.int_buf(), dtype=np.uintp)
        if len(ids) == len(rows):
            return ids, rows
    except (ImportError, AttributeError, ValueError):  # pragma: no cover - an older pymunk
        pass
    bodies = list(space.bodies)
    rows = np.empty((len(bodies), width))
    for i, b in enumerate(bodies):
        values: list[float] = []
        for f in fields:
            v = getattr(b, names[f][0])
            values += [v.x, v.y] if names[f][1] == 2 else [v]
        rows[i] = values
    return np.array([b.id for b in bodies], dtype=np.uintp), rows


def scan(space: Any) -> Scan:
    """Read ``space`` (a pymunk.Space, already checked) into a :class:`Scan`. Numbers that
    are not finite (an angle of inf, a radius of nan) pass through quietly, as NaN or inf:
    :func:`~dumbbell.spaces.estimates.state_problem` names them."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        return _scan(space)


def _scan(space: Any) -> Scan:
    bodies = list(space.bodies)
    in_space = len(bodies)
    shapes = list(space.shapes)
    index = {id(b): i for i, b in enumerate(bodies)}
    # Bodies the shapes sit on that the space does not list (its static body, mostly).
    for s in shapes:
        b = s.body
        if id(b) not in index:
            index[id(b)] = len(bodies)
            bodies.append(b)
    rows = [_body_row(b) for b in bodies]
    motion = _motion(space, bodies[:in_space]) if in_space else np.empty((0, 6))
    if len(bodies) > in_space:
        extra = bodies[in_space:]
        motion = np.vstack([motion, [(b.position.x, b.position.y, b.angle, b.velocity.x,
                                      b.velocity.y, b.angular_velocity) for b in extra]])
    table = np.array([r[:4] for r in rows], dtype=float).reshape(-1, 4)
    pos, angle = motion[:, 0:2], motion[:, 2]
    cog = table[:, 2:4]
    kinds = np.array([int(b.body_type) for b in bodies], dtype=int)
    owner = np.array([index[id(s.body)] for s in shapes], dtype=int)
    cg = _to_world(pos, angle, cog)
    geometry = _shapes(shapes, owner, cog, pos, angle)
    filters = [s.filter for s in shapes]
    return Scan(
        space=space, bodies=bodies, in_space=in_space, kind=kinds,
        mass=table[:, 0], moment=table[:, 1], cog=cog, cg=cg, pos=pos.copy(),
        v=motion[:, 3:5].copy(), w=motion[:, 5].copy(), angle=angle.copy(),
        field=np.array([r[4] for r in rows], dtype=bool),
        shapes=shapes, owner=owner, bb=geometry[0], size=geometry[1], reach=geometry[2],
        sensor=np.array([bool(s.sensor) for s in shapes], dtype=bool),
        group=np.array([int(f.group) for f in filters], dtype=np.int64),
        categories=np.array([int(f.categories) for f in filters], dtype=np.int64),
        mask=np.array([int(f.mask) for f in filters], dtype=np.int64),
        elasticity=np.array([float(s.elasticity) for s in shapes], dtype=float),
        gravity=np.array([float(space.gravity[0]), float(space.gravity[1])]),
        index=index,
    )


def _shapes(shapes: list[Any], owner: np.ndarray, cog: np.ndarray,
            pos: np.ndarray | None = None, angle: np.ndarray | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bounding boxes in world coordinates (from each shape's geometry and its body's ``pos``
    and ``angle`` now, read without touching pymunk's cached ones; nan without them), thinnest
    extents and reaches of ``shapes``."""
    import pymunk

    m = len(shapes)
    size = np.zeros(m)
    reach = np.zeros(m)
    radius = np.zeros(m)
    # Each shape's outline points in body coordinates: a circle's centre, a segment's ends,
    # a polygon's vertices; the box is their span plus the radius.
    points: list[list[tuple[float, float]]] = []
    polys: dict[int, list[int]] = {}
    for j, s in enumerate(shapes):
        c = cog[owner[j]]
        if isinstance(s, pymunk.Circle):
            r = float(s.radius)
            pts = [(s.offset.x, s.offset.y)]
            size[j] = 2.0 * r
        elif isinstance(s, pymunk.Segment):
            r = float(s.radius)
            pts = [(s.a.x, s.a.y), (s.b.x, s.b.y)]
            size[j] = 2.0 * r
        elif isinstance(s, pymunk.Poly):
            r = float(s.radius)
            pts = [(v.x, v.y) for v in s.get_vertices()]
            polys.setdefault(len(pts), []).append(j)
        else:
            r, pts = 0.0, [(float(c[0]), float(c[1]))]
        radius[j] = r
        points.append(pts)
        reach[j] = max(math.hypot(x - c[0], y - c[1]) for x, y in pts) + r
        if not (math.isfinite(r) and all(math.isfinite(v) for p in pts for v in p)):
            # Geometry that is not a number (max() can pass over a NaN): nan marks the
            # shape for :func:`~dumbbell.spaces.estimates.state_problem`.
            reach[j] = size[j] = math.nan
    for count, idx in polys.items():
        v = np.array([points[j] for j in idx], dtype=float).reshape(-1, count, 2)
        size[idx] = _poly_width(v) + 2.0 * radius[idx]
    bb = np.full((m, 4), np.nan)
    if pos is not None and angle is not None:
        for count in {len(p) for p in points}:
            idx = np.array([j for j in range(m) if len(points[j]) == count], dtype=int)
            local = np.array([points[j] for j in idx], dtype=float).reshape(-1, count, 2)
            b = owner[idx]
            c, s_ = np.cos(angle[b])[:, None], np.sin(angle[b])[:, None]
            x = pos[b, 0][:, None] + c * local[..., 0] - s_ * local[..., 1]
            y = pos[b, 1][:, None] + s_ * local[..., 0] + c * local[..., 1]
            r = radius[idx]
            bb[idx] = np.column_stack([x.min(axis=1) - r, y.min(axis=1) - r,
                                       x.max(axis=1) + r, y.max(axis=1) + r])
    return bb, size, reach


def _poly_width(v: np.ndarray) -> np.ndarray:
    """Least width across an edge of each polygon ``v`` (polygons, vertices, 2): over its
    edges, the spread of the vertices along the edge's normal; 0 for a degenerate one."""
    edge = np.roll(v, -1, axis=1) - v
    length = np.hypot(edge[..., 0], edge[..., 1])
    ok = length > 0
    safe = np.where(ok, length, 1.0)
    n = np.stack([edge[..., 1] / safe, -edge[..., 0] / safe], axis=-1)   # (P, k, 2)
    proj = np.einsum("pvd,ped->pev", v, n)                               # (P, k, k)
    spread = proj.max(axis=2) - proj.min(axis=2)                       # (P, k)
    spread = np.where(ok, spread, np.inf)
    width = spread.min(axis=1)
    return np.where(np.isfinite(width), width, 0.0)


def world_outline(shape: Any, body: Any, pymunk: Any) -> tuple[str, np.ndarray, float]:
    """A fixed shape's outline in world coordinates: ('circle', [[cx, cy]], r),
    ('segment', [[ax, ay], [bx, by]], r) or ('poly', vertices, r)."""
    if isinstance(shape, pymunk.Circle):
        p = body.local_to_world(shape.offset)
        return "circle", np.array([[p.x, p.y]]), float(shape.radius)
    if isinstance(shape, pymunk.Segment):
        a, b = body.local_to_world(shape.a), body.local_to_world(shape.b)
        return "segment", np.array([[a.x, a.y], [b.x, b.y]]), float(shape.radius)
    verts = [body.local_to_world(v) for v in shape.get_vertices()]
    return "poly", np.array([[p.x, p.y] for p in verts]), float(shape.radius)


def apart(sc: Scan) -> set[tuple[int, int]]:
    """Pairs of body numbers that a constraint with ``collide_bodies = False`` keeps from
    colliding (both orders)."""
    pairs = set()
    for c in sc.space.constraints:
        if not c.collide_bodies:
            a, b = sc.number(c.a), sc.number(c.b)
            pairs.update(((a, b), (b, a)))
    return pairs


def _classes(sc: Scan) -> tuple[np.ndarray, np.ndarray]:
    """Each shape's filter class (shapes with equal group, categories and mask share one),
    and which classes can collide: (class of each shape, classes x classes booleans)."""
    keys = np.column_stack([sc.group, sc.categories, sc.mask]) if len(sc.shapes) else \
        np.zeros((0, 3), dtype=np.int64)
    unique, which = np.unique(keys, axis=0, return_inverse=True)
    which = np.asarray(which).reshape(-1)
    g, cat, mask = unique[:, 0], unique[:, 1], unique[:, 2]
    same_group = (g[:, None] == g[None, :]) & (g[:, None] != 0)
    compatible = (~same_group & ((cat[:, None] & mask[None, :]) != 0)
                  & ((cat[None, :] & mask[:, None]) != 0))
    return which, compatible


@dataclass
class _Filters:
    """What :func:`best_other` needs about who can hit whom, worked out once per scan:
    shape classes, which classes collide, each body's classes, the pairs kept apart, and for
    each body its one class (-1 when it has none, several, or partners kept apart: those
    bodies take the slow path)."""

    cls: np.ndarray
    compatible: np.ndarray
    own: dict[int, set[int]]
    kept_apart: set[tuple[int, int]]
    single: np.ndarray


def _filters(sc: Scan) -> _Filters:
    cached = getattr(sc, "_filters_cache", None)
    if cached is not None:
        return cached
    cls, compatible = _classes(sc)
    own: dict[int, set[int]] = {}
    for j in np.flatnonzero(~sc.sensor):
        own.setdefault(int(sc.owner[j]), set()).add(int(cls[j]))
    kept_apart = apart(sc)
    partnered = {a for a, _ in kept_apart}
    single = np.full(len(sc.bodies), -1)
    for i, classes in own.items():
        if len(classes) == 1 and i not in partnered:
            single[i] = next(iter(classes))
    sc._filters_cache = _Filters(cls, compatible, own, kept_apart, single)
    return sc._filters_cache


def best_other(sc: Scan, value: np.ndarray, candidate: np.ndarray, idx: np.ndarray,
               mode: str) -> tuple[np.ndarray, np.ndarray]:
    """For each body of ``idx``: the least (``mode`` 'min') or largest ('max') ``value`` over
    the ``candidate`` shapes it can hit, and that shape's number (nan and -1 when there is
    none). A body can hit another body's solid (not sensor) shape when the shape filters let
    them collide and no constraint with ``collide_bodies = False`` joins the two bodies. The
    shapes are grouped by filter and ranked once, so this is linear in bodies and shapes
    (N log N for the ranking)."""
    out = np.full(len(idx), np.nan)
    which_shape = np.full(len(idx), -1)
    if len(sc.shapes) == 0 or len(idx) == 0:
        return out, which_shape
    f = _filters(sc)
    cand = candidate & ~sc.sensor & ~np.isnan(value)
    order: dict[int, np.ndarray] = {}
    for c in np.unique(f.cls[cand]):
        members = np.flatnonzero(cand & (f.cls == c))
        ranked = np.argsort(value[members], kind="stable")
        order[int(c)] = members[ranked if mode == "min" else ranked[::-1]]
    better = np.less if mode == "min" else np.greater
    idx = np.asarray(idx, dtype=int)
    single = f.single[idx]
    # Bodies with one filter class and no partners kept apart: the best shape of each class
    # that collides with theirs, or the best of another body when that one is their own.
    for cb, ranked in order.items():
        top = int(ranked[0])
        others = np.flatnonzero(sc.owner[ranked] != sc.owner[top])
        alt = int(ranked[others[0]]) if len(others) else -1
        pick = np.where(sc.owner[top] != idx, top, alt)
        use = (single >= 0) & f.compatible[np.maximum(single, 0), cb] & (pick >= 0)
        vals = value[np.maximum(pick, 0)]
        take = use & ((which_shape < 0) | better(vals, out))
        out[take], which_shape[take] = vals[take], pick[take]
    # The others, one at a time.
    for k in np.flatnonzero(single < 0):
        i = int(idx[k])
        for ca in f.own.get(i, ()):
            for cb, ranked in order.items():
                j = _first_other(sc, f, i, ranked) if f.compatible[ca, cb] else -1
                if j >= 0 and (which_shape[k] < 0 or better(value[j], out[k])):
                    out[k], which_shape[k] = value[j], j
    return out, which_shape


def _first_other(sc: Scan, f: _Filters, i: int, ranked: np.ndarray) -> int:
    """The first of the shapes ``ranked`` that belongs to a body other than ``i`` and not
    kept apart from it, or -1."""
    for j in ranked:
        o = int(sc.owner[j])
        if o != i and (i, o) not in f.kept_apart:
            return int(j)
    return -1


def hittable_in(sc: Scan, i: int, box: np.ndarray) -> np.ndarray:
    """The numbers of the solid shapes inside ``box`` (left, bottom, right, top; pymunk's
    spatial index) that body ``i`` can hit (see :func:`best_other`)."""
    import pymunk

    if not hasattr(sc, "_number_of_shape"):
        sc._number_of_shape = {id(s): j for j, s in enumerate(sc.shapes)}
    number = sc._number_of_shape
    found = sc.space.bb_query(pymunk.BB(*(float(x) for x in box)), pymunk.ShapeFilter())
    mine = np.flatnonzero((sc.owner == i) & ~sc.sensor)
    out = []
    for s in found:
        j = number.get(id(s))
        if j is None or sc.sensor[j]:
            continue
        o = int(sc.owner[j])
        if o == i or (i, o) in _filters(sc).kept_apart:
            continue
        if any(_collide(sc, int(a), j) for a in mine):
            out.append(j)
    return np.array(out, dtype=int)


def _collide(sc: Scan, a: int, b: int) -> bool:
    """Whether the shape filters of shapes ``a`` and ``b`` let them collide."""
    if sc.group[a] != 0 and sc.group[a] == sc.group[b]:
        return False
    return bool(sc.categories[a] & sc.mask[b]) and bool(sc.categories[b] & sc.mask[a])
