"""The interactive player (issue 31): file sizes, drawing speed in the page, writing time.

    python benchmarks/player.py [--rounds 3] [--seconds 3] [--bodies 300 1000]

1. **Sizes**: the player of each shipped scene over its GIF's length, as ``dumbbell play``
   writes it (the scene's own solver and sampling, 25 fps, 640x360): the textbook's 10 s
   at most 1 MB, a 2D scene's at most 1.5 MB; a recording of N bodies (pymunk circles
   falling in a box) over 10 s at 25 fps, ``spaces.Recorder(space, "run.html")``, at most
   5 MB for 300 bodies.
2. **Drawing**: each page opened in headless Chromium (Debian's, through Playwright), played
   for ``--seconds`` from the start; the page itself counts the frames it drew per second
   (requestAnimationFrame), how many of them showed a new picture (a recording's frames are
   1/25 s apart: a frame of the display that shows the same samples is not drawn again) and
   times each drawing (performance.now() around the draw). The frame rate is capped by the
   display's refresh (60 Hz in headless Chromium): at least 60 for the scenes, at least 30
   for 1,000 bodies. A first row measures the browser's own pace on the machine at that
   moment: a page that only fills a canvas of the same size each frame.
3. **Writing**: the player and the GIF of the same run, written in this one process,
   alternately, ``--rounds`` times; the minimum of each, and their ratio.

Prints one table per part and the machine's load (``os.getloadavg``).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SCENES = ("textbook-1d", "tilted-2d", "rigid-2d", "topple-2d", "friction-2d")
FPS = 25


def scene_run(name: str):
    """The run ``dumbbell play scenes/NAME.toml`` plays: the scene's solver, sampled as the
    GIF, over the GIF's length."""
    import dumbbell
    from dumbbell.cli.render import gif_trajectory
    from dumbbell.model.scene import GifSettings

    scene = dumbbell.load_scene(ROOT / "scenes" / f"{name}.toml")
    gif = scene.outputs.gif or GifSettings(scene.run.t_end)
    return gif_trajectory(scene, gif.fps, gif.t_end), gif.t_end


