"""Foundation benchmarks, measured side by side in one run.

1. The textbook run (10 s, dt = 1e-5, 1e6 steps): the listing of section 13.5.1 as printed
   (numpy arrays indexed element by element in plain Python) against ``dumbbell.simulate``,
   in the same process, alternating (one of each per round): a ratio is the median of the
   per-round ratios, with their range, and the load average is printed beside them. The JIT
   warm-up is excluded from the ratio and reported separately.
2. Memory: dt = 1e-7 (1e8 steps) with every = 10000, peak resident memory of a fresh process.
3. The exact solution over 10 s against the 1e6-step Euler-Cromer run, at the same sampling.

Usage: python benchmarks/foundation.py [--repeat N] [--skip-listing]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np


def listing_as_printed(time_end: float = 10.0, dt: float = 0.00001) -> tuple[np.ndarray, ...]:
    """The textbook's listing, typos fixed, run as printed (numpy arrays, a Python loop)."""
    from numpy import zeros

    m = 0.1
    k = 200.0
    b = 0.2
    h0 = 1.0
    g = 9.8
    n = round(time_end / dt)
    t = zeros(n, float)
    xA = zeros(n, float)
    vA = zeros(n, float)
    xB = zeros(n, float)
    vB = zeros(n, float)
    xA[0] = h0 + b
    vA[0] = 0.0
    xB[0] = h0
    vB[0] = 0.0
    for i in range(n - 1):
        f = k * (xA[i] - xB[i] - b)
        fA = -f - m * g
        fB = f - m * g
        aA = fA / m
        vA[i + 1] = vA[i] + aA * dt
        xA[i + 1] = xA[i] + vA[i + 1] * dt
        aB = fB / m
        vB[i + 1] = vB[i] + aB * dt
        xB[i + 1] = xB[i] + vB[i + 1] * dt
        t[i + 1] = t[i] + dt
        if (xB[i + 1] < 0.0) and (xB[i] >= 0.0):
            vB[i + 1] = abs(vB[i + 1])
    xcm = (xA + xB) * 0.5
    vcm = (vA + vB) * 0.5
    Kcm = 0.5 * (2.0 * m) * vcm**2
    Kcmdelta = 0.5 * m * (vA - vcm) ** 2 + 0.5 * m * (vB - vcm) ** 2
    Ug = xcm * (2.0 * m) * g
    Uk = 0.5 * k * (xA - xB - b) ** 2
    E = Kcm + Kcmdelta + Ug + Uk
    return xA, vA, xB, vB, E


def rounds(fns: dict[str, object], repeat: int) -> tuple[dict[str, list[float]], dict]:
    """Run every function once per round, ``repeat`` rounds, alternating, so that a busy
    moment of a shared machine hits both sides of a ratio alike; returns each one's times (s)
    and last result."""
    times: dict[str, list[float]] = {name: [] for name in fns}
    last: dict[str, object] = {}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            last[name] = fn()
            times[name].append(time.perf_counter() - t0)
    return times, last


def paired(times: dict[str, list[float]], slow: str, fast: str) -> str:
    """Median, and range, of the per-round ratios slow / fast."""
    ratios = sorted(a / b for a, b in zip(times[slow], times[fast], strict=True))
    return (f"{float(np.median(ratios)):.3g}x (median of {len(ratios)} paired rounds; "
            f"{ratios[0]:.3g}x to {ratios[-1]:.3g}x)")


def best(times: list[float], unit: float = 1e3, label: str = "ms") -> str:
    return f"{min(times) * unit:.3g} {label} (median {float(np.median(times)) * unit:.3g} {label})"


