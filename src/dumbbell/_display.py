"""How a result shows itself: ``repr`` one line of at most :data:`MAX_REPR` characters (a
summary, never the data), and ``_repr_html_`` that line above a small table for notebooks.
Shared by every layer's result types (model, analysis)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from html import escape
from typing import Any

#: Longest ``repr`` of a result (characters).
MAX_REPR = 200
#: Most table rows ``_repr_html_`` shows; the rest are counted.
MAX_ROWS = 30


def one_line(text: str) -> str:
    """``text`` on one line (runs of white space as one space), cut to :data:`MAX_REPR`
    characters with "..." where it was cut (keeping a closing ">")."""
    text = " ".join(str(text).split())
    if len(text) <= MAX_REPR:
        return text
    tail = ">" if text.endswith(">") else ""
    return text[: MAX_REPR - 3 - len(tail)] + "..." + tail


def counted(n: int, noun: str, plural: str | None = None, grouped: bool = False) -> str:
    """``n`` things, the noun agreeing with the count: '1 run', '3 runs' (``plural`` where
    adding 's' is wrong); ``grouped`` writes thousands apart: '12,000 points'."""
    word = noun if n == 1 else (plural or noun + "s")
    return f"{n:,} {word}" if grouped else f"{n} {word}"


def significant(value: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant digits, trailing zeros kept so that numbers side
    by side show their precision alike: 0.0300 beside 0.0192, not 0.03; 154 and 1.30e+03
    without a trailing point."""
    if not math.isfinite(value):
        return str(value)
    text = f"{value:#.{digits}g}"
    mantissa, e, exponent = text.partition("e")
    return mantissa.rstrip(".") + e + exponent


def number(value: Any, digits: int = 3) -> str:
    """A table cell: "-" for None or NaN, ``digits`` significant digits for a float."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    if isinstance(value, bool | str):
        return str(value)
    if isinstance(value, int):
        return f"{value:,}"
    try:
        return f"{float(value):.{digits}g}"
    except (TypeError, ValueError):
        return str(value)


def html_table(summary: str, header: Sequence[str], rows: Iterable[Sequence[Any]],
               notes: Sequence[str] = ()) -> str:
    """``summary`` (the one-line repr) above a table of ``rows`` (at most :data:`MAX_ROWS`,
    then a count of the rest) and ``notes``, every text escaped."""
    body, more = [], 0
    for i, row in enumerate(rows):
        if i >= MAX_ROWS:
            more += 1
            continue
        body.append("<tr>" + "".join(f"<td>{escape(number(c))}</td>" for c in row) + "</tr>")
    if more:
        body.append(f"<tr><td colspan='{len(header)}'>... and {more:,} more rows</td></tr>")
    head = "<tr>" + "".join(f"<th>{escape(h)}</th>" for h in header) + "</tr>"
    tail = "".join(f"<p>{escape(n)}</p>" for n in notes)
    return (f"<div><p><code>{escape(summary)}</code></p><table>{head}{''.join(body)}</table>"
            f"{tail}</div>")
