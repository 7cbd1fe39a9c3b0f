"""The sweep's CSV (:class:`dumbbell.analysis.sweep.SweepResult` in): the axes' values, then
:data:`~dumbbell.analysis.sweep.RESULT_COLUMNS`, one line per grid point in grid order. The
map is :mod:`dumbbell.plot`'s."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..analysis.sweep import SweepResult
from .tables import csv_text as _csv_text
from .tables import write_text

__all__ = ["write_csv"]


def _checked(result: Any) -> SweepResult:
    from ..model import args

    return args.instance(result, "result", SweepResult, "a SweepResult (from dumbbell.sweep)")


def _value(value: Any) -> Any:
    # A swept switch is written as TOML spells it, so the cell reads back as a scene value.
    if isinstance(value, bool):
        return "true" if value else "false"
    return value


def csv_text(result: SweepResult) -> str:
    """The CSV as text: the same bytes whichever backend produced the rows."""
    result = _checked(result)
    return _csv_text(result.columns, ([_value(v) for v in row.cells]
                                      for row in result.rows))


def write_csv(result: SweepResult, path: str | Path) -> Path:
    """Write :func:`csv_text` to ``path`` atomically; returns the path."""
    result = _checked(result)
    return write_text(path, csv_text(result))
