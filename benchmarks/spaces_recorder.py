"""spaces.Recorder against what a pymunk user writes today, on the same frames.

    python benchmarks/spaces_recorder.py [--seconds 4] [--repeat 3]
    python benchmarks/spaces_recorder.py --corpus [NAMES] [--seconds 4] [--repeat 3]
    python benchmarks/spaces_recorder.py --table [--seconds 4]

Two baselines draw the same frames as the recorder (the same world box, 640x360, 25 fps):

- ``matplotlib``: pymunk's ``matplotlib_util``: per frame ``ax.clear()``, ``space.debug_draw``,
  draw the canvas, keep the RGB pixels; then ``imageio`` writes the GIF (Pillow quantizes
  every frame);
- ``pygame``: pymunk's ``pygame_util`` on a headless surface: per frame fill, ``space.debug_draw``
  (through a ``Transform`` onto the same box), keep the pixels as a Pillow image; then Pillow
  writes the GIF.

The recorder runs twice: the space only (``energy=False``: what the baselines draw) and with its
energy bars and strip (``recorder+energy``, its own framing).

Default: Newton's cradle of ``dumbbell.examples``, 4 s at dt = 1 ms, each side as a whole
process (interpreter start, imports, building, stepping, drawing, writing), alternately,
``--repeat`` times. ``--corpus``: pymunk's own example programs (run headless through
``tests/pymunk_corpus.py``): each side records the same run in one process, alternately; timed
is each side's own work (its per-frame calls and writing the file), not the program's stepping,
which is the same for all. ``--table``: the per-example table of docs/spaces-reference.md (orientation,
frame size, the smallest body drawn, the recorder's cost per frame against pygame_util).

    python benchmarks/spaces_recorder.py --side SIDE --out OUT.gif --world X0,X1,Y0,Y1
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

#: The recorder's scene area on a frame without the energy panel (px: left, top, width,
#: height), given to the baselines' processes on their command line, so that they do not
#: import dumbbell (what a user of matplotlib_util or pygame_util does not load).
AREA: tuple[int, int, int, int] | None = None


def scene_area() -> tuple[int, int, int, int]:
    """Where the recorder draws the view on a W x H frame without the energy panel (px)."""
    if AREA is not None:
        return AREA
    from dumbbell.animation.camera import scene_area as area

    return area(W, H, False)

FPS, DT = 25, 1e-3
W, H = 640, 360
SIDES = ("matplotlib", "pygame", "recorder", "recorder+energy")
#: The corpus examples of --corpus by default: the cradle, the pyramid and a y-down one.
CORPUS = ("newtons_cradle", "box2d_pyramid", "slide_and_pinjoint")


# --- one side: a frame-drawing object with add(space) and save(path) ----------------------


class Matplotlib:
    """pymunk's matplotlib_util, frames collected and written by imageio."""

    def __init__(self, world: tuple[float, float, float, float]):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from pymunk import matplotlib_util

        self.world = world
        self.fig = plt.figure(figsize=(W / 100, H / 100), dpi=100)
        # The recorder's view of the world box: its scene area under the time label.
        left, top, width, height = scene_area()
        self.ax = self.fig.add_axes((left / W, 1 - (top + height) / H, width / W, height / H))
        self.ax.set_axis_off()
        px_per_unit = width / (world[1] - world[0])

        class Options(matplotlib_util.DrawOptions):
            # matplotlib_util sizes a constraint's dots in data units (a disc metres wide in
            # an SI space, hiding everything): sized in pixels here, as pygame_util does.
            def draw_dot(self, size: float, pos: Any, color: Any) -> None:
                super().draw_dot(size / px_per_unit, pos, color)

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # matplotlib_util is deprecated in pymunk 7
            self.options = Options(self.ax)
        self.options.flags = (Options.DRAW_SHAPES | Options.DRAW_CONSTRAINTS)
        self.frames: list[Any] = []

    def add(self, space: Any, draw: Callable[[Any, Any], None]) -> None:
        import numpy as np

        x0, x1, bottom, top = self.world
        self.ax.clear()
        self.ax.set_axis_off()
        self.ax.set_xlim(x0, x1)
        self.ax.set_ylim(bottom, top)  # bottom > top: y down
        self.ax.set_aspect("equal")
        draw(space, self.options)
        self.fig.canvas.draw()
        self.frames.append(np.asarray(self.fig.canvas.buffer_rgba())[:, :, :3].copy())

    def save(self, path: str) -> None:
        import imageio.v2 as imageio

        imageio.mimsave(path, self.frames, duration=1000 / FPS, loop=0)


