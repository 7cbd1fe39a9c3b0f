"""Programs written here the way pymunk users write them, as a corpus for ``dumbbell.spaces``
(issue 28's tests): a pool table, a car, a ragdoll, a cloth, a gas of 10,000 particles, a
game whose collision callbacks remove bodies and scale velocities, a program that adds and
removes bodies and joints every few frames, a planet with a ``velocity_func`` field (its
potential declared and not), a conveyor with a kinematic lift, a damped chain of pins, a
hammer whose centre of gravity pymunk computes from its shapes.

None of them comes from ``pymunk.examples`` or anywhere else. Each is written for a window
library (pygame, drawing with ``pymunk.pygame_util`` or by hand; pyglet; arcade; kivy) or
none (a script), in that library's units and orientation: pixels and y down for pygame,
pixels or metres and y up for the others. The libraries other than pygame are replaced by
stand-ins (a window that never opens, a clock that calls the program's scheduled functions
for a given number of frames); pygame runs with its dummy video driver. Nothing is drawn:
a program's drawing calls go to the stand-ins or are left out, as a headless run would.

What a program does for the tests, and only this: it hands its space to :class:`Tape`
once built (:meth:`Tape.start` attaches a ledger, a heat counter and a recorder, as a user
putting ``dumbbell.spaces`` on the program would) and wraps each thing it does to its
bodies between steps, or inside a callback, in ``with tape.act(...)``, which measures the
energy just before and just after it by hand (:func:`hand_energy`, from pymunk's getters,
with no code of dumbbell's). The harness counts the steps (``Space.step`` wrapped while a
program runs) and records a frame at each 1/fps of simulated time.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import random
import sys
import types
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .pymunk_corpus import _Anything, _StandInModule

#: Frames per second of the recordings.
FPS = 25
#: Window libraries whose stand-ins a program can import.
STAND_INS = ("pyglet", "arcade", "kivy")


# --------------------------------------------------------------------------------------
# Energy by hand: pymunk's getters and the textbook formulas, nothing of dumbbell's.


@dataclass
class Hand:
    """A space's energy computed by hand: each term, and the sum of the absolute values of
    the parts that make it (the size of its rounding), per term."""

    K_trans: float
    K_rot: float
    U_g: float
    U_spring: float
    U_field: float
    momentum: tuple[float, float]
    mass: float
    size: dict[str, float]

    @property
    def E(self) -> float:
        """K + U_g + U_spring (what ``spaces.energy`` calls E; the fields are apart)."""
        return self.K_trans + self.K_rot + self.U_g + self.U_spring

    @property
    def E_total(self) -> float:
        """E with the declared fields' potential (what a ledger with them calls E)."""
        return self.E + self.U_field


def body_energy(body: Any, gravity: Any, fields: tuple = ()) -> float:
    """One dynamic body's energy: 1/2 m |v|^2 + 1/2 I w^2 - m g . r, v the velocity of its
    centre of gravity (pymunk's ``Body.velocity``) and r where its centre of gravity is
    (``position`` is the body's origin), plus the potential of a field its velocity_func
    applies, where one is given."""
    c = body.local_to_world(body.center_of_gravity)
    v = body.velocity
    e = (0.5 * body.mass * (v.x * v.x + v.y * v.y) + 0.5 * body.moment * body.angular_velocity ** 2
         - body.mass * (gravity.x * c.x + gravity.y * c.y))
    for func, potential in fields:
        if body.velocity_func is func:
            e += float(potential(c.x, c.y, body.mass))
    return e


def spring_energy(c: Any) -> float:
    """A DampedSpring's 1/2 k (d - L)^2, d between its anchors in the world; a
    DampedRotarySpring's 1/2 k (angle_a - angle_b - rest)^2; 0 for any other constraint."""
    import pymunk

    if isinstance(c, pymunk.DampedSpring):
        pa, pb = c.a.local_to_world(c.anchor_a), c.b.local_to_world(c.anchor_b)
        d = math.hypot(pb.x - pa.x, pb.y - pa.y)
        return 0.5 * c.stiffness * (d - c.rest_length) ** 2
    if isinstance(c, pymunk.DampedRotarySpring):
        return 0.5 * c.stiffness * (c.a.angle - c.b.angle - c.rest_angle) ** 2
    return 0.0