def recording(bodies: int, path: Path, seconds: float = 10.0):
    """Record ``bodies`` circles falling into a box for ``seconds`` at 25 fps to ``path``
    (the page, or a GIF by its suffix); returns the recorder."""
    import pymunk

    from dumbbell import spaces

    space = pymunk.Space()
    space.gravity = (0, -9.8)
    walls = [((-6, 0), (6, 0)), ((-6, 0), (-6, 30)), ((6, 0), (6, 30))]
    for a, b in walls:
        seg = pymunk.Segment(space.static_body, a, b, 0.1)
        seg.elasticity, seg.friction = 0.5, 0.5
        space.add(seg)
    side = max(1, int(bodies ** 0.5))
    for i in range(bodies):
        body = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.2))
        body.position = (-5 + 10 * (i % side) / side, 2 + 0.5 * (i // side))
        shape = pymunk.Circle(body, 0.2)
        shape.elasticity, shape.friction = 0.5, 0.5
        space.add(body, shape)
    steps = round(seconds * FPS)
    with spaces.Recorder(space, path, fps=FPS) as rec:
        for _ in range(steps):
            for _ in range(4):
                space.step(1 / FPS / 4)
            rec.capture()
    return rec


BASELINE = """<!DOCTYPE html><canvas id=c width=906 height=510></canvas><script>
const c = document.getElementById("c").getContext("2d", {alpha: false});
function measure(seconds) { return new Promise(function (resolve) {
  let n = 0, first = null; const ms = [];
  function step(now) {
    const t0 = performance.now(); c.fillStyle = n % 2 ? "#fff" : "#eee"; c.fillRect(0, 0, 906, 510);
    ms.push(performance.now() - t0); if (first === null) first = now; n += 1;
    if (now - first < seconds * 1000) { requestAnimationFrame(step); return; }
    ms.sort(function (a, b) { return a - b; });
    resolve({frames: n, fps: (n - 1) / ((now - first) / 1000),
             meanDrawMs: ms.reduce(function (a, b) { return a + b; }, 0) / ms.length,
             p95DrawMs: ms[Math.floor(0.95 * (ms.length - 1))]});
  }
  requestAnimationFrame(step); }); }
</script>"""


def measure_pages(paths: dict[str, Path], seconds: float) -> dict[str, dict]:
    from tests import browser

    why = browser.unavailable()
    if why:
        print(f"drawing not measured: {why}")
        return {}
    out = {}
    with browser.launched() as b:
        # The browser's own pace on this machine now: a page that fills a canvas of the
        # same size each frame and draws nothing else.
        blank = b.new_page(viewport={"width": 1280, "height": 720})
        blank.set_content(BASELINE)
        out["baseline: a canvas filled each frame"] = blank.evaluate(f"measure({seconds})")
        blank.close()
        for name, path in paths.items():
            opened = browser.open_player(b, path)
            out[name] = opened.page.evaluate(f"window.dumbbellPlayer.measure({seconds})")
            if opened.console:
                out[name]["console"] = opened.console
            opened.page.close()
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--bodies", type=int, nargs="*", default=[300, 1000])
    a = ap.parse_args()
    from dumbbell import player, render_gif

    print(f"load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} CPUs)")
    tmp = Path(tempfile.mkdtemp(prefix="dumbbell-player-bench-"))
    pages: dict[str, Path] = {}
    runs = {}
    print("\n| page | seconds of run | size (MB) | budget (MB) |\n|---|---|---|---|")
    for name in SCENES:
        traj, t_end = scene_run(name)
        runs[name] = (traj, t_end)
        pages[name] = player(traj).save(tmp / f"{name}.html")
        budget = 1.0 if name == "textbook-1d" else 1.5
        print(f"| {name} | {t_end:g} | {pages[name].stat().st_size / 1e6:.3f} | {budget} |")
    recorders = {}
    for n in a.bodies:
        path = tmp / f"bodies-{n}.html"
        recorders[n] = recording(n, path)
        pages[f"{n} bodies"] = path
        print(f"| {n} bodies (recording) | 10 | {path.stat().st_size / 1e6:.3f} | "
              f"{'5' if n <= 300 else '-'} |")

    print(f"\nDrawing in headless Chromium, {a.seconds:g} s of play each (measured in the page)")
    print("| page | frames per second (requestAnimationFrame) | new pictures drawn per "
          "second | mean draw (ms) | 95th percentile (ms) |")
    print("|---|---|---|---|---|")
    for name, m in measure_pages(pages, a.seconds).items():
        drawn = f"{m['drawnPerSecond']:.1f}" if "drawnPerSecond" in m else "-"
        print(f"| {name} | {m['fps']:.1f} | {drawn} | {m['meanDrawMs']:.2f} | "
              f"{m['p95DrawMs']:.2f} |" + (f" console: {m['console']}" if "console" in m else ""))

    print(f"\nWriting the player against the GIF of the same run, {a.rounds} rounds "
          "alternately, in this process (minimum of each)")
    print("| run | player (s) | GIF (s) | player / GIF |\n|---|---|---|---|")
    for name in ("textbook-1d", "tilted-2d"):
        traj, t_end = runs[name]
        tp, tg = [], []
        for _ in range(a.rounds):
            t0 = time.perf_counter()
            player(traj).save(tmp / "w.html")
            tp.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            render_gif(traj, tmp / "w.gif", quiet=True, t_end=t_end)
            tg.append(time.perf_counter() - t0)
        print(f"| {name} | {min(tp):.3f} | {min(tg):.3f} | {min(tp) / min(tg):.3f} |")
    from dumbbell.animation import recording as R
    from dumbbell.animation import space_player

    for n, rec in recorders.items():
        r = rec.recording()
        tp, tg = [], []
        for _ in range(a.rounds):
            t0 = time.perf_counter()
            space_player.write(tmp / "w.html", r)
            tp.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            R.write(tmp / "w.gif", r)
            tg.append(time.perf_counter() - t0)
        print(f"| {n} bodies (recording) | {min(tp):.3f} | {min(tg):.3f} | "
              f"{min(tp) / min(tg):.3f} |")
    print(f"\nload average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
