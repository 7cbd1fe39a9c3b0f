"""``dumbbell run``: the main job, everything a scene's ``[outputs]`` asks for."""

from __future__ import annotations

import argparse
import contextlib
import gc
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..animation.render import MAX_FRAMES
from ..errors import DumbbellError
from ..solvers import MAX_SAMPLES
from .app import add_out, add_quiet, positive_int
from .showcase import PIECES

#: The scenes ``dumbbell run --all`` runs (the other pieces of the showcase follow them).
SHOWCASE = tuple(p.scene for p in PIECES if p.argv[0] == "run")

def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "run", help="make everything a scene's [outputs] asks for (the main job)",
        description="Run SCENE with its own solver and settings and write what its [outputs] "
                    "table asks for (figures as PNG, the trajectory and impacts as CSV, GIFs) "
                    "into DIR. With no SCENE, runs the packaged textbook scene (section 13.5.1).",
    )
    p.add_argument("scene", metavar="SCENE", nargs="?",
                   help="scene file (TOML); default: the packaged textbook-1d scene")
    add_out(p, "the outputs")
    p.add_argument("--all", action="store_true",
                   help="make the whole showcase, every file the repository tracks in "
                        "renders/: the scenes " + ", ".join(SHOWCASE) + ", then "
                        + "; ".join(p.command for p in PIECES if p.argv[0] != "run")
                        + " (about two minutes on 2 cores)")
    p.add_argument("--max-samples", type=positive_int("samples", 10**12), metavar="N",
                   default=MAX_SAMPLES,
                   help=f"refuse, before anything runs, a scene whose run would keep more than "
                        f"N samples (run.t_end / run.dt / run.every + 1; default "
                        f"{MAX_SAMPLES:,})")
    p.add_argument("--max-frames", type=positive_int("frames"), metavar="N",
                   default=MAX_FRAMES,
                   help=f"refuse, before anything runs, a GIF of more than N frames "
                        f"(outputs.gif t_end x fps; default {MAX_FRAMES:,})")
    add_quiet(p)
    # The run's settings come from the scene: a refusal names its keys.
    p.set_defaults(func=run, names={"every": "run.every", "dt": "run.dt",
                                    "t_end": "run.t_end"})


def run(args: argparse.Namespace) -> int:
    from ..errors import UsageError
    from .app import read_scene
    from .showcase import load_packaged, run_pieces

    if args.all and args.scene:
        raise UsageError("give either SCENE or --all, not both")
    # A shipped scene (no SCENE, --all, the showcase's own) is not the user's file to edit.
    packaged = args.all or not isinstance(args.scene, str)
    scenes = ([load_packaged(n) for n in SHOWCASE] if args.all
              else [read_scene(args.scene, stdin=False) if args.scene
                    else load_packaged("textbook-1d")])
    # Validate every scene, and its budgets, before any output is written.
    for scene in scenes:
        _check_budgets(scene, args.max_samples, args.max_frames, packaged=packaged)
    if args.all:
        return run_pieces(Path(args.out), quiet=args.quiet, max_samples=args.max_samples,
                          max_frames=args.max_frames)
    from .app import plan_outputs

    plan_outputs(args, [path for _, path in outputs(scenes[0], Path(args.out))])
    return run_scene(scenes[0], Path(args.out), quiet=args.quiet,
                     max_samples=args.max_samples, max_frames=args.max_frames)


def _check_budgets(scene, max_samples: int, max_frames: int, packaged: bool = False) -> None:
    """UsageError naming the scene and its keys when its run would keep more than
    ``max_samples`` samples or its GIF have more than ``max_frames`` frames. A ``packaged``
    scene (installed with dumbbell, not the user's to edit) is named by its name, and the
    message offers only the flags."""
    import string

    from ..animation.render import _check_frames
    from ..errors import UsageError
    from ..solvers.base import scene_options

    def in_scene(exc: UsageError, keys: dict[str, str]) -> UsageError:
        if not packaged:
            return UsageError(f"{scene.source}: {exc.reason}", fixes=exc.fixes).named(keys)
        # Only the budget flags: the scene's keys are in a file inside the installation.
        flags = [f for f in exc.fixes
                 if all(p in (None, "max_frames", "max_samples")
                        for _, p, _, _ in string.Formatter().parse(f))]
        return UsageError(f"the packaged scene {scene.name}: {exc.reason}", fixes=flags)

    try:
        scene_options(scene, max_samples=max_samples)
    except UsageError as exc:
        raise in_scene(exc, {}) from None
    if scene.outputs.gif is not None:
        gif = scene.outputs.gif
        try:
            _check_frames(gif.t_end, gif.fps, max_frames,
                         "the GIF's length" if packaged else "outputs.gif.t_end")
        except UsageError as exc:
            raise in_scene(exc, {"t_end": "outputs.gif.t_end",
                                 "fps": "outputs.gif.fps"}) from None


