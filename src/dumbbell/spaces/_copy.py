"""A copy of a pymunk space for the guard's probe (:mod:`._probe`): a new space built from
the public attributes of the user's one (bodies, shapes, constraints and their settings, the
space's settings, the forces set now), so that nothing in the user's space changes and no
callback of the program runs on it (collision handlers and a constraint's
``pre_solve``/``post_solve`` are not copied; a custom ``velocity_func``, spring force or
torque is, being part of the physics)."""

from __future__ import annotations

from typing import Any

from .._pymunk import spring_function
from ._layout import body_function


class Uncopyable(Exception):
    """The space holds something the probe cannot copy (the message says what)."""


# --- the copy --------------------------------------------------------------------------------


class Copy:
    """A new space with the user's bodies, shapes and constraints, built from their public
    attributes (see the module docstring); ``body`` maps id() of each user body to its copy,
    ``constraints`` are the copies in the order of ``space.constraints``, ``pushes`` the
    forces set now (copy body, force, torque)."""

    def __init__(self, space: Any) -> None:
        import pymunk

        new = pymunk.Space()
        for name in ("gravity", "damping", "iterations", "collision_slop", "collision_bias",
                     "collision_persistence", "idle_speed_threshold", "sleep_time_threshold"):
            setattr(new, name, getattr(space, name))
        self.space = new
        self.body: dict[int, Any] = {id(space.static_body): new.static_body}
        self.pushes: list[tuple[Any, Any, float]] = []
        for b in space.bodies:
            self._body(b, pymunk)
        for s in space.shapes:
            self._shape(s, pymunk)
        self.constraints = [self._constraint(c, pymunk) for c in space.constraints]
        new.add(*self.constraints)

    def _of(self, body: Any, pymunk: Any) -> Any:
        """The copy of ``body`` (a body only shapes or constraints use is copied then)."""
        found = self.body.get(id(body))
        return found if found is not None else self._body(body, pymunk, add=False)

    def _body(self, b: Any, pymunk: Any, add: bool = True) -> Any:
        kind = b.body_type
        if kind == pymunk.Body.DYNAMIC:
            c = pymunk.Body(b.mass, b.moment)
            c.center_of_gravity = b.center_of_gravity
            velocity, position = (body_function(b, "velocity_func"),
                                  body_function(b, "position_func"))
            if velocity is not None:
                c.velocity_func = velocity
            if position is not None:
                c.position_func = position
            if b.force != (0, 0) or b.torque != 0:
                self.pushes.append((c, b.force, b.torque))
        else:
            c = pymunk.Body(body_type=kind)
        # The angle first: pymunk turns a body about its centre of gravity, so an angle set
        # after the position would move the body's origin away from the original's.
        c.angle = b.angle
        c.position = b.position
        if kind != pymunk.Body.STATIC:
            c.velocity, c.angular_velocity = b.velocity, b.angular_velocity
        self.body[id(b)] = c
        if add and kind != pymunk.Body.STATIC:
            self.space.add(c)
        return c

    def _shape(self, s: Any, pymunk: Any) -> None:
        body = self._of(s.body, pymunk)
        if isinstance(s, pymunk.Circle):
            c = pymunk.Circle(body, s.radius, s.offset)
        elif isinstance(s, pymunk.Segment):
            c = pymunk.Segment(body, s.a, s.b, s.radius)
        elif isinstance(s, pymunk.Poly):
            c = pymunk.Poly(body, s.get_vertices(), radius=s.radius)
        else:
            raise Uncopyable(f"a shape of kind {type(s).__name__}")
        for name in ("friction", "elasticity", "surface_velocity", "sensor", "filter"):
            setattr(c, name, getattr(s, name))
        self.space.add(c)

    def _constraint(self, c: Any, pymunk: Any) -> Any:
        a, b = self._of(c.a, pymunk), self._of(c.b, pymunk)
        kind = next((k for k in MAKERS if isinstance(c, getattr(pymunk, k))), None)
        if kind is None:
            raise Uncopyable(f"a constraint of kind {type(c).__name__}")
        new = MAKERS[kind](pymunk, c, a, b)
        for name in ("max_force", "max_bias", "error_bias", "collide_bodies"):
            setattr(new, name, getattr(c, name))
        return new


def _spring(pymunk: Any, c: Any, a: Any, b: Any) -> Any:
    new = pymunk.DampedSpring(a, b, c.anchor_a, c.anchor_b, c.rest_length, c.stiffness,
                              c.damping)
    func = spring_function(c)  # pymunk 7.0.x's force_func has no getter
    if func is not None:
        new.force_func = func
    return new


def _rotary_spring(pymunk: Any, c: Any, a: Any, b: Any) -> Any:
    new = pymunk.DampedRotarySpring(a, b, c.rest_angle, c.stiffness, c.damping)
    func = spring_function(c)  # pymunk 7.0.x's torque_func has no getter
    if func is not None:
        new.torque_func = func
    return new


def _pin(pymunk: Any, c: Any, a: Any, b: Any) -> Any:
    new = pymunk.PinJoint(a, b, c.anchor_a, c.anchor_b)
    new.distance = c.distance
    return new


def _ratchet(pymunk: Any, c: Any, a: Any, b: Any) -> Any:
    new = pymunk.RatchetJoint(a, b, c.phase, c.ratchet)
    new.angle = c.angle
    return new


#: How each constraint kind is copied (by its pymunk class name).
MAKERS = {
    "PinJoint": _pin,
    "SlideJoint": lambda pm, c, a, b: pm.SlideJoint(a, b, c.anchor_a, c.anchor_b, c.min, c.max),
    "PivotJoint": lambda pm, c, a, b: pm.PivotJoint(a, b, c.anchor_a, c.anchor_b),
    "GrooveJoint": lambda pm, c, a, b: pm.GrooveJoint(a, b, c.groove_a, c.groove_b, c.anchor_b),
    "DampedSpring": _spring,
    "DampedRotarySpring": _rotary_spring,
    "RotaryLimitJoint": lambda pm, c, a, b: pm.RotaryLimitJoint(a, b, c.min, c.max),
    "RatchetJoint": _ratchet,
    "GearJoint": lambda pm, c, a, b: pm.GearJoint(a, b, c.phase, c.ratio),
    "SimpleMotor": lambda pm, c, a, b: pm.SimpleMotor(a, b, c.rate),
}
