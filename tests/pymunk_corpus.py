"""pymunk's own example programs as a test corpus, run headless from the installed package.

pymunk ships its examples inside the package (``pymunk.examples``). They are programs: each
builds a space and steps it from a pygame (or pyglet) loop. :func:`run_example` runs one as
written, with pygame's dummy video driver and a stand-in for pyglet's window and clock, and
hands the space to the caller at two moments: once it is built (just before its first
``Space.step``), and after each step. It stops the program after a given number of steps.
Nothing of the programs is copied here; they are imported from the installed pymunk.

What the harness changes in a program, and only this:

- ``pygame.time.Clock`` does not sleep, and the event queue is empty (no mouse, no keys);
- ``Space.debug_draw`` draws nothing with the programs' own (pymunk's) draw options (their
  drawing is not under test); other options, a recorder's, draw as usual;
- ``random`` is seeded, so a program gives the same space every time;
- for ``isolate``: a callback may remove parts of the space before the first step (the
  constraints demo, one constraint kind at a time).

Run ``python tests/pymunk_corpus.py`` to list the corpus with its size and orientation.
"""

from __future__ import annotations

import contextlib
import importlib.abc
import importlib.util
import io
import math
import os
import random
import runpy
import sys
import types
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

#: The corpus: example module -> what it shows (issue 20's list, and a few more).
EXAMPLES = {
    "constraints": "every constraint kind, each in its own box (y down, pixels)",
    "newtons_cradle": "balls on pin joints passing momentum through elastic contacts",
    "planet": "orbits in a central 1/r^2 field set through a custom velocity_func",
    "box2d_pyramid": "325 boxes stacked on a ground segment, friction 1 (y up)",
    "box2d_vertical_stack": "a column of boxes resting on the ground",
    "slide_and_pinjoint": "balls on a slide joint and a pin joint falling on a slope",
    "damped_rotary_spring_pointer": "a pointer pulled round by a damped rotary spring",
    "spiderweb": "a web of damped springs hanging from static points (pyglet)",
    "tank": "a tank driven through pivot joints with finite max_force, among boxes",
    "flipper": "pinball flippers on pivots and rotary springs; balls dropped in",
    "contact_with_friction": "balls rolling and sliding down segments with friction",
    "bouncing_balls": "balls added over time, bouncing on elastic segments",
    "breakout": "a kinematic paddle and a ball bouncing among bricks",
    "basic_test": "a ball dropped on a segment",
}

#: Command-line arguments a program needs (the cradle's screensaver mode pushes the balls).
ARGV = {"newtons_cradle": ["/s"]}

#: The constraint kinds of the constraints demo, in the order of its boxes.
CONSTRAINT_KINDS = ("PinJoint", "SlideJoint", "PivotJoint", "GrooveJoint", "DampedSpring",
                    "DampedRotarySpring", "RotaryLimitJoint", "RatchetJoint", "GearJoint",
                    "SimpleMotor")


class _Stop(Exception):
    """Raised from inside ``Space.step`` once the program has taken its steps."""


@dataclass
class Run:
    """What :func:`run_example` saw: the space the program stepped (built as the program
    built it), each step's dt, whether the program draws with y up, the screen size in
    pixels, and the program's module globals (its objects, by the program's own names)."""

    name: str
    space: Any = None
    dts: list[float] = field(default_factory=list)
    y_up: bool = False
    screen: tuple[int, int] = (600, 600)
    module: dict[str, Any] = field(default_factory=dict)
    stdout: str = ""

    @property
    def t(self) -> float:
        """Time the program has simulated (s, or the program's unit)."""
        return math.fsum(self.dts)


class _Anything:
    """Stands in for any pyglet object the programs draw with: every attribute and call
    gives another stand-in."""

    def __init__(self, *a: Any, **k: Any) -> None:
        pass

    def __getattr__(self, name: str) -> Any:
        return _Anything()

    def __call__(self, *a: Any, **k: Any) -> Any:
        return _Anything()


class _StandInModule(types.ModuleType):
    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return _Anything()


