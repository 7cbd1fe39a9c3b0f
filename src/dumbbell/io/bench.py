"""The benchmark's files: CSV (one row per point), JSON (everything) and a Markdown table
(:class:`dumbbell.analysis.bench.BenchResult` in, files out). The figures are
:mod:`dumbbell.plot`'s."""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

from .._display import counted, significant
from ..analysis.bench import (
    CSV_COLUMNS,
    FIT_MAX_ERROR,
    FIT_MIN_ERROR,
    MIN_TIMED,
    BenchResult,
    dt_label,
)
from ..model import args
from .tables import csv_text, write_text

__all__ = ["markdown", "write_all"]


def _checked(result: Any) -> BenchResult:
    return args.instance(result, "result", BenchResult, "a BenchResult (from dumbbell.bench)")


def write_csv(result: BenchResult, path: Path) -> Path:
    """One row per point, columns CSV_COLUMNS (s, m, dimensionless)."""
    result = _checked(result)
    path = args.path(path, "path")
    rows = ([row[c] for c in CSV_COLUMNS] for row in map(_row, result.points))
    return write_text(path, csv_text(CSV_COLUMNS, rows))


def _row(point: Any) -> dict[str, Any]:
    """A point's fields as written: the verdict column says "skipped" for a step not run."""
    return {**asdict(point), "verdict": point.status}


