"""The restitution study's CSV (:class:`dumbbell.analysis.restitution.RestitutionResult` in):
one line per tilt, the columns of :meth:`~dumbbell.analysis.restitution.RestitutionResult.columns`
(tilt in degrees, the rest dimensionless). The figure is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

from pathlib import Path

from ..analysis.restitution import RestitutionResult
from .tables import csv_text, write_text

__all__ = ["write_csv"]


def write_csv(result: RestitutionResult, path: str | Path) -> Path:
    """Write the columns as CSV to ``path`` atomically; returns the path."""
    from ..model import args

    args.instance(result, "result", RestitutionResult,
                  "a RestitutionResult (from dumbbell.analysis.restitution.restitution)")
    path = args.path(path, "path")
    cols = result.columns()
    rows = ([float(cols[c][i]) for c in cols] for i in range(len(result.theta)))
    return write_text(path, csv_text(list(cols), rows))
