"""What the recorder collects of a space: its shapes and constraints as the primitives of
:mod:`dumbbell.animation.recorded`, in world coordinates (:class:`PaletteDrawOptions`, a
``pymunk.SpaceDebugDrawOptions``; imported with pymunk, when the recorder first needs it)."""

from __future__ import annotations

import operator
from typing import Any

import numpy as np
import pymunk
from pymunk.space_debug_draw_options import SpaceDebugColor

from ..animation.pens import BODY_INKS
from ..animation.recorded import Shapes

#: No public names: ``PaletteDrawOptions`` is :mod:`dumbbell.spaces.recorder`'s.
__all__: list[str] = []

STATIC, DYNAMIC, BLACK = pymunk.Body.STATIC, pymunk.Body.DYNAMIC, SpaceDebugColor(0, 0, 0, 255)


class PaletteDrawOptions(pymunk.SpaceDebugDrawOptions):
    """Collects a space's shapes and constraints as primitives in world coordinates for
    the recorder's painter (their format: :mod:`dumbbell.animation.recorded`).
    ``capture(space)`` returns the moving ones (dynamic and kinematic bodies'
    shapes, constraints) and keeps the static ones of the same moment in ``static``;
    ``space.debug_draw(options)`` collects the same shapes into ``items`` and
    ``static``, through pymunk's callbacks.

    Examples
    --------
    >>> import pymunk
    >>> from dumbbell import spaces
    >>> space = pymunk.Space()                     # a rod on a pivot
    >>> rod = pymunk.Body(1.0, 0.1)
    >>> pivot = pymunk.PivotJoint(space.static_body, rod, (0, 0))
    >>> space.add(rod, pymunk.Segment(rod, (-0.5, 0.0), (0.5, 0.0), 0.02), pivot)
    >>> options = spaces.draw_options()
    >>> isinstance(options, pymunk.SpaceDebugDrawOptions), options.ink_of(rod)
    (True, 0)
    >>> len(options.capture(space))                 # the rod and the pivot
    2
    """

    def __init__(self) -> None:
        super().__init__()
        self.flags = pymunk.SpaceDebugDrawOptions.DRAW_SHAPES
        self.items: list[tuple] = []
        self.static: list[tuple] = []
        self._ink: dict[int, int] = {}
        self._number: dict[int, int] = {}
        self._shape: tuple[int, int] = (-1, -1)
        self._sink: list[tuple] = self.items
        self._geometry: _Geometry | None = None

    def ink_of(self, body: Any) -> int:
        """Index into the recorder's body colours of a dynamic body (in the order the
        bodies are first seen); -1 for static and kinematic ones (grey).

        Parameters
        ----------
        body : pymunk.Body
            The body.

        Returns
        -------
        int
            The colour's index; -1 for grey.
        """
        from ..model import args

        return self._ink_of(args.pymunk_object(body, "body", ("Body",)))

    def _ink_of(self, body: Any) -> int:
        if body.body_type != DYNAMIC:
            return -1
        key = id(body)
        ink = self._ink.get(key)
        if ink is None:
            ink = self._ink[key] = len(self._ink) % len(BODY_INKS)
        return ink

    def _number_of(self, body: Any) -> int:
        """The number of a moving (dynamic or kinematic) body, in the order first seen;
        -1 for a static body."""
        if body.body_type == STATIC:
            return -1
        return self._number.setdefault(id(body), len(self._number))

    def color_for_shape(self, shape: Any) -> Any:
        body = shape.body
        self._sink = self.static if body.body_type == STATIC else self.items
        self._shape = (self._ink_of(body), self._number_of(body))
        return BLACK

    def draw_circle(self, pos: Any, angle: float, radius: float, outline_color: Any,
                    fill_color: Any) -> None:
        self._sink.append(("circle", *self._shape, pos.x, pos.y, radius, angle))

    def draw_segment(self, a: Any, b: Any, color: Any) -> None:
        self._sink.append(("seg", *self._shape, a.x, a.y, b.x, b.y, 0.0))

    def draw_fat_segment(self, a: Any, b: Any, radius: float, outline_color: Any,
                         fill_color: Any) -> None:
        self._sink.append(("seg", *self._shape, a.x, a.y, b.x, b.y, radius))

    def draw_polygon(self, verts: Any, radius: float, outline_color: Any,
                     fill_color: Any) -> None:
        flat = tuple(c for v in verts for c in (v.x, v.y))
        self._sink.append(("poly", *self._shape, flat, radius))

    def draw_dot(self, size: float, pos: Any, color: Any) -> None:
        pass  # collision points are not drawn

    def capture(self, space: Any) -> list[tuple]:
        """The primitives of ``space`` now: the moving ones are returned (dynamic and
        kinematic shapes, constraints), the static ones kept in ``static``. The same
        primitives as ``space.debug_draw(self)`` collects, computed from each body's pose
        and its shapes' local geometry (see :class:`_Geometry`).

        Parameters
        ----------
        space : pymunk.Space
            The space.

        Returns
        -------
        list of tuple
            The moving primitives.
        """
        from ..model import args

        args.space(space)
        self.items, self.static = self._geometry_of(space).items(space)
        self.items += constraint_items(space, self._number_of)
        return self.items

    def _geometry_of(self, space: Any) -> _Geometry:
        """The geometry of the shapes of ``space`` now (made again when they change)."""
        shapes = space.shapes
        if self._geometry is None or not self._geometry.same(shapes):
            self._geometry = _Geometry(list(shapes), self._ink_of, self._number_of)
        return self._geometry


