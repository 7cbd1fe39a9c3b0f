"""``dumbbell simulate``: one run of one scene to CSV."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import UsageError
from ..solvers.base import MAX_SAMPLES, MAX_STEPS
from .app import (
    add_quiet,
    add_scene,
    positive_float,
    positive_int,
    read_scene,
    stdout_closed,
    verdict_status,
)

#: What ``dumbbell simulate --help`` says the command does.
DESCRIPTION = """\
Run SCENE and write a CSV with a header row: for 1D scenes
t,xA,vA,xB,vB,K_cm,K_int,U_g,U_spring,E (s, m, m/s, J; x vertical); for 2D scenes positions
and velocities in x and y, then the energy terms the scene can have. A run that ends badly
(unstable, tunnelled, failed) keeps its samples up to the failure, prints one line saying
why, and exits 3.
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "simulate", help="run one scene and write its trajectory as CSV",
        description=DESCRIPTION,
    )
    add_scene(p, solver="solver: euler-cromer, exact, pymunk, ... (default: the scene's "
                        "run.solver)")
    p.add_argument("--dt", type=positive_float("s"), metavar="DT",
                   help="time step in s (default: the scene's run.dt)")
    p.add_argument("--t-end", type=positive_float("s"), metavar="T",
                   help="end time in s (default: the scene's run.t_end)")
    p.add_argument("--every", type=positive_int("steps", MAX_STEPS), metavar="N",
                   help="keep every N-th step (default: the scene's run.every, else 1)")
    p.add_argument("--max-samples", type=positive_int("samples", 10**12), metavar="N",
                   default=MAX_SAMPLES,
                   help=f"refuse, before anything runs, a run that would keep more than N "
                        f"samples (t_end / dt / every + 1; default {MAX_SAMPLES:,}, about "
                        f"{MAX_SAMPLES * 80 // 10**6} MB for a 1D scene)")
    p.add_argument("-o", "--output", metavar="FILE",
                   help="CSV file to write (default, or '-': standard output)")
    p.add_argument("--events", metavar="FILE",
                   help="also write the impacts as CSV: t,body,v_before,v_after (s, -, m/s, m/s)")
    add_quiet(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..io.trajectory import dump_csv, write_csv, write_events
    from ..solvers import simulate

    if (not args.output or args.output == "-") and stdout_closed():
        raise UsageError("-o -: standard output is closed, so the CSV has nowhere to go; "
                         "give -o FILE")
    scene = read_scene(args.scene)
    traj = simulate(scene, args.solver, dt=args.dt, t_end=args.t_end, every=args.every,
                    quiet=args.quiet, max_samples=args.max_samples)
    if args.output and args.output != "-":
        write_csv(traj, args.output)
    else:
        dump_csv(traj, sys.stdout)
    if args.events:
        write_events(traj, Path(args.events))
    if not traj.verdict.ok:
        sys.stderr.write(f"dumbbell simulate: {traj.solver}: {traj.verdict}\n")
    return verdict_status(traj.verdict)
