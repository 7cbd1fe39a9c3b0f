"""`dumbbell render` against the GIF script users would otherwise write, side by side.

    python benchmarks/render_speed.py [--repeat 3] [--scene scenes/textbook-1d.toml]

The baseline is a matplotlib FuncAnimation + PillowWriter script drawing the same content as
`dumbbell render` (floor, particles at their radius, zig-zag spring, centre of mass, time,
impact mark; energy bars with the range since the last frame, stacked E with a marker, value
texts; the strip of the energy time series with a cursor). It simulates the scene in-process
exactly as `dumbbell render` does, so both pay the same simulation. Both run as whole
processes (interpreter start, imports, simulation, drawing, encoding, writing), alternately,
`--repeat` times; the script prints min and median wall times, their ratio, the file sizes,
and `dumbbell render`'s time per frame split into drawing and encoding (measured in-process).

    python benchmarks/render_speed.py --baseline OUT.gif     # the baseline alone
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FPS, WIDTH, HEIGHT = 25, 640, 360


def baseline(scene_path: str, out: str, t_end: float) -> None:
    """The matplotlib version: FuncAnimation updating artists, saved with PillowWriter."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.patches import Circle

    from dumbbell.animation.render import frames_of, sample_every
    from dumbbell.model.energy import energy_columns
    from dumbbell.model.scene import load_scene
    from dumbbell.plot.style import COLOURS
    from dumbbell.solvers import simulate

    scene = load_scene(scene_path)
    traj = simulate(scene, t_end=t_end, every=sample_every(scene.run.dt, FPS, t_end))
    fr = frames_of(traj, FPS, t_end)
    t_ready = time.perf_counter()
    names = energy_columns(scene)
    terms = [n for n in names if n not in ("E", "E_lost")]
    colour = {n: COLOURS.get(n, "grey") for n in names}
    colour["E"] = "black"
    hi = max(float(np.nanmax(v)) for v in fr.series.values()) * 1.02

    fig = plt.figure(figsize=(WIDTH / 100, HEIGHT / 100), dpi=100)
    ax = fig.add_axes((0.07, 0.04, 0.22, 0.86))
    top = float(max(fr.A[:, 1].max(), fr.B[:, 1].max())) + 0.05
    ax.set_xlim(-top * 0.22 / 0.86 * HEIGHT / WIDTH * 2, top * 0.22 / 0.86 * HEIGHT / WIDTH * 2)
    ax.set_ylim(-0.08, top)
    ax.set_aspect("equal", adjustable="box")
    ax.axhspan(-1, 0, color="0.9")
    ax.axhline(0, color="0.4")
    ax.set_xticks([])
    ax.set_ylabel("height (m)", fontsize=8)
    ax.tick_params(labelsize=8)
    for s in ("top", "right", "bottom"):
        ax.spines[s].set_visible(False)
    spring, = ax.plot([], [], color="0.3", lw=1.2)
    discs = {p: ax.add_patch(Circle((0, 0), scene.system.A.radius, fc=COLOURS[p], ec="0.1"))
             for p in ("A", "B")}
    cm, = ax.plot([], [], "o", mfc="white", mec="black", ms=6)
    time_text = fig.text(0.01, 0.95, "", fontsize=10, weight="bold")
    impact = ax.text(0, -0.05, "", fontsize=7, ha="center")

    bx = fig.add_axes((0.45, 0.52, 0.42, 0.38))
    rows = np.arange(len(names))[::-1]
    bx.set_yticks(rows, names, fontsize=8)
    bx.set_xlim(0, hi)
    bx.set_title("Energy (J)", fontsize=9, loc="left")
    bx.tick_params(labelsize=7)
    pale = {n: bx.barh(r, 0, color=colour[n], alpha=0.35)[0] for n, r in zip(names, rows)}
    bars = {n: bx.barh(r, 0, color=colour[n])[0] for n, r in zip(names, rows) if n != "E"}
    stack = {n: bx.barh(rows[names.index("E")], 0, color=colour[n])[0] for n in terms}
    marker, = bx.plot([0, 0], [rows[names.index("E")] - 0.4, rows[names.index("E")] + 0.4],
                      color="black", lw=2)
    values = {n: bx.text(hi * 1.02, r, "", va="center", fontsize=8) for n, r in zip(names, rows)}

    sx = fig.add_axes((0.45, 0.1, 0.5, 0.32))
    for n in names:
        sx.plot(fr.series_t, fr.series[n], color=colour[n], lw=0.8)
    sx.set_xlim(0, fr.t_end)
    sx.set_xlabel("t (s)", fontsize=8)
    sx.tick_params(labelsize=7)
    cursor = sx.axvline(0, color="0.1", lw=1.2)

    zig = np.array([0, 0.12] + [0.12 + 0.76 * (i + 0.5) / 18 for i in range(18)] + [0.88, 1])
    side = np.array([0, 0] + [(-1) ** i for i in range(18)] + [0, 0]) * 0.012
    impact_frames = set(np.searchsorted(fr.t, np.asarray(fr.impacts)).tolist())

    def update(k: int):
        a, b = fr.A[k], fr.B[k]
        d = a - b
        length = float(np.hypot(*d)) or 1.0
        n = np.array([-d[1], d[0]]) / length
        spring.set_data(b[0] + d[0] * zig + n[0] * side, b[1] + d[1] * zig + n[1] * side)
        discs["A"].center, discs["B"].center = tuple(a), tuple(b)
        c = (scene.system.A.mass * a + scene.system.B.mass * b) / scene.system.M
        cm.set_data([c[0]], [c[1]])
        time_text.set_text(f"t = {fr.t[k]:.2f} s")
        impact.set_text("impact" if k in impact_frames else "")
        x = 0.0
        for name in names:
            v = fr.energy[name][k]
            pale[name].set_x(min(fr.lo[name][k], 0))
            pale[name].set_width(fr.hi[name][k] - min(fr.lo[name][k], 0))
            if name in bars:
                bars[name].set_width(v)
            values[name].set_text(f"{v:.2f}")
        for name in terms:
            v = max(fr.energy[name][k], 0.0)
            stack[name].set_x(x)
            stack[name].set_width(v)
            x += v
        marker.set_xdata([fr.energy["E"][k]] * 2)
        cursor.set_xdata([fr.t[k]] * 2)

    anim = FuncAnimation(fig, update, frames=len(fr.t), blit=False)
    anim.save(out, writer=PillowWriter(fps=FPS))
    # For the report: time per frame after the simulation (drawing, grabbing, quantizing, saving).
    per_frame = (time.perf_counter() - t_ready) / len(fr.t)
    sys.stderr.write(f"baseline-per-frame {per_frame:.6f}\n")


