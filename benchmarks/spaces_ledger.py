"""spaces.Ledger: how well it closes on pymunk's own examples, and what it costs per step.

    python benchmarks/spaces_ledger.py            # the closure table, then the costs
    python benchmarks/spaces_ledger.py --table    # only the table (the one in docs/spaces.md)
    python benchmarks/spaces_ledger.py --cost [--steps 300] [--repeat 3]

The table runs every case of ``tests/ledger_cases.py``: each constraint kind of pymunk's
constraints demo alone, and the corpus examples (headless, loaded from the installed
pymunk). Closure is |E(t) - E(0) - sum of the terms| / scale, printed as a power-of-ten
bound; scale is the largest kinetic energy and change of a potential seen.

The cost: box2d_pyramid (325 boxes), kept awake (``sleep_time_threshold = inf``), copied
twice after 100 steps; one copy steps bare, the other with a ledger attached, alternately
step by step, ``--steps`` each, ``--repeat`` times. Printed: median time of a bare
``space.step``, of a step with the ledger, the ledger's own (their difference), and the
ratio ledger / step. Then ``spaces.energy`` on the same pyramid, median of 50 calls.
Ratios taken side by side in one run hold on a loaded machine better than the times.
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


def cost(steps: int, repeat: int) -> None:
    from dumbbell import spaces

    base, dt = pyramid()
    bare_t: list[float] = []
    with_t: list[float] = []
    for _ in range(repeat):
        bare, counted = base.copy(), base.copy()
        ledger = spaces.Ledger(counted)  # it counts while it is referenced
        counted.step(dt)  # the ledger's compiled loops load (or compile) here
        bare.step(dt)
        for _ in range(steps):
            t0 = time.perf_counter()
            bare.step(dt)
            t1 = time.perf_counter()
            counted.step(dt)
            t2 = time.perf_counter()
            bare_t.append(t1 - t0)
            with_t.append(t2 - t1)
        assert ledger.balance().steps == steps + 1
    step, both = statistics.median(bare_t), statistics.median(with_t)
    print(f"box2d_pyramid, {len(list(base.bodies))} bodies awake, {steps} x {repeat} steps "
          "alternately:")
    print(f"  space.step alone      {step * 1e3:.3f} ms (median)")
    print(f"  space.step + ledger   {both * 1e3:.3f} ms")
    print(f"  ledger                {(both - step) * 1e3:.3f} ms  = {(both - step) / step:.2f}"
          " x space.step")
    calls = []
    for _ in range(50):
        t0 = time.perf_counter()
        spaces.energy(base)
        calls.append(time.perf_counter() - t0)
    print(f"  spaces.energy         {statistics.median(calls) * 1e3:.3f} ms a call (median "
          f"of 50) = {statistics.median(calls) / step:.1f} x space.step")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", action="store_true", help="only the closure table")
    parser.add_argument("--cost", action="store_true", help="only the costs")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--repeat", type=int, default=3)
    a = parser.parse_args()
    if not a.cost:
        print(closure_table())
    if not a.table:
        if not a.cost:
            print()
        cost(a.steps, a.repeat)


if __name__ == "__main__":
    main()
