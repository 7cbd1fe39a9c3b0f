"""spaces.Recorder against pymunk's matplotlib_util recording the same Newton's cradle.

    python benchmarks/spaces_recorder.py [--seconds 4] [--repeat 3]

Both sides run as whole processes (interpreter start, imports, building the cradle, stepping
it at dt = 1 ms, drawing every frame at 25 fps, writing a 640x360 GIF), alternately,
``--repeat`` times. The baseline is what a pymunk user writes today: per frame ``ax.clear()``,
``space.debug_draw(pymunk.matplotlib_util.DrawOptions(ax))``, draw the canvas, keep the RGB
pixels; then ``imageio`` writes the GIF (Pillow quantizes every frame). The recorder runs
twice: with only the space drawn (what the baseline draws), and with its energy bars and
strip. Printed: min and median wall times, the ratios, the file sizes.

    python benchmarks/spaces_recorder.py --side baseline --out OUT.gif     # one side alone
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FPS, DT = 25, 1e-3


def baseline(out: str, seconds: float) -> None:
    """pymunk's matplotlib_util, frames collected and written by imageio."""
    import matplotlib

    matplotlib.use("Agg")
    import imageio.v2 as imageio
    import matplotlib.pyplot as plt
    import numpy as np
    from pymunk import matplotlib_util

    from dumbbell.examples.newtons_cradle import build

    space = build()
    fig = plt.figure(figsize=(6.4, 3.6), dpi=100)
    ax = fig.add_axes((0, 0, 1, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # matplotlib_util is deprecated in pymunk 7
        options = matplotlib_util.DrawOptions(ax)
    frames = []
    steps = round(1 / (FPS * DT))
    for _ in range(round(seconds * FPS) + 1):
        ax.clear()
        ax.set_xlim(-0.45, 0.45)
        ax.set_ylim(-0.1, 0.35)
        ax.set_aspect("equal")
        space.debug_draw(options)
        fig.canvas.draw()
        frames.append(np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy())
        for _ in range(steps):
            space.step(DT)
    imageio.mimsave(out, frames, duration=1000 / FPS, loop=0)


def recorder(out: str, seconds: float, energy: bool) -> None:
    """dumbbell.spaces.Recorder on the same cradle and steps."""
    from dumbbell import spaces
    from dumbbell.examples.newtons_cradle import build

    space = build()
    steps = round(1 / (FPS * DT))
    with spaces.Recorder(space, out, fps=FPS, energy=energy) as rec:
        for _ in range(round(seconds * FPS) + 1):
            rec.capture()
            for _ in range(steps):
                space.step(DT)


def _run(side: str, out: str, seconds: float) -> float:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, __file__, "--side", side, "--out", out,
                    "--seconds", str(seconds)], check=True, env=env)
    return time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="simulated time (s)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--side", choices=["baseline", "recorder", "recorder-energy"])
    parser.add_argument("--out")
    args = parser.parse_args()
    if args.side:
        if args.side == "baseline":
            baseline(args.out, args.seconds)
        else:
            recorder(args.out, args.seconds, args.side == "recorder-energy")
        return
    sides = ["baseline", "recorder", "recorder-energy"]
    times: dict[str, list[float]] = {s: [] for s in sides}
    with tempfile.TemporaryDirectory() as tmp:
        outs = {s: str(Path(tmp) / f"{s}.gif") for s in sides}
        for _ in range(args.repeat):
            for s in sides:
                times[s].append(_run(s, outs[s], args.seconds))
        sizes = {s: Path(outs[s]).stat().st_size for s in sides}
    frames = round(args.seconds * FPS) + 1
    print(f"Newton's cradle, {args.seconds:g} s at dt = {DT:g} s, {frames} frames at {FPS} fps,"
          f" 640x360, whole processes, {args.repeat} runs each (min / median s):")
    base = min(times["baseline"])
    for s in sides:
        t = times[s]
        print(f"  {s:16s} {min(t):7.2f} / {statistics.median(t):7.2f}   {sizes[s] / 1e3:8.0f} kB"
              f"   {base / min(t):5.1f}x faster than baseline" if s != "baseline" else
              f"  {s:16s} {min(t):7.2f} / {statistics.median(t):7.2f}   {sizes[s] / 1e3:8.0f} kB")


if __name__ == "__main__":
    main()
