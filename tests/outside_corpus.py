"""Programs written here the way pymunk users write them, as a corpus for ``dumbbell.spaces``
(issue 28's tests): a pool table, a car, a ragdoll, a cloth, a gas of 10,000 particles, a
game whose collision callbacks remove bodies and scale velocities, a program that adds and
removes bodies and joints every few frames, a planet with a ``velocity_func`` field (its
potential declared and not), a conveyor with a kinematic lift, a damped chain of pins, a
hammer whose centre of gravity pymunk computes from its shapes, a program stepped by its
measured frame time, a ship steered by per-frame forces (with and without sub-steps).

None of them comes from ``pymunk.examples`` or anywhere else. Each is written for a window
library (pygame, drawing with ``pymunk.pygame_util`` or by hand; pyglet; arcade; kivy) or
none (a script), in that library's units and orientation: pixels and y down for pygame,
pixels or metres and y up for the others. Nothing is drawn: a program's drawing calls go to
the stand-ins of ``tests/outside_tape.py`` or to pygame's dummy display.

What a program does for the tests, and only this: it hands its space to the tape once built
(``tape.start``) and wraps each thing it does to its bodies between steps, or inside a
callback, in ``with tape.act(...)`` (see ``tests/outside_tape.py``); ``tape.frame()`` after
each frame it draws, and ``tape.running`` as its main loop's condition where the program
owns its loop. ``python -m tests.outside_corpus [NAME ...]`` runs them and prints a line
each.
"""

from __future__ import annotations

import itertools
import math
import random
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .outside_tape import Tape, window

# --------------------------------------------------------------------------------------
# The programs. Each takes the tape and builds, runs and drives its space as its window
# library would; `tape.running` is its main loop's condition where the program owns it.