def outputs(scene, out: Path) -> list[tuple[str, Path]]:
    """Every file :func:`run_scene` writes for ``scene`` in ``out``, with what it is (each
    figure's name, 'csv', 'impacts', 'gif'), one pair per file written: a figure listed twice
    would be two pairs on one path, which the plan refuses."""
    names = [(name, out / f"{scene.name}-{name}.png") for name in scene.outputs.figures]
    if scene.outputs.csv:
        names.append(("csv", out / f"{scene.name}.csv"))
        if scene.system.floor is not None:
            names.append(("impacts", out / f"{scene.name}-impacts.csv"))
    if scene.outputs.gif is not None:
        names.append(("gif", out / f"{scene.name}.gif"))
    return names


def run_scene(scene, out: Path, quiet: bool = False, max_samples: int = MAX_SAMPLES,
              max_frames: int = MAX_FRAMES) -> int:
    """Make every output ``scene`` asks for in ``out``, refusing a run that would keep more
    than ``max_samples`` samples or a GIF of more than ``max_frames`` frames; returns the
    exit status (0, 3 or 4: :func:`~.app.verdict_status`). The figures are drawn beside the CSVs and the GIF, in a forked
    process, where there is a CPU for it (:mod:`.beside`); the bytes are the same either
    way."""
    from ..files import atomic_output
    from ..solvers import run_scene
    from ..solvers.base import scene_options
    from .app import verdict_status
    from .beside import beside

    names = dict(outputs(scene, out))
    with contextlib.ExitStack() as stack:
        # The figures' files first (the child writes them), then the child: leaving early
        # stops the child before the files are removed.
        files = {name: stack.enter_context(atomic_output(names[name]))
                 for name in scene.outputs.figures}
        figures = stack.enter_context(beside(
            lambda traj, alive: _draw_figures(files, traj, alive), _figure_imports,
            fork=None if files else False))
        options = scene_options(scene, max_samples=max_samples)
        traj = run_scene(scene, None, replace(options, quiet=quiet))
        # numba, its kernels and whatever else the run imported stay until the command ends:
        # the garbage collector need not look at them again.
        gc.freeze()
        figures.send(traj)
        try:
            _write_rest(scene, traj, names, quiet, max_frames)
        except (DumbbellError, OSError):
            # Drawn one after the other, the figures would have failed first: their error is
            # the one to tell.
            figures.wait()
            raise
        figures.wait()
    if not quiet:
        for path in names.values():
            sys.stderr.write(f"wrote {path}\n")
    if not traj.verdict.ok:
        sys.stderr.write(f"dumbbell run: {scene.name}: {traj.solver}: {traj.verdict}\n")
    return verdict_status(traj.verdict)


def _write_rest(scene, traj: Any, names: dict[str, Path], quiet: bool, max_frames: int
                ) -> None:
    """The CSVs and the GIF of ``scene`` from ``traj``, into the files ``names`` gives."""
    if scene.outputs.csv:
        from ..io.trajectory import write_csv, write_events

        write_csv(traj, names["csv"])
        if "impacts" in names:
            write_events(traj, names["impacts"])
    if scene.outputs.gif is not None:
        from ..animation.render import _render_gif
        from .render import gif_trajectory

        gif = scene.outputs.gif
        # The samples `dumbbell render` would draw from: one scene, one GIF's bytes. Its
        # settings were checked when the scene was read, its frames by _check_budgets.
        drawn = gif_trajectory(scene, gif, quiet=quiet, traj=traj)
        _render_gif(drawn, names["gif"], gif, quiet, None)


def _figure_imports() -> None:
    """What drawing the figures imports, done in the child before the trajectory comes."""
    import matplotlib.backends.backend_agg
    import matplotlib.figure  # noqa: F401

    from .. import plot  # noqa: F401
    from ..io import figures  # noqa: F401


def _draw_figures(files: dict[str, Path], traj: Any, alive: Any) -> None:
    """Draw each figure ``files`` names for ``traj`` into its (temporary) file, while
    ``alive()``."""
    from ..io.figures import write_figure

    for name, path in files.items():
        ax = _figure(name, traj)
        if not alive():
            return
        write_figure(ax.figure, path)


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

        return plot.contact_momentum(about_contact(traj), solver=traj.solver)
    if name == "topple":
        from ..analysis.topple import closed_form, measure

        return plot.topple(closed_form(traj.scene), measure(traj), solver=traj.solver)[0]
    return getattr(plot, name)(traj)
