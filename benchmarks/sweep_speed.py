"""The 50x50 Euler-Cromer sweep: a local process pool against the same sweep run serially,
and the measured blow-up boundary against the theory's w*dt = 2.

1. Speed, side by side in one run: the textbook scene over k = 1e2..1e7 N/m and
   dt = 1e-6..1e-2 s (50 x 50 log-spaced, t_end = 1 s, about 3e8 steps in all), once with
   ``--workers 1`` (in this process) and once on a pool of ``--workers`` processes (default 2),
   alternated ``--repeat`` times. Pool times include starting the processes. The CSVs of the
   two must be byte-identical. Reports the best (minimum) and median times and the speed-up.
2. The boundary against the theory's w*dt = 2: by bisection on w*dt for each time-stepping
   solver, k and mass ratio (no floor: only the spring's limit counts), and on the 50x50
   grids: for each k the largest dt below which every run is ok, on the textbook scene
   (floor, gravity, run.unstable_energy = 10) and on the stiff no-floor scene.

Usage: python benchmarks/sweep_speed.py [--repeat 3] [--workers 2] [--n 50] [--skip-speed]
       [--skip-boundary]
Prints markdown tables.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _sweep(scene, n: int, workers: int, t_end: float = 1.0):
    """Run the n x n sweep; returns (wall s, CPU s of this process and its children, result)."""
    from dumbbell.analysis.sweep import SweepOptions, parse_axis, run_sweep

    axes = [parse_axis(f"k=log:1e2:1e7:{n}"), parse_axis(f"dt=log:1e-6:1e-2:{n}")]
    c0, t0 = os.times(), time.perf_counter()
    result = run_sweep(scene, axes, SweepOptions("euler-cromer", t_end, workers))
    wall, c1 = time.perf_counter() - t0, os.times()
    cpu = sum(c1[:4]) - sum(c0[:4])
    return wall, cpu, result


def speed(n: int, workers: int, repeat: int) -> None:
    from dumbbell.io.sweep import csv_text
    from dumbbell.model.scene import load_scene
    from dumbbell.solvers.euler_cromer import EulerCromer

    scene = load_scene(ROOT / "scenes" / "textbook-1d.toml")
    EulerCromer.warm_up()
    serial, pooled, cpu_s, cpu_p, texts = [], [], [], [], set()
    for _ in range(repeat):
        t, cpu, res = _sweep(scene, n, 1)
        serial.append(t)
        cpu_s.append(cpu)
        texts.add(csv_text(res))
        t, cpu, res = _sweep(scene, n, workers)
        pooled.append(t)
        cpu_p.append(cpu)
        texts.add(csv_text(res))
    load = os.getloadavg()[0]
    print(f"## {n}x{n} Euler-Cromer sweep, t_end = 1 s ({os.cpu_count()} CPUs here, load "
          f"average {load:.1f} at the end)\n")
    print("| backend | best wall [s] | median wall [s] | median CPU [s] |")
    print("|---|---|---|---|")
    print(f"| serial (--workers 1) | {min(serial):.2f} | {statistics.median(serial):.2f} | "
          f"{statistics.median(cpu_s):.2f} |")
    print(f"| process pool (--workers {workers}) | {min(pooled):.2f} | "
          f"{statistics.median(pooled):.2f} | {statistics.median(cpu_p):.2f} |")
    ratios = [s / p for s, p in zip(serial, pooled, strict=True)]
    print(f"\nspeed-up: {min(serial) / min(pooled):.2f}x (best against best), median of the "
          f"paired ratios {statistics.median(ratios):.2f}x; CSVs identical: {len(texts) == 1}. "
          f"The pool's CPU time against the serial run's, "
          f"{statistics.median(cpu_p) / statistics.median(cpu_s):.2f}, is its overhead: on "
          f"{workers} idle cores the speed-up would be about "
          f"{workers * statistics.median(cpu_s) / statistics.median(cpu_p):.2f}x.\n")


def grid_boundary(n: int, workers: int) -> None:
    """Where the 50x50 sweeps stop being stable (ok or inaccurate), against 2/w, and why the
    textbook's fails early."""
    from dumbbell.model.scene import load_scene

    for name, label in (("textbook-1d.toml", "textbook scene (floor, gravity, threshold 10)"),
                        ("extreme/stiff-wdt-1.9.toml",
                         "stiff scene (no floor, no gravity, threshold 100)")):
        scene = load_scene(ROOT / "scenes" / name)
        _, _, result = _sweep(scene, n, workers)
        rows = result.boundary()
        print(f"## Grid boundary, {label}, {n}x{n}, t_end = 1 s\n")
        print("| k [N/m] | 2/w (theory) [s] | largest stable dt [s] | its w*dt | "
              "smallest failing dt [s] | its w*dt |")
        print("|---|---|---|---|---|---|")
        for row in rows[:: max(1, len(rows) // 10)]:
            th = row["theory_dt"]
            fail = row["first_failing_dt"]
            print(f"| {row['spring.stiffness']:.3g} | {th:.3g} | {row['largest_ok_dt']:.3g} | "
                  f"{row['w_dt']:.2f} | {fail:.3g} | {2.0 / th * fail:.2f} |")
        ratios = [r["w_dt"] for r in rows if r["first_failing_dt"] == r["first_failing_dt"]]
        below: dict[str, int] = {}
        for r in result.rows:
            if r["verdict"] not in ("ok", "inaccurate") and r["w_dt"] < 2.0:
                below[r["verdict"]] = below.get(r["verdict"], 0) + 1
        print(f"\nw*(largest stable dt) from {min(ratios):.2f} to {max(ratios):.2f} over the "
              f"{len(ratios)} k with a failure on the grid (dt grid step "
              f"{(1e-2 / 1e-6) ** (1 / (n - 1)):.3f}x); runs that failed below w*dt = 2: "
              f"{below or 'none'}\n")


def critical_ratio(scene, solver: str, lo: float = 1.5, hi: float = 2.5, steps: int = 2000,
                   iterations: int = 24) -> float:
    """w*dt at which ``solver`` first ends early (unstable: not ``ok`` or ``inaccurate``), by
    bisection between ``lo`` (stable) and ``hi`` (not), each run ``steps`` steps long."""
    from dumbbell.solvers import simulate

    def ok(h: float) -> bool:
        dt = h / scene.system.omega
        return simulate(scene, solver, dt=dt, t_end=steps * dt).verdict.complete

    assert ok(lo) and not ok(hi)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return 0.5 * (lo + hi)


def bisected_boundary() -> None:
    """The blow-up boundary by bisection, per solver, k and mass ratio (no floor)."""
    from dumbbell.model.scene import load_scene
    from dumbbell.solvers import METHODS

    base = load_scene(ROOT / "scenes" / "extreme" / "stiff-wdt-1.9.toml")
    solvers = [s for s in ("euler-cromer", "verlet", "pymunk") if s in METHODS]
    print("## Blow-up boundary by bisection (no floor, no gravity, 2000 steps per run)\n")
    print("w*dt at which the verdict turns from ok to unstable. 'growth only': "
          "run.unstable_energy = 1e12, so only a growing solution counts; 'threshold 100': "
          "the scene's own threshold, which also catches the bounded swing h/(2-h) of a "
          "stable step (100 at h = 1.980).\n")
    print("| k [N/m] | mB/mA | " + " | ".join(
        f"{s} (growth only) | {s} (threshold 100)" for s in solvers) + " |")
    print("|---|---|" + "---|---|" * len(solvers))
    for k in (1e2, 1e4, 1e6, 1e7):
        for ratio in (1.0, 100.0):
            scene = base.with_values({"spring.stiffness": k, "bodies.A.mass": 0.1 / ratio})
            cells = []
            for solver in solvers:
                grow = critical_ratio(scene.with_values({"run.unstable_energy": 1e12}), solver)
                thr = critical_ratio(scene, solver)
                cells.append(f"{grow:.5f} | {thr:.4f}")
            print(f"| {k:.0e} | {ratio:g} | " + " | ".join(cells) + " |")
    print()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--n", type=int, default=50)
    parser.add_argument("--skip-speed", action="store_true")
    parser.add_argument("--skip-boundary", action="store_true")
    args = parser.parse_args()
    if not args.skip_speed:
        speed(args.n, args.workers, args.repeat)
    if not args.skip_boundary:
        bisected_boundary()
        grid_boundary(args.n, args.workers)
    return 0


if __name__ == "__main__":
    sys.exit(main())
