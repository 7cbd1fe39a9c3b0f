"""Hardening numbers for docs/hardening.md, measured in one run.

1. The refusal of a run that would keep 1e9 samples (textbook scene, t_end 1e4 s, dt 1e-5 s,
   every step kept): wall time of ``main([...])`` in this process, the peak of Python's own
   allocations during it (tracemalloc), and the growth of this process's peak resident memory.
2. ``sweep --workers 10000`` on a 3-point grid, as a real process: the most processes it had
   at once (itself excluded), and the line it printed about the cap.

Usage: python benchmarks/hardening.py
"""

from __future__ import annotations

import io
import os
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
from contextlib import redirect_stderr
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "textbook-1d.toml"


def refusal() -> None:
    from dumbbell.cli import main

    argv = ["simulate", str(SCENE), "--t-end", "1e4", "--dt", "1e-5", "--every", "1",
            "-o", os.devnull]
    with redirect_stderr(io.StringIO()):
        main(["simulate", str(SCENE), "--t-end", "0.01", "-o", os.devnull])  # imports, JIT
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    err = io.StringIO()
    tracemalloc.start()
    t0 = time.perf_counter()
    with redirect_stderr(err):
        status = main(argv)
    wall = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print("1. refusal of 1e9 samples:", " ".join(argv[:9]))
    print(f"   exit {status}, {wall * 1e3:.2f} ms, Python allocations peak {peak / 1024:.0f} kB, "
          f"peak RSS growth {(rss1 - rss0)} kB")
    print(f"   stderr: {err.getvalue().strip()}")


def workers() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        code = "import sys; from dumbbell.cli import main; sys.exit(main())"
        env = {**os.environ, "CI": "1", "PYTHONPATH": str(ROOT / "src")}
        proc = subprocess.Popen(
            [sys.executable, "-c", code, "sweep", str(SCENE), "--grid", "k=100,200,300",
             "--t-end", "0.5", "--workers", "10000", "--out", tmp],
            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=env)
        most = 0
        parent = psutil.Process(proc.pid)
        while proc.poll() is None:
            try:
                most = max(most, len(parent.children(recursive=True)))
            except psutil.NoSuchProcess:
                break
            time.sleep(0.01)
        err = proc.stderr.read() if proc.stderr else ""
    print(f"2. sweep --workers 10000 on a 3-point grid ({os.cpu_count()} CPUs): exit "
          f"{proc.returncode}, at most {most} worker processes at once")
    for line in err.strip().splitlines():
        print(f"   stderr: {line}")


if __name__ == "__main__":
    refusal()
    workers()