class _Geometry:
    """A space's shapes as local geometry on their bodies (a moving and a static
    :class:`~dumbbell.animation.recorded.Shapes`), made again when the shapes change: a
    capture then reads every body's pose at once (``pymunk.batch``), and the painter places
    each kind of shape with one numpy expression, instead of a Python call per shape from
    ``space.debug_draw``. Always the bodies' present pose, so a body placed by hand before a
    step is drawn where it is (pymunk's own drawing waits for the next step). A shape changed
    in place (pymunk's ``unsafe_set_radius``, ``unsafe_set_vertices``, ...) is seen once the
    space's list of shapes changes."""

    def __init__(self, shapes: list[Any], ink_of: Any, number_of: Any) -> None:
        self.shapes = shapes
        self.bodies: list[Any] = []
        where: dict[int, int] = {}
        kinds, rows, local, radii = [], [], [], []
        for shape in shapes:
            body = shape.body
            if id(body) not in where:
                where[id(body)] = len(self.bodies)
                self.bodies.append(body)
            rows.append(where[id(body)])
            if isinstance(shape, pymunk.Circle):
                kinds.append("circle")
                local.append([tuple(shape.offset)])
            elif isinstance(shape, pymunk.Segment):
                kinds.append("seg")
                local.append([tuple(shape.a), tuple(shape.b)])
            else:
                kinds.append("poly")
                local.append([tuple(v) for v in shape.get_vertices()])
            radii.append(shape.radius)
        tags = [(ink_of(b), number_of(b)) for b in self.bodies]
        static = [b.body_type == pymunk.Body.STATIC for b in self.bodies]

        def subset(want: bool) -> Any:
            idx = [i for i, r in enumerate(rows) if static[r] == want]
            return Shapes.of([(kinds[i], rows[i], *tags[rows[i]]) for i in idx],
                             [local[i] for i in idx], [radii[i] for i in idx])

        self.moving, self.static = subset(False), subset(True)
        self.static_rows = np.flatnonzero(static)
        self._ids = np.array([b.id for b in self.bodies], dtype=np.int64)
        self._rows: np.ndarray | None = None
        self._seen, self._found = -1, np.zeros(0, dtype=bool)

    def same(self, shapes: Any) -> bool:
        """Whether ``shapes`` are the shapes this geometry was made of, in the same order."""
        return len(shapes) == len(self.shapes) and all(map(operator.is_, shapes, self.shapes))

    def poses(self, space: Any) -> np.ndarray:
        """Every body's x, y and angle now (one row per body)."""
        import pymunk.batch

        fields = pymunk.batch.BodyFields
        buf = pymunk.batch.Buffer()
        pymunk.batch.get_space_bodies(space, fields.BODY_ID | fields.POSITION | fields.ANGLE,
                                      buf)
        ids = np.frombuffer(buf.int_buf(), dtype=np.int64)
        data = np.frombuffer(buf.float_buf(), dtype=float).reshape(-1, 3)
        if self._rows is None or len(ids) != self._seen or not np.array_equal(
                ids[self._rows[self._found]], self._ids[self._found]):
            # Which row holds which body (pymunk keeps the order while no body comes or
            # goes); bodies the batch does not list (static ones) are read one by one.
            row = {v: r for r, v in enumerate(ids.tolist())}
            rows = [row.get(i, -1) for i in self._ids.tolist()]
            self._rows, self._seen = np.array(rows, dtype=int), len(ids)
            self._found = self._rows >= 0
        out = np.empty((len(self.bodies), 3))
        out[self._found] = data[self._rows[self._found]]
        for i in np.flatnonzero(~self._found).tolist():
            body = self.bodies[i]
            out[i] = (*body.position, body.angle)
        return out

    def items(self, space: Any) -> tuple[list[tuple], list[tuple]]:
        """The moving and the static primitives of the shapes now, in the shapes' order."""
        pose = self.poses(space)
        return self.moving.items(pose), self.static.items(pose)


