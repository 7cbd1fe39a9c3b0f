"""Checks of arguments at the border of every public function.

Each returns the value in the form the code below expects (a float, an int, a Scene, a Path)
or raises :class:`~dumbbell.errors.UsageError` naming the argument and what is allowed. Numbers
are anything :mod:`numbers` calls real or integral, so numpy scalars (``np.float32(1e-4)``,
``np.int64(100)``) are numbers; ``bool`` is not a number here.
"""

from __future__ import annotations

import math
import numbers
import os
from pathlib import Path
from typing import Any

from ..errors import UsageError


def show(value: Any) -> str:
    """``value`` for an error message: one line, at most 60 characters."""
    try:
        text = repr(value) if isinstance(value, str) else str(value)
    except ValueError:  # an integer with more digits than Python will print
        text = "a whole number too large to print"
    text = " ".join(text.split())
    return text if len(text) <= 60 else text[:57] + "..."


def real(value: Any, name: str, unit: str, positive: bool = True) -> float:
    """``value`` as a finite float (> 0 if ``positive``), in ``unit``."""
    allowed = f"must be a finite number{' > 0' if positive else ''} ({unit})"
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    try:
        number = float(value)
    except (OverflowError, ValueError, TypeError):
        number = math.nan
    if not math.isfinite(number) or (positive and number <= 0):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    return number


def positives(values: Any, name: str, unit: str) -> list[float]:
    """``values`` as a non-empty list of finite numbers > 0, in ``unit``."""
    if isinstance(values, str) or not isinstance(values, list | tuple) or not values:
        raise UsageError(f"{name} = {show(values)}: must be a list of numbers > 0 ({unit})",
                         param=name)
    return [real(v, name, unit) for v in values]


def whole(value: Any, name: str, unit: str, lo: int = 1, hi: int | None = None) -> int:
    """``value`` as an int from ``lo`` to ``hi`` (no upper bound if None)."""
    allowed = (f"must be a whole number from {lo:,} to {hi:,} ({unit})" if hi is not None
               else f"must be a whole number >= {lo:,} ({unit})")
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    number = int(value)
    if number < lo or (hi is not None and number > hi):
        raise UsageError(f"{name} = {show(value)}: {allowed}", param=name)
    return number


def flag(value: Any, name: str) -> bool:
    """``value`` as a bool (True/False or a numpy bool)."""
    if not isinstance(value, bool) and type(value).__name__ != "bool_":
        raise UsageError(f"{name} = {show(value)}: must be True or False", param=name)
    return bool(value)


def choice(value: Any, name: str, choices: list[str] | tuple[str, ...]) -> str:
    """``value`` as one of the names ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise UsageError(f"{name} = {show(value)}: must be one of {', '.join(choices)}",
                         param=name)
    return value


def names(value: Any, name: str, choices: list[str] | tuple[str, ...]) -> list[str]:
    """``value`` as a non-empty list of names among ``choices`` (a single str is refused:
    ``"exact"`` would otherwise read as five one-letter names)."""
    if isinstance(value, str) or not isinstance(value, list | tuple) or not value:
        raise UsageError(f"{name} = {show(value)}: must be a list of names among "
                         f"{', '.join(choices)}", param=name)
    return [choice(v, name, choices) for v in value]


def path(value: Any, name: str) -> Path:
    """``value`` (a str or os.PathLike, not empty) as a Path."""
    if not isinstance(value, str | os.PathLike) or str(value) == "":
        raise UsageError(f"{name} = {show(value)}: must be a path (str or pathlib.Path)",
                         param=name)
    return Path(value)


def scene(value: Any, name: str = "scene") -> Any:
    """``value`` as a Scene: a Scene, or the path of a scene file, which is loaded."""
    from .scene import Scene, load_scene

    if isinstance(value, Scene):
        return value
    if isinstance(value, str | os.PathLike):
        return load_scene(value)
    raise UsageError(f"{name} = {show(value)}: must be a Scene or the path of a scene file",
                     param=name)
