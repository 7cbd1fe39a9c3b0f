"""``dumbbell compare``: the engine and the hand-written method against the exact solution
(1D and the rigid 2D dumbbell) or the high-accuracy reference (2D spring)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .app import _shown, add_out, add_quiet, add_scene, positive_float, read_scene, solver_names

#: What ``dumbbell compare --help`` says the command does.
DESCRIPTION = """\
Run SCENE with pymunk and the hand-written method (or --solvers) and with the most accurate
solution there is (exact in 1D and for the rigid 2D dumbbell, the RK8 reference for a 2D
spring), then print and write: impact times side by side, the largest position error over a
window before the chaotic motion parts the runs, each solver's energy error over the whole
run, and run times. Writes SCENE-compare.csv, -compare-impacts.csv, -compare-errors.csv and
three PNG figures (positions, error, energy) into DIR.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "compare", help="solvers against the exact solution or the 2D reference",
        description=DESCRIPTION,
    )
    add_scene(p)
    add_out(p, "the outputs")
    p.add_argument("--dt", type=positive_float("s"), nargs="+", metavar="DT",
                   help="time step(s) in s for the compared solvers (default: the scene's "
                        "run.dt); several give one run each")
    p.add_argument("--window", type=positive_float("s"), default=2.0, metavar="T",
                   help="window [0, T] s for the position error (default: 2)")
    p.add_argument("--t-end", type=positive_float("s"), metavar="T",
                   help="end time in s (default: the scene's run.t_end)")
    p.add_argument("--solvers", metavar="NAME", nargs="+",
                   help="solvers to compare, as in bench and stability (commas also work; "
                        "default: pymunk and euler-cromer in 1D, pymunk and euler-cromer-2d "
                        "in 2D)")
    add_quiet(p)
    p.set_defaults(func=run, names={"dts": "--dt"})


def run(args: argparse.Namespace) -> int:
    from ..analysis.compare import CompareOptions, compare
    from ..errors import UsageError
    from ..io.compare import text, write
    from ..solvers import available

    scene = read_scene(args.scene)
    solvers = None
    if args.solvers:
        solvers = solver_names(args.solvers)
        unknown = [s for s in solvers if s not in available()]
        if unknown or not solvers:
            raise UsageError(f"--solvers {_shown(' '.join(args.solvers))}: must name solvers among "
                             + ", ".join(available()))
    from .app import plan_outputs

    stem = Path(args.out) / f"{scene.name}-compare"
    plan_outputs(args, [Path(f"{stem}{end}") for end in (
        ".csv", "-impacts.csv", "-errors.csv", "-positions.png", "-error.png", "-energy.png")])
    try:
        result = compare(scene, CompareOptions(solvers, args.dt, args.window, args.t_end,
                                               args.quiet))
    except UsageError as exc:
        if exc.param != "dts":
            raise
        # The library's dts is this command's --dt: "dts: dt = ..." reads "--dt = ...".
        raise UsageError(exc.reason.removeprefix("dts: "), param="dt",
                         fixes=exc.fixes) from None
    paths = write(result, Path(args.out))
    from .. import plot
    from ..io.figures import save_figure

    for name, draw in (("positions", plot.compare_positions), ("error", plot.compare),
                       ("energy", plot.compare_energy)):
        paths.append(save_figure(draw(result).figure, f"{stem}-{name}.png"))
    print(text(result))
    if not args.quiet:
        for path in paths:
            sys.stderr.write(f"wrote {path}\n")
    return 0
