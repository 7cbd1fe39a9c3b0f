"""What skipping numba's BLAS probe saves a command: the seconds to ready numba's CPU target in
a fresh process, with the probe (``scipy.linalg.cython_blas`` imported, as numba does) and
without it (as ``dumbbell``'s commands do, see ``_install._numba_target``), interleaved.

    python benchmarks/blas_probe.py [rounds]
"""

from __future__ import annotations

import statistics
import subprocess
import sys

ONE = """
import sys, time
from dumbbell import _install
_install.COMMAND_LINE.set(sys.argv[1] == "skip")
import numba
t = time.perf_counter()
_install._numba_target()
print(time.perf_counter() - t)
"""


def main(rounds: int = 5) -> None:
    times: dict[str, list[float]] = {"skip": [], "probe": []}
    for _ in range(rounds):
        for way, seconds in times.items():
            out = subprocess.run([sys.executable, "-c", ONE, way], capture_output=True,
                                 text=True, check=True).stdout
            seconds.append(float(out))
    for way, seconds in times.items():
        print(f"{way:5s}: median {statistics.median(seconds):.2f} s of {rounds} "
              f"({', '.join(f'{s:.2f}' for s in seconds)})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
