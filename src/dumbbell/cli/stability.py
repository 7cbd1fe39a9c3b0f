"""``dumbbell stability``: the catalogue of extreme scenes, every solver, beside the theory."""

from __future__ import annotations

import argparse
import sys

from .app import add_quiet, positive_int


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "stability", help="run the extreme scenes with every solver and compare with theory",
        description="Run every scene in DIR (default: the shipped scenes/extreme catalogue) "
                    "with every solver that can run it, and write OUT/stability.md (a table: "
                    "verdict, w*dt, the largest relative energy error, the time of failure, "
                    "the verdict theory expects and whether they agree), OUT/stability.csv and "
                    "OUT/stability-map.png (log10 of the largest relative energy error over "
                    "(w*dt, mass ratio) for each time-stepping solver, with the line w*dt = 2).",
    )
    p.add_argument("--cases", metavar="DIR",
                   help="folder of scene files (default: the shipped scenes/extreme)")
    p.add_argument("--solvers", nargs="+", metavar="NAME",
                   help="solvers to run (default: every solver that can run each case; the "
                        "2D reference only on 2D cases)")
    p.add_argument("--out", metavar="DIR", default="renders",
                   help="folder for the report files (default: renders)")
    p.add_argument("--workers", type=positive_int("processes"), metavar="N",
                   help="local processes (default: the number of CPUs)")
    add_quiet(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..analysis.stability import report

    result = report(args.cases, args.solvers, args.out, args.workers, args.quiet)
    if not args.quiet:
        rows = result["rows"]
        bad = sum(r["agreement"] != "agrees" for r in rows)
        sys.stderr.write(f"{len(rows)} runs, {len(rows) - bad} agree with the theory, "
                         f"{bad} disagree\n")
        for path in result["written"]:
            sys.stderr.write(f"wrote {path}\n")
    return 0
