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


def arguments(name: str, doc: str, seconds: float, argv: list[str] | None) -> argparse.Namespace:
    """The examples' command line: ``--out`` (``NAME.gif``), ``--seconds``, ``--fps``, ``--dt``
    (s; each example also runs at dt / 10). Bad values: one line and exit status 2."""
    parser = argparse.ArgumentParser(prog=f"python -m dumbbell.examples.{name}",
                                     description=doc.splitlines()[0])
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
    return args


def print_guard(space: Any, args: argparse.Namespace) -> None:
    """Print the step-size guard's report at the frame step and at the example's step."""
    from .. import spaces

    print(spaces.report(space, 1.0 / args.fps))
    print(spaces.report(space, args.dt))
