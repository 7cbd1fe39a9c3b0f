"""Progress bars that show on a terminal and stay quiet in CI, in pipes or with --quiet."""

from __future__ import annotations

import math
import numbers
import os
import sys
from typing import Any, Self

from .errors import UsageError

#: No public names: the commands and analyses draw their bars with :func:`bar`.
__all__: list[str] = []


def _progress_wanted(quiet: bool = False) -> bool:
    """True when a progress bar should be drawn: stderr is a terminal, not CI, not quiet."""
    if not isinstance(quiet, bool) and type(quiet).__name__ != "bool_":
        raise UsageError(f"quiet = {quiet!r:.60}: must be True or False", param="quiet")
    if quiet or os.environ.get("CI"):
        return False
    return sys.stderr.isatty()


class _NoBar:
    """Stands in for a tqdm bar when none is wanted, so callers need no branches."""

    n = 0

    def update(self, n: int = 1) -> None:
        self.n += n

    def set_postfix_str(self, text: str) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        pass


def bar(total: float | None, desc: str, unit: str = "it", quiet: bool = False, **kw: Any) -> Any:
    """A tqdm bar on a terminal, or a silent stand-in, counting to ``total`` (None: unknown)
    ``unit``s. Use as a context manager."""
    # Checked here with the errors module only: progress sits below the model's checks.
    if total is not None and (isinstance(total, bool) or not isinstance(total, numbers.Real)
                              or not 0 <= total < math.inf):
        raise UsageError(f"total = {total!r:.60}: must be a finite number >= 0 or None",
                         param="total")
    for name, value in (("desc", desc), ("unit", unit)):
        if not isinstance(value, str):
            raise UsageError(f"{name} = {value!r:.60}: must be a str", param=name)
    if not _progress_wanted(quiet):
        return _NoBar()
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, leave=False, dynamic_ncols=True, **kw)