def hand_energy(space: Any, fields: tuple = ()) -> Hand:
    """The space's energy by hand: dynamic bodies only (static and kinematic ones hold
    none), the springs, and the fields given as (velocity_func, potential(x, y, m))."""
    import pymunk

    g = space.gravity
    kt, kr, ug, uf, px, py, m = [], [], [], [], [], [], []
    for b in space.bodies:
        if b.body_type != pymunk.Body.DYNAMIC:
            continue
        v = b.velocity
        c = b.local_to_world(b.center_of_gravity)
        kt.append(0.5 * b.mass * (v.x * v.x + v.y * v.y))
        kr.append(0.5 * b.moment * b.angular_velocity ** 2)
        ug.append(-b.mass * (g.x * c.x + g.y * c.y))
        px.append(b.mass * v.x)
        py.append(b.mass * v.y)
        m.append(b.mass)
        for func, potential in fields:
            if b.velocity_func is func:
                uf.append(float(potential(c.x, c.y, b.mass)))
    us = [spring_energy(c) for c in space.constraints]
    size = {"K_trans": math.fsum(kt), "K_rot": math.fsum(kr),
            "U_g": math.fsum(abs(u) for u in ug), "U_spring": math.fsum(us),
            "U_field": math.fsum(abs(u) for u in uf),
            "momentum": math.fsum(abs(p) for p in px + py)}
    size["E"] = size["K_trans"] + size["K_rot"] + size["U_g"] + size["U_spring"]
    return Hand(math.fsum(kt), math.fsum(kr), math.fsum(ug), math.fsum(us), math.fsum(uf),
                (math.fsum(px), math.fsum(py)), math.fsum(m), size)


# --------------------------------------------------------------------------------------
# The tape: what the program did, measured, and the tools attached to its space.


@dataclass
class Checkpoint:
    """The space's energy by hand and by ``spaces.energy`` after ``step`` steps."""

    step: int
    hand: Hand
    lib: Any


