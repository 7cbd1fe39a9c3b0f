"""spaces.Ledger: how well it closes on pymunk's own examples, and what it costs per step.

    python benchmarks/spaces_ledger.py            # the closure table, then the costs
    python benchmarks/spaces_ledger.py --table    # only the table (the one in docs/spaces.md)
    python benchmarks/spaces_ledger.py --cost [--steps 300] [--repeat 3]

The table runs every case of ``tests/ledger_cases.py``: each constraint kind of pymunk's
constraints demo alone, and the corpus examples (headless, loaded from the installed
pymunk). Closure is |E(t) - E(0) - sum of the terms| / scale, printed as a power-of-ten
bound; scale is the largest kinetic energy and change of a potential seen.

The cost: box2d_pyramid (325 boxes), kept awake (``sleep_time_threshold = inf``), copied
twice after its first 100 steps; one copy steps bare, the other with a ledger attached (its
first step apart: it reads the space whole). They step in blocks of 10 steps, alternately,
the order swapped from one pair of blocks to the next (so that neither always runs on the
caches the other warmed), ``--steps`` each, ``--repeat`` times on fresh copies; the two
copies move bit for bit alike (checked). Each block is timed by the thread's CPU clock
(``time.thread_time``): time the process spends waiting for a core on a loaded machine is
not the ledger's, and a wall clock charges it to whichever block it falls in, longer
blocks more often. Printed: median CPU time of a bare ``space.step`` and of a step with the
ledger, over the blocks; the ledger's own (their difference) as a ratio to the step, the
median and the quartiles of that ratio over the pairs of blocks; and the machine's load.
Then ``spaces.energy`` on the same pyramid, median of 50 calls.
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


def cost(steps: int, repeat: int, block: int = 10) -> None:
    from dumbbell import spaces

    base, dt = pyramid()
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
    print(f"box2d_pyramid, {len(list(base.bodies))} bodies awake, {steps} x {repeat} steps each "
          f"in blocks of {block}, alternately; CPU time of this thread (load {' '.join(load)})")
    print(f"  space.step alone      {step * 1e3:.3f} ms (median)")
    print(f"  space.step + ledger   {both * 1e3:.3f} ms")
    print(f"  ledger                {(both - step) * 1e3:.3f} ms  = "
          f"{statistics.median(ratios):.2f} x space.step (quartiles {q[0]:.2f}-{q[2]:.2f})")
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
    a = parser.parse_args()
    if not a.cost:
        print(closure_table())
    if not a.table:
        if not a.cost:
            print()
        cost(a.steps, a.repeat)


if __name__ == "__main__":
    main()
