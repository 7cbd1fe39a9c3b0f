"""The exact solution against Euler-Cromer, side by side in one process, warm.

Both run the textbook scene (``scenes/textbook-1d.toml``: 10 s, 22 impacts) through
``dumbbell.simulate`` with the same sampling, energies and verdict included: ``exact`` in
closed form, ``euler-cromer`` with its 1e6 steps of dt = 1e-5 s. The runs alternate (exact,
Euler-Cromer, exact, ...) so that a load change on the machine hits both alike; the ratio is
of the two medians, and the median of the per-pair ratios is printed beside it. Each call is
timed twice: wall clock, and the CPU time of the calling thread, which a loaded machine
inflates much less (a 12 ms run is preempted far more often than a 1 ms one). The exact
solver's own work (its impact search and sampling, ``Trajectory.wall_time``) is shown apart
from what every solver's run pays after it (the verdict, the energies, the result). The JIT is
excluded: both are compiled (or loaded from numba's cache) before the clock starts, and the
exact kernels' own first run is timed in fresh processes.

Usage: python benchmarks/exact_speed.py [--runs N] [--skip-jit]
Prints a markdown table, then how it was taken. Runs with any installed ``dumbbell`` (its
public API only), so the same script measures a checkout before and after a change.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

#: (what is measured, simulate's keyword arguments): pairs of exact and Euler-Cromer runs.
PAIRS = [
    ("every = 100: 10,001 samples (as shipped)", {"every": 100}),
    ("every = 1: all 1,000,001 samples", {"every": 1}),
]

_JIT_CODE = """
import time
from dumbbell.solvers import simulate
from dumbbell.model.scene import load_scene, packaged_scene
scene = load_scene(packaged_scene())
t0 = time.perf_counter()
simulate(scene, "exact", t_end=0.5, every=100)
print(time.perf_counter() - t0)
"""


def interleaved(runs: int, calls: dict[str, object]) -> dict[str, dict[str, list[float]]]:
    """Wall and thread CPU seconds of each call in ``calls``, ``runs`` times, the calls
    alternating, and the ``wall_time`` of the trajectory each returned."""
    times: dict[str, dict[str, list[float]]] = {
        name: {"wall": [], "cpu": [], "solver": []} for name in calls}
    for _ in range(runs):
        for name, call in calls.items():
            t0, c0 = time.perf_counter(), time.thread_time()
            traj = call()
            times[name]["cpu"].append(time.thread_time() - c0)
            times[name]["wall"].append(time.perf_counter() - t0)
            times[name]["solver"].append(traj.wall_time)
    return times


def first_run(cache: str) -> float:
    """Seconds of a first short exact run in a fresh process whose numba cache is ``cache``."""
    out = subprocess.run([sys.executable, "-c", _JIT_CODE], capture_output=True, text=True,
                         check=True, env={**os.environ, "NUMBA_CACHE_DIR": cache})
    return float(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=21, help="interleaved runs (default 21)")
    parser.add_argument("--skip-jit", action="store_true",
                        help="skip the fresh-process compile and cache-load timings")
    args = parser.parse_args()

    import dumbbell
    from dumbbell.model.scene import load_scene, packaged_scene
    from dumbbell.solvers import simulate

    scene = load_scene(packaged_scene())
    rows: list[tuple[str, str]] = []
    if not args.skip_jit:
        with tempfile.TemporaryDirectory() as cache:
            cold, cached = first_run(cache), first_run(cache)
        rows.append((("first exact run (0.5 s) in a fresh process: empty numba cache / cache "
                     "filled"), f"{cold:.2f} s / {cached:.2f} s"))
    for what, kwargs in PAIRS:
        calls = {"exact": lambda kw=kwargs: simulate(scene, "exact", **kw),
                 "euler-cromer": lambda kw=kwargs: simulate(scene, "euler-cromer", **kw)}
        interleaved(2, calls)  # compile or load, and warm every cache
        times = interleaved(args.runs, calls)
        ex, ec = times["exact"], times["euler-cromer"]
        for clock in ("wall", "cpu"):
            e, c = statistics.median(ex[clock]), statistics.median(ec[clock])
            pair = statistics.median(b / a for a, b in zip(ex[clock], ec[clock], strict=True))
            rows.append((f"{what}, {clock} clock: exact / euler-cromer (medians)",
                         (f"{e * 1e3:.3f} ms / {c * 1e3:.2f} ms: exact **{c / e:.1f}x** "
                         f"cheaper (median of the per-pair ratios {pair:.1f}x)")))
        own = statistics.median(ex["solver"])
        rows.append((f"{what}: exact's own search and sampling (Trajectory.wall_time)",
                     f"{own * 1e3:.3f} ms of the {statistics.median(ex['wall']) * 1e3:.3f} ms"))
    traj = simulate(scene, "exact", every=100)
    rows.append(("exact, 10 s: impacts, verdict", f"{len(traj.events)}, {traj.verdict}"))

    print("| measurement | result |\n|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |")
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"\nHow: dumbbell {getattr(dumbbell, '__version__', '?')} from "
          f"{os.path.dirname(dumbbell.__file__)}; Python {platform.python_version()}, "
          f"{os.cpu_count()} cores, load average {load} (1, 5, 15 min). One process, warm "
          f"(each call run twice before timing), {args.runs} runs of each solver alternating, "
          "times of dumbbell.simulate on scenes/textbook-1d.toml (t_end = 10 s, dt = 1e-5 s), "
          "energies and verdict included; wall clock and the thread's CPU time.")


if __name__ == "__main__":
    main()