@dataclass
class Tape:
    """What a run records. ``window`` is the library the program draws with ('pygame',
    'pygame_util', 'pyglet', 'arcade', 'kivy', 'none'); ``y_up`` which way y points in
    that window; ``units`` the space's units for the recorder."""

    name: str
    folder: Path
    frames: int
    window: str
    y_up: bool
    units: Any = ("m", "kg", "s")
    check_every: int = 60
    space: Any = None
    ledger: Any = None
    heat: Any = None
    rec: Any = None
    fields: tuple = ()
    declared: bool = False
    events: dict[tuple[str, str], float] = field(default_factory=dict)
    labels: dict[int, str] = field(default_factory=dict)
    kept: list[Any] = field(default_factory=list)
    unannounced: list[str] = field(default_factory=list)
    checkpoints: list[Checkpoint] = field(default_factory=list)
    dts: list[float] = field(default_factory=list)
    frame_count: int = 0
    next_frame: int = 1
    balance: Any = None
    path: Path | None = None
    dt: float = 0.0
    velocity_funcs: list[Any] = field(default_factory=list)
    pushes: dict[str, float] | None = None

    # -- what the harness does ---------------------------------------------------------

    def start(self, space: Any, fields: tuple = (), declare: bool = False) -> None:
        """The program's space is built: label its bodies as the ledger does (their place
        in ``space.bodies``), attach a ledger (the fields' potentials declared if
        ``declare``), a heat counter and a recorder, and take the first checkpoint."""
        from dumbbell import spaces

        self.space = space
        self.fields = tuple(fields) if declare else ()
        self.velocity_funcs = [f for f, _ in fields]
        self.declared = declare
        for i, b in enumerate(space.bodies):
            self.labels[id(b)] = f"{_kind(b)}{i}"
            self.kept.append(b)
        self.ledger = spaces.Ledger(space)
        if declare:
            for func, potential in fields:
                self.ledger.declare_potential(func, potential, name=f"field of {func.__name__}")
        self.heat = spaces.HeatCounter(space)
        self.path = self.folder / f"{self.name}.gif"
        self.rec = spaces.Recorder(space, self.path, fps=FPS, units=self.units, heat=self.heat)
        self.checkpoint()

    def checkpoint(self) -> None:
        from dumbbell import spaces

        self.checkpoints.append(Checkpoint(len(self.dts), hand_energy(self.space, self.fields),
                                           spaces.energy(self.space)))

    def before_step(self) -> list[tuple[Any, Any, Any]]:
        """Each dynamic body's centre of gravity and velocity before a step."""
        import pymunk

        return [(b, b.local_to_world(b.center_of_gravity), b.velocity)
                for b in self.space.bodies if b.body_type == pymunk.Body.DYNAMIC]

    def after_step(self, before: list[tuple[Any, Any, Any]], dt: float) -> None:
        """Gravity's part of each body's push out of what it overlaps, over the step: pymunk
        moves a centre of gravity by (v + v_bias) dt, v the velocity the step starts with
        and v_bias what the last step's contacts gave to push overlapping shapes apart, so
        the push is c1 - c0 - v dt, and gravity's part of its energy -m g . that."""
        g = self.space.gravity
        for body, c0, v0 in before:
            if body.space is not self.space:
                continue
            c1 = body.local_to_world(body.center_of_gravity)
            dx, dy = c1.x - c0.x - v0.x * dt, c1.y - c0.y - v0.y * dt
            label = self.labels[id(body)]
            self.pushes[label] = self.pushes.get(label, 0.0) - body.mass * (g.x * dx + g.y * dy)

    def stepped(self, dt: float) -> None:
        """After each of the space's steps: count it, capture a frame at each 1/fps."""
        self.dts.append(dt)
        self.dt = dt
        self._label_new("step")
        t = math.fsum(self.dts)
        if t >= self.next_frame / FPS - 1e-9:
            self.rec.capture(t=t)
            self.next_frame = math.floor(t * FPS + 1e-9) + 1
        if len(self.dts) % self.check_every == 0:
            self.checkpoint()

    def finish(self) -> None:
        """The run is over: the balance, the last checkpoint, a last frame (the space as
        the run leaves it), the GIF; tools detached."""
        if self.space is None:
            raise RuntimeError(f"{self.name}: the program never started its tape")
        self.balance = self.ledger.balance()
        t = math.fsum(self.dts)
        if t > self.rec.times[-1]:
            self.rec.capture(t=t)
        if not self.checkpoints or self.checkpoints[-1].step != len(self.dts):
            self.checkpoint()
        self.rec.write()
        self.ledger.detach()
        self.heat.detach()

    # -- what the program does ---------------------------------------------------------

    def frame(self) -> None:
        """The program drew a frame (the stand-in loops run until ``frames`` are drawn)."""
        self.frame_count += 1

    @property
    def running(self) -> bool:
        return self.frame_count < self.frames

    @contextlib.contextmanager
    def act(self, space: Any, *bodies: Any, where: str = "program") -> Iterator[None]:
        """Measure what the block does: each body's energy (the ``bodies`` given, else every
        dynamic body of the space) and the springs' just before and just after it. A body
        there before and after that changed is a ``program`` term (``unattributed`` when
        ``where='callback'``: inside a step), a body that came ``entered``, one that went
        ``left``; the springs' change is what the program did to them, by adding or
        removing constraints or by moving bodies."""
        watch = list(bodies) if bodies else None
        before = self._energies(space, watch)
        springs = math.fsum(spring_energy(c) for c in space.constraints)
        constraints = {id(c) for c in space.constraints}
        yield
        after = self._energies(space, watch)
        if any(key not in self.labels for key in after):
            self._label_new("act")
        for key in before.keys() | after.keys():
            if key in before and key in after:
                d = after[key][1] - before[key][1]
                kind = "unattributed" if where == "callback" else "program"
                source = self.labels[key] if where == "callback" else f"program: {self.labels[key]}"
                self._event(kind, source, d)
            elif key in after:
                self._event("entered", self.labels[key], after[key][1])
            else:
                self._event("left", self.labels[key], -before[key][1])
        d = math.fsum(spring_energy(c) for c in space.constraints) - springs
        if d:
            what = ("constraints added or removed"
                    if {id(c) for c in space.constraints} != constraints
                    else "springs stretched by moved bodies")
            self._event("program", f"program: {what}", d)

    # -- helpers -------------------------------------------------------------------------

    def _energies(self, space: Any, watch: list[Any] | None) -> dict[int, tuple[Any, float]]:
        import pymunk

        bodies = space.bodies if watch is None else [b for b in watch if b.space is space]
        g = space.gravity
        return {id(b): (b, body_energy(b, g, self.fields)) for b in bodies
                if b.body_type == pymunk.Body.DYNAMIC}

    def _event(self, kind: str, source: str, value: float) -> None:
        if value != 0.0:
            key = (kind, source)
            self.events[key] = self.events.get(key, 0.0) + value

    def _label(self, body: Any) -> str:
        if id(body) not in self.labels:
            self.labels[id(body)] = f"{_kind(body)}{self._next()}"
            self.kept.append(body)  # keeps id() unique while the tape lives
        return self.labels[id(body)]

    def _next(self) -> int:
        return len(self.labels)

    def _label_new(self, when: str) -> None:
        """Bodies new in the space named as the ledger names them (the next numbers,
        dynamic ones first, in their order in ``space.bodies``); after a step, those the
        program added without measuring them are noted, so that a test can say so."""
        import pymunk

        new = [b for b in self.space.bodies if id(b) not in self.labels]
        new.sort(key=lambda b: b.body_type != pymunk.Body.DYNAMIC)  # dynamic first
        for b in new:
            self._label(b)
            if when == "step":
                self.unannounced.append(self.labels[id(b)])