def _pyglet_stand_in(run: Run, budget: Callable[[], bool]) -> dict[str, types.ModuleType]:
    """pyglet's modules, with a window that never opens and a clock that calls the program's
    scheduled functions until the step budget is used."""
    scheduled: list[tuple[Callable[..., Any], float]] = []

    class Window:
        def __init__(self, *a: Any, **k: Any) -> None:
            self.width, self.height = k.get("width", 640), k.get("height", 480)
            run.screen = (self.width, self.height)

        def event(self, f: Callable[..., Any]) -> Callable[..., Any]:
            return f

        def __getattr__(self, name: str) -> Any:
            return _Anything()

    def run_app(*a: Any, **k: Any) -> None:
        while budget():
            for f, interval in scheduled[:]:  # a callback may schedule more
                f(interval)

    names = ("", ".window", ".window.key", ".window.mouse", ".clock", ".app", ".text",
             ".graphics", ".shapes", ".gl", ".image", ".sprite", ".resource")
    mods = {f"pyglet{n}": _StandInModule(f"pyglet{n}") for n in names}
    for name, mod in mods.items():
        mod.__path__ = []  # a package, so that 'from pyglet.window import key' works
        parent, _, leaf = name.rpartition(".")
        if parent:
            setattr(mods[parent], leaf, mod)
    mods["pyglet"].version = "2.0"
    mods["pyglet.window"].Window = Window
    mods["pyglet.clock"].schedule_interval = lambda f, dt, *a, **k: scheduled.append((f, dt))
    mods["pyglet.clock"].schedule = lambda f, *a, **k: scheduled.append((f, 1 / 60))
    mods["pyglet.app"].run = run_app
    return mods