def fresh_process(code: str, env: dict[str, str] | None = None) -> str:
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                         text=True, check=True, env={**os.environ, **(env or {})})
    return out.stdout.strip()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5,
                        help="rounds, one run of each per round (default 5)")
    parser.add_argument("--skip-listing", action="store_true",
                        help="skip the plain-Python listing (it takes several seconds)")
    args = parser.parse_args()

    import dumbbell
    from dumbbell.model.scene import packaged_scene
    from dumbbell.solvers import euler_cromer

    scene = dumbbell.load_scene(packaged_scene())
    rows: list[tuple[str, str]] = []

    # JIT: compile from scratch in a fresh process with an empty cache, and load from the cache.
    with tempfile.TemporaryDirectory() as cache:
        cold = fresh_process("from dumbbell.solvers import euler_cromer;"
                             "print(euler_cromer.EulerCromer.warm_up())", {"NUMBA_CACHE_DIR": cache})
        cached = fresh_process("from dumbbell.solvers import euler_cromer;"
                               "print(euler_cromer.EulerCromer.warm_up())", {"NUMBA_CACHE_DIR": cache})
    rows.append(("JIT compile, fresh process, empty cache", f"{float(cold):.2f} s"))
    rows.append(("JIT load from numba's cache, fresh process", f"{float(cached):.3f} s"))
    euler_cromer.EulerCromer.warm_up()

    def every_step():
        traj = dumbbell.simulate(scene, "euler-cromer", every=1)
        traj["E"]
        return traj

    def shipped():
        traj = dumbbell.simulate(scene)  # the scene's own settings: every=100
        traj["E"]
        return traj

    def exact():
        return dumbbell.simulate(scene, "exact", every=100)

    exact()  # load exact's compiled code before timing
    load = os.getloadavg()[0]
    fns = {"shipped": shipped, "every_step": every_step, "exact": exact}
    if not args.skip_listing:
        fns["listing"] = listing_as_printed
    times, last = rounds(fns, args.repeat)
    rows.append((("dumbbell.simulate(textbook scene), 1e6 steps, 1e4 samples (every=100), "
                 "with energies"), best(times["shipped"])))
    rows.append(("dumbbell.simulate, 1e6 steps, all 1e6 samples (every=1), with energies",
                 best(times["every_step"])))
    rows.append(("exact, 10 s, 1e4 samples (every=100), with energies", best(times["exact"])))
    rows.append(("exact against euler-cromer, both 1e4 samples over 10 s",
                 "cheaper by " + paired(times, "shipped", "exact")))
    if not args.skip_listing:
        listing, traj = last["listing"], last["every_step"]
        same = all(np.array_equal(a[:-1], traj[c][:-2]) for a, c in
                   zip(listing[:4], ("xA", "vA", "xB", "vB"), strict=True))
        rows.append(("textbook listing as printed, plain Python",
                     best(times["listing"], 1, "s")))
        rows.append(("speed-up, textbook scene as shipped (every=100)",
                     paired(times, "listing", "shipped")))
        rows.append(("speed-up, every step kept (every=1)",
                     paired(times, "listing", "every_step")))
        rows.append(("listing and dumbbell agree bit for bit over 10 s", str(same)))
    t0 = time.perf_counter()
    ex1 = dumbbell.simulate(scene, "exact", every=1)
    rows.append(("exact, 10 s, 1e6 samples (every=1), with energies",
                 f"{(time.perf_counter() - t0) * 1e3:.3g} ms"))
    E = ex1["E"]
    rows.append(("exact: largest |E - E0| / E0 over 10 s", f"{np.abs(E - E[0]).max() / E[0]:.1e}"))
    rows.append((("load average (1 min) before / after the timed rounds, on "
                 f"{os.cpu_count()} CPUs"), f"{load:.1f} / {os.getloadavg()[0]:.1f}"))

    mem = fresh_process("""
        import time, dumbbell
        from dumbbell.model.scene import packaged_scene
        from dumbbell.solvers import euler_cromer
        euler_cromer.EulerCromer.warm_up()
        scene = dumbbell.load_scene(packaged_scene())
        t0 = time.perf_counter()
        traj = dumbbell.simulate(scene, "euler-cromer", dt=1e-7, every=10000)
        wall = time.perf_counter() - t0
        # VmHWM, not ru_maxrss: Linux carries the parent's ru_maxrss across fork and exec.
        status = open("/proc/self/status").read().split("VmHWM:")[1].split()
        peak = int(status[0]) / 1024
        print(f"{peak:.0f} {wall:.2f} {len(traj)} {traj.verdict.status}")
    """)
    peak, wall, n, status = mem.split()
    rows.append(("dt = 1e-7 (1e8 steps), every=10000: peak memory",
                 f"{peak} MB ({n} samples, {wall} s, verdict {status})"))

    print("| measurement | result |\n|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |")


if __name__ == "__main__":
    main()
