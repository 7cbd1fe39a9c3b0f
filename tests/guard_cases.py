"""Spaces the step guard's own tests and ``benchmarks/guard_accuracy.py`` share: a program's
per-frame push in its several forms, a car driven by wheel torques, and a pendulum on a
joint (pixel units, y down, as pygame programs build them).

Each is built here in the manner of an outside pymunk program, not taken from pymunk's
examples."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

#: Gravity of the pixel spaces (px/s^2, y down).
G_PX = 900.0
#: How a program pushes a body once a frame, by name.
PUSHES = ("force", "torque", "world point", "local point", "velocity_func")


def pushed(how: str) -> tuple[Any, Any]:
    """A space with one free body the program pushes once a frame by ``how`` (one of
    :data:`PUSHES`), with gravity and its centre of gravity off its origin; and a function
    that sets the push (call it before each frame)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, G_PX)
    body = pymunk.Body(2.0, 300.0)
    body.center_of_gravity = (3.0, -4.0)
    body.position, body.angle = (100.0, 200.0), 0.3
    body.velocity, body.angular_velocity = (10.0, -5.0), 0.2
    space.add(body, pymunk.Circle(body, 10.0, (3.0, -4.0)))

    if how == "velocity_func":
        # A wind of the program's own that calls pymunk's update (which uses the body's
        # force, then clears it), and a force and torque set each frame.
        def wind(b: Any, gravity: Any, damping: float, dt: float) -> None:
            pymunk.Body.update_velocity(b, gravity + (120.0, -50.0), damping, dt)

        body.velocity_func = wind

    def push() -> None:
        if how in ("force", "velocity_func"):
            body.force = (40.0, -30.0)
        if how in ("torque", "velocity_func"):
            body.torque = 500.0
        if how == "world point":
            body.apply_force_at_world_point((40.0, -30.0), body.position + (20.0, 5.0))
        if how == "local point":
            body.apply_force_at_local_point((40.0, -30.0), (-15.0, 8.0))

    return space, push


@dataclass
class Car:
    """A car (pixel units, y down): a chassis on two wheels, each held by a groove and a
    spring (its suspension), driven by a torque on each wheel set once a frame."""

    space: Any
    chassis: Any
    wheels: tuple[Any, Any]
    torque: float

    def drive(self) -> None:
        """The program's push of one frame: a torque on each wheel."""
        for w in self.wheels:
            w.torque = self.torque


def car(torque: float = 3e4) -> Car:
    """The car at rest on a long flat road."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, G_PX)
    road = pymunk.Segment(space.static_body, (-1000.0, 300.0), (20000.0, 300.0), 5.0)
    road.friction = 1.0
    space.add(road)
    chassis = pymunk.Body(10.0, pymunk.moment_for_box(10.0, (120.0, 30.0)))
    chassis.position = (100.0, 220.0)
    box = pymunk.Poly.create_box(chassis, (120.0, 30.0))
    box.friction = 0.5
    space.add(chassis, box)
    wheels = []
    for x in (-45.0, 45.0):
        wheel = pymunk.Body(2.0, pymunk.moment_for_circle(2.0, 0.0, 20.0))
        wheel.position = (100.0 + x, 275.0)
        tyre = pymunk.Circle(wheel, 20.0)
        tyre.friction = 1.5
        groove = pymunk.GrooveJoint(chassis, wheel, (x, 10.0), (x, 60.0), (0.0, 0.0))
        spring = pymunk.DampedSpring(chassis, wheel, (x, 0.0), (0.0, 0.0), 55.0, 3000.0, 60.0)
        for c in (groove, spring):
            c.collide_bodies = False
        space.add(wheel, tyre, groove, spring)
        wheels.append(wheel)
    return Car(space, chassis, (wheels[0], wheels[1]), torque)


def pendulum(joint: str = "PinJoint", length: float = 200.0, mass: float = 1.0,
             angle: float = 0.0, gravity: float = G_PX) -> Any:
    """A bob (radius 10) on a joint to the static body at (300, 100), released from rest at
    ``angle`` (rad) below the horizontal: ``joint`` 'PinJoint' (length ``length``),
    'PivotJoint' (a bar of that length turning about its end) or 'SlideJoint' (taut)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, gravity)
    anchor = (300.0, 100.0)
    end = (anchor[0] + length * math.cos(angle), anchor[1] + length * math.sin(angle))
    if joint == "PivotJoint":
        body = pymunk.Body(mass, pymunk.moment_for_segment(mass, (-length / 2, 0),
                                                           (length / 2, 0), 5.0))
        body.center_of_gravity = (length / 2, 0.0)
        body.position, body.angle = anchor, angle
        shape = pymunk.Segment(body, (0, 0), (length, 0), 5.0)
        c = pymunk.PivotJoint(space.static_body, body, anchor, (0.0, 0.0))
    else:
        body = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0.0, 10.0))
        body.position = end
        shape = pymunk.Circle(body, 10.0)
        c = (pymunk.PinJoint(space.static_body, body, anchor, (0.0, 0.0)) if joint == "PinJoint"
             else pymunk.SlideJoint(space.static_body, body, anchor, (0.0, 0.0), 0.0, length))
    space.add(body, shape, c)
    return space


