"""spaces.Ledger: how well it closes on pymunk's own examples, and what it costs per step.

    python benchmarks/spaces_ledger.py            # the closure table, then the costs
    python benchmarks/spaces_ledger.py --table    # only the table (the one in docs/spaces-reference.md)
    python benchmarks/spaces_ledger.py --cost [--steps 300] [--repeat 3] [--space pyramid]

The table runs every case of ``tests/ledger_cases.py``: each constraint kind of pymunk's
constraints demo alone, and the corpus examples (headless, loaded from the installed
pymunk). Closure is |E(t) - E(0) - sum of the terms| / scale, printed as a power-of-ten
bound; scale is the largest kinetic energy and change of a potential seen.

The cost: box2d_pyramid (325 boxes), kept awake (``sleep_time_threshold = inf``), copied
twice after its first 100 steps; one copy steps bare, the other with a ledger attached (its
first step apart: it reads the space whole). They step in blocks of 16 steps (the ledger does
its contacts' work 16 steps at a time: each block holds one such batch), alternately,
the order swapped from one pair of blocks to the next (so that neither always runs on the
caches the other warmed), ``--steps`` each, ``--repeat`` times on fresh copies; the two
copies move bit for bit alike (checked). Each block is timed by the thread's CPU clock
(``time.thread_time``): time the process spends waiting for a core on a loaded machine is
not the ledger's, and a wall clock charges it to whichever block it falls in, longer
blocks more often. Printed: median CPU time of a bare ``space.step`` and of a step with the
ledger, over the blocks; the ledger's own (their difference) as a ratio to the step, the
median and the quartiles of that ratio over the pairs of blocks, and the ratio of all the
blocks' times together; and the machine's load.
Then ``spaces.energy`` on the same pyramid, median of 50 calls.

``--space large`` (or ``all``) times the same way a larger space built here: a pyramid of
820 boxes on a floor, 200 balls thrown into a heap beside it, a chain of 60 links on pivot
joints (every third with a finite ``max_force``) swinging from the static body, and 23
springs and 23 pin joints between bodies of the pyramid (1,080 bodies, about 2,300
touching pairs, 106 joints), copied after its first 100 steps, awake.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def closure_table() -> str:
    from tests.ledger_cases import CASES, run, table

    return table([run(case) for case in CASES])


def pyramid() -> tuple[object, float]:
    """The pyramid's space after 100 steps, awake, and its step (s)."""
    from tests.pymunk_corpus import run_example

    run = run_example("box2d_pyramid", 2)
    space = run.space
    space.sleep_time_threshold = math.inf
    for _ in range(100):
        space.step(run.dts[0])
    return space, run.dts[0]