def _timed(cmd: list[str], env: dict[str, str]) -> tuple[float, str]:
    t0 = time.perf_counter()
    done = subprocess.run(cmd, check=True, env=env, cwd=ROOT, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    return time.perf_counter() - t0, done.stderr


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default=str(ROOT / "scenes" / "textbook-1d.toml"))
    ap.add_argument("--t-end", type=float, default=10.0, help="animation length (s)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--baseline", metavar="OUT", help="run only the baseline, writing OUT")
    args = ap.parse_args()
    if args.baseline:
        baseline(args.scene, args.baseline, args.t_end)
        return

    env = dict(os.environ, CI="1")
    exe = Path(sys.executable).with_name("dumbbell")
    tmp = Path(tempfile.mkdtemp(prefix="render-speed-"))
    ours_gif, base_gif = tmp / "ours.gif", tmp / "baseline.gif"
    ours_cmd = [str(exe), "render", args.scene, "-o", str(ours_gif), "--quiet",
                "--t-end", str(args.t_end), "--fps", str(FPS), "--size", f"{WIDTH}x{HEIGHT}"]
    base_cmd = [sys.executable, __file__, "--baseline", str(base_gif), "--scene", args.scene,
                "--t-end", str(args.t_end)]
    ours, base, base_frame = [], [], []
    for i in range(args.repeat):
        ours.append(_timed(ours_cmd, env)[0])
        seconds, err = _timed(base_cmd, env)
        base.append(seconds)
        base_frame += [float(line.split()[1]) * 1e3 for line in err.splitlines()
                       if line.startswith("baseline-per-frame")]
        print(f"run {i + 1}: dumbbell render {ours[-1]:.2f} s, matplotlib {base[-1]:.2f} s, "
              f"ratio {base[-1] / ours[-1]:.1f}", flush=True)

    # The split of dumbbell render's own time, in-process (simulation excluded).
    from dumbbell.animation.render import render_gif, sample_every
    from dumbbell.model.scene import load_scene
    from dumbbell.solvers import simulate

    scene = load_scene(args.scene)
    traj = simulate(scene, t_end=args.t_end, every=sample_every(scene.run.dt, FPS, args.t_end))
    splits = []
    for _ in range(args.repeat):
        timing: dict[str, float] = {}
        render_gif(traj, tmp / "split.gif", quiet=True, fps=FPS, size=(WIDTH, HEIGHT),
                   t_end=args.t_end, timing=timing)
        splits.append(timing)
    n = splits[0]["frames"]

    def ms(key: str) -> str:
        values = [s[key] / n * 1e3 for s in splits]
        return f"min {min(values):.2f} / median {statistics.median(values):.2f} ms"

    print(f"\n{Path(args.scene).name}, {args.t_end:g} s at {FPS} fps = {n} frames, "
          f"{WIDTH}x{HEIGHT}, {args.repeat} runs each, whole processes:")
    print(f"  dumbbell render       min {min(ours):6.2f} s  median {statistics.median(ours):6.2f} s"
          f"  file {ours_gif.stat().st_size / 1e6:.2f} MB")
    print(f"  matplotlib baseline   min {min(base):6.2f} s  median {statistics.median(base):6.2f} s"
          f"  file {base_gif.stat().st_size / 1e6:.2f} MB")
    print(f"  ratio (baseline / dumbbell render): min/min {min(base) / min(ours):.1f}x, "
          f"median/median {statistics.median(base) / statistics.median(ours):.1f}x")
    print(f"  dumbbell render per frame: drawing {ms('draw')}, encoding {ms('encode')}; "
          f"set-up {min(s['setup'] for s in splits) * 1e3:.0f} ms once (simulation excluded)")
    if base_frame:
        print(f"  matplotlib per frame (after its simulation): min {min(base_frame):.0f} / "
              f"median {statistics.median(base_frame):.0f} ms")


if __name__ == "__main__":
    main()