def _kind(body: Any) -> str:
    import pymunk

    return {pymunk.Body.KINEMATIC: "kinematic body ",
            pymunk.Body.STATIC: "static body "}.get(body.body_type, "body ")


# --------------------------------------------------------------------------------------
# Window libraries: stand-ins for pyglet, arcade and kivy; pygame headless.


def _stand_in(name: str, tape: Tape) -> dict[str, types.ModuleType]:
    """The modules of window library ``name``, whose loop runs while ``tape.running``."""
    scheduled: list[tuple[Callable[..., Any], float]] = []

    def run_scheduled() -> None:
        while tape.running:
            for f, interval in scheduled[:]:
                f(interval)

    def schedule_interval(f: Callable[..., Any], interval: float, *a: Any, **k: Any) -> Any:
        scheduled.append((f, interval))
        return _Anything()

    def package(*names: str) -> dict[str, types.ModuleType]:
        mods = {n: _StandInModule(n) for n in names}
        for n, mod in mods.items():
            mod.__path__ = []
            parent, _, leaf = n.rpartition(".")
            if parent:
                setattr(mods[parent], leaf, mod)
        return mods

    if name == "pyglet":
        mods = package("pyglet", "pyglet.window", "pyglet.clock", "pyglet.app",
                       "pyglet.shapes", "pyglet.graphics", "pyglet.text")

        class Window:
            def __init__(self, width: int = 640, height: int = 480, **k: Any) -> None:
                self.width, self.height = width, height

            def event(self, f: Callable[..., Any]) -> Callable[..., Any]:
                return f

            def __getattr__(self, attr: str) -> Any:
                return _Anything()

        mods["pyglet.window"].Window = Window
        mods["pyglet.clock"].schedule_interval = schedule_interval
        mods["pyglet.app"].run = lambda *a, **k: run_scheduled()
        return mods
    if name == "arcade":
        mods = package("arcade")
        windows: list[Any] = []

        class ArcadeWindow:
            def __init__(self, width: int = 800, height: int = 600, title: str = "",
                         **k: Any) -> None:
                self.width, self.height = width, height
                windows.append(self)

            def on_update(self, delta_time: float) -> None:
                pass

            def on_draw(self) -> None:
                pass

            def clear(self) -> None:
                pass

        def run() -> None:
            window = windows[-1]
            while tape.running:
                window.on_update(1 / 60)
                window.on_draw()

        mods["arcade"].Window = ArcadeWindow
        mods["arcade"].run = run
        return mods
    if name == "kivy":
        mods = package("kivy", "kivy.app", "kivy.clock", "kivy.uix", "kivy.uix.widget",
                       "kivy.graphics")

        class Widget:
            def __init__(self, **k: Any) -> None:
                self.canvas = _Anything()

        class App:
            def run(self) -> None:
                self.root = self.build()
                run_scheduled()

        mods["kivy.uix.widget"].Widget = Widget
        mods["kivy.app"].App = App
        mods["kivy.clock"].Clock = types.SimpleNamespace(schedule_interval=schedule_interval)
        return mods
    raise KeyError(name)


