"""A physical pendulum on a rotary spring: a rod on a pivot, held by a DampedRotarySpring.

    python -m dumbbell.examples.pendulum [--out pendulum.gif] [--seconds 10] [--dt 1e-3]

A uniform rod of mass m and length L hangs from a pivot at its top end; a rotary spring of
stiffness kappa (N m/rad) between the rod and the world adds its torque to gravity's. For
small swings theta'' = -(m g d + kappa) / I theta, with d = L/2 the pivot's distance from the
centre of gravity and I = m L^2 / 3 the moment about the pivot, so the period is
T = 2 pi sqrt(I / (m g d + kappa)). The rod starts 3 degrees out; the period is measured from
the upward zero crossings of the angle (interpolated between steps) and compared with that
formula, and with the formula plus its first finite-amplitude correction (gravity's share of
the stiffness times theta0^2 / 16). Printed: the guard's report, the periods, and the drift
of E (gravity, the rotary spring, the rod's translation and spin) over the run.
"""

from __future__ import annotations

import itertools
import math
import sys
from typing import Any

from . import arguments, check_run, check_tools, print_guard, record_and_compare

#: No public names: a program, run as ``python -m dumbbell.examples.pendulum``.
__all__: list[str] = []

#: Rod mass (kg), length (m), width (m), spring stiffness (N m/rad), pivot height (m: the rod
#: hangs with its centre of gravity at y = 0, where U_g is zero), starting angle (rad).
MASS, LENGTH, WIDTH, KAPPA, PIVOT, THETA0 = 1.0, 1.0, 0.04, 5.0, 0.5, math.radians(3.0)


def build(theta0: float = THETA0) -> Any:
    """The pendulum's space: the rod on a PivotJoint and a DampedRotarySpring to the world."""
    import pymunk

    from ..model import args

    theta0 = args.real(theta0, "theta0", "rad", positive=False)
    space = pymunk.Space()
    space.gravity = (0.0, -9.81)
    rod = pymunk.Body(MASS, pymunk.moment_for_box(MASS, (WIDTH, LENGTH)))
    rod.angle = theta0
    d = LENGTH / 2
    rod.position = (d * math.sin(theta0), PIVOT - d * math.cos(theta0))
    shape = pymunk.Poly.create_box(rod, (WIDTH, LENGTH))
    pivot = pymunk.PivotJoint(space.static_body, rod, (0.0, PIVOT))
    spring = pymunk.DampedRotarySpring(rod, space.static_body, 0.0, KAPPA, 0.0)
    space.add(rod, shape, pivot, spring)
    return space


def small_angle_period() -> float:
    """T = 2 pi sqrt(I_pivot / (m g d + kappa)) (s)."""
    d = LENGTH / 2
    inertia = MASS * (LENGTH**2 + WIDTH**2) / 12 + MASS * d**2
    return 2 * math.pi * math.sqrt(inertia / (MASS * 9.81 * d + KAPPA))


def amplitude_corrected_period(theta0: float = THETA0) -> float:
    """The small-angle period with gravity's first finite-amplitude correction: its share of
    the stiffness times theta0^2 / 16 (the spring's torque is linear, gravity's is sin)."""
    from ..model import args

    theta0 = args.real(theta0, "theta0", "rad", positive=False)
    share = MASS * 9.81 * LENGTH / 2 / (MASS * 9.81 * LENGTH / 2 + KAPPA)
    return small_angle_period() * (1 + share * theta0**2 / 16)


def measure(dt: float, seconds: float, fps: int = 25, space: Any = None,
            recorder: Any = None) -> dict[str, float]:
    """Run for ``seconds`` at step ``dt`` (s): the mean period between upward zero crossings
    of the rod's angle (s) and the largest |E - E0| / E0."""
    from .. import spaces

    dt, seconds, fps = check_run(dt, seconds, fps)
    check_tools(space, recorder)
    space = build() if space is None else space
    rod = next(iter(space.bodies))
    e0 = spaces.energy(space).E
    steps = round(1.0 / (fps * dt))
    crossings: list[float] = []
    prev, worst = rod.angle, 0.0
    n = 0
    for _ in range(round(seconds * fps)):
        for _ in range(steps):
            space.step(dt)
            n += 1
            a = rod.angle
            if prev < 0.0 <= a:
                crossings.append((n - 1) * dt + dt * (-prev) / (a - prev))
            prev = a
        worst = max(worst, abs(spaces.energy(space).E - e0) / e0)
        if recorder is not None:
            recorder.capture()
    periods = [b - a for a, b in itertools.pairwise(crossings)]
    return {"period": sum(periods) / len(periods) if periods else math.nan,
            "periods": len(periods), "energy_drift_max": worst}


def main(argv: list[str] | None = None) -> int:

    args = arguments("pendulum", __doc__, 10.0, argv)
    space = build()
    print_guard(space, args)
    T0, T1 = small_angle_period(), amplitude_corrected_period()
    return record_and_compare(
        args, space, measure,
        lambda dt, m: (f"dt = {dt:.3g} s: period {m['period']:.6f} s over {m['periods']} "
                       f"swings, {(m['period'] - T0) / T0:+.3%} from the small-angle formula, "
                       f"{(m['period'] - T1) / T1:+.1e} from the corrected one; energy drift "
                       f"max {m['energy_drift_max']:.2e}"),
        f"small-angle period {T0:.6f} s; with the amplitude correction {T1:.6f} s",
        title="Pendulum on a rotary spring", world=(-0.45, 0.45, -0.55, 0.55))


if __name__ == "__main__":
    sys.exit(main())
