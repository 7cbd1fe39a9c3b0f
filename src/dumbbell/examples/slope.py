"""A box sliding and tumbling down a slope with friction; the heat counter closes the balance.

    python -m dumbbell.examples.slope [--out slope.gif] [--seconds 3] [--dt 1e-3]

A 20 x 10 cm box of 1 kg is thrown spinning onto a 30 degree slope (friction coefficient 0.4,
an inelastic contact): it tumbles, lands on a face and slides on. Friction and the impacts
turn energy into heat, which :class:`dumbbell.spaces.HeatCounter` sums impact by impact from
the contact impulses. The balance E(0) = E(t) + heat + error leaves the method's error, which
shrinks in proportion to dt; the run is repeated at dt / 10 to show it. Printed: the guard's
report, then at both steps E(0), E(t), the heat and what is left, relative to the heat.
"""

from __future__ import annotations

import math
import sys
from typing import Any

from . import arguments, check_run, check_tools, print_guard, record_and_compare

#: No public names: a program, run as ``python -m dumbbell.examples.slope``.
__all__: list[str] = []

#: Slope angle (rad), friction coefficient, restitution, box size (m), mass (kg), spin (rad/s).
ANGLE, MU, ELASTICITY, SIZE, MASS, SPIN = math.radians(30), 0.4, 0.2, (0.2, 0.1), 1.0, -12.0
#: Length of the slope (m); its foot is at y = 0, where U_g is zero.
RAMP = 6.0


def build() -> Any:
    """The slope's space: a static ramp down to the right with its foot at y = 0, and the box
    just above its upper end, spinning."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    space.collision_slop = 1e-4  # SI units: pymunk's 0.1 would be 10 cm
    space.collision_bias = 1.0   # no position correction, which adds energy
    c, s = math.cos(ANGLE), math.sin(ANGLE)
    top = RAMP * s
    ramp = pymunk.Poly(space.static_body, [(0.0, top), (RAMP * c, 0.0), (RAMP * c, -0.1),
                                           (0.0, top - 0.1)])
    ramp.friction, ramp.elasticity = MU, ELASTICITY
    box = pymunk.Body(MASS, pymunk.moment_for_box(MASS, SIZE))
    box.angle = -ANGLE
    lift = SIZE[1] / 2 + 0.15
    box.position = (0.4 * c + lift * s, top - 0.4 * s + lift * c)
    box.angular_velocity = SPIN
    shape = pymunk.Poly.create_box(box, SIZE)
    shape.friction, shape.elasticity = 1.0, 1.0  # pymunk multiplies: the ramp's values count
    space.add(ramp, box, shape)
    return space


def measure(dt: float, seconds: float, fps: int = 25, space: Any = None, recorder: Any = None,
            heat: Any = None) -> dict[str, float]:
    """Run for ``seconds`` at step ``dt`` (s): E(0), E(t), the heat (J) and the distance the
    box travelled (m)."""
    from .. import spaces

    dt, seconds, fps = check_run(dt, seconds, fps)
    check_tools(space, recorder, heat)
    space = build() if space is None else space
    heat = spaces.HeatCounter(space, units="m") if heat is None else heat
    box = next(iter(space.bodies))
    start = box.position
    e0 = spaces.energy(space).E
    steps = round(1.0 / (fps * dt))
    for _ in range(round(seconds * fps)):
        for _ in range(steps):
            space.step(dt)
        if recorder is not None:
            recorder.capture()
    return {"E0": e0, "E": spaces.energy(space).E, "heat": heat.total,
            "distance": (box.position - start).length}


def main(argv: list[str] | None = None) -> int:
    from .. import spaces

    args = arguments("slope", __doc__, 2.0, argv)
    space = build()
    print_guard(space, args)
    heat = spaces.HeatCounter(space, units="m")
    c, s = math.cos(ANGLE), math.sin(ANGLE)

    def line(dt: float, m: dict[str, float]) -> str:
        left = m["E0"] - m["E"] - m["heat"]
        return (f"dt = {dt:.3g} s: E(0) = {m['E0']:.5f} J, E(t) = {m['E']:.5f} J, heat "
                f"{m['heat']:.5f} J over {m['distance']:.3f} m; E(0) - E(t) - heat = "
                f"{left:+.2e} J ({left / m['heat']:+.2e} of the heat)")

    return record_and_compare(
        args, space, measure, line, heat=heat, title="Box on a slope",
        world=(-0.1, RAMP * c + 0.05, -0.15, RAMP * s + 0.45))


if __name__ == "__main__":
    sys.exit(main())
