"""The harness of the outside corpus (``tests/outside_corpus.py``): the energy of a space
by hand, the :class:`Tape` that measures what a program does, and the window libraries a
program imports, headless.

- :func:`hand_energy`: a space's energy from pymunk's getters and the textbook formulas
  (1/2 m v^2, 1/2 I w^2, -m g . r of the centre of gravity, 1/2 k (d - L)^2), with no code of
  dumbbell's.
- :class:`Tape`: a program hands it its space once built (:meth:`Tape.start` attaches a
  ledger, a heat counter and a recorder, as a user putting ``dumbbell.spaces`` on the
  program would) and wraps each thing it does to its bodies between steps, or inside a
  callback, in ``with tape.act(...)``, which measures the energy just before and just after
  it by hand. The harness counts the steps (``Space.step`` wrapped while a program runs),
  records a frame at each 1/fps of simulated time and, where asked, measures each step's
  push of overlapping shapes apart from the bodies' public state.
- :func:`window`: the program's window library and nothing else: pyglet, arcade and kivy are
  stand-ins (a window that never opens, a clock that calls the program's scheduled functions
  for a given number of frames); pygame runs with its dummy video driver and a clock that
  does not sleep; the other libraries are blocked while the program runs.
- :func:`recentred`: a space's world rebuilt with every origin at its centre of gravity.
"""

from __future__ import annotations

import contextlib
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
FPS = 10
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
    #: False: the program runs bare (no ledger, heat counter or recorder attached), to
    #: compare its motion with the run that has them.
    tools: bool = True

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
        if not self.tools:
            self.checkpoint()
            return
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
        if self.tools and t >= self.next_frame / FPS - 1e-9:
            self.rec.capture(t=t)
            self.next_frame = math.floor(t * FPS + 1e-9) + 1
        if len(self.dts) % self.check_every == 0:
            self.checkpoint()

    def finish(self) -> None:
        """The run is over: the balance, the last checkpoint, a last frame (the space as
        the run leaves it), the GIF; tools detached."""
        if self.space is None:
            raise RuntimeError(f"{self.name}: the program never started its tape")
        if not self.tools:
            return
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
def window(tape: Tape) -> Iterator[None]:
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
