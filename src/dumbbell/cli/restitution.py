"""``dumbbell restitution``: the apparent restitution of a tilted dumbbell against its tilt."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .app import _shown, add_out, add_quiet, positive_float, read_scene

#: Largest number of tilts in one call: each costs several runs.
MAX_TILTS = 91


def tilt_range(text: str) -> list[float]:
    """An argparse type: START:STOP:N (N tilts in degrees from START to STOP inclusive) or a
    list A,B,C; every tilt in [0, 90) degrees."""
    message = (f"{_shown(text)}: must be START:STOP:N or a list A,B,...: degrees in [0, 90), with "
               f"START <= STOP and N a whole number from 1 to {MAX_TILTS} (N = 1 needs "
               "START = STOP)")
    try:
        if ":" in text:
            start_s, stop_s, n_s = text.split(":")
            start, stop, n = float(start_s), float(stop_s), int(n_s)
            if not (1 <= n <= MAX_TILTS) or (n == 1) != (start == stop) or start > stop:
                raise ValueError
            values = [start] if n == 1 else [start + (stop - start) * i / (n - 1)
                                             for i in range(n)]
        else:
            values = [float(v) for v in text.split(",")]
            if not (1 <= len(values) <= MAX_TILTS) or values != sorted(set(values)):
                raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(message) from None
    if not all(0 <= v < 90 for v in values):
        raise argparse.ArgumentTypeError(message)
    return values


tilt_range.__name__ = "tilt range"


def restitution_coefficient(text: str) -> float:
    """An argparse type: a number from 0 to 1."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"{_shown(text)}: must be a number from 0 to 1")
    return value


restitution_coefficient.__name__ = "restitution"


#: What ``dumbbell restitution --help`` says the command does.
DESCRIPTION = """\
Drop SCENE's dumbbell (2D, frictionless floor) at each tilt and measure e_eff =
-V_after/V_before of its centre of mass: rigid in the truth and in pymunk (first impact,
against the impulse law's formula), and as spring dumbbells of three stiffnesses in pymunk
(after the first cluster of impacts). Writes SCENE-restitution.csv (one row per tilt) and
SCENE-restitution.png into DIR and prints the table.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "restitution", help="apparent restitution of a tilted dumbbell against its tilt",
        description=DESCRIPTION,
    )
    p.add_argument("scene", metavar="SCENE", help="scene file (TOML), 2D with a spring or rod")
    p.add_argument("--theta", type=tilt_range, default=tilt_range("0:80:9"),
                   metavar="START:STOP:N",
                   help="N tilts in degrees from START to STOP inclusive (default 0:80:9; "
                        "0:60:3 is 0, 30 and 60), or a list such as 0,30,45,60,80")
    p.add_argument("--elasticity", type=restitution_coefficient, metavar="E",
                   help="the floor's restitution, 0 to 1 (default: the scene's "
                        "floor.elasticity)")
    p.add_argument("--dt", type=positive_float("s"), default=1e-5, metavar="DT",
                   help="pymunk's time step in s for the rigid dumbbell (default 1e-5; the "
                        "spring dumbbells use at most 0.02/w)")
    p.add_argument("--stiffness", type=positive_float("N/m"), nargs="+", metavar="K",
                   default=[200.0, 2e3, 2e4],
                   help="spring constants of the spring dumbbells in N/m (default 200 2000 "
                        "20000)")
    add_out(p, "the CSV and PNG")
    add_quiet(p)
    # The library's thetas and stiffnesses are --theta and --stiffness here.
    p.set_defaults(func=run, names={"thetas": "--theta", "stiffnesses": "--stiffness"})


def run(args: argparse.Namespace) -> int:
    from ..analysis.restitution import restitution
    from ..io.figures import save_figure
    from ..io.restitution import markdown, write_csv
    from ..plot.rotation_chapter import restitution as draw
    from ..progress import bar

    scene = read_scene(args.scene, stdin=False)
    if args.elasticity is not None and scene.system.floor is not None:
        scene = scene.with_values({"floor.elasticity": args.elasticity})
    from .app import plan_outputs

    out = Path(args.out)
    csv, png = plan_outputs(args, [out / f"{scene.name}-restitution.csv",
                                   out / f"{scene.name}-restitution.png"])
    runs = len(args.theta) * (1 + len(args.stiffness))
    with bar(runs, "restitution", unit="run", quiet=args.quiet) as progress:
        result = restitution(scene, args.theta, tuple(args.stiffness), args.dt,
                             progress=progress.update)
    write_csv(result, csv)
    save_figure(draw(result)[0].figure, png)
    print(markdown(result))
    if not args.quiet:
        for path in (csv, png):
            sys.stderr.write(f"wrote {path}\n")
    return 0