def every_constraint() -> Any:
    """One of each pymunk constraint kind, in this order: a bob on a PinJoint, a slack
    SlideJoint that snaps taut, a bar on a PivotJoint, a block in a sloping GrooveJoint, a
    bob on a DampedSpring, a wheel on a DampedRotarySpring, a bar against a
    RotaryLimitJoint, a wheel turning a RatchetJoint, a GearJoint between two wheels, and a
    SimpleMotor; each part 300 px from the next, so that nothing touches (pixel units, y
    down). Wheels and bars turn on pivots to the static body (added after the ten)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, G_PX)
    static = space.static_body
    pivots = []

    def bob(x: float, y: float, radius: float = 10.0) -> Any:
        b = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0.0, radius))
        b.position = (x, y)
        space.add(b, pymunk.Circle(b, radius))
        return b

    def bar(x: float, y: float) -> Any:
        b = pymunk.Body(1.0, pymunk.moment_for_segment(1.0, (-50, 0), (50, 0), 4.0))
        b.center_of_gravity = (50.0, 0.0)
        b.position = (x, y)
        space.add(b, pymunk.Segment(b, (0, 0), (100, 0), 4.0))
        pivots.append(pymunk.PivotJoint(static, b, (x, y)))
        return b

    def wheel(x: float, y: float, spin: float = 0.0) -> Any:
        b = bob(x, y, 20.0)
        b.angular_velocity = spin
        pivots.append(pymunk.PivotJoint(static, b, (x, y)))
        return b

    pin = pymunk.PinJoint(static, bob(200.0, 100.0), (100.0, 100.0), (0.0, 0.0))
    slide = pymunk.SlideJoint(static, bob(400.0, 200.0), (400.0, 100.0), (0.0, 0.0), 0.0, 160.0)
    pivot = pymunk.PivotJoint(static, _bar(space, 700.0), (700.0, 100.0))
    block = bob(1000.0, 100.0)
    groove = pymunk.GrooveJoint(static, block, (1000.0, 100.0), (1200.0, 180.0), (0.0, 0.0))
    spring = pymunk.DampedSpring(static, bob(1300.0, 150.0), (1300.0, 100.0), (0.0, 0.0),
                                 30.0, 50.0, 0.0)
    turned = wheel(1600.0, 100.0, 3.0)
    rotary = pymunk.DampedRotarySpring(static, turned, 0.0, 2e5, 0.0)
    limit = pymunk.RotaryLimitJoint(static, bar(1900.0, 100.0), -0.5, 0.5)
    ratchet = pymunk.RatchetJoint(static, wheel(2200.0, 100.0, 4.0), 0.0, math.pi / 4)
    gear = pymunk.GearJoint(wheel(2500.0, 100.0, 2.0), wheel(2560.0, 100.0), 0.0, 2.0)
    motor = pymunk.SimpleMotor(static, wheel(2900.0, 100.0), 5.0)
    space.add(pin, slide, pivot, groove, spring, rotary, limit, ratchet, gear, motor, *pivots)
    return space


def _bar(space: Any, x: float) -> Any:
    """A 100 px bar with its origin at (x, 100) and its centre of gravity 50 px along it,
    level (for the PivotJoint of :func:`every_constraint`)."""
    import pymunk

    b = pymunk.Body(1.0, pymunk.moment_for_segment(1.0, (-50, 0), (50, 0), 4.0))
    b.center_of_gravity = (50.0, 0.0)
    b.position = (x, 100.0)
    space.add(b, pymunk.Segment(b, (0, 0), (100, 0), 4.0))
    return b
