"""``dumbbell sweep``: one scene over a grid of parameter values, to CSV and a map PNG."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .._display import counted
from .app import add_out, add_quiet, positive_float, positive_int, read_scene

#: What ``dumbbell sweep --help`` says the command does.
DESCRIPTION = """\
Run SCENE at every point of a grid of one or two scene keys and write OUT/SCENE-sweep.csv
(one row per point: the values, w*dt, the verdict, the time of failure and the largest
relative energy error) and OUT/SCENE-sweep.png (a map of log10 of that error, failures
marked by verdict, the line w*dt = 2 on top). The CSV is the same whichever backend runs it.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep", help="run one scene over a grid of parameters (process pool or Dask)",
        description=DESCRIPTION,
        epilog="Example: dumbbell sweep scenes/textbook-1d.toml --grid k=log:1e2:1e7:50 "
               "dt=log:1e-6:1e-2:50 --t-end 1. On a Dask cluster (pip install "
               "'dumbbell[dask]'; dask scheduler; dask worker tcp://HOST:8786): add "
               "--scheduler tcp://HOST:8786.",
    )
    p.add_argument("scene", metavar="SCENE", help="scene file (TOML)")
    p.add_argument("--grid", nargs="+", required=True, metavar="NAME=SPEC",
                   help="one or two axes: NAME a dotted scene key (spring.stiffness, "
                        "bodies.A.mass, run.dt; k and dt are short names), SPEC log:A:B:N, "
                        "lin:A:B:N or V1,V2,...")
    p.add_argument("--solver", metavar="NAME",
                   help="solver (default: the scene's run.solver)")
    p.add_argument("--t-end", type=positive_float("s"), metavar="T",
                   help="end time of every run in s (default: the scene's run.t_end)")
    add_out(p, "the CSV and PNG")
    p.add_argument("--workers", type=positive_int("processes"), metavar="N",
                   help="local processes (default: the number of CPUs; 1 runs in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on the Dask cluster at ADDRESS (tcp://host:8786), or 'local' to "
                        "start a Dask LocalCluster here; needs pip install 'dumbbell[dask]'")
    p.add_argument("--connect-timeout", type=positive_float("s"), metavar="S", default=10.0,
                   help="seconds to wait for the Dask scheduler at --scheduler to answer "
                        "(default 10)")
    add_quiet(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..analysis.sweep import SweepOptions, check_axes, parse_axis, plan, run_sweep
    from ..errors import UsageError
    from ..parallel import cap_note
    from ..solvers import solver_class

    scene = read_scene(args.scene, stdin=False)
    axes = [parse_axis(text) for text in args.grid]
    check_axes(axes)
    for axis in axes:
        if not axis.numeric:
            raise UsageError(f"--grid {axis.text!r}: a map needs numbers; list numbers only")
    solver = solver_class(args.solver or scene.run.solver)
    if args.scheduler is not None:
        address = args.scheduler.strip()
        if address != "local" and "://" not in address:
            raise UsageError(f"--scheduler {args.scheduler!r}: must be 'local' or an address "
                             "such as tcp://host:8786")
        if args.workers is not None and address != "local":
            raise UsageError("--workers: the cluster's own workers run the sweep; give "
                             "--workers only with --scheduler local")
        try:
            import dask.distributed  # noqa: F401
        except ImportError:
            raise UsageError("--scheduler needs dask.distributed: pip install "
                             "'dumbbell[dask]'") from None
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out}: exists and is not a folder")
    points = plan(scene, axes, solver, args.t_end)
    from .app import plan_outputs

    csv_path, png_path = plan_outputs(args, [out / f"{scene.name}-sweep.csv",
                                             out / f"{scene.name}-sweep.png"])
    note = cap_note("--workers", args.workers, len(points), "grid points")
    if note:
        sys.stderr.write(f"dumbbell sweep: {note}\n")
    result = run_sweep(scene, axes, SweepOptions(
        solver, args.t_end, args.workers, args.scheduler and args.scheduler.strip(), args.quiet,
        connect_timeout=args.connect_timeout), points)
    from ..io.figures import save_figure
    from ..io.sweep import write_csv

    write_csv(result, csv_path)
    from ..plot.maps import sweep_map

    save_figure(sweep_map(result).figure, png_path, dpi=100)
    if not args.quiet:
        counts = ", ".join(f"{n} {v}" for v, n in sorted(result.counts().items()))
        sys.stderr.write(f"{counted(len(result.rows), 'run')} ({counts}) in {result.wall_time:.2f} s on "
                         f"{result.backend}\nwrote {csv_path}\nwrote {png_path}\n")
    return 0
