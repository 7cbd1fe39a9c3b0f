"""The step-size guard's cost against the body count, with ``space.step`` as the yardstick.

    python benchmarks/guard_speed.py [--sizes 100 400 1600 10000] [--repeat 3]
    python benchmarks/guard_speed.py --src OTHER/src --sizes 100 400   # another checkout
    python benchmarks/guard_speed.py --pin          # also with a pendulum on a pin joint

The scene: N square boxes (1 kg, 20 px) in columns of a stack on a ground segment between two
walls, y up, g = 900 px/s^2, pymunk's pixel defaults, resting on each other (0.05 px of overlap,
under the slop, so every contact is there from the first step); plus pymunk's own box2d_pyramid
(325 boxes) built as the example builds it; with ``--pin``, each size again with a pendulum on
a PinJoint beside the stack (the guard then measures the joint on a copy of the whole space,
its steps bounded by the probe's budget). For each size, side by side in one process: ten
``space.step(1/150)`` (the reference),
``spaces.report``, ``spaces.check``, ``spaces.suggest_dt`` and ``Driver(space, 1/150)`` (the time
it takes to choose its sub-steps), each the minimum over ``--repeat`` runs on a fresh space.
Printed: seconds and each as a multiple of one ``space.step``. ``--src`` runs the same
measurements on another checkout's ``src`` folder (for a before/after on one machine).
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DT = 1 / 150
SIZE, GAP = 20.0, -0.05


def boxes(n: int):
    """N boxes in a stack of ceil(sqrt(N)) columns on a ground between two walls (y up)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    cols = math.ceil(math.sqrt(n))
    width = cols * (SIZE + 1.0) + 40.0
    height = (n // cols + 2) * (SIZE + GAP) + 40.0
    for a, b in (((0, 0), (width, 0)), ((0, 0), (0, height)), ((width, 0), (width, height))):
        wall = pymunk.Segment(space.static_body, a, b, 1.0)
        wall.friction = 1.0
        space.add(wall)
    half = SIZE / 2
    points = [(-half, -half), (-half, half), (half, half), (half, -half)]
    moment = pymunk.moment_for_poly(1.0, points)
    for i in range(n):
        body = pymunk.Body(1.0, moment)
        body.position = (20.0 + half + (i % cols) * (SIZE + 1.0),
                         1.0 + half + GAP + (i // cols) * (SIZE + GAP))
        shape = pymunk.Poly(body, points)
        shape.friction = 1.0
        space.add(body, shape)
    return space


def pyramid():
    """pymunk's box2d_pyramid scene as its example builds it (325 boxes, y up)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    ground = pymunk.Segment(space.static_body, (5, 100), (595, 100), 1.0)
    ground.friction = 1.0
    space.add(ground)
    x = pymunk.Vec2d(-270, 7.5) + (300, 100)
    dx, dy = pymunk.Vec2d(0.5625, 1.1) * 20, pymunk.Vec2d(1.125, 0.0) * 20
    points = [(-10, -10), (-10, 10), (10, 10), (10, -10)]
    for i in range(25):
        y = pymunk.Vec2d(*x)
        for _ in range(i, 25):
            body = pymunk.Body(1.0, pymunk.moment_for_poly(1.0, points, (0, 0)))
            body.position = y
            shape = pymunk.Poly(body, points)
            shape.friction = 1
            space.add(body, shape)
            y += dy
        x += dx
    return space


def with_pin(n: int):
    """:func:`boxes` and a 1 kg bob on a 200 px PinJoint beside the stack, released level:
    the guard's probe then runs (a copy of the whole space, bounded in steps)."""
    import pymunk

    space = boxes(n)
    top = max(b.position.y for b in space.bodies) + 300.0
    bob = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0.0, 10.0))
    bob.position = (-400.0, top)
    space.add(bob, pymunk.Circle(bob, 10.0),
              pymunk.PinJoint(space.static_body, bob, (-200.0, top), (0.0, 0.0)))
    return space


def timed(make, use, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        space = make()
        t0 = time.perf_counter()
        use(space)
        best = min(best, time.perf_counter() - t0)
    return best


def measure(sizes: list[int], repeat: int, pins: bool = False) -> list[dict]:
    from dumbbell import spaces

    rows = []
    cases = [(f"{n} boxes", (lambda n=n: boxes(n))) for n in sizes]
    cases.insert(min(2, len(cases)), ("box2d_pyramid (325)", pyramid))
    if pins:
        cases += [(f"{n} boxes + a pin", (lambda n=n: with_pin(n))) for n in sizes]
    for name, make in cases:
        def ten_steps(space):
            for _ in range(10):
                space.step(DT)

        row = {"case": name, "step": timed(make, ten_steps, repeat) / 10}
        row["report"] = timed(make, lambda s: spaces.report(s, DT), repeat)
        row["check"] = timed(make, lambda s: spaces.check(s, DT), repeat)
        row["suggest_dt"] = timed(make, lambda s: spaces.suggest_dt(s, DT), repeat)
        row["Driver"] = timed(make, lambda s: spaces.Driver(s, DT), repeat)
        rows.append(row)
        print(_line(row), flush=True)
    return rows


HEAD = (f"{'case':22s} {'step (ms)':>10s} {'report (s)':>11s} {'x step':>8s} {'check (s)':>10s} "
        f"{'suggest_dt (s)':>15s} {'Driver (s)':>11s} {'x step':>8s}")


def _line(row: dict) -> str:
    return (f"{row['case']:22s} {1e3 * row['step']:10.3f} {row['report']:11.4f} "
            f"{row['report'] / row['step']:8.0f} {row['check']:10.4f} {row['suggest_dt']:15.4f} "
            f"{row['Driver']:11.4f} {row['Driver'] / row['step']:8.0f}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 400, 1600, 10000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--src", help="run on this checkout's src folder instead")
    parser.add_argument("--pin", action="store_true",
                        help="also each size with a pendulum on a PinJoint (the joint probe)")
    a = parser.parse_args(argv)
    if a.src:
        return subprocess.call([sys.executable, __file__, "--sizes", *map(str, a.sizes),
                                "--repeat", str(a.repeat), *(["--pin"] if a.pin else [])],
                               env={"PYTHONPATH": str(Path(a.src).resolve()),
                                    "PATH": "/usr/bin:/bin"})
    import dumbbell

    print(f"guard from {Path(dumbbell.__file__).parent}; minimum of {a.repeat} runs each, "
          "2 shared cores: compare the columns of one run, not runs")
    print(HEAD, flush=True)
    measure(a.sizes, a.repeat, a.pin)
    return 0


if __name__ == "__main__":
    sys.exit(main())
