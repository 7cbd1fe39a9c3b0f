"""The ``pymunk`` solver: its speed against a bare ``Space.step`` loop, and its accuracy.

1. Speed, side by side in one process: the same space (built by the solver's own ``build``)
   stepped in a bare ``for _ in range(n): space.step(dt)`` loop, against ``simulate(scene,
   "pymunk", every=N)`` which also reads the state back every N-th step and records impacts.
   Alternated ``--repeat`` times; the best (= minimum time, the usual convention on a shared
   machine) and median steps/s, the ratio of the best rates and the median of the paired
   ratios. Goal: the ratio >= 0.8 at every = 100.
2. Accuracy on the textbook scene: pymunk and the textbook's Euler-Cromer against the exact
   solution at dt = 1e-4, 1e-5, 1e-6: the largest position error of either particle over
   [0, 2 s] (before the chaotic motion parts the runs) and the energy error over the whole
   run, as ``dumbbell compare`` and ``dumbbell bench`` report them (dumbbell.analysis.metrics).

Usage: python benchmarks/pymunk_speed.py [--repeat 5] [--steps 300000] [--t-end 10]
Prints markdown tables.
"""

from __future__ import annotations

import argparse
import statistics
import time

from dumbbell.analysis.metrics import energy_error, position_error
from dumbbell.model.scene import load_scene, packaged_scene
from dumbbell.solvers import simulate
from dumbbell.solvers.engine import build


def bare_rate(scene, dt: float, steps: int) -> float:
    """Steps per second of a bare Space.step loop on the solver's own space."""
    step = build(scene).space.step
    t0 = time.perf_counter()
    for _ in range(steps):
        step(dt)
    return steps / (time.perf_counter() - t0)


def solver_rate(scene, dt: float, steps: int, every: int) -> float:
    """Steps per second of the pymunk solver (its own timer: the stepping loop)."""
    run = simulate(scene, "pymunk", dt=dt, t_end=steps * dt, every=every)
    return run.info["steps"] / run.wall_time


def speed(scene, repeat: int, steps: int) -> None:
    dt = 1e-5
    bare_rate(scene, dt, 10_000)  # warm-up: import, first allocations
    rows = []
    for every in (100, 10, 1):
        bare, ours, ratio = [], [], []
        for _ in range(repeat):
            b = bare_rate(scene, dt, steps)
            s = solver_rate(scene, dt, steps, every)
            bare.append(b)
            ours.append(s)
            ratio.append(s / b)
        rows.append((every, bare, ours, ratio))
    print(f"### pymunk solver against a bare Space.step loop ({scene.name}, dt = {dt:g} s, "
          f"{steps} steps, {repeat} alternating repeats)\n")
    print("| every | bare loop steps/s (best / median) | pymunk solver steps/s (best / median) "
          "| ratio of best rates | median of paired ratios |")
    print("|---:|---:|---:|---:|---:|")
    for every, bare, ours, ratio in rows:
        print(f"| {every} | {max(bare):.3g} / {statistics.median(bare):.3g} "
              f"| {max(ours):.3g} / {statistics.median(ours):.3g} "
              f"| {max(ours) / max(bare):.2f} | {statistics.median(ratio):.2f} |")
    print()


def accuracy(scene, t_end: float, window: float = 2.0) -> None:
    print(f"### Against the exact solution ({scene.name}, t_end = {t_end:g} s): largest "
          f"position error of either particle over [0, {window:g}] s, energy error over the "
          "whole run\n")
    print("| solver | dt [s] | max position error [m] | energy error | impacts (exact: n) "
          "| run time [s] |")
    print("|---|---:|---:|---:|---:|---:|")
    for dt in (1e-4, 1e-5, 1e-6):
        every = round(1e-3 / dt)
        exact = simulate(scene, "exact", dt=dt, t_end=t_end, every=every)
        for name in ("pymunk", "euler-cromer"):
            run = simulate(scene, name, dt=dt, t_end=t_end, every=every)
            print(f"| {name} | {dt:g} | {position_error(run, exact, window):.2e} "
                  f"| {energy_error(run, exact):.2e} | {len(run.events)} ({len(exact.events)}) "
                  f"| {run.wall_time:.3g} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--steps", type=int, default=300_000)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--skip-accuracy", action="store_true")
    args = parser.parse_args()
    scene = load_scene(packaged_scene("textbook-1d"))
    speed(scene, args.repeat, args.steps)
    if not args.skip_accuracy:
        accuracy(scene, args.t_end)


if __name__ == "__main__":
    main()
