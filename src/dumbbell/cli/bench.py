"""``dumbbell bench``: work-precision diagrams, error against run time for every solver."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .app import add_out, add_quiet, options, positive_float, positive_int, read_scene


def register(sub: argparse._SubParsersAction) -> None:
    from ..analysis.bench import (
        DEFAULT_BUDGET,
        DEFAULT_REPEAT,
        DEFAULT_WINDOW,
        MAX_REPEAT,
        MIN_TIMED,
        SAMPLE_SPACING,
        SAMPLES_PER_PERIOD,
    )

    p = sub.add_parser(
        "bench", help="error against run time for every solver (work-precision diagrams)",
        description="Run SCENE with each solver at each step size and measure the largest "
                    "position error over [0, T] against the truth (the exact solution in 1D "
                    "and for the rigid 2D dumbbell; the reference solver for a 2D spring), the largest relative energy error over the "
                    "whole run and the error of the impact times, against the run time "
                    "(fastest and median of N runs after a warm-up; JIT compile reported "
                    "apart). Writes bench-SCENE.csv, .json, .md, -work-precision.png and "
                    "-convergence.png into DIR. Failed runs are listed as failed; a step "
                    "whose runs would exceed the budget is listed as skipped. Exit 0 even "
                    "when some runs fail: failures are results here.",
    )
    p.add_argument("scene", metavar="SCENE", help="scene file (TOML)")
    add_out(p, "the outputs")
    p.add_argument("--solvers", nargs="+", metavar="NAME",
                   help="solvers to compare (default: every solver the scene supports, "
                        "except the truth, which is always added as a point of its own)")
    p.add_argument("--dts", nargs="+", type=positive_float("s"), metavar="DT",
                   help="step sizes in s (default: 1e-3 3.16e-4 1e-4 ... 1e-6)")
    p.add_argument("--window", type=positive_float("s"), metavar="T", default=DEFAULT_WINDOW,
                   help=f"window of the position error, [0, T] in s (default {DEFAULT_WINDOW:g}"
                        ": the motion is chaotic, so later errors measure divergence, not "
                        "accuracy)")
    p.add_argument("--t-end", type=positive_float("s"), metavar="T",
                   help="simulated time of each run in s (default: the scene's run.t_end)")
    p.add_argument("--repeat", type=positive_int("runs", MAX_REPEAT), metavar="N", default=DEFAULT_REPEAT,
                   help=f"timed runs per point after one warm-up run (default {DEFAULT_REPEAT}"
                        f"; runs shorter than {MIN_TIMED:g} s in all are repeated until they "
                        "are not)")
    p.add_argument("--budget", type=positive_float("s"), metavar="S", default=DEFAULT_BUDGET,
                   help="skip a step when the estimated time of its runs (steps x cost per "
                        "step at the previous step x (N+1)) passes S seconds (default "
                        f"{DEFAULT_BUDGET:g})")
    p.add_argument("--sample-spacing", type=positive_float("s"), metavar="S",
                   help=f"compare positions at samples about S seconds apart (every "
                        f"round(S/dt) steps; default {SAMPLE_SPACING:g}, the textbook run's "
                        f"output, or 1/{SAMPLES_PER_PERIOD} of the spring's period if shorter); "
                        "the exact and reference solvers are timed for exactly these samples")
    add_quiet(p)
    # The library's dt (one of dts) and spacing are --dts and --sample-spacing here.
    p.set_defaults(func=run, names={"dt": "--dts", "spacing": "--sample-spacing"})


def run(args: argparse.Namespace) -> int:
    from ..analysis.bench import BenchOptions, run_bench
    from ..io.bench import write_all
    from .app import plan_outputs

    scene = read_scene(args.scene, stdin=False)
    stem = Path(args.out) / f"bench-{scene.name}"
    plan_outputs(args, [Path(f"{stem}{end}") for end in (
        ".csv", ".json", ".md", "-work-precision.png", "-convergence.png")])
    result = run_bench(scene, options(BenchOptions, args, spacing="sample_spacing"))
    written = write_all(result, Path(args.out))
    from ..io.figures import save_figure
    from ..plot.bench import convergence, work_precision

    # The figures keep their own resolution ("figure": the dpi they were made with).
    written += [save_figure(work_precision(result).figure, f"{stem}-work-precision.png",
                            dpi="figure"),
                save_figure(convergence(result).figure, f"{stem}-convergence.png",
                            dpi="figure")]
    if not args.quiet:
        from ..io.bench import markdown

        sys.stdout.write(markdown(result))
        for path in written:
            sys.stderr.write(f"wrote {path}\n")
    return 0
