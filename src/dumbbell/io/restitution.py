"""The restitution study's outputs (:class:`dumbbell.analysis.restitution.RestitutionResult`
in): one line per tilt, the columns of
:meth:`~dumbbell.analysis.restitution.RestitutionResult.columns` (tilt in degrees, the rest
dimensionless), as a CSV file and as the Markdown table ``dumbbell restitution`` prints. The
figure is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

from pathlib import Path

from ..analysis.restitution import RestitutionResult
from .tables import csv_text, write_text

__all__ = ["markdown", "write_csv"]


def _checked(result: object) -> RestitutionResult:
    from ..model import args

    return args.instance(result, "result", RestitutionResult,
                         "a RestitutionResult (from dumbbell.analysis.restitution.restitution)")


def write_csv(result: RestitutionResult, path: str | Path) -> Path:
    """Write the columns as CSV to ``path`` atomically; returns the path."""
    from ..model import args

    result = _checked(result)
    path = args.path(path, "path")
    cols = result.columns()
    rows = ([float(cols[c][i]) for c in cols] for i in range(len(result.theta)))
    return write_text(path, csv_text(list(cols), rows))


def markdown(result: RestitutionResult) -> str:
    """The columns as a Markdown table, one row per tilt, 6 significant digits."""
    cols = _checked(result).columns()
    head = "| " + " | ".join(cols) + " |"
    rule = "|" + "---|" * len(cols)
    rows = ["| " + " | ".join(f"{cols[c][i]:.6g}" for c in cols) + " |"
            for i in range(len(result.theta))]
    return "\n".join([head, rule, *rows])
