"""The comparison's outputs (:class:`dumbbell.analysis.compare.Comparison` in): the CSVs of
the summary, the impact times side by side and the position-error series, and the text table
``dumbbell compare`` prints. The figures are :mod:`dumbbell.plot`'s; the command saves them."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.compare import MAX_TIMED_RUNS, TIME_AGAIN_BELOW, Comparison
from ..files import atomic_output
from ..model import args
from .tables import csv_text, write_text

__all__ = ["text", "write"]


def _checked(result: Any) -> Comparison:
    return args.instance(result, "result", Comparison, "a Comparison (from dumbbell.compare)")


#: Columns of SCENE-compare.csv (times in s, position errors in m, the energy error
#: dimensionless; the measures of :mod:`dumbbell.analysis.metrics`). ``run_time_s`` is warm;
#: ``warm_up_s`` what the first run paid on top (numba start-up, compile or cache load).
#: Each measure says its span: ``max_position_error_m`` covers [0, ``error_until_s``] (the
#: window, ``window_s``, or up to ``parted_at_s``, where the runs part by chaos, when
#: sooner); ``energy_error`` and ``impacts`` cover the whole run, [0, ``run_until_s``].
SUMMARY_COLUMNS = ("solver", "dt", "run_time_s", "steps", "max_position_error_m",
                   "error_until_s", "window_s", "parted_at_s", "error_passes_1mm_at_s",
                   "energy_error", "impacts", "run_until_s", "verdict", "warm_up_s")


def summary_csv(result: Comparison) -> str:
    """One line per run, the truth first, with :data:`SUMMARY_COLUMNS`."""
    result = _checked(result)
    rows = []
    for row, rec in zip([None, *result.rows], result.summary(), strict=True):
        r = result.truth if row is None else row.traj
        rows.append((r.solver if row is None else row.label, r.dt if r.dt else "",
                     f"{rec['wall_time']:.6g}", r.info.get("steps", ""),
                     None if row is None else row.window_error,
                     None if row is None else row.error_until, result.window,
                     rec["parted_at"], None if row is None else row.diverged_at,
                     rec["energy_error"], len(r.events), rec["run_until"], r.verdict.status,
                     "" if math.isnan(rec["warm_up"]) else f"{rec['warm_up']:.3g}"))
    return csv_text(SUMMARY_COLUMNS, rows)


def impacts_csv(result: Comparison) -> str:
    """:meth:`Comparison.impacts` as CSV: number, body, the truth's time, then each run's
    time and its difference from the truth (s)."""
    result = _checked(result)
    keys = ["n", "body", "truth_t"] + [k for row in result.rows
                                       for k in (f"{row.label}_t", f"{row.label}_diff")]
    return csv_text(keys, ([rec[k] for k in keys] for rec in result.impacts()))


def write_errors(result: Comparison, path: Path) -> Path:
    """The position-error series (m) of every run at the samples all runs have, beside t (s)."""
    result = _checked(result)
    path = args.path(path, "path")
    n = min(len(row.error) for row in result.rows) if result.rows else 0
    table = np.column_stack([result.truth.t[:n], *[row.error[:n] for row in result.rows]])
    with atomic_output(path) as tmp:
        np.savetxt(tmp, table, delimiter=",", comments="", fmt="%.17g",
                   header=",".join(["t"] + [f"{row.label}_position_error_m"
                                            for row in result.rows]))
    return path


def write(result: Comparison, out: Path) -> list[Path]:
    """SCENE-compare.csv, -compare-impacts.csv and -compare-errors.csv into a folder: what
    ``dumbbell compare`` writes.

    Parameters
    ----------
    result : Comparison
        What :func:`dumbbell.compare` measured.
    out : pathlib.Path
        The folder (made if missing).

    Returns
    -------
    list of pathlib.Path
        The files written, each whole or not at all.

    Raises
    ------
    UsageError
        A ``result`` that is not a Comparison; an ``out`` where no folder can be made.

    Examples
    --------
    >>> from pathlib import Path
    >>> from dumbbell.io.compare import write
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> result = dumbbell.compare(scene, solvers=["euler-cromer"], dts=[1e-4], t_end=1.0,
    ...                           window=1.0)
    >>> [path.name for path in write(result, Path("compare"))]
    ['textbook-1d-compare.csv', 'textbook-1d-compare-impacts.csv', 'textbook-1d-compare-errors.csv']
    """
    result = _checked(result)
    out = args.path(out, "out")
    stem = out / f"{result.scene.name}-compare"
    return [write_text(f"{stem}.csv", summary_csv(result)),
            write_text(f"{stem}-impacts.csv", impacts_csv(result)),
            write_errors(result, Path(f"{stem}-errors.csv"))]


def text(result: Comparison) -> str:
    """The summary as a fixed-width text table (times in s, position errors in m, steps/s),
    then the impacts inside the window and the notes: what ``dumbbell compare`` prints.

    Parameters
    ----------
    result : Comparison
        What :func:`dumbbell.compare` measured (its rows, impacts and notes).

    Returns
    -------
    str
        The text, lines of at most about 130 characters.

    Raises
    ------
    UsageError
        Any ``result`` but a Comparison.

    Examples
    --------
    Its first line names the scene and its file:

    >>> import dumbbell
    >>> from dumbbell.io.compare import text
    >>> from dumbbell.model.scene import scenes_dir
    >>> result = dumbbell.compare(scenes_dir() / "textbook-1d.toml", solvers=["euler-cromer"],
    ...                           dts=[1e-4], t_end=1.0, window=1.0)
    >>> print(text(result).splitlines()[0])
    Bouncing dumbbell, textbook section 13.5.1  (...textbook-1d.toml)
    """
    result = _checked(result)
    head = (f"{'solver':<26}{'dt [s]':>9}{'run time [s]':>14}{'warm-up [s]':>13}"
            f"{'steps/s':>10}{'max |dr| [m]':>14}{'over [s]':>11}{'parts at':>10}"
            f"{'|dr|>1mm at':>13}{'E error':>11}{'impacts':>9}{'over [s]':>10}  verdict")
    lines = [f"{result.scene.title}  ({result.scene.source})",
             f"truth: {result.truth_note}",
             (f"position error (max |dr|): largest distance of either particle from its true "
              f"place over [0, {result.window:g}] s, or up to where the runs part by chaos "
              "when that comes sooner (later errors do not measure the method); "
              "E error and impacts: over the whole run"),
             "", head, "-" * len(head)]
    for i, rec in enumerate(result.summary()):
        rate = "-" if rec["steps_per_s"] is None else f"{rec['steps_per_s']:.3g}"
        dt = "-" if rec["dt"] is None else f"{rec['dt']:g}"
        err = "(truth)" if i == 0 else f"{rec['window_error']:.3g}"
        span = "-" if i == 0 else f"0-{rec['error_until']:.3g}"
        part = "-" if rec["parted_at"] is None else f"{rec['parted_at']:.3g} s"
        div = "-" if rec["diverged_at"] is None else f"{rec['diverged_at']:.3g} s"
        energy = "-" if math.isnan(rec["energy_error"]) else f"{rec['energy_error']:.2e}"
        warm = "-" if math.isnan(rec["warm_up"]) else f"{rec['warm_up']:.3g}"
        lines.append(
            f"{rec['label']:<26}{dt:>9}{rec['wall_time']:>14.3g}{warm:>13}"
            f"{rate:>10}{err:>14}{span:>11}{part:>10}{div:>13}{energy:>11}"
            f"{rec['impacts']:>9}{'0-' + format(rec['run_until'], '.3g'):>10}"
            f"  {rec['verdict']}")
    lines += [("run time: warm, on the solver's own clock (a run under "
              f"{TIME_AGAIN_BELOW:g} s, or of exact or reference, is timed again: the fastest "
              f"of up to {MAX_TIMED_RUNS} later runs); warm-up: what the first run paid on top "
              "(numba's start-up and compile, or its load from numba's cache)"),
              "", *_impact_lines(result), *result.notes]
    return "\n".join(lines)


def _impact_lines(result: Comparison) -> list[str]:
    """The impacts inside the window as text (differences in ms; '?' where the bodies
    no longer match: the runs have parted)."""
    head = f"{'impact':>6} {'body':>4} {'truth t [s]':>12}" + "".join(
        f"{row.label[:22]:>24}" for row in result.rows)
    lines = [f"impacts in [0, {result.window:g}] s: time, and difference from the truth",
             head]
    for rec in result.impacts():
        if rec["truth_t"] > result.window:  # type: ignore[operator]
            break
        cells = ""
        for row in result.rows:
            t, d = rec[f"{row.label}_t"], rec[f"{row.label}_diff"]
            cell = ("-" if math.isnan(t) else (f"{t:.5f} ({d * 1e3:+.3f} ms)"  # type: ignore
                    if not math.isnan(d) else f"{t:.5f} (?)"))  # type: ignore[arg-type]
            cells += f"{cell:>24}"
        lines.append(f"{rec['n']:>6} {rec['body']:>4} {rec['truth_t']:>12.6f}{cells}")
    return lines
