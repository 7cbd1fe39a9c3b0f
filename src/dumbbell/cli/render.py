"""``dumbbell render``: an animated GIF of one scene with live energy bars."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..animation.render import MAX_FRAMES
from ..model.scene import GifSettings
from .app import (
    DEFAULT_OUT,
    _shown,
    add_quiet,
    add_scene,
    positive_float,
    positive_int,
    read_scene,
    verdict_status,
)

#: What ``dumbbell render --help`` says the command does.
DESCRIPTION = """\
Run SCENE and write an animated GIF (looping forever): the floor, the particles at their
true radius, the spring as a zig-zag (a rod when rigid), the centre of mass, the time and in
2D the axis angle; bars of every energy term on one fixed scale with a marker at the total;
and a strip of the energy time series (a 1 s window scrolling under a cursor). Settings come
from the flags, else the scene's [outputs.gif] table, else fps 25, 640x360, strip on, the
scene's run.t_end. A run that ends badly still writes its GIF up to the failure, prints why
and exits 3.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "render", help="animate a scene as a GIF with live energy bars",
        description=DESCRIPTION,
    )
    add_scene(p, solver="solver (default: the scene's run.solver)")
    p.add_argument("-o", "--output", metavar="FILE.gif",
                   help=f"GIF to write (default: {DEFAULT_OUT}/<scene>.gif)")
    p.add_argument("--fps", metavar="N", type=_whole,
                   help="frames per second, 1 to 50 (default 25). GIF delays are whole "
                        "10 ms units: at 25 fps every frame lasts 40 ms; when 100/fps is not "
                        "whole (30 fps) delays alternate (30, 40, 30 ms) to keep real time")
    p.add_argument("--size", metavar="WxH", help="width x height in pixels (default 640x360)")
    add_length_flags(p, "length of the animation in s", "an animation of more than N frames")
    # The step comes from the scene: a run past the step cap names its key.
    p.set_defaults(func=run, names={"dt": "run.dt"})


def add_length_flags(p: argparse.ArgumentParser, length: str, refused: str) -> None:
    """The flags an animation's length and strip share (``dumbbell render`` and ``play``):
    ``--t-end`` (``length``), ``--max-frames`` (what is ``refused``), ``--no-strip``, ``-q``."""
    p.add_argument("--t-end", type=positive_float("s"), metavar="T",
                   help=f"{length} (default: the scene's run.t_end)")
    p.add_argument("--max-frames", type=positive_int("frames"), metavar="N",
                   default=MAX_FRAMES,
                   help=f"refuse, before anything runs, {refused} "
                        f"(t_end x fps; default {MAX_FRAMES:,})")
    p.add_argument("--no-strip", dest="strip", action="store_false", default=None,
                   help="leave out the strip of the energy time series")
    add_quiet(p)


def _whole(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{_shown(text)}: must be a whole number") from None


def gif_flags(args: argparse.Namespace, scene) -> GifSettings:
    """The animation's settings: the flags (``--fps``, ``--size``, ``--no-strip``,
    ``--t-end``), else the scene's [outputs.gif] table, else the defaults; checked here, at the
    border, each named where it came from."""
    from ..animation.render import check_fps, check_size

    gif = scene.outputs.gif or GifSettings(scene.run.t_end)
    fps = check_fps(args.fps if args.fps is not None else gif.fps,
                    "--fps" if args.fps is not None else "outputs.gif.fps")
    width, height = check_size(args.size or gif.size,
                               "--size" if args.size else "outputs.gif.size")
    strip = args.strip if args.strip is not None else gif.strip
    return GifSettings(args.t_end or gif.t_end, fps, f"{width}x{height}", strip)


def check_gif_frames(args: argparse.Namespace, scene, gif: GifSettings) -> None:
    """UsageError when the animation has more than ``--max-frames`` frames, naming the
    setting its length came from."""
    from ..animation.render import _check_frames

    _check_frames(gif.t_end, gif.fps, args.max_frames,
                  "--t-end" if args.t_end else "outputs.gif.t_end" if scene.outputs.gif
                  else "run.t_end")


def run(args: argparse.Namespace) -> int:
    from ..animation.render import _render_gif

    scene = read_scene(args.scene)
    # Validate every setting before anything runs or is written.
    gif = gif_flags(args, scene)
    out = Path(args.output) if args.output else Path(DEFAULT_OUT) / f"{scene.name}.gif"
    if out.suffix.lower() != ".gif":
        from ..errors import UsageError

        raise UsageError(f"-o {out}: must end in .gif")
    from .app import plan_outputs

    if not args.output:  # -o itself was checked with the other flags
        plan_outputs(args, [out], "the default -o")
    check_gif_frames(args, scene, gif)
    traj = gif_trajectory(scene, gif, args.solver, quiet=args.quiet)
    _render_gif(traj, out, gif, args.quiet, None)
    if not args.quiet:
        sys.stderr.write(f"wrote {out}\n")
    if not traj.verdict.ok:
        sys.stderr.write(f"dumbbell render: {scene.name}: {traj.solver}: {traj.verdict}\n")
    return verdict_status(traj.verdict)


def gif_trajectory(scene, gif, solver: str | None = None, quiet: bool = True, traj=None):
    """The run a GIF of ``scene`` with the settings ``gif`` (its ``fps`` over ``t_end`` s)
    is drawn from: sampled as
    :func:`dumbbell.animation.render.sample_every` says, which keeps the scene's own
    ``run.every`` when it serves the GIF. ``traj``, a run already made (``dumbbell run``'s),
    is used when it has those samples and lasts long enough; else the scene is run again.
    So ``dumbbell render`` and ``dumbbell run`` draw one scene from the same samples and
    write the same bytes."""
    from dataclasses import replace

    from ..animation.render import _sample_every
    from ..solvers import MAX_SAMPLES, run_scene
    from ..solvers.base import scene_options

    options = scene_options(scene, t_end=gif.t_end)
    every = _sample_every(options.dt, gif.fps, options.t_end, scene.run.every)
    if (traj is not None and traj.every == every and traj.dt == options.dt
            and (solver is None or traj.solver == solver)
            and (not traj.verdict.complete  # ended early: a new run would end there too
                 or traj.t[-1] >= options.t_end - options.dt * every / 2)):
        return traj
    options = scene_options(scene, t_end=options.t_end, every=every, max_samples=MAX_SAMPLES)
    return run_scene(scene, solver, replace(options, quiet=quiet))
