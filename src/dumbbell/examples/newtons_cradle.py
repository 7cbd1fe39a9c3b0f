"""Newton's cradle: five elastic steel balls on pins, in SI units.

    python -m dumbbell.examples.newtons_cradle [--out newtons_cradle.gif] [--seconds 10]

The first ball starts 30 degrees out. At the bottom each ball passes its momentum to the
next: the row carries it across and the last ball swings out. The balls hang 0.1 mm apart, so
the impacts come one after another (pymunk's solver passes momentum along a row of touching
balls only approximately). Printed: the guard's report at the frame step, then the drift of
energy over the run and the change of the row's momentum across each impact, at the frame
step divided into the guard's sub-steps and at ten times finer.
"""

from __future__ import annotations

import math
import sys
from typing import Any

from . import arguments, check_run, check_tools, print_guard, record_and_compare

#: No public names: a program, run as ``python -m dumbbell.examples.newtons_cradle``.
__all__: list[str] = []

#: Ball radius (m), mass (kg), pin length (m), gap between hanging balls (m), start angle.
RADIUS, MASS, LENGTH, GAP, LIFT = 0.025, 0.5, 0.3, 1e-4, math.radians(30)
BALLS = 5


def build() -> Any:
    """The cradle's space: five balls on pins from a bar, the first lifted by :data:`LIFT`."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    space.collision_slop = 1e-5  # SI units: pymunk's 0.1 would be 10 cm
    space.collision_bias = 1.0   # no position correction, which adds energy at each impact
    space.iterations = 20
    bar = pymunk.Segment(space.static_body, (-0.3, LENGTH), (0.3, LENGTH), 0.006)
    bar.filter = pymunk.ShapeFilter(categories=0)  # drawn, never hit
    space.add(bar)
    spacing = 2 * RADIUS + GAP
    for i in range(BALLS):
        x = (i - (BALLS - 1) / 2) * spacing
        body = pymunk.Body(MASS, pymunk.moment_for_circle(MASS, 0, RADIUS))
        if i == 0:
            body.position = (x - LENGTH * math.sin(LIFT), LENGTH * (1 - math.cos(LIFT)))
        else:
            body.position = (x, 0.0)
        ball = pymunk.Circle(body, RADIUS)
        ball.elasticity, ball.friction = 1.0, 0.0
        space.add(body, ball, pymunk.PinJoint(space.static_body, body, (x, LENGTH), (0, 0)))
    return space


def measure(dt: float, seconds: float, fps: int = 25, space: Any = None,
            recorder: Any = None) -> dict[str, float]:
    """Run the cradle for ``seconds`` at step ``dt`` (s; a whole number of steps per frame of
    1/``fps`` s): the largest energy drift |E - E0| / E0 at the frames, the last one, and the
    largest relative change of the row's horizontal momentum across an impact (at the bottom
    the pins pull only vertically, so the impact must keep it). ``space``: a built cradle to
    run (default: a new one); ``recorder`` captures each frame."""
    from .. import spaces

    dt, seconds, fps = check_run(dt, seconds, fps)
    check_tools(space, recorder)
    space = build() if space is None else space
    balls = [b for b in space.bodies]
    e0 = spaces.energy(space).E
    touching = [False]

    def contact(arbiter: Any, space: Any, data: Any) -> None:
        touching[0] = True

    space.on_collision(None, None, post_solve=contact)
    steps = round(1.0 / (fps * dt))
    worst_e = worst_p = drift = 0.0
    before = None
    for _ in range(round(seconds * fps)):
        for _ in range(steps):
            px = sum(b.mass * b.velocity.x for b in balls)
            touching[0] = False
            space.step(dt)
            if touching[0] and before is None:
                before = px
            elif not touching[0] and before is not None:
                after = sum(b.mass * b.velocity.x for b in balls)
                worst_p = max(worst_p, abs(after - before) / abs(before))
                before = None
        drift = abs(spaces.energy(space).E - e0) / e0
        worst_e = max(worst_e, drift)
        if recorder is not None:
            recorder.capture()
    return {"energy_drift_max": worst_e, "energy_drift_end": drift,
            "momentum_change_max": worst_p}


def main(argv: list[str] | None = None) -> int:

    args = arguments("newtons_cradle", __doc__, 10.0, argv)
    space = build()
    print_guard(space, args)
    return record_and_compare(
        args, space, measure,
        lambda dt, m: (f"dt = {dt:.3g} s over {args.seconds:g} s: energy drift max "
                       f"{m['energy_drift_max']:.2e}, at the end {m['energy_drift_end']:.2e}; "
                       f"momentum change across an impact max {m['momentum_change_max']:.2e}"),
        title="Newton's cradle")


if __name__ == "__main__":
    sys.exit(main())
