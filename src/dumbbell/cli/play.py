"""``dumbbell play``: an interactive player of a scene's run (or runs side by side) as one
self-contained HTML page."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .app import (
    DEFAULT_OUT,
    EXIT_VERDICT,
    add_scene,
    positive_int,
    read_scene,
)
from .render import add_length_flags

#: What ``dumbbell play --help`` says the command does.
DESCRIPTION = """\
Run SCENE and write an interactive player: one HTML file that works offline (open it in a
browser), drawing what the GIF shows (the world, the energy bars with their values, the
strip of the energy time series with its cursor, the time) with controls to play and pause
(space), step one frame (arrow keys), drag the time, change the speed (0.1x to 4x), loop, and
jump to the previous or next impact ([ and ]). With --solvers, each solver's run is shown on
one clock: the chosen one drawn solid with its bars, the others as ghosts, every run's values
in the table. Settings come from the flags, else the scene's [outputs.gif] table, else 25 fps,
640x360, strip on, the scene's run.t_end. A run that ends badly is still played up to its
end; the command then prints why and exits 3.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("play", help="write an interactive HTML player of a scene's run",
                       description=DESCRIPTION)
    add_scene(p)
    p.add_argument("--solvers", nargs="+", metavar="NAME",
                   help="solvers to run side by side on one clock (default: the scene's "
                        "run.solver)")
    p.add_argument("-o", "--output", metavar="FILE.html",
                   help=f"page to write (default: {DEFAULT_OUT}/<scene>.html)")
    p.add_argument("--fps", metavar="N", type=positive_int("frames per second", 50),
                   help="frames per second of the frame steps and of play, 1 to 50 "
                        "(default 25, as the GIF)")
    p.add_argument("--size", metavar="WxH",
                   help="the picture's width x height in pixels (default 640x360; the page "
                        "scales it to the window)")
    add_length_flags(p, "length in s", "more than N frames")
    p.set_defaults(func=run, names={"dt": "run.dt"})


def run(args: argparse.Namespace) -> int:
    from ..animation.player import player
    from ..errors import UsageError
    from ..solvers import runnable, solver_class
    from .render import check_gif_frames, gif_flags, gif_trajectory

    scene = read_scene(args.scene)
    gif = gif_flags(args, scene)
    out = Path(args.output) if args.output else Path(DEFAULT_OUT) / f"{scene.name}.html"
    if out.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"-o {out}: must end in .html")
    solvers = args.solvers or [None]
    for name in solvers:  # each once: the CLI's border refused a name given twice
        if name is not None:
            try:
                runnable(solver_class(name), scene)
            except UsageError as exc:
                raise UsageError(f"--solvers: {exc}") from None
    from .app import plan_outputs

    if not args.output:  # -o itself was checked with the other flags
        plan_outputs(args, [out], "the default -o")
    check_gif_frames(args, scene, gif)
    trajs = [gif_trajectory(scene, gif, name, quiet=args.quiet) for name in solvers]
    player(trajs if len(trajs) > 1 else trajs[0], fps=gif.fps, size=gif.size, strip=gif.strip,
           t_end=gif.t_end).save(out)
    if not args.quiet:
        sys.stderr.write(f"wrote {out}\n")
    bad = [x for x in trajs if not x.verdict.ok]
    for x in bad:
        sys.stderr.write(f"dumbbell play: {scene.name}: {x.solver}: {x.verdict}\n")
    return EXIT_VERDICT if bad else 0