def large() -> tuple[object, float]:
    """The larger space (see the module docstring) after 100 steps, awake, and its step."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -900.0)
    space.sleep_time_threshold = math.inf
    floor = pymunk.Segment(space.static_body, (-2000, 0), (4000, 0), 5)
    floor.friction = 0.8
    space.add(floor)
    bodies = []
    for i in range(40):  # 820 boxes of 20 x 20
        for j in range(40 - i):
            box = pymunk.Body(1, pymunk.moment_for_box(1, (20, 20)))
            box.position = (j * 21 + i * 10.5 + (j % 7) * 0.01, 10 + i * 21)
            shape = pymunk.Poly.create_box(box, (20, 20))
            shape.friction, shape.elasticity = 0.6, 0.1
            space.add(box, shape)
            bodies.append(box)
    for k in range(200):  # balls in a heap
        ball = pymunk.Body(2, pymunk.moment_for_circle(2, 0, 6))
        ball.position = (1000 + (k % 20) * 13, 20 + (k // 20) * 13)
        ball.velocity = ((k * 37) % 101 - 50.0, (k * 53) % 101 - 50.0)
        shape = pymunk.Circle(ball, 6)
        shape.friction, shape.elasticity = 0.3, 0.5
        space.add(ball, shape)
        bodies.append(ball)
    prev = space.static_body
    for k in range(60):  # a chain on pivots
        link = pymunk.Body(1, 10)
        link.position = (1510 + 10 * k, 600)
        joint = pymunk.PivotJoint(prev, link, (1500 + 10 * k, 600))
        joint.max_force = 5e5 if k % 3 else math.inf
        space.add(link, pymunk.Circle(link, 3), joint)
        prev = link
    for k in range(0, 820, 37):
        space.add(pymunk.DampedSpring(bodies[k], bodies[k + 1], (0, 0), (0, 0), 25, 50, 0.5),
                  pymunk.PinJoint(bodies[k], bodies[k + 2]))
    dt = 1 / 60
    for _ in range(100):
        space.step(dt)
    return space, dt


SPACES = {"pyramid": ("box2d_pyramid", pyramid), "large": ("the large space", large)}


def cost(steps: int, repeat: int, space: str = "pyramid") -> None:
    from dumbbell import spaces
    from dumbbell.spaces._contacts import Contacts

    block = Contacts.BATCH  # each block holds one batch of the contacts' work

    name, make = SPACES[space]
    base, dt = make()
    bare_t: list[float] = []
    with_t: list[float] = []
    ratios: list[float] = []
    clock = time.thread_time
    for _ in range(repeat):
        bare, counted = base.copy(), base.copy()
        ledger = spaces.Ledger(counted)  # it counts while it is referenced
        counted.step(dt)  # the ledger's first step reads the space whole
        bare.step(dt)
        for k in range(steps // block):
            pair = {}
            for which in ((bare, counted) if k % 2 else (counted, bare)):
                t0 = clock()
                for _ in range(block):
                    which.step(dt)
                pair[id(which)] = (clock() - t0) / block
            b, w = pair[id(bare)], pair[id(counted)]
            bare_t.append(b)
            with_t.append(w)
            ratios.append((w - b) / b)
        assert ledger.balance().steps == 1 + block * (steps // block)
        assert [tuple(x.position) + tuple(x.velocity) for x in bare.bodies] == \
            [tuple(x.position) + tuple(x.velocity) for x in counted.bodies]
    step, both = statistics.median(bare_t), statistics.median(with_t)
    q = statistics.quantiles(ratios, n=4)
    load = Path("/proc/loadavg").read_text().split()[:3] if Path("/proc/loadavg").exists() \
        else ["?"] * 3
    print(f"{name}, {len(list(base.bodies))} bodies awake, {len(base.constraints)} joints, "
          f"{steps} x {repeat} steps each in blocks of {block}, alternately; CPU time of this "
          f"thread (load {' '.join(load)})")
    print(f"  space.step alone      {step * 1e3:.3f} ms (median)")
    print(f"  space.step + ledger   {both * 1e3:.3f} ms")
    print(f"  ledger                {(both - step) * 1e3:.3f} ms  = "
          f"{statistics.median(ratios):.2f} x space.step (quartiles {q[0]:.2f}-{q[2]:.2f}; "
          f"all blocks' time together: {sum(with_t) / sum(bare_t) - 1:.2f} x)")
    if space != "pyramid":
        return
    calls = []
    for _ in range(50):
        t0 = clock()
        spaces.energy(base)
        calls.append(clock() - t0)
    print(f"  spaces.energy         {statistics.median(calls) * 1e3:.3f} ms a call (median "
          f"of 50) = {statistics.median(calls) / step:.1f} x space.step")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", action="store_true", help="only the closure table")
    parser.add_argument("--cost", action="store_true", help="only the costs")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--space", choices=[*SPACES, "all"], default="pyramid",
                        help="the space the costs are taken on (default: the pyramid)")
    a = parser.parse_args()
    if not a.cost:
        print(closure_table())
    if not a.table:
        if not a.cost:
            print()
        for which in (SPACES if a.space == "all" else [a.space]):
            cost(a.steps, a.repeat, which)


if __name__ == "__main__":
    main()
