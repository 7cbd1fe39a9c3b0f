"""``dumbbell stability``: the catalogue of extreme scenes, every solver, beside the theory."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._display import counted
from .app import add_out, add_quiet, options, positive_int

if TYPE_CHECKING:
    from ..analysis.stability import StabilityOptions
    from ..solvers import Solver


#: What ``dumbbell stability --help`` says the command does.
DESCRIPTION = """\
Run every scene in DIR (default: the shipped scenes/extreme catalogue) with every solver
that can run it, and write OUT/stability.md (a table: verdict, w*dt, the largest relative
energy error, the time of failure, the verdict theory expects and whether they agree),
OUT/stability.csv and OUT/stability-map.png (log10 of the largest relative energy error over
(w*dt, mass ratio) for each time-stepping solver, with the line w*dt = 2).
"""


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "stability", help="run the extreme scenes with every solver and compare with theory",
        description=DESCRIPTION,
    )
    p.add_argument("--cases", metavar="DIR",
                   help="folder of scene files (default: the shipped scenes/extreme)")
    p.add_argument("--solvers", nargs="+", metavar="NAME",
                   help="solvers to run (default: every solver that can run each case; the "
                        "2D reference only on 2D cases)")
    add_out(p, "the report files")
    p.add_argument("--workers", type=positive_int("processes"), metavar="N",
                   help="local processes (default: the number of CPUs)")
    add_quiet(p)
    p.set_defaults(func=run)


def report(options: StabilityOptions, out: str | Path, note: str | None = None,
           args: argparse.Namespace | None = None
           ) -> dict[str, Any]:
    """Run the catalogue and the map; write OUT/stability.md, .csv and stability-map.png.
    Everything is validated before anything runs, and only then is ``note`` (a line about
    the workers) printed, so that a refusal stays one line. Returns rows, paths and skipped
    runs."""
    from ..analysis.stability import (
        StabilityResult,
        guard_lines,
        map_solvers,
        plan_runs,
        run_cases,
    )
    from ..errors import UsageError
    from ..io.stability import write

    runs, skipped = plan_runs(options)
    workers, quiet = options.workers, options.quiet
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a folder")
    from .app import plan_outputs

    steppers = map_solvers(options.solvers)
    plan_outputs(args or argparse.Namespace(out=out),
                 [out / "stability.md", out / "stability.csv"]
                 + ([out / "stability-map.png"] if steppers else []))
    if note:
        sys.stderr.write(f"dumbbell stability: {note}\n")
    result = StabilityResult(tuple(run_cases(runs, workers, quiet)), tuple(skipped),
                             tuple(guard_lines(runs)))
    written = write(result, out)
    path = write_map(options.solvers, out, workers, quiet)
    if path is not None:
        written.append(path)
    return {"rows": list(result.rows), "skipped": skipped, "written": written}


def write_map(solvers: tuple[type[Solver], ...] | None, out: str | Path,
              workers: int | None = None, quiet: bool = True) -> Path | None:
    """OUT/stability-map.png for the time-stepping ``solvers`` among those asked for (all by
    default); None when there is none."""
    from ..analysis.stability import map_rows, map_solvers
    from ..io.figures import save_figure
    from ..plot.maps import stability_map

    steppers = map_solvers(solvers)
    if not steppers:
        return None
    panels = stability_map({cls.name: map_rows(cls, workers, quiet) for cls in steppers})
    return save_figure(panels[0].figure, Path(out) / "stability-map.png", dpi=90)


def run(args: argparse.Namespace) -> int:
    from ..analysis.stability import StabilityOptions
    from ..parallel import cap_note

    # Jobs are many (cases x solvers); the CPUs are the cap that binds.
    note = cap_note("--workers", args.workers, 1 << 30)
    result = report(options(StabilityOptions, args), args.out, note, args)
    if not args.quiet:
        rows = result["rows"]
        bad = sum(not r.agrees for r in rows)
        sys.stderr.write(f"{counted(len(rows), 'run')}, {len(rows) - bad} agree with the theory, "
                         f"{bad} disagree\n")
        for path in result["written"]:
            sys.stderr.write(f"wrote {path}\n")
    return 0
