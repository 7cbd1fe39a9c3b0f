"""The step guard's own numbers against independent measurements (issue 28's targets).

    python benchmarks/guard_accuracy.py            # both parts
    python benchmarks/guard_accuracy.py --forces   # sub-steps keep the program's push
    python benchmarks/guard_accuracy.py --joints   # the joint rows against the ledger

**Forces.** A body pushed once a frame in each way a program does it (``Body.force``,
``Body.torque``, ``apply_force_at_world_point``, ``apply_force_at_local_point``, a force
through a custom ``velocity_func``: ``tests/guard_cases.py``), one frame of 0.05 s through
``spaces.step`` and ``spaces.Driver`` with 1 and with 7 and 80 sub-steps: the largest
relative difference of the velocity and spin from the one-step frame (the target: 1e-9).
Then the car of ``tests/guard_cases.py`` (wheel torques set each frame, suspension
springs) driven 2 s at 1/60 s with 1 sub-step and with the guard's sub-steps, through
``Driver``; and, for comparison, stepped at the guard's sub-steps by ``space.step`` alone
(the push in the first sub-step only, as before the fix).

**Joints.** Pendulums of ``tests/guard_cases.py`` (pixel units, g = 900 px/s^2, released
from rest) at dt = 1/60 and 1/600 s: the drift per second the guard's row states, against
``spaces.Ledger``'s joint term over 2 s of the user's own space, divided by 2 s (the
target: within a factor 2). The probe's cost is printed as its steps and its time, next to
the time of the same steps of bare ``space.step`` (side by side in one run; 2 shared cores:
compare the columns of one run, not runs).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

FRAME = 0.05


def forces() -> None:
    from tests.guard_cases import PUSHES, car, pushed

    from dumbbell import spaces

    print("per-frame push, one frame of 0.05 s: largest |v_n - v_1| / |v_1| over vx, vy, w")
    print(f"{'push':16s} {'through':8s} {'n = 7':>10s} {'n = 80':>10s}")
    worst = 0.0
    for how in PUSHES:
        for through in ("step", "Driver"):
            got = {}
            for n in (1, 7, 80):
                space, push = pushed(how)
                push()
                if through == "step":
                    spaces.step(space, FRAME, substeps=n)
                else:
                    spaces.Driver(space, FRAME, substeps=n).step()
                (body,) = space.bodies
                got[n] = (*body.velocity, body.angular_velocity)
            diffs = [max(abs(a - b) / max(abs(b), 1e-300) for a, b in
                         zip(got[n], got[1], strict=True)) for n in (7, 80)]
            worst = max(worst, *diffs)
            print(f"{how:16s} {through:8s} {diffs[0]:10.2g} {diffs[1]:10.2g}")
    print(f"worst: {worst:.2g} (target 1e-9)")
    n = spaces.substeps(car().space, 1 / 60)
    speeds = {}
    for label, sub, bare in (("1 sub-step (Driver)", 1, False),
                             (f"{n} sub-steps (Driver)", n, False),
                             (f"{n} sub-steps, space.step alone", n, True)):
        c = car()
        driver = spaces.Driver(c.space, 1 / 60, substeps=sub)
        for _ in range(120):
            c.drive()
            if bare:
                for _ in range(sub):
                    c.space.step(1 / 60 / sub)
            else:
                driver.step()
        speeds[label] = c.chassis.velocity.x
    base = speeds["1 sub-step (Driver)"]
    print(f"\ncar on wheel torques, 2 s at 1/60 s, the guard's sub-steps: {n}")
    for label, v in speeds.items():
        print(f"  {label:34s} {v:12.6f} px/s  (v / v_1 - 1 = {v / base - 1:+.2g})")


def joints() -> None:
    from tests.guard_cases import pendulum

    from dumbbell import spaces
    from dumbbell.spaces._probe import probe

    cases = [("PinJoint, L = 200 px, from level", lambda: pendulum()),
             ("PinJoint, L = 100 px, from level", lambda: pendulum(length=100.0)),
             ("PinJoint, L = 200 px, from 1 rad below", lambda: pendulum(angle=1.0)),
             ("PinJoint, 3 kg, g = 500", lambda: pendulum(mass=3.0, gravity=500.0)),
             ("SlideJoint (taut), L = 200 px", lambda: pendulum("SlideJoint")),
             ("PivotJoint, a bar of 200 px", lambda: pendulum("PivotJoint"))]
    print(f"{'pendulum':40s} {'dt (s)':>8s} {'guard (/s)':>11s} {'ledger (/s)':>12s} "
          f"{'ratio':>7s} {'probe steps':>12s} {'probe (s)':>10s} {'bare (s)':>9s}")
    for name, make in cases:
        for dt in (1 / 60, 1 / 600):
            (row,) = [f for f, _ in spaces.survey(make(), dt, units="px") if f.kind == "joint"]
            sign = -1.0 if "takes out" in row.note else 1.0
            stated = sign * row.value
            space = make()
            ledger = spaces.Ledger(space)
            steps = round(2.0 / dt)
            for _ in range(steps):
                space.step(dt)
            balance = ledger.balance()
            ledger.detach()
            measured = sum(t.energy for t in balance.terms if t.kind == "constraint") / 2.0
            found = probe(make(), dt, [0])
            bare = make()
            t0 = time.perf_counter()
            for _ in range(found.steps):
                bare.step(dt)
            bare_s = time.perf_counter() - t0
            ratio = stated / measured if measured else math.nan
            print(f"{name:40s} {dt:8.4g} {stated:11.5g} {measured:12.5g} {ratio:7.4f} "
                  f"{found.steps:12,d} {found.cost:10.3f} {bare_s:9.4f}")
    print("guard and ledger in kg px^2/s^2 per s (what the joint puts in: negative, it takes "
          "out); ratio = guard / ledger (target: within a factor 2)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--forces", action="store_true")
    parser.add_argument("--joints", action="store_true")
    a = parser.parse_args(argv)
    both = not (a.forces or a.joints)
    if a.forces or both:
        forces()
    if a.joints or both:
        print()
        joints()
    return 0


if __name__ == "__main__":
    sys.exit(main())
