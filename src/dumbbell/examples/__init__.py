"""Examples of :mod:`dumbbell.spaces` on spaces that are not dumbbells, each runnable as
``python -m dumbbell.examples.NAME``: it writes a GIF with energy bars and prints the step-size
guard's report and what it measured.

- ``newtons_cradle``: five elastic balls on pins; energy and momentum pass along the row;
- ``pendulum``: a physical pendulum on a ``DampedRotarySpring``; its period against the
  small-angle formula;
- ``slope``: a box sliding and tumbling down a slope with friction; the heat counter closes
  the energy balance.
"""

from __future__ import annotations

import argparse
from typing import Any

#: The examples, each a module with ``build()``, ``measure(dt, seconds, ...)`` and ``main()``.
__all__ = ["newtons_cradle", "pendulum", "slope"]

#: Most steps one ``measure`` may take (``seconds / dt``): a few minutes of pymunk.
MAX_STEPS = 10**8


def check_run(dt: Any, seconds: Any, fps: Any) -> tuple[float, float, int]:
    """The times of an example's ``measure`` checked at the border (UsageError naming
    the one that is not valid): ``dt`` (s) > 0 and at most one frame 1/``fps`` (fps 1..50),
    ``seconds`` (s) > 0 with at most :data:`MAX_STEPS` steps. Returns (dt, seconds, fps);
    :func:`check_tools` checks the rest."""
    from ..animation.render import check_fps
    from ..errors import UsageError
    from ..model import args

    dt = args.real(dt, "dt", "s")
    seconds = args.real(seconds, "seconds", "s")
    fps = check_fps(fps)
    if dt > 1.0 / fps:
        raise UsageError(f"dt = {dt:g}: must be at most one frame, 1/fps = {1.0 / fps:g} s",
                         param="dt")
    if seconds / dt > MAX_STEPS:
        raise UsageError(f"seconds = {seconds:g}: {seconds:g} s / dt {dt:g} s is more than "
                         f"{MAX_STEPS:,} steps; lower seconds or raise dt", param="seconds")
    return dt, seconds, fps


def check_tools(space: Any, recorder: Any = None, heat: Any = None) -> None:
    """The objects an example's ``measure`` is given, checked at the border: ``space`` None
    or a pymunk.Space with a dynamic body, ``recorder`` None or a Recorder, ``heat`` None or
    a HeatCounter."""
    from ..errors import UsageError
    from ..model import args

    if space is not None:
        import pymunk

        args.space(space)
        if not any(b.body_type == pymunk.Body.DYNAMIC for b in space.bodies):
            raise UsageError("space: holds no dynamic body; give the example's build() or None",
                             param="space")
    if recorder is not None:
        from ..spaces.recorder import Recorder

        args.instance(recorder, "recorder", Recorder, "a dumbbell.spaces.Recorder or None")
    if heat is not None:
        from ..spaces.heat import HeatCounter

        args.instance(heat, "heat", HeatCounter, "a dumbbell.spaces.HeatCounter or None")


def check_argv(argv: Any) -> list[str] | None:
    """``argv`` as None (the command line) or a list of str, else a UsageError."""
    from ..errors import UsageError
    from ..model import args

    if argv is not None and (not isinstance(argv, list | tuple)
                             or not all(isinstance(a, str) for a in argv)):
        raise UsageError(f"argv = {args.show(argv)}: must be a list of str or None",
                         param="argv")
    return None if argv is None else list(argv)


def arguments(name: str, doc: str | None, seconds: float, argv: list[str] | None
              ) -> argparse.Namespace:
    """The examples' command line: ``--out`` (``NAME.gif``), ``--seconds``, ``--fps``, ``--dt``
    (s; each example also runs at dt / 10). Bad values: one line and exit status 2. ``doc``:
    the example's docstring, whose first line describes it (None under ``python -OO``, which
    drops docstrings: the description then only names the example)."""
    argv = check_argv(argv)
    summary = doc.strip().splitlines()[0] if doc and doc.strip() else \
        f"The {name} example of dumbbell.spaces."
    parser = argparse.ArgumentParser(prog=f"python -m dumbbell.examples.{name}",
                                     description=summary)
    parser.add_argument("--out", default=f"{name}.gif", help="GIF or MP4 to write")
    parser.add_argument("--seconds", type=float, default=seconds, help="simulated time (s)")
    parser.add_argument("--fps", type=int, default=25, help="frames per second (1..50)")
    parser.add_argument("--dt", type=float, default=1e-3, help="step (s); also run at dt/10")
    args = parser.parse_args(argv)
    for key in ("seconds", "dt"):
        value = getattr(args, key)
        if not (value > 0 and value < float("inf")):
            parser.error(f"--{key} {value}: must be a finite number > 0 (s)")
    if not 1 <= args.fps <= 50:
        parser.error(f"--fps {args.fps}: must be a whole number from 1 to 50")
    if args.dt > 1.0 / args.fps:
        parser.error(f"--dt {args.dt}: must be at most one frame, 1/fps s")
    if args.seconds / args.dt > MAX_STEPS:
        parser.error(f"--seconds {args.seconds}: more than {MAX_STEPS:,} steps of --dt")
    return args


def print_guard(space: Any, args: argparse.Namespace) -> None:
    """Print the step-size guard's report at the frame step and at the example's step (the
    examples are in SI units: lengths in m)."""
    from .. import spaces

    print(spaces.report(space, 1.0 / args.fps, units="m"))
    print(spaces.report(space, args.dt, units="m"))


def record_and_compare(args: argparse.Namespace, space: Any, measure: Any, line: Any,
                       header: str = "", **recorder: Any) -> int:
    """An example's run: ``measure(dt, seconds, fps, space, rec)`` measures ``space`` at
    ``args.dt`` while a Recorder ``rec`` (with the keywords ``recorder``; its ``heat`` counter
    is given to ``measure`` too) captures each frame into ``args.out``, then a new space again
    at dt / 10; then ``header`` (if any), a ``line(dt, measured)`` for each run and the file
    written. Returns the exit status, 0."""
    from .. import spaces
    from .._display import counted

    tools = {"heat": recorder["heat"]} if "heat" in recorder else {}
    with spaces.Recorder(space, args.out, fps=args.fps, units="m", **recorder) as rec:
        rec.capture()
        measured = measure(args.dt, args.seconds, args.fps, space, rec, **tools)
    if header:
        print(header)
    again = measure(args.dt / 10, args.seconds, args.fps)
    for dt, m in ((args.dt, measured), (args.dt / 10, again)):
        print(line(dt, m))
    print(f"wrote {args.out} ({counted(rec.frames, 'frame')})")
    return 0