class Pygame:
    """pymunk's pygame_util on a headless surface, frames saved by Pillow."""

    def __init__(self, world: tuple[float, float, float, float]):
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame
        import pymunk
        import pymunk.pygame_util

        self.pygame, self.util = pygame, pymunk.pygame_util
        self.surface = pygame.Surface((W, H))
        self.options = pymunk.pygame_util.DrawOptions(self.surface)
        self.options.flags = (pymunk.SpaceDebugDrawOptions.DRAW_SHAPES
                              | pymunk.SpaceDebugDrawOptions.DRAW_CONSTRAINTS)
        # The recorder's view of the world box: its scene area under the time label.
        left, top_px, width, _ = scene_area()
        x0, x1, bottom, top = world
        s = width / (x1 - x0)
        flip = 1.0 if bottom > top else -1.0
        self.options.transform = pymunk.Transform(a=s, b=0, c=0, d=flip * s,
                                                  tx=left - x0 * s, ty=top_px - flip * top * s)
        self.frames: list[Any] = []

    def add(self, space: Any, draw: Callable[[Any, Any], None]) -> None:
        from PIL import Image

        self.util.positive_y_is_up = False  # (a y-up program sets it): the transform flips
        self.surface.fill((255, 255, 255))
        draw(space, self.options)
        self.frames.append(Image.frombytes("RGB", (W, H),
                                           self.pygame.image.tobytes(self.surface, "RGB")))

    def save(self, path: str) -> None:
        self.frames[0].save(path, save_all=True, append_images=self.frames[1:],
                            duration=round(1000 / FPS), loop=0)


class Recorder:
    """dumbbell.spaces.Recorder: made on the first frame's space, then capture() per frame."""

    def __init__(self, world: tuple[float, float, float, float] | None, energy: bool,
                 out: str, **options: Any):
        self.world, self.energy, self.out, self.options = world, energy, out, options
        self.rec: Any = None

    def add(self, space: Any, draw: Callable[[Any, Any], None], t: float | None = None) -> None:
        from dumbbell import spaces

        if self.rec is None:
            self.rec = spaces.Recorder(space, self.out, fps=FPS, energy=self.energy,
                                       world=None if self.energy else self.world,
                                       size=(W, H), **self.options)
        else:
            self.rec.capture(t=t)

    def save(self, path: str) -> None:
        self.rec.write()  # to the path it was made with


def make(side: str, world: tuple[float, float, float, float] | None, out: str,
         **options: Any) -> Any:
    if side == "matplotlib":
        return Matplotlib(world)  # type: ignore[arg-type]
    if side == "pygame":
        return Pygame(world)  # type: ignore[arg-type]
    return Recorder(world, side == "recorder+energy", out, **options)


# --- whole processes on dumbbell's own cradle ----------------------------------------------


def cradle_side(side: str, out: str, seconds: float, world: tuple[float, ...]) -> None:
    """One side, as a whole process: build the cradle, step it, draw every frame, write."""
    import pymunk

    from dumbbell.examples.newtons_cradle import build

    space = build()
    drawer = make(side, world, out)  # type: ignore[arg-type]
    steps = round(1 / (FPS * DT))
    for k in range(round(seconds * FPS) + 1):
        if k:
            for _ in range(steps):
                space.step(DT)
        drawer.add(space, pymunk.Space.debug_draw)
    drawer.save(out)


def cradle_world(seconds: float) -> tuple[float, float, float, float]:
    """The recorder's own framing of the cradle's run, space only (every side draws it)."""
    from dumbbell import spaces
    from dumbbell.examples.newtons_cradle import build

    space = build()
    with tempfile.TemporaryDirectory() as tmp, spaces.Recorder(
            space, Path(tmp) / "w.gif", energy=False, size=(W, H)) as rec:
        for _ in range(round(seconds * FPS)):
            for _ in range(round(1 / (FPS * DT))):
                space.step(DT)
            rec.capture()
    return rec.view  # type: ignore[return-value]