def pool_table(tape: Tape) -> None:
    """A pool table seen from above, pygame drawing with pygame.draw (pixels, y down, no
    gravity). Cloth friction by the usual trick: each ball pinned to the static body by a
    PivotJoint with max_bias 0 and a finite max_force (its sliding friction) and a
    GearJoint likewise (its spin's). Six pocket sensors; a ball that falls in is removed
    from a post-step callback, as pymunk requires; the cue ball comes back on its spot."""
    import pygame
    import pymunk

    BALL, POCKET = 1, 2
    screen = pygame.display.set_mode((1100, 600))
    clock = pygame.time.Clock()
    space = pymunk.Space()
    left, right, top, bottom = 50, 1050, 50, 550
    r, mass, pocket_r = 14, 0.17, 24
    corners = [(left, top), (right, top), (left, bottom), (right, bottom),
               ((left + right) / 2, top), ((left + right) / 2, bottom)]
    rails = [((left + 30, top), ((left + right) / 2 - 30, top)),
             (((left + right) / 2 + 30, top), (right - 30, top)),
             ((left + 30, bottom), ((left + right) / 2 - 30, bottom)),
             (((left + right) / 2 + 30, bottom), (right - 30, bottom)),
             ((left, top + 30), (left, bottom - 30)), ((right, top + 30), (right, bottom - 30))]
    for a, b in rails:
        cushion = pymunk.Segment(space.static_body, a, b, 6)
        cushion.elasticity, cushion.friction = 0.8, 0.2
        space.add(cushion)
    for c in corners:
        hole = pymunk.Circle(space.static_body, pocket_r, c)
        hole.sensor, hole.collision_type = True, POCKET
        space.add(hole)

    def new_ball(x: float, y: float) -> pymunk.Body:
        ball = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0, r))
        ball.position = (x, y)
        shape = pymunk.Circle(ball, r)
        shape.elasticity, shape.friction, shape.collision_type = 0.95, 0.05, BALL
        slide = pymunk.PivotJoint(space.static_body, ball, (0, 0), (0, 0))
        slide.max_bias, slide.max_force = 0, mass * 0.25 * 981  # sliding friction
        roll = pymunk.GearJoint(space.static_body, ball, 0.0, 1.0)
        roll.max_bias, roll.max_force = 0, 40.0
        space.add(ball, shape, slide, roll)
        return ball

    cue_spot = (300.0, 300.0)
    cue = new_ball(*cue_spot)
    balls = [cue]
    for row in range(5):
        for k in range(row + 1):
            balls.append(new_ball(760 + row * 2 * r * 0.88, 300 + (k - row / 2) * 2.02 * r))
    tape.start(space)
    state = {"cue": cue, "respot": None, "frame": 0}

    def drop(space: pymunk.Space, key: Any, ball: pymunk.Body) -> None:
        with tape.act(space, ball, where="callback"):
            space.remove(ball, *ball.shapes, *ball.constraints)
        balls.remove(ball)
        if ball is state["cue"]:
            state["cue"], state["respot"] = None, state["frame"] + 30

    def fell_in(arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        ball = arbiter.shapes[0].body
        space.add_post_step_callback(drop, ball, ball)

    space.on_collision(BALL, POCKET, begin=fell_in)

    def strike(target: tuple[float, float], speed: float) -> None:
        ball = state["cue"]
        aim = pymunk.Vec2d(*target) - ball.position
        with tape.act(space, ball):
            ball.apply_impulse_at_local_point(aim.normalized() * mass * speed, (0, 3))

    while tape.running:
        frame = state["frame"]
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        if frame == 0:
            strike((760, 301), 1900)
        if frame == state["respot"]:
            with tape.act(space):
                state["cue"] = new_ball(*cue_spot)
                balls.append(state["cue"])
        if frame % 50 == 40 and state["cue"] is not None and len(balls) > 1:
            # the player aims at the ball nearest a pocket
            target = min(balls[1:], key=lambda b: min(b.position.get_distance(c)
                                                      for c in corners))
            strike(tuple(target.position), 1400)
        for _ in range(2):
            space.step(1 / 120)
        screen.fill((10, 90, 30))
        for ball in balls:
            pygame.draw.circle(screen, (240, 240, 240), (int(ball.position.x),
                                                          int(ball.position.y)), r)
        pygame.display.flip()
        clock.tick(60)
        state["frame"] += 1
        tape.frame()


def car(tape: Tape) -> None:
    """An arcade game: a car on a long road (SI units, y up), its chassis on two wheels
    held by GrooveJoints and DampedSprings, driven by wheel torques set before every step
    (pymunk clears them after each), an antenna on a pivot and a rotary spring; the player
    fires a nitro impulse and pulls the handbrake."""
    import arcade
    import pymunk

    class Game(arcade.Window):
        def __init__(self) -> None:
            super().__init__(1280, 720, "Hill car")
            self.space = space = pymunk.Space()
            space.gravity = (0.0, -9.81)
            road = [(-20, 0), (30, 0), (38, 0.6), (42, 0.6), (46, 0), (300, 0)]
            for a, b in itertools.pairwise(road):
                seg = pymunk.Segment(space.static_body, a, b, 0.05)
                seg.friction = 1.0
                space.add(seg)
            nocollide = pymunk.ShapeFilter(group=1)
            self.chassis = chassis = pymunk.Body(300, pymunk.moment_for_box(300, (2.4, 0.5)))
            chassis.position = (0.0, 1.0)
            body_shape = pymunk.Poly.create_box(chassis, (2.4, 0.5))
            body_shape.filter, body_shape.friction = nocollide, 0.5
            space.add(chassis, body_shape)
            self.wheels = []
            for x in (-0.9, 0.9):
                wheel = pymunk.Body(20, pymunk.moment_for_circle(20, 0, 0.35))
                wheel.position = (x, 0.42)
                tyre = pymunk.Circle(wheel, 0.35)
                tyre.filter, tyre.friction = nocollide, 1.5
                groove = pymunk.GrooveJoint(chassis, wheel, (x, -0.1), (x, -0.8), (0, 0))
                spring = pymunk.DampedSpring(chassis, wheel, (x, 0.0), (0, 0), 0.7, 30000, 2000)
                space.add(wheel, tyre, groove, spring)
                self.wheels.append(wheel)
            antenna = pymunk.Body(0.3, pymunk.moment_for_poly(
                0.3, [(-0.015, 0), (0.015, 0), (0.015, 0.6), (-0.015, 0.6)]))
            verts = [(-0.015, 0), (0.015, 0), (0.015, 0.6), (-0.015, 0.6)]
            antenna.center_of_gravity = (0.0, 0.3)
            antenna.position = chassis.local_to_world((-1.0, 0.25))
            rod = pymunk.Poly(antenna, verts)
            rod.filter = nocollide
            space.add(antenna, rod,
                      pymunk.PivotJoint(chassis, antenna, antenna.position),
                      pymunk.DampedRotarySpring(chassis, antenna, 0.0, 20.0, 0.5))
            self.frame = 0
            tape.start(space)

        def on_update(self, delta_time: float) -> None:
            if self.frame == 30:  # nitro
                with tape.act(self.space, self.chassis):
                    self.chassis.apply_impulse_at_local_point((1500.0, 0.0), (0.0, 0.1))
            if self.frame == 60:  # handbrake: the wheels stop turning
                with tape.act(self.space, *self.wheels):
                    for wheel in self.wheels:
                        wheel.angular_velocity = 0.0
            throttle = 400.0 if self.frame < 60 else 0.0
            for _ in range(4):
                for wheel in self.wheels:
                    wheel.torque = -throttle
                self.chassis.torque = 2 * throttle
                self.space.step(delta_time / 4)
            self.frame += 1

        def on_draw(self) -> None:
            self.clear()
            tape.frame()

    Game()
    arcade.run()


def ragdoll(tape: Tape) -> None:
    """A ragdoll thrown down some stairs, pygame with pymunk.pygame_util (pixels, y down,
    gravity 900 px/s^2 down): limbs are bodies whose origin is at their upper joint and
    whose centre of gravity is half a limb away, held by PivotJoints and kept in range by
    RotaryLimitJoints; the player throws it, kicks a shin and yanks the head."""
    import pygame
    import pymunk
    import pymunk.pygame_util

    screen = pygame.display.set_mode((1000, 650))
    draw_options = pymunk.pygame_util.DrawOptions(screen)
    space = pymunk.Space()
    space.gravity = (0, 900)
    space.iterations = 20
    floor = pymunk.Segment(space.static_body, (0, 600), (1000, 600), 5)
    floor.friction = 0.9
    space.add(floor)
    for k in range(4):  # stairs down to the right
        x0, y = 300 + 80 * k, 360 + 60 * k
        step = pymunk.Poly(space.static_body, [(x0, y), (1000, y), (1000, y + 60), (x0, y + 60)])
        step.friction = 0.9
        space.add(step)
    me = pymunk.ShapeFilter(group=1)

    def part(mass: float, verts: list[tuple[float, float]], at: tuple[float, float]
             ) -> pymunk.Body:
        body = pymunk.Body(mass, pymunk.moment_for_poly(mass, verts))
        shape = pymunk.Poly(body, verts)
        body.center_of_gravity = shape.center_of_gravity
        body.position = at
        shape.filter, shape.friction = me, 0.8
        space.add(body, shape)
        return body

    def joint(a: pymunk.Body, b: pymunk.Body, at: tuple[float, float], lo: float,
              hi: float) -> None:
        space.add(pymunk.PivotJoint(a, b, at), pymunk.RotaryLimitJoint(a, b, lo, hi))

    def limb(parent: pymunk.Body, at: tuple[float, float], length: float, width: float,
             mass: float, lo: float, hi: float) -> pymunk.Body:
        w = width / 2
        body = part(mass, [(-w, 0), (w, 0), (w, length), (-w, length)], at)
        joint(parent, body, at, lo, hi)
        return body

    x, y = 200, 150
    torso = part(10, [(-15, -30), (15, -30), (15, 30), (-15, 30)], (x, y))
    head = pymunk.Body(3, pymunk.moment_for_circle(3, 0, 14))
    head.position = (x, y - 48)
    skull = pymunk.Circle(head, 14)
    skull.filter, skull.friction = me, 0.8
    space.add(head, skull)
    joint(torso, head, (x, y - 32), -0.6, 0.6)
    arms, legs = [], []
    for side in (-1, 1):
        upper = limb(torso, (x + side * 17, y - 26), 32, 9, 1.5, -2.5, 2.5)
        lower = limb(upper, (x + side * 17, y + 6), 30, 8, 1.0, -0.1, 2.4)
        thigh = limb(torso, (x + side * 8, y + 30), 40, 12, 3.0, -1.5, 1.5)
        shin = limb(thigh, (x + side * 8, y + 70), 38, 10, 2.0, -2.4, 0.1)
        arms += [upper, lower]
        legs += [thigh, shin]
    tape.start(space)
    for frame in range(tape.frames):
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        if frame == 10:  # thrown towards the stairs
            with tape.act(space, torso):
                torso.apply_impulse_at_world_point((3000, -2500), torso.position + (0, -20))
        if frame == 40:  # kicked in the shin
            with tape.act(space, legs[1]):
                legs[1].apply_impulse_at_local_point((-300, -200), (0, 30))
        if frame == 70:  # the head yanked up by the mouse
            with tape.act(space, head):
                head.velocity = (0, -400)
        space.step(1 / 60)
        screen.fill((255, 255, 255))
        space.debug_draw(draw_options)
        pygame.display.flip()
        tape.frame()


def cloth(tape: Tape) -> None:
    """A curtain in pyglet (pixels, y up, gravity 900 px/s^2 down): a 14 x 10 grid of small
    bodies joined by DampedSprings, SlideJoints across each cell, the top row pinned by
    PivotJoints; a wind (Body.force set before every step), a ball thrown through it, a
    tear (springs removed) and a corner dragged by the mouse."""
    import pyglet
    import pymunk

    window = pyglet.window.Window(width=900, height=700)
    space = pymunk.Space()
    space.gravity = (0, -900)
    cols, rows, gap = 14, 10, 20.0
    mass, radius = 0.5, 3.0
    cloth_filter = pymunk.ShapeFilter(group=2)
    grid: list[list[pymunk.Body]] = []
    for i in range(rows):
        row = []
        for j in range(cols):
            b = pymunk.Body(mass, pymunk.moment_for_circle(mass, 0, radius))
            b.position = (310 + j * gap, 560 - i * gap)
            dot = pymunk.Circle(b, radius)
            dot.filter = cloth_filter
            space.add(b, dot)
            row.append(b)
        grid.append(row)
    springs = {}
    for i in range(rows):
        for j in range(cols):
            b = grid[i][j]
            if i == 0:
                space.add(pymunk.PivotJoint(space.static_body, b, b.position))
            if j + 1 < cols:
                s = pymunk.DampedSpring(b, grid[i][j + 1], (0, 0), (0, 0), gap, 1000, 1.0)
                springs[(i, j, "h")] = s
                space.add(s)
            if i + 1 < rows:
                s = pymunk.DampedSpring(b, grid[i + 1][j], (0, 0), (0, 0), gap, 1000, 1.0)
                springs[(i, j, "v")] = s
                space.add(s)
            if i + 1 < rows and j + 1 < cols:
                space.add(pymunk.SlideJoint(b, grid[i + 1][j + 1], (0, 0), (0, 0), 0,
                                            gap * math.sqrt(2) * 1.05))
    tape.start(space)
    clock = {"t": 0.0, "frame": 0}
    everyone = [b for row in grid for b in row]

    def update(dt: float) -> None:
        frame = clock["frame"]
        if frame == 15:  # a ball thrown at the curtain
            ball = pymunk.Body(5, pymunk.moment_for_circle(5, 0, 25))
            ball.position, ball.velocity = (150, 400), (700, 150)
            with tape.act(space, ball):
                space.add(ball, pymunk.Circle(ball, 25))
        if frame == 35:  # torn in the middle
            with tape.act(space, *everyone):
                for j in range(5, 9):
                    space.remove(springs[(5, j, "v")])
        if frame == 45:  # the bottom-left corner dragged by the mouse
            corner = grid[-1][0]
            with tape.act(space):
                corner.position += (-30, 10)
                corner.velocity = (0, 0)
        for _ in range(3):
            wind = 120 * math.sin(2.0 * clock["t"])
            for b in everyone:
                b.force = (wind, 0)
            space.step(dt / 3)
            clock["t"] += dt / 3
        clock["frame"] += 1
        tape.frame()

    @window.event
    def on_draw() -> None:
        window.clear()

    pyglet.clock.schedule_interval(update, 1 / 60)
    pyglet.app.run()


def gas(tape: Tape, n_side: int = 100) -> None:
    """A kivy app: a gas of n_side^2 (10,000) elastic particles in a box (pixels, y up, no
    gravity); a thermostat scales every velocity by 1.02, and some particles are let out
    and others let in."""
    import pymunk
    from kivy.app import App
    from kivy.clock import Clock
    from kivy.uix.widget import Widget

    class Gas(Widget):
        def __init__(self, **kw: Any) -> None:
            super().__init__(**kw)
            self.space = space = pymunk.Space()
            rng = random.Random(28)
            size = 10.0 * n_side
            for a, b in (((0, 0), (size, 0)), ((size, 0), (size, size)),
                         ((size, size), (0, size)), ((0, size), (0, 0))):
                wall = pymunk.Segment(space.static_body, a, b, 2)
                wall.elasticity = 1.0
                space.add(wall)
            self.particles = []
            for i in range(n_side):
                for j in range(n_side):
                    p = self.particle((5 + 10 * i, 5 + 10 * j), rng)
                    space.add(p, *p.shapes)
                    self.particles.append(p)
            self.rng, self.frame = rng, 0
            tape.start(space)

        def particle(self, at: tuple[float, float], rng: random.Random) -> pymunk.Body:
            p = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 2.0))
            p.position = at
            p.velocity = (rng.gauss(0, 150), rng.gauss(0, 150))
            dot = pymunk.Circle(p, 2.0)
            dot.elasticity, dot.friction = 1.0, 0.0
            return p

        def update(self, dt: float) -> None:
            if self.frame == 1:  # the thermostat
                with tape.act(self.space):
                    for p in self.particles:
                        p.velocity *= 1.02
            if self.frame == 2:  # the rightmost particles let out, as many let in
                out = sorted(self.particles, key=lambda p: -p.position.x)[:25]
                new = [self.particle((10.0 + 10 * k, 10.0), self.rng) for k in range(25)]
                with tape.act(self.space, *out, *new):
                    for p in out:
                        self.space.remove(p, *p.shapes)
                        self.particles.remove(p)
                    for p in new:
                        self.space.add(p, *p.shapes)
                        self.particles.append(p)
            self.space.step(dt)
            self.frame += 1
            tape.frame()

    class GasApp(App):
        def build(self) -> Gas:
            widget = Gas()
            Clock.schedule_interval(widget.update, 1 / 60)
            return widget

    GasApp().run()