def _json_value(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None if math.isnan(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, dict):
        return {k: _json_value(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_json_value(v) for v in value]
    return value


def to_json(result: BenchResult) -> dict[str, Any]:
    """The result as plain JSON data (inf as the string "inf", nan as null)."""
    result = _checked(result)
    data = {
        "scene": result.scene, "source": result.source, "truth": result.truth,
        "window_s": result.window, "t_end_s": result.t_end, "repeat": result.repeat,
        "budget_s": result.budget, "sample_spacing_s": result.spacing,
        "fit_max_error_m": FIT_MAX_ERROR, "fit_min_error_m": FIT_MIN_ERROR,
        "notes": result.notes,
        "points": [_row(p) for p in result.points],
        "orders": {n: asdict(f) for n, f in result.fits.items()},
        "matched_error": result.speedups(),
    }
    return _json_value(data)


def write_json(result: BenchResult, path: Path) -> Path:
    """:func:`to_json` as indented JSON."""
    result = _checked(result)
    path = args.path(path, "path")
    return write_text(path, json.dumps(to_json(result), indent=1) + "\n")


def _sci(x: float | None, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return f"{x:.{digits}e}"


def markdown(result: BenchResult) -> str:
    """The table, fitted orders and matched-error speed-ups as markdown: the
    ``bench-SCENE.md`` that ``dumbbell bench`` writes.

    Parameters
    ----------
    result : BenchResult
        The benchmark, from :func:`dumbbell.bench`.

    Returns
    -------
    str
        The Markdown text: the run's settings, the table, the fitted orders.

    Raises
    ------
    UsageError
        A ``result`` that is not a BenchResult (from :func:`dumbbell.bench`).

    Examples
    --------
    The table's header, below the line that says how the run was timed:

    >>> from dumbbell.io.bench import markdown
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.bench(scene, solvers=["verlet"], dts=[1e-3, 1e-4, 1e-5], window=1.0,
    ...                         t_end=1.0, repeat=1)
    >>> print(markdown(result).splitlines()[2])
    | solver | dt (s) | steps | run time min (median) | position error (m) | ...
    """
    result = _checked(result)
    lines = [
        (f"Work-precision benchmark of `{result.source}` over t_end = {result.t_end:g} s; "
        f"truth: `{result.truth}`; position error over [0, {result.window:g}] s; time: min "
        f"(median) of at least {counted(result.repeat, 'run')} after a warm-up; short runs are "
        f"repeated until {MIN_TIMED:g} s are timed."),
        "",
        ("| solver | dt (s) | steps | run time min (median) | position error (m) "
        "| energy error (rel.) | impact time error (s) | verdict |"),
        "|---|---|---|---|---|---|---|---|",
    ]
    for p in result.points:
        dt = dt_label(p.dt) if p.dt is not None else f"(samples every {result.spacing:g} s)"
        if p.ran:
            time_s = f"{_ms(p.seconds)} ({_ms(p.seconds_median)})"
        else:
            time_s = f"~{_ms(p.seconds)} (estimate)"
        verdict = p.status if p.complete else f"**{p.status}**" + (
            f" at {p.verdict_t:.3g} s" if p.verdict_t is not None else "")
        imp = _sci(p.impact_time_error)
        if p.impacts_truth:
            imp += f" ({p.impacts_compared}/{p.impacts_truth})"
        steps = f"{p.steps:,}" if p.dt is not None else "-"
        lines.append(f"| {p.solver} | {dt} | {steps} | {time_s} | {_sci(p.error)} "
                     f"| {_sci(p.energy_error)} | {imp} | {verdict} |")
    lines.append("")
    if result.fits:
        fit_text = "; ".join(
            f"{n} {f.order:.2f} (dt {dt_label(min(f.dts))}..{dt_label(max(f.dts))} s, "
            f"{counted(len(f.dts), 'point')}{'' if f.expected is None else f'; its order {f.expected}'})"
            for n, f in result.fits.items())
        lines.append(f"Fitted order of the position error over [0, {result.window:g}] s "
                     f"(least squares in log-log over the points that reached their end with "
                     f"error between "
                     f"{FIT_MIN_ERROR:g} and {FIT_MAX_ERROR:g} m): {fit_text}.")
    sp = result.speedups()
    if sp and sp.get("seconds"):
        parts = [f"{n} {_ms(t)} ({sp['speedup'].get(n, math.nan):.3g}x)"
                 for n, t in sp["seconds"].items()]
        lines.append(f"Run time to reach {sp['baseline']}'s error at dt = 1e-5 s "
                     f"({sp['target_error']:.2e} m), interpolated along each line "
                     f"(speed-up against {sp['baseline']}): {'; '.join(parts)}.")
    compile_parts = {p.solver: p.compile_seconds for p in result.points
                     if math.isfinite(p.compile_seconds)}
    if compile_parts:
        lines.append("JIT compile (or load from numba's cache) before the runs, not in the "
                     "times above: "
                     + "; ".join(f"{n} {_ms(v)}" for n, v in compile_parts.items())
                     + " (the first numba solver also pays numba's one-time start-up).")
    for p in result.points:
        if p.ran and p.window != result.window:
            lines.append(f"The {p.solver} row's errors are {p.reason}.")
    lines.extend(result.notes)
    return "\n".join(lines) + "\n"


def _ms(seconds: float) -> str:
    """A time in the unit that suits it (s, ms, µs), three significant digits with their
    trailing zeros, so that times side by side show one precision: '30.0 ms; 19.2 ms'."""
    if not math.isfinite(seconds):
        return "-"
    if seconds >= 1:
        return f"{significant(seconds)} s"
    if seconds >= 1e-3:
        return f"{significant(seconds * 1e3)} ms"
    return f"{significant(seconds * 1e6)} µs"


def write_markdown(result: BenchResult, path: Path) -> Path:
    """:func:`markdown` as a file."""
    result = _checked(result)
    path = args.path(path, "path")
    return write_text(path, markdown(result))


def write_all(result: BenchResult, out: Path) -> list[Path]:
    """CSV, JSON and markdown into a folder, named bench-SCENE*. (The figures are
    :mod:`dumbbell.plot`'s: :func:`~dumbbell.plot.work_precision` and
    :func:`~dumbbell.plot.convergence`; the command saves them.)

    Parameters
    ----------
    result : BenchResult
        What :func:`dumbbell.bench` measured.
    out : pathlib.Path
        As for :func:`dumbbell.io.compare.write`: the folder, made if missing.

    Returns
    -------
    list of pathlib.Path
        The CSV, JSON and Markdown files, in that order.

    Raises
    ------
    UsageError
        A ``result`` that is not a BenchResult, or an ``out`` that cannot be written.

    Examples
    --------
    >>> from pathlib import Path
    >>> import dumbbell
    >>> from dumbbell.io.bench import write_all
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.bench(scenes_dir() / "textbook-1d.toml", solvers=["verlet"],
    ...                         dts=[1e-3, 1e-4, 1e-5], window=1.0, t_end=1.0, repeat=1)
    >>> [path.name for path in write_all(result, Path("bench"))]
    ['bench-textbook-1d.csv', 'bench-textbook-1d.json', 'bench-textbook-1d.md']
    """
    result = _checked(result)
    out = args.path(out, "out")
    stem = f"bench-{result.scene}"
    return [
        write_csv(result, out / f"{stem}.csv"),
        write_json(result, out / f"{stem}.json"),
        write_markdown(result, out / f"{stem}.md"),
    ]