def _run(side: str, out: str, seconds: float, world: tuple[float, ...]) -> tuple[float, float]:
    """One side as a whole process: its wall time and its CPU time (user + system), s."""
    import resource

    # As on a user's machine: byte code cached (the first, untimed run writes it).
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, __file__, "--side", side, "--out", out, "--seconds",
                    str(seconds), "--world=" + ",".join(repr(v) for v in world),
                    "--area=" + ",".join(str(v) for v in scene_area())], check=True, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def whole_processes(seconds: float, repeat: int) -> None:
    world = cradle_world(seconds)
    times: dict[str, list[tuple[float, float]]] = {s: [] for s in SIDES}
    with tempfile.TemporaryDirectory() as tmp:
        outs = {s: str(Path(tmp) / f"{s}.gif") for s in SIDES}
        for s in SIDES:
            _run(s, outs[s], 0.2, world)  # warm-up: byte code and font caches
        for _ in range(repeat):
            for s in SIDES:
                times[s].append(_run(s, outs[s], seconds, world))
        sizes = {s: Path(outs[s]).stat().st_size for s in SIDES}
    frames = round(seconds * FPS) + 1
    print(f"Newton's cradle (dumbbell.examples), {seconds:g} s at dt = {DT:g} s, {frames} frames "
          f"at {FPS} fps, {W}x{H}, whole processes after one untimed warm-up run each, "
          f"{repeat} runs each, alternately:")
    _print(times, sizes)


def _print(times: dict[str, list[tuple[float, float]]], sizes: dict[str, int]) -> None:
    """Per side: wall and CPU time (min / median, s), the file's size, and the ratios of
    the baselines' least times to the recorder's, by wall time and by CPU time."""
    print(f"  {'side':16s} {'wall min / median':>18s} {'CPU min / median':>18s} {'GIF':>8s}"
          "   faster than matplotlib, pygame (wall; CPU)")
    best = {s: (min(w for w, _ in t), min(c for _, c in t)) for s, t in times.items()}
    for s, t in times.items():
        walls, cpus = [w for w, _ in t], [c for _, c in t]
        line = (f"  {s:16s} {min(walls):8.3f} / {statistics.median(walls):7.3f} "
                f"{min(cpus):8.3f} / {statistics.median(cpus):7.3f} {sizes[s] / 1e3:6.0f} kB")
        if s.startswith("recorder"):
            r = {b: (best[b][0] / best[s][0], best[b][1] / best[s][1])
                 for b in ("matplotlib", "pygame")}
            line += (f"   {r['matplotlib'][0]:5.1f}x, {r['pygame'][0]:4.1f}x; "
                     f"{r['matplotlib'][1]:5.1f}x, {r['pygame'][1]:4.1f}x")
        print(line)


# --- in one process on pymunk's examples --------------------------------------------------


def _corpus() -> Any:
    sys.path.insert(0, str(ROOT))
    from tests import pymunk_corpus, recorder_corpus

    return pymunk_corpus, recorder_corpus


def record_corpus(name: str, side: str, seconds: float, world: Any, out: str
                  ) -> tuple[float, float]:
    """Run corpus program ``name`` and draw it with ``side``: the wall and CPU seconds
    spent by the side."""
    import pymunk

    pymunk_corpus, _ = _corpus()
    real_draw = pymunk.Space.debug_draw  # the harness mutes the programs' own drawing
    drawer = make(side, world, out, units=("px", "kg", "s"))
    state = {"t": 0.0, "next": 1, "spent": 0.0, "cpu": 0.0}

    def timed(space: Any, t: float | None) -> None:
        t0, c0 = time.perf_counter(), time.process_time()
        if isinstance(drawer, Recorder):
            drawer.add(space, real_draw, t)
        else:
            drawer.add(space, real_draw)
        state["spent"] += time.perf_counter() - t0
        state["cpu"] += time.process_time() - c0

    def on_step(space: Any, dt: float) -> None:
        state["t"] += dt
        if state["t"] >= state["next"] / FPS - 1e-9:
            timed(space, state["t"])
            state["next"] += 1

    dt = pymunk_corpus.run_example(name, 1).dts[0]
    pymunk_corpus.run_example(name, math.ceil(seconds / dt - 1e-9),
                              on_start=lambda s: timed(s, None), on_step=on_step)
    t0, c0 = time.perf_counter(), time.process_time()
    drawer.save(out)
    return (state["spent"] + time.perf_counter() - t0,
            state["cpu"] + time.process_time() - c0)


