"""The comparison's files (:class:`dumbbell.analysis.compare.Comparison` in, CSVs out): the
summary, the impact times side by side and the position-error series. The figures are
:mod:`dumbbell.plot`'s; the command saves them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.compare import Comparison
from ..model import args
from .files import atomic_output
from .tables import csv_text, write_text

__all__ = ["SUMMARY_COLUMNS", "impacts_csv", "summary_csv", "write", "write_errors"]


def _checked(result: Any) -> Comparison:
    return args.instance(result, "result", Comparison, "a Comparison (from dumbbell.compare)")


#: Columns of SCENE-compare.csv (times in s, position errors in m, the energy error
#: dimensionless; the measures of :mod:`dumbbell.analysis.metrics`).
SUMMARY_COLUMNS = ("solver", "dt", "run_time_s", "steps", "max_position_error_m", "window_s",
                   "error_passes_1mm_at_s", "energy_error", "impacts", "verdict")


def summary_csv(result: Comparison) -> str:
    """One line per run, the truth first, with :data:`SUMMARY_COLUMNS`."""
    result = _checked(result)
    rows = []
    for row, rec in zip([None, *result.rows], result.summary(), strict=True):
        r = result.truth if row is None else row.traj
        rows.append((r.solver if row is None else row.label, r.dt if r.dt else "",
                     f"{r.wall_time:.6g}", r.info.get("steps", ""),
                     None if row is None else row.window_error, result.window,
                     None if row is None else row.diverged_at,
                     rec["energy_error"], len(r.events), r.verdict.status))
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
    """SCENE-compare.csv, -compare-impacts.csv and -compare-errors.csv into ``out``; returns
    the paths."""
    result = _checked(result)
    out = args.path(out, "out")
    stem = out / f"{result.scene.name}-compare"
    return [write_text(f"{stem}.csv", summary_csv(result)),
            write_text(f"{stem}-impacts.csv", impacts_csv(result)),
            write_errors(result, Path(f"{stem}-errors.csv"))]