def constraint_items(space: Any, number_of: Any) -> list[tuple]:
    """The primitives of the constraints of ``space`` that have a picture: springs (linear
    and rotary), pin and slide joints and grooves as lines, pivots that hold a position as
    dots; each tagged with
    a moving body it joins (its ``number_of``), -1 when it joins none."""
    items: list[tuple] = []
    for c in space.constraints:
        a, b = c.a, c.b
        tag = number_of(b)
        if tag < 0:
            tag = number_of(a)
        if isinstance(c, pymunk.DampedSpring):
            pa, pb = a.local_to_world(c.anchor_a), b.local_to_world(c.anchor_b)
            items.append(("spring", -1, tag, pa.x, pa.y, pb.x, pb.y))
        elif isinstance(c, pymunk.DampedRotarySpring):
            # At the pivot the two bodies share, if any; else at the moving body.
            pins = [j for j in space.constraints if isinstance(j, pymunk.PivotJoint)
                    and {id(j.a), id(j.b)} == {id(a), id(b)}]
            if pins:
                p = pins[0].a.local_to_world(pins[0].anchor_a)
            else:
                body = b if b.body_type == pymunk.Body.DYNAMIC else a
                p = body.local_to_world(body.center_of_gravity)
            items.append(("rotary", -1, tag, p.x, p.y, a.angle - b.angle - c.rest_angle))
        elif isinstance(c, pymunk.PinJoint | pymunk.SlideJoint):
            pa, pb = a.local_to_world(c.anchor_a), b.local_to_world(c.anchor_b)
            items.append(("line", -1, tag, pa.x, pa.y, pb.x, pb.y))
        elif isinstance(c, pymunk.PivotJoint) and c.max_bias > 0:
            # (With max_bias 0 a pivot drives velocities only and holds no position: pymunk's
            # idiom for top-down friction and control bodies. It is not drawn.)
            p = a.local_to_world(c.anchor_a)
            items.append(("dot", -1, tag, p.x, p.y))
        elif isinstance(c, pymunk.GrooveJoint):
            ga, gb = a.local_to_world(c.groove_a), a.local_to_world(c.groove_b)
            items.append(("line", -1, tag, ga.x, ga.y, gb.x, gb.y))
    return items