class _Clock:
    """pygame's Clock, without the sleeping: ``tick`` returns the milliseconds a busy
    machine's frames take (16 or 17, now and then a dropped frame of 33 or 50)."""

    def __init__(self) -> None:
        self.frames = 0

    def tick(self, *a: Any) -> int:
        self.frames += 1
        k = self.frames
        return 50 if k % 23 == 0 else 33 if k % 7 == 0 else 16 + (k * 5) % 3 // 2


@contextlib.contextmanager
def _window(tape: Tape) -> Iterator[None]:
    """What the program's process would have imported, and nothing else: its window
    library (a stand-in, or pygame itself headless); the others, pygame and pygame_util
    included, are blocked (None in ``sys.modules``) while it runs. ``Space.step`` counts
    the steps of the tape's space."""
    import pygame  # loaded once for good: blocked below, never unloaded (it cannot reload)
    import pymunk

    names = ["pygame", "pymunk.pygame_util", *STAND_INS]
    saved = {n: sys.modules[n] for n in list(sys.modules) if n in names or
             any(n.startswith(s + ".") for s in STAND_INS)}
    installed: dict[str, Any] = {n: None for n in names}
    if tape.window in STAND_INS:
        installed.update(_stand_in(tape.window, tape))
    elif tape.window in ("pygame", "pygame_util"):
        installed["pygame"] = pygame
        real_clock = pygame.time.Clock
        pygame.time.Clock = _Clock  # no sleeping: the frames are not shown
        if tape.window == "pygame_util":
            import pymunk.pygame_util

            installed["pymunk.pygame_util"] = pymunk.pygame_util
    for n in list(sys.modules):
        if any(n.startswith(s + ".") for s in STAND_INS):
            del sys.modules[n]
    sys.modules.update(installed)
    real_step = pymunk.Space.step
    flag = getattr(sys.modules.get("pymunk.pygame_util"), "positive_y_is_up", None)

    def step(space: Any, dt: float) -> None:
        if space is not tape.space:
            real_step(space, dt)
            return
        before = tape.before_step() if tape.pushes is not None else None
        real_step(space, dt)
        if before is not None:
            tape.after_step(before, dt)
        tape.stepped(dt)

    pymunk.Space.step = step
    state = random.getstate()
    try:
        yield
    finally:
        if tape.window in ("pygame", "pygame_util"):
            pygame.time.Clock = real_clock
            pygame.quit()
        random.setstate(state)
        pymunk.Space.step = real_step
        if flag is not None:
            sys.modules["pymunk.pygame_util"].positive_y_is_up = flag
        for n in installed:
            sys.modules.pop(n, None)
        for n in list(sys.modules):
            if any(n.startswith(s + ".") for s in STAND_INS):
                del sys.modules[n]
        sys.modules.update(saved)


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
        if frame % 70 == 40 and state["cue"] is not None and len(balls) > 1:
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
            if self.frame == 60:  # nitro
                with tape.act(self.space, self.chassis):
                    self.chassis.apply_impulse_at_local_point((1500.0, 0.0), (0.0, 0.1))
            if self.frame == 120:  # handbrake: the wheels stop turning
                with tape.act(self.space, *self.wheels):
                    for wheel in self.wheels:
                        wheel.angular_velocity = 0.0
            throttle = 400.0 if self.frame < 120 else 0.0
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
        if frame == 80:  # kicked in the shin
            with tape.act(space, legs[1]):
                legs[1].apply_impulse_at_local_point((-300, -200), (0, 30))
        if frame == 140:  # the head yanked up by the mouse
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
        if frame == 30:  # a ball thrown at the curtain
            ball = pymunk.Body(5, pymunk.moment_for_circle(5, 0, 25))
            ball.position, ball.velocity = (150, 400), (700, 150)
            with tape.act(space, ball):
                space.add(ball, pymunk.Circle(ball, 25))
        if frame == 70:  # torn in the middle
            with tape.act(space, *everyone):
                for j in range(5, 9):
                    space.remove(springs[(5, j, "v")])
        if frame == 90:  # the bottom-left corner dragged by the mouse
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
            if self.frame == 2:  # the thermostat
                with tape.act(self.space):
                    for p in self.particles:
                        p.velocity *= 1.02
            if self.frame == 4:  # the rightmost particles let out, as many let in
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
        if frame == 30:  # a rocket burn
            with tape.act(space, moons[0]):
                moons[0].apply_impulse_at_local_point((0, 40))
        if frame == 60:  # a launch
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
            crate.position = (1.0, 2.3)
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
        if frame == 60:  # flicked
            with tape.act(space, bobs[-1]):
                bobs[-1].velocity += (0, -400)
        if frame == 100:  # a link cut
            with tape.act(space, bobs[2], bobs[3]):
                space.remove(links[3])
        if frame == 130:  # a bob caught
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
            if self.frame == 40:  # a swing
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
        if frame % 15 == 5 and len(balls) < 9:
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


