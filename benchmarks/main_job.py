"""Where users wait: the main job, ``import dumbbell`` and the first run, as whole processes.

    python benchmarks/main_job.py [--runs 7] [--skip-first-run]

Each measurement is a fresh process, timed from outside (wall clock), the way a user waits:

- the main job, ``dumbbell run -q --out DIR`` (the packaged textbook scene: 1e6 Euler-Cromer
  steps, three figures, two CSVs, a 250-frame GIF), warm: numba's cache filled and the files
  read once before the clock starts;
- ``python -c "import numpy"``, the floor of any Python process that computes: the main job
  is given as a multiple of it;
- ``python -c "import dumbbell"``, and which heavy libraries that import loaded;
- the first run after an install: the main job with an empty numba cache (a new
  ``NUMBA_CACHE_DIR`` each time), so every kernel it needs is compiled;
- peak memory of the main job: the largest resident set of any one of its processes (what
  ``/usr/bin/time -f %M`` reports; the job forks a second process for its figures), and the
  largest sum of the proportional set sizes of its processes (each shared page counted once
  across them), sampled every 10 ms in three runs of their own (the sampling takes CPU, so
  those runs are not timed): what the job holds at its peak.

The warm runs alternate (numpy, import dumbbell, main job, numpy, ...) ``--runs`` times, so a
change of load on the machine hits all alike; the table gives medians and, for the main job,
the range. It ends with how it was taken: the machine, its load before and after, the
versions.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: Libraries ``import dumbbell`` must not load (they load when used).
HEAVY = ("numpy", "matplotlib", "numba", "pymunk", "scipy", "pandas", "PIL")


def dumbbell_command() -> list[str]:
    """The ``dumbbell`` console script beside this interpreter, else ``python -m dumbbell``."""
    script = Path(sys.executable).with_name("dumbbell")
    return [str(script)] if script.is_file() else [sys.executable, "-m", "dumbbell"]


def _pss(pid: int) -> int:
    """The proportional set size of process ``pid`` (bytes): its private pages, and its
    share of the pages it shares (with its forked child, say); 0 once it is gone."""
    try:
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Pss:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def timed(argv: list[str], env: dict[str, str] | None = None, watch: bool = False
          ) -> tuple[float, float]:
    """Wall seconds of ``argv`` run to its end, and the largest sum of the proportional set
    sizes of its process tree (MiB, sampled every 10 ms when ``watch``; 0 otherwise, or
    without /proc/PID/smaps_rollup)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    peak = 0.0
    if watch:
        import psutil

        root = psutil.Process(proc.pid)
        while proc.poll() is None:
            try:
                tree = [proc.pid, *(p.pid for p in root.children(recursive=True))]
                peak = max(peak, sum(_pss(pid) for pid in tree) / 2**20)
            except psutil.Error:
                pass
            time.sleep(0.01)
    _, err = proc.communicate()
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed ({proc.returncode}): {err.decode()[-500:]}")
    return wall, peak


def max_rss(argv: list[str]) -> float:
    """The largest resident set (MiB) of any one process of ``argv``'s run (measured by a
    fresh process that runs it: the resource usage of children keeps the largest ever)."""
    code = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True, "
            "stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL); "
            "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    out = subprocess.run([sys.executable, "-c", code, *argv], check=True, capture_output=True,
                         text=True)
    return int(out.stdout) / 1024


def loaded_by_import() -> list[str]:
    code = ("import sys, dumbbell; print(' '.join(m for m in " + repr(HEAVY)
            + " if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True)
    return out.stdout.split()


def import_time() -> float:
    """Seconds ``import dumbbell`` itself takes (-X importtime, cumulative)."""
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", "import dumbbell"],
                         check=True, capture_output=True, text=True)
    for line in out.stderr.splitlines():
        parts = [p.strip() for p in line.split("|")]
        if len(parts) == 3 and parts[2] == "dumbbell":
            return int(parts[1]) / 1e6
    return float("nan")


def machine() -> str:
    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            model = next(line.split(":", 1)[1].strip() for line in fh
                         if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        usable = os.cpu_count()
    return f"{model}, {os.cpu_count()} CPUs ({usable} usable)"


def versions() -> str:
    from importlib.metadata import PackageNotFoundError, version

    found = []
    for name in ("dumbbell", "numpy", "numba", "matplotlib", "pillow"):
        try:
            found.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            pass
    return ", ".join(found)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7,
                        help="alternating runs of each warm measurement (default 7)")
    parser.add_argument("--first-runs", type=int, default=3,
                        help="runs with an empty numba cache (default 3)")
    parser.add_argument("--skip-first-run", action="store_true",
                        help="skip the runs with an empty numba cache")
    args = parser.parse_args()

    load_before = os.getloadavg()
    job = dumbbell_command()
    work = Path(tempfile.mkdtemp(prefix="dumbbell-main-job-"))
    try:
        run = [*job, "run", "-q", "--out", str(work / "out")]
        commands = {
            "numpy": [sys.executable, "-c", "import numpy"],
            "import dumbbell": [sys.executable, "-c", "import dumbbell"],
            "main job": run,
        }
        for argv in commands.values():  # warm: numba's cache, font cache, files read
            timed(argv)
        times: dict[str, list[float]] = {name: [] for name in commands}
        for _ in range(args.runs):
            for name, argv in commands.items():
                times[name].append(timed(argv)[0])
        # Memory apart from the clock: the watcher's sampling takes CPU from the job.
        sums = [timed(run, watch=True)[1] for _ in range(3)]
        rss = max_rss(run)

        first: list[float] = []
        if not args.skip_first_run:
            for i in range(args.first_runs):
                cache = work / f"numba-cache-{i}"
                env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
                first.append(timed(run, env=env)[0])
    finally:
        shutil.rmtree(work, ignore_errors=True)

    floor = statistics.median(times["numpy"])
    job_t = statistics.median(times["main job"])
    imp = statistics.median(times["import dumbbell"])
    rows = [
        ("main job, warm: `dumbbell run -q --out DIR` (median, range)",
         (f"**{job_t:.2f} s** ({min(times['main job']):.2f}-{max(times['main job']):.2f} s): "
          f"{job_t / floor:.1f}x the floor")),
        ("floor: `python -c \"import numpy\"` (median)", f"{floor:.3f} s"),
        ("`python -c \"import dumbbell\"` (median); the import itself (-X importtime)",
         f"{imp:.3f} s ({imp / floor:.2f}x the floor); {import_time():.3f} s"),
        ("heavy libraries `import dumbbell` loaded",
         ", ".join(loaded_by_import()) or "none of " + ", ".join(HEAVY)),
    ]
    if first:
        mid = statistics.median(first)
        rows.append(("first run after an install: empty numba cache (median, range)",
                     (f"**{mid:.2f} s** ({min(first):.2f}-{max(first):.2f} s): "
                      f"{mid / job_t:.1f}x the warm run")))
    rows.append(("peak memory of the main job: largest process (RSS) / all its processes (PSS)",
                 f"**{rss:.0f} MiB** / {max(sums):.0f} MiB"))
    print("| measurement | result |\n|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |")
    after = os.getloadavg()
    print(f"\nHow: {machine()}; Python {platform.python_version()} ({versions()}); "
          f"load average {load_before[0]:.2f} before, {after[0]:.2f} after (1 min). Whole "
          f"processes timed from outside, {args.runs} runs of each alternating after one "
          f"warm-up each; {len(first)} first runs, each with a new empty NUMBA_CACHE_DIR; "
          f"the main job is `{' '.join(Path(a).name for a in job)} run`.")


if __name__ == "__main__":
    main()