def corpus_world(name: str, seconds: float) -> tuple[float, float, float, float]:
    """The recorder's framing of the example (space only): every side draws this box."""
    _, recorder_corpus = _corpus()
    with tempfile.TemporaryDirectory() as tmp:
        r = recorder_corpus.record(name, seconds, Path(tmp) / "w.gif", energy=False,
                                   size=(W, H))
    return r.rec.view


def corpus(names: list[str], seconds: float, repeat: int) -> None:
    frames = round(seconds * FPS) + 1
    print(f"pymunk's examples, {seconds:g} s each, {frames} frames at {FPS} fps, {W}x{H}; each "
          f"side's own work in one process (capture, draw, write), {repeat} runs each, "
          "alternately:")
    for name in names:
        world = corpus_world(name, seconds)
        times: dict[str, list[tuple[float, float]]] = {s: [] for s in SIDES}
        with tempfile.TemporaryDirectory() as tmp:
            outs = {s: str(Path(tmp) / f"{s}.gif") for s in SIDES}
            for _ in range(repeat):
                for s in SIDES:
                    times[s].append(record_corpus(name, s, seconds, world, outs[s]))
            sizes = {s: Path(outs[s]).stat().st_size for s in SIDES}
        print(f"{name}:")
        _print(times, sizes)


def table(seconds: float) -> None:
    """The per-example table of docs/spaces-reference.md."""
    _, rc = _corpus()
    print("| example | y | frame (px) | smallest body drawn, first / last frame (px) | "
          "recorder, CPU ms per frame | pygame_util + Pillow, CPU ms per frame | ratio |")
    print("|---|---|---|---|---|---|---|")
    for name in rc.NAMES:
        with tempfile.TemporaryDirectory() as tmp:
            r = rc.record(name, seconds, Path(tmp) / f"{name}.gif", size=(W, H))
            sizes = []
            for space in (r.first, r.last):
                visible = [i for i in rc.dynamic(space) if rc.extent(rc.picture(
                    space, r.rec, bodies=[i])) > 0] if len(rc.dynamic(space)) <= 12 else [
                    min(rc.dynamic(space), key=lambda i: rc.body_size(list(space.bodies)[i]))]
                sizes.append(min((rc.extent(rc.picture(space, r.rec, bodies=[i]))
                                  for i in visible), default=None))
            _, plain = record_corpus(name, "recorder", seconds, r.rec.view,
                                     str(Path(tmp) / "p.gif"))
            _, base = record_corpus(name, "pygame", seconds, r.rec.view,
                                    str(Path(tmp) / "b.gif"))
        n = r.rec.frames
        shown = " / ".join("-" if v is None else f"{v:.0f}" for v in sizes)
        print(f"| {name} | {'up' if r.rec.view[3] > r.rec.view[2] else 'down'} | {W}x{H} | "
              f"{shown} | {1e3 * plain / n:.1f} | {1e3 * base / n:.1f} | {base / plain:.1f}x |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="simulated time (s)")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--corpus", nargs="?", const=",".join(CORPUS),
                        help="comma-separated pymunk examples (default: %(const)s)")
    parser.add_argument("--table", action="store_true")
    parser.add_argument("--side", choices=SIDES)
    parser.add_argument("--out")
    parser.add_argument("--world", help="x0,x1,bottom,top (for --side)")
    parser.add_argument("--area", help="the scene area: left,top,width,height px (for --side)")
    args = parser.parse_args()
    if args.side:
        global AREA
        if args.area:
            AREA = tuple(int(v) for v in args.area.split(","))  # type: ignore[assignment]
        world = tuple(float(v) for v in args.world.split(","))
        cradle_side(args.side, args.out, args.seconds, world)
    elif args.table:
        table(args.seconds)
    elif args.corpus:
        corpus(args.corpus.split(","), args.seconds, args.repeat)
    else:
        whole_processes(args.seconds, args.repeat)


if __name__ == "__main__":
    main()