def bumpers(tape: Tape) -> None:
    """An arcade game (pixels, y up, gravity 600 px/s^2 down): balls dropped every 20 frames
    onto pegs that kick them on first touch (a post_solve callback scaling the ball's
    velocity by 1.2), crates knocked out when a ball hits them (removed from a post-step
    callback, as pymunk requires) and a mud strip that halves a ball's velocity
    (post_solve); balls that leave the screen are removed."""
    import arcade
    import pymunk

    BALL, PEG, CRATE, MUD = 1, 2, 3, 4

    class Bumpers(arcade.Window):
        def __init__(self) -> None:
            super().__init__(800, 700, "Bumpers")
            self.space = space = pymunk.Space()
            space.gravity = (0, -600)
            for a, b in (((40, 40), (40, 680)), ((760, 40), (760, 680))):
                wall = pymunk.Segment(space.static_body, a, b, 4)
                wall.elasticity = 0.6
                space.add(wall)
            mud = pymunk.Segment(space.static_body, (40, 60), (500, 30), 6)
            mud.collision_type, mud.friction = MUD, 0.8
            space.add(mud)
            for row in range(4):
                for k in range(6):
                    peg = pymunk.Circle(space.static_body, 8,
                                        (110 + 110 * k + 55 * (row % 2), 560 - 80 * row))
                    peg.collision_type, peg.elasticity = PEG, 0.7
                    space.add(peg)
            shelf = pymunk.Segment(space.static_body, (520, 150), (740, 150), 4)
            shelf.friction = 0.9
            space.add(shelf)
            self.crates = []
            for k in range(6):
                crate = pymunk.Body(2, pymunk.moment_for_box(2, (30, 30)))
                crate.position = (545 + 36 * k, 170)
                box = pymunk.Poly.create_box(crate, (30, 30))
                box.collision_type, box.friction = CRATE, 0.9
                space.add(crate, box)
                self.crates.append(crate)
            self.balls = []
            self.rng = random.Random(3)
            self.frame = 0
            space.on_collision(BALL, PEG, post_solve=self.kick)
            space.on_collision(BALL, CRATE, begin=self.knock)
            space.on_collision(BALL, MUD, post_solve=self.slow)
            tape.start(space)

        def kick(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
            if arbiter.is_first_contact:
                ball = arbiter.shapes[0].body
                with tape.act(space, ball, where="callback"):
                    ball.velocity *= 1.2

        def slow(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
            ball = arbiter.shapes[0].body
            with tape.act(space, ball, where="callback"):
                ball.velocity *= 0.5

        def knock(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
            crate = arbiter.shapes[1].body
            space.add_post_step_callback(self.remove_crate, crate, crate)

        def remove_crate(self, space: pymunk.Space, key: Any, crate: pymunk.Body) -> None:
            with tape.act(space, crate, where="callback"):
                space.remove(crate, *crate.shapes)
            self.crates.remove(crate)

        def on_update(self, delta_time: float) -> None:
            if self.frame % 20 == 0:
                ball = pymunk.Body(1, pymunk.moment_for_circle(1, 0, 10))
                ball.position = (self.rng.uniform(100, 700), 660)
                ball.velocity = (self.rng.uniform(-150, 150), 0)
                shape = pymunk.Circle(ball, 10)
                shape.collision_type, shape.elasticity, shape.friction = BALL, 0.6, 0.5
                with tape.act(self.space, ball):
                    self.space.add(ball, shape)
                self.balls.append(ball)
            gone = [b for b in self.balls if b.position.y < 0]
            if gone:
                with tape.act(self.space, *gone):
                    for b in gone:
                        self.space.remove(b, *b.shapes)
                        self.balls.remove(b)
            self.space.step(delta_time)
            self.frame += 1

        def on_draw(self) -> None:
            self.clear()
            tape.frame()

    Bumpers()
    arcade.run()


def spawner(tape: Tape) -> None:
    """pygame with pymunk.pygame_util (pixels, y down, gravity 900): every few frames a ball
    is added, the oldest removed with its joints, a joint added between two balls (a pin,
    a stretched spring, a slide, or a friction pivot to the static body with max_bias 0 and
    a finite max_force), a joint removed, a ball clicked."""
    import pygame
    import pymunk
    import pymunk.pygame_util

    screen = pygame.display.set_mode((800, 600))
    options = pymunk.pygame_util.DrawOptions(screen)
    space = pymunk.Space()
    space.gravity = (0, 900)
    for a, b in (((20, 580), (780, 580)), ((20, 580), (20, 20)), ((780, 580), (780, 20))):
        wall = pymunk.Segment(space.static_body, a, b, 5)
        wall.friction, wall.elasticity = 0.7, 0.5
        space.add(wall)
    rng = random.Random(7)
    balls: list[pymunk.Body] = []
    joints: list[pymunk.Constraint] = []

    def ball() -> tuple[pymunk.Body, pymunk.Circle]:
        b = pymunk.Body(1, pymunk.moment_for_circle(1, 0, 12))
        b.position = (rng.uniform(60, 740), rng.uniform(60, 200))
        b.velocity = (rng.uniform(-200, 200), rng.uniform(-100, 100))
        shape = pymunk.Circle(b, 12)
        shape.friction, shape.elasticity = 0.6, 0.5
        return b, shape

    for _ in range(6):
        b, shape = ball()
        space.add(b, shape)
        balls.append(b)
    tape.start(space)
    kinds = ("pin", "spring", "slide", "friction")
    for frame in range(tape.frames):
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        if frame % 6 == 0:
            b, shape = ball()
            with tape.act(space, b):
                space.add(b, shape)
            balls.append(b)
        if frame % 10 == 5 and len(balls) > 4:
            old = balls.pop(0)
            gone = [c for c in joints if old in (c.a, c.b)]
            with tape.act(space, old):
                space.remove(old, *old.shapes, *gone)
            joints[:] = [c for c in joints if c not in gone]
        if frame % 9 == 3 and len(balls) >= 2:
            a, b = rng.sample(balls, 2)
            kind = kinds[(frame // 9) % len(kinds)]
            d = a.position.get_distance(b.position)
            if kind == "pin":
                c = pymunk.PinJoint(a, b)
            elif kind == "spring":
                c = pymunk.DampedSpring(a, b, (0, 0), (0, 0), 0.6 * d, 40.0, 0.5)
            elif kind == "slide":
                c = pymunk.SlideJoint(a, b, (0, 0), (0, 0), 0.5 * d, 1.2 * d)
            else:
                c = pymunk.PivotJoint(space.static_body, a, (0, 0), (0, 0))
                c.max_bias, c.max_force = 0, 400
            with tape.act(space, a, b):
                space.add(c)
            joints.append(c)
        if frame % 13 == 8 and joints:
            c = joints.pop(rng.randrange(len(joints)))
            with tape.act(space, *(b for b in (c.a, c.b) if b is not space.static_body)):
                space.remove(c)
        if frame % 25 == 12:
            b = rng.choice(balls)
            with tape.act(space, b):
                b.apply_impulse_at_local_point((rng.uniform(-300, 300), -400))
        space.step(1 / 60)
        screen.fill((255, 255, 255))
        space.debug_draw(options)
        pygame.display.flip()
        tape.frame()


GM = 4.0e6  # px^3/s^2


def planet_gravity(body: Any, gravity: Any, damping: float, dt: float) -> None:
    """The sun's pull, -GM r / |r|^3 towards the origin, a velocity_func."""
    import pymunk

    p = body.position
    r2 = p.x * p.x + p.y * p.y
    g = -GM / (r2 * math.sqrt(r2)) * p
    pymunk.Body.update_velocity(body, g, damping, dt)


def sun_potential(x: Any, y: Any, m: Any) -> Any:
    """The potential of the sun's pull, -GM m / r (numpy arrays or floats)."""
    import numpy as np

    return -GM * m / np.hypot(x, y)


def planet(tape: Tape, declare: bool = False) -> None:
    """A script (no window, y up, pixels, no space gravity): 30 moons on circular orbits
    about a sun, pulled by a velocity_func; a rocket burn on one, another launched. With
    ``declare`` the user declares the field's potential -GM m / r to the ledger."""
    import pymunk

    space = pymunk.Space()
    sun = pymunk.Circle(space.static_body, 30)
    space.add(sun)
    rng = random.Random(11)
    moons = []

    def moon(r: float, phase: float) -> pymunk.Body:
        b = pymunk.Body(1, pymunk.moment_for_circle(1, 0, 5))
        b.position = (r * math.cos(phase), r * math.sin(phase))
        v = math.sqrt(GM / r)
        b.velocity = (-v * math.sin(phase), v * math.cos(phase))
        b.angular_velocity = rng.uniform(-2, 2)
        b.velocity_func = planet_gravity
        return b

    for _ in range(30):
        b = moon(rng.uniform(80, 300), rng.uniform(0, 2 * math.pi))
        space.add(b, pymunk.Circle(b, 5))
        moons.append(b)
    tape.start(space, fields=((planet_gravity, sun_potential),), declare=declare)
    for frame in range(tape.frames):
        if frame == 15:  # a rocket burn
            with tape.act(space, moons[0]):
                moons[0].apply_impulse_at_local_point((0, 40))
        if frame == 30:  # a launch
            b = moon(200, 0.5)
            with tape.act(space, b):
                space.add(b, pymunk.Circle(b, 5))
            moons.append(b)
        space.step(1 / 60)
        tape.frame()


def conveyor(tape: Tape) -> None:
    """pygame drawing by hand with y flipped (SI, y up, gravity 9.81 m/s^2 down): crates
    dropped on a conveyor belt (a static segment with a surface_velocity) carrying them to
    a lift (a kinematic platform the program sends up and down); crates delivered onto the
    lift, or fallen off the screen, are removed."""
    import pygame
    import pymunk

    screen = pygame.display.set_mode((1000, 600))
    space = pymunk.Space()
    space.gravity = (0, -9.81)

    def to_screen(p: Any) -> tuple[int, int]:
        return int(100 * p.x), int(600 - 100 * p.y)

    belt = pymunk.Segment(space.static_body, (0.5, 2.0), (6.0, 2.0), 0.05)
    belt.friction, belt.surface_velocity = 0.9, (2.5, 0)
    space.add(belt)
    lift = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    lift.position = (7.0, 1.5)
    deck = pymunk.Poly.create_box(lift, (1.2, 0.1))
    deck.friction = 0.6
    space.add(lift, deck)
    crates: list[pymunk.Body] = []
    tape.start(space)
    for frame in range(tape.frames):
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        if frame % 30 == 0:
            crate = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.3, 0.3)))
            crate.position = (3.0, 2.3)
            box = pymunk.Poly.create_box(crate, (0.3, 0.3))
            box.friction = 0.9
            with tape.act(space, crate):
                space.add(crate, box)
            crates.append(crate)
        if frame % 60 == 0:
            with tape.act(space, lift):
                lift.velocity = (0, 0.6 if (frame // 60) % 2 == 0 else -0.6)
        gone = [c for c in crates if c.position.y < -1.0 or c.position.x > 6.6]  # delivered
        if gone:
            with tape.act(space, *gone):
                for c in gone:
                    space.remove(c, *c.shapes)
                    crates.remove(c)
        space.step(1 / 60)
        screen.fill((255, 255, 255))
        for c in crates:
            for s in c.shapes:
                pygame.draw.polygon(screen, (120, 80, 40),
                                    [to_screen(c.local_to_world(v)) for v in s.get_vertices()])
        pygame.display.flip()
        tape.frame()


def chain(tape: Tape) -> None:
    """pygame with pymunk.pygame_util (pixels, y down, gravity 900): a chain of six bobs on
    PinJoints released from horizontal in a damped space (space.damping = 0.8), its last
    link a hammer head whose centre of gravity is off its origin; the user flicks the last
    bob, cuts a link and catches a bob."""
    import pygame
    import pymunk
    import pymunk.pygame_util

    screen = pygame.display.set_mode((900, 700))
    options = pymunk.pygame_util.DrawOptions(screen)
    space = pymunk.Space()
    space.gravity = (0, 900)
    space.damping = 0.8
    anchor = (300, 100)
    prev, prev_at = space.static_body, anchor
    links = []
    for k in range(6):
        if k < 5:
            bob = pymunk.Body(1, pymunk.moment_for_circle(1, 0, 10))
            space.add(bob, pymunk.Circle(bob, 10))
        else:
            verts = [(-5, -8), (30, -8), (30, 8), (-5, 8)]
            bob = pymunk.Body(3, pymunk.moment_for_poly(3, verts))
            head = pymunk.Poly(bob, verts)
            bob.center_of_gravity = head.center_of_gravity
            space.add(bob, head)
        bob.position = (anchor[0] + 50 * (k + 1), anchor[1])
        pin = pymunk.PinJoint(prev, bob, prev_at if prev is space.static_body else (0, 0),
                              (0, 0))
        space.add(pin)
        links.append(pin)
        prev, prev_at = bob, (0, 0)
    bobs = [c.b for c in links]
    tape.start(space)
    for frame in range(tape.frames):
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        if frame == 30:  # flicked
            with tape.act(space, bobs[-1]):
                bobs[-1].velocity += (0, -400)
        if frame == 50:  # a link cut
            with tape.act(space, bobs[2], bobs[3]):
                space.remove(links[3])
        if frame == 65:  # a bob caught
            with tape.act(space, bobs[1]):
                bobs[1].velocity = (0, 0)
                bobs[1].angular_velocity = 0
        space.step(1 / 60)
        screen.fill((255, 255, 255))
        space.debug_draw(options)
        pygame.display.flip()
        tape.frame()


def hammer(tape: Tape) -> None:
    """A kivy app (SI, y up, gravity 9.81 down): a hammer on a pivot with a return spring
    (DampedRotarySpring), its mass, moment and centre of gravity computed by pymunk from
    its shapes' masses (a light handle and a heavy head, so the centre of gravity is far
    from the grip, the body's origin), swings down onto an L-shaped block (also built from
    shape masses) standing on a table; the user gives the hammer a swing."""
    import pymunk
    from kivy.app import App
    from kivy.clock import Clock
    from kivy.uix.widget import Widget

    class Workshop(Widget):
        def __init__(self, **kw: Any) -> None:
            super().__init__(**kw)
            self.space = space = pymunk.Space()
            space.gravity = (0, -9.81)
            table = pymunk.Segment(space.static_body, (0.3, 0.5), (2.5, 0.5), 0.02)
            table.friction = 0.7
            space.add(table)
            self.hammer = hammer = pymunk.Body()
            hammer.position = (0.0, 1.5)
            handle = pymunk.Poly(hammer, [(0, -0.02), (0.8, -0.02), (0.8, 0.02), (0, 0.02)])
            handle.mass = 0.5
            head = pymunk.Poly(hammer, [(0.8, -0.1), (0.95, -0.1), (0.95, 0.1), (0.8, 0.1)])
            head.mass, head.friction, head.elasticity = 2.0, 0.5, 0.3
            space.add(hammer, handle, head)
            space.add(pymunk.PivotJoint(space.static_body, hammer, (0.0, 1.5)),
                      pymunk.DampedRotarySpring(space.static_body, hammer, 0.3, 15.0, 0.2))
            self.block = block = pymunk.Body()
            block.position = (0.5, 0.52)
            foot = pymunk.Poly(block, [(0, 0), (0.4, 0), (0.4, 0.08), (0, 0.08)])
            post = pymunk.Poly(block, [(0, 0.08), (0.08, 0.08), (0.08, 0.45), (0, 0.45)])
            for s in (foot, post):
                s.density, s.friction = 600.0, 0.7
            space.add(block, foot, post)
            self.frame = 0
            tape.start(space)

        def update(self, dt: float) -> None:
            if self.frame == 20:  # a swing
                with tape.act(self.space, self.hammer):
                    self.hammer.angular_velocity = -6.0
            for _ in range(2):
                self.space.step(dt / 2)
            self.frame += 1
            tape.frame()

    class WorkshopApp(App):
        def build(self) -> Workshop:
            w = Workshop()
            Clock.schedule_interval(w.update, 1 / 60)
            return w

    WorkshopApp().run()


def frame_drops(tape: Tape) -> None:
    """pygame with pymunk.pygame_util (pixels, y down, gravity 900), stepped by the frame
    time it measures (``dt = clock.tick(60) / 1000``: 16 or 17 ms, 33 or 50 when a frame is
    dropped): balls placed sunk into the floor (pushed out by pymunk's position correction
    over the next steps) and balls dropped one by one, each on its own part of the floor."""
    import pygame
    import pymunk
    import pymunk.pygame_util

    screen = pygame.display.set_mode((800, 600))
    options = pymunk.pygame_util.DrawOptions(screen)
    clock = pygame.time.Clock()
    space = pymunk.Space()
    space.gravity = (0, 900)
    floor = pymunk.Segment(space.static_body, (40, 550), (760, 550), 5)  # its top at y = 545
    floor.friction = 0.8
    space.add(floor)
    balls = []

    def ball(x: float, y: float, r: float = 15) -> pymunk.Body:
        b = pymunk.Body(1, pymunk.moment_for_circle(1, 0, r))
        b.position = (x, y)
        shape = pymunk.Circle(b, r)
        shape.friction = 0.8
        return b

    for x, sunk in ((100, 8), (180, 3), (260, 12)):  # placed partly inside the floor
        b = ball(x, 545 - 15 + sunk)
        space.add(b, *b.shapes)
        balls.append(b)
    tape.start(space)
    frame = 0
    while tape.running:
        for event in pygame.event.get():
            if event.type == pygame.QUIT:
                return
        dt = clock.tick(60) / 1000.0
        if frame % 8 == 5 and len(balls) < 9:
            b = ball(340 + 70 * (len(balls) - 3), 150)
            with tape.act(space, b):
                space.add(b, *b.shapes)
            balls.append(b)
        space.step(dt)
        screen.fill((255, 255, 255))
        space.debug_draw(options)
        pygame.display.flip()
        frame += 1
        tape.frame()


def ship(tape: Tape, substeps: int = 1) -> None:
    """An arcade game in space (pixels, y up, no gravity): a ship steered by thrusters that
    push along the screen's axes and a turning torque, set once per frame (``Body.force``,
    ``Body.torque``), its centre of gravity behind its nose (the body's origin); it fires a
    bullet every 15 frames (removed 40 frames later); rocks drift far away. With
    ``substeps`` > 1 the player applies the guard's advice: each frame is
    ``spaces.step(space, dt, substeps)``."""
    import arcade
    import pymunk

    from dumbbell import spaces

    class Asteroids(arcade.Window):
        def __init__(self) -> None:
            super().__init__(1024, 768, "Asteroids")
            self.space = space = pymunk.Space()
            crew = pymunk.ShapeFilter(group=1)
            nose = [(0, 0), (-60, 20), (-60, -20)]
            self.ship = ship = pymunk.Body(10, pymunk.moment_for_poly(10, nose))
            hull = pymunk.Poly(ship, nose)
            ship.center_of_gravity = hull.center_of_gravity
            ship.position = (200, 380)
            hull.filter = crew
            space.add(ship, hull)
            rng = random.Random(5)
            for _ in range(5):
                rock = pymunk.Body(40, pymunk.moment_for_circle(40, 0, 30))
                rock.position = (rng.uniform(3000, 4000), rng.uniform(-500, 500))
                rock.velocity = (rng.uniform(-20, 20), rng.uniform(-20, 20))
                space.add(rock, pymunk.Circle(rock, 30))
            self.bullets: list[tuple[int, pymunk.Body]] = []
            self.crew, self.frame = crew, 0
            tape.start(space)

        def on_update(self, delta_time: float) -> None:
            k = self.frame
            self.ship.force = (1500 * math.cos(k / 9), 900 * math.sin(k / 13))
            self.ship.torque = 4000 * math.sin(k / 7)
            if k % 15 == 0:
                bullet = pymunk.Body(0.1, pymunk.moment_for_circle(0.1, 0, 3))
                bullet.position = self.ship.local_to_world((5, 0))
                bullet.velocity = self.ship.velocity + (600, 0)
                dot = pymunk.Circle(bullet, 3)
                dot.filter = self.crew
                with tape.act(self.space, bullet):
                    self.space.add(bullet, dot)
                self.bullets.append((k, bullet))
            old = [b for when, b in self.bullets if k - when >= 40]
            if old:
                with tape.act(self.space, *old):
                    for b in old:
                        self.space.remove(b, *b.shapes)
                self.bullets = [(w, b) for w, b in self.bullets if b not in old]
            if substeps == 1:
                self.space.step(delta_time)
            else:
                spaces.step(self.space, delta_time, substeps=substeps)
            self.frame += 1

        def on_draw(self) -> None:
            self.clear()
            tape.frame()

    Asteroids()
    arcade.run()


@dataclass(frozen=True)
class Program:
    """A corpus entry: the program, its window library and which way y points in that
    window, the space's units, the frames it runs, and how often energy is checked."""

    run: Callable[..., None]
    window: str
    y_up: bool
    units: Any
    frames: int
    check_every: int = 60
    kwargs: tuple = ()
    pushes: bool = False


PX = ("px", "kg", "s")
SI = ("m", "kg", "s")

PROGRAMS = {
    "pool_table": Program(pool_table, "pygame", False, PX, 120, 100),
    "car": Program(car, "arcade", True, SI, 75, 150),
    "ragdoll": Program(ragdoll, "pygame_util", False, PX, 90),
    "cloth": Program(cloth, "pyglet", True, PX, 60, 90),
    "gas": Program(gas, "kivy", True, PX, 3, 1000),
    "bumpers": Program(bumpers, "arcade", True, PX, 130),
    "spawner": Program(spawner, "pygame_util", False, PX, 120),
    "planet": Program(planet, "none", True, PX, 45),
    "planet_declared": Program(planet, "none", True, PX, 45, kwargs=(("declare", True),)),
    "conveyor": Program(conveyor, "pygame", True, SI, 120),
    "chain": Program(chain, "pygame_util", False, PX, 80),
    "hammer": Program(hammer, "kivy", True, SI, 60, 80),
    "frame_drops": Program(frame_drops, "pygame_util", False, PX, 120, pushes=True),
    "ship": Program(ship, "arcade", True, PX, 90),
    "ship_substeps": Program(ship, "arcade", True, PX, 90, kwargs=(("substeps", 6),)),
}


def run(name: str, folder: str | Path, tools: bool = True) -> Tape:
    """Run corpus program ``name`` headless with its tape; the GIF goes into ``folder``.
    ``tools=False``: bare, with no ledger, heat counter or recorder attached."""
    p = PROGRAMS[name]
    tape = Tape(name, Path(folder), p.frames, p.window, p.y_up, p.units, p.check_every,
                pushes={} if p.pushes else None, tools=tools)
    with window(tape):
        p.run(tape, **dict(p.kwargs))
    tape.finish()
    return tape


if __name__ == "__main__":
    import tempfile
    import time

    with tempfile.TemporaryDirectory() as tmp:
        for name in sys.argv[1:] or PROGRAMS:
            t0 = time.perf_counter()
            tape = run(name, tmp)
            b = tape.balance
            print(f"{name:16s} {time.perf_counter() - t0:6.2f} s  steps {len(tape.dts)} "
                  f"bodies {len(tape.space.bodies)} constraints {len(tape.space.constraints)} "
                  f"events {len(tape.events)} ledger steps {b.steps} complete {b.complete} "
                  f"closure {b.relative_closure:.1e} unaccounted {len(b.unaccounted)}")