class _StandInFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports the given stand-in modules by their names (``import pyglet`` gives pyglet's
    stand-in), and nothing else."""

    def __init__(self, modules: dict[str, types.ModuleType]) -> None:
        self.modules = modules

    def find_spec(self, name: str, path: Any, target: Any = None) -> Any:
        if name not in self.modules:
            return None
        return importlib.util.spec_from_loader(name, self, is_package=True)

    def create_module(self, spec: Any) -> types.ModuleType:
        return self.modules[spec.name]

    def exec_module(self, module: types.ModuleType) -> None:
        pass  # made whole by _pyglet_stand_in


@contextlib.contextmanager
def _headless(run: Run, steps: int, on_start: Callable[[Any], Any] | None,
              on_step: Callable[[Any, float], Any] | None,
              isolate: Callable[[Any], Any] | None,
              on_first: Callable[[Any, float], Any] | None = None,
              substeps: int = 1,
              on_substep: Callable[[Any, float], Any] | None = None) -> Iterator[None]:
    import pygame
    import pymunk
    import pymunk.pygame_util

    real_step = pymunk.Space.step
    real_clock = pygame.time.Clock
    real_get = pygame.event.get
    real_draw = pymunk.Space.debug_draw
    real_y = pymunk.pygame_util.positive_y_is_up

    def step(space: Any, dt: float) -> None:
        if run.space is None:
            run.space = space
            if isolate is not None:
                isolate(space)
            if on_start is not None:
                on_start(space)
            if on_first is not None:
                on_first(space, dt)
        if space is not run.space:  # a second space (a copy): step it, do not count it
            real_step(space, dt)
            return
        if len(run.dts) >= steps:
            raise _Stop
        for _ in range(substeps):
            real_step(space, dt / substeps)
            if on_substep is not None:
                on_substep(space, dt / substeps)
        run.dts.append(dt)
        if on_step is not None:
            on_step(space, dt)

    class Clock:
        def tick(self, *a: Any) -> int:
            return 16

        def get_fps(self) -> float:
            return 60.0

        def get_time(self) -> int:
            return 16

    def get(*a: Any, **k: Any) -> list[Any]:
        # Events the program posted itself (timers, a first push) pass; no user input.
        user = {pygame.QUIT, pygame.KEYDOWN, pygame.KEYUP, pygame.MOUSEBUTTONDOWN,
                pygame.MOUSEBUTTONUP, pygame.MOUSEMOTION}
        return [e for e in real_get(*a, **k) if e.type not in user]

    def debug_draw(space: Any, options: Any) -> None:
        if not type(options).__module__.startswith("pymunk."):
            real_draw(space, options)  # not the program's drawing: a recorder's, say
            return
        surface = getattr(options, "surface", None)
        if surface is not None:
            run.screen = tuple(surface.get_size())

    stand_in = _pyglet_stand_in(run, lambda: len(run.dts) < steps)
    saved = {name: sys.modules.get(name) for name in [*stand_in, "pymunk.pyglet_util"]}
    saved_argv = sys.argv
    sys.argv = [f"{run.name}.py", *ARGV.get(run.name, [])]
    for name in saved:
        sys.modules.pop(name, None)
    # pyglet's stand-in is imported only by a program that imports pyglet, as pyglet would
    # be: which window libraries a program has imported is what a recorder reads.
    finder = _StandInFinder(stand_in)
    sys.meta_path.insert(0, finder)
    pymunk.Space.step, pymunk.Space.debug_draw = step, debug_draw
    pygame.time.Clock, pygame.event.get = Clock, get
    state = random.getstate()
    random.seed(0)
    try:
        yield
    finally:
        # Up is against gravity; without gravity, as the program draws (pygame_util draws
        # y down unless the program sets its flag).
        gy = run.space.gravity.y if run.space is not None else 0.0
        run.y_up = gy < 0 if gy else bool(pymunk.pygame_util.positive_y_is_up)
        sys.argv = saved_argv
        random.setstate(state)
        pymunk.Space.step, pymunk.Space.debug_draw = real_step, real_draw
        pygame.time.Clock, pygame.event.get = real_clock, real_get
        pymunk.pygame_util.positive_y_is_up = real_y
        sys.meta_path.remove(finder)
        for name, mod in saved.items():
            if mod is None:
                sys.modules.pop(name, None)
            else:
                sys.modules[name] = mod


def run_example(name: str, steps: int, *, on_start: Callable[[Any], Any] | None = None,
                on_step: Callable[[Any, float], Any] | None = None,
                isolate: Callable[[Any], Any] | None = None,
                on_first: Callable[[Any, float], Any] | None = None,
                substeps: int = 1,
                on_substep: Callable[[Any, float], Any] | None = None) -> Run:
    """Run ``pymunk.examples.<name>`` headless for ``steps`` calls of ``Space.step``.

    ``isolate(space)`` may change the space once it is built; ``on_start(space)`` is called
    after that, before the first step; ``on_first(space, dt)`` then, with the first step's
    dt; ``on_step(space, dt)`` after every step. ``substeps`` > 1 runs each of the program's
    steps as that many equal steps (a step-size guard's advice applied); ``dts`` and
    ``on_step`` still see the program's steps, ``on_substep(space, h)`` each of the equal
    steps. Returns the :class:`Run` (its ``space`` is left as the last step left it)."""
    if name not in EXAMPLES:
        raise KeyError(f"{name!r} is not in the corpus: {', '.join(EXAMPLES)}")
    import pygame

    run = Run(name)
    # By path, as `python path/to/example.py` would: pytest's import hook claims modules
    # named like tests (basic_test), and a program that builds at import time builds afresh.
    path = importlib.util.find_spec(f"pymunk.examples.{name}").origin
    out = io.StringIO()
    with (_headless(run, steps, on_start, on_step, isolate, on_first, substeps, on_substep),
          contextlib.redirect_stdout(out)):
        try:
            run.module = runpy.run_path(path, run_name="__main__")
        except (_Stop, SystemExit):
            pass
    pygame.quit()
    run.stdout = out.getvalue()
    if run.space is None:
        raise RuntimeError(f"{name}: the program never stepped its space")
    return run


def keep_only(kind: str) -> Callable[[Any], None]:
    """For the constraints demo: an ``isolate`` that keeps only the box of one constraint
    kind: the two bodies that kind joins (the box's own constraint is the one between two
    dynamic bodies), the pivots that hold them, and the static walls."""

    def isolate(space: Any) -> None:
        static = space.static_body
        target = [c for c in space.constraints
                  if type(c).__name__ == kind and c.a is not static and c.b is not static]
        if not target:
            raise KeyError(f"no {kind} in the space")
        keep = {id(b) for c in target for b in (c.a, c.b) if b is not space.static_body}
        for c in list(space.constraints):
            if not ({id(c.a), id(c.b)} - {id(space.static_body)}) <= keep or (
                    type(c).__name__ != kind and {id(c.a), id(c.b)} <= keep):
                space.remove(c)
        for body in list(space.bodies):
            if id(body) not in keep:
                space.remove(body, *body.shapes)

    return isolate


if __name__ == "__main__":
    for kind in CONSTRAINT_KINDS:
        s = run_example("constraints", 30, isolate=keep_only(kind)).space
        print(f"constraints/{kind:20s} bodies {len(s.bodies)} constraints "
              f"{sorted(type(c).__name__ for c in s.constraints)}")
    for example in EXAMPLES:
        r = run_example(example, 30)
        s = r.space
        print(f"{example:30s} bodies {len(s.bodies):4d} shapes {len(s.shapes):4d} "
              f"constraints {len(s.constraints):4d} dt {r.dts[0]:.5f} "
              f"y_up {r.y_up} screen {r.screen} g {tuple(s.gravity)}")