def recentred(space: Any) -> Any:
    """The same world as ``space`` with every dynamic body's origin moved to its centre of
    gravity: a new space whose bodies have the same mass, moment, pose of their shapes,
    velocity and spin, their shapes' geometry and their constraints' anchors shifted in the
    body's own coordinates to match. Static and kinematic bodies are copied as they are."""
    import pymunk

    out = pymunk.Space()
    out.gravity, out.damping, out.iterations = space.gravity, space.damping, space.iterations
    out.collision_slop, out.collision_bias = space.collision_slop, space.collision_bias
    made: dict[int, tuple[Any, Any]] = {id(space.static_body): (out.static_body, (0.0, 0.0))}
    for b in space.bodies:
        if b.body_type == pymunk.Body.DYNAMIC:
            new = pymunk.Body(b.mass, b.moment)
            off = b.center_of_gravity
            new.angle = b.angle
            new.position = b.local_to_world(off)
        else:
            new = pymunk.Body(body_type=b.body_type)
            off = pymunk.Vec2d(0.0, 0.0)
            new.angle, new.position = b.angle, b.position
        new.velocity, new.angular_velocity = b.velocity, b.angular_velocity
        made[id(b)] = (new, off)
        out.add(new)
    for s in space.shapes:
        new, off = made[id(s.body)]
        if isinstance(s, pymunk.Circle):
            shape = pymunk.Circle(new, s.radius, s.offset - off)
        elif isinstance(s, pymunk.Segment):
            shape = pymunk.Segment(new, s.a - off, s.b - off, s.radius)
        else:
            shape = pymunk.Poly(new, [v - off for v in s.get_vertices()], radius=s.radius)
        for attr in ("friction", "elasticity", "sensor", "collision_type", "filter",
                     "surface_velocity"):
            setattr(shape, attr, getattr(s, attr))
        out.add(shape)
    for c in space.constraints:
        (a, oa), (b, ob) = made[id(c.a)], made[id(c.b)]
        if isinstance(c, pymunk.GrooveJoint):
            new_c = pymunk.GrooveJoint(a, b, c.groove_a - oa, c.groove_b - oa, c.anchor_b - ob)
        elif isinstance(c, pymunk.DampedSpring):
            new_c = pymunk.DampedSpring(a, b, c.anchor_a - oa, c.anchor_b - ob, c.rest_length,
                                        c.stiffness, c.damping)
        elif isinstance(c, pymunk.SlideJoint):
            new_c = pymunk.SlideJoint(a, b, c.anchor_a - oa, c.anchor_b - ob, c.min, c.max)
        elif isinstance(c, pymunk.PinJoint):
            new_c = pymunk.PinJoint(a, b, c.anchor_a - oa, c.anchor_b - ob)
            new_c.distance = c.distance  # (made from the bodies' present places otherwise)
        elif isinstance(c, pymunk.PivotJoint):
            new_c = pymunk.PivotJoint(a, b, c.anchor_a - oa, c.anchor_b - ob)
        elif isinstance(c, pymunk.DampedRotarySpring):
            new_c = pymunk.DampedRotarySpring(a, b, c.rest_angle, c.stiffness, c.damping)
        elif isinstance(c, pymunk.RotaryLimitJoint):
            new_c = pymunk.RotaryLimitJoint(a, b, c.min, c.max)
        elif isinstance(c, pymunk.GearJoint):
            new_c = pymunk.GearJoint(a, b, c.phase, c.ratio)
        else:
            raise TypeError(f"recentred: {type(c).__name__} is not handled")
        for attr in ("max_force", "max_bias", "error_bias", "collide_bodies"):
            setattr(new_c, attr, getattr(c, attr))
        out.add(new_c)
    return out


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
    "pool_table": Program(pool_table, "pygame", False, PX, 200, 100),
    "car": Program(car, "arcade", True, SI, 150, 150),
    "ragdoll": Program(ragdoll, "pygame_util", False, PX, 180),
    "cloth": Program(cloth, "pyglet", True, PX, 120, 90),
    "gas": Program(gas, "kivy", True, PX, 6, 1000),
    "bumpers": Program(bumpers, "arcade", True, PX, 180),
    "spawner": Program(spawner, "pygame_util", False, PX, 240),
    "planet": Program(planet, "none", True, PX, 120),
    "planet_declared": Program(planet, "none", True, PX, 120, kwargs=(("declare", True),)),
    "conveyor": Program(conveyor, "pygame", True, SI, 240),
    "chain": Program(chain, "pygame_util", False, PX, 180),
    "hammer": Program(hammer, "kivy", True, SI, 120, 80),
    "frame_drops": Program(frame_drops, "pygame_util", False, PX, 150, pushes=True),
    "ship": Program(ship, "arcade", True, PX, 90),
    "ship_substeps": Program(ship, "arcade", True, PX, 90, kwargs=(("substeps", 6),)),
}


def run(name: str, folder: str | Path) -> Tape:
    """Run corpus program ``name`` headless with its tape; the GIF goes into ``folder``."""
    p = PROGRAMS[name]
    tape = Tape(name, Path(folder), p.frames, p.window, p.y_up, p.units, p.check_every,
                pushes={} if p.pushes else None)
    with _window(tape):
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
