"""What every table writer shares: one spelling of a CSV cell, CSV text, an atomic text file.

A float is written with ``repr`` (the shortest text that reads back to the same number), so a
CSV is byte-identical however its rows were computed; a missing value is an empty cell.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from ..errors import UsageError
from ..files import atomic_output, writable_path
from ..model import args

#: No public names: the table cells every writer shares.
__all__: list[str] = []


def cell(value: Any) -> str:
    """One CSV cell: "" for None, ``repr`` for a float ("nan", "inf" included), else str."""
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return str(value)


def csv_text(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A CSV with ``header``, then one line per row of cells (see :func:`cell`), "\\n" ends."""
    if isinstance(header, str) or not isinstance(header, Sequence) or not all(
            isinstance(h, str) for h in header):
        raise UsageError(f"header = {args.show(header)}: must be a list of column names (str)",
                         param="header")
    if isinstance(rows, str | bytes) or not isinstance(rows, Iterable):
        raise UsageError(f"rows = {args.show(rows)}: must be rows (lists of cells)",
                         param="rows")
    rows = list(rows)
    if not all(isinstance(r, Sequence) and not isinstance(r, str) for r in rows):
        raise UsageError(f"rows = {args.show(rows)}: must be rows (lists of cells)",
                         param="rows")
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([cell(v) for v in row] for row in rows)
    return buf.getvalue()


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (whole or not at all); returns the path."""
    path = writable_path(path)
    text = args.text(text, "text", "the text to write (str)")
    with atomic_output(path) as tmp:
        tmp.write_text(text)
    return path
