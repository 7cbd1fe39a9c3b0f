"""The 2D truths, old against new, side by side in one process.

1. The spring reference on ``scenes/tilted-2d.toml`` (2 s simulated, samples every 1 ms):
   the OLD implementation (scipy's DOP853 on the full 8-component state, rtol = atol = 1e-12,
   impacts as terminal events; kept here, and only here, as it was) against the NEW one
   (:mod:`dumbbell.solvers.reference_2d`: RK8 on d = rA - rB at a fixed step, the centre of
   mass in closed form, a floor search with a curvature bound). Warm run times (best and
   median of ``--repeat`` alternated runs) and the position error over [0, 1 s] of each
   against a tighter run: the new method at a quarter of its step angle (local error
   4^9 = 2.6e5 times smaller), and, for the old, also against itself at rtol = atol = 1e-13.
2. The rigid scene ``scenes/rigid-2d.toml`` over 10 s: the impact list of the old truth
   (the reference's DOP853, which steps over B's touch at 2.68 s) against the new
   (``exact``: the closed-form flight).

Usage: python benchmarks/truth_2d.py [--repeat 7]
Prints markdown tables.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
import warnings

import numpy as np

from dumbbell.model.scene import load_scene, packaged_scene
from dumbbell.solvers import make_options, reference_2d, simulate


def old_reference(scene, times: np.ndarray, t_end: float, rtol: float = 1e-12,
                  atol: float = 1e-12) -> tuple[np.ndarray, list[tuple[float, str]]]:
    """The reference as it was before the rewrite (2D particles and a spring): DOP853 on the
    full state with the floor as terminal events; returns the states at ``times`` (rows:
    xA, yA, vxA, vyA, xB, yB, vxB, vyB) and the impacts (t, body)."""
    from scipy.integrate import solve_ivp

    A, B = scene.system.A, scene.system.B
    mA, mB, g, k, b = A.mass, B.mass, scene.system.g, scene.system.k, scene.system.b
    e = scene.system.floor.elasticity

    def rhs(_t, y):
        dx, dy = y[0] - y[4], y[1] - y[5]
        L = math.hypot(dx, dy)
        s = -k * (L - b) / L if L > 0 else 0.0
        return [y[2], y[3], s * dx / mA, s * dy / mA - g,
                y[6], y[7], -s * dx / mB, -s * dy / mB - g]

    events = []
    for row in (1, 5):
        def event(_t, y, row=row):
            return y[row]
        event.terminal = True
        event.direction = -1
        events.append(event)
    y = np.array([A.x, A.height, A.vx, A.vy, B.x, B.height, B.vx, B.vy], dtype=float)
    t_end = max(t_end, float(times[-1]))
    out = np.empty((len(times), 8))
    t, n, impacts = 0.0, 0, []
    while True:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol,
                            events=events, dense_output=True)
        hi = int(np.searchsorted(times, sol.t[-1], side="right"))
        if hi > n:
            out[n:hi] = sol.sol(times[n:hi]).T
            n = hi
        if sol.status != 1:
            break
        hits = [(float(te[0]), i) for i, te in enumerate(sol.t_events) if len(te)]
        t, i = min(hits)
        y = np.asarray(sol.y_events[i][0], dtype=float)
        y[3 if i == 0 else 7] *= -e
        impacts.append((t, "AB"[i]))
    return out[:n], impacts


def new_reference(scene, times: np.ndarray, t_end: float, step_angle: float
                  ) -> tuple[np.ndarray, list[tuple[float, str]]]:
    cols, impacts, _, _ = reference_2d.integrate(scene, times, t_end, step_angle)
    keys = ["xA", "yA", "vxA", "vyA", "xB", "yB", "vxB", "vyB"]
    return np.column_stack([cols[c] for c in keys]), [(e.t, e.body) for e in impacts]


def position_error(Y: np.ndarray, truth: np.ndarray, times: np.ndarray, window: float) -> float:
    n = int(np.searchsorted(times, window * (1 + 1e-12), side="right"))
    return float(np.max(np.abs(Y[:n][:, [0, 1, 4, 5]] - truth[:n][:, [0, 1, 4, 5]])))


def spring(repeat: int) -> None:
    scene = load_scene(packaged_scene("tilted-2d"))
    options = make_options(scene, t_end=2.0, every=100)
    times = options.sample_times()
    reference_2d.warm_up()
    old_reference(scene, times, 2.0)
    old_t, new_t = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        Y_old, imp_old = old_reference(scene, times, 2.0)
        old_t.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        Y_new, imp_new = new_reference(scene, times, 2.0, reference_2d.STEP_ANGLE)
        new_t.append(time.perf_counter() - t0)
    tight, _ = new_reference(scene, times, 2.0, reference_2d.STEP_ANGLE / 4)
    old_tight, _ = old_reference(scene, times, 2.0, 1e-13, 1e-13)
    print("## Spring reference on tilted-2d (2 s simulated, samples every 1 ms, warm)\n")
    print("| implementation | best [s] | median [s] | position error over [0, 1 s] vs new at "
          "step/4 [m] | vs old at rtol 1e-13 [m] | impacts in 2 s |")
    print("|---|---|---|---|---|---|")
    for name, ts, Y, imp in (("old: DOP853 full state, events", old_t, Y_old, imp_old),
                             ("new: RK8 on d, CM closed form", new_t, Y_new, imp_new)):
        print(f"| {name} | {min(ts):.4f} | {statistics.median(ts):.4f} | "
              f"{position_error(Y, tight, times, 1.0):.2e} | "
              f"{position_error(Y, old_tight, times, 1.0):.2e} | {len(imp)} |")
    print(f"\nspeed-up (best / best): {min(old_t) / min(new_t):.1f}x; median of paired ratios: "
          f"{statistics.median(o / n for o, n in zip(old_t, new_t, strict=True)):.1f}x")
    diff = max(abs(a[0] - b[0]) for a, b in zip(imp_old, imp_new, strict=True))
    print(f"largest impact-time difference old vs new: {diff:.2e} s "
          f"(same bodies: {[b for _, b in imp_old] == [b for _, b in imp_new]})\n")


def rigid() -> None:
    scene = load_scene(packaged_scene("rigid-2d"))
    old = simulate(scene, "reference", every=100)
    new = simulate(scene, "exact", every=100)
    print("## Rigid scene over 10 s: impacts, old truth (reference) against new (exact)\n")
    print(f"old verdict: {old.verdict}\nnew verdict: {new.verdict}\n")
    print("| n | old t [s] | body | new t [s] | body |")
    print("|---|---|---|---|---|")
    for i in range(max(len(old.events), len(new.events))):
        o = old.events[i] if i < len(old.events) else None
        n = new.events[i] if i < len(new.events) else None
        print(f"| {i + 1} | {o.t:.6f} | {o.body} |" if o else f"| {i + 1} | - | - |", end="")
        print(f" {n.t:.6f} | {n.body} |" if n else " - | - |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    spring(args.repeat)
    rigid()


if __name__ == "__main__":
    main()
