"""``dumbbell run``: the main job, everything a scene's ``[outputs]`` asks for."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from .app import add_quiet

#: Scenes whose outputs the README shows; ``dumbbell run --all`` regenerates them all.
SHOWCASE = ("textbook-1d", "tilted-2d", "rigid-2d", "topple-2d")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help="make everything a scene's [outputs] asks for (the main job)",
        description="Run SCENE with its own solver and settings and write what its [outputs] "
                    "table asks for (figures as PNG, the trajectory and impacts as CSV, GIFs) "
                    "into DIR. With no SCENE, runs the packaged textbook scene (section 13.5.1).",
    )
    p.add_argument("scene", metavar="SCENE", nargs="?",
                   help="scene file (TOML); default: the packaged textbook-1d scene")
    p.add_argument("--out", metavar="DIR", default="renders",
                   help="folder for the outputs (default: renders)")
    p.add_argument("--all", action="store_true",
                   help="run every showcase scene (" + ", ".join(SHOWCASE) + ")")
    add_quiet(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..errors import UsageError
    from ..model.scene import load_scene, packaged_scene

    if args.all and args.scene:
        raise UsageError("give either SCENE or --all, not both")
    paths = ([packaged_scene(n) for n in SHOWCASE] if args.all
             else [Path(args.scene) if args.scene else packaged_scene()])
    # Validate every scene before any output is written.
    scenes = [load_scene(p) for p in paths]
    for scene in scenes:
        if scene.outputs.gif is not None:
            from ..animation.render import MAX_FRAMES, check_frames

            gif = scene.outputs.gif
            check_frames(gif.t_end, gif.fps, MAX_FRAMES,
                         f"{scene.source}: outputs.gif.t_end")
    status = 0
    for scene in scenes:
        status = max(status, run_scene(scene, Path(args.out), quiet=args.quiet))
    return status


def run_scene(scene, out: Path, quiet: bool = False) -> int:
    """Make every output ``scene`` asks for in ``out``; returns the exit status (0 or 3)."""
    from ..solvers import simulate
    from .app import EXIT_VERDICT

    traj = simulate(scene, quiet=quiet)
    written: list[Path] = []
    if scene.outputs.figures:
        from ..io.figures import save_figure

        for name in scene.outputs.figures:
            ax = _figure(name, traj)
            written.append(save_figure(ax.figure, out / f"{scene.name}-{name}.png"))
    if scene.outputs.csv:
        written.append(traj.to_csv(out / f"{scene.name}.csv"))
        if scene.system.floor is not None:
            written.append(traj.events_to_csv(out / f"{scene.name}-impacts.csv"))
    if scene.outputs.gif is not None:
        from ..animation.render import render_gif

        gif = scene.outputs.gif
        written.append(render_gif(traj, out / f"{scene.name}.gif", quiet=quiet, fps=gif.fps,
                                  size=gif.size, strip=gif.strip, t_end=gif.t_end))
    if not quiet:
        for path in written:
            sys.stderr.write(f"wrote {path}\n")
    if not traj.verdict.ok:
        sys.stderr.write(f"dumbbell run: {scene.name}: {traj.solver}: {traj.verdict}\n")
        return EXIT_VERDICT
    return 0


def _figure(name: str, traj: Any) -> Any:
    """Draw figure ``name`` of a scene's ``[outputs] figures`` for ``traj``; returns its axes.
    The rotation preview runs its own variants of the scene first; the topple figure sets the
    run beside its closed form."""
    from .. import plot

    if name == "rotation":
        from ..analysis.rotation import preview

        return plot.rotation(preview(traj))
    if name == "contact":
        from ..analysis.contact import about_contact

        ax = plot.contact_momentum(about_contact(traj), solver=traj.solver)
        ax.figure.tight_layout()
        return ax
    if name == "topple":
        from ..analysis.topple import closed_form, measure

        axes = plot.topple(closed_form(traj.scene), measure(traj), solver=traj.solver)
        axes[0].figure.tight_layout()
        return axes[0]
    return getattr(plot, name)(traj)
